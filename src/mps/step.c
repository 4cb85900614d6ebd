/* ---- >>mps_step : predictor, pressure equation, corrector, time stepping ---- */

/* Largest FLUID speed (m/s) and its particle in *who (-1 when none; the particle with a non-finite
   velocity, and the result NaN, when there is one). */
static fsdem_real fsdem__mps_umax(const fsdem_mps *s, int *who) {
    fsdem_real m2 = 0;
    int i;
    *who = -1;
    for (i = 0; i < s->n; ++i) {
        fsdem_real v2;
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        v2 = fsdem__dot(s->v[i], s->v[i]);
        if (!fsdem__finite(v2)) {
            *who = i;
            return v2 - v2;
        }
        if (v2 > m2) {
            m2 = v2;
            *who = i;
        }
    }
    return (fsdem_real)sqrt(m2);
}

/* The longest step the explicit viscous term of the predictor (step 2) allows, dt nu <= 0.8
   lambda eps_min / (2d) (s; infinite without viscosity). Eq. 10 on u at particle i, with
   S_i = sum_j w_ij / eps_j, has its row in the disc of centre -c S_i and radius c S_i
   (c = 2d / (lambda n0_lap), Gershgorin, with the Laplacian's weights; the ghost velocities of
   FSDEM_MPS_WALL_VISCOSITY_NO_SLIP are averages, so the radius holds), so forward Euler is stable
   while dt nu c S_i <= 1; S_i = n0_lap / eps_min on a full lattice, and the 0.8 leaves room for
   neighbourhoods crowded to 1.25 n0_lap. */
static fsdem_real fsdem__mps_dt_viscous(const fsdem_mps *s) {
    fsdem_real eps_min = 1;
    int i;
    if (!(s->desc.viscosity > 0)) return (fsdem_real)HUGE_VAL;
    for (i = 0; i < s->n; ++i)
        if (s->kind[i] != FSDEM_MPS_KIND_DUMMY && s->eps[i] < eps_min) eps_min = s->eps[i];
    return (fsdem_real)0.8 * s->lambda * eps_min / (2 * (fsdem_real)s->dim * s->desc.viscosity);
}

/* The speed of the CFL rule: u_max (seed 002 Eq. 37), c0 + u_max in the explicit scheme. */
static fsdem_real fsdem__mps_signal_speed(const fsdem_mps *s, fsdem_real umax) {
    return s->desc.scheme == FSDEM_MPS_SCHEME_EXPLICIT ? fsdem__mps_c0(s) + umax : umax;
}

/* The stable step: the CFL rule, speed dt / r0 <= C (fsdem__mps_signal_speed), and the viscous
   limit, at most dt_max. */
static fsdem_real fsdem__mps_dt_from(const fsdem_mps *s, fsdem_real umax) {
    const fsdem_real viscous = fsdem__mps_dt_viscous(s), speed = fsdem__mps_signal_speed(s, umax);
    fsdem_real dt = s->desc.dt_max;
    if (speed > 0 && s->desc.cfl * s->r0 / speed < dt) dt = s->desc.cfl * s->r0 / speed;
    return viscous < dt ? viscous : dt;
}

