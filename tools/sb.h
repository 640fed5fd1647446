/* sb.h -- sinew-bake library: description + OBJ mesh -> control lattice ->
 * integrated matrices -> Sinew blob. Host-side C99 + libc + libm; allocates.
 * Every fallible function returns 0 on success, -1 on error with a message in
 * sb_error() (file:line for description mistakes). */
#ifndef SB_H
#define SB_H

#include <stddef.h>
#include <stdint.h>

#define SB_NAME_MAX 32

/* ---- errors, small utilities (sb_util.c) ---- */
const char *sb_error(void);
int sb_fail(const char *fmt, ...);          /* sets the message, returns -1 */
void *sb_alloc(size_t n);                   /* zeroed; exits on out-of-memory */
uint32_t sb_crc32(const unsigned char *p, size_t n);
double sb_now(void);                        /* seconds, for progress/timing */

/* ---- mesh (sb_mesh.c) ---- */
typedef struct sb_mesh {
    int nv, nt;
    double *v;      /* nv x 3, mesh units */
    int *tri;       /* nt x 3, 0-based, counter-clockwise seen from outside */
    double lo[3], hi[3];
} sb_mesh;
int sb_mesh_load_obj(const char *path, sb_mesh *m);  /* parse, triangulate (no duplicate edges), check closed */
void sb_mesh_free(sb_mesh *m);
/* A surface from separate points and triangles (a glTF primitive's vertices):
 * points at exactly the same position are welded into one vertex (first
 * occurrence order), to_surf[i] (nsrc ints, caller's) gets point i's vertex;
 * triangles collapsed by the weld are dropped (counted in *dropped); then the
 * OBJ loader's checks (closed, consistently oriented, extent, volume). */
int sb_mesh_from_points(const char *path, int nsrc, const double *pos, int nsrc_tri, const int *src_tri, sb_mesh *m,
                        int *to_surf, int *dropped);
double sb_mesh_volume(const sb_mesh *m);             /* divergence theorem, mesh units^3 */

/* Inside test: rays along +x; triangles binned by their (y,z) bounding box. */
typedef struct sb_inside {
    const sb_mesh *m;
    double y0, z0, dy, dz;
    int ny, nz;
    int *start;   /* (ny*nz+1) */
    int *tris;
    double *ty, *tz, *tx;  /* per triangle projected corners (3 each) */
} sb_inside;
void sb_inside_init(sb_inside *in, const sb_mesh *m);
int sb_inside_test(const sb_inside *in, const double p[3]);
/* x of every crossing of the +x ray through (any x, y, z), as sb_inside_test counts them:
 * p is inside iff p lies in the mesh bounding box and an odd number of xs exceed p[0].
 * Returns the number of crossings (only the first max are stored). */
int sb_inside_ray(const sb_inside *in, double y, double z, double *xs, int max);
/* closest point of the mesh surface to p (brute force); returns the distance */
double sb_mesh_closest(const sb_mesh *m, const double p[3], double out[3]);
void sb_inside_free(sb_inside *in);

/* ---- description (sb_desc.c) ---- */
enum { SB_RG_ALL, SB_RG_BOX, SB_RG_SPHERE, SB_RG_BONE };
typedef struct sb_region {
    int kind;
    double a[6];    /* box: lo xyz, hi xyz; sphere: centre xyz, radius */
    int bone;       /* SB_RG_BONE: joint index (description order) ending the bone */
    int line;
} sb_region;
typedef struct sb_matrule { sb_region r; int mat; } sb_matrule;
typedef struct sb_framerule { sb_region r; int j1, j2; double w; } sb_framerule;
typedef struct sb_pin { sb_region r; int joint; } sb_pin;
typedef struct sb_material { char name[SB_NAME_MAX]; double E, nu, rho; int line; } sb_material;
typedef struct sb_joint {
    char name[SB_NAME_MAX];
    char parent_name[SB_NAME_MAX];
    int parent;     /* index in description order, -1 root */
    double pos[3];  /* mesh units */
    int line;
    double bone_r;  /* radius of the bone ending here (mesh units), < 0: automatic ('bone JOINT R') */
    int bone_line;  /* line of its 'bone' statement, 0 if none */
} sb_joint;
typedef struct sb_limitrule { sb_region r; double dist; } sb_limitrule;
/* 'shares NAME FINE C2 C4 C8 RIGID' (seed 004 ch. 4): an external force's split over levels */
typedef struct sb_shares { char name[SB_NAME_MAX]; double s[5]; int line; } sb_shares;
/* 'shares_region REGION NAME': free vertices in REGION use that profile */
typedef struct sb_sharerule { sb_region r; int prof; } sb_sharerule;

