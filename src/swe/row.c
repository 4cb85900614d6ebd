/* ---- >>swe_row : reconstruction, predictor and x faces of a row ---- */

/* Limited slope (per cell) from the backward and forward differences. */
FSDEM__FORCE_INLINE fsdem_real fsdem__swe_limit(int limiter, fsdem_real a, fsdem_real b) {
    fsdem_real aa = (fsdem_real)fabs(a), ab = (fsdem_real)fabs(b), m;
    if (limiter == FSDEM_SWE_LIMITER_MINMOD) {
        /* (sign a + sign b)/2 min(|a|, |b|): arithmetic only, no data-dependent branch */
        m = aa < ab ? a : b;
        return a * b > 0 ? m : 0;
    }
    if (a * b <= 0) return 0;
    switch (limiter) {
    case FSDEM_SWE_LIMITER_VAN_LEER: return 2 * a * b / (a + b);
    case FSDEM_SWE_LIMITER_MC:
        m = (fsdem_real)0.5 * (aa + ab);
        if (2 * aa < m) m = 2 * aa;
        if (2 * ab < m) m = 2 * ab;
        return a > 0 ? m : -m;
    case FSDEM_SWE_LIMITER_SUPERBEE: {
        fsdem_real m1 = 2 * aa < ab ? 2 * aa : ab, m2 = aa < 2 * ab ? aa : 2 * ab;
        m = m1 > m2 ? m1 : m2;
        return a > 0 ? m : -m;
    }
    default: return aa < ab ? a : b;
    }
}

/* Per-step constants and one band's accumulators. */
typedef struct fsdem__swe_ctx {
    fsdem_real dt, lx, ly, g, dry, tiny, rain_dt, idx, idy, manning, visc;
    int order, limiter, two_d, sources, friction;
    fsdem__swe_work *w; /* the band's work rows */
    fsdem_real *bterm;  /* where the boundary-face volumes go (NULL: a row beside the band, not kept) */
    fsdem__swe_tally t; /* results */
} fsdem__swe_ctx;

/* Row j of the primitive ring (slot j mod slots), pointer to its `var` array (0 eta, 1 h, 2 u, 3 v). */
static fsdem_real *fsdem__swe_prim(const fsdem__swe_work *w, int j, int var) {
    int slot = ((j % w->slots) + w->slots) % w->slots;
    return w->prim + ((size_t)slot * 4 + (size_t)var) * (size_t)(w->nx + 2);
}

static fsdem__swe_rowcell *fsdem__swe_rowcells(const fsdem__swe_work *w, int j) {
    return w->rows + (size_t)(j & 1) * (size_t)w->nx;
}

/* Index of a boundary face in the step's list (bterm), in the order a single sweep meets them: the
   west and east faces of row 0, the south side, then the west and east faces of each next row, and
   the north side last. */
static int fsdem__swe_bterm_west(const fsdem_swe *s, int j) { return j == 0 ? 0 : s->nx + 2 * j; }
static int fsdem__swe_bterm_side(const fsdem_swe *s, int north, int i) { return north ? s->nx + 2 * s->ny + i : 2 + i; }

/* The volume (m^3, positive inwards) through boundary face `index` in this step. */
static void fsdem__swe_bterm_put(const fsdem__swe_ctx *c, int index, fsdem_real volume) {
    if (c->bterm) c->bterm[index] = volume;
}

/* The state arrays (eta, qx, qy) of row `src`: the band's copy of a row beside it, or the live row. */
static void fsdem__swe_state_row(const fsdem_swe *s, const fsdem__swe_work *w, int src, const fsdem_real **eta,
                                 const fsdem_real **qx, const fsdem_real **qy) {
    const size_t nx = (size_t)s->nx;
    int q;
    for (q = 0; q < 4; ++q)
        if (s->dim == 2 && w->halo_row[q] == src) {
            *eta = w->halo + 3 * q * nx;
            *qx = *eta + nx;
            *qy = *qx + nx;
            return;
        }
    *eta = s->eta + (size_t)src * nx;
    *qx = s->qx + (size_t)src * nx;
    *qy = s->qy + (size_t)src * nx;
}

