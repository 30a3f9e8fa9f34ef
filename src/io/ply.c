/*
 * ply.c - the PLY reader of ply.h.
 */
#include "readers.h"

#include "io_util.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define PLY_MAX_ELEMENTS 16
#define PLY_MAX_PROPS 32
#define PLY_MAX_HEADER_LINES 1024

typedef enum ply_type { T_NONE, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 } ply_type;

typedef struct ply_prop {
    char name[32];
    ply_type type;        /* the value's, or the list items' */
    ply_type count_type;  /* T_NONE: not a list */
} ply_prop;

typedef struct ply_element {
    char name[32];
    uint64_t count;
    ply_prop props[PLY_MAX_PROPS];
    int nprops;
} ply_element;

enum { FMT_ASCII, FMT_LE, FMT_BE };

typedef struct ply_reader {
    pk_context *ctx;
    const char *name;
    const unsigned char *p, *end;
    int format;
} ply_reader;

static const struct {
    const char *name;
    ply_type type;
} type_names[] = {{"char", T_I8},     {"int8", T_I8},     {"uchar", T_U8},   {"uint8", T_U8},
                  {"short", T_I16},   {"int16", T_I16},   {"ushort", T_U16}, {"uint16", T_U16},
                  {"int", T_I32},     {"int32", T_I32},   {"uint", T_U32},   {"uint32", T_U32},
                  {"float", T_F32},   {"float32", T_F32}, {"double", T_F64}, {"float64", T_F64}};

