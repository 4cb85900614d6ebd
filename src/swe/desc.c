/* ---- >>swe_desc : defaults and validation ---- */

fsdem_swe_desc fsdem_swe_desc_default(int dim) {
    fsdem_swe_desc d;
    int k;
    memset(&d, 0, sizeof d);
    d.dim = dim;
    d.nx = 100;
    d.ny = dim == 2 ? 100 : 1;
    d.x_min = 0;
    d.x_max = 1;
    d.y_min = 0;
    d.y_max = 1;
    d.width = 1;
    d.gravity = fsdem_v3(0, 0, (fsdem_real)-9.81);
    d.density = 1000;
    d.cfl = (fsdem_real)0.5;
    d.dt_max = 1;
    d.order = 2;
    d.limiter = FSDEM_SWE_LIMITER_MINMOD;
    d.dry_depth = (fsdem_real)1e-6;
    d.manning = 0;
    d.eddy_viscosity = 0;
    d.rain_rate = 0;
    for (k = 0; k < 4; ++k) d.boundary[k].type = FSDEM_SWE_BC_WALL;
    return d;
}

static const char *fsdem__swe_side_name(int side) {
    static const char *names[4] = {"XMIN", "XMAX", "YMIN", "YMAX"};
    return side >= 0 && side < 4 ? names[side] : "?";
}

/* A time series: increasing finite times, values finite within +-bound (in [0, bound] when
   non_negative). */
static fsdem_result fsdem__swe_series_check(const fsdem_real *t, const fsdem_real *v, int n, int non_negative, fsdem_real bound,
                                            const char *what, char *msg, size_t size) {
    int k;
    if (n == 0 && !t && !v) return FSDEM_OK;
    if (n < 1 || !t || !v)
        return fsdem__reject(msg, size, "%s: a series needs series_count >= 1 and both arrays (got %d points)",
                             what, n);
    for (k = 0; k < n; ++k) {
        if (!fsdem__finite(t[k]) || !fsdem__finite(v[k]))
            return fsdem__reject(msg, size, "%s: series point %d is not finite", what, k);
        if (k > 0 && !(t[k] > t[k - 1]))
            return fsdem__reject(msg, size, "%s: series times must increase strictly (point %d: %g after %g s)",
                                 what, k, (double)t[k], (double)t[k - 1]);
        if (!(v[k] >= (non_negative ? 0 : -bound) && v[k] <= bound))
            return fsdem__reject(msg, size, "%s: series value %d must be in [%g, %g] (got %g)", what, k,
                                 non_negative ? 0.0 : -(double)bound, (double)bound, (double)v[k]);
    }
    return FSDEM_OK;
}

static fsdem_result fsdem__swe_boundary_check(const fsdem_swe_boundary *b, int side, char *msg, size_t size) {
    char what[64];
    snprintf(what, sizeof what, "boundary[%s]", fsdem__swe_side_name(side));
    if (!b) return fsdem__reject(msg, size, "%s is NULL", what);
    if (b->type != FSDEM_SWE_BC_WALL && b->type != FSDEM_SWE_BC_TRANSMISSIVE && b->type != FSDEM_SWE_BC_DISCHARGE &&
        b->type != FSDEM_SWE_BC_STAGE)
        return fsdem__reject(msg, size, "%s.type is not a fsdem_swe_bc (%d)", what, (int)b->type);
    {
        /* a stage is an elevation; a unit discharge is at most FSDEM_MAX_SPEED through FSDEM_MAX_LENGTH of depth */
        const int discharge = b->type == FSDEM_SWE_BC_DISCHARGE;
        const fsdem_real bound = discharge ? FSDEM_MAX_SPEED * FSDEM_MAX_LENGTH : FSDEM_MAX_LENGTH;
        if (!(b->value >= (discharge ? 0 : -bound) && b->value <= bound))
            return fsdem__reject(msg, size, "%s.value must be in [%g, %g] %s (got %g)", what, discharge ? 0.0 : -(double)bound,
                                 (double)bound, discharge ? "m^2/s (an inflow discharge)" : "m", (double)b->value);
        return fsdem__swe_series_check(b->series_time, b->series_value, b->series_count, discharge, bound, what, msg, size);
    }
}

/* The first value that is not in [-bound, bound] (in [0, bound] when non_negative), or -1. */
static int fsdem__swe_first_bad(const fsdem_real *a, int n, int non_negative, fsdem_real bound) {
    int k;
    for (k = 0; k < n; ++k)
        if (!(a[k] >= (non_negative ? 0 : -bound) && a[k] <= bound)) return k;
    return -1;
}

