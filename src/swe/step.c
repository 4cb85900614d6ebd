/* ---- >>swe_step : y faces, repair, stable dt, stepping ---- */

/* y faces between rows j-1 and j (j = 0: the YMIN boundary; j = ny: the YMAX boundary). Cells of row
   j-1 get their north faces and are finished (when `finish`: not a row beside the band); the
   south-face data of row j are stored. */
static void fsdem__swe_yfaces(fsdem_swe *s, fsdem__swe_ctx *c, int j, int finish) {
    const int nx = s->nx, ny = s->ny;
    const fsdem_real g = c->g, ly = c->ly, half = (fsdem_real)0.5;
    fsdem__swe_sface *S = c->w->south;
    const fsdem__swe_rowcell *lo = j > 0 ? fsdem__swe_rowcells(c->w, j - 1) : NULL;
    const fsdem__swe_rowcell *hi = j < ny ? fsdem__swe_rowcells(c->w, j) : NULL;
    fsdem__swe_flux f;
    int i, row = (j - 1) * nx;
    for (i = 0; i < nx; ++i) {
        if (j == 0) {
            const fsdem_real *R = hi[i].s;
            fsdem__swe_boundary_flux(s, FSDEM_SIDE_YMIN, 0, R[0], R[1], R[2], R[3], &f);
            fsdem__swe_bterm_put(c, fsdem__swe_bterm_side(s, 0, i), f.mass * s->dx * c->dt);
        } else if (j == ny) {
            const fsdem_real *L = lo[i].n;
            fsdem__swe_boundary_flux(s, FSDEM_SIDE_YMAX, 1, L[0], L[1], L[2], L[3], &f);
            fsdem__swe_bterm_put(c, fsdem__swe_bterm_side(s, 1, i), -(f.mass * s->dx * c->dt));
        } else if (s->blocked && (s->blocked[row + i] || s->blocked[row + nx + i])) {
            const fsdem_real *L = lo[i].n, *R = hi[i].s;
            if (!s->blocked[row + nx + i]) fsdem__swe_wall_flux(s, 0, R[0], R[1], R[2], R[3], &f);
            else if (!s->blocked[row + i]) fsdem__swe_wall_flux(s, 1, L[0], L[1], L[2], L[3], &f);
            else memset(&f, 0, sizeof f);
        } else {
            const fsdem_real *L = lo[i].n, *R = hi[i].s;
            fsdem__swe_riemann(g, c->tiny, L[0], L[1], L[2], L[3], R[0], R[1], R[2], R[3], &f);
        }
        if (j > 0 && finish) {
            const fsdem__swe_sface *q = S + i;
            fsdem_real de = lo[i].acc[0] - ly * (f.mass - q->mass);
            fsdem_real dqy = lo[i].acc[2] - ly * (f.aL - q->a + half * g * (f.hL + q->h) * (f.eL - q->e));
            fsdem_real dqx = lo[i].acc[1] - ly * (f.tan - q->t);
            fsdem__swe_finish(s, c, row + i, de, dqx, dqy);
        }
        S[i].mass = f.mass;
        S[i].a = f.aR;
        S[i].t = f.tan;
        S[i].h = f.hR;
        S[i].e = f.eR;
    }
}

/* Restores non-negative depths after a step that produced a negative one (not expected with
   cfl <= 0.5; kept as a guarantee): the deficit is taken from the wet neighbours, and what they
   cannot give is counted in vol_clipped. */
static void fsdem__swe_repair(fsdem_swe *s) {
    int k, q;
    for (k = 0; k < s->n; ++k) {
        fsdem_real deficit = s->bed[k] - s->eta[k], avail = 0, take;
        int nb[4], nn = 0, i = k % s->nx, j = k / s->nx;
        if (!(deficit > 0)) continue;
        if (i > 0) nb[nn++] = k - 1;
        if (i < s->nx - 1) nb[nn++] = k + 1;
        if (j > 0) nb[nn++] = k - s->nx;
        if (j < s->ny - 1) nb[nn++] = k + s->nx;
        for (q = 0; q < nn; ++q) {
            fsdem_real hq = s->eta[nb[q]] - s->bed[nb[q]];
            if (hq > 0) avail += hq;
        }
        take = deficit < avail ? deficit : avail;
        for (q = 0; q < nn && take > 0; ++q) {
            fsdem_real hq = s->eta[nb[q]] - s->bed[nb[q]];
            if (hq > 0) s->eta[nb[q]] -= take * hq / avail;
        }
        s->vol_clipped += (deficit - take) * s->area;
        s->eta[k] = s->bed[k];
        s->qx[k] = s->qy[k] = 0;
    }
}

