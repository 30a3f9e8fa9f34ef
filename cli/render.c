/*
 * render.c - `paprsek render`: loads a scene (or the built-in Cornell box),
 * applies the command-line overrides, renders, writes the image and prints
 * the seed's statistics table. SIGINT/SIGTERM stop the render cleanly.
 */
#include "cli.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static volatile sig_atomic_t g_stop; /* set by the signal handler only */
static volatile int g_cancel;        /* the render's cancel flag (an int in the API) */
_Static_assert(sizeof(sig_atomic_t) == sizeof(int), "the cancel flag is written by a signal handler");

static void on_signal(int sig)
{
    g_stop = sig;
    g_cancel = 1;
}

static void help(void)
{
    printf("usage: paprsek render [SCENE] -o OUT [options]\n"
           "\n"
           "SCENE is a Wavefront .obj (materials from its .mtl files) or a .json scene\n"
           "(docs/scene-format.md); without it the built-in Cornell box is rendered.\n"
           "OUT is written by extension: .png (8-bit sRGB) or .pfm (linear float RGB),\n"
           "through a temporary file that is renamed into place.\n"
           "\n"
           "options (they override the scene's own \"render\" settings):\n"
           "  -o, --output FILE      the image to write (required)\n"
           "  --width W, --height H  image size in pixels (default 512x512)\n"
           "  --spp N                samples per pixel, stratified jitter (default 1: pixel centres)\n"
           "  --light-samples N      shadow samples per shading point over the area lights\n"
           "                         (emissive triangles, chosen by power; default 32)\n"
           "  --max-depth N          reflection/refraction depth (default 8)\n"
           "  --threads N            worker threads (default: all cores)\n"
           "  --accel NAME           bvh (default), midpoint (the seed's BVH), none, embree\n"
           "  --fresnel on|off       exact dielectric Fresnel (default on); off = fixed Ks/Tf mix\n"
           "  --look-from x,y,z      camera position\n"
           "  --look-at x,y,z        camera target\n"
           "  --up x,y,z             camera up vector (default 0,1,0)\n"
           "  --fov DEG              vertical field of view in degrees\n"
           "  --stats                print the statistics table (rays, tests, nodes, times)\n"
           "  --stats-json FILE      write the statistics as JSON\n"
           "  --quiet                do not print warnings\n"
           "  -h, --help             this text\n"
           "\n"
           "On SIGINT or SIGTERM the render stops, the finished tiles are written to\n"
           "OUT with '.partial' before the extension, OUT itself is left untouched and\n"
           "the exit status is 130.\n");
}

typedef struct cli_opts {
    const char *scene, *out, *stats_json;
    int stats, quiet;
    int width, height, spp, light_samples, max_depth, threads, fresnel;
    int has_accel;
    pk_accel_kind accel;
    int has_from, has_at, has_up, has_fov;
    float from[3], at[3], up[3], fov;
} cli_opts;

static int need_arg(int i, int argc, const char *opt)
{
    if (i + 1 >= argc) {
        cli_usage_error("%s needs a value", opt);
        return 0;
    }
    return 1;
}

