/*
 * test_grid_io.c - the grid file readers of participating media
 * (src/io/grid_io.h): Mitsuba .vol files written here, read back value for
 * value with their size and box; hostile ones (truncated anywhere, NaN and
 * infinite values, zero, negative and huge sizes, foreign versions,
 * encodings and channel counts, empty and inverted boxes) each refused
 * with one message that names the file, nothing left allocated. NanoVDB
 * files written here in that format's layout, read back and refused the
 * same way; an OpenVDB file made by OpenVDB (tests/data/media/grid.vdb),
 * read back where the build has OpenVDB, refused with a message where not.
 */
#include "test.h"

#include "io/grid_io.h"
#include "warnings.h"

#include <stdint.h>

/* ---- an allocator that counts live blocks ---------------------------------- */

static long live_blocks;
static size_t largest_block; /* the largest size asked for (reset by the tests that read it) */

static void *count_realloc(void *user, void *ptr, size_t size)
{
    (void)user;
    if (size == 0) {
        if (ptr) live_blocks--;
        free(ptr);
        return NULL;
    }
    if (size > largest_block) largest_block = size;
    void *p = realloc(ptr, size);
    if (p && !ptr) live_blocks++;
    return p;
}

static const pk_allocator counting = {count_realloc, NULL};

/* ---- files ------------------------------------------------------------------ */

static char tmpdir[256];

static const char *tmp_path(const char *name)
{
    static char buf[4][512];
    static int k;
    k = (k + 1) & 3;
    snprintf(buf[k], sizeof buf[k], "%s/%s", tmpdir, name);
    return buf[k];
}

static void write_file(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    REQUIRE(f);
    REQUIRE(fwrite(data, 1, n, f) == n);
    REQUIRE(fclose(f) == 0);
}

/* a growing byte buffer, little endian */
typedef struct bytes {
    unsigned char *p;
    size_t n, cap;
} bytes;

static void put(bytes *b, const void *src, size_t n)
{
    if (b->n + n > b->cap) {
        b->cap = (b->n + n) * 2 + 64;
        b->p = realloc(b->p, b->cap);
        REQUIRE(b->p);
    }
    memcpy(b->p + b->n, src, n);
    b->n += n;
}

static void put_u8(bytes *b, unsigned v)
{
    const unsigned char c = (unsigned char)v;
    put(b, &c, 1);
}

static void put_u32(bytes *b, uint32_t v)
{
    const unsigned char c[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                                (unsigned char)(v >> 24)};
    put(b, c, 4);
}

static void put_i32(bytes *b, int32_t v) { put_u32(b, (uint32_t)v); }

static void put_f32(bytes *b, float v)
{
    uint32_t u;
    memcpy(&u, &v, 4);
    put_u32(b, u);
}

/* ---- .vol ------------------------------------------------------------------- */

/* The value of voxel (x, y, z) channel c in the test grids. */
static float vol_value(int x, int y, int z, int c) { return (float)(x + 10 * y + 100 * z) + 0.25f * (float)c; }

static bytes vol_bytes(int version, int encoding, int nx, int ny, int nz, int channels, const float box[6],
                       size_t nvalues)
{
    bytes b = {0};
    put(&b, "VOL", 3);
    put_u8(&b, (unsigned)version);
    put_i32(&b, encoding);
    put_i32(&b, nx), put_i32(&b, ny), put_i32(&b, nz);
    put_i32(&b, channels);
    for (int i = 0; i < 6; i++) put_f32(&b, box[i]);
    size_t k = 0;
    for (int z = 0; z < nz && k < nvalues; z++)
        for (int y = 0; y < ny && k < nvalues; y++)
            for (int x = 0; x < nx && k < nvalues; x++)
                for (int c = 0; c < channels && k < nvalues; c++, k++) put_f32(&b, vol_value(x, y, z, c));
    return b;
}

static const float unit_box[6] = {-1.0f, 0.5f, 2.0f, 3.0f, 1.5f, 2.25f};

static void check_vol_good(pk_context *ctx, int channels)
{
    const int nx = 4, ny = 3, nz = 2;
    bytes b = vol_bytes(3, 1, nx, ny, nz, channels, unit_box, (size_t)-1);
    char name[64];
    snprintf(name, sizeof name, "good%d.vol", channels);
    const char *path = tmp_path(name);
    write_file(path, b.p, b.n);
    free(b.p);
    medium_grid g;
    aabb box;
    pk_status st = grid_read_vol(ctx, &counting, path, &g, &box);
    REQUIRE(st == PK_OK);
    CHECK(g.nx == nx && g.ny == ny && g.nz == nz && g.channels == channels && g.data);
    CHECK(box.lo.x == -1.0f && box.lo.y == 0.5f && box.lo.z == 2.0f);
    CHECK(box.hi.x == 3.0f && box.hi.y == 1.5f && box.hi.z == 2.25f);
    int bad = 0;
    for (int z = 0; z < nz; z++)
        for (int y = 0; y < ny; y++)
            for (int x = 0; x < nx; x++)
                for (int c = 0; c < channels; c++) {
                    const float v = g.data[(((size_t)z * ny + y) * nx + x) * channels + c];
                    if (v != vol_value(x, y, z, c)) bad++;
                }
    CHECKF(bad == 0, "%d values differ", bad);
    /* the lookup at a voxel's centre reads that voxel */
    const vec3 q = v3((2 + 0.5f) / nx, (1 + 0.5f) / ny, (1 + 0.5f) / nz);
    const vec3 v = medium_grid_lookup(&g, q);
    CHECK_NEAR(v.x, vol_value(2, 1, 1, 0), 1e-4);
    if (channels == 3) CHECK_NEAR(v.z, vol_value(2, 1, 1, 2), 1e-4);
    mem_free(&counting, g.data);
    CHECK(live_blocks == 0);
    CHECK(pk_context_status(ctx) == PK_OK);
}

