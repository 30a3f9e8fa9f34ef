/*
 * pk_hd.h - PK_HD marks functions compiled for the CPU and, by nvcc, for the
 * GPU as well (docs/gpu.md): plain C over plain structs, so that the CPU's
 * tests check the code the GPU runs. Empty in C.
 */
#ifndef PK_HD_H
#define PK_HD_H

#if defined(__CUDACC__)
#define PK_HD __host__ __device__
#else
#define PK_HD
#endif

/* C11's static assertion, under nvcc (C++) */
#if defined(__cplusplus) && !defined(_Static_assert)
#define _Static_assert static_assert
#endif
/* and C11's alignment specifier */
#if defined(__cplusplus) && !defined(_Alignas)
#define _Alignas(n) alignas(n)
#endif

#endif
