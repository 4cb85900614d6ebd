/* ---- >>swe_object : creation, series, state ---- */

static fsdem_real fsdem__swe_limit(int limiter, fsdem_real a, fsdem_real b);

static void fsdem__swe_free_series(fsdem_swe *s, fsdem_real **t, fsdem_real **v, int *n) {
    fsdem__free(&s->allocator, *t, sizeof(fsdem_real) * (size_t)*n);
    fsdem__free(&s->allocator, *v, sizeof(fsdem_real) * (size_t)*n);
    *t = *v = NULL;
    *n = 0;
}

/* Copies a series into freshly allocated arrays (n = 0: none). */
static fsdem_result fsdem__swe_copy_series(fsdem_swe *s, const fsdem_real *t, const fsdem_real *v, int n,
                                           fsdem_real **tout, fsdem_real **vout) {
    *tout = *vout = NULL;
    if (n <= 0) return FSDEM_OK;
    *tout = (fsdem_real *)fsdem__alloc(&s->allocator, sizeof(fsdem_real) * (size_t)n);
    *vout = (fsdem_real *)fsdem__alloc(&s->allocator, sizeof(fsdem_real) * (size_t)n);
    if (!*tout || !*vout) {
        fsdem__free(&s->allocator, *tout, sizeof(fsdem_real) * (size_t)n);
        fsdem__free(&s->allocator, *vout, sizeof(fsdem_real) * (size_t)n);
        *tout = *vout = NULL;
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    memcpy(*tout, t, sizeof(fsdem_real) * (size_t)n);
    memcpy(*vout, v, sizeof(fsdem_real) * (size_t)n);
    return FSDEM_OK;
}

/* Value of a series at time t (linear, held constant outside), or `constant` without a series. */
static fsdem_real fsdem__swe_series_at(const fsdem_real *ts, const fsdem_real *vs, int n, fsdem_real constant,
                                       fsdem_real t) {
    int lo = 0, hi = n - 1;
    if (n <= 0) return constant;
    if (t <= ts[0]) return vs[0];
    if (t >= ts[n - 1]) return vs[n - 1];
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (ts[mid] <= t) lo = mid;
        else hi = mid;
    }
    return vs[lo] + (vs[hi] - vs[lo]) * (t - ts[lo]) / (ts[hi] - ts[lo]);
}

static fsdem_result fsdem__swe_store_boundary(fsdem_swe *s, int side, const fsdem_swe_boundary *b) {
    fsdem_real *t, *v;
    fsdem_result res = fsdem__swe_copy_series(s, b->series_time, b->series_value, b->series_count, &t, &v);
    if (res != FSDEM_OK) return res;
    fsdem__swe_free_series(s, &s->bnd[side].t, &s->bnd[side].v, &s->bnd[side].n);
    s->bnd[side].type = b->type;
    s->bnd[side].value = b->value;
    s->bnd[side].t = t;
    s->bnd[side].v = v;
    s->bnd[side].n = t ? b->series_count : 0;
    return FSDEM_OK;
}

/* Velocity of a cell (0 when dry). */
static void fsdem__swe_velocity(const fsdem_swe *s, int k, fsdem_real *u, fsdem_real *v) {
    fsdem_real h = s->eta[k] - s->bed[k];
    if (h < s->desc.dry_depth) {
        *u = *v = 0;
        return;
    }
    *u = s->qx[k] / h;
    *v = s->qy[k] / h;
}

static int fsdem__swe_is_blocked(const fsdem_swe *s, int k) { return s->blocked && k >= 0 && s->blocked[k]; }

/* Keeps blocked cells dry (after a setter wrote depths). */
static void fsdem__swe_dry_blocked(fsdem_swe *s) {
    int k;
    for (k = 0; s->blocked && k < s->n; ++k)
        if (s->blocked[k]) {
            s->eta[k] = s->bed[k];
            s->qx[k] = s->qy[k] = 0;
        }
}

