/*
 * mtl.c - Wavefront MTL reader: newmtl, Kd/Ks/Ka/Ke/Tf colours (three values
 * or one grey value), Ns, Ni, d, Tr (d = 1 - Tr), illum, and the texture maps
 * map_Kd, map_Ks, map_Ns, map_Ke, map_d, map_bump/bump, norm with their -s, -o,
 * -clamp and -bm options (docs/materials.md). A texture that cannot be used
 * is warned about and its material keeps its constant. Other statements are
 * warned about once per kind. Keywords are matched without regard to case,
 * as several exporters write them differently.
 */
#include "io_util.h"
#include "readers.h"
#include "../scene/scene.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct mtl_state {
    io_reader r;
    pk_scene *s;
    int64_t cur;          /* material being defined, -1 before the first newmtl */
    const char *tex_dir;  /* where texture files are read from; NULL: not read */
} mtl_state;

static bool kw_ci(const char *k, size_t n, const char *w)
{
    size_t i = 0;
    for (; i < n; i++)
        if (!w[i] || (k[i] | 0x20) != (w[i] | 0x20)) return false;
    return w[i] == '\0';
}

static pk_status parse_newmtl(mtl_state *st, const char *p, const char *le)
{
    const char *ns, *ne;
    io_rest(p, le, &ns, &ne);
    if (ns == ne) return io_error(&st->r, PK_ERR_PARSE, "newmtl needs a name");
    char *name = mem_strndup(&st->r.ctx->alloc, ns, (size_t)(ne - ns));
    if (!name) return ctx_nomem(st->r.ctx);
    uint32_t idx;
    pk_status rc = scene_add_material(st->r.ctx, st->s, name, &idx);
    mem_free(&st->r.ctx->alloc, name);
    if (rc == PK_OK) st->cur = idx;
    return rc;
}

/* "K? r g b" or "K? v" (grey); "K? spectral ..." and "K? xyz ..." are warned
 * about and leave the colour unchanged. */
static pk_status parse_colour(mtl_state *st, const char *kw, size_t kn, const char *p, const char *le,
                              vec3 *out)
{
    const char *t = io_skip_blanks(p, le);
    const char *te = io_token_end(t, le);
    if (kw_ci(t, (size_t)(te - t), "spectral") || kw_ci(t, (size_t)(te - t), "xyz")) {
        char key[64], what[128];
        snprintf(key, sizeof key, "%.*s %.*s", io_tok_len(kw, kw + kn), kw, io_tok_len(t, te), t);
        snprintf(what, sizeof what, "'%s' is not supported, statement ignored", key);
        io_warn_once(&st->r, key, strlen(key), what);
        return PK_OK;
    }
    float c[3];
    int n;
    pk_status rc = io_read_floats(&st->r, &p, le, c, 3, &n);
    if (rc != PK_OK) return rc;
    if ((n != 1 && n != 3) || !io_at_end(p, le))
        return io_error(&st->r, PK_ERR_PARSE, "%.*s needs 1 or 3 numbers, found %s%d", io_tok_len(kw, kw + kn), kw,
                        n == 3 ? "more than " : "", n);
    vec3 v = n == 1 ? v3s(c[0]) : v3(c[0], c[1], c[2]);
    if (v.x < 0.0f || v.y < 0.0f || v.z < 0.0f) {
        /* as JSON scenes, colours are not negative; MTL files are accepted */
        io_warn(&st->r, "%.*s has a negative component; it is taken as 0", io_tok_len(kw, kw + kn), kw);
        v = v3(fmaxf(v.x, 0.0f), fmaxf(v.y, 0.0f), fmaxf(v.z, 0.0f));
    }
    *out = v;
    return PK_OK;
}

static pk_status parse_scalar(mtl_state *st, const char *kw, size_t kn, const char *p, const char *le,
                              float *out)
{
    float c[1];
    int n;
    pk_status rc = io_read_floats(&st->r, &p, le, c, 1, &n);
    if (rc != PK_OK) return rc;
    if (n != 1 || !io_at_end(p, le))
        return io_error(&st->r, PK_ERR_PARSE, "%.*s needs 1 number, found %s", io_tok_len(kw, kw + kn), kw,
                        n == 0 ? "none" : "more");
    *out = c[0];
    return PK_OK;
}