/* The file is refused with want, a message naming it and containing part;
 * nothing is left allocated and out is empty. */
static void expect_refused(pk_context *ctx, const char *path, pk_status st, medium_grid *g, pk_status want,
                           const char *part)
{
    const char *msg = pk_context_error(ctx);
    CHECKF(st == want, "%s: status %d, want %d (%s)", path, (int)st, (int)want, msg);
    CHECKF(strncmp(msg, path, strlen(path)) == 0 && msg[strlen(path)] == ':', "%s: message '%s' does not name the file",
           path, msg);
    CHECKF(strstr(msg, part) != NULL, "%s: message '%s' does not say '%s'", path, msg, part);
    CHECK(g->data == NULL && g->nx == 0);
    CHECKF(live_blocks == 0, "%s: %ld blocks left", path, live_blocks);
    pk_context_clear_error(ctx);
}

static void vol_refused(pk_context *ctx, const char *name, const bytes *b, pk_status want, const char *part)
{
    const char *path = tmp_path(name);
    write_file(path, b->p, b->n);
    medium_grid g;
    aabb box;
    pk_status st = grid_read_vol(ctx, &counting, path, &g, &box);
    expect_refused(ctx, path, st, &g, want, part);
}

static void check_vol_hostile(pk_context *ctx)
{
    /* truncated everywhere: inside the magic, the header, the box and the data */
    bytes full = vol_bytes(3, 1, 3, 2, 2, 3, unit_box, (size_t)-1);
    for (size_t cut = 0; cut < full.n; cut += (cut < 52 ? 1 : 7)) {
        bytes t = full;
        t.n = cut;
        char name[64];
        snprintf(name, sizeof name, "cut%zu.vol", cut);
        vol_refused(ctx, name, &t, PK_ERR_PARSE, "truncated");
    }
    free(full.p);

    bytes b = vol_bytes(3, 1, 2, 2, 2, 1, unit_box, (size_t)-1);
    b.p[0] = 'X';
    vol_refused(ctx, "magic.vol", &b, PK_ERR_PARSE, "VOL");
    free(b.p);

    b = vol_bytes(2, 1, 2, 2, 2, 1, unit_box, (size_t)-1);
    vol_refused(ctx, "version.vol", &b, PK_ERR_UNSUPPORTED, "version 2");
    free(b.p);
    b = vol_bytes(3, 2, 2, 2, 2, 1, unit_box, (size_t)-1);
    vol_refused(ctx, "encoding.vol", &b, PK_ERR_UNSUPPORTED, "encoding 2");
    free(b.p);
    b = vol_bytes(3, 1, 2, 2, 2, 2, unit_box, (size_t)-1);
    vol_refused(ctx, "channels2.vol", &b, PK_ERR_UNSUPPORTED, "2 channels");
    free(b.p);
    b = vol_bytes(3, 1, 2, 2, 2, 0, unit_box, (size_t)-1);
    vol_refused(ctx, "channels0.vol", &b, PK_ERR_UNSUPPORTED, "0 channels");
    free(b.p);

    /* sizes: zero, negative, beyond the limit, overflowing any product */
    const int sizes[][3] = {{0, 2, 2}, {2, -1, 2}, {2, 2, -2147483647 - 1}, {2, 2, 0}};
    for (int i = 0; i < 4; i++) {
        b = vol_bytes(3, 1, sizes[i][0], sizes[i][1], sizes[i][2], 1, unit_box, 0);
        vol_refused(ctx, "negative.vol", &b, PK_ERR_PARSE, "bad grid size");
        free(b.p);
    }
    const int huge[][3] = {{513, 512, 512}, {2147483647, 2147483647, 2147483647}, {65536, 65536, 65536},
                           {1, 1, 134217729}, {2147483647, 2, 1}};
    for (int i = 0; i < 5; i++) {
        b = vol_bytes(3, 1, huge[i][0], huge[i][1], huge[i][2], 3, unit_box, 16);
        vol_refused(ctx, "huge.vol", &b, PK_ERR_LIMIT, "beyond the limit");
        free(b.p);
    }
    /* at the limit exactly, but the data is not there: truncated, not allocated */
    b = vol_bytes(3, 1, 512, 512, 512, 1, unit_box, 16);
    vol_refused(ctx, "limit.vol", &b, PK_ERR_PARSE, "truncated");
    free(b.p);

    /* values */
    b = vol_bytes(3, 1, 2, 2, 2, 3, unit_box, (size_t)-1);
    const float nan = NAN, inf = INFINITY;
    memcpy(b.p + 48 + 4 * (3 * 5 + 1), &nan, 4); /* voxel 5 = (1, 0, 1), channel 1 */
    vol_refused(ctx, "nan.vol", &b, PK_ERR_PARSE, "voxel (1, 0, 1) channel 1 is NaN");
    memcpy(b.p + 48 + 4 * (3 * 5 + 1), &inf, 4);
    vol_refused(ctx, "inf.vol", &b, PK_ERR_PARSE, "is infinite");
    free(b.p);

    /* boxes: inverted, empty, not finite */
    const float inverted[6] = {0, 0, 0, 1, -1, 1}, empty[6] = {0, 0, 0, 1, 1, 0}, nanbox[6] = {0, 0, 0, 1, NAN, 1};
    b = vol_bytes(3, 1, 2, 2, 2, 1, inverted, (size_t)-1);
    vol_refused(ctx, "inverted.vol", &b, PK_ERR_PARSE, "inverted bounding box (y from 0 to -1)");
    free(b.p);
    b = vol_bytes(3, 1, 2, 2, 2, 1, empty, (size_t)-1);
    vol_refused(ctx, "empty.vol", &b, PK_ERR_PARSE, "empty or inverted bounding box (z");
    free(b.p);
    b = vol_bytes(3, 1, 2, 2, 2, 1, nanbox, (size_t)-1);
    vol_refused(ctx, "nanbox.vol", &b, PK_ERR_PARSE, "not finite");
    free(b.p);

    /* a missing file */
    medium_grid g;
    aabb box;
    const char *path = tmp_path("missing.vol");
    pk_status st = grid_read_vol(ctx, &counting, path, &g, &box);
    expect_refused(ctx, path, st, &g, PK_ERR_IO, "cannot open");
}

