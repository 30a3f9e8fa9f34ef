/*
 * fuzz_scene.h - what the scene harnesses (OBJ, MTL, JSON, Mitsuba XML)
 * share around their one call: a context whose warnings are read in full,
 * an empty scene, then the commit, the message every failure must leave,
 * and the invariants of the committed scene.
 */
#ifndef PK_FUZZ_SCENE_H
#define PK_FUZZ_SCENE_H

#include "fuzz.h"

#include "scene/scene.h"

#include <stdbool.h>

/* Parses (data, size) into the empty scene s. */
typedef pk_status (*fuzz_parse_fn)(pk_context *ctx, pk_scene *s, const char *data, size_t size);

/* Runs parse on the input in a scene named name; commits when commit is set
 * and the parse succeeded. Aborts on a failure without a message and on a
 * committed scene that breaks an invariant. */
static inline int fuzz_scene_run(const uint8_t *data, size_t size, const char *name, fuzz_parse_fn parse,
                                 bool commit)
{
    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) return 0;
    size_t warned = 0;
    pk_context_set_warning_handler(ctx, fuzz_warning, &warned);
    pk_scene *s = NULL;
    if (scene_create(ctx, name, &s) == PK_OK) {
        pk_status st = parse(ctx, s, (const char *)data, size);
        if (st == PK_OK && commit) st = scene_commit(ctx, s);
        fuzz_check_error(ctx, st);
        if (st == PK_OK && commit) {
            char why[256];
            if (!scene_check(s, why, sizeof why)) {
                fprintf(stderr, "fuzz: %s: the committed scene breaks an invariant: %s\n", name, why);
                abort();
            }
        }
        scene_destroy(s);
    }
    pk_context_destroy(ctx);
    return 0;
}

#endif
