/* ---- >>pic_desc : defaults, validation, creation ---- */

fsdem_pic_desc fsdem_pic_desc_default(int dim) {
    fsdem_pic_desc d;
    int k;
    memset(&d, 0, sizeof d);
    d.dim = dim;
    d.domain_min = fsdem_v3(0, 0, 0);
    d.domain_max = fsdem_v3(1, 1, 1);
    d.cell_size = (fsdem_real)(1.0 / 32.0);
    d.density = 1000;
    d.viscosity = 0;
    d.gravity = dim == 3 ? fsdem_v3(0, 0, (fsdem_real)-9.81) : fsdem_v3(0, (fsdem_real)-9.81, 0);
    for (k = 0; k < 6; ++k) {
        d.boundary[k] = FSDEM_PIC_BC_SLIP;
        d.boundary_velocity[k] = fsdem_v3(0, 0, 0);
    }
    d.free_surface = 1;
    d.transfer = FSDEM_PIC_TRANSFER_FLIP;
    d.flip_ratio = (fsdem_real)0.97;
    d.kernel = FSDEM_PIC_KERNEL_LINEAR;
    d.particles_per_cell = dim == 3 ? 8 : 4;
    d.jitter = 0;
    d.seed = 1;
    d.min_particles_per_cell = d.particles_per_cell / 2;
    d.max_particles_per_cell = 3 * d.particles_per_cell;
    d.advection_order = 2;
    d.cfl = 1;
    d.cfl_max = 5;
    d.dt_max = (fsdem_real)0.01;
    d.density_projection = 1;
    d.ghost_theta_min = (fsdem_real)0.01;
    d.extrapolation_layers = 0;
    d.pressure_precond = FSDEM_PRECOND_AUTO;
#ifdef FSDEM_USE_FLOAT
    d.pressure_tolerance = (fsdem_real)1e-5;
    d.viscosity_tolerance = (fsdem_real)1e-5;
#else
    d.pressure_tolerance = (fsdem_real)1e-8;
    d.viscosity_tolerance = (fsdem_real)1e-8;
#endif
    d.pressure_max_iterations = 500;
    d.viscosity_precond = FSDEM_PRECOND_MIC0;
    d.max_memory = 0;
    return d;
}

static const char *fsdem__pic_side_name(int side) {
    static const char *names[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};
    return side >= 0 && side < 6 ? names[side] : "?";
}

/* Grid size of a desc: cells per axis as doubles (may be huge), and an estimate of the bytes the
   solver needs for it. */
static void fsdem__pic_grid_size(const fsdem_pic_desc *d, double cells[3], double *total,
                                 double *bytes) {
    int a;
    double faces = 0, per_cell, per_face;
    *total = 1;
    for (a = 0; a < 3; ++a) {
        cells[a] = 1;
        if (a < d->dim) {
            double e = (double)fsdem__comp(d->domain_max, a) - (double)fsdem__comp(d->domain_min, a);
            cells[a] = floor(e / (double)d->cell_size + 0.5);
            if (cells[a] < 1) cells[a] = 1;
        }
        *total *= cells[a];
    }
    for (a = 0; a < d->dim; ++a) faces += *total / cells[a] * (cells[a] + 1);
    per_face = 15.0 * sizeof(fsdem_real) + 2 + sizeof(int);
    per_cell = 8.0 * sizeof(fsdem_real) + 3 + sizeof(int);
    per_cell += 12.0 * sizeof(fsdem_real); /* pressure solver: vectors and multigrid levels */
    if (d->viscosity > 0) per_face += 16.0 * sizeof(fsdem_real) + 1;
    *bytes = *total * per_cell + faces * per_face;
}

