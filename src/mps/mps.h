/* ===== >>mps : MPS free-surface solver (seed 002) ================================================== */

/* Incompressible free-surface flow by the Moving Particle Semi-implicit method (Koshizuka and Oka
   1996) in the form of seed 002 §2.1: the Zhang kernel (Eq. 6), number density, gradient,
   divergence and Laplacian with the 1/eps_j factor of a per-particle porosity (Eq. 7-11), the
   mixed source term of the pressure Poisson equation (Eq. 12, gamma = 0.01; Eq. 13, the source
   times the porosity eps_i, with desc.model = FSDEM_MPS_MODEL_B), free-surface detection
   by number density and neighbour asymmetry (Eq. 14-16), and the CFL rule of Eq. 37 (§2.4).
   Around it: probes and gauges (pressure sensors, water level, force on an obstacle; a CSV series
   at exact output times), particle snapshots (fsdem_mps_write_vtp in >>io) and save/restore
   (>>restart).

   Two schemes find the pressure (desc.scheme). The default is weakly compressible and explicit
   (FSDEM_MPS_SCHEME_EXPLICIT: a density per particle, an equation of state, no pressure equation),
   chosen by measurement (issue 35; validation/mps_still_water, mps_dambreak_2d, mps_spheric2 run
   both): it holds still water to 0.03 r0 where the seed's drifts 0.8 r0 (2D) and 3 r0 (3D), and
   follows Martin & Moyce's front as well. Seed 002's semi-implicit scheme
   (FSDEM_MPS_SCHEME_SEMI_IMPLICIT, the steps below) stays for reproducing the seed: it takes steps
   about 7 times longer (its Courant number is on the flow's speed, not the sound speed's), each
   with a pressure equation. MPS-DEM (>>couple_mps) was validated with the seed's scheme, and its
   cases set it.

   Particles are of three kinds. FLUID particles move. WALL particles are the layer of a solid next
   to the fluid: fixed, their pressure is solved with the fluid's, so the fluid is pushed back.
   DUMMY particles are the deeper layers of a solid: fixed, they only complete the number density
   of the particles near the wall. Solids are built on the r0 lattice by fsdem_mps_add_box_walls
   (a tank) and fsdem_mps_add_box_obstacle (a box inside it): one WALL layer and enough DUMMY
   layers that a wall particle sees a full neighbourhood within re (ceil(re/r0) - 1 of them: 4 for
   re = 4.1 r0). Fluid fills boxes on the same lattice (fsdem_mps_fill_box) or comes from a list.

   Step of dt (all sums at the positions r^m of the start of the step, over neighbours j within re):
     1. neighbours (cell list on fsdem_cellgrid, cells of edge re: the pairs with a FLUID particle
        every step, the WALL-WALL and WALL-DUMMY pairs once, as solids never move, DUMMY-DUMMY
        pairs never), number density n_i (Eq. 7);
     2. predictor u* = u + dt (nu lap(u) + g) for FLUID particles (Eq. 10 on u; solids u* = dt g, so
        a uniform body force makes no source of Eq. 12 at the walls: see step 4);
     3. free surface (FLUID and WALL particles): n_i < beta n0 (Eq. 14) or |F_i| > alpha |F0| (Eq.
        15-16), where |F0| is |F| of a particle on the flat surface of the full initial lattice (the
        seed's "F0 of the internal particles" is zero on a lattice; the surface one is meant);
     4. pressure Poisson equation on the FLUID and WALL particles not on the surface (surface: p = 0,
        Dirichlet; DUMMY particles are no unknowns: in Eq. 10 they take the ghost pressure p_i +
        rho g.(r_j - r_i), as in the corrector's gradient, a known term, which is the Neumann condition
        dp/dn = rho g.n of a wall): Eq. 10 = Eq. 12, its row i multiplied by -n0 lambda/(2d) / eps_i
        so the matrix  A_ii = sum_j w_ij/(eps_i eps_j),  A_ij = -w_ij/(eps_i eps_j)  (sums over the
        non-DUMMY j) is symmetric and positive definite (a fsdem_csr, solved by fsdem_pcg; Eq. 13
        instead of Eq. 12 with desc.model = FSDEM_MPS_MODEL_B);
     5. negative pressures set to 0 when desc.clamp_negative_pressure (the seed says nothing; the
        original MPS clamps, so this scheme's default does);
     6. corrector u = u* - dt/rho grad p (Eq. 8 or the stabilised form, desc.gradient);
     6b. collisions (desc.collision_distance, restitution; Koshizuka, Nobe and Oka 1998): pairs that
        would end the step closer than collision_distance r0 lose (1 + e) of their approach speed
        (details at fsdem__mps_collide), then r += dt u;
     7. when desc.shifting > 0, r += dr, the Fickian particle shift of Lind, Xu, Stansby and Rogers
        (2012, J. Comput. Phys. 231:1499), dr = -D grad C with D = desc.shifting r0^2 and grad C the
        kernel sum of Eq. 8 with C = 1, computed at the positions of step 1: FLUID particles only,
        none on the surface, only tangentially (normal: F of Eq. 15) with a surface neighbour,
        at most cfl r0 (details at fsdem__mps_shift in the implementation).
   Operators: Eq. 8-10 are exact for linear fields (gradient, divergence) and quadratic fields
   (Laplacian) at particles whose neighbourhood is a full regular lattice; they are first and
   second order only in that sense (consistency is lost near the surface and in disordered regions).
   Still water. The drift is quoted one way: the largest displacement of a FLUID particle from its
   start after 0.5 s, in r0 (the goal: below 0.1 r0), with the top row's mean sinking beside it.
   In a tank 0.2 m deep at r0 = 0.01 m with the defaults: 2D 0.86 r0, top row 0.47 r0
   (test_mps_still_water, validation/mps_hydrostatic); 3D 3.87 r0, top row 0.91 r0; 2D with the
   sum form of Eq. 8 1.1 r0. The figures below are of the sum form without collisions unless said. Two causes, measured:
   (a) the free-surface band. The lattice at rest is not a discrete equilibrium: the rows below the
   surface row have number densities short of n0 by geometry (0.85 n0 one row down, re = 4.1 r0),
   which Eq. 12 reads as expansion. In the first step from rest the density term alone lowers the
   pressure at mid-depth to 522 Pa against 883 hydrostatic (its weight gamma rho/dt^2 grows as dt
   shrinks), and the top row's mean sinks 0.7 r0 in 0.15 s. Without it (gamma = 0) Eq. 10 is still one-
   sided there: the pressure one row down is 2.3 times hydrostatic, and the sum form of Eq. 8
   pushes that row up at 0.54 g (0.29 g with the min form; the corrected form, exact for linear
   fields, shows the pressure error itself: rows 1-5 fall at 0.4-1 g with gamma = 0.01). (b) A
   shear instability along the walls: after a settling phase (1 s with the velocities zeroed after
   each step) the columns next to each wall slide against each other, alternately up and down,
   their speed doubling every 0.02 s (about 35/s, the same at dt = 1e-3 and 5e-4 s, with gamma =
   0.01, 0.001 and 0): a mechanical instability of the pairwise-repulsive sum form against the fixed
   wall layer, not of the time stepping. Neither particle shifting nor the corrected gradient cures
   them (drift at 0.5 s: shifting 0.02 / 0.05 with the sum form 0.97 / 1.30 r0, 0.1 or more blows up
   between 0.35 and 0.5 s; corrected gradient without shifting or with 0.05 blows up by 0.32 s, with
   0.2 drifts 6.8 r0); both stay behind desc switches, off by default. Mid-depth pressure is within
   2% whenever the tank survives. A cure needs consistent operators at the free surface (e.g. ghost
   values above it) and a wall condition that resists shear; not done. A source that corrects
   compression only (the density term of Eq. 12 where n > n0, as DFSPH-type solvers do; tried
   outside the library, not offered) fixes the level but not the drift: 2D at 0.5 s with the sum
   form 0.69 r0, level -0.04 %, mid-depth p +0.2 % (gamma 0.01); at 5 s 2.9 r0, level +0.3 %,
   p +3.8 %; with the min form 18 r0 at 5 s. Of 24 combinations of gamma (0, 0.01, 0.05), that
   source, the sum or min form and shifting (0, 0.02) none drifts less than 0.5 r0 by 0.5 s; the
   drift is spread over the tank (64-290 of 400 particles move more than 0.3 r0), not a corner's.
   The CMPS gradient of Khayyer and Gotoh (2008), ((p_i + p_j) - (p^_i + p^_j)) with p^ the
   smallest pressure around a particle, is not offered: on a full lattice it equals grad p -
   grad p^ (write p_i + p_j = 2 p_i + (p_j - p_i), and the same for p^; the constant 2 (p_i - p^_i)
   sums to zero against the odd r_ij), which is zero wherever p^ follows p at a fixed offset, as
   in hydrostatic water (p^_i is the pressure of the highest neighbour, a fixed height above i).
   Tried outside the library: still water at mid-depth +86 % (the pressure equation makes up for
   the missing gradient), against -1.5 % with the min form.
   Laplacian radius (desc.re_laplacian, after MPS codes that use 2.1-3.1 r0 for Eq. 10 while Eq. 7
   keeps 4.1 r0). The pressure matrix holds the pairs within it, so its cost falls fast; its
   physics, measured when the option came (3D tank 0.8 x 0.4 m, column 0.2 x 0.4 x 0.4 m at
   r0 = 0.01 m, 34,110 rows; the 2D Martin & Moyce case of validation/mps_dambreak_2d at a/40):
       re_laplacian            4.1 r0        3.1 r0        2.1 r0
       3D entries per row      219           108           30.5
       3D MIC(0) setup+solve   1.27 s (19)   0.43 s (20)   0.086 s (25 iterations)
       3D AMG setup+solve      0.96 s (6)    0.70 s (6)    0.13 s (7 iterations)
       2D front slope dZ/dT    1.255         1.254         1.252 (table 1.261; all within 5 %)
       2D inner n/n0 drift     0.40 %        0.57 %        1.77 % (the case's line is 1 %)
       2D still water drift    0.86 r0       0.70 r0       0.89 r0 (largest, at 0.5 s)
   so 3.1 r0 halves the matrix at no measured loss and 2.1 r0 lets the volume drift; the default
   stays the seed's re.
   Periodic axes (desc.periodic): along them a pair interacts through its minimum image (the
   cell grid's neighbourhoods wrap, every separation r_j - r_i of the operators, the DUMMY ghosts
   and the probes is taken modulo the period), positions are wrapped into the domain after each
   move and as particles are added, and tank walls are built with those sides open
   (fsdem_mps_add_box_walls stops them at the box's faces, so they meet across the seam). The
   period must be a whole number of r0 and exceed 2 re. Obstacles must not cross the seam; the
   MPS-DEM coupler refuses a periodic MPS (its averaging does not wrap).
   A liquid with no free surface (a closed or periodic box full of it) has a singular pressure
   equation: the source's mean is removed and the lowest pressure set to 0 (fsdem__mps_assemble).
   Viscosity at walls (desc.wall_viscosity): the no-slip ghost velocities of Adami, Hu and Adams
   (2012) by default; with the old rule (WALL particles at rest, DUMMY ones out of Eq. 10) the wall
   drags too little. The explicit viscous term limits the step to dt nu <= 0.8 lambda eps_min/(2d)
   besides Eq. 37 (fsdem__mps_dt_viscous); for water at r0 = 1 cm that is 80 s, so only viscous
   flows feel it.
   Units: m, s, kg/m^3, m^2/s (kinematic viscosity), Pa. In 2D the problem lies in the x-y plane.
   One step allocates nothing once its lists have reached their size (the neighbour list and the
   matrix grow by doubling when the particle arrangement needs more room than ever before). */

