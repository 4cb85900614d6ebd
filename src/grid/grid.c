/* ===== >>impl_grid : cell grid ===================================================================== */

/* Contents: setup (cell size enlarged to bound the cell count), binning by counting sort, cell
   lookup, the 3^dim neighbourhood and the half (forward) neighbourhood; the MAC layout (private:
   cell and face indices and positions of the PIC's grid, for the PIC and its couplers). */

fsdem_result fsdem_cellgrid_setup(fsdem_cellgrid *g, const fsdem_allocator *allocator, int dim,
                                  fsdem_vec3 lo, fsdem_vec3 hi, fsdem_real cell_size, int max_cells) {
    return fsdem_cellgrid_setup_periodic(g, allocator, dim, lo, hi, cell_size, max_cells, NULL);
}

fsdem_result fsdem_cellgrid_setup_periodic(fsdem_cellgrid *g, const fsdem_allocator *allocator, int dim, fsdem_vec3 lo,
                                           fsdem_vec3 hi, fsdem_real cell_size, int max_cells, const int periodic[3]) {
    double extent[3], cells = 1;
    int axis, tries;
    if (!g) return FSDEM_ERR_INVALID_ARG;
    if (allocator) g->allocator = *allocator;
    if ((dim != 2 && dim != 3) || !(cell_size > 0) || !fsdem__finite(cell_size) ||
        !fsdem__finite3(lo) || !fsdem__finite3(hi))
        return FSDEM_ERR_INVALID_ARG;
    if (max_cells <= 0) max_cells = 1 << 24;
    for (axis = 0; axis < 3; ++axis) {
        extent[axis] = axis < dim ? (double)fsdem__comp(hi, axis) - fsdem__comp(lo, axis) : 0;
        /* finite, or the cell count below never fits (a box of +-1e308 overflows to infinity) */
        if (axis < dim && !(extent[axis] > 0 && extent[axis] < HUGE_VAL)) return FSDEM_ERR_INVALID_ARG;
    }
    /* Enlarge the cell until the cell count fits: a coarse grid is slower, never wrong. Each try
       grows it by 1.25, so 400 tries cover any finite extent over any positive size. */
    for (tries = 0;; ++tries) {
        cells = 1;
        for (axis = 0; axis < dim; ++axis) cells *= floor(extent[axis] / cell_size) + 1;
        if (cells <= max_cells) break;
        if (tries == 400 || !fsdem__finite(cell_size * (fsdem_real)1.25)) return FSDEM_ERR_INVALID_ARG;
        cell_size *= (fsdem_real)1.25;
    }
    g->dim = dim;
    g->origin = lo;
    g->cell_size = cell_size;
    g->inv_cell_size = 1 / cell_size;
    for (axis = 0; axis < 3; ++axis) {
        const int tiles = axis < dim ? (int)floor(extent[axis] / cell_size) : 0;
        g->wrap[axis] = periodic && axis < dim && periodic[axis] && tiles >= 3;
        g->n[axis] = g->wrap[axis] ? tiles : periodic && axis < dim && periodic[axis] ? 1 : axis < dim ? tiles + 1 : 1;
        /* a periodic axis of one cell bins everything in it */
        g->inv_width[axis] = g->wrap[axis] ? (fsdem_real)(tiles / extent[axis])
                             : periodic && axis < dim && periodic[axis] ? 0
                                                                        : g->inv_cell_size;
    }
    g->cell_count = g->n[0] * g->n[1] * g->n[2];
    if (g->cell_count + 1 > g->cell_capacity) {
        fsdem__free(&g->allocator, g->cell_start, sizeof(int) * (size_t)g->cell_capacity);
        g->cell_capacity = 0;
        g->cell_start = (int *)fsdem__alloc(&g->allocator, sizeof(int) * (size_t)(g->cell_count + 1));
        if (!g->cell_start) return FSDEM_ERR_OUT_OF_MEMORY;
        g->cell_capacity = g->cell_count + 1;
    }
    memset(g->cell_start, 0, sizeof(int) * (size_t)(g->cell_count + 1));
    return FSDEM_OK;
}

static int fsdem__cellgrid_coord(const fsdem_cellgrid *g, fsdem_real x, int axis) {
    fsdem_real s = (x - fsdem__comp(g->origin, axis)) * g->inv_width[axis];
    int c;
    if (!(s > 0)) return 0; /* also catches NaN */
    c = s < (fsdem_real)g->n[axis] ? (int)s : g->n[axis] - 1;
    return c;
}