/* Makes room for the pressure matrix of `nnz` entries (by doubling). */
static fsdem_result fsdem__mps_matrix_room(fsdem_mps *s, long long nnz) {
    int cap;
    int *col;
    fsdem_real *val;
    if (nnz <= s->a_cap) return FSDEM_OK;
    cap = fsdem__mps_capacity(s->a_cap, nnz);
    if (!cap) return FSDEM_ERR_OUT_OF_MEMORY;
    col = (int *)fsdem__alloc(&s->allocator, sizeof(int) * (size_t)cap);
    val = (fsdem_real *)fsdem__alloc(&s->allocator, sizeof(fsdem_real) * (size_t)cap);
    if (!col || !val) {
        fsdem__free(&s->allocator, col, sizeof(int) * (size_t)cap);
        fsdem__free(&s->allocator, val, sizeof(fsdem_real) * (size_t)cap);
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    fsdem__free(&s->allocator, s->a_col, sizeof(int) * (size_t)s->a_cap);
    fsdem__free(&s->allocator, s->a_val, sizeof(fsdem_real) * (size_t)s->a_cap);
    s->bytes += (sizeof(int) + sizeof(fsdem_real)) * (size_t)(cap - s->a_cap);
    s->a_col = col;
    s->a_val = val;
    s->a_cap = cap;
    return FSDEM_OK;
}

/* Particle shifting (desc.shifting > 0): the Fickian shift of Lind, Xu, Stansby and Rogers (2012),
   J. Comput. Phys. 231:1499, dr_i = -D grad C_i, with a constant coefficient of order h^2 per
   step as in that paper (here D = desc.shifting r0^2), adapted to MPS: the concentration
   gradient is the kernel sum of Eq. 8 with C = 1 at every neighbour, FLUID, WALL and DUMMY alike,
       grad C_i = d/n0 sum_j 2 (r_j - r_i) w_ij / (|r_j - r_i|^2 eps_j),
   zero inside a full lattice and pointing to where neighbours crowd (a particle displaced by s
   from its lattice site has grad C = 1.19 s / r0^2 for re = 4.1 r0 in 2D, so desc.shifting = c
   moves it back by 1.19 c s in one step). Free surface (after Lind et al. 2012): a surface
   particle is not shifted; a particle with a surface neighbour (its neighbourhood is cut by the
   surface) is shifted only tangentially, its normal the asymmetry vector F_i of seed 002 Eq. 15
   (the shift's component along F_i removed), as the number-density deficiency below the surface is
   geometry, not clustering. WALL and DUMMY particles never move. The shift is computed at the
   positions of the start of the step (its neighbour rows) and added after the corrector's move;
   it is limited to desc.cfl r0 (a choice of this library, not of the paper: a shift is not longer
   than the motion a step allows). The velocity is not corrected (the paper's Taylor correction of
   the velocity to the shifted position is left out). Allocates nothing. */
static void fsdem__mps_shift(fsdem_mps *s) {
    const fsdem_real D = s->desc.shifting * s->r0 * s->r0, cap = s->desc.cfl * s->r0;
    int i, e;
    for (i = 0; i < s->n; ++i) {
        fsdem_vec3 gc = fsdem__zero3(), F = fsdem__zero3(), d;
        fsdem_real len;
        int band = 0;
        s->shift[i] = fsdem__zero3();
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID || s->surf[i] || s->inlet[i] >= 0 || D == 0) continue;
        for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
            const int j = s->nb[e];
            const fsdem_vec3 r = fsdem__mps_sep(s, i, j);
            const fsdem_real r2 = fsdem__dot(r, r);
            if (!(r2 > 0) || !(s->nbw[e] > 0)) continue; /* not within re */
            band |= s->surf[j];
            gc = fsdem__madd(gc, r, 2 * s->nbw[e] / (r2 * s->eps[j]));
            F = fsdem__madd(F, r, s->nbw[e] / ((fsdem_real)sqrt(r2) * s->eps[j]));
        }
        d = fsdem__scale(gc, -D * (fsdem_real)s->dim / s->n0);
        if (band) {
            const fsdem_real f2 = fsdem__dot(F, F);
            if (f2 > 0) d = fsdem__madd(d, F, -fsdem__dot(d, F) / f2);
        }
        if (s->dim == 2) d.z = 0;
        len = fsdem__norm(d);
        if (len > cap) d = fsdem__scale(d, cap / len);
        s->shift[i] = d;
    }
}

