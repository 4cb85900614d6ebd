/* ---- >>pic_geometry : obstacles, signed distances, cut-cell face fractions ---- */

/* Signed distance of one obstacle, positive outside the solid. */
static fsdem_real fsdem__pic_obst_sdf(const fsdem_pic *s, const fsdem__pic_obst *o, fsdem_vec3 p) {
    const fsdem_pic_obstacle *d = &o->d;
    fsdem_vec3 normal;
    switch (d->type) {
    case FSDEM_PIC_OBSTACLE_TYPE_BOX: return fsdem__geom_box(p, d->a, d->b, s->dim, &normal);
    case FSDEM_PIC_OBSTACLE_TYPE_CYLINDER:
        if (s->dim == 3) return fsdem__geom_cylinder(p, d->a, d->b, d->radius);
        return fsdem__geom_sphere(p, d->a, d->radius, 2); /* a disc in 2D */
    case FSDEM_PIC_OBSTACLE_TYPE_SPHERE: return fsdem__geom_sphere(p, d->a, d->radius, s->dim);
    case FSDEM_PIC_OBSTACLE_TYPE_POLYGON: return fsdem__geom_polygon(p, o->verts, d->vertex_count);
    case FSDEM_PIC_OBSTACLE_TYPE_SDF: return d->sdf(d->sdf_user, p, &normal);
    }
    return 1e30f;
}

/* Signed distance to the union of the obstacles (large when there are none); *which gets the
   nearest obstacle (or -1). Obstacles whose inflated bounding box does not hold p are skipped: they
   are more than two cells away. */
static fsdem_real fsdem__pic_obst_min(const fsdem_pic *s, fsdem_vec3 p, int *which) {
    fsdem_real best = (fsdem_real)1e30, d;
    int o, b, w = -1;
    for (o = 0; o < s->obst_count; ++o) {
        const fsdem__pic_obst *ob = &s->obst[o];
        int outside = 0;
        for (b = 0; b < s->dim; ++b)
            if (fsdem__comp(p, b) < fsdem__comp(ob->box_lo, b) || fsdem__comp(p, b) > fsdem__comp(ob->box_hi, b))
                outside = 1;
        if (outside) continue;
        d = fsdem__pic_obst_sdf(s, ob, p);
        if (d < best) {
            best = d;
            w = o;
        }
    }
    if (which) *which = w;
    return best;
}

static int fsdem__pic_side_closed(const fsdem_pic *s, int side) {
    return s->desc.boundary[side] != FSDEM_PIC_BC_OUTFLOW;
}

/* Distance to obstacles and closed walls, positive in the open domain; gradient by differences. */
static fsdem_real fsdem__pic_solid_sdf(const fsdem_pic *s, fsdem_vec3 p) {
    fsdem_real d = fsdem__pic_obst_min(s, p, NULL), w;
    int b;
    for (b = 0; b < s->dim; ++b) {
        if (fsdem__pic_side_closed(s, 2 * b)) {
            w = fsdem__comp(p, b) - fsdem__comp(s->lo, b);
            if (w < d) d = w;
        }
        if (fsdem__pic_side_closed(s, 2 * b + 1)) {
            w = fsdem__comp(s->hi, b) - fsdem__comp(p, b);
            if (w < d) d = w;
        }
    }
    return d;
}

static fsdem_real fsdem__pic_obst_dist(const fsdem_pic *s, fsdem_vec3 p) { return fsdem__pic_obst_min(s, p, NULL); }

/* Unit gradient at p of a distance `dist` by central differences over 1e-3 of a cell (0 where it is
   flat). */
static fsdem_vec3 fsdem__pic_gradient(const fsdem_pic *s, fsdem_real (*dist)(const fsdem_pic *, fsdem_vec3), fsdem_vec3 p) {
    fsdem_real h = s->dx * (fsdem_real)1e-3, g[3] = {0, 0, 0}, len;
    int b;
    for (b = 0; b < s->dim; ++b)
        g[b] = dist(s, fsdem__axis_shift(p, b, h)) - dist(s, fsdem__axis_shift(p, b, -h));
    len = (fsdem_real)sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    return len > 0 ? fsdem_v3(g[0] / len, g[1] / len, g[2] / len) : fsdem_v3(0, 0, 0);
}

fsdem_real fsdem_pic_solid_distance(const fsdem_pic *s, fsdem_vec3 p, fsdem_vec3 *normal) {
    if (normal) *normal = fsdem__zero3();
    if (!s) return 0;
    if (normal) *normal = fsdem__pic_gradient(s, fsdem__pic_solid_sdf, p);
    return fsdem__pic_solid_sdf(s, p);
}

