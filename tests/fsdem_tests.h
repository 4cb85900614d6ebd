/* Shared declarations of the Check suite: one suite per module, and small helpers. */
#ifndef FSDEM_TESTS_H
#define FSDEM_TESTS_H
#include <check.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fsdem.h"

Suite *core_suite(void);
Suite *dem_suite(void);
Suite *linalg_suite(void);
Suite *pic_suite(void);
Suite *swe_suite(void);
Suite *couple_swe_suite(void);
Suite *interface_suite(void);
Suite *restart_suite(void);
Suite *robustness_suite(void);
Suite *io_suite(void);
Suite *mps_suite(void);
Suite *drag_suite(void);
Suite *couple_mps_suite(void);
Suite *couple_pic_suite(void);
Suite *couple_gic_suite(void);
Suite *couple_suite(void);
Suite *probing_suite(void);
Suite *dem_contact_suite(void);
Suite *dem_periodic_suite(void);
Suite *mps_periodic_suite(void);

/* Steps two MPS solvers `steps` times and asserts the same particles, positions and pressures, bit
   for bit (tests/test_mps.c). */
void test_same_run(fsdem_mps *a, fsdem_mps *b, int steps);

/* ---- tolerances that follow the precision of fsdem_real ----

   The suite runs in double (`make test`) and in float (`make test-float`, -DFSDEM_USE_FLOAT). A
   tolerance is either physics or method (a discretisation error, a convergence order, a bound on
   a transient), which does not depend on the precision, or rounding, which does. Rounding bounds
   are written as
       TOL(tol, k) = max(tol, k * TEST_EPS)
   where `tol` is the bound of the double build and k * TEST_EPS the same kind of bound in units of
   the machine epsilon of fsdem_real: k counts the roundings that accumulate in the checked value,
   relative to its scale (for an absolute bound k carries the scale: TOL(1e-14, 4 * 0.3) is 4 eps of
   a 0.3 m depth), with the reason next to each use. In double TOL returns `tol` unchanged
   (the check below fails the test if k * DBL_EPSILON would exceed it, so no double tolerance is
   ever loosened by this helper); in float k * FLT_EPSILON (1.2e-7 per unit of k) usually wins.
   A check whose only error is rounding in both builds writes k * TEST_EPS directly. Tolerances of a
   solver (a relative residual) follow the precision through the solver's own float defaults (the
   pressure and pcg tolerances are 1e-5 in float). */
#ifdef FSDEM_USE_FLOAT
#define TEST_FLOAT 1
#define TEST_EPS ((double)FLT_EPSILON)
#else
#define TEST_FLOAT 0
#define TEST_EPS DBL_EPSILON
#endif

static inline double test_tol(double tol, double k, const char *file, int line) {
    const double e = k * TEST_EPS;
    ck_assert_msg(TEST_FLOAT || e <= tol, "%s:%d: TOL(%g, %g): %g eps exceeds the double tolerance", file, line, tol,
                  k, k);
    return e > tol ? e : tol;
}
#define TOL(tol, k) test_tol((tol), (k), __FILE__, __LINE__)

/* Prints the measured figures of a test when FSDEM_TEST_VERBOSE is set (and not "0"). */
#define TEST_REPORT(...)                                                                           \
    do {                                                                                           \
        const char *test_verbose_ = getenv("FSDEM_TEST_VERBOSE");                                  \
        if (test_verbose_ && test_verbose_[0] && test_verbose_[0] != '0') {                        \
            printf("  [%s] ", __func__);                                                           \
            printf(__VA_ARGS__);                                                                   \
            putchar('\n');                                                                         \
            fflush(stdout);                                                                        \
        }                                                                                          \
    } while (0)

/* True when FSDEM_TEST_LIGHT is set (and not "0"), as `make valgrind` sets it: the heavy tests are
   sized down (fewer steps, shorter runs, fewer cases, coarser grids) so that memory checking covers
   every test and code path in minutes. Each such test says next to its "(light: ...)" comment what
   it asserts at that size, which is what still holds there; without the switch every test runs at
   its full size with its full assertions. */
static inline int test_light(void) {
    const char *light = getenv("FSDEM_TEST_LIGHT");
    return light && light[0] && light[0] != '0';
}

/* Reads a CSV snapshot written by a fsdem_X_write_csv (tests/test_io.c): its header line must be
   `header`, then exactly `rows` rows equal bit for bit to `expected` (row-major, the header's column
   count per row; may be NULL when rows is 0). */
void test_csv_expect(const char *path, const char *header, int rows, const double *expected);

/* The whole state of a coupler: its saved bytes (its fsdem_X_save_memory, the fluid and the DEM
   with them) and the counts of its fsdem_coupling_stats (CPU times are not state). TEST_KEEP(save,
   c, stats, &kept) takes it; test_kept_same(&before, &after, what) asserts that nothing changed and
   frees both. */
typedef struct test_kept {
    unsigned char *bytes;
    size_t size;
    fsdem_coupling_stats stats;
} test_kept;

#define TEST_KEEP(save, c, coupling_stats, kept)                                                   \
    do {                                                                                           \
        size_t need_ = 0;                                                                          \
        ck_assert_int_eq(save((c), NULL, 0, &need_), FSDEM_OK);                                    \
        (kept)->bytes = (unsigned char *)malloc(need_);                                            \
        ck_assert_ptr_nonnull((kept)->bytes);                                                      \
        ck_assert_int_eq(save((c), (kept)->bytes, need_, &(kept)->size), FSDEM_OK);                \
        (kept)->stats = (coupling_stats);                                                          \
    } while (0)

static inline void test_kept_same(test_kept *before, test_kept *after, const char *what) {
    const fsdem_coupling_stats a = before->stats, b = after->stats;
    ck_assert_msg(before->size == after->size && memcmp(before->bytes, after->bytes, before->size) == 0, "%s: the state changed", what);
    ck_assert_msg(a.steps == b.steps && a.time == b.time && a.dt == b.dt && a.substeps == b.substeps && a.substeps_total == b.substeps_total,
                  "%s: the statistics changed", what);
    free(before->bytes);
    free(after->bytes);
}

/* The bytes of file `path` now (malloc'ed, *size of them); a gauge file open for writing reads as
   written so far (the series flushes every row). */
static inline unsigned char *test_file_bytes(const char *path, size_t *size) {
    FILE *fp = fopen(path, "rb");
    unsigned char *bytes = NULL;
    long n;
    ck_assert_ptr_nonnull(fp);
    ck_assert(fseek(fp, 0, SEEK_END) == 0 && (n = ftell(fp)) >= 0 && fseek(fp, 0, SEEK_SET) == 0);
    bytes = (unsigned char *)malloc((size_t)n + 1);
    ck_assert_ptr_nonnull(bytes);
    ck_assert(fread(bytes, 1, (size_t)n, fp) == (size_t)n);
    fclose(fp);
    *size = (size_t)n;
    return bytes;
}

/* Asserts that file `path` holds the `size` bytes `expected` now (grown = 1: begins with them and
   is longer). */
static inline void test_file_is(const char *path, const unsigned char *expected, size_t size, int grown, const char *what) {
    size_t now = 0;
    unsigned char *bytes = test_file_bytes(path, &now);
    ck_assert_msg((grown ? now > size : now == size) && memcmp(bytes, expected, size) == 0, "%s: %s has %lu bytes, %s %lu", what, path,
                  (unsigned long)now, grown ? "expected more than" : "expected", (unsigned long)size);
    free(bytes);
}

/* True when every component is finite. */
static inline int test_finite3(fsdem_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

#endif