/* Collisions (desc.collision_distance > 0), the model of Koshizuka's MPS (Koshizuka, Nobe and Oka
   1998; collision distance 0.5 r0 and restitution 0.2 in the reference code of Koshizuka's MPS
   textbook). The default distance here is 0.8 r0: at 0.5 r0 a particle under a clamped (zero)
   pressure slipped between two WALL particles one spacing apart, reaching exactly 0.5 r0 from
   both at the midpoint, and fell through the floor (Martin & Moyce dam break at a/40, t = 0.31 s;
   3D still water at 0.50 s); at 0.8 r0 the gap is closed and both run through. After the corrector, a FLUID particle i and a neighbour j that would end the step
   closer than collision_distance r0 (at r + dt v) while approaching ((v_j - v_i).(r_j - r_i) < 0)
   collide along n = (r_j - r_i)/|r_j - r_i|: their approach speed v_n is replaced by -e v_n, the
   restitution e = desc.restitution, the two FLUID particles sharing the change (equal masses, so
   momentum is kept) and a WALL or DUMMY partner taking none (fixed). Pairs in particle order, each once, the velocities updated as they
   go (deterministic). It keeps a particle from sinking into a wall, where the number density term
   of Eq. 12 would then throw it out (a dam break's front toe did so at 22 m/s). */
static void fsdem__mps_collide(fsdem_mps *s, fsdem_real dt) {
    const fsdem_real dc = s->desc.collision_distance * s->r0, e = s->desc.restitution;
    int i, k;
    if (!(dc > 0)) return;
    for (i = 0; i < s->n; ++i) {
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        for (k = s->nb_start[i]; k < s->nb_start[i + 1]; ++k) {
            const int j = s->nb[k], fluid = s->kind[j] == FSDEM_MPS_KIND_FLUID;
            fsdem_vec3 r, dv, ahead, n;
            fsdem_real len, vn;
            if (fluid && j < i) continue; /* each FLUID pair once */
            r = fsdem__mps_sep(s, i, j);
            dv = fsdem__sub(s->v[j], s->v[i]);
            vn = fsdem__dot(dv, r);
            if (!(vn < 0)) continue; /* not approaching (a pair at one point too: r = 0) */
            ahead = fsdem__madd(r, dv, dt);
            if (!(fsdem__dot(ahead, ahead) < dc * dc)) continue;
            len = fsdem__norm(r);
            n = fsdem__scale(r, 1 / len);
            vn = (1 + e) * vn / len; /* (1 + e) times the approach speed along n, negative */
            if (fluid) {
                s->v[i] = fsdem__madd(s->v[i], n, vn / 2);
                s->v[j] = fsdem__madd(s->v[j], n, -vn / 2);
            } else
                s->v[i] = fsdem__madd(s->v[i], n, vn);
        }
    }
}

/* The force of the liquid on each box obstacle: the pressure on its faces, sum over its WALL
   particles k and the faces f of the box within one spacing of k (two at an edge, three at a
   corner) of -(p_k + rho g.(x_f - x_k)) r0^(d-1) n_f, with n_f the outward normal and x_f the
   point of the face next to k: each WALL particle stands for the r0^(d-1) of face in front of
   it, and its pressure, solved half a spacing inside, is carried to the face by the hydrostatic
   extrapolation of the pressure equation's DUMMY ghosts (exact for still water). */
static void fsdem__mps_obstacle_forces(fsdem_mps *s) {
    const fsdem_real area = (fsdem_real)pow((double)s->r0, s->dim - 1), rho = s->desc.density;
    int i, a, side;
    if (s->obst_n == 0) return; /* no obstacle: no pass over the particles */
    for (a = 0; a < s->obst_n; ++a) s->obst[a].force = fsdem__zero3();
    for (i = 0; i < s->n; ++i) {
        fsdem__mps_obst *o;
        if (s->kind[i] != FSDEM_MPS_KIND_WALL || s->body[i] < 0) continue;
        o = &s->obst[s->body[i]];
        for (a = 0; a < s->dim; ++a)
            for (side = 0; side < 2; ++side) {
                const fsdem_real face = fsdem__comp(side ? o->hi : o->lo, a), x = fsdem__comp(s->x[i], a);
                fsdem_vec3 n = fsdem__zero3(), xf = s->x[i];
                if (!((side ? face - x : x - face) < s->r0)) continue;
                fsdem__set_comp(&n, a, side ? 1 : -1);
                fsdem__set_comp(&xf, a, face);
                o->force = fsdem__madd(o->force, n, -(s->p[i] + rho * fsdem__dot(s->desc.gravity, fsdem__sub(xf, s->x[i]))) * area);
            }
    }
}

