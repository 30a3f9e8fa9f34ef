/*
 * obj.c - Wavefront OBJ reader: v/vn/vt/f (every index form, negative
 * indices), polygons fan-triangulated in file order, mtllib/usemtl, an
 * optional affine transform. Reads a (data, size) buffer and appends to a
 * scene through the scene_add_* builders; unknown statements are warned about
 * once per kind.
 */
#include "io_util.h"
#include "readers.h"
#include "../scene/scene.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define OBJ_INLINE_CORNERS 64
#define OBJ_MAX_UNDEFINED_WARNINGS 10

typedef struct corner {
    uint32_t v;
    int32_t n, t;
} corner;

/* Invariants:
 *  1. pos_base <= s->npositions, nrm_base <= s->nnormals and uv_base <= s->nuvs: file index i > 0
 *     names position pos_base + i - 1, and is valid while i <= npositions - pos_base.
 *  2. corners holds cap_corners <= PK_MAX_POLYGON_VERTICES entries (or the
 *     inline array when heap_corners is NULL). */
typedef struct obj_state {
    io_reader r;
    pk_scene *s;
    const char *base_dir;
    size_t pos_base, nrm_base, uv_base;
    uint32_t material;           /* current usemtl, 0 = default */
    bool fixed_material;         /* every face takes material; usemtl names are not looked up */
    int undefined_warnings;
    bool has_xform;
    xform m;                     /* the position transform */
    float nm[9];                 /* its normal matrix (xform_normal_matrix) */
    corner inline_corners[OBJ_INLINE_CORNERS];
    corner *heap_corners;
    size_t cap_corners;
} obj_state;

/* ---- transform ---------------------------------------------------------- */

static pk_status setup_xform(obj_state *st, const xform *x)
{
    if (!xform_finite(x))
        return ctx_error(st->r.ctx, PK_ERR_INVALID_ARGUMENT, "%s: transform is not finite", st->r.name);
    st->m = *x;
    if (!xform_normal_matrix(x, st->nm))
        return ctx_error(st->r.ctx, PK_ERR_INVALID_ARGUMENT, "%s: transform is singular", st->r.name);
    st->has_xform = true;
    return PK_OK;
}

/* ---- statements --------------------------------------------------------- */

static pk_status parse_v(obj_state *st, const char *p, const char *le)
{
    float c[7];
    int n;
    pk_status rc = io_read_floats(&st->r, &p, le, c, 7, &n);
    if (rc != PK_OK) return rc;
    if (n < 3) return io_error(&st->r, PK_ERR_PARSE, "v needs 3 coordinates, found %d", n);
    if (n == 5 || !io_at_end(p, le))
        return io_error(&st->r, PK_ERR_PARSE, "v takes x y z, then w or r g b; found %s%d numbers",
                        n == 7 ? "more than " : "", n);
    vec3 pos = v3(c[0], c[1], c[2]);
    if (st->has_xform) {
        pos = xform_point(&st->m, pos);
        if (!v3_finite(pos)) return io_error(&st->r, PK_ERR_PARSE, "transformed vertex is not finite");
    }
    return scene_add_position(st->r.ctx, st->s, pos);
}

static pk_status parse_vn(obj_state *st, const char *p, const char *le)
{
    float c[3];
    int n;
    pk_status rc = io_read_floats(&st->r, &p, le, c, 3, &n);
    if (rc != PK_OK) return rc;
    if (n < 3) return io_error(&st->r, PK_ERR_PARSE, "vn needs 3 coordinates, found %d", n);
    if (!io_at_end(p, le)) return io_error(&st->r, PK_ERR_PARSE, "vn takes 3 coordinates, found more");
    vec3 nv = v3(c[0], c[1], c[2]);
    if (st->has_xform) nv = xform_apply3(st->nm, nv);
    /* Renormalised in double so that huge or tiny finite inputs stay finite. */
    double x = (double)nv.x, y = (double)nv.y, z = (double)nv.z;
    double l2 = x * x + y * y + z * z;
    if (l2 > 0.0 && isfinite(l2)) {
        double inv = 1.0 / sqrt(l2);
        nv = v3((float)(x * inv), (float)(y * inv), (float)(z * inv));
    }
    if (!v3_finite(nv)) nv = v3s(0.0f);
    return scene_add_normal(st->r.ctx, st->s, nv);
}

