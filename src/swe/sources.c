/* ---- >>swe_sources : boundaries, friction, rain, blocked cells, point sources ---- */

fsdem_result fsdem_swe_set_boundary(fsdem_swe *s, fsdem_side side, const fsdem_swe_boundary *bc) {
    char msg[FSDEM__MESSAGE_SIZE];
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((int)side < 0 || (int)side >= (s->dim == 2 ? 4 : 2))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_set_boundary: side %d does not exist in %dD",
                           (int)side, s->dim);
    if (fsdem__swe_boundary_check(bc, (int)side, msg, sizeof msg) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_set_boundary: %s", msg);
    if (fsdem__swe_store_boundary(s, (int)side, bc) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_swe_set_boundary: out of memory");
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_set_manning(fsdem_swe *s, const fsdem_real *manning) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!manning) {
        fsdem__free(&s->allocator, s->manning, sizeof(fsdem_real) * (size_t)s->n);
        s->manning = NULL;
        return fsdem__ok(&s->status);
    }
    /* at most 1: five times the roughest floodplain of Chow's (1959) table (dense brush, 0.2) */
    if (fsdem__swe_array_check(s, manning, 1, 1, "fsdem_swe_set_manning", "s/m^(1/3)") != FSDEM_OK)
        return FSDEM_ERR_INVALID_ARG;
    if (!s->manning) {
        s->manning = (fsdem_real *)fsdem__alloc(&s->allocator, sizeof(fsdem_real) * (size_t)s->n);
        if (!s->manning) return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_swe_set_manning: out of memory");
    }
    memcpy(s->manning, manning, sizeof(fsdem_real) * (size_t)s->n);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_set_rain(fsdem_swe *s, fsdem_real rate) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!(rate >= 0) || !fsdem__finite(rate))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_set_rain: rate must be >= 0 (got %g m/s)",
                           (double)rate);
    s->rain = rate;
    return fsdem__ok(&s->status);
}

/* Replaces the mask by `mask` (n flags, or NULL for none) after checking sources and gauges; the
   water of newly blocked cells is removed and booked as a source. */
static fsdem_result fsdem__swe_apply_blocked(fsdem_swe *s, const unsigned char *mask, const char *what) {
    int k, count = 0;
    for (k = 0; mask && k < s->src_count; ++k)
        if (s->src[k].active && mask[s->src[k].cell])
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: point source %d would be in a blocked cell", what,
                               s->src[k].id);
    for (k = 0; mask && k < s->gauge_count; ++k)
        if (mask[fsdem_swe_cell_at(s, s->gauge[2 * k], s->gauge[2 * k + 1])])
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: gauge %d would be in a blocked cell", what, k);
    if (mask && !s->blocked) {
        s->blocked = (unsigned char *)fsdem__alloc(&s->allocator, (size_t)s->n);
        if (!s->blocked) return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory", what);
        memset(s->blocked, 0, (size_t)s->n);
    }
    for (k = 0; mask && k < s->n; ++k) {
        const int b = mask[k] != 0;
        if (b && !s->blocked[k]) s->vol_source -= (s->eta[k] - s->bed[k]) * s->area;
        s->blocked[k] = (unsigned char)b;
        count += b;
    }
    if (!count) {
        fsdem__free(&s->allocator, s->blocked, (size_t)s->n);
        s->blocked = NULL;
    }
    s->blocked_count = count;
    fsdem__swe_dry_blocked(s);
    fsdem__swe_scan(s);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_set_blocked(fsdem_swe *s, const unsigned char *blocked) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__swe_apply_blocked(s, blocked, "fsdem_swe_set_blocked");
}

/* Blocks the cells whose centre p makes inside(p) true, on top of the current mask. */
static fsdem_result fsdem__swe_block_where(fsdem_swe *s, int (*inside)(const void *shape, fsdem_real x, fsdem_real y),
                                           const void *shape, const char *what) {
    unsigned char *mask = (unsigned char *)fsdem__alloc(&s->allocator, (size_t)s->n);
    fsdem_result res;
    int k;
    if (!mask) return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory", what);
    for (k = 0; k < s->n; ++k) {
        fsdem_real x, y;
        fsdem__swe_centre(s, k, &x, &y);
        mask[k] = (unsigned char)(fsdem__swe_is_blocked(s, k) || inside(shape, x, y));
    }
    res = fsdem__swe_apply_blocked(s, mask, what);
    fsdem__free(&s->allocator, mask, (size_t)s->n);
    return res;
}

