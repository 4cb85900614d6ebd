/* ---- >>mps_neighbours : cell-list search into sorted neighbour rows ---- */

/* r_j - r_i, through the minimum image along periodic axes. */
static fsdem_vec3 fsdem__mps_sep(const fsdem_mps *s, int i, int j) {
    return fsdem__min_image(&s->periods, fsdem__sub(s->x[j], s->x[i]));
}

/* Capacity for `need` entries: the next power-of-two multiple of 1024 (0 when it would overflow). */
static int fsdem__mps_capacity(int have, long long need) {
    long long cap = have > 0 ? have : 1024;
    while (cap < need) cap *= 2;
    return cap > (1LL << 30) ? 0 : (int)cap;
}

/* The neighbours of every FLUID and WALL particle within re at the current positions, as rows of
   ascending particle index with their weights w_ij (Eq. 6; of the Laplacian; of the explicit
   scheme's pair, over |r|^2); DUMMY particles have empty rows (their
   own sums are never needed) but appear in the others'. Pairs are found once each by the forward
   scan of the cell grid (as the DEM's pair search), put into unsorted rows, then copied column by
   column into the final rows, which leaves each sorted. Allocates only when the lists outgrow every
   earlier one. */
/* Pairs within re from the cell scan, appended to *list (2 ints each, from pair *count on, the
   array grown as needed; *examined counts the candidates). Every cell holds its FLUID items, then
   its WALL items (from s->cell_wall[c]), then its DUMMY items (from s->cell_dummy[c]), so each kind
   of pair is one range of a neighbouring cell: with `solid` = 0 the pairs with a FLUID particle,
   with `solid` = 1 the WALL-WALL and WALL-DUMMY pairs. DUMMY-DUMMY pairs are never examined.
   Returns FSDEM_ERR_OUT_OF_MEMORY when the list cannot grow. */
static fsdem_result fsdem__mps_scan(fsdem_mps *s, int solid, int **list, int *cap, int *count, long long *examined) {
    const fsdem_cellgrid *g = &s->grid;
    const fsdem_real re2 = s->re * s->re;
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
                    *count += fsdem__dot(d, d) < re2;
                }
            }
    }
    return FSDEM_OK;
}

static fsdem_result fsdem__mps_neighbours(fsdem_mps *s) {
    const fsdem_cellgrid *g = &s->grid;
    const int solids = s->counts[FSDEM_MPS_KIND_WALL] + s->counts[FSDEM_MPS_KIND_DUMMY];
    const int explicit_scheme = s->desc.scheme == FSDEM_MPS_SCHEME_EXPLICIT;
    long long examined = 0;
    int c, a, i, e, count = 0;
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
    s->pair_count = count;
    s->candidates = examined;
    /* directed entries (r, c): c in the row of r, for every non-DUMMY r; first bucketed by column c
       (counting sort into tmp_nb/tmp_w, rows r), then scattered by row in column order, which
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
        void **arrays[8];
        size_t elem[8];
        void *fresh[8];
        int k, ok = 1;
        arrays[0] = (void **)&s->nb;
        arrays[1] = (void **)&s->tmp_nb;
        arrays[2] = (void **)&s->nbw;
        arrays[3] = (void **)&s->tmp_w;
        arrays[4] = (void **)&s->nbl;
        arrays[5] = (void **)&s->tmp_l;
        arrays[6] = (void **)&s->nbx;
        arrays[7] = (void **)&s->tmp_x;
        elem[0] = elem[1] = sizeof(int);
        for (k = 2; k < 8; ++k) elem[k] = sizeof(fsdem_real);
        if (!cap) return FSDEM_ERR_OUT_OF_MEMORY;
        for (k = 0; k < 8; ++k) ok &= (fresh[k] = fsdem__alloc(&s->allocator, elem[k] * (size_t)cap)) != NULL;
        if (!ok) {
            for (k = 0; k < 8; ++k) fsdem__free(&s->allocator, fresh[k], elem[k] * (size_t)cap);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
        for (k = 0; k < 8; ++k) {
            fsdem__free(&s->allocator, *arrays[k], elem[k] * (size_t)s->nb_cap);
            *arrays[k] = fresh[k];
        }
        s->bytes += 2 * (sizeof(int) + 3 * sizeof(fsdem_real)) * (size_t)(cap - s->nb_cap);
        s->nb_cap = cap;
    }
    memcpy(s->cursor, s->tmp_start, sizeof(int) * (size_t)s->n);
    for (e = 0; e < count; ++e) {
        const int pa = s->pairs[2 * e], pb = s->pairs[2 * e + 1];
        const fsdem_real r = fsdem__norm(fsdem__mps_sep(s, pb, pa));
        const fsdem_real w = fsdem__kernel_mps(r, s->re);
        const fsdem_real wl = s->re_lap == s->re ? w : r < s->re_lap ? fsdem__kernel_mps(r, s->re_lap) : 0;
        const fsdem_real wx = explicit_scheme && r > 0 ? fsdem__kernel_mps_explicit(r, s->re_x) / (r * r) : 0;
        if (s->kind[pa] != FSDEM_MPS_KIND_DUMMY) {
            s->tmp_nb[s->cursor[pb]] = pa;
            s->tmp_l[s->cursor[pb]] = wl;
            s->tmp_x[s->cursor[pb]] = wx;
            s->tmp_w[s->cursor[pb]++] = w;
        }
        if (s->kind[pb] != FSDEM_MPS_KIND_DUMMY) {
            s->tmp_nb[s->cursor[pa]] = pb;
            s->tmp_l[s->cursor[pa]] = wl;
            s->tmp_x[s->cursor[pa]] = wx;
            s->tmp_w[s->cursor[pa]++] = w;
        }
    }
    memcpy(s->cursor, s->nb_start, sizeof(int) * (size_t)s->n);
    for (c = 0; c < s->n; ++c)
        for (e = s->tmp_start[c]; e < s->tmp_start[c + 1]; ++e) {
            const int r = s->tmp_nb[e];
            s->nb[s->cursor[r]] = c;
            s->nbl[s->cursor[r]] = s->tmp_l[e];
            s->nbx[s->cursor[r]] = s->tmp_x[e];
            s->nbw[s->cursor[r]++] = s->tmp_w[e];
        }
    return FSDEM_OK;
}
