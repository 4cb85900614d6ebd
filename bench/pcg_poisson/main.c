/* PCG on the Poisson equation: -lap(u) = 1 on the unit square / cube, homogeneous Dirichlet
   boundaries, standard 5-point (2D) / 7-point (3D) stencil on n^2 / n^3 interior unknowns, the
   rows scaled by h^2 (so b = h^2, h = 1/(n+1)), initial guess 0, stop at ||r||_2/||b||_2 < 1e-8.
   The same problems are solved with hypre's PCG + BoomerAMG by hypre_poisson.c (see README.md).

   Timed (wall clock): fsdem_pcg_setup_stencil (workspace allocation and first touch, coarse
   levels, factorisation) + fsdem_pcg_solve on a fresh solver object; the right-hand side is built
   before the clock starts. Each preconditioner runs `repeats` times (argument 1, default 3) and
   the fastest run is printed:

     BENCH pcg_poisson_<2d|3d>_<precond> time_s=<setup+solve> iters=<n> setup_s=... solve_s=...
           resetup_s=<setup again on the same object, memory reused> memory_mb=... relres=...

   on one thread, and for multigrid the same on two (a build with OpenMP, as `make bench` builds):

     BENCH pcg_poisson_<2d|3d>_mg_2t threads=2 ranks=1 time_s=... speedup_2t=<ratio>

   then the iteration counts of every preconditioner over a sweep of grid sizes:

     BENCH pcg_poisson_sweep_<2d|3d> n=<n> iters_none=... iters_jacobi=... iters_ic0=...
           iters_mic0=... iters_mg=...

   Argument 2 `quick` shrinks the problems (256^2, 64^3) for a fast look. */
