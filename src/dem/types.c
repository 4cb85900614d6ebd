/* ===== >>impl_dem : discrete element method ======================================================== */

/* Contents: the object and its private types; >>dem_desc (defaults, validation, the time-step
   rule), >>dem_law (contact laws: pair constants, the batched law kernel, rolling resistance),
   >>dem_periodic (minimum images and wrapping), >>dem_object (creation, materials, particles),
   >>dem_wall (wall geometry and distances), >>dem_neighbours (neighbour lists with contact history), >>dem_forces (force evaluation),
   >>dem_integrate (Verlet, predictor-corrector, advance), >>dem_diagnostics (stable dt, energy,
   statistics, contacts). */

/* Constants of one material pair, computed when a material is added. */
typedef struct fsdem__dem_pair {
    fsdem_real e_star;   /* Pa, 1/E* = (1-nu_i^2)/E_i + (1-nu_j^2)/E_j (Hertz) */
    fsdem_real g_star;   /* Pa, 1/G* = 2(2-nu_i)(1+nu_i)/E_i + 2(2-nu_j)(1+nu_j)/E_j (Mindlin) */
    fsdem_real e_pair;   /* Pa, 2/(1/E_i + 1/E_j): equals E for one material (GIC, k_n = E r) */
    fsdem_real nu;       /* -, mean Poisson ratio (psi of seed 000 Eq. 12-13) */
    fsdem_real alpha;    /* -, mean alpha of seed 000 Eq. 11 */
    fsdem_real friction; /* -, mean mu */
    fsdem_real rolling;  /* -, mean mu_r */
    fsdem_real restitution; /* -, mean e */
    fsdem_real cohesion; /* J/m^3, mean cohesion energy density */
    fsdem_real tsuji;    /* -, damping coefficient giving that restitution (>>dem_law) */
    /* The law's coefficients in the form the contact kernel evaluates (fsdem__dem_batch_law):
         law      kn                  cn                      kt                 ct
         Hertz    (4/3) E* (Pa)       tsuji^2 (4/3) E* (Pa)   8 G* (Pa)          sqrt(4 G* / E*)
         linear   ||g||/(theta dx)    2 alpha sqrt(kn)        1/(2(1+psi))       1/sqrt(2(1+psi))
                  (1/s^2)             (1/s)                   seed 000 Eq. 10-13 per unit m_ij
         seed 002 (4/3) E* (Pa)       2 zeta, zeta =          1/(2+nu)           sqrt(kt)
         linear                       -ln e/sqrt(ln^2 e + pi^2)   (Eq. 21-24, times sqrt(R*))
         GIC      2 E_pair (Pa)       0                       1/(2(1+nu))        0
       ct is 0 without tangential damping (desc.tangential_damping). */
    fsdem_real kn, cn, kt, ct;
} fsdem__dem_pair;

typedef struct fsdem__dem_wall {
    fsdem_dem_wall_desc d;
    int active;
    fsdem_vec3 force;   /* N, exerted by the particles on the wall at the last force evaluation */
    fsdem_vec3 impulse; /* N s, given by the wall to the particles since it was added */
    fsdem_vec3 force_a; /* N, force of the predictor evaluation (predictor-corrector) */
    fsdem_real moved;   /* m, distance travelled since the last neighbour-list build */
} fsdem__dem_wall;

/* Neighbour list in compressed rows: the entries of particle i are start[i] .. start[i+1]-1, and
   first[k] = i. Entry k names a partner in key[k] (particle j > i, or wall*8+face) and keeps the
   contact's tangential spring displacement in history[k], the contact history carried across steps
   and rebuilds. history[k] means something only while key[k] carries FSDEM__DEM_HELD (the contact
   touched at the last committed force evaluation); without it the spring is zero. So a separation
   costs one bit and the many entries that do not touch are passed over without reading history. */
