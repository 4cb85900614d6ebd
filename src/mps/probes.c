/* ---- >>mps_probes : pressure, water level, obstacle force ---- */

/* W(r) of the probes (section >>mps): (1 - r^2/R^2)^3 inside R, times the normalisation of a kernel
   when `normalised`. */
static fsdem_real fsdem__mps_probe_weight(const fsdem_mps *s, fsdem_real r2, fsdem_real R, int normalised) {
    const fsdem_real q = 1 - r2 / (R * R);
    const double c = !normalised ? 1 : s->dim == 2 ? 4 / (FSDEM__PI * (double)(R * R)) : 315 / (64 * FSDEM__PI * (double)(R * R * R));
    return q > 0 ? (fsdem_real)(c * (double)(q * q * q)) : 0;
}

/* Pressure at a point (fsdem_mps_probe_pressure; radius > 0). */
static fsdem_real fsdem__mps_pressure_at(const fsdem_mps *s, fsdem_vec3 point, fsdem_real radius) {
    double sum = 0, weights = 0;
    int i;
    if (s->dim == 2) point.z = 0;
    for (i = 0; i < s->n; ++i) {
        fsdem_vec3 d;
        fsdem_real w;
        if (s->kind[i] == FSDEM_MPS_KIND_DUMMY) continue;
        d = fsdem__min_image(&s->periods, fsdem__sub(s->x[i], point));
        w = fsdem__mps_probe_weight(s, fsdem__dot(d, d), radius, 0);
        sum += (double)(w * s->p[i]);
        weights += (double)w;
    }
    return weights > 0 ? (fsdem_real)(sum / weights) : 0;
}

fsdem_result fsdem_mps_probe_pressure(const fsdem_mps *s, fsdem_vec3 point, fsdem_real radius, fsdem_real *pressure) {
    if (pressure) *pressure = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!pressure || !fsdem__finite3(point) || !(radius >= 0) || !fsdem__finite(radius))
        return fsdem__fail((fsdem__status *)&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_mps_probe_pressure: %s", !pressure ? "pressure is NULL" : "the point and radius must be finite, radius >= 0");
    *pressure = fsdem__mps_pressure_at(s, point, radius > 0 ? radius : s->re);
    return fsdem__ok((fsdem__status *)&s->status);
}

/* Liquid fraction at the point of the gauge line at height z (fsdem_mps_probe_height). */
static fsdem_real fsdem__mps_liquid_fraction(const fsdem_mps *s, fsdem_vec3 gauge, fsdem_real z, fsdem_real R) {
    const int up = s->dim - 1;
    const fsdem_real volume = (fsdem_real)pow((double)s->r0, s->dim);
    double f = 0;
    int i;
    fsdem__set_comp(&gauge, up, z);
    for (i = 0; i < s->n; ++i) {
        fsdem_vec3 d;
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        d = fsdem__min_image(&s->periods, fsdem__sub(s->x[i], gauge));
        f += (double)fsdem__mps_probe_weight(s, fsdem__dot(d, d), R, 1);
    }
    return (fsdem_real)(f * (double)volume);
}

/* Water level at a gauge line (fsdem_mps_probe_height). */
static fsdem_real fsdem__mps_level(const fsdem_mps *s, fsdem_vec3 gauge) {
    const int up = s->dim - 1;
    const fsdem_real R = 2 * s->r0, step = s->r0 / 4;
    fsdem_real top = 0, bottom = 0, z, f_above = 0;
    int i, found = 0;
    if (s->dim == 2) gauge.z = 0;
    /* the span of the liquid within R of the line */
    for (i = 0; i < s->n; ++i) {
        fsdem_vec3 d;
        fsdem_real zi;
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        d = fsdem__min_image(&s->periods, fsdem__sub(s->x[i], gauge));
        fsdem__set_comp(&d, up, 0);
        if (!(fsdem__dot(d, d) < R * R)) continue;
        zi = fsdem__comp(s->x[i], up);
        if (!found || zi > top) top = zi;
        if (!found || zi < bottom) bottom = zi;
        found = 1;
    }
    /* from above the highest particle down, the first sample whose fraction reaches 1/2 */
    for (z = top + R; found && z >= bottom - R; z -= step) {
        const fsdem_real f = fsdem__mps_liquid_fraction(s, gauge, z, R);
        if (f >= (fsdem_real)0.5) return z + step * (f - (fsdem_real)0.5) / (f - f_above);
        f_above = f;
    }
    return fsdem__comp(s->desc.domain_min, up);
}

