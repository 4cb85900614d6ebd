/* ===== >>couple_pic : resolved cut-cell PIC-DEM (seed 000) ========================================= */

/* Two-way coupling of PIC/FLIP water (fsdem_pic) with DEM discs (2D) or spheres (3D) (fsdem_dem)
   that the water sees at their true shape, after seed 000 §2. Every coupled step of dt:
     1. predicted body velocities Q* = (V*, w*) = Q^n + dt M^-1 (F_g + F_collision^n): gravity and
        the contact forces of the DEM's last step (Eq. 6, with the collisions at time n as the seed's
        prediction; fixed DEM particles keep their velocity);
     2. each body becomes a moving cut-cell solid of the PIC (fsdem_pic_get_coupling): for every
        face near it the closed fraction 1 - E_b from its exact signed distance (sampled as the
        static obstacles are), and on the face the solid velocity V* + w* x (x_f - X_b). Bodies do
        not overlap (the gap below), so on a face shared by two the closed parts add and the solid
        velocity is their closed-fraction-weighted mean: the solid flux is exact. The cells whose
        fluid-fraction kernel a body covers get the reference that keeps them full;
     3. the implicit solid velocity of Eq. 5-6: the solid flux of cell c, J_c . Q / dx with
        J_c = sum over c's faces of s (1 - E_b) [e_a, (x_f - X_b) x e_a] (s = +1 on the upper face,
        -1 on the lower), enters the pressure equation with Q^{n+1} = Q* + dt M^-1 G, where
        G = dx^(dim-1) sum_c p_c J_c is the pressure force and torque. This adds the symmetric
        positive semi-definite term rho dx^dim J M^-1 J^T p to the operator (fsdem_pic_set_pressure
        _extra), so the pressure and the body velocities are solved together: no added-mass
        instability however light the body. G is the discrete adjoint of the solid flux: the
        pressure's power on the bodies equals minus the power it spends on the water they
        displace, and in hydrostatic water G = rho g dx^dim sum (1 - E) over the faces normal to
        gravity, the body volume as the faces see it. Once p is solved, the faces' solid velocity
        becomes Q^{n+1}'s (the response of fsdem_pic_set_pressure_extra): the PIC's fluxes,
        extrapolation and grid-to-particle transfer see the body as it ends the step, and its
        FLIP reference sees it as it started (fsdem_pic_coupling.start_velocity), so water next to
        a body that the pressure holds at rest stays at rest (Q* holds g dt: read from the closed
        faces it kicked the water next to the body by about g dt / 2 with the PIC transfer);
     4. one PIC step; then the fluid force on each body is G from the step's pressure plus the
        viscous force, the momentum the implicit viscous solve gave the closed faces of the body
        (fsdem_pic_coupling.shear), with their moments about the centre. The water loses exactly
        what the bodies gain (both are the same face sums), so momentum is conserved to the solver
        tolerance. The viscous force is explicit in the body velocity: the step is limited to
        desc.viscous_dt_fraction of a body's viscous relaxation time;
     5. the DEM over dt in K = INT(dt/dt_DEM) substeps (Eq. 25, fsdem_dem_advance) with the fluid
        force and torque held: with the DEM's predictor-corrector integrator these are Eq. 21-24,
        except that the fluid impulse is spread evenly over the substeps instead of given at the
        start (the same end velocity; positions differ by O(dt^2 F/m));
     6. the gap (§2.2.2): the DEM's contact_offset is the imaginary boundary of Eq. 19 (the seed
        uses 2 dx), so contacts start before the real surfaces meet and a gap of open cells stays
        between them. In the contact area of every contact (centred on the middle of the gap, of
        length desc.contact_length along the tangent, 4 dx in the seed, and as wide along the normal:
        a square in 2D, a short cylinder in 3D) the water particles' velocities are multiplied by C
        (Eq. 20), linear in the distance t from the contact point along the tangent: desc.dissipation
        (beta) at the point, 1 at the area's edge (C = beta + (1 - beta) 2 t / length); beta = 1
        switches it off. The seed gives the area's length, not its width; the width is a choice;
     7. the water particles inside a body at its new position are moved to its surface
        (fsdem_pic_exclude_particles); the density projection of later steps spreads them. On
        creation, and when bodies are added, the particles inside the new bodies are removed;
     8. well-balanced weight (desc.discrete_weight): in still water the pressure force is exactly
        rho g V_g, V_g = dx^dim sum (1 - E) over the faces normal to gravity, the body's volume as
        the grid sees it; that midpoint rule over cross-sections differs from the exact volume V by
        O(dx^1.5) (2D, -1.2% to +0.3% at 10 cells per radius as the centre moves through a cell),
        enough to make a body of the water's density sink or rise. So the body's weight is taken on
        the same volume: gravity m g V_g / V, the DEM's m g plus m g (V_g / V - 1) given as an
        external force (in Q* too). Bodies of the water's density are then in exact balance and
        floating drafts are exact on the grid; the exchange with the water is not touched.
   Forces are per unit depth in the 2D PIC; the DEM's discs of length disc_length receive them
   times that length. Contacts with domain walls are the DEM's walls (add them to the DEM).
   Next to moving bodies the PIC's statistics mean what they mean elsewhere: max_divergence takes
   the solid flux of each body's velocity at the end of the step (the pressure's answer, which the
   coupler gives the PIC through fsdem_pic_set_pressure_extra's response), and fluid_volume counts
   a cut cell by its open volume. A dam break from rest wants fsdem_pic_desc.dt_max well below
   sqrt(dx / g): the PIC's step estimate does not foresee the impulsive start, and its CFL check
   would end the first step. */

