/*
 * test_gltf_layers.c - glTF's material layers: the metallic-roughness BSDF
 * bounding a volume (PBSDF_MR_VOLUME: its transmission refracts) by
 * chi-square of its sampling against its pdf, sample weights against
 * eval / pdf, reciprocity with the eta^2 rule of a refracting boundary,
 * closed forms (a white transmitter seen from inside is the rough
 * dielectric; outside, its refraction is the dielectric's scaled by the
 * transmitted share) and white furnaces; then the reader on assets written
 * here: the layers' textures land on the material, the general volume
 * refracts, unlit is an emitter that does not scatter, emissive strength
 * scales a textured emission, dispersion is warned about once, and
 * KHR_materials_variants picks materials (an unknown name lists the
 * variants).
 */
#include "test.h"
#include "chi2.h"
#include "warnings.h"

#include "io/gltf.h"
#include "io/readers.h"
#include "render/pbsdf.h"
#include "render/shading.h"
#include "render/surface.h"
#include "scene/scene.h"
#include "scene/scene_view.h"

#include <stdint.h>

/* ---- random numbers ---- */
static uint64_t rng_s = 0x9E3779B97F4A7C15ull;
static double rnd(void)
{
    rng_s ^= rng_s << 13, rng_s ^= rng_s >> 7, rng_s ^= rng_s << 17;
    return (double)(rng_s >> 11) * (1.0 / 9007199254740992.0);
}
static vec3 rnd_dir(void)
{
    double z = 2 * rnd() - 1, phi = 2 * M_PI * rnd(), s = sqrt(fmax(0, 1 - z * z));
    return v3((float)(s * cos(phi)), (float)(s * sin(phi)), (float)z);
}

static pbsdf mrv(vec3 base, float metallic, float rough, float transmission, float ior, float coat)
{
    pbsdf b = pbsdf_metallic_roughness(base, metallic, rough * rough, transmission, ior);
    if (coat > 0.0f) b = pbsdf_with_clearcoat(b, coat, 0.09f);
    b.flags |= PBSDF_MR_VOLUME;
    return b;
}

/* ---- chi-square of pbsdf_sample against pbsdf_pdf over (z, phi) cells ---- */
#define NZ 32
#define NP 64
#define QN 12
static double chi2_run(const pbsdf *b, vec3 wo, int nsamp, double *total_out, int *bad_weight)
{
    static double expct[NZ * NP + 1], obs[NZ * NP + 1];
    memset(obs, 0, sizeof obs);
    double total = 0;
    for (int iz = 0; iz < NZ; iz++)
        for (int ip = 0; ip < NP; ip++) {
            double acc = 0;
            for (int a = 0; a < QN; a++)
                for (int c = 0; c < QN; c++) {
                    double z = -1 + 2.0 * (iz + (a + 0.5) / QN) / NZ, ph = 2 * M_PI * (ip + (c + 0.5) / QN) / NP;
                    double s = sqrt(fmax(0, 1 - z * z));
                    acc += (double)pbsdf_pdf(b, wo, v3((float)(s * cos(ph)), (float)(s * sin(ph)), (float)z));
                }
            double cell = acc / (QN * QN) * (2.0 / NZ) * (2 * M_PI / NP);
            expct[iz * NP + ip] = cell * nsamp;
            total += cell;
        }
    expct[NZ * NP] = fmax(0, 1 - total) * nsamp;
    for (int i = 0; i < nsamp; i++) {
        float u[3] = {(float)rnd(), (float)rnd(), (float)rnd()};
        vec3 wi, w;
        float pdf;
        bool delta;
        if (!pbsdf_sample(b, wo, u, &wi, &w, &pdf, &delta)) {
            obs[NZ * NP] += 1;
            continue;
        }
        vec3 e = pbsdf_eval(b, wo, wi);
        float p2 = pbsdf_pdf(b, wo, wi);
        if (delta || fabsf(p2 - pdf) > 1e-4f * p2 || fabsf(w.x - e.x / pdf) > 1e-4f * fabsf(w.x) + 1e-7f)
            (*bad_weight)++;
        double z = wi.z, ph = atan2(wi.y, wi.x);
        if (ph < 0) ph += 2 * M_PI;
        int iz = (int)((z + 1) / 2 * NZ), ip = (int)(ph / (2 * M_PI) * NP);
        iz = iz < 0 ? 0 : iz >= NZ ? NZ - 1 : iz;
        ip = ip < 0 ? 0 : ip >= NP ? NP - 1 : ip;
        obs[iz * NP + ip] += 1;
    }
    double chi2 = 0, pe = 0, po = 0;
    int dof = 0;
    for (int i = 0; i <= NZ * NP; i++) {
        if (expct[i] < 5) {
            pe += expct[i], po += obs[i];
        } else {
            double d = obs[i] - expct[i];
            chi2 += d * d / expct[i];
            dof++;
        }
    }
    if (pe > 0) {
        chi2 += (po - pe) * (po - pe) / pe;
        dof++;
    }
    *total_out = total;
    return dof > 1 ? chi2_pvalue(chi2, dof - 1) : 1.0;
}