static void check_vol_trailing(pk_context *ctx)
{
    bytes b = vol_bytes(3, 1, 1, 1, 1, 1, unit_box, (size_t)-1);
    put_u32(&b, 7);
    const char *path = tmp_path("trailing.vol");
    write_file(path, b.p, b.n);
    free(b.p);
    warning_log w;
    warning_log_attach(ctx, &w);
    medium_grid g;
    aabb box;
    REQUIRE(grid_read_vol(ctx, &counting, path, &g, &box) == PK_OK);
    CHECK(g.nx == 1 && g.data[0] == vol_value(0, 0, 0, 0));
    CHECK(w.count == 1 && warning_log_count(&w, "4 bytes after the grid's data ignored") == 1);
    mem_free(&counting, g.data);
    pk_context_set_warning_handler(ctx, NULL, NULL);
}

/* ---- NanoVDB ------------------------------------------------------------------ */

/* A float grid written by hand in NanoVDB's layout (version 32.3.3): a root
 * with an upper node at the origin's block and a constant tile over the
 * block at x = -4096; the upper node's first lower node has a leaf at the
 * origin and a tile of 7.5 at x = 8..15; every other table entry is a tile
 * of another value. The root's box is x -2..9, y -1..3, z 0..2, so that
 * the dense grid meets all of them and the background (y = -1). */
enum {
    NVT_GRID = 672, NVT_TREE = 64, NVT_ROOT = 64, NVT_TILE = 32,
    NVT_UPPER = 8256 + 32768 * 8, NVT_LOWER = 1088 + 4096 * 8, NVT_LEAF = 96 + 512 * 4,
    NVT_ROOT_AT = NVT_GRID + NVT_TREE, NVT_UPPER_AT = NVT_ROOT_AT + NVT_ROOT + 2 * NVT_TILE,
    NVT_LOWER_AT = NVT_UPPER_AT + NVT_UPPER, NVT_LEAF_AT = NVT_LOWER_AT + NVT_LOWER,
    NVT_SIZE = NVT_LEAF_AT + NVT_LEAF,
};
static const uint32_t nvt_version = 32u << 21 | 3u << 10 | 3u;
static const int nvt_lo[3] = {-2, -1, 0}, nvt_hi[3] = {9, 3, 2};

static void set_u32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}
static void set_u64(unsigned char *p, uint64_t v)
{
    for (int i = 0; i < 8; i++) p[i] = (unsigned char)(v >> (8 * i));
}
static void set_f32(unsigned char *p, float v)
{
    uint32_t u;
    memcpy(&u, &v, 4);
    set_u32(p, u);
}
static void set_f64(unsigned char *p, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    set_u64(p, u);
}

static float nvt_leaf_value(int x, int y, int z) { return 1.0f + (float)x + 10.0f * (float)y + 100.0f * (float)z; }

/* What a lookup returns at index (x, y, z) inside the root's box. */
static float nvt_expected(int x, int y, int z)
{
    if (y < 0) return 0.5f;            /* no root tile: the background */
    if (x < 0) return 3.0f;            /* the constant root tile */
    if (x < 8) return nvt_leaf_value(x, y, z);
    return 7.5f;                       /* the lower node's tile */
}

static uint64_t nvt_key(int32_t x, int32_t y, int32_t z)
{
    return (uint64_t)((uint32_t)z >> 12) | (uint64_t)((uint32_t)y >> 12) << 21 | (uint64_t)((uint32_t)x >> 12) << 42;
}

