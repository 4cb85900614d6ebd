/* ===== >>pic : PIC/FLIP free-surface solver on a MAC grid ===== */

/* Incompressible Navier-Stokes (seed 000 Eq. 1-2) for one liquid with a free surface, solved by
   marker particles on a staggered (MAC) grid: particle-to-grid transfer, body forces, implicit
   viscosity, pressure projection, grid-to-particle transfer (PIC, FLIP, their blend, or APIC),
   particle advection through the grid velocity, then the density projection of seed 004 §5.1 and
   Appendix B (alpha_s = 0) that keeps the particle distribution, hence the water volume, uniform.

   Grid. Cells of edge `cell_size` cover [domain_min, domain_max]; the extent is rounded to whole
   cells (domain_max moves by less than half a cell). Velocities live on cell faces in the layout of
   >>linalg: face[0] holds (n[0]+1) n[1] n[2] x-faces, face (i,j,k) at (k n[1] + j)(n[0]+1) + i lies
   between cells i-1 and i; likewise y- and z-faces. Cells are FLUID, AIR or SOLID
   (fsdem_stencil_cell values).

   Free surface. The fluid fraction of a cell is the particle count around its centre (tent kernel,
   normalised by what a uniformly filled neighbourhood would give, seed 004 Eq. 7b); a signed
   distance phi (m, < 0 in water) follows from it, exact for a plane surface. Cells with
   phi < -ghost_theta_min dx are FLUID. p = 0 at phi = 0 through the second-order ghost-fluid method.
   Cells mostly inside obstacles take phi from their open neighbours.

   Solids. Static obstacles (boxes, spheres/discs, cylinders, 2D polygons, callbacks) are signed
   distances turned into face-area fractions E in [0, 1] (the cut-cell weights of seed 000 Eq. 5).
   The pressure equation of a cell is sum_f E_f (p_c - p_nb) = -(rho dx^2/dt) div, with the divergence
   sum_f n_f (E_f u_f + (1 - E_f) us_f)/dx, where us_f is the solid velocity on the face. Domain walls
   are faces with E = 0 and a prescribed (kinematic) velocity. A coupler adds moving solids through
   fsdem_pic_coupling_view(): per-face open fractions and solid velocities, a per-face acceleration, and
   an optional extra SPD term of the pressure operator (the implicit solid velocity of seed 000
   Eq. 6), all without touching the projection.

   Step (fsdem_pic_step): P2G -> classify cells -> extrapolate -> save the grid velocity for FLIP ->
   implicit viscosity -> gravity and coupler accelerations -> pressure projection -> extrapolate ->
   G2P -> RK2/RK3 advection -> push particles out of solids, drop those leaving through outflows ->
   density projection -> reseeding. No allocation happens inside a step. */

typedef struct fsdem_pic fsdem_pic;

/* Grid-to-particle velocity update. */
typedef enum fsdem_pic_transfer {
    FSDEM_PIC_TRANSFER_PIC = 0,  /* particles take the grid velocity (dissipative, stable) */
    FSDEM_PIC_TRANSFER_FLIP = 1, /* particles add the grid velocity change; blended with PIC by */
                                 /*    flip_ratio (1 = pure FLIP) */
    FSDEM_PIC_TRANSFER_APIC = 2  /* affine PIC: each particle also carries a velocity gradient */
} fsdem_pic_transfer;

/* Particle-grid interpolation kernel of the P2G/G2P transfers. */
typedef enum fsdem_pic_kernel {
    FSDEM_PIC_KERNEL_LINEAR = 0,   /* 2^dim faces per particle and component */
    FSDEM_PIC_KERNEL_QUADRATIC = 1 /* quadratic B-spline, 3^dim faces, smoother */
} fsdem_pic_kernel;

/* Boundary condition on one side of the domain box (desc.boundary, indexed by fsdem_side). */
typedef enum fsdem_pic_bc {
    FSDEM_PIC_BC_SLIP = 0,    /* impermeable wall, free slip */
    FSDEM_PIC_BC_NO_SLIP = 1, /* impermeable wall; viscous no slip at the wall's tangential */
                              /*    velocity (a moving lid is a tangential boundary_velocity) */
    FSDEM_PIC_BC_INFLOW = 2,  /* prescribed velocity boundary_velocity (all components); the cells */
                              /*    next to it are kept filled with particles of that velocity */
    FSDEM_PIC_BC_OUTFLOW = 3  /* open: p = 0 on the boundary, particles crossing it are removed */
} fsdem_pic_bc;