static void test_chi2(void)
{
    struct {
        const char *name;
        float metallic, rough, transmission, ior, coat, wz;
    } cases[] = {
        {"glass outside", 0, 0.5f, 1, 1.5f, 0, 0.7f},
        {"mixed outside", 0.3f, 0.6f, 0.6f, 1.4f, 0.5f, 0.5f},
        {"mixed inside", 0.3f, 0.6f, 0.6f, 1.4f, 0.5f, -0.6f},
        {"grazing inside", 0, 0.4f, 0.8f, 1.5f, 0, -0.2f},
    };
    const int nc = (int)(sizeof cases / sizeof cases[0]);
    const double alpha = 1 - pow(1 - 0.01, 1.0 / nc); /* 0.01 over the cases (Sidak) */
    for (int i = 0; i < nc; i++) {
        pbsdf b = mrv(v3(0.8f, 0.5f, 0.3f), cases[i].metallic, cases[i].rough, cases[i].transmission, cases[i].ior,
                      cases[i].coat);
        double wz = cases[i].wz, s = sqrt(1 - wz * wz);
        vec3 wo = v3((float)s, 0.0f, (float)wz);
        double total;
        int badw = 0;
        double pv = chi2_run(&b, wo, 200000, &total, &badw);
        printf("chi2 %-15s p = %.4f, pdf integral %.4f, bad weights %d\n", cases[i].name, pv, total, badw);
        CHECKF(pv > alpha, "%s: p-value %g", cases[i].name, pv);
        CHECKF(total <= 1.0 + 2e-3, "%s: the pdf integrates to %g", cases[i].name, total);
        CHECK(badw == 0);
    }
}

/* Reciprocity: with radiance not scaled at the boundary (pbsdf.h), f(wo, wi)
 * eta_o^2 = f(wi, wo) eta_i^2 ... checked against the plain dielectric's
 * own ratio, and both against eta^2 itself; reflection is symmetric (but for
 * the clearcoat, whose weight is the view's alone: none here). */
static void test_reciprocity(void)
{
    int n = 0, bad_t = 0, bad_r = 0, bad_d = 0;
    for (int k = 0; k < 20000; k++) {
        const float ior = 1.2f + (float)rnd(), rough = 0.2f + 0.8f * (float)rnd();
        pbsdf b = mrv(v3((float)rnd(), (float)rnd(), (float)rnd()), 0.5f * (float)rnd(), rough, (float)rnd(), ior, 0);
        pbsdf d = pbsdf_dielectric(ior, rough * rough, v3s(1.0f));
        vec3 a = rnd_dir(), c = rnd_dir();
        /* (nearer grazing, float rounding in the dielectric's own terms passes 2e-3) */
        if (fabsf(a.z) < 0.1f || fabsf(c.z) < 0.1f) continue;
        const vec3 f1 = pbsdf_eval(&b, a, c), f2 = pbsdf_eval(&b, c, a);
        const float g1 = f1.y / fabsf(c.z), g2 = f2.y / fabsf(a.z); /* f without the cosine */
        if (a.z * c.z > 0.0f) {
            if (fabsf(g1 - g2) > 1e-3f * fmaxf(g1, g2) + 1e-6f) bad_r++;
            continue;
        }
        const float dd1 = pbsdf_eval(&d, a, c).y / fabsf(c.z), dd2 = pbsdf_eval(&d, c, a).y / fabsf(a.z);
        if (!(dd1 > 1e-4f && dd2 > 1e-4f)) continue;
        n++;
        /* eta of the side of a over that of c, squared */
        const float e2 = a.z > 0.0f ? 1.0f / (ior * ior) : ior * ior;
        if (fabsf(dd1 * e2 - dd2) > 2e-3f * dd2 + 1e-7f && bad_d++ < 3)
            fprintf(stderr, "dielectric not reciprocal: %g %g (a.z %g c.z %g)\n", (double)(dd1 * e2), (double)dd2,
                    (double)a.z, (double)c.z);
        if (fabsf(g1 * e2 - g2) > 2e-3f * g2 + 1e-7f) {
            if (bad_t++ < 3) fprintf(stderr, "not reciprocal: %g %g\n", (double)(g1 * e2), (double)g2);
        }
    }
    printf("reciprocity: %d transmitted pairs, %d not reciprocal (dielectric %d), %d reflections\n", n, bad_t, bad_d,
           bad_r);
    CHECK(n > 1000 && bad_t == 0 && bad_d == 0 && bad_r == 0);
}

