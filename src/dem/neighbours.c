/* ---- >>dem_neighbours : neighbour lists with contact history ---- */

/* Doubles the entry arrays of a list (all three or none). */
static fsdem_result fsdem__dem_list_grow(fsdem_dem *d, fsdem__dem_list *l) {
    const size_t n = (size_t)l->count;
    int cap = l->capacity > 0 ? 2 * l->capacity : 256;
    int *first, *key;
    fsdem_vec3 *history;
    if (l->capacity > (1 << 29)) return FSDEM_ERR_OUT_OF_MEMORY;
    first = (int *)fsdem__alloc(&d->allocator, sizeof(int) * (size_t)cap);
    key = (int *)fsdem__alloc(&d->allocator, sizeof(int) * (size_t)cap);
    history = (fsdem_vec3 *)fsdem__alloc(&d->allocator, sizeof(fsdem_vec3) * (size_t)cap);
    if (!first || !key || !history) {
        fsdem__free(&d->allocator, first, sizeof(int) * (size_t)cap);
        fsdem__free(&d->allocator, key, sizeof(int) * (size_t)cap);
        fsdem__free(&d->allocator, history, sizeof(fsdem_vec3) * (size_t)cap);
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    if (n) {
        memcpy(first, l->first, sizeof(int) * n);
        memcpy(key, l->key, sizeof(int) * n);
        memcpy(history, l->history, sizeof(fsdem_vec3) * n);
    }
    fsdem__dem_list_free_entries(d, l);
    l->first = first;
    l->key = key;
    l->history = history;
    l->capacity = cap;
    return FSDEM_OK;
}

/* Appends (row, partner `key`) with the history that entry `from` of list `old` holds (none for -1). */
/* Writes entry e = (row, partner `key`) with the spring that entry `from` of list `old` holds (none
   for -1). Without branches on the flag: the spring is copied whether held or not, as it means
   nothing without it. */
static void fsdem__dem_list_set(fsdem__dem_list *l, int e, int row, int key, const fsdem__dem_list *old, int from) {
    const int src = from >= 0 ? from : 0;
    l->first[e] = row;
    l->key[e] = key | (((from >= 0) & (old->count > 0)) ? old->key[src] & FSDEM__DEM_HELD : 0);
    if (old->count > 0) l->history[e] = old->history[src];
}

static fsdem_result fsdem__dem_list_append(fsdem_dem *d, fsdem__dem_list *l, int row, int key, const fsdem__dem_list *old, int from) {
    if (l->count == l->capacity && fsdem__dem_list_grow(d, l) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__dem_list_set(l, l->count++, row, key, old, from);
    return FSDEM_OK;
}

/* The tangential spring of entry k (zero unless held). */
static fsdem_vec3 fsdem__dem_spring(const fsdem__dem_list *l, int k) {
    return l->key[k] & FSDEM__DEM_HELD ? l->history[k] : fsdem__zero3();
}

/* Entry of (row, partner) in a previous list, or -1. */
static int fsdem__dem_old_entry(const fsdem__dem_list *old, int row, int partner) {
    int k;
    if (row >= 0 && row < old->rows)
        for (k = old->start[row]; k < old->start[row + 1]; ++k)
            if (FSDEM__DEM_PARTNER(old->key[k]) == partner) return k;
    return -1;
}

static void fsdem__dem_swap_lists(fsdem__dem_list *a, fsdem__dem_list *b) {
    fsdem__dem_list t = *a;
    *a = *b;
    *b = t;
}

/* Pairs within reach (r_i + r_j + offset + skin), each found once by scanning every cell against
   itself and its forward neighbours (fsdem_cellgrid_forward), into d->found as pairs of cell-order
   indices; xs and reach_s are the positions and radii plus half the offset and skin in cell order, so
   the scan reads them in sequence. Returns the number of pairs, or -1 when d->found cannot grow. */
FSDEM__FORCE_INLINE int fsdem__dem_find_pairs_in(fsdem_dem *d, const fsdem_vec3 *xs, const fsdem_real *reach_s, const int periodic) {
    const fsdem_cellgrid *g = &d->grid;
    int c, f, a, b, count = 0;
    for (c = 0; c < g->cell_count; ++c) {
        int coord[3], cells[14], nf;
        if (g->cell_start[c] == g->cell_start[c + 1]) continue;
        coord[0] = c % g->n[0];
        coord[1] = c / g->n[0] % g->n[1];
        coord[2] = c / (g->n[0] * g->n[1]);
        nf = fsdem_cellgrid_forward(g, coord, cells);
        for (f = 0; f < nf; ++f) {
            const int b1 = g->cell_start[cells[f] + 1];
            for (a = g->cell_start[c]; a < g->cell_start[c + 1]; ++a) {
                const int b0 = f == 0 ? a + 1 : g->cell_start[cells[f]];
                if (2 * (count + b1 - b0) > d->found_capacity &&
                    fsdem__grow(&d->allocator, (void **)&d->found, &d->found_capacity, 2 * count, 2 * (count + b1 - b0),
                                sizeof(int)) != FSDEM_OK)
                    return -1;
                for (b = b0; b < b1; ++b) {
                    /* arithmetic, not branches, which would mispredict */
                    const fsdem_vec3 e = periodic ? fsdem__min_image(&d->periods, fsdem__sub(xs[a], xs[b])) : fsdem__sub(xs[a], xs[b]);
                    const fsdem_real ex = e.x, ey = e.y, ez = e.z;
                    const fsdem_real reach = reach_s[a] + reach_s[b];
                    d->found[2 * count] = a;
                    d->found[2 * count + 1] = b;
                    count += ex * ex + ey * ey + ez * ez < reach * reach;
                }
            }
        }
    }
    return count;
}

static int fsdem__dem_find_pairs(fsdem_dem *d, const fsdem_vec3 *xs, const fsdem_real *reach_s) {
    return d->periods.any ? fsdem__dem_find_pairs_in(d, xs, reach_s, 1) : fsdem__dem_find_pairs_in(d, xs, reach_s, 0);
}

/* The particle-pair list from the `count` pairs in d->found: row min(i, j), partner max(i, j), each
   carrying its history from the previous list. Pairs of fixed particles exert nothing, so they go
   to d->inert instead, where fsdem_dem_contacts still finds them. `cursor` is scratch for n rows. */
static fsdem_result fsdem__dem_fill_pairs(fsdem_dem *d, int count, int *cursor) {
    fsdem__dem_list *l = &d->pp;
    const int *items = d->grid.items;
    int k, i, inert = 0;
    for (k = 0; k < count; ++k) {
        /* partition: the pairs of fixed particles to the end of d->found, as particle indices */
        const int a = items[d->found[2 * k]], b = items[d->found[2 * k + 1]];
        if (d->inv_m[a] == 0 && d->inv_m[b] == 0) {
            const int last = --count;
            d->found[2 * k] = d->found[2 * last];
            d->found[2 * k + 1] = d->found[2 * last + 1];
            d->found[2 * last] = a;
            d->found[2 * last + 1] = b;
            ++inert;
            --k;
        }
    }
    if (fsdem__grow(&d->allocator, (void **)&d->inert, &d->inert_capacity, 0, 2 * inert, sizeof(int)) != FSDEM_OK)
        return FSDEM_ERR_OUT_OF_MEMORY;
    if (inert) memcpy(d->inert, d->found + 2 * count, sizeof(int) * 2 * (size_t)inert); /* found may be NULL */
    d->inert_count = inert;
    while (l->capacity < count)
        if (fsdem__dem_list_grow(d, l) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    memset(l->start, 0, sizeof(int) * (size_t)(d->n + 1));
    for (k = 0; k < count; ++k) {
        const int a = items[d->found[2 * k]], b = items[d->found[2 * k + 1]];
        l->start[(a < b ? a : b) + 1]++;
    }
    for (i = 0; i < d->n; ++i) {
        l->start[i + 1] += l->start[i];
        cursor[i] = l->start[i];
    }
    for (k = 0; k < count; ++k) {
        const int a = items[d->found[2 * k]], b = items[d->found[2 * k + 1]];
        const int i0 = a < b ? a : b, j = a < b ? b : a, e = cursor[i0]++;
        const int oi = d->old_of[i0], oj = d->old_of[j], lo = oi < oj ? oi : oj, hi = oi < oj ? oj : oi;
        fsdem__dem_list_set(l, e, i0, j, &d->pp_old, lo >= 0 ? fsdem__dem_old_entry(&d->pp_old, lo, hi) : -1);
    }
    l->count = count;
    return FSDEM_OK;
}

/* Rebuilds both lists: pairs within r_i + r_j + offset + skin, and particle-wall faces within
   r_i + offset + skin, carrying each surviving contact's history over from the previous lists. */
static fsdem_result fsdem__dem_rebuild(fsdem_dem *d) {
    const fsdem_real off = d->desc.contact_offset;
    fsdem_real r_max = 0, skin, *reach_s;
    fsdem_vec3 *xs;
    int i, k, dim = d->desc.dim, max_cells, *cursor, pairs;
    fsdem_result res = FSDEM_OK;
    for (i = 0; i < d->n; ++i)
        if (d->r[i] > r_max) r_max = d->r[i];
    skin = d->desc.skin >= 0 ? d->desc.skin : (fsdem_real)0.25 * r_max;
    d->skin = skin;
    d->r_max = r_max;
    max_cells = 8 * d->n > 65536 ? 8 * d->n : 65536;
    fsdem__dem_wrap(d);
    if (fsdem_cellgrid_setup_periodic(&d->grid, NULL, dim, d->desc.domain_min, d->desc.domain_max,
                                      r_max > 0 ? 2 * r_max + off + skin : 1, max_cells, d->desc.periodic) != FSDEM_OK ||
        fsdem_cellgrid_build(&d->grid, d->x, d->n) != FSDEM_OK)
        return FSDEM_ERR_OUT_OF_MEMORY;
    /* scratch: positions and reaches (half each: r + (offset + skin)/2) in cell order, row cursors */
    if (fsdem__arena_reserve(&d->allocator, &d->arena,
                             fsdem__arena_bytes(sizeof(fsdem_vec3) * (size_t)d->n) +
                                 fsdem__arena_bytes(sizeof(fsdem_real) * (size_t)d->n) +
                                 fsdem__arena_bytes(sizeof(int) * (size_t)d->n)) != FSDEM_OK)
        return FSDEM_ERR_OUT_OF_MEMORY;
    xs = (fsdem_vec3 *)fsdem__arena_push(&d->arena, sizeof(fsdem_vec3) * (size_t)d->n);
    reach_s = (fsdem_real *)fsdem__arena_push(&d->arena, sizeof(fsdem_real) * (size_t)d->n);
    cursor = (int *)fsdem__arena_push(&d->arena, sizeof(int) * (size_t)d->n);
    for (k = 0; k < d->n; ++k) {
        const int j = d->grid.items[k];
        xs[k] = d->x[j];
        reach_s[k] = d->r[j] + (off + skin) / 2;
    }
    pairs = fsdem__dem_find_pairs(d, xs, reach_s);
    if (pairs < 0) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__dem_swap_lists(&d->pp, &d->pp_old);
    fsdem__dem_swap_lists(&d->pw, &d->pw_old);
    if (fsdem__grow(&d->allocator, (void **)&d->pp.start, &d->pp.start_capacity, 0, d->n + 1, sizeof(int)) != FSDEM_OK ||
        fsdem__grow(&d->allocator, (void **)&d->pw.start, &d->pw.start_capacity, 0, d->n + 1, sizeof(int)) != FSDEM_OK ||
        fsdem__dem_fill_pairs(d, pairs, cursor) != FSDEM_OK)
        res = FSDEM_ERR_OUT_OF_MEMORY;
    d->pw.count = 0;
    for (i = 0; i < d->n && res == FSDEM_OK; ++i) {
        const int oi = d->old_of[i];
        d->pw.start[i] = d->pw.count;
        for (k = 0; k < d->wall_count && res == FSDEM_OK; ++k) {
            const fsdem__dem_wall *w = &d->walls[k];
            int face, faces = fsdem__dem_wall_faces(w, dim);
            if (!w->active) continue;
            for (face = 0; face < faces; ++face) {
                fsdem_vec3 nrm;
                int key = FSDEM__DEM_WALL_KEY(k, face), on_feature;
                if (fsdem__dem_wall_distance(w, face, d->x[i], dim, &nrm, &on_feature) >= d->r[i] + off + skin) continue;
                res = fsdem__dem_list_append(d, &d->pw, i, key, &d->pw_old, fsdem__dem_old_entry(&d->pw_old, oi, key));
                if (res != FSDEM_OK) break;
            }
        }
    }
    if (res != FSDEM_OK) {
        fsdem__dem_swap_lists(&d->pp, &d->pp_old);
        fsdem__dem_swap_lists(&d->pw, &d->pw_old);
        return res;
    }
    d->pw.start[d->n] = d->pw.count;
    d->pp.rows = d->pw.rows = d->n;
    for (i = 0; i < d->n; ++i) {
        d->x_ref[i] = d->x[i];
        d->old_of[i] = i;
    }
    for (k = 0; k < d->wall_count; ++k) d->walls[k].moved = 0;
    d->max_disp2 = 0;
    d->rebuilds++;
    fsdem__dem_dt_check(d);
    /* scratch for the longest wall row, and the force evaluation's arena (fsdem__dem_compute_forces) for
       the new list; the lists above are complete, so a failure here only asks for another rebuild */
    for (i = 0, k = 0; i < d->n; ++i)
        if (d->pw.start[i + 1] - d->pw.start[i] > k) k = d->pw.start[i + 1] - d->pw.start[i];
    d->need_rebuild = fsdem__grow(&d->allocator, (void **)&d->hits, &d->hit_capacity, 0, k, sizeof(fsdem__dem_wall_hit)) !=
                          FSDEM_OK ||
                      fsdem__arena_reserve(&d->allocator, &d->arena, fsdem__dem_force_scratch(d, fsdem__workers())) != FSDEM_OK;
    d->workers = d->need_rebuild ? 1 : fsdem__workers();
    return d->need_rebuild ? FSDEM_ERR_OUT_OF_MEMORY : FSDEM_OK;
}

static int fsdem__dem_lists_stale(const fsdem_dem *d) {
    fsdem_real disp = (fsdem_real)sqrt(d->max_disp2), wall_moved = 0;
    int k;
    for (k = 0; k < d->wall_count; ++k)
        if (d->walls[k].moved > wall_moved) wall_moved = d->walls[k].moved;
    return d->need_rebuild || 2 * disp > d->skin || disp + wall_moved > d->skin;
}

/* Wall contacts (overlap > 0) of particle i into `hits`; returns their number. A mesh of
   triangles or a polyline shares edges and vertices between elements, and a particle touching a
   shared edge would be pushed once per element. So an edge/vertex contact is dropped when its
   contact point lies in the plane of a face contact of the same particle (the edge belongs to that
   face), or when an edge/vertex contact kept before has the same normal (one edge seen from two
   elements). `hits` has room for the particle's row of the particle-wall list. With `keys` (the
   list's keys; NULL: nothing changes), entries without a kept contact lose their tangential
   history. */
static int fsdem__dem_wall_hits_into(const fsdem_dem *d, int i, fsdem__dem_wall_hit *hits, int *keys) {
    const fsdem_real off = d->desc.contact_offset, tol = (fsdem_real)fsdem__tolerance(1e-9) * d->r[i];
    const fsdem_vec3 xi = d->x[i];
    int k, a, b, count = 0, kept = 0;
    for (k = d->pw.start[i]; k < d->pw.start[i + 1]; ++k) {
        const int key = d->pw.key[k];
        const fsdem__dem_wall *wall = &d->walls[FSDEM__DEM_WALL_OF(key)];
        fsdem__dem_wall_hit *h = &hits[count];
        if (wall->active) {
            h->delta = d->r[i] + off - fsdem__dem_wall_distance(wall, FSDEM__DEM_FACE_OF(key), xi, d->desc.dim, &h->n, &h->on_feature);
            if (h->delta > 0) {
                h->entry = k;
                count++;
                continue;
            }
        }
        if (keys) keys[k] &= ~FSDEM__DEM_HELD;
    }
    for (a = 0; a < count; ++a) {
        fsdem__dem_wall_hit h = hits[a];
        int duplicate = 0;
        if (h.on_feature) {
            /* contact point q = x - (r + off - delta) n; in face b's plane when (q - x).n_b = -(r + off - delta_b) */
            fsdem_vec3 q_rel = fsdem__scale(h.n, -(d->r[i] + off - h.delta));
            for (b = 0; b < count && !duplicate; ++b) {
                const fsdem__dem_wall_hit *o = &hits[b];
                if (b == a) continue;
                if (!o->on_feature)
                    duplicate = fsdem__dot(q_rel, o->n) + (d->r[i] + off - o->delta) <= tol &&
                                fsdem__dot(q_rel, o->n) + (d->r[i] + off - o->delta) >= -tol;
                else if (b < a)
                    duplicate = fsdem__dot(h.n, o->n) >= 1 - (fsdem_real)fsdem__tolerance(1e-12);
            }
        }
        if (duplicate) {
            if (keys) keys[h.entry] &= ~FSDEM__DEM_HELD;
            continue;
        }
        hits[kept++] = h;
    }
    return kept;
}

/* Wall contacts of particle i into d->hits (fsdem__dem_wall_hits_into); with `reset`, entries
   without a kept contact lose their tangential history. */
static int fsdem__dem_wall_hits(fsdem_dem *d, int i, int reset) {
    return fsdem__dem_wall_hits_into(d, i, d->hits, reset ? d->pw.key : NULL);
}