typedef struct fsdem_pic_desc {
    int dim;                          /* 2 or 3 */
    fsdem_vec3 domain_min;            /* m; default (0,0,0) */
    fsdem_vec3 domain_max;            /* m; default (1,1,1) (z unused in 2D) */
    fsdem_real cell_size;             /* m; edge of a grid cell, > 0; default 1/32 */
    fsdem_real density;               /* kg/m^3; liquid density rho; default 1000 */
    fsdem_real viscosity;             /* m^2/s; kinematic viscosity nu (seed 000 Eq. 2), implicit; */
                                      /*    default 0 (inviscid) */
    fsdem_vec3 gravity;               /* m/s^2; default (0,-9.81,0) in 2D, (0,0,-9.81) in 3D */
    fsdem_pic_bc boundary[6];         /* indexed by fsdem_side; default FSDEM_PIC_BC_SLIP */
    fsdem_vec3 boundary_velocity[6];  /* m/s; lid or inflow velocity per side; default 0 */
    int free_surface;                 /* 1: cells are FLUID where particles are; 0: every open cell */
                                      /*    is FLUID (a completely filled box, e.g. a cavity); default 1 */
    fsdem_pic_transfer transfer;      /* default FSDEM_PIC_TRANSFER_FLIP */
    fsdem_real flip_ratio;            /* -; FLIP share of the blend in [0, 1]; default 0.97 */
    fsdem_pic_kernel kernel;          /* default FSDEM_PIC_KERNEL_LINEAR */
    int particles_per_cell;           /* seeding density; default 4 (2D) / 8 (3D) */
    fsdem_real jitter;                /* -; random displacement of seeds as a fraction of their */
                                      /*    spacing, in [0, 1]; default 0: seeds on the sub-cell */
                                      /*    lattice, a flat surface, still water at rest (jittered, */
                                      /*    the surface is rough at the scale of a cell and relaxes */
                                      /*    in waves of cm/s: validation/pic_hydrostatic) */
    unsigned seed;                    /* random seed of jitter and reseeding; default 1 */
    int min_particles_per_cell;       /* reseeding moves particles from crowded neighbour cells into */
                                      /*    interior fluid cells with fewer (volume-neutral); */
                                      /*    0 = never; default particles_per_cell / 2 */
    int max_particles_per_cell;       /* reseeding removes particles from cells with more; 0 = never; */
                                      /*    default 3 particles_per_cell */
    int advection_order;              /* 2 (midpoint) or 3 (Ralston RK3); default 2 */
    fsdem_real cfl;                   /* -; adaptive dt = cfl dx / (u_max + sqrt(|g| dx)); default 1 */
    fsdem_real cfl_max;               /* -; a fixed dt beyond this CFL number is refused; default 5 */
    fsdem_real dt_max;                /* s; largest step; default 0.01 */
    int density_projection;           /* 1: seed 004 §5.1 density projection after advection; default 1 */
    fsdem_real ghost_theta_min;       /* -; smallest interface fraction of the ghost-fluid method; */
                                      /*    default 0.01 */
    int extrapolation_layers;         /* faces of velocity extrapolation into air and solids; */
                                      /*    0 = auto (cfl_max + 2); default 0 */
    fsdem_precond pressure_precond;   /* default FSDEM_PRECOND_AUTO (multigrid) */
    fsdem_real pressure_tolerance;    /* -; relative residual of the pressure solve; default 1e-8 */
    int pressure_max_iterations;      /* default 500 */
    fsdem_precond viscosity_precond;  /* default FSDEM_PRECOND_MIC0 */
    fsdem_real viscosity_tolerance;   /* -; relative residual of the viscous solves; default 1e-8 */
    size_t max_memory;                /* bytes; creation fails when the grid would need more; */
                                      /*    0 = no limit beyond the allocator; default 0 */
    fsdem_allocator allocator;        /* default: FSDEM_MALLOC/FSDEM_FREE */
    fsdem_log_fn log;                 /* optional; default NULL */
    void *log_user;
} fsdem_pic_desc;

