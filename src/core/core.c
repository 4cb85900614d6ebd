/* ===== >>impl_core : results, allocator, messages, vector algebra ================================== */

/* Contents: results and messages, the allocator and growth, the per-step scratch arena, the status
   every object keeps, finite-value checks, the CSV series of probes and CSV snapshots of rows,
   3-vector algebra, >>core_gauges (the point gauges of the particle solvers), >>core_lane (short
   vectors for the batched kernels) and >>core_claims (who writes a solver's coupling arrays). */

#define FSDEM__PI 3.14159265358979323846
#define FSDEM__MESSAGE_SIZE 512

/* Forces inlining where the compiler allows it: a kernel written once with a constant argument (a
   contact law, a limiter) is instantiated per value, so hot loops carry no switch. */
#if defined(__GNUC__) || defined(__clang__)
#define FSDEM__FORCE_INLINE static inline __attribute__((always_inline))
#elif defined(_MSC_VER)
#define FSDEM__FORCE_INLINE static __forceinline
#else
#define FSDEM__FORCE_INLINE static inline
#endif

/* Promise that pointers do not alias, so loops over several particle arrays keep them in registers
   (C99 restrict; the compilers' own spelling in C++ and in MSVC, whose C mode lacks the keyword
   before C11). */
#if defined(_MSC_VER) || (defined(__cplusplus) && (defined(__GNUC__) || defined(__clang__)))
#define FSDEM__RESTRICT __restrict
#elif defined(__cplusplus)
#define FSDEM__RESTRICT
#else
#define FSDEM__RESTRICT restrict
#endif

/* OpenMP, when the build has it and FSDEM_NO_OPENMP is not defined (>>doc THREADS):
   FSDEM__OMP(directive) is `#pragma omp directive`, and nothing otherwise (where gcc would warn of an
   unknown pragma). fsdem__workers() is the calling thread's OpenMP thread count, fsdem__worker() the
   calling thread's number in its team and fsdem__team() the team's size. */
#if defined(_OPENMP) && !defined(FSDEM_NO_OPENMP)
#define FSDEM__THREADS 1
#include <omp.h>
#define FSDEM__PRAGMA(x) _Pragma(#x)
#define FSDEM__OMP(x) FSDEM__PRAGMA(omp x)
static int fsdem__workers(void) { return omp_get_max_threads(); }
/* threaded: inside a team: the calling thread's number and the team's size. */
static int fsdem__worker(void) { return omp_get_thread_num(); }
static int fsdem__team(void) { return omp_get_num_threads(); }
/* More threads than four per processor cannot run at once, and each of the multigrid pipeline's
   stages then waits for a time slice (issue 34: 10000 threads on two cores stalled a 128^2 PIC). */
fsdem_result fsdem_set_threads(int count) {
    const int most = omp_get_num_procs() > 1 ? 4 * omp_get_num_procs() : 4;
    if (count < 1 || count > most || count > omp_get_thread_limit()) return FSDEM_ERR_INVALID_ARG;
    omp_set_num_threads(count);
    return FSDEM_OK;
}
#else
#define FSDEM__OMP(x)
static int fsdem__workers(void) { return 1; }
static int fsdem__worker(void) { return 0; }
static int fsdem__team(void) { return 1; }
fsdem_result fsdem_set_threads(int count) { return count >= 1 ? FSDEM_OK : FSDEM_ERR_INVALID_ARG; }
#endif
int fsdem_threads(void) { return fsdem__workers(); }

/* Loops over fewer items than this stay on one thread (starting a team costs microseconds). */
#ifndef FSDEM__TEAM_ITEMS /* (see FSDEM__DEM_CHUNK) */
#define FSDEM__TEAM_ITEMS 4096
#endif

/* The team of a threaded loop, the one rule every parallel region takes its size from: the calling
   thread's OpenMP thread count, but no more threads than items / grain (a share of fewer than
   `grain` items does not pay for a thread) nor than `cap` (the threads the loop's work buffers were
   sized for; FSDEM__NO_CAP for a loop without), and at least one. Results never depend on it (>>doc
   THREADS). */
