/* ===== >>couple_swe : SWE-DEM floating debris (seed 003) ========================================== */

/* Two-way coupling of a shallow-water solver (1D along x, or 2D in x-y) with DEM debris after seed 003
   Eq. 3-8. The debris are the spheres of a 3D fsdem_dem whose z axis is vertical (gravity along -z);
   the water surface and velocity at a sphere come from the fsdem_swe. On each sphere:
     buoyancy      F_b = rho g V_sub, upwards, V_sub the submerged spherical cap (Eq. 5);
     horizontal    F_h = p_B S_B - p_F S_F per horizontal axis (Eq. 6-7): the hydrostatic part
                   rho g z integrated over the submerged circular segments of the sphere's back and
                   front (with the surface elevations sampled at x - r and x + r), plus the dynamic
                   pressure rho (beta u - w)^2 on the side facing the relative flow.
   The vertical position follows from buoyancy against gravity in the DEM (floating), and a sphere in
   water too shallow to float it rests on the bed with friction when the DEM has a bed wall (a plane,
   or fsdem_swe_bed_sdf for the solver's own bathymetry). On the water, the reaction -F_h is a momentum
   source spread over the wet cells under the sphere's footprint as force per unit plan area divided by
   rho (Eq. 8 as printed, S_px = p/rho, is loose about units; this form makes the exchange exact: the
   water gains exactly -F_h dt per step while the debris gains F_h dt).
   Each coupled step: forces from the current state, one SWE step dt, then K DEM substeps of dt/K
   (seed 000 Eq. 25, fsdem_dem_advance_with) with the horizontal forces held fixed and the buoyancy
   (and heave damping) recomputed at every DEM force evaluation from the sphere's height against the
   held water surface: buoyancy is a stiff spring, and holding it over a whole fluid step would let
   bobbing grow without bound. A horizontal force is only applied while wet cells under (or next to)
   the sphere can take its reaction. The coupler owns the SWE's momentum sources and the DEM's
   external forces (it claims them, >>couple), and reaches both solvers through their coupling
   functions only (>>doc). */

typedef struct fsdem_swe_dem fsdem_swe_dem;

typedef struct fsdem_swe_dem_desc {
    fsdem_swe *swe;               /* water; not owned; must outlive the coupler */
    fsdem_dem *dem;               /* debris: dim 3, gravity along -z; not owned */
    fsdem_real beta;              /* -; surface-velocity correction of seed 003 Eq. 6; default 1.1 */
    int two_way;                  /* 1: the water feels the reaction (Eq. 8); 0: one-way; default 1 */
    fsdem_real heave_damping;     /* -; fraction of critical damping of the bobbing about the floating
                                     draft (wave radiation is not in the SWE); default 0 */
    long long max_substeps;       /* DEM substeps one coupled step may take; a longer step is refused
                                     before anything moves; default 100000 */
    fsdem_log_fn log;             /* optional; default NULL */
    void *log_user;
} fsdem_swe_dem_desc;

FSDEM_API fsdem_swe_dem_desc fsdem_swe_dem_desc_default(void);
/* Creates a coupler. FSDEM_ERR_INVALID_ARG (missing solver, DEM not 3D, gravity not along -z or
   different from the SWE's, beta <= 0, negative damping; the reason goes to desc->log and to
   `message` of fsdem_swe_dem_desc_check), FSDEM_ERR_OUT_OF_MEMORY. Destroy with fsdem_swe_dem_destroy
   before the solvers (it leaves them alive). */
FSDEM_API fsdem_result fsdem_swe_dem_desc_check(const fsdem_swe_dem_desc *desc, char *message, size_t message_size);
FSDEM_API fsdem_result fsdem_swe_dem_create(const fsdem_swe_dem_desc *desc, fsdem_swe_dem **out);
FSDEM_API void fsdem_swe_dem_destroy(fsdem_swe_dem *coupler);
FSDEM_API const char *fsdem_swe_dem_last_error(const fsdem_swe_dem *coupler);

