/* ===== >>dem : discrete element method ============================================================= */

typedef struct fsdem_dem fsdem_dem;

/* Contact law of a simulation. All laws use Coulomb friction with the material's `friction`. */
typedef enum fsdem_dem_law {
    /* Linear spring-dashpot of seed 000 Eq. 7-18: k from theta and dx (Eq. 10), damping from alpha
       (Eq. 11), tangential spring over one step capped by Coulomb (Eq. 8, 12-15), moment Eq. 9. */
    FSDEM_DEM_LAW_LINEAR = 0,
    /* Hertz normal force (4/3) E* sqrt(R*) d^1.5, Mindlin tangential spring on the accumulated
       tangential displacement, Tsuji-form damping calibrated so the normal restitution equals the
       material's `restitution` exactly (see >>dem_law in the implementation). */
    FSDEM_DEM_LAW_HERTZ_MINDLIN = 1,
    /* Granule-In-Cell law of seed 004 Eq. 1a-1c: k_n = E r, viscous tangential force capped by
       |F_n| tan(phi) with tan(phi) = friction. */
    FSDEM_DEM_LAW_GIC = 2
} fsdem_dem_law;

/* Contact options (LIGGGHTS users set them in their pair_style). Hand calculations of a two-sphere
   contact for each: tests/test_dem.c, "contact options". */

/* How a tangential spring carries its history from step to step (Hertz-Mindlin, and the linear law
   with seed 002's stiffness; seed 000's linear law has a one-step spring, Eq. 8, and no history). */
typedef enum fsdem_dem_tangential_history {
    /* the spring of the last step turned into the current tangent plane with its length kept, plus
       the increment v_t dt: a contact that rolls round its partner carries its spring with it
       (Luding 2008, Granular Matter 10:235, the projection of the tangential spring; LIGGGHTS
       `tangential history`); the default */
    FSDEM_DEM_TANGENTIAL_HISTORY_INCREMENTAL = 0,
    /* the total relative tangential displacement since first touch: the increments v_t dt summed in
       the fixed frame, never turned, and projected on the current tangent plane where the force is
       taken (the shear displacement of Cundall and Strack 1979); the same as INCREMENTAL while the
       contact normal keeps its direction */
    FSDEM_DEM_TANGENTIAL_HISTORY_TOTAL = 1
} fsdem_dem_tangential_history;

/* What Coulomb's limit mu |F_n| caps, while the contact slides the spring is reset to the capped
   force. LIGGGHTS' own `limitForce` keyword is another matter: it keeps the normal force from
   turning attractive, which Hertz-Mindlin here always does and the linear laws, as their seeds
   print them (seed 000 Eq. 7, seed 002 Eq. 19), do not. */
typedef enum fsdem_dem_coulomb_limit {
    /* spring plus dashpot: |F_t| <= mu |F_n| (seed 000 Eq. 15, seed 002 Eq. 20); the default */
    FSDEM_DEM_COULOMB_LIMIT_TOTAL = 0,
    /* the spring alone, the dashpot added after: |k_t xi| <= mu |F_n| ("Ft and Fn are the tangential
       spring and normal force components" of LIGGGHTS `tangential history`); a sliding contact's
       force then exceeds mu |F_n| by its dashpot */
    FSDEM_DEM_COULOMB_LIMIT_SPRING = 1
} fsdem_dem_coulomb_limit;

