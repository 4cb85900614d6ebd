/* ---- >>linalg_ic : incomplete Cholesky on stencils and CSR matrices ---- */

/* Stencil IC(0)/MIC(0): M = L L^T with L = (pivots) on the diagonal and the matrix off-diagonals
   below it, so only q = 1/sqrt(pivot) is stored. MIC moves tau times the fill that IC(0) drops
   (between the two upper neighbours of a lower neighbour) to the diagonal. */
static void fsdem__stencil_ic_build(fsdem_pcg *s, fsdem_real tau) {
    const fsdem__level *L = &s->level[0];
    int dim = s->dim, i, j, k, a, b;
    int st[3];
    fsdem_real safety = s->desc.ic_safety, *q = s->ic;
    st[0] = 1;
    st[1] = L->sy;
    st[2] = L->sz;
    memset(q, 0, sizeof(fsdem_real) * (size_t)L->count);
    for (k = 0; k < L->n[2]; ++k)
        for (j = 0; j < L->n[1]; ++j)
            for (i = 0; i < L->n[0]; ++i) {
                int c = fsdem__level_index(L, dim, i, j, k);
                fsdem_real e;
                if (FSDEM__TYPE(L->type[c]) != FSDEM_STENCIL_CELL_FLUID || !(L->d[c] > 0)) continue;
                e = L->d[c];
                for (a = 0; a < dim; ++a) {
                    int lo = c - st[a];
                    fsdem_real t = L->w[a][c] * q[lo];
                    e -= t * t;
                    if (tau > 0 && t != 0)
                        for (b = 0; b < dim; ++b)
                            if (b != a) e -= tau * L->w[a][c] * L->w[b][lo + st[b]] * q[lo] * q[lo];
                }
                if (!(e >= safety * L->d[c])) e = L->d[c];
                q[c] = 1 / (fsdem_real)sqrt(e);
            }
}

static void fsdem__stencil_ic_apply(const fsdem_pcg *s, const fsdem_real *r, fsdem_real *z) {
    const fsdem__level *L = &s->level[0];
    const fsdem_real *q = s->ic, *w0 = L->w[0], *w1 = L->w[1], *w2 = L->w[2];
    int i, j, k, sy = L->sy, sz = L->sz, dim = s->dim;
    /* forward: L y = r */
    for (k = 0; k < L->n[2]; ++k)
        for (j = 0; j < L->n[1]; ++j) {
            int c0 = fsdem__level_index(L, dim, 0, j, k);
            for (i = 0; i < L->n[0]; ++i) {
                int c = c0 + i;
                fsdem_real t = r[c] + w0[c] * q[c - 1] * z[c - 1] + w1[c] * q[c - sy] * z[c - sy];
                if (dim == 3) t += w2[c] * q[c - sz] * z[c - sz];
                z[c] = t * q[c];
            }
        }
    /* backward: L^T z = y */
    for (k = L->n[2] - 1; k >= 0; --k)
        for (j = L->n[1] - 1; j >= 0; --j) {
            int c0 = fsdem__level_index(L, dim, 0, j, k);
            for (i = L->n[0] - 1; i >= 0; --i) {
                int c = c0 + i;
                fsdem_real t = w0[c + 1] * z[c + 1] + w1[c + sy] * z[c + sy];
                if (dim == 3) t += w2[c + sz] * z[c + sz];
                z[c] = q[c] * (z[c] + q[c] * t);
            }
        }
}

