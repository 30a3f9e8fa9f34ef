/*
 * embree.c - Embree 3 as an accelerator (--accel embree), so that Paprsek's
 * own structures can be timed and checked against it on the same rays. One
 * triangle geometry holds every triangle (degenerate ones too, so Embree's
 * primID is Paprsek's triangle number) and one sphere-point geometry the
 * spheres. Without Embree's headers at build time (PK_HAVE_EMBREE 0) this
 * file is a stub.
 *
 * Embree is not linked: the library is compiled against Embree's headers and
 * loads libembree3.so.3 with dlopen the first time the Embree accelerator is
 * asked for (pk_accel_available or pk_accel_create), so that a program that
 * never uses it neither needs Embree installed nor pays for loading it. Every
 * rtc* function is called through the table rtc, filled with dlsym; the
 * header's prototypes give the pointer types (__typeof__), so a call that
 * does not match Embree's declarations does not compile.
 */
#include "accel.h"
#include "device/dynlib.h"

#if defined(PK_HAVE_EMBREE) && PK_HAVE_EMBREE

#include <embree3/rtcore.h>

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Every Embree function this file calls. */
#define RTC_FUNCTIONS(X)                                                                 \
    X(NewDevice) X(ReleaseDevice) X(GetDeviceError) X(GetDeviceProperty)                 \
    X(SetDeviceErrorFunction) X(SetDeviceMemoryMonitorFunction)                          \
    X(NewScene) X(ReleaseScene) X(SetSceneFlags) X(SetSceneBuildQuality) X(CommitScene)  \
    X(NewGeometry) X(ReleaseGeometry) X(SetNewGeometryBuffer) X(SetGeometryBuildQuality) \
    X(SetGeometryUserData) X(SetGeometryOccludedFilterFunction) X(CommitGeometry)        \
    X(AttachGeometryByID) X(SetGeometryInstancedScene) X(SetGeometryTransform)         \
    X(Intersect1) X(Occluded1) X(Intersect8) X(Occluded8) X(Intersect16) X(Occluded16)

/* rtc.Name points to Embree's rtcName once the library is ready (embree
 * below): filled under the loader's lock, never changed afterwards. The
 * library (the config's embree.library, libembree3.so.3 by default) is
 * never closed: Embree keeps threads of its own. */
static struct rtc_table {
#define RTC_FIELD(name) __typeof__(&rtc##name) name;
    RTC_FUNCTIONS(RTC_FIELD)
#undef RTC_FIELD
} rtc;

static dynlib embree = DYNLIB_INIT;

