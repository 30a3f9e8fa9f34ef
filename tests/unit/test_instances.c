/*
 * test_instances.c - instances kept as instances (a two-level structure)
 * against the same scene flattened:
 *  - the two-level BVH and midpoint against the two-level brute force
 *    (none) under general transforms (rotations, non-uniform scales,
 *    mirrors): bit-identical closest hits, agreeing any-hit answers, the
 *    checker's invariants;
 *  - the two-level structures against the flattened scene's: bit-identical
 *    hits (t, u, v and the same triangle of the same instance) where the
 *    transforms are exact in float (signed permutations times powers of two,
 *    whole translations, vertices and ray origins on a coarse grid), close
 *    (same triangle, t within 1e-4 relative) under general transforms, where
 *    rounding differs between moving the ray and moving the triangles;
 *  - the same for Embree's instance geometry (skipped without Embree);
 *  - rendered images of a scene kept and flattened (path tracer and
 *    Whitted): byte-identical with exact transforms, normals and uvs;
 *  - scene_commit's rule (auto, flatten, keep), emitting instances always
 *    flattened, the GPU's refusal;
 *  - 10,000 instances of a 1,280-triangle mesh: kept by the default rule,
 *    the structure's bytes far below what 12.8 M flattened triangles take.
 */
#include "test.h"

#include "accel/accel.h"
#include "render/frame.h"
#include "render/sampling.h"

#include <string.h>

#define NRAYS 20000

static pk_context *ctx;

/* ---- accelerator level ---- */

typedef struct inst_scene {
    vec3 *world;                 /* world triangles, 3 per */
    size_t nworld;
    accel_sphere sph[2];
    size_t nsph;
    vec3 *mv[3];                 /* meshes */
    size_t mn[3];
    accel_mesh meshes[3];
    accel_instance inst[64];
    size_t ninst;
    vec3 *flat;                  /* world + every instance's triangles placed, 3 per */
    size_t nflat;
} inst_scene;

/* exact: vertices on a 1/8 grid, transforms that are signed permutations
 * times powers of two with whole translations. */
static void make_scene(inst_scene *S, bool exact, uint64_t seed)
{
    memset(S, 0, sizeof *S);
    rng r = rng_seed(seed, 5);
#define RND(a, b) ((a) + ((b) - (a)) * rng_float(&r))
#define GRID(x) (exact ? floorf((x) * 8.0f) / 8.0f : (x))
    for (int m = 0; m < 3; m++) {
        size_t n = m == 0 ? 32 : 24;
        S->mv[m] = malloc(3 * n * sizeof(vec3));
        for (size_t k = 0; k < n; k++) {
            if (m == 0 && k < 16) { /* a grid of quads: shared edges and vertices */
                const float x = (float)(k % 4) * 0.5f - 1.0f, z = (float)(k / 4 % 2) * 0.5f - 0.5f;
                const int half = (int)(k / 8);
                vec3 a = v3(x, 0.25f * half, z), b = v3(x + 0.5f, 0.25f * half, z), c = v3(x + 0.5f, 0.25f * half, z + 0.5f),
                     d = v3(x, 0.25f * half, z + 0.5f);
                S->mv[m][3 * k] = a, S->mv[m][3 * k + 1] = k % 2 ? c : b, S->mv[m][3 * k + 2] = k % 2 ? d : c;
                continue;
            }
            vec3 c = v3(GRID(RND(-1, 1)), GRID(RND(-1, 1)), GRID(RND(-1, 1)));
            for (int j = 0; j < 3; j++)
                S->mv[m][3 * k + j] = v3(GRID(c.x + RND(-0.5f, 0.5f)), GRID(c.y + RND(-0.5f, 0.5f)), GRID(c.z + RND(-0.5f, 0.5f)));
        }
        if (m == 2) S->mv[m][3 * 5 + 2] = S->mv[m][3 * 5]; /* a degenerate triangle */
        S->mn[m] = n;
        S->meshes[m] = (accel_mesh){S->mv[m], n};
    }
    S->nworld = 6;
    S->world = malloc(3 * S->nworld * sizeof(vec3));
    for (size_t k = 0; k < 3 * S->nworld; k++) S->world[k] = v3(GRID(RND(-6, 6)), GRID(RND(-6, 6)), GRID(RND(-6, 6)));
    S->nsph = 2;
    S->sph[0] = (accel_sphere){v3(3, 3, 3), 0.75f};
    S->sph[1] = (accel_sphere){v3(-4, 1, 2), 0.5f};
    S->ninst = 48;
    uint32_t prim0 = (uint32_t)(S->nworld + S->nsph);
    size_t total = S->nworld;
    for (size_t i = 0; i < S->ninst; i++) {
        xform x;
        const uint32_t mesh = (uint32_t)(i % 3);
        if (exact) {
            /* a signed permutation times 2^k, a whole translation */
            static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
            const int *p = perms[rng_u32(&r) % 6];
            const float sc = (float)(1 << (rng_u32(&r) % 3)) * (rng_u32(&r) % 2 ? 0.5f : 1.0f);
            x = xform_identity();
            for (int row = 0; row < 3; row++) {
                x.m[4 * row + 0] = x.m[4 * row + 1] = x.m[4 * row + 2] = 0.0f;
                x.m[4 * row + p[row]] = (rng_u32(&r) % 4 == 0 ? -sc : sc);
                x.m[4 * row + 3] = floorf(RND(-8, 8));
            }
        } else {
            xform t = xform_translate(v3(RND(-8, 8), RND(-8, 8), RND(-8, 8)));
            xform ro = xform_rotate(v3(RND(-1, 1), RND(-1, 1), RND(-1, 1) + 0.1f), RND(0, 360));
            xform sc = xform_scale(v3(RND(0.3f, 2), RND(0.3f, 2), (i % 4 == 0 ? -1.0f : 1.0f) * RND(0.3f, 2)));
            xform a = xform_mul(&ro, &sc);
            x = xform_mul(&t, &a);
        }
        S->inst[i] = (accel_instance){x, mesh, prim0};
        prim0 += (uint32_t)S->mn[mesh];
        total += S->mn[mesh];
    }
    S->flat = malloc(3 * total * sizeof(vec3));
    memcpy(S->flat, S->world, 3 * S->nworld * sizeof(vec3));
    S->nflat = S->nworld;
    for (size_t i = 0; i < S->ninst; i++) {
        const accel_instance *in = &S->inst[i];
        for (size_t k = 0; k < 3 * S->mn[in->mesh]; k++) S->flat[3 * S->nflat + k] = xform_point(&in->to_world, S->mv[in->mesh][k]);
        S->nflat += S->mn[in->mesh];
    }
#undef RND
#undef GRID
}

