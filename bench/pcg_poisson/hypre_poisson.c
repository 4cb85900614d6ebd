/* The pcg_poisson problems solved with hypre's PCG preconditioned by BoomerAMG, for comparison
   with fsdem's MGPCG (see README.md here). Not built by `make bench`:

       mpicc -O2 -I/usr/include/hypre bench/pcg_poisson/hypre_poisson.c -o build/bench/hypre_poisson -lHYPRE -lm
       OMP_NUM_THREADS=1 build/bench/hypre_poisson          (one MPI rank, one thread)

   Problems: -lap(u) = 1 on the unit square (512^2 interior unknowns, 5-point stencil) and the unit
   cube (128^3, 7-point), homogeneous Dirichlet boundaries, the stencil scaled by h^2 so the rows
   read 4u - sum(neighbours) = h^2 (2D) and 6u - sum = h^2 (3D) with h = 1/(n+1); initial guess 0;
   stop at ||r||_2 / ||b||_2 < 1e-8 (HYPRE_PCGSetTwoNorm). Timed: HYPRE_ParCSRPCGSetup (BoomerAMG
   setup) plus HYPRE_ParCSRPCGSolve; assembly is not timed. Each configuration runs `repeats` times
   (argument 1, default 3) and the fastest run is printed as
       BENCH hypre_pcg_boomeramg_<2d|3d>_<config> time_s=<setup+solve> iters=<n> setup_s=... solve_s=...
   Configurations: `default` (hypre 2.26 defaults: HMIS coarsening, extended+i interpolation,
   hybrid Gauss-Seidel down/up, strong threshold 0.25), `st05` (the same with strong threshold
   0.5, hypre's advice for 3D Laplacians) and `falgout` (Falgout coarsening, classical
   interpolation, symmetric hybrid Gauss-Seidel, as in hypre's example 5). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <mpi.h>
#include "HYPRE.h"
#include "HYPRE_krylov.h"
#include "HYPRE_parcsr_ls.h"

typedef struct problem {
    int dim, n, rows;
    HYPRE_IJMatrix A;
    HYPRE_ParCSRMatrix parA;
    HYPRE_IJVector b, x;
    HYPRE_ParVector parb, parx;
} problem;

static void assemble(problem *p, int dim, int n) {
    int rows = dim == 2 ? n * n : n * n * n, r;
    double h = 1.0 / (n + 1);
    p->dim = dim;
    p->n = n;
    p->rows = rows;
    HYPRE_IJMatrixCreate(MPI_COMM_WORLD, 0, rows - 1, 0, rows - 1, &p->A);
    HYPRE_IJMatrixSetObjectType(p->A, HYPRE_PARCSR);
    HYPRE_IJMatrixInitialize(p->A);
    for (r = 0; r < rows; ++r) {
        int i = r % n, j = (r / n) % n, k = dim == 3 ? r / (n * n) : 0;
        HYPRE_Int cols[7], ncols = 0, row = r;
        double vals[7];
        cols[ncols] = r;
        vals[ncols++] = 2.0 * dim;
        if (i > 0) { cols[ncols] = r - 1; vals[ncols++] = -1; }
        if (i < n - 1) { cols[ncols] = r + 1; vals[ncols++] = -1; }
        if (j > 0) { cols[ncols] = r - n; vals[ncols++] = -1; }
        if (j < n - 1) { cols[ncols] = r + n; vals[ncols++] = -1; }
        if (dim == 3 && k > 0) { cols[ncols] = r - n * n; vals[ncols++] = -1; }
        if (dim == 3 && k < n - 1) { cols[ncols] = r + n * n; vals[ncols++] = -1; }
        HYPRE_IJMatrixSetValues(p->A, 1, &ncols, &row, cols, vals);
    }
    HYPRE_IJMatrixAssemble(p->A);
    HYPRE_IJMatrixGetObject(p->A, (void **)&p->parA);

    HYPRE_IJVectorCreate(MPI_COMM_WORLD, 0, rows - 1, &p->b);
    HYPRE_IJVectorSetObjectType(p->b, HYPRE_PARCSR);
    HYPRE_IJVectorInitialize(p->b);
    HYPRE_IJVectorCreate(MPI_COMM_WORLD, 0, rows - 1, &p->x);
    HYPRE_IJVectorSetObjectType(p->x, HYPRE_PARCSR);
    HYPRE_IJVectorInitialize(p->x);
    {
        HYPRE_Int *idx = (HYPRE_Int *)malloc(sizeof(HYPRE_Int) * (size_t)rows);
        double *bv = (double *)malloc(sizeof(double) * (size_t)rows);
        double *xv = (double *)calloc((size_t)rows, sizeof(double));
        for (r = 0; r < rows; ++r) {
            idx[r] = r;
            bv[r] = h * h;
        }
        HYPRE_IJVectorSetValues(p->b, rows, idx, bv);
        HYPRE_IJVectorSetValues(p->x, rows, idx, xv);
        free(idx);
        free(bv);
        free(xv);
    }
    HYPRE_IJVectorAssemble(p->b);
    HYPRE_IJVectorGetObject(p->b, (void **)&p->parb);
    HYPRE_IJVectorAssemble(p->x);
    HYPRE_IJVectorGetObject(p->x, (void **)&p->parx);
}

static void reset_x(problem *p) {
    HYPRE_ParVectorSetConstantValues(p->parx, 0.0);
}

static void destroy(problem *p) {
    HYPRE_IJMatrixDestroy(p->A);
    HYPRE_IJVectorDestroy(p->b);
    HYPRE_IJVectorDestroy(p->x);
}

/* One timed setup + solve; returns 0 on convergence. */
static int run(problem *p, const char *config, double *setup_s, double *solve_s, int *iters, double *relres) {
    HYPRE_Solver pcg, amg;
    HYPRE_Int it = 0;
    double t0, t1, t2;
    reset_x(p);
    HYPRE_ParCSRPCGCreate(MPI_COMM_WORLD, &pcg);
    HYPRE_PCGSetMaxIter(pcg, 1000);
    HYPRE_PCGSetTol(pcg, 1e-8);
    HYPRE_PCGSetTwoNorm(pcg, 1);
    HYPRE_PCGSetPrintLevel(pcg, 0);
    HYPRE_PCGSetLogging(pcg, 1);

    HYPRE_BoomerAMGCreate(&amg);
    HYPRE_BoomerAMGSetPrintLevel(amg, 0);
    HYPRE_BoomerAMGSetTol(amg, 0.0);
    HYPRE_BoomerAMGSetMaxIter(amg, 1);
    if (strcmp(config, "st05") == 0) {
        HYPRE_BoomerAMGSetStrongThreshold(amg, 0.5);
    } else if (strcmp(config, "falgout") == 0) {
        HYPRE_BoomerAMGSetCoarsenType(amg, 6);
        HYPRE_BoomerAMGSetInterpType(amg, 0);
        HYPRE_BoomerAMGSetPMaxElmts(amg, 0);
        HYPRE_BoomerAMGSetRelaxType(amg, 6);
        HYPRE_BoomerAMGSetNumSweeps(amg, 1);
        HYPRE_BoomerAMGSetStrongThreshold(amg, p->dim == 3 ? 0.5 : 0.25);
    }
    HYPRE_PCGSetPrecond(pcg, (HYPRE_PtrToSolverFcn)HYPRE_BoomerAMGSolve, (HYPRE_PtrToSolverFcn)HYPRE_BoomerAMGSetup,
                        amg);

    t0 = MPI_Wtime();
    HYPRE_ParCSRPCGSetup(pcg, p->parA, p->parb, p->parx);
    t1 = MPI_Wtime();
    HYPRE_ParCSRPCGSolve(pcg, p->parA, p->parb, p->parx);
    t2 = MPI_Wtime();
    HYPRE_PCGGetNumIterations(pcg, &it);
    HYPRE_PCGGetFinalRelativeResidualNorm(pcg, relres);
    *setup_s = t1 - t0;
    *solve_s = t2 - t1;
    *iters = (int)it;
    HYPRE_ParCSRPCGDestroy(pcg);
    HYPRE_BoomerAMGDestroy(amg);
    return *relres < 1e-8 ? 0 : 1;
}

