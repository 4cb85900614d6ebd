/* ===== >>impl_geom : signed distances and closest points =============================================

   Contents: closest points (segment, triangle); the unit direction between two points; signed
   distances (positive outside the solid) of an axis-aligned box (with its outward normal), a sphere
   or disc, a flat-capped cylinder and a 2D polygon; the cut-cell sampler (the open fraction of a
   grid face outside a solid given by its signed distance). */

/* Closest point to p on segment a-b. */
static fsdem_vec3 fsdem__geom_closest_on_segment(fsdem_vec3 p, fsdem_vec3 a, fsdem_vec3 b) {
    fsdem_vec3 ab = fsdem__sub(b, a);
    fsdem_real len2 = fsdem__dot(ab, ab), s = len2 > 0 ? fsdem__dot(fsdem__sub(p, a), ab) / len2 : 0;
    s = s < 0 ? 0 : s > 1 ? 1 : s;
    return fsdem__madd(a, ab, s);
}

/* Closest point to p on triangle a-b-c: the projection when it falls inside, else the closest
   point on the nearest edge (then *on_edge is 1). */
static fsdem_vec3 fsdem__geom_closest_on_triangle(fsdem_vec3 p, fsdem_vec3 a, fsdem_vec3 b, fsdem_vec3 c, int *on_edge) {
    fsdem_vec3 ab = fsdem__sub(b, a), ac = fsdem__sub(c, a), ap = fsdem__sub(p, a);
    fsdem_vec3 nrm = fsdem__cross(ab, ac), q, best;
    fsdem_real n2 = fsdem__dot(nrm, nrm), u, v, dist2, best2;
    fsdem_vec3 edge_point[3];
    int k;
    /* barycentric coordinates of the projection of p */
    v = fsdem__dot(fsdem__cross(ap, ac), nrm) / n2;
    u = fsdem__dot(fsdem__cross(ab, ap), nrm) / n2;
    *on_edge = !(v > 0 && u > 0 && u + v < 1);
    if (v >= 0 && u >= 0 && u + v <= 1) return fsdem__add(a, fsdem__add(fsdem__scale(ab, v), fsdem__scale(ac, u)));
    edge_point[0] = fsdem__geom_closest_on_segment(p, a, b);
    edge_point[1] = fsdem__geom_closest_on_segment(p, b, c);
    edge_point[2] = fsdem__geom_closest_on_segment(p, c, a);
    best = edge_point[0];
    q = fsdem__sub(p, best);
    best2 = fsdem__dot(q, q);
    for (k = 1; k < 3; ++k) {
        q = fsdem__sub(p, edge_point[k]);
        dist2 = fsdem__dot(q, q);
        if (dist2 < best2) {
            best2 = dist2;
            best = edge_point[k];
        }
    }
    return best;
}

/* Unit vector from q to p, or `fallback` when they coincide; their distance goes to *dist. */
static fsdem_vec3 fsdem__geom_direction(fsdem_vec3 p, fsdem_vec3 q, fsdem_vec3 fallback, fsdem_real *dist) {
    fsdem_vec3 dv = fsdem__sub(p, q);
    *dist = fsdem__norm(dv);
    return *dist > 0 ? fsdem__scale(dv, 1 / *dist) : fallback;
}

/* Signed distance from p to the box [lo, hi] over the first `dim` axes (2D: z ignored), positive
   outside, and the unit outward normal: from the closest point of the surface towards p outside,
   through the nearest face inside. */
