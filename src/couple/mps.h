/* ===== >>couple_mps : unresolved MPS-DEM, Models A and B (seed 002) ================================ */

/* Two-way coupling of MPS water (fsdem_mps) with DEM sediment (fsdem_dem) by local averaging, after
   seed 002 §2.1-2.4. The DEM particles are smaller than the MPS spacing (unresolved): the water sees
   them through a porosity field and a momentum exchange, computed with the weight
       w_s(r) = 4 (r/r_e)^5 - 5 (r/r_e)^4 + 1 for r < r_e, 0 beyond               (Eq. 29)
   whose integral over space is n_s = (10 pi / 21) r_e^3 in 3D (Eq. 30) and, by the same integral
   over the plane (int_0^1 (4x^5 - 5x^4 + 1) 2 pi x dx = 2 pi (4/7 - 5/6 + 1/2)), n_s = (10 pi / 21)
   r_e^2 in 2D, where volumes are areas per unit depth (a disc of radius R stands for pi R^2).
   Every coupled step:
     1. porosity of the FLUID particles, eps_i = 1 - sum_k w_s(r_ik) V_k / n_s (Eq. 31), not let
        below desc.min_porosity; written to the MPS (its Eq. 7-16 use 1/eps_j). WALL and DUMMY
        particles keep eps = 1: they sit on the fixed r0 lattice, so a 1/eps on them would count
        them more than once in the number density of their neighbours and read a bed on the floor
        as compressed (the bottom pressure of a settled bed came out twice hydrostatic).
        Within r_e of a wall or obstacle n_s is reduced by the part of the weight's integral that
        lies inside the solid (the sum of w_s r0^d over its WALL and DUMMY particles): Eq. 31 as
        printed reads a bed packed against a wall as looser there (not done at the free surface);
     2. at each DEM particle k, over the FLUID particles i within r_e: porosity eps_k (Eq. 32), fluid
        velocity u_k (Eq. 33), and for Model A the pressure gradient grad P_k, the same w_s average
        of the gradients the MPS corrector applied to those particles;
     3. drag F^d = c V_k (u_k - v_k) with c = beta/(1 - eps) of the chosen law (>>drag; Eq. 25-28
        with FSDEM_DRAG_LAW_ERGUN_WEN_YU) and the force on the particle (held over the DEM substeps):
          Model A (the MPS desc.model):  F^int = F^d - V_k grad P_k            (Eq. 34)
          Model B:                       F^int = F^d / eps_k - V_k rho_f g     (Eq. 35);
     4. the reaction on the fluid (Eq. 36): FLUID particle i gets -sum_k X_k w_s(r_ki) s_i / W_k
        with W_k = sum_j w_s(r_kj) s_j over the FLUID particles j, where X_k is the force that the
        fluid and the solid exchange: F^d (Model A, Eq. 2: the solid's -V grad P is the mixture
        pressure acting on the solid's volume, as -grad P on its own volume acts on each fluid
        particle) or F^int (Model B, Eq. 4: f_B). Each X_k is split into weights that sum to one,
        so the fluid gets exactly -sum_k X_k: the exchange conserves momentum to rounding (Shepard:
        W_k is the sum of the weights actually present, cut by walls, the free surface or nothing,
        never the analytic n_s), which fsdem_mps_dem_stats audits every update (exchange_residual).
        The share factor s_i = n_s / (eps_i n_s,i), with n_s,i the normaliser of step 1, makes the
        reaction a force density gathered at the particle, as its porosity is: the particle stands
        for r0^d / eps_i of mixture, and its kernel is cut by walls as n_s,i says. In a uniform bed
        every particle then gets the same reaction per volume, next to walls too; with Eq. 36 as
        printed (s_i = 1) the water within r0 of a wall got 0.5-0.7 of the bulk's, which in Model B
        (whose reaction at rest is the grains' buoyancy, as large as the water's own weight in a
        packed bed) drove a circulation along the walls: a bed of fixed spheres under still water
        between walls had its water at 0.25-0.33 m/s and its floor pressure falling to 0.83 rho g H
        in 0.3 s; with s_i, 0.06-0.14 m/s and 0.97-0.99 rho g H (as Model A, and as the same bed in
        a laterally periodic cell). In the bulk s_i = 1 / eps_i, the same for all neighbours of a
        grain in a uniform bed, so the split is Eq. 36's there;
     5. one MPS step of dt, then the DEM over the same dt in K = fsdem_dem_substep_count substeps
        (fsdem_dem_advance) with the forces of 3 held: the sequential staggered scheme with the
        MPS step of Eq. 37 and DEM steps of Eq. 38 (Sun et al. 2021's MSS as the seed uses it; here
        the forces are held, not interpolated, over the substeps).
   Models A and B term by term (seed 002 Eq. 2, 4, 34-35; Zhou, Kuang, Chu & Yu 2010 compare the
   two formulations):
     A: the grain gets F^d - V grad P (the whole pressure gradient, hydrostatic and dynamic, as
        its buoyancy) and the fluid -F^d; the fluid's own pressure term is -eps grad P.
     B: the grain gets F^d / eps - V rho_f g (Archimedes on the hydrostatic part only; the 1/eps
        carries the grain's share of the dynamic gradient) and the fluid -(F^d / eps - V rho_f g);
        the fluid's pressure term is -grad P.
   Limits, from the grain's and the fluid's momentum per unit volume (n = (1 - eps) / V grains):
     single grain (eps -> 1, still water, grad P = rho_f g): both give F^d - V rho_f g, drag plus
        Archimedes, so the same terminal velocity (tests: a grain at rest in still water, terminal
        velocities);
     steady uniform suspension over a floor: A: -eps grad P + eps rho_f g - n F^d = 0 and
        F^d - V grad P + rho_s V g = 0 give F^d = -eps (rho_s - rho_f) V g; B: F^d / eps - V rho_f g
        + rho_s V g = 0 gives the same. A drag law fitted to hindered settling (Richardson-Zaki)
        therefore reaches the grain alike in both; mixing the conventions (B's F^d / eps with A's
        -V grad P) gives F^d = -eps^2 (rho_s - rho_f) V g, off by 1/eps (validation/mpsdem_settling);
     fixed bed with the fluid driven through it: both give grad P_dynamic = beta w / eps, Ergun's
        law term by term with the Ergun branch (validation/mpsdem_fixed_bed).
   Periodic axes: an MPS with periodic axes couples to a DEM periodic along the same axes with the
   same periods (fsdem_mps_dem_desc_check); pairs, porosities, averages and reactions take minimum
   images, so a bed or a suspension can be a periodic cell with no side walls.
   The averaging radius (desc.averaging_radius, the r_e of Eq. 29-36) defaults to the MPS re as the
   seed has it. Ergun is steep in eps, and the porosity, fluid velocity and reactions are smoothed
   over r_e: within r_e of a bed's face a grain averages in clear water (a slip of U instead of
   U / eps), so in a bed not many r_e deep the drag falls short. A radius of 2-3 grain diameters
   and at most a tenth of the bed's height keeps the faces sharp; below about 2 r0 the averages
   see too few MPS particles to be smooth.
   The MPS particle velocity is the intrinsic fluid velocity u_f and each MPS particle carries the
   fluid mass rho_f r0^d: in a porous region it stands for a volume of mixture r0^d / eps, which is
   what the 1/eps_j of Eq. 7 counts (so the particles spread where solids are). Eq. 2 and 4 are the
   momentum of that volume; their D eps / Dt terms (u_d = eps u_f, eps changing along the path) are
   not included.
   Held forces are explicit: a step longer than the drag relaxation time of a particle, m_k /
   (c V_k) (with Model B's 1/eps_k), would overshoot, and so would one longer than the water's,
   rho_f r0^d over its shares of the grains' coefficients (eps rho_f / beta in a uniform bed: 7 ms
   in a bed of 2 mm grains at Re_p 100, shorter than the MPS's CFL step), so the coupled stable
   step is also at most desc.drag_dt_fraction of the shortest of both. Virtual mass, lift and lubrication forces are not
   included (the seed leaves them out, §2.3).
   Loads on a structure come in the seed's two parts (Fig. 18-19): the fluid's, the pressure on a
   box obstacle of the MPS (fsdem_mps_obstacle_force), and the sediment's, the contact force on a
   DEM wall at the same place (fsdem_dem_wall_force); validation/mpsdem_obstacle records both. */

