/* fuzz_json.c - the JSON scene parser through its (buffer, size) entry point,
 * then the scene commit; meshes are looked up in tests/data, so fuzzed scenes
 * can name real files. */
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
    if (scene_create(ctx, "fuzz.json", &s) == PK_OK) {
        pk_status st = scene_json_parse(ctx, s, (const char *)data, size, "fuzz.json", PK_TEST_DATA);
        if (st == PK_OK) st = scene_commit(ctx, s);
        fuzz_check_error(ctx, st);
        scene_destroy(s);
    }
    pk_context_destroy(ctx);
    return 0;
}