static int parse_args(int argc, char **argv, cli_opts *o)
{
    memset(o, 0, sizeof *o);
    o->width = o->height = o->spp = o->light_samples = o->max_depth = o->threads = o->fresnel = -1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
#define INT_OPT(name, field, lo, hi)                                                          \
    if (strcmp(a, name) == 0) {                                                               \
        if (!need_arg(i, argc, a)) return 2;                                                  \
        if (!cli_parse_int(argv[++i], lo, hi, &o->field))                                     \
            return cli_usage_error("%s: '%s' is not a whole number in %ld..%ld", name, argv[i], \
                                   (long)(lo), (long)(hi));                                   \
        continue;                                                                             \
    }
#define VEC_OPT(name, field, flag)                                                            \
    if (strcmp(a, name) == 0) {                                                               \
        if (!need_arg(i, argc, a)) return 2;                                                  \
        if (!cli_parse_vec3(argv[++i], o->field))                                             \
            return cli_usage_error("%s: '%s' is not x,y,z (three finite numbers)", name, argv[i]); \
        o->flag = 1;                                                                          \
        continue;                                                                             \
    }
        INT_OPT("--width", width, 1, PK_MAX_IMAGE_SIDE)
        INT_OPT("--height", height, 1, PK_MAX_IMAGE_SIDE)
        INT_OPT("--spp", spp, 1, PK_MAX_SPP)
        INT_OPT("--light-samples", light_samples, 0, PK_MAX_LIGHT_SAMPLES)
        INT_OPT("--max-depth", max_depth, 0, PK_MAX_DEPTH)
        INT_OPT("--threads", threads, 1, PK_MAX_THREADS)
        VEC_OPT("--look-from", from, has_from)
        VEC_OPT("--look-at", at, has_at)
        VEC_OPT("--up", up, has_up)
#undef INT_OPT
#undef VEC_OPT
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            help();
            return -1;
        } else if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
            if (!need_arg(i, argc, a)) return 2;
            o->out = argv[++i];
        } else if (strcmp(a, "--stats-json") == 0) {
            if (!need_arg(i, argc, a)) return 2;
            o->stats_json = argv[++i];
        } else if (strcmp(a, "--stats") == 0) {
            o->stats = 1;
        } else if (strcmp(a, "--quiet") == 0) {
            o->quiet = 1;
        } else if (strcmp(a, "--accel") == 0) {
            if (!need_arg(i, argc, a)) return 2;
            if (pk_accel_kind_parse(argv[++i], &o->accel) != PK_OK)
                return cli_usage_error("--accel: unknown accelerator '%s' (none, midpoint, bvh, embree)", argv[i]);
            if (!pk_accel_available(o->accel))
                return cli_usage_error("--accel %s: not available in this build (install libembree-dev and rebuild)",
                                       argv[i]);
            o->has_accel = 1;
        } else if (strcmp(a, "--fresnel") == 0) {
            if (!need_arg(i, argc, a)) return 2;
            const char *v = argv[++i];
            if (strcmp(v, "on") == 0)
                o->fresnel = 1;
            else if (strcmp(v, "off") == 0)
                o->fresnel = 0;
            else
                return cli_usage_error("--fresnel: expected on or off, not '%s'", v);
        } else if (strcmp(a, "--fov") == 0) {
            if (!need_arg(i, argc, a)) return 2;
            char *end;
            o->fov = strtof(argv[++i], &end);
            if (*end || end == argv[i] || !(o->fov > 0.0f && o->fov < 180.0f))
                return cli_usage_error("--fov: '%s' must be a number of degrees between 0 and 180", argv[i]);
            o->has_fov = 1;
        } else if (a[0] == '-' && a[1] != '\0') {
            return cli_usage_error("render: unknown option '%s' (see paprsek render --help)", a);
        } else if (!o->scene) {
            o->scene = a;
        } else {
            return cli_usage_error("render: more than one scene given ('%s' and '%s')", o->scene, a);
        }
    }
    if (!o->out) return cli_usage_error("render: no output file (-o OUT.png)");
    return 0;
}

/* True when path ends with ext (ASCII, any case). */
static int ends_with_ci(const char *path, const char *ext)
{
    size_t lp = strlen(path), le = strlen(ext);
    if (lp < le) return 0;
    for (size_t i = 0; i < le; i++) {
        char c = path[lp - le + i];
        if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
        if (c != ext[i]) return 0;
    }
    return 1;
}

/* True when a and b name the same existing file. */
static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (stat(a, &sa) != 0 || stat(b, &sb) != 0) return 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

