/*
 * scene_pbrt.c - pbrt-v4 scenes (docs/scene-format.md, "pbrt-v4"): the
 * directive layer over the tokenizer (pbrt_tok.c) and the shared graphics
 * state (scene_build.h). Directives are read one at a time with their
 * positional arguments and their parameter list ("type name" value...), then
 * carried out: transforms on the builder's stack, materials through the
 * material constructors, shapes as meshes (or analytic spheres), lights as
 * the scene's point lights, environment and emissive materials, objects as
 * the scene's meshes and instances. Every message says file:line.
 *
 * Handedness: pbrt's camera space is left-handed (+x right, +y up, +z
 * forward), Paprsek's camera right-handed. When the camera transform does
 * not itself mirror, the image pbrt renders is the mirror image of what a
 * right-handed camera with the same eye, view and up sees; the reader then
 * mirrors the whole world across the camera's vertical plane (the matrix
 * `mirror`, applied before every world transform), which gives pbrt's image
 * with Paprsek's camera. Windings are kept so that each surface faces the
 * side pbrt's normal points to.
 */
#include "readers.h"

#include "../image/image_read.h"
#include "../options.h"
#include "../scene/camera.h"
#include "../math/distrib.h"
#include "../scene/spectra.h"
#include "grid_io.h"
#include "io_util.h"
#include "pbrt_param.h"
#include "scene_build.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#define PB_MAX_INCLUDE_DEPTH 16
#define PB_NAME_MAX 256
#define PB_MAX_SUBDIV_TRIS (1u << 24) /* triangles one loopsubdiv shape may make */

/* ---- the reader's state ------------------------------------------------------------ */

typedef enum tex_class { TC_IMAGE, TC_CHECKER, TC_CONST, TC_EXPR } tex_class;

/* A named texture: a constant, an image or a uv checkerboard of constants
 * (the scene's own map kinds), or an expression of procedural nodes
 * (TC_EXPR). Every class also keeps its nodes, so that another texture can
 * take it as an operand. */
typedef struct named_tex {
    char *name;
    bool is_float;
    tex_class cls;
    tex_ref ref;      /* TC_IMAGE, TC_CHECKER; TC_EXPR once added to the scene (added) */
    bool added;
    vec3 value;       /* TC_CONST: the value; TC_EXPR: its mean; else the constant the map multiplies */
    tex_node *nodes;  /* owned, nnodes (1..TEX_MAX_NODES) */
    int nnodes;
} named_tex;

typedef struct area_light {
    vec3 L;           /* radiance (scale applied) */
    bool two_sided;
    float power;      /* > 0: the emitted power the shape is scaled to */
    int32_t image;    /* "filename": the scene's texture that multiplies L (the emission map, looked up with its edges
                         clamped, as pbrt-v4 does), -1 none */
} area_light;

typedef struct mat_variant {
    uint32_t base;
    vec3 ke;
    bool two_sided;
    int32_t alpha_tex;   /* named texture index, -1 none */
    int32_t ke_tex;      /* the emission map (a scene texture), -1 none */
    uint32_t mat;
} mat_variant;

typedef struct gstate {
    uint32_t material;
    bool interface;      /* the current material is pbrt's "interface": only bounds media */
    int32_t area;        /* index into areas, -1 none */
    bool reverse;
    /* MediumInterface: the inside and outside media's names (indices into
     * pp.mnames, -1 for "": vacuum); equal ones are no transition, and the
     * shapes keep the ray's medium */
    int32_t mi_in, mi_out;
} gstate;

typedef struct named_xf {
    char *name;
    xform x;
} named_xf;

/* Attribute "target" parameters: defaults for the directives of that
 * target in the attribute block (depth) where they were given. */
typedef enum attr_target { AT_SHAPE, AT_LIGHT, AT_MATERIAL, AT_MEDIUM, AT_TEXTURE } attr_target;

typedef struct attr_def {
    attr_target target;
    int depth;
    pparam prm;
} attr_def;

typedef struct named_obj {
    char *name;
    uint32_t mesh;       /* UINT32_MAX: empty */
} named_obj;

typedef struct pfile {
    const char *name;    /* for messages */
    const char *dir;     /* includes are relative to it */
    char *key;           /* the resolved path, for cycles */
    pbrt_tokenizer tok;
} pfile;

typedef struct pp {
    pk_context *ctx;
    pk_scene *s;
    scene_builder b;
    pfile *files[PB_MAX_INCLUDE_DEPTH + 1];
    int nfiles;
    pfile *f;            /* the current file */
    size_t line;         /* of the directive being carried out */
    const char *dname;   /* its name */
    plist pl;
    pdict pd;            /* pl as a dictionary (pd_from_pbrt): what the directive used */

    gstate gs[SB_MAX_DEPTH];
    bool in_world;
    bool active_end;     /* ActiveTransform EndTime: transforms are not applied */
    xform mirror;        /* applied before every world transform (see the top) */

    /* camera */
    bool cam_set;
    xform cam_from_world;
    size_t cam_line;
    const char *cam_file;
    float fov, lens_radius, focal_distance, frame_aspect, screen[4];
    bool has_screen, ortho;
    int film_w, film_h;
    float film_iso, exposure_time;  /* pbrt's sensor records radiance x time x ISO / 100 */

    named_tex *tex;
    size_t ntex, cap_tex;
    area_light *areas;
    size_t nareas, cap_areas;
    mat_variant *vars;
    size_t nvars, cap_vars;
    uint8_t *is_interface;  /* per scene material */
    size_t cap_iface;
    named_xf *coords;
    size_t ncoords, cap_coords;
    named_obj *objs;
    size_t nobjs, cap_objs;
    char *obj_name;         /* the object being defined */
    int obj_depth;          /* the attribute depth its ObjectBegin opened */
    size_t obj_line;        /* and its line */
    pfile top;              /* the first file, for messages after it is read */
    attr_def *defs;
    size_t ndefs, cap_defs;
    /* media: the names MediumInterface used, the camera's medium (the
     * outside medium current at Camera) and where it was named, and the
     * first medium this file added (their grids are mirrored at the end) */
    char **mnames;
    size_t nmnames, cap_mnames;
    int32_t cam_mi;
    size_t cam_mi_line;
    char cam_mi_file[256];
    size_t media_start;
} pp;

static const pk_allocator *A(pp *p) { return &p->ctx->alloc; }

