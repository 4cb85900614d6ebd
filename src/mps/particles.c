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
    if (!fsdem__finite3(x) || !fsdem__within(v, FSDEM_MAX_SPEED))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "%s: particle %d has a non-finite position or a velocity (%g, %g, %g) m/s above FSDEM_MAX_SPEED (%g m/s)", fn,
                           j, (double)v.x, (double)v.y, (double)v.z, (double)FSDEM_MAX_SPEED);
    for (a = 0; a < s->dim; ++a)
        if (!s->desc.periodic[a] &&
            !(fsdem__comp(x, a) >= fsdem__comp(s->desc.domain_min, a) && fsdem__comp(x, a) <= fsdem__comp(s->desc.domain_max, a)))
            return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_DOMAIN, "%s: particle %d at (%g, %g, %g) m is outside the domain", fn,
                               j, (double)x.x, (double)x.y, (double)x.z);
    return FSDEM_OK;
}

/* Brings x into the domain along the periodic axes. */
static void fsdem__mps_wrap(const fsdem_mps *s, fsdem_vec3 *x) {
    int a;
    for (a = 0; a < s->dim && s->periods.any; ++a)
        fsdem__wrap_axis(&s->periods, a, fsdem__comp(s->desc.domain_min, a), fsdem__comp(s->desc.domain_max, a), x);
}

/* Appends one particle (room reserved, point checked), its position wrapped into the domain. */
static void fsdem__mps_push(fsdem_mps *s, fsdem_mps_kind kind, fsdem_vec3 x, fsdem_vec3 v) {
    const int i = s->n++;
    if (s->dim == 2) x.z = v.z = 0;
    fsdem__mps_wrap(s, &x);
    s->x[i] = x;
    s->v[i] = kind == FSDEM_MPS_KIND_FLUID ? v : fsdem__zero3();
    s->us[i] = s->v[i];
    s->shift[i] = fsdem__zero3();
    s->p[i] = 0;
    s->eps[i] = 1;
    s->nd[i] = 0;
    s->rho[i] = 0; /* set by the explicit scheme's hydrostatic start */
    s->fext[i] = s->gradp[i] = fsdem__zero3();
    s->kind[i] = (unsigned char)kind;
    s->surf[i] = 0;
    s->body[i] = -1;
    s->inlet[i] = -1;
    s->unknown[i] = -1;
    s->counts[kind]++;
    s->rows_valid = 0;
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

fsdem_result fsdem_mps_reserve(fsdem_mps *s, int count) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (count < 0) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_reserve: count = %d < 0", count);
    if (count > (1 << 29) - s->n - s->buffered || fsdem__mps_reserve(s, s->n + s->buffered + count) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps_reserve: no memory for %d particles",
                           s->n + s->buffered + count);
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
        const double first = ceil(((double)fsdem__comp(from, a) - l) / r0 - 0.5 - 1e-9), last = floor(((double)fsdem__comp(to, a) - l) / r0 - 0.5 + 1e-9);
        /* bounded before the conversion to int, which would overflow first */
        if (a < s->dim && !(last - first <= 1e7 && fabs(first) <= 1e9 && fabs(last) <= 1e9))
            return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "%s: the box holds too many lattice points", fn);
        i0[a] = a < s->dim ? (int)first : 0;
        i1[a] = a < s->dim ? (int)last : 0;
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
static int fsdem__mps_layer_outside(const fsdem_mps *s, fsdem_vec3 lo, fsdem_vec3 hi, unsigned open, fsdem_vec3 p) {
    fsdem_real worst = 0;
    int a;
    for (a = 0; a < s->dim; ++a) {
        const fsdem_real x = fsdem__comp(p, a), l = fsdem__comp(lo, a), h = fsdem__comp(hi, a);
        const fsdem_real out = x < l ? l - x : x > h ? x - h : 0;
        if (out > 0 && (open & (1u << (2 * a + (x > h))))) return -1;
        if (out > worst) worst = out;
    }
    return worst > 0 ? (int)ceil((double)(worst / s->r0) - 1e-6) : 0;
}

/* Depth of p inside the box in layers: 1 for the outer layer, 0 outside. */
static int fsdem__mps_layer_inside(const fsdem_mps *s, fsdem_vec3 lo, fsdem_vec3 hi, fsdem_vec3 p) {
    fsdem_real depth = -1;
    int a;
    for (a = 0; a < s->dim; ++a) {
        const fsdem_real x = fsdem__comp(p, a), l = fsdem__comp(lo, a), h = fsdem__comp(hi, a);
        const fsdem_real in = x - l < h - x ? x - l : h - x;
        if (!(in > 0)) return 0;
        if (depth < 0 || in < depth) depth = in;
    }
    return (int)ceil((double)(depth / s->r0) - 1e-6);
}

