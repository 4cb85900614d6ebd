/* fsdem.h - fluid-solid mixture flows with discrete elements. Single-file C99 library.

   ===== >>doc : documentation ==========================================================================

   USAGE
     In exactly one C or C++ file:
         #define FSDEM_IMPLEMENTATION
         #include "fsdem.h"
     Everywhere else include "fsdem.h" without the define. Link with libm (-lm). Nothing else.

   TABLE OF CONTENTS (grep -n '>>' fsdem.h prints the map)
     >>doc      this text
     >>config   configuration macros
     >>core     real type, vectors, results, allocator, logging
     >>grid     cell grid (uniform spatial binning) shared by DEM, MPS and the couplings
     >>dem      discrete element method: particles, materials, contact laws, walls, integration
     >>io       CSV time series and particle snapshots (CSV, legacy VTK for ParaView)
     >>impl     implementation, in the same order
     >>licence  MIT

   CONFIGURATION MACROS (define before including)
     FSDEM_USE_FLOAT         fsdem_real is float instead of double.
     FSDEM_MALLOC(sz)        default allocator; define FSDEM_MALLOC, FSDEM_REALLOC and FSDEM_FREE
     FSDEM_REALLOC(p, sz)    all three or none. An fsdem_allocator in a desc overrides them per
     FSDEM_FREE(p)           object.
     FSDEM_ASSERT(c)         programmer-error checks (default: assert from <assert.h>).
     FSDEM_API               decoration of public functions (default: extern).

   CONCEPTS
     Units are SI throughout: metres, seconds, kilograms, newtons, pascals, radians.
     Dimension is a runtime field of each desc (2 or 3). Vectors always have three components.
     In 2D the motion lies in the x-y plane, z is unused and gravity defaults to (0, -9.81, 0);
     particles are discs of out-of-plane length `disc_length` (so a 2D run of cylinders has their
     real mass). In 3D particles are spheres and gravity defaults to (0, 0, -9.81).
     Objects are created from a desc filled by fsdem_<noun>_desc_default() and then edited: zero is
     a meaningful value for gravity or friction, so defaults never come from zero-initialisation.

   HELLO WORLD (a sphere dropped on a floor)
     fsdem_dem_desc d = fsdem_dem_desc_default(3);
     d.domain_min = fsdem_v3(-1, -1, 0); d.domain_max = fsdem_v3(1, 1, 2);
     d.law = FSDEM_CONTACT_HERTZ_MINDLIN;
     d.dt = 1e-5;
     fsdem_dem *dem;
     if (fsdem_dem_create(&d, &dem) != FSDEM_OK) return 1;
     fsdem_material mat = fsdem_material_default();          (2500 kg/m3, E = 1e8 Pa, e = 0.5)
     int steel; fsdem_dem_add_material(dem, &mat, &steel);
     fsdem_wall_desc floor = fsdem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 1), steel);
     fsdem_dem_add_wall(dem, &floor, NULL);
     fsdem_particle_desc p = fsdem_particle_desc_default();
     p.position = fsdem_v3(0, 0, 0.5); p.radius = 0.01; p.material = steel;
     fsdem_dem_add_particle(dem, &p, NULL);
     for (int s = 0; s < 100000; ++s)
         if (fsdem_dem_step(dem) != FSDEM_OK) { puts(fsdem_dem_last_error(dem)); break; }
     fsdem_dem_destroy(dem);

   THREAD SAFETY
     No global mutable state. Distinct objects may be used from distinct threads at once; one
     object must not be used from two threads at once.

   ERRORS
     Fallible calls return fsdem_result: FSDEM_OK (0) or a negative code; fsdem_result_string()
     names it. The object keeps a message with the detail (which field, which particle), read with
     fsdem_<object>_last_error(). Bad input is rejected before anything changes, so the object stays
     as it was and usable. A step that produces a non-finite value or moves a particle out of the
     domain completes, returns FSDEM_ERR_NAN or FSDEM_ERR_OUT_OF_DOMAIN and names the particle; the
     caller may remove it and go on. The library never prints and never exits; an optional log
     callback in each desc receives the same messages. FSDEM_ASSERT guards programmer errors only
     (out-of-range indices into arrays the caller owns).
*/
#ifndef FSDEM_H_INCLUDED
#define FSDEM_H_INCLUDED

/* ===== >>config : configuration macros ============================================================ */

#include <stddef.h>

#ifndef FSDEM_API
#define FSDEM_API extern
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ===== >>core : real type, vectors, results, allocator, logging =================================== */

#ifdef FSDEM_USE_FLOAT
typedef float fsdem_real;
#else
typedef double fsdem_real;
#endif

typedef struct fsdem_vec3 {
    fsdem_real x, y, z;
} fsdem_vec3;

/* Result of every fallible call. 0 is success, negative values are errors. */
typedef enum fsdem_result {
    FSDEM_OK = 0,
    FSDEM_ERR_INVALID_ARG = -1,   /* a desc field or argument is out of range or not finite */
    FSDEM_ERR_OUT_OF_MEMORY = -2, /* the allocator returned NULL or a size overflowed */
    FSDEM_ERR_OUT_OF_DOMAIN = -3, /* a particle is (or would be) outside the simulation domain */
    FSDEM_ERR_NAN = -4,           /* a computed value is NaN or infinite */
    FSDEM_ERR_CFL = -5,           /* a time step violates its stability limit */
    FSDEM_ERR_NOT_CONVERGED = -6, /* an iterative solver did not converge */
    FSDEM_ERR_IO = -7,            /* a file could not be opened or written */
    FSDEM_ERR_NOT_FOUND = -8      /* an index or id does not name an existing item */
} fsdem_result;

/* Short constant name of a result code, e.g. "FSDEM_ERR_INVALID_ARG". Never NULL. */
FSDEM_API const char *fsdem_result_string(fsdem_result result);

typedef enum fsdem_log_level {
    FSDEM_LOG_ERROR = 0,
    FSDEM_LOG_WARNING = 1,
    FSDEM_LOG_INFO = 2
} fsdem_log_level;

/* Optional log sink. `message` is valid only during the call. */
typedef void (*fsdem_log_fn)(void *user, fsdem_log_level level, const char *message);

/* Memory hooks of one object. Either both function pointers are set or both are NULL (then the
   FSDEM_MALLOC/FSDEM_FREE macros are used). `size` in free is the size that was allocated. */
typedef struct fsdem_allocator {
    void *(*alloc)(void *user, size_t size);
    void (*free)(void *user, void *ptr, size_t size);
    void *user;
} fsdem_allocator;

/* Vector helpers (inline in every translation unit). */
static inline fsdem_vec3 fsdem_v3(fsdem_real x, fsdem_real y, fsdem_real z) {
    fsdem_vec3 v;
    v.x = x;
    v.y = y;
    v.z = z;
    return v;
}

/* ===== >>grid : cell grid shared by DEM, MPS and the couplings ==================================== */

/* A uniform grid of cubic cells over a box; items (particle indices) are binned by a counting sort,
   so a build is O(n) and a query visits the 3^dim cells around a point. Positions outside the box
   are clamped into its border cells, so every item is found. The cell size is enlarged when the box
   would need more than `max_cells` cells, which keeps memory bounded for any domain.
   The struct is public so solvers can embed it; treat its fields as read-only. */
typedef struct fsdem_cellgrid {
    int dim;                  /* 2 or 3 */
    fsdem_vec3 origin;        /* m, lower corner */
    fsdem_real cell_size;     /* m, edge of one cell (>= the requested size) */
    fsdem_real inv_cell_size; /* 1/m */
    int n[3];                 /* cells per axis (n[2] = 1 in 2D) */
    int cell_count;           /* n[0]*n[1]*n[2] */
    int *cell_start;          /* cell_count + 1 offsets into `items` */
    int *items;               /* item indices sorted by cell */
    int *cell_of;             /* cell of each item, as binned by the last build */
    int item_capacity, cell_capacity;
    fsdem_allocator allocator;
} fsdem_cellgrid;

/* Set up the grid geometry for the box [lo, hi] and a wanted cell size (m). `max_cells` caps the
   number of cells (0: 1<<24). Reuses memory already held. Returns FSDEM_ERR_INVALID_ARG for an empty
   box or a non-positive size, FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_cellgrid_setup(fsdem_cellgrid *grid, const fsdem_allocator *allocator,
                                            int dim, fsdem_vec3 lo, fsdem_vec3 hi,
                                            fsdem_real cell_size, int max_cells);
/* Bin `count` points. Returns FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_cellgrid_build(fsdem_cellgrid *grid, const fsdem_vec3 *points,
                                            int count);
/* Cell holding a point (clamped into the grid) and its integer coordinates. */
FSDEM_API int fsdem_cellgrid_cell(const fsdem_cellgrid *grid, fsdem_vec3 p, int coord[3]);
/* Writes the cells of the 3^dim block around cell coordinates `coord` (those inside the grid) to
   `cells` (room for 27) and returns their number. */
FSDEM_API int fsdem_cellgrid_neighbourhood(const fsdem_cellgrid *grid, const int coord[3],
                                           int cells[27]);
/* Releases the memory; the struct may be set up again. */
FSDEM_API void fsdem_cellgrid_free(fsdem_cellgrid *grid);

/* ===== >>dem : discrete element method ============================================================= */

typedef struct fsdem_dem fsdem_dem;

/* Contact law of a simulation. All laws use Coulomb friction with the material's `friction`. */
typedef enum fsdem_contact_law {
    /* Linear spring-dashpot of seed 000 Eq. 7-18: k from theta and dx (Eq. 10), damping from alpha
       (Eq. 11), tangential spring over one step capped by Coulomb (Eq. 8, 12-15), moment Eq. 9. */
    FSDEM_CONTACT_LINEAR = 0,
    /* Hertz normal force (4/3) E* sqrt(R*) d^1.5, Mindlin tangential spring on the accumulated
       tangential displacement, Tsuji-form damping calibrated so the normal restitution equals the
       material's `restitution` exactly (see >>dem_law in the implementation). */
    FSDEM_CONTACT_HERTZ_MINDLIN = 1,
    /* Granule-In-Cell law of seed 004 Eq. 1a-1c: k_n = E r, viscous tangential force capped by
       |F_n| tan(phi) with tan(phi) = friction. */
    FSDEM_CONTACT_GIC = 2
} fsdem_contact_law;

typedef enum fsdem_integrator {
    /* Velocity Verlet (kick-drift-kick), one force evaluation per step: second order for elastic
       forces; dashpots see the half-step velocity, which makes damping first order in dt (resolve
       a contact with >= 50 steps, or use the predictor-corrector, whose error is far smaller). */
    FSDEM_INTEGRATOR_VERLET = 0,
    /* Predictor-corrector of seed 000 Eq. 21-24, two force evaluations per step. */
    FSDEM_INTEGRATOR_PREDICTOR_CORRECTOR = 1
} fsdem_integrator;

/* Per-material properties. Fields not used by the chosen law are ignored. */
typedef struct fsdem_material {
    fsdem_real density;          /* kg/m^3; default 2500 */
    fsdem_real young_modulus;    /* Pa; Hertz-Mindlin and GIC; default 1e8 */
    fsdem_real poisson_ratio;    /* -; Hertz-Mindlin, GIC, and psi of seed 000 Eq. 12-13; default 0.3 */
    fsdem_real restitution;      /* -; normal restitution e in (0, 1], Hertz-Mindlin; default 0.5 */
    fsdem_real friction;         /* -; Coulomb sliding coefficient mu (tan phi for GIC); default 0.3 */
    fsdem_real rolling_friction; /* -; constant-torque rolling resistance mu_r; default 0 (off) */
    fsdem_real damping_alpha;    /* -; alpha of seed 000 Eq. 11, linear law; default 0.4 */
} fsdem_material;

FSDEM_API fsdem_material fsdem_material_default(void);