/* Recomputes the wave-speed bound and the statistics of the current state (after a setter). */
static void fsdem__swe_scan(fsdem_swe *s) {
    int k, wet = 0;
    fsdem_real wave = 0, speed2 = 0, hmax = 0, accel = 0;
    fsdem_real idx = 1 / s->dx, idy = s->dim == 2 ? 1 / s->dy : 0;
    for (k = 0; k < s->n; ++k) {
        fsdem_real h = s->eta[k] - s->bed[k], u, v, c, w;
        if (h > hmax) hmax = h;
        if (h < s->desc.dry_depth) continue;
        fsdem__swe_velocity(s, k, &u, &v);
        c = (fsdem_real)sqrt(s->g * h);
        w = (fsdem_real)fabs(u) * idx + (fsdem_real)fabs(v) * idy + c * (idx + idy);
        if (w > wave) wave = w;
        {
            int i = k % s->nx, j = k / s->nx;
            fsdem_real a = 0;
            if (i > 0 && i < s->nx - 1)
                a += (fsdem_real)fabs(fsdem__swe_limit(0, s->eta[k] - s->eta[k - 1], s->eta[k + 1] - s->eta[k])) * idx * idx;
            if (j > 0 && j < s->ny - 1)
                a += (fsdem_real)fabs(fsdem__swe_limit(0, s->eta[k] - s->eta[k - s->nx], s->eta[k + s->nx] - s->eta[k])) *
                     idy * idy;
            if (s->g * a > accel) accel = s->g * a;
        }
        if (u * u + v * v > speed2) speed2 = u * u + v * v;
        wet++;
    }
    s->max_wave = wave;
    s->max_accel = accel;
    s->max_speed = (fsdem_real)sqrt(speed2);
    s->max_depth = hmax;
    s->wet_cells = wet;
}

/* Reals of one band's work rows (fsdem__swe_work), and of the work headers' room per band. */
#define FSDEM__SWE_WORK_HEAD ((sizeof(fsdem__swe_work) + sizeof(fsdem_real) - 1) / sizeof(fsdem_real))
static size_t fsdem__swe_work_reals(const fsdem_swe *s) {
    const size_t nx = (size_t)s->nx;
    if (s->dim != 2) return 4 * (nx + 2);
    return 3 * 4 * (nx + 2) + (2 * sizeof(fsdem__swe_rowcell) + sizeof(fsdem__swe_sface)) / sizeof(fsdem_real) * nx + 12 * nx;
}

