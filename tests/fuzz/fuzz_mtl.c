/* fuzz_mtl.c - the MTL parser through its (buffer, size) entry point. */
#include "fuzz_scene.h"

#include "io/readers.h"

static pk_status parse(pk_context *ctx, pk_scene *s, const char *data, size_t size)
{
    return mtl_parse(ctx, s, data, size, "fuzz.mtl");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    return fuzz_scene_run(data, size, "fuzz.mtl", parse, false);
}
