/* ===== >>swe : shallow-water equations (seed 003) ================================================= */

/* Depth-averaged shallow-water flow on a uniform Cartesian grid, 1D (x) or 2D (x-y), solved in the
   pre-balanced form of seed 003 Eq. 1-2 (Liang and Borthwick 2009; Liang and Marche 2009):
       q = [eta, uh, vh],  f = [uh, u^2 h + g (eta^2 - 2 eta z_b)/2, uvh],
       s = [0, -tau_bx/rho - g eta dz_b/dx + S_vx + S_px, ... y likewise]
   eta is the surface elevation, z_b the bed, h = eta - z_b the depth. Godunov-type finite volumes with
   the HLL Riemann solver; second order in space and time by MUSCL-Hancock with a slope limiter, or
   first order. Wet/dry fronts use the non-negative depth (hydrostatic) reconstruction with Liang's
   local bed modification, so still water stays still over any bed, wet or dry, to the last bit, and
   depths never go negative. Bed friction (Manning) is implicit; an eddy viscosity, rain, point
   sources and a per-cell momentum source (S_px, for couplers) are optional.

   Grid and storage: nx x ny cells (ny = 1 in 1D), cell (i, j) has centre
   (x_min + (i + 1/2) dx, y_min + (j + 1/2) dy) and index k = i + nx j in every array of this section.
   In 1D the channel has a `width` (default 1 m) so volumes and momenta have their 3D units.
   Units: m, s, m^2/s for unit discharges uh and vh, kg/m^3 for the water density.
   One thread: the sweep is sequential (no OpenMP in this section); distinct solvers may run in
   distinct threads. */

typedef struct fsdem_swe fsdem_swe;

/* Slope limiter of the second-order reconstruction (all are TVD, so reconstructed depths stay within
   the neighbours' range and never go negative). */
typedef enum fsdem_swe_limiter {
    FSDEM_SWE_LIMITER_MINMOD = 0,   /* most dissipative, the default */
    FSDEM_SWE_LIMITER_VAN_LEER = 1, /* harmonic mean */
    FSDEM_SWE_LIMITER_MC = 2,       /* monotonised central */
    FSDEM_SWE_LIMITER_SUPERBEE = 3  /* least dissipative, steepens fronts */
} fsdem_swe_limiter;

/* fsdem_swe_desc.boundary is indexed by fsdem_side; 1D uses XMIN and XMAX only. */
typedef enum fsdem_swe_bc {
    FSDEM_SWE_BC_WALL = 0,         /* reflective, free slip: no mass flux, mirrored normal velocity */
    FSDEM_SWE_BC_TRANSMISSIVE = 1, /* zero gradient: waves leave (approximately) without reflection */
    FSDEM_SWE_BC_DISCHARGE = 2,    /* inflow of a unit discharge `value` (m^2/s, >= 0, into the domain)
                                      imposed exactly as the boundary mass flux; the boundary depth comes
                                      from the outgoing Riemann invariant (subcritical inflow) */
    FSDEM_SWE_BC_STAGE = 3         /* fixed surface elevation `value` (m) outside; the normal velocity
                                      comes from the outgoing Riemann invariant */
} fsdem_swe_bc;

/* One side's boundary condition. With a series, `value` follows it in time (linear interpolation,
   held constant before the first and after the last point): a hydrograph for DISCHARGE, a stage
   record for STAGE. The series is copied when the boundary is set. */
typedef struct fsdem_swe_boundary {
    fsdem_swe_bc type;               /* default FSDEM_SWE_BC_WALL */
    fsdem_real value;                /* m^2/s (DISCHARGE) or m (STAGE); default 0 */
    const fsdem_real *series_time;   /* s, strictly increasing; NULL: constant `value`; default NULL */
    const fsdem_real *series_value;  /* m^2/s or m, one per time; default NULL */
    int series_count;                /* points in the series; default 0 */
} fsdem_swe_boundary;

