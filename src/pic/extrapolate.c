/* ---- >>pic_extrapolate : velocity extrapolation into air and solids ---- */

/* Extends `field` (a face field, valid where fvalid is set) by `layers` rings of faces, each new
   face taking the mean of its valid neighbours along the grid axes (breadth first: only the
   current front is visited). Faces still invalid get 0. */
static void fsdem__pic_extrapolate(fsdem_pic *s, fsdem_real *const field[3], int layers) {
    int a, b, i, j, k, layer;
    for (a = 0; a < s->dim; ++a) {
        unsigned char *valid = s->fvalid[a], *queued = s->fvalid2[a];
        fsdem_real *tmp = s->ftmp[a], *u = field[a];
        const int *fn = s->fn[a];
        int *queue = s->fqueue, head = 0, tail = 0, q;
        memset(queued, 0, (size_t)s->nface[a]);
        /* the first front: invalid faces next to a valid one */
        for (k = 0; k < fn[2]; ++k)
            for (j = 0; j < fn[1]; ++j)
                for (i = 0; i < fn[0]; ++i) {
                    int f = (k * fn[1] + j) * fn[0] + i, coord[3], near = 0;
                    if (valid[f]) continue;
                    coord[0] = i;
                    coord[1] = j;
                    coord[2] = k;
                    for (b = 0; b < s->dim && !near; ++b) {
                        int st = s->fstep[a][b];
                        if ((coord[b] > 0 && valid[f - st]) || (coord[b] < fn[b] - 1 && valid[f + st])) near = 1;
                    }
                    if (near) {
                        queue[tail++] = f;
                        queued[f] = 1;
                    }
                }
        for (layer = 0; layer < layers && head < tail; ++layer) {
            int end = tail;
            for (q = head; q < end; ++q) {
                int f = queue[q], cnt = 0, coord[3], rest = f;
                fsdem_real sum = 0;
                coord[0] = rest % fn[0];
                rest /= fn[0];
                coord[1] = rest % fn[1];
                coord[2] = rest / fn[1];
                for (b = 0; b < s->dim; ++b) {
                    int st = s->fstep[a][b];
                    if (coord[b] > 0 && valid[f - st]) {
                        sum += u[f - st];
                        ++cnt;
                    }
                    if (coord[b] < fn[b] - 1 && valid[f + st]) {
                        sum += u[f + st];
                        ++cnt;
                    }
                }
                tmp[f] = cnt ? sum / (fsdem_real)cnt : 0;
            }
            for (q = head; q < end; ++q) {
                u[queue[q]] = tmp[queue[q]];
                valid[queue[q]] = 1;
            }
            if (layer + 1 < layers)
                for (q = head; q < end; ++q) {
                    int f = queue[q], coord[3], rest = f;
                    coord[0] = rest % fn[0];
                    rest /= fn[0];
                    coord[1] = rest % fn[1];
                    coord[2] = rest / fn[1];
                    for (b = 0; b < s->dim; ++b) {
                        int st = s->fstep[a][b];
                        if (coord[b] > 0 && !valid[f - st] && !queued[f - st]) {
                            queue[tail++] = f - st;
                            queued[f - st] = 1;
                        }
                        if (coord[b] < fn[b] - 1 && !valid[f + st] && !queued[f + st]) {
                            queue[tail++] = f + st;
                            queued[f + st] = 1;
                        }
                    }
                }
            head = end;
        }
        for (i = 0; i < s->nface[a]; ++i)
            if (!valid[i]) u[i] = 0;
    }
}

/* The velocity of closed face g of axis a at the start of the step: a moving solid's start velocity
   (fsdem_pic_coupling.start_velocity), else the face's solid velocity. The viscous solve takes it
   as its no-slip value and the FLIP reference as the face's velocity; the projection takes the
   velocity at the end of the step (us), which holds the step's gravity and the pressure's answer. */
static fsdem_real fsdem__pic_solid_start(const fsdem_pic *s, int a, int g) {
    return s->copen[a][g] < s->sopen[a][g] ? s->cvstart[a][g] : s->us[a][g];
}

/* Faces fully covered by a solid (E = 0) carry the solid's velocity, at the start of the step or at
   its end. */
static void fsdem__pic_solid_faces(fsdem_pic *s, fsdem_real *const field[3], int at_start) {
    int a, f;
    for (a = 0; a < s->dim; ++a)
        for (f = 0; f < s->nface[a]; ++f)
            if (s->E[a][f] <= 0) field[a][f] = at_start ? fsdem__pic_solid_start(s, a, f) : s->us[a][f];
}

static int fsdem__pic_layers(const fsdem_pic *s) {
    return s->desc.extrapolation_layers > 0 ? s->desc.extrapolation_layers : (int)ceil(s->desc.cfl_max) + 2;
}
