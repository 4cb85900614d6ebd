/* ---- >>linalg_amg : smoothed-aggregation algebraic multigrid for CSR matrices ---- */

/* FSDEM_PRECOND_AMG: a V-cycle of smoothed aggregation (Vanek, Mandel and Brezina 1996, Computing
   56:179-196), built from the matrix alone, for any fsdem_csr (MPS pressure equations, a user's
   own). Each level coarsens the one above:
     1. strength: j is a strong neighbour of i when |a_ij| >= theta max_k!=i |a_ik| (theta =
        desc.amg_strength). The row-relative test of classical AMG (Ruge and Stueben 1987) rather
        than the paper's a_ij^2 >= theta^2 a_ii a_jj: in the wide rows of an MPS pressure matrix
        (46 entries in 2D at re = 4.1 r0) no entry reaches 0.08 of the diagonal, and the paper's
        test left 0.3 strong neighbours per row, so nothing coarsened. Both signs count, so
        matrices with positive off-diagonal entries, such as normal equations, coarsen too;
     2. aggregation in the three passes of the paper: a node whose strong neighbours are all free
        founds an aggregate of them; a free node left over joins the aggregate of its strongest
        aggregated neighbour; what is still free founds aggregates with its free strong neighbours;
     3. the tentative prolongation P0 is constant on each aggregate (the near-null space of a
        Poisson matrix), columns of unit length; it is smoothed by one damped Jacobi step,
        P = (I - omega D^-1 A) P0 with omega = 4 / (3 rho(D^-1 A)), rho from 12 power iterations;
     4. the coarse matrix is the Galerkin product P^T A P (symmetric positive definite when A is).
   Coarsening stops at FSDEM__AMG_COARSE rows, solved exactly by a dense Cholesky factorisation,
   or when a level shrinks by less than a tenth (then that level is the coarsest and takes
   desc.mg_sweeps * 8 smoothing sweeps instead, when it is too large to factor). The cycle is a W
   (two coarse cycles per level: aggregates of 10-25 nodes make the coarse levels so small that
   the second costs little, and it kept the iterations on MPS matrices from creeping up by one per
   level, 7-8-9 with a V-cycle from 3,200 to 51,000 rows); it smooths with desc.mg_sweeps forward
   Gauss-Seidel sweeps before the coarse correction and as many backward sweeps after it, so the
   preconditioner is symmetric, as conjugate gradients need.
   Setup allocates (the hierarchy is rebuilt at every setup); a solve allocates nothing. */

#define FSDEM__AMG_MAX_LEVELS 25
#define FSDEM__AMG_COARSE 300 /* rows solved by dense Cholesky */

typedef struct fsdem__amg_level {
    int n, nnz;               /* rows and entries of A */
    const int *a_start, *a_col;
    const fsdem_real *a_val;  /* A: the caller's matrix on level 0, owned (the arrays below) on others */
    int *own_start, *own_col;
    fsdem_real *own_val;
    fsdem_real *inv_diag;
    int nc, p_nnz;            /* P: n x nc, from the next level to this one; P^T: nc x n */
    int *p_start, *p_col, *pt_start, *pt_col;
    fsdem_real *p_val, *pt_val;
    fsdem_real *x, *b, *r;
} fsdem__amg_level;

struct fsdem__amg {
    int levels;
    fsdem__amg_level lv[FSDEM__AMG_MAX_LEVELS];
    fsdem_real *chol;         /* coarsest level: lower Cholesky factor, row-major, or NULL (smoothing) */
    int chol_n, coarse_sweeps;
    size_t bytes;
};

static void *fsdem__amg_array(const fsdem_allocator *al, fsdem__amg *g, size_t count, size_t elem) {
    void *p = fsdem__alloc(al, (count ? count : 1) * elem);
    if (p) g->bytes += (count ? count : 1) * elem;
    return p;
}

