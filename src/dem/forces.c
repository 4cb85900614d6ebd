/* ---- >>dem_forces : contact force evaluation ---- */

/* The law the kernels are instantiated with: the desc's, or seed 002's linear law. */
static fsdem_dem_law fsdem__dem_kernel_law(const fsdem_dem *d) {
    return d->desc.law == FSDEM_DEM_LAW_LINEAR && !fsdem__dem_seed000_stiffness(&d->desc) ? FSDEM__DEM_LAW_SEED002 : d->desc.law;
}

/* The contact options as the kernels read them. */
static fsdem__dem_rules fsdem__dem_rules_of(const fsdem_dem *d) {
    fsdem__dem_rules r;
    r.total_history = d->desc.tangential_history == FSDEM_DEM_TANGENTIAL_HISTORY_TOTAL;
    r.cap_spring = d->desc.coulomb_limit == FSDEM_DEM_COULOMB_LIMIT_SPRING;
    r.cohesion = d->cohesive;
    r.offset = d->desc.contact_offset;
    r.area_depth = d->desc.dim == 2 ? d->desc.disc_length : 0;
    return r;
}

/* Material pair `pair`'s coefficients into lane c of a batch. */
static void fsdem__dem_gather_pair_coefficients(const fsdem_dem *d, fsdem__dem_batch *b, int c, int pair) {
    const fsdem__dem_pair *p = d->pairs + pair;
    b->pair[c] = pair;
    b->kn[c] = p->kn;
    b->cn[c] = p->cn;
    b->kt[c] = p->kt;
    b->ct[c] = p->ct;
    b->mu[c] = p->friction;
    b->coh[c] = p->cohesion;
}

/* Contact `k` of the particle-pair list into lane c of a batch; the coefficients of its material
   pair unless the batch is `uniform`, the mean mass only for the law that uses it. */
/* threaded: inside a team as on one thread: one lane of the calling thread's batch. */
FSDEM__FORCE_INLINE void fsdem__dem_gather_pair(const fsdem_dem *d, fsdem__dem_batch *FSDEM__RESTRICT b, int c, int k, const fsdem_dem_law law,
                                            int uniform) {
    const int i = d->pp.first[k], key = d->pp.key[k], j = FSDEM__DEM_PARTNER(key);
    const fsdem_vec3 vi = d->v[i], vj = d->v[j], wi = d->w[i], wj = d->w[j];
    const fsdem_vec3 e = fsdem__min_image(&d->periods, fsdem__sub(d->x[i], d->x[j]));
    const fsdem_vec3 spring = key & FSDEM__DEM_HELD ? d->pp.history[k] : fsdem__zero3();
    b->i[c] = i;
    b->other[c] = j;
    b->entry[c] = k;
    b->dx[0][c] = e.x;
    b->dx[1][c] = e.y;
    b->dx[2][c] = e.z;
    b->dv[0][c] = vi.x - vj.x;
    b->dv[1][c] = vi.y - vj.y;
    b->dv[2][c] = vi.z - vj.z;
    b->wi[0][c] = wi.x;
    b->wi[1][c] = wi.y;
    b->wi[2][c] = wi.z;
    b->wj[0][c] = wj.x;
    b->wj[1][c] = wj.y;
    b->wj[2][c] = wj.z;
    b->ri[c] = d->r[i];
    b->rj[c] = d->r[j];
    b->inv_mi[c] = d->inv_m[i];
    b->inv_mj[c] = d->inv_m[j];
    if (law == FSDEM_DEM_LAW_LINEAR) b->m_mean[c] = (d->m[i] + d->m[j]) / 2;
    b->spring[0][c] = spring.x;
    b->spring[1][c] = spring.y;
    b->spring[2][c] = spring.z;
    if (!uniform) fsdem__dem_gather_pair_coefficients(d, b, c, d->material[i] * d->material_count + d->material[j]);
    else b->pair[c] = 0;
}

