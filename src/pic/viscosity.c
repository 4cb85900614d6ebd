/* ---- >>pic_viscosity : implicit nu lap(u), one stencil solve per component ---- */

/* The viscous force on the closed faces of component a after its solve (fsdem_pic_coupling.shear):
   each unknown face f next to a closed face g lost rho dx^dim (dt nu / dx^2)(u_f - us_g) of
   momentum to it over dt, the Dirichlet term of the solve, so the forces sum to the momentum the
   liquid lost to solids. */
static void fsdem__pic_shear(fsdem_pic *s, int a) {
    const int *fn = s->fn[a];
    const unsigned char *cell = s->vcell[a];
    fsdem_real c = s->desc.density * s->desc.viscosity * (s->dim == 3 ? s->dx : 1);
    int b, i, j, k, sg, coord[3];
    memset(s->shear[a], 0, sizeof(fsdem_real) * (size_t)s->nface[a]);
    for (k = 0; k < fn[2]; ++k)
        for (j = 0; j < fn[1]; ++j)
            for (i = 0; i < fn[0]; ++i) {
                int f = (k * fn[1] + j) * fn[0] + i;
                if (cell[f] != FSDEM_STENCIL_CELL_FLUID) continue;
                coord[0] = i;
                coord[1] = j;
                coord[2] = k;
                for (b = 0; b < s->dim; ++b)
                    for (sg = -1; sg <= 1; sg += 2) {
                        int nc = coord[b] + sg, g;
                        if (nc < 0 || nc >= fn[b]) continue;
                        g = f + sg * s->fstep[a][b];
                        if (cell[g] != FSDEM_STENCIL_CELL_FLUID && s->E[a][g] <= 0) s->shear[a][g] += c * (s->u[a][f] - fsdem__pic_solid_start(s, a, g));
                    }
            }
}

/* Solves (I - dt nu L) u = u* on every face with E > 0 next to a fluid cell. The face grid of each
   component is a stencil grid of its own; the equation is divided by k = dt nu / dx^2:
       u/k + sum_nb (u - u_nb) + sum_dirichlet c (u - U) = u_star/k,
   with neighbours outside the unknowns either Dirichlet (a solid face at distance dx: c = 1, U its
   solid velocity; a no-slip or inflow side half a cell away: c = 2, U the side's velocity) or
   Neumann (air, slip sides, outflow). */
static fsdem_result fsdem__pic_viscosity(fsdem_pic *s, fsdem_real dt) {
    fsdem_real k = dt * s->desc.viscosity * s->inv_dx * s->inv_dx, inv_k = 1 / k;
    int a, b, i, j, kk;
    fsdem_result worst = FSDEM_OK;
    s->v_iters = 0;
    for (a = 0; a < s->dim; ++a) {
        const int *fn = s->fn[a];
        unsigned char *cell = s->vcell[a];
        fsdem_real *dg = s->ftmp[a], *rhs = s->wsum[a];
        fsdem_stencil st;
        fsdem_pcg_info info;
        fsdem_result r;
        int unknowns = 0;
        for (kk = 0; kk < fn[2]; ++kk)
            for (j = 0; j < fn[1]; ++j)
                for (i = 0; i < fn[0]; ++i) {
                    int f = (kk * fn[1] + j) * fn[0] + i, coord = a == 0 ? i : a == 1 ? j : kk, fluid = 0;
                    if (s->E[a][f] > 0) {
                        int cidx = fsdem__mac_cell(&s->mac, i < s->n[0] ? i : s->n[0] - 1, j < s->n[1] ? j : s->n[1] - 1,
                                                   kk < s->n[2] ? kk : s->n[2] - 1);
                        if (coord < s->n[a] && s->ctype[cidx] == FSDEM_STENCIL_CELL_FLUID) fluid = 1;
                        if (coord > 0 && s->ctype[cidx - (coord < s->n[a] ? s->cstep[a] : 0)] == FSDEM_STENCIL_CELL_FLUID) fluid = 1;
                    }
                    cell[f] = fluid ? FSDEM_STENCIL_CELL_FLUID : FSDEM_STENCIL_CELL_SOLID;
                    unknowns += fluid;
                }
        if (!unknowns) continue;
        for (kk = 0; kk < fn[2]; ++kk)
            for (j = 0; j < fn[1]; ++j)
                for (i = 0; i < fn[0]; ++i) {
                    int f = (kk * fn[1] + j) * fn[0] + i, coord[3], sg;
                    fsdem_real d = 0, r0 = 0;
                    if (cell[f] != FSDEM_STENCIL_CELL_FLUID) {
                        dg[f] = 0;
                        rhs[f] = 0;
                        continue;
                    }
                    coord[0] = i;
                    coord[1] = j;
                    coord[2] = kk;
                    for (b = 0; b < s->dim; ++b)
                        for (sg = -1; sg <= 1; sg += 2) {
                            int nc = coord[b] + sg, g;
                            if (nc < 0 || nc >= fn[b]) {
                                if (b != a) {
                                    int side = 2 * b + (sg > 0);
                                    fsdem_pic_bc bc = s->desc.boundary[side];
                                    if (bc == FSDEM_PIC_BC_NO_SLIP || bc == FSDEM_PIC_BC_INFLOW) {
                                        d += 2;
                                        r0 += 2 * fsdem__comp(s->desc.boundary_velocity[side], a);
                                    }
                                }
                                continue;
                            }
                            g = f + sg * s->fstep[a][b];
                            if (cell[g] == FSDEM_STENCIL_CELL_FLUID) continue;
                            if (s->E[a][g] <= 0) {
                                d += 1;
                                r0 += fsdem__pic_solid_start(s, a, g);
                            }
                        }
                    dg[f] = inv_k + d;
                    rhs[f] = inv_k * s->u[a][f] + r0;
                }
        memset(&st, 0, sizeof st);
        st.dim = s->dim;
        for (b = 0; b < 3; ++b) st.n[b] = fn[b];
        st.cell = cell;
        for (b = 0; b < s->dim; ++b) st.face[b] = s->vface[a][b];
        st.diag = dg;
        r = fsdem_pcg_setup_stencil(s->pcg_v[a], &st);
        if (r == FSDEM_OK) r = fsdem_pcg_solve(s->pcg_v[a], rhs, s->u[a], &info);
        else info.iterations = 0;
        s->v_iters += info.iterations;
        fsdem__pic_shear(s, a);
        if (r != FSDEM_OK && worst == FSDEM_OK) {
            worst = r;
            fsdem__fail(&s->status, r, "fsdem_pic: viscous solve of component %c failed: %s", "xyz"[a],
                        fsdem_pcg_last_error(s->pcg_v[a]));
        }
    }
    return worst;
}