static void free_scene(inst_scene *S)
{
    for (int m = 0; m < 3; m++) free(S->mv[m]);
    free(S->world);
    free(S->flat);
}

/* The flattened build's number of instanced hit number p (spheres come
 * after every triangle there). */
static uint32_t flat_prim(const inst_scene *S, uint32_t p)
{
    if (p == PK_NO_HIT || p < S->nworld) return p;
    if (p < S->nworld + S->nsph) return (uint32_t)(p + (S->nflat - S->nworld));
    return (uint32_t)(p - S->nsph);
}

static void make_rays(ray *rays, size_t n, bool exact, uint64_t seed)
{
    rng r = rng_seed(seed, 17);
    for (size_t i = 0; i < n; i++) {
        vec3 o = v3(rng_float(&r) * 24 - 12, rng_float(&r) * 24 - 12, rng_float(&r) * 24 - 12);
        if (exact) o = v3(floorf(o.x * 64) / 64, floorf(o.y * 64) / 64, floorf(o.z * 64) / 64);
        vec3 target = v3(rng_float(&r) * 16 - 8, rng_float(&r) * 16 - 8, rng_float(&r) * 16 - 8);
        vec3 d = v3_sub(target, o);
        if (i % 3 == 0) d = v3_scale(d, 0.001f + 10.0f * rng_float(&r)); /* t is not a distance */
        if (i % 23 == 0) d.y = 0.0f;
        rays[i] = (ray){o, 0.0f, d, INFINITY};
        if (i % 5 == 0) rays[i].tmax = 0.5f + rng_float(&r);
        if (i % 7 == 0) rays[i].tmin = 0.2f * rng_float(&r);
    }
}

static void build(pk_accel_kind kind, const inst_scene *S, bool instanced, accel **out)
{
    *out = NULL;
    if (instanced) {
        accel_input in = {S->world, S->nworld, S->sph, S->nsph, 2};
        accel_instances ti = {S->meshes, 3, S->inst, S->ninst};
        REQUIRE(accel_create_instanced(ctx, kind, &in, &ti, out) == PK_OK);
    } else {
        accel_input in = {S->flat, S->nflat, S->sph, S->nsph, 2};
        REQUIRE(accel_create(ctx, kind, &in, out) == PK_OK);
    }
}

static bool same_hit(hit a, hit b)
{
    return memcmp(&a.t, &b.t, 4) == 0 && a.prim == b.prim && memcmp(&a.u, &b.u, 4) == 0 && memcmp(&a.v, &b.v, 4) == 0;
}

/* Embree's: the same triangle, t, u and v within 1e-5 (Embree's own
 * triangle test and instance transforms round differently when the
 * triangle moves instead of the ray). */
static bool same_embree_hit(hit a, hit b)
{
    if (a.prim == PK_NO_HIT || b.prim == PK_NO_HIT) return a.prim == b.prim;
    return a.prim == b.prim && fabsf(a.t - b.t) <= 1e-5f * fabsf(b.t) && fabsf(a.u - b.u) <= 1e-5f &&
           fabsf(a.v - b.v) <= 1e-5f;
}

