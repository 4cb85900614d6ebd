/* ===== >>linalg : sparse operators and preconditioned conjugate gradients ===== */

/* One conjugate-gradient solver for every symmetric positive definite system in the library: the
   PIC/FLIP pressure projection and implicit viscosity (MAC-grid stencils) and the MPS pressure
   Poisson equation (general sparse matrices). Operators come in two forms:

   - fsdem_csr: a general sparse matrix in compressed rows, owned by the caller.
   - fsdem_stencil: a matrix-free 5-point (2D) / 7-point (3D) cell-centred operator on a MAC grid,
     with one coefficient per face and a type per cell, built for pressure equations:

         (A p)_c = sum over faces f of c:  w_f (p_c - p_nb(f))  +  diag_c p_c      for fluid cells c

     where p_nb = 0 for an air neighbour (free surface, Dirichlet), a face next to a solid cell adds
     nothing (Neumann), and outside the grid is a Dirichlet p = 0 wherever the boundary face's
     coefficient is > 0 (give it 0 for a wall). A face coefficient is typically an open fraction
     times dt/(rho dx^2): the cut-cell weight E/dx of seed 000 Eq. 5 (E: the unblocked length of the
     cell edge), or the face volume fraction beta of seed 004 Eq. 11 and 63; any w >= 0 works. `diag` carries what the faces do not: the ghost-fluid free surface (a fluid cell
     whose air neighbour lies a fraction theta of the way to the interface adds w (1/theta - 1)),
     or the identity term of an implicit viscosity solve. Keep pressure equations in their
     conservative, symmetric form: seed 004 Eq. 12 divides each row by alpha_f', which would make
     the matrix unsymmetric; solve div(alpha_f' grad p) = alpha_f' (right-hand side of Eq. 12)
     instead. A Neumann face whose flux is moved to the right-hand side (the push-out condition of
     seed 004 App. B, the solid velocity of seed 000 Eq. 5) is a face with coefficient 0.

   A fsdem_pcg object is set up once per operator (this is where all memory is allocated and the
   preconditioner is built) and then solves any number of right-hand sides without allocating.
   Preconditioners: Jacobi, incomplete Cholesky IC(0) and modified IC(0) (both on stencils and on
   CSR), for stencils a geometric multigrid V-cycle (MGPCG), and for CSR matrices smoothed-
   aggregation algebraic multigrid (AMG, built from the matrix alone: >>linalg_amg in the
   implementation); with either multigrid the iteration count stays nearly constant as the problem
   is refined (2D Poisson, 64^2 to 512^2: 7 AMG iterations to 1e-8 at every size, MIC(0) 34 to
   171). A solve stops when ||b - A x||_2 <= tolerance ||b||_2 (checked on
   the true residual). Not converging, a non-positive curvature p.Ap <= 0 (the operator is not
   positive definite) and NaN are result codes with a message, never a silent wrong answer.

   Stencil vectors (x, b) hold one value per cell, x fastest, then y, then z: cell (i, j, k) is at
   (k n[1] + j) n[0] + i. Face arrays use the MAC layout of the velocity components: face[0] holds
   (n[0]+1) n[1] n[2] x-faces, the face between cells i-1 and i at (k n[1] + j)(n[0]+1) + i; face[1]
   n[0] (n[1]+1) n[2] y-faces at (k (n[1]+1) + j) n[0] + i; face[2] n[0] n[1] (n[2]+1) z-faces at
   (k n[1] + j) n[0] + i. */

typedef enum fsdem_stencil_cell {
    FSDEM_STENCIL_CELL_FLUID = 0, /* an unknown */
    FSDEM_STENCIL_CELL_AIR = 1,   /* Dirichlet p = 0 (free surface); the solution there is 0 */
    FSDEM_STENCIL_CELL_SOLID = 2  /* excluded; faces towards it are Neumann; the solution there is 0 */
} fsdem_stencil_cell;

/* Optional symmetric positive semi-definite term added to a stencil operator, y += E x, on vectors
   in the stencil layout (e.g. the implicit solid coupling dt J^T M^-1 J of seed 000 Eq. 6). It must
   add only to fluid cells. Preconditioners do not see it. */
typedef void (*fsdem_operator_fn)(void *user, const fsdem_real *x, fsdem_real *y);

/* A MAC-grid stencil operator. A view of caller-owned arrays: fsdem_pcg_setup_stencil copies what
   it needs, so the arrays may change or go away after setup (call setup again after a change).
   Zero-initialise it and set dim and n: NULL arrays give the plain -h^2 Laplacian of the unit box
   with Dirichlet walls (every cell fluid, every face 1). */
