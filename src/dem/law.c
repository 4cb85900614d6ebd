/* ---- >>dem_law : contact laws ---- */

/* Restitution of the dimensionless Hertz contact with Tsuji-form damping,
       x'' = -max(0, x^(3/2) + a x^(1/4) x'),   x(0) = 0, x'(0) = 1,
   which is the contact m d'' = -k d^(3/2) - a sqrt(m k) d^(1/4) d' scaled by t0 = (m/(k v0^0.5))^0.4,
   d0 = v0 t0. The scaling removes m, k and v0, so e depends on a alone (Tsuji et al. 1992), and the
   force is clamped at zero (no adhesion) as it is in the simulation. Integrated with RK4. */
static double fsdem__dem_hertz_restitution(double a) {
    double x = 0, v = 1, h = 4e-3 / (1 + a); /* ~800 steps per contact: e to about 1e-6 */
    int step;
    for (step = 0; step < 100000000; ++step) {
        double k1x, k1v, k2x, k2v, k3x, k3v, k4x, k4v, xs, vs, xn, vn;
#define FSDEM__DEM_HERTZ_ACC(X, V) (-fmax(0.0, fmax(X, 0.0) * sqrt(fmax(X, 0.0)) + a * sqrt(sqrt(fmax(X, 0.0))) * (V)))
        k1x = v;
        k1v = FSDEM__DEM_HERTZ_ACC(x, v);
        xs = x + 0.5 * h * k1x;
        vs = v + 0.5 * h * k1v;
        k2x = vs;
        k2v = FSDEM__DEM_HERTZ_ACC(xs, vs);
        xs = x + 0.5 * h * k2x;
        vs = v + 0.5 * h * k2v;
        k3x = vs;
        k3v = FSDEM__DEM_HERTZ_ACC(xs, vs);
        xs = x + h * k3x;
        vs = v + h * k3v;
        k4x = vs;
        k4v = FSDEM__DEM_HERTZ_ACC(xs, vs);
#undef FSDEM__DEM_HERTZ_ACC
        xn = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
        vn = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
        /* Once the clamped force vanishes on the way out (v < 0) it stays zero (the elastic term
           falls faster than the damping one as x shrinks at constant v): the particle coasts off
           at -vn. Stopping here, not at x = 0, bounds the work for heavy damping, where the
           coasting tail would take ever longer. */
        if (step > 0 && vn < 0 && (xn <= 0 || xn * sqrt(xn) + a * sqrt(sqrt(xn)) * vn <= 0)) return -vn;
        x = xn;
        v = vn;
    }
    return 0;
}

/* Damping coefficient a whose restitution is e (bisection; e decreases monotonically with a): a
   bracket [0, hi <= 1e4] and 40 halvings, each an integration of at most ~1e5 steps (a = 1e4 gives
   e ~ 1e-8), so it takes milliseconds for any e in the accepted range [1e-6, 1]. */
static fsdem_real fsdem__dem_tsuji_coefficient(fsdem_real e) {
    double lo = 0, hi = 1, mid = 0;
    int it;
    if (e >= 1) return 0;
    while (fsdem__dem_hertz_restitution(hi) > e && hi < 1e4) hi *= 2;
    for (it = 0; it < 40; ++it) {
        mid = 0.5 * (lo + hi);
        if (fsdem__dem_hertz_restitution(mid) > e) lo = mid;
        else hi = mid;
    }
    return (fsdem_real)(0.5 * (lo + hi));
}

/* The law's coefficients of a pair from its moduli and its (mixed or set) properties. `known`
   (known_count pairs) are pairs set up before, whose Hertz damping calibration is reused for a
   restitution seen before: it costs a few milliseconds. */