static bool init_embree(void *h, const char *name, char *why, size_t n)
{
    struct rtc_table t;
    void *sym;
#define RTC_LOAD(fn)                                                                              \
    sym = dynlib_symbol(h, "rtc" #fn);                                                            \
    if (!sym) {                                                                                   \
        snprintf(why, n, "%s has no rtc" #fn " (not Embree 3?)", name);                          \
        return false;                                                                             \
    }                                                                                             \
    memcpy(&t.fn, &sym, sizeof sym);
    RTC_FUNCTIONS(RTC_LOAD)
#undef RTC_LOAD
    rtc = t;
    return true;
}

/* Loads the Embree library ctx's config names (ctx NULL: the default) once
 * per process; true when its functions are in rtc, else why says why. */
static bool embree_loaded(const pk_context *ctx, char *why, size_t n)
{
    return dynlib_load(&embree, config_embree_library(ctx), init_embree, why, n);
}

enum { GEOM_TRIS = 0, GEOM_SPHERES = 1, GEOM_FIRST_INSTANCE = 2 };

/* Invariants:
 *  1. scene is committed and never changed after accel_embree_create;
 *  2. geometry GEOM_TRIS holds triangle k as primitive k (ntris of them),
 *     geometry GEOM_SPHERES sphere k as primitive k (nspheres);
 *  3. spheres is a copy of the input spheres (for u, v of sphere hits). */
typedef struct embree_accel {
    accel base;
    pk_allocator alloc;       /* copy of the context's allocator */
    RTCDevice device;
    RTCScene scene;
    accel_sphere *spheres;
    RTCScene *mesh_scenes;    /* per mesh of an instanced input: its triangles as geometry 0 (NULL: none) */
    size_t nmesh_scenes;
    uint32_t *inst_prim0;     /* instance i (geometry GEOM_FIRST_INSTANCE + i): its triangle 0's number */
    size_t ninst;
    int64_t device_bytes;     /* bytes Embree holds (memory monitor, atomic) */
    unsigned packet_width;    /* 8 or 16: the widest native packet */
    bool has_filter;          /* occlusion filters work: any-hit reports t */
} embree_accel;

/* The error callback's state while building. */
typedef struct build_errors {
    pk_context *ctx;
    bool failed;
} build_errors;

/* An intersection context that carries where an occlusion filter writes the
 * hit it accepts: out[ray id]. */
typedef struct occ_context {
    struct RTCIntersectContext base;
    hit *out;
} occ_context;

bool accel_embree_available(const pk_context *ctx)
{
    char why[8];
    return embree_loaded(ctx, why, sizeof why);
}

pk_status accel_embree_unavailable(pk_context *ctx)
{
    char why[400];
    if (embree_loaded(ctx, why, sizeof why))
        return ctx_error(ctx, PK_ERR_UNSUPPORTED, "accelerator 'embree' is not available");
    return ctx_error(ctx, PK_ERR_UNSUPPORTED, "accelerator 'embree' is not available: %s (Debian: install libembree3-3)",
                     why);
}

static const char *rtc_error_name(enum RTCError code)
{
    switch (code) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    default: return "unknown error";
    }
}

static pk_status rtc_error_status(enum RTCError code)
{
    switch (code) {
    case RTC_ERROR_OUT_OF_MEMORY: return PK_ERR_NOMEM;
    case RTC_ERROR_INVALID_ARGUMENT: return PK_ERR_INVALID_ARGUMENT;
    case RTC_ERROR_CANCELLED: return PK_ERR_CANCELLED;
    default: return PK_ERR_UNSUPPORTED;
    }
}

static void on_build_error(void *user, enum RTCError code, const char *str)
{
    build_errors *be = user;
    be->failed = true;
    ctx_error(be->ctx, rtc_error_status(code), "embree: %s%s%s", rtc_error_name(code),
              str && str[0] ? ": " : "", str ? str : "");
}

/* Counts what the device holds; Embree builds with several threads. */
static bool on_memory(void *user, ssize_t bytes, bool post)
{
    (void)post;
    embree_accel *e = user;
    __atomic_fetch_add(&e->device_bytes, (int64_t)bytes, __ATOMIC_RELAXED);
    return true;
}

/* embree.quality of ctx's config: 0 low, 1 medium, 2 high */
static enum RTCBuildQuality build_quality(const pk_context *ctx)
{
    static const enum RTCBuildQuality q[3] = {RTC_BUILD_QUALITY_LOW, RTC_BUILD_QUALITY_MEDIUM, RTC_BUILD_QUALITY_HIGH};
    const int i = ctx->config.embree_quality;
    return q[i >= 0 && i < 3 ? i : 1];
}

/* u, v of a sphere hit, computed as sphere_intersect does (geom.h). */
static void sphere_uv(const embree_accel *e, uint32_t k, vec3 o, vec3 d, float t, float *u, float *v)
{
    const accel_sphere *s = &e->spheres[k];
    vec3 p = v3_scale(v3_sub(v3_add(o, v3_scale(d, t)), s->center), 1.0f / s->radius);
    float phi = atan2f(p.z, p.x);
    float theta = acosf(fminf(1.0f, fmaxf(-1.0f, p.y)));
    *u = (phi + PK_PI) * (0.5f / PK_PI);
    *v = theta * (1.0f / PK_PI);
}

/* Fills *h from Embree's answer for a ray from o along d (inst: the
 * instance geometry the hit is in, or RTC_INVALID_GEOMETRY_ID). */
static void set_hit(const embree_accel *e, vec3 o, vec3 d, float t, unsigned inst, unsigned geom, unsigned prim,
                    float u, float v, hit *h)
{
    h->t = t;
    if (inst != RTC_INVALID_GEOMETRY_ID) {
        h->prim = e->inst_prim0[inst - GEOM_FIRST_INSTANCE] + prim;
        h->u = u;
        h->v = v;
    } else if (geom == GEOM_TRIS) {
        h->prim = prim;
        h->u = u;
        h->v = v;
    } else {
        h->prim = (uint32_t)e->base.ntris + prim;
        sphere_uv(e, prim, o, d, t, &h->u, &h->v);
    }
}

static void init_ray1(struct RTCRay *rr, const ray *r)
{
    rr->org_x = r->o.x;
    rr->org_y = r->o.y;
    rr->org_z = r->o.z;
    rr->tnear = r->tmin;
    rr->dir_x = r->d.x;
    rr->dir_y = r->d.y;
    rr->dir_z = r->d.z;
    rr->time = 0.0f;
    rr->tfar = r->tmax;
    rr->mask = 0xFFFFFFFFu;
    rr->id = 0;
    rr->flags = 0;
}

/* Occlusion filter: accepts the first hit and records it in out[ray id].
 * Ray and hit are SoA blocks of N lanes (rtcore_ray.h, RTCRayN/RTCHitN). */
static void occ_filter(const struct RTCFilterFunctionNArguments *args)
{
    const embree_accel *e = args->geometryUserPtr;
    const occ_context *oc = (const occ_context *)args->context;
    const unsigned n = args->N;
    const float *rf = (const float *)args->ray;
    const unsigned *ru = (const unsigned *)args->ray;
    const float *hf = (const float *)args->hit;
    const unsigned *hu = (const unsigned *)args->hit;
    for (unsigned i = 0; i < n; i++) {
        if (args->valid[i] != -1) continue;
        vec3 o = v3(rf[0 * n + i], rf[1 * n + i], rf[2 * n + i]);
        vec3 d = v3(rf[4 * n + i], rf[5 * n + i], rf[6 * n + i]);
        set_hit(e, o, d, rf[8 * n + i], hu[7 * n + i], hu[6 * n + i], hu[5 * n + i], hf[3 * n + i], hf[4 * n + i],
                &oc->out[ru[10 * n + i]]);
    }
}

static bool emb_intersect(const accel *a, const ray *r, hit *h, accel_counters *c)
{
    (void)c;
    const embree_accel *e = (const embree_accel *)a;
    struct RTCIntersectContext ictx;
    rtcInitIntersectContext(&ictx);
    struct RTCRayHit rh;
    init_ray1(&rh.ray, r);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtc.Intersect1(e->scene, &ictx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
        hit_clear(h);
        return false;
    }
    set_hit(e, r->o, r->d, rh.ray.tfar, rh.hit.instID[0], rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, h);
    return true;
}

static bool emb_occluded(const accel *a, const ray *r, hit *h, accel_counters *c)
{
    (void)c;
    const embree_accel *e = (const embree_accel *)a;
    hit scratch;
    occ_context oc;
    rtcInitIntersectContext(&oc.base);
    oc.out = h ? h : &scratch;
    hit_clear(oc.out);
    struct RTCRay rr;
    init_ray1(&rr, r);
    rtc.Occluded1(e->scene, &oc.base, &rr);
    if (rr.tfar != -INFINITY) {
        hit_clear(oc.out);
        return false;
    }
    return true;
}

/* Field indices in the SoA RTCRayHitN / RTCRayN layout (rtcore_ray.h). */
enum {
    F_ORG_X, F_ORG_Y, F_ORG_Z, F_TNEAR, F_DIR_X, F_DIR_Y, F_DIR_Z, F_TIME, F_TFAR, F_MASK, F_ID,
    F_FLAGS, F_RAY_FIELDS,
    /* hit fields follow the ray fields */
    F_NG_X = F_RAY_FIELDS, F_NG_Y, F_NG_Z, F_U, F_V, F_PRIM, F_GEOM, F_INST
};

typedef union packet_buf {
    struct RTCRayHit16 rh16;
    struct RTCRayHit8 rh8;
    struct RTCRay16 r16;
    struct RTCRay8 r8;
} packet_buf;

/* Coherent groups of e->packet_width rays through rtcIntersect8/16 or
 * rtcOccluded8/16; the last group has its unused lanes switched off. */
static void emb_packets(const accel *a, const ray *r, hit *h, size_t n, bool any_hit,
                        accel_counters *c)
{
    (void)c;
    const embree_accel *e = (const embree_accel *)a;
    const unsigned w = e->packet_width;
    _Alignas(64) packet_buf buf;
    _Alignas(64) int valid[16];
    float *f = (float *)&buf;
    unsigned *u = (unsigned *)&buf;

    if (any_hit && !e->has_filter) {
        /* No filter functions in this Embree: only the closest hit gives a t. */
        for (size_t i = 0; i < n; i++) emb_intersect(a, &r[i], &h[i], NULL);
        return;
    }
    memset(&buf, 0, sizeof buf);
    for (size_t base = 0; base < n; base += w) {
        const unsigned m = n - base < w ? (unsigned)(n - base) : w;
        for (unsigned i = 0; i < w; i++) {
            if (i >= m) {
                valid[i] = 0;
                continue;
            }
            const ray *ri = &r[base + i];
            valid[i] = -1;
            f[F_ORG_X * w + i] = ri->o.x;
            f[F_ORG_Y * w + i] = ri->o.y;
            f[F_ORG_Z * w + i] = ri->o.z;
            f[F_TNEAR * w + i] = ri->tmin;
            f[F_DIR_X * w + i] = ri->d.x;
            f[F_DIR_Y * w + i] = ri->d.y;
            f[F_DIR_Z * w + i] = ri->d.z;
            f[F_TIME * w + i] = 0.0f;
            f[F_TFAR * w + i] = ri->tmax;
            u[F_MASK * w + i] = 0xFFFFFFFFu;
            u[F_ID * w + i] = i;
            u[F_FLAGS * w + i] = 0;
            if (!any_hit) {
                u[F_GEOM * w + i] = RTC_INVALID_GEOMETRY_ID;
                u[F_INST * w + i] = RTC_INVALID_GEOMETRY_ID;
            }
        }
        hit *out = h + base;
        if (any_hit) {
            occ_context oc;
            rtcInitIntersectContext(&oc.base);
            oc.base.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
            oc.out = out;
            for (unsigned i = 0; i < m; i++) hit_clear(&out[i]);
            if (w == 16) rtc.Occluded16(valid, e->scene, &oc.base, &buf.r16);
            else rtc.Occluded8(valid, e->scene, &oc.base, &buf.r8);
            for (unsigned i = 0; i < m; i++)
                if (f[F_TFAR * w + i] != -INFINITY) hit_clear(&out[i]);
        } else {
            struct RTCIntersectContext ictx;
            rtcInitIntersectContext(&ictx);
            ictx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
            if (w == 16) rtc.Intersect16(valid, e->scene, &ictx, &buf.rh16);
            else rtc.Intersect8(valid, e->scene, &ictx, &buf.rh8);
            for (unsigned i = 0; i < m; i++) {
                const ray *ri = &r[base + i];
                if (u[F_GEOM * w + i] == RTC_INVALID_GEOMETRY_ID) hit_clear(&out[i]);
                else
                    set_hit(e, ri->o, ri->d, f[F_TFAR * w + i], u[F_INST * w + i], u[F_GEOM * w + i],
                            u[F_PRIM * w + i], f[F_U * w + i], f[F_V * w + i], &out[i]);
            }
        }
    }
}

static void emb_destroy(accel *a)
{
    embree_accel *e = (embree_accel *)a;
    if (!e) return;
    pk_allocator al = e->alloc;
    if (e->scene) rtc.ReleaseScene(e->scene);
    for (size_t m = 0; e->mesh_scenes && m < e->nmesh_scenes; m++)
        if (e->mesh_scenes[m]) rtc.ReleaseScene(e->mesh_scenes[m]);
    mem_free(&al, e->mesh_scenes);
    mem_free(&al, e->inst_prim0);
    if (e->device) rtc.ReleaseDevice(e->device);
    mem_free(&al, e->spheres);
    mem_free(&al, e);
}

static const accel_ops embree_ops = {
    .destroy = emb_destroy,
    .intersect = emb_intersect,
    .occluded = emb_occluded,
    .intersect_packet = emb_packets,
};

/* Adds the triangles as geometry GEOM_TRIS of scene: vertices 3k..3k+2 are triangle k. */
static void add_triangles(embree_accel *e, RTCScene scene, const accel_input *in, enum RTCBuildQuality q)
{
    RTCGeometry g = rtc.NewGeometry(e->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!g) return;
    float *vb = rtc.SetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                        3 * sizeof(float), 3 * in->ntris);
    unsigned *ib = rtc.SetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           3 * sizeof(unsigned), in->ntris);
    if (vb && ib) {
        for (size_t i = 0; i < 3 * in->ntris; i++) {
            vb[3 * i + 0] = in->verts[i].x;
            vb[3 * i + 1] = in->verts[i].y;
            vb[3 * i + 2] = in->verts[i].z;
            ib[i] = (unsigned)i;
        }
        rtc.SetGeometryBuildQuality(g, q);
        rtc.SetGeometryUserData(g, e);
        if (e->has_filter) rtc.SetGeometryOccludedFilterFunction(g, occ_filter);
        rtc.CommitGeometry(g);
        rtc.AttachGeometryByID(scene, g, GEOM_TRIS);
    }
    rtc.ReleaseGeometry(g);
}