static pk_status pfail(pp *p, size_t line, pk_status st, const char *fmt, ...) PK_PRINTF(4, 5);
static pk_status pfail(pp *p, size_t line, pk_status st, const char *fmt, ...)
{
    char buf[PK_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    return ctx_error(p->ctx, st, "%s:%zu: %s", p->f->name, line, buf);
}

static void pwarn(pp *p, size_t line, const char *fmt, ...) PK_PRINTF(3, 4);
static void pwarn(pp *p, size_t line, const char *fmt, ...)
{
    if (!p->ctx->warn) return;
    char buf[PK_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    ctx_warn(p->ctx, "%s:%zu: %s", p->f->name, line, buf);
}

static gstate *GS(pp *p) { return &p->gs[p->b.depth]; }

/* ---- parameter lists ------------------------------------------------------------------ */

static pk_status tok_error(pp *p, const pbrt_token *tk)
{
    return pfail(p, tk->line, PK_ERR_PARSE, "%s", p->f->tok.why);
}

static void plist_clear(pp *p) { pb_list_clear(&p->pd, &p->pl); }
static pk_status read_params(pp *p) { return pb_read_params(&p->pd, &p->pl, &p->f->tok); }

/* The dictionary's messages: pbrt's, at the parameter's line. */
static pk_status pd_pbrt_fail(void *self, const pdict *d, const pd_entry *e, long elem, pk_status st, const char *msg)
{
    (void)d, (void)elem;
    pp *p = self;
    return pfail(p, e ? e->line : p->line, st, "%s", msg);
}
static void pd_pbrt_unused(void *self, const pdict *d, const pd_entry *e)
{
    pwarn(self, e->line, "%s: parameter '%s %s' is not supported; ignored", d->what, e->type, e->name);
}
static const pd_source pbrt_source = {.fail = pd_pbrt_fail, .warn_unused = pd_pbrt_unused};

/* Drops the Attribute defaults of blocks deeper than depth. */
static void defs_pop(pp *p, int depth)
{
    while (p->ndefs && p->defs[p->ndefs - 1].depth > depth) pb_param_free(A(p), &p->defs[--p->ndefs].prm);
}

/* Appends the Attribute defaults of target that the directive did not give
 * (the latest one of a name holds). */
static pk_status apply_defaults(pp *p, attr_target target)
{
    for (size_t i = p->ndefs; i-- > 0;) {
        const attr_def *d = &p->defs[i];
        if (d->target != target) continue;
        bool given = false;
        for (size_t k = 0; k < p->pl.n && !given; k++) given = strcmp(p->pl.p[k].name, d->prm.name) == 0;
        if (given) continue;
        if (!mem_grow(A(p), (void **)&p->pl.p, &p->pl.cap, p->pl.n + 1, sizeof *p->pl.p)) return ctx_nomem(p->ctx);
        pk_status st = pb_param_copy(p->ctx, &d->prm, &p->pl.p[p->pl.n]);
        if (st) return st;
        p->pl.p[p->pl.n++].from_attribute = true;
    }
    return pd_from_pbrt(&p->pd, &p->pl);
}

/* Warns about the parameters the directive did not use (pbrt refuses them;
 * a scene written for a later pbrt still renders here). fmt...: the
 * directive, as the message names it (the dictionary's what, read only
 * while it reports). */
static void warn_unused(pp *p, const char *fmt, ...) PK_PRINTF(2, 3);
static void warn_unused(pp *p, const char *fmt, ...)
{
    char what[96];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    p->pd.what = what;
    (void)pd_report_unused(&p->pd); /* read_params refuses duplicates: it cannot fail */
}

/* ---- colours and spectra ------------------------------------------------------------------ */

/* Sampled spectrum values (wavelengths in nm, increasing) as linear RGB:
 * an emitter by pbrt's rule, anything else as a reflectance (a flat one is
 * grey, and a flat index of refraction its value). */
#define PB_MAX_SPECTRUM 4096
static pk_status spectrum_samples(pp *p, const pparam *q, const float *nm, const float *val, size_t n, bool illuminant,
                                  vec3 *out)
{
    for (size_t i = 1; i < n; i++)
        if (!(nm[i] > nm[i - 1]))
            return pfail(p, q->line, PK_ERR_PARSE, "'spectrum %s': wavelengths must increase", q->name);
    *out = illuminant ? spectra_pbrt_emitter(nm, val, n) : spectrum_to_rgb(nm, val, (int)n);
    return PK_OK;
}

/* A spectrum named by a file (pbrt-v4's .spd: wavelength and value pairs,
 * '#' to the end of a line a comment), relative to the file that names
 * it. A file that cannot be read or is not such a list is a warning, and
 * 1 stands in (as pbrt would stop, a scene still renders here). */
static pk_status spectrum_file(pp *p, const pparam *q, const char *name, bool illuminant, vec3 *out)
{
    *out = v3s(1.0f);
    char *data;
    size_t size, n = 0, k = 0;
    pk_context tmp = io_scratch_context(p->ctx);
    pk_status st = io_read_relative(p->ctx, &tmp, p->f->dir, name, NULL, &data, &size);
    if (st == PK_ERR_NOMEM) return st;
    if (st) {
        pwarn(p, q->line, "spectrum \"%.60s\" is neither a named spectrum nor a file that can be read (%s); using 1",
              name, tmp.message);
        return PK_OK;
    }
    float *nm = mem_alloc(A(p), 2 * PB_MAX_SPECTRUM * sizeof(float)), *val = nm + PB_MAX_SPECTRUM;
    const char *why = NULL, *c = data, *e = data + size;
    if (!nm) st = ctx_nomem(p->ctx);
    while (st == PK_OK && !why && c < e) {
        if (*c == '#') {
            while (c < e && *c != '\n') c++;
        } else if (*c == ' ' || *c == '\t' || *c == '\r' || *c == '\n' || *c == ',') {
            c++;
        } else if (k == 2 * PB_MAX_SPECTRUM) {
            why = "more than 4096 samples";
        } else {
            float v;
            const char *next = io_parse_float(c, e, &v);
            if (!next || next == c || !isfinite(v)) why = "something that is not a number";
            else {
                if (k % 2) val[k / 2] = v;
                else nm[k / 2] = v;
                k++;
                c = next;
            }
        }
    }
    n = k / 2;
    if (st == PK_OK && !why && (k % 2 || n == 0)) why = k % 2 ? "an odd count of numbers" : "no samples";
    if (st == PK_OK && !why)
        for (size_t i = 1; i < n && !why; i++)
            if (!(nm[i] > nm[i - 1])) why = "wavelengths that do not increase";
    if (st == PK_OK && why)
        pwarn(p, q->line, "spectrum file \"%.60s\" holds %s (wavelength and value pairs were expected); using 1", name,
              why);
    else if (st == PK_OK)
        st = spectrum_samples(p, q, nm, val, n, illuminant, out);
    mem_free(A(p), nm);
    mem_free(A(p), data);
    return st;
}

/* A spectrum parameter as linear RGB. illuminant: the light's rule (a
 * blackbody or a standard illuminant at luminance 1). */
static pk_status spectrum_rgb(pp *p, const pparam *q, bool illuminant, vec3 *out)
{
    if (q->type == PT_RGB) {
        *out = v3((float)q->num[0], (float)q->num[1], (float)q->num[2]);
        if (q->nnum != 3) return pfail(p, q->line, PK_ERR_PARSE, "'rgb %s' takes 3 values, not %zu", q->name, q->nnum);
        if (!v3_finite(*out)) return pfail(p, q->line, PK_ERR_PARSE, "'rgb %s' is not finite in float", q->name);
        return PK_OK;
    }
    if (q->type == PT_BLACKBODY) {
        if (!(q->num[0] > 0.0) || q->num[0] > 1e6)
            return pfail(p, q->line, PK_ERR_PARSE, "'blackbody %s' %g K is not a temperature", q->name, q->num[0]);
        *out = spectra_pbrt_blackbody((float)q->num[0]);
        if (!illuminant) *out = v3_scale(*out, 1.0f / fmaxf(v3_max_comp(*out), 1e-6f));
        return PK_OK;
    }
    if (q->type == PT_FLOAT) {
        if (q->nnum != 1) return pfail(p, q->line, PK_ERR_PARSE, "'float %s' takes one value", q->name);
        *out = v3s((float)q->num[0]);
        return PK_OK;
    }
    /* spectrum: pairs, a name, or a file of pairs */
    if (q->nnum) {
        size_t n = q->nnum / 2;
        if (n > PB_MAX_SPECTRUM) return pfail(p, q->line, PK_ERR_LIMIT, "'spectrum %s': more than %d samples", q->name, PB_MAX_SPECTRUM);
        float nm[PB_MAX_SPECTRUM], val[PB_MAX_SPECTRUM];
        for (size_t i = 0; i < n; i++) nm[i] = (float)q->num[2 * i], val[i] = (float)q->num[2 * i + 1];
        return spectrum_samples(p, q, nm, val, n, illuminant, out);
    }
    const char *nmn = q->str[0];
    const int known = spectra_pbrt_named(nmn, out);
    if (known == SPECTRA_PBRT_UNKNOWN) return spectrum_file(p, q, nmn, illuminant, out);
    return PK_OK;
}

/* ---- named textures ------------------------------------------------------------------------- */

static named_tex *find_tex(pp *p, const char *name)
{
    for (size_t i = p->ntex; i-- > 0;)
        if (strcmp(p->tex[i].name, name) == 0) return &p->tex[i];
    return NULL;
}

/* The scene's copy of an expression texture's nodes, made once (later
 * uses share it). */
static pk_status tex_add_expr(pp *p, named_tex *t, tex_ref *out)
{
    if (!t->added) {
        pk_status st = scene_add_tex_nodes(p->ctx, p->s, t->nodes, t->nnodes, &t->ref);
        if (st) return st;
        t->added = true;
    }
    *out = t->ref;
    return PK_OK;
}

/* A colour parameter (reflectance, ...): *c the constant, *tex the map
 * (when tex is non-NULL and the parameter names an image or checkerboard
 * texture). found: whether the parameter was there. */
static pk_status get_colour(pp *p, const char *name, vec3 *c, tex_ref *tex, bool *found)
{
    pparam *q;
    pk_status st = pb_typed(&p->pd, name,
                            TB(PT_RGB) | TB(PT_SPECTRUM) | TB(PT_BLACKBODY) | TB(PT_TEXTURE) | TB(PT_FLOAT),
                            "a colour (rgb, spectrum, blackbody, float or texture)", &q);
    if (found) *found = q != NULL;
    if (st || !q) return st;
    if (q->type != PT_TEXTURE) return spectrum_rgb(p, q, false, c);
    if (q->nstr != 1) return pfail(p, q->line, PK_ERR_PARSE, "'texture %s' takes one name", name);
    named_tex *t = find_tex(p, q->str[0]);
    if (!t) return pfail(p, q->line, PK_ERR_PARSE, "'texture %s': no texture named \"%.60s\"", name, q->str[0]);
    if (t->cls == TC_CONST) {
        *c = t->value;
        return PK_OK;
    }
    if (!tex) {
        pwarn(p, q->line, "a texture for '%s' is not supported (the material has no texture map for it); using its mean %g",
              name, (double)v3_luminance(t->value));
        *c = t->value;
        return PK_OK;
    }
    if (t->cls == TC_EXPR) {
        pk_status st2 = tex_add_expr(p, t, tex);
        *c = v3s(1.0f);
        return st2;
    }
    *tex = t->ref;
    *c = t->value;
    return PK_OK;
}

/* A float parameter that may be a texture (a constant one is used; an
 * image is warned and def used) or, where spectra are allowed, a named
 * glass. */
static pk_status get_float_tex(pp *p, const char *name, float *v, bool *found)
{
    pparam *q;
    pk_status st = pb_typed(&p->pd, name, TB(PT_FLOAT) | TB(PT_TEXTURE) | TB(PT_SPECTRUM) | TB(PT_RGB),
                            "a float or a float texture", &q);
    if (found) *found = q != NULL;
    if (st || !q) return st;
    if (q->type == PT_FLOAT) {
        if (q->nnum != 1) return pfail(p, q->line, PK_ERR_PARSE, "'float %s' takes one value, not %zu", name, q->nnum);
        *v = (float)q->num[0];
        return PK_OK;
    }
    if (q->type == PT_SPECTRUM || q->type == PT_RGB) {
        vec3 c;
        if ((st = spectrum_rgb(p, q, false, &c))) return st;
        if (q->type == PT_RGB || q->nnum) pwarn(p, q->line, "'%s %s' is reduced to one value (green)", q->tname, name);
        *v = c.y;
        return PK_OK;
    }
    if (q->nstr != 1) return pfail(p, q->line, PK_ERR_PARSE, "'texture %s' takes one name", name);
    named_tex *t = find_tex(p, q->str[0]);
    if (!t) return pfail(p, q->line, PK_ERR_PARSE, "'texture %s': no texture named \"%.60s\"", name, q->str[0]);
    if (t->cls == TC_CONST) {
        *v = t->value.x;
        return PK_OK;
    }
    if (t->cls == TC_EXPR) {
        *v = t->value.x;
        pwarn(p, q->line, "a texture for '%s' is not supported (the material has no texture map for it); using its mean %g",
              name, (double)*v);
        return PK_OK;
    }
    pwarn(p, q->line, "a texture for '%s' is not supported; using %g", name, (double)*v);
    return PK_OK;
}

/* ---- transforms ------------------------------------------------------------------------------- */

/* pbrt's 16 numbers: the matrix in column-major order. */
static pk_status read_matrix(pp *p, const double *v, size_t line, xform *out)
{
    xform x;
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) x.m[4 * r + c] = (float)v[4 * c + r];
    if (!xform_finite(&x)) return pfail(p, line, PK_ERR_PARSE, "the matrix is not finite");
    if (!xform_is_affine(&x))
        return pfail(p, line, PK_ERR_PARSE, "projective matrices are not supported (the last column must be 0 0 0 1)");
    *out = x;
    return PK_OK;
}

static pk_status ctm_concat(pp *p, const xform *x)
{
    if (p->active_end) return PK_OK;
    xform c = xform_mul(sb_transform(&p->b), x);
    if (!xform_finite(&c)) return pfail(p, p->line, PK_ERR_PARSE, "%s: the transform is no longer finite", p->dname);
    sb_set_transform(&p->b, &c);
    return PK_OK;
}

static void ctm_set(pp *p, const xform *x)
{
    if (!p->active_end) sb_set_transform(&p->b, x);
}

/* The transform from the current object space to Paprsek's world. */
static xform world_xf(pp *p) { return xform_mul(&p->mirror, sb_transform(&p->b)); }

/* ---- materials -------------------------------------------------------------------------------- */

static pk_status set_interface(pp *p, uint32_t mat, bool v)
{
    if (mat >= p->cap_iface) {
        size_t cap = p->cap_iface;
        uint8_t *n = p->is_interface;
        if (!mem_grow(A(p), (void **)&n, &cap, (size_t)mat + 1, 1)) return ctx_nomem(p->ctx);
        memset(n + p->cap_iface, 0, cap - p->cap_iface);
        p->is_interface = n, p->cap_iface = cap;
    }
    p->is_interface[mat] = v;
    return PK_OK;
}

static bool mat_is_interface(pp *p, uint32_t mat) { return mat < p->cap_iface && p->is_interface[mat]; }

static float rough_alpha(float r, bool remap)
{
    if (!(r > 0.0f)) return 0.0f;
    float a = remap ? sqrtf(r) : r;
    return a < 1e-3f ? 0.0f : a; /* pbrt treats these as smooth */
}

/* A roughness texture as a map of the GGX alpha (map non-NULL): the
 * texture's nodes, then their square root when remap (pbrt's
 * RoughnessToAlpha); the constant alpha becomes 1. False when the texture
 * does not fit (warned by the caller's float path). */
static pk_status roughness_map(pp *p, const named_tex *t, bool remap, tex_ref *map, bool *done)
{
    *done = false;
    if (t->nnodes + (remap ? 1 : 0) > TEX_MAX_NODES) return PK_OK;
    tex_node nodes[TEX_MAX_NODES];
    memcpy(nodes, t->nodes, (size_t)t->nnodes * sizeof *nodes);
    int n = t->nnodes;
    if (remap) {
        memset(&nodes[n], 0, sizeof nodes[n]);
        nodes[n].op = TN_SQRT, nodes[n].a = (int8_t)(n - 1), nodes[n].b = nodes[n].c = -1;
        n++;
    }
    pk_status st = scene_add_tex_nodes(p->ctx, p->s, nodes, n, map);
    *done = st == PK_OK;
    return st;
}

static float clamp_alpha(float a) { return !isfinite(a) || a < 0.0f ? 0.0f : a > 1.0f ? 1.0f : a; }

/* roughness / uroughness / vroughness and remaproughness (prefix: "" or
 * "interface." / "conductor."). map: where a roughness texture goes (the
 * material's map_alpha; its alpha is then 1), NULL where there is none.
 * alpha_v NULL: anisotropic roughness is warned about and rendered as the
 * mean of the two alphas. alpha_v non-NULL: *alpha is the alpha along u
 * (the surface's dp/du) and *alpha_v the one along v where the two differ
 * (material's alpha_v), -1 where the roughness is isotropic. */
static pk_status get_roughness_uv(pp *p, const char *prefix, float *alpha, float *alpha_v, tex_ref *map)
{
    if (alpha_v) *alpha_v = -1.0f;
    char n1[64], n2[64], n3[64], n4[64];
    snprintf(n1, sizeof n1, "%sroughness", prefix);
    snprintf(n2, sizeof n2, "%suroughness", prefix);
    snprintf(n3, sizeof n3, "%svroughness", prefix);
    snprintf(n4, sizeof n4, "remaproughness");
    float r = 0.0f, u = -1.0f, v = -1.0f;
    bool remap = true, fu, fv;
    pk_status st;
    if (map) {
        pparam *rq = NULL;
        if ((st = pb_typed(&p->pd, n1, TB(PT_FLOAT) | TB(PT_TEXTURE) | TB(PT_SPECTRUM) | TB(PT_RGB),
                           "a float or a float texture", &rq)))
            return st;
        named_tex *rt = rq && rq->type == PT_TEXTURE && rq->nstr == 1 ? find_tex(p, rq->str[0]) : NULL;
        if (rt && rt->cls != TC_CONST) {
            if (!pd_has(&p->pd, n2) && !pd_has(&p->pd, n3)) {
                bool done;
                if ((st = pb_bool(&p->pd, n4, &remap)) || (st = roughness_map(p, rt, remap, map, &done))) return st;
                if (done) {
                    *alpha = 1.0f;
                    return PK_OK;
                }
            }
        }
    }
    if ((st = get_float_tex(p, n1, &r, NULL)) || (st = get_float_tex(p, n2, &u, &fu)) ||
        (st = get_float_tex(p, n3, &v, &fv)) || (st = pb_bool(&p->pd, n4, &remap)))
        return st;
    if (fu || fv) {
        if (!fu) u = r;
        if (!fv) v = r;
        if (u != v && alpha_v) {
            *alpha = clamp_alpha(rough_alpha(u, remap));
            *alpha_v = clamp_alpha(rough_alpha(v, remap));
            if (*alpha_v == *alpha) *alpha_v = -1.0f;
            return PK_OK;
        }
        if (u != v)
            pwarn(p, p->line, "anisotropic roughness %g x %g is rendered isotropic (the mean of the two alphas)",
                  (double)u, (double)v);
        *alpha = 0.5f * (rough_alpha(u, remap) + rough_alpha(v, remap));
        if (*alpha < 1e-3f) *alpha = 0.0f;
    } else {
        *alpha = rough_alpha(r, remap);
    }
    if (!isfinite(*alpha) || *alpha < 0.0f) *alpha = 0.0f;
    if (*alpha > 1.0f) *alpha = 1.0f;
    return PK_OK;
}
static pk_status get_roughness(pp *p, const char *prefix, float *alpha, tex_ref *map)
{
    return get_roughness_uv(p, prefix, alpha, NULL, map);
}

static pk_status get_eta(pp *p, const char *name, float def, float *eta)
{
    *eta = def;
    pk_status st = get_float_tex(p, name, eta, NULL);
    if (st) return st;
    if (!(*eta > 0.0f) || !isfinite(*eta)) {
        pwarn(p, p->line, "'%s' %g is not an index of refraction; using %g", name, (double)*eta, (double)def);
        *eta = def;
    }
    if (*eta == 1.0f) *eta = 1.0001f; /* an index-matched surface: next to invisible */
    return PK_OK;
}

/* A conductor from the parameters named prefix + eta, k, roughness (or
 * reflectance), at least as rough as min_alpha (a coat's roughness). */
static pk_status make_conductor(pp *p, material *m, const char *prefix, float min_alpha, bool maps)
{
    char ne[64], nk[64], nr[64];
    snprintf(ne, sizeof ne, "%seta", prefix);
    snprintf(nk, sizeof nk, "%sk", prefix);
    snprintf(nr, sizeof nr, "%sroughness", prefix);
    float alpha, alpha_v = -1.0f;
    tex_ref ta;
    tex_ref_init(&ta);
    /* anisotropic where the conductor stands alone (maps); a coated one's is averaged */
    pk_status st = get_roughness_uv(p, prefix, &alpha, maps ? &alpha_v : NULL, maps ? &ta : NULL);
    if (st) return st;
    if (min_alpha > alpha) alpha = min_alpha;
    vec3 refl;
    bool has_refl;
    tex_ref tr;
    tex_ref_init(&tr);
    if ((st = get_colour(p, "reflectance", &refl, &tr, &has_refl))) return st;
    vec3 eta, k;
    spectra_named_metal("Cu", &eta, &k);
    bool fe, fk;
    tex_ref te, tk; /* spectrum textures on eta and k (pbrt evaluates them per hit) */
    tex_ref_init(&te);
    tex_ref_init(&tk);
    if ((st = get_colour(p, ne, &eta, maps ? &te : NULL, &fe)) || (st = get_colour(p, nk, &k, maps ? &tk : NULL, &fk)))
        return st;
    if (has_refl) {
        if (fe || fk) pwarn(p, p->line, "conductor: both reflectance and eta/k are given; reflectance is used");
        material_conductor_f0(m, refl, alpha);
        m->map_ks = tr;
    } else {
        material_conductor(m, eta, k, alpha);
        m->map_eta = te, m->map_k = tk;
    }
    m->alpha_v = alpha_v;
    m->map_alpha = ta;
    return PK_OK;
}

/* The coat's layer (both coated materials): thickness, albedo, g, maxdepth
 * and nsamples, pbrt-v4's defaults where absent. */
static pk_status coat_layer(pp *p, material_layer *l)
{
    int64_t md = 10, ns = 1;
    *l = material_layer_default();
    pk_status st;
    if ((st = get_float_tex(p, "thickness", &l->thickness, NULL)) ||
        (st = get_colour(p, "albedo", &l->albedo, NULL, NULL)) || (st = get_float_tex(p, "g", &l->g, NULL)) ||
        (st = pb_int(&p->pd, "maxdepth", 1, 1 << 16, &md)) ||
        (st = pb_int(&p->pd, "nsamples", 1, 1 << 16, &ns)))
        return st;
    if (!(l->thickness > 0.0f) || !isfinite(l->thickness)) {
        pwarn(p, p->line, "'thickness' %g is not positive; using 0.01", (double)l->thickness);
        l->thickness = 0.01f;
    }
    if (!(l->g > -1.0f && l->g < 1.0f)) {
        pwarn(p, p->line, "'g' %g is outside (-1, 1); clamped", (double)l->g);
        l->g = isnan(l->g) ? 0.0f : fminf(fmaxf(l->g, -0.99f), 0.99f);
    }
    if (v3_min_comp(l->albedo) < 0.0f || v3_max_comp(l->albedo) > 1.0f)
        pwarn(p, p->line, "'albedo' is outside 0..1; clamped");
    l->maxdepth = (int)md, l->nsamples = (int)ns;
    return PK_OK;
}

/* An image file named in the scene (relative to the current file), loaded
 * once as a texture: *idx its index, or -1 when it cannot be used, with the
 * reason in why (a warning for the caller to give); other failures return. */
static pk_status load_image(pp *p, const char *fn, bool colour, int32_t *idx, char *why, size_t nwhy)
{
    *idx = -1;
    char *path = path_join(A(p), p->f->dir, fn);
    if (!path) return ctx_nomem(p->ctx);
    const bool was_ok = p->ctx->status == PK_OK;
    pk_status st = texture_load(p->ctx, p->s, path, colour, idx);
    mem_free(A(p), path);
    if (st == PK_OK) return PK_OK;
    *idx = -1;
    return io_demote_error(p->ctx, st, was_ok, why, nwhy) ? PK_OK : st;
}

/* pbrt-v4 decodes PNG files from sRGB and reads the others as linear. */
static bool png_name(const char *fn)
{
    const size_t fl = strlen(fn);
    return fl >= 4 && (strcmp(fn + fl - 4, ".png") == 0 || strcmp(fn + fl - 4, ".PNG") == 0);
}

/* Fills m from a material's type and the current parameters. */
static pk_status build_material(pp *p, const char *type, material *m, bool *interface, int depth)
{
    pk_status st;
    *interface = false;
    tex_ref tkd;
    tex_ref_init(&tkd);
    vec3 kd = v3s(0.5f);
    float alpha = 0.0f, eta;
    if (strcmp(type, "diffuse") == 0) {
        if ((st = get_colour(p, "reflectance", &kd, &tkd, NULL))) return st;
        material_diffuse(m, kd);
        m->map_kd = tkd;
    } else if (strcmp(type, "coateddiffuse") == 0) {
        material_layer layer;
        tex_ref ta;
        tex_ref_init(&ta);
        if ((st = get_colour(p, "reflectance", &kd, &tkd, NULL)) || (st = get_roughness(p, "", &alpha, &ta)) ||
            (st = get_eta(p, "eta", 1.5f, &eta)) || (st = coat_layer(p, &layer)))
            return st;
        material_coated_diffuse(m, kd, eta, alpha, layer);
        m->map_kd = tkd;
        m->map_alpha = ta;
    } else if (strcmp(type, "conductor") == 0) {
        if ((st = make_conductor(p, m, "", 0.0f, true))) return st;
    } else if (strcmp(type, "coatedconductor") == 0) {
        /* a coat of interface.eta and interface.roughness over a conductor of
         * conductor.eta/k (or reflectance) and conductor.roughness */
        material_layer layer;
        float ba;
        tex_ref ta;
        tex_ref_init(&ta);
        vec3 refl, ce, ck;
        bool has_refl, fe, fk;
        tex_ref tr;
        tex_ref_init(&tr);
        spectra_named_metal("Cu", &ce, &ck);
        if ((st = get_roughness(p, "interface.", &alpha, &ta)) || (st = get_eta(p, "interface.eta", 1.5f, &eta)) ||
            (st = get_roughness(p, "conductor.", &ba, NULL)) ||
            (st = get_colour(p, "reflectance", &refl, &tr, &has_refl)) ||
            (st = get_colour(p, "conductor.eta", &ce, NULL, &fe)) ||
            (st = get_colour(p, "conductor.k", &ck, NULL, &fk)) || (st = coat_layer(p, &layer)))
            return st;
        if (has_refl) {
            if (fe || fk)
                pwarn(p, p->line,
                      "coatedconductor: both reflectance and conductor.eta/k are given; reflectance is used");
            material_coated_conductor_f0(m, refl, ba, eta, alpha, layer);
            m->map_ks = tr;
        } else {
            material_coated_conductor(m, ce, ck, ba, eta, alpha, layer);
        }
        m->map_alpha = ta;
    } else if (strcmp(type, "dielectric") == 0) {
        tex_ref ta;
        tex_ref_init(&ta);
        float alpha_v;
        if ((st = get_eta(p, "eta", 1.5f, &eta)) || (st = get_roughness_uv(p, "", &alpha, &alpha_v, &ta))) return st;
        material_dielectric(m, eta, alpha, v3s(1.0f));
        m->alpha_v = alpha_v;
        m->map_alpha = ta;
    } else if (strcmp(type, "thindielectric") == 0) {
        if ((st = get_eta(p, "eta", 1.5f, &eta))) return st;
        material_thin_dielectric(m, eta, v3s(1.0f));
    } else if (strcmp(type, "diffusetransmission") == 0) {
        vec3 tr = v3s(0.25f);
        float sc = 1.0f;
        kd = v3s(0.25f);
        tex_ref ttr;
        tex_ref_init(&ttr);
        if ((st = get_colour(p, "reflectance", &kd, &tkd, NULL)) ||
            (st = get_colour(p, "transmittance", &tr, &ttr, NULL)) || (st = pb_float(&p->pd, "scale", &sc)))
            return st;
        /* pbrt-v4 clamps scale * reflectance and scale * transmittance to 0..1 */
        const vec3 r = v3_scale(kd, sc), t = v3_scale(tr, sc);
        material_diffuse_transmission(m, v3_min(v3_max(r, v3s(0.0f)), v3s(1.0f)), v3_min(v3_max(t, v3s(0.0f)), v3s(1.0f)));
        m->map_kd = tkd;
        m->map_tf = ttr;
    } else if (strcmp(type, "mix") == 0) {
        pparam *q;
        if ((st = pb_typed(&p->pd, "materials", TB(PT_STRING), "two material names", &q))) return st;
        if (!q || q->nstr != 2) return pfail(p, p->line, PK_ERR_PARSE, "mix needs 'string materials' with two names");
        int64_t idx[2];
        for (int k = 0; k < 2; k++) {
            idx[k] = scene_find_material(p->s, q->str[k]);
            if (idx[k] < 0) return pfail(p, q->line, PK_ERR_PARSE, "mix: no material named \"%.60s\"", q->str[k]);
            if (scene_mix_depth(p->s, (uint32_t)idx[k]) >= MATERIAL_MIX_DEPTH)
                return pfail(p, q->line, PK_ERR_PARSE, "mix: mixes nested more than %d deep", MATERIAL_MIX_DEPTH);
        }
        /* amount: a float or a float texture (the probability of the second) */
        float amount = 0.5f;
        tex_ref tam;
        tex_ref_init(&tam);
        pparam *qa;
        if ((st = pb_typed(&p->pd, "amount", TB(PT_FLOAT) | TB(PT_TEXTURE), "a float or a float texture", &qa)))
            return st;
        if (qa && qa->type == PT_FLOAT) {
            if (qa->nnum != 1) return pfail(p, qa->line, PK_ERR_PARSE, "'float amount' takes one value, not %zu", qa->nnum);
            amount = (float)qa->num[0];
        } else if (qa) {
            if (qa->nstr != 1) return pfail(p, qa->line, PK_ERR_PARSE, "'texture amount' takes one name");
            named_tex *t = find_tex(p, qa->str[0]);
            if (!t) return pfail(p, qa->line, PK_ERR_PARSE, "'texture amount': no texture named \"%.60s\"", qa->str[0]);
            amount = t->value.x; /* a constant, or the factor on an image's values */
            if (t->cls == TC_EXPR) { /* a procedural texture: its values themselves */
                if ((st = tex_add_expr(p, t, &tam))) return st;
                amount = 1.0f;
            } else if (t->cls != TC_CONST) {
                tam = t->ref;
            }
        }
        material_mix(m, (int)idx[0], (int)idx[1], amount);
        m->map_alpha = tam;
        (void)depth;
    } else if (strcmp(type, "interface") == 0 || strcmp(type, "") == 0 || strcmp(type, "none") == 0) {
        material_interface(m);
        *interface = true;
    } else if (strcmp(type, "measured") == 0 || strcmp(type, "hair") == 0 || strcmp(type, "subsurface") == 0) {
        pd_mark_all(&p->pd);
        pwarn(p, p->line, "material \"%s\" is not supported; rendered as diffuse grey 0.5", type);
        material_diffuse(m, v3s(0.5f));
    } else {
        return pfail(p, p->line, PK_ERR_PARSE, "unknown material type \"%.40s\"", type);
    }
    /* shared parameters */
    pparam *q;
    if ((st = pb_typed(&p->pd, "normalmap", TB(PT_STRING), "a file name", &q))) return st;
    if (q && q->nstr == 1) {
        int32_t idx;
        char why[PK_ERRMSG_MAX];
        if ((st = load_image(p, q->str[0], false, &idx, why, sizeof why))) return st;
        if (idx < 0) {
            pwarn(p, q->line, "normal map not used (%s)", why);
        } else {
            tex_ref_init(&m->map_norm);
            m->map_norm.kind = TEX_IMAGE;
            m->map_norm.tex = idx;
        }
    }
    /* displacement: pbrt bump-maps with it (heights along the normal, in
     * scene units): the material's bump map. A constant moves the surface
     * without tilting it, so it changes nothing. */
    if ((st = pb_typed(&p->pd, "displacement", TB(PT_FLOAT) | TB(PT_TEXTURE), "a float or a float texture", &q)))
        return st;
    if (q && q->type == PT_TEXTURE) {
        if (q->nstr != 1) return pfail(p, q->line, PK_ERR_PARSE, "'texture displacement' takes one name");
        named_tex *t = find_tex(p, q->str[0]);
        if (!t) return pfail(p, q->line, PK_ERR_PARSE, "'texture displacement': no texture named \"%.60s\"", q->str[0]);
        tex_ref r;
        tex_ref_init(&r);
        if (t->cls == TC_EXPR) {
            if ((st = tex_add_expr(p, t, &r))) return st;
            r.bm = 1.0f;
        } else if (t->cls != TC_CONST) {
            r = t->ref;
            r.bm = t->value.x; /* the factor on the image's values */
        }
        if (r.kind != TEX_NONE && m->map_norm.kind != TEX_NONE)
            pwarn(p, q->line, "'displacement' with a normal map: the normal map is used, as pbrt does");
        else if (r.kind != TEX_NONE)
            m->map_bump = r;
    }
    return PK_OK;
}

/* A material from a Material or MakeNamedMaterial directive. */
static pk_status new_material(pp *p, const char *name, const char *type, uint32_t *out)
{
    uint32_t idx;
    pk_status st = scene_add_material(p->ctx, p->s, name, &idx);
    if (st) return st;
    material *m = &p->s->materials[idx];
    m->two_sided = false;
    bool iface;
    if ((st = build_material(p, type, m, &iface, 0))) return st;
    if ((st = set_interface(p, idx, iface))) return st;
    *out = idx;
    return PK_OK;
}

/* The material a shape gets: the current one with the current area light's
 * emission and an alpha map, made once per combination. */
static pk_status shape_material(pp *p, vec3 ke, int32_t ke_tex, bool two_sided, int32_t alpha_tex, uint32_t *out)
{
    uint32_t base = GS(p)->material;
    if (ke.x == 0.0f && ke.y == 0.0f && ke.z == 0.0f && alpha_tex < 0) {
        *out = base;
        return PK_OK;
    }
    for (size_t i = 0; i < p->nvars; i++) {
        const mat_variant *v = &p->vars[i];
        if (v->base == base && v->ke.x == ke.x && v->ke.y == ke.y && v->ke.z == ke.z && v->two_sided == two_sided &&
            v->alpha_tex == alpha_tex && v->ke_tex == ke_tex) {
            *out = v->mat;
            return PK_OK;
        }
    }
    if (!mem_grow(A(p), (void **)&p->vars, &p->cap_vars, p->nvars + 1, sizeof *p->vars)) return ctx_nomem(p->ctx);
    char name[PB_NAME_MAX + 16];
    snprintf(name, sizeof name, "%.*s+%zu", PB_NAME_MAX, p->s->materials[base].name ? p->s->materials[base].name : "",
             p->nvars);
    uint32_t idx;
    pk_status st = scene_material_with_emission(p->ctx, p->s, base, name, ke, two_sided, &idx);
    if (st) return st;
    if (alpha_tex >= 0) {
        named_tex *at = &p->tex[alpha_tex];
        tex_ref r = at->ref;
        if (at->cls == TC_EXPR) {
            if ((st = tex_add_expr(p, at, &r))) return st;
        }
        p->s->materials[idx].map_d = r;
    }
    if (ke_tex >= 0 && v3_max_comp(ke) > 0.0f) {
        tex_ref *r = &p->s->materials[idx].map_ke;
        tex_ref_init(r);
        r->kind = TEX_IMAGE;
        r->tex = ke_tex;
        r->clamp = TEX_CLAMP;
    }
    mat_variant v = {base, ke, two_sided, alpha_tex, ke_tex, idx};
    p->vars[p->nvars++] = v;
    *out = idx;
    return PK_OK;
}

/* ---- shapes ------------------------------------------------------------------------------------- */

typedef struct mesh_in {
    vec3 *pos;
    vec3 *nrm;        /* NULL: none */
    float *uv;        /* NULL: none */
    size_t npos;
    uint32_t *tris;   /* 3 per triangle; reordered here */
    size_t ntris;
} mesh_in;

/* A builder call's failure, latched again with where it happened. */
static pk_status builder_status(pp *p, pk_status st, const pk_context *tmp)
{
    if (st == PK_OK) return PK_OK;
    if (st == PK_ERR_NOMEM) return ctx_nomem(p->ctx);
    return pfail(p, p->line, st, "%s", tmp->message);
}

/* ---- where media are ------------------------------------------------------------------------ */

/* The number of a name MediumInterface used (*idx; -1 for "", vacuum). */
static pk_status medium_name_index(pp *p, const char *name, int32_t *idx)
{
    *idx = -1;
    if (!name[0]) return PK_OK;
    for (size_t i = 0; i < p->nmnames; i++)
        if (strcmp(p->mnames[i], name) == 0) {
            *idx = (int32_t)i;
            return PK_OK;
        }
    if (p->nmnames >= INT32_MAX) return pfail(p, p->line, PK_ERR_LIMIT, "too many medium names");
    if (!mem_grow(A(p), (void **)&p->mnames, &p->cap_mnames, p->nmnames + 1, sizeof *p->mnames)) return ctx_nomem(p->ctx);
    char *c = mem_strdup(A(p), name);
    if (!c) return ctx_nomem(p->ctx);
    p->mnames[p->nmnames] = c;
    *idx = (int32_t)p->nmnames++;
    return PK_OK;
}

/* The scene's medium of name number idx (MEDIUM_NONE for -1); what: the
 * directive, for the message at line. */
static pk_status medium_resolve(pp *p, int32_t idx, size_t line, const char *what, int32_t *out)
{
    *out = MEDIUM_NONE;
    if (idx < 0) return PK_OK;
    int64_t m = scene_find_medium(p->s, p->mnames[idx]);
    if (m < 0)
        return pfail(p, line, PK_ERR_PARSE,
                     "%s: MediumInterface names no medium \"%.80s\" (MakeNamedMedium must define it before the "
                     "shapes and the camera that use it)",
                     what, p->mnames[idx]);
    *out = (int32_t)m;
    return PK_OK;
}

/* Whether the current MediumInterface changes the medium (pbrt's rule: a
 * shape whose inside and outside are the same keeps the ray's medium). */
static bool medium_transition(pp *p) { return GS(p)->mi_in != GS(p)->mi_out; }

/* *mat with the current MediumInterface on its sides (pbrt's outside is the
 * side the surface normal points to: Paprsek's exterior); unchanged (media
 * inherited) when the interface is no transition. */
static pk_status shape_media(pp *p, uint32_t *mat)
{
    if (!medium_transition(p)) return PK_OK;
    int32_t in, out;
    pk_status st;
    char what[64];
    snprintf(what, sizeof what, "%.40s", p->dname ? p->dname : "Shape");
    if ((st = medium_resolve(p, GS(p)->mi_in, p->line, what, &in)) ||
        (st = medium_resolve(p, GS(p)->mi_out, p->line, what, &out)))
        return st;
    return scene_material_with_media(p->ctx, p->s, *mat, in, out, mat);
}

/* World area of the mesh (for an area light's power). */
static double mesh_area(const xform *x, const mesh_in *m)
{
    double a = 0.0;
    for (size_t t = 0; t < m->ntris; t++) {
        vec3 p0 = xform_point(x, m->pos[m->tris[3 * t]]), p1 = xform_point(x, m->pos[m->tris[3 * t + 1]]),
             p2 = xform_point(x, m->pos[m->tris[3 * t + 2]]);
        a += 0.5 * (double)v3_len(v3_cross(v3_sub(p1, p0), v3_sub(p2, p0)));
    }
    return a;
}

/* Emission of the current area light on a shape of world area area, and
 * its emission map (*image, -1 none). With "power", pbrt-v4 divides by the
 * image's mean luminance too. */
static vec3 area_emission(pp *p, double area, bool *two_sided, int32_t *image)
{
    int32_t a = GS(p)->area;
    *two_sided = false;
    *image = -1;
    if (a < 0) return v3s(0.0f);
    const area_light *l = &p->areas[a];
    *two_sided = l->two_sided;
    *image = l->image;
    vec3 L = l->L;
    if (l->power > 0.0f) {
        double k = (l->two_sided ? 2.0 : 1.0) * area * (double)PK_PI;
        if (l->image >= 0) k *= (double)v3_luminance(texture_mean_rgb(&p->s->textures[l->image]));
        if (k > 0.0) L = v3_scale(L, (float)((double)l->power / k));
    }
    return L;
}

/* Adds a mesh in the current space with the current material and area
 * light. Triangles face where pbrt's surface normal points: the shading
 * normals' side when the mesh has them, else the winding's (reversed by
 * ReverseOrientation); the winding is swapped wherever the transform to the
 * world mirrors. alpha_tex: the cut-out texture, -1 none. */
static pk_status add_mesh_uv(pp *p, mesh_in *m, int32_t alpha_tex);
static pk_status mesh_alloc(pp *p, mesh_in *m, size_t npos, size_t ntris, bool nrm, bool uv);
static void mesh_free(pp *p, mesh_in *m);

/* Whether the shape's material (or its alpha texture) reads texture
 * coordinates: then meshes without them get pbrt's defaults. */
static bool needs_uv(pp *p, int32_t alpha_tex)
{
    const material *m = &p->s->materials[GS(p)->material];
    return alpha_tex >= 0 || m->map_kd.kind || m->map_ks.kind || m->map_ns.kind || m->map_d.kind ||
           m->map_alpha.kind || m->map_bump.kind || m->map_norm.kind || m->map_mr.kind || m->map_eta.kind ||
           m->map_k.kind || m->map_tf.kind || material_anisotropic(m); /* the roughness follows pbrt's dp/du */
}

/* A copy of m in which every face (per_face corners of faces[]) has
 * vertices of its own with the texture coordinates cuv[corner] (pbrt's
 * defaults for a shape without uv); faces[] is renumbered to them. */
static pk_status unshare_uv(pp *p, const mesh_in *m, uint32_t *faces, size_t nfaces, size_t per_face,
                            const float (*cuv)[2], mesh_in *out)
{
    memset(out, 0, sizeof *out);
    if (nfaces > (size_t)(UINT32_MAX / 2) / per_face) return pfail(p, p->line, PK_ERR_LIMIT, "too many vertices");
    const size_t n = nfaces * per_face;
    pk_status st = mesh_alloc(p, out, n, 0, m->nrm != NULL, true);
    if (st) return st;
    for (size_t i = 0; i < n; i++) {
        const uint32_t v = faces[i];
        out->pos[i] = m->pos[v];
        if (m->nrm) out->nrm[i] = m->nrm[v];
        out->uv[2 * i] = cuv[i % per_face][0], out->uv[2 * i + 1] = cuv[i % per_face][1];
        faces[i] = (uint32_t)i;
    }
    return PK_OK;
}

static pk_status add_mesh(pp *p, mesh_in *m, int32_t alpha_tex)
{
    if (m->uv || !needs_uv(p, alpha_tex)) return add_mesh_uv(p, m, alpha_tex);
    /* pbrt's triangles without uv: (0,0), (1,0), (1,1) at their corners */
    static const float tri_uv[3][2] = {{0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}};
    uint32_t *faces = mem_realloc_array(A(p), NULL, m->ntris ? 3 * m->ntris : 1, sizeof *faces);
    if (!faces) return ctx_nomem(p->ctx);
    memcpy(faces, m->tris, 3 * m->ntris * sizeof *faces);
    mesh_in un;
    pk_status st = unshare_uv(p, m, faces, m->ntris, 3, tri_uv, &un);
    if (st == PK_OK) {
        mem_free(A(p), un.tris);
        un.tris = faces, un.ntris = m->ntris;
        faces = NULL;
        st = add_mesh_uv(p, &un, alpha_tex);
        mesh_free(p, &un);
    }
    mem_free(A(p), faces);
    return st;
}

static pk_status add_mesh_uv(pp *p, mesh_in *m, int32_t alpha_tex)
{
    /* an interface that bounds no media changes nothing: left out */
    if (GS(p)->interface && !medium_transition(p)) return PK_OK;
    xform w = world_xf(p);
    const bool mirrored = xform_det3(&w) < 0.0;
    for (size_t t = 0; t < m->ntris; t++) {
        uint32_t *tr = &m->tris[3 * t];
        bool flip;
        if (m->nrm) {
            vec3 a = m->pos[tr[0]], b = m->pos[tr[1]], c = m->pos[tr[2]];
            vec3 ng = v3_cross(v3_sub(b, a), v3_sub(c, a));
            vec3 ns = v3_add(v3_add(m->nrm[tr[0]], m->nrm[tr[1]]), m->nrm[tr[2]]);
            flip = v3_dot(ng, ns) < 0.0f;
        } else {
            flip = GS(p)->reverse;
        }
        if (flip != mirrored) {
            uint32_t sw = tr[1];
            tr[1] = tr[2], tr[2] = sw;
        }
    }
    bool two = false;
    vec3 ke = v3s(0.0f);
    int32_t ke_tex = -1;
    /* interfaces do not emit (as in pbrt) */
    if (GS(p)->area >= 0 && !GS(p)->interface)
        ke = area_emission(p, p->areas[GS(p)->area].power > 0.0f ? mesh_area(&w, m) : 0.0, &two, &ke_tex);
    uint32_t mat;
    pk_status st = shape_material(p, ke, ke_tex, two, alpha_tex, &mat);
    if (st == PK_OK) st = shape_media(p, &mat);
    if (st) return st;
    xform saved = *sb_transform(&p->b);
    sb_set_transform(&p->b, &w);
    uint32_t old = p->b.material;
    sb_set_material(&p->b, mat);
    sb_mesh sm = {m->pos, m->nrm, m->uv, m->npos, m->tris, m->ntris, false};
    pk_context tmp = io_scratch_context(p->ctx);
    p->b.ctx = &tmp;
    st = sb_add_mesh(&p->b, &sm);
    p->b.ctx = p->ctx;
    sb_set_transform(&p->b, &saved);
    sb_set_material(&p->b, old);
    return builder_status(p, st, &tmp);
}

static void mesh_free(pp *p, mesh_in *m)
{
    mem_free(A(p), m->pos);
    mem_free(A(p), m->nrm);
    mem_free(A(p), m->uv);
    mem_free(A(p), m->tris);
    memset(m, 0, sizeof *m);
}

static pk_status mesh_alloc(pp *p, mesh_in *m, size_t npos, size_t ntris, bool nrm, bool uv)
{
    memset(m, 0, sizeof *m);
    m->npos = npos, m->ntris = ntris;
    m->pos = mem_calloc(A(p), npos ? npos : 1, sizeof(vec3));
    m->tris = mem_calloc(A(p), ntris ? ntris : 1, 3 * sizeof(uint32_t));
    if (nrm) m->nrm = mem_calloc(A(p), npos ? npos : 1, sizeof(vec3));
    if (uv) m->uv = mem_calloc(A(p), npos ? npos : 1, 2 * sizeof(float));
    if (!m->pos || !m->tris || (nrm && !m->nrm) || (uv && !m->uv)) {
        mesh_free(p, m);
        return ctx_nomem(p->ctx);
    }
    return PK_OK;
}

/* The shape's "alpha": 1 (opaque: -1), 0 (invisible: *skip), a float
 * image texture (its index). */
static pk_status shape_alpha(pp *p, int32_t *tex, bool *skip)
{
    pparam *q;
    *tex = -1;
    *skip = false;
    pk_status st = pb_typed(&p->pd, "alpha", TB(PT_FLOAT) | TB(PT_TEXTURE), "a float or a float texture", &q);
    if (st || !q) return st;
    if (q->type == PT_FLOAT) {
        if (q->nnum != 1) return pfail(p, q->line, PK_ERR_PARSE, "'float alpha' takes one value");
        if (q->num[0] <= 0.0) *skip = true;
        else if (q->num[0] < 1.0)
            pwarn(p, q->line, "a partly transparent alpha %g is rendered opaque (only textures cut holes)", q->num[0]);
        return PK_OK;
    }
    if (q->nstr != 1) return pfail(p, q->line, PK_ERR_PARSE, "'texture alpha' takes one name");
    named_tex *t = find_tex(p, q->str[0]);
    if (!t) return pfail(p, q->line, PK_ERR_PARSE, "'texture alpha': no texture named \"%.60s\"", q->str[0]);
    if (t->cls == TC_CONST) {
        if (t->value.x <= 0.0f) *skip = true;
        return PK_OK;
    }
    /* images, checkerboards and procedural textures cut holes */
    *tex = (int32_t)(t - p->tex);
    return PK_OK;
}

/* Vertex arrays of a mesh directive: P, N, uv, indices (checked). */
static pk_status read_mesh_params(pp *p, const char *what, size_t per_face, mesh_in *m, uint32_t **faces,
                                  size_t *nfaces)
{
    pparam *P, *N, *UV, *I;
    pk_status st;
    if ((st = pb_typed(&p->pd, "P", TB(PT_POINT3), "point3", &P)) ||
        (st = pb_typed(&p->pd, "N", TB(PT_NORMAL), "normal", &N)) ||
        (st = pb_typed(&p->pd, "uv", TB(PT_POINT2) | TB(PT_FLOAT), "point2", &UV)) ||
        (st = pb_typed(&p->pd, "indices", TB(PT_INT), "integer", &I)))
        return st;
    if (!UV && (st = pb_typed(&p->pd, "st", TB(PT_POINT2) | TB(PT_FLOAT), "point2", &UV))) return st;
    pb_param(&p->pd, "S"), pb_param(&p->pd, "faceIndices");
    if (!P) return pfail(p, p->line, PK_ERR_PARSE, "%s needs 'point3 P'", what);
    size_t npos = P->nnum / 3;
    if (npos > UINT32_MAX / 2) return pfail(p, P->line, PK_ERR_LIMIT, "%s: too many vertices", what);
    if (N && N->nnum != P->nnum)
        return pfail(p, N->line, PK_ERR_PARSE, "%s: 'normal N' has %zu normals for %zu vertices", what, N->nnum / 3, npos);
    if (UV && UV->nnum != 2 * npos)
        return pfail(p, UV->line, PK_ERR_PARSE, "%s: '%s %s' has %zu values for %zu vertices (2 each)", what, UV->tname,
                     UV->name, UV->nnum, npos);
    size_t nidx;
    if (I) {
        nidx = I->nnum;
        if (nidx % per_face)
            return pfail(p, I->line, PK_ERR_PARSE, "%s: 'integer indices' has %zu values, not a multiple of %zu", what,
                         nidx, per_face);
    } else {
        if (npos != per_face)
            return pfail(p, p->line, PK_ERR_PARSE, "%s without 'integer indices' must have exactly %zu vertices, not %zu",
                         what, per_face, npos);
        nidx = per_face;
    }
    *nfaces = nidx / per_face;
    if ((st = mesh_alloc(p, m, npos, 0, N != NULL, UV != NULL))) return st;
    mem_free(A(p), m->tris);
    m->tris = NULL;
    *faces = mem_calloc(A(p), nidx ? nidx : 1, sizeof(uint32_t));
    if (!*faces) {
        mesh_free(p, m);
        return ctx_nomem(p->ctx);
    }
    for (size_t i = 0; i < nidx; i++) {
        double v = I ? I->num[i] : (double)i;
        if (v < 0.0 || v >= (double)npos) {
            mesh_free(p, m);
            mem_free(A(p), *faces);
            *faces = NULL;
            return pfail(p, I->line, PK_ERR_PARSE, "%s: index %.0f (number %zu) is out of range (%zu vertices)", what, v, i,
                         npos);
        }
        (*faces)[i] = (uint32_t)v;
    }
    for (size_t i = 0; i < npos; i++) {
        m->pos[i] = v3((float)P->num[3 * i], (float)P->num[3 * i + 1], (float)P->num[3 * i + 2]);
        if (N) m->nrm[i] = v3((float)N->num[3 * i], (float)N->num[3 * i + 1], (float)N->num[3 * i + 2]);
        if (UV) m->uv[2 * i] = (float)UV->num[2 * i], m->uv[2 * i + 1] = (float)UV->num[2 * i + 1];
    }
    for (size_t i = 0; i < npos; i++)
        if (!v3_finite(m->pos[i])) {
            mesh_free(p, m);
            mem_free(A(p), *faces);
            *faces = NULL;
            return pfail(p, P->line, PK_ERR_PARSE, "%s: vertex %zu is not finite in float", what, i);
        }
    return PK_OK;
}

static pk_status shape_trianglemesh(pp *p, int32_t alpha)
{
    mesh_in m;
    uint32_t *f;
    size_t nf;
    pk_status st = read_mesh_params(p, "trianglemesh", 3, &m, &f, &nf);
    if (st) return st;
    m.tris = f, m.ntris = nf;
    st = add_mesh(p, &m, alpha);
    mesh_free(p, &m);
    return st;
}

/* Whether patch q's uv are not an affine function of its parameters
 * (u00 + u11 != u10 + u01): pbrt interpolates them bilinearly, which two
 * triangles cannot. */
static bool patch_twisted(const mesh_in *m, const uint32_t *q)
{
    for (int c = 0; c < 2; c++) {
        const float a = m->uv[2 * q[0] + c], b = m->uv[2 * q[1] + c], d = m->uv[2 * q[2] + c], e = m->uv[2 * q[3] + c];
        if (fabsf(a + e - b - d) > 1e-6f * (1.0f + fabsf(a) + fabsf(b) + fabsf(d) + fabsf(e))) return true;
    }
    return false;
}

/* The patches of m with twisted uv as grids of g x g cells (positions,
 * normals and uv interpolated bilinearly, as pbrt evaluates the patch),
 * the others as two triangles; into *out. */
static pk_status patches_as_grids(pp *p, const mesh_in *m, const uint32_t *f, size_t nf, size_t ntw, mesh_in *out)
{
    const size_t g = ntw <= 64 ? 64 : ntw <= 1024 ? 16 : 4;
    const size_t gv = (g + 1) * (g + 1);
    if (ntw > (UINT32_MAX / 2 - m->npos) / gv || nf > SIZE_MAX / 4 / (2 * g * g))
        return pfail(p, p->line, PK_ERR_LIMIT, "bilinearmesh: too many patches with twisted texture coordinates");
    pk_status st = mesh_alloc(p, out, m->npos + ntw * gv, 2 * (nf - ntw) + ntw * 2 * g * g, m->nrm != NULL, true);
    if (st) return st;
    memcpy(out->pos, m->pos, m->npos * sizeof *m->pos);
    if (m->nrm) memcpy(out->nrm, m->nrm, m->npos * sizeof *m->nrm);
    memcpy(out->uv, m->uv, 2 * m->npos * sizeof *m->uv);
    size_t nv = m->npos, nt = 0;
    for (size_t i = 0; i < nf; i++) {
        const uint32_t *q = &f[4 * i];
        if (!patch_twisted(m, q)) {
            const uint32_t a[6] = {q[0], q[1], q[3], q[0], q[3], q[2]};
            memcpy(&out->tris[3 * nt], a, sizeof a);
            nt += 2;
            continue;
        }
        const size_t base = nv;
        for (size_t j = 0; j <= g; j++)
            for (size_t k = 0; k <= g; k++) {
                const float s = (float)k / (float)g, t = (float)j / (float)g;
                const float w[4] = {(1.0f - s) * (1.0f - t), s * (1.0f - t), (1.0f - s) * t, s * t};
                vec3 P = v3s(0.0f), N = v3s(0.0f);
                float u = 0.0f, v = 0.0f;
                for (int c = 0; c < 4; c++) {
                    P = v3_add(P, v3_scale(m->pos[q[c]], w[c]));
                    if (m->nrm) N = v3_add(N, v3_scale(m->nrm[q[c]], w[c]));
                    u += w[c] * m->uv[2 * q[c]], v += w[c] * m->uv[2 * q[c] + 1];
                }
                out->pos[nv] = P;
                if (m->nrm) out->nrm[nv] = N;
                out->uv[2 * nv] = u, out->uv[2 * nv + 1] = v;
                nv++;
            }
        for (size_t j = 0; j < g; j++)
            for (size_t k = 0; k < g; k++) {
                const uint32_t c00 = (uint32_t)(base + j * (g + 1) + k), c10 = c00 + 1, c01 = c00 + (uint32_t)(g + 1),
                               c11 = c01 + 1;
                const uint32_t a[6] = {c00, c10, c11, c00, c11, c01};
                memcpy(&out->tris[3 * nt], a, sizeof a);
                nt += 2;
            }
    }
    out->ntris = nt;
    return PK_OK;
}

/* Bilinear patches (p00 p10 p01 p11) as two triangles each (textured
 * patches with twisted uv as grids). */
static pk_status shape_bilinear(pp *p, int32_t alpha)
{
    mesh_in m;
    uint32_t *f;
    size_t nf;
    pk_status st = read_mesh_params(p, "bilinearmesh", 4, &m, &f, &nf);
    if (st) return st;
    if (!m.uv && needs_uv(p, alpha)) {
        /* pbrt's patches without uv: (0,0), (1,0), (0,1), (1,1) at p00 p10 p01 p11 */
        static const float quad_uv[4][2] = {{0.0f, 0.0f}, {1.0f, 0.0f}, {0.0f, 1.0f}, {1.0f, 1.0f}};
        mesh_in un;
        if ((st = unshare_uv(p, &m, f, nf, 4, quad_uv, &un))) {
            mem_free(A(p), f);
            mesh_free(p, &m);
            return st;
        }
        mesh_free(p, &m);
        m = un;
    }
    if (m.uv && needs_uv(p, alpha)) {
        size_t ntw = 0;
        for (size_t i = 0; i < nf; i++) ntw += patch_twisted(&m, &f[4 * i]);
        if (ntw) {
            mesh_in gm;
            st = patches_as_grids(p, &m, f, nf, ntw, &gm);
            mem_free(A(p), f);
            mesh_free(p, &m);
            if (st) return st;
            st = add_mesh(p, &gm, alpha);
            mesh_free(p, &gm);
            return st;
        }
    }
    uint32_t *t = mem_calloc(A(p), nf ? 2 * nf : 1, 3 * sizeof(uint32_t));
    if (!t) {
        mem_free(A(p), f);
        mesh_free(p, &m);
        return ctx_nomem(p->ctx);
    }
    for (size_t i = 0; i < nf; i++) {
        const uint32_t *q = &f[4 * i];
        uint32_t a[6] = {q[0], q[1], q[3], q[0], q[3], q[2]};
        memcpy(&t[6 * i], a, sizeof a);
    }
    mem_free(A(p), f);
    mem_free(A(p), m.tris);
    m.tris = t, m.ntris = 2 * nf;
    st = add_mesh(p, &m, alpha);
    mesh_free(p, &m);
    return st;
}

/* ---- Loop subdivision ---- */

typedef struct edge_rec {
    uint32_t a, b;       /* a < b */
    uint32_t opp[2];     /* the vertices opposite the edge in its faces */
    int nfaces;
    uint32_t mid;        /* the new vertex */
} edge_rec;

typedef struct edge_map {
    edge_rec *e;
    size_t n, slots;     /* slots a power of two; index 0 means empty (stored index + 1) */
    uint32_t *idx;
} edge_map;

static uint64_t edge_hash(uint32_t a, uint32_t b)
{
    uint64_t h = ((uint64_t)a << 32) | b;
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
    return h;
}

/* The edge (a, b), added when absent; NULL when out of memory. */
static edge_rec *edge_get(edge_map *em, uint32_t a, uint32_t b)
{
    if (a > b) {
        uint32_t t = a;
        a = b, b = t;
    }
    size_t mask = em->slots - 1, i = (size_t)edge_hash(a, b) & mask;
    while (em->idx[i]) {
        edge_rec *r = &em->e[em->idx[i] - 1];
        if (r->a == a && r->b == b) return r;
        i = (i + 1) & mask;
    }
    edge_rec *r = &em->e[em->n];
    memset(r, 0, sizeof *r);
    r->a = a, r->b = b;
    em->idx[i] = (uint32_t)(++em->n);
    return r;
}

/* One level of Loop subdivision of (pos, npos, tris, ntris) into new
 * arrays; boundary edges and vertices follow the boundary rules (the
 * boundary curve is a cubic B-spline of its own). */
static pk_status loop_level(pp *p, size_t line, vec3 **pos, size_t *npos, uint32_t **tris, size_t *ntris)
{
    const size_t nv = *npos, nt = *ntris, ne_max = 3 * nt;
    const vec3 *P = *pos;
    const uint32_t *T = *tris;
    edge_map em = {0};
    em.slots = 16;
    while (em.slots < 2 * ne_max + 2) em.slots *= 2;
    em.e = mem_calloc(A(p), ne_max ? ne_max : 1, sizeof *em.e);
    em.idx = mem_calloc(A(p), em.slots, sizeof *em.idx);
    uint32_t *valence = mem_calloc(A(p), nv ? nv : 1, sizeof *valence);
    vec3 *ring = mem_calloc(A(p), nv ? nv : 1, sizeof *ring);      /* sum of neighbours */
    vec3 *bsum = mem_calloc(A(p), nv ? nv : 1, sizeof *bsum);      /* sum of boundary neighbours */
    uint8_t *bnd = mem_calloc(A(p), nv ? nv : 1, 1);
    vec3 *np = NULL;
    uint32_t *ntr = NULL;
    pk_status st = PK_OK;
    if (!em.e || !em.idx || !valence || !ring || !bsum || !bnd) {
        st = ctx_nomem(p->ctx);
        goto done;
    }
    for (size_t t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = T[3 * t + k], b = T[3 * t + (k + 1) % 3], c = T[3 * t + (k + 2) % 3];
            edge_rec *r = edge_get(&em, a, b);
            if (r->nfaces == 2) {
                st = pfail(p, line, PK_ERR_PARSE,
                           "loopsubdiv: the edge %u-%u is shared by more than two triangles (not a manifold)", a, b);
                goto done;
            }
            r->opp[r->nfaces++] = c;
        }
    for (size_t i = 0; i < em.n; i++) {
        edge_rec *r = &em.e[i];
        valence[r->a]++, valence[r->b]++;
        ring[r->a] = v3_add(ring[r->a], P[r->b]);
        ring[r->b] = v3_add(ring[r->b], P[r->a]);
        if (r->nfaces == 1) {
            bnd[r->a] = bnd[r->b] = 1;
            bsum[r->a] = v3_add(bsum[r->a], P[r->b]);
            bsum[r->b] = v3_add(bsum[r->b], P[r->a]);
        }
    }
    size_t nnew = nv + em.n;
    if (nnew > UINT32_MAX / 2 || 4 * nt > UINT32_MAX / 4) {
        st = pfail(p, line, PK_ERR_LIMIT, "loopsubdiv: too many vertices");
        goto done;
    }
    np = mem_calloc(A(p), nnew ? nnew : 1, sizeof *np);
    ntr = mem_calloc(A(p), nt ? 4 * nt : 1, 3 * sizeof *ntr);
    if (!np || !ntr) {
        st = ctx_nomem(p->ctx);
        goto done;
    }
    /* even vertices */
    for (size_t v = 0; v < nv; v++) {
        uint32_t n = valence[v];
        if (n == 0) {
            np[v] = P[v];
        } else if (bnd[v]) {
            np[v] = v3_add(v3_scale(P[v], 0.75f), v3_scale(bsum[v], 0.125f));
        } else {
            float beta = n == 3 ? 3.0f / 16.0f : 3.0f / (8.0f * (float)n);
            np[v] = v3_add(v3_scale(P[v], 1.0f - (float)n * beta), v3_scale(ring[v], beta));
        }
    }
    /* odd vertices */
    for (size_t i = 0; i < em.n; i++) {
        edge_rec *r = &em.e[i];
        r->mid = (uint32_t)(nv + i);
        vec3 e = v3_add(P[r->a], P[r->b]);
        if (r->nfaces == 2)
            np[r->mid] = v3_add(v3_scale(e, 0.375f), v3_scale(v3_add(P[r->opp[0]], P[r->opp[1]]), 0.125f));
        else
            np[r->mid] = v3_scale(e, 0.5f);
    }
    for (size_t t = 0; t < nt; t++) {
        uint32_t a = T[3 * t], b = T[3 * t + 1], c = T[3 * t + 2];
        uint32_t ab = edge_get(&em, a, b)->mid, bc = edge_get(&em, b, c)->mid, ca = edge_get(&em, c, a)->mid;
        uint32_t q[12] = {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca};
        memcpy(&ntr[12 * t], q, sizeof q);
    }
    mem_free(A(p), *pos);
    mem_free(A(p), *tris);
    *pos = np, *npos = nnew, *tris = ntr, *ntris = 4 * nt;
    np = NULL, ntr = NULL;
done:
    mem_free(A(p), em.e);
    mem_free(A(p), em.idx);
    mem_free(A(p), valence);
    mem_free(A(p), ring);
    mem_free(A(p), bsum);
    mem_free(A(p), bnd);
    mem_free(A(p), np);
    mem_free(A(p), ntr);
    return st;
}

/* Moves the vertices to their limit positions (Loop's limit masks:
 * interior 1 - n g and g = 1 / (n + 3 / (8 beta)) each neighbour; boundary
 * 3/5 and 1/5 each boundary neighbour), and gives area-weighted normals. */
static pk_status loop_limit(pp *p, vec3 *pos, size_t npos, const uint32_t *tris, size_t ntris, vec3 *nrm)
{
    uint32_t *valence = mem_calloc(A(p), npos ? npos : 1, sizeof *valence);
    vec3 *ring = mem_calloc(A(p), npos ? npos : 1, sizeof *ring);
    vec3 *bsum = mem_calloc(A(p), npos ? npos : 1, sizeof *bsum);
    uint8_t *bnd = mem_calloc(A(p), npos ? npos : 1, 1);
    edge_map em = {0};
    em.slots = 16;
    while (em.slots < 6 * ntris + 2) em.slots *= 2;
    em.e = mem_calloc(A(p), ntris ? 3 * ntris : 1, sizeof *em.e);
    em.idx = mem_calloc(A(p), em.slots, sizeof *em.idx);
    pk_status st = PK_OK;
    if (!valence || !ring || !bsum || !bnd || !em.e || !em.idx) {
        st = ctx_nomem(p->ctx);
        goto done;
    }
    for (size_t t = 0; t < ntris; t++)
        for (int k = 0; k < 3; k++) {
            edge_rec *r = edge_get(&em, tris[3 * t + k], tris[3 * t + (k + 1) % 3]);
            r->nfaces++;
        }
    for (size_t i = 0; i < em.n; i++) {
        edge_rec *r = &em.e[i];
        valence[r->a]++, valence[r->b]++;
        ring[r->a] = v3_add(ring[r->a], pos[r->b]);
        ring[r->b] = v3_add(ring[r->b], pos[r->a]);
        if (r->nfaces == 1) {
            bnd[r->a] = bnd[r->b] = 1;
            bsum[r->a] = v3_add(bsum[r->a], pos[r->b]);
            bsum[r->b] = v3_add(bsum[r->b], pos[r->a]);
        }
    }
    for (size_t v = 0; v < npos; v++) {
        uint32_t n = valence[v];
        if (n == 0) continue;
        if (bnd[v]) {
            pos[v] = v3_add(v3_scale(pos[v], 0.6f), v3_scale(bsum[v], 0.2f));
        } else {
            float beta = n == 3 ? 3.0f / 16.0f : 3.0f / (8.0f * (float)n);
            float g = 1.0f / ((float)n + 3.0f / (8.0f * beta));
            pos[v] = v3_add(v3_scale(pos[v], 1.0f - (float)n * g), v3_scale(ring[v], g));
        }
    }
    for (size_t v = 0; v < npos; v++) nrm[v] = v3s(0.0f);
    for (size_t t = 0; t < ntris; t++) {
        const uint32_t *q = &tris[3 * t];
        vec3 ng = v3_cross(v3_sub(pos[q[1]], pos[q[0]]), v3_sub(pos[q[2]], pos[q[0]]));
        for (int k = 0; k < 3; k++) nrm[q[k]] = v3_add(nrm[q[k]], ng);
    }
    for (size_t v = 0; v < npos; v++) nrm[v] = v3_norm_scaled(nrm[v]);
done:
    mem_free(A(p), valence);
    mem_free(A(p), ring);
    mem_free(A(p), bsum);
    mem_free(A(p), bnd);
    mem_free(A(p), em.e);
    mem_free(A(p), em.idx);
    return st;
}

static pk_status shape_loopsubdiv(pp *p, int32_t alpha)
{
    int64_t levels = 3;
    pk_status st = pb_int(&p->pd, "levels", 0, 16, &levels);
    if (st) return st;
    mesh_in m;
    uint32_t *f;
    size_t nf;
    if ((st = read_mesh_params(p, "loopsubdiv", 3, &m, &f, &nf))) return st;
    mem_free(A(p), m.nrm), m.nrm = NULL;
    if (m.uv) {
        pwarn(p, p->line, "loopsubdiv: texture coordinates are not subdivided; dropped");
        mem_free(A(p), m.uv), m.uv = NULL;
    }
    mem_free(A(p), m.tris);
    m.tris = f, m.ntris = nf;
    for (size_t t = 0; t < nf; t++)
        if (f[3 * t] == f[3 * t + 1] || f[3 * t + 1] == f[3 * t + 2] || f[3 * t] == f[3 * t + 2]) {
            mesh_free(p, &m);
            return pfail(p, p->line, PK_ERR_PARSE, "loopsubdiv: triangle %zu repeats a vertex", t);
        }
    double grow = (double)nf;
    for (int64_t l = 0; l < levels; l++) grow *= 4.0;
    if (grow > (double)PB_MAX_SUBDIV_TRIS) {
        mesh_free(p, &m);
        return pfail(p, p->line, PK_ERR_LIMIT, "loopsubdiv: %lld levels of %zu triangles make more than %u triangles",
                     (long long)levels, nf, (unsigned)PB_MAX_SUBDIV_TRIS);
    }
    for (int64_t l = 0; l < levels && st == PK_OK; l++) st = loop_level(p, p->line, &m.pos, &m.npos, &m.tris, &m.ntris);
    if (st == PK_OK) {
        m.nrm = mem_calloc(A(p), m.npos ? m.npos : 1, sizeof(vec3));
        if (!m.nrm) st = ctx_nomem(p->ctx);
    }
    if (st == PK_OK) st = loop_limit(p, m.pos, m.npos, m.tris, m.ntris, m.nrm);
    if (st == PK_OK) {
        /* the limit normals follow the winding; pbrt's side is the winding's */
        if (GS(p)->reverse)
            for (size_t v = 0; v < m.npos; v++) m.nrm[v] = v3_neg(m.nrm[v]);
        st = add_mesh(p, &m, alpha);
    }
    mesh_free(p, &m);
    return st;
}

/* A surface of revolution about z as a grid: nu steps of phi in
 * [0, phimax], nv rows given by f(row) -> (radius, z) and the normal. */
typedef void (*rev_fn)(const void *user, float t, float *r, float *z, float *nr, float *nz);

static pk_status add_revolution(pp *p, int nu, int nv, float phimax, rev_fn fn, const void *user, int32_t alpha)
{
    mesh_in m;
    size_t npos = (size_t)(nu + 1) * (size_t)(nv + 1);
    pk_status st = mesh_alloc(p, &m, npos, (size_t)nu * (size_t)nv * 2, true, true);
    if (st) return st;
    for (int j = 0; j <= nv; j++) {
        float t = (float)j / (float)nv, r, z, nr, nz;
        fn(user, t, &r, &z, &nr, &nz);
        for (int i = 0; i <= nu; i++) {
            float u = (float)i / (float)nu, phi = u * phimax;
            size_t k = (size_t)j * (size_t)(nu + 1) + (size_t)i;
            m.pos[k] = v3(r * cosf(phi), r * sinf(phi), z);
            m.nrm[k] = v3(nr * cosf(phi), nr * sinf(phi), nz);
            m.uv[2 * k] = u, m.uv[2 * k + 1] = t;
        }
    }
    /* a row of radius 0 (a pole, a disk's centre) is one point: the
     * triangles that would have two corners there are left out */
    size_t o = 0;
    for (int j = 0; j < nv; j++) {
        const bool lo0 = v3_len2(v3_sub(m.pos[(size_t)j * (size_t)(nu + 1)], m.pos[(size_t)j * (size_t)(nu + 1) + 1])) == 0.0f;
        const bool hi0 = v3_len2(v3_sub(m.pos[(size_t)(j + 1) * (size_t)(nu + 1)],
                                        m.pos[(size_t)(j + 1) * (size_t)(nu + 1) + 1])) == 0.0f;
        for (int i = 0; i < nu; i++) {
            uint32_t a = (uint32_t)(j * (nu + 1) + i), b = a + 1, c = a + (uint32_t)(nu + 1), d = c + 1;
            if (!lo0) {
                uint32_t q[3] = {a, b, d};
                memcpy(&m.tris[o], q, sizeof q);
                o += 3;
            }
            if (!hi0) {
                uint32_t q[3] = {a, d, c};
                memcpy(&m.tris[o], q, sizeof q);
                o += 3;
            }
        }
    }
    m.ntris = o / 3;
    if (GS(p)->reverse)
        for (size_t k = 0; k < npos; k++) m.nrm[k] = v3_neg(m.nrm[k]);
    st = add_mesh(p, &m, alpha);
    mesh_free(p, &m);
    return st;
}

typedef struct sph_arg {
    float radius, zmin, zmax;
} sph_arg;

static void sph_fn(const void *user, float t, float *r, float *z, float *nr, float *nz)
{
    const sph_arg *a = user;
    float th0 = acosf(fminf(fmaxf(a->zmin / a->radius, -1.0f), 1.0f));
    float th1 = acosf(fminf(fmaxf(a->zmax / a->radius, -1.0f), 1.0f));
    float th = th0 + (th1 - th0) * t;
    *r = a->radius * sinf(th), *z = a->radius * cosf(th);
    *nr = sinf(th), *nz = cosf(th);
}

typedef struct disk_arg {
    float h, rin, rout;
} disk_arg;

static void disk_fn(const void *user, float t, float *r, float *z, float *nr, float *nz)
{
    const disk_arg *a = user;
    *r = a->rout + (a->rin - a->rout) * t, *z = a->h;
    *nr = 0.0f, *nz = 1.0f;
}

typedef struct cyl_arg {
    float r, zmin, zmax;
} cyl_arg;

static void cyl_fn(const void *user, float t, float *r, float *z, float *nr, float *nz)
{
    const cyl_arg *a = user;
    *r = a->r, *z = a->zmin + (a->zmax - a->zmin) * t;
    *nr = 1.0f, *nz = 0.0f;
}

/* The steps around: 128 for a full turn, fewer for a part. */
static int steps_around(float phimax) { return (int)ceilf(128.0f * phimax / (2.0f * PK_PI)) < 4 ? 4 : (int)ceilf(128.0f * phimax / (2.0f * PK_PI)); }

static pk_status shape_sphere(pp *p, int32_t alpha)
{
    float radius = 1.0f, zmin, zmax, phimax = 360.0f;
    pk_status st;
    if ((st = pb_float(&p->pd, "radius", &radius))) return st;
    zmin = -radius, zmax = radius;
    if ((st = pb_float(&p->pd, "zmin", &zmin)) || (st = pb_float(&p->pd, "zmax", &zmax)) ||
        (st = pb_float(&p->pd, "phimax", &phimax)))
        return st;
    if (!(radius > 0.0f)) return pfail(p, p->line, PK_ERR_PARSE, "sphere: radius %g must be positive", (double)radius);
    float zlo = fmaxf(fminf(zmin, zmax), -radius), zhi = fminf(fmaxf(zmin, zmax), radius);
    phimax = fminf(fmaxf(phimax, 0.0f), 360.0f);
    if (!(zhi > zlo) || !(phimax > 0.0f)) return PK_OK; /* nothing left of it */
    xform w = world_xf(p);
    const float *x = w.m;
    vec3 c0 = v3(x[0], x[4], x[8]), c1 = v3(x[1], x[5], x[9]), c2 = v3(x[2], x[6], x[10]);
    float l0 = v3_len(c0), l1 = v3_len(c1), l2 = v3_len(c2);
    bool similar = fabsf(l0 - l1) <= 1e-5f * l0 && fabsf(l0 - l2) <= 1e-5f * l0 &&
                   fabsf(v3_dot(c0, c1)) <= 1e-5f * l0 * l1 && fabsf(v3_dot(c0, c2)) <= 1e-5f * l0 * l2 &&
                   fabsf(v3_dot(c1, c2)) <= 1e-5f * l1 * l2;
    bool full = zlo <= -radius && zhi >= radius && phimax >= 360.0f;
    /* textured spheres are tessellated: pbrt's uv follow the sphere's own
     * frame (phi about its z axis), which an analytic sphere does not keep */
    if (full && similar && !GS(p)->reverse && alpha < 0 && !needs_uv(p, alpha)) {
        if (GS(p)->interface && !medium_transition(p)) return PK_OK;
        sphere sp;
        sp.center = xform_point(&w, v3s(0.0f));
        sp.radius = radius * l0;
        if (!v3_finite(sp.center) || !(sp.radius > 0.0f) || !isfinite(sp.radius))
            return pfail(p, p->line, PK_ERR_PARSE, "sphere: its centre or radius in the world is not a usable number (not finite, or the radius too small)");
        bool two = false;
        vec3 ke = v3s(0.0f);
        int32_t ke_tex = -1;
        if (!GS(p)->interface)
            ke = area_emission(p, 4.0 * (double)PK_PI * (double)sp.radius * (double)sp.radius, &two, &ke_tex);
        if ((st = shape_material(p, ke, ke_tex, two, -1, &sp.material)) || (st = shape_media(p, &sp.material))) return st;
        return scene_add_sphere(p->ctx, p->s, &sp);
    }
    /* partial, inside out, stretched or cut out: tessellated */
    sph_arg a = {radius, zlo, zhi};
    int nu = (steps_around(phimax * PK_PI / 180.0f) + 1) / 2;
    return add_revolution(p, nu < 4 ? 4 : nu, 32, phimax * PK_PI / 180.0f, sph_fn, &a, alpha);
}

static pk_status shape_disk(pp *p, int32_t alpha)
{
    float h = 0.0f, r = 1.0f, ri = 0.0f, phimax = 360.0f;
    pk_status st;
    if ((st = pb_float(&p->pd, "height", &h)) || (st = pb_float(&p->pd, "radius", &r)) ||
        (st = pb_float(&p->pd, "innerradius", &ri)) || (st = pb_float(&p->pd, "phimax", &phimax)))
        return st;
    phimax = fminf(fmaxf(phimax, 0.0f), 360.0f);
    if (!(r > 0.0f) || !(ri >= 0.0f) || !(ri < r) || !(phimax > 0.0f)) return PK_OK;
    disk_arg a = {h, ri, r};
    return add_revolution(p, steps_around(phimax * PK_PI / 180.0f), 1, phimax * PK_PI / 180.0f, disk_fn, &a, alpha);
}

static pk_status shape_cylinder(pp *p, int32_t alpha)
{
    float r = 1.0f, zmin = -1.0f, zmax = 1.0f, phimax = 360.0f;
    pk_status st;
    if ((st = pb_float(&p->pd, "radius", &r)) || (st = pb_float(&p->pd, "zmin", &zmin)) ||
        (st = pb_float(&p->pd, "zmax", &zmax)) || (st = pb_float(&p->pd, "phimax", &phimax)))
        return st;
    phimax = fminf(fmaxf(phimax, 0.0f), 360.0f);
    if (!(r > 0.0f) || zmin == zmax || !(phimax > 0.0f)) return PK_OK;
    cyl_arg a = {r, fminf(zmin, zmax), fmaxf(zmin, zmax)};
    return add_revolution(p, steps_around(phimax * PK_PI / 180.0f), 1, phimax * PK_PI / 180.0f, cyl_fn, &a, alpha);
}

static pk_status shape_plymesh(pp *p, int32_t alpha)
{
    const char *fn = NULL;
    pk_status st = pb_string(&p->pd, "filename", &fn);
    if (st) return st;
    if (!fn) return pfail(p, p->line, PK_ERR_PARSE, "plymesh needs 'string filename'");
    if (pb_param(&p->pd, "displacement"))
        pwarn(p, p->line, "plymesh: 'displacement' is not supported; the mesh is rendered undisplaced");
    pb_param(&p->pd, "edgelength");
    pk_context tmp = io_scratch_context(p->ctx);
    ply_mesh pm;
    if ((st = ply_read_relative(p->ctx, &tmp, p->f->dir, fn, &pm))) {
        ply_mesh_free(p->ctx, &pm);
        return pfail(p, p->line, st, "plymesh: %s", tmp.message);
    }
    mesh_in m = {pm.positions, pm.normals, pm.uvs, pm.nvertices, pm.indices, pm.ntriangles};
    st = add_mesh(p, &m, alpha);
    ply_mesh_free(p->ctx, &pm);
    return st;
}

static pk_status d_shape(pp *p, const char *type)
{
    int32_t alpha;
    bool skip;
    pk_status st = shape_alpha(p, &alpha, &skip);
    if (st) return st;
    pb_param(&p->pd, "emissionfilename");
    if (skip) {
        pd_mark_all(&p->pd);
        return PK_OK;
    }
    if (strcmp(type, "trianglemesh") == 0) st = shape_trianglemesh(p, alpha);
    else if (strcmp(type, "plymesh") == 0) st = shape_plymesh(p, alpha);
    else if (strcmp(type, "sphere") == 0) st = shape_sphere(p, alpha);
    else if (strcmp(type, "disk") == 0) st = shape_disk(p, alpha);
    else if (strcmp(type, "cylinder") == 0) st = shape_cylinder(p, alpha);
    else if (strcmp(type, "bilinearmesh") == 0) st = shape_bilinear(p, alpha);
    else if (strcmp(type, "loopsubdiv") == 0) st = shape_loopsubdiv(p, alpha);
    else if (strcmp(type, "curve") == 0) {
        pd_mark_all(&p->pd);
        pwarn(p, p->line, "shape \"curve\" is not supported; skipped");
    } else {
        return pfail(p, p->line, PK_ERR_PARSE, "unknown shape \"%.40s\"", type);
    }
    if (st == PK_OK) warn_unused(p, "Shape \"%.40s\"", type);
    return st;
}

/* ---- lights ------------------------------------------------------------------------------------- */

/* pbrt's "scale" and the spectrum of a light (illuminant rules). */
static pk_status light_spectrum(pp *p, const char *name, vec3 *c)
{
    pparam *q;
    *c = v3s(1.0f);
    pk_status st = pb_typed(&p->pd, name, TB(PT_RGB) | TB(PT_SPECTRUM) | TB(PT_BLACKBODY),
                            "a spectrum (rgb, spectrum, blackbody)", &q);
    if (st || !q) return st;
    return spectrum_rgb(p, q, true, c);
}

static pk_status portal_points(pp *p, vec3 out[4], bool *ok);
static pk_status equal_area_env(pp *p, const char *file, size_t line, const xform *light_to_world, float scale,
                                float illuminance);

/* pbrt-v4's goniometric light (an intensity I shaped by an equal-area
 * image of directions, grey: the mean of its channels; the image's up, the
 * +z of its square, is the light's +y) and projection light (an image
 * projected along the light's +z through a field of view "fov" across the
 * image's shorter side, 90 by default, its top toward +y). Both sit at the
 * light's origin and take nearest texels, as pbrt-v4 does. */
static pk_status mapped_light(pp *p, bool gonio, const xform *w, float scale)
{
    pk_status st;
    vec3 I = v3s(1.0f);
    const char *fn = NULL;
    float fov = 90.0f, power = -1.0f;
    if ((gonio && (st = light_spectrum(p, "I", &I))) || (st = pb_string(&p->pd, "filename", &fn)) ||
        (st = pb_float(&p->pd, "power", &power)) || (!gonio && (st = pb_float(&p->pd, "fov", &fov))))
        return st;
    const char *what = gonio ? "goniometric" : "projection";
    if (!fn) {
        if (!gonio) return pfail(p, p->line, PK_ERR_PARSE, "projection: 'string filename' is required");
        pwarn(p, p->line, "goniometric: no 'filename'; the light emits nothing (as in pbrt-v4)");
        return PK_OK;
    }
    if (!gonio && !(fov > 0.0f && fov < 180.0f))
        return pfail(p, p->line, PK_ERR_PARSE, "projection: fov %g must be between 0 and 180 degrees", (double)fov);
    int32_t idx;
    char why[PK_ERRMSG_MAX];
    if ((st = load_image(p, fn, png_name(fn), &idx, why, sizeof why))) return st;
    if (idx < 0) {
        pwarn(p, p->line, "%s: the image is not used (%s); the light is skipped", what, why);
        return PK_OK;
    }
    const tex_level *lv = &p->s->textures[idx].lv[0];
    if (gonio && lv->w != lv->h)
        return pfail(p, p->line, PK_ERR_PARSE, "goniometric: \"%.80s\" is %dx%d, not a square equal-area image", fn,
                     lv->w, lv->h);
    xform inv;
    if (!xform_invert(w, &inv)) return pfail(p, p->line, PK_ERR_PARSE, "%s: the light's transform is singular", what);
    /* world -> light directions: the inverse's linear part */
    float m[9];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) m[3 * r + c] = inv.m[4 * r + c];
    if (gonio) { /* the square's frame is the light's with y and z swapped */
        for (int c = 0; c < 3; c++) {
            const float t = m[3 + c];
            m[3 + c] = m[6 + c], m[6 + c] = t;
        }
    } else { /* the image's rows run down: its frame's y is the light's -y */
        for (int c = 0; c < 3; c++) m[3 + c] = -m[3 + c];
    }
    const float aspect = (float)lv->w / (float)lv->h;
    const float sx = aspect > 1.0f ? aspect : 1.0f, sy = aspect > 1.0f ? 1.0f : 1.0f / aspect;
    const vec3 position = xform_point(w, v3s(0.0f));
    const vec3 intensity = v3_scale(I, scale);
    if (!v3_finite(position) || !v3_finite(intensity) || !(v3_min_comp(intensity) >= 0.0f))
        return pfail(p, p->line, PK_ERR_PARSE, "%s: the intensity or position is not finite and positive", what);
    return scene_light_mapped(p->ctx, p->s, position, intensity, gonio ? LIGHT_MAP_GONIOMETRIC : LIGHT_MAP_PROJECTION,
                              idx, m, tanf(fov * (PK_PI / 360.0f)), sx, sy, power);
}

