/*
 * test_medium.c - the medium model (scene/medium.h): the grid lookup
 * against its definition (trilinear between cell centres, held at the
 * edges), majorant grids that bound the extinction everywhere along rays
 * through them (and the DDA that walks them covers the ray's part inside
 * the box without gaps), Henyey-Greenstein sampling against its pdf by
 * chi-square for several g, the pdf's normalisation, and scene_commit's
 * refusals of bad media.
 */
#include "chi2.h"
#include "test.h"

#include "io/grid_io.h"
#include "paprsek.h"
#include "render/sampling.h"
#include "scene/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI_D 3.14159265358979323846

static pk_context *ctx;

static float frand(rng *r) { return rng_float(r); }

/* ---- lookups ---------------------------------------------------------------------- */

static void check_lookup(void)
{
    float data[3 * 2 * 2];
    medium_grid g = {3, 2, 2, 1, data};
    for (int i = 0; i < 12; i++) data[i] = (float)(i * i % 7);
    /* at a cell centre: the voxel */
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < 2; j++)
            for (int i = 0; i < 3; i++) {
                const vec3 q = v3((i + 0.5f) / 3.0f, (j + 0.5f) / 2.0f, (k + 0.5f) / 2.0f);
                CHECK_NEAR(medium_grid_lookup(&g, q).x, data[(k * 2 + j) * 3 + i], 1e-5);
            }
    /* half way between two centres along x: their mean; in the outer half cell: the edge value */
    CHECK_NEAR(medium_grid_lookup(&g, v3(1.0f / 3.0f, 0.25f, 0.25f)).x, 0.5f * (data[0] + data[1]), 1e-5);
    CHECK_NEAR(medium_grid_lookup(&g, v3(0.01f, 0.25f, 0.25f)).x, data[0], 1e-6);
    CHECK_NEAR(medium_grid_lookup(&g, v3(0.99f, 0.75f, 0.75f)).x, data[11], 1e-6);
    /* three channels */
    float d3[2 * 3] = {1, 2, 3, 5, 7, 11};
    medium_grid g3 = {2, 1, 1, 3, d3};
    const vec3 v = medium_grid_lookup(&g3, v3(0.5f, 0.5f, 0.5f));
    CHECK_NEAR(v.x, 3.0f, 1e-6);
    CHECK_NEAR(v.y, 4.5f, 1e-6);
    CHECK_NEAR(v.z, 7.0f, 1e-6);
}

/* ---- majorants ---------------------------------------------------------------------- */