static void fsdem__dem_pair_coefficients(fsdem__dem_pair *p, const fsdem_dem_desc *desc, fsdem_real k0_linear,
                                         const fsdem__dem_pair *known, int known_count) {
    const fsdem_real e = p->restitution;
    int k;
    p->tsuji = 0;
    if (desc->law == FSDEM_DEM_LAW_HERTZ_MINDLIN) {
        for (k = 0; k < known_count && known[k].restitution != e; ++k) {
        }
        p->tsuji = k < known_count ? known[k].tsuji : fsdem__dem_tsuji_coefficient(e);
    }
    if (fsdem__dem_seed000_stiffness(desc)) {
        p->kn = k0_linear;
        p->cn = 2 * p->alpha * (fsdem_real)sqrt(k0_linear);
        p->kt = 1 / (2 * (1 + p->nu));
        p->ct = 1 / (fsdem_real)sqrt(2 * (1 + p->nu));
    } else if (desc->law == FSDEM_DEM_LAW_LINEAR) { /* seed 002 Eq. 21-24 */
        const double ln_e = log((double)e);
        p->kn = (fsdem_real)(4.0 / 3.0) * p->e_star;
        p->cn = (fsdem_real)(-2 * ln_e / sqrt(ln_e * ln_e + FSDEM__PI * FSDEM__PI));
        p->kt = 1 / (2 + p->nu);
        p->ct = (fsdem_real)sqrt(p->kt);
    } else if (desc->law == FSDEM_DEM_LAW_GIC) {
        p->kn = 2 * p->e_pair;
        p->cn = p->ct = 0;
        p->kt = 1 / (2 * (1 + p->nu));
    } else {
        p->kn = (fsdem_real)(4.0 / 3.0) * p->e_star;
        p->cn = p->tsuji * p->tsuji * p->kn;
        p->kt = 8 * p->g_star;
        p->ct = (fsdem_real)sqrt(4 * p->g_star / p->e_star);
    }
    if (!desc->tangential_damping && desc->law != FSDEM_DEM_LAW_GIC) p->ct = 0;
}

/* A pair of materials: moduli, and the means of their contact properties (fsdem_dem_material_pair). */
static void fsdem__dem_pair_setup(fsdem__dem_pair *p, const fsdem_dem_material *a, const fsdem_dem_material *b, const fsdem_dem_desc *desc,
                                  fsdem_real k0_linear, const fsdem__dem_pair *known, int known_count) {
    fsdem_real ea = a->young_modulus, eb = b->young_modulus, na = a->poisson_ratio, nb = b->poisson_ratio;
    const fsdem_real ia = 1 / ea, ib = 1 / eb;
    fsdem_real inv_e = (1 - na * na) * ia + (1 - nb * nb) * ib;
    fsdem_real inv_g = 2 * (2 - na) * (1 + na) * ia + 2 * (2 - nb) * (1 + nb) * ib;
    fsdem_real inv_ep = ia + ib;
    p->e_star = 1 / inv_e;
    p->g_star = 1 / inv_g;
    p->e_pair = 2 / inv_ep;
    p->nu = (na + nb) / 2;
    p->alpha = (a->damping_alpha + b->damping_alpha) / 2;
    p->friction = (a->friction + b->friction) / 2;
    p->rolling = (a->rolling_friction + b->rolling_friction) / 2;
    p->restitution = (a->restitution + b->restitution) / 2;
    p->cohesion = (a->cohesion + b->cohesion) / 2;
    fsdem__dem_pair_coefficients(p, desc, k0_linear, known, known_count);
}

/* Contacts in structure-of-arrays form, up to FSDEM__DEM_BATCH at a time, for the vector kernel below
   (fsdem__dem_compute_forces fills and drains them). A particle pair enters as the bodies' data, which
   the kernel turns into a contact; a wall contact enters as a contact. */
#define FSDEM__DEM_BATCH 32

