/*
 * light_tree.h - choosing among many lights by their importance to the
 * shading point: a binary tree over the lights that have a place (emissive
 * triangles and spheres, point and spot lights), each node bounding its
 * lights' positions (a box), the directions they emit about (a cone of
 * half-angle theta_o about an axis, plus theta_e beyond which they send
 * nothing) and their power, after Conty Estevez and Kulla, "Importance
 * Sampling of Many Lights with Adaptive Tree Splitting" (2018), as pbrt-v4
 * uses it. A shading point walks from the root to one light, going to each
 * child with the probability of that child's importance, a conservative
 * estimate of the light it can send to the point; the probability of a
 * given light is found again by walking the path its bits record. Lights
 * without a place (the environment, the sun, distant lights) are chosen
 * apart, by power, with the probability they have in the power CDF.
 *
 * Everything here is PK_HD and deterministic, so sampling a light and
 * asking for its probability later (MIS) compute the same numbers.
 */
#ifndef PK_LIGHT_TREE_H
#define PK_LIGHT_TREE_H

#include "../math/vec3.h"
#include "../pk_hd.h"

#include <stdint.h>

#define LIGHT_TREE_LEAF 1u
#define LIGHT_TREE_TWO_SIDED 2u
#define LIGHT_TREE_MAX_DEPTH 63 /* a light's path is a 64-bit word */

/* A node: an interior node's first child follows it, its second is at
 * next; a leaf holds the light next. */
typedef struct light_tree_node {
    float lo[3], hi[3];  /* bounds of the positions */
    float axis[3];       /* unit */
    float phi;           /* power */
    float cos_o, cos_e;  /* the cone of normals and the angle of emission beyond it */
    uint32_t next;
    uint32_t flags;      /* LIGHT_TREE_* */
} light_tree_node;

/* The cosine of max(0, theta_a - theta_b) from both angles' cosines and
 * sines. */
static inline PK_HD float lt_cos_sub_clamped(float cos_a, float sin_a, float cos_b, float sin_b)
{
    if (cos_a > cos_b) return 1.0f;
    return cos_a * cos_b + sin_a * sin_b;
}

static inline PK_HD float lt_sin_of(float c)
{
    const float s2 = 1.0f - c * c;
    return s2 > 0.0f ? sqrtf(s2) : 0.0f;
}

/* How much light the node's lights can send to p, of normal n (zero: a
 * point that takes light from every direction): power over the squared
 * distance, times the cosines at the lights and at p, each taken at the
 * most favourable angle the bounds allow. Never negative. */
static inline PK_HD float light_tree_importance(const light_tree_node *nd, vec3 p, vec3 n)
{
    if (!(nd->phi > 0.0f)) return 0.0f;
    const vec3 lo = v3(nd->lo[0], nd->lo[1], nd->lo[2]), hi = v3(nd->hi[0], nd->hi[1], nd->hi[2]);
    const vec3 pc = v3_scale(v3_add(lo, hi), 0.5f);
    const vec3 to_p = v3_sub(p, pc);
    const float dist2 = v3_len2(to_p);
    const float r2 = 0.25f * v3_len2(v3_sub(hi, lo)); /* the bounding sphere of the box */
    const float d2 = dist2 > r2 ? dist2 : r2;
    /* the cone of directions the box fills, seen from p */
    float cos_b = -1.0f;
    const bool inside = p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x <= hi.x && p.y <= hi.y && p.z <= hi.z;
    if (!inside && dist2 > r2) cos_b = sqrtf(1.0f - r2 / dist2);
    const float sin_b = lt_sin_of(cos_b);
    const float il = dist2 > 0.0f ? 1.0f / sqrtf(dist2) : 0.0f;
    const vec3 wi = v3_scale(to_p, il); /* from the lights toward p */
    float cos_w = nd->axis[0] * wi.x + nd->axis[1] * wi.y + nd->axis[2] * wi.z;
    if (nd->flags & LIGHT_TREE_TWO_SIDED) cos_w = fabsf(cos_w);
    if (!(dist2 > 0.0f)) cos_w = 1.0f;
    const float sin_w = lt_sin_of(cos_w);
    const float cos_wo = lt_cos_sub_clamped(cos_w, sin_w, nd->cos_o, lt_sin_of(nd->cos_o));
    const float cos_p = lt_cos_sub_clamped(cos_wo, lt_sin_of(cos_wo), cos_b, sin_b);
    if (cos_p <= nd->cos_e) return 0.0f;
    float imp = nd->phi * cos_p / d2;
    if (v3_len2(n) > 0.0f && dist2 > 0.0f) {
        const float cos_i = fabsf(v3_dot(wi, n));
        imp *= lt_cos_sub_clamped(cos_i, lt_sin_of(cos_i), cos_b, sin_b);
    }
    return imp > 0.0f && isfinite(imp) ? imp : 0.0f;
}

/* The probability of going to the first child of interior node i. */
static inline PK_HD float light_tree_p_first(const light_tree_node *nodes, uint32_t i, vec3 p, vec3 n, bool *none)
{
    const float i0 = light_tree_importance(&nodes[i + 1], p, n), i1 = light_tree_importance(&nodes[nodes[i].next], p, n);
    const float sum = i0 + i1;
    *none = !(sum > 0.0f);
    return *none ? 0.0f : i0 / sum;
}

/* Walks from the root with u in [0, 1): the light reached, and through
 * *pmf the probability of reaching it; false when no light can reach p. */
static inline PK_HD bool light_tree_pick(const light_tree_node *nodes, vec3 p, vec3 n, float u, uint32_t *light,
                                         float *pmf)
{
    uint32_t i = 0;
    float pr = 1.0f;
    if (!(light_tree_importance(&nodes[0], p, n) > 0.0f)) return false;
    while (!(nodes[i].flags & LIGHT_TREE_LEAF)) {
        bool none;
        const float p0 = light_tree_p_first(nodes, i, p, n, &none);
        if (none) return false;
        if (u < p0) {
            u = u / p0;
            pr *= p0;
            i = i + 1;
        } else {
            const float p1 = 1.0f - p0;
            u = (u - p0) / p1;
            pr *= p1;
            i = nodes[i].next;
        }
        u = u < 0x1.fffffep-1f ? u : 0x1.fffffep-1f;
    }
    *light = nodes[i].next;
    *pmf = pr;
    return pr > 0.0f;
}

/* The probability light_tree_pick gives the light whose path from the root
 * is trail (bit k: the second child at depth k). */
static inline PK_HD float light_tree_pmf(const light_tree_node *nodes, uint64_t trail, vec3 p, vec3 n)
{
    uint32_t i = 0;
    float pr = 1.0f;
    if (!(light_tree_importance(&nodes[0], p, n) > 0.0f)) return 0.0f;
    while (!(nodes[i].flags & LIGHT_TREE_LEAF)) {
        bool none;
        const float p0 = light_tree_p_first(nodes, i, p, n, &none);
        if (none) return 0.0f;
        if (trail & 1u) {
            pr *= 1.0f - p0;
            i = nodes[i].next;
        } else {
            pr *= p0;
            i = i + 1;
        }
        trail >>= 1;
    }
    return pr;
}

#endif
