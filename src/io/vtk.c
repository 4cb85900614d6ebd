/* ---- >>io_vtk : the VTK XML writer core ----

   A writer opens the file (fsdem__vtk_open), starts the dataset (fsdem__vtk_polydata or
   fsdem__vtk_imagedata: the dataset element, FieldData TimeValue, <Piece>), writes sections of
   arrays in VTK's order (fsdem__vtk_section, fsdem__vtk_write, fsdem__vtk_section_end; PolyData:
   PointData, CellData, Points, Verts, Lines, Polys) and closes (fsdem__vtk_close: </Piece>, the
   appended data, </VTKFile>). An array is a description (fsdem__vtk_array), not a copy: its values
   are read through it when they are written, which for FSDEM_VTK_FORMAT_APPENDED is at the close, so the
   data it points to must live until then (the description itself is copied). Each value goes
   through a double, which holds every Float32, Float64, Int32 and UInt8 value exactly. Binary
   numbers are written in the machine's byte order, which the root element names. The rules of the
   three formats are those of fsdem_vtk_format (>>io). */

typedef enum fsdem__vtk_type {
    FSDEM__VTK_FLOAT32 = 0,
    FSDEM__VTK_FLOAT64 = 1,
    FSDEM__VTK_INT32 = 2,
    FSDEM__VTK_UINT8 = 3
} fsdem__vtk_type;

#ifdef FSDEM_USE_FLOAT
#define FSDEM__VTK_REAL FSDEM__VTK_FLOAT32
#else
#define FSDEM__VTK_REAL FSDEM__VTK_FLOAT64
#endif

/* Int32 values are written from an int and byte counts from an unsigned long long. */
typedef char fsdem__vtk_int_is_32_bits[sizeof(int) == 4 ? 1 : -1];
typedef char fsdem__vtk_ull_is_64_bits[sizeof(unsigned long long) == 8 ? 1 : -1];

/* Where an array's values come from. */
typedef enum fsdem__vtk_source {
    FSDEM__VTK_FROM_REALS = 0,  /* const fsdem_real[count] */
    FSDEM__VTK_FROM_VEC3S = 1,  /* const fsdem_vec3[count] (3 components) */
    FSDEM__VTK_FROM_INTS = 2,   /* const int[count] */
    FSDEM__VTK_FROM_BYTES = 3,  /* const unsigned char[count] */
    FSDEM__VTK_FROM_RAMP = 4,   /* first + step * index (Int32) */
    FSDEM__VTK_FROM_DOUBLE = 5, /* one const double, repeated */
    FSDEM__VTK_FROM_FN = 6      /* a callback per tuple */
} fsdem__vtk_source;

/* Tuple `index` of a computed array into out[0 .. components - 1]. */
typedef void (*fsdem__vtk_tuple_fn)(const void *user, long long index, double out[3]);

typedef struct fsdem__vtk_array {
    const char *name;
    fsdem__vtk_type type;
    int components; /* 1 or 3 */
    long long count; /* tuples */
    fsdem__vtk_source source;
    const void *data; /* the values, or the callback's user */
    fsdem__vtk_tuple_fn fn;
    long long first, step; /* FSDEM__VTK_FROM_RAMP */
} fsdem__vtk_array;

#define FSDEM__VTK_MAX_ARRAYS 24 /* arrays of one file (the most any writer has is 14) */

typedef struct fsdem__vtk_writer {
    FILE *fp;
    fsdem_vtk_format format;
    const char *type;      /* "PolyData" or "ImageData" */
    fsdem__status *status; /* the object's, for the message (may be NULL) */
    const char *who, *path;
    double time;           /* s, the TimeValue field */
    unsigned long long appended; /* FSDEM_VTK_FORMAT_APPENDED: bytes of the blocks announced so far */
    fsdem__vtk_array queue[FSDEM__VTK_MAX_ARRAYS]; /* FSDEM_VTK_FORMAT_APPENDED: the blocks to write */
    int queued;
} fsdem__vtk_writer;

