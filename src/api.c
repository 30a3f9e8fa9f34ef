/*
 * api.c - the one door: every public function checks its arguments here,
 * records errors in the context and calls into the modules.
 */
#include "paprsek_internal.h"

#include "options.h"

#include "accel/accel.h"
#include "image/image.h"
#include "image/image_write.h"
#include "io/readers.h"
#include "render/render.h"
#include "scene/camera.h"
#include "scene/scene.h"

#include <stdio.h>
#include <string.h>

/* ---- options ------------------------------------------------------------------ */

int pk_accel_available(pk_accel_kind kind)
{
    if (kind == PK_ACCEL_EMBREE) return accel_embree_available(NULL);
    if (kind == PK_ACCEL_CUDA) return accel_cuda_built();
    return (unsigned)kind <= PK_ACCEL_BVH;
}

/* pk_accel_available for ctx: Embree is the library its config names. */
static bool accel_available_in(const pk_context *ctx, pk_accel_kind kind)
{
    return kind == PK_ACCEL_EMBREE ? accel_embree_available(ctx) : pk_accel_available(kind) != 0;
}

/* Latches why kind cannot be used (Embree says which library did not load). */
static pk_status accel_unavailable(pk_context *ctx, pk_accel_kind kind)
{
    if (kind == PK_ACCEL_EMBREE) return accel_embree_unavailable(ctx);
    return ctx_error(ctx, PK_ERR_UNSUPPORTED, "accelerator '%s' is not available in this build",
                     pk_accel_kind_name(kind));
}

/* ---- scenes ----------------------------------------------------------------- */

static const char *base_name(const char *path)
{
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

static pk_status load_memory(pk_context *ctx, const scene_reader *fmt, const char *data, size_t size,
                             const char *name, const char *base_dir, const char *const *params, size_t nparams,
                             pk_scene **out)
{
    pk_scene *s = NULL;
    pk_status st = scene_create(ctx, name, &s);
    if (st != PK_OK) return st;
    st = fmt->parse(ctx, s, data, size, name, base_dir, params, nparams);
    if (st == PK_OK) st = scene_commit(ctx, s);
    if (st != PK_OK) {
        scene_destroy(s);
        if (ctx->status == PK_OK) ctx_error(ctx, st, "%s: %s", name, pk_status_string(st));
        return ctx->status;
    }
    *out = s;
    return PK_OK;
}

pk_status pk_scene_load_memory(pk_context *ctx, const char *format, const char *data, size_t size, const char *name,
                               const char *base_dir, pk_scene **out)
{
    if (!ctx || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if (!data && size) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "no data");
    const scene_reader *fmt = format ? scene_reader_named(format) : NULL;
    if (!fmt)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                         "unknown scene format '%.20s' (expected obj, json, xml, pbrt, gltf or glb)", format ? format : "");
    char def[32];
    if (!name) snprintf(def, sizeof def, "memory.%s", fmt->name);
    return load_memory(ctx, fmt, data ? data : "", size, name ? name : def, base_dir ? base_dir : fmt->default_dir,
                       NULL, 0, out);
}

const char *pk_scene_format(const char *path)
{
    const scene_reader *fmt = path ? scene_reader_for_path(path) : NULL;
    return fmt ? fmt->name : NULL;
}

pk_status pk_scene_load_obj_memory(pk_context *ctx, const char *data, size_t size, const char *name,
                                   const char *base_dir, pk_scene **out)
{
    if (!ctx || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if (!data && size) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "no data");
    return load_memory(ctx, scene_reader_named("obj"), data ? data : "", size, name ? name : "memory.obj", base_dir,
                       NULL, 0, out);
}

pk_status pk_scene_load_json_memory(pk_context *ctx, const char *data, size_t size, const char *name,
                                    const char *base_dir, pk_scene **out)
{
    if (!ctx || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if (!data && size) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "no data");
    return load_memory(ctx, scene_reader_named("json"), data ? data : "", size, name ? name : "memory.json",
                       base_dir ? base_dir : ".", NULL, 0, out);
}

