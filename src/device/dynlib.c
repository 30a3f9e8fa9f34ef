/*
 * dynlib.c - shared libraries loaded at run time (see dynlib.h).
 */
#include "dynlib.h"

#include <dlfcn.h>
#include <stdio.h>
#include <string.h>

bool dynlib_load(dynlib *lib, const char *name, dynlib_init_fn init, char *why, size_t n)
{
    bool ok = false;
    pthread_mutex_lock(&lib->lock);
    if (lib->ready) {
        ok = strcmp(lib->name, name) == 0;
        if (!ok)
            snprintf(why, n, "%s is already loaded in this process; %.200s cannot be loaded beside it", lib->name,
                     name);
    } else if (lib->failed[0] && strcmp(lib->failed, name) == 0) {
        snprintf(why, n, "%s", lib->error);
    } else if (strlen(name) >= DYNLIB_NAME_MAX) {
        snprintf(why, n, "library name too long (%zu bytes)", strlen(name));
    } else {
        void *h = dlopen(name, RTLD_NOW | RTLD_LOCAL);
        if (!h) {
            const char *e = dlerror();
            snprintf(lib->error, sizeof lib->error, "%s could not be loaded (%s)", name, e ? e : "no reason given");
        } else if (!init(h, name, lib->error, sizeof lib->error)) {
            dlclose(h);
        } else {
            lib->handle = h;
            snprintf(lib->name, sizeof lib->name, "%s", name);
            lib->failed[0] = '\0';
            lib->ready = ok = true;
        }
        if (!ok) {
            snprintf(lib->failed, sizeof lib->failed, "%s", name);
            snprintf(why, n, "%s", lib->error);
        }
    }
    pthread_mutex_unlock(&lib->lock);
    return ok;
}

void *dynlib_symbol(void *handle, const char *symbol) { return dlsym(handle, symbol); }
