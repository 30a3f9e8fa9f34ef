/*
 * frame.c - building a frame (see frame.h).
 */
#include "frame.h"

#include <omp.h>
#include <string.h>

pk_status frame_build_accel(pk_context *ctx, const pk_scene *s, pk_accel_kind kind, int threads, accel **out)
{
    *out = NULL;
    vec3 *verts = NULL;
    accel_sphere *sph = NULL;
    if (s->ntris) {
        verts = mem_realloc_array(&ctx->alloc, NULL, s->ntris, 3 * sizeof *verts); /* overflow-checked */
        if (!verts) return ctx_nomem(ctx);
        for (size_t k = 0; k < s->ntris; k++) scene_tri_verts(s, k, &verts[3 * k], &verts[3 * k + 1], &verts[3 * k + 2]);
    }
    if (s->nspheres) {
        sph = mem_realloc_array(&ctx->alloc, NULL, s->nspheres, sizeof *sph);
        if (!sph) {
            mem_free(&ctx->alloc, verts);
            return ctx_nomem(ctx);
        }
        for (size_t i = 0; i < s->nspheres; i++) {
            sph[i].center = s->spheres[i].center;
            sph[i].radius = s->spheres[i].radius;
        }
    }
    accel_input in = {verts, s->ntris, sph, s->nspheres, threads > 0 ? threads : omp_get_max_threads()};
    accel_instances ti = {NULL, 0, NULL, 0};
    pk_status st = PK_OK;
    accel_mesh *meshes = NULL;
    accel_instance *inst = NULL;
    if (s->nkept) { /* the kept instances: their meshes' object-space triangles */
        meshes = mem_calloc(&ctx->alloc, s->nmeshes, sizeof *meshes);
        inst = mem_realloc_array(&ctx->alloc, NULL, s->nkept, sizeof *inst);
        if (!meshes || !inst) st = ctx_nomem(ctx);
        for (size_t i = 0; i < s->nkept && st == PK_OK; i++) {
            const uint32_t mi = s->kept[i].mesh;
            inst[i] = (accel_instance){s->kept[i].to_world, mi, s->kept[i].prim0};
            if (meshes[mi].verts || !s->meshes[mi].ntris) continue;
            const scene_mesh *m = &s->meshes[mi];
            vec3 *mv = mem_realloc_array(&ctx->alloc, NULL, m->ntris, 3 * sizeof *mv);
            if (!mv) {
                st = ctx_nomem(ctx);
                break;
            }
            for (size_t k = 0; k < m->ntris; k++)
                for (int j = 0; j < 3; j++) mv[3 * k + j] = s->mesh_positions[m->first_pos + s->mesh_tris[m->first_tri + k].v[j]];
            meshes[mi].verts = mv;
            meshes[mi].ntris = m->ntris;
        }
        ti = (accel_instances){meshes, s->nmeshes, inst, s->nkept};
    }
    if (st == PK_OK) st = accel_create_instanced(ctx, kind, &in, &ti, out);
    for (size_t m = 0; meshes && m < s->nmeshes; m++) mem_free(&ctx->alloc, (void *)meshes[m].verts);
    mem_free(&ctx->alloc, meshes);
    mem_free(&ctx->alloc, inst);
    mem_free(&ctx->alloc, verts);
    mem_free(&ctx->alloc, sph);
    return st;
}

/* Whether anything in s emits: area lights, emissive spheres, point lights. */
static bool scene_has_light(const pk_scene *s)
{
    if (s->nemissive || s->nlights) return true;
    for (size_t i = 0; i < s->nspheres; i++) {
        vec3 ke = s->materials[s->spheres[i].material].ke;
        if (ke.x > 0.0f || ke.y > 0.0f || ke.z > 0.0f) return true;
    }
    return false;
}

static pk_status frame_env(pk_context *ctx, frame *f, const pk_scene *s)
{
    scene_environment env = s->env;
    if (!env.set && !scene_has_light(s)) {
        env.radiance = v3s(1.0f);
        ctx_warn(ctx, "%s: the scene has no light; lighting it with a uniform white environment of radiance 1 "
                 "(--env none for black, --env r,g,b or --env FILE for another)", s->name);
    }
    return env_build(ctx, &env, env.map_rgb, env.map_w, env.map_h, s->bounds, &f->env);
}

pk_status frame_init(pk_context *ctx, frame *f, const pk_scene *s, pk_accel_kind kind, int threads)
{
    memset(f, 0, sizeof *f);
    f->s = s;
    f->v = scene_view_of(s);
    double t0 = time_now();
    pk_status st = frame_build_accel(ctx, s, kind, threads, &f->a);
    if (st != PK_OK) return st;
    f->build_s = f->a->info.build_ms > 0.0 ? f->a->info.build_ms * 1e-3 : time_now() - t0;
    vec3 ext = aabb_extent(s->bounds);
    f->eps = 1e-5f * fmaxf(v3_max_comp(ext), 1e-6f);
    if ((st = frame_env(ctx, f, s)) != PK_OK || (st = light_set_build(ctx, s, &f->env, &f->lights)) != PK_OK) {
        frame_free(&ctx->alloc, f);
        return st;
    }
    return PK_OK;
}

void frame_free(const pk_allocator *al, frame *f)
{
    light_set_free(al, &f->lights);
    env_free(al, &f->env);
    accel_destroy(f->a);
    f->a = NULL;
}
