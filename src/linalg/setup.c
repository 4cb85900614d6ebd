/* ---- >>linalg_setup : setup for stencils and CSR matrices ---- */

/* Carves the stencil workspace; `levels` = number of multigrid levels to hold (1 without MG). */
static void fsdem__stencil_carve(fsdem_pcg *s, fsdem__pcg_carver *cv, int levels, int want_ic, int cells,
                                 int with_extra) {
    int l, a, N = s->level[0].count;
    fsdem_real **vec[4];
    vec[0] = &s->x;
    vec[1] = &s->r;
    vec[2] = &s->z;
    vec[3] = &s->p;
    for (a = 0; a < 4; ++a) *vec[a] = (fsdem_real *)fsdem__pcg_carve(cv, (size_t)N, sizeof(fsdem_real));
    s->ux = s->uy = NULL;
    if (with_extra) {
        s->ux = (fsdem_real *)fsdem__pcg_carve(cv, (size_t)cells, sizeof(fsdem_real));
        s->uy = (fsdem_real *)fsdem__pcg_carve(cv, (size_t)cells, sizeof(fsdem_real));
    }
    s->ic = want_ic ? (fsdem_real *)fsdem__pcg_carve(cv, (size_t)N, sizeof(fsdem_real)) : NULL;
    s->rowbuf = levels > 1 ? (fsdem_real *)fsdem__pcg_carve(cv, (size_t)s->workers * fsdem__mg_rowbuf_length(s), sizeof(fsdem_real))
                           : NULL;
    s->restricted = levels > 1 && s->workers > 1
                        ? (fsdem_real *)fsdem__pcg_carve(cv, fsdem__mg_restricted_length(&s->level[0], &s->level[1]), sizeof(fsdem_real))
                        : NULL;
    s->dot_part = (double *)fsdem__pcg_carve(cv, fsdem__dot_blocks(N), sizeof(double));
    s->progress = levels > 1 && s->workers > 1
                      ? (int *)fsdem__pcg_carve(cv, (size_t)(s->dim == 3 ? s->level[0].n[2] : s->level[0].n[1]), sizeof(int))
                      : NULL;
    s->mark = (unsigned char *)fsdem__pcg_carve(cv, (size_t)N, 1);
    s->ns_cell = (int *)fsdem__pcg_carve(cv, (size_t)N, sizeof(int));
    for (l = 0; l < levels; ++l) {
        fsdem__level *L = &s->level[l];
        size_t n = (size_t)L->count;
        L->type = (unsigned char *)fsdem__pcg_carve(cv, n, 1);
        L->d = (fsdem_real *)fsdem__pcg_carve(cv, n, sizeof(fsdem_real));
        L->inv_d = (fsdem_real *)fsdem__pcg_carve(cv, n, sizeof(fsdem_real));
        for (a = 0; a < 3; ++a)
            L->w[a] = a < s->dim ? (fsdem_real *)fsdem__pcg_carve(cv, n, sizeof(fsdem_real)) : NULL;
        if (s->dim == 2) L->w[2] = L->w[1]; /* never read in 2D; keeps the kernels' pointers valid */
        L->x = L->b = NULL;
        if (l > 0) {
            L->x = (fsdem_real *)fsdem__pcg_carve(cv, n, sizeof(fsdem_real));
            L->b = (fsdem_real *)fsdem__pcg_carve(cv, n, sizeof(fsdem_real));
        }
    }
}

/* Finds the fluid regions that no Dirichlet condition reaches (their matrix is singular: the
   constant is in its null space). A fluid cell is an anchor when its extra diagonal is positive
   or a face towards an air cell or a Dirichlet boundary has a positive coefficient, i.e. when
   d exceeds the sum of its fluid couplings; the test is made on the coefficients, not on d. */
