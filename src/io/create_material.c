/*
 * create_material.c - one creator per material type (create_material.h).
 * The table is keyed by (dialect, type name); the rows of the Paprsek
 * dialect are the JSON scene's types. Each row lists its parameters, which
 * are declared before any is read so that unknown keys are reported first,
 * and the creator reads them: a shared prelude for the maps and the
 * parameters several types have (albedo, roughness or alpha, ior,
 * transmittance: their rules are one), then the type's own. Messages and
 * their order are those the JSON reader always gave.
 */
#include "create_material.h"

#include <math.h>
#include <string.h>

typedef enum mat_dialect { MD_PAPRSEK } mat_dialect;

/* What the prelude read, for the type's creator. tex_*: the value a loaded
 * texture stands for (negative: no texture). */
typedef struct mat_common {
    vec3 albedo, transmittance, tex_albedo, tex_specular;
    float roughness, alpha, ior, tex_alpha;
} mat_common;

typedef struct mat_row mat_row;
typedef pk_status (*mat_create_fn)(pdict *d, const mat_row *row, const mat_common *c, material *m);
struct mat_row {
    mat_dialect dialect;
    const char *type;
#define MAT_MAX_PARAMS 16
    const char *params[MAT_MAX_PARAMS];
    mat_create_fn create; /* NULL: the interface (no surface) */
};

/* The row's parameter named name, marked; NULL when it is absent or not a
 * parameter of the row (an unknown key, reported already). */
static const pd_entry *param(pdict *d, const mat_row *row, const char *name)
{
    for (int i = 0; i < MAT_MAX_PARAMS && row->params[i]; i++)
        if (strcmp(row->params[i], name) == 0) return pd_get(d, name);
    return NULL;
}
static bool is_obj(const pd_entry *e) { return e && e->kind == PD_OBJECT; }

static pk_status create_typed(pdict *d, const pd_entry *type_entry, material *m);

/* A nested material ("bsdf") may not name media: they belong to the outer one. */
static pk_status nested_sides(pdict *sub)
{
    static const char *const sides[2] = {"interior", "exterior"};
    for (int i = 0; i < 2; i++) {
        const pd_entry *e = pd_get(sub, sides[i]);
        if (e) return pd_fail(sub, e, -1, PK_ERR_PARSE, "media belong to the outer material, not to its \"bsdf\"");
    }
    return PK_OK;
}

/* Reads the nested material e ("bsdf") into *m. */
static pk_status read_nested(pdict *d, const pd_entry *e, material *m)
{
    pdict sub;
    pk_status st = pd_nested(d, e, &sub);
    if (st == PK_OK) st = nested_sides(&sub);
    if (st == PK_OK) st = create_typed(&sub, pd_get(&sub, "type"), m);
    pd_free(&sub);
    return st;
}

/* The "type" of the nested object e ("" when it is not a string), or NULL
 * when e is not an object or has none; *sub holds the object (pd_free it). */
static const char *nested_type(pdict *d, const pd_entry *e, bool *is_string, pdict *sub)
{
    *is_string = false;
    pd_init(sub, d->ctx, d->src, d->self, d->what, d->owns);
    if (!is_obj(e) || pd_nested(d, e, sub) != PK_OK) return NULL;
    const pd_entry *t = pd_get(sub, "type");
    if (!t) return NULL;
    *is_string = t->kind == PD_STRING;
    return *is_string ? t->str : "";
}

static pk_status create_diffuse(pdict *d, const mat_row *row, const mat_common *c, material *m)
{
    (void)d, (void)row;
    material_diffuse(m, c->albedo);
    return PK_OK;
}

/* "alpha_u" and "alpha_v" (conductor, dielectric): anisotropic roughness,
 * alpha_u along the surface's dp/du; either one left out is the isotropic
 * alpha. *alpha_v is -1 where the two are equal (isotropic). */
static pk_status read_alpha_uv(pdict *d, const mat_row *row, const mat_common *c, float *alpha, float *alpha_v)
{
    const pd_entry *eu = param(d, row, "alpha_u"), *ev = param(d, row, "alpha_v");
    *alpha = c->alpha, *alpha_v = -1.0f;
    if (!eu && !ev) return PK_OK;
    float au = c->alpha, av = c->alpha;
    pk_status st;
    if (eu && (st = pd_float(d, "alpha_u", au, PD_UNIT, &au))) return st;
    if (ev && (st = pd_float(d, "alpha_v", av, PD_UNIT, &av))) return st;
    *alpha = au;
    if (av != au) *alpha_v = av;
    return PK_OK;
}

