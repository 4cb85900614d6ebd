/* ---- >>mps_desc : defaults, validation, lattice constants, creation ---- */

/* Support of the explicit scheme's gradient and divergence, in r0 (see >>mps_explicit). */
#define FSDEM__MPS_EXPLICIT_SUPPORT 2.8f

/* The interaction radius a desc asks for: desc.re, or by default 4.1 r0 for the seed's scheme
   (seed 002 §2.1) and the support of the explicit scheme's weight, 2.8 r0 (a smaller neighbourhood
   is cheaper, and still water is quieter with it: 0.030 r0 at 0.5 s against 0.053 r0 at 4.1 r0). */
static fsdem_real fsdem__mps_default_re(const fsdem_mps_desc *d) {
    if (d->re > 0) return d->re;
    return (d->scheme == FSDEM_MPS_SCHEME_EXPLICIT ? FSDEM__MPS_EXPLICIT_SUPPORT : (fsdem_real)4.1) * d->r0;
}

fsdem_mps_desc fsdem_mps_desc_default(int dim) { return fsdem_mps_desc_default_scheme(dim, FSDEM_MPS_SCHEME_EXPLICIT); }

fsdem_mps_desc fsdem_mps_desc_default_scheme(int dim, fsdem_mps_scheme scheme) {
    fsdem_mps_desc d;
    memset(&d, 0, sizeof d);
    d.dim = dim;
    d.scheme = scheme;
    d.r0 = (fsdem_real)0.01;
    d.re = 0;
    d.density = 1000;
    d.viscosity = (fsdem_real)1e-6;
    d.gravity = dim == 3 ? fsdem_v3(0, 0, (fsdem_real)-9.81) : fsdem_v3(0, (fsdem_real)-9.81, 0);
    d.gamma = (fsdem_real)0.01;
    d.beta = (fsdem_real)0.8;
    d.alpha = (fsdem_real)0.9;
    d.cfl = 0;
    d.density_diffusion = (fsdem_real)0.1;
    d.dt_max = (fsdem_real)1e-3;
    d.domain_min = fsdem_v3(0, 0, 0);
    d.domain_max = fsdem_v3(1, 1, 1);
    d.gradient = FSDEM_MPS_GRADIENT_MODEL_MIN;
    d.wall_viscosity = FSDEM_MPS_WALL_VISCOSITY_NO_SLIP;
    /* The explicit scheme's density is its particles' volume: clamped, the particles of a stretched
       surface lost density with nothing to bring it back, and the Martin & Moyce column's volume
       (sum m / rho_i) grew 5.7 % by 0.575 s (+0.22 % unclamped, the release of the hydrostatic
       start's compression; still water the same either way). The seed's scheme needs the clamp:
       without it its still water blew up (7.6 r0 at 0.5 s). */
    d.clamp_negative_pressure = scheme != FSDEM_MPS_SCHEME_EXPLICIT;
    d.collision_distance = (fsdem_real)0.8;
    d.restitution = (fsdem_real)0.2;
    d.shifting = 0;
    d.pressure_precond = FSDEM_PRECOND_AUTO;
#ifdef FSDEM_USE_FLOAT
    d.pressure_tolerance = (fsdem_real)1e-5;
#else
    d.pressure_tolerance = (fsdem_real)1e-8;
#endif
    d.pressure_max_iterations = 1000;
    return d;
}

