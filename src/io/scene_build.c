/*
 * scene_build.c - the readers' graphics state and mesh adding (scene_build.h).
 */
#include "scene_build.h"

void sb_init(scene_builder *b, pk_context *ctx, pk_scene *s)
{
    b->ctx = ctx;
    b->s = s;
    b->depth = 0;
    b->stack[0] = xform_identity();
    b->material = 0;
    b->in_object = false;
    b->obj_pos = b->obj_nrm = b->obj_uv = b->obj_tri = 0;
}

bool sb_push(scene_builder *b)
{
    if (b->depth + 1 >= SB_MAX_DEPTH) return false;
    b->stack[b->depth + 1] = b->stack[b->depth];
    b->depth++;
    return true;
}

bool sb_pop(scene_builder *b)
{
    if (b->depth == 0) return false;
    b->depth--;
    return true;
}

pk_status sb_add_mesh(scene_builder *b, const sb_mesh *m)
{
    pk_scene *s = b->s;
    const xform *x = sb_transform(b);
    size_t pbase = s->npositions, nbase = s->nnormals, tbase = s->nuvs;
    pk_status st;
    float cof[9] = {0};
    if (m->nrm) xform_normal_cofactors(x, cof);
    for (size_t i = 0; i < m->npos; i++) {
        vec3 q = xform_point(x, m->pos[i]);
        if (!v3_finite(q)) return ctx_error(b->ctx, PK_ERR_PARSE, "%s: a transformed vertex is not finite", s->name);
        if ((st = scene_add_position(b->ctx, s, q))) return st;
        if (m->nrm) {
            vec3 n = v3_norm_scaled(xform_apply3(cof, m->nrm[i]));
            if (!v3_finite(n)) n = v3s(0.0f);
            if ((st = scene_add_normal(b->ctx, s, n))) return st;
        }
        if (m->uv) {
            uv2 t = {m->uv[2 * i], m->uv[2 * i + 1]};
            if (!isfinite(t.u) || !isfinite(t.v)) t.u = t.v = 0.0f;
            if ((st = scene_add_uv(b->ctx, s, t))) return st;
        }
    }
    for (size_t t = 0; t < m->ntris; t++) {
        triangle tr;
        uint32_t a = m->tris[3 * t], c1 = m->tris[3 * t + 1], c2 = m->tris[3 * t + 2];
        if (m->flip) {
            uint32_t sw = c1;
            c1 = c2, c2 = sw;
        }
        tr.v[0] = (uint32_t)(pbase + a), tr.v[1] = (uint32_t)(pbase + c1), tr.v[2] = (uint32_t)(pbase + c2);
        for (int k = 0; k < 3; k++) tr.n[k] = m->nrm ? (int32_t)(nbase + tr.v[k] - pbase) : -1;
        for (int k = 0; k < 3; k++) tr.t[k] = m->uv ? (int32_t)(tbase + tr.v[k] - pbase) : -1;
        tr.material = b->material;
        if ((st = scene_add_triangle(b->ctx, s, &tr))) return st;
    }
    return PK_OK;
}

bool sb_begin_object(scene_builder *b)
{
    if (b->in_object) return false;
    b->in_object = true;
    b->obj_pos = b->s->npositions, b->obj_nrm = b->s->nnormals, b->obj_uv = b->s->nuvs, b->obj_tri = b->s->ntris;
    return true;
}

pk_status sb_end_object(scene_builder *b, uint32_t *mesh)
{
    if (!b->in_object) return ctx_error(b->ctx, PK_ERR_INVALID_ARGUMENT, "%s: no object is being defined", b->s->name);
    b->in_object = false;
    return scene_capture_mesh(b->ctx, b->s, b->obj_pos, b->obj_nrm, b->obj_uv, b->obj_tri, mesh);
}

pk_status sb_add_instance(scene_builder *b, uint32_t mesh)
{
    if (b->in_object)
        return ctx_error(b->ctx, PK_ERR_INVALID_ARGUMENT, "%s: an instance inside an object definition", b->s->name);
    return scene_add_instance(b->ctx, b->s, mesh, sb_transform(b), SCENE_MESH_MATERIAL);
}