static pk_status create_conductor(pdict *d, const mat_row *row, const mat_common *c, material *m)
{
    vec3 eta = v3(0.2f, 0.92f, 1.1f), k = v3(3.9f, 2.45f, 2.14f); /* copper, as pbrt */
    vec3 f0 = v3s(-1.0f); /* set: Schlick's Fresnel of this reflectance */
    const pd_entry *spec = param(d, row, "specular"), *pe = param(d, row, "eta"), *pk = param(d, row, "k");
    pk_status st;
    if (spec && !is_obj(spec)) {
        const pd_entry *other = pe ? pe : pk;
        if (other) return pd_fail(d, other, -1, PK_ERR_PARSE, "give \"eta\" and \"k\" or \"specular\", not both");
        if ((st = pd_vec3(d, "specular", f0, PD_V_REFLECTANCE, &f0))) return st;
    } else if (c->tex_specular.x >= 0.0f) {
        f0 = c->tex_specular;
    } else {
        if (pe && (st = pd_vec3(d, "eta", eta, PD_V_POSITIVE, &eta))) return st;
        if (pk && (st = pd_vec3(d, "k", k, PD_V_NONNEG, &k))) return st;
    }
    float alpha, alpha_v;
    if ((st = read_alpha_uv(d, row, c, &alpha, &alpha_v))) return st;
    if (f0.x >= 0.0f) material_conductor_f0(m, f0, alpha);
    else material_conductor(m, eta, k, alpha);
    m->alpha_v = alpha_v;
    return PK_OK;
}

static pk_status create_dielectric(pdict *d, const mat_row *row, const mat_common *c, material *m)
{
    float alpha, alpha_v;
    pk_status st = read_alpha_uv(d, row, c, &alpha, &alpha_v);
    if (st) return st;
    if (c->ior == 1.0f && (alpha > 0.0f || alpha_v > 0.0f))
        return pd_fail(d, pd_get(d, "ior"), -1, PK_ERR_PARSE, "must not be 1 on a rough surface (roughness > 0)");
    material_dielectric(m, c->ior, alpha, c->transmittance);
    m->alpha_v = alpha_v;
    return PK_OK;
}

static pk_status create_plastic(pdict *d, const mat_row *row, const mat_common *c, material *m)
{
    (void)d, (void)row;
    material_plastic(m, c->albedo, c->ior, c->alpha);
    return PK_OK;
}

/* glTF 2.0's material */
static pk_status create_metallic_roughness(pdict *d, const mat_row *row, const mat_common *c, material *m)
{
    (void)row;
    float metallic = 1.0f, transmission = 0.0f, clearcoat = 0.0f, clearcoat_roughness = 0.0f;
    pk_status st;
    if ((st = pd_float(d, "metallic", 1.0f, PD_UNIT, &metallic))) return st;
    if ((st = pd_float(d, "transmission", 0.0f, PD_UNIT, &transmission))) return st;
    if ((st = pd_float(d, "clearcoat", 0.0f, PD_UNIT, &clearcoat))) return st;
    if ((st = pd_float(d, "clearcoat_roughness", 0.0f, PD_UNIT, &clearcoat_roughness))) return st;
    material_metallic_roughness(m, c->albedo, metallic, c->roughness);
    m->transmission = transmission;
    m->ni = c->ior;
    m->clearcoat = clearcoat;
    m->clearcoat_roughness = clearcoat_roughness;
    return PK_OK;
}

/* Mitsuba 3's principled BSDF (Mitsuba's parameter names; "eta", the
 * index, or Mitsuba's "specular" that maps to it) */
