/* ---- >>mps_neighbours : cell-list search into sorted neighbour rows, kept while they hold ---- */

/* r_j - r_i, through the minimum image along periodic axes. */
static inline fsdem_vec3 fsdem__mps_sep(const fsdem_mps *s, int i, int j) {
    return fsdem__min_image(&s->periods, fsdem__sub(s->x[j], s->x[i]));
}

/* Capacity for `need` entries: the next power-of-two multiple of 1024 (0 when it would overflow). */
static int fsdem__mps_capacity(int have, long long need) {
    long long cap = have > 0 ? have : 1024;
    while (cap < need) cap *= 2;
    return cap > (1LL << 30) ? 0 : (int)cap;
}

/* The neighbour rows are Verlet lists: they hold every pair within re + s->skin at the positions
   they were built at (s->x_built), so they still hold every pair within re until some particle has
   moved skin/2; fsdem__mps_neighbours rebuilds them only then (or after particles were added,
   removed or restored: s->rows_valid = 0) and weighs every entry at the current positions, those
   beyond re with 0, which leaves every sum over a row as it would be over the pairs within re. */

/* Pairs within re + skin from the cell scan, appended to *list (2 ints each, from pair *count on, the
   array grown as needed; *examined counts the candidates). Every cell holds its FLUID items, then
   its WALL items (from s->cell_wall[c]), then its DUMMY items (from s->cell_dummy[c]), so each kind
   of pair is one range of a neighbouring cell: with `solid` = 0 the pairs with a FLUID particle,
   with `solid` = 1 the WALL-WALL and WALL-DUMMY pairs. DUMMY-DUMMY pairs are never examined.
   Returns FSDEM_ERR_OUT_OF_MEMORY when the list cannot grow. */
static fsdem_result fsdem__mps_scan(fsdem_mps *s, int solid, int **list, int *cap, int *count, long long *examined) {
    const fsdem_cellgrid *g = &s->grid;
    const fsdem_real reach2 = (s->re + s->skin) * (s->re + s->skin);
    int c, f, a, b;
    for (c = 0; c < g->cell_count; ++c) {
        int coord[3], cells[14], nf;
        if (g->cell_start[c] == g->cell_start[c + 1]) continue;
        coord[0] = c % g->n[0];
        coord[1] = c / g->n[0] % g->n[1];
        coord[2] = c / (g->n[0] * g->n[1]);
        nf = fsdem_cellgrid_forward(g, coord, cells);
        for (f = 0; f < nf; ++f)
            for (a = solid ? s->cell_wall[c] : g->cell_start[c]; a < g->cell_start[c + 1]; ++a) {
                const int pa = g->items[a], cf = cells[f], fluid = a < s->cell_wall[c], dummy = a >= s->cell_dummy[c];
                int b0, b1;
                if (!solid && fluid) b0 = f == 0 ? a + 1 : g->cell_start[cf], b1 = g->cell_start[cf + 1];
                else if (!solid) b0 = f == 0 ? a : g->cell_start[cf], b1 = f == 0 ? a : s->cell_wall[cf];
                else if (!dummy) b0 = f == 0 ? a + 1 : s->cell_wall[cf], b1 = g->cell_start[cf + 1];
                else b0 = f == 0 ? a : s->cell_wall[cf], b1 = f == 0 ? a : s->cell_dummy[cf];
                if (b1 <= b0) continue;
                if (2 * ((long long)*count + b1 - b0) > *cap) {
                    const int fresh_cap = fsdem__mps_capacity(*cap, 2 * ((long long)*count + b1 - b0));
                    int *fresh = fresh_cap ? (int *)fsdem__alloc(&s->allocator, sizeof(int) * (size_t)fresh_cap) : NULL;
                    if (!fresh) return FSDEM_ERR_OUT_OF_MEMORY;
                    if (*count) memcpy(fresh, *list, sizeof(int) * 2 * (size_t)*count);
                    fsdem__free(&s->allocator, *list, sizeof(int) * (size_t)*cap);
                    s->bytes += sizeof(int) * (size_t)(fresh_cap - *cap);
                    *list = fresh;
                    *cap = fresh_cap;
                }
                *examined += b1 - b0;
                for (b = b0; b < b1; ++b) {
                    const int pb = g->items[b];
                    const fsdem_vec3 d = fsdem__mps_sep(s, pb, pa);
                    (*list)[2 * *count] = pa;
                    (*list)[2 * *count + 1] = pb;
                    *count += fsdem__dot(d, d) < reach2;
                }
            }
    }
    return FSDEM_OK;
}

