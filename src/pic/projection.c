/* ---- >>pic_projection : pressure (and density) projection ---- */

static fsdem_real fsdem__pic_theta(const fsdem_pic *s, fsdem_real phi_in, fsdem_real phi_out) {
    fsdem_real t = phi_in < phi_out ? phi_in / (phi_in - phi_out) : 1;
    if (!(t >= s->desc.ghost_theta_min)) t = s->desc.ghost_theta_min;
    if (t > 1) t = 1;
    return t;
}

/* Fills s->diag with the ghost-fluid terms: a fluid cell whose neighbour across an open face is air
   (phi of the two gives the interface fraction theta) or an outflow side (p = 0 on the side,
   theta = 1/2) adds E (1/theta - 1) to the stencil's E (p_c - 0). Returns 1 when a cell has an
   air or outflow neighbour (a Dirichlet condition somewhere). */
static void fsdem__pic_ghost_diag(fsdem_pic *s) {
    int a, i, j, k, c, sg, coord[3];
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                fsdem_real d = 0;
                c = fsdem__mac_cell(&s->mac, i, j, k);
                if (s->ctype[c] != FSDEM_STENCIL_CELL_FLUID) {
                    s->diag[c] = 0;
                    continue;
                }
                coord[0] = i;
                coord[1] = j;
                coord[2] = k;
                for (a = 0; a < s->dim; ++a)
                    for (sg = 0; sg < 2; ++sg) {
                        int f = fsdem__mac_face(&s->mac, a, i, j, k) + sg * s->fstep[a][a], nc = coord[a] + (sg ? 1 : -1);
                        fsdem_real e = s->Ef[a][f];
                        if (e <= 0) continue;
                        if (nc < 0 || nc >= s->n[a]) {
                            d += e; /* outflow side: theta = 1/2 */
                            continue;
                        }
                        {
                            int nb = c + (sg ? 1 : -1) * s->cstep[a];
                            if (s->ctype[nb] == FSDEM_STENCIL_CELL_AIR)
                                d += e * (1 / fsdem__pic_theta(s, s->phi[c], s->phi[nb]) - 1);
                        }
                    }
                s->diag[c] = d;
            }
}

/* Gradient of a cell field `q` across face f of axis a (lower cell index cl, upper cu, -1 outside)
   with the ghost-fluid treatment; *ok = 0 when the face is not next to a fluid cell. */
static fsdem_real fsdem__pic_face_grad(const fsdem_pic *s, const fsdem_real *q, int cl, int cu, int *ok) {
    int fl = cl >= 0 && s->ctype[cl] == FSDEM_STENCIL_CELL_FLUID;
    int fu = cu >= 0 && s->ctype[cu] == FSDEM_STENCIL_CELL_FLUID;
    *ok = 1;
    if (fl && fu) return q[cu] - q[cl];
    if (fl) {
        if (cu < 0) return -2 * q[cl];
        if (s->ctype[cu] == FSDEM_STENCIL_CELL_AIR) return -q[cl] / fsdem__pic_theta(s, s->phi[cl], s->phi[cu]);
    } else if (fu) {
        if (cl < 0) return 2 * q[cu];
        if (s->ctype[cl] == FSDEM_STENCIL_CELL_AIR) return q[cu] / fsdem__pic_theta(s, s->phi[cu], s->phi[cl]);
    }
    *ok = 0;
    return 0;
}

/* Divergence of the face field u (with the solid fluxes) of cell (i, j, k), 1/s: the liquid's flux
   weighted by the faces' porosity (seed 004 Eq. 12a), the solids' by their share of the face. */
static fsdem_real fsdem__pic_divergence(const fsdem_pic *s, fsdem_real *const u[3], int i, int j, int k) {
    fsdem_real sum = 0;
    int a;
    for (a = 0; a < s->dim; ++a) {
        int f = fsdem__mac_face(&s->mac, a, i, j, k), g = f + s->fstep[a][a];
        sum += s->Ef[a][g] * u[a][g] + (1 - s->E[a][g]) * s->us[a][g];
        sum -= s->Ef[a][f] * u[a][f] + (1 - s->E[a][f]) * s->us[a][f];
    }
    return sum * s->inv_dx;
}

