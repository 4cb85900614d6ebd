/* ---- >>dem_wall : wall geometry ---- */

static fsdem_dem_wall_desc fsdem__dem_wall_desc(fsdem_dem_wall_type type, fsdem_vec3 a, fsdem_vec3 b, fsdem_vec3 c, int material) {
    fsdem_dem_wall_desc w;
    memset(&w, 0, sizeof w);
    w.type = type;
    w.a = a;
    w.b = b;
    w.c = c;
    w.material = material;
    return w;
}

fsdem_dem_wall_desc fsdem_dem_wall_plane(fsdem_vec3 point, fsdem_vec3 normal, int material) {
    return fsdem__dem_wall_desc(FSDEM_DEM_WALL_TYPE_PLANE, point, normal, fsdem__zero3(), material);
}
fsdem_dem_wall_desc fsdem_dem_wall_box(fsdem_vec3 lo, fsdem_vec3 hi, int inside, int material) {
    return fsdem__dem_wall_desc(inside ? FSDEM_DEM_WALL_TYPE_BOX_INSIDE : FSDEM_DEM_WALL_TYPE_BOX_OUTSIDE, lo, hi, fsdem__zero3(), material);
}
fsdem_dem_wall_desc fsdem_dem_wall_segment(fsdem_vec3 a, fsdem_vec3 b, int material) {
    return fsdem__dem_wall_desc(FSDEM_DEM_WALL_TYPE_SEGMENT, a, b, fsdem__zero3(), material);
}
fsdem_dem_wall_desc fsdem_dem_wall_triangle(fsdem_vec3 a, fsdem_vec3 b, fsdem_vec3 c, int material) {
    return fsdem__dem_wall_desc(FSDEM_DEM_WALL_TYPE_TRIANGLE, a, b, c, material);
}
fsdem_dem_wall_desc fsdem_dem_wall_sdf(fsdem_sdf_fn sdf, void *user, int material) {
    fsdem_dem_wall_desc w = fsdem__dem_wall_desc(FSDEM_DEM_WALL_TYPE_SDF, fsdem__zero3(), fsdem__zero3(), fsdem__zero3(), material);
    w.sdf = sdf;
    w.sdf_user = user;
    return w;
}

static int fsdem__dem_wall_faces(const fsdem__dem_wall *w, int dim) {
    return w->d.type == FSDEM_DEM_WALL_TYPE_BOX_INSIDE ? 2 * dim : 1;
}

/* Signed distance (m) from p to face `face` of a wall, with the unit normal from the wall towards p.
   *on_feature is set when the closest point is an edge or vertex of a triangle, or an end of a
   segment: such points are shared by neighbouring elements of a mesh (see fsdem__dem_wall_hits). */
static fsdem_real fsdem__dem_wall_distance(const fsdem__dem_wall *w, int face, fsdem_vec3 p, int dim, fsdem_vec3 *n,
                                      int *on_feature) {
    const fsdem_dem_wall_desc *g = &w->d;
    fsdem_real dist;
    *on_feature = 0;
    switch (g->type) {
    case FSDEM_DEM_WALL_TYPE_PLANE:
        *n = g->b;
        return fsdem__dot(fsdem__sub(p, g->a), g->b);
    case FSDEM_DEM_WALL_TYPE_BOX_INSIDE: {
        int axis = face / 2;
        fsdem_real e[3] = {0, 0, 0};
        e[axis] = face % 2 == 0 ? 1 : -1;
        *n = fsdem_v3(e[0], e[1], e[2]);
        return face % 2 == 0 ? fsdem__comp(p, axis) - fsdem__comp(g->a, axis) : fsdem__comp(g->b, axis) - fsdem__comp(p, axis);
    }
    case FSDEM_DEM_WALL_TYPE_BOX_OUTSIDE: return fsdem__geom_box(p, g->a, g->b, dim, n);
    case FSDEM_DEM_WALL_TYPE_SEGMENT: {
        fsdem_vec3 ab = fsdem__sub(g->b, g->a), perp = fsdem_v3(-ab.y, ab.x, 0);
        fsdem_real len = fsdem__norm(perp);
        fsdem_vec3 q = fsdem__geom_closest_on_segment(p, g->a, g->b);
        perp = len > 0 ? fsdem__scale(perp, 1 / len) : fsdem_v3(0, 1, 0);
        *on_feature = fsdem__dot(fsdem__sub(q, g->a), fsdem__sub(q, g->a)) == 0 ||
                      fsdem__dot(fsdem__sub(q, g->b), fsdem__sub(q, g->b)) == 0;
        *n = fsdem__geom_direction(p, q, perp, &dist);
        return dist;
    }
    case FSDEM_DEM_WALL_TYPE_TRIANGLE: {
        fsdem_vec3 nrm = fsdem__cross(fsdem__sub(g->b, g->a), fsdem__sub(g->c, g->a));
        fsdem_vec3 q = fsdem__geom_closest_on_triangle(p, g->a, g->b, g->c, on_feature);
        nrm = fsdem__scale(nrm, 1 / fsdem__norm(nrm));
        *n = fsdem__geom_direction(p, q, nrm, &dist);
        return dist;
    }
    case FSDEM_DEM_WALL_TYPE_SDF:
    default: {
        fsdem_vec3 grad = fsdem_v3(0, 0, 1);
        fsdem_real len;
        dist = g->sdf(g->sdf_user, p, &grad);
        if (dim == 2) grad.z = 0;
        len = fsdem__norm(grad);
        *n = len > 0 ? fsdem__scale(grad, 1 / len) : fsdem_v3(0, 0, 1);
        return dist;
    }
    }
}

