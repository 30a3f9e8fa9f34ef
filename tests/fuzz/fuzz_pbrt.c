/* fuzz_pbrt.c - the pbrt-v4 reader through its (buffer, size) entry point,
 * then the scene commit; Include, Import, plymesh and imagemap files are
 * looked up in tests/data/pbrt, so fuzzed scenes can name real files
 * (parts/world.pbrt, ../fuzz_seed_mesh.ply, ../tex_checker.png). */
#include "fuzz_scene.h"

#include "io/readers.h"

static pk_status parse(pk_context *ctx, pk_scene *s, const char *data, size_t size)
{
    return scene_pbrt_parse(ctx, s, data, size, "fuzz.pbrt", PK_TEST_DATA "/pbrt");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    return fuzz_scene_run(data, size, "fuzz.pbrt", parse, true);
}
