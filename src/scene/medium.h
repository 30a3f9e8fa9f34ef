/*
 * medium.h - participating media: what fills the space between surfaces
 * (fog, smoke, clouds, the inside of skin, wax or milk), their lookups and
 * the majorants that distance sampling runs against. Readers describe a
 * medium with medium_init and the fields below and hand it to
 * scene_add_medium; scene_commit checks it and derives its majorant grid;
 * the volumetric path tracer (render/volpath_kernel.h) reads it.
 *
 * The model (docs/media.md): at a point x a medium has the extinction
 * sigma_t(x) = sigma_t * density(x) (per unit of world length, per RGB
 * channel), the single-scattering albedo albedo(x) = albedo *
 * albedo_grid(x), so that sigma_s = albedo sigma_t and sigma_a = sigma_t -
 * sigma_s, the emitted radiance le(x) = le * emission_grid(x), which enters
 * the ray at the rate sigma_a(x) le(x), and a Henyey-Greenstein phase
 * function of asymmetry g (0: isotropic). A homogeneous medium has no grids
 * (density 1 everywhere). A grid medium's grids span the unit cube of grid
 * space, which grid_to_world places in the world; outside that box the
 * density is zero.
 *
 * Grids hold nx * ny * nz voxels of 1 or 3 floats (x fastest, then y, then
 * z). Voxel (i, j, k) is the cell [i, i+1] / nx x [j, j+1] / ny x [k, k+1]
 * / nz of the unit cube; lookups interpolate trilinearly between the cell
 * centres and hold the edge value in the outer half cells.
 *
 * Where media are: every material names the medium on the side its
 * geometric normal points to (medium_out: the exterior) and on the other
 * side (medium_in: the interior), or MEDIUM_INHERIT for a surface that does
 * not change the medium a ray is in. A ray that crosses a surface takes
 * the medium of the side it enters; the camera's medium is the scene's
 * camera_medium. MAT_INTERFACE surfaces only bound media: rays pass
 * through them unchanged.
 */
#ifndef PK_MEDIUM_H
#define PK_MEDIUM_H

#include "../math/vec3.h"
#include "../math/xform.h"

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define MEDIUM_NONE (-1)     /* no medium: vacuum */
#define MEDIUM_INHERIT (-2)  /* a surface side that keeps the ray's medium */

/* At most this many voxels per grid (2^27 = 512^3: 512 MiB of one
 * channel); larger grids are refused with a message. */
#define MEDIUM_MAX_VOXELS ((size_t)1 << 27)
/* Majorant cells per axis at most (fewer for smaller grids). Finer grids
 * (32^3 cells over a 256^3 plume) cost more DDA steps than the null
 * collisions they save (bench/media.sh, docs/performance.md). */
#define MEDIUM_MAJORANT_RES 16

typedef enum medium_kind { MEDIUM_HOMOGENEOUS = 0, MEDIUM_GRID = 1 } medium_kind;

typedef struct medium_grid {
    int nx, ny, nz;
    int channels;  /* 1 or 3 */
    float *data;   /* nx * ny * nz * channels floats, owned; NULL: no grid */
} medium_grid;

typedef struct medium {
    char *name;            /* owned; may be NULL */
    int kind;              /* medium_kind */
    vec3 sigma_t;          /* extinction per unit length (scale included); >= 0, finite */
    vec3 albedo;           /* single-scattering albedo, 0..1 */
    vec3 le;               /* emitted radiance; >= 0 */
    float g;               /* Henyey-Greenstein asymmetry, -1 < g < 1 */
    /* MEDIUM_GRID: */
    medium_grid density;   /* required: 1 or 3 channels, >= 0 */
    medium_grid albedo_grid;   /* optional: multiplies albedo (values clamped to 0..1) */
    medium_grid emission_grid; /* optional: multiplies le */
    xform grid_to_world;   /* the unit cube of grid space into the world (affine, not singular) */
    /* derived by scene_commit (medium_prepare): */
    xform world_to_grid;
    aabb bounds;           /* the world box that holds the grid */
    int mres[3];           /* majorant cells per axis */
    float *majorant;       /* mres[0] * mres[1] * mres[2] bounds of max-channel sigma_t, owned */
    float sigma_max;       /* the largest extinction of any channel anywhere */
    bool chromatic;        /* some point's sigma_t differs between channels */
} medium;

/* A homogeneous medium that neither absorbs nor scatters (sigma_t 0,
 * albedo 1, no emission, isotropic), identity placement, no grids. */
static inline void medium_init(medium *m)
{
    *m = (medium){0};
    m->kind = MEDIUM_HOMOGENEOUS;
    m->albedo = v3s(1.0f);
    m->grid_to_world = xform_identity();
    m->world_to_grid = xform_identity();
}

/* ---- lookups ------------------------------------------------------------------ */

static inline PK_HD float medium__clampf(float x, float lo, float hi) { return fminf(fmaxf(x, lo), hi); }