/* Two-level kinds against two-level brute force, general transforms. */
static void check_two_level(void)
{
    inst_scene S;
    make_scene(&S, false, 3);
    accel *ref = NULL;
    build(PK_ACCEL_NONE, &S, true, &ref);
    ray *rays = malloc(NRAYS * sizeof *rays);
    hit *h0 = malloc(NRAYS * sizeof *h0), *h1 = malloc(NRAYS * sizeof *h1), *o1 = malloc(NRAYS * sizeof *o1);
    REQUIRE(rays && h0 && h1 && o1);
    make_rays(rays, NRAYS, false, 9);
    accel_trace_batch(ref, rays, h0, NRAYS, 2, 0, NULL);
    size_t hits = 0, inst_hits = 0;
    for (size_t i = 0; i < NRAYS; i++) {
        hits += h0[i].prim != PK_NO_HIT;
        inst_hits += h0[i].prim != PK_NO_HIT && h0[i].prim >= S.nworld + S.nsph;
    }
    CHECKF(inst_hits > NRAYS / 10 && hits > inst_hits, "too few hits to test (%zu, %zu in instances)", hits, inst_hits);
    const pk_accel_kind kinds[] = {PK_ACCEL_BVH, PK_ACCEL_MIDPOINT};
    for (size_t q = 0; q < 2; q++) {
        accel *acc = NULL;
        build(kinds[q], &S, true, &acc);
        char why[256] = "";
        CHECKF(accel_instances_check(acc, why, sizeof why), "%s: %s", acc->info.name, why);
        accel_trace_batch(acc, rays, h1, NRAYS, 2, 0, NULL);
        accel_trace_batch(acc, rays, o1, NRAYS, 2, PK_TRACE_ANY_HIT, NULL);
        size_t bad = 0, bad_any = 0;
        for (size_t i = 0; i < NRAYS; i++) {
            if (!same_hit(h0[i], h1[i]) && bad++ < 5)
                fprintf(stderr, "  %s ray %zu: t %.9g prim %u, brute force t %.9g prim %u\n", acc->info.name, i,
                        (double)h1[i].t, h1[i].prim, (double)h0[i].t, h0[i].prim);
            if ((o1[i].prim != PK_NO_HIT) != (h0[i].prim != PK_NO_HIT)) bad_any++;
        }
        CHECKF(bad == 0, "%s two-level: %zu of %d closest hits differ from brute force", acc->info.name, bad, NRAYS);
        CHECKF(bad_any == 0, "%s two-level: %zu any-hit answers differ", acc->info.name, bad_any);
        accel_destroy(acc);
    }
    /* against the flattened scene: the same triangle of the same instance, t close */
    accel *flat = NULL;
    build(PK_ACCEL_BVH, &S, false, &flat);
    char why[256] = "";
    CHECK(!accel_instances_check(flat, why, sizeof why) && strstr(why, "not a two-level") != NULL);
    accel_trace_batch(flat, rays, h1, NRAYS, 2, 0, NULL);
    size_t other = 0, far = 0;
    for (size_t i = 0; i < NRAYS; i++) {
        if (flat_prim(&S, h0[i].prim) != h1[i].prim) {
            other++;
            continue;
        }
        /* relative to t, and a floor of 1e-5 in distance (a few ulps of the scene's coordinates, up
         * to 24): a ray that starts on a triangle hits it at a t near 0, where the two transforms'
         * roundings differ by more than 1e-4 of t (ray 911 with clang: t 2.4607e-4 against 2.4623e-4,
         * 2e-6 apart in distance) */
        const float len = v3_len(rays[i].d);
        if (h0[i].prim != PK_NO_HIT && fabsf(h0[i].t - h1[i].t) * len > 1e-4f * fabsf(h1[i].t) * len + 1e-5f) far++;
    }
    CHECKF(other <= NRAYS / 1000, "general transforms: %zu of %d rays hit another triangle than flattened", other, NRAYS);
    CHECKF(far == 0, "general transforms: %zu hits with t off by more than 1e-4 (and 1e-5 in distance)", far);
    printf("general transforms: %zu hits (%zu in instances); %zu of %d rays differ from the flattened scene's "
           "triangle (grazing edges), t within 1e-4 (or 1e-5 in distance)\n", hits, inst_hits, other, NRAYS);
    accel_destroy(flat);
    accel_destroy(ref);
    free(rays), free(h0), free(h1), free(o1);
    free_scene(&S);
}