typedef struct fsdem_mps fsdem_mps;

/* Kind of a particle (fsdem_mps_particles.kind). */
typedef enum fsdem_mps_kind {
    FSDEM_MPS_KIND_FLUID = 0, /* moves; pressure solved (0 on the free surface) */
    FSDEM_MPS_KIND_WALL = 1,  /* fixed; pressure solved; the solid layer next to the fluid */
    FSDEM_MPS_KIND_DUMMY = 2  /* fixed; no pressure; completes the number density behind a wall layer */
} fsdem_mps_kind;

/* Pressure gradient of the corrector. */
typedef enum fsdem_mps_gradient_model {
    /* seed 002 Eq. 8 as printed, (p_j + p_i) (Tanaka and Masunaga 2010; Khayyer and Gotoh): the
       sum makes every pair repulsive for positive pressures and conserves momentum. But a uniform
       pressure pushes every particle with a cut neighbourhood (near the free surface) outwards,
       in proportion to it, and the next pressure equation answers that expansion with the
       opposite level: in a 2D dam break (4 m tank, 1 x 2 m column, r0 = 0.015 m) the pressure of
       the lower half of the column swung between +4.1e5 and -3.8e5 Pa from one step to the next
       at t = 0.20 s and the run blew up (0.09 s without collisions, 0.28 s with them) */
    FSDEM_MPS_GRADIENT_MODEL_SUM = 0,
    /* Koshizuka, Nobe and Oka (1998): (p_j - min p) with the smallest pressure of i and its
       neighbours; also repulsive, exact for linear fields in the interior of a lattice, and blind
       to a uniform pressure level; with the collisions of step 6b the dam break above runs through
       (without them it failed at 0.19 s); the default */
    FSDEM_MPS_GRADIENT_MODEL_MIN = 1,
    /* the difference form (p_j - p_i) times the inverse of the moment matrix
       sum_j w_ij (r_j - r_i)(r_j - r_i)^T / |r_j - r_i|^2, the corrected gradient of Khayyer and
       Gotoh (2011, Appl. Ocean Res. 33:235; after Randles and Libersky 1996): exact for linear
       fields in any neighbourhood that spans the space; not repulsive (no pressure force in a
       uniform pressure), so clustering is left to particle shifting (desc.shifting) */
    FSDEM_MPS_GRADIENT_MODEL_CORRECTED = 2
} fsdem_mps_gradient_model;