/* Wall contact `hit` of particle i into lane c of a batch (coefficients as fsdem__dem_gather_pair). */
static void fsdem__dem_gather_wall(const fsdem_dem *d, fsdem__dem_batch *b, int c, int i, const fsdem__dem_wall_hit *hit, int uniform) {
    const int key = d->pw.key[hit->entry], wall = FSDEM__DEM_WALL_OF(key);
    const fsdem_real arm = d->r[i] - hit->delta / 2;
    const fsdem_vec3 n = hit->n, spring = key & FSDEM__DEM_HELD ? d->pw.history[hit->entry] : fsdem__zero3();
    const fsdem_vec3 vrel = fsdem__sub(fsdem__sub(d->v[i], fsdem__scale(fsdem__cross(d->w[i], n), arm)),
                                       d->walls[wall].d.velocity);
    b->i[c] = i;
    b->other[c] = wall;
    b->entry[c] = hit->entry;
    b->n[0][c] = n.x;
    b->n[1][c] = n.y;
    b->n[2][c] = n.z;
    b->delta[c] = hit->delta;
    b->vrel[0][c] = vrel.x;
    b->vrel[1][c] = vrel.y;
    b->vrel[2][c] = vrel.z;
    b->m_eff[c] = b->m_mean[c] = d->m[i];
    b->r_eff[c] = d->r[i];
    b->arm_i[c] = arm;
    b->spring[0][c] = spring.x;
    b->spring[1][c] = spring.y;
    b->spring[2][c] = spring.z;
    if (!uniform) fsdem__dem_gather_pair_coefficients(d, b, c, d->material[i] * d->material_count + d->walls[wall].d.material);
    else b->pair[c] = 0;
}

static fsdem_vec3 fsdem__dem_batch_vec(const fsdem_real (*a)[FSDEM__DEM_BATCH], int c) { return fsdem_v3(a[0][c], a[1][c], a[2][c]); }

/* Lane c's new spring into its list entry, which holds one from now on. */
static void fsdem__dem_commit_spring(fsdem__dem_list *l, const fsdem__dem_batch *b, int c) {
    l->history[b->entry[c]] = fsdem__dem_batch_vec(b->spring, c);
    l->key[b->entry[c]] |= FSDEM__DEM_HELD;
}

/* The rolling-resistance torque on lane c's particle (minus it on a partner particle) into *tr;
   returns 0 where its material pair has none. */
static int fsdem__dem_lane_rolling(const fsdem_dem *d, const fsdem__dem_batch *b, int c, int walls, fsdem_real h,
                                   fsdem_vec3 *tr) {
    const int i = b->i[c], o = b->other[c];
    const fsdem_real mu_r = d->pairs[b->pair[c]].rolling;
    if (!(mu_r > 0)) return 0;
    *tr = fsdem__dem_rolling_torque(walls ? d->w[i] : fsdem__sub(d->w[i], d->w[o]), mu_r, b->r_eff[c], b->fn[c],
                                    d->inv_i[i] + (walls ? 0 : d->inv_i[o]), h);
    return 1;
}

/* Adds a batch's forces and torques to the particles (and its walls, `walls`), commits the springs
   when `commit` and the law has history, and applies rolling resistance. */
FSDEM__FORCE_INLINE void fsdem__dem_scatter(fsdem_dem *d, const fsdem__dem_batch *FSDEM__RESTRICT b, const int walls, int commit,
                                        fsdem_real h) {
    fsdem__dem_list *l = walls ? &d->pw : &d->pp;
    fsdem_vec3 *FSDEM__RESTRICT f = d->f, *FSDEM__RESTRICT t = d->t;
    fsdem_real max_overlap = d->max_overlap;
    int c;
    for (c = 0; c < b->count; ++c) {
        const int i = b->i[c], o = b->other[c];
        const fsdem_vec3 force = fsdem__dem_batch_vec(b->force, c), torque = fsdem__dem_batch_vec(b->torque_i, c);
        f[i] = fsdem__add(f[i], force);
        t[i] = fsdem__add(t[i], torque);
        if (walls) d->walls[o].force = fsdem__sub(d->walls[o].force, force);
        else {
            f[o] = fsdem__sub(f[o], force);
            t[o] = fsdem__add(t[o], fsdem__dem_batch_vec(b->torque_j, c));
        }
        if (commit) fsdem__dem_commit_spring(l, b, c);
        if (b->delta[c] > max_overlap) max_overlap = b->delta[c];
    }
    d->max_overlap = max_overlap;
    if (d->rolling)
        for (c = 0; c < b->count; ++c) {
            const int i = b->i[c], o = b->other[c];
            fsdem_vec3 tr;
            if (!fsdem__dem_lane_rolling(d, b, c, walls, h, &tr)) continue;
            t[i] = fsdem__add(t[i], tr);
            if (!walls) t[o] = fsdem__sub(t[o], tr);
        }
}

/* The entries [k0, k1) of the particle-pair list whose pair touches, into `touching`; returns their
   number. With `commit`, the pairs that do not touch lose their spring. Branch-free, and
   instantiated with and without `commit`. */