static fsdem__vtk_array fsdem__vtk_from(const char *name, fsdem__vtk_type type, int components, long long count,
                                       fsdem__vtk_source source, const void *data) {
    fsdem__vtk_array a;
    memset(&a, 0, sizeof a);
    a.name = name;
    a.type = type;
    a.components = components;
    a.count = count;
    a.source = source;
    a.data = data;
    return a;
}
static fsdem__vtk_array fsdem__vtk_reals(const char *name, const fsdem_real *p, long long n) {
    return fsdem__vtk_from(name, FSDEM__VTK_REAL, 1, n, FSDEM__VTK_FROM_REALS, p);
}
static fsdem__vtk_array fsdem__vtk_vec3s(const char *name, const fsdem_vec3 *p, long long n) {
    return fsdem__vtk_from(name, FSDEM__VTK_REAL, 3, n, FSDEM__VTK_FROM_VEC3S, p);
}
static fsdem__vtk_array fsdem__vtk_ints(const char *name, const int *p, long long n) {
    return fsdem__vtk_from(name, FSDEM__VTK_INT32, 1, n, FSDEM__VTK_FROM_INTS, p);
}
static fsdem__vtk_array fsdem__vtk_bytes(const char *name, const unsigned char *p, long long n) {
    return fsdem__vtk_from(name, FSDEM__VTK_UINT8, 1, n, FSDEM__VTK_FROM_BYTES, p);
}
/* Int32 values first, first + step, ... (connectivity and offsets of regular cells). */
static fsdem__vtk_array fsdem__vtk_ramp(const char *name, long long n, long long first, long long step) {
    fsdem__vtk_array a = fsdem__vtk_from(name, FSDEM__VTK_INT32, 1, n, FSDEM__VTK_FROM_RAMP, NULL);
    a.first = first;
    a.step = step;
    return a;
}
static fsdem__vtk_array fsdem__vtk_computed(const char *name, fsdem__vtk_type type, int components, long long n,
                                           fsdem__vtk_tuple_fn fn, const void *user) {
    fsdem__vtk_array a = fsdem__vtk_from(name, type, components, n, FSDEM__VTK_FROM_FN, user);
    a.fn = fn;
    return a;
}

static const char *fsdem__vtk_type_name(fsdem__vtk_type t) {
    switch (t) {
    case FSDEM__VTK_FLOAT32: return "Float32";
    case FSDEM__VTK_FLOAT64: return "Float64";
    case FSDEM__VTK_INT32: return "Int32";
    default: return "UInt8";
    }
}

static size_t fsdem__vtk_type_size(fsdem__vtk_type t) {
    return t == FSDEM__VTK_FLOAT64 ? 8 : t == FSDEM__VTK_UINT8 ? 1 : 4;
}

static int fsdem__vtk_little_endian(void) {
    const unsigned int one = 1;
    unsigned char first;
    memcpy(&first, &one, 1);
    return first == 1;
}

static void fsdem__vtk_tuple(const fsdem__vtk_array *a, long long i, double v[3]) {
    switch (a->source) {
    case FSDEM__VTK_FROM_REALS: v[0] = (double)((const fsdem_real *)a->data)[i]; break;
    case FSDEM__VTK_FROM_VEC3S: {
        const fsdem_vec3 p = ((const fsdem_vec3 *)a->data)[i];
        v[0] = (double)p.x;
        v[1] = (double)p.y;
        v[2] = (double)p.z;
        break;
    }
    case FSDEM__VTK_FROM_INTS: v[0] = (double)((const int *)a->data)[i]; break;
    case FSDEM__VTK_FROM_BYTES: v[0] = (double)((const unsigned char *)a->data)[i]; break;
    case FSDEM__VTK_FROM_RAMP: v[0] = (double)(a->first + a->step * i); break;
    case FSDEM__VTK_FROM_DOUBLE: v[0] = *(const double *)a->data; break;
    default: a->fn(a->data, i, v); break;
    }
}

/* One value in the array's type, in the machine's byte order, into out; returns its size. */
static size_t fsdem__vtk_pack(fsdem__vtk_type t, double v, unsigned char *out) {
    switch (t) {
    case FSDEM__VTK_FLOAT32: {
        const float f = (float)v;
        memcpy(out, &f, 4);
        return 4;
    }
    case FSDEM__VTK_FLOAT64: memcpy(out, &v, 8); return 8;
    case FSDEM__VTK_INT32: {
        const int k = (int)v;
        memcpy(out, &k, 4);
        return 4;
    }
    default: out[0] = (unsigned char)v; return 1;
    }
}

