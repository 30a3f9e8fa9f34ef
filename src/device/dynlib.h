/*
 * dynlib.h - a shared library loaded at run time (dlopen), once per process:
 * the one loader behind Embree (accel/embree.c), the CUDA driver
 * (device/cuda.c) and whatever back end comes later. The library is linked
 * against none of them; each fills a table of function pointers from the
 * handle (dynlib_symbol) in its init callback.
 */
#ifndef PK_DYNLIB_H
#define PK_DYNLIB_H

#include "paprsek_internal.h"

#include <pthread.h>

#define DYNLIB_NAME_MAX 256

/* Invariants (under lock):
 *  1. ready: handle is the library loaded by name and init succeeded; it is
 *     never closed (back ends keep threads and tables of their own) and no
 *     other name is loaded into this slot afterwards;
 *  2. !ready and failed[0]: the last attempt, by the name failed, did not
 *     load; error says why (it is not tried again under that name). */
typedef struct dynlib {
    pthread_mutex_t lock;
    bool ready;
    void *handle;
    char name[DYNLIB_NAME_MAX];
    char failed[DYNLIB_NAME_MAX];
    char error[384];
} dynlib;

#define DYNLIB_INIT {PTHREAD_MUTEX_INITIALIZER, false, NULL, "", "", ""}

/* Fills the caller's table from handle; false with a reason in why (n bytes)
 * when a symbol is missing. Called with the slot's lock held. */
typedef bool (*dynlib_init_fn)(void *handle, const char *name, char *why, size_t n);

/* Loads lib from name (a path or a soname) and runs init once; true when the
 * library is ready. Otherwise false and why (n bytes) says what went wrong:
 * the library could not be opened ("NAME could not be loaded (dlerror)"),
 * init's reason, or another name was loaded into this slot before. */
PK_HIDDEN bool dynlib_load(dynlib *lib, const char *name, dynlib_init_fn init, char *why, size_t n);
/* The address of symbol in handle, or NULL. */
PK_HIDDEN void *dynlib_symbol(void *handle, const char *symbol);

#endif