/* Exact transforms: instanced and flattened give the same bits. */
static void check_exact(pk_accel_kind kind, const char *name)
{
    inst_scene S;
    make_scene(&S, true, 11);
    accel *flat = NULL, *two = NULL;
    build(kind, &S, false, &flat);
    build(kind, &S, true, &two);
    ray *rays = malloc(NRAYS * sizeof *rays);
    hit *h0 = malloc(NRAYS * sizeof *h0), *h1 = malloc(NRAYS * sizeof *h1), *o1 = malloc(NRAYS * sizeof *o1);
    REQUIRE(rays && h0 && h1 && o1);
    make_rays(rays, NRAYS, true, 21);
    accel_trace_batch(flat, rays, h0, NRAYS, 2, 0, NULL);
    accel_trace_batch(two, rays, h1, NRAYS, 2, 0, NULL);
    accel_trace_batch(two, rays, o1, NRAYS, 2, PK_TRACE_ANY_HIT, NULL);
    size_t bad = 0, bad_any = 0, inst_hits = 0;
    for (size_t i = 0; i < NRAYS; i++) {
        hit m = h1[i];
        m.prim = flat_prim(&S, m.prim);
        inst_hits += h1[i].prim != PK_NO_HIT && h1[i].prim >= S.nworld + S.nsph;
        if (!(kind == PK_ACCEL_EMBREE ? same_embree_hit(m, h0[i]) : same_hit(m, h0[i])) && bad++ < 5 &&
            kind != PK_ACCEL_EMBREE)
            fprintf(stderr, "  %s ray %zu: instanced t %.9g prim %u (flattened %u) u %.9g, flattened t %.9g prim %u u %.9g\n",
                    name, i, (double)h1[i].t, h1[i].prim, m.prim, (double)h1[i].u, (double)h0[i].t, h0[i].prim,
                    (double)h0[i].u);
        if ((o1[i].prim != PK_NO_HIT) != (h0[i].prim != PK_NO_HIT)) bad_any++;
    }
    CHECKF(inst_hits > NRAYS / 10, "%s: too few hits in instances (%zu)", name, inst_hits);
    /* Embree misses or finds a very few edge hits one way and not the other */
    CHECKF(kind == PK_ACCEL_EMBREE ? bad <= NRAYS / 1000 : bad == 0,
           "%s exact transforms: %zu of %d hits differ between instanced and flattened", name, bad, NRAYS);
    CHECKF(kind == PK_ACCEL_EMBREE ? bad_any <= NRAYS / 1000 : bad_any == 0,
           "%s exact transforms: %zu any-hit answers differ", name, bad_any);
    printf("%s, exact transforms: %d rays, %zu hits in instances, instanced = flattened %s: %s\n", name, NRAYS,
           inst_hits, kind == PK_ACCEL_EMBREE ? "(triangle; t, u, v within 1e-5)" : "bit for bit",
           bad > (kind == PK_ACCEL_EMBREE ? (size_t)NRAYS / 1000 : 0) ? "no" : "yes");
    if (kind == PK_ACCEL_EMBREE) printf("embree: %zu of %d rays differ beyond that\n", bad, NRAYS);
    accel_destroy(flat);
    accel_destroy(two);
    free(rays), free(h0), free(h1), free(o1);
    free_scene(&S);
}

static void check_embree(void)
{
    if (!accel_embree_available(ctx)) {
        printf("Embree is not available: its instance geometry is not tested\n");
        return;
    }
    check_exact(PK_ACCEL_EMBREE, "embree");
    /* general transforms: Embree's instances against its flattened build, closely */
    inst_scene S;
    make_scene(&S, false, 3);
    accel *flat = NULL, *two = NULL;
    build(PK_ACCEL_EMBREE, &S, false, &flat);
    build(PK_ACCEL_EMBREE, &S, true, &two);
    ray *rays = malloc(NRAYS * sizeof *rays);
    hit *h0 = malloc(NRAYS * sizeof *h0), *h1 = malloc(NRAYS * sizeof *h1);
    REQUIRE(rays && h0 && h1);
    make_rays(rays, NRAYS, false, 9);
    accel_trace_batch(flat, rays, h0, NRAYS, 2, 0, NULL);
    accel_trace_batch(two, rays, h1, NRAYS, 2, PK_TRACE_COHERENT, NULL);
    size_t other = 0;
    for (size_t i = 0; i < NRAYS; i++)
        if (flat_prim(&S, h1[i].prim) != h0[i].prim ||
            (h0[i].prim != PK_NO_HIT && fabsf(h0[i].t - h1[i].t) > 1e-4f * fabsf(h0[i].t)))
            other++;
    CHECKF(other <= NRAYS / 1000, "embree general transforms: %zu of %d rays differ", other, NRAYS);
    accel_destroy(flat);
    accel_destroy(two);
    free(rays), free(h0), free(h1);
    free_scene(&S);
}

/* ---- scene and renderer level ---- */

/* A floor, a light quad, and a mesh (two quads with normals and uvs)
 * placed n times; exact: signed permutations and whole translations. */