static void check_majorants(void)
{
    pk_scene *s = NULL;
    REQUIRE(scene_create(ctx, "majorants", &s) == PK_OK);
    sphere sp = {v3s(0.0f), 1.0f, 0};
    REQUIRE(scene_add_sphere(ctx, s, &sp) == PK_OK);
    medium m;
    medium_init(&m);
    m.kind = MEDIUM_GRID;
    m.sigma_t = v3(2.0f, 0.5f, 1.0f);
    const int n[3] = {37, 20, 45};
    m.density = (medium_grid){n[0], n[1], n[2], 3, NULL};
    const size_t nv = (size_t)n[0] * n[1] * n[2];
    m.density.data = mem_realloc_array(&s->alloc, NULL, nv * 3, sizeof(float));
    REQUIRE(m.density.data);
    rng r = rng_seed(7, 11);
    for (size_t i = 0; i < nv * 3; i++) { /* sparse blobs in one corner: most voxels empty */
        const size_t v = i / 3, x = v % (size_t)n[0], z = v / ((size_t)n[0] * (size_t)n[1]);
        const float u = frand(&r);
        m.density.data[i] = u < 0.8f || x > 15 || z > 20 ? 0.0f : 10.0f * frand(&r);
    }
    const xform sc = xform_scale(v3(3.0f, 2.0f, 4.0f)), tr = xform_translate(v3(-1.5f, -1.0f, -2.0f));
    const xform rot = xform_rotate(v3(1.0f, 1.0f, 0.0f), 30.0f);
    const xform a = xform_mul(&tr, &sc);
    m.grid_to_world = xform_mul(&rot, &a);
    uint32_t mi;
    REQUIRE(scene_add_medium(ctx, s, &m, &mi) == PK_OK);
    s->camera_medium = (int32_t)mi;
    REQUIRE(scene_commit(ctx, s) == PK_OK);
    const medium *md = &s->media[mi];
    CHECK(md->mres[0] == 16 && md->mres[1] == 16 && md->mres[2] == 16);
    CHECK(md->chromatic);
    CHECK(s->medium_bytes == nv * 3 * sizeof(float) + 16 * 16 * 16 * sizeof(float));
    int violations = 0, gaps = 0;
    long points = 0, empty_cells = 0, segments = 0;
    for (int ray_i = 0; ray_i < 3000; ray_i++) {
        const vec3 o = v3(6.0f * frand(&r) - 3.0f, 6.0f * frand(&r) - 3.0f, 6.0f * frand(&r) - 3.0f);
        vec3 d = v3(frand(&r) - 0.5f, frand(&r) - 0.5f, frand(&r) - 0.5f);
        d = v3_scale(v3_norm(d), 0.5f + frand(&r)); /* not unit: the walk is in the ray's parameter */
        majorant_iter it = majorant_start(md, o, d, 0.0f, 20.0f);
        float t0, t1, sig, prev = -1.0f;
        bool first = true;
        while (majorant_next(&it, &t0, &t1, &sig)) {
            segments++;
            if (!first && fabsf(t0 - prev) > 1e-4f) gaps++;
            first = false;
            prev = t1;
            if (sig == 0.0f) empty_cells++;
            for (int k = 0; k < 8; k++) {
                const float t = t0 + (t1 - t0) * (k + 0.5f) / 8.0f;
                const medium_point mp = medium_at(md, v3_add(o, v3_scale(d, t)));
                const float st = v3_max_comp(v3_add(mp.sigma_a, mp.sigma_s));
                points++;
                if (st > sig * (1.0f + 1e-4f) + 1e-6f && violations++ < 5)
                    CHECKF(0, "ray %d: sigma_t %g above the majorant %g at t %g", ray_i, (double)st, (double)sig,
                           (double)t);
            }
        }
    }
    CHECKF(violations == 0, "%d points above their majorant", violations);
    CHECKF(gaps == 0, "%d gaps between consecutive segments", gaps);
    CHECKF(empty_cells > 0, "sparse blobs leave empty majorant cells (%ld of %ld segments)", empty_cells, segments);
    printf("  majorants: %ld points in %ld segments, %ld empty\n", points, segments, empty_cells);
    scene_destroy(s);
}

/* ---- Henyey-Greenstein ----------------------------------------------------------------- */