/* Stiffness and damping of FSDEM_DEM_LAW_LINEAR. */
typedef enum fsdem_dem_linear_stiffness {
    /* seed 000 Eq. 10-13: k_n from theta, dx and ||g|| per unit of the mean mass, damping from the
       materials' alpha, a one-step tangential spring (Eq. 8); the default */
    FSDEM_DEM_LINEAR_STIFFNESS_SEED000 = 0,
    /* seed 002 Eq. 19-24 from the materials: chi^n = (sqrt 2 / 3) E sqrt(R) / (1 - nu^2) (Eq. 21),
       written for a pair as (4/3) E* sqrt(R*), to which it reduces for two equal spheres;
       chi^t = chi^n / (2 + nu) (Eq. 22); eta = -2 ln(e) sqrt(chi m* / (ln^2 e + pi^2)) (Eq. 23-24,
       with the reduced mass m*, which makes the normal restitution exactly e); a tangential spring
       with history (desc.tangential_history); no tension cut-off, as printed. Eq. 21 has the units of
       a Hertz coefficient (N m^-3/2), and the seed uses it as a linear stiffness (N/m) in SI units:
       so does this option. The dt rule AUTO is then the Rayleigh time (seed 002 Eq. 38). */
    FSDEM_DEM_LINEAR_STIFFNESS_SEED002 = 1
} fsdem_dem_linear_stiffness;

typedef enum fsdem_dem_integrator {
    /* Velocity Verlet (kick-drift-kick), one force evaluation per step: second order for elastic
       forces; dashpots see the half-step velocity, which makes damping first order in dt (resolve
       a contact with >= 50 steps, or use the predictor-corrector, whose error is far smaller). */
    FSDEM_DEM_INTEGRATOR_VERLET = 0,
    /* Predictor-corrector of seed 000 Eq. 21-24, two force evaluations per step. */
    FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR = 1
} fsdem_dem_integrator;

/* Per-material properties. Fields not used by the chosen law are ignored. */
typedef struct fsdem_dem_material {
    fsdem_real density;          /* kg/m^3; default 2500 */
    fsdem_real young_modulus;    /* Pa; Hertz-Mindlin and GIC; default 1e8 */
    fsdem_real poisson_ratio;    /* -; Hertz-Mindlin, GIC, and psi of seed 000 Eq. 12-13; default 0.3 */
    fsdem_real restitution;      /* -; normal restitution e in (0, 1], Hertz-Mindlin; default 0.5 */
    fsdem_real friction;         /* -; Coulomb sliding coefficient mu (tan phi for GIC); default 0.3 */
    fsdem_real rolling_friction; /* -; constant-torque rolling resistance mu_r; default 0 (off) */
    fsdem_real damping_alpha;    /* -; alpha of seed 000 Eq. 11, linear law; default 0.4 */
    fsdem_real cohesion;         /* J/m^3; cohesion energy density k of the simplified JKR model: */
                                 /*    an attraction k A, A the area of the circle where the two */
                                 /*    spheres (with the contact offset) intersect (3D), or the */
                                 /*    chord times disc_length (2D) (LIGGGHTS `cohesion sjkr`); */
                                 /*    default 0 (off) */
} fsdem_dem_material;

FSDEM_API fsdem_dem_material fsdem_dem_material_default(void);

/* The contact properties of one pair of materials (LIGGGHTS' peratomtypepair tables). Unless set
   with fsdem_dem_set_material_pair, a pair takes the arithmetic mean of its two materials' values
   (their own values for a material with itself). */
typedef struct fsdem_dem_material_pair {
    fsdem_real restitution;      /* -; in [1e-6, 1] */
    fsdem_real friction;         /* -; >= 0 */
    fsdem_real rolling_friction; /* -; >= 0 */
    fsdem_real cohesion;         /* J/m^3; >= 0 */
} fsdem_dem_material_pair;