static pk_scene *make_pk_scene(const char *config, size_t n, bool exact, bool emissive_instance)
{
    pk_context_clear_error(ctx);
    REQUIRE(pk_context_set_config(ctx, config) == PK_OK);
    pk_scene *s = NULL;
    REQUIRE(scene_create(ctx, "instances", &s) == PK_OK);
    uint32_t red, lamp;
    REQUIRE(scene_add_material(ctx, s, "red", &red) == PK_OK);
    s->materials[red].kd = v3(0.7f, 0.2f, 0.1f);
    REQUIRE(scene_add_material(ctx, s, "lamp", &lamp) == PK_OK);
    s->materials[lamp].ke = v3s(4.0f);
    /* the mesh: 4 triangles over 6 vertices, bent so that normals vary */
    const size_t p0 = s->npositions, n0 = s->nnormals, u0 = s->nuvs, t0 = s->ntris;
    const vec3 mp[6] = {v3(-1, 0, -1), v3(1, 0, -1), v3(1, 0.5f, 0), v3(-1, 0.5f, 0), v3(1, 0, 1), v3(-1, 0, 1)};
    for (int i = 0; i < 6; i++) {
        REQUIRE(scene_add_position(ctx, s, mp[i]) == PK_OK);
        REQUIRE(scene_add_normal(ctx, s, v3_norm(v3(mp[i].x * 0.3f, 1.0f, mp[i].z * 0.5f))) == PK_OK);
        REQUIRE(scene_add_uv(ctx, s, (uv2){mp[i].x * 0.5f + 0.5f, mp[i].z * 0.5f + 0.5f}) == PK_OK);
    }
    const int idx[4][3] = {{0, 1, 2}, {0, 2, 3}, {3, 2, 4}, {3, 4, 5}};
    for (int k = 0; k < 4; k++) {
        triangle t;
        for (int j = 0; j < 3; j++) t.v[j] = (uint32_t)(p0 + idx[k][j]), t.n[j] = (int32_t)(n0 + idx[k][j]), t.t[j] = (int32_t)(u0 + idx[k][j]);
        t.material = k < 2 ? red : 0;
        REQUIRE(scene_add_triangle(ctx, s, &t) == PK_OK);
    }
    uint32_t mesh;
    REQUIRE(scene_capture_mesh(ctx, s, p0, n0, u0, t0, &mesh) == PK_OK);
    rng r = rng_seed(77, 1);
    for (size_t i = 0; i < n; i++) {
        xform x;
        const float gx = (float)(i % 8) * 3.0f - 10.5f, gz = (float)(i / 8 % 8) * 3.0f - 10.5f, gy = (float)(i / 64) * 2.0f;
        if (exact) {
            x = xform_identity();
            if (i % 3 == 1) x.m[0] = -1.0f;                                          /* a mirror */
            if (i % 3 == 2) x.m[0] = x.m[2] = x.m[8] = x.m[10] = 0.0f, x.m[2] = 2.0f, x.m[8] = 1.0f; /* swap x, z, scale */
            x.m[3] = gx, x.m[7] = gy, x.m[11] = gz;
        } else {
            xform t = xform_translate(v3(gx, gy, gz));
            xform ro = xform_rotate(v3(rng_float(&r), 1.0f, rng_float(&r)), 360.0f * rng_float(&r));
            xform sc = xform_scale(v3(1.2f, i % 2 ? -0.8f : 0.8f, 1.0f));
            xform a = xform_mul(&ro, &sc);
            x = xform_mul(&t, &a);
        }
        REQUIRE(scene_add_instance(ctx, s, mesh, &x, emissive_instance && i == 0 ? lamp : SCENE_MESH_MATERIAL) == PK_OK);
    }
    /* a floor and a lamp of the world's own */
    const vec3 fl[4] = {v3(-14, -1, -14), v3(14, -1, -14), v3(14, -1, 14), v3(-14, -1, 14)};
    const vec3 la[4] = {v3(-2, 12, -2), v3(2, 12, -2), v3(2, 12, 2), v3(-2, 12, 2)};
    for (int q = 0; q < 2; q++) {
        const size_t b = s->npositions;
        for (int i = 0; i < 4; i++) REQUIRE(scene_add_position(ctx, s, q ? la[i] : fl[i]) == PK_OK);
        triangle t1 = {{(uint32_t)b, (uint32_t)b + 2, (uint32_t)b + 1}, {-1, -1, -1}, {-1, -1, -1}, q ? lamp : 0};
        triangle t2 = {{(uint32_t)b, (uint32_t)b + 3, (uint32_t)b + 2}, {-1, -1, -1}, {-1, -1, -1}, q ? lamp : 0};
        if (q) t1.v[1] = (uint32_t)b + 1, t1.v[2] = (uint32_t)b + 2, t2.v[1] = (uint32_t)b + 2, t2.v[2] = (uint32_t)b + 3;
        REQUIRE(scene_add_triangle(ctx, s, &t1) == PK_OK && scene_add_triangle(ctx, s, &t2) == PK_OK);
    }
    s->has_camera = true;
    pk_camera_init(&s->camera);
    s->camera.look_from[0] = 3.0f, s->camera.look_from[1] = 14.0f, s->camera.look_from[2] = 22.0f;
    s->camera.look_at[0] = 0.0f, s->camera.look_at[1] = 0.0f, s->camera.look_at[2] = 0.0f;
    REQUIRE(scene_commit(ctx, s) == PK_OK);
    return s;
}

static pk_image *render(pk_scene *s, pk_integrator_kind integ, pk_accel_kind kind)
{
    pk_render_options ro;
    pk_render_options_init(&ro);
    ro.width = 96, ro.height = 72, ro.spp = 4, ro.threads = 2, ro.integrator = integ, ro.accel = kind;
    pk_image *img = NULL;
    CHECKF(pk_render(ctx, s, &ro, &img, NULL) == PK_OK, "render: %s", pk_context_error(ctx));
    return img;
}

static double image_diff(pk_image *a, pk_image *b, size_t *ndiff)
{
    const float *pa = pk_image_pixels(a), *pb = pk_image_pixels(b);
    size_t n = (size_t)pk_image_width(a) * pk_image_height(a) * 3;
    double sum = 0.0, tot = 0.0;
    *ndiff = 0;
    for (size_t i = 0; i < n; i++) {
        *ndiff += memcmp(&pa[i], &pb[i], 4) != 0;
        sum += fabs((double)pa[i] - (double)pb[i]);
        tot += fabs((double)pb[i]);
    }
    return tot > 0 ? sum / tot : 0.0;
}

