/* ---- >>linalg_kernels : stencil kernels on padded levels ---- */

/* y = A x on slabs [p0, p1) of a level (rows in 2D, planes in 3D; interior cells). */
/* threaded: inside a team: the calling thread's slabs. */
FSDEM__FORCE_INLINE void fsdem__level_apply_slabs(const fsdem__level *L, int dim, const fsdem_real *x, fsdem_real *y, int p0,
                                                  int p1) {
    int i, j, k, sy = L->sy, sz = L->sz;
    const fsdem_real *d = L->d, *w0 = L->w[0], *w1 = L->w[1], *w2 = L->w[2];
    if (dim == 2) {
        for (j = p0; j < p1; ++j) {
            int c0 = (j + 1) * sy + 1;
            for (i = 0; i < L->n[0]; ++i) {
                int c = c0 + i;
                y[c] = d[c] * x[c] - w0[c] * x[c - 1] - w0[c + 1] * x[c + 1] - w1[c] * x[c - sy] -
                       w1[c + sy] * x[c + sy];
            }
        }
        return;
    }
    for (k = p0; k < p1; ++k)
        for (j = 0; j < L->n[1]; ++j) {
            int c0 = (k + 1) * sz + (j + 1) * sy + 1;
            for (i = 0; i < L->n[0]; ++i) {
                int c = c0 + i;
                y[c] = d[c] * x[c] - w0[c] * x[c - 1] - w0[c + 1] * x[c + 1] - w1[c] * x[c - sy] -
                       w1[c + sy] * x[c + sy] - w2[c] * x[c - sz] - w2[c + sz] * x[c + sz];
            }
        }
}

/* y = A x on a level (interior cells; y untouched on ghosts), each thread over its share of slabs. */
/* threaded: opens a team over the slabs. */
static void fsdem__level_apply(const fsdem__level *L, int dim, const fsdem_real *x, fsdem_real *y) {
    const int slabs = dim == 3 ? L->n[2] : L->n[1], team = fsdem__team_for(L->count, FSDEM__DOT_BLOCK, FSDEM__NO_CAP);
    if (team <= 1) {
        fsdem__level_apply_slabs(L, dim, x, y, 0, slabs);
        return;
    }
    FSDEM__OMP(parallel num_threads(team))
    {
        int p0, p1;
        fsdem__share(slabs, &p0, &p1);
        fsdem__level_apply_slabs(L, dim, x, y, p0, p1);
    }
}

/* Gauss-Seidel on the cells of one colour ((i + j + k) % 2 == colour) of row (j, k). With
   `from_zero` the row is treated as if x were 0 before the sweep: cells of this colour get
   b / d and the others 0 (so no clearing pass is needed). */
static void fsdem__mg_smooth_row(const fsdem__level *L, int dim, const fsdem_real *b, fsdem_real *x, int colour, int j,
                              int k, int from_zero) {
    int i, sy = L->sy, sz = L->sz, n0 = L->n[0], c0 = fsdem__level_index(L, dim, 0, j, k);
    int i0 = (j + k + colour) & 1;
    const fsdem_real *inv_d = L->inv_d, *w0 = L->w[0], *w1 = L->w[1], *w2 = L->w[2];
    if (from_zero) {
        for (i = 0; i < n0; ++i) x[c0 + i] = 0;
        for (i = i0; i < n0; i += 2) x[c0 + i] = inv_d[c0 + i] * b[c0 + i];
        return;
    }
    if (dim == 2) {
        for (i = i0; i < n0; i += 2) {
            int c = c0 + i;
            x[c] = inv_d[c] *
                   (b[c] + w0[c] * x[c - 1] + w0[c + 1] * x[c + 1] + w1[c] * x[c - sy] + w1[c + sy] * x[c + sy]);
        }
        return;
    }
    for (i = i0; i < n0; i += 2) {
        int c = c0 + i;
        x[c] = inv_d[c] * (b[c] + w0[c] * x[c - 1] + w0[c + 1] * x[c + 1] + w1[c] * x[c - sy] + w1[c + sy] * x[c + sy] +
                           w2[c] * x[c - sz] + w2[c + sz] * x[c + sz]);
    }
}

