/*
 * render_common.c - what `paprsek render` and paprsek-mpi share: the render
 * options (one table for parsing, ranges and --help), the checks made before
 * any work, the settings a scene gets from the command line, the outputs
 * (image, AOVs, OUT.partial) and the statistics.
 */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <sys/resource.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* ---- the options: one table for parsing, ranges and --help ---------------- */

enum {
    OPT_OUTPUT = 1,
    OPT_EXPOSURE,
    OPT_TONEMAP,
    OPT_TRANSPARENT,
    OPT_CAMERA_ORBIT,
    OPT_INT, /* an integer render option of the library's table */
    OPT_ACCEL,
    OPT_DEVICE,
    OPT_CONFIG,
    OPT_INTEGRATOR,
    OPT_FRESNEL,
    OPT_ENERGY,
    OPT_CLAMP_INDIRECT,
    OPT_FILTER,
    OPT_LOOK_FROM,
    OPT_LOOK_AT,
    OPT_UP,
    OPT_FOV,
    OPT_LENS_RADIUS,
    OPT_FOCUS_DISTANCE,
    OPT_ORTHOGRAPHIC,
    OPT_PERSPECTIVE,
    OPT_TIME,
    OPT_NOISE,
    OPT_MIN_SPP,
    OPT_ENV,
    OPT_AOV,
    OPT_STATS,
    OPT_STATS_JSON,
    OPT_DEFINE,
    OPT_CAMERA,
    OPT_VARIANT,
    OPT_QUIET,
    OPT_DENOISE,
    OPT_NO_DENOISE,
    OPT_DENOISE_QUALITY,
    OPT_WEIGHTS,
    OPT_HELP
};

#define MAX_RENDER_OPTIONS CLI_RENDER_MAX_OPTIONS
static cli_option g_opts[MAX_RENDER_OPTIONS];
static char g_int_names[MAX_RENDER_OPTIONS][64];
static size_t g_nopts;
static cli_option g_extra[CLI_RENDER_MAX_EXTRA]; /* a program's own options */
static size_t g_nextra;

void cli_render_add_option(cli_option o)
{
    if (g_nopts == 0 && g_nextra < CLI_RENDER_MAX_EXTRA) g_extra[g_nextra++] = o;
}

static void add(cli_option o)
{
    if (g_nopts < MAX_RENDER_OPTIONS) g_opts[g_nopts++] = o;
}

/* The table: -o first, the library's integer options (pk_int_options) in
 * its order, then the rest. Built once. */
