/*
 * env.c - the environment and sun lights (see env.h).
 */
#include "env.h"

#include "../math/distrib.h"

#include <string.h>

#define SKY_W 512 /* resolution of a baked sky without a map */
#define SKY_H 256

/* ---- the Preetham clear sky ------------------------------------------------ */

/* The Perez luminance distribution (theta from the zenith, gamma from the sun). */
static float perez(const float c[5], float cos_theta, float gamma, float cos_gamma)
{
    return (1.0f + c[0] * expf(c[1] / fmaxf(cos_theta, 0.01f))) *
           (1.0f + c[2] * expf(c[3] * gamma) + c[4] * cos_gamma * cos_gamma);
}

vec3 sky_preetham(vec3 d, vec3 sun, float T)
{
    if (d.y <= 0.0f) return v3s(0.0f);
    const float ts = acosf(fminf(fmaxf(sun.y, 0.0f), 1.0f)); /* the sun's zenith angle, at most 90 degrees */
    /* the distribution coefficients of luminance Y and chromaticity x, y (linear in turbidity) */
    const float cY[5] = {0.1787f * T - 1.4630f, -0.3554f * T + 0.4275f, -0.0227f * T + 5.3251f,
                         0.1206f * T - 2.5771f, -0.0670f * T + 0.3703f};
    const float cx[5] = {-0.0193f * T - 0.2592f, -0.0665f * T + 0.0008f, -0.0004f * T + 0.2125f,
                         -0.0641f * T - 0.8989f, -0.0033f * T + 0.0452f};
    const float cy[5] = {-0.0167f * T - 0.2608f, -0.0950f * T + 0.0092f, -0.0079f * T + 0.2102f,
                         -0.0441f * T - 1.6537f, -0.0109f * T + 0.0529f};
    /* zenith values: luminance in kcd/m^2, chromaticities */
    const float chi = (4.0f / 9.0f - T / 120.0f) * (PK_PI - 2.0f * ts);
    const float Yz = (4.0453f * T - 4.9710f) * tanf(chi) - 0.2155f * T + 2.4192f;
    const float t2 = ts * ts, t3 = t2 * ts, TT = T * T;
    const float xz = TT * (0.00166f * t3 - 0.00375f * t2 + 0.00209f * ts) +
                     T * (-0.02903f * t3 + 0.06377f * t2 - 0.03202f * ts + 0.00394f) +
                     (0.11693f * t3 - 0.21196f * t2 + 0.06052f * ts + 0.25886f);
    const float yz = TT * (0.00275f * t3 - 0.00610f * t2 + 0.00317f * ts) +
                     T * (-0.04214f * t3 + 0.08970f * t2 - 0.04153f * ts + 0.00516f) +
                     (0.15346f * t3 - 0.26756f * t2 + 0.06670f * ts + 0.26688f);
    const float cos_t = d.y;
    const float cos_g = fminf(fmaxf(v3_dot(d, sun), -1.0f), 1.0f), g = acosf(cos_g);
    const float cos_ts = cosf(ts);
    float Y = Yz * perez(cY, cos_t, g, cos_g) / perez(cY, 1.0f, ts, cos_ts);
    float x = xz * perez(cx, cos_t, g, cos_g) / perez(cx, 1.0f, ts, cos_ts);
    float y = yz * perez(cy, cos_t, g, cos_g) / perez(cy, 1.0f, ts, cos_ts);
    if (!(Y > 0.0f) || !(y > 0.0f)) return v3s(0.0f);
    /* kcd/m^2 to W/(m^2 sr) at 683 lm/W, then xyY -> XYZ -> linear sRGB */
    Y *= 1000.0f / 683.0f;
    const float X = x / y * Y, Z = (1.0f - x - y) / y * Y;
    vec3 c = v3(3.2406f * X - 1.5372f * Y - 0.4986f * Z, -0.9689f * X + 1.8758f * Y + 0.0415f * Z,
                0.0557f * X - 0.2040f * Y + 1.0570f * Z);
    return v3(fmaxf(c.x, 0.0f), fmaxf(c.y, 0.0f), fmaxf(c.z, 0.0f));
}

/* ---- the Hosek-Wilkie sky (RGB) ---------------------------------------------- */

#include "hosek_rgb.inc"

/* The quintic Bezier of the six control points c[0], c[stride], ... at x. */
static double hosek_bezier(const double *c, int stride, double x)
{
    const double y = 1.0 - x;
    return y * y * y * y * y * c[0] + 5.0 * y * y * y * y * x * c[stride] + 10.0 * y * y * y * x * x * c[2 * stride] +
           10.0 * y * y * x * x * x * c[3 * stride] + 5.0 * y * x * x * x * x * c[4 * stride] +
           x * x * x * x * x * c[5 * stride];
}

