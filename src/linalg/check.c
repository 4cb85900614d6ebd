/* ---- >>linalg_check : validation of operators ---- */

/* threaded: inside a team as on one thread: reads the stencil only. */
static fsdem_real fsdem__stencil_face(const fsdem_stencil *st, int axis, int i, int j, int k) {
    const fsdem_real *f = st->face[axis];
    int n0 = st->n[0], n1 = st->n[1];
    if (!f) return 1;
    if (axis == 0) return f[((size_t)k * n1 + j) * (size_t)(n0 + 1) + i];
    if (axis == 1) return f[((size_t)k * (n1 + 1) + j) * (size_t)n0 + i];
    return f[((size_t)k * n1 + j) * (size_t)n0 + i];
}

/* threaded: inside a team as on one thread: reads the stencil only. */
static int fsdem__stencil_type(const fsdem_stencil *st, int i, int j, int k) {
    if (!st->cell) return FSDEM_STENCIL_CELL_FLUID;
    return st->cell[((size_t)k * st->n[1] + j) * (size_t)st->n[0] + i];
}

/* Padded cell count of a stencil (as a double: it may not fit an int). */
static double fsdem__stencil_padded(const fsdem_stencil *st) {
    return ((double)st->n[0] + 2) * ((double)st->n[1] + 2) * (st->dim == 3 ? (double)st->n[2] + 2 : 1);
}

/* Indices are ints; the multigrid levels add up to 8/7 of the finest. */
#define FSDEM__MAX_PADDED (2147483647.0 / 2)

/* Cells per axis with n[2] = 1 in 2D. */
static void fsdem__stencil_dims(const fsdem_stencil *st, int n[3]) {
    n[0] = st->n[0];
    n[1] = st->n[1];
    n[2] = st->dim == 3 ? st->n[2] : 1;
}

fsdem_result fsdem_stencil_check(const fsdem_stencil *st, char *msg, size_t size) {
    int n[3], i, j, k, a;
    double padded;
    if (!st) return fsdem__reject(msg, size, "fsdem_stencil is NULL");
    if (st->dim != 2 && st->dim != 3)
        return fsdem__reject(msg, size, "fsdem_stencil.dim must be 2 or 3 (got %d)", st->dim);
    fsdem__stencil_dims(st, n);
    for (a = 0; a < st->dim; ++a)
        if (n[a] < 1)
            return fsdem__reject(msg, size, "fsdem_stencil.n[%d] must be >= 1 (got %d)", a, n[a]);
    padded = fsdem__stencil_padded(st);
    if (padded > FSDEM__MAX_PADDED)
        return fsdem__reject(msg, size, "fsdem_stencil: %d x %d x %d cells is too large", n[0], n[1], n[2]);
    for (k = 0; st->cell && k < n[2]; ++k)
        for (j = 0; j < n[1]; ++j)
            for (i = 0; i < n[0]; ++i) {
                int t = fsdem__stencil_type(st, i, j, k);
                if (t > FSDEM_STENCIL_CELL_SOLID)
                    return fsdem__reject(msg, size, "fsdem_stencil.cell of cell (%d,%d,%d) is %d, not a "
                                                    "fsdem_stencil_cell", i, j, k, t);
            }
    if (!st->diag && !st->face[0] && !st->face[1] && (st->dim == 2 || !st->face[2])) return FSDEM_OK;
    for (k = 0; k < n[2]; ++k)
        for (j = 0; j < n[1]; ++j)
            for (i = 0; i < n[0]; ++i) {
                if (fsdem__stencil_type(st, i, j, k) != FSDEM_STENCIL_CELL_FLUID) continue;
                if (st->diag) {
                    fsdem_real dv = st->diag[((size_t)k * n[1] + j) * (size_t)n[0] + i];
                    if (!(dv >= 0) || !fsdem__finite(dv))
                        return fsdem__reject(msg, size, "fsdem_stencil.diag of fluid cell (%d,%d,%d) is %g; it "
                                                        "must be finite and >= 0", i, j, k, (double)dv);
                }
                /* both faces of every axis of a fluid cell are read */
                for (a = 0; a < st->dim; ++a) {
                    int side;
                    for (side = 0; side < 2; ++side) {
                        int fi = i + (a == 0 ? side : 0), fj = j + (a == 1 ? side : 0), fk = k + (a == 2 ? side : 0);
                        fsdem_real w = fsdem__stencil_face(st, a, fi, fj, fk);
                        if (!(w >= 0) || !fsdem__finite(w))
                            return fsdem__reject(msg, size, "fsdem_stencil.face[%d] at face (%d,%d,%d) of fluid "
                                                            "cell (%d,%d,%d) is %g; it must be finite and >= 0",
                                                 a, fi, fj, fk, i, j, k, (double)w);
                    }
                }
            }
    return FSDEM_OK;
}