typedef struct fsdem_dem_desc {
    int dim;                        /* 2 or 3 */
    fsdem_vec3 domain_min;          /* m; particles must stay inside [domain_min, domain_max] */
    fsdem_vec3 domain_max;          /* m; default (-1,-1,-1)..(1,1,1) */
    fsdem_vec3 gravity;             /* m/s^2; default (0,-9.81,0) in 2D, (0,0,-9.81) in 3D */
    fsdem_contact_law law;          /* default FSDEM_CONTACT_HERTZ_MINDLIN */
    fsdem_integrator integrator;    /* default FSDEM_INTEGRATOR_VERLET */
    fsdem_real dt;                  /* s; time step; default 1e-5 */
    fsdem_real skin;                /* m; neighbour-list margin; < 0: 0.25 x largest radius; default -1 */
    fsdem_real contact_offset;      /* m; imaginary-boundary gap of seed 000 Eq. 19 (2 dx there): */
                                    /*    contacts start at distance r_i + r_j + offset; default 0 */
    fsdem_real linear_theta;        /* -; theta of seed 000 Eq. 10; default 0.01 */
    fsdem_real linear_dx;           /* m; dx of seed 000 Eq. 10; default 0 (must be set for LINEAR) */
    fsdem_real linear_accel;        /* m/s^2; ||g|| of Eq. 10; default 0: use |gravity| */
    fsdem_real disc_length;         /* m; out-of-plane length of 2D discs; default 1 */
    int rotation;                   /* 1: integrate angular velocity; 0: translation only (seed 004) */
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
FSDEM_API fsdem_result fsdem_dem_add_material(fsdem_dem *dem, const fsdem_material *material,
                                              int *index);

typedef struct fsdem_particle_desc {
    fsdem_vec3 position;         /* m; inside the domain */
    fsdem_vec3 velocity;         /* m/s; default 0 */
    fsdem_vec3 angular_velocity; /* rad/s; default 0 (2D: only z is used) */
    fsdem_real radius;           /* m; > 0; default 0 (must be set) */
    int material;                /* index from fsdem_dem_add_material; default 0 */
    int fixed;                   /* 1: kinematic, moves with its velocity whatever the forces */
} fsdem_particle_desc;

FSDEM_API fsdem_particle_desc fsdem_particle_desc_default(void);
/* Adds a particle at the end; its index goes to *index (may be NULL). Each particle also gets a
   stable id (fsdem_particles.id) that survives removals. Errors: FSDEM_ERR_INVALID_ARG (radius,
   material, non-finite values), FSDEM_ERR_OUT_OF_DOMAIN, FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_dem_add_particle(fsdem_dem *dem, const fsdem_particle_desc *particle,
                                              int *index);
/* Removes particle `index`; later particles move down one index (ids do not change), contact
   history is kept. O(n). FSDEM_ERR_NOT_FOUND for a bad index. */
FSDEM_API fsdem_result fsdem_dem_remove_particle(fsdem_dem *dem, int index);
/* Overwrites a particle's kinematic state (all three vectors). Validated like add_particle. */
FSDEM_API fsdem_result fsdem_dem_set_particle_state(fsdem_dem *dem, int index, fsdem_vec3 position,
                                                    fsdem_vec3 velocity,
                                                    fsdem_vec3 angular_velocity);

/* Views of the particle arrays (structure of arrays), valid until particles are added or removed.
   `force` and `torque` are the contact forces of the last step (N, N m), without gravity and
   without the external ones. `external_force`/`external_torque` are written by the caller or a
   coupler and are held fixed over steps (a fluid force during DEM substeps). */
typedef struct fsdem_particles {
    int count;
    int dim;
    const int *id;
    const fsdem_vec3 *position;
    const fsdem_vec3 *velocity;
    const fsdem_vec3 *angular_velocity;
    const fsdem_vec3 *force;
    const fsdem_vec3 *torque;
    fsdem_vec3 *external_force;
    fsdem_vec3 *external_torque;
    const fsdem_real *radius;
    const fsdem_real *mass;
    const int *material;
    const unsigned char *fixed;
} fsdem_particles;

FSDEM_API fsdem_particles fsdem_dem_particles(fsdem_dem *dem);

/* ---- walls ---- */

typedef enum fsdem_wall_type {
    FSDEM_WALL_PLANE = 0,       /* infinite plane through `a` with unit normal `b` (towards particles) */
    FSDEM_WALL_BOX_INSIDE = 1,  /* axis-aligned box [a, b] holding the particles inside */
    FSDEM_WALL_BOX_OUTSIDE = 2, /* axis-aligned solid box [a, b]; particles stay outside */
    FSDEM_WALL_SEGMENT = 3,     /* 2D segment a-b (both sides) */
    FSDEM_WALL_TRIANGLE = 4,    /* 3D triangle a-b-c (both sides) */
    FSDEM_WALL_SDF = 5          /* signed distance given by a callback */
} fsdem_wall_type;

/* Signed distance (m) from p to a solid, positive on the particles' side; writes the unit outward
   normal (the distance gradient) to *normal. */
typedef fsdem_real (*fsdem_sdf_fn)(void *user, fsdem_vec3 p, fsdem_vec3 *normal);

typedef struct fsdem_wall_desc {
    fsdem_wall_type type;
    fsdem_vec3 a, b, c;   /* m; geometry, meaning per type above */
    fsdem_vec3 velocity;  /* m/s; the wall translates with it; default 0 */
    int material;         /* index from fsdem_dem_add_material */
    fsdem_sdf_fn sdf;     /* FSDEM_WALL_SDF only */
    void *sdf_user;
} fsdem_wall_desc;

FSDEM_API fsdem_wall_desc fsdem_wall_plane(fsdem_vec3 point, fsdem_vec3 normal, int material);
FSDEM_API fsdem_wall_desc fsdem_wall_box(fsdem_vec3 lo, fsdem_vec3 hi, int inside, int material);
FSDEM_API fsdem_wall_desc fsdem_wall_segment(fsdem_vec3 a, fsdem_vec3 b, int material);
FSDEM_API fsdem_wall_desc fsdem_wall_triangle(fsdem_vec3 a, fsdem_vec3 b, fsdem_vec3 c, int material);
FSDEM_API fsdem_wall_desc fsdem_wall_sdf(fsdem_sdf_fn sdf, void *user, int material);

/* Adds a wall; its id goes to *id (may be NULL). Ids are stable. FSDEM_ERR_INVALID_ARG names the
   problem (zero normal, degenerate triangle, missing callback, wrong dimension, bad material). */
FSDEM_API fsdem_result fsdem_dem_add_wall(fsdem_dem *dem, const fsdem_wall_desc *wall, int *id);
/* Removes a wall (the id is not reused). */
FSDEM_API fsdem_result fsdem_dem_remove_wall(fsdem_dem *dem, int id);
FSDEM_API fsdem_result fsdem_dem_set_wall_velocity(fsdem_dem *dem, int id, fsdem_vec3 velocity);
/* Force (N) the particles exert on the wall at the last force evaluation. */
FSDEM_API fsdem_vec3 fsdem_dem_wall_force(const fsdem_dem *dem, int id);
/* Impulse (N s) the wall has given to the particles since it was added (integrated consistently
   with the integrator, so total particle momentum changes by exactly the sum over walls). */
FSDEM_API fsdem_vec3 fsdem_dem_wall_impulse(const fsdem_dem *dem, int id);

/* ---- time integration ---- */

/* Advances by one step of desc.dt (or the last fsdem_dem_set_dt). Errors: FSDEM_ERR_NAN,
   FSDEM_ERR_OUT_OF_DOMAIN (the step is complete and the message names the particle),
   FSDEM_ERR_OUT_OF_MEMORY (neighbour lists could not grow; nothing moved). */
FSDEM_API fsdem_result fsdem_dem_step(fsdem_dem *dem);
/* Advances by an outer (fluid) step dt_outer with K = INT(dt_outer/dt) substeps of dt_outer/K, or
   one substep of dt_outer when dt > dt_outer (seed 000 Eq. 25). External forces stay fixed over
   the substeps. K goes to *substeps (may be NULL). */
FSDEM_API fsdem_result fsdem_dem_advance(fsdem_dem *dem, fsdem_real dt_outer, int *substeps);
FSDEM_API fsdem_result fsdem_dem_set_dt(fsdem_dem *dem, fsdem_real dt);
FSDEM_API fsdem_real fsdem_dem_dt(const fsdem_dem *dem);
FSDEM_API fsdem_real fsdem_dem_time(const fsdem_dem *dem);

typedef enum fsdem_dt_rule {
    /* seed 000 Eq. 18: (2 pi / gamma) sqrt(m_ij / k), k from Eq. 10; `param` is gamma (150 there) */
    FSDEM_DT_LINEAR_SEED000 = 0,
    /* seed 002 Eq. 38, the Rayleigh time pi R sqrt(2 rho (1+nu)/E) / (0.1631 nu + 0.8766) over all
       particles; multiply by a safety fraction `param` (e.g. 0.2) */
    FSDEM_DT_RAYLEIGH = 1,
    /* seed 004 Eq. 32: (1/2) sqrt(m / k_n), k_n = E r; `param` unused */
    FSDEM_DT_GIC = 2
} fsdem_dt_rule;

/* Stable time step of the current particles by `rule` (smallest over particles). FSDEM_ERR_NOT_FOUND
   when there are no particles, FSDEM_ERR_INVALID_ARG for a bad param. */
FSDEM_API fsdem_result fsdem_dem_dt_estimate(const fsdem_dem *dem, fsdem_dt_rule rule,
                                             fsdem_real param, fsdem_real *dt);

/* ---- diagnostics ---- */

typedef struct fsdem_energy {
    fsdem_real kinetic;    /* J, translational, free particles */
    fsdem_real rotational; /* J */
    fsdem_real potential;  /* J, -m g.x summed over free particles */
    fsdem_real elastic;    /* J, stored in normal and tangential contact springs */
} fsdem_energy;

FSDEM_API fsdem_energy fsdem_dem_energy(const fsdem_dem *dem);

typedef struct fsdem_dem_stats {
    long long steps;          /* steps taken */
    long long rebuilds;       /* neighbour-list rebuilds */
    int contacts;             /* particle-particle contacts at the last force evaluation */
    int wall_contacts;        /* particle-wall contacts at the last force evaluation */
    int neighbour_pairs;      /* entries in the particle-particle neighbour list */
    fsdem_real max_overlap;   /* m, largest overlap at the last force evaluation */
    size_t memory_bytes;      /* bytes held by the object */
} fsdem_dem_stats;

FSDEM_API fsdem_dem_stats fsdem_dem_get_stats(const fsdem_dem *dem);

/* One geometric contact (overlap > 0) in the current positions. */
typedef struct fsdem_contact_info {
    int i;              /* particle index */
    int j;              /* partner particle index (> i), or -1 - wall id for a wall contact */
    fsdem_vec3 normal;  /* unit normal from the partner towards particle i */
    fsdem_real overlap; /* m, including the contact offset */
} fsdem_contact_info;

/* Lists the contacts of the current positions (found through the neighbour lists, rebuilt first if
   stale). Writes up to `capacity` entries to `out` (may be NULL) and returns the total number, or
   FSDEM_ERR_OUT_OF_MEMORY (negative) when the lists cannot be rebuilt. */
FSDEM_API int fsdem_dem_contacts(fsdem_dem *dem, fsdem_contact_info *out, int capacity);

/* ===== >>io : CSV time series and particle snapshots =============================================== */

/* A CSV time series: a header row, then one row of numbers per call. Owned by the caller. */
typedef struct fsdem_csv {
    void *file; /* FILE*, NULL when closed */
    int columns;
} fsdem_csv;

/* Opens `path` for writing and writes `header` (comma-separated names, e.g. "t,x_ave,z_ave").
   FSDEM_ERR_IO when the file cannot be opened; FSDEM_ERR_INVALID_ARG for an empty header. */
FSDEM_API fsdem_result fsdem_csv_open(fsdem_csv *csv, const char *path, const char *header);
/* Writes one row; `count` must equal the number of header columns. */
FSDEM_API fsdem_result fsdem_csv_row(fsdem_csv *csv, const fsdem_real *values, int count);
FSDEM_API fsdem_result fsdem_csv_close(fsdem_csv *csv);

/* Particle snapshot as CSV: id,x,y,z,vx,vy,vz,wx,wy,wz,radius,material. */
FSDEM_API fsdem_result fsdem_dem_write_csv(const fsdem_dem *dem, const char *path);
/* Particle snapshot as legacy VTK polydata (ParaView: Glyph filter, scale by "radius"). */
FSDEM_API fsdem_result fsdem_dem_write_vtk(const fsdem_dem *dem, const char *path);

#ifdef __cplusplus
}
#endif
#endif /* FSDEM_H_INCLUDED */

/* ===== >>impl : implementation ===================================================================== */
#ifdef FSDEM_IMPLEMENTATION
#ifndef FSDEM_IMPLEMENTATION_DONE
#define FSDEM_IMPLEMENTATION_DONE

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#if defined(FSDEM_MALLOC) && defined(FSDEM_REALLOC) && defined(FSDEM_FREE)
/* user-supplied */
#elif !defined(FSDEM_MALLOC) && !defined(FSDEM_REALLOC) && !defined(FSDEM_FREE)
#include <stdlib.h>
#define FSDEM_MALLOC(sz) malloc(sz)
#define FSDEM_REALLOC(p, sz) realloc(p, sz)
#define FSDEM_FREE(p) free(p)
#else
#error "fsdem.h: define all of FSDEM_MALLOC, FSDEM_REALLOC and FSDEM_FREE, or none"
#endif

#ifndef FSDEM_ASSERT
#include <assert.h>
#define FSDEM_ASSERT(c) assert(c)
#endif

/* ===== >>impl_core : results, allocator, messages, vector algebra ================================== */

#define FSDEM__PI 3.14159265358979323846
#define FSDEM__MESSAGE_SIZE 256

const char *fsdem_result_string(fsdem_result result) {
    switch (result) {
    case FSDEM_OK: return "FSDEM_OK";
    case FSDEM_ERR_INVALID_ARG: return "FSDEM_ERR_INVALID_ARG";
    case FSDEM_ERR_OUT_OF_MEMORY: return "FSDEM_ERR_OUT_OF_MEMORY";
    case FSDEM_ERR_OUT_OF_DOMAIN: return "FSDEM_ERR_OUT_OF_DOMAIN";
    case FSDEM_ERR_NAN: return "FSDEM_ERR_NAN";
    case FSDEM_ERR_CFL: return "FSDEM_ERR_CFL";
    case FSDEM_ERR_NOT_CONVERGED: return "FSDEM_ERR_NOT_CONVERGED";
    case FSDEM_ERR_IO: return "FSDEM_ERR_IO";
    case FSDEM_ERR_NOT_FOUND: return "FSDEM_ERR_NOT_FOUND";
    }
    return "FSDEM_ERR_UNKNOWN";
}

static void *fsdem__alloc(const fsdem_allocator *a, size_t size) {
    if (size == 0) size = 1;
    return a->alloc ? a->alloc(a->user, size) : FSDEM_MALLOC(size);
}

static void fsdem__free(const fsdem_allocator *a, void *ptr, size_t size) {
    if (!ptr) return;
    if (a->free) a->free(a->user, ptr, size);
    else FSDEM_FREE(ptr);
}

/* Grows *ptr (holding *capacity elements of `elem` bytes, `used` of them live) to at least `need`
   elements, by doubling. Leaves *ptr untouched on failure. */
static fsdem_result fsdem__grow(const fsdem_allocator *a, void **ptr, int *capacity, int used,
                                int need, size_t elem) {
    int cap = *capacity > 0 ? *capacity : 16;
    void *fresh;
    if (need <= *capacity && *ptr) return FSDEM_OK;
    while (cap < need) {
        if (cap > (1 << 29)) return FSDEM_ERR_OUT_OF_MEMORY;
        cap *= 2;
    }
    if ((size_t)cap > ((size_t)-1) / elem) return FSDEM_ERR_OUT_OF_MEMORY;
    fresh = fsdem__alloc(a, (size_t)cap * elem);
    if (!fresh) return FSDEM_ERR_OUT_OF_MEMORY;
    if (*ptr && used > 0) memcpy(fresh, *ptr, (size_t)used * elem);
    fsdem__free(a, *ptr, (size_t)(*capacity) * elem);
    *ptr = fresh;
    *capacity = cap;
    return FSDEM_OK;
}

/* Message and log sink shared by all objects. */
typedef struct fsdem__status {
    char message[FSDEM__MESSAGE_SIZE];
    fsdem_log_fn log;
    void *log_user;
} fsdem__status;

static fsdem_result fsdem__vfail(fsdem__status *s, fsdem_result code, const char *fmt, va_list ap) {
    vsnprintf(s->message, sizeof s->message, fmt, ap);
    if (s->log) s->log(s->log_user, FSDEM_LOG_ERROR, s->message);
    return code;
}

static fsdem_result fsdem__fail(fsdem__status *s, fsdem_result code, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    code = fsdem__vfail(s, code, fmt, ap);
    va_end(ap);
    return code;
}

static fsdem_result fsdem__ok(fsdem__status *s) {
    s->message[0] = '\0';
    return FSDEM_OK;
}

static int fsdem__finite(fsdem_real x) { return x == x && x - x == 0; }
static int fsdem__finite3(fsdem_vec3 v) {
    return fsdem__finite(v.x) && fsdem__finite(v.y) && fsdem__finite(v.z);
}

