/* ---- >>mps_open : inflow and outflow planes ---- */

/* The signed distance of particle i past an open plane along its direction (m). */
static fsdem_real fsdem__mps_past(const fsdem_mps *s, int i, int axis, int direction, fsdem_real position) {
    return (fsdem__comp(s->x[i], axis) - position) * (fsdem_real)direction;
}

/* Depth of an inflow buffer and of an outflow zone: the reach of the kernel, ceil(re/r0) r0. */
static fsdem_real fsdem__mps_open_depth(const fsdem_mps *s) { return (fsdem_real)s->layers * s->r0; }

/* Checks an open boundary (`what` names its desc): an axis of the solver's that is not periodic, a
   direction of +-1, the plane and the zone `depth` behind it (`upstream`) or past it inside the
   domain, and the zone's extent lo-hi over the other axes as a fill box. The lattice anchor (lo,
   the plane along `axis`) and the zone's box go to *anchor, *from, *to when given. */
static fsdem_result fsdem__mps_check_open(fsdem_mps *s, const char *what, int axis, int direction, fsdem_real position, int upstream,
                                          fsdem_vec3 lo, fsdem_vec3 hi, fsdem_vec3 *anchor, fsdem_vec3 *from, fsdem_vec3 *to) {
    const fsdem_real depth = fsdem__mps_open_depth(s);
    char field[64];
    fsdem_real far;
    fsdem_vec3 f = lo, t = hi;
    if (axis < 0 || axis >= s->dim)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s.axis = %d must be in [0, %d)", what, axis, s->dim);
    if (direction != 1 && direction != -1)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s.direction = %d must be +1 or -1", what, direction);
    if (s->desc.periodic[axis])
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s.axis = %d is periodic", what, axis);
    far = position + (fsdem_real)(upstream ? -direction : direction) * depth;
    if (!fsdem__finite(position) || !(far >= fsdem__comp(s->desc.domain_min, axis) && far <= fsdem__comp(s->desc.domain_max, axis)) ||
        !(position >= fsdem__comp(s->desc.domain_min, axis) && position <= fsdem__comp(s->desc.domain_max, axis)))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "%s.position = %g m: the plane and its zone, %g m %s it, must lie inside the domain along %c", what,
                           (double)position, (double)depth, upstream ? "upstream of" : "past", "xyz"[axis]);
    fsdem__set_comp(&f, axis, position < far ? position : far);
    fsdem__set_comp(&t, axis, position < far ? far : position);
    if (anchor) {
        *anchor = lo;
        fsdem__set_comp(anchor, axis, position);
    }
    if (from) *from = f;
    if (to) *to = t;
    snprintf(field, sizeof field, "%s.lo/hi", what);
    return fsdem__mps_check_box(s, field, f, t);
}

/* An MPS that can take an open boundary: no coupler claims its arrays, and none was handed them. */
static fsdem_result fsdem__mps_open_allowed(fsdem_mps *s, const char *fn) {
    const char *holder = fsdem_claimant(&s->claims, FSDEM_MPS_ARRAYS_FORCE | FSDEM_MPS_ARRAYS_POROSITY);
    if (holder || s->external)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: the MPS is coupled (%s): open boundaries need an MPS without a coupler",
                           fn, holder ? holder : "its coupling arrays were handed out");
    return FSDEM_OK;
}

/* An inflow's buffer zone (from-to) inside the domain and free of particles: a buffer over liquid,
   over walls or over another buffer would place particles on top of others. */
static fsdem_result fsdem__mps_zone_free(fsdem_mps *s, fsdem_vec3 from, fsdem_vec3 to) {
    int i, a, inside;
    for (a = 0; a < s->dim; ++a)
        if (!(fsdem__comp(from, a) >= fsdem__comp(s->desc.domain_min, a) && fsdem__comp(to, a) <= fsdem__comp(s->desc.domain_max, a)))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                               "fsdem_mps_inflow_desc.lo/hi: the buffer zone from %g to %g m along %c must lie inside the domain (%g to %g m)",
                               (double)fsdem__comp(from, a), (double)fsdem__comp(to, a), "xyz"[a], (double)fsdem__comp(s->desc.domain_min, a),
                               (double)fsdem__comp(s->desc.domain_max, a));
    for (i = 0; i < s->n; ++i) {
        for (a = 0, inside = 1; a < s->dim && inside; ++a)
            inside = fsdem__comp(s->x[i], a) > fsdem__comp(from, a) && fsdem__comp(s->x[i], a) < fsdem__comp(to, a);
        if (inside)
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                               "fsdem_mps_inflow_desc: the buffer zone from (%g, %g, %g) to (%g, %g, %g) m holds particle %d at (%g, %g, %g) m: "
                               "it must be free (not in the liquid, the walls or another inflow's buffer)",
                               (double)from.x, (double)from.y, (double)from.z, (double)to.x, (double)to.y, (double)to.z, i,
                               (double)s->x[i].x, (double)s->x[i].y, (double)s->x[i].z);
    }
    return FSDEM_OK;
}

