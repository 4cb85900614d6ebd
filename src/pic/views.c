/* ---- >>pic_views : grid, coupling, sampling, statistics ---- */

fsdem_pic_fields fsdem_pic_get_fields(const fsdem_pic *s) {
    fsdem_pic_fields g;
    int a;
    memset(&g, 0, sizeof g);
    if (!s) return g;
    g.dim = s->dim;
    for (a = 0; a < 3; ++a) {
        g.n[a] = s->n[a];
        g.face_count[a] = s->nface[a];
        g.velocity[a] = s->u[a];
        g.open[a] = s->E[a];
        g.solid_velocity[a] = s->us[a];
    }
    g.cell_size = s->dx;
    g.origin = s->lo;
    g.cell = s->ctype;
    g.pressure = s->pres;
    g.phi = s->phi;
    g.fraction = s->frac;
    return g;
}

fsdem_claims *fsdem_pic_claims(fsdem_pic *s) { return s ? &s->claims : NULL; }

fsdem_pic_coupling fsdem_pic_get_coupling(fsdem_pic *s) {
    fsdem_pic_coupling c;
    if (s) {
        s->cells_fresh = 0; /* the caller may change the references: the next step recounts the cells */
        return s->coupling;
    }
    memset(&c, 0, sizeof c);
    return c;
}

fsdem_result fsdem_pic_set_pressure_extra(fsdem_pic *s, fsdem_operator_fn fn, fsdem_pic_response_fn response, void *user) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    s->pressure_extra = fn;
    s->pressure_response = fn ? response : NULL;
    s->pressure_extra_user = fn ? user : NULL;
    return fsdem__ok(&s->status);
}

static int fsdem__pic_fluid_cell(const fsdem_pic *s, int c) { return c >= 0 && s->ctype[c] == FSDEM_STENCIL_CELL_FLUID; }

/* The cells below (lower index along a) and above face (i, j, k) of axis a; -1 off the grid. */
static void fsdem__pic_face_cells(const fsdem_pic *s, int a, const int f3[3], int *below, int *above) {
    const int coord = f3[a];
    *above = coord < s->n[a] ? fsdem__mac_cell(&s->mac, f3[0], f3[1], f3[2]) : -1;
    *below = coord > 0 ? fsdem__mac_cell(&s->mac, f3[0] - (a == 0), f3[1] - (a == 1), f3[2] - (a == 2)) : -1;
}

fsdem_result fsdem_pic_sample(const fsdem_pic *s, int count, const fsdem_vec3 *points, fsdem_fluid_sample *out) {
    int n, a, b, q0, q1, q2;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (count < 0 || (count > 0 && (!points || !out)))
        return fsdem__fail((fsdem__status *)&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_sample: bad count %d or NULL arrays",
                           count);
    for (n = 0; n < count; ++n) {
        const fsdem_vec3 x = points[n];
        fsdem_real grad[3] = {0, 0, 0}, g[3], frac = 0;
        fsdem__kernel kw;
        out[n].velocity = fsdem__pic_interp_vel(s, s->u, x);
        /* pressure gradient: the face differences (p_above - p_below)/dx, interpolated over the faces
           between two open cells (weights renormalised) */
        for (a = 0; a < s->dim; ++a) {
            fsdem_real sum = 0, wsum = 0;
            fsdem__pic_kernel(s, a, x, 0, &kw);
            for (q2 = 0; q2 < kw.count[2]; ++q2)
                for (q1 = 0; q1 < kw.count[1]; ++q1)
                    for (q0 = 0; q0 < kw.count[0]; ++q0) {
                        const int f3[3] = {kw.idx[0][q0], kw.idx[1][q1], kw.idx[2][q2]};
                        const fsdem_real w = kw.w[0][q0] * kw.w[1][q1] * kw.w[2][q2];
                        int lo, hi;
                        fsdem__pic_face_cells(s, a, f3, &lo, &hi);
                        if (lo < 0 || hi < 0 || s->ctype[lo] == FSDEM_STENCIL_CELL_SOLID ||
                            s->ctype[hi] == FSDEM_STENCIL_CELL_SOLID || !(w > 0))
                            continue;
                        sum += w * (s->pres[hi] - s->pres[lo]);
                        wsum += w;
                    }
            grad[a] = wsum > 0 ? sum / wsum * s->inv_dx : 0;
        }
        out[n].pressure_gradient = fsdem_v3(grad[0], grad[1], grad[2]);
        /* liquid fraction clamp(1/2 - phi/dx, 0, 1) between cell centres (clamped to the outer ones) */
        for (b = 0; b < 3; ++b) {
            fsdem_real t = b < s->dim ? (fsdem__comp(x, b) - fsdem__comp(s->lo, b)) * s->inv_dx - (fsdem_real)0.5 : 0;
            g[b] = t < 0 ? 0 : t > (fsdem_real)(s->n[b] - 1) ? (fsdem_real)(s->n[b] - 1) : t;
        }
        fsdem__kernel_weights(&kw, s->dim, g, s->n, 0);
        for (q2 = 0; q2 < kw.count[2]; ++q2)
            for (q1 = 0; q1 < kw.count[1]; ++q1)
                for (q0 = 0; q0 < kw.count[0]; ++q0) {
                    const int c = fsdem__mac_cell(&s->mac, kw.idx[0][q0], kw.idx[1][q1], kw.idx[2][q2]);
                    fsdem_real f = s->desc.free_surface ? (fsdem_real)0.5 - s->phi[c] * s->inv_dx : 1;
                    if (s->ctype[c] == FSDEM_STENCIL_CELL_SOLID) f = 0;
                    frac += kw.w[0][q0] * kw.w[1][q1] * kw.w[2][q2] * (f < 0 ? 0 : f > 1 ? 1 : f);
                }
        out[n].volume_fraction = frac;
    }
    return fsdem__ok((fsdem__status *)&s->status);
}

