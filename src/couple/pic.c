/* ===== >>impl_couple_pic : resolved PIC-DEM ==========================================================

   Contents: >>couple_pic_object (desc, creation, per-body storage), >>couple_pic_faces (bodies as
   moving cut-cell solids: face fractions, solid velocities, J, references), >>couple_pic_exchange
   (the implicit pressure term, fluid forces), >>couple_pic_gap (Eq. 20, particles out of bodies),
   >>couple_pic_step (its stages and verbs on the staged step of >>couple). The coupler speaks to
   the PIC through its public calls only: it indexes the grid through its own MAC layout (fsdem__mac, built from
   fsdem_pic_get_fields), writes the coupling arrays (fsdem_pic_get_coupling: the coupler owns open,
   solid_velocity, start_velocity and reference, and resets them at every cut) and cuts the faces
   with the cut-cell sampler of >>geom that the PIC cuts its obstacles with, so static obstacles and
   moving bodies are cut alike. */

/* ---- >>couple_pic_object : desc, creation, per-body storage ---- */

/* For every PIC cell, the items (bodies or contacts) whose box covers it: item[start[c] ..
   start[c + 1]). */
typedef struct fsdem__pic_dem_map {
    int *start; /* ncell + 1 */
    int *item;
    int item_cap;
} fsdem__pic_dem_map;

struct fsdem_pic_dem {
    fsdem_coupler head;            /* >>couple; its records are `load` once a step has loaded them */
    fsdem_pic_dem_desc desc;
    int dim;
    fsdem_real rho, nu;            /* liquid density, kinematic viscosity */
    fsdem_real depth;              /* m; the DEM's disc_length in 2D (the PIC works per metre), 1 in 3D */
    fsdem_vec3 gravity;            /* m/s^2 */
    fsdem__mac grid;               /* the PIC's layout, from fsdem_pic_get_fields */
    fsdem_pic_coupling arrays;     /* the PIC's coupling arrays (valid while it lives) */
    unsigned char side_closed[6];  /* the PIC's domain sides that are walls (not outflow) */
    /* per body (DEM particle), `bodies` of them */
    int bodies, body_cap;
    fsdem_pic_dem_force *load;     /* the record of each body: its id and volume from the last cut, */
                                   /*    its loads from the last step */
    fsdem_vec3 *vstar, *wstar;     /* predicted velocities Q* (step 1) */
    fsdem_real *inv_m, *inv_i;     /* 1/kg and 1/(kg m^2) per metre of depth (0: fixed) */
    fsdem_real *weight;            /* the volume seen over the exact one (desc.discrete_weight), else 1 */
    fsdem_real *relax;             /* s; viscous relaxation time (0: none) */
    /* faces each body covers or cuts: entries face_start[b] .. face_start[b + 1] */
    int *face_start;
    int *face;                     /* face index in its axis */
    unsigned char *face_axis;
    fsdem_real *face_closed;       /* 1 - E_b */
    int face_count, face_cap;
    /* J of each body: cells jac_start[b] .. jac_start[b + 1], linear and angular parts */
    int *jac_start, *jac_cell;
    fsdem_vec3 *jac_v, *jac_w;
    int jac_count, jac_cap;

    int *slot;                     /* per cell: entry of the current body's J, -1 */
    fsdem__pic_dem_map body_map, contact_map;
    fsdem_dem_contact *contact;    /* contacts after the last step, and their points (step 6) */
    fsdem_vec3 *contact_point;
    int contact_count, contact_cap;
    int operator_set;              /* the pressure term is installed */
    long long dissipated, pushed, removed;
    fsdem_real viscous_dt;
    fsdem_vec3 force_sum;
    int loaded;                    /* the loads of a step are in `load` */
};

static const fsdem__coupler_class *fsdem__pic_dem_class(void);

fsdem_pic_dem_desc fsdem_pic_dem_desc_default(void) {
    fsdem_pic_dem_desc d;
    memset(&d, 0, sizeof d);
    d.dissipation = (fsdem_real)0.5;
    d.contact_length = 0;
    d.viscous_dt_fraction = (fsdem_real)0.5;
    d.discrete_weight = 1;
    d.max_substeps = 100000;
    return d;
}

