/* ===== >>couple_gic : Granule-In-Cell volume-fraction coupling (seed 004) ========================== */

/* Two-way coupling of PIC/FLIP water (fsdem_pic) with DEM granules smaller than a grid cell
   (fsdem_dem), through the volume fractions of seed 004 (Tang et al. 2025): the water shares each
   cell with the sand, keeps the volume the sand leaves it, and the two exchange momentum on the
   grid. Every coupled step of dt (seed 004 Algorithm 1, sand first):
     1. sand substeps (Algorithm 2): the DEM advances dt in K = fsdem_dem_substep_count substeps
        (fsdem_dem_advance_with); at every force evaluation each granule i of volume V_i (per the
        DEM's disc_length in 2D) gets from the water of the last fluid step, sampled at its centre
        (fsdem_pic_sample: velocity u, pressure gradient grad p, liquid fraction l):
          pressure-gradient force  F_p = -V_i grad p                               (Eq. 5a)
          drag                     F_d = s c V_i (u - v_i)                         (Eq. 5b, or >>drag)
        with c of desc.drag at the porosity eps of the granule's position (the cells' alpha_f'
        interpolated) and s = desc.drag_scale, and with desc.virtual_mass its added mass
        m_a = C_a rho_f V_i l (C_a = 1/2 for a sphere, Eq. 5c; 1 for a disc, the potential-flow
        value of a cylinder) in the inertia of Eq. 14, (m + m_a) dv/dt = m_a a_f + F_o, where
        a_f = g - grad p / rho_f is the water's acceleration of the last step at the granule and
        F_o = F_c + m g + l (F_p + F_d) every other force, the contacts F_c of the evaluation
        included. Eq. 17's a_f also holds the exchange, F_s / (rho_f alpha_f); it is left out: held
        from the last step it feeds the virtual-mass reaction back on itself with the gain
        C_a alpha_s / alpha_f (the water's acceleration from the granules' added mass over the
        water's own mass in the cell), above 1 wherever alpha_s > 1/3 for spheres (1/2 for discs),
        and a ball of sand entering water at 1 m/s then diverged within tens of steps. The DEM keeps the mass m, so the granule is given the load
        F_ext that makes its m dv/dt = F_c + m g + F_ext the motion of Eq. 14:
          F_ext = (m l (F_p + F_d) + m m_a (a_f - g) - m_a F_c) / (m + m_a),
        whose part beyond l (F_p + F_d) is the virtual-mass force F_v = m_a (a_f - dv/dt) (Eq. 5c).
        A granule in air (l = 0) feels none of them. With the predictor-corrector integrator F_c is
        that of the substep's start (its loads are held over the substep);
     2. momentum exchange (Eq. 18): each evaluation's -(l F_d + F_v) goes to the water's faces around the
        granule (fsdem_pic_add_force, tent kernel of half-width max(r_i, dx)) weighted by the time
        the DEM integrator holds it (h/2, h, ..., h, h/2 for Verlet substeps of h, h for the
        predictor-corrector) over dt, so the water gains exactly the impulse the granules' drag
        and virtual mass lost. F_p is not exchanged: the water's own step applies -grad p to the liquid's volume
        alpha_f (Eq. 8 with Eq. 3's -alpha_f grad p), and -V_i grad p is the same mixture pressure
        on the granule's volume; handing its reaction to the water too would count the pressure on
        the granules' volume twice (a fixed bed under still water would then hold
        grad p = rho g alpha_f / (alpha_f - alpha_s), not rho g);
     3. granule volume fraction at the cell centres from the new positions (Eq. 7a),
        alpha_s = sum_i V_i N(x_i - x) / dx^dim with the tent kernel N, the weight that would fall
        outside the grid folded into the boundary cell (so sum alpha_s dx^dim = sum V_i exactly),
        capped at desc.max_solid_fraction (§5.1: 0.740 in 3D, 0.907 in 2D); alpha_f' = 1 - alpha_s
        becomes the PIC's porosity (fsdem_pic_coupling.porosity);
     4. one PIC step of dt: the variable-coefficient velocity projection (Eq. 11/12a) after the
        exchanged accelerations, div(alpha_f' u) = 0 as the seed prints it or, with
        desc.displacement_flow, the mixture's continuity
        div(alpha_f' u) = -l (alpha_f'(new) - alpha_f'(old)) / dt (the porosities of step 3 and
        of the step before, l the cell's liquid fraction), so that the water's velocity carries
        the volume the granules leave and take (a settling grain's return flow: the momentum of
        grain and water is then (rho_s - rho_f) V w, not rho_s V w); and after advection the
        density projection towards alpha_f' (Eq. 12b-13, the ratio clamped to [0.5, 1.5], moves
        within a cell), which pushes water out of the space the sand took and lets it into the
        space the sand left.
   The granule forces of a substep use the fluid of the last step (§5.2); before the PIC's first
   step, which has solved no pressure yet, grad p is that of water at rest, rho_f g. The stable coupled step
   (Eq. 33) is the PIC's, at most desc.cfl dx / max |v_i| and desc.max_dt_ratio times the DEM's dt
   (1000 in the seed), and at most desc.drag_dt_fraction of the shortest drag relaxation time of a
   granule, m_i / (s c V_i), or of the water round it, alpha_f rho / (alpha_s s c), since the
   exchange is explicit for the water: c at the granule's slip against the water of the last step
   plus what its present acceleration (loads and gravity, for a granule without contacts) adds
   within the step, for the granules in the water and those that reach it within the step
   (against water at rest); a granule released from rest, whose drag of Eq. 5b is 0 at zero slip,
   is so limited from the first step on.
   Ownership: the coupler claims the PIC's porosity and its accelerations (it zeroes them at the start
   of every step, fsdem_pic_clear_forces) and the DEM's external forces (>>couple); a resolved
   PIC-DEM on the same PIC, with its own DEM, steps with it (fsdem_coupled_step).
   Not built yet: the concentration-gradient and capillary forces (Eq. 21-31), wetting
   (Eq. 19-20). The viscous stress of Eq. 3 is the PIC's nu lap(u), not div(alpha_f T). */

