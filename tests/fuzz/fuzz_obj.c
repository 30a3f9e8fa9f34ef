/* fuzz_obj.c - the OBJ parser through its (buffer, size) entry point, then
 * the scene commit; mtllib files are looked up in tests/data. */
#include "fuzz_scene.h"

#include "io/readers.h"

static pk_status parse(pk_context *ctx, pk_scene *s, const char *data, size_t size)
{
    return obj_parse(ctx, s, data, size, "fuzz.obj", PK_TEST_DATA, NULL);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    return fuzz_scene_run(data, size, "fuzz.obj", parse, true);
}