static void check_hg(void)
{
    const float gs[5] = {0.0f, 0.3f, 0.9f, -0.6f, 0.0005f};
    const vec3 wo = v3_norm(v3(0.3f, -0.5f, 0.8f));
    for (int gi = 0; gi < 5; gi++) {
        const float g = gs[gi];
        /* normalisation: the integral of the pdf over the sphere (midpoint rule in cos, phi) */
        double integral = 0.0;
        const int nc = 4000;
        for (int i = 0; i < nc; i++) {
            const double c = -1.0 + (i + 0.5) * 2.0 / nc;
            integral += (double)phase_hg(g, (float)c) * 2.0 * PI_D * 2.0 / nc;
        }
        CHECKF(fabs(integral - 1.0) < 2e-3, "g %g: the pdf integrates to %g", (double)g, integral);
        /* chi-square over (cos to -wo, phi) bins, expected counts from the pdf */
        enum { NC = 20, NP = 8 };
        const int N = 400000;
        double count[NC][NP] = {{0}};
        rng r = rng_seed(3, (uint64_t)gi);
        const vec3 w = v3_neg(wo);
        const vec3 a = fabsf(w.x) > 0.9f ? v3(0.0f, 1.0f, 0.0f) : v3(1.0f, 0.0f, 0.0f);
        const vec3 t = v3_norm(v3_cross(a, w)), b = v3_cross(w, t);
        int bad_pdf = 0;
        for (int i = 0; i < N; i++) {
            float pdf;
            const vec3 wi = phase_hg_sample(g, wo, frand(&r), frand(&r), &pdf);
            if (fabsf(pdf - phase_hg_eval(g, wo, wi)) > 1e-5f * pdf) bad_pdf++;
            const float c = fminf(fmaxf(v3_dot(wi, w), -1.0f), 1.0f);
            float phi = atan2f(v3_dot(wi, b), v3_dot(wi, t));
            if (phi < 0.0f) phi += 2.0f * (float)PI_D;
            int ci = (int)((c + 1.0f) * 0.5f * NC), pi = (int)(phi / (2.0f * (float)PI_D) * NP);
            if (ci >= NC) ci = NC - 1;
            if (pi >= NP) pi = NP - 1;
            count[ci][pi] += 1.0;
        }
        CHECKF(bad_pdf == 0, "g %g: %d samples whose pdf is not phase_hg_eval", (double)g, bad_pdf);
        double chi2 = 0.0;
        int dof = -1;
        for (int ci = 0; ci < NC; ci++) {
            /* the probability of the cos bin: integral of 2 pi p over it (p in the scattering cosine -dot(wo, wi) = c) */
            double pc = 0.0;
            const int sub = 200;
            for (int k = 0; k < sub; k++) {
                const double c = -1.0 + (ci + (k + 0.5) / sub) * 2.0 / NC;
                pc += (double)phase_hg(g, (float)-c) * 2.0 * PI_D * (2.0 / NC) / sub;
            }
            for (int pi = 0; pi < NP; pi++) {
                const double e = pc / NP * N;
                if (e < 5.0) continue;
                chi2 += (count[ci][pi] - e) * (count[ci][pi] - e) / e;
                dof++;
            }
        }
        const double p = chi2_pvalue(chi2, dof);
        CHECKF(p > 1e-3, "g %g: chi-square %.1f with %d dof, p %.2g", (double)g, chi2, dof, p);
        printf("  HG g %+.4f: chi-square %.1f, %d dof, p %.3f; pdf integral %.5f\n", (double)g, chi2, dof, p, integral);
    }
}

/* ---- refusals ------------------------------------------------------------------------ */

static void expect_refused(medium m, const char *want)
{
    pk_scene *s = NULL;
    pk_context_clear_error(ctx);
    REQUIRE(scene_create(ctx, "bad.json", &s) == PK_OK);
    sphere sp = {v3s(0.0f), 1.0f, 0};
    REQUIRE(scene_add_sphere(ctx, s, &sp) == PK_OK);
    uint32_t mi;
    m.name = mem_strdup(&s->alloc, "fog");
    REQUIRE(scene_add_medium(ctx, s, &m, &mi) == PK_OK);
    const pk_status st = scene_commit(ctx, s);
    CHECKF(st != PK_OK && strstr(pk_context_error(ctx), want), "want a refusal with '%s', got %d: %s", want, (int)st,
           pk_context_error(ctx));
    CHECKF(strstr(pk_context_error(ctx), "bad.json") && strstr(pk_context_error(ctx), "fog"),
           "the message names the file and the medium: %s", pk_context_error(ctx));
    scene_destroy(s);
}

