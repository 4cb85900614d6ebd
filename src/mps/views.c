/* ---- >>mps_views : views, statistics ---- */

fsdem_mps_particles fsdem_mps_get_particles(fsdem_mps *s) {
    fsdem_mps_particles v;
    memset(&v, 0, sizeof v);
    if (!s) return v;
    v.count = s->n;
    v.dim = s->dim;
    v.position = s->x;
    v.velocity = s->v;
    v.pressure = s->p;
    v.kind = s->kind;
    v.surface = s->surf;
    v.number_density = s->nd;
    v.density = s->rho;
    v.porosity = s->eps;
    v.pressure_gradient = s->gradp;
    v.inflow = s->inlet;
    v.mass = fsdem__mps_mass(s);
    return v;
}

fsdem_claims *fsdem_mps_claims(fsdem_mps *s) { return s ? &s->claims : NULL; }

fsdem_mps_coupling fsdem_mps_get_coupling(fsdem_mps *s) {
    fsdem_mps_coupling c;
    memset(&c, 0, sizeof c);
    if (!s) return c;
    s->external = 1;
    c.count = s->n;
    c.force = s->fext;
    c.porosity = s->eps;
    return c;
}

fsdem_csr fsdem_mps_pressure_matrix(const fsdem_mps *s, const int **rows_particle) {
    fsdem_csr m;
    memset(&m, 0, sizeof m);
    if (rows_particle) *rows_particle = NULL;
    if (!s) return m;
    m.rows = s->rows;
    m.row_start = s->a_start;
    m.col = s->a_col;
    m.val = s->a_val;
    if (rows_particle) *rows_particle = s->row_particle;
    return m;
}

fsdem_mps_stats fsdem_mps_get_stats(const fsdem_mps *s) {
    fsdem_mps_stats st;
    int i, who;
    memset(&st, 0, sizeof st);
    if (!s) return st;
    st.steps = s->steps;
    st.time = s->time;
    st.dt = s->dt_last;
    st.fluid = s->counts[FSDEM_MPS_KIND_FLUID];
    st.wall = s->counts[FSDEM_MPS_KIND_WALL];
    st.dummy = s->counts[FSDEM_MPS_KIND_DUMMY];
    st.surface = s->surface_count;
    st.unknowns = s->rows;
    st.neighbours = s->pair_count;
    st.n0 = s->n0;
    st.lambda = s->lambda;
    st.f0 = s->f0;
    st.pressure_iterations = s->iters;
    st.pressure_iterations_total = s->iters_total;
    st.pressure_residual = s->residual;
    st.max_speed = fsdem__mps_umax(s, &who);
    for (i = 0; i < s->n; ++i)
        if (s->p[i] > st.max_pressure) st.max_pressure = s->p[i];
    st.seconds_total = s->sec_total;
    st.seconds_pressure = s->sec_pressure;
    st.seconds_search = s->sec_search;
    st.seconds_assembly = s->sec_assembly;
    st.seconds_solve = s->sec_solve;
    st.candidate_pairs = s->candidates;
    st.inflow_planes = s->inflow_n;
    st.outflow_planes = s->outflow_n;
    st.inflow_particles = s->inflow_total;
    st.outflow_particles = s->outflow_total;
    st.memory_bytes = s->bytes;
    return st;
}