static pk_status d_light(pp *p, const char *type)
{
    pk_status st;
    float scale = 1.0f, power = -1.0f;
    if ((st = pb_float(&p->pd, "scale", &scale))) return st;
    if (p->b.in_object) {
        pd_mark_all(&p->pd);
        pwarn(p, p->line, "a light inside an object definition is ignored (as pbrt-v4 does not allow it)");
        return PK_OK;
    }
    xform w = world_xf(p);
    if (strcmp(type, "point") == 0 || strcmp(type, "spot") == 0) {
        vec3 I, from = v3s(0.0f), to = v3(0.0f, 0.0f, 1.0f);
        float cone = 30.0f, delta = 5.0f;
        if ((st = light_spectrum(p, "I", &I)) || (st = pb_float(&p->pd, "power", &power)) ||
            (st = pb_vec3(&p->pd, "from", &from)))
            return st;
        const vec3 position = xform_point(&w, from);
        vec3 axis = v3s(0.0f);
        float cs = 1.0f, ce = 1.0f, k_e = 4.0f * PK_PI;
        if (type[0] == 's') {
            if ((st = pb_vec3(&p->pd, "to", &to)) || (st = pb_float(&p->pd, "coneangle", &cone)) ||
                (st = pb_float(&p->pd, "conedelta", &delta)))
                return st;
            ce = cosf(cone * PK_PI / 180.0f), cs = cosf((cone - delta) * PK_PI / 180.0f);
            if (!(cs > ce)) cs = fminf(ce + 1e-4f, 1.0f);
            axis = v3_norm_scaled(xform_vector(&w, v3_sub(to, from)));
            if (!v3_finite(axis) || v3_len2(axis) == 0.0f)
                return pfail(p, p->line, PK_ERR_PARSE, "spot: 'from' and 'to' give no direction");
            if (!(ce >= -1.0f && ce <= cs)) return pfail(p, p->line, PK_ERR_PARSE, "spot: 'coneangle' is not a number");
            k_e = 2.0f * PK_PI * ((1.0f - cs) + (cs - ce) * 0.5f);
        }
        if (power > 0.0f) scale *= power / k_e;
        const vec3 intensity = v3_scale(I, scale);
        if (!v3_finite(position) || !v3_finite(intensity))
            return pfail(p, p->line, PK_ERR_PARSE, "light: not finite in the world");
        if (!(v3_min_comp(intensity) >= 0.0f)) return pfail(p, p->line, PK_ERR_PARSE, "light: the intensity is negative");
        st = type[0] == 's' ? scene_light_spot(p->ctx, p->s, position, axis, cs, ce, SPOT_FALLOFF_SMOOTHSTEP, intensity)
                            : scene_light_point(p->ctx, p->s, position, intensity);
        if (st) return st;
    } else if (strcmp(type, "distant") == 0) {
        vec3 L, from = v3s(0.0f), to = v3(0.0f, 0.0f, 1.0f);
        float illum = -1.0f;
        if ((st = light_spectrum(p, "L", &L)) || (st = pb_vec3(&p->pd, "from", &from)) ||
            (st = pb_vec3(&p->pd, "to", &to)) || (st = pb_float(&p->pd, "illuminance", &illum)))
            return st;
        if (illum > 0.0f) scale *= illum;
        const vec3 to_light = v3_norm_scaled(xform_vector(&w, v3_sub(from, to)));
        if (!v3_finite(to_light) || v3_len2(to_light) == 0.0f)
            return pfail(p, p->line, PK_ERR_PARSE, "distant: 'from' and 'to' give no direction");
        const vec3 irradiance = v3_scale(L, scale);
        if (!v3_finite(irradiance) || !(v3_min_comp(irradiance) >= 0.0f))
            return pfail(p, p->line, PK_ERR_PARSE, "distant: the radiance must be finite and not negative");
        if ((st = scene_light_distant(p->ctx, p->s, to_light, irradiance))) return st;
    } else if (strcmp(type, "infinite") == 0) {
        vec3 L;
        const char *fn = NULL;
        bool has_L;
        pparam *q;
        if ((st = pb_typed(&p->pd, "L", TB(PT_RGB) | TB(PT_SPECTRUM) | TB(PT_BLACKBODY), "a spectrum", &q))) return st;
        has_L = q != NULL;
        if ((st = light_spectrum(p, "L", &L)) || (st = pb_string(&p->pd, "filename", &fn))) return st;
        float illum = -1.0f;
        if ((st = pb_float(&p->pd, "illuminance", &illum))) return st;
        vec3 portal[4];
        bool has_portal = false;
        if ((st = portal_points(p, portal, &has_portal))) return st;
        if (has_L && fn) return pfail(p, p->line, PK_ERR_PARSE, "infinite: give either 'L' or 'filename', not both");
        const scene_environment *env = &p->s->env;
        const bool had_env = env->has_portal || env->map || env->map_rgb || v3_max_comp(env->radiance) > 0.0f ||
                             env->has_sky;
        if (had_env && (has_portal || env->has_portal))
            pwarn(p, p->line, "infinite: a portal applies to every infinite light of the scene (the scene has two)");
        if (fn) {
            if ((st = equal_area_env(p, fn, p->line, &w, scale, illum))) return st;
        } else {
            /* a uniform sky of one nit gives pi lux on a level surface */
            if (illum > 0.0f) scale *= illum / PK_PI;
            scene_env_add_radiance(p->s, v3_scale(L, scale));
        }
        if (has_portal) {
            /* into the (possibly mirrored, see the top) world; a mirror turns
             * the rectangle's normal inward, which walking its corners the
             * other way round turns back */
            const float *mm = p->mirror.m;
            const float det = mm[0] * (mm[5] * mm[10] - mm[6] * mm[9]) - mm[1] * (mm[4] * mm[10] - mm[6] * mm[8]) +
                              mm[2] * (mm[4] * mm[9] - mm[5] * mm[8]);
            vec3 *pq = p->s->env.portal;
            for (int k = 0; k < 4; k++) pq[k] = xform_point(&p->mirror, portal[det < 0.0f ? (4 - k) % 4 : k]);
            p->s->env.has_portal = true;
        }
    } else if (strcmp(type, "goniometric") == 0 || strcmp(type, "projection") == 0) {
        if ((st = mapped_light(p, type[0] == 'g', &w, scale))) return st;
    } else {
        return pfail(p, p->line, PK_ERR_PARSE, "unknown light \"%.40s\"", type);
    }
    warn_unused(p, "LightSource \"%.40s\"", type);
    return PK_OK;
}

