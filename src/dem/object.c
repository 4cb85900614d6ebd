/* ---- >>dem_object : creation, materials, particles ---- */

/* Every per-particle array with its element size, so growth and removal treat them alike. */
#define FSDEM__DEM_PARTICLE_ARRAYS 21
static void fsdem__dem_particle_arrays(fsdem_dem *d, void **ptr[FSDEM__DEM_PARTICLE_ARRAYS],
                                   size_t size[FSDEM__DEM_PARTICLE_ARRAYS]) {
    int k = 0;
#define FSDEM__DEM_ARRAY(field)          \
    ptr[k] = (void **)&d->field;     \
    size[k++] = sizeof(*d->field)
    FSDEM__DEM_ARRAY(id); FSDEM__DEM_ARRAY(material); FSDEM__DEM_ARRAY(old_of); FSDEM__DEM_ARRAY(fixed);
    FSDEM__DEM_ARRAY(x); FSDEM__DEM_ARRAY(v); FSDEM__DEM_ARRAY(w); FSDEM__DEM_ARRAY(f); FSDEM__DEM_ARRAY(t);
    FSDEM__DEM_ARRAY(fext); FSDEM__DEM_ARRAY(text); FSDEM__DEM_ARRAY(x_ref);
    FSDEM__DEM_ARRAY(x0); FSDEM__DEM_ARRAY(v0); FSDEM__DEM_ARRAY(w0); FSDEM__DEM_ARRAY(fa); FSDEM__DEM_ARRAY(ta);
    FSDEM__DEM_ARRAY(r); FSDEM__DEM_ARRAY(m); FSDEM__DEM_ARRAY(inv_m); FSDEM__DEM_ARRAY(inv_i);
#undef FSDEM__DEM_ARRAY
    FSDEM_ASSERT(k == FSDEM__DEM_PARTICLE_ARRAYS);
}

/* Bytes of the per-particle arrays for `count` particles. */
static size_t fsdem__dem_particle_bytes(fsdem_dem *d, int count) {
    void **ptr[FSDEM__DEM_PARTICLE_ARRAYS];
    size_t size[FSDEM__DEM_PARTICLE_ARRAYS], total = 0;
    int k;
    fsdem__dem_particle_arrays(d, ptr, size);
    for (k = 0; k < FSDEM__DEM_PARTICLE_ARRAYS; ++k) total += size[k] * (size_t)count;
    return total;
}

