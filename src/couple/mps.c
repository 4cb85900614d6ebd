/* ===== >>impl_couple_mps : unresolved MPS-DEM ========================================================

   Contents: >>couple_mps_object (desc, creation), >>couple_mps_exchange (seed 002 Eq. 25-36: pairs,
   porosity, averages, forces, reactions), >>couple_mps_step (its stages and verbs on the staged
   step of >>couple). The coupler reaches the solvers through their coupling functions only
   (>>doc). */

/* ---- >>couple_mps_object : desc, creation ---- */

/* An MPS particle within the radius of a DEM particle, and its w_s (Eq. 29). */
typedef struct fsdem__mps_dem_pair {
    int particle;
    fsdem_real weight;
} fsdem__mps_dem_pair;

/* What an update writes besides the force records and the solvers' coupling arrays. */
typedef struct fsdem__mps_dem_tally {
    long long pairs;               /* DEM-MPS pairs within the averaging radius */
    fsdem_real drag_dt;            /* s; the shortest drag relaxation time (0: none) */
    int wet;                       /* DEM particles with FLUID neighbours */
    fsdem_vec3 drag_sum, pressure_sum, fluid_sum; /* N: sums of F^d, the pressure parts, the reactions */
} fsdem__mps_dem_tally;

struct fsdem_mps_dem {
    fsdem_coupler head;            /* >>couple; its records are `force` */
    fsdem_mps_dem_desc desc;
    int dim;
    fsdem_mps_model model;         /* the MPS desc's */
    fsdem_real rho, mu;            /* fluid density, dynamic viscosity */
    fsdem_real ns;                 /* n_s of Eq. 30 (m^3; m^2 in 2D) */
    fsdem_real cell_volume;        /* r0^d of the MPS lattice (m^3; m^2 in 2D) */
    fsdem_real depth;              /* m; the DEM's disc_length in 2D (forces per metre on the MPS), 1 in 3D */
    fsdem_vec3 gravity;            /* m/s^2 */
    fsdem__periods periods;        /* the MPS's periodic axes, which the DEM shares */
    fsdem_cellgrid grid;           /* MPS particles, cells of edge averaging_radius / 2 (fsdem__mps_dem_ranges) */
    /* DEM-MPS pairs within the radius, by DEM particle: start[k] .. start[k+1] */
    int *start, start_cap;
    fsdem__mps_dem_pair *pair;
    int pair_cap;
    fsdem_real *solid;             /* per MPS particle: sum_k w_s V_k (Eq. 31) */
    fsdem_real *rate;              /* per MPS particle: its share of the grains' slip coefficients */
                                   /*    (kg/s; N/m per m/s in 2D), whose inverse times its mass is */
                                   /*    the water's drag relaxation time */
    fsdem_real *share;             /* per MPS particle: s_i of step 4 (0 for WALL and DUMMY) */
    int solid_cap;                 /* of solid, rate and share */
    fsdem_mps_dem_force *force;    /* per DEM particle of the last update (head.records of them) */
    int force_cap;
    fsdem__mps_dem_tally tally;
};

static const fsdem__coupler_class *fsdem__mps_dem_class(void);

fsdem_mps_dem_desc fsdem_mps_dem_desc_default(void) {
    fsdem_mps_dem_desc d;
    memset(&d, 0, sizeof d);
    d.drag = FSDEM_DRAG_LAW_ERGUN_WEN_YU;
    d.averaging_radius = 0;
    d.min_porosity = (fsdem_real)0.2;
    d.drag_dt_fraction = (fsdem_real)0.5;
    d.max_substeps = 100000;
    return d;
}