/* Binary output: raw bytes (appended), or base64 (inline) kept as one stream across calls. */
typedef struct fsdem__vtk_sink {
    fsdem__vtk_writer *w;
    unsigned char pending[3];
    int npending;
    char text[4096];
    int ntext;
} fsdem__vtk_sink;

static void fsdem__vtk_sink_put(fsdem__vtk_sink *s, const unsigned char *p, size_t n) {
    static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    if (s->w->format == FSDEM_VTK_FORMAT_APPENDED) {
        fwrite(p, 1, n, s->w->fp);
        return;
    }
    while (n--) {
        s->pending[s->npending++] = *p++;
        if (s->npending < 3) continue;
        if (s->ntext + 4 > (int)sizeof s->text) {
            fwrite(s->text, 1, (size_t)s->ntext, s->w->fp);
            s->ntext = 0;
        }
        s->text[s->ntext++] = digits[s->pending[0] >> 2];
        s->text[s->ntext++] = digits[((s->pending[0] & 3) << 4) | (s->pending[1] >> 4)];
        s->text[s->ntext++] = digits[((s->pending[1] & 15) << 2) | (s->pending[2] >> 6)];
        s->text[s->ntext++] = digits[s->pending[2] & 63];
        s->npending = 0;
    }
}

/* Ends a base64 stream: the last one or two bytes with '=' padding. */
static void fsdem__vtk_sink_end(fsdem__vtk_sink *s) {
    static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    if (s->w->format == FSDEM_VTK_FORMAT_APPENDED) return;
    if (s->npending) {
        const unsigned char b0 = s->pending[0], b1 = s->npending > 1 ? s->pending[1] : 0;
        char quad[4];
        quad[0] = digits[b0 >> 2];
        quad[1] = digits[((b0 & 3) << 4) | (b1 >> 4)];
        quad[2] = s->npending > 1 ? digits[(b1 & 15) << 2] : '=';
        quad[3] = '=';
        fwrite(s->text, 1, (size_t)s->ntext, s->w->fp);
        s->ntext = 0;
        fwrite(quad, 1, 4, s->w->fp);
        s->npending = 0;
    }
    fwrite(s->text, 1, (size_t)s->ntext, s->w->fp);
    s->ntext = 0;
}

static unsigned long long fsdem__vtk_bytes_of(const fsdem__vtk_array *a) {
    return (unsigned long long)a->count * (unsigned long long)a->components * fsdem__vtk_type_size(a->type);
}

/* The values of an array in the writer's format: text, or the byte count and the data in binary. */
static void fsdem__vtk_values(fsdem__vtk_writer *w, const fsdem__vtk_array *a) {
    long long i;
    int c;
    double v[3];
    if (w->format == FSDEM_VTK_FORMAT_ASCII) {
        for (i = 0; i < a->count; ++i) {
            fsdem__vtk_tuple(a, i, v);
            for (c = 0; c < a->components; ++c) {
                const char sep = c + 1 < a->components ? ' ' : '\n';
                switch (a->type) {
                case FSDEM__VTK_FLOAT32: fprintf(w->fp, "%.9g%c", (double)(float)v[c], sep); break;
                case FSDEM__VTK_FLOAT64: fprintf(w->fp, "%.17g%c", v[c], sep); break;
                case FSDEM__VTK_INT32: fprintf(w->fp, "%d%c", (int)v[c], sep); break;
                default: fprintf(w->fp, "%u%c", (unsigned)(unsigned char)v[c], sep); break;
                }
            }
        }
    } else {
        /* whole tuples of up to 3 x 8 bytes fill the buffer; flushed at 3072 - 24 */
        unsigned char buf[3072];
        const unsigned long long bytes = fsdem__vtk_bytes_of(a);
        fsdem__vtk_sink sink;
        size_t used;
        sink.w = w;
        sink.npending = sink.ntext = 0;
        memcpy(buf, &bytes, 8);
        used = 8;
        for (i = 0; i < a->count; ++i) {
            if (used + 24 > sizeof buf) {
                fsdem__vtk_sink_put(&sink, buf, used);
                used = 0;
            }
            fsdem__vtk_tuple(a, i, v);
            for (c = 0; c < a->components; ++c) used += fsdem__vtk_pack(a->type, v[c], buf + used);
        }
        fsdem__vtk_sink_put(&sink, buf, used);
        fsdem__vtk_sink_end(&sink);
    }
}