static fsdem_vec3 fsdem__add(fsdem_vec3 a, fsdem_vec3 b) { return fsdem_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static fsdem_vec3 fsdem__sub(fsdem_vec3 a, fsdem_vec3 b) { return fsdem_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static fsdem_vec3 fsdem__scale(fsdem_vec3 a, fsdem_real s) { return fsdem_v3(a.x * s, a.y * s, a.z * s); }
static fsdem_vec3 fsdem__madd(fsdem_vec3 a, fsdem_vec3 b, fsdem_real s) {
    return fsdem_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s);
}
static fsdem_real fsdem__dot(fsdem_vec3 a, fsdem_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static fsdem_vec3 fsdem__cross(fsdem_vec3 a, fsdem_vec3 b) {
    return fsdem_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static fsdem_real fsdem__norm(fsdem_vec3 a) { return (fsdem_real)sqrt(fsdem__dot(a, a)); }
static fsdem_vec3 fsdem__zero3(void) { return fsdem_v3(0, 0, 0); }
static fsdem_real fsdem__comp(fsdem_vec3 v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

/* ===== >>impl_grid : cell grid ===================================================================== */

fsdem_result fsdem_cellgrid_setup(fsdem_cellgrid *g, const fsdem_allocator *allocator, int dim,
                                  fsdem_vec3 lo, fsdem_vec3 hi, fsdem_real cell_size, int max_cells) {
    double extent[3], cells = 1;
    int axis;
    if (allocator) g->allocator = *allocator;
    if ((dim != 2 && dim != 3) || !(cell_size > 0) || !fsdem__finite(cell_size) ||
        !fsdem__finite3(lo) || !fsdem__finite3(hi))
        return FSDEM_ERR_INVALID_ARG;
    if (max_cells <= 0) max_cells = 1 << 24;
    for (axis = 0; axis < 3; ++axis) {
        extent[axis] = axis < dim ? (double)fsdem__comp(hi, axis) - fsdem__comp(lo, axis) : 0;
        if (axis < dim && !(extent[axis] > 0)) return FSDEM_ERR_INVALID_ARG;
    }
    /* Enlarge the cell until the cell count fits: a coarse grid is slower, never wrong. */
    for (;;) {
        cells = 1;
        for (axis = 0; axis < dim; ++axis) cells *= floor(extent[axis] / cell_size) + 1;
        if (cells <= max_cells) break;
        cell_size *= (fsdem_real)1.25;
    }
    g->dim = dim;
    g->origin = lo;
    g->cell_size = cell_size;
    g->inv_cell_size = 1 / cell_size;
    for (axis = 0; axis < 3; ++axis)
        g->n[axis] = axis < dim ? (int)floor(extent[axis] / cell_size) + 1 : 1;
    g->cell_count = g->n[0] * g->n[1] * g->n[2];
    if (g->cell_count + 1 > g->cell_capacity) {
        fsdem__free(&g->allocator, g->cell_start, sizeof(int) * (size_t)g->cell_capacity);
        g->cell_capacity = 0;
        g->cell_start = (int *)fsdem__alloc(&g->allocator, sizeof(int) * (size_t)(g->cell_count + 1));
        if (!g->cell_start) return FSDEM_ERR_OUT_OF_MEMORY;
        g->cell_capacity = g->cell_count + 1;
    }
    memset(g->cell_start, 0, sizeof(int) * (size_t)(g->cell_count + 1));
    return FSDEM_OK;
}

static int fsdem__cell_coord(const fsdem_cellgrid *g, fsdem_real x, int axis) {
    fsdem_real s = (x - fsdem__comp(g->origin, axis)) * g->inv_cell_size;
    int c;
    if (!(s > 0)) return 0; /* also catches NaN */
    c = s < (fsdem_real)g->n[axis] ? (int)s : g->n[axis] - 1;
    return c;
}

int fsdem_cellgrid_cell(const fsdem_cellgrid *g, fsdem_vec3 p, int coord[3]) {
    int c[3];
    c[0] = fsdem__cell_coord(g, p.x, 0);
    c[1] = fsdem__cell_coord(g, p.y, 1);
    c[2] = g->dim == 3 ? fsdem__cell_coord(g, p.z, 2) : 0;
    if (coord) {
        coord[0] = c[0];
        coord[1] = c[1];
        coord[2] = c[2];
    }
    return (c[2] * g->n[1] + c[1]) * g->n[0] + c[0];
}

fsdem_result fsdem_cellgrid_build(fsdem_cellgrid *g, const fsdem_vec3 *points, int count) {
    int i, c, sum = 0;
    if (count > g->item_capacity) {
        int cap = count + count / 4 + 16;
        int *items = (int *)fsdem__alloc(&g->allocator, sizeof(int) * (size_t)cap);
        int *cell_of = (int *)fsdem__alloc(&g->allocator, sizeof(int) * (size_t)cap);
        if (!items || !cell_of) {
            fsdem__free(&g->allocator, items, sizeof(int) * (size_t)cap);
            fsdem__free(&g->allocator, cell_of, sizeof(int) * (size_t)cap);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
        fsdem__free(&g->allocator, g->items, sizeof(int) * (size_t)g->item_capacity);
        fsdem__free(&g->allocator, g->cell_of, sizeof(int) * (size_t)g->item_capacity);
        g->items = items;
        g->cell_of = cell_of;
        g->item_capacity = cap;
    }
    memset(g->cell_start, 0, sizeof(int) * (size_t)(g->cell_count + 1));
    for (i = 0; i < count; ++i) {
        c = fsdem_cellgrid_cell(g, points[i], NULL);
        g->cell_of[i] = c;
        g->cell_start[c + 1]++;
    }
    for (c = 0; c < g->cell_count; ++c) {
        sum += g->cell_start[c + 1];
        g->cell_start[c + 1] = sum;
    }
    /* Counting sort; cell_start[c] is used as a cursor and restored afterwards. */
    for (i = 0; i < count; ++i) g->items[g->cell_start[g->cell_of[i]]++] = i;
    for (c = g->cell_count; c > 0; --c) g->cell_start[c] = g->cell_start[c - 1];
    g->cell_start[0] = 0;
    return FSDEM_OK;
}

int fsdem_cellgrid_neighbourhood(const fsdem_cellgrid *g, const int coord[3], int cells[27]) {
    int count = 0, dx, dy, dz, zr = g->dim == 3 ? 1 : 0;
    for (dz = -zr; dz <= zr; ++dz) {
        int z = coord[2] + dz;
        if (z < 0 || z >= g->n[2]) continue;
        for (dy = -1; dy <= 1; ++dy) {
            int y = coord[1] + dy;
            if (y < 0 || y >= g->n[1]) continue;
            for (dx = -1; dx <= 1; ++dx) {
                int x = coord[0] + dx;
                if (x < 0 || x >= g->n[0]) continue;
                cells[count++] = (z * g->n[1] + y) * g->n[0] + x;
            }
        }
    }
    return count;
}

void fsdem_cellgrid_free(fsdem_cellgrid *g) {
    fsdem__free(&g->allocator, g->cell_start, sizeof(int) * (size_t)g->cell_capacity);
    fsdem__free(&g->allocator, g->items, sizeof(int) * (size_t)g->item_capacity);
    fsdem__free(&g->allocator, g->cell_of, sizeof(int) * (size_t)g->item_capacity);
    g->cell_start = g->items = g->cell_of = NULL;
    g->cell_capacity = g->item_capacity = 0;
}

/* ===== >>impl_dem : discrete element method ======================================================== */

/* Constants of one material pair, computed when a material is added. */
typedef struct fsdem__pair {
    fsdem_real e_star;   /* Pa, 1/E* = (1-nu_i^2)/E_i + (1-nu_j^2)/E_j (Hertz) */
    fsdem_real g_star;   /* Pa, 1/G* = 2(2-nu_i)(1+nu_i)/E_i + 2(2-nu_j)(1+nu_j)/E_j (Mindlin) */
    fsdem_real e_pair;   /* Pa, 2/(1/E_i + 1/E_j): equals E for one material (GIC, k_n = E r) */
    fsdem_real nu;       /* -, mean Poisson ratio (psi of seed 000 Eq. 12-13) */
    fsdem_real alpha;    /* -, mean alpha of seed 000 Eq. 11 */
    fsdem_real friction; /* -, mean mu */
    fsdem_real rolling;  /* -, mean mu_r */
    fsdem_real restitution; /* -, mean e */
    fsdem_real tsuji;    /* -, damping coefficient giving that restitution (>>dem_law) */
} fsdem__pair;

typedef struct fsdem__wall {
    fsdem_wall_desc d;
    int active;
    fsdem_vec3 force;   /* N, exerted by the particles on the wall at the last force evaluation */
    fsdem_vec3 impulse; /* N s, given by the wall to the particles since it was added */
    fsdem_vec3 force_a; /* N, force of the predictor evaluation (predictor-corrector) */
    fsdem_real moved;   /* m, distance travelled since the last neighbour-list build */
} fsdem__wall;

/* Neighbour list in compressed rows: the entries of particle i are start[i] .. start[i+1]-1. Each
   entry names a partner (particle j > i, or wall*8+face) and keeps the contact's tangential spring
   displacement, which is the contact history carried across steps and rebuilds. */
typedef struct fsdem__entry {
    int other;
    fsdem_vec3 history; /* m */
} fsdem__entry;

typedef struct fsdem__list {
    int *start;
    int start_capacity;
    int rows; /* particles the list was built for */
    fsdem__entry *entry;
    int count, capacity;
} fsdem__list;

/* One particle-wall contact of the current positions. */
typedef struct fsdem__wall_hit {
    int entry;         /* index into the particle-wall list */
    fsdem_vec3 n;      /* unit normal from the wall towards the particle */
    fsdem_real delta;  /* m, overlap > 0 */
    int on_feature;    /* contact point on a triangle edge/vertex or a segment end */
} fsdem__wall_hit;

#define FSDEM__WALL_KEY(wall, face) ((wall) * 8 + (face))
#define FSDEM__WALL_OF(key) ((key) / 8)
#define FSDEM__FACE_OF(key) ((key) % 8)

struct fsdem_dem {
    fsdem_dem_desc desc;
    fsdem__status status;
    fsdem_allocator allocator;
    fsdem_real dt, time;
    long long steps, rebuilds;

    /* particles, structure of arrays */
    int n, capacity, next_id;
    int *id, *material, *old_of; /* old_of: row in the previous neighbour lists, -1 if new */
    unsigned char *fixed;
    fsdem_vec3 *x, *v, *w, *f, *t, *fext, *text, *x_ref;
    fsdem_vec3 *x0, *v0, *w0, *fa, *ta; /* predictor-corrector: start state and first forces */
    fsdem_real *r, *m, *inv_m, *inv_i;

    fsdem_material *materials;
    int material_count, material_capacity;
    fsdem__pair *pairs; /* material_count^2 */
    int pair_capacity;

    fsdem__wall *walls;
    int wall_count, wall_capacity;

    fsdem__list pp, pp_old, pw, pw_old;
    struct fsdem__wall_hit *hits; /* scratch: one particle's wall contacts (fsdem__wall_hits) */
    int hit_capacity;
    fsdem_cellgrid grid;
    fsdem_real skin, r_max, max_disp2, k0_linear;
    int need_rebuild, forces_valid;
    int contacts, wall_contacts;
    fsdem_real max_overlap;
};

/* ---- >>dem_desc : defaults and validation ---- */

fsdem_material fsdem_material_default(void) {
    fsdem_material m;
    m.density = 2500;
    m.young_modulus = 1e8;
    m.poisson_ratio = (fsdem_real)0.3;
    m.restitution = (fsdem_real)0.5;
    m.friction = (fsdem_real)0.3;
    m.rolling_friction = 0;
    m.damping_alpha = (fsdem_real)0.4;
    return m;
}

fsdem_dem_desc fsdem_dem_desc_default(int dim) {
    fsdem_dem_desc d;
    memset(&d, 0, sizeof d);
    d.dim = dim;
    d.domain_min = fsdem_v3(-1, -1, -1);
    d.domain_max = fsdem_v3(1, 1, 1);
    d.gravity = dim == 2 ? fsdem_v3(0, (fsdem_real)-9.81, 0) : fsdem_v3(0, 0, (fsdem_real)-9.81);
    d.law = FSDEM_CONTACT_HERTZ_MINDLIN;
    d.integrator = FSDEM_INTEGRATOR_VERLET;
    d.dt = (fsdem_real)1e-5;
    d.skin = -1;
    d.contact_offset = 0;
    d.linear_theta = (fsdem_real)0.01;
    d.linear_dx = 0;
    d.linear_accel = 0;
    d.disc_length = 1;
    d.rotation = 1;
    d.capacity = 1024;
    return d;
}

/* Writes "why" to msg and returns FSDEM_ERR_INVALID_ARG. */
static fsdem_result fsdem__reject(char *msg, size_t size, const char *fmt, ...) {
    va_list ap;
    if (msg && size) {
        va_start(ap, fmt);
        vsnprintf(msg, size, fmt, ap);
        va_end(ap);
    }
    return FSDEM_ERR_INVALID_ARG;
}

fsdem_result fsdem_dem_desc_check(const fsdem_dem_desc *d, char *msg, size_t size) {
    int axis;
    if (!d) return fsdem__reject(msg, size, "fsdem_dem_desc is NULL");
    if (d->dim != 2 && d->dim != 3)
        return fsdem__reject(msg, size, "fsdem_dem_desc.dim must be 2 or 3 (got %d)", d->dim);
    if (!fsdem__finite3(d->domain_min) || !fsdem__finite3(d->domain_max))
        return fsdem__reject(msg, size, "fsdem_dem_desc.domain_min/domain_max must be finite");
    for (axis = 0; axis < d->dim; ++axis)
        if (!(fsdem__comp(d->domain_max, axis) > fsdem__comp(d->domain_min, axis)))
            return fsdem__reject(msg, size, "fsdem_dem_desc.domain_max must exceed domain_min on axis %d",
                                 axis);
    if (!fsdem__finite3(d->gravity)) return fsdem__reject(msg, size, "fsdem_dem_desc.gravity is not finite");
    if (d->law != FSDEM_CONTACT_LINEAR && d->law != FSDEM_CONTACT_HERTZ_MINDLIN && d->law != FSDEM_CONTACT_GIC)
        return fsdem__reject(msg, size, "fsdem_dem_desc.law is not a fsdem_contact_law (%d)", (int)d->law);
    if (d->integrator != FSDEM_INTEGRATOR_VERLET && d->integrator != FSDEM_INTEGRATOR_PREDICTOR_CORRECTOR)
        return fsdem__reject(msg, size, "fsdem_dem_desc.integrator is not a fsdem_integrator (%d)",
                             (int)d->integrator);
    if (!(d->dt > 0) || !fsdem__finite(d->dt))
        return fsdem__reject(msg, size, "fsdem_dem_desc.dt must be > 0 and finite (got %g s)", (double)d->dt);
    if (!fsdem__finite(d->skin)) return fsdem__reject(msg, size, "fsdem_dem_desc.skin is not finite");
    if (!(d->contact_offset >= 0) || !fsdem__finite(d->contact_offset))
        return fsdem__reject(msg, size, "fsdem_dem_desc.contact_offset must be >= 0 (got %g m)",
                             (double)d->contact_offset);
    if (!(d->disc_length > 0) || !fsdem__finite(d->disc_length))
        return fsdem__reject(msg, size, "fsdem_dem_desc.disc_length must be > 0 (got %g m)", (double)d->disc_length);
    if (d->capacity < 0) return fsdem__reject(msg, size, "fsdem_dem_desc.capacity must be >= 0");
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        return fsdem__reject(msg, size, "fsdem_dem_desc.allocator: set both alloc and free, or neither");
    if (d->law == FSDEM_CONTACT_LINEAR) {
        fsdem_real accel = d->linear_accel > 0 ? d->linear_accel : fsdem__norm(d->gravity);
        if (!(d->linear_theta > 0) || !fsdem__finite(d->linear_theta))
            return fsdem__reject(msg, size, "fsdem_dem_desc.linear_theta must be > 0 (got %g)", (double)d->linear_theta);
        if (!(d->linear_dx > 0) || !fsdem__finite(d->linear_dx))
            return fsdem__reject(msg, size, "fsdem_dem_desc.linear_dx must be > 0 for the linear law (got %g m)",
                                 (double)d->linear_dx);
        if (!(d->linear_accel >= 0) || !fsdem__finite(d->linear_accel))
            return fsdem__reject(msg, size, "fsdem_dem_desc.linear_accel must be >= 0 (got %g)", (double)d->linear_accel);
        if (!(accel > 0))
            return fsdem__reject(msg, size, "the linear law needs ||g|| > 0 in seed 000 Eq. 10: set "
                                            "fsdem_dem_desc.linear_accel when gravity is zero");
    }
    return FSDEM_OK;
}

static fsdem_result fsdem__material_check(const fsdem_material *m, char *msg, size_t size) {
    if (!m) return fsdem__reject(msg, size, "fsdem_material is NULL");
    if (!(m->density > 0) || !fsdem__finite(m->density))
        return fsdem__reject(msg, size, "fsdem_material.density must be > 0 (got %g kg/m^3)", (double)m->density);
    /* An infinite modulus is allowed: a rigid wall material. */
    if (!(m->young_modulus > 0))
        return fsdem__reject(msg, size, "fsdem_material.young_modulus must be > 0 (got %g Pa)", (double)m->young_modulus);
    if (!(m->poisson_ratio > -1 && m->poisson_ratio <= (fsdem_real)0.5))
        return fsdem__reject(msg, size, "fsdem_material.poisson_ratio must be in (-1, 0.5] (got %g)",
                             (double)m->poisson_ratio);
    if (!(m->restitution > 0 && m->restitution <= 1))
        return fsdem__reject(msg, size, "fsdem_material.restitution must be in (0, 1] (got %g)", (double)m->restitution);
    if (!(m->friction >= 0) || !fsdem__finite(m->friction))
        return fsdem__reject(msg, size, "fsdem_material.friction must be >= 0 (got %g)", (double)m->friction);
    if (!(m->rolling_friction >= 0) || !fsdem__finite(m->rolling_friction))
        return fsdem__reject(msg, size, "fsdem_material.rolling_friction must be >= 0 (got %g)",
                             (double)m->rolling_friction);
    if (!(m->damping_alpha >= 0) || !fsdem__finite(m->damping_alpha))
        return fsdem__reject(msg, size, "fsdem_material.damping_alpha must be >= 0 (got %g)", (double)m->damping_alpha);
    return FSDEM_OK;
}

/* ---- >>dem_law : contact laws ---- */

/* Restitution of the dimensionless Hertz contact with Tsuji-form damping,
       x'' = -max(0, x^(3/2) + a x^(1/4) x'),   x(0) = 0, x'(0) = 1,
   which is the contact m d'' = -k d^(3/2) - a sqrt(m k) d^(1/4) d' scaled by t0 = (m/(k v0^0.5))^0.4,
   d0 = v0 t0. The scaling removes m, k and v0, so e depends on a alone (Tsuji et al. 1992), and the
   force is clamped at zero (no adhesion) as it is in the simulation. Integrated with RK4. */
static double fsdem__hertz_restitution(double a) {
    double x = 0, v = 1, h = 4e-3 / (1 + a); /* ~800 steps per contact: e to about 1e-6 */
    int step;
    for (step = 0; step < 100000000; ++step) {
        double k1x, k1v, k2x, k2v, k3x, k3v, k4x, k4v, xs, vs, xn, vn;
#define FSDEM__HERTZ_ACC(X, V) (-fmax(0.0, fmax(X, 0.0) * sqrt(fmax(X, 0.0)) + a * sqrt(sqrt(fmax(X, 0.0))) * (V)))
        k1x = v;
        k1v = FSDEM__HERTZ_ACC(x, v);
        xs = x + 0.5 * h * k1x;
        vs = v + 0.5 * h * k1v;
        k2x = vs;
        k2v = FSDEM__HERTZ_ACC(xs, vs);
        xs = x + 0.5 * h * k2x;
        vs = v + 0.5 * h * k2v;
        k3x = vs;
        k3v = FSDEM__HERTZ_ACC(xs, vs);
        xs = x + h * k3x;
        vs = v + h * k3v;
        k4x = vs;
        k4v = FSDEM__HERTZ_ACC(xs, vs);
#undef FSDEM__HERTZ_ACC
        xn = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
        vn = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
        if (step > 0 && xn <= 0) {
            double s = x / (x - xn); /* linear interpolation to the crossing */
            return -(v + s * (vn - v));
        }
        x = xn;
        v = vn;
    }
    return 0;
}

/* Damping coefficient a whose restitution is e (bisection; e decreases monotonically with a). */
static fsdem_real fsdem__tsuji_coefficient(fsdem_real e) {
    double lo = 0, hi = 1, mid = 0;
    int it;
    if (e >= 1) return 0;
    while (fsdem__hertz_restitution(hi) > e && hi < 1e4) hi *= 2;
    for (it = 0; it < 40; ++it) {
        mid = 0.5 * (lo + hi);
        if (fsdem__hertz_restitution(mid) > e) lo = mid;
        else hi = mid;
    }
    return (fsdem_real)(0.5 * (lo + hi));
}

static fsdem_real fsdem__inv_or_zero(fsdem_real x) { return fsdem__finite(x) ? 1 / x : 0; }

static void fsdem__pair_setup(fsdem__pair *p, const fsdem_material *a, const fsdem_material *b, fsdem_contact_law law,
                              const fsdem__pair *known, int known_count) {
    fsdem_real ea = a->young_modulus, eb = b->young_modulus, na = a->poisson_ratio, nb = b->poisson_ratio;
    fsdem_real e = (a->restitution + b->restitution) / 2;
    fsdem_real inv_e = (1 - na * na) * fsdem__inv_or_zero(ea) + (1 - nb * nb) * fsdem__inv_or_zero(eb);
    fsdem_real inv_g = 2 * (2 - na) * (1 + na) * fsdem__inv_or_zero(ea) + 2 * (2 - nb) * (1 + nb) * fsdem__inv_or_zero(eb);
    fsdem_real inv_ep = fsdem__inv_or_zero(ea) + fsdem__inv_or_zero(eb);
    int k;
    p->e_star = inv_e > 0 ? 1 / inv_e : (fsdem_real)HUGE_VAL;
    p->g_star = inv_g > 0 ? 1 / inv_g : (fsdem_real)HUGE_VAL;
    p->e_pair = inv_ep > 0 ? 2 / inv_ep : (fsdem_real)HUGE_VAL;
    p->nu = (na + nb) / 2;
    p->alpha = (a->damping_alpha + b->damping_alpha) / 2;
    p->friction = (a->friction + b->friction) / 2;
    p->rolling = (a->rolling_friction + b->rolling_friction) / 2;
    p->restitution = e;
    p->tsuji = 0;
    if (law != FSDEM_CONTACT_HERTZ_MINDLIN) return;
    /* The calibration costs a few milliseconds; reuse it for a restitution seen before. */
    for (k = 0; k < known_count; ++k)
        if (known[k].restitution == e) {
            p->tsuji = known[k].tsuji;
            return;
        }
    p->tsuji = fsdem__tsuji_coefficient(e);
}

/* One contact as the laws see it. */
typedef struct fsdem__contact {
    fsdem_vec3 n;        /* unit normal from the partner to particle i */
    fsdem_real delta;    /* m, overlap > 0 */
    fsdem_vec3 vrel;     /* m/s, velocity of i's contact point relative to the partner's */
    fsdem_real m_eff;    /* kg, reduced mass (m_i for a wall) */
    fsdem_real m_mean;   /* kg, m_ij = (m_i + m_j)/2 of seed 000 Eq. 10 (m_i for a wall) */
    fsdem_real r_eff;    /* m, R* = r_i r_j/(r_i + r_j) (r_i for a wall) */
    const fsdem__pair *pair;
} fsdem__contact;

/* Rotates a stored tangential displacement into the current tangent plane, keeping its length. */
static fsdem_vec3 fsdem__rotate_history(fsdem_vec3 xi, fsdem_vec3 n) {
    fsdem_real len2 = fsdem__dot(xi, xi), proj2;
    if (len2 == 0) return xi;
    xi = fsdem__madd(xi, n, -fsdem__dot(xi, n));
    proj2 = fsdem__dot(xi, xi);
    return proj2 > 0 ? fsdem__scale(xi, (fsdem_real)sqrt(len2 / proj2)) : xi;
}

/* Force on particle i (N). *fn gets the normal force magnitude; the history is updated in place
   when `commit` (the predictor of the predictor-corrector evaluates without committing). */
static fsdem_vec3 fsdem__contact_force(const fsdem_dem *d, const fsdem__contact *c, fsdem_vec3 *history,
                                       int commit, fsdem_real h, fsdem_real *fn_out) {
    const fsdem__pair *p = c->pair;
    fsdem_real vn = fsdem__dot(c->vrel, c->n), fn, ft_len, ft_max;
    fsdem_vec3 vt = fsdem__madd(c->vrel, c->n, -vn), ft;
    switch (d->desc.law) {
    case FSDEM_CONTACT_LINEAR: {
        /* seed 000 Eq. 10-13 with m_ij the mean mass, k_n = m_ij ||g|| / (theta dx) */
        fsdem_real kn = c->m_mean * d->k0_linear;
        fsdem_real cn = 2 * p->alpha * c->m_mean * (fsdem_real)sqrt(d->k0_linear);
        fsdem_real kt = kn / (2 * (1 + p->nu));
        fsdem_real ct = cn / (fsdem_real)sqrt(2 * (1 + p->nu));
        fn = kn * c->delta - cn * vn;           /* Eq. 7, no tension cut-off as printed */
        ft = fsdem__scale(vt, -(kt * h + ct));  /* Eq. 8: spring over one DEM step plus dashpot */
        (void)history;
        break;
    }
    case FSDEM_CONTACT_GIC: {
        /* seed 004 Eq. 1a-1c. k_n = E r for equal spheres; here E_pair * 2R*, the same for one
           material. The viscous tangential coefficient k_t is not given in the seed: we take the
           critical damping of the tangential spring k_n/(2(1+nu)) (seed 000 Eq. 12). */
        fsdem_real kn = p->e_pair * 2 * c->r_eff;
        fsdem_real kt = 2 * (fsdem_real)sqrt(c->m_eff * kn / (2 * (1 + p->nu)));
        fn = kn * c->delta;
        ft = fsdem__scale(vt, -kt);
        break;
    }
    default: {
        /* Hertz-Mindlin. Normal stiffness S_n = 2 E* sqrt(R* d), elastic force (2/3) S_n d =
           (4/3) E* sqrt(R*) d^1.5; tangential stiffness S_t = 8 G* sqrt(R* d) on the accumulated
           tangential displacement (seed 002 Eq. 20). Damping eta = a sqrt((2/3) m* S), which is
           Tsuji's a sqrt(m* k) d^(1/4) with a calibrated from e (fsdem__tsuji_coefficient). */
        fsdem_real srd = (fsdem_real)sqrt(c->r_eff * c->delta);
        fsdem_real sn = 2 * p->e_star * srd, st = 8 * p->g_star * srd;
        fsdem_real eta_n = p->tsuji * (fsdem_real)sqrt((fsdem_real)(2.0 / 3.0) * c->m_eff * sn);
        fsdem_real eta_t = p->tsuji * (fsdem_real)sqrt((fsdem_real)(2.0 / 3.0) * c->m_eff * st);
        fsdem_vec3 xi = fsdem__madd(fsdem__rotate_history(*history, c->n), vt, h);
        fn = (fsdem_real)(2.0 / 3.0) * sn * c->delta - eta_n * vn;
        if (fn < 0) fn = 0;
        ft = fsdem__add(fsdem__scale(xi, -st), fsdem__scale(vt, -eta_t));
        ft_max = p->friction * fn;
        ft_len = fsdem__norm(ft);
        if (ft_len > ft_max) {
            /* Sliding: cap at Coulomb and let the spring carry the capped force alone. Folding the
               damping term into the spring (-(F_t + eta_t v_t)/S_t) would store energy along the
               slip at first touch, where eta_t ~ d^(1/4) outgrows mu F_n ~ d^(3/2). */
            ft = fsdem__scale(ft, ft_max / ft_len);
            xi = st > 0 ? fsdem__scale(ft, -1 / st) : fsdem__zero3();
        }
        if (commit) *history = xi;
        *fn_out = fn;
        return fsdem__madd(ft, c->n, fn);
    }
    }
    /* Coulomb cap (seed 000 Eq. 15, seed 004 Eq. 1b) for the laws without history */
    ft_max = p->friction * (fn < 0 ? -fn : fn);
    ft_len = fsdem__norm(ft);
    if (ft_len > ft_max) ft = fsdem__scale(ft, ft_max / ft_len);
    *fn_out = fn;
    return fsdem__madd(ft, c->n, fn);
}

/* Constant-torque rolling resistance on i: -mu_r R* |F_n| along the relative spin, limited so that
   it cannot reverse the relative spin within one step. */
static fsdem_vec3 fsdem__rolling_torque(fsdem_vec3 w_rel, fsdem_real mu_r, fsdem_real r_eff, fsdem_real fn,
                                        fsdem_real inv_i_sum, fsdem_real h) {
    fsdem_real wlen = fsdem__norm(w_rel), tau = mu_r * r_eff * (fn < 0 ? -fn : fn), cap;
    if (wlen == 0 || tau == 0) return fsdem__zero3();
    cap = inv_i_sum > 0 ? wlen / (h * inv_i_sum) : tau;
    if (tau > cap) tau = cap;
    return fsdem__scale(w_rel, -tau / wlen);
}

/* ---- >>dem_object : creation, materials, particles ---- */

/* Every per-particle array with its element size, so growth and removal treat them alike. */
#define FSDEM__PARTICLE_ARRAYS 21
static void fsdem__particle_arrays(fsdem_dem *d, void **ptr[FSDEM__PARTICLE_ARRAYS],
                                   size_t size[FSDEM__PARTICLE_ARRAYS]) {
    int k = 0;
#define FSDEM__ARRAY(field)          \
    ptr[k] = (void **)&d->field;     \
    size[k++] = sizeof(*d->field)
    FSDEM__ARRAY(id); FSDEM__ARRAY(material); FSDEM__ARRAY(old_of); FSDEM__ARRAY(fixed);
    FSDEM__ARRAY(x); FSDEM__ARRAY(v); FSDEM__ARRAY(w); FSDEM__ARRAY(f); FSDEM__ARRAY(t);
    FSDEM__ARRAY(fext); FSDEM__ARRAY(text); FSDEM__ARRAY(x_ref);
    FSDEM__ARRAY(x0); FSDEM__ARRAY(v0); FSDEM__ARRAY(w0); FSDEM__ARRAY(fa); FSDEM__ARRAY(ta);
    FSDEM__ARRAY(r); FSDEM__ARRAY(m); FSDEM__ARRAY(inv_m); FSDEM__ARRAY(inv_i);
#undef FSDEM__ARRAY
    FSDEM_ASSERT(k == FSDEM__PARTICLE_ARRAYS);
}

static fsdem_result fsdem__reserve_particles(fsdem_dem *d, int need) {
    void **ptr[FSDEM__PARTICLE_ARRAYS];
    void *fresh[FSDEM__PARTICLE_ARRAYS];
    size_t size[FSDEM__PARTICLE_ARRAYS];
    int k, cap = d->capacity > 0 ? d->capacity : 64;
    if (need <= d->capacity) return FSDEM_OK;
    while (cap < need) {
        if (cap > (1 << 29)) return FSDEM_ERR_OUT_OF_MEMORY;
        cap *= 2;
    }
    fsdem__particle_arrays(d, ptr, size);
    for (k = 0; k < FSDEM__PARTICLE_ARRAYS; ++k) {
        fresh[k] = fsdem__alloc(&d->allocator, size[k] * (size_t)cap);
        if (!fresh[k]) {
            while (k-- > 0) fsdem__free(&d->allocator, fresh[k], size[k] * (size_t)cap);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
    }
    for (k = 0; k < FSDEM__PARTICLE_ARRAYS; ++k) {
        if (d->n > 0) memcpy(fresh[k], *ptr[k], size[k] * (size_t)d->n);
        fsdem__free(&d->allocator, *ptr[k], size[k] * (size_t)d->capacity);
        *ptr[k] = fresh[k];
    }
    d->capacity = cap;
    return FSDEM_OK;
}

static void fsdem__list_free(fsdem_dem *d, fsdem__list *l) {
    fsdem__free(&d->allocator, l->start, sizeof(int) * (size_t)l->start_capacity);
    fsdem__free(&d->allocator, l->entry, sizeof(fsdem__entry) * (size_t)l->capacity);
    memset(l, 0, sizeof *l);
}

fsdem_result fsdem_dem_create(const fsdem_dem_desc *desc, fsdem_dem **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_allocator al;
    fsdem_dem *d;
    fsdem_result res;
    if (out) *out = NULL;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    if (fsdem_dem_desc_check(desc, msg, sizeof msg) != FSDEM_OK) {
        if (desc && desc->log) desc->log(desc->log_user, FSDEM_LOG_ERROR, msg);
        return FSDEM_ERR_INVALID_ARG;
    }
    al = desc->allocator;
    d = (fsdem_dem *)fsdem__alloc(&al, sizeof *d);
    if (!d) return FSDEM_ERR_OUT_OF_MEMORY;
    memset(d, 0, sizeof *d);
    d->desc = *desc;
    d->allocator = al;
    d->status.log = desc->log;
    d->status.log_user = desc->log_user;
    d->dt = desc->dt;
    d->grid.allocator = al;
    d->need_rebuild = 1;
    {
        fsdem_real accel = desc->linear_accel > 0 ? desc->linear_accel : fsdem__norm(desc->gravity);
        d->k0_linear = desc->law == FSDEM_CONTACT_LINEAR ? accel / (desc->linear_theta * desc->linear_dx) : 0;
    }
    res = fsdem__reserve_particles(d, desc->capacity > 0 ? desc->capacity : 1);
    if (res != FSDEM_OK) {
        fsdem_dem_destroy(d);
        return res;
    }
    *out = d;
    return FSDEM_OK;
}

void fsdem_dem_destroy(fsdem_dem *d) {
    void **ptr[FSDEM__PARTICLE_ARRAYS];
    size_t size[FSDEM__PARTICLE_ARRAYS];
    int k;
    fsdem_allocator al;
    if (!d) return;
    al = d->allocator;
    fsdem__particle_arrays(d, ptr, size);
    for (k = 0; k < FSDEM__PARTICLE_ARRAYS; ++k) fsdem__free(&al, *ptr[k], size[k] * (size_t)d->capacity);
    fsdem__free(&al, d->materials, sizeof(fsdem_material) * (size_t)d->material_capacity);
    fsdem__free(&al, d->pairs, sizeof(fsdem__pair) * (size_t)d->pair_capacity);
    fsdem__free(&al, d->walls, sizeof(fsdem__wall) * (size_t)d->wall_capacity);
    fsdem__list_free(d, &d->pp);
    fsdem__list_free(d, &d->pp_old);
    fsdem__list_free(d, &d->pw);
    fsdem__list_free(d, &d->pw_old);
    fsdem__free(&al, d->hits, sizeof(fsdem__wall_hit) * (size_t)d->hit_capacity);
    fsdem_cellgrid_free(&d->grid);
    fsdem__free(&al, d, sizeof *d);
}

const char *fsdem_dem_last_error(const fsdem_dem *d) { return d ? d->status.message : "fsdem_dem is NULL"; }

fsdem_result fsdem_dem_add_material(fsdem_dem *d, const fsdem_material *mat, int *index) {
    char msg[FSDEM__MESSAGE_SIZE];
    int nm = d->material_count + 1, a, b;
    fsdem__pair *pairs;
    if (fsdem__material_check(mat, msg, sizeof msg) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "%s", msg);
    if (fsdem__grow(&d->allocator, (void **)&d->materials, &d->material_capacity, d->material_count, nm,
                    sizeof(fsdem_material)) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "out of memory adding a material");
    pairs = (fsdem__pair *)fsdem__alloc(&d->allocator, sizeof(fsdem__pair) * (size_t)(nm * nm));
    if (!pairs) return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "out of memory adding a material");
    d->materials[d->material_count] = *mat;
    for (a = 0; a < nm; ++a)
        for (b = 0; b < nm; ++b) {
            if (a < nm - 1 && b < nm - 1) pairs[a * nm + b] = d->pairs[a * (nm - 1) + b];
            else if (b < a) pairs[a * nm + b] = pairs[b * nm + a];
            else fsdem__pair_setup(&pairs[a * nm + b], &d->materials[a], &d->materials[b], d->desc.law, pairs,
                                   a * nm + b);
        }
    /* the loop reads earlier rows only, which are already in the new table */
    fsdem__free(&d->allocator, d->pairs, sizeof(fsdem__pair) * (size_t)d->pair_capacity);
    d->pairs = pairs;
    d->pair_capacity = nm * nm;
    d->material_count = nm;
    d->forces_valid = 0;
    if (index) *index = nm - 1;
    return fsdem__ok(&d->status);
}

static int fsdem__inside_domain(const fsdem_dem *d, fsdem_vec3 p) {
    const fsdem_vec3 lo = d->desc.domain_min, hi = d->desc.domain_max;
    if (!(p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y)) return 0;
    return d->desc.dim == 2 || (p.z >= lo.z && p.z <= hi.z);
}

/* Checks a kinematic state; writes the reason and returns the code, or FSDEM_OK. */
static fsdem_result fsdem__state_check(fsdem_dem *d, const char *what, fsdem_vec3 x, fsdem_vec3 v, fsdem_vec3 w) {
    if (!fsdem__finite3(x) || !fsdem__finite3(v) || !fsdem__finite3(w))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "%s: position, velocity and angular velocity must be finite",
                           what);
    if (!fsdem__inside_domain(d, x))
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_DOMAIN, "%s: position (%g, %g, %g) m is outside the domain", what,
                           (double)x.x, (double)x.y, (double)x.z);
    return FSDEM_OK;
}

fsdem_particle_desc fsdem_particle_desc_default(void) {
    fsdem_particle_desc p;
    memset(&p, 0, sizeof p);
    return p;
}

/* Keeps 2D state in the plane: z of positions and velocities, x and y of spins. */
static void fsdem__planar(const fsdem_dem *d, fsdem_vec3 *x, fsdem_vec3 *v, fsdem_vec3 *w) {
    if (d->desc.dim != 2) return;
    x->z = 0;
    v->z = 0;
    w->x = w->y = 0;
}

fsdem_result fsdem_dem_add_particle(fsdem_dem *d, const fsdem_particle_desc *p, int *index) {
    fsdem_result res;
    int i = d->n;
    fsdem_real volume, inertia_factor, rho;
    fsdem_vec3 x, v, w;
    if (!p) return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_add_particle: desc is NULL");
    if (!(p->radius > 0) || !fsdem__finite(p->radius))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_particle_desc.radius must be > 0 (got %g m)",
                           (double)p->radius);
    if (p->material < 0 || p->material >= d->material_count)
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_particle_desc.material %d is not a material of this simulation (%d added)",
                           p->material, d->material_count);
    res = fsdem__state_check(d, "fsdem_particle_desc", p->position, p->velocity, p->angular_velocity);
    if (res != FSDEM_OK) return res;
    if (fsdem__reserve_particles(d, d->n + 1) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "out of memory adding particle %d", d->n);
    x = p->position;
    v = p->velocity;
    w = p->angular_velocity;
    fsdem__planar(d, &x, &v, &w);
    rho = d->materials[p->material].density;
    if (d->desc.dim == 2) {
        volume = (fsdem_real)FSDEM__PI * p->radius * p->radius * d->desc.disc_length;
        inertia_factor = (fsdem_real)0.5; /* disc about its axis: m r^2 / 2 */
    } else {
        volume = (fsdem_real)(4.0 / 3.0 * FSDEM__PI) * p->radius * p->radius * p->radius;
        inertia_factor = (fsdem_real)0.4; /* solid sphere: 2 m r^2 / 5 */
    }
    d->id[i] = d->next_id++;
    d->material[i] = p->material;
    d->old_of[i] = -1;
    d->fixed[i] = (unsigned char)(p->fixed != 0);
    d->x[i] = x;
    d->v[i] = v;
    d->w[i] = w;
    d->f[i] = d->t[i] = d->fext[i] = d->text[i] = fsdem__zero3();
    d->x_ref[i] = x;
    d->r[i] = p->radius;
    d->m[i] = rho * volume;
    d->inv_m[i] = p->fixed ? 0 : 1 / d->m[i];
    d->inv_i[i] = p->fixed ? 0 : 1 / (inertia_factor * d->m[i] * p->radius * p->radius);
    d->n++;
    d->need_rebuild = 1;
    d->forces_valid = 0;
    if (index) *index = i;
    return fsdem__ok(&d->status);
}

fsdem_result fsdem_dem_remove_particle(fsdem_dem *d, int index) {
    void **ptr[FSDEM__PARTICLE_ARRAYS];
    size_t size[FSDEM__PARTICLE_ARRAYS];
    int k;
    if (index < 0 || index >= d->n)
        return fsdem__fail(&d->status, FSDEM_ERR_NOT_FOUND, "fsdem_dem_remove_particle: index %d not in [0, %d)", index,
                           d->n);
    fsdem__particle_arrays(d, ptr, size);
    for (k = 0; k < FSDEM__PARTICLE_ARRAYS; ++k) {
        char *base = (char *)*ptr[k];
        memmove(base + size[k] * (size_t)index, base + size[k] * (size_t)(index + 1),
                size[k] * (size_t)(d->n - index - 1));
    }
    d->n--;
    d->need_rebuild = 1; /* old_of moved with the rows, so the history carries over */
    d->forces_valid = 0;
    return fsdem__ok(&d->status);
}

fsdem_result fsdem_dem_set_particle_state(fsdem_dem *d, int index, fsdem_vec3 x, fsdem_vec3 v, fsdem_vec3 w) {
    fsdem_result res;
    if (index < 0 || index >= d->n)
        return fsdem__fail(&d->status, FSDEM_ERR_NOT_FOUND, "fsdem_dem_set_particle_state: index %d not in [0, %d)",
                           index, d->n);
    res = fsdem__state_check(d, "fsdem_dem_set_particle_state", x, v, w);
    if (res != FSDEM_OK) return res;
    fsdem__planar(d, &x, &v, &w);
    d->x[index] = x;
    d->v[index] = v;
    d->w[index] = w;
    d->need_rebuild = 1;
    d->forces_valid = 0;
    return fsdem__ok(&d->status);
}

fsdem_particles fsdem_dem_particles(fsdem_dem *d) {
    fsdem_particles p;
    p.count = d->n;
    p.dim = d->desc.dim;
    p.id = d->id;
    p.position = d->x;
    p.velocity = d->v;
    p.angular_velocity = d->w;
    p.force = d->f;
    p.torque = d->t;
    p.external_force = d->fext;
    p.external_torque = d->text;
    p.radius = d->r;
    p.mass = d->m;
    p.material = d->material;
    p.fixed = d->fixed;
    return p;
}

/* ---- >>dem_wall : wall geometry ---- */

static fsdem_wall_desc fsdem__wall_desc(fsdem_wall_type type, fsdem_vec3 a, fsdem_vec3 b, fsdem_vec3 c, int material) {
    fsdem_wall_desc w;
    memset(&w, 0, sizeof w);
    w.type = type;
    w.a = a;
    w.b = b;
    w.c = c;
    w.material = material;
    return w;
}

fsdem_wall_desc fsdem_wall_plane(fsdem_vec3 point, fsdem_vec3 normal, int material) {
    return fsdem__wall_desc(FSDEM_WALL_PLANE, point, normal, fsdem__zero3(), material);
}
fsdem_wall_desc fsdem_wall_box(fsdem_vec3 lo, fsdem_vec3 hi, int inside, int material) {
    return fsdem__wall_desc(inside ? FSDEM_WALL_BOX_INSIDE : FSDEM_WALL_BOX_OUTSIDE, lo, hi, fsdem__zero3(), material);
}
fsdem_wall_desc fsdem_wall_segment(fsdem_vec3 a, fsdem_vec3 b, int material) {
    return fsdem__wall_desc(FSDEM_WALL_SEGMENT, a, b, fsdem__zero3(), material);
}
fsdem_wall_desc fsdem_wall_triangle(fsdem_vec3 a, fsdem_vec3 b, fsdem_vec3 c, int material) {
    return fsdem__wall_desc(FSDEM_WALL_TRIANGLE, a, b, c, material);
}
fsdem_wall_desc fsdem_wall_sdf(fsdem_sdf_fn sdf, void *user, int material) {
    fsdem_wall_desc w = fsdem__wall_desc(FSDEM_WALL_SDF, fsdem__zero3(), fsdem__zero3(), fsdem__zero3(), material);
    w.sdf = sdf;
    w.sdf_user = user;
    return w;
}

static int fsdem__wall_faces(const fsdem__wall *w, int dim) {
    return w->d.type == FSDEM_WALL_BOX_INSIDE ? 2 * dim : 1;
}

/* Closest point to p on segment a-b. */
static fsdem_vec3 fsdem__closest_on_segment(fsdem_vec3 p, fsdem_vec3 a, fsdem_vec3 b) {
    fsdem_vec3 ab = fsdem__sub(b, a);
    fsdem_real len2 = fsdem__dot(ab, ab), s = len2 > 0 ? fsdem__dot(fsdem__sub(p, a), ab) / len2 : 0;
    s = s < 0 ? 0 : s > 1 ? 1 : s;
    return fsdem__madd(a, ab, s);
}

/* Closest point to p on triangle a-b-c: the projection when it falls inside, else the closest
   point on the nearest edge (then *on_edge is 1). */
static fsdem_vec3 fsdem__closest_on_triangle(fsdem_vec3 p, fsdem_vec3 a, fsdem_vec3 b, fsdem_vec3 c, int *on_edge) {
    fsdem_vec3 ab = fsdem__sub(b, a), ac = fsdem__sub(c, a), ap = fsdem__sub(p, a);
    fsdem_vec3 nrm = fsdem__cross(ab, ac), q, best;
    fsdem_real n2 = fsdem__dot(nrm, nrm), u, v, dist2, best2;
    fsdem_vec3 edge_point[3];
    int k;
    /* barycentric coordinates of the projection of p */
    v = fsdem__dot(fsdem__cross(ap, ac), nrm) / n2;
    u = fsdem__dot(fsdem__cross(ab, ap), nrm) / n2;
    *on_edge = !(v > 0 && u > 0 && u + v < 1);
    if (v >= 0 && u >= 0 && u + v <= 1) return fsdem__add(a, fsdem__add(fsdem__scale(ab, v), fsdem__scale(ac, u)));
    edge_point[0] = fsdem__closest_on_segment(p, a, b);
    edge_point[1] = fsdem__closest_on_segment(p, b, c);
    edge_point[2] = fsdem__closest_on_segment(p, c, a);
    best = edge_point[0];
    q = fsdem__sub(p, best);
    best2 = fsdem__dot(q, q);
    for (k = 1; k < 3; ++k) {
        q = fsdem__sub(p, edge_point[k]);
        dist2 = fsdem__dot(q, q);
        if (dist2 < best2) {
            best2 = dist2;
            best = edge_point[k];
        }
    }
    return best;
}

/* Unit vector from q to p, or `fallback` when they coincide. */
static fsdem_vec3 fsdem__direction(fsdem_vec3 p, fsdem_vec3 q, fsdem_vec3 fallback, fsdem_real *dist) {
    fsdem_vec3 dv = fsdem__sub(p, q);
    *dist = fsdem__norm(dv);
    return *dist > 0 ? fsdem__scale(dv, 1 / *dist) : fallback;
}

/* Signed distance (m) from p to face `face` of a wall, with the unit normal from the wall towards p.
   *on_feature is set when the closest point is an edge or vertex of a triangle, or an end of a
   segment: such points are shared by neighbouring elements of a mesh (see fsdem__wall_hits). */
static fsdem_real fsdem__wall_distance(const fsdem__wall *w, int face, fsdem_vec3 p, int dim, fsdem_vec3 *n,
                                      int *on_feature) {
    const fsdem_wall_desc *g = &w->d;
    fsdem_real dist;
    *on_feature = 0;
    switch (g->type) {
    case FSDEM_WALL_PLANE:
        *n = g->b;
        return fsdem__dot(fsdem__sub(p, g->a), g->b);
    case FSDEM_WALL_BOX_INSIDE: {
        int axis = face / 2;
        fsdem_real e[3] = {0, 0, 0};
        e[axis] = face % 2 == 0 ? 1 : -1;
        *n = fsdem_v3(e[0], e[1], e[2]);
        return face % 2 == 0 ? fsdem__comp(p, axis) - fsdem__comp(g->a, axis) : fsdem__comp(g->b, axis) - fsdem__comp(p, axis);
    }
    case FSDEM_WALL_BOX_OUTSIDE: {
        fsdem_real pc[3] = {p.x, p.y, p.z}, lo[3] = {g->a.x, g->a.y, g->a.z}, hi[3] = {g->b.x, g->b.y, g->b.z};
        fsdem_real q[3], e[3] = {0, 0, 0}, depth = (fsdem_real)HUGE_VAL;
        int axis, inside = 1, best_axis = 0, best_side = 0;
        for (axis = 0; axis < 3; ++axis) {
            q[axis] = pc[axis] < lo[axis] ? lo[axis] : pc[axis] > hi[axis] ? hi[axis] : pc[axis];
            if (axis < dim && q[axis] != pc[axis]) inside = 0;
        }
        if (dim == 2) q[2] = pc[2];
        if (!inside) {
            *n = fsdem__direction(p, fsdem_v3(q[0], q[1], q[2]), fsdem_v3(1, 0, 0), &dist);
            return dist;
        }
        /* centre inside the solid: push out through the nearest face */
        for (axis = 0; axis < dim; ++axis) {
            if (pc[axis] - lo[axis] < depth) { depth = pc[axis] - lo[axis]; best_axis = axis; best_side = 0; }
            if (hi[axis] - pc[axis] < depth) { depth = hi[axis] - pc[axis]; best_axis = axis; best_side = 1; }
        }
        e[best_axis] = best_side ? 1 : -1;
        *n = fsdem_v3(e[0], e[1], e[2]);
        return -depth;
    }
    case FSDEM_WALL_SEGMENT: {
        fsdem_vec3 ab = fsdem__sub(g->b, g->a), perp = fsdem_v3(-ab.y, ab.x, 0);
        fsdem_real len = fsdem__norm(perp);
        fsdem_vec3 q = fsdem__closest_on_segment(p, g->a, g->b);
        perp = len > 0 ? fsdem__scale(perp, 1 / len) : fsdem_v3(0, 1, 0);
        *on_feature = fsdem__dot(fsdem__sub(q, g->a), fsdem__sub(q, g->a)) == 0 ||
                      fsdem__dot(fsdem__sub(q, g->b), fsdem__sub(q, g->b)) == 0;
        *n = fsdem__direction(p, q, perp, &dist);
        return dist;
    }
    case FSDEM_WALL_TRIANGLE: {
        fsdem_vec3 nrm = fsdem__cross(fsdem__sub(g->b, g->a), fsdem__sub(g->c, g->a));
        fsdem_vec3 q = fsdem__closest_on_triangle(p, g->a, g->b, g->c, on_feature);
        nrm = fsdem__scale(nrm, 1 / fsdem__norm(nrm));
        *n = fsdem__direction(p, q, nrm, &dist);
        return dist;
    }
    case FSDEM_WALL_SDF:
    default: {
        fsdem_vec3 grad = fsdem_v3(0, 0, 1);
        fsdem_real len;
        dist = g->sdf(g->sdf_user, p, &grad);
        if (dim == 2) grad.z = 0;
        len = fsdem__norm(grad);
        *n = len > 0 ? fsdem__scale(grad, 1 / len) : fsdem_v3(0, 0, 1);
        return dist;
    }
    }
}

fsdem_result fsdem_dem_add_wall(fsdem_dem *d, const fsdem_wall_desc *desc, int *id) {
    fsdem_wall_desc g;
    fsdem__wall *w;
    int axis;
    if (!desc) return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_add_wall: desc is NULL");
    g = *desc;
    if (g.material < 0 || g.material >= d->material_count)
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_wall_desc.material %d is not a material of this simulation",
                           g.material);
    if (!fsdem__finite3(g.a) || !fsdem__finite3(g.b) || !fsdem__finite3(g.c) || !fsdem__finite3(g.velocity))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_wall_desc: geometry and velocity must be finite");
    if (d->desc.dim == 2) {
        g.a.z = g.b.z = g.c.z = g.velocity.z = 0;
    }
    switch (g.type) {
    case FSDEM_WALL_PLANE: {
        fsdem_real len;
        if (d->desc.dim == 2) g.b.z = 0;
        len = fsdem__norm(g.b);
        if (!(len > 0)) return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_wall_plane: the normal is zero");
        g.b = fsdem__scale(g.b, 1 / len);
        break;
    }
    case FSDEM_WALL_BOX_INSIDE:
    case FSDEM_WALL_BOX_OUTSIDE:
        for (axis = 0; axis < d->desc.dim; ++axis)
            if (!(fsdem__comp(g.b, axis) > fsdem__comp(g.a, axis)))
                return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_wall_box: hi must exceed lo on axis %d", axis);
        break;
    case FSDEM_WALL_SEGMENT:
        if (!(fsdem__norm(fsdem__sub(g.b, g.a)) > 0))
            return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_wall_segment: the end points coincide");
        break;
    case FSDEM_WALL_TRIANGLE:
        if (d->desc.dim != 3)
            return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_wall_triangle: triangles need dim = 3 (use segments in 2D)");
        if (!(fsdem__norm(fsdem__cross(fsdem__sub(g.b, g.a), fsdem__sub(g.c, g.a))) > 0))
            return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_wall_triangle: the triangle is degenerate");
        break;
    case FSDEM_WALL_SDF:
        if (!g.sdf) return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_wall_sdf: the callback is NULL");
        if (fsdem__norm(g.velocity) > 0)
            return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                               "fsdem_wall_sdf: a moving SDF wall must move inside its callback (velocity must be 0)");
        break;
    default:
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_wall_desc.type %d is not a fsdem_wall_type", (int)g.type);
    }
    if (fsdem__grow(&d->allocator, (void **)&d->walls, &d->wall_capacity, d->wall_count, d->wall_count + 1,
                    sizeof(fsdem__wall)) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "out of memory adding a wall");
    w = &d->walls[d->wall_count];
    memset(w, 0, sizeof *w);
    w->d = g;
    w->active = 1;
    if (id) *id = d->wall_count;
    d->wall_count++;
    d->need_rebuild = 1;
    d->forces_valid = 0;
    return fsdem__ok(&d->status);
}

