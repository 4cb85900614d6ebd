/* ---- >>restart_dem : discrete elements ---- */

/* One neighbour list: its rows and entries, the row offsets, the row of each entry, the partner keys
   with their HELD bits and the tangential springs (zero where not HELD: they mean nothing there and
   may be uninitialised), exactly as they are: the entries, their order and their springs decide the
   next steps, and a rebuild forced at the restore would rebuild at other positions than the
   uninterrupted run does. While the lists are current (not `stale`) they have one row per particle.
   *entries gets the saved number of entries; returns the longest saved row. */
static int fsdem__restart_dem_list(fsdem__restart *io, fsdem_dem *d, fsdem__dem_list *l, int pairs, int n, int stale,
                                   int walls, int *entries) {
    const char *name = pairs ? "particle-pair list" : "particle-wall list";
    const unsigned char *start = NULL;
    int rows = l->rows, count = l->count, longest = 0, i, k;
    fsdem__restart_count(io, &rows, FSDEM__DEM_MAX_PARTICLES, sizeof(int), pairs ? "pair-list rows" : "wall-list rows");
    fsdem__restart_count(io, &count, 1 << 30, 2 * sizeof(int) + sizeof(fsdem_vec3),
                         pairs ? "pair-list entries" : "wall-list entries");
    *entries = count;
    if (io->res != FSDEM_OK) return 0;
    if (io->mode == FSDEM__RESTART_CHECK && ((!stale && rows != n) || (rows == 0 && count != 0)))
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "the %s has %d rows and %d entries for %d particles (corrupted data)",
                            name, rows, count, n);
    if (io->mode == FSDEM__RESTART_RESERVE) {
        if (rows > 0)
            fsdem__restart_need(io, fsdem__grow(&d->allocator, (void **)&l->start, &l->start_capacity,
                                                l->rows > 0 ? l->rows + 1 : 0, rows + 1, sizeof(int)), name);
        while (io->res == FSDEM_OK && l->capacity < count) fsdem__restart_need(io, fsdem__dem_list_grow(d, l), name);
    }
    if (rows > 0) {
        start = fsdem__restart_peek(io, sizeof(int) * (size_t)(rows + 1));
        for (i = 0; start && i < rows; ++i) {
            const int a = fsdem__restart_int_at(start, i), b = fsdem__restart_int_at(start, i + 1);
            if (io->mode == FSDEM__RESTART_CHECK && (a > b || (i == 0 && a != 0) || (i == rows - 1 && b != count))) {
                fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "the %s has bad row offsets at row %d (corrupted data)", name, i);
                start = NULL;
            } else if (b - a > longest)
                longest = b - a;
        }
        fsdem__restart_data(io, l->start, sizeof(int) * (size_t)(rows + 1));
    }
    if (io->mode == FSDEM__RESTART_CHECK && start) {
        /* each entry in its row; pairs name a later particle, wall entries a wall and a face */
        const unsigned char *first = fsdem__restart_peek(io, 2 * sizeof(int) * (size_t)count);
        for (i = 0; first && i < rows; ++i)
            for (k = fsdem__restart_int_at(start, i); k < fsdem__restart_int_at(start, i + 1); ++k) {
                const int key = fsdem__restart_int_at(first, (long)count + k), partner = FSDEM__DEM_PARTNER(key);
                const int bad = pairs ? partner <= i || partner >= rows
                                      : partner / 8 >= walls || partner % 8 >= 2 * d->desc.dim;
                if (fsdem__restart_int_at(first, k) != i || key < 0 || bad) {
                    fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "the %s has a bad entry %d (corrupted data)", name, k);
                    first = NULL;
                    break;
                }
            }
    }
    fsdem__restart_data(io, l->first, sizeof(int) * (size_t)count);
    fsdem__restart_data(io, l->key, sizeof(int) * (size_t)count);
    if (io->mode == FSDEM__RESTART_WRITE) /* a spring without its HELD bit means nothing: saved as 0 */
        for (k = 0; k < count; ++k) {
            fsdem_vec3 spring = fsdem__dem_spring(l, k);
            fsdem__restart_data(io, &spring, sizeof spring);
        }
    else
        fsdem__restart_data(io, l->history, sizeof(fsdem_vec3) * (size_t)count);
    if (io->mode == FSDEM__RESTART_COMMIT) {
        l->rows = rows;
        l->count = count;
    }
    return longest;
}

/* Everything of a DEM, in order. State: time, dt, counters, the neighbour-list bookkeeping (x_ref,
   max_disp2, need_rebuild, skin, r_max, walls' `moved`), forces_valid and forces_cleared with the
   forces and torques of the last evaluation (the next Verlet kick uses them), external loads,
   materials with their pair table (the Hertz damping calibration is costly and its result must be
   the same bits), walls, particles, both neighbour lists and the inert pairs. Configuration: the
   desc fields that steps read, compared. Not saved, rebuilt or rewritten before use: the cell grid,
   the pair scratch (found), the wall-hit scratch and the arena (reserved here for the next force
   evaluation), the previous lists pp_old and pw_old (storage the next rebuild fills), the
   predictor-corrector's x0, v0, w0, fa, ta and the walls' force_a (written at the start of each
   such step), capacities, the allocator, log and message. SDF walls keep the object's callbacks. */
