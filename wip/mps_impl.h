/* ===== >>impl_mps : MPS solver ===================================================================== */

/* Contents: the object below; >>mps_desc (defaults, validation, lattice constants, creation),
   >>mps_particles (storage, lattice fills, walls, obstacles), >>mps_neighbours (cell-list search
   into sorted neighbour rows), >>mps_operators (number density, gradient, divergence, Laplacian,
   surface), >>mps_step (predictor, pressure equation, corrector, time stepping), >>mps_views
   (views, statistics). */

struct fsdem_mps {
    fsdem_mps_desc desc;
    fsdem__status status;
    fsdem_allocator allocator;
    size_t bytes;                 /* held, besides the pcg */
    int dim;
    fsdem_real r0, re;
    fsdem_real n0, lambda, f0;    /* lattice constants (>>mps_desc) */
    int layers;                   /* WALL + DUMMY layers of a solid: ceil(re/r0) */
    /* particles, structure of arrays, `cap` allocated */
    int n, cap;
    fsdem_vec3 *x, *v, *us;       /* position, velocity, predicted velocity u* */
    fsdem_vec3 *shift;            /* particle shift of the step (desc.shifting) */
    fsdem_real *p, *eps, *nd;     /* pressure, porosity, number density */
    fsdem_real *div, *b, *sol;    /* divergence of u*, right-hand side and solution (by unknown) */
    unsigned char *kind, *surf;
    int *unknown;                 /* row of each particle in the pressure equation, or -1 */
    int *row_particle;            /* particle of each row */
    int counts[3];                /* particles per kind */
    /* neighbours: rows of every non-DUMMY particle (DUMMY rows are empty), columns ascending */
    fsdem_cellgrid grid;
    int *pairs, pair_cap;         /* 2 per pair found by the cell scan */
    int *nb_start;                /* n + 1 */
    int *tmp_start, *cursor;      /* n + 1 each: rows by column and fill cursors of the build */
    int *nb, *tmp_nb, nb_cap;     /* neighbour indices */
    fsdem_real *nbw, *tmp_w;      /* w_ij (Eq. 6) */
    long long pair_count;
    /* pressure matrix */
    int *a_start, *a_col, a_cap;
    fsdem_real *a_val;
    int rows;
    fsdem_pcg *pcg;
    /* obstacles */
    fsdem_vec3 *obst, *obst_hi;
    int obst_n, obst_cap;
    /* time and statistics */
    double time;
    long long steps, iters_total;
    fsdem_real dt_last, residual;
    int iters, surface_count;
    double sec_total, sec_pressure;
};

/* ---- >>mps_desc : defaults, validation, lattice constants, creation ---- */