static fsdem__wall *fsdem__wall_by_id(fsdem_dem *d, int id, const char *what) {
    if (id < 0 || id >= d->wall_count || !d->walls[id].active) {
        fsdem__fail(&d->status, FSDEM_ERR_NOT_FOUND, "%s: wall %d does not exist", what, id);
        return NULL;
    }
    return &d->walls[id];
}

fsdem_result fsdem_dem_remove_wall(fsdem_dem *d, int id) {
    fsdem__wall *w = fsdem__wall_by_id(d, id, "fsdem_dem_remove_wall");
    if (!w) return FSDEM_ERR_NOT_FOUND;
    w->active = 0;
    w->force = fsdem__zero3();
    d->need_rebuild = 1;
    d->forces_valid = 0;
    return fsdem__ok(&d->status);
}

fsdem_result fsdem_dem_set_wall_velocity(fsdem_dem *d, int id, fsdem_vec3 velocity) {
    fsdem__wall *w = fsdem__wall_by_id(d, id, "fsdem_dem_set_wall_velocity");
    if (!w) return FSDEM_ERR_NOT_FOUND;
    if (!fsdem__finite3(velocity))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_set_wall_velocity: velocity must be finite");
    if (w->d.type == FSDEM_WALL_SDF && fsdem__norm(velocity) > 0)
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_set_wall_velocity: an SDF wall moves in its callback");
    if (d->desc.dim == 2) velocity.z = 0;
    w->d.velocity = velocity;
    return fsdem__ok(&d->status);
}

