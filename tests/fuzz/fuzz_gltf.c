/* fuzz_gltf.c - the glTF 2.0 reader through its (buffer, size) entry point
 * (JSON or GLB, told by the first bytes), then the scene commit; buffers and
 * images are looked up in tests/data/gltf, so fuzzed assets can name real
 * files. Where the build has the Draco module, Draco-compressed primitives
 * are decoded by it (PK_DRACO_MODULE names it). */
#include "fuzz_scene.h"

#include "io/readers.h"

static pk_status parse(pk_context *ctx, pk_scene *s, const char *data, size_t size)
{
#ifdef PK_DRACO_MODULE
    if (pk_context_set_config(ctx, "draco.module=" PK_DRACO_MODULE) != PK_OK) return pk_context_status(ctx);
#endif
    return scene_gltf_parse(ctx, s, data, size, "fuzz.gltf", PK_TEST_DATA "/gltf");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    return fuzz_scene_run(data, size, "fuzz.gltf", parse, true);
}