/* Largest (|un| + c)/d of the states outside DISCHARGE and STAGE boundaries (they may move faster than
   the cells). */
static fsdem_real fsdem__swe_boundary_wave(const fsdem_swe *s, fsdem_real t) {
    fsdem_real wave = 0;
    int side, i;
    for (side = 0; side < (s->dim == 2 ? 4 : 2); ++side) {
        const fsdem__swe_bnd *b = &s->bnd[side];
        int count = side < 2 ? s->ny : s->nx;
        fsdem_real value, d = side < 2 ? s->dx : s->dy, sgn = (side & 1) ? 1 : -1;
        if (b->type != FSDEM_SWE_BC_DISCHARGE && b->type != FSDEM_SWE_BC_STAGE) continue;
        value = fsdem__swe_series_at(b->t, b->v, b->n, b->value, t);
        for (i = 0; i < count; ++i) {
            int k = side == 0 ? i * s->nx : side == 1 ? i * s->nx + s->nx - 1 : side == 2 ? i : (s->ny - 1) * s->nx + i;
            fsdem_real h = s->eta[k] - s->bed[k], u, v, un, hb, ub, w;
            fsdem__swe_velocity(s, k, &u, &v);
            if (h < 0) h = 0;
            un = side < 2 ? u : v;
            if (b->type == FSDEM_SWE_BC_DISCHARGE) {
                hb = fsdem__swe_inflow_depth(s->g, value, sgn * un + 2 * (fsdem_real)sqrt(s->g * h));
                ub = hb > 0 ? value / hb : 0;
            } else {
                hb = value > s->bed[k] ? value - s->bed[k] : 0;
                ub = (fsdem_real)fabs(sgn * un + 2 * ((fsdem_real)sqrt(s->g * h) - (fsdem_real)sqrt(s->g * hb)));
            }
            w = (ub + (fsdem_real)sqrt(s->g * hb)) / d;
            if (s->dim == 2) w += (fsdem_real)sqrt(s->g * hb) / (side < 2 ? s->dy : s->dx);
            if (w > wave) wave = w;
        }
    }
    return wave;
}

/* Inverse of the stable step without the cfl factor: max wave rate (1/s) and the viscous rate. */
static fsdem_real fsdem__swe_rate(const fsdem_swe *s) {
    fsdem_real rate = s->max_wave, bw = fsdem__swe_boundary_wave(s, s->time), vr;
    if (bw > rate) rate = bw;
    if (s->desc.eddy_viscosity > 0) {
        vr = 2 * s->desc.eddy_viscosity * (1 / (s->dx * s->dx) + (s->dim == 2 ? 1 / (s->dy * s->dy) : 0));
        if (vr > rate) rate = vr;
    }
    return rate;
}

/* Largest dt with Courant number `cfl` when the velocities may also grow by max_accel dt within the
   step: solves max_accel dt^2 + rate dt = cfl. */
static fsdem_real fsdem__swe_dt_for(const fsdem_swe *s, fsdem_real cfl) {
    fsdem_real rate = fsdem__swe_rate(s), a = s->max_accel, dt = s->desc.dt_max, lim;
    if (rate <= 0 && a <= 0) return dt;
    lim = 2 * cfl / (rate + (fsdem_real)sqrt(rate * rate + 4 * a * cfl));
    return lim < dt ? lim : dt;
}

fsdem_result fsdem_swe_stable_dt(const fsdem_swe *s, fsdem_real *dt) {
    if (!s || !dt) return FSDEM_ERR_INVALID_ARG;
    *dt = fsdem__swe_dt_for(s, s->desc.cfl);
    return FSDEM_OK;
}