typedef struct fsdem__dem_batch {
    int count;
    int i[FSDEM__DEM_BATCH];     /* particle */
    int other[FSDEM__DEM_BATCH]; /* partner particle, or wall index */
    int entry[FSDEM__DEM_BATCH]; /* neighbour-list entry (its spring) */
    int pair[FSDEM__DEM_BATCH];  /* material pair */
    /* particle pairs: geometry input */
    fsdem_real dx[3][FSDEM__DEM_BATCH];       /* m, x_i - x_j */
    fsdem_real dv[3][FSDEM__DEM_BATCH];       /* m/s, v_i - v_j */
    fsdem_real wi[3][FSDEM__DEM_BATCH], wj[3][FSDEM__DEM_BATCH]; /* rad/s */
    fsdem_real ri[FSDEM__DEM_BATCH], rj[FSDEM__DEM_BATCH];       /* m */
    fsdem_real inv_mi[FSDEM__DEM_BATCH], inv_mj[FSDEM__DEM_BATCH]; /* 1/kg */
    /* the contact: law input */
    fsdem_real n[3][FSDEM__DEM_BATCH];    /* unit normal from the partner to i */
    fsdem_real delta[FSDEM__DEM_BATCH];   /* m, overlap > 0 */
    fsdem_real vrel[3][FSDEM__DEM_BATCH]; /* m/s, velocity of i's contact point relative to the partner's */
    fsdem_real m_eff[FSDEM__DEM_BATCH];   /* kg, reduced mass (m_i for a wall) */
    fsdem_real m_mean[FSDEM__DEM_BATCH];  /* kg, m_ij = (m_i + m_j)/2 of seed 000 Eq. 10 (m_i for a wall) */
    fsdem_real r_eff[FSDEM__DEM_BATCH];   /* m, R* = r_i r_j/(r_i + r_j) (r_i for a wall) */
    fsdem_real arm_i[FSDEM__DEM_BATCH];   /* m, centre of i to the contact point */
    fsdem_real kn[FSDEM__DEM_BATCH], cn[FSDEM__DEM_BATCH], kt[FSDEM__DEM_BATCH], ct[FSDEM__DEM_BATCH]; /* fsdem__dem_pair */
    fsdem_real mu[FSDEM__DEM_BATCH];      /* -, Coulomb coefficient */
    fsdem_real coh[FSDEM__DEM_BATCH];     /* J/m^3, cohesion energy density */
    fsdem_real spring[3][FSDEM__DEM_BATCH]; /* m, tangential spring: held value in, new value out */
    /* output */
    fsdem_real force[3][FSDEM__DEM_BATCH];    /* N, on i */
    fsdem_real torque_i[3][FSDEM__DEM_BATCH]; /* N m, on i */
    fsdem_real torque_j[3][FSDEM__DEM_BATCH]; /* N m, on the partner particle */
    fsdem_real fn[FSDEM__DEM_BATCH];          /* N, normal force */
} fsdem__dem_batch;

/* Copies contact 0 into the lanes after `count` up to a whole lane, so the kernel sees real data
   there: the pair input for a batch of particle pairs (`pairs`), the contact otherwise, and the
   coefficients unless the batch is `uniform`. */
/* threaded: inside a team as on one thread: the calling thread's batch. */
static void fsdem__dem_batch_pad(fsdem__dem_batch *b, int pairs, int uniform) {
    int c, a;
    for (c = b->count; c % FSDEM__LANES; ++c) {
        for (a = 0; a < 3; ++a) {
            if (pairs) {
                b->dx[a][c] = b->dx[a][0];
                b->dv[a][c] = b->dv[a][0];
                b->wi[a][c] = b->wi[a][0];
                b->wj[a][c] = b->wj[a][0];
            } else {
                b->n[a][c] = b->n[a][0];
                b->vrel[a][c] = b->vrel[a][0];
            }
            b->spring[a][c] = b->spring[a][0];
        }
        if (pairs) {
            b->ri[c] = b->ri[0];
            b->rj[c] = b->rj[0];
            b->inv_mi[c] = b->inv_mi[0];
            b->inv_mj[c] = b->inv_mj[0];
        } else {
            b->delta[c] = b->delta[0];
            b->m_eff[c] = b->m_eff[0];
            b->r_eff[c] = b->r_eff[0];
            b->arm_i[c] = b->arm_i[0];
        }
        b->m_mean[c] = b->m_mean[0]; /* may be unset (laws that do not read it): copied, never used */
        if (!uniform) {
            b->kn[c] = b->kn[0];
            b->cn[c] = b->cn[0];
            b->kt[c] = b->kt[0];
            b->ct[c] = b->ct[0];
            b->mu[c] = b->mu[0];
            b->coh[c] = b->coh[0];
        }
    }
}

#define FSDEM__DEM_LOAD3(v, arr, c)                \
    v##x = fsdem__lane_load(&(arr)[0][c]);     \
    v##y = fsdem__lane_load(&(arr)[1][c]);     \
    v##z = fsdem__lane_load(&(arr)[2][c])