/* Weights of the tent kernel of half-width `hw` at `point` on the faces of axis a next to FLUID
   cells: with `add` == 0 returns their sum; otherwise adds add x weight to the coupling
   acceleration of each. */
static fsdem_real fsdem__pic_spread(fsdem_pic *s, int a, fsdem_vec3 point, fsdem_real hw, fsdem_real add) {
    int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, f3[3], b;
    fsdem_real sum = 0;
    for (b = 0; b < s->dim; ++b) {
        const fsdem_real off = b == a ? 0 : (fsdem_real)0.5, x = (fsdem__comp(point, b) - fsdem__comp(s->lo, b)) * s->inv_dx;
        const fsdem_real reach = hw * s->inv_dx;
        lo[b] = (int)floor(x - reach - off) + 1;
        hi[b] = (int)ceil(x + reach - off) - 1;
        if (lo[b] < 0) lo[b] = 0;
        if (hi[b] > s->fn[a][b] - 1) hi[b] = s->fn[a][b] - 1;
    }
    for (f3[2] = lo[2]; f3[2] <= hi[2]; ++f3[2])
        for (f3[1] = lo[1]; f3[1] <= hi[1]; ++f3[1])
            for (f3[0] = lo[0]; f3[0] <= hi[0]; ++f3[0]) {
                const int f = fsdem__mac_face(&s->mac, a, f3[0], f3[1], f3[2]);
                fsdem_vec3 xf = fsdem__mac_face_pos(&s->mac, a, f3[0], f3[1], f3[2]);
                fsdem_real w = 1;
                int below, above;
                fsdem__pic_face_cells(s, a, f3, &below, &above);
                if (s->E[a][f] <= 0 || (!fsdem__pic_fluid_cell(s, below) && !fsdem__pic_fluid_cell(s, above))) continue;
                for (b = 0; b < s->dim; ++b) {
                    const fsdem_real t = 1 - (fsdem_real)fabs(fsdem__comp(xf, b) - fsdem__comp(point, b)) / hw;
                    w *= t > 0 ? t : 0;
                }
                if (!(w > 0)) continue;
                sum += w;
                if (add != 0) s->cacc[a][f] += add * w;
            }
    return sum;
}

