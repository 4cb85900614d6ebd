/* ---- >>linalg_solve : preconditioned conjugate gradients ---- */

/* y = A x on internal vectors. */
static void fsdem__pcg_apply(fsdem_pcg *s, const fsdem_real *x, fsdem_real *y) {
    if (s->kind == FSDEM__KIND_CSR) {
        fsdem_csr_apply(&s->csr, x, y);
        return;
    }
    fsdem__level_apply(&s->level[0], s->dim, x, y);
    if (s->stencil.extra) {
        const fsdem__level *L = &s->level[0];
        int i, j, k, u = 0;
        for (k = 0; k < L->n[2]; ++k)
            for (j = 0; j < L->n[1]; ++j)
                for (i = 0; i < L->n[0]; ++i, ++u) {
                    s->ux[u] = x[fsdem__level_index(L, s->dim, i, j, k)];
                    s->uy[u] = 0;
                }
        s->stencil.extra(s->stencil.extra_user, s->ux, s->uy);
        u = 0;
        for (k = 0; k < L->n[2]; ++k)
            for (j = 0; j < L->n[1]; ++j)
                for (i = 0; i < L->n[0]; ++i, ++u) {
                    int c = fsdem__level_index(L, s->dim, i, j, k);
                    if (FSDEM__TYPE(L->type[c]) == FSDEM_STENCIL_CELL_FLUID)
                        y[c] += s->uy[u];
                }
    }
}

/* z = M^-1 r. */
/* threaded: opens a team for the Jacobi product; IC(0) and MIC(0) run on one thread. */
static void fsdem__pcg_precondition(fsdem_pcg *s, const fsdem_real *r, fsdem_real *z) {
    int i, n = s->length;
    switch (s->precond) {
    case FSDEM_PRECOND_JACOBI: {
        const fsdem_real *inv = s->kind == FSDEM__KIND_CSR ? s->ic : s->level[0].inv_d;
        FSDEM__OMP(parallel for schedule(static)
                   num_threads(fsdem__team_for(n, FSDEM__DOT_BLOCK, FSDEM__NO_CAP)))
        for (i = 0; i < n; ++i) z[i] = inv[i] * r[i];
        break;
    }
    case FSDEM_PRECOND_IC0:
    case FSDEM_PRECOND_MIC0:
        if (s->kind == FSDEM__KIND_CSR) fsdem__csr_ic_apply(s, r, z);
        else fsdem__stencil_ic_apply(s, r, z);
        break;
    case FSDEM_PRECOND_MG: fsdem__mg_vcycle(s, r, z); break;
    case FSDEM_PRECOND_AMG:
        memcpy(s->amg->lv[0].b, r, sizeof(fsdem_real) * (size_t)n);
        memset(s->amg->lv[0].x, 0, sizeof(fsdem_real) * (size_t)n);
        fsdem__amg_cycle(s->amg, 0, s->desc.mg_sweeps);
        memcpy(z, s->amg->lv[0].x, sizeof(fsdem_real) * (size_t)n);
        break;
    default: memcpy(z, r, sizeof(fsdem_real) * (size_t)n); break;
    }
}

/* Removes the mean of v over each unanchored fluid region; returns the squared norm removed. */
static double fsdem__pcg_project(const fsdem_pcg *s, fsdem_real *v) {
    int e = 0, removed_start;
    double removed = 0;
    while (e < s->ns_cells) {
        double sum = 0;
        int count = 0, f;
        removed_start = e;
        do {
            int c = s->ns_cell[e];
            if (c < 0) c = -c - 1;
            sum += v[c];
            count++;
            e++;
        } while (e < s->ns_cells && s->ns_cell[e] >= 0);
        sum /= count;
        for (f = removed_start; f < e; ++f) {
            int c = s->ns_cell[f];
            if (c < 0) c = -c - 1;
            v[c] -= (fsdem_real)sum;
        }
        removed += sum * sum * count;
    }
    return removed;
}

/* Copies a caller vector into an internal one (0 off fluid cells). Returns the index of the first
   non-finite value read, or -1. */