static void add_spheres(embree_accel *e, const accel_input *in, enum RTCBuildQuality q)
{
    RTCGeometry g = rtc.NewGeometry(e->device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    if (!g) return;
    float *vb = rtc.SetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                        4 * sizeof(float), in->nspheres);
    if (vb) {
        for (size_t i = 0; i < in->nspheres; i++) {
            vb[4 * i + 0] = in->spheres[i].center.x;
            vb[4 * i + 1] = in->spheres[i].center.y;
            vb[4 * i + 2] = in->spheres[i].center.z;
            vb[4 * i + 3] = in->spheres[i].radius;
        }
        rtc.SetGeometryBuildQuality(g, q);
        rtc.SetGeometryUserData(g, e);
        if (e->has_filter) rtc.SetGeometryOccludedFilterFunction(g, occ_filter);
        rtc.CommitGeometry(g);
        rtc.AttachGeometryByID(e->scene, g, GEOM_SPHERES);
    }
    rtc.ReleaseGeometry(g);
}

/* The meshes as scenes of their own and the instances as instance
 * geometries GEOM_FIRST_INSTANCE + i of e->scene. */
static void add_instances(embree_accel *e, const accel_input *in, const accel_instances *ti, enum RTCBuildQuality q)
{
    for (size_t m = 0; m < ti->nmeshes; m++) {
        if (!ti->meshes[m].ntris) continue;
        RTCScene ms = rtc.NewScene(e->device);
        if (!ms) return;
        e->mesh_scenes[m] = ms;
        rtc.SetSceneBuildQuality(ms, q);
        accel_input mi = {ti->meshes[m].verts, ti->meshes[m].ntris, NULL, 0, in->threads};
        add_triangles(e, ms, &mi, q);
        rtc.CommitScene(ms);
    }
    for (size_t i = 0; i < ti->ninstances; i++) {
        const accel_instance *ii = &ti->instances[i];
        e->inst_prim0[i] = ii->prim0;
        if (!e->mesh_scenes[ii->mesh]) continue;
        RTCGeometry g = rtc.NewGeometry(e->device, RTC_GEOMETRY_TYPE_INSTANCE);
        if (!g) return;
        rtc.SetGeometryInstancedScene(g, e->mesh_scenes[ii->mesh]);
        float m34[12];
        for (int k = 0; k < 12; k++) m34[k] = ii->to_world.m[k];
        rtc.SetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, m34);
        rtc.CommitGeometry(g);
        rtc.AttachGeometryByID(e->scene, g, (unsigned)(GEOM_FIRST_INSTANCE + i));
        rtc.ReleaseGeometry(g);
    }
}

