/* ---- >>linalg_mg : multigrid V-cycle ---- */

/* The V-cycle works slab by slab (a slab is a row in 2D, a plane in 3D) as a wavefront: in one
   pass over memory, stage s of a pipeline handles slab t - s at step t. Each Gauss-Seidel
   half-sweep is a stage, so are the fused residual-restriction and the prolongation. A stage
   only reads slabs that the stage before it has finished and the stage after it has not yet
   touched, so the result is exactly that of the half-sweeps one after another, at a fraction of
   the memory traffic. */
enum { FSDEM__STAGE_SMOOTH, FSDEM__STAGE_SMOOTH_FROM_ZERO, FSDEM__STAGE_RESTRICT, FSDEM__STAGE_PROLONG };

typedef struct fsdem__mg_stage {
    int kind, colour;
} fsdem__mg_stage;

/* One stage over the rows of slabs [p0, p1) on the calling thread, with row buffer `buf` (the
   restriction's second pass excepted: fsdem__mg_gather). */
/* threaded: inside a team: rows of the calling thread's slab. */
static void fsdem__mg_stage_rows(const fsdem__level *L, const fsdem__level *C, int dim, const fsdem_real *b, fsdem_real *x,
                                 fsdem_real *xc_or_bc, const fsdem__mg_stage *stage, int p0, int p1, fsdem_real *buf) {
    int p, j;
    for (p = p0; p < p1; ++p) {
        const int jb = dim == 3 ? 0 : p, je = dim == 3 ? L->n[1] : p + 1, k = dim == 3 ? p : 0;
        for (j = jb; j < je; ++j) switch (stage->kind) {
            case FSDEM__STAGE_SMOOTH: fsdem__mg_smooth_row(L, dim, b, x, stage->colour, j, k, 0); break;
            case FSDEM__STAGE_SMOOTH_FROM_ZERO: fsdem__mg_smooth_row(L, dim, b, x, stage->colour, j, k, 1); break;
            default: fsdem__mg_prolong_row(L, C, dim, xc_or_bc, x, j, k, buf); break;
            }
    }
}

static void fsdem__mg_pipeline(const fsdem__level *L, const fsdem__level *C, int dim, const fsdem_real *b,
                               fsdem_real *x, fsdem_real *xc_or_bc, const fsdem__mg_stage *stage, int stages,
                               fsdem_real *buf) {
    int slabs = dim == 3 ? L->n[2] : L->n[1], t, s, j;
    for (t = 0; t < slabs + stages - 1; ++t)
        for (s = 0; s < stages; ++s) {
            int p = t - s, jb = dim == 3 ? 0 : p, je = dim == 3 ? L->n[1] : p + 1, k = dim == 3 ? p : 0;
            if (p < 0 || p >= slabs) continue;
            if (stage[s].kind != FSDEM__STAGE_RESTRICT) fsdem__mg_stage_rows(L, C, dim, b, x, xc_or_bc, stage + s, p, p + 1, buf);
            else
                for (j = jb; j < je; ++j) fsdem__mg_restrict_row(L, C, dim, b, x, xc_or_bc, j, k, buf);
        }
}

/* The restriction's second pass for coarse slab P: the fine rows' x-restricted residuals
   (`restricted`, row j + k n1) added to the coarse rows of P, fine row after fine row as the
   pipeline adds them, so every coarse entry sums the same terms in the same order. */
/* threaded: inside a team: one coarse slab. */
static void fsdem__mg_gather(const fsdem__level *F, const fsdem__level *C, int dim, const fsdem_real *restricted,
                             fsdem_real *bc, int P) {
    const int axis = dim == 3 ? 2 : 1, slabs = F->n[axis], nI = C->n[0];
    const int p0 = C->ratio[axis] == 2 ? 2 * P - 1 : P, p1 = C->ratio[axis] == 2 ? 2 * P + 2 : P;
    int p, j, q;
    for (p = p0 < 0 ? 0 : p0; p <= p1 && p < slabs; ++p) {
        const int jb = dim == 3 ? 0 : p, je = dim == 3 ? F->n[1] : p + 1, k = dim == 3 ? p : 0;
        for (j = jb; j < je; ++j) {
            const fsdem__mg_targets t = fsdem__mg_targets_of(C, dim, j, k);
            int mask = 0;
            for (q = 0; q < 4; ++q) mask |= (t.slab[q] == P) << q;
            fsdem__mg_restrict_add(bc, &t, restricted + ((size_t)k * F->n[1] + j) * (size_t)nI, nI, mask);
        }
    }
}