static int fsdem__swe_in_box(const void *shape, fsdem_real x, fsdem_real y) {
    const fsdem_real *b = (const fsdem_real *)shape; /* x0, y0, x1, y1, dim */
    return x >= b[0] && x <= b[2] && (b[4] == 1 || (y >= b[1] && y <= b[3]));
}

fsdem_result fsdem_swe_block_box(fsdem_swe *s, fsdem_real x0, fsdem_real y0, fsdem_real x1, fsdem_real y1) {
    fsdem_real box[5];
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!fsdem__finite(x0) || !fsdem__finite(x1) || !(x1 >= x0) ||
        (s->dim == 2 && (!fsdem__finite(y0) || !fsdem__finite(y1) || !(y1 >= y0))))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_block_box: the corners must be finite with x1 >= x0, y1 >= y0");
    box[0] = x0;
    box[1] = y0;
    box[2] = x1;
    box[3] = y1;
    box[4] = (fsdem_real)s->dim;
    return fsdem__swe_block_where(s, fsdem__swe_in_box, box, "fsdem_swe_block_box");
}

typedef struct fsdem__swe_polygon {
    const fsdem_vec3 *v;
    int count;
} fsdem__swe_polygon;

static int fsdem__swe_in_polygon(const void *shape, fsdem_real x, fsdem_real y) {
    const fsdem__swe_polygon *poly = (const fsdem__swe_polygon *)shape;
    return fsdem__geom_polygon(fsdem_v3(x, y, 0), poly->v, poly->count) < 0;
}

fsdem_result fsdem_swe_block_polygon(fsdem_swe *s, const fsdem_vec3 *vertices, int count) {
    fsdem__swe_polygon poly;
    int k;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (s->dim != 2) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_block_polygon: polygons need dim = 2");
    if (!vertices || count < 3)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_block_polygon: needs >= 3 vertices (got %d)",
                           vertices ? count : 0);
    for (k = 0; k < count; ++k)
        if (!fsdem__finite(vertices[k].x) || !fsdem__finite(vertices[k].y))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_block_polygon: vertex %d is not finite", k);
    poly.v = vertices;
    poly.count = count;
    return fsdem__swe_block_where(s, fsdem__swe_in_polygon, &poly, "fsdem_swe_block_polygon");
}

fsdem_result fsdem_swe_add_point_source(fsdem_swe *s, const fsdem_swe_point_source *p, int *id) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem__swe_src *q;
    int k;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!p) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_add_point_source: source is NULL");
    /* at most FSDEM_MAX_SPEED through a FSDEM_MAX_LENGTH square */
    if (!(fabs(p->discharge) <= FSDEM_MAX_SPEED * FSDEM_MAX_LENGTH * FSDEM_MAX_LENGTH))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_add_point_source: discharge %g m^3/s is not finite or beyond %g",
                           (double)p->discharge, (double)(FSDEM_MAX_SPEED * FSDEM_MAX_LENGTH * FSDEM_MAX_LENGTH));
    if (fsdem__swe_series_check(p->series_time, p->series_value, p->series_count, 0,
                                FSDEM_MAX_SPEED * FSDEM_MAX_LENGTH * FSDEM_MAX_LENGTH, "point source", msg, sizeof msg) !=
        FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_add_point_source: %s", msg);
    k = fsdem_swe_cell_at(s, p->x, p->y);
    if (k < 0)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_DOMAIN,
                           "fsdem_swe_add_point_source: point (%g, %g) is outside the grid", (double)p->x, (double)p->y);
    if (fsdem__swe_is_blocked(s, k))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_add_point_source: point (%g, %g) is in a blocked cell",
                           (double)p->x, (double)p->y);
    if (fsdem__grow(&s->allocator, (void **)&s->src, &s->src_capacity, s->src_count, s->src_count + 1,
                    sizeof(fsdem__swe_src)) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_swe_add_point_source: out of memory");
    q = &s->src[s->src_count];
    memset(q, 0, sizeof *q);
    if (fsdem__swe_copy_series(s, p->series_time, p->series_value, p->series_count, &q->t, &q->v) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_swe_add_point_source: out of memory");
    q->n = q->t ? p->series_count : 0;
    q->discharge = p->discharge;
    q->cell = k;
    q->id = s->src_next_id++;
    q->active = 1;
    s->src_count++;
    if (id) *id = q->id;
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_remove_point_source(fsdem_swe *s, int id) {
    int k;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < s->src_count; ++k)
        if (s->src[k].active && s->src[k].id == id) {
            s->src[k].active = 0;
            return fsdem__ok(&s->status);
        }
    return fsdem__fail(&s->status, FSDEM_ERR_NOT_FOUND, "fsdem_swe_remove_point_source: no source with id %d", id);
}
