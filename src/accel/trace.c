/*
 * trace.c - tracing a batch of rays through any accelerator in parallel
 * (OpenMP over chunks of 256 rays): single rays, any-hit queries or
 * coherent packets; an accelerator with a batch operation of its own (the
 * GPU) takes the whole batch.
 */
#include "accel.h"

#include <omp.h>

void accel_trace_batch(const accel *a, const ray *rays, hit *hits, size_t n, int threads, unsigned flags,
                       pk_trace_counters *counters)
{
    if (a->ops->trace_batch) {
        a->ops->trace_batch(a, rays, hits, n, flags, counters);
        return;
    }
    int nt = threads > 0 ? threads : omp_get_max_threads();
    const bool any = (flags & PK_TRACE_ANY_HIT) != 0, coherent = (flags & PK_TRACE_COHERENT) != 0;
    const size_t chunk = 256;
    const long nchunks = (long)((n + chunk - 1) / chunk);
    uint64_t tests = 0, nodes = 0;
#pragma omp parallel num_threads(nt) reduction(+ : tests, nodes)
    {
        accel_counters c = {0, 0};
        accel_counters *cp = counters ? &c : NULL;
#pragma omp for schedule(dynamic, 4)
        for (long ci = 0; ci < nchunks; ci++) {
            size_t lo = (size_t)ci * chunk, hi = lo + chunk < n ? lo + chunk : n;
            if (coherent) {
                accel_intersect_many(a, rays + lo, hits + lo, hi - lo, any, cp);
            } else if (any) {
                for (size_t i = lo; i < hi; i++) a->ops->occluded(a, &rays[i], &hits[i], cp);
            } else {
                for (size_t i = lo; i < hi; i++) a->ops->intersect(a, &rays[i], &hits[i], cp);
            }
        }
        tests += c.tests;
        nodes += c.nodes;
    }
    if (counters) {
        counters->intersection_tests += tests;
        counters->nodes_visited += nodes;
    }
}