/* The velocity the solids' particles carry into the viscous term (Eq. 10 on u, step 2). */
typedef enum fsdem_mps_wall_viscosity {
    /* no-slip by the ghost velocity of Adami, Hu and Adams (2012, J. Comput. Phys. 231:7057, Eq.
       22-23): each WALL and DUMMY particle takes 2 u_w - u~ with u~ the kernel average (Shepard
       sum, weights w_ij/eps_i of Eq. 7) of the FLUID velocities within re of it and u_w = 0
       (solids are fixed), so the velocity passes through zero at the solid surface; the discrete
       steady plane Poiseuille flow (2D, re = 4.1 r0) is then within 6.2 / 1.8 / 0.6 % of the
       parabola at 10 / 20 / 40 rows (the lattice's discrete steady state; tests/test_mps_periodic.c
       runs 30 rows in 2D, 24 in 3D); the default */
    FSDEM_MPS_WALL_VISCOSITY_NO_SLIP = 0,
    /* WALL particles at rest, DUMMY particles left out (Eq. 10 over the non-DUMMY neighbours, as
       the pressure equation): the wall drags too little, the steady Poiseuille centre speed 70 /
       34 / 17 % above the parabola's at 10 / 20 / 40 rows; kept to reproduce older results */
    FSDEM_MPS_WALL_VISCOSITY_AT_REST = 1
} fsdem_mps_wall_viscosity;

/* How the pressure is found (see >>mps_explicit in the implementation for the explicit scheme). */
typedef enum fsdem_mps_scheme {
    /* seed 002 §2.1: the pressure Poisson equation of steps 2-6 above (the seed's; incompressible
       to the solver's tolerance) */
    FSDEM_MPS_SCHEME_SEMI_IMPLICIT = 0,
    /* weakly compressible, explicit (Oochi, Koshizuka and Sakai 2010; Shakibaeinia and Jin 2010):
       every particle carries a density rho_i, evolved by the continuity equation with the MPS
       divergence (Eq. 9) and a diffusion of the density like delta-SPH's (Molteni and Colagrossi
       2009) of its departure from hydrostatic (so a liquid at rest stays so exactly); the pressure
       follows by the linear equation of state p = c0^2 (rho_i - rho) with an artificial sound
       speed c0 (desc.sound_speed); WALL and DUMMY particles take the pressure of the liquid around
       them extrapolated hydrostatically (Adami, Hu and Adams 2012); the velocity is u += dt
       (-grad p / rho + nu lap u + g + f/m) with the sum form of Eq. 8 (desc.gradient is not used),
       then the density and the positions with the new velocity (symplectic Euler); the step is
       limited by (c0 + u_max) dt / r0 <= cfl. The gradient and divergence weigh pairs by
       q^2 (1 - q)^3, q = r / 2.8 r0 (so desc.re >= 2.8 r0): a pair then pushes as the Wendland
       kernel's gradient does in SPH. With the seed's kernel (Eq. 6) the square lattice is unstable
       to the shear of one column against the next (a column's stiffness against its neighbour,
       summed over the lattice, is negative for a pair force decreasing as steeply as w/r; growth
       about 30/s at 1 kPa, measured 35/s: the columns beside the walls slid from 0.15 s); with
       this one it is slightly positive. A particle whose density is not set yet starts at the
       hydrostatic density of its depth below the top of its column of liquid (the hydrostatic
       start). No pressure equation, no surface detection (the surface's particles keep rho near
       rho: p near 0); the solid particles in the air (extrapolated pressure not positive) are left
       out of the gradient. Negative pressures are kept by default (desc.clamp_negative_pressure
       0): a stretched surface's particles, whose density falls, are pulled back, and the liquid's
       volume sum m / rho_i stays within 0.23 % through Martin & Moyce's dam break (+5.7 % with
       the clamp). The default radius re is the weight's support, 2.8 r0, and the default
       cfl 0.35 (SPH's usual 0.25 h / c0 for that support). Still water (the tank of the notes
       above; validation/mps_still_water): 2D largest displacement 0.030 r0 at 0.5 s and 0.034 r0
       at 5 s (0.008 and 0.02 r0 three columns or more from the walls), mid-depth pressure within
       0.04 %; 3D (0.1 x 0.1 m, 0.2 m deep) 0.041 r0 at 0.5 s, 0.020 r0 at 1 s. With re = 4.1 r0 the
       2D figure at 0.5 s was 0.053 r0.
       The porosity enters as in the corrector (Model B: the pressure term over eps_i); the
       mixture's continuity is not in it yet. */
    FSDEM_MPS_SCHEME_EXPLICIT = 1
} fsdem_mps_scheme;