fsdem_mps_desc fsdem_mps_desc_default(int dim) {
    fsdem_mps_desc d;
    memset(&d, 0, sizeof d);
    d.dim = dim;
    d.r0 = (fsdem_real)0.01;
    d.re = 0;
    d.density = 1000;
    d.viscosity = (fsdem_real)1e-6;
    d.gravity = dim == 3 ? fsdem_v3(0, 0, (fsdem_real)-9.81) : fsdem_v3(0, (fsdem_real)-9.81, 0);
    d.gamma = (fsdem_real)0.01;
    d.beta = (fsdem_real)0.8;
    d.alpha = (fsdem_real)0.9;
    d.cfl = (fsdem_real)0.2;
    d.dt_max = (fsdem_real)1e-3;
    d.domain_min = fsdem_v3(0, 0, 0);
    d.domain_max = fsdem_v3(1, 1, 1);
    d.gradient = FSDEM_MPS_GRADIENT_SUM;
    d.clamp_negative_pressure = 1;
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
    if (!(d->r0 > 0) || !fsdem__finite(d->r0))
        return fsdem__reject(msg, size, "fsdem_mps_desc.r0 = %g m must be > 0 and finite", (double)d->r0);
    if (d->re != 0 && (!(d->re >= 2 * d->r0) || !fsdem__finite(d->re)))
        return fsdem__reject(msg, size, "fsdem_mps_desc.re = %g m must be 0 (4.1 r0) or >= 2 r0 = %g m", (double)d->re,
                             (double)(2 * d->r0));
    if (d->re > 20 * d->r0)
        return fsdem__reject(msg, size, "fsdem_mps_desc.re = %g m must be <= 20 r0 = %g m", (double)d->re,
                             (double)(20 * d->r0));
    if (!(d->density > 0) || !fsdem__finite(d->density))
        return fsdem__reject(msg, size, "fsdem_mps_desc.density = %g kg/m^3 must be > 0", (double)d->density);
    if (!(d->viscosity >= 0) || !fsdem__finite(d->viscosity))
        return fsdem__reject(msg, size, "fsdem_mps_desc.viscosity = %g m^2/s must be >= 0", (double)d->viscosity);
    if (!fsdem__finite3(d->gravity)) return fsdem__reject(msg, size, "fsdem_mps_desc.gravity must be finite");
    if (!(d->gamma >= 0 && d->gamma <= 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.gamma = %g must be in [0, 1]", (double)d->gamma);
    if (!(d->beta > 0 && d->beta < 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.beta = %g must be in (0, 1)", (double)d->beta);
    if (!(d->alpha > 0) || !fsdem__finite(d->alpha))
        return fsdem__reject(msg, size, "fsdem_mps_desc.alpha = %g must be > 0", (double)d->alpha);
    if (!(d->cfl > 0 && d->cfl <= 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.cfl = %g must be in (0, 1]", (double)d->cfl);
    if (!(d->dt_max > 0) || !fsdem__finite(d->dt_max))
        return fsdem__reject(msg, size, "fsdem_mps_desc.dt_max = %g s must be > 0", (double)d->dt_max);
    if (!fsdem__finite3(d->domain_min) || !fsdem__finite3(d->domain_max))
        return fsdem__reject(msg, size, "fsdem_mps_desc.domain_min/domain_max must be finite");
    for (a = 0; a < d->dim; ++a)
        if (!(fsdem__comp(d->domain_max, a) > fsdem__comp(d->domain_min, a)))
            return fsdem__reject(msg, size, "fsdem_mps_desc.domain_max.%c = %g must exceed domain_min.%c = %g", "xyz"[a],
                                 (double)fsdem__comp(d->domain_max, a), "xyz"[a], (double)fsdem__comp(d->domain_min, a));
    if ((int)d->gradient < 0 || (int)d->gradient > 1)
        return fsdem__reject(msg, size, "fsdem_mps_desc.gradient = %d is not a fsdem_mps_gradient_model", (int)d->gradient);
    if (!(d->shifting >= 0 && d->shifting <= 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.shifting = %g must be in [0, 1]", (double)d->shifting);
    if ((int)d->pressure_precond < 0 || (int)d->pressure_precond > 4)
        return fsdem__reject(msg, size, "fsdem_mps_desc.pressure_precond = %d must be a fsdem_precond for a CSR matrix "
                             "(AUTO, NONE, JACOBI, IC0, MIC0)", (int)d->pressure_precond);
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
   reference values of the PPE source, the Laplacian and the surface test (Eq. 14-16). */
static void fsdem__mps_lattice(fsdem_mps *s) {
    const int m = (int)ceil((double)(s->re / s->r0)), kz = s->dim == 3 ? m : 0;
    double n0 = 0, l = 0, f = 0;
    int i, j, k;
    for (k = -kz; k <= kz; ++k)
        for (j = -m; j <= m; ++j)
            for (i = -m; i <= m; ++i) {
                const fsdem_real r = s->r0 * (fsdem_real)sqrt((double)(i * i + j * j + k * k));
                const fsdem_real w = fsdem__kernel_mps(r, s->re);
                const int up = s->dim == 3 ? k : j;
                if (i == 0 && j == 0 && k == 0) continue;
                n0 += w;
                l += w * r * r;
                if (up <= 0) f += w * (double)up * s->r0 / r;
            }
    s->n0 = (fsdem_real)n0;
    s->lambda = (fsdem_real)(l / n0);
    s->f0 = (fsdem_real)(fabs(f) * s->dim / n0);
}

fsdem_result fsdem_mps_create(const fsdem_mps_desc *desc, fsdem_mps **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_result r;
    fsdem_mps *s;
    fsdem_pcg_desc pd;
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
    s->dim = desc->dim;
    s->r0 = desc->r0;
    s->re = desc->re > 0 ? desc->re : (fsdem_real)4.1 * desc->r0;
    s->desc.re = s->re;
    s->layers = (int)ceil((double)(s->re / s->r0) - 1e-9);
    fsdem__mps_lattice(s);
    pd = fsdem_pcg_desc_default();
    pd.preconditioner = desc->pressure_precond;
    pd.tolerance = desc->pressure_tolerance;
    pd.max_iterations = desc->pressure_max_iterations;
    pd.allocator = desc->allocator;
    r = fsdem_pcg_create(&pd, &s->pcg);
    if (r == FSDEM_OK)
        r = fsdem_cellgrid_setup(&s->grid, &s->allocator, s->dim, desc->domain_min, desc->domain_max, s->re, 0);
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
#define FSDEM__MPS_ARRAYS 14
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
    FSDEM__MPS_ARRAY(div);
    FSDEM__MPS_ARRAY(b);
    FSDEM__MPS_ARRAY(sol);
    FSDEM__MPS_ARRAY(kind);
    FSDEM__MPS_ARRAY(surf);
    FSDEM__MPS_ARRAY(unknown);
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
    fsdem__free(&s->allocator, s->tmp_w, sizeof(fsdem_real) * (size_t)s->nb_cap);
    fsdem__free(&s->allocator, s->a_col, sizeof(int) * (size_t)s->a_cap);
    fsdem__free(&s->allocator, s->a_val, sizeof(fsdem_real) * (size_t)s->a_cap);
    fsdem__free(&s->allocator, s->obst, sizeof(fsdem_vec3) * 2 * (size_t)s->obst_cap);
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

/* ---- >>mps_particles : storage, lattice fills, walls, obstacles ---- */

/* Makes room for `need` particles (all arrays, and the per-particle rows of the neighbour list
   and matrix); nothing changes on failure. */
static fsdem_result fsdem__mps_reserve(fsdem_mps *s, int need) {
    void **ptr[FSDEM__MPS_ARRAYS];
    size_t elem[FSDEM__MPS_ARRAYS];
    void *fresh[FSDEM__MPS_ARRAYS + 4];
    int a, k, cap = s->cap > 0 ? s->cap : 64;
    if (need <= s->cap) return FSDEM_OK;
    while (cap < need) {
        if (cap > (1 << 28)) return FSDEM_ERR_OUT_OF_MEMORY;
        cap *= 2;
    }
    k = fsdem__mps_arrays(s, ptr, elem);
    for (a = 0; a < k; ++a) fresh[a] = fsdem__alloc(&s->allocator, elem[a] * (size_t)cap);
    for (a = 0; a < 4; ++a) fresh[k + a] = fsdem__alloc(&s->allocator, sizeof(int) * (size_t)(cap + 1));
    for (a = 0; a < k + 4; ++a)
        if (!fresh[a]) {
            for (a = 0; a < k + 4; ++a)
                fsdem__free(&s->allocator, fresh[a], a < k ? elem[a] * (size_t)cap : sizeof(int) * (size_t)(cap + 1));
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
    for (a = 0; a < k; ++a) {
        if (s->n) memcpy(fresh[a], *ptr[a], elem[a] * (size_t)s->n);
        fsdem__free(&s->allocator, *ptr[a], elem[a] * (size_t)s->cap);
        *ptr[a] = fresh[a];
        s->bytes += elem[a] * (size_t)(cap - s->cap);
    }
    for (a = 0; a < 4; ++a) {
        int **rows = fsdem__mps_rows(s, a);
        if (s->cap) memcpy(fresh[k + a], *rows, sizeof(int) * (size_t)(s->cap + 1));
        else memset(fresh[k + a], 0, sizeof(int) * (size_t)(cap + 1));
        fsdem__free(&s->allocator, *rows, sizeof(int) * (size_t)(s->cap + 1));
        *rows = (int *)fresh[k + a];
    }
    s->bytes += 4 * sizeof(int) * (size_t)(cap - s->cap);
    s->cap = cap;
    return FSDEM_OK;
}

/* Checks particle j of a list for fsdem_mps_add_particles and its fills (`fn` names the caller). */
static fsdem_result fsdem__mps_check_point(fsdem_mps *s, const char *fn, int j, fsdem_vec3 x, fsdem_vec3 v) {
    int a;
    if (!fsdem__finite3(x) || !fsdem__finite3(v))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: particle %d has a non-finite position or velocity", fn, j);
    for (a = 0; a < s->dim; ++a)
        if (!(fsdem__comp(x, a) >= fsdem__comp(s->desc.domain_min, a) && fsdem__comp(x, a) <= fsdem__comp(s->desc.domain_max, a)))
            return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_DOMAIN, "%s: particle %d at (%g, %g, %g) m is outside the domain", fn,
                               j, (double)x.x, (double)x.y, (double)x.z);
    return FSDEM_OK;
}

/* Appends one particle (room reserved, point checked). */
static void fsdem__mps_push(fsdem_mps *s, fsdem_mps_kind kind, fsdem_vec3 x, fsdem_vec3 v) {
    const int i = s->n++;
    if (s->dim == 2) x.z = v.z = 0;
    s->x[i] = x;
    s->v[i] = kind == FSDEM_MPS_FLUID ? v : fsdem__zero3();
    s->us[i] = s->v[i];
    s->shift[i] = fsdem__zero3();
    s->p[i] = 0;
    s->eps[i] = 1;
    s->nd[i] = 0;
    s->kind[i] = (unsigned char)kind;
    s->surf[i] = 0;
    s->unknown[i] = -1;
    s->counts[kind]++;
}

fsdem_result fsdem_mps_add_particles(fsdem_mps *s, fsdem_mps_kind kind, int count, const fsdem_vec3 *positions,
                                     const fsdem_vec3 *velocities) {
    int j;
    fsdem_result r;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((int)kind < 0 || (int)kind > 2)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_add_particles: kind = %d is not a fsdem_mps_kind", (int)kind);
    if (count < 0 || (count > 0 && !positions))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_add_particles: count = %d and positions %s", count,
                           positions ? "given" : "NULL");
    for (j = 0; j < count; ++j)
        if ((r = fsdem__mps_check_point(s, "fsdem_mps_add_particles", j, positions[j],
                                        velocities ? velocities[j] : fsdem__zero3())) != FSDEM_OK)
            return r;
    if (count > (1 << 29) - s->n || fsdem__mps_reserve(s, s->n + count) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps_add_particles: no memory for %d particles", s->n + count);
    for (j = 0; j < count; ++j) fsdem__mps_push(s, kind, positions[j], velocities ? velocities[j] : fsdem__zero3());
    return fsdem__ok(&s->status);
}

/* What a lattice walk does with a point: the kind to add, or -1 to skip it. */
typedef int (*fsdem__mps_classify_fn)(const fsdem_mps *s, const void *user, fsdem_vec3 p);

/* Walks the lattice lo + (i + 1/2) r0 (i may be negative) over the box [from, to] and adds each
   point `classify` accepts: a first pass counts and checks, a second adds, so the call is all or
   nothing. `fn` names the public caller in messages; *added (may be NULL) counts. */
static fsdem_result fsdem__mps_lattice_fill(fsdem_mps *s, const char *fn, fsdem_vec3 lo, fsdem_vec3 from, fsdem_vec3 to,
                                            fsdem__mps_classify_fn classify, const void *user, fsdem_vec3 velocity,
                                            int *added) {
    int i0[3], i1[3], a, pass, count = 0;
    if (added) *added = 0;
    for (a = 0; a < 3; ++a) {
        const double l = (double)fsdem__comp(lo, a), r0 = (double)s->r0;
        i0[a] = a < s->dim ? (int)ceil(((double)fsdem__comp(from, a) - l) / r0 - 0.5 - 1e-9) : 0;
        i1[a] = a < s->dim ? (int)floor(((double)fsdem__comp(to, a) - l) / r0 - 0.5 + 1e-9) : 0;
        if (a < s->dim && (double)(i1[a] - i0[a]) > 1e7)
            return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "%s: the box holds too many lattice points", fn);
    }
    for (pass = 0; pass < 2; ++pass) {
        int i, j, k, c = 0;
        fsdem_result r;
        if (pass == 1) {
            if (count > (1 << 29) - s->n || fsdem__mps_reserve(s, s->n + count) != FSDEM_OK)
                return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "%s: no memory for %d particles", fn, s->n + count);
        }
        for (k = i0[2]; k <= i1[2]; ++k)
            for (j = i0[1]; j <= i1[1]; ++j)
                for (i = i0[0]; i <= i1[0]; ++i) {
                    fsdem_vec3 p = fsdem_v3(lo.x + ((fsdem_real)i + (fsdem_real)0.5) * s->r0,
                                            lo.y + ((fsdem_real)j + (fsdem_real)0.5) * s->r0,
                                            s->dim == 3 ? lo.z + ((fsdem_real)k + (fsdem_real)0.5) * s->r0 : 0);
                    const int kind = classify(s, user, p);
                    if (kind < 0) continue;
                    if (pass == 0) {
                        if ((r = fsdem__mps_check_point(s, fn, count, p, velocity)) != FSDEM_OK) return r;
                        ++count;
                    } else {
                        fsdem__mps_push(s, (fsdem_mps_kind)kind, p, velocity);
                        ++c;
                    }
                }
    }
    if (added) *added = count;
    return fsdem__ok(&s->status);
}

/* Depth of p outside the box [lo, hi] in lattice layers: 0 inside, k when the largest excursion
   along an axis is within (k - 1, k] spacings. `open` (bits of fsdem_side) marks sides beyond which
   a point is rejected (-1). */
static int fsdem__mps_layer_outside(const fsdem_mps *s, const fsdem_vec3 *box, unsigned open, fsdem_vec3 p) {
    fsdem_real worst = 0;
    int a;
    for (a = 0; a < s->dim; ++a) {
        const fsdem_real x = fsdem__comp(p, a), l = fsdem__comp(box[0], a), h = fsdem__comp(box[1], a);
        const fsdem_real out = x < l ? l - x : x > h ? x - h : 0;
        if (out > 0 && (open & (1u << (2 * a + (x > h))))) return -1;
        if (out > worst) worst = out;
    }
    return worst > 0 ? (int)ceil((double)(worst / s->r0) - 1e-6) : 0;
}

/* Depth of p inside the box in layers: 1 for the outer layer, 0 outside. */
static int fsdem__mps_layer_inside(const fsdem_mps *s, const fsdem_vec3 *box, fsdem_vec3 p) {
    fsdem_real depth = -1;
    int a;
    for (a = 0; a < s->dim; ++a) {
        const fsdem_real x = fsdem__comp(p, a), l = fsdem__comp(box[0], a), h = fsdem__comp(box[1], a);
        const fsdem_real in = x - l < h - x ? x - l : h - x;
        if (!(in > 0)) return 0;
        if (depth < 0 || in < depth) depth = in;
    }
    return (int)ceil((double)(depth / s->r0) - 1e-6);
}

/* Fluid: inside the fill box and outside every obstacle. */
static int fsdem__mps_classify_fluid(const fsdem_mps *s, const void *user, fsdem_vec3 p) {
    int o;
    (void)user;
    for (o = 0; o < s->obst_n; ++o)
        if (fsdem__mps_layer_inside(s, s->obst + 2 * o, p) > 0) return -1;
    return FSDEM_MPS_FLUID;
}

/* Tank walls: the first layer outside the box WALL, the next ones DUMMY. */
typedef struct fsdem__mps_walls {
    fsdem_vec3 box[2];
    unsigned open;
} fsdem__mps_walls;

static int fsdem__mps_classify_walls(const fsdem_mps *s, const void *user, fsdem_vec3 p) {
    const fsdem__mps_walls *w = (const fsdem__mps_walls *)user;
    const int layer = fsdem__mps_layer_outside(s, w->box, w->open, p);
    return layer <= 0 || layer > s->layers ? -1 : layer == 1 ? FSDEM_MPS_WALL : FSDEM_MPS_DUMMY;
}

/* Obstacle: the outer layer inside the box WALL, the next ones DUMMY. */
static int fsdem__mps_classify_obstacle(const fsdem_mps *s, const void *user, fsdem_vec3 p) {
    const int layer = fsdem__mps_layer_inside(s, (const fsdem_vec3 *)user, p);
    return layer <= 0 || layer > s->layers ? -1 : layer == 1 ? FSDEM_MPS_WALL : FSDEM_MPS_DUMMY;
}

/* Checks a box argument of the fills (`fn` names the caller). */
static fsdem_result fsdem__mps_check_box(fsdem_mps *s, const char *fn, fsdem_vec3 lo, fsdem_vec3 hi) {
    int a;
    if (!fsdem__finite3(lo) || !fsdem__finite3(hi))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: the box corners must be finite", fn);
    for (a = 0; a < s->dim; ++a)
        if (!(fsdem__comp(hi, a) - fsdem__comp(lo, a) >= s->r0))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: the box is thinner than r0 = %g m along %c", fn,
                               (double)s->r0, "xyz"[a]);
    return FSDEM_OK;
}

fsdem_result fsdem_mps_fill_box(fsdem_mps *s, fsdem_vec3 lo, fsdem_vec3 hi, fsdem_vec3 velocity, int *added) {
    fsdem_result r;
    if (added) *added = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem__mps_check_box(s, "fsdem_mps_fill_box", lo, hi)) != FSDEM_OK) return r;
    return fsdem__mps_lattice_fill(s, "fsdem_mps_fill_box", lo, lo, hi, fsdem__mps_classify_fluid, NULL, velocity, added);
}

fsdem_result fsdem_mps_add_box_walls(fsdem_mps *s, fsdem_vec3 lo, fsdem_vec3 hi, unsigned open_sides, int *added) {
    fsdem__mps_walls w;
    fsdem_real reach;
    fsdem_result r;
    if (added) *added = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem__mps_check_box(s, "fsdem_mps_add_box_walls", lo, hi)) != FSDEM_OK) return r;
    w.box[0] = lo;
    w.box[1] = hi;
    w.open = open_sides;
    reach = (fsdem_real)s->layers * s->r0;
    return fsdem__mps_lattice_fill(s, "fsdem_mps_add_box_walls", lo, fsdem__sub(lo, fsdem_v3(reach, reach, reach)),
                                   fsdem__add(hi, fsdem_v3(reach, reach, reach)), fsdem__mps_classify_walls, &w,
                                   fsdem__zero3(), added);
}

fsdem_result fsdem_mps_add_box_obstacle(fsdem_mps *s, fsdem_vec3 lo, fsdem_vec3 hi, int *id) {
    fsdem_vec3 box[2];
    fsdem_result r;
    if (id) *id = -1;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem__mps_check_box(s, "fsdem_mps_add_box_obstacle", lo, hi)) != FSDEM_OK) return r;
    if (s->obst_n == s->obst_cap) {
        const int cap = s->obst_cap ? 2 * s->obst_cap : 4;
        fsdem_vec3 *o = (fsdem_vec3 *)fsdem__alloc(&s->allocator, sizeof(fsdem_vec3) * 2 * (size_t)cap);
        if (!o) return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps_add_box_obstacle: out of memory");
        if (s->obst_n) memcpy(o, s->obst, sizeof(fsdem_vec3) * 2 * (size_t)s->obst_n);
        fsdem__free(&s->allocator, s->obst, sizeof(fsdem_vec3) * 2 * (size_t)s->obst_cap);
        s->obst = o;
        s->obst_cap = cap;
    }
    box[0] = lo;
    box[1] = hi;
    r = fsdem__mps_lattice_fill(s, "fsdem_mps_add_box_obstacle", lo, lo, hi, fsdem__mps_classify_obstacle, box,
                                fsdem__zero3(), NULL);
    if (r != FSDEM_OK) return r;
    s->obst[2 * s->obst_n] = lo;
    s->obst[2 * s->obst_n + 1] = hi;
    if (id) *id = s->obst_n;
    s->obst_n++;
    return fsdem__ok(&s->status);
}

/* ---- >>mps_neighbours : cell-list search into sorted neighbour rows ---- */

/* Capacity for `need` entries: the next power-of-two multiple of 1024 (0 when it would overflow). */
static int fsdem__mps_capacity(int have, long long need) {
    long long cap = have > 0 ? have : 1024;
    while (cap < need) cap *= 2;
    return cap > (1LL << 30) ? 0 : (int)cap;
}

/* The neighbours of every FLUID and WALL particle within re at the current positions, as rows of
   ascending particle index with their weights w_ij (Eq. 6); DUMMY particles have empty rows (their
   own sums are never needed) but appear in the others'. Pairs are found once each by the forward
   scan of the cell grid (as the DEM's pair search), put into unsorted rows, then copied column by
   column into the final rows, which leaves each sorted. Allocates only when the lists outgrow every
   earlier one. */
static fsdem_result fsdem__mps_neighbours(fsdem_mps *s) {
    const fsdem_cellgrid *g = &s->grid;
    const fsdem_real re2 = s->re * s->re;
    int c, f, a, b, i, e, count = 0;
    if (fsdem_cellgrid_build(&s->grid, s->x, s->n) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    for (c = 0; c < g->cell_count; ++c) {
        int coord[3], cells[14], nf;
        if (g->cell_start[c] == g->cell_start[c + 1]) continue;
        coord[0] = c % g->n[0];
        coord[1] = c / g->n[0] % g->n[1];
        coord[2] = c / (g->n[0] * g->n[1]);
        nf = fsdem_cellgrid_forward(g, coord, cells);
        for (f = 0; f < nf; ++f) {
            const int b1 = g->cell_start[cells[f] + 1];
            for (a = g->cell_start[c]; a < g->cell_start[c + 1]; ++a) {
                const int pa = g->items[a], b0 = f == 0 ? a + 1 : g->cell_start[cells[f]];
                if (2 * ((long long)count + b1 - b0) > s->pair_cap) {
                    const int cap = fsdem__mps_capacity(s->pair_cap, 2 * ((long long)count + b1 - b0));
                    int *fresh = cap ? (int *)fsdem__alloc(&s->allocator, sizeof(int) * (size_t)cap) : NULL;
                    if (!fresh) return FSDEM_ERR_OUT_OF_MEMORY;
                    if (count) memcpy(fresh, s->pairs, sizeof(int) * 2 * (size_t)count);
                    fsdem__free(&s->allocator, s->pairs, sizeof(int) * (size_t)s->pair_cap);
                    s->bytes += sizeof(int) * (size_t)(cap - s->pair_cap);
                    s->pairs = fresh;
                    s->pair_cap = cap;
                }
                for (b = b0; b < b1; ++b) {
                    const int pb = g->items[b];
                    const fsdem_vec3 d = fsdem__sub(s->x[pa], s->x[pb]);
                    s->pairs[2 * count] = pa;
                    s->pairs[2 * count + 1] = pb;
                    count += fsdem__dot(d, d) < re2 && (s->kind[pa] != FSDEM_MPS_DUMMY || s->kind[pb] != FSDEM_MPS_DUMMY);
                }
            }
        }
    }
    s->pair_count = count;
    /* directed entries (r, c): c in the row of r, for every non-DUMMY r; first bucketed by column c
       (counting sort into tmp_nb/tmp_w, rows r), then scattered by row in column order, which
       leaves every row sorted */
    memset(s->tmp_start, 0, sizeof(int) * (size_t)(s->n + 1));
    memset(s->nb_start, 0, sizeof(int) * (size_t)(s->n + 1));
    for (e = 0; e < count; ++e) {
        const int pa = s->pairs[2 * e], pb = s->pairs[2 * e + 1];
        if (s->kind[pa] != FSDEM_MPS_DUMMY) {
            s->nb_start[pa + 1]++;
            s->tmp_start[pb + 1]++;
        }
        if (s->kind[pb] != FSDEM_MPS_DUMMY) {
            s->nb_start[pb + 1]++;
            s->tmp_start[pa + 1]++;
        }
    }
    for (i = 0; i < s->n; ++i) {
        s->nb_start[i + 1] += s->nb_start[i];
        s->tmp_start[i + 1] += s->tmp_start[i];
    }
    if (s->nb_start[s->n] > s->nb_cap) {
        const int cap = fsdem__mps_capacity(s->nb_cap, s->nb_start[s->n]);
        void **arrays[4];
        size_t elem[4];
        void *fresh[4];
        int k;
        arrays[0] = (void **)&s->nb;
        arrays[1] = (void **)&s->tmp_nb;
        arrays[2] = (void **)&s->nbw;
        arrays[3] = (void **)&s->tmp_w;
        elem[0] = elem[1] = sizeof(int);
        elem[2] = elem[3] = sizeof(fsdem_real);
        if (!cap) return FSDEM_ERR_OUT_OF_MEMORY;
        for (k = 0; k < 4; ++k) fresh[k] = fsdem__alloc(&s->allocator, elem[k] * (size_t)cap);
        if (!fresh[0] || !fresh[1] || !fresh[2] || !fresh[3]) {
            for (k = 0; k < 4; ++k) fsdem__free(&s->allocator, fresh[k], elem[k] * (size_t)cap);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
        for (k = 0; k < 4; ++k) {
            fsdem__free(&s->allocator, *arrays[k], elem[k] * (size_t)s->nb_cap);
            *arrays[k] = fresh[k];
        }
        s->bytes += 2 * (sizeof(int) + sizeof(fsdem_real)) * (size_t)(cap - s->nb_cap);
        s->nb_cap = cap;
    }
    memcpy(s->cursor, s->tmp_start, sizeof(int) * (size_t)s->n);
    for (e = 0; e < count; ++e) {
        const int pa = s->pairs[2 * e], pb = s->pairs[2 * e + 1];
        const fsdem_real w = fsdem__kernel_mps(fsdem__norm(fsdem__sub(s->x[pa], s->x[pb])), s->re);
        if (s->kind[pa] != FSDEM_MPS_DUMMY) {
            s->tmp_nb[s->cursor[pb]] = pa;
            s->tmp_w[s->cursor[pb]++] = w;
        }
        if (s->kind[pb] != FSDEM_MPS_DUMMY) {
            s->tmp_nb[s->cursor[pa]] = pb;
            s->tmp_w[s->cursor[pa]++] = w;
        }
    }
    memcpy(s->cursor, s->nb_start, sizeof(int) * (size_t)s->n);
    for (c = 0; c < s->n; ++c)
        for (e = s->tmp_start[c]; e < s->tmp_start[c + 1]; ++e) {
            const int r = s->tmp_nb[e];
            s->nb[s->cursor[r]] = c;
            s->nbw[s->cursor[r]++] = s->tmp_w[e];
        }
    return FSDEM_OK;
}

/* ---- >>mps_operators : number density, gradient, divergence, Laplacian, surface ---- */

/* Number density n_i (seed 002 Eq. 7, every neighbour, DUMMY included) and the surface flag
   (Eq. 14-16) of every FLUID and WALL particle, from the neighbour rows; returns the number of
   surface particles. A particle is on the surface when n_i < beta n0, or else when the asymmetry
   |F_i| of Eq. 15 exceeds alpha |F0| (|F0|: the flat surface of the lattice, >>mps_desc). */
static int fsdem__mps_density(fsdem_mps *s) {
    const fsdem_real fscale = (fsdem_real)s->dim / s->n0;
    int i, e, surface = 0;
    for (i = 0; i < s->n; ++i) {
        fsdem_real nd = 0;
        fsdem_vec3 F = fsdem__zero3();
        s->nd[i] = 0;
        s->surf[i] = 0;
        if (s->kind[i] == FSDEM_MPS_DUMMY) continue;
        for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
            const int j = s->nb[e];
            const fsdem_real we = s->nbw[e] / s->eps[j];
            const fsdem_vec3 r = fsdem__sub(s->x[j], s->x[i]);
            const fsdem_real len = fsdem__norm(r);
            nd += we;                                           /* seed 002 Eq. 7 */
            if (len > 0) F = fsdem__madd(F, r, we / len);       /* seed 002 Eq. 15 */
        }
        s->nd[i] = nd;
        s->surf[i] = (unsigned char)(nd < s->desc.beta * s->n0 ||                 /* seed 002 Eq. 14 */
                                     fscale * fsdem__norm(F) > s->desc.alpha * s->f0); /* Eq. 16 */
        surface += s->surf[i];
    }
    return surface;
}

/* Gradient of phi at particle i (seed 002 Eq. 8): the sum form (phi_j + phi_i) of the seed, or
   Koshizuka et al. (1998) (phi_j - min phi) with the smallest value of i and its non-DUMMY
   neighbours (desc.gradient). A DUMMY neighbour j takes the ghost value phi_i + ghost.(r_j - r_i):
   the pressure step passes ghost = rho g, the hydrostatic extrapolation from i, so the solid
   behind the wall layer pushes as a full neighbourhood of liquid would (skipping the DUMMY
   particles instead leaves the sum form one-sided and pulls particles into walls); the public
   operator passes 0 (a mirror value, zero normal derivative). */
static fsdem_vec3 fsdem__mps_grad_at(const fsdem_mps *s, const fsdem_real *phi, int i, fsdem_vec3 ghost) {
    fsdem_vec3 g = fsdem__zero3();
    fsdem_real base = phi[i];
    /* a DUMMY particle higher than the hydrostatic extrapolation reaches is in the air beside the
       free surface: its ghost pressure is not below 0, as the liquid's (desc.clamp_negative_pressure);
       a negative ghost pulled the particles at the top of the walls into them */
    const int clamp = s->desc.clamp_negative_pressure && (ghost.x != 0 || ghost.y != 0 || ghost.z != 0);
    int e;
    if (s->desc.gradient == FSDEM_MPS_GRADIENT_MIN)
        for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e)
            if (s->kind[s->nb[e]] != FSDEM_MPS_DUMMY && phi[s->nb[e]] < base) base = phi[s->nb[e]];
    if (s->desc.gradient == FSDEM_MPS_GRADIENT_MIN) base = -base;
    for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
        const int j = s->nb[e];
        const fsdem_vec3 r = fsdem__sub(s->x[j], s->x[i]);
        const fsdem_real r2 = fsdem__dot(r, r);
        fsdem_real pj = phi[j];
        if (s->kind[j] == FSDEM_MPS_DUMMY) {
            pj = phi[i] + fsdem__dot(ghost, r);
            if (pj < 0 && clamp) pj = 0;
        }
        if (!(r2 > 0)) continue;
        g = fsdem__madd(g, r, (pj + base) * s->nbw[e] / (r2 * s->eps[j]));
    }
    return fsdem__scale(g, (fsdem_real)s->dim / s->n0);
}