fsdem_result fsdem_swe_create(const fsdem_swe_desc *desc, fsdem_swe **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_allocator al;
    fsdem_swe *s;
    fsdem_result res;
    size_t n, nx, reals;
    int k;
    if (out) *out = NULL;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    res = fsdem_swe_desc_check(desc, msg, sizeof msg);
    s = (fsdem_swe *)fsdem__object_new(res, msg, desc ? desc->log : NULL, desc ? desc->log_user : NULL,
                                       desc ? &desc->allocator : NULL, sizeof *s, "fsdem_swe_create", &res);
    if (!s) return res;
    al = desc->allocator;
    s->desc = *desc;
    s->desc.bed = s->desc.depth = NULL;
    s->allocator = al;
    s->status.log = desc->log;
    s->status.log_user = desc->log_user;
    fsdem__claims_init(&s->claims, "shallow-water solver", fsdem__swe_claimable, 1);
    s->dim = desc->dim;
    s->nx = desc->nx;
    s->ny = desc->ny;
    s->n = desc->nx * desc->ny;
    s->g = -desc->gravity.z;
    s->tiny = desc->dry_depth * (fsdem_real)1e-9;
    s->dx = (desc->x_max - desc->x_min) / (fsdem_real)desc->nx;
    s->dy = desc->dim == 2 ? (desc->y_max - desc->y_min) / (fsdem_real)desc->ny : desc->width;
    s->area = s->dx * s->dy;
    s->rain = desc->rain_rate;
    n = (size_t)s->n;
    nx = (size_t)s->nx;
    s->workers = s->dim == 2 ? fsdem__workers() : 1;
    reals = 6 * n + 2 * nx + 2 * (size_t)s->ny + (size_t)s->workers * (fsdem__swe_work_reals(s) + FSDEM__SWE_WORK_HEAD);
    s->block_bytes = reals * sizeof(fsdem_real);
    s->block = (fsdem_real *)fsdem__alloc(&al, s->block_bytes);
    if (!s->block) {
        fsdem__log_oom(desc->log, desc->log_user, "fsdem_swe_create", s->block_bytes);
        fsdem__free(&al, s, sizeof *s);
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    memset(s->block, 0, s->block_bytes);
    s->work = (fsdem__swe_work *)(void *)s->block; /* first: the block is aligned for its pointers */
    s->eta = s->block + (size_t)s->workers * FSDEM__SWE_WORK_HEAD;
    s->qx = s->eta + n;
    s->qy = s->qx + n;
    s->bed = s->qy + n;
    s->sx = s->bed + n;
    s->sy = s->sx + n;
    s->bterm = s->sy + n;
    {
        fsdem_real *next = s->bterm + 2 * nx + 2 * (size_t)s->ny;
        int w;
        for (w = 0; w < s->workers; ++w) {
            fsdem__swe_work *wk = s->work + w;
            wk->slots = s->dim == 2 ? 3 : 1;
            wk->nx = s->nx;
            wk->prim = next;
            next += (size_t)wk->slots * 4 * (nx + 2);
            if (s->dim == 2) {
                wk->rows = (fsdem__swe_rowcell *)(void *)next;
                wk->south = (fsdem__swe_sface *)(void *)(wk->rows + 2 * nx);
                wk->halo = (fsdem_real *)(void *)(wk->south + nx);
                next = wk->halo + 12 * nx;
            }
        }
    }
    for (k = 0; k < 4; ++k) {
        s->bnd[k].type = FSDEM_SWE_BC_WALL;
        if (k < (s->dim == 2 ? 4 : 2) && fsdem__swe_store_boundary(s, k, &desc->boundary[k]) != FSDEM_OK) {
            fsdem__log_oom(desc->log, desc->log_user, "fsdem_swe_create",
                           2 * sizeof(fsdem_real) * (size_t)desc->boundary[k].series_count);
            fsdem_swe_destroy(s);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
        s->desc.boundary[k].series_time = s->desc.boundary[k].series_value = NULL;
        s->desc.boundary[k].series_count = 0;
    }
    for (k = 0; k < s->n; ++k) {
        s->bed[k] = desc->bed ? desc->bed[k] : 0;
        s->eta[k] = s->bed[k] + (desc->depth ? desc->depth[k] : 0);
    }
    fsdem__swe_scan(s);
    *out = s;
    return FSDEM_OK;
}

void fsdem_swe_destroy(fsdem_swe *s) {
    int k;
    if (!s) return;
    fsdem__series_close(&s->gauges, &s->allocator);
    for (k = 0; k < 4; ++k) fsdem__swe_free_series(s, &s->bnd[k].t, &s->bnd[k].v, &s->bnd[k].n);
    for (k = 0; k < s->src_count; ++k) fsdem__swe_free_series(s, &s->src[k].t, &s->src[k].v, &s->src[k].n);
    fsdem__free(&s->allocator, s->src, sizeof(fsdem__swe_src) * (size_t)s->src_capacity);
    fsdem__free(&s->allocator, s->gauge, 2 * sizeof(fsdem_real) * (size_t)s->gauge_capacity);
    fsdem__free(&s->allocator, s->manning, sizeof(fsdem_real) * (size_t)s->n);
    fsdem__free(&s->allocator, s->blocked, (size_t)s->n);
    fsdem__free(&s->allocator, s->block, s->block_bytes);
    fsdem__free(&s->allocator, s, sizeof *s);
}

const char *fsdem_swe_last_error(const fsdem_swe *s) { return s ? s->status.message : "fsdem_swe is NULL"; }

fsdem_swe_grid fsdem_swe_get_grid(const fsdem_swe *s) {
    fsdem_swe_grid g;
    memset(&g, 0, sizeof g);
    if (!s) return g;
    g.dim = s->dim;
    g.nx = s->nx;
    g.ny = s->ny;
    g.dx = s->dx;
    g.dy = s->dy;
    g.x_min = s->desc.x_min;
    g.y_min = s->dim == 2 ? s->desc.y_min : 0;
    g.cell_area = s->area;
    return g;
}

/* Rejects a per-cell input array: NULL, or its first bad value (beyond +-bound, or < 0 when
   non_negative) named. */
static fsdem_result fsdem__swe_array_check(fsdem_swe *s, const fsdem_real *a, int non_negative, fsdem_real bound, const char *what,
                                           const char *unit) {
    int k;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!a) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: array is NULL", what);
    k = fsdem__swe_first_bad(a, s->n, non_negative, bound);
    if (k >= 0)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: value %d (cell i=%d, j=%d) must be in [%g, %g] %s (got %g %s)", what,
                           k, k % s->nx, k / s->nx, non_negative ? 0.0 : -(double)bound, (double)bound, unit, (double)a[k], unit);
    return FSDEM_OK;
}

