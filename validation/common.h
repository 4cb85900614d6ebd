/* validation/common.h - small helpers shared by the validation cases (not part of fsdem.h).

   A case's main starts with vc_begin, chooses its resolution from the tier, and announces it:

       int main(int argc, char **argv) {
           int n;
           vc_begin(CASE, argc, argv, NULL);           // --tier=default|full, the data folder
           n = vc_option_int("--cells", vc_full() ? 40 : 20); // the tiers' resolutions, in one place
           vc_tier("dx = a/%d", n);                     // TIER line; rejects unknown arguments
           ...
           return vc_exit_code();                       // the TIME line is printed at exit
       }

   Command line of every case: run [DATA_DIR] [--tier=default|full] [case options]. DATA_DIR is the
   first argument when it does not start with "-" (otherwise VC_DATA_DIR); case options are
   --name=value or --name value (vc_option*) and --name (vc_flag); an argument no call read is an
   error (vc_tier exits with status 2 and says which).

   vc_begin    parses --tier and the data folder, prints nothing yet; `full_alias` (or NULL) names
               the case's older flag for its full-tier resolution ("--seed", "--fine", "--all"), which
               then means --tier=full.
   vc_full     1 in the full tier (the seeds' resolutions and the fine runs, `make validate-full`), 0
               in the default one (`make validate`, the whole tier within 20 minutes on 2 cores).
   vc_tier     prints `TIER <case> tier=<default|full> resolution=<text>`; from then on, `TIME <case>
               cpu_s=<x>` (CPU of the process, clock()) is printed when the program exits.
   vc_check*   print one `CHECK <case> <metric> value=<v> ref=<r> tol=<t> PASS|FAIL` line and count
               failures; vc_exit_code() is 1 when any check failed.
   vc_check_full*  the same in the full tier; in the default tier the line is printed as `INFO <case>
               <metric> value=<v> ref=<r> tol=<t> (full tier)`, never PASS nor FAIL, and counts as
               nothing. Only for lines that need the fine run (a convergence, "at the seed's
               resolution"); the case README says why, with the default tier's figures.
   vc_info     print an `INFO <case> ...` line (figures worth reporting that are not checks).
   vc_table    a reference CSV from validation/data: `#` comment lines are skipped, the first other
               line is the header, fields may be double-quoted (and then hold commas).
   vc_data_dir the folder of the reference data: the DATA_DIR argument when given, otherwise
               VC_DATA_DIR (the Makefile defines it as the absolute path of validation/data; without
               it, the path of validation/data seen from build/validation/<case>/, where `make
               validate` runs a case).
   vc_path     joins a directory and a file name.

   Building one case by hand (what the Makefile does): the implementation is compiled once, the case
   includes fsdem.h without FSDEM_IMPLEMENTATION and links against it:
       cc -std=c99 -O2 -I. -c validation/fsdem_impl.c -o fsdem_impl.o
       cc -std=c99 -O2 -I. -Ivalidation validation/<case>/main.c fsdem_impl.o -lm -o run
       ./run validation/data                  (or --tier=full) */
#ifndef FSDEM_VALIDATION_COMMON_H
#define FSDEM_VALIDATION_COMMON_H

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

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

/* ---- tiers and the command line ---- */

#ifndef VC_DATA_DIR
#define VC_DATA_DIR "../../../validation/data"
#endif

#define VC_MAX_ARGS 64

static struct {
    const char *case_name, *data_dir;
    int full, argc, announced;
    char **argv;
    unsigned char used[VC_MAX_ARGS];
} vc__run;

static inline void vc__time(void) {
    printf("TIME %s cpu_s=%.1f\n", vc__run.case_name, (double)clock() / CLOCKS_PER_SEC);
    fflush(stdout);
}

static inline void vc__usage(const char *why, const char *arg) {
    fprintf(stderr, "%s: %s%s\nusage: run [DATA_DIR] [--tier=default|full] [options of the case: see its README.md]\n",
            vc__run.case_name, why, arg);
    exit(2);
}

/* Index of the argument `--name` or `--name=value` (the last one given), or 0. */
static inline int vc__find(const char *name) {
    const size_t len = strlen(name);
    int a, found = 0;
    for (a = 1; a < vc__run.argc; ++a)
        if (!strncmp(vc__run.argv[a], name, len) && (vc__run.argv[a][len] == '\0' || vc__run.argv[a][len] == '='))
            found = a;
    return found;
}