#define _POSIX_C_SOURCE 199309L
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double wall(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static const char *precond_name(fsdem_precond p) {
    switch (p) {
    case FSDEM_PRECOND_NONE: return "none";
    case FSDEM_PRECOND_JACOBI: return "jacobi";
    case FSDEM_PRECOND_IC0: return "ic0";
    case FSDEM_PRECOND_MIC0: return "mic0";
    case FSDEM_PRECOND_MG: return "mg";
    default: return "auto";
    }
}

typedef struct run_result {
    double setup_s, solve_s, resetup_s, relres;
    int iters;
    size_t memory;
    fsdem_result status;
} run_result;

/* One cold run: create, setup, solve (timed), then a warm re-setup (timed separately). */
static run_result run_once(int dim, int n, fsdem_precond pc, const fsdem_real *b, fsdem_real *x, fsdem_real *y) {
    fsdem_stencil st;
    fsdem_pcg_desc d = fsdem_pcg_desc_default();
    fsdem_pcg *s = NULL;
    fsdem_pcg_info info;
    run_result r;
    int cells = dim == 3 ? n * n * n : n * n, i;
    double t0, t1, t2, rr = 0, bb = 0;
    memset(&r, 0, sizeof r);
    memset(&st, 0, sizeof st);
    st.dim = dim;
    st.n[0] = st.n[1] = st.n[2] = n;
    d.preconditioner = pc;
    d.tolerance = 1e-8;
    d.max_iterations = 100000;
    memset(x, 0, sizeof(fsdem_real) * (size_t)cells);
    if (fsdem_pcg_create(&d, &s) != FSDEM_OK) {
        r.status = FSDEM_ERR_OUT_OF_MEMORY;
        return r;
    }
    t0 = wall();
    r.status = fsdem_pcg_setup_stencil(s, &st);
    t1 = wall();
    if (r.status == FSDEM_OK) r.status = fsdem_pcg_solve(s, b, x, &info);
    t2 = wall();
    r.setup_s = t1 - t0;
    r.solve_s = t2 - t1;
    r.iters = info.iterations;
    r.memory = info.memory_bytes;
    t0 = wall();
    fsdem_pcg_setup_stencil(s, &st);
    r.resetup_s = wall() - t0;
    fsdem_pcg_destroy(s);
    /* independent check of the answer with the reference product */
    fsdem_stencil_apply(&st, x, y);
    for (i = 0; i < cells; ++i) {
        rr += ((double)b[i] - y[i]) * ((double)b[i] - y[i]);
        bb += (double)b[i] * b[i];
    }
    r.relres = sqrt(rr / bb);
    return r;
}

/* The fastest of `repeats` cold runs on `threads` threads. */
static run_result run_best(int dim, int n, fsdem_precond pc, const fsdem_real *b, fsdem_real *x, fsdem_real *y, int repeats,
                           int threads) {
    run_result best;
    int k;
    fsdem_set_threads(threads);
    memset(&best, 0, sizeof best);
    for (k = 0; k < repeats; ++k) {
        run_result r = run_once(dim, n, pc, b, x, y);
        if (k == 0 || r.setup_s + r.solve_s < best.setup_s + best.solve_s) best = r;
    }
    fsdem_set_threads(1);
    return best;
}

int main(int argc, char **argv) {
    static const fsdem_precond pcs[5] = {FSDEM_PRECOND_NONE, FSDEM_PRECOND_JACOBI, FSDEM_PRECOND_IC0,
                                         FSDEM_PRECOND_MIC0, FSDEM_PRECOND_MG};
    int repeats = argc > 1 ? atoi(argv[1]) : 3, quick = argc > 2 && strcmp(argv[2], "quick") == 0;
    int dim, status = 0;
    if (repeats < 1) repeats = 1;
    fsdem_set_threads(1);
    for (dim = 2; dim <= 3; ++dim) {
        int n_big = dim == 2 ? (quick ? 256 : 512) : (quick ? 64 : 128);
        int n_small = dim == 2 ? 64 : 32, cells = dim == 3 ? n_big * n_big * n_big : n_big * n_big, p, n, i;
        int sweep[5][8];
        fsdem_real *b = (fsdem_real *)malloc(sizeof(fsdem_real) * (size_t)cells);
        fsdem_real *x = (fsdem_real *)malloc(sizeof(fsdem_real) * (size_t)cells);
        fsdem_real *y = (fsdem_real *)malloc(sizeof(fsdem_real) * (size_t)cells);
        if (!b || !x || !y) return 1;
        /* headline: the largest size, best of `repeats` */
        for (p = 0; p < 5; ++p) {
            run_result best;
            double h = 1.0 / (n_big + 1);
            if (pcs[p] == FSDEM_PRECOND_NONE) continue;
            for (i = 0; i < cells; ++i) b[i] = (fsdem_real)(h * h);
            best = run_best(dim, n_big, pcs[p], b, x, y, repeats, 1);
            printf("BENCH pcg_poisson_%dd_%s time_s=%.4f iters=%d setup_s=%.4f solve_s=%.4f resetup_s=%.4f "
                   "memory_mb=%.1f relres=%.2e n=%d%s\n",
                   dim, precond_name(pcs[p]), best.setup_s + best.solve_s, best.iters, best.setup_s, best.solve_s,
                   best.resetup_s, (double)best.memory / 1e6, best.relres, n_big,
                   best.status == FSDEM_OK ? "" : " FAILED");
            fflush(stdout);
            if (best.status != FSDEM_OK) status = 1;
            if (pcs[p] == FSDEM_PRECOND_MG) { /* the same solve on two threads (a build with OpenMP) */
                run_result two;
                fsdem_set_threads(2);
                if (fsdem_threads() < 2) {
                    printf("BENCH pcg_poisson_%dd_mg speedup_2t=n/a (built without OpenMP)\n", dim);
                    continue;
                }
                two = run_best(dim, n_big, pcs[p], b, x, y, repeats, 2);
                printf("BENCH pcg_poisson_%dd_mg_2t threads=2 ranks=1 time_s=%.4f iters=%d setup_s=%.4f solve_s=%.4f "
                       "speedup_2t=%.2f (setup + solve; solve alone %.2f)\n",
                       dim, two.setup_s + two.solve_s, two.iters, two.setup_s, two.solve_s,
                       (best.setup_s + best.solve_s) / (two.setup_s + two.solve_s), best.solve_s / two.solve_s);
                fflush(stdout);
            }
        }
        /* iteration counts over grid sizes */
        for (n = n_small, i = 0; n <= n_big; n *= 2, ++i) {
            int c = dim == 3 ? n * n * n : n * n, q;
            double h = 1.0 / (n + 1);
            for (q = 0; q < c; ++q) b[q] = (fsdem_real)(h * h);
            for (p = 0; p < 5; ++p) {
                run_result r = run_once(dim, n, pcs[p], b, x, y);
                sweep[p][i] = r.status == FSDEM_OK ? r.iters : -1;
            }
            printf("BENCH pcg_poisson_sweep_%dd n=%d iters_none=%d iters_jacobi=%d iters_ic0=%d iters_mic0=%d "
                   "iters_mg=%d\n",
                   dim, n, sweep[0][i], sweep[1][i], sweep[2][i], sweep[3][i], sweep[4][i]);
            fflush(stdout);
        }
        free(b);
        free(x);
        free(y);
    }
    return status;
}