/* An infinite light's "point3 portal": four points in the world (pbrt-v4
 * does not apply the current transform to them) that must make a planar
 * rectangle, checked as pbrt-v4 does (opposite edges parallel, adjacent
 * ones perpendicular, within 0.001 in cosine); otherwise a warning and no
 * portal (the whole environment shines). */
static pk_status portal_points(pp *p, vec3 out[4], bool *ok)
{
    pparam *q;
    pk_status st = pb_typed(&p->pd, "portal", TB(PT_POINT3), "point3 values", &q);
    *ok = false;
    if (st || !q) return st;
    if (q->nnum != 12) {
        pwarn(p, q->line,
              "infinite: 'portal' takes 4 points (12 numbers), not %zu numbers; the whole environment is used", q->nnum);
        return PK_OK;
    }
    for (int k = 0; k < 4; k++) out[k] = v3((float)q->num[3 * k], (float)q->num[3 * k + 1], (float)q->num[3 * k + 2]);
    const bool good = io_portal_is_rectangle(out);
    if (!good) {
        pwarn(p, q->line, "infinite: the 'portal' is not a planar rectangle; the whole environment is used");
        return PK_OK;
    }
    *ok = true;
    return PK_OK;
}

/* An infinite light's image: pbrt-v4 keeps it as an equal-area octahedral
 * square, looked up through the light's transform; it is resampled here
 * into the lat-long map of the environment, already in the world (so its
 * rotation stays the identity). */