const cli_option *cli_render_options(size_t *n)
{
    if (g_nopts == 0) {
        add((cli_option){.name = "output", .short_name = 'o', .id = OPT_OUTPUT, .kind = CLI_STRING, .arg = "FILE",
                         .help = "the image to write (required): .png (8-bit sRGB), .pfm or .exr (linear "
                                 "float RGB)"});
        add((cli_option){.name = "exposure", .id = OPT_EXPOSURE, .kind = CLI_STRING, .arg = "EV",
                         .help = "PNG only: multiply the linear values by 2^EV before the tone curve; a number "
                                 "in -20..20, default 0 (.pfm and .exr are written unscaled)"});
        add((cli_option){.name = "tonemap", .id = OPT_TONEMAP, .kind = CLI_STRING, .arg = "CURVE",
                         .help = "PNG only: the tone curve after the exposure: clamp (default: values above 1 "
                                 "clipped), agx (Blender's AgX), pbr-neutral (Khronos PBR Neutral), aces (Hill's "
                                 "fit of ACES); .pfm and .exr stay linear and untouched"});
        add((cli_option){.name = "transparent", .id = OPT_TRANSPARENT, .kind = CLI_FLAG,
                         .help = "transparent background: what the camera sees of the environment gets alpha 0 "
                                 "(the environment still lights the scene); PNG becomes RGBA, .exr gets a "
                                 "channel A (colour premultiplied); not with .pfm, nor on the GPU"});
        size_t count = 0;
        const pk_int_option *ints = pk_int_options(&count);
        for (size_t i = 0; i < count && g_nopts < MAX_RENDER_OPTIONS; i++) {
            cli_option o = cli_option_from_render(&ints[i], g_int_names[g_nopts], sizeof g_int_names[0]);
            o.id = OPT_INT;
            add(o);
        }
        add((cli_option){.name = "accel", .id = OPT_ACCEL, .kind = CLI_STRING, .arg = "NAME",
                         .help = "the acceleration structure: bvh (default: binned SAH, wide SIMD BVH, AVX-512 where the CPU has it), midpoint "
                                 "(simple BVH, for comparison), none (every ray tests every primitive), embree "
                                 "(Embree 3, when built with it); all give the same image; cuda: render on the "
                                 "GPU (the same as --device cuda)"});
        add((cli_option){.name = "device", .id = OPT_DEVICE, .kind = CLI_STRING, .arg = "cpu|cuda",
                         .help = "where to render: cpu (default) or cuda (an NVIDIA GPU: the path tracer, "
                                 "triangles only, on the GPU's own BVH; the same image as the CPU's up to noise)"});
        add((cli_option){.name = "config", .id = OPT_CONFIG, .kind = CLI_STRING, .arg = "KEY=VALUE,...",
                         .help = "settings of the library's back ends: cpu.isa=auto|avx2, bvh.quality=high|fast, "
                                 "embree.quality=low|medium|high, embree.library=FILE, cuda.library=FILE, "
                                 "cuda.module=FILE, openvdb.module=FILE, draco.module=FILE, "
                                 "scene.instances=auto|flatten|keep (README, Configuration); they override the "
                                 "environment variables "
                                 "PAPRSEK_CPU_ISA, PAPRSEK_BVH_QUALITY, PAPRSEK_EMBREE_QUALITY, "
                                 "PAPRSEK_EMBREE_LIBRARY and PAPRSEK_CUDA_LIBRARY, which are passed on as these keys"});
        add((cli_option){.name = "integrator", .id = OPT_INTEGRATOR, .kind = CLI_STRING, .arg = "NAME",
                         .help = "path (path tracing, global illumination, one-sided area lights; the default), "
                                 "volpath (path tracing through participating media: fog, smoke, subsurface; the "
                                 "default for scenes with media) or whitted (direct light, mirrors and glass; "
                                 "emitters two-sided)"});
        add((cli_option){.name = "fresnel", .id = OPT_FRESNEL, .kind = CLI_STRING, .arg = "on|off",
                         .help = "on: exact dielectric Fresnel (default); off: fixed Ks/Tf weights"});
        add((cli_option){.name = "energy-compensation", .id = OPT_ENERGY, .kind = CLI_STRING, .arg = "on|off",
                         .help = "path tracers: on gives back the light that rough metals, glass and coatings "
                                 "lose between their microfacets (brighter rough surfaces, as Cycles and glTF "
                                 "viewers render them); off: single scattering only. Default: on for glTF "
                                 "scenes, else off (or the scene's render setting)"});
        add((cli_option){.name = "clamp-indirect", .id = OPT_CLAMP_INDIRECT, .kind = CLI_STRING, .arg = "X",
                         .help = "path tracer: scale down the light each sample brings after a bounce so that "
                                 "no channel exceeds X (fewer fireflies, a darker, biased image); 0 = off "
                                 "(default)"});
        add((cli_option){.name = "filter", .id = OPT_FILTER, .kind = CLI_STRING, .arg = "NAME[:KEY=V,...]",
                         .help = "the pixel filter, replacing the scene's: box (radius 0.5, the default for OBJ, "
                                 "JSON and the built-in scene), triangle (2), gaussian (1.5, sigma=0.5: the "
                                 "default for pbrt-v4 and Mitsuba scenes), mitchell (2, b=1/3, c=1/3), "
                                 "blackman-harris (1.5) or lanczos (4, tau=3); keys: radius=R (both axes), "
                                 "xradius=R, yradius=R (pixels, at most 16) and the filter's own (sigma, b, c, "
                                 "tau), e.g. gaussian:radius=2,sigma=0.7"});
        add((cli_option){.name = "look-from", .id = OPT_LOOK_FROM, .kind = CLI_STRING, .arg = "X,Y,Z",
                         .help = "camera position"});
        add((cli_option){.name = "look-at", .id = OPT_LOOK_AT, .kind = CLI_STRING, .arg = "X,Y,Z",
                         .help = "camera target"});
        add((cli_option){.name = "up", .id = OPT_UP, .kind = CLI_STRING, .arg = "X,Y,Z",
                         .help = "camera up vector (default 0,1,0)"});
        add((cli_option){.name = "time", .id = OPT_TIME, .kind = CLI_STRING, .arg = "SECONDS",
                         .help = "render passes of --spp samples per pixel until SECONDS have passed (at least "
                                 "one pass); the image is the mean of all passes"});
        add((cli_option){.name = "noise", .id = OPT_NOISE, .kind = CLI_STRING, .arg = "X",
                         .help = "adaptive sampling: render passes of one sample per pixel over the 16x16 tiles "
                                 "whose estimated relative error is still above X (e.g. 0.05: 5 %), from the "
                                 "difference of two halves of the samples; each pixel gets at least --min-spp "
                                 "samples and at most --spp (default 1024 with --noise); --time still stops the "
                                 "render. The statistics say how many samples went where"});
        add((cli_option){.name = "min-spp", .id = OPT_MIN_SPP, .kind = CLI_STRING, .arg = "N",
                         .help = "with --noise: the samples every pixel gets before its tile may stop (default 16)"});
        add((cli_option){.name = "env", .id = OPT_ENV, .kind = CLI_STRING, .arg = "SPEC",
                         .help = "the light from the surroundings, replacing the scene's: none (black), R,G,B "
                                 "or V (a constant radiance), or an image FILE (lat-long, +y up: .hdr, .exr, "
                                 ".pfm, .png, .jpg). A scene without lights and without an environment is lit "
                                 "by a white one of radiance 1"});
        add((cli_option){.name = "aov", .id = OPT_AOV, .kind = CLI_STRING, .arg = "LIST",
                         .help = "also write these outputs, from the camera rays: albedo, normal, depth, "
                                 "heatmap (nodes visited + primitives tested per camera ray), alpha (coverage), "
                                 "samples (samples per pixel: where --noise spent them), comma-separated; "
                                 "layers NAME.R/G/B of an .exr OUT, else files beside OUT as NAME.AOV.EXT"});
        add((cli_option){.name = "camera-orbit", .id = OPT_CAMERA_ORBIT, .kind = CLI_STRING,
                         .arg = "THETA,PHI,RADIUS",
                         .help = "place the camera on a sphere about the centre of the scene's bounds, looking "
                                 "at it, as model-viewer's camera-orbit: THETA degrees around the y axis from +z, "
                                 "PHI degrees down from +y (90: level), RADIUS a distance or auto (the bounding "
                                 "sphere just fills the vertical field of view); --look-at moves the centre, "
                                 "--look-from is then ignored"});
        add((cli_option){.name = "fov", .id = OPT_FOV, .kind = CLI_STRING, .arg = "DEG",
                         .help = "vertical field of view in degrees, between 0 and 180"});
        add((cli_option){.name = "lens-radius", .id = OPT_LENS_RADIUS, .kind = CLI_STRING, .arg = "R",
                         .help = "a thin lens of radius R (scene units) for depth of field: only what lies at "
                                 "--focus-distance is sharp; 0 is a pinhole (everything sharp)"});
        add((cli_option){.name = "focus-distance", .id = OPT_FOCUS_DISTANCE, .kind = CLI_STRING, .arg = "D",
                         .help = "the distance along the view to the plane in focus (with --lens-radius); 0 "
                                 "(default) is the distance from --look-from to --look-at"});
        add((cli_option){.name = "orthographic", .id = OPT_ORTHOGRAPHIC, .kind = CLI_STRING, .arg = "WIDTH",
                         .help = "an orthographic projection: parallel rays along the view, the view WIDTH "
                                 "scene units wide (the height follows the image's aspect); 0 is the width "
                                 "the perspective view has at --look-at"});
        add((cli_option){.name = "perspective", .id = OPT_PERSPECTIVE, .kind = CLI_FLAG,
                         .help = "the perspective projection (--fov), also where the scene's camera is "
                                 "orthographic"});
        add((cli_option){.name = "stats", .id = OPT_STATS, .kind = CLI_FLAG,
                         .help = "print the statistics table on standard output (rays, intersection tests, "
                                 "nodes, build and render time)"});
        add((cli_option){.name = "stats-json", .id = OPT_STATS_JSON, .kind = CLI_STRING, .arg = "FILE",
                         .help = "write the statistics as JSON to FILE; - writes them to standard output"});
        add((cli_option){.name = "define", .short_name = 'D', .id = OPT_DEFINE, .kind = CLI_STRING, .arg = "NAME=VALUE",
                         .help = "set the parameter $NAME of a Mitsuba XML scene over its <default> value "
                                 "(may be repeated, up to 64 times)"});
        add((cli_option){.name = "camera", .id = OPT_CAMERA, .kind = CLI_STRING, .arg = "N",
                         .help = "a glTF asset (.gltf, .glb): render its camera N (its cameras array, from "
                                 "0); without it the first camera in node order"});
        add((cli_option){.name = "variant", .id = OPT_VARIANT, .kind = CLI_STRING, .arg = "NAME",
                         .help = "a glTF asset with material variants (KHR_materials_variants): draw its "
                                 "variant NAME (without it the default materials); an unknown name is an "
                                 "error that lists the asset's variants"});
        add((cli_option){.name = "denoise", .id = OPT_DENOISE, .kind = CLI_FLAG,
                         .help = "denoise the image (Open Image Denoise's network, with the albedo and normal of "
                                 "the same render); the default when neither --spp nor --time nor the scene "
                                 "names a sample count, which then takes 16 samples per pixel (measured: the "
                                 "denoised error falls 2.5x from 4 to 16 samples and slowly after; "
                                 "docs/denoising.md)"});
        add((cli_option){.name = "no-denoise", .id = OPT_NO_DENOISE, .kind = CLI_FLAG,
                         .help = "write the raw image, also in the default case"});
        add((cli_option){.name = "denoise-quality", .id = OPT_DENOISE_QUALITY, .kind = CLI_STRING, .arg = "high|fast",
                         .help = "the denoiser's network: high (default) or fast (the small one, about 1.6x "
                                 "faster)"});
        add((cli_option){.name = "weights", .id = OPT_WEIGHTS, .kind = CLI_STRING, .arg = "DIR",
                         .help = "the folder of the denoiser's weights (default: beside the program, where "
                                 "`make weights` puts them, or the installed share/paprsek/weights)"});
        add((cli_option){.name = "quiet", .short_name = 'q', .id = OPT_QUIET, .kind = CLI_FLAG,
                         .help = "no progress bar, no 'wrote' line, no warnings (errors are still printed)"});
        for (size_t i = 0; i < g_nextra; i++) add(g_extra[i]);
        add((cli_option){.name = "help", .short_name = 'h', .id = OPT_HELP, .kind = CLI_FLAG, .help = "this text"});
    }
    *n = g_nopts;
    return g_opts;
}