/* Assembles the pressure equation (section >>mps, step 4): unknowns are the FLUID and WALL
   particles off the surface with a non-DUMMY neighbour, numbered in particle order, so each row's
   columns ascend with the neighbour rows; row i is seed 002 Eq. 10 = Eq. 12 times
   -n0 lambda/(2d)/eps_i, which makes it symmetric, its DUMMY neighbours at the hydrostatic ghost
   pressure (their known terms on the right). The right-hand side goes to s->b. */
static fsdem_result fsdem__mps_assemble(fsdem_mps *s, fsdem_real dt) {
    const fsdem_real rho = s->desc.density, gamma = s->desc.gamma;
    const fsdem_real scale = -s->n0_lap * s->lambda / (2 * (fsdem_real)s->dim);
    long long nnz = 0;
    int i, e, rows = 0, anchored = 0;
    for (i = 0; i < s->n; ++i) {
        int solid_only = 1;
        s->unknown[i] = -1;
        if (s->kind[i] == FSDEM_MPS_KIND_DUMMY || s->surf[i]) continue;
        if (s->outflow_n && s->kind[i] == FSDEM_MPS_KIND_FLUID && fsdem__mps_outflowing(s, i) > 0) continue; /* p = 0 */
        for (e = s->nb_start[i]; e < s->nb_start[i + 1] && solid_only; ++e)
            solid_only = s->kind[s->nb[e]] == FSDEM_MPS_KIND_DUMMY || s->nbl[e] == 0;
        if (solid_only) continue;
        s->row_particle[rows] = i;
        s->unknown[i] = rows++;
    }
    for (i = 0; i < s->n; ++i)
        if (s->unknown[i] >= 0) {
            nnz++;
            for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) nnz += s->unknown[s->nb[e]] >= 0 && s->nbl[e] > 0;
        }
    if (fsdem__mps_matrix_room(s, nnz) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    nnz = 0;
    s->a_start[0] = 0;
    for (i = 0; i < s->n; ++i) {
        const int row = s->unknown[i];
        fsdem_real diag = 0, source;
        long long at = -1;
        if (row < 0) continue;
        for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
            const int j = s->nb[e];
            const fsdem_real a = s->nbl[e] / (s->eps[i] * s->eps[j]);
            if (s->kind[j] == FSDEM_MPS_KIND_DUMMY || !(a > 0)) continue;
            diag += a;
            if (s->unknown[j] < 0) { /* a surface neighbour: p = 0 there anchors the level */
                anchored = 1;
                continue;
            }
            if (at < 0 && j > i) at = nnz++; /* the diagonal's place among ascending columns */
            s->a_col[nnz] = s->unknown[j];
            s->a_val[nnz++] = -a;
        }
        if (at < 0) at = nnz++;
        s->a_col[at] = row;
        s->a_val[at] = diag;
        s->a_start[row + 1] = (int)nnz;
        /* seed 002 Eq. 12: (1 - gamma) rho/dt div u* - gamma rho/dt^2 (n_i - n0)/n0; Eq. 13 (model B)
           the same with eps_i rho */
        source = (1 - gamma) * rho / dt * s->div[i] - gamma * rho / (dt * dt) * (s->nd[i] - s->n0) / s->n0;
        if (s->desc.model == FSDEM_MPS_MODEL_B) source *= s->eps[i];
        s->b[row] = scale * source / s->eps[i];
        /* DUMMY neighbours in Eq. 10 at the ghost pressure p_i + rho g.(r_j - r_i), the hydrostatic
           extrapolation from i that the corrector's gradient uses too (fsdem__mps_grad_at): their
           (p_j - p_i) w_ij terms are known and move to the right-hand side (the matrix is unchanged,
           still symmetric) */
        for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
            const int j = s->nb[e];
            if (s->kind[j] != FSDEM_MPS_KIND_DUMMY) continue;
            s->b[row] += rho * fsdem__dot(s->desc.gravity, fsdem__mps_sep(s, i, j)) * s->nbl[e] / (s->eps[i] * s->eps[j]);
        }
        s->sol[row] = s->p[i];
    }
    s->rows = rows;
    /* No surface particle (a closed or periodic box full of liquid): the matrix is singular, the
       constant its null space (its rows sum to 0); the source loses its mean, the part no pressure
       can answer (for a liquid whose volume is fixed by its walls, the density error that
       compression cannot remove), so that the system has solutions; the solve's level is then
       set in fsdem__mps_do_step. The first unknown is then pinned to 0 (its row and column
       reduced to the diagonal): the matrix becomes positive definite, and since the rows sum to 0
       and the source to 0, the dropped row holds whenever the others do, so the solution is the
       singular system's. (Unpinned, a uniform flow, whose source is rounding alone, led the
       preconditioned CG into the null space: non-positive curvature.) Detected for the whole
       liquid: a sealed pocket beside liquid that has a free surface keeps a singular block (not
       handled) */
    s->closed = rows > 0 && !anchored;
    if (s->closed) {
        double mean = 0;
        for (i = 0; i < rows; ++i) mean += (double)s->b[i];
        mean /= rows;
        for (i = 0; i < rows; ++i) s->b[i] -= (fsdem_real)mean;
        for (i = 0; i < rows; ++i)
            for (e = s->a_start[i]; e < s->a_start[i + 1]; ++e)
                if ((i == 0) != (s->a_col[e] == 0)) s->a_val[e] = 0;
        s->b[0] = 0;
    }
    return FSDEM_OK;
}

