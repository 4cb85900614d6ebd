/* ---- >>io_dem : particles, walls, contacts ---- */

fsdem_result fsdem_dem_write_csv(const fsdem_dem *d, const char *path) {
    FILE *fp;
    int i, bad;
    if (!d || !path) return FSDEM_ERR_INVALID_ARG;
    if (!(fp = fopen(path, "w"))) return FSDEM_ERR_IO;
    fprintf(fp, "id,x,y,z,vx,vy,vz,wx,wy,wz,radius,material\n");
    for (i = 0; i < d->n; ++i)
        fprintf(fp, "%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%d\n", d->id[i], (double)d->x[i].x,
                (double)d->x[i].y, (double)d->x[i].z, (double)d->v[i].x, (double)d->v[i].y, (double)d->v[i].z,
                (double)d->w[i].x, (double)d->w[i].y, (double)d->w[i].z, (double)d->r[i], d->material[i]);
    bad = ferror(fp);
    return (fclose(fp) != 0 || bad) ? FSDEM_ERR_IO : FSDEM_OK;
}

fsdem_result fsdem_dem_write_vtp(const fsdem_dem *d, const char *path, fsdem_vtk_format format) {
    fsdem__vtk_writer w;
    fsdem_result res;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    res = fsdem__vtk_particles_begin(&w, &d->status, "fsdem_dem_write_vtp", path, format, d->time, d->n, "radius", "velocity");
    if (res != FSDEM_OK) return res;
    fsdem__vtk_write(&w, fsdem__vtk_ints("id", d->id, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_reals("radius", d->r, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_reals("mass", d->m, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_ints("material", d->material, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_bytes("fixed", d->fixed, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_vec3s("velocity", d->v, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_vec3s("angular_velocity", d->w, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_vec3s("force", d->f, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_vec3s("torque", d->t, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_vec3s("external_force", d->fext, d->n));
    return fsdem__vtk_particles_end(&w, d->x, d->n);
}

/* Wall geometry for the writer: points, cells (connectivity, offsets) and per-cell wall data, the
   line cells (two points) first and then the polygons, as VTK orders PolyData cells. Points are not
   shared, so the connectivity of point k is k; offsets count from the start of their section. */
typedef struct fsdem__io_walls {
    fsdem_vec3 *points;
    int *connectivity, *offsets, *wall_id;
    unsigned char *type;
    fsdem_vec3 *force;
    int points_count, cells_count;
    int lines;                     /* the pass: 1 takes line cells, 0 polygons */
    int section_start;             /* points before the current section */
    int line_cells, line_points;   /* the line section, after the build */
} fsdem__io_walls;

#define FSDEM__IO_WALL_POINTS 24 /* the most points of one wall: a 3D box's six faces of four */
#define FSDEM__IO_WALL_CELLS 6

static void fsdem__io_walls_cell(fsdem__io_walls *g, const fsdem_vec3 *v, int n, int id, const fsdem__dem_wall *w) {
    int k;
    if ((n == 2) != g->lines) return; /* the other pass's */
    for (k = 0; k < n; ++k) {
        g->connectivity[g->points_count] = g->points_count;
        g->points[g->points_count++] = v[k];
    }
    g->offsets[g->cells_count] = g->points_count - g->section_start;
    g->wall_id[g->cells_count] = id;
    g->type[g->cells_count] = (unsigned char)w->d.type;
    g->force[g->cells_count++] = w->force;
}

/* Keeps the part of a convex polygon where sign (x_axis - bound) >= 0 (Sutherland-Hodgman). */
static int fsdem__io_clip(const fsdem_vec3 *in, int n, fsdem_vec3 *out, int axis, fsdem_real bound, fsdem_real sign) {
    int k, m = 0;
    for (k = 0; k < n; ++k) {
        const fsdem_vec3 cur = in[k], prev = in[(k + n - 1) % n];
        const fsdem_real dc = sign * (fsdem__comp(cur, axis) - bound), dp = sign * (fsdem__comp(prev, axis) - bound);
        if ((dc >= 0) != (dp >= 0)) {
            fsdem_vec3 q = fsdem__madd(prev, fsdem__sub(cur, prev), dp / (dp - dc));
            if (axis == 0) q.x = bound;
            else if (axis == 1) q.y = bound;
            else q.z = bound;
            out[m++] = q;
        }
        if (dc >= 0) out[m++] = cur;
    }
    return m;
}

/* A plane (through p, unit normal n) drawn inside the box [lo, hi]: in 3D the convex polygon where
   they meet, ordered counter-clockwise about n (up to 10 vertices), in 2D the chord of the line
   through the rectangle (2 vertices, z = 0). Returns the number of vertices; fewer than 3 in 3D or
   2 in 2D: the plane misses the box. */
static int fsdem__io_plane_patch(fsdem_vec3 p, fsdem_vec3 n, fsdem_vec3 lo, fsdem_vec3 hi, int dim, fsdem_vec3 *out) {
    const fsdem_vec3 mid = fsdem__scale(fsdem__add(lo, hi), (fsdem_real)0.5);
    const fsdem_vec3 c = fsdem__madd(mid, n, -fsdem__dot(fsdem__sub(mid, p), n)); /* mid projected on the plane */
    fsdem_vec3 diag = fsdem__sub(hi, lo);
    fsdem_real half;
    int axis, count;
    if (dim == 2) diag.z = 0;
    half = fsdem__norm(diag); /* every point of the box projects within half of c */
    if (dim == 2) {
        const fsdem_vec3 t = fsdem_v3(-n.y, n.x, 0);
        fsdem_real t0 = -half, t1 = half;
        for (axis = 0; axis < 2; ++axis) {
            const fsdem_real ta = fsdem__comp(t, axis), ca = fsdem__comp(c, axis);
            const fsdem_real la = fsdem__comp(lo, axis), ha = fsdem__comp(hi, axis);
            if (ta == 0) {
                if (ca < la || ca > ha) return 0;
            } else {
                fsdem_real a = (la - ca) / ta, b = (ha - ca) / ta;
                if (a > b) {
                    const fsdem_real s = a;
                    a = b;
                    b = s;
                }
                if (a > t0) t0 = a;
                if (b < t1) t1 = b;
            }
        }
        if (!(t0 < t1)) return 0;
        out[0] = fsdem__madd(c, t, t0);
        out[1] = fsdem__madd(c, t, t1);
        out[0].z = out[1].z = 0;
        return 2;
    } else {
        /* u, v = n x u: an orthonormal basis of the plane with u x v = n */
        const fsdem_real ax = n.x < 0 ? -n.x : n.x, ay = n.y < 0 ? -n.y : n.y, az = n.z < 0 ? -n.z : n.z;
        const fsdem_vec3 e = ax <= ay && ax <= az ? fsdem_v3(1, 0, 0) : ay <= az ? fsdem_v3(0, 1, 0) : fsdem_v3(0, 0, 1);
        fsdem_vec3 u = fsdem__cross(e, n), v, a[12], b[12];
        u = fsdem__scale(u, half / fsdem__norm(u));
        v = fsdem__cross(n, u);
        a[0] = fsdem__sub(fsdem__sub(c, u), v);
        a[1] = fsdem__sub(fsdem__add(c, u), v);
        a[2] = fsdem__add(fsdem__add(c, u), v);
        a[3] = fsdem__add(fsdem__sub(c, u), v);
        count = 4;
        for (axis = 0; axis < 3 && count >= 3; ++axis) {
            count = fsdem__io_clip(a, count, b, axis, fsdem__comp(lo, axis), 1);
            count = fsdem__io_clip(b, count, a, axis, fsdem__comp(hi, axis), -1);
        }
        if (count < 3) return 0;
        memcpy(out, a, sizeof *a * (size_t)count);
        return count;
    }
}

/* The cells of the drawable walls of the pass g->lines into g (room for FSDEM__IO_WALL_POINTS points
   and FSDEM__IO_WALL_CELLS cells per wall). */
static void fsdem__io_walls_pass(const fsdem_dem *d, fsdem__io_walls *g) {
    /* a 3D box's faces as corners (bit 0: x at hi, bit 1: y, bit 2: z), counter-clockwise seen from outside */
    static const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    const int dim = d->desc.dim;
    int id, f, k;
    for (id = 0; id < d->wall_count; ++id) {
        const fsdem__dem_wall *w = &d->walls[id];
        const fsdem_dem_wall_desc *gd = &w->d;
        fsdem_vec3 v[12];
        if (!w->active) continue;
        switch (gd->type) {
        case FSDEM_DEM_WALL_TYPE_PLANE:
            k = fsdem__io_plane_patch(gd->a, gd->b, d->desc.domain_min, d->desc.domain_max, dim, v);
            if (k >= (dim == 2 ? 2 : 3)) fsdem__io_walls_cell(g, v, k, id, w);
            break;
        case FSDEM_DEM_WALL_TYPE_BOX_INSIDE:
        case FSDEM_DEM_WALL_TYPE_BOX_OUTSIDE:
            if (dim == 2) {
                const fsdem_vec3 r[4] = {fsdem_v3(gd->a.x, gd->a.y, 0), fsdem_v3(gd->b.x, gd->a.y, 0), fsdem_v3(gd->b.x, gd->b.y, 0),
                                         fsdem_v3(gd->a.x, gd->b.y, 0)};
                for (f = 0; f < 4; ++f) {
                    v[0] = r[f];
                    v[1] = r[(f + 1) % 4];
                    fsdem__io_walls_cell(g, v, 2, id, w);
                }
            } else
                for (f = 0; f < 6; ++f) {
                    for (k = 0; k < 4; ++k) {
                        /* an inside box holds the particles: its faces face inwards */
                        const int corner = faces[f][gd->type == FSDEM_DEM_WALL_TYPE_BOX_INSIDE ? 3 - k : k];
                        v[k] = fsdem_v3(corner & 1 ? gd->b.x : gd->a.x, corner & 2 ? gd->b.y : gd->a.y, corner & 4 ? gd->b.z : gd->a.z);
                    }
                    fsdem__io_walls_cell(g, v, 4, id, w);
                }
            break;
        case FSDEM_DEM_WALL_TYPE_SEGMENT:
            v[0] = gd->a;
            v[1] = gd->b;
            fsdem__io_walls_cell(g, v, 2, id, w);
            break;
        case FSDEM_DEM_WALL_TYPE_TRIANGLE:
            v[0] = gd->a;
            v[1] = gd->b;
            v[2] = gd->c;
            fsdem__io_walls_cell(g, v, 3, id, w);
            break;
        default: break; /* SDF: known only through its callback */
        }
    }
}

/* Every drawable wall: the line cells (2D walls, segments), then the polygons (3D walls). */
static void fsdem__io_walls_build(const fsdem_dem *d, fsdem__io_walls *g) {
    g->points_count = g->cells_count = g->section_start = 0;
    g->lines = 1;
    fsdem__io_walls_pass(d, g);
    g->line_cells = g->cells_count;
    g->line_points = g->section_start = g->points_count;
    g->lines = 0;
    fsdem__io_walls_pass(d, g);
}

fsdem_result fsdem_dem_write_walls_vtp(const fsdem_dem *d, const char *path, fsdem_vtk_format format) {
    static const char *const who = "fsdem_dem_write_walls_vtp";
    const size_t walls = d && d->wall_count > 0 ? (size_t)d->wall_count : 1; /* no allocation of 0 bytes */
    const size_t np = FSDEM__IO_WALL_POINTS * walls, nc = FSDEM__IO_WALL_CELLS * walls;
    fsdem__status *st;
    fsdem__io_walls g;
    fsdem__vtk_writer w;
    fsdem_result res;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    st = (fsdem__status *)&d->status; /* the message is the object's only mutable part here */
    res = fsdem__vtk_check(st, who, path, format);
    if (res != FSDEM_OK) return res;
    g.points = (fsdem_vec3 *)fsdem__alloc(&d->allocator, sizeof(fsdem_vec3) * np);
    g.connectivity = (int *)fsdem__alloc(&d->allocator, sizeof(int) * np);
    g.offsets = (int *)fsdem__alloc(&d->allocator, sizeof(int) * nc);
    g.wall_id = (int *)fsdem__alloc(&d->allocator, sizeof(int) * nc);
    g.type = (unsigned char *)fsdem__alloc(&d->allocator, nc);
    g.force = (fsdem_vec3 *)fsdem__alloc(&d->allocator, sizeof(fsdem_vec3) * nc);
    if (!g.points || !g.connectivity || !g.offsets || !g.wall_id || !g.type || !g.force)
        res = fsdem__fail(st, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory (%d walls)", who, d->wall_count);
    else {
        fsdem__io_walls_build(d, &g);
        res = fsdem__vtk_open(&w, st, who, path, format, "PolyData");
        if (res == FSDEM_OK) {
            const int polys = g.cells_count - g.line_cells;
            fsdem__vtk_polydata(&w, d->time, g.points_count, 0, g.line_cells, polys);
            fsdem__vtk_section(&w, "CellData", "wall_id", "force");
            fsdem__vtk_write(&w, fsdem__vtk_ints("wall_id", g.wall_id, g.cells_count));
            fsdem__vtk_write(&w, fsdem__vtk_bytes("type", g.type, g.cells_count));
            fsdem__vtk_write(&w, fsdem__vtk_vec3s("force", g.force, g.cells_count));
            fsdem__vtk_section_end(&w, "CellData");
            fsdem__vtk_section(&w, "Points", NULL, NULL);
            fsdem__vtk_write(&w, fsdem__vtk_vec3s("Points", g.points, g.points_count));
            fsdem__vtk_section_end(&w, "Points");
            if (g.line_cells)
                fsdem__vtk_cells(&w, "Lines", fsdem__vtk_ints("connectivity", g.connectivity, g.line_points),
                                 fsdem__vtk_ints("offsets", g.offsets, g.line_cells));
            if (polys)
                fsdem__vtk_cells(&w, "Polys", fsdem__vtk_ints("connectivity", g.connectivity + g.line_points, g.points_count - g.line_points),
                                 fsdem__vtk_ints("offsets", g.offsets + g.line_cells, polys));
            res = fsdem__vtk_close(&w);
        }
    }
    fsdem__free(&d->allocator, g.points, sizeof(fsdem_vec3) * np);
    fsdem__free(&d->allocator, g.connectivity, sizeof(int) * np);
    fsdem__free(&d->allocator, g.offsets, sizeof(int) * nc);
    fsdem__free(&d->allocator, g.wall_id, sizeof(int) * nc);
    fsdem__free(&d->allocator, g.type, nc);
    fsdem__free(&d->allocator, g.force, sizeof(fsdem_vec3) * nc);
    return res;
}

/* Contacts for the writer: two points and the cell data of each. */
typedef struct fsdem__io_contacts {
    fsdem_vec3 *points; /* 2 per contact */
    fsdem_vec3 *force;
    fsdem_real *normal_force, *overlap;
    int *particle, *partner;
    int count;
} fsdem__io_contacts;

/* The contact law on a filled batch, as fsdem__dem_drain runs it, with the law chosen at run time
   (one more instantiation of the kernel; the step's are per law). */
static void fsdem__io_dem_batch_law(fsdem__dem_batch *b, fsdem_dem_law law, fsdem_real h, int pairs, fsdem_real off,
                                    const fsdem__dem_pair *uniform, const fsdem__dem_rules *rules) {
    fsdem__dem_batch_law(b, law, h, pairs, off, uniform, rules);
}

/* Runs the law on a batch of particle pairs or (`walls`) wall contacts and appends its contacts to
   c, leaving the object as it is (nothing is scattered, no spring is committed); empties the batch. */
static void fsdem__io_dem_drain(const fsdem_dem *d, fsdem__dem_batch *batch, int walls, fsdem_real h, fsdem__io_contacts *c) {
    const fsdem__dem_pair *uniform = d->material_count == 1 ? d->pairs : NULL;
    const fsdem__dem_batch *b = batch; /* read only after the law */
    const fsdem_real off = d->desc.contact_offset;
    const fsdem__dem_rules rules = fsdem__dem_rules_of(d);
    int k;
    fsdem__dem_batch_pad(batch, !walls, uniform != NULL);
    fsdem__io_dem_batch_law(batch, fsdem__dem_kernel_law(d), h, !walls, walls ? 0 : off, uniform, &rules);
    for (k = 0; k < b->count; ++k) {
        const int i = b->i[k], e = c->count++;
        c->points[2 * e] = d->x[i];
        if (walls) {
            /* the wall's closest point: r_i + offset - overlap from the centre, along -n */
            const fsdem_vec3 n = fsdem__dem_batch_vec(b->n, k);
            c->points[2 * e + 1] = fsdem__madd(d->x[i], n, -(d->r[i] + off - b->delta[k]));
            c->partner[e] = -1 - b->other[k];
        } else {
            c->points[2 * e + 1] = fsdem__dem_image_of(d, i, b->other[k]); /* across a periodic seam: its image */
            c->partner[e] = d->id[b->other[k]];
        }
        c->force[e] = fsdem__dem_batch_vec(b->force, k);
        c->normal_force[e] = b->fn[k];
        c->overlap[e] = b->delta[k];
        c->particle[e] = d->id[i];
    }
    batch->count = 0;
}

/* The contacts of the last force evaluation with their forces (fsdem_dem_write_contacts_vtp), into c
   (NULL: only counted); `hits` has room for the longest row of the particle-wall list. Returns
   their number. */
static int fsdem__io_dem_contacts(const fsdem_dem *d, fsdem__dem_batch *b, fsdem__dem_wall_hit *hits, fsdem__io_contacts *c) {
    const fsdem_real off = d->desc.contact_offset;
    /* springs with history: as committed, not advanced again; seed 000's linear law: its one-step spring */
    const fsdem_real h = fsdem__dem_kernel_law(d) == FSDEM_DEM_LAW_LINEAR ? d->dt : 0;
    const int uniform = d->material_count == 1;
    int i, k, nh, count = 0;
    if (c) {
        c->count = 0;
        b->count = 0;
    }
    /* touching pairs, as fsdem__dem_touching finds them */
    for (k = 0; k < d->pp.count; ++k) {
        const int key = d->pp.key[k];
        const int p = d->pp.first[k], q = FSDEM__DEM_PARTNER(key);
        const fsdem_vec3 e = fsdem__min_image(&d->periods, fsdem__sub(d->x[p], d->x[q]));
        const fsdem_real ex = e.x, ey = e.y, ez = e.z;
        const fsdem_real reach = d->r[p] + d->r[q] + off;
        if (!(ex * ex + ey * ey + ez * ez < reach * reach)) continue;
        count++;
        if (!c) continue;
        fsdem__dem_gather_pair(d, b, b->count++, k, fsdem__dem_kernel_law(d), uniform);
        if (b->count == FSDEM__DEM_BATCH) fsdem__io_dem_drain(d, b, 0, h, c);
    }
    if (c && b->count) fsdem__io_dem_drain(d, b, 0, h, c);
    /* wall contacts of the free particles, as fsdem__dem_compute_forces_law finds them */
    for (i = 0; i < d->n; ++i) {
        if (d->inv_m[i] == 0 || d->pw.start[i] == d->pw.start[i + 1]) continue;
        nh = fsdem__dem_wall_hits_into(d, i, hits, NULL);
        count += nh;
        if (!c) continue;
        for (k = 0; k < nh; ++k) {
            fsdem__dem_gather_wall(d, b, b->count++, i, &hits[k], uniform);
            if (b->count == FSDEM__DEM_BATCH) fsdem__io_dem_drain(d, b, 1, h, c);
        }
    }
    if (c && b->count) fsdem__io_dem_drain(d, b, 1, h, c);
    return count;
}

fsdem_result fsdem_dem_write_contacts_vtp(const fsdem_dem *d, const char *path, fsdem_vtk_format format) {
    static const char *const who = "fsdem_dem_write_contacts_vtp";
    fsdem__status *st;
    fsdem__vtk_writer w;
    fsdem__io_contacts c;
    fsdem__dem_batch *b = NULL;
    fsdem__dem_wall_hit *hits = NULL;
    size_t row_max = 1, n = 1; /* room for the longest wall row and the contacts (no allocation of 0 bytes) */
    fsdem_result res;
    int i;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    st = (fsdem__status *)&d->status; /* the message is the object's only mutable part here */
    res = fsdem__vtk_check(st, who, path, format);
    if (res != FSDEM_OK) return res;
    memset(&c, 0, sizeof c);
    /* the lists describe the particles of the last step unless they were edited since */
    if (!d->need_rebuild && d->pp.rows == d->n && d->pw.rows == d->n && d->n > 0) {
        for (i = 0; i < d->n; ++i)
            if ((size_t)(d->pw.start[i + 1] - d->pw.start[i]) > row_max) row_max = (size_t)(d->pw.start[i + 1] - d->pw.start[i]);
        b = (fsdem__dem_batch *)fsdem__alloc(&d->allocator, sizeof *b);
        hits = (fsdem__dem_wall_hit *)fsdem__alloc(&d->allocator, sizeof *hits * row_max);
        if (b && hits) {
            n = (size_t)fsdem__io_dem_contacts(d, b, hits, NULL);
            if (n == 0) n = 1;
            c.points = (fsdem_vec3 *)fsdem__alloc(&d->allocator, sizeof(fsdem_vec3) * 2 * n);
            c.force = (fsdem_vec3 *)fsdem__alloc(&d->allocator, sizeof(fsdem_vec3) * n);
            c.normal_force = (fsdem_real *)fsdem__alloc(&d->allocator, sizeof(fsdem_real) * n);
            c.overlap = (fsdem_real *)fsdem__alloc(&d->allocator, sizeof(fsdem_real) * n);
            c.particle = (int *)fsdem__alloc(&d->allocator, sizeof(int) * n);
            c.partner = (int *)fsdem__alloc(&d->allocator, sizeof(int) * n);
        }
        if (!b || !hits || !c.points || !c.force || !c.normal_force || !c.overlap || !c.particle || !c.partner)
            res = fsdem__fail(st, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory (%lu contacts)", who, (unsigned long)n);
        else
            fsdem__io_dem_contacts(d, b, hits, &c);
    }
    if (res == FSDEM_OK) res = fsdem__vtk_open(&w, st, who, path, format, "PolyData");
    if (res == FSDEM_OK) {
        fsdem__vtk_polydata(&w, d->time, 2 * (long long)c.count, 0, c.count, 0);
        fsdem__vtk_section(&w, "CellData", "normal_force", "force");
        fsdem__vtk_write(&w, fsdem__vtk_vec3s("force", c.force, c.count));
        fsdem__vtk_write(&w, fsdem__vtk_reals("normal_force", c.normal_force, c.count));
        fsdem__vtk_write(&w, fsdem__vtk_reals("overlap", c.overlap, c.count));
        fsdem__vtk_write(&w, fsdem__vtk_ints("particle", c.particle, c.count));
        fsdem__vtk_write(&w, fsdem__vtk_ints("partner", c.partner, c.count));
        fsdem__vtk_section_end(&w, "CellData");
        fsdem__vtk_section(&w, "Points", NULL, NULL);
        fsdem__vtk_write(&w, fsdem__vtk_vec3s("Points", c.points, 2 * (long long)c.count));
        fsdem__vtk_section_end(&w, "Points");
        fsdem__vtk_cells(&w, "Lines", fsdem__vtk_ramp("connectivity", 2 * (long long)c.count, 0, 1),
                         fsdem__vtk_ramp("offsets", c.count, 2, 2));
        res = fsdem__vtk_close(&w);
    }
    fsdem__free(&d->allocator, b, sizeof *b);
    fsdem__free(&d->allocator, hits, sizeof *hits * row_max);
    fsdem__free(&d->allocator, c.points, sizeof(fsdem_vec3) * 2 * n);
    fsdem__free(&d->allocator, c.force, sizeof(fsdem_vec3) * n);
    fsdem__free(&d->allocator, c.normal_force, sizeof(fsdem_real) * n);
    fsdem__free(&d->allocator, c.overlap, sizeof(fsdem_real) * n);
    fsdem__free(&d->allocator, c.particle, sizeof(int) * n);
    fsdem__free(&d->allocator, c.partner, sizeof(int) * n);
    return res;
}