/* Loads row `src` of the state as primitive values into ring row `dst`, with one ghost cell at each
   end. A ghost row (dst != src) beyond a wall mirrors `src` (v flips); beyond other sides it copies
   h, u, v and extrapolates the bed linearly from row `ext` (ext < 0: flat), so a uniform flow down
   a slope keeps its gravity forcing in the boundary cells. Ghost cells at the row ends do the same. */
static void fsdem__swe_load_row(const fsdem_swe *s, fsdem__swe_work *w, int src, int dst, int flip_v, int ext) {
    fsdem_real *e = fsdem__swe_prim(w, dst, 0) + 1, *h = fsdem__swe_prim(w, dst, 1) + 1;
    fsdem_real *u = fsdem__swe_prim(w, dst, 2) + 1, *v = fsdem__swe_prim(w, dst, 3) + 1;
    const fsdem_real *bed = s->bed + (size_t)src * (size_t)s->nx, *eta, *qx, *qy;
    fsdem_real dry = s->desc.dry_depth, vs = flip_v ? -1 : 1;
    int i, nx = s->nx;
    fsdem__swe_state_row(s, w, src, &eta, &qx, &qy);
    for (i = 0; i < nx; ++i) {
        fsdem_real ee = eta[i], hh = ee - bed[i];
        e[i] = ee;
        if (hh >= dry) {
            fsdem_real inv = 1 / hh;
            h[i] = hh;
            u[i] = qx[i] * inv;
            v[i] = vs * qy[i] * inv;
        } else {
            h[i] = hh > 0 ? hh : 0;
            u[i] = v[i] = 0;
        }
    }
    if (ext >= 0) {
        const fsdem_real *bx = s->bed + (size_t)ext * (size_t)nx;
        for (i = 0; i < nx; ++i) e[i] += bed[i] - bx[i];
    }
    e[-1] = e[0];
    h[-1] = h[0];
    v[-1] = v[0];
    if (s->bnd[FSDEM_SIDE_XMIN].type == FSDEM_SWE_BC_WALL) u[-1] = -u[0];
    else {
        u[-1] = u[0];
        if (nx > 1) e[-1] += bed[0] - bed[1];
    }
    e[nx] = e[nx - 1];
    h[nx] = h[nx - 1];
    v[nx] = v[nx - 1];
    if (s->bnd[FSDEM_SIDE_XMAX].type == FSDEM_SWE_BC_WALL) u[nx] = -u[nx - 1];
    else {
        u[nx] = u[nx - 1];
        if (nx > 1) e[nx] += bed[nx - 1] - bed[nx - 2];
    }
}

/* Factor by which Manning friction scales a unit discharge of magnitude qm (m^2/s) at depth h over
   `dt`, by backward Euler of dq/dt = -C |q| q with C = g n^2 / h^(7/3), solved exactly:
   |q| = 2 |q*| / (1 + sqrt(1 + 4 dt C |q*|)). It never reverses the flow and is stable at any depth. */
static inline fsdem_real fsdem__swe_manning_factor(fsdem_real g, fsdem_real n, fsdem_real h, fsdem_real qm, fsdem_real dt) {
    const fsdem_real C = g * n * n / (h * h * (fsdem_real)cbrt(h));
    return 2 / (1 + (fsdem_real)sqrt(1 + 4 * dt * C * qm));
}

/* Completes cell k: adds the increments, the sources and friction, writes the state back and
   updates the step's statistics. */
