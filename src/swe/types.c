/* ===== >>impl_swe : shallow-water solver ========================================================== */

/* Contents: the scheme below and the object; >>swe_desc (defaults, validation), >>swe_object
   (creation, series, state, coupling), >>swe_sources (boundaries, friction, rain, blocked cells,
   point sources), >>swe_riemann (face fluxes), >>swe_row (reconstruction,
   predictor and x faces of a row), >>swe_step (y faces, repair, stable dt, stepping), >>swe_diag
   (diagnostics, output, gauges, bed SDF). */

/* Scheme (one step of dt, >>swe_row and >>swe_step):
     1. MUSCL reconstruction of eta, h, u, v per cell with the limiter (slopes per cell width); z_b at
        a face is eta_face - h_face, so the bed is never reconstructed on its own. Ghost cells mirror
        the cell at a wall; at other sides they copy h, u, v and extrapolate the bed linearly.
     2. Hancock predictor: each cell's face values are advanced by dt/2 with the flux difference of
        its own faces plus sources (the pressure/bed-slope pair in the form g h (eta_E - eta_W), which
        vanishes for a flat surface over any bed) and half a step of friction. Skipped in a cell
        where it would make a face depth negative (counted in stats.predictor_fallbacks).
     3. Faces: non-negative depth reconstruction with Liang's local bed modification,
            z_f = max(z_L, z_R), m = min(eta_L, eta_R);
            if z_f <= m: h*_s = eta_s - z_f, eta*_s = eta_s                      (plain)
            else:        h*_s = max(0, eta_s - z_f), eta*_s = h*_s + m, z_f -> m (dz = z_f - m)
        then HLL with the two-rarefaction wave speeds, or, when one side is dry, the exact Godunov
        flux of the rarefaction into dry bed (sharper wet fronts than HLL's estimate).
     4. Update. Mass uses the single face flux, so volume is conserved to rounding. Normal momentum
        uses the algebraically identical "side" form of the pre-balanced scheme (seed 003 Eq. 2 with
        the source -g eta_bar dz_b/dx of Liang and Marche 2009): the face flux seen from side s is
            F = A_s + g h*_s^2/2 + D_s,  D_L = s_L (s_R dU - dF)/(s_R - s_L),  D_R = s_R (s_L dU - dF)/(s_R - s_L)
        (A = advective part), and the cell's pressure flux difference plus bed-slope source combine to
            -(g/2) (h*_E + h*_W) (eta*_E - eta*_W) / dx,
        which is exactly zero when the cell's own face surfaces are equal: a lake at rest stays at rest
        bit for bit, also against dry islands (there eta*_s = m = the lake's surface).
     5. Point sources, rain, momentum source S_p (explicit), eddy viscosity (explicit, time n), Manning
        friction (backward Euler, exact: |q| = 2|q*| / (1 + sqrt(1 + 4 dt C |q*|)), C = g n^2 / h^(7/3)),
        which never reverses the flow, is stable at any depth and keeps uniform flow at normal depth.
     6. Depths stay non-negative: TVD reconstruction, the predictor fallback, and a time step that also
        bounds the velocity gained within the step (fsdem_swe_stable_dt). Should a depth still come out
        negative, the deficit is taken from the wet neighbours (stats.clipped_volume counts any part
        they cannot give; zero in every test and validation case).
   Thin layers: cells shallower than dry_depth carry no momentum; face depths below 1e-9 dry_depth
   carry no flux and unit discharges below 1e-100 m^2/s are set to zero, which stops the scheme's
   geometrically decaying leaks ahead of fronts and waves before they become subnormal numbers.
   Sweeps: rows are processed bottom to top with ring buffers of three rows of primitive values and two
   rows of predicted face states, so each state array is read once and written once per step; the
   row kernel is specialised per limiter. With threads, each thread sweeps its own band of rows
   (fsdem__swe_sweep), bit for bit the single sweep. */

/* Work data of one cell of a row in flight (2D): the predicted states at its north and south faces
   and its increments from the x faces. Kept together so the y-face sweep streams one array. */
typedef struct fsdem__swe_rowcell {
    fsdem_real n[4];   /* north face: eta, h, v (normal), u (tangential) */
    fsdem_real s[4];   /* south face */
    fsdem_real acc[3]; /* eta, uh, vh increments from the x faces (and viscosity) */
    fsdem_real pad;
} fsdem__swe_rowcell;