/* Form of the pressure equation's source with a porosity field (seed 002 §2.1). */
typedef enum fsdem_mps_model {
    FSDEM_MPS_MODEL_A = 0, /* Eq. 12: rho_f in both terms of the mixed source */
    FSDEM_MPS_MODEL_B = 1  /* Eq. 13: eps_f rho_f, eps_f the porosity of the particle (identical at eps = 1) */
} fsdem_mps_model;

typedef struct fsdem_mps_desc {
    int dim;                        /* 2 or 3 */
    fsdem_mps_scheme scheme;        /* default FSDEM_MPS_SCHEME_EXPLICIT (see the enum) */
    fsdem_real r0;                  /* m; initial particle spacing, > 0; default 0.01 */
    fsdem_real re;                  /* m; interaction radius, >= 2 r0; 0 = 4.1 r0 (seed 002 §2.1) */
                                    /*    with the seed's scheme, 2.8 r0 with the explicit one; */
                                    /*    default 0 */
    fsdem_real re_laplacian;        /* m; radius of the Laplacian (Eq. 10-11: the pressure equation */
                                    /*    and viscosity), in [1.5 r0, re]; 0 = re (the seed's); */
                                    /*    default 0 (see the notes on its cost) */
    fsdem_real density;             /* kg/m^3; rho_f; default 1000 */
    fsdem_real viscosity;           /* m^2/s; kinematic viscosity nu = mu_f/rho_f; default 1e-6 */
    fsdem_vec3 gravity;             /* m/s^2; default (0,-9.81,0) in 2D, (0,0,-9.81) in 3D */
    fsdem_real gamma;               /* -; weight of the number-density term of Eq. 12, in [0, 1]; */
                                    /*    default 0.01 */
    fsdem_mps_model model;          /* source of the pressure equation: Eq. 12 or 13; default A */
    fsdem_real beta;                /* -; surface when n < beta n0 (Eq. 14), in (0, 1); default 0.8 */
    fsdem_real alpha;               /* -; surface when |F| > alpha |F0| (Eq. 16), > 0; default 0.9 */
    fsdem_real cfl;                 /* -; Courant number C of Eq. 37, u_max dt / r0 <= C (explicit: */
                                    /*    (c0 + u_max) dt / r0 <= C), in (0, 1]; 0 = the scheme's: */
                                    /*    0.2 (the seed's), 0.35 (explicit); default 0 */
    fsdem_real sound_speed;         /* m/s; c0 of FSDEM_MPS_SCHEME_EXPLICIT, >= 0; 0 = 10 sqrt(2 |g| H) */
                                    /*    with H the height of the liquid at the first step (10 */
                                    /*    times the speed of a fall from its top: density within */
                                    /*    1 %); default 0 */
    fsdem_real density_diffusion;   /* -; delta of the explicit scheme's density diffusion, in */
                                    /*    [0, 1]; default 0.1 (delta-SPH's) */
    fsdem_real dt_max;              /* s; longest step (taken while nothing moves); default 1e-3 */
    fsdem_vec3 domain_min;          /* m; every particle must stay inside; default (0,0,0) */
    fsdem_vec3 domain_max;          /* m; default (1,1,1) (z unused in 2D) */
    int periodic[3];                /* 1: axis a is periodic, of period domain_max - domain_min: a */
                                    /*    whole number of r0 (lattice fills meet without a seam) */
                                    /*    and more than 2 re; default 0 (see the section notes) */
    fsdem_mps_gradient_model gradient; /* default FSDEM_MPS_GRADIENT_MODEL_MIN (see the enum) */
    fsdem_mps_wall_viscosity wall_viscosity; /* default FSDEM_MPS_WALL_VISCOSITY_NO_SLIP (see the enum) */
    int clamp_negative_pressure;    /* 1: p < 0 is set to 0 (after the solve, or from the equation */
                                    /*    of state); default 1 for the seed's scheme, 0 for the */
                                    /*    explicit one (fsdem_mps_desc_default_scheme) */
    fsdem_real collision_distance;  /* -; in units of r0: approaching FLUID particles that would */
                                    /*    come closer collide (step 6b), in [0, 1); 0 = off; */
                                    /*    default 0.8 (see fsdem__mps_collide) */
    fsdem_real restitution;         /* -; coefficient of restitution of those collisions, in [0, 1]; */
                                    /*    default 0.2 */
    fsdem_real shifting;            /* -; particle shifting D / r0^2 (Lind et al. 2012, step 7), */
                                    /*    in [0, 1]; 0 = off; default 0 (see the notes above) */
    fsdem_precond pressure_precond; /* default FSDEM_PRECOND_AUTO: MIC(0) in 2D, Jacobi in 3D; */
                                    /*    FSDEM_PRECOND_AMG on request */
    fsdem_real pressure_tolerance;  /* -; relative residual of the pressure solve; default 1e-8 */
                                    /*    (1e-5 in float) */
    int pressure_max_iterations;    /* >= 1; default 1000 */
    fsdem_allocator allocator;      /* default: FSDEM_MALLOC/FSDEM_FREE */
    fsdem_log_fn log;               /* optional; default NULL */
    void *log_user;
} fsdem_mps_desc;

