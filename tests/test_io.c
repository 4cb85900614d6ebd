/* IO: every VTK XML file the library writes, in each of the three formats, read back by a small XML
   reader and base64/raw decoder written here (no library code), and compared with the object's own
   views: counts (NumberOfPoints, NumberOfVerts/Lines/Polys, WholeExtent), every array's name, type
   and component count, and every value. ASCII prints the digits that read back to the same bits
   (17 for Float64, 9 for Float32) and binary is the bits themselves, so values compare exactly in
   all three formats. A .pvd series must parse after every add, before close, and bad pieces and
   times are refused. The reader is strict: well-formed XML (balanced tags, quoted attributes, only
   the five predefined entities and character references), one base64 stream per inline array, and
   byte counts that match the data. Files are left in build/ for tests/vtk_readback.py (VTK's own
   readers, run by hand). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fsdem_tests.h"

#ifdef FSDEM_USE_FLOAT
#define REAL_TYPE "Float32"
#define RTOL 1e-4
#else
#define REAL_TYPE "Float64"
#define RTOL 1e-9
#endif
#define R(x) ((double)(fsdem_real)(x)) /* a constant as the library stores it */

/* ---- a small XML reader -------------------------------------------------------------------------- */

#define X_ATTRS 12

typedef struct xnode {
    char name[40];
    int parent; /* node index, -1 for the root */
    int nattr;
    char attr_name[X_ATTRS][40];
    char attr_value[X_ATTRS][512]; /* entities decoded */
    size_t text_begin, text_end;   /* content between the start and the end tag */
} xnode;

typedef struct xdoc {
    unsigned char *buf;
    size_t size;
    xnode *nodes;
    int count, capacity;
    size_t raw; /* AppendedData: offset of the first byte after '_' (0: none) */
    char why[256];
} xdoc;