static fsdem_result fsdem__pic_check(const fsdem_pic_desc *d, char *msg, size_t size) {
    int a, k;
    double cells[3], total, bytes;
#define FSDEM__PIC_BAD(...)                                                                        \
    do {                                                                                           \
        if (msg && size) snprintf(msg, size, __VA_ARGS__);                                         \
        return FSDEM_ERR_INVALID_ARG;                                                              \
    } while (0)
    if (msg && size) msg[0] = '\0';
    if (d->dim != 2 && d->dim != 3) FSDEM__PIC_BAD("fsdem_pic_desc.dim = %d must be 2 or 3", d->dim);
    if (!(d->cell_size > 0) || !fsdem__finite(d->cell_size))
        FSDEM__PIC_BAD("fsdem_pic_desc.cell_size = %g m must be > 0 and finite", (double)d->cell_size);
    if (!fsdem__finite3(d->domain_min) || !fsdem__finite3(d->domain_max))
        FSDEM__PIC_BAD("fsdem_pic_desc.domain_min/domain_max must be finite");
    for (a = 0; a < d->dim; ++a)
        if (!(fsdem__comp(d->domain_max, a) > fsdem__comp(d->domain_min, a)))
            FSDEM__PIC_BAD("fsdem_pic_desc.domain_max.%c = %g must exceed domain_min.%c = %g", "xyz"[a],
                           (double)fsdem__comp(d->domain_max, a), "xyz"[a],
                           (double)fsdem__comp(d->domain_min, a));
    if (!(d->density > 0) || !fsdem__finite(d->density))
        FSDEM__PIC_BAD("fsdem_pic_desc.density = %g kg/m^3 must be > 0", (double)d->density);
    if (!(d->viscosity >= 0) || !fsdem__finite(d->viscosity))
        FSDEM__PIC_BAD("fsdem_pic_desc.viscosity = %g m^2/s must be >= 0", (double)d->viscosity);
    if (fsdem__check_gravity("fsdem_pic_desc", d->gravity, d->dim, msg, size) != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < 2 * d->dim; ++k) {
        if ((int)d->boundary[k] < 0 || (int)d->boundary[k] > 3)
            FSDEM__PIC_BAD("fsdem_pic_desc.boundary[%d] (%s side) = %d is not a fsdem_pic_bc", k,
                           fsdem__pic_side_name(k), (int)d->boundary[k]);
        if (!fsdem__within(d->boundary_velocity[k], FSDEM_MAX_SPEED))
            FSDEM__PIC_BAD("fsdem_pic_desc.boundary_velocity[%d] must be finite and at most FSDEM_MAX_SPEED (%g m/s)", k,
                           (double)FSDEM_MAX_SPEED);
    }
    if ((int)d->transfer < 0 || (int)d->transfer > 2)
        FSDEM__PIC_BAD("fsdem_pic_desc.transfer = %d is not a fsdem_pic_transfer", (int)d->transfer);
    if (!(d->flip_ratio >= 0 && d->flip_ratio <= 1))
        FSDEM__PIC_BAD("fsdem_pic_desc.flip_ratio = %g must be in [0, 1]", (double)d->flip_ratio);
    if ((int)d->kernel < 0 || (int)d->kernel > 1)
        FSDEM__PIC_BAD("fsdem_pic_desc.kernel = %d is not a fsdem_pic_kernel", (int)d->kernel);
    if (d->particles_per_cell < 1 || d->particles_per_cell > 64)
        FSDEM__PIC_BAD("fsdem_pic_desc.particles_per_cell = %d must be in [1, 64]", d->particles_per_cell);
    if (!(d->jitter >= 0 && d->jitter <= 1))
        FSDEM__PIC_BAD("fsdem_pic_desc.jitter = %g must be in [0, 1]", (double)d->jitter);
    if (d->min_particles_per_cell < 0 || d->min_particles_per_cell > d->particles_per_cell)
        FSDEM__PIC_BAD("fsdem_pic_desc.min_particles_per_cell = %d must be in [0, particles_per_cell = %d]",
                       d->min_particles_per_cell, d->particles_per_cell);
    if (d->max_particles_per_cell != 0 && d->max_particles_per_cell < d->particles_per_cell)
        FSDEM__PIC_BAD("fsdem_pic_desc.max_particles_per_cell = %d must be 0 or >= particles_per_cell = %d",
                       d->max_particles_per_cell, d->particles_per_cell);
    if (d->advection_order != 2 && d->advection_order != 3)
        FSDEM__PIC_BAD("fsdem_pic_desc.advection_order = %d must be 2 or 3", d->advection_order);
    if (!(d->cfl > 0) || !fsdem__finite(d->cfl))
        FSDEM__PIC_BAD("fsdem_pic_desc.cfl = %g must be > 0", (double)d->cfl);
    if (!(d->cfl_max >= d->cfl) || !fsdem__finite(d->cfl_max))
        FSDEM__PIC_BAD("fsdem_pic_desc.cfl_max = %g must be >= cfl = %g", (double)d->cfl_max, (double)d->cfl);
    if (fsdem__check_dt_max("fsdem_pic_desc", d->dt_max, d->gravity, msg, size) != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    if (!(d->ghost_theta_min > 0 && d->ghost_theta_min <= 1))
        FSDEM__PIC_BAD("fsdem_pic_desc.ghost_theta_min = %g must be in (0, 1]", (double)d->ghost_theta_min);
    if (d->extrapolation_layers < 0 || d->extrapolation_layers > 1000)
        FSDEM__PIC_BAD("fsdem_pic_desc.extrapolation_layers = %d must be in [0, 1000]", d->extrapolation_layers);
    if ((int)d->pressure_precond < 0 || (int)d->pressure_precond > 5)
        FSDEM__PIC_BAD("fsdem_pic_desc.pressure_precond = %d must be a fsdem_precond for a stencil (AUTO, NONE, JACOBI, IC0, "
                       "MIC0, MG)", (int)d->pressure_precond);
    if ((int)d->viscosity_precond < 0 || (int)d->viscosity_precond > 5)
        FSDEM__PIC_BAD("fsdem_pic_desc.viscosity_precond = %d must be a fsdem_precond for a stencil (AUTO, NONE, JACOBI, IC0, "
                       "MIC0, MG; AMG takes CSR matrices only)", (int)d->viscosity_precond);
    if (!(d->pressure_tolerance > 0 && d->pressure_tolerance < 1))
        FSDEM__PIC_BAD("fsdem_pic_desc.pressure_tolerance = %g must be in (0, 1)", (double)d->pressure_tolerance);
    if (!(d->viscosity_tolerance > 0 && d->viscosity_tolerance < 1))
        FSDEM__PIC_BAD("fsdem_pic_desc.viscosity_tolerance = %g must be in (0, 1)", (double)d->viscosity_tolerance);
    if (d->pressure_max_iterations < 1)
        FSDEM__PIC_BAD("fsdem_pic_desc.pressure_max_iterations = %d must be >= 1", d->pressure_max_iterations);
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        FSDEM__PIC_BAD("fsdem_pic_desc.allocator needs both alloc and free, or neither");
#undef FSDEM__PIC_BAD
    fsdem__pic_grid_size(d, cells, &total, &bytes);
    for (a = 0; a < d->dim; ++a) {
        /* whole cells move domain_max by at most half a cell, unless the extent is below half a cell */
        const double extent = (double)fsdem__comp(d->domain_max, a) - (double)fsdem__comp(d->domain_min, a);
        if (fabs(cells[a] * (double)d->cell_size - extent) > 0.5 * (double)d->cell_size * (1 + 1e-9))
            return fsdem__reject(msg, size,
                                 "fsdem_pic_desc.cell_size = %g m exceeds twice the extent %g m along %c: the grid would "
                                 "change the domain by more than half a cell",
                                 (double)d->cell_size, extent, "xyz"[a]);
    }
    if (total > 4e8 || cells[0] + 1 > 2e9 || cells[1] + 1 > 2e9 || cells[2] + 1 > 2e9 ||
        (d->max_memory > 0 && bytes > (double)d->max_memory) || bytes > (double)((size_t)-1) / 2) {
        if (msg && size)
            snprintf(msg, size,
                     "fsdem_pic_desc.the grid of %.0f x %.0f x %.0f = %.4g cells (cell_size %g m) needs about "
                     "%.4g bytes, more than %s",
                     cells[0], cells[1], cells[2], total, (double)d->cell_size, bytes,
                     d->max_memory > 0 && bytes > (double)d->max_memory ? "max_memory allows"
                                                                         : "fits in memory");
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    return FSDEM_OK;
}

fsdem_result fsdem_pic_desc_check(const fsdem_pic_desc *desc, char *message, size_t message_size) {
    if (!desc) {
        if (message && message_size) snprintf(message, message_size, "fsdem_pic_desc is NULL");
        return FSDEM_ERR_INVALID_ARG;
    }
    return fsdem__pic_check(desc, message, message_size);
}

/* Allocation that is counted in the solver's memory figure. */
static void *fsdem__pic_alloc(fsdem_pic *s, size_t bytes) {
    void *p = fsdem__alloc(&s->allocator, bytes);
    if (p) s->bytes += bytes;
    return p;
}

static void fsdem__pic_release(fsdem_pic *s, void *p, size_t bytes) {
    if (p) {
        fsdem__free(&s->allocator, p, bytes);
        s->bytes -= bytes;
    }
}

/* One grid array of the solver: where its pointer lives, its length, element size and initial
   value (reals: `fill`; other types: zero). */
typedef struct fsdem__pic_array {
    void **ptr;
    size_t count, elem;
    fsdem_real fill;
} fsdem__pic_array;

/* 19 per axis (13, and 6 for the implicit viscosity) and 14 per cell: 71 in 3D with viscosity */
#define FSDEM__PIC_MAX_ARRAYS 80

static void fsdem__pic_array_add(fsdem__pic_array *t, int *n, void **ptr, size_t count, size_t elem, fsdem_real fill) {
    FSDEM_ASSERT(*n < FSDEM__PIC_MAX_ARRAYS);
    t[*n].ptr = ptr;
    t[*n].count = count > 0 ? count : 1;
    t[*n].elem = elem;
    t[*n].fill = fill;
    ++*n;
}

/* Every grid array of the solver (faces per axis, implicit-viscosity face grids, cells), so
   creation and destruction treat them alike from one list. Returns their number. */
static int fsdem__pic_arrays(fsdem_pic *s, fsdem__pic_array t[FSDEM__PIC_MAX_ARRAYS]) {
    const size_t R = sizeof(fsdem_real), nc = (size_t)s->ncell;
    int n = 0, a, b, c;
#define FSDEM__PIC_REALS(field, count, fill) fsdem__pic_array_add(t, &n, (void **)&s->field, count, R, (fsdem_real)(fill))
#define FSDEM__PIC_BYTES(field, count) fsdem__pic_array_add(t, &n, (void **)&s->field, count, 1, 0)
    for (a = 0; a < s->dim; ++a) {
        const size_t nf = (size_t)s->nface[a];
        FSDEM__PIC_REALS(u[a], nf, 0);
        FSDEM__PIC_REALS(uold[a], nf, 0);
        FSDEM__PIC_REALS(wsum[a], nf, 0);
        FSDEM__PIC_REALS(ftmp[a], nf, 0);
        FSDEM__PIC_REALS(sopen[a], nf, 1);
        FSDEM__PIC_REALS(svel[a], nf, 0);
        FSDEM__PIC_REALS(copen[a], nf, 1);
        FSDEM__PIC_REALS(cvel[a], nf, 0);
        FSDEM__PIC_REALS(cacc[a], nf, 0);
        FSDEM__PIC_REALS(cvstart[a], nf, 0);
        FSDEM__PIC_REALS(E[a], nf, 1);
        FSDEM__PIC_REALS(us[a], nf, 0);
        FSDEM__PIC_REALS(fpor[a], nf, 1);
        FSDEM__PIC_REALS(Ef[a], nf, 1);
        FSDEM__PIC_BYTES(fvalid[a], nf);
        FSDEM__PIC_BYTES(fvalid2[a], nf);
        if (s->desc.viscosity > 0) {
            FSDEM__PIC_REALS(shear[a], nf, 0);
            FSDEM__PIC_BYTES(vcell[a], nf);
            for (b = 0; b < s->dim; ++b) {
                size_t m = 1;
                for (c = 0; c < 3; ++c) m *= (size_t)(s->fn[a][c] + (c == b));
                FSDEM__PIC_REALS(vface[a][b], m, 0);
            }
        }
    }
    FSDEM__PIC_REALS(frac, nc, 0);
    FSDEM__PIC_REALS(fref, nc, 1);
    FSDEM__PIC_REALS(phi, nc, 0);
    FSDEM__PIC_REALS(pres, nc, 0);
    FSDEM__PIC_REALS(rhs, nc, 0);
    FSDEM__PIC_REALS(diag, nc, 0);
    FSDEM__PIC_REALS(ctmp, nc, 0);
    FSDEM__PIC_REALS(crhs, nc, 0);
    FSDEM__PIC_REALS(cref, nc, 1);
    FSDEM__PIC_REALS(cpor, nc, 1);
    FSDEM__PIC_BYTES(ctype, nc);
    FSDEM__PIC_BYTES(cnear, nc);
    FSDEM__PIC_BYTES(csolid, nc);
    fsdem__pic_array_add(t, &n, (void **)&s->cstart, nc + 1, sizeof(int), 0);
    fsdem__pic_array_add(t, &n, (void **)&s->fqueue, (size_t)s->fqueue_size, sizeof(int), 0);
#undef FSDEM__PIC_REALS
#undef FSDEM__PIC_BYTES
    return n;
}

static void fsdem__pic_free_particles(fsdem_pic *s) {
    size_t cap = (size_t)s->pcap;
    int a;
    fsdem__pic_release(s, s->px, cap * sizeof(fsdem_vec3));
    fsdem__pic_release(s, s->pv, cap * sizeof(fsdem_vec3));
    fsdem__pic_release(s, s->ptmp, cap * sizeof(fsdem_vec3));
    for (a = 0; a < 3; ++a) fsdem__pic_release(s, s->pc[a], cap * sizeof(fsdem_vec3));
    fsdem__pic_release(s, s->pcell, cap * sizeof(int));
    fsdem__pic_release(s, s->pidx, cap * sizeof(int));
    fsdem__pic_release(s, s->pflag, cap);
    s->px = s->pv = s->ptmp = s->pc[0] = s->pc[1] = s->pc[2] = NULL;
    s->pcell = s->pidx = NULL;
    s->pflag = NULL;
    s->pcap = 0;
}

void fsdem_pic_destroy(fsdem_pic *s) {
    fsdem__pic_array t[FSDEM__PIC_MAX_ARRAYS];
    fsdem_allocator al;
    int a, n;
    if (!s) return;
    fsdem__pic_free_particles(s);
    n = fsdem__pic_arrays(s, t);
    for (a = 0; a < n; ++a) fsdem__pic_release(s, *t[a].ptr, t[a].count * t[a].elem);
    for (a = 0; a < 3; ++a)
        if (s->pcg_v[a]) fsdem_pcg_destroy(s->pcg_v[a]);
    for (a = 0; a < s->obst_count; ++a)
        if (s->obst[a].verts)
            fsdem__pic_release(s, s->obst[a].verts, sizeof(fsdem_vec3) * (size_t)s->obst[a].d.vertex_count);
    fsdem__pic_release(s, s->obst, sizeof(fsdem__pic_obst) * (size_t)s->obst_capacity);
    if (s->pcg_p) fsdem_pcg_destroy(s->pcg_p);
    fsdem__gauges_free(&s->gauges, &s->allocator);
    al = s->allocator;
    fsdem__free(&al, s, sizeof *s);
}

const char *fsdem_pic_last_error(const fsdem_pic *s) { return s ? s->status.message : "fsdem_pic is NULL"; }


/* Fill the viscous face-grid coefficients of axis a: 1 between two faces, 0 on the boundary. */
static void fsdem__pic_fill_vface(fsdem_pic *s, int a) {
    int b, i, j, k, m[3], c;
    for (b = 0; b < s->dim; ++b) {
        for (c = 0; c < 3; ++c) m[c] = s->fn[a][c] + (c == b);
        for (k = 0; k < m[2]; ++k)
            for (j = 0; j < m[1]; ++j)
                for (i = 0; i < m[0]; ++i) {
                    int coord = b == 0 ? i : b == 1 ? j : k;
                    s->vface[a][b][(k * m[1] + j) * m[0] + i] =
                        (coord == 0 || coord == m[b] - 1) ? (fsdem_real)0 : (fsdem_real)1;
                }
    }
}

static void fsdem__pic_static_flags(fsdem_pic *s);
static void fsdem__pic_compute_fref(fsdem_pic *s);

/* Grid geometry, strides and seeding constants of a new solver from its (checked) desc. */
static void fsdem__pic_layout(fsdem_pic *s, const fsdem_pic_desc *desc) {
    double cells[3], total, bytes;
    int a, root;
    int n[3];
    fsdem__pic_grid_size(desc, cells, &total, &bytes);
    for (a = 0; a < 3; ++a) n[a] = (int)cells[a];
    fsdem__mac_init(&s->mac, desc->dim, n, desc->cell_size, desc->domain_min);
    /* the loops' mirrors of the layout */
    s->dim = s->mac.dim;
    s->dx = s->mac.dx;
    s->inv_dx = s->mac.inv_dx;
    s->ncell = s->mac.ncell;
    s->lo = s->mac.lo;
    s->hi = s->mac.hi;
    memcpy(s->n, s->mac.n, sizeof s->n);
    memcpy(s->fn, s->mac.fn, sizeof s->fn);
    memcpy(s->fstep, s->mac.fstep, sizeof s->fstep);
    s->cstep[0] = 1;
    s->cstep[1] = s->n[0];
    s->cstep[2] = s->n[0] * s->n[1];
    for (a = 0; a < 3; ++a) s->nface[a] = a < s->dim ? s->fn[a][0] * s->fn[a][1] * s->fn[a][2] : 0;
    s->fqueue_size = s->nface[0] > s->nface[1] ? s->nface[0] : s->nface[1];
    if (s->nface[2] > s->fqueue_size) s->fqueue_size = s->nface[2];
    s->ppc = desc->particles_per_cell;
    root = (int)floor(pow((double)s->ppc, 1.0 / s->dim) + 0.5);
    s->sub = (int)pow((double)root, (double)s->dim) == s->ppc ? root : 0;
    s->pvol = (fsdem_real)pow((double)s->dx, (double)s->dim) / (fsdem_real)s->ppc;
    s->gmag = fsdem__norm(desc->gravity);
    s->rng = 0x9E3779B97F4A7C15ull ^ (unsigned long long)desc->seed;
    if (s->dim == 2) s->desc.domain_max.z = s->desc.domain_min.z;
}

/* Allocates and fills every grid array of the table (fsdem__pic_arrays). FSDEM_ERR_OUT_OF_MEMORY
   leaves the ones allocated so far for fsdem_pic_destroy. */
static fsdem_result fsdem__pic_allocate(fsdem_pic *s) {
    fsdem__pic_array t[FSDEM__PIC_MAX_ARRAYS];
    const int n = fsdem__pic_arrays(s, t);
    int a, b;
    size_t k;
    for (a = 0; a < n; ++a) {
        unsigned char *p = (unsigned char *)fsdem__pic_alloc(s, t[a].count * t[a].elem);
        if (!p) return FSDEM_ERR_OUT_OF_MEMORY;
        *t[a].ptr = p;
        if (t[a].elem == sizeof(fsdem_real) && t[a].fill != 0)
            for (k = 0; k < t[a].count; ++k) ((fsdem_real *)(void *)p)[k] = t[a].fill;
        else memset(p, 0, t[a].count * t[a].elem);
    }
    for (a = 0; a < s->dim && s->desc.viscosity > 0; ++a) fsdem__pic_fill_vface(s, a);
    for (b = 0; b < s->ncell; ++b) s->ctype[b] = FSDEM_STENCIL_CELL_AIR;
    return FSDEM_OK;
}

/* The linear solvers, set up once on the full grid so that steps never allocate: the pressure
   solve on the cell grid, and with a viscosity one solve per velocity component on its face grid. */
static fsdem_result fsdem__pic_solvers(fsdem_pic *s) {
    const fsdem_pic_desc *desc = &s->desc;
    fsdem_pcg_desc pd = fsdem_pcg_desc_default();
    fsdem_stencil st;
    fsdem_result r;
    int a, b;
    pd.preconditioner = desc->pressure_precond;
    pd.tolerance = desc->pressure_tolerance;
    pd.max_iterations = desc->pressure_max_iterations;
    pd.allocator = s->allocator;
    r = fsdem_pcg_create(&pd, &s->pcg_p);
    if (r == FSDEM_OK) {
        memset(&st, 0, sizeof st);
        st.dim = s->dim;
        for (a = 0; a < 3; ++a) st.n[a] = s->n[a];
        r = fsdem_pcg_setup_stencil(s->pcg_p, &st);
    }
    for (a = 0; a < s->dim && r == FSDEM_OK && desc->viscosity > 0; ++a) {
        pd.preconditioner = desc->viscosity_precond;
        pd.tolerance = desc->viscosity_tolerance;
        r = fsdem_pcg_create(&pd, &s->pcg_v[a]);
        if (r == FSDEM_OK) {
            memset(&st, 0, sizeof st);
            st.dim = s->dim;
            for (b = 0; b < 3; ++b) st.n[b] = s->fn[a][b];
            r = fsdem_pcg_setup_stencil(s->pcg_v[a], &st);
        }
    }
    return r;
}

fsdem_result fsdem_pic_create(const fsdem_pic_desc *desc, fsdem_pic **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_result r;
    fsdem_pic *s;
    int a;
    if (out) *out = NULL;
    if (!desc || !out) return FSDEM_ERR_INVALID_ARG;
    r = fsdem__pic_check(desc, msg, sizeof msg);
    s = (fsdem_pic *)fsdem__object_new(r, msg, desc->log, desc->log_user, &desc->allocator, sizeof *s, "fsdem_pic_create", &r);
    if (!s) return r;
    s->desc = *desc;
    s->allocator = desc->allocator;
    s->bytes = sizeof *s;
    s->status.log = desc->log;
    s->status.log_user = desc->log_user;
    fsdem__claims_init(&s->claims, "PIC", fsdem__pic_claimable, 3);
    fsdem__pic_layout(s, desc);
    for (a = 0; a < s->dim && desc->log; ++a)
        if (fsdem__comp(s->hi, a) != fsdem__comp(desc->domain_max, a)) {
            snprintf(msg, sizeof msg, "fsdem_pic_create: domain_max.%c rounded from %.9g to %.9g m (%d cells of %g m)",
                     "xyz"[a], (double)fsdem__comp(desc->domain_max, a), (double)fsdem__comp(s->hi, a), s->n[a],
                     (double)s->dx);
            desc->log(desc->log_user, FSDEM_LOG_LEVEL_INFO, msg);
        }
    if (fsdem__pic_allocate(s) != FSDEM_OK) {
        snprintf(msg, sizeof msg, "fsdem_pic_create: out of memory allocating the %d x %d x %d grid", s->n[0], s->n[1],
                 s->n[2]);
        r = FSDEM_ERR_OUT_OF_MEMORY;
    } else if ((r = fsdem__pic_solvers(s)) != FSDEM_OK) {
        snprintf(msg, sizeof msg, "fsdem_pic_create: setting up the linear solvers failed (%s)", fsdem_result_string(r));
        r = r == FSDEM_ERR_INVALID_ARG ? FSDEM_ERR_INVALID_ARG : FSDEM_ERR_OUT_OF_MEMORY;
    }
    if (r != FSDEM_OK) {
        if (desc->log) desc->log(desc->log_user, FSDEM_LOG_LEVEL_ERROR, msg);
        fsdem_pic_destroy(s);
        return r;
    }
    s->coupling.dim = s->dim;
    for (a = 0; a < 3; ++a) {
        s->coupling.n[a] = s->n[a];
        s->coupling.face_count[a] = s->nface[a];
        s->coupling.open[a] = s->copen[a];
        s->coupling.solid_velocity[a] = s->cvel[a];
        s->coupling.acceleration[a] = s->cacc[a];
        s->coupling.shear[a] = s->shear[a];
        s->coupling.start_velocity[a] = s->cvstart[a];
    }
    s->coupling.pressure_rhs = s->crhs;
    s->coupling.reference = s->cref;
    s->coupling.porosity = s->cpor;
    fsdem__pic_static_flags(s);
    fsdem__pic_compute_fref(s);
    *out = s;
    fsdem__ok(&s->status);
    return FSDEM_OK;
}

/* splitmix64, uniform in [0, 1) */
static fsdem_real fsdem__pic_rand(fsdem_pic *s) {
    unsigned long long z = (s->rng += 0x9E3779B97F4A7C15ull);
    /* (the right shifts are written as divisions by powers of two, which keeps '>' '>' out of the
       grep map of the file) */
    z = (z ^ (z / 1073741824ull)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z / 134217728ull)) * 0x94D049BB133111EBull;
    z ^= z / 2147483648ull;
    return (fsdem_real)((double)(z / 2048ull) * (1.0 / 9007199254740992.0));
}
