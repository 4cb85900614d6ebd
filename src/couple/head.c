/* ===== >>impl_couple : the coupler head, the fluids, the staged step, records =====================

   Contents: the head every coupler starts with, its class and its creation (below);
   >>couple_fluids (the three fluids through their public calls), >>couple_dem (the DEM's checks
   and substeps), >>couple_records (the per-particle records by their fields: lookup, CSV). The
   staged step itself is >>impl_couple_step, after >>impl_restart, whose saves it keeps. A coupler, this chapter included, reaches the
   solvers through their public calls only (>>doc; tests/map_check.sh holds every coupler chapter to
   it). */

/* Where a stage's CPU time goes (fsdem_coupling_stats). */
enum { FSDEM__CLOCK_FLUID = 0, FSDEM__CLOCK_DEM = 1, FSDEM__CLOCK_COUPLING = 2 };

/* One stage of a coupled step of dt: a failure's message names the coupler and the stage ("fsdem_gic:
   sand substeps: ..."). The fluid's step is the stage whose run is NULL: the driver takes it once
   for all couplers of the fluid. */
typedef struct fsdem__stage {
    const char *name;
    int clock;
    fsdem_result (*run)(fsdem_coupler *c, fsdem_real dt);
} fsdem__stage;

/* A fluid as the couplers see it: its public calls (>>couple_fluids). */
typedef struct fsdem__fluid {
    const char *name;                                   /* "PIC", as messages name it */
    const char *field;                                  /* "pic", its field in a coupler's desc */
    double (*time)(const void *fluid);
    fsdem_result (*stable_dt)(const void *fluid, fsdem_real *dt);
    fsdem_result (*step_dt)(void *fluid, fsdem_real dt);
    const char *(*last_error)(const void *fluid);
    fsdem_claims *(*claims)(void *fluid);
    fsdem_result (*gauges_hold)(void *fluid, int hold);
    fsdem_result (*reserve)(void *fluid); /* may be NULL: the room its next step would allocate, made */
                                          /*    before a coupled step keeps the state (a capacity */
                                          /*    saved with it), so that a put-back allocates nothing */
} fsdem__fluid;

/* What makes a coupler of one kind. */
typedef struct fsdem__coupler_class {
    const char *name;                   /* "fsdem_gic": its messages start so */
    const fsdem__fluid *fluid;
    size_t record_size;                 /* bytes of its per-particle record, whose first field is the int id */
    const fsdem__field *fields;         /* the record's fields (>>core), CSV columns and restart */
    int field_count;
    /* its step (>>impl_couple_step): prepare (may be NULL) does what must come before the step's
       length is known; limit (may be NULL) cuts the fluid's stable dt by the coupler's own limits;
       check refuses a dt before anything moves (chosen: the caller's dt, not a stable one); then the
       stages in order. A refusal after the state was kept puts it back. */
    fsdem_result (*prepare)(fsdem_coupler *c);
    fsdem_result (*limit)(const fsdem_coupler *c, fsdem_real *dt);
    fsdem_result (*check)(fsdem_coupler *c, fsdem_real dt, int chosen);
    const fsdem__stage *stages;
    int stage_count;
} fsdem__coupler_class;

/* The head of every coupler, its first member. */
struct fsdem_coupler {
    const fsdem__coupler_class *cls;
    fsdem__status status;
    fsdem_allocator allocator;          /* the DEM's */
    void *fluid;                        /* not owned */
    fsdem_dem *dem;                     /* not owned */
    unsigned fluid_arrays;              /* the fluid's arrays it claimed */
    long long max_substeps;             /* DEM substeps one coupled step may take */
    long long steps, substeps, substeps_total;
    fsdem_real dt_last;
    double seconds[3];                  /* CPU seconds, by clock */
    const char *stage;                  /* the name of the stage under way, for its messages */
    const void *record;                 /* the records of the last update (cls->record_size bytes */
    int records;                        /*    each, ids ascending), `records` of them (0: none) */
    unsigned char *kept;                /* the state before the step under way (fsdem__coupler_keep): */
    size_t kept_saved, kept_capacity;   /*    its saved bytes, then its records (not every field of */
    int kept_records;                   /*    a record is saved) */
};

/* The desc checks every coupler shares: a fluid of dimension fluid_dim and gravity fluid_g and a DEM
   alike, the substep bound, and the arrays the coupler would claim free (`desc` names the desc,
   "fsdem_gic_desc"). */