pk_status pk_scene_load_xml_memory(pk_context *ctx, const char *data, size_t size, const char *name,
                                   const char *base_dir, pk_scene **out)
{
    if (!ctx || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if (!data && size) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "no data");
    return load_memory(ctx, scene_reader_named("xml"), data ? data : "", size, name ? name : "memory.xml",
                       base_dir ? base_dir : ".", NULL, 0, out);
}

pk_status pk_scene_load_file(pk_context *ctx, const char *path, pk_scene **out)
{
    return pk_scene_load_file_params(ctx, path, NULL, 0, out);
}

pk_status pk_scene_load_file_params(pk_context *ctx, const char *path, const char *const *params, size_t nparams,
                                    pk_scene **out)
{
    if (!ctx || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if (nparams && !params) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "no parameters");
    if (!path) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "no scene path");
    const scene_reader *fmt = scene_reader_for_path(path);
    if (!fmt)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                         "%s: unknown scene format (expected .obj, .json, .xml, .pbrt, .gltf or .glb)", path);
    char *data = NULL, *dir = NULL;
    size_t size = 0;
    pk_status st = file_read_all(ctx, path, &data, &size);
    if (st != PK_OK) return st;
    dir = path_dirname(&ctx->alloc, path);
    if (!dir) {
        st = ctx_nomem(ctx);
        goto out;
    }
    st = load_memory(ctx, fmt, data, size, base_name(path), dir, params, nparams, out);
out:
    mem_free(&ctx->alloc, data);
    mem_free(&ctx->alloc, dir);
    return st;
}

pk_status pk_scene_create_cornell_box(pk_context *ctx, pk_scene **out)
{
    if (!ctx || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    pk_scene *s = NULL;
    pk_status st = scene_create(ctx, "cornell-box (built in)", &s);
    if (st != PK_OK) return st;
    st = scene_build_cornell(ctx, s);
    if (st == PK_OK) st = scene_commit(ctx, s);
    if (st != PK_OK) {
        scene_destroy(s);
        return st;
    }
    *out = s;
    return PK_OK;
}

void pk_scene_destroy(pk_scene *scene) { scene_destroy(scene); }

void pk_scene_get_info(const pk_scene *s, pk_scene_info *info)
{
    if (!s || !info) return;
    memset(info, 0, sizeof *info);
    info->triangles = s->ntris;
    info->degenerate_triangles = s->ndegenerate;
    info->spheres = s->nspheres;
    info->materials = s->nmaterials;
    info->point_lights = s->nlights;
    info->emissive_triangles = s->nemissive;
    info->bounds_min[0] = s->bounds.lo.x;
    info->bounds_min[1] = s->bounds.lo.y;
    info->bounds_min[2] = s->bounds.lo.z;
    info->bounds_max[0] = s->bounds.hi.x;
    info->bounds_max[1] = s->bounds.hi.y;
    info->bounds_max[2] = s->bounds.hi.z;
    info->has_camera = s->has_camera;
    info->textures = s->ntextures;
    info->texture_bytes = s->texture_bytes;
    info->media = s->nmedia;
    info->medium_bytes = s->medium_bytes;
    info->has_media = scene_has_media(s);
}

pk_status pk_scene_get_emissive_triangle(const pk_scene *s, size_t k, size_t *tri)
{
    if (!s || !tri || k >= s->nemissive) return PK_ERR_INVALID_ARGUMENT;
    *tri = s->emissive[k];
    return PK_OK;
}

pk_status pk_scene_get_triangle(const pk_scene *s, size_t k, float verts[9])
{
    if (!s || !verts || k >= s->ntris) return PK_ERR_INVALID_ARGUMENT;
    vec3 p[3];
    scene_tri_verts(s, k, &p[0], &p[1], &p[2]);
    for (int i = 0; i < 3; i++) {
        verts[3 * i] = p[i].x;
        verts[3 * i + 1] = p[i].y;
        verts[3 * i + 2] = p[i].z;
    }
    return PK_OK;
}

void pk_scene_get_camera(const pk_scene *s, pk_camera *cam)
{
    if (!s || !cam) return;
    scene_camera(s, cam);
}

pk_status pk_scene_set_camera(pk_context *ctx, pk_scene *s, const pk_camera *cam)
{
    if (!ctx || !s || !cam) return PK_ERR_INVALID_ARGUMENT;
    pk_status st = camera_validate(ctx, cam, "camera");
    if (st != PK_OK) return st;
    s->camera = *cam;
    s->has_camera = true;
    return PK_OK;
}

void pk_environment_init(pk_environment *env)
{
    if (!env) return;
    memset(env, 0, sizeof *env);
    env->map_scale = 1.0f;
}

pk_status pk_scene_set_environment(pk_context *ctx, pk_scene *s, const pk_environment *in)
{
    if (!ctx || !s) return PK_ERR_INVALID_ARGUMENT;
    if (in) {
        for (int c = 0; c < 3; c++)
            if (!(in->radiance[c] >= 0.0f) || !isfinite(in->radiance[c]))
                return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "environment: radiance must be finite and not negative");
        if (!(in->map_scale >= 0.0f) || !isfinite(in->map_scale) || !isfinite(in->rotation))
            return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "environment: the scale must be finite and not negative, "
                             "the rotation finite");
    }
    /* built in place through the constructors; the old one comes back if the map cannot be read */
    scene_environment old = s->env;
    scene_env_init(&s->env);
    s->env.set = true;
    pk_status st = PK_OK;
    if (in) {
        scene_env_add_radiance(s, v3(in->radiance[0], in->radiance[1], in->radiance[2]));
        float rot[9];
        scene_rotation_y(in->rotation, rot);
        scene_env_frame(s, rot);
        if (in->map) st = scene_env_map(ctx, s, in->map, in->map_scale);
    }
    scene_env_clear(&s->alloc, st == PK_OK ? &old : &s->env);
    if (st != PK_OK) s->env = old;
    return st;
}