static pk_status parse_vt(obj_state *st, const char *p, const char *le)
{
    float c[3];
    int n;
    pk_status rc = io_read_floats(&st->r, &p, le, c, 3, &n);
    if (rc != PK_OK) return rc;
    if (n < 1) return io_error(&st->r, PK_ERR_PARSE, "vt needs 1 to 3 coordinates, found none");
    if (!io_at_end(p, le)) return io_error(&st->r, PK_ERR_PARSE, "vt takes 1 to 3 coordinates, found more");
    uv2 t = {c[0], n >= 2 ? c[1] : 0.0f};
    return scene_add_uv(st->r.ctx, st->s, t);
}

/* Resolves OBJ index i (1-based, or negative = relative to the end) against
 * count elements defined so far. */
static pk_status resolve(obj_state *st, int64_t i, size_t count, const char *what, const char *ts,
                         const char *te, size_t *out)
{
    if (i == 0) return io_error(&st->r, PK_ERR_PARSE, "%s index 0 is not allowed (indices start at 1)", what);
    if (i > 0 && (uint64_t)i <= count) {
        *out = (size_t)i - 1;
        return PK_OK;
    }
    if (i < 0 && (uint64_t)(-i) <= count) {
        *out = count - (size_t)(-i);
        return PK_OK;
    }
    if (count == 0)
        return io_error(&st->r, PK_ERR_PARSE, "%s index %.*s out of range (none defined yet)", what,
                        io_tok_len(ts, te), ts);
    if (i > 0)
        return io_error(&st->r, PK_ERR_PARSE, "%s index %.*s out of range (1..%zu)", what, io_tok_len(ts, te),
                        ts, count);
    return io_error(&st->r, PK_ERR_PARSE, "%s index %.*s out of range (-%zu..-1)", what, io_tok_len(ts, te), ts,
                    count);
}

static corner *corner_slot(obj_state *st, size_t k)
{
    if (k < OBJ_INLINE_CORNERS) return &st->inline_corners[k];
    /* k < PK_MAX_POLYGON_VERTICES here, so the size is bounded */
    if (!mem_grow(&st->r.ctx->alloc, (void **)&st->heap_corners, &st->cap_corners, k + 1, sizeof(corner)))
        return NULL;
    if (k == OBJ_INLINE_CORNERS) memcpy(st->heap_corners, st->inline_corners, sizeof st->inline_corners);
    return &st->heap_corners[k];
}

static pk_status parse_f(obj_state *st, const char *p, const char *le)
{
    io_reader *r = &st->r;
    const size_t npos = st->s->npositions - st->pos_base;
    const size_t nnrm = st->s->nnormals - st->nrm_base;
    const size_t ntex = st->s->nuvs - st->uv_base;
    size_t k = 0;
    for (;;) {
        p = io_skip_blanks(p, le);
        if (p == le || *p == '#') break;
        const char *ts = p;
        const char *te = io_token_end(p, le);
        if (k == PK_MAX_POLYGON_VERTICES)
            return io_error(r, PK_ERR_LIMIT, "face has more than %d vertices", PK_MAX_POLYGON_VERTICES);

        /* v, v/vt, v//vn or v/vt/vn; [xs[j], xe[j]) is the text of each number */
        int64_t idx[3] = {0, 0, 0};
        const char *xs[3] = {NULL, NULL, NULL}, *xe[3] = {NULL, NULL, NULL};
        const char *q = p;
        for (int j = 0; j < 3; j++) {
            if (j > 0) {
                if (q == te) break;
                if (*q != '/') goto bad;
                q++;
                if (j == 1 && q < te && *q == '/') continue; /* v//vn */
            }
            xs[j] = q;
            q = io_parse_int(q, te, &idx[j]);
            if (!q) goto bad;
            xe[j] = q;
        }
        if (q != te) goto bad;

        size_t vi, ni = 0, ti = 0;
        pk_status rc = resolve(st, idx[0], npos, "face", xs[0], xe[0], &vi);
        if (rc == PK_OK && xs[1]) rc = resolve(st, idx[1], ntex, "texture coordinate", xs[1], xe[1], &ti);
        if (rc == PK_OK && xs[2]) rc = resolve(st, idx[2], nnrm, "normal", xs[2], xe[2], &ni);
        if (rc != PK_OK) return rc;

        corner *c = corner_slot(st, k);
        if (!c) return ctx_nomem(r->ctx);
        c->v = (uint32_t)(st->pos_base + vi);
        c->n = xs[2] ? (int32_t)(st->nrm_base + ni) : -1;
        c->t = xs[1] ? (int32_t)(st->uv_base + ti) : -1;
        k++;
        p = te;
        continue;
    bad:
        return io_error(r, PK_ERR_PARSE, "bad face vertex '%.*s'", io_tok_len(ts, te), ts);
    }
    if (k < 3) return io_error(r, PK_ERR_PARSE, "face has %zu vertices, at least 3 are needed", k);

    const corner *cs = k <= OBJ_INLINE_CORNERS ? st->inline_corners : st->heap_corners;
    triangle t;
    t.material = st->material;
    t.v[0] = cs[0].v;
    t.n[0] = cs[0].n;
    t.t[0] = cs[0].t;
    for (size_t j = 1; j + 1 < k; j++) {
        t.v[1] = cs[j].v;
        t.n[1] = cs[j].n;
        t.t[1] = cs[j].t;
        t.v[2] = cs[j + 1].v;
        t.n[2] = cs[j + 1].n;
        t.t[2] = cs[j + 1].t;
        pk_status rc = scene_add_triangle(r->ctx, st->s, &t);
        if (rc != PK_OK) return rc;
    }
    return PK_OK;
}