void cli_render_usage(FILE *f, const char *usage_line)
{
    size_t n;
    const cli_option *opts = cli_render_options(&n);
    fputs(usage_line, f);
    fputs("\n"
          "SCENE is a Wavefront .obj (materials from its .mtl files), a .json scene,\n"
          "a Mitsuba .xml scene, a pbrt-v4 .pbrt scene or a glTF 2.0 asset (.gltf,\n"
          ".glb) (docs/scene-format.md);\n"
          "without it the built-in Cornell box is rendered.\n"
          "OUT is written by extension, through a temporary file that is renamed into\n"
          "place. Its folder is checked before the scene is read: it must exist and be\n"
          "writable. The formats:\n"
          "  .png  8-bit sRGB. Tone curve (clamp): each linear value v becomes\n"
          "        x = v * 2^EV (--exposure, default 0); x <= 0 gives 0, x >= 1 gives\n"
          "        255, else the sRGB curve s = 12.92 x (x <= 0.0031308) or\n"
          "        1.055 x^(1/2.4) - 0.055, stored as floor(255 s + 0.5). --tonemap agx,\n"
          "        pbr-neutral or aces compress x instead of clipping it. With\n"
          "        --transparent: RGBA, colour divided by alpha (the pixel's coverage).\n"
          "  .pfm  linear 32-bit float RGB, the rendered values unchanged (no alpha).\n"
          "  .exr  OpenEXR, linear 32-bit float channels R, G, B, the rendered values\n"
          "        unchanged (scanlines, lossless ZIP compression); with --transparent\n"
          "        also A, and R, G, B premultiplied by it. Never tone-mapped.\n"
          "\n"
          "options (they override the scene's own \"render\" settings; --name VALUE and\n"
          "--name=VALUE are the same, and a unique beginning of a name is enough):\n",
          f);
    cli_print_options(f, opts, n);
    fputs("\n"
          "When stderr is a terminal, a progress bar (percentage, elapsed time, ETA)\n"
          "is redrawn there, and at the end one line says what was written, e.g.\n"
          "\"wrote cornell.png (512x512, 1.2 s)\" (the time from start to finish).\n"
          "Otherwise, and with --quiet, stderr carries only warnings and errors.\n"
          "\n"
          "exit status:\n"
          "  0    the image was written\n"
          "  1    a runtime failure: a file that cannot be read or written, a malformed\n"
          "       scene, a scene beyond the limits\n"
          "  2    a usage error: unknown option, bad value, unknown image format\n"
          "  130  interrupted by SIGINT (Ctrl-C)\n"
          "  143  interrupted by SIGTERM\n"
          "On SIGINT or SIGTERM the render stops, the finished tiles are written to\n"
          "OUT with '.partial' before the extension, and OUT itself is left untouched.\n",
          f);
}


/* --filter NAME[:KEY=VALUE,...] into *f; 0, or cli_usage_error's status. */
static int parse_filter(const char *v, pk_filter *f)
{
    char name[32];
    const char *colon = strchr(v, ':');
    const size_t n = colon ? (size_t)(colon - v) : strlen(v);
    pk_filter_type type;
    if (n >= sizeof name || (memcpy(name, v, n), name[n] = '\0', pk_filter_parse(name, &type) != PK_OK))
        return cli_usage_error("--filter: unknown filter '%.*s' (box, triangle, gaussian, mitchell, "
                               "blackman-harris, lanczos)",
                               (int)(n > 40 ? 40 : n), v);
    pk_filter_init(f, type);
    for (const char *c = colon ? colon + 1 : NULL; c && *c;) {
        const char *e = strchr(c, ',');
        const size_t len = e ? (size_t)(e - c) : strlen(c);
        const char *eq = memchr(c, '=', len);
        if (!eq) return cli_usage_error("--filter: '%.*s' is not KEY=VALUE", (int)len, c);
        const size_t klen = (size_t)(eq - c);
        char num[48];
        const size_t vlen = len - klen - 1;
        char *end = num;
        float x = NAN;
        if (vlen > 0 && vlen < sizeof num) {
            memcpy(num, eq + 1, vlen);
            num[vlen] = '\0';
            x = strtof(num, &end);
        }
        if (vlen == 0 || vlen >= sizeof num || *end || !isfinite(x))
            return cli_usage_error("--filter: %.*s needs a number", (int)len, c);
#define KEY(s) (klen == strlen(s) && strncmp(c, s, klen) == 0)
        if (KEY("radius")) f->radius_x = f->radius_y = x;
        else if (KEY("xradius")) f->radius_x = x;
        else if (KEY("yradius")) f->radius_y = x;
        else if (KEY("sigma") && type == PK_FILTER_GAUSSIAN) f->sigma = x;
        else if ((KEY("b") || KEY("B")) && type == PK_FILTER_MITCHELL) f->b = x;
        else if ((KEY("c") || KEY("C")) && type == PK_FILTER_MITCHELL) f->c = x;
        else if (KEY("tau") && type == PK_FILTER_LANCZOS) f->tau = x;
        else
            return cli_usage_error("--filter: %s has no parameter '%.*s'", pk_filter_name(type), (int)klen, c);
#undef KEY
        c = e ? e + 1 : NULL;
    }
    /* the library's own check, its message */
    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) return cli_usage_error("--filter: out of memory");
    pk_render_options ro;
    pk_render_options_init(&ro);
    ro.filter = *f;
    const pk_status st = pk_render_options_check(ctx, &ro);
    int rc = 0;
    if (st != PK_OK) rc = cli_usage_error("--filter: %s", pk_context_error(ctx));
    pk_context_destroy(ctx);
    return rc;
}

/* Whether v is a number in (0, hi], into *out. */
static int positive_number(const char *v, double hi, double *out)
{
    char *end;
    *out = strtod(v, &end);
    return !*end && end != v && *out > 0.0 && *out <= hi;
}