static inline void fsdem__swe_finish(fsdem_swe *s, fsdem__swe_ctx *c, int k, fsdem_real de, fsdem_real dqx,
                                     fsdem_real dqy) {
    fsdem_real e = s->eta[k] + de + c->rain_dt, qx = s->qx[k] + dqx, qy = s->qy[k] + dqy, h;
    if (s->blocked && s->blocked[k]) return; /* a solid: no water, no update */
    if (c->sources) {
        qx += c->dt * s->sx[k];
        qy += c->dt * s->sy[k];
    }
    if (!c->two_d) qy = 0;
    /* the scheme leaks geometrically decaying momentum ahead of a wave into still water; flush it
       long before it reaches subnormal numbers, whose arithmetic is ~100 times slower */
    if (fabs(qx) < FSDEM__SWE_QTINY) qx = 0;
    if (fabs(qy) < FSDEM__SWE_QTINY) qy = 0;
    h = e - s->bed[k];
    if (h < c->dry) {
        qx = qy = 0;
        if (h < 0) c->t.negative = 1;
    } else {
        fsdem_real n = s->manning ? s->manning[k] : c->manning, u, v, cc, w;
        if (n > 0) {
            fsdem_real qm = (fsdem_real)sqrt(qx * qx + qy * qy);
            if (qm > 0) {
                const fsdem_real fac = fsdem__swe_manning_factor(c->g, n, h, qm, c->dt);
                qx *= fac;
                qy *= fac;
            }
        }
        u = qx / h;
        v = qy / h;
        cc = (fsdem_real)sqrt(c->g * h);
        w = ((u < 0 ? -u : u) + cc) * c->idx + ((v < 0 ? -v : v) + cc) * c->idy;
        if (w > c->t.wave) c->t.wave = w;
        if (u * u + v * v > c->t.speed2) c->t.speed2 = u * u + v * v;
        if (h > c->t.hmax) c->t.hmax = h;
        c->t.wet++;
    }
    if (!((e + qx + qy) - (e + qx + qy) == 0) && c->t.bad < 0) c->t.bad = k;
    s->eta[k] = e;
    s->qx[k] = qx;
    s->qy[k] = qy;
}

/* Explicit eddy-viscosity increment of cell i of row j (time-n velocities, face depth the smaller of
   the two cells, so nothing diffuses into dry cells): dt div(nu h grad u). */
static void fsdem__swe_viscous(const fsdem__swe_ctx *c, int j, int i, fsdem_real *dqx,
                               fsdem_real *dqy) {
    const fsdem_real *h = fsdem__swe_prim(c->w, j, 1) + 1, *u = fsdem__swe_prim(c->w, j, 2) + 1, *v = fsdem__swe_prim(c->w, j, 3) + 1;
    fsdem_real kx = c->visc * c->dt * c->idx * c->idx, hc = h[i], fx, fy;
    fsdem_real hw = h[i - 1] < hc ? h[i - 1] : hc, he = h[i + 1] < hc ? h[i + 1] : hc;
    fx = kx * (he * (u[i + 1] - u[i]) - hw * (u[i] - u[i - 1]));
    fy = kx * (he * (v[i + 1] - v[i]) - hw * (v[i] - v[i - 1]));
    if (c->two_d) {
        const fsdem_real *hs = fsdem__swe_prim(c->w, j - 1, 1) + 1, *us = fsdem__swe_prim(c->w, j - 1, 2) + 1;
        const fsdem_real *vs = fsdem__swe_prim(c->w, j - 1, 3) + 1, *hn = fsdem__swe_prim(c->w, j + 1, 1) + 1;
        const fsdem_real *un = fsdem__swe_prim(c->w, j + 1, 2) + 1, *vn = fsdem__swe_prim(c->w, j + 1, 3) + 1;
        fsdem_real ky = c->visc * c->dt * c->idy * c->idy;
        fsdem_real hS = hs[i] < hc ? hs[i] : hc, hN = hn[i] < hc ? hn[i] : hc;
        fx += ky * (hN * (un[i] - u[i]) - hS * (u[i] - us[i]));
        fy += ky * (hN * (vn[i] - v[i]) - hS * (v[i] - vs[i]));
    }
    *dqx = fx;
    *dqy = fy;
}