/* Defaults for dim = 2 (x-y plane, gravity -y) or 3 (gravity -z); see the field comments. */
FSDEM_API fsdem_pic_desc fsdem_pic_desc_default(int dim);
/* Checks a desc without creating anything (also the memory the grid needs against max_memory); the
   reason, naming the field, goes to `message` (may be NULL). Returns FSDEM_OK,
   FSDEM_ERR_INVALID_ARG or FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_pic_desc_check(const fsdem_pic_desc *desc, char *message,
                                            size_t message_size);
/* Creates a solver with an empty domain (no particles, no obstacles). All grid memory and the
   linear solvers are set up here. *out is NULL on failure. Errors: FSDEM_ERR_INVALID_ARG (the
   reason goes to desc->log and fsdem_pic_desc_check), FSDEM_ERR_OUT_OF_MEMORY (the grid does not
   fit max_memory, int indices or the allocator). Destroy with fsdem_pic_destroy. */
FSDEM_API fsdem_result fsdem_pic_create(const fsdem_pic_desc *desc, fsdem_pic **out);
FSDEM_API void fsdem_pic_destroy(fsdem_pic *pic);
/* Message of the last failed call on this object ("" after success). Valid until the next call. */
FSDEM_API const char *fsdem_pic_last_error(const fsdem_pic *pic);

/* ---- obstacles ---- */

typedef enum fsdem_pic_obstacle_type {
    FSDEM_PIC_OBSTACLE_TYPE_BOX = 0,      /* axis-aligned solid box [a, b] */
    FSDEM_PIC_OBSTACLE_TYPE_SPHERE = 1,   /* sphere (3D) or disc (2D), centre a, radius `radius` */
    FSDEM_PIC_OBSTACLE_TYPE_CYLINDER = 2, /* 3D: flat-capped cylinder with axis a-b and `radius`; */
                                     /*    2D: a disc like SPHERE */
    FSDEM_PIC_OBSTACLE_TYPE_POLYGON = 3,  /* 2D: closed polygon `vertices` (x, y used), any orientation */
    FSDEM_PIC_OBSTACLE_TYPE_SDF = 4       /* callback: signed distance, positive on the liquid side */
} fsdem_pic_obstacle_type;

typedef struct fsdem_pic_obstacle {
    fsdem_pic_obstacle_type type;
    fsdem_vec3 a, b;              /* m; geometry, meaning per type */
    fsdem_real radius;            /* m; SPHERE, CYLINDER */
    const fsdem_vec3 *vertices;   /* POLYGON: `vertex_count` >= 3 points, copied when added */
    int vertex_count;
    fsdem_sdf_fn sdf;             /* SDF: distance (m) and unit normal towards the liquid */
    void *sdf_user;               /*    (must stay valid while the solver lives) */
    fsdem_vec3 velocity;          /* m/s; kinematic surface velocity (the geometry does not move): */
                                  /*    normal flux through cut faces and no-slip value; default 0 */
} fsdem_pic_obstacle;

FSDEM_API fsdem_pic_obstacle fsdem_pic_obstacle_box(fsdem_vec3 lo, fsdem_vec3 hi);
FSDEM_API fsdem_pic_obstacle fsdem_pic_obstacle_sphere(fsdem_vec3 centre, fsdem_real radius);
FSDEM_API fsdem_pic_obstacle fsdem_pic_obstacle_cylinder(fsdem_vec3 a, fsdem_vec3 b, fsdem_real radius);
FSDEM_API fsdem_pic_obstacle fsdem_pic_obstacle_polygon(const fsdem_vec3 *vertices, int count);
FSDEM_API fsdem_pic_obstacle fsdem_pic_obstacle_sdf(fsdem_sdf_fn sdf, void *user);

