/*
 * options.c - render-option defaults, the one table of integer option ranges
 * (served to the API, JSON scenes and the paprsek program) and the
 * accelerator name table. Depends on nothing but the public header and the
 * context's error latch.
 */
#include "options.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#define OPT(field, label, lo, hi, def, text) {#field, label, text, lo, hi, def, offsetof(pk_render_options, field)}

static const pk_int_option table[] = {
    OPT(width, "width", 1, PK_MAX_IMAGE_SIDE, 512, "image width in pixels"),
    OPT(height, "height", 1, PK_MAX_IMAGE_SIDE, 512, "image height in pixels"),
    OPT(spp, "samples per pixel", 1, PK_MAX_SPP, 1, "samples per pixel (stratified jitter; 1 = pixel centres)"),
    OPT(light_samples, "light samples", 0, PK_MAX_LIGHT_SAMPLES, 32,
        "shadow samples per shading point over the area lights and the environment (0 = point lights "
        "and the sun only)"),
    OPT(max_depth, "max depth", -1, PK_MAX_DEPTH, -1,
        "path length in bounces (path) or reflection and refraction depth (whitted); -1 = the integrator's "
        "default, 64 for path, 1024 for volpath and 8 for whitted"),
    OPT(threads, "threads", 0, PK_MAX_THREADS, 0, "worker threads (0 = all cores)"),
    OPT(seed, "seed", 0, 2147483647, 0, "the path tracer's noise pattern (another seed, other noise)"),
    OPT(regularize, "regularize", 0, 1, 0,
        "1: after the first rough or diffuse bounce, roughen near-specular surfaces (fewer caustic "
        "fireflies, a biased image); 0: off"),
    OPT(light_tree, "light tree", -1, 1, -1,
        "how the path tracer chooses a light to sample: 1 by its importance to the shading point (a tree "
        "over the lights), 0 by power alone, -1 the tree when the scene has 8 or more lights besides the "
        "environment, the sun and distant lights"),
};
#undef OPT

#define NOPTS (sizeof table / sizeof table[0])

const pk_int_option *pk_int_options(size_t *count)
{
    if (count) *count = NOPTS;
    return table;
}

/* name matches key with '-' taken as '_'. */
static bool same_name(const char *name, const char *key)
{
    for (; *name && *key; name++, key++)
        if (*name != *key && !(*name == '-' && *key == '_')) return false;
    return *name == *key;
}

const pk_int_option *pk_int_option_find(const char *name)
{
    if (!name) return NULL;
    for (size_t i = 0; i < NOPTS; i++)
        if (same_name(name, table[i].name)) return &table[i];
    return NULL;
}

int *options_int_field(pk_render_options *opt, const pk_int_option *o)
{
    return (int *)(void *)((char *)opt + o->offset);
}

int pk_render_options_max_depth(const pk_render_options *opt)
{
    if (!opt) return PK_DEFAULT_DEPTH_PATH;
    if (opt->max_depth >= 0) return opt->max_depth;
    if (opt->integrator == PK_INTEGRATOR_VOLPATH) return PK_DEFAULT_DEPTH_VOLPATH;
    return opt->integrator == PK_INTEGRATOR_WHITTED ? PK_DEFAULT_DEPTH_WHITTED : PK_DEFAULT_DEPTH_PATH;
}

void pk_render_options_init(pk_render_options *opt)
{
    if (!opt) return;
    memset(opt, 0, sizeof *opt);
    for (size_t i = 0; i < NOPTS; i++) *options_int_field(opt, &table[i]) = table[i].default_value;
    opt->accel = PK_ACCEL_DEFAULT;
    opt->fresnel = 1;
    pk_filter_init(&opt->filter, PK_FILTER_BOX);
}

pk_status options_check(pk_context *ctx, const pk_render_options *o)
{
    for (size_t i = 0; i < NOPTS; i++) {
        const int v = *(const int *)(const void *)((const char *)o + table[i].offset);
        if (v < table[i].min || v > table[i].max)
            return ctx_error(ctx, PK_ERR_LIMIT, "%s %d is out of range (%d..%d)", table[i].label, v, table[i].min,
                             table[i].max);
    }
    if ((uint64_t)o->width * (uint64_t)o->height > PK_MAX_IMAGE_PIXELS)
        return ctx_error(ctx, PK_ERR_LIMIT, "image of %dx%d pixels is larger than %u pixels", o->width, o->height,
                         PK_MAX_IMAGE_PIXELS);
    if ((unsigned)o->accel > PK_ACCEL_CUDA)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "unknown accelerator %d", (int)o->accel);
    if ((unsigned)o->integrator > PK_INTEGRATOR_VOLPATH)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "unknown integrator %d", (int)o->integrator);
    if ((unsigned)o->transparent > 1u)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "transparent %d is not 0 or 1", o->transparent);
    if ((unsigned)o->energy_compensation > 1u)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "energy compensation %d is not 0 or 1", o->energy_compensation);
    if ((unsigned)o->device > PK_DEVICE_CUDA)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "unknown device %d", (int)o->device);
    return options_check_filter(ctx, &o->filter);
}