/* The obstacle union as a fsdem__geom_dist_fn (`solid` is the solver). */
static fsdem_real fsdem__pic_obstacles_dist(const void *solid, fsdem_vec3 p) {
    return fsdem__pic_obst_min((const fsdem_pic *)solid, p, NULL);
}

/* Face fractions and solid velocities of the obstacle union into open[a], vel[a]. Returns the
   number of cells with at least one face open. */
static int fsdem__pic_static_faces(const fsdem_pic *s, fsdem_real *open[3], fsdem_real *vel[3]) {
    int a, i, j, k, which, open_cells = 0;
    fsdem_real reach = s->dx * (fsdem_real)0.9;
    for (a = 0; a < s->dim; ++a)
        for (k = 0; k < s->fn[a][2]; ++k)
            for (j = 0; j < s->fn[a][1]; ++j)
                for (i = 0; i < s->fn[a][0]; ++i) {
                    int f = fsdem__mac_face(&s->mac, a, i, j, k);
                    fsdem_vec3 p = fsdem__mac_face_pos(&s->mac, a, i, j, k);
                    fsdem_real d = fsdem__pic_obst_min(s, p, &which);
                    open[a][f] = 1;
                    vel[a][f] = 0;
                    if (which < 0) continue;
                    vel[a][f] = fsdem__comp(s->obst[which].d.velocity, a);
                    if (d > reach) continue;
                    p = fsdem__axis_shift(p, (a + 1) % s->dim, -s->dx / 2);
                    if (s->dim == 3) p = fsdem__axis_shift(p, (a + 2) % 3, -s->dx / 2);
                    open[a][f] = fsdem__geom_face_fraction(s->dim, a, p, s->dx, s->mac.surface_tol, fsdem__pic_obstacles_dist, s);
                }
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                int any = 0;
                for (a = 0; a < s->dim && !any; ++a) {
                    int f = fsdem__mac_face(&s->mac, a, i, j, k);
                    if (open[a][f] > 0 || open[a][f + s->fstep[a][a]] > 0) any = 1;
                }
                open_cells += any;
            }
    return open_cells;
}

/* Static-solid and near-solid flags of the cells from sopen. */
static void fsdem__pic_static_flags(fsdem_pic *s) {
    int a, i, j, k, c, di, dj, dk, zr = s->dim == 3 ? 1 : 0;
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                int any_open = 0, any_cut = 0;
                c = fsdem__mac_cell(&s->mac, i, j, k);
                for (a = 0; a < s->dim; ++a) {
                    int f = fsdem__mac_face(&s->mac, a, i, j, k), g = f + s->fstep[a][a];
                    if (s->sopen[a][f] > 0 || s->sopen[a][g] > 0) any_open = 1;
                    if (s->sopen[a][f] < 1 || s->sopen[a][g] < 1) any_cut = 1;
                }
                s->csolid[c] = (unsigned char)!any_open;
                s->ctmp[c] = (fsdem_real)any_cut;
            }
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                int near = 0;
                for (dk = -zr; dk <= zr; ++dk)
                    for (dj = -1; dj <= 1; ++dj)
                        for (di = -1; di <= 1; ++di) {
                            int x = i + di, y = j + dj, z = k + dk;
                            if (x < 0 || y < 0 || z < 0 || x >= s->n[0] || y >= s->n[1] || z >= s->n[2]) continue;
                            if (s->ctmp[fsdem__mac_cell(&s->mac, x, y, z)] > 0) near = 1;
                        }
                s->cnear[fsdem__mac_cell(&s->mac, i, j, k)] = (unsigned char)near;
            }
}

/* One-dimensional integral of the tent kernel of cell i (of n) over the domain, per cell volume. */
static fsdem_real fsdem__pic_tent_1d(int i, int n) {
    fsdem_real v = 1;
    if (i == 0) v -= (fsdem_real)0.125;
    if (i == n - 1) v -= (fsdem_real)0.125;
    return v;
}

/* Reference fluid fraction of each cell: what the tent kernel collects from a uniformly filled open
   domain. Walls truncate it analytically. Near obstacles it is summed over the seeding lattice
   (the unjittered sub-cell sites of the 3^dim cells around, those outside the solids), so a freshly
   seeded cut cell reads exactly 1; with a particle count that is not a perfect power the seeding is
   random and the expected value, the kernel integral over the open space, is sampled instead (8
   points per axis over the support). Dividing the particle count by it makes a full cell read 1 next
   to any solid. */
