/* ---- >>pic_step : time stepping ---- */

static fsdem_real fsdem__pic_umax(const fsdem_pic *s, int *who) {
    fsdem_real m2 = 0;
    int p, k, w = -1;
    for (p = 0; p < s->np; ++p) {
        fsdem_real v2 = fsdem__dot(s->pv[p], s->pv[p]);
        if (v2 > m2 || v2 != v2) {
            m2 = v2;
            w = p;
            if (v2 != v2) break;
        }
    }
    for (k = 0; k < 2 * s->dim; ++k) {
        fsdem_pic_bc bc = s->desc.boundary[k];
        if (bc == FSDEM_PIC_BC_NO_SLIP || bc == FSDEM_PIC_BC_INFLOW) {
            fsdem_real v2 = fsdem__dot(s->desc.boundary_velocity[k], s->desc.boundary_velocity[k]);
            if (v2 > m2) {
                m2 = v2;
                w = -2 - k;
            }
        }
    }
    if (who) *who = w;
    return (fsdem_real)sqrt(m2);
}

static fsdem_real fsdem__pic_dt_from(const fsdem_pic *s, fsdem_real umax) {
    fsdem_real speed = umax + (fsdem_real)sqrt(s->gmag * s->dx), dt = s->desc.dt_max;
    if (speed > 0 && s->desc.cfl * s->dx / speed < dt) dt = s->desc.cfl * s->dx / speed;
    return dt;
}

fsdem_result fsdem_pic_stable_dt(const fsdem_pic *s, fsdem_real *dt) {
    int who;
    fsdem_real umax;
    if (!s || !dt) return FSDEM_ERR_INVALID_ARG;
    umax = fsdem__pic_umax(s, &who);
    if (!fsdem__finite(umax))
        return fsdem__fail((fsdem__status *)&s->status, FSDEM_ERR_NAN, "fsdem_pic_stable_dt: particle %d has a non-finite velocity",
                           who);
    *dt = fsdem__pic_dt_from(s, umax);
    return fsdem__ok((fsdem__status *)&s->status);
}

double fsdem_pic_time(const fsdem_pic *s) { return s ? s->time : 0; }

fsdem_pic_desc fsdem_pic_get_desc(const fsdem_pic *s) {
    fsdem_pic_desc d;
    if (!s) {
        memset(&d, 0, sizeof d);
        return d;
    }
    d = s->desc;
    d.domain_max = s->hi;
    if (s->dim == 2) d.domain_max.z = d.domain_min.z;
    return d;
}

static fsdem_result fsdem__pic_do_step(fsdem_pic *s, fsdem_real dt) {
    fsdem_result r, worst = FSDEM_OK;
    int a, f, bad, layers = fsdem__pic_layers(s);
    fsdem_real umax = 0;
    clock_t t0 = clock();
    const double time0 = s->time;
    fsdem__ok(&s->status);
    fsdem__series_begin(&s->gauges.series);

    /* 1. particles to grid, cells, extrapolation, FLIP reference */
    fsdem__pic_effective_faces(s);
    if (!s->cells_fresh) fsdem__pic_fraction(s);
    fsdem__pic_types(s);
    fsdem__pic_p2g(s);
    fsdem__pic_extrapolate(s, s->u, layers);
    fsdem__pic_solid_faces(s, s->u, 1);
    for (a = 0; a < s->dim; ++a) memcpy(s->uold[a], s->u[a], sizeof(fsdem_real) * (size_t)s->nface[a]);

    /* 2. implicit viscosity, then body forces and coupler accelerations: in that order water at
       rest under gravity is not sheared against solids (the viscous solve would otherwise act on
       g dt, which the projection removes, and leave a spurious force on every wall and body) */
    if (s->desc.viscosity > 0) {
        r = fsdem__pic_viscosity(s, dt);
        if (r != FSDEM_OK && worst == FSDEM_OK) worst = r;
    }
    for (a = 0; a < s->dim; ++a) {
        fsdem_real g = fsdem__comp(s->desc.gravity, a) * dt;
        for (f = 0; f < s->nface[a]; ++f) s->u[a][f] += g + dt * s->cacc[a][f] / s->fpor[a][f];
    }

    /* 3. pressure projection */
    r = fsdem__pic_project(s, dt);
    if (r != FSDEM_OK && worst == FSDEM_OK) worst = r;
    for (a = 0; a < s->dim; ++a)
        for (f = 0; f < s->nface[a]; ++f)
            if (s->fvalid[a][f] && (fsdem_real)fabs(s->u[a][f]) > umax) umax = (fsdem_real)fabs(s->u[a][f]);
    fsdem__pic_extrapolate(s, s->u, layers);
    fsdem__pic_solid_faces(s, s->u, 0);

    /* 4. grid to particles */
    for (a = 0; a < s->dim; ++a)
        for (f = 0; f < s->nface[a]; ++f) s->uold[a][f] = s->u[a][f] - s->uold[a][f];
    bad = fsdem__pic_g2p(s);

    /* 5. advection, solids and outflow, density projection */
    fsdem__pic_advect(s, dt);
    if (fsdem__pic_constrain(s)) {
        int before = s->np;
        fsdem__pic_remove_marked(s);
        s->removed += before - s->np;
    }
    if (s->desc.density_projection) {
        fsdem__pic_fraction(s);
        fsdem__pic_types(s);
        r = fsdem__pic_density_projection(s);
        if (r != FSDEM_OK && worst == FSDEM_OK)
            worst = fsdem__fail(&s->status, r, "fsdem_pic: density projection failed: %s", fsdem_pcg_last_error(s->pcg_p));
        if (fsdem__pic_constrain(s)) {
            int before = s->np;
            fsdem__pic_remove_marked(s);
            s->removed += before - s->np;
        }
    }

    /* 6. reseeding, cell order, cells of the final positions (for diagnostics) */
    fsdem__pic_fraction(s);
    fsdem__pic_types(s);
    if (fsdem__pic_reseed(s)) {
        fsdem__pic_fraction(s);
        fsdem__pic_types(s);
    }
    if ((s->steps & 7) == 0) fsdem__pic_sort(s);
    s->cells_fresh = 1;

    s->time += dt;
    s->dt_last = dt;
    s->steps++;
    s->sec_total += (double)(clock() - t0) / CLOCKS_PER_SEC;
    if (bad >= 0 && worst == FSDEM_OK)
        worst = fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pic: step %lld: particle %d has a non-finite velocity", s->steps, bad);
    if (worst == FSDEM_OK && umax * dt * s->inv_dx > s->desc.cfl_max)
        worst = fsdem__fail(&s->status, FSDEM_ERR_CFL,
                            "fsdem_pic: step %lld: the projected grid velocity %g m/s moves %g cells in dt = %g s (cfl_max %g)",
                            s->steps, (double)umax, (double)(umax * dt * s->inv_dx), (double)dt, (double)s->desc.cfl_max);
    if (worst == FSDEM_OK && fsdem__series_step(&s->gauges.series, time0, s->time) != FSDEM_OK)
        worst = fsdem__fail(&s->status, FSDEM_ERR_IO, "fsdem_pic: could not write the gauge file");
    return worst;
}