/* Steps 2-4 and 6 of the section's step of dt (the seed's scheme, after the neighbours and the
   number density, before the obstacle forces, collisions and the move): predictor, pressure
   equation, corrector. A failure changes no particle. */
static fsdem_result fsdem__mps_semi_implicit(fsdem_mps *s, fsdem_real dt) {
    const fsdem_real rho = s->desc.density, nu = s->desc.viscosity, mass = fsdem__mps_mass(s);
    const int no_slip = s->desc.wall_viscosity == FSDEM_MPS_WALL_VISCOSITY_NO_SLIP && nu > 0;
    const fsdem_vec3 *visc_u = no_slip ? s->uvisc : s->v;
    const clock_t tp = clock();
    clock_t ta;
    fsdem_pcg_info info;
    fsdem_csr A;
    fsdem_result r;
    int i;
    /* 2. predictor: u* = u + dt (nu lap u + g) (seed 002 Eq. A.6 with eps = 1). WALL and DUMMY
       particles take u* = dt g, their velocity (0) plus the same body force: a uniform field has no
       divergence (Eq. 9), so gravity alone leaves no source at the walls in Eq. 12, and the walls
       carry its weight through the hydrostatic ghost pressure of the DUMMY particles in the
       pressure equation (fsdem__mps_assemble), the discrete Neumann condition dp/dn = rho g.n.
       With u* = 0 at the solids instead, the source of the rows near a wall held only part of the
       weight (one-sided Eq. 9 against the one-sided Eq. 10): still water started with 0.7 rho g h
       at the bottom and fell at 0.25-0.35 g in its first step. The viscous term takes the solids'
       velocities of desc.wall_viscosity. */
    if (no_slip) fsdem__mps_wall_ghosts(s);
    for (i = 0; i < s->n; ++i) {
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID || s->inlet[i] >= 0) { /* solids at rest, inflow buffers at their speed */
            s->us[i] = fsdem__madd(s->v[i], s->desc.gravity, dt);
            if (s->dim == 2) s->us[i].z = 0;
            continue;
        }
        s->us[i] = fsdem__add(s->v[i], fsdem__scale(fsdem__add(fsdem__scale(fsdem__mps_lap_at(s, NULL, visc_u, i, no_slip), nu),
                                                                s->desc.gravity), dt));
        if (s->external) s->us[i] = fsdem__madd(s->us[i], s->fext[i], dt / mass); /* a coupler's force (Eq. 2, 4) */
        if (s->dim == 2) s->us[i].z = 0;
    }
    for (i = 0; i < s->n; ++i) s->div[i] = s->kind[i] == FSDEM_MPS_KIND_DUMMY ? 0 : fsdem__mps_div_at(s, s->us, i);
    /* 3. pressure equation */
    if (fsdem__mps_assemble(s, dt) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps: out of memory assembling the pressure matrix");
    ta = clock();
    memset(&info, 0, sizeof info);
    s->iters = 0;
    s->residual = 0;
    if (s->rows > 0) {
        A.rows = s->rows;
        A.row_start = s->a_start;
        A.col = s->a_col;
        A.val = s->a_val;
        r = fsdem__pcg_setup_csr_valid(s->pcg, &A);
        if (r == FSDEM_OK) r = fsdem_pcg_solve(s->pcg, s->b, s->sol, &info);
        s->iters = info.iterations;
        s->residual = info.residual;
        if (r != FSDEM_OK) {
            if (r == FSDEM_ERR_OUT_OF_MEMORY)
                return fsdem__fail(&s->status, r, "fsdem_mps: out of memory in the pressure solve: %s", fsdem_pcg_last_error(s->pcg));
            return fsdem__fail(&s->status, FSDEM_ERR_NOT_CONVERGED,
                               "fsdem_mps: step %lld: the pressure solve of %d unknowns failed after %d iterations (residual "
                               "%g, tolerance %g): %s; nothing changed",
                               s->steps + 1, s->rows, info.iterations, (double)info.residual,
                               (double)s->desc.pressure_tolerance, fsdem_pcg_last_error(s->pcg));
        }
    }
    s->sec_pressure += (double)(clock() - tp) / CLOCKS_PER_SEC;
    s->sec_assembly += (double)(ta - tp) / CLOCKS_PER_SEC;
    s->sec_solve += (double)(clock() - ta) / CLOCKS_PER_SEC;
    /* 4. pressures (clamped where asked), then the corrector: u = u* - dt/rho grad p.
       A closed liquid's pressure is known up to a constant: the lowest is set to 0 */
    if (s->closed) {
        fsdem_real low = s->sol[0];
        for (i = 1; i < s->rows; ++i)
            if (s->sol[i] < low) low = s->sol[i];
        for (i = 0; i < s->rows; ++i) s->sol[i] -= low;
    }
    for (i = 0; i < s->n; ++i) {
        fsdem_real p = s->unknown[i] >= 0 ? s->sol[s->unknown[i]] : 0;
        if (p < 0 && s->desc.clamp_negative_pressure) p = 0;
        s->p[i] = p;
    }
    for (i = 0; i < s->n; ++i) {
        fsdem_real per_mass = -dt / rho;
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        /* seed 002 Eq. A.5; with Model B the whole pressure gradient acts on the fluid (Eq. 4-5:
           -grad P per volume of mixture, which is 1/eps_i times the particle's volume of fluid) */
        if (s->desc.model == FSDEM_MPS_MODEL_B) per_mass /= s->eps[i];
        s->gradp[i] = fsdem__mps_grad_at(s, s->p, i, fsdem__scale(s->desc.gravity, rho));
        s->v[i] = fsdem__madd(s->us[i], s->gradp[i], per_mass);
        if (s->dim == 2) s->v[i].z = 0;
    }
    return FSDEM_OK;
}