/* The grid's bytes (NVT_SIZE of them), named name, of value type type. */
static unsigned char *nvt_grid(const char *name, uint32_t type, const char *magic)
{
    unsigned char *g = calloc(1, NVT_SIZE);
    REQUIRE(g);
    memcpy(g, magic, 8);
    set_u32(g + 16, nvt_version);
    set_u32(g + 28, 1);              /* grid count */
    set_u64(g + 32, NVT_SIZE);
    snprintf((char *)g + 40, 256, "%s", name);
    const double scale[3] = {0.5, 0.25, 2.0}, shift[3] = {1.0, 2.0, 3.0};
    for (int a = 0; a < 3; a++) {
        set_f32(g + 296 + 16 * a, (float)scale[a]);          /* matF diagonal */
        set_f32(g + 296 + 36 + 16 * a, (float)(1.0 / scale[a]));
        set_f32(g + 296 + 72 + 4 * a, (float)shift[a]);
        set_f64(g + 296 + 88 + 32 * a, scale[a]);            /* matD diagonal */
        set_f64(g + 296 + 160 + 32 * a, 1.0 / scale[a]);
        set_f64(g + 296 + 232 + 8 * a, shift[a]);
        set_f64(g + 608 + 8 * a, scale[a]);                  /* voxel size */
    }
    set_u32(g + 632, 2);             /* fog volume */
    set_u32(g + 636, type);
    unsigned char *tree = g + NVT_GRID;
    set_u64(tree + 0, NVT_LEAF_AT - NVT_GRID);
    set_u64(tree + 8, NVT_LOWER_AT - NVT_GRID);
    set_u64(tree + 16, NVT_UPPER_AT - NVT_GRID);
    set_u64(tree + 24, NVT_ROOT_AT - NVT_GRID);
    set_u32(tree + 32, 1), set_u32(tree + 36, 1), set_u32(tree + 40, 1);
    unsigned char *root = g + NVT_ROOT_AT;
    for (int a = 0; a < 3; a++) set_u32(root + 4 * a, (uint32_t)nvt_lo[a]), set_u32(root + 12 + 4 * a, (uint32_t)nvt_hi[a]);
    set_u32(root + 24, 2);           /* tiles */
    set_f32(root + 28, 0.5f);        /* background */
    unsigned char *tile = root + NVT_ROOT;
    set_u64(tile, nvt_key(0, 0, 0));
    set_u64(tile + 8, NVT_UPPER_AT - NVT_ROOT_AT);
    set_u32(tile + 16, 1);
    tile += NVT_TILE;
    set_u64(tile, nvt_key(-4096, 0, 0));
    set_u32(tile + 16, 1);
    set_f32(tile + 20, 3.0f);
    unsigned char *upper = g + NVT_UPPER_AT;
    for (int n = 0; n < 32768; n++) set_f32(upper + 8256 + 8 * n, 0.0f);
    upper[4128] = 1; /* child mask, slot 0 */
    upper[32] = 1;   /* value mask */
    set_u64(upper + 8256, NVT_LOWER_AT - NVT_UPPER_AT);
    unsigned char *lower = g + NVT_LOWER_AT;
    for (int n = 0; n < 4096; n++) set_f32(lower + 1088 + 8 * n, 0.25f);
    lower[544] = 1;
    set_u64(lower + 1088, NVT_LEAF_AT - NVT_LOWER_AT);
    set_f32(lower + 1088 + 8 * (1 << 8), 7.5f); /* slot (1, 0, 0): x 8..15 */
    unsigned char *leaf = g + NVT_LEAF_AT;
    for (int x = 0; x < 8; x++)
        for (int y = 0; y < 8; y++)
            for (int z = 0; z < 8; z++) set_f32(leaf + 96 + 4 * (x << 6 | y << 3 | z), nvt_leaf_value(x, y, z));
    memset(leaf + 16, 0xff, 64);
    return g;
}

typedef struct nvt_entry {
    const char *name;
    uint32_t type;
    const unsigned char *data;
    size_t size;
} nvt_entry;

/* A one-segment file of the given grids. */
static bytes nvt_file(const nvt_entry *e, int n, uint16_t codec)
{
    bytes b = {0};
    put(&b, "NanoVDB0", 8);
    put_u32(&b, nvt_version);
    const unsigned char c[4] = {(unsigned char)n, 0, (unsigned char)codec, (unsigned char)(codec >> 8)};
    put(&b, c, 4);
    for (int i = 0; i < n; i++) {
        unsigned char m[176] = {0};
        set_u64(m, e[i].size);
        set_u64(m + 8, e[i].size);
        set_u32(m + 32, e[i].type);
        set_u32(m + 136, (uint32_t)strlen(e[i].name) + 1);
        set_u32(m + 172, nvt_version);
        put(&b, m, sizeof m);
        put(&b, e[i].name, strlen(e[i].name) + 1);
    }
    for (int i = 0; i < n; i++) put(&b, e[i].data, e[i].size);
    return b;
}

static void nvt_check_dense(const medium_grid *g, const aabb *box)
{
    const int nx = nvt_hi[0] - nvt_lo[0] + 1, ny = nvt_hi[1] - nvt_lo[1] + 1, nz = nvt_hi[2] - nvt_lo[2] + 1;
    CHECKF(g->nx == nx && g->ny == ny && g->nz == nz && g->channels == 1, "%d x %d x %d x %d", g->nx, g->ny, g->nz,
           g->channels);
    int bad = 0;
    for (int z = 0; z < nz; z++)
        for (int y = 0; y < ny; y++)
            for (int x = 0; x < nx; x++) {
                const float v = g->data[((size_t)z * ny + y) * nx + x];
                const float want = nvt_expected(x + nvt_lo[0], y + nvt_lo[1], z + nvt_lo[2]);
                if (v != want && bad++ < 5)
                    fprintf(stderr, "index (%d, %d, %d): %g, want %g\n", x + nvt_lo[0], y + nvt_lo[1], z + nvt_lo[2],
                            (double)v, (double)want);
            }
    CHECKF(bad == 0, "%d values differ", bad);
    /* index box -2.5..9.5, -1.5..3.5, -0.5..2.5 through scale (0.5, 0.25, 2) and shift (1, 2, 3) */
    CHECK(box->lo.x == -0.25f && box->lo.y == 1.625f && box->lo.z == 2.0f);
    CHECK(box->hi.x == 5.75f && box->hi.y == 2.875f && box->hi.z == 8.0f);
}