/* The primitive rows around row j (eta, h, u, v of rows j, j - 1 and j + 1; the outer ones only
   in 2D), each offset past its ghost cell so index -1 and nx are the ghosts. */
typedef struct fsdem__swe_rows {
    const fsdem_real *e, *h, *u, *v;     /* row j */
    const fsdem_real *se, *sh, *su, *sv; /* row j - 1 (south) */
    const fsdem_real *ne, *nh, *nu, *nv; /* row j + 1 (north) */
    const unsigned char *b, *sb, *nb;    /* blocked flags of rows j, j - 1, j + 1 (NULL: none there) */
} fsdem__swe_rows;

/* A cell's reconstruction: its centre values after the Hancock predictor, and the limited slopes
   per cell width along x and y, each in the order eta, h, u, v. */
typedef struct fsdem__swe_recon {
    fsdem_real e, h, u, v;
    fsdem_real sx[4], sy[4];
} fsdem__swe_recon;

/* Hancock predictor of a wet cell (>>impl_swe item 2): advances r's centre values by dt/2 with its
   own face fluxes, the pressure/bed-slope pair g h deta, the momentum source (sx, sy) and half a
   step of Manning friction n; skipped (counted as a fallback) where it would make a face depth
   negative. */
FSDEM__FORCE_INLINE void fsdem__swe_hancock(fsdem__swe_ctx *c, fsdem__swe_recon *r, const int two_d, fsdem_real srcx,
                                            fsdem_real srcy, fsdem_real n) {
    const fsdem_real g = c->g, half = (fsdem_real)0.5, hlx = half * c->lx, hly = half * c->ly, hdt = half * c->dt;
    const fsdem_real h = r->h, u = r->u, w = r->v;
    const fsdem_real hE = h + half * r->sx[1], hW = h - half * r->sx[1], uE = u + half * r->sx[2], uW = u - half * r->sx[2];
    const fsdem_real qE = hE * uE, qW = hW * uW, shx = (fsdem_real)fabs(r->sx[1]), shy = (fsdem_real)fabs(r->sy[1]);
    fsdem_real de, dqx, dqy, hp;
    de = -hlx * (qE - qW);
    dqx = -hlx * (qE * uE - qW * uW + g * h * r->sx[0]);
    dqy = -hlx * (qE * (w + half * r->sx[3]) - qW * (w - half * r->sx[3]));
    if (two_d) {
        const fsdem_real hN = h + half * r->sy[1], hS = h - half * r->sy[1], vN = w + half * r->sy[3], vS = w - half * r->sy[3];
        const fsdem_real rN = hN * vN, rS = hS * vS;
        de -= hly * (rN - rS);
        dqx -= hly * (rN * (u + half * r->sy[2]) - rS * (u - half * r->sy[2]));
        dqy -= hly * (rN * vN - rS * vS + g * h * r->sy[0]);
    }
    dqx += hdt * srcx;
    dqy += hdt * srcy;
    hp = h + de;
    if (n > 0 && hp >= c->dry) {
        /* half-step friction, as in the corrector (>>impl_swe item 5), so a steady frictional flow
           has face velocities equal to its cell velocities */
        const fsdem_real fx = h * u + dqx, fy = two_d ? h * w + dqy : 0, qm = (fsdem_real)sqrt(fx * fx + fy * fy);
        if (qm > 0) {
            const fsdem_real fac = fsdem__swe_manning_factor(g, n, hp, qm, hdt) - 1;
            dqx += fx * fac;
            dqy += fy * fac;
        }
    }
    if (!(hp >= half * (shx > shy ? shx : shy) && hp > 0)) {
        c->t.fallbacks++;
        return;
    }
    if (hp >= c->dry) {
        const fsdem_real inv = 1 / hp;
        r->u = (h * u + dqx) * inv;
        r->v = two_d ? (h * w + dqy) * inv : 0;
    } else {
        r->u = r->v = 0;
    }
    r->e += de;
    r->h = hp;
}