static void check_images(void)
{
    for (int exact = 1; exact >= 0; exact--) {
        pk_scene *flat = make_pk_scene("scene.instances=flatten", 40, exact, false);
        pk_scene *kept = make_pk_scene("scene.instances=keep", 40, exact, false);
        CHECK(flat->nkept == 0 && kept->nkept == 40 && kept->nkept_tris == 160);
        CHECK(memcmp(&flat->bounds, &kept->bounds, sizeof flat->bounds) == 0);
        const pk_integrator_kind integ[2] = {PK_INTEGRATOR_PATH, PK_INTEGRATOR_WHITTED};
        for (int q = 0; q < 2; q++) {
            pk_image *a = render(flat, integ[q], PK_ACCEL_BVH), *b = render(kept, integ[q], PK_ACCEL_BVH);
            REQUIRE(a && b);
            size_t nd = 0;
            const double rel = image_diff(b, a, &nd);
            /* Whitted's rays here start where moving them into an instance is
             * exact (the camera's whole-number origin; shadow rays only ask
             * whether); the path tracer's bounces start anywhere, and a ray
             * origin less a whole translation rounds unlike a vertex plus it:
             * hits agree to the last bits, rarely a path goes another way */
            if (exact && q == 1)
                CHECKF(nd == 0, "%s, exact transforms: %zu values differ kept vs flattened", q ? "whitted" : "path", nd);
            else if (exact)
                CHECKF(rel < 1e-6 && nd < 96 * 72 * 3 / 100, "path, exact transforms: %zu values differ, relative %.3g", nd, rel);
            else
                CHECKF(rel < 2e-3, "%s, general transforms: relative difference %.3g", q ? "whitted" : "path", rel);
            printf("image %s, %s transforms: %zu values differ kept vs flattened, mean relative difference %.3g\n",
                   q ? "whitted" : "path", exact ? "exact" : "general", nd, rel);
            pk_image_destroy(a);
            pk_image_destroy(b);
        }
        if (exact && accel_embree_available(ctx)) {
            pk_image *a = render(flat, PK_INTEGRATOR_PATH, PK_ACCEL_EMBREE), *b = render(kept, PK_INTEGRATOR_PATH, PK_ACCEL_EMBREE);
            REQUIRE(a && b);
            size_t nd = 0;
            const double rel = image_diff(b, a, &nd);
            CHECKF(rel < 1e-3, "embree: kept vs flattened relative difference %.3g", rel);
            printf("image path (embree), exact transforms: %zu values differ kept vs flattened, mean relative difference %.3g\n", nd, rel);
            pk_image_destroy(a);
            pk_image_destroy(b);
        }
        scene_destroy(flat);
        scene_destroy(kept);
    }
}

static void check_rule(void)
{
    /* auto: 40 instances of 4 triangles stay flattened (today's scenes are unchanged) */
    pk_scene *s = make_pk_scene("scene.instances=auto", 40, true, false);
    CHECK(s->nkept == 0 && s->ntris == 4 + 160);
    scene_destroy(s);
    /* an emitting instance is flattened even when asked to keep */
    s = make_pk_scene("scene.instances=keep", 10, true, true);
    CHECK(s->nkept == 9 && s->nemissive == 2 + 4);
    scene_destroy(s);
    /* the GPU refuses a scene that keeps instances, naming the limit */
    s = make_pk_scene("scene.instances=keep", 4, true, false);
    pk_render_options ro;
    pk_render_options_init(&ro);
    ro.width = 8, ro.height = 8, ro.device = PK_DEVICE_CUDA, ro.accel = PK_ACCEL_CUDA;
    pk_image *img = NULL;
    pk_context_clear_error(ctx);
    CHECK(pk_render(ctx, s, &ro, &img, NULL) != PK_OK && img == NULL);
    CHECKF(strstr(pk_context_error(ctx), "4 instances") != NULL || strstr(pk_context_error(ctx), "not available") != NULL,
           "GPU message: %s", pk_context_error(ctx));
    pk_context_clear_error(ctx);
    scene_destroy(s);
    REQUIRE(pk_context_set_config(ctx, "scene.instances=auto") == PK_OK);
}