fsdem_vec3 fsdem_dem_wall_force(const fsdem_dem *d, int id) {
    return id >= 0 && id < d->wall_count ? d->walls[id].force : fsdem__zero3();
}

fsdem_vec3 fsdem_dem_wall_impulse(const fsdem_dem *d, int id) {
    return id >= 0 && id < d->wall_count ? d->walls[id].impulse : fsdem__zero3();
}

/* ---- >>dem_neighbours : neighbour lists with contact history ---- */

static fsdem_result fsdem__list_append(fsdem_dem *d, fsdem__list *l, int other, fsdem_vec3 history) {
    if (l->count == l->capacity && fsdem__grow(&d->allocator, (void **)&l->entry, &l->capacity, l->count, l->count + 1,
                                               sizeof(fsdem__entry)) != FSDEM_OK)
        return FSDEM_ERR_OUT_OF_MEMORY;
    l->entry[l->count].other = other;
    l->entry[l->count].history = history;
    l->count++;
    return FSDEM_OK;
}

/* History stored under (row, key) in a previous list, or zero. */
static fsdem_vec3 fsdem__old_history(const fsdem__list *old, int row, int key) {
    int k;
    if (row >= 0 && row < old->rows)
        for (k = old->start[row]; k < old->start[row + 1]; ++k)
            if (old->entry[k].other == key) return old->entry[k].history;
    return fsdem__zero3();
}