/* threaded: inside a team: one chunk of the pair list. */
FSDEM__FORCE_INLINE int fsdem__dem_touching_range(fsdem_dem *d, int *FSDEM__RESTRICT touching, int k0, int k1, const int commit,
                                                  const int periodic) {
    const fsdem_real off = d->desc.contact_offset;
    const fsdem_vec3 *FSDEM__RESTRICT x = d->x;
    const fsdem_real *FSDEM__RESTRICT r = d->r;
    const int *FSDEM__RESTRICT first = d->pp.first;
    int *FSDEM__RESTRICT keys = d->pp.key;
    int k, count = 0;
    for (k = k0; k < k1; ++k) {
        const int key = keys[k], i = first[k], j = FSDEM__DEM_PARTNER(key);
        const fsdem_vec3 e = periodic ? fsdem__min_image(&d->periods, fsdem__sub(x[i], x[j])) : fsdem__sub(x[i], x[j]);
        const fsdem_real ex = e.x, ey = e.y, ez = e.z, reach = r[i] + r[j] + off;
        const int touch = ex * ex + ey * ey + ez * ez < reach * reach;
        touching[count] = k;
        count += touch;
        if (commit) keys[k] = key & ~((touch - 1) & FSDEM__DEM_HELD); /* arithmetic: a branch here would mispredict */
    }
    return count;
}

/* The touching entries of the whole pair list into `touching`, in list order: on `team` threads chunk
   by chunk (each chunk's entries at its own start, then moved together), else in one pass. */
/* threaded: opens a team over the chunks of the pair list. */
static int fsdem__dem_touching(fsdem_dem *d, int *touching, int commit, int team, int *chunk_count) {
    const int pairs = d->pp.count, chunks = pairs / FSDEM__DEM_CHUNK + 1, periodic = d->periods.any;
    int q, count = 0;
    if (team <= 1 || chunks <= 1) {
        if (periodic) return commit ? fsdem__dem_touching_range(d, touching, 0, pairs, 1, 1) : fsdem__dem_touching_range(d, touching, 0, pairs, 0, 1);
        return commit ? fsdem__dem_touching_range(d, touching, 0, pairs, 1, 0) : fsdem__dem_touching_range(d, touching, 0, pairs, 0, 0);
    }
    FSDEM__OMP(parallel for schedule(static) num_threads(team))
    for (q = 0; q < chunks; ++q) {
        const int k0 = q * FSDEM__DEM_CHUNK, k1 = pairs - k0 < FSDEM__DEM_CHUNK ? pairs : k0 + FSDEM__DEM_CHUNK;
        int *out = touching + k0;
        if (periodic) chunk_count[q] = commit ? fsdem__dem_touching_range(d, out, k0, k1, 1, 1) : fsdem__dem_touching_range(d, out, k0, k1, 0, 1);
        else chunk_count[q] = commit ? fsdem__dem_touching_range(d, out, k0, k1, 1, 0) : fsdem__dem_touching_range(d, out, k0, k1, 0, 0);
    }
    for (q = 0; q < chunks; ++q) {
        memmove(touching + count, touching + (size_t)q * FSDEM__DEM_CHUNK, sizeof(int) * (size_t)chunk_count[q]);
        count += chunk_count[q];
    }
    return count;
}

/* A batch's results into `out` (one per lane), with the rolling-resistance torque where the pair has
   it, its springs committed when `commit`; returns its largest overlap. */
/* threaded: inside a team: one batch. */
static fsdem_real fsdem__dem_keep_results(fsdem_dem *d, const fsdem__dem_batch *b, fsdem__dem_result *out, int commit,
                                          fsdem_real h) {
    fsdem_real max_overlap = 0;
    int c;
    for (c = 0; c < b->count; ++c) {
        fsdem__dem_result *o = out + c;
        o->i = b->i[c];
        o->other = b->other[c];
        o->force = fsdem__dem_batch_vec(b->force, c);
        o->torque_i = fsdem__dem_batch_vec(b->torque_i, c);
        o->torque_j = fsdem__dem_batch_vec(b->torque_j, c);
        o->rolls = d->rolling && fsdem__dem_lane_rolling(d, b, c, 0, h, &o->rolling);
        if (commit) fsdem__dem_commit_spring(&d->pp, b, c);
        if (b->delta[c] > max_overlap) max_overlap = b->delta[c];
    }
    return max_overlap;
}

/* Adds the results of `count` touching pairs to the particles in [lo, hi), in the order
   fsdem__dem_scatter adds them on one thread: batch by batch, in each the forces and torques pair
   by pair, then the rolling torques. Each thread adds to its own particles only. */