/* The illuminance that pbrt-v4 computes for an equal-area environment image
 * (w x h pixels, linear sRGB) to honour an infinite light's "illuminance":
 * the luminance of the pixels whose direction points up (+z in the light's
 * space) times that direction's cosine, summed and multiplied by 2 pi / (w h).
 * (Each pixel spans 4 pi / (w h) steradians; pbrt-v4 uses 2 pi, so the
 * illuminance its images show is twice the one asked for. The scene's author
 * saw pbrt's image, so its factor is kept.) Only the z of the pixel's
 * direction is needed: on the octahedral square it is 1 - r^2, r the distance
 * of the point from the square's diamond edge, with the sign of its side. */
static double pbrt_equal_area_illuminance(const float *rgb, int w, int h)
{
    double sum = 0.0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double u = 2.0 * ((double)x + 0.5) / (double)w - 1.0, v = 2.0 * ((double)y + 0.5) / (double)h - 1.0;
            double sd = 1.0 - (fabs(u) + fabs(v)), r = 1.0 - fabs(sd), z = sd >= 0.0 ? 1.0 - r * r : r * r - 1.0;
            if (z <= 0.0) continue;
            const float *px = &rgb[3 * ((size_t)y * (size_t)w + (size_t)x)];
            sum += (0.212639 * (double)px[0] + 0.715169 * (double)px[1] + 0.072192 * (double)px[2]) * z;
        }
    return sum * 2.0 * (double)PK_PI / ((double)w * (double)h);
}

static pk_status equal_area_env(pp *p, const char *file, size_t line, const xform *light_to_world, float scale,
                                float illuminance)
{
    char *path = path_join(A(p), p->f->dir, file);
    if (!path) return ctx_nomem(p->ctx);
    int w = 0, h = 0;
    float *src = NULL;
    const bool was_ok = p->ctx->status == PK_OK;
    pk_status st = image_load_rgb(p->ctx, path, &w, &h, &src);
    mem_free(A(p), path);
    if (st != PK_OK) {
        char why[PK_ERRMSG_MAX];
        if (!io_demote_error(p->ctx, st, was_ok, why, sizeof why)) return st;
        pwarn(p, line, "infinite light not read (%s); a uniform environment of radiance %g is used", why, (double)scale);
        scene_env_add_radiance(p->s, v3s(scale));
        return PK_OK;
    }
    if (w != h) {
        mem_free(A(p), src);
        pwarn(p, line,
              "infinite: \"%.80s\" is %dx%d, not the square equal-area image pbrt-v4 uses (lat-long images are not "
              "pbrt-v4's); a uniform environment of radiance %g is used",
              file, w, h, (double)scale);
        scene_env_add_radiance(p->s, v3s(scale));
        return PK_OK;
    }
    if (p->s->env.map || p->s->env.map_rgb) {
        mem_free(A(p), src);
        pwarn(p, line, "a second image environment is ignored (one map per scene)");
        return PK_OK;
    }
    if (illuminance > 0.0f) {
        const double k_e = pbrt_equal_area_illuminance(src, w, h);
        if (k_e > 0.0) scale = (float)((double)scale * (double)illuminance / k_e);
        else pwarn(p, line, "infinite: \"%.80s\" is black above the horizon; 'illuminance' is not used", file);
    }
    xform to_light;
    if (!xform_invert(light_to_world, &to_light)) {
        mem_free(A(p), src);
        return pfail(p, line, PK_ERR_PARSE, "infinite: the light's transform is singular");
    }
    int ow = 2 * w, oh = w;
    if (ow > 8192) ow = 8192, oh = 4096;
    float *dst = mem_calloc(A(p), (size_t)ow * (size_t)oh, 3 * sizeof(float));
    if (!dst) {
        mem_free(A(p), src);
        return ctx_nomem(p->ctx);
    }
    for (int j = 0; j < oh; j++)
        for (int i = 0; i < ow; i++) {
            float th = ((float)j + 0.5f) / (float)oh * PK_PI, ph = ((float)i + 0.5f) / (float)ow * 2.0f * PK_PI;
            vec3 d = v3(sinf(th) * sinf(ph), cosf(th), -sinf(th) * cosf(ph));
            vec3 dl = v3_norm_scaled(xform_vector(&to_light, d));
            float u, v;
            equal_area_sphere_to_square(dl, &u, &v);
            /* bilinear, clamped at the edges */
            float x = u * (float)w - 0.5f, y = v * (float)h - 0.5f;
            int x0 = (int)floorf(x), y0 = (int)floorf(y);
            float fx = x - (float)x0, fy = y - (float)y0;
            float *o = &dst[3 * ((size_t)j * (size_t)ow + (size_t)i)];
            for (int c = 0; c < 3; c++) {
                float acc = 0.0f;
                for (int dy = 0; dy < 2; dy++)
                    for (int dx = 0; dx < 2; dx++) {
                        int xx = x0 + dx, yy = y0 + dy;
                        xx = xx < 0 ? 0 : xx >= w ? w - 1 : xx;
                        yy = yy < 0 ? 0 : yy >= h ? h - 1 : yy;
                        float wt = (dx ? fx : 1.0f - fx) * (dy ? fy : 1.0f - fy);
                        acc += wt * src[3 * ((size_t)yy * (size_t)w + (size_t)xx) + (size_t)c];
                    }
                o[c] = acc * scale;
            }
        }
    mem_free(A(p), src);
    return scene_env_map_pixels(p->ctx, p->s, file, dst, ow, oh, 1.0f);
}

static pk_status d_area_light(pp *p, const char *type)
{
    pk_status st;
    if (strcmp(type, "diffuse") != 0) {
        pd_mark_all(&p->pd);
        pwarn(p, p->line, "area light \"%.40s\" is not supported; the shapes do not emit", type);
        GS(p)->area = -1;
        return PK_OK;
    }
    area_light l = {v3s(1.0f), false, -1.0f, -1};
    float scale = 1.0f;
    const char *fn = NULL;
    if ((st = light_spectrum(p, "L", &l.L)) || (st = pb_float(&p->pd, "scale", &scale)) ||
        (st = pb_bool(&p->pd, "twosided", &l.two_sided)) || (st = pb_float(&p->pd, "power", &l.power)) ||
        (st = pb_string(&p->pd, "filename", &fn)))
        return st;
    if (fn) { /* the image's linear RGB is the radiance (times scale), looked up by the shape's uv */
        if (pb_param(&p->pd, "L"))
            return pfail(p, p->line, PK_ERR_PARSE, "AreaLightSource: give either 'L' or 'filename', not both");
        int32_t idx;
        char why[PK_ERRMSG_MAX];
        if ((st = load_image(p, fn, png_name(fn), &idx, why, sizeof why))) return st;
        if (idx < 0) {
            pwarn(p, p->line, "AreaLightSource: the emission image is not used (%s); a uniform radiance %g is",
                  why, (double)scale);
        } else {
            l.image = idx;
        }
        l.L = v3s(1.0f);
    }
    l.L = v3_scale(l.L, scale);
    if (!v3_finite(l.L)) return pfail(p, p->line, PK_ERR_PARSE, "AreaLightSource: the radiance is not finite");
    if (!(v3_min_comp(l.L) >= 0.0f)) return pfail(p, p->line, PK_ERR_PARSE, "AreaLightSource: the radiance is negative");
    if (!mem_grow(A(p), (void **)&p->areas, &p->cap_areas, p->nareas + 1, sizeof *p->areas)) return ctx_nomem(p->ctx);
    p->areas[p->nareas] = l;
    GS(p)->area = (int32_t)p->nareas++;
    warn_unused(p, "AreaLightSource");
    return PK_OK;
}

/* ---- textures ------------------------------------------------------------------------------------- */

/* The texture-building state: the nodes of the expression so far. */
typedef struct tex_build {
    tex_node n[TEX_MAX_NODES];
    int count;
    bool full;           /* an operand did not fit */
} tex_build;

static int tb_push(tex_build *b, const tex_node *d)
{
    if (b->count >= TEX_MAX_NODES) {
        b->full = true;
        return -1;
    }
    b->n[b->count] = *d;
    return b->count++;
}

static tex_node tn_new(tex_op op)
{
    tex_node d;
    memset(&d, 0, sizeof d);
    d.op = (uint8_t)op;
    d.a = d.b = d.c = -1;
    d.su = d.sv = 1.0f;
    d.k[0] = v3s(1.0f);
    return d;
}

static int tb_const(tex_build *b, vec3 c)
{
    tex_node d = tn_new(TN_CONST);
    d.k[0] = c;
    return tb_push(b, &d);
}

/* Appends a named texture's nodes (its operands moved along); its root. */
static int tb_append(tex_build *b, const named_tex *t)
{
    if (b->count + t->nnodes > TEX_MAX_NODES) {
        b->full = true;
        return -1;
    }
    const int base = b->count;
    for (int i = 0; i < t->nnodes; i++) {
        tex_node d = t->nodes[i];
        if (d.a >= 0) d.a = (int8_t)(d.a + base);
        if (d.b >= 0) d.b = (int8_t)(d.b + base);
        if (d.c >= 0) d.c = (int8_t)(d.c + base);
        b->n[b->count++] = d;
    }
    return b->count - 1;
}

/* An operand of a texture: a named texture or a constant (float or
 * colour as the texture is), def when absent. Its node's index in *idx. */
static pk_status tex_operand(pp *p, tex_build *b, const char *name, bool is_float, vec3 def, int *idx)
{
    pparam *q;
    pk_status st = pb_typed(&p->pd, name,
                            TB(PT_RGB) | TB(PT_SPECTRUM) | TB(PT_BLACKBODY) | TB(PT_TEXTURE) | TB(PT_FLOAT),
                            is_float ? "a float or a float texture" : "a colour (rgb, spectrum, blackbody, float or texture)",
                            &q);
    if (st) return st;
    if (q && q->type == PT_TEXTURE) {
        if (q->nstr != 1) return pfail(p, q->line, PK_ERR_PARSE, "'texture %s' takes one name", name);
        named_tex *t = find_tex(p, q->str[0]);
        if (!t) return pfail(p, q->line, PK_ERR_PARSE, "'texture %s': no texture named \"%.60s\"", name, q->str[0]);
        *idx = tb_append(b, t);
        return PK_OK;
    }
    vec3 c = def;
    if (q) {
        if (is_float) {
            float f = def.x;
            if ((st = get_float_tex(p, name, &f, NULL))) return st;
            c = v3s(f);
        } else if ((st = get_colour(p, name, &c, NULL, NULL))) {
            return st;
        }
    }
    *idx = tb_const(b, c);
    return PK_OK;
}

/* The texture space: the inverse of the transform at the Texture
 * directive (with the reader's mirror), as the node's three rows. */
static pk_status tex_space(pp *p, tex_node *d)
{
    xform w = world_xf(p), inv;
    if (!xform_invert(&w, &inv) || !xform_finite(&inv))
        return pfail(p, p->line, PK_ERR_PARSE, "Texture: the transform cannot be inverted");
    memcpy(d->xf, inv.m, sizeof d->xf);
    return PK_OK;
}

/* pbrt's 2D mappings: "uv" (uscale, vscale, udelta, vdelta), "spherical",
 * "cylindrical" and "planar" (v1, v2, udelta, vdelta), into d. */
static pk_status tex_mapping2d(pp *p, tex_node *d)
{
    const char *mapping = "uv";
    pk_status st = pb_string(&p->pd, "mapping", &mapping);
    if (st) return st;
    if (strcmp(mapping, "uv") == 0) {
        d->map = TMAP_UV;
        return (st = pb_float(&p->pd, "uscale", &d->su)) || (st = pb_float(&p->pd, "vscale", &d->sv)) ||
                       (st = pb_float(&p->pd, "udelta", &d->du)) || (st = pb_float(&p->pd, "vdelta", &d->dv))
                   ? st
                   : PK_OK;
    }
    if (strcmp(mapping, "spherical") == 0) d->map = TMAP_SPHERICAL;
    else if (strcmp(mapping, "cylindrical") == 0) d->map = TMAP_CYLINDRICAL;
    else if (strcmp(mapping, "planar") == 0) {
        d->map = TMAP_PLANAR;
        d->v1 = v3(1.0f, 0.0f, 0.0f), d->v2 = v3(0.0f, 1.0f, 0.0f);
        if ((st = pb_vec3(&p->pd, "v1", &d->v1)) || (st = pb_vec3(&p->pd, "v2", &d->v2)) ||
            (st = pb_float(&p->pd, "udelta", &d->du)) || (st = pb_float(&p->pd, "vdelta", &d->dv)))
            return st;
    } else {
        pwarn(p, p->line, "Texture: mapping \"%.20s\" is unknown; uv is used", mapping);
        d->map = TMAP_UV;
        return PK_OK;
    }
    return tex_space(p, d);
}

/* pbrt's 3D mapping: the texture-space point. */
static pk_status tex_mapping3d(pp *p, tex_node *d)
{
    d->map = TMAP_3D;
    return tex_space(p, d);
}

/* The noise textures' octaves and roughness (omega). */
static pk_status tex_octaves(pp *p, tex_node *d)
{
    int64_t oct = 8;
    d->omega = 0.5f;
    pk_status st;
    if ((st = pb_int(&p->pd, "octaves", 0, 64, &oct)) || (st = pb_float(&p->pd, "roughness", &d->omega))) return st;
    d->octaves = (int32_t)oct;
    if (!isfinite(d->omega)) return pfail(p, p->line, PK_ERR_PARSE, "Texture: 'roughness' must be finite");
    return PK_OK;
}

/* A texture's mean over a fixed spread of points (uv in [0, 1)^2, points
 * in a box of side 8, normals all around): what stands in where a
 * parameter takes no map. */
static vec3 tex_mean(pp *p, const tex_node *nodes, int n)
{
    tex_ref r;
    tex_ref_init(&r);
    r.kind = TEX_EXPR, r.node = 0, r.nnodes = n;
    vec3 sum = v3s(0.0f);
    const int k = 16;
    for (int i = 0; i < k; i++)
        for (int j = 0; j < k; j++) {
            const float u = ((float)i + 0.5f) / (float)k, v = ((float)j + 0.5f) / (float)k;
            const float ph = 2.0f * PK_PI * u, ct = 2.0f * v - 1.0f, sn = sqrtf(fmaxf(0.0f, 1.0f - ct * ct));
            tex_query q = {u, v, 0.0f, v3(8.0f * u - 4.0f, 8.0f * v - 4.0f, 8.0f * fmodf(u * 7.0f + v * 3.0f, 1.0f) - 4.0f),
                           v3(sn * cosf(ph), ct, sn * sinf(ph)), nodes, u, v, 0.0f};
            sum = v3_add(sum, tex_expr_eval(p->s->textures, &r, q));
        }
    return v3_scale(sum, 1.0f / (float)(k * k));
}

/* The nodes of a texture of the scene's own kinds (constant, image, uv
 * checkerboard of constants), so that other textures can use it. */
static void tex_own_nodes(const named_tex *t, tex_build *b)
{
    b->count = 0;
    if (t->cls == TC_CONST) {
        tb_const(b, t->value);
    } else if (t->cls == TC_IMAGE) {
        tex_node d = tn_new(TN_IMAGE);
        d.tex = t->ref.tex, d.clamp = t->ref.clamp, d.grey = t->is_float;
        d.su = t->ref.s[0], d.sv = t->ref.s[1], d.du = t->ref.o[0], d.dv = t->ref.o[1];
        d.k[0] = t->value;
        tb_push(b, &d);
    } else if (t->cls == TC_CHECKER) {
        tex_node d = tn_new(TN_CHECKER);
        d.a = (int8_t)tb_const(b, t->ref.even);
        d.b = (int8_t)tb_const(b, t->ref.odd);
        d.su = t->ref.s[0] * t->ref.checker_scale, d.sv = t->ref.s[1] * t->ref.checker_scale;
        d.du = t->ref.o[0] * t->ref.checker_scale, d.dv = t->ref.o[1] * t->ref.checker_scale;
        tb_push(b, &d);
    }
}

static pk_status d_texture(pp *p, const char *name, const char *kind, const char *cls)
{
    pk_status st;
    bool is_float = strcmp(kind, "float") == 0;
    if (!is_float && strcmp(kind, "spectrum") != 0 && strcmp(kind, "color") != 0)
        return pfail(p, p->line, PK_ERR_PARSE, "Texture \"%.60s\": the type must be \"float\" or \"spectrum\", not \"%.20s\"",
                     name, kind);
    named_tex t;
    memset(&t, 0, sizeof t);
    t.is_float = is_float;
    tex_ref_init(&t.ref);
    t.value = v3s(1.0f);
    t.cls = TC_CONST;
    tex_build b;
    b.count = 0, b.full = false;
    const vec3 zero = v3s(0.0f), one = v3s(1.0f);
    if (strcmp(cls, "imagemap") == 0) {
        const char *fn = NULL, *enc = NULL, *wrap = "repeat", *filter = NULL;
        bool invert = false;
        float sc = 1.0f;
        tex_node d = tn_new(TN_IMAGE);
        if ((st = tex_mapping2d(p, &d))) return st;
        if ((st = pb_string(&p->pd, "filename", &fn)) || (st = pb_string(&p->pd, "encoding", &enc)) ||
            (st = pb_string(&p->pd, "wrap", &wrap)) || (st = pb_string(&p->pd, "filter", &filter)) ||
            (st = pb_float(&p->pd, "scale", &sc)) || (st = pb_bool(&p->pd, "invert", &invert)))
            return st;
        pb_param(&p->pd, "maxanisotropy");
        if (!fn) return pfail(p, p->line, PK_ERR_PARSE, "imagemap \"%.60s\" needs 'string filename'", name);
        /* pbrt-v4's default: sRGB for PNG files, linear for the others */
        bool colour = png_name(fn);
        if (enc && strcmp(enc, "linear") == 0) colour = false;
        else if (enc && strcmp(enc, "sRGB") == 0) colour = true;
        else if (enc) pwarn(p, p->line, "imagemap: encoding \"%.20s\" is read as sRGB", enc);
        if (invert) pwarn(p, p->line, "imagemap: 'invert' is not supported; the image is used as it is");
        int32_t idx;
        char why[PK_ERRMSG_MAX];
        if ((st = load_image(p, fn, colour, &idx, why, sizeof why))) return st;
        if (idx < 0) {
            pwarn(p, p->line, "texture \"%.60s\" not used (%s); the constant %g stands in", name, why, (double)sc);
            t.value = v3s(sc);
        } else {
            t.value = v3s(sc);
            t.ref.kind = TEX_IMAGE;
            t.ref.tex = idx;
            t.ref.clamp = strcmp(wrap, "clamp") == 0 || strcmp(wrap, "black") == 0 ? TEX_CLAMP : 0;
            if (strcmp(wrap, "black") == 0) pwarn(p, p->line, "imagemap: wrap \"black\" is rendered as \"clamp\"");
            if (d.map == TMAP_UV) {
                t.cls = TC_IMAGE;
                t.ref.s[0] = d.su, t.ref.s[1] = d.sv, t.ref.o[0] = d.du, t.ref.o[1] = d.dv;
            } else {
                d.tex = idx, d.clamp = t.ref.clamp, d.grey = is_float, d.k[0] = t.value;
                tb_push(&b, &d);
                t.cls = TC_EXPR;
            }
        }
    } else if (strcmp(cls, "checkerboard") == 0) {
        int64_t dim = 2;
        if ((st = pb_int(&p->pd, "dimension", 2, 3, &dim))) return st;
        tex_node d = tn_new(TN_CHECKER);
        int a, c;
        if ((st = tex_operand(p, &b, "tex1", is_float, one, &a)) || (st = tex_operand(p, &b, "tex2", is_float, zero, &c)))
            return st;
        if ((st = dim == 3 ? tex_mapping3d(p, &d) : tex_mapping2d(p, &d))) return st;
        d.a = (int8_t)a, d.b = (int8_t)c;
        if (!b.full && d.map == TMAP_UV && b.count == 2 && b.n[0].op == TN_CONST && b.n[1].op == TN_CONST) {
            /* two constants in uv: the scene's own checker */
            t.cls = TC_CHECKER;
            t.ref.kind = TEX_CHECKER;
            t.ref.even = b.n[0].k[0], t.ref.odd = b.n[1].k[0];
            t.ref.checker_scale = 1.0f;
            t.ref.s[0] = d.su, t.ref.s[1] = d.sv, t.ref.o[0] = d.du, t.ref.o[1] = d.dv;
            b.count = 0;
        } else {
            tb_push(&b, &d);
            t.cls = TC_EXPR;
        }
    } else if (strcmp(cls, "constant") == 0) {
        if (is_float) {
            float v = 1.0f;
            if ((st = get_float_tex(p, "value", &v, NULL))) return st;
            t.value = v3s(v);
        } else if ((st = get_colour(p, "value", &t.value, NULL, NULL))) {
            return st;
        }
    } else if (strcmp(cls, "bilerp") == 0) {
        tex_node d = tn_new(TN_BILERP);
        if ((st = tex_mapping2d(p, &d))) return st;
        const char *nm[4] = {"v00", "v01", "v10", "v11"};
        for (int i = 0; i < 4; i++) {
            d.k[i] = v3s(i & 1 ? 1.0f : 0.0f);
            if (is_float) {
                float f = d.k[i].x;
                if ((st = pb_float(&p->pd, nm[i], &f))) return st;
                d.k[i] = v3s(f);
            } else if ((st = get_colour(p, nm[i], &d.k[i], NULL, NULL))) {
                return st;
            }
        }
        tb_push(&b, &d);
        t.cls = TC_EXPR;
    } else if (strcmp(cls, "dots") == 0) {
        tex_node d = tn_new(TN_DOTS);
        int a, c;
        if ((st = tex_operand(p, &b, "inside", is_float, one, &a)) ||
            (st = tex_operand(p, &b, "outside", is_float, zero, &c)) || (st = tex_mapping2d(p, &d)))
            return st;
        d.a = (int8_t)a, d.b = (int8_t)c;
        tb_push(&b, &d);
        t.cls = TC_EXPR;
    } else if (strcmp(cls, "fbm") == 0 || strcmp(cls, "wrinkled") == 0 || strcmp(cls, "windy") == 0 ||
               strcmp(cls, "marble") == 0) {
        const bool marble = cls[1] == 'a';
        if (marble && is_float) return pfail(p, p->line, PK_ERR_PARSE, "Texture \"%.60s\": marble is a spectrum texture", name);
        if (!marble && !is_float)
            return pfail(p, p->line, PK_ERR_PARSE, "Texture \"%.60s\": %s is a float texture", name, cls);
        tex_node d = tn_new(cls[0] == 'f' ? TN_FBM : cls[1] == 'r' ? TN_WRINKLED : cls[1] == 'i' ? TN_WINDY : TN_MARBLE);
        if ((st = tex_mapping3d(p, &d))) return st;
        if (d.op != TN_WINDY && (st = tex_octaves(p, &d))) return st;
        if (marble) {
            d.scale = 1.0f, d.variation = 0.2f;
            if ((st = pb_float(&p->pd, "scale", &d.scale)) || (st = pb_float(&p->pd, "variation", &d.variation))) return st;
        }
        tb_push(&b, &d);
        t.cls = TC_EXPR;
    } else if (strcmp(cls, "scale") == 0) {
        int a, c;
        if ((st = tex_operand(p, &b, "tex", is_float, one, &a)) || (st = tex_operand(p, &b, "scale", true, one, &c)))
            return st;
        named_tex *src = NULL;
        pparam *q = pb_param(&p->pd, "tex");
        if (q && q->type == PT_TEXTURE && q->nstr == 1) src = find_tex(p, q->str[0]);
        const bool cscale = !b.full && b.n[c].op == TN_CONST;
        if (!b.full && b.n[a].op == TN_CONST && cscale) {
            t.value = v3_mul(b.n[a].k[0], b.n[c].k[0]); /* a constant */
            b.count = 0;
        } else if (cscale && src && (src->cls == TC_IMAGE || src->cls == TC_CHECKER)) {
            /* the image (or checker) with its constant scaled, as pbrt does */
            t.cls = src->cls, t.ref = src->ref, t.value = v3_scale(src->value, b.n[c].k[0].x);
            b.count = 0;
        } else {
            tex_node d = tn_new(TN_SCALE);
            d.a = (int8_t)a, d.b = (int8_t)c;
            tb_push(&b, &d);
            t.cls = TC_EXPR;
        }
    } else if (strcmp(cls, "mix") == 0 || strcmp(cls, "directionmix") == 0) {
        const bool dir = cls[0] == 'd';
        tex_node d = tn_new(dir ? TN_DIRMIX : TN_MIX);
        int a, c, m = -1;
        if ((st = tex_operand(p, &b, "tex1", is_float, zero, &a)) || (st = tex_operand(p, &b, "tex2", is_float, one, &c)))
            return st;
        if (dir) {
            vec3 v = v3(0.0f, 1.0f, 0.0f);
            if ((st = pb_vec3(&p->pd, "dir", &v))) return st;
            const xform w = world_xf(p);
            v = xform_vector(&w, v);
            if (!(v3_len2(v) > 0.0f) || !v3_finite(v))
                return pfail(p, p->line, PK_ERR_PARSE, "directionmix: 'dir' must be a nonzero finite vector");
            d.v1 = v3_norm(v);
        } else if ((st = tex_operand(p, &b, "amount", true, v3s(0.5f), &m))) {
            return st;
        }
        d.a = (int8_t)a, d.b = (int8_t)c, d.c = (int8_t)m;
        tb_push(&b, &d);
        t.cls = TC_EXPR;
    } else {
        pd_mark_all(&p->pd);
        pwarn(p, p->line, "texture \"%.30s\" is not supported; \"%.60s\" is the constant 1", cls, name);
    }
    if (t.cls == TC_EXPR && b.full) {
        pd_mark_all(&p->pd);
        pwarn(p, p->line, "Texture \"%.60s\": the expression has more than %d parts; the constant 1 stands in", name,
              TEX_MAX_NODES);
        t.cls = TC_CONST, t.value = v3s(1.0f), b.count = 0;
    }
    if (t.cls == TC_EXPR) t.value = tex_mean(p, b.n, b.count);
    else tex_own_nodes(&t, &b);
    t.nnodes = b.count;
    t.nodes = mem_realloc_array(A(p), NULL, (size_t)b.count, sizeof *t.nodes);
    if (!t.nodes) return ctx_nomem(p->ctx);
    memcpy(t.nodes, b.n, (size_t)b.count * sizeof *t.nodes);
    if (!mem_grow(A(p), (void **)&p->tex, &p->cap_tex, p->ntex + 1, sizeof *p->tex)) {
        mem_free(A(p), t.nodes);
        return ctx_nomem(p->ctx);
    }
    t.name = mem_strdup(A(p), name);
    if (!t.name) {
        mem_free(A(p), t.nodes);
        return ctx_nomem(p->ctx);
    }
    p->tex[p->ntex++] = t;
    warn_unused(p, "Texture \"%.30s\"", cls);
    return PK_OK;
}

