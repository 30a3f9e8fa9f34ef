/*
 * mpi_main.c - paprsek-mpi: one image rendered by many processes over MPI
 * (docs/distributed.md), built on the public header and the options of
 * `paprsek render` (cli/render_common.c).
 *
 *   mpirun -np N paprsek-mpi render SCENE -o OUT [the render options]
 *
 * Rank 0 reads the scene's files (recording every file the library reads)
 * and broadcasts their bytes; every rank loads the scene from those bytes
 * and builds its own render session. Rank 0 deals tiles one at a time (two
 * outstanding per rank, so that a rank never waits for its next tile): a
 * rank that renders slowly asks less often and gets fewer tiles. Results
 * come back as the tile's sums and counts (and the sums of the AOVs the film
 * holds: albedo and normal when the image is denoised, those of --aov) and
 * are added into rank 0's film, which is resolved, denoised when `paprsek
 * render` would denoise it, and written like `paprsek render` writes it.
 * Rank 0 also renders, in a thread of its own, while its main thread deals
 * and merges (only that thread calls MPI).
 *
 * Every pixel's samples depend only on the scene, the options, the pixel
 * and the pass, and each tile's sums are added once per pass into a film
 * that held the same sums as one process's film: the image is the single
 * process's image bit for bit, whatever the number of ranks and the order
 * in which tiles finish. The denoiser runs once, on rank 0, on that image
 * and the AOVs merged the same way, and gives the same bits for any number
 * of threads: the denoised image is `paprsek render`'s too.
 */
#include "cli.h"

#include <errno.h>
#include <fcntl.h>
#include <mpi.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

enum {
    TAG_TILE = 1,   /* 0 -> rank: int32 tile index, pass */
    TAG_STOP = 2,   /* 0 -> rank: no more tiles (empty) */
    TAG_RESULT = 3, /* rank -> 0: header + sums + counts (+ the AOVs' sums) of one tile */
    TAG_FAIL = 4    /* rank -> 0: a message: the rank could not render */
};

#define DEPTH 2        /* tiles dealt ahead to each rank */
#define MSG_MAX 480    /* the message of a rank's failure */
#define HEADER_INTS 4  /* a result's header: tile, pass, width, height */

static volatile sig_atomic_t g_stop; /* the signal that stops the job (SIGTERM under mpirun) */
static volatile int g_cancel;        /* the renders' cancel flag */
_Static_assert(sizeof(sig_atomic_t) == sizeof(int), "the cancel flag is written by a signal handler");

static void on_signal(int sig)
{
    g_stop = sig;
    g_cancel = 1;
}

static int g_rank, g_size;
static unsigned g_aovs; /* the AOVs (PK_AOV_*) every film holds and every result carries */
static char g_host[MPI_MAX_PROCESSOR_NAME];

/* "paprsek-mpi: <fmt>" on stderr. */
static void say(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void say(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("paprsek-mpi: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    fflush(stderr);
}

/* Waits (without burning a core as MPI's blocking calls do) until a message
 * from source with tag (MPI_ANY_*) arrives or a signal stops the job.
 * Returns 1 with *st filled, 0 when stopped. */
static int wait_message(int source, int tag, MPI_Status *st)
{
    long ns = 20000;
    for (;;) {
        int flag = 0;
        MPI_Iprobe(source, tag, MPI_COMM_WORLD, &flag, st);
        if (flag) return 1;
        if (g_stop) return 0;
        struct timespec ts = {0, ns};
        nanosleep(&ts, NULL);
        if (ns < 2000000) ns += ns / 2;
    }
}

/* ---- the scene's files: recorded on rank 0, served on the others ---------- */

typedef struct file_entry {
    char *path;
    char *data;
    size_t size;
} file_entry;

typedef struct file_set {
    file_entry *files;
    size_t n, cap;
} file_set;

static void file_set_free(file_set *fs)
{
    for (size_t i = 0; i < fs->n; i++) {
        free(fs->files[i].path);
        free(fs->files[i].data);
    }
    free(fs->files);
    memset(fs, 0, sizeof *fs);
}

static const file_entry *file_set_find(const file_set *fs, const char *path)
{
    for (size_t i = 0; i < fs->n; i++)
        if (strcmp(fs->files[i].path, path) == 0) return &fs->files[i];
    return NULL;
}

static int file_set_add(file_set *fs, char *path, char *data, size_t size)
{
    if (fs->n == fs->cap) {
        size_t cap = fs->cap ? 2 * fs->cap : 16;
        file_entry *f = realloc(fs->files, cap * sizeof *f);
        if (!f) return 0;
        fs->files = f;
        fs->cap = cap;
    }
    fs->files[fs->n++] = (file_entry){path, data, size};
    return 1;
}

/* Rank 0's reader: the file system, as the library reads it, and a copy of
 * every file read, for the other ranks. */
static pk_status record_reader(void *user, const char *path, const void **data, size_t *size, char *why,
                               size_t why_cap)
{
    file_set *fs = user;
    const file_entry *e = file_set_find(fs, path);
    if (e) {
        *data = e->data;
        *size = e->size;
        return PK_OK;
    }
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        snprintf(why, why_cap, "cannot open: %s", strerror(errno));
        return PK_ERR_IO;
    }
    struct stat sb;
    if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
        close(fd);
        snprintf(why, why_cap, "not a regular file");
        return PK_ERR_IO;
    }
    if ((unsigned long long)sb.st_size > (unsigned long long)PK_MAX_FILE_BYTES) {
        close(fd);
        snprintf(why, why_cap, "file is larger than %zu bytes", (size_t)PK_MAX_FILE_BYTES);
        return PK_ERR_LIMIT;
    }
    size_t n = (size_t)sb.st_size, got = 0;
    char *buf = malloc(n ? n : 1);
    char *copy = strdup(path);
    if (!buf || !copy) {
        close(fd);
        free(buf);
        free(copy);
        return PK_ERR_NOMEM;
    }
    while (got < n) {
        ssize_t k = read(fd, buf + got, n - got);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) break;
        got += (size_t)k;
    }
    close(fd);
    if (got != n) {
        free(buf);
        free(copy);
        snprintf(why, why_cap, "read error");
        return PK_ERR_IO;
    }
    if (!file_set_add(fs, copy, buf, n)) {
        free(buf);
        free(copy);
        return PK_ERR_NOMEM;
    }
    *data = buf;
    *size = n;
    return PK_OK;
}