void sky_hosek_init(sky_hosek *h, vec3 sun, float turbidity, vec3 albedo)
{
    memset(h, 0, sizeof *h);
    h->sun = sun;
    double T = fmin(fmax((double)turbidity, 1.0), 10.0);
    int ti = (int)T;
    double tr = T - ti;
    if (ti == 10) ti = 9, tr = 1.0; /* the last table row, fully */
    const double elev = asin(fmin(fmax((double)sun.y, 0.0), 1.0));
    const double x = cbrt(elev / 1.57079632679489661923); /* (elevation / (pi / 2))^(1/3) */
    const float al[3] = {albedo.x, albedo.y, albedo.z};
    for (int c = 0; c < 3; c++) {
        const double a = fmin(fmax((double)al[c], 0.0), 1.0);
        /* weights of (albedo 0|1) x (turbidity ti|ti + 1), rows 0-based */
        const double w[2][2] = {{(1.0 - a) * (1.0 - tr), (1.0 - a) * tr}, {a * (1.0 - tr), a * tr}};
        for (int ia = 0; ia < 2; ia++)
            for (int it = 0; it < 2; it++) {
                if (w[ia][it] == 0.0) continue;
                const int row = ti - 1 + it;
                const double *m = hosek_rgb[c] + 540 * ia + 54 * row;
                for (int i = 0; i < 9; i++) h->cfg[c][i] += w[ia][it] * hosek_bezier(m + i, 9, x);
                h->rad[c] += w[ia][it] * hosek_bezier(hosek_rgb_rad[c] + 60 * ia + 6 * row, 1, x);
            }
    }
}

vec3 sky_hosek_eval(const sky_hosek *h, vec3 d)
{
    if (!(d.y > 0.0f)) return v3s(0.0f);
    const double ct = (double)d.y, cg = fmin(fmax((double)v3_dot(d, h->sun), -1.0), 1.0), g = acos(cg);
    float out[3];
    for (int c = 0; c < 3; c++) {
        const double *k = h->cfg[c]; /* A B C D E F G I H */
        const double mie = (1.0 + cg * cg) / pow(1.0 + k[8] * k[8] - 2.0 * k[8] * cg, 1.5);
        const double f = (1.0 + k[0] * exp(k[1] / (ct + 0.01))) *
                         (k[2] + k[3] * exp(k[4] * g) + k[5] * cg * cg + k[6] * mie + k[7] * sqrt(ct));
        out[c] = (float)fmax(f * h->rad[c] / 106.856980, 0.0);
    }
    return v3(out[0], out[1], out[2]);
}

/* ---- building ---------------------------------------------------------------- */

void env_free(const pk_allocator *al, env_light *e)
{
    mem_free(al, e->rgb);
    mem_free(al, e->marginal);
    mem_free(al, e->conditional);
    mem_free(al, e->weight);
    mem_free(al, e->portal_f);
    mem_free(al, e->portal_sat);
    memset(e, 0, sizeof *e);
}

static bool any(vec3 c) { return c.x > 0.0f || c.y > 0.0f || c.z > 0.0f; }
static float clean(float v) { return isfinite(v) && v > 0.0f ? v : 0.0f; }

/* The sampling tables of the baked image: weights luminance * sin(theta). */
static pk_status build_tables(pk_context *ctx, env_light *e)
{
    const int w = e->w, h = e->h;
    const size_t n = (size_t)w * (size_t)h;
    e->marginal = mem_realloc_array(&ctx->alloc, NULL, (size_t)h, sizeof(float));
    e->conditional = mem_realloc_array(&ctx->alloc, NULL, n, sizeof(float));
    e->weight = mem_realloc_array(&ctx->alloc, NULL, n, sizeof(float));
    if (!e->marginal || !e->conditional || !e->weight) return ctx_nomem(ctx);
    double total = 0.0, lum_solid = 0.0;
    double *rows = mem_realloc_array(&ctx->alloc, NULL, (size_t)h, sizeof(double));
    if (!rows) return ctx_nomem(ctx);
    for (int j = 0; j < h; j++) {
        const float st = sinf(((float)j + 0.5f) / (float)h * PK_PI);
        double acc = 0.0;
        for (int i = 0; i < w; i++) {
            const float *p = &e->rgb[3 * ((size_t)j * (size_t)w + (size_t)i)];
            double f = (double)v3_luminance(v3(p[0], p[1], p[2])) * (double)st;
            e->weight[(size_t)j * (size_t)w + (size_t)i] = (float)f;
            acc += f;
            e->conditional[(size_t)j * (size_t)w + (size_t)i] = (float)acc;
        }
        float *row = &e->conditional[(size_t)j * (size_t)w];
        for (int i = 0; i < w; i++) row[i] = acc > 0.0 ? (float)((double)row[i] / acc) : (float)(i + 1) / (float)w;
        row[w - 1] = 1.0f;
        rows[j] = acc;
        total += acc;
    }
    /* mean radiance over the sphere: sum of L sin(theta) dtheta dphi / (4 pi) */
    lum_solid = total * (2.0 * (double)PK_PI / w) * ((double)PK_PI / h) / (4.0 * (double)PK_PI);
    double acc = 0.0;
    for (int j = 0; j < h; j++) {
        acc += rows[j];
        e->marginal[j] = total > 0.0 ? (float)(acc / total) : (float)(j + 1) / (float)h;
    }
    e->marginal[h - 1] = 1.0f;
    mem_free(&ctx->alloc, rows);
    /* weight: the pdf over (u, v) of each pixel, f * w * h / total */
    for (size_t k = 0; k < n; k++) e->weight[k] = total > 0.0 ? (float)((double)e->weight[k] * (double)n / total) : 0.0f;
    e->active = total > 0.0;
    e->power_env = lum_solid; /* times pi R^2 by the caller */
    e->bytes += (size_t)h * sizeof(float) + 2 * n * sizeof(float);
    return PK_OK;
}

