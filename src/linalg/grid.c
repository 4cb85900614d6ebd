/* ---- >>linalg_grid : padded MAC-grid levels ---- */

static void fsdem__level_geometry(fsdem__level *L, int dim, const int n[3]) {
    L->n[0] = n[0];
    L->n[1] = n[1];
    L->n[2] = dim == 3 ? n[2] : 1;
    L->sy = n[0] + 2;
    L->sz = L->sy * (n[1] + 2);
    L->count = dim == 3 ? L->sz * (L->n[2] + 2) : L->sz;
}

/* threaded: inside a team as on one thread: pure. */
static int fsdem__level_index(const fsdem__level *L, int dim, int i, int j, int k) {
    return (i + 1) + (j + 1) * L->sy + (dim == 3 ? (k + 1) * L->sz : 0);
}

/* Geometry of every level the multigrid may need (coarsening to one cell). Returns the count. */
static int fsdem__mg_plan(fsdem__level *lv, int dim, const int n0[3]) {
    int n[3], count = 0, a;
    n[0] = n0[0];
    n[1] = n0[1];
    n[2] = dim == 3 ? n0[2] : 1;
    for (a = 0; a < 3; ++a) {
        lv[0].ratio[a] = 1;
        lv[0].h[a] = 1;
    }
    for (;;) {
        fsdem__level_geometry(&lv[count], dim, n);
        ++count;
        if ((n[0] == 1 && n[1] == 1 && n[2] == 1) || count == FSDEM__MG_MAX_LEVELS) break;
        for (a = 0; a < 3; ++a) {
            lv[count].ratio[a] = n[a] > 1 ? 2 : 1;
            lv[count].h[a] = lv[count - 1].h[a] * (fsdem_real)lv[count].ratio[a];
            n[a] = n[a] > 1 ? (n[a] + 1) / 2 : 1;
        }
    }
    return count;
}

/* Ghost types from the boundary faces: a ghost is AIR (Dirichlet) when a boundary face between it
   and the nearest interior cell has a positive coefficient, else SOLID. */
static void fsdem__level_ghosts(fsdem__level *L, int dim) {
    int i, j, k, a;
    int lo[3], hi[3];
    for (a = 0; a < 3; ++a) {
        lo[a] = (a < dim) ? -1 : 0;
        hi[a] = (a < dim) ? L->n[a] : 0;
    }
    for (k = lo[2]; k <= hi[2]; ++k)
        for (j = lo[1]; j <= hi[1]; ++j)
            for (i = lo[0]; i <= hi[0]; ++i) {
                int g[3], c[3] = {0, 0, 0}, ghost = 0, air = 0, ci;
                g[0] = i;
                g[1] = j;
                g[2] = k;
                for (a = 0; a < dim; ++a) {
                    c[a] = g[a] < 0 ? 0 : g[a] >= L->n[a] ? L->n[a] - 1 : g[a];
                    if (c[a] != g[a]) ghost = 1;
                }
                if (!ghost) continue;
                ci = fsdem__level_index(L, dim, c[0], c[1], c[2]);
                for (a = 0; a < dim; ++a) {
                    int s = a == 0 ? 1 : a == 1 ? L->sy : L->sz;
                    if (g[a] < 0 && L->w[a][ci] > 0) air = 1;
                    if (g[a] >= L->n[a] && L->w[a][ci + s] > 0) air = 1;
                }
                L->type[fsdem__level_index(L, dim, i, j, k)] =
                    (unsigned char)(air ? FSDEM_STENCIL_CELL_AIR : FSDEM_STENCIL_CELL_SOLID);
            }
}

/* Diagonal of a level from its physical face coefficients and the extra diagonal `extra`. */
/* threaded: opens a team over the cells. */
static void fsdem__level_diagonal(fsdem__level *L, int dim, const fsdem_real *extra) {
    int c, a, fluid = 0;
    FSDEM__OMP(parallel for private(a) reduction(+ : fluid) schedule(static)
               num_threads(fsdem__team_for(L->count, FSDEM__DOT_BLOCK, FSDEM__NO_CAP)))
    for (c = 0; c < L->count; ++c) {
        fsdem_real d = 0;
        if (FSDEM__TYPE(L->type[c]) != FSDEM_STENCIL_CELL_FLUID) {
            L->d[c] = L->inv_d[c] = 0;
            continue;
        }
        for (a = 0; a < dim; ++a) {
            int s = a == 0 ? 1 : a == 1 ? L->sy : L->sz;
            d += L->w[a][c] + L->w[a][c + s];
        }
        d += extra[c];
        L->d[c] = d;
        L->inv_d[c] = d > 0 ? 1 / d : 0;
        fluid++;
    }
    L->fluid = fluid;
}