void pk_scene_get_render_options(const pk_scene *s, pk_render_options *opt)
{
    if (!opt) return;
    pk_render_options_init(opt);
    if (!s) return;
    const scene_render_settings *r = &s->render;
    if (r->has_width) opt->width = r->opt.width;
    if (r->has_height) opt->height = r->opt.height;
    if (r->has_spp) opt->spp = r->opt.spp;
    if (r->has_light_samples) opt->light_samples = r->opt.light_samples;
    if (r->has_max_depth) opt->max_depth = r->opt.max_depth;
    if (r->has_threads) opt->threads = r->opt.threads;
    if (r->has_accel) opt->accel = r->opt.accel;
    if (r->has_fresnel) opt->fresnel = r->opt.fresnel;
    if (r->has_seed) opt->seed = r->opt.seed;
    if (r->has_regularize) opt->regularize = r->opt.regularize;
    if (r->has_light_tree) opt->light_tree = r->opt.light_tree;
    if (r->has_clamp_indirect) opt->clamp_indirect = r->opt.clamp_indirect;
    if (r->has_energy_compensation) opt->energy_compensation = r->opt.energy_compensation;
    if (r->has_filter) opt->filter = r->opt.filter;
    if (r->has_integrator) opt->integrator = r->opt.integrator;
}

int pk_scene_has_sample_count(const pk_scene *s) { return s && s->render.has_spp; }

int pk_scene_has_image_size(const pk_scene *s) { return s && s->render.has_width && s->render.has_height; }

/* ---- images ---------------------------------------------------------------- */

pk_status pk_image_create(pk_context *ctx, int width, int height, pk_image **out)
{
    if (!ctx || !out) return PK_ERR_INVALID_ARGUMENT;
    return image_create(ctx, width, height, out);
}

void pk_image_destroy(pk_image *img) { image_destroy(img); }