static void print_table(const char *scene, const pk_render_options *ro, const pk_stats *st)
{
    uint64_t rays = st->rays_camera + st->rays_shadow + st->rays_reflection + st->rays_refraction;
    double r = rays ? (double)rays : 1.0;
    printf("%-28s %s\n", "scene", scene);
    printf("%-28s %s, %d thread%s, %dx%d, %d spp, %d light samples, depth %d, fresnel %s\n", "settings",
           pk_accel_kind_name(ro->accel), st->threads, st->threads == 1 ? "" : "s", ro->width, ro->height, ro->spp,
           ro->light_samples, ro->max_depth, ro->fresnel ? "on" : "off");
    printf("%-28s %.0f\n", "build [us]", st->build_us);
    printf("%-28s %.3f\n", "render [s]", st->render_s);
    printf("%-28s %llu (camera %llu, shadow %llu, reflection %llu, refraction %llu)\n", "rays",
           (unsigned long long)rays, (unsigned long long)st->rays_camera, (unsigned long long)st->rays_shadow,
           (unsigned long long)st->rays_reflection, (unsigned long long)st->rays_refraction);
    printf("%-28s %llu\n", "intersection tests", (unsigned long long)st->intersection_tests);
    printf("%-28s %llu\n", "nodes traversed", (unsigned long long)st->nodes_visited);
    printf("%-28s %.2f\n", "tests/ray", (double)st->intersection_tests / r);
    printf("%-28s %.2f\n", "nodes/ray", (double)st->nodes_visited / r);
    printf("%-28s %.4f\n", "traversal time/ray [us]", st->render_s * st->threads / r * 1e6);
    printf("%-28s %.2f\n", "Mrays/s", st->render_s > 0 ? (double)rays / st->render_s / 1e6 : 0.0);
}

/* Writes s as a JSON string literal. */
static void json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

static int write_stats_json(const char *path, const char *scene, const pk_render_options *ro, const pk_stats *st)
{
    uint64_t rays = st->rays_camera + st->rays_shadow + st->rays_reflection + st->rays_refraction;
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        return 1;
    }
    fputs("{\n  \"scene\": ", f);
    json_string(f, scene);
    fprintf(f,
            ",\n  \"accel\": \"%s\",\n  \"width\": %d,\n  \"height\": %d,\n  \"spp\": %d,\n"
            "  \"light_samples\": %d,\n  \"max_depth\": %d,\n  \"fresnel\": %s,\n  \"threads\": %d,\n"
            "  \"build_us\": %.1f,\n  \"render_s\": %.6f,\n  \"rays\": %llu,\n  \"rays_camera\": %llu,\n"
            "  \"rays_shadow\": %llu,\n  \"rays_reflection\": %llu,\n  \"rays_refraction\": %llu,\n"
            "  \"intersection_tests\": %llu,\n  \"nodes_visited\": %llu,\n  \"mrays_per_s\": %.3f\n}\n",
            pk_accel_kind_name(ro->accel), ro->width, ro->height, ro->spp, ro->light_samples, ro->max_depth,
            ro->fresnel ? "true" : "false", st->threads, st->build_us, st->render_s, (unsigned long long)rays,
            (unsigned long long)st->rays_camera, (unsigned long long)st->rays_shadow,
            (unsigned long long)st->rays_reflection, (unsigned long long)st->rays_refraction,
            (unsigned long long)st->intersection_tests, (unsigned long long)st->nodes_visited,
            st->render_s > 0 ? (double)rays / st->render_s / 1e6 : 0.0);
    if (fclose(f) != 0) {
        perror(path);
        return 1;
    }
    return 0;
}

/* "dir/name.png" -> "dir/name.partial.png" */
static char *partial_name(const char *out)
{
    size_t n = strlen(out);
    const char *dot = strrchr(out, '.');
    const char *slash = strrchr(out, '/');
    if (!dot || (slash && dot < slash)) dot = out + n;
    char *p = malloc(n + 16);
    if (!p) return NULL;
    size_t head = (size_t)(dot - out);
    memcpy(p, out, head);
    strcpy(p + head, ".partial");
    strcat(p, dot);
    return p;
}

