/* ---- >>dem_desc : defaults and validation ---- */

fsdem_dem_material fsdem_dem_material_default(void) {
    fsdem_dem_material m;
    m.density = 2500;
    m.young_modulus = 1e8;
    m.poisson_ratio = (fsdem_real)0.3;
    m.restitution = (fsdem_real)0.5;
    m.friction = (fsdem_real)0.3;
    m.rolling_friction = 0;
    m.damping_alpha = (fsdem_real)0.4;
    m.cohesion = 0;
    return m;
}

fsdem_dem_desc fsdem_dem_desc_default(int dim) {
    fsdem_dem_desc d;
    memset(&d, 0, sizeof d);
    d.dim = dim;
    d.domain_min = fsdem_v3(-1, -1, -1);
    d.domain_max = fsdem_v3(1, 1, 1);
    d.gravity = dim == 2 ? fsdem_v3(0, (fsdem_real)-9.81, 0) : fsdem_v3(0, 0, (fsdem_real)-9.81);
    d.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
    d.integrator = FSDEM_DEM_INTEGRATOR_VERLET;
    d.dt = (fsdem_real)1e-5;
    d.dt_rule = FSDEM_DEM_DT_RULE_AUTO;
    d.dt_param = 0;
    d.skin = -1;
    d.contact_offset = 0;
    d.linear_theta = (fsdem_real)0.01;
    d.linear_dx = 0;
    d.linear_accel = 0;
    d.disc_length = 1;
    d.rotation = 1;
    d.tangential_damping = 1;
    d.tangential_history = FSDEM_DEM_TANGENTIAL_HISTORY_INCREMENTAL;
    d.coulomb_limit = FSDEM_DEM_COULOMB_LIMIT_TOTAL;
    d.linear_stiffness = FSDEM_DEM_LINEAR_STIFFNESS_SEED000;
    d.capacity = 1024;
    return d;
}

/* The linear law with the stiffness of seed 000 Eq. 10 (theta, dx, ||g||). */
static int fsdem__dem_seed000_stiffness(const fsdem_dem_desc *d) {
    return d->law == FSDEM_DEM_LAW_LINEAR && d->linear_stiffness == FSDEM_DEM_LINEAR_STIFFNESS_SEED000;
}

