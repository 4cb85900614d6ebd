/* ---- >>restart_mps : MPS ---- */

/* Checks (in CHECK) the `count` open planes about to be read, inflows or outflows: an axis of the
   solver's, a direction of +-1, a finite plane (corrupted data otherwise). */
static void fsdem__restart_mps_planes(fsdem__restart *io, int dim, int count, int inflows) {
    const size_t size = inflows ? sizeof(fsdem_mps_inflow_desc) : sizeof(fsdem_mps_outflow_desc);
    const unsigned char *p = io->mode == FSDEM__RESTART_CHECK ? fsdem__restart_peek(io, size * (size_t)count) : NULL;
    int k;
    for (k = 0; p && k < count; ++k) {
        fsdem_mps_inflow_desc in;
        fsdem_mps_outflow_desc out;
        int axis, direction;
        fsdem_real position;
        if (inflows) {
            memcpy(&in, p + size * (size_t)k, size);
            axis = in.axis, direction = in.direction, position = in.position;
        } else {
            memcpy(&out, p + size * (size_t)k, size);
            axis = out.axis, direction = out.direction, position = out.position;
        }
        if (axis < 0 || axis >= dim || (direction != 1 && direction != -1) || !fsdem__finite(position)) {
            fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "%s %d: axis %d, direction %d, plane %g (corrupted data)",
                                inflows ? "inflow" : "outflow", k, axis, direction, (double)position);
            return;
        }
    }
}

/* The particles go into arrays of the saved capacity (all FSDEM__MPS_ARRAYS of them and the four
   row-offset arrays, as fsdem__mps_reserve makes them; the object's own when it has that capacity,
   so a coupled step's put-back allocates nothing); of their contents the state that the
   next step reads (positions, velocities, pressures: the pressure solve starts from them, the
   explicit scheme's densities and its sound speed, kinds, porosities, a coupler's forces, obstacle
   membership) and the views of the last step (number
   density, surface flags, pressure gradients) are saved. The neighbour rows and the matrix are
   rebuilt by every step; their memory stays. */