/* Defaults for dim = 2 (x-y plane, gravity -y) or 3 (gravity -z); see the field comments. The
   explicit scheme's: fsdem_mps_desc_default_scheme(dim, FSDEM_MPS_SCHEME_EXPLICIT). */
FSDEM_API fsdem_mps_desc fsdem_mps_desc_default(int dim);
/* The defaults of a scheme: they differ in clamp_negative_pressure (1 for the seed's scheme, 0 for
   the explicit one) and in what re = 0 and cfl = 0 stand for (their field comments). Use it, not
   desc_default and a new desc.scheme, to run seed 002's scheme as the seed does. */
FSDEM_API fsdem_mps_desc fsdem_mps_desc_default_scheme(int dim, fsdem_mps_scheme scheme);
/* Checks a desc without creating anything; the reason, naming the field, goes to `message` (may be
   NULL). Returns FSDEM_OK or FSDEM_ERR_INVALID_ARG (r0 <= 0, re < 2 r0, an empty domain, ...). */
FSDEM_API fsdem_result fsdem_mps_desc_check(const fsdem_mps_desc *desc, char *message, size_t message_size);
/* Creates a solver without particles (time 0); n0, lambda and |F0| are computed here from the full
   r0 lattice. *out is NULL on failure. Errors: FSDEM_ERR_INVALID_ARG (the reason goes to desc->log
   and fsdem_mps_desc_check), FSDEM_ERR_OUT_OF_MEMORY. Destroy with fsdem_mps_destroy. */
FSDEM_API fsdem_result fsdem_mps_create(const fsdem_mps_desc *desc, fsdem_mps **out);
FSDEM_API void fsdem_mps_destroy(fsdem_mps *mps);
/* Message of the last failed call on this object ("" after success). Valid until the next call. */
FSDEM_API const char *fsdem_mps_last_error(const fsdem_mps *mps);
/* The desc in force (re resolved). */
FSDEM_API fsdem_mps_desc fsdem_mps_get_desc(const fsdem_mps *mps);

/* ---- particles ---- */

/* Adds `count` particles of one kind (positions m; velocities m/s, NULL for rest; solids are
   always at rest). All or nothing: FSDEM_ERR_INVALID_ARG (a bad kind, count < 0, NULL positions, a
   non-finite value, naming the particle), FSDEM_ERR_OUT_OF_DOMAIN (the first one outside the
   domain), FSDEM_ERR_OUT_OF_MEMORY. Allocates (outside any step). */
FSDEM_API fsdem_result fsdem_mps_add_particles(fsdem_mps *mps, fsdem_mps_kind kind, int count,
                                               const fsdem_vec3 *positions, const fsdem_vec3 *velocities);
/* Makes room for `count` particles more than those present and those its inflows add in the next
   step, so that the next step allocates no particle storage (a step grows it when it must; a
   coupled step reserves first, so that a step it puts back allocates nothing). FSDEM_ERR_INVALID_ARG
   (count < 0), FSDEM_ERR_OUT_OF_MEMORY; nothing changes on failure. */
FSDEM_API fsdem_result fsdem_mps_reserve(fsdem_mps *mps, int count);
/* Fills the box [lo, hi] with FLUID particles on the r0 lattice anchored at lo: centres at
   lo + (i + 1/2) r0 per axis, those inside the box and outside every box obstacle, all with
   `velocity`. The number added goes to *added (may be NULL). Errors as fsdem_mps_add_particles,
   and FSDEM_ERR_INVALID_ARG for an empty box. */
FSDEM_API fsdem_result fsdem_mps_fill_box(fsdem_mps *mps, fsdem_vec3 lo, fsdem_vec3 hi, fsdem_vec3 velocity,
                                          int *added);
/* Builds the walls of a box tank whose inside is [lo, hi], on the lattice of fsdem_mps_fill_box
   anchored at lo: the lattice points outside the box within one spacing of it are WALL particles,
   the next ceil(re/r0) - 1 layers DUMMY particles. A side whose bit (1 << fsdem_side) is set in
   `open_sides` has no wall, and the walls next to it stop at the box's face there (a tank open
   at the top: 1 << FSDEM_SIDE_YMAX in 2D, 1 << FSDEM_SIDE_ZMAX in 3D); the sides across a periodic
   axis (desc.periodic) are always open. *added (may be NULL) counts the particles. Errors as
   fsdem_mps_fill_box. */
FSDEM_API fsdem_result fsdem_mps_add_box_walls(fsdem_mps *mps, fsdem_vec3 lo, fsdem_vec3 hi,
                                               unsigned open_sides, int *added);
/* Adds a solid box [lo, hi] inside the flow: lattice points lo + (i + 1/2) r0 inside it, the outer
   layer WALL particles, the next ceil(re/r0) - 1 layers DUMMY (the core, beyond reach, is left
   empty). Later fsdem_mps_fill_box calls leave the box out. Its index goes to *id (may be NULL).
   Errors as fsdem_mps_fill_box. */
FSDEM_API fsdem_result fsdem_mps_add_box_obstacle(fsdem_mps *mps, fsdem_vec3 lo, fsdem_vec3 hi, int *id);