static int x_space(int c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
static int x_namechar(int c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == ':' || c == '-' ||
           c == '.';
}

static int x_fail(xdoc *d, const char *why, size_t pos) {
    snprintf(d->why, sizeof d->why, "%s at byte %lu", why, (unsigned long)pos);
    return 0;
}

/* Decodes the entities of s[0..n) into out (size cap); 0 on a bad entity or a raw '<' or '&'. */
static int x_decode(const char *s, size_t n, char *out, size_t cap) {
    size_t i = 0, o = 0;
    while (i < n) {
        char c = s[i];
        if (c == '<') return 0;
        if (c == '&') {
            static const char *const names[5] = {"&amp;", "&lt;", "&gt;", "&quot;", "&apos;"};
            static const char chars[5] = {'&', '<', '>', '"', '\''};
            int k, found = 0;
            for (k = 0; k < 5 && !found; ++k)
                if (n - i >= strlen(names[k]) && strncmp(s + i, names[k], strlen(names[k])) == 0) {
                    c = chars[k];
                    i += strlen(names[k]);
                    found = 1;
                }
            if (!found && n - i > 3 && s[i + 1] == '#') {
                char *end;
                long v = strtol(s + i + 2, &end, 10);
                if (*end != ';' || v <= 0 || v > 127) return 0;
                c = (char)v;
                i = (size_t)(end - s) + 1;
                found = 1;
            }
            if (!found) return 0;
        } else
            ++i;
        if (o + 1 >= cap) return 0;
        out[o++] = c;
    }
    out[o] = '\0';
    return 1;
}

static void xdoc_free(xdoc *d) {
    free(d->buf);
    free(d->nodes);
    memset(d, 0, sizeof *d);
}

/* Parses a whole file; returns 1 when it is well-formed (with the appended raw section skipped). */
static int xdoc_read(xdoc *d, const char *path) {
    FILE *fp = fopen(path, "rb");
    int stack[64], depth = 0, roots = 0;
    size_t pos = 0;
    long len;
    memset(d, 0, sizeof *d);
    if (!fp) return x_fail(d, "cannot open", 0);
    fseek(fp, 0, SEEK_END);
    len = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    d->size = (size_t)len;
    d->buf = (unsigned char *)malloc(d->size + 1);
    if (fread(d->buf, 1, d->size, fp) != d->size) {
        fclose(fp);
        return x_fail(d, "short read", 0);
    }
    fclose(fp);
    d->buf[d->size] = '\0';
    if (strncmp((const char *)d->buf, "<?xml", 5) != 0) return x_fail(d, "no XML declaration", 0);
    {
        const char *end = strstr((const char *)d->buf, "?>");
        if (!end) return x_fail(d, "unterminated declaration", 0);
        pos = (size_t)(end - (const char *)d->buf) + 2;
    }
    for (;;) {
        const char *s = (const char *)d->buf;
        while (pos < d->size && x_space(s[pos])) ++pos;
        if (pos >= d->size) break;
        if (s[pos] != '<') {
            /* character data: only inside an element, and well-formed */
            char tmp[64];
            if (depth == 0) return x_fail(d, "text outside the root", pos);
            while (pos < d->size && s[pos] != '<') {
                if (s[pos] == '&') {
                    size_t e = pos;
                    while (e < d->size && s[e] != ';' && e - pos < 10) ++e;
                    if (e >= d->size || s[e] != ';' || !x_decode(s + pos, e - pos + 1, tmp, sizeof tmp))
                        return x_fail(d, "bad entity in text", pos);
                    pos = e;
                }
                ++pos;
            }
            continue;
        }
        if (strncmp(s + pos, "<!--", 4) == 0) {
            const char *end = strstr(s + pos, "-->");
            if (!end) return x_fail(d, "unterminated comment", pos);
            pos = (size_t)(end - s) + 3;
            continue;
        }
        if (s[pos + 1] == '/') {
            /* end tag */
            size_t n = 0;
            xnode *top;
            pos += 2;
            if (depth == 0) return x_fail(d, "end tag without start", pos);
            top = &d->nodes[stack[depth - 1]];
            while (pos + n < d->size && x_namechar(s[pos + n])) ++n;
            if (n != strlen(top->name) || strncmp(s + pos, top->name, n) != 0) return x_fail(d, "mismatched end tag", pos);
            top->text_end = pos - 2;
            pos += n;
            while (pos < d->size && x_space(s[pos])) ++pos;
            if (pos >= d->size || s[pos] != '>') return x_fail(d, "bad end tag", pos);
            ++pos;
            --depth;
            continue;
        }
        {
            /* start tag */
            xnode *node;
            size_t n = 0;
            int empty = 0;
            ++pos;
            if (d->count == d->capacity) {
                d->capacity = d->capacity ? 2 * d->capacity : 64;
                d->nodes = (xnode *)realloc(d->nodes, sizeof(xnode) * (size_t)d->capacity);
            }
            node = &d->nodes[d->count];
            memset(node, 0, sizeof *node);
            while (pos + n < d->size && x_namechar(s[pos + n])) ++n;
            if (n == 0 || n >= sizeof node->name) return x_fail(d, "bad element name", pos);
            memcpy(node->name, s + pos, n);
            pos += n;
            node->parent = depth ? stack[depth - 1] : -1;
            if (depth == 0 && ++roots > 1) return x_fail(d, "two root elements", pos);
            for (;;) {
                size_t an = 0, vstart;
                char quote;
                int had_space = 0;
                while (pos < d->size && x_space(s[pos])) {
                    ++pos;
                    had_space = 1;
                }
                if (pos >= d->size) return x_fail(d, "unterminated tag", pos);
                if (s[pos] == '/' && s[pos + 1] == '>') {
                    empty = 1;
                    pos += 2;
                    break;
                }
                if (s[pos] == '>') {
                    ++pos;
                    break;
                }
                if (!had_space) return x_fail(d, "attributes must be separated", pos);
                while (pos + an < d->size && x_namechar(s[pos + an])) ++an;
                if (an == 0 || an >= sizeof node->attr_name[0] || node->nattr == X_ATTRS) return x_fail(d, "bad attribute", pos);
                memcpy(node->attr_name[node->nattr], s + pos, an);
                node->attr_name[node->nattr][an] = '\0';
                pos += an;
                if (s[pos] != '=' || (s[pos + 1] != '"' && s[pos + 1] != '\'')) return x_fail(d, "attribute without quoted value", pos);
                quote = s[pos + 1];
                pos += 2;
                vstart = pos;
                while (pos < d->size && s[pos] != quote) ++pos;
                if (pos >= d->size) return x_fail(d, "unterminated attribute", vstart);
                if (!x_decode(s + vstart, pos - vstart, node->attr_value[node->nattr], sizeof node->attr_value[0]))
                    return x_fail(d, "bad character or entity in an attribute", vstart);
                node->nattr++;
                ++pos;
            }
            d->count++;
            node->text_begin = node->text_end = pos;
            if (empty) continue;
            if (depth == 64) return x_fail(d, "too deep", pos);
            stack[depth++] = d->count - 1;
            if (strcmp(node->name, "AppendedData") == 0) {
                /* raw bytes: '_' after white space, then data up to the last </AppendedData> */
                const char *tail = "</AppendedData>";
                size_t t = d->size - strlen(tail);
                while (pos < d->size && x_space(s[pos])) ++pos;
                if (pos >= d->size || s[pos] != '_') return x_fail(d, "AppendedData without '_'", pos);
                d->raw = pos + 1;
                while (t > pos && strncmp(s + t, tail, strlen(tail)) != 0) --t;
                if (t <= pos) return x_fail(d, "AppendedData not closed", pos);
                pos = t;
            }
        }
    }
    if (depth != 0) return x_fail(d, "unclosed elements at the end", pos);
    if (roots != 1) return x_fail(d, "no root element", pos);
    return 1;
}

static const char *x_attr(const xdoc *d, int k, const char *name) {
    int a;
    for (a = 0; a < d->nodes[k].nattr; ++a)
        if (strcmp(d->nodes[k].attr_name[a], name) == 0) return d->nodes[k].attr_value[a];
    return NULL;
}

/* The nth element named `name` (document order), or -1. */
static int x_find(const xdoc *d, const char *name, int nth) {
    int k;
    for (k = 0; k < d->count; ++k)
        if (strcmp(d->nodes[k].name, name) == 0 && nth-- == 0) return k;
    return -1;
}

static int x_count(const xdoc *d, const char *name) {
    int k, n = 0;
    for (k = 0; k < d->count; ++k) n += strcmp(d->nodes[k].name, name) == 0;
    return n;
}

/* The DataArray named `name` directly in the section `section` (PointData, Points, ...), or -1. */
static int x_array(const xdoc *d, const char *section, const char *name) {
    int k;
    for (k = 0; k < d->count; ++k) {
        const char *n = x_attr(d, k, "Name");
        if (strcmp(d->nodes[k].name, "DataArray") == 0 && d->nodes[k].parent >= 0 &&
            strcmp(d->nodes[d->nodes[k].parent].name, section) == 0 && n && strcmp(n, name) == 0)
            return k;
    }
    return -1;
}

static int x_arrays_in(const xdoc *d, const char *section) {
    int k, n = 0;
    for (k = 0; k < d->count; ++k)
        n += strcmp(d->nodes[k].name, "DataArray") == 0 && d->nodes[k].parent >= 0 &&
             strcmp(d->nodes[d->nodes[k].parent].name, section) == 0;
    return n;
}

static long long x_attr_ll(const xdoc *d, int k, const char *name) {
    const char *v = x_attr(d, k, name);
    ck_assert_msg(v != NULL, "element %s has no attribute %s", d->nodes[k].name, name);
    return atoll(v);
}

/* ---- base64 and array decoding ------------------------------------------------------------------ */

static int b64_value(int c) {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
}

/* One base64 stream (padding only at its end) into out; returns the number of bytes or -1. */
static long b64_decode(const char *s, size_t n, unsigned char *out) {
    size_t i, o = 0;
    if (n % 4) return -1;
    for (i = 0; i < n; i += 4) {
        int v[4], k, pad = 0;
        for (k = 0; k < 4; ++k) {
            v[k] = s[i + k] == '=' ? 0 : b64_value((unsigned char)s[i + k]);
            if (s[i + k] == '=') {
                if (i + 4 != n || k < 2) return -1; /* '=' only closes the last quad */
                pad++;
            } else if (v[k] < 0 || pad)
                return -1;
        }
        out[o++] = (unsigned char)((v[0] << 2) | (v[1] >> 4));
        if (pad < 2) out[o++] = (unsigned char)(((v[1] & 15) << 4) | (v[2] >> 2));
        if (pad < 1) out[o++] = (unsigned char)(((v[2] & 3) << 6) | v[3]);
    }
    return (long)o;
}

static size_t type_size(const char *type) {
    if (strcmp(type, "Float64") == 0) return 8;
    if (strcmp(type, "Float32") == 0 || strcmp(type, "Int32") == 0) return 4;
    if (strcmp(type, "UInt8") == 0) return 1;
    return 0;
}

static double unpack(const char *type, const unsigned char *p) {
    if (strcmp(type, "Float64") == 0) {
        double v;
        memcpy(&v, p, 8);
        return v;
    }
    if (strcmp(type, "Float32") == 0) {
        float v;
        memcpy(&v, p, 4);
        return v;
    }
    if (strcmp(type, "Int32") == 0) {
        int v;
        memcpy(&v, p, 4);
        return v;
    }
    return p[0];
}

static int host_little_endian(void) {
    const unsigned int one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

/* The values of DataArray k as doubles (malloc'd into *out); returns their number. Binary data must
   start with a UInt64 byte count equal to the data that follow. */
static long x_values(const xdoc *d, int k, double **out) {
    const char *type = x_attr(d, k, "type"), *format = x_attr(d, k, "format");
    const char *text = (const char *)d->buf + d->nodes[k].text_begin;
    size_t tlen = d->nodes[k].text_end - d->nodes[k].text_begin, size;
    long n = 0, i;
    ck_assert_ptr_nonnull(type);
    ck_assert_ptr_nonnull(format);
    size = type_size(type);
    ck_assert_msg(size > 0, "unknown type %s", type);
    if (strcmp(format, "ascii") == 0) {
        char *copy = (char *)malloc(tlen + 1), *p, *end;
        memcpy(copy, text, tlen);
        copy[tlen] = '\0';
        *out = (double *)malloc(sizeof(double) * (tlen / 2 + 1));
        for (p = copy;; p = end) {
            double v = strtod(p, &end);
            if (end == p) break;
            (*out)[n++] = strcmp(type, "Float32") == 0 ? (double)(float)v : v;
        }
        while (*p && x_space(*p)) ++p;
        ck_assert_msg(*p == '\0', "array %s: stray text '%.20s'", x_attr(d, k, "Name"), p);
        free(copy);
        return n;
    } else {
        const unsigned char *bytes;
        unsigned char *decoded = NULL;
        unsigned long long count;
        size_t avail;
        if (strcmp(format, "binary") == 0) {
            long got;
            while (tlen && x_space(text[0])) {
                ++text;
                --tlen;
            }
            while (tlen && x_space(text[tlen - 1])) --tlen;
            decoded = (unsigned char *)malloc(tlen + 8);
            got = b64_decode(text, tlen, decoded);
            ck_assert_msg(got >= 8, "array %s: not one base64 stream", x_attr(d, k, "Name"));
            bytes = decoded;
            avail = (size_t)got;
        } else {
            long long offset = x_attr_ll(d, k, "offset");
            ck_assert_str_eq(format, "appended");
            ck_assert_msg(d->raw > 0, "appended array without AppendedData");
            ck_assert_msg(offset >= 0 && d->raw + (size_t)offset + 8 <= d->size, "offset out of the file");
            bytes = d->buf + d->raw + offset;
            avail = d->size - d->raw - (size_t)offset;
        }
        memcpy(&count, bytes, 8);
        if (strcmp(format, "binary") == 0)
            ck_assert_msg(count + 8 == avail, "array %s: byte count %llu but %lu bytes", x_attr(d, k, "Name"), count,
                          (unsigned long)(avail - 8));
        else
            ck_assert_msg(count + 8 <= avail, "array %s: byte count %llu past the end", x_attr(d, k, "Name"), count);
        ck_assert_msg(count % size == 0, "byte count not a multiple of the type");
        n = (long)(count / size);
        *out = (double *)malloc(sizeof(double) * (size_t)(n + 1));
        for (i = 0; i < n; ++i) (*out)[i] = unpack(type, bytes + 8 + (size_t)i * size);
        free(decoded);
        return n;
    }
}

/* Checks the appended section: its blocks (count + data) follow one another from offset 0 and fill it. */
static void x_check_appended(const xdoc *d) {
    unsigned long long at = 0;
    int k;
    const char *tail = "\n</AppendedData>\n</VTKFile>\n";
    if (!d->raw) return;
    for (k = 0; k < d->count; ++k) {
        unsigned long long count;
        if (strcmp(d->nodes[k].name, "DataArray") != 0) continue;
        ck_assert_int_eq(x_attr_ll(d, k, "offset"), (long long)at);
        memcpy(&count, d->buf + d->raw + at, 8);
        at += 8 + count;
    }
    ck_assert_msg(d->raw + at + strlen(tail) == d->size, "appended data: %llu bytes of blocks, %lu in the file", at,
                  (unsigned long)(d->size - d->raw - strlen(tail)));
    ck_assert(memcmp(d->buf + d->raw + at, tail, strlen(tail)) == 0);
}

static const char *const FORMAT_NAME[3] = {"ascii", "binary", "appended"};

/* Opens a VTK file written in `format` and checks the root element: type, version 1.0, byte order of
   this machine, UInt64 headers, every DataArray in that format, the appended blocks, the time. */
static void vtk_open(xdoc *d, const char *path, const char *type, int format, double time) {
    int root, k, t;
    double *v;
    ck_assert_msg(xdoc_read(d, path), "%s: %s", path, d->why);
    root = x_find(d, "VTKFile", 0);
    ck_assert_int_eq(root, 0);
    ck_assert_str_eq(x_attr(d, root, "type"), type);
    ck_assert_str_eq(x_attr(d, root, "version"), "1.0");
    ck_assert_str_eq(x_attr(d, root, "byte_order"), host_little_endian() ? "LittleEndian" : "BigEndian");
    ck_assert_str_eq(x_attr(d, root, "header_type"), "UInt64");
    ck_assert_int_eq(x_count(d, type), 1);
    ck_assert_int_eq(d->nodes[x_find(d, type, 0)].parent, root);
    ck_assert_int_eq(x_count(d, "Piece"), 1);
    ck_assert_int_eq(x_count(d, "AppendedData"), format == FSDEM_VTK_FORMAT_APPENDED);
    for (k = 0; k < d->count; ++k)
        if (strcmp(d->nodes[k].name, "DataArray") == 0) ck_assert_str_eq(x_attr(d, k, "format"), FORMAT_NAME[format]);
    x_check_appended(d);
    t = x_array(d, "FieldData", "TimeValue");
    ck_assert_int_ge(t, 0);
    ck_assert_str_eq(x_attr(d, t, "type"), "Float64");
    ck_assert_int_eq(x_attr_ll(d, t, "NumberOfTuples"), 1);
    ck_assert_int_eq(x_values(d, t, &v), 1);
    ck_assert_msg(v[0] == time, "TimeValue %.17g, time %.17g", v[0], time);
    free(v);
}

/* Checks array `name` in `section`: type, components, and its values against `expected` (n tuples). */
static void vtk_expect(const xdoc *d, const char *section, const char *name, const char *type, int components,
                       const double *expected, long n) {
    int k = x_array(d, section, name);
    double *v;
    long got, i;
    ck_assert_msg(k >= 0, "no array %s in %s", name, section);
    ck_assert_str_eq(x_attr(d, k, "type"), type);
    ck_assert_int_eq(x_attr_ll(d, k, "NumberOfComponents"), components);
    got = x_values(d, k, &v);
    ck_assert_msg(got == n * components, "%s/%s: %ld values, expected %ld", section, name, got, n * components);
    for (i = 0; i < got; ++i)
        ck_assert_msg(v[i] == expected[i], "%s/%s[%ld] = %.17g, expected %.17g", section, name, i, v[i], expected[i]);
    free(v);
}

/* Expected values from the object's views. */
static double *from_reals(const fsdem_real *p, long n) {
    double *e = (double *)malloc(sizeof(double) * (size_t)(n + 1));
    long i;
    for (i = 0; i < n; ++i) e[i] = (double)p[i];
    return e;
}
static double *from_vec3s(const fsdem_vec3 *p, long n) {
    double *e = (double *)malloc(sizeof(double) * (size_t)(3 * n + 1));
    long i;
    for (i = 0; i < n; ++i) {
        e[3 * i] = (double)p[i].x;
        e[3 * i + 1] = (double)p[i].y;
        e[3 * i + 2] = (double)p[i].z;
    }
    return e;
}
static double *from_ints(const int *p, long n) {
    double *e = (double *)malloc(sizeof(double) * (size_t)(n + 1));
    long i;
    for (i = 0; i < n; ++i) e[i] = p[i];
    return e;
}
static double *from_ramp(long n, long first, long step) {
    double *e = (double *)malloc(sizeof(double) * (size_t)(n + 1));
    long i;
    for (i = 0; i < n; ++i) e[i] = (double)(first + step * i);
    return e;
}

#define EXPECT(d, section, name, type, comps, values, n)                \
    do {                                                                \
        double *e_ = (values);                                          \
        vtk_expect(d, section, name, type, comps, e_, n);               \
        free(e_);                                                       \
    } while (0)

static void vtk_piece_counts(const xdoc *d, long points, long verts, long lines, long polys) {
    int p = x_find(d, "Piece", 0);
    ck_assert_int_eq(x_attr_ll(d, p, "NumberOfPoints"), points);
    ck_assert_int_eq(x_attr_ll(d, p, "NumberOfVerts"), verts);
    ck_assert_int_eq(x_attr_ll(d, p, "NumberOfLines"), lines);
    ck_assert_int_eq(x_attr_ll(d, p, "NumberOfStrips"), 0);
    ck_assert_int_eq(x_attr_ll(d, p, "NumberOfPolys"), polys);
    ck_assert_int_eq(x_arrays_in(d, "Points"), 1);
    ck_assert_int_eq(x_count(d, "Verts"), verts > 0);
    ck_assert_int_eq(x_count(d, "Lines"), lines > 0 || (verts == 0 && polys == 0));
    ck_assert_int_eq(x_count(d, "Polys"), polys > 0);
}

/* ---- scenes ------------------------------------------------------------------------------------- */

static fsdem_dem *dem_make(const fsdem_dem_desc *desc) {
    fsdem_dem *dem = NULL;
    ck_assert_int_eq(fsdem_dem_create(desc, &dem), FSDEM_OK);
    return dem;
}

/* A settling pile in a box with a floor: two materials (non-uniform coefficients), a fixed particle,
   external forces, rotation; `restitution` 1 removes every dashpot. Centres `spacing` apart (radii
   5 to 6.2 mm), the bottom layer touching the floor. */
static fsdem_dem *dem_pile(int dim, fsdem_dem_law law, double restitution, int steps, double spacing) {
    fsdem_dem_desc d = fsdem_dem_desc_default(dim);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    fsdem_dem_wall_desc w;
    fsdem_dem_coupling ext;
    fsdem_dem *dem;
    int a, b, i, k, mat[2];
    d.domain_min = fsdem_v3(-0.1, -0.1, -0.1);
    d.domain_max = fsdem_v3(0.1, 0.1, 0.1);
    d.law = law;
    d.dt = 2e-5;
    d.linear_dx = 0.01;
    dem = dem_make(&d);
    m.restitution = (fsdem_real)restitution;
    m.friction = 0.4;
    m.rolling_friction = 0.05;
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, &mat[0]), FSDEM_OK);
    m.young_modulus = 3e8;
    m.density = 1500;
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, &mat[1]), FSDEM_OK);
    w = fsdem_dem_wall_plane(fsdem_v3(0, dim == 2 ? -0.05 : 0, dim == 2 ? 0 : -0.05), fsdem_v3(0, dim == 2 ? 1 : 0, dim == 2 ? 0 : 1),
                             mat[0]);
    ck_assert_int_eq(fsdem_dem_add_wall(dem, &w, NULL), FSDEM_OK);
    w = fsdem_dem_wall_box(fsdem_v3(-0.03, -0.05, -0.05), fsdem_v3(0.03, 0.09, 0.09), 1, mat[1]);
    ck_assert_int_eq(fsdem_dem_add_wall(dem, &w, NULL), FSDEM_OK);
    k = 0;
    for (b = 0; b < 4; ++b)
        for (a = 0; a < 4; ++a)
            for (i = 0; i < (dim == 3 ? 2 : 1); ++i) {
                const double x = -1.5 * spacing + spacing * a, up = -0.0455 + spacing * b, z = spacing * (i - 0.5);
                p.position = dim == 3 ? fsdem_v3(x, z, up) : fsdem_v3(x, up, 0);
                p.radius = 0.005 + 0.0003 * ((k * 7) % 5);
                p.material = mat[k % 2];
                p.velocity = fsdem_v3(0.05 * ((k * 3) % 5 - 2), 0.02 * ((k * 5) % 3 - 1), dim == 3 ? 0.03 * (k % 3 - 1) : 0);
                p.angular_velocity = fsdem_v3(dim == 3 ? 3.0 * (k % 2) : 0, 0, 2.0 * (k % 3 - 1));
                p.fixed = k == 1;
                if (p.fixed) p.velocity = fsdem_v3(0, 0, 0);
                ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
                k++;
            }
    ext = fsdem_dem_get_coupling(dem);
    for (i = 0; i < ext.count; ++i) ext.force[i] = fsdem_v3(1e-4 * i, -2e-4 * (i % 3), 0);
    for (i = 0; i < steps; ++i) ck_assert_int_eq(fsdem_dem_step(dem), FSDEM_OK);
    return dem;
}

