/* ===== >>impl_couple_step : the staged step, the stable rule, the advance ===========================

   Contents: the step of one coupler or of couplers sharing a fluid (>>couple_step): the state kept
   (>>restart_journal) and the prepare, the checks that refuse before anything moves, the stages
   around the fluid's step, the state put back on a failure after something moved; the stable
   rule; the advance; the verbs of each coupler on them. It follows >>impl_restart, whose saves it keeps. */

/* The message of couplers[from] (or a new one, from < 0) given to every coupler of the list. */
static fsdem_result fsdem__coupled_fail(fsdem_coupler *const *list, int n, int from, fsdem_result res, const char *fmt, ...) {
    int k;
    if (from < 0) {
        va_list ap;
        va_start(ap, fmt);
        fsdem__vfail(&list[0]->status, res, fmt, ap);
        va_end(ap);
        from = 0;
    }
    for (k = 0; k < n; ++k)
        if (list[k] != list[from]) memcpy(list[k]->status.message, list[from]->status.message, sizeof list[k]->status.message);
    return res;
}

/* A step of the list failed after its state was kept, with the message of couplers[from]: every
   coupler, fluid and DEM put back as kept before the prepare, the fluid's gauge rows of the step
   dropped, the message (and a put-back that failed) to every coupler; passes `res` on. The
   restores write into the objects' own arrays, whose capacities the step did not change (the
   fluid's reserve ran before the keep), so they allocate nothing. */
static fsdem_result fsdem__coupled_put_back(fsdem_coupler *const *list, int n, int from, fsdem_result res) {
    char message[FSDEM__MESSAGE_SIZE];
    int k, lost = -1;
    memcpy(message, list[from]->status.message, sizeof message);
    for (k = 0; k < n; ++k)
        if (fsdem__restart_put_back(list[k]) != FSDEM_OK && lost < 0) lost = k;
    list[0]->cls->fluid->gauges_hold(list[0]->fluid, 0); /* the rows it held were dropped with the step */
    if (lost >= 0)
        return fsdem__coupled_fail(list, n, -1, res, "%s; and the state before the step could not be put back: %s", message,
                                   list[lost]->status.message);
    return fsdem__coupled_fail(list, n, -1, res, "%s", message);
}

/* A list of couplers that can step together: not empty, no NULL, none twice, one fluid. */
static fsdem_result fsdem__coupled_list(fsdem_coupler *const *list, int n, const char *who) {
    int k, j;
    if (!list || n < 1) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < n; ++k)
        if (!list[k]) return FSDEM_ERR_INVALID_ARG;
    for (k = 1; k < n; ++k) {
        if (list[k]->fluid != list[0]->fluid)
            return fsdem__coupled_fail(list, n, -1, FSDEM_ERR_INVALID_ARG, "%s: couplers %d (%s) and 0 (%s) have different fluids", who, k,
                                       list[k]->cls->name, list[0]->cls->name);
        for (j = 0; j < k; ++j)
            if (list[j] == list[k]) return fsdem__coupled_fail(list, n, -1, FSDEM_ERR_INVALID_ARG, "%s: coupler %d is listed twice", who, k);
    }
    return FSDEM_OK;
}

/* The stable dt of couplers of one fluid: the fluid's, cut by every coupler's own limits. */
static fsdem_result fsdem__coupled_stable(fsdem_coupler *const *list, int n, fsdem_real *dt) {
    const fsdem__fluid *f = list[0]->cls->fluid;
    fsdem_result res = f->stable_dt(list[0]->fluid, dt);
    int k;
    if (res != FSDEM_OK)
        return fsdem__coupled_fail(list, n, -1, res, "%s: %s stable step: %s", list[0]->cls->name, f->name, f->last_error(list[0]->fluid));
    for (k = 0; k < n; ++k)
        if (list[k]->cls->limit && (res = list[k]->cls->limit(list[k], dt)) != FSDEM_OK) return fsdem__coupled_fail(list, n, k, res, NULL);
    return FSDEM_OK;
}

/* The fluid's reserve, then every coupler's state kept (>>restart_journal; a failure of either, out
   of memory, refuses the step with nothing moved), then the couplers' prepare, in order, timed as
   coupling, then with `dt` the stable dt; a failure after the keep puts the state back. */
