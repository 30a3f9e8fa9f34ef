/*
 * grid_nanovdb.c - float grids of NanoVDB files (.nvdb, NanoVDB's file
 * format of major version 32, as pbrt-v4's "nanovdb" medium reads them),
 * read by our own reader of the documented layout and made dense over the
 * grid's active index box.
 *
 * A file is a sequence of segments, each a 16-byte header (the magic
 * "NanoVDB0" or "NanoVDB2", the version, the number of grids, the codec),
 * one 176-byte record per grid followed by its name, then the grids
 * themselves, one after another; newer writers may also store grids as
 * they lie in memory, one after another, with no segment header. A grid is
 * a 672-byte grid record (magic, version, size, name, the index-to-world
 * map, the value type), a 64-byte tree record (byte offsets of the node
 * arrays) and a four-level tree: a root with a table of 32-byte tiles
 * (a key naming a 4096^3 block, a byte offset to an upper node or 0 for a
 * constant tile, and a value), upper nodes of 32^3 entries over 128^3
 * blocks, lower nodes of 16^3 entries over 8^3 blocks and leaves of 8^3
 * values; each node holds a child mask and a table whose entries are either
 * a byte offset to a child (relative to the node) or a tile value. Leaves
 * and node tables run x slowest, z fastest. Everything is little endian.
 *
 * The dense grid holds what a lookup in the tree returns at every voxel of
 * the root's active box: leaf values, tile values and the background where
 * no tile covers a voxel. Every child is placed by where the tree puts it
 * (its parent's origin and its slot), never by the coordinates a node
 * stores, so that the blocks filled are disjoint and the work is bounded by
 * the size of the dense grid; every offset is checked to lie inside the
 * grid's bytes before it is read.
 */
#include "grid_io.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* sizes and offsets in bytes, for float grids */
enum {
    NV_HEADER_SIZE = 16,
    NV_META_SIZE = 176,
    NV_GRID_SIZE = 672,
    NV_TREE_SIZE = 64,
    NV_GRID_OFF_VERSION = 16,
    NV_GRID_OFF_SIZE = 32,
    NV_GRID_OFF_NAME = 40,
    NV_GRID_NAME_MAX = 256,
    NV_GRID_OFF_MATD = 296 + 88,
    NV_GRID_OFF_VECD = 296 + 232,
    NV_GRID_OFF_TYPE = 636,
    NV_TREE_OFF_ROOT = 24,
    NV_ROOT_OFF_TABLE_SIZE = 24,
    NV_ROOT_OFF_BACKGROUND = 28,
    NV_ROOT_SIZE = 64,
    NV_TILE_SIZE = 32,
    NV_TILE_OFF_CHILD = 8,
    NV_TILE_OFF_VALUE = 20,
    NV_UPPER_OFF_CHILD_MASK = 4128,
    NV_UPPER_OFF_TABLE = 8256,
    NV_UPPER_SIZE = 8256 + 32768 * 8,
    NV_LOWER_OFF_CHILD_MASK = 544,
    NV_LOWER_OFF_TABLE = 1088,
    NV_LOWER_SIZE = 1088 + 4096 * 8,
    NV_LEAF_OFF_VALUES = 96,
    NV_LEAF_SIZE = 96 + 512 * 4,
};

/* the plausible size of the dense box for a grid of so many bytes (nv_read_grid) */
#define NV_VOXELS_PER_BYTE 512u
#define NV_SMALL_BOX ((uint64_t)1 << 20)

#define NV_TYPE_FLOAT 1u
#define NV_MAJOR 32u