typedef struct fsdem_gic fsdem_gic;

typedef struct fsdem_gic_desc {
    fsdem_pic *pic;               /* water; not owned; must outlive the coupler */
    fsdem_dem *dem;               /* granules; same dim and gravity as the PIC; not owned */
    fsdem_drag_law drag;          /* default FSDEM_DRAG_LAW_GIC (seed 004 Eq. 5b) */
    fsdem_real drag_scale;        /* -; factor on the law's coefficient, in [1e-3, 1e3] (a */
                                  /*    calibration, not another law); default 1 (0.1 with the */
                                  /*    GIC law is the seed's mu = 0.044 of §6.1) */
    int virtual_mass;             /* 1: the granules' added mass, Eq. 14-17 (see step 1); default 0: */
                                  /*    explicit, it diverged in dense sand entering water at 1 m/s */
                                  /*    (validation/gic_volume); dilute granules take it well */
    fsdem_real viscosity;         /* m^2/s; kinematic viscosity the drag laws use, as the PIC's */
                                  /*    (all but the GIC law need one); 0: the PIC's; default 0 */
    fsdem_real max_solid_fraction; /* -; cap of alpha_s in [0.5, 1) (below random loose */
                                  /*    packing, 0.55, it would cap beds of touching granules); */
                                  /*    0: 0.740 in 3D, 0.907 in 2D (densest packings, §5.1); */
                                  /*    default 0 */
    fsdem_real cfl;               /* -; Eq. 33: dt <= cfl dx / max |v_granule|, in [0.01, 1] (a */
                                  /*    granule crosses at most one cell a step; below 0.01 the */
                                  /*    step only shrinks); default 1 */
    fsdem_real max_dt_ratio;      /* -; Eq. 33: dt <= this x the DEM's dt, >= 1; default 1000 */
    fsdem_real drag_dt_fraction;  /* -; dt <= this x the shortest drag relaxation time, in */
                                  /*    [0.01, 1]; default 0.5 */
    long long max_substeps;       /* DEM substeps one coupled step may take; a longer step is */
                                  /*    refused before anything moves; default 100000 */
    int displacement_flow;        /* 1: the velocity projection carries the granules' change of */
                                  /*    alpha_f' (step 4; written into the PIC's pressure_rhs for */
                                  /*    its step); default 0: Eq. 12a as printed, */
                                  /*    div(alpha_f' u) = 0 (with 1, the dense ball of */
                                  /*    validation/gic_volume diverges as it enters the water; a */
                                  /*    settling grain takes it: tests/test_couple_gic.c) */
    fsdem_log_fn log;             /* optional; default NULL */
    void *log_user;
} fsdem_gic_desc;