/* An inflow and an outflow across the same stream (one axis, extents that overlap over the
   others): the outflow must face the same way and lie downstream of the inflow's plane, else it
   removes the liquid the inflow feeds. */
static fsdem_result fsdem__mps_open_ordered(fsdem_mps *s, const fsdem_mps_inflow_desc *in, const fsdem_mps_outflow_desc *out) {
    int a, across = in->axis == out->axis;
    for (a = 0; a < s->dim && across; ++a)
        across = a == in->axis || (fsdem__comp(in->lo, a) < fsdem__comp(out->hi, a) && fsdem__comp(out->lo, a) < fsdem__comp(in->hi, a));
    if (across && (in->direction != out->direction || !((out->position - in->position) * (fsdem_real)in->direction > 0)))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_mps: the outflow at %c = %g m (direction %+d) is not downstream of the inflow at %c = %g m (direction %+d) "
                           "across the same stream",
                           "xyz"[out->axis], (double)out->position, out->direction, "xyz"[in->axis], (double)in->position, in->direction);
    return FSDEM_OK;
}

fsdem_mps_inflow_desc fsdem_mps_inflow_desc_default(void) {
    fsdem_mps_inflow_desc d;
    memset(&d, 0, sizeof d);
    d.direction = 1;
    return d;
}

fsdem_mps_outflow_desc fsdem_mps_outflow_desc_default(void) {
    fsdem_mps_outflow_desc d;
    memset(&d, 0, sizeof d);
    d.direction = 1;
    return d;
}

fsdem_result fsdem_mps_add_inflow(fsdem_mps *s, const fsdem_mps_inflow_desc *in, int *added) {
    fsdem_vec3 anchor, from, to, u = fsdem__zero3();
    fsdem_result r;
    int first, i, count = 0;
    if (added) *added = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!in) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_add_inflow: inflow is NULL");
    if ((r = fsdem__mps_open_allowed(s, "fsdem_mps_add_inflow")) != FSDEM_OK) return r;
    if ((r = fsdem__mps_check_open(s, "fsdem_mps_inflow_desc", in->axis, in->direction, in->position, 1, in->lo, in->hi, &anchor,
                                   &from, &to)) != FSDEM_OK)
        return r;
    if (!(in->speed > 0 && in->speed <= FSDEM_MAX_SPEED))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_inflow_desc.speed = %g m/s must be in (0, FSDEM_MAX_SPEED]",
                           (double)in->speed);
    if ((r = fsdem__mps_zone_free(s, from, to)) != FSDEM_OK) return r;
    for (i = 0; i < s->outflow_n; ++i)
        if ((r = fsdem__mps_open_ordered(s, in, &s->outflows[i])) != FSDEM_OK) return r;
    fsdem__set_comp(&u, in->axis, in->speed * (fsdem_real)in->direction);
    if (!fsdem__mps_list_room(s, (void **)&s->inflows, &s->inflow_cap, s->inflow_n, sizeof *s->inflows))
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps_add_inflow: out of memory");
    first = s->n;
    r = fsdem__mps_lattice_fill(s, "fsdem_mps_add_inflow", anchor, from, to, fsdem__mps_classify_fluid, NULL, u, &count);
    if (r != FSDEM_OK) return r;
    for (i = first; i < s->n; ++i) s->inlet[i] = s->inflow_n;
    s->inflows[s->inflow_n++] = *in;
    s->buffered += count;
    if (added) *added = count;
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_mps_add_outflow(fsdem_mps *s, const fsdem_mps_outflow_desc *out) {
    fsdem_result r;
    int k;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!out) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_add_outflow: outflow is NULL");
    if ((r = fsdem__mps_open_allowed(s, "fsdem_mps_add_outflow")) != FSDEM_OK) return r;
    if ((r = fsdem__mps_check_open(s, "fsdem_mps_outflow_desc", out->axis, out->direction, out->position, 0, out->lo, out->hi, NULL,
                                   NULL, NULL)) != FSDEM_OK)
        return r;
    for (k = 0; k < s->inflow_n; ++k)
        if ((r = fsdem__mps_open_ordered(s, &s->inflows[k], out)) != FSDEM_OK) return r;
    if (!fsdem__mps_list_room(s, (void **)&s->outflows, &s->outflow_cap, s->outflow_n, sizeof *s->outflows))
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps_add_outflow: out of memory");
    s->outflows[s->outflow_n++] = *out;
    return fsdem__ok(&s->status);
}