/* The gauge values h, eta, u, v of every gauge now (as fsdem_swe_sample_state; 0 where it fails). */
static void fsdem__swe_gauge_values(const void *solver, fsdem_real *out) {
    const fsdem_swe *s = (const fsdem_swe *)solver;
    int k;
    for (k = 0; k < s->gauge_count; ++k) {
        fsdem_swe_cell c;
        memset(&c, 0, sizeof c);
        fsdem_swe_sample_state(s, s->gauge[2 * k], s->gauge[2 * k + 1], &c);
        out[4 * k] = c.depth;
        out[4 * k + 1] = c.eta;
        out[4 * k + 2] = c.u;
        out[4 * k + 3] = c.v;
    }
}

/* Loads state row r into the band's ring: a ghost row below row 0 (r = -1) and above the last
   (r = ny) as the sides want (>>impl_swe item 1). */
static void fsdem__swe_load_ring(const fsdem_swe *s, fsdem__swe_work *w, int r) {
    const int ny = s->ny, wall_lo = s->bnd[FSDEM_SIDE_YMIN].type == FSDEM_SWE_BC_WALL;
    const int wall_hi = s->bnd[FSDEM_SIDE_YMAX].type == FSDEM_SWE_BC_WALL;
    if (r < 0) fsdem__swe_load_row(s, w, 0, -1, wall_lo, !wall_lo && ny > 1 ? 1 : -1);
    else if (r >= ny) fsdem__swe_load_row(s, w, ny - 1, ny, wall_hi, !wall_hi && ny > 1 ? ny - 2 : -1);
    else fsdem__swe_load_row(s, w, r, r, 0, -1);
}

/* Copies the state rows beside band [j0, j1) (j0 - 2, j0 - 1, j1, j1 + 1, where they exist) into its
   halo, so the band reads them as they were before any band wrote. */
/* threaded: inside a team: the calling thread's band. */
static void fsdem__swe_band_halo(const fsdem_swe *s, fsdem__swe_work *w, int j0, int j1) {
    const int rows[4] = {j0 - 2, j0 - 1, j1, j1 + 1};
    const size_t nx = (size_t)s->nx;
    int q;
    for (q = 0; q < 4; ++q) {
        const int r = rows[q];
        fsdem_real *h = w->halo + 3 * q * nx;
        w->halo_row[q] = -1;
        if (r < 0 || r >= s->ny) continue;
        memcpy(h, s->eta + (size_t)r * nx, sizeof(fsdem_real) * nx);
        memcpy(h + nx, s->qx + (size_t)r * nx, sizeof(fsdem_real) * nx);
        memcpy(h + 2 * nx, s->qy + (size_t)r * nx, sizeof(fsdem_real) * nx);
        w->halo_row[q] = r;
    }
}

/* Sweeps rows [j0, j1) of a 2D grid, bottom to top, into c's work rows and tally. The faces with the
   rows beside the band need those rows reconstructed: they are, from the halo, with a copy of the
   context whose tally and boundary volumes are dropped (their own band counts them), and they are
   not finished. Every cell's update is then what one sweep of the whole grid computes. */
/* threaded: inside a team: the calling thread's band of rows. */
static void fsdem__swe_band(fsdem_swe *s, fsdem__swe_ctx *c, int j0, int j1) {
    fsdem__swe_ctx beside = *c;
    int j;
    beside.bterm = NULL;
    if (j0 > 0) fsdem__swe_load_ring(s, c->w, j0 - 2);
    fsdem__swe_load_ring(s, c->w, j0 - 1);
    fsdem__swe_load_ring(s, c->w, j0);
    if (j0 > 0) fsdem__swe_row(s, &beside, j0 - 1);
    for (j = j0; j < j1; ++j) {
        fsdem__swe_load_ring(s, c->w, j + 1);
        fsdem__swe_row(s, c, j);
        fsdem__swe_yfaces(s, c, j, j > j0); /* (row j0 - 1 is the band's below's) */
    }
    if (j1 < s->ny) {
        fsdem__swe_load_ring(s, c->w, j1 + 1);
        fsdem__swe_row(s, &beside, j1);
    }
    fsdem__swe_yfaces(s, c, j1, 1);
}