static pk_status create_principled(pdict *d, const mat_row *row, const mat_common *c, material *m)
{
    static const char *const names[] = {"metallic",   "spec_trans", "anisotropic", "spec_tint",      "sheen",
                                        "sheen_tint", "flatness",   "clearcoat",   "clearcoat_gloss"};
    static const char *const rates[] = {"main_specular_sampling_rate", "clearcoat_sampling_rate",
                                        "diffuse_reflectance_sampling_rate"};
    float v[9] = {0}, rate[3] = {1.0f, 1.0f, 1.0f};
    pk_status st;
    const pd_entry *e;
    vec3 base = v3s(0.5f);
    bool loaded;
    if (is_obj(e = param(d, row, "base_color"))) {
        if ((st = pd_texture(d, e, true, &m->map_kd, &loaded))) return st;
        base = loaded ? v3s(1.0f) : v3s(0.5f);
    } else if ((st = pd_vec3(d, "base_color", base, PD_V_REFLECTANCE, &base))) {
        return st;
    }
    float roughness = param(d, row, "roughness") ? c->roughness : 0.5f;
    if (c->tex_alpha >= 0.0f) roughness = c->tex_alpha > 0.0f ? 1.0f : 0.5f;
    for (int k = 0; k < 9; k++) {
        if (is_obj(e = param(d, row, names[k]))) return pd_fail(d, e, -1, PK_ERR_PARSE, "must be a number in 0..1");
        if ((st = pd_float(d, names[k], 0.0f, PD_UNIT, &v[k]))) return st;
    }
    for (int k = 0; k < 3; k++)
        if ((st = pd_float(d, rates[k], 1.0f, PD_NONNEG, &rate[k]))) return st;
    const pd_entry *ee = param(d, row, "eta"), *se = param(d, row, "specular");
    if (ee && se) return pd_fail(d, se, -1, PK_ERR_PARSE, "give \"eta\" or \"specular\", not both");
    float eta = 0.0f, specular = 0.5f;
    if (ee) {
        if ((st = pd_float(d, "eta", 1.5f, PD_POSITIVE, &eta))) return st;
        if (v[1] > 0.0f && eta == 1.0f) eta = 1.001f; /* as Mitsuba: an index of 1 cannot refract */
    } else {
        if ((st = pd_float(d, "specular", 0.5f, PD_NONNEG, &specular))) return st;
        if (!(specular < 12.5f)) return pd_fail(d, se, -1, PK_ERR_PARSE, "must be below 12.5");
        if (v[1] > 0.0f && specular == 0.0f) specular = 1e-3f;
        eta = 2.0f / (1.0f - sqrtf(0.08f * specular)) - 1.0f;
    }
    material_principled(m, base, v[0], roughness);
    m->transmission = v[1], m->anisotropic = v[2], m->spec_tint = v[3], m->sheen = v[4], m->sheen_tint = v[5];
    m->flatness = v[6], m->clearcoat = v[7], m->clearcoat_gloss = v[8];
    m->srate_spec = rate[0], m->srate_cc = rate[1], m->srate_diff = rate[2];
    m->ni = eta;
    m->map_alpha.squared = false; /* the map multiplies the roughness */
    material_principled_update(m);
    return PK_OK;
}

static pk_status create_thin_dielectric(pdict *d, const mat_row *row, const mat_common *c, material *m)
{
    (void)d, (void)row;
    material_thin_dielectric(m, c->ior, c->transmittance);
    return PK_OK;
}

/* pbrt-v4's defaults: reflectance and transmittance 0.25 */
static pk_status create_diffuse_transmission(pdict *d, const mat_row *row, const mat_common *c, material *m)
{
    const vec3 r = param(d, row, "albedo") ? c->albedo : v3s(0.25f);
    const vec3 t = param(d, row, "transmittance") ? c->transmittance : v3s(0.25f);
    material_diffuse_transmission(m, r, t);
    return PK_OK;
}

/* Oren-Nayar: "alpha" as Mitsuba's roughdiffuse (0.2 by default) */
static pk_status create_rough_diffuse(pdict *d, const mat_row *row, const mat_common *c, material *m)
{
    material_rough_diffuse(m, c->albedo, param(d, row, "alpha") ? c->alpha : 0.2f);
    return PK_OK;
}

/* Mitsuba's phong and its defaults: albedo (diffuse) 0.5, specular 0.2, exponent 30 */
static pk_status create_phong(pdict *d, const mat_row *row, const mat_common *c, material *m)
{
    vec3 ks = v3s(0.2f);
    float n = 30.0f;
    const pd_entry *spec = param(d, row, "specular");
    pk_status st;
    if (c->tex_specular.x >= 0.0f) ks = c->tex_specular;
    else if (spec && (st = pd_vec3(d, "specular", ks, PD_V_REFLECTANCE, &ks))) return st;
    if ((st = pd_float(d, "exponent", n, PD_NONNEG, &n))) return st;
    material_phong(m, c->albedo, ks, n);
    return PK_OK;
}

