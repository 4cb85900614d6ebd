/* ---- >>restart_api : memory and files ---- */

/* What the API needs to know of one object. */
typedef struct fsdem__restart_object {
    unsigned int kind;
    int dim, sizes[4];
    void *object;
    fsdem__restart_visit_fn visit;
    const fsdem_allocator *allocator;
    fsdem__status *status; /* the message is the only part of a saved (const) object that changes */
    const char *name;
} fsdem__restart_object;

static const char *fsdem__restart_kind_name(unsigned int kind) {
    switch (kind) {
    case FSDEM__RESTART_DEM: return "fsdem_dem";
    case FSDEM__RESTART_PIC: return "fsdem_pic";
    case FSDEM__RESTART_SWE: return "fsdem_swe";
    case FSDEM__RESTART_SWE_DEM: return "fsdem_swe_dem";
    case FSDEM__RESTART_MPS: return "fsdem_mps";
    case FSDEM__RESTART_MPS_DEM: return "fsdem_mps_dem";
    case FSDEM__RESTART_PIC_DEM: return "fsdem_pic_dem";
    case FSDEM__RESTART_GIC: return "fsdem_gic";
    }
    return "unknown object";
}

/* An object as the API sees it (a zeroed one, object NULL, for a NULL handle): its kind and
   dimension and four counts go to the header, where a restore into another object contradicts
   them. */
static fsdem__restart_object fsdem__restart_object_of(const void *object, unsigned int kind, int dim, const int sizes[4],
                                                      fsdem__restart_visit_fn visit, const fsdem_allocator *allocator,
                                                      const fsdem__status *status) {
    fsdem__restart_object o;
    memset(&o, 0, sizeof o);
    if (!object) return o;
    o.kind = kind;
    o.dim = dim;
    memcpy(o.sizes, sizes, sizeof o.sizes);
    o.object = (void *)object;
    o.visit = visit;
    o.allocator = allocator;
    o.status = (fsdem__status *)status;
    o.name = fsdem__restart_kind_name(kind);
    return o;
}

static fsdem__restart_object fsdem__restart_of_dem(const fsdem_dem *d) {
    if (!d) return fsdem__restart_object_of(NULL, 0, 0, NULL, NULL, NULL, NULL);
    {
        const int sizes[4] = {d->n, d->material_count, d->wall_count, d->pp.count};
        return fsdem__restart_object_of(d, FSDEM__RESTART_DEM, d->desc.dim, sizes, fsdem__restart_dem, &d->allocator, &d->status);
    }
}

static fsdem__restart_object fsdem__restart_of_pic(const fsdem_pic *s) {
    if (!s) return fsdem__restart_object_of(NULL, 0, 0, NULL, NULL, NULL, NULL);
    {
        const int sizes[4] = {s->n[0], s->n[1], s->n[2], s->np};
        return fsdem__restart_object_of(s, FSDEM__RESTART_PIC, s->dim, sizes, fsdem__restart_pic, &s->allocator, &s->status);
    }
}

static fsdem__restart_object fsdem__restart_of_swe(const fsdem_swe *s) {
    if (!s) return fsdem__restart_object_of(NULL, 0, 0, NULL, NULL, NULL, NULL);
    {
        const int sizes[4] = {s->nx, s->ny, s->src_count, s->gauge_count};
        return fsdem__restart_object_of(s, FSDEM__RESTART_SWE, s->dim, sizes, fsdem__restart_swe, &s->allocator, &s->status);
    }
}

static fsdem__restart_object fsdem__restart_of_swe_dem(const fsdem_swe_dem *c) {
    if (!c) return fsdem__restart_object_of(NULL, 0, 0, NULL, NULL, NULL, NULL);
    {
        const int sizes[4] = {c->desc.swe->nx, c->desc.swe->ny, c->desc.dem->n, c->head.records};
        return fsdem__restart_object_of(c, FSDEM__RESTART_SWE_DEM, c->desc.swe->dim, sizes, fsdem__restart_swe_dem, &c->head.allocator, &c->head.status);
    }
}