static void fsdem__pic_stencil_view(const fsdem_pic *s, fsdem_stencil *st, int with_extra) {
    int a;
    memset(st, 0, sizeof *st);
    st->dim = s->dim;
    for (a = 0; a < 3; ++a) st->n[a] = s->n[a];
    st->cell = s->ctype;
    for (a = 0; a < s->dim; ++a) st->face[a] = s->Ef[a];
    st->diag = s->diag;
    if (with_extra) {
        st->extra = s->pressure_extra;
        st->extra_user = s->pressure_extra_user;
    }
}

/* Applies the gradient of the cell field q to the face field `out`: out -= scale grad q over faces
   next to fluid, which are marked valid (others invalid). */
static void fsdem__pic_apply_grad(fsdem_pic *s, const fsdem_real *q, fsdem_real scale, fsdem_real *const out[3]) {
    int a, i, j, k;
    for (a = 0; a < s->dim; ++a)
        for (k = 0; k < s->fn[a][2]; ++k)
            for (j = 0; j < s->fn[a][1]; ++j)
                for (i = 0; i < s->fn[a][0]; ++i) {
                    int f = fsdem__mac_face(&s->mac, a, i, j, k), coord = a == 0 ? i : a == 1 ? j : k, ok;
                    int cu = -1, cl = -1;
                    fsdem_real g;
                    s->fvalid[a][f] = 0;
                    if (s->E[a][f] <= 0) continue;
                    if (coord < s->n[a]) cu = fsdem__mac_cell(&s->mac, i, j, k);
                    if (coord > 0) cl = fsdem__mac_cell(&s->mac, i - (a == 0), j - (a == 1), k - (a == 2));
                    g = fsdem__pic_face_grad(s, q, cl, cu, &ok);
                    if (!ok) continue;
                    out[a][f] -= scale * g;
                    s->fvalid[a][f] = 1;
                }
}

/* Pressure projection: sum_f E_f (p_c - p_nb) (+ ghost-fluid diag, + coupler term) =
   -(rho dx^2 / dt) div(u*) (seed 000 Eq. 5; the solid fluxes of partly covered faces enter the
   divergence), then u -= dt/(rho dx) grad p on every face next to fluid. */
static fsdem_result fsdem__pic_project(fsdem_pic *s, fsdem_real dt) {
    fsdem_stencil st;
    fsdem_pcg_info info;
    fsdem_result r;
    fsdem_real scale = -s->desc.density * s->dx * s->dx / dt, d2 = 0, dmax = 0;
    int i, j, k, c;
    clock_t t0 = clock();
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                c = fsdem__mac_cell(&s->mac, i, j, k);
                if (s->ctype[c] != FSDEM_STENCIL_CELL_FLUID) {
                    s->rhs[c] = 0;
                    s->pres[c] = 0;
                    continue;
                }
                {
                    fsdem_real dv = fsdem__pic_divergence(s, s->u, i, j, k);
                    d2 += dv * dv;
                    s->rhs[c] = scale * dv + s->crhs[c];
                }
            }
    s->div_before = (fsdem_real)sqrt(d2);
    fsdem__pic_ghost_diag(s);
    fsdem__pic_stencil_view(s, &st, 1);
    r = fsdem_pcg_setup_stencil(s->pcg_p, &st);
    info.iterations = 0;
    info.residual = 0;
    if (r == FSDEM_OK && s->fluid_cells > 0) r = fsdem_pcg_solve(s->pcg_p, s->rhs, s->pres, &info);
    if (r == FSDEM_OK && s->pressure_response) {
        s->pressure_response(s->pressure_extra_user, s->pres, dt); /* the solids' final velocity, */
        fsdem__pic_effective_faces(s);                              /* into us (E is unchanged) */
    }
    s->p_iters = info.iterations;
    s->p_res = info.residual;
    s->sec_pressure += (double)(clock() - t0) / CLOCKS_PER_SEC;
    if (r != FSDEM_OK)
        fsdem__fail(&s->status, r, "fsdem_pic: pressure solve failed (%d iterations, residual %g): %s", info.iterations,
                    (double)info.residual, fsdem_pcg_last_error(s->pcg_p));
    fsdem__pic_apply_grad(s, s->pres, dt / (s->desc.density * s->dx), s->u);
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                c = fsdem__mac_cell(&s->mac, i, j, k);
                if (s->ctype[c] == FSDEM_STENCIL_CELL_FLUID) {
                    fsdem_real dv = (fsdem_real)fabs(fsdem__pic_divergence(s, s->u, i, j, k));
                    if (dv > dmax) dmax = dv;
                }
            }
    s->max_div = dmax;
    return r;
}
