/*
 * bench.c - `paprsek bench ...`: times an accelerator on a .rays file
 * (`rays`), makes the standard ray files from a scene and a camera
 * (`gen-rays`) and checks that two .hits files agree (`compare`). The file
 * formats and the workloads are those of spec/ray-benchmark.md.
 */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define MAX_REPS 100000
#define AGREE_REL_TOL 1e-4        /* distances agree to this, relative */
#define AGREE_MAX_FRACTION 1e-4   /* at most 0.01% of the rays may disagree */

static const char usage_text[] =
    "usage: paprsek bench rays SCENE.obj RAYS.rays [--accel NAME] [--threads N] [--reps K]\n"
    "                          [--hits OUT.hits] [--any-hit] [--packets] [--stats]\n"
    "       paprsek bench gen-rays [SCENE.obj] -o OUT.rays [--look-from X,Y,Z --look-at X,Y,Z --fov DEG]\n"
    "                          [--workload cornell-sphere|bunny|sponza [--shared DIR]]\n"
    "                          [--size N] [--kind primary|diffuse|shadow] [--seed S] [--accel NAME] [--threads N]\n"
    "       paprsek bench compare A.hits B.hits [--any-hit] [--rays RAYS.rays]";

/* ---- the options of each subcommand ---------------------------------------- */

enum {
    B_ACCEL = 1, B_THREADS, B_REPS, B_HITS, B_ANY_HIT, B_PACKETS, B_STATS, B_HELP,
    B_OUTPUT, B_LOOK_FROM, B_LOOK_AT, B_FOV, B_SIZE, B_KIND, B_SEED, B_WORKLOAD, B_SHARED, B_RAYS, B_CONFIG
};

#define ACCEL_HELP "none, midpoint, bvh (default), embree or cuda (an NVIDIA GPU)"
#define OPT_FLAG(n, i, h) {.name = n, .id = i, .kind = CLI_FLAG, .help = h}
#define OPT_STR(n, i, a, h) {.name = n, .id = i, .kind = CLI_STRING, .arg = a, .help = h}
#define CONFIG_HELP                                                                                          \
    "settings of the library's back ends: cpu.isa=auto|avx2, bvh.quality=high|fast, "                       \
    "embree.quality=low|medium|high, embree.library=FILE, cuda.library=FILE, cuda.module=FILE "        \
    "(README, Configuration); they "                                                                        \
    "override the environment variables PAPRSEK_CPU_ISA, PAPRSEK_BVH_QUALITY, PAPRSEK_EMBREE_QUALITY, "     \
    "PAPRSEK_EMBREE_LIBRARY and PAPRSEK_CUDA_LIBRARY, which are passed on as these keys"

static cli_option rays_opts[] = {
    OPT_STR("accel", B_ACCEL, "NAME", "the acceleration structure: " ACCEL_HELP),
    {.name = "threads", .id = B_THREADS}, /* the library's entry, put here by bench_options() */
    {.name = "reps", .id = B_REPS, .kind = CLI_INT, .arg = "K", .help = "timed repetitions (the median is reported)",
     .min = 1, .max = MAX_REPS, .default_value = 5},
    OPT_STR("hits", B_HITS, "FILE", "write the hits of the last repetition (16 bytes per ray)"),
    OPT_FLAG("any-hit", B_ANY_HIT, "occlusion rays: any hit, not the closest"),
    OPT_FLAG("packets", B_PACKETS, "trace coherent groups of rays as packets"),
    OPT_FLAG("stats", B_STATS, "count nodes and tests per ray in one more, untimed pass"),
    OPT_STR("config", B_CONFIG, "KEY=VALUE,...", CONFIG_HELP),
    {.name = "help", .short_name = 'h', .id = B_HELP, .kind = CLI_FLAG, .help = "this text"},
};

static cli_option gen_opts[] = {
    {.name = "output", .short_name = 'o', .id = B_OUTPUT, .kind = CLI_STRING, .arg = "FILE",
     .help = "the ray file to write (required)"},
    OPT_STR("look-from", B_LOOK_FROM, "X,Y,Z", "camera position"),
    OPT_STR("look-at", B_LOOK_AT, "X,Y,Z", "camera target"),
    OPT_STR("fov", B_FOV, "DEG", "vertical field of view in degrees, between 0 and 180"),
    {.name = "size", .id = B_SIZE, .kind = CLI_INT, .arg = "N", .help = "N x N primary rays",
     .min = 1, .max = PK_MAX_IMAGE_SIDE, .default_value = 1024},
    OPT_STR("kind", B_KIND, "KIND",
            "primary (default), diffuse (one bounce from each hit) or shadow (from each hit toward a point "
            "on the area lights, stopping just short of it: for --any-hit)"),
    OPT_STR("seed", B_SEED, "S", "random seed of the diffuse directions (default 1)"),
    OPT_STR("workload", B_WORKLOAD, "NAME", "a standard workload's scene and camera: cornell-sphere, bunny, sponza"),
    OPT_STR("shared", B_SHARED, "DIR", "where the workloads' scenes are (default ../shared)"),
    OPT_STR("accel", B_ACCEL, "NAME", "the acceleration structure for diffuse rays: " ACCEL_HELP),
    OPT_STR("config", B_CONFIG, "KEY=VALUE,...", CONFIG_HELP),
    {.name = "threads", .id = B_THREADS},
    {.name = "help", .short_name = 'h', .id = B_HELP, .kind = CLI_FLAG, .help = "this text"},
};