/* pbrt-v4's layered material: a coat ("ior", "roughness" or "alpha") over a
 * Lambertian base ("albedo", 0.5) or, where "eta"/"k" or "specular" is
 * given, a conductor of that index (relative to vacuum) or normal-incidence
 * reflectance with "base_roughness" or "base_alpha"; the layer between:
 * "thickness" 0.01, "layer_albedo" 0, "g" 0, "maxdepth" 10, "nsamples" 1
 * (pbrt-v4's defaults) */
static pk_status create_coated(pdict *d, const mat_row *row, const mat_common *c, material *m)
{
    material_layer l = material_layer_default();
    const pd_entry *spec = param(d, row, "specular"), *pe = param(d, row, "eta"), *pk = param(d, row, "k");
    const pd_entry *alb = param(d, row, "albedo"), *br = param(d, row, "base_roughness"),
                   *ba = param(d, row, "base_alpha");
    const bool metal = spec || pe || pk;
    pk_status st;
    if (metal && alb)
        return pd_fail(d, alb, -1, PK_ERR_PARSE,
                       "a coated conductor (\"eta\", \"k\" or \"specular\") has no diffuse \"albedo\"");
    if (!metal && (br || ba))
        return pd_fail(d, br ? br : ba, -1, PK_ERR_PARSE,
                       "is the conductor base's roughness: give \"eta\" and \"k\" or \"specular\"");
    if (spec && (pe || pk))
        return pd_fail(d, pe ? pe : pk, -1, PK_ERR_PARSE, "give \"eta\" and \"k\" or \"specular\", not both");
    if (br && ba) return pd_fail(d, ba, -1, PK_ERR_PARSE, "give \"base_roughness\" or \"base_alpha\", not both");
    float balpha = 0.0f;
    if (br) {
        if ((st = pd_float(d, "base_roughness", 0.0f, PD_UNIT, &balpha))) return st;
        balpha *= balpha;
    } else if (ba && (st = pd_float(d, "base_alpha", 0.0f, PD_UNIT, &balpha))) {
        return st;
    }
    if ((st = pd_float(d, "thickness", l.thickness, PD_POSITIVE, &l.thickness)) ||
        (st = pd_vec3(d, "layer_albedo", l.albedo, PD_V_REFLECTANCE, &l.albedo)) ||
        (st = pd_float(d, "g", l.g, PD_ANY, &l.g)))
        return st;
    if (!(l.g > -1.0f && l.g < 1.0f)) return pd_fail(d, pd_get(d, "g"), -1, PK_ERR_PARSE, "must be in (-1, 1)");
    if ((st = pd_int(d, "maxdepth", l.maxdepth, 1, 65536, &l.maxdepth)) ||
        (st = pd_int(d, "nsamples", l.nsamples, 1, 65536, &l.nsamples)))
        return st;
    if (!metal) {
        material_coated_diffuse(m, c->albedo, c->ior, c->alpha, l);
        return PK_OK;
    }
    vec3 eta = v3(0.2f, 0.92f, 1.1f), k = v3(3.9f, 2.45f, 2.14f); /* copper, as pbrt */
    vec3 f0 = v3s(-1.0f);
    if (c->tex_specular.x >= 0.0f) f0 = c->tex_specular;
    else if (spec && (st = pd_vec3(d, "specular", f0, PD_V_REFLECTANCE, &f0))) return st;
    if (pe && (st = pd_vec3(d, "eta", eta, PD_V_POSITIVE, &eta))) return st;
    if (pk && (st = pd_vec3(d, "k", k, PD_V_NONNEG, &k))) return st;
    if (f0.x >= 0.0f) material_coated_conductor_f0(m, f0, balpha, c->ior, c->alpha, l);
    else material_coated_conductor(m, eta, k, balpha, c->ior, c->alpha, l);
    return PK_OK;
}

/* mix: "materials", two names of materials defined before it, and
 * "amount" (0.5 by default), the probability of the second: a number in
 * 0..1 or a texture */