static fsdem_result fsdem__dem_reserve_particles(fsdem_dem *d, int need) {
    void **ptr[FSDEM__DEM_PARTICLE_ARRAYS];
    void *fresh[FSDEM__DEM_PARTICLE_ARRAYS];
    size_t size[FSDEM__DEM_PARTICLE_ARRAYS];
    int k, cap = d->capacity > 0 ? d->capacity : 64;
    if (need <= d->capacity) return FSDEM_OK;
    if (need > FSDEM__DEM_MAX_PARTICLES) return FSDEM_ERR_OUT_OF_MEMORY;
    while (cap < need) cap = cap > FSDEM__DEM_MAX_PARTICLES / 2 ? FSDEM__DEM_MAX_PARTICLES : 2 * cap;
    fsdem__dem_particle_arrays(d, ptr, size);
    for (k = 0; k < FSDEM__DEM_PARTICLE_ARRAYS; ++k) {
        fresh[k] = fsdem__alloc(&d->allocator, size[k] * (size_t)cap);
        if (!fresh[k]) {
            while (k-- > 0) fsdem__free(&d->allocator, fresh[k], size[k] * (size_t)cap);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
    }
    for (k = 0; k < FSDEM__DEM_PARTICLE_ARRAYS; ++k) {
        if (d->n > 0) memcpy(fresh[k], *ptr[k], size[k] * (size_t)d->n);
        fsdem__free(&d->allocator, *ptr[k], size[k] * (size_t)d->capacity);
        *ptr[k] = fresh[k];
    }
    d->capacity = cap;
    return FSDEM_OK;
}

static void fsdem__dem_list_free_entries(fsdem_dem *d, fsdem__dem_list *l) {
    fsdem__free(&d->allocator, l->first, sizeof(int) * (size_t)l->capacity);
    fsdem__free(&d->allocator, l->key, sizeof(int) * (size_t)l->capacity);
    fsdem__free(&d->allocator, l->history, sizeof(fsdem_vec3) * (size_t)l->capacity);
}

static void fsdem__dem_list_free(fsdem_dem *d, fsdem__dem_list *l) {
    fsdem__free(&d->allocator, l->start, sizeof(int) * (size_t)l->start_capacity);
    fsdem__dem_list_free_entries(d, l);
    memset(l, 0, sizeof *l);
}

fsdem_result fsdem_dem_create(const fsdem_dem_desc *desc, fsdem_dem **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_dem *d;
    fsdem_result res;
    if (out) *out = NULL;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    res = fsdem_dem_desc_check(desc, msg, sizeof msg);
    d = (fsdem_dem *)fsdem__object_new(res, msg, desc ? desc->log : NULL, desc ? desc->log_user : NULL,
                                       desc ? &desc->allocator : NULL, sizeof *d, "fsdem_dem_create", &res);
    if (!d) return res;
    d->desc = *desc;
    if (desc->dt_rule == FSDEM_DEM_DT_RULE_AUTO)
        d->desc.dt_rule = fsdem__dem_seed000_stiffness(desc) ? FSDEM_DEM_DT_RULE_LINEAR_SEED000
                          : desc->law == FSDEM_DEM_LAW_GIC   ? FSDEM_DEM_DT_RULE_GIC
                                                             : FSDEM_DEM_DT_RULE_RAYLEIGH;
    if (desc->dt_param == 0)
        d->desc.dt_param = d->desc.dt_rule == FSDEM_DEM_DT_RULE_LINEAR_SEED000 ? 150
                           : d->desc.dt_rule == FSDEM_DEM_DT_RULE_RAYLEIGH   ? (fsdem_real)0.2
                                                                        : 1;
    d->allocator = desc->allocator;
    d->status.log = desc->log;
    d->status.log_user = desc->log_user;
    fsdem__claims_init(&d->claims, "DEM", fsdem__dem_claimable, 1);
    d->dt = desc->dt;
    d->grid.allocator = desc->allocator;
    d->need_rebuild = 1;
    d->periods = fsdem__periods_of(desc->periodic, desc->dim, desc->domain_min, desc->domain_max);
    {
        fsdem_real accel = desc->linear_accel > 0 ? desc->linear_accel : fsdem__norm(desc->gravity);
        d->k0_linear = fsdem__dem_seed000_stiffness(desc) ? accel / (desc->linear_theta * desc->linear_dx) : 0;
    }
    res = fsdem__dem_reserve_particles(d, desc->capacity > 0 ? desc->capacity : 1);
    if (res != FSDEM_OK) {
        fsdem__log_oom(desc->log, desc->log_user, "fsdem_dem_create", fsdem__dem_particle_bytes(d, desc->capacity));
        fsdem_dem_destroy(d);
        return res;
    }
    *out = d;
    return FSDEM_OK;
}

void fsdem_dem_destroy(fsdem_dem *d) {
    void **ptr[FSDEM__DEM_PARTICLE_ARRAYS];
    size_t size[FSDEM__DEM_PARTICLE_ARRAYS];
    int k;
    fsdem_allocator al;
    if (!d) return;
    al = d->allocator;
    fsdem__dem_particle_arrays(d, ptr, size);
    for (k = 0; k < FSDEM__DEM_PARTICLE_ARRAYS; ++k) fsdem__free(&al, *ptr[k], size[k] * (size_t)d->capacity);
    fsdem__free(&al, d->materials, sizeof(fsdem_dem_material) * (size_t)d->material_capacity);
    fsdem__free(&al, d->pairs, sizeof(fsdem__dem_pair) * (size_t)d->pair_capacity);
    fsdem__free(&al, d->walls, sizeof(fsdem__dem_wall) * (size_t)d->wall_capacity);
    fsdem__dem_list_free(d, &d->pp);
    fsdem__dem_list_free(d, &d->pp_old);
    fsdem__dem_list_free(d, &d->pw);
    fsdem__dem_list_free(d, &d->pw_old);
    fsdem__free(&al, d->hits, sizeof(fsdem__dem_wall_hit) * (size_t)d->hit_capacity);
    fsdem__arena_free(&al, &d->arena);
    fsdem__free(&al, d->found, sizeof(int) * (size_t)d->found_capacity);
    fsdem__free(&al, d->inert, sizeof(int) * (size_t)d->inert_capacity);
    fsdem_cellgrid_free(&d->grid);
    fsdem__free(&al, d, sizeof *d);
}

const char *fsdem_dem_last_error(const fsdem_dem *d) { return d ? d->status.message : "fsdem_dem is NULL"; }

/* Whether some pair of materials has rolling resistance or cohesion (the force loop adds them only then). */
static void fsdem__dem_pair_flags(fsdem_dem *d) {
    int k;
    d->rolling = d->cohesive = 0;
    for (k = 0; k < d->material_count * d->material_count; ++k) {
        d->rolling |= d->pairs[k].rolling > 0;
        d->cohesive |= d->pairs[k].cohesion > 0;
    }
}

fsdem_result fsdem_dem_add_material(fsdem_dem *d, const fsdem_dem_material *mat, int *index) {
    char msg[FSDEM__MESSAGE_SIZE];
    int nm, a, b;
    fsdem__dem_pair *pairs;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    nm = d->material_count + 1;
    if (fsdem__dem_material_check(mat, msg, sizeof msg) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "%s", msg);
    if (fsdem__grow(&d->allocator, (void **)&d->materials, &d->material_capacity, d->material_count, nm,
                    sizeof(fsdem_dem_material)) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_dem_add_material: out of memory");
    pairs = (fsdem__dem_pair *)fsdem__alloc(&d->allocator, sizeof(fsdem__dem_pair) * (size_t)(nm * nm));
    if (!pairs) return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_dem_add_material: out of memory");
    d->materials[d->material_count] = *mat;
    for (a = 0; a < nm; ++a)
        for (b = 0; b < nm; ++b) {
            if (a < nm - 1 && b < nm - 1) pairs[a * nm + b] = d->pairs[a * (nm - 1) + b];
            else if (b < a) pairs[a * nm + b] = pairs[b * nm + a];
            else fsdem__dem_pair_setup(&pairs[a * nm + b], &d->materials[a], &d->materials[b], &d->desc, d->k0_linear,
                                   pairs, a * nm + b);
        }
    /* the loop reads earlier rows only, which are already in the new table */
    fsdem__free(&d->allocator, d->pairs, sizeof(fsdem__dem_pair) * (size_t)d->pair_capacity);
    d->pairs = pairs;
    d->pair_capacity = nm * nm;
    d->material_count = nm;
    fsdem__dem_pair_flags(d);
    d->forces_valid = 0;
    if (index) *index = nm - 1;
    return fsdem__ok(&d->status);
}

static fsdem_result fsdem__dem_material_pair_check(const fsdem_dem_material_pair *v, char *msg, size_t size) {
    if (!v) return fsdem__reject(msg, size, "fsdem_dem_set_material_pair: values is NULL");
    if (!(v->restitution >= (fsdem_real)1e-6 && v->restitution <= 1))
        return fsdem__reject(msg, size, "fsdem_dem_material_pair.restitution must be in [1e-6, 1] (got %g)", (double)v->restitution);
    if (!(v->friction >= 0) || !fsdem__finite(v->friction))
        return fsdem__reject(msg, size, "fsdem_dem_material_pair.friction must be >= 0 (got %g)", (double)v->friction);
    if (!(v->rolling_friction >= 0) || !fsdem__finite(v->rolling_friction))
        return fsdem__reject(msg, size, "fsdem_dem_material_pair.rolling_friction must be >= 0 (got %g)", (double)v->rolling_friction);
    if (!(v->cohesion >= 0) || !fsdem__finite(v->cohesion))
        return fsdem__reject(msg, size, "fsdem_dem_material_pair.cohesion must be >= 0 (got %g J/m^3)", (double)v->cohesion);
    return FSDEM_OK;
}

fsdem_result fsdem_dem_set_material_pair(fsdem_dem *d, int a, int b, const fsdem_dem_material_pair *values) {
    char msg[FSDEM__MESSAGE_SIZE];
    int k;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    if (a < 0 || a >= d->material_count || b < 0 || b >= d->material_count)
        return fsdem__fail(&d->status, FSDEM_ERR_NOT_FOUND, "fsdem_dem_set_material_pair: materials %d and %d (%d added)", a, b,
                           d->material_count);
    if (fsdem__dem_material_pair_check(values, msg, sizeof msg) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "%s", msg);
    for (k = 0; k < 2; ++k) {
        /* set up aside: the table, searched for a known Hertz calibration, still holds the old pair */
        fsdem__dem_pair *p = &d->pairs[k ? b * d->material_count + a : a * d->material_count + b], q = *p;
        q.restitution = values->restitution;
        q.friction = values->friction;
        q.rolling = values->rolling_friction;
        q.cohesion = values->cohesion;
        fsdem__dem_pair_coefficients(&q, &d->desc, d->k0_linear, d->pairs, d->material_count * d->material_count);
        *p = q;
    }
    fsdem__dem_pair_flags(d);
    d->forces_valid = 0;
    return fsdem__ok(&d->status);
}

fsdem_dem_material_pair fsdem_dem_get_material_pair(const fsdem_dem *d, int a, int b) {
    fsdem_dem_material_pair v;
    memset(&v, 0, sizeof v);
    if (d && a >= 0 && a < d->material_count && b >= 0 && b < d->material_count) {
        const fsdem__dem_pair *p = &d->pairs[a * d->material_count + b];
        v.restitution = p->restitution;
        v.friction = p->friction;
        v.rolling_friction = p->rolling;
        v.cohesion = p->cohesion;
    }
    return v;
}

static int fsdem__dem_inside_domain(const fsdem_dem *d, fsdem_vec3 p) {
    const fsdem_vec3 lo = d->desc.domain_min, hi = d->desc.domain_max;
    if (!(p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y)) return 0;
    return d->desc.dim == 2 || (p.z >= lo.z && p.z <= hi.z);
}

/* Checks a kinematic state of a particle of radius r; writes the reason and returns the code, or
   FSDEM_OK. Speeds, of the centre and of the surface by the spin, are bounded by FSDEM_MAX_SPEED. */
static fsdem_result fsdem__dem_state_check(fsdem_dem *d, const char *what, fsdem_vec3 x, fsdem_vec3 v, fsdem_vec3 w, fsdem_real r) {
    if (!fsdem__finite3(x) || !fsdem__finite3(v) || !fsdem__finite3(w))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "%s: position, velocity and angular velocity must be finite",
                           what);
    if (!fsdem__within(v, FSDEM_MAX_SPEED) || !fsdem__within(fsdem__scale(w, r), FSDEM_MAX_SPEED))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                           "%s: velocity (%g, %g, %g) m/s or the surface speed of angular velocity (%g, %g, %g) rad/s is above "
                           "FSDEM_MAX_SPEED (%g m/s)",
                           what, (double)v.x, (double)v.y, (double)v.z, (double)w.x, (double)w.y, (double)w.z, (double)FSDEM_MAX_SPEED);
    if (!fsdem__dem_inside_domain(d, x))
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_DOMAIN, "%s: position (%g, %g, %g) m is outside the domain", what,
                           (double)x.x, (double)x.y, (double)x.z);
    return FSDEM_OK;
}