fsdem_result fsdem_mps_probe_height(const fsdem_mps *s, fsdem_vec3 gauge, fsdem_real *height) {
    if (height) *height = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!height || !fsdem__finite3(gauge))
        return fsdem__fail((fsdem__status *)&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_mps_probe_height: %s", !height ? "height is NULL" : "the gauge position must be finite");
    *height = fsdem__mps_level(s, gauge);
    return fsdem__ok((fsdem__status *)&s->status);
}

/* The value of gauge k (section >>mps, gauges). */
static fsdem_real fsdem__mps_gauge_value(const fsdem_mps *s, int k) {
    return s->gauges.kind[k] == FSDEM_MPS_GAUGE_KIND_LEVEL
               ? fsdem__mps_level(s, s->gauges.at[k])
               : fsdem__mps_pressure_at(s, s->gauges.at[k], s->gauges.radius[k] > 0 ? s->gauges.radius[k] : s->re);
}

static void fsdem__mps_gauge_values(const void *solver, fsdem_real *out) {
    const fsdem_mps *s = (const fsdem_mps *)solver;
    int k;
    for (k = 0; k < s->gauges.count; ++k) out[k] = fsdem__mps_gauge_value(s, k);
}

fsdem_result fsdem_mps_add_gauge(fsdem_mps *s, fsdem_mps_gauge_kind kind, fsdem_vec3 position, fsdem_real radius, int *id) {
    if (id) *id = -1;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__gauges_add(&s->gauges, &s->status, &s->allocator, "fsdem_mps_add_gauge", (int)kind, position, radius, s->dim,
                             s->desc.domain_min, s->desc.domain_max, id);
}

fsdem_result fsdem_mps_gauge(const fsdem_mps *s, int id, fsdem_real *value) {
    if (!s || !value) return FSDEM_ERR_INVALID_ARG;
    if (id < 0 || id >= s->gauges.count) return FSDEM_ERR_NOT_FOUND;
    *value = fsdem__mps_gauge_value(s, id);
    return FSDEM_OK;
}

fsdem_result fsdem_mps_gauges_open(fsdem_mps *s, const char *path, fsdem_real interval) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__gauges_open(&s->gauges, &s->status, &s->allocator, "fsdem_mps_gauges_open", path, s->time, interval,
                              fsdem__mps_gauge_values, s);
}

fsdem_result fsdem_mps_gauges_hold(fsdem_mps *s, int hold) {
    return s ? fsdem__series_hold_call(&s->gauges.series, &s->status, "fsdem_mps_gauges_hold", hold) : FSDEM_ERR_INVALID_ARG;
}

fsdem_result fsdem_mps_gauges_close(fsdem_mps *s) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__gauges_close(&s->gauges, &s->status, &s->allocator, "fsdem_mps_gauges_close");
}

fsdem_result fsdem_mps_obstacle_force(const fsdem_mps *s, int id, fsdem_vec3 *force) {
    if (force) *force = fsdem__zero3();
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!force || id < 0 || id >= s->obst_n)
        return fsdem__fail((fsdem__status *)&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_obstacle_force: %s",
                           !force ? "force is NULL" : "no obstacle has this id");
    *force = s->obst[id].force;
    return fsdem__ok((fsdem__status *)&s->status);
}