/* ---- camera, film, sampler, integrator ------------------------------------------------------- */

static pk_status set_coords(pp *p, const char *name, const xform *x);

static pk_status d_camera(pp *p, const char *type)
{
    pk_status st;
    if (strcmp(type, "perspective") == 0) p->ortho = false;
    else if (strcmp(type, "orthographic") == 0) p->ortho = true;
    else {
        pwarn(p, p->line, "camera \"%.40s\" is not supported; rendered as a perspective camera", type);
        pd_mark_all(&p->pd);
    }
    p->fov = 90.0f;
    if ((st = pb_float(&p->pd, "fov", &p->fov)) || (st = pb_float(&p->pd, "lensradius", &p->lens_radius)) ||
        (st = pb_float(&p->pd, "focaldistance", &p->focal_distance)) ||
        (st = pb_float(&p->pd, "frameaspectratio", &p->frame_aspect)))
        return st;
    if (!(p->fov > 0.0f && p->fov < 180.0f))
        return pfail(p, p->line, PK_ERR_PARSE, "camera: fov %g must be between 0 and 180 degrees", (double)p->fov);
    pparam *q;
    if ((st = pb_typed(&p->pd, "screenwindow", TB(PT_FLOAT), "4 floats", &q))) return st;
    if (q) {
        if (q->nnum != 4) return pfail(p, q->line, PK_ERR_PARSE, "'float screenwindow' takes 4 values, not %zu", q->nnum);
        for (int i = 0; i < 4; i++) p->screen[i] = (float)q->num[i];
        if (!(p->screen[1] > p->screen[0]) || !(p->screen[3] > p->screen[2]))
            return pfail(p, q->line, PK_ERR_PARSE, "camera: the screen window is empty");
        p->has_screen = true;
    }
    float so = 0.0f, sc = 1.0f;
    if ((st = pb_float(&p->pd, "shutteropen", &so)) || (st = pb_float(&p->pd, "shutterclose", &sc))) return st;
    if (!(sc > so)) return pfail(p, p->line, PK_ERR_PARSE, "camera: 'shutterclose' must be after 'shutteropen'");
    p->exposure_time = sc - so;
    static const char *const quiet[] = {"near", "far", "hither", "yon"};
    pd_declare(&p->pd, quiet, sizeof quiet / sizeof quiet[0]);
    xform inv;
    if (!xform_invert(sb_transform(&p->b), &inv))
        return pfail(p, p->line, PK_ERR_PARSE, "camera: the current transform is singular (no camera can be placed)");
    pk_status cs = set_coords(p, "camera", &inv);
    if (cs) return cs;
    /* pbrt: the camera sits in the outside medium current here */
    p->cam_mi = GS(p)->mi_out;
    p->cam_mi_line = p->line;
    snprintf(p->cam_mi_file, sizeof p->cam_mi_file, "%s", p->f->name);
    p->cam_set = true;
    p->cam_from_world = *sb_transform(&p->b);
    p->cam_line = p->line;
    p->cam_file = p->f->name;
    warn_unused(p, "Camera");
    return PK_OK;
}

/* The camera at WorldBegin: pbrt's camera frame, the world mirror when that
 * frame is pbrt's usual left-handed one, and the vertical fov. */
static pk_status finish_camera(pp *p)
{
    xform wfc;
    if (!xform_invert(&p->cam_from_world, &wfc))
        return pfail(p, p->cam_line, PK_ERR_PARSE, "camera: the camera transform is singular");
    vec3 eye = xform_point(&wfc, v3s(0.0f));
    vec3 fwd = v3_norm_scaled(xform_vector(&wfc, v3(0.0f, 0.0f, 1.0f)));
    vec3 up = v3_norm_scaled(xform_vector(&wfc, v3(0.0f, 1.0f, 0.0f)));
    vec3 right = xform_vector(&wfc, v3(1.0f, 0.0f, 0.0f));
    vec3 n = v3_norm_scaled(v3_cross(fwd, up)); /* Paprsek's right */
    p->mirror = xform_identity();
    if (v3_dot(n, right) < 0.0f) {
        /* reflection across the plane through eye with normal n */
        float *m = p->mirror.m;
        float nv[3] = {n.x, n.y, n.z}, e[3] = {eye.x, eye.y, eye.z};
        float ne = n.x * eye.x + n.y * eye.y + n.z * eye.z;
        for (int r = 0; r < 3; r++) {
            for (int c = 0; c < 3; c++) m[4 * r + c] = (r == c ? 1.0f : 0.0f) - 2.0f * nv[r] * nv[c];
            m[4 * r + 3] = 2.0f * ne * nv[r];
        }
        (void)e;
    }
    pk_camera cam;
    camera_look(&cam, eye, v3_add(eye, fwd), up);
    /* the screen window: pbrt's default spans [-1, 1] on the shorter axis */
    const float w = (float)p->film_w, h = (float)p->film_h;
    float aspect = p->frame_aspect > 0.0f ? p->frame_aspect : w / h;
    float sx0, sx1, sy0, sy1;
    if (p->has_screen) sx0 = p->screen[0], sx1 = p->screen[1], sy0 = p->screen[2], sy1 = p->screen[3];
    else if (aspect > 1.0f) sx0 = -aspect, sx1 = aspect, sy0 = -1.0f, sy1 = 1.0f;
    else sx0 = -1.0f, sx1 = 1.0f, sy0 = -1.0f / aspect, sy1 = 1.0f / aspect;
    if (fabsf(sx0 + sx1) > 1e-4f * (sx1 - sx0) || fabsf(sy0 + sy1) > 1e-4f * (sy1 - sy0))
        pwarn(p, p->cam_line, "camera: an off-centre screen window is rendered centred");
    float pix_aspect = ((sx1 - sx0) / w) / ((sy1 - sy0) / h);
    if (fabsf(pix_aspect - 1.0f) > 1e-3f)
        pwarn(p, p->cam_line, "camera: the screen window's shape does not match the film's (non-square pixels); the "
                              "vertical extent is kept");
    float half_y = 0.5f * (sy1 - sy0);
    float t = tanf(0.5f * p->fov * PK_PI / 180.0f) * half_y;
    cam.fov_deg = 2.0f * atanf(t) * 180.0f / PK_PI;
    if (p->ortho) {
        /* pbrt's orthographic screen window is in camera-space units */
        cam.projection = PK_PROJECTION_ORTHOGRAPHIC;
        cam.ortho_width = sx1 - sx0;
        cam.fov_deg = 45.0f;
    }
    if (p->lens_radius > 0.0f) {
        if (!(p->focal_distance > 0.0f))
            return pfail(p, p->cam_line, PK_ERR_PARSE, "camera: 'focaldistance' %g must be positive",
                         (double)p->focal_distance);
        cam.lens_radius = p->lens_radius;
        cam.focus_distance = p->focal_distance;
    }
    if (!(cam.fov_deg > 0.0f && cam.fov_deg < 180.0f))
        return pfail(p, p->cam_line, PK_ERR_PARSE, "camera: the vertical field of view is out of range");
    if (scene_set_camera(p->s, &cam) != CAMERA_OK)
        return pfail(p, p->cam_line, PK_ERR_PARSE, "camera: the camera transform gives no usable camera");
    return PK_OK;
}

static pk_status d_film(pp *p, const char *type)
{
    (void)type;
    pk_status st;
    const pk_int_option *ow = pk_int_option_find("width"), *oh = pk_int_option_find("height");
    int64_t w = p->film_w, h = p->film_h;
    if ((st = pb_int(&p->pd, "xresolution", ow->min, ow->max, &w)) ||
        (st = pb_int(&p->pd, "yresolution", oh->min, oh->max, &h)))
        return st;
    if ((uint64_t)w * (uint64_t)h > (uint64_t)PK_MAX_IMAGE_PIXELS)
        return pfail(p, p->line, PK_ERR_LIMIT, "Film: %lldx%lld is more than %u pixels", (long long)w, (long long)h,
                     (unsigned)PK_MAX_IMAGE_PIXELS);
    p->film_w = (int)w, p->film_h = (int)h;
    pparam *q;
    if ((st = pb_typed(&p->pd, "cropwindow", TB(PT_FLOAT), "4 floats", &q))) return st;
    if (q) pwarn(p, q->line, "Film: crop windows are not supported; the whole image is rendered");
    if ((st = pb_typed(&p->pd, "pixelbounds", TB(PT_INT), "4 integers", &q))) return st;
    if (q) pwarn(p, q->line, "Film: pixel bounds are not supported; the whole image is rendered");
    /* pbrt's sensor scales what it records by exposure time x ISO / 100 */
    float iso = 100.0f;
    const char *sensor = "cie1931";
    if ((st = pb_float(&p->pd, "iso", &iso)) || (st = pb_string(&p->pd, "sensor", &sensor))) return st;
    if (!(iso > 0.0f)) return pfail(p, p->line, PK_ERR_PARSE, "Film: 'iso' %g must be positive", (double)iso);
    p->film_iso = iso;
    if (strcmp(sensor, "cie1931") != 0) {
        /* pbrt-v4's measured cameras (Jiang et al., "What is the space of
         * spectral sensitivity functions for digital color cameras?", 2013) */
        static const char *const cameras[] = {
            "canon_eos_100d",  "canon_eos_1dx_mkii", "canon_eos_200d",  "canon_eos_200d_mkii", "canon_eos_5d",
            "canon_eos_5d_mkii", "canon_eos_5d_mkiii", "canon_eos_5d_mkiv", "canon_eos_5ds",   "canon_eos_m",
            "hasselblad_l1d_20c", "nikon_d810",       "nikon_d850",      "sony_ilce_6400",      "sony_ilce_7m3",
            "sony_ilce_7rm3",  "sony_ilce_9"};
        bool camera = false;
        for (size_t i = 0; i < sizeof cameras / sizeof cameras[0]; i++) camera = camera || strcmp(sensor, cameras[i]) == 0;
        if (camera)
            pwarn(p, p->line,
                  "Film: the camera sensor \"%s\" is not simulated (colours as the CIE 1931 observer sees them)", sensor);
        else
            pwarn(p, p->line, "Film: unknown sensor \"%.40s\" (colours as the CIE 1931 observer sees them)", sensor);
    }
    if (pb_param(&p->pd, "whitebalance")) pwarn(p, p->line, "Film: white balance is not applied");
    /* the output file is named on the command line; the rest is the film's look */
    static const char *const quiet[] = {"filename", "diagonal", "maxcomponentvalue", "savefp16", "writefp16"};
    pd_declare(&p->pd, quiet, sizeof quiet / sizeof quiet[0]);
    warn_unused(p, "Film");
    return PK_OK;
}

static pk_status d_sampler(pp *p, const char *type)
{
    (void)type;
    int64_t spp = -1;
    const pk_int_option *o = pk_int_option_find("spp");
    pk_status st = pb_int(&p->pd, "pixelsamples", 1, INT64_C(1) << 40, &spp);
    if (st) return st;
    if (spp > 0) {
        if (spp > o->max) {
            pwarn(p, p->line, "pixelsamples %lld is more than %d; using %d", (long long)spp, o->max, o->max);
            spp = o->max;
        }
        if ((st = scene_render_int(p->ctx, p->s, "spp", (int)spp))) return st;
    }
    static const char *const quiet[] = {"seed", "randomization", "jitter", "xsamples", "ysamples", "dimensions"};
    pd_declare(&p->pd, quiet, sizeof quiet / sizeof quiet[0]);
    warn_unused(p, "Sampler");
    return PK_OK;
}

/* PixelFilter: pbrt-v4's filters and their defaults ("sinc" is the lanczos
 * filter); an unknown one is warned about and the default gaussian kept. */
static pk_status d_pixel_filter(pp *p, const char *type)
{
    static const struct {
        const char *name;
        pk_filter_type t;
    } names[] = {{"box", PK_FILTER_BOX},
                 {"triangle", PK_FILTER_TRIANGLE},
                 {"gaussian", PK_FILTER_GAUSSIAN},
                 {"mitchell", PK_FILTER_MITCHELL},
                 {"sinc", PK_FILTER_LANCZOS}};
    int k = -1;
    for (int i = 0; i < (int)(sizeof names / sizeof names[0]); i++)
        if (strcmp(type, names[i].name) == 0) k = i;
    if (k < 0) {
        pd_mark_all(&p->pd);
        pwarn(p, p->line, "PixelFilter \"%.40s\" is not known; using \"gaussian\"", type);
        return PK_OK;
    }
    pk_filter f;
    pk_filter_init(&f, names[k].t);
    pk_status st;
    if ((st = pb_float(&p->pd, "xradius", &f.radius_x)) || (st = pb_float(&p->pd, "yradius", &f.radius_y))) return st;
    if (f.type == PK_FILTER_GAUSSIAN && (st = pb_float(&p->pd, "sigma", &f.sigma))) return st;
    if (f.type == PK_FILTER_MITCHELL && ((st = pb_float(&p->pd, "B", &f.b)) || (st = pb_float(&p->pd, "C", &f.c))))
        return st;
    if (f.type == PK_FILTER_LANCZOS && (st = pb_float(&p->pd, "tau", &f.tau))) return st;
    warn_unused(p, "PixelFilter");
    float *r[2] = {&f.radius_x, &f.radius_y};
    for (int i = 0; i < 2; i++) {
        if (!(*r[i] > 0.0f))
            return pfail(p, p->line, PK_ERR_PARSE, "PixelFilter \"%s\": %s %g must be positive", type,
                         i ? "yradius" : "xradius", (double)*r[i]);
        if (*r[i] > PK_FILTER_MAX_RADIUS) {
            pwarn(p, p->line, "PixelFilter \"%s\": %s %g is more than %g pixels; using %g", type,
                  i ? "yradius" : "xradius", (double)*r[i], (double)PK_FILTER_MAX_RADIUS,
                  (double)PK_FILTER_MAX_RADIUS);
            *r[i] = PK_FILTER_MAX_RADIUS;
        }
    }
    if (f.type == PK_FILTER_GAUSSIAN && !(f.sigma > 0.0f && isfinite(f.sigma)))
        return pfail(p, p->line, PK_ERR_PARSE, "PixelFilter \"gaussian\": sigma %g must be positive", (double)f.sigma);
    if (f.type == PK_FILTER_MITCHELL && !(fabsf(f.b) <= 16.0f && fabsf(f.c) <= 16.0f))
        return pfail(p, p->line, PK_ERR_PARSE, "PixelFilter \"mitchell\": B %g and C %g must be in [-16, 16]",
                     (double)f.b, (double)f.c);
    if (f.type == PK_FILTER_LANCZOS && !(f.tau > 0.0f && f.tau <= 1024.0f))
        return pfail(p, p->line, PK_ERR_PARSE, "PixelFilter \"sinc\": tau %g must be in (0, 1024]", (double)f.tau);
    return scene_render_filter(p->ctx, p->s, &f);
}

static pk_status d_integrator(pp *p, const char *type)
{
    static const char *const pathlike[] = {"path", "volpath", "bdpt", "mlt", "sppm", "lightpath", "simplepath",
                                           "simplevolpath", NULL};
    bool ok = false;
    for (int i = 0; pathlike[i]; i++) ok |= strcmp(type, pathlike[i]) == 0;
    int64_t md = 5;
    bool reg = false;
    pk_status st;
    if ((st = pb_int(&p->pd, "maxdepth", 0, INT32_MAX, &md)) || (st = pb_bool(&p->pd, "regularize", &reg))) return st;
    if (!ok) {
        pd_mark_all(&p->pd);
        pwarn(p, p->line, "integrator \"%.40s\" is not supported; rendered with the path tracer", type);
    } else if (strcmp(type, "simplevolpath") == 0) {
        pwarn(p, p->line, "integrator \"simplevolpath\" is rendered with the volumetric path tracer (volpath)");
    } else if (strcmp(type, "path") != 0 && strcmp(type, "volpath") != 0) {
        pwarn(p, p->line, "integrator \"%.40s\" is rendered with the path tracer", type);
    }
    scene_render_integrator(p->s, strcmp(type, "volpath") == 0 || strcmp(type, "simplevolpath") == 0
                                      ? PK_INTEGRATOR_VOLPATH
                                      : PK_INTEGRATOR_PATH);
    if ((st = scene_render_int(p->ctx, p->s, "max_depth", md > PK_MAX_DEPTH ? PK_MAX_DEPTH : (int)md)) ||
        (st = scene_render_int(p->ctx, p->s, "regularize", reg ? 1 : 0)))
        return st;
    static const char *const quiet[] = {"lightsampler", "samplelights", "samplebsdf", "iterations", "photonsperiteration",
                                        "radius", "seed", "visualizestrategies", "visualizeweights", "mutationsperpixel",
                                        "largestepprobability", "sigma", "bootstrapsamples", "chains"};
    pd_declare(&p->pd, quiet, sizeof quiet / sizeof quiet[0]);
    warn_unused(p, "Integrator");
    return PK_OK;
}

/* ---- participating media: MakeNamedMedium ----------------------------------------------------- */

/* pbrt-v4's "preset" media: the measured reduced scattering and absorption
 * coefficients (per mm; red, green, blue) of Jensen, Marschner, Levoy and
 * Hanrahan, "A Practical Model for Subsurface Light Transport" (2001). */
static const struct {
    const char *name;
    float ss[3], sa[3];
} medium_presets[] = {
    {"Apple", {2.29f, 2.39f, 1.97f}, {0.0030f, 0.0034f, 0.046f}},
    {"Chicken1", {0.15f, 0.21f, 0.38f}, {0.015f, 0.077f, 0.19f}},
    {"Chicken2", {0.19f, 0.25f, 0.32f}, {0.018f, 0.088f, 0.20f}},
    {"Cream", {7.38f, 5.47f, 3.15f}, {0.0002f, 0.0028f, 0.0163f}},
    {"Ketchup", {0.18f, 0.07f, 0.03f}, {0.061f, 0.97f, 1.45f}},
    {"Marble", {2.19f, 2.62f, 3.00f}, {0.0021f, 0.0041f, 0.0071f}},
    {"Potato", {0.68f, 0.70f, 0.55f}, {0.0024f, 0.0090f, 0.12f}},
    {"Skimmilk", {0.70f, 1.22f, 1.90f}, {0.0014f, 0.0025f, 0.0142f}},
    {"Skin1", {0.74f, 0.88f, 1.01f}, {0.032f, 0.17f, 0.48f}},
    {"Skin2", {1.09f, 1.59f, 1.79f}, {0.013f, 0.070f, 0.145f}},
    {"Spectralon", {11.6f, 20.4f, 14.9f}, {0.0f, 0.0f, 0.0f}},
    {"Wholemilk", {2.55f, 3.21f, 3.77f}, {0.0011f, 0.0024f, 0.014f}},
};

/* A medium's spectrum parameter (sigma_a, sigma_s; Le with illuminant) as
 * RGB, >= 0; *v keeps its default when the parameter is absent. */
static pk_status medium_spectrum(pp *p, const char *what, const char *name, bool illuminant, vec3 *v)
{
    pparam *q;
    pk_status st = pb_typed(&p->pd, name, TB(PT_RGB) | TB(PT_SPECTRUM) | TB(PT_BLACKBODY) | TB(PT_FLOAT),
                            "a spectrum (rgb, spectrum, blackbody or float)", &q);
    if (st || !q) return st;
    if (q->type == PT_RGB && q->nnum != 3)
        return pfail(p, q->line, PK_ERR_PARSE, "%s: 'rgb %s' takes 3 values, not %zu", what, name, q->nnum);
    if ((st = spectrum_rgb(p, q, illuminant, v))) return st;
    if (q->type == PT_SPECTRUM) *v = v3_max(*v, v3s(0.0f)); /* a spectrum's RGB may dip below 0 */
    if (!v3_finite(*v) || v->x < 0.0f || v->y < 0.0f || v->z < 0.0f)
        return pfail(p, q->line, PK_ERR_PARSE, "%s: '%s %s' (%g, %g, %g) must be finite and >= 0", what, q->tname, name,
                     (double)v->x, (double)v->y, (double)v->z);
    return PK_OK;
}

/* A medium's float parameter, which must lie in [lo, hi]. */
static pk_status medium_float(pp *p, const char *what, const char *name, float lo, float hi, float *v)
{
    const pparam *q = pb_param(&p->pd, name);
    pk_status st = pb_float(&p->pd, name, v);
    if (st) return st;
    if (q && !(*v >= lo && *v <= hi))
        return pfail(p, q->line, PK_ERR_PARSE, "%s: '%s %s' %g must lie in %g..%g", what, q->tname, name, (double)*v,
                     (double)lo, (double)hi);
    return PK_OK;
}