/* Reconstruction of cell i of the rows `p`: limited slopes (first order: none), the Hancock
   predictor, and the cell's contribution to the acceleration bound of the next dt. A blocked
   neighbour enters as the mirror image of the cell (normal velocity reversed), as the ghost cell
   beyond a WALL side does, so a wall of blocked cells and a WALL side give the same flow. */
FSDEM__FORCE_INLINE void fsdem__swe_reconstruct(const fsdem_swe *s, fsdem__swe_ctx *c, const fsdem__swe_rows *p, int j,
                                                int i, const int limiter, const int two_d, fsdem__swe_recon *r) {
    const int k = j * s->nx + i;
    const fsdem_real *row[4] = {p->e, p->h, p->u, p->v};
    const fsdem_real *srow[4] = {p->se, p->sh, p->su, p->sv}, *nrow[4] = {p->ne, p->nh, p->nu, p->nv};
    fsdem_real w[4], e[4], so[4], no[4];
    int a;
    for (a = 0; a < 4; ++a) {
        w[a] = row[a][i - 1];
        e[a] = row[a][i + 1];
        so[a] = two_d ? srow[a][i] : 0;
        no[a] = two_d ? nrow[a][i] : 0;
        r->sx[a] = r->sy[a] = 0;
    }
    r->e = p->e[i];
    r->h = p->h[i];
    r->u = p->u[i];
    r->v = p->v[i];
    if (p->b) {
        const fsdem_real mirror_x[4] = {r->e, r->h, -r->u, r->v}, mirror_y[4] = {r->e, r->h, r->u, -r->v};
        for (a = 0; a < 4; ++a) {
            if (i > 0 && p->b[i - 1]) w[a] = mirror_x[a];
            if (i < s->nx - 1 && p->b[i + 1]) e[a] = mirror_x[a];
            if (p->sb && p->sb[i]) so[a] = mirror_y[a];
            if (p->nb && p->nb[i]) no[a] = mirror_y[a];
        }
    }
    /* a dry cell among dry neighbours has nothing to reconstruct or predict */
    if (c->order == 2 &&
        !(r->h < c->tiny && w[1] < c->tiny && e[1] < c->tiny && (!two_d || (so[1] < c->tiny && no[1] < c->tiny)))) {
        const fsdem_real centre[4] = {r->e, r->h, r->u, r->v};
        for (a = 0; a < 4; ++a) {
            r->sx[a] = fsdem__swe_limit(limiter, centre[a] - w[a], e[a] - centre[a]);
            if (two_d) r->sy[a] = fsdem__swe_limit(limiter, centre[a] - so[a], no[a] - centre[a]);
        }
        if (r->h >= c->dry)
            fsdem__swe_hancock(c, r, two_d, c->sources ? s->sx[k] : 0, c->sources ? s->sy[k] : 0,
                               c->friction ? (s->manning ? s->manning[k] : c->manning) : 0);
    }
    if (r->h >= c->dry) {
        /* acceleration bound for the next step's dt (g |grad eta| with minmod slopes, which vanish
           at a lake's shore and at a dam; a thin film on a slope feels the slope) */
        const int reuse = limiter == FSDEM_SWE_LIMITER_MINMOD && c->order == 2;
        const fsdem_real ax = reuse ? r->sx[0] : fsdem__swe_limit(FSDEM_SWE_LIMITER_MINMOD, p->e[i] - w[0], e[0] - p->e[i]);
        fsdem_real acc = (ax < 0 ? -ax : ax) * c->idx * c->idx;
        if (two_d) {
            const fsdem_real ay = reuse ? r->sy[0] : fsdem__swe_limit(FSDEM_SWE_LIMITER_MINMOD, p->e[i] - so[0], no[0] - p->e[i]);
            acc += (ay < 0 ? -ay : ay) * c->idy * c->idy;
        }
        if (acc > c->t.accel) c->t.accel = acc;
    }
}

