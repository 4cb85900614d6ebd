/* ===== >>impl_restart : checkpoint and restart =======================================================

   Contents: >>restart_format (header, checksum, and the one cursor that writes, checks and reads
   every object), >>restart_dem, >>restart_pic, >>restart_swe, >>restart_mps, >>restart_couplers
   (one visitor per object lists what it saves, in order, and serves saving and restoring alike; the
   couplers' by their field tables), >>restart_api (memory and files), >>restart_journal (the state
   a coupled step keeps, to put back should it fail). A restore runs the visitor three times over
   the payload: CHECK validates everything and compares the desc, RESERVE allocates, COMMIT writes
   into the object. Only COMMIT changes the object, and it cannot fail. */

/* ---- >>restart_format : header, checksum, cursor ---- */

#define FSDEM__RESTART_VERSION 5u /* 2: DEM contact options and material-pair tables; 3: the PIC's start
                                      velocities of moving solids at any viscosity; 4: the PIC's porosity;
                                      5: the MPS's explicit scheme (its desc fields, c0, densities) */
#define FSDEM__RESTART_HEADER 64
#define FSDEM__RESTART_BOM 0x01020304u
#define FSDEM__RESTART_FNV_BASIS 0xcbf29ce484222325ull
#define FSDEM__RESTART_FNV_PRIME 0x100000001b3ull
#define FSDEM__RESTART_INT_MAX 2147483647

/* The header stores its fields as unsigned int (4 bytes) and unsigned long long (8 bytes). */
typedef char fsdem__restart_int_sizes[sizeof(unsigned int) == 4 && sizeof(unsigned long long) == 8 ? 1 : -1];

enum { FSDEM__RESTART_DEM = 1, FSDEM__RESTART_PIC = 2, FSDEM__RESTART_SWE = 3, FSDEM__RESTART_SWE_DEM = 4, FSDEM__RESTART_MPS = 5,
       FSDEM__RESTART_MPS_DEM = 6, FSDEM__RESTART_PIC_DEM = 7, FSDEM__RESTART_GIC = 8 };

typedef enum fsdem__restart_mode {
    FSDEM__RESTART_WRITE = 0,   /* object to payload (to memory, to a file, or only measured) */
    FSDEM__RESTART_CHECK = 1,   /* payload validated and compared with the object; nothing stored */
    FSDEM__RESTART_RESERVE = 2, /* the memory the payload needs is allocated; nothing stored */
    FSDEM__RESTART_COMMIT = 3   /* payload to object; cannot fail */
} fsdem__restart_mode;

/* A block RESERVE allocated for COMMIT to hand over to the object. */
typedef struct fsdem__restart_held {
    void *ptr;
    size_t bytes;
    const fsdem_allocator *allocator;
} fsdem__restart_held;

/* The cursor of a save or a restore. */
typedef struct fsdem__restart {
    fsdem__restart_mode mode;
    unsigned char *out;          /* WRITE to memory: where the payload goes (NULL: a file, or measuring) */
    FILE *file;                  /* WRITE to a file */
    const unsigned char *in;     /* reading: the payload */
    size_t pos, size;            /* cursor; bytes of the payload (WRITE to memory: room for it) */
    unsigned long long hash;     /* FNV-1a of the header and of the bytes written so far */
    int unchecked;               /* no checksum written or verified: a coupled step's kept state */
                                 /*    (>>restart_journal), which never leaves the process */
    fsdem_result res;            /* the first failure, FSDEM_OK so far */
    char fn[48];                 /* public function, first in every message */
    const char *section;         /* the solver being read in a coupler's file, or NULL */
    char message[FSDEM__MESSAGE_SIZE];
    const fsdem_allocator *allocator; /* of `blocks` */
    fsdem__restart_held *blocks;
    int block_count, block_capacity, block_next;
} fsdem__restart;

typedef void (*fsdem__restart_visit_fn)(fsdem__restart *io, void *object);

/* 64-bit FNV-1a of `n` bytes, continuing from `h`: each step (xor a byte, multiply by an odd prime)
   is a bijection of the state, so any one changed byte changes the sum; and it costs little next to
   writing the data. */