/* How far FLUID particle i is past the outflow planes it has crossed within their extent (the
   largest), or 0. */
static fsdem_real fsdem__mps_outflowing(const fsdem_mps *s, int i) {
    fsdem_real most = 0;
    int k, a;
    for (k = 0; k < s->outflow_n; ++k) {
        const fsdem_mps_outflow_desc *o = &s->outflows[k];
        const fsdem_real past = fsdem__mps_past(s, i, o->axis, o->direction, o->position);
        int inside = 1;
        if (!(past > most)) continue;
        for (a = 0; a < s->dim; ++a)
            if (a != o->axis && !(fsdem__comp(s->x[i], a) >= fsdem__comp(o->lo, a) && fsdem__comp(s->x[i], a) <= fsdem__comp(o->hi, a)))
                inside = 0;
        if (inside) most = past;
    }
    return most;
}

/* The imposed velocity of the buffer particles of inflow k. */
static fsdem_vec3 fsdem__mps_inflow_velocity(const fsdem_mps *s, int k) {
    fsdem_vec3 u = fsdem__zero3();
    fsdem__set_comp(&u, s->inflows[k].axis, s->inflows[k].speed * (fsdem_real)s->inflows[k].direction);
    return u;
}

/* After a move: buffer particles past their plane become liquid, each replaced by a new one the
   buffer's depth upstream (room reserved at the start of the step); FLUID particles the zone's
   depth past an outflow plane are removed, the others keeping their order. */
static void fsdem__mps_open_update(fsdem_mps *s) {
    const fsdem_real depth = fsdem__mps_open_depth(s);
    const int n = s->n;
    void **ptr[FSDEM__MPS_ARRAYS];
    size_t elem[FSDEM__MPS_ARRAYS];
    int i, k, kept = 0, solids_after = 0, arrays;
    for (i = 0; i < n && s->inflow_n; ++i) {
        const int in = s->inlet[i];
        fsdem_vec3 x;
        if (in < 0 || fsdem__mps_past(s, i, s->inflows[in].axis, s->inflows[in].direction, s->inflows[in].position) < 0) continue;
        s->inlet[i] = -1;
        s->buffered--;
        s->inflow_total++;
        x = s->x[i];
        fsdem__set_comp(&x, s->inflows[in].axis, fsdem__comp(x, s->inflows[in].axis) - (fsdem_real)s->inflows[in].direction * depth);
        fsdem__mps_push(s, FSDEM_MPS_KIND_FLUID, x, fsdem__mps_inflow_velocity(s, in));
        s->inlet[s->n - 1] = in;
        s->buffered++;
    }
    if (s->outflow_n == 0) return;
    arrays = fsdem__mps_arrays(s, ptr, elem) - FSDEM__MPS_ROW_ARRAYS; /* the particles' own */
    for (i = 0; i < s->n; ++i) {
        if (s->kind[i] == FSDEM_MPS_KIND_FLUID && s->inlet[i] < 0 && fsdem__mps_outflowing(s, i) >= depth) {
            s->counts[FSDEM_MPS_KIND_FLUID]--;
            s->outflow_total++;
            s->cursor[i] = -1; /* old index -> new index (s->cursor is free between steps) */
            continue;
        }
        s->cursor[i] = kept;
        if (kept < i) {
            for (k = 0; k < arrays; ++k)
                memcpy((char *)*ptr[k] + elem[k] * (size_t)kept, (char *)*ptr[k] + elem[k] * (size_t)i, elem[k]);
            solids_after |= s->kind[kept] != FSDEM_MPS_KIND_FLUID;
        }
        ++kept;
    }
    if (kept < s->n)
        for (k = 0; k < s->rows; ++k) s->row_particle[k] = s->cursor[s->row_particle[k]];
    if (kept < s->n) s->rows_valid = 0; /* renumbered */
    s->n = kept;
    if (solids_after) s->solid_pairs_of = -1; /* solids renumbered: their pairs are found again */
}