typedef struct fsdem_pic_dem fsdem_pic_dem;

typedef struct fsdem_pic_dem_desc {
    fsdem_pic *pic;                /* water; not owned; must outlive the coupler */
    fsdem_dem *dem;                /* bodies; same dim and gravity as the PIC; not owned; its */
                                   /*    contact_offset is the imaginary boundary (Eq. 19) */
    fsdem_real dissipation;        /* -; beta of Eq. 20 in [0, 1]; 1 switches it off; default 0.5 */
    fsdem_real contact_length;     /* m; side of the contact area of Eq. 20; 0: 4 dx; default 0 */
    fsdem_real viscous_dt_fraction; /* -; coupled step <= this fraction of the shortest viscous */
                                   /*    relaxation time of a body, in (0, 1]; default 0.5 */
    int discrete_weight;           /* 1: gravity acts on a body through its volume as the grid sees */
                                   /*    it (item 8 above); 0: the DEM's m g; default 1 */
    long long max_substeps;        /* DEM substeps one coupled step may take; a longer step is */
                                   /*    refused before anything moves; default 100000 */
    fsdem_log_fn log;              /* optional; default NULL */
    void *log_user;
} fsdem_pic_dem_desc;

FSDEM_API fsdem_pic_dem_desc fsdem_pic_dem_desc_default(void);
/* Checks a desc: both solvers set, the same dim and gravity, the ranges above. FSDEM_OK or
   FSDEM_ERR_INVALID_ARG with the reason, naming the field, in `message` (may be NULL). */
FSDEM_API fsdem_result fsdem_pic_dem_desc_check(const fsdem_pic_dem_desc *desc, char *message, size_t message_size);
/* Creates a coupler (its memory from the DEM's allocator), removes the water particles inside the
   bodies and installs the implicit term in the PIC's pressure operator. FSDEM_ERR_INVALID_ARG as
   the check (the reason also goes to desc->log), FSDEM_ERR_OUT_OF_MEMORY. fsdem_pic_dem_destroy,
   before the solvers, removes the term and the moving solids from the PIC and leaves both alive. The coupler
   owns the PIC's open, solid_velocity and reference arrays (fsdem_pic_get_coupling): every step
   resets and rewrites them (it claims them, >>couple). */
FSDEM_API fsdem_result fsdem_pic_dem_create(const fsdem_pic_dem_desc *desc, fsdem_pic_dem **out);
FSDEM_API void fsdem_pic_dem_destroy(fsdem_pic_dem *coupler);
FSDEM_API const char *fsdem_pic_dem_last_error(const fsdem_pic_dem *coupler);
/* The desc in force (contact_length resolved). */
FSDEM_API fsdem_pic_dem_desc fsdem_pic_dem_get_desc(const fsdem_pic_dem *coupler);

/* The fluid's load on one body in the last coupled step (whole body: N and N m, the 2D PIC's per
   metre values times disc_length). */
