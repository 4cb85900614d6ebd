/* ---- >>pic_reseed : particle counts per cell ---- */

/* Counting sort of the particles by cell: cstart (ncell + 1 offsets), pidx (particle order). */
static void fsdem__pic_bin(fsdem_pic *s) {
    int p, c, sum = 0;
    memset(s->cstart, 0, sizeof(int) * (size_t)(s->ncell + 1));
    for (p = 0; p < s->np; ++p) {
        c = fsdem__mac_cell_of(&s->mac, s->px[p]);
        s->pcell[p] = c;
        s->cstart[c + 1]++;
    }
    for (c = 0; c < s->ncell; ++c) {
        sum += s->cstart[c + 1];
        s->cstart[c + 1] = sum;
    }
    for (p = 0; p < s->np; ++p) s->pidx[s->cstart[s->pcell[p]]++] = p;
    for (c = s->ncell; c > 0; --c) s->cstart[c] = s->cstart[c - 1];
    s->cstart[0] = 0;
}

/* Reorders the particle arrays by cell (cache locality of the transfers). */
static void fsdem__pic_sort(fsdem_pic *s) {
    fsdem_vec3 **arrays[5];
    int n = 2, a, p;
    fsdem__pic_bin(s);
    arrays[0] = &s->px;
    arrays[1] = &s->pv;
    if (s->pc[0]) {
        arrays[2] = &s->pc[0];
        arrays[3] = &s->pc[1];
        arrays[4] = &s->pc[2];
        n = 5;
    }
    for (a = 0; a < n; ++a) {
        fsdem_vec3 *src = *arrays[a], *dst = s->ptmp;
        for (p = 0; p < s->np; ++p) dst[p] = src[s->pidx[p]];
        s->ptmp = src;
        *arrays[a] = dst;
    }
}

static int fsdem__pic_append(fsdem_pic *s, fsdem_vec3 x, fsdem_vec3 v) {
    if (s->np >= s->pcap) {
        s->refused++;
        return 0;
    }
    if (s->dim == 2) {
        x.z = 0;
        v.z = 0;
    }
    s->px[s->np] = x;
    s->pv[s->np] = v;
    if (s->pc[0]) s->pc[0][s->np] = s->pc[1][s->np] = s->pc[2][s->np] = fsdem__zero3();
    s->pflag[s->np] = 0;
    s->np++;
    s->reseeded++;
    return 1;
}

/* Random open position in cell (i, j, k); 0 when none was found in a few tries. */
static int fsdem__pic_random_in_cell(fsdem_pic *s, int i, int j, int k, fsdem_vec3 *out) {
    int t;
    for (t = 0; t < 8; ++t) {
        /* one draw per statement: C leaves the order of a function's arguments unspecified, so
           draws in one argument list would give different runs with different compilers */
        const fsdem_real rx = fsdem__pic_rand(s), ry = fsdem__pic_rand(s), rz = s->dim == 3 ? fsdem__pic_rand(s) : 0;
        fsdem_vec3 p = fsdem_v3(s->lo.x + s->dx * ((fsdem_real)i + rx), s->lo.y + s->dx * ((fsdem_real)j + ry),
                                s->dim == 3 ? s->lo.z + s->dx * ((fsdem_real)k + rz) : 0);
        if (fsdem__pic_open_at(s, p)) {
            *out = p;
            return 1;
        }
    }
    return 0;
}

/* A particle that a crowded neighbour of cell (i, j, k) can give up for volume-neutral reseeding:
   from the cell of the 3^dim block around with the most particles, if it holds more than
   particles_per_cell (counting those already taken, in taken[]); -1 when there is none. */
static int fsdem__pic_donor(fsdem_pic *s, int i, int j, int k, int *taken) {
    int di, dj, dk, best = -1, best_count = s->ppc, zr = s->dim == 3 ? 1 : 0, maxp = s->desc.max_particles_per_cell;
    for (dk = -zr; dk <= zr; ++dk)
        for (dj = -1; dj <= 1; ++dj)
            for (di = -1; di <= 1; ++di) {
                int x = i + di, y = j + dj, z = k + dk, c, count;
                if (x < 0 || y < 0 || z < 0 || x >= s->n[0] || y >= s->n[1] || z >= s->n[2]) continue;
                c = fsdem__mac_cell(&s->mac, x, y, z);
                count = s->cstart[c + 1] - s->cstart[c];
                if (maxp > 0 && count > maxp) count = maxp; /* the rest is already removed */
                count -= taken[c];
                if (count > best_count) {
                    best_count = count;
                    best = c;
                }
            }
    if (best < 0) return -1;
    taken[best]++;
    return s->pidx[s->cstart[best] + best_count - 1];
}

