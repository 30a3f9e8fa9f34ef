/* fuzz_xml.c - the Mitsuba XML reader through its (buffer, size) entry
 * point, then the scene commit; meshes and included files are looked up in
 * tests/data, so fuzzed scenes can name real files. */
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
    if (scene_create(ctx, "fuzz.xml", &s) == PK_OK) {
        pk_status st = scene_xml_parse(ctx, s, (const char *)data, size, "fuzz.xml", PK_TEST_DATA, NULL, 0);
        if (st == PK_OK) st = scene_commit(ctx, s);
        fuzz_check_error(ctx, st);
        if (st == PK_OK) {
            char why[256];
            if (!scene_check(s, why, sizeof why)) {
                fprintf(stderr, "fuzz: a committed XML scene fails its check: %s\n", why);
                abort();
            }
        }
        scene_destroy(s);
    }
    pk_context_destroy(ctx);
    return 0;
}
