/* ---- >>pic_cells : effective faces, fluid fraction, level set, cell types ---- */

/* Reference fractions below this mark cells mostly inside obstacles (see fsdem__pic_fraction). */
#define FSDEM__PIC_FREF_RELIABLE ((fsdem_real)0.5)

/* Cell c is mostly inside static obstacles or moving solids (its particle count is unreliable). */
static int fsdem__pic_mostly_solid(const fsdem_pic *s, int c) {
    return (s->cnear[c] || s->cref[c] < 1) && s->fref[c] * s->cref[c] < FSDEM__PIC_FREF_RELIABLE;
}

/* E and us of every face from the static obstacles, the coupler arrays and the domain sides. */
static void fsdem__pic_effective_faces(fsdem_pic *s) {
    int a, i, j, k;
    for (a = 0; a < s->dim; ++a)
        for (k = 0; k < s->fn[a][2]; ++k)
            for (j = 0; j < s->fn[a][1]; ++j)
                for (i = 0; i < s->fn[a][0]; ++i) {
                    int f = fsdem__mac_face(&s->mac, a, i, j, k), coord = a == 0 ? i : a == 1 ? j : k;
                    fsdem_real so = s->sopen[a][f], co = s->copen[a][f];
                    if (co < 0) co = 0;
                    if (co > 1) co = 1;
                    if (coord == 0 || coord == s->n[a]) {
                        int side = 2 * a + (coord != 0);
                        fsdem_pic_bc bc = s->desc.boundary[side];
                        if (bc == FSDEM_PIC_BC_OUTFLOW) {
                            s->E[a][f] = so < co ? so : co;
                            s->us[a][f] = co < so ? s->cvel[a][f] : s->svel[a][f];
                        } else {
                            s->E[a][f] = 0;
                            s->us[a][f] = bc == FSDEM_PIC_BC_INFLOW ? fsdem__comp(s->desc.boundary_velocity[side], a) : 0;
                        }
                    } else {
                        s->E[a][f] = so < co ? so : co;
                        s->us[a][f] = co < so ? s->cvel[a][f] : s->svel[a][f];
                    }
                    {
                        /* seed 004 Appendix B: beta = (alpha_j' + alpha_f') / 2 between two cells */
                        const int cu = coord < s->n[a] ? fsdem__mac_cell(&s->mac, i, j, k) : -1;
                        const int cl = coord > 0 ? fsdem__mac_cell(&s->mac, i - (a == 0), j - (a == 1), k - (a == 2)) : -1;
                        const fsdem_real beta = cl < 0 ? s->cpor[cu] : cu < 0 ? s->cpor[cl] : (s->cpor[cl] + s->cpor[cu]) / 2;
                        s->fpor[a][f] = beta;
                        s->Ef[a][f] = s->E[a][f] * beta;
                    }
                }
}

/* Fluid fraction of each cell from the particles (tent kernel at cell centres, seed 004 Eq. 7b,
   divided by the reference fraction) and the level set phi derived from it: for a plane surface
   at distance d from a cell centre the tent kernel collects 1 - (dx - d)^2 / (2 dx^2), which is
   inverted here, so phi is exact for plane surfaces and bounded by one cell. */
