/* fuzz_json.c - the JSON scene parser through its (buffer, size) entry point,
 * then the scene commit; meshes are looked up in tests/data, so fuzzed scenes
 * can name real files. */
#include "fuzz_scene.h"

#include "io/readers.h"

static pk_status parse(pk_context *ctx, pk_scene *s, const char *data, size_t size)
{
    return scene_json_parse(ctx, s, data, size, "fuzz.json", PK_TEST_DATA);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    return fuzz_scene_run(data, size, "fuzz.json", parse, true);
}