static fsdem__restart_object fsdem__restart_of_mps(const fsdem_mps *s) {
    if (!s) return fsdem__restart_object_of(NULL, 0, 0, NULL, NULL, NULL, NULL);
    {
        const int sizes[4] = {s->n, s->counts[FSDEM_MPS_KIND_FLUID], s->obst_n, 0};
        return fsdem__restart_object_of(s, FSDEM__RESTART_MPS, s->dim, sizes, fsdem__restart_mps, &s->allocator, &s->status);
    }
}

static fsdem__restart_object fsdem__restart_of_mps_dem(const fsdem_mps_dem *c) {
    if (!c) return fsdem__restart_object_of(NULL, 0, 0, NULL, NULL, NULL, NULL);
    {
        const int sizes[4] = {c->desc.mps->n, c->desc.dem->n, c->head.records, 0};
        return fsdem__restart_object_of(c, FSDEM__RESTART_MPS_DEM, c->dim, sizes, fsdem__restart_mps_dem, &c->head.allocator, &c->head.status);
    }
}

static fsdem__restart_object fsdem__restart_of_gic(const fsdem_gic *c) {
    if (!c) return fsdem__restart_object_of(NULL, 0, 0, NULL, NULL, NULL, NULL);
    {
        const int sizes[4] = {fsdem_pic_get_particles(c->desc.pic).count, fsdem_dem_get_particles(c->desc.dem).count, c->grid.ncell, 0};
        return fsdem__restart_object_of(c, FSDEM__RESTART_GIC, c->dim, sizes, fsdem__restart_gic, &c->head.allocator, &c->head.status);
    }
}

static fsdem__restart_object fsdem__restart_of_pic_dem(const fsdem_pic_dem *c) {
    if (!c) return fsdem__restart_object_of(NULL, 0, 0, NULL, NULL, NULL, NULL);
    {
        const int sizes[4] = {c->desc.pic->np, c->desc.dem->n, c->loaded ? c->bodies : 0, 0};
        return fsdem__restart_object_of(c, FSDEM__RESTART_PIC_DEM, c->dim, sizes, fsdem__restart_pic_dem, &c->head.allocator, &c->head.status);
    }
}

/* A cursor for `verb` of object o ("save", "restore_memory", ...). */
static void fsdem__restart_begin(fsdem__restart *io, const fsdem__restart_object *o, const char *verb,
                                 fsdem__restart_mode mode) {
    memset(io, 0, sizeof *io);
    io->mode = mode;
    io->res = FSDEM_OK;
    io->allocator = o->allocator;
    snprintf(io->fn, sizeof io->fn, "%s_%s", o->name, verb);
}

/* Hands the cursor's result to the object: its message on failure, an empty one on success. */
static fsdem_result fsdem__restart_end(fsdem__restart *io, const fsdem__restart_object *o) {
    int k;
    for (k = io->block_next; k < io->block_count; ++k)
        fsdem__free(io->blocks[k].allocator, io->blocks[k].ptr, io->blocks[k].bytes);
    fsdem__free(io->allocator, io->blocks, sizeof *io->blocks * (size_t)io->block_capacity);
    io->blocks = NULL;
    io->block_count = io->block_capacity = io->block_next = 0;
    return io->res == FSDEM_OK ? fsdem__ok(o->status) : fsdem__fail(o->status, io->res, "%s", io->message);
}

/* The header of o with a payload of `payload` bytes, and the checksum of its first 56 bytes. */
static unsigned long long fsdem__restart_header(unsigned char h[FSDEM__RESTART_HEADER], const fsdem__restart_object *o,
                                                unsigned long long payload) {
    const unsigned int u[6] = {FSDEM__RESTART_VERSION, FSDEM__RESTART_BOM, (unsigned int)sizeof(fsdem_real), o->kind,
                               (unsigned int)o->dim, 0u};
    memset(h, 0, FSDEM__RESTART_HEADER);
    memcpy(h, "FSDEMRST", 8);
    memcpy(h + 8, u, sizeof u);
    memcpy(h + 32, o->sizes, sizeof o->sizes);
    memcpy(h + 48, &payload, 8);
    return fsdem__restart_fnv(FSDEM__RESTART_FNV_BASIS, h, 56);
}