/* Divergence of u at particle i (seed 002 Eq. 9) over its non-DUMMY neighbours. */
static fsdem_real fsdem__mps_div_at(const fsdem_mps *s, const fsdem_vec3 *u, int i) {
    fsdem_real d = 0;
    int e;
    for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
        const int j = s->nb[e];
        const fsdem_vec3 r = fsdem__sub(s->x[j], s->x[i]);
        const fsdem_real r2 = fsdem__dot(r, r);
        if (s->kind[j] == FSDEM_MPS_DUMMY || !(r2 > 0)) continue;
        d += fsdem__dot(fsdem__sub(u[j], u[i]), r) * s->nbw[e] / (r2 * s->eps[j]);
    }
    return d * (fsdem_real)s->dim / s->n0;
}

/* Laplacian at particle i (seed 002 Eq. 10, lambda of Eq. 11) over its non-DUMMY neighbours, of
   a scalar (phi) or, when phi is NULL, of a vector field u. */
static fsdem_vec3 fsdem__mps_lap_at(const fsdem_mps *s, const fsdem_real *phi, const fsdem_vec3 *u, int i) {
    fsdem_vec3 l = fsdem__zero3();
    int e;
    for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
        const int j = s->nb[e];
        const fsdem_real we = s->nbw[e] / s->eps[j];
        if (s->kind[j] == FSDEM_MPS_DUMMY) continue;
        if (phi) l.x += (phi[j] - phi[i]) * we;
        else l = fsdem__madd(l, fsdem__sub(u[j], u[i]), we);
    }
    return fsdem__scale(l, 2 * (fsdem_real)s->dim / (s->n0 * s->lambda));
}