static void fsdem__pic_fraction(fsdem_pic *s) {
    int p, c, b, q0, q1, q2;
    fsdem_real inv_ppc = 1 / (fsdem_real)s->ppc;
    memset(s->frac, 0, sizeof(fsdem_real) * (size_t)s->ncell);
    for (p = 0; p < s->np; ++p) {
        fsdem__kernel kw;
        fsdem_real g[3];
        for (b = 0; b < 3; ++b)
            g[b] = b < s->dim ? (fsdem__comp(s->px[p], b) - fsdem__comp(s->lo, b)) * s->inv_dx - (fsdem_real)0.5 : 0;
        fsdem__kernel_weights(&kw, s->dim, g, s->n, 0);
        /* nodes outside the grid collect nothing (the reference fraction fref is truncated alike) */
        for (q2 = 0; q2 < kw.count[2]; ++q2) {
            int k = kw.lo[2] + q2;
            if (k < 0 || k >= s->n[2]) continue;
            for (q1 = 0; q1 < kw.count[1]; ++q1) {
                int j = kw.lo[1] + q1;
                if (j < 0 || j >= s->n[1]) continue;
                for (q0 = 0; q0 < kw.count[0]; ++q0) {
                    int i = kw.lo[0] + q0;
                    if (i < 0 || i >= s->n[0]) continue;
                    s->frac[fsdem__mac_cell(&s->mac, i, j, k)] += kw.w[0][q0] * kw.w[1][q1] * kw.w[2][q2];
                }
            }
        }
    }
    for (c = 0; c < s->ncell; ++c) {
        const fsdem_real ref = s->fref[c] * s->cref[c] * s->cpor[c];
        fsdem_real f = ref > (fsdem_real)1e-3 ? s->frac[c] * inv_ppc / ref : 0;
        s->frac[c] = f;
        if (f >= 1) s->phi[c] = -s->dx;
        else if (f >= (fsdem_real)0.5) s->phi[c] = -s->dx * (1 - (fsdem_real)sqrt(2 * (1 - f)));
        else s->phi[c] = s->dx * (1 - (fsdem_real)sqrt(2 * f));
    }
    /* In cells mostly inside obstacles the count of a few particles over a small reference is
       unreliable (an isolated "air" cell under water would put p = 0 deep in the liquid); their
       phi is extended from the neighbours that are mostly open, as level sets are extended into
       solids (static obstacles and the coupler's moving ones alike). */
    {
        int i, j, k, a, sg, coord[3];
        for (k = 0; k < s->n[2]; ++k)
            for (j = 0; j < s->n[1]; ++j)
                for (i = 0; i < s->n[0]; ++i) {
                    fsdem_real sum = 0;
                    int cnt = 0;
                    c = fsdem__mac_cell(&s->mac, i, j, k);
                    if (!fsdem__pic_mostly_solid(s, c)) continue;
                    coord[0] = i;
                    coord[1] = j;
                    coord[2] = k;
                    for (a = 0; a < s->dim; ++a)
                        for (sg = -1; sg <= 1; sg += 2) {
                            int nc = coord[a] + sg, nb;
                            if (nc < 0 || nc >= s->n[a]) continue;
                            nb = c + sg * s->cstep[a];
                            if (s->fref[nb] * s->cref[nb] < FSDEM__PIC_FREF_RELIABLE) continue;
                            sum += s->phi[nb];
                            cnt++;
                        }
                    if (cnt) s->ctmp[c] = sum / (fsdem_real)cnt;
                    else s->ctmp[c] = s->phi[c];
                }
        for (c = 0; c < s->ncell; ++c)
            if (fsdem__pic_mostly_solid(s, c)) s->phi[c] = s->ctmp[c];
    }
}

/* Cell types from the effective faces and phi; returns the number of fluid cells. A cell is FLUID
   when phi < -theta_min dx: a surface through (or within theta_min dx of) a cell centre leaves
   that cell AIR whatever the rounding, so a flat surface is reconstructed the same in every column
   and the ghost-fluid fraction theta never needs clamping. */
static int fsdem__pic_types(fsdem_pic *s) {
    int a, i, j, k, c, fluid = 0;
    fsdem_real thresh = -s->desc.ghost_theta_min * s->dx;
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                int open = 0;
                c = fsdem__mac_cell(&s->mac, i, j, k);
                for (a = 0; a < s->dim && !open; ++a) {
                    int f = fsdem__mac_face(&s->mac, a, i, j, k);
                    if (s->E[a][f] > 0 || s->E[a][f + s->fstep[a][a]] > 0) open = 1;
                }
                if (!open) s->ctype[c] = FSDEM_STENCIL_CELL_SOLID;
                else if (!s->desc.free_surface || s->phi[c] < thresh) s->ctype[c] = FSDEM_STENCIL_CELL_FLUID;
                else s->ctype[c] = FSDEM_STENCIL_CELL_AIR;
                fluid += s->ctype[c] == FSDEM_STENCIL_CELL_FLUID;
            }
    s->fluid_cells = fluid;
    return fluid;
}

/* Effective faces, fluid fraction, level set and cell types of the current particles (after the
   particles or the obstacles changed outside a step), so views and statistics are current. */
static void fsdem__pic_refresh(fsdem_pic *s) {
    fsdem__pic_effective_faces(s);
    fsdem__pic_fraction(s);
    fsdem__pic_types(s);
    s->cells_fresh = 1;
}
