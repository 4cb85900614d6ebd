/* ---- >>mps_operators : gradient, divergence, Laplacian ---- */

/* The 3 x 3 matrix (rows) that turns the kernel sum of the gradient at particle i into the
   gradient: d/n0 times the identity for the forms of Eq. 8, the inverse of the moment matrix
   M = sum_j w_ij (r_j - r_i)(r_j - r_i)^T / (|r_j - r_i|^2 eps_j) (DUMMY neighbours included) for
   FSDEM_MPS_GRADIENT_MODEL_CORRECTED, or d/n0 again where M is singular to rounding (a neighbourhood
   that does not span the plane or space, e.g. a lone particle or a line of them). */
static void fsdem__mps_gradient_transform(const fsdem_mps *s, int i, fsdem_vec3 T[3]) {
    const fsdem_real plain = (fsdem_real)s->dim / s->n0;
    double m[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, det, c[3][3];
    int e, a, b;
    T[0] = fsdem_v3(plain, 0, 0);
    T[1] = fsdem_v3(0, plain, 0);
    T[2] = fsdem_v3(0, 0, plain);
    if (s->desc.gradient != FSDEM_MPS_GRADIENT_MODEL_CORRECTED) return;
    for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
        const int j = s->nb[e];
        const fsdem_vec3 r = fsdem__mps_sep(s, i, j);
        const double r2 = (double)fsdem__dot(r, r), rv[3] = {(double)r.x, (double)r.y, (double)r.z};
        if (!(r2 > 0)) continue;
        for (a = 0; a < 3; ++a)
            for (b = 0; b < 3; ++b) m[a][b] += rv[a] * rv[b] * (double)(s->nbw[e] / s->eps[j]) / r2;
    }
    if (s->dim == 2) m[2][2] = 1, m[0][2] = m[2][0] = m[1][2] = m[2][1] = 0;
    /* cofactors and determinant; singular when det is tiny against the product of the diagonal */
    c[0][0] = m[1][1] * m[2][2] - m[1][2] * m[2][1];
    c[0][1] = m[0][2] * m[2][1] - m[0][1] * m[2][2];
    c[0][2] = m[0][1] * m[1][2] - m[0][2] * m[1][1];
    c[1][0] = m[1][2] * m[2][0] - m[1][0] * m[2][2];
    c[1][1] = m[0][0] * m[2][2] - m[0][2] * m[2][0];
    c[1][2] = m[0][2] * m[1][0] - m[0][0] * m[1][2];
    c[2][0] = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    c[2][1] = m[0][1] * m[2][0] - m[0][0] * m[2][1];
    c[2][2] = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    det = m[0][0] * c[0][0] + m[0][1] * c[1][0] + m[0][2] * c[2][0];
    if (!(det > 1e-6 * m[0][0] * m[1][1] * m[2][2])) return;
    for (a = 0; a < 3; ++a) T[a] = fsdem_v3((fsdem_real)(c[a][0] / det), (fsdem_real)(c[a][1] / det), (fsdem_real)(c[a][2] / det));
    if (s->dim == 2) T[2] = fsdem__zero3();
}

/* T v for the rows T of fsdem__mps_gradient_transform. */
static fsdem_vec3 fsdem__mps_apply(const fsdem_vec3 T[3], fsdem_vec3 v) {
    return fsdem_v3(fsdem__dot(T[0], v), fsdem__dot(T[1], v), fsdem__dot(T[2], v));
}

/* Gradient of phi at particle i (seed 002 Eq. 8): the sum form (phi_j + phi_i) of the seed, or
   Koshizuka et al. (1998) (phi_j - min phi) with the smallest value of i and its non-DUMMY
   neighbours (desc.gradient). A DUMMY neighbour j takes the ghost value phi_i + ghost.(r_j - r_i):
   the pressure step passes ghost = rho g, the hydrostatic extrapolation from i, so the solid
   behind the wall layer pushes as a full neighbourhood of liquid would (skipping the DUMMY
   particles instead leaves the sum form one-sided and pulls particles into walls); the public
   operator passes 0 (a mirror value, zero normal derivative). With FSDEM_MPS_GRADIENT_MODEL_CORRECTED the
   form is (phi_j - phi_i) and the sum is multiplied by the inverse moment matrix of i (the factor
   d/n0 of Eq. 8 cancels in it). */
static fsdem_vec3 fsdem__mps_grad_at(const fsdem_mps *s, const fsdem_real *phi, int i, fsdem_vec3 ghost) {
    fsdem_vec3 g = fsdem__zero3(), T[3];
    fsdem_real base = s->desc.gradient == FSDEM_MPS_GRADIENT_MODEL_CORRECTED ? -phi[i] : phi[i];
    /* a DUMMY particle higher than the hydrostatic extrapolation reaches is in the air beside the
       free surface: its ghost pressure is not below 0, as the liquid's (desc.clamp_negative_pressure);
       a negative ghost pulled the particles at the top of the walls into them */
    const int clamp = s->desc.clamp_negative_pressure && (ghost.x != 0 || ghost.y != 0 || ghost.z != 0);
    int e;
    if (s->desc.gradient == FSDEM_MPS_GRADIENT_MODEL_MIN)
        for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e)
            if (s->kind[s->nb[e]] != FSDEM_MPS_KIND_DUMMY && s->nbw[e] > 0 && phi[s->nb[e]] < base) base = phi[s->nb[e]];
    if (s->desc.gradient == FSDEM_MPS_GRADIENT_MODEL_MIN) base = -base;
    fsdem__mps_gradient_transform(s, i, T);
    for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
        const int j = s->nb[e];
        const fsdem_vec3 r = fsdem__mps_sep(s, i, j);
        const fsdem_real r2 = fsdem__dot(r, r);
        fsdem_real pj = phi[j];
        if (s->kind[j] == FSDEM_MPS_KIND_DUMMY) {
            pj = phi[i] + fsdem__dot(ghost, r);
            if (pj < 0 && clamp) pj = 0;
        }
        if (!(r2 > 0)) continue;
        g = fsdem__madd(g, r, (pj + base) * s->nbw[e] / (r2 * s->eps[j]));
    }
    return fsdem__mps_apply(T, g);
}

