/*
 * test_grid_io.c - the grid file readers of participating media
 * (src/io/grid_io.h): Mitsuba .vol files written here, read back value for
 * value with their size and box; hostile ones (truncated anywhere, NaN and
 * infinite values, zero, negative and huge sizes, foreign versions,
 * encodings and channel counts, empty and inverted boxes) each refused
 * with one message that names the file, nothing left allocated. NanoVDB
 * and OpenVDB files further down.
 */
#include "test.h"

#include "io/grid_io.h"
#include "warnings.h"

#include <stdint.h>

/* ---- an allocator that counts live blocks ---------------------------------- */

static long live_blocks;

static void *count_realloc(void *user, void *ptr, size_t size)
{
    (void)user;
    if (size == 0) {
        if (ptr) live_blocks--;
        free(ptr);
        return NULL;
    }
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
    pk_context_destroy(ctx);
    cleanup();
    return test_done("test_grid_io");
}