/* The portal's frame from its corners: false unless they make a rectangle. */
static bool portal_frame(const vec3 p[4], float m[9])
{
    const vec3 e03 = v3_sub(p[3], p[0]), e01 = v3_sub(p[1], p[0]);
    if (!(v3_len2(e03) > 0.0f) || !(v3_len2(e01) > 0.0f)) return false;
    const vec3 x = v3_norm(e03), y = v3_norm(e01), z = v3_norm(v3_cross(x, y));
    if (!v3_finite(z) || fabsf(v3_dot(x, y)) > 1e-3f) return false;
    const float r[9] = {x.x, x.y, x.z, y.x, y.y, y.z, z.x, z.y, z.z};
    memcpy(m, r, sizeof r);
    return true;
}

#define PORTAL_MIN 32 /* the density grid's cells a side: the map's rows, within these */
#define PORTAL_MAX 1024

/* The portal's density grid and summed-area table (e's radiance is built):
 * per cell the luminance toward its centre times d(omega)/d(u, v) there,
 * plus a floor of 1% of the mean, so that every direction through the
 * portal can be drawn. */
static pk_status build_portal(pk_context *ctx, const scene_environment *env, env_light *e)
{
    if (!portal_frame(env->portal, e->portal_to_local)) return PK_OK; /* the readers check; whole environment */
    const int n = e->uniform ? 64 : (e->h < PORTAL_MIN ? PORTAL_MIN : e->h > PORTAL_MAX ? PORTAL_MAX : e->h);
    e->pw = e->ph = n;
    const size_t cells = (size_t)n * (size_t)n, W = (size_t)n + 1;
    e->portal_f = mem_realloc_array(&ctx->alloc, NULL, cells, sizeof(float));
    e->portal_sat = mem_calloc(&ctx->alloc, W * W, sizeof(double));
    if (!e->portal_f || !e->portal_sat) return ctx_nomem(ctx);
    e->bytes += cells * sizeof(float) + W * W * sizeof(double);
    double sum = 0.0, flux = 0.0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            float jac;
            const vec3 d = portal_dir(e, ((float)i + 0.5f) / (float)n, ((float)j + 0.5f) / (float)n, &jac);
            const double lum = (double)v3_luminance(env_eval(e, d));
            e->portal_f[(size_t)j * (size_t)n + (size_t)i] = (float)(lum * (double)jac);
            sum += lum * (double)jac;
            flux += lum * (double)jac * (double)v3_dot(d, v3(e->portal_to_local[6], e->portal_to_local[7],
                                                             e->portal_to_local[8]));
        }
    /* the floor: 1% of the mean over the grid (of d(omega)/d(u, v) alone for a black one) */
    double floor_k = 0.01 * sum / (double)cells, total = 0.0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            float jac;
            (void)portal_dir(e, ((float)i + 0.5f) / (float)n, ((float)j + 0.5f) / (float)n, &jac);
            float *f = &e->portal_f[(size_t)j * (size_t)n + (size_t)i];
            *f = (float)((double)*f + (sum > 0.0 ? floor_k : (double)jac));
            total += (double)*f;
        }
    /* density: integral 1 over the unit square; the table of its integrals */
    for (size_t k = 0; k < cells; k++) e->portal_f[k] = (float)((double)e->portal_f[k] * (double)cells / total);
    for (int j = 0; j < n; j++) {
        double row = 0.0;
        for (int i = 0; i < n; i++) {
            row += (double)e->portal_f[(size_t)j * (size_t)n + (size_t)i] / (double)cells;
            e->portal_sat[(size_t)(j + 1) * W + (size_t)(i + 1)] = e->portal_sat[(size_t)j * W + (size_t)(i + 1)] + row;
        }
    }
    e->portal = true;
    e->portal_p0 = env->portal[0];
    e->portal_p2 = env->portal[2];
    /* the power through the portal: its area times the irradiance of the
     * hemisphere it looks at (the sum of luminance times the cosine) */
    const double area = (double)v3_len(v3_sub(env->portal[3], env->portal[0])) *
                        (double)v3_len(v3_sub(env->portal[1], env->portal[0]));
    e->power_env = area * flux / (double)cells;
    return PK_OK;
}