static unsigned int fsdem__restart_u32(const unsigned char *p) {
    unsigned int v;
    memcpy(&v, p, sizeof v);
    return v;
}

/* Measures the payload of o and fills the header; the cursor is then ready to write the payload. */
static void fsdem__restart_prepare(fsdem__restart *io, const fsdem__restart_object *o,
                                   unsigned char header[FSDEM__RESTART_HEADER]) {
    o->visit(io, o->object);
    io->hash = fsdem__restart_header(header, o, (unsigned long long)io->pos);
    io->size = io->pos;
    io->pos = 0;
}

/* Saves o to `buffer` (`capacity` bytes; NULL: only the size) for `verb`, with its checksum unless
   `unchecked`. The payload is measured first, so a buffer too small is refused before anything is
   written. */
static fsdem_result fsdem__restart_save_to(const fsdem__restart_object *o, void *buffer, size_t capacity, size_t *size,
                                           const char *verb, int unchecked) {
    fsdem__restart io;
    unsigned char header[FSDEM__RESTART_HEADER];
    if (!o->object) return FSDEM_ERR_INVALID_ARG; /* a NULL handle: no object to hold a message */
    fsdem__restart_begin(&io, o, verb, FSDEM__RESTART_WRITE);
    io.unchecked = unchecked;
    if (!size) {
        fsdem__restart_fail(&io, FSDEM_ERR_INVALID_ARG, "size is NULL");
        return fsdem__restart_end(&io, o);
    }
    fsdem__restart_prepare(&io, o, header);
    *size = FSDEM__RESTART_HEADER + io.size;
    if (buffer && capacity < *size)
        fsdem__restart_fail(&io, FSDEM_ERR_INVALID_ARG, "the buffer of %llu bytes is too small: %llu are needed",
                            (unsigned long long)capacity, (unsigned long long)*size);
    if (buffer && io.res == FSDEM_OK) {
        io.out = (unsigned char *)buffer + FSDEM__RESTART_HEADER;
        o->visit(&io, o->object);
        FSDEM_ASSERT(io.pos == io.size);
        memcpy(header + 56, &io.hash, 8);
        memcpy(buffer, header, FSDEM__RESTART_HEADER);
    }
    return fsdem__restart_end(&io, o);
}

static fsdem_result fsdem__restart_save_memory(const fsdem__restart_object *o, void *buffer, size_t capacity,
                                               size_t *size) {
    return fsdem__restart_save_to(o, buffer, capacity, size, "save_memory", 0);
}

/* Saves o to the file `path` in one pass: header, payload, then the checksum into the header. */
static fsdem_result fsdem__restart_save_file(const fsdem__restart_object *o, const char *path) {
    fsdem__restart io;
    unsigned char header[FSDEM__RESTART_HEADER];
    FILE *fp;
    int bad;
    if (!o->object) return FSDEM_ERR_INVALID_ARG; /* a NULL handle: no object to hold a message */
    fsdem__restart_begin(&io, o, "save", FSDEM__RESTART_WRITE);
    if (!path) {
        fsdem__restart_fail(&io, FSDEM_ERR_INVALID_ARG, "path is NULL");
        return fsdem__restart_end(&io, o);
    }
    fp = fopen(path, "wb");
    if (!fp) {
        fsdem__restart_fail(&io, FSDEM_ERR_IO, "cannot open '%s' for writing", path);
        return fsdem__restart_end(&io, o);
    }
    fsdem__restart_prepare(&io, o, header);
    bad = fwrite(header, 1, FSDEM__RESTART_HEADER, fp) != FSDEM__RESTART_HEADER;
    io.file = fp;
    o->visit(&io, o->object);
    memcpy(header + 56, &io.hash, 8);
    bad |= ferror(fp) || fseek(fp, 56, SEEK_SET) != 0 || fwrite(header + 56, 1, 8, fp) != 8;
    bad |= fclose(fp) != 0;
    if (bad) fsdem__restart_fail(&io, FSDEM_ERR_IO, "cannot write '%s'", path);
    return fsdem__restart_end(&io, o);
}