/* Closed forms: a white pure transmitter seen from inside is the rough
 * dielectric (internal reflection and refraction out); from outside its
 * refraction is the dielectric's; a metal transmits nothing either way;
 * the share of a coloured one is sqrt(base) (1 - metallic) transmission. */
static void test_closed_forms(void)
{
    int bad = 0, n = 0;
    for (int k = 0; k < 5000; k++) {
        const float ior = 1.2f + (float)rnd(), rough = 0.1f + 0.9f * (float)rnd();
        pbsdf w = mrv(v3s(1.0f), 0, rough, 1, ior, 0), d = pbsdf_dielectric(ior, rough * rough, v3s(1.0f));
        pbsdf m = mrv(v3s(0.7f), 1, rough, 1, ior, 0);
        const vec3 base = v3(0.64f, 0.25f, 0.09f);
        pbsdf c = mrv(base, 0.2f, rough, 0.5f, ior, 0);
        vec3 a = rnd_dir(), e = rnd_dir();
        if (a.z > 0.0f) a.z = -a.z; /* inside */
        n++;
        const vec3 fw = pbsdf_eval(&w, a, e), fd = pbsdf_eval(&d, a, e);
        if (fabsf(fw.x - fd.x) > 1e-6f * fmaxf(fd.x, 1.0f) || fabsf(pbsdf_pdf(&w, a, e) - pbsdf_pdf(&d, a, e)) > 1e-4f)
            bad++;
        if (e.z < 0.0f) { /* from outside into the inside */
            const vec3 o = v3(-a.x, -a.y, -a.z);
            if (fabsf(pbsdf_eval(&w, o, e).x - pbsdf_eval(&d, o, e).x) > 1e-6f) bad++;
            const vec3 fc = pbsdf_eval(&c, o, e), fdo = pbsdf_eval(&d, o, e);
            if (fabsf(fc.y - 0.5f * 0.8f * 0.5f * fdo.y) > 1e-5f * fmaxf(fdo.y, 1.0f)) bad++;
            if (pbsdf_eval(&m, o, e).x != 0.0f) bad++;
        } else if (pbsdf_eval(&m, a, e).x != 0.0f) {
            bad++;
        }
    }
    printf("closed forms: %d directions, %d mismatches\n", n, bad);
    CHECK(bad == 0);
}

/* White furnace: the mean sample weight (the directional albedo) of a white
 * pure transmitter. From inside the smooth boundary's is exactly 1 (R + T,
 * each sample's weight 1), the rough one's at most 1 (4 standard errors);
 * from outside the smooth one's is F_schlick + 1 - F_exact (glTF's
 * reflection takes Schlick's Fresnel, the refraction the exact one). */
