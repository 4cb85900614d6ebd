/* ---- >>pic_advection : particle motion, solids, outflow ---- */

/* Moves every particle through the grid velocity (threaded: each particle on its own). */
/* threaded: opens a team over the particles. */
static void fsdem__pic_advect(fsdem_pic *s, fsdem_real dt) {
    int p;
    FSDEM__OMP(parallel for schedule(static)
               num_threads(fsdem__team_for(s->np, FSDEM__TEAM_ITEMS, FSDEM__NO_CAP)))
    for (p = 0; p < s->np; ++p) {
        fsdem_vec3 x = s->px[p], k1, k2, k3;
        k1 = fsdem__pic_interp_vel(s, s->u, x);
        if (s->desc.advection_order == 2) {
            k2 = fsdem__pic_interp_vel(s, s->u, fsdem__madd(x, k1, dt / 2));
            x = fsdem__madd(x, k2, dt);
        } else { /* Ralston's third-order method */
            k2 = fsdem__pic_interp_vel(s, s->u, fsdem__madd(x, k1, dt / 2));
            k3 = fsdem__pic_interp_vel(s, s->u, fsdem__madd(x, k2, dt * (fsdem_real)0.75));
            x = fsdem__madd(x, fsdem__add(fsdem__add(fsdem__scale(k1, 2), fsdem__scale(k2, 3)), fsdem__scale(k3, 4)),
                            dt / 9);
        }
        if (s->dim == 2) x.z = 0;
        s->px[p] = x;
    }
}

/* Keeps particles in the open domain: those beyond an outflow side are marked for removal, the
   others are clamped inside the walls and pushed out of obstacles along the distance gradient
   (seed 004 Eq. 61). Returns the number marked. */
static int fsdem__pic_constrain(fsdem_pic *s) {
    fsdem_real eps = s->dx * (fsdem_real)1e-3;
    int p, b, marked = 0, it;
    for (p = 0; p < s->np; ++p) {
        fsdem_real xb[3];
        int gone = 0;
        xb[0] = s->px[p].x;
        xb[1] = s->px[p].y;
        xb[2] = s->px[p].z;
        for (b = 0; b < s->dim; ++b) {
            fsdem_real lo = fsdem__comp(s->lo, b), hi = fsdem__comp(s->hi, b);
            if (xb[b] < lo && s->desc.boundary[2 * b] == FSDEM_PIC_BC_OUTFLOW) gone = 1;
            if (xb[b] > hi && s->desc.boundary[2 * b + 1] == FSDEM_PIC_BC_OUTFLOW) gone = 1;
            if (!(xb[b] > lo + eps)) xb[b] = lo + eps;
            if (xb[b] > hi - eps) xb[b] = hi - eps;
        }
        if (gone) {
            s->pflag[p] = 1;
            ++marked;
            continue;
        }
        s->px[p] = fsdem_v3(xb[0], xb[1], xb[2]);
        if (s->obst_count && s->cnear[fsdem__mac_cell_of(&s->mac, s->px[p])]) {
            for (it = 0; it < 3; ++it) {
                fsdem_real d = fsdem__pic_obst_min(s, s->px[p], NULL);
                fsdem_vec3 nrm;
                if (d > eps) break;
                nrm = fsdem__pic_gradient(s, fsdem__pic_obst_dist, s->px[p]);
                s->px[p] = fsdem__madd(s->px[p], nrm, eps - d);
            }
            if (fsdem__pic_obst_min(s, s->px[p], NULL) <= 0 || !fsdem__pic_open_at(s, s->px[p])) {
                s->pflag[p] = 1;
                ++marked;
            }
        }
    }
    return marked;
}

/* Density projection of seed 004 §5.1 with alpha_s = 0 (target fraction 1): solve
   lap q = 1 - alpha_star (Eq. 12b with q = dt^2 p2 / rho; the ratio alpha_star/alpha_target clamped to [0.5, 1.5]) with
   q = 0 at the free surface (ghost fluid) and zero flux through solids (particles are already out
   of them, so the push-out term of Appendix B Eq. 64 vanishes), then move every particle by the
   interpolated dx = -grad q (Eq. 13), limited to one cell. Surface cells are only decompressed:
   their deficit is geometry, not a hole. */