typedef struct fsdem_swe_desc {
    int dim;                         /* 1 or 2 */
    int nx, ny;                      /* cells along x and y (ny must be 1 in 1D); default 100 (1D: 100 x 1) */
    fsdem_real x_min, x_max;         /* m; extent along x; default 0 .. 1 */
    fsdem_real y_min, y_max;         /* m; extent along y, 2D only; default 0 .. 1 */
    fsdem_real width;                /* m; 1D only: channel width for volumes, momenta, forces; default 1 */
    fsdem_vec3 gravity;              /* m/s^2; vertical, (0, 0, -g) with g > 0; default (0, 0, -9.81) */
    fsdem_real density;              /* kg/m^3; water density for momentum and force; default 1000 */
    fsdem_real cfl;                  /* -; Courant number of adaptive steps, in (0, 1]; default 0.5 */
    fsdem_real dt_max;               /* s; longest adaptive step (used when nothing moves); default 1 */
    int order;                       /* 1 (first order) or 2 (MUSCL-Hancock); default 2 */
    fsdem_swe_limiter limiter;       /* order 2 only; default FSDEM_SWE_LIMITER_MINMOD */
    fsdem_real dry_depth;            /* m; cells shallower than this have zero velocity; default 1e-6 */
    fsdem_real manning;              /* s/m^(1/3); uniform Manning n, 0 = frictionless; default 0 */
    fsdem_real eddy_viscosity;       /* m^2/s; turbulent viscosity of S_v = div(nu h grad u); default 0 */
    fsdem_real rain_rate;            /* m/s; uniform rain on every cell; default 0 */
    fsdem_swe_boundary boundary[4];  /* indexed by fsdem_side; default all walls */
    const fsdem_real *bed;           /* m; nx*ny bed elevations z_b, copied; NULL: flat at 0; default NULL */
    const fsdem_real *depth;         /* m; nx*ny initial depths >= 0, copied; NULL: dry; default NULL */
    fsdem_allocator allocator;       /* default: FSDEM_MALLOC/FSDEM_FREE */
    fsdem_log_fn log;                /* optional; default NULL */
    void *log_user;
} fsdem_swe_desc;

/* Defaults for a 1D or 2D grid (see the field comments). */
FSDEM_API fsdem_swe_desc fsdem_swe_desc_default(int dim);
/* Checks a desc, including every value of `bed` and `depth`, without creating anything; on failure
   writes the reason, naming the field or cell, to `message` (may be NULL). Returns FSDEM_OK or
   FSDEM_ERR_INVALID_ARG (zero or negative cell counts, an empty extent, cfl outside (0, 1], a NaN
   bed, a negative or NaN depth, a bad boundary or series, ...). */
FSDEM_API fsdem_result fsdem_swe_desc_check(const fsdem_swe_desc *desc, char *message, size_t message_size);
/* Creates a solver (time 0). All memory is allocated here; steps allocate nothing. On
   FSDEM_ERR_INVALID_ARG the reason goes to desc->log (and is available from fsdem_swe_desc_check);
   also FSDEM_ERR_OUT_OF_MEMORY. *out is NULL on failure. Destroy with fsdem_swe_destroy. */
FSDEM_API fsdem_result fsdem_swe_create(const fsdem_swe_desc *desc, fsdem_swe **out);
FSDEM_API void fsdem_swe_destroy(fsdem_swe *swe);
/* Message of the last failed call on this object ("" after success). Valid until the next call. */
FSDEM_API const char *fsdem_swe_last_error(const fsdem_swe *swe);

/* ---- state ---- */

/* Geometry of the grid. */
typedef struct fsdem_swe_grid {
    int dim, nx, ny;
    fsdem_real dx, dy;        /* m; dy = width in 1D */
    fsdem_real x_min, y_min;  /* m; lower corner (y_min = 0 in 1D) */
    fsdem_real cell_area;     /* m^2; dx dy */
} fsdem_swe_grid;

FSDEM_API fsdem_swe_grid fsdem_swe_get_grid(const fsdem_swe *swe);

/* Replaces the bed (nx*ny values, m), keeping each cell's depth. FSDEM_ERR_INVALID_ARG names the
   first non-finite value; the state is then unchanged. */
FSDEM_API fsdem_result fsdem_swe_set_bed(fsdem_swe *swe, const fsdem_real *bed);
/* Sets the depths (m, >= 0), keeping the unit discharges. FSDEM_ERR_INVALID_ARG names the first
   negative or non-finite value; the state is then unchanged. */