static inline void vc_begin(const char *case_name, int argc, char **argv, const char *full_alias) {
    int a;
    const char *tier;
    memset(&vc__run, 0, sizeof vc__run);
    vc__run.case_name = case_name;
    vc__run.argc = argc;
    vc__run.argv = argv;
    if (argc > VC_MAX_ARGS) vc__usage("too many arguments", "");
    vc__run.data_dir = VC_DATA_DIR;
    if (argc > 1 && argv[1][0] != '-') {
        if (argv[1][0]) vc__run.data_dir = argv[1];
        vc__run.used[1] = 1;
    }
    if ((a = vc__find("--tier")) != 0) {
        tier = argv[a][6] == '=' ? argv[a] + 7 : "";
        if (!strcmp(tier, "full")) vc__run.full = 1;
        else if (strcmp(tier, "default")) vc__usage("--tier takes default or full, not ", argv[a]);
        for (a = 1; a < argc; ++a)
            if (!strncmp(argv[a], "--tier=", 7)) vc__run.used[a] = 1;
    }
    if (full_alias && (a = vc__find(full_alias)) != 0 && argv[a][strlen(full_alias)] == '\0') {
        vc__run.full = 1;
        vc__run.used[a] = 1;
    }
}

static inline int vc_full(void) { return vc__run.full; }

/* 1 when the flag `--name` is given. */
static inline int vc_flag(const char *name) {
    const int a = vc__find(name);
    if (a && vc__run.argv[a][strlen(name)] == '=') vc__usage("this option takes no value: ", vc__run.argv[a]);
    if (a) vc__run.used[a] = 1;
    return a != 0;
}

/* The value of `--name=value` or `--name value`, or NULL when the option is not given. */
static inline const char *vc_option(const char *name) {
    const int a = vc__find(name);
    const size_t len = strlen(name);
    if (!a) return NULL;
    vc__run.used[a] = 1;
    if (vc__run.argv[a][len] == '=') return vc__run.argv[a] + len + 1;
    if (a + 1 >= vc__run.argc) vc__usage("a value is missing after ", vc__run.argv[a]);
    vc__run.used[a + 1] = 1;
    return vc__run.argv[a + 1];
}

static inline double vc__number(const char *name, const char *text) {
    char *end;
    const double v = strtod(text, &end);
    if (end == text || *end) {
        fprintf(stderr, "%s: %s takes a number, not '%s'\n", vc__run.case_name, name, text);
        exit(2);
    }
    return v;
}

static inline double vc_option_num(const char *name, double fallback) {
    const char *v = vc_option(name);
    return v ? vc__number(name, v) : fallback;
}

static inline int vc_option_int(const char *name, int fallback) {
    const char *v = vc_option(name);
    return v ? (int)vc__number(name, v) : fallback;
}

/* Prints the TIER line (the resolution, printf-style) and arranges the TIME line at exit; an
   argument that no vc_flag / vc_option call has read ends the program with status 2. */
static inline void vc_tier(const char *fmt, ...) {
    va_list ap;
    int a;
    for (a = 1; a < vc__run.argc; ++a)
        if (!vc__run.used[a]) vc__usage("unknown argument ", vc__run.argv[a]);
    printf("TIER %s tier=%s resolution=", vc__run.case_name, vc__run.full ? "full" : "default");
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
    printf("\n");
    fflush(stdout);
    if (!vc__run.announced) atexit(vc__time);
    vc__run.announced = 1;
}

/* A check that needs the full tier's resolution: a CHECK there, an INFO line in the default tier. */
static inline int vc_check_full(const char *case_name, const char *metric, double value, double ref, double tol) {
    if (vc__run.full) return vc_check(case_name, metric, value, ref, tol);
    printf("INFO %s %s value=%.6g ref=%.6g tol=%.3g (full tier)\n", case_name, metric, value, ref, tol);
    fflush(stdout);
    return 1;
}

static inline int vc_check_full_rel(const char *case_name, const char *metric, double value, double ref, double rel) {
    return vc_check_full(case_name, metric, value, ref, rel * fabs(ref));
}

/* The data folder: DATA_DIR when given to vc_begin, VC_DATA_DIR otherwise. */
static inline const char *vc_data_dir(void) { return vc__run.data_dir ? vc__run.data_dir : VC_DATA_DIR; }

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