static void fsdem__restart_dem(fsdem__restart *io, void *object) {
    static const fsdem__field same[22] = {
        FSDEM__SAME(fsdem_dem, dim, INT), FSDEM__SAME(fsdem_dem, domain_min, VEC3), FSDEM__SAME(fsdem_dem, domain_max, VEC3),
        FSDEM__SAME(fsdem_dem, gravity, VEC3), FSDEM__SAME(fsdem_dem, law, INT), FSDEM__SAME(fsdem_dem, integrator, INT),
        FSDEM__SAME(fsdem_dem, dt_rule, INT), FSDEM__SAME(fsdem_dem, dt_param, REAL), FSDEM__SAME(fsdem_dem, skin, REAL),
        FSDEM__SAME(fsdem_dem, contact_offset, REAL), FSDEM__SAME(fsdem_dem, linear_theta, REAL),
        FSDEM__SAME(fsdem_dem, linear_dx, REAL), FSDEM__SAME(fsdem_dem, linear_accel, REAL),
        FSDEM__SAME(fsdem_dem, disc_length, REAL), FSDEM__SAME(fsdem_dem, rotation, INT),
        FSDEM__SAME(fsdem_dem, tangential_damping, INT), FSDEM__SAME(fsdem_dem, tangential_history, INT),
        FSDEM__SAME(fsdem_dem, coulomb_limit, INT), FSDEM__SAME(fsdem_dem, linear_stiffness, INT),
        FSDEM__SAME(fsdem_dem, periodic[0], INT), FSDEM__SAME(fsdem_dem, periodic[1], INT),
        FSDEM__SAME(fsdem_dem, periodic[2], INT)};
    static const fsdem__field state[10] = {
        FSDEM__SAVED(fsdem_dem, dt), FSDEM__SAVED(fsdem_dem, time), FSDEM__SAVED(fsdem_dem, steps),
        FSDEM__SAVED(fsdem_dem, rebuilds), FSDEM__SAVED(fsdem_dem, stable_dt), FSDEM__SAVED(fsdem_dem, dt_warned),
        FSDEM__SAVED(fsdem_dem, next_id), FSDEM__SAVED(fsdem_dem, skin), FSDEM__SAVED(fsdem_dem, r_max),
        FSDEM__SAVED(fsdem_dem, max_disp2)};
    static const fsdem__field state1[7] = {
        FSDEM__SAVED(fsdem_dem, forces_valid), FSDEM__SAVED(fsdem_dem, rolling), FSDEM__SAVED(fsdem_dem, external),
        FSDEM__SAVED(fsdem_dem, forces_cleared), FSDEM__SAVED(fsdem_dem, contacts), FSDEM__SAVED(fsdem_dem, wall_contacts),
        FSDEM__SAVED(fsdem_dem, max_overlap)};
    fsdem_dem *d = (fsdem_dem *)object;
    const int reserve = io->mode == FSDEM__RESTART_RESERVE, commit = io->mode == FSDEM__RESTART_COMMIT;
    int nm = d->material_count, nw = d->wall_count, n = d->n, stale = d->need_rebuild, inert = d->inert_count;
    int k, longest, pairs = 0, wall_entries = 0;
    fsdem__restart_tag(io, "DEM1");
    fsdem__restart_same_fields(io, d, same, 22);

    fsdem__restart_fields(io, d, state, 10);
    fsdem__restart_int_in(io, &stale, 0, 1, "need_rebuild");
    fsdem__restart_fields(io, d, state1, 7);
    if (commit) d->need_rebuild = stale;

    /* materials and their pair table */
    fsdem__restart_count(io, &nm, 46340, sizeof(fsdem_dem_material), "material count");
    if (reserve && nm > 0) {
        fsdem__restart_need(io, fsdem__grow(&d->allocator, (void **)&d->materials, &d->material_capacity, d->material_count,
                                            nm, sizeof(fsdem_dem_material)), "the materials");
        fsdem__restart_need(io, fsdem__grow(&d->allocator, (void **)&d->pairs, &d->pair_capacity,
                                            d->material_count * d->material_count, nm * nm, sizeof(fsdem__dem_pair)),
                            "the materials");
    }
    fsdem__restart_data(io, d->materials, sizeof(fsdem_dem_material) * (size_t)nm);
    fsdem__restart_data(io, d->pairs, sizeof(fsdem__dem_pair) * (size_t)nm * (size_t)nm);
    if (commit) {
        d->material_count = nm;
        fsdem__dem_pair_flags(d);
    }

    /* walls: geometry where it has moved to, velocity, forces and impulses */
    fsdem__restart_count(io, &nw, FSDEM__DEM_HELD / 8, 4 * sizeof(int) + 6 * sizeof(fsdem_vec3), "wall count");
    if (reserve && nw > 0)
        fsdem__restart_need(io, fsdem__grow(&d->allocator, (void **)&d->walls, &d->wall_capacity, d->wall_count, nw,
                                            sizeof(fsdem__dem_wall)), "the walls");
    for (k = 0; k < nw && io->res == FSDEM_OK; ++k) {
        fsdem__dem_wall w;
        int type, material;
        if (io->mode == FSDEM__RESTART_WRITE) w = d->walls[k];
        else memset(&w, 0, sizeof w);
        type = (int)w.d.type;
        material = w.d.material;
        fsdem__restart_int_in(io, &type, 0, FSDEM_DEM_WALL_TYPE_SDF, "wall type");
        fsdem__restart_value(io, &w.d.a, sizeof w.d.a);
        fsdem__restart_value(io, &w.d.b, sizeof w.d.b);
        fsdem__restart_value(io, &w.d.c, sizeof w.d.c);
        fsdem__restart_value(io, &w.d.velocity, sizeof w.d.velocity);
        fsdem__restart_int_in(io, &material, 0, nm - 1, "wall material");
        fsdem__restart_int_in(io, &w.active, 0, 1, "wall active flag");
        fsdem__restart_value(io, &w.force, sizeof w.force);
        fsdem__restart_value(io, &w.impulse, sizeof w.impulse);
        fsdem__restart_value(io, &w.moved, sizeof w.moved);
        if (io->mode != FSDEM__RESTART_WRITE && io->res == FSDEM_OK && type == FSDEM_DEM_WALL_TYPE_SDF) {
            if (k >= d->wall_count || d->walls[k].d.type != FSDEM_DEM_WALL_TYPE_SDF)
                fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                                    "wall %d is an SDF wall in the save: add the same SDF walls (fsdem_dem_wall_sdf), in the "
                                    "same order, to the object before restoring",
                                    k);
            else {
                w.d.sdf = d->walls[k].d.sdf; /* wall k of the object is overwritten only below */
                w.d.sdf_user = d->walls[k].d.sdf_user;
            }
        }
        if (commit) {
            w.d.type = (fsdem_dem_wall_type)type;
            w.d.material = material;
            d->walls[k] = w;
        }
    }
    if (commit) d->wall_count = nw;

    /* particles */
    fsdem__restart_count(io, &n, FSDEM__DEM_MAX_PARTICLES, 8 * sizeof(fsdem_vec3) + 4 * sizeof(fsdem_real),
                          "particle count");
    if (reserve) fsdem__restart_need(io, fsdem__dem_reserve_particles(d, n > 0 ? n : 1), "the particles");
    fsdem__restart_data(io, d->id, sizeof(int) * (size_t)n);
    fsdem__restart_ints(io, d->material, n, 0, nm - 1, "material of particle");
    fsdem__restart_ints(io, d->old_of, n, -1, FSDEM__RESTART_INT_MAX, "previous row of particle");
    fsdem__restart_flags(io, d->fixed, n, 1, "fixed flag of particle");
    fsdem__restart_data(io, d->x, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->v, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->w, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->f, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->t, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->fext, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->text, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->x_ref, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->r, sizeof(fsdem_real) * (size_t)n);
    fsdem__restart_data(io, d->m, sizeof(fsdem_real) * (size_t)n);
    fsdem__restart_data(io, d->inv_m, sizeof(fsdem_real) * (size_t)n);
    fsdem__restart_data(io, d->inv_i, sizeof(fsdem_real) * (size_t)n);
    if (commit) d->n = n;

    /* neighbour lists with contact history, and the pairs of fixed particles listed aside */
    fsdem__restart_dem_list(io, d, &d->pp, 1, n, stale, nw, &pairs);
    longest = fsdem__restart_dem_list(io, d, &d->pw, 0, n, stale, nw, &wall_entries);
    fsdem__restart_count(io, &inert, 1 << 29, 2 * sizeof(int), "inert pair count");
    if (reserve && inert > 0)
        fsdem__restart_need(io, fsdem__grow(&d->allocator, (void **)&d->inert, &d->inert_capacity, 2 * d->inert_count,
                                            2 * inert, sizeof(int)), "the inert pairs");
    fsdem__restart_ints(io, d->inert, 2 * inert, 0, stale ? FSDEM__RESTART_INT_MAX : n - 1, "inert pair entry");
    if (commit) d->inert_count = inert;
    /* scratch of a force evaluation before the next rebuild, as fsdem__dem_rebuild reserves it */
    if (reserve && io->res == FSDEM_OK) {
        if (longest > 0)
            fsdem__restart_need(io, fsdem__grow(&d->allocator, (void **)&d->hits, &d->hit_capacity, 0, longest,
                                                sizeof(fsdem__dem_wall_hit)), "the wall contacts");
        fsdem__restart_need(io, fsdem__arena_reserve(&d->allocator, &d->arena,
                                                     fsdem__arena_bytes(sizeof(int) * (size_t)pairs) +
                                                         fsdem__arena_bytes(sizeof(fsdem__dem_batch))),
                            "the force evaluation");
    }
    fsdem__restart_tag(io, "DEM.");
}
