/*
 * surface.c - surface reconstruction at a hit: interpolated vertex normals
 * (flipped to the face's side), sphere normals, sides.
 */
#include "surface.h"

bool trace_past_holes(const accel *a, const scene_view *s, ray *r, hit *h, accel_counters *cp)
{
    for (int k = 0; k < HOLE_STEPS && surface_is_hole(s, r, h); k++) {
        r->tmin = nextafterf(h->t, INFINITY);
        if (!accel_intersect(a, r, h, cp)) return false;
    }
    return true;
}

bool occluded_past_holes(const accel *a, const scene_view *s, const ray *r, accel_counters *cp)
{
    if (!s->has_cutout) return accel_occluded(a, r, cp);
    ray rr = *r;
    hit h;
    if (!accel_intersect(a, &rr, &h, cp)) return false;
    return trace_past_holes(a, s, &rr, &h, cp);
}