#define FSDEM__DEM_STORE3(arr, c, vx, vy, vz)      \
    fsdem__lane_store(&(arr)[0][c], vx);       \
    fsdem__lane_store(&(arr)[1][c], vy);       \
    fsdem__lane_store(&(arr)[2][c], vz)

/* One lane-wide group of contacts as the law kernels see them: unit normal n (from the partner to
   i), overlap, tangential relative velocity v_t, normal relative speed vn, effective mass and
   radius, the pair coefficients (fsdem__dem_pair) and the Coulomb coefficient. */
typedef struct fsdem__dem_lanes {
    fsdem__lane nx, ny, nz, vx, vy, vz, vn, delta, m_eff, r_eff, kn, cn, kt, ct, mu;
} fsdem__dem_lanes;

/* The contact options of a simulation as the kernels read them (fsdem_dem_desc, >>dem). */
typedef struct fsdem__dem_rules {
    int total_history;      /* FSDEM_DEM_TANGENTIAL_HISTORY_TOTAL */
    int cap_spring;         /* FSDEM_DEM_COULOMB_LIMIT_SPRING */
    int cohesion;           /* some material pair is cohesive: add the attraction k A */
    fsdem_real offset;      /* m, the contact offset: the spheres of the cohesive area are r + offset/2 */
    fsdem_real area_depth;  /* m, 2D: the disc length (the area is the chord times it); 3D: 0 (pi a^2) */
} fsdem__dem_rules;

/* The linear law with seed 002's stiffness, as the kernels are instantiated for it (not public: a
   fsdem_dem_linear_stiffness of FSDEM_DEM_LAW_LINEAR). */
#define FSDEM__DEM_LAW_SEED002 ((fsdem_dem_law)3)

/* Coulomb cap |F_t| <= ft_max on a tangential force (seed 000 Eq. 15, seed 004 Eq. 1b), for the laws
   without a tangential history. */
FSDEM__FORCE_INLINE void fsdem__dem_coulomb_cap(fsdem__lane ft_max, fsdem__lane *tx, fsdem__lane *ty, fsdem__lane *tz) {
    const fsdem__lane one = fsdem__lane_set(1), ft2 = *tx * *tx + *ty * *ty + *tz * *tz;
    const fsdem__mask slide = ft2 > ft_max * ft_max;
    const fsdem__lane scale = fsdem__lane_select(slide, ft_max / fsdem__lane_sqrt(fsdem__lane_select(slide, ft2, one)), one);
    *tx *= scale;
    *ty *= scale;
    *tz *= scale;
}

/* Linear spring-dashpot of seed 000 Eq. 7-13 with m_ij the mean mass `m`: k_n = m_ij ||g|| /
   (theta dx), c_n = 2 alpha sqrt(m_ij k_n), k_t = k_n/(2(1+psi)), c_t = c_n/sqrt(2(1+psi)); the
   tangential spring acts over one DEM step h (Eq. 8); no tension cut-off, as printed. Returns the
   normal force and writes the tangential one. */
FSDEM__FORCE_INLINE fsdem__lane fsdem__dem_law_linear(const fsdem__dem_lanes *k, fsdem__lane m, fsdem_real h, fsdem__lane *tx,
                                                     fsdem__lane *ty, fsdem__lane *tz) {
    const fsdem__lane g = -m * (k->kn * k->kt * h + k->cn * k->ct), fn = m * (k->kn * k->delta - k->cn * k->vn);
    *tx = g * k->vx;
    *ty = g * k->vy;
    *tz = g * k->vz;
    fsdem__dem_coulomb_cap(k->mu * fsdem__lane_max(fn, -fn), tx, ty, tz);
    return fn;
}

/* Granule-In-Cell law of seed 004 Eq. 1a-1c: k_n = E r for equal spheres (here E_pair 2 R*); the
   viscous tangential coefficient is not given in the seed: we take the critical damping of the
   tangential spring k_n/(2(1+nu)) (seed 000 Eq. 12). */
FSDEM__FORCE_INLINE fsdem__lane fsdem__dem_law_gic(const fsdem__dem_lanes *k, fsdem__lane *tx, fsdem__lane *ty, fsdem__lane *tz) {
    const fsdem__lane stiff = k->kn * k->r_eff, g = -2 * fsdem__lane_sqrt(k->m_eff * stiff * k->kt), fn = stiff * k->delta;
    *tx = g * k->vx;
    *ty = g * k->vy;
    *tz = g * k->vz;
    fsdem__dem_coulomb_cap(k->mu * fn, tx, ty, tz);
    return fn;
}

