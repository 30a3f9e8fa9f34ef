/*
 * medium.c - the scene's participating media: adding and finding them,
 * checking what readers describe, and deriving what distance sampling needs
 * (medium.h).
 */
#include "scene.h"

#include <stdio.h>
#include <string.h>

#define SCENE_MAX_MEDIA ((size_t)1 << 16)

static void grid_free(const pk_allocator *a, medium_grid *g)
{
    mem_free(a, g->data);
    g->data = NULL;
}

void medium_free(const pk_allocator *a, medium *m)
{
    mem_free(a, m->name);
    grid_free(a, &m->density);
    grid_free(a, &m->albedo_grid);
    grid_free(a, &m->emission_grid);
    mem_free(a, m->majorant);
    m->name = NULL;
    m->majorant = NULL;
}

void medium_set_coefficients(medium *m, vec3 sigma_a, vec3 sigma_s, float scale)
{
    const vec3 t = v3_add(sigma_a, sigma_s);
    const float tt[3] = {t.x, t.y, t.z}, ss[3] = {sigma_s.x, sigma_s.y, sigma_s.z};
    float a[3];
    for (int c = 0; c < 3; c++) a[c] = tt[c] > 0.0f ? fminf(ss[c] / tt[c], 1.0f) : 1.0f;
    m->sigma_t = v3_scale(t, scale);
    m->albedo = v3(a[0], a[1], a[2]);
}

pk_status scene_add_medium(pk_context *ctx, pk_scene *s, medium *m, uint32_t *index)
{
    if (s->nmedia >= SCENE_MAX_MEDIA) {
        medium_free(&s->alloc, m);
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: more than %zu media in one scene", s->name, (size_t)SCENE_MAX_MEDIA);
    }
    if (!mem_grow(&s->alloc, (void **)&s->media, &s->cap_media, s->nmedia + 1, sizeof *s->media)) {
        medium_free(&s->alloc, m);
        return ctx_nomem(ctx);
    }
    m->majorant = NULL;
    *index = (uint32_t)s->nmedia;
    s->media[s->nmedia++] = *m;
    s->committed = false;
    return PK_OK;
}

int64_t scene_find_medium(const pk_scene *s, const char *name)
{
    for (size_t i = s->nmedia; i-- > 0;)
        if (s->media[i].name && strcmp(s->media[i].name, name) == 0) return (int64_t)i;
    return -1;
}

static bool v3_nonneg_finite(vec3 v) { return v3_finite(v) && v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f; }

/* Checks grid g (what: its role in messages). */
static pk_status grid_check(pk_context *ctx, const pk_scene *s, const char *mname, const char *what,
                            const medium_grid *g, bool nonneg)
{
    if (g->nx < 1 || g->ny < 1 || g->nz < 1 || (g->channels != 1 && g->channels != 3))
        return ctx_error(ctx, PK_ERR_PARSE, "%s: medium '%s': %s grid has size %dx%dx%d with %d channels", s->name,
                         mname, what, g->nx, g->ny, g->nz, g->channels);
    const size_t n = (size_t)g->nx * (size_t)g->ny * (size_t)g->nz;
    if ((size_t)g->nx > MEDIUM_MAX_VOXELS || (size_t)g->ny > MEDIUM_MAX_VOXELS || n > MEDIUM_MAX_VOXELS ||
        n / (size_t)g->nx / (size_t)g->ny != (size_t)g->nz)
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: medium '%s': %s grid of %dx%dx%d voxels is over the limit of %zu",
                         s->name, mname, what, g->nx, g->ny, g->nz, (size_t)MEDIUM_MAX_VOXELS);
    const size_t nv = n * (size_t)g->channels;
    for (size_t i = 0; i < nv; i++) {
        const float v = g->data[i];
        if (!isfinite(v) || (nonneg && v < 0.0f))
            return ctx_error(ctx, PK_ERR_PARSE, "%s: medium '%s': %s grid value %zu is %g (values must be finite%s)",
                             s->name, mname, what, i / (size_t)g->channels, (double)v, nonneg ? " and >= 0" : "");
    }
    return PK_OK;
}

/* The majorant grid of a grid medium: each cell bounds sigma_t over every
 * point whose trilinear lookup reads a voxel the cell reaches. */