typedef struct fsdem__dem_list {
    int *start;
    int start_capacity;
    int rows; /* particles the list was built for */
    int *first, *key;
    fsdem_vec3 *history; /* m */
    int count, capacity;
} fsdem__dem_list;

#define FSDEM__DEM_HELD (1 << 30) /* the entry's spring is live */
#define FSDEM__DEM_PARTNER(key) ((key) & ~FSDEM__DEM_HELD)
#define FSDEM__DEM_MAX_PARTICLES (FSDEM__DEM_HELD - 1) /* partners and wall keys stay below the flag */

/* One particle-wall contact of the current positions. */
typedef struct fsdem__dem_wall_hit {
    int entry;         /* index into the particle-wall list */
    fsdem_vec3 n;      /* unit normal from the wall towards the particle */
    fsdem_real delta;  /* m, overlap > 0 */
    int on_feature;    /* contact point on a triangle edge/vertex or a segment end */
} fsdem__dem_wall_hit;

#define FSDEM__DEM_WALL_KEY(wall, face) ((wall) * 8 + (face))
#define FSDEM__DEM_WALL_OF(key) (FSDEM__DEM_PARTNER(key) / 8)
#define FSDEM__DEM_FACE_OF(key) (FSDEM__DEM_PARTNER(key) % 8)

struct fsdem_dem {
    fsdem_dem_desc desc; /* dt_rule and dt_param resolved */
    fsdem__status status;
    fsdem_claims claims;             /* who writes its coupling arrays (>>core_claims) */
    fsdem_allocator allocator;
    fsdem_real dt;
    double time;
    long long steps, rebuilds;
    fsdem_real stable_dt; /* fsdem_dem_stable_dt at the last rebuild (0: no particles) */
    int dt_warned;        /* the dt warning was logged for the current dt and stable_dt */

    /* particles, structure of arrays */
    int n, capacity, next_id;
    int *id, *material, *old_of; /* old_of: row in the previous neighbour lists, -1 if new */
    unsigned char *fixed;
    fsdem_vec3 *x, *v, *w, *f, *t, *fext, *text, *x_ref;
    fsdem_vec3 *x0, *v0, *w0, *fa, *ta; /* predictor-corrector: start state and first forces */
    fsdem_real *r, *m, *inv_m, *inv_i;

    fsdem_dem_material *materials;
    int material_count, material_capacity;
    fsdem__dem_pair *pairs; /* material_count^2 */
    int pair_capacity;

    fsdem__dem_wall *walls;
    int wall_count, wall_capacity;

    fsdem__dem_list pp, pp_old, pw, pw_old;
    struct fsdem__dem_wall_hit *hits; /* scratch: one particle's wall contacts (fsdem__dem_wall_hits) */
    fsdem__arena arena;           /* per-step scratch of the force evaluation, reserved by rebuilds */
    int workers;                  /* threads the arena was reserved for (fsdem__dem_force_scratch) */
    int *found, found_capacity;   /* scratch of the rebuild: pairs within reach (fsdem__dem_find_pairs) */
    int *inert, inert_count, inert_capacity; /* pairs of fixed particles within reach (i, j), listed aside */
    int hit_capacity;
    fsdem_cellgrid grid;
    fsdem_real skin, r_max, max_disp2, k0_linear;
    int need_rebuild, forces_valid;
    int rolling;  /* some material pair has rolling resistance */
    int cohesive; /* some material pair has cohesion */
    fsdem__periods periods; /* the periodic axes (>>dem_periodic) */
    int external; /* fext/text may be nonzero (fsdem_dem_get_coupling handed them out, or a coupler wrote them) */
    int forces_cleared; /* f and t were zeroed by the last Verlet pass, for the force evaluation */
    int contacts, wall_contacts;
    fsdem_real max_overlap;
};

/* The arrays of fsdem_dem_arrays, by bit (>>core_claims). */
static const char *const fsdem__dem_claimable[1] = {"external loads"};
