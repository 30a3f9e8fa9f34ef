/*
 * io_util.c - line reading, number parsing and messages shared by the OBJ
 * and MTL parsers. The float parser gathers up to 19 significant digits into
 * a uint64 and scales it by powers of ten in double, then rounds to float:
 * correctly rounded when the digits fit 2^53 and the exponent is within +-22
 * (every number in the shared scenes), otherwise at most 1 ulp off (only near
 * a halfway point). It does not depend on the C locale.
 */
#include "io_util.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <zlib.h>

void io_reader_init(io_reader *r, pk_context *ctx, const char *name, const char *data, size_t size)
{
    memset(r, 0, sizeof *r);
    r->ctx = ctx;
    r->name = name ? name : "(buffer)";
    r->p = data ? data : "";
    r->end = data ? data + size : r->p;
    r->next_line = 1;
    /* Windows editors start UTF-8 files with a byte order mark: without
     * this, the first statement would be an unknown one (and be dropped). */
    if (r->end - r->p >= 3 && memcmp(r->p, "\xEF\xBB\xBF", 3) == 0) r->p += 3;
}

void io_reader_free(io_reader *r) { mem_free(&r->ctx->alloc, r->scratch); r->scratch = NULL; }

/* One physical line [*ls, *le) without its '\n' (and '\r' left as a blank). */
static bool next_physical(io_reader *r, const char **ls, const char **le)
{
    if (r->p >= r->end) return false;
    const char *s = r->p;
    const char *nl = memchr(s, '\n', (size_t)(r->end - s));
    *ls = s;
    *le = nl ? nl : r->end;
    r->p = nl ? nl + 1 : r->end;
    r->next_line++;
    return true;
}

/* The backslash that ends [s, e) (before trailing blanks), or NULL. Comments
 * never continue: "# C:\dir\" (a whole line, or after a statement) must not
 * swallow the next statement. A comment starts with a '#' at the start of a
 * token, as io_rest reads it. */
static const char *continuation(const char *s, const char *e)
{
    const char *q = e;
    while (q > s && io_is_blank(q[-1])) q--;
    if (q == s || q[-1] != '\\') return NULL;
    for (const char *c = s; c < q - 1; c++)
        if (*c == '#' && (c == s || io_is_blank(c[-1]))) return NULL;
    return q - 1;
}

static bool scratch_append(io_reader *r, size_t *len, const char *s, size_t n)
{
    if (n > SIZE_MAX - *len - 1) return false;
    if (!mem_grow(&r->ctx->alloc, (void **)&r->scratch, &r->scratch_cap, *len + n + 1, 1)) return false;
    memcpy(r->scratch + *len, s, n);
    *len += n;
    return true;
}

int io_next_line(io_reader *r, const char **ls, const char **le)
{
    r->line = r->next_line;
    if (!next_physical(r, ls, le)) return 0;
    const char *bs = continuation(*ls, *le);
    if (PK_LIKELY(!bs)) return 1;

    /* Join: each backslash becomes a blank. */
    size_t len = 0;
    for (;;) {
        if (!scratch_append(r, &len, *ls, (size_t)(bs - *ls)) || !scratch_append(r, &len, " ", 1)) {
            ctx_nomem(r->ctx);
            return -1;
        }
        const char *s, *e;
        if (!next_physical(r, &s, &e)) break;
        bs = continuation(s, e);
        if (!bs) {
            if (!scratch_append(r, &len, s, (size_t)(e - s))) {
                ctx_nomem(r->ctx);
                return -1;
            }
            break;
        }
        *ls = s;
    }
    *ls = r->scratch;
    *le = r->scratch + len;
    return 1;
}

void io_rest(const char *p, const char *e, const char **rs, const char **re)
{
    p = io_skip_blanks(p, e);
    const char *q = p;
    while (q < e && !(*q == '#' && (q == p || io_is_blank(q[-1])))) q++;
    while (q > p && io_is_blank(q[-1])) q--;
    *rs = p;
    *re = q;
}

/* ---- numbers ------------------------------------------------------------ */