/* Rows of a band at least (fewer rows would spend more on the rows beside it than on its own). */
#ifndef FSDEM__SWE_BAND_ROWS /* (see FSDEM__DEM_CHUNK) */
#define FSDEM__SWE_BAND_ROWS 8
#endif

/* The 2D sweep: one band of rows per thread (as many as the work rows allow), each band copying the
   rows beside it before any band writes; the tallies are then combined in band order (maxima and
   counts: the same for any split; the first non-finite cell: the lowest band's). */
/* threaded: opens a team of bands of rows. */
static void fsdem__swe_sweep(fsdem_swe *s, fsdem__swe_ctx *c) {
    int bands = fsdem__team_for(s->ny, FSDEM__SWE_BAND_ROWS, s->workers), b;
    FSDEM__OMP(parallel num_threads(bands))
    {
        const int team = fsdem__team(), w = fsdem__worker();
        fsdem__swe_ctx mine = *c;
        {
            int j0, j1;
            fsdem__share(s->ny, &j0, &j1);
            mine.w = s->work + w;
            if (team > 1) fsdem__swe_band_halo(s, mine.w, j0, j1);
            else mine.w->halo_row[0] = mine.w->halo_row[1] = mine.w->halo_row[2] = mine.w->halo_row[3] = -1;
            FSDEM__OMP(barrier)
            fsdem__swe_band(s, &mine, j0, j1);
            mine.w->tally = mine.t;
        }
        if (w == 0) bands = team;
    }
    for (b = 0; b < bands; ++b) {
        const fsdem__swe_tally *t = &s->work[b].tally;
        if (t->wave > c->t.wave) c->t.wave = t->wave;
        if (t->speed2 > c->t.speed2) c->t.speed2 = t->speed2;
        if (t->hmax > c->t.hmax) c->t.hmax = t->hmax;
        if (t->accel > c->t.accel) c->t.accel = t->accel;
        c->t.wet += t->wet;
        c->t.negative |= t->negative;
        c->t.fallbacks += t->fallbacks;
        if (c->t.bad < 0) c->t.bad = t->bad;
    }
}

/* One step of exactly dt (already validated). */
static fsdem_result fsdem__swe_do_step(fsdem_swe *s, fsdem_real dt) {
    fsdem__swe_ctx c;
    int k, side;
    fsdem_real tm = s->time + (fsdem_real)0.5 * dt;
    const double t0 = s->time;
    fsdem__series_begin(&s->gauges);
    memset(&c, 0, sizeof c);
    c.dt = dt;
    c.lx = dt / s->dx;
    c.ly = s->dim == 2 ? dt / s->dy : 0;
    c.idx = 1 / s->dx;
    c.idy = s->dim == 2 ? 1 / s->dy : 0;
    c.g = s->g;
    c.dry = s->desc.dry_depth;
    c.tiny = s->tiny;
    c.rain_dt = s->rain * dt;
    c.manning = s->desc.manning;
    c.visc = s->desc.eddy_viscosity;
    c.order = s->desc.order;
    c.limiter = (int)s->desc.limiter;
    c.two_d = s->dim == 2;
    c.sources = s->sources_used;
    c.friction = s->manning != NULL || s->desc.manning > 0;
    c.t.bad = -1;
    for (side = 0; side < 4; ++side)
        s->bvalue[side] = fsdem__swe_series_at(s->bnd[side].t, s->bnd[side].v, s->bnd[side].n, s->bnd[side].value, tm);
    c.bterm = s->bterm;
    if (!c.two_d) {
        c.w = s->work;
        fsdem__swe_load_row(s, c.w, 0, 0, 0, -1);
        fsdem__swe_row(s, &c, 0);
    } else {
        fsdem__swe_sweep(s, &c);
    }
    {
        fsdem_real bflux = 0;
        for (k = 0; k < (c.two_d ? 2 * (s->nx + s->ny) : 2); ++k) bflux += s->bterm[k];
        s->vol_boundary += bflux;
    }
    s->vol_source += c.rain_dt * s->area * (fsdem_real)(s->n - s->blocked_count);
    for (k = 0; k < s->src_count; ++k) {
        fsdem__swe_src *p = &s->src[k];
        fsdem_real dh, h;
        if (!p->active) continue;
        dh = fsdem__swe_series_at(p->t, p->v, p->n, p->discharge, tm) * dt / s->area;
        h = s->eta[p->cell] - s->bed[p->cell];
        if (dh < -h) dh = h > 0 ? -h : 0;
        s->eta[p->cell] += dh;
        s->vol_source += dh * s->area;
        h += dh;
        if (h < c.dry) s->qx[p->cell] = s->qy[p->cell] = 0;
        else {
            fsdem_real w = (fsdem_real)sqrt(c.g * h) * (c.idx + c.idy) +
                           ((fsdem_real)fabs(s->qx[p->cell]) * c.idx + (fsdem_real)fabs(s->qy[p->cell]) * c.idy) / h;
            if (w > c.t.wave) c.t.wave = w;
        }
    }
    if (c.t.negative) fsdem__swe_repair(s);
    s->fallbacks += c.t.fallbacks;
    s->max_wave = c.t.wave;
    s->max_accel = c.g * c.t.accel;
    s->max_speed = (fsdem_real)sqrt(c.t.speed2);
    s->max_depth = c.t.hmax;
    s->wet_cells = c.t.wet;
    s->time += dt;
    s->dt_last = dt;
    s->steps++;
    if (c.t.bad >= 0)
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_swe_step: non-finite state in cell %d (i=%d, j=%d) at t=%g s",
                           c.t.bad, c.t.bad % s->nx, c.t.bad / s->nx, (double)s->time);
    if (fsdem__series_step(&s->gauges, t0, s->time) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_IO, "fsdem_swe: could not write the gauge file");
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_step(fsdem_swe *s) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__swe_do_step(s, fsdem__swe_dt_for(s, s->desc.cfl));
}