fsdem_result fsdem_dem_add_wall(fsdem_dem *d, const fsdem_dem_wall_desc *desc, int *id) {
    fsdem_dem_wall_desc g;
    fsdem__dem_wall *w;
    int axis;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    if (!desc) return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_add_wall: desc is NULL");
    g = *desc;
    if (g.material < 0 || g.material >= d->material_count)
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_wall_desc.material %d is not a material of this simulation",
                           g.material);
    if (!fsdem__finite3(g.a) || !fsdem__finite3(g.b) || !fsdem__finite3(g.c) || !fsdem__within(g.velocity, FSDEM_MAX_SPEED))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_dem_wall_desc: the geometry must be finite and the velocity at most FSDEM_MAX_SPEED (%g m/s)",
                           (double)FSDEM_MAX_SPEED);
    if (d->desc.dim == 2) {
        g.a.z = g.b.z = g.c.z = g.velocity.z = 0;
    }
    switch (g.type) {
    case FSDEM_DEM_WALL_TYPE_PLANE: {
        fsdem_real len, big;
        if (d->desc.dim == 2) g.b.z = 0;
        /* scaled by its largest component first, so a normal of (1e300, 1e300, 1e300) does not
           overflow to a zero unit vector */
        big = (fsdem_real)fmax(fmax(fabs(g.b.x), fabs(g.b.y)), fabs(g.b.z));
        if (!(big > 0)) return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_wall_plane: the normal is zero");
        g.b = fsdem__scale(g.b, 1 / big);
        len = fsdem__norm(g.b);
        g.b = fsdem__scale(g.b, 1 / len);
        break;
    }
    case FSDEM_DEM_WALL_TYPE_BOX_INSIDE:
    case FSDEM_DEM_WALL_TYPE_BOX_OUTSIDE:
        for (axis = 0; axis < d->desc.dim; ++axis)
            if (!(fsdem__comp(g.b, axis) > fsdem__comp(g.a, axis)) || !fsdem__finite(fsdem__comp(g.b, axis) - fsdem__comp(g.a, axis)))
                return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                                   "fsdem_dem_wall_box: hi must exceed lo by a finite extent on axis %d", axis);
        break;
    case FSDEM_DEM_WALL_TYPE_SEGMENT:
        if (d->desc.dim != 2)
            return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_wall_segment: segments need dim = 2 (use triangles in 3D)");
        if (!(fsdem__norm(fsdem__sub(g.b, g.a)) > 0) || !fsdem__finite(fsdem__norm(fsdem__sub(g.b, g.a))))
            return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                               "fsdem_dem_wall_segment: the end points must be distinct at a finite distance");
        break;
    case FSDEM_DEM_WALL_TYPE_TRIANGLE:
        if (d->desc.dim != 3)
            return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_wall_triangle: triangles need dim = 3 (use segments in 2D)");
        {
            /* twice the area; not finite when coordinates of 1e200 overflow it */
            const fsdem_real area2 = fsdem__norm(fsdem__cross(fsdem__sub(g.b, g.a), fsdem__sub(g.c, g.a)));
            if (!(area2 > 0) || !fsdem__finite(area2) || !fsdem__finite(1 / area2))
                return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                                   "fsdem_dem_wall_triangle: the triangle is degenerate or too large (twice its area: %g m^2)",
                                   (double)area2);
        }
        break;
    case FSDEM_DEM_WALL_TYPE_SDF:
        if (!g.sdf) return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_wall_sdf: the callback is NULL");
        if (fsdem__norm(g.velocity) > 0)
            return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                               "fsdem_dem_wall_sdf: a moving SDF wall must move inside its callback (velocity must be 0)");
        break;
    default:
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_wall_desc.type %d is not a fsdem_dem_wall_type", (int)g.type);
    }
    /* wall keys (wall * 8 + face) stay below the entry flags */
    if (d->wall_count >= FSDEM__DEM_HELD / 8)
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_dem_add_wall: at most %d walls", FSDEM__DEM_HELD / 8);
    if (fsdem__grow(&d->allocator, (void **)&d->walls, &d->wall_capacity, d->wall_count, d->wall_count + 1,
                    sizeof(fsdem__dem_wall)) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_dem_add_wall: out of memory");
    w = &d->walls[d->wall_count];
    memset(w, 0, sizeof *w);
    w->d = g;
    w->active = 1;
    if (id) *id = d->wall_count;
    d->wall_count++;
    d->need_rebuild = 1;
    d->forces_valid = 0;
    return fsdem__ok(&d->status);
}