int cli_render_parse(int argc, char **argv, cli_render_opts *o, void (*help)(FILE *f))
{
    memset(o, 0, sizeof *o);
    o->fresnel = -1;
    o->energy = -1;
    o->denoise = -1;
    size_t n;
    const cli_option *opts = cli_render_options(&n);
    cli_parser p;
    cli_parser_init(&p, "render", opts, n, argc, argv);
    int r;
    while ((r = cli_next(&p)) != CLI_END) {
        if (r == CLI_ERROR) return 2;
        const char *v = p.value;
        if (r == CLI_ARGUMENT) {
            if (o->scene) return cli_usage_error("render: more than one scene given ('%s' and '%s')", o->scene, v);
            o->scene = v;
            continue;
        }
        const char *name = opts[p.index].name;
        switch (opts[p.index].id) {
        case OPT_OUTPUT: o->out = v; break;
        case OPT_EXPOSURE: {
            char *end;
            double ev = strtod(v, &end);
            if (*end || end == v || !(ev >= -PK_MAX_EXPOSURE_EV && ev <= PK_MAX_EXPOSURE_EV))
                return cli_usage_error("--exposure: '%s' must be a number of stops in %d..%d", v,
                                       -PK_MAX_EXPOSURE_EV, PK_MAX_EXPOSURE_EV);
            o->exposure = (float)ev;
            o->has_exposure = 1;
            break;
        }
        case OPT_TONEMAP:
            if ((o->tonemap = pk_tonemap_parse(v)) < 0)
                return cli_usage_error("--tonemap: '%s' is not a tone curve (clamp, agx, pbr-neutral, aces)", v);
            break;
        case OPT_TRANSPARENT: o->transparent = 1; break;
        case OPT_CAMERA_ORBIT: {
            float t[3] = {0.0f, 0.0f, 0.0f};
            char buf[128];
            snprintf(buf, sizeof buf, "%s", v);
            char *comma = strrchr(buf, ',');
            int ok = comma != NULL && strlen(v) < sizeof buf;
            if (ok && strcmp(comma + 1, "auto") == 0) {
                *comma = 0;
                char *e1, *e2;
                t[0] = strtof(buf, &e1);
                ok = *e1 == ',' && e1 != buf;
                if (ok) {
                    t[1] = strtof(e1 + 1, &e2);
                    ok = !*e2 && e2 != e1 + 1;
                }
                t[2] = 0.0f;
            } else if (ok) {
                ok = cli_parse_vec3(v, t) && t[2] > 0.0f;
            }
            if (!ok || !isfinite(t[0]) || !isfinite(t[1]))
                return cli_usage_error("--camera-orbit: '%s' must be THETA,PHI,RADIUS (degrees, degrees, a distance "
                                       "> 0 or auto)", v);
            memcpy(o->orbit, t, sizeof t);
            o->has_orbit = 1;
            break;
        }
        case OPT_INT:
            o->int_set[p.index] = 1;
            o->int_value[p.index] = p.int_value;
            break;
        case OPT_ACCEL: {
            pk_accel_kind k;
            if (pk_accel_kind_parse(v, &k) != PK_OK)
                return cli_usage_error("--accel: unknown accelerator '%s' (none, midpoint, bvh, embree)", v);
            if (!pk_accel_available(k))
                return cli_usage_error("--accel %s: not available in this build (%s)", v,
                                       k == PK_ACCEL_CUDA ? "rebuild where nvcc is, with -DPK_WITH_CUDA=ON"
                                                          : "install libembree-dev and rebuild");
            if (k == PK_ACCEL_CUDA) { /* a render on the GPU: the device's spelling */
                o->device = PK_DEVICE_CUDA;
                o->has_device = 1;
                o->has_accel = 0;
            } else {
                o->accel = k;
                o->has_accel = 1;
                if (o->has_device && o->device == PK_DEVICE_CUDA) o->has_device = 0;
            }
            break;
        }
        case OPT_DEVICE:
            if (pk_device_parse(v, &o->device) != PK_OK)
                return cli_usage_error("--device: unknown device '%s' (cpu, cuda)", v);
            if (o->device == PK_DEVICE_CUDA && !pk_accel_available(PK_ACCEL_CUDA))
                return cli_usage_error("--device cuda: not available in this build (rebuild where nvcc is, "
                                       "with -DPK_WITH_CUDA=ON)");
            o->has_device = 1;
            break;
        case OPT_CONFIG: o->config = v; break;
        case OPT_INTEGRATOR:
            if (pk_integrator_parse(v, &o->integrator) != PK_OK)
                return cli_usage_error("--integrator: unknown integrator '%s' (path, volpath, whitted)", v);
            o->has_integrator = 1;
            break;
        case OPT_CLAMP_INDIRECT: {
            char *end;
            const float x = strtof(v, &end);
            if (*end || end == v || !(x >= 0.0f && isfinite(x)))
                return cli_usage_error("--clamp-indirect: '%s' must be a number, 0 (off) or more", v);
            o->clamp_indirect = x;
            o->has_clamp_indirect = 1;
            break;
        }
        case OPT_FILTER:
            if (parse_filter(v, &o->filter) != 0) return 2;
            o->has_filter = 1;
            break;
        case OPT_FRESNEL:
            if (strcmp(v, "on") == 0)
                o->fresnel = 1;
            else if (strcmp(v, "off") == 0)
                o->fresnel = 0;
            else
                return cli_usage_error("--fresnel: expected on or off, not '%s'", v);
            break;
        case OPT_ENERGY:
            if (strcmp(v, "on") == 0)
                o->energy = 1;
            else if (strcmp(v, "off") == 0)
                o->energy = 0;
            else
                return cli_usage_error("--energy-compensation: expected on or off, not '%s'", v);
            break;
        case OPT_LOOK_FROM:
        case OPT_LOOK_AT:
        case OPT_UP: {
            int id = opts[p.index].id;
            float *dst = id == OPT_LOOK_FROM ? o->from : id == OPT_LOOK_AT ? o->at : o->up;
            if (!cli_parse_vec3(v, dst))
                return cli_usage_error("--%s: '%s' is not x,y,z (three finite numbers)", name, v);
            *(id == OPT_LOOK_FROM ? &o->has_from : id == OPT_LOOK_AT ? &o->has_at : &o->has_up) = 1;
            break;
        }
        case OPT_FOV: {
            char *end;
            o->fov = strtof(v, &end);
            if (*end || end == v || !(o->fov > 0.0f && o->fov < 180.0f))
                return cli_usage_error("--fov: '%s' must be a number of degrees between 0 and 180", v);
            o->has_fov = 1;
            break;
        }
        case OPT_LENS_RADIUS:
        case OPT_FOCUS_DISTANCE:
        case OPT_ORTHOGRAPHIC: {
            const int id = opts[p.index].id;
            char *end;
            const float x = strtof(v, &end);
            if (*end || end == v || !(x >= 0.0f && isfinite(x)))
                return cli_usage_error("--%s: '%s' must be a number of scene units, 0 or more", name, v);
            if (id == OPT_LENS_RADIUS) {
                o->lens_radius = x;
                o->has_lens_radius = 1;
            } else if (id == OPT_FOCUS_DISTANCE) {
                o->focus_distance = x;
                o->has_focus_distance = 1;
            } else {
                if (o->projection == PK_PROJECTION_PERSPECTIVE + 1)
                    return cli_usage_error("--orthographic and --perspective exclude each other");
                o->ortho_width = x;
                o->projection = PK_PROJECTION_ORTHOGRAPHIC + 1;
            }
            break;
        }
        case OPT_PERSPECTIVE:
            if (o->projection == PK_PROJECTION_ORTHOGRAPHIC + 1)
                return cli_usage_error("--orthographic and --perspective exclude each other");
            o->projection = PK_PROJECTION_PERSPECTIVE + 1;
            break;
        case OPT_ENV: o->env = v; break;
        case OPT_NOISE:
            if (!positive_number(v, 10.0, &o->noise))
                return cli_usage_error("--noise: '%s' must be a relative error in (0, 10], such as 0.05", v);
            break;
        case OPT_MIN_SPP: {
            char *end;
            const long ms = strtol(v, &end, 10);
            if (*end || end == v || ms < 1 || ms > 65536)
                return cli_usage_error("--min-spp: '%s' must be a whole number of samples in 1..65536", v);
            o->min_spp = (int)ms;
            break;
        }
        case OPT_TIME:
            if (!positive_number(v, 1e7, &o->time))
                return cli_usage_error("--time: '%s' must be a number of seconds in (0, 10000000]", v);
            break;
        case OPT_AOV: {
            char buf[128];
            snprintf(buf, sizeof buf, "%s", v);
            for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
                unsigned a = pk_aov_parse(tok);
                if (!a)
                    return cli_usage_error("--aov: unknown output '%s' (albedo, normal, depth, heatmap, alpha, samples)",
                                           tok);
                o->aovs |= a;
            }
            if (!o->aovs)
                return cli_usage_error("--aov: no output named (albedo, normal, depth, heatmap, alpha, samples)");
            break;
        }
        case OPT_STATS: o->stats = 1; break;
        case OPT_STATS_JSON: o->stats_json = v; break;
        case OPT_DEFINE:
            if (!strchr(v, '=') || v[0] == '=') return cli_usage_error("-D %s: expected NAME=VALUE", v);
            if (o->ndefines == sizeof o->defines / sizeof o->defines[0])
                return cli_usage_error("-D: more than %zu parameters", sizeof o->defines / sizeof o->defines[0]);
            o->defines[o->ndefines++] = v;
            break;
        case OPT_CAMERA: {
            static char param[32];
            char *end;
            long num = strtol(v, &end, 10);
            if (*end || end == v || num < 0 || num > 1000000)
                return cli_usage_error("--camera: '%s' must be a camera number (0, 1, ...)", v);
            if (o->ndefines == sizeof o->defines / sizeof o->defines[0])
                return cli_usage_error("-D: more than %zu parameters", sizeof o->defines / sizeof o->defines[0]);
            snprintf(param, sizeof param, "camera=%ld", num);
            o->defines[o->ndefines++] = param;
            o->has_camera_pick = 1;
            break;
        }
        case OPT_VARIANT: {
            static char vparam[300];
            if (!v[0] || strlen(v) > 256) return cli_usage_error("--variant: expected a variant's name");
            if (o->ndefines == sizeof o->defines / sizeof o->defines[0])
                return cli_usage_error("-D: more than %zu parameters", sizeof o->defines / sizeof o->defines[0]);
            snprintf(vparam, sizeof vparam, "variant=%s", v);
            o->defines[o->ndefines++] = vparam;
            o->has_variant = 1;
            break;
        }
        case OPT_QUIET: o->quiet = 1; break;
        case OPT_DENOISE: o->denoise = 1; break;
        case OPT_NO_DENOISE: o->denoise = 0; break;
        case OPT_DENOISE_QUALITY:
            if (strcmp(v, "high") == 0)
                o->denoise_fast = 0;
            else if (strcmp(v, "fast") == 0)
                o->denoise_fast = 1;
            else
                return cli_usage_error("--denoise-quality: expected high or fast, not '%s'", v);
            break;
        case OPT_WEIGHTS: o->weights = v; break;
        default:
            if (opts[p.index].id >= CLI_RENDER_EXTRA && opts[p.index].id < CLI_RENDER_EXTRA + CLI_RENDER_MAX_EXTRA)
                o->extra[opts[p.index].id - CLI_RENDER_EXTRA] = v ? v : "";
            break;
        case OPT_HELP: help(stdout); return -1;
        }
    }
    if (!o->out) return cli_usage_error("render: no output file (-o OUT.png)");
    return cli_check_config(o->config);
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