fsdem_result fsdem_swe_set_bed(fsdem_swe *s, const fsdem_real *bed) {
    int k;
    if (fsdem__swe_array_check(s, bed, 0, FSDEM_MAX_LENGTH, "fsdem_swe_set_bed", "m") != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < s->n; ++k) {
        fsdem_real h = s->eta[k] - s->bed[k];
        s->bed[k] = bed[k];
        s->eta[k] = bed[k] + h;
    }
    fsdem__swe_scan(s);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_set_depth(fsdem_swe *s, const fsdem_real *depth) {
    int k;
    if (fsdem__swe_array_check(s, depth, 1, FSDEM_MAX_LENGTH, "fsdem_swe_set_depth", "m") != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < s->n; ++k) {
        s->eta[k] = s->bed[k] + depth[k];
        if (depth[k] < s->desc.dry_depth) s->qx[k] = s->qy[k] = 0;
    }
    fsdem__swe_scan(s);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_set_surface(fsdem_swe *s, const fsdem_real *eta) {
    int k;
    if (fsdem__swe_array_check(s, eta, 0, FSDEM_MAX_LENGTH, "fsdem_swe_set_surface", "m") != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < s->n; ++k) {
        s->eta[k] = eta[k] > s->bed[k] ? eta[k] : s->bed[k];
        if (s->eta[k] - s->bed[k] < s->desc.dry_depth) s->qx[k] = s->qy[k] = 0;
    }
    fsdem__swe_scan(s);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_set_velocity(fsdem_swe *s, const fsdem_real *u, const fsdem_real *v) {
    int k;
    if (fsdem__swe_array_check(s, u, 0, FSDEM_MAX_SPEED, "fsdem_swe_set_velocity (u)", "m/s") != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    if (v && s->dim == 2 && fsdem__swe_array_check(s, v, 0, FSDEM_MAX_SPEED, "fsdem_swe_set_velocity (v)", "m/s") != FSDEM_OK)
        return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < s->n; ++k) {
        fsdem_real h = s->eta[k] - s->bed[k];
        int wet = h >= s->desc.dry_depth;
        s->qx[k] = wet ? u[k] * h : 0;
        s->qy[k] = wet && v && s->dim == 2 ? v[k] * h : 0;
    }
    fsdem__swe_scan(s);
    return fsdem__ok(&s->status);
}

static void fsdem__swe_centre(const fsdem_swe *s, int k, fsdem_real *x, fsdem_real *y) {
    *x = s->desc.x_min + ((fsdem_real)(k % s->nx) + (fsdem_real)0.5) * s->dx;
    *y = s->dim == 2 ? s->desc.y_min + ((fsdem_real)(k / s->nx) + (fsdem_real)0.5) * s->dy : 0;
}

fsdem_result fsdem_swe_set_cells(fsdem_swe *s, fsdem_swe_init_fn fn, void *user) {
    int k, pass;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!fn) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_set_cells: fn is NULL");
    /* pass 0 validates everything, pass 1 writes, so a bad cell leaves the state unchanged */
    for (pass = 0; pass < 2; ++pass)
        for (k = 0; k < s->n; ++k) {
            fsdem_swe_cell c;
            fsdem_real x, y;
            fsdem__swe_centre(s, k, &x, &y);
            c.bed = 0;
            c.depth = 0;
            c.eta = 0;
            c.u = c.v = 0;
            fn(user, x, y, &c);
            if (pass == 0) {
                if (!(fabs(c.bed) <= FSDEM_MAX_LENGTH) || !(c.depth >= 0 && c.depth <= FSDEM_MAX_LENGTH) ||
                    !(fabs(c.u) <= FSDEM_MAX_SPEED) || !(fabs(c.v) <= FSDEM_MAX_SPEED))
                    return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                                       "fsdem_swe_set_cells: cell %d (i=%d, j=%d, x=%g, y=%g) has bed %g m, depth %g m, "
                                       "u %g, v %g m/s: bed and depth (>= 0) must be within FSDEM_MAX_LENGTH, the speeds within "
                                       "FSDEM_MAX_SPEED",
                                       k, k % s->nx, k / s->nx, (double)x, (double)y, (double)c.bed, (double)c.depth,
                                       (double)c.u, (double)c.v);
                continue;
            }
            s->bed[k] = c.bed;
            s->eta[k] = c.bed + c.depth;
            if (c.depth >= s->desc.dry_depth) {
                s->qx[k] = c.u * c.depth;
                s->qy[k] = s->dim == 2 ? c.v * c.depth : 0;
            } else {
                s->qx[k] = s->qy[k] = 0;
            }
        }
    fsdem__swe_scan(s);
    return fsdem__ok(&s->status);
}

fsdem_swe_fields fsdem_swe_get_fields(const fsdem_swe *s) {
    fsdem_swe_fields f;
    memset(&f, 0, sizeof f);
    if (!s) return f;
    f.nx = s->nx;
    f.ny = s->ny;
    f.eta = s->eta;
    f.qx = s->qx;
    f.qy = s->qy;
    f.bed = s->bed;
    f.blocked = s->blocked;
    return f;
}

fsdem_claims *fsdem_swe_claims(fsdem_swe *s) { return s ? &s->claims : NULL; }

fsdem_swe_coupling fsdem_swe_get_coupling(fsdem_swe *s) {
    fsdem_swe_coupling c;
    memset(&c, 0, sizeof c);
    if (!s) return c;
    c.nx = s->nx;
    c.ny = s->ny;
    c.source_x = s->sx;
    c.source_y = s->sy;
    s->sources_used = 1; /* the caller may write them from now on */
    return c;
}

fsdem_result fsdem_swe_copy_field(const fsdem_swe *s, fsdem_swe_field field, fsdem_real *out) {
    int k;
    if (!s || !out) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < s->n; ++k) {
        fsdem_real u, v;
        switch (field) {
        case FSDEM_SWE_FIELD_DEPTH: out[k] = s->eta[k] - s->bed[k]; break;
        case FSDEM_SWE_FIELD_ETA: out[k] = s->eta[k]; break;
        case FSDEM_SWE_FIELD_U: fsdem__swe_velocity(s, k, &u, &v); out[k] = u; break;
        case FSDEM_SWE_FIELD_V: fsdem__swe_velocity(s, k, &u, &v); out[k] = v; break;
        case FSDEM_SWE_FIELD_BED: out[k] = s->bed[k]; break;
        case FSDEM_SWE_FIELD_QX: out[k] = s->qx[k]; break;
        case FSDEM_SWE_FIELD_QY: out[k] = s->qy[k]; break;
        default: return FSDEM_ERR_INVALID_ARG;
        }
    }
    return FSDEM_OK;
}