/* Interpolation along one axis for fine index i and coarsening ratio r (1 or 2): the parent's
   coarse index *I, the offset *o (index step) to the other coarse cell, and the weights of the
   parent (*a) and of the other cell (*b). */
static void fsdem__mg_axis_weights(int i, int r, int stride, int *I, int *o, fsdem_real *a, fsdem_real *b) {
    if (r == 2) {
        *I = i >> 1;
        *o = (i & 1) ? stride : -stride;
        *a = (fsdem_real)0.75;
        *b = (fsdem_real)0.25;
    } else {
        *I = i;
        *o = 0;
        *a = 1;
        *b = 0;
    }
}

/* 1 / (sum of the interpolation weights of the non-solid coarse cells) for a fine cell whose
   kernel has parent pc, offsets o[] and weights a[], b[]. */
static fsdem_real fsdem__mg_interp_inv_norm(const fsdem__level *C, int pc, const int o[3], const fsdem_real a[3],
                                         const fsdem_real b[3]) {
    fsdem_real norm = 0;
    int u, v, w;
    for (w = 0; w < 2; ++w)
        for (v = 0; v < 2; ++v)
            for (u = 0; u < 2; ++u) {
                fsdem_real wt = (u ? b[0] : a[0]) * (v ? b[1] : a[1]) * (w ? b[2] : a[2]);
                if (wt != 0 && FSDEM__TYPE(C->type[pc + u * o[0] + v * o[1] + w * o[2]]) != FSDEM_STENCIL_CELL_SOLID)
                    norm += wt;
            }
    return norm > 0 ? 1 / norm : 0;
}

static fsdem_real fsdem__mg_interp_inv_norm1(const fsdem__level *C, int pc, int ox, int oy, int oz, fsdem_real ax,
                                          fsdem_real bx, fsdem_real ay, fsdem_real by, fsdem_real az, fsdem_real bz) {
    int o[3];
    fsdem_real a[3], b[3];
    o[0] = ox;
    o[1] = oy;
    o[2] = oz;
    a[0] = ax;
    a[1] = ay;
    a[2] = az;
    b[0] = bx;
    b[1] = by;
    b[2] = bz;
    return fsdem__mg_interp_inv_norm(C, pc, o, a, b);
}

/* P and P^T are tensor products of one-dimensional stencils (3/4 to the parent, 1/4 to the next
   coarse cell on the child's side), times 1/norm on fluid cells next to solids. Both are applied
   row by row: along x through a row buffer, along y and z as axpys between whole rows, which
   vectorises. `buf` holds two rows of the fine level (n[0] + 4 each). */