static int fsdem__pcg_load(const fsdem_pcg *s, const fsdem_real *src, fsdem_real *dst) {
    int i, j, k, u = 0, bad = -1;
    if (s->kind == FSDEM__KIND_CSR) {
        for (i = 0; i < s->length; ++i) {
            dst[i] = src[i];
            if (bad < 0 && !fsdem__finite(src[i])) bad = i;
        }
        return bad;
    }
    {
        const fsdem__level *L = &s->level[0];
        for (k = 0; k < L->n[2]; ++k)
            for (j = 0; j < L->n[1]; ++j)
                for (i = 0; i < L->n[0]; ++i, ++u) {
                    int c = fsdem__level_index(L, s->dim, i, j, k);
                    if (FSDEM__TYPE(L->type[c]) == FSDEM_STENCIL_CELL_FLUID) {
                        dst[c] = src[u];
                        if (bad < 0 && !fsdem__finite(src[u])) bad = u;
                    } else {
                        dst[c] = 0;
                    }
                }
    }
    return bad;
}

static void fsdem__pcg_store(const fsdem_pcg *s, const fsdem_real *src, fsdem_real *dst) {
    int i, j, k, u = 0;
    if (s->kind == FSDEM__KIND_CSR) {
        memcpy(dst, src, sizeof(fsdem_real) * (size_t)s->length);
        return;
    }
    {
        const fsdem__level *L = &s->level[0];
        for (k = 0; k < L->n[2]; ++k)
            for (j = 0; j < L->n[1]; ++j)
                for (i = 0; i < L->n[0]; ++i, ++u) dst[u] = src[fsdem__level_index(L, s->dim, i, j, k)];
    }
}

/* a.b over [lo, hi) with two interleaved accumulators (lo even). */
/* threaded: inside a team: one block. */
static double fsdem__pcg_block_dot(const fsdem_real *a, const fsdem_real *b, int lo, int hi) {
    double s0 = 0, s1 = 0;
    int i;
    for (i = lo; i + 1 < hi; i += 2) {
        s0 += (double)a[i] * b[i];
        s1 += (double)a[i + 1] * b[i + 1];
    }
    if (i < hi) s0 += (double)a[i] * b[i];
    return s0 + s1;
}

/* a.b over n entries: block by block (FSDEM__DOT_BLOCK), the block sums added in order, so the bits
   do not depend on the threads (a vector of one block gives the block's sum itself). */
/* threaded: opens a team over the blocks. */
static double fsdem__pcg_vdot(const fsdem_pcg *s, const fsdem_real *a, const fsdem_real *b, int n) {
    const int blocks = (int)fsdem__dot_blocks(n);
    double *part = s->dot_part, sum = 0;
    int q;
    if (blocks <= 1) return fsdem__pcg_block_dot(a, b, 0, n);
    FSDEM__OMP(parallel for schedule(static)
               num_threads(fsdem__team_for(blocks, 1, FSDEM__NO_CAP)))
    for (q = 0; q < blocks; ++q) {
        const int lo = q * FSDEM__DOT_BLOCK, hi = n - lo < FSDEM__DOT_BLOCK ? n : lo + FSDEM__DOT_BLOCK;
        part[q] = fsdem__pcg_block_dot(a, b, lo, hi);
    }
    for (q = 0; q < blocks; ++q) sum += part[q];
    return sum;
}

static int fsdem__pcg_finite_d(double v) { return v == v && v - v == 0; }

/* x += alpha p, r -= alpha A p (A p in z); returns r.r, summed block by block as fsdem__pcg_vdot
   (one accumulator inside a block). */