static fsdem_result fsdem__coupled_prepare(fsdem_coupler *const *list, int n, fsdem_real *dt) {
    const fsdem__fluid *f = list[0]->cls->fluid;
    fsdem_result res = FSDEM_OK;
    int k;
    if (f->reserve && (res = f->reserve(list[0]->fluid)) != FSDEM_OK)
        return fsdem__coupled_fail(list, n, -1, res, "%s: %s: %s", list[0]->cls->name, f->name, f->last_error(list[0]->fluid));
    for (k = 0; k < n && res == FSDEM_OK; ++k) {
        const clock_t t0 = clock();
        if ((res = fsdem__restart_keep(list[k])) != FSDEM_OK) fsdem__coupled_fail(list, n, k, res, NULL);
        list[k]->seconds[FSDEM__CLOCK_COUPLING] += (double)(clock() - t0) / CLOCKS_PER_SEC;
    }
    for (k = 0; k < n && res == FSDEM_OK; ++k)
        if (list[k]->cls->prepare) {
            const clock_t t0 = clock();
            if ((res = list[k]->cls->prepare(list[k])) != FSDEM_OK) fsdem__coupled_put_back(list, n, k, res);
            list[k]->seconds[FSDEM__CLOCK_COUPLING] += (double)(clock() - t0) / CLOCKS_PER_SEC;
        }
    if (res == FSDEM_OK && dt && (res = fsdem__coupled_stable(list, n, dt)) != FSDEM_OK) fsdem__coupled_put_back(list, n, 0, res);
    return res;
}

/* The stages of coupler c before its fluid step (after = 0), or after it (after = 1), each timed on
   its clock; the first failure ends them. */
static fsdem_result fsdem__coupled_stages(fsdem_coupler *c, fsdem_real dt, int after) {
    const fsdem__coupler_class *cls = c->cls;
    fsdem_result res = FSDEM_OK;
    int s = 0;
    if (after)
        while (s < cls->stage_count && cls->stages[s++].run) continue;
    for (; s < cls->stage_count && res == FSDEM_OK && cls->stages[s].run; ++s) {
        const clock_t t0 = clock();
        c->stage = cls->stages[s].name;
        res = cls->stages[s].run(c, dt);
        c->seconds[cls->stages[s].clock] += (double)(clock() - t0) / CLOCKS_PER_SEC;
    }
    return res;
}

/* The name of the coupler's fluid-step stage ("PIC step"). */
static const char *fsdem__coupler_fluid_stage(const fsdem_coupler *c) {
    int s = 0;
    while (c->cls->stages[s].run) ++s;
    return c->cls->stages[s].name;
}

/* A coupled step of dt after the prepare (which kept the state): every coupler's checks, the stages
   before the fluid's step, the fluid's step, the stages after it. A refusal or a failure puts the
   kept state back (fsdem__coupled_put_back), so a refused step leaves couplers, fluid and DEMs as
   they were. `chosen`: dt is the caller's, not a stable one. */
static fsdem_result fsdem__coupled_go(fsdem_coupler *const *list, int n, fsdem_real dt, int chosen) {
    const fsdem__fluid *f = list[0]->cls->fluid;
    void *fluid = list[0]->fluid;
    fsdem_result res;
    clock_t t0;
    double seconds;
    int k;
    for (k = 0; k < n; ++k)
        if ((res = fsdem__coupler_particles_valid(list[k])) != FSDEM_OK || (res = list[k]->cls->check(list[k], dt, chosen)) != FSDEM_OK)
            return fsdem__coupled_put_back(list, n, k, res);
    f->gauges_hold(fluid, 1); /* the fluid's gauge rows of the step wait until it is taken */
    for (k = 0; k < n; ++k)
        if ((res = fsdem__coupled_stages(list[k], dt, 0)) != FSDEM_OK) return fsdem__coupled_put_back(list, n, k, res);
    t0 = clock();
    res = f->step_dt(fluid, dt);
    seconds = (double)(clock() - t0) / CLOCKS_PER_SEC;
    for (k = 0; k < n; ++k) list[k]->seconds[FSDEM__CLOCK_FLUID] += seconds;
    if (res != FSDEM_OK) {
        fsdem__fail(&list[0]->status, res, "%s: %s: %s", list[0]->cls->name, fsdem__coupler_fluid_stage(list[0]), f->last_error(fluid));
        return fsdem__coupled_put_back(list, n, 0, res);
    }
    for (k = 0; k < n; ++k) {
        list[k]->steps++;
        list[k]->dt_last = dt;
    }
    for (k = 0; k < n; ++k)
        if ((res = fsdem__coupled_stages(list[k], dt, 1)) != FSDEM_OK) return fsdem__coupled_put_back(list, n, k, res);
    if ((res = f->gauges_hold(fluid, 0)) != FSDEM_OK) /* the step is taken; its rows could not be written */
        return fsdem__coupled_fail(list, n, -1, res, "%s: %s", list[0]->cls->name, f->last_error(fluid));
    for (k = 0; k < n; ++k) fsdem__ok(&list[k]->status);
    return FSDEM_OK;
}