/* Checks the header of `size` bytes at `data` against o: magic, version, byte order, precision,
   kind, dimension, the announced size, then the checksum (unless io->unchecked). */
static void fsdem__restart_check_header(fsdem__restart *io, const fsdem__restart_object *o, const unsigned char *data,
                                        size_t size) {
    unsigned long long payload, sum;
    unsigned int precision, kind, dim;
    if (!data) {
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "buffer is NULL");
        return;
    }
    if (size < FSDEM__RESTART_HEADER || memcmp(data, "FSDEMRST", 8) != 0) {
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "not a fsdem restart file (%s)",
                            size < FSDEM__RESTART_HEADER ? "shorter than the 64-byte header" : "no FSDEMRST magic");
        return;
    }
    precision = fsdem__restart_u32(data + 16);
    kind = fsdem__restart_u32(data + 20);
    dim = fsdem__restart_u32(data + 24);
    memcpy(&payload, data + 48, 8);
    memcpy(&sum, data + 56, 8);
    if (fsdem__restart_u32(data + 8) != FSDEM__RESTART_VERSION)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "format version %u; this build reads version %u",
                            fsdem__restart_u32(data + 8), FSDEM__RESTART_VERSION);
    else if (fsdem__restart_u32(data + 12) != FSDEM__RESTART_BOM)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "written on a machine of another byte order");
    else if (precision != sizeof(fsdem_real))
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "precision: written with %u-byte reals, this build's fsdem_real has %u (%s)",
                            precision, (unsigned int)sizeof(fsdem_real), sizeof(fsdem_real) == 4 ? "FSDEM_USE_FLOAT" : "double");
    else if (kind != o->kind)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "the data hold the state of a %s, not of a %s",
                            fsdem__restart_kind_name(kind), fsdem__restart_kind_name(o->kind));
    else if (dim != (unsigned int)o->dim)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "dimension: the data hold a %uD state, the object is %dD", dim, o->dim);
    else if (payload != (unsigned long long)(size - FSDEM__RESTART_HEADER))
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "%s: %llu bytes after the header, %llu announced",
                            payload > (unsigned long long)(size - FSDEM__RESTART_HEADER) ? "truncated" : "trailing bytes",
                            (unsigned long long)(size - FSDEM__RESTART_HEADER), payload);
    else if (!io->unchecked && fsdem__restart_fnv(fsdem__restart_fnv(FSDEM__RESTART_FNV_BASIS, data, 56), data + FSDEM__RESTART_HEADER,
                                (size_t)payload) != sum)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "checksum mismatch: the data are corrupted");
}

/* Restores o from `size` bytes at `data` for `verb`: the header (its checksum unless `unchecked`),
   then the visitor's CHECK, RESERVE and COMMIT passes over the payload. */
static fsdem_result fsdem__restart_load(const fsdem__restart_object *o, const char *verb, const unsigned char *data, size_t size,
                                        int unchecked) {
    fsdem__restart io;
    static const fsdem__restart_mode passes[3] = {FSDEM__RESTART_CHECK, FSDEM__RESTART_RESERVE, FSDEM__RESTART_COMMIT};
    int pass;
    fsdem__restart_begin(&io, o, verb, FSDEM__RESTART_CHECK);
    io.unchecked = unchecked;
    fsdem__restart_check_header(&io, o, data, size);
    for (pass = 0; pass < 3 && io.res == FSDEM_OK; ++pass) {
        io.mode = passes[pass];
        io.in = data + FSDEM__RESTART_HEADER;
        io.size = size - FSDEM__RESTART_HEADER;
        io.pos = 0;
        o->visit(&io, o->object);
        if (io.res == FSDEM_OK && io.pos != io.size)
            fsdem__restart_fail(&io, FSDEM_ERR_INVALID_ARG, "%llu bytes left unread (corrupted data)",
                                (unsigned long long)(io.size - io.pos));
    }
    FSDEM_ASSERT(io.res != FSDEM_OK || io.block_next == io.block_count);
    return fsdem__restart_end(&io, o);
}