static unsigned long long fsdem__restart_fnv(unsigned long long h, const unsigned char *p, size_t n) {
    size_t k;
    for (k = 0; k < n; ++k) h = (h ^ p[k]) * FSDEM__RESTART_FNV_PRIME;
    return h;
}

/* Records the first failure and its message (the public function first, then the solver section of
   a coupler's file); later failures keep the first, so a message names the root cause. */
static void fsdem__restart_fail(fsdem__restart *io, fsdem_result code, const char *fmt, ...) {
    char detail[384];
    va_list ap;
    if (io->res != FSDEM_OK) return;
    va_start(ap, fmt);
    vsnprintf(detail, sizeof detail, fmt, ap);
    va_end(ap);
    snprintf(io->message, sizeof io->message, "%s: %s%s%s", io->fn, io->section ? io->section : "",
             io->section ? ": " : "", detail);
    io->res = code;
}

/* The next `bytes` of the payload when restoring (a failure and NULL when they run past its end);
   NULL when saving. Lets a check read arrays in place. */
static const unsigned char *fsdem__restart_peek(fsdem__restart *io, size_t bytes) {
    if (io->mode == FSDEM__RESTART_WRITE || io->res != FSDEM_OK) return NULL;
    if (bytes > io->size - io->pos) {
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "the data end early at byte %llu of %llu (corrupted data)",
                            (unsigned long long)io->pos, (unsigned long long)io->size);
        return NULL;
    }
    return io->in + io->pos;
}

/* Object data: WRITE appends `bytes` from p (to memory or to the file, or only counts them), COMMIT
   copies them into p, CHECK and RESERVE step over them. The one place bytes move. */
static void fsdem__restart_data(fsdem__restart *io, void *p, size_t bytes) {
    if (io->res != FSDEM_OK || bytes == 0) return;
    if (io->mode == FSDEM__RESTART_WRITE) {
        if (io->out) {
            FSDEM_ASSERT(bytes <= io->size - io->pos);
            memcpy(io->out + io->pos, p, bytes);
        } else if (io->file)
            fwrite(p, 1, bytes, io->file); /* errors: ferror at the end (fsdem__restart_save_file) */
        if ((io->out || io->file) && !io->unchecked) io->hash = fsdem__restart_fnv(io->hash, (const unsigned char *)p, bytes);
        io->pos += bytes;
        return;
    }
    if (!fsdem__restart_peek(io, bytes)) return;
    if (io->mode == FSDEM__RESTART_COMMIT) memcpy(p, io->in + io->pos, bytes);
    io->pos += bytes;
}

/* A value the visitor itself looks at (a count, a type, a flag): written like data, and read into p
   in every reading mode, so CHECK can validate it before anything depends on it. */
static void fsdem__restart_value(fsdem__restart *io, void *p, size_t bytes) {
    if (io->mode == FSDEM__RESTART_WRITE) {
        fsdem__restart_data(io, p, bytes);
        return;
    }
    if (!fsdem__restart_peek(io, bytes)) return;
    memcpy(p, io->in + io->pos, bytes);
    io->pos += bytes;
}

/* The int at index k of payload bytes (which need not be aligned). */
static int fsdem__restart_int_at(const unsigned char *p, long k) {
    int v;
    memcpy(&v, p + (size_t)k * sizeof v, sizeof v);
    return v;
}

/* An int that must lie in [lo, hi]: written, or read into *v and checked. */
static void fsdem__restart_int_in(fsdem__restart *io, int *v, int lo, int hi, const char *what) {
    fsdem__restart_value(io, v, sizeof *v);
    if (io->mode != FSDEM__RESTART_WRITE && io->res == FSDEM_OK && (*v < lo || *v > hi))
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "%s is %d, outside [%d, %d] (corrupted data)", what, *v, lo, hi);
}

/* A count: written, or read and checked to lie in [0, max] with at least `item_bytes` of payload left
   per item, so that a corrupted count can neither run long loops nor ask for a huge allocation.
   Returns 1 when it may be used. */