static void fsdem__pic_compute_fref(fsdem_pic *s) {
    int i, j, k, c, q[3], m, S = s->sub ? s->sub : 8;
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                c = fsdem__mac_cell(&s->mac, i, j, k);
                if (s->csolid[c]) {
                    s->fref[c] = 0;
                    continue;
                }
                if (!s->cnear[c] || s->obst_count == 0) {
                    s->fref[c] = fsdem__pic_tent_1d(i, s->n[0]) * fsdem__pic_tent_1d(j, s->n[1]) *
                                 (s->dim == 3 ? fsdem__pic_tent_1d(k, s->n[2]) : 1);
                } else {
                    /* sites at offsets (q + 1/2) h from the lower corner of the 2-cell-wide support
                       [centre - dx, centre + dx] (lattice: h = dx / sub; sampling: h = 2 dx / 8) */
                    fsdem_vec3 cc = fsdem__mac_cell_pos(&s->mac, i, j, k);
                    fsdem_real h = s->sub ? s->dx / (fsdem_real)S : 2 * s->dx / (fsdem_real)S, lo_off;
                    int per = s->sub ? 2 * S + 1 : S; /* lattice: the sites of the 3 cells that the kernel reaches */
                    double sum = 0, wsum = 0;
                    int qz = s->dim == 3 ? per : 1;
                    lo_off = s->sub ? -(fsdem_real)1.5 * s->dx : -s->dx;
                    for (q[2] = 0; q[2] < qz; ++q[2])
                        for (q[1] = 0; q[1] < per; ++q[1])
                            for (q[0] = 0; q[0] < per; ++q[0]) {
                                fsdem_real off[3], w = 1;
                                fsdem_vec3 p;
                                int inside = 1;
                                for (m = 0; m < 3; ++m) {
                                    off[m] = m < s->dim ? lo_off + h * ((fsdem_real)q[m] + (fsdem_real)0.5) : 0;
                                    if (m < s->dim) {
                                        fsdem_real t = 1 - (fsdem_real)fabs(off[m]) * s->inv_dx;
                                        w *= t > 0 ? t : 0;
                                    }
                                }
                                if (w <= 0) continue;
                                p = fsdem_v3(cc.x + off[0], cc.y + off[1], cc.z + off[2]);
                                for (m = 0; m < s->dim; ++m)
                                    if (fsdem__comp(p, m) < fsdem__comp(s->lo, m) || fsdem__comp(p, m) > fsdem__comp(s->hi, m))
                                        inside = 0;
                                wsum += w;
                                if (inside && fsdem__pic_obst_min(s, p, NULL) > 0) sum += w;
                            }
                    s->fref[c] = (fsdem_real)(wsum > 0 ? sum / wsum : 0);
                }
            }
}

fsdem_pic_obstacle fsdem_pic_obstacle_box(fsdem_vec3 lo, fsdem_vec3 hi) {
    fsdem_pic_obstacle o;
    memset(&o, 0, sizeof o);
    o.type = FSDEM_PIC_OBSTACLE_TYPE_BOX;
    o.a = lo;
    o.b = hi;
    return o;
}

fsdem_pic_obstacle fsdem_pic_obstacle_sphere(fsdem_vec3 centre, fsdem_real radius) {
    fsdem_pic_obstacle o;
    memset(&o, 0, sizeof o);
    o.type = FSDEM_PIC_OBSTACLE_TYPE_SPHERE;
    o.a = centre;
    o.radius = radius;
    return o;
}

fsdem_pic_obstacle fsdem_pic_obstacle_cylinder(fsdem_vec3 a, fsdem_vec3 b, fsdem_real radius) {
    fsdem_pic_obstacle o;
    memset(&o, 0, sizeof o);
    o.type = FSDEM_PIC_OBSTACLE_TYPE_CYLINDER;
    o.a = a;
    o.b = b;
    o.radius = radius;
    return o;
}

fsdem_pic_obstacle fsdem_pic_obstacle_polygon(const fsdem_vec3 *vertices, int count) {
    fsdem_pic_obstacle o;
    memset(&o, 0, sizeof o);
    o.type = FSDEM_PIC_OBSTACLE_TYPE_POLYGON;
    o.vertices = vertices;
    o.vertex_count = count;
    return o;
}

fsdem_pic_obstacle fsdem_pic_obstacle_sdf(fsdem_sdf_fn sdf, void *user) {
    fsdem_pic_obstacle o;
    memset(&o, 0, sizeof o);
    o.type = FSDEM_PIC_OBSTACLE_TYPE_SDF;
    o.sdf = sdf;
    o.sdf_user = user;
    return o;
}