/* threaded: inside a team. Progress of the threaded pipeline: the number of stages finished on a
   slab, published by the thread that owns the slab and awaited by its neighbours' owners, through
   sequentially consistent OpenMP atomics (OpenMP 4.0; each implies the flush that makes the slab's
   values visible before its count). */
#ifdef FSDEM__THREADS
static int fsdem__mg_progress(const int *done, int p) {
    int stages;
    FSDEM__OMP(atomic read seq_cst)
    stages = done[p];
    return stages;
}
static void fsdem__mg_publish(int *done, int p, int stages) {
    FSDEM__OMP(atomic write seq_cst)
    done[p] = stages + 0; /* (+ 0: gcc 12 takes a bare parameter under an atomic write for unused) */
}
#endif

/* The pipeline of one thread over its slabs [p0, p1), downwards or upwards: stage s on slab p waits
   until stage s - 1 is finished on both neighbours (p - 1, p + 1), which may belong to other threads.
   Then every stage reads what it would read in one thread's pipeline (a colour's half-sweep reads
   the other colour only; stage s + 1 of a neighbour waits for stage s here), so the result is the
   same bit for bit. Neighbouring threads sweep towards each other's ends or away from them together,
   so they meet in step. The restriction writes each fine row's x-restricted residual
   (`restricted`); fsdem__mg_gather adds them to the coarse level after the pipeline. */
/* threaded: inside a team: the calling thread's pipeline, waiting on its neighbours' progress. */
static void fsdem__mg_thread_pipeline(const fsdem_pcg *s, const fsdem__level *L, const fsdem__level *C,
                                      const fsdem_real *b, fsdem_real *x, fsdem_real *xc, const fsdem__mg_stage *stage,
                                      int stages, int p0, int p1, int down, int *done, fsdem_real *buf) {
#ifdef FSDEM__THREADS
    const int dim = s->dim, slabs = dim == 3 ? L->n[2] : L->n[1], len = p1 - p0, nI = C ? C->n[0] : 0;
    int t, q, j;
    for (t = 0; t < len + stages - 1; ++t)
        for (q = 0; q < stages; ++q) {
            const int local = t - q, p = down ? p1 - 1 - local : p0 + local;
            if (local < 0 || local >= len) continue;
            while ((p > 0 && fsdem__mg_progress(done, p - 1) < q) || (p + 1 < slabs && fsdem__mg_progress(done, p + 1) < q))
                FSDEM__SPIN_PAUSE();
            if (stage[q].kind != FSDEM__STAGE_RESTRICT) fsdem__mg_stage_rows(L, C, dim, b, x, xc, stage + q, p, p + 1, buf);
            else {
                const int jb = dim == 3 ? 0 : p, je = dim == 3 ? L->n[1] : p + 1, k = dim == 3 ? p : 0;
                for (j = jb; j < je; ++j)
                    fsdem__mg_restrict_x(L, C, dim, b, x, j, k, buf + 2, s->restricted + ((size_t)k * L->n[1] + j) * (size_t)nI);
            }
            fsdem__mg_publish(done, p, q + 1);
        }
#else
    (void)s, (void)L, (void)C, (void)b, (void)x, (void)xc, (void)stage, (void)stages, (void)p0, (void)p1, (void)down;
    (void)done, (void)buf;
#endif
}

/* Runs the stages on level L: on one thread, the pipeline; with threads (and a level large enough
   to pay for them), one pipeline per thread over its share of the slabs (fsdem__mg_thread_pipeline),
   then the restriction's gather over the coarse slabs. The same result bit for bit. */