static pk_status nvt_read(pk_context *ctx, const char *name, const bytes *b, const char *grid, medium_grid *g,
                          aabb *box, const char **path)
{
    *path = tmp_path(name);
    write_file(*path, b->p, b->n);
    return grid_read_nanovdb(ctx, &counting, *path, grid, g, box);
}

static void check_nanovdb_good(pk_context *ctx)
{
    unsigned char *density = nvt_grid("density", 1, "NanoVDB0");
    unsigned char *temp = nvt_grid("temperature", 2, "NanoVDB0");
    const nvt_entry one = {"density", 1, density, NVT_SIZE};
    bytes b = nvt_file(&one, 1, 0);
    medium_grid g;
    aabb box;
    const char *path;
    REQUIRE(nvt_read(ctx, "one.nvdb", &b, NULL, &g, &box, &path) == PK_OK);
    nvt_check_dense(&g, &box);
    mem_free(&counting, g.data);
    REQUIRE(nvt_read(ctx, "one.nvdb", &b, "density", &g, &box, &path) == PK_OK);
    nvt_check_dense(&g, &box);
    mem_free(&counting, g.data);
    free(b.p);

    /* the first float grid, by default, after a grid of doubles */
    const nvt_entry two[2] = {{"temperature", 2, temp, NVT_SIZE}, {"density", 1, density, NVT_SIZE}};
    b = nvt_file(two, 2, 0);
    REQUIRE(nvt_read(ctx, "two.nvdb", &b, "", &g, &box, &path) == PK_OK);
    nvt_check_dense(&g, &box);
    mem_free(&counting, g.data);
    pk_status st = nvt_read(ctx, "two.nvdb", &b, "temperature", &g, &box, &path);
    expect_refused(ctx, path, st, &g, PK_ERR_UNSUPPORTED, "grid 'temperature': values of type double");
    st = nvt_read(ctx, "two.nvdb", &b, "smoke", &g, &box, &path);
    expect_refused(ctx, path, st, &g, PK_ERR_PARSE, "no grid named 'smoke' (the file has 'temperature', 'density')");
    free(b.p);
    /* two segments, one grid each */
    b = nvt_file(two, 1, 0);
    bytes second = nvt_file(two + 1, 1, 0);
    put(&b, second.p, second.n);
    free(second.p);
    REQUIRE(nvt_read(ctx, "segments.nvdb", &b, NULL, &g, &box, &path) == PK_OK);
    nvt_check_dense(&g, &box);
    mem_free(&counting, g.data);
    st = nvt_read(ctx, "segments.nvdb", &b, "nothing", &g, &box, &path);
    expect_refused(ctx, path, st, &g, PK_ERR_PARSE, "no grid named 'nothing' (the file has 'temperature', 'density')");
    free(b.p);
    b = nvt_file(two, 1, 0);
    st = nvt_read(ctx, "nofloat.nvdb", &b, NULL, &g, &box, &path);
    expect_refused(ctx, path, st, &g, PK_ERR_UNSUPPORTED, "no float grid (the file has 'temperature')");
    free(b.p);

    /* a grid as it lies in memory, no segment header */
    memcpy(density, "NanoVDB1", 8);
    b = (bytes){density, NVT_SIZE, NVT_SIZE};
    REQUIRE(nvt_read(ctx, "raw.nvdb", &b, "density", &g, &box, &path) == PK_OK);
    nvt_check_dense(&g, &box);
    mem_free(&counting, g.data);
    memcpy(density, "NanoVDB0", 8);
    REQUIRE(nvt_read(ctx, "raw0.nvdb", &b, NULL, &g, &box, &path) == PK_OK);
    nvt_check_dense(&g, &box);
    mem_free(&counting, g.data);
    CHECK(live_blocks == 0);
    free(density);
    free(temp);
}

/* The one-grid file with the grid's bytes changed by edit, refused. */
static void nvt_refused(pk_context *ctx, const char *name, void (*edit)(unsigned char *g), uint16_t codec,
                        pk_status want, const char *part)
{
    unsigned char *grid = nvt_grid("density", 1, "NanoVDB0");
    if (edit) edit(grid);
    const nvt_entry one = {"density", 1, grid, NVT_SIZE};
    bytes b = nvt_file(&one, 1, codec);
    medium_grid g;
    aabb box;
    const char *path;
    pk_status st = nvt_read(ctx, name, &b, NULL, &g, &box, &path);
    expect_refused(ctx, path, st, &g, want, part);
    free(b.p);
    free(grid);
}