typedef struct fsdem_pic_dem_force {
    int id;                      /* stable id of the DEM particle (fsdem_dem_particles.id) */
    fsdem_vec3 pressure_force;   /* N; G of step 3 */
    fsdem_vec3 viscous_force;    /* N; step 4 */
    fsdem_vec3 torque;           /* N m; pressure and viscous, about the centre */
    fsdem_vec3 weight_correction; /* N; m g (V_g / V - 1) with desc.discrete_weight (item 8), else 0 */
    fsdem_real volume;           /* m^3; V_g, the body volume the faces normal to gravity see (item */
                                 /*    8; per metre in 2D) */
    int faces;                   /* faces the body covers or cuts */
} fsdem_pic_dem_force;

/* Load on DEM particle `index` from the last step, found by the particle's id, so removals since do
   not mix the records up. FSDEM_ERR_NOT_FOUND for a bad index, before the first step, or for a
   particle added since. */
FSDEM_API fsdem_result fsdem_pic_dem_get_force(const fsdem_pic_dem *coupler, int index, fsdem_pic_dem_force *out);
/* The records as CSV (>>couple): id, pressure_force_x .. _z, viscous_force_x .. _z, torque_x .. _z,
   weight_correction_x .. _z, volume, faces. */
FSDEM_API fsdem_result fsdem_pic_dem_write_csv(const fsdem_pic_dem *coupler, const char *path);
/* Steps 2-3 and 7 of the section at the current state, without stepping: the water particles inside
   bodies added since are removed, and every body is cut into the PIC's coupling arrays at its
   velocity (no prediction), as at creation. FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_pic_dem_update(fsdem_pic_dem *coupler);
/* One coupled step of the stable dt. The DEM substep count is checked before anything moves
   (FSDEM_ERR_INVALID_ARG above max_substeps). Errors of either solver are passed on with their
   message, and the step is put back (>>couple_step). */
FSDEM_API fsdem_result fsdem_pic_dem_step(fsdem_pic_dem *coupler);
/* One coupled step of exactly dt (s): FSDEM_ERR_INVALID_ARG for dt <= 0 or not finite or above
   max_substeps DEM substeps, FSDEM_ERR_CFL when dt exceeds the PIC's cfl_max (fsdem_pic_check_dt),
   a body would move more than cfl_max cells or dt exceeds the viscous limit; then coupler, PIC and
   DEM are exactly as they were (saved bytes and statistics). */
FSDEM_API fsdem_result fsdem_pic_dem_step_dt(fsdem_pic_dem *coupler, fsdem_real dt);
/* Coupled steps until exactly `duration` (s) later; their number goes to *steps (may be NULL). */
FSDEM_API fsdem_result fsdem_pic_dem_advance(fsdem_pic_dem *coupler, fsdem_real duration, long long *steps);
/* Stable coupled step (s): the PIC's, the bodies' speed over the PIC's cfl (cfl dx / (|V| + |w| r +
   sqrt(|g| dx))) and the viscous limit. FSDEM_ERR_NAN when a velocity is not finite. */
FSDEM_API fsdem_result fsdem_pic_dem_stable_dt(const fsdem_pic_dem *coupler, fsdem_real *dt);
/* The PIC time (s). */
FSDEM_API double fsdem_pic_dem_time(const fsdem_pic_dem *coupler);

typedef struct fsdem_pic_dem_stats {
    fsdem_coupling_stats coupling; /* steps, time, dt, substeps, CPU seconds (>>couple) */
    fsdem_vec3 fluid_force;      /* N; sum of the fluid forces on the bodies, last step */
    fsdem_real viscous_dt;       /* s; the viscous limit of the last step (0: none) */
    int contacts;                /* contacts (gap areas) after the last step */
    long long dissipated;        /* particle velocities scaled by Eq. 20, total */
    long long pushed;            /* particles moved out of bodies, total */
    long long removed;           /* particles removed inside new bodies, total */
} fsdem_pic_dem_stats;

FSDEM_API fsdem_pic_dem_stats fsdem_pic_dem_get_stats(const fsdem_pic_dem *coupler);
/* The coupler as any coupler, to step with others on the same PIC (fsdem_coupled_step: a GIC sand
   bed and resolved bodies at once). */
FSDEM_API fsdem_coupler *fsdem_pic_dem_coupler(fsdem_pic_dem *coupler);