/* 10,000 instances of a 1,280-triangle sphere: kept by the default rule. */
static void check_many(void)
{
    pk_context_clear_error(ctx);
    REQUIRE(pk_context_set_config(ctx, "scene.instances=auto") == PK_OK);
    pk_scene *s = NULL;
    REQUIRE(scene_create(ctx, "many", &s) == PK_OK);
    const int S = 32, T = 21;
    REQUIRE(scene_add_position(ctx, s, v3(0, 1, 0)) == PK_OK);
    for (int j = 1; j < T; j++)
        for (int i = 0; i < S; i++) {
            const float th = PK_PI * (float)j / (float)T, ph = 2.0f * PK_PI * (float)i / (float)S;
            REQUIRE(scene_add_position(ctx, s, v3(sinf(th) * cosf(ph), cosf(th), sinf(th) * sinf(ph))) == PK_OK);
        }
    REQUIRE(scene_add_position(ctx, s, v3(0, -1, 0)) == PK_OK);
    const uint32_t last = (uint32_t)s->npositions - 1;
#define RING(j, i) (1u + (uint32_t)((j) - 1) * (uint32_t)S + (uint32_t)((i) % S))
    for (int i = 0; i < S; i++) {
        triangle a = {{0, RING(1, i + 1), RING(1, i)}, {-1, -1, -1}, {-1, -1, -1}, 0};
        triangle b = {{last, RING(T - 1, i), RING(T - 1, i + 1)}, {-1, -1, -1}, {-1, -1, -1}, 0};
        REQUIRE(scene_add_triangle(ctx, s, &a) == PK_OK && scene_add_triangle(ctx, s, &b) == PK_OK);
    }
    for (int j = 1; j < T - 1; j++)
        for (int i = 0; i < S; i++) {
            triangle a = {{RING(j, i), RING(j, i + 1), RING(j + 1, i + 1)}, {-1, -1, -1}, {-1, -1, -1}, 0};
            triangle b = {{RING(j, i), RING(j + 1, i + 1), RING(j + 1, i)}, {-1, -1, -1}, {-1, -1, -1}, 0};
            REQUIRE(scene_add_triangle(ctx, s, &a) == PK_OK && scene_add_triangle(ctx, s, &b) == PK_OK);
        }
#undef RING
    REQUIRE(s->ntris == 1280);
    uint32_t mesh;
    REQUIRE(scene_capture_mesh(ctx, s, 0, 0, 0, 0, &mesh) == PK_OK);
    const size_t n = 10000;
    for (size_t i = 0; i < n; i++) {
        xform x = xform_translate(v3((float)(i % 100) * 2.5f, 0.0f, (float)(i / 100) * 2.5f));
        REQUIRE(scene_add_instance(ctx, s, mesh, &x, SCENE_MESH_MATERIAL) == PK_OK);
    }
    REQUIRE(scene_commit(ctx, s) == PK_OK);
    CHECKF(s->nkept == n && s->nkept_tris == n * 1280 && s->ntris == 0, "kept %zu instances, %zu triangles", s->nkept,
           s->ntris);
    accel *a = NULL;
    REQUIRE(frame_build_accel(ctx, s, PK_ACCEL_BVH, 2, &a) == PK_OK);
    /* a flattened BVH holds at least a 32-byte slot per triangle, and the
     * scene 12 bytes of vertex and 40 of triangle record: over 1 GB here */
    const size_t flat_min = n * 1280 * (32 + 40 + 12);
    CHECKF(a->info.bytes * 100 < flat_min, "two-level structure of %zu bytes (flattened: over %zu)", a->info.bytes, flat_min);
    printf("10000 instances of 1280 triangles: structure %.2f MiB (flattened: over %.0f MiB), primitives %zu\n",
           (double)a->info.bytes / 1048576.0, (double)flat_min / 1048576.0, a->info.primitives);
    CHECK(a->info.primitives == n * 1280);
    /* rays down the rows hit the right instances */
    for (size_t i = 0; i < n; i += 997) {
        const vec3 c = v3((float)(i % 100) * 2.5f, 0.0f, (float)(i / 100) * 2.5f);
        ray r = {v3(c.x + 0.1f, 10.0f, c.z + 0.05f), 0.0f, v3(0, -1, 0), INFINITY};
        hit h;
        CHECK(accel_intersect(a, &r, &h, NULL));
        CHECKF(h.prim >= s->kept[i].prim0 && h.prim < s->kept[i].prim0 + 1280 && fabsf(h.t - 9.0f) < 0.02f,
               "instance %zu: prim %u t %g", i, h.prim, (double)h.t);
    }
    accel_destroy(a);
    pk_image *img = render(s, PK_INTEGRATOR_PATH, PK_ACCEL_BVH);
    CHECK(img != NULL);
    pk_image_destroy(img);
    scene_destroy(s);
}

/* ---- JSON: a mesh's "instances" ---- */

static const char *json_files[][2] = {
    {"mem/tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n"},
    {"mem/ok.json", "{\"meshes\": [{\"obj\": \"tri.obj\", \"transform\": {\"scale\": 2},\n"
                    "  \"instances\": [{\"translate\": [4, 0, 0]}, [1,0,0,0, 0,1,0,0, 0,0,-1,3, 0,0,0,1]]},\n"
                    " {\"obj\": \"tri.obj\"}]}"},
    {"mem/singular.json", "{\"meshes\": [{\"obj\": \"tri.obj\",\n  \"instances\": [{\"translate\": [4, 0, 0]},\n"
                          "  {\"scale\": [1, 0, 1]}]}]}"},
    {"mem/notarray.json", "{\"meshes\": [{\"obj\": \"tri.obj\", \"instances\": {}}]}"},
};

static pk_status serve(void *user, const char *path, const void **data, size_t *size, char *why, size_t cap)
{
    (void)user;
    for (size_t i = 0; i < sizeof json_files / sizeof *json_files; i++)
        if (strcmp(path, json_files[i][0]) == 0) {
            *data = json_files[i][1];
            *size = strlen(json_files[i][1]);
            return PK_OK;
        }
    snprintf(why, cap, "no such file");
    return PK_ERR_IO;
}