/* The trilinear value of grid g at grid-space point q (unit cube), in c[0..2]
 * (a one-channel grid repeats its value). */
static inline PK_HD vec3 medium_grid_lookup(const medium_grid *g, vec3 q)
{
    const float x = medium__clampf(q.x * (float)g->nx - 0.5f, 0.0f, (float)(g->nx - 1));
    const float y = medium__clampf(q.y * (float)g->ny - 0.5f, 0.0f, (float)(g->ny - 1));
    const float z = medium__clampf(q.z * (float)g->nz - 0.5f, 0.0f, (float)(g->nz - 1));
    const int x0 = (int)x, y0 = (int)y, z0 = (int)z;
    const int x1 = x0 + 1 < g->nx ? x0 + 1 : x0, y1 = y0 + 1 < g->ny ? y0 + 1 : y0, z1 = z0 + 1 < g->nz ? z0 + 1 : z0;
    const float fx = x - (float)x0, fy = y - (float)y0, fz = z - (float)z0;
    const int nc = g->channels;
    float out[3];
    for (int c = 0; c < nc; c++) {
#define MG_AT(i, j, k) g->data[(((size_t)(k) * (size_t)g->ny + (size_t)(j)) * (size_t)g->nx + (size_t)(i)) * (size_t)nc + (size_t)c]
        const float c00 = MG_AT(x0, y0, z0) + fx * (MG_AT(x1, y0, z0) - MG_AT(x0, y0, z0));
        const float c10 = MG_AT(x0, y1, z0) + fx * (MG_AT(x1, y1, z0) - MG_AT(x0, y1, z0));
        const float c01 = MG_AT(x0, y0, z1) + fx * (MG_AT(x1, y0, z1) - MG_AT(x0, y0, z1));
        const float c11 = MG_AT(x0, y1, z1) + fx * (MG_AT(x1, y1, z1) - MG_AT(x0, y1, z1));
#undef MG_AT
        const float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
        out[c] = c0 + fz * (c1 - c0);
    }
    if (nc == 1) return v3s(out[0]);
    return v3(out[0], out[1], out[2]);
}

/* What the medium is at world point p. */
typedef struct medium_point {
    vec3 sigma_a, sigma_s, le;
} medium_point;

static inline PK_HD medium_point medium_at(const medium *m, vec3 p)
{
    medium_point mp;
    vec3 st = m->sigma_t, al = m->albedo, le = m->le;
    if (m->kind == MEDIUM_GRID) {
        const vec3 q = xform_point(&m->world_to_grid, p);
        if (!(q.x >= 0.0f && q.x <= 1.0f && q.y >= 0.0f && q.y <= 1.0f && q.z >= 0.0f && q.z <= 1.0f)) {
            mp.sigma_a = mp.sigma_s = mp.le = v3s(0.0f);
            return mp;
        }
        st = v3_mul(st, medium_grid_lookup(&m->density, q));
        if (m->albedo_grid.data) {
            vec3 a = medium_grid_lookup(&m->albedo_grid, q);
            al = v3_mul(al, v3(medium__clampf(a.x, 0.0f, 1.0f), medium__clampf(a.y, 0.0f, 1.0f),
                               medium__clampf(a.z, 0.0f, 1.0f)));
        }
        if (m->emission_grid.data) le = v3_mul(le, medium_grid_lookup(&m->emission_grid, q));
    }
    mp.sigma_s = v3_mul(st, al);
    mp.sigma_a = v3_max(v3_sub(st, mp.sigma_s), v3s(0.0f));
    mp.le = le;
    return mp;
}

/* ---- majorants along a ray ------------------------------------------------------ */

/* Walks the segments of a ray over which one majorant bounds the extinction
 * of every channel: one segment for a homogeneous medium; for a grid, the
 * majorant cells the ray crosses inside the grid's box (a 3D DDA in grid
 * space; space outside the box has no medium and no segment). Ray
 * parameters are those of the world ray o + t d. */
typedef struct majorant_iter {
    const medium *m;
    float t, tend;       /* the part still to walk */
    int cell[3], step[3];
    float tnext[3], tdelta[3];
    bool homogeneous, done;
} majorant_iter;