/* Rule of fsdem_dem_stable_dt (and of the dt warning, fsdem_dem_stats.dt_ratio). */
typedef enum fsdem_dem_dt_rule {
    /* the rule of the contact law: LINEAR_SEED000 for FSDEM_DEM_LAW_LINEAR (RAYLEIGH with seed 002's
       stiffness), RAYLEIGH for FSDEM_DEM_LAW_HERTZ_MINDLIN, GIC for FSDEM_DEM_LAW_GIC */
    FSDEM_DEM_DT_RULE_AUTO = 0,
    /* seed 000 Eq. 18: (2 pi / gamma) sqrt(m_ij / k), k from Eq. 10; dt_param is gamma (default 150) */
    FSDEM_DEM_DT_RULE_LINEAR_SEED000 = 1,
    /* seed 002 Eq. 38, the Rayleigh time pi R sqrt(2 rho (1+nu)/E) / (0.1631 nu + 0.8766) over all
       particles, times dt_param, a safety fraction in (0, 1] (default 0.2, as LIGGGHTS advises) */
    FSDEM_DEM_DT_RULE_RAYLEIGH = 2,
    /* seed 004 Eq. 32: (1/2) sqrt(m / k_n), k_n = E r, times dt_param in (0, 1] (default 1) */
    FSDEM_DEM_DT_RULE_GIC = 3
} fsdem_dem_dt_rule;

typedef struct fsdem_dem_desc {
    int dim;                        /* 2 or 3 */
    fsdem_vec3 domain_min;          /* m; particles must stay inside [domain_min, domain_max] */
    fsdem_vec3 domain_max;          /* m; default (-1,-1,-1)..(1,1,1) */
    fsdem_vec3 gravity;             /* m/s^2; default (0,-9.81,0) in 2D, (0,0,-9.81) in 3D */
    fsdem_dem_law law;          /* default FSDEM_DEM_LAW_HERTZ_MINDLIN */
    fsdem_dem_integrator integrator;    /* default FSDEM_DEM_INTEGRATOR_VERLET */
    fsdem_real dt;                  /* s; time step; default 1e-5 */
    fsdem_dem_dt_rule dt_rule;      /* rule of fsdem_dem_stable_dt; default FSDEM_DEM_DT_RULE_AUTO */
    fsdem_real dt_param;            /* gamma or safety fraction of the rule; 0: its default; default 0 */
    fsdem_real skin;                /* m; neighbour-list margin; < 0: 0.25 x largest radius; default -1 */
    fsdem_real contact_offset;      /* m; imaginary-boundary gap of seed 000 Eq. 19 (2 dx there): */
                                    /*    contacts start at distance r_i + r_j + offset; default 0 */
    fsdem_real linear_theta;        /* -; theta of seed 000 Eq. 10; default 0.01 */
    fsdem_real linear_dx;           /* m; dx of seed 000 Eq. 10; default 0 (must be set for LINEAR) */
    fsdem_real linear_accel;        /* m/s^2; ||g|| of Eq. 10; default 0: use |gravity| */
    fsdem_real disc_length;         /* m; out-of-plane length of 2D discs; default 1 */
    int rotation;                   /* 1: integrate angular velocity; 0: translation only (seed 004) */
    int tangential_damping;         /* 1: tangential dashpot on (Hertz-Mindlin, linear laws); */
                                    /*    default 1 (LIGGGHTS `tangential_damping`) */
    fsdem_dem_tangential_history tangential_history; /* default INCREMENTAL (see the enum) */
    fsdem_dem_coulomb_limit coulomb_limit;   /* default TOTAL (see the enum) */
    fsdem_dem_linear_stiffness linear_stiffness; /* linear law only; default SEED000 */
    int periodic[3];                /* 1: axis a is periodic, of period domain_max - domain_min */
                                    /*    (LIGGGHTS `boundary p`): contacts act across the seam, */
                                    /*    positions wrap; z must be 0 in 2D; default 0, 0, 0 */
    int capacity;                   /* initial particle capacity (grows as needed); default 1024 */
    fsdem_allocator allocator;      /* default: FSDEM_MALLOC/FSDEM_FREE */
    fsdem_log_fn log;               /* optional; default NULL */
    void *log_user;
} fsdem_dem_desc;