static void fsdem__swap_lists(fsdem__list *a, fsdem__list *b) {
    fsdem__list t = *a;
    *a = *b;
    *b = t;
}

/* Rebuilds both lists: pairs within r_i + r_j + offset + skin, and particle-wall faces within
   r_i + offset + skin, carrying each surviving contact's history over from the previous lists. */
static fsdem_result fsdem__rebuild(fsdem_dem *d) {
    const fsdem_real off = d->desc.contact_offset;
    fsdem_real r_max = 0, skin;
    int i, k, dim = d->desc.dim, max_cells;
    fsdem_result res = FSDEM_OK;
    for (i = 0; i < d->n; ++i)
        if (d->r[i] > r_max) r_max = d->r[i];
    skin = d->desc.skin >= 0 ? d->desc.skin : (fsdem_real)0.25 * r_max;
    d->skin = skin;
    d->r_max = r_max;
    max_cells = 8 * d->n > 65536 ? 8 * d->n : 65536;
    if (fsdem_cellgrid_setup(&d->grid, NULL, dim, d->desc.domain_min, d->desc.domain_max,
                             r_max > 0 ? 2 * r_max + off + skin : 1, max_cells) != FSDEM_OK ||
        fsdem_cellgrid_build(&d->grid, d->x, d->n) != FSDEM_OK)
        return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__swap_lists(&d->pp, &d->pp_old);
    fsdem__swap_lists(&d->pw, &d->pw_old);
    if (fsdem__grow(&d->allocator, (void **)&d->pp.start, &d->pp.start_capacity, 0, d->n + 1, sizeof(int)) != FSDEM_OK ||
        fsdem__grow(&d->allocator, (void **)&d->pw.start, &d->pw.start_capacity, 0, d->n + 1, sizeof(int)) != FSDEM_OK)
        res = FSDEM_ERR_OUT_OF_MEMORY;
    d->pp.count = d->pw.count = 0;
    for (i = 0; i < d->n && res == FSDEM_OK; ++i) {
        int coord[3], cells[27], nc, c, oi = d->old_of[i];
        fsdem_vec3 xi = d->x[i];
        fsdem_real ri = d->r[i];
        d->pp.start[i] = d->pp.count;
        fsdem_cellgrid_cell(&d->grid, xi, coord);
        nc = fsdem_cellgrid_neighbourhood(&d->grid, coord, cells);
        for (c = 0; c < nc && res == FSDEM_OK; ++c) {
            for (k = d->grid.cell_start[cells[c]]; k < d->grid.cell_start[cells[c] + 1]; ++k) {
                int j = d->grid.items[k], oj, lo, hi;
                fsdem_vec3 dx;
                fsdem_real reach;
                if (j <= i) continue;
                dx = fsdem__sub(xi, d->x[j]);
                reach = ri + d->r[j] + off + skin;
                if (fsdem__dot(dx, dx) >= reach * reach) continue;
                oj = d->old_of[j];
                lo = oi < oj ? oi : oj;
                hi = oi < oj ? oj : oi;
                res = fsdem__list_append(d, &d->pp, j, lo >= 0 ? fsdem__old_history(&d->pp_old, lo, hi) : fsdem__zero3());
                if (res != FSDEM_OK) break;
            }
        }
        d->pw.start[i] = d->pw.count;
        for (k = 0; k < d->wall_count && res == FSDEM_OK; ++k) {
            const fsdem__wall *w = &d->walls[k];
            int face, faces = fsdem__wall_faces(w, dim);
            if (!w->active) continue;
            for (face = 0; face < faces; ++face) {
                fsdem_vec3 nrm;
                int key = FSDEM__WALL_KEY(k, face), on_feature;
                if (fsdem__wall_distance(w, face, xi, dim, &nrm, &on_feature) >= ri + off + skin) continue;
                res = fsdem__list_append(d, &d->pw, key, fsdem__old_history(&d->pw_old, oi, key));
                if (res != FSDEM_OK) break;
            }
        }
    }
    if (res != FSDEM_OK) {
        fsdem__swap_lists(&d->pp, &d->pp_old);
        fsdem__swap_lists(&d->pw, &d->pw_old);
        return res;
    }
    d->pp.start[d->n] = d->pp.count;
    d->pw.start[d->n] = d->pw.count;
    d->pp.rows = d->pw.rows = d->n;
    for (i = 0, k = 0; i < d->n; ++i)
        if (d->pw.start[i + 1] - d->pw.start[i] > k) k = d->pw.start[i + 1] - d->pw.start[i];
    if (fsdem__grow(&d->allocator, (void **)&d->hits, &d->hit_capacity, 0, k, sizeof(fsdem__wall_hit)) != FSDEM_OK)
        return FSDEM_ERR_OUT_OF_MEMORY;
    for (i = 0; i < d->n; ++i) {
        d->x_ref[i] = d->x[i];
        d->old_of[i] = i;
    }
    for (k = 0; k < d->wall_count; ++k) d->walls[k].moved = 0;
    d->max_disp2 = 0;
    d->need_rebuild = 0;
    d->rebuilds++;
    return FSDEM_OK;
}

static int fsdem__lists_stale(const fsdem_dem *d) {
    fsdem_real disp = (fsdem_real)sqrt(d->max_disp2), wall_moved = 0;
    int k;
    for (k = 0; k < d->wall_count; ++k)
        if (d->walls[k].moved > wall_moved) wall_moved = d->walls[k].moved;
    return d->need_rebuild || 2 * disp > d->skin || disp + wall_moved > d->skin;
}

