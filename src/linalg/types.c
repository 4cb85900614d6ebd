/* ===== >>impl_linalg : sparse operators and preconditioned conjugate gradients ===== */

/* Contents: the padded layout and multigrid notes below; >>linalg_check (operator validation),
   >>linalg_object (creation, memory), >>linalg_grid (padded MAC-grid levels), >>linalg_kernels
   (stencil kernels), >>linalg_mg (V-cycle), >>linalg_ic (incomplete Cholesky), >>linalg_amg
   (algebraic multigrid for CSR matrices), >>linalg_setup
   (setup for stencils and CSR), >>linalg_solve (preconditioned conjugate gradients). */

/* Layout. A stencil is solved on padded arrays: one ghost cell on each side of every axis (none
   along z in 2D), so the kernels need no bounds tests. Cell (i, j, k) sits at
   (i + 1) + (j + 1) sy + (k + 1) sz (2D: no z term). Each level of the operator stores
     type[c]   fsdem_stencil_cell (ghosts: AIR where the boundary face is Dirichlet, else SOLID),
               plus FSDEM__NEAR_SOLID on fluid cells whose coarse-grid interpolation touches a
               solid cell;
     d[c]      the diagonal (0 off fluid cells), inv_d[c] its inverse (0 where d = 0);
     w[a][c]   the coupling across the face on the low side of c along axis a. While a level is
               built it holds the physical coefficient (0 next to a solid); once the next coarser
               level exists it is reduced to the matrix off-diagonal: kept only between two fluid
               cells. Then y = A x is d x - sum w x_nb with no masks, since x is 0 off fluid cells.

   Multigrid (>>linalg_mg). Coarse levels halve each axis longer than one cell ((n + 1) / 2; an
   axis of one cell is not coarsened), down to one cell or to a level with no fluid left. A coarse
   cell is AIR if any child is air (Dirichlet dominates, so the coarse problem never loses its
   free surface), else FLUID if any child is fluid, else SOLID. A coarse face coefficient is the
   sum of its fine sub-face coefficients divided by the coarsening ratio along its normal, and
   the extra diagonal is summed over the children: this is the finite-volume rediscretisation
   that matches R A P for smooth fields with P = cell-centred (bi/tri)linear interpolation and
   R = P^T. P leaves out coarse cells that are solid and renormalises the remaining weights
   (Neumann); air cells and Dirichlet ghosts contribute their value 0. The V-cycle smooths with
   red-black Gauss-Seidel, red then black before the coarse correction and black then red after,
   so the preconditioner is symmetric positive definite, as CG needs. */

#define FSDEM__MG_MAX_LEVELS 40
#define FSDEM__NEAR_SOLID 0x80
#define FSDEM__TYPE(t) ((t) & 3)

#ifdef FSDEM_USE_FLOAT
#define FSDEM__SYM_TOL 1e-4
#define FSDEM__DEFAULT_TOL 1e-5
#else
#define FSDEM__SYM_TOL 1e-10
#define FSDEM__DEFAULT_TOL 1e-8
#endif

typedef struct fsdem__level {
    int n[3], ratio[3];    /* interior cells per axis; coarsening ratio from the finer level */
    fsdem_real h[3];       /* cell size per axis in units of the finest cell */
    int sy, sz, count;     /* padded strides and cell count */
    int fluid;             /* fluid cells */
    unsigned char *type;
    fsdem_real *d, *inv_d, *w[3];
    fsdem_real *x, *b;     /* multigrid vectors (level 0 borrows the CG vectors) */
} fsdem__level;

enum { FSDEM__KIND_NONE = 0, FSDEM__KIND_STENCIL = 1, FSDEM__KIND_CSR = 2 };

typedef struct fsdem__amg fsdem__amg;
static void fsdem__amg_free(const fsdem_allocator *al, fsdem__amg *g);

struct fsdem_pcg {
    fsdem_pcg_desc desc;
    fsdem__status status;
    fsdem_allocator allocator;
    int kind;               /* FSDEM__KIND_* of the last successful setup */
    fsdem_precond precond;  /* resolved preconditioner */
    int length;             /* internal vector length (padded cells or rows) */
    int user_length;        /* length of the caller's vectors */
    int dim;
    fsdem_stencil stencil;  /* geometry and extra term of the last stencil setup */
    fsdem_csr csr;          /* matrix of the last CSR setup */
    void *arena;            /* every array below lives in this one block */
    size_t arena_bytes;
    fsdem_real *x, *r, *z, *p; /* CG vectors; z also holds A p */
    fsdem_real *ux, *uy;    /* caller-layout copies for the stencil's extra term */
    int levels;
    fsdem__level level[FSDEM__MG_MAX_LEVELS];
    fsdem_real *ic;         /* stencil IC/MIC: 1/sqrt(pivot); CSR Jacobi: 1/diagonal */
    fsdem_real *rowbuf;     /* multigrid: two rows of the finest level per worker */
    fsdem_real *restricted; /* multigrid, threaded: each fine row's residual restricted along x */
    double *dot_part;       /* a dot product's block sums (FSDEM__DOT_BLOCK) */
    int *progress;          /* multigrid, threaded: stages finished per slab of a level */
    int workers;            /* threads the per-worker buffers were carved for (at setup) */
    int ns_components, ns_cells; /* null space: fluid regions without a Dirichlet anchor */
    int *ns_cell;           /* their cells, each region's first cell stored as -(c + 1) */
    unsigned char *mark;
    int *u_start, *u_col;   /* CSR IC/MIC: upper factor U (M = U^T U), diagonal first per row */
    fsdem_real *u_val;
    int *u_pos;             /* CSR IC/MIC workspace: column -> position in a row of U, or -1 */
    fsdem__amg *amg;        /* CSR AMG hierarchy (>>linalg_amg), allocated apart from the arena */
};
