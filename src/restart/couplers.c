/* ---- >>restart_couplers : the four couplers, by their field tables ---- */

/* A coupler's file holds the coupled run: its tag, the fluid, then the DEM in full (restored into the
   solvers the coupler was created with), then the coupler's own part, listed in tables: its desc
   (with the values resolved at creation) compared field by field, its counters and figures, and the
   records of its last update that the next step or fsdem_X_get_force reads. Not saved: the solver
   pointers, the claims, the allocator, log and message, the CPU times, and what every step rebuilds
   (pair lists, grids, cuts). */

/* `count` records of the coupler's kind at `records` (NULL while checking and reserving: nothing is
   stored then), their saved fields. */
static void fsdem__restart_records(fsdem__restart *io, const fsdem_coupler *c, void *records, int count) {
    int k;
    for (k = 0; k < count && io->res == FSDEM_OK; ++k)
        fsdem__restart_fields(io, records ? (char *)records + (size_t)k * c->cls->record_size : NULL, c->cls->fields, c->cls->field_count);
}

/* Bytes of the saved fields of one record: the least a count of records needs of the payload. */
static size_t fsdem__restart_record_bytes(const fsdem_coupler *c) {
    size_t bytes = 0;
    int k;
    for (k = 0; k < c->cls->field_count; ++k)
        if (c->cls->fields[k].saved) bytes += c->cls->fields[k].size;
    return bytes;
}

/* The start of every coupler's file: the tag, the fluid (`fluid` visits it, in the section named
   `fluid_section`), the DEM, and the desc fields in `same`. */
static void fsdem__restart_coupler(fsdem__restart *io, fsdem_coupler *c, const char *tag, fsdem__restart_visit_fn fluid,
                                   const char *fluid_section, const char *dem_section, const fsdem__field *same, int n) {
    fsdem__restart_tag(io, tag);
    io->section = fluid_section;
    fluid(io, c->fluid);
    io->section = dem_section;
    fsdem__restart_dem(io, c->dem);
    io->section = NULL;
    fsdem__restart_same_fields(io, c, same, n);
}

/* Where records read in a restore go: the object's in WRITE and COMMIT, nowhere otherwise. */
static void *fsdem__restart_here(const fsdem__restart *io, void *records) {
    return io->mode == FSDEM__RESTART_WRITE || io->mode == FSDEM__RESTART_COMMIT ? records : NULL;
}

/* SWE-DEM: the counters, the last step, the impulse given to the water, and the force records and
   reactions of its last update (files of older builds hold them for every slot of the arrays: `count`
   slots, of which the first `records` are records). */
static void fsdem__restart_swe_dem(fsdem__restart *io, void *object) {
    static const fsdem__field same[7] = {
        FSDEM__SAME(fsdem_swe_dem, beta, REAL), FSDEM__SAME(fsdem_swe_dem, two_way, INT),
        FSDEM__SAME(fsdem_swe_dem, heave_damping, REAL), FSDEM__SAME(fsdem_swe_dem, max_substeps, LL),
        FSDEM__FIELD(fsdem_swe_dem, rho, "swe.density", REAL, 1), FSDEM__FIELD(fsdem_swe_dem, g, "swe.gravity", REAL, 1),
        FSDEM__FIELD(fsdem_swe_dem, dry, "swe.dry_depth", REAL, 1)};
    static const fsdem__field state[6] = {
        FSDEM__SAVED(fsdem_swe_dem, head.steps), FSDEM__SAVED(fsdem_swe_dem, head.substeps),
        FSDEM__SAVED(fsdem_swe_dem, head.substeps_total), FSDEM__SAVED(fsdem_swe_dem, head.dt_last),
        FSDEM__SAVED(fsdem_swe_dem, wet), FSDEM__SAVED(fsdem_swe_dem, impulse)};
    fsdem_swe_dem *c = (fsdem_swe_dem *)object;
    const int commit = io->mode == FSDEM__RESTART_COMMIT;
    int count = c->head.records, records = c->head.records;
    fsdem__restart_coupler(io, &c->head, "SWD1", fsdem__restart_swe, "shallow water", "debris (DEM)", same, 7);
    fsdem__restart_fields(io, c, state, 6);
    fsdem__restart_count(io, &count, 1 << 29, fsdem__restart_record_bytes(&c->head) + sizeof(fsdem_vec3), "force record count");
    fsdem__restart_value(io, &records, sizeof records); /* checked before it is used */
    if (io->res == FSDEM_OK && (records < 0 || records > count)) fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "bad record count");
    if (count > c->force_capacity) { /* else into the object's arrays */
        fsdem_swe_dem_force *force = (fsdem_swe_dem_force *)fsdem__restart_block(io, &c->head.allocator, sizeof *force * (size_t)count);
        fsdem_vec3 *reaction = (fsdem_vec3 *)fsdem__restart_block(io, &c->head.allocator, sizeof *reaction * (size_t)count);
        if (commit) {
            fsdem__free(&c->head.allocator, c->force, sizeof *force * (size_t)c->force_capacity);
            fsdem__free(&c->head.allocator, c->reaction, sizeof *reaction * (size_t)c->force_capacity);
            c->force = force;
            c->reaction = reaction;
            c->force_capacity = count;
        }
    }
    if (commit) {
        if (c->force) memset(c->force, 0, sizeof *c->force * (size_t)count);
        c->head.record = c->force;
        c->head.records = records;
    }
    fsdem__restart_records(io, &c->head, fsdem__restart_here(io, c->force), count);
    fsdem__restart_data(io, c->reaction, sizeof(fsdem_vec3) * (size_t)count);
    fsdem__restart_tag(io, "SWD.");
}

