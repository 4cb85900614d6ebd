/* ===== >>impl_pic : PIC/FLIP solver ===== */

/* Contents: >>pic_types (the object), >>pic_desc (defaults, validation, creation), >>pic_geometry
   (obstacles, cut-cell face fractions), >>pic_particles (storage, seeding), >>pic_transfer (P2G,
   G2P), >>pic_cells (effective faces, fluid fraction, level set, cell types), >>pic_extrapolate,
   >>pic_viscosity, >>pic_projection (pressure and density projection), >>pic_advection,
   >>pic_reseed, >>pic_step (time stepping), >>pic_views (fields, coupling, sampling, statistics),
   >>pic_output. */

#include <time.h>

/* ---- >>pic_types : the solver object ---- */

typedef struct fsdem__pic_obst {
    fsdem_pic_obstacle d;
    fsdem_vec3 *verts; /* POLYGON: owned copy */
    fsdem_vec3 box_lo, box_hi; /* bounding box (m), inflated by two cells */
} fsdem__pic_obst;

struct fsdem_pic {
    fsdem_pic_desc desc;
    fsdem__status status;
    fsdem_claims claims;             /* who writes its coupling arrays (>>core_claims) */
    fsdem_allocator allocator;
    int dim, n[3], ncell;
    int fn[3][3];      /* face grid sizes: fn[a][b] = n[b] + (a == b) */
    int nface[3];      /* faces per axis (0 above dim) */
    int cstep[3];      /* cell index stride per axis */
    int fstep[3][3];   /* face index stride of axis-a faces along b */
    fsdem_real dx, inv_dx;
    fsdem_vec3 lo, hi; /* grid box */
    fsdem__mac mac;    /* the layout of the grid below (its n, fn, fstep, dx, lo, hi mirror it for the loops) */
    double time;
    fsdem_real dt_last;
    long long steps;
    unsigned long long rng;
    int ppc, sub;      /* particles per cell; seeds per axis when ppc = sub^dim, else 0 */
    fsdem_real pvol;   /* m^dim per particle */
    fsdem_real gmag;   /* |g| */

    /* particles, structure of arrays */
    int np, pcap;
    fsdem_vec3 *px, *pv, *ptmp;
    fsdem_vec3 *pc[3]; /* APIC: gradient of velocity component a (1/s); NULL otherwise */
    int *pcell, *pidx;
    unsigned char *pflag;

    /* faces, per axis */
    fsdem_real *u[3], *uold[3], *wsum[3], *ftmp[3];
    fsdem_real *sopen[3], *svel[3];           /* static obstacles: open fraction, solid velocity */
    fsdem_real *copen[3], *cvel[3], *cacc[3]; /* coupler arrays */
    fsdem_real *shear[3];                     /* viscous force on closed faces (viscosity > 0) */
    fsdem_real *cvstart[3];                   /* coupler: moving solids' velocity at the start of the step */
    fsdem_real *E[3], *us[3];                 /* effective open fraction and solid velocity */
    fsdem_real *fpor[3], *Ef[3];              /* face porosity (mean of its cells') and E fpor */
    unsigned char *fvalid[3], *fvalid2[3];
    int *fqueue; /* breadth-first front of the extrapolation, max(nface) entries */
    int fqueue_size;

    /* cells */
    fsdem_real *frac, *fref, *phi, *pres, *rhs, *diag, *ctmp, *crhs;
    fsdem_real *cref; /* coupler's factor on fref (moving solids) */
    fsdem_real *cpor; /* coupler's target fluid volume fraction (granules, seed 004 Eq. 6) */
    unsigned char *ctype, *cnear, *csolid;
    int *cstart; /* ncell + 1 */

    /* implicit viscosity: per axis a the face grid is a stencil grid of its own */
    fsdem_real *vface[3][3]; /* coefficients 1 inside, 0 on the face grid's boundary */
    unsigned char *vcell[3];

    fsdem__pic_obst *obst;
    int obst_count, obst_capacity;

    fsdem_pcg *pcg_p;
    fsdem_pcg *pcg_v[3];
    fsdem_pic_coupling coupling;     /* the coupler's arrays (fsdem_pic_get_coupling) */
    fsdem_operator_fn pressure_extra; /* fsdem_pic_set_pressure_extra */
    fsdem_pic_response_fn pressure_response;
    void *pressure_extra_user;
    fsdem__gauges gauges;

    /* diagnostics */
    int cells_fresh; /* frac/phi hold the current particle positions (set at the end of a step) */
    int fluid_cells, p_iters, v_iters, d_iters;
    fsdem_real p_res, max_div, div_before, umax_part;
    long long reseeded, removed, refused, moved;
    double sec_total, sec_pressure, sec_density;
    size_t bytes;
};

/* The arrays of fsdem_pic_arrays, by bit (>>core_claims). */
static const char *const fsdem__pic_claimable[3] = {"moving solids", "porosity", "acceleration"};