/* A <DataArray>: inline with its values (ascii, base64), or announced with its offset and queued for
   the appended data. `field`: a FieldData array, which also names its number of tuples. */
static void fsdem__vtk_write_array(fsdem__vtk_writer *w, fsdem__vtk_array a, int field) {
    static const char *const formats[3] = {"ascii", "binary", "appended"};
    fprintf(w->fp, "<DataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%d\" format=\"%s\"", fsdem__vtk_type_name(a.type),
            a.name, a.components, formats[w->format]);
    if (field) fprintf(w->fp, " NumberOfTuples=\"%lld\"", a.count);
    if (w->format == FSDEM_VTK_FORMAT_APPENDED) {
        FSDEM_ASSERT(w->queued < FSDEM__VTK_MAX_ARRAYS);
        fprintf(w->fp, " offset=\"%llu\"/>\n", w->appended);
        w->queue[w->queued++] = a;
        w->appended += 8 + fsdem__vtk_bytes_of(&a);
        return;
    }
    fputs(">\n", w->fp);
    fsdem__vtk_values(w, &a);
    fputs(w->format == FSDEM_VTK_FORMAT_BASE64 ? "\n</DataArray>\n" : "</DataArray>\n", w->fp);
}

static void fsdem__vtk_write(fsdem__vtk_writer *w, fsdem__vtk_array a) { fsdem__vtk_write_array(w, a, 0); }

/* Checks the arguments every writer shares; the message goes to `status` (may be NULL). */
static fsdem_result fsdem__vtk_check(fsdem__status *status, const char *who, const char *path, fsdem_vtk_format format) {
    fsdem__status scratch;
    fsdem__status *st = status ? status : &scratch;
    if (!status) scratch.log = NULL;
    if (!path) return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: path is NULL", who);
    if ((int)format < (int)FSDEM_VTK_FORMAT_ASCII || (int)format > (int)FSDEM_VTK_FORMAT_APPENDED)
        return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: format %d is not a fsdem_vtk_format", who, (int)format);
    return FSDEM_OK;
}

/* Checks the arguments, creates the file and writes the root element of a dataset `type`. */
static fsdem_result fsdem__vtk_open(fsdem__vtk_writer *w, fsdem__status *status, const char *who, const char *path,
                                    fsdem_vtk_format format, const char *type) {
    fsdem_result res = fsdem__vtk_check(status, who, path, format);
    memset(w, 0, sizeof *w);
    if (res != FSDEM_OK) return res;
    w->format = format;
    w->type = type;
    w->status = status;
    w->who = who;
    w->path = path;
    w->fp = fopen(path, "wb");
    if (!w->fp) {
        if (status) fsdem__fail(status, FSDEM_ERR_IO, "%s: cannot open '%s' for writing", who, path);
        return FSDEM_ERR_IO;
    }
    fprintf(w->fp, "<?xml version=\"1.0\"?>\n<VTKFile type=\"%s\" version=\"1.0\" byte_order=\"%s\" header_type=\"UInt64\">\n",
            type, fsdem__vtk_little_endian() ? "LittleEndian" : "BigEndian");
    return FSDEM_OK;
}

/* The FieldData of the dataset: TimeValue (s). */
static void fsdem__vtk_time(fsdem__vtk_writer *w, double time) {
    w->time = time;
    fputs("<FieldData>\n", w->fp);
    fsdem__vtk_write_array(w, fsdem__vtk_from("TimeValue", FSDEM__VTK_FLOAT64, 1, 1, FSDEM__VTK_FROM_DOUBLE, &w->time), 1);
    fputs("</FieldData>\n", w->fp);
}

/* <PolyData>, the time, and the piece's counts (strips are never written). */
static void fsdem__vtk_polydata(fsdem__vtk_writer *w, double time, long long points, long long verts, long long lines,
                                long long polys) {
    fputs("<PolyData>\n", w->fp);
    fsdem__vtk_time(w, time);
    fprintf(w->fp,
            "<Piece NumberOfPoints=\"%lld\" NumberOfVerts=\"%lld\" NumberOfLines=\"%lld\" NumberOfStrips=\"0\" "
            "NumberOfPolys=\"%lld\">\n",
            points, verts, lines, polys);
}

/* <ImageData> of cells[0] x cells[1] x cells[2] cells (0 for a flat axis: one layer of points), the
   time, and the piece, which is the whole extent. */