fsdem_result fsdem_mps_dem_desc_check(const fsdem_mps_dem_desc *d, char *msg, size_t size) {
    fsdem_dem_desc dd;
    fsdem_mps_desc md;
    fsdem_mps_stats st;
    int a;
    if (!d) return fsdem__reject(msg, size, "fsdem_mps_dem_desc is NULL");
    if (!d->mps || !d->dem) return fsdem__reject(msg, size, "fsdem_mps_dem_desc.mps and .dem must both be set");
    dd = fsdem_dem_get_desc(d->dem);
    md = fsdem_mps_get_desc(d->mps);
    st = fsdem_mps_get_stats(d->mps);
    if (dd.dim != md.dim)
        return fsdem__reject(msg, size, "fsdem_mps_dem_desc: the DEM is %dD and the MPS %dD", dd.dim, md.dim);
    for (a = 0; a < md.dim; ++a) { /* grains and water wrap alike, or a grain would leave through the water's wall */
        const fsdem_real lo = fsdem__comp(md.domain_min, a), hi = fsdem__comp(md.domain_max, a);
        if (!md.periodic[a] != !dd.periodic[a])
            return fsdem__reject(msg, size, "fsdem_mps_dem_desc: the %s is periodic along %c and the %s is not", md.periodic[a] ? "MPS" : "DEM",
                                 "xyz"[a], md.periodic[a] ? "DEM" : "MPS");
        if (md.periodic[a] && (fsdem__comp(dd.domain_min, a) != lo || fsdem__comp(dd.domain_max, a) != hi))
            return fsdem__reject(msg, size, "fsdem_mps_dem_desc: along the periodic %c the DEM domain [%g, %g] m differs from the MPS's [%g, %g] m",
                                 "xyz"[a], (double)fsdem__comp(dd.domain_min, a), (double)fsdem__comp(dd.domain_max, a), (double)lo, (double)hi);
        if (md.periodic[a] && !(2 * (d->averaging_radius > 0 ? d->averaging_radius : md.re) < hi - lo))
            return fsdem__reject(msg, size, "fsdem_mps_dem_desc.averaging_radius: the period %g m along %c must exceed twice it (%g m)",
                                 (double)(hi - lo), "xyz"[a], (double)(d->averaging_radius > 0 ? d->averaging_radius : md.re));
    }
    if (st.inflow_planes || st.outflow_planes) /* the coupler's per-particle records do not follow removals */
        return fsdem__reject(msg, size, "fsdem_mps_dem_desc: an MPS with inflows or outflows cannot be coupled yet");
    if (strcmp(fsdem_drag_law_name(d->drag), "unknown") == 0)
        return fsdem__reject(msg, size, "fsdem_mps_dem_desc.drag = %d is not a fsdem_drag_law", (int)d->drag);
    if (!(d->averaging_radius == 0 ||
          (d->averaging_radius > 0 && d->averaging_radius <= fsdem__smallest_extent(md.domain_min, md.domain_max, md.dim))))
        return fsdem__reject(msg, size,
                             "fsdem_mps_dem_desc.averaging_radius must be 0 (the MPS re) or in (0, %g] m, the MPS domain's smallest extent "
                             "(got %g m)",
                             (double)fsdem__smallest_extent(md.domain_min, md.domain_max, md.dim), (double)d->averaging_radius);
    if (!(d->min_porosity > 0 && d->min_porosity < 1))
        return fsdem__reject(msg, size, "fsdem_mps_dem_desc.min_porosity must be in (0, 1) (got %g)", (double)d->min_porosity);
    if (!(d->drag_dt_fraction > 0 && d->drag_dt_fraction <= 1))
        return fsdem__reject(msg, size, "fsdem_mps_dem_desc.drag_dt_fraction must be in (0, 1] (got %g)",
                             (double)d->drag_dt_fraction);
    return fsdem__coupler_check(fsdem__mps_dem_class(), "fsdem_mps_dem_desc", d->mps, FSDEM_MPS_ARRAYS_FORCE | FSDEM_MPS_ARRAYS_POROSITY,
                                d->dem, md.dim, md.gravity, d->max_substeps, msg, size);
}