static pk_status build_majorant(pk_context *ctx, pk_scene *s, medium *m)
{
    const medium_grid *g = &m->density;
    const int n[3] = {g->nx, g->ny, g->nz};
    for (int a = 0; a < 3; a++) m->mres[a] = n[a] < MEDIUM_MAJORANT_RES ? n[a] : MEDIUM_MAJORANT_RES;
    const size_t cells = (size_t)m->mres[0] * (size_t)m->mres[1] * (size_t)m->mres[2];
    m->majorant = mem_realloc_array(&s->alloc, NULL, cells, sizeof *m->majorant);
    if (!m->majorant) return ctx_nomem(ctx);
    /* the largest density value (over channels, weighted by sigma_t) of each voxel */
    int lo[3][MEDIUM_MAJORANT_RES], hi[3][MEDIUM_MAJORANT_RES];
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < m->mres[a]; c++) {
            /* cell c covers [c, c+1] / mres of the unit cube; a point there reads
             * voxels from floor(x n - 0.5) to that + 1, clamped */
            const double x0 = (double)c / m->mres[a] * n[a] - 0.5, x1 = (double)(c + 1) / m->mres[a] * n[a] - 0.5;
            int l = (int)floor(x0), h = (int)floor(x1) + 1;
            if (l < 0) l = 0;
            if (h > n[a] - 1) h = n[a] - 1;
            lo[a][c] = l, hi[a][c] = h;
        }
    float wmax = 0.0f;
    bool chromatic = false;
    const float sc[3] = {m->sigma_t.x, m->sigma_t.y, m->sigma_t.z};
    for (int cz = 0; cz < m->mres[2]; cz++)
        for (int cy = 0; cy < m->mres[1]; cy++)
            for (int cx = 0; cx < m->mres[0]; cx++) {
                float best = 0.0f;
                for (int k = lo[2][cz]; k <= hi[2][cz]; k++)
                    for (int j = lo[1][cy]; j <= hi[1][cy]; j++)
                        for (int i = lo[0][cx]; i <= hi[0][cx]; i++) {
                            const float *v =
                                &g->data[(((size_t)k * (size_t)g->ny + (size_t)j) * (size_t)g->nx + (size_t)i) *
                                         (size_t)g->channels];
                            for (int ch = 0; ch < 3; ch++) { /* (no fmaxf: a call per voxel in libm) */
                                const float d = v[g->channels == 3 ? ch : 0] * sc[ch];
                                best = d > best ? d : best;
                            }
                            if (g->channels == 3 && (v[0] != v[1] || v[1] != v[2])) chromatic = true;
                        }
                /* one ulp of headroom per factor: the lookup's arithmetic cannot exceed it */
                const float b = best * (1.0f + 1e-5f);
                m->majorant[((size_t)cz * (size_t)m->mres[1] + (size_t)cy) * (size_t)m->mres[0] + (size_t)cx] = b;
                wmax = b > wmax ? b : wmax;
            }
    m->sigma_max = wmax;
    m->chromatic = chromatic || !(m->sigma_t.x == m->sigma_t.y && m->sigma_t.y == m->sigma_t.z);
    return PK_OK;
}

static size_t grid_bytes(const medium_grid *g)
{
    return g->data ? (size_t)g->nx * (size_t)g->ny * (size_t)g->nz * (size_t)g->channels * sizeof(float) : 0;
}