static pk_status create_mix(pdict *d, const mat_row *row, const mat_common *c, material *m)
{
    (void)c;
    const pd_entry *e = param(d, row, "materials"), *am = param(d, row, "amount");
    if (!e) return pd_fail(d, NULL, -1, PK_ERR_PARSE, "a mix needs \"materials\": the names of two materials");
    if (!d->src || !d->src->material)
        return pd_fail(d, e, -1, PK_ERR_PARSE, "a mix names materials of a scene file, which are not at hand here");
    if (e->kind != PD_OTHER && e->kind != PD_NUMBERS)
        return pd_fail(d, e, -1, PK_ERR_PARSE, "must be a list of two material names");
    uint32_t ab[2];
    pk_status st;
    for (long k = 0; k < 2; k++)
        if ((st = d->src->material(d->self, d, e, k, &ab[k]))) return st;
    float amount = 0.5f;
    tex_ref map;
    tex_ref_init(&map);
    if (is_obj(am)) {
        bool loaded;
        if ((st = pd_texture(d, am, false, &map, &loaded))) return st;
        amount = loaded ? 1.0f : 0.5f;
    } else if ((st = pd_float(d, "amount", amount, PD_UNIT, &amount))) {
        return st;
    }
    material_mix(m, (int)ab[0], (int)ab[1], amount);
    m->map_alpha = map;
    return PK_OK;
}

/* emitter: black diffuse, or the surface its "bsdf" describes */
static pk_status create_emitter(pdict *d, const mat_row *row, const mat_common *c, material *m)
{
    (void)c;
    vec3 ke = v3s(1.0f);
    pk_status st;
    tex_ref map;
    tex_ref_init(&map);
    const pd_entry *re = param(d, row, "radiance");
    if (is_obj(re)) { /* an emission map: its linear colour (decoded from sRGB for 8-bit images) times its scale */
        bool loaded;
        if ((st = pd_texture(d, re, true, &map, &loaded))) return st;
    } else if ((st = pd_vec3(d, "radiance", ke, PD_V_COLOUR, &ke))) {
        return st;
    }
    const pd_entry *b = param(d, row, "bsdf");
    if (b) {
        pdict sub;
        bool str;
        const char *bt = nested_type(d, b, &str, &sub);
        if (!bt) {
            pd_free(&sub);
            return pd_fail(d, b, -1, PK_ERR_PARSE,
                           "must be a material object with a \"type\" (the emitting surface's reflection)");
        }
        if (str && strcmp(bt, "emitter") == 0) {
            st = pd_fail(&sub, pd_get(&sub, "type"), -1, PK_ERR_PARSE, "an emitter's bsdf cannot be another emitter");
            pd_free(&sub);
            return st;
        }
        pd_free(&sub);
        if ((st = read_nested(d, b, m))) return st;
    } else {
        material_diffuse(m, v3s(0.0f));
    }
    m->ke = ke;
    m->map_ke = map;
    return PK_OK;
}

/* two_sided: the nested material, reflecting and emitting on both sides */
static pk_status create_two_sided(pdict *d, const mat_row *row, const mat_common *c, material *m)
{
    (void)c;
    const pd_entry *in = param(d, row, "bsdf");
    pdict sub;
    bool str;
    const char *bt = nested_type(d, in, &str, &sub);
    pk_status st;
    if (!bt) {
        pd_free(&sub);
        return pd_fail(d, in, -1, PK_ERR_PARSE, "a two_sided material needs a \"bsdf\": a material object with a \"type\"");
    }
    if (str && (strcmp(bt, "dielectric") == 0 || strcmp(bt, "two_sided") == 0)) {
        st = pd_fail(&sub, pd_get(&sub, "type"), -1, PK_ERR_PARSE, "is two-sided already");
        pd_free(&sub);
        return st;
    }
    pd_free(&sub);
    if ((st = read_nested(d, in, m))) return st;
    m->two_sided = true;
    const pd_entry *ts = pd_get(d, "two_sided");
    if (ts) return pd_fail(d, ts, -1, PK_ERR_PARSE, "a two_sided material is two-sided by its type");
    return PK_OK;
}

/* The physically based material types (docs/materials.md), by dialect and
 * name; the pbrt, Mitsuba and glTF names will be rows of their dialects. */