/* ---- DEM particles ---------------------------------------------------------------------------------- */

static void check_dem_particles(int dim) {
    fsdem_dem *dem = dem_pile(dim, FSDEM_DEM_LAW_HERTZ_MINDLIN, 0.5, 300, 0.0128);
    fsdem_dem_particles p = fsdem_dem_get_particles(dem);
    int f;
    ck_assert_int_gt(p.count, 10);
    for (f = 0; f < 3; ++f) {
        char path[64];
        xdoc d;
        double *e;
        long i;
        snprintf(path, sizeof path, "build/test_io_dem%dd_%s.vtp", dim, FORMAT_NAME[f]);
        ck_assert_int_eq(fsdem_dem_write_vtp(dem, path, (fsdem_vtk_format)f), FSDEM_OK);
        ck_assert_str_eq(fsdem_dem_last_error(dem), "");
        vtk_open(&d, path, "PolyData", f, fsdem_dem_time(dem));
        vtk_piece_counts(&d, p.count, p.count, 0, 0);
        EXPECT(&d, "Points", "Points", REAL_TYPE, 3, from_vec3s(p.position, p.count), p.count);
        EXPECT(&d, "Verts", "connectivity", "Int32", 1, from_ramp(p.count, 0, 1), p.count);
        EXPECT(&d, "Verts", "offsets", "Int32", 1, from_ramp(p.count, 1, 1), p.count);
        ck_assert_int_eq(x_arrays_in(&d, "PointData"), 10);
        EXPECT(&d, "PointData", "id", "Int32", 1, from_ints(p.id, p.count), p.count);
        EXPECT(&d, "PointData", "radius", REAL_TYPE, 1, from_reals(p.radius, p.count), p.count);
        EXPECT(&d, "PointData", "mass", REAL_TYPE, 1, from_reals(p.mass, p.count), p.count);
        EXPECT(&d, "PointData", "material", "Int32", 1, from_ints(p.material, p.count), p.count);
        e = (double *)malloc(sizeof(double) * (size_t)p.count);
        for (i = 0; i < p.count; ++i) e[i] = p.fixed[i];
        EXPECT(&d, "PointData", "fixed", "UInt8", 1, e, p.count);
        EXPECT(&d, "PointData", "velocity", REAL_TYPE, 3, from_vec3s(p.velocity, p.count), p.count);
        EXPECT(&d, "PointData", "angular_velocity", REAL_TYPE, 3, from_vec3s(p.angular_velocity, p.count), p.count);
        EXPECT(&d, "PointData", "force", REAL_TYPE, 3, from_vec3s(p.force, p.count), p.count);
        EXPECT(&d, "PointData", "torque", REAL_TYPE, 3, from_vec3s(p.torque, p.count), p.count);
        EXPECT(&d, "PointData", "external_force", REAL_TYPE, 3, from_vec3s(p.external_force, p.count), p.count);
        ck_assert_str_eq(x_attr(&d, x_find(&d, "PointData", 0), "Scalars"), "radius");
        ck_assert_str_eq(x_attr(&d, x_find(&d, "PointData", 0), "Vectors"), "velocity");
        xdoc_free(&d);
    }
    fsdem_dem_destroy(dem);
}

START_TEST(io_dem_particles_read_back_3d) { check_dem_particles(3); }
END_TEST

START_TEST(io_dem_particles_read_back_2d) { check_dem_particles(2); }
END_TEST

/* ---- DEM walls ---------------------------------------------------------------------------------- */

static fsdem_real sdf_ball(void *user, fsdem_vec3 p, fsdem_vec3 *n) {
    const fsdem_real r = (fsdem_real)sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    (void)user;
    *n = r > 0 ? fsdem_v3(p.x / r, p.y / r, p.z / r) : fsdem_v3(0, 0, 1);
    return 10 - r;
}

/* Unit normal of polygon `cell` (Newell's method) and its centroid. */
static fsdem_vec3 poly_normal(const double *pts, const double *conn, long begin, long end, fsdem_vec3 *centroid) {
    double nx = 0, ny = 0, nz = 0, cx = 0, cy = 0, cz = 0, len;
    long k;
    for (k = begin; k < end; ++k) {
        const double *a = pts + 3 * (long)conn[k], *b = pts + 3 * (long)conn[k + 1 < end ? k + 1 : begin];
        nx += (a[1] - b[1]) * (a[2] + b[2]);
        ny += (a[2] - b[2]) * (a[0] + b[0]);
        nz += (a[0] - b[0]) * (a[1] + b[1]);
        cx += a[0];
        cy += a[1];
        cz += a[2];
    }
    len = sqrt(nx * nx + ny * ny + nz * nz);
    *centroid = fsdem_v3(cx / (double)(end - begin), cy / (double)(end - begin), cz / (double)(end - begin));
    return fsdem_v3(nx / len, ny / len, nz / len);
}

