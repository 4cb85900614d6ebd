/* ---- >>dem_diagnostics : time-step estimates, energy, statistics ---- */

fsdem_result fsdem_dem_stable_dt(const fsdem_dem *d, fsdem_real *dt) {
    fsdem__status *st;
    if (!d || !dt) return FSDEM_ERR_INVALID_ARG;
    st = (fsdem__status *)&d->status; /* the message is the object's only mutable part here */
    if (d->n == 0) return fsdem__fail(st, FSDEM_ERR_NOT_FOUND, "fsdem_dem_stable_dt: there are no particles");
    *dt = fsdem__dem_rule_dt(d);
    return fsdem__ok(st);
}

/* Elastic energy (J) stored in one contact's normal and tangential springs: overlap delta, mean
   and effective radius as the force kernels see them (fsdem__dem_batch). */
static fsdem_real fsdem__dem_contact_energy(const fsdem_dem *d, const fsdem__dem_pair *p, fsdem_real delta, fsdem_real m_mean,
                                        fsdem_real r_eff, fsdem_vec3 history) {
    switch ((int)fsdem__dem_kernel_law(d)) {
    case FSDEM_DEM_LAW_LINEAR: return (fsdem_real)0.5 * m_mean * d->k0_linear * delta * delta;
    case FSDEM_DEM_LAW_GIC: return (fsdem_real)0.5 * p->e_pair * 2 * r_eff * delta * delta;
    case FSDEM__DEM_LAW_SEED002: { /* chi^n d^2 / 2 + chi^t |xi|^2 / 2 (Eq. 19-22) */
        const fsdem_real chi = p->kn * (fsdem_real)sqrt(r_eff);
        return (fsdem_real)0.5 * chi * (delta * delta + p->kt * fsdem__dot(history, history));
    }
    default: {
        fsdem_real srd = (fsdem_real)sqrt(r_eff * delta);
        /* integral of (4/3) E* sqrt(R*) d^1.5 = (8/15) E* sqrt(R*) d^2.5, plus the Mindlin spring */
        return (fsdem_real)(8.0 / 15.0) * p->e_star * srd * delta * delta +
               (fsdem_real)0.5 * 8 * p->g_star * srd * fsdem__dot(history, history);
    }
    }
}

fsdem_dem_energy fsdem_dem_get_energy(const fsdem_dem *d) {
    fsdem_dem_energy e;
    int i, k, nh, nm;
    memset(&e, 0, sizeof e);
    if (!d) return e;
    nm = d->material_count;
    for (i = 0; i < d->n; ++i) {
        fsdem_real iner = d->inv_i[i] > 0 ? 1 / d->inv_i[i] : 0;
        if (d->fixed[i]) continue;
        e.kinetic += (fsdem_real)0.5 * d->m[i] * fsdem__dot(d->v[i], d->v[i]);
        e.rotational += (fsdem_real)0.5 * iner * fsdem__dot(d->w[i], d->w[i]);
        e.potential -= d->m[i] * fsdem__dot(d->desc.gravity, d->x[i]);
    }
    if (d->need_rebuild) return e; /* lists are stale after edits; springs are counted after a step */
    for (i = 0; i < d->n; ++i) {
        const fsdem__dem_pair *row = d->pairs + d->material[i] * nm;
        for (k = d->pp.start[i]; k < d->pp.start[i + 1]; ++k) {
            int j = FSDEM__DEM_PARTNER(d->pp.key[k]);
            fsdem_real delta = d->r[i] + d->r[j] + d->desc.contact_offset - fsdem__norm(fsdem__min_image(&d->periods, fsdem__sub(d->x[i], d->x[j])));
            if (delta <= 0) continue;
            e.elastic += fsdem__dem_contact_energy(d, row + d->material[j], delta, (d->m[i] + d->m[j]) / 2,
                                               d->r[i] * d->r[j] / (d->r[i] + d->r[j]), fsdem__dem_spring(&d->pp, k));
        }
        nh = d->inv_m[i] > 0 ? fsdem__dem_wall_hits((fsdem_dem *)d, i, 0) : 0; /* fixed: no wall force */
        for (k = 0; k < nh; ++k) {
            const fsdem__dem_wall_hit *hit = &d->hits[k];
            e.elastic += fsdem__dem_contact_energy(d, row + d->walls[FSDEM__DEM_WALL_OF(d->pw.key[hit->entry])].d.material,
                                               hit->delta, d->m[i], d->r[i], fsdem__dem_spring(&d->pw, hit->entry));
        }
    }
    return e;
}