/* A NUL-terminated copy of [s, e) in buf, or on the heap when it does not fit
 * (*heap then owns it). NULL when out of memory. */
static const char *name_copy(pk_context *ctx, const char *s, const char *e, char *buf, size_t n, char **heap)
{
    size_t len = (size_t)(e - s);
    *heap = NULL;
    if (len < n) {
        memcpy(buf, s, len);
        buf[len] = '\0';
        return buf;
    }
    *heap = mem_strndup(&ctx->alloc, s, len);
    return *heap;
}

/* Reads and parses the material library rel (relative to base_dir). One that
 * cannot be read is warned about: its faces get the default material. */
static pk_status read_library(obj_state *st, const char *rel)
{
    io_reader *r = &st->r;
    char *path = path_join(&r->ctx->alloc, st->base_dir, rel);
    if (!path) return ctx_nomem(r->ctx);
    char *data = NULL;
    size_t size = 0;
    bool was_ok = r->ctx->status == PK_OK;
    pk_status rc = file_read_all(r->ctx, path, &data, &size);
    if (rc == PK_OK) {
        char *dir = path_dirname(&r->ctx->alloc, path);
        rc = dir ? mtl_parse_dir(r->ctx, st->s, data, size, rel, dir) : ctx_nomem(r->ctx);
        mem_free(&r->ctx->alloc, dir);
        mem_free(&r->ctx->alloc, data);
    } else {
        char why[PK_ERRMSG_MAX];
        if (io_demote_error(r->ctx, rc, was_ok, why, sizeof why)) {
            io_warn(r, "cannot read material library '%s' (%s); its materials are not defined", rel, why);
            rc = PK_OK;
        }
    }
    mem_free(&r->ctx->alloc, path);
    return rc;
}

/* True when rel names a regular file in base_dir; false also when out of memory. */
static bool library_exists(obj_state *st, const char *rel)
{
    char *path = path_join(&st->r.ctx->alloc, st->base_dir, rel);
    bool ok = path && file_exists(st->r.ctx, path);
    mem_free(&st->r.ctx->alloc, path);
    return ok;
}

static pk_status parse_mtllib(obj_state *st, const char *p, const char *le)
{
    io_reader *r = &st->r;
    if (!st->base_dir) return PK_OK;
    char buf[256], *heap;
    pk_status rc;
    /* The statement lists file names separated by blanks, but exporters
     * (Blender among them) write one name that holds blanks unquoted: when
     * the whole rest of the line names a file, it is that file. */
    const char *rs, *re;
    io_rest(p, le, &rs, &re);
    if (io_token_end(rs, re) != re) {
        const char *whole = name_copy(r->ctx, rs, re, buf, sizeof buf, &heap);
        if (!whole) return ctx_nomem(r->ctx);
        bool found = library_exists(st, whole);
        rc = found ? read_library(st, whole) : PK_OK;
        mem_free(&r->ctx->alloc, heap);
        if (found) return rc;
    }
    for (;;) {
        p = io_skip_blanks(p, le);
        if (p == le || *p == '#') break;
        const char *te = io_token_end(p, le);
        const char *rel = name_copy(r->ctx, p, te, buf, sizeof buf, &heap);
        if (!rel) return ctx_nomem(r->ctx);
        rc = read_library(st, rel);
        mem_free(&r->ctx->alloc, heap);
        if (rc != PK_OK) return rc;
        p = te;
    }
    return PK_OK;
}