/* Reduces the physical face coefficients of a level to matrix off-diagonals. */
static void fsdem__level_offdiagonal(fsdem__level *L, int dim) {
    int c, a;
    for (a = 0; a < dim; ++a) {
        int s = a == 0 ? 1 : a == 1 ? L->sy : L->sz;
        fsdem_real *w = L->w[a];
        for (c = 0; c < L->count; ++c)
            if (FSDEM__TYPE(L->type[c]) != FSDEM_STENCIL_CELL_FLUID || c - s < 0 ||
                FSDEM__TYPE(L->type[c - s]) != FSDEM_STENCIL_CELL_FLUID)
                w[c] = 0;
    }
}

/* Level 0 from the caller's stencil: types, physical coefficients, extra diagonal (to `extra`). */
/* threaded: opens teams over the rows. */
static void fsdem__level_from_stencil(fsdem__level *L, const fsdem_stencil *st, fsdem_real *extra) {
    int dim = st->dim, i, j, k, a;
    memset(L->type, FSDEM_STENCIL_CELL_SOLID, (size_t)L->count);
    for (a = 0; a < 3; ++a)
        if (a < dim) memset(L->w[a], 0, sizeof(fsdem_real) * (size_t)L->count);
    memset(extra, 0, sizeof(fsdem_real) * (size_t)L->count);
    FSDEM__OMP(parallel for collapse(2) private(i) schedule(static)
               num_threads(fsdem__team_for(L->count, FSDEM__DOT_BLOCK, FSDEM__NO_CAP)))
    for (k = 0; k < L->n[2]; ++k)
        for (j = 0; j < L->n[1]; ++j)
            for (i = 0; i < L->n[0]; ++i)
                L->type[fsdem__level_index(L, dim, i, j, k)] = (unsigned char)fsdem__stencil_type(st, i, j, k);
    /* Each face once, stored at the cell on its high side; only faces with a fluid side are read. */
    for (a = 0; a < dim; ++a) {
        int s = a == 0 ? 1 : a == 1 ? L->sy : L->sz;
        int ext[3];
        ext[0] = L->n[0];
        ext[1] = L->n[1];
        ext[2] = L->n[2];
        ext[a] += 1;
        FSDEM__OMP(parallel for collapse(2) private(i) schedule(static)
                   num_threads(fsdem__team_for(L->count, FSDEM__DOT_BLOCK, FSDEM__NO_CAP)))
        for (k = 0; k < ext[2]; ++k)
            for (j = 0; j < ext[1]; ++j)
                for (i = 0; i < ext[0]; ++i) {
                    int hi = fsdem__level_index(L, dim, i, j, k);
                    int t_hi = (a == 0 ? i : a == 1 ? j : k) < L->n[a] ? L->type[hi] : -1;
                    int t_lo = (a == 0 ? i : a == 1 ? j : k) > 0 ? L->type[hi - s] : -1;
                    if (t_hi != FSDEM_STENCIL_CELL_FLUID && t_lo != FSDEM_STENCIL_CELL_FLUID) continue;
                    if (t_hi == FSDEM_STENCIL_CELL_SOLID || t_lo == FSDEM_STENCIL_CELL_SOLID) continue;
                    L->w[a][hi] = fsdem__stencil_face(st, a, i, j, k);
                }
    }
    if (st->diag)
        for (k = 0; k < L->n[2]; ++k)
            for (j = 0; j < L->n[1]; ++j)
                for (i = 0; i < L->n[0]; ++i) {
                    int c = fsdem__level_index(L, dim, i, j, k);
                    if (L->type[c] == FSDEM_STENCIL_CELL_FLUID)
                        extra[c] = st->diag[((size_t)k * L->n[1] + j) * (size_t)L->n[0] + i];
                }
    fsdem__level_ghosts(L, dim);
}

/* Coarse level C from fine level F (physical coefficients, extra diagonal `fextra`); writes the
   coarse extra diagonal to `cextra`. */