/* MPS-DEM: the counters, the tally and the force records of its last update (a step recomputes them
   first, so they serve fsdem_mps_dem_get_force until then); the pair lists and the grid are rebuilt
   by every update. */
static void fsdem__restart_mps_dem(fsdem__restart *io, void *object) {
    static const fsdem__field same[5] = {
        FSDEM__SAME(fsdem_mps_dem, drag, INT), FSDEM__SAME(fsdem_mps_dem, averaging_radius, REAL),
        FSDEM__SAME(fsdem_mps_dem, min_porosity, REAL), FSDEM__SAME(fsdem_mps_dem, drag_dt_fraction, REAL),
        FSDEM__SAME(fsdem_mps_dem, max_substeps, LL)};
    static const fsdem__field state[10] = {
        FSDEM__SAVED(fsdem_mps_dem, head.steps), FSDEM__SAVED(fsdem_mps_dem, head.substeps),
        FSDEM__SAVED(fsdem_mps_dem, head.substeps_total), FSDEM__SAVED(fsdem_mps_dem, tally.pairs),
        FSDEM__SAVED(fsdem_mps_dem, head.dt_last), FSDEM__SAVED(fsdem_mps_dem, tally.drag_dt),
        FSDEM__SAVED(fsdem_mps_dem, tally.wet), FSDEM__SAVED(fsdem_mps_dem, tally.drag_sum),
        FSDEM__SAVED(fsdem_mps_dem, tally.pressure_sum), FSDEM__SAVED(fsdem_mps_dem, tally.fluid_sum)};
    fsdem_mps_dem *c = (fsdem_mps_dem *)object;
    int count = c->head.records;
    fsdem_mps_dem_force *force;
    fsdem__restart_coupler(io, &c->head, "MPD1", fsdem__restart_mps, "water (MPS)", "sediment (DEM)", same, 5);
    fsdem__restart_fields(io, c, state, 10);
    fsdem__restart_count(io, &count, 1 << 29, fsdem__restart_record_bytes(&c->head), "force record count");
    force = count <= c->force_cap ? c->force : (fsdem_mps_dem_force *)fsdem__restart_block(io, &c->head.allocator, sizeof *force * (size_t)count);
    if (io->mode == FSDEM__RESTART_COMMIT) {
        if (force != c->force) {
            fsdem__free(&c->head.allocator, c->force, sizeof *force * (size_t)c->force_cap);
            c->force = force;
            c->force_cap = count;
        }
        if (force) memset(force, 0, sizeof *force * (size_t)count);
        c->head.record = force;
        c->head.records = count;
    }
    fsdem__restart_records(io, &c->head, fsdem__restart_here(io, c->force), count);
    fsdem__restart_tag(io, "MPD.");
}

/* PIC-DEM: the counters, the viscous limit and the loads of its last step. Its cut (faces, J,
   references) is redone at the start of every step over the PIC's reset coupling arrays, so it is
   not saved; the viscous limit of the saved step is: the run goes on bit for bit. */