#define FSDEM__NO_CAP 0x7fffffff
static int fsdem__team_for(long long items, long long grain, int cap) {
    long long team = fsdem__workers();
    if (grain > 0 && items / grain < team) team = items / grain;
    if (cap < team) team = cap;
    return team < 1 ? 1 : (int)team;
}

/* A pause in a spin-wait: the CPU's hint that the thread only waits (x86 PAUSE, ARM YIELD), which
   frees the core's shared resources for the thread it waits for. */
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define FSDEM__SPIN_PAUSE() __builtin_ia32_pause()
#elif defined(__GNUC__) && (defined(__aarch64__) || defined(__arm__))
#define FSDEM__SPIN_PAUSE() __asm__ __volatile__("yield")
#else
#define FSDEM__SPIN_PAUSE() ((void)0)
#endif

/* threaded: inside a team. The calling thread's share [*begin, *end) of n items split evenly over
   its team, in team order. */
static void fsdem__share(int n, int *begin, int *end) {
    const int me = fsdem__worker(), size = fsdem__team();
    *begin = (int)((long long)n * me / size);
    *end = (int)((long long)n * (me + 1) / size);
}

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

/* Grows `count` arrays that share one capacity (*capacity elements, `used` live; array k has
   elements of elem[k] bytes) to at least `need` elements, by doubling: all of them or, on failure,
   none (so each array keeps the size the shared capacity says, and frees it with that size). */