/* Keeps the particle counts of the cells in range without changing the water volume (the particle
   count is the volume once the density projection has evened the particles out):
   - cells with more than max_particles_per_cell lose the excess;
   - interior fluid cells (no air neighbour) with fewer than min_particles_per_cell (times the part
     of the cell's kernel that solids leave open) and a fluid
     fraction below 1 get particles up to that minimum (with the grid velocity), each one taken
     from a crowded neighbour (more than particles_per_cell); without such a neighbour nothing is
     added (the density projection evens out the rest);
   - cells along inflow sides are topped up to particles_per_cell with the inflow velocity (the
     inflow brings volume in).
   Uses the cell types of the current positions. Returns 1 when particles changed. */
static int fsdem__pic_reseed(fsdem_pic *s) {
    int c, i, j, k, a, sg, q, maxp = s->desc.max_particles_per_cell, minp = s->desc.min_particles_per_cell;
    int removed = 0, moved = 0, *taken = s->fqueue; /* fqueue has >= ncell entries and is free here */
    int np0 = s->np;
    fsdem__pic_bin(s);
    memset(taken, 0, sizeof(int) * (size_t)s->ncell);
    if (maxp > 0)
        for (c = 0; c < s->ncell; ++c) {
            int count = s->cstart[c + 1] - s->cstart[c];
            if (count > maxp) {
                for (q = maxp; q < count; ++q) s->pflag[s->pidx[s->cstart[c] + q]] = 1;
                removed += count - maxp;
            }
        }
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                int count, coord[3], interior = 1, inflow = -1;
                c = fsdem__mac_cell(&s->mac, i, j, k);
                count = s->cstart[c + 1] - s->cstart[c] - taken[c];
                if (s->ctype[c] == FSDEM_STENCIL_CELL_SOLID || (maxp > 0 && count > maxp)) continue;
                coord[0] = i;
                coord[1] = j;
                coord[2] = k;
                for (a = 0; a < s->dim; ++a)
                    for (sg = 0; sg < 2; ++sg) {
                        int nc = coord[a] + (sg ? 1 : -1);
                        if (nc < 0 || nc >= s->n[a]) {
                            if (s->desc.boundary[2 * a + sg] == FSDEM_PIC_BC_INFLOW) inflow = 2 * a + sg;
                            continue;
                        }
                        if (s->ctype[c + (sg ? 1 : -1) * s->cstep[a]] == FSDEM_STENCIL_CELL_AIR) interior = 0;
                    }
                if (inflow >= 0) {
                    fsdem_vec3 x;
                    for (q = count; q < s->ppc; ++q)
                        if (fsdem__pic_random_in_cell(s, i, j, k, &x)) fsdem__pic_append(s, x, s->desc.boundary_velocity[inflow]);
                    continue;
                }
                /* the minimum is that of the cell's open part (the solids' share of the kernel aside) */
                if (minp > 0 && count < minp * s->fref[c] * s->cref[c] * s->cpor[c] && interior && s->ctype[c] == FSDEM_STENCIL_CELL_FLUID &&
                    s->frac[c] < 1) {
                    fsdem_vec3 x;
                    for (q = count; q < minp; ++q) {
                        int donor;
                        if (!fsdem__pic_random_in_cell(s, i, j, k, &x)) break;
                        donor = fsdem__pic_donor(s, i, j, k, taken);
                        if (donor < 0) break;
                        if (!fsdem__pic_append(s, x, fsdem__pic_interp_vel(s, s->u, x))) {
                            break;
                        }
                        s->reseeded--; /* a move, not a new particle */
                        s->pflag[donor] = 1;
                        moved++;
                    }
                }
            }
    if (removed || moved) fsdem__pic_remove_marked(s);
    s->removed += removed;
    s->moved += moved;
    return removed || moved || s->np != np0;
}
