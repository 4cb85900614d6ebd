/* ---- >>restart_pic : PIC/FLIP ---- */

/* Everything of a PIC solver, in order. State: time, last dt, steps (they pick the sorting steps),
   the random-number state, particles with their capacity (a full capacity refuses inflow seeds) and
   APIC matrices, obstacles (polygons with their vertices) with the static face fractions, solid
   velocities and cell flags derived from them (recomputing them samples SDF callbacks), the
   coupler's arrays, cells_fresh with the fractions and level set it vouches for, the pressure (the
   initial guess of the next solve), the face velocities, effective faces and cell types (views,
   sampling and fsdem_pic_add_force read them between steps), counters and the last step's figures.
   Configuration: the grid and the desc fields that steps read, compared. Not saved, rewritten
   before use: uold, wsum, ftmp, the valid-face marks, the extrapolation queue, rhs, diag, ctmp,
   cstart and the particle scratch (ptmp, pcell, pidx; pflag is zeroed), the viscous face grids, the
   linear solvers (set up at every use), CPU times, the allocator, log and message. SDF obstacles
   keep the object's callbacks; a pressure-extra operator stays as set. */
/* The gauges of a PIC solver (positions, kinds, radii); their file is not part of the state. */
/* Point gauges (fsdem__gauges), into the object's arrays when they hold them (else fresh ones);
   refused while their file is open (`close` names the function that closes it), but for a coupled
   step's put-back (io->unchecked): its gauges are the step's, and their series stays open, the rows
   the step held dropped. */
static void fsdem__restart_gauges(fsdem__restart *io, fsdem__gauges *g, const fsdem_allocator *al, const char *close) {
    int ng = g->count, in_place;
    fsdem_vec3 *at = g->at;
    int *kind = g->kind;
    fsdem_real *radius = g->radius;
    if (io->mode == FSDEM__RESTART_CHECK && g->series.file && !io->unchecked)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "the object has a gauge file open: close it (%s) before restoring and open it again afterwards", close);
    fsdem__restart_count(io, &ng, 1 << 24, sizeof(fsdem_vec3) + sizeof(int) + sizeof(fsdem_real), "gauge count");
    in_place = ng <= g->capacity;
    if (!in_place) {
        at = (fsdem_vec3 *)fsdem__restart_block(io, al, sizeof(fsdem_vec3) * (size_t)ng);
        kind = (int *)fsdem__restart_block(io, al, sizeof(int) * (size_t)ng);
        radius = (fsdem_real *)fsdem__restart_block(io, al, sizeof(fsdem_real) * (size_t)ng);
    }
    if (io->mode == FSDEM__RESTART_COMMIT) {
        if (io->unchecked) fsdem__series_drop(&g->series);
        if (!in_place) {
            fsdem__gauges_free_arrays(g, al); /* the series stays as it is */
            g->at = at;
            g->kind = kind;
            g->radius = radius;
            g->capacity = ng;
        }
        g->count = ng;
    }
    fsdem__restart_data(io, g->at, sizeof(fsdem_vec3) * (size_t)ng);
    fsdem__restart_ints(io, g->kind, ng, FSDEM__GAUGE_LEVEL, FSDEM__GAUGE_PRESSURE, "gauge kind");
    fsdem__restart_data(io, g->radius, sizeof(fsdem_real) * (size_t)ng);
}

/* The obstacles (polygons own their vertices), written into the object's arrays where they hold
   them, else into fresh ones; SDF obstacles keep the object's callbacks. */
