/*
 * bvh_traverse_avx512.c - bvh_traverse.c compiled for AVX-512 (x86-64-v4):
 * bvh_intersect_avx512 and bvh_occluded_avx512 (see bvh.h on the two sets).
 * CMake compiles this file with -march=x86-64-v4 where the compiler accepts
 * it; the accelerator calls these functions only on CPUs that have AVX-512.
 */
#include "../paprsek_internal.h"
#if PK_HAVE_AVX512_KERNELS
#define BVH_AVX512 1
#include "bvh_traverse.c"
#else
typedef int bvh_traverse_avx512_unused; /* ISO C forbids an empty file */
#endif