FSDEM_API fsdem_result fsdem_swe_set_depth(fsdem_swe *swe, const fsdem_real *depth);
/* Sets the surface elevation (m); cells whose bed is above it become dry (h = 0). */
FSDEM_API fsdem_result fsdem_swe_set_surface(fsdem_swe *swe, const fsdem_real *eta);
/* Sets the velocities (m/s; v may be NULL, ignored in 1D): uh = u h, vh = v h. */
FSDEM_API fsdem_result fsdem_swe_set_velocity(fsdem_swe *swe, const fsdem_real *u, const fsdem_real *v);

/* State of one cell (or of a point, interpolated), as set by or returned to the caller. */
typedef struct fsdem_swe_cell {
    fsdem_real bed;    /* m, z_b */
    fsdem_real depth;  /* m, h >= 0 */
    fsdem_real eta;    /* m, surface elevation z_b + h (output only) */
    fsdem_real u, v;   /* m/s */
} fsdem_swe_cell;

/* Initial condition from a function of the cell centre (y = 0 in 1D): `fn` fills bed, depth, u, v.
   Validated like the array setters; nothing changes on failure. */
typedef void (*fsdem_swe_init_fn)(void *user, fsdem_real x, fsdem_real y, fsdem_swe_cell *cell);
FSDEM_API fsdem_result fsdem_swe_set_cells(fsdem_swe *swe, fsdem_swe_init_fn fn, void *user);

/* Read-only views of the state arrays (nx*ny each, index i + nx j), valid until the solver is
   destroyed; change them with the setters. */
typedef struct fsdem_swe_fields {
    int nx, ny;
    const fsdem_real *eta;           /* m */
    const fsdem_real *qx;            /* m^2/s, uh */
    const fsdem_real *qy;            /* m^2/s, vh (all zero in 1D) */
    const fsdem_real *bed;           /* m */
    const unsigned char *blocked;    /* 1 for blocked cells (fsdem_swe_set_blocked); NULL when none */
} fsdem_swe_fields;

FSDEM_API fsdem_swe_fields fsdem_swe_get_fields(const fsdem_swe *swe);

/* Writable coupling arrays (nx*ny each): the momentum source S_p of seed 003 Eq. 2 and 8 in
   m^2/s^2 (acceleration times depth, i.e. force per unit plan area divided by the density), added to
   d(uh)/dt and d(vh)/dt and held over steps until changed (zero at creation). A source in a dry cell
   is dropped (dry cells carry no momentum). Steps read them once this function has handed them out
   (or fsdem_swe_add_force wrote them). */
typedef struct fsdem_swe_coupling {
    int nx, ny;
    fsdem_real *source_x;   /* m^2/s^2 */
    fsdem_real *source_y;   /* m^2/s^2 (ignored in 1D) */
} fsdem_swe_coupling;

FSDEM_API fsdem_swe_coupling fsdem_swe_get_coupling(fsdem_swe *swe);

/* The shallow water's coupling arrays, as writers claim them (fsdem_claim; a two-way fsdem_swe_dem
   claims them). */
typedef enum fsdem_swe_arrays {
    FSDEM_SWE_ARRAYS_SOURCE = 1   /* source_x, source_y (fsdem_swe_add_force, fsdem_swe_clear_forces) */
} fsdem_swe_arrays;

/* The shallow water's claim registry (>>core_claims); NULL for a NULL solver. */
FSDEM_API fsdem_claims *fsdem_swe_claims(fsdem_swe *swe);

typedef enum fsdem_swe_field {
    FSDEM_SWE_FIELD_DEPTH = 0, /* m */
    FSDEM_SWE_FIELD_ETA = 1,   /* m */
    FSDEM_SWE_FIELD_U = 2,     /* m/s (0 in dry cells) */
    FSDEM_SWE_FIELD_V = 3,     /* m/s */
    FSDEM_SWE_FIELD_BED = 4,   /* m */
    FSDEM_SWE_FIELD_QX = 5,    /* m^2/s */
    FSDEM_SWE_FIELD_QY = 6     /* m^2/s */
} fsdem_swe_field;