fsdem_dem_particle_desc fsdem_dem_particle_desc_default(void) {
    fsdem_dem_particle_desc p;
    memset(&p, 0, sizeof p);
    return p;
}

/* Keeps 2D state in the plane: z of positions and velocities, x and y of spins. */
static void fsdem__dem_planar(const fsdem_dem *d, fsdem_vec3 *x, fsdem_vec3 *v, fsdem_vec3 *w) {
    if (d->desc.dim != 2) return;
    x->z = 0;
    v->z = 0;
    w->x = w->y = 0;
}

fsdem_result fsdem_dem_add_particle(fsdem_dem *d, const fsdem_dem_particle_desc *p, int *index) {
    fsdem_result res;
    int i;
    fsdem_real volume, inertia_factor, mass, inertia;
    fsdem_vec3 x, v, w;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    i = d->n;
    if (!p) return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_add_particle: desc is NULL");
    if (!(p->radius > 0 && p->radius <= FSDEM_MAX_LENGTH))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_particle_desc.radius must be in (0, %g] m (got %g m)",
                           (double)FSDEM_MAX_LENGTH, (double)p->radius);
    if (p->material < 0 || p->material >= d->material_count)
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_dem_particle_desc.material %d is not a material of this simulation (%d added)",
                           p->material, d->material_count);
    res = fsdem__dem_state_check(d, "fsdem_dem_particle_desc", p->position, p->velocity, p->angular_velocity, p->radius);
    if (res != FSDEM_OK) return res;
    if (d->desc.dim == 2) {
        volume = (fsdem_real)FSDEM__PI * p->radius * p->radius * d->desc.disc_length;
        inertia_factor = (fsdem_real)0.5; /* disc about its axis: m r^2 / 2 */
    } else {
        volume = (fsdem_real)(4.0 / 3.0 * FSDEM__PI) * p->radius * p->radius * p->radius;
        inertia_factor = (fsdem_real)0.4; /* solid sphere: 2 m r^2 / 5 */
    }
    mass = d->materials[p->material].density * volume;
    inertia = inertia_factor * mass * p->radius * p->radius;
    /* a radius of 1e120 overflows the mass (the particle would act as fixed), one of 1e-120 rounds
       it to zero (NaN at the next step): both are refused */
    if (!(mass > 0 && inertia > 0) || !fsdem__finite(inertia) || !fsdem__finite(1 / inertia))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_dem_particle_desc.radius %g m gives mass %g kg and moment of inertia %g kg m^2, "
                           "which are not positive finite numbers",
                           (double)p->radius, (double)mass, (double)inertia);
    if (d->periods.any && (res = fsdem__dem_period_check(d, p->radius)) != FSDEM_OK) return res;
    if (fsdem__dem_reserve_particles(d, d->n + 1) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_dem_add_particle: out of memory adding particle %d", d->n);
    if (p->radius > d->r_max) d->r_max = p->radius; /* the periodic check's; a rebuild sets it anew */
    x = p->position;
    v = p->velocity;
    w = p->angular_velocity;
    fsdem__dem_planar(d, &x, &v, &w);
    d->id[i] = d->next_id++;
    d->material[i] = p->material;
    d->old_of[i] = -1;
    d->fixed[i] = (unsigned char)(p->fixed != 0);
    d->x[i] = x;
    d->v[i] = v;
    d->w[i] = w;
    d->f[i] = d->t[i] = d->fext[i] = d->text[i] = fsdem__zero3();
    d->x_ref[i] = x;
    d->r[i] = p->radius;
    d->m[i] = mass;
    d->inv_m[i] = p->fixed ? 0 : 1 / mass;
    d->inv_i[i] = p->fixed ? 0 : 1 / inertia;
    d->n++;
    d->need_rebuild = 1;
    d->forces_valid = 0;
    if (index) *index = i;
    return fsdem__ok(&d->status);
}