static void fsdem__restart_pic_dem(fsdem__restart *io, void *object) {
    static const fsdem__field same[5] = {
        FSDEM__SAME(fsdem_pic_dem, dissipation, REAL), FSDEM__SAME(fsdem_pic_dem, contact_length, REAL),
        FSDEM__SAME(fsdem_pic_dem, viscous_dt_fraction, REAL), FSDEM__SAME(fsdem_pic_dem, discrete_weight, INT),
        FSDEM__SAME(fsdem_pic_dem, max_substeps, LL)};
    static const fsdem__field state[9] = {
        FSDEM__SAVED(fsdem_pic_dem, head.steps), FSDEM__SAVED(fsdem_pic_dem, head.substeps),
        FSDEM__SAVED(fsdem_pic_dem, head.substeps_total), FSDEM__SAVED(fsdem_pic_dem, dissipated),
        FSDEM__SAVED(fsdem_pic_dem, pushed), FSDEM__SAVED(fsdem_pic_dem, removed), FSDEM__SAVED(fsdem_pic_dem, head.dt_last),
        FSDEM__SAVED(fsdem_pic_dem, viscous_dt), FSDEM__SAVED(fsdem_pic_dem, force_sum)};
    fsdem_pic_dem *c = (fsdem_pic_dem *)object;
    int count = c->loaded ? c->bodies : 0, b;
    fsdem__restart_coupler(io, &c->head, "PDM1", fsdem__restart_pic, "water (PIC)", "bodies (DEM)", same, 5);
    fsdem__restart_fields(io, c, state, 9);
    fsdem__restart_count(io, &count, 1 << 29, fsdem__restart_record_bytes(&c->head), "body load count");
    if (io->mode == FSDEM__RESTART_RESERVE) fsdem__restart_need(io, fsdem__pic_dem_reserve_bodies(c, count), "the bodies' records");
    if (io->mode == FSDEM__RESTART_COMMIT) { /* the next step cuts afresh, as every step does */
        c->face_count = c->jac_count = 0;
        c->bodies = count;
        c->loaded = count > 0;
        for (b = 0; b <= count; ++b) c->face_start[b] = c->jac_start[b] = 0;
        for (b = 0; b < count; ++b) c->load[b].faces = 0;
        c->head.record = c->load;
        c->head.records = count;
    }
    fsdem__restart_records(io, &c->head, fsdem__restart_here(io, c->load), count);
    fsdem__restart_tag(io, "PDM.");
}

/* GIC: the volume fractions, the last step's tally (its drag limit bounds the next step) and the
   counters. The force records are rebuilt by the next step's evaluations. */
static void fsdem__restart_gic(fsdem__restart *io, void *object) {
    static const fsdem__field same[9] = {
        FSDEM__SAME(fsdem_gic, drag, INT), FSDEM__SAME(fsdem_gic, drag_scale, REAL), FSDEM__SAME(fsdem_gic, virtual_mass, INT),
        FSDEM__FIELD(fsdem_gic, mu, "viscosity", REAL, 1), FSDEM__SAME(fsdem_gic, max_solid_fraction, REAL),
        FSDEM__SAME(fsdem_gic, cfl, REAL), FSDEM__SAME(fsdem_gic, max_dt_ratio, REAL),
        FSDEM__SAME(fsdem_gic, drag_dt_fraction, REAL), FSDEM__SAME(fsdem_gic, max_substeps, LL)};
    static const fsdem__field state[13] = {
        FSDEM__SAVED(fsdem_gic, max_solid), FSDEM__SAVED(fsdem_gic, solid_volume), FSDEM__SAVED(fsdem_gic, last.pressure),
        FSDEM__SAVED(fsdem_gic, last.drag), FSDEM__SAVED(fsdem_gic, last.virtual_mass), FSDEM__SAVED(fsdem_gic, last.to_fluid),
        FSDEM__SAVED(fsdem_gic, last.lost), FSDEM__SAVED(fsdem_gic, last.drag_dt), FSDEM__SAVED(fsdem_gic, last.wet),
        FSDEM__SAVED(fsdem_gic, head.steps), FSDEM__SAVED(fsdem_gic, head.substeps), FSDEM__SAVED(fsdem_gic, head.substeps_total),
        FSDEM__SAVED(fsdem_gic, head.dt_last)};
    fsdem_gic *c = (fsdem_gic *)object;
    const size_t cells = sizeof(fsdem_real) * (size_t)c->grid.ncell;
    fsdem__restart_coupler(io, &c->head, "GIC1", fsdem__restart_pic, "water (PIC)", "granules (DEM)", same, 9);
    fsdem__restart_data(io, c->solid, cells);
    fsdem__restart_data(io, c->porosity, cells);
    fsdem__restart_fields(io, c, state, 13);
    if (io->mode == FSDEM__RESTART_COMMIT) c->head.records = 0;
    fsdem__restart_tag(io, "GIC.");
}