static fsdem_result fsdem__grow_set(const fsdem_allocator *a, void **const *arrays, const size_t *elem, int count, int *capacity,
                                    int used, int need) {
    enum { MAX_SET = 8 };
    void *fresh[MAX_SET];
    int cap = *capacity > 0 ? *capacity : 16, k;
    FSDEM_ASSERT(count <= MAX_SET);
    if (need <= *capacity) return FSDEM_OK;
    while (cap < need) {
        if (cap > (1 << 29)) return FSDEM_ERR_OUT_OF_MEMORY;
        cap *= 2;
    }
    for (k = 0; k < count; ++k) {
        fresh[k] = (size_t)cap <= ((size_t)-1) / elem[k] ? fsdem__alloc(a, (size_t)cap * elem[k]) : NULL;
        if (!fresh[k]) {
            while (k-- > 0) fsdem__free(a, fresh[k], (size_t)cap * elem[k]);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
    }
    for (k = 0; k < count; ++k) {
        if (*arrays[k] && used > 0) memcpy(fresh[k], *arrays[k], (size_t)used * elem[k]);
        fsdem__free(a, *arrays[k], (size_t)(*capacity) * elem[k]);
        *arrays[k] = fresh[k];
    }
    *capacity = cap;
    return FSDEM_OK;
}

/* Per-step scratch arena: one block that a step carves up and gives back whole at its end. It is
   reserved, growing only when a step needs more than any step before (when the lists it serves grew),
   so a steady run allocates nothing; pushes within a reservation cannot fail. Blocks are aligned for
   the widest vector (fsdem__lane). */
typedef struct fsdem__arena {
    unsigned char *base;
    size_t size, used;
} fsdem__arena;

#define FSDEM__ARENA_ALIGN 64

/* Empties the arena and makes room for `bytes` in pushes (each rounded up to FSDEM__ARENA_ALIGN).
   FSDEM_ERR_OUT_OF_MEMORY leaves it empty and as large as before. */
static fsdem_result fsdem__arena_reserve(const fsdem_allocator *al, fsdem__arena *a, size_t bytes) {
    size_t size = a->size ? a->size : 4096;
    unsigned char *fresh;
    a->used = 0;
    if (bytes + FSDEM__ARENA_ALIGN <= a->size) return FSDEM_OK;
    while (size < bytes + FSDEM__ARENA_ALIGN) {
        if (size > ((size_t)-1) / 4) return FSDEM_ERR_OUT_OF_MEMORY;
        size *= 2;
    }
    fresh = (unsigned char *)fsdem__alloc(al, size);
    if (!fresh) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__free(al, a->base, a->size);
    a->base = fresh;
    a->size = size;
    return FSDEM_OK;
}

static void fsdem__arena_reset(fsdem__arena *a) { a->used = 0; }

/* Rounds a push up so that the next one starts aligned. */
static size_t fsdem__arena_bytes(size_t bytes) {
    return (bytes + FSDEM__ARENA_ALIGN - 1) / FSDEM__ARENA_ALIGN * FSDEM__ARENA_ALIGN;
}

/* `bytes` of the reservation, aligned to FSDEM__ARENA_ALIGN. */
static void *fsdem__arena_push(fsdem__arena *a, size_t bytes) {
    unsigned char *p = a->base + a->used;
    size_t pad = (size_t)(FSDEM__ARENA_ALIGN - ((size_t)p % FSDEM__ARENA_ALIGN)) % FSDEM__ARENA_ALIGN;
    FSDEM_ASSERT(a->used + pad + bytes <= a->size);
    a->used += pad + bytes;
    return p + pad;
}

static void fsdem__arena_free(const fsdem_allocator *al, fsdem__arena *a) {
    fsdem__free(al, a->base, a->size);
    a->base = NULL;
    a->size = a->used = 0;
}

/* Message and log sink shared by all objects. */
typedef struct fsdem__status {
    char message[FSDEM__MESSAGE_SIZE];
    fsdem_log_fn log;
    void *log_user;
} fsdem__status;

static fsdem_result fsdem__vfail(fsdem__status *s, fsdem_result code, const char *fmt, va_list ap) {
    vsnprintf(s->message, sizeof s->message, fmt, ap);
    if (s->log) s->log(s->log_user, FSDEM_LOG_LEVEL_ERROR, s->message);
    return code;
}

static fsdem_result fsdem__fail(fsdem__status *s, fsdem_result code, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    code = fsdem__vfail(s, code, fmt, ap);
    va_end(ap);
    return code;
}

/* Logs an allocation failure of `bytes` in the function `what` (at creation, where no object exists
   yet to keep the message). */
static void fsdem__log_oom(fsdem_log_fn log, void *log_user, const char *what, size_t bytes) {
    char msg[128];
    if (!log) return;
    snprintf(msg, sizeof msg, "%s: out of memory (%lu bytes)", what, (unsigned long)bytes);
    log(log_user, FSDEM_LOG_LEVEL_ERROR, msg);
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

static fsdem_result fsdem__ok(fsdem__status *s) {
    s->message[0] = '\0';
    return FSDEM_OK;
}

/* The common start of every fsdem_<object>_create: `checked` is the result of the desc check and `why`
   its reason, which goes to the desc's log on failure; otherwise a zeroed object of `size` bytes is
   allocated with `al` (a failure is logged as one of `name`, the create function). Returns it, or
   NULL with *res set. */
static void *fsdem__object_new(fsdem_result checked, const char *why, fsdem_log_fn log, void *log_user,
                               const fsdem_allocator *al, size_t size, const char *name, fsdem_result *res) {
    void *obj;
    if (checked != FSDEM_OK) {
        if (log) log(log_user, FSDEM_LOG_LEVEL_ERROR, why);
        *res = checked;
        return NULL;
    }
    obj = fsdem__alloc(al, size);
    *res = obj ? FSDEM_OK : FSDEM_ERR_OUT_OF_MEMORY;
    if (obj) memset(obj, 0, size);
    else fsdem__log_oom(log, log_user, name, size);
    return obj;
}

static int fsdem__finite(fsdem_real x) { return x == x && x - x == 0; }

/* A CSV time series of probe values written by a solver as it steps (SWE and PIC gauges): a header,
   then rows at the exact multiples of `interval`, the values interpolated linearly between the
   start and the end of the step that passed each one (interval 0: one row per step). The series
   samples its solver itself: a solver's step calls fsdem__series_begin first and fsdem__series_step
   last, and nothing else. `before` holds the values at the start of the step in flight, `now` those
   at its end. Held (fsdem__series_hold), the rows of a step wait, unwritten, until the next step
   begins or the hold ends; a coupled step holds them, so that a step it puts back (>>couple_step)
   drops them (fsdem__series_drop) and leaves the file as it was. */
typedef void (*fsdem__series_sample_fn)(const void *solver, fsdem_real *out);
typedef struct fsdem__series {
    void *file;            /* FILE*, NULL when closed */
    double interval, next; /* s */
    int columns;           /* values per row after t */
    fsdem_real *before, *now;
    fsdem__series_sample_fn sample;
    const void *solver;
    int hold;              /* the rows of a step wait */
    int pending;           /* the rows of the step from pending_t0 to pending_t1 wait (its values in */
    double pending_t0, pending_t1; /* before and now) */
} fsdem__series;

/* Writes the row of time t with the values in ser->now. */
static void fsdem__series_row(fsdem__series *ser, double t) {
    int k;
    fprintf((FILE *)ser->file, "\n%.10g", t);
    for (k = 0; k < ser->columns; ++k) fprintf((FILE *)ser->file, ",%.10g", (double)ser->now[k]);
}

/* Opens `path`, writes `header` and the row of time t sampled from `solver` by `sample`, and
   allocates the rows with `al`. FSDEM_ERR_IO, FSDEM_ERR_OUT_OF_MEMORY. */
static fsdem_result fsdem__series_open(fsdem__series *ser, const fsdem_allocator *al, const char *path, const char *header,
                                       int columns, double t, double interval, fsdem__series_sample_fn sample,
                                       const void *solver) {
    FILE *fp;
    fsdem_real *rows = (fsdem_real *)fsdem__alloc(al, sizeof(fsdem_real) * 2 * (size_t)columns);
    if (!rows) return FSDEM_ERR_OUT_OF_MEMORY;
    fp = path ? fopen(path, "w") : NULL;
    if (!fp) {
        fsdem__free(al, rows, sizeof(fsdem_real) * 2 * (size_t)columns);
        return FSDEM_ERR_IO;
    }
    ser->file = fp;
    ser->interval = interval;
    ser->next = t + interval;
    ser->columns = columns;
    ser->before = rows;
    ser->now = rows + columns;
    ser->sample = sample;
    ser->solver = solver;
    fputs(header, fp);
    sample(solver, ser->now);
    fsdem__series_row(ser, t);
    return FSDEM_OK;
}

/* Writes the rows of the step from t0 to t1 (its values in before and now). */
static fsdem_result fsdem__series_write(fsdem__series *ser, double t0, double t1) {
    FILE *fp = (FILE *)ser->file;
    int k;
    if (ser->interval <= 0) fsdem__series_row(ser, t1);
    for (; ser->interval > 0 && ser->next <= t1 * (1 + 1e-12); ser->next += ser->interval) {
        const double w = t1 > t0 ? (ser->next - t0) / (t1 - t0) : 1;
        fprintf(fp, "\n%.10g", ser->next);
        for (k = 0; k < ser->columns; ++k) fprintf(fp, ",%.10g", (1 - w) * ser->before[k] + w * ser->now[k]);
    }
    fflush(fp);
    return ferror(fp) ? FSDEM_ERR_IO : FSDEM_OK;
}

/* Writes the rows that wait, if any. */
static fsdem_result fsdem__series_release(fsdem__series *ser) {
    if (!ser->pending) return FSDEM_OK;
    ser->pending = 0;
    return fsdem__series_write(ser, ser->pending_t0, ser->pending_t1);
}

/* Holds the rows of the steps to come (hold = 1), or ends the hold and writes the rows that wait. */
static fsdem_result fsdem__series_hold(fsdem__series *ser, int hold) {
    ser->hold = hold;
    return hold ? FSDEM_OK : fsdem__series_release(ser);
}

/* fsdem_X_gauges_hold of a solver whose series is `ser` (its status st, its public name fn). */
static fsdem_result fsdem__series_hold_call(fsdem__series *ser, fsdem__status *st, const char *fn, int hold) {
    if (!ser->file) return fsdem__ok(st);
    return fsdem__series_hold(ser, hold != 0) == FSDEM_OK ? fsdem__ok(st) : fsdem__fail(st, FSDEM_ERR_IO, "%s: write error", fn);
}

/* Forgets the rows that wait (their step was put back). */
static void fsdem__series_drop(fsdem__series *ser) { ser->pending = 0; }

/* Before a step: the rows of a step held before it written, then the values at its start, from which
   the rows inside it are interpolated. */
static void fsdem__series_begin(fsdem__series *ser) {
    if (!ser->file) return;
    fsdem__series_release(ser); /* a write error stays in the file's error flag for the step to report */
    if (ser->interval > 0) ser->sample(ser->solver, ser->before);
}

/* After a step from t0 to t1: samples its end and writes the rows it passed, or holds them. */
static fsdem_result fsdem__series_step(fsdem__series *ser, double t0, double t1) {
    if (!ser->file) return FSDEM_OK;
    ser->sample(ser->solver, ser->now);
    if (!ser->hold) return fsdem__series_write(ser, t0, t1);
    ser->pending = 1;
    ser->pending_t0 = t0;
    ser->pending_t1 = t1;
    return FSDEM_OK;
}

/* Closes the file (a last newline) and frees the rows. FSDEM_ERR_IO when writing failed. */
static fsdem_result fsdem__series_close(fsdem__series *ser, const fsdem_allocator *al) {
    int bad;
    if (!ser->file) return FSDEM_OK;
    fsdem__series_release(ser);
    fputc('\n', (FILE *)ser->file);
    bad = ferror((FILE *)ser->file);
    bad |= fclose((FILE *)ser->file) != 0;
    fsdem__free(al, ser->before, sizeof(fsdem_real) * 2 * (size_t)ser->columns);
    memset(ser, 0, sizeof *ser);
    return bad ? FSDEM_ERR_IO : FSDEM_OK;
}



/* CSV snapshots of rows of numbers (the MPS particles, the couplers' records). Fills the values of
   row `index`; returns 0 when the row is left out. */
typedef int (*fsdem__row_fn)(const void *object, int index, double *values);

/* Writes `header` and the rows 0 .. rows-1 that `row` gives (as many values as the header has
   names), with 17 significant digits so that they read back exactly. */
static fsdem_result fsdem__write_rows(const fsdem__status *status, const char *who, const char *path, const char *header,
                                      int rows, fsdem__row_fn row, const void *object) {
    double values[32];
    int columns = 1, index, k, bad;
    const char *h;
    FILE *fp;
    if (!path) return fsdem__fail((fsdem__status *)status, FSDEM_ERR_INVALID_ARG, "%s: path is NULL", who);
    for (h = header; *h; ++h) columns += *h == ',';
    FSDEM_ASSERT(columns <= (int)(sizeof values / sizeof values[0]));
    if (!(fp = fopen(path, "w"))) return fsdem__fail((fsdem__status *)status, FSDEM_ERR_IO, "%s: cannot open '%s' for writing", who, path);
    fprintf(fp, "%s\n", header);
    for (index = 0; index < rows; ++index) {
        if (!row(object, index, values)) continue;
        for (k = 0; k < columns; ++k) fprintf(fp, k ? ",%.17g" : "%.17g", values[k]);
        fputc('\n', fp);
    }
    bad = ferror(fp);
    if (fclose(fp) != 0 || bad) return fsdem__fail((fsdem__status *)status, FSDEM_ERR_IO, "%s: cannot write '%s'", who, path);
    return fsdem__ok((fsdem__status *)status);
}

/* A field of a struct, by table: its name, what it holds, where and how long it is. A coupler's
   record lists its fields so (the CSV columns, >>couple_records), and a restart visitor the desc
   fields it compares and the scalars it saves (>>restart_format). */
enum { FSDEM__FIELD_INT, FSDEM__FIELD_LL, FSDEM__FIELD_REAL, FSDEM__FIELD_VEC3, FSDEM__FIELD_BYTES };
typedef struct fsdem__field {
    const char *name;
    int kind;            /* FSDEM__FIELD_*: how to read it (BYTES: only saved, as they are) */
    size_t offset, size; /* bytes */
    int saved;           /* part of the restart (a record's field may be left out) */
} fsdem__field;
#define FSDEM__FIELD(type, member, name, kind, saved) \
    { name, FSDEM__FIELD_##kind, offsetof(type, member), sizeof(((type *)0)->member), saved }

/* A relative tolerance of at least `floor` and of 100 roundings of fsdem_real, so a test written for
   double still holds in float. */
static double fsdem__tolerance(double floor) {
#ifdef FSDEM_USE_FLOAT
    const double eps = FLT_EPSILON;
#else
    const double eps = DBL_EPSILON;
#endif
    return floor > 100 * eps ? floor : 100 * eps;
}
static int fsdem__finite3(fsdem_vec3 v) {
    return fsdem__finite(v.x) && fsdem__finite(v.y) && fsdem__finite(v.z);
}
/* |v| <= bound (>>core plausibility bounds), NaN refused; each component is bounded before the
   norm, which then cannot overflow */
static int fsdem__within(fsdem_vec3 v, fsdem_real bound) {
    if (!(fabs(v.x) <= bound && fabs(v.y) <= bound && fabs(v.z) <= bound)) return 0;
    return v.x * v.x + v.y * v.y + v.z * v.z <= bound * bound;
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

/* p moved by h along axis b. */
static fsdem_vec3 fsdem__axis_shift(fsdem_vec3 p, int b, fsdem_real h) {
    if (b == 0) p.x += h;
    else if (b == 1) p.y += h;
    else p.z += h;
    return p;
}
static void fsdem__set_comp(fsdem_vec3 *v, int axis, fsdem_real value) {
    if (axis == 0) v->x = value;
    else if (axis == 1) v->y = value;
    else v->z = value;
}

/* The gravity of a desc named `desc` (e.g. "fsdem_mps_desc"): finite, in the plane in 2D (z = 0),
   and |g| <= FSDEM_MAX_ACCELERATION. */
static fsdem_result fsdem__check_gravity(const char *desc, fsdem_vec3 g, int dim, char *msg, size_t size) {
    if (!fsdem__within(g, FSDEM_MAX_ACCELERATION))
        return fsdem__reject(msg, size, "%s.gravity (%g, %g, %g) m/s^2 must be finite and at most FSDEM_MAX_ACCELERATION (%g m/s^2)",
                             desc, (double)g.x, (double)g.y, (double)g.z, (double)FSDEM_MAX_ACCELERATION);
    if (dim == 2 && g.z != 0)
        return fsdem__reject(msg, size, "%s.gravity.z = %g m/s^2 must be 0 in 2D (the motion is in the x-y plane)", desc, (double)g.z);
    return FSDEM_OK;
}

/* The longest step dt_max of a fluid desc: > 0, and short enough that gravity alone cannot take a
   particle at rest past FSDEM_MAX_SPEED in one step (|g| dt_max <= FSDEM_MAX_SPEED). */
static fsdem_result fsdem__check_dt_max(const char *desc, fsdem_real dt_max, fsdem_vec3 g, char *msg, size_t size) {
    const fsdem_real g_norm = fsdem__norm(g);
    if (!(dt_max > 0) || !fsdem__finite(dt_max) || g_norm * dt_max > FSDEM_MAX_SPEED)
        return fsdem__reject(msg, size, "%s.dt_max = %g s must be > 0 and |gravity| dt_max at most FSDEM_MAX_SPEED (%g m/s)", desc,
                             (double)dt_max, (double)FSDEM_MAX_SPEED);
    return FSDEM_OK;
}