/* The tangential force of a spring with history (Hertz-Mindlin, seed 002's linear law): stiffness
   st, dashpot eta_t, Coulomb's limit ft_max = mu |F_n|; the spring of lane group c of the batch is
   updated in place by the rules of desc.tangential_history and desc.coulomb_limit (>>dem). While
   the contact slides, the spring carries the capped force alone: folding the dashpot term into the
   spring (-(F_t + eta_t v_t)/S_t) would store energy along the slip at first touch, where Hertz's
   eta_t ~ d^(1/4) outgrows mu F_n ~ d^(3/2). */
FSDEM__FORCE_INLINE void fsdem__dem_tangential_spring(const fsdem__dem_lanes *k, fsdem__dem_batch *b, int c, fsdem_real h,
                                                      const fsdem__dem_rules *rules, fsdem__lane st, fsdem__lane eta_t,
                                                      fsdem__lane ft_max, fsdem__lane *tx, fsdem__lane *ty, fsdem__lane *tz) {
    const fsdem__lane one = fsdem__lane_set(1);
    fsdem__lane sx, sy, sz, px, py, pz, sn, scale, ft2, inv;
    fsdem__mask slide;
    FSDEM__DEM_LOAD3(s, b->spring, c);
    if (rules->total_history) {
        /* the total displacement: the increment added in the fixed frame, its tangential part taken */
        sx += k->vx * h;
        sy += k->vy * h;
        sz += k->vz * h;
        sn = sx * k->nx + sy * k->ny + sz * k->nz;
        px = sx - sn * k->nx;
        py = sy - sn * k->ny;
        pz = sz - sn * k->nz;
    } else {
        /* the held spring, turned into the current tangent plane with its length kept; proj2 = 0
           leaves a zero spring, whatever finite scale multiplies it */
        const fsdem__lane len2 = sx * sx + sy * sy + sz * sz;
        fsdem__lane proj2;
        sn = sx * k->nx + sy * k->ny + sz * k->nz;
        sx -= sn * k->nx;
        sy -= sn * k->ny;
        sz -= sn * k->nz;
        proj2 = sx * sx + sy * sy + sz * sz;
        scale = fsdem__lane_sqrt(len2 / fsdem__lane_select(proj2 > 0, proj2, one));
        px = sx = sx * scale + k->vx * h;
        py = sy = sy * scale + k->vy * h;
        pz = sz = sz * scale + k->vz * h;
    }
    if (rules->cap_spring) {
        /* the spring alone within mu |F_n|, the dashpot added after */
        const fsdem__lane fs2 = st * st * (px * px + py * py + pz * pz);
        slide = fs2 > ft_max * ft_max;
        scale = fsdem__lane_select(slide, ft_max / fsdem__lane_sqrt(fsdem__lane_select(slide, fs2, one)), one);
        px *= scale;
        py *= scale;
        pz *= scale;
        *tx = -st * px - eta_t * k->vx;
        *ty = -st * py - eta_t * k->vy;
        *tz = -st * pz - eta_t * k->vz;
        FSDEM__DEM_STORE3(b->spring, c, fsdem__lane_select(slide, px, sx), fsdem__lane_select(slide, py, sy),
                          fsdem__lane_select(slide, pz, sz));
        return;
    }
    *tx = -st * px - eta_t * k->vx;
    *ty = -st * py - eta_t * k->vy;
    *tz = -st * pz - eta_t * k->vz;
    ft2 = *tx * *tx + *ty * *ty + *tz * *tz;
    slide = ft2 > ft_max * ft_max;
    /* sliding: cap at Coulomb, the spring -F_t / S_t; one division gives both 1/|F_t| and 1/S_t */
    ft2 = fsdem__lane_sqrt(fsdem__lane_select(slide, ft2, one)); /* |F_t| where sliding */
    inv = 1 / (ft2 * fsdem__lane_select(slide, st, one));        /* a sliding contact has S_t > 0 */
    scale = fsdem__lane_select(slide, ft_max * st * inv, one);
    *tx *= scale;
    *ty *= scale;
    *tz *= scale;
    inv = -ft2 * inv; /* -1/S_t where sliding */
    FSDEM__DEM_STORE3(b->spring, c, fsdem__lane_select(slide, *tx * inv, sx), fsdem__lane_select(slide, *ty * inv, sy),
                      fsdem__lane_select(slide, *tz * inv, sz));
}

