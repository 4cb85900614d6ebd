/* ---- >>mps_explicit : the weakly compressible scheme (FSDEM_MPS_SCHEME_EXPLICIT) ---- */

/* Height of x against gravity, -g.x / |g| (m; 0 without gravity). */
static fsdem_real fsdem__mps_height(const fsdem_mps *s, fsdem_vec3 x) {
    const fsdem_real g = fsdem__norm(s->desc.gravity);
    return g > 0 ? -fsdem__dot(s->desc.gravity, x) / g : 0;
}

/* The sound speed c0 of the explicit scheme (m/s): desc.sound_speed, or the one set at the first
   step, or (before it) 10 sqrt(2 |g| H), H the height of the FLUID particles plus r0; 0 when
   nothing gives one (no gravity, no desc.sound_speed). A Mach number of 0.1 for the speed of a fall
   from the top keeps the density within about 1 % of rho (Monaghan 1994). */
static fsdem_real fsdem__mps_c0(const fsdem_mps *s) {
    fsdem_real lo = (fsdem_real)HUGE_VAL, hi = -(fsdem_real)HUGE_VAL;
    int i;
    if (s->desc.sound_speed > 0) return s->desc.sound_speed;
    if (s->c0 > 0) return s->c0;
    for (i = 0; i < s->n; ++i)
        if (s->kind[i] == FSDEM_MPS_KIND_FLUID) {
            const fsdem_real h = fsdem__mps_height(s, s->x[i]);
            if (h < lo) lo = h;
            if (h > hi) hi = h;
        }
    if (!(hi >= lo)) return 0;
    return 10 * (fsdem_real)sqrt(2 * (double)fsdem__norm(s->desc.gravity) * (double)(hi - lo + s->r0));
}

/* The hydrostatic start: every FLUID particle whose density is not set yet (0) takes
   rho + rho |g| depth / c0^2 (the equation of state of a liquid at rest), its depth measured from
   r0/2 above the highest FLUID particle of its column (neighbours within r0/2 of its vertical line,
   the top passed from neighbour to neighbour until no particle learns a higher one; s->div holds
   the tops). */
static void fsdem__mps_hydrostatic_start(fsdem_mps *s, fsdem_real c0) {
    const fsdem_real g = fsdem__norm(s->desc.gravity), half = s->r0 / 2;
    fsdem_real *top = s->div;
    int i, e, unset = 0, changed = 1;
    for (i = 0; i < s->n; ++i) unset += s->kind[i] == FSDEM_MPS_KIND_FLUID && s->rho[i] == 0;
    if (!unset) return;
    for (i = 0; i < s->n; ++i) top[i] = fsdem__mps_height(s, s->x[i]);
    while (changed) {
        changed = 0;
        for (i = 0; i < s->n; ++i)
            if (s->kind[i] == FSDEM_MPS_KIND_FLUID)
                for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
                    const int j = s->nb[e];
                    const fsdem_vec3 r = fsdem__mps_sep(s, i, j);
                    const fsdem_real up = g > 0 ? -fsdem__dot(s->desc.gravity, r) / g : 0;
                    const fsdem_vec3 across = g > 0 ? fsdem__madd(r, s->desc.gravity, up / g) : r; /* r less its vertical part */
                    if (s->kind[j] == FSDEM_MPS_KIND_FLUID && s->nbw[e] > 0 && top[j] > top[i] && fsdem__norm(across) <= half) {
                        top[i] = top[j];
                        changed = 1;
                    }
                }
    }
    for (i = 0; i < s->n; ++i)
        if (s->kind[i] == FSDEM_MPS_KIND_FLUID && s->rho[i] == 0)
            s->rho[i] = s->desc.density * (1 + g * (top[i] + half - fsdem__mps_height(s, s->x[i])) / (c0 * c0));
}