/* Rebuilds the neighbours and the number density at the current positions for a public operator
   (`fn` names it), checking its arguments. */
static fsdem_result fsdem__mps_operator_setup(fsdem_mps *s, const char *fn, const void *in, const void *out) {
    if (!in || !out) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: NULL field", fn);
    if (s->n > 0 && fsdem__mps_neighbours(s) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory building the neighbour list", fn);
    if (s->n > 0) fsdem__mps_density(s);
    return FSDEM_OK;
}

fsdem_result fsdem_mps_gradient(fsdem_mps *s, const fsdem_real *phi, fsdem_vec3 *out) {
    fsdem_result r;
    int i;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem__mps_operator_setup(s, "fsdem_mps_gradient", phi, out)) != FSDEM_OK) return r;
    for (i = 0; i < s->n; ++i) out[i] = s->kind[i] == FSDEM_MPS_DUMMY ? fsdem__zero3() : fsdem__mps_grad_at(s, phi, i, fsdem__zero3());
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_mps_divergence(fsdem_mps *s, const fsdem_vec3 *field, fsdem_real *out) {
    fsdem_result r;
    int i;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem__mps_operator_setup(s, "fsdem_mps_divergence", field, out)) != FSDEM_OK) return r;
    for (i = 0; i < s->n; ++i) out[i] = s->kind[i] == FSDEM_MPS_DUMMY ? 0 : fsdem__mps_div_at(s, field, i);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_mps_laplacian(fsdem_mps *s, const fsdem_real *phi, fsdem_real *out) {
    fsdem_result r;
    int i;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem__mps_operator_setup(s, "fsdem_mps_laplacian", phi, out)) != FSDEM_OK) return r;
    for (i = 0; i < s->n; ++i) out[i] = s->kind[i] == FSDEM_MPS_DUMMY ? 0 : fsdem__mps_lap_at(s, phi, NULL, i).x;
    return fsdem__ok(&s->status);
}