static void test_furnace(void)
{
    for (int rough = 0; rough < 2; rough++) {
        pbsdf b = mrv(v3s(1.0f), 0, rough ? 0.5f : 0.0f, 1, 1.5f, 0);
        for (int side = 0; side < 2; side++) {
            double worst = 0, worst_err = 0, worst_z = 0, worst_want = 0;
            for (int iz = 1; iz <= 8; iz++) {
                const double z = (side ? -1 : 1) * iz / 8.0, s = sqrt(fmax(0, 1 - z * z));
                const vec3 wo = v3((float)s, 0.0f, (float)z);
                const int n = 50000;
                double sum = 0, sum2 = 0;
                for (int k = 0; k < n; k++) {
                    float u[3] = {(float)rnd(), (float)rnd(), (float)rnd()};
                    vec3 wi, w;
                    float pdf;
                    bool delta;
                    double x = 0;
                    if (pbsdf_sample(&b, wo, u, &wi, &w, &pdf, &delta)) x = w.x;
                    sum += x, sum2 += x * x;
                }
                const double mean = sum / n, err = sqrt(fmax(0, sum2 / n - mean * mean) / n);
                double want = 1.0;
                if (!rough && !side) {
                    const double fs = 0.04 + 0.96 * pow(1 - z, 5);
                    want = fs + 1 - (double)pbsdf_fresnel_dielectric((float)z, 1.5f);
                }
                if (!rough) CHECKF(fabs(mean - want) <= 4 * err + 1e-5, "smooth side %d z %g: %g, want %g", side, z,
                                   mean, want);
                if (mean - want - 4 * err > worst - worst_want - 4 * worst_err || iz == 1)
                    worst = mean, worst_err = err, worst_z = z, worst_want = want;
            }
            printf("furnace %s %s: worst %.4f +- %.4f against %.4f (wo.z %.3f)\n", rough ? "rough" : "smooth",
                   side ? "inside" : "outside", worst, worst_err, worst_want, worst_z);
            if (rough && side) CHECKF(worst <= 1 + 4 * worst_err, "rough inside: albedo %g", worst);
        }
    }
}

/* ---- the reader ------------------------------------------------------------------------ */

static char msg[1024];
static warning_log wlog;

static pk_status load(const char *json, pk_scene **out, const char *const *params, size_t np)
{
    pk_context *ctx;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_clear(&wlog);
    warning_log_attach(ctx, &wlog);
    pk_scene *s;
    REQUIRE(scene_create(ctx, "t.gltf", &s) == PK_OK);
    pk_status st = scene_gltf_parse_params(ctx, s, json, strlen(json), "t.gltf", PK_TEST_DATA, params, np);
    if (st == PK_OK) st = scene_commit(ctx, s);
    snprintf(msg, sizeof msg, "%s", pk_context_error(ctx));
    if (st != PK_OK || !out) scene_destroy(s);
    else *out = s;
    pk_context_destroy(ctx);
    return st;
}

/* one triangle (positions, uvs) as a data: URI, with the uv accessor 1 */
#define TRI_BUFFER                                                                                                \
    "\"buffers\":[{\"byteLength\":60,\"uri\":\"data:application/octet-stream;base64,"                         \
    "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAIA/AAAAAAAAgD8AAIA/\"}],"                \
    "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24}],"  \
    "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"                  \
    "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}],"