/* Copies one field (nx*ny values) to `out`. FSDEM_ERR_INVALID_ARG for a bad field or NULL. */
FSDEM_API fsdem_result fsdem_swe_copy_field(const fsdem_swe *swe, fsdem_swe_field field, fsdem_real *out);

/* Cell holding the point (x, y) (y ignored in 1D): its index k = i + nx j, or -1 outside. */
FSDEM_API int fsdem_swe_cell_at(const fsdem_swe *swe, fsdem_real x, fsdem_real y);
/* State at a point, interpolated (bi)linearly between cell centres (clamped to the outermost centres
   near the boundary; blocked cells leave the interpolation, the others share their weight): bed,
   depth, eta and velocity. FSDEM_ERR_OUT_OF_DOMAIN outside the grid or in a blocked cell. */
FSDEM_API fsdem_result fsdem_swe_sample_state(const fsdem_swe *swe, fsdem_real x, fsdem_real y, fsdem_swe_cell *out);
/* The coupling sample at `count` points (x, y horizontal, z vertical; 1D: y ignored): the
   depth-averaged velocity where z is in the water column (bed <= z <= eta), the hydrostatic pressure
   gradient rho g (deta/dx, deta/dy, -1) there, and volume fraction 1 in the column, 0 above the
   surface, below the bed and off the grid (where velocity and gradient are 0 too).
   FSDEM_ERR_INVALID_ARG for NULL arrays. */
FSDEM_API fsdem_result fsdem_swe_sample(const fsdem_swe *swe, int count, const fsdem_vec3 *points,
                                       fsdem_fluid_sample *out);
/* Adds a horizontal force exerted on the water (N; its z is ignored) to the momentum sources: spread
   over the wet cells under the square footprint [x - radius, x + radius] (x [y - radius, y + radius]
   in 2D) in proportion to their overlap, or the wet cell holding the point when radius is 0; when
   none is wet, shared equally by the wet cells of that footprint grown by one cell. Over a step of
   dt the water then gains exactly force x dt of momentum. *taken (may be NULL) is 0 when no wet
   cell could take it (the force is dropped). FSDEM_ERR_INVALID_ARG (non-finite input, radius < 0),
   FSDEM_ERR_OUT_OF_DOMAIN (the point is off the grid). */
FSDEM_API fsdem_result fsdem_swe_add_force(fsdem_swe *swe, fsdem_vec3 point, fsdem_real radius, fsdem_vec3 force,
                                          int *taken);
/* Sets the momentum sources (source_x, source_y) to zero. */
FSDEM_API fsdem_result fsdem_swe_clear_forces(fsdem_swe *swe);

/* ---- boundaries, friction and sources ---- */

/* Replaces one side's boundary condition (the series is copied). FSDEM_ERR_INVALID_ARG for a bad
   side (Y sides in 1D), type, value or series; the old condition stays. FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_swe_set_boundary(fsdem_swe *swe, fsdem_side side, const fsdem_swe_boundary *bc);
/* Per-cell Manning coefficients (nx*ny values, s/m^(1/3), >= 0), copied; NULL returns to the uniform
   desc.manning. FSDEM_ERR_INVALID_ARG names a negative or non-finite value. */
FSDEM_API fsdem_result fsdem_swe_set_manning(fsdem_swe *swe, const fsdem_real *manning);
/* Uniform rain rate (m/s, >= 0) from now on. */
FSDEM_API fsdem_result fsdem_swe_set_rain(fsdem_swe *swe, fsdem_real rate);

/* Blocked cells: solids inside the domain (buildings, walls, piers). Their faces reflect like a
   FSDEM_SWE_BC_WALL side (no mass flux, the normal velocity mirrored in the reconstruction), they
   hold no water, and gauges, sampling and point sources never reach into them. `blocked` has nx*ny
   values (nonzero: blocked) and replaces the mask; NULL unblocks every cell. Water in a cell that
   becomes blocked is removed and counted in stats.source_volume (negative), so the volume balance
   still holds. FSDEM_ERR_INVALID_ARG (with nothing changed) when a point source or gauge would be
   in a blocked cell; FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_swe_set_blocked(fsdem_swe *swe, const unsigned char *blocked);
/* Adds to the mask the cells whose centres lie in the box [x0, x1] x [y0, y1] (1D: y ignored). */
FSDEM_API fsdem_result fsdem_swe_block_box(fsdem_swe *swe, fsdem_real x0, fsdem_real y0, fsdem_real x1, fsdem_real y1);
/* Adds to the mask the cells whose centres lie inside the closed polygon of `count` >= 3 vertices
   (x, y used; a building footprint; 2D only). */