static cli_option compare_opts[] = {
    OPT_FLAG("any-hit", B_ANY_HIT, "compare hit or miss only, not distances"),
    OPT_STR("rays", B_RAYS, "FILE", "the rays of the hit files, to excuse hits at a ray's origin"),
    {.name = "help", .short_name = 'h', .id = B_HELP, .kind = CLI_FLAG, .help = "this text"},
};

#define COUNT(a) (sizeof a / sizeof a[0])

/* Fills in --threads from the library's table of render options. */
static void bench_options(void)
{
    static char name[64];
    const pk_int_option *t = pk_int_option_find("threads");
    if (!t) return;
    cli_option o = cli_option_from_render(t, name, sizeof name);
    o.id = B_THREADS;
    for (size_t i = 0; i < COUNT(rays_opts); i++)
        if (rays_opts[i].id == B_THREADS) rays_opts[i] = o;
    for (size_t i = 0; i < COUNT(gen_opts); i++)
        if (gen_opts[i].id == B_THREADS) gen_opts[i] = o;
}

void cli_bench_help(FILE *f)
{
    bench_options();
    fprintf(f, "%s\n\noptions of bench rays:\n", usage_text);
    cli_print_options(f, rays_opts, COUNT(rays_opts));
    fputs("\noptions of bench gen-rays:\n", f);
    cli_print_options(f, gen_opts, COUNT(gen_opts));
    fputs("\noptions of bench compare:\n", f);
    cli_print_options(f, compare_opts, COUNT(compare_opts));
    fputs("\nexit status: 0 success (compare: the files agree); 1 a runtime failure (a file\n"
          "that cannot be read or written; compare: the files disagree); 2 a usage error.\n",
          f);
}

static int online_cpus(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 && n <= PK_MAX_THREADS ? (int)n : 1;
}

/* Reads a file of fixed-size records into *out (caller frees). Returns 0 or
 * prints a message and returns 1. */
static int read_records(const char *path, size_t rec, const char *kind, void **out, size_t *count)
{
    *out = NULL;
    *count = 0;
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "paprsek: %s: cannot open: %s\n", path, strerror(errno));
        return 1;
    }
    struct stat sb;
    if (fstat(fileno(f), &sb) != 0 || !S_ISREG(sb.st_mode)) {
        fprintf(stderr, "paprsek: %s: not a regular file\n", path);
        fclose(f);
        return 1;
    }
    size_t size = (size_t)sb.st_size;
    if (size % rec != 0) {
        fprintf(stderr, "paprsek: %s: malformed %s file: %zu bytes is not a multiple of %zu\n", path,
                kind, size, rec);
        fclose(f);
        return 1;
    }
    if (size == 0) {
        fprintf(stderr, "paprsek: %s: empty %s file\n", path, kind);
        fclose(f);
        return 1;
    }
    void *buf = malloc(size);
    if (!buf) {
        fprintf(stderr, "paprsek: %s: out of memory (%zu bytes)\n", path, size);
        fclose(f);
        return 1;
    }
    if (fread(buf, 1, size, f) != size) {
        fprintf(stderr, "paprsek: %s: read error\n", path);
        free(buf);
        fclose(f);
        return 1;
    }
    fclose(f);
    *out = buf;
    *count = size / rec;
    return 0;
}

/* Writes data to a temporary file beside path, then renames it into place,
 * so that path only ever holds a complete file. */
static int write_file_atomic(const char *path, const void *data, size_t size)
{
    size_t len = strlen(path) + 32;
    char *tmp = malloc(len);
    if (!tmp) {
        fprintf(stderr, "paprsek: %s: out of memory\n", path);
        return 1;
    }
    snprintf(tmp, len, "%s.%ld.tmp", path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        fprintf(stderr, "paprsek: %s: cannot create %s: %s\n", path, tmp, strerror(errno));
        free(tmp);
        return 1;
    }
    int bad = fwrite(data, 1, size, f) != size;
    bad |= fclose(f) != 0;
    if (bad || rename(tmp, path) != 0) {
        fprintf(stderr, "paprsek: %s: cannot write: %s\n", path, strerror(errno));
        remove(tmp);
        free(tmp);
        return 1;
    }
    free(tmp);
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static int is_hit(const pk_hit *h) { return h->prim != PK_NO_HIT || h->t < INFINITY; }

/* A context with the config of the environment and --config (config);
 * NULL after a message (*rc: the exit status). */
static pk_context *new_context(const char *config, int *rc)
{
    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) {
        fprintf(stderr, "paprsek: out of memory\n");
        *rc = 1;
        return NULL;
    }
    pk_context_set_warning_handler(ctx, cli_print_warning, NULL);
    if ((*rc = cli_configure(ctx, config)) != 0) {
        pk_context_destroy(ctx);
        return NULL;
    }
    return ctx;
}

