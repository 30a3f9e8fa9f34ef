/* fuzz_mtl.c - the MTL parser through its (buffer, size) entry point. */
#include "fuzz.h"

#include "io/readers.h"
#include "scene/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) return 0;
    size_t warned = 0;
    pk_context_set_warning_handler(ctx, fuzz_warning, &warned);
    pk_scene *s = NULL;
    if (scene_create(ctx, "fuzz.mtl", &s) == PK_OK) {
        fuzz_check_error(ctx, mtl_parse(ctx, s, (const char *)data, size, "fuzz.mtl"));
        scene_destroy(s);
    }
    pk_context_destroy(ctx);
    return 0;
}
