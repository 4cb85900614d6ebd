/* ---- >>restart_mps_dem : MPS-DEM coupler ---- */

/* The two solvers, then the coupler's counters and the force records of its last update (a step
   recomputes them first, so they only serve fsdem_mps_dem_get_force until then). The pair lists
   and the grid are rebuilt by every update. */
static void fsdem__restart_mps_dem(fsdem__restart *io, void *object) {
    fsdem_mps_dem *c = (fsdem_mps_dem *)object;
    const int commit = io->mode == FSDEM__RESTART_COMMIT;
    int count = c->forces, k;
    fsdem_mps_dem_force *force;
    fsdem__restart_tag(io, "MPD1");
    io->section = "water (MPS)";
    fsdem__restart_mps(io, c->desc.mps);
    io->section = "sediment (DEM)";
    fsdem__restart_dem(io, c->desc.dem);
    io->section = NULL;
    fsdem__restart_same_int(io, (int)c->desc.drag, "drag");
    fsdem__restart_same_real(io, c->desc.averaging_radius, "averaging_radius");
    fsdem__restart_same_real(io, c->desc.min_porosity, "min_porosity");
    fsdem__restart_same_real(io, c->desc.drag_dt_fraction, "drag_dt_fraction");
    fsdem__restart_same_ll(io, c->desc.max_substeps, "max_substeps");
    fsdem__restart_data(io, &c->steps, sizeof c->steps);
    fsdem__restart_data(io, &c->substeps, sizeof c->substeps);
    fsdem__restart_data(io, &c->substeps_total, sizeof c->substeps_total);
    fsdem__restart_data(io, &c->tally.pairs, sizeof c->tally.pairs);
    fsdem__restart_data(io, &c->dt_last, sizeof c->dt_last);
    fsdem__restart_data(io, &c->tally.drag_dt, sizeof c->tally.drag_dt);
    fsdem__restart_data(io, &c->tally.wet, sizeof c->tally.wet);
    fsdem__restart_data(io, &c->tally.drag_sum, sizeof c->tally.drag_sum);
    fsdem__restart_data(io, &c->tally.pressure_sum, sizeof c->tally.pressure_sum);
    fsdem__restart_data(io, &c->tally.fluid_sum, sizeof c->tally.fluid_sum);
    fsdem__restart_count(io, &count, 1 << 29, sizeof(int) + 4 * sizeof(fsdem_vec3) + 2 * sizeof(fsdem_real), "force record count");
    force = (fsdem_mps_dem_force *)fsdem__restart_block(io, &c->allocator, sizeof *force * (size_t)count);
    if (commit) {
        fsdem__free(&c->allocator, c->force, sizeof *force * (size_t)c->force_cap);
        c->force = force;
        c->forces = c->force_cap = count;
        if (force) memset(force, 0, sizeof *force * (size_t)count);
    }
    for (k = 0; k < count && io->res == FSDEM_OK; ++k) {
        fsdem_mps_dem_force scratch, *f = io->mode == FSDEM__RESTART_WRITE || commit ? &c->force[k] : &scratch;
        fsdem__restart_data(io, &f->id, sizeof f->id);
        fsdem__restart_data(io, &f->drag, sizeof f->drag);
        fsdem__restart_data(io, &f->pressure, sizeof f->pressure);
        fsdem__restart_data(io, &f->total, sizeof f->total);
        fsdem__restart_data(io, &f->fluid_velocity, sizeof f->fluid_velocity);
        fsdem__restart_data(io, &f->porosity, sizeof f->porosity);
        fsdem__restart_data(io, &f->reynolds, sizeof f->reynolds);
        fsdem__restart_data(io, &f->wet, sizeof f->wet);
    }
    fsdem__restart_tag(io, "MPD.");
}