/* threaded: inside a team: the calling thread's particles. */
static void fsdem__dem_add_results(fsdem_dem *d, const fsdem__dem_result *res, int count, int lo, int hi) {
    fsdem_vec3 *FSDEM__RESTRICT f = d->f, *FSDEM__RESTRICT t = d->t;
    int b0, c;
    for (b0 = 0; b0 < count; b0 += FSDEM__DEM_BATCH) {
        const int b1 = count - b0 < FSDEM__DEM_BATCH ? count : b0 + FSDEM__DEM_BATCH;
        for (c = b0; c < b1; ++c) {
            const fsdem__dem_result *r = res + c;
            if (r->i >= lo && r->i < hi) {
                f[r->i] = fsdem__add(f[r->i], r->force);
                t[r->i] = fsdem__add(t[r->i], r->torque_i);
            }
            if (r->other >= lo && r->other < hi) {
                f[r->other] = fsdem__sub(f[r->other], r->force);
                t[r->other] = fsdem__add(t[r->other], r->torque_j);
            }
        }
        for (c = b0; c < b1; ++c) {
            const fsdem__dem_result *r = res + c;
            if (!r->rolls) continue;
            if (r->i >= lo && r->i < hi) t[r->i] = fsdem__add(t[r->i], r->rolling);
            if (r->other >= lo && r->other < hi) t[r->other] = fsdem__sub(t[r->other], r->rolling);
        }
    }
}

/* The touching pairs' forces on `team` threads: batches of the contact list evaluated in parallel
   into per-pair results, then added to the particles by their owners in list order, so every
   particle sums the same terms in the same order as on one thread. */
/* threaded: opens a team over the batches, then over the particles. */
FSDEM__FORCE_INLINE void fsdem__dem_pairs_threaded(fsdem_dem *d, const int *touching, int nt, fsdem__dem_batch *batches,
                                               fsdem__dem_result *res, fsdem_real *overlaps, int team, fsdem_real h,
                                               int keep, const fsdem_dem_law law, const fsdem__dem_rules *rules) {
    const int uniform = d->material_count == 1, nb = (nt + FSDEM__DEM_BATCH - 1) / FSDEM__DEM_BATCH, n = d->n;
    const fsdem__dem_pair *pairs = uniform ? d->pairs : NULL;
    int w;
    for (w = 0; w < team; ++w) overlaps[w] = 0; /* (a team may come with fewer threads than asked) */
    FSDEM__OMP(parallel num_threads(team))
    {
        const int me = fsdem__worker();
        fsdem__dem_batch *b = batches + me;
        fsdem_real largest = 0;
        int q, c, lo, hi;
        FSDEM__OMP(for schedule(static))
        for (q = 0; q < nb; ++q) {
            const int k0 = q * FSDEM__DEM_BATCH, k1 = nt - k0 < FSDEM__DEM_BATCH ? nt : k0 + FSDEM__DEM_BATCH;
            fsdem_real m;
            b->count = 0;
            for (c = k0; c < k1; ++c) fsdem__dem_gather_pair(d, b, b->count++, touching[c], law, uniform);
            fsdem__dem_batch_pad(b, 1, uniform);
            fsdem__dem_batch_law(b, law, h, 1, d->desc.contact_offset, pairs, rules);
            m = fsdem__dem_keep_results(d, b, res + k0, keep, h);
            if (m > largest) largest = m;
        }
        overlaps[me] = largest;
        fsdem__share(n, &lo, &hi);
        fsdem__dem_add_results(d, res, nt, lo, hi);
    }
    for (w = 0; w < team; ++w)
        if (overlaps[w] > d->max_overlap) d->max_overlap = overlaps[w];
}

/* Runs the kernels on a filled batch (particle pairs or, with `walls`, wall contacts), applies it
   and empties it; returns the number of contacts it held. */
FSDEM__FORCE_INLINE int fsdem__dem_drain(fsdem_dem *d, fsdem__dem_batch *b, int walls, const fsdem_dem_law law, fsdem_real h,
                                     int keep, const fsdem__dem_rules *rules) {
    const int count = b->count;
    const fsdem__dem_pair *uniform = d->material_count == 1 ? d->pairs : NULL;
    fsdem__dem_batch_pad(b, !walls, uniform != NULL);
    if (walls) fsdem__dem_batch_law(b, law, h, 0, 0, uniform, rules);
    else fsdem__dem_batch_law(b, law, h, 1, d->desc.contact_offset, uniform, rules);
    fsdem__dem_scatter(d, b, walls, keep, h);
    b->count = 0;
    return count;
}