/* Row j: reconstruction and predictor of every cell (stored for the y faces in 2D), the x faces, and
   the x-direction increments (2D: into the accumulator row; 1D: the cells are finished here). */
FSDEM__FORCE_INLINE void fsdem__swe_row_impl(fsdem_swe *s, fsdem__swe_ctx *c, int j, const int limiter,
                                                  const int two_d) {
    const int nx = s->nx;
    const fsdem_real g = c->g, lx = c->lx, half = (fsdem_real)0.5;
    fsdem_real Ee = 0, Eh = 0, Eu = 0, Ev = 0; /* east state of the previous cell */
    fsdem_real Wm = 0, Wa = 0, Wt = 0, Wh = 0, We = 0; /* west-face data of the previous cell */
    fsdem_real vx = 0, vy = 0; /* viscous increment of the previous cell */
    fsdem__swe_rowcell *rc = two_d ? fsdem__swe_rowcells(c->w, j) : NULL;
    fsdem__swe_rows p;
    fsdem__swe_flux f;
    int i;
    p.e = fsdem__swe_prim(c->w, j, 0) + 1;
    p.h = fsdem__swe_prim(c->w, j, 1) + 1;
    p.u = fsdem__swe_prim(c->w, j, 2) + 1;
    p.v = fsdem__swe_prim(c->w, j, 3) + 1;
    p.se = fsdem__swe_prim(c->w, j - 1, 0) + 1;
    p.sh = fsdem__swe_prim(c->w, j - 1, 1) + 1;
    p.su = fsdem__swe_prim(c->w, j - 1, 2) + 1;
    p.sv = fsdem__swe_prim(c->w, j - 1, 3) + 1;
    p.ne = fsdem__swe_prim(c->w, j + 1, 0) + 1;
    p.nh = fsdem__swe_prim(c->w, j + 1, 1) + 1;
    p.nu = fsdem__swe_prim(c->w, j + 1, 2) + 1;
    p.nv = fsdem__swe_prim(c->w, j + 1, 3) + 1;
    p.b = s->blocked ? s->blocked + (size_t)j * (size_t)nx : NULL;
    p.sb = p.b && j > 0 ? p.b - nx : NULL;
    p.nb = p.b && j < s->ny - 1 ? p.b + nx : NULL;
    for (i = 0; i <= nx; ++i) {
        fsdem__swe_recon r;
        fsdem_real cvx = 0, cvy = 0;
        if (i < nx) {
            fsdem__swe_reconstruct(s, c, &p, j, i, limiter, two_d, &r);
            if (two_d) {
                fsdem__swe_rowcell *q = rc + i;
                q->n[0] = r.e + half * r.sy[0];
                q->n[1] = r.h + half * r.sy[1];
                q->n[2] = r.v + half * r.sy[3];
                q->n[3] = r.u + half * r.sy[2];
                q->s[0] = r.e - half * r.sy[0];
                q->s[1] = r.h - half * r.sy[1];
                q->s[2] = r.v - half * r.sy[3];
                q->s[3] = r.u - half * r.sy[2];
            }
            if (c->visc > 0) fsdem__swe_viscous(c, j, i, &cvx, &cvy);
            /* ---- face i - 1/2 ---- */
            if (i == 0) {
                fsdem__swe_boundary_flux(s, FSDEM_SIDE_XMIN, 0, r.e - half * r.sx[0], r.h - half * r.sx[1], r.u - half * r.sx[2],
                                         r.v - half * r.sx[3], &f);
                fsdem__swe_bterm_put(c, fsdem__swe_bterm_west(s, j), f.mass * s->dy * c->dt);
            } else if (p.b && (p.b[i - 1] || p.b[i])) {
                /* a face of a blocked cell reflects; between two blocked cells nothing moves */
                if (!p.b[i]) fsdem__swe_wall_flux(s, 0, r.e - half * r.sx[0], r.h - half * r.sx[1], r.u - half * r.sx[2],
                                                  r.v - half * r.sx[3], &f);
                else if (!p.b[i - 1]) fsdem__swe_wall_flux(s, 1, Ee, Eh, Eu, Ev, &f);
                else memset(&f, 0, sizeof f);
            } else {
                fsdem__swe_riemann(g, c->tiny, Ee, Eh, Eu, Ev, r.e - half * r.sx[0], r.h - half * r.sx[1], r.u - half * r.sx[2],
                                   r.v - half * r.sx[3], &f);
            }
            Ee = r.e + half * r.sx[0]; /* the east face state, for face i + 1/2 */
            Eh = r.h + half * r.sx[1];
            Eu = r.u + half * r.sx[2];
            Ev = r.v + half * r.sx[3];
        } else {
            fsdem__swe_boundary_flux(s, FSDEM_SIDE_XMAX, 1, Ee, Eh, Eu, Ev, &f);
            fsdem__swe_bterm_put(c, fsdem__swe_bterm_west(s, j) + 1, -(f.mass * s->dy * c->dt));
        }
        if (i > 0) {
            /* cell i - 1 has both x faces now */
            fsdem_real de = -lx * (f.mass - Wm);
            fsdem_real dqx = -lx * (f.aL - Wa + half * g * (f.hL + Wh) * (f.eL - We)) + vx;
            fsdem_real dqy = -lx * (f.tan - Wt) + vy;
            if (two_d) {
                rc[i - 1].acc[0] = de;
                rc[i - 1].acc[1] = dqx;
                rc[i - 1].acc[2] = dqy;
            } else {
                fsdem__swe_finish(s, c, i - 1, de, dqx, dqy);
            }
        }
        Wm = f.mass;
        Wa = f.aR;
        Wt = f.tan;
        Wh = f.hR;
        We = f.eR;
        vx = cvx;
        vy = cvy;
    }
}