/* rig controls and rigs (seed 003 §3, §4.1-4.2; tools/DESCRIPTION.md "Rigs and controls") */
enum { SB_CTL_ABSTRACT = 0, SB_CTL_ANGLE = 1, SB_CTL_TWIST = 2 };   /* TWIST bakes as an ANGLE about the bone axis */
typedef struct sb_control {
    char name[SB_NAME_MAX];
    int kind;           /* SB_CTL_* */
    int joint;          /* ANGLE/TWIST: joint index (description order in sb_desc, sorted order in sb_model); else -1 */
    double axis[3];     /* ANGLE/TWIST: unit axis in rest model axes (TWIST: JOINT -> its only child) */
    double value0;      /* ABSTRACT: value after init/reset (public units) */
    int line;
} sb_control;
enum { SB_TPL_BUMP = 0, SB_TPL_RING = 1, SB_TPL_MUSCLE = 2, SB_TPL_UNIFORM = 3, SB_TPL_FILE = 4 };   /* FILE: 'rig_file' (a fitted force field) */
#define SB_TAU_MAX 16
typedef struct sb_rigdef {
    char name[SB_NAME_MAX];
    int control;        /* index into the controls */
    int tpl;            /* SB_TPL_* */
    double s;           /* strength (dimensionless): force density s E_ref / L_ref (DESCRIPTION.md) */
    /* template parameters, mesh units: bump: c[3] R [d[3]]; ring: c[3] axis[3] RADIUS WIDTH;
     * muscle: a[3] b[3] R SHORTEN; uniform: d[3] */
    double p[10];
    int has_dir;        /* bump: a direction was given (else radial) */
    sb_region r;        /* uniform: the region */
    int ntau;           /* tau samples (gamma_k, eta_k), gamma strictly increasing; 0: default */
    double tau_g[SB_TAU_MAX], tau_e[SB_TAU_MAX];
    int tau_line;       /* line of the tau samples (0: default) */
    int line;
    char file[1024];    /* SB_TPL_FILE: the rig file, resolved relative to the description's directory */
} sb_rigdef;

/* segment meshes (seed 004 ch. 3-4; tools/DESCRIPTION.md "Segment meshes"):
 * 'chain' / 'sheet' declare a mesh, 'attach' pins nodes of it */
enum { SB_SEGATT_SURFACE = 0, SB_SEGATT_JOINT = 1 };   /* = SN_SEGATT_* */
typedef struct sb_segatt {
    int node;           /* node index (sheets row-major: row * side + column) */
    int kind;           /* SB_SEGATT_* */
    int joint;          /* JOINT: description order index; SURFACE: -1 */
    double within;      /* SURFACE: largest node-to-vertex distance, mesh units (< 0: default, half a segment) */
    int line;
} sb_segatt;
typedef struct sb_segdef {
    char name[SB_NAME_MAX];
    int kind;           /* 0 chain, 1 sheet (= SN_SEG_CHAIN / SN_SEG_SHEET) */
    int side;           /* chain: nodes; sheet: nodes per row and per column (2^n + 1) */
    double p0[3];       /* chain: first node; sheet: node (0,0), mesh units */
    double u[3], v[3];  /* chain: last node - first node (u); sheet: row edge (0,0)->(0,side-1) and column edge (0,0)->(side-1,0) */
    int levels;         /* sheet: 1..min(n+1, 4); chain 1 */
    double share[4];    /* force share per level, finest first, sum 1 */
    double mass;        /* kg, the whole mesh (finest level) */
    int sweeps;         /* constraint sweeps per step on level 0 */
    int coarse_sweeps;  /* on the coarser levels (sheets); 0: = sweeps */
    int relax;          /* over-relaxation omega of the sweeps' corrections x 32: 32..63 */
    double gamma;       /* translation factor (seed 004 §3.2.2), (0, 1] */
    double damping;     /* 1/s: velocity kept per step = exp(-damping h) */
    double centre;      /* share of a node force applied at the segments' centres (seed 004 §3.1) */
    int gravity;        /* 1 on, 0 off */
    sb_segatt *att; int natt;
    int line;
} sb_segdef;