/* The value of key in ctx's effective config ("medium" for embree.quality). */
static const char *config_value(pk_context *ctx, const char *key, char *buf, size_t cap)
{
    char all[1024];
    pk_context_get_config(ctx, all, sizeof all);
    const size_t kl = strlen(key);
    buf[0] = '\0';
    for (const char *p = all; p && *p; p = strchr(p, ',') ? strchr(p, ',') + 1 : NULL)
        if (strncmp(p, key, kl) == 0 && p[kl] == '=') {
            const char *v = p + kl + 1, *e = strchr(v, ',');
            snprintf(buf, cap, "%.*s", (int)(e ? (size_t)(e - v) : strlen(v)), v);
            break;
        }
    return buf;
}

/* ---- bench rays ------------------------------------------------------------ */

static int bench_rays(int argc, char **argv)
{
    const char *scene_path = NULL, *rays_path = NULL, *hits_path = NULL, *config = NULL;
    pk_accel_kind kind = PK_ACCEL_DEFAULT;
    int threads = 0, reps = 5, any_hit = 0, packets = 0, stats = 0;
    bench_options();
    cli_parser p;
    cli_parser_init(&p, "bench rays", rays_opts, COUNT(rays_opts), argc, argv);
    int r;
    while ((r = cli_next(&p)) != CLI_END) {
        if (r == CLI_ERROR) return 2;
        const char *v = p.value;
        if (r == CLI_ARGUMENT) {
            if (!scene_path)
                scene_path = v;
            else if (!rays_path)
                rays_path = v;
            else
                return cli_usage_error("bench rays: unexpected argument %s\n%s", v, usage_text);
            continue;
        }
        switch (rays_opts[p.index].id) {
        case B_ACCEL:
            if (pk_accel_kind_parse(v, &kind) != PK_OK)
                return cli_usage_error("--accel %s: expected none, midpoint, bvh, embree or cuda", v);
            break;
        case B_THREADS: threads = p.int_value; break;
        case B_REPS: reps = p.int_value; break;
        case B_HITS: hits_path = v; break;
        case B_ANY_HIT: any_hit = 1; break;
        case B_PACKETS: packets = 1; break;
        case B_STATS: stats = 1; break;
        case B_CONFIG: config = v; break;
        case B_HELP: cli_bench_help(stdout); return 0;
        }
    }
    if (!scene_path || !rays_path)
        return cli_usage_error("bench rays needs SCENE.obj and RAYS.rays\n%s", usage_text);
    if (cli_check_config(config)) return 2;
    if (hits_path && cli_check_output(hits_path, 1)) return 1;
    if (threads == 0) threads = online_cpus();

    int rc = 1;
    pk_context *ctx = NULL;
    pk_scene *scene = NULL;
    pk_accel *accel = NULL;
    pk_ray *rays = NULL;
    pk_hit *hits = NULL;
    double *times = NULL;
    size_t n = 0;

    if (read_records(rays_path, sizeof(pk_ray), "ray", (void **)&rays, &n)) goto out;
    if (!(ctx = new_context(config, &rc))) goto out;
    rc = 1;
    if (pk_scene_load_file(ctx, scene_path, &scene) != PK_OK ||
        pk_accel_create(ctx, scene, kind, threads, &accel) != PK_OK) {
        rc = cli_fail_ctx(ctx);
        goto out;
    }
    hits = malloc(n * sizeof *hits);
    times = malloc(4 * (size_t)reps * sizeof *times);
    if (!hits || !times) {
        fprintf(stderr, "paprsek: out of memory (%zu rays)\n", n);
        goto out;
    }
    /* a device accelerator also reports its copies and its kernel per pass */
    pk_accel_device_info dev;
    const int on_device = pk_accel_get_device_info(accel, &dev);
    double *kernel_ms = times + reps, *up_ms = times + 2 * reps, *down_ms = times + 3 * reps;
    unsigned flags = (any_hit ? PK_TRACE_ANY_HIT : 0u) | (packets ? PK_TRACE_COHERENT : 0u);
    pk_accel_trace(accel, rays, hits, n, threads, flags, NULL); /* warm-up */
    for (int k = 0; k < reps && pk_context_status(ctx) == PK_OK; k++) {
        double t0 = cli_now();
        pk_accel_trace(accel, rays, hits, n, threads, flags, NULL);
        times[k] = cli_now() - t0;
        if (on_device) {
            pk_accel_get_device_info(accel, &dev);
            kernel_ms[k] = dev.kernel_ms, up_ms[k] = dev.rays_upload_ms, down_ms[k] = dev.download_ms;
        }
    }
    if (pk_context_status(ctx) != PK_OK) { /* a device that failed */
        rc = cli_fail_ctx(ctx);
        goto out;
    }
    double tmed = median(times, reps), tmin = times[0];
    size_t nhits = 0;
    for (size_t i = 0; i < n; i++) nhits += (size_t)is_hit(&hits[i]);

    pk_accel_info info;
    pk_accel_get_info(accel, &info);
    pk_scene_info sinfo;
    pk_scene_get_info(scene, &sinfo);
    double bytes_per_tri = sinfo.triangles ? (double)info.bytes / (double)sinfo.triangles : 0.0;

    if (hits_path && write_file_atomic(hits_path, hits, n * sizeof *hits)) goto out;
    printf("rays=%zu accel=%s threads=%d build_ms=%.3f time_s=%.6f mrays_per_s=%.3f hits=%zu", n,
           info.name ? info.name : pk_accel_kind_name(kind), threads, info.build_ms, tmed,
           tmed > 0.0 ? (double)n / tmed / 1e6 : 0.0, nhits);
    printf(" min_s=%.6f reps=%d mode=%s packets=%d nodes=%zu leaves=%zu bytes=%zu bytes_per_tri=%.1f"
           " sah_cost=%.3f",
           tmin, reps, any_hit ? "any" : "closest", packets, info.nodes, info.leaves, info.bytes,
           bytes_per_tri, info.sah_cost);
    const char *isa = pk_accel_isa(accel);
    if (isa) printf(" isa=%s", isa);
    if (info.name && strcmp(info.name, "embree") == 0) {
        char q[32];
        printf(" embree_quality=%s", config_value(ctx, "embree.quality", q, sizeof q));
    }
    if (on_device) {
        /* the device's name without spaces, so that the line stays key=value pairs */
        char name[sizeof dev.device];
        size_t k = 0;
        for (; dev.device[k] && k + 1 < sizeof name; k++) name[k] = dev.device[k] == ' ' ? '_' : dev.device[k];
        name[k] = '\0';
        const double kmed = median(kernel_ms, reps);
        printf(" device=%s upload_ms=%.3f structure_bytes=%zu device_bytes=%zu rays_upload_ms=%.3f kernel_ms=%.3f"
               " download_ms=%.3f kernel_mrays_per_s=%.3f",
               name[0] ? name : "unknown", dev.upload_ms, dev.structure_bytes, dev.device_bytes, median(up_ms, reps),
               kmed, median(down_ms, reps), kmed > 0.0 ? (double)n / (kmed * 1e-3) / 1e6 : 0.0);
    }
    if (stats) {
        /* A separate pass: counting costs a little and is not timed. */
        pk_hit *scratch = malloc(n * sizeof *scratch);
        if (!scratch) {
            fprintf(stderr, "paprsek: out of memory (%zu rays)\n", n);
            goto out;
        }
        pk_trace_counters c = {0, 0};
        pk_accel_trace(accel, rays, scratch, n, threads, flags, &c);
        free(scratch);
        printf(" nodes_per_ray=%.2f tests_per_ray=%.2f", (double)c.nodes_visited / (double)n,
               (double)c.intersection_tests / (double)n);
    }
    printf("\n");
    fflush(stdout);
    rc = 0;
out:
    free(times);
    free(hits);
    free(rays);
    pk_accel_destroy(accel);
    pk_scene_destroy(scene);
    pk_context_destroy(ctx);
    return rc;
}