static void fsdem__pic_remove_marked(fsdem_pic *s);
static void fsdem__pic_refresh(fsdem_pic *s);

fsdem_result fsdem_pic_add_obstacle(fsdem_pic *s, const fsdem_pic_obstacle *ob, int *id) {
    fsdem__pic_obst o;
    fsdem_real *open[3], *vel[3];
    int b, i, open_cells, inside;
    static const char *names[5] = {"box", "sphere", "cylinder", "polygon", "sdf"};
    const char *name;
    if (id) *id = -1;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!ob) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: NULL obstacle");
    if ((int)ob->type < 0 || (int)ob->type > 4)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: type %d is not a fsdem_pic_obstacle_type",
                           (int)ob->type);
    name = names[ob->type];
    if (!fsdem__finite3(ob->a) || !fsdem__finite3(ob->b) || !fsdem__finite(ob->radius) || !fsdem__finite3(ob->velocity))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (%s): non-finite geometry or velocity",
                           s->obst_count, name);
    memset(&o, 0, sizeof o);
    o.d = *ob;
    switch (ob->type) {
    case FSDEM_PIC_OBSTACLE_TYPE_BOX:
        for (b = 0; b < s->dim; ++b)
            if (!(fsdem__comp(ob->b, b) > fsdem__comp(ob->a, b)))
                return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (box): b.%c must exceed a.%c",
                                   s->obst_count, "xyz"[b], "xyz"[b]);
        o.box_lo = ob->a;
        o.box_hi = ob->b;
        break;
    case FSDEM_PIC_OBSTACLE_TYPE_SPHERE:
    case FSDEM_PIC_OBSTACLE_TYPE_CYLINDER:
        if (!(ob->radius > 0))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (%s): radius = %g must be > 0",
                               s->obst_count, name, (double)ob->radius);
        if (ob->type == FSDEM_PIC_OBSTACLE_TYPE_CYLINDER && s->dim == 3 && !(fsdem__norm(fsdem__sub(ob->b, ob->a)) > 0))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (cylinder): axis a-b has zero length",
                               s->obst_count);
        o.box_lo = fsdem__sub(ob->a, fsdem_v3(ob->radius, ob->radius, ob->radius));
        o.box_hi = fsdem__add(ob->a, fsdem_v3(ob->radius, ob->radius, ob->radius));
        if (ob->type == FSDEM_PIC_OBSTACLE_TYPE_CYLINDER && s->dim == 3)
            for (b = 0; b < 3; ++b) {
                fsdem_real lo = fsdem__comp(ob->b, b) - ob->radius, hi = fsdem__comp(ob->b, b) + ob->radius;
                if (b == 0) { if (lo < o.box_lo.x) o.box_lo.x = lo; if (hi > o.box_hi.x) o.box_hi.x = hi; }
                if (b == 1) { if (lo < o.box_lo.y) o.box_lo.y = lo; if (hi > o.box_hi.y) o.box_hi.y = hi; }
                if (b == 2) { if (lo < o.box_lo.z) o.box_lo.z = lo; if (hi > o.box_hi.z) o.box_hi.z = hi; }
            }
        break;
    case FSDEM_PIC_OBSTACLE_TYPE_POLYGON:
        if (s->dim != 2)
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (polygon): polygons are 2D only",
                               s->obst_count);
        if (!ob->vertices || ob->vertex_count < 3)
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (polygon): needs >= 3 vertices, has %d",
                               s->obst_count, ob->vertices ? ob->vertex_count : 0);
        o.box_lo = o.box_hi = ob->vertices[0];
        for (i = 0; i < ob->vertex_count; ++i) {
            fsdem_vec3 v = ob->vertices[i];
            if (!fsdem__finite3(v))
                return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (polygon): vertex %d is not finite",
                                   s->obst_count, i);
            if (v.x < o.box_lo.x) o.box_lo.x = v.x;
            if (v.y < o.box_lo.y) o.box_lo.y = v.y;
            if (v.x > o.box_hi.x) o.box_hi.x = v.x;
            if (v.y > o.box_hi.y) o.box_hi.y = v.y;
        }
        {
            /* shoelace area: coincident or collinear vertices enclose nothing */
            double area = 0;
            int j;
            for (i = 0, j = ob->vertex_count - 1; i < ob->vertex_count; j = i++)
                area += (double)ob->vertices[j].x * ob->vertices[i].y - (double)ob->vertices[i].x * ob->vertices[j].y;
            if (!(fabs(area) > 0) || !(fabs(area) < HUGE_VAL))
                return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                                   "fsdem_pic_add_obstacle: obstacle %d (polygon): the vertices enclose no area", s->obst_count);
        }
        break;
    case FSDEM_PIC_OBSTACLE_TYPE_SDF:
        if (!ob->sdf)
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (sdf): NULL callback", s->obst_count);
        for (i = 0; i < s->ncell; ++i) {
            /* a distance that is not a number would be ignored silently by the union below */
            const fsdem_vec3 c = fsdem__mac_cell_pos(&s->mac, i % s->n[0], i / s->n[0] % s->n[1], i / (s->n[0] * s->n[1]));
            fsdem_vec3 nrm;
            const fsdem_real dist = ob->sdf(ob->sdf_user, c, &nrm);
            if (!fsdem__finite(dist))
                return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                                   "fsdem_pic_add_obstacle: obstacle %d (sdf): the callback returned %g at (%g, %g, %g)",
                                   s->obst_count, (double)dist, (double)c.x, (double)c.y, (double)c.z);
        }
        o.box_lo = fsdem__sub(s->lo, fsdem_v3(1e30f, 1e30f, 1e30f));
        o.box_hi = fsdem__add(s->hi, fsdem_v3(1e30f, 1e30f, 1e30f));
        break;
    }
    if (ob->type != FSDEM_PIC_OBSTACLE_TYPE_SDF) {
        fsdem_real pad = 2 * s->dx;
        o.box_lo = fsdem__sub(o.box_lo, fsdem_v3(pad, pad, pad));
        o.box_hi = fsdem__add(o.box_hi, fsdem_v3(pad, pad, pad));
    }
    if (s->dim == 2) {
        o.box_lo.z = -1e30f;
        o.box_hi.z = 1e30f;
    }
    if (ob->type == FSDEM_PIC_OBSTACLE_TYPE_POLYGON) {
        o.verts = (fsdem_vec3 *)fsdem__pic_alloc(s, sizeof(fsdem_vec3) * (size_t)ob->vertex_count);
        if (!o.verts) return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_add_obstacle: out of memory");
        memcpy(o.verts, ob->vertices, sizeof(fsdem_vec3) * (size_t)ob->vertex_count);
        o.d.vertices = o.verts;
    }
    if (s->obst_count == s->obst_capacity) {
        int cap = s->obst_capacity ? 2 * s->obst_capacity : 4;
        fsdem__pic_obst *fresh = (fsdem__pic_obst *)fsdem__pic_alloc(s, sizeof(fsdem__pic_obst) * (size_t)cap);
        if (!fresh) {
            if (o.verts) fsdem__pic_release(s, o.verts, sizeof(fsdem_vec3) * (size_t)ob->vertex_count);
            return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_add_obstacle: out of memory");
        }
        if (s->obst) memcpy(fresh, s->obst, sizeof(fsdem__pic_obst) * (size_t)s->obst_count);
        fsdem__pic_release(s, s->obst, sizeof(fsdem__pic_obst) * (size_t)s->obst_capacity);
        s->obst = fresh;
        s->obst_capacity = cap;
    }
    /* Compute the new fractions into scratch arrays; commit only when some cell stays open. */
    s->obst[s->obst_count++] = o;
    for (b = 0; b < 3; ++b) {
        open[b] = s->ftmp[b];
        vel[b] = s->uold[b];
    }
    open_cells = fsdem__pic_static_faces(s, open, vel);
    if (open_cells == 0) {
        s->obst_count--;
        if (o.verts) fsdem__pic_release(s, o.verts, sizeof(fsdem_vec3) * (size_t)ob->vertex_count);
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pic_add_obstacle: obstacle %d (%s) covers the whole domain: no open cell is left", s->obst_count, name);
    }
    for (b = 0; b < s->dim; ++b) {
        memcpy(s->sopen[b], open[b], sizeof(fsdem_real) * (size_t)s->nface[b]);
        memcpy(s->svel[b], vel[b], sizeof(fsdem_real) * (size_t)s->nface[b]);
    }
    fsdem__pic_static_flags(s);
    fsdem__pic_compute_fref(s);
    s->cells_fresh = 0;
    inside = 0;
    for (i = 0; i < s->np; ++i) {
        s->pflag[i] = fsdem__pic_obst_min(s, s->px[i], NULL) <= 0;
        inside += s->pflag[i];
    }
    if (inside) {
        fsdem__pic_remove_marked(s);
        s->removed += inside;
    }
    fsdem__pic_refresh(s);
    if (id) *id = s->obst_count - 1;
    return fsdem__ok(&s->status);
}