static uint32_t nv_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static uint16_t nv_u16(const unsigned char *p) { return (uint16_t)(p[0] | p[1] << 8); }
static uint64_t nv_u64(const unsigned char *p) { return (uint64_t)nv_u32(p) | (uint64_t)nv_u32(p + 4) << 32; }
static int32_t nv_i32(const unsigned char *p)
{
    const uint32_t u = nv_u32(p);
    int32_t v;
    memcpy(&v, &u, 4);
    return v;
}
static int64_t nv_i64(const unsigned char *p)
{
    const uint64_t u = nv_u64(p);
    int64_t v;
    memcpy(&v, &u, 8);
    return v;
}
static float nv_f32(const unsigned char *p)
{
    const uint32_t u = nv_u32(p);
    float v;
    memcpy(&v, &u, 4);
    return v;
}
static double nv_f64(const unsigned char *p)
{
    const uint64_t u = nv_u64(p);
    double v;
    memcpy(&v, &u, 8);
    return v;
}

/* "NanoVDB" followed by one of the characters of tails */
static bool nv_magic(const unsigned char *p, const char *tails)
{
    return memcmp(p, "NanoVDB", 7) == 0 && p[7] != '\0' && strchr(tails, p[7]) != NULL;
}

static const char *nv_type_name(uint32_t t)
{
    static const char *const names[] = {"unknown", "float",  "double", "int16",  "int32", "int64", "vec3f",
                                        "vec3d",   "mask",   "half",   "uint32", "bool",  "rgba8", "fp4",
                                        "fp8",     "fp16",   "fpn",    "vec4f",  "vec4d", "index", "onindex",
                                        "indexmask", "onindexmask", "pointindex", "vec3u8", "vec3u16", "uint8"};
    return t < sizeof names / sizeof names[0] ? names[t] : "unknown";
}

/* ---- finding the grid ------------------------------------------------------------ */

typedef struct nv_reader {
    pk_context *ctx;
    const char *path;
    const unsigned char *d;
    size_t n;
    const char *want;   /* the grid's name, or NULL for the first float grid */
    char names[160];    /* the grids seen, for messages */
    size_t nnames;
    bool names_full;
    int ngrids;
} nv_reader;

typedef struct nv_found {
    size_t off, size;   /* the grid's bytes */
    const char *name;   /* not NUL-terminated */
    size_t name_len;
    uint32_t type;
    uint16_t codec;
} nv_found;

static void nv_note_name(nv_reader *r, const char *name, size_t len)
{
    r->ngrids++;
    if (r->names_full) return;
    const size_t left = sizeof r->names - r->nnames;
    const int k = snprintf(r->names + r->nnames, left, "%s'%.*s'", r->nnames ? ", " : "", (int)(len > 40 ? 40 : len),
                           name);
    if (k >= 0 && (size_t)k + 6 < left) {
        r->nnames += (size_t)k;
        return;
    }
    snprintf(r->names + r->nnames, left, "%s...", r->nnames ? ", " : ""); /* left >= 6 while not full */
    r->names_full = true;
}

/* Whether the grid named (name, len) of type t is the one asked for. */
static bool nv_wanted(const nv_reader *r, const char *name, size_t len, uint32_t t)
{
    if (!r->want) return t == NV_TYPE_FLOAT;
    return strlen(r->want) == len && memcmp(r->want, name, len) == 0;
}

static pk_status nv_version_error(nv_reader *r, uint32_t v, const char *what)
{
    return ctx_error(r->ctx, PK_ERR_UNSUPPORTED, "%s: %s of NanoVDB version %u.%u.%u (only version %u.x is read)",
                     r->path, what, v >> 21, (v >> 10) & 2047u, v & 1023u, NV_MAJOR);
}