typedef struct fsdem_stencil {
    int dim;                      /* 2 or 3 */
    int n[3];                     /* cells per axis, >= 1; n[2] is ignored (taken as 1) in 2D */
    const unsigned char *cell;    /* n[0] n[1] n[2] fsdem_stencil_cell values; NULL: all fluid */
    const fsdem_real *face[3];    /* face coefficients >= 0 (layout above); NULL: all 1. Only faces */
                                  /*    with a fluid cell on a side are read. face[2] unused in 2D */
    const fsdem_real *diag;       /* extra diagonal >= 0 per cell (fluid cells read); NULL: 0 */
    fsdem_operator_fn extra;      /* optional extra term (see fsdem_operator_fn); NULL: none */
    void *extra_user;             /* passed to `extra`; must stay valid while the pcg uses it */
} fsdem_stencil;

/* A square sparse matrix in compressed sparse rows, stored in full (both triangles), columns
   strictly ascending in each row, the diagonal present. A view of caller-owned arrays, which must
   stay valid and unchanged from fsdem_pcg_setup_csr until the next setup or destroy. */
typedef struct fsdem_csr {
    int rows;                 /* number of rows = columns, >= 1 */
    const int *row_start;     /* rows + 1 offsets into col/val; row_start[0] = 0 */
    const int *col;           /* column of each entry, 0-based */
    const fsdem_real *val;    /* value of each entry */
} fsdem_csr;

typedef enum fsdem_precond {
    FSDEM_PRECOND_AUTO = 0,   /* multigrid for a stencil, MIC(0) for a CSR matrix */
    FSDEM_PRECOND_NONE = 1,   /* plain conjugate gradients */
    FSDEM_PRECOND_JACOBI = 2, /* diagonal scaling */
    FSDEM_PRECOND_IC0 = 3,    /* incomplete Cholesky, no fill */
    FSDEM_PRECOND_MIC0 = 4,   /* modified incomplete Cholesky (row sums kept, times mic_tau) */
    FSDEM_PRECOND_MG = 5,     /* geometric multigrid V-cycle on the MAC grid; stencils only */
    FSDEM_PRECOND_AMG = 6     /* smoothed-aggregation algebraic multigrid V-cycle; CSR matrices only */
} fsdem_precond;

typedef struct fsdem_pcg_desc {
    fsdem_precond preconditioner; /* default FSDEM_PRECOND_AUTO */
    fsdem_real tolerance;         /* -; stop at ||r||_2 <= tolerance ||b||_2; default 1e-8 (1e-5 float) */
    int max_iterations;           /* > 0; default 1000 */
    fsdem_real mic_tau;           /* -; MIC(0) share of the dropped fill moved to the diagonal, */
                                  /*    in [0, 1]; default 0.97 */
    fsdem_real ic_safety;         /* -; IC(0)/MIC(0) pivot floor: a pivot below ic_safety times the */
                                  /*    matrix diagonal is replaced by the diagonal; default 0.25 */
    int mg_sweeps;                /* >= 1; red-black Gauss-Seidel sweeps before and after each */
                                  /*    coarse-grid correction (AMG: forward before, backward */
                                  /*    after); default 2 */
    fsdem_real amg_strength;      /* -; AMG strength of connection theta, in (0, 1): j is a strong */
                                  /*    neighbour of i when |a_ij| >= theta max_k!=i |a_ik|; */
                                  /*    default 0.25 */
    fsdem_allocator allocator;    /* default: FSDEM_MALLOC/FSDEM_FREE */
    fsdem_log_fn log;             /* optional; default NULL */
    void *log_user;
} fsdem_pcg_desc;

/* What a solve did. */
typedef struct fsdem_pcg_info {
    int iterations;             /* CG iterations taken */
    fsdem_real residual;        /* -; final ||b - A x||_2 / ||b||_2 (true residual, recomputed) */
    fsdem_real rhs_norm;        /* ||b||_2 after the null-space projection below */
    int nullspace_components;   /* stencil only: fluid regions with no Dirichlet cell, face or diag */
                                /*    (a closed tank full of water). Their p is fixed up to a */
                                /*    constant: b's mean there is removed and x's mean set to 0 */
    fsdem_real incompatibility; /* -; ||removed part of b||_2 / ||b||_2 (0 without such regions) */
    int levels;                 /* multigrid levels (1 for other preconditioners) */
    size_t memory_bytes;        /* bytes held by the pcg object */
} fsdem_pcg_info;

typedef struct fsdem_pcg fsdem_pcg;

/* Defaults (see the field comments). */
FSDEM_API fsdem_pcg_desc fsdem_pcg_desc_default(void);
/* Checks a desc without creating anything; the reason, naming the field, goes to `message` (may be
   NULL). Returns FSDEM_OK or FSDEM_ERR_INVALID_ARG. */