/* ---- >>mps_step : predictor, pressure equation, corrector, time stepping ---- */

/* Largest FLUID speed (m/s) and its particle in *who (-1 when none; the particle with a non-finite
   velocity, and the result NaN, when there is one). */
static fsdem_real fsdem__mps_umax(const fsdem_mps *s, int *who) {
    fsdem_real m2 = 0;
    int i;
    *who = -1;
    for (i = 0; i < s->n; ++i) {
        fsdem_real v2;
        if (s->kind[i] != FSDEM_MPS_FLUID) continue;
        v2 = fsdem__dot(s->v[i], s->v[i]);
        if (!fsdem__finite(v2)) {
            *who = i;
            return v2 - v2;
        }
        if (v2 > m2) {
            m2 = v2;
            *who = i;
        }
    }
    return (fsdem_real)sqrt(m2);
}

/* The stable step of the CFL rule of seed 002 Eq. 37, u_max dt / r0 <= C, at most dt_max. */
static fsdem_real fsdem__mps_dt_from(const fsdem_mps *s, fsdem_real umax) {
    fsdem_real dt = s->desc.dt_max;
    if (umax > 0 && s->desc.cfl * s->r0 / umax < dt) dt = s->desc.cfl * s->r0 / umax;
    return dt;
}

/* Makes room for the pressure matrix of `nnz` entries (by doubling). */
static fsdem_result fsdem__mps_matrix_room(fsdem_mps *s, long long nnz) {
    int cap;
    int *col;
    fsdem_real *val;
    if (nnz <= s->a_cap) return FSDEM_OK;
    cap = fsdem__mps_capacity(s->a_cap, nnz);
    if (!cap) return FSDEM_ERR_OUT_OF_MEMORY;
    col = (int *)fsdem__alloc(&s->allocator, sizeof(int) * (size_t)cap);
    val = (fsdem_real *)fsdem__alloc(&s->allocator, sizeof(fsdem_real) * (size_t)cap);
    if (!col || !val) {
        fsdem__free(&s->allocator, col, sizeof(int) * (size_t)cap);
        fsdem__free(&s->allocator, val, sizeof(fsdem_real) * (size_t)cap);
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    fsdem__free(&s->allocator, s->a_col, sizeof(int) * (size_t)s->a_cap);
    fsdem__free(&s->allocator, s->a_val, sizeof(fsdem_real) * (size_t)s->a_cap);
    s->bytes += (sizeof(int) + sizeof(fsdem_real)) * (size_t)(cap - s->a_cap);
    s->a_col = col;
    s->a_val = val;
    s->a_cap = cap;
    return FSDEM_OK;
}

/* Particle shifting (desc.shifting > 0): the Fickian shift of Lind, Xu, Stansby and Rogers (2012),
   J. Comput. Phys. 231:1499, dr_i = -D grad C_i, with a constant coefficient of order h^2 per
   step as in that paper (here D = desc.shifting r0^2), adapted to MPS: the concentration
   gradient is the kernel sum of Eq. 8 with C = 1 at every neighbour, FLUID, WALL and DUMMY alike,
       grad C_i = d/n0 sum_j 2 (r_j - r_i) w_ij / (|r_j - r_i|^2 eps_j),
   zero inside a full lattice and pointing to where neighbours crowd (a particle displaced by s
   from its lattice site has grad C = 1.19 s / r0^2 for re = 4.1 r0 in 2D, so desc.shifting = c
   moves it back by 1.19 c s in one step). Free surface (after Lind et al. 2012): a surface
   particle is not shifted; a particle with a surface neighbour (its neighbourhood is cut by the
   surface) is shifted only tangentially, its normal the asymmetry vector F_i of seed 002 Eq. 15
   (the shift's component along F_i removed), as the number-density deficiency below the surface is
   geometry, not clustering. WALL and DUMMY particles never move. The shift is computed at the
   positions of the start of the step (its neighbour rows) and added after the corrector's move;
   it is limited to desc.cfl r0 (a choice of this library, not of the paper: a shift is not longer
   than the motion a step allows). The velocity is not corrected (the paper's Taylor correction of
   the velocity to the shifted position is left out). Allocates nothing. */
static void fsdem__mps_shift(fsdem_mps *s) {
    const fsdem_real D = s->desc.shifting * s->r0 * s->r0, cap = s->desc.cfl * s->r0;
    int i, e;
    for (i = 0; i < s->n; ++i) {
        fsdem_vec3 gc = fsdem__zero3(), F = fsdem__zero3(), d;
        fsdem_real len;
        int band = 0;
        s->shift[i] = fsdem__zero3();
        if (s->kind[i] != FSDEM_MPS_FLUID || s->surf[i] || D == 0) continue;
        for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
            const int j = s->nb[e];
            const fsdem_vec3 r = fsdem__sub(s->x[j], s->x[i]);
            const fsdem_real r2 = fsdem__dot(r, r);
            if (!(r2 > 0)) continue;
            band |= s->surf[j];
            gc = fsdem__madd(gc, r, 2 * s->nbw[e] / (r2 * s->eps[j]));
            F = fsdem__madd(F, r, s->nbw[e] / ((fsdem_real)sqrt(r2) * s->eps[j]));
        }
        d = fsdem__scale(gc, -D * (fsdem_real)s->dim / s->n0);
        if (band) {
            const fsdem_real f2 = fsdem__dot(F, F);
            if (f2 > 0) d = fsdem__madd(d, F, -fsdem__dot(d, F) / f2);
        }
        if (s->dim == 2) d.z = 0;
        len = fsdem__norm(d);
        if (len > cap) d = fsdem__scale(d, cap / len);
        s->shift[i] = d;
    }
}

