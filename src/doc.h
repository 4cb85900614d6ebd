/* fsdem.h - fluid-solid mixture flows with discrete elements. Single-file C99 library.
   Written from the files of src/ by src/pack.sh (src/README.md): edit those, not this file.

   ===== >>doc : documentation ==========================================================================

   USAGE
     In exactly one C or C++ file:
         #define FSDEM_IMPLEMENTATION
         #include "fsdem.h"
     Everywhere else include "fsdem.h" without the define. Link with libm (-lm). Nothing else.

   TABLE OF CONTENTS (grep -n '>>' fsdem.h prints the map; `make test` checks it)
     >>doc      this text
     >>config   version, configuration macros, precision-suffixed symbols
     >>core     real type, vectors, sides, results, allocator, logging, the fluid coupling sample
     >>geom     signed distances and closest points (private; DEM walls, PIC obstacles, couplers)
     >>kernel   interpolation weights on grids (private; PIC transfers, sampling, couplers)
     >>grid     cell grid (uniform spatial binning) shared by DEM, MPS and the couplings
     >>dem      discrete element method: particles, materials, contact laws, walls, integration
     >>linalg   CSR and MAC-grid stencil operators, preconditioned conjugate gradients (Jacobi,
                IC(0), MIC(0), geometric multigrid on stencils, smoothed-aggregation algebraic
                multigrid on CSR matrices) shared by the pressure solves
     >>pic      PIC/FLIP/APIC free-surface solver on a MAC grid: cut-cell obstacles, ghost-fluid
                pressure, implicit viscosity, porosity and density projection (seeds 000 and 004)
     >>swe      shallow-water equations in 1D and 2D: HLL, MUSCL-Hancock, wet/dry, well-balanced
                (seed 003)
     >>mps      MPS free-surface particle solver: fluid, wall and dummy particles, mixed-source
                pressure equation on the shared PCG, periodic axes, inflow and outflow, probes and
                gauges (seed 002)
     >>drag     drag laws of unresolved couplings: Stokes, Schiller-Naumann, Ergun/Wen-Yu (seed 002
                Eq. 26), Gidaspow blend, Di Felice, Beetstra-van der Hoef-Kuipers, the GIC law
                (seed 004)
     >>couple   what every coupler shares: the staged step (one fluid step, the DEM's substeps),
                the stable rule, the advance, per-particle records and their CSV, claims on the
                solvers' coupling arrays
     >>couple_swe  SWE-DEM floating debris: buoyancy, hydrostatic and dynamic pressure (seed 003)
     >>couple_mps  unresolved MPS-DEM, Models A and B: porosity and momentum exchange by local
                averaging, sequential staggered substepping (seed 002)
     >>couple_pic  resolved cut-cell PIC-DEM: moving discs and spheres in the pressure equation
                (implicit solid velocity), the gap and contact dissipation, subcycling (seed 000)
     >>couple_gic  Granule-In-Cell: granules smaller than a cell through volume fractions, the
                porous projections, drag, pressure-gradient force and virtual mass, sand substeps
                first (seed 004)
     >>restart  checkpoint and restart: save / restore of every solver and coupler, to a file or
                to memory, bit-exact continuation (versioned binary format with a checksum)
     >>couple_step  the coupled step, taken whole or not at all (a failure once something moved
                puts the state back), couplers of one fluid stepped together
     >>io       CSV time series; ParaView .pvd series, valid after every entry; VTK XML snapshots
                of every solver (ascii, inline base64 or appended raw): DEM particles, walls and
                contacts (.vtp), PIC particles (.vtp) and grid (.vti), shallow-water fields (.vti),
                MPS particles (.vtp)
     >>impl     implementation, in the same order (each chapter opens with its contents)
     >>licence  MIT

   CONFIGURATION MACROS (define before including)
     FSDEM_USE_FLOAT         fsdem_real is float instead of double. Every public function then has
                             an "_f" suffix at link time (fsdem_dem_create links as
                             fsdem_dem_create_f), so objects compiled with and without it cannot
                             be linked together silently: define it in every translation unit or
                             in none.
     FSDEM_MALLOC(sz)        default allocator; define FSDEM_MALLOC, FSDEM_REALLOC and FSDEM_FREE
     FSDEM_REALLOC(p, sz)    all three or none. An fsdem_allocator in a desc overrides them per
     FSDEM_FREE(p)           object. Read only by the implementation's translation unit.
     FSDEM_ASSERT(c)         programmer-error checks (default: assert from <assert.h>).
     FSDEM_API               decoration of public functions (default: extern); the same in every
                             translation unit.
     FSDEM_NO_SIMD           batched kernels (the DEM contact law) use one real per lane instead of
                             the compiler's vectors. By default they use GNU vector extensions as wide
                             as the target flags allow: 2 doubles with SSE2 (any x86-64), 4 with
                             -mavx2, 8 with -mavx512f or -march=native on such a CPU. Read only by
                             the implementation's translation unit.
     FSDEM_NO_OPENMP         no threads even in a build with -fopenmp (the library's loops run on
                             the calling thread, as without OpenMP). Read only by the
                             implementation's translation unit.
     FSDEM_VERSION_MAJOR/MINOR/PATCH, FSDEM_VERSION_STRING: the version of this file (read-only).

   CONCEPTS
     Units are SI throughout: metres, seconds, kilograms, newtons, pascals, radians.
     Dimension is a runtime field of each desc (2 or 3). Vectors always have three components.
     In 2D the motion lies in the x-y plane, z is unused and gravity defaults to (0, -9.81, 0);
     particles are discs of out-of-plane length `disc_length` (so a 2D run of cylinders has their
     real mass). In 3D particles are spheres and gravity defaults to (0, 0, -9.81).
     Objects are created from a desc filled by fsdem_<noun>_desc_default() and then edited: zero is
     a meaningful value for gravity or friction, so defaults never come from zero-initialisation.

   HELLO WORLD (a sphere dropped on a floor)
     fsdem_dem_desc d = fsdem_dem_desc_default(3);
     d.domain_min = fsdem_v3(-1, -1, 0); d.domain_max = fsdem_v3(1, 1, 2);
     d.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
     d.dt = 1e-5;
     fsdem_dem *dem;
     if (fsdem_dem_create(&d, &dem) != FSDEM_OK) return 1;
     fsdem_dem_material mat = fsdem_dem_material_default();          (2500 kg/m3, E = 1e8 Pa, e = 0.5)
     int steel; fsdem_dem_add_material(dem, &mat, &steel);
     fsdem_dem_wall_desc floor = fsdem_dem_wall_plane(fsdem_v3(0, 0, 0), fsdem_v3(0, 0, 1), steel);
     fsdem_dem_add_wall(dem, &floor, NULL);
     fsdem_dem_particle_desc p = fsdem_dem_particle_desc_default();
     p.position = fsdem_v3(0, 0, 0.5); p.radius = 0.01; p.material = steel;
     fsdem_dem_add_particle(dem, &p, NULL);
     for (int s = 0; s < 100000; ++s)
         if (fsdem_dem_step(dem) != FSDEM_OK) { puts(fsdem_dem_last_error(dem)); break; }
     fsdem_dem_destroy(dem);

   ONE DIALECT FOR EVERY SOLVER
     Each solver (fsdem_dem, fsdem_pic, fsdem_swe, fsdem_mps) and each coupler (fsdem_swe_dem,
     fsdem_mps_dem, fsdem_pic_dem, fsdem_gic) speaks these verbs; X is the object's name
     (tests/map_check.sh holds every one of them to the table). A solver adds verbs of its own
     (add_particle, set_bed, ...); a coupler adds fsdem_X_update(x) (what it writes into the
     solvers, from the current state, without stepping), fsdem_X_get_force(x, index, &record) (its
     per-particle record), fsdem_X_write_csv(x, path) (the records) and fsdem_X_coupler(x) (the
     coupler as any coupler, to step with others of its fluid: fsdem_coupled_step, >>couple).
       fsdem_X_desc fsdem_X_desc_default(dim)      defaults (couplers and fsdem_pcg: no argument)
       fsdem_result fsdem_X_desc_check(desc, message, size)  validation without creating anything
       fsdem_result fsdem_X_create(desc, &x)        *x is NULL on failure; destroy with _destroy
       void         fsdem_X_destroy(x)              NULL is allowed; a coupler before its solvers
       const char  *fsdem_X_last_error(x)           message of the last failed call ("" after success)
       fsdem_X_desc fsdem_X_get_desc(x)             the desc in force (with values resolved)
       fsdem_result fsdem_X_step(x)                 one step of the object's own size: the DEM's dt,
                                                    a fluid's stable (adaptive) dt
       fsdem_result fsdem_X_step_dt(x, dt)          one step of exactly dt (s); FSDEM_ERR_CFL, with
                                                    nothing changed, where dt is unstable
       fsdem_result fsdem_X_advance(x, duration, &steps)  steps until exactly `duration` (s) later;
                                                    steps (long long, may be NULL) counts them
       fsdem_result fsdem_X_stable_dt(x, &dt)       the stable step of the current state (s)
       double       fsdem_X_time(x)                 simulated time (s), a double everywhere
       fsdem_X_stats fsdem_X_get_stats(x)           counters and figures; starts with
                                                    long long steps, double time, fsdem_real dt (a
                                                    coupler's with fsdem_coupling_stats, which does)
       fsdem_X_particles / fsdem_X_fields fsdem_X_get_particles / _get_fields(x)  views (SoA)
       fsdem_result fsdem_X_write_<what>(x, path)   snapshots: CSV, and VTK XML (.vtp, .vti) with a
                                                    last argument fsdem_vtk_format (>>io); FSDEM_ERR_IO
       fsdem_result fsdem_X_save / _restore(x, path)  checkpoint and restart (>>restart): the whole
                                                    state to a file and back into an object made
                                                    from the same desc, the run going on bit for bit;
                                                    _save_memory / _restore_memory with a buffer
     Gravity is a vector (m/s^2) in every desc. A NULL object pointer is refused with
     FSDEM_ERR_INVALID_ARG by every function that returns a result (getters return zeros, last_error
     says which object is NULL). Messages start with the public name they concern: the function
     (`fsdem_pic_add_obstacle: ...`), the desc field (`fsdem_swe_desc.cfl must ...`), or for failures
     inside time stepping the object (`fsdem_dem: particle 12 (id 40) left the domain ...`).
     Public types of a module carry its name (fsdem_dem_material, fsdem_pic_bc); enum values are
     FSDEM_<ENUM>_<VALUE> (fsdem_dem_law: FSDEM_DEM_LAW_LINEAR), result codes alone excepted
     (FSDEM_OK, FSDEM_ERR_<WHAT>); private names are fsdem__<module>_... (core helpers: fsdem__...).
     "stencil" means one thing: the matrix-free MAC-grid operator fsdem_stencil of >>linalg;
     interpolation weights are "kernels" (>>kernel).

   COUPLING INTERFACE
     A coupler is named fsdem_<fluid>_dem (fsdem_swe_dem, fsdem_mps_dem, fsdem_pic_dem), or after
     its method (fsdem_gic, Granule-In-Cell, PIC with granules), and holds non-owning pointers to a
     fluid and a DEM (destroy it before them). It reaches them only through these functions:
       DEM   fsdem_dem_get_particles (read), fsdem_dem_get_desc, fsdem_dem_get_coupling (writable
             external loads), fsdem_dem_substep_count, fsdem_dem_advance_with (substeps with a
             callback at every force evaluation, Verlet substeps fused)
       fluid fsdem_<fluid>_sample (velocity, pressure gradient, volume fraction at points),
             fsdem_<fluid>_add_force / _clear_forces (momentum sources), fsdem_<fluid>_get_coupling
             (writable per-cell, per-face or per-particle arrays), fsdem_<fluid>_get_desc, stable_dt,
             step_dt, and for the shallow water fsdem_swe_sample_state (depth-averaged state at
             (x, y)). The MPS solver, whose fluid is particles, is sampled through its particle view
             (fsdem_mps_get_particles: positions, velocities, pressure gradients) and takes forces
             and porosities through fsdem_mps_get_coupling. The PIC, whose solids are cut faces,
             takes moving solids through fsdem_pic_get_coupling (open fractions, solid velocities
             at the start and end of the step, references, the granules' porosity; shear read back),
             fsdem_pic_set_pressure_extra (an implicit term of the pressure operator, and the
             solids' answer to the solved pressure) and fsdem_pic_exclude_particles, and is read
             through fsdem_pic_get_fields (pressure, open fractions) and fsdem_pic_get_particles.
       both  fsdem_<solver>_claims and fsdem_claim: a coupler claims the arrays it writes (the
             DEM's external loads, the fluid's arrays of its kind) for as long as it lives, so two
             couplers never write one array; couplers of one fluid that write different arrays
             step together (fsdem_coupled_step, >>couple). tests/map_check.sh refuses a coupler
             chapter that calls a solver's private helper or reads a solver's struct.

   THREAD SAFETY
     No global mutable state. Distinct objects may be used from distinct threads at once; one
     object must not be used from two threads at once.

   THREADS
     Built with OpenMP (-fopenmp; FSDEM_NO_OPENMP keeps such a build on one thread), a step runs its
     loops on OpenMP threads (fsdem_set_threads, or OMP_NUM_THREADS). Results do not depend on the
     thread count, bit for bit, and equal those of a build without OpenMP: no floating-point
     atomics; each value is written by one thread, and a sum over many items is taken in an order
     fixed by the data alone (the PCG's dot products in blocks of FSDEM__DOT_BLOCK entries, added
     block by block; the contact forces on a particle in the order of the contact list). `make
     determinism` pins the same hashes at 1, 2, 3 and 4 threads. One rule sizes every team
     (fsdem__team_for in >>core: the thread count, but no more threads than the loop's items over
     its grain, nor than its work buffers were sized for); every function that opens a parallel
     region or runs inside one says so in a `threaded:` line above it; the one wait between threads
     (the multigrid pipeline's) uses OpenMP atomics and pauses the CPU while it spins.
     Threaded so far: the shallow-water rows (bands of rows, each with its own work rows and a
     copy of the rows beside it), the PCG on stencils (the levels' construction, the operator,
     Jacobi, the multigrid V-cycle as one pipeline per thread, vector updates, dot products), the
     DEM's touching pass, contact kernels and integration, and the PIC's grid-to-particle transfer
     and advection (its solves through the PCG). IC(0)/MIC(0), AMG, the DEM's wall contacts and
     neighbour lists, the PIC's particle-to-grid transfer and grid loops, MPS and the couplers' own
     loops run on one thread. Work buffers are sized for the thread count at creation (SWE), setup
     (PCG) or the last neighbour-list build (DEM); a larger team later uses that many threads.

   ERRORS
     Fallible calls return fsdem_result: FSDEM_OK (0) or a negative code; fsdem_result_string()
     names it. The object keeps a message with the detail (which field, which particle), read with
     fsdem_<object>_last_error(). Bad input is rejected before anything changes, so the object stays
     as it was and usable. Beyond NaN and infinity, values no flow could have are bad input too: the
     plausibility bounds of >>core (FSDEM_MAX_SPEED, FSDEM_MAX_ACCELERATION, FSDEM_MAX_LENGTH,
     FSDEM_MAX_MODULUS) refuse a speed of 1e200 m/s at the call instead of a NaN steps later. A
     solver's step that produces a non-finite value or moves a particle out of the domain completes,
     returns FSDEM_ERR_NAN or FSDEM_ERR_OUT_OF_DOMAIN and names the particle; the caller may remove
     it and go on. A coupled step is taken whole or not at all: a failure of either solver puts the
     coupler, the fluid and the DEM back as they were before the call (>>couple_step). The library never prints and never exits; an optional log
     callback in each desc receives the same messages. FSDEM_ASSERT guards programmer errors only
     (out-of-range indices into arrays the caller owns).
*/