/* Wall contacts (overlap > 0) of particle i into d->hits; returns their number. A mesh of
   triangles or a polyline shares edges and vertices between elements, and a particle touching a
   shared edge would be pushed once per element. So an edge/vertex contact is dropped when its
   contact point lies in the plane of a face contact of the same particle (the edge belongs to that
   face), or when an edge/vertex contact kept before has the same normal (one edge seen from two
   elements). With `reset`, entries without a kept contact lose their tangential history. */
static int fsdem__wall_hits(fsdem_dem *d, int i, int reset) {
    const fsdem_real off = d->desc.contact_offset, tol = (fsdem_real)1e-9 * d->r[i];
    const fsdem_vec3 xi = d->x[i];
    int k, a, b, count = 0, kept = 0;
    for (k = d->pw.start[i]; k < d->pw.start[i + 1]; ++k) {
        const int key = d->pw.entry[k].other;
        const fsdem__wall *wall = &d->walls[FSDEM__WALL_OF(key)];
        fsdem__wall_hit *h = &d->hits[count];
        if (wall->active) {
            h->delta = d->r[i] + off - fsdem__wall_distance(wall, FSDEM__FACE_OF(key), xi, d->desc.dim, &h->n, &h->on_feature);
            if (h->delta > 0) {
                h->entry = k;
                count++;
                continue;
            }
        }
        if (reset) d->pw.entry[k].history = fsdem__zero3();
    }
    for (a = 0; a < count; ++a) {
        fsdem__wall_hit h = d->hits[a];
        int duplicate = 0;
        if (h.on_feature) {
            /* contact point q = x - (r + off - delta) n; in face b's plane when (q - x).n_b = -(r + off - delta_b) */
            fsdem_vec3 q_rel = fsdem__scale(h.n, -(d->r[i] + off - h.delta));
            for (b = 0; b < count && !duplicate; ++b) {
                const fsdem__wall_hit *o = &d->hits[b];
                if (b == a) continue;
                if (!o->on_feature)
                    duplicate = fsdem__dot(q_rel, o->n) + (d->r[i] + off - o->delta) <= tol &&
                                fsdem__dot(q_rel, o->n) + (d->r[i] + off - o->delta) >= -tol;
                else if (b < a)
                    duplicate = fsdem__dot(h.n, o->n) >= 1 - (fsdem_real)1e-12;
            }
        }
        if (duplicate) {
            if (reset) d->pw.entry[h.entry].history = fsdem__zero3();
            continue;
        }
        d->hits[kept++] = h;
    }
    return kept;
}

/* ---- >>dem_forces : contact force evaluation ---- */

/* Contact forces and torques of all particle pairs and particle-wall contacts into f, t and the
   walls' force; `h` is the step the history and the one-step spring of seed 000 Eq. 8 use. */
static void fsdem__compute_forces(fsdem_dem *d, fsdem_real h, int commit) {
    const fsdem_real off = d->desc.contact_offset;
    const int nm = d->material_count;
    fsdem_vec3 *f = d->f, *t = d->t;
    const fsdem_vec3 *x = d->x, *v = d->v, *w = d->w;
    const fsdem_real *r = d->r, *m = d->m, *inv_m = d->inv_m, *inv_i = d->inv_i;
    int i, k, nh, contacts = 0, wall_contacts = 0;
    fsdem_real max_overlap = 0;
    for (i = 0; i < d->n; ++i) f[i] = t[i] = fsdem__zero3();
    for (k = 0; k < d->wall_count; ++k) d->walls[k].force = fsdem__zero3();
    for (i = 0; i < d->n; ++i) {
        const fsdem_vec3 xi = x[i], vi = v[i], wi = w[i];
        const fsdem_real ri = r[i];
        const fsdem__pair *row = d->pairs + d->material[i] * nm;
        fsdem_vec3 fi = fsdem__zero3(), ti = fsdem__zero3();
        for (k = d->pp.start[i]; k < d->pp.start[i + 1]; ++k) {
            const int j = d->pp.entry[k].other;
            const fsdem_vec3 dx = fsdem__sub(xi, x[j]);
            const fsdem_real reach = ri + r[j] + off, d2 = fsdem__dot(dx, dx);
            fsdem__contact c;
            fsdem_real dist, la_i, la_j, fn;
            fsdem_vec3 force, nxf;
            if (d2 >= reach * reach || inv_m[i] + inv_m[j] == 0) {
                if (commit) d->pp.entry[k].history = fsdem__zero3(); /* separated: the spring is reset */
                continue;
            }
            dist = (fsdem_real)sqrt(d2);
            c.n = dist > 0 ? fsdem__scale(dx, 1 / dist) : fsdem_v3(1, 0, 0);
            c.delta = reach - dist;
            la_i = ri - c.delta / 2;
            la_j = r[j] - c.delta / 2;
            c.vrel = fsdem__sub(fsdem__sub(vi, v[j]),
                                fsdem__add(fsdem__scale(fsdem__cross(wi, c.n), la_i), fsdem__scale(fsdem__cross(w[j], c.n), la_j)));
            c.m_eff = 1 / (inv_m[i] + inv_m[j]);
            c.m_mean = (m[i] + m[j]) / 2;
            c.r_eff = ri * r[j] / (ri + r[j]);
            c.pair = row + d->material[j];
            force = fsdem__contact_force(d, &c, &d->pp.entry[k].history, commit, h, &fn);
            fi = fsdem__add(fi, force);
            f[j] = fsdem__sub(f[j], force);
            nxf = fsdem__cross(c.n, force); /* arms are along -n (i) and +n (j): torque = arm x F */
            ti = fsdem__madd(ti, nxf, -la_i);
            t[j] = fsdem__madd(t[j], nxf, -la_j);
            if (c.pair->rolling > 0) {
                fsdem_vec3 tr = fsdem__rolling_torque(fsdem__sub(wi, w[j]), c.pair->rolling, c.r_eff, fn,
                                                      inv_i[i] + inv_i[j], h);
                ti = fsdem__add(ti, tr);
                t[j] = fsdem__sub(t[j], tr);
            }
            contacts++;
            if (c.delta > max_overlap) max_overlap = c.delta;
        }
        nh = d->pw.start[i + 1] > d->pw.start[i] && inv_m[i] > 0 ? fsdem__wall_hits(d, i, commit) : 0;
        for (k = 0; k < nh; ++k) {
            const fsdem__wall_hit *hit = &d->hits[k];
            fsdem__wall *wall = &d->walls[FSDEM__WALL_OF(d->pw.entry[hit->entry].other)];
            fsdem__contact c;
            fsdem_real la, fn;
            fsdem_vec3 force;
            c.n = hit->n;
            c.delta = hit->delta;
            la = ri - c.delta / 2;
            c.vrel = fsdem__sub(fsdem__sub(vi, fsdem__scale(fsdem__cross(wi, c.n), la)), wall->d.velocity);
            c.m_eff = c.m_mean = m[i];
            c.r_eff = ri;
            c.pair = row + wall->d.material;
            force = fsdem__contact_force(d, &c, &d->pw.entry[hit->entry].history, commit, h, &fn);
            fi = fsdem__add(fi, force);
            wall->force = fsdem__sub(wall->force, force);
            ti = fsdem__madd(ti, fsdem__cross(c.n, force), -la);
            if (c.pair->rolling > 0)
                ti = fsdem__add(ti, fsdem__rolling_torque(wi, c.pair->rolling, c.r_eff, fn, inv_i[i], h));
            wall_contacts++;
            if (c.delta > max_overlap) max_overlap = c.delta;
        }
        f[i] = fsdem__add(f[i], fi);
        t[i] = fsdem__add(t[i], ti);
    }
    d->contacts = contacts;
    d->wall_contacts = wall_contacts;
    d->max_overlap = max_overlap;
    d->forces_valid = 1;
}

/* ---- >>dem_integrate : time integration ---- */

static fsdem_vec3 fsdem__accel(const fsdem_dem *d, const fsdem_vec3 *f, int i) {
    return fsdem__madd(d->desc.gravity, fsdem__add(f[i], d->fext[i]), d->inv_m[i]);
}

static fsdem_vec3 fsdem__spin_rate(const fsdem_dem *d, const fsdem_vec3 *t, int i) {
    return d->desc.rotation ? fsdem__scale(fsdem__add(t[i], d->text[i]), d->inv_i[i]) : fsdem__zero3();
}

/* Velocity update v += h a, w += h alpha of the free particles, and the walls' impulse. */
static void fsdem__kick(fsdem_dem *d, fsdem_real h) {
    int i, k;
    for (i = 0; i < d->n; ++i) {
        if (d->fixed[i]) continue;
        d->v[i] = fsdem__madd(d->v[i], fsdem__accel(d, d->f, i), h);
        d->w[i] = fsdem__madd(d->w[i], fsdem__spin_rate(d, d->t, i), h);
        fsdem__planar(d, &d->x[i], &d->v[i], &d->w[i]);
    }
    for (k = 0; k < d->wall_count; ++k) d->walls[k].impulse = fsdem__madd(d->walls[k].impulse, d->walls[k].force, -h);
}

static void fsdem__track_displacement(fsdem_dem *d, int i) {
    fsdem_vec3 dd = fsdem__sub(d->x[i], d->x_ref[i]);
    fsdem_real d2 = fsdem__dot(dd, dd);
    if (d2 > d->max_disp2) d->max_disp2 = d2;
}

static void fsdem__move_walls(fsdem_dem *d, fsdem_real h) {
    int k;
    for (k = 0; k < d->wall_count; ++k) {
        fsdem__wall *w = &d->walls[k];
        fsdem_vec3 dv = fsdem__scale(w->d.velocity, h);
        if (w->d.type == FSDEM_WALL_PLANE) w->d.a = fsdem__add(w->d.a, dv); /* b is the normal */
        else {
            w->d.a = fsdem__add(w->d.a, dv);
            w->d.b = fsdem__add(w->d.b, dv);
            w->d.c = fsdem__add(w->d.c, dv);
        }
        w->moved += fsdem__norm(dv);
    }
}

static fsdem_result fsdem__ensure_lists(fsdem_dem *d) {
    if (fsdem__lists_stale(d) && fsdem__rebuild(d) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "out of memory growing the neighbour lists (%d particles)",
                           d->n);
    return FSDEM_OK;
}

/* Names the first particle that is not finite or left the domain. */
static fsdem_result fsdem__check_particles(fsdem_dem *d) {
    int i;
    for (i = 0; i < d->n; ++i) {
        if (!fsdem__finite3(d->x[i]) || !fsdem__finite3(d->v[i]) || !fsdem__finite3(d->w[i]))
            return fsdem__fail(&d->status, FSDEM_ERR_NAN, "particle %d (id %d) has a non-finite state at t = %g s", i,
                               d->id[i], (double)d->time);
        if (!fsdem__inside_domain(d, d->x[i]))
            return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_DOMAIN,
                               "particle %d (id %d) left the domain at t = %g s: position (%g, %g, %g) m", i, d->id[i],
                               (double)d->time, (double)d->x[i].x, (double)d->x[i].y, (double)d->x[i].z);
    }
    return FSDEM_OK;
}

/* Velocity Verlet: kick h/2, drift h, forces, kick h/2. */
static fsdem_result fsdem__step_verlet(fsdem_dem *d, fsdem_real h) {
    int i;
    if (fsdem__ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    if (!d->forces_valid) fsdem__compute_forces(d, h, 0);
    fsdem__kick(d, h / 2);
    for (i = 0; i < d->n; ++i) {
        d->x[i] = fsdem__madd(d->x[i], d->v[i], h);
        fsdem__track_displacement(d, i);
    }
    fsdem__move_walls(d, h);
    if (fsdem__ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__compute_forces(d, h, 1);
    fsdem__kick(d, h / 2);
    return FSDEM_OK;
}

/* Predictor-corrector of seed 000 Eq. 21-24 (forces include gravity and the fixed external ones).
   Eq. 22 and 24 as printed average U^n (the outer step's start) with the new velocity; we average
   the substep's own start velocity U_(k-1), which is the trapezoidal rule the scheme is built on
   and keeps positions consistent with velocities when K > 1. */
static fsdem_result fsdem__step_predictor_corrector(fsdem_dem *d, fsdem_real h) {
    int i, k;
    if (fsdem__ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__compute_forces(d, h, 0); /* F_a at X_(k-1), U_(k-1); history not committed */
    for (k = 0; k < d->wall_count; ++k) d->walls[k].force_a = d->walls[k].force;
    for (i = 0; i < d->n; ++i) {
        d->x0[i] = d->x[i];
        d->v0[i] = d->v[i];
        d->w0[i] = d->w[i];
        d->fa[i] = d->f[i];
        d->ta[i] = d->t[i];
        if (!d->fixed[i]) {
            d->v[i] = fsdem__madd(d->v0[i], fsdem__accel(d, d->fa, i), h);            /* Eq. 21 */
            d->w[i] = fsdem__madd(d->w0[i], fsdem__spin_rate(d, d->ta, i), h);
            fsdem__planar(d, &d->x[i], &d->v[i], &d->w[i]);
        }
        d->x[i] = fsdem__madd(d->x0[i], fsdem__add(d->v0[i], d->v[i]), h / 2);       /* Eq. 22 */
        fsdem__track_displacement(d, i);
    }
    fsdem__move_walls(d, h);
    if (fsdem__ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__compute_forces(d, h, 1); /* F_b at X_a, U_a */
    for (i = 0; i < d->n; ++i) {
        if (!d->fixed[i]) {
            fsdem_vec3 acc = fsdem__add(fsdem__accel(d, d->fa, i), fsdem__accel(d, d->f, i));
            fsdem_vec3 spin = fsdem__add(fsdem__spin_rate(d, d->ta, i), fsdem__spin_rate(d, d->t, i));
            d->v[i] = fsdem__madd(d->v0[i], acc, h / 2);                               /* Eq. 23 */
            d->w[i] = fsdem__madd(d->w0[i], spin, h / 2);
            fsdem__planar(d, &d->x[i], &d->v[i], &d->w[i]);
        }
        d->x[i] = fsdem__madd(d->x0[i], fsdem__add(d->v0[i], d->v[i]), h / 2);       /* Eq. 24 */
        fsdem__track_displacement(d, i);
    }
    for (k = 0; k < d->wall_count; ++k)
        d->walls[k].impulse = fsdem__madd(d->walls[k].impulse, fsdem__add(d->walls[k].force_a, d->walls[k].force), -h / 2);
    d->forces_valid = 0; /* the last forces belong to the predicted state, not the final one */
    return FSDEM_OK;
}

static fsdem_result fsdem__step(fsdem_dem *d, fsdem_real h) {
    fsdem_result res = d->desc.integrator == FSDEM_INTEGRATOR_PREDICTOR_CORRECTOR ? fsdem__step_predictor_corrector(d, h)
                                                                                  : fsdem__step_verlet(d, h);
    if (res != FSDEM_OK) return res;
    d->time += h;
    d->steps++;
    return fsdem__check_particles(d);
}

fsdem_result fsdem_dem_step(fsdem_dem *d) {
    fsdem_result res = fsdem__step(d, d->dt);
    return res == FSDEM_OK ? fsdem__ok(&d->status) : res;
}

fsdem_result fsdem_dem_advance(fsdem_dem *d, fsdem_real dt_outer, int *substeps) {
    int k, count;
    fsdem_result res;
    if (!(dt_outer > 0) || !fsdem__finite(dt_outer))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_advance: dt_outer must be > 0 (got %g s)",
                           (double)dt_outer);
    /* seed 000: K = INT(dt/dt_DEM), dt_DEM = dt/K; Eq. 25: dt_DEM = dt when dt_DEM > dt */
    /* the relative 1e-9 keeps an exact multiple (3e-4/1e-4 = 2.9999999999999996) from losing a step */
    count = d->dt >= dt_outer ? 1 : (int)(dt_outer / d->dt * (1 + 1e-9));
    if (count < 1) count = 1;
    if (substeps) *substeps = count;
    for (k = 0; k < count; ++k) {
        res = fsdem__step(d, dt_outer / count);
        if (res != FSDEM_OK) return res;
    }
    return fsdem__ok(&d->status);
}

fsdem_result fsdem_dem_set_dt(fsdem_dem *d, fsdem_real dt) {
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_set_dt: dt must be > 0 (got %g s)", (double)dt);
    d->dt = dt;
    return fsdem__ok(&d->status);
}

fsdem_real fsdem_dem_dt(const fsdem_dem *d) { return d->dt; }
fsdem_real fsdem_dem_time(const fsdem_dem *d) { return d->time; }

/* ---- >>dem_diagnostics : time-step estimates, energy, statistics ---- */

fsdem_result fsdem_dem_dt_estimate(const fsdem_dem *d, fsdem_dt_rule rule, fsdem_real param, fsdem_real *dt) {
    fsdem__status *st = (fsdem__status *)&d->status; /* the message is the object's only mutable part here */
    fsdem_real best = (fsdem_real)HUGE_VAL;
    int i;
    if (!dt) return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "fsdem_dem_dt_estimate: dt is NULL");
    if (d->n == 0) return fsdem__fail(st, FSDEM_ERR_NOT_FOUND, "fsdem_dem_dt_estimate: there are no particles");
    switch (rule) {
    case FSDEM_DT_LINEAR_SEED000:
        if (!(param > 0)) return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "FSDEM_DT_LINEAR_SEED000: gamma must be > 0");
        if (d->desc.law != FSDEM_CONTACT_LINEAR)
            return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "FSDEM_DT_LINEAR_SEED000 needs the linear contact law");
        /* Eq. 18 with Eq. 10: m_ij / k = theta dx / ||g|| whatever the masses */
        best = (fsdem_real)(2 * FSDEM__PI) / param / (fsdem_real)sqrt(d->k0_linear);
        break;
    case FSDEM_DT_RAYLEIGH:
        if (!(param > 0 && param <= 1))
            return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "FSDEM_DT_RAYLEIGH: the safety fraction must be in (0, 1]");
        /* seed 002 Eq. 38 prints 0.01631; the Rayleigh-wave fit it cites (Thornton & Randall 1988)
           is 0.1631 nu + 0.8766, which we use. */
        for (i = 0; i < d->n; ++i) {
            const fsdem_material *m = &d->materials[d->material[i]];
            fsdem_real t = (fsdem_real)FSDEM__PI * d->r[i] *
                           (fsdem_real)sqrt(2 * m->density * (1 + m->poisson_ratio) / m->young_modulus) /
                           ((fsdem_real)0.1631 * m->poisson_ratio + (fsdem_real)0.8766);
            if (t < best) best = t;
        }
        best *= param;
        break;
    case FSDEM_DT_GIC:
        for (i = 0; i < d->n; ++i) {
            fsdem_real kn = d->materials[d->material[i]].young_modulus * d->r[i]; /* Eq. 32: k_n = E r */
            fsdem_real t = (fsdem_real)0.5 * (fsdem_real)sqrt(d->m[i] / kn);
            if (t < best) best = t;
        }
        break;
    default:
        return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "fsdem_dem_dt_estimate: %d is not a fsdem_dt_rule", (int)rule);
    }
    *dt = best;
    return fsdem__ok(st);
}