fsdem_result fsdem_mps_dem_create(const fsdem_mps_dem_desc *desc, fsdem_mps_dem **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_mps_dem *c;
    fsdem_mps_desc md;
    fsdem_result res;
    fsdem_real re;
    if (out) *out = NULL;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    res = fsdem_mps_dem_desc_check(desc, msg, sizeof msg);
    c = (fsdem_mps_dem *)fsdem__coupler_new(fsdem__mps_dem_class(), res, msg, desc ? desc->mps : NULL, desc ? desc->dem : NULL,
                                            FSDEM_MPS_ARRAYS_FORCE | FSDEM_MPS_ARRAYS_POROSITY, desc ? desc->max_substeps : 0,
                                            desc ? desc->log : NULL, desc ? desc->log_user : NULL, sizeof *c, &res);
    if (!c) return res;
    md = fsdem_mps_get_desc(desc->mps);
    c->desc = *desc;
    c->dim = md.dim;
    c->model = md.model;
    c->rho = md.density;
    c->mu = md.density * md.viscosity;
    c->gravity = md.gravity;
    c->depth = md.dim == 2 ? fsdem_dem_get_desc(desc->dem).disc_length : 1;
    re = c->desc.averaging_radius = desc->averaging_radius > 0 ? desc->averaging_radius : md.re;
    /* Eq. 30: n_s = int w_s dV = (10 pi / 21) r_e^3; in the plane the same integral is (10 pi / 21) r_e^2 */
    c->ns = (fsdem_real)(10 * FSDEM__PI / 21) * re * re * (c->dim == 3 ? re : 1);
    c->cell_volume = md.r0 * md.r0 * (c->dim == 3 ? md.r0 : 1);
    c->periods = fsdem__periods_of(md.periodic, md.dim, md.domain_min, md.domain_max);
    if (fsdem_cellgrid_setup_periodic(&c->grid, &c->head.allocator, c->dim, md.domain_min, md.domain_max, re / 2, 0, md.periodic) !=
        FSDEM_OK) {
        fsdem__log_oom(desc->log, desc->log_user, "fsdem_mps_dem_create", sizeof c->grid);
        fsdem_mps_dem_destroy(c);
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    *out = c;
    return FSDEM_OK;
}

void fsdem_mps_dem_destroy(fsdem_mps_dem *c) {
    const fsdem_allocator *al;
    if (!c) return;
    al = &c->head.allocator;
    fsdem_cellgrid_free(&c->grid);
    fsdem__free(al, c->start, sizeof(int) * (size_t)c->start_cap);
    fsdem__free(al, c->pair, sizeof *c->pair * (size_t)c->pair_cap);
    fsdem__free(al, c->solid, sizeof(fsdem_real) * (size_t)c->solid_cap);
    fsdem__free(al, c->rate, sizeof(fsdem_real) * (size_t)c->solid_cap);
    fsdem__free(al, c->share, sizeof(fsdem_real) * (size_t)c->solid_cap);
    fsdem__free(al, c->force, sizeof(fsdem_mps_dem_force) * (size_t)c->force_cap);
    fsdem__coupler_free(&c->head, sizeof *c);
}

const char *fsdem_mps_dem_last_error(const fsdem_mps_dem *c) { return c ? c->head.status.message : "fsdem_mps_dem is NULL"; }

fsdem_mps_dem_desc fsdem_mps_dem_get_desc(const fsdem_mps_dem *c) {
    fsdem_mps_dem_desc d;
    if (c) return c->desc;
    memset(&d, 0, sizeof d);
    return d;
}

/* ---- >>couple_mps_exchange : pairs, porosity, averages, forces, reactions ---- */

/* Eq. 29 at distance r (0 beyond re). */
static fsdem_real fsdem__mps_dem_weight(fsdem_real r, fsdem_real re) {
    const fsdem_real x = r / re, x4 = x * x * x * x;
    return x < 1 ? 4 * x4 * x - 5 * x4 + 1 : 0;
}

/* Volume of DEM particle k that the porosity counts: the sphere, or in 2D the disc's area (volume
   per metre of depth, as the MPS's). */
static fsdem_real fsdem__mps_dem_volume(const fsdem_mps_dem *c, fsdem_real r) {
    return c->dim == 3 ? (fsdem_real)(4 * FSDEM__PI / 3) * r * r * r : (fsdem_real)FSDEM__PI * r * r;
}

/* The grid's items within distance r of p, as ranges of `items`: the cells are at least r/2 wide
   and a row of cells along x is contiguous in the grid's order, so the block of 5 cells per axis
   around p is at most 25 rows in 3D (5 in 2D), each one range, or two where it wraps round a
   periodic x; rows whose nearest point is farther than r are left out. This scans about 60% of the
   candidates of the 3^d block of cells r wide. Along a periodic axis the block wraps (a period of
   fewer than 5 cells is taken whole, once); separations are then minimum images. Returns the
   number of ranges. */
static int fsdem__mps_dem_ranges(const fsdem_cellgrid *g, fsdem_vec3 p, fsdem_real r, int range[50][2]) {
    int lo[3], hi[3], whole[3], a, y, z, count = 0;
    fsdem_real x[3], width[3];
    for (a = 0; a < 3; ++a) {
        x[a] = fsdem__comp(p, a) - fsdem__comp(g->origin, a);
        whole[a] = a >= g->dim || g->inv_width[a] == 0; /* the plane's z, or a periodic axis of one cell */
        width[a] = g->wrap[a] ? 1 / g->inv_width[a] : g->cell_size;
        lo[a] = whole[a] ? 0 : (int)floor((x[a] - r) * g->inv_width[a]);
        hi[a] = whole[a] ? g->n[a] - 1 : (int)floor((x[a] + r) * g->inv_width[a]);
        if (g->wrap[a] && hi[a] - lo[a] + 1 >= g->n[a]) {
            whole[a] = 1;
            lo[a] = 0;
            hi[a] = g->n[a] - 1;
        } else if (!g->wrap[a]) {
            if (lo[a] < 0) lo[a] = 0;
            if (hi[a] > g->n[a] - 1) hi[a] = g->n[a] - 1;
            if (lo[a] > hi[a]) return 0;
        }
    }
    for (z = lo[2]; z <= hi[2]; ++z)
        for (y = lo[1]; y <= hi[1]; ++y) {
            /* distance from p to the row's slab in y and z (0 inside it), in unwrapped cell coordinates */
            const fsdem_real cy = (fsdem_real)y * width[1], cz = (fsdem_real)z * width[2];
            const fsdem_real dy = whole[1] ? 0 : x[1] < cy ? cy - x[1] : x[1] > cy + width[1] ? x[1] - cy - width[1] : 0;
            const fsdem_real dz = whole[2] ? 0 : x[2] < cz ? cz - x[2] : x[2] > cz + width[2] ? x[2] - cz - width[2] : 0;
            const int row = ((z + g->n[2]) % g->n[2] * g->n[1] + (y + g->n[1]) % g->n[1]) * g->n[0];
            int x0 = lo[0], x1 = hi[0];
            if (dy * dy + dz * dz >= r * r) continue;
            if (x0 < 0 || x1 >= g->n[0]) { /* a periodic x wraps: the part past either end first */
                range[count][0] = g->cell_start[row + (x0 < 0 ? x0 + g->n[0] : 0)];
                range[count++][1] = g->cell_start[row + (x0 < 0 ? g->n[0] : x1 - g->n[0] + 1)];
                if (x0 < 0) x0 = 0;
                else x1 = g->n[0] - 1;
            }
            range[count][0] = g->cell_start[row + x0];
            range[count++][1] = g->cell_start[row + x1 + 1];
        }
    return count;
}

/* The normaliser of Eq. 31 at MPS particle i: n_s (Eq. 30) less the part of the weight's integral
   that lies inside the tank's walls and obstacles, the sum of w_s r0^d over their WALL and DUMMY
   particles (a lattice of cells of volume r0^d, which covers the walls to re = 4.1 r0 deep). Next
   to a wall the spheres can only fill the open part of the kernel: dividing by the whole n_s, as
   Eq. 31 does, read a packed bed as half as dense at the wall and let the water bypass it there
   (a packing of porosity 0.476 in a tank 16 r0 wide averaged 0.546 over the cross-section). */
static fsdem_real fsdem__mps_dem_open_weight(const fsdem_mps_dem *c, const fsdem_mps_particles *mv, int i) {
    const fsdem_real re = c->desc.averaging_radius, re2 = re * re;
    fsdem_real walls = 0;
    int range[50][2], m, e;
    const int nr = fsdem__mps_dem_ranges(&c->grid, mv->position[i], re, range);
    for (m = 0; m < nr; ++m)
        for (e = range[m][0]; e < range[m][1]; ++e) {
            const int j = c->grid.items[e];
            const fsdem_vec3 d = fsdem__min_image(&c->periods, fsdem__sub(mv->position[j], mv->position[i]));
            const fsdem_real r2 = fsdem__dot(d, d);
            if (mv->kind[j] != FSDEM_MPS_KIND_FLUID && r2 < re2) walls += fsdem__mps_dem_weight((fsdem_real)sqrt(r2), re);
        }
    walls *= c->cell_volume;
    /* a corner of three walls leaves an eighth open; the floor only guards a particle pushed into a wall */
    return walls < (fsdem_real)0.9 * c->ns ? c->ns - walls : (fsdem_real)0.1 * c->ns;
}

/* Makes room for the per-particle arrays (nd DEM, nm MPS particles); the records of the last update
   move with their array, so an update that fails later leaves them readable. */
static fsdem_result fsdem__mps_dem_room(fsdem_mps_dem *c, int nd, int nm) {
    const fsdem_allocator *al = &c->head.allocator;
    int cap = c->force_cap;
    void **const fluid[3] = {(void **)&c->solid, (void **)&c->rate, (void **)&c->share};
    const size_t size[3] = {sizeof(fsdem_real), sizeof(fsdem_real), sizeof(fsdem_real)};
    const fsdem_result res = fsdem__grow(al, (void **)&c->force, &cap, c->head.records, nd, sizeof(fsdem_mps_dem_force));
    c->force_cap = cap;
    c->head.record = c->force;
    if (res != FSDEM_OK || fsdem__grow(al, (void **)&c->start, &c->start_cap, 0, nd + 1, sizeof(int)) != FSDEM_OK)
        return FSDEM_ERR_OUT_OF_MEMORY;
    return fsdem__grow_set(al, fluid, size, 3, &c->solid_cap, 0, nm);
}

/* The non-DUMMY MPS particles within the radius of every DEM particle, with their w_s. */
static fsdem_result fsdem__mps_dem_pairs(fsdem_mps_dem *c, const fsdem_dem_particles *dv, const fsdem_mps_particles *mv) {
    const fsdem_real re = c->desc.averaging_radius, re2 = re * re;
    int k, m, e, n = 0;
    if (fsdem_cellgrid_build(&c->grid, mv->position, mv->count) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    for (k = 0; k < dv->count; ++k) {
        int range[50][2];
        const int nr = fsdem__mps_dem_ranges(&c->grid, dv->position[k], re, range);
        c->start[k] = n;
        for (m = 0; m < nr; ++m)
            for (e = range[m][0]; e < range[m][1]; ++e) {
                const int i = c->grid.items[e];
                const fsdem_vec3 d = fsdem__min_image(&c->periods, fsdem__sub(mv->position[i], dv->position[k]));
                const fsdem_real r2 = fsdem__dot(d, d);
                if (mv->kind[i] == FSDEM_MPS_KIND_DUMMY || !(r2 < re2)) continue;
                if (n == c->pair_cap &&
                    fsdem__grow(&c->head.allocator, (void **)&c->pair, &c->pair_cap, n, n + 1, sizeof *c->pair) != FSDEM_OK)
                    return FSDEM_ERR_OUT_OF_MEMORY;
                c->pair[n].particle = i;
                c->pair[n++].weight = fsdem__mps_dem_weight((fsdem_real)sqrt(r2), re);
            }
    }
    c->start[dv->count] = n;
    c->tally.pairs = n;
    return FSDEM_OK;
}

/* Steps 3-4 of >>couple_mps for DEM particle k, with porosity eps, velocity u and pressure gradient
   gp (w_s averages) and W > 0 the sum of w_s s_i over its FLUID neighbours: its force, and the
   reactions. */
static void fsdem__mps_dem_exchange(fsdem_mps_dem *c, const fsdem_dem_particles *dv, const fsdem_mps_particles *mv,
                                    const fsdem_mps_coupling *mc, int k, fsdem_real W, fsdem_real eps, fsdem_vec3 u,
                                    fsdem_vec3 gp) {
    fsdem_mps_dem_force *f = &c->force[k];
    const fsdem_real r = dv->radius[k], V = fsdem__mps_dem_volume(c, r) * (c->dim == 2 ? c->depth : 1);
    const fsdem_vec3 slip = fsdem__sub(u, dv->velocity[k]);
    const fsdem_real speed = fsdem__norm(slip);
    const fsdem_real per_volume = fsdem__drag_per_volume(c->desc.drag, eps, 2 * r, speed, c->rho, c->mu);
    fsdem_real coefficient = per_volume * V; /* kg/s: the force per unit slip on the particle */
    fsdem_vec3 exchanged;
    int e;
    f->wet = 1;
    f->porosity = eps;
    f->fluid_velocity = u;
    f->reynolds = eps * c->rho * 2 * r * speed / c->mu; /* Eq. 28 */
    f->drag = fsdem__scale(slip, coefficient);          /* Eq. 25 */
    if (c->model == FSDEM_MPS_MODEL_A) {
        f->pressure = fsdem__scale(gp, -V); /* Eq. 34 */
        f->total = fsdem__add(f->drag, f->pressure);
        exchanged = f->drag;
    } else {
        f->pressure = fsdem__scale(c->gravity, -V * c->rho); /* Eq. 35 */
        f->total = fsdem__madd(f->pressure, f->drag, 1 / eps);
        coefficient /= eps;
        exchanged = f->total;
    }
    if (!dv->fixed[k] && coefficient > 0) {
        const fsdem_real tau = dv->mass[k] / coefficient; /* drag relaxation time */
        if (c->tally.drag_dt == 0 || tau < c->tally.drag_dt) c->tally.drag_dt = tau;
    }
    /* Eq. 36: the reaction shared in proportion to w_s s_i / W, whose shares sum to one; the water
       takes the same shares of the slip coefficient */
    exchanged = fsdem__scale(exchanged, -1 / (W * c->depth));
    coefficient /= W * c->depth;
    for (e = c->start[k]; e < c->start[k + 1]; ++e) {
        const int i = c->pair[e].particle;
        const fsdem_real share = c->pair[e].weight * c->share[i];
        if (mv->kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        mc->force[i] = fsdem__madd(mc->force[i], exchanged, share);
        c->rate[i] += coefficient * share;
    }
}

fsdem_result fsdem_mps_dem_update(fsdem_mps_dem *c) {
    fsdem_dem_particles dv;
    fsdem_mps_particles mv;
    fsdem_mps_coupling mc;
    fsdem_dem_coupling dc;
    int i, k, e;
    if (!c) return FSDEM_ERR_INVALID_ARG;
    {
        const fsdem_mps_desc md = fsdem_mps_get_desc(c->desc.mps);
        if (fsdem__coupler_particles_fit(&c->head, md.domain_min, md.domain_max, "fsdem_mps_dem_update") != FSDEM_OK)
            return FSDEM_ERR_INVALID_ARG;
    }
    dv = fsdem_dem_get_particles(c->desc.dem);
    mv = fsdem_mps_get_particles(c->desc.mps);
    memset(&c->tally, 0, sizeof c->tally);
    if (fsdem__mps_dem_room(c, dv.count, mv.count) != FSDEM_OK || fsdem__mps_dem_pairs(c, &dv, &mv) != FSDEM_OK)
        return fsdem__fail(&c->head.status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps_dem_update: out of memory (%d DEM and %d MPS particles)",
                           dv.count, mv.count);
    mc = fsdem_mps_get_coupling(c->desc.mps);
    dc = fsdem_dem_get_coupling(c->desc.dem);
    /* 1. porosity of the MPS particles, Eq. 31 */
    for (i = 0; i < mv.count; ++i) c->solid[i] = c->rate[i] = 0;
    for (k = 0; k < dv.count; ++k) {
        const fsdem_real V = fsdem__mps_dem_volume(c, dv.radius[k]);
        for (e = c->start[k]; e < c->start[k + 1]; ++e) c->solid[c->pair[e].particle] += c->pair[e].weight * V;
    }
    for (i = 0; i < mv.count; ++i) {
        fsdem_real eps = 1, open = c->ns;
        if (mv.kind[i] == FSDEM_MPS_KIND_FLUID && c->solid[i] > 0) eps = 1 - c->solid[i] / (open = fsdem__mps_dem_open_weight(c, &mv, i));
        mc.porosity[i] = eps > c->desc.min_porosity ? eps : c->desc.min_porosity;
        c->share[i] = mv.kind[i] == FSDEM_MPS_KIND_FLUID ? c->ns / (mc.porosity[i] * open) : 0; /* s_i of step 4 */
        mc.force[i] = fsdem__zero3();
    }
    /* 2-4. averages at the DEM particles (Eq. 32-33), forces (Eq. 25-28, 34-35), reactions (Eq. 36) */
    for (k = 0; k < dv.count; ++k) {
        fsdem_real W = 0, E = 0, shares = 0;
        fsdem_vec3 U = fsdem__zero3(), G = fsdem__zero3();
        for (e = c->start[k]; e < c->start[k + 1]; ++e) {
            const int i = c->pair[e].particle;
            const fsdem_real w = c->pair[e].weight;
            if (mv.kind[i] != FSDEM_MPS_KIND_FLUID) continue;
            W += w;
            E += w * mc.porosity[i];
            U = fsdem__madd(U, mv.velocity[i], w);
            G = fsdem__madd(G, mv.pressure_gradient[i], w);
            shares += w * c->share[i];
        }
        memset(&c->force[k], 0, sizeof c->force[k]);
        c->force[k].id = dv.id[k];
        c->force[k].porosity = 1;
        if (W > 0) {
            fsdem__mps_dem_exchange(c, &dv, &mv, &mc, k, shares, E / W, fsdem__scale(U, 1 / W), fsdem__scale(G, 1 / W));
            c->tally.wet++;
        }
        if (!fsdem__finite3(c->force[k].total))
            return fsdem__fail(&c->head.status, FSDEM_ERR_NAN, "fsdem_mps_dem_update: the fluid force on DEM particle %d is not finite", k);
        dc.force[k] = c->force[k].total;
        c->tally.drag_sum = fsdem__add(c->tally.drag_sum, c->force[k].drag);
        c->tally.pressure_sum = fsdem__add(c->tally.pressure_sum, c->force[k].pressure);
    }
    for (i = 0; i < mv.count; ++i) {
        const fsdem_real tau = c->rate[i] > 0 ? c->rho * c->cell_volume / c->rate[i] : 0; /* the water's drag relaxation */
        if (tau > 0 && (c->tally.drag_dt == 0 || tau < c->tally.drag_dt)) c->tally.drag_dt = tau;
        c->tally.fluid_sum = fsdem__add(c->tally.fluid_sum, mc.force[i]);
    }
    c->tally.fluid_sum = fsdem__scale(c->tally.fluid_sum, c->depth);
    c->head.record = c->force;
    c->head.records = dv.count;
    return fsdem__ok(&c->head.status);
}

fsdem_result fsdem_mps_dem_get_force(const fsdem_mps_dem *c, int index, fsdem_mps_dem_force *out) {
    return c ? fsdem__coupler_get_record(&c->head, index, out, "fsdem_mps_dem_get_force") : FSDEM_ERR_INVALID_ARG;
}

fsdem_result fsdem_mps_dem_write_csv(const fsdem_mps_dem *c, const char *path) {
    return c ? fsdem__coupler_write_csv(&c->head, path, "fsdem_mps_dem_write_csv") : FSDEM_ERR_INVALID_ARG;
}

/* ---- >>couple_mps_step : coupled time stepping ---- */

/* The update of a step (the class's prepare). */
static fsdem_result fsdem__mps_dem_prepare(fsdem_coupler *head) { return fsdem_mps_dem_update((fsdem_mps_dem *)(void *)head); }

/* The drag limit of the last update on the stable step (>>couple_mps; the class's limit). */
static fsdem_result fsdem__mps_dem_limit(const fsdem_coupler *head, fsdem_real *dt) {
    const fsdem_mps_dem *c = (const fsdem_mps_dem *)(const void *)head;
    if (c->tally.drag_dt > 0 && c->desc.drag_dt_fraction * c->tally.drag_dt < *dt) *dt = c->desc.drag_dt_fraction * c->tally.drag_dt;
    return FSDEM_OK;
}

/* A step of dt refused before anything moves: too many substeps, the MPS's own refusal, or past the
   drag limit. */
static fsdem_result fsdem__mps_dem_check(fsdem_coupler *head, fsdem_real dt, int chosen) {
    fsdem_mps_dem *c = (fsdem_mps_dem *)(void *)head;
    fsdem_result res = fsdem__coupler_substeps_within(head, dt);
    (void)chosen;
    if (res != FSDEM_OK) return res;
    if ((res = fsdem_mps_check_dt(c->desc.mps, dt)) != FSDEM_OK)
        return fsdem__fail(&head->status, res, "fsdem_mps_dem: MPS step: %s", fsdem_mps_last_error(c->desc.mps));
    if (c->tally.drag_dt > 0 && dt > c->desc.drag_dt_fraction * c->tally.drag_dt * (1 + (fsdem_real)1e-6))
        return fsdem__fail(&head->status, FSDEM_ERR_CFL,
                           "fsdem_mps_dem: dt = %g s exceeds drag_dt_fraction %g of the shortest drag relaxation time %g s", (double)dt,
                           (double)c->desc.drag_dt_fraction, (double)c->tally.drag_dt);
    return FSDEM_OK;
}

/* Step 5 of >>couple_mps after the MPS step: the DEM over dt with the forces held. */
static fsdem_result fsdem__mps_dem_substeps(fsdem_coupler *head, fsdem_real dt) {
    return fsdem__coupler_substeps(head, dt, NULL, NULL, NULL);
}

static const fsdem__stage fsdem__mps_dem_stages[2] = {{"MPS step", FSDEM__CLOCK_FLUID, NULL},
                                                      {"DEM substeps", FSDEM__CLOCK_DEM, fsdem__mps_dem_substeps}};

#define FSDEM__MPS_DEM_FIELD(name, kind) FSDEM__FIELD(fsdem_mps_dem_force, name, #name, kind, 1)
static const fsdem__field fsdem__mps_dem_fields[8] = {
    FSDEM__MPS_DEM_FIELD(id, INT),          FSDEM__MPS_DEM_FIELD(drag, VEC3),     FSDEM__MPS_DEM_FIELD(pressure, VEC3),
    FSDEM__MPS_DEM_FIELD(total, VEC3),      FSDEM__MPS_DEM_FIELD(fluid_velocity, VEC3), FSDEM__MPS_DEM_FIELD(porosity, REAL),
    FSDEM__MPS_DEM_FIELD(reynolds, REAL),   FSDEM__MPS_DEM_FIELD(wet, INT)};
#undef FSDEM__MPS_DEM_FIELD

static const fsdem__coupler_class *fsdem__mps_dem_class(void) {
    static const fsdem__coupler_class cls = {"fsdem_mps_dem", &fsdem__fluid_mps, sizeof(fsdem_mps_dem_force),
        fsdem__mps_dem_fields, 8, fsdem__mps_dem_prepare, fsdem__mps_dem_limit, fsdem__mps_dem_check,
        fsdem__mps_dem_stages, 2};
    return &cls;
}

double fsdem_mps_dem_time(const fsdem_mps_dem *c) { return c ? fsdem__coupler_time(&c->head) : 0; }
fsdem_coupler *fsdem_mps_dem_coupler(fsdem_mps_dem *c) { return c ? &c->head : NULL; }

fsdem_mps_dem_stats fsdem_mps_dem_get_stats(const fsdem_mps_dem *c) {
    fsdem_mps_dem_stats st;
    int k;
    memset(&st, 0, sizeof st);
    if (!c) return st;
    st.coupling = fsdem__coupler_stats(&c->head);
    st.wet = c->tally.wet;
    st.drag = c->tally.drag_sum;
    st.pressure = c->tally.pressure_sum;
    st.to_fluid = c->tally.fluid_sum;
    st.drag_dt = c->tally.drag_dt;
    st.pairs = c->tally.pairs;
    for (k = 0; k < c->head.records; ++k)
        st.exchanged = fsdem__add(st.exchanged, c->model == FSDEM_MPS_MODEL_A ? c->force[k].drag : c->force[k].total);
    st.exchange_residual = fsdem__norm(fsdem__add(st.to_fluid, st.exchanged));
    return st;
}
