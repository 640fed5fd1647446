/* sn_thostile.h -- hostile arguments to the constraint and collider API
 * (format 5.0), shared by the blob fuzzers (fuzz_blob.c, lf_blob.c): far
 * targets, huge and zero-size solids, out-of-range vertices and kinds;
 * refused ones return a status, accepted ones are stepped by the caller.
 */
#ifndef SN_THOSTILE_H
#define SN_THOSTILE_H

#include <string.h>
#include "sinew.h"

#if defined(SN_FLOAT)
#define TH_REAL(f, i) ((sn_real)(f))
#else
#define TH_REAL(f, i) ((sn_real)(i))
#endif

static inline void th_hostile_contacts(sn_instance *inst, uint32_t surface_vertices) {
    sn_constraint fc[3];
    sn_collider fk[3];
    sn_status cs_;
    memset(fc, 0, sizeof fc);
    memset(fk, 0, sizeof fk);
    fc[0].at = SN_AT_SURFACE; fc[0].vertex = surface_vertices ? surface_vertices - 1 : 0;
    fc[0].target.x = TH_REAL(3.0e4f, INT32_MAX); fc[0].target.y = TH_REAL(-3.0e4f, INT32_MIN);
    fc[1].at = SN_AT_LATTICE; fc[1].vertex = 0; fc[1].axes = SN_AXIS_DIR; fc[1].dir.x = TH_REAL(1.0e-30f, 1); fc[1].dir.z = TH_REAL(-1.0f, -65536);
    fc[2].at = SN_AT_POINT; fc[2].point.x = TH_REAL(-3.0e4f, INT32_MIN); fc[2].axes = SN_AXIS_Y;
    cs_ = sn_set_constraints(inst, fc, 3);
    if (surface_vertices == 0 && cs_ == SN_ERR_ARG) cs_ = sn_set_constraints(inst, fc + 1, 2);
    fc[0].vertex = surface_vertices; /* out of range: refused, nothing changes */
    (void)sn_set_constraints(inst, fc, 1);
    fk[0].kind = SN_COLLIDER_PLANE; fk[0].b.y = TH_REAL(3.0e4f, INT32_MAX); fk[0].a.y = TH_REAL(-0.2f, -13107);
    fk[1].kind = SN_COLLIDER_SPHERE; fk[1].radius = TH_REAL(3.0e4f, INT32_MAX); fk[1].velocity.x = TH_REAL(1.0e9f, INT32_MAX);
    fk[2].kind = SN_COLLIDER_CAPSULE; fk[2].a.x = TH_REAL(-1.0f, -65536); fk[2].b.x = TH_REAL(-1.0f, -65536); fk[2].radius = TH_REAL(0.5f, 32768);
    (void)sn_set_colliders(inst, fk, 3);
    fk[1].kind = 7; /* refused */
    (void)sn_set_colliders(inst, fk, 3);
    (void)cs_;
}

#endif /* SN_THOSTILE_H */