START_TEST(io_dem_walls_read_back_3d) {
    /* domain [-1, 1] x [-1, 1] x [0, 2]; a floor on its bottom face; a plane through the centre with
       normal -(1, 1, 1)/sqrt(3) cuts the cube in a regular hexagon; a plane outside the box is not
       drawn; boxes inside and outside; a triangle; an SDF wall and a removed wall are left out */
    fsdem_dem_desc desc = fsdem_dem_desc_default(3);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
    fsdem_dem_wall_desc w[8];
    fsdem_dem *dem;
    const fsdem_vec3 s3 = fsdem_v3(-1 / sqrt(3.0), -1 / sqrt(3.0), -1 / sqrt(3.0));
    int ids[8], k, f, mat;
    desc.domain_min = fsdem_v3(-1, -1, 0);
    desc.domain_max = fsdem_v3(1, 1, 2);
    desc.dt = 1e-5;
    dem = dem_make(&desc);
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, &mat), FSDEM_OK);
    w[0] = fsdem_dem_wall_plane(fsdem_v3(0.3, -0.2, 0), fsdem_v3(0, 0, 5), mat);
    w[1] = fsdem_dem_wall_plane(fsdem_v3(0, 0, 1), fsdem_v3(-1, -1, -1), mat);
    w[2] = fsdem_dem_wall_plane(fsdem_v3(0, 0, 3), fsdem_v3(0, 0, -1), mat); /* above the box: misses it */
    w[3] = fsdem_dem_wall_box(fsdem_v3(-0.9, -0.9, -0.2), fsdem_v3(0.9, 0.8, 1.9), 1, mat);
    w[4] = fsdem_dem_wall_box(fsdem_v3(0.5, 0.5, 1.5), fsdem_v3(0.7, 0.6, 1.8), 0, mat);
    w[5] = fsdem_dem_wall_triangle(fsdem_v3(-0.5, -0.5, 0.2), fsdem_v3(0.5, -0.5, 0.25), fsdem_v3(0, 0.5, 0.3), mat);
    w[6] = fsdem_dem_wall_sdf(sdf_ball, NULL, mat);
    w[7] = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0.01), fsdem_v3(0, 0, 1), mat);
    for (k = 0; k < 8; ++k) ck_assert_int_eq(fsdem_dem_add_wall(dem, &w[k], &ids[k]), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_remove_wall(dem, ids[7]), FSDEM_OK);
    /* a sphere on the floor, so the floor carries a force */
    p.radius = 0.06;
    p.position = fsdem_v3(-0.2, -0.3, 0.059);
    ck_assert_int_eq(fsdem_dem_add_particle(dem, &p, NULL), FSDEM_OK);
    for (k = 0; k < 50; ++k) ck_assert_int_eq(fsdem_dem_step(dem), FSDEM_OK);
    ck_assert(fabs((double)fsdem_dem_wall_force(dem, ids[0]).z) > 0);
    for (f = 0; f < 3; ++f) {
        char path[64];
        xdoc d;
        double *pts, *conn, *off, *wid, *type, *force;
        long np, nc, c, start;
        int hexagon = 0, floor = 0, faces_in = 0, faces_out = 0, triangle = 0;
        snprintf(path, sizeof path, "build/test_io_walls3d_%s.vtp", FORMAT_NAME[f]);
        ck_assert_int_eq(fsdem_dem_write_walls_vtp(dem, path, (fsdem_vtk_format)f), FSDEM_OK);
        vtk_open(&d, path, "PolyData", f, fsdem_dem_time(dem));
        /* cells: floor 1 + hexagon 1 + 6 + 6 faces + triangle 1 */
        nc = x_attr_ll(&d, x_find(&d, "Piece", 0), "NumberOfPolys");
        np = x_attr_ll(&d, x_find(&d, "Piece", 0), "NumberOfPoints");
        ck_assert_int_eq(nc, 15);
        ck_assert_int_eq(np, 4 + 6 + 24 + 24 + 3);
        vtk_piece_counts(&d, np, 0, 0, nc);
        ck_assert_int_eq(x_arrays_in(&d, "CellData"), 3);
        ck_assert_int_eq(x_values(&d, x_array(&d, "Points", "Points"), &pts), 3 * np);
        ck_assert_int_eq(x_values(&d, x_array(&d, "Polys", "connectivity"), &conn), np);
        ck_assert_int_eq(x_values(&d, x_array(&d, "Polys", "offsets"), &off), nc);
        ck_assert_int_eq(x_values(&d, x_array(&d, "CellData", "wall_id"), &wid), nc);
        ck_assert_int_eq(x_values(&d, x_array(&d, "CellData", "type"), &type), nc);
        ck_assert_int_eq(x_values(&d, x_array(&d, "CellData", "force"), &force), 3 * nc);
        ck_assert_str_eq(x_attr(&d, x_array(&d, "CellData", "wall_id"), "type"), "Int32");
        ck_assert_str_eq(x_attr(&d, x_array(&d, "CellData", "type"), "type"), "UInt8");
        ck_assert_str_eq(x_attr(&d, x_array(&d, "CellData", "force"), "type"), REAL_TYPE);
        ck_assert_str_eq(x_attr(&d, x_array(&d, "Polys", "offsets"), "type"), "Int32");
        for (c = 0, start = 0; c < nc; start = (long)off[c], ++c) {
            const int id = (int)wid[c];
            const fsdem_vec3 wf = fsdem_dem_wall_force(dem, id);
            fsdem_vec3 centroid, n = poly_normal(pts, conn, start, (long)off[c], &centroid);
            long v;
            ck_assert(force[3 * c] == (double)wf.x && force[3 * c + 1] == (double)wf.y && force[3 * c + 2] == (double)wf.z);
            ck_assert_int_eq((int)type[c], (int)w[id].type);
            ck_assert(id != ids[2] && id != ids[6] && id != ids[7]);
            for (v = start; v < (long)off[c]; ++v) ck_assert_int_eq((long)conn[v], v); /* points are not shared */
            if (id == ids[0]) {
                /* the floor patch is the bottom face of the domain, normal +z */
                floor++;
                ck_assert_int_eq((long)off[c] - start, 4);
                for (v = start; v < (long)off[c]; ++v) {
                    ck_assert(fabs(fabs(pts[3 * v]) - 1) < 1e-6 && fabs(fabs(pts[3 * v + 1]) - 1) < 1e-6);
                    ck_assert(pts[3 * v + 2] == 0);
                }
                ck_assert(n.z > 1 - 1e-6);
            } else if (id == ids[1]) {
                /* regular hexagon: vertices in the plane, on the cube's surface, at distance sqrt(2) from its centre */
                hexagon++;
                ck_assert_int_eq((long)off[c] - start, 6);
                for (v = start; v < (long)off[c]; ++v) {
                    const fsdem_vec3 q = fsdem_v3(pts[3 * v], pts[3 * v + 1], pts[3 * v + 2] - 1);
                    ck_assert(fabs(q.x * s3.x + q.y * s3.y + q.z * s3.z) < 1e-5);
                    ck_assert(fabs(sqrt(q.x * q.x + q.y * q.y + q.z * q.z) - sqrt(2.0)) < 1e-5);
                }
                ck_assert(n.x * s3.x + n.y * s3.y + n.z * s3.z > 1 - 1e-6);
            } else if (id == ids[3] || id == ids[4]) {
                /* box faces: normals towards the particles, inwards for the inside box */
                const fsdem_vec3 lo = w[id].a, hi = w[id].b;
                const fsdem_vec3 mid = fsdem_v3((lo.x + hi.x) / 2, (lo.y + hi.y) / 2, (lo.z + hi.z) / 2);
                const double out = n.x * (centroid.x - mid.x) + n.y * (centroid.y - mid.y) + n.z * (centroid.z - mid.z);
                ck_assert_int_eq((long)off[c] - start, 4);
                for (v = start; v < (long)off[c]; ++v)
                    ck_assert((pts[3 * v] == lo.x || pts[3 * v] == hi.x) && (pts[3 * v + 1] == lo.y || pts[3 * v + 1] == hi.y) &&
                              (pts[3 * v + 2] == lo.z || pts[3 * v + 2] == hi.z));
                if (id == ids[3]) {
                    faces_in++;
                    ck_assert(out < 0);
                } else {
                    faces_out++;
                    ck_assert(out > 0);
                }
            } else {
                ck_assert_int_eq(id, ids[5]);
                triangle++;
                ck_assert_int_eq((long)off[c] - start, 3);
                ck_assert(pts[3 * start] == (double)w[5].a.x && pts[3 * start + 5] == (double)w[5].b.z &&
                          pts[3 * start + 7] == (double)w[5].c.y);
            }
        }
        ck_assert(floor == 1 && hexagon == 1 && faces_in == 6 && faces_out == 6 && triangle == 1);
        free(pts);
        free(conn);
        free(off);
        free(wid);
        free(type);
        free(force);
        xdoc_free(&d);
    }
    fsdem_dem_destroy(dem);
}
END_TEST

START_TEST(io_dem_walls_read_back_2d) {
    /* 2D: a tilted plane's chord of the domain rectangle, a box's four edges (inside and outside), a
       segment: lines only */
    fsdem_dem_desc desc = fsdem_dem_desc_default(2);
    fsdem_dem_material m = fsdem_dem_material_default();
    fsdem_dem_wall_desc w[4];
    fsdem_dem *dem;
    int ids[4], k, f, mat;
    desc.domain_min = fsdem_v3(0, 0, -1);
    desc.domain_max = fsdem_v3(2, 1, 1);
    dem = dem_make(&desc);
    ck_assert_int_eq(fsdem_dem_add_material(dem, &m, &mat), FSDEM_OK);
    w[0] = fsdem_dem_wall_plane(fsdem_v3(1, 0.5, 0), fsdem_v3(-1, 2, 0), mat);
    w[1] = fsdem_dem_wall_box(fsdem_v3(0.1, 0.1, 0), fsdem_v3(1.9, 0.9, 0), 1, mat);
    w[2] = fsdem_dem_wall_box(fsdem_v3(0.5, 0.2, 0), fsdem_v3(0.7, 0.3, 0), 0, mat);
    w[3] = fsdem_dem_wall_segment(fsdem_v3(1.2, 0.2, 0), fsdem_v3(1.6, 0.4, 0), mat);
    for (k = 0; k < 4; ++k) ck_assert_int_eq(fsdem_dem_add_wall(dem, &w[k], &ids[k]), FSDEM_OK);
    for (f = 0; f < 3; ++f) {
        char path[64];
        xdoc d;
        double *pts, *wid;
        long np, i;
        snprintf(path, sizeof path, "build/test_io_walls2d_%s.vtp", FORMAT_NAME[f]);
        ck_assert_int_eq(fsdem_dem_write_walls_vtp(dem, path, (fsdem_vtk_format)f), FSDEM_OK);
        vtk_open(&d, path, "PolyData", f, 0);
        vtk_piece_counts(&d, 20, 0, 10, 0);
        EXPECT(&d, "Lines", "offsets", "Int32", 1, from_ramp(10, 2, 2), 10);
        np = x_values(&d, x_array(&d, "Points", "Points"), &pts);
        ck_assert_int_eq(np, 60);
        ck_assert_int_eq(x_values(&d, x_array(&d, "CellData", "wall_id"), &wid), 10);
        for (i = 0; i < 20; ++i) ck_assert(pts[3 * i + 2] == 0);
        /* the chord: the line through (1, 0.5) normal to (-1, 2) is y = x/2, which crosses the
           rectangle's border at its corners (0, 0) and (2, 1) */
        ck_assert(wid[0] == ids[0]);
        ck_assert(fabs(pts[0] + pts[3] - 2) < 1e-6 && fabs(pts[0] * pts[3]) < 1e-6);
        for (i = 0; i < 2; ++i) ck_assert(fabs(pts[3 * i + 1] - pts[3 * i] / 2) < 1e-6);
        for (i = 1; i < 9; ++i) ck_assert(wid[i] == (i < 5 ? ids[1] : ids[2]));
        ck_assert(pts[3 * 2] == R(0.1) && pts[3 * 2 + 1] == R(0.1) && pts[3 * 3] == R(1.9) && pts[3 * 3 + 1] == R(0.1));
        ck_assert(wid[9] == ids[3] && pts[3 * 18] == R(1.2) && pts[3 * 19 + 1] == R(0.4));
        free(pts);
        free(wid);
        xdoc_free(&d);
    }
    fsdem_dem_destroy(dem);
}
END_TEST