typedef struct fsdem_mps_dem fsdem_mps_dem;

typedef struct fsdem_mps_dem_desc {
    fsdem_mps *mps;               /* water; not owned; must outlive the coupler */
    fsdem_dem *dem;               /* sediment; same dim and gravity as the MPS; not owned */
    fsdem_drag_law drag;          /* default FSDEM_DRAG_LAW_ERGUN_WEN_YU (seed 002 Eq. 26) */
    fsdem_real averaging_radius;  /* m; r_e of w_s (Eq. 29), the reach of the porosity, the fluid */
                                  /*    velocity at the grains and the reactions; 0: the MPS re */
                                  /*    (4.1 r0 by default), which the seed's text implies; default 0. */
                                  /*    Ergun is steep in eps: for a bed, 2-3 grain diameters and at */
                                  /*    most a tenth of its height keep its faces sharp, and at */
                                  /*    least about 2 r0 keep the fluid average smooth (see notes) */
    fsdem_real min_porosity;      /* -; floor of eps_i (Eq. 31 can go below 0 where DEM particles */
                                  /*    overlap in a kernel), in (0, 1); default 0.2 */
    fsdem_real drag_dt_fraction;  /* -; coupled step <= this fraction of the shortest drag */
                                  /*    relaxation time, in (0, 1]; default 0.5 */
    long long max_substeps;       /* DEM substeps one coupled step may take; a longer step is */
                                  /*    refused before anything moves; default 100000 */
    fsdem_log_fn log;             /* optional; default NULL */
    void *log_user;
} fsdem_mps_dem_desc;