/* Pressures: FLUID particles by the equation of state p = c0^2 (rho_i - rho); WALL and DUMMY
   particles the Shepard average of the FLUID pressures within re of them extrapolated
   hydrostatically to them, p_w = sum_f w (p_f + rho g.(r_w - r_f)) / sum_f w (Adami, Hu and Adams
   2012, Eq. 27, fixed walls; gathered by scattering from the FLUID rows' solid entries, as the
   rows of DUMMY particles are empty), 0 with none; negative pressures set to 0 when
   desc.clamp_negative_pressure. One pressure field on every particle: the DUMMY ghost of the
   semi-implicit scheme, p_i + rho g.(r_j - r_i) seen from each i, let the columns beside the walls
   slide (still water drifted 0.5 r0 by 0.5 s). */
static void fsdem__mps_explicit_pressures(fsdem_mps *s, fsdem_real c0) {
    const fsdem_real rho = s->desc.density;
    const int clamp = s->desc.clamp_negative_pressure;
    fsdem_real *weight = s->ghost_weight;
    int i, k;
    for (i = 0; i < s->n; ++i) {
        const fsdem_real p = s->kind[i] == FSDEM_MPS_KIND_FLUID ? c0 * c0 * (s->rho[i] - rho) : 0;
        s->p[i] = p < 0 && clamp ? 0 : p;
        weight[i] = 0;
    }
    for (k = 0; k < s->wall_entry_n; ++k) {
        const int f = s->wall_entries[2 * k], e = s->wall_entries[2 * k + 1], j = s->nb[e];
        s->p[j] += s->nbw[e] * (s->p[f] + rho * fsdem__dot(s->desc.gravity, fsdem__mps_sep(s, f, j)));
        weight[j] += s->nbw[e];
    }
    for (i = 0; i < s->n; ++i)
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID) {
            s->p[i] = weight[i] > 0 ? s->p[i] / weight[i] : 0;
            if (s->p[i] < 0 && clamp) s->p[i] = 0;
        }
}

/* The pressure gradient of the explicit scheme at FLUID particle i: the sum form of seed 002 Eq. 8
   with the scheme's weight w_ij (s->nbx holds w_ij / |r_j - r_i|^2),
   d/n0x sum_j (p_i + p_j) (r_j - r_i) w_ij / (|r_j - r_i|^2 eps_j), over
   every neighbour, solids with their extrapolated pressures: the form whose pair forces are equal
   and opposite and whose adjoint is the divergence of the continuity equation (so pressure work
   and compression balance); the min and corrected forms of desc.gradient blew still water up.
   Solid particles whose extrapolated pressure is not positive are in the air (the wall above a
   free surface) and left out, as the missing liquid above the surface is: with their pressure 0
   in the sum they pushed the particle where the surface meets a wall away with its own pressure
   (0.16 r0 in still water; 0.05 r0 without them). A wall a jet presses on has a positive pressure
   and pushes. */
static fsdem_vec3 fsdem__mps_explicit_gradient(const fsdem_mps *s, int i) {
    fsdem_vec3 g = fsdem__zero3();
    int e;
    for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
        const int j = s->nb[e];
        const fsdem_vec3 r = fsdem__mps_sep(s, i, j);
        if (s->kind[j] != FSDEM_MPS_KIND_FLUID && !(s->p[j] > 0)) continue; /* a solid in the air */
        g = fsdem__madd(g, r, (s->p[i] + s->p[j]) * s->nbx[e] / s->eps[j]);
    }
    return fsdem__scale(g, (fsdem_real)s->dim / s->n0_x);
}

/* The rate of the density of FLUID particle i: -rho_i div u (Eq. 9 with the scheme's weight, every
   neighbour, the solids at rest: the adjoint of fsdem__mps_explicit_gradient) plus the diffusion
   delta c0 r0 lap(rho - rho_h) (Eq. 10's Laplacian over the FLUID neighbours). Molteni and
   Colagrossi (2009) diffuse rho itself, which drives a liquid at rest away from hydrostatic; the
   hydrostatic part rho_h, whose difference between j and i is rho g.(r_j - r_i) / c0^2 for the
   linear equation of state, is taken out, after Fourtakas et al. (2019). */