/* Segments from byte 0 on; *found set (off 0 size 0 when absent). */
static pk_status nv_find_in_segments(nv_reader *r, nv_found *found)
{
    size_t pos = 0;
    while (pos < r->n) {
        const unsigned char *h = r->d + pos;
        if (r->n - pos < NV_HEADER_SIZE)
            return ctx_error(r->ctx, PK_ERR_PARSE, "%s: truncated segment header at byte %zu", r->path, pos);
        if (!nv_magic(h, "02"))
            return ctx_error(r->ctx, PK_ERR_PARSE, "%s: no NanoVDB segment header at byte %zu (bad magic)", r->path, pos);
        const uint32_t version = nv_u32(h + 8);
        if (version >> 21 != NV_MAJOR) return nv_version_error(r, version, "a segment");
        const unsigned count = nv_u16(h + 12), codec = nv_u16(h + 14);
        pos += NV_HEADER_SIZE;
        const size_t metas = pos;
        /* the records and names */
        for (unsigned i = 0; i < count; i++) {
            if (r->n - pos < NV_META_SIZE)
                return ctx_error(r->ctx, PK_ERR_PARSE, "%s: truncated record of grid %u at byte %zu", r->path, i, pos);
            const uint32_t name_size = nv_u32(r->d + pos + 136);
            pos += NV_META_SIZE;
            if (r->n - pos < name_size)
                return ctx_error(r->ctx, PK_ERR_PARSE, "%s: truncated name of grid %u at byte %zu", r->path, i, pos);
            pos += name_size;
        }
        /* the grids */
        size_t m = metas;
        for (unsigned i = 0; i < count; i++) {
            const unsigned char *md = r->d + m;
            const uint64_t grid_size = nv_u64(md), file_size = nv_u64(md + 8);
            const uint32_t type = nv_u32(md + 32), name_size = nv_u32(md + 136);
            const uint16_t gcodec = nv_u16(md + 168);
            const char *name = (const char *)(md + NV_META_SIZE);
            size_t len = 0;
            while (len < name_size && name[len]) len++;
            m += NV_META_SIZE + name_size;
            if (file_size > r->n - pos)
                return ctx_error(r->ctx, PK_ERR_PARSE, "%s: grid '%.*s' is truncated (%llu bytes at byte %zu, %zu there)",
                                 r->path, (int)(len > 64 ? 64 : len), name, (unsigned long long)file_size, pos,
                                 r->n - pos);
            nv_note_name(r, name, len);
            if (!found->size && nv_wanted(r, name, len, type)) {
                found->off = pos;
                found->size = (size_t)file_size;
                found->name = name, found->name_len = len;
                found->type = type;
                found->codec = (uint16_t)(codec ? codec : gcodec);
                if (!found->codec && grid_size != file_size)
                    return ctx_error(r->ctx, PK_ERR_PARSE, "%s: grid '%.*s': %llu bytes on file for a grid of %llu",
                                     r->path, (int)(len > 64 ? 64 : len), name, (unsigned long long)file_size,
                                     (unsigned long long)grid_size);
                if (!found->size) found->size = 1; /* found, empty: refused below as truncated */
            }
            pos += (size_t)file_size;
        }
    }
    return PK_OK;
}

/* Grids stored one after another as they lie in memory. */
static pk_status nv_find_raw(nv_reader *r, nv_found *found)
{
    size_t pos = 0;
    while (pos < r->n) {
        const unsigned char *g = r->d + pos;
        if (r->n - pos < NV_GRID_SIZE)
            return ctx_error(r->ctx, PK_ERR_PARSE, "%s: truncated grid record at byte %zu", r->path, pos);
        if (!nv_magic(g, "01"))
            return ctx_error(r->ctx, PK_ERR_PARSE, "%s: no NanoVDB grid at byte %zu (bad magic)", r->path, pos);
        const uint32_t version = nv_u32(g + NV_GRID_OFF_VERSION);
        if (version >> 21 != NV_MAJOR) return nv_version_error(r, version, "a grid");
        const uint64_t size = nv_u64(g + NV_GRID_OFF_SIZE);
        if (size < NV_GRID_SIZE + NV_TREE_SIZE || size > r->n - pos)
            return ctx_error(r->ctx, PK_ERR_PARSE, "%s: grid at byte %zu: bad or truncated size %llu (%zu bytes there)",
                             r->path, pos, (unsigned long long)size, r->n - pos);
        const char *name = (const char *)(g + NV_GRID_OFF_NAME);
        size_t len = 0;
        while (len < NV_GRID_NAME_MAX && name[len]) len++;
        const uint32_t type = nv_u32(g + NV_GRID_OFF_TYPE);
        nv_note_name(r, name, len);
        if (!found->size && nv_wanted(r, name, len, type)) {
            found->off = pos, found->size = (size_t)size;
            found->name = name, found->name_len = len;
            found->type = type, found->codec = 0;
        }
        pos += (size_t)size;
    }
    return PK_OK;
}