struct sb_gltf;
/* self-collision near creases (seed 003 §3.4; tools/DESCRIPTION.md "Creases"):
 * 'crease POSE [steps N]' target poses, 'crease_settings ...' the runtime's maxima */
typedef struct sb_creasedef {
    char pose[1024];        /* "JOINT:AX,AY,AZ,DEG[+JOINT:...]" */
    int steps;              /* slow-motion steps from rest to the pose */
    int line;
} sb_creasedef;

typedef struct sb_desc {
    char path[1024];
    char mesh_path[1024];   /* resolved relative to the description's directory ('mesh' or 'gltf') */
    int mesh_line;
    struct sb_gltf *gltf;   /* 'gltf FILE [MESH]': the loaded file (joints and surface come from it), else NULL */
    char gltf_mesh[256];    /* its MESH argument ("" for the first skinned mesh) */
    int skin_frames;        /* 'frames skin': lattice frames from the glTF's skin weights (sb_frames.c) */
    int skin_frames_line;
    double unit;            /* metres per mesh unit */
    double cell;            /* lattice cell edge, mesh units */
    double origin[3]; int has_origin;
    int subdiv;             /* quadrature sub-boxes per cell edge */
    double air;             /* weight of outside quadrature points in kept cells */
    double min_fill;        /* drop cells whose inside fraction is below this */
    double blend;           /* frame blend width, mesh units (0: = cell) */
    sb_joint *joints; int nj;
    sb_material *mats; int nm;
    sb_matrule *mrules; int nmr;
    sb_framerule *frules; int nfr;
    sb_pin *pins; int npin;
    double alpha, beta, h;
    int cg_def, cg_max;
    int precond;            /* 'precond ichol|jacobi': SB_PRECOND_* */
    double g[3];
    double kappa, twist_r;  /* retired ('twist' is an error now): always 0 */
    int element;            /* SB_ELEM_*: stiffness element (sb_integrate.c) */
    double bone_radius;     /* 'bone_radius R': radius of every bone without a 'bone' line; < 0: automatic */
    sb_limitrule *lrules; int nlr;   /* 'limit REGION DIST' */
    int rest_modelled;      /* 'rest_shape modelled' (1) or 'sag' (0, default) */
    sb_control *ctls; int nctl;      /* 'control' */
    sb_rigdef *rigs; int nrig;       /* 'rig', 'tau' */
    int force_slots;                 /* 'forces N': external forces per step (default 8) */
    int max_cons;                    /* 'constraints N': position constraints (default 0) */
    int max_cols, max_contacts;      /* 'colliders N CONTACTS': colliders and contact rows per step (default 0 0) */
    sb_shares *shares; int nshares;  /* 'shares' */
    sb_sharerule *srules; int nsr;   /* 'shares_region' */
    sb_segdef *segs; int nseg;       /* 'chain', 'sheet', 'attach' */
    sb_creasedef *creases; int ncrease; /* 'crease' */
    int cr_list, cr_active, cr_ring; /* 'crease_settings': list size, active rows, neighbourhood ring */
    int cr_reach;                    /* 'crease_settings reach': rings around the slow motion's collisions that get rows */
    int cr_tring;                    /* 'crease_settings tring': TNBR rows hold the triangles touching this many rings (< 0: ring) */
    double cr_depth, cr_push;        /* mesh units; < 0: default (half a cell; a quarter of depth) */
    double cr_thin;                  /* mesh units; 0: off: a seed pair whose two vertices are both within this rest distance of an earlier pair's is dropped */
    double cr_exclude;               /* mesh units; < 0: default (one cell): seed pairs closer than this in the rest pose are not collisions */
    int cr_line;                     /* line of 'crease_settings' (0: none) */
    int levels, levels_line;         /* 'levels N': 1, or 2 with the lattice subdivided once (sb_level.c) */
    int levels_cut;                  /* 'levels 2 cut': level 0 is the cut level (sb_cut.c) */
    int lod_level;                   /* 0; 1 in the level-1 description sb_level_desc derives (rig files pick that level's fit) */
    int adapt_line, adapt_max;       /* 'adapt REFINE COARSEN MAX_ACTIVE' (with levels 2; 0: none): A_max */
    double adapt_refine, adapt_coarsen; /* level-0 cells */
    int details_line, details_max;   /* 'details A_MAX REFINE COARSEN' (with levels 2 cut; 0: none) */
    double details_refine, details_coarsen; /* level-0 cells */
} sb_desc;
/* trilinear hex with condensed Wilson-Taylor incompatible modes (default), or the plain trilinear hex */
enum { SB_ELEM_INCOMPATIBLE = 0, SB_ELEM_TRILINEAR = 1 };
int sb_desc_load(const char *path, sb_desc *d);
void sb_desc_free(sb_desc *d);