FSDEM_API fsdem_gic_desc fsdem_gic_desc_default(void);
/* Checks a desc: both solvers set, the same dim and gravity, the ranges above, a viscosity for a
   law that needs one. FSDEM_OK or FSDEM_ERR_INVALID_ARG with the reason, naming the field, in
   `message` (may be NULL). */
FSDEM_API fsdem_result fsdem_gic_desc_check(const fsdem_gic_desc *desc, char *message, size_t message_size);
/* Creates a coupler (its memory from the DEM's allocator). FSDEM_ERR_INVALID_ARG as the check (the
   reason also goes to desc->log), FSDEM_ERR_OUT_OF_MEMORY. fsdem_gic_destroy, before the solvers,
   leaves them alive. */
FSDEM_API fsdem_result fsdem_gic_create(const fsdem_gic_desc *desc, fsdem_gic **out);
FSDEM_API void fsdem_gic_destroy(fsdem_gic *coupler);
FSDEM_API const char *fsdem_gic_last_error(const fsdem_gic *coupler);
/* The desc in force (viscosity and max_solid_fraction resolved). */
FSDEM_API fsdem_gic_desc fsdem_gic_get_desc(const fsdem_gic *coupler);

/* Step 3 of the section at the current granule positions: alpha_s and the PIC's porosity. A step
   does it after its substeps; call it once the granules are placed, so that the first step's
   density projection already knows where the sand is. FSDEM_ERR_NAN (a granule position is not
   finite) and FSDEM_ERR_OUT_OF_DOMAIN (a granule outside the PIC's grid), naming the granule;
   nothing changed then. */
FSDEM_API fsdem_result fsdem_gic_update(fsdem_gic *coupler);

/* Volume fractions on the PIC's cells (layout of fsdem_pic_fields), from the last update; valid
   while the coupler lives. */
typedef struct fsdem_gic_fields {
    int dim;
    int n[3];                        /* cells per axis (n[2] = 1 in 2D) */
    fsdem_real cell_size;            /* m */
    fsdem_vec3 origin;               /* m, lower corner */
    const fsdem_real *solid_fraction; /* -; alpha_s of Eq. 7a before the cap */
    const fsdem_real *porosity;      /* -; alpha_f' = 1 - min(alpha_s, max_solid_fraction) */
} fsdem_gic_fields;

FSDEM_API fsdem_gic_fields fsdem_gic_get_fields(const fsdem_gic *coupler);

/* Fluid state and forces at one granule, from the last force evaluation of the last step. */
typedef struct fsdem_gic_force {
    int id;                       /* stable id of the DEM particle (fsdem_dem_particles.id) */
    fsdem_vec3 pressure;          /* N; l F_p (Eq. 5a) */
    fsdem_vec3 drag;              /* N; l F_d (Eq. 5b or the chosen law) */
    fsdem_vec3 virtual_mass;      /* N; F_v (Eq. 5c, 14), 0 without desc.virtual_mass */
    fsdem_vec3 fluid_velocity;    /* m/s; u at the granule */
    fsdem_vec3 fluid_acceleration; /* m/s^2; a_f at the granule (>>couple_gic step 1) */
    fsdem_real porosity;          /* -; eps at the granule */
    fsdem_real liquid;            /* -; l, the liquid fraction at the granule (0: dry) */
} fsdem_gic_force;