static const mat_row mat_rows[] = {
    {MD_PAPRSEK, "diffuse", {"albedo"}, create_diffuse},
    {MD_PAPRSEK, "conductor", {"eta", "k", "specular", "roughness", "alpha", "alpha_u", "alpha_v"}, create_conductor},
    {MD_PAPRSEK, "dielectric", {"ior", "roughness", "transmittance", "alpha_u", "alpha_v"}, create_dielectric},
    {MD_PAPRSEK, "plastic", {"albedo", "ior", "roughness"}, create_plastic},
    {MD_PAPRSEK, "metallic_roughness",
     {"base_color", "metallic", "roughness", "transmission", "ior", "metallic_roughness_map", "clearcoat",
      "clearcoat_roughness"},
     create_metallic_roughness},
    {MD_PAPRSEK, "emitter", {"radiance", "bsdf"}, create_emitter},
    {MD_PAPRSEK, "two_sided", {"bsdf"}, create_two_sided},
    {MD_PAPRSEK, "interface", {NULL}, NULL},
    {MD_PAPRSEK, "thin_dielectric", {"ior", "transmittance"}, create_thin_dielectric},
    {MD_PAPRSEK, "diffuse_transmission", {"albedo", "transmittance"}, create_diffuse_transmission},
    {MD_PAPRSEK, "mix", {"materials", "amount"}, create_mix},
    {MD_PAPRSEK, "rough_diffuse", {"albedo", "alpha"}, create_rough_diffuse},
    {MD_PAPRSEK, "phong", {"albedo", "specular", "exponent"}, create_phong},
    {MD_PAPRSEK,
     "coated",
     {"albedo", "ior", "roughness", "alpha", "eta", "k", "specular", "base_roughness", "base_alpha", "thickness",
      "layer_albedo", "g", "maxdepth", "nsamples"},
     create_coated},
    {MD_PAPRSEK, "principled",
     {"base_color", "roughness", "metallic", "spec_trans", "anisotropic", "spec_tint", "sheen", "sheen_tint",
      "flatness", "clearcoat", "clearcoat_gloss", "eta", "specular", "main_specular_sampling_rate",
      "clearcoat_sampling_rate", "diffuse_reflectance_sampling_rate"},
     create_principled},
};
#define N_MAT_ROWS (sizeof mat_rows / sizeof mat_rows[0])

/* The maps any material may have: "opacity" (or the MTL record's "d") as a
 * texture (cut-out holes where it is below 0.5), "bump" (heights, with
 * "strength": -bm) and "normal_map" (tangent space). */
static pk_status read_surface_maps(pdict *d, const pd_entry *opacity, material *m)
{
    bool loaded;
    pk_status st;
    const pd_entry *normal = pd_get(d, "normal_map"), *bump = pd_get(d, "bump");
    if (is_obj(opacity) && (st = pd_texture(d, opacity, false, &m->map_d, &loaded))) return st;
    if (normal && (st = pd_texture(d, normal, false, &m->map_norm, &loaded))) return st;
    if (bump && (st = pd_texture(d, bump, false, &m->map_bump, &loaded))) return st;
    return PK_OK;
}

/* The prelude every type shares: maps, textured parameters (the texture's
 * value alone where it loaded), then the numbers several types read. */
