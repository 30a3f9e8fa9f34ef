/*
 * test_options.c - the one table of integer render options serves the API,
 * JSON scenes and the paprsek program alike: for every entry, each of the
 * three accepts the bounds and refuses one past them, with the same range in
 * its message.
 */
#include "test.h"

#include "paprsek.h"

#include <limits.h>
#include <stdbool.h>
#include <sys/wait.h>

static pk_context *ctx;

/* The value of option e set to v (the other image side 1, so that the pixel
 * budget never decides). */
static void set_value(pk_render_options *o, const pk_int_option *e, int v)
{
    pk_render_options_init(o);
    if (strcmp(e->name, "width") == 0) o->height = 1;
    if (strcmp(e->name, "height") == 0) o->width = 1;
    *(int *)(void *)((char *)o + e->offset) = v;
}

static void check_api(const pk_int_option *e, int v, bool ok)
{
    pk_render_options o;
    set_value(&o, e, v);
    pk_status st = pk_render_options_check(ctx, &o);
    if (ok) {
        CHECKF(st == PK_OK, "API: %s = %d refused: %s", e->name, v, pk_context_error(ctx));
    } else {
        char want[256];
        snprintf(want, sizeof want, "%s %d is out of range (%d..%d)", e->label, v, e->min, e->max);
        CHECKF(st == PK_ERR_LIMIT && strcmp(pk_context_error(ctx), want) == 0, "API: %s = %d: status %d, '%s'",
               e->name, v, (int)st, pk_context_error(ctx));
    }
    pk_context_clear_error(ctx);
}

static void check_json(const pk_int_option *e, long long v, bool ok)
{
    char text[512];
    snprintf(text, sizeof text,
             "{\"render\": {\"%s\": %lld%s}, \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1}]}", e->name, v,
             strcmp(e->name, "width") == 0 ? ", \"height\": 1" : strcmp(e->name, "height") == 0 ? ", \"width\": 1" : "");
    pk_scene *s = NULL;
    pk_status st = pk_scene_load_json_memory(ctx, text, strlen(text), "o.json", ".", &s);
    if (ok) {
        CHECKF(st == PK_OK, "JSON: %s = %lld refused: %s", e->name, v, pk_context_error(ctx));
        if (st == PK_OK) {
            pk_render_options o;
            pk_scene_get_render_options(s, &o);
            CHECKF(*(int *)(void *)((char *)&o + e->offset) == v, "JSON: %s = %lld not taken", e->name, v);
            CHECK(pk_render_options_check(ctx, &o) == PK_OK); /* and the API agrees */
        }
    } else {
        char want[256];
        snprintf(want, sizeof want, "o.json:1: render.%s: must be an integer in %d..%d", e->name, e->min, e->max);
        CHECKF(st != PK_OK && strcmp(pk_context_error(ctx), want) == 0, "JSON: %s = %lld: status %d, '%s'", e->name,
               v, (int)st, pk_context_error(ctx));
    }
    pk_scene_destroy(s);
    pk_context_clear_error(ctx);
}

/* Runs the program; returns its exit status. */
static int run_cli(const char *args)
{
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "'%s' render %s -o options_test.png --quiet >options_test.out 2>&1", PK_CLI, args);
    int rc = system(cmd);
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128 + WTERMSIG(rc);
}