FSDEM_API fsdem_mps_dem_desc fsdem_mps_dem_desc_default(void);
/* Checks a desc: both solvers set, the same dim and gravity, the same periodic axes with the same
   periods (each longer than twice the averaging radius), no open planes in the MPS, the ranges
   above. FSDEM_OK or FSDEM_ERR_INVALID_ARG with the reason, naming the field, in `message` (may be
   NULL). */
FSDEM_API fsdem_result fsdem_mps_dem_desc_check(const fsdem_mps_dem_desc *desc, char *message, size_t message_size);
/* Creates a coupler (its memory from the DEM's allocator). FSDEM_ERR_INVALID_ARG as the check
   (the reason also goes to desc->log), FSDEM_ERR_OUT_OF_MEMORY. fsdem_mps_dem_destroy, before the
   solvers, leaves them alive. */
FSDEM_API fsdem_result fsdem_mps_dem_create(const fsdem_mps_dem_desc *desc, fsdem_mps_dem **out);
FSDEM_API void fsdem_mps_dem_destroy(fsdem_mps_dem *coupler);
FSDEM_API const char *fsdem_mps_dem_last_error(const fsdem_mps_dem *coupler);
/* The desc in force (radius resolved). */
FSDEM_API fsdem_mps_dem_desc fsdem_mps_dem_get_desc(const fsdem_mps_dem *coupler);

/* Fluid state and forces at one DEM particle, from the last update. */
typedef struct fsdem_mps_dem_force {
    int id;                       /* stable id of the DEM particle (fsdem_dem_particles.id) */
    fsdem_vec3 drag;              /* N; F^d of Eq. 25 */
    fsdem_vec3 pressure;          /* N; -V grad P (Model A, Eq. 34) or -V rho_f g (Model B, Eq. 35) */
    fsdem_vec3 total;             /* N; F^int, the external force the DEM particle is given */
    fsdem_vec3 fluid_velocity;    /* m/s; u_k of Eq. 33 */
    fsdem_real porosity;          /* -; eps_k of Eq. 32 (1 when dry) */
    fsdem_real reynolds;          /* -; Eq. 28 */
    int wet;                      /* 1 when FLUID particles are within the radius (else no force) */
} fsdem_mps_dem_force;

