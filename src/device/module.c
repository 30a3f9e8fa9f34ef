/*
 * module.c - where the library's own modules are (see module.h).
 */
#define _GNU_SOURCE /* dladdr1, struct link_map */
#include "module.h"

#include <dlfcn.h>
#include <limits.h>
#include <link.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#ifndef PK_MODULE_DIR
#define PK_MODULE_DIR "/usr/local/lib/paprsek"
#endif
#ifndef PK_MODULE_REL
#define PK_MODULE_REL "../lib/paprsek"
#endif

/* The folder of the file that holds this code: the shared library, or the
 * program a static library is linked into. False when it cannot be told. */
static bool code_dir(char *dir, size_t n)
{
    Dl_info info;
    struct link_map *map = NULL;
    char path[PATH_MAX];
    if (dladdr1((void *)(uintptr_t)&code_dir, &info, (void **)&map, RTLD_DL_LINKMAP) && map && map->l_name &&
        map->l_name[0]) {
        snprintf(path, sizeof path, "%s", map->l_name);
    } else { /* the main program, whose name the link map leaves empty */
        const ssize_t len = readlink("/proc/self/exe", path, sizeof path - 1);
        if (len <= 0) return false;
        path[len] = '\0';
    }
    char *slash = strrchr(path, '/');
    if (!slash) return false;
    *slash = '\0';
    if ((size_t)snprintf(dir, n, "%s", slash == path ? "/" : path) >= n) return false;
    return true;
}

bool module_load(dynlib *lib, const char *configured, const char *file, dynlib_init_fn init, bool *missing,
                 char *why, size_t n)
{
    *missing = false;
    if (configured && configured[0]) {
        if (access(configured, F_OK) != 0) {
            *missing = true;
            snprintf(why, n, "%s is not there", configured);
            return false;
        }
        return dynlib_load(lib, configured, init, why, n);
    }
    char dir[PATH_MAX];
    const bool have_dir = code_dir(dir, sizeof dir);
    char cand[4][PATH_MAX + 64];
    int k = 0;
    if (have_dir) {
        snprintf(cand[k++], sizeof cand[0], "%s/paprsek/%s", dir, file);
        snprintf(cand[k++], sizeof cand[0], "%s/%s/%s", dir, PK_MODULE_REL, file);
        snprintf(cand[k++], sizeof cand[0], "%s/%s", dir, file);
    }
    snprintf(cand[k++], sizeof cand[0], "%s/%s", PK_MODULE_DIR, file);
    for (int i = 0; i < k; i++)
        if (access(cand[i], F_OK) == 0) return dynlib_load(lib, cand[i], init, why, n);
    *missing = true;
    if (have_dir)
        snprintf(why, n, "%s is not in %s/paprsek, %s/%s, %s nor %s", file, dir, dir, PK_MODULE_REL, dir,
                 PK_MODULE_DIR);
    else
        snprintf(why, n, "%s is not in %s", file, PK_MODULE_DIR);
    return false;
}