/* FSDEM_OK when every coupler porosity is in (0, 1], else the refusal naming the first cell that
   is not (a step would divide by it). */
static fsdem_result fsdem__pic_check_porosity(const fsdem_pic *s, const char *who) {
    int c;
    for (c = 0; c < s->ncell; ++c)
        if (!(s->cpor[c] > 0 && s->cpor[c] <= 1))
            return fsdem__fail((fsdem__status *)&s->status, FSDEM_ERR_INVALID_ARG,
                               "%s: fsdem_pic_coupling.porosity of cell %d is %g, not in (0, 1]", who, c, (double)s->cpor[c]);
    return FSDEM_OK;
}

fsdem_result fsdem_pic_check_dt(const fsdem_pic *s, fsdem_real dt) {
    fsdem__status *st;
    int who;
    fsdem_real umax, speed, cfl;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (fsdem__pic_check_porosity(s, "fsdem_pic_step_dt") != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    st = (fsdem__status *)&s->status; /* the message is the object's only mutable part here */
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "fsdem_pic_step_dt: dt = %g s must be > 0 and finite", (double)dt);
    umax = fsdem__pic_umax(s, &who);
    if (!fsdem__finite(umax))
        return fsdem__fail(st, FSDEM_ERR_NAN, "fsdem_pic: particle %d has a non-finite velocity", who);
    speed = umax + (fsdem_real)sqrt(s->gmag * s->dx); /* the stable rule's speed: gravity waves too */
    cfl = speed * dt * s->inv_dx;
    if (cfl > s->desc.cfl_max) {
        char fastest[96];
        if (who >= 0) snprintf(fastest, sizeof fastest, "particle %d at %g m/s", who, (double)umax);
        else if (who < -1) snprintf(fastest, sizeof fastest, "%s side velocity %g m/s", fsdem__pic_side_name(-2 - who), (double)umax);
        else snprintf(fastest, sizeof fastest, "still liquid");
        return fsdem__fail(st, FSDEM_ERR_CFL, "fsdem_pic_step_dt: dt = %g s gives CFL %g > cfl_max %g (%s, and sqrt(|g| dx) = %g m/s; dt <= %g s)",
                           (double)dt, (double)cfl, (double)s->desc.cfl_max, fastest, sqrt((double)(s->gmag * s->dx)),
                           (double)(s->desc.cfl_max * s->dx / speed));
    }
    return fsdem__ok(st);
}

fsdem_result fsdem_pic_step_dt(fsdem_pic *s, fsdem_real dt) {
    const fsdem_result res = fsdem_pic_check_dt(s, dt);
    return res == FSDEM_OK ? fsdem__pic_do_step(s, dt) : res;
}

fsdem_result fsdem_pic_step(fsdem_pic *s) {
    int who;
    fsdem_real umax;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (fsdem__pic_check_porosity(s, "fsdem_pic_step") != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    umax = fsdem__pic_umax(s, &who);
    if (!fsdem__finite(umax))
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pic: particle %d has a non-finite velocity", who);
    return fsdem__pic_do_step(s, fsdem__pic_dt_from(s, umax));
}

fsdem_result fsdem_pic_advance(fsdem_pic *s, fsdem_real duration, long long *steps) {
    double end;
    long long n = 0;
    fsdem_result r = FSDEM_OK;
    if (steps) *steps = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!(duration >= 0) || !fsdem__finite(duration))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_advance: duration = %g s must be >= 0", (double)duration);
    if (fsdem__pic_check_porosity(s, "fsdem_pic_advance") != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    end = s->time + (double)duration;
    while (s->time < end - 1e-12 * (end > 1 ? end : 1)) {
        int who;
        fsdem_real umax = fsdem__pic_umax(s, &who), dt;
        if (!fsdem__finite(umax)) {
            r = fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pic_advance: particle %d has a non-finite velocity", who);
            break;
        }
        dt = fsdem__pic_dt_from(s, umax);
        if (s->time + dt > end) dt = (fsdem_real)(end - s->time);
        else if (s->time + 1.5 * dt > end) dt = (fsdem_real)((end - s->time) / 2);
        r = fsdem__pic_do_step(s, dt);
        ++n;
        if (r != FSDEM_OK) break;
    }
    if (steps) *steps = n;
    return r;
}