/* ---- glTF input (sb_gltf_bake.c; tools/DESCRIPTION.md 'gltf') ---- */
/* The glTF vertex order of a surface baked from 'gltf': surface vertex of
 * every glTF vertex (primitives concatenated), so an output can drive the
 * original mesh. Empty (nsrc 0) for an OBJ. */
typedef struct sb_srcmap {
    char path[1024];        /* the glTF file */
    char mesh[256];         /* its mesh's name */
    int nsrc, nsurf, nprim; /* glTF vertices, surface vertices, primitives */
    int *to_surf, *prim, *vert;   /* per glTF vertex: surface vertex, primitive, index in the primitive */
    int nsrc_tri;           /* glTF triangles (before the weld dropped *dropped of them) */
    int *src_tri;           /* 3 x nsrc_tri, glTF vertex indices (concatenated order) */
    int dropped;
    double root[3];         /* the root joint's rest position in the glTF frame: the runtime's model-space origin */
} sb_srcmap;
/* the 'gltf FILE [MESH]' line: load the file, declare its skin's joints */
int sb_desc_gltf(sb_desc *d, const char *file, const char *mesh, int line);
/* the description's surface: its OBJ, or its glTF's welded skinned mesh (map
 * filled, may be NULL) */
int sb_desc_mesh(const sb_desc *d, sb_mesh *m, sb_srcmap *map);
void sb_srcmap_free(sb_srcmap *s);
/* text sidecar (format in tools/DESCRIPTION.md, 'gltf'); 0 or -1 (sb_fail) */
int sb_srcmap_write(const char *path, const sb_srcmap *s);