/* Adds a static obstacle; its index goes to *id (may be NULL). Recomputes the face fractions of
   the union of all obstacles (each face sampled on a 4 x 4 sub-grid, linear in between: walls
   thinner than about a quarter cell may leak) and removes the particles now inside a solid.
   Allocates (outside any step). Errors: FSDEM_ERR_INVALID_ARG (bad geometry, non-finite values, or the obstacle would
   leave no open cell: "covers the whole domain"; the solver is unchanged), FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_pic_add_obstacle(fsdem_pic *pic, const fsdem_pic_obstacle *obstacle,
                                              int *id);
/* Signed distance (m) from p to the nearest obstacle or closed domain wall, positive in the open
   domain; writes the unit normal towards the open side to *normal (may be NULL). */
FSDEM_API fsdem_real fsdem_pic_solid_distance(const fsdem_pic *pic, fsdem_vec3 p, fsdem_vec3 *normal);

/* ---- particles ---- */

/* Seeds particles_per_cell particles per cell (stratified with jitter) in the part of the box
   [lo, hi] that is inside the domain and outside every obstacle, all with `velocity` (m/s). The number
   added goes to *added (may be NULL). Errors: FSDEM_ERR_INVALID_ARG (non-finite input, empty box),
   FSDEM_ERR_OUT_OF_MEMORY (nothing added). Allocates (outside any step). */
FSDEM_API fsdem_result fsdem_pic_fill_box(fsdem_pic *pic, fsdem_vec3 lo, fsdem_vec3 hi,
                                          fsdem_vec3 velocity, int *added);
/* Like fsdem_pic_fill_box for the region where region(user, p, NULL) > 0. */
FSDEM_API fsdem_result fsdem_pic_fill_sdf(fsdem_pic *pic, fsdem_sdf_fn region, void *user,
                                          fsdem_vec3 velocity, int *added);
/* Adds `count` particles (positions m, velocities m/s; velocities may be NULL for rest). All or
   nothing: FSDEM_ERR_INVALID_ARG names the first non-finite particle, FSDEM_ERR_OUT_OF_DOMAIN the
   first one outside the domain or inside a solid, FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_pic_add_particles(fsdem_pic *pic, const fsdem_vec3 *positions,
                                               const fsdem_vec3 *velocities, int count);
/* Reserves room for `count` particles so later steps can reseed and inject without refusing
   (steps never allocate; by default room for 1.5 x the particles present is kept). */
FSDEM_API fsdem_result fsdem_pic_reserve(fsdem_pic *pic, int count);

/* Views of the marker particles (structure of arrays), valid until particles are added or a step
   runs (steps reorder, remove and add particles). `velocity` may be edited between steps. */
typedef struct fsdem_pic_particles {
    int count;
    int dim;
    fsdem_real volume;          /* m^3 (m^2 in 2D) represented by one particle: dx^dim / ppc */
    const fsdem_vec3 *position; /* m */
    fsdem_vec3 *velocity;       /* m/s */
} fsdem_pic_particles;

FSDEM_API fsdem_pic_particles fsdem_pic_get_particles(fsdem_pic *pic);

/* ---- time stepping ---- */

/* Advances by one step of the adaptive size min(dt_max, cfl dx / (u_max + sqrt(|g| dx))).
   Errors (the step is complete, the message names the culprit): FSDEM_ERR_NAN (a particle
   velocity became non-finite), FSDEM_ERR_NOT_CONVERGED (a linear solve stopped at its iteration
   limit), FSDEM_ERR_CFL (the projected velocity moved particles more than cfl_max cells). */
FSDEM_API fsdem_result fsdem_pic_step(fsdem_pic *pic);
/* One step of a given dt (s). FSDEM_ERR_INVALID_ARG for dt <= 0 or not finite, FSDEM_ERR_CFL when
   (u_max + sqrt(|g| dx)) dt / dx > cfl_max, the CFL number of the stable rule's speed (of the
   fastest particle, and of gravity waves a cell long: still water refuses a dt that would let it
   fall far; the message names the fastest particle); in both cases nothing moved. Otherwise as
   fsdem_pic_step. */
FSDEM_API fsdem_result fsdem_pic_step_dt(fsdem_pic *pic, fsdem_real dt);
/* FSDEM_OK when fsdem_pic_step_dt would take a step of dt, else the refusal it would return, with
   its message (a coupler checks before it changes anything). */
FSDEM_API fsdem_result fsdem_pic_check_dt(const fsdem_pic *pic, fsdem_real dt);
/* Advances by `duration` (s) with adaptive steps, the last ones shortened to land on the end time.
   Stops at the first error and returns it. Steps taken go to *steps (may be NULL). */
