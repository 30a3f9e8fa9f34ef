/*
 * tza.c - reading the tensor archive (tza.h) from memory, every read
 * bounds-checked: a truncated or corrupt file is one error, never a read
 * past the buffer.
 */
#include "tza.h"

#include <string.h>

#define TZA_MAGIC 0x41D7u

typedef struct reader {
    const unsigned char *p;
    size_t size, at;
} reader;

static bool rd(reader *r, void *out, size_t n)
{
    if (n > r->size - r->at) return false;
    memcpy(out, r->p + r->at, n);
    r->at += n;
    return true;
}

static bool rd_u8(reader *r, uint8_t *v) { return rd(r, v, 1); }

static bool rd_u16(reader *r, uint16_t *v)
{
    unsigned char b[2];
    if (!rd(r, b, 2)) return false;
    *v = (uint16_t)(b[0] | b[1] << 8);
    return true;
}

static bool rd_u32(reader *r, uint32_t *v)
{
    unsigned char b[4];
    if (!rd(r, b, 4)) return false;
    *v = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
    return true;
}

static bool rd_u64(reader *r, uint64_t *v)
{
    uint32_t lo, hi;
    if (!rd_u32(r, &lo) || !rd_u32(r, &hi)) return false;
    *v = (uint64_t)hi << 32 | lo;
    return true;
}

static pk_status bad(pk_context *ctx, const char *name, size_t at, const char *what)
{
    return ctx_error(ctx, PK_ERR_PARSE, "%s: byte %zu: %s", name, at, what);
}

pk_status tza_parse(pk_context *ctx, const char *name, const void *data, size_t size, tza_archive *out)
{
    memset(out, 0, sizeof *out);
    reader r = {data, size, 0};
    uint16_t magic;
    uint8_t major, minor;
    uint64_t table;
    if (!rd_u16(&r, &magic) || !rd_u8(&r, &major) || !rd_u8(&r, &minor) || !rd_u64(&r, &table))
        return bad(ctx, name, r.at, "the file ends inside its header (not a tensor archive)");
    if (magic != TZA_MAGIC) return bad(ctx, name, 0, "not a tensor archive (.tza): wrong magic number");
    if (major != 2)
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: tensor archive version %u.%u (only 2.x is read)", name,
                         major, minor);
    if (table < 12 || table > size) return bad(ctx, name, 4, "the table offset lies outside the file");
    r.at = (size_t)table;
    uint32_t n;
    if (!rd_u32(&r, &n)) return bad(ctx, name, r.at, "the file ends inside the tensor table");
    if (n == 0 || n > TZA_MAX_TENSORS) return bad(ctx, name, (size_t)table, "implausible number of tensors");
    out->t = mem_calloc(&ctx->alloc, n, sizeof *out->t);
    if (!out->t) return ctx_nomem(ctx);
    for (uint32_t i = 0; i < n; i++) {
        tza_tensor *t = &out->t[i];
        size_t at = r.at;
        uint16_t len;
        uint8_t nd;
        if (!rd_u16(&r, &len)) goto truncated;
        if (len == 0 || len >= TZA_MAX_NAME) {
            tza_free(&ctx->alloc, out);
            return bad(ctx, name, at, "a tensor name is empty or too long");
        }
        if (!rd(&r, t->name, len)) goto truncated;
        t->name[len] = '\0';
        if (strlen(t->name) != len) {
            tza_free(&ctx->alloc, out);
            return bad(ctx, name, at, "a tensor name holds a NUL byte");
        }
        if (!rd_u8(&r, &nd)) goto truncated;
        if (nd == 0 || nd > TZA_MAX_DIMS) {
            tza_free(&ctx->alloc, out);
            return bad(ctx, name, r.at - 1, "a tensor has no dimensions or more than four");
        }
        t->ndims = nd;
        size_t count = 1;
        for (int d = 0; d < nd; d++) {
            if (!rd_u32(&r, &t->dims[d])) goto truncated;
            if (t->dims[d] == 0 || t->dims[d] > 65536 || size_mul_overflows(count, t->dims[d], &count)) {
                tza_free(&ctx->alloc, out);
                return bad(ctx, name, r.at - 4, "a tensor dimension is zero or implausibly large");
            }
        }
        if (!rd(&r, t->layout, nd)) goto truncated;
        t->layout[nd] = '\0';
        uint8_t dt;
        if (!rd_u8(&r, &dt)) goto truncated;
        t->dtype = (char)dt;
        if (dt != 'h' && dt != 'f') {
            /* the message first: t lives in the array tza_free releases */
            pk_status st = ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: byte %zu: tensor %s has data type '%c' "
                                     "(only binary16 'h' and binary32 'f' are read)", name, r.at - 1, t->name,
                                     dt >= 32 && dt < 127 ? dt : '?');
            tza_free(&ctx->alloc, out);
            return st;
        }
        uint64_t off;
        if (!rd_u64(&r, &off)) goto truncated;
        size_t bytes;
        if (size_mul_overflows(count, dt == 'h' ? 2 : 4, &bytes) || off > size || bytes > size - off) {
            tza_free(&ctx->alloc, out);
            return bad(ctx, name, r.at - 8, "a tensor's data lies outside the file");
        }
        t->data = (const unsigned char *)data + off;
        t->count = count;
        for (uint32_t j = 0; j < i; j++)
            if (strcmp(out->t[j].name, t->name) == 0) {
                tza_free(&ctx->alloc, out);
                return bad(ctx, name, at, "a tensor name appears twice");
            }
        out->n = i + 1;
    }
    return PK_OK;
truncated:
    tza_free(&ctx->alloc, out);
    return bad(ctx, name, r.at, "the file ends inside the tensor table (truncated)");
}

void tza_free(const pk_allocator *al, tza_archive *a)
{
    mem_free(al, a->t);
    a->t = NULL;
    a->n = 0;
}

const tza_tensor *tza_find(const tza_archive *a, const char *name)
{
    for (size_t i = 0; i < a->n; i++)
        if (strcmp(a->t[i].name, name) == 0) return &a->t[i];
    return NULL;
}

/* IEEE binary16 to binary32, subnormals, infinities and NaN included. */
static float half_to_float(uint16_t h)
{
    uint32_t sign = (uint32_t)(h & 0x8000u) << 16, exp = (h >> 10) & 0x1fu, man = h & 0x3ffu, bits;
    if (exp == 0) {
        if (man == 0) {
            bits = sign;
        } else { /* subnormal: normalise */
            int e = -1;
            do {
                e++;
                man <<= 1;
            } while (!(man & 0x400u));
            bits = sign | (uint32_t)(127 - 15 - e) << 23 | (man & 0x3ffu) << 13;
        }
    } else if (exp == 31) {
        bits = sign | 0x7f800000u | man << 13;
    } else {
        bits = sign | (exp + 127 - 15) << 23 | man << 13;
    }
    float f;
    memcpy(&f, &bits, 4);
    return f;
}

float tza_get(const tza_tensor *t, size_t i)
{
    const unsigned char *p = t->data + i * (t->dtype == 'h' ? 2 : 4);
    if (t->dtype == 'h') return half_to_float((uint16_t)(p[0] | p[1] << 8));
    uint32_t b = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
    float f;
    memcpy(&f, &b, 4);
    return f;
}