/* ---- the tree ---------------------------------------------------------------------- */

typedef struct nv_dense {
    nv_reader *r;
    const char *gname;
    int gname_len;
    const unsigned char *g;  /* the grid's first byte */
    size_t gsize;            /* and its size */
    int64_t lo[3], hi[3];    /* the dense box in index space (inclusive) */
    int64_t dim[3];
    float *v;
} nv_dense;

static pk_status nv_grid_error(nv_dense *t, pk_status st, const char *what)
{
    return ctx_error(t->r->ctx, st, "%s: grid '%.*s': %s", t->r->path, t->gname_len, t->gname, what);
}

/* The node of size bytes at byte offset rel from the node at base, or NULL
 * when it does not lie inside the grid. */
static const unsigned char *nv_child(const nv_dense *t, const unsigned char *base, int64_t rel, size_t size)
{
    if (rel == 0 || rel > (int64_t)t->gsize || rel < -(int64_t)t->gsize) return NULL;
    const int64_t at = (int64_t)(base - t->g) + rel;
    if ( at < (int64_t)(NV_GRID_SIZE + NV_TREE_SIZE) || (uint64_t)at > (uint64_t)t->gsize ||
        t->gsize - (size_t)at < size)
        return NULL;
    return t->g + at;
}

/* The block [o, o + side)^3 clipped to the dense box into lo..hi; false when
 * they do not meet. */
static bool nv_clip(const nv_dense *t, const int64_t o[3], int64_t side, int64_t lo[3], int64_t hi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = o[a] > t->lo[a] ? o[a] : t->lo[a];
        hi[a] = o[a] + side - 1 < t->hi[a] ? o[a] + side - 1 : t->hi[a];
        if (lo[a] > hi[a]) return false;
    }
    return true;
}

static void nv_fill(nv_dense *t, const int64_t lo[3], const int64_t hi[3], float value)
{
    if (!t->v) return; /* the checking walk */
    for (int64_t z = lo[2]; z <= hi[2]; z++)
        for (int64_t y = lo[1]; y <= hi[1]; y++) {
            float *row = t->v + ((size_t)(z - t->lo[2]) * (size_t)t->dim[1] + (size_t)(y - t->lo[1])) * (size_t)t->dim[0];
            for (int64_t x = lo[0]; x <= hi[0]; x++) row[x - t->lo[0]] = value;
        }
}

static void nv_leaf(nv_dense *t, const unsigned char *leaf, const int64_t o[3])
{
    int64_t lo[3], hi[3];
    if (!t->v || !nv_clip(t, o, 8, lo, hi)) return;
    const unsigned char *vals = leaf + NV_LEAF_OFF_VALUES;
    for (int64_t z = lo[2]; z <= hi[2]; z++)
        for (int64_t y = lo[1]; y <= hi[1]; y++) {
            float *row = t->v + ((size_t)(z - t->lo[2]) * (size_t)t->dim[1] + (size_t)(y - t->lo[1])) * (size_t)t->dim[0];
            for (int64_t x = lo[0]; x <= hi[0]; x++) {
                const size_t n = (size_t)((x - o[0]) << 6 | (y - o[1]) << 3 | (z - o[2]));
                row[x - t->lo[0]] = nv_f32(vals + 4 * n);
            }
        }
}

/* An internal node over a block of side 1 << (log2dim + cshift) at o whose
 * children span 1 << cshift each: lower (log2dim 4, cshift 3) or upper
 * (log2dim 5, cshift 7). */