/* ---- open boundaries ----

   An inflow feeds liquid through a plane at a prescribed velocity from a buffer of particles
   upstream of it (the buffer zones of open-boundary ISPH and MPS): ceil(re/r0) lattice layers deep,
   so the liquid next to the plane sees a full neighbourhood. Buffer particles are FLUID particles
   whose velocity is imposed (speed along the axis; u* = u + dt g in the predictor, as walls take
   the body force) and whose pressure is solved with the liquid's; one that crosses the plane
   becomes ordinary liquid, and a new buffer particle takes its place ceil(re/r0) r0 upstream, so
   the buffer keeps its lattice. An outflow removes liquid beyond a plane: FLUID particles past it
   have p = 0 (Dirichlet, as the free surface) and keep their own motion; they are removed once
   ceil(re/r0) r0 past it. Removal renumbers the particles after the removed ones (views and indices
   are valid until the next step); stats count the particles in and out. Both need the MPS without
   a coupler (fsdem_mps_dem_desc_check refuses them). Flow back through an inflow plane is not
   handled (the buffer keeps its imposed velocity). */

/* An inflow plane x_axis = position, liquid entering it moving at `speed` along direction e_axis. */
typedef struct fsdem_mps_inflow_desc {
    int axis;            /* 0 .. dim-1: the normal of the plane */
    int direction;       /* +1: the liquid flows towards +axis (the buffer below `position`); -1: the reverse */
    fsdem_real position; /* m; the plane */
    fsdem_vec3 lo, hi;   /* m; the inlet's extent over the other axes, its lattice anchored at lo as */
                         /*    fsdem_mps_fill_box's (components along `axis` ignored) */
    fsdem_real speed;    /* m/s, > 0 and finite */
} fsdem_mps_inflow_desc;
/* Defaults: axis 0, direction +1; the plane's position, its extent (lo, hi) and the speed have none
   and are 0: set them (fsdem_mps_add_inflow refuses a speed of 0, naming it). */
FSDEM_API fsdem_mps_inflow_desc fsdem_mps_inflow_desc_default(void);
/* Adds an inflow and fills its buffer (*added particles; may be NULL); the whole buffer, down to
   ceil(re/r0) r0 upstream of the plane, must lie inside the domain. FSDEM_ERR_INVALID_ARG (a field
   named), FSDEM_ERR_OUT_OF_DOMAIN, FSDEM_ERR_OUT_OF_MEMORY; nothing is added on error. */
FSDEM_API fsdem_result fsdem_mps_add_inflow(fsdem_mps *mps, const fsdem_mps_inflow_desc *inflow, int *added);
/* An outflow plane x_axis = position: liquid moving along direction e_axis leaves through it. */
typedef struct fsdem_mps_outflow_desc {
    int axis;            /* 0 .. dim-1 */
    int direction;       /* +1: particles beyond it along +axis are leaving; -1: the reverse */
    fsdem_real position; /* m; the plane; the zone ceil(re/r0) r0 past it must lie inside the domain */
    fsdem_vec3 lo, hi;   /* m; the outlet's extent over the other axes (components along `axis` */
                         /*    ignored): liquid past the plane outside it is not touched */
} fsdem_mps_outflow_desc;
/* Defaults: axis 0, direction +1; the plane's position and its extent (lo, hi) have none and are 0:
   set them. */
FSDEM_API fsdem_mps_outflow_desc fsdem_mps_outflow_desc_default(void);
/* Adds an outflow. FSDEM_ERR_INVALID_ARG (a field named, or a zone outside the domain),
   FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_mps_add_outflow(fsdem_mps *mps, const fsdem_mps_outflow_desc *outflow);

/* Views of the particles (structure of arrays, index order = order of addition), valid until
   particles are added or the solver is destroyed. Steps update them in place; with inflows or
   outflows a step also adds particles (at the end) and removes some (the later ones move down),
   so the views and indices are then valid until the next step. `velocity` of FLUID
   particles and `porosity` (eps_f in (0, 1], 1 by default; the 1/eps_j of Eq. 7-16, for a coupler)
   may be edited between steps. `number_density` and `surface` are those of the last step (or of
   the last operator call). */
typedef struct fsdem_mps_particles {
    int count;
    int dim;
    const fsdem_vec3 *position;       /* m */
    fsdem_vec3 *velocity;             /* m/s (0 for WALL and DUMMY) */
    const fsdem_real *pressure;       /* Pa (0 for DUMMY and surface particles) */
    const unsigned char *kind;        /* fsdem_mps_kind */
    const unsigned char *surface;     /* 1: free-surface particle (p = 0) at the last step */
    const fsdem_real *number_density; /* -; n_i of Eq. 7 at the last step (0 for DUMMY) */
    const fsdem_real *density;        /* kg/m^3; rho_i of FSDEM_MPS_SCHEME_EXPLICIT (its particle's */
                                      /*    volume is mass / rho_i); 0 for WALL and DUMMY, and */
                                      /*    with the seed's scheme */
    fsdem_real *porosity;             /* -; eps_f per particle */
    const fsdem_vec3 *pressure_gradient; /* Pa/m; grad p of the last corrector at FLUID particles */
                                      /*    (desc.gradient form; 0 elsewhere and before a step) */
    const int *inflow;                /* the inflow whose buffer holds the particle, or -1 */
    fsdem_real mass;                  /* kg (kg/m in 2D); the fluid of one particle, rho r0^d */
} fsdem_mps_particles;

FSDEM_API fsdem_mps_particles fsdem_mps_get_particles(fsdem_mps *mps);

/* What a coupler writes (>>doc, COUPLING INTERFACE): a force on every particle (N; N per metre of
   depth in 2D), held over later steps and applied to FLUID particles in the predictor (step 2:
   u* += dt force / mass), and the porosity eps of Eq. 7-16 (the same array as the view's). The
   forces start at zero; steps read them only once this function has handed them out. Valid until
   particles are added (an MPS with inflows or outflows, whose steps add and remove particles, cannot
   be coupled). With desc.model = FSDEM_MPS_MODEL_B the corrector divides the pressure
   acceleration by eps_i (seed 002 Eq. 5: the fluid takes the whole pressure gradient of the
   mixture), with Model A it does not (Eq. 2: -eps grad P on a volume of mixture, i.e. -grad P on
   the fluid's own volume). */