static void fsdem__vtk_imagedata(fsdem__vtk_writer *w, double time, const int cells[3], const double origin[3],
                                 const double spacing[3]) {
    fprintf(w->fp, "<ImageData WholeExtent=\"0 %d 0 %d 0 %d\" Origin=\"%.17g %.17g %.17g\" Spacing=\"%.17g %.17g %.17g\">\n",
            cells[0], cells[1], cells[2], origin[0], origin[1], origin[2], spacing[0], spacing[1], spacing[2]);
    fsdem__vtk_time(w, time);
    fprintf(w->fp, "<Piece Extent=\"0 %d 0 %d 0 %d\">\n", cells[0], cells[1], cells[2]);
}

/* Opens a section (PointData, CellData, Points, Verts, Lines, Polys) with its active scalars and
   vectors (may be NULL). */
static void fsdem__vtk_section(fsdem__vtk_writer *w, const char *tag, const char *scalars, const char *vectors) {
    fprintf(w->fp, "<%s", tag);
    if (scalars) fprintf(w->fp, " Scalars=\"%s\"", scalars);
    if (vectors) fprintf(w->fp, " Vectors=\"%s\"", vectors);
    fputs(">\n", w->fp);
}

static void fsdem__vtk_section_end(fsdem__vtk_writer *w, const char *tag) { fprintf(w->fp, "</%s>\n", tag); }

/* A cell section (Verts, Lines, Polys) from its connectivity and offsets (Int32). */
static void fsdem__vtk_cells(fsdem__vtk_writer *w, const char *tag, fsdem__vtk_array connectivity, fsdem__vtk_array offsets) {
    fsdem__vtk_section(w, tag, NULL, NULL);
    fsdem__vtk_write(w, connectivity);
    fsdem__vtk_write(w, offsets);
    fsdem__vtk_section_end(w, tag);
}

/* Closes the piece and the dataset, writes the appended data and closes the file. The object's
   message names the path on failure, and is cleared on success. */
static fsdem_result fsdem__vtk_close(fsdem__vtk_writer *w) {
    int k, bad;
    fprintf(w->fp, "</Piece>\n</%s>\n", w->type);
    if (w->format == FSDEM_VTK_FORMAT_APPENDED) {
        fputs("<AppendedData encoding=\"raw\">\n_", w->fp);
        for (k = 0; k < w->queued; ++k) fsdem__vtk_values(w, &w->queue[k]);
        fputs("\n</AppendedData>\n", w->fp);
    }
    fputs("</VTKFile>\n", w->fp);
    bad = ferror(w->fp) != 0;
    bad |= fclose(w->fp) != 0;
    w->fp = NULL;
    if (bad) return w->status ? fsdem__fail(w->status, FSDEM_ERR_IO, "%s: write error on '%s'", w->who, w->path) : FSDEM_ERR_IO;
    return w->status ? fsdem__ok(w->status) : FSDEM_OK;
}

/* A particle snapshot (PolyData, one point and one vertex per particle), in two halves around its
   point data: the file, its header and the opening of <PointData> with the active arrays; then
   the closing of <PointData>, the points and the vertices, and the file closed. */
static fsdem_result fsdem__vtk_particles_begin(fsdem__vtk_writer *w, const fsdem__status *status, const char *who, const char *path,
                                               fsdem_vtk_format format, double time, long long n, const char *scalars,
                                               const char *vectors) {
    const fsdem_result res = fsdem__vtk_open(w, (fsdem__status *)status, who, path, format, "PolyData");
    if (res != FSDEM_OK) return res;
    fsdem__vtk_polydata(w, time, n, n, 0, 0);
    fsdem__vtk_section(w, "PointData", scalars, vectors);
    return FSDEM_OK;
}

static fsdem_result fsdem__vtk_particles_end(fsdem__vtk_writer *w, const fsdem_vec3 *points, long long n) {
    fsdem__vtk_section_end(w, "PointData");
    fsdem__vtk_section(w, "Points", NULL, NULL);
    fsdem__vtk_write(w, fsdem__vtk_vec3s("Points", points, n));
    fsdem__vtk_section_end(w, "Points");
    fsdem__vtk_cells(w, "Verts", fsdem__vtk_ramp("connectivity", n, 0, 1), fsdem__vtk_ramp("offsets", n, 1, 1));
    return fsdem__vtk_close(w);
}