static void check_cli(const pk_int_option *e, long long v, bool ok)
{
    char opt[64], args[256];
    snprintf(opt, sizeof opt, "%s", e->name);
    for (char *c = opt; *c; c++)
        if (*c == '_') *c = '-';
    /* a 1x1 image (the other side 1 for width and height) keeps every accepted value fast */
    snprintf(args, sizeof args, "--%s=%lld %s --light-samples 1", opt, v,
             strcmp(e->name, "width") == 0    ? "--height 1"
             : strcmp(e->name, "height") == 0 ? "--width 1"
                                              : "--width 1 --height 1");
    if (strcmp(e->name, "light_samples") == 0)
        snprintf(args, sizeof args, "--%s=%lld --width 1 --height 1", opt, v);
    remove("options_test.png");
    int rc = run_cli(args);
    if (ok) {
        CHECKF(rc == 0 && access("options_test.png", F_OK) == 0, "CLI: --%s=%lld: exit %d", opt, v, rc);
    } else {
        CHECKF(rc == 2 && access("options_test.png", F_OK) != 0, "CLI: --%s=%lld: exit %d (wanted 2)", opt, v, rc);
        /* the message names the table's range */
        char range[64], line[512] = "";
        snprintf(range, sizeof range, "%d..%d", e->min, e->max);
        FILE *f = fopen("options_test.out", "r");
        if (f) {
            if (!fgets(line, sizeof line, f)) line[0] = '\0';
            fclose(f);
        }
        CHECKF(strstr(line, range) != NULL, "CLI: --%s=%lld: message without the range %s: %s", opt, v, range, line);
    }
}

/* pk_context_set_config: the keys, their defaults, what is refused and
 * that a refused string changes nothing. */