/* Divergence of u at particle i (seed 002 Eq. 9) over its non-DUMMY neighbours. */
static fsdem_real fsdem__mps_div_at(const fsdem_mps *s, const fsdem_vec3 *u, int i) {
    fsdem_real d = 0;
    int e;
    for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
        const int j = s->nb[e];
        const fsdem_vec3 r = fsdem__mps_sep(s, i, j);
        const fsdem_real r2 = fsdem__dot(r, r);
        if (s->kind[j] == FSDEM_MPS_KIND_DUMMY || !(r2 > 0)) continue;
        d += fsdem__dot(fsdem__sub(u[j], u[i]), r) * s->nbw[e] / (r2 * s->eps[j]);
    }
    return d * (fsdem_real)s->dim / s->n0;
}

/* Laplacian at particle i (seed 002 Eq. 10, lambda of Eq. 11) of a scalar (phi) or, when phi is
   NULL, of a vector field u, over its non-DUMMY neighbours, or all of them when `dummies`. */
static fsdem_vec3 fsdem__mps_lap_at(const fsdem_mps *s, const fsdem_real *phi, const fsdem_vec3 *u, int i, int dummies) {
    fsdem_vec3 l = fsdem__zero3();
    int e;
    for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
        const int j = s->nb[e];
        const fsdem_real we = s->nbl[e] / s->eps[j];
        if (s->kind[j] == FSDEM_MPS_KIND_DUMMY && !dummies) continue;
        if (phi) l.x += (phi[j] - phi[i]) * we;
        else l = fsdem__madd(l, fsdem__sub(u[j], u[i]), we);
    }
    return fsdem__scale(l, 2 * (fsdem_real)s->dim / (s->n0_lap * s->lambda));
}

/* Mass of the fluid a particle stands for: rho r0^d (kg; kg per metre of depth in 2D). */
static fsdem_real fsdem__mps_mass(const fsdem_mps *s) {
    return s->desc.density * s->r0 * s->r0 * (s->dim == 3 ? s->r0 : 1);
}

/* The ghost velocities of FSDEM_MPS_WALL_VISCOSITY_NO_SLIP into s->uvisc (see the enum): FLUID particles
   their own velocity, WALL and DUMMY particles -u~, the Shepard average of the FLUID velocities
   around them, gathered by scattering from the FLUID rows' solid entries (the rows of DUMMY
   particles are empty); 0 where no FLUID particle is within re. */
static void fsdem__mps_wall_ghosts(fsdem_mps *s) {
    int i, k;
    for (i = 0; i < s->n; ++i) {
        s->uvisc[i] = s->kind[i] == FSDEM_MPS_KIND_FLUID ? s->v[i] : fsdem__zero3();
        s->ghost_weight[i] = 0;
    }
    for (k = 0; k < s->wall_entry_n; ++k) {
        const int f = s->wall_entries[2 * k], e = s->wall_entries[2 * k + 1], j = s->nb[e];
        const fsdem_real w = s->nbw[e] / s->eps[f];
        s->uvisc[j] = fsdem__madd(s->uvisc[j], s->v[f], w);
        s->ghost_weight[j] += w;
    }
    for (i = 0; i < s->n; ++i)
        if (s->ghost_weight[i] > 0) s->uvisc[i] = fsdem__scale(s->uvisc[i], -1 / s->ghost_weight[i]);
}

/* Rebuilds the neighbours and the number density at the current positions for a public operator
   (`fn` names it), checking its arguments. */
static fsdem_result fsdem__mps_operator_setup(fsdem_mps *s, const char *fn, const void *in, const void *out) {
    if (!in || !out) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: NULL field", fn);
    if (s->n > 0 && fsdem__mps_neighbours(s) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory building the neighbour list", fn);
    return FSDEM_OK;
}

fsdem_result fsdem_mps_gradient(fsdem_mps *s, const fsdem_real *phi, fsdem_vec3 *out) {
    fsdem_result r;
    int i;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem__mps_operator_setup(s, "fsdem_mps_gradient", phi, out)) != FSDEM_OK) return r;
    for (i = 0; i < s->n; ++i) out[i] = s->kind[i] == FSDEM_MPS_KIND_DUMMY ? fsdem__zero3() : fsdem__mps_grad_at(s, phi, i, fsdem__zero3());
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_mps_divergence(fsdem_mps *s, const fsdem_vec3 *field, fsdem_real *out) {
    fsdem_result r;
    int i;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem__mps_operator_setup(s, "fsdem_mps_divergence", field, out)) != FSDEM_OK) return r;
    for (i = 0; i < s->n; ++i) out[i] = s->kind[i] == FSDEM_MPS_KIND_DUMMY ? 0 : fsdem__mps_div_at(s, field, i);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_mps_laplacian(fsdem_mps *s, const fsdem_real *phi, fsdem_real *out) {
    fsdem_result r;
    int i;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem__mps_operator_setup(s, "fsdem_mps_laplacian", phi, out)) != FSDEM_OK) return r;
    for (i = 0; i < s->n; ++i) out[i] = s->kind[i] == FSDEM_MPS_KIND_DUMMY ? 0 : fsdem__mps_lap_at(s, phi, NULL, i, 0).x;
    return fsdem__ok(&s->status);
}