/* pk_film: 3 float sums and a uint32 count per pixel (include/paprsek.h). */
#define FILM_BYTES_PER_PIXEL ((int)(3 * sizeof(float) + sizeof(uint32_t)))

/* The process's peak resident memory so far (getrusage: kilobytes on Linux). */
static double peak_rss_mib(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0) return 0.0;
    return (double)ru.ru_maxrss / 1024.0;
}

/* The accelerator a render traced with: the GPU's own with --device cuda. */
/* The integrator that renders: the default is volpath for scenes with media. */
static const char *integrator_label(const pk_render_options *ro, const pk_scene_info *si)
{
    if (ro->integrator == PK_INTEGRATOR_DEFAULT) return si->has_media ? "volpath" : "path";
    return pk_integrator_name(ro->integrator);
}

/* The depth the renderer uses (the integrator's default for -1). */
static int depth_of(const pk_render_options *ro, const pk_scene_info *si)
{
    pk_render_options o = *ro;
    if (o.integrator == PK_INTEGRATOR_DEFAULT && si->has_media) o.integrator = PK_INTEGRATOR_VOLPATH;
    return pk_render_options_max_depth(&o);
}

static const char *accel_label(const pk_render_options *ro)
{
    return ro->device == PK_DEVICE_CUDA ? pk_accel_kind_name(PK_ACCEL_CUDA) : pk_accel_kind_name(ro->accel);
}

/* The library's effective config (pk_context_get_config). */
typedef struct config_text {
    char s[1024];
} config_text;

static config_text config_of(pk_context *ctx)
{
    config_text t;
    pk_context_get_config(ctx, t.s, sizeof t.s);
    return t;
}

