/* ===== >>impl_couple_swe : SWE-DEM floating debris =================================================

   Contents: >>couple_swe_object (desc, creation), >>couple_swe_geometry (submerged parts of a
   sphere), >>couple_swe_forces (seed 003 Eq. 5-8), >>couple_swe_step (its stages and verbs on the
   staged step of >>couple). The coupler reaches the solvers through their coupling functions only
   (>>doc). */

/* ---- >>couple_swe_object : desc, creation ---- */

struct fsdem_swe_dem {
    fsdem_coupler head;            /* >>couple; its records are `force` */
    fsdem_swe_dem_desc desc;
    fsdem_real rho, g, dry;        /* the SWE's density, |g| and dry depth */
    fsdem_swe_dem_force *force;    /* one per DEM particle of the last update */
    fsdem_vec3 *reaction;          /* N, horizontal force on each sphere whose reaction the water took */
    int force_capacity;            /* of force and reaction */
    int wet;                       /* spheres in water at the last update */
    fsdem_vec3 impulse;            /* N s, given to the water */
};

static const fsdem__coupler_class *fsdem__swe_dem_class(void);

fsdem_swe_dem_desc fsdem_swe_dem_desc_default(void) {
    fsdem_swe_dem_desc d;
    memset(&d, 0, sizeof d);
    d.beta = (fsdem_real)1.1;
    d.two_way = 1;
    d.heave_damping = 0;
    d.max_substeps = 100000;
    return d;
}

fsdem_result fsdem_swe_dem_desc_check(const fsdem_swe_dem_desc *d, char *msg, size_t size) {
    fsdem_dem_desc dd;
    fsdem_swe_desc sd;
    fsdem_vec3 g;
    fsdem_real gs;
    if (!d) return fsdem__reject(msg, size, "fsdem_swe_dem_desc is NULL");
    if (!d->swe || !d->dem) return fsdem__reject(msg, size, "fsdem_swe_dem_desc.swe and .dem must both be set");
    dd = fsdem_dem_get_desc(d->dem);
    sd = fsdem_swe_get_desc(d->swe);
    if (dd.dim != 3)
        return fsdem__reject(msg, size, "fsdem_swe_dem_desc.dem must be 3D (spheres, z vertical); it has dim %d", dd.dim);
    g = dd.gravity;
    gs = -sd.gravity.z;
    if (g.x != 0 || g.y != 0 || !(fabs(g.z + gs) <= 1e-12 * gs))
        return fsdem__reject(msg, size, "fsdem_swe_dem_desc: the DEM gravity (%g, %g, %g) must be (0, 0, -g) with the SWE's g = %g m/s^2",
                             (double)g.x, (double)g.y, (double)g.z, (double)gs);
    if (!(d->beta > 0) || !fsdem__finite(d->beta))
        return fsdem__reject(msg, size, "fsdem_swe_dem_desc.beta must be > 0 (got %g)", (double)d->beta);
    if (!(d->heave_damping >= 0) || !fsdem__finite(d->heave_damping))
        return fsdem__reject(msg, size, "fsdem_swe_dem_desc.heave_damping must be >= 0 (got %g)",
                             (double)d->heave_damping);
    return fsdem__coupler_check(fsdem__swe_dem_class(), "fsdem_swe_dem_desc", d->swe, d->two_way ? (unsigned)FSDEM_SWE_ARRAYS_SOURCE : 0u, d->dem, 0,
                                sd.gravity, d->max_substeps, msg, size);
}

fsdem_result fsdem_swe_dem_create(const fsdem_swe_dem_desc *desc, fsdem_swe_dem **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_swe_dem *c;
    fsdem_result res;
    if (out) *out = NULL;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    res = fsdem_swe_dem_desc_check(desc, msg, sizeof msg);
    c = (fsdem_swe_dem *)fsdem__coupler_new(fsdem__swe_dem_class(), res, msg, desc ? desc->swe : NULL, desc ? desc->dem : NULL,
                                            desc && desc->two_way ? (unsigned)FSDEM_SWE_ARRAYS_SOURCE : 0u, desc ? desc->max_substeps : 0,
                                            desc ? desc->log : NULL, desc ? desc->log_user : NULL, sizeof *c, &res);
    if (!c) return res;
    {
        const fsdem_swe_desc sd = fsdem_swe_get_desc(desc->swe);
        c->rho = sd.density;
        c->g = -sd.gravity.z;
        c->dry = sd.dry_depth;
    }
    c->desc = *desc;
    *out = c;
    return FSDEM_OK;
}

void fsdem_swe_dem_destroy(fsdem_swe_dem *c) {
    if (!c) return;
    fsdem__free(&c->head.allocator, c->force, sizeof(fsdem_swe_dem_force) * (size_t)c->force_capacity);
    fsdem__free(&c->head.allocator, c->reaction, sizeof(fsdem_vec3) * (size_t)c->force_capacity);
    fsdem__coupler_free(&c->head, sizeof *c);
}