static fsdem_real fsdem__geom_box(fsdem_vec3 p, fsdem_vec3 lo, fsdem_vec3 hi, int dim, fsdem_vec3 *normal) {
    fsdem_real q[3], e[3] = {0, 0, 0}, depth = (fsdem_real)HUGE_VAL, dist;
    int axis, inside = 1, best_axis = 0, best_side = 0;
    for (axis = 0; axis < 3; ++axis) {
        const fsdem_real x = fsdem__comp(p, axis), l = fsdem__comp(lo, axis), h = fsdem__comp(hi, axis);
        q[axis] = axis >= dim ? x : x < l ? l : x > h ? h : x;
        if (q[axis] != x) inside = 0;
    }
    if (!inside) {
        *normal = fsdem__geom_direction(p, fsdem_v3(q[0], q[1], q[2]), fsdem_v3(1, 0, 0), &dist);
        return dist;
    }
    for (axis = 0; axis < dim; ++axis) {
        const fsdem_real x = fsdem__comp(p, axis), l = fsdem__comp(lo, axis), h = fsdem__comp(hi, axis);
        if (x - l < depth) { depth = x - l; best_axis = axis; best_side = 0; }
        if (h - x < depth) { depth = h - x; best_axis = axis; best_side = 1; }
    }
    e[best_axis] = best_side ? 1 : -1;
    *normal = fsdem_v3(e[0], e[1], e[2]);
    return -depth;
}

/* Signed distance from p to a sphere (3D) or a disc in the x-y plane (2D). */
static fsdem_real fsdem__geom_sphere(fsdem_vec3 p, fsdem_vec3 centre, fsdem_real radius, int dim) {
    fsdem_vec3 q = fsdem__sub(p, centre);
    if (dim == 2) q.z = 0;
    return fsdem__norm(q) - radius;
}

/* Signed distance from p to the flat-capped cylinder of axis a-b (a != b) and `radius`. */
static fsdem_real fsdem__geom_cylinder(fsdem_vec3 p, fsdem_vec3 a, fsdem_vec3 b, fsdem_real radius) {
    fsdem_vec3 e = fsdem__sub(b, a), m = fsdem__scale(fsdem__add(a, b), (fsdem_real)0.5), q;
    fsdem_real len = fsdem__norm(e), z, rad, dr, dz, o2;
    e = fsdem__scale(e, 1 / len);
    q = fsdem__sub(p, m);
    z = fsdem__dot(q, e);
    rad = fsdem__norm(fsdem__madd(q, e, -z));
    dr = rad - radius;
    dz = (fsdem_real)fabs(z) - len / 2;
    o2 = (dr > 0 ? dr * dr : 0) + (dz > 0 ? dz * dz : 0);
    return (dr > dz ? (dr < 0 ? dr : 0) : (dz < 0 ? dz : 0)) + (fsdem_real)sqrt(o2);
}

/* Signed distance from p (x, y) to the closed polygon of `count` vertices (x, y used), any
   orientation: the distance to the nearest edge, negative inside (even-odd rule). */
static fsdem_real fsdem__geom_polygon(fsdem_vec3 p, const fsdem_vec3 *v, int count) {
    fsdem_real best = (fsdem_real)HUGE_VAL;
    int i, j, inside = 0;
    p.z = 0;
    for (i = 0, j = count - 1; i < count; j = i++) {
        const fsdem_vec3 vi = fsdem_v3(v[i].x, v[i].y, 0), vj = fsdem_v3(v[j].x, v[j].y, 0);
        const fsdem_vec3 d = fsdem__sub(p, fsdem__geom_closest_on_segment(p, vj, vi));
        const fsdem_real d2 = fsdem__dot(d, d);
        if (d2 < best) best = d2;
        if ((vi.y > p.y) != (vj.y > p.y) && p.x < (vj.x - vi.x) * (p.y - vi.y) / (vj.y - vi.y) + vi.x) inside = !inside;
    }
    best = (fsdem_real)sqrt(best);
    return inside ? -best : best;
}

/* Fraction of a segment with end values a, b that lies where the distance is > 0 (linear). */
static fsdem_real fsdem__geom_frac2(fsdem_real a, fsdem_real b) {
    if (a > 0 && b > 0) return 1;
    if (a <= 0 && b <= 0) return 0;
    return a > 0 ? a / (a - b) : b / (b - a);
}