static void check_json(void)
{
    pk_context *c = NULL;
    REQUIRE(pk_context_create(NULL, &c) == PK_OK);
    pk_context_set_file_reader(c, serve, NULL);
    REQUIRE(pk_context_set_config(c, "scene.instances=keep") == PK_OK);
    pk_scene *s = NULL;
    CHECKF(pk_scene_load_file(c, "mem/ok.json", &s) == PK_OK, "ok.json: %s", pk_context_error(c));
    if (s) {
        /* two instances of the first mesh (scaled by 2 once, then placed twice), the second in the world */
        CHECK(s->nmeshes == 1 && s->nkept == 2 && s->ntris == 2 && s->nkept_tris == 4);
        CHECK(s->mesh_positions[3].x == 2.0f && s->mesh_positions[3].y == 2.0f); /* "transform" shapes the mesh */
        CHECK(s->kept[0].to_world.m[0] == 1.0f && s->kept[0].to_world.m[3] == 4.0f);
        CHECK(s->kept[1].to_world.m[10] == -1.0f && s->kept[1].to_world.m[11] == 3.0f);
        CHECK(s->bounds.lo.z == 0.0f && s->bounds.hi.z == 3.0f && s->bounds.hi.x == 6.0f);
        pk_scene_destroy(s);
    }
    REQUIRE(pk_context_set_config(c, "scene.instances=flatten") == PK_OK);
    s = NULL;
    CHECK(pk_scene_load_file(c, "mem/ok.json", &s) == PK_OK && s && s->nkept == 0 && s->ntris == 6);
    pk_scene_destroy(s);
    s = NULL;
    CHECK(pk_scene_load_file(c, "mem/singular.json", &s) == PK_ERR_PARSE && s == NULL);
    CHECKF(strstr(pk_context_error(c), "singular.json:3: meshes[0].instances[1]") != NULL, "message: %s",
           pk_context_error(c));
    pk_context_clear_error(c);
    CHECK(pk_scene_load_file(c, "mem/notarray.json", &s) == PK_ERR_PARSE && s == NULL);
    CHECKF(strstr(pk_context_error(c), "meshes[0].instances") != NULL && strstr(pk_context_error(c), "array") != NULL,
           "message: %s", pk_context_error(c));
    pk_context_destroy(c);
}

/* ---- every allocation failing in turn ---- */

typedef struct fail_alloc {
    long calls, fail_at, live, failed;
} fail_alloc;

static void *fail_hook(void *user, void *ptr, size_t size)
{
    fail_alloc *f = user;
    if (size == 0) {
        if (ptr) {
            f->live--;
            free((char *)ptr - 16);
        }
        return NULL;
    }
    f->calls++;
    if (f->fail_at && f->calls == f->fail_at) {
        f->failed++;
        return NULL;
    }
    char *q = realloc(ptr ? (char *)ptr - 16 : NULL, size + 16);
    if (!q) return NULL;
    if (!ptr) f->live++;
    return q + 16;
}

/* Loading a JSON scene that keeps instances, and rendering it through the
 * two-level BVH and brute force, with allocation N failing, for every N:
 * PK_ERR_NOMEM back and nothing left allocated. */
static void check_alloc_fail(void)
{
    long n = 0;
    for (long at = 1; at < 100000; at++) {
        fail_alloc f = {0, at, 0, 0};
        pk_allocator al = {fail_hook, &f};
        pk_context *c = NULL;
        if (pk_context_create(&al, &c) != PK_OK) {
            CHECK(f.live == 0);
            continue;
        }
        pk_context_set_file_reader(c, serve, NULL);
        pk_status st = pk_context_set_config(c, "scene.instances=keep");
        pk_scene *s = NULL;
        if (st == PK_OK) st = pk_scene_load_file(c, "mem/ok.json", &s);
        for (int k = 0; k < 2 && st == PK_OK; k++) {
            pk_render_options ro;
            pk_render_options_init(&ro);
            ro.width = 8, ro.height = 8, ro.spp = 1, ro.threads = 1, ro.accel = k ? PK_ACCEL_NONE : PK_ACCEL_BVH;
            pk_image *img = NULL;
            st = pk_render(c, s, &ro, &img, NULL);
            pk_image_destroy(img);
        }
        pk_scene_destroy(s);
        pk_context_destroy(c);
        CHECKF(f.live == 0, "allocation %ld failing: %ld blocks left", at, f.live);
        CHECKF(st == PK_OK || st == PK_ERR_NOMEM || f.failed, "allocation %ld failing: status %d", at, (int)st);
        if (!f.failed) {
            CHECKF(st == PK_OK, "no allocation failed, status %d", (int)st);
            n = at;
            break;
        }
    }
    CHECKF(n > 20, "the sweep ended after %ld allocations", n);
    printf("allocation failures: %ld points swept\n", n);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    check_two_level();
    check_exact(PK_ACCEL_BVH, "bvh");
    check_exact(PK_ACCEL_MIDPOINT, "midpoint");
    check_exact(PK_ACCEL_NONE, "none");
    check_embree();
    check_rule();
    check_json();
    check_alloc_fail();
    check_images();
    check_many();
    pk_context_destroy(ctx);
    return test_done("test_instances");
}