static fsdem__dem_wall *fsdem__dem_wall_by_id(fsdem_dem *d, int id, const char *what) {
    if (id < 0 || id >= d->wall_count || !d->walls[id].active) {
        fsdem__fail(&d->status, FSDEM_ERR_NOT_FOUND, "%s: wall %d does not exist", what, id);
        return NULL;
    }
    return &d->walls[id];
}

fsdem_result fsdem_dem_remove_wall(fsdem_dem *d, int id) {
    fsdem__dem_wall *w = d ? fsdem__dem_wall_by_id(d, id, "fsdem_dem_remove_wall") : NULL;
    if (!w) return d ? FSDEM_ERR_NOT_FOUND : FSDEM_ERR_INVALID_ARG;
    w->active = 0;
    w->force = fsdem__zero3();
    d->need_rebuild = 1;
    d->forces_valid = 0;
    return fsdem__ok(&d->status);
}

fsdem_result fsdem_dem_set_wall_velocity(fsdem_dem *d, int id, fsdem_vec3 velocity) {
    fsdem__dem_wall *w = d ? fsdem__dem_wall_by_id(d, id, "fsdem_dem_set_wall_velocity") : NULL;
    if (!w) return d ? FSDEM_ERR_NOT_FOUND : FSDEM_ERR_INVALID_ARG;
    if (!fsdem__within(velocity, FSDEM_MAX_SPEED))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_dem_set_wall_velocity: velocity (%g, %g, %g) m/s must be finite and at most FSDEM_MAX_SPEED (%g m/s)",
                           (double)velocity.x, (double)velocity.y, (double)velocity.z, (double)FSDEM_MAX_SPEED);
    if (w->d.type == FSDEM_DEM_WALL_TYPE_SDF && fsdem__norm(velocity) > 0)
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_set_wall_velocity: an SDF wall moves in its callback");
    if (d->desc.dim == 2) velocity.z = 0;
    w->d.velocity = velocity;
    return fsdem__ok(&d->status);
}

fsdem_result fsdem_dem_wall_moved(fsdem_dem *d, int id, fsdem_real distance) {
    fsdem__dem_wall *w = d ? fsdem__dem_wall_by_id(d, id, "fsdem_dem_wall_moved") : NULL;
    if (!w) return d ? FSDEM_ERR_NOT_FOUND : FSDEM_ERR_INVALID_ARG;
    if (!(distance >= 0) || !fsdem__finite(distance))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_wall_moved: distance must be >= 0 (got %g m)",
                           (double)distance);
    w->moved += distance;
    return fsdem__ok(&d->status);
}

fsdem_vec3 fsdem_dem_wall_force(const fsdem_dem *d, int id) {
    return d && id >= 0 && id < d->wall_count ? d->walls[id].force : fsdem__zero3();
}

fsdem_vec3 fsdem_dem_wall_impulse(const fsdem_dem *d, int id) {
    return d && id >= 0 && id < d->wall_count ? d->walls[id].impulse : fsdem__zero3();
}

/* Threaded evaluation (>>doc THREADS): the pair list is cut into chunks of this many entries for
   the touching pass, and the touching pairs into batches as on one thread. */
#ifndef FSDEM__DEM_CHUNK /* (make determinism sets these grains small, so every scene takes every threaded path) */
#define FSDEM__DEM_CHUNK 8192
#endif

/* One touching pair's results, kept so the forces can be added in the order of the contact list. */
typedef struct fsdem__dem_result {
    fsdem_vec3 force, torque_i, torque_j, rolling;
    int i, other, rolls;
} fsdem__dem_result;

/* Bytes of the force evaluation's scratch for `workers` threads: the touching list, one batch per
   thread, and with threads the chunk counts and a result per pair. */
static size_t fsdem__dem_force_scratch(const fsdem_dem *d, int workers) {
    const size_t pairs = (size_t)d->pp.count, chunks = pairs / FSDEM__DEM_CHUNK + 1;
    size_t bytes = fsdem__arena_bytes(sizeof(int) * pairs) + (size_t)workers * fsdem__arena_bytes(sizeof(fsdem__dem_batch));
    if (workers > 1)
        bytes += fsdem__arena_bytes(sizeof(int) * chunks) + fsdem__arena_bytes(sizeof(fsdem__dem_result) * pairs) +
                 fsdem__arena_bytes(sizeof(fsdem_real) * (size_t)workers);
    return bytes;
}