/* ---- lattice + integration (sb_lattice.c and its steps in sb_lattice_geom.c, sb_lattice_fill.c, sb_frames.c; sb_integrate.c) ---- */
typedef struct sb_model {
    /* skeleton, sorted so parents precede children */
    int nj;
    sb_joint *joints;       /* sorted copy; parent indices refer to this order */
    int *desc_to_sorted;
    /* segments: one per non-root joint j, parent(j) -> j, moved by parent(j) */
    int nseg;
    int *seg_child;         /* sorted joint index of the child */
    /* grid */
    int gn[3];              /* grid vertices per axis */
    double gorg[3], c;
    double *gpos;           /* grid vertex positions (mesh units): an undistorted grid, never moved */
    int *gjoint;            /* joint moving a skeleton grid vertex, -1 free */
    int *gvert;             /* blob vertex index, -1 not in lattice */
    /* lattice */
    int nv, nf, nc;
    int *v_grid;            /* grid vertex of each blob vertex */
    double *x;              /* rest positions (mesh units, model space) */
    int *cells;             /* nc x 8 blob vertex indices */
    int *cell_grid;         /* grid cell index (i + gn0*(j + gn1*k) over cells) */
    double *cell_fill;      /* inside fraction of each cell */
    int *fb1, *fb2; double *fw;   /* frames (sorted joint indices, weight of b2) */
    /* sparse symmetric block pattern: for vertex i, neighbours nb[nbptr[i]..nbptr[i+1]) sorted, includes i */
    int *nbptr, *nb;
    double *M;              /* per pattern entry, kg */
    double *S;              /* per pattern entry, 9 doubles row-major, N/m (elastic) */
    double *T;              /* per pattern entry, twist scalar, N/m: retired, all 0 */
    double inside_volume;   /* m^3 of quadrature points inside */
    double mass;            /* kg, sum of all M entries */
    /* surface */
    int ns, nt;
    int *emb_cell; double *emb_t;   /* per mesh vertex, trilinear coords in [0,1]^3 */
    int *tri;
    /* description copy of physics */
    double h, alpha, beta, g[3], unit;
    int cg_def, cg_max;
    int precond;            /* SB_PRECOND_*: the blob's preconditioner (ICHOL section or none) */
    double bbox_diag;
    double min_jac;         /* smallest Jacobian determinant in kept cells / cell volume (1 = undistorted) */
    int n_uncondensed;      /* incompatible element: cells left trilinear (bubble stiffness not positive definite) */
    int quiet;
    /* per kept cell */
    double *Se;             /* nc x 24 x 24 elastic stiffness (N/m), row-major, dof = corner*3 + component;
                             * exactly the matrices summed into S */
    double *Me;             /* NULL, or nc x 8 x 8 per-cell mass (kg) filled by sb_integrate_frac (sb_level.c sets it) */
    int *cfb1, *cfb2; double *cfw;   /* frame at the cell centre (same rule as free vertices) */
    /* per lattice vertex */
    double *limit;          /* largest distance from the skinned position (mesh units), 0 = none */
    int *vseg;              /* bone (segment index) that captured a skeleton vertex; -1 free, -2 pinned */
    /* per bone (segment) */
    double *seg_r;          /* radius (mesh units) */
    double *seg_flesh;      /* measured flesh thickness (mesh units); automatic r = max(min(flesh/2, length/4), cell) */
    int *seg_auto;          /* 1 if the radius is automatic */
    int *seg_ncap;          /* lattice vertices it captures (chain + radius, before ownership) */
    int *seg_nv;            /* lattice vertices it moves (after nearest-bone ownership and pins) */
    int rest_modelled;      /* description 'rest_shape': 1 modelled, 0 sag */
    double mesh_volume;     /* m^3 (divergence theorem) */
    /* rigs (sb_rig.c, sb_rig_build; zero until then; freed by sb_rig_free, which sb_model_free calls) */
    int nctl, nrig;
    struct sb_control *ctl; /* joints in sorted order, TWIST resolved to an axis */
    struct sb_rig *rig;
    /* external forces (sb_force.c, sb_force_build): slots per step, share profiles
     * (fine, coarse 1..3, rigid; each sums to 1), profile of each free vertex (NULL: all 0) */
    int max_forces;
    int max_cons, max_cols, max_contacts; /* constraint section (0 0 0: none) */
    int nprof;
    double (*prof)[5];
    unsigned char *vprof;
    /* segment meshes (sb_segment.c, sb_segment_build) */
    int nsm;
    struct sb_segmesh *sm;
    sb_srcmap src;          /* 'gltf': the surface's glTF vertex order (sb_bake_file); nsrc 0 otherwise */
    /* self-collision near creases (sb_crease.c, sb_crease_build): crease = 1
     * writes the four CREASE sections */
    int crease;
    int cr_nD;              /* seed pairs */
    int *cr_pairs;          /* cr_nD x 2 surface vertices (i, j) */
    int cr_kv, cr_kt;       /* neighbourhood row widths */
    int cr_nq;              /* neighbourhood rows: the vertices the runtime can query (increasing owners) */
    int *cr_vnbr, *cr_tnbr; /* nq x kv (owner first), nq x kt; -1 = unused */
    int cr_list, cr_active;
    double cr_depth, cr_push; /* mesh units */
    double cr_exclude;        /* mesh units: seed pairs closer in the rest pose are not collisions */
    /* level of detail (sb_level.c, sb_level_bake): the finer level's blob and the maps the writer appends
     * (LEVEL_BLOB, LEVEL_UP, LEVEL_DOWN); lod_size 0: one level */
    const unsigned char *lod_blob;
    uint32_t lod_size, lod_nv1;   /* bytes; the finer level's lattice vertices */
    const uint16_t *lod_up, *lod_down; /* lod_nv1 x 4, nv x 4: {cell, t[3] Q15} */
    uint32_t lod_inst_bytes;      /* instance bytes for the larger level */
    const struct sb_cut *cut;     /* the cut level (sb_cut.c): CELLX/CELLXK written from it; extras at cut_nv0 + id */
    int cut_nv0;
    int ad_on, ad_max;            /* adaptation (ADAPT record, with lod_size): A_max */
    double ad_refine, ad_coarsen; /* mesh units */
    int det_on, det_max;          /* the cut level's details (DETAILS, DETAIL, CELLD, CELLDK from cut): A_max */
    double det_refine, det_coarsen; /* mesh units */
    int lshift_set, lshift;       /* lshift_set: the blob's length unit is at least 2^lshift (both levels share it) */
} sb_model;