fsdem_result fsdem_pic_add_force(fsdem_pic *s, fsdem_vec3 point, fsdem_real radius, fsdem_vec3 force, int *taken) {
    fsdem_real hw, wsum[3] = {0, 0, 0};
    int a;
    if (taken) *taken = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    hw = radius > s->dx ? radius : s->dx;
    if (!fsdem__finite3(point) || !fsdem__finite3(force) || !(radius >= 0) || !fsdem__finite(radius))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_force: point, force and radius >= 0 must be finite");
    {
        /* more than would accelerate a domain full of liquid at FSDEM_MAX_ACCELERATION */
        const fsdem_real most = s->desc.density * FSDEM_MAX_ACCELERATION * (fsdem_real)s->ncell * s->dx * s->dx * (s->dim == 3 ? s->dx : 1);
        if (!fsdem__within(force, most))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                               "fsdem_pic_add_force: the force (%g, %g, %g) N would accelerate a domain full of liquid at more than "
                               "FSDEM_MAX_ACCELERATION (|F| <= %g N)",
                               (double)force.x, (double)force.y, (double)force.z, (double)most);
    }
    if (s->dim == 2) point.z = 0;
    /* all components or none, so the momentum given is exactly force x dt */
    for (a = 0; a < s->dim; ++a)
        if (fsdem__comp(force, a) != 0 && !((wsum[a] = fsdem__pic_spread(s, a, point, hw, 0)) > 0)) return fsdem__ok(&s->status);
    for (a = 0; a < s->dim; ++a)
        if (fsdem__comp(force, a) != 0)
            fsdem__pic_spread(s, a, point, hw,
                              fsdem__comp(force, a) / (wsum[a] * s->desc.density * (fsdem_real)pow((double)s->dx, s->dim)));
    if (taken) *taken = 1;
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_pic_clear_forces(fsdem_pic *s) {
    int a;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    for (a = 0; a < s->dim; ++a) memset(s->cacc[a], 0, sizeof(fsdem_real) * (size_t)s->nface[a]);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_pic_exclude_particles(fsdem_pic *s, fsdem_sdf_fn solid, void *user, int remove, int *count) {
    const fsdem_real eps = s ? s->dx * (fsdem_real)1e-3 : 0;
    int p, it, n = 0;
    if (count) *count = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!solid) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_exclude_particles: NULL solid callback");
    /* the new positions go to ptmp first, so a distance that is not a number leaves every particle */
    for (p = 0; p < s->np; ++p) {
        fsdem_vec3 x = s->px[p], nrm;
        fsdem_real d = solid(user, x, &nrm);
        s->pflag[p] = 0;
        for (it = 0; it < 3 && d < eps; ++it) {
            if (!fsdem__finite(d) || !fsdem__finite3(nrm)) break;
            s->pflag[p] = 1;
            if (remove) break;
            x = fsdem__madd(x, nrm, eps - d);
            d = solid(user, x, &nrm);
        }
        if (!fsdem__finite(d) || !fsdem__finite3(nrm))
            return fsdem__fail(&s->status, FSDEM_ERR_NAN,
                               "fsdem_pic_exclude_particles: the solid's distance at particle %d (%g, %g, %g) is not finite", p,
                               (double)s->px[p].x, (double)s->px[p].y, (double)s->px[p].z);
        s->ptmp[p] = x;
        n += s->pflag[p];
    }
    if (n) {
        if (remove) {
            fsdem__pic_remove_marked(s);
            s->removed += n;
        } else {
            memcpy(s->px, s->ptmp, sizeof(fsdem_vec3) * (size_t)s->np);
            memset(s->pflag, 0, (size_t)s->np); /* the steps mark particles to remove in it */
        }
        fsdem__pic_refresh(s);
    }
    if (count) *count = n;
    return fsdem__ok(&s->status);
}

/* ---- gauges ---- */

/* The axis of gravity and the sign of "up" along it; -1 when gravity is not along one axis. */
static int fsdem__pic_up_axis(const fsdem_pic *s, fsdem_real *up) {
    int a, best = -1, others = 0;
    for (a = 0; a < s->dim; ++a)
        if (fsdem__comp(s->desc.gravity, a) != 0) {
            best = a;
            others++;
        }
    if (others != 1) return -1;
    *up = fsdem__comp(s->desc.gravity, best) < 0 ? 1 : -1;
    return best;
}

