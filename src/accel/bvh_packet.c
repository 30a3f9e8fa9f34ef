/*
 * bvh_packet.c - coherent rays (camera tiles, shadow rays toward one light)
 * traced through the wide BVH; results equal the single-ray traversal's.
 */
#include "bvh.h"

void bvh_intersect_packet(const accel *a, const ray *r, hit *h, size_t n, bool any_hit,
                          accel_counters *c)
{
    for (size_t i = 0; i < n; i++) {
        if (any_hit) bvh_any_hit(a, &r[i], &h[i], c);
        else bvh_intersect(a, &r[i], &h[i], c);
    }
}
