/* ---- >>restart_swe_dem : SWE-DEM coupler ---- */

/* A coupler's file holds the coupled run: the SWE, then the DEM (restored into the solvers the
   coupler was created with), then the coupler's own state: counters, the last step, the impulse
   given to the water and the per-particle force records and reactions (fsdem_swe_dem_get_force and
   the next step's impulse read them). Configuration: beta, two_way, heave_damping, max_substeps and
   the water's density, gravity and dry depth taken at creation, compared. Not saved: the solver
   pointers, the allocator, log and message. */
static void fsdem__restart_swe_dem(fsdem__restart *io, void *object) {
    fsdem_swe_dem *c = (fsdem_swe_dem *)object;
    const int commit = io->mode == FSDEM__RESTART_COMMIT;
    int count = c->force_capacity, k;
    fsdem_swe_dem_force *force;
    fsdem_vec3 *reaction;
    fsdem__restart_tag(io, "SWD1");
    io->section = "shallow water";
    fsdem__restart_swe(io, c->desc.swe);
    io->section = "debris (DEM)";
    fsdem__restart_dem(io, c->desc.dem);
    io->section = NULL;
    fsdem__restart_same_real(io, c->desc.beta, "beta");
    fsdem__restart_same_int(io, c->desc.two_way, "two_way");
    fsdem__restart_same_real(io, c->desc.heave_damping, "heave_damping");
    fsdem__restart_same_ll(io, c->desc.max_substeps, "max_substeps");
    fsdem__restart_same_real(io, c->rho, "swe.density");
    fsdem__restart_same_real(io, c->g, "swe.gravity");
    fsdem__restart_same_real(io, c->dry, "swe.dry_depth");
    fsdem__restart_data(io, &c->steps, sizeof c->steps);
    fsdem__restart_data(io, &c->substeps, sizeof c->substeps);
    fsdem__restart_data(io, &c->substeps_total, sizeof c->substeps_total);
    fsdem__restart_data(io, &c->dt_last, sizeof c->dt_last);
    fsdem__restart_data(io, &c->in_water, sizeof c->in_water);
    fsdem__restart_data(io, &c->impulse, sizeof c->impulse);
    fsdem__restart_count(io, &count, 1 << 29, sizeof(int) + 5 * sizeof(fsdem_vec3) + 3 * sizeof(fsdem_real), "force record count");
    {
        int records = c->records;
        fsdem__restart_data(io, &records, sizeof records);
        if (io->res == FSDEM_OK && (records < 0 || records > count)) fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "bad record count");
        if (commit) c->records = records;
    }
    force = (fsdem_swe_dem_force *)fsdem__restart_block(io, &c->allocator, sizeof *force * (size_t)count);
    reaction = (fsdem_vec3 *)fsdem__restart_block(io, &c->allocator, sizeof *reaction * (size_t)count);
    if (commit) {
        fsdem__free(&c->allocator, c->force, sizeof *force * (size_t)c->force_capacity);
        fsdem__free(&c->allocator, c->reaction, sizeof *reaction * (size_t)c->force_capacity);
        c->force = force;
        c->reaction = reaction;
        c->force_capacity = count;
        if (force) memset(force, 0, sizeof *force * (size_t)count);
    }
    for (k = 0; k < count && io->res == FSDEM_OK; ++k) {
        fsdem_swe_dem_force scratch, *f = io->mode == FSDEM__RESTART_WRITE || commit ? &c->force[k] : &scratch;
        fsdem__restart_data(io, &f->id, sizeof f->id);
        fsdem__restart_data(io, &f->buoyancy, sizeof f->buoyancy);
        fsdem__restart_data(io, &f->hydrostatic, sizeof f->hydrostatic);
        fsdem__restart_data(io, &f->dynamic, sizeof f->dynamic);
        fsdem__restart_data(io, &f->heave, sizeof f->heave);
        fsdem__restart_data(io, &f->submerged_volume, sizeof f->submerged_volume);
        fsdem__restart_data(io, &f->frontal_area, sizeof f->frontal_area);
        fsdem__restart_data(io, &f->surface, sizeof f->surface);
        fsdem__restart_data(io, &f->in_water, sizeof f->in_water);
    }
    fsdem__restart_data(io, c->reaction, sizeof(fsdem_vec3) * (size_t)count);
    fsdem__restart_tag(io, "SWD.");
}
