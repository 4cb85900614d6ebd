/* ---- >>dem_integrate : time integration ---- */

static fsdem_vec3 fsdem__dem_accel(const fsdem_dem *d, const fsdem_vec3 *f, int i) {
    return fsdem__madd(d->desc.gravity, fsdem__add(f[i], d->fext[i]), d->inv_m[i]);
}

static fsdem_vec3 fsdem__dem_spin_rate(const fsdem_dem *d, const fsdem_vec3 *t, int i) {
    return d->desc.rotation ? fsdem__scale(fsdem__add(t[i], d->text[i]), d->inv_i[i]) : fsdem__zero3();
}

/* One pass of Verlet over the particles: the velocity update v += h a, w += h alpha of the free
   particles (with the external loads when `external`), then, with `drift`, the position update
   x += h_drift v of all of them, the largest displacement since the last rebuild, and f and t
   cleared for the force evaluation that follows. Returns nonzero when the pass may have produced a
   state that is not finite or outside the domain; fsdem__dem_check_particles then finds and names the
   particle. (Positions are checked after the drift, velocities after a pass without one.) Written
   once and instantiated per flag, so each pass reads every array it needs once; this part does
   particles [i0, i1), raising *max_disp2 and or-ing *suspect. */
/* threaded: inside a team: the calling thread's particles. */
FSDEM__FORCE_INLINE void fsdem__dem_verlet_range(fsdem_dem *d, fsdem_real h, const int drift, fsdem_real h_drift,
                                                const int external, int i0, int i1, fsdem_real *max_disp2, int *suspect) {
    const fsdem_vec3 g = d->desc.gravity, lo = d->desc.domain_min, hi = d->desc.domain_max;
    fsdem_vec3 *FSDEM__RESTRICT f = d->f, *FSDEM__RESTRICT t = d->t;
    const fsdem_vec3 *FSDEM__RESTRICT fe = d->fext, *FSDEM__RESTRICT te = d->text, *FSDEM__RESTRICT x_ref = d->x_ref;
    const fsdem_real *FSDEM__RESTRICT inv_m = d->inv_m, *FSDEM__RESTRICT inv_i = d->inv_i;
    const unsigned char *FSDEM__RESTRICT fixed = d->fixed;
    fsdem_vec3 *FSDEM__RESTRICT x = d->x, *FSDEM__RESTRICT v = d->v, *FSDEM__RESTRICT w = d->w;
    const fsdem_real h_spin = d->desc.rotation ? h : 0;
    const int planar = d->desc.dim == 2;
    fsdem_real disp2 = *max_disp2;
    int i, outside = 0; /* or suspect: not finite */
    for (i = i0; i < i1; ++i) {
        if (!fixed[i]) {
            const fsdem_real a = h * inv_m[i], b = h_spin * inv_i[i];
            v[i].x += h * g.x + a * (external ? f[i].x + fe[i].x : f[i].x);
            v[i].y += h * g.y + a * (external ? f[i].y + fe[i].y : f[i].y);
            v[i].z += h * g.z + a * (external ? f[i].z + fe[i].z : f[i].z);
            w[i].x += b * (external ? t[i].x + te[i].x : t[i].x);
            w[i].y += b * (external ? t[i].y + te[i].y : t[i].y);
            w[i].z += b * (external ? t[i].z + te[i].z : t[i].z);
            if (planar) v[i].z = w[i].x = w[i].y = 0;
        }
        if (drift) {
            f[i] = t[i] = fsdem__zero3();
            fsdem_real dx, dy, dz, d2;
            x[i].x += h_drift * v[i].x;
            x[i].y += h_drift * v[i].y;
            x[i].z += h_drift * v[i].z;
            dx = x[i].x - x_ref[i].x;
            dy = x[i].y - x_ref[i].y;
            dz = x[i].z - x_ref[i].z;
            d2 = dx * dx + dy * dy + dz * dz;
            if (d2 > disp2) disp2 = d2;
            /* false for NaN too; a spin that is not finite shows here (a velocity shows in x) */
            outside |= !(x[i].x >= lo.x && x[i].x <= hi.x && x[i].y >= lo.y && x[i].y <= hi.y &&
                         (planar || (x[i].z >= lo.z && x[i].z <= hi.z)));
            outside |= !((w[i].x + w[i].y) + w[i].z - ((w[i].x + w[i].y) + w[i].z) == 0);
        } else {
            /* not finite if any term is (and, rarely, when finite terms overflow: the check then
               finds nothing); a tree, so no long chain of dependent additions */
            const fsdem_real sum = (v[i].x + v[i].y) + (v[i].z + w[i].x) + (w[i].y + w[i].z);
            outside |= !(sum - sum == 0);
        }
    }
    *max_disp2 = disp2;
    *suspect |= outside;
}

