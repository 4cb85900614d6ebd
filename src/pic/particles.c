/* ---- >>pic_particles : storage, seeding ---- */

/* Reallocates every particle array to `cap` (>= np). Leaves everything unchanged on failure. */
static fsdem_result fsdem__pic_set_capacity(fsdem_pic *s, int cap) {
    fsdem_vec3 *x, *v, *t, *c[3] = {NULL, NULL, NULL};
    int *cell, *idx, a, apic = s->desc.transfer == FSDEM_PIC_TRANSFER_APIC, ok = 1;
    unsigned char *flag;
    size_t n = (size_t)s->np, vb = sizeof(fsdem_vec3) * (size_t)cap;
    if (cap < s->np || cap > (1 << 29)) return FSDEM_ERR_OUT_OF_MEMORY;
    x = (fsdem_vec3 *)fsdem__pic_alloc(s, vb);
    v = (fsdem_vec3 *)fsdem__pic_alloc(s, vb);
    t = (fsdem_vec3 *)fsdem__pic_alloc(s, vb);
    for (a = 0; a < 3 && apic; ++a) {
        c[a] = (fsdem_vec3 *)fsdem__pic_alloc(s, vb);
        if (!c[a]) ok = 0;
    }
    cell = (int *)fsdem__pic_alloc(s, sizeof(int) * (size_t)cap);
    idx = (int *)fsdem__pic_alloc(s, sizeof(int) * (size_t)cap);
    flag = (unsigned char *)fsdem__pic_alloc(s, (size_t)cap);
    if (!x || !v || !t || !cell || !idx || !flag || !ok) {
        fsdem__pic_release(s, x, x ? vb : 0);
        fsdem__pic_release(s, v, v ? vb : 0);
        fsdem__pic_release(s, t, t ? vb : 0);
        for (a = 0; a < 3; ++a) fsdem__pic_release(s, c[a], c[a] ? vb : 0);
        fsdem__pic_release(s, cell, cell ? sizeof(int) * (size_t)cap : 0);
        fsdem__pic_release(s, idx, idx ? sizeof(int) * (size_t)cap : 0);
        fsdem__pic_release(s, flag, flag ? (size_t)cap : 0);
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    if (n) {
        memcpy(x, s->px, n * sizeof(fsdem_vec3));
        memcpy(v, s->pv, n * sizeof(fsdem_vec3));
        for (a = 0; a < 3 && apic; ++a) memcpy(c[a], s->pc[a], n * sizeof(fsdem_vec3));
    }
    memset(flag, 0, (size_t)cap);
    n = (size_t)s->np;
    fsdem__pic_free_particles(s);
    s->np = (int)n;
    s->px = x;
    s->pv = v;
    s->ptmp = t;
    for (a = 0; a < 3; ++a) s->pc[a] = c[a];
    s->pcell = cell;
    s->pidx = idx;
    s->pflag = flag;
    s->pcap = cap;
    return FSDEM_OK;
}

/* Makes room for `need` particles plus half as many again for reseeding and inflow. */
static fsdem_result fsdem__pic_make_room(fsdem_pic *s, long need) {
    long want = need + need / 2 + 64;
    if (need > (1 << 28)) return FSDEM_ERR_OUT_OF_MEMORY;
    if (need <= s->pcap && s->pcap >= need + need / 4) return FSDEM_OK;
    return fsdem__pic_set_capacity(s, (int)want);
}

fsdem_result fsdem_pic_reserve(fsdem_pic *s, int count) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (count < 0) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_reserve: count = %d < 0", count);
    if (count <= s->pcap) return fsdem__ok(&s->status);
    if (fsdem__pic_set_capacity(s, count) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_reserve: out of memory for %d particles", count);
    return fsdem__ok(&s->status);
}

/* Removes the particles whose pflag is set, keeping the order of the others. */
static void fsdem__pic_remove_marked(fsdem_pic *s) {
    int i, j = 0, a, apic = s->pc[0] != NULL;
    for (i = 0; i < s->np; ++i) {
        if (s->pflag[i]) continue;
        if (j != i) {
            s->px[j] = s->px[i];
            s->pv[j] = s->pv[i];
            for (a = 0; a < 3 && apic; ++a) s->pc[a][j] = s->pc[a][i];
        }
        ++j;
    }
    s->np = j;
    memset(s->pflag, 0, (size_t)s->pcap);
    s->cells_fresh = 0;
}


/* Is p a valid place for a particle: inside the grid box and outside the obstacles. */
static int fsdem__pic_open_at(const fsdem_pic *s, fsdem_vec3 p) {
    int b;
    for (b = 0; b < s->dim; ++b)
        if (!(fsdem__comp(p, b) > fsdem__comp(s->lo, b) && fsdem__comp(p, b) < fsdem__comp(s->hi, b))) return 0;
    if (s->cnear[fsdem__mac_cell_of(&s->mac, p)] && fsdem__pic_obst_min(s, p, NULL) <= 0) return 0;
    return 1;
}

/* Seed position q (0 .. ppc-1) in cell (i, j, k): stratified with jitter when ppc = sub^dim. */
static fsdem_vec3 fsdem__pic_seed_pos(fsdem_pic *s, int i, int j, int k, int q) {
    fsdem_real f[3];
    int b, idx[3];
    idx[0] = i;
    idx[1] = j;
    idx[2] = k;
    for (b = 0; b < 3; ++b) {
        if (b >= s->dim) {
            f[b] = 0;
            continue;
        }
        if (s->sub) {
            int sq = q % s->sub;
            q /= s->sub;
            f[b] = ((fsdem_real)sq + (fsdem_real)0.5 + s->desc.jitter * (fsdem__pic_rand(s) - (fsdem_real)0.5)) /
                   (fsdem_real)s->sub;
        } else {
            f[b] = fsdem__pic_rand(s);
        }
        f[b] = fsdem__comp(s->lo, b) + s->dx * ((fsdem_real)idx[b] + f[b]);
    }
    return fsdem_v3(f[0], f[1], s->dim == 3 ? f[2] : 0);
}

static fsdem_result fsdem__pic_fill(fsdem_pic *s, fsdem_vec3 lo, fsdem_vec3 hi, fsdem_sdf_fn region, void *user,
                                    fsdem_vec3 vel, int *added, const char *what) {
    int c0[3], c1[3], b, i, j, k, q, start = s->np;
    long cells = 1;
    for (b = 0; b < 3; ++b) {
        if (b >= s->dim) {
            c0[b] = 0;
            c1[b] = 0;
            continue;
        }
        c0[b] = fsdem__mac_coord(&s->mac, fsdem__comp(lo, b), b);
        c1[b] = fsdem__mac_coord(&s->mac, fsdem__comp(hi, b), b);
        cells *= c1[b] - c0[b] + 1;
    }
    if (fsdem__pic_make_room(s, (long)s->np + cells * s->ppc) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_%s: out of memory for %ld more particles", what,
                           cells * s->ppc);
    for (k = c0[2]; k <= c1[2]; ++k)
        for (j = c0[1]; j <= c1[1]; ++j)
            for (i = c0[0]; i <= c1[0]; ++i) {
                if (s->csolid[fsdem__mac_cell(&s->mac, i, j, k)]) continue;
                for (q = 0; q < s->ppc; ++q) {
                    fsdem_vec3 p = fsdem__pic_seed_pos(s, i, j, k, q);
                    int inside = 1;
                    for (b = 0; b < s->dim; ++b)
                        if (fsdem__comp(p, b) < fsdem__comp(lo, b) || fsdem__comp(p, b) >= fsdem__comp(hi, b)) inside = 0;
                    if (!inside || !fsdem__pic_open_at(s, p)) continue;
                    if (region) {
                        fsdem_vec3 nrm;
                        if (!(region(user, p, &nrm) > 0)) continue;
                    }
                    s->px[s->np] = p;
                    s->pv[s->np] = vel;
                    if (s->pc[0]) s->pc[0][s->np] = s->pc[1][s->np] = s->pc[2][s->np] = fsdem__zero3();
                    s->np++;
                }
            }
    if (added) *added = s->np - start;
    fsdem__pic_refresh(s);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_pic_fill_box(fsdem_pic *s, fsdem_vec3 lo, fsdem_vec3 hi, fsdem_vec3 velocity, int *added) {
    int b;
    if (added) *added = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!fsdem__finite3(lo) || !fsdem__finite3(hi) || !fsdem__within(velocity, FSDEM_MAX_SPEED))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pic_fill_box: a non-finite corner, or a velocity (%g, %g, %g) m/s that is not finite or above "
                           "FSDEM_MAX_SPEED (%g m/s)",
                           (double)velocity.x, (double)velocity.y, (double)velocity.z, (double)FSDEM_MAX_SPEED);
    for (b = 0; b < s->dim; ++b) {
        if (!(fsdem__comp(hi, b) > fsdem__comp(lo, b)))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_fill_box: hi.%c must exceed lo.%c", "xyz"[b], "xyz"[b]);
        if (fsdem__comp(lo, b) < fsdem__comp(s->lo, b)) lo = fsdem__axis_shift(lo, b, fsdem__comp(s->lo, b) - fsdem__comp(lo, b));
        if (fsdem__comp(hi, b) > fsdem__comp(s->hi, b)) hi = fsdem__axis_shift(hi, b, fsdem__comp(s->hi, b) - fsdem__comp(hi, b));
        if (!(fsdem__comp(hi, b) > fsdem__comp(lo, b)))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_fill_box: the box is outside the domain along %c",
                               "xyz"[b]);
    }
    return fsdem__pic_fill(s, lo, hi, NULL, NULL, velocity, added, "fill_box");
}