/* Hertz-Mindlin. With s = sqrt(R* d): normal stiffness S_n = 2 E* s, elastic force (2/3) S_n d =
   (4/3) E* s d; tangential stiffness S_t = 8 G* s on the spring (seed 002 Eq. 20, Coulomb sliding).
   Damping eta = a sqrt((2/3) m* S), Tsuji's a sqrt(m* k) d^(1/4) with a calibrated from e
   (fsdem__dem_tsuji_coefficient), so eta_n = sqrt(cn m* s) and eta_t = ct eta_n. The normal force
   never turns attractive. */
FSDEM__FORCE_INLINE fsdem__lane fsdem__dem_law_hertz(const fsdem__dem_lanes *k, fsdem__dem_batch *b, int c, fsdem_real h,
                                                    const fsdem__dem_rules *rules, fsdem__lane *tx, fsdem__lane *ty, fsdem__lane *tz) {
    const fsdem__lane s = fsdem__lane_sqrt(k->r_eff * k->delta);
    const fsdem__lane eta_n = fsdem__lane_sqrt(k->cn * k->m_eff * s);
    const fsdem__lane fn = fsdem__lane_max(k->kn * s * k->delta - eta_n * k->vn, fsdem__lane_set(0));
    fsdem__dem_tangential_spring(k, b, c, h, rules, k->kt * s, k->ct * eta_n, k->mu * fn, tx, ty, tz);
    return fn;
}

/* The linear spring-dashpot of seed 002 Eq. 19-24 (fsdem_dem_linear_stiffness): chi^n = kn sqrt(R*),
   eta^n = cn sqrt(chi^n m*), chi^t = kt chi^n, eta^t = ct eta^n, the spring with history; no
   tension cut-off, as printed, so Coulomb's limit takes |F_n|. */
FSDEM__FORCE_INLINE fsdem__lane fsdem__dem_law_seed002(const fsdem__dem_lanes *k, fsdem__dem_batch *b, int c, fsdem_real h,
                                                      const fsdem__dem_rules *rules, fsdem__lane *tx, fsdem__lane *ty, fsdem__lane *tz) {
    const fsdem__lane chi = k->kn * fsdem__lane_sqrt(k->r_eff);
    const fsdem__lane eta_n = k->cn * fsdem__lane_sqrt(chi * k->m_eff);
    const fsdem__lane fn = chi * k->delta - eta_n * k->vn;
    fsdem__dem_tangential_spring(k, b, c, h, rules, k->kt * chi, k->ct * eta_n, k->mu * fsdem__lane_max(fn, -fn), tx, ty, tz);
    return fn;
}

/* The cohesive attraction k A of the simplified JKR model (fsdem_dem_material.cohesion): A is the
   area of the circle where a sphere of radius r1 meets its partner, pi a^2 with a^2 = h (2 r1 - h),
   h the height of the sphere's cap beyond the circle's plane: for two spheres of radii r1, r2 whose
   centres are d apart, overlapping by delta = r1 + r2 - d, h = delta (d + r2 - r1) / (2 d) (from the
   plane's distance to the first centre, (d^2 + r1^2 - r2^2) / (2 d)); for a plane wall h = delta.
   Written with h, a^2 is well conditioned where the overlap is a small difference of large
   positions. In 2D the area is the chord 2a times the disc length. */
FSDEM__FORCE_INLINE fsdem__lane fsdem__dem_cohesion(fsdem__lane coh, fsdem__lane r1, fsdem__lane h, const fsdem__dem_rules *rules) {
    const fsdem__lane a2 = fsdem__lane_max(h * (2 * r1 - h), fsdem__lane_set(0));
    return coh * (rules->area_depth > 0 ? 2 * fsdem__lane_sqrt(a2) * fsdem__lane_set(rules->area_depth)
                                       : (fsdem_real)FSDEM__PI * a2);
}

