/* ===== >>impl_couple_gic : Granule-In-Cell ===========================================================

   Contents: >>couple_gic_object (desc, creation), >>couple_gic_exchange (seed 004 Eq. 5a-5b, 7a, 18:
   volume fractions, granule forces, the exchange to the grid), >>couple_gic_step (its stages and
   verbs on the staged step of >>couple, sand first). The coupler speaks to the PIC and the DEM
   through their public calls (>>doc). */

/* ---- >>couple_gic_object : desc, creation ---- */

/* What one step's force evaluations add up (its figures in fsdem_gic_stats). */
typedef struct fsdem__gic_tally {
    fsdem_vec3 pressure, drag, virtual_mass, to_fluid, lost; /* N s, in the DEM's units */
    fsdem_real drag_dt;                        /* s; shortest relaxation time (0: none) */
    int wet;
} fsdem__gic_tally;

struct fsdem_gic {
    fsdem_coupler head;            /* >>couple; its records are `force`, of the last evaluation */
    fsdem_gic_desc desc;
    int dim;
    fsdem__mac grid;               /* the PIC's cells (fsdem_pic_get_fields) */
    fsdem_real rho;                /* kg/m^3, the water's */
    fsdem_real mu;                 /* Pa s, the dynamic viscosity the drag laws use */
    fsdem_real depth;              /* m; the DEM's disc_length in 2D (the PIC's forces are per metre), 1 in 3D */
    fsdem_real cell_volume;        /* m^dim */
    fsdem_real *solid, *porosity;  /* per cell: alpha_s (Eq. 7a), alpha_f' */
    fsdem_real *rate;              /* per cell scratch: the water's drag rate (1/s) of the step limit, */
                                   /*    the porosity before the step's update */
    fsdem_real *held;              /* per cell: the PIC's pressure_rhs before the displacement flow's */
                                   /*    source, put back after the PIC step */
    fsdem_real *pressure_rhs;      /* the PIC's (fsdem_pic_coupling): kept, as asking for the */
                                   /*    coupling arrays again makes the PIC recount its cells */
    /* per granule: sample points, the samples, the force records of the last evaluation */
    fsdem_vec3 *point;
    fsdem_fluid_sample *sample;
    fsdem_gic_force *force;
    fsdem_vec3 *fluid_accel;       /* a_f of Eq. 17 at each granule, for the step under way */
    int granule_cap;
    /* the sand substeps under way: their length h, count K, the evaluations made, the step's dt */
    fsdem_real h, dt_now;
    long long substeps_now, calls;
    int failed;                    /* an evaluation failed (its message is in status) */
    int water_at_rest;             /* the PIC has not stepped: no pressure solved yet */
    fsdem__gic_tally tally, last;  /* of the step under way, of the last step */
    fsdem_real max_solid, solid_volume;
    double granule_volume;         /* m^3 (m^2 in 2D); sum of V_i at the last update (0: none yet) */
};

static const fsdem__coupler_class *fsdem__gic_class(void);

fsdem_gic_desc fsdem_gic_desc_default(void) {
    fsdem_gic_desc d;
    memset(&d, 0, sizeof d);
    d.drag = FSDEM_DRAG_LAW_GIC;
    d.drag_scale = 1;
    d.cfl = 1;
    d.max_dt_ratio = 1000;
    d.drag_dt_fraction = (fsdem_real)0.5;
    d.max_substeps = 100000;
    return d;
}

