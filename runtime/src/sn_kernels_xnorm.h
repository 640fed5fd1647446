/* sn_kernels_xnorm.h -- fixed flavour: the area-weighted vertex normals of
 * sn_get_normals (sn_kernels_xnorm.c). */
#ifndef SN_KERNELS_XNORM_H
#define SN_KERNELS_XNORM_H

#include "sn_instance.h"

#if !defined(SN_FLOAT)
/* out[0..nS) = the unit (Q30) area-weighted normals of the nT triangles
 * (u16[3] each, indices < nS) on positions p[0..nS) (public units) */
void sn_k_xnormals(const unsigned char *tris, uint32_t nT, const sn_vec3 *p, uint32_t nS, sn_vec3 *out);
/* the nearest integer to sqrt(x), 16 <= x < 3 2^62: the unit step's root on
 * this build (tests: sn_isqrt64 rounded) */
uint32_t sn_k_xrsqrt(uint64_t x);
/* the unit step alone, in place: a zero sum gives (0, 0, 2^30) (tests) */
void sn_k_xunit(sn_vec3 *out, uint32_t n);
#endif

#endif