int sb_build(const sb_desc *d, const sb_mesh *m, sb_model *o, int quiet);
void sb_model_free(sb_model *o);
int sb_pattern_find(const sb_model *o, int i, int j);  /* entry index or -1 */
/* trilinear shape functions at reference coords t (corner k at (k&1,k>>1&1,k>>2&1)) */
void sb_shape(const double t[3], double N[8], double dN[8][3]);
/* point of cell ci at reference coords t */
void sb_cell_point(const sb_model *o, int ci, const double t[3], double p[3]);
/* nearest bone segment to p (index into seg_child, -1 if none) and its distance */
int sb_nearest_seg(const sb_model *o, const double p[3], double *dist);
/* does a description region (joint indices in description order) contain p? */
int sb_region_has(const sb_model *o, const sb_region *r, const double p[3]);
/* frame bones and weight (as the model's cfb1/cfb2/cfw) at rest point p, mesh units */
void sb_frame_point(const sb_desc *d, const sb_model *o, const double p[3], int *fb1, int *fb2, double *fw);
/* integrals over the kept cells (sb_integrate.c); inbits: per grid cell, per quadrature point, inside flag */
int sb_integrate(const sb_desc *d, sb_model *o, const unsigned char *inbits);
/* the same with inside fractions: per grid cell fidx = -1 (outside), -2 (inside) or k >= 0:
 * frac[k * npt + q] is the inside fraction of quadrature point q's box */
int sb_integrate_frac(const sb_desc *d, sb_model *o, const double *frac, const int *fidx);
/* inside fractions of the quadrature boxes (subdivision n) of the grid cells with
 * slot[gc] >= 0, added into frac[slot * 8n^3 + q] (sb_lattice_fill.c; t0 >= 0 prints progress) */
void sb_box_fractions(const sb_model *o, const sb_mesh *m, const sb_inside *in, int n, const int *slot, double *frac, double t0);
/* checks of a built model (sinew-bake --check, tests): interior volume vs mesh
 * volume (= mass vs rho*V at uniform density), embedding error, null space of S */
typedef struct sb_check {
    double vol_ratio;       /* interior quadrature volume / mesh volume; want within 1% of 1 */
    double emb_err;         /* largest |embedded - mesh vertex| (Q15 coordinates) / bbox diagonal; want <= 1e-5 */
    double trans;           /* largest block-row sum of S / largest |S entry|; want <= 1e-12 */
    double rot;             /* largest S * (infinitesimal rotation) / (max|S| * max|x|); want <= 1e-11 */
    int ok;
} sb_check;
int sb_model_check(const sb_model *o, const sb_mesh *m, sb_check *r);   /* 0 if every check passes */

/* ---- rigs (sb_rig.c) ---- */
/* A rig integrated at the rest shape: Q_i = int_Omega phi_i f dV over the interior
 * (inside quadrature points only, as sb_integrate_frac weighs them, air 0), newtons,
 * rest model axes, at eta = 1; only free vertices with |Q_i| >= 1e-9 max kept. */
typedef struct sb_rig {
    sb_rigdef def;          /* the description's rig (tau defaulted) */
    double E_ref;           /* Pa: Young's modulus at the template centre */
    double L_ref;           /* mesh units: the template's size in the magnitude unit */
    double amp;             /* N/m^3 per unit of the template profile: s E_ref / (L_ref unit) */
    double lo[3], hi[3];    /* support bounding box, mesh units */
    int refine;             /* quadrature: each of the lattice rule's boxes split into refine^3 (edge <= feature/8) */
    int n;                  /* entries */
    int *vert;              /* n free vertex indices, strictly increasing */
    double *Q;              /* n x 3, newtons */
    double qmax;            /* largest |Q_i| over the entries, N */
    double total[3];        /* sum of Q_i over every lattice vertex (skeleton included) = int f dV, N */
} sb_rig;
/* resolve controls, integrate every rig of d over o's interior (m: the mesh o was built from) */
int sb_rig_build(const sb_desc *d, const sb_mesh *m, sb_model *o);
void sb_rig_free(sb_model *o);
/* force density (N/m^3, rest model axes) of rig r at p (mesh units); 0 outside its support */
void sb_rig_field(const sb_model *o, const sb_rig *r, const double p[3], double f[3]);
/* tau_a(gamma): piecewise linear through the samples, clamped at the ends */
double sb_rig_tau(const sb_rigdef *r, double gamma);
const char *sb_rig_tpl_name(int tpl);

/* ---- rig files (sb_rigfile.c; tools/DESCRIPTION.md "Rig files") ----
 * A fitted generalized force field (seed 003 eq. 13) keyed by lattice rest positions:
 * one fit per lattice (cell size), e.g. level 0 and level 1 of 'levels 2'. */