static void fsdem__stencil_nullspace(fsdem_pcg *s, const fsdem_real *extra) {
    const fsdem__level *L = &s->level[0];
    int dim = s->dim, c, a, head, tail, st[3];
    unsigned char *mark = s->mark;
    int *queue = s->ns_cell;
    st[0] = 1;
    st[1] = L->sy;
    st[2] = L->sz;
    memset(mark, 0, (size_t)L->count);
    tail = 0;
    for (c = 0; c < L->count; ++c) {
        int anchor = 0;
        if (L->type[c] != FSDEM_STENCIL_CELL_FLUID) continue;
        if (extra[c] > 0) anchor = 1;
        for (a = 0; a < dim && !anchor; ++a) {
            /* physical coefficients are still in w here */
            if (L->w[a][c] > 0 && FSDEM__TYPE(L->type[c - st[a]]) == FSDEM_STENCIL_CELL_AIR) anchor = 1;
            if (L->w[a][c + st[a]] > 0 && FSDEM__TYPE(L->type[c + st[a]]) == FSDEM_STENCIL_CELL_AIR) anchor = 1;
        }
        if (anchor) {
            mark[c] = 1;
            queue[tail++] = c;
        }
    }
    for (head = 0; head < tail; ++head) {
        int u = queue[head];
        for (a = 0; a < dim; ++a) {
            int lo = u - st[a], hi = u + st[a];
            if (!mark[lo] && L->w[a][u] > 0 && L->type[lo] == FSDEM_STENCIL_CELL_FLUID) {
                mark[lo] = 1;
                queue[tail++] = lo;
            }
            if (!mark[hi] && L->w[a][hi] > 0 && L->type[hi] == FSDEM_STENCIL_CELL_FLUID) {
                mark[hi] = 1;
                queue[tail++] = hi;
            }
        }
    }
    /* the rest: flood each unanchored region, recording its cells */
    s->ns_components = 0;
    s->ns_cells = 0;
    for (c = 0; c < L->count; ++c) {
        if (mark[c] || L->type[c] != FSDEM_STENCIL_CELL_FLUID) continue;
        head = s->ns_cells;
        tail = head;
        mark[c] = 1;
        queue[tail++] = c;
        for (; head < tail; ++head) {
            int u = queue[head];
            for (a = 0; a < dim; ++a) {
                int lo = u - st[a], hi = u + st[a];
                if (!mark[lo] && L->w[a][u] > 0 && L->type[lo] == FSDEM_STENCIL_CELL_FLUID) {
                    mark[lo] = 1;
                    queue[tail++] = lo;
                }
                if (!mark[hi] && L->w[a][hi] > 0 && L->type[hi] == FSDEM_STENCIL_CELL_FLUID) {
                    mark[hi] = 1;
                    queue[tail++] = hi;
                }
            }
        }
        queue[s->ns_cells] = -(queue[s->ns_cells] + 1);
        s->ns_cells = tail;
        s->ns_components++;
    }
}

