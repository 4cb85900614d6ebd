/* ---- >>restart_swe : shallow water ---- */

/* The per-cell masks of the SWE: the blocked cells, when there are any (nx*ny flags; into the
   object's array when it has one); `masks` counts them, so data with a mask this build does not know
   are refused. */
static void fsdem__restart_swe_masks(fsdem__restart *io, fsdem_swe *s) {
    int masks = s->blocked ? 1 : 0, k, count = 0;
    unsigned char *blocked;
    fsdem__restart_int_in(io, &masks, 0, 1, "the number of per-cell masks (data of a newer build)");
    blocked = !masks || s->blocked ? s->blocked : (unsigned char *)fsdem__restart_block(io, &s->allocator, (size_t)s->n);
    if (masks) fsdem__restart_flags(io, blocked, s->n, 1, "blocked flag of cell");
    if (io->mode != FSDEM__RESTART_COMMIT) return;
    if (!masks) {
        fsdem__free(&s->allocator, s->blocked, (size_t)s->n);
        blocked = NULL;
    }
    s->blocked = blocked;
    for (k = 0; blocked && k < s->n; ++k) count += blocked[k];
    s->blocked_count = count;
}

/* A series of n points (times and values): written, or read into *t and *v when they have that
   length, else into fresh arrays that COMMIT hands to *t and *v after freeing the old ones. */
static void fsdem__restart_swe_series(fsdem__restart *io, fsdem_swe *s, fsdem_real **t, fsdem_real **v, int *n,
                                      const char *what) {
    int count = *n;
    fsdem_real *ft = *t, *fv = *v;
    fsdem__restart_count(io, &count, 1 << 28, 2 * sizeof(fsdem_real), what);
    if (count != *n) {
        ft = (fsdem_real *)fsdem__restart_block(io, &s->allocator, sizeof(fsdem_real) * (size_t)count);
        fv = (fsdem_real *)fsdem__restart_block(io, &s->allocator, sizeof(fsdem_real) * (size_t)count);
        if (io->mode == FSDEM__RESTART_COMMIT) {
            fsdem__swe_free_series(s, t, v, n);
            *t = ft;
            *v = fv;
            *n = count;
        }
    }
    fsdem__restart_data(io, ft, sizeof(fsdem_real) * (size_t)count);
    fsdem__restart_data(io, fv, sizeof(fsdem_real) * (size_t)count);
}

/* Everything of a shallow-water solver, in order. State: time, last dt, counters, the bound of the
   wave speed and of the acceleration (the next adaptive dt reads them) and the other figures of the
   last step, the volume budget, rain, the surface, discharges and bed exactly, the momentum sources
   and whether they are in use, the per-cell masks (merge point above), per-cell Manning, the four
   boundaries with their series, point sources with their series, ids and states, gauge positions.
   Configuration: the grid and the desc fields that steps read, compared. Not saved: the work rows
   (prim, rows, south) and the boundary values of the step in flight (bvalue), rewritten by every
   step; the gauge file, its interval and next output time (restore refuses while a file is open);
   capacities, the allocator, log and message. */