static pk_status read_common(pdict *d, const mat_row *row, mat_common *c, material *m)
{
    const bool mr = row->create == create_metallic_roughness;
    pk_status st;
    bool loaded;
    const pd_entry *e, *op = pd_get(d, "opacity");
    if (op && !is_obj(op))
        return pd_fail(d, op, -1, PK_ERR_PARSE, "must be a texture object (cut-out holes where it is below 0.5)");
    if ((st = read_surface_maps(d, op, m))) return st;
    c->tex_albedo = v3s(-1.0f), c->tex_specular = v3s(-1.0f), c->tex_alpha = -1.0f;
    bool tex_base = false, tex_albedo = false, tex_rough[2] = {false, false};
    if (mr) {
        /* base colour: a colour or an (sRGB) texture; metallic and roughness:
         * numbers, scaled by the metallic_roughness_map (data, not sRGB) */
        static const char *const scalars[] = {"metallic", "transmission", "clearcoat", "clearcoat_roughness"};
        for (size_t k = 0; k < sizeof scalars / sizeof scalars[0]; k++)
            if (is_obj(e = param(d, row, scalars[k])))
                return pd_fail(d, e, -1, PK_ERR_PARSE, "must be a number in 0..1 (textures: \"metallic_roughness_map\")");
        if (is_obj(e = param(d, row, "roughness")))
            return pd_fail(d, e, -1, PK_ERR_PARSE, "must be a number in 0..1 (textures: \"metallic_roughness_map\")");
        if (is_obj(e = param(d, row, "base_color"))) {
            if ((st = pd_texture(d, e, true, &m->map_kd, &loaded))) return st;
            c->tex_albedo = loaded ? v3s(1.0f) : v3s(0.5f);
            tex_base = true;
        }
        if ((e = param(d, row, "metallic_roughness_map"))) {
            if (!is_obj(e)) return pd_fail(d, e, -1, PK_ERR_PARSE, "must be a texture object");
            if ((st = pd_texture(d, e, false, &m->map_mr, &loaded))) return st;
        }
    }
    if (is_obj(e = param(d, row, "albedo"))) {
        if ((st = pd_texture(d, e, true, &m->map_kd, &loaded))) return st;
        c->tex_albedo = loaded ? v3s(1.0f) : v3s(0.5f);
        tex_albedo = true;
    }
    if (is_obj(e = param(d, row, "specular"))) {
        if ((st = pd_texture(d, e, true, &m->map_ks, &loaded))) return st;
        c->tex_specular = loaded ? v3s(1.0f) : v3s(0.04f);
    }
    static const char *const rough[2] = {"roughness", "alpha"};
    for (int k = 0; k < 2; k++) {
        if (!is_obj(e = param(d, row, rough[k]))) continue;
        if ((st = pd_texture(d, e, false, &m->map_alpha, &loaded))) return st;
        m->map_alpha.squared = k == 0; /* alpha = roughness^2 */
        c->tex_alpha = loaded ? 1.0f : 0.0f;
        tex_rough[k] = true;
    }
    c->roughness = 0.0f, c->alpha = 0.0f, c->ior = 1.5f;
    c->albedo = v3s(0.5f), c->transmittance = v3s(1.0f);
    if (!tex_albedo && param(d, row, "albedo") && (st = pd_vec3(d, "albedo", c->albedo, PD_V_REFLECTANCE, &c->albedo)))
        return st;
    if (mr) {
        c->albedo = v3s(1.0f); /* glTF's defaults: base colour 1, metallic 1, roughness 1 */
        c->roughness = 1.0f;
        if (!tex_base && (st = pd_vec3(d, "base_color", c->albedo, PD_V_REFLECTANCE, &c->albedo))) return st;
    }
    if (param(d, row, "transmittance") &&
        (st = pd_vec3(d, "transmittance", c->transmittance, PD_V_REFLECTANCE, &c->transmittance)))
        return st;
    const pd_entry *re = tex_rough[0] ? NULL : param(d, row, "roughness");
    if (re) {
        if ((st = pd_float(d, "roughness", c->roughness, PD_UNIT, &c->roughness))) return st;
        c->alpha = c->roughness * c->roughness;
    }
    const pd_entry *ae = tex_rough[1] ? NULL : param(d, row, "alpha");
    if (ae) {
        if (re) return pd_fail(d, ae, -1, PK_ERR_PARSE, "give \"roughness\" or \"alpha\", not both");
        if ((st = pd_float(d, "alpha", c->alpha, PD_UNIT, &c->alpha))) return st;
    }
    if ((e = param(d, row, "ior"))) {
        if ((st = pd_float(d, "ior", c->ior, PD_POSITIVE, &c->ior))) return st;
        if (c->ior == 1.0f && c->alpha > 0.0f && !mr)
            return pd_fail(d, e, -1, PK_ERR_PARSE, "must not be 1 on a rough surface (roughness > 0)");
    }
    if (c->tex_albedo.x >= 0.0f) c->albedo = c->tex_albedo;
    if (c->tex_alpha >= 0.0f) c->alpha = c->tex_alpha;
    m->alpha = c->alpha;
    return PK_OK;
}

