/* ---- >>pic_transfer : kernels, particle-to-grid, grid-to-particle ---- */

/* Kernel weights of point x on the faces of axis a (face nodes sit half a cell off along the other
   axes). */
static void fsdem__pic_kernel(const fsdem_pic *s, int a, fsdem_vec3 x, int quadratic, fsdem__kernel *k) {
    fsdem_real g[3];
    int b;
    for (b = 0; b < 3; ++b)
        g[b] = b < s->dim ? (fsdem__comp(x, b) - fsdem__comp(s->lo, b)) * s->inv_dx - (b == a ? 0 : (fsdem_real)0.5) : 0;
    fsdem__kernel_weights(k, s->dim, g, s->fn[a], quadratic);
}

/* Linear interpolation of a face field of axis a at x. */
static fsdem_real fsdem__pic_interp_face(const fsdem_pic *s, const fsdem_real *field, int a, fsdem_vec3 x) {
    fsdem__kernel kw;
    fsdem_real sum = 0;
    int q0, q1, q2;
    fsdem__pic_kernel(s, a, x, 0, &kw);
    for (q2 = 0; q2 < kw.count[2]; ++q2) {
        int k = kw.idx[2][q2];
        for (q1 = 0; q1 < kw.count[1]; ++q1) {
            int j = kw.idx[1][q1];
            fsdem_real w12 = kw.w[2][q2] * kw.w[1][q1];
            int row = (k * s->fn[a][1] + j) * s->fn[a][0];
            for (q0 = 0; q0 < kw.count[0]; ++q0)
                sum += w12 * kw.w[0][q0] * field[row + kw.idx[0][q0]];
        }
    }
    return sum;
}

/* threaded: inside a team as on one thread: reads the grid only. */
static fsdem_vec3 fsdem__pic_interp_vel(const fsdem_pic *s, fsdem_real *const f[3], fsdem_vec3 x) {
    fsdem_vec3 v;
    v.x = fsdem__pic_interp_face(s, f[0], 0, x);
    v.y = fsdem__pic_interp_face(s, f[1], 1, x);
    v.z = s->dim == 3 ? fsdem__pic_interp_face(s, f[2], 2, x) : 0;
    return v;
}

/* Particle velocities (and APIC affine terms) to the faces: u = sum w m v / sum w m. Faces that
   received weight are marked valid. */
static void fsdem__pic_p2g(fsdem_pic *s) {
    int a, p, q0, q1, q2, f, quad = s->desc.kernel == FSDEM_PIC_KERNEL_QUADRATIC;
    fsdem__kernel kw;
    for (a = 0; a < s->dim; ++a) {
        fsdem_real *u = s->u[a], *m = s->wsum[a];
        const fsdem_vec3 *ca = s->pc[0] ? s->pc[a] : NULL;
        memset(u, 0, sizeof(fsdem_real) * (size_t)s->nface[a]);
        memset(m, 0, sizeof(fsdem_real) * (size_t)s->nface[a]);
        for (p = 0; p < s->np; ++p) {
            fsdem_vec3 x = s->px[p];
            fsdem_real va = fsdem__comp(s->pv[p], a);
            fsdem__pic_kernel(s, a, x, quad, &kw);
            for (q2 = 0; q2 < kw.count[2]; ++q2) {
                int k = kw.idx[2][q2];
                for (q1 = 0; q1 < kw.count[1]; ++q1) {
                    int j = kw.idx[1][q1];
                    fsdem_real w12 = kw.w[2][q2] * kw.w[1][q1];
                    int row = (k * s->fn[a][1] + j) * s->fn[a][0];
                    for (q0 = 0; q0 < kw.count[0]; ++q0) {
                        int i = kw.idx[0][q0];
                        fsdem_real w = w12 * kw.w[0][q0], v = va;
                        f = row + i;
                        if (ca) {
                            fsdem_vec3 xf = fsdem__mac_face_pos(&s->mac, a, i, j, k);
                            v += fsdem__dot(ca[p], fsdem__sub(xf, x));
                        }
                        m[f] += w;
                        u[f] += w * v;
                    }
                }
            }
        }
        for (f = 0; f < s->nface[a]; ++f) {
            s->fvalid[a][f] = m[f] > (fsdem_real)1e-9;
            u[f] = s->fvalid[a][f] ? u[f] / m[f] : 0;
        }
    }
}

