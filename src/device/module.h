/*
 * module.h - the library's own modules: parts built as shared modules of
 * their own and loaded (dynlib) only when needed, so that the library, and
 * the programs linking it, neither link nor load what they bring. Today: the
 * OpenVDB reader (paprsek_openvdb.so, io/grid_openvdb.c) and the CUDA
 * kernels (paprsek_cuda.so, device/cuda.c).
 *
 * A module FILE is looked for, unless the config names one, in the folder D
 * of the file that holds the library's code (libpaprsek.so.0, or a program
 * linked with libpaprsek.a), first that exists of:
 *   D/paprsek/FILE       the installed shared library (LIBDIR/paprsek/FILE);
 *   D/PK_MODULE_REL/FILE installed programs (BINDIR/../LIBDIR/paprsek/FILE);
 *   D/FILE               the build tree, where modules are built beside the
 *                        library and the program;
 *   PK_MODULE_DIR/FILE   the installed folder (LIBDIR/paprsek of the prefix
 *                        configured), for programs elsewhere.
 * `cmake --install` puts them in LIBDIR/paprsek.
 */
#ifndef PK_DEVICE_MODULE_H
#define PK_DEVICE_MODULE_H

#include "dynlib.h"

/* Loads module file into lib: configured (a path; "" or NULL: look for
 * file as above) and init as for dynlib_load. True when ready. Otherwise
 * false, why (n bytes) says what went wrong, and *missing tells whether no
 * such file was there at all (why then lists where it was looked for) or it
 * was there but did not load (why: dlopen's reason or init's). */
PK_HIDDEN bool module_load(dynlib *lib, const char *configured, const char *file, dynlib_init_fn init, bool *missing,
                           char *why, size_t n);

#endif