fsdem_result fsdem_pic_dem_desc_check(const fsdem_pic_dem_desc *d, char *msg, size_t size) {
    fsdem_pic_desc pd;
    if (!d) return fsdem__reject(msg, size, "fsdem_pic_dem_desc is NULL");
    if (!d->pic || !d->dem) return fsdem__reject(msg, size, "fsdem_pic_dem_desc.pic and .dem must both be set");
    pd = fsdem_pic_get_desc(d->pic);
    if (!(d->dissipation >= 0 && d->dissipation <= 1))
        return fsdem__reject(msg, size, "fsdem_pic_dem_desc.dissipation must be in [0, 1] (got %g)", (double)d->dissipation);
    if (!(d->contact_length >= 0 && d->contact_length <= fsdem__smallest_extent(pd.domain_min, pd.domain_max, pd.dim)))
        return fsdem__reject(msg, size,
                             "fsdem_pic_dem_desc.contact_length must be 0 (4 dx) or in (0, %g] m, the PIC domain's smallest extent (got %g m)",
                             (double)fsdem__smallest_extent(pd.domain_min, pd.domain_max, pd.dim), (double)d->contact_length);
    if (!(d->viscous_dt_fraction > 0 && d->viscous_dt_fraction <= 1))
        return fsdem__reject(msg, size, "fsdem_pic_dem_desc.viscous_dt_fraction must be in (0, 1] (got %g)",
                             (double)d->viscous_dt_fraction);
    if (d->discrete_weight != 0 && d->discrete_weight != 1)
        return fsdem__reject(msg, size, "fsdem_pic_dem_desc.discrete_weight must be 0 or 1 (got %d)", d->discrete_weight);
    if (fsdem__coupler_aperiodic("fsdem_pic_dem_desc", d->dem, "PIC", msg, size) != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    return fsdem__coupler_check(fsdem__pic_dem_class(), "fsdem_pic_dem_desc", d->pic, FSDEM_PIC_ARRAYS_SOLIDS, d->dem, pd.dim, pd.gravity,
                                d->max_substeps, msg, size);
}

static void fsdem__pic_dem_free_bodies(fsdem_pic_dem *c) {
    const fsdem_allocator *al = &c->head.allocator;
    const size_t n = (size_t)c->body_cap, V = sizeof(fsdem_vec3) * n, R = sizeof(fsdem_real) * n;
    fsdem__free(al, c->load, sizeof(fsdem_pic_dem_force) * n);
    fsdem__free(al, c->vstar, V);
    fsdem__free(al, c->wstar, V);
    fsdem__free(al, c->inv_m, R);
    fsdem__free(al, c->inv_i, R);
    fsdem__free(al, c->weight, R);
    fsdem__free(al, c->relax, R);
    fsdem__free(al, c->face_start, sizeof(int) * (n + 1));
    fsdem__free(al, c->jac_start, sizeof(int) * (n + 1));
    c->load = NULL;
    c->vstar = c->wstar = NULL;
    c->inv_m = c->inv_i = c->weight = c->relax = NULL;
    c->face_start = c->jac_start = NULL;
    c->body_cap = 0;
    c->head.record = NULL;
    c->head.records = 0;
}

/* Per-body arrays for `n` bodies (zeroed). Allocates only when the DEM has more particles than any
   step before; all of them or, out of memory, none (nothing changes). */
static fsdem_result fsdem__pic_dem_reserve_bodies(fsdem_pic_dem *c, int n) {
    const fsdem_allocator *al = &c->head.allocator;
    const size_t m = (size_t)(n > 0 ? n : 1), V = sizeof(fsdem_vec3) * m, R = sizeof(fsdem_real) * m;
    void **const arrays[9] = {(void **)&c->load,  (void **)&c->vstar,  (void **)&c->wstar,      (void **)&c->inv_m,    (void **)&c->inv_i,
                              (void **)&c->weight, (void **)&c->relax, (void **)&c->face_start, (void **)&c->jac_start};
    const size_t bytes[9] = {sizeof(fsdem_pic_dem_force) * m, V, V, R, R, R, R, sizeof(int) * (m + 1), sizeof(int) * (m + 1)};
    void *fresh[9];
    int k;
    if (n <= c->body_cap && c->vstar) return FSDEM_OK;
    for (k = 0; k < 9; ++k)
        if (!(fresh[k] = fsdem__alloc(al, bytes[k]))) {
            while (k-- > 0) fsdem__free(al, fresh[k], bytes[k]);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
    fsdem__pic_dem_free_bodies(c);
    for (k = 0; k < 9; ++k) {
        memset(fresh[k], 0, bytes[k]);
        *arrays[k] = fresh[k];
    }
    c->body_cap = (int)m;
    c->loaded = 0;
    return FSDEM_OK;
}

static void fsdem__pic_dem_release(fsdem_pic_dem *c) {
    const fsdem_allocator *al = &c->head.allocator;
    const int ncell = c->grid.ncell;
    fsdem__pic_dem_free_bodies(c);
    fsdem__free(al, c->face, sizeof(int) * (size_t)c->face_cap);
    fsdem__free(al, c->face_axis, (size_t)c->face_cap);
    fsdem__free(al, c->face_closed, sizeof(fsdem_real) * (size_t)c->face_cap);
    fsdem__free(al, c->jac_cell, sizeof(int) * (size_t)c->jac_cap);
    fsdem__free(al, c->jac_v, sizeof(fsdem_vec3) * (size_t)c->jac_cap);
    fsdem__free(al, c->jac_w, sizeof(fsdem_vec3) * (size_t)c->jac_cap);
    fsdem__free(al, c->slot, sizeof(int) * (size_t)ncell);
    fsdem__free(al, c->body_map.start, sizeof(int) * (size_t)(ncell + 1));
    fsdem__free(al, c->body_map.item, sizeof(int) * (size_t)c->body_map.item_cap);
    fsdem__free(al, c->contact_map.start, sizeof(int) * (size_t)(ncell + 1));
    fsdem__free(al, c->contact_map.item, sizeof(int) * (size_t)c->contact_map.item_cap);
    fsdem__free(al, c->contact, sizeof(fsdem_dem_contact) * (size_t)c->contact_cap);
    fsdem__free(al, c->contact_point, sizeof(fsdem_vec3) * (size_t)c->contact_cap);
}

static fsdem_result fsdem__pic_dem_faces(fsdem_pic_dem *c, fsdem_real dt);
static fsdem_result fsdem__pic_dem_exclude(fsdem_pic_dem *c, int from, int remove);
static void fsdem__pic_dem_clear_faces(fsdem_pic_dem *c);
static void fsdem__pic_dem_operator(void *user, const fsdem_real *p, fsdem_real *y);
static void fsdem__pic_dem_response(void *user, const fsdem_real *p, fsdem_real dt);

fsdem_result fsdem_pic_dem_create(const fsdem_pic_dem_desc *desc, fsdem_pic_dem **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_pic_dem *c;
    fsdem_pic_desc pd;
    fsdem_result res;
    int ncell, i;
    if (out) *out = NULL;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    res = fsdem_pic_dem_desc_check(desc, msg, sizeof msg);
    c = (fsdem_pic_dem *)fsdem__coupler_new(fsdem__pic_dem_class(), res, msg, desc ? desc->pic : NULL, desc ? desc->dem : NULL,
                                            FSDEM_PIC_ARRAYS_SOLIDS, desc ? desc->max_substeps : 0, desc ? desc->log : NULL,
                                            desc ? desc->log_user : NULL, sizeof *c, &res);
    if (!c) return res;
    pd = fsdem_pic_get_desc(desc->pic);
    c->desc = *desc;
    c->dim = pd.dim;
    c->rho = pd.density;
    c->nu = pd.viscosity;
    c->gravity = pd.gravity;
    c->depth = pd.dim == 2 ? fsdem_dem_get_desc(desc->dem).disc_length : 1;
    if (!(desc->contact_length > 0)) c->desc.contact_length = 4 * pd.cell_size; /* seed 000 §2.2.2 */
    {
        const fsdem_pic_fields g = fsdem_pic_get_fields(desc->pic);
        fsdem__mac_init(&c->grid, g.dim, g.n, g.cell_size, g.origin);
    }
    for (i = 0; i < 6; ++i) c->side_closed[i] = (unsigned char)(pd.boundary[i] != FSDEM_PIC_BC_OUTFLOW);
    c->arrays = fsdem_pic_get_coupling(desc->pic);
    ncell = c->grid.ncell;
    if (fsdem__coupler_particles_fit(&c->head, pd.domain_min, pd.domain_max, "fsdem_pic_dem_create") != FSDEM_OK) {
        fsdem__coupler_free(&c->head, sizeof *c);
        return FSDEM_ERR_INVALID_ARG;
    }
    c->slot = (int *)fsdem__alloc(&c->head.allocator, sizeof(int) * (size_t)ncell);
    c->body_map.start = (int *)fsdem__alloc(&c->head.allocator, sizeof(int) * (size_t)(ncell + 1));
    c->contact_map.start = (int *)fsdem__alloc(&c->head.allocator, sizeof(int) * (size_t)(ncell + 1));
    res = c->slot && c->body_map.start && c->contact_map.start ? FSDEM_OK : FSDEM_ERR_OUT_OF_MEMORY;
    if (res == FSDEM_OK) {
        for (i = 0; i < ncell; ++i) c->slot[i] = -1;
        res = fsdem__pic_dem_reserve_bodies(c, fsdem_dem_get_particles(desc->dem).count);
    }
    if (res == FSDEM_OK) res = fsdem__pic_dem_exclude(c, 0, 1);
    if (res == FSDEM_OK) res = fsdem__pic_dem_faces(c, 0);
    if (res == FSDEM_OK) res = fsdem_pic_set_pressure_extra(desc->pic, fsdem__pic_dem_operator, fsdem__pic_dem_response, c);
    if (res != FSDEM_OK) {
        if (desc->log && !c->head.status.message[0]) desc->log(desc->log_user, FSDEM_LOG_LEVEL_ERROR, "fsdem_pic_dem_create: out of memory");
        fsdem_pic_dem_destroy(c);
        return res;
    }
    c->operator_set = 1;
    *out = c;
    return FSDEM_OK;
}

void fsdem_pic_dem_destroy(fsdem_pic_dem *c) {
    if (!c) return;
    if (c->operator_set) fsdem_pic_set_pressure_extra(c->desc.pic, NULL, NULL, NULL);
    fsdem__pic_dem_clear_faces(c);
    fsdem__pic_dem_release(c);
    fsdem__coupler_free(&c->head, sizeof *c);
}

fsdem_coupler *fsdem_pic_dem_coupler(fsdem_pic_dem *c) { return c ? &c->head : NULL; }

const char *fsdem_pic_dem_last_error(const fsdem_pic_dem *c) { return c ? c->head.status.message : "fsdem_pic_dem is NULL"; }

fsdem_pic_dem_desc fsdem_pic_dem_get_desc(const fsdem_pic_dem *c) {
    fsdem_pic_dem_desc d;
    if (c) return c->desc;
    memset(&d, 0, sizeof d);
    return d;
}

/* ---- >>couple_pic_faces : bodies as moving cut-cell solids ---- */

/* A disc or sphere as a fsdem__geom_dist_fn. */
typedef struct fsdem__pic_dem_ball {
    fsdem_vec3 centre;
    fsdem_real radius;
} fsdem__pic_dem_ball;

static fsdem_real fsdem__pic_dem_ball_dist(const void *solid, fsdem_vec3 p) {
    const fsdem__pic_dem_ball *b = (const fsdem__pic_dem_ball *)solid;
    return fsdem__norm(fsdem__sub(p, b->centre)) - b->radius;
}

/* Index range [*lo, *hi] along axis q of the grid points at lo_q + (i + off) dx that lie within
   [x0, x1], clamped to 0 .. count - 1 (empty when *lo > *hi). */
static void fsdem__pic_dem_range(const fsdem__mac *grid, int q, fsdem_real off, fsdem_real x0, fsdem_real x1, int count, int *lo, int *hi) {
    const fsdem_real o = fsdem__comp(grid->lo, q);
    double a = ceil((double)((x0 - o) * grid->inv_dx - off)), b = floor((double)((x1 - o) * grid->inv_dx - off));
    *lo = a < 0 ? 0 : a > count ? count : (int)a;
    *hi = b >= count ? count - 1 : b < -1 ? -1 : (int)b;
}

/* The centre of face entry e relative to `centre` (m). */
static fsdem_vec3 fsdem__pic_dem_arm(const fsdem_pic_dem *c, int e, fsdem_vec3 centre) {
    const fsdem__mac *grid = &c->grid;
    const int a = c->face_axis[e], f = c->face[e];
    int idx[3];
    fsdem__mac_face_coords(grid, a, f, idx);
    return fsdem__sub(fsdem__mac_face_pos(grid, a, idx[0], idx[1], idx[2]), centre);
}

/* Adds `v`, `w` to cell `cell`'s entry of the J of the body being cut (entries from `first`). */
static fsdem_result fsdem__pic_dem_jac_add(fsdem_pic_dem *c, int cell, fsdem_vec3 v, fsdem_vec3 w) {
    int e = c->slot[cell];
    if (e < 0) {
        void **const arrays[3] = {(void **)&c->jac_cell, (void **)&c->jac_v, (void **)&c->jac_w};
        const size_t elem[3] = {sizeof(int), sizeof(fsdem_vec3), sizeof(fsdem_vec3)};
        if (fsdem__grow_set(&c->head.allocator, arrays, elem, 3, &c->jac_cap, c->jac_count, c->jac_count + 1) != FSDEM_OK)
            return FSDEM_ERR_OUT_OF_MEMORY;
        e = c->slot[cell] = c->jac_count++;
        c->jac_cell[e] = cell;
        c->jac_v[e] = c->jac_w[e] = fsdem__zero3();
    }
    c->jac_v[e] = fsdem__add(c->jac_v[e], v);
    c->jac_w[e] = fsdem__add(c->jac_w[e], w);
    return FSDEM_OK;
}

static fsdem_result fsdem__pic_dem_face_add(fsdem_pic_dem *c, int a, int f, fsdem_real closed) {
    void **const arrays[3] = {(void **)&c->face, (void **)&c->face_axis, (void **)&c->face_closed};
    const size_t elem[3] = {sizeof(int), 1, sizeof(fsdem_real)};
    if (fsdem__grow_set(&c->head.allocator, arrays, elem, 3, &c->face_cap, c->face_count, c->face_count + 1) != FSDEM_OK)
        return FSDEM_ERR_OUT_OF_MEMORY;
    c->face[c->face_count] = f;
    c->face_axis[c->face_count] = (unsigned char)a;
    c->face_closed[c->face_count] = closed;
    c->face_count++;
    return FSDEM_OK;
}

/* Resets the PIC's moving-solid arrays (open, at rest, full), all of them: the coupler owns them,
   and a restored PIC may hold another run's cut. */
static void fsdem__pic_dem_clear_faces(fsdem_pic_dem *c) {
    const fsdem_pic_coupling cp = fsdem_pic_get_coupling(c->desc.pic); /* also marks the PIC's cells for a recount */
    int a, e;
    for (a = 0; a < cp.dim; ++a) {
        for (e = 0; e < cp.face_count[a]; ++e) cp.open[a][e] = 1;
        memset(cp.solid_velocity[a], 0, sizeof(fsdem_real) * (size_t)cp.face_count[a]);
        memset(cp.start_velocity[a], 0, sizeof(fsdem_real) * (size_t)cp.face_count[a]);
    }
    for (e = 0; e < c->grid.ncell; ++e) cp.reference[e] = 1;
    c->face_count = 0;
}

/* Part of the fluid-fraction kernel of cell (i, j, k) (the tent over the 2^dim cells around its
   centre) outside the ball, sampled on 4 points per axis (the PIC samples its static obstacles'
   reference alike). */
static fsdem_real fsdem__pic_dem_kernel_open(const fsdem__mac *grid, const fsdem__pic_dem_ball *ball, int i, int j, int k) {
    const int S = 4;
    const fsdem_vec3 cc = fsdem__mac_cell_pos(grid, i, j, k);
    const fsdem_real h = 2 * grid->dx / (fsdem_real)S;
    fsdem_real open = 0, all = 0;
    int q[3], m;
    for (q[2] = 0; q[2] < (grid->dim == 3 ? S : 1); ++q[2])
        for (q[1] = 0; q[1] < S; ++q[1])
            for (q[0] = 0; q[0] < S; ++q[0]) {
                fsdem_vec3 p = cc;
                fsdem_real w = 1;
                for (m = 0; m < grid->dim; ++m) {
                    const fsdem_real off = -grid->dx + h * ((fsdem_real)q[m] + (fsdem_real)0.5);
                    w *= 1 - (fsdem_real)fabs(off) * grid->inv_dx;
                    p = fsdem__axis_shift(p, m, off);
                }
                all += w;
                if (fsdem__pic_dem_ball_dist(ball, p) > 0) open += w;
            }
    return open / all;
}

/* Cuts body b (step 2 of >>couple_pic): its faces (their closed parts, summed into the PIC's open
   fractions as pending negative values) and its references. */
static fsdem_result fsdem__pic_dem_cut(fsdem_pic_dem *c, int b, fsdem_vec3 centre, fsdem_real radius) {
    const fsdem__mac *grid = &c->grid;
    const fsdem_pic_coupling cp = c->arrays;
    const fsdem__pic_dem_ball ball = {centre, radius};
    const fsdem_real reach = grid->dx * (grid->dim == 3 ? (fsdem_real)0.7072 : (fsdem_real)0.5001), margin = radius + grid->dx;
    int a, q, lo[3], hi[3], idx[3];
    c->face_start[b] = c->face_count;
    for (a = 0; a < grid->dim; ++a) {
        for (q = 0; q < 3; ++q) {
            if (q < grid->dim)
                fsdem__pic_dem_range(grid, q, q == a ? 0 : (fsdem_real)0.5, fsdem__comp(centre, q) - margin, fsdem__comp(centre, q) + margin,
                                     grid->fn[a][q], &lo[q], &hi[q]);
            else lo[q] = hi[q] = 0;
        }
        for (idx[2] = lo[2]; idx[2] <= hi[2]; ++idx[2])
            for (idx[1] = lo[1]; idx[1] <= hi[1]; ++idx[1])
                for (idx[0] = lo[0]; idx[0] <= hi[0]; ++idx[0]) {
                    const int f = fsdem__mac_face(grid, a, idx[0], idx[1], idx[2]), coord = idx[a];
                    const fsdem_vec3 pf = fsdem__mac_face_pos(grid, a, idx[0], idx[1], idx[2]), arm = fsdem__sub(pf, centre);
                    const fsdem_real d = fsdem__norm(arm) - radius;
                    fsdem_real closed, *open = &cp.open[a][f];
                    if (d > reach) continue;
                    /* the domain's closed sides keep E = 0 and their own velocity (>>pic_cells) */
                    if ((coord == 0 || coord == grid->n[a]) && c->side_closed[2 * a + (coord != 0)]) continue;
                    if (d < -reach) closed = 1;
                    else {
                        fsdem_vec3 corner = fsdem__axis_shift(pf, (a + 1) % grid->dim, -grid->dx / 2);
                        if (grid->dim == 3) corner = fsdem__axis_shift(corner, (a + 2) % 3, -grid->dx / 2);
                        closed = 1 - fsdem__geom_face_fraction(grid->dim, a, corner, grid->dx, grid->surface_tol, fsdem__pic_dem_ball_dist, &ball);
                    }
                    if (!(closed > 0)) continue;
                    if (fsdem__pic_dem_face_add(c, a, f, closed) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
                    *open = *open >= 0 ? -closed : *open - closed; /* first body on this face, or the next */
                }
    }
    /* references of the cells whose kernel the body reaches */
    for (q = 0; q < 3; ++q) {
        if (q < grid->dim) fsdem__pic_dem_range(grid, q, (fsdem_real)0.5, fsdem__comp(centre, q) - margin, fsdem__comp(centre, q) + margin, grid->n[q], &lo[q], &hi[q]);
        else lo[q] = hi[q] = 0;
    }
    for (idx[2] = lo[2]; idx[2] <= hi[2]; ++idx[2])
        for (idx[1] = lo[1]; idx[1] <= hi[1]; ++idx[1])
            for (idx[0] = lo[0]; idx[0] <= hi[0]; ++idx[0]) {
                const int cell = fsdem__mac_cell(grid, idx[0], idx[1], idx[2]);
                const fsdem_real open = fsdem__pic_dem_kernel_open(grid, &ball, idx[0], idx[1], idx[2]);
                if (open < 1) cp.reference[cell] *= open; /* bodies do not overlap: their parts multiply */
            }
    return FSDEM_OK;
}

/* J of body b (step 3 of >>couple_pic) from the final closed parts of its faces: each face is the
   upper face of the cell below it (s = +1) and the lower face of the cell above it (s = -1). */
static fsdem_result fsdem__pic_dem_jacobian(fsdem_pic_dem *c, int b, fsdem_vec3 centre) {
    const fsdem__mac *grid = &c->grid;
    int e, idx[3];
    c->jac_start[b] = c->jac_count;
    for (e = c->face_start[b]; e < c->face_start[b + 1]; ++e) {
        const int a = c->face_axis[e], f = c->face[e];
        fsdem_vec3 ea = fsdem__axis_shift(fsdem__zero3(), a, c->face_closed[e]), arm, w;
        int coord;
        fsdem__mac_face_coords(grid, a, f, idx);
        coord = idx[a];
        arm = fsdem__sub(fsdem__mac_face_pos(grid, a, idx[0], idx[1], idx[2]), centre);
        w = fsdem__cross(arm, ea);
        if (coord > 0 &&
            fsdem__pic_dem_jac_add(c, fsdem__mac_cell(grid, idx[0] - (a == 0), idx[1] - (a == 1), idx[2] - (a == 2)), ea, w) != FSDEM_OK)
            return FSDEM_ERR_OUT_OF_MEMORY;
        if (coord < grid->n[a] &&
            fsdem__pic_dem_jac_add(c, fsdem__mac_cell(grid, idx[0], idx[1], idx[2]), fsdem__scale(ea, -1), fsdem__scale(w, -1)) != FSDEM_OK)
            return FSDEM_ERR_OUT_OF_MEMORY;
    }
    c->jac_start[b + 1] = c->jac_count;
    for (e = c->jac_start[b]; e < c->jac_count; ++e) c->slot[c->jac_cell[e]] = -1;
    return FSDEM_OK;
}

/* Faces that bodies leave open by less than this are closed: the projection controls only E u on a
   face, so the velocity of a sliver of a face (a gap between bodies, the edge of a body) would be
   free to spike. */
#define FSDEM__PIC_DEM_MIN_OPEN ((fsdem_real)0.02)

/* Steps 1-3 of >>couple_pic for a coming step of dt (0: the state only, at creation): every body
   cut into the PIC's coupling arrays, its volume as the faces see it, Q*, the solid velocities and
   J, then the viscous relaxation times. */
static fsdem_result fsdem__pic_dem_faces(fsdem_pic_dem *c, fsdem_real dt) {
    const fsdem__mac *grid = &c->grid;
    const fsdem_pic_coupling cp = c->arrays;
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    const fsdem_real inertia = c->dim == 3 ? (fsdem_real)0.4 : (fsdem_real)0.5; /* the DEM's spheres and discs */
    const fsdem_real visc = c->rho * c->nu * (c->dim == 3 ? grid->dx : 1);    /* >>pic_viscosity, per pair */
    const fsdem_real cell = grid->dx * grid->dx * (grid->dim == 3 ? grid->dx : 1), g2 = fsdem__dot(c->gravity, c->gravity);
    int b, e, q;
    fsdem_result res;
    if ((res = fsdem__pic_dem_reserve_bodies(c, P.count)) != FSDEM_OK)
        return fsdem__fail(&c->head.status, res, "fsdem_pic_dem: out of memory for the records of %d bodies", P.count);
    fsdem__pic_dem_clear_faces(c);
    /* the records hold the last step's loads of the bodies as they were then: a new cut retires
       them until its step's loads (fsdem__pic_dem_loads) */
    c->loaded = 0;
    c->head.records = 0;
    c->bodies = P.count;
    for (b = 0; b < P.count; ++b) c->load[b].id = P.id[b];
    for (b = 0; b < P.count; ++b)
        if ((res = fsdem__pic_dem_cut(c, b, P.position[b], P.radius[b])) != FSDEM_OK) {
            c->face_start[b + 1] = c->face_count;
            c->bodies = b + 1;
            for (q = 0; q <= c->bodies; ++q) c->jac_start[q] = 0;
            return fsdem__fail(&c->head.status, res, "fsdem_pic_dem: out of memory cutting body %d", b);
        }
    c->face_start[P.count] = c->face_count;
    /* the faces' closed parts are pending (open = -(their sum)): each body's part is scaled to the
       face's final closed part, slivers closed */
    for (e = 0; e < c->face_count; ++e) {
        const fsdem_real total = -cp.open[c->face_axis[e]][c->face[e]];
        const fsdem_real final_closed = total > 1 - FSDEM__PIC_DEM_MIN_OPEN ? 1 : total;
        c->face_closed[e] *= final_closed / total;
    }
    for (b = 0; b < P.count; ++b) {
        const fsdem_real m = P.mass[b], r = P.radius[b], I = inertia * m * r * r;
        const fsdem_real exact = (fsdem_real)FSDEM__PI * r * r * (c->dim == 3 ? (fsdem_real)4 / 3 * r : 1);
        fsdem_real axis[3] = {0, 0, 0}, seen = 0;
        for (e = c->face_start[b]; e < c->face_start[b + 1]; ++e) axis[c->face_axis[e]] += c->face_closed[e] * cell;
        /* the volume that a pressure gradient along gravity acts on: sum_a (g_a^2 / g^2) V_a */
        for (q = 0; q < c->dim; ++q) seen += g2 > 0 ? fsdem__comp(c->gravity, q) * fsdem__comp(c->gravity, q) / g2 * axis[q] : axis[q] / (fsdem_real)c->dim;
        c->load[b].volume = seen;
        c->weight[b] = c->desc.discrete_weight && seen > 0 ? seen / exact : 1;
        if (P.fixed[b]) {
            c->inv_m[b] = c->inv_i[b] = 0;
            c->vstar[b] = P.velocity[b];
            c->wstar[b] = P.angular_velocity[b];
        } else {
            c->inv_m[b] = c->depth / m;
            c->inv_i[b] = c->depth / I;
            c->vstar[b] = fsdem__add(P.velocity[b], fsdem__scale(fsdem__add(fsdem__scale(c->gravity, c->weight[b]), fsdem__scale(P.force[b], 1 / m)), dt));
            c->wstar[b] = fsdem__add(P.angular_velocity[b], fsdem__scale(P.torque[b], dt / I));
        }
        if (c->dim == 2) {
            c->vstar[b].z = 0;
            c->wstar[b].x = c->wstar[b].y = 0;
        }
        /* the solid fluxes: closed part times the body's velocity at the face centre, Q* for the
           projection and the start velocity for the viscous solve's no-slip and the FLIP reference */
        for (e = c->face_start[b]; e < c->face_start[b + 1]; ++e) {
            const int a = c->face_axis[e], f = c->face[e];
            const fsdem_vec3 arm = fsdem__pic_dem_arm(c, e, P.position[b]);
            cp.solid_velocity[a][f] += c->face_closed[e] * fsdem__comp(fsdem__add(c->vstar[b], fsdem__cross(c->wstar[b], arm)), a);
            cp.start_velocity[a][f] += c->face_closed[e] * fsdem__comp(fsdem__add(P.velocity[b], fsdem__cross(P.angular_velocity[b], arm)), a);
        }
    }
    /* open fractions, and the solid velocity as the closed-part-weighted mean */
    for (e = 0; e < c->face_count; ++e) {
        fsdem_real *open = &cp.open[c->face_axis[e]][c->face[e]];
        if (*open < 0) {
            const fsdem_real total = -*open, closed = total > 1 - FSDEM__PIC_DEM_MIN_OPEN ? 1 : total;
            cp.solid_velocity[c->face_axis[e]][c->face[e]] /= closed;
            cp.start_velocity[c->face_axis[e]][c->face[e]] /= closed;
            *open = 1 - closed;
        }
    }
    c->jac_count = 0;
    for (b = 0; b < P.count; ++b)
        if ((res = fsdem__pic_dem_jacobian(c, b, P.position[b])) != FSDEM_OK) {
            for (q = 0; q <= c->bodies; ++q) c->jac_start[q] = 0;
            c->jac_count = 0;
            return fsdem__fail(&c->head.status, res, "fsdem_pic_dem: out of memory for the J of body %d", b);
        }
    /* the viscous relaxation time: the fastest component of the viscous solve's pull, visc per
       (closed face, open neighbour) pair (>>pic_viscosity) */
    c->viscous_dt = 0;
    for (b = 0; b < c->bodies; ++b) {
        int pairs[3] = {0, 0, 0}, most = 0;
        for (e = c->face_start[b]; e < c->face_start[b + 1]; ++e) {
            const int a = c->face_axis[e], f = c->face[e];
            if (cp.open[a][f] > 0) continue;
            int idx[3];
            fsdem__mac_face_coords(grid, a, f, idx);
            for (q = 0; q < grid->dim; ++q) {
                const int coord = idx[q];
                if (coord > 0 && cp.open[a][f - grid->fstep[a][q]] > 0) pairs[a]++;
                if (coord + 1 < grid->fn[a][q] && cp.open[a][f + grid->fstep[a][q]] > 0) pairs[a]++;
            }
        }
        for (q = 0; q < grid->dim; ++q)
            if (pairs[q] > most) most = pairs[q];
        c->relax[b] = 0;
        if (visc > 0 && most > 0 && c->inv_m[b] > 0) {
            /* translation m / (visc pairs); rotation I / (visc pairs r^2) is shorter (I < m r^2) */
            const fsdem_real mr = c->depth / c->inv_m[b] < c->depth / (c->inv_i[b] * P.radius[b] * P.radius[b])
                                      ? c->depth / c->inv_m[b]
                                      : c->depth / (c->inv_i[b] * P.radius[b] * P.radius[b]);
            c->relax[b] = mr / (c->depth * visc * (fsdem_real)most);
            if (c->viscous_dt == 0 || c->relax[b] < c->viscous_dt) c->viscous_dt = c->relax[b];
        }
    }
    return FSDEM_OK;
}

/* ---- >>couple_pic_exchange : the implicit pressure term, fluid forces ---- */

/* The accelerations M^-1 G, G = dx^(dim-1) J^T p over the FLUID cells, that the pressure p gives
   free body b (m/s^2, 1/s^2). */
static void fsdem__pic_dem_accelerations(const fsdem_pic_dem *c, int b, const unsigned char *type, const fsdem_real *p, fsdem_vec3 *acc,
                                         fsdem_vec3 *alpha) {
    const fsdem__mac *grid = &c->grid;
    const fsdem_real area = grid->dim == 3 ? grid->dx * grid->dx : grid->dx;
    fsdem_vec3 G = fsdem__zero3(), T = fsdem__zero3();
    int e;
    for (e = c->jac_start[b]; e < c->jac_start[b + 1]; ++e) {
        const int cell = c->jac_cell[e];
        if (type[cell] != FSDEM_STENCIL_CELL_FLUID) continue;
        G = fsdem__madd(G, c->jac_v[e], p[cell]);
        T = fsdem__madd(T, c->jac_w[e], p[cell]);
    }
    *acc = fsdem__scale(G, area * c->inv_m[b]);
    *alpha = fsdem__scale(T, area * c->inv_i[b]);
}

/* y += rho dx^dim J M^-1 J^T p over the FLUID cells (step 3 of >>couple_pic), per metre in 2D. */
static void fsdem__pic_dem_operator(void *user, const fsdem_real *p, fsdem_real *y) {
    const fsdem_pic_dem *c = (const fsdem_pic_dem *)user;
    const fsdem__mac *grid = &c->grid;
    const unsigned char *type = fsdem_pic_get_fields(c->desc.pic).cell;
    /* with acc = M^-1 G the term is rho dx J . acc */
    const fsdem_real k = c->rho * grid->dx;
    int b, e;
    for (b = 0; b < c->bodies; ++b) {
        fsdem_vec3 acc, alpha;
        if (c->inv_m[b] == 0) continue;
        fsdem__pic_dem_accelerations(c, b, type, p, &acc, &alpha);
        for (e = c->jac_start[b]; e < c->jac_start[b + 1]; ++e) {
            const int cell = c->jac_cell[e];
            if (type[cell] != FSDEM_STENCIL_CELL_FLUID) continue;
            y[cell] += k * (fsdem__dot(c->jac_v[e], acc) + fsdem__dot(c->jac_w[e], alpha));
        }
    }
}

/* The pressure's answer (fsdem_pic_response_fn, step 3 of >>couple_pic): each free body's velocity
   moves from Q* by dt M^-1 G, the velocity that the implicit term solved for (seed 000 Eq. 6), and
   its faces' solid velocity with it, so the PIC's fluxes, extrapolation and transfer to the
   particles see the body as it ends the step (not its Q*, which holds the step's gravity). */
static void fsdem__pic_dem_response(void *user, const fsdem_real *p, fsdem_real dt) {
    const fsdem_pic_dem *c = (const fsdem_pic_dem *)user;
    const unsigned char *type = fsdem_pic_get_fields(c->desc.pic).cell;
    const fsdem_pic_coupling *cp = &c->arrays; /* mid-step: fsdem_pic_get_coupling would mark the cells for a recount */
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    int b, e;
    for (b = 0; b < c->bodies; ++b) {
        fsdem_vec3 acc, alpha;
        if (c->inv_m[b] == 0) continue;
        fsdem__pic_dem_accelerations(c, b, type, p, &acc, &alpha);
        for (e = c->face_start[b]; e < c->face_start[b + 1]; ++e) {
            const int a = c->face_axis[e], f = c->face[e];
            const fsdem_vec3 dv = fsdem__add(acc, fsdem__cross(alpha, fsdem__pic_dem_arm(c, e, P.position[b])));
            cp->solid_velocity[a][f] += dt * c->face_closed[e] * fsdem__comp(dv, a) / (1 - cp->open[a][f]);
        }
    }
}

/* Step 4 of >>couple_pic after the PIC step: the pressure force G and the viscous force of every
   body from the step's pressure and shear, given to the DEM as held external loads. */
static fsdem_result fsdem__pic_dem_loads(fsdem_pic_dem *c) {
    const fsdem__mac *grid = &c->grid;
    const fsdem_pic_coupling cp = c->arrays;
    const fsdem_pic_fields g = fsdem_pic_get_fields(c->desc.pic);
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    fsdem_dem_coupling dc = fsdem_dem_get_coupling(c->desc.dem);
    const fsdem_real area = grid->dim == 3 ? grid->dx * grid->dx : grid->dx;
    int b, e;
    c->force_sum = fsdem__zero3();
    for (b = 0; b < c->bodies; ++b) {
        fsdem_vec3 G = fsdem__zero3(), T = fsdem__zero3(), F = fsdem__zero3(), Tv = fsdem__zero3();
        for (e = c->jac_start[b]; e < c->jac_start[b + 1]; ++e) {
            G = fsdem__madd(G, c->jac_v[e], g.pressure[c->jac_cell[e]]);
            T = fsdem__madd(T, c->jac_w[e], g.pressure[c->jac_cell[e]]);
        }
        for (e = c->face_start[b]; e < c->face_start[b + 1] && cp.shear[0]; ++e) {
            const int a = c->face_axis[e], f = c->face[e];
            const fsdem_real closed = 1 - cp.open[a][f], share = closed > c->face_closed[e] ? c->face_closed[e] / closed : 1;
            const fsdem_real v = cp.shear[a][f] * share;
            const fsdem_vec3 force = fsdem__axis_shift(fsdem__zero3(), a, v);
            if (v == 0) continue;
            F = fsdem__add(F, force);
            Tv = fsdem__add(Tv, fsdem__cross(fsdem__pic_dem_arm(c, e, P.position[b]), force));
        }
        fsdem_pic_dem_force *r = &c->load[b];
        r->pressure_force = fsdem__scale(G, area * c->depth);
        r->viscous_force = fsdem__scale(F, c->depth);
        r->torque = fsdem__scale(fsdem__add(fsdem__scale(T, area), Tv), c->depth);
        r->faces = c->face_start[b + 1] - c->face_start[b];
        if (!fsdem__finite3(r->pressure_force) || !fsdem__finite3(r->viscous_force) || !fsdem__finite3(r->torque))
            return fsdem__fail(&c->head.status, FSDEM_ERR_NAN, "fsdem_pic_dem: the fluid force on body %d is not finite", b);
        c->force_sum = fsdem__add(c->force_sum, fsdem__add(r->pressure_force, r->viscous_force));
        if (dc.count > b) {
            /* the well-balanced weight's correction (item 8 of >>couple_pic; 0 for fixed bodies) */
            r->weight_correction = P.fixed[b] ? fsdem__zero3() : fsdem__scale(c->gravity, P.mass[b] * (c->weight[b] - 1));
            dc.force[b] = fsdem__add(fsdem__add(r->pressure_force, r->viscous_force), r->weight_correction);
            dc.torque[b] = r->torque;
        }
    }
    c->loaded = 1;
    c->head.record = c->load;
    c->head.records = c->bodies;
    return FSDEM_OK;
}

fsdem_result fsdem_pic_dem_get_force(const fsdem_pic_dem *c, int index, fsdem_pic_dem_force *out) {
    return c ? fsdem__coupler_get_record(&c->head, index, out, "fsdem_pic_dem_get_force") : FSDEM_ERR_INVALID_ARG;
}

fsdem_result fsdem_pic_dem_write_csv(const fsdem_pic_dem *c, const char *path) {
    return c ? fsdem__coupler_write_csv(&c->head, path, "fsdem_pic_dem_write_csv") : FSDEM_ERR_INVALID_ARG;
}

fsdem_pic_dem_stats fsdem_pic_dem_get_stats(const fsdem_pic_dem *c) {
    fsdem_pic_dem_stats st;
    memset(&st, 0, sizeof st);
    if (!c) return st;
    st.coupling = fsdem__coupler_stats(&c->head);
    st.fluid_force = c->force_sum;
    st.viscous_dt = c->viscous_dt;
    st.contacts = c->contact_count;
    st.dissipated = c->dissipated;
    st.pushed = c->pushed;
    st.removed = c->removed;
    return st;
}

/* ---- >>couple_pic_gap : Eq. 20, particles out of bodies ---- */

/* Builds the cell map of `count` boxes [centre_i - half_i, centre_i + half_i]. */
static fsdem_result fsdem__pic_dem_map_build(fsdem_pic_dem *c, fsdem__pic_dem_map *map, int count, const fsdem_vec3 *centre,
                                             const fsdem_real *half, fsdem_real half_all) {
    const fsdem__mac *grid = &c->grid;
    int pass, i, q, lo[3], hi[3], idx[3], total = 0;
    memset(map->start, 0, sizeof(int) * (size_t)(grid->ncell + 1));
    for (pass = 0; pass < 2; ++pass) {
        for (i = 0; i < count; ++i) {
            const fsdem_real h = half ? half[i] : half_all;
            for (q = 0; q < 3; ++q) {
                if (q < grid->dim) fsdem__pic_dem_range(grid, q, (fsdem_real)0.5, fsdem__comp(centre[i], q) - h - grid->dx / 2,
                                                     fsdem__comp(centre[i], q) + h + grid->dx / 2, grid->n[q], &lo[q], &hi[q]);
                else lo[q] = hi[q] = 0;
            }
            for (idx[2] = lo[2]; idx[2] <= hi[2]; ++idx[2])
                for (idx[1] = lo[1]; idx[1] <= hi[1]; ++idx[1])
                    for (idx[0] = lo[0]; idx[0] <= hi[0]; ++idx[0]) {
                        const int cell = fsdem__mac_cell(grid, idx[0], idx[1], idx[2]);
                        if (pass == 0) map->start[cell + 1]++;
                        else map->item[map->start[cell]++] = i;
                    }
        }
        if (pass == 0) {
            for (i = 0; i < grid->ncell; ++i) map->start[i + 1] += map->start[i];
            total = map->start[grid->ncell];
            if (fsdem__grow(&c->head.allocator, (void **)&map->item, &map->item_cap, 0, total > 0 ? total : 1, sizeof(int)) != FSDEM_OK)
                return FSDEM_ERR_OUT_OF_MEMORY;
        }
    }
    /* the second pass advanced every start to the next cell's: shift back */
    for (i = grid->ncell; i > 0; --i) map->start[i] = map->start[i - 1];
    map->start[0] = 0;
    return FSDEM_OK;
}

/* The bodies as one solid for fsdem_pic_exclude_particles (`user` is the coupler). */
static fsdem_real fsdem__pic_dem_solid(void *user, fsdem_vec3 p, fsdem_vec3 *normal) {
    const fsdem_pic_dem *c = (const fsdem_pic_dem *)user;
    const int cell = fsdem__mac_cell_of(&c->grid, p);
    fsdem_dem_particles P;
    fsdem_real best = (fsdem_real)1e30;
    int e;
    *normal = fsdem_v3(1, 0, 0);
    if (c->body_map.start[cell] == c->body_map.start[cell + 1]) return best; /* most particles: no body near */
    P = fsdem_dem_get_particles(c->desc.dem);
    for (e = c->body_map.start[cell]; e < c->body_map.start[cell + 1]; ++e) {
        const int b = c->body_map.item[e];
        const fsdem_vec3 r = fsdem__sub(p, P.position[b]);
        const fsdem_real len = fsdem__norm(r), d = len - P.radius[b];
        if (d < best) {
            best = d;
            *normal = len > 0 ? fsdem__scale(r, 1 / len) : fsdem_v3(0, 1, 0);
        }
    }
    return best;
}

/* Step 7 of >>couple_pic: particles inside bodies `from` .. are moved out (remove = 0) or removed. */
static fsdem_result fsdem__pic_dem_exclude(fsdem_pic_dem *c, int from, int remove) {
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    int moved = 0, e;
    fsdem_result res;
    if (from >= P.count) return FSDEM_OK;
    if (fsdem__pic_dem_map_build(c, &c->body_map, P.count - from, P.position + from, P.radius + from, 0) != FSDEM_OK)
        return fsdem__fail(&c->head.status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_dem: out of memory mapping the bodies");
    for (e = 0; e < c->body_map.start[c->grid.ncell] && from > 0; ++e) c->body_map.item[e] += from;
    res = fsdem_pic_exclude_particles(c->desc.pic, fsdem__pic_dem_solid, c, remove, &moved);
    if (res != FSDEM_OK) return fsdem__fail(&c->head.status, res, "fsdem_pic_dem: %s", fsdem_pic_last_error(c->desc.pic));
    if (remove) c->removed += moved;
    else c->pushed += moved;
    return FSDEM_OK;
}

/* Step 6 of >>couple_pic: Eq. 20 in the contact area of every contact of the DEM's positions. */
static fsdem_result fsdem__pic_dem_gap(fsdem_pic_dem *c) {
    const fsdem_real beta = c->desc.dissipation, half = c->desc.contact_length / 2;
    const fsdem_real offset = fsdem_dem_get_desc(c->desc.dem).contact_offset;
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    const fsdem_pic_particles W = fsdem_pic_get_particles(c->desc.pic);
    const fsdem__mac *grid = &c->grid;
    int n = fsdem_dem_contacts(c->desc.dem, NULL, 0), k, p, e;
    if (n < 0) return fsdem__fail(&c->head.status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_dem: out of memory listing contacts");
    if (n > c->contact_cap) {
        const size_t old = (size_t)c->contact_cap;
        fsdem__free(&c->head.allocator, c->contact, sizeof(fsdem_dem_contact) * old);
        fsdem__free(&c->head.allocator, c->contact_point, sizeof(fsdem_vec3) * old);
        c->contact_cap = 0;
        c->contact = (fsdem_dem_contact *)fsdem__alloc(&c->head.allocator, sizeof(fsdem_dem_contact) * (size_t)n);
        c->contact_point = (fsdem_vec3 *)fsdem__alloc(&c->head.allocator, sizeof(fsdem_vec3) * (size_t)n);
        if (!c->contact || !c->contact_point) {
            fsdem__free(&c->head.allocator, c->contact, sizeof(fsdem_dem_contact) * (size_t)n);
            fsdem__free(&c->head.allocator, c->contact_point, sizeof(fsdem_vec3) * (size_t)n);
            c->contact = NULL;
            c->contact_point = NULL;
            return fsdem__fail(&c->head.status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_dem: out of memory listing contacts");
        }
        c->contact_cap = n;
    }
    c->contact_count = n = n > 0 ? fsdem_dem_contacts(c->desc.dem, c->contact, c->contact_cap) : 0;
    if (beta >= 1 || n == 0) return FSDEM_OK;
    /* the contact point: the middle of the gap between the real surfaces, offset - overlap wide */
    for (k = 0; k < n; ++k) {
        const fsdem_dem_contact *ct = &c->contact[k];
        c->contact_point[k] = fsdem__madd(P.position[ct->i], ct->normal, -(P.radius[ct->i] + (offset - ct->overlap) / 2));
    }
    if (fsdem__pic_dem_map_build(c, &c->contact_map, n, c->contact_point, NULL, half) != FSDEM_OK)
        return fsdem__fail(&c->head.status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_dem: out of memory mapping the contacts");
    for (p = 0; p < W.count; ++p) {
        const int cell = fsdem__mac_cell_of(grid, W.position[p]);
        for (e = c->contact_map.start[cell]; e < c->contact_map.start[cell + 1]; ++e) {
            const int q = c->contact_map.item[e];
            const fsdem_vec3 rel = fsdem__sub(W.position[p], c->contact_point[q]), nrm = c->contact[q].normal;
            const fsdem_real sn = fsdem__dot(rel, nrm), t = fsdem__norm(fsdem__madd(rel, nrm, -sn));
            if ((fsdem_real)fabs(sn) > half || t > half) continue;
            W.velocity[p] = fsdem__scale(W.velocity[p], beta + (1 - beta) * t / half); /* Eq. 20, C of Fig. 3 */
            c->dissipated++;
        }
    }
    return FSDEM_OK;
}

/* ---- >>couple_pic_step : its stages and verbs ---- */

/* The fastest surface speed of a body, |V| + |w| r (m/s), and the body; -1 when one is not finite. */
static fsdem_real fsdem__pic_dem_fastest(const fsdem_dem_particles *P, int *which) {
    fsdem_real vmax = 0;
    int b;
    *which = -1;
    for (b = 0; b < P->count; ++b) {
        const fsdem_real v = fsdem__norm(P->velocity[b]) + fsdem__norm(P->angular_velocity[b]) * P->radius[b];
        *which = b;
        if (!fsdem__finite(v)) return -1;
        if (v > vmax) vmax = v;
    }
    return vmax;
}

/* The stable step's limits of the bodies (>>couple_pic, fsdem_pic_dem_stable_dt): their speed
   over the PIC's cfl, and the viscous limit of the last cut (the class's limit). */
static fsdem_result fsdem__pic_dem_limit(const fsdem_coupler *head, fsdem_real *dt) {
    const fsdem_pic_dem *c = (const fsdem_pic_dem *)(const void *)head;
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    const fsdem_pic_desc pd = fsdem_pic_get_desc(c->desc.pic);
    int b;
    const fsdem_real vmax = fsdem__pic_dem_fastest(&P, &b);
    fsdem_real body;
    if (vmax < 0) return fsdem__fail((fsdem__status *)&head->status, FSDEM_ERR_NAN, "fsdem_pic_dem: body %d has a non-finite velocity", b);
    body = pd.cfl * pd.cell_size / (vmax + (fsdem_real)sqrt(fsdem__norm(pd.gravity) * pd.cell_size));
    if (body < *dt) *dt = body;
    if (c->viscous_dt > 0 && c->desc.viscous_dt_fraction * c->viscous_dt < *dt) *dt = c->desc.viscous_dt_fraction * c->viscous_dt;
    return FSDEM_OK;
}

/* A step of dt refused before the cut changes the PIC's coupling arrays: too many substeps, a body
   that no longer fits, a body moving more than cfl_max cells, the viscous limit of the last cut (the
   one fsdem_pic_dem_stable_dt gave; the new cut may be a little stricter: the step it limits is the
   next), the PIC's own refusal. */
static fsdem_result fsdem__pic_dem_check(fsdem_coupler *head, fsdem_real dt, int chosen) {
    fsdem_pic_dem *c = (fsdem_pic_dem *)(void *)head;
    const fsdem_pic_desc pd = fsdem_pic_get_desc(c->desc.pic);
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    fsdem_result res;
    int b;
    (void)chosen;
    if ((res = fsdem__coupler_substeps_within(head, dt)) != FSDEM_OK) return res;
    if ((res = fsdem__coupler_particles_fit(head, pd.domain_min, pd.domain_max, "fsdem_pic_dem")) != FSDEM_OK) return res;
    for (b = 0; b < P.count; ++b) {
        const fsdem_real v = fsdem__norm(P.velocity[b]) + fsdem__norm(P.angular_velocity[b]) * P.radius[b];
        if (v * dt > pd.cfl_max * pd.cell_size)
            return fsdem__fail(&head->status, FSDEM_ERR_CFL, "fsdem_pic_dem: body %d at %g m/s moves %g cells in dt = %g s (cfl_max %g)", b,
                               (double)v, (double)(v * dt / pd.cell_size), (double)dt, (double)pd.cfl_max);
    }
    if (c->viscous_dt > 0 && dt > c->desc.viscous_dt_fraction * c->viscous_dt * (1 + (fsdem_real)1e-6))
        return fsdem__fail(&head->status, FSDEM_ERR_CFL,
                           "fsdem_pic_dem: dt = %g s exceeds viscous_dt_fraction %g of the shortest viscous relaxation time %g s",
                           (double)dt, (double)c->desc.viscous_dt_fraction, (double)c->viscous_dt);
    if ((res = fsdem_pic_check_dt(c->desc.pic, dt)) != FSDEM_OK)
        return fsdem__fail(&head->status, res, "fsdem_pic_dem: PIC step: %s", fsdem_pic_last_error(c->desc.pic));
    return FSDEM_OK;
}

/* Step 7 of >>couple_pic for bodies added since the last cut: the water particles inside them go. */
static fsdem_result fsdem__pic_dem_new_bodies(fsdem_coupler *head, fsdem_real dt) {
    fsdem_pic_dem *c = (fsdem_pic_dem *)(void *)head;
    (void)dt;
    return fsdem_dem_get_particles(c->desc.dem).count > c->bodies ? fsdem__pic_dem_exclude(c, c->bodies, 1) : FSDEM_OK;
}

static fsdem_result fsdem__pic_dem_cut_stage(fsdem_coupler *head, fsdem_real dt) {
    return fsdem__pic_dem_faces((fsdem_pic_dem *)(void *)head, dt);
}

static fsdem_result fsdem__pic_dem_loads_stage(fsdem_coupler *head, fsdem_real dt) {
    (void)dt;
    return fsdem__pic_dem_loads((fsdem_pic_dem *)(void *)head);
}

static fsdem_result fsdem__pic_dem_substeps(fsdem_coupler *head, fsdem_real dt) {
    return fsdem__coupler_substeps(head, dt, NULL, NULL, NULL);
}

/* Steps 6-7 of >>couple_pic at the bodies' new positions. */
static fsdem_result fsdem__pic_dem_gap_stage(fsdem_coupler *head, fsdem_real dt) {
    fsdem_pic_dem *c = (fsdem_pic_dem *)(void *)head;
    fsdem_result res = fsdem__pic_dem_gap(c);
    (void)dt;
    return res == FSDEM_OK ? fsdem__pic_dem_exclude(c, 0, 0) : res;
}

static const fsdem__stage fsdem__pic_dem_stages[6] = {
    {"new bodies", FSDEM__CLOCK_COUPLING, fsdem__pic_dem_new_bodies}, {"cut", FSDEM__CLOCK_COUPLING, fsdem__pic_dem_cut_stage},
    {"PIC step", FSDEM__CLOCK_FLUID, NULL},                          {"loads", FSDEM__CLOCK_COUPLING, fsdem__pic_dem_loads_stage},
    {"DEM substeps", FSDEM__CLOCK_DEM, fsdem__pic_dem_substeps},     {"gap", FSDEM__CLOCK_COUPLING, fsdem__pic_dem_gap_stage}};

#define FSDEM__PIC_DEM_FIELD(name, kind, saved) FSDEM__FIELD(fsdem_pic_dem_force, name, #name, kind, saved)
static const fsdem__field fsdem__pic_dem_fields[7] = {
    FSDEM__PIC_DEM_FIELD(id, INT, 1),      FSDEM__PIC_DEM_FIELD(pressure_force, VEC3, 1), FSDEM__PIC_DEM_FIELD(viscous_force, VEC3, 1),
    FSDEM__PIC_DEM_FIELD(torque, VEC3, 1), FSDEM__PIC_DEM_FIELD(weight_correction, VEC3, 1), FSDEM__PIC_DEM_FIELD(volume, REAL, 1),
    FSDEM__PIC_DEM_FIELD(faces, INT, 0)};
#undef FSDEM__PIC_DEM_FIELD

static const fsdem__coupler_class *fsdem__pic_dem_class(void) {
    static const fsdem__coupler_class cls = {"fsdem_pic_dem", &fsdem__fluid_pic, sizeof(fsdem_pic_dem_force),
        fsdem__pic_dem_fields, 7, NULL, fsdem__pic_dem_limit, fsdem__pic_dem_check, fsdem__pic_dem_stages, 6};
    return &cls;
}

fsdem_result fsdem_pic_dem_update(fsdem_pic_dem *c) {
    fsdem_result res;
    if (!c) return FSDEM_ERR_INVALID_ARG;
    if ((res = fsdem__pic_dem_new_bodies(&c->head, 0)) == FSDEM_OK && (res = fsdem__pic_dem_faces(c, 0)) == FSDEM_OK) fsdem__ok(&c->head.status);
    return res;
}

double fsdem_pic_dem_time(const fsdem_pic_dem *c) { return c ? fsdem__coupler_time(&c->head) : 0; }