#define SB_RIGFILE_FITS 4
typedef struct sb_rigfit {
    double cell, origin[3]; /* lattice the keys lie on (mesh units) */
    int n;
    double *x;              /* n x 3 rest positions, mesh units */
    double *Q;              /* n x 3 forces at eta = 1, newtons, rest model axes */
    int line;               /* the file's line of its 'cell' */
} sb_rigfit;
typedef struct sb_rigfile {
    int mesh_nv;            /* identity of the character: mesh vertex count and sb_mesh_crc */
    uint32_t mesh_crc;
    int nfit;               /* 1 ('sinew-rig 1'), 1..SB_RIGFILE_FITS ('sinew-rig 2'), distinct cells */
    sb_rigfit fit[SB_RIGFILE_FITS];
} sb_rigfile;
/* CRC-32 of the mesh's vertex coordinates as little-endian IEEE doubles */
uint32_t sb_mesh_crc(const sb_mesh *m);
int sb_rigfile_read(const char *path, sb_rigfile *rf);
void sb_rigfile_free(sb_rigfile *rf);
/* the fit whose cell is cell (within 1e-9 of it), NULL if none */
const sb_rigfit *sb_rigfile_pick(const sb_rigfile *rf, double cell);
/* write Q (o->nf x 3: per free vertex, newtons, rest model axes; zero rows left out) for
 * model o baked from mesh m; comment lines (may hold newlines) go after the first line */
int sb_rigfile_write(const char *path, const sb_model *o, const sb_mesh *m, const double *Q, const char *comment);
/* the same for nfit models of one mesh (distinct cells: the levels of 'levels 2'), one fit
 * each ('sinew-rig 2' when nfit > 1; nfit 1 writes what sb_rigfile_write does) */
int sb_rigfile_write_fits(const char *path, int nfit, const sb_model *const *o, const sb_mesh *m, const double *const *Q, const char *comment);
/* the file's fit for o's cell, on o's free vertices: vert (o->nf ints) and Q (o->nf x 3) get the
 * nout non-zero entries, increasing vertex order; ndrop: entries on no free vertex (skeleton or
 * outside the lattice). level: the level of detail o is (for the message when no fit matches).
 * Errors: another mesh, no fit for this cell, keys off the grid, nothing left. */
int sb_rigfile_apply(const sb_rigfile *rf, const char *path, const sb_model *o, const sb_mesh *m, int level, int *vert, double *Q, int *nout, int *ndrop);

/* ---- external forces (sb_force.c) ---- */
/* share profiles from the description's 'force' lines, per free vertex */
int sb_force_build(const sb_desc *d, sb_model *o);
void sb_force_free(sb_model *o);

/* ---- segment meshes (sb_segment.c) ---- */
/* A built mesh: rest nodes evenly spaced (every segment seg_len long), moved
 * rigidly by 'shift', the mean offset of its surface-attached nodes to their
 * nearest vertices (one attachment: exactly onto it). */
typedef struct sb_segmesh {
    sb_segdef def;          /* the description's mesh (att owned by the description) */
    char path[1024];        /* the description, for file:line messages */
    int nodes;              /* finest level: chain side, sheet side^2 */
    int segs;               /* finest level segments */
    uint32_t segs_all, nodes_all;   /* over every level (sn_seg_counts) */
    double *x;              /* nodes x 3 rest positions, mesh units */
    double seg_len;         /* mesh units */
    double seg_mass;        /* kg per finest segment: mass / segs */
    double keep;            /* velocity kept per step, exp(-damping h) */
    double shift[3];        /* rigid move applied to the declared nodes, mesh units */
    int natt;               /* attachments, node strictly increasing */
    int *att_node, *att_kind, *att_target;   /* target: surface vertex or sorted joint index */
    double *att_dist;       /* SURFACE: node-to-vertex distance after the shift; JOINT: 0 */
} sb_segmesh;
/* chains and sheets from the description, attached to the built model */
int sb_segment_build(const sb_desc *d, const sb_mesh *m, sb_model *o);
void sb_segment_free(sb_model *o);
/* instance state bytes of o's segment meshes (SN_SEG_SEG_BYTES segs + SN_SEG_NODE_BYTES nodes) */
uint32_t sb_segment_state_bytes(const sb_model *o);
/* The frames' references (format 6.4, sb_frefs.c): refs (nf + nc, or NULL),
 * pairs (b1 << 8 | b2, or NULL); returns the distinct pairs' count. */