static void fsdem__restart_pic_obstacles(fsdem__restart *io, fsdem_pic *s) {
    const fsdem_allocator *al = &s->allocator;
    const int commit = io->mode == FSDEM__RESTART_COMMIT;
    int no = s->obst_count, k, in_place;
    fsdem__pic_obst *obst;
    fsdem__restart_count(io, &no, 1 << 20, 2 * sizeof(int) + 5 * sizeof(fsdem_vec3) + sizeof(fsdem_real), "obstacle count");
    in_place = no <= s->obst_capacity;
    obst = in_place ? s->obst : (fsdem__pic_obst *)fsdem__restart_block(io, al, sizeof(fsdem__pic_obst) * (size_t)no);
    for (k = 0; k < no && io->res == FSDEM_OK; ++k) {
        const fsdem__pic_obst *own = k < s->obst_count ? &s->obst[k] : NULL; /* the object's obstacle k */
        fsdem__pic_obst o;
        fsdem_vec3 *verts;
        int type, nv, own_verts;
        if (io->mode == FSDEM__RESTART_WRITE) o = s->obst[k];
        else memset(&o, 0, sizeof o);
        type = (int)o.d.type;
        nv = o.d.type == FSDEM_PIC_OBSTACLE_TYPE_POLYGON ? o.d.vertex_count : 0;
        fsdem__restart_int_in(io, &type, 0, FSDEM_PIC_OBSTACLE_TYPE_SDF, "obstacle type");
        fsdem__restart_value(io, &o.d.a, sizeof o.d.a);
        fsdem__restart_value(io, &o.d.b, sizeof o.d.b);
        fsdem__restart_value(io, &o.d.radius, sizeof o.d.radius);
        fsdem__restart_value(io, &o.d.velocity, sizeof o.d.velocity);
        fsdem__restart_value(io, &o.box_lo, sizeof o.box_lo);
        fsdem__restart_value(io, &o.box_hi, sizeof o.box_hi);
        fsdem__restart_count(io, &nv, 1 << 24, sizeof(fsdem_vec3), "polygon vertex count");
        if (io->mode == FSDEM__RESTART_CHECK && io->res == FSDEM_OK && (type == FSDEM_PIC_OBSTACLE_TYPE_POLYGON) != (nv >= 3))
            fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "obstacle %d has %d vertices (corrupted data)", k, nv);
        own_verts = own && own->verts && own->d.vertex_count == nv;
        verts = own_verts ? own->verts : (fsdem_vec3 *)fsdem__restart_block(io, al, sizeof(fsdem_vec3) * (size_t)nv);
        fsdem__restart_data(io, io->mode == FSDEM__RESTART_WRITE ? o.verts : verts, sizeof(fsdem_vec3) * (size_t)nv);
        if (io->mode != FSDEM__RESTART_WRITE && io->res == FSDEM_OK && type == FSDEM_PIC_OBSTACLE_TYPE_SDF) {
            if (!own || own->d.type != FSDEM_PIC_OBSTACLE_TYPE_SDF)
                fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                                    "obstacle %d is an SDF obstacle in the save: add the same SDF obstacles "
                                    "(fsdem_pic_obstacle_sdf), in the same order, to the object before restoring",
                                    k);
            else {
                o.d.sdf = own->d.sdf;
                o.d.sdf_user = own->d.sdf_user;
            }
        }
        if (commit) {
            if (own && own->verts && !own_verts) fsdem__pic_release(s, own->verts, sizeof(fsdem_vec3) * (size_t)own->d.vertex_count);
            if (!own_verts) s->bytes += sizeof(fsdem_vec3) * (size_t)nv;
            o.d.type = (fsdem_pic_obstacle_type)type;
            o.d.vertex_count = nv;
            o.d.vertices = o.verts = verts;
            obst[k] = o;
        }
    }
    if (commit) {
        for (k = no; k < s->obst_count; ++k)
            if (s->obst[k].verts) fsdem__pic_release(s, s->obst[k].verts, sizeof(fsdem_vec3) * (size_t)s->obst[k].d.vertex_count);
        if (!in_place) {
            fsdem__pic_release(s, s->obst, sizeof(fsdem__pic_obst) * (size_t)s->obst_capacity);
            s->obst = obst;
            s->obst_capacity = no;
            s->bytes += sizeof(fsdem__pic_obst) * (size_t)no;
        }
        s->obst_count = no;
    }
}

/* The particles, with their APIC matrices, into arrays of the saved capacity (a full capacity
   refuses inflow seeds): the object's own when it has that capacity, else fresh ones. */
