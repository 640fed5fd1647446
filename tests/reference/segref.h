/* segref.h -- double-precision reference of the runtime's segment meshes
 * (runtime/SEGMENTS.md), single level:
 * chains and sheets, Palazzi's displacement constraints (seed 004 §3.2)
 * with the same order of operations as the runtime (dynamics, symmetric
 * row-major node sweeps: star at sheet nodes of 3-4 ends, pairs elsewhere;
 * attachments, floor; velocities from the
 * displacements), written independently from the NUMERICS.md text. Units:
 * internal lengths (the caller converts), velocities per step. */
#ifndef SEGREF_H
#define SEGREF_H
#define SEGREF_MAXN 128
#define SEGREF_MAXS 256
typedef struct segref {
    int kind, side, ns, nn, sweeps, n_att;
    double len, gamma, keep, inv_mass, centre, grav[3];
    double omega;                               /* over-relaxation of attachments and pairs (1 after init) */
    double G[SEGREF_MAXS][3], u[SEGREF_MAXS][3], v[SEGREF_MAXS][3], w[SEGREF_MAXS][3];
    double N[SEGREF_MAXN][3], J[SEGREF_MAXN][3]; /* node positions; impulses (dv of mass m0) */
    int att_node[SEGREF_MAXN];
    double att_T[SEGREF_MAXN][3];               /* targets, set by the caller before each step */
    int floor_on;
    double fn[3], foff;
    double gap;                                 /* largest gap after the step / len */
} segref;
/* kind 0 chain (side nodes), 1 sheet (side x side); nodes: rest positions */
void segref_init(segref *r, int kind, int side, const double *nodes, double len, double gamma, double keep,
                 double inv_mass, double centre, int sweeps, const double grav[3]);
void segref_step(segref *r);
#endif