/* The grid's size: nx, ny, nz (pbrt's defaults 1), within the voxel limit. */
static pk_status medium_dims(pp *p, const char *what, int n[3], size_t *count)
{
    static const char *const names[3] = {"nx", "ny", "nz"};
    double total = 1.0;
    for (int a = 0; a < 3; a++) {
        int64_t v = 1;
        pk_status st = pb_int(&p->pd, names[a], 1, (int64_t)MEDIUM_MAX_VOXELS, &v);
        if (st) return st;
        n[a] = (int)v;
        total *= (double)v;
    }
    if (total > (double)MEDIUM_MAX_VOXELS)
        return pfail(p, p->line, PK_ERR_LIMIT, "%s: a grid of %dx%dx%d voxels is over the limit of %zu", what, n[0], n[1],
                     n[2], (size_t)MEDIUM_MAX_VOXELS);
    *count = (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
    return PK_OK;
}

/* The grid of array parameter q (ch values a voxel), count voxels of size
 * n, each value finite and >= 0; allocated as the scene's. */
static pk_status medium_grid_param(pp *p, const char *what, const pparam *q, int ch, const int n[3], size_t count,
                                   medium_grid *g)
{
    const size_t want = count * (size_t)ch;
    if (q->nnum != want)
        return pfail(p, q->line, PK_ERR_PARSE,
                     "%s: '%s %s' has %zu values; nx x ny x nz = %d x %d x %d needs %zu (%d a voxel)", what, q->tname,
                     q->name, q->nnum, n[0], n[1], n[2], want, ch);
    float *d = mem_calloc(&p->s->alloc, want, sizeof *d);
    if (!d) return ctx_nomem(p->ctx);
    for (size_t i = 0; i < want; i++) {
        d[i] = (float)q->num[i];
        if (!isfinite(d[i]) || d[i] < 0.0f) {
            mem_free(&p->s->alloc, d);
            return pfail(p, q->line, PK_ERR_PARSE, "%s: '%s %s' value %zu is %g (values must be finite and >= 0)", what,
                         q->tname, q->name, i, q->num[i]);
        }
    }
    g->nx = n[0], g->ny = n[1], g->nz = n[2], g->channels = ch, g->data = d;
    return PK_OK;
}

/* The box p0..p1 of a grid medium as the map from the unit cube. */
static pk_status medium_box(pp *p, const char *what, xform *box)
{
    vec3 p0 = v3s(0.0f), p1 = v3s(1.0f);
    pk_status st;
    if ((st = pb_vec3(&p->pd, "p0", &p0)) || (st = pb_vec3(&p->pd, "p1", &p1))) return st;
    const vec3 lo = v3_min(p0, p1), ext = v3_sub(v3_max(p0, p1), lo);
    if (!(ext.x > 0.0f && ext.y > 0.0f && ext.z > 0.0f) || !v3_finite(ext))
        return pfail(p, p->line, PK_ERR_PARSE, "%s: the box p0 (%g, %g, %g) .. p1 (%g, %g, %g) has no volume", what,
                     (double)p0.x, (double)p0.y, (double)p0.z, (double)p1.x, (double)p1.y, (double)p1.z);
    const xform t = xform_translate(lo), s = xform_scale(ext);
    *box = xform_mul(&t, &s);
    return PK_OK;
}

#define BB_TABLE 2048
#define BB_TMIN 100.0
#define BB_TMAX 1e5

/* uniformgrid's "temperature": emission from a blackbody at each voxel's
 * temperature (temperature - temperatureoffset) x temperaturescale, none
 * at 100 K or below, times Lescale (one value: lsc, or the emission grid
 * already read). pbrt interpolates the temperature between voxels and then
 * takes the blackbody's colour; here each voxel's colour is interpolated. */
static pk_status medium_temperature(pp *p, const char *what, medium *m, const pparam *tq, const int n[3], size_t count,
                                    float lsc)
{
    float off = 0.0f, sc = 1.0f;
    pk_status st;
    if (pb_param(&p->pd, "temperatureoffset")) st = pb_float(&p->pd, "temperatureoffset", &off);
    else st = pb_float(&p->pd, "temperaturecutoff", &off);
    if (st || (st = pb_float(&p->pd, "temperaturescale", &sc))) return st;
    medium_grid tg = {0};
    if ((st = medium_grid_param(p, what, tq, 1, n, count, &tg))) return st;
    float *e = mem_calloc(&p->s->alloc, count * 3, sizeof *e);
    vec3 *table = mem_calloc(A(p), BB_TABLE, sizeof *table);
    if (!e || !table) {
        mem_free(&p->s->alloc, tg.data);
        mem_free(&p->s->alloc, e);
        mem_free(A(p), table);
        return ctx_nomem(p->ctx);
    }
    /* the colours on a geometric scale of temperatures, interpolated */
    const double step = log(BB_TMAX / BB_TMIN) / (BB_TABLE - 1);
    for (int i = 0; i < BB_TABLE; i++) table[i] = spectra_pbrt_blackbody_peak(BB_TMIN * exp(step * i));
    for (size_t v = 0; v < count; v++) {
        const double t = ((double)tg.data[v] - (double)off) * (double)sc;
        vec3 c = v3s(0.0f);
        if (t > BB_TMAX) {
            c = spectra_pbrt_blackbody_peak(t);
        } else if (t > BB_TMIN) {
            const double x = log(t / BB_TMIN) / step;
            int i = (int)x;
            if (i > BB_TABLE - 2) i = BB_TABLE - 2;
            /* geometric between neighbours (the colours grow about
             * exponentially with the temperature), linear where one is 0 */
            const double f = x - i;
            const float a[3] = {table[i].x, table[i].y, table[i].z}, b[3] = {table[i + 1].x, table[i + 1].y, table[i + 1].z};
            float o[3];
            for (int k = 0; k < 3; k++)
                o[k] = a[k] > 0.0f && b[k] > 0.0f ? (float)exp((1.0 - f) * log((double)a[k]) + f * log((double)b[k]))
                                                  : (float)((1.0 - f) * (double)a[k] + f * (double)b[k]);
            c = v3(o[0], o[1], o[2]);
        }
        const float k = m->emission_grid.data ? m->emission_grid.data[v] : lsc;
        e[3 * v] = c.x * k, e[3 * v + 1] = c.y * k, e[3 * v + 2] = c.z * k;
        if (!isfinite(e[3 * v]) || !isfinite(e[3 * v + 1]) || !isfinite(e[3 * v + 2])) {
            mem_free(&p->s->alloc, tg.data);
            mem_free(&p->s->alloc, e);
            mem_free(A(p), table);
            return pfail(p, tq->line, PK_ERR_PARSE, "%s: the emission of voxel %zu (%g K) is not finite", what, v, t);
        }
    }
    mem_free(&p->s->alloc, tg.data);
    mem_free(A(p), table);
    mem_free(&p->s->alloc, m->emission_grid.data);
    m->emission_grid = (medium_grid){n[0], n[1], n[2], 3, e};
    m->le = v3s(1.0f);
    return PK_OK;
}

/* pbrt-v4's "uniformgrid": a density grid (float, or rgb: 3 channels) times
 * sigma_a + sigma_s, emission Le times Lescale (one value, or a grid). */
static pk_status medium_uniformgrid(pp *p, const char *what, medium *m)
{
    int n[3];
    size_t count;
    pk_status st;
    pparam *dq, *lq, *tq;
    if ((st = medium_dims(p, what, n, &count))) return st;
    if ((st = pb_typed(&p->pd, "density", TB(PT_FLOAT) | TB(PT_RGB), "floats (or rgb triples)", &dq))) return st;
    if (!dq) return pfail(p, p->line, PK_ERR_PARSE, "%s: uniformgrid needs 'float density' (nx x ny x nz values)", what);
    if ((st = pb_typed(&p->pd, "temperature", TB(PT_FLOAT), "floats", &tq))) return st;
    if ((st = medium_grid_param(p, what, dq, dq->type == PT_RGB ? 3 : 1, n, count, &m->density))) return st;
    vec3 le = v3s(0.0f);
    pparam *leq = pb_param(&p->pd, "Le");
    if (tq && leq) return pfail(p, leq->line, PK_ERR_PARSE, "%s: give 'Le' or 'temperature', not both", what);
    if ((st = medium_spectrum(p, what, "Le", true, &le))) return st;
    if ((st = pb_typed(&p->pd, "Lescale", TB(PT_FLOAT), "floats", &lq))) return st;
    float lsc = 1.0f;
    if (lq && lq->nnum == 1) {
        if ((st = medium_float(p, what, "Lescale", 0.0f, 3.4e38f, &lsc))) return st;
    } else if (lq && (v3_max_comp(le) > 0.0f || tq)) {
        if ((st = medium_grid_param(p, what, lq, 1, n, count, &m->emission_grid))) return st;
    }
    m->le = v3_scale(le, lsc);
    m->kind = MEDIUM_GRID;
    if (tq) return medium_temperature(p, what, m, tq, n, count, lsc);
    return PK_OK;
}

/* pbrt-v4's "rgbgrid": grids of sigma_a and sigma_s (RGB; an absent one is
 * 1) and of Le; Paprsek's model takes the extinction sigma_a + sigma_s as
 * a 3-channel density under sigma_t = scale, the albedo sigma_s /
 * (sigma_a + sigma_s) as an albedo grid and Le as the emission grid. */
static pk_status medium_rgbgrid(pp *p, const char *what, medium *m, float scale)
{
    int n[3];
    size_t count;
    pk_status st;
    pparam *qa, *qs, *ql;
    if ((st = medium_dims(p, what, n, &count))) return st;
    if ((st = pb_typed(&p->pd, "sigma_a", TB(PT_RGB), "rgb values", &qa)) ||
        (st = pb_typed(&p->pd, "sigma_s", TB(PT_RGB), "rgb values", &qs)) ||
        (st = pb_typed(&p->pd, "Le", TB(PT_RGB), "rgb values", &ql)))
        return st;
    if (!qa && !qs)
        return pfail(p, p->line, PK_ERR_PARSE, "%s: rgbgrid needs 'rgb sigma_a' and/or 'rgb sigma_s' (nx x ny x nz rgb values)",
                     what);
    if (ql && !qa) return pfail(p, ql->line, PK_ERR_PARSE, "%s: rgbgrid: 'rgb Le' needs 'rgb sigma_a' as well", what);
    medium_grid ga = {0}, gs = {0};
    if ((qa && (st = medium_grid_param(p, what, qa, 3, n, count, &ga))) ||
        (qs && (st = medium_grid_param(p, what, qs, 3, n, count, &gs))) ||
        (ql && (st = medium_grid_param(p, what, ql, 3, n, count, &m->emission_grid)))) {
        mem_free(&p->s->alloc, ga.data);
        mem_free(&p->s->alloc, gs.data);
        return st;
    }
    float *dens = mem_calloc(&p->s->alloc, count * 3, sizeof *dens);
    float *alb = mem_calloc(&p->s->alloc, count * 3, sizeof *alb);
    if (!dens || !alb) {
        mem_free(&p->s->alloc, dens);
        mem_free(&p->s->alloc, alb);
        mem_free(&p->s->alloc, ga.data);
        mem_free(&p->s->alloc, gs.data);
        return ctx_nomem(p->ctx);
    }
    for (size_t i = 0; i < count * 3; i++) {
        const float a = ga.data ? ga.data[i] : 1.0f, s = gs.data ? gs.data[i] : 1.0f, t = a + s;
        dens[i] = t;
        alb[i] = t > 0.0f ? fminf(s / t, 1.0f) : 0.0f;
    }
    mem_free(&p->s->alloc, ga.data);
    mem_free(&p->s->alloc, gs.data);
    m->density = (medium_grid){n[0], n[1], n[2], 3, dens};
    m->albedo_grid = (medium_grid){n[0], n[1], n[2], 3, alb};
    m->sigma_t = v3s(scale);
    m->albedo = v3s(1.0f);
    float lsc = 1.0f;
    if ((st = medium_float(p, what, "Lescale", 0.0f, 3.4e38f, &lsc))) return st;
    m->le = m->emission_grid.data ? v3s(lsc) : v3s(0.0f);
    m->kind = MEDIUM_GRID;
    return PK_OK;
}

/* pbrt-v4's "nanovdb": the density grid (or 'gridname') of a NanoVDB file,
 * placed in its box of the file's space (*box); sigma_a, sigma_s and scale
 * as for the other media. Temperature grids are not read. */
static pk_status medium_nanovdb(pp *p, const char *what, medium *m, xform *box)
{
    const char *fn = NULL, *gname = "density";
    pk_status st;
    if ((st = pb_string(&p->pd, "filename", &fn)) || (st = pb_string(&p->pd, "gridname", &gname))) return st;
    if (!fn) return pfail(p, p->line, PK_ERR_PARSE, "%s: nanovdb needs 'string filename'", what);
    static const char *const temp[] = {"temperaturename", "temperaturecutoff", "temperatureoffset", "temperaturescale",
                                       "Lescale", NULL};
    for (int i = 0; temp[i]; i++)
        if (pb_param(&p->pd, temp[i]))
            pwarn(p, pb_param(&p->pd, temp[i])->line,
                  "%s: temperature grids are not read; the medium does not emit ('%s' ignored)", what, temp[i]);
    char *path = path_join(A(p), p->f->dir, fn);
    if (!path) return ctx_nomem(p->ctx);
    aabb b;
    pk_context tmp = io_scratch_context(p->ctx);
    st = grid_read_nanovdb(&tmp, &p->s->alloc, path, gname, &m->density, &b);
    mem_free(A(p), path);
    if (st != PK_OK) {
        if (st == PK_ERR_NOMEM) return ctx_nomem(p->ctx);
        return pfail(p, p->line, st, "%s: %s", what, tmp.message);
    }
    const vec3 ext = v3_sub(b.hi, b.lo);
    if (!(ext.x > 0.0f && ext.y > 0.0f && ext.z > 0.0f) || !v3_finite(ext) || !v3_finite(b.lo))
        return pfail(p, p->line, PK_ERR_PARSE, "%s: the grid of \"%.80s\" spans no volume", what, fn);
    const xform t = xform_translate(b.lo), s = xform_scale(ext);
    *box = xform_mul(&t, &s);
    m->kind = MEDIUM_GRID;
    return PK_OK;
}

/* ---- pbrt-v4's procedural "cloud", baked into a grid ---- */

/* Gradient noise (Perlin's construction: a gradient at each lattice point,
 * picked by hashing the point among the 12 directions to the cube's edge
 * midpoints, blended with the quintic fade), in about -1..1, and its
 * gradient *d. Paprsek's own hash: not pbrt's pattern. */
static float cloud_noise(vec3 p, vec3 *d)
{
    static const signed char dirs[12][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1}, {-1, 0, 1},
                                            {1, 0, -1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1}};
    const float fl[3] = {floorf(p.x), floorf(p.y), floorf(p.z)};
    const float f[3] = {p.x - fl[0], p.y - fl[1], p.z - fl[2]};
    const int32_t ip[3] = {(int32_t)fl[0], (int32_t)fl[1], (int32_t)fl[2]};
    float u[3], du[3];
    for (int a = 0; a < 3; a++) {
        const float t = f[a];
        u[a] = t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f);
        du[a] = 30.0f * t * t * (t * (t - 2.0f) + 1.0f);
    }
    float v = 0.0f, g[3] = {0.0f, 0.0f, 0.0f};
    for (int c = 0; c < 8; c++) {
        const int o[3] = {c & 1, (c >> 1) & 1, (c >> 2) & 1};
        uint32_t h = (uint32_t)(ip[0] + o[0]) * 0x8da6b343u ^ (uint32_t)(ip[1] + o[1]) * 0xd8163841u ^
                     (uint32_t)(ip[2] + o[2]) * 0xcb1ab31fu;
        h ^= h >> 15, h *= 0x2c1b3c6du, h ^= h >> 12, h *= 0x297a2d39u, h ^= h >> 15;
        const signed char *gr = dirs[h % 12u];
        const float r[3] = {f[0] - (float)o[0], f[1] - (float)o[1], f[2] - (float)o[2]};
        const float n = (float)gr[0] * r[0] + (float)gr[1] * r[1] + (float)gr[2] * r[2];
        float w[3], dw[3];
        for (int a = 0; a < 3; a++) w[a] = o[a] ? u[a] : 1.0f - u[a], dw[a] = o[a] ? du[a] : -du[a];
        const float wt = w[0] * w[1] * w[2];
        v += wt * n;
        g[0] += dw[0] * w[1] * w[2] * n + wt * (float)gr[0];
        g[1] += w[0] * dw[1] * w[2] * n + wt * (float)gr[1];
        g[2] += w[0] * w[1] * dw[2] * n + wt * (float)gr[2];
    }
    if (d) *d = v3(g[0], g[1], g[2]);
    return v;
}

/* The density of pbrt-v4's cloud at p (medium space): the lookup point
 * displaced by two octaves of the noise's gradient (wispiness), five
 * octaves of noise summed, thinning with height y and filling below
 * y = 1/2, clamped to 0..1, as pbrt builds it. */
static float cloud_density(vec3 p, float density, float wisp, float freq)
{
    vec3 q = v3_scale(p, freq);
    if (wisp > 0.0f) {
        float om = 0.05f * wisp, la = 10.0f;
        for (int i = 0; i < 2; i++) {
            vec3 dn;
            cloud_noise(v3_scale(q, la), &dn);
            q = v3_add(q, v3_scale(dn, om));
            om *= 0.5f, la *= 1.99f;
        }
    }
    float d = 0.0f, om = 0.5f, la = 1.0f;
    for (int i = 0; i < 5; i++) {
        d += om * cloud_noise(v3_scale(q, la), NULL);
        om *= 0.5f, la *= 1.99f;
    }
    d = fminf(fmaxf((1.0f - p.y) * 4.5f * density * d, 0.0f), 1.0f);
    d += 2.0f * fmaxf(0.0f, 0.5f - p.y);
    return fminf(fmaxf(d, 0.0f), 1.0f);
}

/* pbrt-v4's "cloud" (density, wispiness, frequency in the box p0..p1):
 * sampled at the voxel centres of a grid of 24 voxels per unit of
 * frequency x length on each axis (16 to 128), whose trilinear lookup
 * stands for the procedure. */
