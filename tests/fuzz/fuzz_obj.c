/* fuzz_obj.c - the OBJ parser through its (buffer, size) entry point, then
 * the scene commit; mtllib files are looked up in tests/data. */
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
    if (scene_create(ctx, "fuzz.obj", &s) == PK_OK) {
        pk_status st = obj_parse(ctx, s, (const char *)data, size, "fuzz.obj", PK_TEST_DATA, NULL);
        if (st == PK_OK) st = scene_commit(ctx, s);
        fuzz_check_error(ctx, st);
        if (st == PK_OK) {
            char why[256];
            if (!scene_check(s, why, sizeof why)) {
                fprintf(stderr, "fuzz: committed scene breaks an invariant: %s\n", why);
                abort();
            }
        }
        scene_destroy(s);
    }
    pk_context_destroy(ctx);
    return 0;
}
