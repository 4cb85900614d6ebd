/* ===== >>kernel : interpolation weights ============================================================ */

/* Private helpers of the implementation (>>impl_kernel): per-axis weights of the tent (linear) and
   quadratic B-spline kernels on a uniform grid with a staggering offset, their derivatives, and
   the clamped node indices; PIC transfers, fluid fractions, sampling and couplers use them. */