static int type_size(ply_type t)
{
    static const int sizes[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
    return sizes[t];
}

static ply_type parse_type(const char *s, size_t n)
{
    for (size_t i = 0; i < sizeof type_names / sizeof type_names[0]; i++)
        if (strlen(type_names[i].name) == n && memcmp(type_names[i].name, s, n) == 0) return type_names[i].type;
    return T_NONE;
}

static pk_status fail(ply_reader *r, const char *fmt, ...) PK_PRINTF(2, 3);
static pk_status fail(ply_reader *r, const char *fmt, ...)
{
    char msg[PK_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return ctx_error(r->ctx, PK_ERR_PARSE, "%s: %s", r->name, msg);
}

/* Next blank-separated token of [*p, e) into (s, n); false at the end. */
static bool token(const char **p, const char *e, const char **s, size_t *n)
{
    const char *c = *p;
    while (c < e && (io_is_blank(*c) || *c == '\n')) c++;
    if (c == e) return false;
    const char *t = c;
    while (t < e && !io_is_blank(*t) && *t != '\n') t++;
    *s = c;
    *n = (size_t)(t - c);
    *p = t;
    return true;
}

static bool tok_is(const char *s, size_t n, const char *w) { return strlen(w) == n && memcmp(s, w, n) == 0; }

/* One value of type t as a double. */
static pk_status read_value(ply_reader *r, ply_type t, double *out)
{
    if (r->format == FMT_ASCII) {
        const char *c = (const char *)r->p, *e = (const char *)r->end, *s;
        size_t n;
        if (!token(&c, e, &s, &n)) return fail(r, "the data ends early");
        if (t == T_F32 || t == T_F64) {
            float f;
            const char *q = io_parse_float(s, s + n, &f);
            if (!q || q != s + n) return fail(r, "bad number '%.*s'", n > 40 ? 40 : (int)n, s);
            *out = (double)f;
        } else {
            int64_t v;
            const char *q = io_parse_int(s, s + n, &v);
            if (!q || q != s + n) return fail(r, "bad integer '%.*s'", n > 40 ? 40 : (int)n, s);
            *out = (double)v;
        }
        r->p = (const unsigned char *)c;
        return PK_OK;
    }
    int sz = type_size(t);
    if ((size_t)(r->end - r->p) < (size_t)sz) return fail(r, "the data ends early");
    unsigned char b[8];
    for (int i = 0; i < sz; i++) b[i] = r->format == FMT_LE ? r->p[i] : r->p[sz - 1 - i];
    r->p += sz;
    uint64_t u = 0;
    for (int i = sz - 1; i >= 0; i--) u = (u << 8) | b[i];
    switch (t) {
    case T_I8: *out = (double)(int8_t)u; break;
    case T_U8: *out = (double)(uint8_t)u; break;
    case T_I16: *out = (double)(int16_t)u; break;
    case T_U16: *out = (double)(uint16_t)u; break;
    case T_I32: *out = (double)(int32_t)(uint32_t)u; break;
    case T_U32: *out = (double)(uint32_t)u; break;
    case T_F32: {
        uint32_t w = (uint32_t)u;
        float f;
        memcpy(&f, &w, 4);
        *out = (double)f;
        break;
    }
    default: {
        double d;
        memcpy(&d, &u, 8);
        *out = d;
        break;
    }
    }
    return PK_OK;
}

static pk_status add_index(ply_reader *r, uint32_t **idx, size_t *n, size_t *cap, uint32_t a, uint32_t b, uint32_t c)
{
    if (!mem_grow(&r->ctx->alloc, (void **)idx, cap, *n + 3, sizeof **idx)) return ctx_nomem(r->ctx);
    (*idx)[(*n)++] = a;
    (*idx)[(*n)++] = b;
    (*idx)[(*n)++] = c;
    return PK_OK;
}

void ply_mesh_free(pk_context *ctx, ply_mesh *m)
{
    mem_free(&ctx->alloc, m->positions);
    mem_free(&ctx->alloc, m->normals);
    mem_free(&ctx->alloc, m->uvs);
    mem_free(&ctx->alloc, m->colors);
    mem_free(&ctx->alloc, m->tangents);
    mem_free(&ctx->alloc, m->uvs1);
    mem_free(&ctx->alloc, m->indices);
    mem_free(&ctx->alloc, m->face_material);
    memset(m, 0, sizeof *m);
}

pk_status ply_parse(pk_context *ctx, const char *data, size_t size, const char *name, ply_mesh *out)
{
    memset(out, 0, sizeof *out);
    ply_reader r = {ctx, name ? name : "mesh.ply", NULL, NULL, FMT_ASCII};
    ply_element *els = mem_calloc(&ctx->alloc, PLY_MAX_ELEMENTS, sizeof *els);
    if (!els) return ctx_nomem(ctx);
    int nels = 0;
    pk_status st = PK_OK;
    const char *c = data ? data : "", *e = c + size;
    int line = 0;
    bool ended = false, has_format = false;
    /* ---- the header: lines up to end_header */
    while (c < e && !ended) {
        const char *le = memchr(c, '\n', (size_t)(e - c));
        if (!le) le = e;
        line++;
        const char *q = c, *s;
        size_t n;
        c = le < e ? le + 1 : e;
        if (line > PLY_MAX_HEADER_LINES) {
            st = fail(&r, "the header has more than %d lines", PLY_MAX_HEADER_LINES);
            goto out;
        }
        if (line == 1) {
            if (!token(&q, le, &s, &n) || !tok_is(s, n, "ply")) {
                st = fail(&r, "not a PLY file (it does not start with 'ply')");
                goto out;
            }
            continue;
        }
        if (!token(&q, le, &s, &n)) continue;
        if (tok_is(s, n, "comment") || tok_is(s, n, "obj_info")) continue;
        if (tok_is(s, n, "end_header")) {
            ended = true;
            break;
        }
        if (tok_is(s, n, "format")) {
            if (!token(&q, le, &s, &n)) goto bad_line;
            if (tok_is(s, n, "ascii")) r.format = FMT_ASCII;
            else if (tok_is(s, n, "binary_little_endian")) r.format = FMT_LE;
            else if (tok_is(s, n, "binary_big_endian")) r.format = FMT_BE;
            else goto bad_line;
            has_format = true;
        } else if (tok_is(s, n, "element")) {
            if (nels == PLY_MAX_ELEMENTS) {
                st = fail(&r, "line %d: more than %d elements", line, PLY_MAX_ELEMENTS);
                goto out;
            }
            ply_element *el = &els[nels];
            if (!token(&q, le, &s, &n)) goto bad_line;
            snprintf(el->name, sizeof el->name, "%.*s", n > 31 ? 31 : (int)n, s);
            const char *ns;
            size_t nn;
            int64_t cnt;
            if (!token(&q, le, &ns, &nn) || io_parse_int(ns, ns + nn, &cnt) != ns + nn || cnt < 0) goto bad_line;
            if ((uint64_t)cnt > (uint64_t)size) {
                st = fail(&r, "line %d: element %s claims %lld items, more than the file's bytes", line, el->name,
                          (long long)cnt);
                goto out;
            }
            el->count = (uint64_t)cnt;
            nels++;
        } else if (tok_is(s, n, "property")) {
            if (nels == 0) goto bad_line;
            ply_element *el = &els[nels - 1];
            if (el->nprops == PLY_MAX_PROPS) {
                st = fail(&r, "line %d: more than %d properties in element %s", line, PLY_MAX_PROPS, el->name);
                goto out;
            }
            ply_prop *pr = &el->props[el->nprops];
            if (!token(&q, le, &s, &n)) goto bad_line;
            if (tok_is(s, n, "list")) {
                if (!token(&q, le, &s, &n) || (pr->count_type = parse_type(s, n)) == T_NONE) goto bad_line;
                if (pr->count_type == T_F32 || pr->count_type == T_F64) goto bad_line;
                if (!token(&q, le, &s, &n)) goto bad_line;
            }
            if ((pr->type = parse_type(s, n)) == T_NONE) goto bad_line;
            if (!token(&q, le, &s, &n)) goto bad_line;
            snprintf(pr->name, sizeof pr->name, "%.*s", n > 31 ? 31 : (int)n, s);
            el->nprops++;
        } else {
            goto bad_line;
        }
        continue;
    bad_line:
        st = ctx_error(ctx, PK_ERR_PARSE, "%s:%d: malformed PLY header line", r.name, line);
        goto out;
    }
    if (!ended) {
        st = fail(&r, "the header has no end_header line");
        goto out;
    }
    if (!has_format) {
        st = fail(&r, "the header has no format line");
        goto out;
    }
    r.p = (const unsigned char *)c;
    r.end = (const unsigned char *)e;

    /* ---- the data, element by element */
    size_t ncap = 0;
    size_t nidx = 0, cap_idx = 0, cap_fmat = 0, nfmat = 0; /* nfmat: triangles face_material covers */
    bool have_vertices = false;
    for (int ei = 0; ei < nels; ei++) {
        ply_element *el = &els[ei];
        /* the smallest number of bytes one item takes */
        uint64_t min_item = 0;
        for (int k = 0; k < el->nprops; k++) {
            ply_prop *pr = &el->props[k];
            min_item += r.format == FMT_ASCII ? 2 : (uint64_t)type_size(pr->count_type ? pr->count_type : pr->type);
        }
        if (min_item == 0) min_item = 1;
        if (el->count > (uint64_t)(r.end - r.p) / min_item) {
            st = fail(&r, "element %s: %llu items cannot fit in the %zu bytes left", el->name,
                      (unsigned long long)el->count, (size_t)(r.end - r.p));
            goto out;
        }
        bool is_vertex = strcmp(el->name, "vertex") == 0, is_face = strcmp(el->name, "face") == 0;
        int px = -1, py = -1, pz = -1, pnx = -1, pny = -1, pnz = -1, pu = -1, pv = -1, pidx = -1, pmat = -1;
        int pu1 = -1, pv1 = -1;
        int pc[4] = {-1, -1, -1, -1}, pt[4] = {-1, -1, -1, -1};
        static const char *const cnames[4] = {"color_r", "color_g", "color_b", "color_a"};
        static const char *const tnames[4] = {"tangent_x", "tangent_y", "tangent_z", "tangent_w"};
        for (int k = 0; k < el->nprops; k++) {
            const char *pn = el->props[k].name;
            bool list = el->props[k].count_type != T_NONE;
            if (is_vertex && !list) {
                if (!strcmp(pn, "x")) px = k;
                else if (!strcmp(pn, "y")) py = k;
                else if (!strcmp(pn, "z")) pz = k;
                else if (!strcmp(pn, "nx")) pnx = k;
                else if (!strcmp(pn, "ny")) pny = k;
                else if (!strcmp(pn, "nz")) pnz = k;
                else if (!strcmp(pn, "u") || !strcmp(pn, "s") || !strcmp(pn, "texture_u") || !strcmp(pn, "texture_s"))
                    pu = k;
                else if (!strcmp(pn, "v") || !strcmp(pn, "t") || !strcmp(pn, "texture_v") || !strcmp(pn, "texture_t"))
                    pv = k;
                else if (!strcmp(pn, "u1")) pu1 = k;
                else if (!strcmp(pn, "v1")) pv1 = k;
                for (int q = 0; q < 4; q++) {
                    if (!strcmp(pn, cnames[q])) pc[q] = k;
                    if (!strcmp(pn, tnames[q])) pt[q] = k;
                }
            }
            if (is_face && list && (!strcmp(pn, "vertex_indices") || !strcmp(pn, "vertex_index"))) pidx = k;
            if (is_face && !list && !strcmp(pn, "material")) pmat = k;
        }
        if (is_vertex) {
            if (have_vertices) {
                st = fail(&r, "more than one vertex element");
                goto out;
            }
            if (px < 0 || py < 0 || pz < 0) {
                st = fail(&r, "the vertex element has no x, y and z");
                goto out;
            }
            if (el->count > UINT32_MAX) {
                st = fail(&r, "more than %u vertices", (unsigned)UINT32_MAX);
                goto out;
            }
            have_vertices = true;
            out->nvertices = (size_t)el->count;
            ncap = out->nvertices ? out->nvertices : 1;
            out->positions = mem_calloc(&ctx->alloc, ncap, sizeof *out->positions);
            if (pnx >= 0 && pny >= 0 && pnz >= 0) out->normals = mem_calloc(&ctx->alloc, ncap, sizeof *out->normals);
            if (pu >= 0 && pv >= 0) out->uvs = mem_calloc(&ctx->alloc, 2 * ncap, sizeof *out->uvs);
            const bool hc = pc[0] >= 0 && pc[1] >= 0 && pc[2] >= 0 && pc[3] >= 0;
            const bool ht = pt[0] >= 0 && pt[1] >= 0 && pt[2] >= 0 && pt[3] >= 0;
            if ((hc && !(out->colors = mem_calloc(&ctx->alloc, 4 * ncap, sizeof *out->colors))) ||
                (ht && !(out->tangents = mem_calloc(&ctx->alloc, 4 * ncap, sizeof *out->tangents))) ||
                (pu1 >= 0 && pv1 >= 0 && !(out->uvs1 = mem_calloc(&ctx->alloc, 2 * ncap, sizeof *out->uvs1)))) {
                st = ctx_nomem(ctx);
                goto out;
            }
            if (!out->positions || (pnx >= 0 && pny >= 0 && pnz >= 0 && !out->normals) ||
                (pu >= 0 && pv >= 0 && !out->uvs)) {
                st = ctx_nomem(ctx);
                goto out;
            }
        }
        for (uint64_t it = 0; it < el->count; it++) {
            double vals[PLY_MAX_PROPS] = {0.0};
            const size_t tri_before = nidx / 3;
            for (int k = 0; k < el->nprops; k++) {
                ply_prop *pr = &el->props[k];
                vals[k] = 0.0;
                if (pr->count_type == T_NONE) {
                    if ((st = read_value(&r, pr->type, &vals[k]))) goto out;
                    continue;
                }
                double dn;
                if ((st = read_value(&r, pr->count_type, &dn))) goto out;
                if (dn < 0.0 || dn > (double)PK_MAX_POLYGON_VERTICES) {
                    st = fail(&r, "element %s: a list of %g items (at most %d)", el->name, dn, PK_MAX_POLYGON_VERTICES);
                    goto out;
                }
                uint32_t first = 0, prev = 0;
                for (int j = 0; j < (int)dn; j++) {
                    double v;
                    if ((st = read_value(&r, pr->type, &v))) goto out;
                    if (k != pidx) continue;
                    if (!(v >= 0.0 && v <= (double)UINT32_MAX - 1.0) || v != floor(v)) {
                        st = fail(&r, "face %llu: vertex index %g is not a valid index", (unsigned long long)it, v);
                        goto out;
                    }
                    uint32_t vi = (uint32_t)v;
                    if (j == 0) first = vi;
                    else if (j >= 2 && (st = add_index(&r, &out->indices, &nidx, &cap_idx, first, prev, vi))) goto out;
                    prev = vi;
                }
            }
            if (pmat >= 0 && nidx / 3 > tri_before) { /* the face's triangles take its material */
                if (!mem_grow(&ctx->alloc, (void **)&out->face_material, &cap_fmat, nidx / 3,
                              sizeof *out->face_material)) {
                    st = ctx_nomem(ctx);
                    goto out;
                }
                const double mv = vals[pmat];
                const uint32_t m = mv >= 0.0 && mv < (double)UINT32_MAX && mv == floor(mv) ? (uint32_t)mv : UINT32_MAX;
                for (size_t t = nfmat; t < tri_before; t++) out->face_material[t] = UINT32_MAX; /* faces without one */
                for (size_t t = tri_before; t < nidx / 3; t++) out->face_material[t] = m;
                nfmat = nidx / 3;
            }
            if (is_vertex) {
                vec3 q = v3((float)vals[px], (float)vals[py], (float)vals[pz]);
                if (!v3_finite(q)) {
                    st = fail(&r, "vertex %llu is not finite", (unsigned long long)it);
                    goto out;
                }
                out->positions[it] = q;
                if (out->normals) {
                    vec3 nv = v3((float)vals[pnx], (float)vals[pny], (float)vals[pnz]);
                    out->normals[it] = v3_finite(nv) ? nv : v3s(0.0f);
                }
                if (out->uvs) {
                    out->uvs[2 * it] = isfinite((float)vals[pu]) ? (float)vals[pu] : 0.0f;
                    out->uvs[2 * it + 1] = isfinite((float)vals[pv]) ? (float)vals[pv] : 0.0f;
                }
                if (out->uvs1) {
                    out->uvs1[2 * it] = isfinite((float)vals[pu1]) ? (float)vals[pu1] : 0.0f;
                    out->uvs1[2 * it + 1] = isfinite((float)vals[pv1]) ? (float)vals[pv1] : 0.0f;
                }
                for (int ch = 0; ch < 4; ch++) {
                    if (out->colors)
                        out->colors[4 * it + (uint64_t)ch] = isfinite((float)vals[pc[ch]]) ? (float)vals[pc[ch]] : 0.0f;
                    if (out->tangents)
                        out->tangents[4 * it + (uint64_t)ch] = isfinite((float)vals[pt[ch]]) ? (float)vals[pt[ch]] : 0.0f;
                }
            }
        }
    }
    if (!have_vertices) {
        st = fail(&r, "no vertex element");
        goto out;
    }
    out->ntriangles = nidx / 3;
    if (out->face_material && nfmat < out->ntriangles) { /* faces after the last with a material have none */
        if (!mem_grow(&ctx->alloc, (void **)&out->face_material, &cap_fmat, out->ntriangles, sizeof *out->face_material)) {
            st = ctx_nomem(ctx);
            goto out;
        }
        for (size_t t = nfmat; t < out->ntriangles; t++) out->face_material[t] = UINT32_MAX;
    }
    for (size_t i = 0; i < nidx; i++)
        if (out->indices[i] >= out->nvertices) {
            st = fail(&r, "triangle %zu: vertex index %u out of range (0..%zu)", i / 3, out->indices[i],
                      out->nvertices ? out->nvertices - 1 : 0);
            goto out;
        }
    st = PK_OK;
out:
    mem_free(&ctx->alloc, els);
    return st;
}

pk_status ply_read_relative(pk_context *ctx, pk_context *scratch, const char *dir, const char *rel, ply_mesh *out)
{
    memset(out, 0, sizeof *out);
    char *full, *data;
    size_t size;
    pk_status st = io_read_relative(ctx, scratch, dir, rel, &full, &data, &size);
    if (st != PK_OK) return st;
    st = ply_parse(scratch, data, size, full, out);
    if (st == PK_ERR_NOMEM) ctx_nomem(ctx);
    mem_free(&ctx->alloc, data);
    mem_free(&ctx->alloc, full);
    return st;
}