/* ---- bench gen-rays -------------------------------------------------------- */

typedef struct workload {
    const char *name, *scene; /* scene relative to SHARED/scenes */
    float from[3], at[3], fov;
} workload;

static const workload workloads[] = {
    {"cornell-sphere", "cornell/CornellBox-Sphere.obj", {0.0f, 1.0f, 3.9f}, {0.0f, 1.0f, 0.0f}, 39.3f},
    {"sponza", "bench/dabrovic-sponza/sponza.obj", {-14.0f, 3.0f, 0.0f}, {10.0f, 5.0f, 0.0f}, 70.0f},
    {"bunny", "bench/stanford-bunny.obj", {-0.02f, 0.11f, 0.25f}, {-0.02f, 0.1f, 0.0f}, 45.0f},
};

typedef struct dvec {
    double x, y, z;
} dvec;

static dvec dv(double x, double y, double z)
{
    dvec r = {x, y, z};
    return r;
}
static dvec dv_sub(dvec a, dvec b) { return dv(a.x - b.x, a.y - b.y, a.z - b.z); }
static dvec dv_add(dvec a, dvec b) { return dv(a.x + b.x, a.y + b.y, a.z + b.z); }
static dvec dv_scale(dvec a, double s) { return dv(a.x * s, a.y * s, a.z * s); }
static double dv_dot(dvec a, dvec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static dvec dv_cross(dvec a, dvec b)
{
    return dv(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

/* A 64-bit hash of (seed, index): every ray draws its own random numbers,
 * so the file does not depend on the order of the work. */
static uint64_t splitmix64(uint64_t x)
{
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

/* Primary rays, one per pixel through its centre, rows from the top; the
 * same camera model as the renderer (float, vertical fov, up = +y). */
static int make_primary(const float from[3], const float at[3], float fov, int size, pk_ray *rays)
{
    const float o[3] = {from[0], from[1], from[2]};
    float w[3] = {from[0] - at[0], from[1] - at[1], from[2] - at[2]};
    float wl = sqrtf(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (!(wl > 0.0f)) return cli_usage_error("--look-from and --look-at are the same point");
    for (int k = 0; k < 3; k++) w[k] /= wl;
    /* u = normalize(up x w) with up = +y */
    float u[3] = {w[2], 0.0f, -w[0]};
    float ul = sqrtf(u[0] * u[0] + u[2] * u[2]);
    if (!(ul > 1e-6f)) return cli_usage_error("the view direction is parallel to up (+y)");
    u[0] /= ul;
    u[2] /= ul;
    const float v[3] = {w[1] * u[2] - w[2] * u[1], w[2] * u[0] - w[0] * u[2], w[0] * u[1] - w[1] * u[0]};
    const float half = tanf(0.5f * fov * 3.14159265358979323846f / 180.0f);
    for (int y = 0; y < size; y++) {
        float sy = (1.0f - 2.0f * ((float)y + 0.5f) / (float)size) * half;
        for (int x = 0; x < size; x++) {
            float sx = (2.0f * ((float)x + 0.5f) / (float)size - 1.0f) * half;
            float d[3];
            for (int k = 0; k < 3; k++) d[k] = u[k] * sx + v[k] * sy - w[k];
            float dl = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            pk_ray *r = &rays[(size_t)y * (size_t)size + (size_t)x];
            for (int k = 0; k < 3; k++) {
                r->org[k] = o[k];
                r->dir[k] = d[k] / dl;
            }
            r->tmin = 0.0f;
            r->tmax = INFINITY;
        }
    }
    return 0;
}

/* Diffuse bounce rays: for every primary ray that hits, one ray from the hit
 * point (offset along the geometric normal turned towards the camera ray) in
 * a cosine-distributed direction. Returns the number of rays written. */
static size_t make_diffuse(const pk_scene *scene, const pk_ray *prim, const pk_hit *hits, size_t n,
                           uint64_t seed, pk_ray *out, size_t *skipped)
{
    pk_scene_info si;
    pk_scene_get_info(scene, &si);
    double extent = 0.0;
    for (int k = 0; k < 3; k++) {
        double e = (double)si.bounds_max[k] - (double)si.bounds_min[k];
        if (e > extent) extent = e;
    }
    const double eps = 1e-4 * extent;
    size_t m = 0;
    *skipped = 0;
    for (size_t i = 0; i < n; i++) {
        const pk_hit *h = &hits[i];
        if (h->prim == PK_NO_HIT) continue;
        float tv[9];
        if (h->prim >= si.triangles || pk_scene_get_triangle(scene, h->prim, tv) != PK_OK) {
            ++*skipped; /* a sphere: its normal is not in the public interface */
            continue;
        }
        dvec a = dv(tv[0], tv[1], tv[2]), b = dv(tv[3], tv[4], tv[5]), c = dv(tv[6], tv[7], tv[8]);
        dvec nrm = dv_cross(dv_sub(b, a), dv_sub(c, a));
        double nl = sqrt(dv_dot(nrm, nrm));
        if (!(nl > 0.0)) {
            ++*skipped;
            continue;
        }
        nrm = dv_scale(nrm, 1.0 / nl);
        dvec o = dv(prim[i].org[0], prim[i].org[1], prim[i].org[2]);
        dvec d = dv(prim[i].dir[0], prim[i].dir[1], prim[i].dir[2]);
        if (dv_dot(nrm, d) > 0.0) nrm = dv_scale(nrm, -1.0);
        dvec p = dv_add(dv_add(o, dv_scale(d, (double)h->t)), dv_scale(nrm, eps));

        uint64_t bits = splitmix64(seed * 0xD1B54A32D192ED03ull + (uint64_t)i);
        double r1 = (double)(bits >> 32) * (1.0 / 4294967296.0);
        double r2 = (double)(bits & 0xFFFFFFFFu) * (1.0 / 4294967296.0);
        double phi = 2.0 * 3.14159265358979323846 * r1, rr = sqrt(r2);
        double lx = rr * cos(phi), ly = rr * sin(phi), lz = sqrt(fmax(0.0, 1.0 - r2));
        /* orthonormal basis about nrm (Duff et al., JCGT 2017) */
        double sign = copysign(1.0, nrm.z);
        double ia = -1.0 / (sign + nrm.z), ib = nrm.x * nrm.y * ia;
        dvec t1 = dv(1.0 + sign * nrm.x * nrm.x * ia, sign * ib, -sign * nrm.x);
        dvec t2 = dv(ib, sign + nrm.y * nrm.y * ia, -nrm.y);
        dvec dir = dv_add(dv_add(dv_scale(t1, lx), dv_scale(t2, ly)), dv_scale(nrm, lz));
        double dl = sqrt(dv_dot(dir, dir));
        dir = dv_scale(dir, 1.0 / dl);

        pk_ray *r = &out[m++];
        r->org[0] = (float)p.x;
        r->org[1] = (float)p.y;
        r->org[2] = (float)p.z;
        r->dir[0] = (float)dir.x;
        r->dir[1] = (float)dir.y;
        r->dir[2] = (float)dir.z;
        r->tmin = 0.0f;
        r->tmax = INFINITY;
    }
    return m;
}

/* Shadow rays: each of the n rays' origins (the diffuse rays' offset hit
 * points) joined to a point on an area light, the light chosen in proportion
 * to its area and the point uniform on it; the direction is the segment
 * itself and tmax 1 - 1e-3, so that the light does not occlude itself.
 * Rewrites rays in place; returns n, or 0 when the scene has no area light. */
static size_t make_shadow(const pk_scene *scene, pk_ray *rays, size_t n, uint64_t seed)
{
    pk_scene_info si;
    pk_scene_get_info(scene, &si);
    const size_t nl = si.emissive_triangles;
    if (nl == 0) return 0;
    double *cdf = malloc(nl * sizeof *cdf);
    float(*tv)[9] = malloc(nl * sizeof *tv);
    if (!cdf || !tv) {
        free(cdf);
        free(tv);
        return 0;
    }
    double total = 0.0;
    for (size_t k = 0; k < nl; k++) {
        size_t t = 0;
        pk_scene_get_emissive_triangle(scene, k, &t);
        pk_scene_get_triangle(scene, t, tv[k]);
        dvec a = dv(tv[k][0], tv[k][1], tv[k][2]), b = dv(tv[k][3], tv[k][4], tv[k][5]),
             c = dv(tv[k][6], tv[k][7], tv[k][8]);
        dvec x = dv_cross(dv_sub(b, a), dv_sub(c, a));
        total += 0.5 * sqrt(dv_dot(x, x));
        cdf[k] = total;
    }
    for (size_t i = 0; i < n; i++) {
        uint64_t bits = splitmix64(seed * 0x9E3779B97F4A7C15ull + 0x5bd1e995u + (uint64_t)i);
        double u0 = (double)(bits >> 40) * (1.0 / 16777216.0);
        double u1 = (double)((bits >> 16) & 0xFFFFFFu) * (1.0 / 16777216.0);
        double u2 = (double)(splitmix64(bits) >> 40) * (1.0 / 16777216.0);
        size_t k = 0;
        while (k + 1 < nl && cdf[k] <= u0 * total) k++;
        double su = sqrt(u1), b0 = 1.0 - su, b1 = u2 * su, b2 = 1.0 - b0 - b1;
        pk_ray *r = &rays[i];
        for (int j = 0; j < 3; j++) {
            double q = b0 * (double)tv[k][j] + b1 * (double)tv[k][3 + j] + b2 * (double)tv[k][6 + j];
            r->dir[j] = (float)(q - (double)r->org[j]);
        }
        r->tmin = 0.0f;
        r->tmax = 1.0f - 1e-3f;
    }
    free(cdf);
    free(tv);
    return n;
}

static int bench_gen_rays(int argc, char **argv)
{
    const char *scene_arg = NULL, *out_path = NULL, *shared = NULL, *kind_name = "primary", *gen_config = NULL;
    const workload *wl = NULL;
    float from[3], at[3], fov = 0.0f;
    int has_from = 0, has_at = 0, has_fov = 0, size = 1024, threads = 0;
    long long seed = 1;
    pk_accel_kind accel_kind = PK_ACCEL_DEFAULT;
    bench_options();
    cli_parser p;
    cli_parser_init(&p, "bench gen-rays", gen_opts, COUNT(gen_opts), argc, argv);
    int r;
    while ((r = cli_next(&p)) != CLI_END) {
        if (r == CLI_ERROR) return 2;
        const char *v = p.value;
        if (r == CLI_ARGUMENT) {
            if (scene_arg) return cli_usage_error("bench gen-rays: unexpected argument %s\n%s", v, usage_text);
            scene_arg = v;
            continue;
        }
        switch (gen_opts[p.index].id) {
        case B_LOOK_FROM:
            if (!cli_parse_vec3(v, from)) return cli_usage_error("--look-from %s: expected x,y,z", v);
            has_from = 1;
            break;
        case B_LOOK_AT:
            if (!cli_parse_vec3(v, at)) return cli_usage_error("--look-at %s: expected x,y,z", v);
            has_at = 1;
            break;
        case B_FOV: {
            char *end;
            errno = 0;
            double f = strtod(v, &end);
            if (end == v || *end || errno || !(f > 0.0 && f < 180.0))
                return cli_usage_error("--fov %s: expected degrees in (0, 180)", v);
            fov = (float)f;
            has_fov = 1;
            break;
        }
        case B_SIZE: size = p.int_value; break;
        case B_KIND:
            kind_name = v;
            if (strcmp(kind_name, "primary") != 0 && strcmp(kind_name, "diffuse") != 0 &&
                strcmp(kind_name, "shadow") != 0)
                return cli_usage_error("--kind %s: expected primary, diffuse or shadow", kind_name);
            break;
        case B_SEED: {
            char *end;
            errno = 0;
            seed = strtoll(v, &end, 10);
            if (end == v || *end || errno || seed < 0)
                return cli_usage_error("--seed %s: expected a non-negative integer", v);
            break;
        }
        case B_WORKLOAD:
            wl = NULL;
            for (size_t k = 0; k < sizeof workloads / sizeof workloads[0]; k++)
                if (strcmp(v, workloads[k].name) == 0) wl = &workloads[k];
            if (!wl) return cli_usage_error("--workload %s: expected cornell-sphere, bunny or sponza", v);
            break;
        case B_SHARED: shared = v; break;
        case B_ACCEL:
            if (pk_accel_kind_parse(v, &accel_kind) != PK_OK)
                return cli_usage_error("--accel %s: expected none, midpoint, bvh, embree or cuda", v);
            break;
        case B_CONFIG: gen_config = v; break;
        case B_THREADS: threads = p.int_value; break;
        case B_OUTPUT: out_path = v; break;
        case B_HELP: cli_bench_help(stdout); return 0;
        }
    }
    if (!out_path) return cli_usage_error("bench gen-rays needs -o OUT.rays\n%s", usage_text);
    char scene_buf[4096];
    const char *scene_path = scene_arg;
    if (wl) {
        if (!has_from) memcpy(from, wl->from, sizeof from);
        if (!has_at) memcpy(at, wl->at, sizeof at);
        if (!has_fov) fov = wl->fov;
        has_from = has_at = has_fov = 1;
        if (!scene_path) {
            snprintf(scene_buf, sizeof scene_buf, "%s/scenes/%s", shared ? shared : "../shared", wl->scene);
            scene_path = scene_buf;
        }
    }
    if (!scene_path) return cli_usage_error("bench gen-rays needs SCENE.obj or --workload\n%s", usage_text);
    if (!has_from || !has_at || !has_fov)
        return cli_usage_error("bench gen-rays needs --look-from, --look-at and --fov (or --workload)");
    if (cli_check_config(gen_config)) return 2;
    if (cli_check_output(out_path, 1)) return 1;
    if (threads == 0) threads = online_cpus();
    const int diffuse = strcmp(kind_name, "primary") != 0; /* diffuse or shadow: from the primary hits */
    const int shadow = strcmp(kind_name, "shadow") == 0;

    int rc = 1;
    pk_context *ctx = NULL;
    pk_scene *scene = NULL;
    pk_accel *accel = NULL;
    pk_hit *hits = NULL;
    pk_ray *out_rays = NULL;
    const size_t n = (size_t)size * (size_t)size;
    pk_ray *rays = malloc(n * sizeof *rays);
    if (!rays) {
        fprintf(stderr, "paprsek: out of memory (%zu rays)\n", n);
        return 1;
    }
    if ((rc = make_primary(from, at, fov, size, rays)) != 0) goto out;
    rc = 1;
    if (!diffuse) {
        /* The scene is not needed for primary rays, but a wrong path is an error. */
        if (access(scene_path, R_OK) != 0) {
            fprintf(stderr, "paprsek: %s: cannot open: %s\n", scene_path, strerror(errno));
            goto out;
        }
        if (write_file_atomic(out_path, rays, n * sizeof *rays)) goto out;
        fprintf(stderr, "paprsek: %s: %zu primary rays\n", out_path, n);
        rc = 0;
        goto out;
    }

    if (!(ctx = new_context(gen_config, &rc))) goto out;
    rc = 1;
    if (pk_scene_load_file(ctx, scene_path, &scene) != PK_OK ||
        pk_accel_create(ctx, scene, accel_kind, threads, &accel) != PK_OK) {
        rc = cli_fail_ctx(ctx);
        goto out;
    }
    hits = malloc(n * sizeof *hits);
    out_rays = malloc(n * sizeof *out_rays);
    if (!hits || !out_rays) {
        fprintf(stderr, "paprsek: out of memory (%zu rays)\n", n);
        goto out;
    }
    pk_accel_trace(accel, rays, hits, n, threads, 0, NULL);
    size_t skipped = 0;
    size_t m = make_diffuse(scene, rays, hits, n, (uint64_t)seed, out_rays, &skipped);
    if (shadow && (m = make_shadow(scene, out_rays, m, (uint64_t)seed)) == 0) {
        fprintf(stderr, "paprsek: %s: the scene has no area light (no triangle with Ke) to cast shadow rays to\n",
                scene_path);
        goto out;
    }
    if (skipped)
        fprintf(stderr, "paprsek: warning: %zu hits on spheres or degenerate triangles have no diffuse ray\n",
                skipped);
    if (m == 0) {
        fprintf(stderr, "paprsek: %s: no primary ray hits the scene, so there are no diffuse rays\n",
                scene_path);
        goto out;
    }
    if (write_file_atomic(out_path, out_rays, m * sizeof *out_rays)) goto out;
    fprintf(stderr, "paprsek: %s: %zu %s rays (from %zu primary rays)\n", out_path, m, shadow ? "shadow" : "diffuse",
            n);
    rc = 0;
out:
    free(out_rays);
    free(hits);
    free(rays);
    pk_accel_destroy(accel);
    pk_scene_destroy(scene);
    pk_context_destroy(ctx);
    return rc;
}

/* ---- bench compare --------------------------------------------------------- */

/* The distance within which a hit is "at the origin": a few float ulps of the
 * origin's coordinates, in units of the ray direction. A ray that starts on a
 * surface (a diffuse ray from a corner) may or may not hit it at t ~ 0, and
 * its t there has no meaningful relative precision. */
static double origin_slack(const pk_ray *r)
{
    double m = 1.0, dl = 0.0;
    for (int k = 0; k < 3; k++) {
        m = fmax(m, fabs((double)r->org[k]));
        dl += (double)r->dir[k] * (double)r->dir[k];
    }
    dl = sqrt(dl);
    return dl > 0.0 ? 1e-6 * m / dl : 0.0;
}

static int bench_compare(int argc, char **argv)
{
    const char *pa = NULL, *pb = NULL, *prays = NULL;
    int any_hit = 0;
    cli_parser p;
    cli_parser_init(&p, "bench compare", compare_opts, COUNT(compare_opts), argc, argv);
    int r;
    while ((r = cli_next(&p)) != CLI_END) {
        if (r == CLI_ERROR) return 2;
        const char *v = p.value;
        if (r == CLI_ARGUMENT) {
            if (!pa)
                pa = v;
            else if (!pb)
                pb = v;
            else
                return cli_usage_error("bench compare: unexpected argument %s\n%s", v, usage_text);
            continue;
        }
        switch (compare_opts[p.index].id) {
        case B_ANY_HIT: any_hit = 1; break;
        case B_RAYS: prays = v; break;
        case B_HELP: cli_bench_help(stdout); return 0;
        }
    }
    if (!pa || !pb) return cli_usage_error("bench compare needs A.hits and B.hits\n%s", usage_text);
    pk_hit *a = NULL, *b = NULL;
    pk_ray *rays = NULL;
    size_t na = 0, nb = 0, nr = 0;
    int rc = 1;
    if (read_records(pa, sizeof(pk_hit), "hit", (void **)&a, &na) ||
        read_records(pb, sizeof(pk_hit), "hit", (void **)&b, &nb) ||
        (prays && read_records(prays, sizeof(pk_ray), "ray", (void **)&rays, &nr)))
        goto out;
    if (na != nb || (rays && nr != na)) {
        fprintf(stderr, "paprsek: %s has %zu hits but %s has %zu%s\n", pa, na, pb, nb,
                rays && nr != na ? " and the ray file a different count" : "");
        goto out;
    }
    size_t hit_mismatch = 0, t_mismatch = 0, near_origin = 0, prim_differ = 0, nhits = 0;
    for (size_t i = 0; i < na; i++) {
        int ha = is_hit(&a[i]), hb = is_hit(&b[i]);
        nhits += (size_t)ha;
        if (!ha && !hb) continue;
        double ta = a[i].t, tb = b[i].t;
        double slack = rays ? origin_slack(&rays[i]) : 0.0;
        if (ha != hb) {
            /* the one that hits says the ray starts on a surface */
            if (rays && fabs(ha ? ta : tb) <= slack) near_origin++;
            else hit_mismatch++;
            continue;
        }
        if (any_hit) continue;
        double scale = fmax(fabs(ta), fabs(tb));
        if (fabs(ta - tb) <= AGREE_REL_TOL * scale) {
            if (a[i].prim != b[i].prim) prim_differ++;
        } else if (rays && (fmin(fabs(ta), fabs(tb)) <= slack || fabs(ta - tb) <= slack)) {
            near_origin++;
        } else {
            t_mismatch++;
        }
    }
    size_t bad = hit_mismatch + t_mismatch;
    double frac = (double)bad / (double)na;
    int agree = frac <= AGREE_MAX_FRACTION;
    printf("rays=%zu hits=%zu mismatches=%zu hit_mismatches=%zu t_mismatches=%zu", na, nhits, bad,
           hit_mismatch, t_mismatch);
    if (rays) printf(" near_origin=%zu", near_origin);
    printf(" prim_differ=%zu fraction=%.6f agree=%s\n", prim_differ, frac, agree ? "yes" : "no");
    if (!agree)
        fprintf(stderr, "paprsek: %s and %s disagree on %zu of %zu rays (more than %.2f%%)\n", pa, pb,
                bad, na, AGREE_MAX_FRACTION * 100.0);
    rc = agree ? 0 : 1;
out:
    free(rays);
    free(a);
    free(b);
    return rc;
}

int cli_bench(int argc, char **argv)
{
    if (argc < 2) return cli_usage_error("bench needs a subcommand\n%s", usage_text);
    const char *sub = argv[1];
    if (strcmp(sub, "rays") == 0) return bench_rays(argc - 1, argv + 1);
    if (strcmp(sub, "gen-rays") == 0) return bench_gen_rays(argc - 1, argv + 1);
    if (strcmp(sub, "compare") == 0) return bench_compare(argc - 1, argv + 1);
    if (strcmp(sub, "--help") == 0 || strcmp(sub, "-h") == 0 || strcmp(sub, "help") == 0) {
        cli_bench_help(stdout);
        return 0;
    }
    static const char *const subs[] = {"rays", "gen-rays", "compare"};
    const char *near = cli_nearest(sub, strlen(sub), subs, COUNT(subs));
    if (near) return cli_usage_error("bench %s: unknown subcommand; did you mean bench %s?", sub, near);
    return cli_usage_error("bench %s: unknown subcommand (rays, gen-rays, compare)\n%s", sub, usage_text);
}