/* The verbs of couplers stepping together, and of each coupler alone (a list of one); `who` names
   the public function in messages. */
static fsdem_result fsdem__coupled_step(fsdem_coupler *const *list, int n) {
    fsdem_real dt = 0;
    fsdem_result res = fsdem__coupled_prepare(list, n, &dt);
    return res != FSDEM_OK ? res : fsdem__coupled_go(list, n, dt, 0);
}

static fsdem_result fsdem__coupled_step_dt(fsdem_coupler *const *list, int n, fsdem_real dt, const char *who) {
    fsdem_result res;
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__coupled_fail(list, n, -1, FSDEM_ERR_INVALID_ARG, "%s: dt = %g s must be > 0 and finite", who, (double)dt);
    if ((res = fsdem__coupled_prepare(list, n, NULL)) != FSDEM_OK) return res;
    return fsdem__coupled_go(list, n, dt, 1);
}

/* Steps until exactly `duration` later: when less than one and a half stable steps are left, the
   last two share them equally, so no step is a sliver; the end is reached to a relative 1e-12. */
static fsdem_result fsdem__coupled_advance(fsdem_coupler *const *list, int n, fsdem_real duration, long long *steps, const char *who) {
    const fsdem__fluid *f = list[0]->cls->fluid;
    const void *fluid = list[0]->fluid;
    long long count = 0;
    fsdem_result res = FSDEM_OK;
    double end;
    if (steps) *steps = 0;
    if (!(duration >= 0) || !fsdem__finite(duration))
        return fsdem__coupled_fail(list, n, -1, FSDEM_ERR_INVALID_ARG, "%s: duration = %g s must be >= 0", who, (double)duration);
    end = f->time(fluid) + (double)duration;
    while (res == FSDEM_OK && f->time(fluid) < end - 1e-12 * (end > 1 ? end : 1)) {
        const double left = end - f->time(fluid);
        fsdem_real dt = 0;
        if ((res = fsdem__coupled_prepare(list, n, &dt)) != FSDEM_OK) break;
        if ((double)dt >= left) dt = (fsdem_real)left;
        else if (1.5 * (double)dt > left) dt = (fsdem_real)(left / 2);
        res = fsdem__coupled_go(list, n, dt, 0);
        ++count;
    }
    if (steps) *steps = count;
    return res;
}

fsdem_result fsdem_coupled_step(fsdem_coupler *const *couplers, int count) {
    const fsdem_result res = fsdem__coupled_list(couplers, count, "fsdem_coupled_step");
    return res != FSDEM_OK ? res : fsdem__coupled_step(couplers, count);
}

fsdem_result fsdem_coupled_step_dt(fsdem_coupler *const *couplers, int count, fsdem_real dt) {
    const fsdem_result res = fsdem__coupled_list(couplers, count, "fsdem_coupled_step_dt");
    return res != FSDEM_OK ? res : fsdem__coupled_step_dt(couplers, count, dt, "fsdem_coupled_step_dt");
}

fsdem_result fsdem_coupled_advance(fsdem_coupler *const *couplers, int count, fsdem_real duration, long long *steps) {
    const fsdem_result res = fsdem__coupled_list(couplers, count, "fsdem_coupled_advance");
    if (steps) *steps = 0;
    return res != FSDEM_OK ? res : fsdem__coupled_advance(couplers, count, duration, steps, "fsdem_coupled_advance");
}

fsdem_result fsdem_coupled_stable_dt(fsdem_coupler *const *couplers, int count, fsdem_real *dt) {
    const fsdem_result res = fsdem__coupled_list(couplers, count, "fsdem_coupled_stable_dt");
    if (res != FSDEM_OK) return res;
    if (!dt) return FSDEM_ERR_INVALID_ARG;
    return fsdem__coupled_stable(couplers, count, dt);
}

/* The verbs of one coupler (NULL refused), its step a list of one. */
static fsdem_result fsdem__coupler_step(fsdem_coupler *c) { return c ? fsdem__coupled_step(&c, 1) : FSDEM_ERR_INVALID_ARG; }