/* The grid-to-particle transfer of particle p (`du` holds u_new - u_old (FLIP) in uold); returns
   nonzero when its new velocity is not finite. */
/* threaded: inside a team: one particle, written by its thread alone. */
FSDEM__FORCE_INLINE int fsdem__pic_g2p_one(fsdem_pic *s, int p, const int quad, fsdem_real ratio, const int apic, fsdem_real dfac) {
    int a, q0, q1, q2, b, bad = 0;
    fsdem__kernel kw;
    {
        fsdem_vec3 x = s->px[p];
        fsdem_real vnew[3] = {0, 0, 0};
        for (a = 0; a < s->dim; ++a) {
            fsdem_real pic = 0, flip = 0, c[3] = {0, 0, 0};
            const fsdem_real *u = s->u[a], *du = s->uold[a];
            fsdem__pic_kernel(s, a, x, quad, &kw);
            for (q2 = 0; q2 < kw.count[2]; ++q2) {
                int k = kw.idx[2][q2];
                for (q1 = 0; q1 < kw.count[1]; ++q1) {
                    int j = kw.idx[1][q1];
                    int row = (k * s->fn[a][1] + j) * s->fn[a][0];
                    for (q0 = 0; q0 < kw.count[0]; ++q0) {
                        int i = kw.idx[0][q0], f = row + i;
                        fsdem_real w = kw.w[2][q2] * kw.w[1][q1] * kw.w[0][q0];
                        pic += w * u[f];
                        if (ratio > 0) flip += w * du[f];
                        if (apic) {
                            if (quad) {
                                fsdem_vec3 d = fsdem__sub(fsdem__mac_face_pos(&s->mac, a, i, j, k), x);
                                c[0] += w * u[f] * d.x * dfac;
                                c[1] += w * u[f] * d.y * dfac;
                                c[2] += w * u[f] * d.z * dfac;
                            } else {
                                c[0] += kw.dw[0][q0] * kw.w[1][q1] * kw.w[2][q2] * u[f] * s->inv_dx;
                                c[1] += kw.w[0][q0] * kw.dw[1][q1] * kw.w[2][q2] * u[f] * s->inv_dx;
                                if (s->dim == 3) c[2] += kw.w[0][q0] * kw.w[1][q1] * kw.dw[2][q2] * u[f] * s->inv_dx;
                            }
                        }
                    }
                }
            }
            if (ratio > 0) vnew[a] = ratio * (fsdem__comp(s->pv[p], a) + flip) + (1 - ratio) * pic;
            else vnew[a] = pic;
            if (apic) {
                if (s->dim == 2) c[2] = 0;
                s->pc[a][p] = fsdem_v3(c[0], c[1], c[2]);
            }
        }
        s->pv[p] = fsdem_v3(vnew[0], vnew[1], vnew[2]);
        for (b = 0; b < s->dim; ++b) bad |= !fsdem__finite(vnew[b]);
    }
    return bad;
}

/* Grid to particles, every particle on its own (threaded); returns the first particle whose velocity
   is not finite, or -1. */
/* threaded: opens a team over the particles. */
static int fsdem__pic_g2p(fsdem_pic *s) {
    const int quad = s->desc.kernel == FSDEM_PIC_KERNEL_QUADRATIC, apic = s->desc.transfer == FSDEM_PIC_TRANSFER_APIC;
    const fsdem_real ratio = s->desc.transfer == FSDEM_PIC_TRANSFER_FLIP ? s->desc.flip_ratio : 0;
    const fsdem_real dfac = 4 * s->inv_dx * s->inv_dx;
    int p, first = s->np;
    FSDEM__OMP(parallel for schedule(static) reduction(min : first)
               num_threads(fsdem__team_for(s->np, FSDEM__TEAM_ITEMS, FSDEM__NO_CAP)))
    for (p = 0; p < s->np; ++p)
        if (fsdem__pic_g2p_one(s, p, quad, ratio, apic, dfac) && p < first) first = p;
    return first < s->np ? first : -1;
}