static pk_status nv_internal(nv_dense *t, const unsigned char *node, const int64_t o[3], int log2dim, int cshift)
{
    const bool upper = log2dim == 5;
    const size_t off_mask = upper ? NV_UPPER_OFF_CHILD_MASK : NV_LOWER_OFF_CHILD_MASK;
    const size_t off_table = upper ? NV_UPPER_OFF_TABLE : NV_LOWER_OFF_TABLE;
    int64_t lo[3], hi[3];
    if (!nv_clip(t, o, (int64_t)1 << (log2dim + cshift), lo, hi)) return PK_OK;
    int64_t c0[3], c1[3]; /* the children's slots that meet the box */
    for (int a = 0; a < 3; a++) c0[a] = (lo[a] - o[a]) >> cshift, c1[a] = (hi[a] - o[a]) >> cshift;
    for (int64_t a = c0[0]; a <= c1[0]; a++)
        for (int64_t b = c0[1]; b <= c1[1]; b++)
            for (int64_t c = c0[2]; c <= c1[2]; c++) {
                const size_t n = (size_t)(a << (2 * log2dim) | b << log2dim | c);
                const unsigned char *entry = node + off_table + 8 * n;
                const int64_t co[3] = {o[0] + (a << cshift), o[1] + (b << cshift), o[2] + (c << cshift)};
                if (node[off_mask + (n >> 3)] >> (n & 7) & 1) {
                    const size_t csize = upper ? NV_LOWER_SIZE : NV_LEAF_SIZE;
                    const unsigned char *child = nv_child(t, node, nv_i64(entry), csize);
                    if (!child)
                        return nv_grid_error(t, PK_ERR_PARSE, upper ? "a lower node lies outside the grid"
                                                                    : "a leaf lies outside the grid");
                    if (upper) {
                        pk_status st = nv_internal(t, child, co, 4, 3);
                        if (st != PK_OK) return st;
                    } else {
                        nv_leaf(t, child, co);
                    }
                } else {
                    int64_t tlo[3], thi[3];
                    if (nv_clip(t, co, (int64_t)1 << cshift, tlo, thi)) nv_fill(t, tlo, thi, nv_f32(entry));
                }
            }
    return PK_OK;
}

/* Every root tile that meets the dense box, and the nodes below it: fills
 * t->v, or with t->v NULL only follows and checks the offsets (the walk
 * before anything is allocated). */
static pk_status nv_walk(nv_dense *t, const unsigned char *root, uint64_t ntiles)
{
    for (uint64_t i = 0; i < ntiles; i++) {
        const unsigned char *tile = root + NV_ROOT_SIZE + NV_TILE_SIZE * i;
        const uint64_t key = nv_u64(tile);
        const uint32_t kx = (uint32_t)(key >> 42 & 0x1fffff) << 12, ky = (uint32_t)(key >> 21 & 0x1fffff) << 12,
                       kz = (uint32_t)(key & 0x1fffff) << 12;
        int32_t ox, oy, oz;
        memcpy(&ox, &kx, 4), memcpy(&oy, &ky, 4), memcpy(&oz, &kz, 4);
        const int64_t o[3] = {ox, oy, oz};
        int64_t lo[3], hi[3];
        if (!nv_clip(t, o, 4096, lo, hi)) continue;
        const int64_t child = nv_i64(tile + NV_TILE_OFF_CHILD);
        if (child == 0) {
            nv_fill(t, lo, hi, nv_f32(tile + NV_TILE_OFF_VALUE));
            continue;
        }
        const unsigned char *upper = nv_child(t, root, child, NV_UPPER_SIZE);
        if (!upper) return nv_grid_error(t, PK_ERR_PARSE, "an upper node lies outside the grid (truncated?)");
        pk_status st = nv_internal(t, upper, o, 5, 7);
        if (st != PK_OK) return st;
    }
    return PK_OK;
}