static void edit_leaf_nan(unsigned char *g) { set_f32(g + NVT_LEAF_AT + 96 + 4 * (3 << 6 | 2 << 3 | 1), NAN); }
static void edit_bg_inf(unsigned char *g) { set_f32(g + NVT_ROOT_AT + 28, INFINITY); }
static void edit_upper_out(unsigned char *g) { set_u64(g + NVT_ROOT_AT + NVT_ROOT + 8, NVT_SIZE); }
static void edit_upper_back(unsigned char *g) { set_u64(g + NVT_ROOT_AT + NVT_ROOT + 8, (uint64_t)-(int64_t)NVT_ROOT_AT); }
static void edit_upper_huge(unsigned char *g) { set_u64(g + NVT_ROOT_AT + NVT_ROOT + 8, (uint64_t)INT64_MIN); }
static void edit_lower_out(unsigned char *g) { set_u64(g + NVT_UPPER_AT + 8256, (uint64_t)INT64_MAX); }
static void edit_leaf_out(unsigned char *g) { set_u64(g + NVT_LOWER_AT + 1088, NVT_LEAF_AT - NVT_LOWER_AT + 1); }
static void edit_root_out(unsigned char *g) { set_u64(g + NVT_GRID + 24, NVT_SIZE); }
static void edit_tiles(unsigned char *g) { set_u32(g + NVT_ROOT_AT + 24, 1u << 30); }
static void edit_same_key(unsigned char *g) { set_u64(g + NVT_ROOT_AT + NVT_ROOT + NVT_TILE, nvt_key(0, 0, 0)); }
static void edit_huge(unsigned char *g) { set_u32(g + NVT_ROOT_AT + 12, 600), set_u32(g + NVT_ROOT_AT + 16, 600), set_u32(g + NVT_ROOT_AT + 20, 600); }
static void edit_widest(unsigned char *g) { set_u32(g + NVT_ROOT_AT, (uint32_t)INT32_MIN), set_u32(g + NVT_ROOT_AT + 12, INT32_MAX); }
static void edit_empty(unsigned char *g) { set_u32(g + NVT_ROOT_AT + 4, 5), set_u32(g + NVT_ROOT_AT + 16, 4); }
static void edit_rotate(unsigned char *g) { set_f64(g + 296 + 88 + 8, 0.1); }
static void edit_flip(unsigned char *g) { set_f64(g + 296 + 88, -0.5); }
static void edit_version(unsigned char *g) { set_u32(g + 16, 31u << 21); }
static void edit_type(unsigned char *g) { set_u32(g + 636, 15); }
static void edit_magic(unsigned char *g) { g[3] = 'X'; }
static void edit_size(unsigned char *g) { set_u64(g + 32, NVT_SIZE + 1); }

/* A box of 8 x 3 x 4194306 voxels (100 M, within the voxel limit: 403 MB
 * dense) in a grid of 864 bytes, a root of two constant tiles and no node
 * (as a fuzzer found it): refused for its size before the dense grid is
 * allocated. Then the hand-made grid with a box of 512 x 512 x 500 voxels
 * (plausible for its 307 KB) and an upper node's offset out of the grid:
 * refused by the walk over the tree before the dense grid is allocated. */
static void check_nanovdb_box_before_alloc(pk_context *ctx)
{
    enum { SMALL = NVT_GRID + NVT_TREE + NVT_ROOT + 2 * NVT_TILE };
    unsigned char *small = nvt_grid("density", 1, "NanoVDB0"); /* its first SMALL bytes */
    set_u64(small + 32, SMALL);
    memset(small + NVT_GRID, 0, NVT_TREE);
    set_u64(small + NVT_GRID + 24, NVT_ROOT_AT - NVT_GRID);
    const int32_t lo[3] = {-3, 0, 0}, hi[3] = {4, 2, 4194305};
    for (int a = 0; a < 3; a++)
        set_u32(small + NVT_ROOT_AT + 4 * a, (uint32_t)lo[a]), set_u32(small + NVT_ROOT_AT + 12 + 4 * a, (uint32_t)hi[a]);
    set_u64(small + NVT_ROOT_AT + NVT_ROOT + 8, 0); /* the tile at the origin: constant too */
    set_f32(small + NVT_ROOT_AT + NVT_ROOT + 20, 2.0f);
    const nvt_entry one = {"density", 1, small, SMALL};
    bytes b = nvt_file(&one, 1, 0);
    medium_grid g;
    aabb box;
    const char *path;
    largest_block = 0;
    pk_status st = nvt_read(ctx, "tiny_huge_box.nvdb", &b, NULL, &g, &box, &path);
    CHECKF(largest_block < ((size_t)1 << 20), "%zu bytes allocated for a grid of %d bytes", largest_block, (int)SMALL);
    expect_refused(ctx, path, st, &g, PK_ERR_PARSE,
                   "grid 'density': a box of 8 x 3 x 4194306 voxels in a grid of 864 bytes (more than 512 voxels a byte");
    free(b.p);
    free(small);

    unsigned char *grid = nvt_grid("density", 1, "NanoVDB0");
    set_u32(grid + NVT_ROOT_AT + 12, 509), set_u32(grid + NVT_ROOT_AT + 16, 510), set_u32(grid + NVT_ROOT_AT + 20, 499);
    edit_upper_out(grid);
    const nvt_entry big = {"density", 1, grid, NVT_SIZE};
    b = nvt_file(&big, 1, 0);
    largest_block = 0;
    st = nvt_read(ctx, "big_box_bad_upper.nvdb", &b, NULL, &g, &box, &path);
    CHECKF(largest_block < ((size_t)1 << 20), "%zu bytes allocated before the tree was checked", largest_block);
    expect_refused(ctx, path, st, &g, PK_ERR_PARSE, "an upper node lies outside the grid");
    free(b.p);
    free(grid);
}