/* A material with a "type" (type_entry). */
static pk_status create_typed(pdict *d, const pd_entry *type_entry, material *m)
{
    size_t t = 0;
    const bool str = type_entry && type_entry->kind == PD_STRING;
    if (str)
        while (t < N_MAT_ROWS && (mat_rows[t].dialect != MD_PAPRSEK || strcmp(type_entry->str, mat_rows[t].type) != 0))
            t++;
    if (!str || t == N_MAT_ROWS)
        return pd_fail(d, type_entry, -1, PK_ERR_PARSE,
                       "must be one of \"diffuse\", \"conductor\", \"dielectric\", \"plastic\", "
                       "\"metallic_roughness\", \"emitter\", \"two_sided\", \"interface\", \"thin_dielectric\", "
                       "\"diffuse_transmission\", \"mix\", \"rough_diffuse\", \"phong\", \"coated\", \"principled\"");
    const mat_row *row = &mat_rows[t];
    /* the known keys: "type", "two_sided", the maps, the type's parameters
     * and the media (read by the caller) */
    static const char *const common[] = {"type", "two_sided", "opacity", "bump", "normal_map", "interior", "exterior"};
    pd_declare(d, common, sizeof common / sizeof common[0]);
    size_t np = 0;
    while (np < MAT_MAX_PARAMS && row->params[np]) np++;
    pd_declare(d, row->params, np);
    pk_status st = pd_report_unused(d);
    if (st) return st;

    material_init(m);
    if (!row->create) { /* no surface: the boundary of media */
        for (int k = 1; k <= 4; k++) {
            const pd_entry *e = pd_get(d, common[k]);
            if (e) return pd_fail(d, e, -1, PK_ERR_PARSE, "an interface has no surface to shade");
        }
        material_interface(m);
        return PK_OK;
    }
    mat_common c;
    if ((st = read_common(d, row, &c, m))) return st;
    if ((st = row->create(d, row, &c, m))) return st;
    if (row->create == create_two_sided) return PK_OK;
    bool two = m->two_sided;
    if ((st = pd_bool(d, "two_sided", two, &two))) return st;
    m->two_sided = two;
    return PK_OK;
}

/* The OBJ/MTL record: "kd", "ks", "ke", "tf", "ka" colours ("kd", "ks" and
 * "ns" may be textures), "ns", "ni", "d" (or an opacity texture), "illum". */
static pk_status create_mtl(pdict *d, material *m)
{
    static const char *const keys[] = {"kd", "ks", "ke", "tf", "ka", "ns", "ni", "d", "illum",
                                       "two_sided", "bump", "normal_map", "interior", "exterior"};
    pd_declare(d, keys, sizeof keys / sizeof keys[0]);
    pk_status st = pd_report_unused(d);
    if (st) return st;
    material_init(m);
    vec3 *colours[5] = {&m->kd, &m->ks, &m->ke, &m->tf, &m->ka};
    bool loaded;
    for (int i = 0; i < 5; i++) {
        const pd_entry *e = pd_get(d, keys[i]);
        if (!e) continue;
        if (i < 2 && is_obj(e)) { /* a texture: its value alone */
            if ((st = pd_texture(d, e, true, i == 0 ? &m->map_kd : &m->map_ks, &loaded))) return st;
            if (loaded) *colours[i] = v3s(1.0f);
            continue;
        }
        if ((st = pd_vec3(d, keys[i], *colours[i], PD_V_COLOUR, colours[i]))) return st;
    }
    const pd_entry *ns = pd_get(d, "ns"), *dd = pd_get(d, "d");
    if (is_obj(ns)) {
        if ((st = pd_texture(d, ns, false, &m->map_ns, &loaded))) return st;
        if (loaded) m->ns = 1.0f;
    } else if ((st = pd_float(d, "ns", m->ns, PD_NONNEG, &m->ns))) {
        return st;
    }
    if ((st = read_surface_maps(d, dd, m))) return st;
    if ((st = pd_float(d, "ni", m->ni, PD_POSITIVE, &m->ni))) return st;
    if (dd && !is_obj(dd) && (st = pd_float(d, "d", m->d, PD_UNIT, &m->d))) return st;
    if ((st = pd_int(d, "illum", m->illum, 0, 10, &m->illum))) return st;
    return pd_bool(d, "two_sided", m->two_sided, &m->two_sided);
}

pk_status create_material(pdict *d, material *m)
{
    const pd_entry *type = pd_get(d, "type");
    return type ? create_typed(d, type, m) : create_mtl(d, m);
}
