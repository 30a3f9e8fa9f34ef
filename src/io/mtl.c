/*
 * mtl.c - Wavefront MTL reader: newmtl, Kd/Ks/Ka/Ke/Tf colours (three values
 * or one grey value), Ns, Ni, d, Tr (d = 1 - Tr), illum. Texture maps and
 * other statements are warned about once per kind. Keywords are matched
 * without regard to case, as several exporters write them differently.
 */
#include "io_util.h"
#include "../scene/scene.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct mtl_state {
    io_reader r;
    pk_scene *s;
    int64_t cur;          /* material being defined, -1 before the first newmtl */
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

static pk_status parse_statement(mtl_state *st, const char *ls, const char *le)
{
    io_reader *r = &st->r;
    const char *p = io_skip_blanks(ls, le);
    if (p == le || *p == '#') return PK_OK;
    const char *kw = p;
    p = io_token_end(p, le);
    size_t n = (size_t)(p - kw);

    if (kw_ci(kw, n, "newmtl")) return parse_newmtl(st, p, le);

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
    mtl_state st;
    io_reader_init(&st.r, ctx, name, data, size);
    st.s = s;
    st.cur = -1;
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