int fsdem_cellgrid_cell(const fsdem_cellgrid *g, fsdem_vec3 p, int coord[3]) {
    int c[3];
    c[0] = fsdem__cellgrid_coord(g, p.x, 0);
    c[1] = fsdem__cellgrid_coord(g, p.y, 1);
    c[2] = g->dim == 3 ? fsdem__cellgrid_coord(g, p.z, 2) : 0;
    if (coord) {
        coord[0] = c[0];
        coord[1] = c[1];
        coord[2] = c[2];
    }
    return (c[2] * g->n[1] + c[1]) * g->n[0] + c[0];
}

fsdem_result fsdem_cellgrid_build(fsdem_cellgrid *g, const fsdem_vec3 *points, int count) {
    int i, c, sum = 0;
    if (!g || !g->cell_start || count < 0 || (count > 0 && !points)) return FSDEM_ERR_INVALID_ARG; /* set up first */
    if (count > g->item_capacity) {
        int cap = count + count / 4 + 16;
        int *items = (int *)fsdem__alloc(&g->allocator, sizeof(int) * (size_t)cap);
        int *cell_of = (int *)fsdem__alloc(&g->allocator, sizeof(int) * (size_t)cap);
        if (!items || !cell_of) {
            fsdem__free(&g->allocator, items, sizeof(int) * (size_t)cap);
            fsdem__free(&g->allocator, cell_of, sizeof(int) * (size_t)cap);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
        fsdem__free(&g->allocator, g->items, sizeof(int) * (size_t)g->item_capacity);
        fsdem__free(&g->allocator, g->cell_of, sizeof(int) * (size_t)g->item_capacity);
        g->items = items;
        g->cell_of = cell_of;
        g->item_capacity = cap;
    }
    memset(g->cell_start, 0, sizeof(int) * (size_t)(g->cell_count + 1));
    for (i = 0; i < count; ++i) {
        c = fsdem_cellgrid_cell(g, points[i], NULL);
        g->cell_of[i] = c;
        g->cell_start[c + 1]++;
    }
    for (c = 0; c < g->cell_count; ++c) {
        sum += g->cell_start[c + 1];
        g->cell_start[c + 1] = sum;
    }
    /* Counting sort; cell_start[c] is used as a cursor and restored afterwards. */
    for (i = 0; i < count; ++i) g->items[g->cell_start[g->cell_of[i]]++] = i;
    for (c = g->cell_count; c > 0; --c) g->cell_start[c] = g->cell_start[c - 1];
    g->cell_start[0] = 0;
    return FSDEM_OK;
}

/* Coordinate c + step along an axis: wrapped round a periodic one, -1 off the grid otherwise. */
static int fsdem__cellgrid_step(const fsdem_cellgrid *g, int axis, int c, int step) {
    c += step;
    if (g->wrap[axis]) return c < 0 ? c + g->n[axis] : c >= g->n[axis] ? c - g->n[axis] : c;
    return c >= 0 && c < g->n[axis] ? c : -1;
}

int fsdem_cellgrid_neighbourhood(const fsdem_cellgrid *g, const int coord[3], int cells[27]) {
    int count = 0, dx, dy, dz, zr = g->dim == 3 ? 1 : 0;
    for (dz = -zr; dz <= zr; ++dz) {
        const int z = fsdem__cellgrid_step(g, 2, coord[2], dz);
        if (z < 0) continue;
        for (dy = -1; dy <= 1; ++dy) {
            const int y = fsdem__cellgrid_step(g, 1, coord[1], dy);
            if (y < 0) continue;
            for (dx = -1; dx <= 1; ++dx) {
                const int x = fsdem__cellgrid_step(g, 0, coord[0], dx);
                if (x < 0) continue;
                cells[count++] = (z * g->n[1] + y) * g->n[0] + x;
            }
        }
    }
    return count;
}

int fsdem_cellgrid_forward(const fsdem_cellgrid *g, const int coord[3], int cells[14]) {
    int count = 0, dx, dy, dz, zr = g->dim == 3 ? 1 : 0;
    for (dz = 0; dz <= zr; ++dz)
        for (dy = dz ? -1 : 0; dy <= 1; ++dy)
            for (dx = dz || dy ? -1 : 0; dx <= 1; ++dx) {
                const int x = fsdem__cellgrid_step(g, 0, coord[0], dx), y = fsdem__cellgrid_step(g, 1, coord[1], dy);
                const int z = fsdem__cellgrid_step(g, 2, coord[2], dz);
                if (x < 0 || y < 0 || z < 0) continue;
                cells[count++] = (z * g->n[1] + y) * g->n[0] + x;
            }
    return count;
}

void fsdem_cellgrid_free(fsdem_cellgrid *g) {
    fsdem__free(&g->allocator, g->cell_start, sizeof(int) * (size_t)g->cell_capacity);
    fsdem__free(&g->allocator, g->items, sizeof(int) * (size_t)g->item_capacity);
    fsdem__free(&g->allocator, g->cell_of, sizeof(int) * (size_t)g->item_capacity);
    g->cell_start = g->items = g->cell_of = NULL;
    g->cell_capacity = g->item_capacity = 0;
}

/* Periodic axes (DEM and MPS): along an axis of period L a pair interacts through its minimum
   image, the separation e less the multiple of L nearest e / L, and positions are kept in
   [lo, lo + L). Axes of length 0 are not periodic. */
typedef struct fsdem__periods {
    int any;                      /* some axis is periodic */
    fsdem_real length[3], inv[3]; /* m, 1/m; 0 along the other axes */
} fsdem__periods;

/* The smallest extent (m) of the box [lo, hi] along the first `dim` axes. */
static fsdem_real fsdem__smallest_extent(fsdem_vec3 lo, fsdem_vec3 hi, int dim) {
    fsdem_real e = hi.x - lo.x;
    if (hi.y - lo.y < e) e = hi.y - lo.y;
    if (dim == 3 && hi.z - lo.z < e) e = hi.z - lo.z;
    return e;
}

/* The periods of the axes a < dim with periodic[a] set, those of the box [lo, hi]. */
static fsdem__periods fsdem__periods_of(const int periodic[3], int dim, fsdem_vec3 lo, fsdem_vec3 hi) {
    fsdem__periods p;
    int a;
    memset(&p, 0, sizeof p);
    for (a = 0; a < dim; ++a)
        if (periodic[a]) {
            p.length[a] = fsdem__comp(hi, a) - fsdem__comp(lo, a);
            p.inv[a] = 1 / p.length[a];
            p.any = 1;
        }
    return p;
}

/* The minimum image of a separation e. */
static fsdem_vec3 fsdem__min_image(const fsdem__periods *p, fsdem_vec3 e) {
    if (p->any) {
        e.x -= p->length[0] * (fsdem_real)floor(e.x * p->inv[0] + (fsdem_real)0.5);
        e.y -= p->length[1] * (fsdem_real)floor(e.y * p->inv[1] + (fsdem_real)0.5);
        e.z -= p->length[2] * (fsdem_real)floor(e.z * p->inv[2] + (fsdem_real)0.5);
    }
    return e;
}

/* Brings coordinate a of *x into [lo, hi) of a periodic axis (hi - lo its period); returns the
   multiple of the period taken off (0 when it was inside). */
static fsdem_real fsdem__wrap_axis(const fsdem__periods *p, int a, fsdem_real lo, fsdem_real hi, fsdem_vec3 *x) {
    const fsdem_real L = p->length[a], c = fsdem__comp(*x, a);
    fsdem_real shift, wrapped;
    if (!(L > 0) || (c >= lo && c < hi)) return 0;
    shift = L * (fsdem_real)floor((c - lo) * p->inv[a]);
    wrapped = c - shift;
    if (wrapped >= hi) { /* c - shift rounded up to the top */
        wrapped -= L;
        shift += L;
    }
    fsdem__set_comp(x, a, wrapped);
    return shift;
}

/* The MAC layout: indices and positions of a MAC grid's cells and faces, as fsdem_pic_fields
   documents them. The PIC keeps one; a coupler builds its own from that public view, so both index
   the same way without the coupler reading the PIC's private fields. */
typedef struct fsdem__mac {
    int dim, n[3], ncell;  /* cells per axis (n[2] = 1 in 2D) */
    int fn[3][3];          /* face grid sizes: fn[a][b] = n[b] + (a == b) */
    int fstep[3][3];       /* face index stride of axis-a faces along b */
    fsdem_real dx, inv_dx;
    fsdem_vec3 lo, hi;     /* grid box (z = 0 in 2D) */
    fsdem_real surface_tol; /* m; solid distances within this count as on the surface (fsdem__geom_face_sample) */
} fsdem__mac;

static void fsdem__mac_init(fsdem__mac *m, int dim, const int n[3], fsdem_real dx, fsdem_vec3 lo) {
    fsdem_real extent = dx;
    int a, b;
    m->dim = dim;
    m->dx = dx;
    m->inv_dx = 1 / dx;
    for (a = 0; a < 3; ++a) m->n[a] = a < dim ? n[a] : 1;
    m->ncell = m->n[0] * m->n[1] * m->n[2];
    m->lo = lo;
    if (dim == 2) m->lo.z = 0;
    m->hi = m->lo;
    m->hi.x = m->lo.x + dx * (fsdem_real)m->n[0];
    m->hi.y = m->lo.y + dx * (fsdem_real)m->n[1];
    if (dim == 3) m->hi.z = m->lo.z + dx * (fsdem_real)m->n[2];
    /* a millionth of the cell or of the largest coordinate, whichever is larger: above the rounding
       of face positions (float included), far below any geometric detail */
    for (a = 0; a < 3; ++a) {
        const fsdem_real lo_a = (fsdem_real)fabs(fsdem__comp(m->lo, a)), hi_a = (fsdem_real)fabs(fsdem__comp(m->hi, a));
        if (lo_a > extent) extent = lo_a;
        if (hi_a > extent) extent = hi_a;
    }
    m->surface_tol = (fsdem_real)fsdem__tolerance(1e-6) * extent;
    for (a = 0; a < 3; ++a) {
        for (b = 0; b < 3; ++b) m->fn[a][b] = m->n[b] + (a == b && a < dim);
        m->fstep[a][0] = 1;
        m->fstep[a][1] = m->fn[a][0];
        m->fstep[a][2] = m->fn[a][0] * m->fn[a][1];
    }
}

static int fsdem__mac_cell(const fsdem__mac *m, int i, int j, int k) { return (k * m->n[1] + j) * m->n[0] + i; }

/* Face (i, j, k) of axis a: the face on the low side of cell (i, j, k) along a. */
static int fsdem__mac_face(const fsdem__mac *m, int a, int i, int j, int k) { return (k * m->fn[a][1] + j) * m->fn[a][0] + i; }

/* The (i, j, k) of face index f of axis a. */
static void fsdem__mac_face_coords(const fsdem__mac *m, int a, int f, int idx[3]) {
    idx[0] = f % m->fn[a][0];
    idx[1] = f / m->fn[a][0] % m->fn[a][1];
    idx[2] = f / (m->fn[a][0] * m->fn[a][1]);
}

/* Centre (m) of face (i, j, k) of axis a. */
static fsdem_vec3 fsdem__mac_face_pos(const fsdem__mac *m, int a, int i, int j, int k) {
    fsdem_vec3 p;
    p.x = m->lo.x + m->dx * ((fsdem_real)i + (a == 0 ? 0 : (fsdem_real)0.5));
    p.y = m->lo.y + m->dx * ((fsdem_real)j + (a == 1 ? 0 : (fsdem_real)0.5));
    p.z = m->dim == 3 ? m->lo.z + m->dx * ((fsdem_real)k + (a == 2 ? 0 : (fsdem_real)0.5)) : 0;
    return p;
}

static fsdem_vec3 fsdem__mac_cell_pos(const fsdem__mac *m, int i, int j, int k) {
    return fsdem_v3(m->lo.x + m->dx * ((fsdem_real)i + (fsdem_real)0.5), m->lo.y + m->dx * ((fsdem_real)j + (fsdem_real)0.5),
                    m->dim == 3 ? m->lo.z + m->dx * ((fsdem_real)k + (fsdem_real)0.5) : 0);
}

/* The cell index along `axis` of coordinate x, clamped to the grid (0 for NaN). */
static int fsdem__mac_coord(const fsdem__mac *m, fsdem_real x, int axis) {
    fsdem_real t = (x - fsdem__comp(m->lo, axis)) * m->inv_dx;
    if (!(t > 0)) return 0; /* also NaN */
    return t < (fsdem_real)m->n[axis] ? (int)t : m->n[axis] - 1;
}

/* The cell holding p (clamped into the grid). */
static int fsdem__mac_cell_of(const fsdem__mac *m, fsdem_vec3 p) {
    return fsdem__mac_cell(m, fsdem__mac_coord(m, p.x, 0), fsdem__mac_coord(m, p.y, 1), m->dim == 3 ? fsdem__mac_coord(m, p.z, 2) : 0);
}