int pk_image_width(const pk_image *img) { return img ? img->width : 0; }
int pk_image_height(const pk_image *img) { return img ? img->height : 0; }
float *pk_image_pixels(pk_image *img) { return img ? img->pixels : NULL; }
const float *pk_image_pixels_const(const pk_image *img) { return img ? img->pixels : NULL; }

pk_status pk_image_write(pk_context *ctx, const pk_image *img, const char *path)
{
    if (!ctx || !img || !path) return PK_ERR_INVALID_ARGUMENT;
    return image_write(ctx, img, path);
}

/* ---- rendering ---------------------------------------------------------------- */

/* Checks *o and resolves its device (options_resolve_device). */
static pk_status check_options(pk_context *ctx, pk_render_options *o)
{
    pk_status st = options_check(ctx, o);
    if (st != PK_OK) return st;
    options_resolve_device(o);
    if (!accel_available_in(ctx, o->accel)) return accel_unavailable(ctx, o->accel);
    if (o->device == PK_DEVICE_CUDA && o->integrator == PK_INTEGRATOR_WHITTED)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "device 'cuda': the GPU renders with the path tracer only, not "
                                                  "the Whitted integrator");
    if (o->device == PK_DEVICE_CUDA && o->integrator == PK_INTEGRATOR_VOLPATH)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "device 'cuda': the GPU renders with the path tracer only, not "
                                                  "the volumetric path tracer (participating media)");
    return PK_OK;
}

pk_status pk_render_options_check(pk_context *ctx, const pk_render_options *opt)
{
    if (!ctx || !opt) return PK_ERR_INVALID_ARGUMENT;
    pk_render_options o = *opt;
    return check_options(ctx, &o);
}

/* The camera a render of scene uses, checked. */
static pk_status render_camera(pk_context *ctx, const pk_scene *scene, pk_camera *cam)
{
    scene_camera(scene, cam);
    if (!scene->has_camera && camera_check(cam) != CAMERA_OK)
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: the scene is too large to frame automatically; give it a camera",
                         scene->name);
    return camera_validate(ctx, cam, "camera");
}

pk_status pk_renderer_create(pk_context *ctx, const pk_scene *scene, const pk_render_options *opt,
                             pk_renderer **out)
{
    if (!ctx || !scene || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    pk_render_options o;
    if (opt)
        o = *opt;
    else
        pk_scene_get_render_options(scene, &o);
    if (!scene->committed)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: the scene is not committed (pk_scene_commit ends building it)",
                         scene->name);
    pk_status st = check_options(ctx, &o);
    if (st != PK_OK) return st;
    pk_camera cam;
    st = render_camera(ctx, scene, &cam);
    if (st != PK_OK) return st;
    return renderer_create(ctx, scene, &o, &cam, out);
}

void pk_renderer_destroy(pk_renderer *r) { renderer_destroy(r); }

void pk_renderer_get_options(const pk_renderer *r, pk_render_options *opt)
{
    if (r && opt) *opt = *renderer_options(r);
}

pk_status pk_renderer_set_camera(pk_renderer *r, const pk_camera *cam)
{
    if (!r || !cam) return PK_ERR_INVALID_ARGUMENT;
    pk_status st = camera_validate(renderer_context(r), cam, "camera");
    if (st == PK_OK) renderer_set_camera(r, cam);
    return st;
}

void pk_renderer_get_camera(const pk_renderer *r, pk_camera *cam)
{
    if (r && cam) *cam = *renderer_camera(r);
}

pk_status pk_renderer_render(pk_renderer *r, const pk_region *regions, size_t n, pk_film *film)
{
    if (!r || !film || (!regions && n)) return PK_ERR_INVALID_ARGUMENT;
    return renderer_render(r, regions, n, film);
}

void pk_renderer_set_pass(pk_renderer *r, uint32_t pass)
{
    if (r) renderer_set_pass(r, pass);
}

void pk_renderer_get_stats(const pk_renderer *r, pk_stats *stats)
{
    if (r && stats) renderer_stats(r, stats);
}