int fsdem_swe_cell_at(const fsdem_swe *s, fsdem_real x, fsdem_real y) {
    fsdem_real fx, fy;
    int i, j;
    if (!s) return -1;
    fx = (x - s->desc.x_min) / s->dx;
    fy = s->dim == 2 ? (y - s->desc.y_min) / s->dy : 0;
    if (!(fx >= 0 && fx <= (fsdem_real)s->nx) || !(fy >= 0 && fy <= (fsdem_real)s->ny)) return -1;
    i = (int)fx;
    j = (int)fy;
    if (i >= s->nx) i = s->nx - 1;
    if (j >= s->ny) j = s->ny - 1;
    return i + s->nx * j;
}

fsdem_result fsdem_swe_sample_state(const fsdem_swe *s, fsdem_real x, fsdem_real y, fsdem_swe_cell *out) {
    fsdem_real fx, fy, wx, wy, w[4], wsum = 0;
    int i0, j0, i1, j1, c[4], q;
    if (!s || !out) return FSDEM_ERR_INVALID_ARG;
    q = fsdem_swe_cell_at(s, x, y);
    if (q < 0 || fsdem__swe_is_blocked(s, q)) return FSDEM_ERR_OUT_OF_DOMAIN;
    /* (bi)linear between the centres around the point, clamped at the outermost centres */
    fx = (x - s->desc.x_min) / s->dx - (fsdem_real)0.5;
    fy = s->dim == 2 ? (y - s->desc.y_min) / s->dy - (fsdem_real)0.5 : 0;
    if (fx < 0) fx = 0;
    if (fy < 0) fy = 0;
    if (fx > (fsdem_real)(s->nx - 1)) fx = (fsdem_real)(s->nx - 1);
    if (fy > (fsdem_real)(s->ny - 1)) fy = (fsdem_real)(s->ny - 1);
    i0 = (int)fx;
    j0 = (int)fy;
    i1 = i0 + 1 < s->nx ? i0 + 1 : i0;
    j1 = j0 + 1 < s->ny ? j0 + 1 : j0;
    wx = fx - (fsdem_real)i0;
    wy = fy - (fsdem_real)j0;
    c[0] = i0 + s->nx * j0;
    c[1] = i1 + s->nx * j0;
    c[2] = i0 + s->nx * j1;
    c[3] = i1 + s->nx * j1;
    w[0] = (1 - wx) * (1 - wy);
    w[1] = wx * (1 - wy);
    w[2] = (1 - wx) * wy;
    w[3] = wx * wy;
    /* never across a wall: blocked cells leave the stencil and the others share their weight */
    for (q = 0; s->blocked && q < 4; ++q) {
        if (s->blocked[c[q]]) w[q] = 0;
        wsum += w[q];
    }
    if (s->blocked)
        for (q = 0; q < 4; ++q) w[q] = wsum > 0 ? w[q] / wsum : (c[q] == fsdem_swe_cell_at(s, x, y));
    out->bed = out->depth = out->u = out->v = 0;
    for (q = 0; q < 4; ++q) {
        fsdem_real u, v;
        if (w[q] == 0) continue;
        fsdem__swe_velocity(s, c[q], &u, &v);
        out->bed += w[q] * s->bed[c[q]];
        out->depth += w[q] * (s->eta[c[q]] - s->bed[c[q]]);
        out->u += w[q] * u;
        out->v += w[q] * v;
    }
    out->eta = out->bed + out->depth;
    return FSDEM_OK;
}