/* threaded: opens a team over the blocks. */
static double fsdem__pcg_step_x_r(const fsdem_pcg *s, fsdem_real alpha) {
    const int n = s->length, blocks = (int)fsdem__dot_blocks(n);
    fsdem_real *FSDEM__RESTRICT xv = s->x, *FSDEM__RESTRICT rv = s->r;
    const fsdem_real *FSDEM__RESTRICT pv = s->p, *FSDEM__RESTRICT qv = s->z;
    double *part = s->dot_part, sum = 0;
    int q;
    FSDEM__OMP(parallel for schedule(static)
               num_threads(fsdem__team_for(blocks, 1, FSDEM__NO_CAP)))
    for (q = 0; q < blocks; ++q) {
        const int lo = q * FSDEM__DOT_BLOCK, hi = n - lo < FSDEM__DOT_BLOCK ? n : lo + FSDEM__DOT_BLOCK;
        double acc = 0;
        int i;
        for (i = lo; i < hi; ++i) {
            xv[i] += alpha * pv[i];
            rv[i] -= alpha * qv[i];
            acc += (double)rv[i] * rv[i];
        }
        part[q] = acc;
    }
    for (q = 0; q < blocks; ++q) sum += part[q];
    return sum;
}

/* True residual b - A x into `out` (uses z as scratch); returns its squared norm. */
static double fsdem__pcg_true_residual(fsdem_pcg *s, const fsdem_real *b, fsdem_real *out) {
    int i;
    fsdem__pcg_load(s, b, out);
    fsdem__pcg_project(s, out);
    fsdem__pcg_apply(s, s->x, s->z);
    for (i = 0; i < s->length; ++i) out[i] -= s->z[i];
    return fsdem__pcg_vdot(s, out, out, s->length);
}

/* r.z must be positive and finite for a symmetric positive definite preconditioner and operator. */
static fsdem_result fsdem__pcg_check_rz(fsdem_pcg *s, double rz, int it) {
    if (!fsdem__pcg_finite_d(rz))
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pcg_solve: r.z is NaN/Inf at iteration %d", it);
    if (rz <= 0)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pcg_solve: r.z = %g <= 0 at iteration %d: the preconditioner is not positive "
                           "definite (is the operator?)", rz, it);
    return FSDEM_OK;
}

/* threaded: opens a team for the search direction; the operator, the preconditioner and the dot
   products open their own. */