static void check_context_config(void)
{
    char buf[1024];
    const char *defaults = "cpu.isa=auto,bvh.quality=high,embree.quality=medium,embree.library=libembree3.so.3,"
                           "cuda.library=libcuda.so.1,dnnl.library=libdnnl.so.2,scene.instances=auto,"
                           "cuda.traversal=sorted,cuda.leaf=16,openvdb.module=,cuda.module=,draco.module=";
    size_t len = pk_context_get_config(ctx, buf, sizeof buf);
    CHECKF(strcmp(buf, defaults) == 0 && len == strlen(defaults), "default config: %s", buf);
    CHECK(pk_context_get_config(ctx, NULL, 0) == len);
    char tiny[8];
    CHECK(pk_context_get_config(ctx, tiny, sizeof tiny) == len && strcmp(tiny, "cpu.isa") == 0);
    CHECK(pk_context_set_config(ctx, "") == PK_OK && pk_context_set_config(ctx, " , ,") == PK_OK);
    CHECK(pk_context_set_config(ctx, " bvh.quality = fast ,cpu.isa=avx2,embree.quality=high,"
                                     "embree.library=/opt/e/libembree3.so.3,cuda.library=libcuda.so.1") == PK_OK);
    pk_context_get_config(ctx, buf, sizeof buf);
    CHECKF(strcmp(buf, "cpu.isa=avx2,bvh.quality=fast,embree.quality=high,embree.library=/opt/e/libembree3.so.3,"
                       "cuda.library=libcuda.so.1,dnnl.library=libdnnl.so.2,scene.instances=auto,"
                       "cuda.traversal=sorted,cuda.leaf=16,openvdb.module=,cuda.module=,draco.module=") == 0,
           "config: %s", buf);
    CHECK(pk_context_set_config(ctx, "scene.instances=keep") == PK_OK);
    pk_context_get_config(ctx, buf, sizeof buf);
    CHECKF(strstr(buf, ",scene.instances=keep") != NULL, "config: %s", buf);
    CHECK(pk_context_set_config(ctx, "scene.instances=flatten") == PK_OK);
    pk_context_get_config(ctx, buf, sizeof buf);
    CHECKF(strstr(buf, ",scene.instances=flatten") != NULL, "config: %s", buf);
    CHECK(pk_context_set_config(ctx, "cuda.traversal=ordered,cuda.leaf=4") == PK_OK);
    pk_context_get_config(ctx, buf, sizeof buf);
    CHECKF(strstr(buf, ",cuda.traversal=ordered,cuda.leaf=4") != NULL, "config: %s", buf);
    CHECK(pk_context_set_config(ctx, "cuda.leaf=8") == PK_OK);
    pk_context_get_config(ctx, buf, sizeof buf);
    CHECKF(strstr(buf, ",cuda.traversal=ordered,cuda.leaf=8") != NULL, "config: %s", buf);
    CHECK(pk_context_set_config(ctx, "openvdb.module=/opt/p/paprsek_openvdb.so") == PK_OK);
    pk_context_get_config(ctx, buf, sizeof buf);
    CHECKF(strstr(buf, ",openvdb.module=/opt/p/paprsek_openvdb.so") != NULL, "config: %s", buf);
    /* keys not named keep their values; the last of a key wins */
    CHECK(pk_context_set_config(ctx, "cpu.isa=auto,cpu.isa=avx2") == PK_OK);
    pk_context_get_config(ctx, buf, sizeof buf);
    CHECKF(strstr(buf, "cpu.isa=avx2,bvh.quality=fast,") == buf, "config: %s", buf);
    /* refused: unknown key, bad value, no '=', NULL; the message names the key */
    const char *bad[][2] = {{"cpu.isa=avx2,bvh.qualty=fast", "bvh.qualty"}, {"bvh.quality=slow", "bvh.quality=slow"},
                            {"embree.quality=extreme", "embree.quality"}, {"cpu.isa", "cpu.isa"},
                            {"cpu.isa=sse2", "cpu.isa=sse2"}, {"PAPRSEK_CPU_ISA=avx2", "PAPRSEK_CPU_ISA"},
                            {"scene.instances=some", "scene.instances=some"},
                            {"cuda.traversal=fast", "cuda.traversal=fast"}, {"cuda.leaf=5", "cuda.leaf=5"}};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        pk_context_clear_error(ctx);
        CHECKF(pk_context_set_config(ctx, bad[i][0]) == PK_ERR_INVALID_ARGUMENT, "'%s' accepted", bad[i][0]);
        CHECKF(strstr(pk_context_error(ctx), bad[i][1]) != NULL, "'%s': message %s", bad[i][0], pk_context_error(ctx));
    }
    pk_context_clear_error(ctx);
    CHECK(pk_context_set_config(ctx, NULL) == PK_ERR_INVALID_ARGUMENT);
    CHECK(pk_context_set_config(NULL, "cpu.isa=avx2") == PK_ERR_INVALID_ARGUMENT);
    pk_context_clear_error(ctx);
    pk_context_get_config(ctx, buf, sizeof buf);
    CHECKF(strstr(buf, "cpu.isa=avx2,bvh.quality=fast,embree.quality=high,") == buf, "config changed: %s", buf);
    /* an empty value restores the default */
    CHECK(pk_context_set_config(ctx, "cpu.isa=,bvh.quality=,embree.quality=,embree.library=,cuda.library=,scene.instances=,"
                                     "cuda.traversal=,cuda.leaf=,openvdb.module=,cuda.module=,draco.module=") ==
          PK_OK);
    pk_context_get_config(ctx, buf, sizeof buf);
    CHECKF(strcmp(buf, defaults) == 0, "config after reset: %s", buf);
}