static fsdem_real fsdem__mps_density_rate(const fsdem_mps *s, int i, fsdem_real c0) {
    const fsdem_real rho = s->desc.density, hydro = rho / (c0 * c0);
    fsdem_real diffusion = 0, div = 0;
    int e;
    for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
        const int j = s->nb[e];
        const fsdem_vec3 r = fsdem__mps_sep(s, i, j);
        div += fsdem__dot(fsdem__sub(s->v[j], s->v[i]), r) * s->nbx[e] / s->eps[j];
        if (s->kind[j] == FSDEM_MPS_KIND_FLUID)
            diffusion += (s->rho[j] - s->rho[i] - hydro * fsdem__dot(s->desc.gravity, r)) * s->nbl[e] / s->eps[j];
    }
    diffusion *= s->desc.density_diffusion * c0 * s->r0 * 2 * (fsdem_real)s->dim / (s->n0_lap * s->lambda);
    return -s->rho[i] * div * (fsdem_real)s->dim / s->n0_x + diffusion;
}

/* The explicit scheme's part of a step of dt (after the neighbours and the number density, before
   the obstacle forces, collisions and the move): the hydrostatic start of new particles, the
   pressures, the velocities u += dt (-grad p / rho + nu lap u + g + f/m) (FLUID particles outside
   inflow buffers; with desc.model B the pressure term over eps_i as in the corrector), then the
   densities with the new velocities. FSDEM_ERR_INVALID_ARG when no sound speed can be had. */
static fsdem_result fsdem__mps_explicit(fsdem_mps *s, fsdem_real dt) {
    const fsdem_real rho = s->desc.density, nu = s->desc.viscosity, mass = fsdem__mps_mass(s), c0 = fsdem__mps_c0(s);
    const int no_slip = s->desc.wall_viscosity == FSDEM_MPS_WALL_VISCOSITY_NO_SLIP && nu > 0;
    int i;
    if (!(c0 > 0))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_mps: the explicit scheme has no sound speed: set desc.sound_speed (there is no gravity to take it from)");
    s->c0 = c0;
    fsdem__mps_hydrostatic_start(s, c0);
    fsdem__mps_explicit_pressures(s, c0);
    if (no_slip) fsdem__mps_wall_ghosts(s);
    for (i = 0; i < s->n; ++i) {
        fsdem_vec3 a;
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID || s->inlet[i] >= 0) continue;
        s->gradp[i] = fsdem__mps_explicit_gradient(s, i);
        a = fsdem__madd(s->desc.gravity, s->gradp[i], -1 / (rho * (s->desc.model == FSDEM_MPS_MODEL_B ? s->eps[i] : 1)));
        if (nu > 0) a = fsdem__madd(a, fsdem__mps_lap_at(s, NULL, no_slip ? s->uvisc : s->v, i, no_slip), nu);
        if (s->external) a = fsdem__madd(a, s->fext[i], 1 / mass); /* a coupler's force (Eq. 2, 4) */
        s->us[i] = fsdem__madd(s->v[i], a, dt);
        if (s->dim == 2) s->us[i].z = 0;
    }
    for (i = 0; i < s->n; ++i)
        if (s->kind[i] == FSDEM_MPS_KIND_FLUID && s->inlet[i] < 0) s->v[i] = s->us[i];
    for (i = 0; i < s->n; ++i) s->div[i] = s->kind[i] == FSDEM_MPS_KIND_FLUID ? fsdem__mps_density_rate(s, i, c0) : 0;
    for (i = 0; i < s->n; ++i)
        if (s->kind[i] == FSDEM_MPS_KIND_FLUID) s->rho[i] += dt * s->div[i];
    s->iters = 0;
    s->residual = 0;
    return FSDEM_OK;
}