/* CSR IC(0)/MIC(0), right-looking on the upper factor U (row k of U is column k of L). */
/* The factor of A with its diagonal times (1 + shift); returns 0 when it overflowed. */
static int fsdem__csr_ic_factor(fsdem_pcg *s, fsdem_real tau, fsdem_real shift) {
    const fsdem_csr *m = &s->csr;
    int n = m->rows, i, k, e, f, cnt = 0;
    fsdem_real safety = s->desc.ic_safety;
    fsdem_real *diag0 = s->ic; /* the matrix diagonal, kept for the pivot floor */
    for (i = 0; i < n; ++i) {
        s->u_start[i] = cnt;
        for (e = m->row_start[i]; e < m->row_start[i + 1]; ++e)
            if (m->col[e] >= i) {
                if (m->col[e] == i) diag0[i] = m->val[e] * (1 + shift);
                s->u_col[cnt] = m->col[e];
                s->u_val[cnt++] = m->col[e] == i ? m->val[e] * (1 + shift) : m->val[e];
            }
        s->u_pos[i] = -1;
    }
    s->u_start[n] = cnt;
    for (k = 0; k < n; ++k) {
        int kb = s->u_start[k], ke = s->u_start[k + 1];
        fsdem_real piv = s->u_val[kb], dk;
        if (!(piv >= safety * diag0[k])) piv = diag0[k];
        dk = (fsdem_real)sqrt(piv);
        s->u_val[kb] = dk;
        for (e = kb + 1; e < ke; ++e) s->u_val[e] /= dk;
        for (e = kb + 1; e < ke; ++e) {
            int row = s->u_col[e], rb = s->u_start[row], re = s->u_start[row + 1];
            fsdem_real li = s->u_val[e];
            for (f = rb; f < re; ++f) s->u_pos[s->u_col[f]] = f;
            s->u_val[rb] -= li * li;
            for (f = e + 1; f < ke; ++f) {
                int col = s->u_col[f];
                fsdem_real fill = li * s->u_val[f];
                if (s->u_pos[col] >= 0) s->u_val[s->u_pos[col]] -= fill;
                else if (tau > 0) {
                    s->u_val[rb] -= tau * fill;
                    s->u_val[s->u_start[col]] -= tau * fill;
                }
            }
            for (f = rb; f < re; ++f) s->u_pos[s->u_col[f]] = -1;
        }
    }
    for (e = 0; e < cnt; ++e)
        if (!fsdem__finite(s->u_val[e])) return 0;
    return 1;
}

/* Incomplete Cholesky of a CSR matrix (MIC with tau > 0). A matrix that is positive definite but
   not an M-matrix (positive off-diagonal entries, e.g. normal equations G^T G) can make the
   factor's entries grow until they overflow, the pivot floor notwithstanding (MIC(0) on the
   normal equations of a least-squares gradient did); then it is refactored with the diagonal
   raised by a shift that grows fourfold from 1e-3 until the factor is finite (Manteuffel 1980,
   Math. Comp. 34:473), as the last resort the diagonal alone (Jacobi). Matrices that factor as they
   are get the factor they always had. */
static void fsdem__csr_ic_build(fsdem_pcg *s, fsdem_real tau) {
    fsdem_real shift = (fsdem_real)1e-3;
    int e, k;
    if (fsdem__csr_ic_factor(s, tau, 0)) return;
    for (; shift < (fsdem_real)1e4; shift *= 4)
        if (fsdem__csr_ic_factor(s, tau, shift)) return;
    for (k = 0; k < s->csr.rows; ++k) /* Jacobi in the factor's form: U = diag^(1/2) (diagonal first) */
        for (e = s->u_start[k]; e < s->u_start[k + 1]; ++e) s->u_val[e] = e == s->u_start[k] ? (fsdem_real)sqrt((double)s->ic[k]) : 0;
}

static void fsdem__csr_ic_apply(const fsdem_pcg *s, const fsdem_real *r, fsdem_real *z) {
    int n = s->csr.rows, k, e;
    if (z != r) memcpy(z, r, sizeof(fsdem_real) * (size_t)n);
    for (k = 0; k < n; ++k) { /* U^T y = r */
        int kb = s->u_start[k], ke = s->u_start[k + 1];
        fsdem_real y = z[k] / s->u_val[kb];
        z[k] = y;
        for (e = kb + 1; e < ke; ++e) z[s->u_col[e]] -= s->u_val[e] * y;
    }
    for (k = n - 1; k >= 0; --k) { /* U z = y */
        int kb = s->u_start[k], ke = s->u_start[k + 1];
        fsdem_real t = z[k];
        for (e = kb + 1; e < ke; ++e) t -= s->u_val[e] * z[s->u_col[e]];
        z[k] = t / s->u_val[kb];
    }
}