int sb_frame_refs(const sb_model *o, uint32_t *refs, uint16_t *pairs);
/* a frame entry's weight w in [0, 1] as FRAMES/CFRAMES store it (Q15, rounded; sb_blob.c) */
uint16_t sb_frame_w(double w);
/* SEGNODES and SEGATTACH counts of o's segment meshes */
void sb_segment_blob_counts(const sb_model *o, uint32_t *nodes, uint32_t *attach);
/* write the three segment sections at their offsets (blob bytes, rs: real size,
 * flavour SB_*, internal unit 2^len_shift mesh units, mass unit m0 kg); 0 or -1 (sb_fail) */
int sb_segment_blob_write(const sb_model *o, unsigned char *blob, const uint32_t *off, int flavour, int rs, int len_shift, double m0);

/* ---- self-collision near creases (sb_crease.c) ---- */
/* Neighbourhoods of the surface and the seed set D from slow motion to each
 * 'crease' pose with the double-precision model (seed 003 §3.4.1). Needs the
 * rest of the model built (it bakes a float64 blob of it). */
int sb_crease_build(const sb_desc *d, sb_model *o, int quiet);
void sb_crease_free(sb_model *o);
/* Penetration of point p into triangle (a, b, c) (counter-clockwise from
 * outside), as the runtime tests it: behind the plane by at most depth, the
 * projection inside the triangle. Returns 1 and *dist (signed, < 0) and the
 * corner 0..2 with the largest barycentric. */
int sb_crease_inside(const double p[3], const double a[3], const double b[3], const double c[3], double depth, double *dist, int *corner);

/* ---- blob (sb_blob.c) ---- */
enum { SB_FIXED = 0, SB_FLOAT = 1, SB_DOUBLE = 2 };
typedef struct sb_blob {
    unsigned char *bytes; size_t size;
    uint32_t sec_off[44], sec_size[44];   /* >= SN_SEC_COUNT */
    int len_shift, frac_S, frac_M, frac_P;
    int ichol_n;            /* ICHOL blocks (0: block Jacobi) */
    double ichol_max;       /* largest |U entry| */
    double m0;
    int *rig_frac;          /* per rig (fixed flavour): fractional bits of its RIG_FORCES; else 0 */
} sb_blob;
int sb_blob_make(const sb_model *o, int flavour, sb_blob *b);

/* IC(0) preconditioner (sb_ichol.c): A0 = (1+a1) M/m0 + (1+b1) h^2 S/m0 over
 * free vertices ~ (I + L^) D (I + L^)^T on the mass pattern. */
#define SB_PRECOND_ICHOL 0
#define SB_PRECOND_JACOBI 1
typedef struct sb_ichol_t {
    int n;          /* blocks: the free-free upper entries of the pattern, row order */
    double *U;      /* n x 9: U_ji = L^_ij^T, row-major */
    double *Dinv;   /* nF x 9: D_i^-1 */
    double maxU;    /* largest |entry| of U */
    int shifted;    /* pivots shifted at a breakdown */
} sb_ichol_t;
int sb_ichol(const sb_model *o, double m0, double a1, double b1, sb_ichol_t *f);
int sb_ichol_quant(const double *U, int bits, int m[9], int *frac);
void sb_ichol_free(sb_ichol_t *f);
void sb_blob_free(sb_blob *b);
int sb_write_file(const char *path, const unsigned char *p, size_t n);  /* temp + rename */
int sb_write_c_array(const char *path, const char *symbol, const unsigned char *p, size_t n);

/* ---- whole bake (sb_bake.c) ---- */
int sb_bake_file(const char *desc_path, int flavour, int quiet, sb_model *o, sb_blob *b);
/* level 1 of a 'levels 2' description alone, as sb_level_bake builds it (sb_level_desc,
 * sb_level_model): o its model (rigs included), b its blob without crease data (the
 * surface's, which the two-level blob shares from level 0). 0 or -1 (sb_error). */
int sb_bake_level1(const char *desc_path, int flavour, sb_model *o, sb_blob *b);
/* its description, mesh and model (rigs 0: without the description's rigs), for the
 * caller to free; 0, or -1 (sb_error) with nothing left allocated */
int sb_level1_load(const char *desc_path, int rigs, sb_desc *d, sb_mesh *m, sb_model *o);

#endif /* SB_H */