/* The surface slope d eta / d(axis) at (x, y) with c the water there: a central difference over one
   cell, its pair moved inside the outermost cell centres near the edge of the grid (beyond them
   the samples are clamped, flat), one-sided against c when a side lies in a blocked cell. */
static fsdem_real fsdem__swe_surface_slope(const fsdem_swe *s, fsdem_real x, fsdem_real y, int axis, const fsdem_swe_cell *c) {
    const int cells = axis == 0 ? s->nx : s->ny;
    const fsdem_real d = axis == 0 ? s->dx : s->dy, lo_edge = (axis == 0 ? s->desc.x_min : s->desc.y_min) + d,
                     hi_edge = lo_edge + (fsdem_real)(cells - 2) * d;
    fsdem_real at = axis == 0 ? x : y, span = 0;
    fsdem_swe_cell lo, hi;
    if (cells < 2) return 0;
    if (at < lo_edge) at = lo_edge;
    if (at > hi_edge) at = hi_edge;
    if (fsdem_swe_sample_state(s, axis == 0 ? at - d / 2 : x, axis == 0 ? y : at - d / 2, &lo) == FSDEM_OK) span += d / 2;
    else lo = *c;
    if (fsdem_swe_sample_state(s, axis == 0 ? at + d / 2 : x, axis == 0 ? y : at + d / 2, &hi) == FSDEM_OK) span += d / 2;
    else hi = *c;
    return span > 0 ? (hi.eta - lo.eta) / span : 0;
}

fsdem_result fsdem_swe_sample(const fsdem_swe *s, int count, const fsdem_vec3 *points, fsdem_fluid_sample *out) {
    int n;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (count < 0 || (count > 0 && (!points || !out)))
        return fsdem__fail((fsdem__status *)&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_sample: bad count %d or NULL arrays",
                           count);
    for (n = 0; n < count; ++n) {
        const fsdem_vec3 p = points[n];
        const fsdem_real rg = s->desc.density * s->g;
        fsdem_swe_cell c;
        memset(&out[n], 0, sizeof out[n]);
        if (fsdem_swe_sample_state(s, p.x, p.y, &c) != FSDEM_OK || c.depth < s->desc.dry_depth || p.z < c.bed ||
            p.z > c.eta)
            continue;
        out[n].velocity = fsdem_v3(c.u, c.v, 0);
        out[n].volume_fraction = 1;
        /* hydrostatic p = rho g (eta - z) */
        out[n].pressure_gradient.x = rg * fsdem__swe_surface_slope(s, p.x, p.y, 0, &c);
        if (s->dim == 2) out[n].pressure_gradient.y = rg * fsdem__swe_surface_slope(s, p.x, p.y, 1, &c);
        out[n].pressure_gradient.z = -rg;
    }
    return fsdem__ok((fsdem__status *)&s->status);
}