int cli_render(int argc, char **argv)
{
    cli_opts o;
    int rc = parse_args(argc, argv, &o);
    if (rc) return rc < 0 ? 0 : rc;
    /* Everything that would only fail after the render is checked first. */
    if (!ends_with_ci(o.out, ".png") && !ends_with_ci(o.out, ".pfm"))
        return cli_usage_error("%s: unknown image format (use .png or .pfm)", o.out);
    if (o.scene && same_file(o.scene, o.out))
        return cli_usage_error("render: refusing to write the image over the scene file '%s'", o.scene);
    if (o.stats_json && o.scene && same_file(o.scene, o.stats_json))
        return cli_usage_error("render: refusing to write the statistics over the scene file '%s'", o.scene);
    if (o.stats_json && (strcmp(o.stats_json, o.out) == 0 || same_file(o.stats_json, o.out)))
        return cli_usage_error("render: --stats-json and -o name the same file '%s'", o.out);

    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) {
        fprintf(stderr, "paprsek: out of memory\n");
        return 1;
    }
    if (!o.quiet) pk_context_set_warning_handler(ctx, cli_print_warning, NULL);
    pk_scene *scene = NULL;
    pk_image *img = NULL;
    rc = 1;
    pk_status st = o.scene ? pk_scene_load_file(ctx, o.scene, &scene) : pk_scene_create_cornell_box(ctx, &scene);
    if (st != PK_OK) goto fail;

    pk_render_options ro;
    pk_scene_get_render_options(scene, &ro);
    if (o.width > 0) ro.width = o.width;
    if (o.height > 0) ro.height = o.height;
    if (o.spp > 0) ro.spp = o.spp;
    if (o.light_samples >= 0) ro.light_samples = o.light_samples;
    if (o.max_depth >= 0) ro.max_depth = o.max_depth;
    if (o.threads > 0) ro.threads = o.threads;
    if (o.fresnel >= 0) ro.fresnel = o.fresnel;
    if (o.has_accel) ro.accel = o.accel;
    ro.collect_stats = o.stats || o.stats_json;
    ro.cancel = &g_cancel;

    if (o.has_from || o.has_at || o.has_up || o.has_fov) {
        pk_camera cam;
        pk_scene_get_camera(scene, &cam);
        if (o.has_from) memcpy(cam.look_from, o.from, sizeof o.from);
        if (o.has_at) memcpy(cam.look_at, o.at, sizeof o.at);
        if (o.has_up) memcpy(cam.up, o.up, sizeof o.up);
        if (o.has_fov) cam.fov_deg = o.fov;
        if (pk_scene_set_camera(ctx, scene, &cam) != PK_OK) goto fail;
    }

    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    pk_stats stats;
    st = pk_render(ctx, scene, &ro, &img, &stats);
    if (st == PK_ERR_CANCELLED) {
        char *partial = partial_name(o.out);
        if (partial && img && pk_image_write(ctx, img, partial) == PK_OK)
            fprintf(stderr, "paprsek: interrupted; finished tiles written to %s\n", partial);
        else
            fprintf(stderr, "paprsek: interrupted\n");
        free(partial);
        rc = 130;
        goto out;
    }
    if (st != PK_OK) goto fail;
    if (pk_image_write(ctx, img, o.out) != PK_OK) goto fail;
    const char *name = o.scene ? o.scene : "cornell-box (built in)";
    if (o.stats) print_table(name, &ro, &stats);
    if (o.stats_json && write_stats_json(o.stats_json, name, &ro, &stats) != 0) goto out;
    rc = 0;
    goto out;
fail:
    rc = cli_fail_ctx(ctx);
out:
    pk_image_destroy(img);
    pk_scene_destroy(scene);
    pk_context_destroy(ctx);
    return rc;
}