/* The other ranks' reader: only what rank 0 sent. */
static pk_status serve_reader(void *user, const char *path, const void **data, size_t *size, char *why,
                              size_t why_cap)
{
    const file_entry *e = file_set_find(user, path);
    if (!e) {
        snprintf(why, why_cap, "not among the files rank 0 sent (rank 0 did not read this file)");
        return PK_ERR_IO;
    }
    *data = e->data;
    *size = e->size;
    return PK_OK;
}

/* Broadcasts n bytes from rank 0 in pieces MPI's int counts can hold. */
static void bcast_bytes(void *buf, size_t n)
{
    const size_t piece = (size_t)1 << 28;
    for (size_t off = 0; off < n; off += piece) {
        size_t k = n - off < piece ? n - off : piece;
        MPI_Bcast((char *)buf + off, (int)k, MPI_BYTE, 0, MPI_COMM_WORLD);
    }
}

/* Rank 0 sends, the others receive the file set: a count and a size, then
 * per file the path's length, the path, the size and the bytes. Returns
 * the bytes broadcast, or 0 after a failure (out of memory) on this rank. */
static uint64_t bcast_files(file_set *fs, int *ok)
{
    uint64_t head[2] = {0, 0}; /* files, bytes of the packed set */
    char *packed = NULL;
    if (g_rank == 0) {
        uint64_t total = 0;
        for (size_t i = 0; i < fs->n; i++) total += 8 + strlen(fs->files[i].path) + 8 + fs->files[i].size;
        packed = malloc(total ? total : 1);
        if (packed) {
            char *p = packed;
            for (size_t i = 0; i < fs->n; i++) {
                uint64_t pl = strlen(fs->files[i].path), sz = fs->files[i].size;
                memcpy(p, &pl, 8);
                memcpy(p + 8, fs->files[i].path, pl);
                memcpy(p + 8 + pl, &sz, 8);
                memcpy(p + 16 + pl, fs->files[i].data, sz);
                p += 16 + pl + sz;
            }
            head[0] = fs->n;
            head[1] = total;
        }
    }
    MPI_Bcast(head, 2, MPI_UINT64_T, 0, MPI_COMM_WORLD);
    if (g_rank != 0) packed = malloc(head[1] ? head[1] : 1);
    /* everyone learns whether everyone has the buffer */
    int have = packed != NULL, all = 0;
    MPI_Allreduce(&have, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (!all) {
        free(packed);
        *ok = have;
        return 0;
    }
    bcast_bytes(packed, head[1]);
    *ok = 1;
    if (g_rank != 0) {
        const char *p = packed, *end = packed + head[1];
        for (uint64_t i = 0; i < head[0] && *ok; i++) {
            uint64_t pl, sz;
            if (end - p < 8) break;
            memcpy(&pl, p, 8);
            if ((uint64_t)(end - p - 8) < pl + 8) break;
            memcpy(&sz, p + 8 + pl, 8);
            if ((uint64_t)(end - p - 16) - pl < sz) break;
            char *path = malloc(pl + 1), *data = malloc(sz ? sz : 1);
            if (!path || !data || !file_set_add(fs, path, data, sz)) {
                free(path);
                free(data);
                *ok = 0;
                break;
            }
            memcpy(path, p + 8, pl);
            path[pl] = '\0';
            memcpy(data, p + 16 + pl, sz);
            p += 16 + pl + sz;
        }
    }
    free(packed);
    return head[1] + sizeof head;
}

/* ---- what every rank reports to rank 0 ----------------------------------- */

typedef struct rank_status {
    int32_t failed;
    char message[MSG_MAX];
    char host[64];
} rank_status;

typedef struct rank_report {
    pk_stats stats;
    uint64_t tiles;
    uint64_t bytes_sent, bytes_received;
    double busy_s; /* seconds in pk_renderer_render */
    double cpu_s;  /* the process's CPU time (user + system), start to end */
    char host[64];
} rank_report;

/* Gathers every rank's status at rank 0, which prints each failure naming
 * the rank. Returns 1 when every rank is fine (on every rank). */
static int all_ready(int failed, const char *message)
{
    rank_status me;
    memset(&me, 0, sizeof me);
    me.failed = failed;
    snprintf(me.message, sizeof me.message, "%s", message ? message : "");
    snprintf(me.host, sizeof me.host, "%.63s", g_host);
    rank_status *all = g_rank == 0 ? calloc((size_t)g_size, sizeof *all) : NULL;
    if (g_rank == 0 && !all) {
        say("out of memory");
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    MPI_Gather(&me, (int)sizeof me, MPI_BYTE, all, (int)sizeof me, MPI_BYTE, 0, MPI_COMM_WORLD);
    int any = 0;
    if (g_rank == 0) {
        for (int r = 0; r < g_size; r++)
            if (all[r].failed) {
                all[r].message[MSG_MAX - 1] = '\0';
                all[r].host[sizeof all[r].host - 1] = '\0';
                say("rank %d on %s: %s", r, all[r].host, all[r].message);
                any = 1;
            }
        free(all);
    }
    MPI_Bcast(&any, 1, MPI_INT, 0, MPI_COMM_WORLD);
    return !any;
}

/* ---- tiles ---------------------------------------------------------------- */

typedef struct job {
    pk_context *ctx;
    pk_renderer *r;
    pk_film *scratch; /* a whole-image film: each tile is rendered into it, taken out and cleared */
    const pk_region *tiles;
    int ntiles;
    int width;
} job;

/* Renders tile t of pass into the scratch film. */
static pk_status render_tile(job *j, int t, uint32_t pass, double *busy)
{
    const double t0 = cli_now();
    pk_renderer_set_pass(j->r, pass);
    pk_status st = pk_renderer_render(j->r, &j->tiles[t], 1, j->scratch);
    *busy += cli_now() - t0;
    return st;
}

/* The AOVs of g_aovs, lowest bit first: the order of their blocks in a result. */
static int aov_list(unsigned out[4])
{
    int n = 0;
    for (unsigned a = PK_AOV_ALBEDO; a <= PK_AOV_HEATMAP; a <<= 1)
        if (g_aovs & a) out[n++] = a;
    return n;
}

/* 3 floats per pixel of the tile g, from a film's array (rows of width
 * pixels) into out, row after row; those values zeroed in the film. */
static void take_rgb(float *from, int width, const pk_region *g, unsigned char *out)
{
    const size_t row3 = 3 * (size_t)g->width * sizeof(float);
    for (int y = 0; y < g->height; y++) {
        const size_t at = (size_t)(g->y + y) * (size_t)width + (size_t)g->x;
        memcpy(out + (size_t)y * row3, from + 3 * at, row3);
        memset(from + 3 * at, 0, row3);
    }
}

/* The tile's sums and counts, from the scratch film into out (w*h*3 floats,
 * w*h counts, then w*h*3 floats per AOV of g_aovs), and the region cleared
 * for the next tile. */
static void take_tile(job *j, int t, unsigned char *out)
{
    const pk_region *g = &j->tiles[t];
    uint32_t *counts = pk_film_counts(j->scratch);
    const size_t n = (size_t)g->width * (size_t)g->height, row1 = (size_t)g->width * sizeof(uint32_t);
    take_rgb(pk_film_sums(j->scratch), j->width, g, out);
    unsigned char *cp = out + 3 * n * sizeof(float);
    for (int y = 0; y < g->height; y++) {
        const size_t at = (size_t)(g->y + y) * (size_t)j->width + (size_t)g->x;
        memcpy(cp + (size_t)y * row1, counts + at, row1);
        memset(counts + at, 0, row1);
    }
    unsigned aov[4];
    const int na = aov_list(aov);
    for (int k = 0; k < na; k++)
        take_rgb(pk_film_aov_sums(j->scratch, aov[k]), j->width, g,
                 out + n * (3 * sizeof(float) + sizeof(uint32_t)) + (size_t)k * 3 * n * sizeof(float));
}

/* dst (3 floats per pixel, rows of width pixels) += in over the tile g (3
 * floats per pixel, row after row): one addition per value. */
static void add_rgb(float *dst, int width, const pk_region *g, const unsigned char *in)
{
    for (int y = 0; y < g->height; y++) {
        const size_t at = (size_t)(g->y + y) * (size_t)width + (size_t)g->x;
        for (int x = 0; x < g->width; x++) {
            const size_t q = (size_t)y * (size_t)g->width + (size_t)x;
            float v[3];
            memcpy(v, in + 3 * q * sizeof(float), sizeof v);
            for (int k = 0; k < 3; k++) dst[3 * (at + (size_t)x) + (size_t)k] += v[k];
        }
    }
}

/* Adds a tile taken by take_tile into film: each pixel's sums, count and AOV
 * sums once, as the renderer adds a tile (its region held what one process's
 * film holds). */
static void add_tile(pk_film *film, const pk_region *g, const unsigned char *in)
{
    uint32_t *counts = pk_film_counts(film);
    const int width = pk_film_width(film);
    const size_t n = (size_t)g->width * (size_t)g->height;
    add_rgb(pk_film_sums(film), width, g, in);
    for (int y = 0; y < g->height; y++) {
        const size_t at = (size_t)(g->y + y) * (size_t)width + (size_t)g->x;
        for (int x = 0; x < g->width; x++) {
            uint32_t c;
            memcpy(&c, in + 3 * n * sizeof(float) + ((size_t)y * (size_t)g->width + (size_t)x) * sizeof c, sizeof c);
            counts[at + (size_t)x] += c;
        }
    }
    unsigned aov[4];
    const int na = aov_list(aov);
    for (int k = 0; k < na; k++)
        add_rgb(pk_film_aov_sums(film, aov[k]), width, g,
                in + n * (3 * sizeof(float) + sizeof(uint32_t)) + (size_t)k * 3 * n * sizeof(float));
}

/* A result's bytes after its header: the sums and counts, and each AOV's sums. */
static size_t tile_bytes(const pk_region *g)
{
    unsigned aov[4];
    const size_t na = (size_t)aov_list(aov);
    return (size_t)g->width * (size_t)g->height * ((3 + 3 * na) * sizeof(float) + sizeof(uint32_t));
}

/* ---- ranks 1..N-1: render what rank 0 deals ------------------------------- */

static int worker(job *j, rank_report *rep, size_t max_tile)
{
    const size_t cap = HEADER_INTS * sizeof(int32_t) + max_tile;
    unsigned char *buf[2] = {malloc(cap), malloc(cap)};
    MPI_Request req[2] = {MPI_REQUEST_NULL, MPI_REQUEST_NULL};
    int which = 0, rc = 0;
    if (!buf[0] || !buf[1]) {
        const char *m = "out of memory";
        MPI_Send(m, (int)strlen(m) + 1, MPI_CHAR, 0, TAG_FAIL, MPI_COMM_WORLD);
        rc = 1;
        goto out;
    }
    for (;;) {
        MPI_Status ms;
        if (!wait_message(0, MPI_ANY_TAG, &ms)) {
            rc = -1;
            break;
        }
        if (ms.MPI_TAG == TAG_STOP) {
            MPI_Recv(NULL, 0, MPI_BYTE, 0, TAG_STOP, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            break;
        }
        int32_t msg[2];
        MPI_Recv(msg, 2, MPI_INT32_T, 0, TAG_TILE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        rep->bytes_received += sizeof msg;
        const int t = msg[0];
        if (t < 0 || t >= j->ntiles) continue; /* never sent */
        pk_status st = render_tile(j, t, (uint32_t)msg[1], &rep->busy_s);
        if (st == PK_ERR_CANCELLED) {
            rc = -1;
            break;
        }
        if (st != PK_OK) {
            char m[MSG_MAX];
            snprintf(m, sizeof m, "on %s: %s", g_host, pk_context_error(j->ctx));
            MPI_Send(m, (int)strlen(m) + 1, MPI_CHAR, 0, TAG_FAIL, MPI_COMM_WORLD);
            rc = 1;
            break;
        }
        /* the buffer of the send before last is free again */
        MPI_Wait(&req[which], MPI_STATUS_IGNORE);
        const pk_region *g = &j->tiles[t];
        int32_t head[HEADER_INTS] = {t, msg[1], g->width, g->height};
        memcpy(buf[which], head, sizeof head);
        take_tile(j, t, buf[which] + sizeof head);
        const size_t n = sizeof head + tile_bytes(g);
        MPI_Isend(buf[which], (int)n, MPI_BYTE, 0, TAG_RESULT, MPI_COMM_WORLD, &req[which]);
        rep->bytes_sent += n;
        rep->tiles++;
        which ^= 1;
    }
    if (rc == 0) MPI_Waitall(2, req, MPI_STATUSES_IGNORE);
out:
    if (rc != 0) return rc;
    free(buf[0]);
    free(buf[1]);
    return 0;
}

/* ---- rank 0: deal, merge, and render in a thread of its own --------------- */

typedef struct local {
    pthread_mutex_t mu;
    pthread_cond_t cv;
    job *j;
    pk_film *film;       /* rank 0's film: every finished tile is added here */
    int queue[DEPTH + 1][2]; /* tile, pass */
    int head, count;
    int quit;
    int done;            /* tiles finished (read by the dealer) */
    pk_status failed;    /* a render that failed (not cancelled) */
    unsigned char *buf;
    rank_report *rep;
} local;

static void *local_main(void *arg)
{
    local *l = arg;
    pthread_mutex_lock(&l->mu);
    for (;;) {
        while (!l->quit && l->count == 0) pthread_cond_wait(&l->cv, &l->mu);
        if (l->quit) break;
        const int t = l->queue[l->head][0], pass = l->queue[l->head][1];
        l->head = (l->head + 1) % (DEPTH + 1);
        l->count--;
        pthread_mutex_unlock(&l->mu);
        pk_status st = render_tile(l->j, t, (uint32_t)pass, &l->rep->busy_s);
        if (st == PK_OK) take_tile(l->j, t, l->buf);
        pthread_mutex_lock(&l->mu);
        if (st != PK_OK) {
            l->failed = st;
            break;
        }
        add_tile(l->film, &l->j->tiles[t], l->buf);
        l->rep->tiles++;
        l->done++;
    }
    pthread_mutex_unlock(&l->mu);
    return NULL;
}

typedef struct dealer {
    job *j;
    local *l;
    pk_film *film;
    cli_progress *bar;
    int outstanding0;    /* rank 0's own tiles not yet finished */
    int *outstanding;    /* per rank */
    int next, done;      /* this pass's next tile to deal, tiles merged */
    uint32_t pass;
    rank_report *rep;
    unsigned char *buf;
    size_t cap;
    int failed_rank;     /* a rank that reported a failure, or -1 */
    char failure[MSG_MAX];
} dealer;

/* Gives rank r (0: rank 0's thread) the next tile of the pass, if any. */
static void deal(dealer *d, int r)
{
    if (d->next >= d->j->ntiles) return;
    const int t = d->next++;
    if (r == 0) {
        pthread_mutex_lock(&d->l->mu);
        int at = (d->l->head + d->l->count) % (DEPTH + 1);
        d->l->queue[at][0] = t;
        d->l->queue[at][1] = (int)d->pass;
        d->l->count++;
        pthread_cond_signal(&d->l->cv);
        pthread_mutex_unlock(&d->l->mu);
        d->outstanding0++;
        return;
    }
    int32_t msg[2] = {t, (int32_t)d->pass};
    MPI_Send(msg, 2, MPI_INT32_T, r, TAG_TILE, MPI_COMM_WORLD);
    d->rep->bytes_sent += sizeof msg;
    d->outstanding[r]++;
}

/* One pass over every tile. Returns PK_OK, PK_ERR_CANCELLED (a signal), or
 * another status after a rank's failure (d->failed_rank, d->failure). */
static pk_status deal_pass(dealer *d, double t0, double seconds)
{
    d->next = 0;
    d->done = 0;
    /* rank 0's thread's count before it gets this pass's tiles */
    pthread_mutex_lock(&d->l->mu);
    int seen0 = d->l->done;
    pthread_mutex_unlock(&d->l->mu);
    for (int k = 0; k < DEPTH; k++)
        for (int r = 0; r < g_size; r++) deal(d, r);
    long ns = 20000;
    while (d->done < d->j->ntiles) {
        if (g_stop) return PK_ERR_CANCELLED;
        int progressed = 0;
        /* rank 0's own tiles */
        pthread_mutex_lock(&d->l->mu);
        const int now0 = d->l->done;
        const pk_status lf = d->l->failed;
        pthread_mutex_unlock(&d->l->mu);
        if (lf != PK_OK) {
            d->failed_rank = 0;
            return lf;
        }
        for (; seen0 < now0; seen0++) {
            d->outstanding0--;
            d->done++;
            deal(d, 0);
            progressed = 1;
        }
        /* the other ranks' */
        int flag = 0;
        MPI_Status ms;
        MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms);
        if (flag) {
            const int src = ms.MPI_SOURCE;
            int count = 0;
            MPI_Get_count(&ms, MPI_BYTE, &count);
            if (ms.MPI_TAG == TAG_FAIL || ms.MPI_TAG != TAG_RESULT || count < 0 || (size_t)count > d->cap) {
                memset(d->failure, 0, sizeof d->failure);
                if (ms.MPI_TAG == TAG_FAIL && count > 0 && count < MSG_MAX) {
                    MPI_Recv(d->failure, count, MPI_CHAR, src, TAG_FAIL, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                    d->failure[MSG_MAX - 1] = '\0';
                } else {
                    snprintf(d->failure, sizeof d->failure, "sent a message of %d bytes with tag %d", count,
                             ms.MPI_TAG);
                }
                d->failed_rank = src;
                return PK_ERR_IO;
            }
            MPI_Recv(d->buf, count, MPI_BYTE, src, TAG_RESULT, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            d->rep->bytes_received += (uint64_t)count;
            int32_t head[HEADER_INTS];
            memcpy(head, d->buf, sizeof head);
            const int t = head[0];
            if (t < 0 || t >= d->j->ntiles || (uint32_t)head[1] != d->pass || head[2] != d->j->tiles[t].width ||
                head[3] != d->j->tiles[t].height ||
                (size_t)count != sizeof head + tile_bytes(&d->j->tiles[t])) {
                d->failed_rank = src;
                snprintf(d->failure, sizeof d->failure, "sent a tile that was not dealt (tile %d, pass %d)", t,
                         head[1]);
                return PK_ERR_IO;
            }
            pthread_mutex_lock(&d->l->mu);
            add_tile(d->film, &d->j->tiles[t], d->buf + sizeof head);
            pthread_mutex_unlock(&d->l->mu);
            d->outstanding[src]--;
            d->done++;
            deal(d, src);
            progressed = 1;
        }
        if (progressed) {
            ns = 20000;
            const double el = cli_now() - t0;
            if (seconds > 0.0)
                cli_progress_update(d->bar, (uint64_t)(el < seconds ? el * 1000.0 : seconds * 1000.0),
                                    (uint64_t)(seconds * 1000.0), el);
            else
                cli_progress_update(d->bar, (uint64_t)d->done, (uint64_t)d->j->ntiles, el);
        } else {
            struct timespec ts = {0, ns};
            nanosleep(&ts, NULL);
            if (ns < 2000000) ns += ns / 2;
        }
    }
    return PK_OK;
}

/* ---- the program ------------------------------------------------------------ */

static void mpi_help(FILE *f)
{
    cli_render_usage(f, "usage: mpirun -np N paprsek-mpi render [SCENE] -o OUT [options]\n"
                        "\n"
                        "Renders one image with N processes (ranks), on one machine or many, and\n"
                        "writes exactly the image `paprsek render` writes with the same options.\n"
                        "Rank 0 reads SCENE and every file it names and sends their bytes to the\n"
                        "other ranks (no shared file system is needed), deals tiles to the ranks as\n"
                        "they finish, and writes OUT. Each rank renders with --threads threads (by\n"
                        "default the cores mpirun lets it use: see --bind-to and --map-by in\n"
                        "mpirun's manual). A denoised image (the default render, --denoise) is\n"
                        "denoised once, by rank 0, after the merge. Under mpirun the progress bar\n"
                        "is drawn only with --progress (on standard output). Details:\n"
                        "docs/distributed.md.\n");
    fputs("\nUnder mpirun, Ctrl-C stops every rank (mpirun sends them SIGTERM and, a\n"
          "second later, SIGKILL): rank 0 writes the finished tiles as OUT.partial in\n"
          "that second, and mpirun exits with status 1. When a rank cannot load the\n"
          "scene, every rank stops and rank 0 names the rank and the cause (exit\n"
          "status 1); when a rank dies, mpirun stops the job and names the rank.\n",
          f);
}

static void mpi_usage(FILE *f)
{
    fputs("usage: mpirun -np N paprsek-mpi render [SCENE] -o OUT [options]\n"
          "       paprsek-mpi render --help     the options\n"
          "       paprsek-mpi --version\n",
          f);
}

/* Statistics: the whole job's (rays, samples, time) and each rank's. */
static void print_ranks(const rank_report *reps, const pk_render_options *ro, double wall_s, uint64_t tiles_total)
{
    printf("%-28s %d\n", "ranks", g_size);
    printf("%-28s %.3f (wall clock, from the first tile dealt to the last merged)\n", "job render [s]", wall_s);
    for (int r = 0; r < g_size; r++) {
        const pk_stats *s = &reps[r].stats;
        const uint64_t rays = s->rays_camera + s->rays_shadow + s->rays_reflection + s->rays_refraction + s->rays_bounce;
        char label[40];
        snprintf(label, sizeof label, "rank %d", r);
        printf("%-28s %s, %d thread%s, %llu tiles (%.1f%%), %llu rays, %llu samples, busy %.3f s, cpu %.3f s, "
               "sent %llu B, received %llu B\n",
               label, reps[r].host, s->threads, s->threads == 1 ? "" : "s", (unsigned long long)reps[r].tiles,
               tiles_total ? 100.0 * (double)reps[r].tiles / (double)tiles_total : 0.0, (unsigned long long)rays,
               (unsigned long long)(s->pixels * (uint64_t)ro->spp), reps[r].busy_s, reps[r].cpu_s,
               (unsigned long long)reps[r].bytes_sent, (unsigned long long)reps[r].bytes_received);
    }
}

/* Sums the ranks' statistics into one table's worth; threads add up, the
 * render time is the job's wall clock. */
static pk_stats job_stats(const rank_report *reps, double wall_s)
{
    pk_stats t;
    memset(&t, 0, sizeof t);
    for (int r = 0; r < g_size; r++) {
        const pk_stats *s = &reps[r].stats;
        t.rays_camera += s->rays_camera;
        t.rays_shadow += s->rays_shadow;
        t.rays_reflection += s->rays_reflection;
        t.rays_refraction += s->rays_refraction;
        t.rays_bounce += s->rays_bounce;
        t.intersection_tests += s->intersection_tests;
        t.nodes_visited += s->nodes_visited;
        t.threads += s->threads;
        t.accel_builds += s->accel_builds;
        t.pixels += s->pixels;
        if (s->build_us > t.build_us) t.build_us = s->build_us; /* the ranks build at once */
    }
    t.render_s = wall_s;
    return t;
}

int main(int argc, char **argv)
{
    const double t_start = cli_now();
    cli_program = "paprsek-mpi";
    int provided = 0;
    if (MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
        fprintf(stderr, "paprsek-mpi: MPI could not start\n");
        return 1;
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &g_size);
    int hl = 0;
    MPI_Get_processor_name(g_host, &hl);
    if (provided < MPI_THREAD_FUNNELED && g_rank == 0)
        say("warning: this MPI does not promise threads; rank 0 renders in a thread of its own anyway");

    /* the command line, checked by rank 0 alone (one message, not N) */
    int rc = 0;
    if (g_rank == 0) {
        if (argc < 2) {
            mpi_usage(stderr);
            rc = 2;
        } else if (strcmp(argv[1], "--version") == 0 || strcmp(argv[1], "-v") == 0) {
            printf("paprsek-mpi %s\n", PK_VERSION_STRING);
            rc = -1;
        } else if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
            if (argc > 2 && strcmp(argv[1], "help") == 0 && strcmp(argv[2], "render") == 0)
                mpi_help(stdout);
            else
                mpi_usage(stdout);
            rc = -1;
        } else if (strcmp(argv[1], "render") != 0) {
            rc = cli_usage_error("unknown command '%s' (paprsek-mpi renders: paprsek-mpi render --help)", argv[1]);
        }
    }
    MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (rc) {
        MPI_Finalize();
        return rc < 0 ? 0 : rc;
    }
    cli_render_add_option((cli_option){.name = "tile", .id = CLI_RENDER_EXTRA, .kind = CLI_INT, .arg = "N",
                                       .help = "paprsek-mpi: the side of the square tiles dealt to the ranks, in "
                                               "pixels (the image is the same for any size)",
                                       .min = 8, .max = 1024, .default_value = 64});
    cli_render_add_option((cli_option){.name = "progress", .id = CLI_RENDER_EXTRA + 1, .kind = CLI_FLAG,
                                       .help = "paprsek-mpi: draw the progress bar on standard output (under "
                                               "mpirun, where the ranks' standard error is never a terminal)"});
    cli_render_opts o;
    pk_write_options wo;
    if (g_rank == 0) {
        rc = cli_render_parse(argc - 1, argv + 1, &o, mpi_help);
        if (rc == 0) rc = cli_render_check(&o, &wo);
        if (rc == 0 && (o.transparent || (o.aovs & PK_AOV_ALPHA)))
            rc = cli_usage_error("paprsek-mpi: --transparent and --aov alpha are for paprsek render only");
        if (rc == 0 && (o.noise > 0.0 || o.min_spp))
            rc = cli_usage_error("paprsek-mpi: --noise and --min-spp (adaptive sampling) are for paprsek render only");
    }
    MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (rc) {
        MPI_Finalize();
        return rc < 0 ? 0 : rc;
    }
    if (g_rank != 0 && cli_render_parse(argc - 1, argv + 1, &o, mpi_help) != 0) {
        /* the same arguments rank 0 accepted: cannot happen */
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    int tile = 64;
    if (o.extra[0]) cli_parse_int(o.extra[0], 8, 1024, &tile);

    /* the scene: rank 0 reads and records, the others are served */
    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) {
        say("rank %d: out of memory", g_rank);
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    cli_progress bar;
    cli_progress_init(&bar, stderr, o.quiet || g_rank != 0);
    /* Under mpirun the ranks' stderr is a pipe and their stdout a
     * pseudo-terminal whatever mpirun's own output is: --progress says that
     * mpirun's output is a terminal. */
    if (g_rank == 0 && !o.quiet && o.extra[1]) {
        cli_progress_init(&bar, stdout, 0);
        bar.enabled = 1;
    }
    if (g_rank == 0 && !o.quiet) pk_context_set_warning_handler(ctx, cli_print_warning, NULL);
    file_set files = {0};
    pk_context_set_file_reader(ctx, g_rank == 0 ? record_reader : serve_reader, &files);
    pk_scene *scene = NULL;
    pk_renderer *r = NULL;
    pk_film *film = NULL, *scratch = NULL;
    pk_region *tiles = NULL;
    rank_report rep;
    memset(&rep, 0, sizeof rep);
    snprintf(rep.host, sizeof rep.host, "%.63s", g_host);
    pk_status st = PK_OK;
    pk_render_options ro;
    /* Rank 0 loads the scene and applies the command line (which may read
     * files too, as an environment map) while its reader records; then the
     * recorded files go to the other ranks, which do the same from them.
     * Rank 0 alone decides, as `paprsek render` does, whether the image is
     * denoised (it alone needs the weights): loaded0[1] tells the others,
     * whose films then hold the albedo and normal the denoiser takes. */
    int loaded0[2] = {1, 0}; /* loaded; denoise: 1 yes, 0 no, -1 cannot (said) */
    pk_denoise_options dopt;
    pk_denoise_options_init(&dopt);
    if (g_rank == 0) {
        st = o.scene ? pk_scene_load_file_params(ctx, o.scene, o.defines, o.ndefines, &scene)
                    : pk_scene_create_cornell_box(ctx, &scene);
        if (st == PK_OK) st = cli_render_settings(ctx, &o, scene, &ro);
        loaded0[0] = st == PK_OK;
        if (st == PK_OK) loaded0[1] = cli_render_wants_denoise(ctx, &o, scene, &dopt);
    }
    MPI_Bcast(loaded0, 2, MPI_INT, 0, MPI_COMM_WORLD);
    if (!loaded0[0]) { /* only rank 0 read anything: its message is the cause */
        if (g_rank == 0) say("rank 0 on %s: %s", g_host, pk_context_error(ctx));
        rc = 1;
        goto finish;
    }
    if (loaded0[1] < 0) { /* --denoise without weights: rank 0 said why */
        rc = 1;
        goto finish;
    }
    const int denoise = loaded0[1];
    g_aovs = o.aovs | (denoise ? PK_AOV_ALBEDO | PK_AOV_NORMAL : 0u);
    int bcast_ok = 1;
    rep.bytes_sent += g_rank == 0 ? bcast_files(&files, &bcast_ok) : 0;
    if (g_rank == 0) {
        file_set_free(&files); /* sent; rank 0 records anything read later afresh */
    } else {
        rep.bytes_received += bcast_files(&files, &bcast_ok);
        if (bcast_ok)
            st = o.scene ? pk_scene_load_file_params(ctx, o.scene, o.defines, o.ndefines, &scene)
                    : pk_scene_create_cornell_box(ctx, &scene);
        if (bcast_ok && st == PK_OK) st = cli_render_settings(ctx, &o, scene, &ro);
        /* the files stay served: a file read later that rank 0 did not
         * send is an error naming it */
    }
    if (bcast_ok && st == PK_OK) {
        ro.cancel = &g_cancel;
        ro.progress = NULL; /* the bar follows the tiles of the whole job */
        st = pk_renderer_create(ctx, scene, &ro, &r);
    }
    if (bcast_ok && st == PK_OK) st = pk_film_create_aovs(ctx, ro.width, ro.height, g_aovs, &scratch);
    if (bcast_ok && st == PK_OK && g_rank == 0) st = pk_film_create_aovs(ctx, ro.width, ro.height, g_aovs, &film);
    int ntiles = 0;
    size_t max_tile = 0;
    if (bcast_ok && st == PK_OK) {
        const int tx = (ro.width + tile - 1) / tile, ty = (ro.height + tile - 1) / tile;
        ntiles = tx * ty;
        tiles = malloc((size_t)ntiles * sizeof *tiles);
        if (!tiles) {
            st = PK_ERR_NOMEM;
        } else {
            for (int y = 0, k = 0; y < ty; y++)
                for (int x = 0; x < tx; x++, k++) {
                    pk_region g = {x * tile, y * tile, tile, tile};
                    if (g.x + g.width > ro.width) g.width = ro.width - g.x;
                    if (g.y + g.height > ro.height) g.height = ro.height - g.y;
                    tiles[k] = g;
                    if (tile_bytes(&g) > max_tile) max_tile = tile_bytes(&g);
                }
        }
    }
    {
        const char *why = !bcast_ok ? "out of memory while receiving the scene's files"
                          : st == PK_ERR_NOMEM && !pk_context_error(ctx)[0] ? "out of memory"
                                                                             : pk_context_error(ctx);
        if (!all_ready(!bcast_ok || st != PK_OK, why)) {
            rc = 1;
            goto finish;
        }
    }

    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    job j = {ctx, r, scratch, tiles, ntiles, ro.width};
    uint32_t passes = 0;
    double wall_s = 0.0;
    if (g_rank != 0) {
        rc = worker(&j, &rep, max_tile);
        if (rc < 0) {
            /* Stopped (mpirun passes Ctrl-C on as SIGTERM, and kills every
             * rank a second later): an early exit here would make mpirun
             * kill rank 0 before it has written OUT.partial, so wait. */
            for (int k = 0; k < 100; k++) {
                struct timespec ts = {0, 100000000};
                nanosleep(&ts, NULL);
            }
            _exit(128 + (g_stop ? (int)g_stop : SIGTERM));
        }
        if (rc > 0) {
            /* rank 0 reports it (TAG_FAIL); wait to be stopped */
            while (!g_stop) sleep(1);
            _exit(1);
        }
    } else {
        local l;
        memset(&l, 0, sizeof l);
        pthread_mutex_init(&l.mu, NULL);
        pthread_cond_init(&l.cv, NULL);
        l.j = &j;
        l.film = film;
        l.rep = &rep;
        l.buf = malloc(max_tile);
        dealer d;
        memset(&d, 0, sizeof d);
        d.j = &j;
        d.l = &l;
        d.film = film;
        d.bar = &bar;
        d.rep = &rep;
        d.cap = HEADER_INTS * sizeof(int32_t) + max_tile;
        d.buf = malloc(d.cap);
        d.outstanding = calloc((size_t)g_size, sizeof *d.outstanding);
        d.failed_rank = -1;
        pthread_t th;
        if (!l.buf || !d.buf || !d.outstanding || pthread_create(&th, NULL, local_main, &l) != 0) {
            say("rank 0: out of memory");
            MPI_Abort(MPI_COMM_WORLD, 1);
        }
        const double t0 = cli_now();
        for (;;) {
            d.pass = passes;
            st = deal_pass(&d, t0, o.time);
            if (st != PK_OK) break;
            passes++;
            if (o.time <= 0.0) break;
            const double el = cli_now() - t0;
            snprintf(bar.note, sizeof bar.note, "pass %u", passes);
            cli_progress_update(&bar, (uint64_t)(el < o.time ? el * 1000.0 : o.time * 1000.0),
                                (uint64_t)(o.time * 1000.0), el);
            if (el >= o.time || passes == UINT32_MAX / (uint32_t)ro.spp) break;
        }
        wall_s = cli_now() - t0;
        pthread_mutex_lock(&l.mu);
        l.quit = 1;
        pthread_cond_signal(&l.cv);
        pthread_mutex_unlock(&l.mu);
        if (st != PK_OK) g_cancel = 1; /* rank 0's thread stops at once */
        pthread_join(th, NULL);
        cli_progress_clear(&bar);
        if (st != PK_OK) {
            if (st != PK_ERR_CANCELLED) {
                if (d.failed_rank == 0) say("rank 0 on %s: %s", g_host, pk_context_error(ctx));
                else say("rank %d: %s", d.failed_rank, d.failure[0] ? d.failure : "failed");
            }
            /* what is finished goes to OUT.partial; OUT is untouched */
            pk_image *img = NULL;
            char *partial = cli_partial_name(o.out);
            if (partial && pk_film_resolve(ctx, film, &img) == PK_OK && pk_image_write_ex(ctx, img, partial, &wo) == PK_OK)
                say("%s; finished tiles written to %s", st == PK_ERR_CANCELLED ? "interrupted" : "stopped", partial);
            else
                say("%s", st == PK_ERR_CANCELLED ? "interrupted" : "stopped");
            free(partial);
            pk_image_destroy(img);
            fflush(stdout);
            if (st == PK_ERR_CANCELLED) _exit(128 + (g_stop ? (int)g_stop : SIGINT));
            MPI_Abort(MPI_COMM_WORLD, 1);
        }
        for (int k = 1; k < g_size; k++) MPI_Send(NULL, 0, MPI_BYTE, k, TAG_STOP, MPI_COMM_WORLD);
        free(l.buf);
        free(d.buf);
        free(d.outstanding);
        pthread_mutex_destroy(&l.mu);
        pthread_cond_destroy(&l.cv);
    }

    /* every rank's statistics to rank 0 */
    pk_renderer_get_stats(r, &rep.stats);
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) == 0)
        rep.cpu_s = (double)ru.ru_utime.tv_sec + (double)ru.ru_utime.tv_usec * 1e-6 + (double)ru.ru_stime.tv_sec +
                    (double)ru.ru_stime.tv_usec * 1e-6;
    rank_report *reps = g_rank == 0 ? calloc((size_t)g_size, sizeof *reps) : NULL;
    if (g_rank == 0 && !reps) {
        say("rank 0: out of memory");
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    MPI_Gather(&rep, (int)sizeof rep, MPI_BYTE, reps, (int)sizeof rep, MPI_BYTE, 0, MPI_COMM_WORLD);
    if (g_rank == 0) {
        pk_image *img = NULL;
        cli_denoise_stats dn = {0, o.denoise_fast, 0.0, 0.0, 0};
        rc = 1;
        st = pk_film_resolve(ctx, film, &img);
        if (st == PK_OK && denoise) {
            /* once, here, on the merged image: the weights come from rank
             * 0's file system, not through the recording reader */
            pk_context_set_file_reader(ctx, NULL, NULL);
            snprintf(bar.note, sizeof bar.note, "denoising");
            cli_progress_update(&bar, 999, 1000, cli_now() - t_start);
            st = cli_render_denoise(ctx, &dopt, film, img, &dn.seconds, &dn.bytes, &dn.flops);
            dn.done = st == PK_OK;
            cli_progress_clear(&bar);
        }
        if (st == PK_OK && cli_render_write(ctx, &o, &wo, img, film) == PK_OK) {
            rc = 0;
        } else {
            const char *m = pk_context_error(ctx);
            say("rank 0 on %s: %s", g_host, m[0] ? m : "out of memory");
        }
        pk_image_destroy(img);
        if (rc == 0) {
            if (bar.enabled) {
                char took[32];
                cli_format_duration(took, sizeof took, cli_now() - t_start);
                if (o.time > 0.0)
                    fprintf(bar.f, "wrote %s (%dx%d, %d ranks, %u passes of %d spp%s, %s)\n", o.out, ro.width,
                            ro.height, g_size, passes, ro.spp, denoise ? ", denoised" : "", took);
                else
                    fprintf(bar.f, "wrote %s (%dx%d, %d ranks, %d spp%s, %s)\n", o.out, ro.width, ro.height, g_size,
                            ro.spp, denoise ? ", denoised" : "", took);
            }
            const char *name = o.scene ? o.scene : "cornell-box (built in)";
            pk_stats js = job_stats(reps, wall_s);
            if (o.stats) {
                cli_print_stats(ctx, name, scene, &ro, &js);
                cli_print_denoise_stats(&dn); /* as `paprsek render` prints it */
                printf("%-28s %u of %d spp\n", "passes", passes, ro.spp);
                print_ranks(reps, &ro, wall_s, (uint64_t)ntiles * passes);
                fflush(stdout);
            }
            if (o.stats_json && cli_write_stats_json(ctx, o.stats_json, name, scene, &ro, &js, &dn, NULL, NULL) != 0) rc = 1;
        }
        free(reps);
    }
    MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD);

finish:
    file_set_free(&files);
    free(tiles);
    pk_film_destroy(scratch);
    pk_film_destroy(film);
    pk_renderer_destroy(r);
    pk_scene_destroy(scene);
    pk_context_destroy(ctx);
    MPI_Finalize();
    return rc;
}