/* One step of dt (the section's steps 1-7, or the explicit scheme's in place of 2-6). Failures
   before the pressure is known change nothing; a completed step reports a non-finite or escaped
   particle. */
static fsdem_result fsdem__mps_do_step(fsdem_mps *s, fsdem_real dt) {
    const double time0 = s->time;
    const clock_t t0 = clock();
    clock_t ts;
    fsdem_result r;
    int i, a, bad = -1;
    if (s->counts[FSDEM_MPS_KIND_FLUID] == 0)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps: no FLUID particles to step");
    for (i = 0; i < s->n; ++i)
        if (!(s->eps[i] > 0 && s->eps[i] <= 1))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps: particle %d has porosity %g outside (0, 1]", i,
                               (double)s->eps[i]);
    if (fsdem__mps_reserve(s, s->n + s->buffered) != FSDEM_OK) /* the inflows' new particles of this step */
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps: out of memory for the inflows' particles");
    fsdem__series_begin(&s->gauges.series);
    /* 1. neighbours, number density, free surface */
    if (fsdem__mps_neighbours(s) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps: out of memory building the neighbour list");
    ts = clock();
    s->sec_search += (double)(ts - t0) / CLOCKS_PER_SEC;
    fsdem__mps_shift(s);
    r = s->desc.scheme == FSDEM_MPS_SCHEME_EXPLICIT ? fsdem__mps_explicit(s, dt) : fsdem__mps_semi_implicit(s, dt);
    if (r != FSDEM_OK) return r;
    fsdem__mps_obstacle_forces(s);
    fsdem__mps_collide(s, dt);
    for (i = 0; i < s->n; ++i)
        if (s->inlet[i] >= 0) { /* inflow buffers move at their imposed velocity */
            s->v[i] = fsdem__mps_inflow_velocity(s, s->inlet[i]);
            s->gradp[i] = fsdem__zero3();
        }
    /* 6b-7. r += dt u, and the shift */
    for (i = 0; i < s->n; ++i)
        if (s->kind[i] == FSDEM_MPS_KIND_FLUID) {
            s->x[i] = fsdem__add(fsdem__madd(s->x[i], s->v[i], dt), s->shift[i]);
            fsdem__mps_wrap(s, &s->x[i]);
        }
    fsdem__mps_open_update(s);
    s->time += (double)dt;
    s->dt_last = dt;
    s->steps++;
    s->iters_total += s->iters;
    s->sec_total += (double)(clock() - t0) / CLOCKS_PER_SEC;
    for (i = 0; i < s->n && bad < 0; ++i)
        if (s->kind[i] == FSDEM_MPS_KIND_FLUID && (!fsdem__finite3(s->v[i]) || !fsdem__finite3(s->x[i]) || !fsdem__finite(s->p[i])))
            bad = i;
    if (bad >= 0)
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_mps: step %lld: particle %d has a non-finite velocity, position or pressure",
                           s->steps, bad);
    for (i = 0; i < s->n; ++i) {
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        for (a = 0; a < s->dim; ++a)
            if (!s->desc.periodic[a] &&
                (fsdem__comp(s->x[i], a) < fsdem__comp(s->desc.domain_min, a) || fsdem__comp(s->x[i], a) > fsdem__comp(s->desc.domain_max, a)))
                return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_DOMAIN, "fsdem_mps: step %lld: particle %d left the domain at (%g, %g, %g) m",
                                   s->steps, i, (double)s->x[i].x, (double)s->x[i].y, (double)s->x[i].z);
    }
    if (fsdem__series_step(&s->gauges.series, time0, s->time) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_IO, "fsdem_mps: step %lld: writing the gauge file failed", s->steps);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_mps_stable_dt(const fsdem_mps *s, fsdem_real *dt) {
    int who;
    fsdem_real umax;
    if (!s || !dt) return FSDEM_ERR_INVALID_ARG;
    umax = fsdem__mps_umax(s, &who);
    if (!fsdem__finite(umax))
        return fsdem__fail((fsdem__status *)&s->status, FSDEM_ERR_NAN, "fsdem_mps_stable_dt: particle %d has a non-finite velocity", who);
    *dt = fsdem__mps_dt_from(s, umax);
    return fsdem__ok((fsdem__status *)&s->status);
}