static void fsdem__restart_mps(fsdem__restart *io, void *object) {
    static const fsdem__field same[30] = {
        FSDEM__SAME(fsdem_mps, dim, INT), FSDEM__SAME(fsdem_mps, scheme, INT), FSDEM__SAME(fsdem_mps, sound_speed, REAL),
        FSDEM__SAME(fsdem_mps, density_diffusion, REAL), FSDEM__SAME(fsdem_mps, r0, REAL), FSDEM__SAME(fsdem_mps, re, REAL),
        FSDEM__SAME(fsdem_mps, re_laplacian, REAL), FSDEM__SAME(fsdem_mps, density, REAL),
        FSDEM__SAME(fsdem_mps, viscosity, REAL), FSDEM__SAME(fsdem_mps, gravity, VEC3), FSDEM__SAME(fsdem_mps, gamma, REAL),
        FSDEM__SAME(fsdem_mps, model, INT), FSDEM__SAME(fsdem_mps, beta, REAL), FSDEM__SAME(fsdem_mps, alpha, REAL),
        FSDEM__SAME(fsdem_mps, cfl, REAL), FSDEM__SAME(fsdem_mps, dt_max, REAL), FSDEM__SAME(fsdem_mps, domain_min, VEC3),
        FSDEM__SAME(fsdem_mps, domain_max, VEC3), FSDEM__SAME(fsdem_mps, periodic[0], INT),
        FSDEM__SAME(fsdem_mps, periodic[1], INT), FSDEM__SAME(fsdem_mps, periodic[2], INT), FSDEM__SAME(fsdem_mps, gradient, INT),
        FSDEM__SAME(fsdem_mps, wall_viscosity, INT), FSDEM__SAME(fsdem_mps, clamp_negative_pressure, INT),
        FSDEM__SAME(fsdem_mps, collision_distance, REAL), FSDEM__SAME(fsdem_mps, restitution, REAL),
        FSDEM__SAME(fsdem_mps, shifting, REAL), FSDEM__SAME(fsdem_mps, pressure_precond, INT),
        FSDEM__SAME(fsdem_mps, pressure_tolerance, REAL), FSDEM__SAME(fsdem_mps, pressure_max_iterations, INT)};
    static const fsdem__field state[9] = {
        FSDEM__SAVED(fsdem_mps, c0), FSDEM__SAVED(fsdem_mps, time), FSDEM__SAVED(fsdem_mps, dt_last), FSDEM__SAVED(fsdem_mps, steps),
        FSDEM__SAVED(fsdem_mps, iters_total), FSDEM__SAVED(fsdem_mps, iters), FSDEM__SAVED(fsdem_mps, residual),
        FSDEM__SAVED(fsdem_mps, surface_count), FSDEM__SAVED(fsdem_mps, pair_count)};
    fsdem_mps *s = (fsdem_mps *)object;
    const fsdem_allocator *al = &s->allocator;
    const int commit = io->mode == FSDEM__RESTART_COMMIT;
    int no = s->obst_n, nin = s->inflow_n, nout = s->outflow_n, n = s->n, cap = s->cap, i, a;
    fsdem__mps_obst *obst;
    fsdem_mps_inflow_desc *inflows;
    fsdem_mps_outflow_desc *outflows;
    fsdem__restart_tag(io, "MPS5");
    fsdem__restart_same_fields(io, s, same, 30);

    fsdem__restart_fields(io, s, state, 9);

    /* obstacles and open boundaries, into the object's arrays when they hold them (else fresh ones) */
    fsdem__restart_count(io, &no, 1 << 24, sizeof(fsdem__mps_obst), "obstacle count");
    obst = no <= s->obst_cap ? s->obst : (fsdem__mps_obst *)fsdem__restart_block(io, al, sizeof *obst * (size_t)no);
    if (commit && obst != s->obst) {
        fsdem__free(al, s->obst, sizeof *s->obst * (size_t)s->obst_cap);
        s->bytes += sizeof *obst * (size_t)no - sizeof *s->obst * (size_t)s->obst_cap;
        s->obst = obst;
        s->obst_cap = no;
    }
    if (commit) s->obst_n = no;
    fsdem__restart_data(io, s->obst, sizeof *s->obst * (size_t)no);

    fsdem__restart_count(io, &nin, 1 << 24, sizeof(fsdem_mps_inflow_desc), "inflow count");
    inflows = nin <= s->inflow_cap ? s->inflows : (fsdem_mps_inflow_desc *)fsdem__restart_block(io, al, sizeof *inflows * (size_t)nin);
    fsdem__restart_count(io, &nout, 1 << 24, sizeof(fsdem_mps_outflow_desc), "outflow count");
    outflows = nout <= s->outflow_cap ? s->outflows
                                      : (fsdem_mps_outflow_desc *)fsdem__restart_block(io, al, sizeof *outflows * (size_t)nout);
    if (commit && inflows != s->inflows) {
        fsdem__free(al, s->inflows, sizeof *s->inflows * (size_t)s->inflow_cap);
        s->bytes += sizeof *inflows * (size_t)nin - sizeof *s->inflows * (size_t)s->inflow_cap;
        s->inflows = inflows;
        s->inflow_cap = nin;
    }
    if (commit && outflows != s->outflows) {
        fsdem__free(al, s->outflows, sizeof *s->outflows * (size_t)s->outflow_cap);
        s->bytes += sizeof *outflows * (size_t)nout - sizeof *s->outflows * (size_t)s->outflow_cap;
        s->outflows = outflows;
        s->outflow_cap = nout;
    }
    if (commit) {
        s->inflow_n = nin;
        s->outflow_n = nout;
    }
    fsdem__restart_mps_planes(io, s->dim, nin, 1);
    fsdem__restart_data(io, s->inflows, sizeof *s->inflows * (size_t)nin);
    fsdem__restart_mps_planes(io, s->dim, nout, 0);
    fsdem__restart_data(io, s->outflows, sizeof *s->outflows * (size_t)nout);
    fsdem__restart_data(io, &s->inflow_total, sizeof s->inflow_total);
    fsdem__restart_data(io, &s->outflow_total, sizeof s->outflow_total);

    /* particles, into arrays of the saved capacity: the object's own when it has that capacity */
    fsdem__restart_count(io, &cap, 1 << 29, 0, "particle capacity");
    fsdem__restart_count(io, &n, cap, 2 * sizeof(fsdem_vec3), "particle count");
    if (io->res == FSDEM_OK && cap != s->cap && (io->mode == FSDEM__RESTART_RESERVE || commit)) {
        void **ptr[FSDEM__MPS_ARRAYS];
        size_t elem[FSDEM__MPS_ARRAYS];
        void *fresh[FSDEM__MPS_ARRAYS + 4];
        const int k = fsdem__mps_arrays(s, ptr, elem);
        for (a = 0; a < k; ++a) fresh[a] = fsdem__restart_block(io, al, elem[a] * (size_t)cap);
        for (a = 0; a < 4; ++a) fresh[k + a] = fsdem__restart_block(io, al, sizeof(int) * (size_t)(cap + 1));
        if (commit) {
            for (a = 0; a < k; ++a) {
                fsdem__free(al, *ptr[a], elem[a] * (size_t)s->cap);
                *ptr[a] = fresh[a];
                s->bytes += elem[a] * (size_t)cap - elem[a] * (size_t)s->cap;
            }
            for (a = 0; a < 4; ++a) {
                int **rows = fsdem__mps_rows(s, a);
                fsdem__free(al, *rows, sizeof(int) * (size_t)(s->cap + 1));
                *rows = (int *)fresh[k + a];
            }
            s->bytes += 4 * sizeof(int) * (size_t)cap - 4 * sizeof(int) * (size_t)s->cap;
            s->cap = cap;
        }
    }
    if (commit) {
        for (a = 0; a < 4; ++a)
            if (*fsdem__mps_rows(s, a)) memset(*fsdem__mps_rows(s, a), 0, sizeof(int) * (size_t)(cap + 1));
        s->n = n;
        s->rows = 0; /* the pressure matrix of the last step is not kept */
    }
    fsdem__restart_data(io, s->x, sizeof *s->x * (size_t)n);
    fsdem__restart_data(io, s->v, sizeof *s->v * (size_t)n);
    fsdem__restart_data(io, s->p, sizeof *s->p * (size_t)n);
    fsdem__restart_data(io, s->eps, sizeof *s->eps * (size_t)n);
    fsdem__restart_data(io, s->nd, sizeof *s->nd * (size_t)n);
    fsdem__restart_data(io, s->rho, sizeof *s->rho * (size_t)n);
    fsdem__restart_data(io, &s->external, sizeof s->external);
    fsdem__restart_data(io, s->fext, sizeof *s->fext * (size_t)n);
    fsdem__restart_data(io, s->gradp, sizeof *s->gradp * (size_t)n);
    fsdem__restart_flags(io, s->kind, n, FSDEM_MPS_KIND_DUMMY, "kind of particle");
    fsdem__restart_flags(io, s->surf, n, 1, "surface flag of particle");
    fsdem__restart_ints(io, s->body, n, -1, no - 1, "obstacle of particle");
    fsdem__restart_ints(io, s->inlet, n, -1, nin - 1, "inflow of particle");
    fsdem__restart_gauges(io, &s->gauges, al, "fsdem_mps_gauges_close");
    if (commit) {
        s->counts[0] = s->counts[1] = s->counts[2] = 0;
        s->buffered = 0;
        for (i = 0; i < n; ++i) {
            s->counts[s->kind[i]]++;
            s->buffered += s->inlet[i] >= 0;
            s->us[i] = s->shift[i] = fsdem__zero3();
            s->unknown[i] = -1;
        }
        s->solid_pairs_of = -1; /* the solids may be others: their pairs are found again */
        s->rows_valid = 0;
    }
    fsdem__restart_tag(io, "MPS.");
}