/* Elevation of the highest free surface above p's column (FSDEM_PIC_GAUGE_KIND_LEVEL). */
static fsdem_real fsdem__pic_level(const fsdem_pic *s, fsdem_vec3 p) {
    fsdem_real up = 1, g[3];
    const int u = fsdem__pic_up_axis(s, &up);
    int c3[3], b, k, top, step;
    for (b = 0; b < 3; ++b) {
        g[b] = b < s->dim ? (fsdem__comp(p, b) - fsdem__comp(s->lo, b)) * s->inv_dx : 0;
        c3[b] = g[b] < 0 ? 0 : g[b] >= (fsdem_real)s->n[b] ? s->n[b] - 1 : (int)g[b];
    }
    top = up > 0 ? s->n[u] - 1 : 0;
    step = up > 0 ? -1 : 1;
    for (k = top; k >= 0 && k < s->n[u]; k += step) {
        int c, above;
        c3[u] = k;
        c = fsdem__mac_cell(&s->mac, c3[0], c3[1], c3[2]);
        if (s->ctype[c] == FSDEM_STENCIL_CELL_SOLID || !(s->phi[c] < 0)) continue;
        /* the centre of cell c is in water; the surface is where phi crosses 0 towards the cell above */
        if (k == top) return up > 0 ? fsdem__comp(s->hi, u) : fsdem__comp(s->lo, u);
        c3[u] = k - step;
        above = fsdem__mac_cell(&s->mac, c3[0], c3[1], c3[2]);
        c3[u] = k;
        {
            const fsdem_real centre = fsdem__comp(s->lo, u) + ((fsdem_real)k + (fsdem_real)0.5) * s->dx;
            const fsdem_real pa = s->ctype[above] == FSDEM_STENCIL_CELL_SOLID ? s->dx : s->phi[above];
            const fsdem_real t = pa > 0 ? s->phi[c] / (s->phi[c] - pa) : (fsdem_real)0.5;
            return centre + up * t * s->dx;
        }
    }
    return up > 0 ? fsdem__comp(s->lo, u) : fsdem__comp(s->hi, u);
}

/* Pressure at p (FSDEM_PIC_GAUGE_KIND_PRESSURE): trilinear between cell centres, or the mean over the
   non-solid cells within `radius`. */
static fsdem_real fsdem__pic_pressure_at(const fsdem_pic *s, fsdem_vec3 p, fsdem_real radius) {
    fsdem_real g[3], sum = 0;
    int b, q0, q1, q2, count = 0, c;
    if (radius > 0) {
        for (c = 0; c < s->ncell; ++c) {
            const fsdem_vec3 x = fsdem__mac_cell_pos(&s->mac, c % s->n[0], c / s->n[0] % s->n[1], c / (s->n[0] * s->n[1]));
            if (s->ctype[c] == FSDEM_STENCIL_CELL_SOLID || fsdem__norm(fsdem__sub(x, p)) > radius) continue;
            sum += s->pres[c];
            count++;
        }
        return count ? sum / (fsdem_real)count : 0;
    } else {
        fsdem__kernel kw;
        for (b = 0; b < 3; ++b) {
            const fsdem_real t = b < s->dim ? (fsdem__comp(p, b) - fsdem__comp(s->lo, b)) * s->inv_dx - (fsdem_real)0.5 : 0;
            g[b] = t < 0 ? 0 : t > (fsdem_real)(s->n[b] - 1) ? (fsdem_real)(s->n[b] - 1) : t;
        }
        fsdem__kernel_weights(&kw, s->dim, g, s->n, 0);
        for (q2 = 0; q2 < kw.count[2]; ++q2)
            for (q1 = 0; q1 < kw.count[1]; ++q1)
                for (q0 = 0; q0 < kw.count[0]; ++q0)
                    sum += kw.w[0][q0] * kw.w[1][q1] * kw.w[2][q2] *
                           s->pres[fsdem__mac_cell(&s->mac, kw.idx[0][q0], kw.idx[1][q1], kw.idx[2][q2])];
        return sum;
    }
}

static fsdem_real fsdem__pic_gauge_value(const fsdem_pic *s, int k) {
    return s->gauges.kind[k] == FSDEM_PIC_GAUGE_KIND_LEVEL ? fsdem__pic_level(s, s->gauges.at[k])
                                                      : fsdem__pic_pressure_at(s, s->gauges.at[k], s->gauges.radius[k]);
}

static void fsdem__pic_gauge_values(const void *solver, fsdem_real *out) {
    const fsdem_pic *s = (const fsdem_pic *)solver;
    int k;
    for (k = 0; k < s->gauges.count; ++k) out[k] = fsdem__pic_gauge_value(s, k);
}

fsdem_result fsdem_pic_add_gauge(fsdem_pic *s, fsdem_pic_gauge_kind kind, fsdem_vec3 position, fsdem_real radius, int *id) {
    fsdem_real up;
    if (id) *id = -1;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (kind == FSDEM_PIC_GAUGE_KIND_LEVEL && fsdem__pic_up_axis(s, &up) < 0)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_gauge: a level gauge needs gravity along one axis");
    return fsdem__gauges_add(&s->gauges, &s->status, &s->allocator, "fsdem_pic_add_gauge", (int)kind, position, radius, s->dim, s->lo,
                             s->hi, id);
}