/* The pass over all particles: on one thread, or (many particles) each thread over its share, the
   largest displacement and the suspicion combined (a maximum and an or: the same at any split). */
/* threaded: opens a team over the particles. */
FSDEM__FORCE_INLINE int fsdem__dem_verlet_pass(fsdem_dem *d, fsdem_real h, const int drift, fsdem_real h_drift,
                                           const int external) {
    const int n = d->n, team = fsdem__team_for(n, FSDEM__DEM_CHUNK, FSDEM__NO_CAP);
    fsdem_real disp2 = d->max_disp2;
    int k, outside = 0;
    if (team <= 1) fsdem__dem_verlet_range(d, h, drift, h_drift, external, 0, n, &disp2, &outside);
    else {
        FSDEM__OMP(parallel num_threads(team) reduction(max : disp2) reduction(| : outside))
        {
            int i0, i1;
            fsdem__share(n, &i0, &i1);
            fsdem__dem_verlet_range(d, h, drift, h_drift, external, i0, i1, &disp2, &outside);
        }
    }
    d->max_disp2 = disp2;
    if (drift) {
        d->forces_valid = 0; /* they are cleared now */
        d->forces_cleared = 1;
    }
    for (k = 0; k < d->wall_count; ++k) d->walls[k].impulse = fsdem__madd(d->walls[k].impulse, d->walls[k].force, -h);
    return outside;
}

/* Velocity update v += h a, w += h alpha of the free particles, and the walls' impulse. */
static int fsdem__dem_kick(fsdem_dem *d, fsdem_real h) {
    return d->external ? fsdem__dem_verlet_pass(d, h, 0, 0, 1) : fsdem__dem_verlet_pass(d, h, 0, 0, 0);
}

/* Kick h, then drift h_drift (and clear the forces). */
static int fsdem__dem_kick_drift(fsdem_dem *d, fsdem_real h, fsdem_real h_drift) {
    return d->external ? fsdem__dem_verlet_pass(d, h, 1, h_drift, 1) : fsdem__dem_verlet_pass(d, h, 1, h_drift, 0);
}

static void fsdem__dem_track_displacement(fsdem_dem *d, int i) {
    fsdem_vec3 dd = fsdem__sub(d->x[i], d->x_ref[i]);
    fsdem_real d2 = fsdem__dot(dd, dd);
    if (d2 > d->max_disp2) d->max_disp2 = d2;
}

static void fsdem__dem_move_walls(fsdem_dem *d, fsdem_real h) {
    int k;
    for (k = 0; k < d->wall_count; ++k) {
        fsdem__dem_wall *w = &d->walls[k];
        fsdem_vec3 dv = fsdem__scale(w->d.velocity, h);
        if (w->d.type == FSDEM_DEM_WALL_TYPE_PLANE) w->d.a = fsdem__add(w->d.a, dv); /* b is the normal */
        else {
            w->d.a = fsdem__add(w->d.a, dv);
            w->d.b = fsdem__add(w->d.b, dv);
            w->d.c = fsdem__add(w->d.c, dv);
        }
        w->moved += fsdem__norm(dv);
    }
}