pk_status env_build(pk_context *ctx, const scene_environment *env, const float *map_rgb, int mw, int mh, aabb bounds,
                    env_light *e)
{
    memset(e, 0, sizeof *e);
    memcpy(e->to_world, env->to_world, sizeof e->to_world);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) e->to_map[3 * r + c] = env->to_world[3 * c + r]; /* a rotation: its transpose */
    vec3 ext = aabb_extent(bounds);
    double radius = 0.5 * (double)v3_len(ext);
    if (!isfinite(radius) || radius <= 0.0) radius = 1.0;
    const double area = (double)PK_PI * radius * radius;
    const vec3 constant = v3(clean(env->radiance.x), clean(env->radiance.y), clean(env->radiance.z));
    const bool map = map_rgb && mw > 0 && mh > 0;
    const bool sky = env->has_sky && env->sky_scale > 0.0f;
    vec3 sun = v3_len2(env->sun_dir) > 0.0f ? v3_norm(env->sun_dir) : v3(0.0f, 1.0f, 0.0f);
    if (!map && !sky) {
        if (any(constant)) {
            e->active = e->uniform = true;
            e->constant = constant;
            e->power_env = (double)v3_luminance(constant) * area;
        }
    } else {
        e->w = map ? mw : SKY_W;
        e->h = map ? mh : SKY_H;
        const size_t n = (size_t)e->w * (size_t)e->h;
        e->rgb = mem_realloc_array(&ctx->alloc, NULL, n, 3 * sizeof(float));
        if (!e->rgb) return ctx_nomem(ctx);
        e->bytes = n * 3 * sizeof(float);
        const float scale = clean(env->map_scale);
        sky_hosek hk;
        if (sky && env->sky_hosek) sky_hosek_init(&hk, sun, env->sky_turbidity, env->sky_albedo);
        for (int j = 0; j < e->h; j++)
            for (int i = 0; i < e->w; i++) {
                const size_t k = (size_t)j * (size_t)e->w + (size_t)i;
                vec3 c = constant;
                if (map)
                    c = v3_add(c, v3(clean(map_rgb[3 * k]) * scale, clean(map_rgb[3 * k + 1]) * scale,
                                     clean(map_rgb[3 * k + 2]) * scale));
                if (sky) {
                    vec3 d = latlong_dir(e, ((float)i + 0.5f) / (float)e->w, ((float)j + 0.5f) / (float)e->h);
                    const vec3 sk = env->sky_hosek ? sky_hosek_eval(&hk, d) : sky_preetham(d, sun, env->sky_turbidity);
                    c = v3_add(c, v3_scale(sk, env->sky_scale));
                }
                e->rgb[3 * k] = clean(c.x), e->rgb[3 * k + 1] = clean(c.y), e->rgb[3 * k + 2] = clean(c.z);
            }
        pk_status st = build_tables(ctx, e);
        if (st != PK_OK) {
            env_free(&ctx->alloc, e);
            return st;
        }
        e->power_env *= area;
    }
    if (env->has_sun && any(env->sun_radiance)) {
        float half = 0.5f * env->sun_angle * (PK_PI / 180.0f);
        half = fminf(fmaxf(half, 1e-4f), 0.5f * PK_PI);
        e->sun = true;
        e->sun_dir = sun;
        e->sun_le = v3(clean(env->sun_radiance.x), clean(env->sun_radiance.y), clean(env->sun_radiance.z));
        e->sun_cos = cosf(half);
        const float sh = sinf(0.5f * half);
        e->sun_omc = 2.0f * sh * sh;
        e->sun_frame = onb_from_normal(sun);
        const double solid = 2.0 * (double)PK_PI * (double)e->sun_omc;
        e->power_sun = (double)v3_luminance(e->sun_le) * solid * area;
    }
    if (env->has_portal && e->active) {
        pk_status st = build_portal(ctx, env, e);
        if (st != PK_OK) {
            env_free(&ctx->alloc, e);
            return st;
        }
    }
    return PK_OK;
}