fsdem_result fsdem_mps_step(fsdem_mps *s) {
    fsdem_real dt = 0;
    fsdem_result r;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem_mps_stable_dt(s, &dt)) != FSDEM_OK) return r;
    return fsdem__mps_do_step(s, dt);
}

fsdem_result fsdem_mps_check_dt(const fsdem_mps *s, fsdem_real dt) {
    fsdem__status *st;
    int who;
    fsdem_real umax, speed;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    st = (fsdem__status *)&s->status; /* the message is the object's only mutable part here */
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "fsdem_mps_step_dt: dt = %g s must be > 0 and finite", (double)dt);
    umax = fsdem__mps_umax(s, &who);
    if (!fsdem__finite(umax))
        return fsdem__fail(st, FSDEM_ERR_NAN, "fsdem_mps_step_dt: particle %d has a non-finite velocity", who);
    speed = fsdem__mps_signal_speed(s, umax);
    if (speed * dt > s->desc.cfl * s->r0 * (1 + (fsdem_real)1e-5))
        return fsdem__fail(st, FSDEM_ERR_CFL,
                           "fsdem_mps_step_dt: dt = %g s gives %s dt / r0 = %g > cfl = %g (particle %d at %g m/s; dt <= %g s)",
                           (double)dt, s->desc.scheme == FSDEM_MPS_SCHEME_EXPLICIT ? "(c0 + u_max)" : "u_max (seed 002 Eq. 37)",
                           (double)(speed * dt / s->r0), (double)s->desc.cfl, who, (double)umax, (double)(s->desc.cfl * s->r0 / speed));
    if (dt > fsdem__mps_dt_viscous(s) * (1 + (fsdem_real)1e-5))
        return fsdem__fail(st, FSDEM_ERR_CFL,
                           "fsdem_mps_step_dt: dt = %g s exceeds the viscous limit %g s of the explicit viscous term (nu = %g m^2/s; "
                           "dt nu <= 0.8 lambda eps_min / (2d))",
                           (double)dt, (double)fsdem__mps_dt_viscous(s), (double)s->desc.viscosity);
    return fsdem__ok(st);
}