pk_status pk_renderer_pick(const pk_renderer *r, const pk_camera *cam, double x, double y, pk_pick *out)
{
    if (!r || !out) return PK_ERR_INVALID_ARGUMENT;
    return renderer_pick(r, cam, x, y, out);
}

pk_status pk_camera_check(pk_context *ctx, const pk_camera *cam)
{
    if (!cam) return PK_ERR_INVALID_ARGUMENT;
    if (!ctx) return camera_check(cam) == CAMERA_OK ? PK_OK : PK_ERR_INVALID_ARGUMENT;
    return camera_validate(ctx, cam, "camera");
}

pk_status pk_render(pk_context *ctx, const pk_scene *scene, const pk_render_options *opt, pk_image **out,
                    pk_stats *stats)
{
    if (!ctx || !scene || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    pk_renderer *r = NULL;
    pk_film *film = NULL;
    pk_image *img = NULL;
    pk_status st = pk_renderer_create(ctx, scene, opt, &r);
    if (st != PK_OK) return st;
    const pk_render_options *o = renderer_options(r);
    if ((st = film_create(ctx, o->width, o->height, 0, &film)) != PK_OK) goto out;
    if ((st = image_create(ctx, o->width, o->height, &img)) != PK_OK) goto out;
    st = renderer_render(r, NULL, 0, film);
    if (st == PK_OK || st == PK_ERR_CANCELLED) {
        film_resolve_into(film, img);
        *out = img;
        img = NULL;
    }
    if (stats) renderer_stats(r, stats);
out:
    image_destroy(img);
    film_destroy(film);
    renderer_destroy(r);
    return st;
}

/* ---- films ---------------------------------------------------------------------- */

pk_status pk_film_create(pk_context *ctx, int width, int height, pk_film **out)
{
    if (!ctx || !out) return PK_ERR_INVALID_ARGUMENT;
    return film_create(ctx, width, height, 0, out);
}

pk_status pk_film_create_aovs(pk_context *ctx, int width, int height, unsigned aovs, pk_film **out)
{
    if (!ctx || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if (aovs & ~(PK_AOV_ALBEDO | PK_AOV_NORMAL | PK_AOV_DEPTH | PK_AOV_HEATMAP | PK_AOV_ALPHA | PK_AOV_SAMPLES))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "unknown AOV bits 0x%x", aovs);
    return film_create(ctx, width, height, aovs, out);
}

unsigned pk_film_aovs(const pk_film *film) { return film ? film->aovs | (film->samples ? PK_AOV_SAMPLES : 0u) : 0; }

static const char *const aov_names[FILM_AOVS] = {"albedo", "normal", "depth", "heatmap", "alpha"};

unsigned pk_aov_parse(const char *name)
{
    if (!name) return 0;
    for (int k = 0; k < FILM_AOVS; k++)
        if (strcmp(name, aov_names[k]) == 0) return 1u << k;
    return strcmp(name, "samples") == 0 ? PK_AOV_SAMPLES : 0;
}

const char *pk_aov_name(unsigned aov)
{
    for (int k = 0; k < FILM_AOVS; k++)
        if (aov == 1u << k) return aov_names[k];
    return aov == PK_AOV_SAMPLES ? "samples" : "unknown";
}

pk_status pk_film_resolve_aov(pk_context *ctx, const pk_film *film, unsigned aov, pk_image **out)
{
    if (!ctx || !film || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    if (aov == PK_AOV_SAMPLES && film->samples) {
        pk_status st = image_create(ctx, film->width, film->height, out);
        const size_t n = (size_t)film->width * (size_t)film->height;
        for (size_t i = 0; st == PK_OK && i < 3 * n; i++) (*out)->pixels[i] = (float)film->counts[i / 3];
        return st;
    }
    int k = -1;
    for (int i = 0; i < FILM_AOVS; i++)
        if (aov == 1u << i) k = i;
    if (k < 0 || !(film->aovs & aov))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "the film holds no AOV '%s'", pk_aov_name(aov));
    pk_status st = image_create(ctx, film->width, film->height, out);
    if (st == PK_OK) film_resolve_aov_into(film, k, *out);
    return st;
}

void pk_film_destroy(pk_film *film) { film_destroy(film); }
int pk_film_width(const pk_film *film) { return film ? film->width : 0; }
int pk_film_height(const pk_film *film) { return film ? film->height : 0; }
float *pk_film_sums(pk_film *film) { return film ? film->sums : NULL; }
uint32_t *pk_film_counts(pk_film *film) { return film ? film->counts : NULL; }

float *pk_film_aov_sums(pk_film *film, unsigned aov)
{
    if (!film) return NULL;
    for (int k = 0; k < FILM_AOVS; k++)
        if (aov == 1u << k) return film->aov[k]; /* NULL when not held */
    return NULL;
}

void pk_film_clear(pk_film *film)
{
    if (film) film_clear(film);
}

pk_status pk_film_merge(pk_context *ctx, pk_film *dst, const pk_film *src)
{
    if (!ctx || !dst || !src) return PK_ERR_INVALID_ARGUMENT;
    if (dst->width != src->width || dst->height != src->height)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "cannot merge a %dx%d film into a %dx%d film", src->width,
                         src->height, dst->width, dst->height);
    film_merge(dst, src); /* dst == src doubles every sum and count */
    return PK_OK;
}