static const double pow10_tab[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                     1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                     1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* True when v (> 0) lies exactly halfway between two adjacent floats. */
static bool float_midpoint(double v)
{
    if (v >= (double)FLT_MIN) {
        uint64_t b;
        memcpy(&b, &v, sizeof b);
        return (b & 0x1FFFFFFFu) == 0x10000000u; /* the 29 bits a float drops */
    }
    double lo = (double)(float)v, hi;
    if (lo == v) return false;
    hi = (double)nextafterf((float)v, lo < v ? INFINITY : 0.0f);
    return (lo + hi) * 0.5 == v;
}

static inline bool is_digit(char c) { return (unsigned)(c - '0') < 10u; }

static bool word_ci(const char *p, const char *e, const char *w, size_t n)
{
    if ((size_t)(e - p) < n) return false;
    for (size_t i = 0; i < n; i++)
        if ((p[i] | 0x20) != w[i]) return false;
    return true;
}

const char *io_parse_float(const char *p, const char *e, float *out)
{
    bool neg = false;
    if (p < e && (*p == '+' || *p == '-')) {
        neg = *p == '-';
        p++;
    }
    if (p < e && !is_digit(*p) && *p != '.') {
        /* nan / inf / infinity, so that the caller can name the problem */
        if (word_ci(p, e, "nan", 3)) {
            *out = NAN;
            return p + 3;
        }
        if (word_ci(p, e, "infinity", 8)) {
            *out = neg ? -INFINITY : INFINITY;
            return p + 8;
        }
        if (word_ci(p, e, "inf", 3)) {
            *out = neg ? -INFINITY : INFINITY;
            return p + 3;
        }
        return NULL;
    }
    uint64_t m = 0;
    int nd = 0;           /* significant digits kept in m (at most 19) */
    int64_t exp10 = 0;    /* value = m * 10^exp10 */
    bool any = false;
    while (p < e && is_digit(*p)) {
        if (nd < 19) {
            m = m * 10u + (uint64_t)(*p - '0');
            if (m) nd++;
        } else if (exp10 < INT32_MAX) {
            exp10++; /* a dropped digit; relative error < 1e-18 */
        }
        any = true;
        p++;
    }
    if (p < e && *p == '.') {
        p++;
        while (p < e && is_digit(*p)) {
            if (nd < 19) {
                m = m * 10u + (uint64_t)(*p - '0');
                if (m) nd++;
                if (exp10 > INT32_MIN) exp10--;
            }
            any = true;
            p++;
        }
    }
    if (!any) return NULL;
    if (p < e && (*p == 'e' || *p == 'E')) {
        const char *q = p + 1;
        bool eneg = false;
        if (q < e && (*q == '+' || *q == '-')) {
            eneg = *q == '-';
            q++;
        }
        if (q < e && is_digit(*q)) {
            int64_t x = 0;
            while (q < e && is_digit(*q)) {
                if (x < 1000000) x = x * 10 + (*q - '0');
                q++;
            }
            exp10 += eneg ? -x : x;
            p = q;
        }
        /* else "1e" or "1e+": the 'e' is left for the caller to reject */
    }

    double v;
    int64_t mag = (int64_t)nd + exp10; /* m * 10^exp10 lies in [10^(mag-1), 10^mag) */
    if (m == 0 || mag < -46) {
        v = 0.0; /* below half the smallest float subnormal */
    } else if (mag > 39) {
        v = HUGE_VAL;
    } else if (m <= ((uint64_t)1 << 53) && exp10 >= -22 && exp10 <= 22) {
        /* One correctly rounded double operation; its exact remainder tells
         * which way to break a tie that the rounding to float would see. */
        double dm = (double)m, pw = pow10_tab[exp10 < 0 ? -exp10 : exp10];
        double rem;
        if (exp10 >= 0) {
            v = dm * pw;
            rem = fma(dm, pw, -v);   /* true value - v */
        } else {
            v = dm / pw;
            rem = -fma(v, pw, -dm);  /* (true value - v) * pw */
        }
        if (rem != 0.0 && float_midpoint(v)) v = nextafter(v, rem > 0.0 ? HUGE_VAL : 0.0);
    } else {
        /* At most four roundings in double: within 1 ulp of float. */
        int64_t x = exp10; /* within [-65, 38] here */
        v = (double)m;
        if (x > 0) {
            while (x > 22) {
                v *= 1e22;
                x -= 22;
            }
            v *= pow10_tab[x];
        } else if (x < 0) {
            while (x < -22) {
                v /= 1e22;
                x += 22;
            }
            v /= pow10_tab[-x];
        }
    }
    /* A double beyond float range must not be converted (undefined in ISO C). */
    float f = v >= 0x1.ffffffp127 ? INFINITY : (float)v;
    *out = neg ? -f : f;
    return p;
}

const char *io_parse_int(const char *p, const char *e, int64_t *out)
{
    bool neg = false;
    if (p < e && (*p == '+' || *p == '-')) {
        neg = *p == '-';
        p++;
    }
    if (p >= e || !is_digit(*p)) return NULL;
    int64_t v = 0;
    while (p < e && is_digit(*p)) {
        if (v <= 1000000000000000LL) v = v * 10 + (*p - '0');
        p++;
    }
    *out = neg ? -v : v;
    return p;
}

pk_status io_read_floats(io_reader *r, const char **pp, const char *e, float *out, int max, int *n)
{
    const char *p = *pp;
    int k = 0;
    while (k < max) {
        p = io_skip_blanks(p, e);
        if (p == e || *p == '#') break;
        const char *q = io_parse_float(p, e, &out[k]);
        if (!q || (q < e && !io_is_blank(*q))) {
            const char *te = io_token_end(p, e);
            return io_error(r, PK_ERR_PARSE, "bad number '%.*s'", io_tok_len(p, te), p);
        }
        if (!isfinite(out[k]))
            return io_error(r, PK_ERR_PARSE, "number '%.*s' is not a finite float", io_tok_len(p, q), p);
        k++;
        p = q;
    }
    *pp = p;
    *n = k;
    return PK_OK;
}

/* ---- messages ----------------------------------------------------------- */

pk_status io_error(io_reader *r, pk_status status, const char *fmt, ...)
{
    char buf[PK_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    return ctx_error(r->ctx, status, "%s:%zu: %s", r->name, r->line, buf);
}

void io_warn(io_reader *r, const char *fmt, ...)
{
    if (!r->ctx->warn) return;
    char buf[PK_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    ctx_warn(r->ctx, "%s:%zu: %s", r->name, r->line, buf);
}

void io_warn_once(io_reader *r, const char *kind, size_t len, const char *what)
{
    size_t cmp = len < IO_WARN_KIND_LEN ? len : IO_WARN_KIND_LEN;
    for (int i = 0; i < r->nkinds; i++)
        if (r->kind_len[i] == len && memcmp(r->kinds[i], kind, cmp) == 0) return;
    if (r->nkinds == IO_WARN_KINDS) {
        if (!r->kinds_full)
            io_warn(r, "%s (too many kinds of unsupported statement; no more are reported)", what);
        r->kinds_full = true;
        return;
    }
    memcpy(r->kinds[r->nkinds], kind, cmp);
    r->kind_len[r->nkinds++] = len;
    io_warn(r, "%s (further ones not reported)", what);
}

void io_warn_unknown(io_reader *r, const char *kw, size_t len)
{
    char what[128];
    snprintf(what, sizeof what, "unknown statement '%.*s' ignored", len > 40 ? 40 : (int)len, kw);
    io_warn_once(r, kw, len, what);
}

bool io_demote_error(pk_context *ctx, pk_status st, bool was_ok, char *why, size_t nwhy)
{
    if (st == PK_OK || st == PK_ERR_NOMEM || !was_ok) return false;
    snprintf(why, nwhy, "%s", ctx->message);
    pk_context_clear_error(ctx);
    return true;
}

pk_status io_read_relative(pk_context *ctx, pk_context *scratch, const char *dir, const char *rel, char **full,
                           char **data, size_t *size)
{
    *data = NULL;
    if (full) *full = NULL;
    char *path = path_join(&ctx->alloc, dir, rel);
    pk_status st = path ? file_read_all(scratch, path, data, size) : ctx_nomem(scratch);
    if (st == PK_OK && io_is_gzip_name(rel)) {
        char *raw = *data;
        st = io_gunzip(scratch, path, raw, *size, data, size);
        mem_free(&ctx->alloc, raw);
        if (st != PK_OK) *data = NULL;
    }
    if (st == PK_ERR_NOMEM) ctx_nomem(ctx);
    if (st == PK_OK && full) *full = path;
    else mem_free(&ctx->alloc, path);
    return st;
}

bool io_is_gzip_name(const char *name)
{
    size_t n = strlen(name);
    return n > 3 && strcmp(name + n - 3, ".gz") == 0;
}

pk_status io_gunzip(pk_context *ctx, const char *name, const char *data, size_t size, char **out, size_t *out_size)
{
    *out = NULL;
    *out_size = 0;
    if (size < 2 || (unsigned char)data[0] != 0x1f || (unsigned char)data[1] != 0x8b)
        return ctx_error(ctx, PK_ERR_PARSE, "%s: not a gzip file", name);
    z_stream z;
    memset(&z, 0, sizeof z);
    if (inflateInit2(&z, 15 + 16) != Z_OK) return ctx_nomem(ctx); /* gzip wrapper only */
    size_t cap = size < ((size_t)1 << 20) ? (size_t)1 << 20 : size, len = 0, in = 0;
    char *buf = mem_alloc(&ctx->alloc, cap + 1);
    pk_status st = buf ? PK_OK : ctx_nomem(ctx);
    int zr = Z_OK;
    while (st == PK_OK) {
        if (len == cap) {
            if (cap >= PK_MAX_FILE_BYTES) {
                st = ctx_error(ctx, PK_ERR_LIMIT, "%s: inflates to more than %zu bytes", name, (size_t)PK_MAX_FILE_BYTES);
                break;
            }
            size_t nc = cap * 2 > PK_MAX_FILE_BYTES ? PK_MAX_FILE_BYTES : cap * 2;
            char *nb = mem_realloc_array(&ctx->alloc, buf, nc + 1, 1);
            if (!nb) {
                st = ctx_nomem(ctx);
                break;
            }
            buf = nb, cap = nc;
        }
        /* zlib counts in uInt: feed and take at most 1 GiB a step */
        const size_t step = (size_t)1 << 30;
        z.next_in = (Bytef *)(uintptr_t)(data + in);
        z.avail_in = (uInt)(size - in < step ? size - in : step);
        z.next_out = (Bytef *)(buf + len);
        z.avail_out = (uInt)(cap - len < step ? cap - len : step);
        const uInt avail_in = z.avail_in, avail_out = z.avail_out;
        zr = inflate(&z, Z_NO_FLUSH);
        in += avail_in - z.avail_in;
        len += avail_out - z.avail_out;
        if (zr == Z_STREAM_END) {
            /* another member follows (files joined by cat), or the end */
            if (in == size) break;
            if (size - in < 2 || (unsigned char)data[in] != 0x1f || (unsigned char)data[in + 1] != 0x8b) break;
            if (inflateReset(&z) != Z_OK) st = ctx_nomem(ctx);
        } else if (zr == Z_MEM_ERROR) {
            st = ctx_nomem(ctx);
        } else if (zr != Z_OK && zr != Z_BUF_ERROR) {
            st = ctx_error(ctx, PK_ERR_PARSE, "%s: damaged gzip data (%s)", name, z.msg ? z.msg : "inflate failed");
        } else if (in == size && z.avail_out > 0) {
            st = ctx_error(ctx, PK_ERR_PARSE, "%s: the gzip data ends early", name);
        }
    }
    inflateEnd(&z);
    if (st != PK_OK) {
        mem_free(&ctx->alloc, buf);
        return st;
    }
    buf[len] = '\0';
    *out = buf;
    *out_size = len;
    return PK_OK;
}

bool io_portal_is_rectangle(const vec3 p[4])
{
    double e[4][3]; /* p0 -> p1, p1 -> p2, p3 -> p2, p0 -> p3, unit */
    const int from[4] = {0, 1, 3, 0}, to[4] = {1, 2, 2, 3};
    for (int k = 0; k < 4; k++) {
        const double d[3] = {(double)p[to[k]].x - (double)p[from[k]].x, (double)p[to[k]].y - (double)p[from[k]].y,
                             (double)p[to[k]].z - (double)p[from[k]].z};
        const double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(len > 0.0) || !isfinite(len)) return false;
        for (int c = 0; c < 3; c++) e[k][c] = d[c] / len;
    }
#define DOT3(a, b) ((a)[0] * (b)[0] + (a)[1] * (b)[1] + (a)[2] * (b)[2])
    const bool parallel = fabs(DOT3(e[0], e[2]) - 1.0) <= 1e-3 && fabs(DOT3(e[1], e[3]) - 1.0) <= 1e-3;
    const bool square = fabs(DOT3(e[0], e[1])) <= 1e-3 && fabs(DOT3(e[1], e[2])) <= 1e-3 &&
                        fabs(DOT3(e[2], e[3])) <= 1e-3 && fabs(DOT3(e[3], e[0])) <= 1e-3;
#undef DOT3
    return parallel && square;
}