FSDEM_API fsdem_result fsdem_swe_block_polygon(fsdem_swe *swe, const fsdem_vec3 *vertices, int count);

/* A point source (Q > 0) or sink (Q < 0) of discharge Q (m^3/s; 1D: the whole channel width) in the
   cell holding (x, y); with a series, Q follows it in time like a boundary series. A sink takes no
   more than the water in its cell. */
typedef struct fsdem_swe_point_source {
    fsdem_real x, y;                 /* m */
    fsdem_real discharge;            /* m^3/s */
    const fsdem_real *series_time;   /* s, optional (NULL) */
    const fsdem_real *series_value;  /* m^3/s */
    int series_count;
} fsdem_swe_point_source;

/* Adds a point source; its id goes to *id (may be NULL). FSDEM_ERR_OUT_OF_DOMAIN, INVALID_ARG,
   OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_swe_add_point_source(fsdem_swe *swe, const fsdem_swe_point_source *src, int *id);
/* Removes a point source (the id is not reused). FSDEM_ERR_NOT_FOUND. */
FSDEM_API fsdem_result fsdem_swe_remove_point_source(fsdem_swe *swe, int id);

/* ---- time integration ---- */

/* Stable time step (s) of the current state: the dt with r dt + a dt^2 = cfl, where r is the max over
   wet cells (and inflow/stage boundary states) of (|u| + c)/dx + (|v| + c)/dy, c = sqrt(g h), and
   a = g max(|deta/dx|/dx + |deta/dy|/dy) bounds the velocity gained within the step (it matters for
   thin films on steep beds; minmod slopes, so it is 0 for a lake at rest, islands included). Capped
   by desc.dt_max and, with an eddy viscosity, by 2 nu dt (1/dx^2 + 1/dy^2) <= cfl. */
FSDEM_API fsdem_result fsdem_swe_stable_dt(const fsdem_swe *swe, fsdem_real *dt);
/* Advances by one step of the stable dt. Errors: FSDEM_ERR_NAN (the step is complete, the message
   names the first bad cell; the state is then not usable), FSDEM_ERR_IO (a gauge row could not be
   written). */
FSDEM_API fsdem_result fsdem_swe_step(fsdem_swe *swe);
/* Advances by exactly dt (s). FSDEM_ERR_CFL, with nothing changed, when dt exceeds the stability
   limit (Courant number > 1); FSDEM_ERR_INVALID_ARG for dt <= 0; otherwise as fsdem_swe_step. */
FSDEM_API fsdem_result fsdem_swe_step_dt(fsdem_swe *swe, fsdem_real dt);
/* FSDEM_OK when fsdem_swe_step_dt would take a step of dt, else the refusal it would return, with
   its message (a coupler checks before it changes anything). */
FSDEM_API fsdem_result fsdem_swe_check_dt(const fsdem_swe *swe, fsdem_real dt);
/* Adaptive steps until `duration` (s) has elapsed exactly (the last step is shortened); the number
   of steps goes to *steps (may be NULL). Stops at the first error. */
FSDEM_API fsdem_result fsdem_swe_advance(fsdem_swe *swe, fsdem_real duration, long long *steps);
/* Simulated time (s). */
FSDEM_API double fsdem_swe_time(const fsdem_swe *swe);
/* The desc in force (bed, depth and boundary series pointers are NULL: the solver keeps copies). */
FSDEM_API fsdem_swe_desc fsdem_swe_get_desc(const fsdem_swe *swe);

/* ---- diagnostics ---- */