/* Defaults for a 2D (discs in x-y) or 3D (spheres) simulation; gravity points down -y or -z. */
FSDEM_API fsdem_dem_desc fsdem_dem_desc_default(int dim);
/* Checks a desc without creating anything; on failure writes the reason to `message` (may be
   NULL). Returns FSDEM_OK or FSDEM_ERR_INVALID_ARG. */
FSDEM_API fsdem_result fsdem_dem_desc_check(const fsdem_dem_desc *desc, char *message,
                                            size_t message_size);
/* Creates a simulation. On FSDEM_ERR_INVALID_ARG the reason goes to desc->log (and is available
   from fsdem_dem_desc_check); *out is NULL on failure. Destroy with fsdem_dem_destroy. */
FSDEM_API fsdem_result fsdem_dem_create(const fsdem_dem_desc *desc, fsdem_dem **out);
FSDEM_API void fsdem_dem_destroy(fsdem_dem *dem);
/* Message of the last failed call on this object ("" after success). Valid until the next call. */
FSDEM_API const char *fsdem_dem_last_error(const fsdem_dem *dem);

/* Adds a material; its index goes to *index (may be NULL). FSDEM_ERR_INVALID_ARG names the field. */
FSDEM_API fsdem_result fsdem_dem_add_material(fsdem_dem *dem, const fsdem_dem_material *material,
                                              int *index);
/* Sets the contact properties of the pair of materials a and b (either order, a == b allowed),
   replacing their mean. FSDEM_ERR_NOT_FOUND for a bad index, FSDEM_ERR_INVALID_ARG names a bad
   field (nothing changes then). */
FSDEM_API fsdem_result fsdem_dem_set_material_pair(fsdem_dem *dem, int a, int b, const fsdem_dem_material_pair *values);
/* The contact properties of the pair a, b in force (zeros for a bad index). */
FSDEM_API fsdem_dem_material_pair fsdem_dem_get_material_pair(const fsdem_dem *dem, int a, int b);

typedef struct fsdem_dem_particle_desc {
    fsdem_vec3 position;         /* m; inside the domain */
    fsdem_vec3 velocity;         /* m/s; default 0 */
    fsdem_vec3 angular_velocity; /* rad/s; default 0 (2D: only z is used) */
    fsdem_real radius;           /* m; > 0; default 0 (must be set) */
    int material;                /* index from fsdem_dem_add_material; default 0 */
    int fixed;                   /* 1: kinematic, moves with its velocity whatever the forces */
} fsdem_dem_particle_desc;

FSDEM_API fsdem_dem_particle_desc fsdem_dem_particle_desc_default(void);
/* Adds a particle at the end; its index goes to *index (may be NULL). Each particle also gets a
   stable id (fsdem_dem_particles.id) that survives removals. Errors: FSDEM_ERR_INVALID_ARG (radius,
   material, non-finite values), FSDEM_ERR_OUT_OF_DOMAIN, FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_dem_add_particle(fsdem_dem *dem, const fsdem_dem_particle_desc *particle,
                                              int *index);
/* Removes particle `index`; later particles move down one index (ids do not change), contact
   history is kept. O(n). FSDEM_ERR_NOT_FOUND for a bad index. */
FSDEM_API fsdem_result fsdem_dem_remove_particle(fsdem_dem *dem, int index);
/* Overwrites a particle's kinematic state (all three vectors). Validated like add_particle. */
FSDEM_API fsdem_result fsdem_dem_set_particle_state(fsdem_dem *dem, int index, fsdem_vec3 position,
                                                    fsdem_vec3 velocity,
                                                    fsdem_vec3 angular_velocity);

/* Read-only views of the particle arrays (structure of arrays), valid until particles are added or
   removed. `force` and `torque` are the contact forces of the last step (N, N m), without gravity
   and without the external loads (fsdem_dem_get_coupling), which are shown too. */
