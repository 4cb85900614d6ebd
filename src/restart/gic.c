/* ---- >>restart_gic : Granule-In-Cell coupler ---- */

/* The two solvers, then the coupler's fractions, counters and last step's tally (its drag limit
   bounds the next step). The force records are rebuilt by the next step's evaluations. */
static void fsdem__restart_gic(fsdem__restart *io, void *object) {
    fsdem_gic *c = (fsdem_gic *)object;
    const size_t cells = sizeof(fsdem_real) * (size_t)c->grid.ncell;
    fsdem__restart_tag(io, "GIC1");
    io->section = "water (PIC)";
    fsdem__restart_pic(io, c->desc.pic);
    io->section = "granules (DEM)";
    fsdem__restart_dem(io, c->desc.dem);
    io->section = NULL;
    fsdem__restart_same_int(io, (int)c->desc.drag, "drag");
    fsdem__restart_same_real(io, c->desc.drag_scale, "drag_scale");
    fsdem__restart_same_int(io, c->desc.virtual_mass, "virtual_mass");
    fsdem__restart_same_real(io, c->desc.viscosity, "viscosity");
    fsdem__restart_same_real(io, c->desc.max_solid_fraction, "max_solid_fraction");
    fsdem__restart_same_real(io, c->desc.cfl, "cfl");
    fsdem__restart_same_real(io, c->desc.max_dt_ratio, "max_dt_ratio");
    fsdem__restart_same_real(io, c->desc.drag_dt_fraction, "drag_dt_fraction");
    fsdem__restart_same_ll(io, c->desc.max_substeps, "max_substeps");
    fsdem__restart_data(io, c->solid, cells);
    fsdem__restart_data(io, c->porosity, cells);
    fsdem__restart_data(io, &c->max_solid, sizeof c->max_solid);
    fsdem__restart_data(io, &c->solid_volume, sizeof c->solid_volume);
    fsdem__restart_data(io, &c->last.pressure, sizeof c->last.pressure);
    fsdem__restart_data(io, &c->last.drag, sizeof c->last.drag);
    fsdem__restart_data(io, &c->last.virtual_mass, sizeof c->last.virtual_mass);
    fsdem__restart_data(io, &c->last.to_fluid, sizeof c->last.to_fluid);
    fsdem__restart_data(io, &c->last.lost, sizeof c->last.lost);
    fsdem__restart_data(io, &c->last.drag_dt, sizeof c->last.drag_dt);
    fsdem__restart_data(io, &c->last.wet, sizeof c->last.wet);
    fsdem__restart_data(io, &c->steps, sizeof c->steps);
    fsdem__restart_data(io, &c->substeps, sizeof c->substeps);
    fsdem__restart_data(io, &c->substeps_total, sizeof c->substeps_total);
    fsdem__restart_data(io, &c->dt_last, sizeof c->dt_last);
    if (io->mode == FSDEM__RESTART_COMMIT) c->records = 0;
    fsdem__restart_tag(io, "GIC.");
}