FSDEM_API fsdem_result fsdem_pic_advance(fsdem_pic *pic, fsdem_real duration, long long *steps);
/* The adaptive step the next fsdem_pic_step would take (s). FSDEM_ERR_NAN when a particle velocity
   is not finite. */
FSDEM_API fsdem_result fsdem_pic_stable_dt(const fsdem_pic *pic, fsdem_real *dt);
/* Simulated time (s). */
FSDEM_API double fsdem_pic_time(const fsdem_pic *pic);
/* The desc in force (domain_max moved to whole cells). */
FSDEM_API fsdem_pic_desc fsdem_pic_get_desc(const fsdem_pic *pic);

/* ---- grid and coupling ---- */

/* Read-only view of the grid after the last step (valid while the solver lives). `cell`, `phi` and
   `fraction` describe the particles at the end of the step (after advection and reseeding); the
   face velocities and the pressure are those of the step's projection, made with the cells of its
   start, so a cell the front entered during the step can show a nonzero divergence. Layout: cell
   (i, j, k), centred at origin + cell_size (i + 1/2, j + 1/2, k + 1/2), is index
   i + n[0] (j + n[1] k); face (i, j, k) of axis a is the face on the low side of cell (i, j, k)
   along a (its coordinate along a runs from 0 to n[a]), index i + m[0] (j + m[1] k) with
   m[b] = n[b] + (a == b), face_count[a] of them. Couplers index the grid by this layout. */
typedef struct fsdem_pic_fields {
    int dim;
    int n[3];                      /* cells per axis (n[2] = 1 in 2D) */
    int face_count[3];             /* faces per axis (0 for z in 2D) */
    fsdem_real cell_size;          /* m */
    fsdem_vec3 origin;             /* m, lower corner */
    const unsigned char *cell;     /* fsdem_stencil_cell per cell */
    const fsdem_real *pressure;    /* Pa per cell (0 outside the fluid) */
    const fsdem_real *phi;         /* m; signed distance to the surface, < 0 in water, |phi| <= dx */
    const fsdem_real *fraction;    /* -; particle fluid fraction per cell (1 = uniformly filled) */
    const fsdem_real *velocity[3]; /* m/s; face velocity after projection and extrapolation */
    const fsdem_real *open[3];     /* -; effective face-area fraction E used by the projection */
    const fsdem_real *solid_velocity[3]; /* m/s; velocity of the solid part of each face (walls, */
                                   /*    inflow, obstacles, coupler): face flux E u + (1 - E) us */
} fsdem_pic_fields;

FSDEM_API fsdem_pic_fields fsdem_pic_get_fields(const fsdem_pic *pic);

