/* fuzz_xml.c - the Mitsuba XML reader through its (buffer, size) entry
 * point, then the scene commit; meshes and included files are looked up in
 * tests/data, so fuzzed scenes can name real files. */
#include "fuzz_scene.h"

#include "io/readers.h"

static pk_status parse(pk_context *ctx, pk_scene *s, const char *data, size_t size)
{
    return scene_xml_parse(ctx, s, data, size, "fuzz.xml", PK_TEST_DATA, NULL, 0);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    return fuzz_scene_run(data, size, "fuzz.xml", parse, true);
}