/* Restores o from the file `path`, read whole into memory (FSDEM_ERR_IO when it cannot be). */
static fsdem_result fsdem__restart_load_file(const fsdem__restart_object *o, const char *path) {
    fsdem__restart io;
    FILE *fp;
    unsigned char *data = NULL;
    long length = -1;
    fsdem_result res;
    if (!o->object) return FSDEM_ERR_INVALID_ARG; /* a NULL handle: no object to hold a message */
    fp = path ? fopen(path, "rb") : NULL;
    fsdem__restart_begin(&io, o, "restore", FSDEM__RESTART_CHECK);
    if (!path) fsdem__restart_fail(&io, FSDEM_ERR_INVALID_ARG, "path is NULL");
    else if (!fp) fsdem__restart_fail(&io, FSDEM_ERR_IO, "cannot open '%s'", path);
    /* a directory opens and seeks on some systems (its "length" is then LONG_MAX): read a byte
       before trusting the length */
    else if (fseek(fp, 0, SEEK_END) != 0 || (length = ftell(fp)) < 0 || fseek(fp, 0, SEEK_SET) != 0 ||
             (length > 0 && (getc(fp) == EOF || fseek(fp, 0, SEEK_SET) != 0)))
        fsdem__restart_fail(&io, FSDEM_ERR_IO, "cannot read '%s' (not a readable file)", path);
    else if (!(data = (unsigned char *)fsdem__alloc(o->allocator, (size_t)length)))
        fsdem__restart_fail(&io, FSDEM_ERR_OUT_OF_MEMORY, "out of memory for the %ld bytes of '%s'", length, path);
    else if (fread(data, 1, (size_t)length, fp) != (size_t)length)
        fsdem__restart_fail(&io, FSDEM_ERR_IO, "cannot read '%s'", path);
    if (fp) fclose(fp);
    res = io.res == FSDEM_OK ? fsdem__restart_load(o, "restore", data, (size_t)length, 0) : fsdem__restart_end(&io, o);
    fsdem__free(o->allocator, data, length > 0 ? (size_t)length : 1);
    return res;
}

/* Restores o from the `size` bytes at `buffer` (a save_memory image). */
static fsdem_result fsdem__restart_load_memory(const fsdem__restart_object *o, const void *buffer, size_t size) {
    if (!o->object) return FSDEM_ERR_INVALID_ARG; /* a NULL handle: no object to hold a message */
    return fsdem__restart_load(o, "restore_memory", (const unsigned char *)buffer, size, 0);
}

/* The public functions: save and restore, to files and to memory, for each of the four objects:
   two lines each around the helpers above, which refuse a NULL object with FSDEM_ERR_INVALID_ARG
   without a message: there is no object to hold it. */

