/* ===== >>core : real type, vectors, results, allocator, logging =================================== */

#ifdef FSDEM_USE_FLOAT
typedef float fsdem_real;
#else
typedef double fsdem_real;
#endif

typedef struct fsdem_vec3 {
    fsdem_real x, y, z;
} fsdem_vec3;

/* Sides of a box domain, in the order of the axes (index into a desc's boundary arrays). */
typedef enum fsdem_side {
    FSDEM_SIDE_XMIN = 0,
    FSDEM_SIDE_XMAX = 1,
    FSDEM_SIDE_YMIN = 2,
    FSDEM_SIDE_YMAX = 3,
    FSDEM_SIDE_ZMIN = 4,
    FSDEM_SIDE_ZMAX = 5
} fsdem_side;

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

/* Plausibility bounds: a value beyond them describes no flow these solvers can resolve and would
   only come back steps later as an overflow or a NaN, so the call that gives it refuses it with
   FSDEM_ERR_INVALID_ARG and a message naming it (as it refuses a NaN). */
#define FSDEM_MAX_SPEED ((fsdem_real)1e4)        /* m/s: every velocity given (particles, fills, walls,
                                                    boundaries); ten times a rifle bullet's */
#define FSDEM_MAX_ACCELERATION ((fsdem_real)1e4) /* m/s^2: |gravity| (about 1000 g; geotechnical
                                                    centrifuges reach a few hundred g) */
#define FSDEM_MAX_LENGTH ((fsdem_real)1e7)       /* m: depths, water levels, radii and lengths (the
                                                    size of the Earth) */
#define FSDEM_MAX_MODULUS ((fsdem_real)1e16)     /* Pa: Young's moduli (diamond: 1.2e12 Pa; room for a
                                                    wall idealised as a thousand times stiffer) */

/* Short constant name of a result code, e.g. "FSDEM_ERR_INVALID_ARG". Never NULL. */
FSDEM_API const char *fsdem_result_string(fsdem_result result);

typedef enum fsdem_log_level {
    FSDEM_LOG_LEVEL_ERROR = 0,
    FSDEM_LOG_LEVEL_WARNING = 1,
    FSDEM_LOG_LEVEL_INFO = 2
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

/* Threads. Built with OpenMP (-fopenmp), the solvers run their loops on the calling thread's OpenMP
   team, and every result is the same bit for bit at any thread count and as in a build without
   OpenMP (>>doc THREADS). The count is OpenMP's own (OMP_NUM_THREADS, omp_set_num_threads):
   fsdem_set_threads(n) sets it for the calling thread, fsdem_threads() reads it. n from 1 to four
   per processor (omp_get_num_procs(), at least 4): FSDEM_ERR_INVALID_ARG otherwise, the count
   unchanged (more threads than that cannot run at once and only wait at the solvers' barriers;
   OMP_NUM_THREADS is OpenMP's and not checked). Without OpenMP no thread is created,
   fsdem_set_threads does nothing (n >= 1 is still required) and fsdem_threads() is 1. */
FSDEM_API fsdem_result fsdem_set_threads(int count);
FSDEM_API int fsdem_threads(void);

/* Who writes a solver's coupling arrays. A coupler claims the arrays it writes when it is created
   and releases them when it is destroyed, so that two writers never share one array: a second claim
   is refused, naming the first claimant, and writers of different arrays share the solver (>>couple).
   A solver's arrays are the bits of its enum fsdem_<solver>_arrays; fsdem_<solver>_claims gives its
   registry, which lives as long as the solver. */
typedef struct fsdem_claims fsdem_claims;
/* Claims the arrays of the bits `arrays` for `owner` (any non-NULL pointer; `name` names it in
   messages and is copied, up to 47 characters). FSDEM_OK, also for arrays the owner holds already;
   FSDEM_ERR_INVALID_ARG, with nothing claimed, for a NULL argument, a bit the solver does not have,
   or an array another owner holds: the reason, naming the array and its claimant, goes to `message`
   (may be NULL). */
FSDEM_API fsdem_result fsdem_claim(fsdem_claims *claims, unsigned arrays, const void *owner, const char *name, char *message,
                                   size_t message_size);
/* Releases the arrays of `arrays` that `owner` holds (the others stay as they are). */
FSDEM_API void fsdem_release(fsdem_claims *claims, unsigned arrays, const void *owner);
/* The name of the claimant of the first held array of `arrays`, or NULL when none is held. */
FSDEM_API const char *fsdem_claimant(const fsdem_claims *claims, unsigned arrays);

/* Vector helpers (inline in every translation unit). */
static inline fsdem_vec3 fsdem_v3(fsdem_real x, fsdem_real y, fsdem_real z) {
    fsdem_vec3 v;
    v.x = x;
    v.y = y;
    v.z = z;
    return v;
}

/* Signed distance (m) from p to a solid, positive on the open (particle or liquid) side; writes the
   unit normal pointing to the open side (the distance gradient) to *normal. Used by DEM walls, PIC
   obstacles and fill regions. */
typedef fsdem_real (*fsdem_sdf_fn)(void *user, fsdem_vec3 p, fsdem_vec3 *normal);

/* What a fluid solver reports at a point for a coupler (fsdem_<fluid>_sample). */
typedef struct fsdem_fluid_sample {
    fsdem_vec3 velocity;          /* m/s, fluid velocity (0 where there is no liquid) */
    fsdem_vec3 pressure_gradient; /* Pa/m, gradient of the (total) pressure */
    fsdem_real volume_fraction;   /* -, liquid fraction: 1 inside the liquid, 0 in air or dry land */
} fsdem_fluid_sample;