fsdem_result fsdem_swe_desc_check(const fsdem_swe_desc *d, char *msg, size_t size) {
    int k, n;
    fsdem_result res;
    if (!d) return fsdem__reject(msg, size, "fsdem_swe_desc is NULL");
    if (d->dim != 1 && d->dim != 2) return fsdem__reject(msg, size, "fsdem_swe_desc.dim must be 1 or 2 (got %d)", d->dim);
    if (d->nx < 1) return fsdem__reject(msg, size, "fsdem_swe_desc.nx must be >= 1 cell (got %d)", d->nx);
    if (d->ny < 1) return fsdem__reject(msg, size, "fsdem_swe_desc.ny must be >= 1 cell (got %d)", d->ny);
    if (d->dim == 1 && d->ny != 1) return fsdem__reject(msg, size, "fsdem_swe_desc.ny must be 1 in 1D (got %d)", d->ny);
    if ((double)d->nx * (double)d->ny > (double)(1 << 30))
        return fsdem__reject(msg, size, "fsdem_swe_desc: nx*ny = %g cells is too many", (double)d->nx * (double)d->ny);
    if (!fsdem__finite(d->x_min) || !fsdem__finite(d->x_max) || !(d->x_max > d->x_min))
        return fsdem__reject(msg, size, "fsdem_swe_desc.x_max must exceed x_min (got %g .. %g m)", (double)d->x_min,
                             (double)d->x_max);
    if (d->dim == 2 && (!fsdem__finite(d->y_min) || !fsdem__finite(d->y_max) || !(d->y_max > d->y_min)))
        return fsdem__reject(msg, size, "fsdem_swe_desc.y_max must exceed y_min (got %g .. %g m)", (double)d->y_min,
                             (double)d->y_max);
    if (d->dim == 1 && (!(d->width > 0) || !fsdem__finite(d->width)))
        return fsdem__reject(msg, size, "fsdem_swe_desc.width must be > 0 (got %g m)", (double)d->width);
    {
        /* cells of a finite, normal size: a range of +-1e308 overflows dx, one of 1e-308 underflows
           the cell area */
        const fsdem_real dx = (d->x_max - d->x_min) / (fsdem_real)d->nx;
        const fsdem_real dy = d->dim == 2 ? (d->y_max - d->y_min) / (fsdem_real)d->ny : d->width, area = dx * dy;
        if (!fsdem__finite(dx) || !fsdem__finite(dy) || !fsdem__finite(area) || !(area > 0) || !fsdem__finite(1 / area) ||
            !fsdem__finite(1 / dx) || !fsdem__finite(1 / dy) || area < (fsdem_real)FLT_MIN)
            return fsdem__reject(msg, size, "fsdem_swe_desc: cells of %g x %g m (extent / cell count) are not of a finite, "
                                            "representable size", (double)dx, (double)dy);
    }
    if (d->gravity.x != 0 || d->gravity.y != 0 || !(d->gravity.z < 0 && d->gravity.z >= -FSDEM_MAX_ACCELERATION))
        return fsdem__reject(msg, size,
                             "fsdem_swe_desc.gravity must be (0, 0, -g) with 0 < g <= FSDEM_MAX_ACCELERATION (%g m/s^2) (got (%g, %g, %g) m/s^2)",
                             (double)FSDEM_MAX_ACCELERATION, (double)d->gravity.x, (double)d->gravity.y, (double)d->gravity.z);
    if (!(d->density > 0) || !fsdem__finite(d->density))
        return fsdem__reject(msg, size, "fsdem_swe_desc.density must be > 0 (got %g kg/m^3)", (double)d->density);
    if (!(d->cfl > 0 && d->cfl <= 1))
        return fsdem__reject(msg, size, "fsdem_swe_desc.cfl must be in (0, 1] (got %g)", (double)d->cfl);
    if (fsdem__check_dt_max("fsdem_swe_desc", d->dt_max, d->gravity, msg, size) != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    if (d->order != 1 && d->order != 2)
        return fsdem__reject(msg, size, "fsdem_swe_desc.order must be 1 or 2 (got %d)", d->order);
    if ((int)d->limiter < 0 || (int)d->limiter > 3)
        return fsdem__reject(msg, size, "fsdem_swe_desc.limiter is not a fsdem_swe_limiter (%d)", (int)d->limiter);
    if (!(d->dry_depth > 0) || !fsdem__finite(d->dry_depth))
        return fsdem__reject(msg, size, "fsdem_swe_desc.dry_depth must be > 0 (got %g m)", (double)d->dry_depth);
    if (!(d->manning >= 0 && d->manning <= 1)) /* the bound of fsdem_swe_set_manning */
        return fsdem__reject(msg, size, "fsdem_swe_desc.manning must be in [0, 1] (got %g s/m^(1/3))", (double)d->manning);
    if (!(d->eddy_viscosity >= 0) || !fsdem__finite(d->eddy_viscosity))
        return fsdem__reject(msg, size, "fsdem_swe_desc.eddy_viscosity must be >= 0 (got %g m^2/s)",
                             (double)d->eddy_viscosity);
    if (!(d->rain_rate >= 0) || !fsdem__finite(d->rain_rate))
        return fsdem__reject(msg, size, "fsdem_swe_desc.rain_rate must be >= 0 (got %g m/s)", (double)d->rain_rate);
    for (k = 0; k < (d->dim == 2 ? 4 : 2); ++k) {
        res = fsdem__swe_boundary_check(&d->boundary[k], k, msg, size);
        if (res != FSDEM_OK) return res;
    }
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        return fsdem__reject(msg, size, "fsdem_swe_desc.allocator: set both alloc and free, or neither");
    n = d->nx * d->ny;
    if (d->bed && (k = fsdem__swe_first_bad(d->bed, n, 0, FSDEM_MAX_LENGTH)) >= 0)
        return fsdem__reject(msg, size, "fsdem_swe_desc.bed[%d] (cell i=%d, j=%d) must be finite, |bed| <= FSDEM_MAX_LENGTH (got %g m)", k,
                             k % d->nx, k / d->nx, (double)d->bed[k]);
    if (d->depth && (k = fsdem__swe_first_bad(d->depth, n, 1, FSDEM_MAX_LENGTH)) >= 0)
        return fsdem__reject(msg, size, "fsdem_swe_desc.depth[%d] (cell i=%d, j=%d) must be in [0, FSDEM_MAX_LENGTH] (got %g m)",
                             k, k % d->nx, k / d->nx, (double)d->depth[k]);
    return FSDEM_OK;
}