typedef struct fsdem_dem_particles {
    int count;
    int dim;
    const int *id;
    const fsdem_vec3 *position;
    const fsdem_vec3 *velocity;
    const fsdem_vec3 *angular_velocity;
    const fsdem_vec3 *force;
    const fsdem_vec3 *torque;
    const fsdem_vec3 *external_force;
    const fsdem_vec3 *external_torque;
    const fsdem_real *radius;
    const fsdem_real *mass;
    const int *material;
    const unsigned char *fixed;
} fsdem_dem_particles;

FSDEM_API fsdem_dem_particles fsdem_dem_get_particles(const fsdem_dem *dem);

/* External loads of every particle, written by the caller: a force (N) and a torque (N m) at the
   centre, besides contacts and gravity, held fixed over steps (a fluid force during DEM substeps).
   They start at zero; steps read them only once this function has handed them out (or a coupler
   wrote them), so a run without them does not pay for them. Valid until particles are added or
   removed. */
typedef struct fsdem_dem_coupling {
    int count;
    fsdem_vec3 *force;
    fsdem_vec3 *torque;
} fsdem_dem_coupling;

FSDEM_API fsdem_dem_coupling fsdem_dem_get_coupling(fsdem_dem *dem);

/* The DEM's arrays a coupler claims (fsdem_claim; >>couple: one coupler per DEM). */
typedef enum fsdem_dem_arrays {
    FSDEM_DEM_ARRAYS_LOADS = 1    /* the external loads of fsdem_dem_get_coupling */
} fsdem_dem_arrays;

/* The DEM's claim registry (>>core_claims); NULL for a NULL DEM. */
FSDEM_API fsdem_claims *fsdem_dem_claims(fsdem_dem *dem);

/* ---- walls ---- */

typedef enum fsdem_dem_wall_type {
    FSDEM_DEM_WALL_TYPE_PLANE = 0,       /* infinite plane through `a` with unit normal `b` (towards particles) */
    FSDEM_DEM_WALL_TYPE_BOX_INSIDE = 1,  /* axis-aligned box [a, b] holding the particles inside */
    FSDEM_DEM_WALL_TYPE_BOX_OUTSIDE = 2, /* axis-aligned solid box [a, b]; particles stay outside */
    FSDEM_DEM_WALL_TYPE_SEGMENT = 3,     /* 2D segment a-b (both sides) */
    FSDEM_DEM_WALL_TYPE_TRIANGLE = 4,    /* 3D triangle a-b-c (both sides) */
    FSDEM_DEM_WALL_TYPE_SDF = 5          /* signed distance given by a callback (moved by it: fsdem_dem_wall_moved) */
} fsdem_dem_wall_type;


typedef struct fsdem_dem_wall_desc {
    fsdem_dem_wall_type type;
    fsdem_vec3 a, b, c;   /* m; geometry, meaning per type above */
    fsdem_vec3 velocity;  /* m/s; the wall translates with it; default 0 */
    int material;         /* index from fsdem_dem_add_material */
    fsdem_sdf_fn sdf;     /* FSDEM_DEM_WALL_TYPE_SDF only */
    void *sdf_user;
} fsdem_dem_wall_desc;

FSDEM_API fsdem_dem_wall_desc fsdem_dem_wall_plane(fsdem_vec3 point, fsdem_vec3 normal, int material);
FSDEM_API fsdem_dem_wall_desc fsdem_dem_wall_box(fsdem_vec3 lo, fsdem_vec3 hi, int inside, int material);
FSDEM_API fsdem_dem_wall_desc fsdem_dem_wall_segment(fsdem_vec3 a, fsdem_vec3 b, int material);
FSDEM_API fsdem_dem_wall_desc fsdem_dem_wall_triangle(fsdem_vec3 a, fsdem_vec3 b, fsdem_vec3 c, int material);
FSDEM_API fsdem_dem_wall_desc fsdem_dem_wall_sdf(fsdem_sdf_fn sdf, void *user, int material);