static int nv_cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static pk_status nv_read_grid(nv_reader *r, const pk_allocator *al, const nv_found *f, medium_grid *out, aabb *box)
{
    nv_dense t = {.r = r, .gname = f->name, .gname_len = (int)(f->name_len > 64 ? 64 : f->name_len)};
    if (f->type != NV_TYPE_FLOAT) {
        char what[96];
        snprintf(what, sizeof what, "values of type %s (only 32-bit float grids are read)", nv_type_name(f->type));
        return nv_grid_error(&t, PK_ERR_UNSUPPORTED, what);
    }
    if (f->codec)
        return nv_grid_error(&t, PK_ERR_UNSUPPORTED,
                             f->codec == 1   ? "compressed with Zip (only uncompressed files are read)"
                             : f->codec == 2 ? "compressed with Blosc (only uncompressed files are read)"
                                             : "compressed with an unknown codec (only uncompressed files are read)");
    if (f->size < NV_GRID_SIZE + NV_TREE_SIZE) return nv_grid_error(&t, PK_ERR_PARSE, "truncated grid record");
    const unsigned char *g = r->d + f->off;
    if (!nv_magic(g, "01")) return nv_grid_error(&t, PK_ERR_PARSE, "bad grid magic");
    const uint32_t version = nv_u32(g + NV_GRID_OFF_VERSION);
    if (version >> 21 != NV_MAJOR) return nv_version_error(r, version, "a grid");
    const uint64_t gsize = nv_u64(g + NV_GRID_OFF_SIZE);
    if (gsize > f->size || gsize < NV_GRID_SIZE + NV_TREE_SIZE)
        return nv_grid_error(&t, PK_ERR_PARSE, "the grid's size does not match its record (truncated?)");
    if (nv_u32(g + NV_GRID_OFF_TYPE) != NV_TYPE_FLOAT) {
        char what[96];
        snprintf(what, sizeof what, "values of type %s (only 32-bit float grids are read)",
                 nv_type_name(nv_u32(g + NV_GRID_OFF_TYPE)));
        return nv_grid_error(&t, PK_ERR_UNSUPPORTED, what);
    }
    t.g = g, t.gsize = (size_t)gsize;

    /* the map: scales and translations only */
    double mat[9], vec[3];
    for (int i = 0; i < 9; i++) mat[i] = nv_f64(g + NV_GRID_OFF_MATD + 8 * i);
    for (int i = 0; i < 3; i++) vec[i] = nv_f64(g + NV_GRID_OFF_VECD + 8 * i);
    for (int i = 0; i < 9; i++)
        if (!isfinite(mat[i])) return nv_grid_error(&t, PK_ERR_PARSE, "the index-to-world map is not finite");
    for (int i = 0; i < 3; i++)
        if (!isfinite(vec[i])) return nv_grid_error(&t, PK_ERR_PARSE, "the index-to-world map is not finite");
    if (mat[1] != 0.0 || mat[2] != 0.0 || mat[3] != 0.0 || mat[5] != 0.0 || mat[6] != 0.0 || mat[7] != 0.0)
        return nv_grid_error(&t, PK_ERR_UNSUPPORTED,
                             "the index-to-world map rotates or shears (only scales and translations are read)");
    if (!(mat[0] > 0.0 && mat[4] > 0.0 && mat[8] > 0.0))
        return nv_grid_error(&t, PK_ERR_UNSUPPORTED, "the index-to-world map does not scale by positive factors");

    /* the root */
    const uint64_t root_off = nv_u64(g + NV_GRID_SIZE + NV_TREE_OFF_ROOT);
    if (root_off < NV_TREE_SIZE || root_off > gsize - NV_GRID_SIZE || gsize - NV_GRID_SIZE - root_off < NV_ROOT_SIZE)
        return nv_grid_error(&t, PK_ERR_PARSE, "the root lies outside the grid (truncated?)");
    const unsigned char *root = g + NV_GRID_SIZE + root_off;
    const uint64_t ntiles = nv_u32(root + NV_ROOT_OFF_TABLE_SIZE);
    if (ntiles > (uint64_t)(t.g + t.gsize - root - NV_ROOT_SIZE) / NV_TILE_SIZE)
        return nv_grid_error(&t, PK_ERR_PARSE, "the root's table runs past the grid (truncated?)");
    const float background = nv_f32(root + NV_ROOT_OFF_BACKGROUND);
    uint64_t nvox = 1;
    for (int a = 0; a < 3; a++) {
        t.lo[a] = nv_i32(root + 4 * a);
        t.hi[a] = nv_i32(root + 12 + 4 * a);
        if (t.hi[a] < t.lo[a]) return nv_grid_error(&t, PK_ERR_PARSE, "no active voxels (empty index box)");
        t.dim[a] = t.hi[a] - t.lo[a] + 1;
    }
    for (int a = 0; a < 3; a++) {
        if ((uint64_t)t.dim[a] > MEDIUM_MAX_VOXELS || nvox * (uint64_t)t.dim[a] > MEDIUM_MAX_VOXELS) {
            return ctx_error(r->ctx, PK_ERR_LIMIT,
                             "%s: grid '%.*s': %lld x %lld x %lld voxels is beyond the limit of %zu voxels", r->path,
                             t.gname_len, t.gname, (long long)t.dim[0], (long long)t.dim[1], (long long)t.dim[2],
                             (size_t)MEDIUM_MAX_VOXELS);
        }
        nvox *= (uint64_t)t.dim[a];
    }
    /* A box the grid's bytes cannot account for: active values lie in leaves,
     * in tiles of lower and upper nodes, or in root tiles of 4096^3 voxels,
     * and the root's box holds them all. A box within the voxel limit
     * cannot hold a root tile, so its active values need an upper node
     * (270 400 bytes): no grid from a NanoVDB writer has more than
     * 2^27 / 271 232 < 495 voxels in its box per byte. A box beyond
     * NV_VOXELS_PER_BYTE voxels per byte (and beyond NV_SMALL_BOX, which
     * hand-made grids of constant tiles stay within) is refused before
     * anything is allocated: a 1 KiB file would otherwise cost 512 MiB. */
    if (nvox > NV_SMALL_BOX && nvox / NV_VOXELS_PER_BYTE > gsize)
        return ctx_error(r->ctx, PK_ERR_PARSE,
                         "%s: grid '%.*s': a box of %lld x %lld x %lld voxels in a grid of %llu bytes "
                         "(more than %u voxels a byte: not a grid a NanoVDB writer makes)",
                         r->path, t.gname_len, t.gname, (long long)t.dim[0], (long long)t.dim[1],
                         (long long)t.dim[2], (unsigned long long)gsize, (unsigned)NV_VOXELS_PER_BYTE);

    /* keys must differ: each names its own block */
    pk_status st = PK_OK;
    if (ntiles > 1) {
        uint64_t *keys = mem_alloc(al, (size_t)ntiles * sizeof *keys);
        if (!keys) return ctx_nomem(r->ctx);
        for (uint64_t i = 0; i < ntiles; i++) keys[i] = nv_u64(root + NV_ROOT_SIZE + NV_TILE_SIZE * i);
        qsort(keys, (size_t)ntiles, sizeof *keys, nv_cmp_u64);
        for (uint64_t i = 1; i < ntiles && st == PK_OK; i++)
            if (keys[i] == keys[i - 1]) st = nv_grid_error(&t, PK_ERR_PARSE, "two root tiles have the same key");
        mem_free(al, keys);
        if (st != PK_OK) return st;
    }

    /* the tree's offsets are all checked before the dense grid is allocated */
    if ((st = nv_walk(&t, root, ntiles)) != PK_OK) return st;
    t.v = mem_alloc(al, (size_t)nvox * sizeof(float));
    if (!t.v) return ctx_nomem(r->ctx);
    for (size_t i = 0; i < (size_t)nvox; i++) t.v[i] = background;
    st = nv_walk(&t, root, ntiles);
    for (size_t i = 0; st == PK_OK && i < (size_t)nvox; i++)
        if (!isfinite(t.v[i])) {
            char what[160];
            const size_t x = i % (size_t)t.dim[0], y = i / (size_t)t.dim[0] % (size_t)t.dim[1],
                         z = i / ((size_t)t.dim[0] * (size_t)t.dim[1]);
            snprintf(what, sizeof what, "the value at voxel (%lld, %lld, %lld) is %s", (long long)(t.lo[0] + (int64_t)x),
                     (long long)(t.lo[1] + (int64_t)y), (long long)(t.lo[2] + (int64_t)z),
                     isnan(t.v[i]) ? "NaN" : "infinite");
            st = nv_grid_error(&t, PK_ERR_PARSE, what);
        }
    /* the box: voxel (i, j, k) holds the value at index point (i, j, k), so
     * the cells of the dense grid span half a voxel either side */
    if (st == PK_OK) {
        float lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = (float)(mat[4 * a] * ((double)t.lo[a] - 0.5) + vec[a]);
            hi[a] = (float)(mat[4 * a] * ((double)t.hi[a] + 0.5) + vec[a]);
            if (!(isfinite(lo[a]) && isfinite(hi[a]) && lo[a] < hi[a]))
                st = nv_grid_error(&t, PK_ERR_PARSE, "the grid's box in world space is empty or not finite");
        }
        box->lo = v3(lo[0], lo[1], lo[2]);
        box->hi = v3(hi[0], hi[1], hi[2]);
    }
    if (st != PK_OK) {
        mem_free(al, t.v);
        return st;
    }
    out->nx = (int)t.dim[0], out->ny = (int)t.dim[1], out->nz = (int)t.dim[2];
    out->channels = 1;
    out->data = t.v;
    return PK_OK;
}