static pk_status parse_illum(mtl_state *st, const char *p, const char *le, int *out)
{
    const char *t = io_skip_blanks(p, le);
    const char *te = io_token_end(t, le);
    int64_t v;
    const char *q = t < te ? io_parse_int(t, te, &v) : NULL;
    if (!q || q != te) {
        if (t == te) return io_error(&st->r, PK_ERR_PARSE, "illum needs a number");
        return io_error(&st->r, PK_ERR_PARSE, "bad illumination model '%.*s'", io_tok_len(t, te), t);
    }
    if (!io_at_end(te, le)) return io_error(&st->r, PK_ERR_PARSE, "illum needs 1 number, found more");
    if (v < 0 || v > 10) {
        io_warn(&st->r, "illumination model %.*s is not one of 0..10; 2 is used", io_tok_len(t, te), t);
        v = 2;
    }
    *out = (int)v;
    return PK_OK;
}

static float clamp01(float x) { return x < 0.0f ? 0.0f : x > 1.0f ? 1.0f : x; }

/* Options of map statements that are read but have no effect here, with the
 * number of values each takes. */
static const struct {
    const char *name;
    int nargs;
} ignored_options[] = {{"-blendu", 1}, {"-blendv", 1}, {"-boost", 1}, {"-mm", 2}, {"-texres", 1},
                       {"-imfchan", 1}, {"-cc", 1}, {"-type", 1}, {"-t", 3}};

/* Up to max numbers after an option (-s, -o: u [v [w]]). false (with a
 * warning) when there is none or one is not finite: the option is ignored. */
static bool map_numbers(mtl_state *st, const char *opt, size_t on, const char **pp, const char *le, float *out,
                        int max, int *n)
{
    const char *p = *pp;
    *n = 0;
    bool finite = true;
    while (*n < max) {
        const char *t = io_skip_blanks(p, le);
        if (t == le) break;
        const char *te = io_token_end(t, le);
        float v;
        const char *q = io_parse_float(t, te, &v);
        if (!q || q != te) break;
        finite &= isfinite(v) != 0;
        out[(*n)++] = v;
        p = te;
    }
    *pp = p;
    if (*n == 0 || !finite) {
        io_warn(&st->r, "texture option %.*s needs %s; ignored", (int)on, opt, *n ? "finite numbers" : "a number");
        return false;
    }
    return true;
}

/* An RGB texture whose mean colour is the flat tangent-space normal's
 * bluish (0.5, 0.5, 1): a normal map, not heights. */
static bool looks_like_normal_map(const texture *t)
{
    if (t->nc < 3) return false;
    float c[4];
    texture_bilinear(t, t->nlevels - 1, 0.5f, 0.5f, 0, c); /* the 1x1 level: the mean */
    return c[2] > 0.7f && fabsf(c[0] - 0.5f) < 0.15f && fabsf(c[1] - 0.5f) < 0.15f;
}

/* "map_X [options] file": fills ref (and loads the texture when the scene's
 * files are read). colour: the texture holds colours (decoded from sRGB). */
