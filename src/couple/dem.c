/* ---- >>couple_dem : the DEM's checks and substeps ---- */

/* Every DEM particle fits in the fluid's domain [lo, hi] (a sphere wider than the domain's smallest
   extent leaves no fluid around it); the particle goes to the message under the name `who`. */
static fsdem_result fsdem__coupler_particles_fit(fsdem_coupler *c, fsdem_vec3 lo, fsdem_vec3 hi, const char *who) {
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->dem);
    const fsdem_real extent = fsdem__smallest_extent(lo, hi, P.dim);
    int i;
    for (i = 0; i < P.count; ++i)
        if (!(2 * P.radius[i] < extent))
            return fsdem__fail(&c->status, FSDEM_ERR_INVALID_ARG,
                               "%s: DEM particle %d (id %d) of radius %g m does not fit in the fluid's domain (smallest extent %g m)", who,
                               i, P.id[i], (double)P.radius[i], (double)extent);
    return FSDEM_OK;
}

/* Before a step of dt moves anything: the DEM can follow it in at most max_substeps substeps. */
static fsdem_result fsdem__coupler_substeps_within(fsdem_coupler *c, fsdem_real dt) {
    long long substeps = 0;
    const fsdem_result res = fsdem_dem_substep_count(c->dem, dt, &substeps);
    if (res != FSDEM_OK) return fsdem__fail(&c->status, res, "%s: %s", c->cls->name, fsdem_dem_last_error(c->dem));
    if (substeps > c->max_substeps)
        return fsdem__fail(&c->status, FSDEM_ERR_INVALID_ARG,
                           "%s: the fluid step %g s needs %lld DEM substeps, more than max_substeps %lld (DEM dt %g s)", c->cls->name,
                           (double)dt, substeps, c->max_substeps, (double)fsdem_dem_get_stats(c->dem).dt);
    return FSDEM_OK;
}

/* The coupler's DEM over dt in substeps, `fn` (may be NULL) called at every force evaluation
   (fsdem_dem_advance_with); the counts go to the head. A failure is named "<stage>: <the DEM's
   message>", unless `fn` failed (*fn_failed set) and named it already. */
static fsdem_result fsdem__coupler_substeps(fsdem_coupler *c, fsdem_real dt, fsdem_dem_substep_fn fn, void *user, const int *fn_failed) {
    long long substeps = 0;
    const fsdem_result res = fsdem_dem_advance_with(c->dem, dt, fn, user, &substeps);
    c->substeps = substeps;
    c->substeps_total += substeps;
    if (res != FSDEM_OK && !(fn_failed && *fn_failed))
        return fsdem__fail(&c->status, res, "%s: %s: %s", c->cls->name, c->stage, fsdem_dem_last_error(c->dem));
    return res;
}

/* Every DEM particle's position and velocity finite, and the particle inside the DEM's domain: a
   step of a DEM that holds a NaN or a particle outside is refused before anything moves (the DEM
   would find it only in its first substep). */
static fsdem_result fsdem__coupler_particles_valid(fsdem_coupler *c) {
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->dem);
    const fsdem_dem_desc dd = fsdem_dem_get_desc(c->dem);
    int i, a;
    for (i = 0; i < P.count; ++i) {
        if (!fsdem__finite3(P.position[i]) || !fsdem__finite3(P.velocity[i]) || !fsdem__finite3(P.angular_velocity[i]))
            return fsdem__fail(&c->status, FSDEM_ERR_NAN, "%s: DEM particle %d (id %d) has a non-finite position or velocity", c->cls->name, i,
                               P.id[i]);
        for (a = 0; a < dd.dim; ++a)
            if (!(fsdem__comp(P.position[i], a) >= fsdem__comp(dd.domain_min, a) && fsdem__comp(P.position[i], a) <= fsdem__comp(dd.domain_max, a)))
                return fsdem__fail(&c->status, FSDEM_ERR_OUT_OF_DOMAIN, "%s: DEM particle %d (id %d) at (%g, %g, %g) m is outside the DEM's domain",
                                   c->cls->name, i, P.id[i], (double)P.position[i].x, (double)P.position[i].y, (double)P.position[i].z);
    }
    return FSDEM_OK;
}