pk_status options_check_filter(pk_context *ctx, const pk_filter *f)
{
    if ((unsigned)f->type > PK_FILTER_LANCZOS)
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "unknown filter type %d", (int)f->type);
    const char *name = pk_filter_name(f->type);
    if (!(f->radius_x > 0.0f && f->radius_x <= PK_FILTER_MAX_RADIUS && f->radius_y > 0.0f &&
          f->radius_y <= PK_FILTER_MAX_RADIUS))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "filter %s: radius %g x %g is not in (0, %g]", name,
                         (double)f->radius_x, (double)f->radius_y, (double)PK_FILTER_MAX_RADIUS);
    if (f->type == PK_FILTER_GAUSSIAN && !(f->sigma > 0.0f && isfinite(f->sigma)))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "filter gaussian: sigma %g must be positive", (double)f->sigma);
    if (f->type == PK_FILTER_MITCHELL && !(fabsf(f->b) <= 16.0f && fabsf(f->c) <= 16.0f))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "filter mitchell: B %g and C %g must be in [-16, 16]",
                         (double)f->b, (double)f->c);
    if (f->type == PK_FILTER_LANCZOS && !(f->tau > 0.0f && f->tau <= 1024.0f))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "filter lanczos: tau %g must be in (0, 1024]", (double)f->tau);
    return PK_OK;
}

/* ---- pixel filters ------------------------------------------------------------ */

static const char *const filter_names[] = {"box", "triangle", "gaussian", "mitchell", "blackman-harris", "lanczos"};

void pk_filter_init(pk_filter *f, pk_filter_type type)
{
    if (!f) return;
    static const float radius[] = {0.5f, 2.0f, 1.5f, 2.0f, 1.5f, 4.0f};
    memset(f, 0, sizeof *f);
    if ((unsigned)type > PK_FILTER_LANCZOS) type = PK_FILTER_BOX;
    f->type = type;
    f->radius_x = f->radius_y = radius[type];
    f->sigma = 0.5f;
    f->b = f->c = 1.0f / 3.0f;
    f->tau = 3.0f;
}

const char *pk_filter_name(pk_filter_type type)
{
    if ((unsigned)type >= sizeof filter_names / sizeof filter_names[0]) return "unknown";
    return filter_names[type];
}

pk_status pk_filter_parse(const char *name, pk_filter_type *out)
{
    if (!name || !out) return PK_ERR_INVALID_ARGUMENT;
    for (int k = PK_FILTER_BOX; k <= PK_FILTER_LANCZOS; k++)
        if (strcmp(name, filter_names[k]) == 0) {
            *out = (pk_filter_type)k;
            return PK_OK;
        }
    return PK_ERR_INVALID_ARGUMENT;
}

void options_resolve_device(pk_render_options *o)
{
    if (o->device == PK_DEVICE_CUDA)
        o->accel = PK_ACCEL_CUDA;
    else if (o->device == PK_DEVICE_CPU && o->accel == PK_ACCEL_CUDA)
        o->device = PK_DEVICE_CUDA;
}

/* ---- device names ------------------------------------------------------------ */

static const char *const device_names[] = {"cpu", "cuda"};

const char *pk_device_name(pk_device_kind kind)
{
    if ((unsigned)kind >= sizeof device_names / sizeof device_names[0]) return "unknown";
    return device_names[kind];
}

pk_status pk_device_parse(const char *name, pk_device_kind *out)
{
    if (!name || !out) return PK_ERR_INVALID_ARGUMENT;
    for (int k = PK_DEVICE_CPU; k <= PK_DEVICE_CUDA; k++)
        if (strcmp(name, device_names[k]) == 0) {
            *out = (pk_device_kind)k;
            return PK_OK;
        }
    return PK_ERR_INVALID_ARGUMENT;
}

/* ---- integrator names ------------------------------------------------------ */

static const char *const integrator_names[] = {"path", "whitted", "path", "volpath"};

const char *pk_integrator_name(pk_integrator_kind kind)
{
    if ((unsigned)kind >= sizeof integrator_names / sizeof integrator_names[0]) return "unknown";
    return integrator_names[kind];
}

pk_status pk_integrator_parse(const char *name, pk_integrator_kind *out)
{
    if (!name || !out) return PK_ERR_INVALID_ARGUMENT;
    if (strcmp(name, "whitted") == 0) *out = PK_INTEGRATOR_WHITTED;
    else if (strcmp(name, "path") == 0) *out = PK_INTEGRATOR_PATH;
    else if (strcmp(name, "volpath") == 0) *out = PK_INTEGRATOR_VOLPATH;
    else if (strcmp(name, "default") == 0) *out = PK_INTEGRATOR_DEFAULT;
    else return PK_ERR_INVALID_ARGUMENT;
    return PK_OK;
}

/* ---- accelerator names ----------------------------------------------------- */

static const char *const accel_names[] = {"bvh", "none", "midpoint", "bvh", "embree", "cuda"};

const char *pk_accel_kind_name(pk_accel_kind kind)
{
    if ((unsigned)kind >= sizeof accel_names / sizeof accel_names[0]) return "unknown";
    return accel_names[kind];
}

pk_status pk_accel_kind_parse(const char *name, pk_accel_kind *out)
{
    if (!name || !out) return PK_ERR_INVALID_ARGUMENT;
    for (int k = PK_ACCEL_NONE; k <= PK_ACCEL_CUDA; k++)
        if (strcmp(name, accel_names[k]) == 0) {
            *out = (pk_accel_kind)k;
            return PK_OK;
        }
    if (strcmp(name, "default") == 0) {
        *out = PK_ACCEL_DEFAULT;
        return PK_OK;
    }
    return PK_ERR_INVALID_ARGUMENT;
}