/* xf += P xc at the fluid cells of row (j, k) of F. */
static void fsdem__mg_prolong_row(const fsdem__level *F, const fsdem__level *C, int dim, const fsdem_real *xc,
                               fsdem_real *xf, int j, int k, fsdem_real *buf) {
    int i, I, J, K, oy, oz, crow, f0, nI = C->n[0];
    fsdem_real ay, by, az, bz, w00, w10, w01, w11;
    fsdem_real *cx = buf + 1; /* coarse row, indices -1 .. nI */
    const fsdem_real *x00, *x10, *x01, *x11;
    const unsigned char *type;
    fsdem__mg_axis_weights(j, C->ratio[1], C->sy, &J, &oy, &ay, &by);
    fsdem__mg_axis_weights(k, C->ratio[2], C->sz, &K, &oz, &az, &bz);
    if (dim == 2) {
        az = 1;
        bz = 0;
        oz = 0;
    }
    crow = fsdem__level_index(C, dim, 0, J, K);
    f0 = fsdem__level_index(F, dim, 0, j, k);
    x00 = xc + crow;
    x10 = x00 + oy;
    x01 = x00 + oz;
    x11 = x00 + oy + oz;
    w00 = ay * az;
    w10 = by * az;
    w01 = ay * bz;
    w11 = by * bz;
    /* y and z: combine up to four coarse rows (ghost ends included; they hold 0) */
    for (I = -1; I <= nI; ++I) cx[I] = w00 * x00[I] + w10 * x10[I] + w01 * x01[I] + w11 * x11[I];
    type = F->type + f0;
    if (C->ratio[0] == 2) {
        const fsdem_real q = (fsdem_real)0.75, e = (fsdem_real)0.25;
        for (i = 0; i < F->n[0]; ++i) {
            unsigned char t = type[i];
            fsdem_real v;
            I = i >> 1;
            v = q * cx[I] + e * cx[(i & 1) ? I + 1 : I - 1];
            if (t == FSDEM_STENCIL_CELL_FLUID) xf[f0 + i] += v;
            else if (FSDEM__TYPE(t) == FSDEM_STENCIL_CELL_FLUID)
                xf[f0 + i] += v * fsdem__mg_interp_inv_norm1(C, crow + I, (i & 1) ? 1 : -1, oy, oz, q, e, ay, by, az, bz);
        }
    } else {
        for (i = 0; i < F->n[0]; ++i) {
            unsigned char t = type[i];
            if (t == FSDEM_STENCIL_CELL_FLUID) xf[f0 + i] += cx[i];
            else if (FSDEM__TYPE(t) == FSDEM_STENCIL_CELL_FLUID)
                xf[f0 + i] += cx[i] * fsdem__mg_interp_inv_norm1(C, crow + i, 0, oy, oz, 1, 0, ay, by, az, bz);
        }
    }
}

/* P^T (b - A x) along x of row (j, k) of F into cr (C->n[0] values), the residual formed on the fly
   in r (n0 + 4 reals). b is 0 off fluid cells on every level, so the residual is too (d and the
   couplings vanish there). */
/* threaded: inside a team: one row of the calling thread's slab. */
static void fsdem__mg_restrict_x(const fsdem__level *F, const fsdem__level *C, int dim, const fsdem_real *b,
                                 const fsdem_real *x, int j, int k, fsdem_real *r, fsdem_real *cr) {
    int i, I, J, K, oy, oz, crow, f0, n0 = F->n[0], nI = C->n[0], sy = F->sy, sz = F->sz;
    fsdem_real ay, by, az, bz;
    const fsdem_real *d, *w0, *w1, *w2, *bb, *xx;
    const unsigned char *type;
    fsdem__mg_axis_weights(j, C->ratio[1], C->sy, &J, &oy, &ay, &by);
    fsdem__mg_axis_weights(k, C->ratio[2], C->sz, &K, &oz, &az, &bz);
    if (dim == 2) {
        az = 1;
        bz = 0;
        oz = 0;
    }
    crow = fsdem__level_index(C, dim, 0, J, K);
    f0 = fsdem__level_index(F, dim, 0, j, k);
    d = F->d + f0;
    w0 = F->w[0] + f0;
    w1 = F->w[1] + f0;
    w2 = F->w[2] + f0;
    bb = b + f0;
    xx = x + f0;
    if (dim == 2)
        for (i = 0; i < n0; ++i)
            r[i] = bb[i] - d[i] * xx[i] + w0[i] * xx[i - 1] + w0[i + 1] * xx[i + 1] + w1[i] * xx[i - sy] +
                   w1[i + sy] * xx[i + sy];
    else
        for (i = 0; i < n0; ++i)
            r[i] = bb[i] - d[i] * xx[i] + w0[i] * xx[i - 1] + w0[i + 1] * xx[i + 1] + w1[i] * xx[i - sy] +
                   w1[i + sy] * xx[i + sy] + w2[i] * xx[i - sz] + w2[i + sz] * xx[i + sz];
    type = F->type + f0;
    for (i = 0; i < n0; ++i)
        if (type[i] & FSDEM__NEAR_SOLID) {
            int ox = C->ratio[0] == 2 ? ((i & 1) ? 1 : -1) : 0;
            fsdem_real ax = C->ratio[0] == 2 ? (fsdem_real)0.75 : 1, bx = C->ratio[0] == 2 ? (fsdem_real)0.25 : 0;
            r[i] *= fsdem__mg_interp_inv_norm1(C, crow + (C->ratio[0] == 2 ? i >> 1 : i), ox, oy, oz, ax, bx, ay, by, az,
                                            bz);
        }
    /* x: coarse I gathers 1/4, 3/4, 3/4, 1/4 from fine 2I-1 .. 2I+2 (zero beyond the row) */
    if (C->ratio[0] == 2) {
        const fsdem_real q = (fsdem_real)0.75, e = (fsdem_real)0.25;
        r[-1] = r[n0] = r[n0 + 1] = 0;
        for (I = 0; I < nI; ++I) cr[I] = e * (r[2 * I - 1] + r[2 * I + 2]) + q * (r[2 * I] + r[2 * I + 1]);
    } else {
        for (I = 0; I < nI; ++I) cr[I] = r[I];
    }
}