fsdem_result fsdem_mps_step_dt(fsdem_mps *s, fsdem_real dt) {
    const fsdem_result res = fsdem_mps_check_dt(s, dt);
    return res == FSDEM_OK ? fsdem__mps_do_step(s, dt) : res;
}

fsdem_result fsdem_mps_advance(fsdem_mps *s, fsdem_real duration, long long *steps) {
    double end;
    long long n = 0;
    fsdem_result r = FSDEM_OK;
    if (steps) *steps = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!(duration >= 0) || !fsdem__finite(duration))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_advance: duration = %g s must be >= 0", (double)duration);
    end = s->time + (double)duration;
    while (s->time < end - 1e-12 * (end > 1 ? end : 1)) {
        fsdem_real dt = 0;
        if ((r = fsdem_mps_stable_dt(s, &dt)) != FSDEM_OK) break;
        if (s->time + dt > end) dt = (fsdem_real)(end - s->time);
        else if (s->time + 1.5 * dt > end) dt = (fsdem_real)((end - s->time) / 2);
        r = fsdem__mps_do_step(s, dt);
        ++n;
        if (r != FSDEM_OK) break;
    }
    if (steps) *steps = n;
    return r;
}

double fsdem_mps_time(const fsdem_mps *s) { return s ? s->time : 0; }
