/* ===== >>impl_mps : MPS solver ===================================================================== */

/* Contents: the object below; >>mps_desc (defaults, validation, lattice constants, creation),
   >>mps_particles (storage, lattice fills, walls, obstacles), >>mps_open (inflow and outflow
   planes), >>mps_neighbours (cell-list search
   into sorted neighbour rows), >>mps_operators (number density, gradient, divergence, Laplacian,
   surface, the solids' ghost velocities), >>mps_explicit (the weakly compressible scheme), >>mps_step (predictor, pressure equation, corrector, collisions, time stepping),
   >>mps_views (views, statistics), >>mps_probes (pressure, water level, obstacle force, gauges). */

/* A box obstacle (fsdem_mps_add_box_obstacle) and the force of the fluid on it in the last step. */
typedef struct fsdem__mps_obst {
    fsdem_vec3 lo, hi;
    fsdem_vec3 force; /* N (N/m in 2D) */
} fsdem__mps_obst;

struct fsdem_mps {
    fsdem_mps_desc desc;
    fsdem__status status;
    fsdem_claims claims;             /* who writes its coupling arrays (>>core_claims) */
    fsdem_allocator allocator;
    size_t bytes;                 /* held, besides the pcg */
    int dim;
    fsdem_real r0, re, re_lap;    /* spacing, radius of Eq. 7-9 and of the Laplacian (Eq. 10-11) */
    fsdem_real n0, lambda, f0;    /* lattice constants (>>mps_desc): lambda with re_lap */
    fsdem_real n0_lap;            /* sum of the Laplacian's weights on the full lattice */
    fsdem_real re_x, n0_x;        /* support and lattice sum of the explicit scheme's weight */
    int layers;                   /* WALL + DUMMY layers of a solid: ceil(re/r0) */
    fsdem__periods periods;       /* the periodic axes (desc.periodic) */
    /* particles, structure of arrays, `cap` allocated */
    int n, cap;
    fsdem_vec3 *x, *v, *us;       /* position, velocity, predicted velocity u* */
    fsdem_vec3 *shift;            /* particle shift of the step (desc.shifting) */
    fsdem_real *p, *eps, *nd;     /* pressure, porosity, number density */
    fsdem_real *rho;              /* density carried in the explicit scheme (kg/m^3; 0: not set yet) */
    fsdem_real c0;                /* the explicit scheme's sound speed once set (m/s; 0: not yet) */
    fsdem_vec3 *fext;             /* external force of a coupler (N; N/m in 2D), FLUID particles */
    fsdem_vec3 *gradp;            /* pressure gradient of the last corrector (Pa/m), FLUID particles */
    fsdem_vec3 *uvisc;            /* velocity in the viscous term: u of FLUID, the ghost of solids */
    fsdem_real *ghost_weight;     /* scratch of the ghost velocities: sum of the fluid weights */
    int external;                 /* fext may be nonzero (fsdem_mps_get_coupling handed it out) */
    fsdem_real *div, *b, *sol;    /* divergence of u*, right-hand side and solution (by unknown) */
    unsigned char *kind, *surf;
    int *body;                    /* the obstacle a WALL or DUMMY particle belongs to, or -1 */
    int *unknown;                 /* row of each particle in the pressure equation, or -1 */
    int *row_particle;            /* particle of each row */
    int counts[3];                /* particles per kind */
    /* neighbours (>>mps_neighbours): rows of every non-DUMMY particle (DUMMY rows are empty), columns ascending */
    fsdem_cellgrid grid;
    int *cell_wall, *cell_dummy;  /* per cell: where its WALL and its DUMMY items start */
    int *pairs, pair_cap;         /* 2 per pair found by the cell scan */
    int *solid_pairs, solid_pair_cap, solid_pair_n; /* the WALL-WALL and WALL-DUMMY pairs */
    int solid_pairs_of;           /* WALL + DUMMY particles when they were found (-1: never) */
    int *nb_start;                /* n + 1 */
    int *tmp_start, *cursor;      /* n + 1 each: rows by column and fill cursors of the build */
    int *nb, *tmp_nb, nb_cap;     /* neighbour indices */
    fsdem_real *nbw;              /* w_ij (Eq. 6; 0 beyond re) */
    fsdem_real *nbl;              /* w_ij of the Laplacian (Eq. 6 with re_laplacian; 0 beyond it) */
    fsdem_real *nbx;              /* the explicit scheme's pair weight over |r_ij|^2 (0 with the seed's) */
    int *wall_entries, wall_entry_cap, wall_entry_n; /* (row, entry) of every WALL or DUMMY neighbour in a
                                                        FLUID row, in row order (built with the rows) */
    fsdem_real skin;              /* the rows hold the pairs within re + skin (Verlet lists) */
    fsdem_vec3 *x_built;          /* positions the rows were built at */
    int rows_valid;               /* 0: particles were added, removed or restored since */
    long long pair_count;
    /* pressure matrix */
    int *a_start, *a_col, a_cap;
    fsdem_real *a_val;
    int rows;
    int closed;                   /* the last matrix had no surface neighbour (singular: see assembly) */
    fsdem_pcg *pcg;
    /* obstacles */
    fsdem__mps_obst *obst;
    int obst_n, obst_cap;
    /* open boundaries (>>mps_open) */
    fsdem_mps_inflow_desc *inflows;
    int inflow_n, inflow_cap;
    fsdem_mps_outflow_desc *outflows;
    int outflow_n, outflow_cap;
    int *inlet;                   /* the inflow whose buffer holds each particle, or -1 */
    int buffered;                 /* particles in inflow buffers */
    long long inflow_total, outflow_total;
    fsdem__gauges gauges;
    /* time and statistics */
    double time;
    long long steps, iters_total;
    fsdem_real dt_last, residual;
    int iters, surface_count;
    double sec_total, sec_pressure, sec_search, sec_assembly, sec_solve;
    long long candidates;         /* pairs the last cell scan examined */
};

/* The arrays of fsdem_mps_arrays, by bit (>>core_claims). */
static const char *const fsdem__mps_claimable[2] = {"forces", "porosity"};
