/* ---- >>linalg_object : creation, memory ---- */

fsdem_pcg_desc fsdem_pcg_desc_default(void) {
    fsdem_pcg_desc d;
    memset(&d, 0, sizeof d);
    d.preconditioner = FSDEM_PRECOND_AUTO;
    d.tolerance = (fsdem_real)FSDEM__DEFAULT_TOL;
    d.max_iterations = 1000;
    d.mic_tau = (fsdem_real)0.97;
    d.ic_safety = (fsdem_real)0.25;
    d.mg_sweeps = 2;
    d.amg_strength = (fsdem_real)0.25;
    return d;
}

fsdem_result fsdem_pcg_desc_check(const fsdem_pcg_desc *d, char *msg, size_t size) {
    if (!d) return fsdem__reject(msg, size, "fsdem_pcg_desc is NULL");
    if ((int)d->preconditioner < (int)FSDEM_PRECOND_AUTO || (int)d->preconditioner > (int)FSDEM_PRECOND_AMG)
        return fsdem__reject(msg, size, "fsdem_pcg_desc.preconditioner is not a fsdem_precond (%d)",
                             (int)d->preconditioner);
    if (!(d->tolerance > 0) || !fsdem__finite(d->tolerance))
        return fsdem__reject(msg, size, "fsdem_pcg_desc.tolerance must be > 0 (got %g)", (double)d->tolerance);
    if (d->max_iterations < 1)
        return fsdem__reject(msg, size, "fsdem_pcg_desc.max_iterations must be >= 1 (got %d)", d->max_iterations);
    if (!(d->mic_tau >= 0 && d->mic_tau <= 1))
        return fsdem__reject(msg, size, "fsdem_pcg_desc.mic_tau must be in [0, 1] (got %g)", (double)d->mic_tau);
    if (!(d->ic_safety >= 0 && d->ic_safety < 1))
        return fsdem__reject(msg, size, "fsdem_pcg_desc.ic_safety must be in [0, 1) (got %g)", (double)d->ic_safety);
    if (d->mg_sweeps < 1 || d->mg_sweeps > 64)
        return fsdem__reject(msg, size, "fsdem_pcg_desc.mg_sweeps must be in [1, 64] (got %d)", d->mg_sweeps);
    if (!(d->amg_strength > 0 && d->amg_strength < 1))
        return fsdem__reject(msg, size, "fsdem_pcg_desc.amg_strength must be in (0, 1) (got %g)", (double)d->amg_strength);
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        return fsdem__reject(msg, size, "fsdem_pcg_desc.allocator: set both alloc and free, or neither");
    return FSDEM_OK;
}

fsdem_result fsdem_pcg_create(const fsdem_pcg_desc *desc, fsdem_pcg **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_pcg *s;
    fsdem_result res;
    if (out) *out = NULL;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    res = fsdem_pcg_desc_check(desc, msg, sizeof msg);
    s = (fsdem_pcg *)fsdem__object_new(res, msg, desc ? desc->log : NULL, desc ? desc->log_user : NULL,
                                       desc ? &desc->allocator : NULL, sizeof *s, "fsdem_pcg_create", &res);
    if (!s) return res;
    s->desc = *desc;
    s->allocator = desc->allocator;
    s->status.log = desc->log;
    s->status.log_user = desc->log_user;
    *out = s;
    return FSDEM_OK;
}

void fsdem_pcg_destroy(fsdem_pcg *s) {
    fsdem_allocator al;
    if (!s) return;
    al = s->allocator;
    fsdem__amg_free(&al, s->amg);
    fsdem__free(&al, s->arena, s->arena_bytes);
    fsdem__free(&al, s, sizeof *s);
}

const char *fsdem_pcg_last_error(const fsdem_pcg *s) { return s ? s->status.message : "fsdem_pcg is NULL"; }

fsdem_result fsdem_pcg_set_tolerance(fsdem_pcg *s, fsdem_real tolerance, int max_iterations) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!(tolerance > 0) || !fsdem__finite(tolerance))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pcg_set_tolerance: tolerance must be > 0 (got %g)",
                           (double)tolerance);
    if (max_iterations < 1)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pcg_set_tolerance: max_iterations must be >= 1 (got %d)", max_iterations);
    s->desc.tolerance = tolerance;
    s->desc.max_iterations = max_iterations;
    return fsdem__ok(&s->status);
}

/* Dot products are summed in blocks of this many entries, the blocks' sums then added in order
   (>>doc THREADS): a vector of one block is summed exactly as before threads came. */
#ifndef FSDEM__DOT_BLOCK /* (see FSDEM__DEM_CHUNK) */
#define FSDEM__DOT_BLOCK 16384
#endif
static size_t fsdem__dot_blocks(int n) { return ((size_t)n + FSDEM__DOT_BLOCK - 1) / FSDEM__DOT_BLOCK; }

/* Reals of one worker's multigrid row buffer: two rows of the finest level with their ends. */
static size_t fsdem__mg_rowbuf_length(const fsdem_pcg *s) { return 2 * ((size_t)s->level[0].n[0] + 8); }

/* Reals of the threaded restriction's scratch: every row of the finest level restricted along x (the
   finest level has the most rows and the widest coarse rows). */
static size_t fsdem__mg_restricted_length(const fsdem__level *F, const fsdem__level *C) {
    return (size_t)F->n[1] * (size_t)F->n[2] * (size_t)C->n[0];
}

/* Carves arrays out of one block: a first pass with base = NULL measures, a second assigns. */
typedef struct fsdem__pcg_carver {
    char *base;
    size_t used;
    int overflow;
} fsdem__pcg_carver;

static void *fsdem__pcg_carve(fsdem__pcg_carver *cv, size_t count, size_t elem) {
    size_t off = (cv->used + 63) & ~(size_t)63;
    if (elem && count > ((size_t)-1 - off) / elem / 2) {
        cv->overflow = 1;
        return NULL;
    }
    cv->used = off + count * elem;
    return cv->base ? (void *)(cv->base + off) : NULL;
}

/* Replaces the arena by one of at least `bytes` (contents are not kept). On failure the old arena
   and everything in it stay as they were. */
static fsdem_result fsdem__pcg_reserve(fsdem_pcg *s, size_t bytes) {
    void *fresh;
    if (bytes <= s->arena_bytes && s->arena) return FSDEM_OK;
    fresh = fsdem__alloc(&s->allocator, bytes);
    if (!fresh) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__free(&s->allocator, s->arena, s->arena_bytes);
    s->arena = fresh;
    s->arena_bytes = bytes;
    return FSDEM_OK;
}