/* fsdem_dem (>>restart): the discrete elements. */
fsdem_result fsdem_dem_save(const fsdem_dem *dem, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_dem(dem);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_dem_restore(fsdem_dem *dem, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_dem(dem);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_dem_save_memory(const fsdem_dem *dem, void *buffer, size_t capacity, size_t *size) {
    const fsdem__restart_object o = fsdem__restart_of_dem(dem);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_dem_restore_memory(fsdem_dem *dem, const void *buffer, size_t size) {
    const fsdem__restart_object o = fsdem__restart_of_dem(dem);
    return fsdem__restart_load_memory(&o, buffer, size);
}

/* fsdem_pic (>>restart): the PIC/FLIP solver. */
fsdem_result fsdem_pic_save(const fsdem_pic *pic, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_pic(pic);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_pic_restore(fsdem_pic *pic, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_pic(pic);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_pic_save_memory(const fsdem_pic *pic, void *buffer, size_t capacity, size_t *size) {
    const fsdem__restart_object o = fsdem__restart_of_pic(pic);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_pic_restore_memory(fsdem_pic *pic, const void *buffer, size_t size) {
    const fsdem__restart_object o = fsdem__restart_of_pic(pic);
    return fsdem__restart_load_memory(&o, buffer, size);
}

/* fsdem_swe (>>restart): the shallow-water solver. */
fsdem_result fsdem_swe_save(const fsdem_swe *swe, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_swe(swe);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_swe_restore(fsdem_swe *swe, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_swe(swe);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_swe_save_memory(const fsdem_swe *swe, void *buffer, size_t capacity, size_t *size) {
    const fsdem__restart_object o = fsdem__restart_of_swe(swe);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_swe_restore_memory(fsdem_swe *swe, const void *buffer, size_t size) {
    const fsdem__restart_object o = fsdem__restart_of_swe(swe);
    return fsdem__restart_load_memory(&o, buffer, size);
}

/* fsdem_swe_dem (>>restart): the SWE-DEM coupler with its two solvers. */
fsdem_result fsdem_swe_dem_save(const fsdem_swe_dem *coupler, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_swe_dem(coupler);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_swe_dem_restore(fsdem_swe_dem *coupler, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_swe_dem(coupler);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_swe_dem_save_memory(const fsdem_swe_dem *coupler, void *buffer, size_t capacity, size_t *size) {
    const fsdem__restart_object o = fsdem__restart_of_swe_dem(coupler);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_swe_dem_restore_memory(fsdem_swe_dem *coupler, const void *buffer, size_t size) {
    const fsdem__restart_object o = fsdem__restart_of_swe_dem(coupler);
    return fsdem__restart_load_memory(&o, buffer, size);
}

/* fsdem_mps (>>restart): the MPS solver. */
fsdem_result fsdem_mps_save(const fsdem_mps *mps, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_mps(mps);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_mps_restore(fsdem_mps *mps, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_mps(mps);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_mps_save_memory(const fsdem_mps *mps, void *buffer, size_t capacity, size_t *size) {
    const fsdem__restart_object o = fsdem__restart_of_mps(mps);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_mps_restore_memory(fsdem_mps *mps, const void *buffer, size_t size) {
    const fsdem__restart_object o = fsdem__restart_of_mps(mps);
    return fsdem__restart_load_memory(&o, buffer, size);
}

/* fsdem_mps_dem (>>restart): the MPS-DEM coupler with its two solvers. */
fsdem_result fsdem_mps_dem_save(const fsdem_mps_dem *coupler, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_mps_dem(coupler);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_mps_dem_restore(fsdem_mps_dem *coupler, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_mps_dem(coupler);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_mps_dem_save_memory(const fsdem_mps_dem *coupler, void *buffer, size_t capacity, size_t *size) {
    const fsdem__restart_object o = fsdem__restart_of_mps_dem(coupler);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_mps_dem_restore_memory(fsdem_mps_dem *coupler, const void *buffer, size_t size) {
    const fsdem__restart_object o = fsdem__restart_of_mps_dem(coupler);
    return fsdem__restart_load_memory(&o, buffer, size);
}

/* fsdem_pic_dem (>>restart): the PIC-DEM coupler with its two solvers. */
fsdem_result fsdem_pic_dem_save(const fsdem_pic_dem *coupler, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_pic_dem(coupler);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_pic_dem_restore(fsdem_pic_dem *coupler, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_pic_dem(coupler);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_pic_dem_save_memory(const fsdem_pic_dem *coupler, void *buffer, size_t capacity, size_t *size) {
    const fsdem__restart_object o = fsdem__restart_of_pic_dem(coupler);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_pic_dem_restore_memory(fsdem_pic_dem *coupler, const void *buffer, size_t size) {
    const fsdem__restart_object o = fsdem__restart_of_pic_dem(coupler);
    return fsdem__restart_load_memory(&o, buffer, size);
}

/* fsdem_gic (>>restart): the Granule-In-Cell coupler with its two solvers. */
fsdem_result fsdem_gic_save(const fsdem_gic *coupler, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_gic(coupler);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_gic_restore(fsdem_gic *coupler, const char *path) {
    const fsdem__restart_object o = fsdem__restart_of_gic(coupler);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_gic_save_memory(const fsdem_gic *coupler, void *buffer, size_t capacity, size_t *size) {
    const fsdem__restart_object o = fsdem__restart_of_gic(coupler);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_gic_restore_memory(fsdem_gic *coupler, const void *buffer, size_t size) {
    const fsdem__restart_object o = fsdem__restart_of_gic(coupler);
    return fsdem__restart_load_memory(&o, buffer, size);
}