static fsdem_result fsdem__dem_ensure_lists(fsdem_dem *d) {
    if (fsdem__dem_lists_stale(d) && fsdem__dem_rebuild(d) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_dem: out of memory growing the neighbour lists (%d particles)",
                           d->n);
    return FSDEM_OK;
}

/* Names the first particle that is not finite or left the domain. */
static fsdem_result fsdem__dem_check_particles(fsdem_dem *d) {
    char hint[160] = "";
    int i;
    if (d->stable_dt > 0 && d->dt > d->stable_dt)
        snprintf(hint, sizeof hint, "; dt = %g s is %.3g times the stable dt %g s (%s), the likely cause", (double)d->dt,
                 (double)(d->dt / d->stable_dt), (double)d->stable_dt, fsdem__dem_rule_name(d->desc.dt_rule));
    for (i = 0; i < d->n; ++i) {
        if (!fsdem__finite3(d->x[i]) || !fsdem__finite3(d->v[i]) || !fsdem__finite3(d->w[i]))
            return fsdem__fail(&d->status, FSDEM_ERR_NAN, "fsdem_dem: particle %d (id %d) has a non-finite state at t = %g s%s",
                               i, d->id[i], d->time, hint);
        if (!fsdem__dem_inside_domain(d, d->x[i]))
            return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_DOMAIN,
                               "fsdem_dem: particle %d (id %d) left the domain at t = %g s: position (%g, %g, %g) m%s", i,
                               d->id[i], d->time, (double)d->x[i].x, (double)d->x[i].y, (double)d->x[i].z, hint);
    }
    return FSDEM_OK;
}

/* Velocity Verlet: kick h/2 and drift h (one pass), forces, kick h/2. *suspect is set when a pass
   saw a state that fsdem__dem_check_particles should look at. */