fsdem_result fsdem_pcg_setup_stencil(fsdem_pcg *s, const fsdem_stencil *st) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem__level plan[FSDEM__MG_MAX_LEVELS];
    fsdem__pcg_carver cv;
    fsdem_precond pc;
    fsdem_result res;
    int n[3], levels, l, cells;
    fsdem_real *extra, *cextra;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (st && (st->dim == 2 || st->dim == 3) && st->n[0] > 0 && st->n[1] > 0 && (st->dim == 2 || st->n[2] > 0) &&
        fsdem__stencil_padded(st) > FSDEM__MAX_PADDED)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY,
                           "fsdem_pcg_setup_stencil: a grid of %d x %d x %d cells does not fit (index overflow)",
                           st->n[0], st->n[1], st->dim == 3 ? st->n[2] : 1);
    if (fsdem_stencil_check(st, msg, sizeof msg) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s", msg);
    pc = s->desc.preconditioner == FSDEM_PRECOND_AUTO ? FSDEM_PRECOND_MG : s->desc.preconditioner;
    if (pc == FSDEM_PRECOND_AMG)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pcg_setup_stencil: FSDEM_PRECOND_AMG needs a CSR matrix (fsdem_pcg_setup_csr); use "
                           "FSDEM_PRECOND_MG for a stencil");
    fsdem__stencil_dims(st, n);
    cells = n[0] * n[1] * n[2];
    memset(plan, 0, sizeof plan);
    levels = pc == FSDEM_PRECOND_MG ? fsdem__mg_plan(plan, st->dim, n) : 1;
    if (levels == 1) {
        fsdem__level_geometry(&plan[0], st->dim, n);
        plan[0].ratio[0] = plan[0].ratio[1] = plan[0].ratio[2] = 1;
        plan[0].h[0] = plan[0].h[1] = plan[0].h[2] = 1;
    }
    /* measure on a copy (so a failure leaves the previous setup intact), reserve, carve */
    {
        fsdem_pcg probe = *s;
        memcpy(probe.level, plan, sizeof plan);
        probe.dim = st->dim;
        probe.workers = fsdem__workers();
        cv.base = NULL;
        cv.used = 0;
        cv.overflow = 0;
        fsdem__stencil_carve(&probe, &cv, levels, pc == FSDEM_PRECOND_IC0 || pc == FSDEM_PRECOND_MIC0, cells,
                             st->extra != NULL);
    }
    if (cv.overflow)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pcg_setup_stencil: workspace size overflows");
    res = fsdem__pcg_reserve(s, cv.used);
    if (res != FSDEM_OK)
        return fsdem__fail(&s->status, res, "fsdem_pcg_setup_stencil: cannot allocate %.0f bytes", (double)cv.used);
    s->kind = FSDEM__KIND_NONE;
    memcpy(s->level, plan, sizeof plan);
    s->dim = st->dim;
    s->workers = fsdem__workers();
    cv.base = (char *)s->arena;
    cv.used = 0;
    fsdem__stencil_carve(s, &cv, levels, pc == FSDEM_PRECOND_IC0 || pc == FSDEM_PRECOND_MIC0, cells, st->extra != NULL);
    /* every array is written in full below; the CG vectors' ghosts must be 0 */
    memset(s->x, 0, sizeof(fsdem_real) * (size_t)s->level[0].count);
    memset(s->r, 0, sizeof(fsdem_real) * (size_t)s->level[0].count);

    /* level 0; the extra diagonals live in the z and p vectors while the levels are built */
    extra = s->z;
    cextra = s->p;
    fsdem__level_from_stencil(&s->level[0], st, extra);
    fsdem__level_diagonal(&s->level[0], st->dim, extra);
    fsdem__stencil_nullspace(s, extra);
    s->levels = 1;
    if (pc == FSDEM_PRECOND_MG) {
        for (l = 1; l < levels && s->level[l - 1].fluid > 0; ++l) {
            fsdem__level *F = &s->level[l - 1], *C = &s->level[l];
            fsdem__level_coarsen(F, C, st->dim, extra, cextra);
            fsdem__level_diagonal(C, st->dim, cextra);
            if (C->fluid == 0) break;
            fsdem__level_mark_near_solid(F, C, st->dim);
            fsdem__level_offdiagonal(F, st->dim);
            memcpy(extra, cextra, sizeof(fsdem_real) * (size_t)C->count);
            s->levels = l + 1;
        }
    }
    fsdem__level_offdiagonal(&s->level[s->levels - 1], st->dim);
    for (l = 1; l < s->levels; ++l) /* ghosts stay 0; the V-cycle writes interior cells only */
        memset(s->level[l].x, 0, sizeof(fsdem_real) * (size_t)s->level[l].count);
    memset(s->z, 0, sizeof(fsdem_real) * (size_t)s->level[0].count);
    memset(s->p, 0, sizeof(fsdem_real) * (size_t)s->level[0].count);
    if (pc == FSDEM_PRECOND_IC0 || pc == FSDEM_PRECOND_MIC0)
        fsdem__stencil_ic_build(s, pc == FSDEM_PRECOND_MIC0 ? s->desc.mic_tau : 0);

    s->stencil = *st;
    s->precond = pc;
    s->length = s->level[0].count;
    s->user_length = cells;
    s->kind = FSDEM__KIND_STENCIL;
    fsdem__amg_free(&s->allocator, s->amg);
    s->amg = NULL;
    return fsdem__ok(&s->status);
}

static void fsdem__csr_carve(fsdem_pcg *s, fsdem__pcg_carver *cv, int n, int upper, fsdem_precond pc) {
    fsdem_real **vec[4];
    int a;
    vec[0] = &s->x;
    vec[1] = &s->r;
    vec[2] = &s->z;
    vec[3] = &s->p;
    for (a = 0; a < 4; ++a) *vec[a] = (fsdem_real *)fsdem__pcg_carve(cv, (size_t)n, sizeof(fsdem_real));
    s->ux = s->uy = NULL;
    s->ic = pc != FSDEM_PRECOND_NONE ? (fsdem_real *)fsdem__pcg_carve(cv, (size_t)n, sizeof(fsdem_real)) : NULL;
    s->dot_part = (double *)fsdem__pcg_carve(cv, fsdem__dot_blocks(n), sizeof(double));
    s->u_start = s->u_col = s->u_pos = NULL;
    s->u_val = NULL;
    if (pc == FSDEM_PRECOND_IC0 || pc == FSDEM_PRECOND_MIC0) {
        s->u_start = (int *)fsdem__pcg_carve(cv, (size_t)n + 1, sizeof(int));
        s->u_pos = (int *)fsdem__pcg_carve(cv, (size_t)n, sizeof(int));
        s->u_col = (int *)fsdem__pcg_carve(cv, (size_t)upper, sizeof(int));
        s->u_val = (fsdem_real *)fsdem__pcg_carve(cv, (size_t)upper, sizeof(fsdem_real));
    }
}