static fsdem_result fsdem__coupler_check(const fsdem__coupler_class *cls, const char *desc, void *fluid, unsigned arrays, fsdem_dem *dem,
                                         int fluid_dim, fsdem_vec3 fluid_g, long long max_substeps, char *msg, size_t size) {
    const fsdem_dem_desc dd = fsdem_dem_get_desc(dem);
    const char *holder;
    if (fluid_dim && dd.dim != fluid_dim)
        return fsdem__reject(msg, size, "%s: the DEM is %dD and the %s %dD", desc, dd.dim, cls->fluid->name, fluid_dim);
    if (fsdem__norm(fsdem__sub(dd.gravity, fluid_g)) > 1e-12 * fsdem__norm(fluid_g))
        return fsdem__reject(msg, size, "%s: the DEM gravity (%g, %g, %g) differs from the %s's (%g, %g, %g) m/s^2", desc, (double)dd.gravity.x,
                             (double)dd.gravity.y, (double)dd.gravity.z, cls->fluid->name, (double)fluid_g.x, (double)fluid_g.y,
                             (double)fluid_g.z);
    if (max_substeps < 1) return fsdem__reject(msg, size, "%s.max_substeps must be >= 1 (got %lld)", desc, max_substeps);
    if ((holder = fsdem_claimant(fsdem_dem_claims(dem), FSDEM_DEM_ARRAYS_LOADS)))
        return fsdem__reject(msg, size, "%s.dem: its external loads are claimed by %s (one coupler per DEM: destroy it first)", desc, holder);
    if ((holder = fsdem_claimant(cls->fluid->claims(fluid), arrays)))
        return fsdem__reject(msg, size, "%s.%s: the %s's arrays this coupler writes are claimed by %s (destroy it first)", desc,
                             cls->fluid->field, cls->fluid->name, holder);
    return FSDEM_OK;
}

/* A DEM without periodic axes, for a fluid that has none (`desc` names the desc, `fluid` the fluid):
   a particle that wraps around would jump across the fluid. */
static fsdem_result fsdem__coupler_aperiodic(const char *desc, fsdem_dem *dem, const char *fluid, char *msg, size_t size) {
    const fsdem_dem_desc dd = fsdem_dem_get_desc(dem);
    int a;
    for (a = 0; a < dd.dim; ++a)
        if (dd.periodic[a])
            return fsdem__reject(msg, size, "%s.dem is periodic along %c and the %s has no periodic axes", desc, "xyz"[a], fluid);
    return FSDEM_OK;
}

/* A new coupler of `size` bytes whose desc check gave `checked` (and `why`): zeroed, its memory from
   the DEM's allocator, its head set, the DEM's loads and the fluid's `arrays` claimed. NULL, with
   *res and the reason logged, on failure. */
static void *fsdem__coupler_new(const fsdem__coupler_class *cls, fsdem_result checked, const char *why, void *fluid, fsdem_dem *dem,
                                unsigned arrays, long long max_substeps, fsdem_log_fn log, void *log_user, size_t size,
                                fsdem_result *res) {
    char who[64];
    fsdem_allocator al;
    fsdem_coupler *c;
    memset(&al, 0, sizeof al);
    snprintf(who, sizeof who, "%s_create", cls->name);
    if (checked == FSDEM_OK) al = fsdem_dem_get_desc(dem).allocator;
    c = (fsdem_coupler *)fsdem__object_new(checked, why, log, log_user, checked == FSDEM_OK ? &al : NULL, size, who, res);
    if (!c) return NULL;
    c->cls = cls;
    c->allocator = al;
    c->status.log = log;
    c->status.log_user = log_user;
    c->fluid = fluid;
    c->dem = dem;
    c->fluid_arrays = arrays;
    c->max_substeps = max_substeps;
    /* the desc check found them free */
    fsdem_claim(fsdem_dem_claims(dem), FSDEM_DEM_ARRAYS_LOADS, c, cls->name, NULL, 0);
    fsdem_claim(cls->fluid->claims(fluid), arrays, c, cls->name, NULL, 0);
    return c;
}

/* Releases the coupler's claims and frees its `size` bytes (its own arrays freed before). */
static void fsdem__coupler_free(fsdem_coupler *c, size_t size) {
    const fsdem_allocator al = c->allocator;
    fsdem__free(&al, c->kept, c->kept_capacity);
    fsdem_release(fsdem_dem_claims(c->dem), FSDEM_DEM_ARRAYS_LOADS, c);
    fsdem_release(c->cls->fluid->claims(c->fluid), c->fluid_arrays, c);
    fsdem__free(&al, c, size);
}