void cli_print_stats(pk_context *ctx, const char *scene, const pk_scene *sc, const pk_render_options *ro,
                     const pk_stats *st)
{
    pk_scene_info si;
    pk_scene_get_info(sc, &si);
    uint64_t rays = st->rays_camera + st->rays_shadow + st->rays_reflection + st->rays_refraction + st->rays_bounce;
    double r = rays ? (double)rays : 1.0;
    const int path = ro->integrator != PK_INTEGRATOR_WHITTED;
    printf("%-28s %s\n", "scene", scene);
    if (path) /* light samples and the Fresnel switch are the Whitted integrator's */
        printf("%-28s %s, %d thread%s, %dx%d, %d spp, depth %d\n", "settings", accel_label(ro),
               st->threads, st->threads == 1 ? "" : "s", ro->width, ro->height, ro->spp, depth_of(ro, &si));
    else
        printf("%-28s %s, %d thread%s, %dx%d, %d spp, %d light samples, depth %d, fresnel %s\n", "settings",
               accel_label(ro), st->threads, st->threads == 1 ? "" : "s", ro->width, ro->height, ro->spp,
               ro->light_samples, pk_render_options_max_depth(ro), ro->fresnel ? "on" : "off");
    printf("%-28s %.0f\n", "build [us]", st->build_us);
    printf("%-28s %.3f\n", "render [s]", st->render_s);
    if (path) {
        printf("%-28s %s, seed %d\n", "integrator", integrator_label(ro, &si), ro->seed);
        printf("%-28s %llu (camera %llu, bounce %llu, shadow %llu)\n", "rays", (unsigned long long)rays,
               (unsigned long long)st->rays_camera, (unsigned long long)st->rays_bounce,
               (unsigned long long)st->rays_shadow);
        printf("%-28s %.0f\n", "samples/s", st->render_s > 0 ? (double)st->pixels * ro->spp / st->render_s : 0.0);
    } else {
        printf("%-28s %llu (camera %llu, shadow %llu, reflection %llu, refraction %llu)\n", "rays",
               (unsigned long long)rays, (unsigned long long)st->rays_camera, (unsigned long long)st->rays_shadow,
               (unsigned long long)st->rays_reflection, (unsigned long long)st->rays_refraction);
    }
    if (ro->device == PK_DEVICE_CUDA || ro->accel == PK_ACCEL_CUDA) { /* the GPU counts rays, not tests and nodes */
        printf("%-28s %s\n", "intersection tests", "not counted on the GPU");
        printf("%-28s %s\n", "nodes traversed", "not counted on the GPU");
    } else {
        printf("%-28s %llu\n", "intersection tests", (unsigned long long)st->intersection_tests);
        printf("%-28s %llu\n", "nodes traversed", (unsigned long long)st->nodes_visited);
        printf("%-28s %.2f\n", "tests/ray", (double)st->intersection_tests / r);
        printf("%-28s %.2f\n", "nodes/ray", (double)st->nodes_visited / r);
        printf("%-28s %.4f\n", "traversal time/ray [us]", st->render_s * st->threads / r * 1e6);
    }
    printf("%-28s %.2f\n", "Mrays/s", st->render_s > 0 ? (double)rays / st->render_s / 1e6 : 0.0);
    printf("%-28s %d per pixel (film: 3 float sums + a count), peak resident %.1f MiB\n", "memory [bytes]",
           FILM_BYTES_PER_PIXEL, peak_rss_mib());
    printf("%-28s %zu image%s, %.2f MiB (mipmaps included)\n", "textures", si.textures, si.textures == 1 ? "" : "s",
           (double)si.texture_bytes / (1024.0 * 1024.0));
    if (si.media)
        printf("%-28s %zu, %.2f MiB (grids and majorants)\n", "media", si.media,
               (double)si.medium_bytes / (1024.0 * 1024.0));
    printf("%-28s %s\n", "config", config_of(ctx).s);
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

/* path "-": standard output. */
void cli_print_denoise_stats(const cli_denoise_stats *dn)
{
    if (!dn || !dn->done) return;
    printf("%-28s %.3f s, %.1f MiB, %.1f GFLOP/s (%s network)\n", "denoise", dn->seconds,
           (double)dn->bytes / (1024.0 * 1024.0), dn->seconds > 0 ? dn->flops / dn->seconds * 1e-9 : 0.0,
           dn->fast ? "fast" : "high-quality");
}

void cli_print_adaptive_stats(const pk_adaptive_result *ad, const pk_adaptive *a, const pk_render_options *ro)
{
    if (!ad) return;
    printf("%-28s %.4f (target %.4f), %zu of %zu tiles reached it\n", "adaptive: estimated noise", (double)ad->noise,
           (double)a->noise, ad->tiles_reached, ad->tiles);
    printf("%-28s mean %.1f, min %u, max %u (%u passes)\n", "adaptive: samples per pixel",
           (double)ad->samples / ((double)ro->width * (double)ro->height), ad->min_spp, ad->max_spp, ad->passes);
}

int cli_write_stats_json(pk_context *ctx, const char *path, const char *scene, const pk_scene *sc,
                         const pk_render_options *ro, const pk_stats *st, const cli_denoise_stats *dn,
                         const pk_adaptive_result *ad, const pk_adaptive *a)
{
    pk_scene_info si;
    pk_scene_get_info(sc, &si);
    uint64_t rays = st->rays_camera + st->rays_shadow + st->rays_reflection + st->rays_refraction + st->rays_bounce;
    const int to_stdout = strcmp(path, "-") == 0;
    FILE *f = to_stdout ? stdout : fopen(path, "w");
    if (!f) return cli_failure("%s: cannot write: %s", path, strerror(errno));
    fputs("{\n  \"scene\": ", f);
    json_string(f, scene);
    fprintf(f,
            ",\n  \"accel\": \"%s\",\n  \"width\": %d,\n  \"height\": %d,\n  \"spp\": %d,\n"
            "  \"light_samples\": %d,\n  \"max_depth\": %d,\n  \"fresnel\": %s,\n  \"threads\": %d,\n"
            "  \"build_us\": %.1f,\n  \"render_s\": %.6f,\n  \"rays\": %llu,\n  \"rays_camera\": %llu,\n"
            "  \"rays_shadow\": %llu,\n  \"rays_reflection\": %llu,\n  \"rays_refraction\": %llu,\n"
            "  \"intersection_tests\": %llu,\n  \"nodes_visited\": %llu,\n  \"mrays_per_s\": %.3f,\n"
            "  \"integrator\": \"%s\",\n  \"seed\": %d,\n  \"rays_bounce\": %llu,\n  \"samples_per_s\": %.1f,\n"
            "  \"film_bytes_per_pixel\": %d,\n  \"peak_rss_mib\": %.1f,\n  \"textures\": %zu,\n"
            "  \"texture_bytes\": %zu,\n  \"media\": %zu,\n  \"medium_bytes\": %zu,\n  \"device\": \"%s\",\n"
            "  \"config\": ",
            accel_label(ro), ro->width, ro->height, ro->spp, ro->light_samples, depth_of(ro, &si),
            ro->fresnel ? "true" : "false", st->threads, st->build_us, st->render_s, (unsigned long long)rays,
            (unsigned long long)st->rays_camera, (unsigned long long)st->rays_shadow,
            (unsigned long long)st->rays_reflection, (unsigned long long)st->rays_refraction,
            (unsigned long long)st->intersection_tests, (unsigned long long)st->nodes_visited,
            st->render_s > 0 ? (double)rays / st->render_s / 1e6 : 0.0, integrator_label(ro, &si), ro->seed,
            (unsigned long long)st->rays_bounce,
            st->render_s > 0 ? (double)st->pixels * ro->spp / st->render_s : 0.0, FILM_BYTES_PER_PIXEL,
            peak_rss_mib(), si.textures, si.texture_bytes, si.media, si.medium_bytes,
            pk_device_name(ro->device == PK_DEVICE_CUDA || ro->accel == PK_ACCEL_CUDA ? PK_DEVICE_CUDA : PK_DEVICE_CPU));
    json_string(f, config_of(ctx).s);
    if (dn && dn->done)
        fprintf(f,
                ",\n  \"denoise\": {\"network\": \"%s\", \"seconds\": %.6f, \"bytes\": %zu, "
                "\"gflop_per_s\": %.2f}",
                dn->fast ? "fast" : "high", dn->seconds, dn->bytes, dn->seconds > 0 ? dn->flops / dn->seconds * 1e-9 : 0.0);
    else
        fputs(",\n  \"denoise\": null", f);
    if (ad)
        fprintf(f,
                ",\n  \"adaptive\": {\"target\": %.6g, \"noise\": %.6g, \"tiles\": %zu, \"tiles_reached\": %zu, "
                "\"samples\": %llu, \"mean_spp\": %.3f, \"min_spp\": %u, \"max_spp\": %u, \"passes\": %u}",
                (double)a->noise, (double)ad->noise, ad->tiles, ad->tiles_reached, (unsigned long long)ad->samples,
                (double)ad->samples / ((double)ro->width * (double)ro->height), ad->min_spp, ad->max_spp, ad->passes);
    fputs("\n}\n", f);
    if (to_stdout ? fflush(f) != 0 || ferror(f) : fclose(f) != 0)
        return cli_failure("%s: cannot write: %s", to_stdout ? "standard output" : path, strerror(errno));
    return 0;
}

/* "dir/name.png" -> "dir/name.partial.png" */
char *cli_partial_name(const char *out)
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


/* "dir/name.png" + "depth" -> "dir/name.depth.png" */
static char *aov_name(const char *out, const char *aov)
{
    size_t n = strlen(out);
    const char *dot = strrchr(out, '.');
    const char *slash = strrchr(out, '/');
    if (!dot || (slash && dot < slash)) dot = out + n;
    char *p = malloc(n + strlen(aov) + 2);
    if (!p) return NULL;
    size_t head = (size_t)(dot - out);
    memcpy(p, out, head);
    p[head] = '.';
    strcpy(p + head + 1, aov);
    strcat(p, dot);
    return p;
}

/* For 8-bit PNG only: normals from [-1, 1] to [0, 1], depth divided by its
 * largest value, the heatmap on a blue-green-red scale between its smallest
 * and largest value (the range is printed). HDR files keep the raw values. */
static void aov_for_png(pk_image *img, unsigned aov, int quiet)
{
    float *px = pk_image_pixels(img);
    const size_t n = (size_t)pk_image_width(img) * (size_t)pk_image_height(img);
    if (aov == PK_AOV_NORMAL) {
        for (size_t i = 0; i < 3 * n; i++) px[i] = px[i] * 0.5f + 0.5f;
        return;
    }
    if (aov != PK_AOV_DEPTH && aov != PK_AOV_HEATMAP && aov != PK_AOV_SAMPLES) return;
    float lo = INFINITY, hi = 0.0f;
    for (size_t i = 0; i < n; i++) {
        lo = px[3 * i] < lo ? px[3 * i] : lo;
        hi = px[3 * i] > hi ? px[3 * i] : hi;
    }
    if (aov == PK_AOV_DEPTH) {
        for (size_t i = 0; i < 3 * n; i++) px[i] = hi > 0.0f ? px[i] / hi : 0.0f;
        if (!quiet) fprintf(stderr, "depth: black 0 to white %g (scene units)\n", (double)hi);
        return;
    }
    for (size_t i = 0; i < n; i++) {
        float t = hi > lo ? (px[3 * i] - lo) / (hi - lo) : 0.0f;
        /* blue (few) -> green -> red (many), linear values for the sRGB encoding */
        px[3 * i] = t > 0.5f ? 2.0f * t - 1.0f : 0.0f;
        px[3 * i + 1] = t < 0.5f ? 2.0f * t : 2.0f - 2.0f * t;
        px[3 * i + 2] = t < 0.5f ? 1.0f - 2.0f * t : 0.0f;
    }
    if (!quiet && aov == PK_AOV_SAMPLES)
        fprintf(stderr, "samples: blue %g to red %g samples per pixel\n", (double)lo, (double)hi);
    else if (!quiet)
        fprintf(stderr, "heatmap: blue %g to red %g nodes visited + primitives tested per camera ray\n", (double)lo,
                (double)hi);
}

/* ---- before, during and after the render ------------------------------------ */

int cli_render_check(const cli_render_opts *o, pk_write_options *wo)
{
    if (o->min_spp && o->noise <= 0.0) return cli_usage_error("--min-spp needs --noise (adaptive sampling)");
    struct stat sb;
    if (stat(o->out, &sb) == 0 && S_ISDIR(sb.st_mode)) return cli_failure("%s: is a folder; name a file in it", o->out);
    const int png = ends_with_ci(o->out, ".png");
    if (!png && !ends_with_ci(o->out, ".pfm") && !ends_with_ci(o->out, ".exr"))
        return cli_usage_error("%s: unknown image format (use .png, .pfm or .exr)", o->out);
    pk_write_options_init(wo);
    if (o->has_exposure) wo->exposure_ev = o->exposure;
    if (o->has_exposure && o->exposure != 0.0f && !png && !o->quiet)
        cli_print_warning(NULL, "--exposure applies to PNG only; the HDR image is written unscaled");
    wo->tonemap = o->tonemap;
    if (o->tonemap != PK_TONEMAP_CLAMP && !png && !o->quiet)
        cli_print_warning(NULL, "--tonemap applies to PNG only; the HDR image is written linear");
    if (o->transparent && ends_with_ci(o->out, ".pfm"))
        return cli_usage_error("--transparent: PFM has no alpha channel; write .png or .exr");
    if (o->has_camera_pick && (!o->scene || !pk_scene_format(o->scene) || strcmp(pk_scene_format(o->scene), "gltf") != 0))
        return cli_usage_error("--camera: picks a camera of a glTF asset (.gltf, .glb); %s%s%s is not one",
                               o->scene ? "'" : "", o->scene ? o->scene : "the built-in Cornell box",
                               o->scene ? "'" : "");
    if (o->has_variant && (!o->scene || !pk_scene_format(o->scene) || strcmp(pk_scene_format(o->scene), "gltf") != 0))
        return cli_usage_error("--variant: picks a material variant of a glTF asset (.gltf, .glb); %s%s%s is not one",
                               o->scene ? "'" : "", o->scene ? o->scene : "the built-in Cornell box",
                               o->scene ? "'" : "");
    if (o->scene && same_file(o->scene, o->out))
        return cli_usage_error("render: refusing to write the image over the scene file '%s'", o->scene);
    const int json_stdout = o->stats_json && strcmp(o->stats_json, "-") == 0;
    if (json_stdout && o->stats)
        return cli_usage_error("render: --stats and --stats-json - both write to standard output; choose one");
    if (o->stats_json && !json_stdout && o->scene && same_file(o->scene, o->stats_json))
        return cli_usage_error("render: refusing to write the statistics over the scene file '%s'", o->scene);
    if (o->stats_json && !json_stdout && (strcmp(o->stats_json, o->out) == 0 || same_file(o->stats_json, o->out)))
        return cli_usage_error("render: --stats-json and -o name the same file '%s'", o->out);
    if (cli_check_output(o->out, 1)) return 1;
    if (o->stats_json && !json_stdout && cli_check_output(o->stats_json, 0)) return 1;
    return 0;
}

int cli_render_spp_given(const cli_render_opts *o)
{
    size_t n;
    const cli_option *opts = cli_render_options(&n);
    for (size_t i = 0; i < n; i++)
        if (o->int_set[i] && opts[i].render && strcmp(opts[i].render->name, "spp") == 0) return 1;
    return 0;
}

int cli_render_clean_default(const cli_render_opts *o, const pk_scene *scene)
{
    if (cli_render_spp_given(o)) return 0;
    return o->time <= 0.0 && o->noise <= 0.0 && !pk_scene_has_sample_count(scene);
}

pk_status cli_render_settings(pk_context *ctx, const cli_render_opts *o, pk_scene *scene, pk_render_options *ro)
{
    pk_scene_get_render_options(scene, ro);
    size_t nopts;
    const cli_option *opts = cli_render_options(&nopts);
    const int scene_w = ro->width, scene_h = ro->height;
    int set_w = 0, set_h = 0;
    for (size_t i = 0; i < nopts; i++)
        if (o->int_set[i]) {
            *(int *)(void *)((char *)ro + opts[i].render->offset) = o->int_value[i];
            set_w |= strcmp(opts[i].render->name, "width") == 0;
            set_h |= strcmp(opts[i].render->name, "height") == 0;
        }
    /* one side given for a scene that has its own size: the other follows
     * the scene's aspect ratio */
    if (set_w != set_h && pk_scene_has_image_size(scene) && scene_w > 0 && scene_h > 0) {
        const double other = set_w ? (double)ro->width * scene_h / scene_w : (double)ro->height * scene_w / scene_h;
        int v = (int)(other + 0.5);
        v = v < 1 ? 1 : v > PK_MAX_IMAGE_SIDE ? PK_MAX_IMAGE_SIDE : v;
        if (set_w) ro->height = v;
        else ro->width = v;
    }
    if (o->fresnel >= 0) ro->fresnel = o->fresnel;
    if (o->energy >= 0) ro->energy_compensation = o->energy;
    if (o->has_clamp_indirect) ro->clamp_indirect = o->clamp_indirect;
    if (o->has_filter) ro->filter = o->filter;
    if (o->has_accel) ro->accel = o->accel;
    if (o->has_device) {
        ro->device = o->device;
        if (o->device == PK_DEVICE_CPU && ro->accel == PK_ACCEL_CUDA) ro->accel = PK_ACCEL_DEFAULT;
    }
    if (o->has_integrator) ro->integrator = o->integrator;
    ro->transparent = o->transparent;
    if (cli_render_clean_default(o, scene)) ro->spp = CLI_CLEAN_SPP;
    ro->collect_stats = o->stats || o->stats_json;
    if (cli_configure(ctx, o->config) != 0) return PK_ERR_INVALID_ARGUMENT; /* (checked at parsing) */
    pk_status st = pk_render_options_check(ctx, ro);
    if (st != PK_OK) return st;
    if (o->env) {
        pk_environment env;
        pk_environment_init(&env);
        char *end;
        float grey = strtof(o->env, &end);
        if (strcmp(o->env, "none") == 0) {
            st = pk_scene_set_environment(ctx, scene, NULL);
        } else if (cli_parse_vec3(o->env, env.radiance) || (end != o->env && !*end && isfinite(grey))) {
            if (end != o->env && !*end) env.radiance[0] = env.radiance[1] = env.radiance[2] = grey;
            st = pk_scene_set_environment(ctx, scene, &env);
        } else {
            env.map = o->env;
            st = pk_scene_set_environment(ctx, scene, &env);
        }
        if (st != PK_OK) return st;
    }
    if (o->has_from || o->has_at || o->has_up || o->has_fov || o->has_lens_radius || o->has_focus_distance ||
        o->projection || o->has_orbit) {
        pk_camera cam;
        pk_scene_get_camera(scene, &cam);
        if (o->has_from) memcpy(cam.look_from, o->from, sizeof o->from);
        if (o->has_at) memcpy(cam.look_at, o->at, sizeof o->at);
        if (o->has_fov) cam.fov_deg = o->fov;
        if (o->has_orbit) {
            pk_scene_info info;
            pk_scene_get_info(scene, &info);
            double c[3], rad = 0.0;
            for (int k = 0; k < 3; k++) {
                const double h = 0.5 * ((double)info.bounds_max[k] - (double)info.bounds_min[k]);
                c[k] = o->has_at ? (double)o->at[k] : 0.5 * ((double)info.bounds_min[k] + (double)info.bounds_max[k]);
                rad += h * h;
            }
            rad = sqrt(rad);
            const double th = (double)o->orbit[0] * 3.14159265358979323846 / 180.0,
                         ph = (double)o->orbit[1] * 3.14159265358979323846 / 180.0;
            const double fov = (double)(o->has_fov ? o->fov : cam.fov_deg) * 3.14159265358979323846 / 180.0;
            double r = o->orbit[2] > 0.0f ? (double)o->orbit[2] : rad / sin(0.5 * fov);
            if (!(r > 0.0)) r = 1.0;
            double d[3] = {sin(ph) * sin(th), cos(ph), sin(ph) * cos(th)};
            for (int k = 0; k < 3; k++) d[k] = fabs(d[k]) < 1e-12 ? 0.0 : d[k]; /* cos(90°) is 0 */
            for (int k = 0; k < 3; k++) {
                cam.look_at[k] = (float)c[k];
                cam.look_from[k] = (float)(c[k] + r * d[k]);
            }
            if (!o->has_up) cam.up[0] = 0.0f, cam.up[1] = 1.0f, cam.up[2] = 0.0f;
        }
        if (o->has_up) memcpy(cam.up, o->up, sizeof o->up);
        if (o->has_fov) cam.fov_deg = o->fov;
        if (o->has_lens_radius) cam.lens_radius = o->lens_radius;
        if (o->has_focus_distance) cam.focus_distance = o->focus_distance;
        if (o->projection) cam.projection = o->projection - 1;
        if (o->projection == PK_PROJECTION_ORTHOGRAPHIC + 1) cam.ortho_width = o->ortho_width;
        st = pk_scene_set_camera(ctx, scene, &cam);
    }
    return st;
}

static pk_status cli_render_write_images(pk_context *ctx, const cli_render_opts *o, const pk_write_options *wo_in,
                                         const pk_image *img, const pk_film *film);

pk_status cli_render_write(pk_context *ctx, const cli_render_opts *o, const pk_write_options *wo_in,
                           const pk_image *img, const pk_film *film)
{
    pk_write_options wo = *wo_in;
    pk_image *alpha = NULL; /* --transparent: the coverage */
    if (o->transparent) {
        pk_status as = pk_film_resolve_aov(ctx, film, PK_AOV_ALPHA, &alpha);
        if (as != PK_OK) return as;
        wo.alpha = alpha;
    }
    pk_status ws0 = cli_render_write_images(ctx, o, &wo, img, film);
    pk_image_destroy(alpha);
    return ws0;
}

static pk_status cli_render_write_images(pk_context *ctx, const cli_render_opts *o, const pk_write_options *wo_in,
                                         const pk_image *img, const pk_film *film)
{
    pk_write_options wo = *wo_in;
    if (o->aovs && ends_with_ci(o->out, ".exr")) {
        /* one file: the AOVs as layers */
        pk_image *li[5] = {NULL, NULL, NULL, NULL, NULL};
        const char *ln[5];
        size_t nl = 0;
        pk_status ls = PK_OK;
        for (unsigned a = 1; a <= PK_AOV_SAMPLES && ls == PK_OK; a <<= 1)
            if (o->aovs & a) {
                ln[nl] = pk_aov_name(a);
                ls = pk_film_resolve_aov(ctx, film, a, &li[nl++]);
            }
        if (ls == PK_OK) {
            wo.nlayers = nl;
            wo.layers = (const pk_image *const *)li;
            wo.layer_names = ln;
            ls = pk_image_write_ex(ctx, img, o->out, &wo);
        }
        for (size_t l = 0; l < 5; l++) pk_image_destroy(li[l]);
        if (ls != PK_OK) return ls;
    } else {
        pk_status ws = pk_image_write_ex(ctx, img, o->out, &wo);
        if (ws != PK_OK) return ws;
    }
    for (unsigned a = 1; a <= PK_AOV_SAMPLES; a <<= 1) {
        if (!(o->aovs & a) || ends_with_ci(o->out, ".exr")) continue;
        pk_image *ai = NULL;
        char *name = aov_name(o->out, pk_aov_name(a));
        if (!name) return PK_ERR_NOMEM;
        pk_status ws = pk_film_resolve_aov(ctx, film, a, &ai);
        if (ws != PK_OK) {
            free(name);
            return ws;
        }
        if (ends_with_ci(o->out, ".png")) aov_for_png(ai, a, o->quiet);
        pk_write_options aw;
        pk_write_options_init(&aw); /* no exposure: these are data, not pictures */
        ws = pk_image_write_ex(ctx, ai, name, &aw);
        pk_image_destroy(ai);
        free(name);
        if (ws != PK_OK) return ws;
    }
    return PK_OK;
}