const char *fsdem_swe_dem_last_error(const fsdem_swe_dem *c) { return c ? c->head.status.message : "fsdem_swe_dem is NULL"; }

fsdem_swe_dem_desc fsdem_swe_dem_get_desc(const fsdem_swe_dem *c) {
    fsdem_swe_dem_desc d;
    if (c) return c->desc;
    memset(&d, 0, sizeof d);
    return d;
}

fsdem_coupler *fsdem_swe_dem_coupler(fsdem_swe_dem *c) { return c ? &c->head : NULL; }

/* ---- >>couple_swe_geometry : submerged parts of a sphere ---- */

/* Submerged part of a vertical circle of radius r centred at height zc under a surface at eta: its
   area and its first moment M = int (eta - z) w(z) dz, so the hydrostatic force on it is rho g M.
   With z = zc - r cos(phi) and w = 2 r sin(phi) both integrals are closed forms in the angle theta of
   the waterline: area r^2 (theta - sin cos), M = 2 r^2 [(eta - zc)(theta - sin cos)/2 + r sin^3 / 3]. */
static void fsdem__swe_dem_submerged_disc(fsdem_real r, fsdem_real zc, fsdem_real eta, fsdem_real *area, fsdem_real *moment) {
    fsdem_real top = eta < zc + r ? eta : zc + r, c, s, th;
    if (top <= zc - r) {
        *area = *moment = 0;
        return;
    }
    c = (zc - top) / r;
    c = c < -1 ? -1 : c > 1 ? 1 : c;
    th = (fsdem_real)acos(c);
    s = (fsdem_real)sin(th);
    *area = r * r * (th - s * c);
    *moment = 2 * r * r * ((eta - zc) * (th - s * c) / 2 + r * s * s * s / 3);
}

/* Volume of the part of a sphere (radius r, centre height zc) below the surface eta: a cap. */
static fsdem_real fsdem__swe_dem_submerged_sphere(fsdem_real r, fsdem_real zc, fsdem_real eta) {
    fsdem_real s = eta - (zc - r);
    if (s <= 0) return 0;
    if (s > 2 * r) s = 2 * r;
    return (fsdem_real)FSDEM__PI * s * s * (3 * r - s) / 3;
}

/* Water at p shifted by `shift` along a horizontal axis (0: x, 1: y); off the grid it is `fallback`. */
static fsdem_swe_cell fsdem__swe_dem_water_at(const fsdem_swe *swe, fsdem_vec3 p, int axis, fsdem_real shift,
                                              fsdem_swe_cell fallback) {
    fsdem_swe_cell cell;
    fsdem_real x = p.x + (axis == 0 ? shift : 0), y = p.y + (axis == 1 ? shift : 0);
    return fsdem_swe_sample_state(swe, x, y, &cell) == FSDEM_OK ? cell : fallback;
}

/* Buoyancy (Eq. 5) and heave damping of sphere i at its current height and vertical speed, against
   the water surface held in out->surface; updates `out` and returns the vertical force (N). */
static fsdem_real fsdem__swe_dem_vertical(const fsdem_swe_dem *c, const fsdem_dem_particles *pv, int i,
                                          fsdem_swe_dem_force *out) {
    const fsdem_real rho = c->rho, g = c->g, r = pv->radius[i], z = pv->position[i].z;
    out->submerged_volume = fsdem__swe_dem_submerged_sphere(r, z, out->surface);
    out->buoyancy = fsdem_v3(0, 0, rho * g * out->submerged_volume);
    out->heave = fsdem__zero3();
    if (c->desc.heave_damping > 0) {
        /* critical damping of the hydrostatic spring rho g A_waterplane of the bobbing */
        fsdem_real a2 = r * r - (out->surface - z) * (out->surface - z);
        if (a2 > 0)
            out->heave.z = -2 * c->desc.heave_damping * (fsdem_real)sqrt(rho * g * (fsdem_real)FSDEM__PI * a2 * pv->mass[i]) *
                           pv->velocity[i].z;
    }
    return out->buoyancy.z + out->heave.z;
}

/* ---- >>couple_swe_forces : seed 003 Eq. 5-8 ---- */