pk_status scene_media_prepare(pk_context *ctx, pk_scene *s)
{
    s->medium_bytes = 0;
    for (size_t i = 0; i < s->nmedia; i++) {
        medium *m = &s->media[i];
        char num[32];
        snprintf(num, sizeof num, "#%zu", i);
        const char *mn = m->name ? m->name : num;
        if (!v3_nonneg_finite(m->sigma_t))
            return ctx_error(ctx, PK_ERR_PARSE, "%s: medium '%s': extinction (%g, %g, %g) must be finite and >= 0",
                             s->name, mn, (double)m->sigma_t.x, (double)m->sigma_t.y, (double)m->sigma_t.z);
        if (!v3_nonneg_finite(m->albedo) || m->albedo.x > 1.0f || m->albedo.y > 1.0f || m->albedo.z > 1.0f)
            return ctx_error(ctx, PK_ERR_PARSE, "%s: medium '%s': albedo (%g, %g, %g) must lie in 0..1", s->name, mn,
                             (double)m->albedo.x, (double)m->albedo.y, (double)m->albedo.z);
        if (!v3_nonneg_finite(m->le))
            return ctx_error(ctx, PK_ERR_PARSE, "%s: medium '%s': emission must be finite and >= 0", s->name, mn);
        if (!(m->g > -1.0f && m->g < 1.0f))
            return ctx_error(ctx, PK_ERR_PARSE, "%s: medium '%s': phase asymmetry g = %g must lie strictly between -1 and 1",
                             s->name, mn, (double)m->g);
        mem_free(&s->alloc, m->majorant);
        m->majorant = NULL;
        if (m->kind == MEDIUM_HOMOGENEOUS) {
            m->sigma_max = v3_max_comp(m->sigma_t);
            m->chromatic = !(m->sigma_t.x == m->sigma_t.y && m->sigma_t.y == m->sigma_t.z);
            m->bounds = (aabb){v3s(-INFINITY), v3s(INFINITY)};
            continue;
        }
        if (m->kind != MEDIUM_GRID)
            return ctx_error(ctx, PK_ERR_PARSE, "%s: medium '%s': unknown kind %d", s->name, mn, m->kind);
        if (!m->density.data)
            return ctx_error(ctx, PK_ERR_PARSE, "%s: medium '%s': a grid medium needs a density grid", s->name, mn);
        pk_status st = grid_check(ctx, s, mn, "density", &m->density, true);
        if (st == PK_OK && m->albedo_grid.data) st = grid_check(ctx, s, mn, "albedo", &m->albedo_grid, true);
        if (st == PK_OK && m->emission_grid.data) st = grid_check(ctx, s, mn, "emission", &m->emission_grid, true);
        if (st != PK_OK) return st;
        if (!xform_finite(&m->grid_to_world) || !xform_is_affine(&m->grid_to_world) ||
            !xform_invert(&m->grid_to_world, &m->world_to_grid))
            return ctx_error(ctx, PK_ERR_PARSE, "%s: medium '%s': the grid's placement is not an invertible affine transform",
                             s->name, mn);
        m->bounds = aabb_empty();
        for (int c = 0; c < 8; c++)
            m->bounds = aabb_grow(m->bounds, xform_point(&m->grid_to_world, v3((float)(c & 1), (float)((c >> 1) & 1),
                                                                                (float)((c >> 2) & 1))));
        st = build_majorant(ctx, s, m);
        if (st != PK_OK) return st;
        s->medium_bytes += grid_bytes(&m->density) + grid_bytes(&m->albedo_grid) + grid_bytes(&m->emission_grid) +
                           (size_t)m->mres[0] * (size_t)m->mres[1] * (size_t)m->mres[2] * sizeof(float);
    }
    const int64_t nm = (int64_t)s->nmedia;
    for (size_t i = 0; i < s->nmaterials; i++) {
        const material *mt = &s->materials[i];
        const int32_t sides[2] = {mt->medium_in, mt->medium_out};
        for (int k = 0; k < 2; k++)
            if (sides[k] < MEDIUM_INHERIT || sides[k] >= nm)
                return ctx_error(ctx, PK_ERR_PARSE, "%s: material '%s' names medium %d, and the scene has %zu", s->name,
                                 mt->name ? mt->name : "", (int)sides[k], s->nmedia);
    }
    if (s->camera_medium < MEDIUM_NONE || s->camera_medium >= nm)
        return ctx_error(ctx, PK_ERR_PARSE, "%s: the camera's medium %d is not one of the scene's %zu", s->name,
                         (int)s->camera_medium, s->nmedia);
    return PK_OK;
}

pk_status scene_material_with_media(pk_context *ctx, pk_scene *s, uint32_t mat, int32_t med_in, int32_t med_out,
                                    uint32_t *out)
{
    if (mat >= s->nmaterials) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: no material %u", s->name, mat);
    const material *m = &s->materials[mat];
    if (m->medium_in == med_in && m->medium_out == med_out) {
        *out = mat;
        return PK_OK;
    }
    char name[512];
    snprintf(name, sizeof name, "%s@%d,%d", m->name ? m->name : "", (int)med_in, (int)med_out);
    const int64_t found = scene_find_material(s, name);
    if (found >= 0) {
        *out = (uint32_t)found;
        return PK_OK;
    }
    uint32_t idx, parts[2];
    pk_status st;
    const bool mix = m->type == MAT_MIX;
    if (mix) { /* both materials of a mix bound the media */
        const int ab[2] = {m->mix_a, m->mix_b};
        for (int k = 0; k < 2; k++)
            if ((st = scene_material_with_media(ctx, s, (uint32_t)ab[k], med_in, med_out, &parts[k])) != PK_OK) return st;
    }
    st = scene_material_copy(ctx, s, mat, name, &idx);
    if (st != PK_OK) return st;
    material *c = &s->materials[idx];
    c->medium_in = med_in, c->medium_out = med_out;
    if (mix) c->mix_a = (int)parts[0], c->mix_b = (int)parts[1];
    *out = idx;
    return PK_OK;
}

bool scene_has_media(const pk_scene *s)
{
    if (s->camera_medium >= 0) return true;
    for (size_t i = 0; i < s->nmaterials; i++)
        if (s->materials[i].medium_in >= 0 || s->materials[i].medium_out >= 0) return true;
    return false;
}