static pk_status parse_map(mtl_state *st, const char *kw, size_t kn, const char *p, const char *le, tex_ref *ref,
                           bool colour, const char *constant)
{
    io_reader *r = &st->r;
    tex_ref nr;
    tex_ref_init(&nr);
    for (;;) {
        p = io_skip_blanks(p, le);
        if (p == le || *p != '-') break;
        const char *o = p, *oe = io_token_end(p, le);
        size_t on = (size_t)(oe - o);
        p = oe;
        float v[3];
        int n;
        if (kw_ci(o, on, "-s") || kw_ci(o, on, "-o")) {
            if (!map_numbers(st, o, on, &p, le, v, 3, &n)) continue;
            float *dst = (o[1] | 0x20) == 's' ? nr.s : nr.o;
            dst[0] = v[0];
            dst[1] = n >= 2 ? v[1] : (o[1] | 0x20) == 's' ? 1.0f : 0.0f;
        } else if (kw_ci(o, on, "-bm")) {
            if (!map_numbers(st, o, on, &p, le, v, 1, &n)) continue;
            nr.bm = v[0];
        } else if (kw_ci(o, on, "-clamp")) {
            const char *t = io_skip_blanks(p, le), *te = io_token_end(t, le);
            if (kw_ci(t, (size_t)(te - t), "on")) nr.clamp = TEX_CLAMP;
            else if (kw_ci(t, (size_t)(te - t), "off")) nr.clamp = 0;
            else {
                io_warn(r, "texture option -clamp needs on or off; ignored");
                continue;
            }
            p = te;
        } else {
            int skip = -1;
            for (size_t i = 0; i < sizeof ignored_options / sizeof ignored_options[0]; i++)
                if (kw_ci(o, on, ignored_options[i].name)) skip = ignored_options[i].nargs;
            char key[64], what[160];
            snprintf(key, sizeof key, "%.*s %.*s", io_tok_len(kw, kw + kn), kw, io_tok_len(o, oe), o);
            if (skip < 0) {
                snprintf(what, sizeof what, "unknown texture option '%.*s' skipped", io_tok_len(o, oe), o);
            } else {
                snprintf(what, sizeof what, "texture option '%.*s' is not supported, ignored", io_tok_len(o, oe), o);
                /* its values (numbers, or one word) */
                for (int k = 0; k < skip; k++) {
                    const char *t = io_skip_blanks(p, le), *te = io_token_end(t, le);
                    if (t == le || (*t == '-' && !(te - t > 1 && (t[1] == '.' || (t[1] >= '0' && t[1] <= '9'))))) break;
                    if (k > 0 && !io_parse_float(t, te, &v[0])) break;
                    p = te;
                }
            }
            io_warn_once(r, key, strlen(key), what);
        }
    }
    const char *fs, *fe;
    io_rest(p, le, &fs, &fe);
    if (fs == fe) {
        io_warn(r, "%.*s without a file name ignored", io_tok_len(kw, kw + kn), kw);
        return PK_OK;
    }
    if (!st->tex_dir) return PK_OK; /* parsed only (no files are read) */
    pk_context *ctx = r->ctx;
    char *rel = mem_strndup(&ctx->alloc, fs, (size_t)(fe - fs));
    if (!rel) return ctx_nomem(ctx);
    for (char *c = rel; *c; c++)
        if (*c == '\\') *c = '/'; /* written on Windows */
    char *path = path_join(&ctx->alloc, st->tex_dir, rel);
    if (!path) {
        mem_free(&ctx->alloc, rel);
        return ctx_nomem(ctx);
    }
    bool was_ok = ctx->status == PK_OK;
    int32_t idx;
    pk_status rc = texture_load(ctx, st->s, path, colour, &idx);
    if (rc == PK_OK) {
        nr.kind = TEX_IMAGE;
        nr.tex = idx;
        if (ref == &st->s->materials[st->cur].map_bump && looks_like_normal_map(&st->s->textures[idx])) {
            /* exporters (Blender's among them) write normal maps as map_Bump */
            ref = &st->s->materials[st->cur].map_norm;
            io_warn_once(r, "bump normal map", 15, "a bump map that holds normals (bluish RGB) is read as a normal map");
        }
        *ref = nr;
    } else {
        char why[PK_ERRMSG_MAX];
        if (io_demote_error(ctx, rc, was_ok, why, sizeof why)) {
            io_warn(r, "texture '%s' not used (%s); %s", rel, why, constant);
            rc = PK_OK;
        }
    }
    mem_free(&ctx->alloc, path);
    mem_free(&ctx->alloc, rel);
    return rc;
}