fsdem_result fsdem_swe_dem_update(fsdem_swe_dem *c) {
    fsdem_swe *swe;
    fsdem_dem_particles pv;
    fsdem_dem_coupling loads;
    fsdem_real beta;
    int i, a, axes, n;
    if (!c) return FSDEM_ERR_INVALID_ARG;
    swe = c->desc.swe;
    beta = c->desc.beta;
    axes = fsdem_swe_get_desc(swe).dim;
    pv = fsdem_dem_get_particles(c->desc.dem);
    n = pv.count;
    if (n > c->force_capacity) {
        fsdem_swe_dem_force *force = (fsdem_swe_dem_force *)fsdem__alloc(&c->head.allocator, sizeof *force * (size_t)n);
        fsdem_vec3 *reaction = (fsdem_vec3 *)fsdem__alloc(&c->head.allocator, sizeof *reaction * (size_t)n);
        if (!force || !reaction) {
            fsdem__free(&c->head.allocator, force, sizeof *force * (size_t)n);
            fsdem__free(&c->head.allocator, reaction, sizeof *reaction * (size_t)n);
            return fsdem__fail(&c->head.status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_swe_dem: out of memory for the forces of %d particles", n);
        }
        fsdem__free(&c->head.allocator, c->force, sizeof *force * (size_t)c->force_capacity);
        fsdem__free(&c->head.allocator, c->reaction, sizeof *reaction * (size_t)c->force_capacity);
        c->force = force;
        c->reaction = reaction;
        c->force_capacity = n;
    }
    loads = fsdem_dem_get_coupling(c->desc.dem);
    if (c->desc.two_way) fsdem_swe_clear_forces(swe);
    c->wet = 0;
    for (i = 0; i < n; ++i) {
        fsdem_swe_dem_force *out = &c->force[i];
        const fsdem_vec3 p = pv.position[i], w = pv.velocity[i];
        const fsdem_real r = pv.radius[i];
        fsdem_swe_cell centre, back[2], front[2], flow;
        fsdem_vec3 horizontal;
        memset(out, 0, sizeof *out);
        out->id = pv.id[i];
        loads.force[i] = c->reaction[i] = fsdem__zero3();
        if (pv.fixed[i] || fsdem_swe_sample_state(swe, p.x, p.y, &centre) != FSDEM_OK) continue;
        /* the water at the centre, and at the back (-r) and front (+r) along each horizontal axis; the
           flow velocity is the centre's, or that of the deepest side while a front reaches the sphere */
        flow = centre;
        for (a = 0; a < axes; ++a) {
            back[a] = fsdem__swe_dem_water_at(swe, p, a, -r, centre);
            front[a] = fsdem__swe_dem_water_at(swe, p, a, r, centre);
            if (flow.depth < c->dry && back[a].depth > flow.depth) flow = back[a];
            if (flow.depth < c->dry && front[a].depth > flow.depth) flow = front[a];
        }
        if (flow.depth < c->dry) continue;
        out->wet = 1;
        c->wet++;
        out->surface = centre.eta;
        for (a = 0; a < axes; ++a) {
            /* Eq. 6-7 along axis a */
            fsdem_real area_b, area_f, m_b, m_f, rel, hydro, dyn;
            fsdem__swe_dem_submerged_disc(r, p.z, back[a].eta, &area_b, &m_b);
            fsdem__swe_dem_submerged_disc(r, p.z, front[a].eta, &area_f, &m_f);
            rel = beta * (a == 0 ? flow.u : flow.v) - (a == 0 ? w.x : w.y);
            hydro = c->rho * c->g * (m_b - m_f);
            dyn = c->rho * rel * (rel < 0 ? -rel : rel) * (rel > 0 ? area_b : area_f);
            if (a == 0) {
                out->hydrostatic.x = hydro;
                out->dynamic.x = dyn;
                out->frontal_area = area_f;
            } else {
                out->hydrostatic.y = hydro;
                out->dynamic.y = dyn;
            }
        }
        horizontal = fsdem__add(out->hydrostatic, out->dynamic);
        if (c->desc.two_way) {
            /* Eq. 8: the reaction -F_h as a momentum source under the sphere; a force whose reaction
               no wet cell can take is dropped, so momentum is exchanged, never created */
            int taken = 0;
            fsdem_swe_add_force(swe, p, r, fsdem__scale(horizontal, -1), &taken);
            if (!taken) out->hydrostatic = out->dynamic = horizontal = fsdem__zero3();
            c->reaction[i] = horizontal;
        }
        horizontal.z = fsdem__swe_dem_vertical(c, &pv, i, out);
        loads.force[i] = horizontal;
    }
    c->head.record = c->force;
    c->head.records = n;
    return fsdem__ok(&c->head.status);
}

fsdem_result fsdem_swe_dem_get_force(const fsdem_swe_dem *c, int index, fsdem_swe_dem_force *out) {
    return c ? fsdem__coupler_get_record(&c->head, index, out, "fsdem_swe_dem_get_force") : FSDEM_ERR_INVALID_ARG;
}

fsdem_result fsdem_swe_dem_write_csv(const fsdem_swe_dem *c, const char *path) {
    return c ? fsdem__coupler_write_csv(&c->head, path, "fsdem_swe_dem_write_csv") : FSDEM_ERR_INVALID_ARG;
}

fsdem_swe_dem_stats fsdem_swe_dem_get_stats(const fsdem_swe_dem *c) {
    fsdem_swe_dem_stats st;
    memset(&st, 0, sizeof st);
    if (!c) return st;
    st.coupling = fsdem__coupler_stats(&c->head);
    st.wet = c->wet;
    st.impulse_to_water = c->impulse;
    return st;
}

/* ---- >>couple_swe_step : its stages and verbs ---- */

/* fsdem_dem_substep_fn: buoyancy and heave damping of the spheres in water refreshed for the heights
   of every DEM force evaluation, against the water surface held over the fluid step. */
static fsdem_result fsdem__swe_dem_refresh(void *user, fsdem_dem *dem, double time) {
    fsdem_swe_dem *c = (fsdem_swe_dem *)user;
    const fsdem_dem_particles pv = fsdem_dem_get_particles(dem);
    const fsdem_dem_coupling loads = fsdem_dem_get_coupling(dem);
    int i;
    (void)time;
    for (i = 0; i < pv.count; ++i)
        if (c->force[i].wet) loads.force[i].z = fsdem__swe_dem_vertical(c, &pv, i, &c->force[i]);
    return FSDEM_OK;
}

/* A step of dt refused before anything moves: too many substeps, or the SWE's own refusal. */
static fsdem_result fsdem__swe_dem_check(fsdem_coupler *head, fsdem_real dt, int chosen) {
    fsdem_swe_dem *c = (fsdem_swe_dem *)(void *)head;
    fsdem_result res = fsdem__coupler_substeps_within(head, dt);
    (void)chosen;
    if (res == FSDEM_OK && (res = fsdem_swe_check_dt(c->desc.swe, dt)) != FSDEM_OK)
        return fsdem__fail(&head->status, res, "fsdem_swe_dem: SWE step: %s", fsdem_swe_last_error(c->desc.swe));
    return res;
}

static fsdem_result fsdem__swe_dem_forces(fsdem_coupler *head, fsdem_real dt) {
    (void)dt;
    return fsdem_swe_dem_update((fsdem_swe_dem *)(void *)head);
}

/* The reactions' impulse on the water over the step, then the DEM's substeps. */
static fsdem_result fsdem__swe_dem_substeps(fsdem_coupler *head, fsdem_real dt) {
    fsdem_swe_dem *c = (fsdem_swe_dem *)(void *)head;
    const int count = fsdem_dem_get_particles(c->desc.dem).count;
    int k;
    for (k = 0; k < c->force_capacity && k < count; ++k) c->impulse = fsdem__madd(c->impulse, c->reaction[k], -dt);
    return fsdem__coupler_substeps(head, dt, fsdem__swe_dem_refresh, c, NULL);
}

static const fsdem__stage fsdem__swe_dem_stages[3] = {{"forces", FSDEM__CLOCK_COUPLING, fsdem__swe_dem_forces},
                                                      {"shallow-water step", FSDEM__CLOCK_FLUID, NULL},
                                                      {"DEM substeps", FSDEM__CLOCK_DEM, fsdem__swe_dem_substeps}};

#define FSDEM__SWE_DEM_FIELD(name, kind) FSDEM__FIELD(fsdem_swe_dem_force, name, #name, kind, 1)
static const fsdem__field fsdem__swe_dem_fields[9] = {
    FSDEM__SWE_DEM_FIELD(id, INT),          FSDEM__SWE_DEM_FIELD(buoyancy, VEC3),         FSDEM__SWE_DEM_FIELD(hydrostatic, VEC3),
    FSDEM__SWE_DEM_FIELD(dynamic, VEC3),    FSDEM__SWE_DEM_FIELD(heave, VEC3),            FSDEM__SWE_DEM_FIELD(submerged_volume, REAL),
    FSDEM__SWE_DEM_FIELD(frontal_area, REAL), FSDEM__SWE_DEM_FIELD(surface, REAL),        FSDEM__SWE_DEM_FIELD(wet, INT)};
#undef FSDEM__SWE_DEM_FIELD

static const fsdem__coupler_class *fsdem__swe_dem_class(void) {
    static const fsdem__coupler_class cls = {"fsdem_swe_dem", &fsdem__fluid_swe, sizeof(fsdem_swe_dem_force),
        fsdem__swe_dem_fields, 9, NULL, NULL, fsdem__swe_dem_check, fsdem__swe_dem_stages, 3};
    return &cls;
}

double fsdem_swe_dem_time(const fsdem_swe_dem *c) { return c ? fsdem__coupler_time(&c->head) : 0; }
