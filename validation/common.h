/* validation/common.h - small helpers shared by the validation cases (not part of fsdem.h).

   vc_check*   print one `CHECK <case> <metric> value=<v> ref=<r> tol=<t> PASS|FAIL` line and count
               failures; vc_exit_code() is 1 when any check failed.
   vc_info     print an `INFO <case> ...` line (figures worth reporting that are not checks).
   vc_table    a reference CSV from validation/data: `#` comment lines are skipped, the first other
               line is the header, fields may be double-quoted (and then hold commas).
   vc_data_dir the folder of the reference data: argv[1] when given, otherwise VC_DATA_DIR (the
               Makefile defines it as the absolute path of validation/data; without it, the path of
               validation/data seen from build/validation/<case>/, where `make validate` runs a case).
   vc_path     joins a directory and a file name. */
#ifndef FSDEM_VALIDATION_COMMON_H
#define FSDEM_VALIDATION_COMMON_H

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int vc_failures = 0;

/* PASS when |value - ref| <= tol (tol is absolute, in the metric's unit). */
static inline int vc_check(const char *case_name, const char *metric, double value, double ref, double tol) {
    int pass = isfinite(value) && fabs(value - ref) <= tol;
    printf("CHECK %s %s value=%.6g ref=%.6g tol=%.3g %s\n", case_name, metric, value, ref, tol,
           pass ? "PASS" : "FAIL");
    fflush(stdout);
    if (!pass) vc_failures++;
    return pass;
}

/* PASS when |value - ref| <= rel |ref|; the printed tol is the absolute one. */
static inline int vc_check_rel(const char *case_name, const char *metric, double value, double ref, double rel) {
    return vc_check(case_name, metric, value, ref, rel * fabs(ref));
}

static inline void vc_info(const char *case_name, const char *fmt, ...) {
    va_list ap;
    printf("INFO %s ", case_name);
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
    printf("\n");
    fflush(stdout);
}

static inline int vc_exit_code(void) { return vc_failures ? 1 : 0; }

#ifndef VC_DATA_DIR
#define VC_DATA_DIR "../../../validation/data"
#endif

static inline const char *vc_data_dir(int argc, char **argv) {
    return argc > 1 && argv[1][0] ? argv[1] : VC_DATA_DIR;
}

static inline const char *vc_path(char *buf, size_t size, const char *dir, const char *file) {
    snprintf(buf, size, "%s/%s", dir, file);
    return buf;
}

typedef struct vc_table {
    int rows, cols;
    char **head; /* cols names */
    char **cell; /* rows * cols fields; missing fields are "" */
} vc_table;

/* Splits one line in place into at most `max` fields; returns the number found. */
static inline int vc__split(char *line, char **field, int max) {
    int n = 0;
    char *r = line, *w;
    while (n < max) {
        int quoted = *r == '"';
        if (quoted) r++;
        field[n++] = w = r;
        for (;;) {
            if (*r == '\0' || *r == '\n' || *r == '\r') {
                *w = '\0';
                return n;
            }
            if (quoted && *r == '"') {
                if (r[1] == '"') { *w++ = '"'; r += 2; continue; } /* doubled quote */
                quoted = 0;
                r++;
                continue;
            }
            if (!quoted && *r == ',') {
                *w = '\0';
                r++;
                break;
            }
            *w++ = *r++;
        }
    }
    return n;
}

static inline char *vc__strdup(const char *s) {
    size_t len = strlen(s) + 1;
    char *c = (char *)malloc(len);
    if (c) memcpy(c, s, len);
    return c;
}

static inline void vc_table_free(vc_table *t) {
    int k;
    for (k = 0; k < t->cols; ++k) free(t->head[k]);
    for (k = 0; k < t->rows * t->cols; ++k) free(t->cell[k]);
    free(t->head);
    free(t->cell);
    memset(t, 0, sizeof *t);
}

/* Loads a reference CSV; returns 0 on success, -1 (with a message on stderr) otherwise. */
static inline int vc_table_load(vc_table *t, const char *path) {
    enum { MAX_FIELDS = 64 };
    char line[8192], *field[MAX_FIELDS];
    FILE *fp = fopen(path, "r");
    int n, k, cap = 0;
    memset(t, 0, sizeof *t);
    if (!fp) {
        fprintf(stderr, "cannot open reference file %s\n", path);
        return -1;
    }
    while (fgets(line, sizeof line, fp)) {
        if (line[0] == '#' || line[0] == '\n' || line[0] == '\r') continue;
        n = vc__split(line, field, MAX_FIELDS);
        if (!t->head) {
            t->cols = n;
            t->head = (char **)calloc((size_t)n, sizeof(char *));
            for (k = 0; k < n; ++k) t->head[k] = vc__strdup(field[k]);
            continue;
        }
        if (t->rows == cap) {
            cap = cap ? 2 * cap : 64;
            t->cell = (char **)realloc(t->cell, sizeof(char *) * (size_t)cap * (size_t)t->cols);
        }
        for (k = 0; k < t->cols; ++k) t->cell[t->rows * t->cols + k] = vc__strdup(k < n ? field[k] : "");
        t->rows++;
    }
    fclose(fp);
    if (!t->head) {
        fprintf(stderr, "reference file %s has no header\n", path);
        return -1;
    }
    return 0;
}

/* Column index of `name`, or -1 (with a message on stderr). */
static inline int vc_table_col(const vc_table *t, const char *name) {
    int k;
    for (k = 0; k < t->cols; ++k)
        if (strcmp(t->head[k], name) == 0) return k;
    fprintf(stderr, "reference table has no column '%s'\n", name);
    return -1;
}

static inline const char *vc_table_str(const vc_table *t, int row, int col) {
    return row >= 0 && row < t->rows && col >= 0 && col < t->cols ? t->cell[row * t->cols + col] : "";
}

/* Leading number of a field ("10 each (head-on)" gives 10), NaN when there is none. */
static inline double vc_table_num(const vc_table *t, int row, int col) {
    const char *s = vc_table_str(t, row, col);
    char *end;
    double v = strtod(s, &end);
    return end == s ? NAN : v;
}

#endif