/* Steps 1-4 of the section at the current state: porosities into the MPS, forces into the DEM's
   external loads and the reactions into the MPS's coupling forces. A step does it first; call it to
   see the fields without stepping. FSDEM_ERR_OUT_OF_MEMORY (nothing changed), FSDEM_ERR_NAN (a
   force is not finite; the particle is named). */
FSDEM_API fsdem_result fsdem_mps_dem_update(fsdem_mps_dem *coupler);
/* Forces on DEM particle `index` from the last update, found by the particle's id, so removals
   since do not mix the records up. FSDEM_ERR_NOT_FOUND for a bad index, before the first update, or
   for a particle added since. */
FSDEM_API fsdem_result fsdem_mps_dem_get_force(const fsdem_mps_dem *coupler, int index, fsdem_mps_dem_force *out);
/* The records as CSV (>>couple): id, drag_x .. _z, pressure_x .. _z, total_x .. _z,
   fluid_velocity_x .. _z, porosity, reynolds, wet. */
FSDEM_API fsdem_result fsdem_mps_dem_write_csv(const fsdem_mps_dem *coupler, const char *path);
/* One coupled step of the stable dt (fsdem_mps_dem_stable_dt after the update). The DEM substep
   count is checked before anything moves (FSDEM_ERR_INVALID_ARG above max_substeps). Errors of
   either solver are passed on with their message, and the step is put back (>>couple_step). */
FSDEM_API fsdem_result fsdem_mps_dem_step(fsdem_mps_dem *coupler);
/* One coupled step of exactly dt (s): FSDEM_ERR_CFL, nothing moved, when dt exceeds the MPS CFL
   step (Eq. 37) or the drag limit of the section. */
FSDEM_API fsdem_result fsdem_mps_dem_step_dt(fsdem_mps_dem *coupler, fsdem_real dt);
/* Coupled steps until exactly `duration` (s) later; their number goes to *steps (may be NULL). */
FSDEM_API fsdem_result fsdem_mps_dem_advance(fsdem_mps_dem *coupler, fsdem_real duration, long long *steps);
/* Stable coupled step (s): the MPS's (Eq. 37) and the drag limit of the last update. */
FSDEM_API fsdem_result fsdem_mps_dem_stable_dt(const fsdem_mps_dem *coupler, fsdem_real *dt);
/* The MPS time (s). */
FSDEM_API double fsdem_mps_dem_time(const fsdem_mps_dem *coupler);

typedef struct fsdem_mps_dem_stats {
    fsdem_coupling_stats coupling; /* steps, time, dt, substeps, CPU seconds (>>couple; the */
                                  /*    update's time counts as the coupling's) */
    int wet;                      /* DEM particles in water at the last update */
    fsdem_vec3 drag;              /* N; sum of F^d, last update */
    fsdem_vec3 pressure;          /* N; sum of the pressure parts (-V grad P or -V rho g) */
    fsdem_vec3 to_fluid;          /* N; sum of the reactions given to the fluid (= -sum X_k) */
    fsdem_vec3 exchanged;         /* N; sum of X_k, what the grains take from the fluid (step 4) */
    fsdem_real exchange_residual; /* N; |to_fluid + exchanged|, the momentum the exchange loses: */
                                  /*    rounding only, whatever walls, free surface or periodic */
                                  /*    images cut the kernels (the audit of step 4) */
    fsdem_real drag_dt;           /* s; the shortest drag relaxation time of the last update, of */
                                  /*    a grain or of the water (0: none) */
    long long pairs;              /* DEM-MPS pairs within the radius, last update */
} fsdem_mps_dem_stats;

FSDEM_API fsdem_mps_dem_stats fsdem_mps_dem_get_stats(const fsdem_mps_dem *coupler);
/* The coupler as any coupler (fsdem_coupled_step). */
FSDEM_API fsdem_coupler *fsdem_mps_dem_coupler(fsdem_mps_dem *coupler);