static void fsdem__amg_free(const fsdem_allocator *al, fsdem__amg *g) {
    int l;
    if (!g) return;
    for (l = 0; l < g->levels; ++l) {
        fsdem__amg_level *L = &g->lv[l];
        const size_t n = (size_t)(L->n ? L->n : 1), nc = (size_t)(L->nc ? L->nc : 1);
        const size_t nnz = (size_t)(L->nnz ? L->nnz : 1), pn = (size_t)(L->p_nnz ? L->p_nnz : 1);
        fsdem__free(al, L->own_start, sizeof(int) * (n + 1));
        fsdem__free(al, L->own_col, sizeof(int) * nnz);
        fsdem__free(al, L->own_val, sizeof(fsdem_real) * nnz);
        fsdem__free(al, L->inv_diag, sizeof(fsdem_real) * n);
        fsdem__free(al, L->p_start, sizeof(int) * (n + 1));
        fsdem__free(al, L->p_col, sizeof(int) * pn);
        fsdem__free(al, L->p_val, sizeof(fsdem_real) * pn);
        fsdem__free(al, L->pt_start, sizeof(int) * (nc + 1));
        fsdem__free(al, L->pt_col, sizeof(int) * pn);
        fsdem__free(al, L->pt_val, sizeof(fsdem_real) * pn);
        fsdem__free(al, L->x, sizeof(fsdem_real) * n);
        fsdem__free(al, L->b, sizeof(fsdem_real) * n);
        fsdem__free(al, L->r, sizeof(fsdem_real) * n);
    }
    fsdem__free(al, g->chol, sizeof(fsdem_real) * (size_t)(g->chol_n ? g->chol_n : 1) * (size_t)(g->chol_n ? g->chol_n : 1));
    fsdem__free(al, g, sizeof *g);
}

/* Work arrays of a setup, sized for the finest level (every level is smaller). */
typedef struct fsdem__amg_work {
    int *mark, *list, *agg;
    fsdem_real *acc, *v, *w;
} fsdem__amg_work;