/* Wet cells of the footprint [x - r, x + r] (x [y - r, y + r] in 2D; grown by `grown` cells) with
   their overlap weights (grown: 1 each): pass 0 sums the weights, pass 1 adds `scale` x weight x
   (fx, fy) to the sources. Returns the sum. */
static fsdem_real fsdem__swe_footprint(fsdem_swe *s, fsdem_vec3 p, fsdem_real r, int grown, int pass, fsdem_real scale,
                                       fsdem_vec3 f) {
    const fsdem_real dry = s->desc.dry_depth;
    int lo[2], hi[2], i, j;
    fsdem_real total = 0;
    lo[0] = (int)floor((p.x - r - s->desc.x_min) / s->dx) - grown;
    hi[0] = (int)floor((p.x + r - s->desc.x_min) / s->dx) + grown;
    lo[1] = s->dim == 2 ? (int)floor((p.y - r - s->desc.y_min) / s->dy) - grown : 0;
    hi[1] = s->dim == 2 ? (int)floor((p.y + r - s->desc.y_min) / s->dy) + grown : 0;
    lo[0] = lo[0] < 0 ? 0 : lo[0];
    hi[0] = hi[0] >= s->nx ? s->nx - 1 : hi[0];
    lo[1] = lo[1] < 0 ? 0 : lo[1];
    hi[1] = hi[1] >= s->ny ? s->ny - 1 : hi[1];
    for (j = lo[1]; j <= hi[1]; ++j)
        for (i = lo[0]; i <= hi[0]; ++i) {
            const int k = i + s->nx * j;
            fsdem_real w = 1;
            if (!grown && r > 0) {
                fsdem_real xa = s->desc.x_min + (fsdem_real)i * s->dx;
                w = (p.x + r < xa + s->dx ? p.x + r : xa + s->dx) - (p.x - r > xa ? p.x - r : xa);
                if (s->dim == 2) {
                    fsdem_real ya = s->desc.y_min + (fsdem_real)j * s->dy;
                    w *= (p.y + r < ya + s->dy ? p.y + r : ya + s->dy) - (p.y - r > ya ? p.y - r : ya);
                }
            }
            if (!(w > 0) || s->eta[k] - s->bed[k] < dry) continue;
            total += w;
            if (pass) {
                s->sx[k] += f.x * scale * w;
                if (s->dim == 2) s->sy[k] += f.y * scale * w;
            }
        }
    return total;
}

fsdem_result fsdem_swe_add_force(fsdem_swe *s, fsdem_vec3 point, fsdem_real radius, fsdem_vec3 force, int *taken) {
    fsdem_real total = 0;
    int grown;
    if (taken) *taken = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!fsdem__finite3(point) || !fsdem__finite3(force) || !(radius >= 0) || !fsdem__finite(radius))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_add_force: point, force and radius >= 0 must be finite");
    {
        /* more than would accelerate all the water the grid can hold (FSDEM_MAX_LENGTH deep) at
           FSDEM_MAX_ACCELERATION */
        const fsdem_real most = s->desc.density * FSDEM_MAX_ACCELERATION * (fsdem_real)s->n * s->area * FSDEM_MAX_LENGTH;
        if (!fsdem__within(force, most))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                               "fsdem_swe_add_force: the force (%g, %g) N would accelerate the deepest water the grid can hold at "
                               "more than FSDEM_MAX_ACCELERATION (|F| <= %g N)",
                               (double)force.x, (double)force.y, (double)most);
    }
    if (fsdem_swe_cell_at(s, point.x, point.y) < 0)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_DOMAIN, "fsdem_swe_add_force: point (%g, %g) is outside the grid",
                           (double)point.x, (double)point.y);
    /* a force felt at a wet/dry edge (water sampled from a neighbouring cell while the footprint is
       dry) goes to the wet cells one cell around, so momentum is exchanged, never created */
    for (grown = 0; grown < 2 && total == 0; ++grown) total = fsdem__swe_footprint(s, point, radius, grown, 0, 0, force);
    if (total > 0) {
        fsdem__swe_footprint(s, point, radius, grown - 1, 1, 1 / (total * s->desc.density * s->area), force);
        s->sources_used = 1;
        if (taken) *taken = 1;
    }
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_clear_forces(fsdem_swe *s) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    memset(s->sx, 0, sizeof(fsdem_real) * (size_t)s->n);
    memset(s->sy, 0, sizeof(fsdem_real) * (size_t)s->n);
    return fsdem__ok(&s->status);
}