/* Assembles the pressure equation (section >>mps, step 4): unknowns are the FLUID and WALL
   particles off the surface with a non-DUMMY neighbour, numbered in particle order, so each row's
   columns ascend with the neighbour rows; row i is seed 002 Eq. 10 = Eq. 12 times
   -n0 lambda/(2d)/eps_i, which makes it symmetric, its DUMMY neighbours at the hydrostatic ghost
   pressure (their known terms on the right). The right-hand side goes to s->b. */
static fsdem_result fsdem__mps_assemble(fsdem_mps *s, fsdem_real dt) {
    const fsdem_real rho = s->desc.density, gamma = s->desc.gamma;
    const fsdem_real scale = -s->n0 * s->lambda / (2 * (fsdem_real)s->dim);
    long long nnz = 0;
    int i, e, rows = 0;
    for (i = 0; i < s->n; ++i) {
        int solid_only = 1;
        s->unknown[i] = -1;
        if (s->kind[i] == FSDEM_MPS_DUMMY || s->surf[i]) continue;
        for (e = s->nb_start[i]; e < s->nb_start[i + 1] && solid_only; ++e) solid_only = s->kind[s->nb[e]] == FSDEM_MPS_DUMMY;
        if (solid_only) continue;
        s->row_particle[rows] = i;
        s->unknown[i] = rows++;
    }
    for (i = 0; i < s->n; ++i)
        if (s->unknown[i] >= 0) {
            nnz++;
            for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) nnz += s->unknown[s->nb[e]] >= 0;
        }
    if (fsdem__mps_matrix_room(s, nnz) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    nnz = 0;
    s->a_start[0] = 0;
    for (i = 0; i < s->n; ++i) {
        const int row = s->unknown[i];
        fsdem_real diag = 0, source;
        long long at = -1;
        if (row < 0) continue;
        for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
            const int j = s->nb[e];
            const fsdem_real a = s->nbw[e] / (s->eps[i] * s->eps[j]);
            if (s->kind[j] == FSDEM_MPS_DUMMY) continue;
            diag += a;
            if (s->unknown[j] < 0) continue;
            if (at < 0 && j > i) at = nnz++; /* the diagonal's place among ascending columns */
            s->a_col[nnz] = s->unknown[j];
            s->a_val[nnz++] = -a;
        }
        if (at < 0) at = nnz++;
        s->a_col[at] = row;
        s->a_val[at] = diag;
        s->a_start[row + 1] = (int)nnz;
        /* seed 002 Eq. 12: (1 - gamma) rho/dt div u* - gamma rho/dt^2 (n_i - n0)/n0 */
        source = (1 - gamma) * rho / dt * s->div[i] - gamma * rho / (dt * dt) * (s->nd[i] - s->n0) / s->n0;
        s->b[row] = scale * source / s->eps[i];
        /* DUMMY neighbours in Eq. 10 at the ghost pressure p_i + rho g.(r_j - r_i), the hydrostatic
           extrapolation from i that the corrector's gradient uses too (fsdem__mps_grad_at): their
           (p_j - p_i) w_ij terms are known and move to the right-hand side (the matrix is unchanged,
           still symmetric) */
        for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
            const int j = s->nb[e];
            if (s->kind[j] != FSDEM_MPS_DUMMY) continue;
            s->b[row] += rho * fsdem__dot(s->desc.gravity, fsdem__sub(s->x[j], s->x[i])) * s->nbw[e] / (s->eps[i] * s->eps[j]);
        }
        s->sol[row] = s->p[i];
    }
    s->rows = rows;
    return FSDEM_OK;
}