/* ---- DEM contacts ------------------------------------------------------------------------------- */

/* Reads a contacts file and checks its structure; returns the cell count and the arrays. */
typedef struct contacts_file {
    long n;
    double *pts, *force, *fn, *overlap, *particle, *partner;
} contacts_file;

static void contacts_read(const char *path, int f, double time, contacts_file *c) {
    xdoc d;
    int p;
    vtk_open(&d, path, "PolyData", f, time);
    p = x_find(&d, "Piece", 0);
    c->n = (long)x_attr_ll(&d, p, "NumberOfLines");
    vtk_piece_counts(&d, 2 * c->n, 0, c->n, 0);
    ck_assert_int_eq(x_arrays_in(&d, "CellData"), 5);
    EXPECT(&d, "Lines", "connectivity", "Int32", 1, from_ramp(2 * c->n, 0, 1), 2 * c->n);
    EXPECT(&d, "Lines", "offsets", "Int32", 1, from_ramp(c->n, 2, 2), c->n);
    ck_assert_str_eq(x_attr(&d, x_array(&d, "CellData", "force"), "type"), REAL_TYPE);
    ck_assert_int_eq(x_attr_ll(&d, x_array(&d, "CellData", "force"), "NumberOfComponents"), 3);
    ck_assert_str_eq(x_attr(&d, x_array(&d, "CellData", "normal_force"), "type"), REAL_TYPE);
    ck_assert_str_eq(x_attr(&d, x_array(&d, "CellData", "overlap"), "type"), REAL_TYPE);
    ck_assert_str_eq(x_attr(&d, x_array(&d, "CellData", "particle"), "type"), "Int32");
    ck_assert_str_eq(x_attr(&d, x_array(&d, "CellData", "partner"), "type"), "Int32");
    ck_assert_int_eq(x_values(&d, x_array(&d, "Points", "Points"), &c->pts), 6 * c->n);
    ck_assert_int_eq(x_values(&d, x_array(&d, "CellData", "force"), &c->force), 3 * c->n);
    ck_assert_int_eq(x_values(&d, x_array(&d, "CellData", "normal_force"), &c->fn), c->n);
    ck_assert_int_eq(x_values(&d, x_array(&d, "CellData", "overlap"), &c->overlap), c->n);
    ck_assert_int_eq(x_values(&d, x_array(&d, "CellData", "particle"), &c->particle), c->n);
    ck_assert_int_eq(x_values(&d, x_array(&d, "CellData", "partner"), &c->partner), c->n);
    xdoc_free(&d);
}

static void contacts_free(contacts_file *c) {
    free(c->pts);
    free(c->force);
    free(c->fn);
    free(c->overlap);
    free(c->particle);
    free(c->partner);
}

static int index_of_id(const fsdem_dem_particles *p, int id) {
    int i;
    for (i = 0; i < p->count; ++i)
        if (p->id[i] == id) return i;
    ck_abort_msg("no particle with id %d", id);
    return -1;
}

/* Checks a contacts file against the particles: geometry of each contact (points, overlap, normal
   force along the normal), the count of the last force evaluation, and with `exact_sums` the
   per-particle sums of the contact forces against fsdem_dem_particles.force. */
static void check_contacts(fsdem_dem *dem, const contacts_file *c, int exact_sums, int pairs_expected, int walls_expected) {
    fsdem_dem_particles p = fsdem_dem_get_particles(dem);
    fsdem_dem_desc desc = fsdem_dem_get_desc(dem);
    fsdem_dem_stats st = fsdem_dem_get_stats(dem);
    fsdem_vec3 *sum = (fsdem_vec3 *)calloc((size_t)p.count, sizeof(fsdem_vec3));
    double scale = 0;
    long k, pairs = 0, walls = 0;
    int i;
    ck_assert_int_eq(c->n, st.contacts + st.wall_contacts);
    for (k = 0; k < c->n; ++k) {
        const int a = index_of_id(&p, (int)c->particle[k]);
        const double *q0 = c->pts + 6 * k, *q1 = q0 + 3;
        const fsdem_vec3 f = fsdem_v3(c->force[3 * k], c->force[3 * k + 1], c->force[3 * k + 2]);
        fsdem_vec3 n;
        double dist, fmag = sqrt(f.x * f.x + f.y * f.y + f.z * f.z);
        ck_assert(q0[0] == (double)p.position[a].x && q0[1] == (double)p.position[a].y && q0[2] == (double)p.position[a].z);
        ck_assert(c->overlap[k] > 0);
        ck_assert(p.fixed[a] == 0 || c->partner[k] >= 0);
        dist = sqrt((q0[0] - q1[0]) * (q0[0] - q1[0]) + (q0[1] - q1[1]) * (q0[1] - q1[1]) + (q0[2] - q1[2]) * (q0[2] - q1[2]));
        n = fsdem_v3((q0[0] - q1[0]) / dist, (q0[1] - q1[1]) / dist, (q0[2] - q1[2]) / dist);
        if (c->partner[k] >= 0) {
            const int b = index_of_id(&p, (int)c->partner[k]);
            pairs++;
            ck_assert(q1[0] == (double)p.position[b].x && q1[1] == (double)p.position[b].y && q1[2] == (double)p.position[b].z);
            ck_assert(!(p.fixed[a] && p.fixed[b]));
            ck_assert_msg(fabs(c->overlap[k] - ((double)p.radius[a] + (double)p.radius[b] + desc.contact_offset - dist)) <
                              RTOL * (double)p.radius[a],
                          "overlap %g, from the centres %g", c->overlap[k], (double)p.radius[a] + (double)p.radius[b] - dist);
            sum[a] = fsdem_v3(sum[a].x + f.x, sum[a].y + f.y, sum[a].z + f.z);
            sum[b] = fsdem_v3(sum[b].x - f.x, sum[b].y - f.y, sum[b].z - f.z);
        } else {
            walls++;
            ck_assert(-1 - (long)c->partner[k] < 2);
            /* the wall point lies r + offset - overlap from the centre */
            ck_assert(fabs(dist - ((double)p.radius[a] + desc.contact_offset - c->overlap[k])) < RTOL * (double)p.radius[a]);
            sum[a] = fsdem_v3(sum[a].x + f.x, sum[a].y + f.y, sum[a].z + f.z);
        }
        /* the normal part of the force is normal_force along the unit normal towards i */
        ck_assert_msg(fabs(f.x * n.x + f.y * n.y + f.z * n.z - c->fn[k]) <= RTOL * (fmag + 1e-12), "normal force %g, F.n %g",
                      c->fn[k], f.x * n.x + f.y * n.y + f.z * n.z);
        if (fmag > scale) scale = fmag;
    }
    ck_assert_int_eq(pairs, st.contacts);
    ck_assert_int_eq(walls, st.wall_contacts);
    if (pairs_expected) ck_assert_int_gt(pairs, 0);
    if (walls_expected) ck_assert_int_gt(walls, 0);
    if (exact_sums)
        for (i = 0; i < p.count; ++i) {
            if (p.fixed[i]) continue;
            ck_assert_msg(fabs((double)sum[i].x - (double)p.force[i].x) <= RTOL * scale &&
                              fabs((double)sum[i].y - (double)p.force[i].y) <= RTOL * scale &&
                              fabs((double)sum[i].z - (double)p.force[i].z) <= RTOL * scale,
                          "particle %d: contacts sum to (%g, %g, %g) N, the step had (%g, %g, %g) N", i, (double)sum[i].x,
                          (double)sum[i].y, (double)sum[i].z, (double)p.force[i].x, (double)p.force[i].y, (double)p.force[i].z);
        }
    free(sum);
}

/* Without dashpots (restitution 1) the law depends on positions and springs only, which a Verlet
   step leaves as its last force evaluation had them: the contacts' forces sum to the particles'
   contact forces (to rounding). Two materials, a fixed particle, friction and rolling resistance;
   the pile starts overlapping and its springs have grown for 40 steps. */
static void check_contacts_sums(int dim) {
    fsdem_dem *dem = dem_pile(dim, FSDEM_DEM_LAW_HERTZ_MINDLIN, 1.0, 40, 0.0118);
    int f;
    for (f = 0; f < 3; ++f) {
        char path[64];
        contacts_file c;
        snprintf(path, sizeof path, "build/test_io_contacts%dd_%s.vtp", dim, FORMAT_NAME[f]);
        ck_assert_int_eq(fsdem_dem_write_contacts_vtp(dem, path, (fsdem_vtk_format)f), FSDEM_OK);
        contacts_read(path, f, fsdem_dem_time(dem), &c);
        check_contacts(dem, &c, 1, 1, 1);
        contacts_free(&c);
    }
    fsdem_dem_destroy(dem);
}

START_TEST(io_dem_contacts_sum_to_particle_forces_3d) { check_contacts_sums(3); }
END_TEST

START_TEST(io_dem_contacts_sum_to_particle_forces_2d) { check_contacts_sums(2); }
END_TEST

/* With dashpots and the other laws: the same contacts and geometry; writing changes nothing (a
   twin that did not write steps on to the same bits). */
START_TEST(io_dem_contacts_other_laws_leave_the_object_unchanged) {
    static const fsdem_dem_law laws[3] = {FSDEM_DEM_LAW_HERTZ_MINDLIN, FSDEM_DEM_LAW_LINEAR, FSDEM_DEM_LAW_GIC};
    int l, k;
    for (l = 0; l < 3; ++l) {
        /* overlapping at the start, a few steps in: contacts with every law */
        fsdem_dem *dem = dem_pile(3, laws[l], 0.5, 5, 0.0118), *twin = dem_pile(3, laws[l], 0.5, 5, 0.0118);
        fsdem_dem_particles p, q;
        contacts_file c;
        ck_assert_int_eq(fsdem_dem_write_contacts_vtp(dem, "build/test_io_contacts_law.vtp", FSDEM_VTK_FORMAT_APPENDED), FSDEM_OK);
        contacts_read("build/test_io_contacts_law.vtp", FSDEM_VTK_FORMAT_APPENDED, fsdem_dem_time(dem), &c);
        check_contacts(dem, &c, 0, 1, 0); /* GIC's stiff walls have thrown the bottom layer off */
        contacts_free(&c);
        ck_assert_int_eq(fsdem_dem_write_walls_vtp(dem, "build/test_io_walls_law.vtp", FSDEM_VTK_FORMAT_BASE64), FSDEM_OK);
        ck_assert_int_eq(fsdem_dem_write_vtp(dem, "build/test_io_dem_law.vtp", FSDEM_VTK_FORMAT_ASCII), FSDEM_OK);
        for (k = 0; k < 50; ++k) {
            ck_assert_int_eq(fsdem_dem_step(dem), FSDEM_OK);
            ck_assert_int_eq(fsdem_dem_step(twin), FSDEM_OK);
        }
        p = fsdem_dem_get_particles(dem);
        q = fsdem_dem_get_particles(twin);
        ck_assert(memcmp(p.position, q.position, sizeof(fsdem_vec3) * (size_t)p.count) == 0);
        ck_assert(memcmp(p.velocity, q.velocity, sizeof(fsdem_vec3) * (size_t)p.count) == 0);
        ck_assert(memcmp(p.angular_velocity, q.angular_velocity, sizeof(fsdem_vec3) * (size_t)p.count) == 0);
        fsdem_dem_destroy(dem);
        fsdem_dem_destroy(twin);
    }
}
END_TEST