/* Position of column `col` in row `row`, or -1. Columns are ascending. */
static int fsdem__csr_find(const fsdem_csr *m, int row, int col) {
    int lo = m->row_start[row], hi = m->row_start[row + 1] - 1;
    while (lo <= hi) {
        int mid = lo + (hi - lo) / 2;
        if (m->col[mid] == col) return mid;
        if (m->col[mid] < col) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

fsdem_result fsdem_csr_check(const fsdem_csr *m, char *msg, size_t size) {
    int i, e;
    if (!m) return fsdem__reject(msg, size, "fsdem_csr is NULL");
    if (m->rows < 1) return fsdem__reject(msg, size, "fsdem_csr.rows must be >= 1 (got %d)", m->rows);
    if (!m->row_start || !m->col || !m->val)
        return fsdem__reject(msg, size, "fsdem_csr: row_start, col and val must not be NULL");
    if (m->row_start[0] != 0)
        return fsdem__reject(msg, size, "fsdem_csr.row_start[0] must be 0 (got %d)", m->row_start[0]);
    for (i = 0; i < m->rows; ++i)
        if (m->row_start[i + 1] < m->row_start[i])
            return fsdem__reject(msg, size, "fsdem_csr.row_start decreases at row %d", i);
    for (i = 0; i < m->rows; ++i) {
        int has_diag = 0;
        for (e = m->row_start[i]; e < m->row_start[i + 1]; ++e) {
            int c = m->col[e];
            if (c < 0 || c >= m->rows)
                return fsdem__reject(msg, size, "fsdem_csr: column %d of row %d is out of range [0, %d)", c, i,
                                     m->rows);
            if (e > m->row_start[i] && c <= m->col[e - 1])
                return fsdem__reject(msg, size, "fsdem_csr: columns of row %d are not strictly ascending", i);
            if (!fsdem__finite(m->val[e]))
                return fsdem__reject(msg, size, "fsdem_csr: entry (%d,%d) is not finite", i, c);
            if (c == i) {
                has_diag = 1;
                if (!(m->val[e] > 0))
                    return fsdem__reject(msg, size, "fsdem_csr: diagonal entry (%d,%d) = %g is not positive, so the "
                                                    "matrix is not positive definite", i, i, (double)m->val[e]);
            }
        }
        if (!has_diag) return fsdem__reject(msg, size, "fsdem_csr: row %d has no diagonal entry", i);
    }
    for (i = 0; i < m->rows; ++i)
        for (e = m->row_start[i]; e < m->row_start[i + 1]; ++e) {
            int c = m->col[e], t;
            double a, b, scale;
            if (c == i) continue;
            t = fsdem__csr_find(m, c, i);
            if (c < i && t >= 0) continue; /* the pair was compared from row c */
            a = m->val[e];
            b = t >= 0 ? m->val[t] : 0;
            scale = fabs(a) > fabs(b) ? fabs(a) : fabs(b);
            if (fabs(a - b) > FSDEM__SYM_TOL * scale)
                return fsdem__reject(msg, size, "fsdem_csr is not symmetric: entry (%d,%d) = %g but (%d,%d) = %g%s", i,
                                     c, a, c, i, b, t >= 0 ? "" : " (absent)");
        }
    return FSDEM_OK;
}

void fsdem_csr_apply(const fsdem_csr *m, const fsdem_real *x, fsdem_real *y) {
    int i, e;
    for (i = 0; i < m->rows; ++i) {
        fsdem_real s = 0;
        for (e = m->row_start[i]; e < m->row_start[i + 1]; ++e) s += m->val[e] * x[m->col[e]];
        y[i] = s;
    }
}

/* Reference stencil product on caller-layout vectors, written straight from the definition in
   >>linalg (the solver's padded kernels are checked against it in the tests). */
void fsdem_stencil_apply(const fsdem_stencil *st, const fsdem_real *x, fsdem_real *y) {
    int n[3], i, j, k, a, side;
    fsdem__stencil_dims(st, n);
    for (k = 0; k < n[2]; ++k)
        for (j = 0; j < n[1]; ++j)
            for (i = 0; i < n[0]; ++i) {
                size_t c = ((size_t)k * n[1] + j) * (size_t)n[0] + i;
                fsdem_real s = 0;
                if (fsdem__stencil_type(st, i, j, k) != FSDEM_STENCIL_CELL_FLUID) {
                    y[c] = 0;
                    continue;
                }
                for (a = 0; a < st->dim; ++a)
                    for (side = 0; side < 2; ++side) {
                        int nb[3];
                        fsdem_real w;
                        nb[0] = i;
                        nb[1] = j;
                        nb[2] = k;
                        nb[a] += side ? 1 : -1;
                        w = fsdem__stencil_face(st, a, i + (a == 0 ? side : 0), j + (a == 1 ? side : 0),
                                                k + (a == 2 ? side : 0));
                        if (nb[a] < 0 || nb[a] >= n[a]) {
                            s += w * x[c]; /* Dirichlet outside when w > 0 */
                        } else {
                            int t = fsdem__stencil_type(st, nb[0], nb[1], nb[2]);
                            size_t cn = ((size_t)nb[2] * n[1] + nb[1]) * (size_t)n[0] + nb[0];
                            if (t == FSDEM_STENCIL_CELL_FLUID) s += w * (x[c] - x[cn]);
                            else if (t == FSDEM_STENCIL_CELL_AIR) s += w * x[c];
                        }
                    }
                if (st->diag) s += st->diag[c] * x[c];
                y[c] = s;
            }
    if (st->extra) st->extra(st->extra_user, x, y);
}