pk_status accel_embree_create(pk_context *ctx, const accel_input *in, accel **out)
{
    return accel_embree_create_instanced(ctx, in, NULL, out);
}

pk_status accel_embree_create_instanced(pk_context *ctx, const accel_input *in, const accel_instances *ti,
                                        accel **out)
{
    *out = NULL;
    char why[8];
    if (!embree_loaded(ctx, why, sizeof why)) return accel_embree_unavailable(ctx);
    const enum RTCBuildQuality quality = build_quality(ctx);
    if (in->ntris > UINT32_MAX / 3 || in->nspheres > UINT32_MAX ||
        in->ntris + in->nspheres >= PK_NO_HIT)
        return ctx_error(ctx, PK_ERR_LIMIT, "embree: %zu triangles and %zu spheres are too many",
                         in->ntris, in->nspheres);

    embree_accel *e = mem_calloc(&ctx->alloc, 1, sizeof *e);
    if (!e) return ctx_nomem(ctx);
    e->alloc = ctx->alloc;
    e->base.ops = &embree_ops;
    e->base.alloc = &e->alloc;
    e->base.ntris = in->ntris;
    e->base.nspheres = in->nspheres;
    if (in->nspheres) {
        e->spheres = mem_alloc(&e->alloc, in->nspheres * sizeof *e->spheres);
        if (!e->spheres) {
            emb_destroy(&e->base);
            return ctx_nomem(ctx);
        }
        memcpy(e->spheres, in->spheres, in->nspheres * sizeof *e->spheres);
    }
    if (ti && ti->ninstances) {
        if (ti->ninstances >= UINT32_MAX - GEOM_FIRST_INSTANCE) {
            emb_destroy(&e->base);
            return ctx_error(ctx, PK_ERR_LIMIT, "embree: %zu instances are too many", ti->ninstances);
        }
        e->mesh_scenes = mem_calloc(&e->alloc, ti->nmeshes ? ti->nmeshes : 1, sizeof *e->mesh_scenes);
        e->inst_prim0 = mem_calloc(&e->alloc, ti->ninstances, sizeof *e->inst_prim0);
        e->nmesh_scenes = ti->nmeshes;
        e->ninst = ti->ninstances;
        if (!e->mesh_scenes || !e->inst_prim0) {
            emb_destroy(&e->base);
            return ctx_nomem(ctx);
        }
    }

    /* start_threads: the worker threads start here, outside build_ms */
    char config[64];
    snprintf(config, sizeof config, "threads=%d,start_threads=1,verbose=0", in->threads > 0 ? in->threads : 1);
    e->device = rtc.NewDevice(config);
    if (!e->device) {
        enum RTCError code = rtc.GetDeviceError(NULL);
        emb_destroy(&e->base);
        return ctx_error(ctx, rtc_error_status(code), "embree: the device could not be created: %s",
                         rtc_error_name(code));
    }
    build_errors be = {ctx, false};
    rtc.SetDeviceErrorFunction(e->device, on_build_error, &be);
    rtc.SetDeviceMemoryMonitorFunction(e->device, on_memory, e);
    e->packet_width = rtc.GetDeviceProperty(e->device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) ? 16 : 8;
    e->has_filter = rtc.GetDeviceProperty(e->device, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED) != 0;

    double t0 = time_now();
    e->scene = rtc.NewScene(e->device);
    if (e->scene) {
        rtc.SetSceneFlags(e->scene, RTC_SCENE_FLAG_NONE);
        rtc.SetSceneBuildQuality(e->scene, quality);
        if (in->ntris) add_triangles(e, e->scene, in, quality);
        if (in->nspheres) add_spheres(e, in, quality);
        if (e->ninst) add_instances(e, in, ti, quality);
        if (!be.failed) rtc.CommitScene(e->scene);
    }
    double t1 = time_now();
    if (be.failed || !e->scene || rtc.GetDeviceError(e->device) != RTC_ERROR_NONE) {
        if (!be.failed) ctx_error(ctx, PK_ERR_UNSUPPORTED, "embree: the scene could not be built");
        const pk_status st = pk_context_status(ctx);
        rtc.SetDeviceErrorFunction(e->device, NULL, NULL);
        emb_destroy(&e->base);
        return st != PK_OK ? st : PK_ERR_UNSUPPORTED;
    }
    /* Tracing has no context to report to, and cannot fail. */
    rtc.SetDeviceErrorFunction(e->device, NULL, NULL);

    e->base.info.name = "embree";
    e->base.info.build_ms = (t1 - t0) * 1e3;
    e->base.info.primitives = in->ntris + in->nspheres;
    for (size_t i = 0; i < e->ninst; i++) e->base.info.primitives += ti->meshes[ti->instances[i].mesh].ntris;
    int64_t bytes = __atomic_load_n(&e->device_bytes, __ATOMIC_RELAXED);
    e->base.info.bytes = bytes > 0 ? (size_t)bytes : 0;
    *out = &e->base;
    return PK_OK;
}

#else /* no Embree */

bool accel_embree_available(const pk_context *ctx)
{
    (void)ctx;
    return false;
}

pk_status accel_embree_unavailable(pk_context *ctx)
{
    return ctx_error(ctx, PK_ERR_UNSUPPORTED,
                     "--accel embree: this build has no Embree (install libembree-dev and rebuild)");
}

pk_status accel_embree_create(pk_context *ctx, const accel_input *in, accel **out)
{
    (void)in;
    *out = NULL;
    return accel_embree_unavailable(ctx);
}

pk_status accel_embree_create_instanced(pk_context *ctx, const accel_input *in, const accel_instances *ti,
                                        accel **out)
{
    (void)in, (void)ti;
    *out = NULL;
    return accel_embree_unavailable(ctx);
}

#endif