/* Before the first step (and after edits) the lists are out of date: an empty, valid file. */
START_TEST(io_dem_contacts_empty_before_a_step) {
    fsdem_dem *dem = dem_pile(3, FSDEM_DEM_LAW_HERTZ_MINDLIN, 0.5, 0, 0.0118);
    int f;
    for (f = 0; f < 3; ++f) {
        contacts_file c;
        ck_assert_int_eq(fsdem_dem_write_contacts_vtp(dem, "build/test_io_contacts_empty.vtp", (fsdem_vtk_format)f), FSDEM_OK);
        contacts_read("build/test_io_contacts_empty.vtp", f, 0, &c);
        ck_assert_int_eq(c.n, 0);
        contacts_free(&c);
    }
    fsdem_dem_destroy(dem);
}
END_TEST

/* ---- PIC ---------------------------------------------------------------------------------------- */

static void check_pic(int dim) {
    fsdem_pic_desc desc = fsdem_pic_desc_default(dim);
    fsdem_pic *pic = NULL;
    int f;
    desc.cell_size = 0.1;
    desc.domain_max = dim == 2 ? fsdem_v3(0.8, 0.6, 0) : fsdem_v3(0.4, 0.3, 0.5);
    ck_assert_int_eq(fsdem_pic_create(&desc, &pic), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_fill_box(pic, fsdem_v3(0, 0, 0), dim == 2 ? fsdem_v3(0.3, 0.4, 0) : fsdem_v3(0.2, 0.3, 0.3),
                                        fsdem_v3(0, 0, 0), NULL),
                     FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_step(pic), FSDEM_OK);
    ck_assert_int_eq(fsdem_pic_step(pic), FSDEM_OK);
    for (f = 0; f < 3; ++f) {
        fsdem_pic_particles p = fsdem_pic_get_particles(pic);
        fsdem_pic_fields g = fsdem_pic_get_fields(pic);
        const long cells = (long)g.n[0] * g.n[1] * g.n[2];
        char path[64];
        xdoc d;
        double *e, spacing[3], origin[3];
        long c;
        int piece, a;
        snprintf(path, sizeof path, "build/test_io_pic%dd_%s.vtp", dim, FORMAT_NAME[f]);
        ck_assert_int_eq(fsdem_pic_write_particles_vtp(pic, path, (fsdem_vtk_format)f), FSDEM_OK);
        vtk_open(&d, path, "PolyData", f, fsdem_pic_time(pic));
        vtk_piece_counts(&d, p.count, p.count, 0, 0);
        ck_assert_int_eq(x_arrays_in(&d, "PointData"), 1);
        EXPECT(&d, "Points", "Points", REAL_TYPE, 3, from_vec3s(p.position, p.count), p.count);
        EXPECT(&d, "PointData", "velocity", REAL_TYPE, 3, from_vec3s(p.velocity, p.count), p.count);
        EXPECT(&d, "Verts", "offsets", "Int32", 1, from_ramp(p.count, 1, 1), p.count);
        xdoc_free(&d);

        snprintf(path, sizeof path, "build/test_io_grid%dd_%s.vti", dim, FORMAT_NAME[f]);
        ck_assert_int_eq(fsdem_pic_write_grid_vti(pic, path, (fsdem_vtk_format)f), FSDEM_OK);
        vtk_open(&d, path, "ImageData", f, fsdem_pic_time(pic));
        {
            char extent[96];
            const int image = x_find(&d, "ImageData", 0);
            snprintf(extent, sizeof extent, "0 %d 0 %d 0 %d", g.n[0], g.n[1], dim == 3 ? g.n[2] : 0);
            ck_assert_str_eq(x_attr(&d, image, "WholeExtent"), extent);
            piece = x_find(&d, "Piece", 0);
            ck_assert_str_eq(x_attr(&d, piece, "Extent"), extent);
            ck_assert_int_eq(sscanf(x_attr(&d, image, "Spacing"), "%lf %lf %lf", &spacing[0], &spacing[1], &spacing[2]), 3);
            ck_assert_int_eq(sscanf(x_attr(&d, image, "Origin"), "%lf %lf %lf", &origin[0], &origin[1], &origin[2]), 3);
            for (a = 0; a < 3; ++a) ck_assert(spacing[a] == (double)g.cell_size);
            ck_assert(origin[0] == (double)g.origin.x && origin[1] == (double)g.origin.y);
        }
        ck_assert_int_eq(x_arrays_in(&d, "CellData"), 5);
        EXPECT(&d, "CellData", "pressure", REAL_TYPE, 1, from_reals(g.pressure, cells), cells);
        EXPECT(&d, "CellData", "phi", REAL_TYPE, 1, from_reals(g.phi, cells), cells);
        EXPECT(&d, "CellData", "fraction", REAL_TYPE, 1, from_reals(g.fraction, cells), cells);
        e = (double *)malloc(sizeof(double) * (size_t)(3 * cells));
        for (c = 0; c < cells; ++c) e[c] = g.cell[c];
        EXPECT(&d, "CellData", "type", "UInt8", 1, e, cells);
        /* cell-centred velocity: the mean of the two faces along each axis */
        e = (double *)malloc(sizeof(double) * (size_t)(3 * cells));
        for (c = 0; c < cells; ++c) {
            const int i = (int)(c % g.n[0]), j = (int)(c / g.n[0] % g.n[1]), k = (int)(c / (g.n[0] * g.n[1]));
            for (a = 0; a < 3; ++a) {
                int fn[3], b, face, next;
                e[3 * c + a] = 0;
                if (a >= dim) continue;
                for (b = 0; b < 3; ++b) fn[b] = g.n[b] + (a == b);
                face = (k * fn[1] + j) * fn[0] + i;
                next = face + (a == 0 ? 1 : a == 1 ? fn[0] : fn[0] * fn[1]);
                e[3 * c + a] = (double)((g.velocity[a][face] + g.velocity[a][next]) / 2);
            }
        }
        EXPECT(&d, "CellData", "velocity", REAL_TYPE, 3, e, cells);
        xdoc_free(&d);
    }
    fsdem_pic_destroy(pic);
}

/* ---- MPS ---------------------------------------------------------------------------------------- */

static double *from_bytes(const unsigned char *p, long n) {
    double *e = (double *)malloc(sizeof(double) * (size_t)(n + 1));
    long i;
    for (i = 0; i < n; ++i) e[i] = p[i];
    return e;
}