/* Writable per-face arrays for a coupler (layout of fsdem_pic_fields), read by every step; valid
   while the solver lives:
   - open[a][f]: fraction of face f not covered by moving solids (default 1); the projection uses
     min(static obstacle fraction, open);
   - solid_velocity[a][f]: velocity component a (m/s) of the moving solid on that face (default 0),
     used where open < the static fraction;
   - acceleration[a][f]: extra acceleration (m/s^2) added with gravity, that of a face the liquid
     fills: where granules share it, the step divides it by the face's porosity, so the liquid's
     momentum there, rho alpha_f' dx^dim u, gains rho dx^dim a dt whatever the porosity (default 0;
     kept until changed; fsdem_pic_add_force adds to it, fsdem_pic_clear_forces zeroes it);
   - pressure_rhs[c]: added to the right-hand side of the pressure equation
     sum_f E_f (p_c - p_nb) = -(rho dx^2/dt) div (Pa; default 0, kept until changed);
   - reference[c]: the part of cell c's fluid-fraction kernel that moving solids leave open (default
     1): the particle count of a full cell is divided by it, as by the static obstacles' own part, so
     that water around a moving body reads full and keeps its pressure;
   - start_velocity[a][f]: the moving solid's velocity on face f at the start of the step (default
     0): the no-slip value of the implicit viscous solve, which comes before gravity and the
     accelerations, and the closed faces' value in the FLIP reference (solid_velocity, the
     velocity at the end of the step, holds the step's gravity: a body at rest in water at rest
     would otherwise be sheared, and its neighbours kicked, by its own g dt);
   - shear[a][f] (read only; NULL without viscosity): the viscous force component a (N; N/m in 2D)
     that the liquid exerted on the closed face f (E = 0) during the last step's implicit viscous
     solve, rho nu dx^(dim-2) sum (u_nb - us_f) over the liquid faces next to it; the liquid got
     exactly the opposite, so a coupler that hands it to the solid conserves momentum.
   - porosity[c]: the volume fraction of cell c that the liquid may fill among granules smaller
     than a cell, alpha_f' = 1 - alpha_s of seed 004 Eq. 6 (default 1), in (0, 1] (a step refuses
     another value with FSDEM_ERR_INVALID_ARG naming the cell, before anything moves). The pressure
     equation becomes the variable-coefficient one of seed 004 Eq. 12a: every face's coefficient
     and liquid flux are multiplied by the mean porosity of its two cells (Appendix B's beta), so
     div(alpha_f' u) = 0; the fluid fraction of a cell counts its particles against porosity x a
     full cell's (Eq. 7b over Eq. 6), and the density projection moves the particles towards that
     target (Eq. 12b-13), so water that granules enter is pushed out; reseeding keeps the minimum
     count of the porous cell, and fluid_volume counts porosity x the cell's open volume; the
     accelerations are divided by the faces' porosity (below), so a force from fsdem_pic_add_force
     still gives the water exactly force x dt.
   A cell whose faces are all closed becomes SOLID. Particles are pushed out of static obstacles
   in every step; moving solids are the coupler's (fsdem_pic_exclude_particles). The arrays are read
   by the next step, which recounts the fluid fractions after this call. Owners, claimed
   (fsdem_pic_arrays below): open, solid_velocity, start_velocity and reference describe the moving
   solids as a whole, so one coupler (fsdem_pic_dem) owns them and rewrites them before every step;
   porosity describes the granules as a whole and acceleration their exchange with the water, so
   their one owner is the granular coupler (fsdem_gic), which clears the accelerations before every
   step; pressure_rhs is a sum that any writer adds to. */
typedef struct fsdem_pic_coupling {
    int dim;
    int n[3];
    int face_count[3];
    fsdem_real *open[3];
    fsdem_real *solid_velocity[3];
    fsdem_real *acceleration[3];
    fsdem_real *pressure_rhs;
    fsdem_real *reference;
    const fsdem_real *shear[3];
    fsdem_real *start_velocity[3];
    fsdem_real *porosity;
} fsdem_pic_coupling;

FSDEM_API fsdem_pic_coupling fsdem_pic_get_coupling(fsdem_pic *pic);

/* The PIC's coupling arrays, as writers claim them (fsdem_claim): the moving solids (fsdem_pic_dem),
   the granules' porosity and the accelerations (fsdem_gic), each of one writer; pressure_rhs is a
   sum any writer adds to. */
typedef enum fsdem_pic_arrays {
    FSDEM_PIC_ARRAYS_SOLIDS = 1,      /* open, solid_velocity, start_velocity, reference, and the */
                                      /*    pressure's extra term (fsdem_pic_set_pressure_extra) */
    FSDEM_PIC_ARRAYS_POROSITY = 2,    /* porosity */
    FSDEM_PIC_ARRAYS_ACCELERATION = 4 /* acceleration (fsdem_pic_add_force, fsdem_pic_clear_forces) */
} fsdem_pic_arrays;

/* The PIC's claim registry (>>core_claims); NULL for a NULL PIC. */
FSDEM_API fsdem_claims *fsdem_pic_claims(fsdem_pic *pic);
/* The moving solids' answer to a solved pressure p (Pa, cell layout) over a step of dt (s): it
   sets solid_velocity to their velocity at the end of the step, Q* plus the response that the
   extra term K p stands for. */
typedef void (*fsdem_pic_response_fn)(void *user, const fsdem_real *pressure, fsdem_real dt);