static pk_status parse_statement(mtl_state *st, const char *ls, const char *le)
{
    io_reader *r = &st->r;
    const char *p = io_skip_blanks(ls, le);
    if (p == le || *p == '#') return PK_OK;
    const char *kw = p;
    p = io_token_end(p, le);
    size_t n = (size_t)(p - kw);

    if (kw_ci(kw, n, "newmtl")) return parse_newmtl(st, p, le);

    static const struct {
        const char *kw;
        bool colour;
        const char *constant;
    } maps[] = {{"map_Kd", true, "Kd is used alone"},
                {"map_Ks", true, "Ks is used alone"},
                {"map_Ns", false, "Ns is used alone"},
                {"map_d", false, "the surface has no holes"},
                {"map_bump", false, "the surface is not bumped"},
                {"bump", false, "the surface is not bumped"},
                {"norm", false, "the surface's normals are not changed"},
                {"map_Ke", true, "Ke is used alone"}};
    for (int i = 0; i < 8; i++) {
        if (!kw_ci(kw, n, maps[i].kw)) continue;
        if (st->cur < 0) {
            io_warn_once(r, "(before newmtl)", 15, "material statement before the first newmtl ignored");
            return PK_OK;
        }
        material *m = &st->s->materials[st->cur];
        tex_ref *refs[8] = {&m->map_kd, &m->map_ks, &m->map_ns, &m->map_d,
                            &m->map_bump, &m->map_bump, &m->map_norm, &m->map_ke};
        /* texture_load may grow the texture table, never the materials */
        return parse_map(st, kw, n, p, le, refs[i], maps[i].colour, maps[i].constant);
    }

    bool known = kw_ci(kw, n, "Kd") || kw_ci(kw, n, "Ks") || kw_ci(kw, n, "Ka") || kw_ci(kw, n, "Ke") ||
                 kw_ci(kw, n, "Tf") || kw_ci(kw, n, "Ns") || kw_ci(kw, n, "Ni") || kw_ci(kw, n, "d") ||
                 kw_ci(kw, n, "Tr") || kw_ci(kw, n, "illum");
    if (!known) {
        io_warn_unknown(r, kw, n);
        return PK_OK;
    }
    if (st->cur < 0) {
        io_warn_once(r, "(before newmtl)", 15, "material statement before the first newmtl ignored");
        return PK_OK;
    }
    /* Pointers into s->materials are taken after any newmtl (which may move it). */
    material *m = &st->s->materials[st->cur];
    float f;
    pk_status rc;
    switch (kw[0] | 0x20) {
    case 'k':
        switch (kw[1] | 0x20) {
        case 'd': return parse_colour(st, kw, n, p, le, &m->kd);
        case 's': return parse_colour(st, kw, n, p, le, &m->ks);
        case 'a': return parse_colour(st, kw, n, p, le, &m->ka);
        default: return parse_colour(st, kw, n, p, le, &m->ke);
        }
    case 'n':
        rc = parse_scalar(st, kw, n, p, le, &f);
        if (rc != PK_OK) return rc;
        if ((kw[1] | 0x20) == 's') {
            if (f < 0.0f) {
                io_warn(r, "%.*s %g is negative; 0 is used", (int)n, kw, (double)f);
                f = 0.0f;
            }
            m->ns = f;
        } else {
            if (!(f > 0.0f)) {
                io_warn(r, "%.*s %g is not a positive index of refraction; 1 is used", (int)n, kw, (double)f);
                f = 1.0f;
            }
            m->ni = f;
        }
        return PK_OK;
    case 'd': {
        const char *t = io_skip_blanks(p, le);
        const char *te = io_token_end(t, le);
        if (kw_ci(t, (size_t)(te - t), "-halo")) {
            io_warn_once(r, "d -halo", 7, "'d -halo' is not supported, read as plain d");
            p = te;
        }
        rc = parse_scalar(st, kw, n, p, le, &f);
        if (rc == PK_OK) m->d = clamp01(f);
        return rc;
    }
    case 't':
        if ((kw[1] | 0x20) == 'f') return parse_colour(st, kw, n, p, le, &m->tf);
        rc = parse_scalar(st, kw, n, p, le, &f);
        if (rc == PK_OK) m->d = clamp01(1.0f - f);
        return rc;
    default:
        return parse_illum(st, p, le, &m->illum);
    }
}

pk_status mtl_parse(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name)
{
    return mtl_parse_dir(ctx, s, data, size, name, NULL);
}

pk_status mtl_parse_dir(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name,
                        const char *tex_dir)
{
    mtl_state st;
    io_reader_init(&st.r, ctx, name, data, size);
    st.s = s;
    st.cur = -1;
    st.tex_dir = tex_dir;
    pk_status rc = PK_OK;
    const char *ls, *le;
    int got;
    while (rc == PK_OK && (got = io_next_line(&st.r, &ls, &le)) != 0) {
        if (got < 0) {
            rc = PK_ERR_NOMEM;
            break;
        }
        rc = parse_statement(&st, ls, le);
    }
    io_reader_free(&st.r);
    return rc;
}