/* Elastic energy (J) stored in one contact's normal and tangential springs. */
static fsdem_real fsdem__contact_energy(const fsdem_dem *d, const fsdem__contact *c, fsdem_vec3 history) {
    const fsdem__pair *p = c->pair;
    switch (d->desc.law) {
    case FSDEM_CONTACT_LINEAR: return (fsdem_real)0.5 * c->m_mean * d->k0_linear * c->delta * c->delta;
    case FSDEM_CONTACT_GIC: return (fsdem_real)0.5 * p->e_pair * 2 * c->r_eff * c->delta * c->delta;
    default: {
        fsdem_real srd = (fsdem_real)sqrt(c->r_eff * c->delta);
        /* integral of (4/3) E* sqrt(R*) d^1.5 = (8/15) E* sqrt(R*) d^2.5, plus the Mindlin spring */
        return (fsdem_real)(8.0 / 15.0) * p->e_star * srd * c->delta * c->delta +
               (fsdem_real)0.5 * 8 * p->g_star * srd * fsdem__dot(history, history);
    }
    }
}

fsdem_energy fsdem_dem_energy(const fsdem_dem *d) {
    fsdem_energy e;
    const int nm = d->material_count;
    int i, k, nh;
    memset(&e, 0, sizeof e);
    for (i = 0; i < d->n; ++i) {
        fsdem_real iner = d->inv_i[i] > 0 ? 1 / d->inv_i[i] : 0;
        if (d->fixed[i]) continue;
        e.kinetic += (fsdem_real)0.5 * d->m[i] * fsdem__dot(d->v[i], d->v[i]);
        e.rotational += (fsdem_real)0.5 * iner * fsdem__dot(d->w[i], d->w[i]);
        e.potential -= d->m[i] * fsdem__dot(d->desc.gravity, d->x[i]);
    }
    if (d->need_rebuild) return e; /* lists are stale after edits; springs are counted after a step */
    for (i = 0; i < d->n; ++i) {
        const fsdem__pair *row = d->pairs + d->material[i] * nm;
        fsdem__contact c;
        for (k = d->pp.start[i]; k < d->pp.start[i + 1]; ++k) {
            int j = d->pp.entry[k].other;
            fsdem_real dist = fsdem__norm(fsdem__sub(d->x[i], d->x[j]));
            c.delta = d->r[i] + d->r[j] + d->desc.contact_offset - dist;
            if (c.delta <= 0) continue;
            c.m_mean = (d->m[i] + d->m[j]) / 2;
            c.r_eff = d->r[i] * d->r[j] / (d->r[i] + d->r[j]);
            c.pair = row + d->material[j];
            e.elastic += fsdem__contact_energy(d, &c, d->pp.entry[k].history);
        }
        nh = fsdem__wall_hits((fsdem_dem *)d, i, 0);
        for (k = 0; k < nh; ++k) {
            const fsdem__wall_hit *hit = &d->hits[k];
            c.delta = hit->delta;
            c.m_mean = d->m[i];
            c.r_eff = d->r[i];
            c.pair = row + d->walls[FSDEM__WALL_OF(d->pw.entry[hit->entry].other)].d.material;
            e.elastic += fsdem__contact_energy(d, &c, d->pw.entry[hit->entry].history);
        }
    }
    return e;
}

static size_t fsdem__particle_bytes(fsdem_dem *d) {
    void **ptr[FSDEM__PARTICLE_ARRAYS];
    size_t size[FSDEM__PARTICLE_ARRAYS], total = 0;
    int k;
    fsdem__particle_arrays(d, ptr, size);
    for (k = 0; k < FSDEM__PARTICLE_ARRAYS; ++k) total += size[k] * (size_t)d->capacity;
    return total;
}

fsdem_dem_stats fsdem_dem_get_stats(const fsdem_dem *d) {
    fsdem_dem_stats s;
    memset(&s, 0, sizeof s);
    s.steps = d->steps;
    s.rebuilds = d->rebuilds;
    s.contacts = d->contacts;
    s.wall_contacts = d->wall_contacts;
    s.neighbour_pairs = d->pp.count;
    s.max_overlap = d->max_overlap;
    s.memory_bytes = sizeof *d + fsdem__particle_bytes((fsdem_dem *)d) +
                     (size_t)(d->pp.capacity + d->pp_old.capacity + d->pw.capacity + d->pw_old.capacity) *
                         sizeof(fsdem__entry) +
                     (size_t)(d->pp.start_capacity + d->pp_old.start_capacity + d->pw.start_capacity +
                              d->pw_old.start_capacity) * sizeof(int) +
                     (size_t)(d->grid.cell_capacity + 2 * d->grid.item_capacity) * sizeof(int) +
                     (size_t)d->pair_capacity * sizeof(fsdem__pair) + (size_t)d->wall_capacity * sizeof(fsdem__wall) +
                     (size_t)d->material_capacity * sizeof(fsdem_material);
    return s;
}

/* Writes contact `count` to out when there is room. */
static void fsdem__report_contact(fsdem_contact_info *out, int capacity, int count, int i, int j, fsdem_vec3 n,
                                  fsdem_real overlap) {
    if (!out || count >= capacity) return;
    out[count].i = i;
    out[count].j = j;
    out[count].normal = n;
    out[count].overlap = overlap;
}

int fsdem_dem_contacts(fsdem_dem *d, fsdem_contact_info *out, int capacity) {
    const fsdem_real off = d->desc.contact_offset;
    int i, k, nh, count = 0;
    if (fsdem__ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    for (i = 0; i < d->n; ++i) {
        for (k = d->pp.start[i]; k < d->pp.start[i + 1]; ++k) {
            int j = d->pp.entry[k].other;
            fsdem_real dist;
            fsdem_vec3 n = fsdem__direction(d->x[i], d->x[j], fsdem_v3(1, 0, 0), &dist);
            if (d->r[i] + d->r[j] + off - dist <= 0) continue;
            fsdem__report_contact(out, capacity, count++, i, j, n, d->r[i] + d->r[j] + off - dist);
        }
        nh = fsdem__wall_hits(d, i, 0);
        for (k = 0; k < nh; ++k)
            fsdem__report_contact(out, capacity, count++, i, -1 - FSDEM__WALL_OF(d->pw.entry[d->hits[k].entry].other),
                                  d->hits[k].n, d->hits[k].delta);
    }
    return count;
}

/* ===== >>impl_io : CSV and VTK output ============================================================== */

fsdem_result fsdem_csv_open(fsdem_csv *csv, const char *path, const char *header) {
    FILE *fp;
    const char *c;
    if (!csv || !path || !header || !header[0]) return FSDEM_ERR_INVALID_ARG;
    csv->file = NULL;
    csv->columns = 1;
    for (c = header; *c; ++c)
        if (*c == ',') csv->columns++;
    fp = fopen(path, "w");
    if (!fp) return FSDEM_ERR_IO;
    csv->file = fp;
    if (fprintf(fp, "%s\n", header) < 0) {
        fclose(fp);
        csv->file = NULL;
        return FSDEM_ERR_IO;
    }
    return FSDEM_OK;
}

fsdem_result fsdem_csv_row(fsdem_csv *csv, const fsdem_real *values, int count) {
    int k;
    if (!csv || !csv->file || !values || count != csv->columns) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < count; ++k)
        if (fprintf((FILE *)csv->file, k ? ",%.10g" : "%.10g", (double)values[k]) < 0) return FSDEM_ERR_IO;
    return fputc('\n', (FILE *)csv->file) == EOF ? FSDEM_ERR_IO : FSDEM_OK;
}

fsdem_result fsdem_csv_close(fsdem_csv *csv) {
    int bad;
    if (!csv || !csv->file) return FSDEM_ERR_INVALID_ARG;
    bad = fclose((FILE *)csv->file) != 0;
    csv->file = NULL;
    return bad ? FSDEM_ERR_IO : FSDEM_OK;
}

fsdem_result fsdem_dem_write_csv(const fsdem_dem *d, const char *path) {
    FILE *fp = path ? fopen(path, "w") : NULL;
    int i, bad;
    if (!fp) return FSDEM_ERR_IO;
    fprintf(fp, "id,x,y,z,vx,vy,vz,wx,wy,wz,radius,material\n");
    for (i = 0; i < d->n; ++i)
        fprintf(fp, "%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%d\n", d->id[i], (double)d->x[i].x,
                (double)d->x[i].y, (double)d->x[i].z, (double)d->v[i].x, (double)d->v[i].y, (double)d->v[i].z,
                (double)d->w[i].x, (double)d->w[i].y, (double)d->w[i].z, (double)d->r[i], d->material[i]);
    bad = ferror(fp);
    return (fclose(fp) != 0 || bad) ? FSDEM_ERR_IO : FSDEM_OK;
}

static void fsdem__vtk_vectors(FILE *fp, const char *name, const fsdem_vec3 *v, int n) {
    int i;
    fprintf(fp, "VECTORS %s double\n", name);
    for (i = 0; i < n; ++i) fprintf(fp, "%.10g %.10g %.10g\n", (double)v[i].x, (double)v[i].y, (double)v[i].z);
}

fsdem_result fsdem_dem_write_vtk(const fsdem_dem *d, const char *path) {
    FILE *fp = path ? fopen(path, "w") : NULL;
    int i, bad;
    if (!fp) return FSDEM_ERR_IO;
    fprintf(fp, "# vtk DataFile Version 3.0\nfsdem particles t=%.10g s\nASCII\nDATASET POLYDATA\n", (double)d->time);
    fprintf(fp, "POINTS %d double\n", d->n);
    for (i = 0; i < d->n; ++i) fprintf(fp, "%.10g %.10g %.10g\n", (double)d->x[i].x, (double)d->x[i].y, (double)d->x[i].z);
    fprintf(fp, "VERTICES %d %d\n", d->n, 2 * d->n);
    for (i = 0; i < d->n; ++i) fprintf(fp, "1 %d\n", i);
    fprintf(fp, "POINT_DATA %d\nSCALARS radius double 1\nLOOKUP_TABLE default\n", d->n);
    for (i = 0; i < d->n; ++i) fprintf(fp, "%.10g\n", (double)d->r[i]);
    fprintf(fp, "SCALARS id int 1\nLOOKUP_TABLE default\n");
    for (i = 0; i < d->n; ++i) fprintf(fp, "%d\n", d->id[i]);
    fsdem__vtk_vectors(fp, "velocity", d->v, d->n);
    fsdem__vtk_vectors(fp, "angular_velocity", d->w, d->n);
    bad = ferror(fp);
    return (fclose(fp) != 0 || bad) ? FSDEM_ERR_IO : FSDEM_OK;
}

#endif /* FSDEM_IMPLEMENTATION_DONE */
#endif /* FSDEM_IMPLEMENTATION */

/* ===== >>licence : MIT ================================================================================

   Copyright (c) 2026 the fsdem.h authors

   Permission is hereby granted, free of charge, to any person obtaining a copy of this software and
   associated documentation files (the "Software"), to deal in the Software without restriction,
   including without limitation the rights to use, copy, modify, merge, publish, distribute,
   sublicense, and/or sell copies of the Software, and to permit persons to whom the Software is
   furnished to do so, subject to the following conditions:

   The above copyright notice and this permission notice shall be included in all copies or
   substantial portions of the Software.

   THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR IMPLIED, INCLUDING BUT
   NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY, FITNESS FOR A PARTICULAR PURPOSE AND
   NONINFRINGEMENT. IN NO EVENT SHALL THE AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM,
   DAMAGES OR OTHER LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM, OUT
   OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE SOFTWARE.
*/