/* Fluid forces on one sphere, as the last update computed them (fsdem_swe_dem_update). */
typedef struct fsdem_swe_dem_force {
    int id;                       /* stable id of the DEM particle (fsdem_dem_particles.id) */
    fsdem_vec3 buoyancy;          /* N, (0, 0, rho g V_sub) */
    fsdem_vec3 hydrostatic;       /* N, horizontal */
    fsdem_vec3 dynamic;           /* N, horizontal */
    fsdem_vec3 heave;             /* N, vertical damping (0 unless heave_damping > 0) */
    fsdem_real submerged_volume;  /* m^3 */
    fsdem_real frontal_area;      /* m^2, submerged area facing +x (S_F of seed 003 along x) */
    fsdem_real surface;           /* m, water surface at the centre, held over the DEM substeps */
    int wet;                      /* 1 when water reaches the sphere */
} fsdem_swe_dem_force;

/* Computes the fluid forces on every free sphere from the current states, writes them to the DEM's
   external forces and, with two_way, the reactions to the SWE's momentum sources. A step does it
   first; call it to see the forces without stepping. FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_swe_dem_update(fsdem_swe_dem *coupler);
/* Forces on particle `index` from the last update (zero for fixed particles and dry spheres), found
   by the particle's id, so removals since do not mix the records up. FSDEM_ERR_NOT_FOUND for a bad
   index or a particle added since the update. */
FSDEM_API fsdem_result fsdem_swe_dem_get_force(const fsdem_swe_dem *coupler, int index, fsdem_swe_dem_force *out);
/* The records as CSV (>>couple): id, buoyancy_x .. _z, hydrostatic_x .. _z, dynamic_x .. _z,
   heave_x .. _z, submerged_volume, frontal_area, surface, wet. */
FSDEM_API fsdem_result fsdem_swe_dem_write_csv(const fsdem_swe_dem *coupler, const char *path);
/* One coupled step of the SWE's stable dt: update the forces, the SWE step, then the DEM over the
   same dt in substeps. The substep count is checked first, so a step the DEM cannot take (more than
   max_substeps) is refused with FSDEM_ERR_INVALID_ARG before anything moves. Errors of either
   solver are passed on with their message, and the step is put back (>>couple_step). */
FSDEM_API fsdem_result fsdem_swe_dem_step(fsdem_swe_dem *coupler);
/* One coupled step of dt (s); FSDEM_ERR_CFL (nothing moved) when it is unstable for the SWE
   (fsdem_swe_check_dt). */
FSDEM_API fsdem_result fsdem_swe_dem_step_dt(fsdem_swe_dem *coupler, fsdem_real dt);
/* Coupled steps until exactly `duration` (s) later; their number goes to *steps (may be NULL). */
FSDEM_API fsdem_result fsdem_swe_dem_advance(fsdem_swe_dem *coupler, fsdem_real duration, long long *steps);
/* The SWE's stable dt (s). */
FSDEM_API fsdem_result fsdem_swe_dem_stable_dt(const fsdem_swe_dem *coupler, fsdem_real *dt);
/* The SWE's time (s). */
FSDEM_API double fsdem_swe_dem_time(const fsdem_swe_dem *coupler);
FSDEM_API fsdem_swe_dem_desc fsdem_swe_dem_get_desc(const fsdem_swe_dem *coupler);

typedef struct fsdem_swe_dem_stats {
    fsdem_coupling_stats coupling; /* steps, time, dt, substeps, CPU seconds (>>couple) */
    int wet;                      /* spheres in water at the last update */
    fsdem_vec3 impulse_to_water;  /* N s, momentum given to the water by the reactions, total */
} fsdem_swe_dem_stats;

FSDEM_API fsdem_swe_dem_stats fsdem_swe_dem_get_stats(const fsdem_swe_dem *coupler);
/* The coupler as any coupler, to step with others on the same SWE (fsdem_coupled_step). */
FSDEM_API fsdem_coupler *fsdem_swe_dem_coupler(fsdem_swe_dem *coupler);