/* An optional symmetric positive semi-definite term y += K p added to the pressure operator of the
   equation above (p and y in Pa, vectors in the cell layout; e.g. the implicit solid response
   dt J^T M^-1 J of seed 000 Eq. 6 in these units). It must write only to FLUID cells; the
   preconditioner does not see it. `response` (may be NULL) is called after every pressure solve,
   before the gradient is applied: the face fluxes behind fsdem_pic_stats.max_divergence, the
   extrapolation and the grid-to-particle transfer then see the solids' final velocity, so water
   next to a body that the pressure holds at rest stays at rest. fn = NULL removes both; `user`
   must stay valid while they are set. */
FSDEM_API fsdem_result fsdem_pic_set_pressure_extra(fsdem_pic *pic, fsdem_operator_fn fn, fsdem_pic_response_fn response,
                                                   void *user);

/* Samples the grid at `count` points (clamped into the domain): velocity (trilinear from the faces),
   the gradient of the pressure (Pa/m, from the face differences) and the liquid fraction
   clamp(1/2 - phi/dx, 0, 1) (trilinear from the cells). FSDEM_ERR_INVALID_ARG for NULL arrays. */
FSDEM_API fsdem_result fsdem_pic_sample(const fsdem_pic *pic, int count, const fsdem_vec3 *points,
                                       fsdem_fluid_sample *out);
/* Adds a force exerted on the liquid at `point` (N; N/m in 2D, per unit depth) to the faces'
   acceleration, spread by the tent kernel of half-width max(radius, dx) over the faces next to
   FLUID cells of the last step and divided by rho dx^dim, so the grid momentum before the
   projection gains exactly force x dt per step. *taken (may be NULL) is 0 when no face next to the
   liquid lies within reach (the force is then dropped). FSDEM_ERR_INVALID_ARG for non-finite input. */
FSDEM_API fsdem_result fsdem_pic_add_force(fsdem_pic *pic, fsdem_vec3 point, fsdem_real radius, fsdem_vec3 force,
                                          int *taken);
/* Zeroes the coupling accelerations. */
FSDEM_API fsdem_result fsdem_pic_clear_forces(fsdem_pic *pic);
/* Keeps particles out of a solid region given by `solid` (distance in m, positive in the liquid,
   with the unit normal towards the liquid; `user` is passed on), such as moving bodies after they
   moved. Particles at a distance below 1e-3 dx are moved along the normal to 1e-3 dx (`remove` = 0:
   the liquid the region swept is kept and the density projection of later steps spreads it) or
   removed (`remove` = 1: the liquid the region now holds, e.g. where a body is first placed). The
   number moved or removed goes to *count (may be NULL). FSDEM_ERR_INVALID_ARG for NULL pic or
   solid, FSDEM_ERR_NAN (the particle is named; nothing moved) when the distance is not finite. */
FSDEM_API fsdem_result fsdem_pic_exclude_particles(fsdem_pic *pic, fsdem_sdf_fn solid, void *user, int remove,
                                                   int *count);

/* ---- gauges ---- */

typedef enum fsdem_pic_gauge_kind {
    /* water level: the elevation (m, the coordinate along -gravity) of the highest free surface
       above the point's column of cells (the cell column holding x in 2D, x-y in 3D), where phi
       crosses 0 between two cell centres; the bottom of the domain when the column is dry */
    FSDEM_PIC_GAUGE_KIND_LEVEL = 0,
    /* pressure (Pa): at the point (trilinear between cell centres) for radius 0, else the mean over
       the non-solid cells whose centres lie within `radius` of it (a sensor patch on a wall) */
    FSDEM_PIC_GAUGE_KIND_PRESSURE = 1
} fsdem_pic_gauge_kind;

/* Adds a gauge (before fsdem_pic_gauges_open); its id goes to *id (may be NULL). The level gauge
   needs gravity along one axis. FSDEM_ERR_OUT_OF_DOMAIN, FSDEM_ERR_INVALID_ARG (bad kind, radius
   < 0, non-finite input, gravity not along an axis for a level gauge, a file is open),
   FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_pic_add_gauge(fsdem_pic *pic, fsdem_pic_gauge_kind kind, fsdem_vec3 position,
                                          fsdem_real radius, int *id);
/* Gauge `id` now (m or Pa). FSDEM_ERR_NOT_FOUND. */
FSDEM_API fsdem_result fsdem_pic_gauge(const fsdem_pic *pic, int id, fsdem_real *value);
/* Opens a gauge time series: a CSV with columns t, then level_<id> or p_<id> per gauge, written as
   fsdem_swe_gauges_open does (rows at multiples of `interval`, interpolated within a step; 0: every
   step). FSDEM_ERR_IO, FSDEM_ERR_INVALID_ARG (no gauges, interval < 0). */
