/* ===== >>impl_kernel : interpolation weights ==========================================================

   Contents: fsdem__kernel (per-axis node range, weights, derivatives and clamped node indices) and
   fsdem__kernel_weights, the tent (linear, 2 nodes) and quadratic B-spline (3 nodes) kernels at a
   position given in grid units; fsdem__kernel_mps, the particle-interaction weight of MPS, and fsdem__kernel_mps_explicit, that of
   its explicit scheme. */

/* Kernel weights of one point along each axis: nodes lo[b] .. lo[b] + count[b] - 1, weights w and
   their derivatives dw (per grid unit), and the node indices clamped into the grid (idx). */
typedef struct fsdem__kernel {
    int lo[3];
    int count[3];
    int idx[3][3];
    fsdem_real w[3][3];
    fsdem_real dw[3][3];
} fsdem__kernel;

/* Weights at position s[b] (grid units: node i sits at s = i) on a grid of n[b] nodes, for the first
   `dim` axes; the others get the single node 0 with weight 1. Positions far outside (or NaN) are
   clamped to 4 nodes beyond the grid, so the indices stay representable. */
static void fsdem__kernel_weights(fsdem__kernel *k, int dim, const fsdem_real s[3], const int n[3], int quadratic) {
    int b, q;
    for (b = 0; b < 3; ++b) {
        fsdem_real x = s[b], t;
        int i0;
        for (q = 0; q < 3; ++q) { /* every entry set, also those past count (compilers cannot see the bound) */
            k->idx[b][q] = 0;
            k->w[b][q] = k->dw[b][q] = 0;
        }
        if (b >= dim) {
            k->lo[b] = 0;
            k->count[b] = 1;
            k->w[b][0] = 1;
            continue;
        }
        if (!(x > -4)) x = -4; /* also NaN */
        if (x > (fsdem_real)n[b] + 4) x = (fsdem_real)n[b] + 4;
        if (!quadratic) {
            i0 = (int)(x + 8) - 8; /* floor: x > -8 here */
            t = x - (fsdem_real)i0;
            k->count[b] = 2;
            k->w[b][0] = 1 - t;
            k->w[b][1] = t;
            k->dw[b][0] = -1;
            k->dw[b][1] = 1;
        } else {
            i0 = (int)(x + (fsdem_real)7.5) - 8; /* floor(x - 1/2) */
            t = x - (fsdem_real)i0;
            k->count[b] = 3;
            k->w[b][0] = (fsdem_real)0.5 * ((fsdem_real)1.5 - t) * ((fsdem_real)1.5 - t);
            k->w[b][1] = (fsdem_real)0.75 - (t - 1) * (t - 1);
            k->w[b][2] = (fsdem_real)0.5 * (t - (fsdem_real)0.5) * (t - (fsdem_real)0.5);
            k->dw[b][0] = t - (fsdem_real)1.5;
            k->dw[b][1] = -2 * (t - 1);
            k->dw[b][2] = t - (fsdem_real)0.5;
        }
        k->lo[b] = i0;
        for (q = 0; q < k->count[b]; ++q) {
            const int i = i0 + q;
            k->idx[b][q] = i < 0 ? 0 : i > n[b] - 1 ? n[b] - 1 : i;
        }
    }
}

/* Weight of the MPS particle interaction at distance r (m) for the radius re (m): the kernel of
   Zhang et al. (2014), re/(0.85 r + 0.15 re) - 1 for r < re, 0 beyond (seed 002 Eq. 6). It is finite
   at r = 0 (re/(0.15 re) - 1 = 17/3), unlike the original MPS kernel re/r - 1, which keeps
   coincident particles from producing infinite number densities and pressure spikes. */
static inline fsdem_real fsdem__kernel_mps(fsdem_real r, fsdem_real re) {
    return r < re ? re / ((fsdem_real)0.85 * r + (fsdem_real)0.15 * re) - 1 : 0;
}

/* Weight of MPS's explicit scheme at distance r (m) for the support R (m): q^2 (1 - q)^3, q = r/R,
   0 beyond. In MPS's sum-form gradient a pair pushes with w/r, which is then the gradient of the
   Wendland C2 kernel of SPH (Wendland 1995) of support R: smooth, zero at contact and at R. */
static inline fsdem_real fsdem__kernel_mps_explicit(fsdem_real r, fsdem_real R) {
    const fsdem_real q = r / R;
    return q < 1 ? q * q * (1 - q) * (1 - q) * (1 - q) : 0;
}