/* Adds a wall; its id goes to *id (may be NULL). Ids are stable. FSDEM_ERR_INVALID_ARG names the
   problem (zero normal, degenerate triangle, missing callback, wrong dimension, bad material). */
FSDEM_API fsdem_result fsdem_dem_add_wall(fsdem_dem *dem, const fsdem_dem_wall_desc *wall, int *id);
/* Removes a wall (the id is not reused). */
FSDEM_API fsdem_result fsdem_dem_remove_wall(fsdem_dem *dem, int id);
FSDEM_API fsdem_result fsdem_dem_set_wall_velocity(fsdem_dem *dem, int id, fsdem_vec3 velocity);
/* Tells the neighbour search that wall `id` moved by up to `distance` (m) outside the library, as an
   SDF wall moved by its callback does; without it, particles that were far from the wall at the last
   rebuild would not see it come. FSDEM_ERR_NOT_FOUND, FSDEM_ERR_INVALID_ARG (negative distance). */
FSDEM_API fsdem_result fsdem_dem_wall_moved(fsdem_dem *dem, int id, fsdem_real distance);
/* Force (N) the particles exert on the wall at the last force evaluation. */
FSDEM_API fsdem_vec3 fsdem_dem_wall_force(const fsdem_dem *dem, int id);
/* Impulse (N s) the wall's contacts have given to the particles since it was added, integrated as
   the integrator does: the momentum of the free particles changes by the sum over walls plus the
   impulses of gravity, external forces and contacts with fixed particles. */
FSDEM_API fsdem_vec3 fsdem_dem_wall_impulse(const fsdem_dem *dem, int id);

/* ---- time integration ---- */

/* Advances by one step of the current dt (desc.dt, or the last fsdem_dem_set_dt). Errors:
   FSDEM_ERR_NAN, FSDEM_ERR_OUT_OF_DOMAIN (the step is complete and the message names the particle,
   and dt when it exceeds the stable estimate), FSDEM_ERR_OUT_OF_MEMORY (the neighbour lists could
   not grow: the step stopped part way, after the drift, and is not undone; the object stays
   consistent and a later step rebuilds the lists). */
FSDEM_API fsdem_result fsdem_dem_step(fsdem_dem *dem);
/* One step of dt (s) instead of the current dt (which does not change). FSDEM_ERR_INVALID_ARG for
   dt <= 0 or not finite; otherwise as fsdem_dem_step. */
FSDEM_API fsdem_result fsdem_dem_step_dt(fsdem_dem *dem, fsdem_real dt);
/* Advances by `duration` (s, an outer fluid step) in K = fsdem_dem_substep_count substeps of
   duration/K (seed 000 Eq. 25). External loads stay as they are over the substeps. K goes to *steps
   (may be NULL). Verlet substeps run fused, one pass over the particles each, so this is the fast
   way to take many steps; the state it ends in is that of K calls of fsdem_dem_step_dt, to
   rounding. Errors as fsdem_dem_step, at the substep that met them, and FSDEM_ERR_INVALID_ARG for
   a bad duration or more than FSDEM_DEM_MAX_SUBSTEPS substeps (nothing changes then). */
FSDEM_API fsdem_result fsdem_dem_advance(fsdem_dem *dem, fsdem_real duration, long long *steps);
/* Substeps of fsdem_dem_advance(dem, duration): K = INT(duration/dt) (an exact multiple counts
   whole to a relative 1e-9), or 1 when dt > duration (seed 000 Eq. 25). FSDEM_ERR_INVALID_ARG for a
   duration that is not > 0 and finite, or for K > FSDEM_DEM_MAX_SUBSTEPS. */
FSDEM_API fsdem_result fsdem_dem_substep_count(const fsdem_dem *dem, fsdem_real duration, long long *count);
#define FSDEM_DEM_MAX_SUBSTEPS 100000000LL
/* Called by fsdem_dem_advance_with wherever the advance evaluates forces: once before the first
   substep and after the drift of every substep, with the positions at `time` (s). It writes the
   external loads (fsdem_dem_get_coupling) that the kicks around that time use, such as a buoyancy
   refreshed for the new heights. Velocities are the integrator's at that point (the half-step
   velocity with Verlet). It must not add or remove particles; an error it returns stops the
   advance with that result (its message is the callback's to give through its own object). */