static void check_refusals(void)
{
    medium m;
    medium_init(&m);
    m.sigma_t = v3(1.0f, -1.0f, 1.0f);
    expect_refused(m, "extinction");
    medium_init(&m);
    m.sigma_t = v3(1.0f, NAN, 1.0f);
    expect_refused(m, "extinction");
    medium_init(&m);
    m.albedo = v3(1.2f, 0.5f, 0.5f);
    expect_refused(m, "albedo");
    medium_init(&m);
    m.g = 1.0f;
    expect_refused(m, "asymmetry");
    medium_init(&m);
    m.kind = MEDIUM_GRID;
    expect_refused(m, "density grid");
    /* a grid with a NaN, a negative value, over the voxel limit, a singular placement */
    static float vals[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    const char *why[4] = {"finite", ">= 0", "limit", "invertible"};
    for (int k = 0; k < 4; k++) {
        medium_init(&m);
        m.kind = MEDIUM_GRID;
        m.density = (medium_grid){2, 2, 2, 1, NULL};
        m.density.data = malloc(sizeof vals); /* the default allocator's */
        REQUIRE(m.density.data);
        memcpy(m.density.data, vals, sizeof vals);
        if (k == 0) m.density.data[3] = NAN;
        if (k == 1) m.density.data[5] = -0.5f;
        if (k == 2) m.density.nx = m.density.ny = m.density.nz = 1 << 12;
        if (k == 3) m.grid_to_world = xform_scale(v3(1.0f, 0.0f, 1.0f));
        expect_refused(m, why[k]);
    }
}

/* JSON grid media read from OpenVDB files (through the OpenVDB module,
 * where the build made one: PK_OPENVDB_MODULE;
 * tests/data/media/grid.vdb: its float grid "density" holds 100 + x + 10 y
 * over x -2..2, y 0..1, one z) and a file of no known kind refused. */
static void check_json_grid_files(void)
{
    const char *dir = PK_TEST_DATA "/media";
    const char *vdb = "{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1}],\n"
                      " \"media\": [{\"name\": \"smoke\", \"type\": \"grid\", \"file\": \"grid.vdb\", \"grid\": \"density\","
                      " \"sigma_t\": 0.01}],\n \"medium\": \"smoke\"}\n";
    pk_scene *s = NULL;
    pk_context_clear_error(ctx);
    if (PK_OPENVDB_MODULE[0]) { /* the module this build made */
        char cfg[600];
        snprintf(cfg, sizeof cfg, "openvdb.module=%s", PK_OPENVDB_MODULE);
        REQUIRE(pk_context_set_config(ctx, cfg) == PK_OK);
    } else {
        REQUIRE(pk_context_set_config(ctx, "openvdb.module=/no-such-dir/paprsek_openvdb.so") == PK_OK);
    }
    pk_status st = pk_scene_load_json_memory(ctx, vdb, strlen(vdb), "vdb.json", dir, &s);
    if (PK_OPENVDB_MODULE[0]) {
        CHECKF(st == PK_OK, "vdb.json: %s", pk_context_error(ctx));
        if (st == PK_OK) {
            CHECK(s->nmedia == 1 && s->camera_medium == 0);
            const medium_grid *g = &s->media[0].density;
            CHECKF(g->nx == 5 && g->ny == 2 && g->nz == 1 && g->channels == 1, "grid %dx%dx%d", g->nx, g->ny, g->nz);
            if (g->nx == 5 && g->ny == 2 && g->nz == 1) {
                CHECK_NEAR(g->data[0], 98.0f, 1e-4);      /* x -2, y 0 */
                CHECK_NEAR(g->data[5 + 4], 112.0f, 1e-4); /* x 2, y 1 */
            }
            pk_scene_destroy(s);
        }
    } else {
        CHECKF(st != PK_OK && strstr(pk_context_error(ctx), "OpenVDB module") &&
                   strstr(pk_context_error(ctx), "libopenvdb-dev"),
               "without OpenVDB: %s", pk_context_error(ctx));
        printf("  (this build has no OpenVDB module: a .vdb medium is only checked to be refused)\n");
    }
    const char *bad = "{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1}],\n"
                      " \"media\": [{\"name\": \"smoke\", \"type\": \"grid\", \"file\": \"smoke.raw\"}]}\n";
    pk_context_clear_error(ctx);
    s = NULL;
    st = pk_scene_load_json_memory(ctx, bad, strlen(bad), "bad.json", dir, &s);
    CHECKF(st != PK_OK && strstr(pk_context_error(ctx), "bad.json:2") && strstr(pk_context_error(ctx), ".vdb"),
           "an unknown grid file: %s", pk_context_error(ctx));
    pk_scene_destroy(s);
    pk_context_clear_error(ctx);
    REQUIRE(pk_context_set_config(ctx, "openvdb.module=") == PK_OK);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    check_lookup();
    check_majorants();
    check_hg();
    check_refusals();
    check_json_grid_files();
    pk_context_destroy(ctx);
    return test_done("medium");
}