static inline PK_HD majorant_iter majorant_start(const medium *m, vec3 o, vec3 d, float tmin, float tmax)
{
    majorant_iter it;
    it.m = m;
    it.t = tmin, it.tend = tmax;
    it.homogeneous = m->kind != MEDIUM_GRID;
    it.done = !(tmax > tmin);
    if (it.homogeneous || it.done) return it;
    const vec3 go = xform_point(&m->world_to_grid, o), gd = xform_vector(&m->world_to_grid, d);
    const float oo[3] = {go.x, go.y, go.z}, dd[3] = {gd.x, gd.y, gd.z};
    float t0 = tmin, t1 = tmax;
    for (int a = 0; a < 3; a++) { /* clip to the unit cube */
        if (dd[a] == 0.0f) {
            if (!(oo[a] >= 0.0f && oo[a] <= 1.0f)) t1 = -1.0f;
            continue;
        }
        float ta = (0.0f - oo[a]) / dd[a], tb = (1.0f - oo[a]) / dd[a];
        if (ta > tb) { float tt = ta; ta = tb; tb = tt; }
        t0 = fmaxf(t0, ta), t1 = fminf(t1, tb);
    }
    if (!(t1 > t0)) {
        it.done = true;
        return it;
    }
    it.t = t0, it.tend = t1;
    for (int a = 0; a < 3; a++) {
        const int n = m->mres[a];
        const float pa = medium__clampf(oo[a] + t0 * dd[a], 0.0f, 1.0f) * (float)n;
        int c = (int)pa;
        if (c >= n) c = n - 1;
        if (c < 0) c = 0;
        it.cell[a] = c;
        if (dd[a] > 0.0f) {
            it.step[a] = 1;
            it.tnext[a] = t0 + ((float)(c + 1) / (float)n - (oo[a] + t0 * dd[a])) / dd[a];
            it.tdelta[a] = 1.0f / ((float)n * dd[a]);
        } else if (dd[a] < 0.0f) {
            it.step[a] = -1;
            it.tnext[a] = t0 + ((float)c / (float)n - (oo[a] + t0 * dd[a])) / dd[a];
            it.tdelta[a] = -1.0f / ((float)n * dd[a]);
        } else {
            it.step[a] = 0;
            it.tnext[a] = INFINITY;
            it.tdelta[a] = INFINITY;
        }
    }
    return it;
}

/* The next segment [*t0, *t1) and its majorant *sigma; false when the ray
 * has no more. */
static inline PK_HD bool majorant_next(majorant_iter *it, float *t0, float *t1, float *sigma)
{
    if (it->done) return false;
    if (it->homogeneous) {
        *t0 = it->t, *t1 = it->tend, *sigma = it->m->sigma_max;
        it->done = true;
        return true;
    }
    const medium *m = it->m;
    int a = 0; /* the axis whose cell boundary comes first */
    if (it->tnext[1] < it->tnext[a]) a = 1;
    if (it->tnext[2] < it->tnext[a]) a = 2;
    const float te = fminf(it->tnext[a], it->tend);
    *t0 = it->t, *t1 = te;
    *sigma = m->majorant[((size_t)it->cell[2] * (size_t)m->mres[1] + (size_t)it->cell[1]) * (size_t)m->mres[0] +
                         (size_t)it->cell[0]];
    it->t = te;
    if (te >= it->tend) {
        it->done = true;
    } else {
        it->cell[a] += it->step[a];
        it->tnext[a] += it->tdelta[a];
        if (it->cell[a] < 0 || it->cell[a] >= m->mres[a]) it->done = true;
    }
    return true;
}

/* ---- the phase function ---------------------------------------------------------- */

/* Henyey-Greenstein's phase function for the angle between wo and wi (both
 * pointing away from the scattering point, so that forward scattering
 * g > 0 sends light on along -wo): its value, which is also its pdf, per
 * steradian. */
static inline PK_HD float phase_hg(float g, float cos_theta)
{
    const float den = 1.0f + g * g + 2.0f * g * cos_theta;
    return (1.0f - g * g) / (4.0f * (float)M_PI * den * sqrtf(fmaxf(den, 1e-12f)));
}

/* phase_hg for directions wo, wi (unit, away from the point). */
static inline PK_HD float phase_hg_eval(float g, vec3 wo, vec3 wi) { return phase_hg(g, v3_dot(wo, wi)); }

/* Samples wi for wo (unit, away from the point) from Henyey-Greenstein's
 * distribution exactly (u1, u2 uniform in [0, 1)); *pdf = phase_hg_eval. */
static inline PK_HD vec3 phase_hg_sample(float g, vec3 wo, float u1, float u2, float *pdf)
{
    float c; /* cosine of the scattering angle between -wo and wi */
    if (fabsf(g) < 1e-3f) {
        c = 1.0f - 2.0f * u1;
    } else {
        const float s = (1.0f - g * g) / (1.0f - g + 2.0f * g * u1);
        c = (1.0f + g * g - s * s) / (2.0f * g);
    }
    c = medium__clampf(c, -1.0f, 1.0f);
    const float sn = sqrtf(fmaxf(0.0f, 1.0f - c * c)), phi = 2.0f * (float)M_PI * u2;
    const vec3 w = v3_neg(wo);
    const vec3 a = fabsf(w.x) > 0.9f ? v3(0.0f, 1.0f, 0.0f) : v3(1.0f, 0.0f, 0.0f);
    const vec3 t = v3_norm(v3_cross(a, w)), b = v3_cross(w, t);
    const vec3 wi = v3_norm(v3_add(v3_add(v3_scale(t, sn * cosf(phi)), v3_scale(b, sn * sinf(phi))), v3_scale(w, c)));
    *pdf = phase_hg_eval(g, wo, wi);
    return wi;
}

#endif
