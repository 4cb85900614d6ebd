/* bench/mpsdem_dambreak/count_pairs.c: the candidate pairs of the MPS neighbour search (cells of edge re,
   forward scan, as fsdem__mps_neighbours) on the initial state of the bench, by the kinds of the two
   particles. Evidence for the profile in README.md; not run by make.
   Build: cc -std=c99 -O2 -I. bench/mpsdem_dambreak/count_pairs.c -o count_pairs -lm */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"
#include "../../validation/mpsdem_dambreak/case.h"

int main(void) {
    sd_case c;
    fsdem_cellgrid g;
    fsdem_mps_particles p;
    fsdem_mps_desc d;
    long long cand = 0, dd = 0, fixed = 0, kept = 0;
    int cell, f, a, b;
    if (sd_create(&c, 0.0027, FSDEM_MPS_MODEL_B, 1) != 0) return 1;
    p = fsdem_mps_get_particles(c.mps);
    d = fsdem_mps_get_desc(c.mps);
    memset(&g, 0, sizeof g);
    fsdem_cellgrid_setup(&g, NULL, 3, d.domain_min, d.domain_max, d.re, 0);
    fsdem_cellgrid_build(&g, p.position, p.count);
    for (cell = 0; cell < g.cell_count; ++cell) {
        int coord[3], cells[14], nf;
        coord[0] = cell % g.n[0]; coord[1] = cell / g.n[0] % g.n[1]; coord[2] = cell / (g.n[0] * g.n[1]);
        nf = fsdem_cellgrid_forward(&g, coord, cells);
        for (f = 0; f < nf; ++f)
            for (a = g.cell_start[cell]; a < g.cell_start[cell + 1]; ++a) {
                int pa = g.items[a], b0 = f == 0 ? a + 1 : g.cell_start[cells[f]];
                for (b = b0; b < g.cell_start[cells[f] + 1]; ++b) {
                    int pb = g.items[b];
                    fsdem_vec3 x = fsdem_v3(p.position[pa].x - p.position[pb].x, p.position[pa].y - p.position[pb].y, p.position[pa].z - p.position[pb].z);
                    cand++;
                    dd += p.kind[pa] == FSDEM_MPS_KIND_DUMMY && p.kind[pb] == FSDEM_MPS_KIND_DUMMY;
                    fixed += p.kind[pa] != FSDEM_MPS_KIND_FLUID && p.kind[pb] != FSDEM_MPS_KIND_FLUID;
                    kept += x.x * x.x + x.y * x.y + x.z * x.z < d.re * d.re && !(p.kind[pa] == FSDEM_MPS_KIND_DUMMY && p.kind[pb] == FSDEM_MPS_KIND_DUMMY);
                }
            }
    }
    printf("particles %d cell %.4g m: candidate pairs %lld, dummy-dummy %lld (%.1f%%), both fixed %lld (%.1f%%), kept %lld (%.1f%%)\n", p.count,
           (double)g.cell_size, cand, dd, 100.0 * dd / cand, fixed, 100.0 * fixed / cand, kept, 100.0 * kept / cand);
    fsdem_cellgrid_free(&g);
    sd_destroy(&c);
    return 0;
}