typedef struct fsdem_mps_coupling {
    int count;
    fsdem_vec3 *force;                /* N (N/m in 2D) */
    fsdem_real *porosity;             /* -; in (0, 1] */
} fsdem_mps_coupling;

FSDEM_API fsdem_mps_coupling fsdem_mps_get_coupling(fsdem_mps *mps);

/* The MPS's coupling arrays, as writers claim them (fsdem_claim; fsdem_mps_dem claims both). */
typedef enum fsdem_mps_arrays {
    FSDEM_MPS_ARRAYS_FORCE = 1,   /* force */
    FSDEM_MPS_ARRAYS_POROSITY = 2 /* porosity */
} fsdem_mps_arrays;

/* The MPS's claim registry (>>core_claims); NULL for a NULL MPS. */
FSDEM_API fsdem_claims *fsdem_mps_claims(fsdem_mps *mps);

/* ---- particle-interaction operators (seed 002 Eq. 7-10) ---- */

/* The discrete operators of the solver applied to caller fields at the current positions (one
   value, or vector, per particle; the output of DUMMY particles is 0). The sums run over every
   neighbour except DUMMY particles, as in the step's pressure terms; each refreshes the view's
   number_density. Gradient: Eq. 8 or the form of desc.gradient. Allocates (the neighbour list).
   FSDEM_ERR_INVALID_ARG (NULL arrays), FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_mps_gradient(fsdem_mps *mps, const fsdem_real *phi, fsdem_vec3 *out);
FSDEM_API fsdem_result fsdem_mps_divergence(fsdem_mps *mps, const fsdem_vec3 *field, fsdem_real *out);
FSDEM_API fsdem_result fsdem_mps_laplacian(fsdem_mps *mps, const fsdem_real *phi, fsdem_real *out);
/* The pressure matrix of the last step (fsdem_csr, rows = unknowns in particle order; see the
   section's step 4) and in *rows_particle (may be NULL) the particle of each row (in the numbering
   after that step's outflow removals). Valid until the next step. rows = 0 before the first
   step. */
FSDEM_API fsdem_csr fsdem_mps_pressure_matrix(const fsdem_mps *mps, const int **rows_particle);

/* ---- time stepping ---- */

/* Stable step of the current state (s): C r0 / u_max over FLUID particles (Eq. 37), at most dt_max.
   FSDEM_ERR_NAN when a velocity is not finite. */
FSDEM_API fsdem_result fsdem_mps_stable_dt(const fsdem_mps *mps, fsdem_real *dt);
/* One step of the stable dt. Errors: FSDEM_ERR_INVALID_ARG (no FLUID particle, a porosity outside
   (0, 1]), FSDEM_ERR_NAN (a non-finite velocity before the step), FSDEM_ERR_NOT_CONVERGED (the
   pressure solve stopped at its iteration limit or failed), FSDEM_ERR_OUT_OF_MEMORY: in these cases
   nothing changed. After a completed step: FSDEM_ERR_NAN (a particle's velocity or position became
   non-finite) or FSDEM_ERR_OUT_OF_DOMAIN (a FLUID particle left the domain), naming the particle;
   the caller may remove it (not yet possible) or stop. */
FSDEM_API fsdem_result fsdem_mps_step(fsdem_mps *mps);
/* One step of exactly dt (s). FSDEM_ERR_INVALID_ARG for dt <= 0 or not finite, FSDEM_ERR_CFL when
   u_max dt / r0 > cfl (Eq. 37; the message names the fastest particle); nothing changes then.
   Otherwise as fsdem_mps_step. */
FSDEM_API fsdem_result fsdem_mps_step_dt(fsdem_mps *mps, fsdem_real dt);
/* FSDEM_OK when fsdem_mps_step_dt would take a step of dt, else the refusal it would return, with
   its message (a coupler checks before it changes anything). */
FSDEM_API fsdem_result fsdem_mps_check_dt(const fsdem_mps *mps, fsdem_real dt);
/* Adaptive steps until `duration` (s) later exactly (the last steps shortened); the number of
   steps goes to *steps (may be NULL). Stops at the first error. */
FSDEM_API fsdem_result fsdem_mps_advance(fsdem_mps *mps, fsdem_real duration, long long *steps);
/* Simulated time (s). */
FSDEM_API double fsdem_mps_time(const fsdem_mps *mps);

typedef struct fsdem_mps_stats {
    long long steps;
    double time;                  /* s */
    fsdem_real dt;                /* s, last step */
    int fluid, wall, dummy;       /* particles of each kind */
    int surface;                  /* FLUID and WALL particles on the free surface, last step */
    int unknowns;                 /* rows of the last pressure equation */
    long long neighbours;         /* particle pairs within re (each counted once), last step */
    fsdem_real n0;                /* -; number density of the full lattice (Eq. 7 with eps = 1) */
    fsdem_real lambda;            /* m^2; Eq. 11 on the full lattice */
    fsdem_real f0;                /* -; |F| (Eq. 15) of a particle on the flat surface of the lattice */
    int pressure_iterations;      /* PCG iterations, last step */
    long long pressure_iterations_total;
    fsdem_real pressure_residual; /* -; relative, last step */
    fsdem_real max_speed;         /* m/s, FLUID particles */
    fsdem_real max_pressure;      /* Pa */
    double seconds_total;         /* CPU seconds in steps (clock()) */
    double seconds_pressure;      /* CPU seconds in the pressure equation: assembly, setup, solve */
    double seconds_search;        /* CPU seconds of seconds_total in the neighbour search, number */
                                  /*    density and surface detection (step 1) */
    double seconds_assembly;      /* ... in assembling the pressure equation */
    double seconds_solve;         /* ... in its preconditioner setup and solve (the rest of */
                                  /*    seconds_total: the operators of steps 2 and 6) */
    long long candidate_pairs;    /* pairs the last neighbour search examined (neighbours: kept) */
    int inflow_planes, outflow_planes; /* open boundaries added (fsdem_mps_add_inflow/add_outflow) */
    long long inflow_particles;   /* buffer particles that crossed an inflow plane, since creation */
    long long outflow_particles;  /* particles removed past an outflow plane, since creation */
    size_t memory_bytes;          /* bytes held by the solver, its pcg included */
} fsdem_mps_stats;