static void check_mps(int dim) {
    fsdem_mps_desc desc = fsdem_mps_desc_default_scheme(dim, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_mps *mps = NULL;
    const fsdem_vec3 hi = dim == 2 ? fsdem_v3(0.2, 0.2, 0) : fsdem_v3(0.1, 0.1, 0.1);
    int f;
    desc.r0 = dim == 2 ? 0.02 : 0.025;
    desc.domain_min = fsdem_v3(-0.2, -0.2, -0.2);
    ck_assert_int_eq(fsdem_mps_create(&desc, &mps), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_add_box_walls(mps, fsdem_v3(0, 0, 0), hi, 1u << (dim == 2 ? FSDEM_SIDE_YMAX : FSDEM_SIDE_ZMAX), NULL),
                     FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_fill_box(mps, fsdem_v3(0, 0, 0), hi, fsdem_v3(0, 0, 0), NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_step(mps), FSDEM_OK);
    for (f = 0; f < 3; ++f) {
        fsdem_mps_particles p = fsdem_mps_get_particles(mps);
        char path[64];
        xdoc d;
        snprintf(path, sizeof path, "build/test_io_mps%dd_%s.vtp", dim, FORMAT_NAME[f]);
        ck_assert_int_eq(fsdem_mps_write_vtp(mps, path, (fsdem_vtk_format)f), FSDEM_OK);
        vtk_open(&d, path, "PolyData", f, fsdem_mps_time(mps));
        vtk_piece_counts(&d, p.count, p.count, 0, 0);
        ck_assert_int_eq(x_arrays_in(&d, "PointData"), 6);
        EXPECT(&d, "Points", "Points", REAL_TYPE, 3, from_vec3s(p.position, p.count), p.count);
        EXPECT(&d, "PointData", "kind", "UInt8", 1, from_bytes(p.kind, p.count), p.count);
        EXPECT(&d, "PointData", "surface", "UInt8", 1, from_bytes(p.surface, p.count), p.count);
        EXPECT(&d, "PointData", "pressure", REAL_TYPE, 1, from_reals(p.pressure, p.count), p.count);
        EXPECT(&d, "PointData", "velocity", REAL_TYPE, 3, from_vec3s(p.velocity, p.count), p.count);
        EXPECT(&d, "PointData", "number_density", REAL_TYPE, 1, from_reals(p.number_density, p.count), p.count);
        EXPECT(&d, "PointData", "porosity", REAL_TYPE, 1, from_reals(p.porosity, p.count), p.count);
        EXPECT(&d, "Verts", "offsets", "Int32", 1, from_ramp(p.count, 1, 1), p.count);
        xdoc_free(&d);
    }
    ck_assert_int_eq(fsdem_mps_write_vtp(NULL, "build/x.vtp", FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_mps_write_vtp(mps, "build/no/such/dir/x.vtp", FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_IO);
    ck_assert_ptr_nonnull(strstr(fsdem_mps_last_error(mps), "build/no/such/dir/x.vtp"));
    fsdem_mps_destroy(mps);
}

START_TEST(io_mps_read_back_2d) { check_mps(2); }
END_TEST

START_TEST(io_mps_read_back_3d) { check_mps(3); }
END_TEST

START_TEST(io_pic_read_back_2d) { check_pic(2); }
END_TEST

START_TEST(io_pic_read_back_3d) { check_pic(3); }
END_TEST

/* ---- SWE ---------------------------------------------------------------------------------------- */

static void swe_cells(void *user, fsdem_real x, fsdem_real y, fsdem_swe_cell *c) {
    (void)user;
    c->bed = (fsdem_real)(0.1 * x - 0.05 * y);
    c->depth = x < 0.6 ? (fsdem_real)(0.5 + 0.2 * y) : (x > 1.6 ? 0 : (fsdem_real)0.1); /* a dry strip */
    c->u = (fsdem_real)(0.2 * y);
    c->v = (fsdem_real)(-0.1 * x);
}

static void check_swe(int dim) {
    fsdem_swe_desc desc = fsdem_swe_desc_default(dim);
    fsdem_swe *swe = NULL;
    fsdem_real manning[40 * 6];
    int f, k;
    desc.nx = 40;
    desc.ny = dim == 2 ? 6 : 1;
    desc.x_min = 0;
    desc.x_max = 2;
    desc.y_min = -0.3;
    desc.y_max = 0.6;
    desc.width = 0.75;
    ck_assert_int_eq(fsdem_swe_create(&desc, &swe), FSDEM_OK);
    ck_assert_int_eq(fsdem_swe_set_cells(swe, swe_cells, NULL), FSDEM_OK);
    if (dim == 2) {
        for (k = 0; k < desc.nx * desc.ny; ++k) manning[k] = (fsdem_real)(0.01 + 0.001 * (k % 7));
        ck_assert_int_eq(fsdem_swe_set_manning(swe, manning), FSDEM_OK);
    }
    for (k = 0; k < 5; ++k) ck_assert_int_eq(fsdem_swe_step(swe), FSDEM_OK);
    for (f = 0; f < 3; ++f) {
        const fsdem_swe_fields fl = fsdem_swe_get_fields(swe);
        const fsdem_swe_grid g = fsdem_swe_get_grid(swe);
        const long n = (long)g.nx * g.ny;
        fsdem_real *u = (fsdem_real *)malloc(sizeof(fsdem_real) * (size_t)n), *v = (fsdem_real *)malloc(sizeof(fsdem_real) * (size_t)n);
        fsdem_real *h = (fsdem_real *)malloc(sizeof(fsdem_real) * (size_t)n);
        char path[64], extent[64];
        double *e, origin[3], spacing[3];
        xdoc d;
        int image;
        long i;
        snprintf(path, sizeof path, "build/test_io_swe%dd_%s.vti", dim, FORMAT_NAME[f]);
        ck_assert_int_eq(fsdem_swe_write_vti(swe, path, (fsdem_vtk_format)f), FSDEM_OK);
        vtk_open(&d, path, "ImageData", f, fsdem_swe_time(swe));
        image = x_find(&d, "ImageData", 0);
        snprintf(extent, sizeof extent, "0 %d 0 %d 0 0", g.nx, dim == 2 ? g.ny : 1);
        ck_assert_str_eq(x_attr(&d, image, "WholeExtent"), extent);
        ck_assert_str_eq(x_attr(&d, x_find(&d, "Piece", 0), "Extent"), extent);
        ck_assert_int_eq(sscanf(x_attr(&d, image, "Origin"), "%lf %lf %lf", &origin[0], &origin[1], &origin[2]), 3);
        ck_assert_int_eq(sscanf(x_attr(&d, image, "Spacing"), "%lf %lf %lf", &spacing[0], &spacing[1], &spacing[2]), 3);
        ck_assert(origin[0] == (double)g.x_min && origin[1] == (double)g.y_min && origin[2] == 0);
        ck_assert(spacing[0] == (double)g.dx && spacing[1] == (double)g.dy && spacing[2] > 0);
        if (dim == 1) ck_assert(spacing[1] == (double)desc.width);
        ck_assert_int_eq(x_arrays_in(&d, "CellData"), dim == 2 ? 5 : 4);
        ck_assert_int_eq(fsdem_swe_copy_field(swe, FSDEM_SWE_FIELD_U, u), FSDEM_OK);
        ck_assert_int_eq(fsdem_swe_copy_field(swe, FSDEM_SWE_FIELD_V, v), FSDEM_OK);
        ck_assert_int_eq(fsdem_swe_copy_field(swe, FSDEM_SWE_FIELD_DEPTH, h), FSDEM_OK);
        EXPECT(&d, "CellData", "h", REAL_TYPE, 1, from_reals(h, n), n);
        EXPECT(&d, "CellData", "eta", REAL_TYPE, 1, from_reals(fl.eta, n), n);
        EXPECT(&d, "CellData", "bed", REAL_TYPE, 1, from_reals(fl.bed, n), n);
        e = (double *)malloc(sizeof(double) * (size_t)(3 * n));
        for (i = 0; i < n; ++i) {
            e[3 * i] = (double)u[i];
            e[3 * i + 1] = (double)v[i];
            e[3 * i + 2] = 0;
        }
        EXPECT(&d, "CellData", "velocity", REAL_TYPE, 3, e, n);
        if (dim == 2) EXPECT(&d, "CellData", "manning", REAL_TYPE, 1, from_reals(manning, n), n);
        free(u);
        free(v);
        free(h);
        xdoc_free(&d);
    }
    fsdem_swe_destroy(swe);
}

START_TEST(io_swe_read_back_1d) { check_swe(1); }
END_TEST

START_TEST(io_swe_read_back_2d) { check_swe(2); }
END_TEST

/* ---- series ------------------------------------------------------------------------------------- */

/* Parses a .pvd and checks it holds `count` DataSets; returns the document. */
static void pvd_expect(xdoc *d, const char *path, int count) {
    ck_assert_msg(xdoc_read(d, path), "%s: %s", path, d->why);
    ck_assert_str_eq(x_attr(d, 0, "type"), "Collection");
    ck_assert_int_eq(x_count(d, "Collection"), 1);
    ck_assert_int_eq(x_count(d, "DataSet"), count);
}

START_TEST(io_pvd_valid_after_every_add) {
    static const char *const names[4] = {"a_0000.vtp", "grid 1.vti", "odd&<name>\"'.vtu", "sub/dir/x.vts"};
    static const double times[4] = {0, 0.1, 1.0 / 3.0, 1e300};
    fsdem_pvd pvd;
    xdoc d;
    int k;
    ck_assert_int_eq(fsdem_pvd_open(&pvd, "build/test_io_series.pvd"), FSDEM_OK);
    pvd_expect(&d, "build/test_io_series.pvd", 0);
    xdoc_free(&d);
    for (k = 0; k < 4; ++k) {
        int j;
        ck_assert_int_eq(fsdem_pvd_add(&pvd, times[k], names[k]), FSDEM_OK);
        /* valid before close: every entry so far, names as given, times to the last bit */
        pvd_expect(&d, "build/test_io_series.pvd", k + 1);
        for (j = 0; j <= k; ++j) {
            const int n = x_find(&d, "DataSet", j);
            ck_assert_str_eq(x_attr(&d, n, "file"), names[j]);
            ck_assert(strtod(x_attr(&d, n, "timestep"), NULL) == times[j]);
            ck_assert_str_eq(x_attr(&d, n, "part"), "0");
        }
        xdoc_free(&d);
    }
    /* refused, and the file stays as it was */
    ck_assert_int_eq(fsdem_pvd_add(&pvd, 2.0, "legacy.vtk"), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pvd_add(&pvd, 2.0, "series.pvd"), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pvd_add(&pvd, 2.0, "noextension"), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pvd_add(&pvd, 2.0, ".vtp"), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pvd_add(&pvd, 2.0, "x.VTP"), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pvd_add(&pvd, 2.0, "line\nbreak.vtp"), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pvd_add(&pvd, 2.0, NULL), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pvd_add(&pvd, NAN, "a.vtp"), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pvd_add(&pvd, INFINITY, "a.vtp"), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pvd_add(&pvd, -INFINITY, "a.vtp"), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pvd_add(NULL, 0, "a.vtp"), FSDEM_ERR_INVALID_ARG);
    pvd_expect(&d, "build/test_io_series.pvd", 4);
    xdoc_free(&d);
    ck_assert_int_eq(fsdem_pvd_close(&pvd), FSDEM_OK);
    pvd_expect(&d, "build/test_io_series.pvd", 4);
    xdoc_free(&d);
    ck_assert_int_eq(fsdem_pvd_add(&pvd, 3.0, "late.vtp"), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pvd_close(&pvd), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pvd_open(&pvd, "build/no/such/dir/x.pvd"), FSDEM_ERR_IO);
    ck_assert_int_eq(fsdem_pvd_open(NULL, "build/x.pvd"), FSDEM_ERR_INVALID_ARG);
}
END_TEST

/* A series of real snapshots, as an example writes it: the pieces exist and are what they claim. */
START_TEST(io_pvd_series_of_snapshots) {
    fsdem_dem *dem = dem_pile(2, FSDEM_DEM_LAW_HERTZ_MINDLIN, 0.5, 0, 0.0128);
    fsdem_pvd particles, walls;
    xdoc d;
    int frame, k;
    ck_assert_int_eq(fsdem_pvd_open(&particles, "build/test_io_particles.pvd"), FSDEM_OK);
    ck_assert_int_eq(fsdem_pvd_open(&walls, "build/test_io_walls.pvd"), FSDEM_OK);
    for (frame = 0; frame < 3; ++frame) {
        char name[64], path[80];
        snprintf(name, sizeof name, "test_io_particles_%d.vtp", frame);
        snprintf(path, sizeof path, "build/%s", name);
        ck_assert_int_eq(fsdem_dem_write_vtp(dem, path, (fsdem_vtk_format)frame), FSDEM_OK);
        ck_assert_int_eq(fsdem_pvd_add(&particles, fsdem_dem_time(dem), name), FSDEM_OK);
        snprintf(name, sizeof name, "test_io_walls_%d.vtp", frame);
        snprintf(path, sizeof path, "build/%s", name);
        ck_assert_int_eq(fsdem_dem_write_walls_vtp(dem, path, (fsdem_vtk_format)frame), FSDEM_OK);
        ck_assert_int_eq(fsdem_pvd_add(&walls, fsdem_dem_time(dem), name), FSDEM_OK);
        for (k = 0; k < 20; ++k) ck_assert_int_eq(fsdem_dem_step(dem), FSDEM_OK);
    }
    pvd_expect(&d, "build/test_io_particles.pvd", 3);
    for (k = 0; k < 3; ++k) {
        char path[80];
        xdoc piece;
        snprintf(path, sizeof path, "build/%s", x_attr(&d, x_find(&d, "DataSet", k), "file"));
        vtk_open(&piece, path, "PolyData", k, strtod(x_attr(&d, x_find(&d, "DataSet", k), "timestep"), NULL));
        xdoc_free(&piece);
    }
    xdoc_free(&d);
    ck_assert_int_eq(fsdem_pvd_close(&particles), FSDEM_OK);
    ck_assert_int_eq(fsdem_pvd_close(&walls), FSDEM_OK);
    fsdem_dem_destroy(dem);
}
END_TEST

/* ---- CSV snapshots -------------------------------------------------------------------------------- */

/* Declared in fsdem_tests.h for the couplers' tests. Reads the CSV file `path` with its own parser
   (fgets and strtod, no library code): the first line must be `header`, then exactly `rows` lines of
   as many comma-separated numbers as the header has names, equal bit for bit to `expected` (row after
   row). The writers print 17 significant digits, which strtod reads back to the same double, and a
   float build's values are exact doubles, so nothing is compared with a tolerance. */
void test_csv_expect(const char *path, const char *header, int rows, const double *expected) {
    FILE *fp = fopen(path, "r");
    char line[4096];
    int columns = 1, row = 0, k;
    const char *h;
    for (h = header; *h; ++h) columns += *h == ',';
    ck_assert_msg(fp != NULL, "%s was not written", path);
    ck_assert_msg(fgets(line, sizeof line, fp) != NULL, "%s is empty", path);
    line[strcspn(line, "\r\n")] = '\0';
    ck_assert_msg(strcmp(line, header) == 0, "%s: header '%s', expected '%s'", path, line, header);
    while (fgets(line, sizeof line, fp)) {
        char *p = line, *end;
        ck_assert_msg(row < rows, "%s: more than %d rows", path, rows);
        for (k = 0; k < columns; ++k) {
            const double v = strtod(p, &end), e = expected[(size_t)row * (size_t)columns + (size_t)k];
            ck_assert_msg(end != p, "%s row %d: column %d is not a number", path, row, k);
            ck_assert_msg(v == e || (isnan(v) && isnan(e)), "%s row %d column %d: %.17g, expected %.17g", path, row, k, v, e);
            ck_assert_msg(*end == (k + 1 < columns ? ',' : '\n'), "%s row %d: '%c' after column %d", path, row, *end, k);
            p = end + 1;
        }
        row++;
    }
    fclose(fp);
    ck_assert_msg(row == rows, "%s: %d rows, expected %d", path, row, rows);
}

/* fsdem_mps_write_csv: one row per particle of every kind, in index order, equal to the particle view
   (after a step, so pressures, number densities and surface flags are set); an unwritable path is
   FSDEM_ERR_IO with the path in the message. */
static void check_mps_csv(int dim) {
    fsdem_mps_desc desc = fsdem_mps_desc_default_scheme(dim, FSDEM_MPS_SCHEME_SEMI_IMPLICIT);
    fsdem_mps *mps = NULL;
    const fsdem_vec3 hi = dim == 2 ? fsdem_v3(0.2, 0.2, 0) : fsdem_v3(0.1, 0.1, 0.1);
    fsdem_mps_particles p;
    double *e;
    int i;
    desc.r0 = dim == 2 ? 0.02 : 0.025;
    desc.domain_min = fsdem_v3(-0.2, -0.2, -0.2);
    ck_assert_int_eq(fsdem_mps_create(&desc, &mps), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_write_csv(mps, "build/test_io_mps_empty.csv"), FSDEM_OK);
    test_csv_expect("build/test_io_mps_empty.csv", "kind,surface,x,y,z,vx,vy,vz,pressure,number_density,porosity", 0, NULL);
    ck_assert_int_eq(fsdem_mps_add_box_walls(mps, fsdem_v3(0, 0, 0), hi, 1u << (dim == 2 ? FSDEM_SIDE_YMAX : FSDEM_SIDE_ZMAX), NULL),
                     FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_fill_box(mps, fsdem_v3(0, 0, 0), hi, fsdem_v3(0.1f, 0, 0), NULL), FSDEM_OK);
    ck_assert_int_eq(fsdem_mps_step(mps), FSDEM_OK);
    p = fsdem_mps_get_particles(mps);
    e = (double *)malloc(sizeof(double) * 11 * (size_t)p.count);
    for (i = 0; i < p.count; ++i) {
        double *r = e + 11 * i;
        r[0] = p.kind[i], r[1] = p.surface[i];
        r[2] = p.position[i].x, r[3] = p.position[i].y, r[4] = p.position[i].z;
        r[5] = p.velocity[i].x, r[6] = p.velocity[i].y, r[7] = p.velocity[i].z;
        r[8] = p.pressure[i], r[9] = p.number_density[i], r[10] = p.porosity[i];
    }
    ck_assert_int_eq(fsdem_mps_write_csv(mps, "build/test_io_mps.csv"), FSDEM_OK);
    test_csv_expect("build/test_io_mps.csv", "kind,surface,x,y,z,vx,vy,vz,pressure,number_density,porosity", p.count, e);
    free(e);
    ck_assert_int_eq(fsdem_mps_write_csv(mps, "build/no/such/dir/x.csv"), FSDEM_ERR_IO);
    ck_assert_ptr_nonnull(strstr(fsdem_mps_last_error(mps), "build/no/such/dir/x.csv"));
    ck_assert_int_eq(fsdem_mps_write_csv(mps, NULL), FSDEM_ERR_INVALID_ARG);
    fsdem_mps_destroy(mps);
}

START_TEST(io_mps_csv_read_back_2d) { check_mps_csv(2); }
END_TEST

START_TEST(io_mps_csv_read_back_3d) { check_mps_csv(3); }
END_TEST

/* ---- errors ------------------------------------------------------------------------------------- */

START_TEST(io_writers_refuse_bad_arguments) {
    fsdem_dem *dem = dem_pile(3, FSDEM_DEM_LAW_HERTZ_MINDLIN, 0.5, 2, 0.0128);
    fsdem_swe_desc sd = fsdem_swe_desc_default(1);
    fsdem_pic_desc pd = fsdem_pic_desc_default(2);
    fsdem_swe *swe = NULL;
    fsdem_pic *pic = NULL;
    const fsdem_vtk_format bad = (fsdem_vtk_format)3;
    ck_assert_int_eq(fsdem_swe_create(&sd, &swe), FSDEM_OK);
    pd.domain_max = fsdem_v3(0.4, 0.4, 0);
    pd.cell_size = 0.1;
    ck_assert_int_eq(fsdem_pic_create(&pd, &pic), FSDEM_OK);
    ck_assert_int_eq(fsdem_dem_write_vtp(NULL, "build/x.vtp", FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_dem_write_walls_vtp(NULL, "build/x.vtp", FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_dem_write_contacts_vtp(NULL, "build/x.vtp", FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pic_write_particles_vtp(NULL, "build/x.vtp", FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pic_write_grid_vti(NULL, "build/x.vti", FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_swe_write_vti(NULL, "build/x.vti", FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_dem_write_csv(NULL, "build/x.csv"), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_dem_write_vtp(dem, NULL, FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_INVALID_ARG);
    ck_assert_str_eq(fsdem_dem_last_error(dem), "fsdem_dem_write_vtp: path is NULL");
    ck_assert_int_eq(fsdem_dem_write_vtp(dem, "build/x.vtp", bad), FSDEM_ERR_INVALID_ARG);
    ck_assert_str_eq(fsdem_dem_last_error(dem), "fsdem_dem_write_vtp: format 3 is not a fsdem_vtk_format");
    ck_assert_int_eq(fsdem_dem_write_walls_vtp(dem, "build/x.vtp", (fsdem_vtk_format)-1), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_dem_write_contacts_vtp(dem, NULL, FSDEM_VTK_FORMAT_BASE64), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pic_write_particles_vtp(pic, "build/x.vtp", bad), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_pic_write_grid_vti(pic, NULL, FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_INVALID_ARG);
    ck_assert_int_eq(fsdem_swe_write_vti(swe, "build/x.vti", bad), FSDEM_ERR_INVALID_ARG);
    ck_assert_str_eq(fsdem_swe_last_error(swe), "fsdem_swe_write_vti: format 3 is not a fsdem_vtk_format");
    ck_assert_int_eq(fsdem_dem_write_vtp(dem, "build/no/such/dir/x.vtp", FSDEM_VTK_FORMAT_APPENDED), FSDEM_ERR_IO);
    ck_assert_str_eq(fsdem_dem_last_error(dem), "fsdem_dem_write_vtp: cannot open 'build/no/such/dir/x.vtp' for writing");
    ck_assert_int_eq(fsdem_dem_write_walls_vtp(dem, "build/no/such/dir/x.vtp", FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_IO);
    ck_assert_int_eq(fsdem_dem_write_contacts_vtp(dem, "build/no/such/dir/x.vtp", FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_IO);
    ck_assert_int_eq(fsdem_pic_write_particles_vtp(pic, "build/no/such/dir/x.vtp", FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_IO);
    ck_assert_int_eq(fsdem_pic_write_grid_vti(pic, "build/no/such/dir/x.vti", FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_IO);
    ck_assert_int_eq(fsdem_swe_write_vti(swe, "build/no/such/dir/x.vti", FSDEM_VTK_FORMAT_ASCII), FSDEM_ERR_IO);
    ck_assert_int_eq(fsdem_dem_write_csv(dem, "build/no/such/dir/x.csv"), FSDEM_ERR_IO);
    /* a success clears the message */
    ck_assert_int_eq(fsdem_dem_write_vtp(dem, "build/test_io_ok.vtp", FSDEM_VTK_FORMAT_ASCII), FSDEM_OK);
    ck_assert_str_eq(fsdem_dem_last_error(dem), "");
    fsdem_dem_destroy(dem);
    fsdem_swe_destroy(swe);
    fsdem_pic_destroy(pic);
}
END_TEST

Suite *io_suite(void) {
    Suite *s = suite_create("io");
    TCase *tc = tcase_create("io");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, io_dem_particles_read_back_3d);
    tcase_add_test(tc, io_dem_particles_read_back_2d);
    tcase_add_test(tc, io_dem_walls_read_back_3d);
    tcase_add_test(tc, io_dem_walls_read_back_2d);
    tcase_add_test(tc, io_dem_contacts_sum_to_particle_forces_3d);
    tcase_add_test(tc, io_dem_contacts_sum_to_particle_forces_2d);
    tcase_add_test(tc, io_dem_contacts_other_laws_leave_the_object_unchanged);
    tcase_add_test(tc, io_dem_contacts_empty_before_a_step);
    tcase_add_test(tc, io_pic_read_back_2d);
    tcase_add_test(tc, io_pic_read_back_3d);
    tcase_add_test(tc, io_mps_read_back_2d);
    tcase_add_test(tc, io_mps_read_back_3d);
    tcase_add_test(tc, io_mps_csv_read_back_2d);
    tcase_add_test(tc, io_mps_csv_read_back_3d);
    tcase_add_test(tc, io_swe_read_back_1d);
    tcase_add_test(tc, io_swe_read_back_2d);
    tcase_add_test(tc, io_pvd_valid_after_every_add);
    tcase_add_test(tc, io_pvd_series_of_snapshots);
    tcase_add_test(tc, io_writers_refuse_bad_arguments);
    suite_add_tcase(s, tc);
    return s;
}