/* The row kernel specialised for each limiter and dimension, so the inner loop has no switch. */
static void fsdem__swe_row(fsdem_swe *s, fsdem__swe_ctx *c, int j) {
    if (c->two_d) {
        switch (c->limiter) {
        case FSDEM_SWE_LIMITER_VAN_LEER: fsdem__swe_row_impl(s, c, j, FSDEM_SWE_LIMITER_VAN_LEER, 1); break;
        case FSDEM_SWE_LIMITER_MC: fsdem__swe_row_impl(s, c, j, FSDEM_SWE_LIMITER_MC, 1); break;
        case FSDEM_SWE_LIMITER_SUPERBEE: fsdem__swe_row_impl(s, c, j, FSDEM_SWE_LIMITER_SUPERBEE, 1); break;
        default: fsdem__swe_row_impl(s, c, j, FSDEM_SWE_LIMITER_MINMOD, 1); break;
        }
    } else {
        switch (c->limiter) {
        case FSDEM_SWE_LIMITER_VAN_LEER: fsdem__swe_row_impl(s, c, j, FSDEM_SWE_LIMITER_VAN_LEER, 0); break;
        case FSDEM_SWE_LIMITER_MC: fsdem__swe_row_impl(s, c, j, FSDEM_SWE_LIMITER_MC, 0); break;
        case FSDEM_SWE_LIMITER_SUPERBEE: fsdem__swe_row_impl(s, c, j, FSDEM_SWE_LIMITER_SUPERBEE, 0); break;
        default: fsdem__swe_row_impl(s, c, j, FSDEM_SWE_LIMITER_MINMOD, 0); break;
        }
    }
}