/* The contact law on every contact of a batch: force and torques, normal force, new spring (laws
   with history). With `pairs`, the contacts are first made from the particle-pair input: normal,
   overlap (offset `off` included), velocity of the contact point, effective mass and radius, lever
   arms (each body's radius less half the overlap). With `uniform`, every contact has that material
   pair and the batch holds no coefficients. `rules` are the contact options. Written once,
   branch-free, and inlined with a constant `law` and `pairs`. h is the step the spring and seed
   000's one-step tangential spring (Eq. 8) use. The normal force the law gives goes to b->fn
   (rolling resistance and Coulomb's limit take it); cohesion is added to the force after. */
/* threaded: inside a team as on one thread: the calling thread's batch. */
FSDEM__FORCE_INLINE void fsdem__dem_batch_law(fsdem__dem_batch *b, const fsdem_dem_law law, fsdem_real h, const int pairs,
                                          fsdem_real off, const fsdem__dem_pair *uniform, const fsdem__dem_rules *rules) {
    const fsdem__lane one = fsdem__lane_set(1), zero = fsdem__lane_set(0);
    int c;
    for (c = 0; c < b->count; c += FSDEM__LANES) {
        fsdem__dem_lanes k;
        fsdem__lane tx, ty, tz, mx, my, mz, arm_i, arm_j, fn, pull = zero;
        if (pairs) {
            fsdem__lane dxx, dxy, dxz, wix, wiy, wiz, wjx, wjy, wjz, ax, ay, az, dist, q, safe, inv, vx, vy, vz;
            const fsdem__lane ri = fsdem__lane_load(&b->ri[c]), rj = fsdem__lane_load(&b->rj[c]);
            const fsdem__lane inv_m = fsdem__lane_load(&b->inv_mi[c]) + fsdem__lane_load(&b->inv_mj[c]);
            fsdem__mask apart;
            FSDEM__DEM_LOAD3(dx, b->dx, c);
            FSDEM__DEM_LOAD3(v, b->dv, c);
            FSDEM__DEM_LOAD3(wi, b->wi, c);
            FSDEM__DEM_LOAD3(wj, b->wj, c);
            dist = fsdem__lane_sqrt(dxx * dxx + dxy * dxy + dxz * dxz);
            /* 1/dist and 1/q, q = (1/m_i + 1/m_j)(r_i + r_j) > 0, from one division; coincident
               centres (dx = 0) take the normal (1, 0, 0) */
            apart = dist > 0;
            safe = fsdem__lane_select(apart, dist, one);
            q = inv_m * (ri + rj);
            inv = 1 / (safe * q);
            k.nx = fsdem__lane_select(apart, dxx * (q * inv), one);
            k.ny = dxy * (q * inv);
            k.nz = dxz * (q * inv);
            /* >= 0: the pair touched (d^2 < reach^2), but sqrt may round dist up to the reach */
            k.delta = fsdem__lane_max(ri + rj + off - dist, zero);
            arm_i = ri - k.delta * (fsdem_real)0.5;
            arm_j = rj - k.delta * (fsdem_real)0.5;
            /* m* = 1/(1/m_i + 1/m_j) = (r_i + r_j)/q, R* = r_i r_j/(r_i + r_j) = r_i r_j (1/m_i + 1/m_j)/q */
            k.m_eff = (ri + rj) * (safe * inv);
            k.r_eff = ri * rj * inv_m * (safe * inv);
            /* contact-point velocity: v_i - v_j - (w_i l_i + w_j l_j) x n */
            ax = wix * arm_i + wjx * arm_j;
            ay = wiy * arm_i + wjy * arm_j;
            az = wiz * arm_i + wjz * arm_j;
            k.vx = vx - (ay * k.nz - az * k.ny);
            k.vy = vy - (az * k.nx - ax * k.nz);
            k.vz = vz - (ax * k.ny - ay * k.nx);
            fsdem__lane_store(&b->delta[c], k.delta);
            fsdem__lane_store(&b->r_eff[c], k.r_eff);
            if (rules->cohesion) {
                const fsdem__lane r1 = ri + (fsdem_real)0.5 * off, r2 = rj + (fsdem_real)0.5 * off;
                const fsdem__lane coh = uniform ? fsdem__lane_set(uniform->cohesion) : fsdem__lane_load(&b->coh[c]);
                pull = fsdem__dem_cohesion(coh, r1, k.delta * (dist + r2 - r1) / (2 * safe), rules);
            }
        } else {
            FSDEM__DEM_LOAD3(k.n, b->n, c);
            FSDEM__DEM_LOAD3(k.v, b->vrel, c);
            k.delta = fsdem__lane_load(&b->delta[c]);
            k.m_eff = fsdem__lane_load(&b->m_eff[c]);
            k.r_eff = fsdem__lane_load(&b->r_eff[c]);
            arm_i = fsdem__lane_load(&b->arm_i[c]);
            arm_j = zero;
            if (rules->cohesion) {
                const fsdem__lane r1 = k.r_eff + rules->offset;
                const fsdem__lane coh = uniform ? fsdem__lane_set(uniform->cohesion) : fsdem__lane_load(&b->coh[c]);
                pull = fsdem__dem_cohesion(coh, r1, k.delta, rules);
            }
        }
        if (uniform) {
            k.kn = fsdem__lane_set(uniform->kn);
            k.cn = fsdem__lane_set(uniform->cn);
            k.kt = fsdem__lane_set(uniform->kt);
            k.ct = fsdem__lane_set(uniform->ct);
            k.mu = fsdem__lane_set(uniform->friction);
        } else {
            k.kn = fsdem__lane_load(&b->kn[c]);
            k.cn = fsdem__lane_load(&b->cn[c]);
            k.kt = fsdem__lane_load(&b->kt[c]);
            k.ct = fsdem__lane_load(&b->ct[c]);
            k.mu = fsdem__lane_load(&b->mu[c]);
        }
        k.vn = k.vx * k.nx + k.vy * k.ny + k.vz * k.nz;
        k.vx -= k.vn * k.nx; /* tangential relative velocity */
        k.vy -= k.vn * k.ny;
        k.vz -= k.vn * k.nz;
        if (law == FSDEM_DEM_LAW_LINEAR) fn = fsdem__dem_law_linear(&k, fsdem__lane_load(&b->m_mean[c]), h, &tx, &ty, &tz);
        else if (law == FSDEM_DEM_LAW_GIC) fn = fsdem__dem_law_gic(&k, &tx, &ty, &tz);
        else if (law == FSDEM__DEM_LAW_SEED002) fn = fsdem__dem_law_seed002(&k, b, c, h, rules, &tx, &ty, &tz);
        else fn = fsdem__dem_law_hertz(&k, b, c, h, rules, &tx, &ty, &tz);
        fsdem__lane_store(&b->fn[c], fn);
        if (rules->cohesion) fn -= pull;
        FSDEM__DEM_STORE3(b->force, c, tx + fn * k.nx, ty + fn * k.ny, tz + fn * k.nz);
        /* torques: the arms point along -n from i and +n from the partner, torque = arm x F, and
           n x F = n x F_t */
        mx = k.ny * tz - k.nz * ty;
        my = k.nz * tx - k.nx * tz;
        mz = k.nx * ty - k.ny * tx;
        FSDEM__DEM_STORE3(b->torque_i, c, -arm_i * mx, -arm_i * my, -arm_i * mz);
        if (pairs) {
            FSDEM__DEM_STORE3(b->torque_j, c, -arm_j * mx, -arm_j * my, -arm_j * mz);
        }
    }
}

#undef FSDEM__DEM_LOAD3
#undef FSDEM__DEM_STORE3

/* Constant-torque rolling resistance on i: -mu_r R* |F_n| along the relative spin, limited so that
   it cannot reverse the relative spin within one step. */
static fsdem_vec3 fsdem__dem_rolling_torque(fsdem_vec3 w_rel, fsdem_real mu_r, fsdem_real r_eff, fsdem_real fn,
                                        fsdem_real inv_i_sum, fsdem_real h) {
    fsdem_real wlen = fsdem__norm(w_rel), tau = mu_r * r_eff * (fn < 0 ? -fn : fn), cap;
    if (wlen == 0 || tau == 0) return fsdem__zero3();
    cap = inv_i_sum > 0 ? wlen / (h * inv_i_sum) : tau;
    if (tau > cap) tau = cap;
    return fsdem__scale(w_rel, -tau / wlen);
}