fsdem_result fsdem_dem_desc_check(const fsdem_dem_desc *d, char *msg, size_t size) {
    int axis;
    if (!d) return fsdem__reject(msg, size, "fsdem_dem_desc is NULL");
    if (d->dim != 2 && d->dim != 3)
        return fsdem__reject(msg, size, "fsdem_dem_desc.dim must be 2 or 3 (got %d)", d->dim);
    if (!fsdem__finite3(d->domain_min) || !fsdem__finite3(d->domain_max))
        return fsdem__reject(msg, size, "fsdem_dem_desc.domain_min/domain_max must be finite");
    for (axis = 0; axis < d->dim; ++axis)
        if (!(fsdem__comp(d->domain_max, axis) > fsdem__comp(d->domain_min, axis)) ||
            !fsdem__finite(fsdem__comp(d->domain_max, axis) - fsdem__comp(d->domain_min, axis)))
            return fsdem__reject(msg, size, "fsdem_dem_desc.domain_max must exceed domain_min by a finite extent on axis %d",
                                 axis);
    if (fsdem__check_gravity("fsdem_dem_desc", d->gravity, d->dim, msg, size) != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    if (d->law != FSDEM_DEM_LAW_LINEAR && d->law != FSDEM_DEM_LAW_HERTZ_MINDLIN && d->law != FSDEM_DEM_LAW_GIC)
        return fsdem__reject(msg, size, "fsdem_dem_desc.law is not a fsdem_dem_law (%d)", (int)d->law);
    if (d->integrator != FSDEM_DEM_INTEGRATOR_VERLET && d->integrator != FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR)
        return fsdem__reject(msg, size, "fsdem_dem_desc.integrator is not a fsdem_dem_integrator (%d)",
                             (int)d->integrator);
    if (!(d->dt > 0) || !fsdem__finite(d->dt))
        return fsdem__reject(msg, size, "fsdem_dem_desc.dt must be > 0 and finite (got %g s)", (double)d->dt);
    if ((int)d->dt_rule < (int)FSDEM_DEM_DT_RULE_AUTO || (int)d->dt_rule > (int)FSDEM_DEM_DT_RULE_GIC)
        return fsdem__reject(msg, size, "fsdem_dem_desc.dt_rule is not a fsdem_dem_dt_rule (%d)", (int)d->dt_rule);
    if (!(d->dt_param >= 0) || !fsdem__finite(d->dt_param))
        return fsdem__reject(msg, size, "fsdem_dem_desc.dt_param must be >= 0 (got %g)", (double)d->dt_param);
    if (d->dt_param > 1 && d->dt_rule != FSDEM_DEM_DT_RULE_LINEAR_SEED000 &&
        !(d->dt_rule == FSDEM_DEM_DT_RULE_AUTO && fsdem__dem_seed000_stiffness(d)))
        return fsdem__reject(msg, size, "fsdem_dem_desc.dt_param: a safety fraction must be in (0, 1] (got %g)",
                             (double)d->dt_param);
    if (d->tangential_damping != 0 && d->tangential_damping != 1)
        return fsdem__reject(msg, size, "fsdem_dem_desc.tangential_damping must be 0 or 1 (got %d)", d->tangential_damping);
    if ((int)d->tangential_history < 0 || (int)d->tangential_history > 1)
        return fsdem__reject(msg, size, "fsdem_dem_desc.tangential_history is not a fsdem_dem_tangential_history (%d)",
                             (int)d->tangential_history);
    if ((int)d->coulomb_limit < 0 || (int)d->coulomb_limit > 1)
        return fsdem__reject(msg, size, "fsdem_dem_desc.coulomb_limit is not a fsdem_dem_coulomb_limit (%d)", (int)d->coulomb_limit);
    for (axis = 0; axis < 3; ++axis)
        if (d->periodic[axis] != 0 && (d->periodic[axis] != 1 || axis >= d->dim))
            return fsdem__reject(msg, size, "fsdem_dem_desc.periodic[%d] = %d must be 0 or 1 (0 for z in 2D)", axis, d->periodic[axis]);
    if ((int)d->linear_stiffness < 0 || (int)d->linear_stiffness > 1)
        return fsdem__reject(msg, size, "fsdem_dem_desc.linear_stiffness is not a fsdem_dem_linear_stiffness (%d)",
                             (int)d->linear_stiffness);
    if (d->dt_rule == FSDEM_DEM_DT_RULE_LINEAR_SEED000 && !fsdem__dem_seed000_stiffness(d))
        return fsdem__reject(msg, size,
                             "fsdem_dem_desc.dt_rule FSDEM_DEM_DT_RULE_LINEAR_SEED000 needs the linear law with seed 000's stiffness");
    if (!fsdem__finite(d->skin)) return fsdem__reject(msg, size, "fsdem_dem_desc.skin is not finite");
    if (!(d->contact_offset >= 0) || !fsdem__finite(d->contact_offset))
        return fsdem__reject(msg, size, "fsdem_dem_desc.contact_offset must be >= 0 (got %g m)",
                             (double)d->contact_offset);
    if (!(d->disc_length > 0) || !fsdem__finite(d->disc_length))
        return fsdem__reject(msg, size, "fsdem_dem_desc.disc_length must be > 0 (got %g m)", (double)d->disc_length);
    if (d->capacity < 0) return fsdem__reject(msg, size, "fsdem_dem_desc.capacity must be >= 0");
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        return fsdem__reject(msg, size, "fsdem_dem_desc.allocator: set both alloc and free, or neither");
    if (fsdem__dem_seed000_stiffness(d)) {
        fsdem_real accel = d->linear_accel > 0 ? d->linear_accel : fsdem__norm(d->gravity);
        if (!(d->linear_theta > 0) || !fsdem__finite(d->linear_theta))
            return fsdem__reject(msg, size, "fsdem_dem_desc.linear_theta must be > 0 (got %g)", (double)d->linear_theta);
        if (!(d->linear_dx > 0) || !fsdem__finite(d->linear_dx))
            return fsdem__reject(msg, size, "fsdem_dem_desc.linear_dx must be > 0 for the linear law (got %g m)",
                                 (double)d->linear_dx);
        if (!(d->linear_accel >= 0) || !fsdem__finite(d->linear_accel))
            return fsdem__reject(msg, size, "fsdem_dem_desc.linear_accel must be >= 0 (got %g)", (double)d->linear_accel);
        if (!(accel > 0))
            return fsdem__reject(msg, size, "fsdem_dem_desc: the linear law needs ||g|| > 0 in seed 000 Eq. 10: set "
                                            "fsdem_dem_desc.linear_accel when gravity is zero");
    }
    return FSDEM_OK;
}

static fsdem_result fsdem__dem_material_check(const fsdem_dem_material *m, char *msg, size_t size) {
    if (!m) return fsdem__reject(msg, size, "fsdem_dem_material is NULL");
    if (!(m->density > 0) || !fsdem__finite(m->density))
        return fsdem__reject(msg, size, "fsdem_dem_material.density must be > 0 (got %g kg/m^3)", (double)m->density);
    /* a rigid wall is a stiff finite material: two infinite moduli would meet in a NaN */
    if (!(m->young_modulus > 0 && m->young_modulus <= FSDEM_MAX_MODULUS))
        return fsdem__reject(msg, size, "fsdem_dem_material.young_modulus must be in (0, %g] Pa (got %g Pa)",
                             (double)FSDEM_MAX_MODULUS, (double)m->young_modulus);
    if (!(m->poisson_ratio > -1 && m->poisson_ratio <= (fsdem_real)0.5))
        return fsdem__reject(msg, size, "fsdem_dem_material.poisson_ratio must be in (-1, 0.5] (got %g)",
                             (double)m->poisson_ratio);
    if (!(m->restitution >= (fsdem_real)1e-6 && m->restitution <= 1))
        return fsdem__reject(msg, size, "fsdem_dem_material.restitution must be in [1e-6, 1] (got %g)", (double)m->restitution);
    if (!(m->friction >= 0) || !fsdem__finite(m->friction))
        return fsdem__reject(msg, size, "fsdem_dem_material.friction must be >= 0 (got %g)", (double)m->friction);
    if (!(m->rolling_friction >= 0) || !fsdem__finite(m->rolling_friction))
        return fsdem__reject(msg, size, "fsdem_dem_material.rolling_friction must be >= 0 (got %g)",
                             (double)m->rolling_friction);
    if (!(m->damping_alpha >= 0) || !fsdem__finite(m->damping_alpha))
        return fsdem__reject(msg, size, "fsdem_dem_material.damping_alpha must be >= 0 (got %g)", (double)m->damping_alpha);
    if (!(m->cohesion >= 0) || !fsdem__finite(m->cohesion))
        return fsdem__reject(msg, size, "fsdem_dem_material.cohesion must be >= 0 (got %g J/m^3)", (double)m->cohesion);
    return FSDEM_OK;
}

static const char *fsdem__dem_rule_name(fsdem_dem_dt_rule rule) {
    switch (rule) {
    case FSDEM_DEM_DT_RULE_LINEAR_SEED000: return "seed 000 Eq. 18";
    case FSDEM_DEM_DT_RULE_RAYLEIGH: return "Rayleigh time, seed 002 Eq. 38";
    case FSDEM_DEM_DT_RULE_GIC: return "seed 004 Eq. 32";
    default: return "?";
    }
}

/* The stable dt of the current particles by the resolved rule (+inf without particles). */
static fsdem_real fsdem__dem_rule_dt(const fsdem_dem *d) {
    fsdem_real best = (fsdem_real)HUGE_VAL;
    const fsdem_real param = d->desc.dt_param;
    int i;
    switch (d->desc.dt_rule) {
    case FSDEM_DEM_DT_RULE_LINEAR_SEED000:
        /* Eq. 18 with Eq. 10: m_ij / k = theta dx / ||g|| whatever the masses */
        return d->n ? (fsdem_real)(2 * FSDEM__PI) / param / (fsdem_real)sqrt(d->k0_linear) : best;
    case FSDEM_DEM_DT_RULE_RAYLEIGH:
        /* seed 002 Eq. 38 prints 0.01631; the Rayleigh-wave fit it cites (Thornton & Randall 1988)
           is 0.1631 nu + 0.8766, which we use. */
        for (i = 0; i < d->n; ++i) {
            const fsdem_dem_material *m = &d->materials[d->material[i]];
            fsdem_real t = (fsdem_real)FSDEM__PI * d->r[i] *
                           (fsdem_real)sqrt(2 * m->density * (1 + m->poisson_ratio) / m->young_modulus) /
                           ((fsdem_real)0.1631 * m->poisson_ratio + (fsdem_real)0.8766);
            if (t < best) best = t;
        }
        return best * param;
    default:
        for (i = 0; i < d->n; ++i) {
            fsdem_real kn = d->materials[d->material[i]].young_modulus * d->r[i]; /* Eq. 32: k_n = E r */
            fsdem_real t = (fsdem_real)0.5 * (fsdem_real)sqrt(d->m[i] / kn);
            if (t < best) best = t;
        }
        return best * param;
    }
}

/* Refreshes stable_dt (at rebuilds and dt changes) and logs a warning once per change when dt
   exceeds it, as LIGGGHTS' fix check/timestep/gran does: such a run loses energy conservation
   long before a particle leaves the domain. */
static void fsdem__dem_dt_check(fsdem_dem *d) {
    /* no particles: no estimate (and no arithmetic on its infinity, which raises FE_INVALID) */
    const fsdem_real stable = d->n > 0 ? fsdem__dem_rule_dt(d) : 0;
    if (stable != d->stable_dt) d->dt_warned = 0;
    d->stable_dt = stable;
    if (stable > 0 && d->dt > stable && !d->dt_warned && d->status.log) {
        char msg[FSDEM__MESSAGE_SIZE];
        snprintf(msg, sizeof msg, "fsdem_dem: dt = %g s is %.3g times the stable dt %g s (%s)", (double)d->dt,
                 (double)(d->dt / stable), (double)stable, fsdem__dem_rule_name(d->desc.dt_rule));
        d->status.log(d->status.log_user, FSDEM_LOG_LEVEL_WARNING, msg);
        d->dt_warned = 1;
    }
}