/* Forces on DEM particle `index` from the last step, found by the particle's id.
   FSDEM_ERR_NOT_FOUND for a bad index, before the first step (or after a restore), or for a
   particle added since. */
FSDEM_API fsdem_result fsdem_gic_get_force(const fsdem_gic *coupler, int index, fsdem_gic_force *out);
/* The records as CSV (>>couple): id, pressure_x .. _z, drag_x .. _z, virtual_mass_x .. _z,
   fluid_velocity_x .. _z, fluid_acceleration_x .. _z, porosity, liquid. */
FSDEM_API fsdem_result fsdem_gic_write_csv(const fsdem_gic *coupler, const char *path);
/* One coupled step of the stable dt. */
FSDEM_API fsdem_result fsdem_gic_step(fsdem_gic *coupler);
/* One coupled step of exactly dt (s): FSDEM_ERR_INVALID_ARG for dt <= 0 or not finite or above
   max_substeps DEM substeps, FSDEM_ERR_CFL when dt exceeds the PIC's cfl_max (fsdem_pic_check_dt)
   or the drag limit; nothing moved then. Errors of either solver during the step are passed on
   with their message, and the step is put back (>>couple_step). */
FSDEM_API fsdem_result fsdem_gic_step_dt(fsdem_gic *coupler, fsdem_real dt);
/* Coupled steps until exactly `duration` (s) later; their number goes to *steps (may be NULL). */
FSDEM_API fsdem_result fsdem_gic_advance(fsdem_gic *coupler, fsdem_real duration, long long *steps);
/* Stable coupled step (s) of the section (Eq. 33 and the drag limit).
   FSDEM_ERR_NAN when a velocity is not finite. */
FSDEM_API fsdem_result fsdem_gic_stable_dt(const fsdem_gic *coupler, fsdem_real *dt);
/* The PIC time (s). */
FSDEM_API double fsdem_gic_time(const fsdem_gic *coupler);

typedef struct fsdem_gic_stats {
    fsdem_coupling_stats coupling; /* steps, time, dt, substeps, CPU seconds (>>couple; the force */
                                  /*    evaluations count as the DEM's, in its substeps) */
    int wet;                      /* granules with l > 0 at the last evaluation */
    fsdem_vec3 pressure_impulse;  /* N s; the granules' Eq. 5a impulse over the last step */
    fsdem_vec3 drag_impulse;      /* N s; the granules' drag impulse over the last step */
    fsdem_vec3 virtual_mass_impulse; /* N s; the granules' virtual-mass impulse, last step */
    fsdem_vec3 to_fluid;          /* N s; the impulse handed to the water's faces, last step, in the */
                                  /*    DEM's units (the water gets it per metre of depth in 2D) */
    fsdem_vec3 lost;              /* N s; exchange with no liquid face in reach (dropped) */
    fsdem_real drag_dt;           /* s; shortest drag relaxation time at the last step's start, of a */
                                  /*    granule or of a cell's water (0: none; >>couple_gic) */
    fsdem_real max_solid_fraction; /* -; largest alpha_s of the last update, before the cap */
    fsdem_real solid_volume;      /* m^3 (m^2 in 2D); sum of alpha_s dx^dim, = the granules' volume */
} fsdem_gic_stats;

FSDEM_API fsdem_gic_stats fsdem_gic_get_stats(const fsdem_gic *coupler);
/* The coupler as any coupler, to step with others on the same PIC (fsdem_coupled_step: a sand bed
   and resolved bodies at once). */
FSDEM_API fsdem_coupler *fsdem_gic_coupler(fsdem_gic *coupler);