fsdem_result fsdem_pic_fill_sdf(fsdem_pic *s, fsdem_sdf_fn region, void *user, fsdem_vec3 velocity, int *added) {
    if (added) *added = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!region) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_fill_sdf: NULL region");
    if (!fsdem__within(velocity, FSDEM_MAX_SPEED))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pic_fill_sdf: the velocity (%g, %g, %g) m/s must be finite and at most FSDEM_MAX_SPEED (%g m/s)",
                           (double)velocity.x, (double)velocity.y, (double)velocity.z, (double)FSDEM_MAX_SPEED);
    return fsdem__pic_fill(s, s->lo, s->hi, region, user, velocity, added, "fill_sdf");
}

fsdem_result fsdem_pic_add_particles(fsdem_pic *s, const fsdem_vec3 *x, const fsdem_vec3 *v, int count) {
    int i;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (count < 0 || (count > 0 && !x))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_particles: bad count %d or NULL positions", count);
    for (i = 0; i < count; ++i) {
        fsdem_vec3 p = x[i];
        if (!fsdem__finite3(p) || (v && !fsdem__within(v[i], FSDEM_MAX_SPEED)))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                               "fsdem_pic_add_particles: particle %d has a non-finite position, or a velocity that is not finite or "
                               "above FSDEM_MAX_SPEED (%g m/s)",
                               i, (double)FSDEM_MAX_SPEED);
        if (s->dim == 2) p.z = 0;
        if (!fsdem__pic_open_at(s, p))
            return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_DOMAIN,
                               "fsdem_pic_add_particles: particle %d at (%g, %g, %g) is outside the domain or inside a solid", i,
                               (double)p.x, (double)p.y, (double)p.z);
    }
    if (fsdem__pic_make_room(s, (long)s->np + count) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_add_particles: out of memory for %d particles",
                           s->np + count);
    for (i = 0; i < count; ++i) {
        s->px[s->np] = x[i];
        if (s->dim == 2) s->px[s->np].z = 0;
        s->pv[s->np] = v ? v[i] : fsdem__zero3();
        if (s->dim == 2) s->pv[s->np].z = 0;
        if (s->pc[0]) s->pc[0][s->np] = s->pc[1][s->np] = s->pc[2][s->np] = fsdem__zero3();
        s->np++;
    }
    fsdem__pic_refresh(s);
    return fsdem__ok(&s->status);
}

fsdem_pic_particles fsdem_pic_get_particles(fsdem_pic *s) {
    fsdem_pic_particles v;
    memset(&v, 0, sizeof v);
    if (!s) return v;
    v.count = s->np;
    v.dim = s->dim;
    v.volume = s->pvol;
    v.position = s->px;
    v.velocity = s->pv;
    return v;
}