static pk_status parse_usemtl(obj_state *st, const char *p, const char *le)
{
    io_reader *r = &st->r;
    const char *ns, *ne;
    io_rest(p, le, &ns, &ne);
    if (ns == ne) {
        io_warn(r, "usemtl without a name; the default material is used");
        if (!st->fixed_material) st->material = 0;
        return PK_OK;
    }
    if (st->fixed_material) return PK_OK;
    char buf[256], *heap;
    const char *name = name_copy(r->ctx, ns, ne, buf, sizeof buf, &heap);
    if (!name) return ctx_nomem(r->ctx);
    int64_t idx = scene_find_material(st->s, name);
    if (idx < 0) {
        st->material = 0;
        if (st->undefined_warnings < OBJ_MAX_UNDEFINED_WARNINGS) {
            st->undefined_warnings++;
            io_warn(r, "material '%.*s' is not defined; its faces use the default material%s",
                    io_tok_len(ns, ne), ns,
                    st->undefined_warnings == OBJ_MAX_UNDEFINED_WARNINGS ? " (further ones not reported)" : "");
        }
    } else {
        st->material = (uint32_t)idx;
    }
    mem_free(&r->ctx->alloc, heap);
    return PK_OK;
}

static inline bool kw_is(const char *k, size_t n, const char *w, size_t wn)
{
    return n == wn && memcmp(k, w, n) == 0;
}

static pk_status parse_statement(obj_state *st, const char *ls, const char *le)
{
    const char *p = io_skip_blanks(ls, le);
    if (p == le || *p == '#') return PK_OK;
    const char *kw = p;
    p = io_token_end(p, le);
    size_t n = (size_t)(p - kw);
    if (n == 1) {
        switch (kw[0]) {
        case 'v': return parse_v(st, p, le);
        case 'f': return parse_f(st, p, le);
        case 'o':
        case 'g':
        case 's': return PK_OK;
        default: break;
        }
    } else if (n == 2 && kw[0] == 'v') {
        if (kw[1] == 'n') return parse_vn(st, p, le);
        if (kw[1] == 't') return parse_vt(st, p, le);
    } else if (kw_is(kw, n, "usemtl", 6)) {
        return parse_usemtl(st, p, le);
    } else if (kw_is(kw, n, "mtllib", 6)) {
        return parse_mtllib(st, p, le);
    }
    io_warn_unknown(&st->r, kw, n);
    return PK_OK;
}

static pk_status parse(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name,
                       const char *base_dir, const xform *xf, const uint32_t *mat)
{
    obj_state *st = mem_alloc(&ctx->alloc, sizeof *st);
    if (!st) return ctx_nomem(ctx);
    memset(st, 0, sizeof *st);
    io_reader_init(&st->r, ctx, name, data, size);
    st->s = s;
    st->base_dir = base_dir;
    st->pos_base = s->npositions;
    st->nrm_base = s->nnormals;
    st->uv_base = s->nuvs;
    if (mat) st->material = *mat, st->fixed_material = true;

    pk_status rc = xf ? setup_xform(st, xf) : PK_OK;
    const char *ls, *le;
    int got;
    while (rc == PK_OK && (got = io_next_line(&st->r, &ls, &le)) != 0) {
        if (got < 0) {
            rc = PK_ERR_NOMEM;
            break;
        }
        rc = parse_statement(st, ls, le);
    }
    io_reader_free(&st->r);
    mem_free(&ctx->alloc, st->heap_corners);
    mem_free(&ctx->alloc, st);
    return rc;
}

pk_status obj_parse(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name,
                    const char *base_dir, const xform *xf)
{
    return parse(ctx, s, data, size, name, base_dir, xf, NULL);
}

pk_status obj_parse_with_material(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name,
                                  const xform *xf, uint32_t mat)
{
    return parse(ctx, s, data, size, name, NULL, xf, &mat);
}