/* The coarse rows that fine row (j, k) restricts to: (J, K), its y neighbour on the child's side,
   its z neighbour and their diagonal (targets 0-3), with their weights. */
typedef struct fsdem__mg_targets {
    int row[4], slab[4];
    fsdem_real w[4];
} fsdem__mg_targets;

static fsdem__mg_targets fsdem__mg_targets_of(const fsdem__level *C, int dim, int j, int k) {
    fsdem__mg_targets t;
    int J, K, oy, oz, dy, dz;
    fsdem_real ay, by, az, bz;
    fsdem__mg_axis_weights(j, C->ratio[1], 1, &J, &dy, &ay, &by);
    fsdem__mg_axis_weights(k, C->ratio[2], 1, &K, &dz, &az, &bz);
    if (dim == 2) {
        az = 1;
        bz = 0;
        dz = 0;
    }
    oy = dy * C->sy;
    oz = dz * C->sz;
    t.row[0] = fsdem__level_index(C, dim, 0, J, K);
    t.row[1] = t.row[0] + oy;
    t.row[2] = t.row[0] + oz;
    t.row[3] = t.row[0] + oy + oz;
    /* the slab (a plane in 3D, a row in 2D) each target lies in */
    t.slab[0] = t.slab[1] = dim == 3 ? K : J;
    t.slab[2] = t.slab[3] = dim == 3 ? K + dz : J;
    if (dim == 2) t.slab[1] = t.slab[3] = J + dy;
    t.w[0] = ay * az;
    t.w[1] = by * az;
    t.w[2] = ay * bz;
    t.w[3] = by * bz;
    return t;
}

/* bc += w cr on the targets of t in `mask` (bit q: target q); zero weights are skipped. */
static void fsdem__mg_restrict_add(fsdem_real *bc, const fsdem__mg_targets *t, const fsdem_real *cr, int nI, int mask) {
    int q, I;
    for (q = 0; q < 4; ++q)
        if ((mask >> q & 1) && (q == 0 || t->w[q] != 0)) {
            fsdem_real *c = bc + t->row[q], w = t->w[q];
            for (I = 0; I < nI; ++I) c[I] += w * cr[I];
        }
}

/* bc += P^T (b - A x) over row (j, k) of F (x first, then y and z as axpys between whole rows).
   Coarse ghost and non-fluid entries receive values that fsdem__mg_clean clears. */
static void fsdem__mg_restrict_row(const fsdem__level *F, const fsdem__level *C, int dim, const fsdem_real *b,
                                const fsdem_real *x, fsdem_real *bc, int j, int k, fsdem_real *buf) {
    fsdem_real *cr = buf + F->n[0] + 6;
    const fsdem__mg_targets t = fsdem__mg_targets_of(C, dim, j, k);
    fsdem__mg_restrict_x(F, C, dim, b, x, j, k, buf + 2, cr);
    fsdem__mg_restrict_add(bc, &t, cr, C->n[0], 15);
}

/* Zeroes b on the non-fluid cells (ghosts included) of a level after a restriction. */
static void fsdem__mg_clean(const fsdem__level *L, fsdem_real *b) {
    int c;
    for (c = 0; c < L->count; ++c)
        if (FSDEM__TYPE(L->type[c]) != FSDEM_STENCIL_CELL_FLUID) b[c] = 0;
}