static double fsdem__coupler_time(const fsdem_coupler *c) { return c->cls->fluid->time(c->fluid); }

static fsdem_coupling_stats fsdem__coupler_stats(const fsdem_coupler *c) {
    fsdem_coupling_stats st;
    st.steps = c->steps;
    st.time = fsdem__coupler_time(c);
    st.dt = c->dt_last;
    st.substeps = c->substeps;
    st.substeps_total = c->substeps_total;
    st.seconds_fluid = c->seconds[FSDEM__CLOCK_FLUID];
    st.seconds_dem = c->seconds[FSDEM__CLOCK_DEM];
    st.seconds_coupling = c->seconds[FSDEM__CLOCK_COUPLING];
    return st;
}

/* ---- >>couple_fluids : the fluids through their public calls ---- */

static double fsdem__fluid_pic_time(const void *f) { return fsdem_pic_time((const fsdem_pic *)f); }
static fsdem_result fsdem__fluid_pic_stable(const void *f, fsdem_real *dt) { return fsdem_pic_stable_dt((const fsdem_pic *)f, dt); }
static fsdem_result fsdem__fluid_pic_step(void *f, fsdem_real dt) { return fsdem_pic_step_dt((fsdem_pic *)f, dt); }
static const char *fsdem__fluid_pic_error(const void *f) { return fsdem_pic_last_error((const fsdem_pic *)f); }
static fsdem_claims *fsdem__fluid_pic_claims(void *f) { return fsdem_pic_claims((fsdem_pic *)f); }
static fsdem_result fsdem__fluid_pic_hold(void *f, int hold) { return fsdem_pic_gauges_hold((fsdem_pic *)f, hold); }
static const fsdem__fluid fsdem__fluid_pic = {"PIC", "pic", fsdem__fluid_pic_time, fsdem__fluid_pic_stable, fsdem__fluid_pic_step,
                                              fsdem__fluid_pic_error, fsdem__fluid_pic_claims, fsdem__fluid_pic_hold, NULL};

static double fsdem__fluid_mps_time(const void *f) { return fsdem_mps_time((const fsdem_mps *)f); }
static fsdem_result fsdem__fluid_mps_stable(const void *f, fsdem_real *dt) { return fsdem_mps_stable_dt((const fsdem_mps *)f, dt); }
static fsdem_result fsdem__fluid_mps_step(void *f, fsdem_real dt) { return fsdem_mps_step_dt((fsdem_mps *)f, dt); }
static const char *fsdem__fluid_mps_error(const void *f) { return fsdem_mps_last_error((const fsdem_mps *)f); }
static fsdem_claims *fsdem__fluid_mps_claims(void *f) { return fsdem_mps_claims((fsdem_mps *)f); }
static fsdem_result fsdem__fluid_mps_hold(void *f, int hold) { return fsdem_mps_gauges_hold((fsdem_mps *)f, hold); }
static fsdem_result fsdem__fluid_mps_reserve(void *f) { return fsdem_mps_reserve((fsdem_mps *)f, 0); }
static const fsdem__fluid fsdem__fluid_mps = {"MPS", "mps", fsdem__fluid_mps_time, fsdem__fluid_mps_stable, fsdem__fluid_mps_step,
                                              fsdem__fluid_mps_error, fsdem__fluid_mps_claims, fsdem__fluid_mps_hold,
                                              fsdem__fluid_mps_reserve};

static double fsdem__fluid_swe_time(const void *f) { return fsdem_swe_time((const fsdem_swe *)f); }
static fsdem_result fsdem__fluid_swe_stable(const void *f, fsdem_real *dt) { return fsdem_swe_stable_dt((const fsdem_swe *)f, dt); }
static fsdem_result fsdem__fluid_swe_step(void *f, fsdem_real dt) { return fsdem_swe_step_dt((fsdem_swe *)f, dt); }
static const char *fsdem__fluid_swe_error(const void *f) { return fsdem_swe_last_error((const fsdem_swe *)f); }
static fsdem_claims *fsdem__fluid_swe_claims(void *f) { return fsdem_swe_claims((fsdem_swe *)f); }
static fsdem_result fsdem__fluid_swe_hold(void *f, int hold) { return fsdem_swe_gauges_hold((fsdem_swe *)f, hold); }
static const fsdem__fluid fsdem__fluid_swe = {"shallow-water", "swe", fsdem__fluid_swe_time, fsdem__fluid_swe_stable, fsdem__fluid_swe_step,
                                              fsdem__fluid_swe_error, fsdem__fluid_swe_claims, fsdem__fluid_swe_hold, NULL};
