/* ---- >>swe_diag : diagnostics and output ---- */

fsdem_real fsdem_swe_volume(const fsdem_swe *s) {
    double sum = 0;
    int k;
    if (!s) return 0;
    for (k = 0; k < s->n; ++k) sum += (double)(s->eta[k] - s->bed[k]);
    return (fsdem_real)(sum * (double)s->area);
}

fsdem_vec3 fsdem_swe_momentum(const fsdem_swe *s) {
    double mx = 0, my = 0, scale;
    int k;
    if (!s) return fsdem__zero3();
    scale = (double)s->desc.density * (double)s->area;
    for (k = 0; k < s->n; ++k) {
        mx += (double)s->qx[k];
        my += (double)s->qy[k];
    }
    return fsdem_v3((fsdem_real)(mx * scale), (fsdem_real)(my * scale), 0);
}

fsdem_swe_stats fsdem_swe_get_stats(const fsdem_swe *s) {
    fsdem_swe_stats st;
    int k;
    memset(&st, 0, sizeof st);
    if (!s) return st;
    st.steps = s->steps;
    st.time = s->time;
    st.dt = s->dt_last;
    st.max_depth = s->max_depth;
    st.max_speed = s->max_speed;
    st.wet_cells = s->wet_cells;
    st.boundary_volume = s->vol_boundary;
    st.source_volume = s->vol_source;
    st.clipped_volume = s->vol_clipped;
    st.predictor_fallbacks = s->fallbacks;
    st.memory_bytes = sizeof *s + s->block_bytes + (s->manning ? sizeof(fsdem_real) * (size_t)s->n : 0) +
                      sizeof(fsdem__swe_src) * (size_t)s->src_capacity +
                      2 * sizeof(fsdem_real) * (size_t)s->gauge_capacity;
    for (k = 0; k < 4; ++k) st.memory_bytes += 2 * sizeof(fsdem_real) * (size_t)s->bnd[k].n;
    for (k = 0; k < s->src_count; ++k) st.memory_bytes += 2 * sizeof(fsdem_real) * (size_t)s->src[k].n;
    return st;
}

fsdem_result fsdem_swe_write_csv(const fsdem_swe *s, const char *path) {
    FILE *fp;
    int k, bad;
    if (!s || !path) return FSDEM_ERR_INVALID_ARG;
    if (!(fp = fopen(path, "w"))) return FSDEM_ERR_IO;
    fprintf(fp, s->dim == 2 ? "x,y,bed,h,eta,u,v\n" : "x,bed,h,eta,u\n");
    for (k = 0; k < s->n; ++k) {
        fsdem_real x, y, u, v;
        fsdem__swe_centre(s, k, &x, &y);
        fsdem__swe_velocity(s, k, &u, &v);
        if (s->dim == 2)
            fprintf(fp, "%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n", (double)x, (double)y, (double)s->bed[k],
                    (double)(s->eta[k] - s->bed[k]), (double)s->eta[k], (double)u, (double)v);
        else
            fprintf(fp, "%.10g,%.10g,%.10g,%.10g,%.10g\n", (double)x, (double)s->bed[k],
                    (double)(s->eta[k] - s->bed[k]), (double)s->eta[k], (double)u);
    }
    bad = ferror(fp);
    return (fclose(fp) != 0 || bad) ? FSDEM_ERR_IO : FSDEM_OK;
}