static int fsdem__restart_count(fsdem__restart *io, int *n, int max, size_t item_bytes, const char *what) {
    fsdem__restart_int_in(io, n, 0, max, what);
    if (io->mode != FSDEM__RESTART_WRITE && io->res == FSDEM_OK && (size_t)*n * item_bytes > io->size - io->pos)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "%s is %d, more than the data can hold (corrupted data)", what, *n);
    return io->res == FSDEM_OK;
}

/* `count` ints of object data, each in [lo, hi] (checked in CHECK): indices that steps follow. */
static void fsdem__restart_ints(fsdem__restart *io, int *a, int count, int lo, int hi, const char *what) {
    const unsigned char *p = io->mode == FSDEM__RESTART_CHECK ? fsdem__restart_peek(io, sizeof(int) * (size_t)count) : NULL;
    int k, v;
    for (k = 0; p && k < count; ++k)
        if ((v = fsdem__restart_int_at(p, k)) < lo || v > hi) {
            fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "%s %d is %d, outside [%d, %d] (corrupted data)", what, k, v, lo, hi);
            return;
        }
    fsdem__restart_data(io, a, sizeof(int) * (size_t)count);
}

/* `count` bytes of object data, each at most hi (checked in CHECK): flags and cell types. */
static void fsdem__restart_flags(fsdem__restart *io, unsigned char *a, int count, int hi, const char *what) {
    const unsigned char *p = io->mode == FSDEM__RESTART_CHECK ? fsdem__restart_peek(io, (size_t)count) : NULL;
    int k;
    for (k = 0; p && k < count; ++k)
        if (p[k] > hi) {
            fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "%s %d is %d, more than %d (corrupted data)", what, k, p[k], hi);
            return;
        }
    fsdem__restart_data(io, a, (size_t)count);
}

/* A desc field the object must share with the save: written, or read and compared (bit for bit for
   reals). A difference is refused naming the field and both values: the object was not created
   from the desc of the save. */
static void fsdem__restart_same_int(fsdem__restart *io, int mine, const char *what) {
    int saved = mine;
    fsdem__restart_value(io, &saved, sizeof saved);
    if (io->mode == FSDEM__RESTART_CHECK && io->res == FSDEM_OK && saved != mine)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "desc.%s is %d in the save and %d in the object (create the object from the desc it was saved with)",
                            what, saved, mine);
}

static void fsdem__restart_same_ll(fsdem__restart *io, long long mine, const char *what) {
    long long saved = mine;
    fsdem__restart_value(io, &saved, sizeof saved);
    if (io->mode == FSDEM__RESTART_CHECK && io->res == FSDEM_OK && saved != mine)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "desc.%s is %lld in the save and %lld in the object (create the object from the desc it was saved with)",
                            what, saved, mine);
}

static void fsdem__restart_same_vec3(fsdem__restart *io, fsdem_vec3 mine, const char *what) {
    fsdem_vec3 saved = mine;
    fsdem__restart_value(io, &saved, sizeof saved);
    if (io->mode == FSDEM__RESTART_CHECK && io->res == FSDEM_OK && memcmp(&saved, &mine, sizeof saved) != 0)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "desc.%s is (%.17g, %.17g, %.17g) in the save and (%.17g, %.17g, %.17g) in the object "
                            "(create the object from the desc it was saved with)",
                            what, (double)saved.x, (double)saved.y, (double)saved.z, (double)mine.x, (double)mine.y,
                            (double)mine.z);
}

static void fsdem__restart_same_real(fsdem__restart *io, fsdem_real mine, const char *what) {
    fsdem_real saved = mine;
    fsdem__restart_value(io, &saved, sizeof saved);
    if (io->mode == FSDEM__RESTART_CHECK && io->res == FSDEM_OK && memcmp(&saved, &mine, sizeof saved) != 0)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "desc.%s is %.17g in the save and %.17g in the object (create the object from the desc it was saved with)",
                            what, (double)saved, (double)mine);
}

/* A section tag of four characters: written, or read and checked, so that data out of place are
   caught at the section where they start. */