/* Same for a triangle with vertex values a, b, c (exact for a linear distance). */
static fsdem_real fsdem__geom_frac3(fsdem_real a, fsdem_real b, fsdem_real c) {
    int pos = (a > 0) + (b > 0) + (c > 0);
    fsdem_real t;
    if (pos == 3) return 1;
    if (pos == 0) return 0;
    if (pos == 1) { /* the lone positive vertex first */
        if (b > 0) { t = a; a = b; b = t; }
        else if (c > 0) { t = a; a = c; c = t; }
        return a * a / ((a - b) * (a - c));
    }
    if (b <= 0) { t = a; a = b; b = t; }
    else if (c <= 0) { t = a; a = c; c = t; }
    return 1 - a * a / ((a - b) * (a - c));
}

#define FSDEM__GEOM_FACE_SUB 4 /* sub-segments (sub-squares per side) of a face for its open fraction */

/* A solid's signed distance (m, positive outside) at p. */
typedef fsdem_real (*fsdem__geom_dist_fn)(const void *solid, fsdem_vec3 p);

/* The distance for the face fractions, 0 within `tol` of the surface. A face lying on a solid's
   side (a box edge on a grid line) must not depend on the rounding of the two coordinates: left to
   it, the face could come out open by 1e-15 of its area and leave a chain of cells joined only by
   such faces, a near-singular pressure operator. Counted as on the surface, a sample point there
   is solid (fsdem__geom_frac2 opens only d > 0), so a side on a face and a side a hair off it give
   the same fractions. */
static fsdem_real fsdem__geom_face_sample(fsdem_real tol, fsdem__geom_dist_fn dist, const void *solid, fsdem_vec3 p) {
    fsdem_real d = dist(solid, p);
    return (fsdem_real)fabs(d) <= tol ? 0 : d;
}

/* The cut-cell sampler: open fraction of the face of axis a with lower corner `c0` (m), spanning
   one cell of `dx` along the other axes (dim 2 or 3), outside the solid whose signed distance is
   dist(solid, p) (a PIC's obstacle union, a coupler's moving body), `tol` as above. */
static fsdem_real fsdem__geom_face_fraction(int dim, int a, fsdem_vec3 c0, fsdem_real dx, fsdem_real tol, fsdem__geom_dist_fn dist,
                                            const void *solid) {
    const int S = FSDEM__GEOM_FACE_SUB;
    fsdem_real h = dx / S, v[FSDEM__GEOM_FACE_SUB + 1][FSDEM__GEOM_FACE_SUB + 1], sum = 0;
    int b1 = (a + 1) % 3, b2 = (a + 2) % 3, i, j;
    if (dim == 2) {
        int b = a == 0 ? 1 : 0;
        for (i = 0; i <= S; ++i) v[0][i] = fsdem__geom_face_sample(tol, dist, solid, fsdem__axis_shift(c0, b, h * (fsdem_real)i));
        for (i = 0; i < S; ++i) sum += fsdem__geom_frac2(v[0][i], v[0][i + 1]);
        return sum / S;
    }
    for (j = 0; j <= S; ++j)
        for (i = 0; i <= S; ++i)
            v[j][i] = fsdem__geom_face_sample(
                tol, dist, solid, fsdem__axis_shift(fsdem__axis_shift(c0, b1, h * (fsdem_real)i), b2, h * (fsdem_real)j));
    for (j = 0; j < S; ++j)
        for (i = 0; i < S; ++i) {
            fsdem_vec3 m = fsdem__axis_shift(fsdem__axis_shift(c0, b1, h * ((fsdem_real)i + (fsdem_real)0.5)), b2,
                                                 h * ((fsdem_real)j + (fsdem_real)0.5));
            fsdem_real vc = fsdem__geom_face_sample(tol, dist, solid, m);
            sum += fsdem__geom_frac3(vc, v[j][i], v[j][i + 1]) + fsdem__geom_frac3(vc, v[j][i + 1], v[j + 1][i + 1]) +
                   fsdem__geom_frac3(vc, v[j + 1][i + 1], v[j + 1][i]) + fsdem__geom_frac3(vc, v[j + 1][i], v[j][i]);
        }
    return sum / (4 * S * S);
}