fsdem_result fsdem_gic_desc_check(const fsdem_gic_desc *d, char *msg, size_t size) {
    fsdem_pic_desc pd;
    if (!d) return fsdem__reject(msg, size, "fsdem_gic_desc is NULL");
    if (!d->pic || !d->dem) return fsdem__reject(msg, size, "fsdem_gic_desc.pic and .dem must both be set");
    pd = fsdem_pic_get_desc(d->pic);
    if (strcmp(fsdem_drag_law_name(d->drag), "unknown") == 0)
        return fsdem__reject(msg, size, "fsdem_gic_desc.drag = %d is not a fsdem_drag_law", (int)d->drag);
    if (d->virtual_mass != 0 && d->virtual_mass != 1)
        return fsdem__reject(msg, size, "fsdem_gic_desc.virtual_mass must be 0 or 1 (got %d)", d->virtual_mass);
    if (d->displacement_flow != 0 && d->displacement_flow != 1)
        return fsdem__reject(msg, size, "fsdem_gic_desc.displacement_flow must be 0 or 1 (got %d)", d->displacement_flow);
    if (!(d->drag_scale >= 1e-3 && d->drag_scale <= 1e3))
        return fsdem__reject(msg, size, "fsdem_gic_desc.drag_scale must be in [1e-3, 1e3] (got %g)", (double)d->drag_scale);
    if (!(d->viscosity >= 0) || !fsdem__finite(d->viscosity))
        return fsdem__reject(msg, size, "fsdem_gic_desc.viscosity must be >= 0 m^2/s and finite (got %g)", (double)d->viscosity);
    if (d->drag != FSDEM_DRAG_LAW_GIC && d->viscosity == 0 && !(pd.viscosity > 0))
        return fsdem__reject(msg, size,
                             "fsdem_gic_desc.viscosity: the %s drag law needs a viscosity, and it is 0 here and in the (inviscid) PIC",
                             fsdem_drag_law_name(d->drag));
    if (!(d->max_solid_fraction == 0 || (d->max_solid_fraction >= 0.5 && d->max_solid_fraction < 1)))
        return fsdem__reject(msg, size, "fsdem_gic_desc.max_solid_fraction must be 0 (densest packing) or in [0.5, 1) (got %g)",
                             (double)d->max_solid_fraction);
    if (!(d->cfl >= 0.01 && d->cfl <= 1))
        return fsdem__reject(msg, size, "fsdem_gic_desc.cfl must be in [0.01, 1] (got %g)", (double)d->cfl);
    if (!(d->max_dt_ratio >= 1) || !fsdem__finite(d->max_dt_ratio))
        return fsdem__reject(msg, size, "fsdem_gic_desc.max_dt_ratio must be >= 1 and finite (got %g)", (double)d->max_dt_ratio);
    if (!(d->drag_dt_fraction >= 0.01 && d->drag_dt_fraction <= 1))
        return fsdem__reject(msg, size, "fsdem_gic_desc.drag_dt_fraction must be in [0.01, 1] (got %g)", (double)d->drag_dt_fraction);
    if (fsdem__coupler_aperiodic("fsdem_gic_desc", d->dem, "PIC", msg, size) != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    return fsdem__coupler_check(fsdem__gic_class(), "fsdem_gic_desc", d->pic, FSDEM_PIC_ARRAYS_POROSITY | FSDEM_PIC_ARRAYS_ACCELERATION, d->dem,
                                pd.dim, pd.gravity, d->max_substeps, msg, size);
}

fsdem_result fsdem_gic_create(const fsdem_gic_desc *desc, fsdem_gic **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_gic *c;
    fsdem_pic_fields g;
    fsdem_pic_desc pd;
    fsdem_result res;
    size_t cells;
    int k;
    if (out) *out = NULL;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    res = fsdem_gic_desc_check(desc, msg, sizeof msg);
    c = (fsdem_gic *)fsdem__coupler_new(fsdem__gic_class(), res, msg, desc ? desc->pic : NULL, desc ? desc->dem : NULL,
                                        FSDEM_PIC_ARRAYS_POROSITY | FSDEM_PIC_ARRAYS_ACCELERATION, desc ? desc->max_substeps : 0,
                                        desc ? desc->log : NULL, desc ? desc->log_user : NULL, sizeof *c, &res);
    if (!c) return res;
    pd = fsdem_pic_get_desc(desc->pic);
    g = fsdem_pic_get_fields(desc->pic);
    c->desc = *desc;
    c->dim = g.dim;
    c->rho = pd.density;
    c->depth = g.dim == 2 ? fsdem_dem_get_desc(desc->dem).disc_length : 1;
    if (c->desc.viscosity == 0) c->desc.viscosity = pd.viscosity;
    c->mu = pd.density * c->desc.viscosity;
    if (c->desc.max_solid_fraction == 0) c->desc.max_solid_fraction = (fsdem_real)(g.dim == 3 ? 0.740 : 0.907);
    fsdem__mac_init(&c->grid, g.dim, g.n, g.cell_size, g.origin);
    c->cell_volume = g.cell_size * g.cell_size * (g.dim == 3 ? g.cell_size : 1);
    cells = (size_t)c->grid.ncell;
    c->solid = (fsdem_real *)fsdem__alloc(&c->head.allocator, sizeof(fsdem_real) * cells);
    c->porosity = (fsdem_real *)fsdem__alloc(&c->head.allocator, sizeof(fsdem_real) * cells);
    c->rate = (fsdem_real *)fsdem__alloc(&c->head.allocator, sizeof(fsdem_real) * cells);
    c->held = (fsdem_real *)fsdem__alloc(&c->head.allocator, sizeof(fsdem_real) * cells);
    if (!c->solid || !c->porosity || !c->rate || !c->held) {
        fsdem__log_oom(desc->log, desc->log_user, "fsdem_gic_create", 4 * sizeof(fsdem_real) * cells);
        fsdem_gic_destroy(c);
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    for (k = 0; k < c->grid.ncell; ++k) {
        c->solid[k] = 0;
        c->porosity[k] = 1;
    }
    *out = c;
    return FSDEM_OK;
}

void fsdem_gic_destroy(fsdem_gic *c) {
    const fsdem_allocator *al;
    size_t cells;
    if (!c) return;
    al = &c->head.allocator;
    cells = (size_t)c->grid.ncell;
    fsdem__free(al, c->solid, sizeof(fsdem_real) * cells);
    fsdem__free(al, c->porosity, sizeof(fsdem_real) * cells);
    fsdem__free(al, c->rate, sizeof(fsdem_real) * cells);
    fsdem__free(al, c->held, sizeof(fsdem_real) * cells);
    fsdem__free(al, c->point, sizeof(fsdem_vec3) * (size_t)c->granule_cap);
    fsdem__free(al, c->sample, sizeof(fsdem_fluid_sample) * (size_t)c->granule_cap);
    fsdem__free(al, c->force, sizeof(fsdem_gic_force) * (size_t)c->granule_cap);
    fsdem__free(al, c->fluid_accel, sizeof(fsdem_vec3) * (size_t)c->granule_cap);
    fsdem__coupler_free(&c->head, sizeof *c);
}

const char *fsdem_gic_last_error(const fsdem_gic *c) { return c ? c->head.status.message : "fsdem_gic is NULL"; }

fsdem_coupler *fsdem_gic_coupler(fsdem_gic *c) { return c ? &c->head : NULL; }

fsdem_gic_desc fsdem_gic_get_desc(const fsdem_gic *c) {
    fsdem_gic_desc d;
    if (c) return c->desc;
    memset(&d, 0, sizeof d);
    return d;
}

fsdem_gic_fields fsdem_gic_get_fields(const fsdem_gic *c) {
    fsdem_gic_fields f;
    int a;
    memset(&f, 0, sizeof f);
    if (!c) return f;
    f.dim = c->dim;
    for (a = 0; a < 3; ++a) f.n[a] = c->grid.n[a];
    f.cell_size = c->grid.dx;
    f.origin = c->grid.lo;
    f.solid_fraction = c->solid;
    f.porosity = c->porosity;
    return f;
}

/* Room for `count` granules in the per-granule arrays (outside the substeps); the records of the
   last step move with their array. */
static fsdem_result fsdem__gic_reserve(fsdem_gic *c, int count) {
    void **const arrays[4] = {(void **)&c->point, (void **)&c->sample, (void **)&c->force, (void **)&c->fluid_accel};
    const size_t sizes[4] = {sizeof(fsdem_vec3), sizeof(fsdem_fluid_sample), sizeof(fsdem_gic_force), sizeof(fsdem_vec3)};
    if (fsdem__grow_set(&c->head.allocator, arrays, sizes, 4, &c->granule_cap, c->head.records, count) != FSDEM_OK)
        return fsdem__fail(&c->head.status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_gic: out of memory (%d granules)", count);
    c->head.record = c->force;
    return FSDEM_OK;
}

/* ---- >>couple_gic_exchange : volume fractions, granule forces, the exchange ---- */

/* Volume of granule i (m^3; the disc's area times the DEM's disc_length in 2D, as its mass). */
static fsdem_real fsdem__gic_volume(const fsdem_gic *c, fsdem_real r) {
    return c->dim == 3 ? (fsdem_real)(4 * FSDEM__PI / 3) * r * r * r : (fsdem_real)FSDEM__PI * r * r * c->depth;
}

/* Kernel of point p over the cell centres (grid units: centre i at i), indices clamped into the
   grid, so weight beyond a side falls on the boundary cell. */
static void fsdem__gic_kernel(const fsdem_gic *c, fsdem_vec3 p, fsdem__kernel *kw) {
    fsdem_real s[3];
    int b;
    for (b = 0; b < 3; ++b)
        s[b] = b < c->dim ? (fsdem__comp(p, b) - fsdem__comp(c->grid.lo, b)) * c->grid.inv_dx - (fsdem_real)0.5 : 0;
    fsdem__kernel_weights(kw, c->dim, s, c->grid.n, 0);
}

/* Every granule finite and inside the PIC's grid (the volume of one outside would be folded into the
   boundary cells); `who` names the call in the message. */
static fsdem_result fsdem__gic_granules_inside(fsdem_gic *c, const fsdem_dem_particles *P, const char *who) {
    int i, a;
    for (i = 0; i < P->count; ++i) {
        int outside = 0;
        if (!fsdem__finite3(P->position[i]))
            return fsdem__fail(&c->head.status, FSDEM_ERR_NAN, "%s: granule %d (id %d) has a non-finite position", who, i, P->id[i]);
        for (a = 0; a < c->dim; ++a)
            outside |= fsdem__comp(P->position[i], a) < fsdem__comp(c->grid.lo, a) || fsdem__comp(P->position[i], a) > fsdem__comp(c->grid.hi, a);
        if (outside)
            return fsdem__fail(&c->head.status, FSDEM_ERR_OUT_OF_DOMAIN,
                               "%s: granule %d (id %d) at (%g, %g, %g) m is outside the PIC's grid (keep the DEM's walls within it)", who, i,
                               P->id[i], (double)P->position[i].x, (double)P->position[i].y, (double)P->position[i].z);
    }
    return FSDEM_OK;
}

/* Step 3 of >>couple_gic: alpha_s (Eq. 7a) and the porosity, into the PIC. */
fsdem_result fsdem_gic_update(fsdem_gic *c) {
    fsdem_dem_particles P;
    fsdem_pic_coupling pc;
    int i, k, q0, q1, q2;
    double volume = 0;
    fsdem_real most = 0;
    fsdem_result res;
    if (!c) return FSDEM_ERR_INVALID_ARG;
    P = fsdem_dem_get_particles(c->desc.dem);
    if ((res = fsdem__gic_granules_inside(c, &P, "fsdem_gic_update")) != FSDEM_OK) return res;
    memset(c->solid, 0, sizeof(fsdem_real) * (size_t)c->grid.ncell);
    for (i = 0; i < P.count; ++i) {
        const fsdem_real share = fsdem__gic_volume(c, P.radius[i]) / (c->cell_volume * c->depth);
        fsdem__kernel kw;
        fsdem__gic_kernel(c, P.position[i], &kw);
        for (q2 = 0; q2 < kw.count[2]; ++q2)
            for (q1 = 0; q1 < kw.count[1]; ++q1)
                for (q0 = 0; q0 < kw.count[0]; ++q0)
                    c->solid[fsdem__mac_cell(&c->grid, kw.idx[0][q0], kw.idx[1][q1], kw.idx[2][q2])] +=
                        share * kw.w[0][q0] * kw.w[1][q1] * kw.w[2][q2];
    }
    pc = fsdem_pic_get_coupling(c->desc.pic);
    for (k = 0; k < c->grid.ncell; ++k) {
        const fsdem_real s = c->solid[k];
        volume += (double)s;
        if (s > most) most = s;
        c->porosity[k] = 1 - (s < c->desc.max_solid_fraction ? s : c->desc.max_solid_fraction);
        pc.porosity[k] = c->porosity[k];
    }
    c->max_solid = most;
    c->solid_volume = (fsdem_real)(volume * (double)c->cell_volume);
    for (volume = 0, i = 0; i < P.count; ++i) volume += (double)fsdem__gic_volume(c, P.radius[i]);
    c->granule_volume = volume;
    return fsdem__ok(&c->head.status);
}

/* The porosity alpha_f' at point p (the cells' values interpolated). */
static fsdem_real fsdem__gic_porosity_at(const fsdem_gic *c, fsdem_vec3 p) {
    fsdem__kernel kw;
    fsdem_real e = 0;
    int q0, q1, q2;
    fsdem__gic_kernel(c, p, &kw);
    for (q2 = 0; q2 < kw.count[2]; ++q2)
        for (q1 = 0; q1 < kw.count[1]; ++q1)
            for (q0 = 0; q0 < kw.count[0]; ++q0)
                e += c->porosity[fsdem__mac_cell(&c->grid, kw.idx[0][q0], kw.idx[1][q1], kw.idx[2][q2])] * kw.w[0][q0] * kw.w[1][q1] *
                     kw.w[2][q2];
    return e;
}

/* a_f of Eq. 17 at every granule from the water of the last step, g - grad p / rho_f (0 before the
   PIC's first step: water at rest); the exchange's part is left out (>>couple_gic step 1). */
static void fsdem__gic_fluid_accelerations(fsdem_gic *c) {
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    const fsdem_vec3 g = fsdem_pic_get_desc(c->desc.pic).gravity;
    int i;
    if (!c->desc.virtual_mass) return;
    if (c->water_at_rest) {
        for (i = 0; i < P.count; ++i) c->fluid_accel[i] = fsdem__zero3();
        return;
    }
    for (i = 0; i < P.count; ++i) c->point[i] = P.position[i];
    fsdem_pic_sample(c->desc.pic, P.count, c->point, c->sample);
    for (i = 0; i < P.count; ++i) c->fluid_accel[i] = fsdem__madd(g, c->sample[i].pressure_gradient, -1 / c->rho);
}

/* Steps 1-2 of >>couple_gic at one force evaluation of the sand substeps (fsdem_dem_substep_fn):
   the granules' loads from the water of the last fluid step and their reactions onto its faces,
   weighted by the time the integrator holds these loads. */
static fsdem_result fsdem__gic_evaluate(void *user, fsdem_dem *dem, double time) {
    fsdem_gic *c = (fsdem_gic *)user;
    const fsdem_dem_particles P = fsdem_dem_get_particles(dem);
    const fsdem_dem_coupling load = fsdem_dem_get_coupling(dem);
    const fsdem_dem_desc dd = fsdem_dem_get_desc(dem);
    const int verlet = dd.integrator == FSDEM_DEM_INTEGRATOR_VERLET;
    const fsdem_vec3 gravity = dd.gravity;
    const fsdem_real held = verlet && (c->calls == 0 || c->calls == c->substeps_now) ? c->h / 2 : c->h;
    fsdem_result res;
    int i, wet_count = 0;
    c->failed = 1; /* until the evaluation completes */
    (void)time;
    for (i = 0; i < P.count; ++i) c->point[i] = P.position[i];
    res = fsdem_pic_sample(c->desc.pic, P.count, c->point, c->sample);
    if (res != FSDEM_OK) return fsdem__fail(&c->head.status, res, "fsdem_gic: %s", fsdem_pic_last_error(c->desc.pic));
    if (c->water_at_rest) /* no pressure solved yet */
        for (i = 0; i < P.count; ++i) c->sample[i].pressure_gradient = fsdem__scale(fsdem_pic_get_desc(c->desc.pic).gravity, c->rho);
    for (i = 0; i < P.count; ++i) {
        char why[FSDEM__MESSAGE_SIZE];
        const fsdem_fluid_sample *s = &c->sample[i];
        fsdem_gic_force *rec = &c->force[i];
        const fsdem_real volume = fsdem__gic_volume(c, P.radius[i]), wet = s->volume_fraction;
        const fsdem_vec3 slip = fsdem__sub(s->velocity, P.velocity[i]);
        fsdem_real cv = 0, eps = fsdem__gic_porosity_at(c, P.position[i]);
        rec->id = P.id[i];
        rec->fluid_velocity = s->velocity;
        rec->porosity = eps;
        rec->liquid = wet;
        rec->pressure = rec->drag = rec->virtual_mass = fsdem__zero3();
        rec->fluid_acceleration = c->desc.virtual_mass ? c->fluid_accel[i] : fsdem__zero3();
        if (P.fixed[i] || !(wet > 0)) {
            load.force[i] = fsdem__zero3();
            continue;
        }
        res = fsdem_drag_coefficient(c->desc.drag, eps, 2 * P.radius[i], fsdem__norm(slip), c->rho,
                                     c->mu > 0 ? c->mu : 1, &cv, NULL, why, sizeof why);
        if (res != FSDEM_OK) return fsdem__fail(&c->head.status, res, "fsdem_gic: granule %d (id %d): %s", i, P.id[i], why);
        cv *= c->desc.drag_scale;
        rec->pressure = fsdem__scale(s->pressure_gradient, -volume * wet);
        rec->drag = fsdem__scale(slip, cv * volume * wet);
        load.force[i] = fsdem__add(rec->pressure, rec->drag);
        if (c->desc.virtual_mass) { /* Eq. 14 through the DEM's mass m (>>couple_gic step 1) */
            const fsdem_real m = P.mass[i], ma = (c->dim == 3 ? (fsdem_real)0.5 : 1) * c->rho * volume * wet, k = 1 / (m + ma);
            const fsdem_vec3 ext = fsdem__madd(fsdem__madd(fsdem__scale(load.force[i], m * k), fsdem__sub(c->fluid_accel[i], gravity), m * ma * k),
                                               P.force[i], -ma * k);
            rec->virtual_mass = fsdem__sub(ext, load.force[i]);
            load.force[i] = ext;
        }
        c->tally.pressure = fsdem__madd(c->tally.pressure, rec->pressure, held);
        c->tally.drag = fsdem__madd(c->tally.drag, rec->drag, held);
        c->tally.virtual_mass = fsdem__madd(c->tally.virtual_mass, rec->virtual_mass, held);
        wet_count++;
        {
            const fsdem_vec3 impulse = fsdem__scale(fsdem__add(rec->drag, rec->virtual_mass), -held);
            int taken = 0;
            if (impulse.x != 0 || impulse.y != 0 || impulse.z != 0) {
                res = fsdem_pic_add_force(c->desc.pic, P.position[i], P.radius[i], fsdem__scale(impulse, 1 / (c->dt_now * c->depth)),
                                          &taken);
                if (res != FSDEM_OK) return fsdem__fail(&c->head.status, res, "fsdem_gic: %s", fsdem_pic_last_error(c->desc.pic));
                if (taken) c->tally.to_fluid = fsdem__add(c->tally.to_fluid, impulse);
                else c->tally.lost = fsdem__add(c->tally.lost, impulse);
            }
        }
    }
    c->tally.wet = wet_count;
    c->head.record = c->force;
    c->head.records = P.count;
    c->calls++;
    c->failed = 0;
    return FSDEM_OK;
}

/* ---- >>couple_gic_step : its stages and verbs (sand first) ---- */

/* The shortest drag relaxation time (s; 0: none) of the granules in the water now or within
   `horizon` (s) of their paths (a granule about to enter the water counts, at its speed against
   water at rest), from the water of the last step: a granule's own, m_i / (s c V_i), and the
   water's in each cell, rho alpha_f' dx^dim / sum_i s c_i V_i N_i over the granules' kernel
   weights there (the rate at which their drag relaxes it: the cell's share of the exchange over
   its water's mass, with the capped porosity and overlapping granules as they are). c is taken at
   the slip a granule without contacts reaches within the horizon at its present acceleration,
   |u - v_i| + horizon |F_ext / m_i + g| (the drag's growth only slows it): a law whose drag
   vanishes at zero slip (Eq. 5b) gave a granule released from rest no limit, and the first step
   ran two relaxation times; one falling at its terminal speed has no acceleration and keeps its
   slip. A granule in contact keeps its slip too: the contacts carry its weight in a bed, and their
   forces swing from substep to substep without building up a slip (with them in the acceleration,
   gic_volume's resting ball took 8 times the steps). */
static fsdem_real fsdem__gic_drag_time(const fsdem_gic *c, fsdem_real horizon) {
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    const fsdem_vec3 g = fsdem_dem_get_desc(c->desc.dem).gravity;
    fsdem_real shortest = 0;
    int i, k, q0, q1, q2;
    memset(c->rate, 0, sizeof(fsdem_real) * (size_t)c->grid.ncell);
    for (i = 0; i < P.count; ++i) {
        fsdem_fluid_sample here, ahead;
        const fsdem_vec3 x = P.position[i], y = fsdem__madd(x, P.velocity[i], horizon);
        const int alone = P.force[i].x == 0 && P.force[i].y == 0 && P.force[i].z == 0; /* no contact */
        const fsdem_vec3 load = P.external_force ? P.external_force[i] : fsdem__zero3();
        const fsdem_real volume = fsdem__gic_volume(c, P.radius[i]), gain = alone ? horizon * fsdem__norm(fsdem__madd(g, load, 1 / P.mass[i])) : 0;
        fsdem_real cv = 0, t, slip;
        fsdem__kernel kw;
        if (P.fixed[i] || fsdem_pic_sample(c->desc.pic, 1, &x, &here) != FSDEM_OK || fsdem_pic_sample(c->desc.pic, 1, &y, &ahead) != FSDEM_OK)
            continue;
        if (!(here.volume_fraction > 0) && !(ahead.volume_fraction > 0)) continue;
        if (!(here.volume_fraction > 0)) here.velocity = fsdem__zero3();
        slip = fsdem__norm(fsdem__sub(here.velocity, P.velocity[i])) + gain;
        if (fsdem_drag_coefficient(c->desc.drag, fsdem__gic_porosity_at(c, here.volume_fraction > 0 ? x : y), 2 * P.radius[i],
                                   slip < FSDEM_MAX_SPEED ? slip : FSDEM_MAX_SPEED, c->rho, c->mu > 0 ? c->mu : 1, &cv, NULL, NULL, 0) != FSDEM_OK ||
            !(cv > 0))
            continue;
        cv *= c->desc.drag_scale;
        t = P.mass[i] / (cv * volume);
        if (shortest == 0 || t < shortest) shortest = t;
        fsdem__gic_kernel(c, here.volume_fraction > 0 ? x : y, &kw);
        for (q2 = 0; q2 < kw.count[2]; ++q2)
            for (q1 = 0; q1 < kw.count[1]; ++q1)
                for (q0 = 0; q0 < kw.count[0]; ++q0)
                    c->rate[fsdem__mac_cell(&c->grid, kw.idx[0][q0], kw.idx[1][q1], kw.idx[2][q2])] +=
                        cv * volume / c->depth * kw.w[0][q0] * kw.w[1][q1] * kw.w[2][q2];
    }
    for (k = 0; k < c->grid.ncell; ++k)
        if (c->rate[k] > 0) {
            const fsdem_real t = c->rho * c->porosity[k] * c->cell_volume / c->rate[k];
            if (shortest == 0 || t < shortest) shortest = t;
        }
    return shortest;
}

/* The coupler's limits on the stable step (Eq. 33, the drag limit; the class's limit). */
static fsdem_result fsdem__gic_limit(const fsdem_coupler *head, fsdem_real *dt) {
    const fsdem_gic *c = (const fsdem_gic *)(const void *)head;
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    fsdem_real vmax = 0, limit = c->desc.max_dt_ratio * fsdem_dem_get_desc(c->desc.dem).dt;
    int i;
    for (i = 0; i < P.count; ++i) {
        const fsdem_real v = fsdem__norm(P.velocity[i]);
        if (!fsdem__finite(v))
            return fsdem__fail((fsdem__status *)&head->status, FSDEM_ERR_NAN, "fsdem_gic: granule %d (id %d) has a non-finite velocity", i,
                               P.id[i]);
        if (v > vmax) vmax = v;
    }
    if (vmax > 0 && c->desc.cfl * c->grid.dx / vmax < limit) limit = c->desc.cfl * c->grid.dx / vmax;
    if (limit < *dt) *dt = limit;
    {
        const fsdem_real drag = fsdem__gic_drag_time(c, *dt);
        if (drag > 0 && c->desc.drag_dt_fraction * drag < *dt) *dt = c->desc.drag_dt_fraction * drag;
    }
    return FSDEM_OK;
}

/* A step of dt refused before anything moves: too many substeps, a granule outside the grid, the
   PIC's own refusal, and for a dt of the caller's the drag limit (a stable dt keeps it by
   construction). */
static fsdem_result fsdem__gic_check(fsdem_coupler *head, fsdem_real dt, int chosen) {
    fsdem_gic *c = (fsdem_gic *)(void *)head;
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    fsdem_result res = fsdem__coupler_substeps_within(head, dt);
    if (res != FSDEM_OK || (res = fsdem__gic_granules_inside(c, &P, "fsdem_gic")) != FSDEM_OK ||
        (res = fsdem__coupler_particles_fit(head, c->grid.lo, c->grid.hi, "fsdem_gic")) != FSDEM_OK)
        return res;
    if ((res = fsdem_pic_check_dt(c->desc.pic, dt)) != FSDEM_OK)
        return fsdem__fail(&head->status, res, "fsdem_gic: %s", fsdem_pic_last_error(c->desc.pic));
    if (chosen) {
        const fsdem_real drag = fsdem__gic_drag_time(c, dt);
        if (drag > 0 && dt > c->desc.drag_dt_fraction * drag * (1 + (fsdem_real)1e-6))
            return fsdem__fail(&head->status, FSDEM_ERR_CFL,
                               "fsdem_gic: dt = %g s exceeds drag_dt_fraction %g of the shortest drag relaxation time %g s",
                               (double)dt, (double)c->desc.drag_dt_fraction, (double)drag);
    }
    return FSDEM_OK;
}

/* Steps 1-2 of >>couple_gic: the sand's substeps over dt, each force evaluation handing its
   exchange to the water's accelerations, cleared first. */
static fsdem_result fsdem__gic_sand(fsdem_coupler *head, fsdem_real dt) {
    fsdem_gic *c = (fsdem_gic *)(void *)head;
    fsdem_result res;
    if ((res = fsdem__gic_reserve(c, fsdem_dem_get_particles(c->desc.dem).count)) != FSDEM_OK) return res;
    fsdem_dem_substep_count(c->desc.dem, dt, &c->substeps_now);
    c->h = dt / (fsdem_real)c->substeps_now;
    c->dt_now = dt;
    c->calls = 0;
    c->failed = 0;
    c->water_at_rest = fsdem_pic_get_stats(c->desc.pic).steps == 0; /* once a step: the stats sum over the PIC */
    memset(&c->tally, 0, sizeof c->tally);
    c->tally.drag_dt = fsdem__gic_drag_time(c, dt);
    fsdem__gic_fluid_accelerations(c);
    fsdem_pic_clear_forces(c->desc.pic);
    res = fsdem__coupler_substeps(head, dt, fsdem__gic_evaluate, c, &c->failed);
    c->last = c->tally;
    return res;
}

/* Step 3 of >>couple_gic at the sand's new positions; with desc.displacement_flow, the volume the
   granules moved over the step becomes the source of the water's velocity projection: the
   mixture's continuity, d alpha_f'/dt + div(alpha_f' u) = 0, asks div(alpha_f' u) =
   -(alpha_f'(new) - alpha_f'(old)) / dt, which the PIC's pressure_rhs gives as
   -rho dx^2 (alpha_f'(new) - alpha_f'(old)) / dt^2 (>>pic: after the projection
   div = dt pressure_rhs / (rho dx^2)), times the cell's liquid fraction (in a cell the surface
   cuts, the granules displace air too). In the liquid the source sums to 0 over the cells, as the
   granules' volume is kept; a step in which their volume changed (granules added or removed, or the
   first step without fsdem_gic_update; the sum of their volumes, not of the cells', which rounds
   differently as they move) has no earlier fractions to difference and takes none. The PIC's
   values are held and put back after its step (fsdem__gic_release). */
static fsdem_result fsdem__gic_fractions(fsdem_coupler *head, fsdem_real dt) {
    fsdem_gic *c = (fsdem_gic *)(void *)head;
    const double before = c->granule_volume;
    const size_t cells = sizeof(fsdem_real) * (size_t)c->grid.ncell;
    fsdem_pic_coupling pc;
    fsdem_result res;
    int k;
    memcpy(c->rate, c->porosity, cells);
    if ((res = fsdem_gic_update(c)) != FSDEM_OK) return res;
    pc = fsdem_pic_get_coupling(c->desc.pic);
    c->pressure_rhs = pc.pressure_rhs;
    memcpy(c->held, pc.pressure_rhs, cells);
    if (c->desc.displacement_flow && before > 0 && fabs(c->granule_volume - before) <= 1e-9 * before) {
        const fsdem_real scale = -c->rho * c->grid.dx * c->grid.dx / (dt * dt);
        const fsdem_real *wet = fsdem_pic_get_fields(c->desc.pic).fraction;
        for (k = 0; k < c->grid.ncell; ++k) pc.pressure_rhs[k] += scale * (wet[k] < 1 ? wet[k] : 1) * (c->porosity[k] - c->rate[k]);
    }
    return FSDEM_OK;
}

/* After the PIC step: the PIC's pressure_rhs as it was before the displacement flow's source. */
static fsdem_result fsdem__gic_release(fsdem_coupler *head, fsdem_real dt) {
    fsdem_gic *c = (fsdem_gic *)(void *)head;
    (void)dt;
    memcpy(c->pressure_rhs, c->held, sizeof(fsdem_real) * (size_t)c->grid.ncell);
    return FSDEM_OK;
}

static const fsdem__stage fsdem__gic_stages[4] = {{"sand substeps", FSDEM__CLOCK_DEM, fsdem__gic_sand},
                                                  {"fractions", FSDEM__CLOCK_COUPLING, fsdem__gic_fractions},
                                                  {"PIC step", FSDEM__CLOCK_FLUID, NULL},
                                                  {"release", FSDEM__CLOCK_COUPLING, fsdem__gic_release}};

#define FSDEM__GIC_FIELD(name, kind) FSDEM__FIELD(fsdem_gic_force, name, #name, kind, 0)
static const fsdem__field fsdem__gic_fields[8] = {
    FSDEM__GIC_FIELD(id, INT),           FSDEM__GIC_FIELD(pressure, VEC3),       FSDEM__GIC_FIELD(drag, VEC3),
    FSDEM__GIC_FIELD(virtual_mass, VEC3), FSDEM__GIC_FIELD(fluid_velocity, VEC3), FSDEM__GIC_FIELD(fluid_acceleration, VEC3),
    FSDEM__GIC_FIELD(porosity, REAL),    FSDEM__GIC_FIELD(liquid, REAL)};
#undef FSDEM__GIC_FIELD

static const fsdem__coupler_class *fsdem__gic_class(void) {
    static const fsdem__coupler_class cls = {"fsdem_gic", &fsdem__fluid_pic, sizeof(fsdem_gic_force), fsdem__gic_fields, 8, NULL,
        fsdem__gic_limit, fsdem__gic_check, fsdem__gic_stages, 4};
    return &cls;
}

double fsdem_gic_time(const fsdem_gic *c) { return c ? fsdem__coupler_time(&c->head) : 0; }

fsdem_result fsdem_gic_get_force(const fsdem_gic *c, int index, fsdem_gic_force *out) {
    return c ? fsdem__coupler_get_record(&c->head, index, out, "fsdem_gic_get_force") : FSDEM_ERR_INVALID_ARG;
}

fsdem_result fsdem_gic_write_csv(const fsdem_gic *c, const char *path) {
    return c ? fsdem__coupler_write_csv(&c->head, path, "fsdem_gic_write_csv") : FSDEM_ERR_INVALID_ARG;
}

fsdem_gic_stats fsdem_gic_get_stats(const fsdem_gic *c) {
    fsdem_gic_stats st;
    memset(&st, 0, sizeof st);
    if (!c) return st;
    st.coupling = fsdem__coupler_stats(&c->head);
    st.wet = c->last.wet;
    st.pressure_impulse = c->last.pressure;
    st.drag_impulse = c->last.drag;
    st.virtual_mass_impulse = c->last.virtual_mass;
    st.to_fluid = c->last.to_fluid;
    st.lost = c->last.lost;
    st.drag_dt = c->last.drag_dt;
    st.max_solid_fraction = c->max_solid;
    st.solid_volume = c->solid_volume;
    return st;
}