/* The device field: names, and PK_ACCEL_CUDA and PK_DEVICE_CUDA checked alike. */
static void check_device(void)
{
    pk_device_kind k = PK_DEVICE_CUDA;
    CHECK(pk_device_parse("cpu", &k) == PK_OK && k == PK_DEVICE_CPU);
    CHECK(pk_device_parse("cuda", &k) == PK_OK && k == PK_DEVICE_CUDA);
    CHECK(pk_device_parse("gpu", &k) == PK_ERR_INVALID_ARGUMENT && pk_device_parse(NULL, &k) == PK_ERR_INVALID_ARGUMENT);
    CHECK(strcmp(pk_device_name(PK_DEVICE_CPU), "cpu") == 0 && strcmp(pk_device_name(PK_DEVICE_CUDA), "cuda") == 0);
    pk_render_options o;
    pk_render_options_init(&o);
    CHECK(o.device == PK_DEVICE_CPU);
    o.device = (pk_device_kind)7;
    CHECK(pk_render_options_check(ctx, &o) == PK_ERR_INVALID_ARGUMENT && strstr(pk_context_error(ctx), "device"));
    pk_context_clear_error(ctx);
    /* energy compensation: off by default, 0 or 1 */
    pk_render_options_init(&o);
    CHECK(o.energy_compensation == 0);
    o.energy_compensation = 1;
    CHECK(pk_render_options_check(ctx, &o) == PK_OK);
    o.energy_compensation = 2;
    CHECK(pk_render_options_check(ctx, &o) == PK_ERR_INVALID_ARGUMENT &&
          strstr(pk_context_error(ctx), "energy compensation 2 is not 0 or 1"));
    pk_context_clear_error(ctx);
    const int gpu = pk_accel_available(PK_ACCEL_CUDA);
    for (int spelling = 0; spelling < 2; spelling++) {
        pk_render_options_init(&o);
        if (spelling) o.accel = PK_ACCEL_CUDA;
        else o.device = PK_DEVICE_CUDA;
        o.integrator = PK_INTEGRATOR_WHITTED;
        CHECK(pk_render_options_check(ctx, &o) == PK_ERR_UNSUPPORTED);
        pk_context_clear_error(ctx);
        o.integrator = PK_INTEGRATOR_PATH;
        CHECK(pk_render_options_check(ctx, &o) == (gpu ? PK_OK : PK_ERR_UNSUPPORTED));
        pk_context_clear_error(ctx);
    }
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    size_t n = 0;
    const pk_int_option *t = pk_int_options(&n);
    REQUIRE(t && n >= 6);
    const char *expected[] = {"width", "height", "spp", "light_samples", "max_depth", "threads"};
    for (size_t k = 0; k < sizeof expected / sizeof *expected; k++) {
        const pk_int_option *e = pk_int_option_find(expected[k]);
        CHECKF(e != NULL, "no table entry %s", expected[k]);
    }
    CHECK(pk_int_option_find("light-samples") == pk_int_option_find("light_samples"));
    CHECK(pk_int_option_find("light") == NULL && pk_int_option_find("") == NULL && pk_int_option_find(NULL) == NULL);
    /* the defaults are the table's */
    pk_render_options d;
    pk_render_options_init(&d);
    for (size_t i = 0; i < n; i++) {
        const pk_int_option *e = &t[i];
        CHECKF(e->min <= e->default_value && e->default_value <= e->max, "%s default outside its range", e->name);
        CHECKF(*(const int *)(const void *)((const char *)&d + e->offset) == e->default_value, "%s default", e->name);
        CHECK(e->label && e->label[0] && e->help && e->help[0]);
    }
    CHECK(pk_render_options_check(ctx, &d) == PK_OK);
    const bool cli = access(PK_CLI, X_OK) == 0;
    if (!cli) printf("note: %s is not built; the program's part is not checked\n", PK_CLI);
    for (size_t i = 0; i < n; i++) {
        const pk_int_option *e = &t[i];
        /* one past a bound that is INT_MIN or INT_MAX cannot be stored in the
         * int field: the API part is checked at the bound only there */
        const long long ok[2] = {e->min, e->max}, bad[2] = {(long long)e->min - 1, (long long)e->max + 1};
        for (int k = 0; k < 2; k++) {
            check_api(e, (int)ok[k], true);
            if (bad[k] >= INT_MIN && bad[k] <= INT_MAX) check_api(e, (int)bad[k], false);
            check_json(e, ok[k], true);
            check_json(e, bad[k], false);
            if (cli) {
                check_cli(e, ok[k], true);
                check_cli(e, bad[k], false);
            }
        }
    }
    check_context_config();
    check_device();
    remove("options_test.png");
    remove("options_test.out");
    pk_context_destroy(ctx);
    return test_done("test_options");
}