fsdem_result fsdem_swe_check_dt(const fsdem_swe *s, fsdem_real dt) {
    fsdem__status *st;
    fsdem_real courant;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    st = (fsdem__status *)&s->status; /* the message is the object's only mutable part here */
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "fsdem_swe_step_dt: dt must be > 0 (got %g s)", (double)dt);
    courant = dt * fsdem__swe_rate(s) + dt * dt * s->max_accel;
    if (courant > 1)
        return fsdem__fail(st, FSDEM_ERR_CFL, "fsdem_swe_step_dt: dt = %g s gives Courant number %g > 1 (stable dt at cfl 1: %g s)",
                           (double)dt, (double)courant, (double)fsdem__swe_dt_for(s, 1));
    return fsdem__ok(st);
}

fsdem_result fsdem_swe_step_dt(fsdem_swe *s, fsdem_real dt) {
    const fsdem_result res = fsdem_swe_check_dt(s, dt);
    return res == FSDEM_OK ? fsdem__swe_do_step(s, dt) : res;
}

fsdem_result fsdem_swe_advance(fsdem_swe *s, fsdem_real duration, long long *steps) {
    double t_end;
    fsdem_result res = FSDEM_OK;
    long long count = 0;
    if (steps) *steps = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!(duration >= 0) || !fsdem__finite(duration))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_advance: duration must be >= 0 (got %g s)",
                           (double)duration);
    t_end = s->time + (double)duration;
    while (s->time < t_end) {
        fsdem_real dt = fsdem__swe_dt_for(s, s->desc.cfl);
        double left = t_end - s->time;
        int last = (double)dt >= left;
        res = fsdem__swe_do_step(s, last ? (fsdem_real)left : dt);
        count++;
        if (last) s->time = t_end;
        if (res != FSDEM_OK) break;
    }
    if (steps) *steps = count;
    return res;
}

double fsdem_swe_time(const fsdem_swe *s) { return s ? s->time : 0; }

fsdem_swe_desc fsdem_swe_get_desc(const fsdem_swe *s) {
    fsdem_swe_desc d;
    int k;
    if (!s) {
        memset(&d, 0, sizeof d);
        return d;
    }
    d = s->desc;
    d.rain_rate = s->rain;
    for (k = 0; k < 4; ++k) {
        d.boundary[k].type = s->bnd[k].type;
        d.boundary[k].value = s->bnd[k].value;
    }
    return d;
}