/* Rebuilds the rows of every FLUID and WALL particle, ascending particle index: pairs found once
   each by the forward scan of the cell grid (as the DEM's pair search), bucketed by column, then
   copied column by column into the final rows, which leaves each sorted. DUMMY particles have
   empty rows (their own sums are never needed) but appear in the others'. Allocates only when the
   lists outgrow every earlier one. */
static fsdem_result fsdem__mps_build_rows(fsdem_mps *s) {
    const fsdem_cellgrid *g = &s->grid;
    const int solids = s->counts[FSDEM_MPS_KIND_WALL] + s->counts[FSDEM_MPS_KIND_DUMMY];
    long long examined = 0;
    int c, a, i, e, count = 0;
    s->rows_valid = 0;
    if (fsdem_cellgrid_build(&s->grid, s->x, s->n) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    /* each cell's items in the order FLUID, WALL, DUMMY (stable; s->cursor and s->tmp_start are
       free until the rows are built) */
    for (c = 0; c < g->cell_count; ++c) {
        int k = g->cell_start[c], nw = 0, nd = 0;
        for (a = g->cell_start[c]; a < g->cell_start[c + 1]; ++a) {
            const int p = g->items[a];
            if (s->kind[p] == FSDEM_MPS_KIND_WALL) s->cursor[nw++] = p;
            else if (s->kind[p] == FSDEM_MPS_KIND_DUMMY) s->tmp_start[nd++] = p;
            else s->grid.items[k++] = p;
        }
        s->cell_wall[c] = k;
        s->cell_dummy[c] = k + nw;
        if (nw) memcpy(s->grid.items + k, s->cursor, sizeof(int) * (size_t)nw);
        if (nd) memcpy(s->grid.items + k + nw, s->tmp_start, sizeof(int) * (size_t)nd);
    }
    /* WALL-WALL and WALL-DUMMY pairs: solids never move, so they are found once (again only after
       solids were added or restored) and copied into every step's list */
    if (s->solid_pairs_of != solids) {
        long long once = 0;
        s->solid_pair_n = 0;
        if (fsdem__mps_scan(s, 1, &s->solid_pairs, &s->solid_pair_cap, &s->solid_pair_n, &once) != FSDEM_OK)
            return FSDEM_ERR_OUT_OF_MEMORY;
        s->solid_pairs_of = solids;
    }
    if (fsdem__mps_scan(s, 0, &s->pairs, &s->pair_cap, &count, &examined) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    if (2 * ((long long)count + s->solid_pair_n) > s->pair_cap) {
        const int cap = fsdem__mps_capacity(s->pair_cap, 2 * ((long long)count + s->solid_pair_n));
        int *fresh = cap ? (int *)fsdem__alloc(&s->allocator, sizeof(int) * (size_t)cap) : NULL;
        if (!fresh) return FSDEM_ERR_OUT_OF_MEMORY;
        if (count) memcpy(fresh, s->pairs, sizeof(int) * 2 * (size_t)count);
        fsdem__free(&s->allocator, s->pairs, sizeof(int) * (size_t)s->pair_cap);
        s->bytes += sizeof(int) * (size_t)(cap - s->pair_cap);
        s->pairs = fresh;
        s->pair_cap = cap;
    }
    if (s->solid_pair_n) memcpy(s->pairs + 2 * (size_t)count, s->solid_pairs, sizeof(int) * 2 * (size_t)s->solid_pair_n);
    count += s->solid_pair_n;
    s->candidates = examined;
    /* directed entries (r, c): c in the row of r, for every non-DUMMY r; first bucketed by column c
       (counting sort into tmp_nb, rows r), then scattered by row in column order, which
       leaves every row sorted */
    memset(s->tmp_start, 0, sizeof(int) * (size_t)(s->n + 1));
    memset(s->nb_start, 0, sizeof(int) * (size_t)(s->n + 1));
    for (e = 0; e < count; ++e) {
        const int pa = s->pairs[2 * e], pb = s->pairs[2 * e + 1];
        if (s->kind[pa] != FSDEM_MPS_KIND_DUMMY) {
            s->nb_start[pa + 1]++;
            s->tmp_start[pb + 1]++;
        }
        if (s->kind[pb] != FSDEM_MPS_KIND_DUMMY) {
            s->nb_start[pb + 1]++;
            s->tmp_start[pa + 1]++;
        }
    }
    for (i = 0; i < s->n; ++i) {
        s->nb_start[i + 1] += s->nb_start[i];
        s->tmp_start[i + 1] += s->tmp_start[i];
    }
    if (s->nb_start[s->n] > s->nb_cap) {
        const int cap = fsdem__mps_capacity(s->nb_cap, s->nb_start[s->n]);
        void **arrays[5];
        size_t elem[5];
        void *fresh[5];
        int k, ok = 1;
        arrays[0] = (void **)&s->nb;
        arrays[1] = (void **)&s->tmp_nb;
        arrays[2] = (void **)&s->nbw;
        arrays[3] = (void **)&s->nbl;
        arrays[4] = (void **)&s->nbx;
        elem[0] = elem[1] = sizeof(int);
        elem[2] = elem[3] = elem[4] = sizeof(fsdem_real);
        if (!cap) return FSDEM_ERR_OUT_OF_MEMORY;
        for (k = 0; k < 5; ++k) ok &= (fresh[k] = fsdem__alloc(&s->allocator, elem[k] * (size_t)cap)) != NULL;
        if (!ok) {
            for (k = 0; k < 5; ++k) fsdem__free(&s->allocator, fresh[k], elem[k] * (size_t)cap);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
        for (k = 0; k < 5; ++k) {
            fsdem__free(&s->allocator, *arrays[k], elem[k] * (size_t)s->nb_cap);
            *arrays[k] = fresh[k];
        }
        s->bytes += (2 * sizeof(int) + 3 * sizeof(fsdem_real)) * (size_t)(cap - s->nb_cap);
        s->nb_cap = cap;
    }
    memcpy(s->cursor, s->tmp_start, sizeof(int) * (size_t)s->n);
    for (e = 0; e < count; ++e) {
        const int pa = s->pairs[2 * e], pb = s->pairs[2 * e + 1];
        if (s->kind[pa] != FSDEM_MPS_KIND_DUMMY) s->tmp_nb[s->cursor[pb]++] = pa;
        if (s->kind[pb] != FSDEM_MPS_KIND_DUMMY) s->tmp_nb[s->cursor[pa]++] = pb;
    }
    memcpy(s->cursor, s->nb_start, sizeof(int) * (size_t)s->n);
    for (c = 0; c < s->n; ++c)
        for (e = s->tmp_start[c]; e < s->tmp_start[c + 1]; ++e) s->nb[s->cursor[s->tmp_nb[e]]++] = c;
    /* the FLUID rows' WALL and DUMMY entries, which the solids' Shepard averages scatter from */
    count = 0;
    for (i = 0; i < s->n; ++i)
        if (s->kind[i] == FSDEM_MPS_KIND_FLUID)
            for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) count += s->kind[s->nb[e]] != FSDEM_MPS_KIND_FLUID;
    if (2 * (long long)count > s->wall_entry_cap) {
        const int before = s->wall_entry_cap;
        if (fsdem__grow(&s->allocator, (void **)&s->wall_entries, &s->wall_entry_cap, 0, 2 * count, sizeof(int)) != FSDEM_OK)
            return FSDEM_ERR_OUT_OF_MEMORY;
        s->bytes += sizeof(int) * (size_t)(s->wall_entry_cap - before);
    }
    s->wall_entry_n = 0;
    for (i = 0; i < s->n; ++i)
        if (s->kind[i] == FSDEM_MPS_KIND_FLUID)
            for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e)
                if (s->kind[s->nb[e]] != FSDEM_MPS_KIND_FLUID) {
                    s->wall_entries[2 * s->wall_entry_n] = i;
                    s->wall_entries[2 * s->wall_entry_n++ + 1] = e;
                }
    memcpy(s->x_built, s->x, sizeof(fsdem_vec3) * (size_t)s->n);
    s->rows_valid = 1;
    return FSDEM_OK;
}

/* Whether the rows still hold every pair within re: built for these particles, and no particle
   more than skin/2 from where it was then (two of them then came at most skin closer). */
static int fsdem__mps_rows_hold(const fsdem_mps *s) {
    const fsdem_real half = s->skin / 2;
    int i;
    if (!s->rows_valid) return 0;
    for (i = 0; i < s->n; ++i) {
        const fsdem_vec3 d = fsdem__min_image(&s->periods, fsdem__sub(s->x[i], s->x_built[i]));
        if (!(fsdem__dot(d, d) <= half * half)) return 0;
    }
    return 1;
}

/* The weights of every row entry at the current positions: w_ij (Eq. 6), the Laplacian's (with
   re_laplacian), the explicit scheme's pair weight over |r_ij|^2; 0 beyond their radii. In the same
   pass, the sums over them that every step needs: the number density n_i (seed 002 Eq. 7, every
   neighbour, DUMMY included) and the surface flag (Eq. 14-16) of every FLUID and WALL particle, on
   the surface when n_i < beta n0, or else when the asymmetry |F_i| of Eq. 15 exceeds alpha |F0|
   (|F0|: the flat surface of the lattice, >>mps_desc). Counts the pairs within re (a pair with a
   DUMMY particle has one entry, others two) and the surface particles. */
static void fsdem__mps_weigh(fsdem_mps *s) {
    const int explicit_scheme = s->desc.scheme == FSDEM_MPS_SCHEME_EXPLICIT;
    const fsdem_real re2 = s->re * s->re, inv_rx = 1 / s->re_x, fscale = (fsdem_real)s->dim / s->n0;
    long long twice = 0;
    int i, e, surface = 0;
    for (i = 0; i < s->n; ++i) {
        fsdem_real nd = 0;
        fsdem_vec3 F = fsdem__zero3(); /* -F_i of Eq. 15: the entries' separations are r_i - r_j */
        for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
            const int j = s->nb[e];
            const fsdem_vec3 d = fsdem__mps_sep(s, j, i);
            const fsdem_real r2 = fsdem__dot(d, d);
            fsdem_real r, w, we;
            if (!(r2 < re2)) { /* in the skin: every radius is at most re */
                s->nbw[e] = s->nbl[e] = s->nbx[e] = 0;
                continue;
            }
            r = (fsdem_real)sqrt(r2);
            w = fsdem__kernel_mps(r, s->re);
            s->nbw[e] = w;
            s->nbl[e] = s->re_lap == s->re ? w : r < s->re_lap ? fsdem__kernel_mps(r, s->re_lap) : 0;
            if (explicit_scheme && r < s->re_x) { /* w / r^2 = (1 - q)^3 / re_x^2 */
                const fsdem_real c = 1 - r * inv_rx;
                s->nbx[e] = c * c * c * inv_rx * inv_rx;
            } else
                s->nbx[e] = 0;
            twice += s->kind[j] == FSDEM_MPS_KIND_DUMMY ? 2 : 1;
            we = w / s->eps[j];
            nd += we;                                     /* seed 002 Eq. 7 */
            if (r > 0) F = fsdem__madd(F, d, we / r);     /* seed 002 Eq. 15 */
        }
        s->nd[i] = nd;
        s->surf[i] = (unsigned char)(s->kind[i] != FSDEM_MPS_KIND_DUMMY &&
                                     (nd < s->desc.beta * s->n0 ||                    /* seed 002 Eq. 14 */
                                      fscale * fsdem__norm(F) > s->desc.alpha * s->f0)); /* Eq. 16 */
        surface += s->surf[i];
    }
    s->pair_count = twice / 2;
    s->surface_count = surface;
}

/* The neighbour rows at the current positions with their weights, the number density and the
   surface (the rows rebuilt when they no longer hold). FSDEM_ERR_OUT_OF_MEMORY when a rebuild cannot grow the lists. */
static fsdem_result fsdem__mps_neighbours(fsdem_mps *s) {
    if (!fsdem__mps_rows_hold(s) && fsdem__mps_build_rows(s) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__mps_weigh(s);
    return FSDEM_OK;
}