pk_status pk_film_resolve(pk_context *ctx, const pk_film *film, pk_image **out)
{
    if (!ctx || !film || !out) return PK_ERR_INVALID_ARGUMENT;
    pk_status st = image_create(ctx, film->width, film->height, out);
    if (st == PK_OK) film_resolve_into(film, *out);
    return st;
}

/* ---- accelerators over scenes ---------------------------------------------------- */

struct pk_accel {
    pk_context *ctx;
    accel *a;
};

pk_status pk_accel_create(pk_context *ctx, const pk_scene *scene, pk_accel_kind kind, int threads, pk_accel **out)
{
    if (!ctx || !scene || !out) return PK_ERR_INVALID_ARGUMENT;
    *out = NULL;
    const pk_int_option *th = pk_int_option_find("threads");
    if (threads < th->min || threads > th->max)
        return ctx_error(ctx, PK_ERR_LIMIT, "threads %d is out of range (%d..%d)", threads, th->min, th->max);
    if ((unsigned)kind > PK_ACCEL_CUDA)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "unknown accelerator %d", (int)kind);
    if (!accel_available_in(ctx, kind)) return accel_unavailable(ctx, kind);
    pk_accel *pa = mem_calloc(&ctx->alloc, 1, sizeof *pa);
    if (!pa) return ctx_nomem(ctx);
    pa->ctx = ctx;
    pk_status st = frame_build_accel(ctx, scene, kind, threads, &pa->a);
    if (st != PK_OK) {
        mem_free(&ctx->alloc, pa);
        return st;
    }
    *out = pa;
    return PK_OK;
}

void pk_accel_destroy(pk_accel *pa)
{
    if (!pa) return;
    accel_destroy(pa->a);
    mem_free(&pa->ctx->alloc, pa);
}

void pk_accel_get_info(const pk_accel *pa, pk_accel_info *info)
{
    if (!pa || !info) return;
    *info = pa->a->info;
}

const char *pk_accel_isa(const pk_accel *pa)
{
    return pa ? pa->a->isa : NULL;
}

void pk_accel_trace(const pk_accel *pa, const pk_ray *rays, pk_hit *hits, size_t n, int threads, unsigned flags,
                    pk_trace_counters *counters)
{
    if (!pa || !rays || !hits || n == 0) return;
    accel_trace_batch(pa->a, (const ray *)rays, (hit *)hits, n, threads, flags, counters);
}

int pk_accel_get_device_info(const pk_accel *pa, pk_accel_device_info *info)
{
    if (!pa || !info) return 0;
    memset(info, 0, sizeof *info);
    if (!pa->a->ops->device_info) return 0;
    pa->a->ops->device_info(pa->a, info);
    return 1;
}