FSDEM_API fsdem_mps_stats fsdem_mps_get_stats(const fsdem_mps *mps);

/* ---- probes (the sensors of experiments) ----

   Point probes average over the particles near a point with the smooth weight
       W(r) = (1 - r^2/R^2)^3 for r < R, 0 beyond,
   normalised as a kernel (integral 1: C = 4/(pi R^2) in 2D, 315/(64 pi R^3) in 3D) where a
   volume is measured. They read the state after the last step (positions of its end, pressures of
   its solve) and scan all particles: O(particles) per call, meant for output times, not for
   every particle. "Up" is the last axis (y in 2D, z in 3D), as the lattice's free surface. */

/* Pressure (Pa) at `point`: the W-weighted mean (Shepard) of the FLUID and WALL particles within
   `radius` (m; 0 means re) of it, surface particles (p = 0) included; 0 when none is there (a
   sensor in the air). A sensor on a wall reads its WALL particles and the liquid beside them.
   FSDEM_ERR_INVALID_ARG for NULL arguments, a non-finite point or a negative radius. */
FSDEM_API fsdem_result fsdem_mps_probe_pressure(const fsdem_mps *mps, fsdem_vec3 point, fsdem_real radius,
                                                fsdem_real *pressure);
/* Water level (m, a coordinate along the last axis) at the gauge through `gauge` (its x in 2D, x
   and y in 3D; the last coordinate is ignored): the highest point of that vertical line where the
   liquid fraction sum_j r0^d W(|r_j - point|) over FLUID particles (R = 2 r0) reaches 1/2, which
   on a flat surface is the surface of the volume the particles stand for (half a spacing above
   the top row), interpolated between samples r0/4 apart; domain_min's last coordinate when no
   liquid is within R of the line. The first liquid from above counts, a jet over the gauge
   included, as a gauge sees it. FSDEM_ERR_INVALID_ARG for NULL arguments or a non-finite gauge. */
FSDEM_API fsdem_result fsdem_mps_probe_height(const fsdem_mps *mps, fsdem_vec3 gauge, fsdem_real *height);
/* Gauges: probes at fixed places sampled at exact output times into a CSV series, as the PIC
   solver's (fsdem_pic_add_gauge). */
typedef enum fsdem_mps_gauge_kind {
    FSDEM_MPS_GAUGE_KIND_LEVEL = 0,   /* water level at the gauge line through the position (fsdem_mps_probe_height) */
    FSDEM_MPS_GAUGE_KIND_PRESSURE = 1 /* pressure at the position (fsdem_mps_probe_pressure with the radius) */
} fsdem_mps_gauge_kind;

/* Adds a gauge (before fsdem_mps_gauges_open); its id goes to *id (may be NULL). Radius (m) of a
   pressure sensor, 0 for re. FSDEM_ERR_OUT_OF_DOMAIN, FSDEM_ERR_INVALID_ARG (bad kind, radius < 0,
   non-finite input, a file is open), FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_mps_add_gauge(fsdem_mps *mps, fsdem_mps_gauge_kind kind, fsdem_vec3 position, fsdem_real radius,
                                           int *id);
/* Gauge `id` now (m or Pa). FSDEM_ERR_NOT_FOUND. */
FSDEM_API fsdem_result fsdem_mps_gauge(const fsdem_mps *mps, int id, fsdem_real *value);
/* Opens a gauge time series: a CSV with columns t, then level_<id> or p_<id> per gauge, rows at the
   multiples of `interval` (s) interpolated linearly within the step that passes each, or one per
   step for interval 0. FSDEM_ERR_IO, FSDEM_ERR_INVALID_ARG (no gauges, interval < 0). A restore is
   refused while it is open. */
FSDEM_API fsdem_result fsdem_mps_gauges_open(fsdem_mps *mps, const char *path, fsdem_real interval);
/* Closes the gauge file (also done by fsdem_mps_destroy). FSDEM_ERR_IO. */
FSDEM_API fsdem_result fsdem_mps_gauges_close(fsdem_mps *mps);
/* Holds the gauge rows of the steps to come (hold = 1): a step's rows wait, unwritten, until the next
   step begins or the hold ends (hold = 0 writes them). A coupler holds them through its step, so
   that a step it puts back leaves the file as it was (>>couple_step). Without an open gauge file
   there is nothing to hold. FSDEM_ERR_IO when rows could not be written. */
FSDEM_API fsdem_result fsdem_mps_gauges_hold(fsdem_mps *mps, int hold);

/* Force (N; N per metre of depth in 2D) of the liquid on the box obstacle `id`
   (fsdem_mps_add_box_obstacle) in the last step: the pressure of the step on its faces, each WALL
   particle of its skin standing for r0^(d-1) of every face within a spacing of it, its pressure
   carried from its centre (half a spacing inside) to the face hydrostatically, as the DUMMY ghosts
   of the pressure equation are. Exact for still water (Archimedes); viscous stress is not included
   (of order nu / (u r0) of the pressure force). 0 before the first step. FSDEM_ERR_INVALID_ARG for
   NULL arguments or an unknown id. */
FSDEM_API fsdem_result fsdem_mps_obstacle_force(const fsdem_mps *mps, int id, fsdem_vec3 *force);