/* fsdem_pcg_setup_csr for a matrix valid by construction (a solver's own assembly, whose tests
   check it with fsdem_csr_check): the check took about 5 % of an MPS step (perf). */
static fsdem_result fsdem__pcg_setup_csr_valid(fsdem_pcg *s, const fsdem_csr *m) {
    fsdem__amg *amg = NULL;
    fsdem__pcg_carver cv;
    fsdem_precond pc;
    fsdem_result res;
    int i, e, upper = 0;
    pc = s->desc.preconditioner == FSDEM_PRECOND_AUTO ? FSDEM_PRECOND_MIC0 : s->desc.preconditioner;
    if (pc == FSDEM_PRECOND_MG)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pcg_setup_csr: FSDEM_PRECOND_MG needs a stencil operator (fsdem_pcg_setup_stencil); use "
                           "FSDEM_PRECOND_MIC0 for a CSR matrix");
    for (i = 0; i < m->rows; ++i)
        for (e = m->row_start[i]; e < m->row_start[i + 1]; ++e)
            if (m->col[e] >= i) upper++;
    if (pc == FSDEM_PRECOND_AMG && (res = fsdem__amg_build(&s->allocator, &s->desc, m, &amg)) != FSDEM_OK)
        return fsdem__fail(&s->status, res,
                           res == FSDEM_ERR_INVALID_ARG ? "fsdem_pcg_setup_csr: the matrix of %d rows is not positive definite (a diagonal "
                                                          "entry of it or of a coarse AMG level is not positive)"
                                                        : "fsdem_pcg_setup_csr: out of memory building the AMG hierarchy of %d rows",
                           m->rows);
    {
        fsdem_pcg probe = *s;
        cv.base = NULL;
        cv.used = 0;
        cv.overflow = 0;
        fsdem__csr_carve(&probe, &cv, m->rows, upper, pc);
    }
    res = cv.overflow ? FSDEM_ERR_OUT_OF_MEMORY : fsdem__pcg_reserve(s, cv.used);
    if (res != FSDEM_OK) {
        fsdem__amg_free(&s->allocator, amg);
        return fsdem__fail(&s->status, res, "fsdem_pcg_setup_csr: out of memory for %.0f bytes of workspace", (double)cv.used);
    }
    fsdem__amg_free(&s->allocator, s->amg);
    s->amg = amg;
    s->kind = FSDEM__KIND_NONE;
    cv.base = (char *)s->arena;
    cv.used = 0;
    fsdem__csr_carve(s, &cv, m->rows, upper, pc);
    memset(s->arena, 0, cv.used);
    s->csr = *m;
    s->dim = 0;
    s->levels = 1;
    s->ns_components = s->ns_cells = 0;
    if (pc == FSDEM_PRECOND_JACOBI)
        for (i = 0; i < m->rows; ++i) s->ic[i] = 1 / m->val[fsdem__csr_find(m, i, i)];
    if (pc == FSDEM_PRECOND_IC0 || pc == FSDEM_PRECOND_MIC0)
        fsdem__csr_ic_build(s, pc == FSDEM_PRECOND_MIC0 ? s->desc.mic_tau : 0);
    s->precond = pc;
    s->length = s->user_length = m->rows;
    s->kind = FSDEM__KIND_CSR;
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_pcg_setup_csr(fsdem_pcg *s, const fsdem_csr *m) {
    char msg[FSDEM__MESSAGE_SIZE];
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (fsdem_csr_check(m, msg, sizeof msg) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s", msg);
    return fsdem__pcg_setup_csr_valid(s, m);
}