fsdem_result fsdem_swe_add_gauge(fsdem_swe *s, fsdem_real x, fsdem_real y, int *id) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (s->gauges.file)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_add_gauge: close the gauge file first");
    if (fsdem_swe_cell_at(s, x, y) < 0)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_DOMAIN, "fsdem_swe_add_gauge: point (%g, %g) is outside the grid",
                           (double)x, (double)y);
    if (s->blocked && s->blocked[fsdem_swe_cell_at(s, x, y)])
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_add_gauge: point (%g, %g) is in a blocked cell",
                           (double)x, (double)y);
    if (fsdem__grow(&s->allocator, (void **)&s->gauge, &s->gauge_capacity, s->gauge_count, s->gauge_count + 1,
                    2 * sizeof(fsdem_real)) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_swe_add_gauge: out of memory");
    s->gauge[2 * s->gauge_count] = x;
    s->gauge[2 * s->gauge_count + 1] = y;
    if (id) *id = s->gauge_count;
    s->gauge_count++;
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_gauge(const fsdem_swe *s, int id, fsdem_swe_cell *out) {
    if (!s || !out) return FSDEM_ERR_INVALID_ARG;
    if (id < 0 || id >= s->gauge_count) return FSDEM_ERR_NOT_FOUND;
    return fsdem_swe_sample_state(s, s->gauge[2 * id], s->gauge[2 * id + 1], out);
}

fsdem_result fsdem_swe_gauges_open(fsdem_swe *s, const char *path, fsdem_real interval) {
    char *header;
    size_t size;
    int k, n = 1;
    fsdem_result res;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (s->gauge_count == 0)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_gauges_open: add gauges first");
    if (!(interval >= 0) || !fsdem__finite(interval))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_gauges_open: interval must be >= 0 (got %g s)",
                           (double)interval);
    if (s->gauges.file) fsdem_swe_gauges_close(s);
    size = 2 + 48 * (size_t)s->gauge_count;
    header = (char *)fsdem__alloc(&s->allocator, size);
    if (!header) return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_swe_gauges_open: out of memory");
    header[0] = 't';
    header[1] = '\0';
    for (k = 0; k < s->gauge_count; ++k)
        n += snprintf(header + n, size - (size_t)n, ",h_%d,eta_%d,u_%d,v_%d", k, k, k, k);
    res = fsdem__series_open(&s->gauges, &s->allocator, path, header, 4 * s->gauge_count, s->time, interval,
                             fsdem__swe_gauge_values, s);
    fsdem__free(&s->allocator, header, size);
    if (res != FSDEM_OK)
        return fsdem__fail(&s->status, res, "fsdem_swe_gauges_open: cannot open '%s'", path ? path : "(null)");
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_gauges_hold(fsdem_swe *s, int hold) {
    return s ? fsdem__series_hold_call(&s->gauges, &s->status, "fsdem_swe_gauges_hold", hold) : FSDEM_ERR_INVALID_ARG;
}

fsdem_result fsdem_swe_gauges_close(fsdem_swe *s) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__series_close(&s->gauges, &s->allocator) == FSDEM_OK
               ? fsdem__ok(&s->status)
               : fsdem__fail(&s->status, FSDEM_ERR_IO, "fsdem_swe_gauges_close: write error");
}

fsdem_real fsdem_swe_bed_sdf(void *user, fsdem_vec3 p, fsdem_vec3 *normal) {
    const fsdem_swe *swe = (const fsdem_swe *)user;
    if (!swe) { /* no bed: far away, so a wall made with a NULL user never touches */
        if (normal) *normal = fsdem_v3(0, 0, 1);
        return (fsdem_real)FLT_MAX;
    }
    const fsdem_real x0 = swe->desc.x_min + swe->dx / 2, x1 = swe->desc.x_min + (swe->nx - (fsdem_real)0.5) * swe->dx;
    const fsdem_real y0 = swe->desc.y_min + swe->dy / 2, y1 = swe->desc.y_min + (swe->ny - (fsdem_real)0.5) * swe->dy;
    fsdem_real x = p.x < x0 ? x0 : p.x > x1 ? x1 : p.x, y = p.y < y0 ? y0 : p.y > y1 ? y1 : p.y, gx, gy, len;
    fsdem_swe_cell c0, cm, cp;
    fsdem_swe_sample_state(swe, x, y, &c0);
    /* bed slope from centred differences over one cell */
    fsdem_swe_sample_state(swe, x - swe->dx / 2, y, &cm);
    fsdem_swe_sample_state(swe, x + swe->dx / 2, y, &cp);
    gx = (cp.bed - cm.bed) / swe->dx;
    gy = 0;
    if (swe->dim == 2) {
        fsdem_swe_sample_state(swe, x, y - swe->dy / 2, &cm);
        fsdem_swe_sample_state(swe, x, y + swe->dy / 2, &cp);
        gy = (cp.bed - cm.bed) / swe->dy;
    }
    len = (fsdem_real)sqrt(1 + gx * gx + gy * gy);
    *normal = fsdem_v3(-gx / len, -gy / len, 1 / len);
    return (p.z - c0.bed) / len;
}