FSDEM_API fsdem_result fsdem_pcg_desc_check(const fsdem_pcg_desc *desc, char *message, size_t message_size);
/* Creates a solver; nothing size-dependent is allocated until a setup call. *out is NULL on
   failure. Errors: FSDEM_ERR_INVALID_ARG (the reason goes to desc->log), FSDEM_ERR_OUT_OF_MEMORY.
   Destroy with fsdem_pcg_destroy. */
FSDEM_API fsdem_result fsdem_pcg_create(const fsdem_pcg_desc *desc, fsdem_pcg **out);
FSDEM_API void fsdem_pcg_destroy(fsdem_pcg *pcg);
/* Message of the last failed call on this object ("" after success). Valid until the next call. */
FSDEM_API const char *fsdem_pcg_last_error(const fsdem_pcg *pcg);
/* Changes the stopping rule of later solves (tolerance > 0, max_iterations > 0). */
FSDEM_API fsdem_result fsdem_pcg_set_tolerance(fsdem_pcg *pcg, fsdem_real tolerance, int max_iterations);

/* Sets up for a stencil operator: validates it, copies its coefficients, (re)allocates the
   workspace when it grew and builds the preconditioner. Call again whenever the stencil changes;
   memory is reused when the grid does not grow. Errors: FSDEM_ERR_INVALID_ARG (dim, a size < 1, a
   bad cell type, a negative or non-finite coefficient; the message names the cell or face; the
   previous setup stays usable), FSDEM_ERR_OUT_OF_MEMORY (the allocator failed, or the grid has
   more than about 2^30 cells; the previous setup stays usable). */
FSDEM_API fsdem_result fsdem_pcg_setup_stencil(fsdem_pcg *pcg, const fsdem_stencil *stencil);
/* Sets up for a CSR matrix (kept by reference, see fsdem_csr): validates it (sizes, indices, sorted
   columns, finite values, a positive diagonal, symmetry to a relative 1e-10 (1e-4 in float)),
   allocates the workspace and builds the preconditioner (FSDEM_PRECOND_MG is refused; AMG builds
   its hierarchy here, which costs about one to two solves).
   Errors: FSDEM_ERR_INVALID_ARG (message names the row and entry), FSDEM_ERR_OUT_OF_MEMORY; after
   either the previous setup stays usable. */
FSDEM_API fsdem_result fsdem_pcg_setup_csr(fsdem_pcg *pcg, const fsdem_csr *matrix);

/* Solves A x = b for the operator of the last setup. `x` (length: rows, or cells of the stencil)
   holds the initial guess on entry (zeros are fine) and the solution on return; for a stencil it is
   0 in air and solid cells. `b` has the same length (its air and solid entries are ignored). `info`
   may be NULL. Allocates nothing. Errors: FSDEM_ERR_NOT_CONVERGED (x holds the last iterate and
   info the residual reached), FSDEM_ERR_NAN (b or x holds NaN/Inf, or the iteration produced it;
   x is then unchanged), FSDEM_ERR_INVALID_ARG (no setup, NULL vectors, or the operator or
   preconditioner is not positive definite: p.Ap <= 0 or r.z <= 0; x holds the last iterate). */
FSDEM_API fsdem_result fsdem_pcg_solve(fsdem_pcg *pcg, const fsdem_real *b, fsdem_real *x,
                                       fsdem_pcg_info *info);

/* Checks a stencil without setting anything up; the reason goes to `message` (may be NULL).
   Returns FSDEM_OK or FSDEM_ERR_INVALID_ARG. */
FSDEM_API fsdem_result fsdem_stencil_check(const fsdem_stencil *stencil, char *message,
                                           size_t message_size);
/* y = A x for a stencil (including `extra`), on vectors in the stencil layout; y is 0 in air and
   solid cells. No validation: check the stencil first. x and y must not overlap. */
FSDEM_API void fsdem_stencil_apply(const fsdem_stencil *stencil, const fsdem_real *x, fsdem_real *y);
/* Checks a CSR matrix as fsdem_pcg_setup_csr does; the reason goes to `message` (may be NULL).
   Returns FSDEM_OK or FSDEM_ERR_INVALID_ARG. */
FSDEM_API fsdem_result fsdem_csr_check(const fsdem_csr *matrix, char *message, size_t message_size);
/* y = A x for a CSR matrix. No validation. x and y must not overlap. */
FSDEM_API void fsdem_csr_apply(const fsdem_csr *matrix, const fsdem_real *x, fsdem_real *y);