/* threaded: opens teams over the coarse rows. */
static void fsdem__level_coarsen(const fsdem__level *F, fsdem__level *C, int dim, const fsdem_real *fextra,
                                 fsdem_real *cextra) {
    int I, J, K, a, di, dj, dk;
    int rx = C->ratio[0], ry = C->ratio[1], rz = C->ratio[2];
    memset(C->type, FSDEM_STENCIL_CELL_SOLID, (size_t)C->count);
    memset(cextra, 0, sizeof(fsdem_real) * (size_t)C->count);
    for (a = 0; a < dim; ++a) memset(C->w[a], 0, sizeof(fsdem_real) * (size_t)C->count);
    FSDEM__OMP(parallel for collapse(2) private(I, di, dj, dk) schedule(static)
               num_threads(fsdem__team_for(C->count, FSDEM__DOT_BLOCK, FSDEM__NO_CAP)))
    for (K = 0; K < C->n[2]; ++K)
        for (J = 0; J < C->n[1]; ++J)
            for (I = 0; I < C->n[0]; ++I) {
                int any_air = 0, any_fluid = 0, c = fsdem__level_index(C, dim, I, J, K);
                fsdem_real ex = 0;
                for (dk = 0; dk < rz; ++dk)
                    for (dj = 0; dj < ry; ++dj)
                        for (di = 0; di < rx; ++di) {
                            int i = I * rx + di, j = J * ry + dj, k = K * rz + dk, f, t;
                            if (i >= F->n[0] || j >= F->n[1] || k >= F->n[2]) continue;
                            f = fsdem__level_index(F, dim, i, j, k);
                            t = FSDEM__TYPE(F->type[f]);
                            if (t == FSDEM_STENCIL_CELL_AIR) any_air = 1;
                            if (t == FSDEM_STENCIL_CELL_FLUID) {
                                any_fluid = 1;
                                ex += fextra[f];
                            }
                        }
                C->type[c] = (unsigned char)(any_air ? FSDEM_STENCIL_CELL_AIR
                                             : any_fluid ? FSDEM_STENCIL_CELL_FLUID
                                                         : FSDEM_STENCIL_CELL_SOLID);
                cextra[c] = C->type[c] == FSDEM_STENCIL_CELL_FLUID ? ex : 0;
            }
    /* faces: the sum of the fine sub-faces over the coarsening ratio along the normal */
    for (a = 0; a < dim; ++a) {
        int ext[3], ra = C->ratio[a];
        ext[0] = C->n[0];
        ext[1] = C->n[1];
        ext[2] = C->n[2];
        ext[a] += 1;
        FSDEM__OMP(parallel for collapse(2) private(I) schedule(static)
                   num_threads(fsdem__team_for(C->count, FSDEM__DOT_BLOCK, FSDEM__NO_CAP)))
        for (K = 0; K < ext[2]; ++K)
            for (J = 0; J < ext[1]; ++J)
                for (I = 0; I < ext[0]; ++I) {
                    int lo[3], cnt[3], u, v, wdx;
                    fsdem_real sum = 0;
                    int cc[3];
                    cc[0] = I;
                    cc[1] = J;
                    cc[2] = K;
                    for (u = 0; u < 3; ++u) {
                        if (u == a) {
                            lo[u] = cc[u] * ra > F->n[u] ? F->n[u] : cc[u] * ra;
                            cnt[u] = 1;
                        } else {
                            lo[u] = cc[u] * C->ratio[u];
                            cnt[u] = C->ratio[u];
                        }
                    }
                    for (wdx = 0; wdx < cnt[2]; ++wdx)
                        for (v = 0; v < cnt[1]; ++v)
                            for (u = 0; u < cnt[0]; ++u) {
                                int i = lo[0] + u, j = lo[1] + v, k = lo[2] + wdx;
                                if ((a != 0 && i >= F->n[0]) || (a != 1 && j >= F->n[1]) ||
                                    (a != 2 && k >= F->n[2]))
                                    continue;
                                sum += F->w[a][fsdem__level_index(F, dim, i, j, k)];
                            }
                    /* A boundary face reaches the Dirichlet point of the finest level, half a finest
                       cell beyond the face: scale by the ratio of the centre-to-point distances. */
                    if (cc[a] == 0 || cc[a] == C->n[a]) sum *= (F->h[a] + 1) / (C->h[a] + 1);
                    else sum /= (fsdem_real)ra;
                    C->w[a][fsdem__level_index(C, dim, I, J, K)] = sum;
                }
    }
    fsdem__level_ghosts(C, dim);
}

/* Marks fine fluid cells whose interpolation kernel (from level C) contains a solid cell. */
/* threaded: opens a team over the rows. */
static void fsdem__level_mark_near_solid(fsdem__level *F, const fsdem__level *C, int dim) {
    int i, j, k;
    FSDEM__OMP(parallel for collapse(2) private(i) schedule(static)
               num_threads(fsdem__team_for(F->count, FSDEM__DOT_BLOCK, FSDEM__NO_CAP)))
    for (k = 0; k < F->n[2]; ++k)
        for (j = 0; j < F->n[1]; ++j)
            for (i = 0; i < F->n[0]; ++i) {
                int f = fsdem__level_index(F, dim, i, j, k), near = 0, u, v, w;
                int pc = fsdem__level_index(C, dim, i / C->ratio[0], j / C->ratio[1], k / C->ratio[2]);
                int o[3];
                if (FSDEM__TYPE(F->type[f]) != FSDEM_STENCIL_CELL_FLUID) continue;
                o[0] = C->ratio[0] == 2 ? ((i & 1) ? 1 : -1) : 0;
                o[1] = C->ratio[1] == 2 ? ((j & 1) ? C->sy : -C->sy) : 0;
                o[2] = C->ratio[2] == 2 ? ((k & 1) ? C->sz : -C->sz) : 0;
                for (w = 0; w < 2; ++w)
                    for (v = 0; v < 2; ++v)
                        for (u = 0; u < 2; ++u)
                            if (FSDEM__TYPE(C->type[pc + u * o[0] + v * o[1] + w * o[2]]) == FSDEM_STENCIL_CELL_SOLID)
                                near = 1;
                if (near) F->type[f] |= FSDEM__NEAR_SOLID;
            }
}