static void fsdem__restart_tag(fsdem__restart *io, const char *tag) {
    char got[4];
    memcpy(got, tag, 4);
    fsdem__restart_value(io, got, 4);
    if (io->mode != FSDEM__RESTART_WRITE && io->res == FSDEM_OK && memcmp(got, tag, 4) != 0)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "section '%.4s' expected at byte %llu (corrupted data)", tag,
                            (unsigned long long)(io->pos - 4));
}

/* RESERVE: a failed allocation becomes the restore's result. */
static void fsdem__restart_need(fsdem__restart *io, fsdem_result res, const char *what) {
    if (res != FSDEM_OK) fsdem__restart_fail(io, FSDEM_ERR_OUT_OF_MEMORY, "out of memory for %s", what);
}

/* A fresh block of `bytes` for the object: RESERVE allocates it with the object's allocator and keeps
   it, COMMIT hands the blocks over in the order RESERVE made them (the visitor asks for them in the
   same order both times). NULL in the other modes and for 0 bytes. Blocks not handed over are freed
   when the restore fails. */
static void *fsdem__restart_block(fsdem__restart *io, const fsdem_allocator *al, size_t bytes) {
    fsdem__restart_held *b;
    if (io->res != FSDEM_OK || bytes == 0) return NULL;
    if (io->mode == FSDEM__RESTART_COMMIT) {
        FSDEM_ASSERT(io->block_next < io->block_count && io->blocks[io->block_next].bytes == bytes);
        return io->blocks[io->block_next++].ptr;
    }
    if (io->mode != FSDEM__RESTART_RESERVE) return NULL;
    if (fsdem__grow(io->allocator, (void **)&io->blocks, &io->block_capacity, io->block_count, io->block_count + 1,
                    sizeof *io->blocks) != FSDEM_OK) {
        fsdem__restart_need(io, FSDEM_ERR_OUT_OF_MEMORY, "the restore's bookkeeping");
        return NULL;
    }
    b = &io->blocks[io->block_count];
    b->ptr = fsdem__alloc(al, bytes);
    b->bytes = bytes;
    b->allocator = al;
    if (!b->ptr) fsdem__restart_need(io, FSDEM_ERR_OUT_OF_MEMORY, "the restored state");
    else io->block_count++;
    return NULL;
}

/* Fields by table (fsdem__field, >>core): a visitor lists the desc fields it compares and the
   scalars it saves, in the order of the payload: FSDEM__SAME(T, member, kind) is T's desc.member,
   FSDEM__SAVED(T, member) its member saved as it is. */
#define FSDEM__SAME(T, member, kind) FSDEM__FIELD(T, desc.member, #member, kind, 1)
#define FSDEM__SAVED(T, member) FSDEM__FIELD(T, member, #member, BYTES, 1)

/* The desc fields of `object` in `same` compared with the save's (the name prints as desc.<name>). */
static void fsdem__restart_same_fields(fsdem__restart *io, const void *object, const fsdem__field *same, int n) {
    int k;
    for (k = 0; k < n; ++k) {
        const void *at = (const char *)object + same[k].offset;
        FSDEM_ASSERT(same[k].kind != FSDEM__FIELD_INT || same[k].size == sizeof(int)); /* (enums included) */
        switch (same[k].kind) {
        case FSDEM__FIELD_INT: fsdem__restart_same_int(io, *(const int *)at, same[k].name); break;
        case FSDEM__FIELD_LL: fsdem__restart_same_ll(io, *(const long long *)at, same[k].name); break;
        case FSDEM__FIELD_REAL: fsdem__restart_same_real(io, *(const fsdem_real *)at, same[k].name); break;
        default: fsdem__restart_same_vec3(io, *(const fsdem_vec3 *)at, same[k].name); break;
        }
    }
}

/* The fields of `object` (a struct, or a record) in `fields` that are saved, as data. */
static void fsdem__restart_fields(fsdem__restart *io, void *object, const fsdem__field *fields, int n) {
    int k;
    for (k = 0; k < n; ++k)
        if (fields[k].saved) fsdem__restart_data(io, object ? (char *)object + fields[k].offset : NULL, fields[k].size);
}