static pk_status nv_parse(pk_context *ctx, const pk_allocator *al, const char *path, const unsigned char *d, size_t n,
                          const char *grid, medium_grid *out, aabb *box)
{
    nv_reader r = {.ctx = ctx, .path = path, .d = d, .n = n, .want = grid && grid[0] ? grid : NULL};
    if (n < 8 || !nv_magic(d, "012"))
        return ctx_error(ctx, PK_ERR_PARSE, "%s: not a NanoVDB file (it does not start with \"NanoVDB\")", path);
    /* "NanoVDB0" starts both a segment and, from older writers, a grid: a
     * segment header has the version where a grid has its checksum */
    bool raw = d[7] == '1';
    if (d[7] == '0' && n >= NV_GRID_SIZE && nv_u32(d + 8) >> 21 != NV_MAJOR &&
        nv_u32(d + NV_GRID_OFF_VERSION) >> 21 == NV_MAJOR)
        raw = true;
    nv_found f = {0};
    pk_status st = raw ? nv_find_raw(&r, &f) : nv_find_in_segments(&r, &f);
    if (st != PK_OK) return st;
    if (!f.size) {
        if (r.want)
            return ctx_error(ctx, PK_ERR_PARSE, "%s: no grid named '%s' (%s%s)", path, r.want,
                             r.ngrids ? "the file has " : "the file has no grids", r.names);
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "%s: no float grid (%s%s)", path,
                         r.ngrids ? "the file has " : "the file has no grids", r.names);
    }
    return nv_read_grid(&r, al, &f, out, box);
}

pk_status grid_read_nanovdb(pk_context *ctx, const pk_allocator *al, const char *path, const char *grid,
                            medium_grid *out, aabb *box)
{
    *out = (medium_grid){0};
    *box = aabb_empty();
    char *data = NULL;
    size_t size = 0;
    pk_status st = file_read_all(ctx, path, &data, &size);
    if (st != PK_OK) return st;
    st = nv_parse(ctx, al, path, (const unsigned char *)data, size, grid, out, box);
    mem_free(&ctx->alloc, data);
    if (st != PK_OK) {
        *out = (medium_grid){0};
        *box = aabb_empty();
    }
    return st;
}