static fsdem_result fsdem__pic_density_projection(fsdem_pic *s) {
    fsdem_stencil st;
    fsdem_pcg_info info;
    fsdem_result r;
    int i, j, k, c, a, sg, p, any = 0;
    fsdem_real dx2 = s->dx * s->dx;
    clock_t t0;
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                fsdem_real f, rr, ref;
                int surface = 0, coord[3];
                c = fsdem__mac_cell(&s->mac, i, j, k);
                s->ctmp[c] = 0;
                if (s->ctype[c] != FSDEM_STENCIL_CELL_FLUID) {
                    s->rhs[c] = 0;
                    continue;
                }
                coord[0] = i;
                coord[1] = j;
                coord[2] = k;
                for (a = 0; a < s->dim; ++a)
                    for (sg = 0; sg < 2; ++sg) {
                        int f = fsdem__mac_face(&s->mac, a, i, j, k) + sg * s->fstep[a][a], nc = coord[a] + (sg ? 1 : -1);
                        if (s->E[a][f] <= 0) continue;
                        if (nc < 0 || nc >= s->n[a] || s->ctype[c + (sg ? 1 : -1) * s->cstep[a]] == FSDEM_STENCIL_CELL_AIR)
                            surface = 1;
                    }
                f = s->frac[c];
                if (f < (fsdem_real)0.5) f = (fsdem_real)0.5;
                if (f > (fsdem_real)1.5) f = (fsdem_real)1.5;
                rr = 1 - f;
                if (surface && rr > 0) rr = 0;
                ref = s->fref[c] * s->cref[c];
                if (ref < FSDEM__PIC_FREF_RELIABLE) rr = 0; /* count unreliable (mostly solid) */
                if (rr != 0) any = 1;
                /* the volume to move is the deficit of the open part of the cell (times its
                   porosity: Eq. 12b multiplied by alpha_f'); the fluxes through the faces are
                   weighted like the pressure's */
                s->rhs[c] = -dx2 * rr * (ref < 1 ? ref : 1) * s->cpor[c];
            }
    s->d_iters = 0;
    if (!any) return FSDEM_OK;
    t0 = clock();
    fsdem__pic_ghost_diag(s);
    fsdem__pic_stencil_view(s, &st, 0);
    r = fsdem_pcg_setup_stencil(s->pcg_p, &st);
    info.iterations = 0;
    if (r == FSDEM_OK) {
        fsdem_pcg_set_tolerance(s->pcg_p, (fsdem_real)1e-4, s->desc.pressure_max_iterations);
        r = fsdem_pcg_solve(s->pcg_p, s->rhs, s->ctmp, &info);
        fsdem_pcg_set_tolerance(s->pcg_p, s->desc.pressure_tolerance, s->desc.pressure_max_iterations);
    }
    s->d_iters = info.iterations;
    s->sec_density += (double)(clock() - t0) / CLOCKS_PER_SEC;
    if (r != FSDEM_OK && r != FSDEM_ERR_NOT_CONVERGED) return r; /* keep the particles where they are */
    for (a = 0; a < s->dim; ++a) memset(s->uold[a], 0, sizeof(fsdem_real) * (size_t)s->nface[a]);
    fsdem__pic_apply_grad(s, s->ctmp, s->inv_dx, s->uold);
    for (p = 0; p < s->np; ++p) {
        fsdem_vec3 d = fsdem__pic_interp_vel(s, s->uold, s->px[p]);
        fsdem_real len = fsdem__norm(d);
        if (len > s->dx) d = fsdem__scale(d, s->dx / len);
        s->px[p] = fsdem__add(s->px[p], d);
    }
    return FSDEM_OK;
}