fsdem_dem_stats fsdem_dem_get_stats(const fsdem_dem *d) {
    fsdem_dem_stats s;
    memset(&s, 0, sizeof s);
    if (!d) return s;
    s.steps = d->steps;
    s.time = d->time;
    s.dt = d->dt;
    s.stable_dt = d->stable_dt;
    s.dt_ratio = d->stable_dt > 0 ? d->dt / d->stable_dt : 0;
    s.rebuilds = d->rebuilds;
    s.contacts = d->contacts;
    s.wall_contacts = d->wall_contacts;
    s.neighbour_pairs = d->pp.count + d->inert_count;
    s.max_overlap = d->max_overlap;
    s.memory_bytes = sizeof *d + fsdem__dem_particle_bytes((fsdem_dem *)d, d->capacity) +
                     (size_t)(d->pp.capacity + d->pp_old.capacity + d->pw.capacity + d->pw_old.capacity) *
                         (2 * sizeof(int) + sizeof(fsdem_vec3)) +
                     (size_t)(d->pp.start_capacity + d->pp_old.start_capacity + d->pw.start_capacity +
                              d->pw_old.start_capacity) * sizeof(int) +
                     (size_t)(d->grid.cell_capacity + 2 * d->grid.item_capacity) * sizeof(int) +
                     (size_t)d->pair_capacity * sizeof(fsdem__dem_pair) + (size_t)d->wall_capacity * sizeof(fsdem__dem_wall) +
                     (size_t)d->material_capacity * sizeof(fsdem_dem_material) + d->arena.size +
                     (size_t)(d->found_capacity + d->inert_capacity) * sizeof(int) +
                     (size_t)d->hit_capacity * sizeof(fsdem__dem_wall_hit);
    return s;
}

/* Writes contact `count` to out when there is room. */
static void fsdem__dem_report_contact(fsdem_dem_contact *out, int capacity, int count, int i, int j, fsdem_vec3 n,
                                  fsdem_real overlap) {
    if (!out || count >= capacity) return;
    out[count].i = i;
    out[count].j = j;
    out[count].normal = n;
    out[count].overlap = overlap;
}

/* Reports particles i < j as contact `count` when they overlap; returns the new count. */
static int fsdem__dem_report_pair(const fsdem_dem *d, fsdem_dem_contact *out, int capacity, int count, int i, int j) {
    fsdem_real dist;
    fsdem_vec3 n = fsdem__geom_direction(d->x[i], fsdem__dem_image_of(d, i, j), fsdem_v3(1, 0, 0), &dist);
    const fsdem_real overlap = d->r[i] + d->r[j] + d->desc.contact_offset - dist;
    if (overlap <= 0) return count;
    fsdem__dem_report_contact(out, capacity, count, i, j, n, overlap);
    return count + 1;
}

int fsdem_dem_contacts(fsdem_dem *d, fsdem_dem_contact *out, int capacity) {
    int i, k, nh, count = 0;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    if (fsdem__dem_ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    for (k = 0; k < d->inert_count; ++k) {
        const int a = d->inert[2 * k], b = d->inert[2 * k + 1];
        count = fsdem__dem_report_pair(d, out, capacity, count, a < b ? a : b, a < b ? b : a);
    }
    for (i = 0; i < d->n; ++i) {
        for (k = d->pp.start[i]; k < d->pp.start[i + 1]; ++k)
            count = fsdem__dem_report_pair(d, out, capacity, count, i, FSDEM__DEM_PARTNER(d->pp.key[k]));
        nh = fsdem__dem_wall_hits(d, i, 0);
        for (k = 0; k < nh; ++k)
            fsdem__dem_report_contact(out, capacity, count++, i, -1 - FSDEM__DEM_WALL_OF(d->pw.key[d->hits[k].entry]),
                                  d->hits[k].n, d->hits[k].delta);
    }
    return count;
}