/* Contact forces and torques of all particle pairs and particle-wall contacts into f, t and the
   walls' force; `h` is the step the history and the one-step spring of seed 000 Eq. 8 use, and the
   springs are kept when `commit` (the predictor of the predictor-corrector does not keep them).
   A pass over the whole pair list finds the touching pairs without branching; they and the wall
   contacts then go through the vector kernels a batch at a time. Written once, instantiated per
   contact law (fsdem__dem_compute_forces). */
FSDEM__FORCE_INLINE void fsdem__dem_compute_forces_law(fsdem_dem *d, fsdem_real h, int commit, const fsdem_dem_law law) {
    const int n = d->n, keep = commit && (law == FSDEM_DEM_LAW_HERTZ_MINDLIN || law == FSDEM__DEM_LAW_SEED002);
    const int uniform = d->material_count == 1, team = fsdem__team_for(d->pp.count, 2 * FSDEM__DEM_CHUNK, d->workers);
    const fsdem__dem_rules rules = fsdem__dem_rules_of(d);
    fsdem__dem_batch *b, *batches;
    int *touching, *chunk_count = NULL, i, k, c, nt = 0, nw = 0;
    fsdem__arena_reset(&d->arena);
    touching = (int *)fsdem__arena_push(&d->arena, sizeof(int) * (size_t)d->pp.count);
    b = batches = (fsdem__dem_batch *)fsdem__arena_push(&d->arena, sizeof *b * (size_t)d->workers);
    if (team > 1) chunk_count = (int *)fsdem__arena_push(&d->arena, sizeof(int) * (size_t)(d->pp.count / FSDEM__DEM_CHUNK + 1));
    if (!d->forces_cleared) {
        memset(d->f, 0, sizeof *d->f * (size_t)n);
        memset(d->t, 0, sizeof *d->t * (size_t)n);
    }
    d->forces_cleared = 0;
    for (k = 0; k < d->wall_count; ++k) d->walls[k].force = fsdem__zero3();
    d->max_overlap = 0;
    nt = fsdem__dem_touching(d, touching, commit, team, chunk_count);
    b->count = 0;
    if (team > 1) {
        fsdem__dem_result *res = (fsdem__dem_result *)fsdem__arena_push(&d->arena, sizeof(fsdem__dem_result) * (size_t)d->pp.count);
        fsdem_real *overlaps = (fsdem_real *)fsdem__arena_push(&d->arena, sizeof(fsdem_real) * (size_t)team);
        fsdem__dem_pairs_threaded(d, touching, nt, batches, res, overlaps, team, h, keep, law, &rules);
        b->count = 0; /* the walls' batches follow in the first */
    } else {
        for (k = 0; k < nt; ++k) {
            fsdem__dem_gather_pair(d, b, b->count++, touching[k], law, uniform);
            if (b->count == FSDEM__DEM_BATCH || k == nt - 1) fsdem__dem_drain(d, b, 0, law, h, keep, &rules);
        }
    }
    for (k = 0; k < d->pw.count; k = d->pw.start[i + 1]) {
        /* row to row through the particles with wall entries */
        int nh;
        i = d->pw.first[k];
        if (d->inv_m[i] == 0) continue; /* fixed: no wall force */
        nh = fsdem__dem_wall_hits(d, i, commit);
        for (c = 0; c < nh; ++c) {
            fsdem__dem_gather_wall(d, b, b->count++, i, &d->hits[c], uniform);
            if (b->count == FSDEM__DEM_BATCH) nw += fsdem__dem_drain(d, b, 1, law, h, keep, &rules);
        }
    }
    if (b->count) nw += fsdem__dem_drain(d, b, 1, law, h, keep, &rules);
    d->contacts = nt;
    d->wall_contacts = nw;
    d->forces_valid = 1;
}

static void fsdem__dem_compute_forces(fsdem_dem *d, fsdem_real h, int commit) {
    switch ((int)fsdem__dem_kernel_law(d)) {
    case FSDEM_DEM_LAW_LINEAR: fsdem__dem_compute_forces_law(d, h, commit, FSDEM_DEM_LAW_LINEAR); break;
    case FSDEM_DEM_LAW_GIC: fsdem__dem_compute_forces_law(d, h, commit, FSDEM_DEM_LAW_GIC); break;
    case FSDEM__DEM_LAW_SEED002: fsdem__dem_compute_forces_law(d, h, commit, FSDEM__DEM_LAW_SEED002); break;
    default: fsdem__dem_compute_forces_law(d, h, commit, FSDEM_DEM_LAW_HERTZ_MINDLIN); break;
    }
}