static fsdem_result fsdem__coupler_step_dt(fsdem_coupler *c, fsdem_real dt, const char *who) {
    return c ? fsdem__coupled_step_dt(&c, 1, dt, who) : FSDEM_ERR_INVALID_ARG;
}

static fsdem_result fsdem__coupler_advance(fsdem_coupler *c, fsdem_real duration, long long *steps, const char *who) {
    if (steps) *steps = 0;
    return c ? fsdem__coupled_advance(&c, 1, duration, steps, who) : FSDEM_ERR_INVALID_ARG;
}

static fsdem_result fsdem__coupler_stable_dt(const fsdem_coupler *c, fsdem_real *dt) {
    fsdem_coupler *list = (fsdem_coupler *)c; /* only the message changes (a failure's) */
    return c && dt ? fsdem__coupled_stable(&list, 1, dt) : FSDEM_ERR_INVALID_ARG;
}

/* The verbs of each coupler (>>couple_swe, >>couple_mps, >>couple_pic, >>couple_gic). */
fsdem_result fsdem_swe_dem_step(fsdem_swe_dem *c) { return fsdem__coupler_step(c ? &c->head : NULL); }
fsdem_result fsdem_swe_dem_step_dt(fsdem_swe_dem *c, fsdem_real dt) {
    return fsdem__coupler_step_dt(c ? &c->head : NULL, dt, "fsdem_swe_dem_step_dt");
}
fsdem_result fsdem_swe_dem_advance(fsdem_swe_dem *c, fsdem_real duration, long long *steps) {
    return fsdem__coupler_advance(c ? &c->head : NULL, duration, steps, "fsdem_swe_dem_advance");
}
fsdem_result fsdem_swe_dem_stable_dt(const fsdem_swe_dem *c, fsdem_real *dt) { return fsdem__coupler_stable_dt(c ? &c->head : NULL, dt); }

fsdem_result fsdem_mps_dem_step(fsdem_mps_dem *c) { return fsdem__coupler_step(c ? &c->head : NULL); }
fsdem_result fsdem_mps_dem_step_dt(fsdem_mps_dem *c, fsdem_real dt) {
    return fsdem__coupler_step_dt(c ? &c->head : NULL, dt, "fsdem_mps_dem_step_dt");
}
fsdem_result fsdem_mps_dem_advance(fsdem_mps_dem *c, fsdem_real duration, long long *steps) {
    return fsdem__coupler_advance(c ? &c->head : NULL, duration, steps, "fsdem_mps_dem_advance");
}
fsdem_result fsdem_mps_dem_stable_dt(const fsdem_mps_dem *c, fsdem_real *dt) { return fsdem__coupler_stable_dt(c ? &c->head : NULL, dt); }

fsdem_result fsdem_pic_dem_step(fsdem_pic_dem *c) { return fsdem__coupler_step(c ? &c->head : NULL); }
fsdem_result fsdem_pic_dem_step_dt(fsdem_pic_dem *c, fsdem_real dt) {
    return fsdem__coupler_step_dt(c ? &c->head : NULL, dt, "fsdem_pic_dem_step_dt");
}
fsdem_result fsdem_pic_dem_advance(fsdem_pic_dem *c, fsdem_real duration, long long *steps) {
    return fsdem__coupler_advance(c ? &c->head : NULL, duration, steps, "fsdem_pic_dem_advance");
}
fsdem_result fsdem_pic_dem_stable_dt(const fsdem_pic_dem *c, fsdem_real *dt) { return fsdem__coupler_stable_dt(c ? &c->head : NULL, dt); }

fsdem_result fsdem_gic_step(fsdem_gic *c) { return fsdem__coupler_step(c ? &c->head : NULL); }
fsdem_result fsdem_gic_step_dt(fsdem_gic *c, fsdem_real dt) { return fsdem__coupler_step_dt(c ? &c->head : NULL, dt, "fsdem_gic_step_dt"); }
fsdem_result fsdem_gic_advance(fsdem_gic *c, fsdem_real duration, long long *steps) {
    return fsdem__coupler_advance(c ? &c->head : NULL, duration, steps, "fsdem_gic_advance");
}
fsdem_result fsdem_gic_stable_dt(const fsdem_gic *c, fsdem_real *dt) { return fsdem__coupler_stable_dt(c ? &c->head : NULL, dt); }