static fsdem_result fsdem__dem_step_verlet(fsdem_dem *d, fsdem_real h, int *suspect) {
    if (fsdem__dem_ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    if (!d->forces_valid) fsdem__dem_compute_forces(d, h, 0);
    *suspect = fsdem__dem_kick_drift(d, h / 2, h);
    if (d->periods.any) fsdem__dem_wrap(d);
    fsdem__dem_move_walls(d, h);
    if (fsdem__dem_ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__dem_compute_forces(d, h, 1);
    *suspect |= fsdem__dem_kick(d, h / 2);
    return FSDEM_OK;
}

/* Predictor-corrector of seed 000 Eq. 21-24 (forces include gravity and the fixed external ones).
   Eq. 22 and 24 as printed average U^n (the outer step's start) with the new velocity; we average
   the substep's own start velocity U_(k-1), which is the trapezoidal rule the scheme is built on
   and keeps positions consistent with velocities when K > 1. */
static fsdem_result fsdem__dem_step_predictor_corrector(fsdem_dem *d, fsdem_real h) {
    int i, k;
    if (fsdem__dem_ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__dem_compute_forces(d, h, 0); /* F_a at X_(k-1), U_(k-1); history not committed */
    for (k = 0; k < d->wall_count; ++k) d->walls[k].force_a = d->walls[k].force;
    for (i = 0; i < d->n; ++i) {
        d->x0[i] = d->x[i];
        d->v0[i] = d->v[i];
        d->w0[i] = d->w[i];
        d->fa[i] = d->f[i];
        d->ta[i] = d->t[i];
        if (!d->fixed[i]) {
            d->v[i] = fsdem__madd(d->v0[i], fsdem__dem_accel(d, d->fa, i), h);            /* Eq. 21 */
            d->w[i] = fsdem__madd(d->w0[i], fsdem__dem_spin_rate(d, d->ta, i), h);
            fsdem__dem_planar(d, &d->x[i], &d->v[i], &d->w[i]);
        }
        d->x[i] = fsdem__madd(d->x0[i], fsdem__add(d->v0[i], d->v[i]), h / 2);       /* Eq. 22 */
        fsdem__dem_track_displacement(d, i);
    }
    fsdem__dem_move_walls(d, h);
    if (fsdem__dem_ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__dem_compute_forces(d, h, 1); /* F_b at X_a, U_a */
    for (i = 0; i < d->n; ++i) {
        if (!d->fixed[i]) {
            fsdem_vec3 acc = fsdem__add(fsdem__dem_accel(d, d->fa, i), fsdem__dem_accel(d, d->f, i));
            fsdem_vec3 spin = fsdem__add(fsdem__dem_spin_rate(d, d->ta, i), fsdem__dem_spin_rate(d, d->t, i));
            d->v[i] = fsdem__madd(d->v0[i], acc, h / 2);                               /* Eq. 23 */
            d->w[i] = fsdem__madd(d->w0[i], spin, h / 2);
            fsdem__dem_planar(d, &d->x[i], &d->v[i], &d->w[i]);
        }
        d->x[i] = fsdem__madd(d->x0[i], fsdem__add(d->v0[i], d->v[i]), h / 2);       /* Eq. 24 */
        fsdem__dem_track_displacement(d, i);
    }
    for (k = 0; k < d->wall_count; ++k)
        d->walls[k].impulse = fsdem__madd(d->walls[k].impulse, fsdem__add(d->walls[k].force_a, d->walls[k].force), -h / 2);
    if (d->periods.any) fsdem__dem_wrap(d); /* the predicted positions need none: pairs take minimum images */
    d->forces_valid = 0; /* the last forces belong to the predicted state, not the final one */
    return FSDEM_OK;
}

static fsdem_result fsdem__dem_step(fsdem_dem *d, fsdem_real h) {
    int suspect = 1;
    fsdem_result res = d->desc.integrator == FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR ? fsdem__dem_step_predictor_corrector(d, h)
                                                                                  : fsdem__dem_step_verlet(d, h, &suspect);
    if (res != FSDEM_OK) return res;
    d->time += h;
    d->steps++;
    return suspect ? fsdem__dem_check_particles(d) : FSDEM_OK;
}

fsdem_result fsdem_dem_step(fsdem_dem *d) {
    fsdem_result res;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    res = fsdem__dem_step(d, d->dt);
    return res == FSDEM_OK ? fsdem__ok(&d->status) : res;
}

fsdem_result fsdem_dem_step_dt(fsdem_dem *d, fsdem_real dt) {
    fsdem_result res;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_step_dt: dt must be > 0 (got %g s)", (double)dt);
    res = fsdem__dem_step(d, dt);
    return res == FSDEM_OK ? fsdem__ok(&d->status) : res;
}

/* Substeps of an outer step (seed 000): K = INT(dt/dt_DEM), dt_DEM = dt/K, and Eq. 25: one substep of
   dt when dt_DEM > dt. The relative tolerance (1e-9, more in float) keeps an exact multiple
   (3e-4/1e-4 = 2.9999999999999996, or 1000 dt rounded to float) from losing a step. */
static fsdem_result fsdem__dem_substeps(const fsdem_dem *d, fsdem_real duration, long long *count, const char *who) {
    fsdem__status *st = (fsdem__status *)&d->status; /* the message is the object's only mutable part here */
    const double ratio = (double)duration / d->dt * (1 + fsdem__tolerance(1e-9));
    if (!(duration > 0) || !fsdem__finite(duration))
        return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: the duration must be > 0 (got %g s)", who, (double)duration);
    if (ratio > (double)FSDEM_DEM_MAX_SUBSTEPS)
        return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: %g s / dt %g s = %g substeps is more than FSDEM_DEM_MAX_SUBSTEPS (%lld)",
                           who, (double)duration, (double)d->dt, ratio, FSDEM_DEM_MAX_SUBSTEPS);
    *count = ratio < 1 ? 1 : (long long)ratio;
    return FSDEM_OK;
}

fsdem_result fsdem_dem_substep_count(const fsdem_dem *d, fsdem_real duration, long long *count) {
    if (!d || !count) return FSDEM_ERR_INVALID_ARG;
    return fsdem__dem_substeps(d, duration, count, "fsdem_dem_substep_count");
}

/* `count` Verlet steps of h as leapfrog: the closing half kick of a step and the opening one of the
   next are one kick of h in the kick-drift pass, so a step costs one pass over the particles, not
   two. The same arithmetic as `count` calls of fsdem__dem_step_verlet (velocities in between are never
   seen); the half kick is closed at the end, and early when a pass saw a suspect state, which the
   check then names (the substeps stop there), or when the callback `fn` (run after every force
   evaluation) fails. */
static fsdem_result fsdem__dem_advance_verlet(fsdem_dem *d, fsdem_real h, long long count, fsdem_dem_substep_fn fn,
                                              void *user) {
    long long k;
    int open = 0, suspect;
    fsdem_result res;
    if (fsdem__dem_ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    if (!d->forces_valid) fsdem__dem_compute_forces(d, h, 0);
    if (fn && (res = fn(user, d, d->time)) != FSDEM_OK) return res;
    for (k = 0; k < count; ++k) {
        fsdem_result called = FSDEM_OK;
        suspect = fsdem__dem_kick_drift(d, open ? h : h / 2, h);
        if (d->periods.any) fsdem__dem_wrap(d);
        fsdem__dem_move_walls(d, h);
        if (fsdem__dem_ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
        fsdem__dem_compute_forces(d, h, 1);
        d->time += h;
        d->steps++;
        open = 1;
        if (fn) called = fn(user, d, d->time);
        if (k == count - 1 || suspect || called != FSDEM_OK) {
            suspect |= fsdem__dem_kick(d, h / 2);
            open = 0;
            res = suspect ? fsdem__dem_check_particles(d) : FSDEM_OK;
            if (res != FSDEM_OK) return res;
            if (called != FSDEM_OK) return called;
        }
    }
    return FSDEM_OK;
}

/* fsdem_dem_advance_with, its errors under the public name `who` */
static fsdem_result fsdem__dem_advance(fsdem_dem *d, fsdem_real duration, fsdem_dem_substep_fn fn, void *user, long long *steps,
                                       const char *who) {
    long long k, count = 0;
    fsdem_result res;
    if (steps) *steps = 0;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    res = fsdem__dem_substeps(d, duration, &count, who);
    if (res != FSDEM_OK) return res;
    if (steps) *steps = count;
    if (d->desc.integrator == FSDEM_DEM_INTEGRATOR_VERLET)
        res = fsdem__dem_advance_verlet(d, duration / (fsdem_real)count, count, fn, user);
    else
        for (k = 0; k < count && res == FSDEM_OK; ++k) {
            /* the predictor-corrector holds the external loads over a substep: one call at its start */
            if (fn) res = fn(user, d, d->time);
            if (res == FSDEM_OK) res = fsdem__dem_step(d, duration / (fsdem_real)count);
        }
    return res == FSDEM_OK ? fsdem__ok(&d->status) : res;
}

fsdem_result fsdem_dem_advance_with(fsdem_dem *d, fsdem_real duration, fsdem_dem_substep_fn fn, void *user,
                                    long long *steps) {
    return fsdem__dem_advance(d, duration, fn, user, steps, "fsdem_dem_advance_with");
}

fsdem_result fsdem_dem_advance(fsdem_dem *d, fsdem_real duration, long long *steps) {
    return fsdem__dem_advance(d, duration, NULL, NULL, steps, "fsdem_dem_advance");
}

fsdem_result fsdem_dem_set_dt(fsdem_dem *d, fsdem_real dt) {
    if (!d) return FSDEM_ERR_INVALID_ARG;
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_set_dt: dt must be > 0 (got %g s)", (double)dt);
    d->dt = dt;
    fsdem__dem_dt_check(d);
    return fsdem__ok(&d->status);
}

double fsdem_dem_time(const fsdem_dem *d) { return d ? d->time : 0; }

fsdem_dem_desc fsdem_dem_get_desc(const fsdem_dem *d) {
    fsdem_dem_desc desc;
    if (!d) {
        memset(&desc, 0, sizeof desc);
        return desc;
    }
    desc = d->desc;
    desc.dt = d->dt;
    return desc;
}
