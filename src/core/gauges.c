/* ---- >>core_gauges : the point gauges of the particle solvers ---- */

/* Level and pressure gauges of the PIC and MPS solvers: a kind (the value of FSDEM_PIC_GAUGE_KIND_LEVEL
   and FSDEM_MPS_GAUGE_KIND_LEVEL, or of the _PRESSURE kinds), a position and a sensor radius per gauge,
   and the CSV series they write (fsdem__series; columns level_<id> or p_<id>). The solver samples
   them (its own level and pressure functions) and checks what is its own (the domain, gravity);
   `fn` names its public function in the messages. */
enum { FSDEM__GAUGE_LEVEL = 0, FSDEM__GAUGE_PRESSURE = 1 };

typedef struct fsdem__gauges {
    fsdem_vec3 *at;
    int *kind;
    fsdem_real *radius; /* m; 0 for a point */
    int count, capacity;
    fsdem__series series;
} fsdem__gauges;

/* Appends a gauge at `at`, which must lie in the box [lo, hi] along the first `dim` axes. */
static fsdem_result fsdem__gauges_add(fsdem__gauges *g, fsdem__status *st, const fsdem_allocator *al, const char *fn, int kind,
                                      fsdem_vec3 at, fsdem_real radius, int dim, fsdem_vec3 lo, fsdem_vec3 hi, int *id) {
    const int n = g->count;
    int a;
    if (id) *id = -1;
    if (g->series.file) return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: close the gauge file first", fn);
    if (kind < FSDEM__GAUGE_LEVEL || kind > FSDEM__GAUGE_PRESSURE || !fsdem__finite3(at) || !(radius >= 0) || !fsdem__finite(radius))
        return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: the kind must be a gauge kind, the position finite, the radius >= 0", fn);
    for (a = 0; a < dim; ++a)
        if (!(fsdem__comp(at, a) >= fsdem__comp(lo, a) && fsdem__comp(at, a) <= fsdem__comp(hi, a)))
            return fsdem__fail(st, FSDEM_ERR_OUT_OF_DOMAIN, "%s: (%g, %g, %g) is outside the domain", fn, (double)at.x, (double)at.y,
                               (double)at.z);
    {
        void **const arrays[3] = {(void **)&g->at, (void **)&g->kind, (void **)&g->radius};
        const size_t elem[3] = {sizeof(fsdem_vec3), sizeof(int), sizeof(fsdem_real)};
        if (fsdem__grow_set(al, arrays, elem, 3, &g->capacity, n, n + 1) != FSDEM_OK)
            return fsdem__fail(st, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory for gauge %d", fn, n);
    }
    g->at[n] = at;
    g->kind[n] = kind;
    g->radius[n] = radius;
    g->count++;
    if (id) *id = n;
    return fsdem__ok(st);
}

/* Opens the series at time t (a file already open is closed first). */
static fsdem_result fsdem__gauges_open(fsdem__gauges *g, fsdem__status *st, const fsdem_allocator *al, const char *fn,
                                       const char *path, double t, fsdem_real interval, fsdem__series_sample_fn sample,
                                       const void *solver) {
    char *header;
    size_t size;
    int k, n = 1;
    fsdem_result res;
    if (g->count == 0) return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: add gauges first", fn);
    if (!(interval >= 0) || !fsdem__finite(interval))
        return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: interval must be >= 0 (got %g s)", fn, (double)interval);
    fsdem__series_close(&g->series, al);
    size = 2 + 24 * (size_t)g->count;
    header = (char *)fsdem__alloc(al, size);
    if (!header) return fsdem__fail(st, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
    header[0] = 't';
    header[1] = '\0';
    for (k = 0; k < g->count; ++k)
        n += snprintf(header + n, size - (size_t)n, g->kind[k] == FSDEM__GAUGE_LEVEL ? ",level_%d" : ",p_%d", k);
    res = fsdem__series_open(&g->series, al, path, header, g->count, t, (double)interval, sample, solver);
    fsdem__free(al, header, size);
    if (res != FSDEM_OK) return fsdem__fail(st, res, "%s: cannot open '%s'", fn, path ? path : "(null)");
    return fsdem__ok(st);
}

static fsdem_result fsdem__gauges_close(fsdem__gauges *g, fsdem__status *st, const fsdem_allocator *al, const char *fn) {
    return fsdem__series_close(&g->series, al) == FSDEM_OK ? fsdem__ok(st) : fsdem__fail(st, FSDEM_ERR_IO, "%s: write error", fn);
}

/* Frees the gauges' arrays (count and capacity 0); the series is left as it is. */
static void fsdem__gauges_free_arrays(fsdem__gauges *g, const fsdem_allocator *al) {
    fsdem__free(al, g->at, sizeof(fsdem_vec3) * (size_t)g->capacity);
    fsdem__free(al, g->kind, sizeof(int) * (size_t)g->capacity);
    fsdem__free(al, g->radius, sizeof(fsdem_real) * (size_t)g->capacity);
    g->at = NULL;
    g->kind = NULL;
    g->radius = NULL;
    g->count = g->capacity = 0;
}

/* Closes the series and frees the gauges. */
static void fsdem__gauges_free(fsdem__gauges *g, const fsdem_allocator *al) {
    fsdem__series_close(&g->series, al);
    fsdem__gauges_free_arrays(g, al);
    memset(g, 0, sizeof *g);
}