/* One step of dt (the section's steps 1-6). Failures before the pressure is known change nothing;
   a completed step reports a non-finite or escaped particle. */
static fsdem_result fsdem__mps_do_step(fsdem_mps *s, fsdem_real dt) {
    const fsdem_real rho = s->desc.density, nu = s->desc.viscosity;
    fsdem_pcg_info info;
    fsdem_csr A;
    fsdem_result r;
    clock_t t0 = clock(), t1;
    int i, a, bad = -1;
    if (s->counts[FSDEM_MPS_FLUID] == 0)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps: no FLUID particles to step");
    for (i = 0; i < s->n; ++i)
        if (!(s->eps[i] > 0 && s->eps[i] <= 1))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps: particle %d has porosity %g outside (0, 1]", i,
                               (double)s->eps[i]);
    /* 1. neighbours, number density, free surface */
    if (fsdem__mps_neighbours(s) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps: out of memory building the neighbour list");
    s->surface_count = fsdem__mps_density(s);
    fsdem__mps_shift(s);
    /* 2. predictor: u* = u + dt (nu lap u + g) (seed 002 Eq. A.6 with eps = 1). WALL and DUMMY
       particles take u* = dt g, their velocity (0) plus the same body force: a uniform field has no
       divergence (Eq. 9), so gravity alone leaves no source at the walls in Eq. 12, and the walls
       carry its weight through the hydrostatic ghost pressure of the DUMMY particles in the
       pressure equation (fsdem__mps_assemble), the discrete Neumann condition dp/dn = rho g.n.
       With u* = 0 at the solids instead, the source of the rows near a wall held only part of the
       weight (one-sided Eq. 9 against the one-sided Eq. 10): still water started with 0.7 rho g h
       at the bottom and fell at 0.25-0.35 g in its first step. */
    for (i = 0; i < s->n; ++i) {
        if (s->kind[i] != FSDEM_MPS_FLUID) {
            s->us[i] = fsdem__scale(s->desc.gravity, dt);
            if (s->dim == 2) s->us[i].z = 0;
            continue;
        }
        s->us[i] = fsdem__add(s->v[i], fsdem__scale(fsdem__add(fsdem__scale(fsdem__mps_lap_at(s, NULL, s->v, i), nu),
                                                                s->desc.gravity), dt));
        if (s->dim == 2) s->us[i].z = 0;
    }
    for (i = 0; i < s->n; ++i) s->div[i] = s->kind[i] == FSDEM_MPS_DUMMY ? 0 : fsdem__mps_div_at(s, s->us, i);
    /* 3. pressure equation */
    if (fsdem__mps_assemble(s, dt) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps: out of memory assembling the pressure matrix");
    memset(&info, 0, sizeof info);
    s->iters = 0;
    s->residual = 0;
    if (s->rows > 0) {
        A.rows = s->rows;
        A.row_start = s->a_start;
        A.col = s->a_col;
        A.val = s->a_val;
        r = fsdem_pcg_setup_csr(s->pcg, &A);
        if (r == FSDEM_OK) r = fsdem_pcg_solve(s->pcg, s->b, s->sol, &info);
        s->sec_pressure += (double)(clock() - t0) / CLOCKS_PER_SEC;
        s->iters = info.iterations;
        s->residual = info.residual;
        if (r != FSDEM_OK) {
            if (r == FSDEM_ERR_OUT_OF_MEMORY)
                return fsdem__fail(&s->status, r, "fsdem_mps: out of memory in the pressure solve: %s", fsdem_pcg_last_error(s->pcg));
            return fsdem__fail(&s->status, FSDEM_ERR_NOT_CONVERGED,
                               "fsdem_mps: step %lld: the pressure solve of %d unknowns failed after %d iterations (residual "
                               "%g, tolerance %g): %s; nothing changed",
                               s->steps + 1, s->rows, info.iterations, (double)info.residual,
                               (double)s->desc.pressure_tolerance, fsdem_pcg_last_error(s->pcg));
        }
    }
    t1 = clock();
    /* 4. pressures (clamped where asked), then the corrector: u = u* - dt/rho grad p, r += dt u */
    for (i = 0; i < s->n; ++i) {
        fsdem_real p = s->unknown[i] >= 0 ? s->sol[s->unknown[i]] : 0;
        if (p < 0 && s->desc.clamp_negative_pressure) p = 0;
        s->p[i] = p;
    }
    for (i = 0; i < s->n; ++i) {
        if (s->kind[i] != FSDEM_MPS_FLUID) continue;
        s->v[i] = fsdem__madd(s->us[i], fsdem__mps_grad_at(s, s->p, i, fsdem__scale(s->desc.gravity, rho)), -dt / rho); /* seed 002 Eq. A.5 */
        if (s->dim == 2) s->v[i].z = 0;
    }
    for (i = 0; i < s->n; ++i)
        if (s->kind[i] == FSDEM_MPS_FLUID) s->x[i] = fsdem__add(fsdem__madd(s->x[i], s->v[i], dt), s->shift[i]);
    s->time += (double)dt;
    s->dt_last = dt;
    s->steps++;
    s->iters_total += s->iters;
    s->sec_total += (double)(clock() - t1) / CLOCKS_PER_SEC + (double)(t1 - t0) / CLOCKS_PER_SEC;
    for (i = 0; i < s->n && bad < 0; ++i)
        if (s->kind[i] == FSDEM_MPS_FLUID && (!fsdem__finite3(s->v[i]) || !fsdem__finite3(s->x[i]) || !fsdem__finite(s->p[i])))
            bad = i;
    if (bad >= 0)
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_mps: step %lld: particle %d has a non-finite velocity, position or pressure",
                           s->steps, bad);
    for (i = 0; i < s->n; ++i) {
        if (s->kind[i] != FSDEM_MPS_FLUID) continue;
        for (a = 0; a < s->dim; ++a)
            if (fsdem__comp(s->x[i], a) < fsdem__comp(s->desc.domain_min, a) || fsdem__comp(s->x[i], a) > fsdem__comp(s->desc.domain_max, a))
                return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_DOMAIN, "fsdem_mps: step %lld: particle %d left the domain at (%g, %g, %g) m",
                                   s->steps, i, (double)s->x[i].x, (double)s->x[i].y, (double)s->x[i].z);
    }
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_mps_stable_dt(const fsdem_mps *s, fsdem_real *dt) {
    int who;
    fsdem_real umax;
    if (!s || !dt) return FSDEM_ERR_INVALID_ARG;
    umax = fsdem__mps_umax(s, &who);
    if (!fsdem__finite(umax))
        return fsdem__fail((fsdem__status *)&s->status, FSDEM_ERR_NAN, "fsdem_mps_stable_dt: particle %d has a non-finite velocity", who);
    *dt = fsdem__mps_dt_from(s, umax);
    return fsdem__ok((fsdem__status *)&s->status);
}