/* Water volume (m^3): sum of h dx dy (1D: h dx width). */
FSDEM_API fsdem_real fsdem_swe_volume(const fsdem_swe *swe);
/* Water momentum (kg m/s): rho times the sum of (uh, vh, 0) dx dy. */
FSDEM_API fsdem_vec3 fsdem_swe_momentum(const fsdem_swe *swe);

typedef struct fsdem_swe_stats {
    long long steps;              /* steps taken */
    double time;                  /* s */
    fsdem_real dt;                /* s, the last step */
    fsdem_real max_depth;         /* m, over the cells */
    fsdem_real max_speed;         /* m/s, largest |velocity| over wet cells */
    int wet_cells;                /* cells with h >= dry_depth */
    fsdem_real boundary_volume;   /* m^3, net volume that entered through the boundaries */
    fsdem_real source_volume;     /* m^3, net volume added by rain and point sources */
    fsdem_real clipped_volume;    /* m^3, volume added to keep depths non-negative (0 in practice) */
    long long predictor_fallbacks;/* cells whose MUSCL-Hancock predictor was skipped for positivity */
    size_t memory_bytes;          /* bytes held by the object */
} fsdem_swe_stats;

/* Statistics; conservation reads volume(t) = volume(0) + boundary_volume + source_volume
   + clipped_volume to rounding. */
FSDEM_API fsdem_swe_stats fsdem_swe_get_stats(const fsdem_swe *swe);

/* ---- output ---- */

/* Field snapshot as CSV, one row per cell: x,y,bed,h,eta,u,v (1D: x,bed,h,eta,u). FSDEM_ERR_IO,
   FSDEM_ERR_INVALID_ARG (NULL). The VTK XML snapshot (fsdem_swe_write_vti) is in >>io. */
FSDEM_API fsdem_result fsdem_swe_write_csv(const fsdem_swe *swe, const char *path);

/* Adds a gauge at (x, y) (before fsdem_swe_gauges_open); its id goes to *id (may be NULL).
   FSDEM_ERR_OUT_OF_DOMAIN, FSDEM_ERR_OUT_OF_MEMORY, FSDEM_ERR_INVALID_ARG while a file is open. */
FSDEM_API fsdem_result fsdem_swe_add_gauge(fsdem_swe *swe, fsdem_real x, fsdem_real y, int *id);
/* Samples gauge `id` now (as fsdem_swe_sample_state). FSDEM_ERR_NOT_FOUND. */
FSDEM_API fsdem_result fsdem_swe_gauge(const fsdem_swe *swe, int id, fsdem_swe_cell *out);
/* Opens a gauge time series: a CSV with columns t, then h_<id>,eta_<id>,u_<id>,v_<id> per gauge.
   A row is written now and at every later multiple of `interval` (s) after the opening time, the
   values interpolated linearly within the step that passes it; interval 0: one row per step at the
   step's time. FSDEM_ERR_IO, FSDEM_ERR_INVALID_ARG (no gauges, interval < 0). */
FSDEM_API fsdem_result fsdem_swe_gauges_open(fsdem_swe *swe, const char *path, fsdem_real interval);
/* Closes the gauge file (also done by fsdem_swe_destroy). FSDEM_ERR_IO. */
FSDEM_API fsdem_result fsdem_swe_gauges_close(fsdem_swe *swe);
/* Holds the gauge rows of the steps to come (hold = 1): a step's rows wait, unwritten, until the next
   step begins or the hold ends (hold = 0 writes them). A coupler holds them through its step, so
   that a step it puts back leaves the file as it was (>>couple_step). Without an open gauge file
   there is nothing to hold. FSDEM_ERR_IO when rows could not be written. */
FSDEM_API fsdem_result fsdem_swe_gauges_hold(fsdem_swe *swe, int hold);

/* Signed distance from p to the SWE bed surface z = z_b(x, y), for fsdem_dem_wall_sdf(fsdem_swe_bed_sdf,
   swe, material): (z - z_b)/sqrt(1 + |grad z_b|^2) with the bed normal; exact on planar beds. `user` is
   the fsdem_swe. Points outside the SWE grid take the nearest cell's bed. */
FSDEM_API fsdem_real fsdem_swe_bed_sdf(void *user, fsdem_vec3 p, fsdem_vec3 *normal);