typedef fsdem_result (*fsdem_dem_substep_fn)(void *user, fsdem_dem *dem, double time);
/* fsdem_dem_advance with `fn` (may be NULL) called at every force evaluation. */
FSDEM_API fsdem_result fsdem_dem_advance_with(fsdem_dem *dem, fsdem_real duration, fsdem_dem_substep_fn fn,
                                              void *user, long long *steps);
/* Sets the dt of later fsdem_dem_step and fsdem_dem_advance calls (s, > 0). Logs a warning when it
   exceeds the stable estimate (fsdem_dem_stats.dt_ratio). */
FSDEM_API fsdem_result fsdem_dem_set_dt(fsdem_dem *dem, fsdem_real dt);
/* Simulated time (s). */
FSDEM_API double fsdem_dem_time(const fsdem_dem *dem);
/* Stable time step (s) of the current particles by desc.dt_rule and desc.dt_param (the smallest
   over the particles). FSDEM_ERR_NOT_FOUND when there are no particles. */
FSDEM_API fsdem_result fsdem_dem_stable_dt(const fsdem_dem *dem, fsdem_real *dt);
/* The desc in force: dt is the current dt, dt_rule the resolved rule, dt_param its value. */
FSDEM_API fsdem_dem_desc fsdem_dem_get_desc(const fsdem_dem *dem);

/* ---- diagnostics ---- */

typedef struct fsdem_dem_energy {
    fsdem_real kinetic;    /* J, translational, free particles */
    fsdem_real rotational; /* J */
    fsdem_real potential;  /* J, -m g.x summed over free particles */
    fsdem_real elastic;    /* J, stored in normal and tangential contact springs */
} fsdem_dem_energy;

FSDEM_API fsdem_dem_energy fsdem_dem_get_energy(const fsdem_dem *dem);

typedef struct fsdem_dem_stats {
    long long steps;          /* steps taken */
    double time;              /* s */
    fsdem_real dt;            /* s, the current step */
    fsdem_real stable_dt;     /* s, fsdem_dem_stable_dt at the last neighbour-list build (0: none) */
    fsdem_real dt_ratio;      /* dt / stable_dt; above 1 the log has a warning (0: no particles) */
    long long rebuilds;       /* neighbour-list rebuilds */
    int contacts;             /* particle-particle contacts at the last force evaluation */
    int wall_contacts;        /* particle-wall contacts at the last force evaluation */
    int neighbour_pairs;      /* entries in the particle-particle neighbour list */
    fsdem_real max_overlap;   /* m, largest overlap at the last force evaluation */
    size_t memory_bytes;      /* bytes held by the object */
} fsdem_dem_stats;

FSDEM_API fsdem_dem_stats fsdem_dem_get_stats(const fsdem_dem *dem);

/* One geometric contact (overlap > 0) in the current positions. */
typedef struct fsdem_dem_contact {
    int i;              /* particle index */
    int j;              /* partner particle index (> i), or -1 - wall id for a wall contact */
    fsdem_vec3 normal;  /* unit normal from the partner towards particle i */
    fsdem_real overlap; /* m, including the contact offset */
} fsdem_dem_contact;

/* Lists the contacts of the current positions (found through the neighbour lists, rebuilt first if
   stale). Writes up to `capacity` entries to `out` (may be NULL) and returns the total number, or
   FSDEM_ERR_OUT_OF_MEMORY (negative) when the lists cannot be rebuilt. */
FSDEM_API int fsdem_dem_contacts(fsdem_dem *dem, fsdem_dem_contact *out, int capacity);
