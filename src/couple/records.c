/* ---- >>couple_records : per-particle records by their fields ---- */

/* The record of DEM particle `index` from the last update, or NULL. The records were made for
   particles whose stable ids ascend (the DEM keeps its ids in index order: new particles go to the
   end, removals keep the order), so a particle added or removed since is told by its id, found by
   bisection. */
static const void *fsdem__coupler_record(const fsdem_coupler *c, int index) {
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->dem);
    const size_t size = c->cls->record_size;
    int lo = 0, hi = c->records - 1;
    if (index < 0 || index >= P.count || !c->record) return NULL;
    while (lo <= hi) {
        const int mid = lo + (hi - lo) / 2;
        const char *r = (const char *)c->record + (size_t)mid * size;
        const int at = *(const int *)(const void *)r;
        if (at == P.id[index]) return r;
        if (at < P.id[index]) lo = mid + 1;
        else hi = mid - 1;
    }
    return NULL;
}

/* fsdem_X_get_force: a copy of the record of particle `index`. FSDEM_ERR_NOT_FOUND names the
   particle (the only message a query writes). */
static fsdem_result fsdem__coupler_get_record(const fsdem_coupler *c, int index, void *out, const char *who) {
    const void *r;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    if (!(r = fsdem__coupler_record(c, index)))
        return fsdem__fail((fsdem__status *)&c->status, FSDEM_ERR_NOT_FOUND, "%s: no particle %d in the last update", who, index);
    memcpy(out, r, c->cls->record_size);
    return FSDEM_OK;
}

/* The values of the record of particle `index` as a CSV row (fsdem__row_fn); 0 without a record. */
static int fsdem__coupler_row(const void *object, int index, double *v) {
    const fsdem_coupler *c = (const fsdem_coupler *)object;
    const char *r = (const char *)fsdem__coupler_record(c, index);
    int k, n = 0;
    if (!r) return 0;
    for (k = 0; k < c->cls->field_count; ++k) {
        const fsdem__field *f = &c->cls->fields[k];
        const void *at = r + f->offset;
        if (f->kind == FSDEM__FIELD_INT) v[n++] = *(const int *)at;
        else if (f->kind == FSDEM__FIELD_REAL) v[n++] = (double)*(const fsdem_real *)at;
        else {
            const fsdem_vec3 *u = (const fsdem_vec3 *)at;
            v[n++] = (double)u->x;
            v[n++] = (double)u->y;
            v[n++] = (double)u->z;
        }
    }
    return 1;
}

/* fsdem_X_write_csv: a header of the record's fields (a vector as name_x, name_y, name_z), then a
   row for every DEM particle with a record, in index order. */
static fsdem_result fsdem__coupler_write_csv(const fsdem_coupler *c, const char *path, const char *who) {
    char header[1024];
    size_t used = 0;
    int k;
    for (k = 0; k < c->cls->field_count && used < sizeof header; ++k) {
        const fsdem__field *f = &c->cls->fields[k];
        const char *sep = k ? "," : "";
        used += (size_t)(f->kind == FSDEM__FIELD_VEC3
                             ? snprintf(header + used, sizeof header - used, "%s%s_x,%s_y,%s_z", sep, f->name, f->name, f->name)
                             : snprintf(header + used, sizeof header - used, "%s%s", sep, f->name));
    }
    FSDEM_ASSERT(used < sizeof header); /* the record types' fields fit with room to spare */
    return fsdem__write_rows(&c->status, who, path, header, fsdem_dem_get_particles(c->dem).count, fsdem__coupler_row, c);
}