static void check_nanovdb_hostile(pk_context *ctx)
{
    nvt_refused(ctx, "nan.nvdb", edit_leaf_nan, 0, PK_ERR_PARSE, "grid 'density': the value at voxel (3, 2, 1) is NaN");
    nvt_refused(ctx, "inf.nvdb", edit_bg_inf, 0, PK_ERR_PARSE, "voxel (-2, -1, 0) is infinite");
    nvt_refused(ctx, "upper.nvdb", edit_upper_out, 0, PK_ERR_PARSE, "an upper node lies outside the grid");
    nvt_refused(ctx, "upperback.nvdb", edit_upper_back, 0, PK_ERR_PARSE, "an upper node lies outside the grid");
    nvt_refused(ctx, "upperhuge.nvdb", edit_upper_huge, 0, PK_ERR_PARSE, "an upper node lies outside the grid");
    nvt_refused(ctx, "lower.nvdb", edit_lower_out, 0, PK_ERR_PARSE, "a lower node lies outside the grid");
    nvt_refused(ctx, "leaf.nvdb", edit_leaf_out, 0, PK_ERR_PARSE, "a leaf lies outside the grid");
    nvt_refused(ctx, "root.nvdb", edit_root_out, 0, PK_ERR_PARSE, "the root lies outside the grid");
    nvt_refused(ctx, "tiles.nvdb", edit_tiles, 0, PK_ERR_PARSE, "the root's table runs past the grid");
    nvt_refused(ctx, "key.nvdb", edit_same_key, 0, PK_ERR_PARSE, "two root tiles have the same key");
    nvt_refused(ctx, "huge.nvdb", edit_huge, 0, PK_ERR_LIMIT, "beyond the limit");
    nvt_refused(ctx, "widest.nvdb", edit_widest, 0, PK_ERR_LIMIT, "beyond the limit");
    nvt_refused(ctx, "empty.nvdb", edit_empty, 0, PK_ERR_PARSE, "no active voxels");
    nvt_refused(ctx, "rotate.nvdb", edit_rotate, 0, PK_ERR_UNSUPPORTED, "rotates or shears");
    nvt_refused(ctx, "flip.nvdb", edit_flip, 0, PK_ERR_UNSUPPORTED, "positive factors");
    nvt_refused(ctx, "version.nvdb", edit_version, 0, PK_ERR_UNSUPPORTED, "NanoVDB version 31.0.0 (only version 32.x");
    nvt_refused(ctx, "fp16.nvdb", edit_type, 0, PK_ERR_UNSUPPORTED, "values of type fp16");
    nvt_refused(ctx, "gridmagic.nvdb", edit_magic, 0, PK_ERR_PARSE, "bad grid magic");
    nvt_refused(ctx, "gridsize.nvdb", edit_size, 0, PK_ERR_PARSE, "size does not match");
    nvt_refused(ctx, "zip.nvdb", NULL, 1, PK_ERR_UNSUPPORTED, "compressed with Zip (only uncompressed files are read)");
    check_nanovdb_box_before_alloc(ctx);
    nvt_refused(ctx, "blosc.nvdb", NULL, 2, PK_ERR_UNSUPPORTED, "compressed with Blosc");

    /* the file's own header: magic, version, truncated anywhere */
    unsigned char *grid = nvt_grid("density", 1, "NanoVDB0");
    const nvt_entry one = {"density", 1, grid, NVT_SIZE};
    bytes b = nvt_file(&one, 1, 0);
    medium_grid g;
    aabb box;
    const char *path;
    b.p[2] = 'N';
    pk_status st = nvt_read(ctx, "magic.nvdb", &b, NULL, &g, &box, &path);
    expect_refused(ctx, path, st, &g, PK_ERR_PARSE, "not a NanoVDB file");
    b.p[2] = 'n';
    set_u32(b.p + 8, 33u << 21 | 1u << 10);
    st = nvt_read(ctx, "version.nvdb", &b, NULL, &g, &box, &path);
    expect_refused(ctx, path, st, &g, PK_ERR_UNSUPPORTED, "a segment of NanoVDB version 33.1.0");
    set_u32(b.p + 8, nvt_version);
    for (size_t cut = 0; cut < b.n; cut = cut < 300 ? cut + 1 : cut * 3 / 2) {
        bytes t = b;
        t.n = cut;
        st = nvt_read(ctx, "cut.nvdb", &t, NULL, &g, &box, &path);
        expect_refused(ctx, path, st, &g, PK_ERR_PARSE, cut < 8 ? "not a NanoVDB file" : "truncated");
    }
    free(b.p);
    free(grid);
}

/* ---- OpenVDB -------------------------------------------------------------------- */

/* OpenVDB 10 leaks the nodes it has read when a truncated file makes it
 * throw in the middle of a tree (the cuts of 1 KiB and more below): its
 * own allocations, reported by LeakSanitizer in the sanitizer build. Those
 * are left out of the report; the library's own allocations are counted
 * (live_blocks) and checked by LeakSanitizer as everywhere else. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) { return "leak:libopenvdb.so\n"; }

/* tests/data/media/grid.vdb, written by make_grid_vdb.cpp beside it: grids
 * "temperature" (doubles) and "density" (floats, background 0.5, voxels
 * (x, y, 7), x -2..2, y 0..1, = 100 + x + 10 y but (0, 1, 7) unset), voxel
 * size 0.25, shifted by (1, 2, 3); read through the OpenVDB module
 * (PK_OPENVDB_MODULE: the one this build made, "" where it has none). */