fsdem_result fsdem_dem_remove_particle(fsdem_dem *d, int index) {
    void **ptr[FSDEM__DEM_PARTICLE_ARRAYS];
    size_t size[FSDEM__DEM_PARTICLE_ARRAYS];
    int k;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    if (index < 0 || index >= d->n)
        return fsdem__fail(&d->status, FSDEM_ERR_NOT_FOUND, "fsdem_dem_remove_particle: index %d not in [0, %d)", index,
                           d->n);
    fsdem__dem_particle_arrays(d, ptr, size);
    for (k = 0; k < FSDEM__DEM_PARTICLE_ARRAYS; ++k) {
        char *base = (char *)*ptr[k];
        memmove(base + size[k] * (size_t)index, base + size[k] * (size_t)(index + 1),
                size[k] * (size_t)(d->n - index - 1));
    }
    d->n--;
    d->need_rebuild = 1; /* old_of moved with the rows, so the history carries over */
    d->forces_valid = 0;
    return fsdem__ok(&d->status);
}

fsdem_result fsdem_dem_set_particle_state(fsdem_dem *d, int index, fsdem_vec3 x, fsdem_vec3 v, fsdem_vec3 w) {
    fsdem_result res;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    if (index < 0 || index >= d->n)
        return fsdem__fail(&d->status, FSDEM_ERR_NOT_FOUND, "fsdem_dem_set_particle_state: index %d not in [0, %d)",
                           index, d->n);
    res = fsdem__dem_state_check(d, "fsdem_dem_set_particle_state", x, v, w, d->r[index]);
    if (res != FSDEM_OK) return res;
    fsdem__dem_planar(d, &x, &v, &w);
    d->x[index] = x;
    d->v[index] = v;
    d->w[index] = w;
    d->need_rebuild = 1;
    d->forces_valid = 0;
    return fsdem__ok(&d->status);
}

fsdem_dem_particles fsdem_dem_get_particles(const fsdem_dem *d) {
    fsdem_dem_particles p;
    memset(&p, 0, sizeof p);
    if (!d) return p;
    p.count = d->n;
    p.dim = d->desc.dim;
    p.id = d->id;
    p.position = d->x;
    p.velocity = d->v;
    p.angular_velocity = d->w;
    p.force = d->f;
    p.torque = d->t;
    p.external_force = d->fext;
    p.external_torque = d->text;
    p.radius = d->r;
    p.mass = d->m;
    p.material = d->material;
    p.fixed = d->fixed;
    return p;
}

fsdem_claims *fsdem_dem_claims(fsdem_dem *d) { return d ? &d->claims : NULL; }

fsdem_dem_coupling fsdem_dem_get_coupling(fsdem_dem *d) {
    fsdem_dem_coupling e;
    memset(&e, 0, sizeof e);
    if (!d) return e;
    e.count = d->n;
    e.force = d->fext;
    e.torque = d->text;
    d->external = 1; /* the caller may write them from now on */
    return e;
}