/* South-face fluxes of a cell, kept until its north face is computed on the next row. */
typedef struct fsdem__swe_sface {
    fsdem_real mass, a, t, h, e, pad;
} fsdem__swe_sface;

/* What a step finds, per band of rows (maxima over the wet cells, counts, the first non-finite cell). */
typedef struct fsdem__swe_tally {
    fsdem_real wave, speed2, hmax, accel;
    int wet, negative, bad;
    long long fallbacks;
} fsdem__swe_tally;

/* The work rows of one band of rows (>>swe_step): the ring of primitive rows, the predicted face
   states of the last two rows, the south-face fluxes, and (2D) a copy of the state rows beside the
   band, taken before any band writes its own rows. */
typedef struct fsdem__swe_work {
    int slots;                /* primitive row slots: 3 in 2D, 1 in 1D */
    int nx;
    fsdem_real *prim;         /* slots x 4 x (nx + 2): eta, h, u, v with one ghost cell at each end */
    fsdem__swe_rowcell *rows; /* 2D: 2 x nx, ring of the last two rows */
    fsdem__swe_sface *south;  /* 2D: nx south-face data of the row in flight */
    fsdem_real *halo;         /* 2D: 4 rows x (eta, qx, qy) x nx */
    int halo_row[4];          /* the state row each halo row holds (-1: none) */
    fsdem__swe_tally tally;   /* the band's results of the step in flight */
} fsdem__swe_work;

/* The row kernel is instantiated once per limiter and dimension (FSDEM__FORCE_INLINE) so that its
   inner loop has neither a limiter switch nor 2D branches in 1D. */

/* m^2/s: unit discharges below this are set to zero (no physical meaning; see fsdem__swe_finish) */
#define FSDEM__SWE_QTINY ((fsdem_real)(sizeof(fsdem_real) < sizeof(double) ? 1e-12 : 1e-100))

typedef struct fsdem__swe_bnd {
    fsdem_swe_bc type;
    fsdem_real value;
    fsdem_real *t, *v; /* owned series, n points */
    int n;
} fsdem__swe_bnd;

typedef struct fsdem__swe_src {
    fsdem_real discharge;
    fsdem_real *t, *v;
    int n, cell, id, active;
} fsdem__swe_src;

struct fsdem_swe {
    fsdem_swe_desc desc; /* bed, depth and the boundary series pointers are not kept */
    fsdem__status status;
    fsdem_claims claims;             /* who writes its coupling arrays (>>core_claims) */
    fsdem_allocator allocator;
    int dim, nx, ny, n;
    fsdem_real dx, dy, area, g, tiny;
    double time;
    fsdem_real dt_last;
    long long steps, fallbacks;
    fsdem_real max_wave;  /* 1/s, max over wet cells of (|u|+c)/dx + (|v|+c)/dy of the current state */
    fsdem_real max_accel; /* 1/s^2, max over wet cells of g (|deta/dx|/dx + |deta/dy|/dy), minmod slopes */
    fsdem_real max_speed, max_depth;
    int wet_cells;
    fsdem_real vol_boundary, vol_source, vol_clipped;
    fsdem_real rain;

    /* state, structure of arrays */
    fsdem_real *block; /* one allocation holding the state and the work rows */
    size_t block_bytes;
    fsdem_real *eta, *qx, *qy, *bed, *sx, *sy;
    fsdem_real *manning; /* NULL: uniform desc.manning */
    unsigned char *blocked; /* n flags (1: solid cell), NULL when no cell is blocked */
    int blocked_count;
    int sources_used;

    /* work rows */
    fsdem__swe_work *work; /* one per band of rows a thread sweeps (>>swe_step) */
    int workers;           /* bands the work rows were allocated for (threads at creation) */
    fsdem_real *bterm;     /* the step's boundary-face volumes, in the order one sweep meets them */

    fsdem__swe_bnd bnd[4];
    fsdem_real bvalue[4]; /* boundary values at the middle of the step in flight */

    fsdem__swe_src *src;
    int src_count, src_capacity, src_next_id;

    fsdem_real *gauge; /* x, y of each gauge */
    int gauge_count, gauge_capacity;
    fsdem__series gauges; /* the gauge file, h, eta, u, v per gauge */
};

/* The arrays of fsdem_swe_arrays, by bit (>>core_claims). */
static const char *const fsdem__swe_claimable[1] = {"momentum sources"};
