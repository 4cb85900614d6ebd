/* ---- >>restart_journal : the state a coupled step keeps, to put back should it fail ---- */

/* A coupler as the API sees it (>>restart_api), whatever its kind. */
static fsdem__restart_object fsdem__restart_of_coupler(const fsdem_coupler *c) {
    if (c->cls == fsdem__swe_dem_class()) return fsdem__restart_of_swe_dem((const fsdem_swe_dem *)(const void *)c);
    if (c->cls == fsdem__mps_dem_class()) return fsdem__restart_of_mps_dem((const fsdem_mps_dem *)(const void *)c);
    if (c->cls == fsdem__pic_dem_class()) return fsdem__restart_of_pic_dem((const fsdem_pic_dem *)(const void *)c);
    return fsdem__restart_of_gic((const fsdem_gic *)(const void *)c);
}

/* Keeps what coupler c's step may change, before anything moves: its saved bytes (>>restart_couplers:
   the fluid and the DEM with it) without their checksum (they never leave the process), then its
   records (not every field of a record is saved), in c->kept, which grows with them and is not
   allocated again once they fit. */
static fsdem_result fsdem__restart_keep(fsdem_coupler *c) {
    const fsdem__restart_object o = fsdem__restart_of_coupler(c);
    const size_t records = c->cls->record_size * (size_t)c->records;
    size_t need = 0, saved = 0;
    fsdem_result res = fsdem__restart_save_to(&o, NULL, 0, &need, "keep", 1);
    if (res == FSDEM_OK && need + records > c->kept_capacity) {
        const size_t capacity = need + records + (need + records) / 4;
        unsigned char *fresh = (unsigned char *)fsdem__alloc(&c->allocator, capacity);
        if (!fresh)
            return fsdem__fail(&c->status, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory keeping the state before the step (%.0f bytes)",
                               c->cls->name, (double)capacity);
        fsdem__free(&c->allocator, c->kept, c->kept_capacity);
        c->kept = fresh;
        c->kept_capacity = capacity;
    }
    if (res == FSDEM_OK) res = fsdem__restart_save_to(&o, c->kept, c->kept_capacity, &saved, "keep", 1);
    if (res != FSDEM_OK) return res;
    if (records) memcpy(c->kept + saved, c->record, records);
    c->kept_saved = saved;
    c->kept_records = c->records;
    return FSDEM_OK;
}

/* Puts back what fsdem__restart_keep kept. The record storage is the coupler's own (the pointer is
   const for its readers), and a restore leaves it at least as long as the kept records. */
static fsdem_result fsdem__restart_put_back(fsdem_coupler *c) {
    const fsdem__restart_object o = fsdem__restart_of_coupler(c);
    const fsdem_result res = fsdem__restart_load(&o, "put_back", c->kept, c->kept_saved, 1);
    if (res == FSDEM_OK && c->kept_records) {
        memcpy((void *)c->record, c->kept + c->kept_saved, c->cls->record_size * (size_t)c->kept_records);
        c->records = c->kept_records;
    }
    return res;
}