static void fsdem__restart_pic_particles(fsdem__restart *io, fsdem_pic *s) {
    const fsdem_allocator *al = &s->allocator;
    const int commit = io->mode == FSDEM__RESTART_COMMIT, apic = s->desc.transfer == FSDEM_PIC_TRANSFER_APIC;
    int np = s->np, pcap = s->pcap, a;
    fsdem__restart_count(io, &pcap, 1 << 29, 0, "particle capacity");
    fsdem__restart_count(io, &np, pcap, 2 * sizeof(fsdem_vec3), "particle count");
    if (io->res == FSDEM_OK && pcap != s->pcap) {
        const size_t vb = sizeof(fsdem_vec3) * (size_t)pcap, ib = sizeof(int) * (size_t)pcap;
        fsdem_vec3 *px = (fsdem_vec3 *)fsdem__restart_block(io, al, vb), *pv = (fsdem_vec3 *)fsdem__restart_block(io, al, vb);
        fsdem_vec3 *pt = (fsdem_vec3 *)fsdem__restart_block(io, al, vb), *pc[3] = {NULL, NULL, NULL};
        int *pcell, *pidx;
        unsigned char *pflag;
        for (a = 0; a < 3 && apic; ++a) pc[a] = (fsdem_vec3 *)fsdem__restart_block(io, al, vb);
        pcell = (int *)fsdem__restart_block(io, al, ib);
        pidx = (int *)fsdem__restart_block(io, al, ib);
        pflag = (unsigned char *)fsdem__restart_block(io, al, (size_t)pcap);
        if (commit) {
            fsdem__pic_free_particles(s);
            s->px = px;
            s->pv = pv;
            s->ptmp = pt;
            for (a = 0; a < 3; ++a) s->pc[a] = pc[a];
            s->pcell = pcell;
            s->pidx = pidx;
            s->pflag = pflag;
            s->pcap = pcap;
            s->bytes += (apic ? 6 : 3) * vb + 2 * ib + (size_t)pcap;
        }
    }
    if (commit) {
        if (s->pflag) memset(s->pflag, 0, (size_t)pcap);
        s->np = np;
    }
    fsdem__restart_data(io, s->px, sizeof(fsdem_vec3) * (size_t)np);
    fsdem__restart_data(io, s->pv, sizeof(fsdem_vec3) * (size_t)np);
    for (a = 0; a < 3 && apic; ++a) fsdem__restart_data(io, s->pc[a], sizeof(fsdem_vec3) * (size_t)np);
}