/* threaded: opens a team of pipelines over the slabs, then one over the coarse slabs. */
static void fsdem__mg_run(const fsdem_pcg *s, const fsdem__level *L, const fsdem__level *C, const fsdem_real *b,
                          fsdem_real *x, fsdem_real *xc_or_bc, const fsdem__mg_stage *stage, int stages) {
    const int dim = s->dim, slabs = dim == 3 ? L->n[2] : L->n[1];
    const int team = fsdem__team_for(L->count, FSDEM__DOT_BLOCK, s->workers < slabs ? s->workers : slabs);
    const size_t rowbuf = fsdem__mg_rowbuf_length(s);
    int p, P;
    if (team <= 1 || !s->restricted) {
        fsdem__mg_pipeline(L, C, dim, b, x, xc_or_bc, stage, stages, s->rowbuf);
        return;
    }
    for (p = 0; p < slabs; ++p) s->progress[p] = 0;
    FSDEM__OMP(parallel num_threads(team))
    {
        const int w = fsdem__worker();
        int p0, p1;
        fsdem__share(slabs, &p0, &p1);
        fsdem__mg_thread_pipeline(s, L, C, b, x, xc_or_bc, stage, stages, p0, p1, !(w & 1), s->progress,
                                  s->rowbuf + (size_t)w * rowbuf);
    }
    if (C && stage[stages - 1].kind == FSDEM__STAGE_RESTRICT) {
        const int cslabs = dim == 3 ? C->n[2] : C->n[1];
        FSDEM__OMP(parallel for schedule(static) num_threads(team))
        for (P = 0; P < cslabs; ++P) fsdem__mg_gather(L, C, dim, s->restricted, xc_or_bc, P);
    }
}

/* Pre-smoothing from x = 0 (red first), then (when C is given) bc = P^T (b - A x). */
static void fsdem__mg_down(const fsdem_pcg *s, const fsdem__level *L, const fsdem__level *C, const fsdem_real *b,
                           fsdem_real *x, fsdem_real *bc, int sweeps) {
    fsdem__mg_stage stage[2 * 64 + 2];
    int n = 0, h;
    for (h = 0; h < 2 * sweeps; ++h) {
        stage[n].kind = h == 0 ? FSDEM__STAGE_SMOOTH_FROM_ZERO : FSDEM__STAGE_SMOOTH;
        stage[n++].colour = h & 1;
    }
    if (C) {
        stage[n].kind = FSDEM__STAGE_RESTRICT;
        stage[n++].colour = 0;
        memset(bc, 0, sizeof(fsdem_real) * (size_t)C->count);
    }
    fsdem__mg_run(s, L, C, b, x, bc, stage, n);
    if (C) fsdem__mg_clean(C, bc);
}

/* (When C is given) x += P xc, then post-smoothing (black first: the adjoint of the pre-smoother). */
static void fsdem__mg_up(const fsdem_pcg *s, const fsdem__level *L, const fsdem__level *C, const fsdem_real *b,
                         fsdem_real *x, fsdem_real *xc, int sweeps) {
    fsdem__mg_stage stage[2 * 64 + 2];
    int n = 0, h;
    if (C) {
        stage[n].kind = FSDEM__STAGE_PROLONG;
        stage[n++].colour = 0;
    }
    for (h = 0; h < 2 * sweeps; ++h) {
        stage[n].kind = FSDEM__STAGE_SMOOTH;
        stage[n++].colour = (h & 1) ^ 1;
    }
    fsdem__mg_run(s, L, C, b, x, xc, stage, n);
}

/* z = M^-1 r: one V-cycle from a zero guess. */
static void fsdem__mg_vcycle(fsdem_pcg *s, const fsdem_real *r, fsdem_real *z) {
    int l, dim = s->dim, nu = s->desc.mg_sweeps, last = s->levels - 1;
    fsdem__level *lv = s->level;
    lv[0].b = (fsdem_real *)r; /* read only at level 0 */
    lv[0].x = z;
    for (l = 0; l < last; ++l) fsdem__mg_down(s, &lv[l], &lv[l + 1], lv[l].b, lv[l].x, lv[l + 1].b, nu);
    if (lv[last].n[0] * lv[last].n[1] * lv[last].n[2] == 1) {
        int c = fsdem__level_index(&lv[last], dim, 0, 0, 0);
        lv[last].x[c] = lv[last].inv_d[c] * lv[last].b[c];
    } else {
        fsdem__mg_down(s, &lv[last], NULL, lv[last].b, lv[last].x, NULL, nu);
        fsdem__mg_up(s, &lv[last], NULL, lv[last].b, lv[last].x, NULL, nu);
    }
    for (l = last - 1; l >= 0; --l) fsdem__mg_up(s, &lv[l], &lv[l + 1], lv[l].b, lv[l].x, lv[l + 1].x, nu);
    lv[0].b = lv[0].x = NULL;
}