fsdem_result fsdem_pcg_solve(fsdem_pcg *s, const fsdem_real *b, fsdem_real *x, fsdem_pcg_info *info) {
    fsdem_pcg_info inf;
    double bb, rr, rz = 0, tol2, removed;
    int n, i, it = 0, bad, restart = 1, r_is_true = 1;
    fsdem_result res = FSDEM_OK;
    memset(&inf, 0, sizeof inf);
    inf.levels = 1;
    if (info) *info = inf;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (s->kind == FSDEM__KIND_NONE)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pcg_solve: no operator; call fsdem_pcg_setup_stencil or fsdem_pcg_setup_csr first");
    if (!b || !x) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pcg_solve: b and x must not be NULL");
    n = s->length;
    inf.levels = s->precond == FSDEM_PRECOND_AMG ? s->amg->levels : s->levels;
    inf.memory_bytes = s->arena_bytes + sizeof *s + (s->amg ? s->amg->bytes : 0);
    inf.nullspace_components = s->ns_components;
    bad = fsdem__pcg_load(s, b, s->r);
    if (bad >= 0) {
        if (info) *info = inf;
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pcg_solve: b[%d] = %g is not finite", bad, (double)b[bad]);
    }
    bad = fsdem__pcg_load(s, x, s->x);
    if (bad >= 0) {
        if (info) *info = inf;
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pcg_solve: initial guess x[%d] = %g is not finite", bad,
                           (double)x[bad]);
    }
    bb = fsdem__pcg_vdot(s, s->r, s->r, n);
    removed = fsdem__pcg_project(s, s->r);
    inf.incompatibility = bb > 0 ? (fsdem_real)sqrt(removed / bb) : 0;
    bb = fsdem__pcg_vdot(s, s->r, s->r, n);
    if (!fsdem__pcg_finite_d(bb)) {
        if (info) *info = inf;
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pcg_solve: ||b|| overflows");
    }
    inf.rhs_norm = (fsdem_real)sqrt(bb);
    if (bb == 0) { /* the solution is 0 */
        memset(s->x, 0, sizeof(fsdem_real) * (size_t)n);
        fsdem__pcg_store(s, s->x, x);
        if (info) *info = inf;
        return fsdem__ok(&s->status);
    }
    tol2 = (double)s->desc.tolerance * s->desc.tolerance * bb;
    /* r = b - A x */
    fsdem__pcg_project(s, s->x);
    fsdem__pcg_apply(s, s->x, s->z);
    for (i = 0; i < n; ++i) s->r[i] -= s->z[i];
    rr = fsdem__pcg_vdot(s, s->r, s->r, n);
    for (;;) {
        double pq, alpha, rz_new, beta;
        if (!fsdem__pcg_finite_d(rr)) {
            res = fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pcg_solve: the residual became NaN/Inf at iteration %d", it);
            break;
        }
        if (rr <= tol2) {
            if (r_is_true) break;
            rr = fsdem__pcg_true_residual(s, b, s->r); /* guard against a drifted recurrence */
            r_is_true = 1;
            if (rr <= tol2) break;
            restart = 1;
        }
        if (it >= s->desc.max_iterations) {
            if (!r_is_true) {
                rr = fsdem__pcg_true_residual(s, b, s->r);
                r_is_true = 1;
            }
            res = fsdem__fail(&s->status, FSDEM_ERR_NOT_CONVERGED,
                              "fsdem_pcg_solve: not converged in %d iterations (relative residual %g, tolerance %g)", it,
                              sqrt(rr / bb), (double)s->desc.tolerance);
            break;
        }
        if (restart) {
            fsdem__pcg_precondition(s, s->r, s->z);
            fsdem__pcg_project(s, s->z);
            rz = fsdem__pcg_vdot(s, s->r, s->z, n);
            res = fsdem__pcg_check_rz(s, rz, it);
            if (res != FSDEM_OK) break;
            memcpy(s->p, s->z, sizeof(fsdem_real) * (size_t)n);
            restart = 0;
        }
        fsdem__pcg_apply(s, s->p, s->z); /* z is free until the next preconditioning */
        pq = fsdem__pcg_vdot(s, s->p, s->z, n);
        if (!fsdem__pcg_finite_d(pq)) {
            res = fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pcg_solve: p.Ap is NaN/Inf at iteration %d", it);
            break;
        }
        if (pq <= 0) {
            res = fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                              "fsdem_pcg_solve: non-positive curvature p.Ap = %g at iteration %d: the operator is not "
                              "positive definite", pq, it);
            break;
        }
        alpha = rz / pq;
        rr = fsdem__pcg_step_x_r(s, (fsdem_real)alpha);
        ++it;
        r_is_true = 0;
        if (!fsdem__pcg_finite_d(rr) || rr <= tol2) continue;
        fsdem__pcg_precondition(s, s->r, s->z);
        fsdem__pcg_project(s, s->z);
        rz_new = fsdem__pcg_vdot(s, s->r, s->z, n);
        res = fsdem__pcg_check_rz(s, rz_new, it);
        if (res != FSDEM_OK) break;
        beta = rz_new / rz;
        rz = rz_new;
        {
            const fsdem_real be = (fsdem_real)beta;
            fsdem_real *pv = s->p;
            const fsdem_real *zv = s->z;
            FSDEM__OMP(parallel for schedule(static)
                       num_threads(fsdem__team_for(n, FSDEM__DOT_BLOCK, FSDEM__NO_CAP)))
            for (i = 0; i < n; ++i) pv[i] = zv[i] + be * pv[i];
        }
    }
    inf.iterations = it;
    if (res == FSDEM_ERR_NAN) { /* x is left as it was */
        inf.residual = (fsdem_real)(fsdem__pcg_finite_d(rr) ? sqrt(rr / bb) : rr);
        if (info) *info = inf;
        return res;
    }
    if (!r_is_true) rr = fsdem__pcg_true_residual(s, b, s->r);
    inf.residual = (fsdem_real)sqrt(rr / bb);
    fsdem__pcg_project(s, s->x);
    fsdem__pcg_store(s, s->x, x);
    if (info) *info = inf;
    return res == FSDEM_OK ? fsdem__ok(&s->status) : res;
}