fsdem_result fsdem_mps_step(fsdem_mps *s) {
    fsdem_real dt;
    fsdem_result r;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem_mps_stable_dt(s, &dt)) != FSDEM_OK) return r;
    return fsdem__mps_do_step(s, dt);
}

fsdem_result fsdem_mps_step_dt(fsdem_mps *s, fsdem_real dt) {
    int who;
    fsdem_real umax;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_step_dt: dt = %g s must be > 0 and finite", (double)dt);
    umax = fsdem__mps_umax(s, &who);
    if (!fsdem__finite(umax))
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_mps_step_dt: particle %d has a non-finite velocity", who);
    if (umax * dt > s->desc.cfl * s->r0 * (1 + (fsdem_real)1e-5))
        return fsdem__fail(&s->status, FSDEM_ERR_CFL,
                           "fsdem_mps_step_dt: dt = %g s gives u_max dt / r0 = %g > cfl = %g (seed 002 Eq. 37; particle %d at %g m/s; "
                           "dt <= %g s)",
                           (double)dt, (double)(umax * dt / s->r0), (double)s->desc.cfl, who, (double)umax,
                           (double)(s->desc.cfl * s->r0 / umax));
    return fsdem__mps_do_step(s, dt);
}

fsdem_result fsdem_mps_advance(fsdem_mps *s, fsdem_real duration, long long *steps) {
    double end;
    long long n = 0;
    fsdem_result r = FSDEM_OK;
    if (steps) *steps = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!(duration >= 0) || !fsdem__finite(duration))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_advance: duration = %g s must be >= 0", (double)duration);
    end = s->time + (double)duration;
    while (s->time < end - 1e-12 * (end > 1 ? end : 1)) {
        fsdem_real dt;
        if ((r = fsdem_mps_stable_dt(s, &dt)) != FSDEM_OK) break;
        if (s->time + dt > end) dt = (fsdem_real)(end - s->time);
        else if (s->time + 1.5 * dt > end) dt = (fsdem_real)((end - s->time) / 2);
        r = fsdem__mps_do_step(s, dt);
        ++n;
        if (r != FSDEM_OK) break;
    }
    if (steps) *steps = n;
    return r;
}

double fsdem_mps_time(const fsdem_mps *s) { return s ? s->time : 0; }

/* ---- >>mps_views : views, statistics ---- */

fsdem_mps_particles fsdem_mps_get_particles(fsdem_mps *s) {
    fsdem_mps_particles v;
    memset(&v, 0, sizeof v);
    if (!s) return v;
    v.count = s->n;
    v.dim = s->dim;
    v.position = s->x;
    v.velocity = s->v;
    v.pressure = s->p;
    v.kind = s->kind;
    v.surface = s->surf;
    v.number_density = s->nd;
    v.porosity = s->eps;
    return v;
}

fsdem_csr fsdem_mps_pressure_matrix(const fsdem_mps *s, const int **rows_particle) {
    fsdem_csr m;
    memset(&m, 0, sizeof m);
    if (rows_particle) *rows_particle = NULL;
    if (!s) return m;
    m.rows = s->rows;
    m.row_start = s->a_start;
    m.col = s->a_col;
    m.val = s->a_val;
    if (rows_particle) *rows_particle = s->row_particle;
    return m;
}

fsdem_mps_stats fsdem_mps_get_stats(const fsdem_mps *s) {
    fsdem_mps_stats st;
    int i, who;
    memset(&st, 0, sizeof st);
    if (!s) return st;
    st.steps = s->steps;
    st.time = s->time;
    st.dt = s->dt_last;
    st.fluid = s->counts[FSDEM_MPS_FLUID];
    st.wall = s->counts[FSDEM_MPS_WALL];
    st.dummy = s->counts[FSDEM_MPS_DUMMY];
    st.surface = s->surface_count;
    st.unknowns = s->rows;
    st.neighbours = s->pair_count;
    st.n0 = s->n0;
    st.lambda = s->lambda;
    st.f0 = s->f0;
    st.pressure_iterations = s->iters;
    st.pressure_iterations_total = s->iters_total;
    st.pressure_residual = s->residual;
    st.max_speed = fsdem__mps_umax(s, &who);
    for (i = 0; i < s->n; ++i)
        if (s->p[i] > st.max_pressure) st.max_pressure = s->p[i];
    st.seconds_total = s->sec_total;
    st.seconds_pressure = s->sec_pressure;
    st.memory_bytes = s->bytes;
    return st;
}