static void test_reader_layers(void)
{
    char j[8192];
    snprintf(j, sizeof j,
             "{\"asset\":{\"version\":\"2.0\"}," TRI_BUFFER
             "\"images\":[{\"uri\":\"tex_rgbw.png\"}],\"textures\":[{\"source\":0}],"
             "\"materials\":["
             /* 0: the layers' textures */
             "{\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":0.5,"
             "\"transmissionTexture\":{\"index\":0}},"
             "\"KHR_materials_clearcoat\":{\"clearcoatFactor\":1,\"clearcoatRoughnessFactor\":0.5,"
             "\"clearcoatTexture\":{\"index\":0},\"clearcoatRoughnessTexture\":{\"index\":0},"
             "\"clearcoatNormalTexture\":{\"index\":0,\"scale\":0.5}}}},"
             /* 1: a volume that is not purely transmissive, its thickness textured */
             "{\"pbrMetallicRoughness\":{\"metallicFactor\":0.25},\"extensions\":{\"KHR_materials_transmission\":"
             "{\"transmissionFactor\":0.75},\"KHR_materials_volume\":{\"thicknessFactor\":1,"
             "\"thicknessTexture\":{\"index\":0}},\"KHR_materials_dispersion\":{\"dispersion\":1}}},"
             /* 2: unlit, textured */
             "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.25,1,1],\"baseColorTexture\":{\"index\":0},"
             "\"metallicFactor\":1},\"emissiveFactor\":[1,1,1],\"extensions\":{\"KHR_materials_unlit\":{},"
             "\"KHR_materials_dispersion\":{\"dispersion\":2}}},"
             /* 3: a textured emission with a strength */
             "{\"emissiveFactor\":[1,0.5,0.25],\"emissiveTexture\":{\"index\":0},"
             "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":4}}}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":0},"
             "{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":1},"
             "{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":2},"
             "{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":3}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}");
    pk_scene *s = NULL;
    CHECKF(load(j, &s, NULL, 0) == PK_OK, "%s", msg);
    if (!s) return;
    REQUIRE(s->ntris == 4);
    const material *m0 = &s->materials[s->tris[0].material], *m1 = &s->materials[s->tris[1].material],
                   *m2 = &s->materials[s->tris[2].material], *m3 = &s->materials[s->tris[3].material];
    CHECK(m0->type == MAT_METALLIC_ROUGHNESS && m0->transmission == 0.5f && m0->map_tr.kind == TEX_IMAGE);
    CHECK(m0->map_cc.kind == TEX_IMAGE && m0->map_ccr.kind == TEX_IMAGE && m0->clearcoat_roughness == 0.5f);
    CHECK(m0->map_tr.tex == m0->map_cc.tex && !s->textures[m0->map_tr.tex].srgb); /* data, not colour */
    CHECK(m0->textured && !m0->volume);
    CHECK(m0->map_ccn.kind == TEX_IMAGE && m0->coat_norm_scale == 0.5f && m0->map_ccn.tex == m0->map_cc.tex);
    CHECK(!warning_log_has(&wlog, "clearcoatNormalTexture") && !warning_log_has(&wlog, "not supported"));
    /* the clearcoat's normal at texel centres: the map's x and y times 0.5 in the frame t = +x
     * (u), b = -y (glTF's v runs down +y here), n = +z, normalised; the surface's own normal
     * stays +z (no normalTexture), and the BSDF gets the coat's in its local frame */
    {
        const scene_view v = scene_view_of(s);
        const float centres[4][2] = {{0.25f, 0.75f}, {0.75f, 0.75f}, {0.25f, 0.25f}, {0.75f, 0.25f}};
        int used = 0;
        for (int k = 0; k < 4; k++) {
            const float uc = centres[k][0], vc = centres[k][1];
            /* the triangle's uvs (0, 1), (1, 1), (1, 0) (glTF's (0, 0), (1, 0), (1, 1) with v
             * flipped): uv (u + v, 1 - v) at barycentric (u, v) */
            const float bu = uc + vc - 1.0f, bv = 1.0f - vc;
            if (bu < 0.0f || uc > 1.0f) continue; /* outside the triangle */
            const tex_query q = {uc, vc, 0.0f, v3s(0.0f), v3s(0.0f), v.tex_nodes, uc, vc, 0.0f};
            const vec3 c = tex_eval_rgb(v.textures, &m0->map_ccn, q);
            const vec3 tl = v3(0.5f * (2.0f * c.x - 1.0f), 0.5f * (2.0f * c.y - 1.0f), 2.0f * c.z - 1.0f);
            ray r = {{bu, bv, 1.0f}, 0.0f, {0.0f, 0.0f, -1.0f}, INFINITY};
            hit h = {1.0f, 0, bu, bv};
            material tm;
            const surface sf = surface_texture(&v, &r, &h, 0.0f, surface_at(&v, &r, &h), &tm);
            CHECK(fabsf(sf.ns.z - 1.0f) < 1e-6f);
            if (!(tl.z > 0.0f)) { /* a normal facing away is not used */
                CHECKF(v3_len2(sf.nc) == 0.0f, "texel %d: a coat normal facing away was used", k);
                continue;
            }
            const vec3 want = v3_norm(v3(tl.x, -tl.y, tl.z));
            CHECKF(fabsf(sf.nc.x - want.x) < 1e-5f && fabsf(sf.nc.y - want.y) < 1e-5f && fabsf(sf.nc.z - want.z) < 1e-5f,
                   "texel %d: coat normal (%g %g %g), want (%g %g %g)", k, (double)sf.nc.x, (double)sf.nc.y,
                   (double)sf.nc.z, (double)want.x, (double)want.y, (double)want.z);
            const shading sh = shading_at(&sf);
            const vec3 cl = onb_to_local(sh.frame, want);
            CHECK((sh.b.flags & PBSDF_COAT_NORMAL) && fabsf(sh.b.coat_n.x - cl.x) < 1e-5f &&
                  fabsf(sh.b.coat_n.y - cl.y) < 1e-5f && fabsf(sh.b.coat_n.z - cl.z) < 1e-5f);
            used++;
        }
        CHECK(used >= 1);
    }
    /* the general volume: the metallic-roughness BSDF that refracts, the thickness map not warned about */
    CHECK(m1->type == MAT_METALLIC_ROUGHNESS && m1->volume && m1->metallic == 0.25f && m1->transmission == 0.75f);
    CHECK(!warning_log_has(&wlog, "thicknessTexture") && !warning_log_has(&wlog, "thin sheet"));
    /* dispersion: once */
    CHECK(warning_log_count(&wlog, "drawn without dispersion (needs spectral rendering") == 1);
    /* unlit: emits its base colour times its texture, scatters nothing, no other emission */
    CHECK(m2->type == MAT_DIFFUSE && m2->kd.x == 0.0f && m2->kd.y == 0.0f && m2->kd.z == 0.0f);
    CHECK(m2->ke.x == 0.5f && m2->ke.y == 0.25f && m2->ke.z == 1.0f);
    CHECK(m2->map_ke.kind == TEX_IMAGE && s->textures[m2->map_ke.tex].srgb && m2->map_kd.kind == TEX_NONE);
    CHECK(!warning_log_has(&wlog, "unlit"));
    /* emissive strength scales the textured emission */
    CHECK(m3->ke.x == 4.0f && m3->ke.y == 2.0f && m3->ke.z == 1.0f && m3->map_ke.kind == TEX_IMAGE);
    scene_destroy(s);
}