static void fsdem__restart_pic(fsdem__restart *io, void *object) {
    static const fsdem__field same[38] = {
        FSDEM__SAME(fsdem_pic, dim, INT), FSDEM__SAME(fsdem_pic, domain_min, VEC3), FSDEM__SAME(fsdem_pic, cell_size, REAL),
        FSDEM__SAME(fsdem_pic, density, REAL), FSDEM__SAME(fsdem_pic, viscosity, REAL), FSDEM__SAME(fsdem_pic, gravity, VEC3),
        FSDEM__SAME(fsdem_pic, boundary[0], INT), FSDEM__SAME(fsdem_pic, boundary_velocity[0], VEC3),
        FSDEM__SAME(fsdem_pic, boundary[1], INT), FSDEM__SAME(fsdem_pic, boundary_velocity[1], VEC3),
        FSDEM__SAME(fsdem_pic, boundary[2], INT), FSDEM__SAME(fsdem_pic, boundary_velocity[2], VEC3),
        FSDEM__SAME(fsdem_pic, boundary[3], INT), FSDEM__SAME(fsdem_pic, boundary_velocity[3], VEC3),
        FSDEM__SAME(fsdem_pic, boundary[4], INT), FSDEM__SAME(fsdem_pic, boundary_velocity[4], VEC3),
        FSDEM__SAME(fsdem_pic, boundary[5], INT), FSDEM__SAME(fsdem_pic, boundary_velocity[5], VEC3),
        FSDEM__SAME(fsdem_pic, free_surface, INT), FSDEM__SAME(fsdem_pic, transfer, INT),
        FSDEM__SAME(fsdem_pic, flip_ratio, REAL), FSDEM__SAME(fsdem_pic, kernel, INT),
        FSDEM__SAME(fsdem_pic, particles_per_cell, INT), FSDEM__SAME(fsdem_pic, jitter, REAL),
        FSDEM__SAME(fsdem_pic, min_particles_per_cell, INT), FSDEM__SAME(fsdem_pic, max_particles_per_cell, INT),
        FSDEM__SAME(fsdem_pic, advection_order, INT), FSDEM__SAME(fsdem_pic, cfl, REAL), FSDEM__SAME(fsdem_pic, cfl_max, REAL),
        FSDEM__SAME(fsdem_pic, dt_max, REAL), FSDEM__SAME(fsdem_pic, density_projection, INT),
        FSDEM__SAME(fsdem_pic, ghost_theta_min, REAL), FSDEM__SAME(fsdem_pic, extrapolation_layers, INT),
        FSDEM__SAME(fsdem_pic, pressure_precond, INT), FSDEM__SAME(fsdem_pic, pressure_tolerance, REAL),
        FSDEM__SAME(fsdem_pic, pressure_max_iterations, INT), FSDEM__SAME(fsdem_pic, viscosity_precond, INT),
        FSDEM__SAME(fsdem_pic, viscosity_tolerance, REAL)};
    static const fsdem__field state[16] = {
        FSDEM__SAVED(fsdem_pic, time), FSDEM__SAVED(fsdem_pic, dt_last), FSDEM__SAVED(fsdem_pic, steps),
        FSDEM__SAVED(fsdem_pic, rng), FSDEM__SAVED(fsdem_pic, cells_fresh), FSDEM__SAVED(fsdem_pic, fluid_cells),
        FSDEM__SAVED(fsdem_pic, p_iters), FSDEM__SAVED(fsdem_pic, v_iters), FSDEM__SAVED(fsdem_pic, d_iters),
        FSDEM__SAVED(fsdem_pic, p_res), FSDEM__SAVED(fsdem_pic, max_div), FSDEM__SAVED(fsdem_pic, div_before),
        FSDEM__SAVED(fsdem_pic, reseeded), FSDEM__SAVED(fsdem_pic, removed), FSDEM__SAVED(fsdem_pic, refused),
        FSDEM__SAVED(fsdem_pic, moved)};
    fsdem_pic *s = (fsdem_pic *)object;
    int grid[3], a;
    size_t cells = sizeof(fsdem_real) * (size_t)s->ncell;
    fsdem__restart_tag(io, "PIC2");
    for (a = 0; a < 3; ++a) grid[a] = s->n[a];
    fsdem__restart_value(io, grid, sizeof grid);
    if (io->mode == FSDEM__RESTART_CHECK && io->res == FSDEM_OK &&
        (grid[0] != s->n[0] || grid[1] != s->n[1] || grid[2] != s->n[2]))
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "the grid has %d x %d x %d cells in the save and %d x %d x %d in the object (create the "
                            "object from the desc it was saved with)",
                            grid[0], grid[1], grid[2], s->n[0], s->n[1], s->n[2]);
    fsdem__restart_same_fields(io, s, same, 38);

    fsdem__restart_fields(io, s, state, 16);

    fsdem__restart_pic_obstacles(io, s);
    fsdem__restart_pic_particles(io, s);

    /* grid fields, in place (the grid matches) */
    for (a = 0; a < s->dim; ++a) {
        const size_t fb = sizeof(fsdem_real) * (size_t)s->nface[a];
        fsdem__restart_data(io, s->u[a], fb);
        fsdem__restart_data(io, s->sopen[a], fb);
        fsdem__restart_data(io, s->svel[a], fb);
        fsdem__restart_data(io, s->copen[a], fb);
        fsdem__restart_data(io, s->cvel[a], fb);
        fsdem__restart_data(io, s->cvstart[a], fb);
        fsdem__restart_data(io, s->cacc[a], fb);
        fsdem__restart_data(io, s->E[a], fb);
        fsdem__restart_data(io, s->us[a], fb);
        fsdem__restart_data(io, s->fpor[a], fb);
        fsdem__restart_data(io, s->Ef[a], fb);
    }
    fsdem__restart_data(io, s->frac, cells);
    fsdem__restart_data(io, s->phi, cells);
    fsdem__restart_data(io, s->pres, cells);
    fsdem__restart_data(io, s->crhs, cells);
    fsdem__restart_data(io, s->cref, cells);
    fsdem__restart_data(io, s->cpor, cells);
    fsdem__restart_data(io, s->fref, cells);
    fsdem__restart_flags(io, s->ctype, s->ncell, FSDEM_STENCIL_CELL_SOLID, "type of cell");
    fsdem__restart_flags(io, s->cnear, s->ncell, 1, "near-solid flag of cell");
    fsdem__restart_flags(io, s->csolid, s->ncell, 1, "solid flag of cell");
    fsdem__restart_gauges(io, &s->gauges, &s->allocator, "fsdem_pic_gauges_close");
    fsdem__restart_tag(io, "PIC.");
}