/* Validation shared by fsdem_mps_desc_check and fsdem_mps_create; names the field. */
static fsdem_result fsdem__mps_check(const fsdem_mps_desc *d, char *msg, size_t size) {
    int a;
    if (msg && size) msg[0] = '\0';
    if (d->dim != 2 && d->dim != 3) return fsdem__reject(msg, size, "fsdem_mps_desc.dim = %d must be 2 or 3", d->dim);
    if ((int)d->scheme < 0 || (int)d->scheme > 1)
        return fsdem__reject(msg, size, "fsdem_mps_desc.scheme = %d is not a fsdem_mps_scheme", (int)d->scheme);
    if (!(d->sound_speed >= 0) || !fsdem__finite(d->sound_speed))
        return fsdem__reject(msg, size, "fsdem_mps_desc.sound_speed = %g m/s must be >= 0 and finite (0: from the liquid's height)",
                             (double)d->sound_speed);
    if (!(d->density_diffusion >= 0 && d->density_diffusion <= 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.density_diffusion = %g must be in [0, 1]", (double)d->density_diffusion);
    if (!(d->r0 > 0) || !fsdem__finite(d->r0))
        return fsdem__reject(msg, size, "fsdem_mps_desc.r0 = %g m must be > 0 and finite", (double)d->r0);
    if (d->re != 0 && (!(d->re >= 2 * d->r0) || !fsdem__finite(d->re)))
        return fsdem__reject(msg, size, "fsdem_mps_desc.re = %g m must be 0 (the scheme's default) or >= 2 r0 = %g m", (double)d->re,
                             (double)(2 * d->r0));
    if (d->scheme == FSDEM_MPS_SCHEME_EXPLICIT && d->re != 0 && d->re < FSDEM__MPS_EXPLICIT_SUPPORT * d->r0)
        return fsdem__reject(msg, size, "fsdem_mps_desc.re = %g m must be >= %g r0 = %g m for the explicit scheme (the support of its "
                             "gradient)", (double)d->re, (double)FSDEM__MPS_EXPLICIT_SUPPORT, (double)(FSDEM__MPS_EXPLICIT_SUPPORT * d->r0));
    if (d->re > 20 * d->r0)
        return fsdem__reject(msg, size, "fsdem_mps_desc.re = %g m must be <= 20 r0 = %g m", (double)d->re,
                             (double)(20 * d->r0));
    if (d->re_laplacian != 0 && !(d->re_laplacian >= (fsdem_real)1.5 * d->r0 &&
                                  d->re_laplacian <= fsdem__mps_default_re(d) * (1 + (fsdem_real)1e-6)))
        return fsdem__reject(msg, size, "fsdem_mps_desc.re_laplacian = %g m must be 0 (re) or in [1.5 r0, re] = [%g, %g] m",
                             (double)d->re_laplacian, (double)(1.5 * d->r0), (double)fsdem__mps_default_re(d));
    if (!(d->density > 0) || !fsdem__finite(d->density))
        return fsdem__reject(msg, size, "fsdem_mps_desc.density = %g kg/m^3 must be > 0", (double)d->density);
    if (!(d->viscosity >= 0) || !fsdem__finite(d->viscosity))
        return fsdem__reject(msg, size, "fsdem_mps_desc.viscosity = %g m^2/s must be >= 0", (double)d->viscosity);
    if (fsdem__check_gravity("fsdem_mps_desc", d->gravity, d->dim, msg, size) != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    if (!(d->gamma >= 0 && d->gamma <= 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.gamma = %g must be in [0, 1]", (double)d->gamma);
    if (!(d->beta > 0 && d->beta < 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.beta = %g must be in (0, 1)", (double)d->beta);
    if (!(d->alpha > 0) || !fsdem__finite(d->alpha))
        return fsdem__reject(msg, size, "fsdem_mps_desc.alpha = %g must be > 0", (double)d->alpha);
    if (!(d->cfl >= 0 && d->cfl <= 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.cfl = %g must be 0 (the scheme's default) or in (0, 1]", (double)d->cfl);
    if (fsdem__check_dt_max("fsdem_mps_desc", d->dt_max, d->gravity, msg, size) != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    if (!fsdem__finite3(d->domain_min) || !fsdem__finite3(d->domain_max))
        return fsdem__reject(msg, size, "fsdem_mps_desc.domain_min/domain_max must be finite");
    for (a = 0; a < d->dim; ++a) {
        if (!(fsdem__comp(d->domain_max, a) > fsdem__comp(d->domain_min, a)))
            return fsdem__reject(msg, size, "fsdem_mps_desc.domain_max.%c = %g must exceed domain_min.%c = %g", "xyz"[a],
                                 (double)fsdem__comp(d->domain_max, a), "xyz"[a], (double)fsdem__comp(d->domain_min, a));
        if (!(d->r0 <= fsdem__comp(d->domain_max, a) - fsdem__comp(d->domain_min, a)))
            return fsdem__reject(msg, size, "fsdem_mps_desc.r0 = %g m is larger than the domain along %c (%g m)", (double)d->r0,
                                 "xyz"[a], (double)(fsdem__comp(d->domain_max, a) - fsdem__comp(d->domain_min, a)));
    }
    for (a = 0; a < 3; ++a) {
        const double period = (double)(fsdem__comp(d->domain_max, a) - fsdem__comp(d->domain_min, a)), spacings = period / (double)d->r0;
        const double re = (double)fsdem__mps_default_re(d);
        if (d->periodic[a] == 0) continue;
        if (d->periodic[a] != 1 || a >= d->dim)
            return fsdem__reject(msg, size, "fsdem_mps_desc.periodic[%d] = %d must be 0 or 1 (0 for z in 2D)", a, d->periodic[a]);
        if (fabs(spacings - floor(spacings + 0.5)) > 1e-6 * spacings)
            return fsdem__reject(msg, size, "fsdem_mps_desc.periodic[%d]: the period %g m is %g spacings r0; it must be a whole number "
                                 "of them, or lattice fills leave a seam", a, period, spacings);
        if (!(period > 2 * re))
            return fsdem__reject(msg, size, "fsdem_mps_desc.periodic[%d]: the period %g m must exceed 2 re = %g m (one image of a "
                                 "particle within reach)", a, period, 2 * re);
    }
    if ((int)d->gradient < 0 || (int)d->gradient > 2)
        return fsdem__reject(msg, size, "fsdem_mps_desc.gradient = %d is not a fsdem_mps_gradient_model", (int)d->gradient);
    if ((int)d->wall_viscosity < 0 || (int)d->wall_viscosity > 1)
        return fsdem__reject(msg, size, "fsdem_mps_desc.wall_viscosity = %d is not a fsdem_mps_wall_viscosity", (int)d->wall_viscosity);
    if ((int)d->model < 0 || (int)d->model > 1)
        return fsdem__reject(msg, size, "fsdem_mps_desc.model = %d is not a fsdem_mps_model", (int)d->model);
    if (!(d->collision_distance >= 0 && d->collision_distance < 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.collision_distance = %g must be in [0, 1) (units of r0)",
                             (double)d->collision_distance);
    if (!(d->restitution >= 0 && d->restitution <= 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.restitution = %g must be in [0, 1]", (double)d->restitution);
    if (!(d->shifting >= 0 && d->shifting <= 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.shifting = %g must be in [0, 1]", (double)d->shifting);
    if ((int)d->pressure_precond < 0 || (int)d->pressure_precond > 6 || d->pressure_precond == FSDEM_PRECOND_MG)
        return fsdem__reject(msg, size, "fsdem_mps_desc.pressure_precond = %d must be a fsdem_precond for a CSR matrix "
                             "(AUTO, NONE, JACOBI, IC0, MIC0, AMG)", (int)d->pressure_precond);
    if (!(d->pressure_tolerance > 0 && d->pressure_tolerance < 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.pressure_tolerance = %g must be in (0, 1)",
                             (double)d->pressure_tolerance);
    if (d->pressure_max_iterations < 1)
        return fsdem__reject(msg, size, "fsdem_mps_desc.pressure_max_iterations = %d must be >= 1",
                             d->pressure_max_iterations);
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        return fsdem__reject(msg, size, "fsdem_mps_desc.allocator needs both alloc and free, or neither");
    return FSDEM_OK;
}

fsdem_result fsdem_mps_desc_check(const fsdem_mps_desc *desc, char *message, size_t message_size) {
    if (!desc) return fsdem__reject(message, message_size, "fsdem_mps_desc is NULL");
    return fsdem__mps_check(desc, message, message_size);
}

/* n0 (Eq. 7), lambda (Eq. 11) of a particle inside the full r0 lattice, and |F| (Eq. 15) of a
   particle on its flat free surface (the lattice points at or below it along the last axis): the
   reference values of the PPE source, the Laplacian and the surface test (Eq. 14-16); and n0 of the
   explicit scheme's weight. */
static void fsdem__mps_lattice(fsdem_mps *s) {
    const int m = (int)ceil((double)(s->re / s->r0)), kz = s->dim == 3 ? m : 0;
    double n0 = 0, nl = 0, l = 0, f = 0, nx = 0;
    int i, j, k;
    for (k = -kz; k <= kz; ++k)
        for (j = -m; j <= m; ++j)
            for (i = -m; i <= m; ++i) {
                const fsdem_real r = s->r0 * (fsdem_real)sqrt((double)(i * i + j * j + k * k));
                const fsdem_real w = fsdem__kernel_mps(r, s->re);
                const fsdem_real wl = r < s->re_lap ? fsdem__kernel_mps(r, s->re_lap) : 0;
                const int up = s->dim == 3 ? k : j;
                if (i == 0 && j == 0 && k == 0) continue;
                n0 += w;
                nx += fsdem__kernel_mps_explicit(r, s->re_x);
                nl += wl;
                l += wl * r * r;
                if (up <= 0) f += w * (double)up * s->r0 / r;
            }
    s->n0 = (fsdem_real)n0;
    s->n0_x = (fsdem_real)nx;
    s->n0_lap = (fsdem_real)nl;
    s->lambda = (fsdem_real)(l / nl);
    s->f0 = (fsdem_real)(fabs(f) * s->dim / n0);
}

fsdem_result fsdem_mps_create(const fsdem_mps_desc *desc, fsdem_mps **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_result r;
    fsdem_mps *s;
    fsdem_pcg_desc pd;
    int a;
    if (out) *out = NULL;
    if (!desc || !out) return FSDEM_ERR_INVALID_ARG;
    r = fsdem__mps_check(desc, msg, sizeof msg);
    s = (fsdem_mps *)fsdem__object_new(r, msg, desc->log, desc->log_user, &desc->allocator, sizeof *s, "fsdem_mps_create", &r);
    if (!s) return r;
    s->desc = *desc;
    s->allocator = desc->allocator;
    s->bytes = sizeof *s;
    s->status.log = desc->log;
    s->status.log_user = desc->log_user;
    fsdem__claims_init(&s->claims, "MPS", fsdem__mps_claimable, 2);
    s->dim = desc->dim;
    s->r0 = desc->r0;
    s->re = fsdem__mps_default_re(desc);
    s->desc.re = s->re;
    /* the Courant number: seed 002's 0.2 (Eq. 37); the explicit scheme's (c0 + u_max) dt / r0 of
       0.35 is SPH's usual 0.25 h / c0 for a kernel of support 2h = 2.8 r0 (still water moved as at
       0.2, to 0.001 r0) */
    if (!(desc->cfl > 0)) s->desc.cfl = desc->scheme == FSDEM_MPS_SCHEME_EXPLICIT ? (fsdem_real)0.35 : (fsdem_real)0.2;
    s->re_lap = desc->re_laplacian > 0 ? desc->re_laplacian : s->re;
    s->desc.re_laplacian = s->re_lap;
    s->re_x = FSDEM__MPS_EXPLICIT_SUPPORT * desc->r0;
    s->layers = (int)ceil((double)(s->re / s->r0) - 1e-9);
    s->periods = fsdem__periods_of(desc->periodic, desc->dim, desc->domain_min, desc->domain_max);
    /* the neighbour rows' skin (>>mps_neighbours): 0.3 r0, rebuilt when a particle has moved
       0.15 r0 (every few steps of a dam break's front, rarely in a slow flow), less where a period
       is short (a pair is seen through one image only while re + skin < L/2) */
    s->skin = (fsdem_real)0.3 * desc->r0;
    for (a = 0; a < desc->dim; ++a)
        if (desc->periodic[a]) {
            const fsdem_real room = (fsdem_real)0.99 * (s->periods.length[a] / 2 - s->re);
            if (room < s->skin) s->skin = room > 0 ? room : 0;
        }
    fsdem__mps_lattice(s);
    pd = fsdem_pcg_desc_default();
    /* AUTO: MIC(0) in 2D, Jacobi in 3D, where the incomplete factorisation of rows of ~280
       neighbours (re = 4.1 r0) costs more than the iterations it saves: bench/mps_dambreak's 3D
       step took 2.54 s with MIC(0) (28 iterations) and 1.33 s with Jacobi (53); in 2D 0.062 and
       0.070 s */
    pd.preconditioner = desc->pressure_precond != FSDEM_PRECOND_AUTO ? desc->pressure_precond
                        : desc->dim == 3                             ? FSDEM_PRECOND_JACOBI
                                                                     : FSDEM_PRECOND_MIC0;
    pd.tolerance = desc->pressure_tolerance;
    pd.max_iterations = desc->pressure_max_iterations;
    pd.allocator = desc->allocator;
    r = fsdem_pcg_create(&pd, &s->pcg);
    if (r == FSDEM_OK)
        r = fsdem_cellgrid_setup_periodic(&s->grid, &s->allocator, s->dim, desc->domain_min, desc->domain_max, s->re + s->skin, 0,
                                          desc->periodic);
    if (r == FSDEM_OK) {
        s->cell_wall = (int *)fsdem__alloc(&s->allocator, sizeof(int) * (size_t)s->grid.cell_count);
        s->cell_dummy = (int *)fsdem__alloc(&s->allocator, sizeof(int) * (size_t)s->grid.cell_count);
        if (!s->cell_wall || !s->cell_dummy) r = FSDEM_ERR_OUT_OF_MEMORY;
        else s->bytes += 2 * sizeof(int) * (size_t)s->grid.cell_count;
    }
    s->solid_pairs_of = -1;
    if (r != FSDEM_OK) {
        fsdem__log_oom(desc->log, desc->log_user, "fsdem_mps_create", sizeof *s);
        fsdem_mps_destroy(s);
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    *out = s;
    return fsdem__ok(&s->status);
}

/* The particle arrays of a capacity `cap`, with their element sizes (one list for allocation,
   copying and release). */
#define FSDEM__MPS_ARRAYS 22
#define FSDEM__MPS_ROW_ARRAYS 3
static int fsdem__mps_arrays(fsdem_mps *s, void ***ptr, size_t *elem) {
    void **p[FSDEM__MPS_ARRAYS];
    size_t e[FSDEM__MPS_ARRAYS];
    int k = 0;
#define FSDEM__MPS_ARRAY(field)                                                                    \
    do {                                                                                           \
        p[k] = (void **)&s->field;                                                                 \
        e[k++] = sizeof *s->field;                                                                 \
    } while (0)
    FSDEM__MPS_ARRAY(x);
    FSDEM__MPS_ARRAY(v);
    FSDEM__MPS_ARRAY(us);
    FSDEM__MPS_ARRAY(shift);
    FSDEM__MPS_ARRAY(p);
    FSDEM__MPS_ARRAY(eps);
    FSDEM__MPS_ARRAY(nd);
    FSDEM__MPS_ARRAY(rho);
    FSDEM__MPS_ARRAY(fext);
    FSDEM__MPS_ARRAY(gradp);
    FSDEM__MPS_ARRAY(div);
    FSDEM__MPS_ARRAY(kind);
    FSDEM__MPS_ARRAY(surf);
    FSDEM__MPS_ARRAY(body);
    FSDEM__MPS_ARRAY(unknown);
    FSDEM__MPS_ARRAY(uvisc);
    FSDEM__MPS_ARRAY(ghost_weight);
    FSDEM__MPS_ARRAY(inlet);
    FSDEM__MPS_ARRAY(x_built);
    /* by pressure row, last (FSDEM__MPS_ROW_ARRAYS of them): not moved when particles are removed */
    FSDEM__MPS_ARRAY(b);
    FSDEM__MPS_ARRAY(sol);
    FSDEM__MPS_ARRAY(row_particle);
#undef FSDEM__MPS_ARRAY
    memcpy(ptr, p, sizeof p);
    memcpy(elem, e, sizeof e);
    return k;
}

/* The four arrays of n + 1 row offsets: neighbour rows, their build's column rows and cursors, and
   the matrix rows. */
static int **fsdem__mps_rows(fsdem_mps *s, int which) {
    return which == 0 ? &s->nb_start : which == 1 ? &s->tmp_start : which == 2 ? &s->cursor : &s->a_start;
}

void fsdem_mps_destroy(fsdem_mps *s) {
    void **ptr[FSDEM__MPS_ARRAYS];
    size_t elem[FSDEM__MPS_ARRAYS];
    fsdem_allocator al;
    int a, k;
    if (!s) return;
    k = fsdem__mps_arrays(s, ptr, elem);
    for (a = 0; a < k; ++a) fsdem__free(&s->allocator, *ptr[a], elem[a] * (size_t)s->cap);
    for (a = 0; a < 4; ++a) fsdem__free(&s->allocator, *fsdem__mps_rows(s, a), sizeof(int) * (size_t)(s->cap + 1));
    fsdem__free(&s->allocator, s->pairs, sizeof(int) * (size_t)s->pair_cap);
    fsdem__free(&s->allocator, s->nb, sizeof(int) * (size_t)s->nb_cap);
    fsdem__free(&s->allocator, s->tmp_nb, sizeof(int) * (size_t)s->nb_cap);
    fsdem__free(&s->allocator, s->nbw, sizeof(fsdem_real) * (size_t)s->nb_cap);
    fsdem__free(&s->allocator, s->nbl, sizeof(fsdem_real) * (size_t)s->nb_cap);
    fsdem__free(&s->allocator, s->nbx, sizeof(fsdem_real) * (size_t)s->nb_cap);
    fsdem__free(&s->allocator, s->a_col, sizeof(int) * (size_t)s->a_cap);
    fsdem__free(&s->allocator, s->a_val, sizeof(fsdem_real) * (size_t)s->a_cap);
    fsdem__free(&s->allocator, s->obst, sizeof *s->obst * (size_t)s->obst_cap);
    fsdem__free(&s->allocator, s->inflows, sizeof *s->inflows * (size_t)s->inflow_cap);
    fsdem__free(&s->allocator, s->outflows, sizeof *s->outflows * (size_t)s->outflow_cap);
    fsdem__gauges_free(&s->gauges, &s->allocator);
    fsdem__free(&s->allocator, s->cell_wall, sizeof(int) * (size_t)s->grid.cell_count);
    fsdem__free(&s->allocator, s->cell_dummy, sizeof(int) * (size_t)s->grid.cell_count);
    fsdem__free(&s->allocator, s->solid_pairs, sizeof(int) * (size_t)s->solid_pair_cap);
    fsdem__free(&s->allocator, s->wall_entries, sizeof(int) * (size_t)s->wall_entry_cap);
    fsdem_cellgrid_free(&s->grid);
    if (s->pcg) fsdem_pcg_destroy(s->pcg);
    al = s->allocator;
    fsdem__free(&al, s, sizeof *s);
}

const char *fsdem_mps_last_error(const fsdem_mps *s) { return s ? s->status.message : "fsdem_mps is NULL"; }

fsdem_mps_desc fsdem_mps_get_desc(const fsdem_mps *s) {
    fsdem_mps_desc d;
    if (!s) {
        memset(&d, 0, sizeof d);
        return d;
    }
    return s->desc;
}