FSDEM_API fsdem_result fsdem_pic_gauges_open(fsdem_pic *pic, const char *path, fsdem_real interval);
/* Closes the gauge file (also done by fsdem_pic_destroy). FSDEM_ERR_IO. */
FSDEM_API fsdem_result fsdem_pic_gauges_close(fsdem_pic *pic);
/* Holds the gauge rows of the steps to come (hold = 1): a step's rows wait, unwritten, until the next
   step begins or the hold ends (hold = 0 writes them). A coupler holds them through its step, so
   that a step it puts back leaves the file as it was (>>couple_step). Without an open gauge file
   there is nothing to hold. FSDEM_ERR_IO when rows could not be written. */
FSDEM_API fsdem_result fsdem_pic_gauges_hold(fsdem_pic *pic, int hold);

/* ---- diagnostics ---- */

typedef struct fsdem_pic_stats {
    long long steps;
    double time;                   /* s */
    fsdem_real dt;                 /* s, last step */
    int particles;
    int fluid_cells;
    fsdem_real fluid_volume;       /* m^3 (m^2 in 2D): liquid volume the solver sees, the sum over */
                                   /*    open cells of clamp(1/2 - phi/dx, 0, 1) (1 when free_surface */
                                   /*    = 0) times the cell's open volume: dx^dim times the mean */
                                   /*    open fraction of its faces under obstacles and moving */
                                   /*    solids (exact for cuts along the grid's planes) */
    fsdem_real particle_volume;    /* m^3 (m^2 in 2D): particles x particle volume, the volume the */
                                   /*    particles carry (exact at seeding; fluid_volume, from the */
                                   /*    grid's level set, reads up to a few % lower on coarse grids) */
    fsdem_real kinetic_energy;     /* J (J/m in 2D): sum of rho V_p |v_p|^2 / 2 */
    fsdem_real max_speed;          /* m/s, particles */
    fsdem_real max_divergence;     /* 1/s; largest |div u| over fluid cells after the projection */
    fsdem_real divergence_before;  /* 1/s; l2 norm over fluid cells of div u before the projection */
    int pressure_iterations;       /* last step */
    fsdem_real pressure_residual;  /* -; relative, last step */
    int viscosity_iterations;      /* last step, summed over components */
    int density_iterations;        /* last step */
    long long reseeded;            /* particles added by the inflow sides, total */
    long long moved;               /* particles moved by reseeding from crowded to sparse cells, total */
    long long removed;             /* particles removed (over-full cells, outflow, solids), total */
    long long refused;             /* inflow seeds refused because the particle capacity was full */
    double seconds_total;          /* CPU seconds spent in steps (clock()) */
    double seconds_pressure;       /* CPU seconds in pressure setup + solve */
    double seconds_density;        /* CPU seconds in the density projection's setup + solve */
    size_t memory_bytes;           /* bytes held by the solver, linear solvers included */
} fsdem_pic_stats;

FSDEM_API fsdem_pic_stats fsdem_pic_get_stats(const fsdem_pic *pic);

/* ---- output ---- */

/* Particles as CSV (x,y,z,vx,vy,vz). FSDEM_ERR_IO, FSDEM_ERR_INVALID_ARG (NULL). VTK XML output
   (fsdem_pic_write_particles_vtp, fsdem_pic_write_grid_vti) is in >>io. */
FSDEM_API fsdem_result fsdem_pic_write_particles_csv(const fsdem_pic *pic, const char *path);
/* Grid cells as CSV (i,j,k,x,y,z,type,p,phi,fraction,u,v,w with cell-centred velocity).
   FSDEM_ERR_IO, FSDEM_ERR_INVALID_ARG (NULL). */
FSDEM_API fsdem_result fsdem_pic_write_grid_csv(const fsdem_pic *pic, const char *path);