static int fsdem__amg_int_cmp(const void *a, const void *b) {
    const int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* C = A B for CSR A (m rows) and B (columns < ncols), columns sorted; the arrays go to *cs, *cc,
   *cv (allocated, counted in g). Returns 0 on an allocation failure. */
static int fsdem__amg_multiply(const fsdem_allocator *al, fsdem__amg *g, fsdem__amg_work *wk, int m, const int *as, const int *ac,
                               const fsdem_real *av, const int *bs, const int *bc, const fsdem_real *bv, int **cs, int **cc,
                               fsdem_real **cv, int *cnnz) {
    long long nnz = 0;
    int i, e, f, k;
    *cs = (int *)fsdem__amg_array(al, g, (size_t)m + 1, sizeof(int));
    if (!*cs) return 0;
    (*cs)[0] = 0;
    for (i = 0; i < m; ++i) { /* symbolic: the columns of each row of C */
        int count = 0;
        for (e = as[i]; e < as[i + 1]; ++e)
            for (f = bs[ac[e]]; f < bs[ac[e] + 1]; ++f)
                if (wk->mark[bc[f]] != i) {
                    wk->mark[bc[f]] = i;
                    count++;
                }
        nnz += count;
        if (nnz > 2147483647LL) return 0;
        (*cs)[i + 1] = (int)nnz;
    }
    for (i = 0; i < m; ++i) wk->mark[i] = -1;
    *cnnz = (int)nnz;
    *cc = (int *)fsdem__amg_array(al, g, (size_t)nnz, sizeof(int));
    *cv = (fsdem_real *)fsdem__amg_array(al, g, (size_t)nnz, sizeof(fsdem_real));
    if (!*cc || !*cv) return 0;
    for (i = 0; i < m; ++i) {
        int count = 0;
        for (e = as[i]; e < as[i + 1]; ++e)
            for (f = bs[ac[e]]; f < bs[ac[e] + 1]; ++f) {
                const int c = bc[f];
                if (wk->mark[c] != -2 - i) {
                    wk->mark[c] = -2 - i;
                    wk->acc[c] = 0;
                    wk->list[count++] = c;
                }
                wk->acc[c] += av[e] * bv[f];
            }
        qsort(wk->list, (size_t)count, sizeof(int), fsdem__amg_int_cmp);
        for (k = 0; k < count; ++k) {
            (*cc)[(*cs)[i] + k] = wk->list[k];
            (*cv)[(*cs)[i] + k] = wk->acc[wk->list[k]];
        }
    }
    return 1;
}

/* P^T of P (n rows, nc columns), columns sorted (the counting sort keeps row order). */
static int fsdem__amg_transpose(const fsdem_allocator *al, fsdem__amg *g, fsdem__amg_level *L) {
    int i, e;
    L->pt_start = (int *)fsdem__amg_array(al, g, (size_t)L->nc + 1, sizeof(int));
    L->pt_col = (int *)fsdem__amg_array(al, g, (size_t)L->p_nnz, sizeof(int));
    L->pt_val = (fsdem_real *)fsdem__amg_array(al, g, (size_t)L->p_nnz, sizeof(fsdem_real));
    if (!L->pt_start || !L->pt_col || !L->pt_val) return 0;
    memset(L->pt_start, 0, sizeof(int) * ((size_t)L->nc + 1));
    for (e = 0; e < L->p_nnz; ++e) L->pt_start[L->p_col[e] + 1]++;
    for (i = 0; i < L->nc; ++i) L->pt_start[i + 1] += L->pt_start[i];
    for (i = 0; i < L->n; ++i)
        for (e = L->p_start[i]; e < L->p_start[i + 1]; ++e) {
            const int at = L->pt_start[L->p_col[e]]++;
            L->pt_col[at] = i;
            L->pt_val[at] = L->p_val[e];
        }
    for (i = L->nc; i > 0; --i) L->pt_start[i] = L->pt_start[i - 1];
    L->pt_start[0] = 0;
    return 1;
}

/* Aggregates of level L (steps 1-2 of the section) into wk->agg; returns their number. */
static int fsdem__amg_aggregate(const fsdem__amg_level *L, fsdem_real theta, fsdem__amg_work *wk) {
    int i, e, nagg = 0;
#define FSDEM__AMG_STRONG(i, e) (L->a_col[e] != (i) && (fsdem_real)fabs((double)L->a_val[e]) >= theta * wk->v[i])
    for (i = 0; i < L->n; ++i) {
        wk->agg[i] = -1;
        wk->v[i] = 0;
        for (e = L->a_start[i]; e < L->a_start[i + 1]; ++e)
            if (L->a_col[e] != i && (fsdem_real)fabs((double)L->a_val[e]) > wk->v[i]) wk->v[i] = (fsdem_real)fabs((double)L->a_val[e]);
    }
    for (i = 0; i < L->n; ++i) { /* pass 1: a free node whose strong neighbours are all free */
        int free_all = wk->agg[i] < 0;
        for (e = L->a_start[i]; e < L->a_start[i + 1] && free_all; ++e)
            if (FSDEM__AMG_STRONG(i, e) && wk->agg[L->a_col[e]] >= 0) free_all = 0;
        if (!free_all) continue;
        wk->agg[i] = nagg;
        for (e = L->a_start[i]; e < L->a_start[i + 1]; ++e)
            if (FSDEM__AMG_STRONG(i, e)) wk->agg[L->a_col[e]] = nagg;
        nagg++;
    }
    for (i = 0; i < L->n; ++i) { /* pass 2: the aggregate of the strongest aggregated neighbour */
        fsdem_real best = -1;
        wk->list[i] = -1;
        if (wk->agg[i] >= 0) continue;
        for (e = L->a_start[i]; e < L->a_start[i + 1]; ++e)
            if (FSDEM__AMG_STRONG(i, e) && wk->agg[L->a_col[e]] >= 0 && (fsdem_real)fabs((double)L->a_val[e]) > best) {
                best = (fsdem_real)fabs((double)L->a_val[e]);
                wk->list[i] = wk->agg[L->a_col[e]];
            }
    }
    for (i = 0; i < L->n; ++i) /* joined after the pass, so that no node joins through another joiner */
        if (wk->agg[i] < 0) wk->agg[i] = wk->list[i];
    for (i = 0; i < L->n; ++i) { /* pass 3: what is left, with its free strong neighbours */
        if (wk->agg[i] >= 0) continue;
        wk->agg[i] = nagg;
        for (e = L->a_start[i]; e < L->a_start[i + 1]; ++e)
            if (FSDEM__AMG_STRONG(i, e) && wk->agg[L->a_col[e]] < 0) wk->agg[L->a_col[e]] = nagg;
        nagg++;
    }
#undef FSDEM__AMG_STRONG
    return nagg;
}

/* y = A x on level L. */
static void fsdem__amg_apply(const fsdem__amg_level *L, const fsdem_real *x, fsdem_real *y) {
    int i, e;
    for (i = 0; i < L->n; ++i) {
        fsdem_real sum = 0;
        for (e = L->a_start[i]; e < L->a_start[i + 1]; ++e) sum += L->a_val[e] * x[L->a_col[e]];
        y[i] = sum;
    }
}

/* The smoothed prolongation of level L from its aggregates (step 3 of the section). */
static int fsdem__amg_prolongation(const fsdem_allocator *al, fsdem__amg *g, fsdem__amg_level *L, fsdem__amg_work *wk) {
    double rho = 0, norm = 0;
    fsdem_real omega;
    long long nnz = 0;
    int i, e, it, k;
    /* rho(D^-1 A) by power iteration from a fixed, uneven start (deterministic) */
    for (i = 0; i < L->n; ++i) wk->v[i] = (fsdem_real)(1 + (i % 7) * 0.1);
    for (it = 0; it < 12; ++it) {
        double vv = 0, wv = 0;
        fsdem__amg_apply(L, wk->v, wk->w);
        for (i = 0; i < L->n; ++i) {
            wk->w[i] *= L->inv_diag[i];
            vv += (double)wk->v[i] * wk->v[i];
            wv += (double)wk->w[i] * wk->w[i];
        }
        rho = vv > 0 ? sqrt(wv / vv) : 1;
        norm = sqrt(wv);
        if (!(norm > 0)) break;
        for (i = 0; i < L->n; ++i) wk->v[i] = (fsdem_real)(wk->w[i] / norm);
    }
    omega = (fsdem_real)(4.0 / (3.0 * (rho > 0 ? rho : 1)));
    /* P0: 1/sqrt(size) on each aggregate; wk->v holds it per row */
    for (k = 0; k < L->nc; ++k) wk->acc[k] = 0;
    for (i = 0; i < L->n; ++i) wk->acc[wk->agg[i]] += 1;
    for (i = 0; i < L->n; ++i) wk->v[i] = (fsdem_real)(1 / sqrt((double)wk->acc[wk->agg[i]]));
    for (k = 0; k < L->nc; ++k) wk->mark[k] = -1;
    L->p_start = (int *)fsdem__amg_array(al, g, (size_t)L->n + 1, sizeof(int));
    if (!L->p_start) return 0;
    L->p_start[0] = 0;
    for (i = 0; i < L->n; ++i) { /* columns: the aggregates of i and of its neighbours */
        int count = 0;
        for (e = L->a_start[i] - 1; e < L->a_start[i + 1]; ++e) {
            const int c = wk->agg[e < L->a_start[i] ? i : L->a_col[e]];
            if (wk->mark[c] != i) {
                wk->mark[c] = i;
                count++;
            }
        }
        nnz += count;
        if (nnz > 2147483647LL) return 0;
        L->p_start[i + 1] = (int)nnz;
    }
    L->p_nnz = (int)nnz;
    L->p_col = (int *)fsdem__amg_array(al, g, (size_t)nnz, sizeof(int));
    L->p_val = (fsdem_real *)fsdem__amg_array(al, g, (size_t)nnz, sizeof(fsdem_real));
    if (!L->p_col || !L->p_val) return 0;
    for (k = 0; k < L->nc; ++k) wk->mark[k] = -1;
    for (i = 0; i < L->n; ++i) { /* P_ic = P0_ic - omega / a_ii sum_j a_ij P0_jc */
        int count = 0;
        for (e = L->a_start[i] - 1; e < L->a_start[i + 1]; ++e) {
            const int j = e < L->a_start[i] ? i : L->a_col[e], c = wk->agg[j];
            const fsdem_real add = e < L->a_start[i] ? wk->v[i] : -omega * L->inv_diag[i] * L->a_val[e] * wk->v[j];
            if (wk->mark[c] != i) {
                wk->mark[c] = i;
                wk->acc[c] = 0;
                wk->list[count++] = c;
            }
            wk->acc[c] += add;
        }
        qsort(wk->list, (size_t)count, sizeof(int), fsdem__amg_int_cmp);
        for (k = 0; k < count; ++k) {
            L->p_col[L->p_start[i] + k] = wk->list[k];
            L->p_val[L->p_start[i] + k] = wk->acc[wk->list[k]];
        }
    }
    for (k = 0; k < L->n; ++k) wk->mark[k] = -1;
    return fsdem__amg_transpose(al, g, L);
}

/* Level vectors and 1/a_ii of level L (its A set). Returns 0 on an allocation failure, and on a
   non-positive diagonal (the matrix is not positive definite) sets *indefinite too. */
static int fsdem__amg_level_arrays(const fsdem_allocator *al, fsdem__amg *g, fsdem__amg_level *L, int *indefinite) {
    int i, e;
    L->inv_diag = (fsdem_real *)fsdem__amg_array(al, g, (size_t)L->n, sizeof(fsdem_real));
    L->x = (fsdem_real *)fsdem__amg_array(al, g, (size_t)L->n, sizeof(fsdem_real));
    L->b = (fsdem_real *)fsdem__amg_array(al, g, (size_t)L->n, sizeof(fsdem_real));
    L->r = (fsdem_real *)fsdem__amg_array(al, g, (size_t)L->n, sizeof(fsdem_real));
    if (!L->inv_diag || !L->x || !L->b || !L->r) return 0;
    for (i = 0; i < L->n; ++i) {
        L->inv_diag[i] = 0;
        for (e = L->a_start[i]; e < L->a_start[i + 1]; ++e)
            if (L->a_col[e] == i && L->a_val[e] > 0) L->inv_diag[i] = 1 / L->a_val[e];
        if (!(L->inv_diag[i] > 0)) return !(*indefinite = 1);
    }
    return 1;
}

/* Dense Cholesky factor of the coarsest level (a pivot below 1e-12 of its diagonal entry, from
   rounding in a nearly singular Galerkin product, is replaced by the diagonal entry). */
static int fsdem__amg_factor(const fsdem_allocator *al, fsdem__amg *g, const fsdem__amg_level *L) {
    const int n = L->n;
    int i, j, k, e;
    g->chol = (fsdem_real *)fsdem__amg_array(al, g, (size_t)n * (size_t)n, sizeof(fsdem_real));
    if (!g->chol) return 0;
    g->chol_n = n;
    memset(g->chol, 0, sizeof(fsdem_real) * (size_t)n * (size_t)n);
    for (i = 0; i < n; ++i)
        for (e = L->a_start[i]; e < L->a_start[i + 1]; ++e) g->chol[(size_t)i * n + L->a_col[e]] = L->a_val[e];
    for (j = 0; j < n; ++j) {
        fsdem_real *cj = g->chol + (size_t)j * n, d = cj[j];
        for (k = 0; k < j; ++k) d -= cj[k] * cj[k];
        if (!(d > (fsdem_real)1e-12 * g->chol[(size_t)j * n + j])) d = g->chol[(size_t)j * n + j];
        cj[j] = (fsdem_real)sqrt((double)d);
        for (i = j + 1; i < n; ++i) {
            fsdem_real *ci = g->chol + (size_t)i * n, s = ci[j];
            for (k = 0; k < j; ++k) s -= ci[k] * cj[k];
            ci[j] = s / cj[j];
        }
    }
    return 1;
}

/* Builds the hierarchy of matrix m into a new object (*out); on failure *out is NULL and the result
   FSDEM_ERR_INVALID_ARG when a level's diagonal entry is not positive (m is not positive definite),
   FSDEM_ERR_OUT_OF_MEMORY otherwise. */
static fsdem_result fsdem__amg_build(const fsdem_allocator *al, const fsdem_pcg_desc *desc, const fsdem_csr *m, fsdem__amg **out) {
    fsdem__amg *g = (fsdem__amg *)fsdem__alloc(al, sizeof *g);
    fsdem__amg_work wk;
    const size_t n = (size_t)m->rows;
    int ok, l, indefinite = 0;
    *out = NULL;
    if (!g) return FSDEM_ERR_OUT_OF_MEMORY;
    memset(g, 0, sizeof *g);
    g->bytes = sizeof *g;
    wk.mark = (int *)fsdem__alloc(al, sizeof(int) * n);
    wk.list = (int *)fsdem__alloc(al, sizeof(int) * n);
    wk.agg = (int *)fsdem__alloc(al, sizeof(int) * n);
    wk.acc = (fsdem_real *)fsdem__alloc(al, sizeof(fsdem_real) * n);
    wk.v = (fsdem_real *)fsdem__alloc(al, sizeof(fsdem_real) * n);
    wk.w = (fsdem_real *)fsdem__alloc(al, sizeof(fsdem_real) * n);
    ok = wk.mark && wk.list && wk.agg && wk.acc && wk.v && wk.w;
    if (ok) {
        size_t i;
        for (i = 0; i < n; ++i) wk.mark[i] = -1;
        g->levels = 1;
        g->lv[0].n = m->rows;
        g->lv[0].nnz = m->row_start[m->rows];
        g->lv[0].a_start = m->row_start;
        g->lv[0].a_col = m->col;
        g->lv[0].a_val = m->val;
        ok = fsdem__amg_level_arrays(al, g, &g->lv[0], &indefinite);
    }
    for (l = 0; ok; ++l) {
        fsdem__amg_level *L = &g->lv[l], *C;
        int *ap_start = NULL, *ap_col = NULL, ap_nnz = 0;
        fsdem_real *ap_val = NULL;
        size_t bytes0;
        if (L->n <= FSDEM__AMG_COARSE || l + 1 == FSDEM__AMG_MAX_LEVELS) break;
        L->nc = fsdem__amg_aggregate(L, desc->amg_strength, &wk);
        if (L->nc > L->n - L->n / 10) { /* stalled: this level is the coarsest */
            L->nc = 0;
            break;
        }
        if (!(ok = fsdem__amg_prolongation(al, g, L, &wk))) break;
        bytes0 = g->bytes;
        ok = fsdem__amg_multiply(al, g, &wk, L->n, L->a_start, L->a_col, L->a_val, L->p_start, L->p_col, L->p_val, &ap_start,
                                 &ap_col, &ap_val, &ap_nnz);
        C = &g->lv[l + 1];
        if (ok)
            ok = fsdem__amg_multiply(al, g, &wk, L->nc, L->pt_start, L->pt_col, L->pt_val, ap_start, ap_col, ap_val, &C->own_start,
                                     &C->own_col, &C->own_val, &C->nnz);
        fsdem__free(al, ap_start, sizeof(int) * ((size_t)L->n + 1));
        fsdem__free(al, ap_col, sizeof(int) * (size_t)(ap_nnz ? ap_nnz : 1));
        fsdem__free(al, ap_val, sizeof(fsdem_real) * (size_t)(ap_nnz ? ap_nnz : 1));
        g->bytes = bytes0 + (g->bytes - bytes0) - (sizeof(int) * ((size_t)L->n + 1) + (sizeof(int) + sizeof(fsdem_real)) * (size_t)(ap_nnz ? ap_nnz : 1));
        g->levels = l + 2;
        C->n = L->nc;
        C->a_start = C->own_start;
        C->a_col = C->own_col;
        C->a_val = C->own_val;
        if (ok) ok = fsdem__amg_level_arrays(al, g, C, &indefinite);
    }
    if (ok) {
        const fsdem__amg_level *last = &g->lv[g->levels - 1];
        g->coarse_sweeps = 8 * desc->mg_sweeps;
        if (last->n <= 4 * FSDEM__AMG_COARSE) ok = fsdem__amg_factor(al, g, last);
    }
    fsdem__free(al, wk.mark, sizeof(int) * n);
    fsdem__free(al, wk.list, sizeof(int) * n);
    fsdem__free(al, wk.agg, sizeof(int) * n);
    fsdem__free(al, wk.acc, sizeof(fsdem_real) * n);
    fsdem__free(al, wk.v, sizeof(fsdem_real) * n);
    fsdem__free(al, wk.w, sizeof(fsdem_real) * n);
    if (!ok) {
        fsdem__amg_free(al, g);
        return indefinite ? FSDEM_ERR_INVALID_ARG : FSDEM_ERR_OUT_OF_MEMORY;
    }
    *out = g;
    return FSDEM_OK;
}

/* Gauss-Seidel sweeps on level L, forward or backward. */
static void fsdem__amg_smooth(fsdem__amg_level *L, int sweeps, int backward) {
    int s, k, e;
    for (s = 0; s < sweeps; ++s)
        for (k = 0; k < L->n; ++k) {
            const int i = backward ? L->n - 1 - k : k;
            fsdem_real sum = L->b[i];
            for (e = L->a_start[i]; e < L->a_start[i + 1]; ++e)
                if (L->a_col[e] != i) sum -= L->a_val[e] * L->x[L->a_col[e]];
            L->x[i] = sum * L->inv_diag[i];
        }
}

/* One cycle on level l from its current x towards A x = b (the section's cycle). */
static void fsdem__amg_cycle(fsdem__amg *g, int l, int sweeps) {
    fsdem__amg_level *L = &g->lv[l], *C;
    int i, e, k;
    if (l == g->levels - 1) {
        memset(L->x, 0, sizeof(fsdem_real) * (size_t)L->n);
        if (!g->chol) {
            fsdem__amg_smooth(L, g->coarse_sweeps, 0);
            fsdem__amg_smooth(L, g->coarse_sweeps, 1);
            return;
        }
        for (i = 0; i < L->n; ++i) { /* L y = b, then L^T x = y */
            const fsdem_real *ci = g->chol + (size_t)i * L->n;
            fsdem_real s = L->b[i];
            for (e = 0; e < i; ++e) s -= ci[e] * L->x[e];
            L->x[i] = s / ci[i];
        }
        for (i = L->n - 1; i >= 0; --i) {
            fsdem_real s = L->x[i];
            for (e = i + 1; e < L->n; ++e) s -= g->chol[(size_t)e * L->n + i] * L->x[e];
            L->x[i] = s / g->chol[(size_t)i * L->n + i];
        }
        return;
    }
    C = &g->lv[l + 1];
    fsdem__amg_smooth(L, sweeps, 0);
    fsdem__amg_apply(L, L->x, L->r);
    for (i = 0; i < L->n; ++i) L->r[i] = L->b[i] - L->r[i];
    for (i = 0; i < C->n; ++i) {
        fsdem_real s = 0;
        for (e = L->pt_start[i]; e < L->pt_start[i + 1]; ++e) s += L->pt_val[e] * L->r[L->pt_col[e]];
        C->b[i] = s;
    }
    memset(C->x, 0, sizeof(fsdem_real) * (size_t)C->n);
    for (k = 0; k < 2; ++k) fsdem__amg_cycle(g, l + 1, sweeps); /* a W-cycle */
    for (i = 0; i < L->n; ++i)
        for (e = L->p_start[i]; e < L->p_start[i + 1]; ++e) L->x[i] += L->p_val[e] * C->x[L->p_col[e]];
    fsdem__amg_smooth(L, sweeps, 1);
}
