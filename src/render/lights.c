/*
 * lights.c - building the light table (see lights.h).
 */
#include "lights.h"

#include <string.h>

pk_status lights_build(pk_context *ctx, const pk_scene *s, light_table *lt)
{
    memset(lt, 0, sizeof *lt);
    if (s->nemissive == 0) return PK_OK;
    lt->cdf = mem_realloc_array(&ctx->alloc, NULL, s->nemissive, sizeof(float));
    lt->area = mem_realloc_array(&ctx->alloc, NULL, s->nemissive, sizeof(float));
    lt->normal = mem_realloc_array(&ctx->alloc, NULL, s->nemissive, sizeof(vec3));
    if (!lt->cdf || !lt->area || !lt->normal) {
        lights_free(&ctx->alloc, lt);
        return ctx_nomem(ctx);
    }
    lt->n = s->nemissive;
    double total = 0.0;
    for (size_t i = 0; i < s->nemissive; i++) {
        vec3 a0, b0, c0;
        scene_tri_verts(s, s->emissive[i], &a0, &b0, &c0);
        float area = 0.5f * v3_len(v3_cross(v3_sub(b0, a0), v3_sub(c0, a0)));
        lt->area[i] = area;
        lt->normal[i] = tri_normal(a0, b0, c0);
        float lum = v3_luminance(s->materials[s->tris[s->emissive[i]].material].ke);
        total += (double)fmaxf(lum, 1e-6f) * (double)area;
        lt->cdf[i] = (float)total;
    }
    for (size_t i = 0; i < s->nemissive; i++) lt->cdf[i] = (float)((double)lt->cdf[i] / total);
    lt->cdf[s->nemissive - 1] = 1.0f;
    lt->power = (float)total;
    return PK_OK;
}

void lights_free(const pk_allocator *al, light_table *lt)
{
    mem_free(al, lt->cdf);
    mem_free(al, lt->area);
    mem_free(al, lt->normal);
    memset(lt, 0, sizeof *lt);
}