int main(int argc, char **argv) {
    static const char *configs[] = {"default", "st05", "falgout"};
    int repeats = argc > 1 ? atoi(argv[1]) : 3, d, c, k, size;
    MPI_Init(&argc, &argv);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (size != 1) {
        fprintf(stderr, "run on one MPI rank\n");
        MPI_Finalize();
        return 1;
    }
    HYPRE_Init();
    if (repeats < 1) repeats = 1;
    for (d = 2; d <= 3; ++d) {
        problem p;
        assemble(&p, d, d == 2 ? 512 : 128);
        for (c = 0; c < 3; ++c) {
            double best = 1e30, bs = 0, bv = 0, res = 0;
            int iters = 0, fail = 0;
            for (k = 0; k < repeats; ++k) {
                double s, v, rr;
                int it;
                fail |= run(&p, configs[c], &s, &v, &it, &rr);
                if (s + v < best) {
                    best = s + v;
                    bs = s;
                    bv = v;
                    iters = it;
                    res = rr;
                }
            }
            printf("BENCH hypre_pcg_boomeramg_%dd_%s time_s=%.4f iters=%d setup_s=%.4f solve_s=%.4f relres=%.2e%s\n", d,
                   configs[c], best, iters, bs, bv, res, fail ? " NOT_CONVERGED" : "");
            fflush(stdout);
        }
        destroy(&p);
    }
    HYPRE_Finalize();
    MPI_Finalize();
    return 0;
}