static pk_status medium_cloud(pp *p, const char *what, medium *m, const xform *box)
{
    float dens = 1.0f, wisp = 1.0f, freq = 5.0f;
    pk_status st;
    if ((st = medium_float(p, what, "density", 0.0f, 3.4e38f, &dens)) ||
        (st = medium_float(p, what, "wispiness", 0.0f, 1e6f, &wisp)) ||
        (st = medium_float(p, what, "frequency", 0.0f, 1e6f, &freq)))
        return st;
    const vec3 lo = xform_point(box, v3s(0.0f)), ext = v3_sub(xform_point(box, v3s(1.0f)), lo);
    const float e[3] = {ext.x, ext.y, ext.z};
    int n[3];
    for (int a = 0; a < 3; a++) {
        const double v = ceil(24.0 * (double)freq * (double)e[a]);
        n[a] = v < 16.0 ? 16 : v > 128.0 ? 128 : (int)v;
    }
    const size_t count = (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
    float *d = mem_calloc(&p->s->alloc, count, sizeof *d);
    if (!d) return ctx_nomem(p->ctx);
    for (int k = 0; k < n[2]; k++)
        for (int j = 0; j < n[1]; j++)
            for (int i = 0; i < n[0]; i++) {
                const vec3 q = v3(((float)i + 0.5f) / (float)n[0], ((float)j + 0.5f) / (float)n[1],
                                  ((float)k + 0.5f) / (float)n[2]);
                d[((size_t)k * (size_t)n[1] + (size_t)j) * (size_t)n[0] + (size_t)i] =
                    cloud_density(xform_point(box, q), dens, wisp, freq);
            }
    m->density = (medium_grid){n[0], n[1], n[2], 1, d};
    m->kind = MEDIUM_GRID;
    return PK_OK;
}

static pk_status d_medium(pp *p, const char *name)
{
    char what[PB_NAME_MAX + 32];
    snprintf(what, sizeof what, "MakeNamedMedium \"%.80s\"", name);
    if (scene_find_medium(p->s, name) >= 0)
        return pfail(p, p->line, PK_ERR_PARSE, "%s: a medium of that name is defined already", what);
    const char *type = NULL;
    pk_status st = pb_string(&p->pd, "type", &type);
    if (st) return st;
    if (!type) return pfail(p, p->line, PK_ERR_PARSE, "%s needs 'string type'", what);
    const bool homogeneous = strcmp(type, "homogeneous") == 0, uniform = strcmp(type, "uniformgrid") == 0,
               rgb = strcmp(type, "rgbgrid") == 0, vdb = strcmp(type, "nanovdb") == 0, cloud = strcmp(type, "cloud") == 0;
    if (!homogeneous && !uniform && !rgb && !vdb && !cloud)
        return pfail(p, p->line, PK_ERR_PARSE,
                     "%s: unknown medium type \"%.40s\" (homogeneous, uniformgrid, rgbgrid, nanovdb and cloud are known)",
                     what, type);
    medium m;
    medium_init(&m);
    vec3 sa = v3s(1.0f), ss = v3s(1.0f);
    float scale = 1.0f, g = 0.0f;
    if ((st = medium_float(p, what, "scale", 0.0f, 3.4e38f, &scale)) ||
        (st = medium_float(p, what, "g", -0.9999f, 0.9999f, &g)))
        return st;
    m.g = g;
    const char *preset = NULL;
    if (homogeneous && (st = pb_string(&p->pd, "preset", &preset))) return st;
    if (preset) {
        size_t k = 0, np = sizeof medium_presets / sizeof medium_presets[0];
        while (k < np && strcmp(medium_presets[k].name, preset) != 0) k++;
        if (k == np)
            return pfail(p, pb_param(&p->pd, "preset")->line, PK_ERR_UNSUPPORTED,
                         "%s: preset \"%.60s\" is not known (Paprsek knows the measured media of Jensen et al. 2001: "
                         "Apple, Chicken1, Chicken2, Cream, Ketchup, Marble, Potato, Skimmilk, Skin1, Skin2, Spectralon, "
                         "Wholemilk)",
                         what, preset);
        sa = v3(medium_presets[k].sa[0], medium_presets[k].sa[1], medium_presets[k].sa[2]);
        ss = v3(medium_presets[k].ss[0], medium_presets[k].ss[1], medium_presets[k].ss[2]);
    } else if (!rgb) {
        if ((st = medium_spectrum(p, what, "sigma_a", false, &sa)) || (st = medium_spectrum(p, what, "sigma_s", false, &ss)))
            return st;
    }
    medium_set_coefficients(&m, sa, ss, scale);
    xform box = xform_identity();
    if (homogeneous) {
        vec3 le = v3s(0.0f);
        float lsc = 1.0f;
        if ((st = medium_spectrum(p, what, "Le", true, &le)) || (st = medium_float(p, what, "Lescale", 0.0f, 3.4e38f, &lsc)))
            return st;
        m.le = v3_scale(le, lsc);
    } else if (uniform || rgb || cloud) {
        st = medium_box(p, what, &box);
        if (st == PK_OK)
            st = uniform ? medium_uniformgrid(p, what, &m) : rgb ? medium_rgbgrid(p, what, &m, scale)
                                                                 : medium_cloud(p, what, &m, &box);
    } else {
        st = medium_nanovdb(p, what, &m, &box);
    }
    if (st == PK_OK && m.kind == MEDIUM_GRID) {
        /* placed by the current transform (pbrt's medium space); the
         * world's mirror is applied at the end (finish_media) */
        m.grid_to_world = xform_mul(sb_transform(&p->b), &box);
        if (!xform_finite(&m.grid_to_world))
            st = pfail(p, p->line, PK_ERR_PARSE, "%s: the grid's placement is not finite", what);
    }
    if (st == PK_OK && !(m.name = mem_strdup(&p->s->alloc, name))) st = ctx_nomem(p->ctx);
    if (st != PK_OK) {
        medium_free(&p->s->alloc, &m);
        return st;
    }
    uint32_t idx;
    if ((st = scene_add_medium(p->ctx, p->s, &m, &idx))) return st;
    warn_unused(p, "medium \"%.40s\"", type);
    return PK_OK;
}

/* At the end of the file: the camera's medium, and every grid medium this
 * file made placed in Paprsek's world (through the mirror of the top). */
static pk_status finish_media(pp *p)
{
    if (p->cam_mi >= 0) {
        int64_t m = scene_find_medium(p->s, p->mnames[p->cam_mi]);
        if (m < 0) {
            pfile f = p->top;
            f.name = p->cam_mi_file;
            p->f = &f;
            pk_status st = pfail(p, p->cam_mi_line, PK_ERR_PARSE,
                                 "Camera: the camera's medium \"%.80s\" (the outside medium of the MediumInterface "
                                 "before Camera) is not defined by any MakeNamedMedium",
                                 p->mnames[p->cam_mi]);
            p->f = &p->top;
            return st;
        }
        scene_set_camera_medium(p->s, (int32_t)m);
    }
    for (size_t i = p->media_start; i < p->s->nmedia; i++)
        p->s->media[i].grid_to_world = xform_mul(&p->mirror, &p->s->media[i].grid_to_world);
    return PK_OK;
}

/* ---- directives ---------------------------------------------------------------------------------- */

/* Positional arguments: n numbers (an optional bracket around them). */
static pk_status read_numbers(pp *p, double *v, int n)
{
    pbrt_tokenizer *t = &p->f->tok;
    pbrt_token tk = pbrt_tok_peek(t);
    bool br = tk.kind == PBRT_TOK_LBRACK;
    if (br) pbrt_tok_next(t);
    for (int i = 0; i < n; i++) {
        tk = pbrt_tok_next(t);
        if (tk.kind == PBRT_TOK_ERROR) return tok_error(p, &tk);
        if (tk.kind != PBRT_TOK_NUMBER)
            return pfail(p, tk.line, PK_ERR_PARSE, "%s takes %d numbers; found %s after %d", p->dname, n,
                         tk.kind == PBRT_TOK_END ? "the end of the file" : "something else", i);
        v[i] = tk.number;
        if (!isfinite(v[i]) || fabs(v[i]) > 3.4e38)
            return pfail(p, tk.line, PK_ERR_PARSE, "%s: number %d is not finite", p->dname, i + 1);
    }
    if (br) {
        tk = pbrt_tok_next(t);
        if (tk.kind != PBRT_TOK_RBRACK)
            return pfail(p, tk.line, PK_ERR_PARSE, "%s takes %d numbers; the list does not end with ']' after them",
                         p->dname, n);
    }
    return PK_OK;
}

/* A positional quoted string into buf. */
static pk_status read_name(pp *p, char *buf, size_t cap)
{
    pbrt_token tk = pbrt_tok_next(&p->f->tok);
    if (tk.kind == PBRT_TOK_ERROR) return tok_error(p, &tk);
    if (tk.kind != PBRT_TOK_STRING)
        return pfail(p, tk.line, PK_ERR_PARSE, "%s needs a quoted name here", p->dname);
    if (pbrt_tok_string(&tk, buf, cap) >= cap)
        return pfail(p, tk.line, PK_ERR_LIMIT, "%s: the name is longer than %zu bytes", p->dname, cap - 1);
    return PK_OK;
}

static pk_status parse_file(pp *p, const char *data, size_t size, const char *name, const char *dir, char *key);

static pk_status d_include(pp *p)
{
    char rel[1024];
    pk_status st = read_name(p, rel, sizeof rel);
    if (st) return st;
    if (p->nfiles > PB_MAX_INCLUDE_DEPTH)
        return pfail(p, p->line, PK_ERR_LIMIT, "%s \"%.200s\": includes nested deeper than %d", p->dname, rel,
                     PB_MAX_INCLUDE_DEPTH);
    char *path = path_join(A(p), p->f->dir, rel);
    if (!path) return ctx_nomem(p->ctx);
    for (int i = 0; i < p->nfiles; i++)
        if (p->files[i]->key && strcmp(p->files[i]->key, path) == 0) {
            st = pfail(p, p->line, PK_ERR_PARSE, "%s \"%.200s\": the file includes itself (a cycle)", p->dname, rel);
            mem_free(A(p), path);
            return st;
        }
    char *data = NULL;
    size_t size = 0;
    pk_context tmp = io_scratch_context(p->ctx);
    st = file_read_all(&tmp, path, &data, &size);
    if (st == PK_OK && io_is_gzip_name(rel)) { /* pbrt-v4 reads gzip files by their name */
        char *raw = data;
        st = io_gunzip(&tmp, path, raw, size, &data, &size);
        mem_free(A(p), raw);
    }
    if (st) {
        mem_free(A(p), path);
        if (st == PK_ERR_NOMEM) return ctx_nomem(p->ctx);
        return pfail(p, p->line, st, "%s: %s", p->dname, tmp.message);
    }
    char *dir = path_dirname(A(p), path);
    if (!dir) {
        mem_free(A(p), path);
        mem_free(A(p), data);
        return ctx_nomem(p->ctx);
    }
    st = parse_file(p, data, size, path, dir, path);
    mem_free(A(p), data);
    mem_free(A(p), dir);
    mem_free(A(p), path);
    return st;
}

static pk_status push_state(pp *p)
{
    if (!sb_push(&p->b))
        return pfail(p, p->line, PK_ERR_LIMIT, "%s: more than %d nested attribute blocks", p->dname, SB_MAX_DEPTH - 1);
    p->gs[p->b.depth] = p->gs[p->b.depth - 1];
    return PK_OK;
}

static pk_status pop_state(pp *p, bool transform_only)
{
    gstate keep = *GS(p);
    if (!sb_pop(&p->b)) return pfail(p, p->line, PK_ERR_PARSE, "%s without a matching begin", p->dname);
    defs_pop(p, p->b.depth);
    if (transform_only) *GS(p) = keep;
    return PK_OK;
}

static pk_status d_world_begin(pp *p)
{
    if (p->in_world) return pfail(p, p->line, PK_ERR_PARSE, "WorldBegin appears twice");
    p->in_world = true;
    pk_status st;
    if (!p->cam_set) {
        p->cam_set = true;
        p->cam_from_world = xform_identity();
        p->cam_line = p->line;
    }
    if ((st = finish_camera(p))) return st;
    xform id = xform_identity();
    sb_set_transform(&p->b, &id);
    p->active_end = false;
    return set_coords(p, "world", &id);
}

static named_xf *find_coords(pp *p, const char *name)
{
    for (size_t i = p->ncoords; i-- > 0;)
        if (strcmp(p->coords[i].name, name) == 0) return &p->coords[i];
    return NULL;
}

static pk_status set_coords(pp *p, const char *name, const xform *x)
{
    named_xf *c = find_coords(p, name);
    if (c) {
        c->x = *x;
        return PK_OK;
    }
    if (!mem_grow(A(p), (void **)&p->coords, &p->cap_coords, p->ncoords + 1, sizeof *p->coords)) return ctx_nomem(p->ctx);
    char *n = mem_strdup(A(p), name);
    if (!n) return ctx_nomem(p->ctx);
    p->coords[p->ncoords].name = n;
    p->coords[p->ncoords++].x = *x;
    return PK_OK;
}

static pk_status d_object_end(pp *p)
{
    if (!p->b.in_object) return pfail(p, p->line, PK_ERR_PARSE, "ObjectEnd without ObjectBegin");
    uint32_t mesh = UINT32_MAX;
    pk_status st;
    if (p->s->ntris == p->b.obj_tri) {
        p->b.in_object = false; /* nothing was added: an empty object */
    } else {
        pk_context tmp = io_scratch_context(p->ctx);
        p->b.ctx = &tmp;
        st = sb_end_object(&p->b, &mesh);
        p->b.ctx = p->ctx;
        if ((st = builder_status(p, st, &tmp))) return st;
    }
    if (!mem_grow(A(p), (void **)&p->objs, &p->cap_objs, p->nobjs + 1, sizeof *p->objs)) return ctx_nomem(p->ctx);
    p->objs[p->nobjs].name = p->obj_name;
    p->objs[p->nobjs++].mesh = mesh;
    p->obj_name = NULL;
    return pop_state(p, false);
}

static pk_status d_object_instance(pp *p, const char *name)
{
    if (p->b.in_object) return pfail(p, p->line, PK_ERR_PARSE, "ObjectInstance inside ObjectBegin/ObjectEnd");
    named_obj *o = NULL;
    for (size_t i = p->nobjs; i-- > 0;)
        if (strcmp(p->objs[i].name, name) == 0) {
            o = &p->objs[i];
            break;
        }
    if (!o) return pfail(p, p->line, PK_ERR_PARSE, "ObjectInstance: no object named \"%.80s\"", name);
    if (o->mesh == UINT32_MAX) return PK_OK;
    /* the object's triangles were placed by mirror x (their own transform);
     * the instance is mirror x CTM x mirror^-1 (the mirror is its own inverse) */
    xform c = *sb_transform(&p->b);
    xform a = xform_mul(&p->mirror, &c);
    xform w = xform_mul(&a, &p->mirror);
    double det = xform_det3(&w);
    if (!xform_finite(&w) || !(det != 0.0) || !isfinite(det) || fabs(det) < 1e-30)
        return pfail(p, p->line, PK_ERR_PARSE, "ObjectInstance \"%.80s\": the transform is singular or not finite", name);
    if (det < 0.0)
        pwarn(p, p->line, "ObjectInstance \"%.80s\": a mirroring instance turns its one-sided surfaces inside out", name);
    xform saved = c;
    sb_set_transform(&p->b, &w);
    pk_context tmp = io_scratch_context(p->ctx);
    p->b.ctx = &tmp;
    pk_status st = sb_add_instance(&p->b, o->mesh);
    p->b.ctx = p->ctx;
    sb_set_transform(&p->b, &saved);
    return builder_status(p, st, &tmp);
}

/* The directives that take no parameter list read none; every other reads
 * its list before it acts. */
static pk_status directive(pp *p, const pbrt_token *tk)
{
    char dn[32];
    /* (the token's bytes are not NUL-terminated: a (data, size) buffer may end with them) */
    if (tk->len >= sizeof dn)
        return pfail(p, tk->line, PK_ERR_PARSE, "unknown directive '%.*s'", io_tok_len(tk->text, tk->text + tk->len),
                     tk->text);
    memcpy(dn, tk->text, tk->len);
    dn[tk->len] = '\0';
    p->dname = dn;
    p->line = tk->line;
    pk_status st;
    double v[16];
    char a[PB_NAME_MAX], b2[PB_NAME_MAX], c[PB_NAME_MAX];

    /* transforms */
    if (strcmp(dn, "Identity") == 0) {
        xform id = xform_identity();
        ctm_set(p, &id);
        return PK_OK;
    }
    if (strcmp(dn, "Translate") == 0) {
        if ((st = read_numbers(p, v, 3))) return st;
        xform x = xform_translate(v3((float)v[0], (float)v[1], (float)v[2]));
        return ctm_concat(p, &x);
    }
    if (strcmp(dn, "Scale") == 0) {
        if ((st = read_numbers(p, v, 3))) return st;
        xform x = xform_scale(v3((float)v[0], (float)v[1], (float)v[2]));
        return ctm_concat(p, &x);
    }
    if (strcmp(dn, "Rotate") == 0) {
        if ((st = read_numbers(p, v, 4))) return st;
        vec3 ax = v3((float)v[1], (float)v[2], (float)v[3]);
        if (!(v3_len2(ax) > 0.0f) || !isfinite(v3_len2(ax)))
            return pfail(p, p->line, PK_ERR_PARSE, "Rotate: the axis %g %g %g has no direction", v[1], v[2], v[3]);
        xform x = xform_rotate(v3_norm_scaled(ax), (float)v[0]);
        return ctm_concat(p, &x);
    }
    if (strcmp(dn, "LookAt") == 0) {
        if ((st = read_numbers(p, v, 9))) return st;
        vec3 eye = v3((float)v[0], (float)v[1], (float)v[2]), at = v3((float)v[3], (float)v[4], (float)v[5]),
             up = v3((float)v[6], (float)v[7], (float)v[8]);
        vec3 dir = v3_sub(at, eye);
        if (!(v3_len2(dir) > 0.0f)) return pfail(p, p->line, PK_ERR_PARSE, "LookAt: the eye and the target are the same point");
        dir = v3_norm_scaled(dir);
        vec3 right = v3_cross(v3_norm_scaled(up), dir);
        if (!(v3_len(right) > 1e-6f))
            return pfail(p, p->line, PK_ERR_PARSE, "LookAt: the up vector is zero or parallel to the view direction");
        right = v3_norm_scaled(right);
        vec3 nup = v3_cross(dir, right);
        /* world from camera: columns right, up, dir, eye; LookAt concatenates its inverse */
        xform wc = xform_identity();
        wc.m[0] = right.x, wc.m[4] = right.y, wc.m[8] = right.z;
        wc.m[1] = nup.x, wc.m[5] = nup.y, wc.m[9] = nup.z;
        wc.m[2] = dir.x, wc.m[6] = dir.y, wc.m[10] = dir.z;
        wc.m[3] = eye.x, wc.m[7] = eye.y, wc.m[11] = eye.z;
        xform cw;
        if (!xform_invert(&wc, &cw)) return pfail(p, p->line, PK_ERR_PARSE, "LookAt: singular");
        return ctm_concat(p, &cw);
    }
    if (strcmp(dn, "Transform") == 0 || strcmp(dn, "ConcatTransform") == 0) {
        if ((st = read_numbers(p, v, 16))) return st;
        xform x;
        if ((st = read_matrix(p, v, p->line, &x))) return st;
        if (dn[0] == 'T') {
            ctm_set(p, &x);
            return PK_OK;
        }
        return ctm_concat(p, &x);
    }
    if (strcmp(dn, "CoordinateSystem") == 0) {
        if ((st = read_name(p, a, sizeof a))) return st;
        return set_coords(p, a, sb_transform(&p->b));
    }
    if (strcmp(dn, "CoordSysTransform") == 0) {
        if ((st = read_name(p, a, sizeof a))) return st;
        named_xf *cx = find_coords(p, a);
        if (!cx) {
            pwarn(p, p->line, "CoordSysTransform: no coordinate system named \"%.80s\"; ignored", a);
            return PK_OK;
        }
        ctm_set(p, &cx->x);
        return PK_OK;
    }
    if (strcmp(dn, "ActiveTransform") == 0) {
        pbrt_token w = pbrt_tok_next(&p->f->tok);
        if (pbrt_tok_is(&w, "StartTime") || pbrt_tok_is(&w, "All")) p->active_end = false;
        else if (pbrt_tok_is(&w, "EndTime")) {
            p->active_end = true;
            pwarn(p, p->line, "ActiveTransform EndTime: motion is not rendered; the start transform is used");
        } else return pfail(p, w.line, PK_ERR_PARSE, "ActiveTransform takes StartTime, EndTime or All");
        return PK_OK;
    }
    if (strcmp(dn, "TransformTimes") == 0) return read_numbers(p, v, 2);
    if (strcmp(dn, "ReverseOrientation") == 0) {
        GS(p)->reverse = !GS(p)->reverse;
        return PK_OK;
    }
    /* blocks */
    if (strcmp(dn, "AttributeBegin") == 0 || strcmp(dn, "TransformBegin") == 0) return push_state(p);
    if (strcmp(dn, "AttributeEnd") == 0 || strcmp(dn, "TransformEnd") == 0) {
        if (p->b.in_object && p->b.depth == p->obj_depth)
            return pfail(p, p->line, PK_ERR_PARSE, "%s closes the ObjectBegin block", dn);
        return pop_state(p, dn[0] == 'T');
    }
    if (strcmp(dn, "WorldBegin") == 0) return d_world_begin(p);
    if (strcmp(dn, "WorldEnd") == 0) return PK_OK; /* pbrt-v3's; the end of the file ends the world */
    if (strcmp(dn, "Include") == 0 || strcmp(dn, "Import") == 0) return d_include(p);
    if (strcmp(dn, "ObjectEnd") == 0) return d_object_end(p);

    /* directives with names and parameter lists */
    if (strcmp(dn, "ObjectBegin") == 0) {
        if ((st = read_name(p, a, sizeof a)) || (st = read_params(p))) return st;
        if (p->b.in_object) return pfail(p, p->line, PK_ERR_PARSE, "ObjectBegin \"%.80s\" inside another object", a);
        if ((st = push_state(p))) return st;
        if (!sb_begin_object(&p->b)) return pfail(p, p->line, PK_ERR_PARSE, "ObjectBegin inside another object");
        p->obj_depth = p->b.depth;
        p->obj_line = p->line;
        p->obj_name = mem_strdup(A(p), a);
        return p->obj_name ? PK_OK : ctx_nomem(p->ctx);
    }
    if (strcmp(dn, "ObjectInstance") == 0) {
        if ((st = read_name(p, a, sizeof a)) || (st = read_params(p))) return st;
        return d_object_instance(p, a);
    }
    if (strcmp(dn, "NamedMaterial") == 0) {
        if ((st = read_name(p, a, sizeof a)) || (st = read_params(p))) return st;
        int64_t idx = scene_find_material(p->s, a);
        if (idx < 0) return pfail(p, p->line, PK_ERR_PARSE, "NamedMaterial: no material named \"%.80s\"", a);
        GS(p)->material = (uint32_t)idx;
        GS(p)->interface = mat_is_interface(p, (uint32_t)idx);
        return PK_OK;
    }
    if (strcmp(dn, "MediumInterface") == 0) {
        if ((st = read_name(p, a, sizeof a))) return st;
        pbrt_token nx = pbrt_tok_peek(&p->f->tok);
        if (nx.kind == PBRT_TOK_STRING) { /* the outside; one name names both sides */
            if ((st = read_name(p, b2, sizeof b2))) return st;
        } else {
            memcpy(b2, a, sizeof b2);
        }
        int32_t in, out;
        if ((st = medium_name_index(p, a, &in)) || (st = medium_name_index(p, b2, &out))) return st;
        GS(p)->mi_in = in, GS(p)->mi_out = out;
        return PK_OK;
    }
    if (strcmp(dn, "ColorSpace") == 0) {
        if ((st = read_name(p, a, sizeof a))) return st;
        if (strcmp(a, "srgb") != 0)
            pwarn(p, p->line, "ColorSpace \"%.40s\": colours are read as linear sRGB all the same", a);
        return PK_OK;
    }
    if (strcmp(dn, "Option") == 0) {
        if ((st = read_params(p))) return st;
        for (size_t i = 0; i < p->pl.n; i++) {
            pparam *q = &p->pl.p[i];
            if (strcmp(q->name, "seed") == 0 && q->type == PT_INT && q->nnum == 1 && q->num[0] >= 0 &&
                q->num[0] <= 2147483647.0) {
                if ((st = scene_render_int(p->ctx, p->s, "seed", (int)q->num[0]))) return st;
            } else if (strcmp(q->name, "disablepixeljitter") != 0 && strcmp(q->name, "disabletexturefiltering") != 0 &&
                       strcmp(q->name, "disablewavelengthjitter") != 0 && strcmp(q->name, "forcediffuse") != 0 &&
                       strcmp(q->name, "pixelstats") != 0 && strcmp(q->name, "wavefront") != 0 &&
                       strcmp(q->name, "rendercoordsys") != 0 && strcmp(q->name, "displacementedgescale") != 0 &&
                       strcmp(q->name, "msereferenceimage") != 0 && strcmp(q->name, "msereferenceout") != 0) {
                pwarn(p, q->line, "Option '%s' is not known; ignored", q->name);
            }
        }
        return PK_OK;
    }
    if (strcmp(dn, "Attribute") == 0) {
        if ((st = read_name(p, a, sizeof a)) || (st = read_params(p))) return st;
        static const char *const targets[] = {"shape", "light", "material", "medium", "texture"};
        int tg = -1;
        for (int i = 0; i < 5; i++)
            if (strcmp(a, targets[i]) == 0) tg = i;
        if (tg < 0) return pfail(p, p->line, PK_ERR_PARSE, "Attribute: unknown target \"%.40s\"", a);
        for (size_t i = 0; i < p->pl.n; i++) {
            if (!mem_grow(A(p), (void **)&p->defs, &p->cap_defs, p->ndefs + 1, sizeof *p->defs)) return ctx_nomem(p->ctx);
            attr_def *d = &p->defs[p->ndefs];
            d->target = (attr_target)tg;
            d->depth = p->b.depth;
            if ((st = pb_param_copy(p->ctx, &p->pl.p[i], &d->prm))) return st;
            p->ndefs++;
        }
        return PK_OK;
    }
    if (strcmp(dn, "MakeNamedMedium") == 0) {
        if ((st = read_name(p, a, sizeof a)) || (st = read_params(p)) || (st = apply_defaults(p, AT_MEDIUM))) return st;
        return d_medium(p, a);
    }
    if (strcmp(dn, "Texture") == 0) {
        if ((st = read_name(p, a, sizeof a)) || (st = read_name(p, b2, sizeof b2)) || (st = read_name(p, c, sizeof c)) ||
            (st = read_params(p)) || (st = apply_defaults(p, AT_TEXTURE)))
            return st;
        return d_texture(p, a, b2, c);
    }
    if (strcmp(dn, "MakeNamedMaterial") == 0) {
        if ((st = read_name(p, a, sizeof a)) || (st = read_params(p)) || (st = apply_defaults(p, AT_MATERIAL))) return st;
        const char *type = NULL;
        if ((st = pb_string(&p->pd, "type", &type))) return st;
        if (!type) return pfail(p, p->line, PK_ERR_PARSE, "MakeNamedMaterial \"%.80s\" needs 'string type'", a);
        uint32_t idx;
        if ((st = new_material(p, a, type, &idx))) return st;
        warn_unused(p, "material \"%.40s\"", type);
        return PK_OK;
    }
    if (strcmp(dn, "Material") == 0) {
        if ((st = read_name(p, a, sizeof a)) || (st = read_params(p)) || (st = apply_defaults(p, AT_MATERIAL))) return st;
        char nm[PB_NAME_MAX + 64];
        snprintf(nm, sizeof nm, "%.200s:%zu", p->f->name, p->line);
        uint32_t idx;
        if ((st = new_material(p, nm, a, &idx))) return st;
        GS(p)->material = idx;
        GS(p)->interface = mat_is_interface(p, idx);
        warn_unused(p, "material \"%.40s\"", a);
        return PK_OK;
    }
    /* the rest: a type name and parameters */
    static const char *const typed[] = {"Shape",   "LightSource", "AreaLightSource", "Camera",      "Film",
                                        "Sampler", "Integrator",  "PixelFilter",     "Accelerator", NULL};
    int which = -1;
    for (int i = 0; typed[i]; i++)
        if (strcmp(dn, typed[i]) == 0) which = i;
    if (which < 0) return pfail(p, tk->line, PK_ERR_PARSE, "unknown directive '%s'", dn);
    if ((st = read_name(p, a, sizeof a)) || (st = read_params(p))) return st;
    if (which <= 2 && (st = apply_defaults(p, which == 0 ? AT_SHAPE : AT_LIGHT))) return st;
    bool world_only = which <= 2, options_only = which >= 3;
    if (world_only && !p->in_world) return pfail(p, p->line, PK_ERR_PARSE, "%s before WorldBegin", dn);
    if (options_only && p->in_world) return pfail(p, p->line, PK_ERR_PARSE, "%s after WorldBegin", dn);
    switch (which) {
    case 0: return d_shape(p, a);
    case 1: return d_light(p, a);
    case 2: return d_area_light(p, a);
    case 3: return d_camera(p, a);
    case 4: return d_film(p, a);
    case 5: return d_sampler(p, a);
    case 6: return d_integrator(p, a);
    case 7: return d_pixel_filter(p, a);
    default:
        pd_mark_all(&p->pd);
        return PK_OK; /* Paprsek's accelerator is its own */
    }
}

static pk_status parse_file(pp *p, const char *data, size_t size, const char *name, const char *dir, char *key)
{
    pfile f;
    memset(&f, 0, sizeof f);
    f.name = name, f.dir = dir, f.key = key;
    pbrt_tok_init(&f.tok, data, size);
    pfile *outer = p->f;
    p->files[p->nfiles++] = &f;
    p->f = &f;
    pk_status st = PK_OK;
    for (;;) {
        pbrt_token tk = pbrt_tok_next(&f.tok);
        if (tk.kind == PBRT_TOK_END) break;
        if (tk.kind == PBRT_TOK_ERROR) {
            st = tok_error(p, &tk);
            break;
        }
        if (tk.kind != PBRT_TOK_WORD) {
            st = pfail(p, tk.line, PK_ERR_PARSE, "expected a directive, found %s '%.*s'",
                       tk.kind == PBRT_TOK_STRING ? "the string" : tk.kind == PBRT_TOK_NUMBER ? "the number" : "",
                       io_tok_len(tk.text, tk.text + tk.len), tk.text);
            break;
        }
        if ((st = directive(p, &tk))) break;
        plist_clear(p);
    }
    plist_clear(p);
    p->nfiles--;
    p->f = outer;
    return st;
}

pk_status scene_pbrt_parse(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name,
                           const char *base_dir)
{
    pp *p = mem_calloc(&ctx->alloc, 1, sizeof *p);
    if (!p) return ctx_nomem(ctx);
    p->ctx = ctx;
    p->s = s;
    pd_init(&p->pd, ctx, &pbrt_source, p, NULL, false);
    sb_init(&p->b, ctx, s);
    p->gs[0].material = 0;
    p->gs[0].area = -1;
    p->gs[0].mi_in = p->gs[0].mi_out = -1;
    p->cam_mi = -1;
    p->media_start = s->nmedia;
    p->mirror = xform_identity();
    p->cam_from_world = xform_identity();
    p->film_w = 1280, p->film_h = 720;
    p->film_iso = 100.0f, p->exposure_time = 1.0f;
    p->fov = 90.0f;
    p->focal_distance = 1e6f;
    const char *dir = base_dir ? base_dir : ".";
    const char *base = strrchr(name, '/');
    char *key = path_join(&ctx->alloc, dir, base ? base + 1 : name);
    pk_status st = key ? PK_OK : ctx_nomem(ctx);
    /* pbrt's defaults: the material "diffuse" 0.5 (material 0 is that grey),
     * 16 samples are the sampler's own (not set), depth 5 */
    if (st == PK_OK) st = scene_render_int(ctx, s, "max_depth", 5);
    if (st == PK_OK) { /* and its pixel filter, when the file names none */
        pk_filter gauss;
        pk_filter_init(&gauss, PK_FILTER_GAUSSIAN);
        st = scene_render_filter(ctx, s, &gauss);
    }
    if (st == PK_OK) st = parse_file(p, data, size, name, dir, key);
    p->top.name = name, p->top.dir = dir;
    p->f = &p->top;
    if (st == PK_OK && !p->in_world) st = finish_camera(p); /* no WorldBegin: nothing but the camera */
    if (st == PK_OK && p->b.in_object)
        st = pfail(p, p->obj_line, PK_ERR_PARSE, "ObjectBegin \"%.80s\" has no ObjectEnd", p->obj_name ? p->obj_name : "");
    if (st == PK_OK) st = finish_media(p);
    if (st == PK_OK) {
        /* the image pbrt records: every emitter scaled by the sensor's ratio */
        const float k = p->exposure_time * p->film_iso / 100.0f;
        if (k != 1.0f) scene_scale_emission(s, k);
        if ((st = scene_render_int(ctx, s, "width", p->film_w)) == PK_OK)
            st = scene_render_int(ctx, s, "height", p->film_h);
    }
    if (st == PK_OK) {
        if (!s->env.set && s->nlights == 0) {
            /* pbrt renders a scene without lights black; so does this reader */
            bool emits = false;
            for (size_t i = 0; i < s->nmaterials && !emits; i++) emits = v3_max_comp(s->materials[i].ke) > 0.0f;
            if (!emits) scene_env_none(s);
        }
    }
    plist_clear(p);
    defs_pop(p, -1);
    mem_free(&ctx->alloc, p->defs);
    mem_free(&ctx->alloc, p->pl.p);
    for (size_t i = 0; i < p->ntex; i++) mem_free(&ctx->alloc, p->tex[i].name), mem_free(&ctx->alloc, p->tex[i].nodes);
    for (size_t i = 0; i < p->ncoords; i++) mem_free(&ctx->alloc, p->coords[i].name);
    for (size_t i = 0; i < p->nobjs; i++) mem_free(&ctx->alloc, p->objs[i].name);
    for (size_t i = 0; i < p->nmnames; i++) mem_free(&ctx->alloc, p->mnames[i]);
    mem_free(&ctx->alloc, p->mnames);
    mem_free(&ctx->alloc, p->obj_name);
    mem_free(&ctx->alloc, p->tex);
    mem_free(&ctx->alloc, p->areas);
    mem_free(&ctx->alloc, p->vars);
    mem_free(&ctx->alloc, p->is_interface);
    mem_free(&ctx->alloc, p->coords);
    mem_free(&ctx->alloc, p->objs);
    mem_free(&ctx->alloc, key);
    mem_free(&ctx->alloc, p);
    return st;
}