/* Room for one more entry in a list of n entries of `elem` bytes (obstacles, inflows, outflows),
   grown by doubling; 0 when out of memory. */
static int fsdem__mps_list_room(fsdem_mps *s, void **list, int *cap, int n, size_t elem) {
    const int fresh_cap = *cap ? 2 * *cap : 4;
    void *fresh;
    if (n < *cap) return 1;
    if (!(fresh = fsdem__alloc(&s->allocator, elem * (size_t)fresh_cap))) return 0;
    if (n) memcpy(fresh, *list, elem * (size_t)n);
    fsdem__free(&s->allocator, *list, elem * (size_t)*cap);
    s->bytes += elem * (size_t)(fresh_cap - *cap);
    *list = fresh;
    *cap = fresh_cap;
    return 1;
}

/* Fluid: inside the fill box and outside every obstacle. */
static int fsdem__mps_classify_fluid(const fsdem_mps *s, const void *user, fsdem_vec3 p) {
    int o;
    (void)user;
    for (o = 0; o < s->obst_n; ++o)
        if (fsdem__mps_layer_inside(s, s->obst[o].lo, s->obst[o].hi, p) > 0) return -1;
    return FSDEM_MPS_KIND_FLUID;
}

/* Tank walls: the first layer outside the box WALL, the next ones DUMMY. */
typedef struct fsdem__mps_walls {
    fsdem_vec3 box[2];
    unsigned open;
} fsdem__mps_walls;

static int fsdem__mps_classify_walls(const fsdem_mps *s, const void *user, fsdem_vec3 p) {
    const fsdem__mps_walls *w = (const fsdem__mps_walls *)user;
    const int layer = fsdem__mps_layer_outside(s, w->box[0], w->box[1], w->open, p);
    return layer <= 0 || layer > s->layers ? -1 : layer == 1 ? FSDEM_MPS_KIND_WALL : FSDEM_MPS_KIND_DUMMY;
}

/* Obstacle: the outer layer inside the box WALL, the next ones DUMMY. */
static int fsdem__mps_classify_obstacle(const fsdem_mps *s, const void *user, fsdem_vec3 p) {
    const fsdem__mps_obst *o = (const fsdem__mps_obst *)user;
    const int layer = fsdem__mps_layer_inside(s, o->lo, o->hi, p);
    return layer <= 0 || layer > s->layers ? -1 : layer == 1 ? FSDEM_MPS_KIND_WALL : FSDEM_MPS_KIND_DUMMY;
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
    int a;
    if (added) *added = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem__mps_check_box(s, "fsdem_mps_add_box_walls", lo, hi)) != FSDEM_OK) return r;
    if (open_sides >> (2 * s->dim))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_mps_add_box_walls: open_sides = 0x%x has bits beyond the %d sides of a %dD box (1 << fsdem_side)",
                           open_sides, 2 * s->dim, s->dim);
    w.box[0] = lo;
    w.box[1] = hi;
    w.open = open_sides;
    for (a = 0; a < s->dim; ++a) /* a wall across a periodic axis would wrap into the liquid */
        if (s->desc.periodic[a]) w.open |= 3u << (2 * a);
    reach = (fsdem_real)s->layers * s->r0;
    return fsdem__mps_lattice_fill(s, "fsdem_mps_add_box_walls", lo, fsdem__sub(lo, fsdem_v3(reach, reach, reach)),
                                   fsdem__add(hi, fsdem_v3(reach, reach, reach)), fsdem__mps_classify_walls, &w,
                                   fsdem__zero3(), added);
}

fsdem_result fsdem_mps_add_box_obstacle(fsdem_mps *s, fsdem_vec3 lo, fsdem_vec3 hi, int *id) {
    fsdem__mps_obst box;
    fsdem_result r;
    int first, i;
    if (id) *id = -1;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem__mps_check_box(s, "fsdem_mps_add_box_obstacle", lo, hi)) != FSDEM_OK) return r;
    if (!fsdem__mps_list_room(s, (void **)&s->obst, &s->obst_cap, s->obst_n, sizeof *s->obst))
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps_add_box_obstacle: out of memory");
    box.lo = lo;
    box.hi = hi;
    box.force = fsdem__zero3();
    first = s->n;
    r = fsdem__mps_lattice_fill(s, "fsdem_mps_add_box_obstacle", lo, lo, hi, fsdem__mps_classify_obstacle, &box,
                                fsdem__zero3(), NULL);
    if (r != FSDEM_OK) return r;
    for (i = first; i < s->n; ++i) s->body[i] = s->obst_n;
    s->obst[s->obst_n] = box;
    if (id) *id = s->obst_n;
    s->obst_n++;
    return fsdem__ok(&s->status);
}