static void fsdem__restart_swe(fsdem__restart *io, void *object) {
    static const fsdem__field same[15] = {
        FSDEM__SAME(fsdem_swe, dim, INT), FSDEM__SAME(fsdem_swe, x_min, REAL), FSDEM__SAME(fsdem_swe, x_max, REAL),
        FSDEM__SAME(fsdem_swe, y_min, REAL), FSDEM__SAME(fsdem_swe, y_max, REAL), FSDEM__SAME(fsdem_swe, width, REAL),
        FSDEM__SAME(fsdem_swe, gravity, VEC3), FSDEM__SAME(fsdem_swe, density, REAL), FSDEM__SAME(fsdem_swe, cfl, REAL),
        FSDEM__SAME(fsdem_swe, dt_max, REAL), FSDEM__SAME(fsdem_swe, order, INT), FSDEM__SAME(fsdem_swe, limiter, INT),
        FSDEM__SAME(fsdem_swe, dry_depth, REAL), FSDEM__SAME(fsdem_swe, manning, REAL),
        FSDEM__SAME(fsdem_swe, eddy_viscosity, REAL)};
    static const fsdem__field state[14] = {
        FSDEM__SAVED(fsdem_swe, time), FSDEM__SAVED(fsdem_swe, dt_last), FSDEM__SAVED(fsdem_swe, steps),
        FSDEM__SAVED(fsdem_swe, fallbacks), FSDEM__SAVED(fsdem_swe, max_wave), FSDEM__SAVED(fsdem_swe, max_accel),
        FSDEM__SAVED(fsdem_swe, max_speed), FSDEM__SAVED(fsdem_swe, max_depth), FSDEM__SAVED(fsdem_swe, wet_cells),
        FSDEM__SAVED(fsdem_swe, vol_boundary), FSDEM__SAVED(fsdem_swe, vol_source), FSDEM__SAVED(fsdem_swe, vol_clipped),
        FSDEM__SAVED(fsdem_swe, rain), FSDEM__SAVED(fsdem_swe, sources_used)};
    fsdem_swe *s = (fsdem_swe *)object;
    const fsdem_allocator *al = &s->allocator;
    const int commit = io->mode == FSDEM__RESTART_COMMIT;
    const size_t cells = sizeof(fsdem_real) * (size_t)s->n;
    int grid[2], has_manning = s->manning != NULL, ns = s->src_count, next_id = s->src_next_id, ng = s->gauge_count;
    int side, k;
    fsdem__swe_src *src;
    fsdem_real *manning, *xy;
    fsdem__restart_tag(io, "SWE1");
    grid[0] = s->nx;
    grid[1] = s->ny;
    fsdem__restart_value(io, grid, sizeof grid);
    if (io->mode == FSDEM__RESTART_CHECK && io->res == FSDEM_OK && (grid[0] != s->nx || grid[1] != s->ny))
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "the grid has %d x %d cells in the save and %d x %d in the object (create the object from "
                            "the desc it was saved with)",
                            grid[0], grid[1], s->nx, s->ny);
    fsdem__restart_same_fields(io, s, same, 15);
    if (io->mode == FSDEM__RESTART_CHECK && s->gauges.file && !io->unchecked) /* a put-back keeps it (fsdem__restart_gauges) */
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "the object has a gauge file open: close it (fsdem_swe_gauges_close) before restoring and "
                            "open it again afterwards");
    if (io->mode == FSDEM__RESTART_COMMIT && io->unchecked) fsdem__series_drop(&s->gauges);

    fsdem__restart_fields(io, s, state, 14);

    /* the state, exactly, in place */
    fsdem__restart_data(io, s->eta, cells);
    fsdem__restart_data(io, s->qx, cells);
    fsdem__restart_data(io, s->qy, cells);
    fsdem__restart_data(io, s->bed, cells);
    fsdem__restart_data(io, s->sx, cells);
    fsdem__restart_data(io, s->sy, cells);
    fsdem__restart_swe_masks(io, s);

    /* per-cell Manning: kept in place when the object has the array, else a fresh one */
    fsdem__restart_int_in(io, &has_manning, 0, 1, "per-cell Manning flag");
    manning = has_manning && !s->manning ? (fsdem_real *)fsdem__restart_block(io, al, cells) : NULL;
    if (commit && !has_manning) {
        fsdem__free(al, s->manning, cells);
        s->manning = NULL;
    } else if (commit && manning)
        s->manning = manning;
    if (has_manning) fsdem__restart_data(io, s->manning, cells);

    for (side = 0; side < 4 && io->res == FSDEM_OK; ++side) {
        fsdem__swe_bnd *b = &s->bnd[side];
        int type = (int)b->type;
        fsdem_real value = b->value;
        fsdem__restart_int_in(io, &type, 0, FSDEM_SWE_BC_STAGE, "boundary type");
        fsdem__restart_value(io, &value, sizeof value);
        fsdem__restart_swe_series(io, s, &b->t, &b->v, &b->n, "boundary series length");
        if (commit) {
            b->type = (fsdem_swe_bc)type;
            b->value = value;
        }
    }

    /* point sources and gauge positions (the gauge file is not part of the state), into the object's
       arrays when they hold them, else into fresh ones */
    fsdem__restart_count(io, &ns, 1 << 24, sizeof(fsdem_real) + 4 * sizeof(int), "point source count");
    fsdem__restart_value(io, &next_id, sizeof next_id);
    src = ns <= s->src_capacity ? s->src : (fsdem__swe_src *)fsdem__restart_block(io, al, sizeof(fsdem__swe_src) * (size_t)ns);
    for (k = 0; k < ns && io->res == FSDEM_OK; ++k) {
        fsdem__swe_src q;
        if (io->mode == FSDEM__RESTART_WRITE) q = s->src[k];
        else memset(&q, 0, sizeof q);
        fsdem__restart_value(io, &q.discharge, sizeof q.discharge);
        fsdem__restart_int_in(io, &q.cell, 0, s->n - 1, "point source cell");
        fsdem__restart_value(io, &q.id, sizeof q.id);
        fsdem__restart_int_in(io, &q.active, 0, 1, "point source active flag");
        if (io->mode != FSDEM__RESTART_WRITE && k < s->src_count) { /* its series into the object's source k's */
            q.t = s->src[k].t;
            q.v = s->src[k].v;
            q.n = s->src[k].n;
        }
        fsdem__restart_swe_series(io, s, &q.t, &q.v, &q.n, "point source series length");
        if (commit) src[k] = q;
    }
    fsdem__restart_count(io, &ng, 1 << 24, 2 * sizeof(fsdem_real), "gauge count");
    xy = ng <= s->gauge_capacity ? s->gauge : (fsdem_real *)fsdem__restart_block(io, al, 2 * sizeof(fsdem_real) * (size_t)ng);
    if (commit) {
        for (k = ns; k < s->src_count; ++k) fsdem__swe_free_series(s, &s->src[k].t, &s->src[k].v, &s->src[k].n);
        if (src != s->src) {
            fsdem__free(al, s->src, sizeof(fsdem__swe_src) * (size_t)s->src_capacity);
            s->src = src;
            s->src_capacity = ns;
        }
        s->src_count = ns;
        s->src_next_id = next_id;
        if (xy != s->gauge) {
            fsdem__free(al, s->gauge, 2 * sizeof(fsdem_real) * (size_t)s->gauge_capacity);
            s->gauge = xy;
            s->gauge_capacity = ng;
        }
        s->gauge_count = ng;
    }
    fsdem__restart_data(io, s->gauge, 2 * sizeof(fsdem_real) * (size_t)ng);
    fsdem__restart_tag(io, "SWE.");
}