static void check_openvdb(pk_context *ctx)
{
    const char *path = PK_TEST_DATA "/media/grid.vdb";
    medium_grid g;
    aabb box;
    pk_status st;
    /* without the module (openvdb.module names a file that is not there, or
     * one that is not a module): one message naming OpenVDB's package */
    pk_context *bare = NULL;
    REQUIRE(pk_context_create(NULL, &bare) == PK_OK);
    char cfg[700];
    snprintf(cfg, sizeof cfg, "openvdb.module=%s/no-such-dir/paprsek_openvdb.so", tmpdir);
    REQUIRE(pk_context_set_config(bare, cfg) == PK_OK);
    CHECK(!grid_have_openvdb(bare));
    char expected[1200];
    snprintf(expected, sizeof expected, "%s: .vdb files are read by the OpenVDB module, which is not here "
             "(%s/no-such-dir/paprsek_openvdb.so is not there): install OpenVDB (Debian: libopenvdb-dev) and build "
             "the module (make build)", path, tmpdir);
    st = grid_read_openvdb(bare, &counting, path, NULL, &g, &box);
    CHECKF(strcmp(pk_context_error(bare), expected) == 0, "without the module: '%s'", pk_context_error(bare));
    expect_refused(bare, path, st, &g, PK_ERR_UNSUPPORTED, "libopenvdb-dev");
    const char *fake = tmp_path("fake_openvdb.so");
    write_file(fake, "not a shared object", 19);
    snprintf(cfg, sizeof cfg, "openvdb.module=%s", fake);
    REQUIRE(pk_context_set_config(bare, cfg) == PK_OK);
    st = grid_read_openvdb(bare, &counting, path, NULL, &g, &box);
    expect_refused(bare, path, st, &g, PK_ERR_UNSUPPORTED, "the OpenVDB module does not load: ");
    st = grid_read_openvdb(bare, &counting, path, NULL, &g, &box);
    expect_refused(bare, path, st, &g, PK_ERR_UNSUPPORTED, "; is OpenVDB installed? (Debian: libopenvdb-dev)");
    pk_context_destroy(bare);
    if (!PK_OPENVDB_MODULE[0]) {
        fprintf(stderr, "note: this build has no OpenVDB module: grid.vdb is only checked to be refused\n");
        return;
    }
    /* the module this build made (a build with OpenVDB must read the file) */
    snprintf(cfg, sizeof cfg, "openvdb.module=%s", PK_OPENVDB_MODULE);
    REQUIRE(pk_context_set_config(ctx, cfg) == PK_OK);
    REQUIRE(grid_have_openvdb(ctx));
    for (int k = 0; k < 2; k++) {
        st = grid_read_openvdb(ctx, &counting, path, k ? "density" : NULL, &g, &box);
        REQUIRE(st == PK_OK);
        CHECKF(g.nx == 5 && g.ny == 2 && g.nz == 1 && g.channels == 1, "%d x %d x %d x %d", g.nx, g.ny, g.nz,
               g.channels);
        int bad = 0;
        for (int y = 0; y < 2; y++)
            for (int x = -2; x <= 2; x++) {
                const float want = x == 0 && y == 1 ? 0.5f : (float)(100 + x + 10 * y);
                if (g.data[y * 5 + x + 2] != want) bad++;
            }
        CHECKF(bad == 0, "%d values differ", bad);
        /* index box -2.5..2.5, -0.5..1.5, 6.5..7.5, times 0.25, plus (1, 2, 3) */
        CHECK(box.lo.x == 0.375f && box.lo.y == 1.875f && box.lo.z == 4.625f);
        CHECK(box.hi.x == 1.625f && box.hi.y == 2.375f && box.hi.z == 4.875f);
        mem_free(&counting, g.data);
    }
    st = grid_read_openvdb(ctx, &counting, path, "temperature", &g, &box);
    expect_refused(ctx, path, st, &g, PK_ERR_UNSUPPORTED, "grid 'temperature': values of type double");
    st = grid_read_openvdb(ctx, &counting, path, "smoke", &g, &box);
    expect_refused(ctx, path, st, &g, PK_ERR_PARSE, "no grid named 'smoke' (the file has 'temperature', 'density')");

    /* truncated copies and foreign bytes */
    FILE *f = fopen(path, "rb");
    REQUIRE(f);
    static unsigned char buf[1 << 16];
    const size_t n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    REQUIRE(n > 1000 && n < sizeof buf);
    for (size_t cut = 0; cut < n; cut = cut < 64 ? cut + 8 : cut * 2) {
        const char *p = tmp_path("cut.vdb");
        write_file(p, buf, cut);
        st = grid_read_openvdb(ctx, &counting, p, NULL, &g, &box);
        expect_refused(ctx, p, st, &g, PK_ERR_PARSE, "not a readable OpenVDB file");
    }
    const char *p = tmp_path("foreign.vdb");
    write_file(p, "VOL\3 this is not an OpenVDB file at all", 40);
    st = grid_read_openvdb(ctx, &counting, p, NULL, &g, &box);
    expect_refused(ctx, p, st, &g, PK_ERR_PARSE, "not a readable OpenVDB file");
    p = tmp_path("missing.vdb");
    st = grid_read_openvdb(ctx, &counting, p, NULL, &g, &box);
    expect_refused(ctx, p, st, &g, PK_ERR_IO, "cannot open");
}

/* ---- the rest --------------------------------------------------------------- */

static void cleanup(void)
{
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", tmpdir);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "%s", "/tmp/test_grid_io.XXXXXX");
    REQUIRE(mkdtemp(tmpdir));
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    check_vol_good(ctx, 1);
    check_vol_good(ctx, 3);
    check_vol_hostile(ctx);
    check_vol_trailing(ctx);
    check_nanovdb_good(ctx);
    check_nanovdb_hostile(ctx);
    check_openvdb(ctx);
    pk_context_destroy(ctx);
    cleanup();
    return test_done("test_grid_io");
}
