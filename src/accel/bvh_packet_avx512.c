/*
 * bvh_packet_avx512.c - bvh_packet.c compiled for AVX-512 (x86-64-v4):
 * bvh_intersect_packet_avx512 (see bvh.h on the two sets of kernels).
 */
#include "../paprsek_internal.h"
#if PK_HAVE_AVX512_KERNELS
#define BVH_AVX512 1
#include "bvh_packet.c"
#else
typedef int bvh_packet_avx512_unused; /* ISO C forbids an empty file */
#endif
