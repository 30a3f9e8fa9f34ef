/* fuzz_obj.c - the OBJ parser through its (buffer, size) entry point. */
#include "fuzz.h"

#include "scene/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) return 0;
    pk_scene *s = NULL;
    if (scene_create(ctx, "fuzz.obj", &s) == PK_OK) {
        if (obj_parse(ctx, s, (const char *)data, size, "fuzz.obj", NULL, NULL) == PK_OK) scene_commit(ctx, s);
        scene_destroy(s);
    }
    pk_context_destroy(ctx);
    return 0;
}