static void test_reader_variants(void)
{
    char j[8192];
    snprintf(j, sizeof j,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_materials_variants\"]," TRI_BUFFER
             "\"extensions\":{\"KHR_materials_variants\":{\"variants\":[{\"name\":\"red\"},{\"name\":\"blue\"},"
             "{\"name\":\"green\"}]}},"
             "\"materials\":[{\"name\":\"grey\"},{\"name\":\"red\"},{\"name\":\"blue\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0,"
             "\"extensions\":{\"KHR_materials_variants\":{\"mappings\":[{\"material\":1,\"variants\":[0]},"
             "{\"material\":2,\"variants\":[1]}]}}},"
             "{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}");
    static const struct {
        const char *param, *first, *second;
    } cases[] = {{NULL, "grey", "grey"}, {"variant=red", "red", "grey"}, {"variant=blue", "blue", "grey"},
                 {"variant=green", "grey", "grey"}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        pk_scene *s = NULL;
        const char *p[1] = {cases[i].param};
        CHECKF(load(j, &s, p, cases[i].param ? 1 : 0) == PK_OK, "%s", msg);
        if (!s) continue;
        REQUIRE(s->ntris == 2);
        CHECKF(strcmp(s->materials[s->tris[0].material].name, cases[i].first) == 0 &&
                   strcmp(s->materials[s->tris[1].material].name, cases[i].second) == 0,
               "%s: %s %s", cases[i].param ? cases[i].param : "default", s->materials[s->tris[0].material].name,
               s->materials[s->tris[1].material].name);
        scene_destroy(s);
    }
    const char *p[1] = {"variant=purple"};
    CHECK(load(j, NULL, p, 1) == PK_ERR_INVALID_ARGUMENT);
    CHECKF(strcmp(msg, "t.gltf: variant 'purple' is not one of the asset's: 'red', 'blue', 'green'") == 0, "%s", msg);
    /* an asset without variants */
    char k[4096];
    snprintf(k, sizeof k,
             "{\"asset\":{\"version\":\"2.0\"}," TRI_BUFFER
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}");
    CHECK(load(k, NULL, p, 1) == PK_ERR_INVALID_ARGUMENT);
    CHECKF(strcmp(msg, "t.gltf: variant 'purple': the asset has no material variants") == 0, "%s", msg);
    /* a mapping to a material that is not there */
    char *bad = strstr(j, "{\"material\":2,");
    REQUIRE(bad);
    bad[12] = '7';
    const char *pb[1] = {"variant=blue"};
    CHECK(load(j, NULL, pb, 1) == PK_ERR_PARSE);
    CHECKF(strstr(msg, "/meshes/0/primitives/0/extensions/KHR_materials_variants/mappings/1") != NULL, "%s", msg);
}

int main(void)
{
    test_chi2();
    test_reciprocity();
    test_closed_forms();
    test_furnace();
    test_reader_layers();
    test_reader_variants();
    return test_done("test_gltf_layers");
}