fsdem_result fsdem_pic_gauge(const fsdem_pic *s, int id, fsdem_real *value) {
    if (!s || !value) return FSDEM_ERR_INVALID_ARG;
    if (id < 0 || id >= s->gauges.count) return FSDEM_ERR_NOT_FOUND;
    *value = fsdem__pic_gauge_value(s, id);
    return FSDEM_OK;
}

fsdem_result fsdem_pic_gauges_open(fsdem_pic *s, const char *path, fsdem_real interval) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__gauges_open(&s->gauges, &s->status, &s->allocator, "fsdem_pic_gauges_open", path, s->time, interval,
                              fsdem__pic_gauge_values, s);
}

fsdem_result fsdem_pic_gauges_hold(fsdem_pic *s, int hold) {
    return s ? fsdem__series_hold_call(&s->gauges.series, &s->status, "fsdem_pic_gauges_hold", hold) : FSDEM_ERR_INVALID_ARG;
}

fsdem_result fsdem_pic_gauges_close(fsdem_pic *s) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__gauges_close(&s->gauges, &s->status, &s->allocator, "fsdem_pic_gauges_close");
}

/* The part of cell c that obstacles and moving solids leave open: the mean open fraction of its
   faces (the domain's sides count as open; exact for cuts along the grid's planes). */
static fsdem_real fsdem__pic_open_volume(const fsdem_pic *s, int c) {
    const int i = c % s->n[0], j = c / s->n[0] % s->n[1], k = c / (s->n[0] * s->n[1]);
    fsdem_real sum = 0;
    int a, side;
    for (a = 0; a < s->dim; ++a)
        for (side = 0; side < 2; ++side) {
            const int f = fsdem__mac_face(&s->mac, a, i, j, k) + side * s->fstep[a][a];
            const fsdem_real co = s->copen[a][f] < 0 ? 0 : s->copen[a][f] > 1 ? 1 : s->copen[a][f];
            sum += s->sopen[a][f] < co ? s->sopen[a][f] : co;
        }
    return sum / (fsdem_real)(2 * s->dim);
}

fsdem_pic_stats fsdem_pic_get_stats(const fsdem_pic *s) {
    fsdem_pic_stats st;
    int c, p, a;
    double vol = 0, ke = 0, cellv;
    memset(&st, 0, sizeof st);
    if (!s) return st;
    cellv = pow((double)s->dx, (double)s->dim);
    for (c = 0; c < s->ncell; ++c) {
        double f = 1;
        if (s->ctype[c] == FSDEM_STENCIL_CELL_SOLID) continue;
        if (s->desc.free_surface) {
            f = 0.5 - (double)s->phi[c] * (double)s->inv_dx;
            f = f < 0 ? 0 : f > 1 ? 1 : f;
        }
        vol += f * (double)fsdem__pic_open_volume(s, c) * (double)s->cpor[c];
    }
    for (p = 0; p < s->np; ++p) ke += (double)fsdem__dot(s->pv[p], s->pv[p]);
    st.time = (fsdem_real)s->time;
    st.dt = s->dt_last;
    st.steps = s->steps;
    st.particles = s->np;
    st.fluid_cells = s->fluid_cells;
    st.fluid_volume = (fsdem_real)(vol * cellv);
    st.particle_volume = s->pvol * (fsdem_real)s->np;
    st.kinetic_energy = (fsdem_real)(0.5 * (double)s->desc.density * (double)s->pvol * ke);
    st.max_speed = fsdem__pic_umax(s, &a);
    st.max_divergence = s->max_div;
    st.divergence_before = s->div_before;
    st.pressure_iterations = s->p_iters;
    st.pressure_residual = s->p_res;
    st.viscosity_iterations = s->v_iters;
    st.density_iterations = s->d_iters;
    st.reseeded = s->reseeded;
    st.removed = s->removed;
    st.refused = s->refused;
    st.moved = s->moved;
    st.seconds_total = s->sec_total;
    st.seconds_pressure = s->sec_pressure;
    st.seconds_density = s->sec_density;
    st.memory_bytes = s->bytes;
    return st;
}
