/* fsdem.h - fluid-solid mixture flows with discrete elements. Single-file C99 library.

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
                IC(0), MIC(0), geometric multigrid) shared by the pressure solves
     >>pic      PIC/FLIP/APIC free-surface solver on a MAC grid: cut-cell obstacles, ghost-fluid
                pressure, implicit viscosity, density projection (seeds 000 and 004)
     >>swe      shallow-water equations in 1D and 2D: HLL, MUSCL-Hancock, wet/dry, well-balanced
                (seed 003)
     >>couple_swe  SWE-DEM floating debris: buoyancy, hydrostatic and dynamic pressure (seed 003)
     >>mps      MPS free-surface particle solver: fluid, wall and dummy particles, mixed-source
                pressure equation on the shared PCG, probes and gauges (seed 002)
     >>drag     drag laws of unresolved couplings: Stokes, Schiller-Naumann, Ergun/Wen-Yu (seed 002
                Eq. 26), Gidaspow blend, Di Felice, Beetstra-van der Hoef-Kuipers
     >>couple_mps  unresolved MPS-DEM, Models A and B: porosity and momentum exchange by local
                averaging, sequential staggered substepping (seed 002)
     >>couple_pic  resolved cut-cell PIC-DEM: moving discs and spheres in the pressure equation
                (implicit solid velocity), the gap and contact dissipation, subcycling (seed 000)
     >>restart  checkpoint and restart: save / restore of every solver and coupler, to a file or
                to memory, bit-exact continuation (versioned binary format with a checksum)
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
     fsdem_mps_dem, fsdem_pic_dem) speaks these verbs; X is the object's name (tests/map_check.sh
     holds every one of them to the table). A solver adds verbs of its own (add_particle, set_bed,
     ...); a coupler's per-particle record is fsdem_X_get_force(x, index, &record).
       fsdem_X_desc fsdem_X_desc_default(dim)      defaults (couplers and fsdem_pcg: no argument)
       fsdem_result fsdem_X_desc_check(desc, message, size)  validation without creating anything
       fsdem_result fsdem_X_create(desc, &x)        *x is NULL on failure; destroy with _destroy
       void         fsdem_X_destroy(x)              NULL is allowed
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
                                                    long long steps, double time, fsdem_real dt
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
     A coupler is named fsdem_<fluid>_dem (fsdem_swe_dem, fsdem_mps_dem, fsdem_pic_dem) and
     holds non-owning pointers to a fluid and a DEM. It reaches them only through these functions:
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
             takes moving solids through fsdem_pic_get_coupling (open fractions, solid velocities,
             references; shear read back), fsdem_pic_set_pressure_extra (an implicit term of the
             pressure operator) and fsdem_pic_exclude_particles, and is read through
             fsdem_pic_get_fields (pressure, open fractions) and fsdem_pic_get_particles.

   THREAD SAFETY
     No global mutable state. Distinct objects may be used from distinct threads at once; one
     object must not be used from two threads at once.

   ERRORS
     Fallible calls return fsdem_result: FSDEM_OK (0) or a negative code; fsdem_result_string()
     names it. The object keeps a message with the detail (which field, which particle), read with
     fsdem_<object>_last_error(). Bad input is rejected before anything changes, so the object stays
     as it was and usable. Beyond NaN and infinity, values no flow could have are bad input too: the
     plausibility bounds of >>core (FSDEM_MAX_SPEED, FSDEM_MAX_ACCELERATION, FSDEM_MAX_LENGTH,
     FSDEM_MAX_MODULUS) refuse a speed of 1e200 m/s at the call instead of a NaN steps later. A step that produces a non-finite value or moves a particle out of the
     domain completes, returns FSDEM_ERR_NAN or FSDEM_ERR_OUT_OF_DOMAIN and names the particle; the
     caller may remove it and go on. The library never prints and never exits; an optional log
     callback in each desc receives the same messages. FSDEM_ASSERT guards programmer errors only
     (out-of-range indices into arrays the caller owns).
*/
#ifndef FSDEM_H_INCLUDED
#define FSDEM_H_INCLUDED

/* ===== >>config : version, configuration macros, precision-suffixed symbols ======================== */

#include <stddef.h>

#define FSDEM_VERSION_MAJOR 0
#define FSDEM_VERSION_MINOR 9
#define FSDEM_VERSION_PATCH 0
#define FSDEM_VERSION_STRING "0.9.0"

/* FSDEM__SYMBOLS_BEGIN (generated by tests/map_check.sh --symbols; the check fails when a public
   function is missing here) */
#ifdef FSDEM_USE_FLOAT
#define fsdem_cellgrid_build fsdem_cellgrid_build_f
#define fsdem_cellgrid_cell fsdem_cellgrid_cell_f
#define fsdem_cellgrid_forward fsdem_cellgrid_forward_f
#define fsdem_cellgrid_free fsdem_cellgrid_free_f
#define fsdem_cellgrid_neighbourhood fsdem_cellgrid_neighbourhood_f
#define fsdem_cellgrid_setup fsdem_cellgrid_setup_f
#define fsdem_cellgrid_setup_periodic fsdem_cellgrid_setup_periodic_f
#define fsdem_csr_apply fsdem_csr_apply_f
#define fsdem_csr_check fsdem_csr_check_f
#define fsdem_csv_close fsdem_csv_close_f
#define fsdem_csv_open fsdem_csv_open_f
#define fsdem_csv_row fsdem_csv_row_f
#define fsdem_dem_add_material fsdem_dem_add_material_f
#define fsdem_dem_add_particle fsdem_dem_add_particle_f
#define fsdem_dem_add_wall fsdem_dem_add_wall_f
#define fsdem_dem_advance fsdem_dem_advance_f
#define fsdem_dem_advance_with fsdem_dem_advance_with_f
#define fsdem_dem_contacts fsdem_dem_contacts_f
#define fsdem_dem_create fsdem_dem_create_f
#define fsdem_dem_desc_check fsdem_dem_desc_check_f
#define fsdem_dem_desc_default fsdem_dem_desc_default_f
#define fsdem_dem_destroy fsdem_dem_destroy_f
#define fsdem_dem_get_coupling fsdem_dem_get_coupling_f
#define fsdem_dem_get_desc fsdem_dem_get_desc_f
#define fsdem_dem_get_energy fsdem_dem_get_energy_f
#define fsdem_dem_get_material_pair fsdem_dem_get_material_pair_f
#define fsdem_dem_get_particles fsdem_dem_get_particles_f
#define fsdem_dem_get_stats fsdem_dem_get_stats_f
#define fsdem_dem_last_error fsdem_dem_last_error_f
#define fsdem_dem_material_default fsdem_dem_material_default_f
#define fsdem_dem_particle_desc_default fsdem_dem_particle_desc_default_f
#define fsdem_dem_remove_particle fsdem_dem_remove_particle_f
#define fsdem_dem_remove_wall fsdem_dem_remove_wall_f
#define fsdem_dem_restore fsdem_dem_restore_f
#define fsdem_dem_restore_memory fsdem_dem_restore_memory_f
#define fsdem_dem_save fsdem_dem_save_f
#define fsdem_dem_save_memory fsdem_dem_save_memory_f
#define fsdem_dem_set_dt fsdem_dem_set_dt_f
#define fsdem_dem_set_material_pair fsdem_dem_set_material_pair_f
#define fsdem_dem_set_particle_state fsdem_dem_set_particle_state_f
#define fsdem_dem_set_wall_velocity fsdem_dem_set_wall_velocity_f
#define fsdem_dem_stable_dt fsdem_dem_stable_dt_f
#define fsdem_dem_step fsdem_dem_step_f
#define fsdem_dem_step_dt fsdem_dem_step_dt_f
#define fsdem_dem_substep_count fsdem_dem_substep_count_f
#define fsdem_dem_time fsdem_dem_time_f
#define fsdem_dem_wall_box fsdem_dem_wall_box_f
#define fsdem_dem_wall_force fsdem_dem_wall_force_f
#define fsdem_dem_wall_impulse fsdem_dem_wall_impulse_f
#define fsdem_dem_wall_moved fsdem_dem_wall_moved_f
#define fsdem_dem_wall_plane fsdem_dem_wall_plane_f
#define fsdem_dem_wall_sdf fsdem_dem_wall_sdf_f
#define fsdem_dem_wall_segment fsdem_dem_wall_segment_f
#define fsdem_dem_wall_triangle fsdem_dem_wall_triangle_f
#define fsdem_dem_write_contacts_vtp fsdem_dem_write_contacts_vtp_f
#define fsdem_dem_write_csv fsdem_dem_write_csv_f
#define fsdem_dem_write_vtp fsdem_dem_write_vtp_f
#define fsdem_dem_write_walls_vtp fsdem_dem_write_walls_vtp_f
#define fsdem_drag_coefficient fsdem_drag_coefficient_f
#define fsdem_drag_law_name fsdem_drag_law_name_f
#define fsdem_mps_add_box_obstacle fsdem_mps_add_box_obstacle_f
#define fsdem_mps_add_box_walls fsdem_mps_add_box_walls_f
#define fsdem_mps_add_gauge fsdem_mps_add_gauge_f
#define fsdem_mps_add_particles fsdem_mps_add_particles_f
#define fsdem_mps_advance fsdem_mps_advance_f
#define fsdem_mps_create fsdem_mps_create_f
#define fsdem_mps_dem_advance fsdem_mps_dem_advance_f
#define fsdem_mps_dem_create fsdem_mps_dem_create_f
#define fsdem_mps_dem_desc_check fsdem_mps_dem_desc_check_f
#define fsdem_mps_dem_desc_default fsdem_mps_dem_desc_default_f
#define fsdem_mps_dem_destroy fsdem_mps_dem_destroy_f
#define fsdem_mps_dem_get_desc fsdem_mps_dem_get_desc_f
#define fsdem_mps_dem_get_force fsdem_mps_dem_get_force_f
#define fsdem_mps_dem_get_stats fsdem_mps_dem_get_stats_f
#define fsdem_mps_dem_last_error fsdem_mps_dem_last_error_f
#define fsdem_mps_dem_restore fsdem_mps_dem_restore_f
#define fsdem_mps_dem_restore_memory fsdem_mps_dem_restore_memory_f
#define fsdem_mps_dem_save fsdem_mps_dem_save_f
#define fsdem_mps_dem_save_memory fsdem_mps_dem_save_memory_f
#define fsdem_mps_dem_stable_dt fsdem_mps_dem_stable_dt_f
#define fsdem_mps_dem_step fsdem_mps_dem_step_f
#define fsdem_mps_dem_step_dt fsdem_mps_dem_step_dt_f
#define fsdem_mps_dem_time fsdem_mps_dem_time_f
#define fsdem_mps_dem_update fsdem_mps_dem_update_f
#define fsdem_mps_dem_write_csv fsdem_mps_dem_write_csv_f
#define fsdem_mps_desc_check fsdem_mps_desc_check_f
#define fsdem_mps_desc_default fsdem_mps_desc_default_f
#define fsdem_mps_destroy fsdem_mps_destroy_f
#define fsdem_mps_divergence fsdem_mps_divergence_f
#define fsdem_mps_fill_box fsdem_mps_fill_box_f
#define fsdem_mps_gauge fsdem_mps_gauge_f
#define fsdem_mps_gauges_close fsdem_mps_gauges_close_f
#define fsdem_mps_gauges_open fsdem_mps_gauges_open_f
#define fsdem_mps_get_coupling fsdem_mps_get_coupling_f
#define fsdem_mps_get_desc fsdem_mps_get_desc_f
#define fsdem_mps_get_particles fsdem_mps_get_particles_f
#define fsdem_mps_get_stats fsdem_mps_get_stats_f
#define fsdem_mps_gradient fsdem_mps_gradient_f
#define fsdem_mps_laplacian fsdem_mps_laplacian_f
#define fsdem_mps_last_error fsdem_mps_last_error_f
#define fsdem_mps_obstacle_force fsdem_mps_obstacle_force_f
#define fsdem_mps_pressure_matrix fsdem_mps_pressure_matrix_f
#define fsdem_mps_probe_height fsdem_mps_probe_height_f
#define fsdem_mps_probe_pressure fsdem_mps_probe_pressure_f
#define fsdem_mps_restore fsdem_mps_restore_f
#define fsdem_mps_restore_memory fsdem_mps_restore_memory_f
#define fsdem_mps_save fsdem_mps_save_f
#define fsdem_mps_save_memory fsdem_mps_save_memory_f
#define fsdem_mps_stable_dt fsdem_mps_stable_dt_f
#define fsdem_mps_step fsdem_mps_step_f
#define fsdem_mps_step_dt fsdem_mps_step_dt_f
#define fsdem_mps_time fsdem_mps_time_f
#define fsdem_mps_write_csv fsdem_mps_write_csv_f
#define fsdem_mps_write_vtp fsdem_mps_write_vtp_f
#define fsdem_pcg_create fsdem_pcg_create_f
#define fsdem_pcg_desc_check fsdem_pcg_desc_check_f
#define fsdem_pcg_desc_default fsdem_pcg_desc_default_f
#define fsdem_pcg_destroy fsdem_pcg_destroy_f
#define fsdem_pcg_last_error fsdem_pcg_last_error_f
#define fsdem_pcg_set_tolerance fsdem_pcg_set_tolerance_f
#define fsdem_pcg_setup_csr fsdem_pcg_setup_csr_f
#define fsdem_pcg_setup_stencil fsdem_pcg_setup_stencil_f
#define fsdem_pcg_solve fsdem_pcg_solve_f
#define fsdem_pic_add_force fsdem_pic_add_force_f
#define fsdem_pic_add_gauge fsdem_pic_add_gauge_f
#define fsdem_pic_add_obstacle fsdem_pic_add_obstacle_f
#define fsdem_pic_add_particles fsdem_pic_add_particles_f
#define fsdem_pic_advance fsdem_pic_advance_f
#define fsdem_pic_clear_forces fsdem_pic_clear_forces_f
#define fsdem_pic_create fsdem_pic_create_f
#define fsdem_pic_dem_advance fsdem_pic_dem_advance_f
#define fsdem_pic_dem_create fsdem_pic_dem_create_f
#define fsdem_pic_dem_desc_check fsdem_pic_dem_desc_check_f
#define fsdem_pic_dem_desc_default fsdem_pic_dem_desc_default_f
#define fsdem_pic_dem_destroy fsdem_pic_dem_destroy_f
#define fsdem_pic_dem_get_desc fsdem_pic_dem_get_desc_f
#define fsdem_pic_dem_get_force fsdem_pic_dem_get_force_f
#define fsdem_pic_dem_get_stats fsdem_pic_dem_get_stats_f
#define fsdem_pic_dem_last_error fsdem_pic_dem_last_error_f
#define fsdem_pic_dem_restore fsdem_pic_dem_restore_f
#define fsdem_pic_dem_restore_memory fsdem_pic_dem_restore_memory_f
#define fsdem_pic_dem_save fsdem_pic_dem_save_f
#define fsdem_pic_dem_save_memory fsdem_pic_dem_save_memory_f
#define fsdem_pic_dem_stable_dt fsdem_pic_dem_stable_dt_f
#define fsdem_pic_dem_step fsdem_pic_dem_step_f
#define fsdem_pic_dem_step_dt fsdem_pic_dem_step_dt_f
#define fsdem_pic_dem_time fsdem_pic_dem_time_f
#define fsdem_pic_dem_write_csv fsdem_pic_dem_write_csv_f
#define fsdem_pic_desc_check fsdem_pic_desc_check_f
#define fsdem_pic_desc_default fsdem_pic_desc_default_f
#define fsdem_pic_destroy fsdem_pic_destroy_f
#define fsdem_pic_exclude_particles fsdem_pic_exclude_particles_f
#define fsdem_pic_fill_box fsdem_pic_fill_box_f
#define fsdem_pic_fill_sdf fsdem_pic_fill_sdf_f
#define fsdem_pic_gauge fsdem_pic_gauge_f
#define fsdem_pic_gauges_close fsdem_pic_gauges_close_f
#define fsdem_pic_gauges_open fsdem_pic_gauges_open_f
#define fsdem_pic_get_coupling fsdem_pic_get_coupling_f
#define fsdem_pic_get_desc fsdem_pic_get_desc_f
#define fsdem_pic_get_fields fsdem_pic_get_fields_f
#define fsdem_pic_get_particles fsdem_pic_get_particles_f
#define fsdem_pic_get_stats fsdem_pic_get_stats_f
#define fsdem_pic_last_error fsdem_pic_last_error_f
#define fsdem_pic_obstacle_box fsdem_pic_obstacle_box_f
#define fsdem_pic_obstacle_cylinder fsdem_pic_obstacle_cylinder_f
#define fsdem_pic_obstacle_polygon fsdem_pic_obstacle_polygon_f
#define fsdem_pic_obstacle_sdf fsdem_pic_obstacle_sdf_f
#define fsdem_pic_obstacle_sphere fsdem_pic_obstacle_sphere_f
#define fsdem_pic_reserve fsdem_pic_reserve_f
#define fsdem_pic_restore fsdem_pic_restore_f
#define fsdem_pic_restore_memory fsdem_pic_restore_memory_f
#define fsdem_pic_sample fsdem_pic_sample_f
#define fsdem_pic_save fsdem_pic_save_f
#define fsdem_pic_save_memory fsdem_pic_save_memory_f
#define fsdem_pic_set_pressure_extra fsdem_pic_set_pressure_extra_f
#define fsdem_pic_solid_distance fsdem_pic_solid_distance_f
#define fsdem_pic_stable_dt fsdem_pic_stable_dt_f
#define fsdem_pic_step fsdem_pic_step_f
#define fsdem_pic_step_dt fsdem_pic_step_dt_f
#define fsdem_pic_time fsdem_pic_time_f
#define fsdem_pic_write_grid_csv fsdem_pic_write_grid_csv_f
#define fsdem_pic_write_grid_vti fsdem_pic_write_grid_vti_f
#define fsdem_pic_write_particles_csv fsdem_pic_write_particles_csv_f
#define fsdem_pic_write_particles_vtp fsdem_pic_write_particles_vtp_f
#define fsdem_pvd_add fsdem_pvd_add_f
#define fsdem_pvd_close fsdem_pvd_close_f
#define fsdem_pvd_open fsdem_pvd_open_f
#define fsdem_result_string fsdem_result_string_f
#define fsdem_stencil_apply fsdem_stencil_apply_f
#define fsdem_stencil_check fsdem_stencil_check_f
#define fsdem_swe_add_force fsdem_swe_add_force_f
#define fsdem_swe_add_gauge fsdem_swe_add_gauge_f
#define fsdem_swe_add_point_source fsdem_swe_add_point_source_f
#define fsdem_swe_advance fsdem_swe_advance_f
#define fsdem_swe_bed_sdf fsdem_swe_bed_sdf_f
#define fsdem_swe_block_box fsdem_swe_block_box_f
#define fsdem_swe_block_polygon fsdem_swe_block_polygon_f
#define fsdem_swe_cell_at fsdem_swe_cell_at_f
#define fsdem_swe_clear_forces fsdem_swe_clear_forces_f
#define fsdem_swe_copy_field fsdem_swe_copy_field_f
#define fsdem_swe_create fsdem_swe_create_f
#define fsdem_swe_dem_advance fsdem_swe_dem_advance_f
#define fsdem_swe_dem_create fsdem_swe_dem_create_f
#define fsdem_swe_dem_desc_check fsdem_swe_dem_desc_check_f
#define fsdem_swe_dem_desc_default fsdem_swe_dem_desc_default_f
#define fsdem_swe_dem_destroy fsdem_swe_dem_destroy_f
#define fsdem_swe_dem_get_desc fsdem_swe_dem_get_desc_f
#define fsdem_swe_dem_get_force fsdem_swe_dem_get_force_f
#define fsdem_swe_dem_get_stats fsdem_swe_dem_get_stats_f
#define fsdem_swe_dem_last_error fsdem_swe_dem_last_error_f
#define fsdem_swe_dem_restore fsdem_swe_dem_restore_f
#define fsdem_swe_dem_restore_memory fsdem_swe_dem_restore_memory_f
#define fsdem_swe_dem_save fsdem_swe_dem_save_f
#define fsdem_swe_dem_save_memory fsdem_swe_dem_save_memory_f
#define fsdem_swe_dem_stable_dt fsdem_swe_dem_stable_dt_f
#define fsdem_swe_dem_step fsdem_swe_dem_step_f
#define fsdem_swe_dem_step_dt fsdem_swe_dem_step_dt_f
#define fsdem_swe_dem_time fsdem_swe_dem_time_f
#define fsdem_swe_dem_update_forces fsdem_swe_dem_update_forces_f
#define fsdem_swe_dem_write_csv fsdem_swe_dem_write_csv_f
#define fsdem_swe_desc_check fsdem_swe_desc_check_f
#define fsdem_swe_desc_default fsdem_swe_desc_default_f
#define fsdem_swe_destroy fsdem_swe_destroy_f
#define fsdem_swe_gauge fsdem_swe_gauge_f
#define fsdem_swe_gauges_close fsdem_swe_gauges_close_f
#define fsdem_swe_gauges_open fsdem_swe_gauges_open_f
#define fsdem_swe_get_coupling fsdem_swe_get_coupling_f
#define fsdem_swe_get_desc fsdem_swe_get_desc_f
#define fsdem_swe_get_fields fsdem_swe_get_fields_f
#define fsdem_swe_get_grid fsdem_swe_get_grid_f
#define fsdem_swe_get_stats fsdem_swe_get_stats_f
#define fsdem_swe_last_error fsdem_swe_last_error_f
#define fsdem_swe_momentum fsdem_swe_momentum_f
#define fsdem_swe_remove_point_source fsdem_swe_remove_point_source_f
#define fsdem_swe_restore fsdem_swe_restore_f
#define fsdem_swe_restore_memory fsdem_swe_restore_memory_f
#define fsdem_swe_sample fsdem_swe_sample_f
#define fsdem_swe_sample_state fsdem_swe_sample_state_f
#define fsdem_swe_save fsdem_swe_save_f
#define fsdem_swe_save_memory fsdem_swe_save_memory_f
#define fsdem_swe_set_bed fsdem_swe_set_bed_f
#define fsdem_swe_set_blocked fsdem_swe_set_blocked_f
#define fsdem_swe_set_boundary fsdem_swe_set_boundary_f
#define fsdem_swe_set_cells fsdem_swe_set_cells_f
#define fsdem_swe_set_depth fsdem_swe_set_depth_f
#define fsdem_swe_set_manning fsdem_swe_set_manning_f
#define fsdem_swe_set_rain fsdem_swe_set_rain_f
#define fsdem_swe_set_surface fsdem_swe_set_surface_f
#define fsdem_swe_set_velocity fsdem_swe_set_velocity_f
#define fsdem_swe_stable_dt fsdem_swe_stable_dt_f
#define fsdem_swe_step fsdem_swe_step_f
#define fsdem_swe_step_dt fsdem_swe_step_dt_f
#define fsdem_swe_time fsdem_swe_time_f
#define fsdem_swe_volume fsdem_swe_volume_f
#define fsdem_swe_write_csv fsdem_swe_write_csv_f
#define fsdem_swe_write_vti fsdem_swe_write_vti_f
#endif
/* FSDEM__SYMBOLS_END */

#ifndef FSDEM_API
#define FSDEM_API extern
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ===== >>core : real type, vectors, results, allocator, logging =================================== */

#ifdef FSDEM_USE_FLOAT
typedef float fsdem_real;
#else
typedef double fsdem_real;
#endif

typedef struct fsdem_vec3 {
    fsdem_real x, y, z;
} fsdem_vec3;

/* Sides of a box domain, in the order of the axes (index into a desc's boundary arrays). */
typedef enum fsdem_side {
    FSDEM_SIDE_XMIN = 0,
    FSDEM_SIDE_XMAX = 1,
    FSDEM_SIDE_YMIN = 2,
    FSDEM_SIDE_YMAX = 3,
    FSDEM_SIDE_ZMIN = 4,
    FSDEM_SIDE_ZMAX = 5
} fsdem_side;

/* Result of every fallible call. 0 is success, negative values are errors. */
typedef enum fsdem_result {
    FSDEM_OK = 0,
    FSDEM_ERR_INVALID_ARG = -1,   /* a desc field or argument is out of range or not finite */
    FSDEM_ERR_OUT_OF_MEMORY = -2, /* the allocator returned NULL or a size overflowed */
    FSDEM_ERR_OUT_OF_DOMAIN = -3, /* a particle is (or would be) outside the simulation domain */
    FSDEM_ERR_NAN = -4,           /* a computed value is NaN or infinite */
    FSDEM_ERR_CFL = -5,           /* a time step violates its stability limit */
    FSDEM_ERR_NOT_CONVERGED = -6, /* an iterative solver did not converge */
    FSDEM_ERR_IO = -7,            /* a file could not be opened or written */
    FSDEM_ERR_NOT_FOUND = -8      /* an index or id does not name an existing item */
} fsdem_result;

/* Plausibility bounds: a value beyond them describes no flow these solvers can resolve and would
   only come back steps later as an overflow or a NaN, so the call that gives it refuses it with
   FSDEM_ERR_INVALID_ARG and a message naming it (as it refuses a NaN). */
#define FSDEM_MAX_SPEED ((fsdem_real)1e4)        /* m/s: every velocity given (particles, fills, walls,
                                                    boundaries); ten times a rifle bullet's */
#define FSDEM_MAX_ACCELERATION ((fsdem_real)1e4) /* m/s^2: |gravity| (about 1000 g; geotechnical
                                                    centrifuges reach a few hundred g) */
#define FSDEM_MAX_LENGTH ((fsdem_real)1e7)       /* m: depths, water levels, radii and lengths (the
                                                    size of the Earth) */
#define FSDEM_MAX_MODULUS ((fsdem_real)1e16)     /* Pa: Young's moduli (diamond: 1.2e12 Pa; room for a
                                                    wall idealised as a thousand times stiffer) */

/* Short constant name of a result code, e.g. "FSDEM_ERR_INVALID_ARG". Never NULL. */
FSDEM_API const char *fsdem_result_string(fsdem_result result);

typedef enum fsdem_log_level {
    FSDEM_LOG_LEVEL_ERROR = 0,
    FSDEM_LOG_LEVEL_WARNING = 1,
    FSDEM_LOG_LEVEL_INFO = 2
} fsdem_log_level;

/* Optional log sink. `message` is valid only during the call. */
typedef void (*fsdem_log_fn)(void *user, fsdem_log_level level, const char *message);

/* Memory hooks of one object. Either both function pointers are set or both are NULL (then the
   FSDEM_MALLOC/FSDEM_FREE macros are used). `size` in free is the size that was allocated. */
typedef struct fsdem_allocator {
    void *(*alloc)(void *user, size_t size);
    void (*free)(void *user, void *ptr, size_t size);
    void *user;
} fsdem_allocator;

/* Vector helpers (inline in every translation unit). */
static inline fsdem_vec3 fsdem_v3(fsdem_real x, fsdem_real y, fsdem_real z) {
    fsdem_vec3 v;
    v.x = x;
    v.y = y;
    v.z = z;
    return v;
}

/* Signed distance (m) from p to a solid, positive on the open (particle or liquid) side; writes the
   unit normal pointing to the open side (the distance gradient) to *normal. Used by DEM walls, PIC
   obstacles and fill regions. */
typedef fsdem_real (*fsdem_sdf_fn)(void *user, fsdem_vec3 p, fsdem_vec3 *normal);

/* What a fluid solver reports at a point for a coupler (fsdem_<fluid>_sample). */
typedef struct fsdem_fluid_sample {
    fsdem_vec3 velocity;          /* m/s, fluid velocity (0 where there is no liquid) */
    fsdem_vec3 pressure_gradient; /* Pa/m, gradient of the (total) pressure */
    fsdem_real volume_fraction;   /* -, liquid fraction: 1 inside the liquid, 0 in air or dry land */
} fsdem_fluid_sample;

/* ===== >>geom : signed distances and closest points ================================================ */

/* Private helpers of the implementation (>>impl_geom), one copy for every user: closest points on
   segments and triangles, signed distances of boxes, spheres, discs, capped cylinders and polygons,
   distance gradients by central differences. DEM walls, PIC obstacles and the couplers call them. */

/* ===== >>kernel : interpolation weights ============================================================ */

/* Private helpers of the implementation (>>impl_kernel): per-axis weights of the tent (linear) and
   quadratic B-spline kernels on a uniform grid with a staggering offset, their derivatives, and
   the clamped node indices; PIC transfers, fluid fractions, sampling and couplers use them. */

/* ===== >>grid : cell grid shared by DEM, MPS and the couplings ==================================== */

/* A uniform grid of cubic cells over a box; items (particle indices) are binned by a counting sort,
   so a build is O(n) and a query visits the 3^dim cells around a point. Positions outside the box
   are clamped into its border cells, so every item is found. The cell size is enlarged when the box
   would need more than `max_cells` cells, which keeps memory bounded for any domain. Along a
   periodic axis the cells tile the period exactly (a little wider than cell_size) and the
   neighbourhoods wrap round, so neighbours across the seam are found; with fewer than 3 cells along
   it the axis is one cell. The struct is public so solvers can embed it; treat its fields as
   read-only. */
typedef struct fsdem_cellgrid {
    int dim;                  /* 2 or 3 */
    fsdem_vec3 origin;        /* m, lower corner */
    fsdem_real cell_size;     /* m, edge of one cell (>= the requested size) */
    fsdem_real inv_cell_size; /* 1/m */
    fsdem_real inv_width[3];  /* 1/m, per axis: 1/cell_size, or cells per period along a periodic axis */
    int wrap[3];              /* 1: the neighbourhoods wrap round this (periodic) axis */
    int n[3];                 /* cells per axis (n[2] = 1 in 2D) */
    int cell_count;           /* n[0]*n[1]*n[2] */
    int *cell_start;          /* cell_count + 1 offsets into `items` */
    int *items;               /* item indices sorted by cell */
    int *cell_of;             /* cell of each item, as binned by the last build */
    int item_capacity, cell_capacity;
    fsdem_allocator allocator;
} fsdem_cellgrid;

/* Set up the grid geometry for the box [lo, hi] and a wanted cell size (m). `max_cells` caps the
   number of cells (0: 1<<24). Reuses memory already held. Returns FSDEM_ERR_INVALID_ARG for an empty
   box or a non-positive size, FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_cellgrid_setup(fsdem_cellgrid *grid, const fsdem_allocator *allocator,
                                            int dim, fsdem_vec3 lo, fsdem_vec3 hi,
                                            fsdem_real cell_size, int max_cells);
/* fsdem_cellgrid_setup with the axes a where periodic[a] != 0 periodic, of period hi - lo
   (periodic may be NULL: none). */
FSDEM_API fsdem_result fsdem_cellgrid_setup_periodic(fsdem_cellgrid *grid, const fsdem_allocator *allocator, int dim,
                                                     fsdem_vec3 lo, fsdem_vec3 hi, fsdem_real cell_size, int max_cells,
                                                     const int periodic[3]);
/* Bin `count` (>= 0) points. FSDEM_ERR_INVALID_ARG before a successful setup, for a negative count or
   NULL points; FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_cellgrid_build(fsdem_cellgrid *grid, const fsdem_vec3 *points,
                                            int count);
/* Cell holding a point (clamped into the grid) and its integer coordinates. */
FSDEM_API int fsdem_cellgrid_cell(const fsdem_cellgrid *grid, fsdem_vec3 p, int coord[3]);
/* Writes the cells of the 3^dim block around cell coordinates `coord` (those inside the grid) to
   `cells` (room for 27) and returns their number. */
FSDEM_API int fsdem_cellgrid_neighbourhood(const fsdem_cellgrid *grid, const int coord[3],
                                           int cells[27]);
/* The cell at `coord` and the neighbours after it in the 3^dim block (those inside the grid), into
   `cells` (room for 14), returning their number: visiting every cell against these finds each pair
   of neighbouring cells once. The cell itself comes first. */
FSDEM_API int fsdem_cellgrid_forward(const fsdem_cellgrid *grid, const int coord[3], int cells[14]);
/* Releases the memory; the struct may be set up again. */
FSDEM_API void fsdem_cellgrid_free(fsdem_cellgrid *grid);

/* ===== >>dem : discrete element method ============================================================= */

typedef struct fsdem_dem fsdem_dem;

/* Contact law of a simulation. All laws use Coulomb friction with the material's `friction`. */
typedef enum fsdem_dem_law {
    /* Linear spring-dashpot of seed 000 Eq. 7-18: k from theta and dx (Eq. 10), damping from alpha
       (Eq. 11), tangential spring over one step capped by Coulomb (Eq. 8, 12-15), moment Eq. 9. */
    FSDEM_DEM_LAW_LINEAR = 0,
    /* Hertz normal force (4/3) E* sqrt(R*) d^1.5, Mindlin tangential spring on the accumulated
       tangential displacement, Tsuji-form damping calibrated so the normal restitution equals the
       material's `restitution` exactly (see >>dem_law in the implementation). */
    FSDEM_DEM_LAW_HERTZ_MINDLIN = 1,
    /* Granule-In-Cell law of seed 004 Eq. 1a-1c: k_n = E r, viscous tangential force capped by
       |F_n| tan(phi) with tan(phi) = friction. */
    FSDEM_DEM_LAW_GIC = 2
} fsdem_dem_law;

/* Contact options (LIGGGHTS users set them in their pair_style). Hand calculations of a two-sphere
   contact for each: tests/test_dem.c, "contact options". */

/* How a tangential spring carries its history from step to step (Hertz-Mindlin, and the linear law
   with seed 002's stiffness; seed 000's linear law has a one-step spring, Eq. 8, and no history). */
typedef enum fsdem_dem_tangential_history {
    /* the spring of the last step turned into the current tangent plane with its length kept, plus
       the increment v_t dt: a contact that rolls round its partner carries its spring with it
       (Luding 2008, Granular Matter 10:235, the projection of the tangential spring; LIGGGHTS
       `tangential history`); the default */
    FSDEM_DEM_TANGENTIAL_HISTORY_INCREMENTAL = 0,
    /* the total relative tangential displacement since first touch: the increments v_t dt summed in
       the fixed frame, never turned, and projected on the current tangent plane where the force is
       taken (the shear displacement of Cundall and Strack 1979); the same as INCREMENTAL while the
       contact normal keeps its direction */
    FSDEM_DEM_TANGENTIAL_HISTORY_TOTAL = 1
} fsdem_dem_tangential_history;

/* What Coulomb's limit mu |F_n| caps, while the contact slides the spring is reset to the capped
   force. LIGGGHTS' own `limitForce` keyword is another matter: it keeps the normal force from
   turning attractive, which Hertz-Mindlin here always does and the linear laws, as their seeds
   print them (seed 000 Eq. 7, seed 002 Eq. 19), do not. */
typedef enum fsdem_dem_coulomb_limit {
    /* spring plus dashpot: |F_t| <= mu |F_n| (seed 000 Eq. 15, seed 002 Eq. 20); the default */
    FSDEM_DEM_COULOMB_LIMIT_TOTAL = 0,
    /* the spring alone, the dashpot added after: |k_t xi| <= mu |F_n| ("Ft and Fn are the tangential
       spring and normal force components" of LIGGGHTS `tangential history`); a sliding contact's
       force then exceeds mu |F_n| by its dashpot */
    FSDEM_DEM_COULOMB_LIMIT_SPRING = 1
} fsdem_dem_coulomb_limit;

/* Stiffness and damping of FSDEM_DEM_LAW_LINEAR. */
typedef enum fsdem_dem_linear_stiffness {
    /* seed 000 Eq. 10-13: k_n from theta, dx and ||g|| per unit of the mean mass, damping from the
       materials' alpha, a one-step tangential spring (Eq. 8); the default */
    FSDEM_DEM_LINEAR_STIFFNESS_SEED000 = 0,
    /* seed 002 Eq. 19-24 from the materials: chi^n = (sqrt 2 / 3) E sqrt(R) / (1 - nu^2) (Eq. 21),
       written for a pair as (4/3) E* sqrt(R*), to which it reduces for two equal spheres;
       chi^t = chi^n / (2 + nu) (Eq. 22); eta = -2 ln(e) sqrt(chi m* / (ln^2 e + pi^2)) (Eq. 23-24,
       with the reduced mass m*, which makes the normal restitution exactly e); a tangential spring
       with history (desc.tangential_history); no tension cut-off, as printed. Eq. 21 has the units of
       a Hertz coefficient (N m^-3/2), and the seed uses it as a linear stiffness (N/m) in SI units:
       so does this option. The dt rule AUTO is then the Rayleigh time (seed 002 Eq. 38). */
    FSDEM_DEM_LINEAR_STIFFNESS_SEED002 = 1
} fsdem_dem_linear_stiffness;

typedef enum fsdem_dem_integrator {
    /* Velocity Verlet (kick-drift-kick), one force evaluation per step: second order for elastic
       forces; dashpots see the half-step velocity, which makes damping first order in dt (resolve
       a contact with >= 50 steps, or use the predictor-corrector, whose error is far smaller). */
    FSDEM_DEM_INTEGRATOR_VERLET = 0,
    /* Predictor-corrector of seed 000 Eq. 21-24, two force evaluations per step. */
    FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR = 1
} fsdem_dem_integrator;

/* Per-material properties. Fields not used by the chosen law are ignored. */
typedef struct fsdem_dem_material {
    fsdem_real density;          /* kg/m^3; default 2500 */
    fsdem_real young_modulus;    /* Pa; Hertz-Mindlin and GIC; default 1e8 */
    fsdem_real poisson_ratio;    /* -; Hertz-Mindlin, GIC, and psi of seed 000 Eq. 12-13; default 0.3 */
    fsdem_real restitution;      /* -; normal restitution e in (0, 1], Hertz-Mindlin; default 0.5 */
    fsdem_real friction;         /* -; Coulomb sliding coefficient mu (tan phi for GIC); default 0.3 */
    fsdem_real rolling_friction; /* -; constant-torque rolling resistance mu_r; default 0 (off) */
    fsdem_real damping_alpha;    /* -; alpha of seed 000 Eq. 11, linear law; default 0.4 */
    fsdem_real cohesion;         /* J/m^3; cohesion energy density k of the simplified JKR model: */
                                 /*    an attraction k A, A the area of the circle where the two */
                                 /*    spheres (with the contact offset) intersect (3D), or the */
                                 /*    chord times disc_length (2D) (LIGGGHTS `cohesion sjkr`); */
                                 /*    default 0 (off) */
} fsdem_dem_material;

FSDEM_API fsdem_dem_material fsdem_dem_material_default(void);

/* The contact properties of one pair of materials (LIGGGHTS' peratomtypepair tables). Unless set
   with fsdem_dem_set_material_pair, a pair takes the arithmetic mean of its two materials' values
   (their own values for a material with itself). */
typedef struct fsdem_dem_material_pair {
    fsdem_real restitution;      /* -; in [1e-6, 1] */
    fsdem_real friction;         /* -; >= 0 */
    fsdem_real rolling_friction; /* -; >= 0 */
    fsdem_real cohesion;         /* J/m^3; >= 0 */
} fsdem_dem_material_pair;

/* Rule of fsdem_dem_stable_dt (and of the dt warning, fsdem_dem_stats.dt_ratio). */
typedef enum fsdem_dem_dt_rule {
    /* the rule of the contact law: LINEAR_SEED000 for FSDEM_DEM_LAW_LINEAR (RAYLEIGH with seed 002's
       stiffness), RAYLEIGH for FSDEM_DEM_LAW_HERTZ_MINDLIN, GIC for FSDEM_DEM_LAW_GIC */
    FSDEM_DEM_DT_RULE_AUTO = 0,
    /* seed 000 Eq. 18: (2 pi / gamma) sqrt(m_ij / k), k from Eq. 10; dt_param is gamma (default 150) */
    FSDEM_DEM_DT_RULE_LINEAR_SEED000 = 1,
    /* seed 002 Eq. 38, the Rayleigh time pi R sqrt(2 rho (1+nu)/E) / (0.1631 nu + 0.8766) over all
       particles, times dt_param, a safety fraction in (0, 1] (default 0.2, as LIGGGHTS advises) */
    FSDEM_DEM_DT_RULE_RAYLEIGH = 2,
    /* seed 004 Eq. 32: (1/2) sqrt(m / k_n), k_n = E r, times dt_param in (0, 1] (default 1) */
    FSDEM_DEM_DT_RULE_GIC = 3
} fsdem_dem_dt_rule;

typedef struct fsdem_dem_desc {
    int dim;                        /* 2 or 3 */
    fsdem_vec3 domain_min;          /* m; particles must stay inside [domain_min, domain_max] */
    fsdem_vec3 domain_max;          /* m; default (-1,-1,-1)..(1,1,1) */
    fsdem_vec3 gravity;             /* m/s^2; default (0,-9.81,0) in 2D, (0,0,-9.81) in 3D */
    fsdem_dem_law law;          /* default FSDEM_DEM_LAW_HERTZ_MINDLIN */
    fsdem_dem_integrator integrator;    /* default FSDEM_DEM_INTEGRATOR_VERLET */
    fsdem_real dt;                  /* s; time step; default 1e-5 */
    fsdem_dem_dt_rule dt_rule;      /* rule of fsdem_dem_stable_dt; default FSDEM_DEM_DT_RULE_AUTO */
    fsdem_real dt_param;            /* gamma or safety fraction of the rule; 0: its default; default 0 */
    fsdem_real skin;                /* m; neighbour-list margin; < 0: 0.25 x largest radius; default -1 */
    fsdem_real contact_offset;      /* m; imaginary-boundary gap of seed 000 Eq. 19 (2 dx there): */
                                    /*    contacts start at distance r_i + r_j + offset; default 0 */
    fsdem_real linear_theta;        /* -; theta of seed 000 Eq. 10; default 0.01 */
    fsdem_real linear_dx;           /* m; dx of seed 000 Eq. 10; default 0 (must be set for LINEAR) */
    fsdem_real linear_accel;        /* m/s^2; ||g|| of Eq. 10; default 0: use |gravity| */
    fsdem_real disc_length;         /* m; out-of-plane length of 2D discs; default 1 */
    int rotation;                   /* 1: integrate angular velocity; 0: translation only (seed 004) */
    int tangential_damping;         /* 1: tangential dashpot on (Hertz-Mindlin, linear laws); */
                                    /*    default 1 (LIGGGHTS `tangential_damping`) */
    fsdem_dem_tangential_history tangential_history; /* default INCREMENTAL (see the enum) */
    fsdem_dem_coulomb_limit coulomb_limit;   /* default TOTAL (see the enum) */
    fsdem_dem_linear_stiffness linear_stiffness; /* linear law only; default SEED000 */
    int periodic[3];                /* 1: axis a is periodic, of period domain_max - domain_min */
                                    /*    (LIGGGHTS `boundary p`): contacts act across the seam, */
                                    /*    positions wrap; z must be 0 in 2D; default 0, 0, 0 */
    int capacity;                   /* initial particle capacity (grows as needed); default 1024 */
    fsdem_allocator allocator;      /* default: FSDEM_MALLOC/FSDEM_FREE */
    fsdem_log_fn log;               /* optional; default NULL */
    void *log_user;
} fsdem_dem_desc;

/* Defaults for a 2D (discs in x-y) or 3D (spheres) simulation; gravity points down -y or -z. */
FSDEM_API fsdem_dem_desc fsdem_dem_desc_default(int dim);
/* Checks a desc without creating anything; on failure writes the reason to `message` (may be
   NULL). Returns FSDEM_OK or FSDEM_ERR_INVALID_ARG. */
FSDEM_API fsdem_result fsdem_dem_desc_check(const fsdem_dem_desc *desc, char *message,
                                            size_t message_size);
/* Creates a simulation. On FSDEM_ERR_INVALID_ARG the reason goes to desc->log (and is available
   from fsdem_dem_desc_check); *out is NULL on failure. Destroy with fsdem_dem_destroy. */
FSDEM_API fsdem_result fsdem_dem_create(const fsdem_dem_desc *desc, fsdem_dem **out);
FSDEM_API void fsdem_dem_destroy(fsdem_dem *dem);
/* Message of the last failed call on this object ("" after success). Valid until the next call. */
FSDEM_API const char *fsdem_dem_last_error(const fsdem_dem *dem);

/* Adds a material; its index goes to *index (may be NULL). FSDEM_ERR_INVALID_ARG names the field. */
FSDEM_API fsdem_result fsdem_dem_add_material(fsdem_dem *dem, const fsdem_dem_material *material,
                                              int *index);
/* Sets the contact properties of the pair of materials a and b (either order, a == b allowed),
   replacing their mean. FSDEM_ERR_NOT_FOUND for a bad index, FSDEM_ERR_INVALID_ARG names a bad
   field (nothing changes then). */
FSDEM_API fsdem_result fsdem_dem_set_material_pair(fsdem_dem *dem, int a, int b, const fsdem_dem_material_pair *values);
/* The contact properties of the pair a, b in force (zeros for a bad index). */
FSDEM_API fsdem_dem_material_pair fsdem_dem_get_material_pair(const fsdem_dem *dem, int a, int b);

typedef struct fsdem_dem_particle_desc {
    fsdem_vec3 position;         /* m; inside the domain */
    fsdem_vec3 velocity;         /* m/s; default 0 */
    fsdem_vec3 angular_velocity; /* rad/s; default 0 (2D: only z is used) */
    fsdem_real radius;           /* m; > 0; default 0 (must be set) */
    int material;                /* index from fsdem_dem_add_material; default 0 */
    int fixed;                   /* 1: kinematic, moves with its velocity whatever the forces */
} fsdem_dem_particle_desc;

FSDEM_API fsdem_dem_particle_desc fsdem_dem_particle_desc_default(void);
/* Adds a particle at the end; its index goes to *index (may be NULL). Each particle also gets a
   stable id (fsdem_dem_particles.id) that survives removals. Errors: FSDEM_ERR_INVALID_ARG (radius,
   material, non-finite values), FSDEM_ERR_OUT_OF_DOMAIN, FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_dem_add_particle(fsdem_dem *dem, const fsdem_dem_particle_desc *particle,
                                              int *index);
/* Removes particle `index`; later particles move down one index (ids do not change), contact
   history is kept. O(n). FSDEM_ERR_NOT_FOUND for a bad index. */
FSDEM_API fsdem_result fsdem_dem_remove_particle(fsdem_dem *dem, int index);
/* Overwrites a particle's kinematic state (all three vectors). Validated like add_particle. */
FSDEM_API fsdem_result fsdem_dem_set_particle_state(fsdem_dem *dem, int index, fsdem_vec3 position,
                                                    fsdem_vec3 velocity,
                                                    fsdem_vec3 angular_velocity);

/* Read-only views of the particle arrays (structure of arrays), valid until particles are added or
   removed. `force` and `torque` are the contact forces of the last step (N, N m), without gravity
   and without the external loads (fsdem_dem_get_coupling), which are shown too. */
typedef struct fsdem_dem_particles {
    int count;
    int dim;
    const int *id;
    const fsdem_vec3 *position;
    const fsdem_vec3 *velocity;
    const fsdem_vec3 *angular_velocity;
    const fsdem_vec3 *force;
    const fsdem_vec3 *torque;
    const fsdem_vec3 *external_force;
    const fsdem_vec3 *external_torque;
    const fsdem_real *radius;
    const fsdem_real *mass;
    const int *material;
    const unsigned char *fixed;
} fsdem_dem_particles;

FSDEM_API fsdem_dem_particles fsdem_dem_get_particles(const fsdem_dem *dem);

/* External loads of every particle, written by the caller: a force (N) and a torque (N m) at the
   centre, besides contacts and gravity, held fixed over steps (a fluid force during DEM substeps).
   They start at zero; steps read them only once this function has handed them out (or a coupler
   wrote them), so a run without them does not pay for them. Valid until particles are added or
   removed. */
typedef struct fsdem_dem_coupling {
    int count;
    fsdem_vec3 *force;
    fsdem_vec3 *torque;
} fsdem_dem_coupling;

FSDEM_API fsdem_dem_coupling fsdem_dem_get_coupling(fsdem_dem *dem);

/* ---- walls ---- */

typedef enum fsdem_dem_wall_type {
    FSDEM_DEM_WALL_TYPE_PLANE = 0,       /* infinite plane through `a` with unit normal `b` (towards particles) */
    FSDEM_DEM_WALL_TYPE_BOX_INSIDE = 1,  /* axis-aligned box [a, b] holding the particles inside */
    FSDEM_DEM_WALL_TYPE_BOX_OUTSIDE = 2, /* axis-aligned solid box [a, b]; particles stay outside */
    FSDEM_DEM_WALL_TYPE_SEGMENT = 3,     /* 2D segment a-b (both sides) */
    FSDEM_DEM_WALL_TYPE_TRIANGLE = 4,    /* 3D triangle a-b-c (both sides) */
    FSDEM_DEM_WALL_TYPE_SDF = 5          /* signed distance given by a callback (moved by it: fsdem_dem_wall_moved) */
} fsdem_dem_wall_type;


typedef struct fsdem_dem_wall_desc {
    fsdem_dem_wall_type type;
    fsdem_vec3 a, b, c;   /* m; geometry, meaning per type above */
    fsdem_vec3 velocity;  /* m/s; the wall translates with it; default 0 */
    int material;         /* index from fsdem_dem_add_material */
    fsdem_sdf_fn sdf;     /* FSDEM_DEM_WALL_TYPE_SDF only */
    void *sdf_user;
} fsdem_dem_wall_desc;

FSDEM_API fsdem_dem_wall_desc fsdem_dem_wall_plane(fsdem_vec3 point, fsdem_vec3 normal, int material);
FSDEM_API fsdem_dem_wall_desc fsdem_dem_wall_box(fsdem_vec3 lo, fsdem_vec3 hi, int inside, int material);
FSDEM_API fsdem_dem_wall_desc fsdem_dem_wall_segment(fsdem_vec3 a, fsdem_vec3 b, int material);
FSDEM_API fsdem_dem_wall_desc fsdem_dem_wall_triangle(fsdem_vec3 a, fsdem_vec3 b, fsdem_vec3 c, int material);
FSDEM_API fsdem_dem_wall_desc fsdem_dem_wall_sdf(fsdem_sdf_fn sdf, void *user, int material);

/* Adds a wall; its id goes to *id (may be NULL). Ids are stable. FSDEM_ERR_INVALID_ARG names the
   problem (zero normal, degenerate triangle, missing callback, wrong dimension, bad material). */
FSDEM_API fsdem_result fsdem_dem_add_wall(fsdem_dem *dem, const fsdem_dem_wall_desc *wall, int *id);
/* Removes a wall (the id is not reused). */
FSDEM_API fsdem_result fsdem_dem_remove_wall(fsdem_dem *dem, int id);
FSDEM_API fsdem_result fsdem_dem_set_wall_velocity(fsdem_dem *dem, int id, fsdem_vec3 velocity);
/* Tells the neighbour search that wall `id` moved by up to `distance` (m) outside the library, as an
   SDF wall moved by its callback does; without it, particles that were far from the wall at the last
   rebuild would not see it come. FSDEM_ERR_NOT_FOUND, FSDEM_ERR_INVALID_ARG (negative distance). */
FSDEM_API fsdem_result fsdem_dem_wall_moved(fsdem_dem *dem, int id, fsdem_real distance);
/* Force (N) the particles exert on the wall at the last force evaluation. */
FSDEM_API fsdem_vec3 fsdem_dem_wall_force(const fsdem_dem *dem, int id);
/* Impulse (N s) the wall's contacts have given to the particles since it was added, integrated as
   the integrator does: the momentum of the free particles changes by the sum over walls plus the
   impulses of gravity, external forces and contacts with fixed particles. */
FSDEM_API fsdem_vec3 fsdem_dem_wall_impulse(const fsdem_dem *dem, int id);

/* ---- time integration ---- */

/* Advances by one step of the current dt (desc.dt, or the last fsdem_dem_set_dt). Errors:
   FSDEM_ERR_NAN, FSDEM_ERR_OUT_OF_DOMAIN (the step is complete and the message names the particle,
   and dt when it exceeds the stable estimate), FSDEM_ERR_OUT_OF_MEMORY (the neighbour lists could
   not grow: the step stopped part way, after the drift, and is not undone; the object stays
   consistent and a later step rebuilds the lists). */
FSDEM_API fsdem_result fsdem_dem_step(fsdem_dem *dem);
/* One step of dt (s) instead of the current dt (which does not change). FSDEM_ERR_INVALID_ARG for
   dt <= 0 or not finite; otherwise as fsdem_dem_step. */
FSDEM_API fsdem_result fsdem_dem_step_dt(fsdem_dem *dem, fsdem_real dt);
/* Advances by `duration` (s, an outer fluid step) in K = fsdem_dem_substep_count substeps of
   duration/K (seed 000 Eq. 25). External loads stay as they are over the substeps. K goes to *steps
   (may be NULL). Verlet substeps run fused, one pass over the particles each, so this is the fast
   way to take many steps; the state it ends in is that of K calls of fsdem_dem_step_dt, to
   rounding. Errors as fsdem_dem_step, at the substep that met them, and FSDEM_ERR_INVALID_ARG for
   a bad duration or more than FSDEM_DEM_MAX_SUBSTEPS substeps (nothing changes then). */
FSDEM_API fsdem_result fsdem_dem_advance(fsdem_dem *dem, fsdem_real duration, long long *steps);
/* Substeps of fsdem_dem_advance(dem, duration): K = INT(duration/dt) (an exact multiple counts
   whole to a relative 1e-9), or 1 when dt > duration (seed 000 Eq. 25). FSDEM_ERR_INVALID_ARG for a
   duration that is not > 0 and finite, or for K > FSDEM_DEM_MAX_SUBSTEPS. */
FSDEM_API fsdem_result fsdem_dem_substep_count(const fsdem_dem *dem, fsdem_real duration, long long *count);
#define FSDEM_DEM_MAX_SUBSTEPS 100000000LL
/* Called by fsdem_dem_advance_with wherever the advance evaluates forces: once before the first
   substep and after the drift of every substep, with the positions at `time` (s). It writes the
   external loads (fsdem_dem_get_coupling) that the kicks around that time use, such as a buoyancy
   refreshed for the new heights. Velocities are the integrator's at that point (the half-step
   velocity with Verlet). It must not add or remove particles; an error it returns stops the
   advance with that result (its message is the callback's to give through its own object). */
typedef fsdem_result (*fsdem_dem_substep_fn)(void *user, fsdem_dem *dem, double time);
/* fsdem_dem_advance with `fn` (may be NULL) called at every force evaluation. */
FSDEM_API fsdem_result fsdem_dem_advance_with(fsdem_dem *dem, fsdem_real duration, fsdem_dem_substep_fn fn,
                                              void *user, long long *steps);
/* Sets the dt of later fsdem_dem_step and fsdem_dem_advance calls (s, > 0). Logs a warning when it
   exceeds the stable estimate (fsdem_dem_stats.dt_ratio). */
FSDEM_API fsdem_result fsdem_dem_set_dt(fsdem_dem *dem, fsdem_real dt);
/* Simulated time (s). */
FSDEM_API double fsdem_dem_time(const fsdem_dem *dem);
/* Stable time step (s) of the current particles by desc.dt_rule and desc.dt_param (the smallest
   over the particles). FSDEM_ERR_NOT_FOUND when there are no particles. */
FSDEM_API fsdem_result fsdem_dem_stable_dt(const fsdem_dem *dem, fsdem_real *dt);
/* The desc in force: dt is the current dt, dt_rule the resolved rule, dt_param its value. */
FSDEM_API fsdem_dem_desc fsdem_dem_get_desc(const fsdem_dem *dem);

/* ---- diagnostics ---- */

typedef struct fsdem_dem_energy {
    fsdem_real kinetic;    /* J, translational, free particles */
    fsdem_real rotational; /* J */
    fsdem_real potential;  /* J, -m g.x summed over free particles */
    fsdem_real elastic;    /* J, stored in normal and tangential contact springs */
} fsdem_dem_energy;

FSDEM_API fsdem_dem_energy fsdem_dem_get_energy(const fsdem_dem *dem);

typedef struct fsdem_dem_stats {
    long long steps;          /* steps taken */
    double time;              /* s */
    fsdem_real dt;            /* s, the current step */
    fsdem_real stable_dt;     /* s, fsdem_dem_stable_dt at the last neighbour-list build (0: none) */
    fsdem_real dt_ratio;      /* dt / stable_dt; above 1 the log has a warning (0: no particles) */
    long long rebuilds;       /* neighbour-list rebuilds */
    int contacts;             /* particle-particle contacts at the last force evaluation */
    int wall_contacts;        /* particle-wall contacts at the last force evaluation */
    int neighbour_pairs;      /* entries in the particle-particle neighbour list */
    fsdem_real max_overlap;   /* m, largest overlap at the last force evaluation */
    size_t memory_bytes;      /* bytes held by the object */
} fsdem_dem_stats;

FSDEM_API fsdem_dem_stats fsdem_dem_get_stats(const fsdem_dem *dem);

/* One geometric contact (overlap > 0) in the current positions. */
typedef struct fsdem_dem_contact {
    int i;              /* particle index */
    int j;              /* partner particle index (> i), or -1 - wall id for a wall contact */
    fsdem_vec3 normal;  /* unit normal from the partner towards particle i */
    fsdem_real overlap; /* m, including the contact offset */
} fsdem_dem_contact;

/* Lists the contacts of the current positions (found through the neighbour lists, rebuilt first if
   stale). Writes up to `capacity` entries to `out` (may be NULL) and returns the total number, or
   FSDEM_ERR_OUT_OF_MEMORY (negative) when the lists cannot be rebuilt. */
FSDEM_API int fsdem_dem_contacts(fsdem_dem *dem, fsdem_dem_contact *out, int capacity);

/* ===== >>linalg : sparse operators and preconditioned conjugate gradients ===== */

/* One conjugate-gradient solver for every symmetric positive definite system in the library: the
   PIC/FLIP pressure projection and implicit viscosity (MAC-grid stencils) and the MPS pressure
   Poisson equation (general sparse matrices). Operators come in two forms:

   - fsdem_csr: a general sparse matrix in compressed rows, owned by the caller.
   - fsdem_stencil: a matrix-free 5-point (2D) / 7-point (3D) cell-centred operator on a MAC grid,
     with one coefficient per face and a type per cell, built for pressure equations:

         (A p)_c = sum over faces f of c:  w_f (p_c - p_nb(f))  +  diag_c p_c      for fluid cells c

     where p_nb = 0 for an air neighbour (free surface, Dirichlet), a face next to a solid cell adds
     nothing (Neumann), and outside the grid is a Dirichlet p = 0 wherever the boundary face's
     coefficient is > 0 (give it 0 for a wall). A face coefficient is typically an open fraction
     times dt/(rho dx^2): the cut-cell weight E/dx of seed 000 Eq. 5 (E: the unblocked length of the
     cell edge), or the face volume fraction beta of seed 004 Eq. 11 and 63; any w >= 0 works. `diag` carries what the faces do not: the ghost-fluid free surface (a fluid cell
     whose air neighbour lies a fraction theta of the way to the interface adds w (1/theta - 1)),
     or the identity term of an implicit viscosity solve. Keep pressure equations in their
     conservative, symmetric form: seed 004 Eq. 12 divides each row by alpha_f', which would make
     the matrix unsymmetric; solve div(alpha_f' grad p) = alpha_f' (right-hand side of Eq. 12)
     instead. A Neumann face whose flux is moved to the right-hand side (the push-out condition of
     seed 004 App. B, the solid velocity of seed 000 Eq. 5) is a face with coefficient 0.

   A fsdem_pcg object is set up once per operator (this is where all memory is allocated and the
   preconditioner is built) and then solves any number of right-hand sides without allocating.
   Preconditioners: Jacobi, incomplete Cholesky IC(0) and modified IC(0) (both on stencils and on
   CSR), and for stencils a geometric multigrid V-cycle (MGPCG), whose iteration count stays nearly
   constant as the grid is refined. A solve stops when ||b - A x||_2 <= tolerance ||b||_2 (checked on
   the true residual). Not converging, a non-positive curvature p.Ap <= 0 (the operator is not
   positive definite) and NaN are result codes with a message, never a silent wrong answer.

   Stencil vectors (x, b) hold one value per cell, x fastest, then y, then z: cell (i, j, k) is at
   (k n[1] + j) n[0] + i. Face arrays use the MAC layout of the velocity components: face[0] holds
   (n[0]+1) n[1] n[2] x-faces, the face between cells i-1 and i at (k n[1] + j)(n[0]+1) + i; face[1]
   n[0] (n[1]+1) n[2] y-faces at (k (n[1]+1) + j) n[0] + i; face[2] n[0] n[1] (n[2]+1) z-faces at
   (k n[1] + j) n[0] + i. */

typedef enum fsdem_stencil_cell {
    FSDEM_STENCIL_CELL_FLUID = 0, /* an unknown */
    FSDEM_STENCIL_CELL_AIR = 1,   /* Dirichlet p = 0 (free surface); the solution there is 0 */
    FSDEM_STENCIL_CELL_SOLID = 2  /* excluded; faces towards it are Neumann; the solution there is 0 */
} fsdem_stencil_cell;

/* Optional symmetric positive semi-definite term added to a stencil operator, y += E x, on vectors
   in the stencil layout (e.g. the implicit solid coupling dt J^T M^-1 J of seed 000 Eq. 6). It must
   add only to fluid cells. Preconditioners do not see it. */
typedef void (*fsdem_operator_fn)(void *user, const fsdem_real *x, fsdem_real *y);

/* A MAC-grid stencil operator. A view of caller-owned arrays: fsdem_pcg_setup_stencil copies what
   it needs, so the arrays may change or go away after setup (call setup again after a change).
   Zero-initialise it and set dim and n: NULL arrays give the plain -h^2 Laplacian of the unit box
   with Dirichlet walls (every cell fluid, every face 1). */
typedef struct fsdem_stencil {
    int dim;                      /* 2 or 3 */
    int n[3];                     /* cells per axis, >= 1; n[2] is ignored (taken as 1) in 2D */
    const unsigned char *cell;    /* n[0] n[1] n[2] fsdem_stencil_cell values; NULL: all fluid */
    const fsdem_real *face[3];    /* face coefficients >= 0 (layout above); NULL: all 1. Only faces */
                                  /*    with a fluid cell on a side are read. face[2] unused in 2D */
    const fsdem_real *diag;       /* extra diagonal >= 0 per cell (fluid cells read); NULL: 0 */
    fsdem_operator_fn extra;      /* optional extra term (see fsdem_operator_fn); NULL: none */
    void *extra_user;             /* passed to `extra`; must stay valid while the pcg uses it */
} fsdem_stencil;

/* A square sparse matrix in compressed sparse rows, stored in full (both triangles), columns
   strictly ascending in each row, the diagonal present. A view of caller-owned arrays, which must
   stay valid and unchanged from fsdem_pcg_setup_csr until the next setup or destroy. */
typedef struct fsdem_csr {
    int rows;                 /* number of rows = columns, >= 1 */
    const int *row_start;     /* rows + 1 offsets into col/val; row_start[0] = 0 */
    const int *col;           /* column of each entry, 0-based */
    const fsdem_real *val;    /* value of each entry */
} fsdem_csr;

typedef enum fsdem_precond {
    FSDEM_PRECOND_AUTO = 0,   /* multigrid for a stencil, MIC(0) for a CSR matrix */
    FSDEM_PRECOND_NONE = 1,   /* plain conjugate gradients */
    FSDEM_PRECOND_JACOBI = 2, /* diagonal scaling */
    FSDEM_PRECOND_IC0 = 3,    /* incomplete Cholesky, no fill */
    FSDEM_PRECOND_MIC0 = 4,   /* modified incomplete Cholesky (row sums kept, times mic_tau) */
    FSDEM_PRECOND_MG = 5      /* geometric multigrid V-cycle on the MAC grid; stencils only */
} fsdem_precond;

typedef struct fsdem_pcg_desc {
    fsdem_precond preconditioner; /* default FSDEM_PRECOND_AUTO */
    fsdem_real tolerance;         /* -; stop at ||r||_2 <= tolerance ||b||_2; default 1e-8 (1e-5 float) */
    int max_iterations;           /* > 0; default 1000 */
    fsdem_real mic_tau;           /* -; MIC(0) share of the dropped fill moved to the diagonal, */
                                  /*    in [0, 1]; default 0.97 */
    fsdem_real ic_safety;         /* -; IC(0)/MIC(0) pivot floor: a pivot below ic_safety times the */
                                  /*    matrix diagonal is replaced by the diagonal; default 0.25 */
    int mg_sweeps;                /* >= 1; red-black Gauss-Seidel sweeps before and after each */
                                  /*    coarse-grid correction; default 2 */
    fsdem_allocator allocator;    /* default: FSDEM_MALLOC/FSDEM_FREE */
    fsdem_log_fn log;             /* optional; default NULL */
    void *log_user;
} fsdem_pcg_desc;

/* What a solve did. */
typedef struct fsdem_pcg_info {
    int iterations;             /* CG iterations taken */
    fsdem_real residual;        /* -; final ||b - A x||_2 / ||b||_2 (true residual, recomputed) */
    fsdem_real rhs_norm;        /* ||b||_2 after the null-space projection below */
    int nullspace_components;   /* stencil only: fluid regions with no Dirichlet cell, face or diag */
                                /*    (a closed tank full of water). Their p is fixed up to a */
                                /*    constant: b's mean there is removed and x's mean set to 0 */
    fsdem_real incompatibility; /* -; ||removed part of b||_2 / ||b||_2 (0 without such regions) */
    int levels;                 /* multigrid levels (1 for other preconditioners) */
    size_t memory_bytes;        /* bytes held by the pcg object */
} fsdem_pcg_info;

typedef struct fsdem_pcg fsdem_pcg;

/* Defaults (see the field comments). */
FSDEM_API fsdem_pcg_desc fsdem_pcg_desc_default(void);
/* Checks a desc without creating anything; the reason, naming the field, goes to `message` (may be
   NULL). Returns FSDEM_OK or FSDEM_ERR_INVALID_ARG. */
FSDEM_API fsdem_result fsdem_pcg_desc_check(const fsdem_pcg_desc *desc, char *message, size_t message_size);
/* Creates a solver; nothing size-dependent is allocated until a setup call. *out is NULL on
   failure. Errors: FSDEM_ERR_INVALID_ARG (the reason goes to desc->log), FSDEM_ERR_OUT_OF_MEMORY.
   Destroy with fsdem_pcg_destroy. */
FSDEM_API fsdem_result fsdem_pcg_create(const fsdem_pcg_desc *desc, fsdem_pcg **out);
FSDEM_API void fsdem_pcg_destroy(fsdem_pcg *pcg);
/* Message of the last failed call on this object ("" after success). Valid until the next call. */
FSDEM_API const char *fsdem_pcg_last_error(const fsdem_pcg *pcg);
/* Changes the stopping rule of later solves (tolerance > 0, max_iterations > 0). */
FSDEM_API fsdem_result fsdem_pcg_set_tolerance(fsdem_pcg *pcg, fsdem_real tolerance, int max_iterations);

/* Sets up for a stencil operator: validates it, copies its coefficients, (re)allocates the
   workspace when it grew and builds the preconditioner. Call again whenever the stencil changes;
   memory is reused when the grid does not grow. Errors: FSDEM_ERR_INVALID_ARG (dim, a size < 1, a
   bad cell type, a negative or non-finite coefficient; the message names the cell or face; the
   previous setup stays usable), FSDEM_ERR_OUT_OF_MEMORY (the allocator failed, or the grid has
   more than about 2^30 cells; the previous setup stays usable). */
FSDEM_API fsdem_result fsdem_pcg_setup_stencil(fsdem_pcg *pcg, const fsdem_stencil *stencil);
/* Sets up for a CSR matrix (kept by reference, see fsdem_csr): validates it (sizes, indices, sorted
   columns, finite values, a positive diagonal, symmetry to a relative 1e-10 (1e-4 in float)),
   allocates the workspace and builds the preconditioner (FSDEM_PRECOND_MG is refused).
   Errors: FSDEM_ERR_INVALID_ARG (message names the row and entry), FSDEM_ERR_OUT_OF_MEMORY; after
   either the previous setup stays usable. */
FSDEM_API fsdem_result fsdem_pcg_setup_csr(fsdem_pcg *pcg, const fsdem_csr *matrix);

/* Solves A x = b for the operator of the last setup. `x` (length: rows, or cells of the stencil)
   holds the initial guess on entry (zeros are fine) and the solution on return; for a stencil it is
   0 in air and solid cells. `b` has the same length (its air and solid entries are ignored). `info`
   may be NULL. Allocates nothing. Errors: FSDEM_ERR_NOT_CONVERGED (x holds the last iterate and
   info the residual reached), FSDEM_ERR_NAN (b or x holds NaN/Inf, or the iteration produced it;
   x is then unchanged), FSDEM_ERR_INVALID_ARG (no setup, NULL vectors, or the operator or
   preconditioner is not positive definite: p.Ap <= 0 or r.z <= 0; x holds the last iterate). */
FSDEM_API fsdem_result fsdem_pcg_solve(fsdem_pcg *pcg, const fsdem_real *b, fsdem_real *x,
                                       fsdem_pcg_info *info);

/* Checks a stencil without setting anything up; the reason goes to `message` (may be NULL).
   Returns FSDEM_OK or FSDEM_ERR_INVALID_ARG. */
FSDEM_API fsdem_result fsdem_stencil_check(const fsdem_stencil *stencil, char *message,
                                           size_t message_size);
/* y = A x for a stencil (including `extra`), on vectors in the stencil layout; y is 0 in air and
   solid cells. No validation: check the stencil first. x and y must not overlap. */
FSDEM_API void fsdem_stencil_apply(const fsdem_stencil *stencil, const fsdem_real *x, fsdem_real *y);
/* Checks a CSR matrix as fsdem_pcg_setup_csr does; the reason goes to `message` (may be NULL).
   Returns FSDEM_OK or FSDEM_ERR_INVALID_ARG. */
FSDEM_API fsdem_result fsdem_csr_check(const fsdem_csr *matrix, char *message, size_t message_size);
/* y = A x for a CSR matrix. No validation. x and y must not overlap. */
FSDEM_API void fsdem_csr_apply(const fsdem_csr *matrix, const fsdem_real *x, fsdem_real *y);

/* ===== >>pic : PIC/FLIP free-surface solver on a MAC grid ===== */

/* Incompressible Navier-Stokes (seed 000 Eq. 1-2) for one liquid with a free surface, solved by
   marker particles on a staggered (MAC) grid: particle-to-grid transfer, body forces, implicit
   viscosity, pressure projection, grid-to-particle transfer (PIC, FLIP, their blend, or APIC),
   particle advection through the grid velocity, then the density projection of seed 004 §5.1 and
   Appendix B (alpha_s = 0) that keeps the particle distribution, hence the water volume, uniform.

   Grid. Cells of edge `cell_size` cover [domain_min, domain_max]; the extent is rounded to whole
   cells (domain_max moves by less than half a cell). Velocities live on cell faces in the layout of
   >>linalg: face[0] holds (n[0]+1) n[1] n[2] x-faces, face (i,j,k) at (k n[1] + j)(n[0]+1) + i lies
   between cells i-1 and i; likewise y- and z-faces. Cells are FLUID, AIR or SOLID
   (fsdem_stencil_cell values).

   Free surface. The fluid fraction of a cell is the particle count around its centre (tent kernel,
   normalised by what a uniformly filled neighbourhood would give, seed 004 Eq. 7b); a signed
   distance phi (m, < 0 in water) follows from it, exact for a plane surface. Cells with
   phi < -ghost_theta_min dx are FLUID. p = 0 at phi = 0 through the second-order ghost-fluid method.
   Cells mostly inside obstacles take phi from their open neighbours.

   Solids. Static obstacles (boxes, spheres/discs, cylinders, 2D polygons, callbacks) are signed
   distances turned into face-area fractions E in [0, 1] (the cut-cell weights of seed 000 Eq. 5).
   The pressure equation of a cell is sum_f E_f (p_c - p_nb) = -(rho dx^2/dt) div, with the divergence
   sum_f n_f (E_f u_f + (1 - E_f) us_f)/dx, where us_f is the solid velocity on the face. Domain walls
   are faces with E = 0 and a prescribed (kinematic) velocity. A coupler adds moving solids through
   fsdem_pic_coupling_view(): per-face open fractions and solid velocities, a per-face acceleration, and
   an optional extra SPD term of the pressure operator (the implicit solid velocity of seed 000
   Eq. 6), all without touching the projection.

   Step (fsdem_pic_step): P2G -> classify cells -> extrapolate -> save the grid velocity for FLIP ->
   implicit viscosity -> gravity and coupler accelerations -> pressure projection -> extrapolate ->
   G2P -> RK2/RK3 advection -> push particles out of solids, drop those leaving through outflows ->
   density projection -> reseeding. No allocation happens inside a step. */

typedef struct fsdem_pic fsdem_pic;

/* Grid-to-particle velocity update. */
typedef enum fsdem_pic_transfer {
    FSDEM_PIC_TRANSFER_PIC = 0,  /* particles take the grid velocity (dissipative, stable) */
    FSDEM_PIC_TRANSFER_FLIP = 1, /* particles add the grid velocity change; blended with PIC by */
                                 /*    flip_ratio (1 = pure FLIP) */
    FSDEM_PIC_TRANSFER_APIC = 2  /* affine PIC: each particle also carries a velocity gradient */
} fsdem_pic_transfer;

/* Particle-grid interpolation kernel of the P2G/G2P transfers. */
typedef enum fsdem_pic_kernel {
    FSDEM_PIC_KERNEL_LINEAR = 0,   /* 2^dim faces per particle and component */
    FSDEM_PIC_KERNEL_QUADRATIC = 1 /* quadratic B-spline, 3^dim faces, smoother */
} fsdem_pic_kernel;

/* Boundary condition on one side of the domain box (desc.boundary, indexed by fsdem_side). */
typedef enum fsdem_pic_bc {
    FSDEM_PIC_BC_SLIP = 0,    /* impermeable wall, free slip */
    FSDEM_PIC_BC_NO_SLIP = 1, /* impermeable wall; viscous no slip at the wall's tangential */
                              /*    velocity (a moving lid is a tangential boundary_velocity) */
    FSDEM_PIC_BC_INFLOW = 2,  /* prescribed velocity boundary_velocity (all components); the cells */
                              /*    next to it are kept filled with particles of that velocity */
    FSDEM_PIC_BC_OUTFLOW = 3  /* open: p = 0 on the boundary, particles crossing it are removed */
} fsdem_pic_bc;

typedef struct fsdem_pic_desc {
    int dim;                          /* 2 or 3 */
    fsdem_vec3 domain_min;            /* m; default (0,0,0) */
    fsdem_vec3 domain_max;            /* m; default (1,1,1) (z unused in 2D) */
    fsdem_real cell_size;             /* m; edge of a grid cell, > 0; default 1/32 */
    fsdem_real density;               /* kg/m^3; liquid density rho; default 1000 */
    fsdem_real viscosity;             /* m^2/s; kinematic viscosity nu (seed 000 Eq. 2), implicit; */
                                      /*    default 0 (inviscid) */
    fsdem_vec3 gravity;               /* m/s^2; default (0,-9.81,0) in 2D, (0,0,-9.81) in 3D */
    fsdem_pic_bc boundary[6];         /* indexed by fsdem_side; default FSDEM_PIC_BC_SLIP */
    fsdem_vec3 boundary_velocity[6];  /* m/s; lid or inflow velocity per side; default 0 */
    int free_surface;                 /* 1: cells are FLUID where particles are; 0: every open cell */
                                      /*    is FLUID (a completely filled box, e.g. a cavity); default 1 */
    fsdem_pic_transfer transfer;      /* default FSDEM_PIC_TRANSFER_FLIP */
    fsdem_real flip_ratio;            /* -; FLIP share of the blend in [0, 1]; default 0.97 */
    fsdem_pic_kernel kernel;          /* default FSDEM_PIC_KERNEL_LINEAR */
    int particles_per_cell;           /* seeding density; default 4 (2D) / 8 (3D) */
    fsdem_real jitter;                /* -; random displacement of seeds as a fraction of their */
                                      /*    spacing, in [0, 1]; default 0.5 */
    unsigned seed;                    /* random seed of jitter and reseeding; default 1 */
    int min_particles_per_cell;       /* reseeding moves particles from crowded neighbour cells into */
                                      /*    interior fluid cells with fewer (volume-neutral); */
                                      /*    0 = never; default particles_per_cell / 2 */
    int max_particles_per_cell;       /* reseeding removes particles from cells with more; 0 = never; */
                                      /*    default 3 particles_per_cell */
    int advection_order;              /* 2 (midpoint) or 3 (Ralston RK3); default 2 */
    fsdem_real cfl;                   /* -; adaptive dt = cfl dx / (u_max + sqrt(|g| dx)); default 1 */
    fsdem_real cfl_max;               /* -; a fixed dt beyond this CFL number is refused; default 5 */
    fsdem_real dt_max;                /* s; largest step; default 0.01 */
    int density_projection;           /* 1: seed 004 §5.1 density projection after advection; default 1 */
    fsdem_real ghost_theta_min;       /* -; smallest interface fraction of the ghost-fluid method; */
                                      /*    default 0.01 */
    int extrapolation_layers;         /* faces of velocity extrapolation into air and solids; */
                                      /*    0 = auto (cfl_max + 2); default 0 */
    fsdem_precond pressure_precond;   /* default FSDEM_PRECOND_AUTO (multigrid) */
    fsdem_real pressure_tolerance;    /* -; relative residual of the pressure solve; default 1e-8 */
    int pressure_max_iterations;      /* default 500 */
    fsdem_precond viscosity_precond;  /* default FSDEM_PRECOND_MIC0 */
    fsdem_real viscosity_tolerance;   /* -; relative residual of the viscous solves; default 1e-8 */
    size_t max_memory;                /* bytes; creation fails when the grid would need more; */
                                      /*    0 = no limit beyond the allocator; default 0 */
    fsdem_allocator allocator;        /* default: FSDEM_MALLOC/FSDEM_FREE */
    fsdem_log_fn log;                 /* optional; default NULL */
    void *log_user;
} fsdem_pic_desc;

/* Defaults for dim = 2 (x-y plane, gravity -y) or 3 (gravity -z); see the field comments. */
FSDEM_API fsdem_pic_desc fsdem_pic_desc_default(int dim);
/* Checks a desc without creating anything (also the memory the grid needs against max_memory); the
   reason, naming the field, goes to `message` (may be NULL). Returns FSDEM_OK,
   FSDEM_ERR_INVALID_ARG or FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_pic_desc_check(const fsdem_pic_desc *desc, char *message,
                                            size_t message_size);
/* Creates a solver with an empty domain (no particles, no obstacles). All grid memory and the
   linear solvers are set up here. *out is NULL on failure. Errors: FSDEM_ERR_INVALID_ARG (the
   reason goes to desc->log and fsdem_pic_desc_check), FSDEM_ERR_OUT_OF_MEMORY (the grid does not
   fit max_memory, int indices or the allocator). Destroy with fsdem_pic_destroy. */
FSDEM_API fsdem_result fsdem_pic_create(const fsdem_pic_desc *desc, fsdem_pic **out);
FSDEM_API void fsdem_pic_destroy(fsdem_pic *pic);
/* Message of the last failed call on this object ("" after success). Valid until the next call. */
FSDEM_API const char *fsdem_pic_last_error(const fsdem_pic *pic);

/* ---- obstacles ---- */

typedef enum fsdem_pic_obstacle_type {
    FSDEM_PIC_OBSTACLE_TYPE_BOX = 0,      /* axis-aligned solid box [a, b] */
    FSDEM_PIC_OBSTACLE_TYPE_SPHERE = 1,   /* sphere (3D) or disc (2D), centre a, radius `radius` */
    FSDEM_PIC_OBSTACLE_TYPE_CYLINDER = 2, /* 3D: flat-capped cylinder with axis a-b and `radius`; */
                                     /*    2D: a disc like SPHERE */
    FSDEM_PIC_OBSTACLE_TYPE_POLYGON = 3,  /* 2D: closed polygon `vertices` (x, y used), any orientation */
    FSDEM_PIC_OBSTACLE_TYPE_SDF = 4       /* callback: signed distance, positive on the liquid side */
} fsdem_pic_obstacle_type;

typedef struct fsdem_pic_obstacle {
    fsdem_pic_obstacle_type type;
    fsdem_vec3 a, b;              /* m; geometry, meaning per type */
    fsdem_real radius;            /* m; SPHERE, CYLINDER */
    const fsdem_vec3 *vertices;   /* POLYGON: `vertex_count` >= 3 points, copied when added */
    int vertex_count;
    fsdem_sdf_fn sdf;             /* SDF: distance (m) and unit normal towards the liquid */
    void *sdf_user;               /*    (must stay valid while the solver lives) */
    fsdem_vec3 velocity;          /* m/s; kinematic surface velocity (the geometry does not move): */
                                  /*    normal flux through cut faces and no-slip value; default 0 */
} fsdem_pic_obstacle;

FSDEM_API fsdem_pic_obstacle fsdem_pic_obstacle_box(fsdem_vec3 lo, fsdem_vec3 hi);
FSDEM_API fsdem_pic_obstacle fsdem_pic_obstacle_sphere(fsdem_vec3 centre, fsdem_real radius);
FSDEM_API fsdem_pic_obstacle fsdem_pic_obstacle_cylinder(fsdem_vec3 a, fsdem_vec3 b, fsdem_real radius);
FSDEM_API fsdem_pic_obstacle fsdem_pic_obstacle_polygon(const fsdem_vec3 *vertices, int count);
FSDEM_API fsdem_pic_obstacle fsdem_pic_obstacle_sdf(fsdem_sdf_fn sdf, void *user);

/* Adds a static obstacle; its index goes to *id (may be NULL). Recomputes the face fractions of
   the union of all obstacles (each face sampled on a 4 x 4 sub-grid, linear in between: walls
   thinner than about a quarter cell may leak) and removes the particles now inside a solid.
   Allocates (outside any step). Errors: FSDEM_ERR_INVALID_ARG (bad geometry, non-finite values, or the obstacle would
   leave no open cell: "covers the whole domain"; the solver is unchanged), FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_pic_add_obstacle(fsdem_pic *pic, const fsdem_pic_obstacle *obstacle,
                                              int *id);
/* Signed distance (m) from p to the nearest obstacle or closed domain wall, positive in the open
   domain; writes the unit normal towards the open side to *normal (may be NULL). */
FSDEM_API fsdem_real fsdem_pic_solid_distance(const fsdem_pic *pic, fsdem_vec3 p, fsdem_vec3 *normal);

/* ---- particles ---- */

/* Seeds particles_per_cell particles per cell (stratified with jitter) in the part of the box
   [lo, hi] that is inside the domain and outside every obstacle, all with `velocity` (m/s). The number
   added goes to *added (may be NULL). Errors: FSDEM_ERR_INVALID_ARG (non-finite input, empty box),
   FSDEM_ERR_OUT_OF_MEMORY (nothing added). Allocates (outside any step). */
FSDEM_API fsdem_result fsdem_pic_fill_box(fsdem_pic *pic, fsdem_vec3 lo, fsdem_vec3 hi,
                                          fsdem_vec3 velocity, int *added);
/* Like fsdem_pic_fill_box for the region where region(user, p, NULL) > 0. */
FSDEM_API fsdem_result fsdem_pic_fill_sdf(fsdem_pic *pic, fsdem_sdf_fn region, void *user,
                                          fsdem_vec3 velocity, int *added);
/* Adds `count` particles (positions m, velocities m/s; velocities may be NULL for rest). All or
   nothing: FSDEM_ERR_INVALID_ARG names the first non-finite particle, FSDEM_ERR_OUT_OF_DOMAIN the
   first one outside the domain or inside a solid, FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_pic_add_particles(fsdem_pic *pic, const fsdem_vec3 *positions,
                                               const fsdem_vec3 *velocities, int count);
/* Reserves room for `count` particles so later steps can reseed and inject without refusing
   (steps never allocate; by default room for 1.5 x the particles present is kept). */
FSDEM_API fsdem_result fsdem_pic_reserve(fsdem_pic *pic, int count);

/* Views of the marker particles (structure of arrays), valid until particles are added or a step
   runs (steps reorder, remove and add particles). `velocity` may be edited between steps. */
typedef struct fsdem_pic_particles {
    int count;
    int dim;
    fsdem_real volume;          /* m^3 (m^2 in 2D) represented by one particle: dx^dim / ppc */
    const fsdem_vec3 *position; /* m */
    fsdem_vec3 *velocity;       /* m/s */
} fsdem_pic_particles;

FSDEM_API fsdem_pic_particles fsdem_pic_get_particles(fsdem_pic *pic);

/* ---- time stepping ---- */

/* Advances by one step of the adaptive size min(dt_max, cfl dx / (u_max + sqrt(|g| dx))).
   Errors (the step is complete, the message names the culprit): FSDEM_ERR_NAN (a particle
   velocity became non-finite), FSDEM_ERR_NOT_CONVERGED (a linear solve stopped at its iteration
   limit), FSDEM_ERR_CFL (the projected velocity moved particles more than cfl_max cells). */
FSDEM_API fsdem_result fsdem_pic_step(fsdem_pic *pic);
/* One step of a given dt (s). FSDEM_ERR_INVALID_ARG for dt <= 0 or not finite, FSDEM_ERR_CFL when
   u_max dt / dx > cfl_max (the message names the fastest particle); in both cases nothing moved.
   Otherwise as fsdem_pic_step. */
FSDEM_API fsdem_result fsdem_pic_step_dt(fsdem_pic *pic, fsdem_real dt);
/* Advances by `duration` (s) with adaptive steps, the last ones shortened to land on the end time.
   Stops at the first error and returns it. Steps taken go to *steps (may be NULL). */
FSDEM_API fsdem_result fsdem_pic_advance(fsdem_pic *pic, fsdem_real duration, long long *steps);
/* The adaptive step the next fsdem_pic_step would take (s). FSDEM_ERR_NAN when a particle velocity
   is not finite. */
FSDEM_API fsdem_result fsdem_pic_stable_dt(const fsdem_pic *pic, fsdem_real *dt);
/* Simulated time (s). */
FSDEM_API double fsdem_pic_time(const fsdem_pic *pic);
/* The desc in force (domain_max moved to whole cells). */
FSDEM_API fsdem_pic_desc fsdem_pic_get_desc(const fsdem_pic *pic);

/* ---- grid and coupling ---- */

/* Read-only view of the grid after the last step (valid while the solver lives). `cell`, `phi` and
   `fraction` describe the particles at the end of the step (after advection and reseeding); the
   face velocities and the pressure are those of the step's projection, made with the cells of its
   start, so a cell the front entered during the step can show a nonzero divergence. */
typedef struct fsdem_pic_fields {
    int dim;
    int n[3];                      /* cells per axis (n[2] = 1 in 2D) */
    int face_count[3];             /* faces per axis (0 for z in 2D) */
    fsdem_real cell_size;          /* m */
    fsdem_vec3 origin;             /* m, lower corner */
    const unsigned char *cell;     /* fsdem_stencil_cell per cell */
    const fsdem_real *pressure;    /* Pa per cell (0 outside the fluid) */
    const fsdem_real *phi;         /* m; signed distance to the surface, < 0 in water, |phi| <= dx */
    const fsdem_real *fraction;    /* -; particle fluid fraction per cell (1 = uniformly filled) */
    const fsdem_real *velocity[3]; /* m/s; face velocity after projection and extrapolation */
    const fsdem_real *open[3];     /* -; effective face-area fraction E used by the projection */
    const fsdem_real *solid_velocity[3]; /* m/s; velocity of the solid part of each face (walls, */
                                   /*    inflow, obstacles, coupler): face flux E u + (1 - E) us */
} fsdem_pic_fields;

FSDEM_API fsdem_pic_fields fsdem_pic_get_fields(const fsdem_pic *pic);

/* Writable per-face arrays for a coupler (layout of fsdem_pic_fields), read by every step; valid
   while the solver lives:
   - open[a][f]: fraction of face f not covered by moving solids (default 1); the projection uses
     min(static obstacle fraction, open);
   - solid_velocity[a][f]: velocity component a (m/s) of the moving solid on that face (default 0),
     used where open < the static fraction;
   - acceleration[a][f]: extra acceleration (m/s^2) added with gravity (default 0; kept until
     changed; fsdem_pic_add_force adds to it, fsdem_pic_clear_forces zeroes it);
   - pressure_rhs[c]: added to the right-hand side of the pressure equation
     sum_f E_f (p_c - p_nb) = -(rho dx^2/dt) div (Pa; default 0, kept until changed);
   - reference[c]: the part of cell c's fluid-fraction kernel that moving solids leave open (default
     1): the particle count of a full cell is divided by it, as by the static obstacles' own part, so
     that water around a moving body reads full and keeps its pressure;
   - viscous_velocity[a][f] (NULL without viscosity): the moving solid's velocity on face f at the
     start of the step, the no-slip value of the implicit viscous solve, which comes before gravity
     and the accelerations (solid_velocity, the velocity at the end of the step, includes them; a
     body at rest in water at rest would otherwise be sheared by its own g dt); default 0;
   - shear[a][f] (read only; NULL without viscosity): the viscous force component a (N; N/m in 2D)
     that the liquid exerted on the closed face f (E = 0) during the last step's implicit viscous
     solve, rho nu dx^(dim-2) sum (u_nb - us_f) over the liquid faces next to it; the liquid got
     exactly the opposite, so a coupler that hands it to the solid conserves momentum.
   A cell whose faces are all closed becomes SOLID. Particles are pushed out of static obstacles
   in every step; moving solids are the coupler's (fsdem_pic_exclude_particles). The arrays are read
   by the next step, which recounts the fluid fractions after this call. */
typedef struct fsdem_pic_coupling {
    int dim;
    int n[3];
    int face_count[3];
    fsdem_real *open[3];
    fsdem_real *solid_velocity[3];
    fsdem_real *acceleration[3];
    fsdem_real *pressure_rhs;
    fsdem_real *reference;
    const fsdem_real *shear[3];
    fsdem_real *viscous_velocity[3];
} fsdem_pic_coupling;

FSDEM_API fsdem_pic_coupling fsdem_pic_get_coupling(fsdem_pic *pic);
/* An optional symmetric positive semi-definite term y += K p added to the pressure operator of the
   equation above (p and y in Pa, vectors in the cell layout; e.g. the implicit solid response
   dt J^T M^-1 J of seed 000 Eq. 6 in these units). It must write only to FLUID cells; the
   preconditioner does not see it. fn = NULL removes it; `user` must stay valid while it is set. */
FSDEM_API fsdem_result fsdem_pic_set_pressure_extra(fsdem_pic *pic, fsdem_operator_fn fn, void *user);

/* Samples the grid at `count` points (clamped into the domain): velocity (trilinear from the faces),
   the gradient of the pressure (Pa/m, from the face differences) and the liquid fraction
   clamp(1/2 - phi/dx, 0, 1) (trilinear from the cells). FSDEM_ERR_INVALID_ARG for NULL arrays. */
FSDEM_API fsdem_result fsdem_pic_sample(const fsdem_pic *pic, int count, const fsdem_vec3 *points,
                                       fsdem_fluid_sample *out);
/* Adds a force exerted on the liquid at `point` (N; N/m in 2D, per unit depth) to the faces'
   acceleration, spread by the tent kernel of half-width max(radius, dx) over the faces next to
   FLUID cells of the last step and divided by rho dx^dim, so the grid momentum before the
   projection gains exactly force x dt per step. *taken (may be NULL) is 0 when no face next to the
   liquid lies within reach (the force is then dropped). FSDEM_ERR_INVALID_ARG for non-finite input. */
FSDEM_API fsdem_result fsdem_pic_add_force(fsdem_pic *pic, fsdem_vec3 point, fsdem_real radius, fsdem_vec3 force,
                                          int *taken);
/* Zeroes the coupling accelerations. */
FSDEM_API fsdem_result fsdem_pic_clear_forces(fsdem_pic *pic);
/* Keeps particles out of a solid region given by `solid` (distance in m, positive in the liquid,
   with the unit normal towards the liquid; `user` is passed on), such as moving bodies after they
   moved. Particles at a distance below 1e-3 dx are moved along the normal to 1e-3 dx (`remove` = 0:
   the liquid the region swept is kept and the density projection of later steps spreads it) or
   removed (`remove` = 1: the liquid the region now holds, e.g. where a body is first placed). The
   number moved or removed goes to *count (may be NULL). FSDEM_ERR_INVALID_ARG for NULL pic or
   solid, FSDEM_ERR_NAN (the particle is named; nothing moved) when the distance is not finite. */
FSDEM_API fsdem_result fsdem_pic_exclude_particles(fsdem_pic *pic, fsdem_sdf_fn solid, void *user, int remove,
                                                   int *count);

/* ---- gauges ---- */

typedef enum fsdem_pic_gauge_kind {
    /* water level: the elevation (m, the coordinate along -gravity) of the highest free surface
       above the point's column of cells (the cell column holding x in 2D, x-y in 3D), where phi
       crosses 0 between two cell centres; the bottom of the domain when the column is dry */
    FSDEM_PIC_GAUGE_KIND_LEVEL = 0,
    /* pressure (Pa): at the point (trilinear between cell centres) for radius 0, else the mean over
       the non-solid cells whose centres lie within `radius` of it (a sensor patch on a wall) */
    FSDEM_PIC_GAUGE_KIND_PRESSURE = 1
} fsdem_pic_gauge_kind;

/* Adds a gauge (before fsdem_pic_gauges_open); its id goes to *id (may be NULL). The level gauge
   needs gravity along one axis. FSDEM_ERR_OUT_OF_DOMAIN, FSDEM_ERR_INVALID_ARG (bad kind, radius
   < 0, non-finite input, gravity not along an axis for a level gauge, a file is open),
   FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_pic_add_gauge(fsdem_pic *pic, fsdem_pic_gauge_kind kind, fsdem_vec3 position,
                                          fsdem_real radius, int *id);
/* Gauge `id` now (m or Pa). FSDEM_ERR_NOT_FOUND. */
FSDEM_API fsdem_result fsdem_pic_gauge(const fsdem_pic *pic, int id, fsdem_real *value);
/* Opens a gauge time series: a CSV with columns t, then level_<id> or p_<id> per gauge, written as
   fsdem_swe_gauges_open does (rows at multiples of `interval`, interpolated within a step; 0: every
   step). FSDEM_ERR_IO, FSDEM_ERR_INVALID_ARG (no gauges, interval < 0). */
FSDEM_API fsdem_result fsdem_pic_gauges_open(fsdem_pic *pic, const char *path, fsdem_real interval);
/* Closes the gauge file (also done by fsdem_pic_destroy). FSDEM_ERR_IO. */
FSDEM_API fsdem_result fsdem_pic_gauges_close(fsdem_pic *pic);

/* ---- diagnostics ---- */

typedef struct fsdem_pic_stats {
    long long steps;
    double time;                   /* s */
    fsdem_real dt;                 /* s, last step */
    int particles;
    int fluid_cells;
    fsdem_real fluid_volume;       /* m^3 (m^2 in 2D): liquid volume the solver sees, the sum over */
                                   /*    open cells of clamp(1/2 - phi/dx, 0, 1) dx^dim (all open */
                                   /*    cells when free_surface = 0); cut cells count whole */
    fsdem_real particle_volume;    /* m^3 (m^2 in 2D): particles x particle volume, the volume the */
                                   /*    particles carry (exact at seeding; fluid_volume, from the */
                                   /*    grid's level set, reads up to a few % lower on coarse grids) */
    fsdem_real kinetic_energy;     /* J (J/m in 2D): sum of rho V_p |v_p|^2 / 2 */
    fsdem_real max_speed;          /* m/s, particles */
    fsdem_real max_divergence;     /* 1/s; largest |div u| over fluid cells after the projection */
    fsdem_real divergence_before;  /* 1/s; l2 norm over fluid cells of div u before the projection */
    int pressure_iterations;       /* last step */
    fsdem_real pressure_residual;  /* -; relative, last step */
    int viscosity_iterations;      /* last step, summed over components */
    int density_iterations;        /* last step */
    long long reseeded;            /* particles added by the inflow sides, total */
    long long moved;               /* particles moved by reseeding from crowded to sparse cells, total */
    long long removed;             /* particles removed (over-full cells, outflow, solids), total */
    long long refused;             /* inflow seeds refused because the particle capacity was full */
    double seconds_total;          /* CPU seconds spent in steps (clock()) */
    double seconds_pressure;       /* CPU seconds in pressure setup + solve */
    double seconds_density;        /* CPU seconds in the density projection's setup + solve */
    size_t memory_bytes;           /* bytes held by the solver, linear solvers included */
} fsdem_pic_stats;

FSDEM_API fsdem_pic_stats fsdem_pic_get_stats(const fsdem_pic *pic);

/* ---- output ---- */

/* Particles as CSV (x,y,z,vx,vy,vz). FSDEM_ERR_IO, FSDEM_ERR_INVALID_ARG (NULL). VTK XML output
   (fsdem_pic_write_particles_vtp, fsdem_pic_write_grid_vti) is in >>io. */
FSDEM_API fsdem_result fsdem_pic_write_particles_csv(const fsdem_pic *pic, const char *path);
/* Grid cells as CSV (i,j,k,x,y,z,type,p,phi,fraction,u,v,w with cell-centred velocity).
   FSDEM_ERR_IO, FSDEM_ERR_INVALID_ARG (NULL). */
FSDEM_API fsdem_result fsdem_pic_write_grid_csv(const fsdem_pic *pic, const char *path);


/* ===== >>swe : shallow-water equations (seed 003) ================================================= */

/* Depth-averaged shallow-water flow on a uniform Cartesian grid, 1D (x) or 2D (x-y), solved in the
   pre-balanced form of seed 003 Eq. 1-2 (Liang and Borthwick 2009; Liang and Marche 2009):
       q = [eta, uh, vh],  f = [uh, u^2 h + g (eta^2 - 2 eta z_b)/2, uvh],
       s = [0, -tau_bx/rho - g eta dz_b/dx + S_vx + S_px, ... y likewise]
   eta is the surface elevation, z_b the bed, h = eta - z_b the depth. Godunov-type finite volumes with
   the HLL Riemann solver; second order in space and time by MUSCL-Hancock with a slope limiter, or
   first order. Wet/dry fronts use the non-negative depth (hydrostatic) reconstruction with Liang's
   local bed modification, so still water stays still over any bed, wet or dry, to the last bit, and
   depths never go negative. Bed friction (Manning) is implicit; an eddy viscosity, rain, point
   sources and a per-cell momentum source (S_px, for couplers) are optional.

   Grid and storage: nx x ny cells (ny = 1 in 1D), cell (i, j) has centre
   (x_min + (i + 1/2) dx, y_min + (j + 1/2) dy) and index k = i + nx j in every array of this section.
   In 1D the channel has a `width` (default 1 m) so volumes and momenta have their 3D units.
   Units: m, s, m^2/s for unit discharges uh and vh, kg/m^3 for the water density.
   One thread: the sweep is sequential (no OpenMP in this section); distinct solvers may run in
   distinct threads. */

typedef struct fsdem_swe fsdem_swe;

/* Slope limiter of the second-order reconstruction (all are TVD, so reconstructed depths stay within
   the neighbours' range and never go negative). */
typedef enum fsdem_swe_limiter {
    FSDEM_SWE_LIMITER_MINMOD = 0,   /* most dissipative, the default */
    FSDEM_SWE_LIMITER_VAN_LEER = 1, /* harmonic mean */
    FSDEM_SWE_LIMITER_MC = 2,       /* monotonised central */
    FSDEM_SWE_LIMITER_SUPERBEE = 3  /* least dissipative, steepens fronts */
} fsdem_swe_limiter;

/* fsdem_swe_desc.boundary is indexed by fsdem_side; 1D uses XMIN and XMAX only. */
typedef enum fsdem_swe_bc {
    FSDEM_SWE_BC_WALL = 0,         /* reflective, free slip: no mass flux, mirrored normal velocity */
    FSDEM_SWE_BC_TRANSMISSIVE = 1, /* zero gradient: waves leave (approximately) without reflection */
    FSDEM_SWE_BC_DISCHARGE = 2,    /* inflow of a unit discharge `value` (m^2/s, >= 0, into the domain)
                                      imposed exactly as the boundary mass flux; the boundary depth comes
                                      from the outgoing Riemann invariant (subcritical inflow) */
    FSDEM_SWE_BC_STAGE = 3         /* fixed surface elevation `value` (m) outside; the normal velocity
                                      comes from the outgoing Riemann invariant */
} fsdem_swe_bc;

/* One side's boundary condition. With a series, `value` follows it in time (linear interpolation,
   held constant before the first and after the last point): a hydrograph for DISCHARGE, a stage
   record for STAGE. The series is copied when the boundary is set. */
typedef struct fsdem_swe_boundary {
    fsdem_swe_bc type;               /* default FSDEM_SWE_BC_WALL */
    fsdem_real value;                /* m^2/s (DISCHARGE) or m (STAGE); default 0 */
    const fsdem_real *series_time;   /* s, strictly increasing; NULL: constant `value`; default NULL */
    const fsdem_real *series_value;  /* m^2/s or m, one per time; default NULL */
    int series_count;                /* points in the series; default 0 */
} fsdem_swe_boundary;

typedef struct fsdem_swe_desc {
    int dim;                         /* 1 or 2 */
    int nx, ny;                      /* cells along x and y (ny must be 1 in 1D); default 100 (1D: 100 x 1) */
    fsdem_real x_min, x_max;         /* m; extent along x; default 0 .. 1 */
    fsdem_real y_min, y_max;         /* m; extent along y, 2D only; default 0 .. 1 */
    fsdem_real width;                /* m; 1D only: channel width for volumes, momenta, forces; default 1 */
    fsdem_vec3 gravity;              /* m/s^2; vertical, (0, 0, -g) with g > 0; default (0, 0, -9.81) */
    fsdem_real density;              /* kg/m^3; water density for momentum and force; default 1000 */
    fsdem_real cfl;                  /* -; Courant number of adaptive steps, in (0, 1]; default 0.5 */
    fsdem_real dt_max;               /* s; longest adaptive step (used when nothing moves); default 1 */
    int order;                       /* 1 (first order) or 2 (MUSCL-Hancock); default 2 */
    fsdem_swe_limiter limiter;       /* order 2 only; default FSDEM_SWE_LIMITER_MINMOD */
    fsdem_real dry_depth;            /* m; cells shallower than this have zero velocity; default 1e-6 */
    fsdem_real manning;              /* s/m^(1/3); uniform Manning n, 0 = frictionless; default 0 */
    fsdem_real eddy_viscosity;       /* m^2/s; turbulent viscosity of S_v = div(nu h grad u); default 0 */
    fsdem_real rain_rate;            /* m/s; uniform rain on every cell; default 0 */
    fsdem_swe_boundary boundary[4];  /* indexed by fsdem_side; default all walls */
    const fsdem_real *bed;           /* m; nx*ny bed elevations z_b, copied; NULL: flat at 0; default NULL */
    const fsdem_real *depth;         /* m; nx*ny initial depths >= 0, copied; NULL: dry; default NULL */
    fsdem_allocator allocator;       /* default: FSDEM_MALLOC/FSDEM_FREE */
    fsdem_log_fn log;                /* optional; default NULL */
    void *log_user;
} fsdem_swe_desc;

/* Defaults for a 1D or 2D grid (see the field comments). */
FSDEM_API fsdem_swe_desc fsdem_swe_desc_default(int dim);
/* Checks a desc, including every value of `bed` and `depth`, without creating anything; on failure
   writes the reason, naming the field or cell, to `message` (may be NULL). Returns FSDEM_OK or
   FSDEM_ERR_INVALID_ARG (zero or negative cell counts, an empty extent, cfl outside (0, 1], a NaN
   bed, a negative or NaN depth, a bad boundary or series, ...). */
FSDEM_API fsdem_result fsdem_swe_desc_check(const fsdem_swe_desc *desc, char *message, size_t message_size);
/* Creates a solver (time 0). All memory is allocated here; steps allocate nothing. On
   FSDEM_ERR_INVALID_ARG the reason goes to desc->log (and is available from fsdem_swe_desc_check);
   also FSDEM_ERR_OUT_OF_MEMORY. *out is NULL on failure. Destroy with fsdem_swe_destroy. */
FSDEM_API fsdem_result fsdem_swe_create(const fsdem_swe_desc *desc, fsdem_swe **out);
FSDEM_API void fsdem_swe_destroy(fsdem_swe *swe);
/* Message of the last failed call on this object ("" after success). Valid until the next call. */
FSDEM_API const char *fsdem_swe_last_error(const fsdem_swe *swe);

/* ---- state ---- */

/* Geometry of the grid. */
typedef struct fsdem_swe_grid {
    int dim, nx, ny;
    fsdem_real dx, dy;        /* m; dy = width in 1D */
    fsdem_real x_min, y_min;  /* m; lower corner (y_min = 0 in 1D) */
    fsdem_real cell_area;     /* m^2; dx dy */
} fsdem_swe_grid;

FSDEM_API fsdem_swe_grid fsdem_swe_get_grid(const fsdem_swe *swe);

/* Replaces the bed (nx*ny values, m), keeping each cell's depth. FSDEM_ERR_INVALID_ARG names the
   first non-finite value; the state is then unchanged. */
FSDEM_API fsdem_result fsdem_swe_set_bed(fsdem_swe *swe, const fsdem_real *bed);
/* Sets the depths (m, >= 0), keeping the unit discharges. FSDEM_ERR_INVALID_ARG names the first
   negative or non-finite value; the state is then unchanged. */
FSDEM_API fsdem_result fsdem_swe_set_depth(fsdem_swe *swe, const fsdem_real *depth);
/* Sets the surface elevation (m); cells whose bed is above it become dry (h = 0). */
FSDEM_API fsdem_result fsdem_swe_set_surface(fsdem_swe *swe, const fsdem_real *eta);
/* Sets the velocities (m/s; v may be NULL, ignored in 1D): uh = u h, vh = v h. */
FSDEM_API fsdem_result fsdem_swe_set_velocity(fsdem_swe *swe, const fsdem_real *u, const fsdem_real *v);

/* State of one cell (or of a point, interpolated), as set by or returned to the caller. */
typedef struct fsdem_swe_cell {
    fsdem_real bed;    /* m, z_b */
    fsdem_real depth;  /* m, h >= 0 */
    fsdem_real eta;    /* m, surface elevation z_b + h (output only) */
    fsdem_real u, v;   /* m/s */
} fsdem_swe_cell;

/* Initial condition from a function of the cell centre (y = 0 in 1D): `fn` fills bed, depth, u, v.
   Validated like the array setters; nothing changes on failure. */
typedef void (*fsdem_swe_init_fn)(void *user, fsdem_real x, fsdem_real y, fsdem_swe_cell *cell);
FSDEM_API fsdem_result fsdem_swe_set_cells(fsdem_swe *swe, fsdem_swe_init_fn fn, void *user);

/* Read-only views of the state arrays (nx*ny each, index i + nx j), valid until the solver is
   destroyed; change them with the setters. */
typedef struct fsdem_swe_fields {
    int nx, ny;
    const fsdem_real *eta;           /* m */
    const fsdem_real *qx;            /* m^2/s, uh */
    const fsdem_real *qy;            /* m^2/s, vh (all zero in 1D) */
    const fsdem_real *bed;           /* m */
    const unsigned char *blocked;    /* 1 for blocked cells (fsdem_swe_set_blocked); NULL when none */
} fsdem_swe_fields;

FSDEM_API fsdem_swe_fields fsdem_swe_get_fields(const fsdem_swe *swe);

/* Writable coupling arrays (nx*ny each): the momentum source S_p of seed 003 Eq. 2 and 8 in
   m^2/s^2 (acceleration times depth, i.e. force per unit plan area divided by the density), added to
   d(uh)/dt and d(vh)/dt and held over steps until changed (zero at creation). A source in a dry cell
   is dropped (dry cells carry no momentum). Steps read them once this function has handed them out
   (or fsdem_swe_add_force wrote them). */
typedef struct fsdem_swe_coupling {
    int nx, ny;
    fsdem_real *source_x;   /* m^2/s^2 */
    fsdem_real *source_y;   /* m^2/s^2 (ignored in 1D) */
} fsdem_swe_coupling;

FSDEM_API fsdem_swe_coupling fsdem_swe_get_coupling(fsdem_swe *swe);

typedef enum fsdem_swe_field {
    FSDEM_SWE_FIELD_DEPTH = 0, /* m */
    FSDEM_SWE_FIELD_ETA = 1,   /* m */
    FSDEM_SWE_FIELD_U = 2,     /* m/s (0 in dry cells) */
    FSDEM_SWE_FIELD_V = 3,     /* m/s */
    FSDEM_SWE_FIELD_BED = 4,   /* m */
    FSDEM_SWE_FIELD_QX = 5,    /* m^2/s */
    FSDEM_SWE_FIELD_QY = 6     /* m^2/s */
} fsdem_swe_field;

/* Copies one field (nx*ny values) to `out`. FSDEM_ERR_INVALID_ARG for a bad field or NULL. */
FSDEM_API fsdem_result fsdem_swe_copy_field(const fsdem_swe *swe, fsdem_swe_field field, fsdem_real *out);

/* Cell holding the point (x, y) (y ignored in 1D): its index k = i + nx j, or -1 outside. */
FSDEM_API int fsdem_swe_cell_at(const fsdem_swe *swe, fsdem_real x, fsdem_real y);
/* State at a point, interpolated (bi)linearly between cell centres (clamped to the outermost centres
   near the boundary; blocked cells leave the interpolation, the others share their weight): bed,
   depth, eta and velocity. FSDEM_ERR_OUT_OF_DOMAIN outside the grid or in a blocked cell. */
FSDEM_API fsdem_result fsdem_swe_sample_state(const fsdem_swe *swe, fsdem_real x, fsdem_real y, fsdem_swe_cell *out);
/* The coupling sample at `count` points (x, y horizontal, z vertical; 1D: y ignored): the
   depth-averaged velocity where z is in the water column (bed <= z <= eta), the hydrostatic pressure
   gradient rho g (deta/dx, deta/dy, -1) there, and volume fraction 1 in the column, 0 above the
   surface, below the bed and off the grid (where velocity and gradient are 0 too).
   FSDEM_ERR_INVALID_ARG for NULL arrays. */
FSDEM_API fsdem_result fsdem_swe_sample(const fsdem_swe *swe, int count, const fsdem_vec3 *points,
                                       fsdem_fluid_sample *out);
/* Adds a horizontal force exerted on the water (N; its z is ignored) to the momentum sources: spread
   over the wet cells under the square footprint [x - radius, x + radius] (x [y - radius, y + radius]
   in 2D) in proportion to their overlap, or the wet cell holding the point when radius is 0; when
   none is wet, shared equally by the wet cells of that footprint grown by one cell. Over a step of
   dt the water then gains exactly force x dt of momentum. *taken (may be NULL) is 0 when no wet
   cell could take it (the force is dropped). FSDEM_ERR_INVALID_ARG (non-finite input, radius < 0),
   FSDEM_ERR_OUT_OF_DOMAIN (the point is off the grid). */
FSDEM_API fsdem_result fsdem_swe_add_force(fsdem_swe *swe, fsdem_vec3 point, fsdem_real radius, fsdem_vec3 force,
                                          int *taken);
/* Sets the momentum sources (source_x, source_y) to zero. */
FSDEM_API fsdem_result fsdem_swe_clear_forces(fsdem_swe *swe);

/* ---- boundaries, friction and sources ---- */

/* Replaces one side's boundary condition (the series is copied). FSDEM_ERR_INVALID_ARG for a bad
   side (Y sides in 1D), type, value or series; the old condition stays. FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_swe_set_boundary(fsdem_swe *swe, fsdem_side side, const fsdem_swe_boundary *bc);
/* Per-cell Manning coefficients (nx*ny values, s/m^(1/3), >= 0), copied; NULL returns to the uniform
   desc.manning. FSDEM_ERR_INVALID_ARG names a negative or non-finite value. */
FSDEM_API fsdem_result fsdem_swe_set_manning(fsdem_swe *swe, const fsdem_real *manning);
/* Uniform rain rate (m/s, >= 0) from now on. */
FSDEM_API fsdem_result fsdem_swe_set_rain(fsdem_swe *swe, fsdem_real rate);

/* Blocked cells: solids inside the domain (buildings, walls, piers). Their faces reflect like a
   FSDEM_SWE_BC_WALL side (no mass flux, the normal velocity mirrored in the reconstruction), they
   hold no water, and gauges, sampling and point sources never reach into them. `blocked` has nx*ny
   values (nonzero: blocked) and replaces the mask; NULL unblocks every cell. Water in a cell that
   becomes blocked is removed and counted in stats.source_volume (negative), so the volume balance
   still holds. FSDEM_ERR_INVALID_ARG (with nothing changed) when a point source or gauge would be
   in a blocked cell; FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_swe_set_blocked(fsdem_swe *swe, const unsigned char *blocked);
/* Adds to the mask the cells whose centres lie in the box [x0, x1] x [y0, y1] (1D: y ignored). */
FSDEM_API fsdem_result fsdem_swe_block_box(fsdem_swe *swe, fsdem_real x0, fsdem_real y0, fsdem_real x1, fsdem_real y1);
/* Adds to the mask the cells whose centres lie inside the closed polygon of `count` >= 3 vertices
   (x, y used; a building footprint; 2D only). */
FSDEM_API fsdem_result fsdem_swe_block_polygon(fsdem_swe *swe, const fsdem_vec3 *vertices, int count);

/* A point source (Q > 0) or sink (Q < 0) of discharge Q (m^3/s; 1D: the whole channel width) in the
   cell holding (x, y); with a series, Q follows it in time like a boundary series. A sink takes no
   more than the water in its cell. */
typedef struct fsdem_swe_point_source {
    fsdem_real x, y;                 /* m */
    fsdem_real discharge;            /* m^3/s */
    const fsdem_real *series_time;   /* s, optional (NULL) */
    const fsdem_real *series_value;  /* m^3/s */
    int series_count;
} fsdem_swe_point_source;

/* Adds a point source; its id goes to *id (may be NULL). FSDEM_ERR_OUT_OF_DOMAIN, INVALID_ARG,
   OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_swe_add_point_source(fsdem_swe *swe, const fsdem_swe_point_source *src, int *id);
/* Removes a point source (the id is not reused). FSDEM_ERR_NOT_FOUND. */
FSDEM_API fsdem_result fsdem_swe_remove_point_source(fsdem_swe *swe, int id);

/* ---- time integration ---- */

/* Stable time step (s) of the current state: the dt with r dt + a dt^2 = cfl, where r is the max over
   wet cells (and inflow/stage boundary states) of (|u| + c)/dx + (|v| + c)/dy, c = sqrt(g h), and
   a = g max(|deta/dx|/dx + |deta/dy|/dy) bounds the velocity gained within the step (it matters for
   thin films on steep beds; minmod slopes, so it is 0 for a lake at rest, islands included). Capped
   by desc.dt_max and, with an eddy viscosity, by 2 nu dt (1/dx^2 + 1/dy^2) <= cfl. */
FSDEM_API fsdem_result fsdem_swe_stable_dt(const fsdem_swe *swe, fsdem_real *dt);
/* Advances by one step of the stable dt. Errors: FSDEM_ERR_NAN (the step is complete, the message
   names the first bad cell; the state is then not usable), FSDEM_ERR_IO (a gauge row could not be
   written). */
FSDEM_API fsdem_result fsdem_swe_step(fsdem_swe *swe);
/* Advances by exactly dt (s). FSDEM_ERR_CFL, with nothing changed, when dt exceeds the stability
   limit (Courant number > 1); FSDEM_ERR_INVALID_ARG for dt <= 0; otherwise as fsdem_swe_step. */
FSDEM_API fsdem_result fsdem_swe_step_dt(fsdem_swe *swe, fsdem_real dt);
/* Adaptive steps until `duration` (s) has elapsed exactly (the last step is shortened); the number
   of steps goes to *steps (may be NULL). Stops at the first error. */
FSDEM_API fsdem_result fsdem_swe_advance(fsdem_swe *swe, fsdem_real duration, long long *steps);
/* Simulated time (s). */
FSDEM_API double fsdem_swe_time(const fsdem_swe *swe);
/* The desc in force (bed, depth and boundary series pointers are NULL: the solver keeps copies). */
FSDEM_API fsdem_swe_desc fsdem_swe_get_desc(const fsdem_swe *swe);

/* ---- diagnostics ---- */

/* Water volume (m^3): sum of h dx dy (1D: h dx width). */
FSDEM_API fsdem_real fsdem_swe_volume(const fsdem_swe *swe);
/* Water momentum (kg m/s): rho times the sum of (uh, vh, 0) dx dy. */
FSDEM_API fsdem_vec3 fsdem_swe_momentum(const fsdem_swe *swe);

typedef struct fsdem_swe_stats {
    long long steps;              /* steps taken */
    double time;                  /* s */
    fsdem_real dt;                /* s, the last step */
    fsdem_real max_depth;         /* m, over the cells */
    fsdem_real max_speed;         /* m/s, largest |velocity| over wet cells */
    int wet_cells;                /* cells with h >= dry_depth */
    fsdem_real boundary_volume;   /* m^3, net volume that entered through the boundaries */
    fsdem_real source_volume;     /* m^3, net volume added by rain and point sources */
    fsdem_real clipped_volume;    /* m^3, volume added to keep depths non-negative (0 in practice) */
    long long predictor_fallbacks;/* cells whose MUSCL-Hancock predictor was skipped for positivity */
    size_t memory_bytes;          /* bytes held by the object */
} fsdem_swe_stats;

/* Statistics; conservation reads volume(t) = volume(0) + boundary_volume + source_volume
   + clipped_volume to rounding. */
FSDEM_API fsdem_swe_stats fsdem_swe_get_stats(const fsdem_swe *swe);

/* ---- output ---- */

/* Field snapshot as CSV, one row per cell: x,y,bed,h,eta,u,v (1D: x,bed,h,eta,u). FSDEM_ERR_IO,
   FSDEM_ERR_INVALID_ARG (NULL). The VTK XML snapshot (fsdem_swe_write_vti) is in >>io. */
FSDEM_API fsdem_result fsdem_swe_write_csv(const fsdem_swe *swe, const char *path);

/* Adds a gauge at (x, y) (before fsdem_swe_gauges_open); its id goes to *id (may be NULL).
   FSDEM_ERR_OUT_OF_DOMAIN, FSDEM_ERR_OUT_OF_MEMORY, FSDEM_ERR_INVALID_ARG while a file is open. */
FSDEM_API fsdem_result fsdem_swe_add_gauge(fsdem_swe *swe, fsdem_real x, fsdem_real y, int *id);
/* Samples gauge `id` now (as fsdem_swe_sample_state). FSDEM_ERR_NOT_FOUND. */
FSDEM_API fsdem_result fsdem_swe_gauge(const fsdem_swe *swe, int id, fsdem_swe_cell *out);
/* Opens a gauge time series: a CSV with columns t, then h_<id>,eta_<id>,u_<id>,v_<id> per gauge.
   A row is written now and at every later multiple of `interval` (s) after the opening time, the
   values interpolated linearly within the step that passes it; interval 0: one row per step at the
   step's time. FSDEM_ERR_IO, FSDEM_ERR_INVALID_ARG (no gauges, interval < 0). */
FSDEM_API fsdem_result fsdem_swe_gauges_open(fsdem_swe *swe, const char *path, fsdem_real interval);
/* Closes the gauge file (also done by fsdem_swe_destroy). FSDEM_ERR_IO. */
FSDEM_API fsdem_result fsdem_swe_gauges_close(fsdem_swe *swe);

/* Signed distance from p to the SWE bed surface z = z_b(x, y), for fsdem_dem_wall_sdf(fsdem_swe_bed_sdf,
   swe, material): (z - z_b)/sqrt(1 + |grad z_b|^2) with the bed normal; exact on planar beds. `user` is
   the fsdem_swe. Points outside the SWE grid take the nearest cell's bed. */
FSDEM_API fsdem_real fsdem_swe_bed_sdf(void *user, fsdem_vec3 p, fsdem_vec3 *normal);

/* ===== >>couple_swe : SWE-DEM floating debris (seed 003) ========================================== */

/* Two-way coupling of a shallow-water solver (1D along x, or 2D in x-y) with DEM debris after seed 003
   Eq. 3-8. The debris are the spheres of a 3D fsdem_dem whose z axis is vertical (gravity along -z);
   the water surface and velocity at a sphere come from the fsdem_swe. On each sphere:
     buoyancy      F_b = rho g V_sub, upwards, V_sub the submerged spherical cap (Eq. 5);
     horizontal    F_h = p_B S_B - p_F S_F per horizontal axis (Eq. 6-7): the hydrostatic part
                   rho g z integrated over the submerged circular segments of the sphere's back and
                   front (with the surface elevations sampled at x - r and x + r), plus the dynamic
                   pressure rho (beta u - w)^2 on the side facing the relative flow.
   The vertical position follows from buoyancy against gravity in the DEM (floating), and a sphere in
   water too shallow to float it rests on the bed with friction when the DEM has a bed wall (a plane,
   or fsdem_swe_bed_sdf for the solver's own bathymetry). On the water, the reaction -F_h is a momentum
   source spread over the wet cells under the sphere's footprint as force per unit plan area divided by
   rho (Eq. 8 as printed, S_px = p/rho, is loose about units; this form makes the exchange exact: the
   water gains exactly -F_h dt per step while the debris gains F_h dt).
   Each coupled step: forces from the current state, one SWE step dt, then K DEM substeps of dt/K
   (seed 000 Eq. 25, fsdem_dem_advance_with) with the horizontal forces held fixed and the buoyancy
   (and heave damping) recomputed at every DEM force evaluation from the sphere's height against the
   held water surface: buoyancy is a stiff spring, and holding it over a whole fluid step would let
   bobbing grow without bound. A horizontal force is only applied while wet cells under (or next to)
   the sphere can take its reaction. The coupler owns the SWE's momentum sources and the DEM's
   external forces, and reaches both solvers through their coupling functions only (>>doc). */

typedef struct fsdem_swe_dem fsdem_swe_dem;

typedef struct fsdem_swe_dem_desc {
    fsdem_swe *swe;               /* water; not owned; must outlive the coupler */
    fsdem_dem *dem;               /* debris: dim 3, gravity along -z; not owned */
    fsdem_real beta;              /* -; surface-velocity correction of seed 003 Eq. 6; default 1.1 */
    int two_way;                  /* 1: the water feels the reaction (Eq. 8); 0: one-way; default 1 */
    fsdem_real heave_damping;     /* -; fraction of critical damping of the bobbing about the floating
                                     draft (wave radiation is not in the SWE); default 0 */
    long long max_substeps;       /* DEM substeps one coupled step may take; a longer step is refused
                                     before anything moves; default 100000 */
    fsdem_log_fn log;             /* optional; default NULL */
    void *log_user;
} fsdem_swe_dem_desc;

FSDEM_API fsdem_swe_dem_desc fsdem_swe_dem_desc_default(void);
/* Creates a coupler. FSDEM_ERR_INVALID_ARG (missing solver, DEM not 3D, gravity not along -z or
   different from the SWE's, beta <= 0, negative damping; the reason goes to desc->log and to
   `message` of fsdem_swe_dem_desc_check), FSDEM_ERR_OUT_OF_MEMORY. Destroy with fsdem_swe_dem_destroy
   (which leaves the solvers alive). */
FSDEM_API fsdem_result fsdem_swe_dem_desc_check(const fsdem_swe_dem_desc *desc, char *message, size_t message_size);
FSDEM_API fsdem_result fsdem_swe_dem_create(const fsdem_swe_dem_desc *desc, fsdem_swe_dem **out);
FSDEM_API void fsdem_swe_dem_destroy(fsdem_swe_dem *coupler);
FSDEM_API const char *fsdem_swe_dem_last_error(const fsdem_swe_dem *coupler);

/* Fluid forces on one sphere, as the last fsdem_swe_dem_update_forces computed them. */
typedef struct fsdem_swe_dem_force {
    int id;                       /* stable id of the DEM particle (fsdem_dem_particles.id) */
    fsdem_vec3 buoyancy;          /* N, (0, 0, rho g V_sub) */
    fsdem_vec3 hydrostatic;       /* N, horizontal */
    fsdem_vec3 dynamic;           /* N, horizontal */
    fsdem_vec3 heave;             /* N, vertical damping (0 unless heave_damping > 0) */
    fsdem_real submerged_volume;  /* m^3 */
    fsdem_real frontal_area;      /* m^2, submerged area facing +x (S_F of seed 003 along x) */
    fsdem_real surface;           /* m, water surface at the centre, held over the DEM substeps */
    int in_water;                 /* 1 when water reaches the sphere */
} fsdem_swe_dem_force;

/* Computes the fluid forces on every free sphere from the current states, writes them to the DEM's
   external forces and, with two_way, the reactions to the SWE's momentum sources. */
FSDEM_API fsdem_result fsdem_swe_dem_update_forces(fsdem_swe_dem *coupler);
/* Forces on particle `index` from the last update (zero for fixed particles and dry spheres), found
   by the particle's id, so removals since do not mix the records up. FSDEM_ERR_NOT_FOUND for a bad
   index or a particle added since the update. */
FSDEM_API fsdem_result fsdem_swe_dem_get_force(const fsdem_swe_dem *coupler, int index, fsdem_swe_dem_force *out);
/* One coupled step: update the forces, one adaptive SWE step of at most dt_cap (<= 0: no cap), then
   the DEM over the same dt in substeps. The step goes to *dt and the substep count to *substeps (both
   may be NULL). Errors of either solver are passed on with their message. */
/* One coupled step of the SWE's stable dt: update the forces, the SWE step, then the DEM over the
   same dt in substeps. The substep count is checked first, so a step the DEM cannot take (more than
   max_substeps) is refused with FSDEM_ERR_INVALID_ARG before anything moves. Errors of either
   solver are passed on with their message. */
FSDEM_API fsdem_result fsdem_swe_dem_step(fsdem_swe_dem *coupler);
/* One coupled step of dt (s); FSDEM_ERR_CFL (nothing moved) when it is unstable for the SWE. */
FSDEM_API fsdem_result fsdem_swe_dem_step_dt(fsdem_swe_dem *coupler, fsdem_real dt);
/* Coupled steps until exactly `duration` (s) later; their number goes to *steps (may be NULL). */
FSDEM_API fsdem_result fsdem_swe_dem_advance(fsdem_swe_dem *coupler, fsdem_real duration, long long *steps);
/* The SWE's stable dt (s). */
FSDEM_API fsdem_result fsdem_swe_dem_stable_dt(const fsdem_swe_dem *coupler, fsdem_real *dt);
/* The SWE's time (s). */
FSDEM_API double fsdem_swe_dem_time(const fsdem_swe_dem *coupler);
FSDEM_API fsdem_swe_dem_desc fsdem_swe_dem_get_desc(const fsdem_swe_dem *coupler);

typedef struct fsdem_swe_dem_stats {
    long long steps;              /* coupled steps */
    double time;                  /* s */
    fsdem_real dt;                /* s, the last coupled step */
    long long substeps;           /* DEM substeps of the last coupled step */
    long long substeps_total;     /* DEM substeps of all coupled steps */
    int in_water;                 /* spheres in water at the last force update */
    fsdem_vec3 impulse_to_water;  /* N s, momentum given to the water by the reactions, total */
} fsdem_swe_dem_stats;

FSDEM_API fsdem_swe_dem_stats fsdem_swe_dem_get_stats(const fsdem_swe_dem *coupler);

/* ===== >>mps : MPS free-surface solver (seed 002) ================================================== */

/* Incompressible free-surface flow by the Moving Particle Semi-implicit method (Koshizuka and Oka
   1996) in the form of seed 002 §2.1: the Zhang kernel (Eq. 6), number density, gradient,
   divergence and Laplacian with the 1/eps_j factor of a per-particle porosity (Eq. 7-11), the
   mixed source term of the pressure Poisson equation (Eq. 12, gamma = 0.01; Eq. 13, the source
   times the porosity eps_i, with desc.model = FSDEM_MPS_MODEL_B), free-surface detection
   by number density and neighbour asymmetry (Eq. 14-16), and the CFL rule of Eq. 37 (§2.4).
   Around it: probes and gauges (pressure sensors, water level, force on an obstacle; a CSV series
   at exact output times), particle snapshots (fsdem_mps_write_vtp in >>io) and save/restore
   (>>restart).

   Particles are of three kinds. FLUID particles move. WALL particles are the layer of a solid next
   to the fluid: fixed, their pressure is solved with the fluid's, so the fluid is pushed back.
   DUMMY particles are the deeper layers of a solid: fixed, they only complete the number density
   of the particles near the wall. Solids are built on the r0 lattice by fsdem_mps_add_box_walls
   (a tank) and fsdem_mps_add_box_obstacle (a box inside it): one WALL layer and enough DUMMY
   layers that a wall particle sees a full neighbourhood within re (ceil(re/r0) - 1 of them: 4 for
   re = 4.1 r0). Fluid fills boxes on the same lattice (fsdem_mps_fill_box) or comes from a list.

   Step of dt (all sums at the positions r^m of the start of the step, over neighbours j within re):
     1. neighbours (cell list on fsdem_cellgrid, cells of edge re), number density n_i (Eq. 7);
     2. predictor u* = u + dt (nu lap(u) + g) for FLUID particles (Eq. 10 on u; solids u* = dt g, so
        a uniform body force makes no source of Eq. 12 at the walls: see step 4);
     3. free surface (FLUID and WALL particles): n_i < beta n0 (Eq. 14) or |F_i| > alpha |F0| (Eq.
        15-16), where |F0| is |F| of a particle on the flat surface of the full initial lattice (the
        seed's "F0 of the internal particles" is zero on a lattice; the surface one is meant);
     4. pressure Poisson equation on the FLUID and WALL particles not on the surface (surface: p = 0,
        Dirichlet; DUMMY particles are no unknowns: in Eq. 10 they take the ghost pressure p_i +
        rho g.(r_j - r_i), as in the corrector's gradient, a known term, which is the Neumann condition
        dp/dn = rho g.n of a wall): Eq. 10 = Eq. 12, its row i multiplied by -n0 lambda/(2d) / eps_i
        so the matrix  A_ii = sum_j w_ij/(eps_i eps_j),  A_ij = -w_ij/(eps_i eps_j)  (sums over the
        non-DUMMY j) is symmetric and positive definite (a fsdem_csr, solved by fsdem_pcg; Eq. 13
        instead of Eq. 12 with desc.model = FSDEM_MPS_MODEL_B);
     5. negative pressures set to 0 when desc.clamp_negative_pressure (the seed says nothing; the
        original MPS clamps, so the default does);
     6. corrector u = u* - dt/rho grad p (Eq. 8 or the stabilised form, desc.gradient);
     6b. collisions (desc.collision_distance, restitution; Koshizuka, Nobe and Oka 1998): pairs that
        would end the step closer than collision_distance r0 lose (1 + e) of their approach speed
        (details at fsdem__mps_collide), then r += dt u;
     7. when desc.shifting > 0, r += dr, the Fickian particle shift of Lind, Xu, Stansby and Rogers
        (2012, J. Comput. Phys. 231:1499), dr = -D grad C with D = desc.shifting r0^2 and grad C the
        kernel sum of Eq. 8 with C = 1, computed at the positions of step 1: FLUID particles only,
        none on the surface, only tangentially (normal: F of Eq. 15) with a surface neighbour,
        at most cfl r0 (details at fsdem__mps_shift in the implementation).
   Operators: Eq. 8-10 are exact for linear fields (gradient, divergence) and quadratic fields
   (Laplacian) at particles whose neighbourhood is a full regular lattice; they are first and
   second order only in that sense (consistency is lost near the surface and in disordered regions).
   Still water. The drift is quoted one way: the largest displacement of a FLUID particle from its
   start after 0.5 s, in r0 (issue 11 asks below 0.1 r0), with the top row's mean sinking beside it.
   In a tank 0.2 m deep at r0 = 0.01 m with the defaults: 2D 0.86 r0, top row 0.47 r0
   (test_mps_still_water, validation/mps_hydrostatic); 3D 3.87 r0, top row 0.91 r0; 2D with the
   sum form of Eq. 8 1.1 r0. The figures below are of the sum form without collisions unless said. Two causes, measured:
   (a) the free-surface band. The lattice at rest is not a discrete equilibrium: the rows below the
   surface row have number densities short of n0 by geometry (0.85 n0 one row down, re = 4.1 r0),
   which Eq. 12 reads as expansion. In the first step from rest the density term alone lowers the
   pressure at mid-depth to 522 Pa against 883 hydrostatic (its weight gamma rho/dt^2 grows as dt
   shrinks), and the top row's mean sinks 0.7 r0 in 0.15 s. Without it (gamma = 0) Eq. 10 is still one-
   sided there: the pressure one row down is 2.3 times hydrostatic, and the sum form of Eq. 8
   pushes that row up at 0.54 g (0.29 g with the min form; the corrected form, exact for linear
   fields, shows the pressure error itself: rows 1-5 fall at 0.4-1 g with gamma = 0.01). (b) A
   shear instability along the walls: after a settling phase (1 s with the velocities zeroed after
   each step) the columns next to each wall slide against each other, alternately up and down,
   their speed doubling every 0.02 s (about 35/s, the same at dt = 1e-3 and 5e-4 s, with gamma =
   0.01, 0.001 and 0): a mechanical instability of the pairwise-repulsive sum form against the fixed
   wall layer, not of the time stepping. Neither particle shifting nor the corrected gradient cures
   them (drift at 0.5 s: shifting 0.02 / 0.05 with the sum form 0.97 / 1.30 r0, 0.1 or more blows up
   between 0.35 and 0.5 s; corrected gradient without shifting or with 0.05 blows up by 0.32 s, with
   0.2 drifts 6.8 r0); both stay behind desc switches, off by default. Mid-depth pressure is within
   2% whenever the tank survives. A cure needs consistent operators at the free surface (e.g. ghost
   values above it) and a wall condition that resists shear; not done.
   Units: m, s, kg/m^3, m^2/s (kinematic viscosity), Pa. In 2D the problem lies in the x-y plane.
   One step allocates nothing once its lists have reached their size (the neighbour list and the
   matrix grow by doubling when the particle arrangement needs more room than ever before). */

typedef struct fsdem_mps fsdem_mps;

/* Kind of a particle (fsdem_mps_particles.kind). */
typedef enum fsdem_mps_kind {
    FSDEM_MPS_KIND_FLUID = 0, /* moves; pressure solved (0 on the free surface) */
    FSDEM_MPS_KIND_WALL = 1,  /* fixed; pressure solved; the solid layer next to the fluid */
    FSDEM_MPS_KIND_DUMMY = 2  /* fixed; no pressure; completes the number density behind a wall layer */
} fsdem_mps_kind;

/* Pressure gradient of the corrector. */
typedef enum fsdem_mps_gradient_model {
    /* seed 002 Eq. 8 as printed, (p_j + p_i) (Tanaka and Masunaga 2010; Khayyer and Gotoh): the
       sum makes every pair repulsive for positive pressures and conserves momentum. But a uniform
       pressure pushes every particle with a cut neighbourhood (near the free surface) outwards,
       in proportion to it, and the next pressure equation answers that expansion with the
       opposite level: in a 2D dam break (4 m tank, 1 x 2 m column, r0 = 0.015 m) the pressure of
       the lower half of the column swung between +4.1e5 and -3.8e5 Pa from one step to the next
       at t = 0.20 s and the run blew up (0.09 s without collisions, 0.28 s with them) */
    FSDEM_MPS_GRADIENT_MODEL_SUM = 0,
    /* Koshizuka, Nobe and Oka (1998): (p_j - min p) with the smallest pressure of i and its
       neighbours; also repulsive, exact for linear fields in the interior of a lattice, and blind
       to a uniform pressure level; with the collisions of step 6b the dam break above runs through
       (without them it failed at 0.19 s); the default */
    FSDEM_MPS_GRADIENT_MODEL_MIN = 1,
    /* the difference form (p_j - p_i) times the inverse of the moment matrix
       sum_j w_ij (r_j - r_i)(r_j - r_i)^T / |r_j - r_i|^2, the corrected gradient of Khayyer and
       Gotoh (2011, Appl. Ocean Res. 33:235; after Randles and Libersky 1996): exact for linear
       fields in any neighbourhood that spans the space; not repulsive (no pressure force in a
       uniform pressure), so clustering is left to particle shifting (desc.shifting) */
    FSDEM_MPS_GRADIENT_MODEL_CORRECTED = 2
} fsdem_mps_gradient_model;

/* Form of the pressure equation's source with a porosity field (seed 002 §2.1). */
typedef enum fsdem_mps_model {
    FSDEM_MPS_MODEL_A = 0, /* Eq. 12: rho_f in both terms of the mixed source */
    FSDEM_MPS_MODEL_B = 1  /* Eq. 13: eps_f rho_f, eps_f the porosity of the particle (identical at eps = 1) */
} fsdem_mps_model;

typedef struct fsdem_mps_desc {
    int dim;                        /* 2 or 3 */
    fsdem_real r0;                  /* m; initial particle spacing, > 0; default 0.01 */
    fsdem_real re;                  /* m; interaction radius, >= 2 r0; 0 = 4.1 r0 (seed 002 §2.1); */
                                    /*    default 0 */
    fsdem_real density;             /* kg/m^3; rho_f; default 1000 */
    fsdem_real viscosity;           /* m^2/s; kinematic viscosity nu = mu_f/rho_f; default 1e-6 */
    fsdem_vec3 gravity;             /* m/s^2; default (0,-9.81,0) in 2D, (0,0,-9.81) in 3D */
    fsdem_real gamma;               /* -; weight of the number-density term of Eq. 12, in [0, 1]; */
                                    /*    default 0.01 */
    fsdem_mps_model model;          /* source of the pressure equation: Eq. 12 or 13; default A */
    fsdem_real beta;                /* -; surface when n < beta n0 (Eq. 14), in (0, 1); default 0.8 */
    fsdem_real alpha;               /* -; surface when |F| > alpha |F0| (Eq. 16), > 0; default 0.9 */
    fsdem_real cfl;                 /* -; Courant number C of Eq. 37, u_max dt / r0 <= C, in (0, 1]; */
                                    /*    default 0.2 */
    fsdem_real dt_max;              /* s; longest step (taken while nothing moves); default 1e-3 */
    fsdem_vec3 domain_min;          /* m; every particle must stay inside; default (0,0,0) */
    fsdem_vec3 domain_max;          /* m; default (1,1,1) (z unused in 2D) */
    fsdem_mps_gradient_model gradient; /* default FSDEM_MPS_GRADIENT_MODEL_MIN (see the enum) */
    int clamp_negative_pressure;    /* 1: p < 0 is set to 0 after the solve; default 1 */
    fsdem_real collision_distance;  /* -; in units of r0: approaching FLUID particles that would */
                                    /*    come closer collide (step 6b), in [0, 1); 0 = off; */
                                    /*    default 0.8 (see fsdem__mps_collide) */
    fsdem_real restitution;         /* -; coefficient of restitution of those collisions, in [0, 1]; */
                                    /*    default 0.2 */
    fsdem_real shifting;            /* -; particle shifting D / r0^2 (Lind et al. 2012, step 7), */
                                    /*    in [0, 1]; 0 = off; default 0 (see the notes above) */
    fsdem_precond pressure_precond; /* default FSDEM_PRECOND_AUTO: MIC(0) in 2D, Jacobi in 3D */
    fsdem_real pressure_tolerance;  /* -; relative residual of the pressure solve; default 1e-8 */
                                    /*    (1e-5 in float) */
    int pressure_max_iterations;    /* >= 1; default 1000 */
    fsdem_allocator allocator;      /* default: FSDEM_MALLOC/FSDEM_FREE */
    fsdem_log_fn log;               /* optional; default NULL */
    void *log_user;
} fsdem_mps_desc;

/* Defaults for dim = 2 (x-y plane, gravity -y) or 3 (gravity -z); see the field comments. */
FSDEM_API fsdem_mps_desc fsdem_mps_desc_default(int dim);
/* Checks a desc without creating anything; the reason, naming the field, goes to `message` (may be
   NULL). Returns FSDEM_OK or FSDEM_ERR_INVALID_ARG (r0 <= 0, re < 2 r0, an empty domain, ...). */
FSDEM_API fsdem_result fsdem_mps_desc_check(const fsdem_mps_desc *desc, char *message, size_t message_size);
/* Creates a solver without particles (time 0); n0, lambda and |F0| are computed here from the full
   r0 lattice. *out is NULL on failure. Errors: FSDEM_ERR_INVALID_ARG (the reason goes to desc->log
   and fsdem_mps_desc_check), FSDEM_ERR_OUT_OF_MEMORY. Destroy with fsdem_mps_destroy. */
FSDEM_API fsdem_result fsdem_mps_create(const fsdem_mps_desc *desc, fsdem_mps **out);
FSDEM_API void fsdem_mps_destroy(fsdem_mps *mps);
/* Message of the last failed call on this object ("" after success). Valid until the next call. */
FSDEM_API const char *fsdem_mps_last_error(const fsdem_mps *mps);
/* The desc in force (re resolved). */
FSDEM_API fsdem_mps_desc fsdem_mps_get_desc(const fsdem_mps *mps);

/* ---- particles ---- */

/* Adds `count` particles of one kind (positions m; velocities m/s, NULL for rest; solids are
   always at rest). All or nothing: FSDEM_ERR_INVALID_ARG (a bad kind, count < 0, NULL positions, a
   non-finite value, naming the particle), FSDEM_ERR_OUT_OF_DOMAIN (the first one outside the
   domain), FSDEM_ERR_OUT_OF_MEMORY. Allocates (outside any step). */
FSDEM_API fsdem_result fsdem_mps_add_particles(fsdem_mps *mps, fsdem_mps_kind kind, int count,
                                               const fsdem_vec3 *positions, const fsdem_vec3 *velocities);
/* Fills the box [lo, hi] with FLUID particles on the r0 lattice anchored at lo: centres at
   lo + (i + 1/2) r0 per axis, those inside the box and outside every box obstacle, all with
   `velocity`. The number added goes to *added (may be NULL). Errors as fsdem_mps_add_particles,
   and FSDEM_ERR_INVALID_ARG for an empty box. */
FSDEM_API fsdem_result fsdem_mps_fill_box(fsdem_mps *mps, fsdem_vec3 lo, fsdem_vec3 hi, fsdem_vec3 velocity,
                                          int *added);
/* Builds the walls of a box tank whose inside is [lo, hi], on the lattice of fsdem_mps_fill_box
   anchored at lo: the lattice points outside the box within one spacing of it are WALL particles,
   the next ceil(re/r0) - 1 layers DUMMY particles. A side whose bit (1 << fsdem_side) is set in
   `open_sides` has no wall, and the walls next to it stop at the box's face there (a tank open
   at the top: 1 << FSDEM_SIDE_YMAX in 2D, 1 << FSDEM_SIDE_ZMAX in 3D). *added (may be NULL) counts
   the particles. Errors as fsdem_mps_fill_box. */
FSDEM_API fsdem_result fsdem_mps_add_box_walls(fsdem_mps *mps, fsdem_vec3 lo, fsdem_vec3 hi,
                                               unsigned open_sides, int *added);
/* Adds a solid box [lo, hi] inside the flow: lattice points lo + (i + 1/2) r0 inside it, the outer
   layer WALL particles, the next ceil(re/r0) - 1 layers DUMMY (the core, beyond reach, is left
   empty). Later fsdem_mps_fill_box calls leave the box out. Its index goes to *id (may be NULL).
   Errors as fsdem_mps_fill_box. */
FSDEM_API fsdem_result fsdem_mps_add_box_obstacle(fsdem_mps *mps, fsdem_vec3 lo, fsdem_vec3 hi, int *id);

/* Views of the particles (structure of arrays, index order = order of addition), valid until
   particles are added or the solver is destroyed. Steps update them in place. `velocity` of FLUID
   particles and `porosity` (eps_f in (0, 1], 1 by default; the 1/eps_j of Eq. 7-16, for a coupler)
   may be edited between steps. `number_density` and `surface` are those of the last step (or of
   the last operator call). */
typedef struct fsdem_mps_particles {
    int count;
    int dim;
    const fsdem_vec3 *position;       /* m */
    fsdem_vec3 *velocity;             /* m/s (0 for WALL and DUMMY) */
    const fsdem_real *pressure;       /* Pa (0 for DUMMY and surface particles) */
    const unsigned char *kind;        /* fsdem_mps_kind */
    const unsigned char *surface;     /* 1: free-surface particle (p = 0) at the last step */
    const fsdem_real *number_density; /* -; n_i of Eq. 7 at the last step (0 for DUMMY) */
    fsdem_real *porosity;             /* -; eps_f per particle */
    const fsdem_vec3 *pressure_gradient; /* Pa/m; grad p of the last corrector at FLUID particles */
                                      /*    (desc.gradient form; 0 elsewhere and before a step) */
    fsdem_real mass;                  /* kg (kg/m in 2D); the fluid of one particle, rho r0^d */
} fsdem_mps_particles;

FSDEM_API fsdem_mps_particles fsdem_mps_get_particles(fsdem_mps *mps);

/* What a coupler writes (>>doc, COUPLING INTERFACE): a force on every particle (N; N per metre of
   depth in 2D), held over later steps and applied to FLUID particles in the predictor (step 2:
   u* += dt force / mass), and the porosity eps of Eq. 7-16 (the same array as the view's). The
   forces start at zero; steps read them only once this function has handed them out. Valid until
   particles are added. With desc.model = FSDEM_MPS_MODEL_B the corrector divides the pressure
   acceleration by eps_i (seed 002 Eq. 5: the fluid takes the whole pressure gradient of the
   mixture), with Model A it does not (Eq. 2: -eps grad P on a volume of mixture, i.e. -grad P on
   the fluid's own volume). */
typedef struct fsdem_mps_coupling {
    int count;
    fsdem_vec3 *force;                /* N (N/m in 2D) */
    fsdem_real *porosity;             /* -; in (0, 1] */
} fsdem_mps_coupling;

FSDEM_API fsdem_mps_coupling fsdem_mps_get_coupling(fsdem_mps *mps);

/* ---- particle-interaction operators (seed 002 Eq. 7-10) ---- */

/* The discrete operators of the solver applied to caller fields at the current positions (one
   value, or vector, per particle; the output of DUMMY particles is 0). The sums run over every
   neighbour except DUMMY particles, as in the step's pressure terms; each refreshes the view's
   number_density. Gradient: Eq. 8 or the form of desc.gradient. Allocates (the neighbour list).
   FSDEM_ERR_INVALID_ARG (NULL arrays), FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_mps_gradient(fsdem_mps *mps, const fsdem_real *phi, fsdem_vec3 *out);
FSDEM_API fsdem_result fsdem_mps_divergence(fsdem_mps *mps, const fsdem_vec3 *field, fsdem_real *out);
FSDEM_API fsdem_result fsdem_mps_laplacian(fsdem_mps *mps, const fsdem_real *phi, fsdem_real *out);
/* The pressure matrix of the last step (fsdem_csr, rows = unknowns in particle order; see the
   section's step 4) and in *rows_particle (may be NULL) the particle of each row. Valid until the
   next step. rows = 0 before the first step. */
FSDEM_API fsdem_csr fsdem_mps_pressure_matrix(const fsdem_mps *mps, const int **rows_particle);

/* ---- time stepping ---- */

/* Stable step of the current state (s): C r0 / u_max over FLUID particles (Eq. 37), at most dt_max.
   FSDEM_ERR_NAN when a velocity is not finite. */
FSDEM_API fsdem_result fsdem_mps_stable_dt(const fsdem_mps *mps, fsdem_real *dt);
/* One step of the stable dt. Errors: FSDEM_ERR_INVALID_ARG (no FLUID particle, a porosity outside
   (0, 1]), FSDEM_ERR_NAN (a non-finite velocity before the step), FSDEM_ERR_NOT_CONVERGED (the
   pressure solve stopped at its iteration limit or failed), FSDEM_ERR_OUT_OF_MEMORY: in these cases
   nothing changed. After a completed step: FSDEM_ERR_NAN (a particle's velocity or position became
   non-finite) or FSDEM_ERR_OUT_OF_DOMAIN (a FLUID particle left the domain), naming the particle;
   the caller may remove it (not yet possible) or stop. */
FSDEM_API fsdem_result fsdem_mps_step(fsdem_mps *mps);
/* One step of exactly dt (s). FSDEM_ERR_INVALID_ARG for dt <= 0 or not finite, FSDEM_ERR_CFL when
   u_max dt / r0 > cfl (Eq. 37; the message names the fastest particle); nothing changes then.
   Otherwise as fsdem_mps_step. */
FSDEM_API fsdem_result fsdem_mps_step_dt(fsdem_mps *mps, fsdem_real dt);
/* Adaptive steps until `duration` (s) later exactly (the last steps shortened); the number of
   steps goes to *steps (may be NULL). Stops at the first error. */
FSDEM_API fsdem_result fsdem_mps_advance(fsdem_mps *mps, fsdem_real duration, long long *steps);
/* Simulated time (s). */
FSDEM_API double fsdem_mps_time(const fsdem_mps *mps);

typedef struct fsdem_mps_stats {
    long long steps;
    double time;                  /* s */
    fsdem_real dt;                /* s, last step */
    int fluid, wall, dummy;       /* particles of each kind */
    int surface;                  /* FLUID and WALL particles on the free surface, last step */
    int unknowns;                 /* rows of the last pressure equation */
    long long neighbours;         /* particle pairs within re (each counted once), last step */
    fsdem_real n0;                /* -; number density of the full lattice (Eq. 7 with eps = 1) */
    fsdem_real lambda;            /* m^2; Eq. 11 on the full lattice */
    fsdem_real f0;                /* -; |F| (Eq. 15) of a particle on the flat surface of the lattice */
    int pressure_iterations;      /* PCG iterations, last step */
    long long pressure_iterations_total;
    fsdem_real pressure_residual; /* -; relative, last step */
    fsdem_real max_speed;         /* m/s, FLUID particles */
    fsdem_real max_pressure;      /* Pa */
    double seconds_total;         /* CPU seconds in steps (clock()) */
    double seconds_pressure;      /* CPU seconds in the pressure equation: assembly, setup, solve */
    size_t memory_bytes;          /* bytes held by the solver, its pcg included */
} fsdem_mps_stats;

FSDEM_API fsdem_mps_stats fsdem_mps_get_stats(const fsdem_mps *mps);

/* ---- probes (the sensors of experiments) ----

   Point probes average over the particles near a point with the smooth weight
       W(r) = (1 - r^2/R^2)^3 for r < R, 0 beyond,
   normalised as a kernel (integral 1: C = 4/(pi R^2) in 2D, 315/(64 pi R^3) in 3D) where a
   volume is measured. They read the state after the last step (positions of its end, pressures of
   its solve) and scan all particles: O(particles) per call, meant for output times, not for
   every particle. "Up" is the last axis (y in 2D, z in 3D), as the lattice's free surface. */

/* Pressure (Pa) at `point`: the W-weighted mean (Shepard) of the FLUID and WALL particles within
   `radius` (m; 0 means re) of it, surface particles (p = 0) included; 0 when none is there (a
   sensor in the air). A sensor on a wall reads its WALL particles and the liquid beside them.
   FSDEM_ERR_INVALID_ARG for NULL arguments, a non-finite point or a negative radius. */
FSDEM_API fsdem_result fsdem_mps_probe_pressure(const fsdem_mps *mps, fsdem_vec3 point, fsdem_real radius,
                                                fsdem_real *pressure);
/* Water level (m, a coordinate along the last axis) at the gauge through `gauge` (its x in 2D, x
   and y in 3D; the last coordinate is ignored): the highest point of that vertical line where the
   liquid fraction sum_j r0^d W(|r_j - point|) over FLUID particles (R = 2 r0) reaches 1/2, which
   on a flat surface is the surface of the volume the particles stand for (half a spacing above
   the top row), interpolated between samples r0/4 apart; domain_min's last coordinate when no
   liquid is within R of the line. The first liquid from above counts, a jet over the gauge
   included, as a gauge sees it. FSDEM_ERR_INVALID_ARG for NULL arguments or a non-finite gauge. */
FSDEM_API fsdem_result fsdem_mps_probe_height(const fsdem_mps *mps, fsdem_vec3 gauge, fsdem_real *height);
/* Gauges: probes at fixed places sampled at exact output times into a CSV series, as the PIC
   solver's (fsdem_pic_add_gauge). */
typedef enum fsdem_mps_gauge_kind {
    FSDEM_MPS_GAUGE_KIND_LEVEL = 0,   /* water level at the gauge line through the position (fsdem_mps_probe_height) */
    FSDEM_MPS_GAUGE_KIND_PRESSURE = 1 /* pressure at the position (fsdem_mps_probe_pressure with the radius) */
} fsdem_mps_gauge_kind;

/* Adds a gauge (before fsdem_mps_gauges_open); its id goes to *id (may be NULL). Radius (m) of a
   pressure sensor, 0 for re. FSDEM_ERR_OUT_OF_DOMAIN, FSDEM_ERR_INVALID_ARG (bad kind, radius < 0,
   non-finite input, a file is open), FSDEM_ERR_OUT_OF_MEMORY. */
FSDEM_API fsdem_result fsdem_mps_add_gauge(fsdem_mps *mps, fsdem_mps_gauge_kind kind, fsdem_vec3 position, fsdem_real radius,
                                           int *id);
/* Gauge `id` now (m or Pa). FSDEM_ERR_NOT_FOUND. */
FSDEM_API fsdem_result fsdem_mps_gauge(const fsdem_mps *mps, int id, fsdem_real *value);
/* Opens a gauge time series: a CSV with columns t, then level_<id> or p_<id> per gauge, rows at the
   multiples of `interval` (s) interpolated linearly within the step that passes each, or one per
   step for interval 0. FSDEM_ERR_IO, FSDEM_ERR_INVALID_ARG (no gauges, interval < 0). A restore is
   refused while it is open. */
FSDEM_API fsdem_result fsdem_mps_gauges_open(fsdem_mps *mps, const char *path, fsdem_real interval);
/* Closes the gauge file (also done by fsdem_mps_destroy). FSDEM_ERR_IO. */
FSDEM_API fsdem_result fsdem_mps_gauges_close(fsdem_mps *mps);

/* Force (N; N per metre of depth in 2D) of the liquid on the box obstacle `id`
   (fsdem_mps_add_box_obstacle) in the last step: the pressure of the step on its faces, each WALL
   particle of its skin standing for r0^(d-1) of every face within a spacing of it, its pressure
   carried from its centre (half a spacing inside) to the face hydrostatically, as the DUMMY ghosts
   of the pressure equation are. Exact for still water (Archimedes); viscous stress is not included
   (of order nu / (u r0) of the pressure force). 0 before the first step. FSDEM_ERR_INVALID_ARG for
   NULL arguments or an unknown id. */
FSDEM_API fsdem_result fsdem_mps_obstacle_force(const fsdem_mps *mps, int id, fsdem_vec3 *force);

/* ===== >>drag : drag laws of unresolved couplings (seed 002 Eq. 25-28 and the literature) ===== */

/* The drag of the fluid on one sphere of diameter d and volume V = pi d^3 / 6 at porosity eps (fluid
   volume fraction around it), for the couplers whose grid or particles are coarser than the sphere:
       F = c V (u - v),   c = beta / (1 - eps)   (kg m^-3 s^-1)
   with u the intrinsic fluid velocity at the sphere, v the sphere's, beta the interphase momentum
   exchange coefficient of seed 002 Eq. 25-26. F is the drag WITHOUT the pressure-gradient part: a
   coupler adds -V grad P itself (seed 002 Eq. 34, Model A), or uses F / eps - V rho_f g where only the
   dynamic pressure comes from the drag (Eq. 35, Model B). c is returned rather than beta because it
   stays finite at eps = 1 (a lone sphere), where beta = 0.

   Reynolds numbers: Re = eps rho_f d |u - v| / mu_f (Eq. 28, the superficial slip) for the laws of a
   suspension; Re = rho_f d |u - v| / mu_f for the isolated-sphere laws. mu_f is the DYNAMIC viscosity.
   Every law is written so that |u - v| = 0 (Re = 0) gives its creeping-flow limit, no 0/0.

   Each published form converted to c (each sense checked against Eq. 26, see >>impl_drag):
     STOKES            c = 18 mu / d^2: c V = 3 pi mu d.
     SCHILLER_NAUMANN  the isolated sphere's F = Cd (pi d^2 / 8) rho |u - v|^2 with Cd of Eq. 27
                       (Schiller and Naumann 1933; 0.44 above Re = 1000): c = 0.75 Cd rho |u - v| / d.
     ERGUN_WEN_YU      Eq. 26 as printed, divided by (1 - eps): Ergun (1952) for eps <= 0.8,
                       c = 150 (1 - eps) mu / (eps d^2) + 1.75 rho |u - v| / d; Wen and Yu (1966) above,
                       c = 0.75 Cd rho |u - v| eps^-1.65 / d (Cd of Eq. 27 at the Re of Eq. 28). c jumps
                       at eps = 0.8: d = 1 mm in water (1000 kg/m^3, 1e-3 Pa s) at 0.01 m/s (Re = 8)
                       has c = 55000 on the Ergun side and 52866.60 on the Wen-Yu side (-3.9 %).
     GIDASPOW          the two terms of Eq. 26 blended as Huilin and Gidaspow (2003),
                       beta = (1 - phi) beta_WenYu + phi beta_Ergun, phi = 1/2 + atan(262.5 (eps_s - 0.2)) / pi,
                       eps_s = 1 - eps (262.5 = 150 * 1.75): smooth, half and half at eps = 0.8. The
                       Ergun share never vanishes: 0.606 % at eps = 1, where c is 0.99394 of Stokes.
     DI_FELICE         Di Felice (1994): F = F0 eps^-chi, F0 the single-sphere drag at the superficial
                       slip U = eps |u - v| (Cd0 = (0.63 + 4.8 / sqrt(Re))^2, Re of Eq. 28),
                       chi = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2 / 2): c = 0.75 Cd0 rho |u - v| eps^(2 - chi) / d.
                       F is already the drag of Eq. 25 (see >>impl_drag). Its creeping limit is 0.96 of
                       Stokes (Cd0 -> 23.04 / Re). Below eps = 0.435 c falls as the slip grows over a
                       band of Re (0.29 to 1.7 at eps = 0.4, 0.024 to 5 at eps = 0.05) where chi falls
                       faster than Cd0 |u - v| grows; the force c V |u - v| still grows.
     BEETSTRA          Beetstra, van der Hoef and Kuipers (2007): F(phi, Re) = F_d / (3 pi mu d eps |u - v|),
                       phi = 1 - eps, F_d the drag of Eq. 25 (the total force is F_d / eps):
                       c = 18 mu eps F / d^2, exactly Stokes at eps = 1, Re = 0. */
typedef enum fsdem_drag_law {
    FSDEM_DRAG_LAW_STOKES = 0,           /* isolated sphere, creeping flow: 3 pi mu d, porosity ignored */
    FSDEM_DRAG_LAW_SCHILLER_NAUMANN = 1, /* isolated sphere, Cd of Eq. 27, Re = rho d |u - v| / mu, porosity ignored */
    FSDEM_DRAG_LAW_ERGUN_WEN_YU = 2,     /* seed 002 Eq. 26 exactly: Ergun for eps <= 0.8, Wen-Yu above */
    FSDEM_DRAG_LAW_GIDASPOW = 3,         /* Ergun and Wen-Yu joined by the smooth blend of Huilin and Gidaspow (2003) */
    FSDEM_DRAG_LAW_DI_FELICE = 4,        /* Di Felice (1994) */
    FSDEM_DRAG_LAW_BEETSTRA = 5          /* Beetstra, van der Hoef and Kuipers (2007) */
} fsdem_drag_law;

/* Coefficient of the drag on one particle: F = c V (u - v) as above. Writes c (kg m^-3 s^-1) to
   *per_volume and beta = c (1 - eps) to *beta; either pointer may be NULL. porosity in (0, 1],
   diameter > 0 (m), slip_speed = |u - v| in [0, FSDEM_MAX_SPEED] (m/s), density rho_f > 0 (kg/m^3),
   viscosity mu_f > 0 (dynamic, Pa s), all finite, and a known law; otherwise FSDEM_ERR_INVALID_ARG,
   nothing written, and `message` (may be NULL) names the argument. Every law is finite for any
   Reynolds number; FSDEM_ERR_NAN (nothing written, the message gives porosity, d and Re) only where
   c itself exceeds the largest fsdem_real (a vanishing diameter or porosity). */
FSDEM_API fsdem_result fsdem_drag_coefficient(fsdem_drag_law law, fsdem_real porosity, fsdem_real diameter,
                                              fsdem_real slip_speed, fsdem_real density, fsdem_real viscosity,
                                              fsdem_real *per_volume, fsdem_real *beta, char *message,
                                              size_t message_size);

/* Name of a law ("ergun_wen_yu", ...), "unknown" for other values. Never NULL. */
FSDEM_API const char *fsdem_drag_law_name(fsdem_drag_law law);

/* ===== >>couple_mps : unresolved MPS-DEM, Models A and B (seed 002) ================================ */

/* Two-way coupling of MPS water (fsdem_mps) with DEM sediment (fsdem_dem) by local averaging, after
   seed 002 §2.1-2.4. The DEM particles are smaller than the MPS spacing (unresolved): the water sees
   them through a porosity field and a momentum exchange, computed with the weight
       w_s(r) = 4 (r/r_e)^5 - 5 (r/r_e)^4 + 1 for r < r_e, 0 beyond               (Eq. 29)
   whose integral over space is n_s = (10 pi / 21) r_e^3 in 3D (Eq. 30) and, by the same integral
   over the plane (int_0^1 (4x^5 - 5x^4 + 1) 2 pi x dx = 2 pi (4/7 - 5/6 + 1/2)), n_s = (10 pi / 21)
   r_e^2 in 2D, where volumes are areas per unit depth (a disc of radius R stands for pi R^2).
   Every coupled step:
     1. porosity of the FLUID particles, eps_i = 1 - sum_k w_s(r_ik) V_k / n_s (Eq. 31), not let
        below desc.min_porosity; written to the MPS (its Eq. 7-16 use 1/eps_j). WALL and DUMMY
        particles keep eps = 1: they sit on the fixed r0 lattice, so a 1/eps on them would count
        them more than once in the number density of their neighbours and read a bed on the floor
        as compressed (the bottom pressure of a settled bed came out twice hydrostatic).
        Within r_e of a wall or obstacle n_s is reduced by the part of the weight's integral that
        lies inside the solid (the sum of w_s r0^d over its WALL and DUMMY particles): Eq. 31 as
        printed reads a bed packed against a wall as looser there (not done at the free surface);
     2. at each DEM particle k, over the FLUID particles i within r_e: porosity eps_k (Eq. 32), fluid
        velocity u_k (Eq. 33), and for Model A the pressure gradient grad P_k, the same w_s average
        of the gradients the MPS corrector applied to those particles;
     3. drag F^d = c V_k (u_k - v_k) with c = beta/(1 - eps) of the chosen law (>>drag; Eq. 25-28
        with FSDEM_DRAG_LAW_ERGUN_WEN_YU) and the force on the particle (held over the DEM substeps):
          Model A (the MPS desc.model):  F^int = F^d - V_k grad P_k            (Eq. 34)
          Model B:                       F^int = F^d / eps_k - V_k rho_f g     (Eq. 35);
     4. the reaction on the fluid (Eq. 36): FLUID particle i gets -sum_k X_k w_s(r_ki) / W_k with
        W_k = sum_j w_s(r_kj) over the FLUID particles j, where X_k is the force that the fluid and
        the solid exchange: F^d (Model A, Eq. 2: the solid's -V grad P is the mixture pressure acting
        on the solid's volume, as -grad P on its own volume acts on each fluid particle) or F^int
        (Model B, Eq. 4: f_B). Each X_k is split into weights that sum to one, so the fluid gets
        exactly -sum_k X_k: the exchange conserves momentum to rounding. Limitation: next to a wall
        the kernel is cut, and in a uniform suspension the water within r0 of a wall gets 0.5-0.7
        of the bulk's reaction per volume (0.9-1.1 at 2-4 r0), which drives a circulation along the
        walls (validation/mpsdem_settling); weighting the shares by the open part of each
        particle's kernel evened it to 0.9-1.2 but over-pushed edges and corners and reversed the
        cell, so Eq. 36 is kept as printed;
     5. one MPS step of dt, then the DEM over the same dt in K = fsdem_dem_substep_count substeps
        (fsdem_dem_advance) with the forces of 3 held: the sequential staggered scheme with the
        MPS step of Eq. 37 and DEM steps of Eq. 38 (Sun et al. 2021's MSS as the seed uses it; here
        the forces are held, not interpolated, over the substeps).
   The MPS particle velocity is the intrinsic fluid velocity u_f and each MPS particle carries the
   fluid mass rho_f r0^d: in a porous region it stands for a volume of mixture r0^d / eps, which is
   what the 1/eps_j of Eq. 7 counts (so the particles spread where solids are). Eq. 2 and 4 are the
   momentum of that volume; their D eps / Dt terms (u_d = eps u_f, eps changing along the path) are
   not included.
   Held forces are explicit: a step longer than the drag relaxation time of a particle, m_k /
   (c V_k) (with Model B's 1/eps_k), would overshoot, so the coupled stable step is also at most
   desc.drag_dt_fraction of the shortest one. Virtual mass, lift and lubrication forces are not
   included (the seed leaves them out, §2.3).
   Loads on a structure come in the seed's two parts (Fig. 18-19): the fluid's, the pressure on a
   box obstacle of the MPS (fsdem_mps_obstacle_force), and the sediment's, the contact force on a
   DEM wall at the same place (fsdem_dem_wall_force); validation/mpsdem_obstacle records both. */

typedef struct fsdem_mps_dem fsdem_mps_dem;

typedef struct fsdem_mps_dem_desc {
    fsdem_mps *mps;               /* water; not owned; must outlive the coupler */
    fsdem_dem *dem;               /* sediment; same dim and gravity as the MPS; not owned */
    fsdem_drag_law drag;          /* default FSDEM_DRAG_LAW_ERGUN_WEN_YU (seed 002 Eq. 26) */
    fsdem_real radius;            /* m; r_e of w_s (Eq. 29); 0: the MPS re (4.1 r0 by default), */
                                  /*    which the seed's text implies; default 0 */
    fsdem_real min_porosity;      /* -; floor of eps_i (Eq. 31 can go below 0 where DEM particles */
                                  /*    overlap in a kernel), in (0, 1); default 0.2 */
    fsdem_real drag_dt_fraction;  /* -; coupled step <= this fraction of the shortest drag */
                                  /*    relaxation time, in (0, 1]; default 0.5 */
    long long max_substeps;       /* DEM substeps one coupled step may take; a longer step is */
                                  /*    refused before anything moves; default 100000 */
    fsdem_log_fn log;             /* optional; default NULL */
    void *log_user;
} fsdem_mps_dem_desc;

FSDEM_API fsdem_mps_dem_desc fsdem_mps_dem_desc_default(void);
/* Checks a desc: both solvers set, the same dim and gravity, the ranges above. FSDEM_OK or
   FSDEM_ERR_INVALID_ARG with the reason, naming the field, in `message` (may be NULL). */
FSDEM_API fsdem_result fsdem_mps_dem_desc_check(const fsdem_mps_dem_desc *desc, char *message, size_t message_size);
/* Creates a coupler (its memory from the DEM's allocator). FSDEM_ERR_INVALID_ARG as the check
   (the reason also goes to desc->log), FSDEM_ERR_OUT_OF_MEMORY. fsdem_mps_dem_destroy leaves the
   solvers alive. */
FSDEM_API fsdem_result fsdem_mps_dem_create(const fsdem_mps_dem_desc *desc, fsdem_mps_dem **out);
FSDEM_API void fsdem_mps_dem_destroy(fsdem_mps_dem *coupler);
FSDEM_API const char *fsdem_mps_dem_last_error(const fsdem_mps_dem *coupler);
/* The desc in force (radius resolved). */
FSDEM_API fsdem_mps_dem_desc fsdem_mps_dem_get_desc(const fsdem_mps_dem *coupler);

/* Fluid state and forces at one DEM particle, from the last update. */
typedef struct fsdem_mps_dem_force {
    int id;                       /* stable id of the DEM particle (fsdem_dem_particles.id) */
    fsdem_vec3 drag;              /* N; F^d of Eq. 25 */
    fsdem_vec3 pressure;          /* N; -V grad P (Model A, Eq. 34) or -V rho_f g (Model B, Eq. 35) */
    fsdem_vec3 total;             /* N; F^int, the external force the DEM particle is given */
    fsdem_vec3 fluid_velocity;    /* m/s; u_k of Eq. 33 */
    fsdem_real porosity;          /* -; eps_k of Eq. 32 (1 when dry) */
    fsdem_real reynolds;          /* -; Eq. 28 */
    int wet;                      /* 1 when FLUID particles are within the radius (else no force) */
} fsdem_mps_dem_force;

/* Steps 1-4 of the section at the current state: porosities into the MPS, forces into the DEM's
   external loads and the reactions into the MPS's coupling forces. A step does it first; call it to
   see the fields without stepping. FSDEM_ERR_OUT_OF_MEMORY (nothing changed), FSDEM_ERR_NAN (a
   force is not finite; the particle is named). */
FSDEM_API fsdem_result fsdem_mps_dem_update(fsdem_mps_dem *coupler);
/* Forces on DEM particle `index` from the last update, found by the particle's id, so removals
   since do not mix the records up. FSDEM_ERR_NOT_FOUND for a bad index, before the first update, or
   for a particle added since. */
FSDEM_API fsdem_result fsdem_mps_dem_get_force(const fsdem_mps_dem *coupler, int index, fsdem_mps_dem_force *out);
/* One coupled step of the stable dt (fsdem_mps_dem_stable_dt after the update). The DEM substep
   count is checked before anything moves (FSDEM_ERR_INVALID_ARG above max_substeps). Errors of
   either solver are passed on with their message. */
FSDEM_API fsdem_result fsdem_mps_dem_step(fsdem_mps_dem *coupler);
/* One coupled step of exactly dt (s): FSDEM_ERR_CFL, nothing moved, when dt exceeds the MPS CFL
   step (Eq. 37) or the drag limit of the section. */
FSDEM_API fsdem_result fsdem_mps_dem_step_dt(fsdem_mps_dem *coupler, fsdem_real dt);
/* Coupled steps until exactly `duration` (s) later; their number goes to *steps (may be NULL). */
FSDEM_API fsdem_result fsdem_mps_dem_advance(fsdem_mps_dem *coupler, fsdem_real duration, long long *steps);
/* Stable coupled step (s): the MPS's (Eq. 37) and the drag limit of the last update. */
FSDEM_API fsdem_result fsdem_mps_dem_stable_dt(const fsdem_mps_dem *coupler, fsdem_real *dt);
/* The MPS time (s). */
FSDEM_API double fsdem_mps_dem_time(const fsdem_mps_dem *coupler);

typedef struct fsdem_mps_dem_stats {
    long long steps;              /* coupled steps */
    double time;                  /* s */
    fsdem_real dt;                /* s, the last coupled step */
    long long substeps;           /* DEM substeps of the last coupled step */
    long long substeps_total;
    int wet;                      /* DEM particles in water at the last update */
    fsdem_vec3 drag;              /* N; sum of F^d, last update */
    fsdem_vec3 pressure;          /* N; sum of the pressure parts (-V grad P or -V rho g) */
    fsdem_vec3 to_fluid;          /* N; sum of the reactions given to the fluid (= -sum X_k) */
    fsdem_real drag_dt;           /* s; the drag limit of the last update (0: none) */
    long long pairs;              /* DEM-MPS pairs within the radius, last update */
    double seconds_mps;           /* CPU seconds in MPS steps */
    double seconds_dem;           /* CPU seconds in DEM substeps and the coupling (updates) */
} fsdem_mps_dem_stats;

FSDEM_API fsdem_mps_dem_stats fsdem_mps_dem_get_stats(const fsdem_mps_dem *coupler);

/* ===== >>couple_pic : resolved cut-cell PIC-DEM (seed 000) ========================================= */

/* Two-way coupling of PIC/FLIP water (fsdem_pic) with DEM discs (2D) or spheres (3D) (fsdem_dem)
   that the water sees at their true shape, after seed 000 §2. Every coupled step of dt:
     1. predicted body velocities Q* = (V*, w*) = Q^n + dt M^-1 (F_g + F_collision^n): gravity and
        the contact forces of the DEM's last step (Eq. 6, with the collisions at time n as the seed's
        prediction; fixed DEM particles keep their velocity);
     2. each body becomes a moving cut-cell solid of the PIC (fsdem_pic_get_coupling): for every
        face near it the closed fraction 1 - E_b from its exact signed distance (sampled as the
        static obstacles are), and on the face the solid velocity V* + w* x (x_f - X_b). Bodies do
        not overlap (the gap below), so on a face shared by two the closed parts add and the solid
        velocity is their closed-fraction-weighted mean: the solid flux is exact. The cells whose
        fluid-fraction kernel a body covers get the reference that keeps them full;
     3. the implicit solid velocity of Eq. 5-6: the solid flux of cell c, J_c . Q / dx with
        J_c = sum over c's faces of s (1 - E_b) [e_a, (x_f - X_b) x e_a] (s = +1 on the upper face,
        -1 on the lower), enters the pressure equation with Q^{n+1} = Q* + dt M^-1 G, where
        G = dx^(dim-1) sum_c p_c J_c is the pressure force and torque. This adds the symmetric
        positive semi-definite term rho dx^dim J M^-1 J^T p to the operator (fsdem_pic_set_pressure
        _extra), so the pressure and the body velocities are solved together: no added-mass
        instability however light the body. G is the discrete adjoint of the solid flux: the
        pressure's power on the bodies equals minus the power it spends on the water they
        displace, and in hydrostatic water G = rho g dx^dim sum (1 - E) over the faces normal to
        gravity, the body volume as the faces see it;
     4. one PIC step; then the fluid force on each body is G from the step's pressure plus the
        viscous force, the momentum the implicit viscous solve gave the closed faces of the body
        (fsdem_pic_coupling.shear), with their moments about the centre. The water loses exactly
        what the bodies gain (both are the same face sums), so momentum is conserved to the solver
        tolerance. The viscous force is explicit in the body velocity: the step is limited to
        desc.viscous_dt_fraction of a body's viscous relaxation time;
     5. the DEM over dt in K = INT(dt/dt_DEM) substeps (Eq. 25, fsdem_dem_advance) with the fluid
        force and torque held: with the DEM's predictor-corrector integrator these are Eq. 21-24,
        except that the fluid impulse is spread evenly over the substeps instead of given at the
        start (the same end velocity; positions differ by O(dt^2 F/m));
     6. the gap (§2.2.2): the DEM's contact_offset is the imaginary boundary of Eq. 19 (the seed
        uses 2 dx), so contacts start before the real surfaces meet and a gap of open cells stays
        between them. In the contact area of every contact (centred on the middle of the gap, of
        length desc.contact_length along the tangent, 4 dx in the seed, and as wide along the normal:
        a square in 2D, a short cylinder in 3D) the water particles' velocities are multiplied by C
        (Eq. 20), linear in the distance t from the contact point along the tangent: desc.dissipation
        (beta) at the point, 1 at the area's edge (C = beta + (1 - beta) 2 t / length); beta = 1
        switches it off. The seed gives the area's length, not its width; the width is a choice;
     7. the water particles inside a body at its new position are moved to its surface
        (fsdem_pic_exclude_particles); the density projection of later steps spreads them. On
        creation, and when bodies are added, the particles inside the new bodies are removed;
     8. well-balanced weight (desc.discrete_weight): in still water the pressure force is exactly
        rho g V_g, V_g = dx^dim sum (1 - E) over the faces normal to gravity, the body's volume as
        the grid sees it; that midpoint rule over cross-sections differs from the exact volume V by
        O(dx^1.5) (2D, -1.2% to +0.3% at 10 cells per radius as the centre moves through a cell),
        enough to make a body of the water's density sink or rise. So the body's weight is taken on
        the same volume: gravity m g V_g / V, the DEM's m g plus m g (V_g / V - 1) given as an
        external force (in Q* too). Bodies of the water's density are then in exact balance and
        floating drafts are exact on the grid; the exchange with the water is not touched.
   Forces are per unit depth in the 2D PIC; the DEM's discs of length disc_length receive them
   times that length. Contacts with domain walls are the DEM's walls (add them to the DEM).
   Next to moving bodies two PIC statistics do not mean what they mean elsewhere: max_divergence
   takes the solid flux of the predicted velocity Q*, not of the end velocity the pressure was solved
   with, and fluid_volume counts cut cells whole; particle_volume is the water volume. A dam break
   from rest wants fsdem_pic_desc.dt_max well below sqrt(dx / g): the PIC's step estimate does not
   foresee the impulsive start, and its CFL check would end the first step. */

typedef struct fsdem_pic_dem fsdem_pic_dem;

typedef struct fsdem_pic_dem_desc {
    fsdem_pic *pic;                /* water; not owned; must outlive the coupler */
    fsdem_dem *dem;                /* bodies; same dim and gravity as the PIC; not owned; its */
                                   /*    contact_offset is the imaginary boundary (Eq. 19) */
    fsdem_real dissipation;        /* -; beta of Eq. 20 in [0, 1]; 1 switches it off; default 0.5 */
    fsdem_real contact_length;     /* m; side of the contact area of Eq. 20; 0: 4 dx; default 0 */
    fsdem_real viscous_dt_fraction; /* -; coupled step <= this fraction of the shortest viscous */
                                   /*    relaxation time of a body, in (0, 1]; default 0.5 */
    int discrete_weight;           /* 1: gravity acts on a body through its volume as the grid sees */
                                   /*    it (item 8 above); 0: the DEM's m g; default 1 */
    long long max_substeps;        /* DEM substeps one coupled step may take; a longer step is */
                                   /*    refused before anything moves; default 100000 */
    fsdem_log_fn log;              /* optional; default NULL */
    void *log_user;
} fsdem_pic_dem_desc;

FSDEM_API fsdem_pic_dem_desc fsdem_pic_dem_desc_default(void);
/* Checks a desc: both solvers set, the same dim and gravity, the ranges above. FSDEM_OK or
   FSDEM_ERR_INVALID_ARG with the reason, naming the field, in `message` (may be NULL). */
FSDEM_API fsdem_result fsdem_pic_dem_desc_check(const fsdem_pic_dem_desc *desc, char *message, size_t message_size);
/* Creates a coupler (its memory from the DEM's allocator), removes the water particles inside the
   bodies and installs the implicit term in the PIC's pressure operator. FSDEM_ERR_INVALID_ARG as
   the check (the reason also goes to desc->log), FSDEM_ERR_OUT_OF_MEMORY. fsdem_pic_dem_destroy
   removes the term and the moving solids from the PIC and leaves both solvers alive. The coupler
   owns the PIC's open, solid_velocity and reference arrays (fsdem_pic_get_coupling): every step
   resets and rewrites them. */
FSDEM_API fsdem_result fsdem_pic_dem_create(const fsdem_pic_dem_desc *desc, fsdem_pic_dem **out);
FSDEM_API void fsdem_pic_dem_destroy(fsdem_pic_dem *coupler);
FSDEM_API const char *fsdem_pic_dem_last_error(const fsdem_pic_dem *coupler);
/* The desc in force (contact_length resolved). */
FSDEM_API fsdem_pic_dem_desc fsdem_pic_dem_get_desc(const fsdem_pic_dem *coupler);

/* The fluid's load on one body in the last coupled step (whole body: N and N m, the 2D PIC's per
   metre values times disc_length). */
typedef struct fsdem_pic_dem_force {
    int id;                      /* stable id of the DEM particle (fsdem_dem_particles.id) */
    fsdem_vec3 pressure_force;   /* N; G of step 3 */
    fsdem_vec3 viscous_force;    /* N; step 4 */
    fsdem_vec3 torque;           /* N m; pressure and viscous, about the centre */
    fsdem_vec3 weight_correction; /* N; m g (V_g / V - 1) with desc.discrete_weight (item 8), else 0 */
    fsdem_real volume;           /* m^3; V_g, the body volume the faces normal to gravity see (item */
                                 /*    8; per metre in 2D) */
    int faces;                   /* faces the body covers or cuts */
} fsdem_pic_dem_force;

/* Load on DEM particle `index` from the last step, found by the particle's id, so removals since do
   not mix the records up. FSDEM_ERR_NOT_FOUND for a bad index, before the first step, or for a
   particle added since. */
FSDEM_API fsdem_result fsdem_pic_dem_get_force(const fsdem_pic_dem *coupler, int index, fsdem_pic_dem_force *out);
/* One coupled step of the stable dt. The DEM substep count is checked before anything moves
   (FSDEM_ERR_INVALID_ARG above max_substeps). Errors of either solver are passed on with their
   message. */
FSDEM_API fsdem_result fsdem_pic_dem_step(fsdem_pic_dem *coupler);
/* One coupled step of exactly dt (s): FSDEM_ERR_INVALID_ARG for dt <= 0 or not finite, FSDEM_ERR_CFL
   when dt exceeds the PIC's cfl_max, a body would move more than cfl_max cells or dt exceeds the
   viscous limit; nothing moved then. */
FSDEM_API fsdem_result fsdem_pic_dem_step_dt(fsdem_pic_dem *coupler, fsdem_real dt);
/* Coupled steps until exactly `duration` (s) later; their number goes to *steps (may be NULL). */
FSDEM_API fsdem_result fsdem_pic_dem_advance(fsdem_pic_dem *coupler, fsdem_real duration, long long *steps);
/* Stable coupled step (s): the PIC's, the bodies' speed over the PIC's cfl (cfl dx / (|V| + |w| r +
   sqrt(|g| dx))) and the viscous limit. FSDEM_ERR_NAN when a velocity is not finite. */
FSDEM_API fsdem_result fsdem_pic_dem_stable_dt(const fsdem_pic_dem *coupler, fsdem_real *dt);
/* The PIC time (s). */
FSDEM_API double fsdem_pic_dem_time(const fsdem_pic_dem *coupler);

typedef struct fsdem_pic_dem_stats {
    long long steps;             /* coupled steps */
    double time;                 /* s */
    fsdem_real dt;               /* s, the last coupled step */
    long long substeps;          /* DEM substeps of the last step */
    long long substeps_total;
    fsdem_vec3 fluid_force;      /* N; sum of the fluid forces on the bodies, last step */
    fsdem_real viscous_dt;       /* s; the viscous limit of the last step (0: none) */
    int contacts;                /* contacts (gap areas) after the last step */
    long long dissipated;        /* particle velocities scaled by Eq. 20, total */
    long long pushed;            /* particles moved out of bodies, total */
    long long removed;           /* particles removed inside new bodies, total */
    double seconds_pic;          /* CPU seconds in PIC steps */
    double seconds_dem;          /* CPU seconds in DEM substeps */
    double seconds_coupling;     /* CPU seconds in the coupling (faces, forces, gap, exclusion) */
} fsdem_pic_dem_stats;

FSDEM_API fsdem_pic_dem_stats fsdem_pic_dem_get_stats(const fsdem_pic_dem *coupler);

/* ===== >>restart : checkpoint and restart ========================================================= */

/* Saves the complete state of a solver or coupler to a file or to memory, and restores it, so that
   a run continued from a restored state is the uninterrupted run bit for bit. The format is for the
   same build: the precision of fsdem_real and the byte order are recorded and a mismatch is refused.

   Use: fsdem_dem_save(dem, "run.chk") now and then; to go on later, fsdem_dem_create(&desc, &dem)
   with the desc of the run, add its SDF walls again (below), fsdem_dem_restore(dem, "run.chk"), and
   step on.

   Model. Create the object from the desc it was saved with (the allocator, log and callbacks are
   yours), then restore the state into it. What can change after creation comes from the save and
   replaces what the object holds:
     fsdem_dem      materials with their pair tables, walls (positions, velocities, forces, impulses), particles (ids,
                    kinematics, the contact forces of the last evaluation, external loads), the
                    neighbour lists with their tangential springs, dt, time, counters;
     fsdem_pic      particles (APIC matrices too) and their capacity, the random-number state,
                    obstacles and their face fractions, the grid fields that views and the next
                    step read (face velocities, pressure, level set, fractions, cell types), the
                    coupling arrays, time, counters;
     fsdem_swe      surface and discharges, bed, per-cell Manning, rain, boundaries with their
                    series, point sources, gauge positions, momentum sources, time, counters;
     fsdem_swe_dem  the states of its fsdem_swe and fsdem_dem, restored into the solvers it was
                    created with, and its own counters and per-particle force records (one file
                    holds the coupled run);
     fsdem_mps      particles of every kind (positions, velocities, pressures, porosities, kinds,
                    obstacle membership, and the number density and surface flags of the last
                    step) and their capacity, obstacles with their last forces, time, counters
                    (the pressure matrix of the last step is not kept: fsdem_mps_pressure_matrix
                    is empty until the next step);
     fsdem_mps_dem  the states of its fsdem_mps and fsdem_dem, restored into the solvers it was
                    created with, and its own counters and per-particle force records;
     fsdem_pic_dem  the states of its fsdem_pic and fsdem_dem, restored into the solvers it was
                    created with, and its own counters and per-body load records.
   What must match (else FSDEM_ERR_INVALID_ARG naming the field): the desc fields that steps read.
   DEM: dim, domain, gravity, law, integrator, dt_rule, dt_param, skin, contact_offset, linear_*,
   disc_length, rotation, the contact options (tangential_*, coulomb_limit), periodic. PIC: the grid (cells per axis), dim, domain_min, cell_size, density,
   viscosity, gravity, boundaries, transfer, kernel, seeding and reseeding, advection, cfl,
   dt_max, ghost-fluid, extrapolation and solver settings. SWE: dim, nx, ny, extent, width,
   gravity, density, cfl, dt_max, order, limiter, dry_depth, manning, eddy_viscosity. Coupler:
   beta, two_way, heave_damping, max_substeps (and its solvers' fields above). MPS: every field of
   fsdem_mps_desc but the allocator and log (re as resolved). Not compared:
   allocator, log, DEM dt and capacity, PIC seed and max_memory, SWE rain_rate, boundary, bed and
   depth (all restored or irrelevant once the state is restored).
   Callbacks cannot be saved. An SDF wall (DEM) or SDF obstacle (PIC) of the save takes the
   callback of the object's wall or obstacle with the same index, which must be of that type: add
   them again, in the same order, before restoring. A pressure-extra operator
   (fsdem_pic_set_pressure_extra) stays as set on the object.
   Not restored: the SWE gauge file (restore refuses while one is open; open it again afterwards,
   its rows then start at the restored time), CPU-time figures of the statistics, last_error.
   The DEM's views and coupling arrays and the PIC's particle views obtained before a restore may
   be invalid after it (take them again); the PIC's grid and coupling arrays and the SWE's fields
   and coupling arrays stay where they are.

   Errors. Save: FSDEM_ERR_IO (the file cannot be written), FSDEM_ERR_INVALID_ARG (a NULL argument;
   a buffer too small, *size then holding the size needed), FSDEM_ERR_OUT_OF_MEMORY. Restore:
   FSDEM_ERR_IO (the file cannot be opened or read), FSDEM_ERR_INVALID_ARG (truncated or corrupted
   data, another format version, precision, byte order, dimension or object kind, or a desc that
   differs; the message says which), FSDEM_ERR_OUT_OF_MEMORY. A failed restore leaves the object
   exactly as it was: everything is validated and allocated before anything changes. A restore
   needs memory for the file's contents and for the parts it replaces while both are held. A file
   is written in place: one cut short by a crash is refused by its checksum, so alternate between
   two paths to always keep a good checkpoint.

   Format (version 2): a 64-byte header, then the payload.
     offset  bytes  field
          0      8  magic "FSDEMRST"
          8      4  format version (unsigned)
         12      4  byte-order mark 0x01020304 as the saving machine stores it
         16      4  precision: sizeof(fsdem_real), 4 (FSDEM_USE_FLOAT) or 8
         20      4  object kind: 1 fsdem_dem, 2 fsdem_pic, 3 fsdem_swe, 4 fsdem_swe_dem, 5 fsdem_mps,
                    6 fsdem_mps_dem, 7 fsdem_pic_dem
         24      4  dimension of the object (the SWE's for fsdem_swe_dem)
         28      4  reserved (0)
         32     16  four sizes (int) for tools: DEM particles, materials, walls, pair-list entries;
                    PIC cells along x, y, z and particles; SWE nx, ny, point sources, gauges;
                    SWE-DEM nx, ny, DEM particles, force records; MPS particles, FLUID
                    particles, obstacles, 0; MPS-DEM MPS particles, DEM particles, force records, 0;
                    PIC-DEM PIC particles, DEM particles, body load records, 0
         48      8  payload bytes (unsigned)
         56      8  checksum: 64-bit FNV-1a over bytes 0 to 55 and the payload
   The payload holds tagged sections of integers and reals as the saving machine stores them. */

/* Saves the state to the file `path` (created or replaced). Errors above. */
FSDEM_API fsdem_result fsdem_dem_save(const fsdem_dem *dem, const char *path);
/* Restores the state saved in the file `path` into `dem`. Errors above. */
FSDEM_API fsdem_result fsdem_dem_restore(fsdem_dem *dem, const char *path);
/* Saves the state to `buffer` (`capacity` bytes); *size gets the bytes written, or with a NULL
   buffer the bytes needed (nothing is written). */
FSDEM_API fsdem_result fsdem_dem_save_memory(const fsdem_dem *dem, void *buffer, size_t capacity, size_t *size);
/* Restores the state held in `buffer` (`size` bytes, as fsdem_dem_save_memory wrote them). */
FSDEM_API fsdem_result fsdem_dem_restore_memory(fsdem_dem *dem, const void *buffer, size_t size);

/* The same four for the PIC/FLIP solver. */
FSDEM_API fsdem_result fsdem_pic_save(const fsdem_pic *pic, const char *path);
FSDEM_API fsdem_result fsdem_pic_restore(fsdem_pic *pic, const char *path);
FSDEM_API fsdem_result fsdem_pic_save_memory(const fsdem_pic *pic, void *buffer, size_t capacity, size_t *size);
FSDEM_API fsdem_result fsdem_pic_restore_memory(fsdem_pic *pic, const void *buffer, size_t size);

/* The same four for the shallow-water solver. */
FSDEM_API fsdem_result fsdem_swe_save(const fsdem_swe *swe, const char *path);
FSDEM_API fsdem_result fsdem_swe_restore(fsdem_swe *swe, const char *path);
FSDEM_API fsdem_result fsdem_swe_save_memory(const fsdem_swe *swe, void *buffer, size_t capacity, size_t *size);
FSDEM_API fsdem_result fsdem_swe_restore_memory(fsdem_swe *swe, const void *buffer, size_t size);

/* The same four for the SWE-DEM coupler: its solvers' states are saved and restored with it. */
FSDEM_API fsdem_result fsdem_swe_dem_save(const fsdem_swe_dem *coupler, const char *path);
FSDEM_API fsdem_result fsdem_swe_dem_restore(fsdem_swe_dem *coupler, const char *path);
FSDEM_API fsdem_result fsdem_swe_dem_save_memory(const fsdem_swe_dem *coupler, void *buffer, size_t capacity,
                                                 size_t *size);
FSDEM_API fsdem_result fsdem_swe_dem_restore_memory(fsdem_swe_dem *coupler, const void *buffer, size_t size);

/* The same four for the MPS solver. */
FSDEM_API fsdem_result fsdem_mps_save(const fsdem_mps *mps, const char *path);
FSDEM_API fsdem_result fsdem_mps_restore(fsdem_mps *mps, const char *path);
FSDEM_API fsdem_result fsdem_mps_save_memory(const fsdem_mps *mps, void *buffer, size_t capacity, size_t *size);
FSDEM_API fsdem_result fsdem_mps_restore_memory(fsdem_mps *mps, const void *buffer, size_t size);

/* The same four for the MPS-DEM coupler: its solvers' states are saved and restored with it. */
FSDEM_API fsdem_result fsdem_mps_dem_save(const fsdem_mps_dem *coupler, const char *path);
FSDEM_API fsdem_result fsdem_mps_dem_restore(fsdem_mps_dem *coupler, const char *path);
FSDEM_API fsdem_result fsdem_mps_dem_save_memory(const fsdem_mps_dem *coupler, void *buffer, size_t capacity,
                                                 size_t *size);
FSDEM_API fsdem_result fsdem_mps_dem_restore_memory(fsdem_mps_dem *coupler, const void *buffer, size_t size);

/* The same four for the PIC-DEM coupler: its solvers' states are saved and restored with it. */
FSDEM_API fsdem_result fsdem_pic_dem_save(const fsdem_pic_dem *coupler, const char *path);
FSDEM_API fsdem_result fsdem_pic_dem_restore(fsdem_pic_dem *coupler, const char *path);
FSDEM_API fsdem_result fsdem_pic_dem_save_memory(const fsdem_pic_dem *coupler, void *buffer, size_t capacity,
                                                 size_t *size);
FSDEM_API fsdem_result fsdem_pic_dem_restore_memory(fsdem_pic_dem *coupler, const void *buffer, size_t size);

/* ===== >>io : CSV time series, ParaView series, VTK XML snapshots ================================== */

/* A CSV time series: a header row, then one row of numbers per call. Owned by the caller. */
typedef struct fsdem_csv {
    void *file; /* FILE*, NULL when closed */
    int columns;
} fsdem_csv;

/* Opens `path` for writing and writes `header` (comma-separated names, e.g. "t,x_ave,z_ave").
   FSDEM_ERR_IO when the file cannot be opened; FSDEM_ERR_INVALID_ARG for an empty header. */
FSDEM_API fsdem_result fsdem_csv_open(fsdem_csv *csv, const char *path, const char *header);
/* Writes one row; `count` must equal the number of header columns. */
FSDEM_API fsdem_result fsdem_csv_row(fsdem_csv *csv, const fsdem_real *values, int count);
FSDEM_API fsdem_result fsdem_csv_close(fsdem_csv *csv);

/* ---- VTK XML snapshots ----

   Every VTK file the library writes is a serial VTK XML file that VTK (>= 6) and ParaView read
   completely: PolyData (.vtp) for particles, walls and contacts, ImageData (.vti) for grids. The
   root element is <VTKFile type="PolyData|ImageData" version="1.0" byte_order="LittleEndian" (or
   "BigEndian": the machine's own order, in which every binary number is written)
   header_type="UInt64">. The dataset element holds <FieldData> with "TimeValue" (Float64, one
   tuple: the object's time in s), then one <Piece>. Arrays are Float64 (Float32 with
   FSDEM_USE_FLOAT), Int32 or UInt8, of 1 or 3 components; a 3-component array is stored tuple by
   tuple (x0 y0 z0 x1 y1 z1 ...). Polygonal cells are described by Int32 "connectivity" and
   "offsets" arrays; cell data follow the cell order of VTK PolyData (Verts, Lines, Strips, Polys).
   How the numbers are stored is the caller's choice, the last argument of every VTK writer: */
typedef enum fsdem_vtk_format {
    /* format="ascii": decimal text, 17 significant digits for Float64 and 9 for Float32, which
       read back to the same bits; the largest files, readable in an editor. A NaN or infinite
       value is written as nan/inf, which VTK's ascii parser stops at: look at a failed state in a
       binary format. */
    FSDEM_VTK_FORMAT_ASCII = 0,
    /* format="binary": inline base64 (RFC 4648 alphabet, '=' padding, no line breaks). Each array
       is one base64 stream of a UInt64 byte count (the number of data bytes that follow, not
       counting itself) followed by the data, as VTK's own writer encodes uncompressed data (it
       encodes the header separately only in compressed files; VTK 9.1's reader takes either).
       Exact, 4/3 of the raw size, and the file is well-formed XML. */
    FSDEM_VTK_FORMAT_BASE64 = 1,
    /* format="appended": each <DataArray> carries offset="N" and no content; after the dataset,
       <AppendedData encoding="raw"> holds '_' and then, array after array in the order of the
       file, a UInt64 byte count and the raw bytes. N counts bytes from the first byte after the
       '_' to the array's count. Exact, the smallest and fastest to write and read; the raw bytes
       make the file not well-formed XML, as VTK's reader expects of appended raw data. */
    FSDEM_VTK_FORMAT_APPENDED = 2
} fsdem_vtk_format;

/* A ParaView time series (.pvd collection): open, add one entry per written file, close. The file
   is complete, valid XML after open and after every add (the closing tags are rewritten after each
   entry and the file is flushed), so a run that is still going, was killed or crashed leaves a
   series ParaView can open. Owned by the caller. */
typedef struct fsdem_pvd {
    void *file;     /* FILE*, NULL when closed */
    long tail;      /* file position of the closing tags, overwritten by the next add */
    int count;      /* entries added */
} fsdem_pvd;

/* Creates (truncates) `path` and writes an empty collection. FSDEM_ERR_INVALID_ARG for NULL
   arguments, FSDEM_ERR_IO when the file cannot be written or is not seekable (a pipe). */
FSDEM_API fsdem_result fsdem_pvd_open(fsdem_pvd *pvd, const char *path);
/* Adds the piece `file` (its name as seen from the .pvd's folder) at `time` (s). The piece must be a
   VTK XML file by its extension: .vtp, .vtu, .vti, .vts or .vtr; a legacy .vtk file, which
   ParaView's series reader cannot take, any other name, a name with a control character, and a
   NaN or infinite time are refused with FSDEM_ERR_INVALID_ARG (the file is unchanged). The
   characters & < > " ' in the name are written as XML entities, so the name (UTF-8) reads back as
   given. The time is written with 17 significant digits. FSDEM_ERR_IO on a write error. */
FSDEM_API fsdem_result fsdem_pvd_add(fsdem_pvd *pvd, double time, const char *file);
/* Closes the file (it is already complete). FSDEM_ERR_IO, FSDEM_ERR_INVALID_ARG (not open). */
FSDEM_API fsdem_result fsdem_pvd_close(fsdem_pvd *pvd);

/* Common to the writers below: `path` is created or truncated; the object is not changed (its
   last_error names the path on failure). FSDEM_ERR_INVALID_ARG for a NULL object or path or a
   `format` that is not a fsdem_vtk_format, FSDEM_ERR_IO when the file cannot be opened or written,
   FSDEM_ERR_OUT_OF_MEMORY where a writer needs scratch memory (walls, contacts). */

/* DEM particle snapshot as CSV: id,x,y,z,vx,vy,vz,wx,wy,wz,radius,material. FSDEM_ERR_IO,
   FSDEM_ERR_INVALID_ARG (NULL). */
FSDEM_API fsdem_result fsdem_dem_write_csv(const fsdem_dem *dem, const char *path);
/* DEM particles as PolyData (.vtp): one point and one vertex per particle (in 2D, z = 0), with
   point data id (Int32, the stable id), radius (m), mass (kg), material (Int32), fixed (UInt8),
   velocity (m/s), angular_velocity (rad/s), force and torque (N, N m: contacts at the last force
   evaluation, as fsdem_dem_particles), external_force (N). Active scalars radius, active vectors
   velocity; ParaView: Glyph filter, sphere, scale by "radius" with factor 2 (the sphere source has
   diameter 1). */
FSDEM_API fsdem_result fsdem_dem_write_vtp(const fsdem_dem *dem, const char *path, fsdem_vtk_format format);
/* DEM walls as PolyData (.vtp), one or more cells per wall: in 3D polygons (a plane as its
   intersection with the domain box [domain_min, domain_max], a convex polygon, none when the plane
   misses the box; a box, inside or outside, as its six faces; a triangle), in 2D lines at z = 0 (a
   plane as its chord of the domain rectangle; a box as its four edges; a segment); a segment is a
   line in 3D too. Line cells come first, then polygons (VTK's order), each in wall order.
   Polygons are ordered so that their normal points to the particles' side (a box's faces:
   inwards for an inside box, outwards for an outside one). Cell data: wall_id (Int32, the id from
   fsdem_dem_add_wall), type (UInt8, fsdem_dem_wall_type), force (N, exerted by the particles on
   the whole wall at the last force evaluation, fsdem_dem_wall_force; every cell of a wall carries
   it). Removed walls are left out, and so are SDF walls, whose surface is known only through their
   callback and cannot be drawn. */
FSDEM_API fsdem_result fsdem_dem_write_walls_vtp(const fsdem_dem *dem, const char *path, fsdem_vtk_format format);
/* DEM contacts as PolyData (.vtp): one line cell per touching particle pair (centre of particle i
   to centre of its partner j) and per wall contact (centre to the closest point of the wall), pairs
   first in neighbour-list order, then wall contacts by particle; the same contacts as the last force
   evaluation (fsdem_dem_stats.contacts + wall_contacts after a Verlet step): pairs that are both
   fixed exert nothing and are left out, as are wall contacts of fixed particles. Cell data: force
   (N, on particle i, from the partner; normal plus tangential, and a cohesive pull), normal_force
   (N, the contact law's normal part along the unit normal from the partner to i, positive in
   compression, without the cohesive pull), overlap (m, contact offset included), particle (Int32,
   id of i) and partner (Int32, id of j, or -1 - wall id). Across a periodic seam the line ends at
   the partner's image nearest i.
   The forces come from the contact law evaluated on the current state, as the step evaluates it,
   without changing anything: positions, velocities and the tangential springs the last step
   committed, with no further spring increment (Hertz-Mindlin) and the current dt for the linear
   law's one-step spring. After a Verlet step the positions are exactly those of the last force
   evaluation and so are the elastic forces, normal and tangential; dashpots see the final
   velocities instead of the half-step ones (a difference of dt/2 times the acceleration), and the
   per-particle sums equal fsdem_dem_particles.force to that difference (to rounding without
   damping). After a predictor-corrector step they are the forces of the final state. The file holds
   no contacts while the neighbour lists are out of date, that is after particles or walls were
   added, removed or set and before the next step (or fsdem_dem_contacts). */
FSDEM_API fsdem_result fsdem_dem_write_contacts_vtp(const fsdem_dem *dem, const char *path, fsdem_vtk_format format);

/* PIC marker particles as PolyData (.vtp): one point and vertex per particle (z = 0 in 2D), point
   data velocity (m/s). */
FSDEM_API fsdem_result fsdem_pic_write_particles_vtp(const fsdem_pic *pic, const char *path, fsdem_vtk_format format);
/* PIC grid as ImageData (.vti), extent 0..n[0] x 0..n[1] x 0..n[2] points (0..0 in z in 2D),
   origin the lower corner, spacing the cell size, with cell data pressure (Pa), phi (m), fraction,
   type (UInt8, fsdem_stencil_cell) and velocity (m/s, cell-centred: the mean of the two faces along
   each axis; z = 0 in 2D), as fsdem_pic_get_fields. */
FSDEM_API fsdem_result fsdem_pic_write_grid_vti(const fsdem_pic *pic, const char *path, fsdem_vtk_format format);

/* MPS particles as PolyData (.vtp): one point and vertex per particle of every kind (z = 0 in 2D),
   in index order, with point data kind (UInt8, fsdem_mps_kind: show the liquid with a Threshold on
   kind = 0), surface (UInt8), pressure (Pa), velocity (m/s), number_density and porosity, as
   fsdem_mps_get_particles. Active scalars pressure, active vectors velocity. */
FSDEM_API fsdem_result fsdem_mps_write_vtp(const fsdem_mps *mps, const char *path, fsdem_vtk_format format);
/* MPS particles as CSV, one row per particle of every kind in index order:
   kind,surface,x,y,z,vx,vy,vz,pressure,number_density,porosity (kind a fsdem_mps_kind). */
FSDEM_API fsdem_result fsdem_mps_write_csv(const fsdem_mps *mps, const char *path);

/* A coupler's per-particle records (fsdem_X_get_force) as CSV, one row per DEM particle that has
   one, in index order; the first column is the particle's stable id (fsdem_dem_particles.id). A
   particle added since the last update or step has no record yet and one removed since has no row;
   before the first update or step the file holds the header alone.
     SWE-DEM  id,buoyancy_z,hydrostatic_x,hydrostatic_y,dynamic_x,dynamic_y,heave_z,submerged_volume,
              frontal_area,surface,in_water
     MPS-DEM  id,drag_x,drag_y,drag_z,pressure_x,pressure_y,pressure_z,total_x,total_y,total_z,
              fluid_u,fluid_v,fluid_w,porosity,reynolds,wet
     PIC-DEM  id,pressure_x,pressure_y,pressure_z,viscous_x,viscous_y,viscous_z,torque_x,torque_y,
              torque_z,weight_correction_x,weight_correction_y,weight_correction_z,volume,faces
   Units as in the record types (N, N m, m^3, m^2, m, m/s). */
FSDEM_API fsdem_result fsdem_swe_dem_write_csv(const fsdem_swe_dem *coupler, const char *path);
FSDEM_API fsdem_result fsdem_mps_dem_write_csv(const fsdem_mps_dem *coupler, const char *path);
FSDEM_API fsdem_result fsdem_pic_dem_write_csv(const fsdem_pic_dem *coupler, const char *path);

/* Shallow-water fields as ImageData (.vti): extent 0..nx x 0..ny x 0..0 points, origin (x_min,
   y_min, 0), spacing (dx, dy, 1); a 1D channel is one cell high, 0..nx x 0..1, origin (x_min, 0, 0),
   spacing (dx, width, 1). Cell data h (m, eta - bed), eta (m), bed (m), velocity (m/s, (u, v, 0) as
   fsdem_swe_copy_field gives them, 0 in dry cells) and, when per-cell coefficients were set
   (fsdem_swe_set_manning), manning (s/m^(1/3)). Active scalars h, active vectors velocity. */
FSDEM_API fsdem_result fsdem_swe_write_vti(const fsdem_swe *swe, const char *path, fsdem_vtk_format format);

#ifdef __cplusplus
}
#endif
#endif /* FSDEM_H_INCLUDED */

/* ===== >>impl : implementation ===================================================================== */
#ifdef FSDEM_IMPLEMENTATION
#ifndef FSDEM_IMPLEMENTATION_DONE
#define FSDEM_IMPLEMENTATION_DONE

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#if defined(FSDEM_MALLOC) && defined(FSDEM_REALLOC) && defined(FSDEM_FREE)
/* user-supplied */
#elif !defined(FSDEM_MALLOC) && !defined(FSDEM_REALLOC) && !defined(FSDEM_FREE)
#include <stdlib.h>
#define FSDEM_MALLOC(sz) malloc(sz)
#define FSDEM_REALLOC(p, sz) realloc(p, sz)
#define FSDEM_FREE(p) free(p)
#else
#error "fsdem.h: define all of FSDEM_MALLOC, FSDEM_REALLOC and FSDEM_FREE, or none"
#endif

#ifndef FSDEM_ASSERT
#include <assert.h>
#define FSDEM_ASSERT(c) assert(c)
#endif

/* Results must not depend on the compiler fusing a * b + c into one rounding (it changes the last
   bits, and a chaotic run then diverges), so the implementation forbids the contraction where the
   compiler honours the standard pragma (clang). GCC contracts only in its GNU modes: build with
   -std=c99 (or -ffp-contract=off) for results that are the same bit for bit across compilers. */
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif

/* ===== >>impl_core : results, allocator, messages, vector algebra ================================== */

/* Contents: results and messages, the allocator and growth, the per-step scratch arena, the status
   every object keeps, finite-value checks, the CSV series of probes, 3-vector algebra,
   >>core_gauges (the point gauges of the particle solvers) and >>core_lane (short vectors for the
   batched kernels). */

#define FSDEM__PI 3.14159265358979323846
#define FSDEM__MESSAGE_SIZE 512

/* Forces inlining where the compiler allows it: a kernel written once with a constant argument (a
   contact law, a limiter) is instantiated per value, so hot loops carry no switch. */
#if defined(__GNUC__) || defined(__clang__)
#define FSDEM__FORCE_INLINE static inline __attribute__((always_inline))
#elif defined(_MSC_VER)
#define FSDEM__FORCE_INLINE static __forceinline
#else
#define FSDEM__FORCE_INLINE static inline
#endif

/* Promise that pointers do not alias, so loops over several particle arrays keep them in registers
   (C99 restrict; the compilers' own spelling in C++ and in MSVC, whose C mode lacks the keyword
   before C11). */
#if defined(_MSC_VER) || (defined(__cplusplus) && (defined(__GNUC__) || defined(__clang__)))
#define FSDEM__RESTRICT __restrict
#elif defined(__cplusplus)
#define FSDEM__RESTRICT
#else
#define FSDEM__RESTRICT restrict
#endif

const char *fsdem_result_string(fsdem_result result) {
    switch (result) {
    case FSDEM_OK: return "FSDEM_OK";
    case FSDEM_ERR_INVALID_ARG: return "FSDEM_ERR_INVALID_ARG";
    case FSDEM_ERR_OUT_OF_MEMORY: return "FSDEM_ERR_OUT_OF_MEMORY";
    case FSDEM_ERR_OUT_OF_DOMAIN: return "FSDEM_ERR_OUT_OF_DOMAIN";
    case FSDEM_ERR_NAN: return "FSDEM_ERR_NAN";
    case FSDEM_ERR_CFL: return "FSDEM_ERR_CFL";
    case FSDEM_ERR_NOT_CONVERGED: return "FSDEM_ERR_NOT_CONVERGED";
    case FSDEM_ERR_IO: return "FSDEM_ERR_IO";
    case FSDEM_ERR_NOT_FOUND: return "FSDEM_ERR_NOT_FOUND";
    }
    return "FSDEM_ERR_UNKNOWN";
}

static void *fsdem__alloc(const fsdem_allocator *a, size_t size) {
    if (size == 0) size = 1;
    return a->alloc ? a->alloc(a->user, size) : FSDEM_MALLOC(size);
}

static void fsdem__free(const fsdem_allocator *a, void *ptr, size_t size) {
    if (!ptr) return;
    if (a->free) a->free(a->user, ptr, size);
    else FSDEM_FREE(ptr);
}

/* Grows *ptr (holding *capacity elements of `elem` bytes, `used` of them live) to at least `need`
   elements, by doubling. Leaves *ptr untouched on failure. */
static fsdem_result fsdem__grow(const fsdem_allocator *a, void **ptr, int *capacity, int used,
                                int need, size_t elem) {
    int cap = *capacity > 0 ? *capacity : 16;
    void *fresh;
    if (need <= *capacity && *ptr) return FSDEM_OK;
    while (cap < need) {
        if (cap > (1 << 29)) return FSDEM_ERR_OUT_OF_MEMORY;
        cap *= 2;
    }
    if ((size_t)cap > ((size_t)-1) / elem) return FSDEM_ERR_OUT_OF_MEMORY;
    fresh = fsdem__alloc(a, (size_t)cap * elem);
    if (!fresh) return FSDEM_ERR_OUT_OF_MEMORY;
    if (*ptr && used > 0) memcpy(fresh, *ptr, (size_t)used * elem);
    fsdem__free(a, *ptr, (size_t)(*capacity) * elem);
    *ptr = fresh;
    *capacity = cap;
    return FSDEM_OK;
}

/* Grows `count` arrays that share one capacity (*capacity elements, `used` live; array k has
   elements of elem[k] bytes) to at least `need` elements, by doubling: all of them or, on failure,
   none (so each array keeps the size the shared capacity says, and frees it with that size). */
static fsdem_result fsdem__grow_set(const fsdem_allocator *a, void **const *arrays, const size_t *elem, int count, int *capacity,
                                    int used, int need) {
    enum { MAX_SET = 8 };
    void *fresh[MAX_SET];
    int cap = *capacity > 0 ? *capacity : 16, k;
    FSDEM_ASSERT(count <= MAX_SET);
    if (need <= *capacity) return FSDEM_OK;
    while (cap < need) {
        if (cap > (1 << 29)) return FSDEM_ERR_OUT_OF_MEMORY;
        cap *= 2;
    }
    for (k = 0; k < count; ++k) {
        fresh[k] = (size_t)cap <= ((size_t)-1) / elem[k] ? fsdem__alloc(a, (size_t)cap * elem[k]) : NULL;
        if (!fresh[k]) {
            while (k-- > 0) fsdem__free(a, fresh[k], (size_t)cap * elem[k]);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
    }
    for (k = 0; k < count; ++k) {
        if (*arrays[k] && used > 0) memcpy(fresh[k], *arrays[k], (size_t)used * elem[k]);
        fsdem__free(a, *arrays[k], (size_t)(*capacity) * elem[k]);
        *arrays[k] = fresh[k];
    }
    *capacity = cap;
    return FSDEM_OK;
}

/* Per-step scratch arena: one block that a step carves up and gives back whole at its end. It is
   reserved, growing only when a step needs more than any step before (when the lists it serves grew),
   so a steady run allocates nothing; pushes within a reservation cannot fail. Blocks are aligned for
   the widest vector (fsdem__lane). */
typedef struct fsdem__arena {
    unsigned char *base;
    size_t size, used;
} fsdem__arena;

#define FSDEM__ARENA_ALIGN 64

/* Empties the arena and makes room for `bytes` in pushes (each rounded up to FSDEM__ARENA_ALIGN).
   FSDEM_ERR_OUT_OF_MEMORY leaves it empty and as large as before. */
static fsdem_result fsdem__arena_reserve(const fsdem_allocator *al, fsdem__arena *a, size_t bytes) {
    size_t size = a->size ? a->size : 4096;
    unsigned char *fresh;
    a->used = 0;
    if (bytes + FSDEM__ARENA_ALIGN <= a->size) return FSDEM_OK;
    while (size < bytes + FSDEM__ARENA_ALIGN) {
        if (size > ((size_t)-1) / 4) return FSDEM_ERR_OUT_OF_MEMORY;
        size *= 2;
    }
    fresh = (unsigned char *)fsdem__alloc(al, size);
    if (!fresh) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__free(al, a->base, a->size);
    a->base = fresh;
    a->size = size;
    return FSDEM_OK;
}

static void fsdem__arena_reset(fsdem__arena *a) { a->used = 0; }

/* Rounds a push up so that the next one starts aligned. */
static size_t fsdem__arena_bytes(size_t bytes) {
    return (bytes + FSDEM__ARENA_ALIGN - 1) / FSDEM__ARENA_ALIGN * FSDEM__ARENA_ALIGN;
}

/* `bytes` of the reservation, aligned to FSDEM__ARENA_ALIGN. */
static void *fsdem__arena_push(fsdem__arena *a, size_t bytes) {
    unsigned char *p = a->base + a->used;
    size_t pad = (size_t)(FSDEM__ARENA_ALIGN - ((size_t)p % FSDEM__ARENA_ALIGN)) % FSDEM__ARENA_ALIGN;
    FSDEM_ASSERT(a->used + pad + bytes <= a->size);
    a->used += pad + bytes;
    return p + pad;
}

static void fsdem__arena_free(const fsdem_allocator *al, fsdem__arena *a) {
    fsdem__free(al, a->base, a->size);
    a->base = NULL;
    a->size = a->used = 0;
}

/* Message and log sink shared by all objects. */
typedef struct fsdem__status {
    char message[FSDEM__MESSAGE_SIZE];
    fsdem_log_fn log;
    void *log_user;
} fsdem__status;

static fsdem_result fsdem__vfail(fsdem__status *s, fsdem_result code, const char *fmt, va_list ap) {
    vsnprintf(s->message, sizeof s->message, fmt, ap);
    if (s->log) s->log(s->log_user, FSDEM_LOG_LEVEL_ERROR, s->message);
    return code;
}

static fsdem_result fsdem__fail(fsdem__status *s, fsdem_result code, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    code = fsdem__vfail(s, code, fmt, ap);
    va_end(ap);
    return code;
}

/* Logs an allocation failure of `bytes` in the function `what` (at creation, where no object exists
   yet to keep the message). */
static void fsdem__log_oom(fsdem_log_fn log, void *log_user, const char *what, size_t bytes) {
    char msg[128];
    if (!log) return;
    snprintf(msg, sizeof msg, "%s: out of memory (%lu bytes)", what, (unsigned long)bytes);
    log(log_user, FSDEM_LOG_LEVEL_ERROR, msg);
}

/* Writes "why" to msg and returns FSDEM_ERR_INVALID_ARG. */
static fsdem_result fsdem__reject(char *msg, size_t size, const char *fmt, ...) {
    va_list ap;
    if (msg && size) {
        va_start(ap, fmt);
        vsnprintf(msg, size, fmt, ap);
        va_end(ap);
    }
    return FSDEM_ERR_INVALID_ARG;
}

static fsdem_result fsdem__ok(fsdem__status *s) {
    s->message[0] = '\0';
    return FSDEM_OK;
}

/* The common start of every fsdem_<object>_create: `checked` is the result of the desc check and `why`
   its reason, which goes to the desc's log on failure; otherwise a zeroed object of `size` bytes is
   allocated with `al` (a failure is logged as one of `name`, the create function). Returns it, or
   NULL with *res set. */
static void *fsdem__object_new(fsdem_result checked, const char *why, fsdem_log_fn log, void *log_user,
                               const fsdem_allocator *al, size_t size, const char *name, fsdem_result *res) {
    void *obj;
    if (checked != FSDEM_OK) {
        if (log) log(log_user, FSDEM_LOG_LEVEL_ERROR, why);
        *res = checked;
        return NULL;
    }
    obj = fsdem__alloc(al, size);
    *res = obj ? FSDEM_OK : FSDEM_ERR_OUT_OF_MEMORY;
    if (obj) memset(obj, 0, size);
    else fsdem__log_oom(log, log_user, name, size);
    return obj;
}

static int fsdem__finite(fsdem_real x) { return x == x && x - x == 0; }

/* A CSV time series of probe values written by a solver as it steps (SWE and PIC gauges): a header,
   then rows at the exact multiples of `interval`, the values interpolated linearly between the
   start and the end of the step that passed each one (interval 0: one row per step). The series
   samples its solver itself: a solver's step calls fsdem__series_begin first and fsdem__series_step
   last, and nothing else. `before` holds the values at the start of the step in flight, `now` those
   at its end. */
typedef void (*fsdem__series_sample_fn)(const void *solver, fsdem_real *out);
typedef struct fsdem__series {
    void *file;            /* FILE*, NULL when closed */
    double interval, next; /* s */
    int columns;           /* values per row after t */
    fsdem_real *before, *now;
    fsdem__series_sample_fn sample;
    const void *solver;
} fsdem__series;

/* Writes the row of time t with the values in ser->now. */
static void fsdem__series_row(fsdem__series *ser, double t) {
    int k;
    fprintf((FILE *)ser->file, "\n%.10g", t);
    for (k = 0; k < ser->columns; ++k) fprintf((FILE *)ser->file, ",%.10g", (double)ser->now[k]);
}

/* Opens `path`, writes `header` and the row of time t sampled from `solver` by `sample`, and
   allocates the rows with `al`. FSDEM_ERR_IO, FSDEM_ERR_OUT_OF_MEMORY. */
static fsdem_result fsdem__series_open(fsdem__series *ser, const fsdem_allocator *al, const char *path, const char *header,
                                       int columns, double t, double interval, fsdem__series_sample_fn sample,
                                       const void *solver) {
    FILE *fp;
    fsdem_real *rows = (fsdem_real *)fsdem__alloc(al, sizeof(fsdem_real) * 2 * (size_t)columns);
    if (!rows) return FSDEM_ERR_OUT_OF_MEMORY;
    fp = path ? fopen(path, "w") : NULL;
    if (!fp) {
        fsdem__free(al, rows, sizeof(fsdem_real) * 2 * (size_t)columns);
        return FSDEM_ERR_IO;
    }
    ser->file = fp;
    ser->interval = interval;
    ser->next = t + interval;
    ser->columns = columns;
    ser->before = rows;
    ser->now = rows + columns;
    ser->sample = sample;
    ser->solver = solver;
    fputs(header, fp);
    sample(solver, ser->now);
    fsdem__series_row(ser, t);
    return FSDEM_OK;
}

/* Before a step: the values at its start, from which the rows inside it are interpolated. */
static void fsdem__series_begin(fsdem__series *ser) {
    if (ser->file && ser->interval > 0) ser->sample(ser->solver, ser->before);
}

/* After a step from t0 to t1: samples its end and writes the rows it passed. */
static fsdem_result fsdem__series_step(fsdem__series *ser, double t0, double t1) {
    FILE *fp = (FILE *)ser->file;
    int k;
    if (!fp) return FSDEM_OK;
    ser->sample(ser->solver, ser->now);
    if (ser->interval <= 0) fsdem__series_row(ser, t1);
    for (; ser->interval > 0 && ser->next <= t1 * (1 + 1e-12); ser->next += ser->interval) {
        const double w = t1 > t0 ? (ser->next - t0) / (t1 - t0) : 1;
        fprintf(fp, "\n%.10g", ser->next);
        for (k = 0; k < ser->columns; ++k) fprintf(fp, ",%.10g", (1 - w) * ser->before[k] + w * ser->now[k]);
    }
    fflush(fp);
    return ferror(fp) ? FSDEM_ERR_IO : FSDEM_OK;
}

/* Closes the file (a last newline) and frees the rows. FSDEM_ERR_IO when writing failed. */
static fsdem_result fsdem__series_close(fsdem__series *ser, const fsdem_allocator *al) {
    int bad;
    if (!ser->file) return FSDEM_OK;
    fputc('\n', (FILE *)ser->file);
    bad = ferror((FILE *)ser->file);
    bad |= fclose((FILE *)ser->file) != 0;
    fsdem__free(al, ser->before, sizeof(fsdem_real) * 2 * (size_t)ser->columns);
    memset(ser, 0, sizeof *ser);
    return bad ? FSDEM_ERR_IO : FSDEM_OK;
}



/* A relative tolerance of at least `floor` and of 100 roundings of fsdem_real, so a test written for
   double still holds in float. */
static double fsdem__tolerance(double floor) {
#ifdef FSDEM_USE_FLOAT
    const double eps = FLT_EPSILON;
#else
    const double eps = DBL_EPSILON;
#endif
    return floor > 100 * eps ? floor : 100 * eps;
}
static int fsdem__finite3(fsdem_vec3 v) {
    return fsdem__finite(v.x) && fsdem__finite(v.y) && fsdem__finite(v.z);
}
/* |v| <= bound (>>core plausibility bounds), NaN refused; each component is bounded before the
   norm, which then cannot overflow */
static int fsdem__within(fsdem_vec3 v, fsdem_real bound) {
    if (!(fabs(v.x) <= bound && fabs(v.y) <= bound && fabs(v.z) <= bound)) return 0;
    return v.x * v.x + v.y * v.y + v.z * v.z <= bound * bound;
}

static fsdem_vec3 fsdem__add(fsdem_vec3 a, fsdem_vec3 b) { return fsdem_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static fsdem_vec3 fsdem__sub(fsdem_vec3 a, fsdem_vec3 b) { return fsdem_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static fsdem_vec3 fsdem__scale(fsdem_vec3 a, fsdem_real s) { return fsdem_v3(a.x * s, a.y * s, a.z * s); }
static fsdem_vec3 fsdem__madd(fsdem_vec3 a, fsdem_vec3 b, fsdem_real s) {
    return fsdem_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s);
}
static fsdem_real fsdem__dot(fsdem_vec3 a, fsdem_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static fsdem_vec3 fsdem__cross(fsdem_vec3 a, fsdem_vec3 b) {
    return fsdem_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static fsdem_real fsdem__norm(fsdem_vec3 a) { return (fsdem_real)sqrt(fsdem__dot(a, a)); }
static fsdem_vec3 fsdem__zero3(void) { return fsdem_v3(0, 0, 0); }
static fsdem_real fsdem__comp(fsdem_vec3 v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }
static void fsdem__set_comp(fsdem_vec3 *v, int axis, fsdem_real value) {
    if (axis == 0) v->x = value;
    else if (axis == 1) v->y = value;
    else v->z = value;
}

/* The gravity of a desc named `desc` (e.g. "fsdem_mps_desc"): finite, in the plane in 2D (z = 0),
   and |g| <= FSDEM_MAX_ACCELERATION. */
static fsdem_result fsdem__check_gravity(const char *desc, fsdem_vec3 g, int dim, char *msg, size_t size) {
    if (!fsdem__within(g, FSDEM_MAX_ACCELERATION))
        return fsdem__reject(msg, size, "%s.gravity (%g, %g, %g) m/s^2 must be finite and at most FSDEM_MAX_ACCELERATION (%g m/s^2)",
                             desc, (double)g.x, (double)g.y, (double)g.z, (double)FSDEM_MAX_ACCELERATION);
    if (dim == 2 && g.z != 0)
        return fsdem__reject(msg, size, "%s.gravity.z = %g m/s^2 must be 0 in 2D (the motion is in the x-y plane)", desc, (double)g.z);
    return FSDEM_OK;
}

/* The longest step dt_max of a fluid desc: > 0, and short enough that gravity alone cannot take a
   particle at rest past FSDEM_MAX_SPEED in one step (|g| dt_max <= FSDEM_MAX_SPEED). */
static fsdem_result fsdem__check_dt_max(const char *desc, fsdem_real dt_max, fsdem_vec3 g, char *msg, size_t size) {
    const fsdem_real g_norm = fsdem__norm(g);
    if (!(dt_max > 0) || !fsdem__finite(dt_max) || g_norm * dt_max > FSDEM_MAX_SPEED)
        return fsdem__reject(msg, size, "%s.dt_max = %g s must be > 0 and |gravity| dt_max at most FSDEM_MAX_SPEED (%g m/s)", desc,
                             (double)dt_max, (double)FSDEM_MAX_SPEED);
    return FSDEM_OK;
}

/* ---- >>core_gauges : the point gauges of the particle solvers ---- */

/* Level and pressure gauges of the PIC and MPS solvers: a kind (the value of FSDEM_PIC_GAUGE_KIND_LEVEL
   and FSDEM_MPS_GAUGE_KIND_LEVEL, or of the _PRESSURE kinds), a position and a sensor radius per gauge,
   and the CSV series they write (fsdem__series; columns level_<id> or p_<id>). The solver samples
   them (its own level and pressure functions) and checks what is its own (the domain, gravity);
   `fn` names its public function in the messages. */
enum { FSDEM__GAUGE_LEVEL = 0, FSDEM__GAUGE_PRESSURE = 1 };

typedef struct fsdem__gauges {
    fsdem_vec3 *at;
    int *kind;
    fsdem_real *radius; /* m; 0 for a point */
    int count, capacity;
    fsdem__series series;
} fsdem__gauges;

/* Appends a gauge at `at`, which must lie in the box [lo, hi] along the first `dim` axes. */
static fsdem_result fsdem__gauges_add(fsdem__gauges *g, fsdem__status *st, const fsdem_allocator *al, const char *fn, int kind,
                                      fsdem_vec3 at, fsdem_real radius, int dim, fsdem_vec3 lo, fsdem_vec3 hi, int *id) {
    const int n = g->count;
    int a;
    if (id) *id = -1;
    if (g->series.file) return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: close the gauge file first", fn);
    if (kind < FSDEM__GAUGE_LEVEL || kind > FSDEM__GAUGE_PRESSURE || !fsdem__finite3(at) || !(radius >= 0) || !fsdem__finite(radius))
        return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: the kind must be a gauge kind, the position finite, the radius >= 0", fn);
    for (a = 0; a < dim; ++a)
        if (!(fsdem__comp(at, a) >= fsdem__comp(lo, a) && fsdem__comp(at, a) <= fsdem__comp(hi, a)))
            return fsdem__fail(st, FSDEM_ERR_OUT_OF_DOMAIN, "%s: (%g, %g, %g) is outside the domain", fn, (double)at.x, (double)at.y,
                               (double)at.z);
    {
        void **const arrays[3] = {(void **)&g->at, (void **)&g->kind, (void **)&g->radius};
        const size_t elem[3] = {sizeof(fsdem_vec3), sizeof(int), sizeof(fsdem_real)};
        if (fsdem__grow_set(al, arrays, elem, 3, &g->capacity, n, n + 1) != FSDEM_OK)
            return fsdem__fail(st, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory for gauge %d", fn, n);
    }
    g->at[n] = at;
    g->kind[n] = kind;
    g->radius[n] = radius;
    g->count++;
    if (id) *id = n;
    return fsdem__ok(st);
}

/* Opens the series at time t (a file already open is closed first). */
static fsdem_result fsdem__gauges_open(fsdem__gauges *g, fsdem__status *st, const fsdem_allocator *al, const char *fn,
                                       const char *path, double t, fsdem_real interval, fsdem__series_sample_fn sample,
                                       const void *solver) {
    char *header;
    size_t size;
    int k, n = 1;
    fsdem_result res;
    if (g->count == 0) return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: add gauges first", fn);
    if (!(interval >= 0) || !fsdem__finite(interval))
        return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: interval must be >= 0 (got %g s)", fn, (double)interval);
    fsdem__series_close(&g->series, al);
    size = 2 + 24 * (size_t)g->count;
    header = (char *)fsdem__alloc(al, size);
    if (!header) return fsdem__fail(st, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
    header[0] = 't';
    header[1] = '\0';
    for (k = 0; k < g->count; ++k)
        n += snprintf(header + n, size - (size_t)n, g->kind[k] == FSDEM__GAUGE_LEVEL ? ",level_%d" : ",p_%d", k);
    res = fsdem__series_open(&g->series, al, path, header, g->count, t, (double)interval, sample, solver);
    fsdem__free(al, header, size);
    if (res != FSDEM_OK) return fsdem__fail(st, res, "%s: cannot open '%s'", fn, path ? path : "(null)");
    return fsdem__ok(st);
}

static fsdem_result fsdem__gauges_close(fsdem__gauges *g, fsdem__status *st, const fsdem_allocator *al, const char *fn) {
    return fsdem__series_close(&g->series, al) == FSDEM_OK ? fsdem__ok(st) : fsdem__fail(st, FSDEM_ERR_IO, "%s: write error", fn);
}

/* Closes the series and frees the gauges. */
static void fsdem__gauges_free(fsdem__gauges *g, const fsdem_allocator *al) {
    fsdem__series_close(&g->series, al);
    fsdem__free(al, g->at, sizeof(fsdem_vec3) * (size_t)g->capacity);
    fsdem__free(al, g->kind, sizeof(int) * (size_t)g->capacity);
    fsdem__free(al, g->radius, sizeof(fsdem_real) * (size_t)g->capacity);
    memset(g, 0, sizeof *g);
}

/* ---- >>core_lane : short vectors for batched kernels ---- */

/* An fsdem__lane holds FSDEM__LANES reals that one instruction processes, where the compiler has GNU
   vector extensions (gcc, clang): 16 bytes (SSE2, NEON), 32 with AVX, 64 with AVX-512, as the target
   flags allow. Elsewhere, or with FSDEM_NO_SIMD, it is a single real. A kernel written with + - * /
   on lanes and the functions below compiles to either, so its arithmetic exists once. Comparisons
   give an fsdem__mask (all bits set or clear per lane) for fsdem__lane_select; combine masks with
   & and |. Kernels keep every lane finite (padding repeats a real entry, divisors are guarded), so
   they raise no floating-point exceptions. */
#if (defined(__GNUC__) || defined(__clang__)) && !defined(FSDEM_NO_SIMD)
#if defined(__AVX512F__)
#define FSDEM__LANE_BYTES 64
#elif defined(__AVX__)
#define FSDEM__LANE_BYTES 32
#else
#define FSDEM__LANE_BYTES 16
#endif
#define FSDEM__LANES ((int)(FSDEM__LANE_BYTES / sizeof(fsdem_real)))
typedef fsdem_real fsdem__lane __attribute__((vector_size(FSDEM__LANE_BYTES)));
#ifdef FSDEM_USE_FLOAT
typedef int fsdem__mask __attribute__((vector_size(FSDEM__LANE_BYTES)));
#else
typedef long long fsdem__mask __attribute__((vector_size(FSDEM__LANE_BYTES)));
#endif
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#elif defined(__aarch64__)
#include <arm_neon.h>
#endif

FSDEM__FORCE_INLINE fsdem__lane fsdem__lane_select(fsdem__mask m, fsdem__lane a, fsdem__lane b) {
    return (fsdem__lane)(((fsdem__mask)a & m) | ((fsdem__mask)b & ~m));
}

/* libm's sqrt sets errno and is called lane by lane; the instructions are not */
FSDEM__FORCE_INLINE fsdem__lane fsdem__lane_sqrt(fsdem__lane a) {
#if defined(FSDEM_USE_FLOAT) && FSDEM__LANE_BYTES == 64 /* (the zero-masked forms: g++ 12 warns inside the plain ones) */
    return (fsdem__lane)_mm512_maskz_sqrt_ps((__mmask16)0xFFFF, (__m512)a);
#elif FSDEM__LANE_BYTES == 64
    return (fsdem__lane)_mm512_maskz_sqrt_pd((__mmask8)0xFF, (__m512d)a);
#elif defined(FSDEM_USE_FLOAT) && FSDEM__LANE_BYTES == 32
    return (fsdem__lane)_mm256_sqrt_ps((__m256)a);
#elif FSDEM__LANE_BYTES == 32
    return (fsdem__lane)_mm256_sqrt_pd((__m256d)a);
#elif defined(FSDEM_USE_FLOAT) && defined(__SSE__)
    return (fsdem__lane)_mm_sqrt_ps((__m128)a);
#elif defined(__SSE2__)
    return (fsdem__lane)_mm_sqrt_pd((__m128d)a);
#elif defined(FSDEM_USE_FLOAT) && defined(__aarch64__)
    return (fsdem__lane)vsqrtq_f32((float32x4_t)a);
#elif defined(__aarch64__)
    return (fsdem__lane)vsqrtq_f64((float64x2_t)a);
#else
    int l;
    for (l = 0; l < FSDEM__LANES; ++l) a[l] = (fsdem_real)sqrt(a[l]);
    return a;
#endif
}
#else
#define FSDEM__LANES 1
typedef fsdem_real fsdem__lane;
typedef int fsdem__mask; /* 0 or 1 */

FSDEM__FORCE_INLINE fsdem__lane fsdem__lane_select(fsdem__mask m, fsdem__lane a, fsdem__lane b) { return m ? a : b; }
FSDEM__FORCE_INLINE fsdem__lane fsdem__lane_sqrt(fsdem__lane a) { return (fsdem_real)sqrt(a); }
#endif

/* Lanes from and to reals at p (no alignment needed). */
FSDEM__FORCE_INLINE fsdem__lane fsdem__lane_load(const fsdem_real *p) {
    fsdem__lane a;
    memcpy(&a, p, sizeof a);
    return a;
}
FSDEM__FORCE_INLINE void fsdem__lane_store(fsdem_real *p, fsdem__lane a) { memcpy(p, &a, sizeof a); }
FSDEM__FORCE_INLINE fsdem__lane fsdem__lane_max(fsdem__lane a, fsdem__lane b) { return fsdem__lane_select(a > b, a, b); }
FSDEM__FORCE_INLINE fsdem__lane fsdem__lane_set(fsdem_real s) {
    fsdem_real v[FSDEM__LANES];
    int l;
    for (l = 0; l < FSDEM__LANES; ++l) v[l] = s;
    return fsdem__lane_load(v);
}

/* ===== >>impl_geom : signed distances and closest points =============================================

   Contents: closest points (segment, triangle); the unit direction between two points; signed
   distances (positive outside the solid) of an axis-aligned box (with its outward normal), a sphere
   or disc, a flat-capped cylinder and a 2D polygon. */

/* Closest point to p on segment a-b. */
static fsdem_vec3 fsdem__geom_closest_on_segment(fsdem_vec3 p, fsdem_vec3 a, fsdem_vec3 b) {
    fsdem_vec3 ab = fsdem__sub(b, a);
    fsdem_real len2 = fsdem__dot(ab, ab), s = len2 > 0 ? fsdem__dot(fsdem__sub(p, a), ab) / len2 : 0;
    s = s < 0 ? 0 : s > 1 ? 1 : s;
    return fsdem__madd(a, ab, s);
}

/* Closest point to p on triangle a-b-c: the projection when it falls inside, else the closest
   point on the nearest edge (then *on_edge is 1). */
static fsdem_vec3 fsdem__geom_closest_on_triangle(fsdem_vec3 p, fsdem_vec3 a, fsdem_vec3 b, fsdem_vec3 c, int *on_edge) {
    fsdem_vec3 ab = fsdem__sub(b, a), ac = fsdem__sub(c, a), ap = fsdem__sub(p, a);
    fsdem_vec3 nrm = fsdem__cross(ab, ac), q, best;
    fsdem_real n2 = fsdem__dot(nrm, nrm), u, v, dist2, best2;
    fsdem_vec3 edge_point[3];
    int k;
    /* barycentric coordinates of the projection of p */
    v = fsdem__dot(fsdem__cross(ap, ac), nrm) / n2;
    u = fsdem__dot(fsdem__cross(ab, ap), nrm) / n2;
    *on_edge = !(v > 0 && u > 0 && u + v < 1);
    if (v >= 0 && u >= 0 && u + v <= 1) return fsdem__add(a, fsdem__add(fsdem__scale(ab, v), fsdem__scale(ac, u)));
    edge_point[0] = fsdem__geom_closest_on_segment(p, a, b);
    edge_point[1] = fsdem__geom_closest_on_segment(p, b, c);
    edge_point[2] = fsdem__geom_closest_on_segment(p, c, a);
    best = edge_point[0];
    q = fsdem__sub(p, best);
    best2 = fsdem__dot(q, q);
    for (k = 1; k < 3; ++k) {
        q = fsdem__sub(p, edge_point[k]);
        dist2 = fsdem__dot(q, q);
        if (dist2 < best2) {
            best2 = dist2;
            best = edge_point[k];
        }
    }
    return best;
}

/* Unit vector from q to p, or `fallback` when they coincide; their distance goes to *dist. */
static fsdem_vec3 fsdem__geom_direction(fsdem_vec3 p, fsdem_vec3 q, fsdem_vec3 fallback, fsdem_real *dist) {
    fsdem_vec3 dv = fsdem__sub(p, q);
    *dist = fsdem__norm(dv);
    return *dist > 0 ? fsdem__scale(dv, 1 / *dist) : fallback;
}

/* Signed distance from p to the box [lo, hi] over the first `dim` axes (2D: z ignored), positive
   outside, and the unit outward normal: from the closest point of the surface towards p outside,
   through the nearest face inside. */
static fsdem_real fsdem__geom_box(fsdem_vec3 p, fsdem_vec3 lo, fsdem_vec3 hi, int dim, fsdem_vec3 *normal) {
    fsdem_real q[3], e[3] = {0, 0, 0}, depth = (fsdem_real)HUGE_VAL, dist;
    int axis, inside = 1, best_axis = 0, best_side = 0;
    for (axis = 0; axis < 3; ++axis) {
        const fsdem_real x = fsdem__comp(p, axis), l = fsdem__comp(lo, axis), h = fsdem__comp(hi, axis);
        q[axis] = axis >= dim ? x : x < l ? l : x > h ? h : x;
        if (q[axis] != x) inside = 0;
    }
    if (!inside) {
        *normal = fsdem__geom_direction(p, fsdem_v3(q[0], q[1], q[2]), fsdem_v3(1, 0, 0), &dist);
        return dist;
    }
    for (axis = 0; axis < dim; ++axis) {
        const fsdem_real x = fsdem__comp(p, axis), l = fsdem__comp(lo, axis), h = fsdem__comp(hi, axis);
        if (x - l < depth) { depth = x - l; best_axis = axis; best_side = 0; }
        if (h - x < depth) { depth = h - x; best_axis = axis; best_side = 1; }
    }
    e[best_axis] = best_side ? 1 : -1;
    *normal = fsdem_v3(e[0], e[1], e[2]);
    return -depth;
}

/* Signed distance from p to a sphere (3D) or a disc in the x-y plane (2D). */
static fsdem_real fsdem__geom_sphere(fsdem_vec3 p, fsdem_vec3 centre, fsdem_real radius, int dim) {
    fsdem_vec3 q = fsdem__sub(p, centre);
    if (dim == 2) q.z = 0;
    return fsdem__norm(q) - radius;
}

/* Signed distance from p to the flat-capped cylinder of axis a-b (a != b) and `radius`. */
static fsdem_real fsdem__geom_cylinder(fsdem_vec3 p, fsdem_vec3 a, fsdem_vec3 b, fsdem_real radius) {
    fsdem_vec3 e = fsdem__sub(b, a), m = fsdem__scale(fsdem__add(a, b), (fsdem_real)0.5), q;
    fsdem_real len = fsdem__norm(e), z, rad, dr, dz, o2;
    e = fsdem__scale(e, 1 / len);
    q = fsdem__sub(p, m);
    z = fsdem__dot(q, e);
    rad = fsdem__norm(fsdem__madd(q, e, -z));
    dr = rad - radius;
    dz = (fsdem_real)fabs(z) - len / 2;
    o2 = (dr > 0 ? dr * dr : 0) + (dz > 0 ? dz * dz : 0);
    return (dr > dz ? (dr < 0 ? dr : 0) : (dz < 0 ? dz : 0)) + (fsdem_real)sqrt(o2);
}

/* Signed distance from p (x, y) to the closed polygon of `count` vertices (x, y used), any
   orientation: the distance to the nearest edge, negative inside (even-odd rule). */
static fsdem_real fsdem__geom_polygon(fsdem_vec3 p, const fsdem_vec3 *v, int count) {
    fsdem_real best = (fsdem_real)HUGE_VAL;
    int i, j, inside = 0;
    p.z = 0;
    for (i = 0, j = count - 1; i < count; j = i++) {
        const fsdem_vec3 vi = fsdem_v3(v[i].x, v[i].y, 0), vj = fsdem_v3(v[j].x, v[j].y, 0);
        const fsdem_vec3 d = fsdem__sub(p, fsdem__geom_closest_on_segment(p, vj, vi));
        const fsdem_real d2 = fsdem__dot(d, d);
        if (d2 < best) best = d2;
        if ((vi.y > p.y) != (vj.y > p.y) && p.x < (vj.x - vi.x) * (p.y - vi.y) / (vj.y - vi.y) + vi.x) inside = !inside;
    }
    best = (fsdem_real)sqrt(best);
    return inside ? -best : best;
}

/* ===== >>impl_kernel : interpolation weights ==========================================================

   Contents: fsdem__kernel (per-axis node range, weights, derivatives and clamped node indices) and
   fsdem__kernel_weights, the tent (linear, 2 nodes) and quadratic B-spline (3 nodes) kernels at a
   position given in grid units; fsdem__kernel_mps, the particle-interaction weight of MPS. */

/* Kernel weights of one point along each axis: nodes lo[b] .. lo[b] + count[b] - 1, weights w and
   their derivatives dw (per grid unit), and the node indices clamped into the grid (idx). */
typedef struct fsdem__kernel {
    int lo[3];
    int count[3];
    int idx[3][3];
    fsdem_real w[3][3];
    fsdem_real dw[3][3];
} fsdem__kernel;

/* Weights at position s[b] (grid units: node i sits at s = i) on a grid of n[b] nodes, for the first
   `dim` axes; the others get the single node 0 with weight 1. Positions far outside (or NaN) are
   clamped to 4 nodes beyond the grid, so the indices stay representable. */
static void fsdem__kernel_weights(fsdem__kernel *k, int dim, const fsdem_real s[3], const int n[3], int quadratic) {
    int b, q;
    for (b = 0; b < 3; ++b) {
        fsdem_real x = s[b], t;
        int i0;
        for (q = 0; q < 3; ++q) { /* every entry set, also those past count (compilers cannot see the bound) */
            k->idx[b][q] = 0;
            k->w[b][q] = k->dw[b][q] = 0;
        }
        if (b >= dim) {
            k->lo[b] = 0;
            k->count[b] = 1;
            k->w[b][0] = 1;
            continue;
        }
        if (!(x > -4)) x = -4; /* also NaN */
        if (x > (fsdem_real)n[b] + 4) x = (fsdem_real)n[b] + 4;
        if (!quadratic) {
            i0 = (int)(x + 8) - 8; /* floor: x > -8 here */
            t = x - (fsdem_real)i0;
            k->count[b] = 2;
            k->w[b][0] = 1 - t;
            k->w[b][1] = t;
            k->dw[b][0] = -1;
            k->dw[b][1] = 1;
        } else {
            i0 = (int)(x + (fsdem_real)7.5) - 8; /* floor(x - 1/2) */
            t = x - (fsdem_real)i0;
            k->count[b] = 3;
            k->w[b][0] = (fsdem_real)0.5 * ((fsdem_real)1.5 - t) * ((fsdem_real)1.5 - t);
            k->w[b][1] = (fsdem_real)0.75 - (t - 1) * (t - 1);
            k->w[b][2] = (fsdem_real)0.5 * (t - (fsdem_real)0.5) * (t - (fsdem_real)0.5);
            k->dw[b][0] = t - (fsdem_real)1.5;
            k->dw[b][1] = -2 * (t - 1);
            k->dw[b][2] = t - (fsdem_real)0.5;
        }
        k->lo[b] = i0;
        for (q = 0; q < k->count[b]; ++q) {
            const int i = i0 + q;
            k->idx[b][q] = i < 0 ? 0 : i > n[b] - 1 ? n[b] - 1 : i;
        }
    }
}

/* Weight of the MPS particle interaction at distance r (m) for the radius re (m): the kernel of
   Zhang et al. (2014), re/(0.85 r + 0.15 re) - 1 for r < re, 0 beyond (seed 002 Eq. 6). It is finite
   at r = 0 (re/(0.15 re) - 1 = 17/3), unlike the original MPS kernel re/r - 1, which keeps
   coincident particles from producing infinite number densities and pressure spikes. */
static inline fsdem_real fsdem__kernel_mps(fsdem_real r, fsdem_real re) {
    return r < re ? re / ((fsdem_real)0.85 * r + (fsdem_real)0.15 * re) - 1 : 0;
}

/* ===== >>impl_grid : cell grid ===================================================================== */

/* Contents: setup (cell size enlarged to bound the cell count), binning by counting sort, cell
   lookup, the 3^dim neighbourhood and the half (forward) neighbourhood. */

fsdem_result fsdem_cellgrid_setup(fsdem_cellgrid *g, const fsdem_allocator *allocator, int dim,
                                  fsdem_vec3 lo, fsdem_vec3 hi, fsdem_real cell_size, int max_cells) {
    return fsdem_cellgrid_setup_periodic(g, allocator, dim, lo, hi, cell_size, max_cells, NULL);
}

fsdem_result fsdem_cellgrid_setup_periodic(fsdem_cellgrid *g, const fsdem_allocator *allocator, int dim, fsdem_vec3 lo,
                                           fsdem_vec3 hi, fsdem_real cell_size, int max_cells, const int periodic[3]) {
    double extent[3], cells = 1;
    int axis, tries;
    if (!g) return FSDEM_ERR_INVALID_ARG;
    if (allocator) g->allocator = *allocator;
    if ((dim != 2 && dim != 3) || !(cell_size > 0) || !fsdem__finite(cell_size) ||
        !fsdem__finite3(lo) || !fsdem__finite3(hi))
        return FSDEM_ERR_INVALID_ARG;
    if (max_cells <= 0) max_cells = 1 << 24;
    for (axis = 0; axis < 3; ++axis) {
        extent[axis] = axis < dim ? (double)fsdem__comp(hi, axis) - fsdem__comp(lo, axis) : 0;
        /* finite, or the cell count below never fits (a box of +-1e308 overflows to infinity) */
        if (axis < dim && !(extent[axis] > 0 && extent[axis] < HUGE_VAL)) return FSDEM_ERR_INVALID_ARG;
    }
    /* Enlarge the cell until the cell count fits: a coarse grid is slower, never wrong. Each try
       grows it by 1.25, so 400 tries cover any finite extent over any positive size. */
    for (tries = 0;; ++tries) {
        cells = 1;
        for (axis = 0; axis < dim; ++axis) cells *= floor(extent[axis] / cell_size) + 1;
        if (cells <= max_cells) break;
        if (tries == 400 || !fsdem__finite(cell_size * (fsdem_real)1.25)) return FSDEM_ERR_INVALID_ARG;
        cell_size *= (fsdem_real)1.25;
    }
    g->dim = dim;
    g->origin = lo;
    g->cell_size = cell_size;
    g->inv_cell_size = 1 / cell_size;
    for (axis = 0; axis < 3; ++axis) {
        const int tiles = axis < dim ? (int)floor(extent[axis] / cell_size) : 0;
        g->wrap[axis] = periodic && axis < dim && periodic[axis] && tiles >= 3;
        g->n[axis] = g->wrap[axis] ? tiles : periodic && axis < dim && periodic[axis] ? 1 : axis < dim ? tiles + 1 : 1;
        /* a periodic axis of one cell bins everything in it */
        g->inv_width[axis] = g->wrap[axis] ? (fsdem_real)(tiles / extent[axis])
                             : periodic && axis < dim && periodic[axis] ? 0
                                                                        : g->inv_cell_size;
    }
    g->cell_count = g->n[0] * g->n[1] * g->n[2];
    if (g->cell_count + 1 > g->cell_capacity) {
        fsdem__free(&g->allocator, g->cell_start, sizeof(int) * (size_t)g->cell_capacity);
        g->cell_capacity = 0;
        g->cell_start = (int *)fsdem__alloc(&g->allocator, sizeof(int) * (size_t)(g->cell_count + 1));
        if (!g->cell_start) return FSDEM_ERR_OUT_OF_MEMORY;
        g->cell_capacity = g->cell_count + 1;
    }
    memset(g->cell_start, 0, sizeof(int) * (size_t)(g->cell_count + 1));
    return FSDEM_OK;
}

static int fsdem__cellgrid_coord(const fsdem_cellgrid *g, fsdem_real x, int axis) {
    fsdem_real s = (x - fsdem__comp(g->origin, axis)) * g->inv_width[axis];
    int c;
    if (!(s > 0)) return 0; /* also catches NaN */
    c = s < (fsdem_real)g->n[axis] ? (int)s : g->n[axis] - 1;
    return c;
}

int fsdem_cellgrid_cell(const fsdem_cellgrid *g, fsdem_vec3 p, int coord[3]) {
    int c[3];
    c[0] = fsdem__cellgrid_coord(g, p.x, 0);
    c[1] = fsdem__cellgrid_coord(g, p.y, 1);
    c[2] = g->dim == 3 ? fsdem__cellgrid_coord(g, p.z, 2) : 0;
    if (coord) {
        coord[0] = c[0];
        coord[1] = c[1];
        coord[2] = c[2];
    }
    return (c[2] * g->n[1] + c[1]) * g->n[0] + c[0];
}

fsdem_result fsdem_cellgrid_build(fsdem_cellgrid *g, const fsdem_vec3 *points, int count) {
    int i, c, sum = 0;
    if (!g || !g->cell_start || count < 0 || (count > 0 && !points)) return FSDEM_ERR_INVALID_ARG; /* set up first */
    if (count > g->item_capacity) {
        int cap = count + count / 4 + 16;
        int *items = (int *)fsdem__alloc(&g->allocator, sizeof(int) * (size_t)cap);
        int *cell_of = (int *)fsdem__alloc(&g->allocator, sizeof(int) * (size_t)cap);
        if (!items || !cell_of) {
            fsdem__free(&g->allocator, items, sizeof(int) * (size_t)cap);
            fsdem__free(&g->allocator, cell_of, sizeof(int) * (size_t)cap);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
        fsdem__free(&g->allocator, g->items, sizeof(int) * (size_t)g->item_capacity);
        fsdem__free(&g->allocator, g->cell_of, sizeof(int) * (size_t)g->item_capacity);
        g->items = items;
        g->cell_of = cell_of;
        g->item_capacity = cap;
    }
    memset(g->cell_start, 0, sizeof(int) * (size_t)(g->cell_count + 1));
    for (i = 0; i < count; ++i) {
        c = fsdem_cellgrid_cell(g, points[i], NULL);
        g->cell_of[i] = c;
        g->cell_start[c + 1]++;
    }
    for (c = 0; c < g->cell_count; ++c) {
        sum += g->cell_start[c + 1];
        g->cell_start[c + 1] = sum;
    }
    /* Counting sort; cell_start[c] is used as a cursor and restored afterwards. */
    for (i = 0; i < count; ++i) g->items[g->cell_start[g->cell_of[i]]++] = i;
    for (c = g->cell_count; c > 0; --c) g->cell_start[c] = g->cell_start[c - 1];
    g->cell_start[0] = 0;
    return FSDEM_OK;
}

/* Coordinate c + step along an axis: wrapped round a periodic one, -1 off the grid otherwise. */
static int fsdem__cellgrid_step(const fsdem_cellgrid *g, int axis, int c, int step) {
    c += step;
    if (g->wrap[axis]) return c < 0 ? c + g->n[axis] : c >= g->n[axis] ? c - g->n[axis] : c;
    return c >= 0 && c < g->n[axis] ? c : -1;
}

int fsdem_cellgrid_neighbourhood(const fsdem_cellgrid *g, const int coord[3], int cells[27]) {
    int count = 0, dx, dy, dz, zr = g->dim == 3 ? 1 : 0;
    for (dz = -zr; dz <= zr; ++dz) {
        const int z = fsdem__cellgrid_step(g, 2, coord[2], dz);
        if (z < 0) continue;
        for (dy = -1; dy <= 1; ++dy) {
            const int y = fsdem__cellgrid_step(g, 1, coord[1], dy);
            if (y < 0) continue;
            for (dx = -1; dx <= 1; ++dx) {
                const int x = fsdem__cellgrid_step(g, 0, coord[0], dx);
                if (x < 0) continue;
                cells[count++] = (z * g->n[1] + y) * g->n[0] + x;
            }
        }
    }
    return count;
}

int fsdem_cellgrid_forward(const fsdem_cellgrid *g, const int coord[3], int cells[14]) {
    int count = 0, dx, dy, dz, zr = g->dim == 3 ? 1 : 0;
    for (dz = 0; dz <= zr; ++dz)
        for (dy = dz ? -1 : 0; dy <= 1; ++dy)
            for (dx = dz || dy ? -1 : 0; dx <= 1; ++dx) {
                const int x = fsdem__cellgrid_step(g, 0, coord[0], dx), y = fsdem__cellgrid_step(g, 1, coord[1], dy);
                const int z = fsdem__cellgrid_step(g, 2, coord[2], dz);
                if (x < 0 || y < 0 || z < 0) continue;
                cells[count++] = (z * g->n[1] + y) * g->n[0] + x;
            }
    return count;
}

void fsdem_cellgrid_free(fsdem_cellgrid *g) {
    fsdem__free(&g->allocator, g->cell_start, sizeof(int) * (size_t)g->cell_capacity);
    fsdem__free(&g->allocator, g->items, sizeof(int) * (size_t)g->item_capacity);
    fsdem__free(&g->allocator, g->cell_of, sizeof(int) * (size_t)g->item_capacity);
    g->cell_start = g->items = g->cell_of = NULL;
    g->cell_capacity = g->item_capacity = 0;
}

/* ===== >>impl_dem : discrete element method ======================================================== */

/* Contents: the object and its private types; >>dem_desc (defaults, validation, the time-step
   rule), >>dem_law (contact laws: pair constants, the batched law kernel, rolling resistance),
   >>dem_periodic (minimum images and wrapping), >>dem_object (creation, materials, particles),
   >>dem_wall (wall geometry and distances), >>dem_neighbours (neighbour lists with contact history), >>dem_forces (force evaluation),
   >>dem_integrate (Verlet, predictor-corrector, advance), >>dem_diagnostics (stable dt, energy,
   statistics, contacts). */

/* Constants of one material pair, computed when a material is added. */
typedef struct fsdem__dem_pair {
    fsdem_real e_star;   /* Pa, 1/E* = (1-nu_i^2)/E_i + (1-nu_j^2)/E_j (Hertz) */
    fsdem_real g_star;   /* Pa, 1/G* = 2(2-nu_i)(1+nu_i)/E_i + 2(2-nu_j)(1+nu_j)/E_j (Mindlin) */
    fsdem_real e_pair;   /* Pa, 2/(1/E_i + 1/E_j): equals E for one material (GIC, k_n = E r) */
    fsdem_real nu;       /* -, mean Poisson ratio (psi of seed 000 Eq. 12-13) */
    fsdem_real alpha;    /* -, mean alpha of seed 000 Eq. 11 */
    fsdem_real friction; /* -, mean mu */
    fsdem_real rolling;  /* -, mean mu_r */
    fsdem_real restitution; /* -, mean e */
    fsdem_real cohesion; /* J/m^3, mean cohesion energy density */
    fsdem_real tsuji;    /* -, damping coefficient giving that restitution (>>dem_law) */
    /* The law's coefficients in the form the contact kernel evaluates (fsdem__dem_batch_law):
         law      kn                  cn                      kt                 ct
         Hertz    (4/3) E* (Pa)       tsuji^2 (4/3) E* (Pa)   8 G* (Pa)          sqrt(4 G* / E*)
         linear   ||g||/(theta dx)    2 alpha sqrt(kn)        1/(2(1+psi))       1/sqrt(2(1+psi))
                  (1/s^2)             (1/s)                   seed 000 Eq. 10-13 per unit m_ij
         seed 002 (4/3) E* (Pa)       2 zeta, zeta =          1/(2+nu)           sqrt(kt)
         linear                       -ln e/sqrt(ln^2 e + pi^2)   (Eq. 21-24, times sqrt(R*))
         GIC      2 E_pair (Pa)       0                       1/(2(1+nu))        0
       ct is 0 without tangential damping (desc.tangential_damping). */
    fsdem_real kn, cn, kt, ct;
} fsdem__dem_pair;

typedef struct fsdem__dem_wall {
    fsdem_dem_wall_desc d;
    int active;
    fsdem_vec3 force;   /* N, exerted by the particles on the wall at the last force evaluation */
    fsdem_vec3 impulse; /* N s, given by the wall to the particles since it was added */
    fsdem_vec3 force_a; /* N, force of the predictor evaluation (predictor-corrector) */
    fsdem_real moved;   /* m, distance travelled since the last neighbour-list build */
} fsdem__dem_wall;

/* Neighbour list in compressed rows: the entries of particle i are start[i] .. start[i+1]-1, and
   first[k] = i. Entry k names a partner in key[k] (particle j > i, or wall*8+face) and keeps the
   contact's tangential spring displacement in history[k], the contact history carried across steps
   and rebuilds. history[k] means something only while key[k] carries FSDEM__DEM_HELD (the contact
   touched at the last committed force evaluation); without it the spring is zero. So a separation
   costs one bit and the many entries that do not touch are passed over without reading history. */
typedef struct fsdem__dem_list {
    int *start;
    int start_capacity;
    int rows; /* particles the list was built for */
    int *first, *key;
    fsdem_vec3 *history; /* m */
    int count, capacity;
} fsdem__dem_list;

#define FSDEM__DEM_HELD (1 << 30) /* the entry's spring is live */
#define FSDEM__DEM_PARTNER(key) ((key) & ~FSDEM__DEM_HELD)
#define FSDEM__DEM_MAX_PARTICLES (FSDEM__DEM_HELD - 1) /* partners and wall keys stay below the flag */

/* One particle-wall contact of the current positions. */
typedef struct fsdem__dem_wall_hit {
    int entry;         /* index into the particle-wall list */
    fsdem_vec3 n;      /* unit normal from the wall towards the particle */
    fsdem_real delta;  /* m, overlap > 0 */
    int on_feature;    /* contact point on a triangle edge/vertex or a segment end */
} fsdem__dem_wall_hit;

#define FSDEM__DEM_WALL_KEY(wall, face) ((wall) * 8 + (face))
#define FSDEM__DEM_WALL_OF(key) (FSDEM__DEM_PARTNER(key) / 8)
#define FSDEM__DEM_FACE_OF(key) (FSDEM__DEM_PARTNER(key) % 8)

struct fsdem_dem {
    fsdem_dem_desc desc; /* dt_rule and dt_param resolved */
    fsdem__status status;
    fsdem_allocator allocator;
    fsdem_real dt;
    double time;
    long long steps, rebuilds;
    fsdem_real stable_dt; /* fsdem_dem_stable_dt at the last rebuild (0: no particles) */
    int dt_warned;        /* the dt warning was logged for the current dt and stable_dt */

    /* particles, structure of arrays */
    int n, capacity, next_id;
    int *id, *material, *old_of; /* old_of: row in the previous neighbour lists, -1 if new */
    unsigned char *fixed;
    fsdem_vec3 *x, *v, *w, *f, *t, *fext, *text, *x_ref;
    fsdem_vec3 *x0, *v0, *w0, *fa, *ta; /* predictor-corrector: start state and first forces */
    fsdem_real *r, *m, *inv_m, *inv_i;

    fsdem_dem_material *materials;
    int material_count, material_capacity;
    fsdem__dem_pair *pairs; /* material_count^2 */
    int pair_capacity;

    fsdem__dem_wall *walls;
    int wall_count, wall_capacity;

    fsdem__dem_list pp, pp_old, pw, pw_old;
    struct fsdem__dem_wall_hit *hits; /* scratch: one particle's wall contacts (fsdem__dem_wall_hits) */
    fsdem__arena arena;           /* per-step scratch of the force evaluation, reserved by rebuilds */
    int *found, found_capacity;   /* scratch of the rebuild: pairs within reach (fsdem__dem_find_pairs) */
    int *inert, inert_count, inert_capacity; /* pairs of fixed particles within reach (i, j), listed aside */
    int hit_capacity;
    fsdem_cellgrid grid;
    fsdem_real skin, r_max, max_disp2, k0_linear;
    int need_rebuild, forces_valid;
    int rolling;  /* some material pair has rolling resistance */
    int cohesive; /* some material pair has cohesion */
    int periodic; /* some axis is periodic (>>dem_periodic) */
    fsdem_real period[3], inv_period[3]; /* m, 1/m; 0 along the other axes */
    int external; /* fext/text may be nonzero (fsdem_dem_get_coupling handed them out, or a coupler wrote them) */
    int forces_cleared; /* f and t were zeroed by the last Verlet pass, for the force evaluation */
    int contacts, wall_contacts;
    fsdem_real max_overlap;
};

/* ---- >>dem_desc : defaults and validation ---- */

fsdem_dem_material fsdem_dem_material_default(void) {
    fsdem_dem_material m;
    m.density = 2500;
    m.young_modulus = 1e8;
    m.poisson_ratio = (fsdem_real)0.3;
    m.restitution = (fsdem_real)0.5;
    m.friction = (fsdem_real)0.3;
    m.rolling_friction = 0;
    m.damping_alpha = (fsdem_real)0.4;
    m.cohesion = 0;
    return m;
}

fsdem_dem_desc fsdem_dem_desc_default(int dim) {
    fsdem_dem_desc d;
    memset(&d, 0, sizeof d);
    d.dim = dim;
    d.domain_min = fsdem_v3(-1, -1, -1);
    d.domain_max = fsdem_v3(1, 1, 1);
    d.gravity = dim == 2 ? fsdem_v3(0, (fsdem_real)-9.81, 0) : fsdem_v3(0, 0, (fsdem_real)-9.81);
    d.law = FSDEM_DEM_LAW_HERTZ_MINDLIN;
    d.integrator = FSDEM_DEM_INTEGRATOR_VERLET;
    d.dt = (fsdem_real)1e-5;
    d.dt_rule = FSDEM_DEM_DT_RULE_AUTO;
    d.dt_param = 0;
    d.skin = -1;
    d.contact_offset = 0;
    d.linear_theta = (fsdem_real)0.01;
    d.linear_dx = 0;
    d.linear_accel = 0;
    d.disc_length = 1;
    d.rotation = 1;
    d.tangential_damping = 1;
    d.tangential_history = FSDEM_DEM_TANGENTIAL_HISTORY_INCREMENTAL;
    d.coulomb_limit = FSDEM_DEM_COULOMB_LIMIT_TOTAL;
    d.linear_stiffness = FSDEM_DEM_LINEAR_STIFFNESS_SEED000;
    d.capacity = 1024;
    return d;
}

/* The linear law with the stiffness of seed 000 Eq. 10 (theta, dx, ||g||). */
static int fsdem__dem_seed000_stiffness(const fsdem_dem_desc *d) {
    return d->law == FSDEM_DEM_LAW_LINEAR && d->linear_stiffness == FSDEM_DEM_LINEAR_STIFFNESS_SEED000;
}

fsdem_result fsdem_dem_desc_check(const fsdem_dem_desc *d, char *msg, size_t size) {
    int axis;
    if (!d) return fsdem__reject(msg, size, "fsdem_dem_desc is NULL");
    if (d->dim != 2 && d->dim != 3)
        return fsdem__reject(msg, size, "fsdem_dem_desc.dim must be 2 or 3 (got %d)", d->dim);
    if (!fsdem__finite3(d->domain_min) || !fsdem__finite3(d->domain_max))
        return fsdem__reject(msg, size, "fsdem_dem_desc.domain_min/domain_max must be finite");
    for (axis = 0; axis < d->dim; ++axis)
        if (!(fsdem__comp(d->domain_max, axis) > fsdem__comp(d->domain_min, axis)) ||
            !fsdem__finite(fsdem__comp(d->domain_max, axis) - fsdem__comp(d->domain_min, axis)))
            return fsdem__reject(msg, size, "fsdem_dem_desc.domain_max must exceed domain_min by a finite extent on axis %d",
                                 axis);
    if (fsdem__check_gravity("fsdem_dem_desc", d->gravity, d->dim, msg, size) != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    if (d->law != FSDEM_DEM_LAW_LINEAR && d->law != FSDEM_DEM_LAW_HERTZ_MINDLIN && d->law != FSDEM_DEM_LAW_GIC)
        return fsdem__reject(msg, size, "fsdem_dem_desc.law is not a fsdem_dem_law (%d)", (int)d->law);
    if (d->integrator != FSDEM_DEM_INTEGRATOR_VERLET && d->integrator != FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR)
        return fsdem__reject(msg, size, "fsdem_dem_desc.integrator is not a fsdem_dem_integrator (%d)",
                             (int)d->integrator);
    if (!(d->dt > 0) || !fsdem__finite(d->dt))
        return fsdem__reject(msg, size, "fsdem_dem_desc.dt must be > 0 and finite (got %g s)", (double)d->dt);
    if ((int)d->dt_rule < (int)FSDEM_DEM_DT_RULE_AUTO || (int)d->dt_rule > (int)FSDEM_DEM_DT_RULE_GIC)
        return fsdem__reject(msg, size, "fsdem_dem_desc.dt_rule is not a fsdem_dem_dt_rule (%d)", (int)d->dt_rule);
    if (!(d->dt_param >= 0) || !fsdem__finite(d->dt_param))
        return fsdem__reject(msg, size, "fsdem_dem_desc.dt_param must be >= 0 (got %g)", (double)d->dt_param);
    if (d->dt_param > 1 && d->dt_rule != FSDEM_DEM_DT_RULE_LINEAR_SEED000 &&
        !(d->dt_rule == FSDEM_DEM_DT_RULE_AUTO && fsdem__dem_seed000_stiffness(d)))
        return fsdem__reject(msg, size, "fsdem_dem_desc.dt_param: a safety fraction must be in (0, 1] (got %g)",
                             (double)d->dt_param);
    if (d->tangential_damping != 0 && d->tangential_damping != 1)
        return fsdem__reject(msg, size, "fsdem_dem_desc.tangential_damping must be 0 or 1 (got %d)", d->tangential_damping);
    if ((int)d->tangential_history < 0 || (int)d->tangential_history > 1)
        return fsdem__reject(msg, size, "fsdem_dem_desc.tangential_history is not a fsdem_dem_tangential_history (%d)",
                             (int)d->tangential_history);
    if ((int)d->coulomb_limit < 0 || (int)d->coulomb_limit > 1)
        return fsdem__reject(msg, size, "fsdem_dem_desc.coulomb_limit is not a fsdem_dem_coulomb_limit (%d)", (int)d->coulomb_limit);
    for (axis = 0; axis < 3; ++axis)
        if (d->periodic[axis] != 0 && (d->periodic[axis] != 1 || axis >= d->dim))
            return fsdem__reject(msg, size, "fsdem_dem_desc.periodic[%d] = %d must be 0 or 1 (0 for z in 2D)", axis, d->periodic[axis]);
    if ((int)d->linear_stiffness < 0 || (int)d->linear_stiffness > 1)
        return fsdem__reject(msg, size, "fsdem_dem_desc.linear_stiffness is not a fsdem_dem_linear_stiffness (%d)",
                             (int)d->linear_stiffness);
    if (d->dt_rule == FSDEM_DEM_DT_RULE_LINEAR_SEED000 && !fsdem__dem_seed000_stiffness(d))
        return fsdem__reject(msg, size,
                             "fsdem_dem_desc.dt_rule FSDEM_DEM_DT_RULE_LINEAR_SEED000 needs the linear law with seed 000's stiffness");
    if (!fsdem__finite(d->skin)) return fsdem__reject(msg, size, "fsdem_dem_desc.skin is not finite");
    if (!(d->contact_offset >= 0) || !fsdem__finite(d->contact_offset))
        return fsdem__reject(msg, size, "fsdem_dem_desc.contact_offset must be >= 0 (got %g m)",
                             (double)d->contact_offset);
    if (!(d->disc_length > 0) || !fsdem__finite(d->disc_length))
        return fsdem__reject(msg, size, "fsdem_dem_desc.disc_length must be > 0 (got %g m)", (double)d->disc_length);
    if (d->capacity < 0) return fsdem__reject(msg, size, "fsdem_dem_desc.capacity must be >= 0");
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        return fsdem__reject(msg, size, "fsdem_dem_desc.allocator: set both alloc and free, or neither");
    if (fsdem__dem_seed000_stiffness(d)) {
        fsdem_real accel = d->linear_accel > 0 ? d->linear_accel : fsdem__norm(d->gravity);
        if (!(d->linear_theta > 0) || !fsdem__finite(d->linear_theta))
            return fsdem__reject(msg, size, "fsdem_dem_desc.linear_theta must be > 0 (got %g)", (double)d->linear_theta);
        if (!(d->linear_dx > 0) || !fsdem__finite(d->linear_dx))
            return fsdem__reject(msg, size, "fsdem_dem_desc.linear_dx must be > 0 for the linear law (got %g m)",
                                 (double)d->linear_dx);
        if (!(d->linear_accel >= 0) || !fsdem__finite(d->linear_accel))
            return fsdem__reject(msg, size, "fsdem_dem_desc.linear_accel must be >= 0 (got %g)", (double)d->linear_accel);
        if (!(accel > 0))
            return fsdem__reject(msg, size, "fsdem_dem_desc: the linear law needs ||g|| > 0 in seed 000 Eq. 10: set "
                                            "fsdem_dem_desc.linear_accel when gravity is zero");
    }
    return FSDEM_OK;
}

static fsdem_result fsdem__dem_material_check(const fsdem_dem_material *m, char *msg, size_t size) {
    if (!m) return fsdem__reject(msg, size, "fsdem_dem_material is NULL");
    if (!(m->density > 0) || !fsdem__finite(m->density))
        return fsdem__reject(msg, size, "fsdem_dem_material.density must be > 0 (got %g kg/m^3)", (double)m->density);
    /* a rigid wall is a stiff finite material: two infinite moduli would meet in a NaN */
    if (!(m->young_modulus > 0 && m->young_modulus <= FSDEM_MAX_MODULUS))
        return fsdem__reject(msg, size, "fsdem_dem_material.young_modulus must be in (0, %g] Pa (got %g Pa)",
                             (double)FSDEM_MAX_MODULUS, (double)m->young_modulus);
    if (!(m->poisson_ratio > -1 && m->poisson_ratio <= (fsdem_real)0.5))
        return fsdem__reject(msg, size, "fsdem_dem_material.poisson_ratio must be in (-1, 0.5] (got %g)",
                             (double)m->poisson_ratio);
    if (!(m->restitution >= (fsdem_real)1e-6 && m->restitution <= 1))
        return fsdem__reject(msg, size, "fsdem_dem_material.restitution must be in [1e-6, 1] (got %g)", (double)m->restitution);
    if (!(m->friction >= 0) || !fsdem__finite(m->friction))
        return fsdem__reject(msg, size, "fsdem_dem_material.friction must be >= 0 (got %g)", (double)m->friction);
    if (!(m->rolling_friction >= 0) || !fsdem__finite(m->rolling_friction))
        return fsdem__reject(msg, size, "fsdem_dem_material.rolling_friction must be >= 0 (got %g)",
                             (double)m->rolling_friction);
    if (!(m->damping_alpha >= 0) || !fsdem__finite(m->damping_alpha))
        return fsdem__reject(msg, size, "fsdem_dem_material.damping_alpha must be >= 0 (got %g)", (double)m->damping_alpha);
    if (!(m->cohesion >= 0) || !fsdem__finite(m->cohesion))
        return fsdem__reject(msg, size, "fsdem_dem_material.cohesion must be >= 0 (got %g J/m^3)", (double)m->cohesion);
    return FSDEM_OK;
}

static const char *fsdem__dem_rule_name(fsdem_dem_dt_rule rule) {
    switch (rule) {
    case FSDEM_DEM_DT_RULE_LINEAR_SEED000: return "seed 000 Eq. 18";
    case FSDEM_DEM_DT_RULE_RAYLEIGH: return "Rayleigh time, seed 002 Eq. 38";
    case FSDEM_DEM_DT_RULE_GIC: return "seed 004 Eq. 32";
    default: return "?";
    }
}

/* The stable dt of the current particles by the resolved rule (+inf without particles). */
static fsdem_real fsdem__dem_rule_dt(const fsdem_dem *d) {
    fsdem_real best = (fsdem_real)HUGE_VAL;
    const fsdem_real param = d->desc.dt_param;
    int i;
    switch (d->desc.dt_rule) {
    case FSDEM_DEM_DT_RULE_LINEAR_SEED000:
        /* Eq. 18 with Eq. 10: m_ij / k = theta dx / ||g|| whatever the masses */
        return d->n ? (fsdem_real)(2 * FSDEM__PI) / param / (fsdem_real)sqrt(d->k0_linear) : best;
    case FSDEM_DEM_DT_RULE_RAYLEIGH:
        /* seed 002 Eq. 38 prints 0.01631; the Rayleigh-wave fit it cites (Thornton & Randall 1988)
           is 0.1631 nu + 0.8766, which we use. */
        for (i = 0; i < d->n; ++i) {
            const fsdem_dem_material *m = &d->materials[d->material[i]];
            fsdem_real t = (fsdem_real)FSDEM__PI * d->r[i] *
                           (fsdem_real)sqrt(2 * m->density * (1 + m->poisson_ratio) / m->young_modulus) /
                           ((fsdem_real)0.1631 * m->poisson_ratio + (fsdem_real)0.8766);
            if (t < best) best = t;
        }
        return best * param;
    default:
        for (i = 0; i < d->n; ++i) {
            fsdem_real kn = d->materials[d->material[i]].young_modulus * d->r[i]; /* Eq. 32: k_n = E r */
            fsdem_real t = (fsdem_real)0.5 * (fsdem_real)sqrt(d->m[i] / kn);
            if (t < best) best = t;
        }
        return best * param;
    }
}

/* Refreshes stable_dt (at rebuilds and dt changes) and logs a warning once per change when dt
   exceeds it, as LIGGGHTS' fix check/timestep/gran does: such a run loses energy conservation
   long before a particle leaves the domain. */
static void fsdem__dem_dt_check(fsdem_dem *d) {
    /* no particles: no estimate (and no arithmetic on its infinity, which raises FE_INVALID) */
    const fsdem_real stable = d->n > 0 ? fsdem__dem_rule_dt(d) : 0;
    if (stable != d->stable_dt) d->dt_warned = 0;
    d->stable_dt = stable;
    if (stable > 0 && d->dt > stable && !d->dt_warned && d->status.log) {
        char msg[FSDEM__MESSAGE_SIZE];
        snprintf(msg, sizeof msg, "fsdem_dem: dt = %g s is %.3g times the stable dt %g s (%s)", (double)d->dt,
                 (double)(d->dt / stable), (double)stable, fsdem__dem_rule_name(d->desc.dt_rule));
        d->status.log(d->status.log_user, FSDEM_LOG_LEVEL_WARNING, msg);
        d->dt_warned = 1;
    }
}

/* ---- >>dem_law : contact laws ---- */

/* Restitution of the dimensionless Hertz contact with Tsuji-form damping,
       x'' = -max(0, x^(3/2) + a x^(1/4) x'),   x(0) = 0, x'(0) = 1,
   which is the contact m d'' = -k d^(3/2) - a sqrt(m k) d^(1/4) d' scaled by t0 = (m/(k v0^0.5))^0.4,
   d0 = v0 t0. The scaling removes m, k and v0, so e depends on a alone (Tsuji et al. 1992), and the
   force is clamped at zero (no adhesion) as it is in the simulation. Integrated with RK4. */
static double fsdem__dem_hertz_restitution(double a) {
    double x = 0, v = 1, h = 4e-3 / (1 + a); /* ~800 steps per contact: e to about 1e-6 */
    int step;
    for (step = 0; step < 100000000; ++step) {
        double k1x, k1v, k2x, k2v, k3x, k3v, k4x, k4v, xs, vs, xn, vn;
#define FSDEM__DEM_HERTZ_ACC(X, V) (-fmax(0.0, fmax(X, 0.0) * sqrt(fmax(X, 0.0)) + a * sqrt(sqrt(fmax(X, 0.0))) * (V)))
        k1x = v;
        k1v = FSDEM__DEM_HERTZ_ACC(x, v);
        xs = x + 0.5 * h * k1x;
        vs = v + 0.5 * h * k1v;
        k2x = vs;
        k2v = FSDEM__DEM_HERTZ_ACC(xs, vs);
        xs = x + 0.5 * h * k2x;
        vs = v + 0.5 * h * k2v;
        k3x = vs;
        k3v = FSDEM__DEM_HERTZ_ACC(xs, vs);
        xs = x + h * k3x;
        vs = v + h * k3v;
        k4x = vs;
        k4v = FSDEM__DEM_HERTZ_ACC(xs, vs);
#undef FSDEM__DEM_HERTZ_ACC
        xn = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
        vn = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
        /* Once the clamped force vanishes on the way out (v < 0) it stays zero (the elastic term
           falls faster than the damping one as x shrinks at constant v): the particle coasts off
           at -vn. Stopping here, not at x = 0, bounds the work for heavy damping, where the
           coasting tail would take ever longer. */
        if (step > 0 && vn < 0 && (xn <= 0 || xn * sqrt(xn) + a * sqrt(sqrt(xn)) * vn <= 0)) return -vn;
        x = xn;
        v = vn;
    }
    return 0;
}

/* Damping coefficient a whose restitution is e (bisection; e decreases monotonically with a): a
   bracket [0, hi <= 1e4] and 40 halvings, each an integration of at most ~1e5 steps (a = 1e4 gives
   e ~ 1e-8), so it takes milliseconds for any e in the accepted range [1e-6, 1]. */
static fsdem_real fsdem__dem_tsuji_coefficient(fsdem_real e) {
    double lo = 0, hi = 1, mid = 0;
    int it;
    if (e >= 1) return 0;
    while (fsdem__dem_hertz_restitution(hi) > e && hi < 1e4) hi *= 2;
    for (it = 0; it < 40; ++it) {
        mid = 0.5 * (lo + hi);
        if (fsdem__dem_hertz_restitution(mid) > e) lo = mid;
        else hi = mid;
    }
    return (fsdem_real)(0.5 * (lo + hi));
}

/* The law's coefficients of a pair from its moduli and its (mixed or set) properties. `known`
   (known_count pairs) are pairs set up before, whose Hertz damping calibration is reused for a
   restitution seen before: it costs a few milliseconds. */
static void fsdem__dem_pair_coefficients(fsdem__dem_pair *p, const fsdem_dem_desc *desc, fsdem_real k0_linear,
                                         const fsdem__dem_pair *known, int known_count) {
    const fsdem_real e = p->restitution;
    int k;
    p->tsuji = 0;
    if (desc->law == FSDEM_DEM_LAW_HERTZ_MINDLIN) {
        for (k = 0; k < known_count && known[k].restitution != e; ++k) {
        }
        p->tsuji = k < known_count ? known[k].tsuji : fsdem__dem_tsuji_coefficient(e);
    }
    if (fsdem__dem_seed000_stiffness(desc)) {
        p->kn = k0_linear;
        p->cn = 2 * p->alpha * (fsdem_real)sqrt(k0_linear);
        p->kt = 1 / (2 * (1 + p->nu));
        p->ct = 1 / (fsdem_real)sqrt(2 * (1 + p->nu));
    } else if (desc->law == FSDEM_DEM_LAW_LINEAR) { /* seed 002 Eq. 21-24 */
        const double ln_e = log((double)e);
        p->kn = (fsdem_real)(4.0 / 3.0) * p->e_star;
        p->cn = (fsdem_real)(-2 * ln_e / sqrt(ln_e * ln_e + FSDEM__PI * FSDEM__PI));
        p->kt = 1 / (2 + p->nu);
        p->ct = (fsdem_real)sqrt(p->kt);
    } else if (desc->law == FSDEM_DEM_LAW_GIC) {
        p->kn = 2 * p->e_pair;
        p->cn = p->ct = 0;
        p->kt = 1 / (2 * (1 + p->nu));
    } else {
        p->kn = (fsdem_real)(4.0 / 3.0) * p->e_star;
        p->cn = p->tsuji * p->tsuji * p->kn;
        p->kt = 8 * p->g_star;
        p->ct = (fsdem_real)sqrt(4 * p->g_star / p->e_star);
    }
    if (!desc->tangential_damping && desc->law != FSDEM_DEM_LAW_GIC) p->ct = 0;
}

/* A pair of materials: moduli, and the means of their contact properties (fsdem_dem_material_pair). */
static void fsdem__dem_pair_setup(fsdem__dem_pair *p, const fsdem_dem_material *a, const fsdem_dem_material *b, const fsdem_dem_desc *desc,
                                  fsdem_real k0_linear, const fsdem__dem_pair *known, int known_count) {
    fsdem_real ea = a->young_modulus, eb = b->young_modulus, na = a->poisson_ratio, nb = b->poisson_ratio;
    const fsdem_real ia = 1 / ea, ib = 1 / eb;
    fsdem_real inv_e = (1 - na * na) * ia + (1 - nb * nb) * ib;
    fsdem_real inv_g = 2 * (2 - na) * (1 + na) * ia + 2 * (2 - nb) * (1 + nb) * ib;
    fsdem_real inv_ep = ia + ib;
    p->e_star = 1 / inv_e;
    p->g_star = 1 / inv_g;
    p->e_pair = 2 / inv_ep;
    p->nu = (na + nb) / 2;
    p->alpha = (a->damping_alpha + b->damping_alpha) / 2;
    p->friction = (a->friction + b->friction) / 2;
    p->rolling = (a->rolling_friction + b->rolling_friction) / 2;
    p->restitution = (a->restitution + b->restitution) / 2;
    p->cohesion = (a->cohesion + b->cohesion) / 2;
    fsdem__dem_pair_coefficients(p, desc, k0_linear, known, known_count);
}

/* Contacts in structure-of-arrays form, up to FSDEM__DEM_BATCH at a time, for the vector kernel below
   (fsdem__dem_compute_forces fills and drains them). A particle pair enters as the bodies' data, which
   the kernel turns into a contact; a wall contact enters as a contact. */
#define FSDEM__DEM_BATCH 32

typedef struct fsdem__dem_batch {
    int count;
    int i[FSDEM__DEM_BATCH];     /* particle */
    int other[FSDEM__DEM_BATCH]; /* partner particle, or wall index */
    int entry[FSDEM__DEM_BATCH]; /* neighbour-list entry (its spring) */
    int pair[FSDEM__DEM_BATCH];  /* material pair */
    /* particle pairs: geometry input */
    fsdem_real dx[3][FSDEM__DEM_BATCH];       /* m, x_i - x_j */
    fsdem_real dv[3][FSDEM__DEM_BATCH];       /* m/s, v_i - v_j */
    fsdem_real wi[3][FSDEM__DEM_BATCH], wj[3][FSDEM__DEM_BATCH]; /* rad/s */
    fsdem_real ri[FSDEM__DEM_BATCH], rj[FSDEM__DEM_BATCH];       /* m */
    fsdem_real inv_mi[FSDEM__DEM_BATCH], inv_mj[FSDEM__DEM_BATCH]; /* 1/kg */
    /* the contact: law input */
    fsdem_real n[3][FSDEM__DEM_BATCH];    /* unit normal from the partner to i */
    fsdem_real delta[FSDEM__DEM_BATCH];   /* m, overlap > 0 */
    fsdem_real vrel[3][FSDEM__DEM_BATCH]; /* m/s, velocity of i's contact point relative to the partner's */
    fsdem_real m_eff[FSDEM__DEM_BATCH];   /* kg, reduced mass (m_i for a wall) */
    fsdem_real m_mean[FSDEM__DEM_BATCH];  /* kg, m_ij = (m_i + m_j)/2 of seed 000 Eq. 10 (m_i for a wall) */
    fsdem_real r_eff[FSDEM__DEM_BATCH];   /* m, R* = r_i r_j/(r_i + r_j) (r_i for a wall) */
    fsdem_real arm_i[FSDEM__DEM_BATCH];   /* m, centre of i to the contact point */
    fsdem_real kn[FSDEM__DEM_BATCH], cn[FSDEM__DEM_BATCH], kt[FSDEM__DEM_BATCH], ct[FSDEM__DEM_BATCH]; /* fsdem__dem_pair */
    fsdem_real mu[FSDEM__DEM_BATCH];      /* -, Coulomb coefficient */
    fsdem_real coh[FSDEM__DEM_BATCH];     /* J/m^3, cohesion energy density */
    fsdem_real spring[3][FSDEM__DEM_BATCH]; /* m, tangential spring: held value in, new value out */
    /* output */
    fsdem_real force[3][FSDEM__DEM_BATCH];    /* N, on i */
    fsdem_real torque_i[3][FSDEM__DEM_BATCH]; /* N m, on i */
    fsdem_real torque_j[3][FSDEM__DEM_BATCH]; /* N m, on the partner particle */
    fsdem_real fn[FSDEM__DEM_BATCH];          /* N, normal force */
} fsdem__dem_batch;

/* Copies contact 0 into the lanes after `count` up to a whole lane, so the kernel sees real data
   there: the pair input for a batch of particle pairs (`pairs`), the contact otherwise, and the
   coefficients unless the batch is `uniform`. */
static void fsdem__dem_batch_pad(fsdem__dem_batch *b, int pairs, int uniform) {
    int c, a;
    for (c = b->count; c % FSDEM__LANES; ++c) {
        for (a = 0; a < 3; ++a) {
            if (pairs) {
                b->dx[a][c] = b->dx[a][0];
                b->dv[a][c] = b->dv[a][0];
                b->wi[a][c] = b->wi[a][0];
                b->wj[a][c] = b->wj[a][0];
            } else {
                b->n[a][c] = b->n[a][0];
                b->vrel[a][c] = b->vrel[a][0];
            }
            b->spring[a][c] = b->spring[a][0];
        }
        if (pairs) {
            b->ri[c] = b->ri[0];
            b->rj[c] = b->rj[0];
            b->inv_mi[c] = b->inv_mi[0];
            b->inv_mj[c] = b->inv_mj[0];
        } else {
            b->delta[c] = b->delta[0];
            b->m_eff[c] = b->m_eff[0];
            b->r_eff[c] = b->r_eff[0];
            b->arm_i[c] = b->arm_i[0];
        }
        b->m_mean[c] = b->m_mean[0]; /* may be unset (laws that do not read it): copied, never used */
        if (!uniform) {
            b->kn[c] = b->kn[0];
            b->cn[c] = b->cn[0];
            b->kt[c] = b->kt[0];
            b->ct[c] = b->ct[0];
            b->mu[c] = b->mu[0];
            b->coh[c] = b->coh[0];
        }
    }
}

#define FSDEM__DEM_LOAD3(v, arr, c)                \
    v##x = fsdem__lane_load(&(arr)[0][c]);     \
    v##y = fsdem__lane_load(&(arr)[1][c]);     \
    v##z = fsdem__lane_load(&(arr)[2][c])
#define FSDEM__DEM_STORE3(arr, c, vx, vy, vz)      \
    fsdem__lane_store(&(arr)[0][c], vx);       \
    fsdem__lane_store(&(arr)[1][c], vy);       \
    fsdem__lane_store(&(arr)[2][c], vz)

/* One lane-wide group of contacts as the law kernels see them: unit normal n (from the partner to
   i), overlap, tangential relative velocity v_t, normal relative speed vn, effective mass and
   radius, the pair coefficients (fsdem__dem_pair) and the Coulomb coefficient. */
typedef struct fsdem__dem_lanes {
    fsdem__lane nx, ny, nz, vx, vy, vz, vn, delta, m_eff, r_eff, kn, cn, kt, ct, mu;
} fsdem__dem_lanes;

/* The contact options of a simulation as the kernels read them (fsdem_dem_desc, >>dem). */
typedef struct fsdem__dem_rules {
    int total_history;      /* FSDEM_DEM_TANGENTIAL_HISTORY_TOTAL */
    int cap_spring;         /* FSDEM_DEM_COULOMB_LIMIT_SPRING */
    int cohesion;           /* some material pair is cohesive: add the attraction k A */
    fsdem_real offset;      /* m, the contact offset: the spheres of the cohesive area are r + offset/2 */
    fsdem_real area_depth;  /* m, 2D: the disc length (the area is the chord times it); 3D: 0 (pi a^2) */
} fsdem__dem_rules;

/* The linear law with seed 002's stiffness, as the kernels are instantiated for it (not public: a
   fsdem_dem_linear_stiffness of FSDEM_DEM_LAW_LINEAR). */
#define FSDEM__DEM_LAW_SEED002 ((fsdem_dem_law)3)

/* Coulomb cap |F_t| <= ft_max on a tangential force (seed 000 Eq. 15, seed 004 Eq. 1b), for the laws
   without a tangential history. */
FSDEM__FORCE_INLINE void fsdem__dem_coulomb_cap(fsdem__lane ft_max, fsdem__lane *tx, fsdem__lane *ty, fsdem__lane *tz) {
    const fsdem__lane one = fsdem__lane_set(1), ft2 = *tx * *tx + *ty * *ty + *tz * *tz;
    const fsdem__mask slide = ft2 > ft_max * ft_max;
    const fsdem__lane scale = fsdem__lane_select(slide, ft_max / fsdem__lane_sqrt(fsdem__lane_select(slide, ft2, one)), one);
    *tx *= scale;
    *ty *= scale;
    *tz *= scale;
}

/* Linear spring-dashpot of seed 000 Eq. 7-13 with m_ij the mean mass `m`: k_n = m_ij ||g|| /
   (theta dx), c_n = 2 alpha sqrt(m_ij k_n), k_t = k_n/(2(1+psi)), c_t = c_n/sqrt(2(1+psi)); the
   tangential spring acts over one DEM step h (Eq. 8); no tension cut-off, as printed. Returns the
   normal force and writes the tangential one. */
FSDEM__FORCE_INLINE fsdem__lane fsdem__dem_law_linear(const fsdem__dem_lanes *k, fsdem__lane m, fsdem_real h, fsdem__lane *tx,
                                                     fsdem__lane *ty, fsdem__lane *tz) {
    const fsdem__lane g = -m * (k->kn * k->kt * h + k->cn * k->ct), fn = m * (k->kn * k->delta - k->cn * k->vn);
    *tx = g * k->vx;
    *ty = g * k->vy;
    *tz = g * k->vz;
    fsdem__dem_coulomb_cap(k->mu * fsdem__lane_max(fn, -fn), tx, ty, tz);
    return fn;
}

/* Granule-In-Cell law of seed 004 Eq. 1a-1c: k_n = E r for equal spheres (here E_pair 2 R*); the
   viscous tangential coefficient is not given in the seed: we take the critical damping of the
   tangential spring k_n/(2(1+nu)) (seed 000 Eq. 12). */
FSDEM__FORCE_INLINE fsdem__lane fsdem__dem_law_gic(const fsdem__dem_lanes *k, fsdem__lane *tx, fsdem__lane *ty, fsdem__lane *tz) {
    const fsdem__lane stiff = k->kn * k->r_eff, g = -2 * fsdem__lane_sqrt(k->m_eff * stiff * k->kt), fn = stiff * k->delta;
    *tx = g * k->vx;
    *ty = g * k->vy;
    *tz = g * k->vz;
    fsdem__dem_coulomb_cap(k->mu * fn, tx, ty, tz);
    return fn;
}

/* The tangential force of a spring with history (Hertz-Mindlin, seed 002's linear law): stiffness
   st, dashpot eta_t, Coulomb's limit ft_max = mu |F_n|; the spring of lane group c of the batch is
   updated in place by the rules of desc.tangential_history and desc.coulomb_limit (>>dem). While
   the contact slides, the spring carries the capped force alone: folding the dashpot term into the
   spring (-(F_t + eta_t v_t)/S_t) would store energy along the slip at first touch, where Hertz's
   eta_t ~ d^(1/4) outgrows mu F_n ~ d^(3/2). */
FSDEM__FORCE_INLINE void fsdem__dem_tangential_spring(const fsdem__dem_lanes *k, fsdem__dem_batch *b, int c, fsdem_real h,
                                                      const fsdem__dem_rules *rules, fsdem__lane st, fsdem__lane eta_t,
                                                      fsdem__lane ft_max, fsdem__lane *tx, fsdem__lane *ty, fsdem__lane *tz) {
    const fsdem__lane one = fsdem__lane_set(1);
    fsdem__lane sx, sy, sz, px, py, pz, sn, scale, ft2, inv;
    fsdem__mask slide;
    FSDEM__DEM_LOAD3(s, b->spring, c);
    if (rules->total_history) {
        /* the total displacement: the increment added in the fixed frame, its tangential part taken */
        sx += k->vx * h;
        sy += k->vy * h;
        sz += k->vz * h;
        sn = sx * k->nx + sy * k->ny + sz * k->nz;
        px = sx - sn * k->nx;
        py = sy - sn * k->ny;
        pz = sz - sn * k->nz;
    } else {
        /* the held spring, turned into the current tangent plane with its length kept; proj2 = 0
           leaves a zero spring, whatever finite scale multiplies it */
        const fsdem__lane len2 = sx * sx + sy * sy + sz * sz;
        fsdem__lane proj2;
        sn = sx * k->nx + sy * k->ny + sz * k->nz;
        sx -= sn * k->nx;
        sy -= sn * k->ny;
        sz -= sn * k->nz;
        proj2 = sx * sx + sy * sy + sz * sz;
        scale = fsdem__lane_sqrt(len2 / fsdem__lane_select(proj2 > 0, proj2, one));
        px = sx = sx * scale + k->vx * h;
        py = sy = sy * scale + k->vy * h;
        pz = sz = sz * scale + k->vz * h;
    }
    if (rules->cap_spring) {
        /* the spring alone within mu |F_n|, the dashpot added after */
        const fsdem__lane fs2 = st * st * (px * px + py * py + pz * pz);
        slide = fs2 > ft_max * ft_max;
        scale = fsdem__lane_select(slide, ft_max / fsdem__lane_sqrt(fsdem__lane_select(slide, fs2, one)), one);
        px *= scale;
        py *= scale;
        pz *= scale;
        *tx = -st * px - eta_t * k->vx;
        *ty = -st * py - eta_t * k->vy;
        *tz = -st * pz - eta_t * k->vz;
        FSDEM__DEM_STORE3(b->spring, c, fsdem__lane_select(slide, px, sx), fsdem__lane_select(slide, py, sy),
                          fsdem__lane_select(slide, pz, sz));
        return;
    }
    *tx = -st * px - eta_t * k->vx;
    *ty = -st * py - eta_t * k->vy;
    *tz = -st * pz - eta_t * k->vz;
    ft2 = *tx * *tx + *ty * *ty + *tz * *tz;
    slide = ft2 > ft_max * ft_max;
    /* sliding: cap at Coulomb, the spring -F_t / S_t; one division gives both 1/|F_t| and 1/S_t */
    ft2 = fsdem__lane_sqrt(fsdem__lane_select(slide, ft2, one)); /* |F_t| where sliding */
    inv = 1 / (ft2 * fsdem__lane_select(slide, st, one));        /* a sliding contact has S_t > 0 */
    scale = fsdem__lane_select(slide, ft_max * st * inv, one);
    *tx *= scale;
    *ty *= scale;
    *tz *= scale;
    inv = -ft2 * inv; /* -1/S_t where sliding */
    FSDEM__DEM_STORE3(b->spring, c, fsdem__lane_select(slide, *tx * inv, sx), fsdem__lane_select(slide, *ty * inv, sy),
                      fsdem__lane_select(slide, *tz * inv, sz));
}

/* Hertz-Mindlin. With s = sqrt(R* d): normal stiffness S_n = 2 E* s, elastic force (2/3) S_n d =
   (4/3) E* s d; tangential stiffness S_t = 8 G* s on the spring (seed 002 Eq. 20, Coulomb sliding).
   Damping eta = a sqrt((2/3) m* S), Tsuji's a sqrt(m* k) d^(1/4) with a calibrated from e
   (fsdem__dem_tsuji_coefficient), so eta_n = sqrt(cn m* s) and eta_t = ct eta_n. The normal force
   never turns attractive. */
FSDEM__FORCE_INLINE fsdem__lane fsdem__dem_law_hertz(const fsdem__dem_lanes *k, fsdem__dem_batch *b, int c, fsdem_real h,
                                                    const fsdem__dem_rules *rules, fsdem__lane *tx, fsdem__lane *ty, fsdem__lane *tz) {
    const fsdem__lane s = fsdem__lane_sqrt(k->r_eff * k->delta);
    const fsdem__lane eta_n = fsdem__lane_sqrt(k->cn * k->m_eff * s);
    const fsdem__lane fn = fsdem__lane_max(k->kn * s * k->delta - eta_n * k->vn, fsdem__lane_set(0));
    fsdem__dem_tangential_spring(k, b, c, h, rules, k->kt * s, k->ct * eta_n, k->mu * fn, tx, ty, tz);
    return fn;
}

/* The linear spring-dashpot of seed 002 Eq. 19-24 (fsdem_dem_linear_stiffness): chi^n = kn sqrt(R*),
   eta^n = cn sqrt(chi^n m*), chi^t = kt chi^n, eta^t = ct eta^n, the spring with history; no
   tension cut-off, as printed, so Coulomb's limit takes |F_n|. */
FSDEM__FORCE_INLINE fsdem__lane fsdem__dem_law_seed002(const fsdem__dem_lanes *k, fsdem__dem_batch *b, int c, fsdem_real h,
                                                      const fsdem__dem_rules *rules, fsdem__lane *tx, fsdem__lane *ty, fsdem__lane *tz) {
    const fsdem__lane chi = k->kn * fsdem__lane_sqrt(k->r_eff);
    const fsdem__lane eta_n = k->cn * fsdem__lane_sqrt(chi * k->m_eff);
    const fsdem__lane fn = chi * k->delta - eta_n * k->vn;
    fsdem__dem_tangential_spring(k, b, c, h, rules, k->kt * chi, k->ct * eta_n, k->mu * fsdem__lane_max(fn, -fn), tx, ty, tz);
    return fn;
}

/* The cohesive attraction k A of the simplified JKR model (fsdem_dem_material.cohesion): A is the
   area of the circle where a sphere of radius r1 meets its partner, pi a^2 with a^2 = h (2 r1 - h),
   h the height of the sphere's cap beyond the circle's plane: for two spheres of radii r1, r2 whose
   centres are d apart, overlapping by delta = r1 + r2 - d, h = delta (d + r2 - r1) / (2 d) (from the
   plane's distance to the first centre, (d^2 + r1^2 - r2^2) / (2 d)); for a plane wall h = delta.
   Written with h, a^2 is well conditioned where the overlap is a small difference of large
   positions. In 2D the area is the chord 2a times the disc length. */
FSDEM__FORCE_INLINE fsdem__lane fsdem__dem_cohesion(fsdem__lane coh, fsdem__lane r1, fsdem__lane h, const fsdem__dem_rules *rules) {
    const fsdem__lane a2 = fsdem__lane_max(h * (2 * r1 - h), fsdem__lane_set(0));
    return coh * (rules->area_depth > 0 ? 2 * fsdem__lane_sqrt(a2) * fsdem__lane_set(rules->area_depth)
                                       : (fsdem_real)FSDEM__PI * a2);
}

/* The contact law on every contact of a batch: force and torques, normal force, new spring (laws
   with history). With `pairs`, the contacts are first made from the particle-pair input: normal,
   overlap (offset `off` included), velocity of the contact point, effective mass and radius, lever
   arms (each body's radius less half the overlap). With `uniform`, every contact has that material
   pair and the batch holds no coefficients. `rules` are the contact options. Written once,
   branch-free, and inlined with a constant `law` and `pairs`. h is the step the spring and seed
   000's one-step tangential spring (Eq. 8) use. The normal force the law gives goes to b->fn
   (rolling resistance and Coulomb's limit take it); cohesion is added to the force after. */
FSDEM__FORCE_INLINE void fsdem__dem_batch_law(fsdem__dem_batch *b, const fsdem_dem_law law, fsdem_real h, const int pairs,
                                          fsdem_real off, const fsdem__dem_pair *uniform, const fsdem__dem_rules *rules) {
    const fsdem__lane one = fsdem__lane_set(1), zero = fsdem__lane_set(0);
    int c;
    for (c = 0; c < b->count; c += FSDEM__LANES) {
        fsdem__dem_lanes k;
        fsdem__lane tx, ty, tz, mx, my, mz, arm_i, arm_j, fn, pull = zero;
        if (pairs) {
            fsdem__lane dxx, dxy, dxz, wix, wiy, wiz, wjx, wjy, wjz, ax, ay, az, dist, q, safe, inv, vx, vy, vz;
            const fsdem__lane ri = fsdem__lane_load(&b->ri[c]), rj = fsdem__lane_load(&b->rj[c]);
            const fsdem__lane inv_m = fsdem__lane_load(&b->inv_mi[c]) + fsdem__lane_load(&b->inv_mj[c]);
            fsdem__mask apart;
            FSDEM__DEM_LOAD3(dx, b->dx, c);
            FSDEM__DEM_LOAD3(v, b->dv, c);
            FSDEM__DEM_LOAD3(wi, b->wi, c);
            FSDEM__DEM_LOAD3(wj, b->wj, c);
            dist = fsdem__lane_sqrt(dxx * dxx + dxy * dxy + dxz * dxz);
            /* 1/dist and 1/q, q = (1/m_i + 1/m_j)(r_i + r_j) > 0, from one division; coincident
               centres (dx = 0) take the normal (1, 0, 0) */
            apart = dist > 0;
            safe = fsdem__lane_select(apart, dist, one);
            q = inv_m * (ri + rj);
            inv = 1 / (safe * q);
            k.nx = fsdem__lane_select(apart, dxx * (q * inv), one);
            k.ny = dxy * (q * inv);
            k.nz = dxz * (q * inv);
            /* >= 0: the pair touched (d^2 < reach^2), but sqrt may round dist up to the reach */
            k.delta = fsdem__lane_max(ri + rj + off - dist, zero);
            arm_i = ri - k.delta * (fsdem_real)0.5;
            arm_j = rj - k.delta * (fsdem_real)0.5;
            /* m* = 1/(1/m_i + 1/m_j) = (r_i + r_j)/q, R* = r_i r_j/(r_i + r_j) = r_i r_j (1/m_i + 1/m_j)/q */
            k.m_eff = (ri + rj) * (safe * inv);
            k.r_eff = ri * rj * inv_m * (safe * inv);
            /* contact-point velocity: v_i - v_j - (w_i l_i + w_j l_j) x n */
            ax = wix * arm_i + wjx * arm_j;
            ay = wiy * arm_i + wjy * arm_j;
            az = wiz * arm_i + wjz * arm_j;
            k.vx = vx - (ay * k.nz - az * k.ny);
            k.vy = vy - (az * k.nx - ax * k.nz);
            k.vz = vz - (ax * k.ny - ay * k.nx);
            fsdem__lane_store(&b->delta[c], k.delta);
            fsdem__lane_store(&b->r_eff[c], k.r_eff);
            if (rules->cohesion) {
                const fsdem__lane r1 = ri + (fsdem_real)0.5 * off, r2 = rj + (fsdem_real)0.5 * off;
                const fsdem__lane coh = uniform ? fsdem__lane_set(uniform->cohesion) : fsdem__lane_load(&b->coh[c]);
                pull = fsdem__dem_cohesion(coh, r1, k.delta * (dist + r2 - r1) / (2 * safe), rules);
            }
        } else {
            FSDEM__DEM_LOAD3(k.n, b->n, c);
            FSDEM__DEM_LOAD3(k.v, b->vrel, c);
            k.delta = fsdem__lane_load(&b->delta[c]);
            k.m_eff = fsdem__lane_load(&b->m_eff[c]);
            k.r_eff = fsdem__lane_load(&b->r_eff[c]);
            arm_i = fsdem__lane_load(&b->arm_i[c]);
            arm_j = zero;
            if (rules->cohesion) {
                const fsdem__lane r1 = k.r_eff + rules->offset;
                const fsdem__lane coh = uniform ? fsdem__lane_set(uniform->cohesion) : fsdem__lane_load(&b->coh[c]);
                pull = fsdem__dem_cohesion(coh, r1, k.delta, rules);
            }
        }
        if (uniform) {
            k.kn = fsdem__lane_set(uniform->kn);
            k.cn = fsdem__lane_set(uniform->cn);
            k.kt = fsdem__lane_set(uniform->kt);
            k.ct = fsdem__lane_set(uniform->ct);
            k.mu = fsdem__lane_set(uniform->friction);
        } else {
            k.kn = fsdem__lane_load(&b->kn[c]);
            k.cn = fsdem__lane_load(&b->cn[c]);
            k.kt = fsdem__lane_load(&b->kt[c]);
            k.ct = fsdem__lane_load(&b->ct[c]);
            k.mu = fsdem__lane_load(&b->mu[c]);
        }
        k.vn = k.vx * k.nx + k.vy * k.ny + k.vz * k.nz;
        k.vx -= k.vn * k.nx; /* tangential relative velocity */
        k.vy -= k.vn * k.ny;
        k.vz -= k.vn * k.nz;
        if (law == FSDEM_DEM_LAW_LINEAR) fn = fsdem__dem_law_linear(&k, fsdem__lane_load(&b->m_mean[c]), h, &tx, &ty, &tz);
        else if (law == FSDEM_DEM_LAW_GIC) fn = fsdem__dem_law_gic(&k, &tx, &ty, &tz);
        else if (law == FSDEM__DEM_LAW_SEED002) fn = fsdem__dem_law_seed002(&k, b, c, h, rules, &tx, &ty, &tz);
        else fn = fsdem__dem_law_hertz(&k, b, c, h, rules, &tx, &ty, &tz);
        fsdem__lane_store(&b->fn[c], fn);
        if (rules->cohesion) fn -= pull;
        FSDEM__DEM_STORE3(b->force, c, tx + fn * k.nx, ty + fn * k.ny, tz + fn * k.nz);
        /* torques: the arms point along -n from i and +n from the partner, torque = arm x F, and
           n x F = n x F_t */
        mx = k.ny * tz - k.nz * ty;
        my = k.nz * tx - k.nx * tz;
        mz = k.nx * ty - k.ny * tx;
        FSDEM__DEM_STORE3(b->torque_i, c, -arm_i * mx, -arm_i * my, -arm_i * mz);
        if (pairs) {
            FSDEM__DEM_STORE3(b->torque_j, c, -arm_j * mx, -arm_j * my, -arm_j * mz);
        }
    }
}

#undef FSDEM__DEM_LOAD3
#undef FSDEM__DEM_STORE3

/* Constant-torque rolling resistance on i: -mu_r R* |F_n| along the relative spin, limited so that
   it cannot reverse the relative spin within one step. */
static fsdem_vec3 fsdem__dem_rolling_torque(fsdem_vec3 w_rel, fsdem_real mu_r, fsdem_real r_eff, fsdem_real fn,
                                        fsdem_real inv_i_sum, fsdem_real h) {
    fsdem_real wlen = fsdem__norm(w_rel), tau = mu_r * r_eff * (fn < 0 ? -fn : fn), cap;
    if (wlen == 0 || tau == 0) return fsdem__zero3();
    cap = inv_i_sum > 0 ? wlen / (h * inv_i_sum) : tau;
    if (tau > cap) tau = cap;
    return fsdem__scale(w_rel, -tau / wlen);
}

/* ---- >>dem_periodic : periodic axes ----

   Along a periodic axis (desc.periodic) of period L, a pair interacts through its minimum image:
   the separation e loses the multiple of L nearest e / L. The neighbour lists are built on a cell
   grid whose neighbourhoods wrap round (fsdem_cellgrid_setup_periodic), their entries keep the
   pair and its spring whichever side of the seam the partners are on, and positions are brought
   back into [domain_min, domain_max) after every drift (with the rebuild reference x_ref, so the
   displacement since the last rebuild is unchanged). The minimum image is the only image in
   reach while L exceeds twice the neighbour reach 2 r_max + contact_offset + skin, which
   fsdem_dem_add_particle checks. */

/* The minimum image of a separation e. */
static fsdem_vec3 fsdem__dem_min_image(const fsdem_dem *d, fsdem_vec3 e) {
    if (d->periodic) {
        e.x -= d->period[0] * (fsdem_real)floor(e.x * d->inv_period[0] + (fsdem_real)0.5);
        e.y -= d->period[1] * (fsdem_real)floor(e.y * d->inv_period[1] + (fsdem_real)0.5);
        e.z -= d->period[2] * (fsdem_real)floor(e.z * d->inv_period[2] + (fsdem_real)0.5);
    }
    return e;
}

/* Where particle i sees particle j: j's image nearest i; j itself, bit for bit, along the axes no
   period separates them (x_i - (x_i - x_j) is x_j only to rounding). */
static fsdem_vec3 fsdem__dem_image_of(const fsdem_dem *d, int i, int j) {
    const fsdem_vec3 e = fsdem__sub(d->x[i], d->x[j]);
    return fsdem__add(d->x[j], fsdem__sub(e, fsdem__dem_min_image(d, e)));
}

/* Brings every position into [domain_min, domain_max) along the periodic axes, moving x_ref along. */
static void fsdem__dem_wrap(fsdem_dem *d) {
    int a, i;
    for (a = 0; a < 3; ++a) {
        const fsdem_real lo = fsdem__comp(d->desc.domain_min, a), hi = fsdem__comp(d->desc.domain_max, a), L = d->period[a];
        if (!(L > 0)) continue;
        for (i = 0; i < d->n; ++i) {
            const fsdem_real x = fsdem__comp(d->x[i], a);
            fsdem_real shift, wrapped;
            if (x >= lo && x < hi) continue;
            shift = L * (fsdem_real)floor((x - lo) * d->inv_period[a]);
            wrapped = x - shift;
            if (wrapped >= hi) { /* x - shift rounded up to the top */
                wrapped -= L;
                shift += L;
            }
            fsdem__set_comp(&d->x[i], a, wrapped);
            fsdem__set_comp(&d->x_ref[i], a, fsdem__comp(d->x_ref[i], a) - shift);
        }
    }
}

/* A particle of radius r keeps every minimum image unique: each period exceeds twice the reach of
   the neighbour lists with it. */
static fsdem_result fsdem__dem_period_check(fsdem_dem *d, fsdem_real r) {
    const fsdem_real r_max = r > d->r_max ? r : d->r_max, skin = d->desc.skin >= 0 ? d->desc.skin : (fsdem_real)0.25 * r_max;
    const fsdem_real reach = 2 * r_max + d->desc.contact_offset + skin;
    int a;
    for (a = 0; a < 3; ++a)
        if (d->period[a] > 0 && !(d->period[a] > 2 * reach))
            return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                               "fsdem_dem_particle_desc.radius %g m: the period %g m along %c must exceed twice the neighbour reach "
                               "2 r_max + contact_offset + skin = %g m",
                               (double)r, (double)d->period[a], "xyz"[a], (double)reach);
    return FSDEM_OK;
}

/* ---- >>dem_object : creation, materials, particles ---- */

/* Every per-particle array with its element size, so growth and removal treat them alike. */
#define FSDEM__DEM_PARTICLE_ARRAYS 21
static void fsdem__dem_particle_arrays(fsdem_dem *d, void **ptr[FSDEM__DEM_PARTICLE_ARRAYS],
                                   size_t size[FSDEM__DEM_PARTICLE_ARRAYS]) {
    int k = 0;
#define FSDEM__DEM_ARRAY(field)          \
    ptr[k] = (void **)&d->field;     \
    size[k++] = sizeof(*d->field)
    FSDEM__DEM_ARRAY(id); FSDEM__DEM_ARRAY(material); FSDEM__DEM_ARRAY(old_of); FSDEM__DEM_ARRAY(fixed);
    FSDEM__DEM_ARRAY(x); FSDEM__DEM_ARRAY(v); FSDEM__DEM_ARRAY(w); FSDEM__DEM_ARRAY(f); FSDEM__DEM_ARRAY(t);
    FSDEM__DEM_ARRAY(fext); FSDEM__DEM_ARRAY(text); FSDEM__DEM_ARRAY(x_ref);
    FSDEM__DEM_ARRAY(x0); FSDEM__DEM_ARRAY(v0); FSDEM__DEM_ARRAY(w0); FSDEM__DEM_ARRAY(fa); FSDEM__DEM_ARRAY(ta);
    FSDEM__DEM_ARRAY(r); FSDEM__DEM_ARRAY(m); FSDEM__DEM_ARRAY(inv_m); FSDEM__DEM_ARRAY(inv_i);
#undef FSDEM__DEM_ARRAY
    FSDEM_ASSERT(k == FSDEM__DEM_PARTICLE_ARRAYS);
}

/* Bytes of the per-particle arrays for `count` particles. */
static size_t fsdem__dem_particle_bytes(fsdem_dem *d, int count) {
    void **ptr[FSDEM__DEM_PARTICLE_ARRAYS];
    size_t size[FSDEM__DEM_PARTICLE_ARRAYS], total = 0;
    int k;
    fsdem__dem_particle_arrays(d, ptr, size);
    for (k = 0; k < FSDEM__DEM_PARTICLE_ARRAYS; ++k) total += size[k] * (size_t)count;
    return total;
}

static fsdem_result fsdem__dem_reserve_particles(fsdem_dem *d, int need) {
    void **ptr[FSDEM__DEM_PARTICLE_ARRAYS];
    void *fresh[FSDEM__DEM_PARTICLE_ARRAYS];
    size_t size[FSDEM__DEM_PARTICLE_ARRAYS];
    int k, cap = d->capacity > 0 ? d->capacity : 64;
    if (need <= d->capacity) return FSDEM_OK;
    if (need > FSDEM__DEM_MAX_PARTICLES) return FSDEM_ERR_OUT_OF_MEMORY;
    while (cap < need) cap = cap > FSDEM__DEM_MAX_PARTICLES / 2 ? FSDEM__DEM_MAX_PARTICLES : 2 * cap;
    fsdem__dem_particle_arrays(d, ptr, size);
    for (k = 0; k < FSDEM__DEM_PARTICLE_ARRAYS; ++k) {
        fresh[k] = fsdem__alloc(&d->allocator, size[k] * (size_t)cap);
        if (!fresh[k]) {
            while (k-- > 0) fsdem__free(&d->allocator, fresh[k], size[k] * (size_t)cap);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
    }
    for (k = 0; k < FSDEM__DEM_PARTICLE_ARRAYS; ++k) {
        if (d->n > 0) memcpy(fresh[k], *ptr[k], size[k] * (size_t)d->n);
        fsdem__free(&d->allocator, *ptr[k], size[k] * (size_t)d->capacity);
        *ptr[k] = fresh[k];
    }
    d->capacity = cap;
    return FSDEM_OK;
}

static void fsdem__dem_list_free_entries(fsdem_dem *d, fsdem__dem_list *l) {
    fsdem__free(&d->allocator, l->first, sizeof(int) * (size_t)l->capacity);
    fsdem__free(&d->allocator, l->key, sizeof(int) * (size_t)l->capacity);
    fsdem__free(&d->allocator, l->history, sizeof(fsdem_vec3) * (size_t)l->capacity);
}

static void fsdem__dem_list_free(fsdem_dem *d, fsdem__dem_list *l) {
    fsdem__free(&d->allocator, l->start, sizeof(int) * (size_t)l->start_capacity);
    fsdem__dem_list_free_entries(d, l);
    memset(l, 0, sizeof *l);
}

fsdem_result fsdem_dem_create(const fsdem_dem_desc *desc, fsdem_dem **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_dem *d;
    fsdem_result res;
    if (out) *out = NULL;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    res = fsdem_dem_desc_check(desc, msg, sizeof msg);
    d = (fsdem_dem *)fsdem__object_new(res, msg, desc ? desc->log : NULL, desc ? desc->log_user : NULL,
                                       desc ? &desc->allocator : NULL, sizeof *d, "fsdem_dem_create", &res);
    if (!d) return res;
    d->desc = *desc;
    if (desc->dt_rule == FSDEM_DEM_DT_RULE_AUTO)
        d->desc.dt_rule = fsdem__dem_seed000_stiffness(desc) ? FSDEM_DEM_DT_RULE_LINEAR_SEED000
                          : desc->law == FSDEM_DEM_LAW_GIC   ? FSDEM_DEM_DT_RULE_GIC
                                                             : FSDEM_DEM_DT_RULE_RAYLEIGH;
    if (desc->dt_param == 0)
        d->desc.dt_param = d->desc.dt_rule == FSDEM_DEM_DT_RULE_LINEAR_SEED000 ? 150
                           : d->desc.dt_rule == FSDEM_DEM_DT_RULE_RAYLEIGH   ? (fsdem_real)0.2
                                                                        : 1;
    d->allocator = desc->allocator;
    d->status.log = desc->log;
    d->status.log_user = desc->log_user;
    d->dt = desc->dt;
    d->grid.allocator = desc->allocator;
    d->need_rebuild = 1;
    {
        int a;
        for (a = 0; a < 3; ++a) {
            d->period[a] = desc->periodic[a] ? fsdem__comp(desc->domain_max, a) - fsdem__comp(desc->domain_min, a) : 0;
            d->inv_period[a] = desc->periodic[a] ? 1 / d->period[a] : 0;
            d->periodic |= desc->periodic[a];
        }
    }
    {
        fsdem_real accel = desc->linear_accel > 0 ? desc->linear_accel : fsdem__norm(desc->gravity);
        d->k0_linear = fsdem__dem_seed000_stiffness(desc) ? accel / (desc->linear_theta * desc->linear_dx) : 0;
    }
    res = fsdem__dem_reserve_particles(d, desc->capacity > 0 ? desc->capacity : 1);
    if (res != FSDEM_OK) {
        fsdem__log_oom(desc->log, desc->log_user, "fsdem_dem_create", fsdem__dem_particle_bytes(d, desc->capacity));
        fsdem_dem_destroy(d);
        return res;
    }
    *out = d;
    return FSDEM_OK;
}

void fsdem_dem_destroy(fsdem_dem *d) {
    void **ptr[FSDEM__DEM_PARTICLE_ARRAYS];
    size_t size[FSDEM__DEM_PARTICLE_ARRAYS];
    int k;
    fsdem_allocator al;
    if (!d) return;
    al = d->allocator;
    fsdem__dem_particle_arrays(d, ptr, size);
    for (k = 0; k < FSDEM__DEM_PARTICLE_ARRAYS; ++k) fsdem__free(&al, *ptr[k], size[k] * (size_t)d->capacity);
    fsdem__free(&al, d->materials, sizeof(fsdem_dem_material) * (size_t)d->material_capacity);
    fsdem__free(&al, d->pairs, sizeof(fsdem__dem_pair) * (size_t)d->pair_capacity);
    fsdem__free(&al, d->walls, sizeof(fsdem__dem_wall) * (size_t)d->wall_capacity);
    fsdem__dem_list_free(d, &d->pp);
    fsdem__dem_list_free(d, &d->pp_old);
    fsdem__dem_list_free(d, &d->pw);
    fsdem__dem_list_free(d, &d->pw_old);
    fsdem__free(&al, d->hits, sizeof(fsdem__dem_wall_hit) * (size_t)d->hit_capacity);
    fsdem__arena_free(&al, &d->arena);
    fsdem__free(&al, d->found, sizeof(int) * (size_t)d->found_capacity);
    fsdem__free(&al, d->inert, sizeof(int) * (size_t)d->inert_capacity);
    fsdem_cellgrid_free(&d->grid);
    fsdem__free(&al, d, sizeof *d);
}

const char *fsdem_dem_last_error(const fsdem_dem *d) { return d ? d->status.message : "fsdem_dem is NULL"; }

/* Whether some pair of materials has rolling resistance or cohesion (the force loop adds them only then). */
static void fsdem__dem_pair_flags(fsdem_dem *d) {
    int k;
    d->rolling = d->cohesive = 0;
    for (k = 0; k < d->material_count * d->material_count; ++k) {
        d->rolling |= d->pairs[k].rolling > 0;
        d->cohesive |= d->pairs[k].cohesion > 0;
    }
}

fsdem_result fsdem_dem_add_material(fsdem_dem *d, const fsdem_dem_material *mat, int *index) {
    char msg[FSDEM__MESSAGE_SIZE];
    int nm, a, b;
    fsdem__dem_pair *pairs;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    nm = d->material_count + 1;
    if (fsdem__dem_material_check(mat, msg, sizeof msg) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "%s", msg);
    if (fsdem__grow(&d->allocator, (void **)&d->materials, &d->material_capacity, d->material_count, nm,
                    sizeof(fsdem_dem_material)) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_dem_add_material: out of memory");
    pairs = (fsdem__dem_pair *)fsdem__alloc(&d->allocator, sizeof(fsdem__dem_pair) * (size_t)(nm * nm));
    if (!pairs) return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_dem_add_material: out of memory");
    d->materials[d->material_count] = *mat;
    for (a = 0; a < nm; ++a)
        for (b = 0; b < nm; ++b) {
            if (a < nm - 1 && b < nm - 1) pairs[a * nm + b] = d->pairs[a * (nm - 1) + b];
            else if (b < a) pairs[a * nm + b] = pairs[b * nm + a];
            else fsdem__dem_pair_setup(&pairs[a * nm + b], &d->materials[a], &d->materials[b], &d->desc, d->k0_linear,
                                   pairs, a * nm + b);
        }
    /* the loop reads earlier rows only, which are already in the new table */
    fsdem__free(&d->allocator, d->pairs, sizeof(fsdem__dem_pair) * (size_t)d->pair_capacity);
    d->pairs = pairs;
    d->pair_capacity = nm * nm;
    d->material_count = nm;
    fsdem__dem_pair_flags(d);
    d->forces_valid = 0;
    if (index) *index = nm - 1;
    return fsdem__ok(&d->status);
}

static fsdem_result fsdem__dem_material_pair_check(const fsdem_dem_material_pair *v, char *msg, size_t size) {
    if (!v) return fsdem__reject(msg, size, "fsdem_dem_set_material_pair: values is NULL");
    if (!(v->restitution >= (fsdem_real)1e-6 && v->restitution <= 1))
        return fsdem__reject(msg, size, "fsdem_dem_material_pair.restitution must be in [1e-6, 1] (got %g)", (double)v->restitution);
    if (!(v->friction >= 0) || !fsdem__finite(v->friction))
        return fsdem__reject(msg, size, "fsdem_dem_material_pair.friction must be >= 0 (got %g)", (double)v->friction);
    if (!(v->rolling_friction >= 0) || !fsdem__finite(v->rolling_friction))
        return fsdem__reject(msg, size, "fsdem_dem_material_pair.rolling_friction must be >= 0 (got %g)", (double)v->rolling_friction);
    if (!(v->cohesion >= 0) || !fsdem__finite(v->cohesion))
        return fsdem__reject(msg, size, "fsdem_dem_material_pair.cohesion must be >= 0 (got %g J/m^3)", (double)v->cohesion);
    return FSDEM_OK;
}

fsdem_result fsdem_dem_set_material_pair(fsdem_dem *d, int a, int b, const fsdem_dem_material_pair *values) {
    char msg[FSDEM__MESSAGE_SIZE];
    int k;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    if (a < 0 || a >= d->material_count || b < 0 || b >= d->material_count)
        return fsdem__fail(&d->status, FSDEM_ERR_NOT_FOUND, "fsdem_dem_set_material_pair: materials %d and %d (%d added)", a, b,
                           d->material_count);
    if (fsdem__dem_material_pair_check(values, msg, sizeof msg) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "%s", msg);
    for (k = 0; k < 2; ++k) {
        /* set up aside: the table, searched for a known Hertz calibration, still holds the old pair */
        fsdem__dem_pair *p = &d->pairs[k ? b * d->material_count + a : a * d->material_count + b], q = *p;
        q.restitution = values->restitution;
        q.friction = values->friction;
        q.rolling = values->rolling_friction;
        q.cohesion = values->cohesion;
        fsdem__dem_pair_coefficients(&q, &d->desc, d->k0_linear, d->pairs, d->material_count * d->material_count);
        *p = q;
    }
    fsdem__dem_pair_flags(d);
    d->forces_valid = 0;
    return fsdem__ok(&d->status);
}

fsdem_dem_material_pair fsdem_dem_get_material_pair(const fsdem_dem *d, int a, int b) {
    fsdem_dem_material_pair v;
    memset(&v, 0, sizeof v);
    if (d && a >= 0 && a < d->material_count && b >= 0 && b < d->material_count) {
        const fsdem__dem_pair *p = &d->pairs[a * d->material_count + b];
        v.restitution = p->restitution;
        v.friction = p->friction;
        v.rolling_friction = p->rolling;
        v.cohesion = p->cohesion;
    }
    return v;
}

static int fsdem__dem_inside_domain(const fsdem_dem *d, fsdem_vec3 p) {
    const fsdem_vec3 lo = d->desc.domain_min, hi = d->desc.domain_max;
    if (!(p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y)) return 0;
    return d->desc.dim == 2 || (p.z >= lo.z && p.z <= hi.z);
}

/* Checks a kinematic state of a particle of radius r; writes the reason and returns the code, or
   FSDEM_OK. Speeds, of the centre and of the surface by the spin, are bounded by FSDEM_MAX_SPEED. */
static fsdem_result fsdem__dem_state_check(fsdem_dem *d, const char *what, fsdem_vec3 x, fsdem_vec3 v, fsdem_vec3 w, fsdem_real r) {
    if (!fsdem__finite3(x) || !fsdem__finite3(v) || !fsdem__finite3(w))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "%s: position, velocity and angular velocity must be finite",
                           what);
    if (!fsdem__within(v, FSDEM_MAX_SPEED) || !fsdem__within(fsdem__scale(w, r), FSDEM_MAX_SPEED))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                           "%s: velocity (%g, %g, %g) m/s or the surface speed of angular velocity (%g, %g, %g) rad/s is above "
                           "FSDEM_MAX_SPEED (%g m/s)",
                           what, (double)v.x, (double)v.y, (double)v.z, (double)w.x, (double)w.y, (double)w.z, (double)FSDEM_MAX_SPEED);
    if (!fsdem__dem_inside_domain(d, x))
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_DOMAIN, "%s: position (%g, %g, %g) m is outside the domain", what,
                           (double)x.x, (double)x.y, (double)x.z);
    return FSDEM_OK;
}

fsdem_dem_particle_desc fsdem_dem_particle_desc_default(void) {
    fsdem_dem_particle_desc p;
    memset(&p, 0, sizeof p);
    return p;
}

/* Keeps 2D state in the plane: z of positions and velocities, x and y of spins. */
static void fsdem__dem_planar(const fsdem_dem *d, fsdem_vec3 *x, fsdem_vec3 *v, fsdem_vec3 *w) {
    if (d->desc.dim != 2) return;
    x->z = 0;
    v->z = 0;
    w->x = w->y = 0;
}

fsdem_result fsdem_dem_add_particle(fsdem_dem *d, const fsdem_dem_particle_desc *p, int *index) {
    fsdem_result res;
    int i;
    fsdem_real volume, inertia_factor, mass, inertia;
    fsdem_vec3 x, v, w;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    i = d->n;
    if (!p) return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_add_particle: desc is NULL");
    if (!(p->radius > 0 && p->radius <= FSDEM_MAX_LENGTH))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_particle_desc.radius must be in (0, %g] m (got %g m)",
                           (double)FSDEM_MAX_LENGTH, (double)p->radius);
    if (p->material < 0 || p->material >= d->material_count)
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_dem_particle_desc.material %d is not a material of this simulation (%d added)",
                           p->material, d->material_count);
    res = fsdem__dem_state_check(d, "fsdem_dem_particle_desc", p->position, p->velocity, p->angular_velocity, p->radius);
    if (res != FSDEM_OK) return res;
    if (d->desc.dim == 2) {
        volume = (fsdem_real)FSDEM__PI * p->radius * p->radius * d->desc.disc_length;
        inertia_factor = (fsdem_real)0.5; /* disc about its axis: m r^2 / 2 */
    } else {
        volume = (fsdem_real)(4.0 / 3.0 * FSDEM__PI) * p->radius * p->radius * p->radius;
        inertia_factor = (fsdem_real)0.4; /* solid sphere: 2 m r^2 / 5 */
    }
    mass = d->materials[p->material].density * volume;
    inertia = inertia_factor * mass * p->radius * p->radius;
    /* a radius of 1e120 overflows the mass (the particle would act as fixed), one of 1e-120 rounds
       it to zero (NaN at the next step): both are refused */
    if (!(mass > 0 && inertia > 0) || !fsdem__finite(inertia) || !fsdem__finite(1 / inertia))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_dem_particle_desc.radius %g m gives mass %g kg and moment of inertia %g kg m^2, "
                           "which are not positive finite numbers",
                           (double)p->radius, (double)mass, (double)inertia);
    if (d->periodic && (res = fsdem__dem_period_check(d, p->radius)) != FSDEM_OK) return res;
    if (fsdem__dem_reserve_particles(d, d->n + 1) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_dem_add_particle: out of memory adding particle %d", d->n);
    if (p->radius > d->r_max) d->r_max = p->radius; /* the periodic check's; a rebuild sets it anew */
    x = p->position;
    v = p->velocity;
    w = p->angular_velocity;
    fsdem__dem_planar(d, &x, &v, &w);
    d->id[i] = d->next_id++;
    d->material[i] = p->material;
    d->old_of[i] = -1;
    d->fixed[i] = (unsigned char)(p->fixed != 0);
    d->x[i] = x;
    d->v[i] = v;
    d->w[i] = w;
    d->f[i] = d->t[i] = d->fext[i] = d->text[i] = fsdem__zero3();
    d->x_ref[i] = x;
    d->r[i] = p->radius;
    d->m[i] = mass;
    d->inv_m[i] = p->fixed ? 0 : 1 / mass;
    d->inv_i[i] = p->fixed ? 0 : 1 / inertia;
    d->n++;
    d->need_rebuild = 1;
    d->forces_valid = 0;
    if (index) *index = i;
    return fsdem__ok(&d->status);
}

fsdem_result fsdem_dem_remove_particle(fsdem_dem *d, int index) {
    void **ptr[FSDEM__DEM_PARTICLE_ARRAYS];
    size_t size[FSDEM__DEM_PARTICLE_ARRAYS];
    int k;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    if (index < 0 || index >= d->n)
        return fsdem__fail(&d->status, FSDEM_ERR_NOT_FOUND, "fsdem_dem_remove_particle: index %d not in [0, %d)", index,
                           d->n);
    fsdem__dem_particle_arrays(d, ptr, size);
    for (k = 0; k < FSDEM__DEM_PARTICLE_ARRAYS; ++k) {
        char *base = (char *)*ptr[k];
        memmove(base + size[k] * (size_t)index, base + size[k] * (size_t)(index + 1),
                size[k] * (size_t)(d->n - index - 1));
    }
    d->n--;
    d->need_rebuild = 1; /* old_of moved with the rows, so the history carries over */
    d->forces_valid = 0;
    return fsdem__ok(&d->status);
}

fsdem_result fsdem_dem_set_particle_state(fsdem_dem *d, int index, fsdem_vec3 x, fsdem_vec3 v, fsdem_vec3 w) {
    fsdem_result res;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    if (index < 0 || index >= d->n)
        return fsdem__fail(&d->status, FSDEM_ERR_NOT_FOUND, "fsdem_dem_set_particle_state: index %d not in [0, %d)",
                           index, d->n);
    res = fsdem__dem_state_check(d, "fsdem_dem_set_particle_state", x, v, w, d->r[index]);
    if (res != FSDEM_OK) return res;
    fsdem__dem_planar(d, &x, &v, &w);
    d->x[index] = x;
    d->v[index] = v;
    d->w[index] = w;
    d->need_rebuild = 1;
    d->forces_valid = 0;
    return fsdem__ok(&d->status);
}

fsdem_dem_particles fsdem_dem_get_particles(const fsdem_dem *d) {
    fsdem_dem_particles p;
    memset(&p, 0, sizeof p);
    if (!d) return p;
    p.count = d->n;
    p.dim = d->desc.dim;
    p.id = d->id;
    p.position = d->x;
    p.velocity = d->v;
    p.angular_velocity = d->w;
    p.force = d->f;
    p.torque = d->t;
    p.external_force = d->fext;
    p.external_torque = d->text;
    p.radius = d->r;
    p.mass = d->m;
    p.material = d->material;
    p.fixed = d->fixed;
    return p;
}

fsdem_dem_coupling fsdem_dem_get_coupling(fsdem_dem *d) {
    fsdem_dem_coupling e;
    memset(&e, 0, sizeof e);
    if (!d) return e;
    e.count = d->n;
    e.force = d->fext;
    e.torque = d->text;
    d->external = 1; /* the caller may write them from now on */
    return e;
}

/* ---- >>dem_wall : wall geometry ---- */

static fsdem_dem_wall_desc fsdem__dem_wall_desc(fsdem_dem_wall_type type, fsdem_vec3 a, fsdem_vec3 b, fsdem_vec3 c, int material) {
    fsdem_dem_wall_desc w;
    memset(&w, 0, sizeof w);
    w.type = type;
    w.a = a;
    w.b = b;
    w.c = c;
    w.material = material;
    return w;
}

fsdem_dem_wall_desc fsdem_dem_wall_plane(fsdem_vec3 point, fsdem_vec3 normal, int material) {
    return fsdem__dem_wall_desc(FSDEM_DEM_WALL_TYPE_PLANE, point, normal, fsdem__zero3(), material);
}
fsdem_dem_wall_desc fsdem_dem_wall_box(fsdem_vec3 lo, fsdem_vec3 hi, int inside, int material) {
    return fsdem__dem_wall_desc(inside ? FSDEM_DEM_WALL_TYPE_BOX_INSIDE : FSDEM_DEM_WALL_TYPE_BOX_OUTSIDE, lo, hi, fsdem__zero3(), material);
}
fsdem_dem_wall_desc fsdem_dem_wall_segment(fsdem_vec3 a, fsdem_vec3 b, int material) {
    return fsdem__dem_wall_desc(FSDEM_DEM_WALL_TYPE_SEGMENT, a, b, fsdem__zero3(), material);
}
fsdem_dem_wall_desc fsdem_dem_wall_triangle(fsdem_vec3 a, fsdem_vec3 b, fsdem_vec3 c, int material) {
    return fsdem__dem_wall_desc(FSDEM_DEM_WALL_TYPE_TRIANGLE, a, b, c, material);
}
fsdem_dem_wall_desc fsdem_dem_wall_sdf(fsdem_sdf_fn sdf, void *user, int material) {
    fsdem_dem_wall_desc w = fsdem__dem_wall_desc(FSDEM_DEM_WALL_TYPE_SDF, fsdem__zero3(), fsdem__zero3(), fsdem__zero3(), material);
    w.sdf = sdf;
    w.sdf_user = user;
    return w;
}

static int fsdem__dem_wall_faces(const fsdem__dem_wall *w, int dim) {
    return w->d.type == FSDEM_DEM_WALL_TYPE_BOX_INSIDE ? 2 * dim : 1;
}

/* Signed distance (m) from p to face `face` of a wall, with the unit normal from the wall towards p.
   *on_feature is set when the closest point is an edge or vertex of a triangle, or an end of a
   segment: such points are shared by neighbouring elements of a mesh (see fsdem__dem_wall_hits). */
static fsdem_real fsdem__dem_wall_distance(const fsdem__dem_wall *w, int face, fsdem_vec3 p, int dim, fsdem_vec3 *n,
                                      int *on_feature) {
    const fsdem_dem_wall_desc *g = &w->d;
    fsdem_real dist;
    *on_feature = 0;
    switch (g->type) {
    case FSDEM_DEM_WALL_TYPE_PLANE:
        *n = g->b;
        return fsdem__dot(fsdem__sub(p, g->a), g->b);
    case FSDEM_DEM_WALL_TYPE_BOX_INSIDE: {
        int axis = face / 2;
        fsdem_real e[3] = {0, 0, 0};
        e[axis] = face % 2 == 0 ? 1 : -1;
        *n = fsdem_v3(e[0], e[1], e[2]);
        return face % 2 == 0 ? fsdem__comp(p, axis) - fsdem__comp(g->a, axis) : fsdem__comp(g->b, axis) - fsdem__comp(p, axis);
    }
    case FSDEM_DEM_WALL_TYPE_BOX_OUTSIDE: return fsdem__geom_box(p, g->a, g->b, dim, n);
    case FSDEM_DEM_WALL_TYPE_SEGMENT: {
        fsdem_vec3 ab = fsdem__sub(g->b, g->a), perp = fsdem_v3(-ab.y, ab.x, 0);
        fsdem_real len = fsdem__norm(perp);
        fsdem_vec3 q = fsdem__geom_closest_on_segment(p, g->a, g->b);
        perp = len > 0 ? fsdem__scale(perp, 1 / len) : fsdem_v3(0, 1, 0);
        *on_feature = fsdem__dot(fsdem__sub(q, g->a), fsdem__sub(q, g->a)) == 0 ||
                      fsdem__dot(fsdem__sub(q, g->b), fsdem__sub(q, g->b)) == 0;
        *n = fsdem__geom_direction(p, q, perp, &dist);
        return dist;
    }
    case FSDEM_DEM_WALL_TYPE_TRIANGLE: {
        fsdem_vec3 nrm = fsdem__cross(fsdem__sub(g->b, g->a), fsdem__sub(g->c, g->a));
        fsdem_vec3 q = fsdem__geom_closest_on_triangle(p, g->a, g->b, g->c, on_feature);
        nrm = fsdem__scale(nrm, 1 / fsdem__norm(nrm));
        *n = fsdem__geom_direction(p, q, nrm, &dist);
        return dist;
    }
    case FSDEM_DEM_WALL_TYPE_SDF:
    default: {
        fsdem_vec3 grad = fsdem_v3(0, 0, 1);
        fsdem_real len;
        dist = g->sdf(g->sdf_user, p, &grad);
        if (dim == 2) grad.z = 0;
        len = fsdem__norm(grad);
        *n = len > 0 ? fsdem__scale(grad, 1 / len) : fsdem_v3(0, 0, 1);
        return dist;
    }
    }
}

fsdem_result fsdem_dem_add_wall(fsdem_dem *d, const fsdem_dem_wall_desc *desc, int *id) {
    fsdem_dem_wall_desc g;
    fsdem__dem_wall *w;
    int axis;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    if (!desc) return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_add_wall: desc is NULL");
    g = *desc;
    if (g.material < 0 || g.material >= d->material_count)
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_wall_desc.material %d is not a material of this simulation",
                           g.material);
    if (!fsdem__finite3(g.a) || !fsdem__finite3(g.b) || !fsdem__finite3(g.c) || !fsdem__within(g.velocity, FSDEM_MAX_SPEED))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_dem_wall_desc: the geometry must be finite and the velocity at most FSDEM_MAX_SPEED (%g m/s)",
                           (double)FSDEM_MAX_SPEED);
    if (d->desc.dim == 2) {
        g.a.z = g.b.z = g.c.z = g.velocity.z = 0;
    }
    switch (g.type) {
    case FSDEM_DEM_WALL_TYPE_PLANE: {
        fsdem_real len, big;
        if (d->desc.dim == 2) g.b.z = 0;
        /* scaled by its largest component first, so a normal of (1e300, 1e300, 1e300) does not
           overflow to a zero unit vector */
        big = (fsdem_real)fmax(fmax(fabs(g.b.x), fabs(g.b.y)), fabs(g.b.z));
        if (!(big > 0)) return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_wall_plane: the normal is zero");
        g.b = fsdem__scale(g.b, 1 / big);
        len = fsdem__norm(g.b);
        g.b = fsdem__scale(g.b, 1 / len);
        break;
    }
    case FSDEM_DEM_WALL_TYPE_BOX_INSIDE:
    case FSDEM_DEM_WALL_TYPE_BOX_OUTSIDE:
        for (axis = 0; axis < d->desc.dim; ++axis)
            if (!(fsdem__comp(g.b, axis) > fsdem__comp(g.a, axis)) || !fsdem__finite(fsdem__comp(g.b, axis) - fsdem__comp(g.a, axis)))
                return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                                   "fsdem_dem_wall_box: hi must exceed lo by a finite extent on axis %d", axis);
        break;
    case FSDEM_DEM_WALL_TYPE_SEGMENT:
        if (d->desc.dim != 2)
            return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_wall_segment: segments need dim = 2 (use triangles in 3D)");
        if (!(fsdem__norm(fsdem__sub(g.b, g.a)) > 0) || !fsdem__finite(fsdem__norm(fsdem__sub(g.b, g.a))))
            return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                               "fsdem_dem_wall_segment: the end points must be distinct at a finite distance");
        break;
    case FSDEM_DEM_WALL_TYPE_TRIANGLE:
        if (d->desc.dim != 3)
            return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_wall_triangle: triangles need dim = 3 (use segments in 2D)");
        {
            /* twice the area; not finite when coordinates of 1e200 overflow it */
            const fsdem_real area2 = fsdem__norm(fsdem__cross(fsdem__sub(g.b, g.a), fsdem__sub(g.c, g.a)));
            if (!(area2 > 0) || !fsdem__finite(area2) || !fsdem__finite(1 / area2))
                return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                                   "fsdem_dem_wall_triangle: the triangle is degenerate or too large (twice its area: %g m^2)",
                                   (double)area2);
        }
        break;
    case FSDEM_DEM_WALL_TYPE_SDF:
        if (!g.sdf) return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_wall_sdf: the callback is NULL");
        if (fsdem__norm(g.velocity) > 0)
            return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                               "fsdem_dem_wall_sdf: a moving SDF wall must move inside its callback (velocity must be 0)");
        break;
    default:
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_wall_desc.type %d is not a fsdem_dem_wall_type", (int)g.type);
    }
    /* wall keys (wall * 8 + face) stay below the entry flags */
    if (d->wall_count >= FSDEM__DEM_HELD / 8)
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_dem_add_wall: at most %d walls", FSDEM__DEM_HELD / 8);
    if (fsdem__grow(&d->allocator, (void **)&d->walls, &d->wall_capacity, d->wall_count, d->wall_count + 1,
                    sizeof(fsdem__dem_wall)) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_dem_add_wall: out of memory");
    w = &d->walls[d->wall_count];
    memset(w, 0, sizeof *w);
    w->d = g;
    w->active = 1;
    if (id) *id = d->wall_count;
    d->wall_count++;
    d->need_rebuild = 1;
    d->forces_valid = 0;
    return fsdem__ok(&d->status);
}

static fsdem__dem_wall *fsdem__dem_wall_by_id(fsdem_dem *d, int id, const char *what) {
    if (id < 0 || id >= d->wall_count || !d->walls[id].active) {
        fsdem__fail(&d->status, FSDEM_ERR_NOT_FOUND, "%s: wall %d does not exist", what, id);
        return NULL;
    }
    return &d->walls[id];
}

fsdem_result fsdem_dem_remove_wall(fsdem_dem *d, int id) {
    fsdem__dem_wall *w = d ? fsdem__dem_wall_by_id(d, id, "fsdem_dem_remove_wall") : NULL;
    if (!w) return d ? FSDEM_ERR_NOT_FOUND : FSDEM_ERR_INVALID_ARG;
    w->active = 0;
    w->force = fsdem__zero3();
    d->need_rebuild = 1;
    d->forces_valid = 0;
    return fsdem__ok(&d->status);
}

fsdem_result fsdem_dem_set_wall_velocity(fsdem_dem *d, int id, fsdem_vec3 velocity) {
    fsdem__dem_wall *w = d ? fsdem__dem_wall_by_id(d, id, "fsdem_dem_set_wall_velocity") : NULL;
    if (!w) return d ? FSDEM_ERR_NOT_FOUND : FSDEM_ERR_INVALID_ARG;
    if (!fsdem__within(velocity, FSDEM_MAX_SPEED))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_dem_set_wall_velocity: velocity (%g, %g, %g) m/s must be finite and at most FSDEM_MAX_SPEED (%g m/s)",
                           (double)velocity.x, (double)velocity.y, (double)velocity.z, (double)FSDEM_MAX_SPEED);
    if (w->d.type == FSDEM_DEM_WALL_TYPE_SDF && fsdem__norm(velocity) > 0)
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_set_wall_velocity: an SDF wall moves in its callback");
    if (d->desc.dim == 2) velocity.z = 0;
    w->d.velocity = velocity;
    return fsdem__ok(&d->status);
}

fsdem_result fsdem_dem_wall_moved(fsdem_dem *d, int id, fsdem_real distance) {
    fsdem__dem_wall *w = d ? fsdem__dem_wall_by_id(d, id, "fsdem_dem_wall_moved") : NULL;
    if (!w) return d ? FSDEM_ERR_NOT_FOUND : FSDEM_ERR_INVALID_ARG;
    if (!(distance >= 0) || !fsdem__finite(distance))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_wall_moved: distance must be >= 0 (got %g m)",
                           (double)distance);
    w->moved += distance;
    return fsdem__ok(&d->status);
}

fsdem_vec3 fsdem_dem_wall_force(const fsdem_dem *d, int id) {
    return d && id >= 0 && id < d->wall_count ? d->walls[id].force : fsdem__zero3();
}

fsdem_vec3 fsdem_dem_wall_impulse(const fsdem_dem *d, int id) {
    return d && id >= 0 && id < d->wall_count ? d->walls[id].impulse : fsdem__zero3();
}

/* ---- >>dem_neighbours : neighbour lists with contact history ---- */

/* Doubles the entry arrays of a list (all three or none). */
static fsdem_result fsdem__dem_list_grow(fsdem_dem *d, fsdem__dem_list *l) {
    const size_t n = (size_t)l->count;
    int cap = l->capacity > 0 ? 2 * l->capacity : 256;
    int *first, *key;
    fsdem_vec3 *history;
    if (l->capacity > (1 << 29)) return FSDEM_ERR_OUT_OF_MEMORY;
    first = (int *)fsdem__alloc(&d->allocator, sizeof(int) * (size_t)cap);
    key = (int *)fsdem__alloc(&d->allocator, sizeof(int) * (size_t)cap);
    history = (fsdem_vec3 *)fsdem__alloc(&d->allocator, sizeof(fsdem_vec3) * (size_t)cap);
    if (!first || !key || !history) {
        fsdem__free(&d->allocator, first, sizeof(int) * (size_t)cap);
        fsdem__free(&d->allocator, key, sizeof(int) * (size_t)cap);
        fsdem__free(&d->allocator, history, sizeof(fsdem_vec3) * (size_t)cap);
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    if (n) {
        memcpy(first, l->first, sizeof(int) * n);
        memcpy(key, l->key, sizeof(int) * n);
        memcpy(history, l->history, sizeof(fsdem_vec3) * n);
    }
    fsdem__dem_list_free_entries(d, l);
    l->first = first;
    l->key = key;
    l->history = history;
    l->capacity = cap;
    return FSDEM_OK;
}

/* Appends (row, partner `key`) with the history that entry `from` of list `old` holds (none for -1). */
/* Writes entry e = (row, partner `key`) with the spring that entry `from` of list `old` holds (none
   for -1). Without branches on the flag: the spring is copied whether held or not, as it means
   nothing without it. */
static void fsdem__dem_list_set(fsdem__dem_list *l, int e, int row, int key, const fsdem__dem_list *old, int from) {
    const int src = from >= 0 ? from : 0;
    l->first[e] = row;
    l->key[e] = key | (((from >= 0) & (old->count > 0)) ? old->key[src] & FSDEM__DEM_HELD : 0);
    if (old->count > 0) l->history[e] = old->history[src];
}

static fsdem_result fsdem__dem_list_append(fsdem_dem *d, fsdem__dem_list *l, int row, int key, const fsdem__dem_list *old, int from) {
    if (l->count == l->capacity && fsdem__dem_list_grow(d, l) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__dem_list_set(l, l->count++, row, key, old, from);
    return FSDEM_OK;
}

/* The tangential spring of entry k (zero unless held). */
static fsdem_vec3 fsdem__dem_spring(const fsdem__dem_list *l, int k) {
    return l->key[k] & FSDEM__DEM_HELD ? l->history[k] : fsdem__zero3();
}

/* Entry of (row, partner) in a previous list, or -1. */
static int fsdem__dem_old_entry(const fsdem__dem_list *old, int row, int partner) {
    int k;
    if (row >= 0 && row < old->rows)
        for (k = old->start[row]; k < old->start[row + 1]; ++k)
            if (FSDEM__DEM_PARTNER(old->key[k]) == partner) return k;
    return -1;
}

static void fsdem__dem_swap_lists(fsdem__dem_list *a, fsdem__dem_list *b) {
    fsdem__dem_list t = *a;
    *a = *b;
    *b = t;
}

/* Pairs within reach (r_i + r_j + offset + skin), each found once by scanning every cell against
   itself and its forward neighbours (fsdem_cellgrid_forward), into d->found as pairs of cell-order
   indices; xs and reach_s are the positions and radii plus half the offset and skin in cell order, so
   the scan reads them in sequence. Returns the number of pairs, or -1 when d->found cannot grow. */
FSDEM__FORCE_INLINE int fsdem__dem_find_pairs_in(fsdem_dem *d, const fsdem_vec3 *xs, const fsdem_real *reach_s, const int periodic) {
    const fsdem_cellgrid *g = &d->grid;
    int c, f, a, b, count = 0;
    for (c = 0; c < g->cell_count; ++c) {
        int coord[3], cells[14], nf;
        if (g->cell_start[c] == g->cell_start[c + 1]) continue;
        coord[0] = c % g->n[0];
        coord[1] = c / g->n[0] % g->n[1];
        coord[2] = c / (g->n[0] * g->n[1]);
        nf = fsdem_cellgrid_forward(g, coord, cells);
        for (f = 0; f < nf; ++f) {
            const int b1 = g->cell_start[cells[f] + 1];
            for (a = g->cell_start[c]; a < g->cell_start[c + 1]; ++a) {
                const int b0 = f == 0 ? a + 1 : g->cell_start[cells[f]];
                if (2 * (count + b1 - b0) > d->found_capacity &&
                    fsdem__grow(&d->allocator, (void **)&d->found, &d->found_capacity, 2 * count, 2 * (count + b1 - b0),
                                sizeof(int)) != FSDEM_OK)
                    return -1;
                for (b = b0; b < b1; ++b) {
                    /* arithmetic, not branches, which would mispredict */
                    const fsdem_vec3 e = periodic ? fsdem__dem_min_image(d, fsdem__sub(xs[a], xs[b])) : fsdem__sub(xs[a], xs[b]);
                    const fsdem_real ex = e.x, ey = e.y, ez = e.z;
                    const fsdem_real reach = reach_s[a] + reach_s[b];
                    d->found[2 * count] = a;
                    d->found[2 * count + 1] = b;
                    count += ex * ex + ey * ey + ez * ez < reach * reach;
                }
            }
        }
    }
    return count;
}

static int fsdem__dem_find_pairs(fsdem_dem *d, const fsdem_vec3 *xs, const fsdem_real *reach_s) {
    return d->periodic ? fsdem__dem_find_pairs_in(d, xs, reach_s, 1) : fsdem__dem_find_pairs_in(d, xs, reach_s, 0);
}

/* The particle-pair list from the `count` pairs in d->found: row min(i, j), partner max(i, j), each
   carrying its history from the previous list. Pairs of fixed particles exert nothing, so they go
   to d->inert instead, where fsdem_dem_contacts still finds them. `cursor` is scratch for n rows. */
static fsdem_result fsdem__dem_fill_pairs(fsdem_dem *d, int count, int *cursor) {
    fsdem__dem_list *l = &d->pp;
    const int *items = d->grid.items;
    int k, i, inert = 0;
    for (k = 0; k < count; ++k) {
        /* partition: the pairs of fixed particles to the end of d->found, as particle indices */
        const int a = items[d->found[2 * k]], b = items[d->found[2 * k + 1]];
        if (d->inv_m[a] == 0 && d->inv_m[b] == 0) {
            const int last = --count;
            d->found[2 * k] = d->found[2 * last];
            d->found[2 * k + 1] = d->found[2 * last + 1];
            d->found[2 * last] = a;
            d->found[2 * last + 1] = b;
            ++inert;
            --k;
        }
    }
    if (fsdem__grow(&d->allocator, (void **)&d->inert, &d->inert_capacity, 0, 2 * inert, sizeof(int)) != FSDEM_OK)
        return FSDEM_ERR_OUT_OF_MEMORY;
    if (inert) memcpy(d->inert, d->found + 2 * count, sizeof(int) * 2 * (size_t)inert); /* found may be NULL */
    d->inert_count = inert;
    while (l->capacity < count)
        if (fsdem__dem_list_grow(d, l) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    memset(l->start, 0, sizeof(int) * (size_t)(d->n + 1));
    for (k = 0; k < count; ++k) {
        const int a = items[d->found[2 * k]], b = items[d->found[2 * k + 1]];
        l->start[(a < b ? a : b) + 1]++;
    }
    for (i = 0; i < d->n; ++i) {
        l->start[i + 1] += l->start[i];
        cursor[i] = l->start[i];
    }
    for (k = 0; k < count; ++k) {
        const int a = items[d->found[2 * k]], b = items[d->found[2 * k + 1]];
        const int i0 = a < b ? a : b, j = a < b ? b : a, e = cursor[i0]++;
        const int oi = d->old_of[i0], oj = d->old_of[j], lo = oi < oj ? oi : oj, hi = oi < oj ? oj : oi;
        fsdem__dem_list_set(l, e, i0, j, &d->pp_old, lo >= 0 ? fsdem__dem_old_entry(&d->pp_old, lo, hi) : -1);
    }
    l->count = count;
    return FSDEM_OK;
}

/* Rebuilds both lists: pairs within r_i + r_j + offset + skin, and particle-wall faces within
   r_i + offset + skin, carrying each surviving contact's history over from the previous lists. */
static fsdem_result fsdem__dem_rebuild(fsdem_dem *d) {
    const fsdem_real off = d->desc.contact_offset;
    fsdem_real r_max = 0, skin, *reach_s;
    fsdem_vec3 *xs;
    int i, k, dim = d->desc.dim, max_cells, *cursor, pairs;
    fsdem_result res = FSDEM_OK;
    for (i = 0; i < d->n; ++i)
        if (d->r[i] > r_max) r_max = d->r[i];
    skin = d->desc.skin >= 0 ? d->desc.skin : (fsdem_real)0.25 * r_max;
    d->skin = skin;
    d->r_max = r_max;
    max_cells = 8 * d->n > 65536 ? 8 * d->n : 65536;
    fsdem__dem_wrap(d);
    if (fsdem_cellgrid_setup_periodic(&d->grid, NULL, dim, d->desc.domain_min, d->desc.domain_max,
                                      r_max > 0 ? 2 * r_max + off + skin : 1, max_cells, d->desc.periodic) != FSDEM_OK ||
        fsdem_cellgrid_build(&d->grid, d->x, d->n) != FSDEM_OK)
        return FSDEM_ERR_OUT_OF_MEMORY;
    /* scratch: positions and reaches (half each: r + (offset + skin)/2) in cell order, row cursors */
    if (fsdem__arena_reserve(&d->allocator, &d->arena,
                             fsdem__arena_bytes(sizeof(fsdem_vec3) * (size_t)d->n) +
                                 fsdem__arena_bytes(sizeof(fsdem_real) * (size_t)d->n) +
                                 fsdem__arena_bytes(sizeof(int) * (size_t)d->n)) != FSDEM_OK)
        return FSDEM_ERR_OUT_OF_MEMORY;
    xs = (fsdem_vec3 *)fsdem__arena_push(&d->arena, sizeof(fsdem_vec3) * (size_t)d->n);
    reach_s = (fsdem_real *)fsdem__arena_push(&d->arena, sizeof(fsdem_real) * (size_t)d->n);
    cursor = (int *)fsdem__arena_push(&d->arena, sizeof(int) * (size_t)d->n);
    for (k = 0; k < d->n; ++k) {
        const int j = d->grid.items[k];
        xs[k] = d->x[j];
        reach_s[k] = d->r[j] + (off + skin) / 2;
    }
    pairs = fsdem__dem_find_pairs(d, xs, reach_s);
    if (pairs < 0) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__dem_swap_lists(&d->pp, &d->pp_old);
    fsdem__dem_swap_lists(&d->pw, &d->pw_old);
    if (fsdem__grow(&d->allocator, (void **)&d->pp.start, &d->pp.start_capacity, 0, d->n + 1, sizeof(int)) != FSDEM_OK ||
        fsdem__grow(&d->allocator, (void **)&d->pw.start, &d->pw.start_capacity, 0, d->n + 1, sizeof(int)) != FSDEM_OK ||
        fsdem__dem_fill_pairs(d, pairs, cursor) != FSDEM_OK)
        res = FSDEM_ERR_OUT_OF_MEMORY;
    d->pw.count = 0;
    for (i = 0; i < d->n && res == FSDEM_OK; ++i) {
        const int oi = d->old_of[i];
        d->pw.start[i] = d->pw.count;
        for (k = 0; k < d->wall_count && res == FSDEM_OK; ++k) {
            const fsdem__dem_wall *w = &d->walls[k];
            int face, faces = fsdem__dem_wall_faces(w, dim);
            if (!w->active) continue;
            for (face = 0; face < faces; ++face) {
                fsdem_vec3 nrm;
                int key = FSDEM__DEM_WALL_KEY(k, face), on_feature;
                if (fsdem__dem_wall_distance(w, face, d->x[i], dim, &nrm, &on_feature) >= d->r[i] + off + skin) continue;
                res = fsdem__dem_list_append(d, &d->pw, i, key, &d->pw_old, fsdem__dem_old_entry(&d->pw_old, oi, key));
                if (res != FSDEM_OK) break;
            }
        }
    }
    if (res != FSDEM_OK) {
        fsdem__dem_swap_lists(&d->pp, &d->pp_old);
        fsdem__dem_swap_lists(&d->pw, &d->pw_old);
        return res;
    }
    d->pw.start[d->n] = d->pw.count;
    d->pp.rows = d->pw.rows = d->n;
    for (i = 0; i < d->n; ++i) {
        d->x_ref[i] = d->x[i];
        d->old_of[i] = i;
    }
    for (k = 0; k < d->wall_count; ++k) d->walls[k].moved = 0;
    d->max_disp2 = 0;
    d->rebuilds++;
    fsdem__dem_dt_check(d);
    /* scratch for the longest wall row, and the force evaluation's arena (fsdem__dem_compute_forces) for
       the new list; the lists above are complete, so a failure here only asks for another rebuild */
    for (i = 0, k = 0; i < d->n; ++i)
        if (d->pw.start[i + 1] - d->pw.start[i] > k) k = d->pw.start[i + 1] - d->pw.start[i];
    d->need_rebuild = fsdem__grow(&d->allocator, (void **)&d->hits, &d->hit_capacity, 0, k, sizeof(fsdem__dem_wall_hit)) !=
                          FSDEM_OK ||
                      fsdem__arena_reserve(&d->allocator, &d->arena,
                                           fsdem__arena_bytes(sizeof(int) * (size_t)d->pp.count) +
                                               fsdem__arena_bytes(sizeof(fsdem__dem_batch))) != FSDEM_OK;
    return d->need_rebuild ? FSDEM_ERR_OUT_OF_MEMORY : FSDEM_OK;
}

static int fsdem__dem_lists_stale(const fsdem_dem *d) {
    fsdem_real disp = (fsdem_real)sqrt(d->max_disp2), wall_moved = 0;
    int k;
    for (k = 0; k < d->wall_count; ++k)
        if (d->walls[k].moved > wall_moved) wall_moved = d->walls[k].moved;
    return d->need_rebuild || 2 * disp > d->skin || disp + wall_moved > d->skin;
}

/* Wall contacts (overlap > 0) of particle i into `hits`; returns their number. A mesh of
   triangles or a polyline shares edges and vertices between elements, and a particle touching a
   shared edge would be pushed once per element. So an edge/vertex contact is dropped when its
   contact point lies in the plane of a face contact of the same particle (the edge belongs to that
   face), or when an edge/vertex contact kept before has the same normal (one edge seen from two
   elements). `hits` has room for the particle's row of the particle-wall list. With `keys` (the
   list's keys; NULL: nothing changes), entries without a kept contact lose their tangential
   history. */
static int fsdem__dem_wall_hits_into(const fsdem_dem *d, int i, fsdem__dem_wall_hit *hits, int *keys) {
    const fsdem_real off = d->desc.contact_offset, tol = (fsdem_real)fsdem__tolerance(1e-9) * d->r[i];
    const fsdem_vec3 xi = d->x[i];
    int k, a, b, count = 0, kept = 0;
    for (k = d->pw.start[i]; k < d->pw.start[i + 1]; ++k) {
        const int key = d->pw.key[k];
        const fsdem__dem_wall *wall = &d->walls[FSDEM__DEM_WALL_OF(key)];
        fsdem__dem_wall_hit *h = &hits[count];
        if (wall->active) {
            h->delta = d->r[i] + off - fsdem__dem_wall_distance(wall, FSDEM__DEM_FACE_OF(key), xi, d->desc.dim, &h->n, &h->on_feature);
            if (h->delta > 0) {
                h->entry = k;
                count++;
                continue;
            }
        }
        if (keys) keys[k] &= ~FSDEM__DEM_HELD;
    }
    for (a = 0; a < count; ++a) {
        fsdem__dem_wall_hit h = hits[a];
        int duplicate = 0;
        if (h.on_feature) {
            /* contact point q = x - (r + off - delta) n; in face b's plane when (q - x).n_b = -(r + off - delta_b) */
            fsdem_vec3 q_rel = fsdem__scale(h.n, -(d->r[i] + off - h.delta));
            for (b = 0; b < count && !duplicate; ++b) {
                const fsdem__dem_wall_hit *o = &hits[b];
                if (b == a) continue;
                if (!o->on_feature)
                    duplicate = fsdem__dot(q_rel, o->n) + (d->r[i] + off - o->delta) <= tol &&
                                fsdem__dot(q_rel, o->n) + (d->r[i] + off - o->delta) >= -tol;
                else if (b < a)
                    duplicate = fsdem__dot(h.n, o->n) >= 1 - (fsdem_real)fsdem__tolerance(1e-12);
            }
        }
        if (duplicate) {
            if (keys) keys[h.entry] &= ~FSDEM__DEM_HELD;
            continue;
        }
        hits[kept++] = h;
    }
    return kept;
}

/* Wall contacts of particle i into d->hits (fsdem__dem_wall_hits_into); with `reset`, entries
   without a kept contact lose their tangential history. */
static int fsdem__dem_wall_hits(fsdem_dem *d, int i, int reset) {
    return fsdem__dem_wall_hits_into(d, i, d->hits, reset ? d->pw.key : NULL);
}

/* ---- >>dem_forces : contact force evaluation ---- */

/* The law the kernels are instantiated with: the desc's, or seed 002's linear law. */
static fsdem_dem_law fsdem__dem_kernel_law(const fsdem_dem *d) {
    return d->desc.law == FSDEM_DEM_LAW_LINEAR && !fsdem__dem_seed000_stiffness(&d->desc) ? FSDEM__DEM_LAW_SEED002 : d->desc.law;
}

/* The contact options as the kernels read them. */
static fsdem__dem_rules fsdem__dem_rules_of(const fsdem_dem *d) {
    fsdem__dem_rules r;
    r.total_history = d->desc.tangential_history == FSDEM_DEM_TANGENTIAL_HISTORY_TOTAL;
    r.cap_spring = d->desc.coulomb_limit == FSDEM_DEM_COULOMB_LIMIT_SPRING;
    r.cohesion = d->cohesive;
    r.offset = d->desc.contact_offset;
    r.area_depth = d->desc.dim == 2 ? d->desc.disc_length : 0;
    return r;
}

/* Material pair `pair`'s coefficients into lane c of a batch. */
static void fsdem__dem_gather_pair_coefficients(const fsdem_dem *d, fsdem__dem_batch *b, int c, int pair) {
    const fsdem__dem_pair *p = d->pairs + pair;
    b->pair[c] = pair;
    b->kn[c] = p->kn;
    b->cn[c] = p->cn;
    b->kt[c] = p->kt;
    b->ct[c] = p->ct;
    b->mu[c] = p->friction;
    b->coh[c] = p->cohesion;
}

/* Contact `k` of the particle-pair list into lane c of a batch; the coefficients of its material
   pair unless the batch is `uniform`, the mean mass only for the law that uses it. */
FSDEM__FORCE_INLINE void fsdem__dem_gather_pair(const fsdem_dem *d, fsdem__dem_batch *FSDEM__RESTRICT b, int c, int k, const fsdem_dem_law law,
                                            int uniform) {
    const int i = d->pp.first[k], key = d->pp.key[k], j = FSDEM__DEM_PARTNER(key);
    const fsdem_vec3 vi = d->v[i], vj = d->v[j], wi = d->w[i], wj = d->w[j];
    const fsdem_vec3 e = fsdem__dem_min_image(d, fsdem__sub(d->x[i], d->x[j]));
    const fsdem_vec3 spring = key & FSDEM__DEM_HELD ? d->pp.history[k] : fsdem__zero3();
    b->i[c] = i;
    b->other[c] = j;
    b->entry[c] = k;
    b->dx[0][c] = e.x;
    b->dx[1][c] = e.y;
    b->dx[2][c] = e.z;
    b->dv[0][c] = vi.x - vj.x;
    b->dv[1][c] = vi.y - vj.y;
    b->dv[2][c] = vi.z - vj.z;
    b->wi[0][c] = wi.x;
    b->wi[1][c] = wi.y;
    b->wi[2][c] = wi.z;
    b->wj[0][c] = wj.x;
    b->wj[1][c] = wj.y;
    b->wj[2][c] = wj.z;
    b->ri[c] = d->r[i];
    b->rj[c] = d->r[j];
    b->inv_mi[c] = d->inv_m[i];
    b->inv_mj[c] = d->inv_m[j];
    if (law == FSDEM_DEM_LAW_LINEAR) b->m_mean[c] = (d->m[i] + d->m[j]) / 2;
    b->spring[0][c] = spring.x;
    b->spring[1][c] = spring.y;
    b->spring[2][c] = spring.z;
    if (!uniform) fsdem__dem_gather_pair_coefficients(d, b, c, d->material[i] * d->material_count + d->material[j]);
    else b->pair[c] = 0;
}

/* Wall contact `hit` of particle i into lane c of a batch (coefficients as fsdem__dem_gather_pair). */
static void fsdem__dem_gather_wall(const fsdem_dem *d, fsdem__dem_batch *b, int c, int i, const fsdem__dem_wall_hit *hit, int uniform) {
    const int key = d->pw.key[hit->entry], wall = FSDEM__DEM_WALL_OF(key);
    const fsdem_real arm = d->r[i] - hit->delta / 2;
    const fsdem_vec3 n = hit->n, spring = key & FSDEM__DEM_HELD ? d->pw.history[hit->entry] : fsdem__zero3();
    const fsdem_vec3 vrel = fsdem__sub(fsdem__sub(d->v[i], fsdem__scale(fsdem__cross(d->w[i], n), arm)),
                                       d->walls[wall].d.velocity);
    b->i[c] = i;
    b->other[c] = wall;
    b->entry[c] = hit->entry;
    b->n[0][c] = n.x;
    b->n[1][c] = n.y;
    b->n[2][c] = n.z;
    b->delta[c] = hit->delta;
    b->vrel[0][c] = vrel.x;
    b->vrel[1][c] = vrel.y;
    b->vrel[2][c] = vrel.z;
    b->m_eff[c] = b->m_mean[c] = d->m[i];
    b->r_eff[c] = d->r[i];
    b->arm_i[c] = arm;
    b->spring[0][c] = spring.x;
    b->spring[1][c] = spring.y;
    b->spring[2][c] = spring.z;
    if (!uniform) fsdem__dem_gather_pair_coefficients(d, b, c, d->material[i] * d->material_count + d->walls[wall].d.material);
    else b->pair[c] = 0;
}

static fsdem_vec3 fsdem__dem_batch_vec(const fsdem_real (*a)[FSDEM__DEM_BATCH], int c) { return fsdem_v3(a[0][c], a[1][c], a[2][c]); }

/* Adds a batch's forces and torques to the particles (and its walls, `walls`), commits the springs
   when `commit` and the law has history, and applies rolling resistance. */
FSDEM__FORCE_INLINE void fsdem__dem_scatter(fsdem_dem *d, const fsdem__dem_batch *FSDEM__RESTRICT b, const int walls, int commit,
                                        fsdem_real h) {
    fsdem__dem_list *l = walls ? &d->pw : &d->pp;
    fsdem_vec3 *FSDEM__RESTRICT f = d->f, *FSDEM__RESTRICT t = d->t, *FSDEM__RESTRICT history = l->history;
    int *FSDEM__RESTRICT keys = l->key;
    fsdem_real max_overlap = d->max_overlap;
    int c;
    for (c = 0; c < b->count; ++c) {
        const int i = b->i[c], o = b->other[c];
        const fsdem_vec3 force = fsdem__dem_batch_vec(b->force, c), torque = fsdem__dem_batch_vec(b->torque_i, c);
        f[i] = fsdem__add(f[i], force);
        t[i] = fsdem__add(t[i], torque);
        if (walls) d->walls[o].force = fsdem__sub(d->walls[o].force, force);
        else {
            f[o] = fsdem__sub(f[o], force);
            t[o] = fsdem__add(t[o], fsdem__dem_batch_vec(b->torque_j, c));
        }
        if (commit) {
            history[b->entry[c]] = fsdem__dem_batch_vec(b->spring, c);
            keys[b->entry[c]] |= FSDEM__DEM_HELD;
        }
        if (b->delta[c] > max_overlap) max_overlap = b->delta[c];
    }
    d->max_overlap = max_overlap;
    if (d->rolling)
        for (c = 0; c < b->count; ++c) {
            const int i = b->i[c], o = b->other[c];
            const fsdem_real mu_r = d->pairs[b->pair[c]].rolling;
            fsdem_vec3 w_rel, tr;
            if (!(mu_r > 0)) continue;
            w_rel = walls ? d->w[i] : fsdem__sub(d->w[i], d->w[o]);
            tr = fsdem__dem_rolling_torque(w_rel, mu_r, b->r_eff[c], b->fn[c], d->inv_i[i] + (walls ? 0 : d->inv_i[o]), h);
            t[i] = fsdem__add(t[i], tr);
            if (!walls) t[o] = fsdem__sub(t[o], tr);
        }
}

/* The entries of the particle-pair list whose pair touches, into `touching`; returns their number.
   With `commit`, the pairs that do not touch lose their spring. Branch-free, and instantiated with
   and without `commit`. */
FSDEM__FORCE_INLINE int fsdem__dem_touching(fsdem_dem *d, int *FSDEM__RESTRICT touching, const int commit, const int periodic) {
    const fsdem_real off = d->desc.contact_offset;
    const fsdem_vec3 *FSDEM__RESTRICT x = d->x;
    const fsdem_real *FSDEM__RESTRICT r = d->r;
    const int *FSDEM__RESTRICT first = d->pp.first;
    int *FSDEM__RESTRICT keys = d->pp.key;
    const int pairs = d->pp.count;
    int k, count = 0;
    for (k = 0; k < pairs; ++k) {
        const int key = keys[k], i = first[k], j = FSDEM__DEM_PARTNER(key);
        const fsdem_vec3 e = periodic ? fsdem__dem_min_image(d, fsdem__sub(x[i], x[j])) : fsdem__sub(x[i], x[j]);
        const fsdem_real ex = e.x, ey = e.y, ez = e.z, reach = r[i] + r[j] + off;
        const int touch = ex * ex + ey * ey + ez * ez < reach * reach;
        touching[count] = k;
        count += touch;
        if (commit) keys[k] = key & ~((touch - 1) & FSDEM__DEM_HELD); /* arithmetic: a branch here would mispredict */
    }
    return count;
}

/* Runs the kernels on a filled batch (particle pairs or, with `walls`, wall contacts), applies it
   and empties it; returns the number of contacts it held. */
FSDEM__FORCE_INLINE int fsdem__dem_drain(fsdem_dem *d, fsdem__dem_batch *b, int walls, const fsdem_dem_law law, fsdem_real h,
                                     int keep, const fsdem__dem_rules *rules) {
    const int count = b->count;
    const fsdem__dem_pair *uniform = d->material_count == 1 ? d->pairs : NULL;
    fsdem__dem_batch_pad(b, !walls, uniform != NULL);
    if (walls) fsdem__dem_batch_law(b, law, h, 0, 0, uniform, rules);
    else fsdem__dem_batch_law(b, law, h, 1, d->desc.contact_offset, uniform, rules);
    fsdem__dem_scatter(d, b, walls, keep, h);
    b->count = 0;
    return count;
}

/* Contact forces and torques of all particle pairs and particle-wall contacts into f, t and the
   walls' force; `h` is the step the history and the one-step spring of seed 000 Eq. 8 use, and the
   springs are kept when `commit` (the predictor of the predictor-corrector does not keep them).
   A pass over the whole pair list finds the touching pairs without branching; they and the wall
   contacts then go through the vector kernels a batch at a time. Written once, instantiated per
   contact law (fsdem__dem_compute_forces). */
FSDEM__FORCE_INLINE void fsdem__dem_compute_forces_law(fsdem_dem *d, fsdem_real h, int commit, const fsdem_dem_law law) {
    const int n = d->n, keep = commit && (law == FSDEM_DEM_LAW_HERTZ_MINDLIN || law == FSDEM__DEM_LAW_SEED002);
    const int uniform = d->material_count == 1;
    const fsdem__dem_rules rules = fsdem__dem_rules_of(d);
    fsdem__dem_batch *b;
    int *touching, i, k, c, nt = 0, nw = 0;
    fsdem__arena_reset(&d->arena);
    touching = (int *)fsdem__arena_push(&d->arena, sizeof(int) * (size_t)d->pp.count);
    b = (fsdem__dem_batch *)fsdem__arena_push(&d->arena, sizeof *b);
    if (!d->forces_cleared) {
        memset(d->f, 0, sizeof *d->f * (size_t)n);
        memset(d->t, 0, sizeof *d->t * (size_t)n);
    }
    d->forces_cleared = 0;
    for (k = 0; k < d->wall_count; ++k) d->walls[k].force = fsdem__zero3();
    d->max_overlap = 0;
    if (d->periodic) nt = commit ? fsdem__dem_touching(d, touching, 1, 1) : fsdem__dem_touching(d, touching, 0, 1);
    else nt = commit ? fsdem__dem_touching(d, touching, 1, 0) : fsdem__dem_touching(d, touching, 0, 0);
    b->count = 0;
    for (k = 0; k < nt; ++k) {
        fsdem__dem_gather_pair(d, b, b->count++, touching[k], law, uniform);
        if (b->count == FSDEM__DEM_BATCH || k == nt - 1) fsdem__dem_drain(d, b, 0, law, h, keep, &rules);
    }
    for (k = 0; k < d->pw.count; k = d->pw.start[i + 1]) {
        /* row to row through the particles with wall entries */
        int nh;
        i = d->pw.first[k];
        if (d->inv_m[i] == 0) continue; /* fixed: no wall force */
        nh = fsdem__dem_wall_hits(d, i, commit);
        for (c = 0; c < nh; ++c) {
            fsdem__dem_gather_wall(d, b, b->count++, i, &d->hits[c], uniform);
            if (b->count == FSDEM__DEM_BATCH) nw += fsdem__dem_drain(d, b, 1, law, h, keep, &rules);
        }
    }
    if (b->count) nw += fsdem__dem_drain(d, b, 1, law, h, keep, &rules);
    d->contacts = nt;
    d->wall_contacts = nw;
    d->forces_valid = 1;
}

static void fsdem__dem_compute_forces(fsdem_dem *d, fsdem_real h, int commit) {
    switch ((int)fsdem__dem_kernel_law(d)) {
    case FSDEM_DEM_LAW_LINEAR: fsdem__dem_compute_forces_law(d, h, commit, FSDEM_DEM_LAW_LINEAR); break;
    case FSDEM_DEM_LAW_GIC: fsdem__dem_compute_forces_law(d, h, commit, FSDEM_DEM_LAW_GIC); break;
    case FSDEM__DEM_LAW_SEED002: fsdem__dem_compute_forces_law(d, h, commit, FSDEM__DEM_LAW_SEED002); break;
    default: fsdem__dem_compute_forces_law(d, h, commit, FSDEM_DEM_LAW_HERTZ_MINDLIN); break;
    }
}

/* ---- >>dem_integrate : time integration ---- */

static fsdem_vec3 fsdem__dem_accel(const fsdem_dem *d, const fsdem_vec3 *f, int i) {
    return fsdem__madd(d->desc.gravity, fsdem__add(f[i], d->fext[i]), d->inv_m[i]);
}

static fsdem_vec3 fsdem__dem_spin_rate(const fsdem_dem *d, const fsdem_vec3 *t, int i) {
    return d->desc.rotation ? fsdem__scale(fsdem__add(t[i], d->text[i]), d->inv_i[i]) : fsdem__zero3();
}

/* One pass of Verlet over the particles: the velocity update v += h a, w += h alpha of the free
   particles (with the external loads when `external`), then, with `drift`, the position update
   x += h_drift v of all of them, the largest displacement since the last rebuild, and f and t
   cleared for the force evaluation that follows. Returns nonzero when the pass may have produced a
   state that is not finite or outside the domain; fsdem__dem_check_particles then finds and names the
   particle. (Positions are checked after the drift, velocities after a pass without one.) Written
   once and instantiated per flag, so each pass reads every array it needs once. */
FSDEM__FORCE_INLINE int fsdem__dem_verlet_pass(fsdem_dem *d, fsdem_real h, const int drift, fsdem_real h_drift,
                                           const int external) {
    const fsdem_vec3 g = d->desc.gravity, lo = d->desc.domain_min, hi = d->desc.domain_max;
    fsdem_vec3 *FSDEM__RESTRICT f = d->f, *FSDEM__RESTRICT t = d->t;
    const fsdem_vec3 *FSDEM__RESTRICT fe = d->fext, *FSDEM__RESTRICT te = d->text, *FSDEM__RESTRICT x_ref = d->x_ref;
    const fsdem_real *FSDEM__RESTRICT inv_m = d->inv_m, *FSDEM__RESTRICT inv_i = d->inv_i;
    const unsigned char *FSDEM__RESTRICT fixed = d->fixed;
    fsdem_vec3 *FSDEM__RESTRICT x = d->x, *FSDEM__RESTRICT v = d->v, *FSDEM__RESTRICT w = d->w;
    const fsdem_real h_spin = d->desc.rotation ? h : 0;
    const int planar = d->desc.dim == 2, n = d->n;
    fsdem_real disp2 = d->max_disp2;
    int i, k, outside = 0; /* or suspect: not finite */
    for (i = 0; i < n; ++i) {
        if (!fixed[i]) {
            const fsdem_real a = h * inv_m[i], b = h_spin * inv_i[i];
            v[i].x += h * g.x + a * (external ? f[i].x + fe[i].x : f[i].x);
            v[i].y += h * g.y + a * (external ? f[i].y + fe[i].y : f[i].y);
            v[i].z += h * g.z + a * (external ? f[i].z + fe[i].z : f[i].z);
            w[i].x += b * (external ? t[i].x + te[i].x : t[i].x);
            w[i].y += b * (external ? t[i].y + te[i].y : t[i].y);
            w[i].z += b * (external ? t[i].z + te[i].z : t[i].z);
            if (planar) v[i].z = w[i].x = w[i].y = 0;
        }
        if (drift) {
            f[i] = t[i] = fsdem__zero3();
            fsdem_real dx, dy, dz, d2;
            x[i].x += h_drift * v[i].x;
            x[i].y += h_drift * v[i].y;
            x[i].z += h_drift * v[i].z;
            dx = x[i].x - x_ref[i].x;
            dy = x[i].y - x_ref[i].y;
            dz = x[i].z - x_ref[i].z;
            d2 = dx * dx + dy * dy + dz * dz;
            if (d2 > disp2) disp2 = d2;
            /* false for NaN too; a spin that is not finite shows here (a velocity shows in x) */
            outside |= !(x[i].x >= lo.x && x[i].x <= hi.x && x[i].y >= lo.y && x[i].y <= hi.y &&
                         (planar || (x[i].z >= lo.z && x[i].z <= hi.z)));
            outside |= !((w[i].x + w[i].y) + w[i].z - ((w[i].x + w[i].y) + w[i].z) == 0);
        } else {
            /* not finite if any term is (and, rarely, when finite terms overflow: the check then
               finds nothing); a tree, so no long chain of dependent additions */
            const fsdem_real sum = (v[i].x + v[i].y) + (v[i].z + w[i].x) + (w[i].y + w[i].z);
            outside |= !(sum - sum == 0);
        }
    }
    d->max_disp2 = disp2;
    if (drift) {
        d->forces_valid = 0; /* they are cleared now */
        d->forces_cleared = 1;
    }
    for (k = 0; k < d->wall_count; ++k) d->walls[k].impulse = fsdem__madd(d->walls[k].impulse, d->walls[k].force, -h);
    return outside;
}

/* Velocity update v += h a, w += h alpha of the free particles, and the walls' impulse. */
static int fsdem__dem_kick(fsdem_dem *d, fsdem_real h) {
    return d->external ? fsdem__dem_verlet_pass(d, h, 0, 0, 1) : fsdem__dem_verlet_pass(d, h, 0, 0, 0);
}

/* Kick h, then drift h_drift (and clear the forces). */
static int fsdem__dem_kick_drift(fsdem_dem *d, fsdem_real h, fsdem_real h_drift) {
    return d->external ? fsdem__dem_verlet_pass(d, h, 1, h_drift, 1) : fsdem__dem_verlet_pass(d, h, 1, h_drift, 0);
}

static void fsdem__dem_track_displacement(fsdem_dem *d, int i) {
    fsdem_vec3 dd = fsdem__sub(d->x[i], d->x_ref[i]);
    fsdem_real d2 = fsdem__dot(dd, dd);
    if (d2 > d->max_disp2) d->max_disp2 = d2;
}

static void fsdem__dem_move_walls(fsdem_dem *d, fsdem_real h) {
    int k;
    for (k = 0; k < d->wall_count; ++k) {
        fsdem__dem_wall *w = &d->walls[k];
        fsdem_vec3 dv = fsdem__scale(w->d.velocity, h);
        if (w->d.type == FSDEM_DEM_WALL_TYPE_PLANE) w->d.a = fsdem__add(w->d.a, dv); /* b is the normal */
        else {
            w->d.a = fsdem__add(w->d.a, dv);
            w->d.b = fsdem__add(w->d.b, dv);
            w->d.c = fsdem__add(w->d.c, dv);
        }
        w->moved += fsdem__norm(dv);
    }
}

static fsdem_result fsdem__dem_ensure_lists(fsdem_dem *d) {
    if (fsdem__dem_lists_stale(d) && fsdem__dem_rebuild(d) != FSDEM_OK)
        return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_dem: out of memory growing the neighbour lists (%d particles)",
                           d->n);
    return FSDEM_OK;
}

/* Names the first particle that is not finite or left the domain. */
static fsdem_result fsdem__dem_check_particles(fsdem_dem *d) {
    char hint[160] = "";
    int i;
    if (d->stable_dt > 0 && d->dt > d->stable_dt)
        snprintf(hint, sizeof hint, "; dt = %g s is %.3g times the stable dt %g s (%s), the likely cause", (double)d->dt,
                 (double)(d->dt / d->stable_dt), (double)d->stable_dt, fsdem__dem_rule_name(d->desc.dt_rule));
    for (i = 0; i < d->n; ++i) {
        if (!fsdem__finite3(d->x[i]) || !fsdem__finite3(d->v[i]) || !fsdem__finite3(d->w[i]))
            return fsdem__fail(&d->status, FSDEM_ERR_NAN, "fsdem_dem: particle %d (id %d) has a non-finite state at t = %g s%s",
                               i, d->id[i], d->time, hint);
        if (!fsdem__dem_inside_domain(d, d->x[i]))
            return fsdem__fail(&d->status, FSDEM_ERR_OUT_OF_DOMAIN,
                               "fsdem_dem: particle %d (id %d) left the domain at t = %g s: position (%g, %g, %g) m%s", i,
                               d->id[i], d->time, (double)d->x[i].x, (double)d->x[i].y, (double)d->x[i].z, hint);
    }
    return FSDEM_OK;
}

/* Velocity Verlet: kick h/2 and drift h (one pass), forces, kick h/2. *suspect is set when a pass
   saw a state that fsdem__dem_check_particles should look at. */
static fsdem_result fsdem__dem_step_verlet(fsdem_dem *d, fsdem_real h, int *suspect) {
    if (fsdem__dem_ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    if (!d->forces_valid) fsdem__dem_compute_forces(d, h, 0);
    *suspect = fsdem__dem_kick_drift(d, h / 2, h);
    if (d->periodic) fsdem__dem_wrap(d);
    fsdem__dem_move_walls(d, h);
    if (fsdem__dem_ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__dem_compute_forces(d, h, 1);
    *suspect |= fsdem__dem_kick(d, h / 2);
    return FSDEM_OK;
}

/* Predictor-corrector of seed 000 Eq. 21-24 (forces include gravity and the fixed external ones).
   Eq. 22 and 24 as printed average U^n (the outer step's start) with the new velocity; we average
   the substep's own start velocity U_(k-1), which is the trapezoidal rule the scheme is built on
   and keeps positions consistent with velocities when K > 1. */
static fsdem_result fsdem__dem_step_predictor_corrector(fsdem_dem *d, fsdem_real h) {
    int i, k;
    if (fsdem__dem_ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__dem_compute_forces(d, h, 0); /* F_a at X_(k-1), U_(k-1); history not committed */
    for (k = 0; k < d->wall_count; ++k) d->walls[k].force_a = d->walls[k].force;
    for (i = 0; i < d->n; ++i) {
        d->x0[i] = d->x[i];
        d->v0[i] = d->v[i];
        d->w0[i] = d->w[i];
        d->fa[i] = d->f[i];
        d->ta[i] = d->t[i];
        if (!d->fixed[i]) {
            d->v[i] = fsdem__madd(d->v0[i], fsdem__dem_accel(d, d->fa, i), h);            /* Eq. 21 */
            d->w[i] = fsdem__madd(d->w0[i], fsdem__dem_spin_rate(d, d->ta, i), h);
            fsdem__dem_planar(d, &d->x[i], &d->v[i], &d->w[i]);
        }
        d->x[i] = fsdem__madd(d->x0[i], fsdem__add(d->v0[i], d->v[i]), h / 2);       /* Eq. 22 */
        fsdem__dem_track_displacement(d, i);
    }
    fsdem__dem_move_walls(d, h);
    if (fsdem__dem_ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__dem_compute_forces(d, h, 1); /* F_b at X_a, U_a */
    for (i = 0; i < d->n; ++i) {
        if (!d->fixed[i]) {
            fsdem_vec3 acc = fsdem__add(fsdem__dem_accel(d, d->fa, i), fsdem__dem_accel(d, d->f, i));
            fsdem_vec3 spin = fsdem__add(fsdem__dem_spin_rate(d, d->ta, i), fsdem__dem_spin_rate(d, d->t, i));
            d->v[i] = fsdem__madd(d->v0[i], acc, h / 2);                               /* Eq. 23 */
            d->w[i] = fsdem__madd(d->w0[i], spin, h / 2);
            fsdem__dem_planar(d, &d->x[i], &d->v[i], &d->w[i]);
        }
        d->x[i] = fsdem__madd(d->x0[i], fsdem__add(d->v0[i], d->v[i]), h / 2);       /* Eq. 24 */
        fsdem__dem_track_displacement(d, i);
    }
    for (k = 0; k < d->wall_count; ++k)
        d->walls[k].impulse = fsdem__madd(d->walls[k].impulse, fsdem__add(d->walls[k].force_a, d->walls[k].force), -h / 2);
    if (d->periodic) fsdem__dem_wrap(d); /* the predicted positions need none: pairs take minimum images */
    d->forces_valid = 0; /* the last forces belong to the predicted state, not the final one */
    return FSDEM_OK;
}

static fsdem_result fsdem__dem_step(fsdem_dem *d, fsdem_real h) {
    int suspect = 1;
    fsdem_result res = d->desc.integrator == FSDEM_DEM_INTEGRATOR_PREDICTOR_CORRECTOR ? fsdem__dem_step_predictor_corrector(d, h)
                                                                                  : fsdem__dem_step_verlet(d, h, &suspect);
    if (res != FSDEM_OK) return res;
    d->time += h;
    d->steps++;
    return suspect ? fsdem__dem_check_particles(d) : FSDEM_OK;
}

fsdem_result fsdem_dem_step(fsdem_dem *d) {
    fsdem_result res;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    res = fsdem__dem_step(d, d->dt);
    return res == FSDEM_OK ? fsdem__ok(&d->status) : res;
}

fsdem_result fsdem_dem_step_dt(fsdem_dem *d, fsdem_real dt) {
    fsdem_result res;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_step_dt: dt must be > 0 (got %g s)", (double)dt);
    res = fsdem__dem_step(d, dt);
    return res == FSDEM_OK ? fsdem__ok(&d->status) : res;
}

/* Substeps of an outer step (seed 000): K = INT(dt/dt_DEM), dt_DEM = dt/K, and Eq. 25: one substep of
   dt when dt_DEM > dt. The relative tolerance (1e-9, more in float) keeps an exact multiple
   (3e-4/1e-4 = 2.9999999999999996, or 1000 dt rounded to float) from losing a step. */
static fsdem_result fsdem__dem_substeps(const fsdem_dem *d, fsdem_real duration, long long *count, const char *who) {
    fsdem__status *st = (fsdem__status *)&d->status; /* the message is the object's only mutable part here */
    const double ratio = (double)duration / d->dt * (1 + fsdem__tolerance(1e-9));
    if (!(duration > 0) || !fsdem__finite(duration))
        return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: the duration must be > 0 (got %g s)", who, (double)duration);
    if (ratio > (double)FSDEM_DEM_MAX_SUBSTEPS)
        return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: %g s / dt %g s = %g substeps is more than FSDEM_DEM_MAX_SUBSTEPS (%lld)",
                           who, (double)duration, (double)d->dt, ratio, FSDEM_DEM_MAX_SUBSTEPS);
    *count = ratio < 1 ? 1 : (long long)ratio;
    return FSDEM_OK;
}

fsdem_result fsdem_dem_substep_count(const fsdem_dem *d, fsdem_real duration, long long *count) {
    if (!d || !count) return FSDEM_ERR_INVALID_ARG;
    return fsdem__dem_substeps(d, duration, count, "fsdem_dem_substep_count");
}

/* `count` Verlet steps of h as leapfrog: the closing half kick of a step and the opening one of the
   next are one kick of h in the kick-drift pass, so a step costs one pass over the particles, not
   two. The same arithmetic as `count` calls of fsdem__dem_step_verlet (velocities in between are never
   seen); the half kick is closed at the end, and early when a pass saw a suspect state, which the
   check then names (the substeps stop there), or when the callback `fn` (run after every force
   evaluation) fails. */
static fsdem_result fsdem__dem_advance_verlet(fsdem_dem *d, fsdem_real h, long long count, fsdem_dem_substep_fn fn,
                                              void *user) {
    long long k;
    int open = 0, suspect;
    fsdem_result res;
    if (fsdem__dem_ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    if (!d->forces_valid) fsdem__dem_compute_forces(d, h, 0);
    if (fn && (res = fn(user, d, d->time)) != FSDEM_OK) return res;
    for (k = 0; k < count; ++k) {
        fsdem_result called = FSDEM_OK;
        suspect = fsdem__dem_kick_drift(d, open ? h : h / 2, h);
        if (d->periodic) fsdem__dem_wrap(d);
        fsdem__dem_move_walls(d, h);
        if (fsdem__dem_ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
        fsdem__dem_compute_forces(d, h, 1);
        d->time += h;
        d->steps++;
        open = 1;
        if (fn) called = fn(user, d, d->time);
        if (k == count - 1 || suspect || called != FSDEM_OK) {
            suspect |= fsdem__dem_kick(d, h / 2);
            open = 0;
            res = suspect ? fsdem__dem_check_particles(d) : FSDEM_OK;
            if (res != FSDEM_OK) return res;
            if (called != FSDEM_OK) return called;
        }
    }
    return FSDEM_OK;
}

/* The smallest extent (m) of the box [lo, hi] along the first `dim` axes. */
static fsdem_real fsdem__smallest_extent(fsdem_vec3 lo, fsdem_vec3 hi, int dim) {
    fsdem_real e = hi.x - lo.x;
    if (hi.y - lo.y < e) e = hi.y - lo.y;
    if (dim == 3 && hi.z - lo.z < e) e = hi.z - lo.z;
    return e;
}

/* A coupler's record of DEM particle `index`. Records k = 0 .. count - 1 were made for particles
   whose stable ids, the int at ids + k stride bytes, ascend: the DEM keeps its ids in index order
   (new particles go to the end, removals keep the order), so a particle removed or added since the
   records were made is told by its id, found by bisection. Returns the record, or -1 for none. */
static int fsdem__dem_record_of(const fsdem_dem *d, int index, const int *ids, size_t stride, int count) {
    int lo = 0, hi = count - 1, id;
    if (index < 0 || index >= d->n) return -1;
    id = d->id[index];
    while (lo <= hi) {
        const int mid = lo + (hi - lo) / 2, at = *(const int *)(const void *)((const char *)ids + (size_t)mid * stride);
        if (at == id) return mid;
        if (at < id) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

/* A coupler's check that every DEM particle fits in the fluid's domain [lo, hi] (a sphere wider
   than the domain's smallest extent leaves no fluid around it); the particle goes to `status`. */
static fsdem_result fsdem__dem_particles_fit(const fsdem_dem *d, fsdem_vec3 lo, fsdem_vec3 hi, fsdem__status *status, const char *who) {
    const fsdem_real extent = fsdem__smallest_extent(lo, hi, d->desc.dim);
    int i;
    for (i = 0; i < d->n; ++i)
        if (!(2 * d->r[i] < extent))
            return fsdem__fail(status, FSDEM_ERR_INVALID_ARG,
                               "%s: DEM particle %d (id %d) of radius %g m does not fit in the fluid's domain (smallest extent %g m)",
                               who, i, d->id[i], (double)d->r[i], (double)extent);
    return FSDEM_OK;
}

/* A coupler's check before a fluid step of dt moves anything: the DEM can follow it in at most
   `max` substeps; the failure goes to the coupler's `status` under its name `who`. */
static fsdem_result fsdem__dem_substeps_within(const fsdem_dem *d, fsdem_real dt, long long max, fsdem__status *status,
                                               const char *who) {
    long long substeps = 0;
    const fsdem_result res = fsdem_dem_substep_count(d, dt, &substeps);
    if (res != FSDEM_OK) return fsdem__fail(status, res, "%s: %s", who, fsdem_dem_last_error(d));
    if (substeps > max)
        return fsdem__fail(status, FSDEM_ERR_INVALID_ARG,
                           "%s: the fluid step %g s needs %lld DEM substeps, more than max_substeps %lld (DEM dt %g s)", who,
                           (double)dt, substeps, max, (double)d->dt);
    return FSDEM_OK;
}

/* The advance of a coupler whose step is prepared (forces, stable dt) and then run: steps until
   exactly `duration` later, the last ones shortened to end exactly as the solvers' advances do
   (fsdem_mps_dem_advance, fsdem_pic_dem_advance). */
typedef struct fsdem__coupled_verbs {
    double (*now)(const void *coupler);                        /* the fluid's time (s) */
    fsdem_result (*prepare)(void *coupler, fsdem_real *dt);    /* the stable dt of the coming step */
    fsdem_result (*run)(void *coupler, fsdem_real dt);         /* one coupled step of dt */
} fsdem__coupled_verbs;

static fsdem_result fsdem__coupled_advance(void *c, fsdem__status *status, const char *who, const fsdem__coupled_verbs *v,
                                           fsdem_real duration, long long *steps) {
    double end;
    long long n = 0;
    fsdem_result res = FSDEM_OK;
    if (!(duration >= 0) || !fsdem__finite(duration))
        return fsdem__fail(status, FSDEM_ERR_INVALID_ARG, "%s: duration = %g s must be >= 0", who, (double)duration);
    end = v->now(c) + (double)duration;
    while (res == FSDEM_OK && v->now(c) < end - 1e-12 * (end > 1 ? end : 1)) {
        const double left = end - v->now(c);
        fsdem_real dt = 0;
        if ((res = v->prepare(c, &dt)) != FSDEM_OK) break;
        if ((double)dt >= left) dt = (fsdem_real)left;
        else if (1.5 * (double)dt > left) dt = (fsdem_real)(left / 2);
        res = v->run(c, dt);
        ++n;
    }
    if (steps) *steps = n;
    return res;
}

/* fsdem_dem_advance_with, its errors under the public name `who` */
static fsdem_result fsdem__dem_advance(fsdem_dem *d, fsdem_real duration, fsdem_dem_substep_fn fn, void *user, long long *steps,
                                       const char *who) {
    long long k, count = 0;
    fsdem_result res;
    if (steps) *steps = 0;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    res = fsdem__dem_substeps(d, duration, &count, who);
    if (res != FSDEM_OK) return res;
    if (steps) *steps = count;
    if (d->desc.integrator == FSDEM_DEM_INTEGRATOR_VERLET)
        res = fsdem__dem_advance_verlet(d, duration / (fsdem_real)count, count, fn, user);
    else
        for (k = 0; k < count && res == FSDEM_OK; ++k) {
            /* the predictor-corrector holds the external loads over a substep: one call at its start */
            if (fn) res = fn(user, d, d->time);
            if (res == FSDEM_OK) res = fsdem__dem_step(d, duration / (fsdem_real)count);
        }
    return res == FSDEM_OK ? fsdem__ok(&d->status) : res;
}

fsdem_result fsdem_dem_advance_with(fsdem_dem *d, fsdem_real duration, fsdem_dem_substep_fn fn, void *user,
                                    long long *steps) {
    return fsdem__dem_advance(d, duration, fn, user, steps, "fsdem_dem_advance_with");
}

fsdem_result fsdem_dem_advance(fsdem_dem *d, fsdem_real duration, long long *steps) {
    return fsdem__dem_advance(d, duration, NULL, NULL, steps, "fsdem_dem_advance");
}

fsdem_result fsdem_dem_set_dt(fsdem_dem *d, fsdem_real dt) {
    if (!d) return FSDEM_ERR_INVALID_ARG;
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG, "fsdem_dem_set_dt: dt must be > 0 (got %g s)", (double)dt);
    d->dt = dt;
    fsdem__dem_dt_check(d);
    return fsdem__ok(&d->status);
}

double fsdem_dem_time(const fsdem_dem *d) { return d ? d->time : 0; }

fsdem_dem_desc fsdem_dem_get_desc(const fsdem_dem *d) {
    fsdem_dem_desc desc;
    if (!d) {
        memset(&desc, 0, sizeof desc);
        return desc;
    }
    desc = d->desc;
    desc.dt = d->dt;
    return desc;
}

/* ---- >>dem_diagnostics : time-step estimates, energy, statistics ---- */

fsdem_result fsdem_dem_stable_dt(const fsdem_dem *d, fsdem_real *dt) {
    fsdem__status *st;
    if (!d || !dt) return FSDEM_ERR_INVALID_ARG;
    st = (fsdem__status *)&d->status; /* the message is the object's only mutable part here */
    if (d->n == 0) return fsdem__fail(st, FSDEM_ERR_NOT_FOUND, "fsdem_dem_stable_dt: there are no particles");
    *dt = fsdem__dem_rule_dt(d);
    return fsdem__ok(st);
}

/* Elastic energy (J) stored in one contact's normal and tangential springs: overlap delta, mean
   and effective radius as the force kernels see them (fsdem__dem_batch). */
static fsdem_real fsdem__dem_contact_energy(const fsdem_dem *d, const fsdem__dem_pair *p, fsdem_real delta, fsdem_real m_mean,
                                        fsdem_real r_eff, fsdem_vec3 history) {
    switch ((int)fsdem__dem_kernel_law(d)) {
    case FSDEM_DEM_LAW_LINEAR: return (fsdem_real)0.5 * m_mean * d->k0_linear * delta * delta;
    case FSDEM_DEM_LAW_GIC: return (fsdem_real)0.5 * p->e_pair * 2 * r_eff * delta * delta;
    case FSDEM__DEM_LAW_SEED002: { /* chi^n d^2 / 2 + chi^t |xi|^2 / 2 (Eq. 19-22) */
        const fsdem_real chi = p->kn * (fsdem_real)sqrt(r_eff);
        return (fsdem_real)0.5 * chi * (delta * delta + p->kt * fsdem__dot(history, history));
    }
    default: {
        fsdem_real srd = (fsdem_real)sqrt(r_eff * delta);
        /* integral of (4/3) E* sqrt(R*) d^1.5 = (8/15) E* sqrt(R*) d^2.5, plus the Mindlin spring */
        return (fsdem_real)(8.0 / 15.0) * p->e_star * srd * delta * delta +
               (fsdem_real)0.5 * 8 * p->g_star * srd * fsdem__dot(history, history);
    }
    }
}

fsdem_dem_energy fsdem_dem_get_energy(const fsdem_dem *d) {
    fsdem_dem_energy e;
    int i, k, nh, nm;
    memset(&e, 0, sizeof e);
    if (!d) return e;
    nm = d->material_count;
    for (i = 0; i < d->n; ++i) {
        fsdem_real iner = d->inv_i[i] > 0 ? 1 / d->inv_i[i] : 0;
        if (d->fixed[i]) continue;
        e.kinetic += (fsdem_real)0.5 * d->m[i] * fsdem__dot(d->v[i], d->v[i]);
        e.rotational += (fsdem_real)0.5 * iner * fsdem__dot(d->w[i], d->w[i]);
        e.potential -= d->m[i] * fsdem__dot(d->desc.gravity, d->x[i]);
    }
    if (d->need_rebuild) return e; /* lists are stale after edits; springs are counted after a step */
    for (i = 0; i < d->n; ++i) {
        const fsdem__dem_pair *row = d->pairs + d->material[i] * nm;
        for (k = d->pp.start[i]; k < d->pp.start[i + 1]; ++k) {
            int j = FSDEM__DEM_PARTNER(d->pp.key[k]);
            fsdem_real delta = d->r[i] + d->r[j] + d->desc.contact_offset - fsdem__norm(fsdem__dem_min_image(d, fsdem__sub(d->x[i], d->x[j])));
            if (delta <= 0) continue;
            e.elastic += fsdem__dem_contact_energy(d, row + d->material[j], delta, (d->m[i] + d->m[j]) / 2,
                                               d->r[i] * d->r[j] / (d->r[i] + d->r[j]), fsdem__dem_spring(&d->pp, k));
        }
        nh = d->inv_m[i] > 0 ? fsdem__dem_wall_hits((fsdem_dem *)d, i, 0) : 0; /* fixed: no wall force */
        for (k = 0; k < nh; ++k) {
            const fsdem__dem_wall_hit *hit = &d->hits[k];
            e.elastic += fsdem__dem_contact_energy(d, row + d->walls[FSDEM__DEM_WALL_OF(d->pw.key[hit->entry])].d.material,
                                               hit->delta, d->m[i], d->r[i], fsdem__dem_spring(&d->pw, hit->entry));
        }
    }
    return e;
}

fsdem_dem_stats fsdem_dem_get_stats(const fsdem_dem *d) {
    fsdem_dem_stats s;
    memset(&s, 0, sizeof s);
    if (!d) return s;
    s.steps = d->steps;
    s.time = d->time;
    s.dt = d->dt;
    s.stable_dt = d->stable_dt;
    s.dt_ratio = d->stable_dt > 0 ? d->dt / d->stable_dt : 0;
    s.rebuilds = d->rebuilds;
    s.contacts = d->contacts;
    s.wall_contacts = d->wall_contacts;
    s.neighbour_pairs = d->pp.count + d->inert_count;
    s.max_overlap = d->max_overlap;
    s.memory_bytes = sizeof *d + fsdem__dem_particle_bytes((fsdem_dem *)d, d->capacity) +
                     (size_t)(d->pp.capacity + d->pp_old.capacity + d->pw.capacity + d->pw_old.capacity) *
                         (2 * sizeof(int) + sizeof(fsdem_vec3)) +
                     (size_t)(d->pp.start_capacity + d->pp_old.start_capacity + d->pw.start_capacity +
                              d->pw_old.start_capacity) * sizeof(int) +
                     (size_t)(d->grid.cell_capacity + 2 * d->grid.item_capacity) * sizeof(int) +
                     (size_t)d->pair_capacity * sizeof(fsdem__dem_pair) + (size_t)d->wall_capacity * sizeof(fsdem__dem_wall) +
                     (size_t)d->material_capacity * sizeof(fsdem_dem_material) + d->arena.size +
                     (size_t)(d->found_capacity + d->inert_capacity) * sizeof(int) +
                     (size_t)d->hit_capacity * sizeof(fsdem__dem_wall_hit);
    return s;
}

/* Writes contact `count` to out when there is room. */
static void fsdem__dem_report_contact(fsdem_dem_contact *out, int capacity, int count, int i, int j, fsdem_vec3 n,
                                  fsdem_real overlap) {
    if (!out || count >= capacity) return;
    out[count].i = i;
    out[count].j = j;
    out[count].normal = n;
    out[count].overlap = overlap;
}

/* Reports particles i < j as contact `count` when they overlap; returns the new count. */
static int fsdem__dem_report_pair(const fsdem_dem *d, fsdem_dem_contact *out, int capacity, int count, int i, int j) {
    fsdem_real dist;
    fsdem_vec3 n = fsdem__geom_direction(d->x[i], fsdem__dem_image_of(d, i, j), fsdem_v3(1, 0, 0), &dist);
    const fsdem_real overlap = d->r[i] + d->r[j] + d->desc.contact_offset - dist;
    if (overlap <= 0) return count;
    fsdem__dem_report_contact(out, capacity, count, i, j, n, overlap);
    return count + 1;
}

int fsdem_dem_contacts(fsdem_dem *d, fsdem_dem_contact *out, int capacity) {
    int i, k, nh, count = 0;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    if (fsdem__dem_ensure_lists(d) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    for (k = 0; k < d->inert_count; ++k) {
        const int a = d->inert[2 * k], b = d->inert[2 * k + 1];
        count = fsdem__dem_report_pair(d, out, capacity, count, a < b ? a : b, a < b ? b : a);
    }
    for (i = 0; i < d->n; ++i) {
        for (k = d->pp.start[i]; k < d->pp.start[i + 1]; ++k)
            count = fsdem__dem_report_pair(d, out, capacity, count, i, FSDEM__DEM_PARTNER(d->pp.key[k]));
        nh = fsdem__dem_wall_hits(d, i, 0);
        for (k = 0; k < nh; ++k)
            fsdem__dem_report_contact(out, capacity, count++, i, -1 - FSDEM__DEM_WALL_OF(d->pw.key[d->hits[k].entry]),
                                  d->hits[k].n, d->hits[k].delta);
    }
    return count;
}

/* ===== >>impl_linalg : sparse operators and preconditioned conjugate gradients ===== */

/* Contents: the padded layout and multigrid notes below; >>linalg_check (operator validation),
   >>linalg_object (creation, memory), >>linalg_grid (padded MAC-grid levels), >>linalg_kernels
   (stencil kernels), >>linalg_mg (V-cycle), >>linalg_ic (incomplete Cholesky), >>linalg_setup
   (setup for stencils and CSR), >>linalg_solve (preconditioned conjugate gradients). */

/* Layout. A stencil is solved on padded arrays: one ghost cell on each side of every axis (none
   along z in 2D), so the kernels need no bounds tests. Cell (i, j, k) sits at
   (i + 1) + (j + 1) sy + (k + 1) sz (2D: no z term). Each level of the operator stores
     type[c]   fsdem_stencil_cell (ghosts: AIR where the boundary face is Dirichlet, else SOLID),
               plus FSDEM__NEAR_SOLID on fluid cells whose coarse-grid interpolation touches a
               solid cell;
     d[c]      the diagonal (0 off fluid cells), inv_d[c] its inverse (0 where d = 0);
     w[a][c]   the coupling across the face on the low side of c along axis a. While a level is
               built it holds the physical coefficient (0 next to a solid); once the next coarser
               level exists it is reduced to the matrix off-diagonal: kept only between two fluid
               cells. Then y = A x is d x - sum w x_nb with no masks, since x is 0 off fluid cells.

   Multigrid (>>linalg_mg). Coarse levels halve each axis longer than one cell ((n + 1) / 2; an
   axis of one cell is not coarsened), down to one cell or to a level with no fluid left. A coarse
   cell is AIR if any child is air (Dirichlet dominates, so the coarse problem never loses its
   free surface), else FLUID if any child is fluid, else SOLID. A coarse face coefficient is the
   sum of its fine sub-face coefficients divided by the coarsening ratio along its normal, and
   the extra diagonal is summed over the children: this is the finite-volume rediscretisation
   that matches R A P for smooth fields with P = cell-centred (bi/tri)linear interpolation and
   R = P^T. P leaves out coarse cells that are solid and renormalises the remaining weights
   (Neumann); air cells and Dirichlet ghosts contribute their value 0. The V-cycle smooths with
   red-black Gauss-Seidel, red then black before the coarse correction and black then red after,
   so the preconditioner is symmetric positive definite, as CG needs. */

#define FSDEM__MG_MAX_LEVELS 40
#define FSDEM__NEAR_SOLID 0x80
#define FSDEM__TYPE(t) ((t) & 3)

#ifdef FSDEM_USE_FLOAT
#define FSDEM__SYM_TOL 1e-4
#define FSDEM__DEFAULT_TOL 1e-5
#else
#define FSDEM__SYM_TOL 1e-10
#define FSDEM__DEFAULT_TOL 1e-8
#endif

typedef struct fsdem__level {
    int n[3], ratio[3];    /* interior cells per axis; coarsening ratio from the finer level */
    fsdem_real h[3];       /* cell size per axis in units of the finest cell */
    int sy, sz, count;     /* padded strides and cell count */
    int fluid;             /* fluid cells */
    unsigned char *type;
    fsdem_real *d, *inv_d, *w[3];
    fsdem_real *x, *b;     /* multigrid vectors (level 0 borrows the CG vectors) */
} fsdem__level;

enum { FSDEM__KIND_NONE = 0, FSDEM__KIND_STENCIL = 1, FSDEM__KIND_CSR = 2 };

struct fsdem_pcg {
    fsdem_pcg_desc desc;
    fsdem__status status;
    fsdem_allocator allocator;
    int kind;               /* FSDEM__KIND_* of the last successful setup */
    fsdem_precond precond;  /* resolved preconditioner */
    int length;             /* internal vector length (padded cells or rows) */
    int user_length;        /* length of the caller's vectors */
    int dim;
    fsdem_stencil stencil;  /* geometry and extra term of the last stencil setup */
    fsdem_csr csr;          /* matrix of the last CSR setup */
    void *arena;            /* every array below lives in this one block */
    size_t arena_bytes;
    fsdem_real *x, *r, *z, *p; /* CG vectors; z also holds A p */
    fsdem_real *ux, *uy;    /* caller-layout copies for the stencil's extra term */
    int levels;
    fsdem__level level[FSDEM__MG_MAX_LEVELS];
    fsdem_real *ic;         /* stencil IC/MIC: 1/sqrt(pivot); CSR Jacobi: 1/diagonal */
    fsdem_real *rowbuf;     /* multigrid: two rows of the finest level */
    int ns_components, ns_cells; /* null space: fluid regions without a Dirichlet anchor */
    int *ns_cell;           /* their cells, each region's first cell stored as -(c + 1) */
    unsigned char *mark;
    int *u_start, *u_col;   /* CSR IC/MIC: upper factor U (M = U^T U), diagonal first per row */
    fsdem_real *u_val;
    int *u_pos;             /* CSR IC/MIC workspace: column -> position in a row of U, or -1 */
};

/* ---- >>linalg_check : validation of operators ---- */

static fsdem_real fsdem__stencil_face(const fsdem_stencil *st, int axis, int i, int j, int k) {
    const fsdem_real *f = st->face[axis];
    int n0 = st->n[0], n1 = st->n[1];
    if (!f) return 1;
    if (axis == 0) return f[((size_t)k * n1 + j) * (size_t)(n0 + 1) + i];
    if (axis == 1) return f[((size_t)k * (n1 + 1) + j) * (size_t)n0 + i];
    return f[((size_t)k * n1 + j) * (size_t)n0 + i];
}

static int fsdem__stencil_type(const fsdem_stencil *st, int i, int j, int k) {
    if (!st->cell) return FSDEM_STENCIL_CELL_FLUID;
    return st->cell[((size_t)k * st->n[1] + j) * (size_t)st->n[0] + i];
}

/* Padded cell count of a stencil (as a double: it may not fit an int). */
static double fsdem__stencil_padded(const fsdem_stencil *st) {
    return ((double)st->n[0] + 2) * ((double)st->n[1] + 2) * (st->dim == 3 ? (double)st->n[2] + 2 : 1);
}

/* Indices are ints; the multigrid levels add up to 8/7 of the finest. */
#define FSDEM__MAX_PADDED (2147483647.0 / 2)

/* Cells per axis with n[2] = 1 in 2D. */
static void fsdem__stencil_dims(const fsdem_stencil *st, int n[3]) {
    n[0] = st->n[0];
    n[1] = st->n[1];
    n[2] = st->dim == 3 ? st->n[2] : 1;
}

fsdem_result fsdem_stencil_check(const fsdem_stencil *st, char *msg, size_t size) {
    int n[3], i, j, k, a;
    double padded;
    if (!st) return fsdem__reject(msg, size, "fsdem_stencil is NULL");
    if (st->dim != 2 && st->dim != 3)
        return fsdem__reject(msg, size, "fsdem_stencil.dim must be 2 or 3 (got %d)", st->dim);
    fsdem__stencil_dims(st, n);
    for (a = 0; a < st->dim; ++a)
        if (n[a] < 1)
            return fsdem__reject(msg, size, "fsdem_stencil.n[%d] must be >= 1 (got %d)", a, n[a]);
    padded = fsdem__stencil_padded(st);
    if (padded > FSDEM__MAX_PADDED)
        return fsdem__reject(msg, size, "fsdem_stencil: %d x %d x %d cells is too large", n[0], n[1], n[2]);
    for (k = 0; st->cell && k < n[2]; ++k)
        for (j = 0; j < n[1]; ++j)
            for (i = 0; i < n[0]; ++i) {
                int t = fsdem__stencil_type(st, i, j, k);
                if (t > FSDEM_STENCIL_CELL_SOLID)
                    return fsdem__reject(msg, size, "fsdem_stencil.cell of cell (%d,%d,%d) is %d, not a "
                                                    "fsdem_stencil_cell", i, j, k, t);
            }
    if (!st->diag && !st->face[0] && !st->face[1] && (st->dim == 2 || !st->face[2])) return FSDEM_OK;
    for (k = 0; k < n[2]; ++k)
        for (j = 0; j < n[1]; ++j)
            for (i = 0; i < n[0]; ++i) {
                if (fsdem__stencil_type(st, i, j, k) != FSDEM_STENCIL_CELL_FLUID) continue;
                if (st->diag) {
                    fsdem_real dv = st->diag[((size_t)k * n[1] + j) * (size_t)n[0] + i];
                    if (!(dv >= 0) || !fsdem__finite(dv))
                        return fsdem__reject(msg, size, "fsdem_stencil.diag of fluid cell (%d,%d,%d) is %g; it "
                                                        "must be finite and >= 0", i, j, k, (double)dv);
                }
                /* both faces of every axis of a fluid cell are read */
                for (a = 0; a < st->dim; ++a) {
                    int side;
                    for (side = 0; side < 2; ++side) {
                        int fi = i + (a == 0 ? side : 0), fj = j + (a == 1 ? side : 0), fk = k + (a == 2 ? side : 0);
                        fsdem_real w = fsdem__stencil_face(st, a, fi, fj, fk);
                        if (!(w >= 0) || !fsdem__finite(w))
                            return fsdem__reject(msg, size, "fsdem_stencil.face[%d] at face (%d,%d,%d) of fluid "
                                                            "cell (%d,%d,%d) is %g; it must be finite and >= 0",
                                                 a, fi, fj, fk, i, j, k, (double)w);
                    }
                }
            }
    return FSDEM_OK;
}

/* Position of column `col` in row `row`, or -1. Columns are ascending. */
static int fsdem__csr_find(const fsdem_csr *m, int row, int col) {
    int lo = m->row_start[row], hi = m->row_start[row + 1] - 1;
    while (lo <= hi) {
        int mid = lo + (hi - lo) / 2;
        if (m->col[mid] == col) return mid;
        if (m->col[mid] < col) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

fsdem_result fsdem_csr_check(const fsdem_csr *m, char *msg, size_t size) {
    int i, e;
    if (!m) return fsdem__reject(msg, size, "fsdem_csr is NULL");
    if (m->rows < 1) return fsdem__reject(msg, size, "fsdem_csr.rows must be >= 1 (got %d)", m->rows);
    if (!m->row_start || !m->col || !m->val)
        return fsdem__reject(msg, size, "fsdem_csr: row_start, col and val must not be NULL");
    if (m->row_start[0] != 0)
        return fsdem__reject(msg, size, "fsdem_csr.row_start[0] must be 0 (got %d)", m->row_start[0]);
    for (i = 0; i < m->rows; ++i)
        if (m->row_start[i + 1] < m->row_start[i])
            return fsdem__reject(msg, size, "fsdem_csr.row_start decreases at row %d", i);
    for (i = 0; i < m->rows; ++i) {
        int has_diag = 0;
        for (e = m->row_start[i]; e < m->row_start[i + 1]; ++e) {
            int c = m->col[e];
            if (c < 0 || c >= m->rows)
                return fsdem__reject(msg, size, "fsdem_csr: column %d of row %d is out of range [0, %d)", c, i,
                                     m->rows);
            if (e > m->row_start[i] && c <= m->col[e - 1])
                return fsdem__reject(msg, size, "fsdem_csr: columns of row %d are not strictly ascending", i);
            if (!fsdem__finite(m->val[e]))
                return fsdem__reject(msg, size, "fsdem_csr: entry (%d,%d) is not finite", i, c);
            if (c == i) {
                has_diag = 1;
                if (!(m->val[e] > 0))
                    return fsdem__reject(msg, size, "fsdem_csr: diagonal entry (%d,%d) = %g is not positive, so the "
                                                    "matrix is not positive definite", i, i, (double)m->val[e]);
            }
        }
        if (!has_diag) return fsdem__reject(msg, size, "fsdem_csr: row %d has no diagonal entry", i);
    }
    for (i = 0; i < m->rows; ++i)
        for (e = m->row_start[i]; e < m->row_start[i + 1]; ++e) {
            int c = m->col[e], t;
            double a, b, scale;
            if (c == i) continue;
            t = fsdem__csr_find(m, c, i);
            if (c < i && t >= 0) continue; /* the pair was compared from row c */
            a = m->val[e];
            b = t >= 0 ? m->val[t] : 0;
            scale = fabs(a) > fabs(b) ? fabs(a) : fabs(b);
            if (fabs(a - b) > FSDEM__SYM_TOL * scale)
                return fsdem__reject(msg, size, "fsdem_csr is not symmetric: entry (%d,%d) = %g but (%d,%d) = %g%s", i,
                                     c, a, c, i, b, t >= 0 ? "" : " (absent)");
        }
    return FSDEM_OK;
}

void fsdem_csr_apply(const fsdem_csr *m, const fsdem_real *x, fsdem_real *y) {
    int i, e;
    for (i = 0; i < m->rows; ++i) {
        fsdem_real s = 0;
        for (e = m->row_start[i]; e < m->row_start[i + 1]; ++e) s += m->val[e] * x[m->col[e]];
        y[i] = s;
    }
}

/* Reference stencil product on caller-layout vectors, written straight from the definition in
   >>linalg (the solver's padded kernels are checked against it in the tests). */
void fsdem_stencil_apply(const fsdem_stencil *st, const fsdem_real *x, fsdem_real *y) {
    int n[3], i, j, k, a, side;
    fsdem__stencil_dims(st, n);
    for (k = 0; k < n[2]; ++k)
        for (j = 0; j < n[1]; ++j)
            for (i = 0; i < n[0]; ++i) {
                size_t c = ((size_t)k * n[1] + j) * (size_t)n[0] + i;
                fsdem_real s = 0;
                if (fsdem__stencil_type(st, i, j, k) != FSDEM_STENCIL_CELL_FLUID) {
                    y[c] = 0;
                    continue;
                }
                for (a = 0; a < st->dim; ++a)
                    for (side = 0; side < 2; ++side) {
                        int nb[3];
                        fsdem_real w;
                        nb[0] = i;
                        nb[1] = j;
                        nb[2] = k;
                        nb[a] += side ? 1 : -1;
                        w = fsdem__stencil_face(st, a, i + (a == 0 ? side : 0), j + (a == 1 ? side : 0),
                                                k + (a == 2 ? side : 0));
                        if (nb[a] < 0 || nb[a] >= n[a]) {
                            s += w * x[c]; /* Dirichlet outside when w > 0 */
                        } else {
                            int t = fsdem__stencil_type(st, nb[0], nb[1], nb[2]);
                            size_t cn = ((size_t)nb[2] * n[1] + nb[1]) * (size_t)n[0] + nb[0];
                            if (t == FSDEM_STENCIL_CELL_FLUID) s += w * (x[c] - x[cn]);
                            else if (t == FSDEM_STENCIL_CELL_AIR) s += w * x[c];
                        }
                    }
                if (st->diag) s += st->diag[c] * x[c];
                y[c] = s;
            }
    if (st->extra) st->extra(st->extra_user, x, y);
}

/* ---- >>linalg_object : creation, memory ---- */

fsdem_pcg_desc fsdem_pcg_desc_default(void) {
    fsdem_pcg_desc d;
    memset(&d, 0, sizeof d);
    d.preconditioner = FSDEM_PRECOND_AUTO;
    d.tolerance = (fsdem_real)FSDEM__DEFAULT_TOL;
    d.max_iterations = 1000;
    d.mic_tau = (fsdem_real)0.97;
    d.ic_safety = (fsdem_real)0.25;
    d.mg_sweeps = 2;
    return d;
}

fsdem_result fsdem_pcg_desc_check(const fsdem_pcg_desc *d, char *msg, size_t size) {
    if (!d) return fsdem__reject(msg, size, "fsdem_pcg_desc is NULL");
    if ((int)d->preconditioner < (int)FSDEM_PRECOND_AUTO || (int)d->preconditioner > (int)FSDEM_PRECOND_MG)
        return fsdem__reject(msg, size, "fsdem_pcg_desc.preconditioner is not a fsdem_precond (%d)",
                             (int)d->preconditioner);
    if (!(d->tolerance > 0) || !fsdem__finite(d->tolerance))
        return fsdem__reject(msg, size, "fsdem_pcg_desc.tolerance must be > 0 (got %g)", (double)d->tolerance);
    if (d->max_iterations < 1)
        return fsdem__reject(msg, size, "fsdem_pcg_desc.max_iterations must be >= 1 (got %d)", d->max_iterations);
    if (!(d->mic_tau >= 0 && d->mic_tau <= 1))
        return fsdem__reject(msg, size, "fsdem_pcg_desc.mic_tau must be in [0, 1] (got %g)", (double)d->mic_tau);
    if (!(d->ic_safety >= 0 && d->ic_safety < 1))
        return fsdem__reject(msg, size, "fsdem_pcg_desc.ic_safety must be in [0, 1) (got %g)", (double)d->ic_safety);
    if (d->mg_sweeps < 1 || d->mg_sweeps > 64)
        return fsdem__reject(msg, size, "fsdem_pcg_desc.mg_sweeps must be in [1, 64] (got %d)", d->mg_sweeps);
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        return fsdem__reject(msg, size, "fsdem_pcg_desc.allocator: set both alloc and free, or neither");
    return FSDEM_OK;
}

fsdem_result fsdem_pcg_create(const fsdem_pcg_desc *desc, fsdem_pcg **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_pcg *s;
    fsdem_result res;
    if (out) *out = NULL;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    res = fsdem_pcg_desc_check(desc, msg, sizeof msg);
    s = (fsdem_pcg *)fsdem__object_new(res, msg, desc ? desc->log : NULL, desc ? desc->log_user : NULL,
                                       desc ? &desc->allocator : NULL, sizeof *s, "fsdem_pcg_create", &res);
    if (!s) return res;
    s->desc = *desc;
    s->allocator = desc->allocator;
    s->status.log = desc->log;
    s->status.log_user = desc->log_user;
    *out = s;
    return FSDEM_OK;
}

void fsdem_pcg_destroy(fsdem_pcg *s) {
    fsdem_allocator al;
    if (!s) return;
    al = s->allocator;
    fsdem__free(&al, s->arena, s->arena_bytes);
    fsdem__free(&al, s, sizeof *s);
}

const char *fsdem_pcg_last_error(const fsdem_pcg *s) { return s ? s->status.message : "fsdem_pcg is NULL"; }

fsdem_result fsdem_pcg_set_tolerance(fsdem_pcg *s, fsdem_real tolerance, int max_iterations) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!(tolerance > 0) || !fsdem__finite(tolerance))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pcg_set_tolerance: tolerance must be > 0 (got %g)",
                           (double)tolerance);
    if (max_iterations < 1)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pcg_set_tolerance: max_iterations must be >= 1 (got %d)", max_iterations);
    s->desc.tolerance = tolerance;
    s->desc.max_iterations = max_iterations;
    return fsdem__ok(&s->status);
}

/* Carves arrays out of one block: a first pass with base = NULL measures, a second assigns. */
typedef struct fsdem__pcg_carver {
    char *base;
    size_t used;
    int overflow;
} fsdem__pcg_carver;

static void *fsdem__pcg_carve(fsdem__pcg_carver *cv, size_t count, size_t elem) {
    size_t off = (cv->used + 63) & ~(size_t)63;
    if (elem && count > ((size_t)-1 - off) / elem / 2) {
        cv->overflow = 1;
        return NULL;
    }
    cv->used = off + count * elem;
    return cv->base ? (void *)(cv->base + off) : NULL;
}

/* Replaces the arena by one of at least `bytes` (contents are not kept). On failure the old arena
   and everything in it stay as they were. */
static fsdem_result fsdem__pcg_reserve(fsdem_pcg *s, size_t bytes) {
    void *fresh;
    if (bytes <= s->arena_bytes && s->arena) return FSDEM_OK;
    fresh = fsdem__alloc(&s->allocator, bytes);
    if (!fresh) return FSDEM_ERR_OUT_OF_MEMORY;
    fsdem__free(&s->allocator, s->arena, s->arena_bytes);
    s->arena = fresh;
    s->arena_bytes = bytes;
    return FSDEM_OK;
}

/* ---- >>linalg_grid : padded MAC-grid levels ---- */

static void fsdem__level_geometry(fsdem__level *L, int dim, const int n[3]) {
    L->n[0] = n[0];
    L->n[1] = n[1];
    L->n[2] = dim == 3 ? n[2] : 1;
    L->sy = n[0] + 2;
    L->sz = L->sy * (n[1] + 2);
    L->count = dim == 3 ? L->sz * (L->n[2] + 2) : L->sz;
}

static int fsdem__level_index(const fsdem__level *L, int dim, int i, int j, int k) {
    return (i + 1) + (j + 1) * L->sy + (dim == 3 ? (k + 1) * L->sz : 0);
}

/* Geometry of every level the multigrid may need (coarsening to one cell). Returns the count. */
static int fsdem__mg_plan(fsdem__level *lv, int dim, const int n0[3]) {
    int n[3], count = 0, a;
    n[0] = n0[0];
    n[1] = n0[1];
    n[2] = dim == 3 ? n0[2] : 1;
    for (a = 0; a < 3; ++a) {
        lv[0].ratio[a] = 1;
        lv[0].h[a] = 1;
    }
    for (;;) {
        fsdem__level_geometry(&lv[count], dim, n);
        ++count;
        if ((n[0] == 1 && n[1] == 1 && n[2] == 1) || count == FSDEM__MG_MAX_LEVELS) break;
        for (a = 0; a < 3; ++a) {
            lv[count].ratio[a] = n[a] > 1 ? 2 : 1;
            lv[count].h[a] = lv[count - 1].h[a] * (fsdem_real)lv[count].ratio[a];
            n[a] = n[a] > 1 ? (n[a] + 1) / 2 : 1;
        }
    }
    return count;
}

/* Ghost types from the boundary faces: a ghost is AIR (Dirichlet) when a boundary face between it
   and the nearest interior cell has a positive coefficient, else SOLID. */
static void fsdem__level_ghosts(fsdem__level *L, int dim) {
    int i, j, k, a;
    int lo[3], hi[3];
    for (a = 0; a < 3; ++a) {
        lo[a] = (a < dim) ? -1 : 0;
        hi[a] = (a < dim) ? L->n[a] : 0;
    }
    for (k = lo[2]; k <= hi[2]; ++k)
        for (j = lo[1]; j <= hi[1]; ++j)
            for (i = lo[0]; i <= hi[0]; ++i) {
                int g[3], c[3] = {0, 0, 0}, ghost = 0, air = 0, ci;
                g[0] = i;
                g[1] = j;
                g[2] = k;
                for (a = 0; a < dim; ++a) {
                    c[a] = g[a] < 0 ? 0 : g[a] >= L->n[a] ? L->n[a] - 1 : g[a];
                    if (c[a] != g[a]) ghost = 1;
                }
                if (!ghost) continue;
                ci = fsdem__level_index(L, dim, c[0], c[1], c[2]);
                for (a = 0; a < dim; ++a) {
                    int s = a == 0 ? 1 : a == 1 ? L->sy : L->sz;
                    if (g[a] < 0 && L->w[a][ci] > 0) air = 1;
                    if (g[a] >= L->n[a] && L->w[a][ci + s] > 0) air = 1;
                }
                L->type[fsdem__level_index(L, dim, i, j, k)] =
                    (unsigned char)(air ? FSDEM_STENCIL_CELL_AIR : FSDEM_STENCIL_CELL_SOLID);
            }
}

/* Diagonal of a level from its physical face coefficients and the extra diagonal `extra`. */
static void fsdem__level_diagonal(fsdem__level *L, int dim, const fsdem_real *extra) {
    int c, a;
    L->fluid = 0;
    for (c = 0; c < L->count; ++c) {
        fsdem_real d = 0;
        if (FSDEM__TYPE(L->type[c]) != FSDEM_STENCIL_CELL_FLUID) {
            L->d[c] = L->inv_d[c] = 0;
            continue;
        }
        for (a = 0; a < dim; ++a) {
            int s = a == 0 ? 1 : a == 1 ? L->sy : L->sz;
            d += L->w[a][c] + L->w[a][c + s];
        }
        d += extra[c];
        L->d[c] = d;
        L->inv_d[c] = d > 0 ? 1 / d : 0;
        L->fluid++;
    }
}

/* Reduces the physical face coefficients of a level to matrix off-diagonals. */
static void fsdem__level_offdiagonal(fsdem__level *L, int dim) {
    int c, a;
    for (a = 0; a < dim; ++a) {
        int s = a == 0 ? 1 : a == 1 ? L->sy : L->sz;
        fsdem_real *w = L->w[a];
        for (c = 0; c < L->count; ++c)
            if (FSDEM__TYPE(L->type[c]) != FSDEM_STENCIL_CELL_FLUID || c - s < 0 ||
                FSDEM__TYPE(L->type[c - s]) != FSDEM_STENCIL_CELL_FLUID)
                w[c] = 0;
    }
}

/* Level 0 from the caller's stencil: types, physical coefficients, extra diagonal (to `extra`). */
static void fsdem__level_from_stencil(fsdem__level *L, const fsdem_stencil *st, fsdem_real *extra) {
    int dim = st->dim, i, j, k, a;
    memset(L->type, FSDEM_STENCIL_CELL_SOLID, (size_t)L->count);
    for (a = 0; a < 3; ++a)
        if (a < dim) memset(L->w[a], 0, sizeof(fsdem_real) * (size_t)L->count);
    memset(extra, 0, sizeof(fsdem_real) * (size_t)L->count);
    for (k = 0; k < L->n[2]; ++k)
        for (j = 0; j < L->n[1]; ++j)
            for (i = 0; i < L->n[0]; ++i)
                L->type[fsdem__level_index(L, dim, i, j, k)] = (unsigned char)fsdem__stencil_type(st, i, j, k);
    /* Each face once, stored at the cell on its high side; only faces with a fluid side are read. */
    for (a = 0; a < dim; ++a) {
        int s = a == 0 ? 1 : a == 1 ? L->sy : L->sz;
        int ext[3];
        ext[0] = L->n[0];
        ext[1] = L->n[1];
        ext[2] = L->n[2];
        ext[a] += 1;
        for (k = 0; k < ext[2]; ++k)
            for (j = 0; j < ext[1]; ++j)
                for (i = 0; i < ext[0]; ++i) {
                    int hi = fsdem__level_index(L, dim, i, j, k);
                    int t_hi = (a == 0 ? i : a == 1 ? j : k) < L->n[a] ? L->type[hi] : -1;
                    int t_lo = (a == 0 ? i : a == 1 ? j : k) > 0 ? L->type[hi - s] : -1;
                    if (t_hi != FSDEM_STENCIL_CELL_FLUID && t_lo != FSDEM_STENCIL_CELL_FLUID) continue;
                    if (t_hi == FSDEM_STENCIL_CELL_SOLID || t_lo == FSDEM_STENCIL_CELL_SOLID) continue;
                    L->w[a][hi] = fsdem__stencil_face(st, a, i, j, k);
                }
    }
    if (st->diag)
        for (k = 0; k < L->n[2]; ++k)
            for (j = 0; j < L->n[1]; ++j)
                for (i = 0; i < L->n[0]; ++i) {
                    int c = fsdem__level_index(L, dim, i, j, k);
                    if (L->type[c] == FSDEM_STENCIL_CELL_FLUID)
                        extra[c] = st->diag[((size_t)k * L->n[1] + j) * (size_t)L->n[0] + i];
                }
    fsdem__level_ghosts(L, dim);
}

/* Coarse level C from fine level F (physical coefficients, extra diagonal `fextra`); writes the
   coarse extra diagonal to `cextra`. */
static void fsdem__level_coarsen(const fsdem__level *F, fsdem__level *C, int dim, const fsdem_real *fextra,
                                 fsdem_real *cextra) {
    int I, J, K, a, di, dj, dk;
    int rx = C->ratio[0], ry = C->ratio[1], rz = C->ratio[2];
    memset(C->type, FSDEM_STENCIL_CELL_SOLID, (size_t)C->count);
    memset(cextra, 0, sizeof(fsdem_real) * (size_t)C->count);
    for (a = 0; a < dim; ++a) memset(C->w[a], 0, sizeof(fsdem_real) * (size_t)C->count);
    for (K = 0; K < C->n[2]; ++K)
        for (J = 0; J < C->n[1]; ++J)
            for (I = 0; I < C->n[0]; ++I) {
                int any_air = 0, any_fluid = 0, c = fsdem__level_index(C, dim, I, J, K);
                fsdem_real ex = 0;
                for (dk = 0; dk < rz; ++dk)
                    for (dj = 0; dj < ry; ++dj)
                        for (di = 0; di < rx; ++di) {
                            int i = I * rx + di, j = J * ry + dj, k = K * rz + dk, f, t;
                            if (i >= F->n[0] || j >= F->n[1] || k >= F->n[2]) continue;
                            f = fsdem__level_index(F, dim, i, j, k);
                            t = FSDEM__TYPE(F->type[f]);
                            if (t == FSDEM_STENCIL_CELL_AIR) any_air = 1;
                            if (t == FSDEM_STENCIL_CELL_FLUID) {
                                any_fluid = 1;
                                ex += fextra[f];
                            }
                        }
                C->type[c] = (unsigned char)(any_air ? FSDEM_STENCIL_CELL_AIR
                                             : any_fluid ? FSDEM_STENCIL_CELL_FLUID
                                                         : FSDEM_STENCIL_CELL_SOLID);
                cextra[c] = C->type[c] == FSDEM_STENCIL_CELL_FLUID ? ex : 0;
            }
    /* faces: the sum of the fine sub-faces over the coarsening ratio along the normal */
    for (a = 0; a < dim; ++a) {
        int ext[3], ra = C->ratio[a];
        ext[0] = C->n[0];
        ext[1] = C->n[1];
        ext[2] = C->n[2];
        ext[a] += 1;
        for (K = 0; K < ext[2]; ++K)
            for (J = 0; J < ext[1]; ++J)
                for (I = 0; I < ext[0]; ++I) {
                    int lo[3], cnt[3], u, v, wdx;
                    fsdem_real sum = 0;
                    int cc[3];
                    cc[0] = I;
                    cc[1] = J;
                    cc[2] = K;
                    for (u = 0; u < 3; ++u) {
                        if (u == a) {
                            lo[u] = cc[u] * ra > F->n[u] ? F->n[u] : cc[u] * ra;
                            cnt[u] = 1;
                        } else {
                            lo[u] = cc[u] * C->ratio[u];
                            cnt[u] = C->ratio[u];
                        }
                    }
                    for (wdx = 0; wdx < cnt[2]; ++wdx)
                        for (v = 0; v < cnt[1]; ++v)
                            for (u = 0; u < cnt[0]; ++u) {
                                int i = lo[0] + u, j = lo[1] + v, k = lo[2] + wdx;
                                if ((a != 0 && i >= F->n[0]) || (a != 1 && j >= F->n[1]) ||
                                    (a != 2 && k >= F->n[2]))
                                    continue;
                                sum += F->w[a][fsdem__level_index(F, dim, i, j, k)];
                            }
                    /* A boundary face reaches the Dirichlet point of the finest level, half a finest
                       cell beyond the face: scale by the ratio of the centre-to-point distances. */
                    if (cc[a] == 0 || cc[a] == C->n[a]) sum *= (F->h[a] + 1) / (C->h[a] + 1);
                    else sum /= (fsdem_real)ra;
                    C->w[a][fsdem__level_index(C, dim, I, J, K)] = sum;
                }
    }
    fsdem__level_ghosts(C, dim);
}

/* Marks fine fluid cells whose interpolation kernel (from level C) contains a solid cell. */
static void fsdem__level_mark_near_solid(fsdem__level *F, const fsdem__level *C, int dim) {
    int i, j, k;
    for (k = 0; k < F->n[2]; ++k)
        for (j = 0; j < F->n[1]; ++j)
            for (i = 0; i < F->n[0]; ++i) {
                int f = fsdem__level_index(F, dim, i, j, k), near = 0, u, v, w;
                int pc = fsdem__level_index(C, dim, i / C->ratio[0], j / C->ratio[1], k / C->ratio[2]);
                int o[3];
                if (FSDEM__TYPE(F->type[f]) != FSDEM_STENCIL_CELL_FLUID) continue;
                o[0] = C->ratio[0] == 2 ? ((i & 1) ? 1 : -1) : 0;
                o[1] = C->ratio[1] == 2 ? ((j & 1) ? C->sy : -C->sy) : 0;
                o[2] = C->ratio[2] == 2 ? ((k & 1) ? C->sz : -C->sz) : 0;
                for (w = 0; w < 2; ++w)
                    for (v = 0; v < 2; ++v)
                        for (u = 0; u < 2; ++u)
                            if (FSDEM__TYPE(C->type[pc + u * o[0] + v * o[1] + w * o[2]]) == FSDEM_STENCIL_CELL_SOLID)
                                near = 1;
                if (near) F->type[f] |= FSDEM__NEAR_SOLID;
            }
}

/* ---- >>linalg_kernels : stencil kernels on padded levels ---- */

/* y = A x on a level (interior cells; y untouched on ghosts). */
static void fsdem__level_apply(const fsdem__level *L, int dim, const fsdem_real *x, fsdem_real *y) {
    int i, j, k, sy = L->sy, sz = L->sz;
    const fsdem_real *d = L->d, *w0 = L->w[0], *w1 = L->w[1], *w2 = L->w[2];
    if (dim == 2) {
        for (j = 0; j < L->n[1]; ++j) {
            int c0 = (j + 1) * sy + 1;
            for (i = 0; i < L->n[0]; ++i) {
                int c = c0 + i;
                y[c] = d[c] * x[c] - w0[c] * x[c - 1] - w0[c + 1] * x[c + 1] - w1[c] * x[c - sy] -
                       w1[c + sy] * x[c + sy];
            }
        }
        return;
    }
    for (k = 0; k < L->n[2]; ++k)
        for (j = 0; j < L->n[1]; ++j) {
            int c0 = (k + 1) * sz + (j + 1) * sy + 1;
            for (i = 0; i < L->n[0]; ++i) {
                int c = c0 + i;
                y[c] = d[c] * x[c] - w0[c] * x[c - 1] - w0[c + 1] * x[c + 1] - w1[c] * x[c - sy] -
                       w1[c + sy] * x[c + sy] - w2[c] * x[c - sz] - w2[c + sz] * x[c + sz];
            }
        }
}

/* Gauss-Seidel on the cells of one colour ((i + j + k) % 2 == colour) of row (j, k). With
   `from_zero` the row is treated as if x were 0 before the sweep: cells of this colour get
   b / d and the others 0 (so no clearing pass is needed). */
static void fsdem__mg_smooth_row(const fsdem__level *L, int dim, const fsdem_real *b, fsdem_real *x, int colour, int j,
                              int k, int from_zero) {
    int i, sy = L->sy, sz = L->sz, n0 = L->n[0], c0 = fsdem__level_index(L, dim, 0, j, k);
    int i0 = (j + k + colour) & 1;
    const fsdem_real *inv_d = L->inv_d, *w0 = L->w[0], *w1 = L->w[1], *w2 = L->w[2];
    if (from_zero) {
        for (i = 0; i < n0; ++i) x[c0 + i] = 0;
        for (i = i0; i < n0; i += 2) x[c0 + i] = inv_d[c0 + i] * b[c0 + i];
        return;
    }
    if (dim == 2) {
        for (i = i0; i < n0; i += 2) {
            int c = c0 + i;
            x[c] = inv_d[c] *
                   (b[c] + w0[c] * x[c - 1] + w0[c + 1] * x[c + 1] + w1[c] * x[c - sy] + w1[c + sy] * x[c + sy]);
        }
        return;
    }
    for (i = i0; i < n0; i += 2) {
        int c = c0 + i;
        x[c] = inv_d[c] * (b[c] + w0[c] * x[c - 1] + w0[c + 1] * x[c + 1] + w1[c] * x[c - sy] + w1[c + sy] * x[c + sy] +
                           w2[c] * x[c - sz] + w2[c + sz] * x[c + sz]);
    }
}

/* Interpolation along one axis for fine index i and coarsening ratio r (1 or 2): the parent's
   coarse index *I, the offset *o (index step) to the other coarse cell, and the weights of the
   parent (*a) and of the other cell (*b). */
static void fsdem__mg_axis_weights(int i, int r, int stride, int *I, int *o, fsdem_real *a, fsdem_real *b) {
    if (r == 2) {
        *I = i >> 1;
        *o = (i & 1) ? stride : -stride;
        *a = (fsdem_real)0.75;
        *b = (fsdem_real)0.25;
    } else {
        *I = i;
        *o = 0;
        *a = 1;
        *b = 0;
    }
}

/* 1 / (sum of the interpolation weights of the non-solid coarse cells) for a fine cell whose
   kernel has parent pc, offsets o[] and weights a[], b[]. */
static fsdem_real fsdem__mg_interp_inv_norm(const fsdem__level *C, int pc, const int o[3], const fsdem_real a[3],
                                         const fsdem_real b[3]) {
    fsdem_real norm = 0;
    int u, v, w;
    for (w = 0; w < 2; ++w)
        for (v = 0; v < 2; ++v)
            for (u = 0; u < 2; ++u) {
                fsdem_real wt = (u ? b[0] : a[0]) * (v ? b[1] : a[1]) * (w ? b[2] : a[2]);
                if (wt != 0 && FSDEM__TYPE(C->type[pc + u * o[0] + v * o[1] + w * o[2]]) != FSDEM_STENCIL_CELL_SOLID)
                    norm += wt;
            }
    return norm > 0 ? 1 / norm : 0;
}

static fsdem_real fsdem__mg_interp_inv_norm1(const fsdem__level *C, int pc, int ox, int oy, int oz, fsdem_real ax,
                                          fsdem_real bx, fsdem_real ay, fsdem_real by, fsdem_real az, fsdem_real bz) {
    int o[3];
    fsdem_real a[3], b[3];
    o[0] = ox;
    o[1] = oy;
    o[2] = oz;
    a[0] = ax;
    a[1] = ay;
    a[2] = az;
    b[0] = bx;
    b[1] = by;
    b[2] = bz;
    return fsdem__mg_interp_inv_norm(C, pc, o, a, b);
}

/* P and P^T are tensor products of one-dimensional stencils (3/4 to the parent, 1/4 to the next
   coarse cell on the child's side), times 1/norm on fluid cells next to solids. Both are applied
   row by row: along x through a row buffer, along y and z as axpys between whole rows, which
   vectorises. `buf` holds two rows of the fine level (n[0] + 4 each). */

/* xf += P xc at the fluid cells of row (j, k) of F. */
static void fsdem__mg_prolong_row(const fsdem__level *F, const fsdem__level *C, int dim, const fsdem_real *xc,
                               fsdem_real *xf, int j, int k, fsdem_real *buf) {
    int i, I, J, K, oy, oz, crow, f0, nI = C->n[0];
    fsdem_real ay, by, az, bz, w00, w10, w01, w11;
    fsdem_real *cx = buf + 1; /* coarse row, indices -1 .. nI */
    const fsdem_real *x00, *x10, *x01, *x11;
    const unsigned char *type;
    fsdem__mg_axis_weights(j, C->ratio[1], C->sy, &J, &oy, &ay, &by);
    fsdem__mg_axis_weights(k, C->ratio[2], C->sz, &K, &oz, &az, &bz);
    if (dim == 2) {
        az = 1;
        bz = 0;
        oz = 0;
    }
    crow = fsdem__level_index(C, dim, 0, J, K);
    f0 = fsdem__level_index(F, dim, 0, j, k);
    x00 = xc + crow;
    x10 = x00 + oy;
    x01 = x00 + oz;
    x11 = x00 + oy + oz;
    w00 = ay * az;
    w10 = by * az;
    w01 = ay * bz;
    w11 = by * bz;
    /* y and z: combine up to four coarse rows (ghost ends included; they hold 0) */
    for (I = -1; I <= nI; ++I) cx[I] = w00 * x00[I] + w10 * x10[I] + w01 * x01[I] + w11 * x11[I];
    type = F->type + f0;
    if (C->ratio[0] == 2) {
        const fsdem_real q = (fsdem_real)0.75, e = (fsdem_real)0.25;
        for (i = 0; i < F->n[0]; ++i) {
            unsigned char t = type[i];
            fsdem_real v;
            I = i >> 1;
            v = q * cx[I] + e * cx[(i & 1) ? I + 1 : I - 1];
            if (t == FSDEM_STENCIL_CELL_FLUID) xf[f0 + i] += v;
            else if (FSDEM__TYPE(t) == FSDEM_STENCIL_CELL_FLUID)
                xf[f0 + i] += v * fsdem__mg_interp_inv_norm1(C, crow + I, (i & 1) ? 1 : -1, oy, oz, q, e, ay, by, az, bz);
        }
    } else {
        for (i = 0; i < F->n[0]; ++i) {
            unsigned char t = type[i];
            if (t == FSDEM_STENCIL_CELL_FLUID) xf[f0 + i] += cx[i];
            else if (FSDEM__TYPE(t) == FSDEM_STENCIL_CELL_FLUID)
                xf[f0 + i] += cx[i] * fsdem__mg_interp_inv_norm1(C, crow + i, 0, oy, oz, 1, 0, ay, by, az, bz);
        }
    }
}

/* bc += P^T (b - A x) over row (j, k) of F, the residual formed on the fly. b is 0 off fluid cells
   on every level, so the residual is too (d and the couplings vanish there). Coarse ghost and
   non-fluid entries receive values that fsdem__mg_clean clears. */
static void fsdem__mg_restrict_row(const fsdem__level *F, const fsdem__level *C, int dim, const fsdem_real *b,
                                const fsdem_real *x, fsdem_real *bc, int j, int k, fsdem_real *buf) {
    int i, I, J, K, oy, oz, crow, f0, n0 = F->n[0], nI = C->n[0], sy = F->sy, sz = F->sz;
    fsdem_real ay, by, az, bz;
    fsdem_real *r = buf + 2, *cr = buf + F->n[0] + 6;
    const fsdem_real *d, *w0, *w1, *w2, *bb, *xx;
    const unsigned char *type;
    fsdem__mg_axis_weights(j, C->ratio[1], C->sy, &J, &oy, &ay, &by);
    fsdem__mg_axis_weights(k, C->ratio[2], C->sz, &K, &oz, &az, &bz);
    if (dim == 2) {
        az = 1;
        bz = 0;
        oz = 0;
    }
    crow = fsdem__level_index(C, dim, 0, J, K);
    f0 = fsdem__level_index(F, dim, 0, j, k);
    d = F->d + f0;
    w0 = F->w[0] + f0;
    w1 = F->w[1] + f0;
    w2 = F->w[2] + f0;
    bb = b + f0;
    xx = x + f0;
    if (dim == 2)
        for (i = 0; i < n0; ++i)
            r[i] = bb[i] - d[i] * xx[i] + w0[i] * xx[i - 1] + w0[i + 1] * xx[i + 1] + w1[i] * xx[i - sy] +
                   w1[i + sy] * xx[i + sy];
    else
        for (i = 0; i < n0; ++i)
            r[i] = bb[i] - d[i] * xx[i] + w0[i] * xx[i - 1] + w0[i + 1] * xx[i + 1] + w1[i] * xx[i - sy] +
                   w1[i + sy] * xx[i + sy] + w2[i] * xx[i - sz] + w2[i + sz] * xx[i + sz];
    type = F->type + f0;
    for (i = 0; i < n0; ++i)
        if (type[i] & FSDEM__NEAR_SOLID) {
            int ox = C->ratio[0] == 2 ? ((i & 1) ? 1 : -1) : 0;
            fsdem_real ax = C->ratio[0] == 2 ? (fsdem_real)0.75 : 1, bx = C->ratio[0] == 2 ? (fsdem_real)0.25 : 0;
            r[i] *= fsdem__mg_interp_inv_norm1(C, crow + (C->ratio[0] == 2 ? i >> 1 : i), ox, oy, oz, ax, bx, ay, by, az,
                                            bz);
        }
    /* x: coarse I gathers 1/4, 3/4, 3/4, 1/4 from fine 2I-1 .. 2I+2 (zero beyond the row) */
    if (C->ratio[0] == 2) {
        const fsdem_real q = (fsdem_real)0.75, e = (fsdem_real)0.25;
        r[-1] = r[n0] = r[n0 + 1] = 0;
        for (I = 0; I < nI; ++I) cr[I] = e * (r[2 * I - 1] + r[2 * I + 2]) + q * (r[2 * I] + r[2 * I + 1]);
    } else {
        for (I = 0; I < nI; ++I) cr[I] = r[I];
    }
    /* y and z: add to up to four coarse rows */
    {
        fsdem_real *c00 = bc + crow, *c10 = c00 + oy, *c01 = c00 + oz, *c11 = c00 + oy + oz;
        fsdem_real w00 = ay * az, w10 = by * az, w01 = ay * bz, w11 = by * bz;
        for (I = 0; I < nI; ++I) c00[I] += w00 * cr[I];
        if (w10 != 0)
            for (I = 0; I < nI; ++I) c10[I] += w10 * cr[I];
        if (w01 != 0)
            for (I = 0; I < nI; ++I) c01[I] += w01 * cr[I];
        if (w11 != 0)
            for (I = 0; I < nI; ++I) c11[I] += w11 * cr[I];
    }
}

/* Zeroes b on the non-fluid cells (ghosts included) of a level after a restriction. */
static void fsdem__mg_clean(const fsdem__level *L, fsdem_real *b) {
    int c;
    for (c = 0; c < L->count; ++c)
        if (FSDEM__TYPE(L->type[c]) != FSDEM_STENCIL_CELL_FLUID) b[c] = 0;
}

/* ---- >>linalg_mg : multigrid V-cycle ---- */

/* The V-cycle works slab by slab (a slab is a row in 2D, a plane in 3D) as a wavefront: in one
   pass over memory, stage s of a pipeline handles slab t - s at step t. Each Gauss-Seidel
   half-sweep is a stage, so are the fused residual-restriction and the prolongation. A stage
   only reads slabs that the stage before it has finished and the stage after it has not yet
   touched, so the result is exactly that of the half-sweeps one after another, at a fraction of
   the memory traffic. */
enum { FSDEM__STAGE_SMOOTH, FSDEM__STAGE_SMOOTH_FROM_ZERO, FSDEM__STAGE_RESTRICT, FSDEM__STAGE_PROLONG };

typedef struct fsdem__mg_stage {
    int kind, colour;
} fsdem__mg_stage;

static void fsdem__mg_pipeline(const fsdem__level *L, const fsdem__level *C, int dim, const fsdem_real *b,
                               fsdem_real *x, fsdem_real *xc_or_bc, const fsdem__mg_stage *stage, int stages,
                               fsdem_real *buf) {
    int slabs = dim == 3 ? L->n[2] : L->n[1], t, s, j;
    for (t = 0; t < slabs + stages - 1; ++t)
        for (s = 0; s < stages; ++s) {
            int p = t - s, jb = dim == 3 ? 0 : p, je = dim == 3 ? L->n[1] : p + 1, k = dim == 3 ? p : 0;
            if (p < 0 || p >= slabs) continue;
            for (j = jb; j < je; ++j) switch (stage[s].kind) {
                case FSDEM__STAGE_SMOOTH: fsdem__mg_smooth_row(L, dim, b, x, stage[s].colour, j, k, 0); break;
                case FSDEM__STAGE_SMOOTH_FROM_ZERO: fsdem__mg_smooth_row(L, dim, b, x, stage[s].colour, j, k, 1); break;
                case FSDEM__STAGE_RESTRICT: fsdem__mg_restrict_row(L, C, dim, b, x, xc_or_bc, j, k, buf); break;
                default: fsdem__mg_prolong_row(L, C, dim, xc_or_bc, x, j, k, buf); break;
                }
        }
}

/* Pre-smoothing from x = 0 (red first), then (when C is given) bc = P^T (b - A x). */
static void fsdem__mg_down(const fsdem__level *L, const fsdem__level *C, int dim, const fsdem_real *b, fsdem_real *x,
                           fsdem_real *bc, int sweeps, fsdem_real *buf) {
    fsdem__mg_stage stage[2 * 64 + 2];
    int n = 0, s;
    for (s = 0; s < 2 * sweeps; ++s) {
        stage[n].kind = s == 0 ? FSDEM__STAGE_SMOOTH_FROM_ZERO : FSDEM__STAGE_SMOOTH;
        stage[n++].colour = s & 1;
    }
    if (C) {
        stage[n].kind = FSDEM__STAGE_RESTRICT;
        stage[n++].colour = 0;
        memset(bc, 0, sizeof(fsdem_real) * (size_t)C->count);
    }
    fsdem__mg_pipeline(L, C, dim, b, x, bc, stage, n, buf);
    if (C) fsdem__mg_clean(C, bc);
}

/* (When C is given) x += P xc, then post-smoothing (black first: the adjoint of the pre-smoother). */
static void fsdem__mg_up(const fsdem__level *L, const fsdem__level *C, int dim, const fsdem_real *b, fsdem_real *x,
                         fsdem_real *xc, int sweeps, fsdem_real *buf) {
    fsdem__mg_stage stage[2 * 64 + 2];
    int n = 0, s;
    if (C) {
        stage[n].kind = FSDEM__STAGE_PROLONG;
        stage[n++].colour = 0;
    }
    for (s = 0; s < 2 * sweeps; ++s) {
        stage[n].kind = FSDEM__STAGE_SMOOTH;
        stage[n++].colour = (s & 1) ^ 1;
    }
    fsdem__mg_pipeline(L, C, dim, b, x, xc, stage, n, buf);
}

/* z = M^-1 r: one V-cycle from a zero guess. */
static void fsdem__mg_vcycle(fsdem_pcg *s, const fsdem_real *r, fsdem_real *z) {
    int l, dim = s->dim, nu = s->desc.mg_sweeps, last = s->levels - 1;
    fsdem__level *lv = s->level;
    lv[0].b = (fsdem_real *)r; /* read only at level 0 */
    lv[0].x = z;
    for (l = 0; l < last; ++l) fsdem__mg_down(&lv[l], &lv[l + 1], dim, lv[l].b, lv[l].x, lv[l + 1].b, nu, s->rowbuf);
    if (lv[last].n[0] * lv[last].n[1] * lv[last].n[2] == 1) {
        int c = fsdem__level_index(&lv[last], dim, 0, 0, 0);
        lv[last].x[c] = lv[last].inv_d[c] * lv[last].b[c];
    } else {
        fsdem__mg_down(&lv[last], NULL, dim, lv[last].b, lv[last].x, NULL, nu, s->rowbuf);
        fsdem__mg_up(&lv[last], NULL, dim, lv[last].b, lv[last].x, NULL, nu, s->rowbuf);
    }
    for (l = last - 1; l >= 0; --l) fsdem__mg_up(&lv[l], &lv[l + 1], dim, lv[l].b, lv[l].x, lv[l + 1].x, nu, s->rowbuf);
    lv[0].b = lv[0].x = NULL;
}

/* ---- >>linalg_ic : incomplete Cholesky on stencils and CSR matrices ---- */

/* Stencil IC(0)/MIC(0): M = L L^T with L = (pivots) on the diagonal and the matrix off-diagonals
   below it, so only q = 1/sqrt(pivot) is stored. MIC moves tau times the fill that IC(0) drops
   (between the two upper neighbours of a lower neighbour) to the diagonal. */
static void fsdem__stencil_ic_build(fsdem_pcg *s, fsdem_real tau) {
    const fsdem__level *L = &s->level[0];
    int dim = s->dim, i, j, k, a, b;
    int st[3];
    fsdem_real safety = s->desc.ic_safety, *q = s->ic;
    st[0] = 1;
    st[1] = L->sy;
    st[2] = L->sz;
    memset(q, 0, sizeof(fsdem_real) * (size_t)L->count);
    for (k = 0; k < L->n[2]; ++k)
        for (j = 0; j < L->n[1]; ++j)
            for (i = 0; i < L->n[0]; ++i) {
                int c = fsdem__level_index(L, dim, i, j, k);
                fsdem_real e;
                if (FSDEM__TYPE(L->type[c]) != FSDEM_STENCIL_CELL_FLUID || !(L->d[c] > 0)) continue;
                e = L->d[c];
                for (a = 0; a < dim; ++a) {
                    int lo = c - st[a];
                    fsdem_real t = L->w[a][c] * q[lo];
                    e -= t * t;
                    if (tau > 0 && t != 0)
                        for (b = 0; b < dim; ++b)
                            if (b != a) e -= tau * L->w[a][c] * L->w[b][lo + st[b]] * q[lo] * q[lo];
                }
                if (!(e >= safety * L->d[c])) e = L->d[c];
                q[c] = 1 / (fsdem_real)sqrt(e);
            }
}

static void fsdem__stencil_ic_apply(const fsdem_pcg *s, const fsdem_real *r, fsdem_real *z) {
    const fsdem__level *L = &s->level[0];
    const fsdem_real *q = s->ic, *w0 = L->w[0], *w1 = L->w[1], *w2 = L->w[2];
    int i, j, k, sy = L->sy, sz = L->sz, dim = s->dim;
    /* forward: L y = r */
    for (k = 0; k < L->n[2]; ++k)
        for (j = 0; j < L->n[1]; ++j) {
            int c0 = fsdem__level_index(L, dim, 0, j, k);
            for (i = 0; i < L->n[0]; ++i) {
                int c = c0 + i;
                fsdem_real t = r[c] + w0[c] * q[c - 1] * z[c - 1] + w1[c] * q[c - sy] * z[c - sy];
                if (dim == 3) t += w2[c] * q[c - sz] * z[c - sz];
                z[c] = t * q[c];
            }
        }
    /* backward: L^T z = y */
    for (k = L->n[2] - 1; k >= 0; --k)
        for (j = L->n[1] - 1; j >= 0; --j) {
            int c0 = fsdem__level_index(L, dim, 0, j, k);
            for (i = L->n[0] - 1; i >= 0; --i) {
                int c = c0 + i;
                fsdem_real t = w0[c + 1] * z[c + 1] + w1[c + sy] * z[c + sy];
                if (dim == 3) t += w2[c + sz] * z[c + sz];
                z[c] = q[c] * (z[c] + q[c] * t);
            }
        }
}

/* CSR IC(0)/MIC(0), right-looking on the upper factor U (row k of U is column k of L). */
static void fsdem__csr_ic_build(fsdem_pcg *s, fsdem_real tau) {
    const fsdem_csr *m = &s->csr;
    int n = m->rows, i, k, e, f, cnt = 0;
    fsdem_real safety = s->desc.ic_safety;
    fsdem_real *diag0 = s->ic; /* the matrix diagonal, kept for the pivot floor */
    for (i = 0; i < n; ++i) {
        s->u_start[i] = cnt;
        for (e = m->row_start[i]; e < m->row_start[i + 1]; ++e)
            if (m->col[e] >= i) {
                if (m->col[e] == i) diag0[i] = m->val[e];
                s->u_col[cnt] = m->col[e];
                s->u_val[cnt++] = m->val[e];
            }
        s->u_pos[i] = -1;
    }
    s->u_start[n] = cnt;
    for (k = 0; k < n; ++k) {
        int kb = s->u_start[k], ke = s->u_start[k + 1];
        fsdem_real piv = s->u_val[kb], dk;
        if (!(piv >= safety * diag0[k])) piv = diag0[k];
        dk = (fsdem_real)sqrt(piv);
        s->u_val[kb] = dk;
        for (e = kb + 1; e < ke; ++e) s->u_val[e] /= dk;
        for (e = kb + 1; e < ke; ++e) {
            int row = s->u_col[e], rb = s->u_start[row], re = s->u_start[row + 1];
            fsdem_real li = s->u_val[e];
            for (f = rb; f < re; ++f) s->u_pos[s->u_col[f]] = f;
            s->u_val[rb] -= li * li;
            for (f = e + 1; f < ke; ++f) {
                int col = s->u_col[f];
                fsdem_real fill = li * s->u_val[f];
                if (s->u_pos[col] >= 0) s->u_val[s->u_pos[col]] -= fill;
                else if (tau > 0) {
                    s->u_val[rb] -= tau * fill;
                    s->u_val[s->u_start[col]] -= tau * fill;
                }
            }
            for (f = rb; f < re; ++f) s->u_pos[s->u_col[f]] = -1;
        }
    }
}

static void fsdem__csr_ic_apply(const fsdem_pcg *s, const fsdem_real *r, fsdem_real *z) {
    int n = s->csr.rows, k, e;
    if (z != r) memcpy(z, r, sizeof(fsdem_real) * (size_t)n);
    for (k = 0; k < n; ++k) { /* U^T y = r */
        int kb = s->u_start[k], ke = s->u_start[k + 1];
        fsdem_real y = z[k] / s->u_val[kb];
        z[k] = y;
        for (e = kb + 1; e < ke; ++e) z[s->u_col[e]] -= s->u_val[e] * y;
    }
    for (k = n - 1; k >= 0; --k) { /* U z = y */
        int kb = s->u_start[k], ke = s->u_start[k + 1];
        fsdem_real t = z[k];
        for (e = kb + 1; e < ke; ++e) t -= s->u_val[e] * z[s->u_col[e]];
        z[k] = t / s->u_val[kb];
    }
}

/* ---- >>linalg_setup : setup for stencils and CSR matrices ---- */

/* Carves the stencil workspace; `levels` = number of multigrid levels to hold (1 without MG). */
static void fsdem__stencil_carve(fsdem_pcg *s, fsdem__pcg_carver *cv, int levels, int want_ic, int cells,
                                 int with_extra) {
    int l, a, N = s->level[0].count;
    fsdem_real **vec[4];
    vec[0] = &s->x;
    vec[1] = &s->r;
    vec[2] = &s->z;
    vec[3] = &s->p;
    for (a = 0; a < 4; ++a) *vec[a] = (fsdem_real *)fsdem__pcg_carve(cv, (size_t)N, sizeof(fsdem_real));
    s->ux = s->uy = NULL;
    if (with_extra) {
        s->ux = (fsdem_real *)fsdem__pcg_carve(cv, (size_t)cells, sizeof(fsdem_real));
        s->uy = (fsdem_real *)fsdem__pcg_carve(cv, (size_t)cells, sizeof(fsdem_real));
    }
    s->ic = want_ic ? (fsdem_real *)fsdem__pcg_carve(cv, (size_t)N, sizeof(fsdem_real)) : NULL;
    s->rowbuf = levels > 1 ? (fsdem_real *)fsdem__pcg_carve(cv, 2 * ((size_t)s->level[0].n[0] + 8), sizeof(fsdem_real)) : NULL;
    s->mark = (unsigned char *)fsdem__pcg_carve(cv, (size_t)N, 1);
    s->ns_cell = (int *)fsdem__pcg_carve(cv, (size_t)N, sizeof(int));
    for (l = 0; l < levels; ++l) {
        fsdem__level *L = &s->level[l];
        size_t n = (size_t)L->count;
        L->type = (unsigned char *)fsdem__pcg_carve(cv, n, 1);
        L->d = (fsdem_real *)fsdem__pcg_carve(cv, n, sizeof(fsdem_real));
        L->inv_d = (fsdem_real *)fsdem__pcg_carve(cv, n, sizeof(fsdem_real));
        for (a = 0; a < 3; ++a)
            L->w[a] = a < s->dim ? (fsdem_real *)fsdem__pcg_carve(cv, n, sizeof(fsdem_real)) : NULL;
        if (s->dim == 2) L->w[2] = L->w[1]; /* never read in 2D; keeps the kernels' pointers valid */
        L->x = L->b = NULL;
        if (l > 0) {
            L->x = (fsdem_real *)fsdem__pcg_carve(cv, n, sizeof(fsdem_real));
            L->b = (fsdem_real *)fsdem__pcg_carve(cv, n, sizeof(fsdem_real));
        }
    }
}

/* Finds the fluid regions that no Dirichlet condition reaches (their matrix is singular: the
   constant is in its null space). A fluid cell is an anchor when its extra diagonal is positive
   or a face towards an air cell or a Dirichlet boundary has a positive coefficient, i.e. when
   d exceeds the sum of its fluid couplings; the test is made on the coefficients, not on d. */
static void fsdem__stencil_nullspace(fsdem_pcg *s, const fsdem_real *extra) {
    const fsdem__level *L = &s->level[0];
    int dim = s->dim, c, a, head, tail, st[3];
    unsigned char *mark = s->mark;
    int *queue = s->ns_cell;
    st[0] = 1;
    st[1] = L->sy;
    st[2] = L->sz;
    memset(mark, 0, (size_t)L->count);
    tail = 0;
    for (c = 0; c < L->count; ++c) {
        int anchor = 0;
        if (L->type[c] != FSDEM_STENCIL_CELL_FLUID) continue;
        if (extra[c] > 0) anchor = 1;
        for (a = 0; a < dim && !anchor; ++a) {
            /* physical coefficients are still in w here */
            if (L->w[a][c] > 0 && FSDEM__TYPE(L->type[c - st[a]]) == FSDEM_STENCIL_CELL_AIR) anchor = 1;
            if (L->w[a][c + st[a]] > 0 && FSDEM__TYPE(L->type[c + st[a]]) == FSDEM_STENCIL_CELL_AIR) anchor = 1;
        }
        if (anchor) {
            mark[c] = 1;
            queue[tail++] = c;
        }
    }
    for (head = 0; head < tail; ++head) {
        int u = queue[head];
        for (a = 0; a < dim; ++a) {
            int lo = u - st[a], hi = u + st[a];
            if (!mark[lo] && L->w[a][u] > 0 && L->type[lo] == FSDEM_STENCIL_CELL_FLUID) {
                mark[lo] = 1;
                queue[tail++] = lo;
            }
            if (!mark[hi] && L->w[a][hi] > 0 && L->type[hi] == FSDEM_STENCIL_CELL_FLUID) {
                mark[hi] = 1;
                queue[tail++] = hi;
            }
        }
    }
    /* the rest: flood each unanchored region, recording its cells */
    s->ns_components = 0;
    s->ns_cells = 0;
    for (c = 0; c < L->count; ++c) {
        if (mark[c] || L->type[c] != FSDEM_STENCIL_CELL_FLUID) continue;
        head = s->ns_cells;
        tail = head;
        mark[c] = 1;
        queue[tail++] = c;
        for (; head < tail; ++head) {
            int u = queue[head];
            for (a = 0; a < dim; ++a) {
                int lo = u - st[a], hi = u + st[a];
                if (!mark[lo] && L->w[a][u] > 0 && L->type[lo] == FSDEM_STENCIL_CELL_FLUID) {
                    mark[lo] = 1;
                    queue[tail++] = lo;
                }
                if (!mark[hi] && L->w[a][hi] > 0 && L->type[hi] == FSDEM_STENCIL_CELL_FLUID) {
                    mark[hi] = 1;
                    queue[tail++] = hi;
                }
            }
        }
        queue[s->ns_cells] = -(queue[s->ns_cells] + 1);
        s->ns_cells = tail;
        s->ns_components++;
    }
}

fsdem_result fsdem_pcg_setup_stencil(fsdem_pcg *s, const fsdem_stencil *st) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem__level plan[FSDEM__MG_MAX_LEVELS];
    fsdem__pcg_carver cv;
    fsdem_precond pc;
    fsdem_result res;
    int n[3], levels, l, cells;
    fsdem_real *extra, *cextra;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (st && (st->dim == 2 || st->dim == 3) && st->n[0] > 0 && st->n[1] > 0 && (st->dim == 2 || st->n[2] > 0) &&
        fsdem__stencil_padded(st) > FSDEM__MAX_PADDED)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY,
                           "fsdem_pcg_setup_stencil: a grid of %d x %d x %d cells does not fit (index overflow)",
                           st->n[0], st->n[1], st->dim == 3 ? st->n[2] : 1);
    if (fsdem_stencil_check(st, msg, sizeof msg) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s", msg);
    pc = s->desc.preconditioner == FSDEM_PRECOND_AUTO ? FSDEM_PRECOND_MG : s->desc.preconditioner;
    fsdem__stencil_dims(st, n);
    cells = n[0] * n[1] * n[2];
    memset(plan, 0, sizeof plan);
    levels = pc == FSDEM_PRECOND_MG ? fsdem__mg_plan(plan, st->dim, n) : 1;
    if (levels == 1) {
        fsdem__level_geometry(&plan[0], st->dim, n);
        plan[0].ratio[0] = plan[0].ratio[1] = plan[0].ratio[2] = 1;
        plan[0].h[0] = plan[0].h[1] = plan[0].h[2] = 1;
    }
    /* measure on a copy (so a failure leaves the previous setup intact), reserve, carve */
    {
        fsdem_pcg probe = *s;
        memcpy(probe.level, plan, sizeof plan);
        probe.dim = st->dim;
        cv.base = NULL;
        cv.used = 0;
        cv.overflow = 0;
        fsdem__stencil_carve(&probe, &cv, levels, pc == FSDEM_PRECOND_IC0 || pc == FSDEM_PRECOND_MIC0, cells,
                             st->extra != NULL);
    }
    if (cv.overflow)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pcg_setup_stencil: workspace size overflows");
    res = fsdem__pcg_reserve(s, cv.used);
    if (res != FSDEM_OK)
        return fsdem__fail(&s->status, res, "fsdem_pcg_setup_stencil: cannot allocate %.0f bytes", (double)cv.used);
    s->kind = FSDEM__KIND_NONE;
    memcpy(s->level, plan, sizeof plan);
    s->dim = st->dim;
    cv.base = (char *)s->arena;
    cv.used = 0;
    fsdem__stencil_carve(s, &cv, levels, pc == FSDEM_PRECOND_IC0 || pc == FSDEM_PRECOND_MIC0, cells, st->extra != NULL);
    /* every array is written in full below; the CG vectors' ghosts must be 0 */
    memset(s->x, 0, sizeof(fsdem_real) * (size_t)s->level[0].count);
    memset(s->r, 0, sizeof(fsdem_real) * (size_t)s->level[0].count);

    /* level 0; the extra diagonals live in the z and p vectors while the levels are built */
    extra = s->z;
    cextra = s->p;
    fsdem__level_from_stencil(&s->level[0], st, extra);
    fsdem__level_diagonal(&s->level[0], st->dim, extra);
    fsdem__stencil_nullspace(s, extra);
    s->levels = 1;
    if (pc == FSDEM_PRECOND_MG) {
        for (l = 1; l < levels && s->level[l - 1].fluid > 0; ++l) {
            fsdem__level *F = &s->level[l - 1], *C = &s->level[l];
            fsdem__level_coarsen(F, C, st->dim, extra, cextra);
            fsdem__level_diagonal(C, st->dim, cextra);
            if (C->fluid == 0) break;
            fsdem__level_mark_near_solid(F, C, st->dim);
            fsdem__level_offdiagonal(F, st->dim);
            memcpy(extra, cextra, sizeof(fsdem_real) * (size_t)C->count);
            s->levels = l + 1;
        }
    }
    fsdem__level_offdiagonal(&s->level[s->levels - 1], st->dim);
    for (l = 1; l < s->levels; ++l) /* ghosts stay 0; the V-cycle writes interior cells only */
        memset(s->level[l].x, 0, sizeof(fsdem_real) * (size_t)s->level[l].count);
    memset(s->z, 0, sizeof(fsdem_real) * (size_t)s->level[0].count);
    memset(s->p, 0, sizeof(fsdem_real) * (size_t)s->level[0].count);
    if (pc == FSDEM_PRECOND_IC0 || pc == FSDEM_PRECOND_MIC0)
        fsdem__stencil_ic_build(s, pc == FSDEM_PRECOND_MIC0 ? s->desc.mic_tau : 0);

    s->stencil = *st;
    s->precond = pc;
    s->length = s->level[0].count;
    s->user_length = cells;
    s->kind = FSDEM__KIND_STENCIL;
    return fsdem__ok(&s->status);
}

static void fsdem__csr_carve(fsdem_pcg *s, fsdem__pcg_carver *cv, int n, int upper, fsdem_precond pc) {
    fsdem_real **vec[4];
    int a;
    vec[0] = &s->x;
    vec[1] = &s->r;
    vec[2] = &s->z;
    vec[3] = &s->p;
    for (a = 0; a < 4; ++a) *vec[a] = (fsdem_real *)fsdem__pcg_carve(cv, (size_t)n, sizeof(fsdem_real));
    s->ux = s->uy = NULL;
    s->ic = pc != FSDEM_PRECOND_NONE ? (fsdem_real *)fsdem__pcg_carve(cv, (size_t)n, sizeof(fsdem_real)) : NULL;
    s->u_start = s->u_col = s->u_pos = NULL;
    s->u_val = NULL;
    if (pc == FSDEM_PRECOND_IC0 || pc == FSDEM_PRECOND_MIC0) {
        s->u_start = (int *)fsdem__pcg_carve(cv, (size_t)n + 1, sizeof(int));
        s->u_pos = (int *)fsdem__pcg_carve(cv, (size_t)n, sizeof(int));
        s->u_col = (int *)fsdem__pcg_carve(cv, (size_t)upper, sizeof(int));
        s->u_val = (fsdem_real *)fsdem__pcg_carve(cv, (size_t)upper, sizeof(fsdem_real));
    }
}

/* fsdem_pcg_setup_csr for a matrix valid by construction (a solver's own assembly, whose tests
   check it with fsdem_csr_check): the check took about 5 % of an MPS step (perf). */
static fsdem_result fsdem__pcg_setup_csr_valid(fsdem_pcg *s, const fsdem_csr *m) {
    fsdem__pcg_carver cv;
    fsdem_precond pc;
    fsdem_result res;
    int i, e, upper = 0;
    pc = s->desc.preconditioner == FSDEM_PRECOND_AUTO ? FSDEM_PRECOND_MIC0 : s->desc.preconditioner;
    if (pc == FSDEM_PRECOND_MG)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pcg_setup_csr: FSDEM_PRECOND_MG needs a stencil operator (fsdem_pcg_setup_stencil); use "
                           "FSDEM_PRECOND_MIC0 for a CSR matrix");
    for (i = 0; i < m->rows; ++i)
        for (e = m->row_start[i]; e < m->row_start[i + 1]; ++e)
            if (m->col[e] >= i) upper++;
    {
        fsdem_pcg probe = *s;
        cv.base = NULL;
        cv.used = 0;
        cv.overflow = 0;
        fsdem__csr_carve(&probe, &cv, m->rows, upper, pc);
    }
    if (cv.overflow)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pcg_setup_csr: workspace size overflows");
    res = fsdem__pcg_reserve(s, cv.used);
    if (res != FSDEM_OK)
        return fsdem__fail(&s->status, res, "fsdem_pcg_setup_csr: cannot allocate %.0f bytes", (double)cv.used);
    s->kind = FSDEM__KIND_NONE;
    cv.base = (char *)s->arena;
    cv.used = 0;
    fsdem__csr_carve(s, &cv, m->rows, upper, pc);
    memset(s->arena, 0, cv.used);
    s->csr = *m;
    s->dim = 0;
    s->levels = 1;
    s->ns_components = s->ns_cells = 0;
    if (pc == FSDEM_PRECOND_JACOBI)
        for (i = 0; i < m->rows; ++i) s->ic[i] = 1 / m->val[fsdem__csr_find(m, i, i)];
    if (pc == FSDEM_PRECOND_IC0 || pc == FSDEM_PRECOND_MIC0)
        fsdem__csr_ic_build(s, pc == FSDEM_PRECOND_MIC0 ? s->desc.mic_tau : 0);
    s->precond = pc;
    s->length = s->user_length = m->rows;
    s->kind = FSDEM__KIND_CSR;
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_pcg_setup_csr(fsdem_pcg *s, const fsdem_csr *m) {
    char msg[FSDEM__MESSAGE_SIZE];
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (fsdem_csr_check(m, msg, sizeof msg) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s", msg);
    return fsdem__pcg_setup_csr_valid(s, m);
}

/* ---- >>linalg_solve : preconditioned conjugate gradients ---- */

/* y = A x on internal vectors. */
static void fsdem__pcg_apply(fsdem_pcg *s, const fsdem_real *x, fsdem_real *y) {
    if (s->kind == FSDEM__KIND_CSR) {
        fsdem_csr_apply(&s->csr, x, y);
        return;
    }
    fsdem__level_apply(&s->level[0], s->dim, x, y);
    if (s->stencil.extra) {
        const fsdem__level *L = &s->level[0];
        int i, j, k, u = 0;
        for (k = 0; k < L->n[2]; ++k)
            for (j = 0; j < L->n[1]; ++j)
                for (i = 0; i < L->n[0]; ++i, ++u) {
                    s->ux[u] = x[fsdem__level_index(L, s->dim, i, j, k)];
                    s->uy[u] = 0;
                }
        s->stencil.extra(s->stencil.extra_user, s->ux, s->uy);
        u = 0;
        for (k = 0; k < L->n[2]; ++k)
            for (j = 0; j < L->n[1]; ++j)
                for (i = 0; i < L->n[0]; ++i, ++u) {
                    int c = fsdem__level_index(L, s->dim, i, j, k);
                    if (FSDEM__TYPE(L->type[c]) == FSDEM_STENCIL_CELL_FLUID)
                        y[c] += s->uy[u];
                }
    }
}

/* z = M^-1 r. */
static void fsdem__pcg_precondition(fsdem_pcg *s, const fsdem_real *r, fsdem_real *z) {
    int i, n = s->length;
    switch (s->precond) {
    case FSDEM_PRECOND_JACOBI: {
        const fsdem_real *inv = s->kind == FSDEM__KIND_CSR ? s->ic : s->level[0].inv_d;
        for (i = 0; i < n; ++i) z[i] = inv[i] * r[i];
        break;
    }
    case FSDEM_PRECOND_IC0:
    case FSDEM_PRECOND_MIC0:
        if (s->kind == FSDEM__KIND_CSR) fsdem__csr_ic_apply(s, r, z);
        else fsdem__stencil_ic_apply(s, r, z);
        break;
    case FSDEM_PRECOND_MG: fsdem__mg_vcycle(s, r, z); break;
    default: memcpy(z, r, sizeof(fsdem_real) * (size_t)n); break;
    }
}

/* Removes the mean of v over each unanchored fluid region; returns the squared norm removed. */
static double fsdem__pcg_project(const fsdem_pcg *s, fsdem_real *v) {
    int e = 0, removed_start;
    double removed = 0;
    while (e < s->ns_cells) {
        double sum = 0;
        int count = 0, f;
        removed_start = e;
        do {
            int c = s->ns_cell[e];
            if (c < 0) c = -c - 1;
            sum += v[c];
            count++;
            e++;
        } while (e < s->ns_cells && s->ns_cell[e] >= 0);
        sum /= count;
        for (f = removed_start; f < e; ++f) {
            int c = s->ns_cell[f];
            if (c < 0) c = -c - 1;
            v[c] -= (fsdem_real)sum;
        }
        removed += sum * sum * count;
    }
    return removed;
}

/* Copies a caller vector into an internal one (0 off fluid cells). Returns the index of the first
   non-finite value read, or -1. */
static int fsdem__pcg_load(const fsdem_pcg *s, const fsdem_real *src, fsdem_real *dst) {
    int i, j, k, u = 0, bad = -1;
    if (s->kind == FSDEM__KIND_CSR) {
        for (i = 0; i < s->length; ++i) {
            dst[i] = src[i];
            if (bad < 0 && !fsdem__finite(src[i])) bad = i;
        }
        return bad;
    }
    {
        const fsdem__level *L = &s->level[0];
        for (k = 0; k < L->n[2]; ++k)
            for (j = 0; j < L->n[1]; ++j)
                for (i = 0; i < L->n[0]; ++i, ++u) {
                    int c = fsdem__level_index(L, s->dim, i, j, k);
                    if (FSDEM__TYPE(L->type[c]) == FSDEM_STENCIL_CELL_FLUID) {
                        dst[c] = src[u];
                        if (bad < 0 && !fsdem__finite(src[u])) bad = u;
                    } else {
                        dst[c] = 0;
                    }
                }
    }
    return bad;
}

static void fsdem__pcg_store(const fsdem_pcg *s, const fsdem_real *src, fsdem_real *dst) {
    int i, j, k, u = 0;
    if (s->kind == FSDEM__KIND_CSR) {
        memcpy(dst, src, sizeof(fsdem_real) * (size_t)s->length);
        return;
    }
    {
        const fsdem__level *L = &s->level[0];
        for (k = 0; k < L->n[2]; ++k)
            for (j = 0; j < L->n[1]; ++j)
                for (i = 0; i < L->n[0]; ++i, ++u) dst[u] = src[fsdem__level_index(L, s->dim, i, j, k)];
    }
}

static double fsdem__pcg_vdot(const fsdem_real *a, const fsdem_real *b, int n) {
    double s0 = 0, s1 = 0;
    int i;
    for (i = 0; i + 1 < n; i += 2) {
        s0 += (double)a[i] * b[i];
        s1 += (double)a[i + 1] * b[i + 1];
    }
    if (i < n) s0 += (double)a[i] * b[i];
    return s0 + s1;
}

static int fsdem__pcg_finite_d(double v) { return v == v && v - v == 0; }

/* True residual b - A x into `out` (uses z as scratch); returns its squared norm. */
static double fsdem__pcg_true_residual(fsdem_pcg *s, const fsdem_real *b, fsdem_real *out) {
    int i;
    fsdem__pcg_load(s, b, out);
    fsdem__pcg_project(s, out);
    fsdem__pcg_apply(s, s->x, s->z);
    for (i = 0; i < s->length; ++i) out[i] -= s->z[i];
    return fsdem__pcg_vdot(out, out, s->length);
}

/* r.z must be positive and finite for a symmetric positive definite preconditioner and operator. */
static fsdem_result fsdem__pcg_check_rz(fsdem_pcg *s, double rz, int it) {
    if (!fsdem__pcg_finite_d(rz))
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pcg_solve: r.z is NaN/Inf at iteration %d", it);
    if (rz <= 0)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pcg_solve: r.z = %g <= 0 at iteration %d: the preconditioner is not positive "
                           "definite (is the operator?)", rz, it);
    return FSDEM_OK;
}

fsdem_result fsdem_pcg_solve(fsdem_pcg *s, const fsdem_real *b, fsdem_real *x, fsdem_pcg_info *info) {
    fsdem_pcg_info inf;
    double bb, rr, rz = 0, tol2, removed;
    int n, i, it = 0, bad, restart = 1, r_is_true = 1;
    fsdem_result res = FSDEM_OK;
    memset(&inf, 0, sizeof inf);
    inf.levels = 1;
    if (info) *info = inf;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (s->kind == FSDEM__KIND_NONE)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pcg_solve: no operator; call fsdem_pcg_setup_stencil or fsdem_pcg_setup_csr first");
    if (!b || !x) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pcg_solve: b and x must not be NULL");
    n = s->length;
    inf.levels = s->levels;
    inf.memory_bytes = s->arena_bytes + sizeof *s;
    inf.nullspace_components = s->ns_components;
    bad = fsdem__pcg_load(s, b, s->r);
    if (bad >= 0) {
        if (info) *info = inf;
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pcg_solve: b[%d] = %g is not finite", bad, (double)b[bad]);
    }
    bad = fsdem__pcg_load(s, x, s->x);
    if (bad >= 0) {
        if (info) *info = inf;
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pcg_solve: initial guess x[%d] = %g is not finite", bad,
                           (double)x[bad]);
    }
    bb = fsdem__pcg_vdot(s->r, s->r, n);
    removed = fsdem__pcg_project(s, s->r);
    inf.incompatibility = bb > 0 ? (fsdem_real)sqrt(removed / bb) : 0;
    bb = fsdem__pcg_vdot(s->r, s->r, n);
    if (!fsdem__pcg_finite_d(bb)) {
        if (info) *info = inf;
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pcg_solve: ||b|| overflows");
    }
    inf.rhs_norm = (fsdem_real)sqrt(bb);
    if (bb == 0) { /* the solution is 0 */
        memset(s->x, 0, sizeof(fsdem_real) * (size_t)n);
        fsdem__pcg_store(s, s->x, x);
        if (info) *info = inf;
        return fsdem__ok(&s->status);
    }
    tol2 = (double)s->desc.tolerance * s->desc.tolerance * bb;
    /* r = b - A x */
    fsdem__pcg_project(s, s->x);
    fsdem__pcg_apply(s, s->x, s->z);
    for (i = 0; i < n; ++i) s->r[i] -= s->z[i];
    rr = fsdem__pcg_vdot(s->r, s->r, n);
    for (;;) {
        double pq, alpha, rz_new, beta;
        if (!fsdem__pcg_finite_d(rr)) {
            res = fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pcg_solve: the residual became NaN/Inf at iteration %d", it);
            break;
        }
        if (rr <= tol2) {
            if (r_is_true) break;
            rr = fsdem__pcg_true_residual(s, b, s->r); /* guard against a drifted recurrence */
            r_is_true = 1;
            if (rr <= tol2) break;
            restart = 1;
        }
        if (it >= s->desc.max_iterations) {
            if (!r_is_true) {
                rr = fsdem__pcg_true_residual(s, b, s->r);
                r_is_true = 1;
            }
            res = fsdem__fail(&s->status, FSDEM_ERR_NOT_CONVERGED,
                              "fsdem_pcg_solve: not converged in %d iterations (relative residual %g, tolerance %g)", it,
                              sqrt(rr / bb), (double)s->desc.tolerance);
            break;
        }
        if (restart) {
            fsdem__pcg_precondition(s, s->r, s->z);
            fsdem__pcg_project(s, s->z);
            rz = fsdem__pcg_vdot(s->r, s->z, n);
            res = fsdem__pcg_check_rz(s, rz, it);
            if (res != FSDEM_OK) break;
            memcpy(s->p, s->z, sizeof(fsdem_real) * (size_t)n);
            restart = 0;
        }
        fsdem__pcg_apply(s, s->p, s->z); /* z is free until the next preconditioning */
        pq = fsdem__pcg_vdot(s->p, s->z, n);
        if (!fsdem__pcg_finite_d(pq)) {
            res = fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pcg_solve: p.Ap is NaN/Inf at iteration %d", it);
            break;
        }
        if (pq <= 0) {
            res = fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                              "fsdem_pcg_solve: non-positive curvature p.Ap = %g at iteration %d: the operator is not "
                              "positive definite", pq, it);
            break;
        }
        alpha = rz / pq;
        {
            double acc0 = 0;
            fsdem_real al = (fsdem_real)alpha;
            fsdem_real *xv = s->x, *rv = s->r;
            const fsdem_real *pv = s->p, *qv = s->z;
            for (i = 0; i < n; ++i) {
                xv[i] += al * pv[i];
                rv[i] -= al * qv[i];
                acc0 += (double)rv[i] * rv[i];
            }
            rr = acc0;
        }
        ++it;
        r_is_true = 0;
        if (!fsdem__pcg_finite_d(rr) || rr <= tol2) continue;
        fsdem__pcg_precondition(s, s->r, s->z);
        fsdem__pcg_project(s, s->z);
        rz_new = fsdem__pcg_vdot(s->r, s->z, n);
        res = fsdem__pcg_check_rz(s, rz_new, it);
        if (res != FSDEM_OK) break;
        beta = rz_new / rz;
        rz = rz_new;
        {
            fsdem_real be = (fsdem_real)beta;
            fsdem_real *pv = s->p;
            const fsdem_real *zv = s->z;
            for (i = 0; i < n; ++i) pv[i] = zv[i] + be * pv[i];
        }
    }
    inf.iterations = it;
    if (res == FSDEM_ERR_NAN) { /* x is left as it was */
        inf.residual = (fsdem_real)(fsdem__pcg_finite_d(rr) ? sqrt(rr / bb) : rr);
        if (info) *info = inf;
        return res;
    }
    if (!r_is_true) rr = fsdem__pcg_true_residual(s, b, s->r);
    inf.residual = (fsdem_real)sqrt(rr / bb);
    fsdem__pcg_project(s, s->x);
    fsdem__pcg_store(s, s->x, x);
    if (info) *info = inf;
    return res == FSDEM_OK ? fsdem__ok(&s->status) : res;
}

/* ===== >>impl_pic : PIC/FLIP solver ===== */

/* Contents: >>pic_types (the object), >>pic_desc (defaults, validation, creation), >>pic_geometry
   (obstacles, cut-cell face fractions), >>pic_particles (storage, seeding), >>pic_transfer (P2G,
   G2P), >>pic_cells (effective faces, fluid fraction, level set, cell types), >>pic_extrapolate,
   >>pic_viscosity, >>pic_projection (pressure and density projection), >>pic_advection,
   >>pic_reseed, >>pic_step (time stepping), >>pic_views (fields, coupling, sampling, statistics),
   >>pic_output. */

#include <time.h>

/* ---- >>pic_types : the solver object ---- */

typedef struct fsdem__pic_obst {
    fsdem_pic_obstacle d;
    fsdem_vec3 *verts; /* POLYGON: owned copy */
    fsdem_vec3 box_lo, box_hi; /* bounding box (m), inflated by two cells */
} fsdem__pic_obst;

struct fsdem_pic {
    fsdem_pic_desc desc;
    fsdem__status status;
    fsdem_allocator allocator;
    int dim, n[3], ncell;
    int fn[3][3];      /* face grid sizes: fn[a][b] = n[b] + (a == b) */
    int nface[3];      /* faces per axis (0 above dim) */
    int cstep[3];      /* cell index stride per axis */
    int fstep[3][3];   /* face index stride of axis-a faces along b */
    fsdem_real dx, inv_dx;
    fsdem_vec3 lo, hi; /* grid box */
    fsdem_real surface_tol; /* m; solid distances within this count as on the surface (>>pic_geometry) */
    double time;
    fsdem_real dt_last;
    long long steps;
    unsigned long long rng;
    int ppc, sub;      /* particles per cell; seeds per axis when ppc = sub^dim, else 0 */
    fsdem_real pvol;   /* m^dim per particle */
    fsdem_real gmag;   /* |g| */

    /* particles, structure of arrays */
    int np, pcap;
    fsdem_vec3 *px, *pv, *ptmp;
    fsdem_vec3 *pc[3]; /* APIC: gradient of velocity component a (1/s); NULL otherwise */
    int *pcell, *pidx;
    unsigned char *pflag;

    /* faces, per axis */
    fsdem_real *u[3], *uold[3], *wsum[3], *ftmp[3];
    fsdem_real *sopen[3], *svel[3];           /* static obstacles: open fraction, solid velocity */
    fsdem_real *copen[3], *cvel[3], *cacc[3]; /* coupler arrays */
    fsdem_real *shear[3];                     /* viscous force on closed faces (viscosity > 0) */
    fsdem_real *cvisc[3];                     /* coupler: no-slip velocity of moving solids (viscosity > 0) */
    fsdem_real *E[3], *us[3];                 /* effective open fraction and solid velocity */
    unsigned char *fvalid[3], *fvalid2[3];
    int *fqueue; /* breadth-first front of the extrapolation, max(nface) entries */
    int fqueue_size;

    /* cells */
    fsdem_real *frac, *fref, *phi, *pres, *rhs, *diag, *ctmp, *crhs;
    fsdem_real *cref; /* coupler's factor on fref (moving solids) */
    unsigned char *ctype, *cnear, *csolid;
    int *cstart; /* ncell + 1 */

    /* implicit viscosity: per axis a the face grid is a stencil grid of its own */
    fsdem_real *vface[3][3]; /* coefficients 1 inside, 0 on the face grid's boundary */
    unsigned char *vcell[3];

    fsdem__pic_obst *obst;
    int obst_count, obst_capacity;

    fsdem_pcg *pcg_p;
    fsdem_pcg *pcg_v[3];
    fsdem_pic_coupling coupling;     /* the coupler's arrays (fsdem_pic_get_coupling) */
    fsdem_operator_fn pressure_extra; /* fsdem_pic_set_pressure_extra */
    void *pressure_extra_user;
    fsdem__gauges gauges;

    /* diagnostics */
    int cells_fresh; /* frac/phi hold the current particle positions (set at the end of a step) */
    int fluid_cells, p_iters, v_iters, d_iters;
    fsdem_real p_res, max_div, div_before, umax_part;
    long long reseeded, removed, refused, moved;
    double sec_total, sec_pressure, sec_density;
    size_t bytes;
};

/* ---- >>pic_desc : defaults, validation, creation ---- */

fsdem_pic_desc fsdem_pic_desc_default(int dim) {
    fsdem_pic_desc d;
    int k;
    memset(&d, 0, sizeof d);
    d.dim = dim;
    d.domain_min = fsdem_v3(0, 0, 0);
    d.domain_max = fsdem_v3(1, 1, 1);
    d.cell_size = (fsdem_real)(1.0 / 32.0);
    d.density = 1000;
    d.viscosity = 0;
    d.gravity = dim == 3 ? fsdem_v3(0, 0, (fsdem_real)-9.81) : fsdem_v3(0, (fsdem_real)-9.81, 0);
    for (k = 0; k < 6; ++k) {
        d.boundary[k] = FSDEM_PIC_BC_SLIP;
        d.boundary_velocity[k] = fsdem_v3(0, 0, 0);
    }
    d.free_surface = 1;
    d.transfer = FSDEM_PIC_TRANSFER_FLIP;
    d.flip_ratio = (fsdem_real)0.97;
    d.kernel = FSDEM_PIC_KERNEL_LINEAR;
    d.particles_per_cell = dim == 3 ? 8 : 4;
    d.jitter = (fsdem_real)0.5;
    d.seed = 1;
    d.min_particles_per_cell = d.particles_per_cell / 2;
    d.max_particles_per_cell = 3 * d.particles_per_cell;
    d.advection_order = 2;
    d.cfl = 1;
    d.cfl_max = 5;
    d.dt_max = (fsdem_real)0.01;
    d.density_projection = 1;
    d.ghost_theta_min = (fsdem_real)0.01;
    d.extrapolation_layers = 0;
    d.pressure_precond = FSDEM_PRECOND_AUTO;
#ifdef FSDEM_USE_FLOAT
    d.pressure_tolerance = (fsdem_real)1e-5;
    d.viscosity_tolerance = (fsdem_real)1e-5;
#else
    d.pressure_tolerance = (fsdem_real)1e-8;
    d.viscosity_tolerance = (fsdem_real)1e-8;
#endif
    d.pressure_max_iterations = 500;
    d.viscosity_precond = FSDEM_PRECOND_MIC0;
    d.max_memory = 0;
    return d;
}

static const char *fsdem__pic_side_name(int side) {
    static const char *names[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};
    return side >= 0 && side < 6 ? names[side] : "?";
}

/* Grid size of a desc: cells per axis as doubles (may be huge), and an estimate of the bytes the
   solver needs for it. */
static void fsdem__pic_grid_size(const fsdem_pic_desc *d, double cells[3], double *total,
                                 double *bytes) {
    int a;
    double faces = 0, per_cell, per_face;
    *total = 1;
    for (a = 0; a < 3; ++a) {
        cells[a] = 1;
        if (a < d->dim) {
            double e = (double)fsdem__comp(d->domain_max, a) - (double)fsdem__comp(d->domain_min, a);
            cells[a] = floor(e / (double)d->cell_size + 0.5);
            if (cells[a] < 1) cells[a] = 1;
        }
        *total *= cells[a];
    }
    for (a = 0; a < d->dim; ++a) faces += *total / cells[a] * (cells[a] + 1);
    per_face = 15.0 * sizeof(fsdem_real) + 2 + sizeof(int);
    per_cell = 8.0 * sizeof(fsdem_real) + 3 + sizeof(int);
    per_cell += 12.0 * sizeof(fsdem_real); /* pressure solver: vectors and multigrid levels */
    if (d->viscosity > 0) per_face += 16.0 * sizeof(fsdem_real) + 1;
    *bytes = *total * per_cell + faces * per_face;
}

static fsdem_result fsdem__pic_check(const fsdem_pic_desc *d, char *msg, size_t size) {
    int a, k;
    double cells[3], total, bytes;
#define FSDEM__PIC_BAD(...)                                                                        \
    do {                                                                                           \
        if (msg && size) snprintf(msg, size, __VA_ARGS__);                                         \
        return FSDEM_ERR_INVALID_ARG;                                                              \
    } while (0)
    if (msg && size) msg[0] = '\0';
    if (d->dim != 2 && d->dim != 3) FSDEM__PIC_BAD("fsdem_pic_desc.dim = %d must be 2 or 3", d->dim);
    if (!(d->cell_size > 0) || !fsdem__finite(d->cell_size))
        FSDEM__PIC_BAD("fsdem_pic_desc.cell_size = %g m must be > 0 and finite", (double)d->cell_size);
    if (!fsdem__finite3(d->domain_min) || !fsdem__finite3(d->domain_max))
        FSDEM__PIC_BAD("fsdem_pic_desc.domain_min/domain_max must be finite");
    for (a = 0; a < d->dim; ++a)
        if (!(fsdem__comp(d->domain_max, a) > fsdem__comp(d->domain_min, a)))
            FSDEM__PIC_BAD("fsdem_pic_desc.domain_max.%c = %g must exceed domain_min.%c = %g", "xyz"[a],
                           (double)fsdem__comp(d->domain_max, a), "xyz"[a],
                           (double)fsdem__comp(d->domain_min, a));
    if (!(d->density > 0) || !fsdem__finite(d->density))
        FSDEM__PIC_BAD("fsdem_pic_desc.density = %g kg/m^3 must be > 0", (double)d->density);
    if (!(d->viscosity >= 0) || !fsdem__finite(d->viscosity))
        FSDEM__PIC_BAD("fsdem_pic_desc.viscosity = %g m^2/s must be >= 0", (double)d->viscosity);
    if (fsdem__check_gravity("fsdem_pic_desc", d->gravity, d->dim, msg, size) != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < 2 * d->dim; ++k) {
        if ((int)d->boundary[k] < 0 || (int)d->boundary[k] > 3)
            FSDEM__PIC_BAD("fsdem_pic_desc.boundary[%d] (%s side) = %d is not a fsdem_pic_bc", k,
                           fsdem__pic_side_name(k), (int)d->boundary[k]);
        if (!fsdem__within(d->boundary_velocity[k], FSDEM_MAX_SPEED))
            FSDEM__PIC_BAD("fsdem_pic_desc.boundary_velocity[%d] must be finite and at most FSDEM_MAX_SPEED (%g m/s)", k,
                           (double)FSDEM_MAX_SPEED);
    }
    if ((int)d->transfer < 0 || (int)d->transfer > 2)
        FSDEM__PIC_BAD("fsdem_pic_desc.transfer = %d is not a fsdem_pic_transfer", (int)d->transfer);
    if (!(d->flip_ratio >= 0 && d->flip_ratio <= 1))
        FSDEM__PIC_BAD("fsdem_pic_desc.flip_ratio = %g must be in [0, 1]", (double)d->flip_ratio);
    if ((int)d->kernel < 0 || (int)d->kernel > 1)
        FSDEM__PIC_BAD("fsdem_pic_desc.kernel = %d is not a fsdem_pic_kernel", (int)d->kernel);
    if (d->particles_per_cell < 1 || d->particles_per_cell > 64)
        FSDEM__PIC_BAD("fsdem_pic_desc.particles_per_cell = %d must be in [1, 64]", d->particles_per_cell);
    if (!(d->jitter >= 0 && d->jitter <= 1))
        FSDEM__PIC_BAD("fsdem_pic_desc.jitter = %g must be in [0, 1]", (double)d->jitter);
    if (d->min_particles_per_cell < 0 || d->min_particles_per_cell > d->particles_per_cell)
        FSDEM__PIC_BAD("fsdem_pic_desc.min_particles_per_cell = %d must be in [0, particles_per_cell = %d]",
                       d->min_particles_per_cell, d->particles_per_cell);
    if (d->max_particles_per_cell != 0 && d->max_particles_per_cell < d->particles_per_cell)
        FSDEM__PIC_BAD("fsdem_pic_desc.max_particles_per_cell = %d must be 0 or >= particles_per_cell = %d",
                       d->max_particles_per_cell, d->particles_per_cell);
    if (d->advection_order != 2 && d->advection_order != 3)
        FSDEM__PIC_BAD("fsdem_pic_desc.advection_order = %d must be 2 or 3", d->advection_order);
    if (!(d->cfl > 0) || !fsdem__finite(d->cfl))
        FSDEM__PIC_BAD("fsdem_pic_desc.cfl = %g must be > 0", (double)d->cfl);
    if (!(d->cfl_max >= d->cfl) || !fsdem__finite(d->cfl_max))
        FSDEM__PIC_BAD("fsdem_pic_desc.cfl_max = %g must be >= cfl = %g", (double)d->cfl_max, (double)d->cfl);
    if (fsdem__check_dt_max("fsdem_pic_desc", d->dt_max, d->gravity, msg, size) != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    if (!(d->ghost_theta_min > 0 && d->ghost_theta_min <= 1))
        FSDEM__PIC_BAD("fsdem_pic_desc.ghost_theta_min = %g must be in (0, 1]", (double)d->ghost_theta_min);
    if (d->extrapolation_layers < 0 || d->extrapolation_layers > 1000)
        FSDEM__PIC_BAD("fsdem_pic_desc.extrapolation_layers = %d must be in [0, 1000]", d->extrapolation_layers);
    if ((int)d->pressure_precond < 0 || (int)d->pressure_precond > 5)
        FSDEM__PIC_BAD("fsdem_pic_desc.pressure_precond = %d is not a fsdem_precond", (int)d->pressure_precond);
    if ((int)d->viscosity_precond < 0 || (int)d->viscosity_precond > 5)
        FSDEM__PIC_BAD("fsdem_pic_desc.viscosity_precond = %d is not a fsdem_precond", (int)d->viscosity_precond);
    if (!(d->pressure_tolerance > 0 && d->pressure_tolerance < 1))
        FSDEM__PIC_BAD("fsdem_pic_desc.pressure_tolerance = %g must be in (0, 1)", (double)d->pressure_tolerance);
    if (!(d->viscosity_tolerance > 0 && d->viscosity_tolerance < 1))
        FSDEM__PIC_BAD("fsdem_pic_desc.viscosity_tolerance = %g must be in (0, 1)", (double)d->viscosity_tolerance);
    if (d->pressure_max_iterations < 1)
        FSDEM__PIC_BAD("fsdem_pic_desc.pressure_max_iterations = %d must be >= 1", d->pressure_max_iterations);
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        FSDEM__PIC_BAD("fsdem_pic_desc.allocator needs both alloc and free, or neither");
#undef FSDEM__PIC_BAD
    fsdem__pic_grid_size(d, cells, &total, &bytes);
    for (a = 0; a < d->dim; ++a) {
        /* whole cells move domain_max by at most half a cell, unless the extent is below half a cell */
        const double extent = (double)fsdem__comp(d->domain_max, a) - (double)fsdem__comp(d->domain_min, a);
        if (fabs(cells[a] * (double)d->cell_size - extent) > 0.5 * (double)d->cell_size * (1 + 1e-9))
            return fsdem__reject(msg, size,
                                 "fsdem_pic_desc.cell_size = %g m exceeds twice the extent %g m along %c: the grid would "
                                 "change the domain by more than half a cell",
                                 (double)d->cell_size, extent, "xyz"[a]);
    }
    if (total > 4e8 || cells[0] + 1 > 2e9 || cells[1] + 1 > 2e9 || cells[2] + 1 > 2e9 ||
        (d->max_memory > 0 && bytes > (double)d->max_memory) || bytes > (double)((size_t)-1) / 2) {
        if (msg && size)
            snprintf(msg, size,
                     "fsdem_pic_desc.the grid of %.0f x %.0f x %.0f = %.4g cells (cell_size %g m) needs about "
                     "%.4g bytes, more than %s",
                     cells[0], cells[1], cells[2], total, (double)d->cell_size, bytes,
                     d->max_memory > 0 && bytes > (double)d->max_memory ? "max_memory allows"
                                                                         : "fits in memory");
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    return FSDEM_OK;
}

fsdem_result fsdem_pic_desc_check(const fsdem_pic_desc *desc, char *message, size_t message_size) {
    if (!desc) {
        if (message && message_size) snprintf(message, message_size, "fsdem_pic_desc is NULL");
        return FSDEM_ERR_INVALID_ARG;
    }
    return fsdem__pic_check(desc, message, message_size);
}

/* Allocation that is counted in the solver's memory figure. */
static void *fsdem__pic_alloc(fsdem_pic *s, size_t bytes) {
    void *p = fsdem__alloc(&s->allocator, bytes);
    if (p) s->bytes += bytes;
    return p;
}

static void fsdem__pic_release(fsdem_pic *s, void *p, size_t bytes) {
    if (p) {
        fsdem__free(&s->allocator, p, bytes);
        s->bytes -= bytes;
    }
}

/* One grid array of the solver: where its pointer lives, its length, element size and initial
   value (reals: `fill`; other types: zero). */
typedef struct fsdem__pic_array {
    void **ptr;
    size_t count, elem;
    fsdem_real fill;
} fsdem__pic_array;

/* 19 per axis (13, and 6 for the implicit viscosity) and 14 per cell: 71 in 3D with viscosity */
#define FSDEM__PIC_MAX_ARRAYS 80

static void fsdem__pic_array_add(fsdem__pic_array *t, int *n, void **ptr, size_t count, size_t elem, fsdem_real fill) {
    FSDEM_ASSERT(*n < FSDEM__PIC_MAX_ARRAYS);
    t[*n].ptr = ptr;
    t[*n].count = count > 0 ? count : 1;
    t[*n].elem = elem;
    t[*n].fill = fill;
    ++*n;
}

/* Every grid array of the solver (faces per axis, implicit-viscosity face grids, cells), so
   creation and destruction treat them alike from one list. Returns their number. */
static int fsdem__pic_arrays(fsdem_pic *s, fsdem__pic_array t[FSDEM__PIC_MAX_ARRAYS]) {
    const size_t R = sizeof(fsdem_real), nc = (size_t)s->ncell;
    int n = 0, a, b, c;
#define FSDEM__PIC_REALS(field, count, fill) fsdem__pic_array_add(t, &n, (void **)&s->field, count, R, (fsdem_real)(fill))
#define FSDEM__PIC_BYTES(field, count) fsdem__pic_array_add(t, &n, (void **)&s->field, count, 1, 0)
    for (a = 0; a < s->dim; ++a) {
        const size_t nf = (size_t)s->nface[a];
        FSDEM__PIC_REALS(u[a], nf, 0);
        FSDEM__PIC_REALS(uold[a], nf, 0);
        FSDEM__PIC_REALS(wsum[a], nf, 0);
        FSDEM__PIC_REALS(ftmp[a], nf, 0);
        FSDEM__PIC_REALS(sopen[a], nf, 1);
        FSDEM__PIC_REALS(svel[a], nf, 0);
        FSDEM__PIC_REALS(copen[a], nf, 1);
        FSDEM__PIC_REALS(cvel[a], nf, 0);
        FSDEM__PIC_REALS(cacc[a], nf, 0);
        FSDEM__PIC_REALS(E[a], nf, 1);
        FSDEM__PIC_REALS(us[a], nf, 0);
        FSDEM__PIC_BYTES(fvalid[a], nf);
        FSDEM__PIC_BYTES(fvalid2[a], nf);
        if (s->desc.viscosity > 0) {
            FSDEM__PIC_REALS(shear[a], nf, 0);
            FSDEM__PIC_REALS(cvisc[a], nf, 0);
            FSDEM__PIC_BYTES(vcell[a], nf);
            for (b = 0; b < s->dim; ++b) {
                size_t m = 1;
                for (c = 0; c < 3; ++c) m *= (size_t)(s->fn[a][c] + (c == b));
                FSDEM__PIC_REALS(vface[a][b], m, 0);
            }
        }
    }
    FSDEM__PIC_REALS(frac, nc, 0);
    FSDEM__PIC_REALS(fref, nc, 1);
    FSDEM__PIC_REALS(phi, nc, 0);
    FSDEM__PIC_REALS(pres, nc, 0);
    FSDEM__PIC_REALS(rhs, nc, 0);
    FSDEM__PIC_REALS(diag, nc, 0);
    FSDEM__PIC_REALS(ctmp, nc, 0);
    FSDEM__PIC_REALS(crhs, nc, 0);
    FSDEM__PIC_REALS(cref, nc, 1);
    FSDEM__PIC_BYTES(ctype, nc);
    FSDEM__PIC_BYTES(cnear, nc);
    FSDEM__PIC_BYTES(csolid, nc);
    fsdem__pic_array_add(t, &n, (void **)&s->cstart, nc + 1, sizeof(int), 0);
    fsdem__pic_array_add(t, &n, (void **)&s->fqueue, (size_t)s->fqueue_size, sizeof(int), 0);
#undef FSDEM__PIC_REALS
#undef FSDEM__PIC_BYTES
    return n;
}

static void fsdem__pic_free_particles(fsdem_pic *s) {
    size_t cap = (size_t)s->pcap;
    int a;
    fsdem__pic_release(s, s->px, cap * sizeof(fsdem_vec3));
    fsdem__pic_release(s, s->pv, cap * sizeof(fsdem_vec3));
    fsdem__pic_release(s, s->ptmp, cap * sizeof(fsdem_vec3));
    for (a = 0; a < 3; ++a) fsdem__pic_release(s, s->pc[a], cap * sizeof(fsdem_vec3));
    fsdem__pic_release(s, s->pcell, cap * sizeof(int));
    fsdem__pic_release(s, s->pidx, cap * sizeof(int));
    fsdem__pic_release(s, s->pflag, cap);
    s->px = s->pv = s->ptmp = s->pc[0] = s->pc[1] = s->pc[2] = NULL;
    s->pcell = s->pidx = NULL;
    s->pflag = NULL;
    s->pcap = 0;
}

void fsdem_pic_destroy(fsdem_pic *s) {
    fsdem__pic_array t[FSDEM__PIC_MAX_ARRAYS];
    fsdem_allocator al;
    int a, n;
    if (!s) return;
    fsdem__pic_free_particles(s);
    n = fsdem__pic_arrays(s, t);
    for (a = 0; a < n; ++a) fsdem__pic_release(s, *t[a].ptr, t[a].count * t[a].elem);
    for (a = 0; a < 3; ++a)
        if (s->pcg_v[a]) fsdem_pcg_destroy(s->pcg_v[a]);
    for (a = 0; a < s->obst_count; ++a)
        if (s->obst[a].verts)
            fsdem__pic_release(s, s->obst[a].verts, sizeof(fsdem_vec3) * (size_t)s->obst[a].d.vertex_count);
    fsdem__pic_release(s, s->obst, sizeof(fsdem__pic_obst) * (size_t)s->obst_capacity);
    if (s->pcg_p) fsdem_pcg_destroy(s->pcg_p);
    fsdem__gauges_free(&s->gauges, &s->allocator);
    al = s->allocator;
    fsdem__free(&al, s, sizeof *s);
}

const char *fsdem_pic_last_error(const fsdem_pic *s) { return s ? s->status.message : "fsdem_pic is NULL"; }

static int fsdem__pic_cell(const fsdem_pic *s, int i, int j, int k) { return (k * s->n[1] + j) * s->n[0] + i; }
static int fsdem__pic_face(const fsdem_pic *s, int a, int i, int j, int k) {
    return (k * s->fn[a][1] + j) * s->fn[a][0] + i;
}

/* Fill the viscous face-grid coefficients of axis a: 1 between two faces, 0 on the boundary. */
static void fsdem__pic_fill_vface(fsdem_pic *s, int a) {
    int b, i, j, k, m[3], c;
    for (b = 0; b < s->dim; ++b) {
        for (c = 0; c < 3; ++c) m[c] = s->fn[a][c] + (c == b);
        for (k = 0; k < m[2]; ++k)
            for (j = 0; j < m[1]; ++j)
                for (i = 0; i < m[0]; ++i) {
                    int coord = b == 0 ? i : b == 1 ? j : k;
                    s->vface[a][b][(k * m[1] + j) * m[0] + i] =
                        (coord == 0 || coord == m[b] - 1) ? (fsdem_real)0 : (fsdem_real)1;
                }
    }
}

static void fsdem__pic_static_flags(fsdem_pic *s);
static void fsdem__pic_compute_fref(fsdem_pic *s);

/* Grid geometry, strides and seeding constants of a new solver from its (checked) desc. */
static void fsdem__pic_layout(fsdem_pic *s, const fsdem_pic_desc *desc) {
    double cells[3], total, bytes;
    int a, b, root;
    s->dim = desc->dim;
    s->dx = desc->cell_size;
    s->inv_dx = 1 / s->dx;
    fsdem__pic_grid_size(desc, cells, &total, &bytes);
    for (a = 0; a < 3; ++a) s->n[a] = (int)cells[a];
    s->ncell = s->n[0] * s->n[1] * s->n[2];
    s->lo = desc->domain_min;
    s->hi = s->lo;
    if (s->dim == 2) s->lo.z = s->hi.z = 0;
    s->hi.x = s->lo.x + s->dx * (fsdem_real)s->n[0];
    s->hi.y = s->lo.y + s->dx * (fsdem_real)s->n[1];
    if (s->dim == 3) s->hi.z = s->lo.z + s->dx * (fsdem_real)s->n[2];
    {
        /* a millionth of the cell or of the largest coordinate, whichever is larger: above the
           rounding of face positions (float included), far below any geometric detail */
        fsdem_real extent = s->dx;
        for (a = 0; a < 3; ++a) {
            fsdem_real m = (fsdem_real)fabs(fsdem__comp(s->lo, a)), M = (fsdem_real)fabs(fsdem__comp(s->hi, a));
            if (m > extent) extent = m;
            if (M > extent) extent = M;
        }
        s->surface_tol = (fsdem_real)fsdem__tolerance(1e-6) * extent;
    }
    s->cstep[0] = 1;
    s->cstep[1] = s->n[0];
    s->cstep[2] = s->n[0] * s->n[1];
    for (a = 0; a < 3; ++a) {
        for (b = 0; b < 3; ++b) s->fn[a][b] = s->n[b] + (a == b && a < s->dim);
        s->nface[a] = a < s->dim ? s->fn[a][0] * s->fn[a][1] * s->fn[a][2] : 0;
        s->fstep[a][0] = 1;
        s->fstep[a][1] = s->fn[a][0];
        s->fstep[a][2] = s->fn[a][0] * s->fn[a][1];
    }
    s->fqueue_size = s->nface[0] > s->nface[1] ? s->nface[0] : s->nface[1];
    if (s->nface[2] > s->fqueue_size) s->fqueue_size = s->nface[2];
    s->ppc = desc->particles_per_cell;
    root = (int)floor(pow((double)s->ppc, 1.0 / s->dim) + 0.5);
    s->sub = (int)pow((double)root, (double)s->dim) == s->ppc ? root : 0;
    s->pvol = (fsdem_real)pow((double)s->dx, (double)s->dim) / (fsdem_real)s->ppc;
    s->gmag = fsdem__norm(desc->gravity);
    s->rng = 0x9E3779B97F4A7C15ull ^ (unsigned long long)desc->seed;
    if (s->dim == 2) s->desc.domain_max.z = s->desc.domain_min.z;
}

/* Allocates and fills every grid array of the table (fsdem__pic_arrays). FSDEM_ERR_OUT_OF_MEMORY
   leaves the ones allocated so far for fsdem_pic_destroy. */
static fsdem_result fsdem__pic_allocate(fsdem_pic *s) {
    fsdem__pic_array t[FSDEM__PIC_MAX_ARRAYS];
    const int n = fsdem__pic_arrays(s, t);
    int a, b;
    size_t k;
    for (a = 0; a < n; ++a) {
        unsigned char *p = (unsigned char *)fsdem__pic_alloc(s, t[a].count * t[a].elem);
        if (!p) return FSDEM_ERR_OUT_OF_MEMORY;
        *t[a].ptr = p;
        if (t[a].elem == sizeof(fsdem_real) && t[a].fill != 0)
            for (k = 0; k < t[a].count; ++k) ((fsdem_real *)(void *)p)[k] = t[a].fill;
        else memset(p, 0, t[a].count * t[a].elem);
    }
    for (a = 0; a < s->dim && s->desc.viscosity > 0; ++a) fsdem__pic_fill_vface(s, a);
    for (b = 0; b < s->ncell; ++b) s->ctype[b] = FSDEM_STENCIL_CELL_AIR;
    return FSDEM_OK;
}

/* The linear solvers, set up once on the full grid so that steps never allocate: the pressure
   solve on the cell grid, and with a viscosity one solve per velocity component on its face grid. */
static fsdem_result fsdem__pic_solvers(fsdem_pic *s) {
    const fsdem_pic_desc *desc = &s->desc;
    fsdem_pcg_desc pd = fsdem_pcg_desc_default();
    fsdem_stencil st;
    fsdem_result r;
    int a, b;
    pd.preconditioner = desc->pressure_precond;
    pd.tolerance = desc->pressure_tolerance;
    pd.max_iterations = desc->pressure_max_iterations;
    pd.allocator = s->allocator;
    r = fsdem_pcg_create(&pd, &s->pcg_p);
    if (r == FSDEM_OK) {
        memset(&st, 0, sizeof st);
        st.dim = s->dim;
        for (a = 0; a < 3; ++a) st.n[a] = s->n[a];
        r = fsdem_pcg_setup_stencil(s->pcg_p, &st);
    }
    for (a = 0; a < s->dim && r == FSDEM_OK && desc->viscosity > 0; ++a) {
        pd.preconditioner = desc->viscosity_precond;
        pd.tolerance = desc->viscosity_tolerance;
        r = fsdem_pcg_create(&pd, &s->pcg_v[a]);
        if (r == FSDEM_OK) {
            memset(&st, 0, sizeof st);
            st.dim = s->dim;
            for (b = 0; b < 3; ++b) st.n[b] = s->fn[a][b];
            r = fsdem_pcg_setup_stencil(s->pcg_v[a], &st);
        }
    }
    return r;
}

fsdem_result fsdem_pic_create(const fsdem_pic_desc *desc, fsdem_pic **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_result r;
    fsdem_pic *s;
    int a;
    if (out) *out = NULL;
    if (!desc || !out) return FSDEM_ERR_INVALID_ARG;
    r = fsdem__pic_check(desc, msg, sizeof msg);
    s = (fsdem_pic *)fsdem__object_new(r, msg, desc->log, desc->log_user, &desc->allocator, sizeof *s, "fsdem_pic_create", &r);
    if (!s) return r;
    s->desc = *desc;
    s->allocator = desc->allocator;
    s->bytes = sizeof *s;
    s->status.log = desc->log;
    s->status.log_user = desc->log_user;
    fsdem__pic_layout(s, desc);
    for (a = 0; a < s->dim && desc->log; ++a)
        if (fsdem__comp(s->hi, a) != fsdem__comp(desc->domain_max, a)) {
            snprintf(msg, sizeof msg, "fsdem_pic_create: domain_max.%c rounded from %.9g to %.9g m (%d cells of %g m)",
                     "xyz"[a], (double)fsdem__comp(desc->domain_max, a), (double)fsdem__comp(s->hi, a), s->n[a],
                     (double)s->dx);
            desc->log(desc->log_user, FSDEM_LOG_LEVEL_INFO, msg);
        }
    if (fsdem__pic_allocate(s) != FSDEM_OK) {
        snprintf(msg, sizeof msg, "fsdem_pic_create: out of memory allocating the %d x %d x %d grid", s->n[0], s->n[1],
                 s->n[2]);
        r = FSDEM_ERR_OUT_OF_MEMORY;
    } else if ((r = fsdem__pic_solvers(s)) != FSDEM_OK) {
        snprintf(msg, sizeof msg, "fsdem_pic_create: setting up the linear solvers failed (%s)", fsdem_result_string(r));
        r = r == FSDEM_ERR_INVALID_ARG ? FSDEM_ERR_INVALID_ARG : FSDEM_ERR_OUT_OF_MEMORY;
    }
    if (r != FSDEM_OK) {
        if (desc->log) desc->log(desc->log_user, FSDEM_LOG_LEVEL_ERROR, msg);
        fsdem_pic_destroy(s);
        return r;
    }
    s->coupling.dim = s->dim;
    for (a = 0; a < 3; ++a) {
        s->coupling.n[a] = s->n[a];
        s->coupling.face_count[a] = s->nface[a];
        s->coupling.open[a] = s->copen[a];
        s->coupling.solid_velocity[a] = s->cvel[a];
        s->coupling.acceleration[a] = s->cacc[a];
        s->coupling.shear[a] = s->shear[a];
        s->coupling.viscous_velocity[a] = s->cvisc[a];
    }
    s->coupling.pressure_rhs = s->crhs;
    s->coupling.reference = s->cref;
    fsdem__pic_static_flags(s);
    fsdem__pic_compute_fref(s);
    *out = s;
    fsdem__ok(&s->status);
    return FSDEM_OK;
}

/* splitmix64, uniform in [0, 1) */
static fsdem_real fsdem__pic_rand(fsdem_pic *s) {
    unsigned long long z = (s->rng += 0x9E3779B97F4A7C15ull);
    /* (the right shifts are written as divisions by powers of two, which keeps '>' '>' out of the
       grep map of the file) */
    z = (z ^ (z / 1073741824ull)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z / 134217728ull)) * 0x94D049BB133111EBull;
    z ^= z / 2147483648ull;
    return (fsdem_real)((double)(z / 2048ull) * (1.0 / 9007199254740992.0));
}

/* ---- >>pic_geometry : obstacles, signed distances, cut-cell face fractions ---- */

/* Signed distance of one obstacle, positive outside the solid. */
static fsdem_real fsdem__pic_obst_sdf(const fsdem_pic *s, const fsdem__pic_obst *o, fsdem_vec3 p) {
    const fsdem_pic_obstacle *d = &o->d;
    fsdem_vec3 normal;
    switch (d->type) {
    case FSDEM_PIC_OBSTACLE_TYPE_BOX: return fsdem__geom_box(p, d->a, d->b, s->dim, &normal);
    case FSDEM_PIC_OBSTACLE_TYPE_CYLINDER:
        if (s->dim == 3) return fsdem__geom_cylinder(p, d->a, d->b, d->radius);
        return fsdem__geom_sphere(p, d->a, d->radius, 2); /* a disc in 2D */
    case FSDEM_PIC_OBSTACLE_TYPE_SPHERE: return fsdem__geom_sphere(p, d->a, d->radius, s->dim);
    case FSDEM_PIC_OBSTACLE_TYPE_POLYGON: return fsdem__geom_polygon(p, o->verts, d->vertex_count);
    case FSDEM_PIC_OBSTACLE_TYPE_SDF: return d->sdf(d->sdf_user, p, &normal);
    }
    return 1e30f;
}

/* Signed distance to the union of the obstacles (large when there are none); *which gets the
   nearest obstacle (or -1). Obstacles whose inflated bounding box does not hold p are skipped: they
   are more than two cells away. */
static fsdem_real fsdem__pic_obst_min(const fsdem_pic *s, fsdem_vec3 p, int *which) {
    fsdem_real best = (fsdem_real)1e30, d;
    int o, b, w = -1;
    for (o = 0; o < s->obst_count; ++o) {
        const fsdem__pic_obst *ob = &s->obst[o];
        int outside = 0;
        for (b = 0; b < s->dim; ++b)
            if (fsdem__comp(p, b) < fsdem__comp(ob->box_lo, b) || fsdem__comp(p, b) > fsdem__comp(ob->box_hi, b))
                outside = 1;
        if (outside) continue;
        d = fsdem__pic_obst_sdf(s, ob, p);
        if (d < best) {
            best = d;
            w = o;
        }
    }
    if (which) *which = w;
    return best;
}

static int fsdem__pic_side_closed(const fsdem_pic *s, int side) {
    return s->desc.boundary[side] != FSDEM_PIC_BC_OUTFLOW;
}

/* Distance to obstacles and closed walls, positive in the open domain; gradient by differences. */
static fsdem_real fsdem__pic_solid_sdf(const fsdem_pic *s, fsdem_vec3 p) {
    fsdem_real d = fsdem__pic_obst_min(s, p, NULL), w;
    int b;
    for (b = 0; b < s->dim; ++b) {
        if (fsdem__pic_side_closed(s, 2 * b)) {
            w = fsdem__comp(p, b) - fsdem__comp(s->lo, b);
            if (w < d) d = w;
        }
        if (fsdem__pic_side_closed(s, 2 * b + 1)) {
            w = fsdem__comp(s->hi, b) - fsdem__comp(p, b);
            if (w < d) d = w;
        }
    }
    return d;
}

static fsdem_vec3 fsdem__pic_axis_shift(fsdem_vec3 p, int b, fsdem_real h) {
    if (b == 0) p.x += h;
    else if (b == 1) p.y += h;
    else p.z += h;
    return p;
}

static fsdem_real fsdem__pic_obst_dist(const fsdem_pic *s, fsdem_vec3 p) { return fsdem__pic_obst_min(s, p, NULL); }

/* Unit gradient at p of a distance `dist` by central differences over 1e-3 of a cell (0 where it is
   flat). */
static fsdem_vec3 fsdem__pic_gradient(const fsdem_pic *s, fsdem_real (*dist)(const fsdem_pic *, fsdem_vec3), fsdem_vec3 p) {
    fsdem_real h = s->dx * (fsdem_real)1e-3, g[3] = {0, 0, 0}, len;
    int b;
    for (b = 0; b < s->dim; ++b)
        g[b] = dist(s, fsdem__pic_axis_shift(p, b, h)) - dist(s, fsdem__pic_axis_shift(p, b, -h));
    len = (fsdem_real)sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    return len > 0 ? fsdem_v3(g[0] / len, g[1] / len, g[2] / len) : fsdem_v3(0, 0, 0);
}

fsdem_real fsdem_pic_solid_distance(const fsdem_pic *s, fsdem_vec3 p, fsdem_vec3 *normal) {
    if (normal) *normal = fsdem__zero3();
    if (!s) return 0;
    if (normal) *normal = fsdem__pic_gradient(s, fsdem__pic_solid_sdf, p);
    return fsdem__pic_solid_sdf(s, p);
}

/* Fraction of a segment with end values a, b that lies where the distance is > 0 (linear). */
static fsdem_real fsdem__pic_frac2(fsdem_real a, fsdem_real b) {
    if (a > 0 && b > 0) return 1;
    if (a <= 0 && b <= 0) return 0;
    return a > 0 ? a / (a - b) : b / (b - a);
}

/* Same for a triangle with vertex values a, b, c (exact for a linear distance). */
static fsdem_real fsdem__pic_frac3(fsdem_real a, fsdem_real b, fsdem_real c) {
    int pos = (a > 0) + (b > 0) + (c > 0);
    fsdem_real t;
    if (pos == 3) return 1;
    if (pos == 0) return 0;
    if (pos == 1) { /* the lone positive vertex first */
        if (b > 0) { t = a; a = b; b = t; }
        else if (c > 0) { t = a; a = c; c = t; }
        return a * a / ((a - b) * (a - c));
    }
    if (b <= 0) { t = a; a = b; b = t; }
    else if (c <= 0) { t = a; a = c; c = t; }
    return 1 - a * a / ((a - b) * (a - c));
}

#define FSDEM__PIC_SUB 4 /* sub-segments (sub-squares per side) of a face for its open fraction */

/* Distance to the obstacle union for the face fractions, 0 within surface_tol of the surface. A
   face lying on a solid's side (a box edge on a grid line) must not depend on the rounding of the
   two coordinates: left to it, the face could come out open by 1e-15 of its area and leave a
   chain of cells joined only by such faces, a near-singular pressure operator. Counted as on the
   surface, a sample point there is solid (fsdem__pic_frac2 opens only d > 0), so a side on a face
   and a side a hair off it give the same fractions. */
typedef fsdem_real (*fsdem__pic_dist_fn)(const void *solid, fsdem_vec3 p);

static fsdem_real fsdem__pic_face_sample(const fsdem_pic *s, fsdem__pic_dist_fn dist, const void *solid, fsdem_vec3 p) {
    fsdem_real d = dist(solid, p);
    return (fsdem_real)fabs(d) <= s->surface_tol ? 0 : d;
}

/* The obstacle union as a fsdem__pic_dist_fn (`solid` is the solver). */
static fsdem_real fsdem__pic_obstacles_dist(const void *solid, fsdem_vec3 p) {
    return fsdem__pic_obst_min((const fsdem_pic *)solid, p, NULL);
}

/* Open fraction of the face of axis a with lower corner `c0` (m), spanning one cell along the
   other axes, outside the solid whose signed distance is dist(solid, p) (the obstacle union, or a
   coupler's moving body). */
static fsdem_real fsdem__pic_face_fraction(const fsdem_pic *s, int a, fsdem_vec3 c0, fsdem__pic_dist_fn dist, const void *solid) {
    const int S = FSDEM__PIC_SUB;
    fsdem_real h = s->dx / S, v[FSDEM__PIC_SUB + 1][FSDEM__PIC_SUB + 1], sum = 0;
    int b1 = (a + 1) % 3, b2 = (a + 2) % 3, i, j;
    if (s->dim == 2) {
        int b = a == 0 ? 1 : 0;
        for (i = 0; i <= S; ++i) v[0][i] = fsdem__pic_face_sample(s, dist, solid, fsdem__pic_axis_shift(c0, b, h * (fsdem_real)i));
        for (i = 0; i < S; ++i) sum += fsdem__pic_frac2(v[0][i], v[0][i + 1]);
        return sum / S;
    }
    for (j = 0; j <= S; ++j)
        for (i = 0; i <= S; ++i)
            v[j][i] = fsdem__pic_face_sample(
                s, dist, solid, fsdem__pic_axis_shift(fsdem__pic_axis_shift(c0, b1, h * (fsdem_real)i), b2, h * (fsdem_real)j));
    for (j = 0; j < S; ++j)
        for (i = 0; i < S; ++i) {
            fsdem_vec3 m = fsdem__pic_axis_shift(fsdem__pic_axis_shift(c0, b1, h * ((fsdem_real)i + (fsdem_real)0.5)), b2,
                                                 h * ((fsdem_real)j + (fsdem_real)0.5));
            fsdem_real vc = fsdem__pic_face_sample(s, dist, solid, m);
            sum += fsdem__pic_frac3(vc, v[j][i], v[j][i + 1]) + fsdem__pic_frac3(vc, v[j][i + 1], v[j + 1][i + 1]) +
                   fsdem__pic_frac3(vc, v[j + 1][i + 1], v[j + 1][i]) + fsdem__pic_frac3(vc, v[j + 1][i], v[j][i]);
        }
    return sum / (4 * S * S);
}

/* Face centre (m) of face (i, j, k) of axis a. */
static fsdem_vec3 fsdem__pic_face_pos(const fsdem_pic *s, int a, int i, int j, int k) {
    fsdem_vec3 p;
    p.x = s->lo.x + s->dx * ((fsdem_real)i + (a == 0 ? 0 : (fsdem_real)0.5));
    p.y = s->lo.y + s->dx * ((fsdem_real)j + (a == 1 ? 0 : (fsdem_real)0.5));
    p.z = s->dim == 3 ? s->lo.z + s->dx * ((fsdem_real)k + (a == 2 ? 0 : (fsdem_real)0.5)) : 0;
    return p;
}

static fsdem_vec3 fsdem__pic_cell_pos(const fsdem_pic *s, int i, int j, int k) {
    return fsdem_v3(s->lo.x + s->dx * ((fsdem_real)i + (fsdem_real)0.5), s->lo.y + s->dx * ((fsdem_real)j + (fsdem_real)0.5),
                    s->dim == 3 ? s->lo.z + s->dx * ((fsdem_real)k + (fsdem_real)0.5) : 0);
}

/* Face fractions and solid velocities of the obstacle union into open[a], vel[a]. Returns the
   number of cells with at least one face open. */
static int fsdem__pic_static_faces(const fsdem_pic *s, fsdem_real *open[3], fsdem_real *vel[3]) {
    int a, i, j, k, which, open_cells = 0;
    fsdem_real reach = s->dx * (fsdem_real)0.9;
    for (a = 0; a < s->dim; ++a)
        for (k = 0; k < s->fn[a][2]; ++k)
            for (j = 0; j < s->fn[a][1]; ++j)
                for (i = 0; i < s->fn[a][0]; ++i) {
                    int f = fsdem__pic_face(s, a, i, j, k);
                    fsdem_vec3 p = fsdem__pic_face_pos(s, a, i, j, k);
                    fsdem_real d = fsdem__pic_obst_min(s, p, &which);
                    open[a][f] = 1;
                    vel[a][f] = 0;
                    if (which < 0) continue;
                    vel[a][f] = fsdem__comp(s->obst[which].d.velocity, a);
                    if (d > reach) continue;
                    p = fsdem__pic_axis_shift(p, (a + 1) % s->dim, -s->dx / 2);
                    if (s->dim == 3) p = fsdem__pic_axis_shift(p, (a + 2) % 3, -s->dx / 2);
                    open[a][f] = fsdem__pic_face_fraction(s, a, p, fsdem__pic_obstacles_dist, s);
                }
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                int any = 0;
                for (a = 0; a < s->dim && !any; ++a) {
                    int f = fsdem__pic_face(s, a, i, j, k);
                    if (open[a][f] > 0 || open[a][f + s->fstep[a][a]] > 0) any = 1;
                }
                open_cells += any;
            }
    return open_cells;
}

/* Static-solid and near-solid flags of the cells from sopen. */
static void fsdem__pic_static_flags(fsdem_pic *s) {
    int a, i, j, k, c, di, dj, dk, zr = s->dim == 3 ? 1 : 0;
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                int any_open = 0, any_cut = 0;
                c = fsdem__pic_cell(s, i, j, k);
                for (a = 0; a < s->dim; ++a) {
                    int f = fsdem__pic_face(s, a, i, j, k), g = f + s->fstep[a][a];
                    if (s->sopen[a][f] > 0 || s->sopen[a][g] > 0) any_open = 1;
                    if (s->sopen[a][f] < 1 || s->sopen[a][g] < 1) any_cut = 1;
                }
                s->csolid[c] = (unsigned char)!any_open;
                s->ctmp[c] = (fsdem_real)any_cut;
            }
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                int near = 0;
                for (dk = -zr; dk <= zr; ++dk)
                    for (dj = -1; dj <= 1; ++dj)
                        for (di = -1; di <= 1; ++di) {
                            int x = i + di, y = j + dj, z = k + dk;
                            if (x < 0 || y < 0 || z < 0 || x >= s->n[0] || y >= s->n[1] || z >= s->n[2]) continue;
                            if (s->ctmp[fsdem__pic_cell(s, x, y, z)] > 0) near = 1;
                        }
                s->cnear[fsdem__pic_cell(s, i, j, k)] = (unsigned char)near;
            }
}

/* One-dimensional integral of the tent kernel of cell i (of n) over the domain, per cell volume. */
static fsdem_real fsdem__pic_tent_1d(int i, int n) {
    fsdem_real v = 1;
    if (i == 0) v -= (fsdem_real)0.125;
    if (i == n - 1) v -= (fsdem_real)0.125;
    return v;
}

/* Reference fluid fraction of each cell: what the tent kernel collects from a uniformly filled open
   domain. Walls truncate it analytically. Near obstacles it is summed over the seeding lattice
   (the unjittered sub-cell sites of the 3^dim cells around, those outside the solids), so a freshly
   seeded cut cell reads exactly 1; with a particle count that is not a perfect power the seeding is
   random and the expected value, the kernel integral over the open space, is sampled instead (8
   points per axis over the support). Dividing the particle count by it makes a full cell read 1 next
   to any solid. */
static void fsdem__pic_compute_fref(fsdem_pic *s) {
    int i, j, k, c, q[3], m, S = s->sub ? s->sub : 8;
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                c = fsdem__pic_cell(s, i, j, k);
                if (s->csolid[c]) {
                    s->fref[c] = 0;
                    continue;
                }
                if (!s->cnear[c] || s->obst_count == 0) {
                    s->fref[c] = fsdem__pic_tent_1d(i, s->n[0]) * fsdem__pic_tent_1d(j, s->n[1]) *
                                 (s->dim == 3 ? fsdem__pic_tent_1d(k, s->n[2]) : 1);
                } else {
                    /* sites at offsets (q + 1/2) h from the lower corner of the 2-cell-wide support
                       [centre - dx, centre + dx] (lattice: h = dx / sub; sampling: h = 2 dx / 8) */
                    fsdem_vec3 cc = fsdem__pic_cell_pos(s, i, j, k);
                    fsdem_real h = s->sub ? s->dx / (fsdem_real)S : 2 * s->dx / (fsdem_real)S, lo_off;
                    int per = s->sub ? 2 * S + 1 : S; /* lattice: the sites of the 3 cells that the kernel reaches */
                    double sum = 0, wsum = 0;
                    int qz = s->dim == 3 ? per : 1;
                    lo_off = s->sub ? -(fsdem_real)1.5 * s->dx : -s->dx;
                    for (q[2] = 0; q[2] < qz; ++q[2])
                        for (q[1] = 0; q[1] < per; ++q[1])
                            for (q[0] = 0; q[0] < per; ++q[0]) {
                                fsdem_real off[3], w = 1;
                                fsdem_vec3 p;
                                int inside = 1;
                                for (m = 0; m < 3; ++m) {
                                    off[m] = m < s->dim ? lo_off + h * ((fsdem_real)q[m] + (fsdem_real)0.5) : 0;
                                    if (m < s->dim) {
                                        fsdem_real t = 1 - (fsdem_real)fabs(off[m]) * s->inv_dx;
                                        w *= t > 0 ? t : 0;
                                    }
                                }
                                if (w <= 0) continue;
                                p = fsdem_v3(cc.x + off[0], cc.y + off[1], cc.z + off[2]);
                                for (m = 0; m < s->dim; ++m)
                                    if (fsdem__comp(p, m) < fsdem__comp(s->lo, m) || fsdem__comp(p, m) > fsdem__comp(s->hi, m))
                                        inside = 0;
                                wsum += w;
                                if (inside && fsdem__pic_obst_min(s, p, NULL) > 0) sum += w;
                            }
                    s->fref[c] = (fsdem_real)(wsum > 0 ? sum / wsum : 0);
                }
            }
}

fsdem_pic_obstacle fsdem_pic_obstacle_box(fsdem_vec3 lo, fsdem_vec3 hi) {
    fsdem_pic_obstacle o;
    memset(&o, 0, sizeof o);
    o.type = FSDEM_PIC_OBSTACLE_TYPE_BOX;
    o.a = lo;
    o.b = hi;
    return o;
}

fsdem_pic_obstacle fsdem_pic_obstacle_sphere(fsdem_vec3 centre, fsdem_real radius) {
    fsdem_pic_obstacle o;
    memset(&o, 0, sizeof o);
    o.type = FSDEM_PIC_OBSTACLE_TYPE_SPHERE;
    o.a = centre;
    o.radius = radius;
    return o;
}

fsdem_pic_obstacle fsdem_pic_obstacle_cylinder(fsdem_vec3 a, fsdem_vec3 b, fsdem_real radius) {
    fsdem_pic_obstacle o;
    memset(&o, 0, sizeof o);
    o.type = FSDEM_PIC_OBSTACLE_TYPE_CYLINDER;
    o.a = a;
    o.b = b;
    o.radius = radius;
    return o;
}

fsdem_pic_obstacle fsdem_pic_obstacle_polygon(const fsdem_vec3 *vertices, int count) {
    fsdem_pic_obstacle o;
    memset(&o, 0, sizeof o);
    o.type = FSDEM_PIC_OBSTACLE_TYPE_POLYGON;
    o.vertices = vertices;
    o.vertex_count = count;
    return o;
}

fsdem_pic_obstacle fsdem_pic_obstacle_sdf(fsdem_sdf_fn sdf, void *user) {
    fsdem_pic_obstacle o;
    memset(&o, 0, sizeof o);
    o.type = FSDEM_PIC_OBSTACLE_TYPE_SDF;
    o.sdf = sdf;
    o.sdf_user = user;
    return o;
}

static void fsdem__pic_remove_marked(fsdem_pic *s);
static void fsdem__pic_refresh(fsdem_pic *s);

fsdem_result fsdem_pic_add_obstacle(fsdem_pic *s, const fsdem_pic_obstacle *ob, int *id) {
    fsdem__pic_obst o;
    fsdem_real *open[3], *vel[3];
    int b, i, open_cells, inside;
    static const char *names[5] = {"box", "sphere", "cylinder", "polygon", "sdf"};
    const char *name;
    if (id) *id = -1;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!ob) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: NULL obstacle");
    if ((int)ob->type < 0 || (int)ob->type > 4)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: type %d is not a fsdem_pic_obstacle_type",
                           (int)ob->type);
    name = names[ob->type];
    if (!fsdem__finite3(ob->a) || !fsdem__finite3(ob->b) || !fsdem__finite(ob->radius) || !fsdem__finite3(ob->velocity))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (%s): non-finite geometry or velocity",
                           s->obst_count, name);
    memset(&o, 0, sizeof o);
    o.d = *ob;
    switch (ob->type) {
    case FSDEM_PIC_OBSTACLE_TYPE_BOX:
        for (b = 0; b < s->dim; ++b)
            if (!(fsdem__comp(ob->b, b) > fsdem__comp(ob->a, b)))
                return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (box): b.%c must exceed a.%c",
                                   s->obst_count, "xyz"[b], "xyz"[b]);
        o.box_lo = ob->a;
        o.box_hi = ob->b;
        break;
    case FSDEM_PIC_OBSTACLE_TYPE_SPHERE:
    case FSDEM_PIC_OBSTACLE_TYPE_CYLINDER:
        if (!(ob->radius > 0))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (%s): radius = %g must be > 0",
                               s->obst_count, name, (double)ob->radius);
        if (ob->type == FSDEM_PIC_OBSTACLE_TYPE_CYLINDER && s->dim == 3 && !(fsdem__norm(fsdem__sub(ob->b, ob->a)) > 0))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (cylinder): axis a-b has zero length",
                               s->obst_count);
        o.box_lo = fsdem__sub(ob->a, fsdem_v3(ob->radius, ob->radius, ob->radius));
        o.box_hi = fsdem__add(ob->a, fsdem_v3(ob->radius, ob->radius, ob->radius));
        if (ob->type == FSDEM_PIC_OBSTACLE_TYPE_CYLINDER && s->dim == 3)
            for (b = 0; b < 3; ++b) {
                fsdem_real lo = fsdem__comp(ob->b, b) - ob->radius, hi = fsdem__comp(ob->b, b) + ob->radius;
                if (b == 0) { if (lo < o.box_lo.x) o.box_lo.x = lo; if (hi > o.box_hi.x) o.box_hi.x = hi; }
                if (b == 1) { if (lo < o.box_lo.y) o.box_lo.y = lo; if (hi > o.box_hi.y) o.box_hi.y = hi; }
                if (b == 2) { if (lo < o.box_lo.z) o.box_lo.z = lo; if (hi > o.box_hi.z) o.box_hi.z = hi; }
            }
        break;
    case FSDEM_PIC_OBSTACLE_TYPE_POLYGON:
        if (s->dim != 2)
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (polygon): polygons are 2D only",
                               s->obst_count);
        if (!ob->vertices || ob->vertex_count < 3)
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (polygon): needs >= 3 vertices, has %d",
                               s->obst_count, ob->vertices ? ob->vertex_count : 0);
        o.box_lo = o.box_hi = ob->vertices[0];
        for (i = 0; i < ob->vertex_count; ++i) {
            fsdem_vec3 v = ob->vertices[i];
            if (!fsdem__finite3(v))
                return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (polygon): vertex %d is not finite",
                                   s->obst_count, i);
            if (v.x < o.box_lo.x) o.box_lo.x = v.x;
            if (v.y < o.box_lo.y) o.box_lo.y = v.y;
            if (v.x > o.box_hi.x) o.box_hi.x = v.x;
            if (v.y > o.box_hi.y) o.box_hi.y = v.y;
        }
        {
            /* shoelace area: coincident or collinear vertices enclose nothing */
            double area = 0;
            int j;
            for (i = 0, j = ob->vertex_count - 1; i < ob->vertex_count; j = i++)
                area += (double)ob->vertices[j].x * ob->vertices[i].y - (double)ob->vertices[i].x * ob->vertices[j].y;
            if (!(fabs(area) > 0) || !(fabs(area) < HUGE_VAL))
                return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                                   "fsdem_pic_add_obstacle: obstacle %d (polygon): the vertices enclose no area", s->obst_count);
        }
        break;
    case FSDEM_PIC_OBSTACLE_TYPE_SDF:
        if (!ob->sdf)
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_obstacle: obstacle %d (sdf): NULL callback", s->obst_count);
        for (i = 0; i < s->ncell; ++i) {
            /* a distance that is not a number would be ignored silently by the union below */
            const fsdem_vec3 c = fsdem__pic_cell_pos(s, i % s->n[0], i / s->n[0] % s->n[1], i / (s->n[0] * s->n[1]));
            fsdem_vec3 nrm;
            const fsdem_real dist = ob->sdf(ob->sdf_user, c, &nrm);
            if (!fsdem__finite(dist))
                return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                                   "fsdem_pic_add_obstacle: obstacle %d (sdf): the callback returned %g at (%g, %g, %g)",
                                   s->obst_count, (double)dist, (double)c.x, (double)c.y, (double)c.z);
        }
        o.box_lo = fsdem__sub(s->lo, fsdem_v3(1e30f, 1e30f, 1e30f));
        o.box_hi = fsdem__add(s->hi, fsdem_v3(1e30f, 1e30f, 1e30f));
        break;
    }
    if (ob->type != FSDEM_PIC_OBSTACLE_TYPE_SDF) {
        fsdem_real pad = 2 * s->dx;
        o.box_lo = fsdem__sub(o.box_lo, fsdem_v3(pad, pad, pad));
        o.box_hi = fsdem__add(o.box_hi, fsdem_v3(pad, pad, pad));
    }
    if (s->dim == 2) {
        o.box_lo.z = -1e30f;
        o.box_hi.z = 1e30f;
    }
    if (ob->type == FSDEM_PIC_OBSTACLE_TYPE_POLYGON) {
        o.verts = (fsdem_vec3 *)fsdem__pic_alloc(s, sizeof(fsdem_vec3) * (size_t)ob->vertex_count);
        if (!o.verts) return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_add_obstacle: out of memory");
        memcpy(o.verts, ob->vertices, sizeof(fsdem_vec3) * (size_t)ob->vertex_count);
        o.d.vertices = o.verts;
    }
    if (s->obst_count == s->obst_capacity) {
        int cap = s->obst_capacity ? 2 * s->obst_capacity : 4;
        fsdem__pic_obst *fresh = (fsdem__pic_obst *)fsdem__pic_alloc(s, sizeof(fsdem__pic_obst) * (size_t)cap);
        if (!fresh) {
            if (o.verts) fsdem__pic_release(s, o.verts, sizeof(fsdem_vec3) * (size_t)ob->vertex_count);
            return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_add_obstacle: out of memory");
        }
        if (s->obst) memcpy(fresh, s->obst, sizeof(fsdem__pic_obst) * (size_t)s->obst_count);
        fsdem__pic_release(s, s->obst, sizeof(fsdem__pic_obst) * (size_t)s->obst_capacity);
        s->obst = fresh;
        s->obst_capacity = cap;
    }
    /* Compute the new fractions into scratch arrays; commit only when some cell stays open. */
    s->obst[s->obst_count++] = o;
    for (b = 0; b < 3; ++b) {
        open[b] = s->ftmp[b];
        vel[b] = s->uold[b];
    }
    open_cells = fsdem__pic_static_faces(s, open, vel);
    if (open_cells == 0) {
        s->obst_count--;
        if (o.verts) fsdem__pic_release(s, o.verts, sizeof(fsdem_vec3) * (size_t)ob->vertex_count);
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pic_add_obstacle: obstacle %d (%s) covers the whole domain: no open cell is left", s->obst_count, name);
    }
    for (b = 0; b < s->dim; ++b) {
        memcpy(s->sopen[b], open[b], sizeof(fsdem_real) * (size_t)s->nface[b]);
        memcpy(s->svel[b], vel[b], sizeof(fsdem_real) * (size_t)s->nface[b]);
    }
    fsdem__pic_static_flags(s);
    fsdem__pic_compute_fref(s);
    s->cells_fresh = 0;
    inside = 0;
    for (i = 0; i < s->np; ++i) {
        s->pflag[i] = fsdem__pic_obst_min(s, s->px[i], NULL) <= 0;
        inside += s->pflag[i];
    }
    if (inside) {
        fsdem__pic_remove_marked(s);
        s->removed += inside;
    }
    fsdem__pic_refresh(s);
    if (id) *id = s->obst_count - 1;
    return fsdem__ok(&s->status);
}

/* ---- >>pic_particles : storage, seeding ---- */

/* Reallocates every particle array to `cap` (>= np). Leaves everything unchanged on failure. */
static fsdem_result fsdem__pic_set_capacity(fsdem_pic *s, int cap) {
    fsdem_vec3 *x, *v, *t, *c[3] = {NULL, NULL, NULL};
    int *cell, *idx, a, apic = s->desc.transfer == FSDEM_PIC_TRANSFER_APIC, ok = 1;
    unsigned char *flag;
    size_t n = (size_t)s->np, vb = sizeof(fsdem_vec3) * (size_t)cap;
    if (cap < s->np || cap > (1 << 29)) return FSDEM_ERR_OUT_OF_MEMORY;
    x = (fsdem_vec3 *)fsdem__pic_alloc(s, vb);
    v = (fsdem_vec3 *)fsdem__pic_alloc(s, vb);
    t = (fsdem_vec3 *)fsdem__pic_alloc(s, vb);
    for (a = 0; a < 3 && apic; ++a) {
        c[a] = (fsdem_vec3 *)fsdem__pic_alloc(s, vb);
        if (!c[a]) ok = 0;
    }
    cell = (int *)fsdem__pic_alloc(s, sizeof(int) * (size_t)cap);
    idx = (int *)fsdem__pic_alloc(s, sizeof(int) * (size_t)cap);
    flag = (unsigned char *)fsdem__pic_alloc(s, (size_t)cap);
    if (!x || !v || !t || !cell || !idx || !flag || !ok) {
        fsdem__pic_release(s, x, x ? vb : 0);
        fsdem__pic_release(s, v, v ? vb : 0);
        fsdem__pic_release(s, t, t ? vb : 0);
        for (a = 0; a < 3; ++a) fsdem__pic_release(s, c[a], c[a] ? vb : 0);
        fsdem__pic_release(s, cell, cell ? sizeof(int) * (size_t)cap : 0);
        fsdem__pic_release(s, idx, idx ? sizeof(int) * (size_t)cap : 0);
        fsdem__pic_release(s, flag, flag ? (size_t)cap : 0);
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    if (n) {
        memcpy(x, s->px, n * sizeof(fsdem_vec3));
        memcpy(v, s->pv, n * sizeof(fsdem_vec3));
        for (a = 0; a < 3 && apic; ++a) memcpy(c[a], s->pc[a], n * sizeof(fsdem_vec3));
    }
    memset(flag, 0, (size_t)cap);
    n = (size_t)s->np;
    fsdem__pic_free_particles(s);
    s->np = (int)n;
    s->px = x;
    s->pv = v;
    s->ptmp = t;
    for (a = 0; a < 3; ++a) s->pc[a] = c[a];
    s->pcell = cell;
    s->pidx = idx;
    s->pflag = flag;
    s->pcap = cap;
    return FSDEM_OK;
}

/* Makes room for `need` particles plus half as many again for reseeding and inflow. */
static fsdem_result fsdem__pic_make_room(fsdem_pic *s, long need) {
    long want = need + need / 2 + 64;
    if (need > (1 << 28)) return FSDEM_ERR_OUT_OF_MEMORY;
    if (need <= s->pcap && s->pcap >= need + need / 4) return FSDEM_OK;
    return fsdem__pic_set_capacity(s, (int)want);
}

fsdem_result fsdem_pic_reserve(fsdem_pic *s, int count) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (count < 0) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_reserve: count = %d < 0", count);
    if (count <= s->pcap) return fsdem__ok(&s->status);
    if (fsdem__pic_set_capacity(s, count) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_reserve: out of memory for %d particles", count);
    return fsdem__ok(&s->status);
}

/* Removes the particles whose pflag is set, keeping the order of the others. */
static void fsdem__pic_remove_marked(fsdem_pic *s) {
    int i, j = 0, a, apic = s->pc[0] != NULL;
    for (i = 0; i < s->np; ++i) {
        if (s->pflag[i]) continue;
        if (j != i) {
            s->px[j] = s->px[i];
            s->pv[j] = s->pv[i];
            for (a = 0; a < 3 && apic; ++a) s->pc[a][j] = s->pc[a][i];
        }
        ++j;
    }
    s->np = j;
    memset(s->pflag, 0, (size_t)s->pcap);
    s->cells_fresh = 0;
}

static int fsdem__pic_coord(const fsdem_pic *s, fsdem_real x, int axis) {
    fsdem_real t = (x - fsdem__comp(s->lo, axis)) * s->inv_dx;
    if (!(t > 0)) return 0; /* also NaN */
    return t < (fsdem_real)s->n[axis] ? (int)t : s->n[axis] - 1;
}

static int fsdem__pic_cell_of(const fsdem_pic *s, fsdem_vec3 p) {
    return fsdem__pic_cell(s, fsdem__pic_coord(s, p.x, 0), fsdem__pic_coord(s, p.y, 1),
                           s->dim == 3 ? fsdem__pic_coord(s, p.z, 2) : 0);
}

/* Is p a valid place for a particle: inside the grid box and outside the obstacles. */
static int fsdem__pic_open_at(const fsdem_pic *s, fsdem_vec3 p) {
    int b;
    for (b = 0; b < s->dim; ++b)
        if (!(fsdem__comp(p, b) > fsdem__comp(s->lo, b) && fsdem__comp(p, b) < fsdem__comp(s->hi, b))) return 0;
    if (s->cnear[fsdem__pic_cell_of(s, p)] && fsdem__pic_obst_min(s, p, NULL) <= 0) return 0;
    return 1;
}

/* Seed position q (0 .. ppc-1) in cell (i, j, k): stratified with jitter when ppc = sub^dim. */
static fsdem_vec3 fsdem__pic_seed_pos(fsdem_pic *s, int i, int j, int k, int q) {
    fsdem_real f[3];
    int b, idx[3];
    idx[0] = i;
    idx[1] = j;
    idx[2] = k;
    for (b = 0; b < 3; ++b) {
        if (b >= s->dim) {
            f[b] = 0;
            continue;
        }
        if (s->sub) {
            int sq = q % s->sub;
            q /= s->sub;
            f[b] = ((fsdem_real)sq + (fsdem_real)0.5 + s->desc.jitter * (fsdem__pic_rand(s) - (fsdem_real)0.5)) /
                   (fsdem_real)s->sub;
        } else {
            f[b] = fsdem__pic_rand(s);
        }
        f[b] = fsdem__comp(s->lo, b) + s->dx * ((fsdem_real)idx[b] + f[b]);
    }
    return fsdem_v3(f[0], f[1], s->dim == 3 ? f[2] : 0);
}

static fsdem_result fsdem__pic_fill(fsdem_pic *s, fsdem_vec3 lo, fsdem_vec3 hi, fsdem_sdf_fn region, void *user,
                                    fsdem_vec3 vel, int *added, const char *what) {
    int c0[3], c1[3], b, i, j, k, q, start = s->np;
    long cells = 1;
    for (b = 0; b < 3; ++b) {
        if (b >= s->dim) {
            c0[b] = 0;
            c1[b] = 0;
            continue;
        }
        c0[b] = fsdem__pic_coord(s, fsdem__comp(lo, b), b);
        c1[b] = fsdem__pic_coord(s, fsdem__comp(hi, b), b);
        cells *= c1[b] - c0[b] + 1;
    }
    if (fsdem__pic_make_room(s, (long)s->np + cells * s->ppc) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_%s: out of memory for %ld more particles", what,
                           cells * s->ppc);
    for (k = c0[2]; k <= c1[2]; ++k)
        for (j = c0[1]; j <= c1[1]; ++j)
            for (i = c0[0]; i <= c1[0]; ++i) {
                if (s->csolid[fsdem__pic_cell(s, i, j, k)]) continue;
                for (q = 0; q < s->ppc; ++q) {
                    fsdem_vec3 p = fsdem__pic_seed_pos(s, i, j, k, q);
                    int inside = 1;
                    for (b = 0; b < s->dim; ++b)
                        if (fsdem__comp(p, b) < fsdem__comp(lo, b) || fsdem__comp(p, b) >= fsdem__comp(hi, b)) inside = 0;
                    if (!inside || !fsdem__pic_open_at(s, p)) continue;
                    if (region) {
                        fsdem_vec3 nrm;
                        if (!(region(user, p, &nrm) > 0)) continue;
                    }
                    s->px[s->np] = p;
                    s->pv[s->np] = vel;
                    if (s->pc[0]) s->pc[0][s->np] = s->pc[1][s->np] = s->pc[2][s->np] = fsdem__zero3();
                    s->np++;
                }
            }
    if (added) *added = s->np - start;
    fsdem__pic_refresh(s);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_pic_fill_box(fsdem_pic *s, fsdem_vec3 lo, fsdem_vec3 hi, fsdem_vec3 velocity, int *added) {
    int b;
    if (added) *added = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!fsdem__finite3(lo) || !fsdem__finite3(hi) || !fsdem__within(velocity, FSDEM_MAX_SPEED))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pic_fill_box: a non-finite corner, or a velocity (%g, %g, %g) m/s that is not finite or above "
                           "FSDEM_MAX_SPEED (%g m/s)",
                           (double)velocity.x, (double)velocity.y, (double)velocity.z, (double)FSDEM_MAX_SPEED);
    for (b = 0; b < s->dim; ++b) {
        if (!(fsdem__comp(hi, b) > fsdem__comp(lo, b)))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_fill_box: hi.%c must exceed lo.%c", "xyz"[b], "xyz"[b]);
        if (fsdem__comp(lo, b) < fsdem__comp(s->lo, b)) lo = fsdem__pic_axis_shift(lo, b, fsdem__comp(s->lo, b) - fsdem__comp(lo, b));
        if (fsdem__comp(hi, b) > fsdem__comp(s->hi, b)) hi = fsdem__pic_axis_shift(hi, b, fsdem__comp(s->hi, b) - fsdem__comp(hi, b));
        if (!(fsdem__comp(hi, b) > fsdem__comp(lo, b)))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_fill_box: the box is outside the domain along %c",
                               "xyz"[b]);
    }
    return fsdem__pic_fill(s, lo, hi, NULL, NULL, velocity, added, "fill_box");
}

fsdem_result fsdem_pic_fill_sdf(fsdem_pic *s, fsdem_sdf_fn region, void *user, fsdem_vec3 velocity, int *added) {
    if (added) *added = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!region) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_fill_sdf: NULL region");
    if (!fsdem__within(velocity, FSDEM_MAX_SPEED))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_pic_fill_sdf: the velocity (%g, %g, %g) m/s must be finite and at most FSDEM_MAX_SPEED (%g m/s)",
                           (double)velocity.x, (double)velocity.y, (double)velocity.z, (double)FSDEM_MAX_SPEED);
    return fsdem__pic_fill(s, s->lo, s->hi, region, user, velocity, added, "fill_sdf");
}

fsdem_result fsdem_pic_add_particles(fsdem_pic *s, const fsdem_vec3 *x, const fsdem_vec3 *v, int count) {
    int i;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (count < 0 || (count > 0 && !x))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_add_particles: bad count %d or NULL positions", count);
    for (i = 0; i < count; ++i) {
        fsdem_vec3 p = x[i];
        if (!fsdem__finite3(p) || (v && !fsdem__within(v[i], FSDEM_MAX_SPEED)))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                               "fsdem_pic_add_particles: particle %d has a non-finite position, or a velocity that is not finite or "
                               "above FSDEM_MAX_SPEED (%g m/s)",
                               i, (double)FSDEM_MAX_SPEED);
        if (s->dim == 2) p.z = 0;
        if (!fsdem__pic_open_at(s, p))
            return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_DOMAIN,
                               "fsdem_pic_add_particles: particle %d at (%g, %g, %g) is outside the domain or inside a solid", i,
                               (double)p.x, (double)p.y, (double)p.z);
    }
    if (fsdem__pic_make_room(s, (long)s->np + count) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_add_particles: out of memory for %d particles",
                           s->np + count);
    for (i = 0; i < count; ++i) {
        s->px[s->np] = x[i];
        if (s->dim == 2) s->px[s->np].z = 0;
        s->pv[s->np] = v ? v[i] : fsdem__zero3();
        if (s->dim == 2) s->pv[s->np].z = 0;
        if (s->pc[0]) s->pc[0][s->np] = s->pc[1][s->np] = s->pc[2][s->np] = fsdem__zero3();
        s->np++;
    }
    fsdem__pic_refresh(s);
    return fsdem__ok(&s->status);
}

fsdem_pic_particles fsdem_pic_get_particles(fsdem_pic *s) {
    fsdem_pic_particles v;
    memset(&v, 0, sizeof v);
    if (!s) return v;
    v.count = s->np;
    v.dim = s->dim;
    v.volume = s->pvol;
    v.position = s->px;
    v.velocity = s->pv;
    return v;
}

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
                            fsdem_vec3 xf = fsdem__pic_face_pos(s, a, i, j, k);
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

/* Grid to particles. `du` holds u_new - u_old (FLIP) in uold. Returns the first particle with a
   non-finite velocity, or -1. */
static int fsdem__pic_g2p(fsdem_pic *s) {
    int a, p, q0, q1, q2, bad = -1, b;
    int quad = s->desc.kernel == FSDEM_PIC_KERNEL_QUADRATIC;
    fsdem_real ratio = s->desc.transfer == FSDEM_PIC_TRANSFER_FLIP ? s->desc.flip_ratio : 0;
    int apic = s->desc.transfer == FSDEM_PIC_TRANSFER_APIC;
    fsdem_real dfac = 4 * s->inv_dx * s->inv_dx;
    fsdem__kernel kw;
    for (p = 0; p < s->np; ++p) {
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
                                fsdem_vec3 d = fsdem__sub(fsdem__pic_face_pos(s, a, i, j, k), x);
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
        for (b = 0; b < s->dim; ++b)
            if (!fsdem__finite(vnew[b]) && bad < 0) bad = p;
    }
    return bad;
}

/* ---- >>pic_cells : effective faces, fluid fraction, level set, cell types ---- */

/* Reference fractions below this mark cells mostly inside obstacles (see fsdem__pic_fraction). */
#define FSDEM__PIC_FREF_RELIABLE ((fsdem_real)0.5)

/* Cell c is mostly inside static obstacles or moving solids (its particle count is unreliable). */
static int fsdem__pic_mostly_solid(const fsdem_pic *s, int c) {
    return (s->cnear[c] || s->cref[c] < 1) && s->fref[c] * s->cref[c] < FSDEM__PIC_FREF_RELIABLE;
}

/* E and us of every face from the static obstacles, the coupler arrays and the domain sides. */
static void fsdem__pic_effective_faces(fsdem_pic *s) {
    int a, i, j, k;
    for (a = 0; a < s->dim; ++a)
        for (k = 0; k < s->fn[a][2]; ++k)
            for (j = 0; j < s->fn[a][1]; ++j)
                for (i = 0; i < s->fn[a][0]; ++i) {
                    int f = fsdem__pic_face(s, a, i, j, k), coord = a == 0 ? i : a == 1 ? j : k;
                    fsdem_real so = s->sopen[a][f], co = s->copen[a][f];
                    if (co < 0) co = 0;
                    if (co > 1) co = 1;
                    if (coord == 0 || coord == s->n[a]) {
                        int side = 2 * a + (coord != 0);
                        fsdem_pic_bc bc = s->desc.boundary[side];
                        if (bc == FSDEM_PIC_BC_OUTFLOW) {
                            s->E[a][f] = so < co ? so : co;
                            s->us[a][f] = co < so ? s->cvel[a][f] : s->svel[a][f];
                        } else {
                            s->E[a][f] = 0;
                            s->us[a][f] = bc == FSDEM_PIC_BC_INFLOW ? fsdem__comp(s->desc.boundary_velocity[side], a) : 0;
                        }
                    } else {
                        s->E[a][f] = so < co ? so : co;
                        s->us[a][f] = co < so ? s->cvel[a][f] : s->svel[a][f];
                    }
                }
}

/* Fluid fraction of each cell from the particles (tent kernel at cell centres, seed 004 Eq. 7b,
   divided by the reference fraction) and the level set phi derived from it: for a plane surface
   at distance d from a cell centre the tent kernel collects 1 - (dx - d)^2 / (2 dx^2), which is
   inverted here, so phi is exact for plane surfaces and bounded by one cell. */
static void fsdem__pic_fraction(fsdem_pic *s) {
    int p, c, b, q0, q1, q2;
    fsdem_real inv_ppc = 1 / (fsdem_real)s->ppc;
    memset(s->frac, 0, sizeof(fsdem_real) * (size_t)s->ncell);
    for (p = 0; p < s->np; ++p) {
        fsdem__kernel kw;
        fsdem_real g[3];
        for (b = 0; b < 3; ++b)
            g[b] = b < s->dim ? (fsdem__comp(s->px[p], b) - fsdem__comp(s->lo, b)) * s->inv_dx - (fsdem_real)0.5 : 0;
        fsdem__kernel_weights(&kw, s->dim, g, s->n, 0);
        /* nodes outside the grid collect nothing (the reference fraction fref is truncated alike) */
        for (q2 = 0; q2 < kw.count[2]; ++q2) {
            int k = kw.lo[2] + q2;
            if (k < 0 || k >= s->n[2]) continue;
            for (q1 = 0; q1 < kw.count[1]; ++q1) {
                int j = kw.lo[1] + q1;
                if (j < 0 || j >= s->n[1]) continue;
                for (q0 = 0; q0 < kw.count[0]; ++q0) {
                    int i = kw.lo[0] + q0;
                    if (i < 0 || i >= s->n[0]) continue;
                    s->frac[fsdem__pic_cell(s, i, j, k)] += kw.w[0][q0] * kw.w[1][q1] * kw.w[2][q2];
                }
            }
        }
    }
    for (c = 0; c < s->ncell; ++c) {
        const fsdem_real ref = s->fref[c] * s->cref[c];
        fsdem_real f = ref > (fsdem_real)1e-3 ? s->frac[c] * inv_ppc / ref : 0;
        s->frac[c] = f;
        if (f >= 1) s->phi[c] = -s->dx;
        else if (f >= (fsdem_real)0.5) s->phi[c] = -s->dx * (1 - (fsdem_real)sqrt(2 * (1 - f)));
        else s->phi[c] = s->dx * (1 - (fsdem_real)sqrt(2 * f));
    }
    /* In cells mostly inside obstacles the count of a few particles over a small reference is
       unreliable (an isolated "air" cell under water would put p = 0 deep in the liquid); their
       phi is extended from the neighbours that are mostly open, as level sets are extended into
       solids (static obstacles and the coupler's moving ones alike). */
    {
        int i, j, k, a, sg, coord[3];
        for (k = 0; k < s->n[2]; ++k)
            for (j = 0; j < s->n[1]; ++j)
                for (i = 0; i < s->n[0]; ++i) {
                    fsdem_real sum = 0;
                    int cnt = 0;
                    c = fsdem__pic_cell(s, i, j, k);
                    if (!fsdem__pic_mostly_solid(s, c)) continue;
                    coord[0] = i;
                    coord[1] = j;
                    coord[2] = k;
                    for (a = 0; a < s->dim; ++a)
                        for (sg = -1; sg <= 1; sg += 2) {
                            int nc = coord[a] + sg, nb;
                            if (nc < 0 || nc >= s->n[a]) continue;
                            nb = c + sg * s->cstep[a];
                            if (s->fref[nb] * s->cref[nb] < FSDEM__PIC_FREF_RELIABLE) continue;
                            sum += s->phi[nb];
                            cnt++;
                        }
                    if (cnt) s->ctmp[c] = sum / (fsdem_real)cnt;
                    else s->ctmp[c] = s->phi[c];
                }
        for (c = 0; c < s->ncell; ++c)
            if (fsdem__pic_mostly_solid(s, c)) s->phi[c] = s->ctmp[c];
    }
}

/* Cell types from the effective faces and phi; returns the number of fluid cells. A cell is FLUID
   when phi < -theta_min dx: a surface through (or within theta_min dx of) a cell centre leaves
   that cell AIR whatever the rounding, so a flat surface is reconstructed the same in every column
   and the ghost-fluid fraction theta never needs clamping. */
static int fsdem__pic_types(fsdem_pic *s) {
    int a, i, j, k, c, fluid = 0;
    fsdem_real thresh = -s->desc.ghost_theta_min * s->dx;
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                int open = 0;
                c = fsdem__pic_cell(s, i, j, k);
                for (a = 0; a < s->dim && !open; ++a) {
                    int f = fsdem__pic_face(s, a, i, j, k);
                    if (s->E[a][f] > 0 || s->E[a][f + s->fstep[a][a]] > 0) open = 1;
                }
                if (!open) s->ctype[c] = FSDEM_STENCIL_CELL_SOLID;
                else if (!s->desc.free_surface || s->phi[c] < thresh) s->ctype[c] = FSDEM_STENCIL_CELL_FLUID;
                else s->ctype[c] = FSDEM_STENCIL_CELL_AIR;
                fluid += s->ctype[c] == FSDEM_STENCIL_CELL_FLUID;
            }
    s->fluid_cells = fluid;
    return fluid;
}

/* Effective faces, fluid fraction, level set and cell types of the current particles (after the
   particles or the obstacles changed outside a step), so views and statistics are current. */
static void fsdem__pic_refresh(fsdem_pic *s) {
    fsdem__pic_effective_faces(s);
    fsdem__pic_fraction(s);
    fsdem__pic_types(s);
    s->cells_fresh = 1;
}

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

/* Faces fully covered by a solid (E = 0) carry the solid's velocity. */
static void fsdem__pic_solid_faces(fsdem_pic *s, fsdem_real *const field[3], int zero) {
    int a, f;
    for (a = 0; a < s->dim; ++a)
        for (f = 0; f < s->nface[a]; ++f)
            if (s->E[a][f] <= 0) field[a][f] = zero ? 0 : s->us[a][f];
}

static int fsdem__pic_layers(const fsdem_pic *s) {
    return s->desc.extrapolation_layers > 0 ? s->desc.extrapolation_layers : (int)ceil(s->desc.cfl_max) + 2;
}

/* ---- >>pic_viscosity : implicit nu lap(u), one stencil solve per component ---- */

/* No-slip velocity of the closed face g of axis a in the viscous solve: a moving solid's velocity at
   the start of the step (fsdem_pic_coupling.viscous_velocity; the projection takes its velocity at
   the end, solid_velocity, which holds the step's gravity too), else the face's solid velocity. */
static fsdem_real fsdem__pic_noslip(const fsdem_pic *s, int a, int g) {
    return s->copen[a][g] < s->sopen[a][g] ? s->cvisc[a][g] : s->us[a][g];
}

/* The viscous force on the closed faces of component a after its solve (fsdem_pic_coupling.shear):
   each unknown face f next to a closed face g lost rho dx^dim (dt nu / dx^2)(u_f - us_g) of
   momentum to it over dt, the Dirichlet term of the solve, so the forces sum to the momentum the
   liquid lost to solids. */
static void fsdem__pic_shear(fsdem_pic *s, int a) {
    const int *fn = s->fn[a];
    const unsigned char *cell = s->vcell[a];
    fsdem_real c = s->desc.density * s->desc.viscosity * (s->dim == 3 ? s->dx : 1);
    int b, i, j, k, sg, coord[3];
    memset(s->shear[a], 0, sizeof(fsdem_real) * (size_t)s->nface[a]);
    for (k = 0; k < fn[2]; ++k)
        for (j = 0; j < fn[1]; ++j)
            for (i = 0; i < fn[0]; ++i) {
                int f = (k * fn[1] + j) * fn[0] + i;
                if (cell[f] != FSDEM_STENCIL_CELL_FLUID) continue;
                coord[0] = i;
                coord[1] = j;
                coord[2] = k;
                for (b = 0; b < s->dim; ++b)
                    for (sg = -1; sg <= 1; sg += 2) {
                        int nc = coord[b] + sg, g;
                        if (nc < 0 || nc >= fn[b]) continue;
                        g = f + sg * s->fstep[a][b];
                        if (cell[g] != FSDEM_STENCIL_CELL_FLUID && s->E[a][g] <= 0) s->shear[a][g] += c * (s->u[a][f] - fsdem__pic_noslip(s, a, g));
                    }
            }
}

/* Solves (I - dt nu L) u = u* on every face with E > 0 next to a fluid cell. The face grid of each
   component is a stencil grid of its own; the equation is divided by k = dt nu / dx^2:
       u/k + sum_nb (u - u_nb) + sum_dirichlet c (u - U) = u_star/k,
   with neighbours outside the unknowns either Dirichlet (a solid face at distance dx: c = 1, U its
   solid velocity; a no-slip or inflow side half a cell away: c = 2, U the side's velocity) or
   Neumann (air, slip sides, outflow). */
static fsdem_result fsdem__pic_viscosity(fsdem_pic *s, fsdem_real dt) {
    fsdem_real k = dt * s->desc.viscosity * s->inv_dx * s->inv_dx, inv_k = 1 / k;
    int a, b, i, j, kk;
    fsdem_result worst = FSDEM_OK;
    s->v_iters = 0;
    for (a = 0; a < s->dim; ++a) {
        const int *fn = s->fn[a];
        unsigned char *cell = s->vcell[a];
        fsdem_real *dg = s->ftmp[a], *rhs = s->wsum[a];
        fsdem_stencil st;
        fsdem_pcg_info info;
        fsdem_result r;
        int unknowns = 0;
        for (kk = 0; kk < fn[2]; ++kk)
            for (j = 0; j < fn[1]; ++j)
                for (i = 0; i < fn[0]; ++i) {
                    int f = (kk * fn[1] + j) * fn[0] + i, coord = a == 0 ? i : a == 1 ? j : kk, fluid = 0;
                    if (s->E[a][f] > 0) {
                        int cidx = fsdem__pic_cell(s, i < s->n[0] ? i : s->n[0] - 1, j < s->n[1] ? j : s->n[1] - 1,
                                                   kk < s->n[2] ? kk : s->n[2] - 1);
                        if (coord < s->n[a] && s->ctype[cidx] == FSDEM_STENCIL_CELL_FLUID) fluid = 1;
                        if (coord > 0 && s->ctype[cidx - (coord < s->n[a] ? s->cstep[a] : 0)] == FSDEM_STENCIL_CELL_FLUID) fluid = 1;
                    }
                    cell[f] = fluid ? FSDEM_STENCIL_CELL_FLUID : FSDEM_STENCIL_CELL_SOLID;
                    unknowns += fluid;
                }
        if (!unknowns) continue;
        for (kk = 0; kk < fn[2]; ++kk)
            for (j = 0; j < fn[1]; ++j)
                for (i = 0; i < fn[0]; ++i) {
                    int f = (kk * fn[1] + j) * fn[0] + i, coord[3], sg;
                    fsdem_real d = 0, r0 = 0;
                    if (cell[f] != FSDEM_STENCIL_CELL_FLUID) {
                        dg[f] = 0;
                        rhs[f] = 0;
                        continue;
                    }
                    coord[0] = i;
                    coord[1] = j;
                    coord[2] = kk;
                    for (b = 0; b < s->dim; ++b)
                        for (sg = -1; sg <= 1; sg += 2) {
                            int nc = coord[b] + sg, g;
                            if (nc < 0 || nc >= fn[b]) {
                                if (b != a) {
                                    int side = 2 * b + (sg > 0);
                                    fsdem_pic_bc bc = s->desc.boundary[side];
                                    if (bc == FSDEM_PIC_BC_NO_SLIP || bc == FSDEM_PIC_BC_INFLOW) {
                                        d += 2;
                                        r0 += 2 * fsdem__comp(s->desc.boundary_velocity[side], a);
                                    }
                                }
                                continue;
                            }
                            g = f + sg * s->fstep[a][b];
                            if (cell[g] == FSDEM_STENCIL_CELL_FLUID) continue;
                            if (s->E[a][g] <= 0) {
                                d += 1;
                                r0 += fsdem__pic_noslip(s, a, g);
                            }
                        }
                    dg[f] = inv_k + d;
                    rhs[f] = inv_k * s->u[a][f] + r0;
                }
        memset(&st, 0, sizeof st);
        st.dim = s->dim;
        for (b = 0; b < 3; ++b) st.n[b] = fn[b];
        st.cell = cell;
        for (b = 0; b < s->dim; ++b) st.face[b] = s->vface[a][b];
        st.diag = dg;
        r = fsdem_pcg_setup_stencil(s->pcg_v[a], &st);
        if (r == FSDEM_OK) r = fsdem_pcg_solve(s->pcg_v[a], rhs, s->u[a], &info);
        else info.iterations = 0;
        s->v_iters += info.iterations;
        fsdem__pic_shear(s, a);
        if (r != FSDEM_OK && worst == FSDEM_OK) {
            worst = r;
            fsdem__fail(&s->status, r, "fsdem_pic: viscous solve of component %c failed: %s", "xyz"[a],
                        fsdem_pcg_last_error(s->pcg_v[a]));
        }
    }
    return worst;
}

/* ---- >>pic_projection : pressure (and density) projection ---- */

static fsdem_real fsdem__pic_theta(const fsdem_pic *s, fsdem_real phi_in, fsdem_real phi_out) {
    fsdem_real t = phi_in < phi_out ? phi_in / (phi_in - phi_out) : 1;
    if (!(t >= s->desc.ghost_theta_min)) t = s->desc.ghost_theta_min;
    if (t > 1) t = 1;
    return t;
}

/* Fills s->diag with the ghost-fluid terms: a fluid cell whose neighbour across an open face is air
   (phi of the two gives the interface fraction theta) or an outflow side (p = 0 on the side,
   theta = 1/2) adds E (1/theta - 1) to the stencil's E (p_c - 0). Returns 1 when a cell has an
   air or outflow neighbour (a Dirichlet condition somewhere). */
static void fsdem__pic_ghost_diag(fsdem_pic *s) {
    int a, i, j, k, c, sg, coord[3];
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                fsdem_real d = 0;
                c = fsdem__pic_cell(s, i, j, k);
                if (s->ctype[c] != FSDEM_STENCIL_CELL_FLUID) {
                    s->diag[c] = 0;
                    continue;
                }
                coord[0] = i;
                coord[1] = j;
                coord[2] = k;
                for (a = 0; a < s->dim; ++a)
                    for (sg = 0; sg < 2; ++sg) {
                        int f = fsdem__pic_face(s, a, i, j, k) + sg * s->fstep[a][a], nc = coord[a] + (sg ? 1 : -1);
                        fsdem_real e = s->E[a][f];
                        if (e <= 0) continue;
                        if (nc < 0 || nc >= s->n[a]) {
                            d += e; /* outflow side: theta = 1/2 */
                            continue;
                        }
                        {
                            int nb = c + (sg ? 1 : -1) * s->cstep[a];
                            if (s->ctype[nb] == FSDEM_STENCIL_CELL_AIR)
                                d += e * (1 / fsdem__pic_theta(s, s->phi[c], s->phi[nb]) - 1);
                        }
                    }
                s->diag[c] = d;
            }
}

/* Gradient of a cell field `q` across face f of axis a (lower cell index cl, upper cu, -1 outside)
   with the ghost-fluid treatment; *ok = 0 when the face is not next to a fluid cell. */
static fsdem_real fsdem__pic_face_grad(const fsdem_pic *s, const fsdem_real *q, int cl, int cu, int *ok) {
    int fl = cl >= 0 && s->ctype[cl] == FSDEM_STENCIL_CELL_FLUID;
    int fu = cu >= 0 && s->ctype[cu] == FSDEM_STENCIL_CELL_FLUID;
    *ok = 1;
    if (fl && fu) return q[cu] - q[cl];
    if (fl) {
        if (cu < 0) return -2 * q[cl];
        if (s->ctype[cu] == FSDEM_STENCIL_CELL_AIR) return -q[cl] / fsdem__pic_theta(s, s->phi[cl], s->phi[cu]);
    } else if (fu) {
        if (cl < 0) return 2 * q[cu];
        if (s->ctype[cl] == FSDEM_STENCIL_CELL_AIR) return q[cu] / fsdem__pic_theta(s, s->phi[cu], s->phi[cl]);
    }
    *ok = 0;
    return 0;
}

/* Divergence of the face field u (with the solid fluxes) of cell (i, j, k), 1/s. */
static fsdem_real fsdem__pic_divergence(const fsdem_pic *s, fsdem_real *const u[3], int i, int j, int k) {
    fsdem_real sum = 0;
    int a;
    for (a = 0; a < s->dim; ++a) {
        int f = fsdem__pic_face(s, a, i, j, k), g = f + s->fstep[a][a];
        sum += s->E[a][g] * u[a][g] + (1 - s->E[a][g]) * s->us[a][g];
        sum -= s->E[a][f] * u[a][f] + (1 - s->E[a][f]) * s->us[a][f];
    }
    return sum * s->inv_dx;
}

static void fsdem__pic_stencil_view(const fsdem_pic *s, fsdem_stencil *st, int with_extra) {
    int a;
    memset(st, 0, sizeof *st);
    st->dim = s->dim;
    for (a = 0; a < 3; ++a) st->n[a] = s->n[a];
    st->cell = s->ctype;
    for (a = 0; a < s->dim; ++a) st->face[a] = s->E[a];
    st->diag = s->diag;
    if (with_extra) {
        st->extra = s->pressure_extra;
        st->extra_user = s->pressure_extra_user;
    }
}

/* Applies the gradient of the cell field q to the face field `out`: out -= scale grad q over faces
   next to fluid, which are marked valid (others invalid). */
static void fsdem__pic_apply_grad(fsdem_pic *s, const fsdem_real *q, fsdem_real scale, fsdem_real *const out[3]) {
    int a, i, j, k;
    for (a = 0; a < s->dim; ++a)
        for (k = 0; k < s->fn[a][2]; ++k)
            for (j = 0; j < s->fn[a][1]; ++j)
                for (i = 0; i < s->fn[a][0]; ++i) {
                    int f = fsdem__pic_face(s, a, i, j, k), coord = a == 0 ? i : a == 1 ? j : k, ok;
                    int cu = -1, cl = -1;
                    fsdem_real g;
                    s->fvalid[a][f] = 0;
                    if (s->E[a][f] <= 0) continue;
                    if (coord < s->n[a]) cu = fsdem__pic_cell(s, i, j, k);
                    if (coord > 0) cl = fsdem__pic_cell(s, i - (a == 0), j - (a == 1), k - (a == 2));
                    g = fsdem__pic_face_grad(s, q, cl, cu, &ok);
                    if (!ok) continue;
                    out[a][f] -= scale * g;
                    s->fvalid[a][f] = 1;
                }
}

/* Pressure projection: sum_f E_f (p_c - p_nb) (+ ghost-fluid diag, + coupler term) =
   -(rho dx^2 / dt) div(u*) (seed 000 Eq. 5; the solid fluxes of partly covered faces enter the
   divergence), then u -= dt/(rho dx) grad p on every face next to fluid. */
static fsdem_result fsdem__pic_project(fsdem_pic *s, fsdem_real dt) {
    fsdem_stencil st;
    fsdem_pcg_info info;
    fsdem_result r;
    fsdem_real scale = -s->desc.density * s->dx * s->dx / dt, d2 = 0, dmax = 0;
    int i, j, k, c;
    clock_t t0 = clock();
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                c = fsdem__pic_cell(s, i, j, k);
                if (s->ctype[c] != FSDEM_STENCIL_CELL_FLUID) {
                    s->rhs[c] = 0;
                    s->pres[c] = 0;
                    continue;
                }
                {
                    fsdem_real dv = fsdem__pic_divergence(s, s->u, i, j, k);
                    d2 += dv * dv;
                    s->rhs[c] = scale * dv + s->crhs[c];
                }
            }
    s->div_before = (fsdem_real)sqrt(d2);
    fsdem__pic_ghost_diag(s);
    fsdem__pic_stencil_view(s, &st, 1);
    r = fsdem_pcg_setup_stencil(s->pcg_p, &st);
    info.iterations = 0;
    info.residual = 0;
    if (r == FSDEM_OK && s->fluid_cells > 0) r = fsdem_pcg_solve(s->pcg_p, s->rhs, s->pres, &info);
    s->p_iters = info.iterations;
    s->p_res = info.residual;
    s->sec_pressure += (double)(clock() - t0) / CLOCKS_PER_SEC;
    if (r != FSDEM_OK)
        fsdem__fail(&s->status, r, "fsdem_pic: pressure solve failed (%d iterations, residual %g): %s", info.iterations,
                    (double)info.residual, fsdem_pcg_last_error(s->pcg_p));
    fsdem__pic_apply_grad(s, s->pres, dt / (s->desc.density * s->dx), s->u);
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                c = fsdem__pic_cell(s, i, j, k);
                if (s->ctype[c] == FSDEM_STENCIL_CELL_FLUID) {
                    fsdem_real dv = (fsdem_real)fabs(fsdem__pic_divergence(s, s->u, i, j, k));
                    if (dv > dmax) dmax = dv;
                }
            }
    s->max_div = dmax;
    return r;
}

/* ---- >>pic_advection : particle motion, solids, outflow ---- */

static void fsdem__pic_advect(fsdem_pic *s, fsdem_real dt) {
    int p;
    for (p = 0; p < s->np; ++p) {
        fsdem_vec3 x = s->px[p], k1, k2, k3;
        k1 = fsdem__pic_interp_vel(s, s->u, x);
        if (s->desc.advection_order == 2) {
            k2 = fsdem__pic_interp_vel(s, s->u, fsdem__madd(x, k1, dt / 2));
            x = fsdem__madd(x, k2, dt);
        } else { /* Ralston's third-order method */
            k2 = fsdem__pic_interp_vel(s, s->u, fsdem__madd(x, k1, dt / 2));
            k3 = fsdem__pic_interp_vel(s, s->u, fsdem__madd(x, k2, dt * (fsdem_real)0.75));
            x = fsdem__madd(x, fsdem__add(fsdem__add(fsdem__scale(k1, 2), fsdem__scale(k2, 3)), fsdem__scale(k3, 4)),
                            dt / 9);
        }
        if (s->dim == 2) x.z = 0;
        s->px[p] = x;
    }
}

/* Keeps particles in the open domain: those beyond an outflow side are marked for removal, the
   others are clamped inside the walls and pushed out of obstacles along the distance gradient
   (seed 004 Eq. 61). Returns the number marked. */
static int fsdem__pic_constrain(fsdem_pic *s) {
    fsdem_real eps = s->dx * (fsdem_real)1e-3;
    int p, b, marked = 0, it;
    for (p = 0; p < s->np; ++p) {
        fsdem_real xb[3];
        int gone = 0;
        xb[0] = s->px[p].x;
        xb[1] = s->px[p].y;
        xb[2] = s->px[p].z;
        for (b = 0; b < s->dim; ++b) {
            fsdem_real lo = fsdem__comp(s->lo, b), hi = fsdem__comp(s->hi, b);
            if (xb[b] < lo && s->desc.boundary[2 * b] == FSDEM_PIC_BC_OUTFLOW) gone = 1;
            if (xb[b] > hi && s->desc.boundary[2 * b + 1] == FSDEM_PIC_BC_OUTFLOW) gone = 1;
            if (!(xb[b] > lo + eps)) xb[b] = lo + eps;
            if (xb[b] > hi - eps) xb[b] = hi - eps;
        }
        if (gone) {
            s->pflag[p] = 1;
            ++marked;
            continue;
        }
        s->px[p] = fsdem_v3(xb[0], xb[1], xb[2]);
        if (s->obst_count && s->cnear[fsdem__pic_cell_of(s, s->px[p])]) {
            for (it = 0; it < 3; ++it) {
                fsdem_real d = fsdem__pic_obst_min(s, s->px[p], NULL);
                fsdem_vec3 nrm;
                if (d > eps) break;
                nrm = fsdem__pic_gradient(s, fsdem__pic_obst_dist, s->px[p]);
                s->px[p] = fsdem__madd(s->px[p], nrm, eps - d);
            }
            if (fsdem__pic_obst_min(s, s->px[p], NULL) <= 0 || !fsdem__pic_open_at(s, s->px[p])) {
                s->pflag[p] = 1;
                ++marked;
            }
        }
    }
    return marked;
}

/* Density projection of seed 004 §5.1 with alpha_s = 0 (target fraction 1): solve
   lap q = 1 - alpha_star (Eq. 12b with q = dt^2 p2 / rho; the ratio alpha_star/alpha_target clamped to [0.5, 1.5]) with
   q = 0 at the free surface (ghost fluid) and zero flux through solids (particles are already out
   of them, so the push-out term of Appendix B Eq. 64 vanishes), then move every particle by the
   interpolated dx = -grad q (Eq. 13), limited to one cell. Surface cells are only decompressed:
   their deficit is geometry, not a hole. */
static fsdem_result fsdem__pic_density_projection(fsdem_pic *s) {
    fsdem_stencil st;
    fsdem_pcg_info info;
    fsdem_result r;
    int i, j, k, c, a, sg, p, any = 0;
    fsdem_real dx2 = s->dx * s->dx;
    clock_t t0;
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                fsdem_real f, rr, ref;
                int surface = 0, coord[3];
                c = fsdem__pic_cell(s, i, j, k);
                s->ctmp[c] = 0;
                if (s->ctype[c] != FSDEM_STENCIL_CELL_FLUID) {
                    s->rhs[c] = 0;
                    continue;
                }
                coord[0] = i;
                coord[1] = j;
                coord[2] = k;
                for (a = 0; a < s->dim; ++a)
                    for (sg = 0; sg < 2; ++sg) {
                        int f = fsdem__pic_face(s, a, i, j, k) + sg * s->fstep[a][a], nc = coord[a] + (sg ? 1 : -1);
                        if (s->E[a][f] <= 0) continue;
                        if (nc < 0 || nc >= s->n[a] || s->ctype[c + (sg ? 1 : -1) * s->cstep[a]] == FSDEM_STENCIL_CELL_AIR)
                            surface = 1;
                    }
                f = s->frac[c];
                if (f < (fsdem_real)0.5) f = (fsdem_real)0.5;
                if (f > (fsdem_real)1.5) f = (fsdem_real)1.5;
                rr = 1 - f;
                if (surface && rr > 0) rr = 0;
                ref = s->fref[c] * s->cref[c];
                if (ref < FSDEM__PIC_FREF_RELIABLE) rr = 0; /* count unreliable (mostly solid) */
                if (rr != 0) any = 1;
                /* the volume to move is the deficit of the open part of the cell; the fluxes
                   through the faces are weighted by their open fractions E like the pressure's */
                s->rhs[c] = -dx2 * rr * (ref < 1 ? ref : 1);
            }
    s->d_iters = 0;
    if (!any) return FSDEM_OK;
    t0 = clock();
    fsdem__pic_ghost_diag(s);
    fsdem__pic_stencil_view(s, &st, 0);
    r = fsdem_pcg_setup_stencil(s->pcg_p, &st);
    info.iterations = 0;
    if (r == FSDEM_OK) {
        fsdem_pcg_set_tolerance(s->pcg_p, (fsdem_real)1e-4, s->desc.pressure_max_iterations);
        r = fsdem_pcg_solve(s->pcg_p, s->rhs, s->ctmp, &info);
        fsdem_pcg_set_tolerance(s->pcg_p, s->desc.pressure_tolerance, s->desc.pressure_max_iterations);
    }
    s->d_iters = info.iterations;
    s->sec_density += (double)(clock() - t0) / CLOCKS_PER_SEC;
    if (r != FSDEM_OK && r != FSDEM_ERR_NOT_CONVERGED) return r; /* keep the particles where they are */
    for (a = 0; a < s->dim; ++a) memset(s->uold[a], 0, sizeof(fsdem_real) * (size_t)s->nface[a]);
    fsdem__pic_apply_grad(s, s->ctmp, s->inv_dx, s->uold);
    for (p = 0; p < s->np; ++p) {
        fsdem_vec3 d = fsdem__pic_interp_vel(s, s->uold, s->px[p]);
        fsdem_real len = fsdem__norm(d);
        if (len > s->dx) d = fsdem__scale(d, s->dx / len);
        s->px[p] = fsdem__add(s->px[p], d);
    }
    return FSDEM_OK;
}

/* ---- >>pic_reseed : particle counts per cell ---- */

/* Counting sort of the particles by cell: cstart (ncell + 1 offsets), pidx (particle order). */
static void fsdem__pic_bin(fsdem_pic *s) {
    int p, c, sum = 0;
    memset(s->cstart, 0, sizeof(int) * (size_t)(s->ncell + 1));
    for (p = 0; p < s->np; ++p) {
        c = fsdem__pic_cell_of(s, s->px[p]);
        s->pcell[p] = c;
        s->cstart[c + 1]++;
    }
    for (c = 0; c < s->ncell; ++c) {
        sum += s->cstart[c + 1];
        s->cstart[c + 1] = sum;
    }
    for (p = 0; p < s->np; ++p) s->pidx[s->cstart[s->pcell[p]]++] = p;
    for (c = s->ncell; c > 0; --c) s->cstart[c] = s->cstart[c - 1];
    s->cstart[0] = 0;
}

/* Reorders the particle arrays by cell (cache locality of the transfers). */
static void fsdem__pic_sort(fsdem_pic *s) {
    fsdem_vec3 **arrays[5];
    int n = 2, a, p;
    fsdem__pic_bin(s);
    arrays[0] = &s->px;
    arrays[1] = &s->pv;
    if (s->pc[0]) {
        arrays[2] = &s->pc[0];
        arrays[3] = &s->pc[1];
        arrays[4] = &s->pc[2];
        n = 5;
    }
    for (a = 0; a < n; ++a) {
        fsdem_vec3 *src = *arrays[a], *dst = s->ptmp;
        for (p = 0; p < s->np; ++p) dst[p] = src[s->pidx[p]];
        s->ptmp = src;
        *arrays[a] = dst;
    }
}

static int fsdem__pic_append(fsdem_pic *s, fsdem_vec3 x, fsdem_vec3 v) {
    if (s->np >= s->pcap) {
        s->refused++;
        return 0;
    }
    if (s->dim == 2) {
        x.z = 0;
        v.z = 0;
    }
    s->px[s->np] = x;
    s->pv[s->np] = v;
    if (s->pc[0]) s->pc[0][s->np] = s->pc[1][s->np] = s->pc[2][s->np] = fsdem__zero3();
    s->pflag[s->np] = 0;
    s->np++;
    s->reseeded++;
    return 1;
}

/* Random open position in cell (i, j, k); 0 when none was found in a few tries. */
static int fsdem__pic_random_in_cell(fsdem_pic *s, int i, int j, int k, fsdem_vec3 *out) {
    int t;
    for (t = 0; t < 8; ++t) {
        /* one draw per statement: C leaves the order of a function's arguments unspecified, so
           draws in one argument list would give different runs with different compilers */
        const fsdem_real rx = fsdem__pic_rand(s), ry = fsdem__pic_rand(s), rz = s->dim == 3 ? fsdem__pic_rand(s) : 0;
        fsdem_vec3 p = fsdem_v3(s->lo.x + s->dx * ((fsdem_real)i + rx), s->lo.y + s->dx * ((fsdem_real)j + ry),
                                s->dim == 3 ? s->lo.z + s->dx * ((fsdem_real)k + rz) : 0);
        if (fsdem__pic_open_at(s, p)) {
            *out = p;
            return 1;
        }
    }
    return 0;
}

/* A particle that a crowded neighbour of cell (i, j, k) can give up for volume-neutral reseeding:
   from the cell of the 3^dim block around with the most particles, if it holds more than
   particles_per_cell (counting those already taken, in taken[]); -1 when there is none. */
static int fsdem__pic_donor(fsdem_pic *s, int i, int j, int k, int *taken) {
    int di, dj, dk, best = -1, best_count = s->ppc, zr = s->dim == 3 ? 1 : 0, maxp = s->desc.max_particles_per_cell;
    for (dk = -zr; dk <= zr; ++dk)
        for (dj = -1; dj <= 1; ++dj)
            for (di = -1; di <= 1; ++di) {
                int x = i + di, y = j + dj, z = k + dk, c, count;
                if (x < 0 || y < 0 || z < 0 || x >= s->n[0] || y >= s->n[1] || z >= s->n[2]) continue;
                c = fsdem__pic_cell(s, x, y, z);
                count = s->cstart[c + 1] - s->cstart[c];
                if (maxp > 0 && count > maxp) count = maxp; /* the rest is already removed */
                count -= taken[c];
                if (count > best_count) {
                    best_count = count;
                    best = c;
                }
            }
    if (best < 0) return -1;
    taken[best]++;
    return s->pidx[s->cstart[best] + best_count - 1];
}

/* Keeps the particle counts of the cells in range without changing the water volume (the particle
   count is the volume once the density projection has evened the particles out):
   - cells with more than max_particles_per_cell lose the excess;
   - interior fluid cells (no air neighbour) with fewer than min_particles_per_cell (times the part
     of the cell's kernel that solids leave open) and a fluid
     fraction below 1 get particles up to that minimum (with the grid velocity), each one taken
     from a crowded neighbour (more than particles_per_cell); without such a neighbour nothing is
     added (the density projection evens out the rest);
   - cells along inflow sides are topped up to particles_per_cell with the inflow velocity (the
     inflow brings volume in).
   Uses the cell types of the current positions. Returns 1 when particles changed. */
static int fsdem__pic_reseed(fsdem_pic *s) {
    int c, i, j, k, a, sg, q, maxp = s->desc.max_particles_per_cell, minp = s->desc.min_particles_per_cell;
    int removed = 0, moved = 0, *taken = s->fqueue; /* fqueue has >= ncell entries and is free here */
    int np0 = s->np;
    fsdem__pic_bin(s);
    memset(taken, 0, sizeof(int) * (size_t)s->ncell);
    if (maxp > 0)
        for (c = 0; c < s->ncell; ++c) {
            int count = s->cstart[c + 1] - s->cstart[c];
            if (count > maxp) {
                for (q = maxp; q < count; ++q) s->pflag[s->pidx[s->cstart[c] + q]] = 1;
                removed += count - maxp;
            }
        }
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                int count, coord[3], interior = 1, inflow = -1;
                c = fsdem__pic_cell(s, i, j, k);
                count = s->cstart[c + 1] - s->cstart[c] - taken[c];
                if (s->ctype[c] == FSDEM_STENCIL_CELL_SOLID || (maxp > 0 && count > maxp)) continue;
                coord[0] = i;
                coord[1] = j;
                coord[2] = k;
                for (a = 0; a < s->dim; ++a)
                    for (sg = 0; sg < 2; ++sg) {
                        int nc = coord[a] + (sg ? 1 : -1);
                        if (nc < 0 || nc >= s->n[a]) {
                            if (s->desc.boundary[2 * a + sg] == FSDEM_PIC_BC_INFLOW) inflow = 2 * a + sg;
                            continue;
                        }
                        if (s->ctype[c + (sg ? 1 : -1) * s->cstep[a]] == FSDEM_STENCIL_CELL_AIR) interior = 0;
                    }
                if (inflow >= 0) {
                    fsdem_vec3 x;
                    for (q = count; q < s->ppc; ++q)
                        if (fsdem__pic_random_in_cell(s, i, j, k, &x)) fsdem__pic_append(s, x, s->desc.boundary_velocity[inflow]);
                    continue;
                }
                /* the minimum is that of the cell's open part (the solids' share of the kernel aside) */
                if (minp > 0 && count < minp * s->fref[c] * s->cref[c] && interior && s->ctype[c] == FSDEM_STENCIL_CELL_FLUID &&
                    s->frac[c] < 1) {
                    fsdem_vec3 x;
                    for (q = count; q < minp; ++q) {
                        int donor;
                        if (!fsdem__pic_random_in_cell(s, i, j, k, &x)) break;
                        donor = fsdem__pic_donor(s, i, j, k, taken);
                        if (donor < 0) break;
                        if (!fsdem__pic_append(s, x, fsdem__pic_interp_vel(s, s->u, x))) {
                            break;
                        }
                        s->reseeded--; /* a move, not a new particle */
                        s->pflag[donor] = 1;
                        moved++;
                    }
                }
            }
    if (removed || moved) fsdem__pic_remove_marked(s);
    s->removed += removed;
    s->moved += moved;
    return removed || moved || s->np != np0;
}

/* ---- >>pic_step : time stepping ---- */

static fsdem_real fsdem__pic_umax(const fsdem_pic *s, int *who) {
    fsdem_real m2 = 0;
    int p, k, w = -1;
    for (p = 0; p < s->np; ++p) {
        fsdem_real v2 = fsdem__dot(s->pv[p], s->pv[p]);
        if (v2 > m2 || v2 != v2) {
            m2 = v2;
            w = p;
            if (v2 != v2) break;
        }
    }
    for (k = 0; k < 2 * s->dim; ++k) {
        fsdem_pic_bc bc = s->desc.boundary[k];
        if (bc == FSDEM_PIC_BC_NO_SLIP || bc == FSDEM_PIC_BC_INFLOW) {
            fsdem_real v2 = fsdem__dot(s->desc.boundary_velocity[k], s->desc.boundary_velocity[k]);
            if (v2 > m2) {
                m2 = v2;
                w = -2 - k;
            }
        }
    }
    if (who) *who = w;
    return (fsdem_real)sqrt(m2);
}

static fsdem_real fsdem__pic_dt_from(const fsdem_pic *s, fsdem_real umax) {
    fsdem_real speed = umax + (fsdem_real)sqrt(s->gmag * s->dx), dt = s->desc.dt_max;
    if (speed > 0 && s->desc.cfl * s->dx / speed < dt) dt = s->desc.cfl * s->dx / speed;
    return dt;
}

fsdem_result fsdem_pic_stable_dt(const fsdem_pic *s, fsdem_real *dt) {
    int who;
    fsdem_real umax;
    if (!s || !dt) return FSDEM_ERR_INVALID_ARG;
    umax = fsdem__pic_umax(s, &who);
    if (!fsdem__finite(umax))
        return fsdem__fail((fsdem__status *)&s->status, FSDEM_ERR_NAN, "fsdem_pic_stable_dt: particle %d has a non-finite velocity",
                           who);
    *dt = fsdem__pic_dt_from(s, umax);
    return fsdem__ok((fsdem__status *)&s->status);
}

double fsdem_pic_time(const fsdem_pic *s) { return s ? s->time : 0; }

fsdem_pic_desc fsdem_pic_get_desc(const fsdem_pic *s) {
    fsdem_pic_desc d;
    if (!s) {
        memset(&d, 0, sizeof d);
        return d;
    }
    d = s->desc;
    d.domain_max = s->hi;
    if (s->dim == 2) d.domain_max.z = d.domain_min.z;
    return d;
}

static fsdem_result fsdem__pic_do_step(fsdem_pic *s, fsdem_real dt) {
    fsdem_result r, worst = FSDEM_OK;
    int a, f, bad, layers = fsdem__pic_layers(s);
    fsdem_real umax = 0;
    clock_t t0 = clock();
    const double time0 = s->time;
    fsdem__ok(&s->status);
    fsdem__series_begin(&s->gauges.series);

    /* 1. particles to grid, cells, extrapolation, FLIP reference */
    fsdem__pic_effective_faces(s);
    if (!s->cells_fresh) fsdem__pic_fraction(s);
    fsdem__pic_types(s);
    fsdem__pic_p2g(s);
    fsdem__pic_extrapolate(s, s->u, layers);
    fsdem__pic_solid_faces(s, s->u, 0);
    for (a = 0; a < s->dim; ++a) memcpy(s->uold[a], s->u[a], sizeof(fsdem_real) * (size_t)s->nface[a]);

    /* 2. implicit viscosity, then body forces and coupler accelerations: in that order water at
       rest under gravity is not sheared against solids (the viscous solve would otherwise act on
       g dt, which the projection removes, and leave a spurious force on every wall and body) */
    if (s->desc.viscosity > 0) {
        r = fsdem__pic_viscosity(s, dt);
        if (r != FSDEM_OK && worst == FSDEM_OK) worst = r;
    }
    for (a = 0; a < s->dim; ++a) {
        fsdem_real g = fsdem__comp(s->desc.gravity, a) * dt;
        for (f = 0; f < s->nface[a]; ++f) s->u[a][f] += g + dt * s->cacc[a][f];
    }

    /* 3. pressure projection */
    r = fsdem__pic_project(s, dt);
    if (r != FSDEM_OK && worst == FSDEM_OK) worst = r;
    for (a = 0; a < s->dim; ++a)
        for (f = 0; f < s->nface[a]; ++f)
            if (s->fvalid[a][f] && (fsdem_real)fabs(s->u[a][f]) > umax) umax = (fsdem_real)fabs(s->u[a][f]);
    fsdem__pic_extrapolate(s, s->u, layers);
    fsdem__pic_solid_faces(s, s->u, 0);

    /* 4. grid to particles */
    for (a = 0; a < s->dim; ++a)
        for (f = 0; f < s->nface[a]; ++f) s->uold[a][f] = s->u[a][f] - s->uold[a][f];
    bad = fsdem__pic_g2p(s);

    /* 5. advection, solids and outflow, density projection */
    fsdem__pic_advect(s, dt);
    if (fsdem__pic_constrain(s)) {
        int before = s->np;
        fsdem__pic_remove_marked(s);
        s->removed += before - s->np;
    }
    if (s->desc.density_projection) {
        fsdem__pic_fraction(s);
        fsdem__pic_types(s);
        r = fsdem__pic_density_projection(s);
        if (r != FSDEM_OK && worst == FSDEM_OK)
            worst = fsdem__fail(&s->status, r, "fsdem_pic: density projection failed: %s", fsdem_pcg_last_error(s->pcg_p));
        if (fsdem__pic_constrain(s)) {
            int before = s->np;
            fsdem__pic_remove_marked(s);
            s->removed += before - s->np;
        }
    }

    /* 6. reseeding, cell order, cells of the final positions (for diagnostics) */
    fsdem__pic_fraction(s);
    fsdem__pic_types(s);
    if (fsdem__pic_reseed(s)) {
        fsdem__pic_fraction(s);
        fsdem__pic_types(s);
    }
    if ((s->steps & 7) == 0) fsdem__pic_sort(s);
    s->cells_fresh = 1;

    s->time += dt;
    s->dt_last = dt;
    s->steps++;
    s->sec_total += (double)(clock() - t0) / CLOCKS_PER_SEC;
    if (bad >= 0 && worst == FSDEM_OK)
        worst = fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pic: step %lld: particle %d has a non-finite velocity", s->steps, bad);
    if (worst == FSDEM_OK && umax * dt * s->inv_dx > s->desc.cfl_max)
        worst = fsdem__fail(&s->status, FSDEM_ERR_CFL,
                            "fsdem_pic: step %lld: the projected grid velocity %g m/s moves %g cells in dt = %g s (cfl_max %g)",
                            s->steps, (double)umax, (double)(umax * dt * s->inv_dx), (double)dt, (double)s->desc.cfl_max);
    if (worst == FSDEM_OK && fsdem__series_step(&s->gauges.series, time0, s->time) != FSDEM_OK)
        worst = fsdem__fail(&s->status, FSDEM_ERR_IO, "fsdem_pic: could not write the gauge file");
    return worst;
}

fsdem_result fsdem_pic_step_dt(fsdem_pic *s, fsdem_real dt) {
    int who;
    fsdem_real umax, cfl;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_step_dt: dt = %g s must be > 0 and finite", (double)dt);
    umax = fsdem__pic_umax(s, &who);
    if (!fsdem__finite(umax))
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pic: particle %d has a non-finite velocity", who);
    cfl = umax * dt * s->inv_dx;
    if (cfl > s->desc.cfl_max) {
        if (who >= 0)
            return fsdem__fail(&s->status, FSDEM_ERR_CFL,
                               "fsdem_pic_step_dt: dt = %g s gives CFL %g > cfl_max %g (particle %d at %g m/s; dt <= %g s)", (double)dt,
                               (double)cfl, (double)s->desc.cfl_max, who, (double)umax,
                               (double)(s->desc.cfl_max * s->dx / umax));
        return fsdem__fail(&s->status, FSDEM_ERR_CFL, "fsdem_pic_step_dt: dt = %g s gives CFL %g > cfl_max %g (%s side velocity %g m/s)",
                           (double)dt, (double)cfl, (double)s->desc.cfl_max, fsdem__pic_side_name(-2 - who), (double)umax);
    }
    return fsdem__pic_do_step(s, dt);
}

fsdem_result fsdem_pic_step(fsdem_pic *s) {
    int who;
    fsdem_real umax;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    umax = fsdem__pic_umax(s, &who);
    if (!fsdem__finite(umax))
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pic: particle %d has a non-finite velocity", who);
    return fsdem__pic_do_step(s, fsdem__pic_dt_from(s, umax));
}

fsdem_result fsdem_pic_advance(fsdem_pic *s, fsdem_real duration, long long *steps) {
    double end;
    long long n = 0;
    fsdem_result r = FSDEM_OK;
    if (steps) *steps = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!(duration >= 0) || !fsdem__finite(duration))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_advance: duration = %g s must be >= 0", (double)duration);
    end = s->time + (double)duration;
    while (s->time < end - 1e-12 * (end > 1 ? end : 1)) {
        int who;
        fsdem_real umax = fsdem__pic_umax(s, &who), dt;
        if (!fsdem__finite(umax)) {
            r = fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_pic_advance: particle %d has a non-finite velocity", who);
            break;
        }
        dt = fsdem__pic_dt_from(s, umax);
        if (s->time + dt > end) dt = (fsdem_real)(end - s->time);
        else if (s->time + 1.5 * dt > end) dt = (fsdem_real)((end - s->time) / 2);
        r = fsdem__pic_do_step(s, dt);
        ++n;
        if (r != FSDEM_OK) break;
    }
    if (steps) *steps = n;
    return r;
}

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

fsdem_pic_coupling fsdem_pic_get_coupling(fsdem_pic *s) {
    fsdem_pic_coupling c;
    if (s) {
        s->cells_fresh = 0; /* the caller may change the references: the next step recounts the cells */
        return s->coupling;
    }
    memset(&c, 0, sizeof c);
    return c;
}

fsdem_result fsdem_pic_set_pressure_extra(fsdem_pic *s, fsdem_operator_fn fn, void *user) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    s->pressure_extra = fn;
    s->pressure_extra_user = fn ? user : NULL;
    return fsdem__ok(&s->status);
}

static int fsdem__pic_fluid_cell(const fsdem_pic *s, int c) { return c >= 0 && s->ctype[c] == FSDEM_STENCIL_CELL_FLUID; }

/* The cells below (lower index along a) and above face (i, j, k) of axis a; -1 off the grid. */
static void fsdem__pic_face_cells(const fsdem_pic *s, int a, const int f3[3], int *below, int *above) {
    const int coord = f3[a];
    *above = coord < s->n[a] ? fsdem__pic_cell(s, f3[0], f3[1], f3[2]) : -1;
    *below = coord > 0 ? fsdem__pic_cell(s, f3[0] - (a == 0), f3[1] - (a == 1), f3[2] - (a == 2)) : -1;
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
                    const int c = fsdem__pic_cell(s, kw.idx[0][q0], kw.idx[1][q1], kw.idx[2][q2]);
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
                const int f = fsdem__pic_face(s, a, f3[0], f3[1], f3[2]);
                fsdem_vec3 xf = fsdem__pic_face_pos(s, a, f3[0], f3[1], f3[2]);
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
        c = fsdem__pic_cell(s, c3[0], c3[1], c3[2]);
        if (s->ctype[c] == FSDEM_STENCIL_CELL_SOLID || !(s->phi[c] < 0)) continue;
        /* the centre of cell c is in water; the surface is where phi crosses 0 towards the cell above */
        if (k == top) return up > 0 ? fsdem__comp(s->hi, u) : fsdem__comp(s->lo, u);
        c3[u] = k - step;
        above = fsdem__pic_cell(s, c3[0], c3[1], c3[2]);
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
            const fsdem_vec3 x = fsdem__pic_cell_pos(s, c % s->n[0], c / s->n[0] % s->n[1], c / (s->n[0] * s->n[1]));
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
                           s->pres[fsdem__pic_cell(s, kw.idx[0][q0], kw.idx[1][q1], kw.idx[2][q2])];
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

fsdem_result fsdem_pic_gauges_close(fsdem_pic *s) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__gauges_close(&s->gauges, &s->status, &s->allocator, "fsdem_pic_gauges_close");
}

fsdem_pic_stats fsdem_pic_get_stats(const fsdem_pic *s) {
    fsdem_pic_stats st;
    int c, p, a;
    double vol = 0, ke = 0, cellv;
    memset(&st, 0, sizeof st);
    if (!s) return st;
    cellv = pow((double)s->dx, (double)s->dim);
    for (c = 0; c < s->ncell; ++c) {
        double f;
        if (s->ctype[c] == FSDEM_STENCIL_CELL_SOLID) continue;
        if (!s->desc.free_surface) {
            vol += 1;
            continue;
        }
        f = 0.5 - (double)s->phi[c] * (double)s->inv_dx;
        vol += f < 0 ? 0 : f > 1 ? 1 : f;
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

/* ---- >>pic_output : CSV (VTK XML: >>impl_io) ---- */

fsdem_result fsdem_pic_write_particles_csv(const fsdem_pic *s, const char *path) {
    FILE *fp;
    int p, bad;
    if (!s || !path) return FSDEM_ERR_INVALID_ARG;
    if (!(fp = fopen(path, "w"))) return FSDEM_ERR_IO;
    fprintf(fp, "x,y,z,vx,vy,vz\n");
    for (p = 0; p < s->np; ++p)
        fprintf(fp, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", (double)s->px[p].x, (double)s->px[p].y, (double)s->px[p].z,
                (double)s->pv[p].x, (double)s->pv[p].y, (double)s->pv[p].z);
    bad = ferror(fp);
    return (fclose(fp) != 0 || bad) ? FSDEM_ERR_IO : FSDEM_OK;
}

/* Cell-centred velocity: mean of the two faces along each axis. */
static fsdem_vec3 fsdem__pic_cell_velocity(const fsdem_pic *s, int i, int j, int k) {
    fsdem_real v[3] = {0, 0, 0};
    int a;
    for (a = 0; a < s->dim; ++a) {
        int f = fsdem__pic_face(s, a, i, j, k);
        v[a] = (s->u[a][f] + s->u[a][f + s->fstep[a][a]]) / 2;
    }
    return fsdem_v3(v[0], v[1], v[2]);
}

fsdem_result fsdem_pic_write_grid_csv(const fsdem_pic *s, const char *path) {
    FILE *fp;
    int i, j, k, bad;
    if (!s || !path) return FSDEM_ERR_INVALID_ARG;
    if (!(fp = fopen(path, "w"))) return FSDEM_ERR_IO;
    fprintf(fp, "i,j,k,x,y,z,type,p,phi,fraction,u,v,w\n");
    for (k = 0; k < s->n[2]; ++k)
        for (j = 0; j < s->n[1]; ++j)
            for (i = 0; i < s->n[0]; ++i) {
                int c = fsdem__pic_cell(s, i, j, k);
                fsdem_vec3 x = fsdem__pic_cell_pos(s, i, j, k), v = fsdem__pic_cell_velocity(s, i, j, k);
                fprintf(fp, "%d,%d,%d,%.9g,%.9g,%.9g,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", i, j, k, (double)x.x, (double)x.y,
                        (double)x.z, (int)s->ctype[c], (double)s->pres[c], (double)s->phi[c], (double)s->frac[c], (double)v.x,
                        (double)v.y, (double)v.z);
            }
    bad = ferror(fp);
    return (fclose(fp) != 0 || bad) ? FSDEM_ERR_IO : FSDEM_OK;
}

/* ===== >>impl_swe : shallow-water solver ========================================================== */

/* Contents: the scheme below and the object; >>swe_desc (defaults, validation), >>swe_object
   (creation, series, state, coupling), >>swe_sources (boundaries, friction, rain, blocked cells,
   point sources), >>swe_riemann (face fluxes), >>swe_row (reconstruction,
   predictor and x faces of a row), >>swe_step (y faces, repair, stable dt, stepping), >>swe_diag
   (diagnostics, output, gauges, bed SDF). */

/* Scheme (one step of dt, >>swe_row and >>swe_step):
     1. MUSCL reconstruction of eta, h, u, v per cell with the limiter (slopes per cell width); z_b at
        a face is eta_face - h_face, so the bed is never reconstructed on its own. Ghost cells mirror
        the cell at a wall; at other sides they copy h, u, v and extrapolate the bed linearly.
     2. Hancock predictor: each cell's face values are advanced by dt/2 with the flux difference of
        its own faces plus sources (the pressure/bed-slope pair in the form g h (eta_E - eta_W), which
        vanishes for a flat surface over any bed) and half a step of friction. Skipped in a cell
        where it would make a face depth negative (counted in stats.predictor_fallbacks).
     3. Faces: non-negative depth reconstruction with Liang's local bed modification,
            z_f = max(z_L, z_R), m = min(eta_L, eta_R);
            if z_f <= m: h*_s = eta_s - z_f, eta*_s = eta_s                      (plain)
            else:        h*_s = max(0, eta_s - z_f), eta*_s = h*_s + m, z_f -> m (dz = z_f - m)
        then HLL with the two-rarefaction wave speeds, or, when one side is dry, the exact Godunov
        flux of the rarefaction into dry bed (sharper wet fronts than HLL's estimate).
     4. Update. Mass uses the single face flux, so volume is conserved to rounding. Normal momentum
        uses the algebraically identical "side" form of the pre-balanced scheme (seed 003 Eq. 2 with
        the source -g eta_bar dz_b/dx of Liang and Marche 2009): the face flux seen from side s is
            F = A_s + g h*_s^2/2 + D_s,  D_L = s_L (s_R dU - dF)/(s_R - s_L),  D_R = s_R (s_L dU - dF)/(s_R - s_L)
        (A = advective part), and the cell's pressure flux difference plus bed-slope source combine to
            -(g/2) (h*_E + h*_W) (eta*_E - eta*_W) / dx,
        which is exactly zero when the cell's own face surfaces are equal: a lake at rest stays at rest
        bit for bit, also against dry islands (there eta*_s = m = the lake's surface).
     5. Point sources, rain, momentum source S_p (explicit), eddy viscosity (explicit, time n), Manning
        friction (backward Euler, exact: |q| = 2|q*| / (1 + sqrt(1 + 4 dt C |q*|)), C = g n^2 / h^(7/3)),
        which never reverses the flow, is stable at any depth and keeps uniform flow at normal depth.
     6. Depths stay non-negative: TVD reconstruction, the predictor fallback, and a time step that also
        bounds the velocity gained within the step (fsdem_swe_stable_dt). Should a depth still come out
        negative, the deficit is taken from the wet neighbours (stats.clipped_volume counts any part
        they cannot give; zero in every test and validation case).
   Thin layers: cells shallower than dry_depth carry no momentum; face depths below 1e-9 dry_depth
   carry no flux and unit discharges below 1e-100 m^2/s are set to zero, which stops the scheme's
   geometrically decaying leaks ahead of fronts and waves before they become subnormal numbers.
   Sweeps: rows are processed bottom to top with ring buffers of three rows of primitive values and two
   rows of predicted face states, so each state array is read once and written once per step; the
   row kernel is specialised per limiter. Single-threaded (no OpenMP in this section). */

/* Work data of one cell of a row in flight (2D): the predicted states at its north and south faces
   and its increments from the x faces. Kept together so the y-face sweep streams one array. */
typedef struct fsdem__swe_rowcell {
    fsdem_real n[4];   /* north face: eta, h, v (normal), u (tangential) */
    fsdem_real s[4];   /* south face */
    fsdem_real acc[3]; /* eta, uh, vh increments from the x faces (and viscosity) */
    fsdem_real pad;
} fsdem__swe_rowcell;

/* South-face fluxes of a cell, kept until its north face is computed on the next row. */
typedef struct fsdem__swe_sface {
    fsdem_real mass, a, t, h, e, pad;
} fsdem__swe_sface;

/* The row kernel is instantiated once per limiter and dimension (FSDEM__FORCE_INLINE) so that its
   inner loop has neither a limiter switch nor 2D branches in 1D. */

/* m^2/s: unit discharges below this are set to zero (no physical meaning; see fsdem__swe_finish) */
#define FSDEM__SWE_QTINY ((fsdem_real)(sizeof(fsdem_real) < sizeof(double) ? 1e-12 : 1e-100))

typedef struct fsdem__swe_bnd {
    fsdem_swe_bc type;
    fsdem_real value;
    fsdem_real *t, *v; /* owned series, n points */
    int n;
} fsdem__swe_bnd;

typedef struct fsdem__swe_src {
    fsdem_real discharge;
    fsdem_real *t, *v;
    int n, cell, id, active;
} fsdem__swe_src;

struct fsdem_swe {
    fsdem_swe_desc desc; /* bed, depth and the boundary series pointers are not kept */
    fsdem__status status;
    fsdem_allocator allocator;
    int dim, nx, ny, n;
    fsdem_real dx, dy, area, g, tiny;
    double time;
    fsdem_real dt_last;
    long long steps, fallbacks;
    fsdem_real max_wave;  /* 1/s, max over wet cells of (|u|+c)/dx + (|v|+c)/dy of the current state */
    fsdem_real max_accel; /* 1/s^2, max over wet cells of g (|deta/dx|/dx + |deta/dy|/dy), minmod slopes */
    fsdem_real max_speed, max_depth;
    int wet_cells;
    fsdem_real vol_boundary, vol_source, vol_clipped;
    fsdem_real rain;

    /* state, structure of arrays */
    fsdem_real *block; /* one allocation holding the state and the work rows */
    size_t block_bytes;
    fsdem_real *eta, *qx, *qy, *bed, *sx, *sy;
    fsdem_real *manning; /* NULL: uniform desc.manning */
    unsigned char *blocked; /* n flags (1: solid cell), NULL when no cell is blocked */
    int blocked_count;
    int sources_used;

    /* work rows */
    int slots;            /* primitive row slots: 3 in 2D, 1 in 1D */
    fsdem_real *prim;     /* slots x 4 x (nx + 2): eta, h, u, v with one ghost cell at each end */
    fsdem__swe_rowcell *rows; /* 2D: 2 x nx, ring of the last two rows (>>swe_step) */
    fsdem__swe_sface *south;  /* 2D: nx south-face data of the row in flight */

    fsdem__swe_bnd bnd[4];
    fsdem_real bvalue[4]; /* boundary values at the middle of the step in flight */

    fsdem__swe_src *src;
    int src_count, src_capacity, src_next_id;

    fsdem_real *gauge; /* x, y of each gauge */
    int gauge_count, gauge_capacity;
    fsdem__series gauges; /* the gauge file, h, eta, u, v per gauge */
};

/* ---- >>swe_desc : defaults and validation ---- */

fsdem_swe_desc fsdem_swe_desc_default(int dim) {
    fsdem_swe_desc d;
    int k;
    memset(&d, 0, sizeof d);
    d.dim = dim;
    d.nx = 100;
    d.ny = dim == 2 ? 100 : 1;
    d.x_min = 0;
    d.x_max = 1;
    d.y_min = 0;
    d.y_max = 1;
    d.width = 1;
    d.gravity = fsdem_v3(0, 0, (fsdem_real)-9.81);
    d.density = 1000;
    d.cfl = (fsdem_real)0.5;
    d.dt_max = 1;
    d.order = 2;
    d.limiter = FSDEM_SWE_LIMITER_MINMOD;
    d.dry_depth = (fsdem_real)1e-6;
    d.manning = 0;
    d.eddy_viscosity = 0;
    d.rain_rate = 0;
    for (k = 0; k < 4; ++k) d.boundary[k].type = FSDEM_SWE_BC_WALL;
    return d;
}

static const char *fsdem__swe_side_name(int side) {
    static const char *names[4] = {"XMIN", "XMAX", "YMIN", "YMAX"};
    return side >= 0 && side < 4 ? names[side] : "?";
}

/* A time series: increasing finite times, values finite within +-bound (in [0, bound] when
   non_negative). */
static fsdem_result fsdem__swe_series_check(const fsdem_real *t, const fsdem_real *v, int n, int non_negative, fsdem_real bound,
                                            const char *what, char *msg, size_t size) {
    int k;
    if (n == 0 && !t && !v) return FSDEM_OK;
    if (n < 1 || !t || !v)
        return fsdem__reject(msg, size, "%s: a series needs series_count >= 1 and both arrays (got %d points)",
                             what, n);
    for (k = 0; k < n; ++k) {
        if (!fsdem__finite(t[k]) || !fsdem__finite(v[k]))
            return fsdem__reject(msg, size, "%s: series point %d is not finite", what, k);
        if (k > 0 && !(t[k] > t[k - 1]))
            return fsdem__reject(msg, size, "%s: series times must increase strictly (point %d: %g after %g s)",
                                 what, k, (double)t[k], (double)t[k - 1]);
        if (!(v[k] >= (non_negative ? 0 : -bound) && v[k] <= bound))
            return fsdem__reject(msg, size, "%s: series value %d must be in [%g, %g] (got %g)", what, k,
                                 non_negative ? 0.0 : -(double)bound, (double)bound, (double)v[k]);
    }
    return FSDEM_OK;
}

static fsdem_result fsdem__swe_boundary_check(const fsdem_swe_boundary *b, int side, char *msg, size_t size) {
    char what[64];
    snprintf(what, sizeof what, "boundary[%s]", fsdem__swe_side_name(side));
    if (!b) return fsdem__reject(msg, size, "%s is NULL", what);
    if (b->type != FSDEM_SWE_BC_WALL && b->type != FSDEM_SWE_BC_TRANSMISSIVE && b->type != FSDEM_SWE_BC_DISCHARGE &&
        b->type != FSDEM_SWE_BC_STAGE)
        return fsdem__reject(msg, size, "%s.type is not a fsdem_swe_bc (%d)", what, (int)b->type);
    {
        /* a stage is an elevation; a unit discharge is at most FSDEM_MAX_SPEED through FSDEM_MAX_LENGTH of depth */
        const int discharge = b->type == FSDEM_SWE_BC_DISCHARGE;
        const fsdem_real bound = discharge ? FSDEM_MAX_SPEED * FSDEM_MAX_LENGTH : FSDEM_MAX_LENGTH;
        if (!(b->value >= (discharge ? 0 : -bound) && b->value <= bound))
            return fsdem__reject(msg, size, "%s.value must be in [%g, %g] %s (got %g)", what, discharge ? 0.0 : -(double)bound,
                                 (double)bound, discharge ? "m^2/s (an inflow discharge)" : "m", (double)b->value);
        return fsdem__swe_series_check(b->series_time, b->series_value, b->series_count, discharge, bound, what, msg, size);
    }
}

/* The first value that is not in [-bound, bound] (in [0, bound] when non_negative), or -1. */
static int fsdem__swe_first_bad(const fsdem_real *a, int n, int non_negative, fsdem_real bound) {
    int k;
    for (k = 0; k < n; ++k)
        if (!(a[k] >= (non_negative ? 0 : -bound) && a[k] <= bound)) return k;
    return -1;
}

fsdem_result fsdem_swe_desc_check(const fsdem_swe_desc *d, char *msg, size_t size) {
    int k, n;
    fsdem_result res;
    if (!d) return fsdem__reject(msg, size, "fsdem_swe_desc is NULL");
    if (d->dim != 1 && d->dim != 2) return fsdem__reject(msg, size, "fsdem_swe_desc.dim must be 1 or 2 (got %d)", d->dim);
    if (d->nx < 1) return fsdem__reject(msg, size, "fsdem_swe_desc.nx must be >= 1 cell (got %d)", d->nx);
    if (d->ny < 1) return fsdem__reject(msg, size, "fsdem_swe_desc.ny must be >= 1 cell (got %d)", d->ny);
    if (d->dim == 1 && d->ny != 1) return fsdem__reject(msg, size, "fsdem_swe_desc.ny must be 1 in 1D (got %d)", d->ny);
    if ((double)d->nx * (double)d->ny > (double)(1 << 30))
        return fsdem__reject(msg, size, "fsdem_swe_desc: nx*ny = %g cells is too many", (double)d->nx * (double)d->ny);
    if (!fsdem__finite(d->x_min) || !fsdem__finite(d->x_max) || !(d->x_max > d->x_min))
        return fsdem__reject(msg, size, "fsdem_swe_desc.x_max must exceed x_min (got %g .. %g m)", (double)d->x_min,
                             (double)d->x_max);
    if (d->dim == 2 && (!fsdem__finite(d->y_min) || !fsdem__finite(d->y_max) || !(d->y_max > d->y_min)))
        return fsdem__reject(msg, size, "fsdem_swe_desc.y_max must exceed y_min (got %g .. %g m)", (double)d->y_min,
                             (double)d->y_max);
    if (d->dim == 1 && (!(d->width > 0) || !fsdem__finite(d->width)))
        return fsdem__reject(msg, size, "fsdem_swe_desc.width must be > 0 (got %g m)", (double)d->width);
    {
        /* cells of a finite, normal size: a range of +-1e308 overflows dx, one of 1e-308 underflows
           the cell area */
        const fsdem_real dx = (d->x_max - d->x_min) / (fsdem_real)d->nx;
        const fsdem_real dy = d->dim == 2 ? (d->y_max - d->y_min) / (fsdem_real)d->ny : d->width, area = dx * dy;
        if (!fsdem__finite(dx) || !fsdem__finite(dy) || !fsdem__finite(area) || !(area > 0) || !fsdem__finite(1 / area) ||
            !fsdem__finite(1 / dx) || !fsdem__finite(1 / dy) || area < (fsdem_real)FLT_MIN)
            return fsdem__reject(msg, size, "fsdem_swe_desc: cells of %g x %g m (extent / cell count) are not of a finite, "
                                            "representable size", (double)dx, (double)dy);
    }
    if (d->gravity.x != 0 || d->gravity.y != 0 || !(d->gravity.z < 0 && d->gravity.z >= -FSDEM_MAX_ACCELERATION))
        return fsdem__reject(msg, size,
                             "fsdem_swe_desc.gravity must be (0, 0, -g) with 0 < g <= FSDEM_MAX_ACCELERATION (%g m/s^2) (got (%g, %g, %g) m/s^2)",
                             (double)FSDEM_MAX_ACCELERATION, (double)d->gravity.x, (double)d->gravity.y, (double)d->gravity.z);
    if (!(d->density > 0) || !fsdem__finite(d->density))
        return fsdem__reject(msg, size, "fsdem_swe_desc.density must be > 0 (got %g kg/m^3)", (double)d->density);
    if (!(d->cfl > 0 && d->cfl <= 1))
        return fsdem__reject(msg, size, "fsdem_swe_desc.cfl must be in (0, 1] (got %g)", (double)d->cfl);
    if (fsdem__check_dt_max("fsdem_swe_desc", d->dt_max, d->gravity, msg, size) != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    if (d->order != 1 && d->order != 2)
        return fsdem__reject(msg, size, "fsdem_swe_desc.order must be 1 or 2 (got %d)", d->order);
    if ((int)d->limiter < 0 || (int)d->limiter > 3)
        return fsdem__reject(msg, size, "fsdem_swe_desc.limiter is not a fsdem_swe_limiter (%d)", (int)d->limiter);
    if (!(d->dry_depth > 0) || !fsdem__finite(d->dry_depth))
        return fsdem__reject(msg, size, "fsdem_swe_desc.dry_depth must be > 0 (got %g m)", (double)d->dry_depth);
    if (!(d->manning >= 0 && d->manning <= 1)) /* the bound of fsdem_swe_set_manning */
        return fsdem__reject(msg, size, "fsdem_swe_desc.manning must be in [0, 1] (got %g s/m^(1/3))", (double)d->manning);
    if (!(d->eddy_viscosity >= 0) || !fsdem__finite(d->eddy_viscosity))
        return fsdem__reject(msg, size, "fsdem_swe_desc.eddy_viscosity must be >= 0 (got %g m^2/s)",
                             (double)d->eddy_viscosity);
    if (!(d->rain_rate >= 0) || !fsdem__finite(d->rain_rate))
        return fsdem__reject(msg, size, "fsdem_swe_desc.rain_rate must be >= 0 (got %g m/s)", (double)d->rain_rate);
    for (k = 0; k < (d->dim == 2 ? 4 : 2); ++k) {
        res = fsdem__swe_boundary_check(&d->boundary[k], k, msg, size);
        if (res != FSDEM_OK) return res;
    }
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        return fsdem__reject(msg, size, "fsdem_swe_desc.allocator: set both alloc and free, or neither");
    n = d->nx * d->ny;
    if (d->bed && (k = fsdem__swe_first_bad(d->bed, n, 0, FSDEM_MAX_LENGTH)) >= 0)
        return fsdem__reject(msg, size, "fsdem_swe_desc.bed[%d] (cell i=%d, j=%d) must be finite, |bed| <= FSDEM_MAX_LENGTH (got %g m)", k,
                             k % d->nx, k / d->nx, (double)d->bed[k]);
    if (d->depth && (k = fsdem__swe_first_bad(d->depth, n, 1, FSDEM_MAX_LENGTH)) >= 0)
        return fsdem__reject(msg, size, "fsdem_swe_desc.depth[%d] (cell i=%d, j=%d) must be in [0, FSDEM_MAX_LENGTH] (got %g m)",
                             k, k % d->nx, k / d->nx, (double)d->depth[k]);
    return FSDEM_OK;
}

/* ---- >>swe_object : creation, series, state ---- */

static fsdem_real fsdem__swe_limit(int limiter, fsdem_real a, fsdem_real b);

static void fsdem__swe_free_series(fsdem_swe *s, fsdem_real **t, fsdem_real **v, int *n) {
    fsdem__free(&s->allocator, *t, sizeof(fsdem_real) * (size_t)*n);
    fsdem__free(&s->allocator, *v, sizeof(fsdem_real) * (size_t)*n);
    *t = *v = NULL;
    *n = 0;
}

/* Copies a series into freshly allocated arrays (n = 0: none). */
static fsdem_result fsdem__swe_copy_series(fsdem_swe *s, const fsdem_real *t, const fsdem_real *v, int n,
                                           fsdem_real **tout, fsdem_real **vout) {
    *tout = *vout = NULL;
    if (n <= 0) return FSDEM_OK;
    *tout = (fsdem_real *)fsdem__alloc(&s->allocator, sizeof(fsdem_real) * (size_t)n);
    *vout = (fsdem_real *)fsdem__alloc(&s->allocator, sizeof(fsdem_real) * (size_t)n);
    if (!*tout || !*vout) {
        fsdem__free(&s->allocator, *tout, sizeof(fsdem_real) * (size_t)n);
        fsdem__free(&s->allocator, *vout, sizeof(fsdem_real) * (size_t)n);
        *tout = *vout = NULL;
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    memcpy(*tout, t, sizeof(fsdem_real) * (size_t)n);
    memcpy(*vout, v, sizeof(fsdem_real) * (size_t)n);
    return FSDEM_OK;
}

/* Value of a series at time t (linear, held constant outside), or `constant` without a series. */
static fsdem_real fsdem__swe_series_at(const fsdem_real *ts, const fsdem_real *vs, int n, fsdem_real constant,
                                       fsdem_real t) {
    int lo = 0, hi = n - 1;
    if (n <= 0) return constant;
    if (t <= ts[0]) return vs[0];
    if (t >= ts[n - 1]) return vs[n - 1];
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (ts[mid] <= t) lo = mid;
        else hi = mid;
    }
    return vs[lo] + (vs[hi] - vs[lo]) * (t - ts[lo]) / (ts[hi] - ts[lo]);
}

static fsdem_result fsdem__swe_store_boundary(fsdem_swe *s, int side, const fsdem_swe_boundary *b) {
    fsdem_real *t, *v;
    fsdem_result res = fsdem__swe_copy_series(s, b->series_time, b->series_value, b->series_count, &t, &v);
    if (res != FSDEM_OK) return res;
    fsdem__swe_free_series(s, &s->bnd[side].t, &s->bnd[side].v, &s->bnd[side].n);
    s->bnd[side].type = b->type;
    s->bnd[side].value = b->value;
    s->bnd[side].t = t;
    s->bnd[side].v = v;
    s->bnd[side].n = t ? b->series_count : 0;
    return FSDEM_OK;
}

/* Velocity of a cell (0 when dry). */
static void fsdem__swe_velocity(const fsdem_swe *s, int k, fsdem_real *u, fsdem_real *v) {
    fsdem_real h = s->eta[k] - s->bed[k];
    if (h < s->desc.dry_depth) {
        *u = *v = 0;
        return;
    }
    *u = s->qx[k] / h;
    *v = s->qy[k] / h;
}

static int fsdem__swe_is_blocked(const fsdem_swe *s, int k) { return s->blocked && k >= 0 && s->blocked[k]; }

/* Keeps blocked cells dry (after a setter wrote depths). */
static void fsdem__swe_dry_blocked(fsdem_swe *s) {
    int k;
    for (k = 0; s->blocked && k < s->n; ++k)
        if (s->blocked[k]) {
            s->eta[k] = s->bed[k];
            s->qx[k] = s->qy[k] = 0;
        }
}

/* Recomputes the wave-speed bound and the statistics of the current state (after a setter). */
static void fsdem__swe_scan(fsdem_swe *s) {
    int k, wet = 0;
    fsdem_real wave = 0, speed2 = 0, hmax = 0, accel = 0;
    fsdem_real idx = 1 / s->dx, idy = s->dim == 2 ? 1 / s->dy : 0;
    for (k = 0; k < s->n; ++k) {
        fsdem_real h = s->eta[k] - s->bed[k], u, v, c, w;
        if (h > hmax) hmax = h;
        if (h < s->desc.dry_depth) continue;
        fsdem__swe_velocity(s, k, &u, &v);
        c = (fsdem_real)sqrt(s->g * h);
        w = (fsdem_real)fabs(u) * idx + (fsdem_real)fabs(v) * idy + c * (idx + idy);
        if (w > wave) wave = w;
        {
            int i = k % s->nx, j = k / s->nx;
            fsdem_real a = 0;
            if (i > 0 && i < s->nx - 1)
                a += (fsdem_real)fabs(fsdem__swe_limit(0, s->eta[k] - s->eta[k - 1], s->eta[k + 1] - s->eta[k])) * idx * idx;
            if (j > 0 && j < s->ny - 1)
                a += (fsdem_real)fabs(fsdem__swe_limit(0, s->eta[k] - s->eta[k - s->nx], s->eta[k + s->nx] - s->eta[k])) *
                     idy * idy;
            if (s->g * a > accel) accel = s->g * a;
        }
        if (u * u + v * v > speed2) speed2 = u * u + v * v;
        wet++;
    }
    s->max_wave = wave;
    s->max_accel = accel;
    s->max_speed = (fsdem_real)sqrt(speed2);
    s->max_depth = hmax;
    s->wet_cells = wet;
}

fsdem_result fsdem_swe_create(const fsdem_swe_desc *desc, fsdem_swe **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_allocator al;
    fsdem_swe *s;
    fsdem_result res;
    size_t n, nx, reals;
    int k;
    if (out) *out = NULL;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    res = fsdem_swe_desc_check(desc, msg, sizeof msg);
    s = (fsdem_swe *)fsdem__object_new(res, msg, desc ? desc->log : NULL, desc ? desc->log_user : NULL,
                                       desc ? &desc->allocator : NULL, sizeof *s, "fsdem_swe_create", &res);
    if (!s) return res;
    al = desc->allocator;
    s->desc = *desc;
    s->desc.bed = s->desc.depth = NULL;
    s->allocator = al;
    s->status.log = desc->log;
    s->status.log_user = desc->log_user;
    s->dim = desc->dim;
    s->nx = desc->nx;
    s->ny = desc->ny;
    s->n = desc->nx * desc->ny;
    s->g = -desc->gravity.z;
    s->tiny = desc->dry_depth * (fsdem_real)1e-9;
    s->dx = (desc->x_max - desc->x_min) / (fsdem_real)desc->nx;
    s->dy = desc->dim == 2 ? (desc->y_max - desc->y_min) / (fsdem_real)desc->ny : desc->width;
    s->area = s->dx * s->dy;
    s->rain = desc->rain_rate;
    s->slots = desc->dim == 2 ? 3 : 1;
    n = (size_t)s->n;
    nx = (size_t)s->nx;
    reals = 6 * n + (size_t)s->slots * 4 * (nx + 2);
    if (s->dim == 2)
        reals += (2 * sizeof(fsdem__swe_rowcell) + sizeof(fsdem__swe_sface)) / sizeof(fsdem_real) * nx;
    s->block_bytes = reals * sizeof(fsdem_real);
    s->block = (fsdem_real *)fsdem__alloc(&al, s->block_bytes);
    if (!s->block) {
        fsdem__log_oom(desc->log, desc->log_user, "fsdem_swe_create", s->block_bytes);
        fsdem__free(&al, s, sizeof *s);
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    memset(s->block, 0, s->block_bytes);
    s->eta = s->block;
    s->qx = s->eta + n;
    s->qy = s->qx + n;
    s->bed = s->qy + n;
    s->sx = s->bed + n;
    s->sy = s->sx + n;
    s->prim = s->sy + n;
    if (s->dim == 2) {
        s->rows = (fsdem__swe_rowcell *)(void *)(s->prim + (size_t)s->slots * 4 * (nx + 2));
        s->south = (fsdem__swe_sface *)(void *)(s->rows + 2 * nx);
    }
    for (k = 0; k < 4; ++k) {
        s->bnd[k].type = FSDEM_SWE_BC_WALL;
        if (k < (s->dim == 2 ? 4 : 2) && fsdem__swe_store_boundary(s, k, &desc->boundary[k]) != FSDEM_OK) {
            fsdem__log_oom(desc->log, desc->log_user, "fsdem_swe_create",
                           2 * sizeof(fsdem_real) * (size_t)desc->boundary[k].series_count);
            fsdem_swe_destroy(s);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
        s->desc.boundary[k].series_time = s->desc.boundary[k].series_value = NULL;
        s->desc.boundary[k].series_count = 0;
    }
    for (k = 0; k < s->n; ++k) {
        s->bed[k] = desc->bed ? desc->bed[k] : 0;
        s->eta[k] = s->bed[k] + (desc->depth ? desc->depth[k] : 0);
    }
    fsdem__swe_scan(s);
    *out = s;
    return FSDEM_OK;
}

void fsdem_swe_destroy(fsdem_swe *s) {
    int k;
    if (!s) return;
    fsdem__series_close(&s->gauges, &s->allocator);
    for (k = 0; k < 4; ++k) fsdem__swe_free_series(s, &s->bnd[k].t, &s->bnd[k].v, &s->bnd[k].n);
    for (k = 0; k < s->src_count; ++k) fsdem__swe_free_series(s, &s->src[k].t, &s->src[k].v, &s->src[k].n);
    fsdem__free(&s->allocator, s->src, sizeof(fsdem__swe_src) * (size_t)s->src_capacity);
    fsdem__free(&s->allocator, s->gauge, 2 * sizeof(fsdem_real) * (size_t)s->gauge_capacity);
    fsdem__free(&s->allocator, s->manning, sizeof(fsdem_real) * (size_t)s->n);
    fsdem__free(&s->allocator, s->blocked, (size_t)s->n);
    fsdem__free(&s->allocator, s->block, s->block_bytes);
    fsdem__free(&s->allocator, s, sizeof *s);
}

const char *fsdem_swe_last_error(const fsdem_swe *s) { return s ? s->status.message : "fsdem_swe is NULL"; }

fsdem_swe_grid fsdem_swe_get_grid(const fsdem_swe *s) {
    fsdem_swe_grid g;
    memset(&g, 0, sizeof g);
    if (!s) return g;
    g.dim = s->dim;
    g.nx = s->nx;
    g.ny = s->ny;
    g.dx = s->dx;
    g.dy = s->dy;
    g.x_min = s->desc.x_min;
    g.y_min = s->dim == 2 ? s->desc.y_min : 0;
    g.cell_area = s->area;
    return g;
}

/* Rejects a per-cell input array: NULL, or its first bad value (beyond +-bound, or < 0 when
   non_negative) named. */
static fsdem_result fsdem__swe_array_check(fsdem_swe *s, const fsdem_real *a, int non_negative, fsdem_real bound, const char *what,
                                           const char *unit) {
    int k;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!a) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: array is NULL", what);
    k = fsdem__swe_first_bad(a, s->n, non_negative, bound);
    if (k >= 0)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: value %d (cell i=%d, j=%d) must be in [%g, %g] %s (got %g %s)", what,
                           k, k % s->nx, k / s->nx, non_negative ? 0.0 : -(double)bound, (double)bound, unit, (double)a[k], unit);
    return FSDEM_OK;
}

fsdem_result fsdem_swe_set_bed(fsdem_swe *s, const fsdem_real *bed) {
    int k;
    if (fsdem__swe_array_check(s, bed, 0, FSDEM_MAX_LENGTH, "fsdem_swe_set_bed", "m") != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < s->n; ++k) {
        fsdem_real h = s->eta[k] - s->bed[k];
        s->bed[k] = bed[k];
        s->eta[k] = bed[k] + h;
    }
    fsdem__swe_scan(s);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_set_depth(fsdem_swe *s, const fsdem_real *depth) {
    int k;
    if (fsdem__swe_array_check(s, depth, 1, FSDEM_MAX_LENGTH, "fsdem_swe_set_depth", "m") != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < s->n; ++k) {
        s->eta[k] = s->bed[k] + depth[k];
        if (depth[k] < s->desc.dry_depth) s->qx[k] = s->qy[k] = 0;
    }
    fsdem__swe_scan(s);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_set_surface(fsdem_swe *s, const fsdem_real *eta) {
    int k;
    if (fsdem__swe_array_check(s, eta, 0, FSDEM_MAX_LENGTH, "fsdem_swe_set_surface", "m") != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < s->n; ++k) {
        s->eta[k] = eta[k] > s->bed[k] ? eta[k] : s->bed[k];
        if (s->eta[k] - s->bed[k] < s->desc.dry_depth) s->qx[k] = s->qy[k] = 0;
    }
    fsdem__swe_scan(s);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_set_velocity(fsdem_swe *s, const fsdem_real *u, const fsdem_real *v) {
    int k;
    if (fsdem__swe_array_check(s, u, 0, FSDEM_MAX_SPEED, "fsdem_swe_set_velocity (u)", "m/s") != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    if (v && s->dim == 2 && fsdem__swe_array_check(s, v, 0, FSDEM_MAX_SPEED, "fsdem_swe_set_velocity (v)", "m/s") != FSDEM_OK)
        return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < s->n; ++k) {
        fsdem_real h = s->eta[k] - s->bed[k];
        int wet = h >= s->desc.dry_depth;
        s->qx[k] = wet ? u[k] * h : 0;
        s->qy[k] = wet && v && s->dim == 2 ? v[k] * h : 0;
    }
    fsdem__swe_scan(s);
    return fsdem__ok(&s->status);
}

static void fsdem__swe_centre(const fsdem_swe *s, int k, fsdem_real *x, fsdem_real *y) {
    *x = s->desc.x_min + ((fsdem_real)(k % s->nx) + (fsdem_real)0.5) * s->dx;
    *y = s->dim == 2 ? s->desc.y_min + ((fsdem_real)(k / s->nx) + (fsdem_real)0.5) * s->dy : 0;
}

fsdem_result fsdem_swe_set_cells(fsdem_swe *s, fsdem_swe_init_fn fn, void *user) {
    int k, pass;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!fn) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_set_cells: fn is NULL");
    /* pass 0 validates everything, pass 1 writes, so a bad cell leaves the state unchanged */
    for (pass = 0; pass < 2; ++pass)
        for (k = 0; k < s->n; ++k) {
            fsdem_swe_cell c;
            fsdem_real x, y;
            fsdem__swe_centre(s, k, &x, &y);
            c.bed = 0;
            c.depth = 0;
            c.eta = 0;
            c.u = c.v = 0;
            fn(user, x, y, &c);
            if (pass == 0) {
                if (!(fabs(c.bed) <= FSDEM_MAX_LENGTH) || !(c.depth >= 0 && c.depth <= FSDEM_MAX_LENGTH) ||
                    !(fabs(c.u) <= FSDEM_MAX_SPEED) || !(fabs(c.v) <= FSDEM_MAX_SPEED))
                    return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                                       "fsdem_swe_set_cells: cell %d (i=%d, j=%d, x=%g, y=%g) has bed %g m, depth %g m, "
                                       "u %g, v %g m/s: bed and depth (>= 0) must be within FSDEM_MAX_LENGTH, the speeds within "
                                       "FSDEM_MAX_SPEED",
                                       k, k % s->nx, k / s->nx, (double)x, (double)y, (double)c.bed, (double)c.depth,
                                       (double)c.u, (double)c.v);
                continue;
            }
            s->bed[k] = c.bed;
            s->eta[k] = c.bed + c.depth;
            if (c.depth >= s->desc.dry_depth) {
                s->qx[k] = c.u * c.depth;
                s->qy[k] = s->dim == 2 ? c.v * c.depth : 0;
            } else {
                s->qx[k] = s->qy[k] = 0;
            }
        }
    fsdem__swe_scan(s);
    return fsdem__ok(&s->status);
}

fsdem_swe_fields fsdem_swe_get_fields(const fsdem_swe *s) {
    fsdem_swe_fields f;
    memset(&f, 0, sizeof f);
    if (!s) return f;
    f.nx = s->nx;
    f.ny = s->ny;
    f.eta = s->eta;
    f.qx = s->qx;
    f.qy = s->qy;
    f.bed = s->bed;
    f.blocked = s->blocked;
    return f;
}

fsdem_swe_coupling fsdem_swe_get_coupling(fsdem_swe *s) {
    fsdem_swe_coupling c;
    memset(&c, 0, sizeof c);
    if (!s) return c;
    c.nx = s->nx;
    c.ny = s->ny;
    c.source_x = s->sx;
    c.source_y = s->sy;
    s->sources_used = 1; /* the caller may write them from now on */
    return c;
}

fsdem_result fsdem_swe_copy_field(const fsdem_swe *s, fsdem_swe_field field, fsdem_real *out) {
    int k;
    if (!s || !out) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < s->n; ++k) {
        fsdem_real u, v;
        switch (field) {
        case FSDEM_SWE_FIELD_DEPTH: out[k] = s->eta[k] - s->bed[k]; break;
        case FSDEM_SWE_FIELD_ETA: out[k] = s->eta[k]; break;
        case FSDEM_SWE_FIELD_U: fsdem__swe_velocity(s, k, &u, &v); out[k] = u; break;
        case FSDEM_SWE_FIELD_V: fsdem__swe_velocity(s, k, &u, &v); out[k] = v; break;
        case FSDEM_SWE_FIELD_BED: out[k] = s->bed[k]; break;
        case FSDEM_SWE_FIELD_QX: out[k] = s->qx[k]; break;
        case FSDEM_SWE_FIELD_QY: out[k] = s->qy[k]; break;
        default: return FSDEM_ERR_INVALID_ARG;
        }
    }
    return FSDEM_OK;
}

int fsdem_swe_cell_at(const fsdem_swe *s, fsdem_real x, fsdem_real y) {
    fsdem_real fx, fy;
    int i, j;
    if (!s) return -1;
    fx = (x - s->desc.x_min) / s->dx;
    fy = s->dim == 2 ? (y - s->desc.y_min) / s->dy : 0;
    if (!(fx >= 0 && fx <= (fsdem_real)s->nx) || !(fy >= 0 && fy <= (fsdem_real)s->ny)) return -1;
    i = (int)fx;
    j = (int)fy;
    if (i >= s->nx) i = s->nx - 1;
    if (j >= s->ny) j = s->ny - 1;
    return i + s->nx * j;
}

fsdem_result fsdem_swe_sample_state(const fsdem_swe *s, fsdem_real x, fsdem_real y, fsdem_swe_cell *out) {
    fsdem_real fx, fy, wx, wy, w[4], wsum = 0;
    int i0, j0, i1, j1, c[4], q;
    if (!s || !out) return FSDEM_ERR_INVALID_ARG;
    q = fsdem_swe_cell_at(s, x, y);
    if (q < 0 || fsdem__swe_is_blocked(s, q)) return FSDEM_ERR_OUT_OF_DOMAIN;
    /* (bi)linear between the centres around the point, clamped at the outermost centres */
    fx = (x - s->desc.x_min) / s->dx - (fsdem_real)0.5;
    fy = s->dim == 2 ? (y - s->desc.y_min) / s->dy - (fsdem_real)0.5 : 0;
    if (fx < 0) fx = 0;
    if (fy < 0) fy = 0;
    if (fx > (fsdem_real)(s->nx - 1)) fx = (fsdem_real)(s->nx - 1);
    if (fy > (fsdem_real)(s->ny - 1)) fy = (fsdem_real)(s->ny - 1);
    i0 = (int)fx;
    j0 = (int)fy;
    i1 = i0 + 1 < s->nx ? i0 + 1 : i0;
    j1 = j0 + 1 < s->ny ? j0 + 1 : j0;
    wx = fx - (fsdem_real)i0;
    wy = fy - (fsdem_real)j0;
    c[0] = i0 + s->nx * j0;
    c[1] = i1 + s->nx * j0;
    c[2] = i0 + s->nx * j1;
    c[3] = i1 + s->nx * j1;
    w[0] = (1 - wx) * (1 - wy);
    w[1] = wx * (1 - wy);
    w[2] = (1 - wx) * wy;
    w[3] = wx * wy;
    /* never across a wall: blocked cells leave the stencil and the others share their weight */
    for (q = 0; s->blocked && q < 4; ++q) {
        if (s->blocked[c[q]]) w[q] = 0;
        wsum += w[q];
    }
    if (s->blocked)
        for (q = 0; q < 4; ++q) w[q] = wsum > 0 ? w[q] / wsum : (c[q] == fsdem_swe_cell_at(s, x, y));
    out->bed = out->depth = out->u = out->v = 0;
    for (q = 0; q < 4; ++q) {
        fsdem_real u, v;
        if (w[q] == 0) continue;
        fsdem__swe_velocity(s, c[q], &u, &v);
        out->bed += w[q] * s->bed[c[q]];
        out->depth += w[q] * (s->eta[c[q]] - s->bed[c[q]]);
        out->u += w[q] * u;
        out->v += w[q] * v;
    }
    out->eta = out->bed + out->depth;
    return FSDEM_OK;
}

/* The surface slope d eta / d(axis) at (x, y) with c the water there: a central difference over one
   cell, its pair moved inside the outermost cell centres near the edge of the grid (beyond them
   the samples are clamped, flat), one-sided against c when a side lies in a blocked cell. */
static fsdem_real fsdem__swe_surface_slope(const fsdem_swe *s, fsdem_real x, fsdem_real y, int axis, const fsdem_swe_cell *c) {
    const int cells = axis == 0 ? s->nx : s->ny;
    const fsdem_real d = axis == 0 ? s->dx : s->dy, lo_edge = (axis == 0 ? s->desc.x_min : s->desc.y_min) + d,
                     hi_edge = lo_edge + (fsdem_real)(cells - 2) * d;
    fsdem_real at = axis == 0 ? x : y, span = 0;
    fsdem_swe_cell lo, hi;
    if (cells < 2) return 0;
    if (at < lo_edge) at = lo_edge;
    if (at > hi_edge) at = hi_edge;
    if (fsdem_swe_sample_state(s, axis == 0 ? at - d / 2 : x, axis == 0 ? y : at - d / 2, &lo) == FSDEM_OK) span += d / 2;
    else lo = *c;
    if (fsdem_swe_sample_state(s, axis == 0 ? at + d / 2 : x, axis == 0 ? y : at + d / 2, &hi) == FSDEM_OK) span += d / 2;
    else hi = *c;
    return span > 0 ? (hi.eta - lo.eta) / span : 0;
}

fsdem_result fsdem_swe_sample(const fsdem_swe *s, int count, const fsdem_vec3 *points, fsdem_fluid_sample *out) {
    int n;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (count < 0 || (count > 0 && (!points || !out)))
        return fsdem__fail((fsdem__status *)&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_sample: bad count %d or NULL arrays",
                           count);
    for (n = 0; n < count; ++n) {
        const fsdem_vec3 p = points[n];
        const fsdem_real rg = s->desc.density * s->g;
        fsdem_swe_cell c;
        memset(&out[n], 0, sizeof out[n]);
        if (fsdem_swe_sample_state(s, p.x, p.y, &c) != FSDEM_OK || c.depth < s->desc.dry_depth || p.z < c.bed ||
            p.z > c.eta)
            continue;
        out[n].velocity = fsdem_v3(c.u, c.v, 0);
        out[n].volume_fraction = 1;
        /* hydrostatic p = rho g (eta - z) */
        out[n].pressure_gradient.x = rg * fsdem__swe_surface_slope(s, p.x, p.y, 0, &c);
        if (s->dim == 2) out[n].pressure_gradient.y = rg * fsdem__swe_surface_slope(s, p.x, p.y, 1, &c);
        out[n].pressure_gradient.z = -rg;
    }
    return fsdem__ok((fsdem__status *)&s->status);
}

/* Wet cells of the footprint [x - r, x + r] (x [y - r, y + r] in 2D; grown by `grown` cells) with
   their overlap weights (grown: 1 each): pass 0 sums the weights, pass 1 adds `scale` x weight x
   (fx, fy) to the sources. Returns the sum. */
static fsdem_real fsdem__swe_footprint(fsdem_swe *s, fsdem_vec3 p, fsdem_real r, int grown, int pass, fsdem_real scale,
                                       fsdem_vec3 f) {
    const fsdem_real dry = s->desc.dry_depth;
    int lo[2], hi[2], i, j;
    fsdem_real total = 0;
    lo[0] = (int)floor((p.x - r - s->desc.x_min) / s->dx) - grown;
    hi[0] = (int)floor((p.x + r - s->desc.x_min) / s->dx) + grown;
    lo[1] = s->dim == 2 ? (int)floor((p.y - r - s->desc.y_min) / s->dy) - grown : 0;
    hi[1] = s->dim == 2 ? (int)floor((p.y + r - s->desc.y_min) / s->dy) + grown : 0;
    lo[0] = lo[0] < 0 ? 0 : lo[0];
    hi[0] = hi[0] >= s->nx ? s->nx - 1 : hi[0];
    lo[1] = lo[1] < 0 ? 0 : lo[1];
    hi[1] = hi[1] >= s->ny ? s->ny - 1 : hi[1];
    for (j = lo[1]; j <= hi[1]; ++j)
        for (i = lo[0]; i <= hi[0]; ++i) {
            const int k = i + s->nx * j;
            fsdem_real w = 1;
            if (!grown && r > 0) {
                fsdem_real xa = s->desc.x_min + (fsdem_real)i * s->dx;
                w = (p.x + r < xa + s->dx ? p.x + r : xa + s->dx) - (p.x - r > xa ? p.x - r : xa);
                if (s->dim == 2) {
                    fsdem_real ya = s->desc.y_min + (fsdem_real)j * s->dy;
                    w *= (p.y + r < ya + s->dy ? p.y + r : ya + s->dy) - (p.y - r > ya ? p.y - r : ya);
                }
            }
            if (!(w > 0) || s->eta[k] - s->bed[k] < dry) continue;
            total += w;
            if (pass) {
                s->sx[k] += f.x * scale * w;
                if (s->dim == 2) s->sy[k] += f.y * scale * w;
            }
        }
    return total;
}

fsdem_result fsdem_swe_add_force(fsdem_swe *s, fsdem_vec3 point, fsdem_real radius, fsdem_vec3 force, int *taken) {
    fsdem_real total = 0;
    int grown;
    if (taken) *taken = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!fsdem__finite3(point) || !fsdem__finite3(force) || !(radius >= 0) || !fsdem__finite(radius))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_add_force: point, force and radius >= 0 must be finite");
    {
        /* more than would accelerate all the water the grid can hold (FSDEM_MAX_LENGTH deep) at
           FSDEM_MAX_ACCELERATION */
        const fsdem_real most = s->desc.density * FSDEM_MAX_ACCELERATION * (fsdem_real)s->n * s->area * FSDEM_MAX_LENGTH;
        if (!fsdem__within(force, most))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                               "fsdem_swe_add_force: the force (%g, %g) N would accelerate the deepest water the grid can hold at "
                               "more than FSDEM_MAX_ACCELERATION (|F| <= %g N)",
                               (double)force.x, (double)force.y, (double)most);
    }
    if (fsdem_swe_cell_at(s, point.x, point.y) < 0)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_DOMAIN, "fsdem_swe_add_force: point (%g, %g) is outside the grid",
                           (double)point.x, (double)point.y);
    /* a force felt at a wet/dry edge (water sampled from a neighbouring cell while the footprint is
       dry) goes to the wet cells one cell around, so momentum is exchanged, never created */
    for (grown = 0; grown < 2 && total == 0; ++grown) total = fsdem__swe_footprint(s, point, radius, grown, 0, 0, force);
    if (total > 0) {
        fsdem__swe_footprint(s, point, radius, grown - 1, 1, 1 / (total * s->desc.density * s->area), force);
        s->sources_used = 1;
        if (taken) *taken = 1;
    }
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_clear_forces(fsdem_swe *s) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    memset(s->sx, 0, sizeof(fsdem_real) * (size_t)s->n);
    memset(s->sy, 0, sizeof(fsdem_real) * (size_t)s->n);
    return fsdem__ok(&s->status);
}

/* ---- >>swe_sources : boundaries, friction, rain, blocked cells, point sources ---- */

fsdem_result fsdem_swe_set_boundary(fsdem_swe *s, fsdem_side side, const fsdem_swe_boundary *bc) {
    char msg[FSDEM__MESSAGE_SIZE];
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((int)side < 0 || (int)side >= (s->dim == 2 ? 4 : 2))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_set_boundary: side %d does not exist in %dD",
                           (int)side, s->dim);
    if (fsdem__swe_boundary_check(bc, (int)side, msg, sizeof msg) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_set_boundary: %s", msg);
    if (fsdem__swe_store_boundary(s, (int)side, bc) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_swe_set_boundary: out of memory");
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_set_manning(fsdem_swe *s, const fsdem_real *manning) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!manning) {
        fsdem__free(&s->allocator, s->manning, sizeof(fsdem_real) * (size_t)s->n);
        s->manning = NULL;
        return fsdem__ok(&s->status);
    }
    /* at most 1: five times the roughest floodplain of Chow's (1959) table (dense brush, 0.2) */
    if (fsdem__swe_array_check(s, manning, 1, 1, "fsdem_swe_set_manning", "s/m^(1/3)") != FSDEM_OK)
        return FSDEM_ERR_INVALID_ARG;
    if (!s->manning) {
        s->manning = (fsdem_real *)fsdem__alloc(&s->allocator, sizeof(fsdem_real) * (size_t)s->n);
        if (!s->manning) return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_swe_set_manning: out of memory");
    }
    memcpy(s->manning, manning, sizeof(fsdem_real) * (size_t)s->n);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_set_rain(fsdem_swe *s, fsdem_real rate) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!(rate >= 0) || !fsdem__finite(rate))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_set_rain: rate must be >= 0 (got %g m/s)",
                           (double)rate);
    s->rain = rate;
    return fsdem__ok(&s->status);
}

/* Replaces the mask by `mask` (n flags, or NULL for none) after checking sources and gauges; the
   water of newly blocked cells is removed and booked as a source. */
static fsdem_result fsdem__swe_apply_blocked(fsdem_swe *s, const unsigned char *mask, const char *what) {
    int k, count = 0;
    for (k = 0; mask && k < s->src_count; ++k)
        if (s->src[k].active && mask[s->src[k].cell])
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: point source %d would be in a blocked cell", what,
                               s->src[k].id);
    for (k = 0; mask && k < s->gauge_count; ++k)
        if (mask[fsdem_swe_cell_at(s, s->gauge[2 * k], s->gauge[2 * k + 1])])
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: gauge %d would be in a blocked cell", what, k);
    if (mask && !s->blocked) {
        s->blocked = (unsigned char *)fsdem__alloc(&s->allocator, (size_t)s->n);
        if (!s->blocked) return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory", what);
        memset(s->blocked, 0, (size_t)s->n);
    }
    for (k = 0; mask && k < s->n; ++k) {
        const int b = mask[k] != 0;
        if (b && !s->blocked[k]) s->vol_source -= (s->eta[k] - s->bed[k]) * s->area;
        s->blocked[k] = (unsigned char)b;
        count += b;
    }
    if (!count) {
        fsdem__free(&s->allocator, s->blocked, (size_t)s->n);
        s->blocked = NULL;
    }
    s->blocked_count = count;
    fsdem__swe_dry_blocked(s);
    fsdem__swe_scan(s);
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_set_blocked(fsdem_swe *s, const unsigned char *blocked) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__swe_apply_blocked(s, blocked, "fsdem_swe_set_blocked");
}

/* Blocks the cells whose centre p makes inside(p) true, on top of the current mask. */
static fsdem_result fsdem__swe_block_where(fsdem_swe *s, int (*inside)(const void *shape, fsdem_real x, fsdem_real y),
                                           const void *shape, const char *what) {
    unsigned char *mask = (unsigned char *)fsdem__alloc(&s->allocator, (size_t)s->n);
    fsdem_result res;
    int k;
    if (!mask) return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory", what);
    for (k = 0; k < s->n; ++k) {
        fsdem_real x, y;
        fsdem__swe_centre(s, k, &x, &y);
        mask[k] = (unsigned char)(fsdem__swe_is_blocked(s, k) || inside(shape, x, y));
    }
    res = fsdem__swe_apply_blocked(s, mask, what);
    fsdem__free(&s->allocator, mask, (size_t)s->n);
    return res;
}

static int fsdem__swe_in_box(const void *shape, fsdem_real x, fsdem_real y) {
    const fsdem_real *b = (const fsdem_real *)shape; /* x0, y0, x1, y1, dim */
    return x >= b[0] && x <= b[2] && (b[4] == 1 || (y >= b[1] && y <= b[3]));
}

fsdem_result fsdem_swe_block_box(fsdem_swe *s, fsdem_real x0, fsdem_real y0, fsdem_real x1, fsdem_real y1) {
    fsdem_real box[5];
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!fsdem__finite(x0) || !fsdem__finite(x1) || !(x1 >= x0) ||
        (s->dim == 2 && (!fsdem__finite(y0) || !fsdem__finite(y1) || !(y1 >= y0))))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_block_box: the corners must be finite with x1 >= x0, y1 >= y0");
    box[0] = x0;
    box[1] = y0;
    box[2] = x1;
    box[3] = y1;
    box[4] = (fsdem_real)s->dim;
    return fsdem__swe_block_where(s, fsdem__swe_in_box, box, "fsdem_swe_block_box");
}

typedef struct fsdem__swe_polygon {
    const fsdem_vec3 *v;
    int count;
} fsdem__swe_polygon;

static int fsdem__swe_in_polygon(const void *shape, fsdem_real x, fsdem_real y) {
    const fsdem__swe_polygon *poly = (const fsdem__swe_polygon *)shape;
    return fsdem__geom_polygon(fsdem_v3(x, y, 0), poly->v, poly->count) < 0;
}

fsdem_result fsdem_swe_block_polygon(fsdem_swe *s, const fsdem_vec3 *vertices, int count) {
    fsdem__swe_polygon poly;
    int k;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (s->dim != 2) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_block_polygon: polygons need dim = 2");
    if (!vertices || count < 3)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_block_polygon: needs >= 3 vertices (got %d)",
                           vertices ? count : 0);
    for (k = 0; k < count; ++k)
        if (!fsdem__finite(vertices[k].x) || !fsdem__finite(vertices[k].y))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_block_polygon: vertex %d is not finite", k);
    poly.v = vertices;
    poly.count = count;
    return fsdem__swe_block_where(s, fsdem__swe_in_polygon, &poly, "fsdem_swe_block_polygon");
}

fsdem_result fsdem_swe_add_point_source(fsdem_swe *s, const fsdem_swe_point_source *p, int *id) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem__swe_src *q;
    int k;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!p) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_add_point_source: source is NULL");
    /* at most FSDEM_MAX_SPEED through a FSDEM_MAX_LENGTH square */
    if (!(fabs(p->discharge) <= FSDEM_MAX_SPEED * FSDEM_MAX_LENGTH * FSDEM_MAX_LENGTH))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_add_point_source: discharge %g m^3/s is not finite or beyond %g",
                           (double)p->discharge, (double)(FSDEM_MAX_SPEED * FSDEM_MAX_LENGTH * FSDEM_MAX_LENGTH));
    if (fsdem__swe_series_check(p->series_time, p->series_value, p->series_count, 0,
                                FSDEM_MAX_SPEED * FSDEM_MAX_LENGTH * FSDEM_MAX_LENGTH, "point source", msg, sizeof msg) !=
        FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_add_point_source: %s", msg);
    k = fsdem_swe_cell_at(s, p->x, p->y);
    if (k < 0)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_DOMAIN,
                           "fsdem_swe_add_point_source: point (%g, %g) is outside the grid", (double)p->x, (double)p->y);
    if (fsdem__swe_is_blocked(s, k))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_add_point_source: point (%g, %g) is in a blocked cell",
                           (double)p->x, (double)p->y);
    if (fsdem__grow(&s->allocator, (void **)&s->src, &s->src_capacity, s->src_count, s->src_count + 1,
                    sizeof(fsdem__swe_src)) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_swe_add_point_source: out of memory");
    q = &s->src[s->src_count];
    memset(q, 0, sizeof *q);
    if (fsdem__swe_copy_series(s, p->series_time, p->series_value, p->series_count, &q->t, &q->v) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_swe_add_point_source: out of memory");
    q->n = q->t ? p->series_count : 0;
    q->discharge = p->discharge;
    q->cell = k;
    q->id = s->src_next_id++;
    q->active = 1;
    s->src_count++;
    if (id) *id = q->id;
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_remove_point_source(fsdem_swe *s, int id) {
    int k;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < s->src_count; ++k)
        if (s->src[k].active && s->src[k].id == id) {
            s->src[k].active = 0;
            return fsdem__ok(&s->status);
        }
    return fsdem__fail(&s->status, FSDEM_ERR_NOT_FOUND, "fsdem_swe_remove_point_source: no source with id %d", id);
}

/* ---- >>swe_riemann : face fluxes ---- */

/* Fluxes through one face along its normal. Inputs are the reconstructed states of the lower (L) and
   upper (R) sides: surface eta, depth h, normal velocity un, tangential velocity ut. */
typedef struct fsdem__swe_flux {
    fsdem_real mass;   /* m^2/s, along the normal */
    fsdem_real tan;    /* m^3/s^2, flux of tangential momentum */
    fsdem_real aL, aR; /* m^3/s^2, normal-momentum flux seen from each side minus g h*_s^2 / 2 */
    fsdem_real hL, hR; /* m, h* after the non-negative reconstruction */
    fsdem_real eL, eR; /* m, eta* */
} fsdem__swe_flux;

static inline void fsdem__swe_riemann(fsdem_real g, fsdem_real tiny, fsdem_real eL, fsdem_real hL, fsdem_real uL,
                                      fsdem_real vL, fsdem_real eR, fsdem_real hR, fsdem_real uR, fsdem_real vR,
                                      fsdem__swe_flux *f) {
    fsdem_real zL = eL - hL, zR = eR - hR;
    fsdem_real zf = zL > zR ? zL : zR, m = eL < eR ? eL : eR;
    fsdem_real hsL, hsR, cL, cR, qL, qR, sL, sR, advL, advR, pL, pR;
    if (zf <= m) {
        hsL = eL - zf;
        hsR = eR - zf;
        f->eL = eL;
        f->eR = eR;
    } else {
        /* the lower surface is below the face bed: lower the face bed to it (Liang's dz) */
        hsL = eL > zf ? eL - zf : 0;
        hsR = eR > zf ? eR - zf : 0;
        f->eL = hsL + m;
        f->eR = hsR + m;
    }
    f->hL = hsL;
    f->hR = hsR;
    /* depths below `tiny` (1e-9 dry_depth) carry no flux: they would only feed ever thinner films
       ahead of a front, whose squares end in slow subnormal arithmetic */
    if (hsL < tiny) hsL = 0;
    if (hsR < tiny) hsR = 0;
    if (!(hsL > 0) && !(hsR > 0)) {
        f->mass = f->tan = f->aL = f->aR = 0;
        return;
    }
    cL = (fsdem_real)sqrt(g * hsL);
    cR = (fsdem_real)sqrt(g * hsR);
    qL = hsL * uL;
    qR = hsR * uR;
    if (!(hsR > 0) || !(hsL > 0)) {
        /* one side dry: the exact Godunov flux of the rarefaction into dry bed (Toro 2001, ch. 5):
           for a dry right side the fan spans uL - cL .. uL + 2cL with u + 2c = uL + 2cL, so at x/t = 0
           u = c = (uL + 2cL)/3 (mirror image for a dry left side) */
        fsdem_real h0, u0, v0, a0;
        if (!(hsR > 0)) {
            a0 = uL + 2 * cL;
            if (uL - cL >= 0) { h0 = hsL; u0 = uL; }
            else if (a0 <= 0) { h0 = 0; u0 = 0; }
            else { u0 = a0 / 3; h0 = u0 * u0 / g; }
            v0 = vL;
        } else {
            a0 = uR - 2 * cR;
            if (uR + cR <= 0) { h0 = hsR; u0 = uR; }
            else if (a0 >= 0) { h0 = 0; u0 = 0; }
            else { u0 = a0 / 3; h0 = u0 * u0 / g; }
            v0 = vR;
        }
        f->mass = h0 * u0;
        f->tan = h0 * u0 * v0;
        a0 = h0 * u0 * u0 + (fsdem_real)0.5 * g * h0 * h0;
        f->aL = a0 - (fsdem_real)0.5 * g * hsL * hsL;
        f->aR = a0 - (fsdem_real)0.5 * g * hsR * hsR;
        return;
    } else {
        fsdem_real us = (fsdem_real)0.5 * (uL + uR) + cL - cR;
        fsdem_real cs = (fsdem_real)0.5 * (cL + cR) + (fsdem_real)0.25 * (uL - uR);
        if (cs < 0) cs = 0;
        sL = uL - cL < us - cs ? uL - cL : us - cs;
        sR = uR + cR > us + cs ? uR + cR : us + cs;
    }
    advL = qL * uL;
    advR = qR * uR;
    pL = (fsdem_real)0.5 * g * hsL * hsL;
    pR = (fsdem_real)0.5 * g * hsR * hsR;
    if (sL >= 0) {
        f->mass = qL;
        f->tan = qL * vL;
        f->aL = advL;
        f->aR = advL + pL - pR;
    } else if (sR <= 0) {
        f->mass = qR;
        f->tan = qR * vR;
        f->aR = advR;
        f->aL = advR + pR - pL;
    } else {
        fsdem_real inv = 1 / (sR - sL), dU = qR - qL, dF = (advR + pR) - (advL + pL);
        f->mass = (sR * qL - sL * qR + sL * sR * (hsR - hsL)) * inv;
        f->tan = (sR * qL * vL - sL * qR * vR + sL * sR * (hsR * vR - hsL * vL)) * inv;
        f->aL = advL + sL * (sR * dU - dF) * inv;
        f->aR = advR + sR * (sL * dU - dF) * inv;
    }
}

/* Boundary depth of an inflow of unit discharge q >= 0 whose outgoing Riemann invariant is R:
   solves 2 sqrt(g h) - q/h = R (increasing in h) by safeguarded Newton on s = sqrt(h). */
static fsdem_real fsdem__swe_inflow_depth(fsdem_real g, fsdem_real q, fsdem_real R) {
    double sg = sqrt((double)g), lo = 0, hi = 1e-3, s, f, df;
    int it;
    if (q <= 0) return R > 0 ? (fsdem_real)(R * R / (4 * g)) : 0;
    while (2 * sg * hi - q / (hi * hi) - R < 0 && hi < 1e6) hi *= 2;
    s = hi;
    for (it = 0; it < 100; ++it) {
        double next;
        f = 2 * sg * s - q / (s * s) - R;
        if (f < 0) lo = s;
        else hi = s;
        df = 2 * sg + 2 * q / (s * s * s);
        next = s - f / df;
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        if (fabs(next - s) <= 1e-15 * s) {
            s = next;
            break;
        }
        s = next;
    }
    return (fsdem_real)(s * s);
}

/* Flux through a reflecting face (a WALL side or the face of a blocked cell) seen from the interior
   state e, h, un (normal velocity), ut; `upper` is 1 when the wall is on the upper side (the
   interior is then the L side): the Riemann problem against the mirror state, with no mass or
   tangential flux. */
static void fsdem__swe_wall_flux(const fsdem_swe *s, int upper, fsdem_real e, fsdem_real h, fsdem_real un, fsdem_real ut,
                                 fsdem__swe_flux *f) {
    if (upper) fsdem__swe_riemann(s->g, s->tiny, e, h, un, ut, e, h, -un, ut, f);
    else fsdem__swe_riemann(s->g, s->tiny, e, h, -un, ut, e, h, un, ut, f);
    f->mass = f->tan = 0;
}

/* Flux through a boundary face. `in_*` is the interior state; `upper` is 1 when the boundary is at the
   upper end of the axis (the interior is then the L side). Returns the fluxes in f, with the interior
   side's aL/aR, hL/hR, eL/eR filled. */
static void fsdem__swe_boundary_flux(const fsdem_swe *s, int side, int upper, fsdem_real ein, fsdem_real hin,
                                     fsdem_real unin, fsdem_real utin, fsdem__swe_flux *f) {
    const fsdem__swe_bnd *b = &s->bnd[side];
    fsdem_real value = s->bvalue[side], g = s->g, sgn = upper ? 1 : -1;
    fsdem_real zin = ein - hin, eex = ein, hex = hin, unex = unin, utex = utin;
    switch (b->type) {
    case FSDEM_SWE_BC_WALL: fsdem__swe_wall_flux(s, upper, ein, hin, unin, utin, f); return;
    case FSDEM_SWE_BC_TRANSMISSIVE: break;
    case FSDEM_SWE_BC_STAGE: {
        /* outgoing invariant w + 2c (w = outward normal velocity) carried from the interior */
        fsdem_real cin = (fsdem_real)sqrt(g * hin), cex, w;
        hex = value > zin ? value - zin : 0;
        cex = (fsdem_real)sqrt(g * hex);
        w = sgn * unin + 2 * (cin - cex);
        unex = hex > 0 ? sgn * w : 0;
        eex = zin + hex;
        break;
    }
    case FSDEM_SWE_BC_DISCHARGE: {
        fsdem_real R = sgn * unin + 2 * (fsdem_real)sqrt(g * hin);
        fsdem_real hb = fsdem__swe_inflow_depth(g, value, R);
        fsdem_real fn = hb > 0 ? value * value / hb + (fsdem_real)0.5 * g * hb * hb : 0;
        fsdem_real own = (fsdem_real)0.5 * g * hin * hin;
        f->mass = -sgn * value;
        f->tan = 0;
        f->hL = f->hR = hin;
        f->eL = f->eR = ein;
        f->aL = f->aR = fn - own;
        return;
    }
    }
    if (upper) fsdem__swe_riemann(g, s->tiny, ein, hin, unin, utin, eex, hex, unex, utex, f);
    else fsdem__swe_riemann(g, s->tiny, eex, hex, unex, utex, ein, hin, unin, utin, f);
}

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

/* Per-step constants and accumulators. */
typedef struct fsdem__swe_ctx {
    fsdem_real dt, lx, ly, g, dry, tiny, rain_dt, idx, idy, manning, visc;
    int order, limiter, two_d, sources, friction;
    /* results */
    fsdem_real wave, speed2, hmax, bflux, accel;
    int wet, negative, bad;
    long long fallbacks;
} fsdem__swe_ctx;

/* Row j of the primitive ring (slot j mod slots), pointer to its `var` array (0 eta, 1 h, 2 u, 3 v). */
static fsdem_real *fsdem__swe_prim(const fsdem_swe *s, int j, int var) {
    int slot = ((j % s->slots) + s->slots) % s->slots;
    return s->prim + ((size_t)slot * 4 + (size_t)var) * (size_t)(s->nx + 2);
}

static fsdem__swe_rowcell *fsdem__swe_rowcells(const fsdem_swe *s, int j) {
    return s->rows + (size_t)(j & 1) * (size_t)s->nx;
}

/* Loads row `src` of the state as primitive values into ring row `dst`, with one ghost cell at each
   end. A ghost row (dst != src) beyond a wall mirrors `src` (v flips); beyond other sides it copies
   h, u, v and extrapolates the bed linearly from row `ext` (ext < 0: flat), so a uniform flow down
   a slope keeps its gravity forcing in the boundary cells. Ghost cells at the row ends do the same. */
static void fsdem__swe_load_row(const fsdem_swe *s, int src, int dst, int flip_v, int ext) {
    fsdem_real *e = fsdem__swe_prim(s, dst, 0) + 1, *h = fsdem__swe_prim(s, dst, 1) + 1;
    fsdem_real *u = fsdem__swe_prim(s, dst, 2) + 1, *v = fsdem__swe_prim(s, dst, 3) + 1;
    const fsdem_real *eta = s->eta + (size_t)src * (size_t)s->nx, *bed = s->bed + (size_t)src * (size_t)s->nx;
    const fsdem_real *qx = s->qx + (size_t)src * (size_t)s->nx, *qy = s->qy + (size_t)src * (size_t)s->nx;
    fsdem_real dry = s->desc.dry_depth, vs = flip_v ? -1 : 1;
    int i, nx = s->nx;
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
        if (h < 0) c->negative = 1;
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
        if (w > c->wave) c->wave = w;
        if (u * u + v * v > c->speed2) c->speed2 = u * u + v * v;
        if (h > c->hmax) c->hmax = h;
        c->wet++;
    }
    if (!((e + qx + qy) - (e + qx + qy) == 0) && c->bad < 0) c->bad = k;
    s->eta[k] = e;
    s->qx[k] = qx;
    s->qy[k] = qy;
}

/* Explicit eddy-viscosity increment of cell i of row j (time-n velocities, face depth the smaller of
   the two cells, so nothing diffuses into dry cells): dt div(nu h grad u). */
static void fsdem__swe_viscous(const fsdem_swe *s, const fsdem__swe_ctx *c, int j, int i, fsdem_real *dqx,
                               fsdem_real *dqy) {
    const fsdem_real *h = fsdem__swe_prim(s, j, 1) + 1, *u = fsdem__swe_prim(s, j, 2) + 1, *v = fsdem__swe_prim(s, j, 3) + 1;
    fsdem_real kx = c->visc * c->dt * c->idx * c->idx, hc = h[i], fx, fy;
    fsdem_real hw = h[i - 1] < hc ? h[i - 1] : hc, he = h[i + 1] < hc ? h[i + 1] : hc;
    fx = kx * (he * (u[i + 1] - u[i]) - hw * (u[i] - u[i - 1]));
    fy = kx * (he * (v[i + 1] - v[i]) - hw * (v[i] - v[i - 1]));
    if (c->two_d) {
        const fsdem_real *hs = fsdem__swe_prim(s, j - 1, 1) + 1, *us = fsdem__swe_prim(s, j - 1, 2) + 1;
        const fsdem_real *vs = fsdem__swe_prim(s, j - 1, 3) + 1, *hn = fsdem__swe_prim(s, j + 1, 1) + 1;
        const fsdem_real *un = fsdem__swe_prim(s, j + 1, 2) + 1, *vn = fsdem__swe_prim(s, j + 1, 3) + 1;
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
        c->fallbacks++;
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
        if (acc > c->accel) c->accel = acc;
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
    fsdem__swe_rowcell *rc = two_d ? fsdem__swe_rowcells(s, j) : NULL;
    fsdem__swe_rows p;
    fsdem__swe_flux f;
    int i;
    p.e = fsdem__swe_prim(s, j, 0) + 1;
    p.h = fsdem__swe_prim(s, j, 1) + 1;
    p.u = fsdem__swe_prim(s, j, 2) + 1;
    p.v = fsdem__swe_prim(s, j, 3) + 1;
    p.se = fsdem__swe_prim(s, j - 1, 0) + 1;
    p.sh = fsdem__swe_prim(s, j - 1, 1) + 1;
    p.su = fsdem__swe_prim(s, j - 1, 2) + 1;
    p.sv = fsdem__swe_prim(s, j - 1, 3) + 1;
    p.ne = fsdem__swe_prim(s, j + 1, 0) + 1;
    p.nh = fsdem__swe_prim(s, j + 1, 1) + 1;
    p.nu = fsdem__swe_prim(s, j + 1, 2) + 1;
    p.nv = fsdem__swe_prim(s, j + 1, 3) + 1;
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
            if (c->visc > 0) fsdem__swe_viscous(s, c, j, i, &cvx, &cvy);
            /* ---- face i - 1/2 ---- */
            if (i == 0) {
                fsdem__swe_boundary_flux(s, FSDEM_SIDE_XMIN, 0, r.e - half * r.sx[0], r.h - half * r.sx[1], r.u - half * r.sx[2],
                                         r.v - half * r.sx[3], &f);
                c->bflux += f.mass * s->dy * c->dt;
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
            c->bflux -= f.mass * s->dy * c->dt;
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

/* ---- >>swe_step : y faces, repair, stable dt, stepping ---- */

/* y faces between rows j-1 and j (j = 0: the YMIN boundary; j = ny: the YMAX boundary). Cells of row
   j-1 get their north faces and are finished; the south-face data of row j are stored. */
static void fsdem__swe_yfaces(fsdem_swe *s, fsdem__swe_ctx *c, int j) {
    const int nx = s->nx, ny = s->ny;
    const fsdem_real g = c->g, ly = c->ly, half = (fsdem_real)0.5;
    fsdem__swe_sface *S = s->south;
    const fsdem__swe_rowcell *lo = j > 0 ? fsdem__swe_rowcells(s, j - 1) : NULL;
    const fsdem__swe_rowcell *hi = j < ny ? fsdem__swe_rowcells(s, j) : NULL;
    fsdem__swe_flux f;
    int i, row = (j - 1) * nx;
    for (i = 0; i < nx; ++i) {
        if (j == 0) {
            const fsdem_real *R = hi[i].s;
            fsdem__swe_boundary_flux(s, FSDEM_SIDE_YMIN, 0, R[0], R[1], R[2], R[3], &f);
            c->bflux += f.mass * s->dx * c->dt;
        } else if (j == ny) {
            const fsdem_real *L = lo[i].n;
            fsdem__swe_boundary_flux(s, FSDEM_SIDE_YMAX, 1, L[0], L[1], L[2], L[3], &f);
            c->bflux -= f.mass * s->dx * c->dt;
        } else if (s->blocked && (s->blocked[row + i] || s->blocked[row + nx + i])) {
            const fsdem_real *L = lo[i].n, *R = hi[i].s;
            if (!s->blocked[row + nx + i]) fsdem__swe_wall_flux(s, 0, R[0], R[1], R[2], R[3], &f);
            else if (!s->blocked[row + i]) fsdem__swe_wall_flux(s, 1, L[0], L[1], L[2], L[3], &f);
            else memset(&f, 0, sizeof f);
        } else {
            const fsdem_real *L = lo[i].n, *R = hi[i].s;
            fsdem__swe_riemann(g, c->tiny, L[0], L[1], L[2], L[3], R[0], R[1], R[2], R[3], &f);
        }
        if (j > 0) {
            const fsdem__swe_sface *q = S + i;
            fsdem_real de = lo[i].acc[0] - ly * (f.mass - q->mass);
            fsdem_real dqy = lo[i].acc[2] - ly * (f.aL - q->a + half * g * (f.hL + q->h) * (f.eL - q->e));
            fsdem_real dqx = lo[i].acc[1] - ly * (f.tan - q->t);
            fsdem__swe_finish(s, c, row + i, de, dqx, dqy);
        }
        S[i].mass = f.mass;
        S[i].a = f.aR;
        S[i].t = f.tan;
        S[i].h = f.hR;
        S[i].e = f.eR;
    }
}

/* Restores non-negative depths after a step that produced a negative one (not expected with
   cfl <= 0.5; kept as a guarantee): the deficit is taken from the wet neighbours, and what they
   cannot give is counted in vol_clipped. */
static void fsdem__swe_repair(fsdem_swe *s) {
    int k, q;
    for (k = 0; k < s->n; ++k) {
        fsdem_real deficit = s->bed[k] - s->eta[k], avail = 0, take;
        int nb[4], nn = 0, i = k % s->nx, j = k / s->nx;
        if (!(deficit > 0)) continue;
        if (i > 0) nb[nn++] = k - 1;
        if (i < s->nx - 1) nb[nn++] = k + 1;
        if (j > 0) nb[nn++] = k - s->nx;
        if (j < s->ny - 1) nb[nn++] = k + s->nx;
        for (q = 0; q < nn; ++q) {
            fsdem_real hq = s->eta[nb[q]] - s->bed[nb[q]];
            if (hq > 0) avail += hq;
        }
        take = deficit < avail ? deficit : avail;
        for (q = 0; q < nn && take > 0; ++q) {
            fsdem_real hq = s->eta[nb[q]] - s->bed[nb[q]];
            if (hq > 0) s->eta[nb[q]] -= take * hq / avail;
        }
        s->vol_clipped += (deficit - take) * s->area;
        s->eta[k] = s->bed[k];
        s->qx[k] = s->qy[k] = 0;
    }
}

/* Largest (|un| + c)/d of the states outside DISCHARGE and STAGE boundaries (they may move faster than
   the cells). */
static fsdem_real fsdem__swe_boundary_wave(const fsdem_swe *s, fsdem_real t) {
    fsdem_real wave = 0;
    int side, i;
    for (side = 0; side < (s->dim == 2 ? 4 : 2); ++side) {
        const fsdem__swe_bnd *b = &s->bnd[side];
        int count = side < 2 ? s->ny : s->nx;
        fsdem_real value, d = side < 2 ? s->dx : s->dy, sgn = (side & 1) ? 1 : -1;
        if (b->type != FSDEM_SWE_BC_DISCHARGE && b->type != FSDEM_SWE_BC_STAGE) continue;
        value = fsdem__swe_series_at(b->t, b->v, b->n, b->value, t);
        for (i = 0; i < count; ++i) {
            int k = side == 0 ? i * s->nx : side == 1 ? i * s->nx + s->nx - 1 : side == 2 ? i : (s->ny - 1) * s->nx + i;
            fsdem_real h = s->eta[k] - s->bed[k], u, v, un, hb, ub, w;
            fsdem__swe_velocity(s, k, &u, &v);
            if (h < 0) h = 0;
            un = side < 2 ? u : v;
            if (b->type == FSDEM_SWE_BC_DISCHARGE) {
                hb = fsdem__swe_inflow_depth(s->g, value, sgn * un + 2 * (fsdem_real)sqrt(s->g * h));
                ub = hb > 0 ? value / hb : 0;
            } else {
                hb = value > s->bed[k] ? value - s->bed[k] : 0;
                ub = (fsdem_real)fabs(sgn * un + 2 * ((fsdem_real)sqrt(s->g * h) - (fsdem_real)sqrt(s->g * hb)));
            }
            w = (ub + (fsdem_real)sqrt(s->g * hb)) / d;
            if (s->dim == 2) w += (fsdem_real)sqrt(s->g * hb) / (side < 2 ? s->dy : s->dx);
            if (w > wave) wave = w;
        }
    }
    return wave;
}

/* Inverse of the stable step without the cfl factor: max wave rate (1/s) and the viscous rate. */
static fsdem_real fsdem__swe_rate(const fsdem_swe *s) {
    fsdem_real rate = s->max_wave, bw = fsdem__swe_boundary_wave(s, s->time), vr;
    if (bw > rate) rate = bw;
    if (s->desc.eddy_viscosity > 0) {
        vr = 2 * s->desc.eddy_viscosity * (1 / (s->dx * s->dx) + (s->dim == 2 ? 1 / (s->dy * s->dy) : 0));
        if (vr > rate) rate = vr;
    }
    return rate;
}

/* Largest dt with Courant number `cfl` when the velocities may also grow by max_accel dt within the
   step: solves max_accel dt^2 + rate dt = cfl. */
static fsdem_real fsdem__swe_dt_for(const fsdem_swe *s, fsdem_real cfl) {
    fsdem_real rate = fsdem__swe_rate(s), a = s->max_accel, dt = s->desc.dt_max, lim;
    if (rate <= 0 && a <= 0) return dt;
    lim = 2 * cfl / (rate + (fsdem_real)sqrt(rate * rate + 4 * a * cfl));
    return lim < dt ? lim : dt;
}

fsdem_result fsdem_swe_stable_dt(const fsdem_swe *s, fsdem_real *dt) {
    if (!s || !dt) return FSDEM_ERR_INVALID_ARG;
    *dt = fsdem__swe_dt_for(s, s->desc.cfl);
    return FSDEM_OK;
}

/* The gauge values h, eta, u, v of every gauge now (as fsdem_swe_sample_state; 0 where it fails). */
static void fsdem__swe_gauge_values(const void *solver, fsdem_real *out) {
    const fsdem_swe *s = (const fsdem_swe *)solver;
    int k;
    for (k = 0; k < s->gauge_count; ++k) {
        fsdem_swe_cell c;
        memset(&c, 0, sizeof c);
        fsdem_swe_sample_state(s, s->gauge[2 * k], s->gauge[2 * k + 1], &c);
        out[4 * k] = c.depth;
        out[4 * k + 1] = c.eta;
        out[4 * k + 2] = c.u;
        out[4 * k + 3] = c.v;
    }
}

/* One step of exactly dt (already validated). */
static fsdem_result fsdem__swe_do_step(fsdem_swe *s, fsdem_real dt) {
    fsdem__swe_ctx c;
    int j, k, side;
    fsdem_real tm = s->time + (fsdem_real)0.5 * dt;
    const double t0 = s->time;
    fsdem__series_begin(&s->gauges);
    memset(&c, 0, sizeof c);
    c.dt = dt;
    c.lx = dt / s->dx;
    c.ly = s->dim == 2 ? dt / s->dy : 0;
    c.idx = 1 / s->dx;
    c.idy = s->dim == 2 ? 1 / s->dy : 0;
    c.g = s->g;
    c.dry = s->desc.dry_depth;
    c.tiny = s->tiny;
    c.rain_dt = s->rain * dt;
    c.manning = s->desc.manning;
    c.visc = s->desc.eddy_viscosity;
    c.order = s->desc.order;
    c.limiter = (int)s->desc.limiter;
    c.two_d = s->dim == 2;
    c.sources = s->sources_used;
    c.friction = s->manning != NULL || s->desc.manning > 0;
    c.bad = -1;
    for (side = 0; side < 4; ++side)
        s->bvalue[side] = fsdem__swe_series_at(s->bnd[side].t, s->bnd[side].v, s->bnd[side].n, s->bnd[side].value, tm);
    if (!c.two_d) {
        fsdem__swe_load_row(s, 0, 0, 0, -1);
        fsdem__swe_row(s, &c, 0);
    } else {
        int wall_lo = s->bnd[FSDEM_SIDE_YMIN].type == FSDEM_SWE_BC_WALL;
        int wall_hi = s->bnd[FSDEM_SIDE_YMAX].type == FSDEM_SWE_BC_WALL;
        fsdem__swe_load_row(s, 0, -1, wall_lo, !wall_lo && s->ny > 1 ? 1 : -1);
        fsdem__swe_load_row(s, 0, 0, 0, -1);
        for (j = 0; j < s->ny; ++j) {
            if (j + 1 < s->ny) fsdem__swe_load_row(s, j + 1, j + 1, 0, -1);
            else fsdem__swe_load_row(s, j, j + 1, wall_hi, !wall_hi && s->ny > 1 ? j - 1 : -1);
            fsdem__swe_row(s, &c, j);
            fsdem__swe_yfaces(s, &c, j);
        }
        fsdem__swe_yfaces(s, &c, s->ny);
    }
    s->vol_boundary += c.bflux;
    s->vol_source += c.rain_dt * s->area * (fsdem_real)(s->n - s->blocked_count);
    for (k = 0; k < s->src_count; ++k) {
        fsdem__swe_src *p = &s->src[k];
        fsdem_real dh, h;
        if (!p->active) continue;
        dh = fsdem__swe_series_at(p->t, p->v, p->n, p->discharge, tm) * dt / s->area;
        h = s->eta[p->cell] - s->bed[p->cell];
        if (dh < -h) dh = h > 0 ? -h : 0;
        s->eta[p->cell] += dh;
        s->vol_source += dh * s->area;
        h += dh;
        if (h < c.dry) s->qx[p->cell] = s->qy[p->cell] = 0;
        else {
            fsdem_real w = (fsdem_real)sqrt(c.g * h) * (c.idx + c.idy) +
                           ((fsdem_real)fabs(s->qx[p->cell]) * c.idx + (fsdem_real)fabs(s->qy[p->cell]) * c.idy) / h;
            if (w > c.wave) c.wave = w;
        }
    }
    if (c.negative) fsdem__swe_repair(s);
    s->fallbacks += c.fallbacks;
    s->max_wave = c.wave;
    s->max_accel = c.g * c.accel;
    s->max_speed = (fsdem_real)sqrt(c.speed2);
    s->max_depth = c.hmax;
    s->wet_cells = c.wet;
    s->time += dt;
    s->dt_last = dt;
    s->steps++;
    if (c.bad >= 0)
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_swe_step: non-finite state in cell %d (i=%d, j=%d) at t=%g s",
                           c.bad, c.bad % s->nx, c.bad / s->nx, (double)s->time);
    if (fsdem__series_step(&s->gauges, t0, s->time) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_IO, "fsdem_swe: could not write the gauge file");
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_step(fsdem_swe *s) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__swe_do_step(s, fsdem__swe_dt_for(s, s->desc.cfl));
}

fsdem_result fsdem_swe_step_dt(fsdem_swe *s, fsdem_real dt) {
    fsdem_real courant;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_step_dt: dt must be > 0 (got %g s)", (double)dt);
    courant = dt * fsdem__swe_rate(s) + dt * dt * s->max_accel;
    if (courant > 1)
        return fsdem__fail(&s->status, FSDEM_ERR_CFL,
                           "fsdem_swe_step_dt: dt = %g s gives Courant number %g > 1 (stable dt at cfl 1: %g s)",
                           (double)dt, (double)courant, (double)fsdem__swe_dt_for(s, 1));
    return fsdem__swe_do_step(s, dt);
}

fsdem_result fsdem_swe_advance(fsdem_swe *s, fsdem_real duration, long long *steps) {
    double t_end;
    fsdem_result res = FSDEM_OK;
    long long count = 0;
    if (steps) *steps = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!(duration >= 0) || !fsdem__finite(duration))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_advance: duration must be >= 0 (got %g s)",
                           (double)duration);
    t_end = s->time + (double)duration;
    while (s->time < t_end) {
        fsdem_real dt = fsdem__swe_dt_for(s, s->desc.cfl);
        double left = t_end - s->time;
        int last = (double)dt >= left;
        res = fsdem__swe_do_step(s, last ? (fsdem_real)left : dt);
        count++;
        if (last) s->time = t_end;
        if (res != FSDEM_OK) break;
    }
    if (steps) *steps = count;
    return res;
}

double fsdem_swe_time(const fsdem_swe *s) { return s ? s->time : 0; }

fsdem_swe_desc fsdem_swe_get_desc(const fsdem_swe *s) {
    fsdem_swe_desc d;
    int k;
    if (!s) {
        memset(&d, 0, sizeof d);
        return d;
    }
    d = s->desc;
    d.rain_rate = s->rain;
    for (k = 0; k < 4; ++k) {
        d.boundary[k].type = s->bnd[k].type;
        d.boundary[k].value = s->bnd[k].value;
    }
    return d;
}

/* ---- >>swe_diag : diagnostics and output ---- */

fsdem_real fsdem_swe_volume(const fsdem_swe *s) {
    double sum = 0;
    int k;
    if (!s) return 0;
    for (k = 0; k < s->n; ++k) sum += (double)(s->eta[k] - s->bed[k]);
    return (fsdem_real)(sum * (double)s->area);
}

fsdem_vec3 fsdem_swe_momentum(const fsdem_swe *s) {
    double mx = 0, my = 0, scale;
    int k;
    if (!s) return fsdem__zero3();
    scale = (double)s->desc.density * (double)s->area;
    for (k = 0; k < s->n; ++k) {
        mx += (double)s->qx[k];
        my += (double)s->qy[k];
    }
    return fsdem_v3((fsdem_real)(mx * scale), (fsdem_real)(my * scale), 0);
}

fsdem_swe_stats fsdem_swe_get_stats(const fsdem_swe *s) {
    fsdem_swe_stats st;
    int k;
    memset(&st, 0, sizeof st);
    if (!s) return st;
    st.steps = s->steps;
    st.time = s->time;
    st.dt = s->dt_last;
    st.max_depth = s->max_depth;
    st.max_speed = s->max_speed;
    st.wet_cells = s->wet_cells;
    st.boundary_volume = s->vol_boundary;
    st.source_volume = s->vol_source;
    st.clipped_volume = s->vol_clipped;
    st.predictor_fallbacks = s->fallbacks;
    st.memory_bytes = sizeof *s + s->block_bytes + (s->manning ? sizeof(fsdem_real) * (size_t)s->n : 0) +
                      sizeof(fsdem__swe_src) * (size_t)s->src_capacity +
                      2 * sizeof(fsdem_real) * (size_t)s->gauge_capacity;
    for (k = 0; k < 4; ++k) st.memory_bytes += 2 * sizeof(fsdem_real) * (size_t)s->bnd[k].n;
    for (k = 0; k < s->src_count; ++k) st.memory_bytes += 2 * sizeof(fsdem_real) * (size_t)s->src[k].n;
    return st;
}

fsdem_result fsdem_swe_write_csv(const fsdem_swe *s, const char *path) {
    FILE *fp;
    int k, bad;
    if (!s || !path) return FSDEM_ERR_INVALID_ARG;
    if (!(fp = fopen(path, "w"))) return FSDEM_ERR_IO;
    fprintf(fp, s->dim == 2 ? "x,y,bed,h,eta,u,v\n" : "x,bed,h,eta,u\n");
    for (k = 0; k < s->n; ++k) {
        fsdem_real x, y, u, v;
        fsdem__swe_centre(s, k, &x, &y);
        fsdem__swe_velocity(s, k, &u, &v);
        if (s->dim == 2)
            fprintf(fp, "%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n", (double)x, (double)y, (double)s->bed[k],
                    (double)(s->eta[k] - s->bed[k]), (double)s->eta[k], (double)u, (double)v);
        else
            fprintf(fp, "%.10g,%.10g,%.10g,%.10g,%.10g\n", (double)x, (double)s->bed[k],
                    (double)(s->eta[k] - s->bed[k]), (double)s->eta[k], (double)u);
    }
    bad = ferror(fp);
    return (fclose(fp) != 0 || bad) ? FSDEM_ERR_IO : FSDEM_OK;
}

fsdem_result fsdem_swe_add_gauge(fsdem_swe *s, fsdem_real x, fsdem_real y, int *id) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (s->gauges.file)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_add_gauge: close the gauge file first");
    if (fsdem_swe_cell_at(s, x, y) < 0)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_DOMAIN, "fsdem_swe_add_gauge: point (%g, %g) is outside the grid",
                           (double)x, (double)y);
    if (s->blocked && s->blocked[fsdem_swe_cell_at(s, x, y)])
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_add_gauge: point (%g, %g) is in a blocked cell",
                           (double)x, (double)y);
    if (fsdem__grow(&s->allocator, (void **)&s->gauge, &s->gauge_capacity, s->gauge_count, s->gauge_count + 1,
                    2 * sizeof(fsdem_real)) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_swe_add_gauge: out of memory");
    s->gauge[2 * s->gauge_count] = x;
    s->gauge[2 * s->gauge_count + 1] = y;
    if (id) *id = s->gauge_count;
    s->gauge_count++;
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_gauge(const fsdem_swe *s, int id, fsdem_swe_cell *out) {
    if (!s || !out) return FSDEM_ERR_INVALID_ARG;
    if (id < 0 || id >= s->gauge_count) return FSDEM_ERR_NOT_FOUND;
    return fsdem_swe_sample_state(s, s->gauge[2 * id], s->gauge[2 * id + 1], out);
}

fsdem_result fsdem_swe_gauges_open(fsdem_swe *s, const char *path, fsdem_real interval) {
    char *header;
    size_t size;
    int k, n = 1;
    fsdem_result res;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (s->gauge_count == 0)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_gauges_open: add gauges first");
    if (!(interval >= 0) || !fsdem__finite(interval))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_gauges_open: interval must be >= 0 (got %g s)",
                           (double)interval);
    if (s->gauges.file) fsdem_swe_gauges_close(s);
    size = 2 + 48 * (size_t)s->gauge_count;
    header = (char *)fsdem__alloc(&s->allocator, size);
    if (!header) return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_swe_gauges_open: out of memory");
    header[0] = 't';
    header[1] = '\0';
    for (k = 0; k < s->gauge_count; ++k)
        n += snprintf(header + n, size - (size_t)n, ",h_%d,eta_%d,u_%d,v_%d", k, k, k, k);
    res = fsdem__series_open(&s->gauges, &s->allocator, path, header, 4 * s->gauge_count, s->time, interval,
                             fsdem__swe_gauge_values, s);
    fsdem__free(&s->allocator, header, size);
    if (res != FSDEM_OK)
        return fsdem__fail(&s->status, res, "fsdem_swe_gauges_open: cannot open '%s'", path ? path : "(null)");
    return fsdem__ok(&s->status);
}

fsdem_result fsdem_swe_gauges_close(fsdem_swe *s) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__series_close(&s->gauges, &s->allocator) == FSDEM_OK
               ? fsdem__ok(&s->status)
               : fsdem__fail(&s->status, FSDEM_ERR_IO, "fsdem_swe_gauges_close: write error");
}

fsdem_real fsdem_swe_bed_sdf(void *user, fsdem_vec3 p, fsdem_vec3 *normal) {
    const fsdem_swe *swe = (const fsdem_swe *)user;
    if (!swe) { /* no bed: far away, so a wall made with a NULL user never touches */
        if (normal) *normal = fsdem_v3(0, 0, 1);
        return (fsdem_real)FLT_MAX;
    }
    const fsdem_real x0 = swe->desc.x_min + swe->dx / 2, x1 = swe->desc.x_min + (swe->nx - (fsdem_real)0.5) * swe->dx;
    const fsdem_real y0 = swe->desc.y_min + swe->dy / 2, y1 = swe->desc.y_min + (swe->ny - (fsdem_real)0.5) * swe->dy;
    fsdem_real x = p.x < x0 ? x0 : p.x > x1 ? x1 : p.x, y = p.y < y0 ? y0 : p.y > y1 ? y1 : p.y, gx, gy, len;
    fsdem_swe_cell c0, cm, cp;
    fsdem_swe_sample_state(swe, x, y, &c0);
    /* bed slope from centred differences over one cell */
    fsdem_swe_sample_state(swe, x - swe->dx / 2, y, &cm);
    fsdem_swe_sample_state(swe, x + swe->dx / 2, y, &cp);
    gx = (cp.bed - cm.bed) / swe->dx;
    gy = 0;
    if (swe->dim == 2) {
        fsdem_swe_sample_state(swe, x, y - swe->dy / 2, &cm);
        fsdem_swe_sample_state(swe, x, y + swe->dy / 2, &cp);
        gy = (cp.bed - cm.bed) / swe->dy;
    }
    len = (fsdem_real)sqrt(1 + gx * gx + gy * gy);
    *normal = fsdem_v3(-gx / len, -gy / len, 1 / len);
    return (p.z - c0.bed) / len;
}

/* ===== >>impl_couple_swe : SWE-DEM floating debris =================================================

   Contents: >>couple_swe_object (desc, creation), >>couple_swe_geometry (submerged parts of a
   sphere), >>couple_swe_forces (seed 003 Eq. 5-8), >>couple_swe_step (coupled time stepping). The
   coupler reaches the solvers through their coupling functions only (>>doc). */

/* ---- >>couple_swe_object : desc, creation ---- */

struct fsdem_swe_dem {
    fsdem_swe_dem_desc desc;
    fsdem__status status;
    fsdem_allocator allocator;
    fsdem_real rho, g, dry;        /* the SWE's density, |g| and dry depth */
    fsdem_swe_dem_force *force;    /* one per DEM particle of the last update */
    int force_capacity, records;   /* records: the particles of the last update */
    long long steps, substeps, substeps_total;
    fsdem_real dt_last;
    int in_water;
    fsdem_vec3 impulse;            /* N s, given to the water */
    fsdem_vec3 *reaction;          /* N, horizontal force on each sphere whose reaction the water took */
};

fsdem_swe_dem_desc fsdem_swe_dem_desc_default(void) {
    fsdem_swe_dem_desc d;
    memset(&d, 0, sizeof d);
    d.beta = (fsdem_real)1.1;
    d.two_way = 1;
    d.heave_damping = 0;
    d.max_substeps = 100000;
    return d;
}

fsdem_result fsdem_swe_dem_desc_check(const fsdem_swe_dem_desc *d, char *msg, size_t size) {
    fsdem_dem_desc dd;
    fsdem_vec3 g;
    fsdem_real gs;
    if (!d) return fsdem__reject(msg, size, "fsdem_swe_dem_desc is NULL");
    if (!d->swe || !d->dem) return fsdem__reject(msg, size, "fsdem_swe_dem_desc.swe and .dem must both be set");
    dd = fsdem_dem_get_desc(d->dem);
    if (dd.dim != 3)
        return fsdem__reject(msg, size, "fsdem_swe_dem_desc.dem must be 3D (spheres, z vertical); it has dim %d", dd.dim);
    g = dd.gravity;
    gs = -fsdem_swe_get_desc(d->swe).gravity.z;
    if (g.x != 0 || g.y != 0 || !(fabs(g.z + gs) <= 1e-12 * gs))
        return fsdem__reject(msg, size, "fsdem_swe_dem_desc: the DEM gravity (%g, %g, %g) must be (0, 0, -g) with the SWE's g = %g m/s^2",
                             (double)g.x, (double)g.y, (double)g.z, (double)gs);
    if (!(d->beta > 0) || !fsdem__finite(d->beta))
        return fsdem__reject(msg, size, "fsdem_swe_dem_desc.beta must be > 0 (got %g)", (double)d->beta);
    if (!(d->heave_damping >= 0) || !fsdem__finite(d->heave_damping))
        return fsdem__reject(msg, size, "fsdem_swe_dem_desc.heave_damping must be >= 0 (got %g)",
                             (double)d->heave_damping);
    if (d->max_substeps < 1)
        return fsdem__reject(msg, size, "fsdem_swe_dem_desc.max_substeps must be >= 1 (got %lld)", d->max_substeps);
    return FSDEM_OK;
}

fsdem_result fsdem_swe_dem_create(const fsdem_swe_dem_desc *desc, fsdem_swe_dem **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_allocator al;
    fsdem_swe_dem *c;
    fsdem_result res;
    if (out) *out = NULL;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    res = fsdem_swe_dem_desc_check(desc, msg, sizeof msg);
    if (res == FSDEM_OK) al = fsdem_dem_get_desc(desc->dem).allocator;
    c = (fsdem_swe_dem *)fsdem__object_new(res, msg, desc ? desc->log : NULL, desc ? desc->log_user : NULL,
                                           res == FSDEM_OK ? &al : NULL, sizeof *c, "fsdem_swe_dem_create", &res);
    if (!c) return res;
    {
        const fsdem_swe_desc sd = fsdem_swe_get_desc(desc->swe);
        c->rho = sd.density;
        c->g = -sd.gravity.z;
        c->dry = sd.dry_depth;
    }
    c->desc = *desc;
    c->allocator = al;
    c->status.log = desc->log;
    c->status.log_user = desc->log_user;
    *out = c;
    return FSDEM_OK;
}

void fsdem_swe_dem_destroy(fsdem_swe_dem *c) {
    fsdem_allocator al;
    if (!c) return;
    al = c->allocator;
    fsdem__free(&al, c->force, sizeof(fsdem_swe_dem_force) * (size_t)c->force_capacity);
    fsdem__free(&al, c->reaction, sizeof(fsdem_vec3) * (size_t)c->force_capacity);
    fsdem__free(&al, c, sizeof *c);
}

const char *fsdem_swe_dem_last_error(const fsdem_swe_dem *c) { return c ? c->status.message : "fsdem_swe_dem is NULL"; }

fsdem_swe_dem_desc fsdem_swe_dem_get_desc(const fsdem_swe_dem *c) {
    fsdem_swe_dem_desc d;
    if (c) return c->desc;
    memset(&d, 0, sizeof d);
    return d;
}

/* ---- >>couple_swe_geometry : submerged parts of a sphere ---- */

/* Submerged part of a vertical circle of radius r centred at height zc under a surface at eta: its
   area and its first moment M = int (eta - z) w(z) dz, so the hydrostatic force on it is rho g M.
   With z = zc - r cos(phi) and w = 2 r sin(phi) both integrals are closed forms in the angle theta of
   the waterline: area r^2 (theta - sin cos), M = 2 r^2 [(eta - zc)(theta - sin cos)/2 + r sin^3 / 3]. */
static void fsdem__swe_dem_submerged_disc(fsdem_real r, fsdem_real zc, fsdem_real eta, fsdem_real *area, fsdem_real *moment) {
    fsdem_real top = eta < zc + r ? eta : zc + r, c, s, th;
    if (top <= zc - r) {
        *area = *moment = 0;
        return;
    }
    c = (zc - top) / r;
    c = c < -1 ? -1 : c > 1 ? 1 : c;
    th = (fsdem_real)acos(c);
    s = (fsdem_real)sin(th);
    *area = r * r * (th - s * c);
    *moment = 2 * r * r * ((eta - zc) * (th - s * c) / 2 + r * s * s * s / 3);
}

/* Volume of the part of a sphere (radius r, centre height zc) below the surface eta: a cap. */
static fsdem_real fsdem__swe_dem_submerged_sphere(fsdem_real r, fsdem_real zc, fsdem_real eta) {
    fsdem_real s = eta - (zc - r);
    if (s <= 0) return 0;
    if (s > 2 * r) s = 2 * r;
    return (fsdem_real)FSDEM__PI * s * s * (3 * r - s) / 3;
}

/* Water at p shifted by `shift` along a horizontal axis (0: x, 1: y); off the grid it is `fallback`. */
static fsdem_swe_cell fsdem__swe_dem_water_at(const fsdem_swe *swe, fsdem_vec3 p, int axis, fsdem_real shift,
                                              fsdem_swe_cell fallback) {
    fsdem_swe_cell cell;
    fsdem_real x = p.x + (axis == 0 ? shift : 0), y = p.y + (axis == 1 ? shift : 0);
    return fsdem_swe_sample_state(swe, x, y, &cell) == FSDEM_OK ? cell : fallback;
}

/* Buoyancy (Eq. 5) and heave damping of sphere i at its current height and vertical speed, against
   the water surface held in out->surface; updates `out` and returns the vertical force (N). */
static fsdem_real fsdem__swe_dem_vertical(const fsdem_swe_dem *c, const fsdem_dem_particles *pv, int i,
                                          fsdem_swe_dem_force *out) {
    const fsdem_real rho = c->rho, g = c->g, r = pv->radius[i], z = pv->position[i].z;
    out->submerged_volume = fsdem__swe_dem_submerged_sphere(r, z, out->surface);
    out->buoyancy = fsdem_v3(0, 0, rho * g * out->submerged_volume);
    out->heave = fsdem__zero3();
    if (c->desc.heave_damping > 0) {
        /* critical damping of the hydrostatic spring rho g A_waterplane of the bobbing */
        fsdem_real a2 = r * r - (out->surface - z) * (out->surface - z);
        if (a2 > 0)
            out->heave.z = -2 * c->desc.heave_damping * (fsdem_real)sqrt(rho * g * (fsdem_real)FSDEM__PI * a2 * pv->mass[i]) *
                           pv->velocity[i].z;
    }
    return out->buoyancy.z + out->heave.z;
}

/* ---- >>couple_swe_forces : seed 003 Eq. 5-8 ---- */

fsdem_result fsdem_swe_dem_update_forces(fsdem_swe_dem *c) {
    fsdem_swe *swe;
    fsdem_dem_particles pv;
    fsdem_dem_coupling loads;
    fsdem_real beta;
    int i, a, axes, n;
    if (!c) return FSDEM_ERR_INVALID_ARG;
    swe = c->desc.swe;
    beta = c->desc.beta;
    axes = fsdem_swe_get_desc(swe).dim;
    pv = fsdem_dem_get_particles(c->desc.dem);
    n = pv.count;
    if (n > c->force_capacity) {
        fsdem_swe_dem_force *force = (fsdem_swe_dem_force *)fsdem__alloc(&c->allocator, sizeof *force * (size_t)n);
        fsdem_vec3 *reaction = (fsdem_vec3 *)fsdem__alloc(&c->allocator, sizeof *reaction * (size_t)n);
        if (!force || !reaction) {
            fsdem__free(&c->allocator, force, sizeof *force * (size_t)n);
            fsdem__free(&c->allocator, reaction, sizeof *reaction * (size_t)n);
            return fsdem__fail(&c->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_swe_dem: out of memory for the forces of %d particles", n);
        }
        fsdem__free(&c->allocator, c->force, sizeof *force * (size_t)c->force_capacity);
        fsdem__free(&c->allocator, c->reaction, sizeof *reaction * (size_t)c->force_capacity);
        c->force = force;
        c->reaction = reaction;
        c->force_capacity = n;
    }
    loads = fsdem_dem_get_coupling(c->desc.dem);
    if (c->desc.two_way) fsdem_swe_clear_forces(swe);
    c->in_water = 0;
    for (i = 0; i < n; ++i) {
        fsdem_swe_dem_force *out = &c->force[i];
        const fsdem_vec3 p = pv.position[i], w = pv.velocity[i];
        const fsdem_real r = pv.radius[i];
        fsdem_swe_cell centre, back[2], front[2], flow;
        fsdem_vec3 horizontal;
        memset(out, 0, sizeof *out);
        out->id = pv.id[i];
        loads.force[i] = c->reaction[i] = fsdem__zero3();
        if (pv.fixed[i] || fsdem_swe_sample_state(swe, p.x, p.y, &centre) != FSDEM_OK) continue;
        /* the water at the centre, and at the back (-r) and front (+r) along each horizontal axis; the
           flow velocity is the centre's, or that of the deepest side while a front reaches the sphere */
        flow = centre;
        for (a = 0; a < axes; ++a) {
            back[a] = fsdem__swe_dem_water_at(swe, p, a, -r, centre);
            front[a] = fsdem__swe_dem_water_at(swe, p, a, r, centre);
            if (flow.depth < c->dry && back[a].depth > flow.depth) flow = back[a];
            if (flow.depth < c->dry && front[a].depth > flow.depth) flow = front[a];
        }
        if (flow.depth < c->dry) continue;
        out->in_water = 1;
        c->in_water++;
        out->surface = centre.eta;
        for (a = 0; a < axes; ++a) {
            /* Eq. 6-7 along axis a */
            fsdem_real area_b, area_f, m_b, m_f, rel, hydro, dyn;
            fsdem__swe_dem_submerged_disc(r, p.z, back[a].eta, &area_b, &m_b);
            fsdem__swe_dem_submerged_disc(r, p.z, front[a].eta, &area_f, &m_f);
            rel = beta * (a == 0 ? flow.u : flow.v) - (a == 0 ? w.x : w.y);
            hydro = c->rho * c->g * (m_b - m_f);
            dyn = c->rho * rel * (rel < 0 ? -rel : rel) * (rel > 0 ? area_b : area_f);
            if (a == 0) {
                out->hydrostatic.x = hydro;
                out->dynamic.x = dyn;
                out->frontal_area = area_f;
            } else {
                out->hydrostatic.y = hydro;
                out->dynamic.y = dyn;
            }
        }
        horizontal = fsdem__add(out->hydrostatic, out->dynamic);
        if (c->desc.two_way) {
            /* Eq. 8: the reaction -F_h as a momentum source under the sphere; a force whose reaction
               no wet cell can take is dropped, so momentum is exchanged, never created */
            int taken = 0;
            fsdem_swe_add_force(swe, p, r, fsdem__scale(horizontal, -1), &taken);
            if (!taken) out->hydrostatic = out->dynamic = horizontal = fsdem__zero3();
            c->reaction[i] = horizontal;
        }
        horizontal.z = fsdem__swe_dem_vertical(c, &pv, i, out);
        loads.force[i] = horizontal;
    }
    c->records = n;
    return fsdem__ok(&c->status);
}

/* The record of DEM particle `index` (-1: none). */
static int fsdem__swe_dem_record(const fsdem_swe_dem *c, int index) {
    return c->records ? fsdem__dem_record_of(c->desc.dem, index, &c->force[0].id, sizeof *c->force, c->records) : -1;
}

fsdem_result fsdem_swe_dem_get_force(const fsdem_swe_dem *c, int index, fsdem_swe_dem_force *out) {
    int k;
    if (!c || !out) return FSDEM_ERR_INVALID_ARG;
    if ((k = fsdem__swe_dem_record(c, index)) < 0)
        return fsdem__fail((fsdem__status *)&c->status, FSDEM_ERR_NOT_FOUND,
                           "fsdem_swe_dem_get_force: no particle %d in the last update", index);
    *out = c->force[k];
    return FSDEM_OK;
}

/* ---- >>couple_swe_step : coupled time stepping ---- */

/* fsdem_dem_substep_fn: buoyancy and heave damping of the spheres in water refreshed for the heights
   of every DEM force evaluation, against the water surface held over the fluid step. */
static fsdem_result fsdem__swe_dem_refresh(void *user, fsdem_dem *dem, double time) {
    fsdem_swe_dem *c = (fsdem_swe_dem *)user;
    const fsdem_dem_particles pv = fsdem_dem_get_particles(dem);
    const fsdem_dem_coupling loads = fsdem_dem_get_coupling(dem);
    int i;
    (void)time;
    for (i = 0; i < pv.count; ++i)
        if (c->force[i].in_water) loads.force[i].z = fsdem__swe_dem_vertical(c, &pv, i, &c->force[i]);
    return FSDEM_OK;
}

/* One coupled step of dt: the DEM substep count is checked before anything moves; `adaptive` steps
   the water with fsdem_swe_step (whose dt is the stable dt computed by the caller), otherwise with
   fsdem_swe_step_dt. */
static fsdem_result fsdem__swe_dem_step(fsdem_swe_dem *c, fsdem_real dt, int adaptive) {
    fsdem_result res;
    long long k, substeps = 0;
    int count;
    res = fsdem__dem_substeps_within(c->desc.dem, dt, c->desc.max_substeps, &c->status, "fsdem_swe_dem");
    if (res != FSDEM_OK) return res;
    res = fsdem_swe_dem_update_forces(c);
    if (res != FSDEM_OK) return res;
    res = adaptive ? fsdem_swe_step(c->desc.swe) : fsdem_swe_step_dt(c->desc.swe, dt);
    if (res != FSDEM_OK) return fsdem__fail(&c->status, res, "fsdem_swe_dem: shallow-water step: %s", fsdem_swe_last_error(c->desc.swe));
    count = fsdem_dem_get_particles(c->desc.dem).count;
    for (k = 0; k < c->force_capacity && k < count; ++k)
        c->impulse = fsdem__madd(c->impulse, c->reaction[k], -dt);
    res = fsdem_dem_advance_with(c->desc.dem, dt, fsdem__swe_dem_refresh, c, &substeps);
    c->steps++;
    c->dt_last = dt;
    c->substeps = substeps;
    c->substeps_total += substeps;
    if (res != FSDEM_OK) return fsdem__fail(&c->status, res, "fsdem_swe_dem: DEM substeps: %s", fsdem_dem_last_error(c->desc.dem));
    return fsdem__ok(&c->status);
}

fsdem_result fsdem_swe_dem_step(fsdem_swe_dem *c) {
    fsdem_real dt = 0;
    if (!c) return FSDEM_ERR_INVALID_ARG;
    fsdem_swe_stable_dt(c->desc.swe, &dt);
    return fsdem__swe_dem_step(c, dt, 1);
}

fsdem_result fsdem_swe_dem_step_dt(fsdem_swe_dem *c, fsdem_real dt) {
    if (!c) return FSDEM_ERR_INVALID_ARG;
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(&c->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_dem_step_dt: dt must be > 0 (got %g s)", (double)dt);
    return fsdem__swe_dem_step(c, dt, 0);
}

fsdem_result fsdem_swe_dem_advance(fsdem_swe_dem *c, fsdem_real duration, long long *steps) {
    double end;
    long long n = 0;
    fsdem_result res = FSDEM_OK;
    if (steps) *steps = 0;
    if (!c) return FSDEM_ERR_INVALID_ARG;
    if (!(duration >= 0) || !fsdem__finite(duration))
        return fsdem__fail(&c->status, FSDEM_ERR_INVALID_ARG, "fsdem_swe_dem_advance: duration must be >= 0 (got %g s)",
                           (double)duration);
    end = fsdem_swe_time(c->desc.swe) + (double)duration;
    while (res == FSDEM_OK && fsdem_swe_time(c->desc.swe) < end) {
        fsdem_real dt = 0;
        const double left = end - fsdem_swe_time(c->desc.swe);
        fsdem_swe_stable_dt(c->desc.swe, &dt);
        res = (double)dt >= left ? fsdem__swe_dem_step(c, (fsdem_real)left, 0) : fsdem__swe_dem_step(c, dt, 1);
        ++n;
    }
    if (steps) *steps = n;
    return res;
}

fsdem_result fsdem_swe_dem_stable_dt(const fsdem_swe_dem *c, fsdem_real *dt) {
    if (!c) return FSDEM_ERR_INVALID_ARG;
    return fsdem_swe_stable_dt(c->desc.swe, dt);
}

double fsdem_swe_dem_time(const fsdem_swe_dem *c) { return c ? fsdem_swe_time(c->desc.swe) : 0; }

fsdem_swe_dem_stats fsdem_swe_dem_get_stats(const fsdem_swe_dem *c) {
    fsdem_swe_dem_stats st;
    memset(&st, 0, sizeof st);
    if (!c) return st;
    st.steps = c->steps;
    st.time = fsdem_swe_time(c->desc.swe);
    st.dt = c->dt_last;
    st.substeps = c->substeps;
    st.substeps_total = c->substeps_total;
    st.in_water = c->in_water;
    st.impulse_to_water = c->impulse;
    return st;
}

/* ===== >>impl_mps : MPS solver ===================================================================== */

/* Contents: the object below; >>mps_desc (defaults, validation, lattice constants, creation),
   >>mps_particles (storage, lattice fills, walls, obstacles), >>mps_neighbours (cell-list search
   into sorted neighbour rows), >>mps_operators (number density, gradient, divergence, Laplacian,
   surface), >>mps_step (predictor, pressure equation, corrector, collisions, time stepping),
   >>mps_views (views, statistics), >>mps_probes (pressure, water level, obstacle force, gauges). */

/* A box obstacle (fsdem_mps_add_box_obstacle) and the force of the fluid on it in the last step. */
typedef struct fsdem__mps_obst {
    fsdem_vec3 lo, hi;
    fsdem_vec3 force; /* N (N/m in 2D) */
} fsdem__mps_obst;

struct fsdem_mps {
    fsdem_mps_desc desc;
    fsdem__status status;
    fsdem_allocator allocator;
    size_t bytes;                 /* held, besides the pcg */
    int dim;
    fsdem_real r0, re;
    fsdem_real n0, lambda, f0;    /* lattice constants (>>mps_desc) */
    int layers;                   /* WALL + DUMMY layers of a solid: ceil(re/r0) */
    /* particles, structure of arrays, `cap` allocated */
    int n, cap;
    fsdem_vec3 *x, *v, *us;       /* position, velocity, predicted velocity u* */
    fsdem_vec3 *shift;            /* particle shift of the step (desc.shifting) */
    fsdem_real *p, *eps, *nd;     /* pressure, porosity, number density */
    fsdem_vec3 *fext;             /* external force of a coupler (N; N/m in 2D), FLUID particles */
    fsdem_vec3 *gradp;            /* pressure gradient of the last corrector (Pa/m), FLUID particles */
    int external;                 /* fext may be nonzero (fsdem_mps_get_coupling handed it out) */
    fsdem_real *div, *b, *sol;    /* divergence of u*, right-hand side and solution (by unknown) */
    unsigned char *kind, *surf;
    int *body;                    /* the obstacle a WALL or DUMMY particle belongs to, or -1 */
    int *unknown;                 /* row of each particle in the pressure equation, or -1 */
    int *row_particle;            /* particle of each row */
    int counts[3];                /* particles per kind */
    /* neighbours: rows of every non-DUMMY particle (DUMMY rows are empty), columns ascending */
    fsdem_cellgrid grid;
    int *pairs, pair_cap;         /* 2 per pair found by the cell scan */
    int *nb_start;                /* n + 1 */
    int *tmp_start, *cursor;      /* n + 1 each: rows by column and fill cursors of the build */
    int *nb, *tmp_nb, nb_cap;     /* neighbour indices */
    fsdem_real *nbw, *tmp_w;      /* w_ij (Eq. 6) */
    long long pair_count;
    /* pressure matrix */
    int *a_start, *a_col, a_cap;
    fsdem_real *a_val;
    int rows;
    fsdem_pcg *pcg;
    /* obstacles */
    fsdem__mps_obst *obst;
    int obst_n, obst_cap;
    fsdem__gauges gauges;
    /* time and statistics */
    double time;
    long long steps, iters_total;
    fsdem_real dt_last, residual;
    int iters, surface_count;
    double sec_total, sec_pressure;
};

/* ---- >>mps_desc : defaults, validation, lattice constants, creation ---- */

fsdem_mps_desc fsdem_mps_desc_default(int dim) {
    fsdem_mps_desc d;
    memset(&d, 0, sizeof d);
    d.dim = dim;
    d.r0 = (fsdem_real)0.01;
    d.re = 0;
    d.density = 1000;
    d.viscosity = (fsdem_real)1e-6;
    d.gravity = dim == 3 ? fsdem_v3(0, 0, (fsdem_real)-9.81) : fsdem_v3(0, (fsdem_real)-9.81, 0);
    d.gamma = (fsdem_real)0.01;
    d.beta = (fsdem_real)0.8;
    d.alpha = (fsdem_real)0.9;
    d.cfl = (fsdem_real)0.2;
    d.dt_max = (fsdem_real)1e-3;
    d.domain_min = fsdem_v3(0, 0, 0);
    d.domain_max = fsdem_v3(1, 1, 1);
    d.gradient = FSDEM_MPS_GRADIENT_MODEL_MIN;
    d.clamp_negative_pressure = 1;
    d.collision_distance = (fsdem_real)0.8;
    d.restitution = (fsdem_real)0.2;
    d.shifting = 0;
    d.pressure_precond = FSDEM_PRECOND_AUTO;
#ifdef FSDEM_USE_FLOAT
    d.pressure_tolerance = (fsdem_real)1e-5;
#else
    d.pressure_tolerance = (fsdem_real)1e-8;
#endif
    d.pressure_max_iterations = 1000;
    return d;
}

/* Validation shared by fsdem_mps_desc_check and fsdem_mps_create; names the field. */
static fsdem_result fsdem__mps_check(const fsdem_mps_desc *d, char *msg, size_t size) {
    int a;
    if (msg && size) msg[0] = '\0';
    if (d->dim != 2 && d->dim != 3) return fsdem__reject(msg, size, "fsdem_mps_desc.dim = %d must be 2 or 3", d->dim);
    if (!(d->r0 > 0) || !fsdem__finite(d->r0))
        return fsdem__reject(msg, size, "fsdem_mps_desc.r0 = %g m must be > 0 and finite", (double)d->r0);
    if (d->re != 0 && (!(d->re >= 2 * d->r0) || !fsdem__finite(d->re)))
        return fsdem__reject(msg, size, "fsdem_mps_desc.re = %g m must be 0 (4.1 r0) or >= 2 r0 = %g m", (double)d->re,
                             (double)(2 * d->r0));
    if (d->re > 20 * d->r0)
        return fsdem__reject(msg, size, "fsdem_mps_desc.re = %g m must be <= 20 r0 = %g m", (double)d->re,
                             (double)(20 * d->r0));
    if (!(d->density > 0) || !fsdem__finite(d->density))
        return fsdem__reject(msg, size, "fsdem_mps_desc.density = %g kg/m^3 must be > 0", (double)d->density);
    if (!(d->viscosity >= 0) || !fsdem__finite(d->viscosity))
        return fsdem__reject(msg, size, "fsdem_mps_desc.viscosity = %g m^2/s must be >= 0", (double)d->viscosity);
    if (fsdem__check_gravity("fsdem_mps_desc", d->gravity, d->dim, msg, size) != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    if (!(d->gamma >= 0 && d->gamma <= 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.gamma = %g must be in [0, 1]", (double)d->gamma);
    if (!(d->beta > 0 && d->beta < 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.beta = %g must be in (0, 1)", (double)d->beta);
    if (!(d->alpha > 0) || !fsdem__finite(d->alpha))
        return fsdem__reject(msg, size, "fsdem_mps_desc.alpha = %g must be > 0", (double)d->alpha);
    if (!(d->cfl > 0 && d->cfl <= 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.cfl = %g must be in (0, 1]", (double)d->cfl);
    if (fsdem__check_dt_max("fsdem_mps_desc", d->dt_max, d->gravity, msg, size) != FSDEM_OK) return FSDEM_ERR_INVALID_ARG;
    if (!fsdem__finite3(d->domain_min) || !fsdem__finite3(d->domain_max))
        return fsdem__reject(msg, size, "fsdem_mps_desc.domain_min/domain_max must be finite");
    for (a = 0; a < d->dim; ++a) {
        if (!(fsdem__comp(d->domain_max, a) > fsdem__comp(d->domain_min, a)))
            return fsdem__reject(msg, size, "fsdem_mps_desc.domain_max.%c = %g must exceed domain_min.%c = %g", "xyz"[a],
                                 (double)fsdem__comp(d->domain_max, a), "xyz"[a], (double)fsdem__comp(d->domain_min, a));
        if (!(d->r0 <= fsdem__comp(d->domain_max, a) - fsdem__comp(d->domain_min, a)))
            return fsdem__reject(msg, size, "fsdem_mps_desc.r0 = %g m is larger than the domain along %c (%g m)", (double)d->r0,
                                 "xyz"[a], (double)(fsdem__comp(d->domain_max, a) - fsdem__comp(d->domain_min, a)));
    }
    if ((int)d->gradient < 0 || (int)d->gradient > 2)
        return fsdem__reject(msg, size, "fsdem_mps_desc.gradient = %d is not a fsdem_mps_gradient_model", (int)d->gradient);
    if ((int)d->model < 0 || (int)d->model > 1)
        return fsdem__reject(msg, size, "fsdem_mps_desc.model = %d is not a fsdem_mps_model", (int)d->model);
    if (!(d->collision_distance >= 0 && d->collision_distance < 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.collision_distance = %g must be in [0, 1) (units of r0)",
                             (double)d->collision_distance);
    if (!(d->restitution >= 0 && d->restitution <= 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.restitution = %g must be in [0, 1]", (double)d->restitution);
    if (!(d->shifting >= 0 && d->shifting <= 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.shifting = %g must be in [0, 1]", (double)d->shifting);
    if ((int)d->pressure_precond < 0 || (int)d->pressure_precond > 4)
        return fsdem__reject(msg, size, "fsdem_mps_desc.pressure_precond = %d must be a fsdem_precond for a CSR matrix "
                             "(AUTO, NONE, JACOBI, IC0, MIC0)", (int)d->pressure_precond);
    if (!(d->pressure_tolerance > 0 && d->pressure_tolerance < 1))
        return fsdem__reject(msg, size, "fsdem_mps_desc.pressure_tolerance = %g must be in (0, 1)",
                             (double)d->pressure_tolerance);
    if (d->pressure_max_iterations < 1)
        return fsdem__reject(msg, size, "fsdem_mps_desc.pressure_max_iterations = %d must be >= 1",
                             d->pressure_max_iterations);
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        return fsdem__reject(msg, size, "fsdem_mps_desc.allocator needs both alloc and free, or neither");
    return FSDEM_OK;
}

fsdem_result fsdem_mps_desc_check(const fsdem_mps_desc *desc, char *message, size_t message_size) {
    if (!desc) return fsdem__reject(message, message_size, "fsdem_mps_desc is NULL");
    return fsdem__mps_check(desc, message, message_size);
}

/* n0 (Eq. 7), lambda (Eq. 11) of a particle inside the full r0 lattice, and |F| (Eq. 15) of a
   particle on its flat free surface (the lattice points at or below it along the last axis): the
   reference values of the PPE source, the Laplacian and the surface test (Eq. 14-16). */
static void fsdem__mps_lattice(fsdem_mps *s) {
    const int m = (int)ceil((double)(s->re / s->r0)), kz = s->dim == 3 ? m : 0;
    double n0 = 0, l = 0, f = 0;
    int i, j, k;
    for (k = -kz; k <= kz; ++k)
        for (j = -m; j <= m; ++j)
            for (i = -m; i <= m; ++i) {
                const fsdem_real r = s->r0 * (fsdem_real)sqrt((double)(i * i + j * j + k * k));
                const fsdem_real w = fsdem__kernel_mps(r, s->re);
                const int up = s->dim == 3 ? k : j;
                if (i == 0 && j == 0 && k == 0) continue;
                n0 += w;
                l += w * r * r;
                if (up <= 0) f += w * (double)up * s->r0 / r;
            }
    s->n0 = (fsdem_real)n0;
    s->lambda = (fsdem_real)(l / n0);
    s->f0 = (fsdem_real)(fabs(f) * s->dim / n0);
}

fsdem_result fsdem_mps_create(const fsdem_mps_desc *desc, fsdem_mps **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_result r;
    fsdem_mps *s;
    fsdem_pcg_desc pd;
    if (out) *out = NULL;
    if (!desc || !out) return FSDEM_ERR_INVALID_ARG;
    r = fsdem__mps_check(desc, msg, sizeof msg);
    s = (fsdem_mps *)fsdem__object_new(r, msg, desc->log, desc->log_user, &desc->allocator, sizeof *s, "fsdem_mps_create", &r);
    if (!s) return r;
    s->desc = *desc;
    s->allocator = desc->allocator;
    s->bytes = sizeof *s;
    s->status.log = desc->log;
    s->status.log_user = desc->log_user;
    s->dim = desc->dim;
    s->r0 = desc->r0;
    s->re = desc->re > 0 ? desc->re : (fsdem_real)4.1 * desc->r0;
    s->desc.re = s->re;
    s->layers = (int)ceil((double)(s->re / s->r0) - 1e-9);
    fsdem__mps_lattice(s);
    pd = fsdem_pcg_desc_default();
    /* AUTO: MIC(0) in 2D, Jacobi in 3D, where the incomplete factorisation of rows of ~280
       neighbours (re = 4.1 r0) costs more than the iterations it saves: bench/mps_dambreak's 3D
       step took 2.54 s with MIC(0) (28 iterations) and 1.33 s with Jacobi (53); in 2D 0.062 and
       0.070 s */
    pd.preconditioner = desc->pressure_precond != FSDEM_PRECOND_AUTO ? desc->pressure_precond
                        : desc->dim == 3                             ? FSDEM_PRECOND_JACOBI
                                                                     : FSDEM_PRECOND_MIC0;
    pd.tolerance = desc->pressure_tolerance;
    pd.max_iterations = desc->pressure_max_iterations;
    pd.allocator = desc->allocator;
    r = fsdem_pcg_create(&pd, &s->pcg);
    if (r == FSDEM_OK)
        r = fsdem_cellgrid_setup(&s->grid, &s->allocator, s->dim, desc->domain_min, desc->domain_max, s->re, 0);
    if (r != FSDEM_OK) {
        fsdem__log_oom(desc->log, desc->log_user, "fsdem_mps_create", sizeof *s);
        fsdem_mps_destroy(s);
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    *out = s;
    return fsdem__ok(&s->status);
}

/* The particle arrays of a capacity `cap`, with their element sizes (one list for allocation,
   copying and release). */
#define FSDEM__MPS_ARRAYS 17
static int fsdem__mps_arrays(fsdem_mps *s, void ***ptr, size_t *elem) {
    void **p[FSDEM__MPS_ARRAYS];
    size_t e[FSDEM__MPS_ARRAYS];
    int k = 0;
#define FSDEM__MPS_ARRAY(field)                                                                    \
    do {                                                                                           \
        p[k] = (void **)&s->field;                                                                 \
        e[k++] = sizeof *s->field;                                                                 \
    } while (0)
    FSDEM__MPS_ARRAY(x);
    FSDEM__MPS_ARRAY(v);
    FSDEM__MPS_ARRAY(us);
    FSDEM__MPS_ARRAY(shift);
    FSDEM__MPS_ARRAY(p);
    FSDEM__MPS_ARRAY(eps);
    FSDEM__MPS_ARRAY(nd);
    FSDEM__MPS_ARRAY(fext);
    FSDEM__MPS_ARRAY(gradp);
    FSDEM__MPS_ARRAY(div);
    FSDEM__MPS_ARRAY(b);
    FSDEM__MPS_ARRAY(sol);
    FSDEM__MPS_ARRAY(kind);
    FSDEM__MPS_ARRAY(surf);
    FSDEM__MPS_ARRAY(body);
    FSDEM__MPS_ARRAY(unknown);
    FSDEM__MPS_ARRAY(row_particle);
#undef FSDEM__MPS_ARRAY
    memcpy(ptr, p, sizeof p);
    memcpy(elem, e, sizeof e);
    return k;
}

/* The four arrays of n + 1 row offsets: neighbour rows, their build's column rows and cursors, and
   the matrix rows. */
static int **fsdem__mps_rows(fsdem_mps *s, int which) {
    return which == 0 ? &s->nb_start : which == 1 ? &s->tmp_start : which == 2 ? &s->cursor : &s->a_start;
}

void fsdem_mps_destroy(fsdem_mps *s) {
    void **ptr[FSDEM__MPS_ARRAYS];
    size_t elem[FSDEM__MPS_ARRAYS];
    fsdem_allocator al;
    int a, k;
    if (!s) return;
    k = fsdem__mps_arrays(s, ptr, elem);
    for (a = 0; a < k; ++a) fsdem__free(&s->allocator, *ptr[a], elem[a] * (size_t)s->cap);
    for (a = 0; a < 4; ++a) fsdem__free(&s->allocator, *fsdem__mps_rows(s, a), sizeof(int) * (size_t)(s->cap + 1));
    fsdem__free(&s->allocator, s->pairs, sizeof(int) * (size_t)s->pair_cap);
    fsdem__free(&s->allocator, s->nb, sizeof(int) * (size_t)s->nb_cap);
    fsdem__free(&s->allocator, s->tmp_nb, sizeof(int) * (size_t)s->nb_cap);
    fsdem__free(&s->allocator, s->nbw, sizeof(fsdem_real) * (size_t)s->nb_cap);
    fsdem__free(&s->allocator, s->tmp_w, sizeof(fsdem_real) * (size_t)s->nb_cap);
    fsdem__free(&s->allocator, s->a_col, sizeof(int) * (size_t)s->a_cap);
    fsdem__free(&s->allocator, s->a_val, sizeof(fsdem_real) * (size_t)s->a_cap);
    fsdem__free(&s->allocator, s->obst, sizeof *s->obst * (size_t)s->obst_cap);
    fsdem__gauges_free(&s->gauges, &s->allocator);
    fsdem_cellgrid_free(&s->grid);
    if (s->pcg) fsdem_pcg_destroy(s->pcg);
    al = s->allocator;
    fsdem__free(&al, s, sizeof *s);
}

const char *fsdem_mps_last_error(const fsdem_mps *s) { return s ? s->status.message : "fsdem_mps is NULL"; }

fsdem_mps_desc fsdem_mps_get_desc(const fsdem_mps *s) {
    fsdem_mps_desc d;
    if (!s) {
        memset(&d, 0, sizeof d);
        return d;
    }
    return s->desc;
}

/* ---- >>mps_particles : storage, lattice fills, walls, obstacles ---- */

/* Makes room for `need` particles (all arrays, and the per-particle rows of the neighbour list
   and matrix); nothing changes on failure. */
static fsdem_result fsdem__mps_reserve(fsdem_mps *s, int need) {
    void **ptr[FSDEM__MPS_ARRAYS];
    size_t elem[FSDEM__MPS_ARRAYS];
    void *fresh[FSDEM__MPS_ARRAYS + 4];
    int a, k, cap = s->cap > 0 ? s->cap : 64;
    if (need <= s->cap) return FSDEM_OK;
    while (cap < need) {
        if (cap > (1 << 28)) return FSDEM_ERR_OUT_OF_MEMORY;
        cap *= 2;
    }
    k = fsdem__mps_arrays(s, ptr, elem);
    for (a = 0; a < k; ++a) fresh[a] = fsdem__alloc(&s->allocator, elem[a] * (size_t)cap);
    for (a = 0; a < 4; ++a) fresh[k + a] = fsdem__alloc(&s->allocator, sizeof(int) * (size_t)(cap + 1));
    for (a = 0; a < k + 4; ++a)
        if (!fresh[a]) {
            for (a = 0; a < k + 4; ++a)
                fsdem__free(&s->allocator, fresh[a], a < k ? elem[a] * (size_t)cap : sizeof(int) * (size_t)(cap + 1));
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
    for (a = 0; a < k; ++a) {
        if (s->n) memcpy(fresh[a], *ptr[a], elem[a] * (size_t)s->n);
        fsdem__free(&s->allocator, *ptr[a], elem[a] * (size_t)s->cap);
        *ptr[a] = fresh[a];
        s->bytes += elem[a] * (size_t)(cap - s->cap);
    }
    for (a = 0; a < 4; ++a) {
        int **rows = fsdem__mps_rows(s, a);
        if (s->cap) memcpy(fresh[k + a], *rows, sizeof(int) * (size_t)(s->cap + 1));
        else memset(fresh[k + a], 0, sizeof(int) * (size_t)(cap + 1));
        fsdem__free(&s->allocator, *rows, sizeof(int) * (size_t)(s->cap + 1));
        *rows = (int *)fresh[k + a];
    }
    s->bytes += 4 * sizeof(int) * (size_t)(cap - s->cap);
    s->cap = cap;
    return FSDEM_OK;
}

/* Checks particle j of a list for fsdem_mps_add_particles and its fills (`fn` names the caller). */
static fsdem_result fsdem__mps_check_point(fsdem_mps *s, const char *fn, int j, fsdem_vec3 x, fsdem_vec3 v) {
    int a;
    if (!fsdem__finite3(x) || !fsdem__within(v, FSDEM_MAX_SPEED))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "%s: particle %d has a non-finite position or a velocity (%g, %g, %g) m/s above FSDEM_MAX_SPEED (%g m/s)", fn,
                           j, (double)v.x, (double)v.y, (double)v.z, (double)FSDEM_MAX_SPEED);
    for (a = 0; a < s->dim; ++a)
        if (!(fsdem__comp(x, a) >= fsdem__comp(s->desc.domain_min, a) && fsdem__comp(x, a) <= fsdem__comp(s->desc.domain_max, a)))
            return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_DOMAIN, "%s: particle %d at (%g, %g, %g) m is outside the domain", fn,
                               j, (double)x.x, (double)x.y, (double)x.z);
    return FSDEM_OK;
}

/* Appends one particle (room reserved, point checked). */
static void fsdem__mps_push(fsdem_mps *s, fsdem_mps_kind kind, fsdem_vec3 x, fsdem_vec3 v) {
    const int i = s->n++;
    if (s->dim == 2) x.z = v.z = 0;
    s->x[i] = x;
    s->v[i] = kind == FSDEM_MPS_KIND_FLUID ? v : fsdem__zero3();
    s->us[i] = s->v[i];
    s->shift[i] = fsdem__zero3();
    s->p[i] = 0;
    s->eps[i] = 1;
    s->nd[i] = 0;
    s->fext[i] = s->gradp[i] = fsdem__zero3();
    s->kind[i] = (unsigned char)kind;
    s->surf[i] = 0;
    s->body[i] = -1;
    s->unknown[i] = -1;
    s->counts[kind]++;
}

fsdem_result fsdem_mps_add_particles(fsdem_mps *s, fsdem_mps_kind kind, int count, const fsdem_vec3 *positions,
                                     const fsdem_vec3 *velocities) {
    int j;
    fsdem_result r;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((int)kind < 0 || (int)kind > 2)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_add_particles: kind = %d is not a fsdem_mps_kind", (int)kind);
    if (count < 0 || (count > 0 && !positions))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_add_particles: count = %d and positions %s", count,
                           positions ? "given" : "NULL");
    for (j = 0; j < count; ++j)
        if ((r = fsdem__mps_check_point(s, "fsdem_mps_add_particles", j, positions[j],
                                        velocities ? velocities[j] : fsdem__zero3())) != FSDEM_OK)
            return r;
    if (count > (1 << 29) - s->n || fsdem__mps_reserve(s, s->n + count) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps_add_particles: no memory for %d particles", s->n + count);
    for (j = 0; j < count; ++j) fsdem__mps_push(s, kind, positions[j], velocities ? velocities[j] : fsdem__zero3());
    return fsdem__ok(&s->status);
}

/* What a lattice walk does with a point: the kind to add, or -1 to skip it. */
typedef int (*fsdem__mps_classify_fn)(const fsdem_mps *s, const void *user, fsdem_vec3 p);

/* Walks the lattice lo + (i + 1/2) r0 (i may be negative) over the box [from, to] and adds each
   point `classify` accepts: a first pass counts and checks, a second adds, so the call is all or
   nothing. `fn` names the public caller in messages; *added (may be NULL) counts. */
static fsdem_result fsdem__mps_lattice_fill(fsdem_mps *s, const char *fn, fsdem_vec3 lo, fsdem_vec3 from, fsdem_vec3 to,
                                            fsdem__mps_classify_fn classify, const void *user, fsdem_vec3 velocity,
                                            int *added) {
    int i0[3], i1[3], a, pass, count = 0;
    if (added) *added = 0;
    for (a = 0; a < 3; ++a) {
        const double l = (double)fsdem__comp(lo, a), r0 = (double)s->r0;
        i0[a] = a < s->dim ? (int)ceil(((double)fsdem__comp(from, a) - l) / r0 - 0.5 - 1e-9) : 0;
        i1[a] = a < s->dim ? (int)floor(((double)fsdem__comp(to, a) - l) / r0 - 0.5 + 1e-9) : 0;
        if (a < s->dim && (double)(i1[a] - i0[a]) > 1e7)
            return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "%s: the box holds too many lattice points", fn);
    }
    for (pass = 0; pass < 2; ++pass) {
        int i, j, k, c = 0;
        fsdem_result r;
        if (pass == 1) {
            if (count > (1 << 29) - s->n || fsdem__mps_reserve(s, s->n + count) != FSDEM_OK)
                return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "%s: no memory for %d particles", fn, s->n + count);
        }
        for (k = i0[2]; k <= i1[2]; ++k)
            for (j = i0[1]; j <= i1[1]; ++j)
                for (i = i0[0]; i <= i1[0]; ++i) {
                    fsdem_vec3 p = fsdem_v3(lo.x + ((fsdem_real)i + (fsdem_real)0.5) * s->r0,
                                            lo.y + ((fsdem_real)j + (fsdem_real)0.5) * s->r0,
                                            s->dim == 3 ? lo.z + ((fsdem_real)k + (fsdem_real)0.5) * s->r0 : 0);
                    const int kind = classify(s, user, p);
                    if (kind < 0) continue;
                    if (pass == 0) {
                        if ((r = fsdem__mps_check_point(s, fn, count, p, velocity)) != FSDEM_OK) return r;
                        ++count;
                    } else {
                        fsdem__mps_push(s, (fsdem_mps_kind)kind, p, velocity);
                        ++c;
                    }
                }
    }
    if (added) *added = count;
    return fsdem__ok(&s->status);
}

/* Depth of p outside the box [lo, hi] in lattice layers: 0 inside, k when the largest excursion
   along an axis is within (k - 1, k] spacings. `open` (bits of fsdem_side) marks sides beyond which
   a point is rejected (-1). */
static int fsdem__mps_layer_outside(const fsdem_mps *s, fsdem_vec3 lo, fsdem_vec3 hi, unsigned open, fsdem_vec3 p) {
    fsdem_real worst = 0;
    int a;
    for (a = 0; a < s->dim; ++a) {
        const fsdem_real x = fsdem__comp(p, a), l = fsdem__comp(lo, a), h = fsdem__comp(hi, a);
        const fsdem_real out = x < l ? l - x : x > h ? x - h : 0;
        if (out > 0 && (open & (1u << (2 * a + (x > h))))) return -1;
        if (out > worst) worst = out;
    }
    return worst > 0 ? (int)ceil((double)(worst / s->r0) - 1e-6) : 0;
}

/* Depth of p inside the box in layers: 1 for the outer layer, 0 outside. */
static int fsdem__mps_layer_inside(const fsdem_mps *s, fsdem_vec3 lo, fsdem_vec3 hi, fsdem_vec3 p) {
    fsdem_real depth = -1;
    int a;
    for (a = 0; a < s->dim; ++a) {
        const fsdem_real x = fsdem__comp(p, a), l = fsdem__comp(lo, a), h = fsdem__comp(hi, a);
        const fsdem_real in = x - l < h - x ? x - l : h - x;
        if (!(in > 0)) return 0;
        if (depth < 0 || in < depth) depth = in;
    }
    return (int)ceil((double)(depth / s->r0) - 1e-6);
}

/* Fluid: inside the fill box and outside every obstacle. */
static int fsdem__mps_classify_fluid(const fsdem_mps *s, const void *user, fsdem_vec3 p) {
    int o;
    (void)user;
    for (o = 0; o < s->obst_n; ++o)
        if (fsdem__mps_layer_inside(s, s->obst[o].lo, s->obst[o].hi, p) > 0) return -1;
    return FSDEM_MPS_KIND_FLUID;
}

/* Tank walls: the first layer outside the box WALL, the next ones DUMMY. */
typedef struct fsdem__mps_walls {
    fsdem_vec3 box[2];
    unsigned open;
} fsdem__mps_walls;

static int fsdem__mps_classify_walls(const fsdem_mps *s, const void *user, fsdem_vec3 p) {
    const fsdem__mps_walls *w = (const fsdem__mps_walls *)user;
    const int layer = fsdem__mps_layer_outside(s, w->box[0], w->box[1], w->open, p);
    return layer <= 0 || layer > s->layers ? -1 : layer == 1 ? FSDEM_MPS_KIND_WALL : FSDEM_MPS_KIND_DUMMY;
}

/* Obstacle: the outer layer inside the box WALL, the next ones DUMMY. */
static int fsdem__mps_classify_obstacle(const fsdem_mps *s, const void *user, fsdem_vec3 p) {
    const fsdem__mps_obst *o = (const fsdem__mps_obst *)user;
    const int layer = fsdem__mps_layer_inside(s, o->lo, o->hi, p);
    return layer <= 0 || layer > s->layers ? -1 : layer == 1 ? FSDEM_MPS_KIND_WALL : FSDEM_MPS_KIND_DUMMY;
}

/* Checks a box argument of the fills (`fn` names the caller). */
static fsdem_result fsdem__mps_check_box(fsdem_mps *s, const char *fn, fsdem_vec3 lo, fsdem_vec3 hi) {
    int a;
    if (!fsdem__finite3(lo) || !fsdem__finite3(hi))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: the box corners must be finite", fn);
    for (a = 0; a < s->dim; ++a)
        if (!(fsdem__comp(hi, a) - fsdem__comp(lo, a) >= s->r0))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: the box is thinner than r0 = %g m along %c", fn,
                               (double)s->r0, "xyz"[a]);
    return FSDEM_OK;
}

fsdem_result fsdem_mps_fill_box(fsdem_mps *s, fsdem_vec3 lo, fsdem_vec3 hi, fsdem_vec3 velocity, int *added) {
    fsdem_result r;
    if (added) *added = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem__mps_check_box(s, "fsdem_mps_fill_box", lo, hi)) != FSDEM_OK) return r;
    return fsdem__mps_lattice_fill(s, "fsdem_mps_fill_box", lo, lo, hi, fsdem__mps_classify_fluid, NULL, velocity, added);
}

fsdem_result fsdem_mps_add_box_walls(fsdem_mps *s, fsdem_vec3 lo, fsdem_vec3 hi, unsigned open_sides, int *added) {
    fsdem__mps_walls w;
    fsdem_real reach;
    fsdem_result r;
    if (added) *added = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem__mps_check_box(s, "fsdem_mps_add_box_walls", lo, hi)) != FSDEM_OK) return r;
    if (open_sides >> (2 * s->dim))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_mps_add_box_walls: open_sides = 0x%x has bits beyond the %d sides of a %dD box (1 << fsdem_side)",
                           open_sides, 2 * s->dim, s->dim);
    w.box[0] = lo;
    w.box[1] = hi;
    w.open = open_sides;
    reach = (fsdem_real)s->layers * s->r0;
    return fsdem__mps_lattice_fill(s, "fsdem_mps_add_box_walls", lo, fsdem__sub(lo, fsdem_v3(reach, reach, reach)),
                                   fsdem__add(hi, fsdem_v3(reach, reach, reach)), fsdem__mps_classify_walls, &w,
                                   fsdem__zero3(), added);
}

fsdem_result fsdem_mps_add_box_obstacle(fsdem_mps *s, fsdem_vec3 lo, fsdem_vec3 hi, int *id) {
    fsdem__mps_obst box;
    fsdem_result r;
    int first, i;
    if (id) *id = -1;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if ((r = fsdem__mps_check_box(s, "fsdem_mps_add_box_obstacle", lo, hi)) != FSDEM_OK) return r;
    if (s->obst_n == s->obst_cap) {
        const int cap = s->obst_cap ? 2 * s->obst_cap : 4;
        fsdem__mps_obst *o = (fsdem__mps_obst *)fsdem__alloc(&s->allocator, sizeof *o * (size_t)cap);
        if (!o) return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps_add_box_obstacle: out of memory");
        if (s->obst_n) memcpy(o, s->obst, sizeof *o * (size_t)s->obst_n);
        fsdem__free(&s->allocator, s->obst, sizeof *o * (size_t)s->obst_cap);
        s->bytes += sizeof *o * (size_t)(cap - s->obst_cap);
        s->obst = o;
        s->obst_cap = cap;
    }
    box.lo = lo;
    box.hi = hi;
    box.force = fsdem__zero3();
    first = s->n;
    r = fsdem__mps_lattice_fill(s, "fsdem_mps_add_box_obstacle", lo, lo, hi, fsdem__mps_classify_obstacle, &box,
                                fsdem__zero3(), NULL);
    if (r != FSDEM_OK) return r;
    for (i = first; i < s->n; ++i) s->body[i] = s->obst_n;
    s->obst[s->obst_n] = box;
    if (id) *id = s->obst_n;
    s->obst_n++;
    return fsdem__ok(&s->status);
}

/* ---- >>mps_neighbours : cell-list search into sorted neighbour rows ---- */

/* Capacity for `need` entries: the next power-of-two multiple of 1024 (0 when it would overflow). */
static int fsdem__mps_capacity(int have, long long need) {
    long long cap = have > 0 ? have : 1024;
    while (cap < need) cap *= 2;
    return cap > (1LL << 30) ? 0 : (int)cap;
}

/* The neighbours of every FLUID and WALL particle within re at the current positions, as rows of
   ascending particle index with their weights w_ij (Eq. 6); DUMMY particles have empty rows (their
   own sums are never needed) but appear in the others'. Pairs are found once each by the forward
   scan of the cell grid (as the DEM's pair search), put into unsorted rows, then copied column by
   column into the final rows, which leaves each sorted. Allocates only when the lists outgrow every
   earlier one. */
static fsdem_result fsdem__mps_neighbours(fsdem_mps *s) {
    const fsdem_cellgrid *g = &s->grid;
    const fsdem_real re2 = s->re * s->re;
    int c, f, a, b, i, e, count = 0;
    if (fsdem_cellgrid_build(&s->grid, s->x, s->n) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    for (c = 0; c < g->cell_count; ++c) {
        int coord[3], cells[14], nf;
        if (g->cell_start[c] == g->cell_start[c + 1]) continue;
        coord[0] = c % g->n[0];
        coord[1] = c / g->n[0] % g->n[1];
        coord[2] = c / (g->n[0] * g->n[1]);
        nf = fsdem_cellgrid_forward(g, coord, cells);
        for (f = 0; f < nf; ++f) {
            const int b1 = g->cell_start[cells[f] + 1];
            for (a = g->cell_start[c]; a < g->cell_start[c + 1]; ++a) {
                const int pa = g->items[a], b0 = f == 0 ? a + 1 : g->cell_start[cells[f]];
                if (2 * ((long long)count + b1 - b0) > s->pair_cap) {
                    const int cap = fsdem__mps_capacity(s->pair_cap, 2 * ((long long)count + b1 - b0));
                    int *fresh = cap ? (int *)fsdem__alloc(&s->allocator, sizeof(int) * (size_t)cap) : NULL;
                    if (!fresh) return FSDEM_ERR_OUT_OF_MEMORY;
                    if (count) memcpy(fresh, s->pairs, sizeof(int) * 2 * (size_t)count);
                    fsdem__free(&s->allocator, s->pairs, sizeof(int) * (size_t)s->pair_cap);
                    s->bytes += sizeof(int) * (size_t)(cap - s->pair_cap);
                    s->pairs = fresh;
                    s->pair_cap = cap;
                }
                for (b = b0; b < b1; ++b) {
                    const int pb = g->items[b];
                    const fsdem_vec3 d = fsdem__sub(s->x[pa], s->x[pb]);
                    s->pairs[2 * count] = pa;
                    s->pairs[2 * count + 1] = pb;
                    count += fsdem__dot(d, d) < re2 && (s->kind[pa] != FSDEM_MPS_KIND_DUMMY || s->kind[pb] != FSDEM_MPS_KIND_DUMMY);
                }
            }
        }
    }
    s->pair_count = count;
    /* directed entries (r, c): c in the row of r, for every non-DUMMY r; first bucketed by column c
       (counting sort into tmp_nb/tmp_w, rows r), then scattered by row in column order, which
       leaves every row sorted */
    memset(s->tmp_start, 0, sizeof(int) * (size_t)(s->n + 1));
    memset(s->nb_start, 0, sizeof(int) * (size_t)(s->n + 1));
    for (e = 0; e < count; ++e) {
        const int pa = s->pairs[2 * e], pb = s->pairs[2 * e + 1];
        if (s->kind[pa] != FSDEM_MPS_KIND_DUMMY) {
            s->nb_start[pa + 1]++;
            s->tmp_start[pb + 1]++;
        }
        if (s->kind[pb] != FSDEM_MPS_KIND_DUMMY) {
            s->nb_start[pb + 1]++;
            s->tmp_start[pa + 1]++;
        }
    }
    for (i = 0; i < s->n; ++i) {
        s->nb_start[i + 1] += s->nb_start[i];
        s->tmp_start[i + 1] += s->tmp_start[i];
    }
    if (s->nb_start[s->n] > s->nb_cap) {
        const int cap = fsdem__mps_capacity(s->nb_cap, s->nb_start[s->n]);
        void **arrays[4];
        size_t elem[4];
        void *fresh[4];
        int k;
        arrays[0] = (void **)&s->nb;
        arrays[1] = (void **)&s->tmp_nb;
        arrays[2] = (void **)&s->nbw;
        arrays[3] = (void **)&s->tmp_w;
        elem[0] = elem[1] = sizeof(int);
        elem[2] = elem[3] = sizeof(fsdem_real);
        if (!cap) return FSDEM_ERR_OUT_OF_MEMORY;
        for (k = 0; k < 4; ++k) fresh[k] = fsdem__alloc(&s->allocator, elem[k] * (size_t)cap);
        if (!fresh[0] || !fresh[1] || !fresh[2] || !fresh[3]) {
            for (k = 0; k < 4; ++k) fsdem__free(&s->allocator, fresh[k], elem[k] * (size_t)cap);
            return FSDEM_ERR_OUT_OF_MEMORY;
        }
        for (k = 0; k < 4; ++k) {
            fsdem__free(&s->allocator, *arrays[k], elem[k] * (size_t)s->nb_cap);
            *arrays[k] = fresh[k];
        }
        s->bytes += 2 * (sizeof(int) + sizeof(fsdem_real)) * (size_t)(cap - s->nb_cap);
        s->nb_cap = cap;
    }
    memcpy(s->cursor, s->tmp_start, sizeof(int) * (size_t)s->n);
    for (e = 0; e < count; ++e) {
        const int pa = s->pairs[2 * e], pb = s->pairs[2 * e + 1];
        const fsdem_real w = fsdem__kernel_mps(fsdem__norm(fsdem__sub(s->x[pa], s->x[pb])), s->re);
        if (s->kind[pa] != FSDEM_MPS_KIND_DUMMY) {
            s->tmp_nb[s->cursor[pb]] = pa;
            s->tmp_w[s->cursor[pb]++] = w;
        }
        if (s->kind[pb] != FSDEM_MPS_KIND_DUMMY) {
            s->tmp_nb[s->cursor[pa]] = pb;
            s->tmp_w[s->cursor[pa]++] = w;
        }
    }
    memcpy(s->cursor, s->nb_start, sizeof(int) * (size_t)s->n);
    for (c = 0; c < s->n; ++c)
        for (e = s->tmp_start[c]; e < s->tmp_start[c + 1]; ++e) {
            const int r = s->tmp_nb[e];
            s->nb[s->cursor[r]] = c;
            s->nbw[s->cursor[r]++] = s->tmp_w[e];
        }
    return FSDEM_OK;
}

/* ---- >>mps_operators : number density, gradient, divergence, Laplacian, surface ---- */

/* Number density n_i (seed 002 Eq. 7, every neighbour, DUMMY included) and the surface flag
   (Eq. 14-16) of every FLUID and WALL particle, from the neighbour rows; returns the number of
   surface particles. A particle is on the surface when n_i < beta n0, or else when the asymmetry
   |F_i| of Eq. 15 exceeds alpha |F0| (|F0|: the flat surface of the lattice, >>mps_desc). */
static int fsdem__mps_density(fsdem_mps *s) {
    const fsdem_real fscale = (fsdem_real)s->dim / s->n0;
    int i, e, surface = 0;
    for (i = 0; i < s->n; ++i) {
        fsdem_real nd = 0;
        fsdem_vec3 F = fsdem__zero3();
        s->nd[i] = 0;
        s->surf[i] = 0;
        if (s->kind[i] == FSDEM_MPS_KIND_DUMMY) continue;
        for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
            const int j = s->nb[e];
            const fsdem_real we = s->nbw[e] / s->eps[j];
            const fsdem_vec3 r = fsdem__sub(s->x[j], s->x[i]);
            const fsdem_real len = fsdem__norm(r);
            nd += we;                                           /* seed 002 Eq. 7 */
            if (len > 0) F = fsdem__madd(F, r, we / len);       /* seed 002 Eq. 15 */
        }
        s->nd[i] = nd;
        s->surf[i] = (unsigned char)(nd < s->desc.beta * s->n0 ||                 /* seed 002 Eq. 14 */
                                     fscale * fsdem__norm(F) > s->desc.alpha * s->f0); /* Eq. 16 */
        surface += s->surf[i];
    }
    return surface;
}

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
        const fsdem_vec3 r = fsdem__sub(s->x[j], s->x[i]);
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
            if (s->kind[s->nb[e]] != FSDEM_MPS_KIND_DUMMY && phi[s->nb[e]] < base) base = phi[s->nb[e]];
    if (s->desc.gradient == FSDEM_MPS_GRADIENT_MODEL_MIN) base = -base;
    fsdem__mps_gradient_transform(s, i, T);
    for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
        const int j = s->nb[e];
        const fsdem_vec3 r = fsdem__sub(s->x[j], s->x[i]);
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
        const fsdem_vec3 r = fsdem__sub(s->x[j], s->x[i]);
        const fsdem_real r2 = fsdem__dot(r, r);
        if (s->kind[j] == FSDEM_MPS_KIND_DUMMY || !(r2 > 0)) continue;
        d += fsdem__dot(fsdem__sub(u[j], u[i]), r) * s->nbw[e] / (r2 * s->eps[j]);
    }
    return d * (fsdem_real)s->dim / s->n0;
}

/* Laplacian at particle i (seed 002 Eq. 10, lambda of Eq. 11) over its non-DUMMY neighbours, of
   a scalar (phi) or, when phi is NULL, of a vector field u. */
static fsdem_vec3 fsdem__mps_lap_at(const fsdem_mps *s, const fsdem_real *phi, const fsdem_vec3 *u, int i) {
    fsdem_vec3 l = fsdem__zero3();
    int e;
    for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
        const int j = s->nb[e];
        const fsdem_real we = s->nbw[e] / s->eps[j];
        if (s->kind[j] == FSDEM_MPS_KIND_DUMMY) continue;
        if (phi) l.x += (phi[j] - phi[i]) * we;
        else l = fsdem__madd(l, fsdem__sub(u[j], u[i]), we);
    }
    return fsdem__scale(l, 2 * (fsdem_real)s->dim / (s->n0 * s->lambda));
}

/* Rebuilds the neighbours and the number density at the current positions for a public operator
   (`fn` names it), checking its arguments. */
static fsdem_result fsdem__mps_operator_setup(fsdem_mps *s, const char *fn, const void *in, const void *out) {
    if (!in || !out) return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "%s: NULL field", fn);
    if (s->n > 0 && fsdem__mps_neighbours(s) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory building the neighbour list", fn);
    if (s->n > 0) fsdem__mps_density(s);
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
    for (i = 0; i < s->n; ++i) out[i] = s->kind[i] == FSDEM_MPS_KIND_DUMMY ? 0 : fsdem__mps_lap_at(s, phi, NULL, i).x;
    return fsdem__ok(&s->status);
}

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

/* Mass of the fluid a particle stands for: rho r0^d (kg; kg per metre of depth in 2D). */
static fsdem_real fsdem__mps_mass(const fsdem_mps *s) {
    return s->desc.density * s->r0 * s->r0 * (s->dim == 3 ? s->r0 : 1);
}

/* The stable step of the CFL rule of seed 002 Eq. 37, u_max dt / r0 <= C, at most dt_max. */
static fsdem_real fsdem__mps_dt_from(const fsdem_mps *s, fsdem_real umax) {
    fsdem_real dt = s->desc.dt_max;
    if (umax > 0 && s->desc.cfl * s->r0 / umax < dt) dt = s->desc.cfl * s->r0 / umax;
    return dt;
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
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID || s->surf[i] || D == 0) continue;
        for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) {
            const int j = s->nb[e];
            const fsdem_vec3 r = fsdem__sub(s->x[j], s->x[i]);
            const fsdem_real r2 = fsdem__dot(r, r);
            if (!(r2 > 0)) continue;
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
            const fsdem_vec3 r = fsdem__sub(s->x[j], s->x[i]);
            const fsdem_vec3 dv = fsdem__sub(s->v[j], s->v[i]);
            const fsdem_vec3 ahead = fsdem__madd(r, dv, dt);
            fsdem_real len, vn;
            fsdem_vec3 n;
            if (fluid && j < i) continue; /* each FLUID pair once */
            len = fsdem__norm(r);
            vn = fsdem__dot(dv, r);
            if (!(len > 0) || !(vn < 0) || !(fsdem__dot(ahead, ahead) < dc * dc)) continue;
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
    const fsdem_real scale = -s->n0 * s->lambda / (2 * (fsdem_real)s->dim);
    long long nnz = 0;
    int i, e, rows = 0;
    for (i = 0; i < s->n; ++i) {
        int solid_only = 1;
        s->unknown[i] = -1;
        if (s->kind[i] == FSDEM_MPS_KIND_DUMMY || s->surf[i]) continue;
        for (e = s->nb_start[i]; e < s->nb_start[i + 1] && solid_only; ++e) solid_only = s->kind[s->nb[e]] == FSDEM_MPS_KIND_DUMMY;
        if (solid_only) continue;
        s->row_particle[rows] = i;
        s->unknown[i] = rows++;
    }
    for (i = 0; i < s->n; ++i)
        if (s->unknown[i] >= 0) {
            nnz++;
            for (e = s->nb_start[i]; e < s->nb_start[i + 1]; ++e) nnz += s->unknown[s->nb[e]] >= 0;
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
            const fsdem_real a = s->nbw[e] / (s->eps[i] * s->eps[j]);
            if (s->kind[j] == FSDEM_MPS_KIND_DUMMY) continue;
            diag += a;
            if (s->unknown[j] < 0) continue;
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
            s->b[row] += rho * fsdem__dot(s->desc.gravity, fsdem__sub(s->x[j], s->x[i])) * s->nbw[e] / (s->eps[i] * s->eps[j]);
        }
        s->sol[row] = s->p[i];
    }
    s->rows = rows;
    return FSDEM_OK;
}

/* One step of dt (the section's steps 1-6). Failures before the pressure is known change nothing;
   a completed step reports a non-finite or escaped particle. */
static fsdem_result fsdem__mps_do_step(fsdem_mps *s, fsdem_real dt) {
    const fsdem_real rho = s->desc.density, nu = s->desc.viscosity, mass = fsdem__mps_mass(s);
    const double time0 = s->time;
    fsdem_pcg_info info;
    fsdem_csr A;
    fsdem_result r;
    clock_t t0 = clock(), t1, tp;
    int i, a, bad = -1;
    if (s->counts[FSDEM_MPS_KIND_FLUID] == 0)
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps: no FLUID particles to step");
    for (i = 0; i < s->n; ++i)
        if (!(s->eps[i] > 0 && s->eps[i] <= 1))
            return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps: particle %d has porosity %g outside (0, 1]", i,
                               (double)s->eps[i]);
    fsdem__series_begin(&s->gauges.series);
    /* 1. neighbours, number density, free surface */
    if (fsdem__mps_neighbours(s) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps: out of memory building the neighbour list");
    s->surface_count = fsdem__mps_density(s);
    fsdem__mps_shift(s);
    /* 2. predictor: u* = u + dt (nu lap u + g) (seed 002 Eq. A.6 with eps = 1). WALL and DUMMY
       particles take u* = dt g, their velocity (0) plus the same body force: a uniform field has no
       divergence (Eq. 9), so gravity alone leaves no source at the walls in Eq. 12, and the walls
       carry its weight through the hydrostatic ghost pressure of the DUMMY particles in the
       pressure equation (fsdem__mps_assemble), the discrete Neumann condition dp/dn = rho g.n.
       With u* = 0 at the solids instead, the source of the rows near a wall held only part of the
       weight (one-sided Eq. 9 against the one-sided Eq. 10): still water started with 0.7 rho g h
       at the bottom and fell at 0.25-0.35 g in its first step. */
    for (i = 0; i < s->n; ++i) {
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID) {
            s->us[i] = fsdem__scale(s->desc.gravity, dt);
            if (s->dim == 2) s->us[i].z = 0;
            continue;
        }
        s->us[i] = fsdem__add(s->v[i], fsdem__scale(fsdem__add(fsdem__scale(fsdem__mps_lap_at(s, NULL, s->v, i), nu),
                                                                s->desc.gravity), dt));
        if (s->external) s->us[i] = fsdem__madd(s->us[i], s->fext[i], dt / mass); /* a coupler's force (Eq. 2, 4) */
        if (s->dim == 2) s->us[i].z = 0;
    }
    for (i = 0; i < s->n; ++i) s->div[i] = s->kind[i] == FSDEM_MPS_KIND_DUMMY ? 0 : fsdem__mps_div_at(s, s->us, i);
    /* 3. pressure equation */
    tp = clock();
    if (fsdem__mps_assemble(s, dt) != FSDEM_OK)
        return fsdem__fail(&s->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps: out of memory assembling the pressure matrix");
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
        s->sec_pressure += (double)(clock() - tp) / CLOCKS_PER_SEC;
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
    t1 = clock();
    /* 4. pressures (clamped where asked), then the corrector: u = u* - dt/rho grad p, r += dt u */
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
    fsdem__mps_obstacle_forces(s);
    fsdem__mps_collide(s, dt);
    for (i = 0; i < s->n; ++i)
        if (s->kind[i] == FSDEM_MPS_KIND_FLUID) s->x[i] = fsdem__add(fsdem__madd(s->x[i], s->v[i], dt), s->shift[i]);
    s->time += (double)dt;
    s->dt_last = dt;
    s->steps++;
    s->iters_total += s->iters;
    s->sec_total += (double)(clock() - t1) / CLOCKS_PER_SEC + (double)(t1 - t0) / CLOCKS_PER_SEC;
    for (i = 0; i < s->n && bad < 0; ++i)
        if (s->kind[i] == FSDEM_MPS_KIND_FLUID && (!fsdem__finite3(s->v[i]) || !fsdem__finite3(s->x[i]) || !fsdem__finite(s->p[i])))
            bad = i;
    if (bad >= 0)
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_mps: step %lld: particle %d has a non-finite velocity, position or pressure",
                           s->steps, bad);
    for (i = 0; i < s->n; ++i) {
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        for (a = 0; a < s->dim; ++a)
            if (fsdem__comp(s->x[i], a) < fsdem__comp(s->desc.domain_min, a) || fsdem__comp(s->x[i], a) > fsdem__comp(s->desc.domain_max, a))
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

fsdem_result fsdem_mps_step_dt(fsdem_mps *s, fsdem_real dt) {
    int who;
    fsdem_real umax;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_step_dt: dt = %g s must be > 0 and finite", (double)dt);
    umax = fsdem__mps_umax(s, &who);
    if (!fsdem__finite(umax))
        return fsdem__fail(&s->status, FSDEM_ERR_NAN, "fsdem_mps_step_dt: particle %d has a non-finite velocity", who);
    if (umax * dt > s->desc.cfl * s->r0 * (1 + (fsdem_real)1e-5))
        return fsdem__fail(&s->status, FSDEM_ERR_CFL,
                           "fsdem_mps_step_dt: dt = %g s gives u_max dt / r0 = %g > cfl = %g (seed 002 Eq. 37; particle %d at %g m/s; "
                           "dt <= %g s)",
                           (double)dt, (double)(umax * dt / s->r0), (double)s->desc.cfl, who, (double)umax,
                           (double)(s->desc.cfl * s->r0 / umax));
    return fsdem__mps_do_step(s, dt);
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
    v.porosity = s->eps;
    v.pressure_gradient = s->gradp;
    v.mass = fsdem__mps_mass(s);
    return v;
}

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
    st.memory_bytes = s->bytes;
    return st;
}

/* ---- >>mps_probes : pressure, water level, obstacle force ---- */

/* W(r) of the probes (section >>mps): (1 - r^2/R^2)^3 inside R, times the normalisation of a kernel
   when `normalised`. */
static fsdem_real fsdem__mps_probe_weight(const fsdem_mps *s, fsdem_real r2, fsdem_real R, int normalised) {
    const fsdem_real q = 1 - r2 / (R * R);
    const double c = !normalised ? 1 : s->dim == 2 ? 4 / (FSDEM__PI * (double)(R * R)) : 315 / (64 * FSDEM__PI * (double)(R * R * R));
    return q > 0 ? (fsdem_real)(c * (double)(q * q * q)) : 0;
}

/* Pressure at a point (fsdem_mps_probe_pressure; radius > 0). */
static fsdem_real fsdem__mps_pressure_at(const fsdem_mps *s, fsdem_vec3 point, fsdem_real radius) {
    double sum = 0, weights = 0;
    int i;
    if (s->dim == 2) point.z = 0;
    for (i = 0; i < s->n; ++i) {
        fsdem_vec3 d;
        fsdem_real w;
        if (s->kind[i] == FSDEM_MPS_KIND_DUMMY) continue;
        d = fsdem__sub(s->x[i], point);
        w = fsdem__mps_probe_weight(s, fsdem__dot(d, d), radius, 0);
        sum += (double)(w * s->p[i]);
        weights += (double)w;
    }
    return weights > 0 ? (fsdem_real)(sum / weights) : 0;
}

fsdem_result fsdem_mps_probe_pressure(const fsdem_mps *s, fsdem_vec3 point, fsdem_real radius, fsdem_real *pressure) {
    if (pressure) *pressure = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!pressure || !fsdem__finite3(point) || !(radius >= 0) || !fsdem__finite(radius))
        return fsdem__fail((fsdem__status *)&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_mps_probe_pressure: %s", !pressure ? "pressure is NULL" : "the point and radius must be finite, radius >= 0");
    *pressure = fsdem__mps_pressure_at(s, point, radius > 0 ? radius : s->re);
    return fsdem__ok((fsdem__status *)&s->status);
}

/* Liquid fraction at the point of the gauge line at height z (fsdem_mps_probe_height). */
static fsdem_real fsdem__mps_liquid_fraction(const fsdem_mps *s, fsdem_vec3 gauge, fsdem_real z, fsdem_real R) {
    const int up = s->dim - 1;
    const fsdem_real volume = (fsdem_real)pow((double)s->r0, s->dim);
    double f = 0;
    int i;
    fsdem__set_comp(&gauge, up, z);
    for (i = 0; i < s->n; ++i) {
        fsdem_vec3 d;
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        d = fsdem__sub(s->x[i], gauge);
        f += (double)fsdem__mps_probe_weight(s, fsdem__dot(d, d), R, 1);
    }
    return (fsdem_real)(f * (double)volume);
}

/* Water level at a gauge line (fsdem_mps_probe_height). */
static fsdem_real fsdem__mps_level(const fsdem_mps *s, fsdem_vec3 gauge) {
    const int up = s->dim - 1;
    const fsdem_real R = 2 * s->r0, step = s->r0 / 4;
    fsdem_real top = 0, bottom = 0, z, f_above = 0;
    int i, found = 0;
    if (s->dim == 2) gauge.z = 0;
    /* the span of the liquid within R of the line */
    for (i = 0; i < s->n; ++i) {
        fsdem_vec3 d;
        fsdem_real zi;
        if (s->kind[i] != FSDEM_MPS_KIND_FLUID) continue;
        d = fsdem__sub(s->x[i], gauge);
        fsdem__set_comp(&d, up, 0);
        if (!(fsdem__dot(d, d) < R * R)) continue;
        zi = fsdem__comp(s->x[i], up);
        if (!found || zi > top) top = zi;
        if (!found || zi < bottom) bottom = zi;
        found = 1;
    }
    /* from above the highest particle down, the first sample whose fraction reaches 1/2 */
    for (z = top + R; found && z >= bottom - R; z -= step) {
        const fsdem_real f = fsdem__mps_liquid_fraction(s, gauge, z, R);
        if (f >= (fsdem_real)0.5) return z + step * (f - (fsdem_real)0.5) / (f - f_above);
        f_above = f;
    }
    return fsdem__comp(s->desc.domain_min, up);
}

fsdem_result fsdem_mps_probe_height(const fsdem_mps *s, fsdem_vec3 gauge, fsdem_real *height) {
    if (height) *height = 0;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!height || !fsdem__finite3(gauge))
        return fsdem__fail((fsdem__status *)&s->status, FSDEM_ERR_INVALID_ARG,
                           "fsdem_mps_probe_height: %s", !height ? "height is NULL" : "the gauge position must be finite");
    *height = fsdem__mps_level(s, gauge);
    return fsdem__ok((fsdem__status *)&s->status);
}

/* The value of gauge k (section >>mps, gauges). */
static fsdem_real fsdem__mps_gauge_value(const fsdem_mps *s, int k) {
    return s->gauges.kind[k] == FSDEM_MPS_GAUGE_KIND_LEVEL
               ? fsdem__mps_level(s, s->gauges.at[k])
               : fsdem__mps_pressure_at(s, s->gauges.at[k], s->gauges.radius[k] > 0 ? s->gauges.radius[k] : s->re);
}

static void fsdem__mps_gauge_values(const void *solver, fsdem_real *out) {
    const fsdem_mps *s = (const fsdem_mps *)solver;
    int k;
    for (k = 0; k < s->gauges.count; ++k) out[k] = fsdem__mps_gauge_value(s, k);
}

fsdem_result fsdem_mps_add_gauge(fsdem_mps *s, fsdem_mps_gauge_kind kind, fsdem_vec3 position, fsdem_real radius, int *id) {
    if (id) *id = -1;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__gauges_add(&s->gauges, &s->status, &s->allocator, "fsdem_mps_add_gauge", (int)kind, position, radius, s->dim,
                             s->desc.domain_min, s->desc.domain_max, id);
}

fsdem_result fsdem_mps_gauge(const fsdem_mps *s, int id, fsdem_real *value) {
    if (!s || !value) return FSDEM_ERR_INVALID_ARG;
    if (id < 0 || id >= s->gauges.count) return FSDEM_ERR_NOT_FOUND;
    *value = fsdem__mps_gauge_value(s, id);
    return FSDEM_OK;
}

fsdem_result fsdem_mps_gauges_open(fsdem_mps *s, const char *path, fsdem_real interval) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__gauges_open(&s->gauges, &s->status, &s->allocator, "fsdem_mps_gauges_open", path, s->time, interval,
                              fsdem__mps_gauge_values, s);
}

fsdem_result fsdem_mps_gauges_close(fsdem_mps *s) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__gauges_close(&s->gauges, &s->status, &s->allocator, "fsdem_mps_gauges_close");
}

fsdem_result fsdem_mps_obstacle_force(const fsdem_mps *s, int id, fsdem_vec3 *force) {
    if (force) *force = fsdem__zero3();
    if (!s) return FSDEM_ERR_INVALID_ARG;
    if (!force || id < 0 || id >= s->obst_n)
        return fsdem__fail((fsdem__status *)&s->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_obstacle_force: %s",
                           !force ? "force is NULL" : "no obstacle has this id");
    *force = s->obst[id].force;
    return fsdem__ok((fsdem__status *)&s->status);
}

/* ===== >>impl_drag : drag laws ===== */

/* Contents: the Wen-Yu term (also the Schiller-Naumann law, at eps = 1), the per-law coefficient
   c = beta / (1 - eps) without checks for the couplers' per-particle loops, the checked public function
   and the names.

   Why each published form is read as the drag of seed 002 Eq. 25 (the -V grad P part excluded):
   - Ergun: the beta of Eq. 26 with -eps grad P in the fluid's momentum balance gives Ergun's pressure
     drop, 150 phi^2 mu U / (eps^3 d^2) at the superficial U.
   - Di Felice: in a settling suspension the drag in this sense balances the weight less the buoyancy
     of the suspension's density, eps (rho_p - rho_f) g V; with Richardson-Zaki's n = 4.65 that makes
     chi = n - 1 = 3.65, Di Felice's 3.7, and his form with chi = 3.65 and Cd of Eq. 27 is exactly the
     Wen-Yu branch of Eq. 26 (eps^(2 - 3.65) = eps^-1.65). (Read as the total force, F / eps, chi would
     have to be n = 4.65.)
   - Beetstra: F(phi, 0) = 10 phi / eps^2 + ... gives c = 180 phi mu / (eps d^2), the Carman-Kozeny
     twin of Ergun's 150 phi mu / (eps d^2) in Eq. 26; read as the total force it would be eps times
     that, off from Ergun by a factor eps. */

/* Wen and Yu (1966) as in seed 002 Eq. 26: c = 0.75 Cd rho slip eps^-1.65 / d with Cd of Eq. 27 at
   Re = eps rho d slip / mu (Eq. 28). Written with Cd Re = 24 (1 + 0.15 Re^0.687) and rho slip / d =
   Re mu / (eps d^2), so Re = 0 gives 18 mu eps^-2.65 / d^2 with no 0/0. At eps = 1 this is the
   Schiller-Naumann law of an isolated sphere. */
static fsdem_real fsdem__drag_wen_yu(fsdem_real eps, fsdem_real d, fsdem_real slip, fsdem_real rho, fsdem_real mu) {
    const fsdem_real re = eps * rho * d * slip / mu;
    const fsdem_real cd_re = re <= 1000 ? 24 * (1 + (fsdem_real)0.15 * (fsdem_real)pow(re, 0.687)) : (fsdem_real)0.44 * re;
    return (fsdem_real)0.75 * cd_re * mu / (d * d) * (fsdem_real)pow(eps, -2.65);
}

/* Ergun (1952) as in seed 002 Eq. 26, divided by (1 - eps). */
static fsdem_real fsdem__drag_ergun(fsdem_real eps, fsdem_real d, fsdem_real slip, fsdem_real rho, fsdem_real mu) {
    return 150 * (1 - eps) * mu / (eps * d * d) + (fsdem_real)1.75 * rho * slip / d;
}

/* c of `law` (kg m^-3 s^-1) for valid arguments (fsdem_drag_coefficient checks them). */
static fsdem_real fsdem__drag_per_volume(fsdem_drag_law law, fsdem_real eps, fsdem_real d, fsdem_real slip,
                                         fsdem_real rho, fsdem_real mu) {
    switch (law) {
    case FSDEM_DRAG_LAW_STOKES: return 18 * mu / (d * d);
    case FSDEM_DRAG_LAW_SCHILLER_NAUMANN: return fsdem__drag_wen_yu(1, d, slip, rho, mu);
    case FSDEM_DRAG_LAW_ERGUN_WEN_YU:
        /* the switch in fsdem_real, so a float build puts eps = 0.8f on the Ergun side too */
        return eps <= (fsdem_real)0.8 ? fsdem__drag_ergun(eps, d, slip, rho, mu) : fsdem__drag_wen_yu(eps, d, slip, rho, mu);
    case FSDEM_DRAG_LAW_GIDASPOW: {
        /* the blend of beta is the same blend of c: both terms carry the one factor (1 - eps) */
        const fsdem_real phi = (fsdem_real)(0.5 + atan(262.5 * ((1 - eps) - 0.2)) / FSDEM__PI);
        return (1 - phi) * fsdem__drag_wen_yu(eps, d, slip, rho, mu) + phi * fsdem__drag_ergun(eps, d, slip, rho, mu);
    }
    case FSDEM_DRAG_LAW_DI_FELICE: {
        /* Cd0 slip = (0.63 sqrt(slip) + 4.8 sqrt(slip / Re))^2 with slip / Re = mu / (eps rho d): finite at
           Re = 0, where chi -> 3.7 (the Gaussian in log10 Re vanishes) and c -> 17.28 mu eps^-2.7 / d^2 */
        const fsdem_real re = eps * rho * d * slip / mu;
        const fsdem_real lg = re > 0 ? (fsdem_real)1.5 - (fsdem_real)log10(re) : 0;
        const fsdem_real chi = re > 0 ? (fsdem_real)(3.7 - 0.65 * exp(-0.5 * lg * lg)) : (fsdem_real)3.7;
        const fsdem_real root = (fsdem_real)(0.63 * sqrt(slip) + 4.8 * sqrt(mu / (eps * rho * d)));
        return (fsdem_real)0.75 * rho * root * root * (fsdem_real)pow(eps, 2 - chi) / d;
    }
    case FSDEM_DRAG_LAW_BEETSTRA: {
        /* the Re term Re / (24 eps^2) (A + 8.4 Re^-0.343) / (1 + 10^(3 phi) Re^-a), a = (1 + 4 phi) / 2,
           written (Re A + 8.4 Re^0.657) / (24 eps^2 (1 + 10^(3 phi) Re^-a)): Re^-a overflows to
           infinity as Re -> 0, where the term is 0, and vanishes as Re grows, where it tends to
           (Re A + 8.4 Re^0.657) / (24 eps^2); multiplied through by Re^a instead, both Re^a and its
           denominator overflow for large Re and give inf / inf */
        const fsdem_real phi = 1 - eps, re = eps * rho * d * slip / mu;
        const fsdem_real inertial =
            re > 0 ? (re * (1 / eps + 3 * phi * eps) + (fsdem_real)8.4 * (fsdem_real)pow(re, 0.657)) /
                         (24 * eps * eps * (1 + (fsdem_real)pow(10.0, 3 * phi) * (fsdem_real)pow(re, -(0.5 + 2 * phi))))
                   : 0;
        const fsdem_real f = 10 * phi / (eps * eps) + eps * eps * (1 + (fsdem_real)1.5 * (fsdem_real)sqrt(phi)) +
                             (fsdem_real)0.413 * inertial;
        return 18 * mu * eps * f / (d * d);
    }
    }
    return 0;
}

const char *fsdem_drag_law_name(fsdem_drag_law law) {
    switch (law) {
    case FSDEM_DRAG_LAW_STOKES: return "stokes";
    case FSDEM_DRAG_LAW_SCHILLER_NAUMANN: return "schiller_naumann";
    case FSDEM_DRAG_LAW_ERGUN_WEN_YU: return "ergun_wen_yu";
    case FSDEM_DRAG_LAW_GIDASPOW: return "gidaspow";
    case FSDEM_DRAG_LAW_DI_FELICE: return "di_felice";
    case FSDEM_DRAG_LAW_BEETSTRA: return "beetstra";
    }
    return "unknown";
}

fsdem_result fsdem_drag_coefficient(fsdem_drag_law law, fsdem_real porosity, fsdem_real diameter, fsdem_real slip_speed,
                                    fsdem_real density, fsdem_real viscosity, fsdem_real *per_volume, fsdem_real *beta,
                                    char *message, size_t message_size) {
    static const char fn[] = "fsdem_drag_coefficient";
    fsdem_real c;
    if ((int)law < (int)FSDEM_DRAG_LAW_STOKES || (int)law > (int)FSDEM_DRAG_LAW_BEETSTRA)
        return fsdem__reject(message, message_size, "%s: law must be a fsdem_drag_law, got %d", fn, (int)law);
    if (!(porosity > 0 && porosity <= 1))
        return fsdem__reject(message, message_size, "%s: porosity must be in (0, 1], got %g", fn, (double)porosity);
    if (!(diameter > 0) || !fsdem__finite(diameter))
        return fsdem__reject(message, message_size, "%s: diameter must be > 0 and finite, got %g m", fn, (double)diameter);
    if (!(slip_speed >= 0 && slip_speed <= FSDEM_MAX_SPEED))
        return fsdem__reject(message, message_size, "%s: slip_speed must be in [0, FSDEM_MAX_SPEED = %g] m/s, got %g m/s", fn,
                             (double)FSDEM_MAX_SPEED, (double)slip_speed);
    if (!(density > 0) || !fsdem__finite(density))
        return fsdem__reject(message, message_size, "%s: density must be > 0 and finite, got %g kg/m^3", fn, (double)density);
    if (!(viscosity > 0) || !fsdem__finite(viscosity))
        return fsdem__reject(message, message_size, "%s: viscosity must be > 0 and finite, got %g Pa s", fn,
                             (double)viscosity);
    c = fsdem__drag_per_volume(law, porosity, diameter, slip_speed, density, viscosity);
    if (!fsdem__finite(c)) {
        if (message && message_size)
            snprintf(message, message_size, "%s: c = %g kg m^-3 s^-1 overflows for porosity %g, d = %g m, Re = %g", fn, (double)c,
                     (double)porosity, (double)diameter, (double)(porosity * density * diameter * slip_speed / viscosity));
        return FSDEM_ERR_NAN;
    }
    if (per_volume) *per_volume = c;
    if (beta) *beta = c * (1 - porosity);
    return FSDEM_OK;
}

/* ===== >>impl_couple_mps : unresolved MPS-DEM ========================================================

   Contents: >>couple_mps_object (desc, creation), >>couple_mps_exchange (seed 002 Eq. 25-36: pairs,
   porosity, averages, forces, reactions), >>couple_mps_step (coupled time stepping). The coupler
   reaches the solvers through their coupling functions only (>>doc). */

/* ---- >>couple_mps_object : desc, creation ---- */

/* An MPS particle within the radius of a DEM particle, and its w_s (Eq. 29). */
typedef struct fsdem__mps_dem_pair {
    int particle;
    fsdem_real weight;
} fsdem__mps_dem_pair;

struct fsdem_mps_dem {
    fsdem_mps_dem_desc desc;
    fsdem__status status;
    fsdem_allocator allocator;
    int dim;
    fsdem_mps_model model;         /* the MPS desc's */
    fsdem_real rho, mu;            /* fluid density, dynamic viscosity */
    fsdem_real ns;                 /* n_s of Eq. 30 (m^3; m^2 in 2D) */
    fsdem_real cell_volume;        /* r0^d of the MPS lattice (m^3; m^2 in 2D) */
    fsdem_real depth;              /* m; the DEM's disc_length in 2D (forces per metre on the MPS), 1 in 3D */
    fsdem_vec3 gravity;            /* m/s^2 */
    fsdem_cellgrid grid;           /* MPS particles, cells of edge radius / 2 (fsdem__mps_dem_ranges) */
    /* DEM-MPS pairs within the radius, by DEM particle: start[k] .. start[k+1] */
    int *start, start_cap;
    fsdem__mps_dem_pair *pair;
    int pair_cap;
    fsdem_real *solid;             /* per MPS particle: sum_k w_s V_k (Eq. 31) */
    int solid_cap;
    fsdem_mps_dem_force *force;    /* per DEM particle */
    int force_cap, forces;         /* forces: DEM particles of the last update (0: none yet) */
    /* statistics */
    long long steps, substeps, substeps_total, pairs;
    fsdem_real dt_last, drag_dt;
    int wet;
    fsdem_vec3 drag_sum, pressure_sum, fluid_sum;
    double sec_mps, sec_dem;
};

fsdem_mps_dem_desc fsdem_mps_dem_desc_default(void) {
    fsdem_mps_dem_desc d;
    memset(&d, 0, sizeof d);
    d.drag = FSDEM_DRAG_LAW_ERGUN_WEN_YU;
    d.radius = 0;
    d.min_porosity = (fsdem_real)0.2;
    d.drag_dt_fraction = (fsdem_real)0.5;
    d.max_substeps = 100000;
    return d;
}

fsdem_result fsdem_mps_dem_desc_check(const fsdem_mps_dem_desc *d, char *msg, size_t size) {
    fsdem_dem_desc dd;
    fsdem_mps_desc md;
    if (!d) return fsdem__reject(msg, size, "fsdem_mps_dem_desc is NULL");
    if (!d->mps || !d->dem) return fsdem__reject(msg, size, "fsdem_mps_dem_desc.mps and .dem must both be set");
    dd = fsdem_dem_get_desc(d->dem);
    md = fsdem_mps_get_desc(d->mps);
    if (dd.dim != md.dim)
        return fsdem__reject(msg, size, "fsdem_mps_dem_desc: the DEM is %dD and the MPS %dD", dd.dim, md.dim);
    if (fsdem__norm(fsdem__sub(dd.gravity, md.gravity)) > 1e-12 * fsdem__norm(md.gravity))
        return fsdem__reject(msg, size, "fsdem_mps_dem_desc: the DEM gravity (%g, %g, %g) differs from the MPS's (%g, %g, %g) m/s^2",
                             (double)dd.gravity.x, (double)dd.gravity.y, (double)dd.gravity.z, (double)md.gravity.x,
                             (double)md.gravity.y, (double)md.gravity.z);
    if (strcmp(fsdem_drag_law_name(d->drag), "unknown") == 0)
        return fsdem__reject(msg, size, "fsdem_mps_dem_desc.drag = %d is not a fsdem_drag_law", (int)d->drag);
    if (!(d->radius == 0 || (d->radius > 0 && d->radius <= fsdem__smallest_extent(md.domain_min, md.domain_max, md.dim))))
        return fsdem__reject(msg, size, "fsdem_mps_dem_desc.radius must be 0 (the MPS re) or in (0, %g] m, the MPS domain's smallest extent (got %g m)",
                             (double)fsdem__smallest_extent(md.domain_min, md.domain_max, md.dim), (double)d->radius);
    if (!(d->min_porosity > 0 && d->min_porosity < 1))
        return fsdem__reject(msg, size, "fsdem_mps_dem_desc.min_porosity must be in (0, 1) (got %g)", (double)d->min_porosity);
    if (!(d->drag_dt_fraction > 0 && d->drag_dt_fraction <= 1))
        return fsdem__reject(msg, size, "fsdem_mps_dem_desc.drag_dt_fraction must be in (0, 1] (got %g)",
                             (double)d->drag_dt_fraction);
    if (d->max_substeps < 1)
        return fsdem__reject(msg, size, "fsdem_mps_dem_desc.max_substeps must be >= 1 (got %lld)", d->max_substeps);
    return FSDEM_OK;
}

fsdem_result fsdem_mps_dem_create(const fsdem_mps_dem_desc *desc, fsdem_mps_dem **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_allocator al;
    fsdem_mps_dem *c;
    fsdem_mps_desc md;
    fsdem_result res;
    fsdem_real re;
    if (out) *out = NULL;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    res = fsdem_mps_dem_desc_check(desc, msg, sizeof msg);
    if (res == FSDEM_OK) al = fsdem_dem_get_desc(desc->dem).allocator;
    c = (fsdem_mps_dem *)fsdem__object_new(res, msg, desc ? desc->log : NULL, desc ? desc->log_user : NULL,
                                           res == FSDEM_OK ? &al : NULL, sizeof *c, "fsdem_mps_dem_create", &res);
    if (!c) return res;
    md = fsdem_mps_get_desc(desc->mps);
    c->desc = *desc;
    c->allocator = al;
    c->status.log = desc->log;
    c->status.log_user = desc->log_user;
    c->dim = md.dim;
    c->model = md.model;
    c->rho = md.density;
    c->mu = md.density * md.viscosity;
    c->gravity = md.gravity;
    c->depth = md.dim == 2 ? fsdem_dem_get_desc(desc->dem).disc_length : 1;
    re = c->desc.radius = desc->radius > 0 ? desc->radius : md.re;
    /* Eq. 30: n_s = int w_s dV = (10 pi / 21) r_e^3; in the plane the same integral is (10 pi / 21) r_e^2 */
    c->ns = (fsdem_real)(10 * FSDEM__PI / 21) * re * re * (c->dim == 3 ? re : 1);
    c->cell_volume = md.r0 * md.r0 * (c->dim == 3 ? md.r0 : 1);
    if (fsdem_cellgrid_setup(&c->grid, &c->allocator, c->dim, md.domain_min, md.domain_max, re / 2, 0) != FSDEM_OK) {
        fsdem__log_oom(desc->log, desc->log_user, "fsdem_mps_dem_create", sizeof c->grid);
        fsdem_mps_dem_destroy(c);
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    *out = c;
    return FSDEM_OK;
}

void fsdem_mps_dem_destroy(fsdem_mps_dem *c) {
    fsdem_allocator al;
    if (!c) return;
    al = c->allocator;
    fsdem_cellgrid_free(&c->grid);
    fsdem__free(&al, c->start, sizeof(int) * (size_t)c->start_cap);
    fsdem__free(&al, c->pair, sizeof *c->pair * (size_t)c->pair_cap);
    fsdem__free(&al, c->solid, sizeof(fsdem_real) * (size_t)c->solid_cap);
    fsdem__free(&al, c->force, sizeof(fsdem_mps_dem_force) * (size_t)c->force_cap);
    fsdem__free(&al, c, sizeof *c);
}

const char *fsdem_mps_dem_last_error(const fsdem_mps_dem *c) { return c ? c->status.message : "fsdem_mps_dem is NULL"; }

fsdem_mps_dem_desc fsdem_mps_dem_get_desc(const fsdem_mps_dem *c) {
    fsdem_mps_dem_desc d;
    if (c) return c->desc;
    memset(&d, 0, sizeof d);
    return d;
}

/* ---- >>couple_mps_exchange : pairs, porosity, averages, forces, reactions ---- */

/* Eq. 29 at distance r (0 beyond re). */
static fsdem_real fsdem__mps_dem_weight(fsdem_real r, fsdem_real re) {
    const fsdem_real x = r / re, x4 = x * x * x * x;
    return x < 1 ? 4 * x4 * x - 5 * x4 + 1 : 0;
}

/* Volume of DEM particle k that the porosity counts: the sphere, or in 2D the disc's area (volume
   per metre of depth, as the MPS's). */
static fsdem_real fsdem__mps_dem_volume(const fsdem_mps_dem *c, fsdem_real r) {
    return c->dim == 3 ? (fsdem_real)(4 * FSDEM__PI / 3) * r * r * r : (fsdem_real)FSDEM__PI * r * r;
}

/* The grid's items within distance r of p, as ranges of `items`: the cells are r/2 wide and a row
   of cells along x is contiguous in the grid's order, so the block of 5 cells per axis around p is
   at most 25 ranges in 3D (5 in 2D); rows whose nearest point is farther than r are left out. This
   scans about 60% of the candidates of the 3^d block of cells r wide. Returns the number of ranges. */
static int fsdem__mps_dem_ranges(const fsdem_cellgrid *g, fsdem_vec3 p, fsdem_real r, int range[25][2]) {
    int lo[3], hi[3], a, y, z, count = 0;
    for (a = 0; a < 3; ++a) {
        const fsdem_real x = fsdem__comp(p, a) - fsdem__comp(g->origin, a);
        lo[a] = (int)floor((x - r) * g->inv_cell_size);
        hi[a] = (int)floor((x + r) * g->inv_cell_size);
        if (a == 2 && g->dim == 2) lo[a] = hi[a] = 0;
        if (lo[a] < 0) lo[a] = 0;
        if (hi[a] > g->n[a] - 1) hi[a] = g->n[a] - 1;
        if (lo[a] > hi[a]) return 0;
    }
    for (z = lo[2]; z <= hi[2]; ++z)
        for (y = lo[1]; y <= hi[1]; ++y) {
            /* distance from p to the row's slab in y and z (0 inside it) */
            const fsdem_real cy = fsdem__comp(g->origin, 1) + (fsdem_real)y * g->cell_size, cz = fsdem__comp(g->origin, 2) + (fsdem_real)z * g->cell_size;
            const fsdem_real dy = p.y < cy ? cy - p.y : p.y > cy + g->cell_size ? p.y - cy - g->cell_size : 0;
            const fsdem_real dz = g->dim == 2 ? 0 : p.z < cz ? cz - p.z : p.z > cz + g->cell_size ? p.z - cz - g->cell_size : 0;
            const int row = (z * g->n[1] + y) * g->n[0];
            if (dy * dy + dz * dz >= r * r) continue;
            range[count][0] = g->cell_start[row + lo[0]];
            range[count++][1] = g->cell_start[row + hi[0] + 1];
        }
    return count;
}

/* The normaliser of Eq. 31 at MPS particle i: n_s (Eq. 30) less the part of the weight's integral
   that lies inside the tank's walls and obstacles, the sum of w_s r0^d over their WALL and DUMMY
   particles (a lattice of cells of volume r0^d, which covers the walls to re = 4.1 r0 deep). Next
   to a wall the spheres can only fill the open part of the kernel: dividing by the whole n_s, as
   Eq. 31 does, read a packed bed as half as dense at the wall and let the water bypass it there
   (a packing of porosity 0.476 in a tank 16 r0 wide averaged 0.546 over the cross-section). */
static fsdem_real fsdem__mps_dem_open_weight(const fsdem_mps_dem *c, const fsdem_mps_particles *mv, int i) {
    const fsdem_real re = c->desc.radius, re2 = re * re;
    fsdem_real walls = 0;
    int range[25][2], m, e;
    const int nr = fsdem__mps_dem_ranges(&c->grid, mv->position[i], re, range);
    for (m = 0; m < nr; ++m)
        for (e = range[m][0]; e < range[m][1]; ++e) {
            const int j = c->grid.items[e];
            const fsdem_vec3 d = fsdem__sub(mv->position[j], mv->position[i]);
            const fsdem_real r2 = fsdem__dot(d, d);
            if (mv->kind[j] != FSDEM_MPS_KIND_FLUID && r2 < re2) walls += fsdem__mps_dem_weight((fsdem_real)sqrt(r2), re);
        }
    walls *= c->cell_volume;
    /* a corner of three walls leaves an eighth open; the floor only guards a particle pushed into a wall */
    return walls < (fsdem_real)0.9 * c->ns ? c->ns - walls : (fsdem_real)0.1 * c->ns;
}

/* Makes room for the per-particle arrays (nd DEM, nm MPS particles). */
static fsdem_result fsdem__mps_dem_room(fsdem_mps_dem *c, int nd, int nm) {
    const fsdem_allocator *al = &c->allocator;
    int cap = c->force_cap;
    if (fsdem__grow(al, (void **)&c->start, &c->start_cap, 0, nd + 1, sizeof(int)) != FSDEM_OK ||
        fsdem__grow(al, (void **)&c->force, &cap, 0, nd, sizeof(fsdem_mps_dem_force)) != FSDEM_OK)
        return FSDEM_ERR_OUT_OF_MEMORY;
    c->force_cap = cap;
    return fsdem__grow(al, (void **)&c->solid, &c->solid_cap, 0, nm, sizeof(fsdem_real));
}

/* The non-DUMMY MPS particles within the radius of every DEM particle, with their w_s. */
static fsdem_result fsdem__mps_dem_pairs(fsdem_mps_dem *c, const fsdem_dem_particles *dv, const fsdem_mps_particles *mv) {
    const fsdem_real re = c->desc.radius, re2 = re * re;
    int k, m, e, n = 0;
    if (fsdem_cellgrid_build(&c->grid, mv->position, mv->count) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
    for (k = 0; k < dv->count; ++k) {
        int range[25][2];
        const int nr = fsdem__mps_dem_ranges(&c->grid, dv->position[k], re, range);
        c->start[k] = n;
        for (m = 0; m < nr; ++m)
            for (e = range[m][0]; e < range[m][1]; ++e) {
                const int i = c->grid.items[e];
                const fsdem_vec3 d = fsdem__sub(mv->position[i], dv->position[k]);
                const fsdem_real r2 = fsdem__dot(d, d);
                if (mv->kind[i] == FSDEM_MPS_KIND_DUMMY || !(r2 < re2)) continue;
                if (n == c->pair_cap &&
                    fsdem__grow(&c->allocator, (void **)&c->pair, &c->pair_cap, n, n + 1, sizeof *c->pair) != FSDEM_OK)
                    return FSDEM_ERR_OUT_OF_MEMORY;
                c->pair[n].particle = i;
                c->pair[n++].weight = fsdem__mps_dem_weight((fsdem_real)sqrt(r2), re);
            }
    }
    c->start[dv->count] = n;
    c->pairs = n;
    return FSDEM_OK;
}

/* Steps 3-4 of >>couple_mps for DEM particle k, whose FLUID neighbours' weights sum to W > 0 with
   porosity eps, velocity u and pressure gradient gp (w_s averages): its force, and the reactions. */
static void fsdem__mps_dem_exchange(fsdem_mps_dem *c, const fsdem_dem_particles *dv, const fsdem_mps_particles *mv,
                                    const fsdem_mps_coupling *mc, int k, fsdem_real W, fsdem_real eps, fsdem_vec3 u,
                                    fsdem_vec3 gp) {
    fsdem_mps_dem_force *f = &c->force[k];
    const fsdem_real r = dv->radius[k], V = fsdem__mps_dem_volume(c, r) * (c->dim == 2 ? c->depth : 1);
    const fsdem_vec3 slip = fsdem__sub(u, dv->velocity[k]);
    const fsdem_real speed = fsdem__norm(slip);
    const fsdem_real per_volume = fsdem__drag_per_volume(c->desc.drag, eps, 2 * r, speed, c->rho, c->mu);
    fsdem_real coefficient = per_volume * V; /* kg/s: the force per unit slip on the particle */
    fsdem_vec3 exchanged;
    int e;
    f->wet = 1;
    f->porosity = eps;
    f->fluid_velocity = u;
    f->reynolds = eps * c->rho * 2 * r * speed / c->mu; /* Eq. 28 */
    f->drag = fsdem__scale(slip, coefficient);          /* Eq. 25 */
    if (c->model == FSDEM_MPS_MODEL_A) {
        f->pressure = fsdem__scale(gp, -V); /* Eq. 34 */
        f->total = fsdem__add(f->drag, f->pressure);
        exchanged = f->drag;
    } else {
        f->pressure = fsdem__scale(c->gravity, -V * c->rho); /* Eq. 35 */
        f->total = fsdem__madd(f->pressure, f->drag, 1 / eps);
        coefficient /= eps;
        exchanged = f->total;
    }
    if (!dv->fixed[k] && coefficient > 0) {
        const fsdem_real tau = dv->mass[k] / coefficient; /* drag relaxation time */
        if (c->drag_dt == 0 || tau < c->drag_dt) c->drag_dt = tau;
    }
    /* Eq. 36: the reaction shared in proportion to w_s / W, whose shares sum to one */
    exchanged = fsdem__scale(exchanged, -1 / (W * c->depth));
    for (e = c->start[k]; e < c->start[k + 1]; ++e) {
        const int i = c->pair[e].particle;
        if (mv->kind[i] == FSDEM_MPS_KIND_FLUID) mc->force[i] = fsdem__madd(mc->force[i], exchanged, c->pair[e].weight);
    }
}

fsdem_result fsdem_mps_dem_update(fsdem_mps_dem *c) {
    fsdem_dem_particles dv;
    fsdem_mps_particles mv;
    fsdem_mps_coupling mc;
    fsdem_dem_coupling dc;
    clock_t t0 = clock();
    int i, k, e;
    if (!c) return FSDEM_ERR_INVALID_ARG;
    {
        const fsdem_mps_desc md = fsdem_mps_get_desc(c->desc.mps);
        if (fsdem__dem_particles_fit(c->desc.dem, md.domain_min, md.domain_max, &c->status, "fsdem_mps_dem_update") != FSDEM_OK)
            return FSDEM_ERR_INVALID_ARG;
    }
    dv = fsdem_dem_get_particles(c->desc.dem);
    mv = fsdem_mps_get_particles(c->desc.mps);
    if (fsdem__mps_dem_room(c, dv.count, mv.count) != FSDEM_OK || fsdem__mps_dem_pairs(c, &dv, &mv) != FSDEM_OK)
        return fsdem__fail(&c->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_mps_dem_update: out of memory (%d DEM and %d MPS particles)",
                           dv.count, mv.count);
    mc = fsdem_mps_get_coupling(c->desc.mps);
    dc = fsdem_dem_get_coupling(c->desc.dem);
    /* 1. porosity of the MPS particles, Eq. 31 */
    for (i = 0; i < mv.count; ++i) c->solid[i] = 0;
    for (k = 0; k < dv.count; ++k) {
        const fsdem_real V = fsdem__mps_dem_volume(c, dv.radius[k]);
        for (e = c->start[k]; e < c->start[k + 1]; ++e) c->solid[c->pair[e].particle] += c->pair[e].weight * V;
    }
    for (i = 0; i < mv.count; ++i) {
        fsdem_real eps = 1;
        if (mv.kind[i] == FSDEM_MPS_KIND_FLUID && c->solid[i] > 0) eps = 1 - c->solid[i] / fsdem__mps_dem_open_weight(c, &mv, i);
        mc.porosity[i] = eps > c->desc.min_porosity ? eps : c->desc.min_porosity;
        mc.force[i] = fsdem__zero3();
    }
    /* 2-4. averages at the DEM particles (Eq. 32-33), forces (Eq. 25-28, 34-35), reactions (Eq. 36) */
    c->wet = 0;
    c->drag_dt = 0;
    c->drag_sum = c->pressure_sum = fsdem__zero3();
    for (k = 0; k < dv.count; ++k) {
        fsdem_real W = 0, E = 0;
        fsdem_vec3 U = fsdem__zero3(), G = fsdem__zero3();
        for (e = c->start[k]; e < c->start[k + 1]; ++e) {
            const int i = c->pair[e].particle;
            const fsdem_real w = c->pair[e].weight;
            if (mv.kind[i] != FSDEM_MPS_KIND_FLUID) continue;
            W += w;
            E += w * mc.porosity[i];
            U = fsdem__madd(U, mv.velocity[i], w);
            G = fsdem__madd(G, mv.pressure_gradient[i], w);
        }
        memset(&c->force[k], 0, sizeof c->force[k]);
        c->force[k].id = dv.id[k];
        c->force[k].porosity = 1;
        if (W > 0) {
            fsdem__mps_dem_exchange(c, &dv, &mv, &mc, k, W, E / W, fsdem__scale(U, 1 / W), fsdem__scale(G, 1 / W));
            c->wet++;
        }
        if (!fsdem__finite3(c->force[k].total))
            return fsdem__fail(&c->status, FSDEM_ERR_NAN, "fsdem_mps_dem_update: the fluid force on DEM particle %d is not finite", k);
        dc.force[k] = c->force[k].total;
        c->drag_sum = fsdem__add(c->drag_sum, c->force[k].drag);
        c->pressure_sum = fsdem__add(c->pressure_sum, c->force[k].pressure);
    }
    c->fluid_sum = fsdem__zero3();
    for (i = 0; i < mv.count; ++i) c->fluid_sum = fsdem__add(c->fluid_sum, mc.force[i]);
    c->fluid_sum = fsdem__scale(c->fluid_sum, c->depth);
    c->forces = dv.count;
    c->sec_dem += (double)(clock() - t0) / CLOCKS_PER_SEC;
    return fsdem__ok(&c->status);
}

/* The record of DEM particle `index` (-1: none). */
static int fsdem__mps_dem_record(const fsdem_mps_dem *c, int index) {
    return c->forces ? fsdem__dem_record_of(c->desc.dem, index, &c->force[0].id, sizeof *c->force, c->forces) : -1;
}

fsdem_result fsdem_mps_dem_get_force(const fsdem_mps_dem *c, int index, fsdem_mps_dem_force *out) {
    int k;
    if (!c || !out) return FSDEM_ERR_INVALID_ARG;
    if ((k = fsdem__mps_dem_record(c, index)) < 0)
        return fsdem__fail((fsdem__status *)&c->status, FSDEM_ERR_NOT_FOUND, "fsdem_mps_dem_get_force: no particle %d in the last update",
                           index);
    *out = c->force[k];
    return FSDEM_OK;
}

/* ---- >>couple_mps_step : coupled time stepping ---- */

/* The stable coupled step of the last update: the MPS's (Eq. 37) and the drag limit. */
static fsdem_result fsdem__mps_dem_stable(const fsdem_mps_dem *c, fsdem_real *dt) {
    const fsdem_result res = fsdem_mps_stable_dt(c->desc.mps, dt);
    if (res != FSDEM_OK) return res;
    if (c->drag_dt > 0 && c->desc.drag_dt_fraction * c->drag_dt < *dt) *dt = c->desc.drag_dt_fraction * c->drag_dt;
    return FSDEM_OK;
}

/* Step 5 of >>couple_mps after an update: the MPS step of dt, then the DEM substeps. */
static fsdem_result fsdem__mps_dem_run(fsdem_mps_dem *c, fsdem_real dt) {
    long long substeps = 0;
    fsdem_result res = fsdem__dem_substeps_within(c->desc.dem, dt, c->desc.max_substeps, &c->status, "fsdem_mps_dem");
    clock_t t0, t1;
    if (res != FSDEM_OK) return res;
    if (c->drag_dt > 0 && dt > c->desc.drag_dt_fraction * c->drag_dt * (1 + (fsdem_real)1e-6))
        return fsdem__fail(&c->status, FSDEM_ERR_CFL,
                           "fsdem_mps_dem: dt = %g s exceeds drag_dt_fraction %g of the shortest drag relaxation time %g s", (double)dt,
                           (double)c->desc.drag_dt_fraction, (double)c->drag_dt);
    t0 = clock();
    res = fsdem_mps_step_dt(c->desc.mps, dt);
    t1 = clock();
    c->sec_mps += (double)(t1 - t0) / CLOCKS_PER_SEC;
    if (res != FSDEM_OK) return fsdem__fail(&c->status, res, "fsdem_mps_dem: MPS step: %s", fsdem_mps_last_error(c->desc.mps));
    res = fsdem_dem_advance(c->desc.dem, dt, &substeps);
    c->sec_dem += (double)(clock() - t1) / CLOCKS_PER_SEC;
    c->steps++;
    c->dt_last = dt;
    c->substeps = substeps;
    c->substeps_total += substeps;
    if (res != FSDEM_OK) return fsdem__fail(&c->status, res, "fsdem_mps_dem: DEM substeps: %s", fsdem_dem_last_error(c->desc.dem));
    return fsdem__ok(&c->status);
}

fsdem_result fsdem_mps_dem_step(fsdem_mps_dem *c) {
    fsdem_real dt = 0;
    fsdem_result res;
    if (!c) return FSDEM_ERR_INVALID_ARG;
    if ((res = fsdem_mps_dem_update(c)) != FSDEM_OK) return res;
    if ((res = fsdem__mps_dem_stable(c, &dt)) != FSDEM_OK)
        return fsdem__fail(&c->status, res, "fsdem_mps_dem_step: %s", fsdem_mps_last_error(c->desc.mps));
    return fsdem__mps_dem_run(c, dt);
}

fsdem_result fsdem_mps_dem_step_dt(fsdem_mps_dem *c, fsdem_real dt) {
    fsdem_result res;
    if (!c) return FSDEM_ERR_INVALID_ARG;
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(&c->status, FSDEM_ERR_INVALID_ARG, "fsdem_mps_dem_step_dt: dt = %g s must be > 0 and finite", (double)dt);
    if ((res = fsdem_mps_dem_update(c)) != FSDEM_OK) return res;
    return fsdem__mps_dem_run(c, dt);
}

/* fsdem__coupled_advance's verbs for this coupler: the update and its stable step, the step. */
static double fsdem__mps_dem_now(const void *c) { return fsdem_mps_time(((const fsdem_mps_dem *)c)->desc.mps); }

static fsdem_result fsdem__mps_dem_prepare(void *object, fsdem_real *dt) {
    fsdem_mps_dem *c = (fsdem_mps_dem *)object;
    fsdem_result res = fsdem_mps_dem_update(c);
    if (res == FSDEM_OK && (res = fsdem__mps_dem_stable(c, dt)) != FSDEM_OK)
        fsdem__fail(&c->status, res, "fsdem_mps_dem_advance: %s", fsdem_mps_last_error(c->desc.mps));
    return res;
}

static fsdem_result fsdem__mps_dem_go(void *c, fsdem_real dt) { return fsdem__mps_dem_run((fsdem_mps_dem *)c, dt); }

fsdem_result fsdem_mps_dem_advance(fsdem_mps_dem *c, fsdem_real duration, long long *steps) {
    static const fsdem__coupled_verbs verbs = {fsdem__mps_dem_now, fsdem__mps_dem_prepare, fsdem__mps_dem_go};
    if (steps) *steps = 0;
    if (!c) return FSDEM_ERR_INVALID_ARG;
    return fsdem__coupled_advance(c, &c->status, "fsdem_mps_dem_advance", &verbs, duration, steps);
}

fsdem_result fsdem_mps_dem_stable_dt(const fsdem_mps_dem *c, fsdem_real *dt) {
    if (!c || !dt) return FSDEM_ERR_INVALID_ARG;
    return fsdem__mps_dem_stable(c, dt);
}

double fsdem_mps_dem_time(const fsdem_mps_dem *c) { return c ? fsdem_mps_time(c->desc.mps) : 0; }

fsdem_mps_dem_stats fsdem_mps_dem_get_stats(const fsdem_mps_dem *c) {
    fsdem_mps_dem_stats st;
    memset(&st, 0, sizeof st);
    if (!c) return st;
    st.steps = c->steps;
    st.time = fsdem_mps_time(c->desc.mps);
    st.dt = c->dt_last;
    st.substeps = c->substeps;
    st.substeps_total = c->substeps_total;
    st.wet = c->wet;
    st.drag = c->drag_sum;
    st.pressure = c->pressure_sum;
    st.to_fluid = c->fluid_sum;
    st.drag_dt = c->drag_dt;
    st.pairs = c->pairs;
    st.seconds_mps = c->sec_mps;
    st.seconds_dem = c->sec_dem;
    return st;
}

/* ===== >>impl_couple_pic : resolved PIC-DEM ==========================================================

   Contents: >>couple_pic_object (desc, creation, per-body storage), >>couple_pic_faces (bodies as
   moving cut-cell solids: face fractions, solid velocities, J, references), >>couple_pic_exchange
   (the implicit pressure term, fluid forces), >>couple_pic_gap (Eq. 20, particles out of bodies),
   >>couple_pic_step (coupled time stepping). The coupler writes the PIC through its coupling
   functions and cuts the faces with the PIC's own face-fraction routine (fsdem__pic_face_fraction),
   so static obstacles and moving bodies are cut alike. */

/* ---- >>couple_pic_object : desc, creation, per-body storage ---- */

/* For every PIC cell, the items (bodies or contacts) whose box covers it: item[start[c] ..
   start[c + 1]). */
typedef struct fsdem__pic_dem_map {
    int *start; /* ncell + 1 */
    int *item;
    int item_cap;
} fsdem__pic_dem_map;

struct fsdem_pic_dem {
    fsdem_pic_dem_desc desc;
    fsdem__status status;
    fsdem_allocator allocator;
    int dim;
    fsdem_real rho, nu;            /* liquid density, kinematic viscosity */
    fsdem_real depth;              /* m; the DEM's disc_length in 2D (the PIC works per metre), 1 in 3D */
    fsdem_vec3 gravity;            /* m/s^2 */
    /* per body (DEM particle), `bodies` of them */
    int bodies, body_cap;
    int *body_id;        /* stable DEM id of each body of the last step */
    fsdem_vec3 *vstar, *wstar;     /* predicted velocities Q* (step 1) */
    fsdem_real *inv_m, *inv_i;     /* 1/kg and 1/(kg m^2) per metre of depth (0: fixed) */
    fsdem_vec3 *fp, *fv, *tq;      /* last step's loads on the whole body (N, N m) */
    fsdem_vec3 *wc;                /* N; the well-balanced weight's correction of the last step */
    fsdem_real *volume;            /* m^3 (m^2 in 2D) as the faces normal to gravity see it */
    fsdem_real *weight;            /* that volume over the exact one (desc.discrete_weight), else 1 */
    fsdem_real *relax;             /* s; viscous relaxation time (0: none) */
    /* faces each body covers or cuts: entries face_start[b] .. face_start[b + 1] */
    int *face_start;
    int *face;                     /* face index in its axis */
    unsigned char *face_axis;
    fsdem_real *face_closed;       /* 1 - E_b */
    int face_count, face_cap;
    /* J of each body: cells jac_start[b] .. jac_start[b + 1], linear and angular parts */
    int *jac_start, *jac_cell;
    fsdem_vec3 *jac_v, *jac_w;
    int jac_count, jac_cap;

    int *slot;                     /* per cell: entry of the current body's J, -1 */
    fsdem__pic_dem_map body_map, contact_map;
    fsdem_dem_contact *contact;    /* contacts after the last step, and their points (step 6) */
    fsdem_vec3 *contact_point;
    int contact_count, contact_cap;
    int operator_set;              /* the pressure term is installed */
    /* statistics */
    long long steps, substeps, substeps_total, dissipated, pushed, removed;
    fsdem_real dt_last, viscous_dt;
    fsdem_vec3 force_sum;
    double sec_pic, sec_dem, sec_coupling;
    int loaded;                    /* the loads of a step are in fp, fv, tq */
};

fsdem_pic_dem_desc fsdem_pic_dem_desc_default(void) {
    fsdem_pic_dem_desc d;
    memset(&d, 0, sizeof d);
    d.dissipation = (fsdem_real)0.5;
    d.contact_length = 0;
    d.viscous_dt_fraction = (fsdem_real)0.5;
    d.discrete_weight = 1;
    d.max_substeps = 100000;
    return d;
}

fsdem_result fsdem_pic_dem_desc_check(const fsdem_pic_dem_desc *d, char *msg, size_t size) {
    fsdem_dem_desc dd;
    fsdem_pic_desc pd;
    if (!d) return fsdem__reject(msg, size, "fsdem_pic_dem_desc is NULL");
    if (!d->pic || !d->dem) return fsdem__reject(msg, size, "fsdem_pic_dem_desc.pic and .dem must both be set");
    dd = fsdem_dem_get_desc(d->dem);
    pd = fsdem_pic_get_desc(d->pic);
    if (dd.dim != pd.dim) return fsdem__reject(msg, size, "fsdem_pic_dem_desc: the DEM is %dD and the PIC %dD", dd.dim, pd.dim);
    if (fsdem__norm(fsdem__sub(dd.gravity, pd.gravity)) > 1e-12 * fsdem__norm(pd.gravity))
        return fsdem__reject(msg, size, "fsdem_pic_dem_desc: the DEM gravity (%g, %g, %g) differs from the PIC's (%g, %g, %g) m/s^2",
                             (double)dd.gravity.x, (double)dd.gravity.y, (double)dd.gravity.z, (double)pd.gravity.x,
                             (double)pd.gravity.y, (double)pd.gravity.z);
    if (!(d->dissipation >= 0 && d->dissipation <= 1))
        return fsdem__reject(msg, size, "fsdem_pic_dem_desc.dissipation must be in [0, 1] (got %g)", (double)d->dissipation);
    if (!(d->contact_length >= 0 && d->contact_length <= fsdem__smallest_extent(pd.domain_min, pd.domain_max, pd.dim)))
        return fsdem__reject(msg, size,
                             "fsdem_pic_dem_desc.contact_length must be 0 (4 dx) or in (0, %g] m, the PIC domain's smallest extent (got %g m)",
                             (double)fsdem__smallest_extent(pd.domain_min, pd.domain_max, pd.dim), (double)d->contact_length);
    if (!(d->viscous_dt_fraction > 0 && d->viscous_dt_fraction <= 1))
        return fsdem__reject(msg, size, "fsdem_pic_dem_desc.viscous_dt_fraction must be in (0, 1] (got %g)",
                             (double)d->viscous_dt_fraction);
    if (d->discrete_weight != 0 && d->discrete_weight != 1)
        return fsdem__reject(msg, size, "fsdem_pic_dem_desc.discrete_weight must be 0 or 1 (got %d)", d->discrete_weight);
    if (d->max_substeps < 1)
        return fsdem__reject(msg, size, "fsdem_pic_dem_desc.max_substeps must be >= 1 (got %lld)", d->max_substeps);
    return FSDEM_OK;
}

static void fsdem__pic_dem_free_bodies(fsdem_pic_dem *c) {
    const size_t n = (size_t)c->body_cap, V = sizeof(fsdem_vec3) * n, R = sizeof(fsdem_real) * n;
    fsdem__free(&c->allocator, c->vstar, V);
    fsdem__free(&c->allocator, c->wstar, V);
    fsdem__free(&c->allocator, c->fp, V);
    fsdem__free(&c->allocator, c->fv, V);
    fsdem__free(&c->allocator, c->tq, V);
    fsdem__free(&c->allocator, c->wc, V);
    fsdem__free(&c->allocator, c->inv_m, R);
    fsdem__free(&c->allocator, c->inv_i, R);
    fsdem__free(&c->allocator, c->volume, R);
    fsdem__free(&c->allocator, c->weight, R);
    fsdem__free(&c->allocator, c->relax, R);
    fsdem__free(&c->allocator, c->face_start, sizeof(int) * (n + 1));
    fsdem__free(&c->allocator, c->jac_start, sizeof(int) * (n + 1));
    fsdem__free(&c->allocator, c->body_id, sizeof(int) * n);
    c->vstar = c->wstar = c->fp = c->fv = c->tq = c->wc = NULL;
    c->inv_m = c->inv_i = c->volume = c->weight = c->relax = NULL;
    c->face_start = c->jac_start = c->body_id = NULL;
    c->body_cap = 0;
}

/* Per-body arrays for `n` bodies (zeroed). Allocates only when the DEM has more particles than any
   step before. */
static fsdem_result fsdem__pic_dem_reserve_bodies(fsdem_pic_dem *c, int n) {
    const size_t m = (size_t)(n > 0 ? n : 1), V = sizeof(fsdem_vec3) * m, R = sizeof(fsdem_real) * m;
    if (n <= c->body_cap && c->vstar) return FSDEM_OK;
    fsdem__pic_dem_free_bodies(c);
    c->vstar = (fsdem_vec3 *)fsdem__alloc(&c->allocator, V);
    c->wstar = (fsdem_vec3 *)fsdem__alloc(&c->allocator, V);
    c->fp = (fsdem_vec3 *)fsdem__alloc(&c->allocator, V);
    c->fv = (fsdem_vec3 *)fsdem__alloc(&c->allocator, V);
    c->tq = (fsdem_vec3 *)fsdem__alloc(&c->allocator, V);
    c->wc = (fsdem_vec3 *)fsdem__alloc(&c->allocator, V);
    c->inv_m = (fsdem_real *)fsdem__alloc(&c->allocator, R);
    c->inv_i = (fsdem_real *)fsdem__alloc(&c->allocator, R);
    c->volume = (fsdem_real *)fsdem__alloc(&c->allocator, R);
    c->weight = (fsdem_real *)fsdem__alloc(&c->allocator, R);
    c->relax = (fsdem_real *)fsdem__alloc(&c->allocator, R);
    c->face_start = (int *)fsdem__alloc(&c->allocator, sizeof(int) * (m + 1));
    c->jac_start = (int *)fsdem__alloc(&c->allocator, sizeof(int) * (m + 1));
    c->body_id = (int *)fsdem__alloc(&c->allocator, sizeof(int) * m);
    c->body_cap = (int)m;
    if (!c->vstar || !c->wstar || !c->fp || !c->fv || !c->tq || !c->wc || !c->inv_m || !c->inv_i || !c->volume || !c->weight || !c->relax ||
        !c->face_start || !c->jac_start || !c->body_id) {
        fsdem__pic_dem_free_bodies(c);
        return FSDEM_ERR_OUT_OF_MEMORY;
    }
    memset(c->vstar, 0, V);
    memset(c->wstar, 0, V);
    memset(c->fp, 0, V);
    memset(c->fv, 0, V);
    memset(c->tq, 0, V);
    memset(c->wc, 0, V);
    memset(c->volume, 0, R);
    memset(c->weight, 0, R);
    memset(c->relax, 0, R);
    memset(c->face_start, 0, sizeof(int) * (m + 1));
    memset(c->jac_start, 0, sizeof(int) * (m + 1));
    memset(c->body_id, 0, sizeof(int) * m);
    c->loaded = 0;
    return FSDEM_OK;
}

static void fsdem__pic_dem_release(fsdem_pic_dem *c) {
    const int ncell = c->desc.pic->ncell;
    fsdem__pic_dem_free_bodies(c);
    fsdem__free(&c->allocator, c->face, sizeof(int) * (size_t)c->face_cap);
    fsdem__free(&c->allocator, c->face_axis, (size_t)c->face_cap);
    fsdem__free(&c->allocator, c->face_closed, sizeof(fsdem_real) * (size_t)c->face_cap);
    fsdem__free(&c->allocator, c->jac_cell, sizeof(int) * (size_t)c->jac_cap);
    fsdem__free(&c->allocator, c->jac_v, sizeof(fsdem_vec3) * (size_t)c->jac_cap);
    fsdem__free(&c->allocator, c->jac_w, sizeof(fsdem_vec3) * (size_t)c->jac_cap);
    fsdem__free(&c->allocator, c->slot, sizeof(int) * (size_t)ncell);
    fsdem__free(&c->allocator, c->body_map.start, sizeof(int) * (size_t)(ncell + 1));
    fsdem__free(&c->allocator, c->body_map.item, sizeof(int) * (size_t)c->body_map.item_cap);
    fsdem__free(&c->allocator, c->contact_map.start, sizeof(int) * (size_t)(ncell + 1));
    fsdem__free(&c->allocator, c->contact_map.item, sizeof(int) * (size_t)c->contact_map.item_cap);
    fsdem__free(&c->allocator, c->contact, sizeof(fsdem_dem_contact) * (size_t)c->contact_cap);
    fsdem__free(&c->allocator, c->contact_point, sizeof(fsdem_vec3) * (size_t)c->contact_cap);
}

static fsdem_result fsdem__pic_dem_faces(fsdem_pic_dem *c, fsdem_real dt);
static fsdem_result fsdem__pic_dem_exclude(fsdem_pic_dem *c, int from, int remove);
static void fsdem__pic_dem_clear_faces(fsdem_pic_dem *c);
static void fsdem__pic_dem_operator(void *user, const fsdem_real *p, fsdem_real *y);

fsdem_result fsdem_pic_dem_create(const fsdem_pic_dem_desc *desc, fsdem_pic_dem **out) {
    char msg[FSDEM__MESSAGE_SIZE];
    fsdem_allocator al;
    fsdem_pic_dem *c;
    fsdem_pic_desc pd;
    fsdem_result res;
    int ncell, i;
    if (out) *out = NULL;
    if (!out) return FSDEM_ERR_INVALID_ARG;
    res = fsdem_pic_dem_desc_check(desc, msg, sizeof msg);
    if (res == FSDEM_OK) al = fsdem_dem_get_desc(desc->dem).allocator;
    c = (fsdem_pic_dem *)fsdem__object_new(res, msg, desc ? desc->log : NULL, desc ? desc->log_user : NULL,
                                           res == FSDEM_OK ? &al : NULL, sizeof *c, "fsdem_pic_dem_create", &res);
    if (!c) return res;
    pd = fsdem_pic_get_desc(desc->pic);
    c->desc = *desc;
    c->allocator = al;
    c->status.log = desc->log;
    c->status.log_user = desc->log_user;
    c->dim = pd.dim;
    c->rho = pd.density;
    c->nu = pd.viscosity;
    c->gravity = pd.gravity;
    c->depth = pd.dim == 2 ? fsdem_dem_get_desc(desc->dem).disc_length : 1;
    if (!(desc->contact_length > 0)) c->desc.contact_length = 4 * pd.cell_size; /* seed 000 §2.2.2 */
    ncell = desc->pic->ncell;
    if (fsdem__dem_particles_fit(desc->dem, pd.domain_min, pd.domain_max, &c->status, "fsdem_pic_dem_create") != FSDEM_OK) {
        if (desc->log) desc->log(desc->log_user, FSDEM_LOG_LEVEL_ERROR, c->status.message);
        fsdem__free(&al, c, sizeof *c);
        return FSDEM_ERR_INVALID_ARG;
    }
    c->slot = (int *)fsdem__alloc(&c->allocator, sizeof(int) * (size_t)ncell);
    c->body_map.start = (int *)fsdem__alloc(&c->allocator, sizeof(int) * (size_t)(ncell + 1));
    c->contact_map.start = (int *)fsdem__alloc(&c->allocator, sizeof(int) * (size_t)(ncell + 1));
    res = c->slot && c->body_map.start && c->contact_map.start ? FSDEM_OK : FSDEM_ERR_OUT_OF_MEMORY;
    if (res == FSDEM_OK) {
        for (i = 0; i < ncell; ++i) c->slot[i] = -1;
        res = fsdem__pic_dem_reserve_bodies(c, fsdem_dem_get_particles(desc->dem).count);
    }
    if (res == FSDEM_OK) res = fsdem__pic_dem_exclude(c, 0, 1);
    if (res == FSDEM_OK) res = fsdem__pic_dem_faces(c, 0);
    if (res == FSDEM_OK) res = fsdem_pic_set_pressure_extra(desc->pic, fsdem__pic_dem_operator, c);
    if (res != FSDEM_OK) {
        if (desc->log) desc->log(desc->log_user, FSDEM_LOG_LEVEL_ERROR, c->status.message[0] ? c->status.message : "fsdem_pic_dem_create: out of memory");
        fsdem_pic_dem_destroy(c);
        return res;
    }
    c->operator_set = 1;
    *out = c;
    return FSDEM_OK;
}

void fsdem_pic_dem_destroy(fsdem_pic_dem *c) {
    fsdem_allocator al;
    if (!c) return;
    al = c->allocator;
    if (c->operator_set) fsdem_pic_set_pressure_extra(c->desc.pic, NULL, NULL);
    fsdem__pic_dem_clear_faces(c);
    fsdem__pic_dem_release(c);
    fsdem__free(&al, c, sizeof *c);
}

const char *fsdem_pic_dem_last_error(const fsdem_pic_dem *c) { return c ? c->status.message : "fsdem_pic_dem is NULL"; }

fsdem_pic_dem_desc fsdem_pic_dem_get_desc(const fsdem_pic_dem *c) {
    fsdem_pic_dem_desc d;
    if (c) return c->desc;
    memset(&d, 0, sizeof d);
    return d;
}

/* ---- >>couple_pic_faces : bodies as moving cut-cell solids ---- */

/* A disc or sphere as a fsdem__pic_dist_fn. */
typedef struct fsdem__pic_dem_ball {
    fsdem_vec3 centre;
    fsdem_real radius;
} fsdem__pic_dem_ball;

static fsdem_real fsdem__pic_dem_ball_dist(const void *solid, fsdem_vec3 p) {
    const fsdem__pic_dem_ball *b = (const fsdem__pic_dem_ball *)solid;
    return fsdem__norm(fsdem__sub(p, b->centre)) - b->radius;
}

/* Index range [*lo, *hi] along axis q of the grid points at lo_q + (i + off) dx that lie within
   [x0, x1], clamped to 0 .. count - 1 (empty when *lo > *hi). */
static void fsdem__pic_dem_range(const fsdem_pic *s, int q, fsdem_real off, fsdem_real x0, fsdem_real x1, int count, int *lo, int *hi) {
    const fsdem_real o = fsdem__comp(s->lo, q);
    double a = ceil((double)((x0 - o) * s->inv_dx - off)), b = floor((double)((x1 - o) * s->inv_dx - off));
    *lo = a < 0 ? 0 : a > count ? count : (int)a;
    *hi = b >= count ? count - 1 : b < -1 ? -1 : (int)b;
}

/* Adds `v`, `w` to cell `cell`'s entry of the J of the body being cut (entries from `first`). */
static fsdem_result fsdem__pic_dem_jac_add(fsdem_pic_dem *c, int cell, fsdem_vec3 v, fsdem_vec3 w) {
    int e = c->slot[cell];
    if (e < 0) {
        void **const arrays[3] = {(void **)&c->jac_cell, (void **)&c->jac_v, (void **)&c->jac_w};
        const size_t elem[3] = {sizeof(int), sizeof(fsdem_vec3), sizeof(fsdem_vec3)};
        if (fsdem__grow_set(&c->allocator, arrays, elem, 3, &c->jac_cap, c->jac_count, c->jac_count + 1) != FSDEM_OK)
            return FSDEM_ERR_OUT_OF_MEMORY;
        e = c->slot[cell] = c->jac_count++;
        c->jac_cell[e] = cell;
        c->jac_v[e] = c->jac_w[e] = fsdem__zero3();
    }
    c->jac_v[e] = fsdem__add(c->jac_v[e], v);
    c->jac_w[e] = fsdem__add(c->jac_w[e], w);
    return FSDEM_OK;
}

static fsdem_result fsdem__pic_dem_face_add(fsdem_pic_dem *c, int a, int f, fsdem_real closed) {
    void **const arrays[3] = {(void **)&c->face, (void **)&c->face_axis, (void **)&c->face_closed};
    const size_t elem[3] = {sizeof(int), 1, sizeof(fsdem_real)};
    if (fsdem__grow_set(&c->allocator, arrays, elem, 3, &c->face_cap, c->face_count, c->face_count + 1) != FSDEM_OK)
        return FSDEM_ERR_OUT_OF_MEMORY;
    c->face[c->face_count] = f;
    c->face_axis[c->face_count] = (unsigned char)a;
    c->face_closed[c->face_count] = closed;
    c->face_count++;
    return FSDEM_OK;
}

/* Resets the PIC's moving-solid arrays (open, at rest, full), all of them: the coupler owns them,
   and a restored PIC may hold another run's cut. */
static void fsdem__pic_dem_clear_faces(fsdem_pic_dem *c) {
    fsdem_pic_coupling cp = fsdem_pic_get_coupling(c->desc.pic);
    int a, e;
    for (a = 0; a < cp.dim; ++a) {
        for (e = 0; e < cp.face_count[a]; ++e) cp.open[a][e] = 1;
        memset(cp.solid_velocity[a], 0, sizeof(fsdem_real) * (size_t)cp.face_count[a]);
        if (cp.viscous_velocity[a]) memset(cp.viscous_velocity[a], 0, sizeof(fsdem_real) * (size_t)cp.face_count[a]);
    }
    for (e = 0; e < c->desc.pic->ncell; ++e) cp.reference[e] = 1;
    c->face_count = 0;
}

/* Part of the fluid-fraction kernel of cell (i, j, k) (the tent over the 2^dim cells around its
   centre) outside the ball, sampled on 4 points per axis (fsdem__pic_compute_fref samples the
   static obstacles alike). */
static fsdem_real fsdem__pic_dem_kernel_open(const fsdem_pic *s, const fsdem__pic_dem_ball *ball, int i, int j, int k) {
    const int S = 4;
    const fsdem_vec3 cc = fsdem__pic_cell_pos(s, i, j, k);
    const fsdem_real h = 2 * s->dx / (fsdem_real)S;
    fsdem_real open = 0, all = 0;
    int q[3], m;
    for (q[2] = 0; q[2] < (s->dim == 3 ? S : 1); ++q[2])
        for (q[1] = 0; q[1] < S; ++q[1])
            for (q[0] = 0; q[0] < S; ++q[0]) {
                fsdem_vec3 p = cc;
                fsdem_real w = 1;
                for (m = 0; m < s->dim; ++m) {
                    const fsdem_real off = -s->dx + h * ((fsdem_real)q[m] + (fsdem_real)0.5);
                    w *= 1 - (fsdem_real)fabs(off) * s->inv_dx;
                    p = fsdem__pic_axis_shift(p, m, off);
                }
                all += w;
                if (fsdem__pic_dem_ball_dist(ball, p) > 0) open += w;
            }
    return open / all;
}

/* Cuts body b (step 2 of >>couple_pic): its faces (their closed parts, summed into the PIC's open
   fractions as pending negative values) and its references. */
static fsdem_result fsdem__pic_dem_cut(fsdem_pic_dem *c, int b, fsdem_vec3 centre, fsdem_real radius) {
    fsdem_pic *s = c->desc.pic;
    fsdem_pic_coupling cp = fsdem_pic_get_coupling(s);
    const fsdem__pic_dem_ball ball = {centre, radius};
    const fsdem_real reach = s->dx * (s->dim == 3 ? (fsdem_real)0.7072 : (fsdem_real)0.5001), margin = radius + s->dx;
    int a, q, lo[3], hi[3], idx[3];
    c->face_start[b] = c->face_count;
    for (a = 0; a < s->dim; ++a) {
        for (q = 0; q < 3; ++q) {
            if (q < s->dim)
                fsdem__pic_dem_range(s, q, q == a ? 0 : (fsdem_real)0.5, fsdem__comp(centre, q) - margin, fsdem__comp(centre, q) + margin,
                                     s->fn[a][q], &lo[q], &hi[q]);
            else lo[q] = hi[q] = 0;
        }
        for (idx[2] = lo[2]; idx[2] <= hi[2]; ++idx[2])
            for (idx[1] = lo[1]; idx[1] <= hi[1]; ++idx[1])
                for (idx[0] = lo[0]; idx[0] <= hi[0]; ++idx[0]) {
                    const int f = fsdem__pic_face(s, a, idx[0], idx[1], idx[2]), coord = idx[a];
                    const fsdem_vec3 pf = fsdem__pic_face_pos(s, a, idx[0], idx[1], idx[2]), arm = fsdem__sub(pf, centre);
                    const fsdem_real d = fsdem__norm(arm) - radius;
                    fsdem_real closed, *open = &cp.open[a][f];
                    if (d > reach) continue;
                    /* the domain's closed sides keep E = 0 and their own velocity (>>pic_cells) */
                    if ((coord == 0 || coord == s->n[a]) && fsdem__pic_side_closed(s, 2 * a + (coord != 0))) continue;
                    if (d < -reach) closed = 1;
                    else {
                        fsdem_vec3 corner = fsdem__pic_axis_shift(pf, (a + 1) % s->dim, -s->dx / 2);
                        if (s->dim == 3) corner = fsdem__pic_axis_shift(corner, (a + 2) % 3, -s->dx / 2);
                        closed = 1 - fsdem__pic_face_fraction(s, a, corner, fsdem__pic_dem_ball_dist, &ball);
                    }
                    if (!(closed > 0)) continue;
                    if (fsdem__pic_dem_face_add(c, a, f, closed) != FSDEM_OK) return FSDEM_ERR_OUT_OF_MEMORY;
                    *open = *open >= 0 ? -closed : *open - closed; /* first body on this face, or the next */
                }
    }
    /* references of the cells whose kernel the body reaches */
    for (q = 0; q < 3; ++q) {
        if (q < s->dim) fsdem__pic_dem_range(s, q, (fsdem_real)0.5, fsdem__comp(centre, q) - margin, fsdem__comp(centre, q) + margin, s->n[q], &lo[q], &hi[q]);
        else lo[q] = hi[q] = 0;
    }
    for (idx[2] = lo[2]; idx[2] <= hi[2]; ++idx[2])
        for (idx[1] = lo[1]; idx[1] <= hi[1]; ++idx[1])
            for (idx[0] = lo[0]; idx[0] <= hi[0]; ++idx[0]) {
                const int cell = fsdem__pic_cell(s, idx[0], idx[1], idx[2]);
                const fsdem_real open = fsdem__pic_dem_kernel_open(s, &ball, idx[0], idx[1], idx[2]);
                if (open < 1) cp.reference[cell] *= open; /* bodies do not overlap: their parts multiply */
            }
    return FSDEM_OK;
}

/* J of body b (step 3 of >>couple_pic) from the final closed parts of its faces: each face is the
   upper face of the cell below it (s = +1) and the lower face of the cell above it (s = -1). */
static fsdem_result fsdem__pic_dem_jacobian(fsdem_pic_dem *c, int b, fsdem_vec3 centre) {
    const fsdem_pic *s = c->desc.pic;
    int e, idx[3];
    c->jac_start[b] = c->jac_count;
    for (e = c->face_start[b]; e < c->face_start[b + 1]; ++e) {
        const int a = c->face_axis[e], f = c->face[e];
        fsdem_vec3 ea = fsdem__pic_axis_shift(fsdem__zero3(), a, c->face_closed[e]), arm, w;
        int coord;
        idx[0] = f % s->fn[a][0];
        idx[1] = f / s->fn[a][0] % s->fn[a][1];
        idx[2] = f / (s->fn[a][0] * s->fn[a][1]);
        coord = idx[a];
        arm = fsdem__sub(fsdem__pic_face_pos(s, a, idx[0], idx[1], idx[2]), centre);
        w = fsdem__cross(arm, ea);
        if (coord > 0 &&
            fsdem__pic_dem_jac_add(c, fsdem__pic_cell(s, idx[0] - (a == 0), idx[1] - (a == 1), idx[2] - (a == 2)), ea, w) != FSDEM_OK)
            return FSDEM_ERR_OUT_OF_MEMORY;
        if (coord < s->n[a] &&
            fsdem__pic_dem_jac_add(c, fsdem__pic_cell(s, idx[0], idx[1], idx[2]), fsdem__scale(ea, -1), fsdem__scale(w, -1)) != FSDEM_OK)
            return FSDEM_ERR_OUT_OF_MEMORY;
    }
    c->jac_start[b + 1] = c->jac_count;
    for (e = c->jac_start[b]; e < c->jac_count; ++e) c->slot[c->jac_cell[e]] = -1;
    return FSDEM_OK;
}

/* Faces that bodies leave open by less than this are closed: the projection controls only E u on a
   face, so the velocity of a sliver of a face (a gap between bodies, the edge of a body) would be
   free to spike. */
#define FSDEM__PIC_DEM_MIN_OPEN ((fsdem_real)0.02)

/* Steps 1-3 of >>couple_pic for a coming step of dt (0: the state only, at creation): every body
   cut into the PIC's coupling arrays, its volume as the faces see it, Q*, the solid velocities and
   J, then the viscous relaxation times. */
static fsdem_result fsdem__pic_dem_faces(fsdem_pic_dem *c, fsdem_real dt) {
    fsdem_pic *s = c->desc.pic;
    fsdem_pic_coupling cp = fsdem_pic_get_coupling(s);
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    const fsdem_real inertia = c->dim == 3 ? (fsdem_real)0.4 : (fsdem_real)0.5; /* the DEM's spheres and discs */
    const fsdem_real visc = c->rho * c->nu * (c->dim == 3 ? s->dx : 1);    /* >>pic_viscosity, per pair */
    const fsdem_real cell = s->dx * s->dx * (s->dim == 3 ? s->dx : 1), g2 = fsdem__dot(c->gravity, c->gravity);
    int b, e, q;
    fsdem_result res;
    if ((res = fsdem__pic_dem_reserve_bodies(c, P.count)) != FSDEM_OK)
        return fsdem__fail(&c->status, res, "fsdem_pic_dem: out of memory for the records of %d bodies", P.count);
    fsdem__pic_dem_clear_faces(c);
    c->bodies = P.count;
    if (P.count) memcpy(c->body_id, P.id, sizeof(int) * (size_t)P.count);
    for (b = 0; b < P.count; ++b)
        if ((res = fsdem__pic_dem_cut(c, b, P.position[b], P.radius[b])) != FSDEM_OK) {
            c->face_start[b + 1] = c->face_count;
            c->bodies = b + 1;
            for (q = 0; q <= c->bodies; ++q) c->jac_start[q] = 0;
            return fsdem__fail(&c->status, res, "fsdem_pic_dem: out of memory cutting body %d", b);
        }
    c->face_start[P.count] = c->face_count;
    /* the faces' closed parts are pending (open = -(their sum)): each body's part is scaled to the
       face's final closed part, slivers closed */
    for (e = 0; e < c->face_count; ++e) {
        const fsdem_real total = -cp.open[c->face_axis[e]][c->face[e]];
        const fsdem_real final_closed = total > 1 - FSDEM__PIC_DEM_MIN_OPEN ? 1 : total;
        c->face_closed[e] *= final_closed / total;
    }
    for (b = 0; b < P.count; ++b) {
        const fsdem_real m = P.mass[b], r = P.radius[b], I = inertia * m * r * r;
        const fsdem_real exact = (fsdem_real)FSDEM__PI * r * r * (c->dim == 3 ? (fsdem_real)4 / 3 * r : 1);
        fsdem_real axis[3] = {0, 0, 0}, seen = 0;
        for (e = c->face_start[b]; e < c->face_start[b + 1]; ++e) axis[c->face_axis[e]] += c->face_closed[e] * cell;
        /* the volume that a pressure gradient along gravity acts on: sum_a (g_a^2 / g^2) V_a */
        for (q = 0; q < c->dim; ++q) seen += g2 > 0 ? fsdem__comp(c->gravity, q) * fsdem__comp(c->gravity, q) / g2 * axis[q] : axis[q] / (fsdem_real)c->dim;
        c->volume[b] = seen;
        c->weight[b] = c->desc.discrete_weight && seen > 0 ? seen / exact : 1;
        if (P.fixed[b]) {
            c->inv_m[b] = c->inv_i[b] = 0;
            c->vstar[b] = P.velocity[b];
            c->wstar[b] = P.angular_velocity[b];
        } else {
            c->inv_m[b] = c->depth / m;
            c->inv_i[b] = c->depth / I;
            c->vstar[b] = fsdem__add(P.velocity[b], fsdem__scale(fsdem__add(fsdem__scale(c->gravity, c->weight[b]), fsdem__scale(P.force[b], 1 / m)), dt));
            c->wstar[b] = fsdem__add(P.angular_velocity[b], fsdem__scale(P.torque[b], dt / I));
        }
        if (c->dim == 2) {
            c->vstar[b].z = 0;
            c->wstar[b].x = c->wstar[b].y = 0;
        }
        /* the solid fluxes: closed part times the body's velocity at the face centre, Q* for the
           projection and the start velocity for the viscous solve's no-slip */
        for (e = c->face_start[b]; e < c->face_start[b + 1]; ++e) {
            const int a = c->face_axis[e], f = c->face[e];
            int idx[3];
            fsdem_vec3 arm;
            idx[0] = f % s->fn[a][0];
            idx[1] = f / s->fn[a][0] % s->fn[a][1];
            idx[2] = f / (s->fn[a][0] * s->fn[a][1]);
            arm = fsdem__sub(fsdem__pic_face_pos(s, a, idx[0], idx[1], idx[2]), P.position[b]);
            cp.solid_velocity[a][f] += c->face_closed[e] * fsdem__comp(fsdem__add(c->vstar[b], fsdem__cross(c->wstar[b], arm)), a);
            if (cp.viscous_velocity[a])
                cp.viscous_velocity[a][f] +=
                    c->face_closed[e] * fsdem__comp(fsdem__add(P.velocity[b], fsdem__cross(P.angular_velocity[b], arm)), a);
        }
    }
    /* open fractions, and the solid velocity as the closed-part-weighted mean */
    for (e = 0; e < c->face_count; ++e) {
        fsdem_real *open = &cp.open[c->face_axis[e]][c->face[e]];
        if (*open < 0) {
            const fsdem_real total = -*open, closed = total > 1 - FSDEM__PIC_DEM_MIN_OPEN ? 1 : total;
            cp.solid_velocity[c->face_axis[e]][c->face[e]] /= closed;
            if (cp.viscous_velocity[c->face_axis[e]]) cp.viscous_velocity[c->face_axis[e]][c->face[e]] /= closed;
            *open = 1 - closed;
        }
    }
    c->jac_count = 0;
    for (b = 0; b < P.count; ++b)
        if ((res = fsdem__pic_dem_jacobian(c, b, P.position[b])) != FSDEM_OK) {
            for (q = 0; q <= c->bodies; ++q) c->jac_start[q] = 0;
            c->jac_count = 0;
            return fsdem__fail(&c->status, res, "fsdem_pic_dem: out of memory for the J of body %d", b);
        }
    /* the viscous relaxation time: the fastest component of the viscous solve's pull, visc per
       (closed face, open neighbour) pair (>>pic_viscosity) */
    c->viscous_dt = 0;
    for (b = 0; b < c->bodies; ++b) {
        int pairs[3] = {0, 0, 0}, most = 0;
        for (e = c->face_start[b]; e < c->face_start[b + 1]; ++e) {
            const int a = c->face_axis[e], f = c->face[e];
            if (cp.open[a][f] > 0) continue;
            for (q = 0; q < s->dim; ++q) {
                int coord = q == 0 ? f % s->fn[a][0] : q == 1 ? f / s->fn[a][0] % s->fn[a][1] : f / (s->fn[a][0] * s->fn[a][1]);
                if (coord > 0 && cp.open[a][f - s->fstep[a][q]] > 0) pairs[a]++;
                if (coord + 1 < s->fn[a][q] && cp.open[a][f + s->fstep[a][q]] > 0) pairs[a]++;
            }
        }
        for (q = 0; q < s->dim; ++q)
            if (pairs[q] > most) most = pairs[q];
        c->relax[b] = 0;
        if (visc > 0 && most > 0 && c->inv_m[b] > 0) {
            /* translation m / (visc pairs); rotation I / (visc pairs r^2) is shorter (I < m r^2) */
            const fsdem_real mr = c->depth / c->inv_m[b] < c->depth / (c->inv_i[b] * P.radius[b] * P.radius[b])
                                      ? c->depth / c->inv_m[b]
                                      : c->depth / (c->inv_i[b] * P.radius[b] * P.radius[b]);
            c->relax[b] = mr / (c->depth * visc * (fsdem_real)most);
            if (c->viscous_dt == 0 || c->relax[b] < c->viscous_dt) c->viscous_dt = c->relax[b];
        }
    }
    return FSDEM_OK;
}

/* ---- >>couple_pic_exchange : the implicit pressure term, fluid forces ---- */

/* y += rho dx^dim J M^-1 J^T p over the FLUID cells (step 3 of >>couple_pic), per metre in 2D. */
static void fsdem__pic_dem_operator(void *user, const fsdem_real *p, fsdem_real *y) {
    const fsdem_pic_dem *c = (const fsdem_pic_dem *)user;
    const fsdem_pic *s = c->desc.pic;
    const unsigned char *type = s->ctype;
    /* with acc = M^-1 G (G = dx^(dim-1) J^T p) the term is rho dx J . acc */
    const fsdem_real area = s->dim == 3 ? s->dx * s->dx : s->dx, k = c->rho * s->dx;
    int b, e;
    for (b = 0; b < c->bodies; ++b) {
        fsdem_vec3 G = fsdem__zero3(), T = fsdem__zero3(), acc, alpha;
        if (c->inv_m[b] == 0) continue;
        for (e = c->jac_start[b]; e < c->jac_start[b + 1]; ++e) {
            const int cell = c->jac_cell[e];
            if (type[cell] != FSDEM_STENCIL_CELL_FLUID) continue;
            G = fsdem__madd(G, c->jac_v[e], p[cell]);
            T = fsdem__madd(T, c->jac_w[e], p[cell]);
        }
        acc = fsdem__scale(G, area * c->inv_m[b]);
        alpha = fsdem__scale(T, area * c->inv_i[b]);
        for (e = c->jac_start[b]; e < c->jac_start[b + 1]; ++e) {
            const int cell = c->jac_cell[e];
            if (type[cell] != FSDEM_STENCIL_CELL_FLUID) continue;
            y[cell] += k * (fsdem__dot(c->jac_v[e], acc) + fsdem__dot(c->jac_w[e], alpha));
        }
    }
}

/* Step 4 of >>couple_pic after the PIC step: the pressure force G and the viscous force of every
   body from the step's pressure and shear, given to the DEM as held external loads. */
static fsdem_result fsdem__pic_dem_loads(fsdem_pic_dem *c) {
    const fsdem_pic *s = c->desc.pic;
    fsdem_pic_coupling cp = fsdem_pic_get_coupling(c->desc.pic);
    const fsdem_pic_fields g = fsdem_pic_get_fields(s);
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    fsdem_dem_coupling dc = fsdem_dem_get_coupling(c->desc.dem);
    const fsdem_real area = s->dim == 3 ? s->dx * s->dx : s->dx;
    int b, e;
    c->force_sum = fsdem__zero3();
    for (b = 0; b < c->bodies; ++b) {
        fsdem_vec3 G = fsdem__zero3(), T = fsdem__zero3(), F = fsdem__zero3(), Tv = fsdem__zero3();
        for (e = c->jac_start[b]; e < c->jac_start[b + 1]; ++e) {
            G = fsdem__madd(G, c->jac_v[e], g.pressure[c->jac_cell[e]]);
            T = fsdem__madd(T, c->jac_w[e], g.pressure[c->jac_cell[e]]);
        }
        for (e = c->face_start[b]; e < c->face_start[b + 1] && cp.shear[0]; ++e) {
            const int a = c->face_axis[e], f = c->face[e];
            const fsdem_real closed = 1 - cp.open[a][f], share = closed > c->face_closed[e] ? c->face_closed[e] / closed : 1;
            const fsdem_real v = cp.shear[a][f] * share;
            fsdem_vec3 force = fsdem__pic_axis_shift(fsdem__zero3(), a, v), arm;
            int idx[3];
            if (v == 0) continue;
            idx[0] = f % s->fn[a][0];
            idx[1] = f / s->fn[a][0] % s->fn[a][1];
            idx[2] = f / (s->fn[a][0] * s->fn[a][1]);
            arm = fsdem__sub(fsdem__pic_face_pos(s, a, idx[0], idx[1], idx[2]), P.position[b]);
            F = fsdem__add(F, force);
            Tv = fsdem__add(Tv, fsdem__cross(arm, force));
        }
        c->fp[b] = fsdem__scale(G, area * c->depth);
        c->fv[b] = fsdem__scale(F, c->depth);
        c->tq[b] = fsdem__scale(fsdem__add(fsdem__scale(T, area), Tv), c->depth);
        if (!fsdem__finite3(c->fp[b]) || !fsdem__finite3(c->fv[b]) || !fsdem__finite3(c->tq[b]))
            return fsdem__fail(&c->status, FSDEM_ERR_NAN, "fsdem_pic_dem: the fluid force on body %d is not finite", b);
        c->force_sum = fsdem__add(c->force_sum, fsdem__add(c->fp[b], c->fv[b]));
        if (dc.count > b) {
            /* the well-balanced weight's correction (item 8 of >>couple_pic; 0 for fixed bodies) */
            c->wc[b] = P.fixed[b] ? fsdem__zero3() : fsdem__scale(c->gravity, P.mass[b] * (c->weight[b] - 1));
            dc.force[b] = fsdem__add(fsdem__add(c->fp[b], c->fv[b]), c->wc[b]);
            dc.torque[b] = c->tq[b];
        }
    }
    c->loaded = 1;
    return FSDEM_OK;
}

/* The load record of DEM particle `index` (-1: none). */
static int fsdem__pic_dem_record(const fsdem_pic_dem *c, int index) {
    return c->loaded && c->bodies ? fsdem__dem_record_of(c->desc.dem, index, c->body_id, sizeof(int), c->bodies) : -1;
}

fsdem_result fsdem_pic_dem_get_force(const fsdem_pic_dem *c, int index, fsdem_pic_dem_force *out) {
    int k;
    if (!c || !out) return FSDEM_ERR_INVALID_ARG;
    if ((k = fsdem__pic_dem_record(c, index)) < 0)
        return fsdem__fail((fsdem__status *)&c->status, FSDEM_ERR_NOT_FOUND, "fsdem_pic_dem_get_force: no body %d in the last step (%d)",
                           index, c->loaded ? c->bodies : 0);
    out->id = c->body_id[k];
    out->pressure_force = c->fp[k];
    out->viscous_force = c->fv[k];
    out->torque = c->tq[k];
    out->weight_correction = c->wc[k];
    out->volume = c->volume[k];
    out->faces = c->face_start[k + 1] - c->face_start[k];
    return fsdem__ok((fsdem__status *)&c->status);
}

/* ---- >>couple_pic_gap : Eq. 20, particles out of bodies ---- */

/* Builds the cell map of `count` boxes [centre_i - half_i, centre_i + half_i]. */
static fsdem_result fsdem__pic_dem_map_build(fsdem_pic_dem *c, fsdem__pic_dem_map *map, int count, const fsdem_vec3 *centre,
                                             const fsdem_real *half, fsdem_real half_all) {
    const fsdem_pic *s = c->desc.pic;
    int pass, i, q, lo[3], hi[3], idx[3], total = 0;
    memset(map->start, 0, sizeof(int) * (size_t)(s->ncell + 1));
    for (pass = 0; pass < 2; ++pass) {
        for (i = 0; i < count; ++i) {
            const fsdem_real h = half ? half[i] : half_all;
            for (q = 0; q < 3; ++q) {
                if (q < s->dim) fsdem__pic_dem_range(s, q, (fsdem_real)0.5, fsdem__comp(centre[i], q) - h - s->dx / 2,
                                                     fsdem__comp(centre[i], q) + h + s->dx / 2, s->n[q], &lo[q], &hi[q]);
                else lo[q] = hi[q] = 0;
            }
            for (idx[2] = lo[2]; idx[2] <= hi[2]; ++idx[2])
                for (idx[1] = lo[1]; idx[1] <= hi[1]; ++idx[1])
                    for (idx[0] = lo[0]; idx[0] <= hi[0]; ++idx[0]) {
                        const int cell = fsdem__pic_cell(s, idx[0], idx[1], idx[2]);
                        if (pass == 0) map->start[cell + 1]++;
                        else map->item[map->start[cell]++] = i;
                    }
        }
        if (pass == 0) {
            for (i = 0; i < s->ncell; ++i) map->start[i + 1] += map->start[i];
            total = map->start[s->ncell];
            if (fsdem__grow(&c->allocator, (void **)&map->item, &map->item_cap, 0, total > 0 ? total : 1, sizeof(int)) != FSDEM_OK)
                return FSDEM_ERR_OUT_OF_MEMORY;
        }
    }
    /* the second pass advanced every start to the next cell's: shift back */
    for (i = s->ncell; i > 0; --i) map->start[i] = map->start[i - 1];
    map->start[0] = 0;
    return FSDEM_OK;
}

/* The bodies as one solid for fsdem_pic_exclude_particles (`user` is the coupler). */
static fsdem_real fsdem__pic_dem_solid(void *user, fsdem_vec3 p, fsdem_vec3 *normal) {
    const fsdem_pic_dem *c = (const fsdem_pic_dem *)user;
    const int cell = fsdem__pic_cell_of(c->desc.pic, p);
    fsdem_dem_particles P;
    fsdem_real best = (fsdem_real)1e30;
    int e;
    *normal = fsdem_v3(1, 0, 0);
    if (c->body_map.start[cell] == c->body_map.start[cell + 1]) return best; /* most particles: no body near */
    P = fsdem_dem_get_particles(c->desc.dem);
    for (e = c->body_map.start[cell]; e < c->body_map.start[cell + 1]; ++e) {
        const int b = c->body_map.item[e];
        const fsdem_vec3 r = fsdem__sub(p, P.position[b]);
        const fsdem_real len = fsdem__norm(r), d = len - P.radius[b];
        if (d < best) {
            best = d;
            *normal = len > 0 ? fsdem__scale(r, 1 / len) : fsdem_v3(0, 1, 0);
        }
    }
    return best;
}

/* Step 7 of >>couple_pic: particles inside bodies `from` .. are moved out (remove = 0) or removed. */
static fsdem_result fsdem__pic_dem_exclude(fsdem_pic_dem *c, int from, int remove) {
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    int moved = 0, e;
    fsdem_result res;
    if (from >= P.count) return FSDEM_OK;
    if (fsdem__pic_dem_map_build(c, &c->body_map, P.count - from, P.position + from, P.radius + from, 0) != FSDEM_OK)
        return fsdem__fail(&c->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_dem: out of memory mapping the bodies");
    for (e = 0; e < c->body_map.start[c->desc.pic->ncell] && from > 0; ++e) c->body_map.item[e] += from;
    res = fsdem_pic_exclude_particles(c->desc.pic, fsdem__pic_dem_solid, c, remove, &moved);
    if (res != FSDEM_OK) return fsdem__fail(&c->status, res, "fsdem_pic_dem: %s", fsdem_pic_last_error(c->desc.pic));
    if (remove) c->removed += moved;
    else c->pushed += moved;
    return FSDEM_OK;
}

/* Step 6 of >>couple_pic: Eq. 20 in the contact area of every contact of the DEM's positions. */
static fsdem_result fsdem__pic_dem_gap(fsdem_pic_dem *c) {
    const fsdem_real beta = c->desc.dissipation, half = c->desc.contact_length / 2;
    const fsdem_real offset = fsdem_dem_get_desc(c->desc.dem).contact_offset;
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    const fsdem_pic_particles W = fsdem_pic_get_particles(c->desc.pic);
    const fsdem_pic *s = c->desc.pic;
    int n = fsdem_dem_contacts(c->desc.dem, NULL, 0), k, p, e;
    if (n < 0) return fsdem__fail(&c->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_dem: out of memory listing contacts");
    if (n > c->contact_cap) {
        const size_t old = (size_t)c->contact_cap;
        fsdem__free(&c->allocator, c->contact, sizeof(fsdem_dem_contact) * old);
        fsdem__free(&c->allocator, c->contact_point, sizeof(fsdem_vec3) * old);
        c->contact_cap = 0;
        c->contact = (fsdem_dem_contact *)fsdem__alloc(&c->allocator, sizeof(fsdem_dem_contact) * (size_t)n);
        c->contact_point = (fsdem_vec3 *)fsdem__alloc(&c->allocator, sizeof(fsdem_vec3) * (size_t)n);
        if (!c->contact || !c->contact_point) {
            fsdem__free(&c->allocator, c->contact, sizeof(fsdem_dem_contact) * (size_t)n);
            fsdem__free(&c->allocator, c->contact_point, sizeof(fsdem_vec3) * (size_t)n);
            c->contact = NULL;
            c->contact_point = NULL;
            return fsdem__fail(&c->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_dem: out of memory listing contacts");
        }
        c->contact_cap = n;
    }
    c->contact_count = n = n > 0 ? fsdem_dem_contacts(c->desc.dem, c->contact, c->contact_cap) : 0;
    if (beta >= 1 || n == 0) return FSDEM_OK;
    /* the contact point: the middle of the gap between the real surfaces, offset - overlap wide */
    for (k = 0; k < n; ++k) {
        const fsdem_dem_contact *ct = &c->contact[k];
        c->contact_point[k] = fsdem__madd(P.position[ct->i], ct->normal, -(P.radius[ct->i] + (offset - ct->overlap) / 2));
    }
    if (fsdem__pic_dem_map_build(c, &c->contact_map, n, c->contact_point, NULL, half) != FSDEM_OK)
        return fsdem__fail(&c->status, FSDEM_ERR_OUT_OF_MEMORY, "fsdem_pic_dem: out of memory mapping the contacts");
    for (p = 0; p < W.count; ++p) {
        const int cell = fsdem__pic_cell_of(s, W.position[p]);
        for (e = c->contact_map.start[cell]; e < c->contact_map.start[cell + 1]; ++e) {
            const int q = c->contact_map.item[e];
            const fsdem_vec3 rel = fsdem__sub(W.position[p], c->contact_point[q]), nrm = c->contact[q].normal;
            const fsdem_real sn = fsdem__dot(rel, nrm), t = fsdem__norm(fsdem__madd(rel, nrm, -sn));
            if ((fsdem_real)fabs(sn) > half || t > half) continue;
            W.velocity[p] = fsdem__scale(W.velocity[p], beta + (1 - beta) * t / half); /* Eq. 20, C of Fig. 3 */
            c->dissipated++;
        }
    }
    return FSDEM_OK;
}

/* ---- >>couple_pic_step : coupled time stepping ---- */

/* The stable coupled step (>>couple_pic, fsdem_pic_dem_stable_dt). */
static fsdem_result fsdem__pic_dem_stable(const fsdem_pic_dem *c, fsdem_real *dt) {
    fsdem__status *st = (fsdem__status *)&c->status; /* the message is the object's only mutable part here */
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    const fsdem_pic_desc pd = fsdem_pic_get_desc(c->desc.pic);
    const fsdem_real dx = pd.cell_size;
    fsdem_real vmax = 0;
    int b;
    fsdem_result res = fsdem_pic_stable_dt(c->desc.pic, dt);
    if (res != FSDEM_OK) return fsdem__fail(st, res, "fsdem_pic_dem: %s", fsdem_pic_last_error(c->desc.pic));
    for (b = 0; b < P.count; ++b) {
        const fsdem_real v = fsdem__norm(P.velocity[b]) + fsdem__norm(P.angular_velocity[b]) * P.radius[b];
        if (!fsdem__finite(v)) return fsdem__fail(st, FSDEM_ERR_NAN, "fsdem_pic_dem: body %d has a non-finite velocity", b);
        if (v > vmax) vmax = v;
    }
    {
        const fsdem_real body = pd.cfl * dx / (vmax + (fsdem_real)sqrt(fsdem__norm(pd.gravity) * dx));
        if (body < *dt) *dt = body;
    }
    if (c->viscous_dt > 0 && c->desc.viscous_dt_fraction * c->viscous_dt < *dt) *dt = c->desc.viscous_dt_fraction * c->viscous_dt;
    return FSDEM_OK;
}

/* One coupled step of dt (steps 1-7 of >>couple_pic). */
static fsdem_result fsdem__pic_dem_run(fsdem_pic_dem *c, fsdem_real dt) {
    const fsdem_dem_particles P = fsdem_dem_get_particles(c->desc.dem);
    const fsdem_pic_desc pd = fsdem_pic_get_desc(c->desc.pic);
    long long substeps = 0;
    int b, before = c->bodies;
    clock_t t0 = clock(), t1, t2;
    fsdem_result res = fsdem__dem_substeps_within(c->desc.dem, dt, c->desc.max_substeps, &c->status, "fsdem_pic_dem");
    if (res != FSDEM_OK) return res;
    if ((res = fsdem__dem_particles_fit(c->desc.dem, pd.domain_min, pd.domain_max, &c->status, "fsdem_pic_dem")) != FSDEM_OK) return res;
    for (b = 0; b < P.count; ++b) {
        const fsdem_real v = fsdem__norm(P.velocity[b]) + fsdem__norm(P.angular_velocity[b]) * P.radius[b];
        if (v * dt > pd.cfl_max * pd.cell_size)
            return fsdem__fail(&c->status, FSDEM_ERR_CFL, "fsdem_pic_dem: body %d at %g m/s moves %g cells in dt = %g s (cfl_max %g)", b,
                               (double)v, (double)(v * dt / pd.cell_size), (double)dt, (double)pd.cfl_max);
    }
    /* the limit of the last cut, the one fsdem_pic_dem_stable_dt gave (the new cut may be a little
       stricter: the step it limits is the next) */
    if (c->viscous_dt > 0 && dt > c->desc.viscous_dt_fraction * c->viscous_dt * (1 + (fsdem_real)1e-6))
        return fsdem__fail(&c->status, FSDEM_ERR_CFL,
                           "fsdem_pic_dem: dt = %g s exceeds viscous_dt_fraction %g of the shortest viscous relaxation time %g s",
                           (double)dt, (double)c->desc.viscous_dt_fraction, (double)c->viscous_dt);
    if (P.count > before && (res = fsdem__pic_dem_exclude(c, before, 1)) != FSDEM_OK) return res;
    if ((res = fsdem__pic_dem_faces(c, dt)) != FSDEM_OK) return res;
    t1 = clock();
    c->sec_coupling += (double)(t1 - t0) / CLOCKS_PER_SEC;
    res = fsdem_pic_step_dt(c->desc.pic, dt);
    t2 = clock();
    c->sec_pic += (double)(t2 - t1) / CLOCKS_PER_SEC;
    if (res != FSDEM_OK) return fsdem__fail(&c->status, res, "fsdem_pic_dem: PIC step: %s", fsdem_pic_last_error(c->desc.pic));
    if ((res = fsdem__pic_dem_loads(c)) != FSDEM_OK) return res;
    t1 = clock();
    c->sec_coupling += (double)(t1 - t2) / CLOCKS_PER_SEC;
    res = fsdem_dem_advance(c->desc.dem, dt, &substeps);
    t2 = clock();
    c->sec_dem += (double)(t2 - t1) / CLOCKS_PER_SEC;
    c->steps++;
    c->dt_last = dt;
    c->substeps = substeps;
    c->substeps_total += substeps;
    if (res != FSDEM_OK) return fsdem__fail(&c->status, res, "fsdem_pic_dem: DEM substeps: %s", fsdem_dem_last_error(c->desc.dem));
    if ((res = fsdem__pic_dem_gap(c)) == FSDEM_OK) res = fsdem__pic_dem_exclude(c, 0, 0);
    c->sec_coupling += (double)(clock() - t2) / CLOCKS_PER_SEC;
    if (res != FSDEM_OK) return res;
    return fsdem__ok(&c->status);
}

fsdem_result fsdem_pic_dem_step(fsdem_pic_dem *c) {
    fsdem_real dt = 0;
    fsdem_result res;
    if (!c) return FSDEM_ERR_INVALID_ARG;
    if ((res = fsdem__pic_dem_stable(c, &dt)) != FSDEM_OK) return res;
    return fsdem__pic_dem_run(c, dt);
}

fsdem_result fsdem_pic_dem_step_dt(fsdem_pic_dem *c, fsdem_real dt) {
    if (!c) return FSDEM_ERR_INVALID_ARG;
    if (!(dt > 0) || !fsdem__finite(dt))
        return fsdem__fail(&c->status, FSDEM_ERR_INVALID_ARG, "fsdem_pic_dem_step_dt: dt = %g s must be > 0 and finite", (double)dt);
    return fsdem__pic_dem_run(c, dt);
}

/* fsdem__coupled_advance's verbs for this coupler. */
static double fsdem__pic_dem_now(const void *c) { return fsdem_pic_time(((const fsdem_pic_dem *)c)->desc.pic); }
static fsdem_result fsdem__pic_dem_prepare(void *c, fsdem_real *dt) { return fsdem__pic_dem_stable((fsdem_pic_dem *)c, dt); }
static fsdem_result fsdem__pic_dem_go(void *c, fsdem_real dt) { return fsdem__pic_dem_run((fsdem_pic_dem *)c, dt); }

fsdem_result fsdem_pic_dem_advance(fsdem_pic_dem *c, fsdem_real duration, long long *steps) {
    static const fsdem__coupled_verbs verbs = {fsdem__pic_dem_now, fsdem__pic_dem_prepare, fsdem__pic_dem_go};
    if (steps) *steps = 0;
    if (!c) return FSDEM_ERR_INVALID_ARG;
    return fsdem__coupled_advance(c, &c->status, "fsdem_pic_dem_advance", &verbs, duration, steps);
}

fsdem_result fsdem_pic_dem_stable_dt(const fsdem_pic_dem *c, fsdem_real *dt) {
    if (!c || !dt) return FSDEM_ERR_INVALID_ARG;
    return fsdem__pic_dem_stable(c, dt);
}

double fsdem_pic_dem_time(const fsdem_pic_dem *c) { return c ? fsdem_pic_time(c->desc.pic) : 0; }

fsdem_pic_dem_stats fsdem_pic_dem_get_stats(const fsdem_pic_dem *c) {
    fsdem_pic_dem_stats st;
    memset(&st, 0, sizeof st);
    if (!c) return st;
    st.steps = c->steps;
    st.time = fsdem_pic_time(c->desc.pic);
    st.dt = c->dt_last;
    st.substeps = c->substeps;
    st.substeps_total = c->substeps_total;
    st.fluid_force = c->force_sum;
    st.viscous_dt = c->viscous_dt;
    st.contacts = c->contact_count;
    st.dissipated = c->dissipated;
    st.pushed = c->pushed;
    st.removed = c->removed;
    st.seconds_pic = c->sec_pic;
    st.seconds_dem = c->sec_dem;
    st.seconds_coupling = c->sec_coupling;
    return st;
}

/* ===== >>impl_restart : checkpoint and restart =======================================================

   Contents: >>restart_format (header, checksum, and the one cursor that writes, checks and reads
   every object), >>restart_dem, >>restart_pic, >>restart_swe, >>restart_swe_dem, >>restart_mps,
   >>restart_mps_dem, >>restart_pic_dem (one visitor per object lists what it saves, in order, and serves saving and
   restoring alike), >>restart_api
   (memory and files). A restore runs the visitor three times over the payload: CHECK validates
   everything and compares the desc, RESERVE allocates, COMMIT writes into the object. Only COMMIT
   changes the object, and it cannot fail. */

/* ---- >>restart_format : header, checksum, cursor ---- */

#define FSDEM__RESTART_VERSION 2u /* 2: DEM contact options and material-pair tables (issue 23) */
#define FSDEM__RESTART_HEADER 64
#define FSDEM__RESTART_BOM 0x01020304u
#define FSDEM__RESTART_FNV_BASIS 0xcbf29ce484222325ull
#define FSDEM__RESTART_FNV_PRIME 0x100000001b3ull
#define FSDEM__RESTART_INT_MAX 2147483647

/* The header stores its fields as unsigned int (4 bytes) and unsigned long long (8 bytes). */
typedef char fsdem__restart_int_sizes[sizeof(unsigned int) == 4 && sizeof(unsigned long long) == 8 ? 1 : -1];

enum { FSDEM__RESTART_DEM = 1, FSDEM__RESTART_PIC = 2, FSDEM__RESTART_SWE = 3, FSDEM__RESTART_SWE_DEM = 4, FSDEM__RESTART_MPS = 5,
       FSDEM__RESTART_MPS_DEM = 6, FSDEM__RESTART_PIC_DEM = 7 };

typedef enum fsdem__restart_mode {
    FSDEM__RESTART_WRITE = 0,   /* object to payload (to memory, to a file, or only measured) */
    FSDEM__RESTART_CHECK = 1,   /* payload validated and compared with the object; nothing stored */
    FSDEM__RESTART_RESERVE = 2, /* the memory the payload needs is allocated; nothing stored */
    FSDEM__RESTART_COMMIT = 3   /* payload to object; cannot fail */
} fsdem__restart_mode;

/* A block RESERVE allocated for COMMIT to hand over to the object. */
typedef struct fsdem__restart_held {
    void *ptr;
    size_t bytes;
    const fsdem_allocator *allocator;
} fsdem__restart_held;

/* The cursor of a save or a restore. */
typedef struct fsdem__restart {
    fsdem__restart_mode mode;
    unsigned char *out;          /* WRITE to memory: where the payload goes (NULL: a file, or measuring) */
    FILE *file;                  /* WRITE to a file */
    const unsigned char *in;     /* reading: the payload */
    size_t pos, size;            /* cursor; bytes of the payload (WRITE to memory: room for it) */
    unsigned long long hash;     /* FNV-1a of the header and of the bytes written so far */
    fsdem_result res;            /* the first failure, FSDEM_OK so far */
    char fn[48];                 /* public function, first in every message */
    const char *section;         /* the solver being read in a coupler's file, or NULL */
    char message[FSDEM__MESSAGE_SIZE];
    const fsdem_allocator *allocator; /* of `blocks` */
    fsdem__restart_held *blocks;
    int block_count, block_capacity, block_next;
} fsdem__restart;

typedef void (*fsdem__restart_visit_fn)(fsdem__restart *io, void *object);

/* 64-bit FNV-1a of `n` bytes, continuing from `h`: each step (xor a byte, multiply by an odd prime)
   is a bijection of the state, so any one changed byte changes the sum; and it costs little next to
   writing the data. */
static unsigned long long fsdem__restart_fnv(unsigned long long h, const unsigned char *p, size_t n) {
    size_t k;
    for (k = 0; k < n; ++k) h = (h ^ p[k]) * FSDEM__RESTART_FNV_PRIME;
    return h;
}

/* Records the first failure and its message (the public function first, then the solver section of
   a coupler's file); later failures keep the first, so a message names the root cause. */
static void fsdem__restart_fail(fsdem__restart *io, fsdem_result code, const char *fmt, ...) {
    char detail[384];
    va_list ap;
    if (io->res != FSDEM_OK) return;
    va_start(ap, fmt);
    vsnprintf(detail, sizeof detail, fmt, ap);
    va_end(ap);
    snprintf(io->message, sizeof io->message, "%s: %s%s%s", io->fn, io->section ? io->section : "",
             io->section ? ": " : "", detail);
    io->res = code;
}

/* The next `bytes` of the payload when restoring (a failure and NULL when they run past its end);
   NULL when saving. Lets a check read arrays in place. */
static const unsigned char *fsdem__restart_peek(fsdem__restart *io, size_t bytes) {
    if (io->mode == FSDEM__RESTART_WRITE || io->res != FSDEM_OK) return NULL;
    if (bytes > io->size - io->pos) {
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "the data end early at byte %llu of %llu (corrupted data)",
                            (unsigned long long)io->pos, (unsigned long long)io->size);
        return NULL;
    }
    return io->in + io->pos;
}

/* Object data: WRITE appends `bytes` from p (to memory or to the file, or only counts them), COMMIT
   copies them into p, CHECK and RESERVE step over them. The one place bytes move. */
static void fsdem__restart_data(fsdem__restart *io, void *p, size_t bytes) {
    if (io->res != FSDEM_OK || bytes == 0) return;
    if (io->mode == FSDEM__RESTART_WRITE) {
        if (io->out) {
            FSDEM_ASSERT(bytes <= io->size - io->pos);
            memcpy(io->out + io->pos, p, bytes);
        } else if (io->file)
            fwrite(p, 1, bytes, io->file); /* errors: ferror at the end (fsdem__restart_save_file) */
        if (io->out || io->file) io->hash = fsdem__restart_fnv(io->hash, (const unsigned char *)p, bytes);
        io->pos += bytes;
        return;
    }
    if (!fsdem__restart_peek(io, bytes)) return;
    if (io->mode == FSDEM__RESTART_COMMIT) memcpy(p, io->in + io->pos, bytes);
    io->pos += bytes;
}

/* A value the visitor itself looks at (a count, a type, a flag): written like data, and read into p
   in every reading mode, so CHECK can validate it before anything depends on it. */
static void fsdem__restart_value(fsdem__restart *io, void *p, size_t bytes) {
    if (io->mode == FSDEM__RESTART_WRITE) {
        fsdem__restart_data(io, p, bytes);
        return;
    }
    if (!fsdem__restart_peek(io, bytes)) return;
    memcpy(p, io->in + io->pos, bytes);
    io->pos += bytes;
}

/* The int at index k of payload bytes (which need not be aligned). */
static int fsdem__restart_int_at(const unsigned char *p, long k) {
    int v;
    memcpy(&v, p + (size_t)k * sizeof v, sizeof v);
    return v;
}

/* An int that must lie in [lo, hi]: written, or read into *v and checked. */
static void fsdem__restart_int_in(fsdem__restart *io, int *v, int lo, int hi, const char *what) {
    fsdem__restart_value(io, v, sizeof *v);
    if (io->mode != FSDEM__RESTART_WRITE && io->res == FSDEM_OK && (*v < lo || *v > hi))
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "%s is %d, outside [%d, %d] (corrupted data)", what, *v, lo, hi);
}

/* A count: written, or read and checked to lie in [0, max] with at least `item_bytes` of payload left
   per item, so that a corrupted count can neither run long loops nor ask for a huge allocation.
   Returns 1 when it may be used. */
static int fsdem__restart_count(fsdem__restart *io, int *n, int max, size_t item_bytes, const char *what) {
    fsdem__restart_int_in(io, n, 0, max, what);
    if (io->mode != FSDEM__RESTART_WRITE && io->res == FSDEM_OK && (size_t)*n * item_bytes > io->size - io->pos)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "%s is %d, more than the data can hold (corrupted data)", what, *n);
    return io->res == FSDEM_OK;
}

/* `count` ints of object data, each in [lo, hi] (checked in CHECK): indices that steps follow. */
static void fsdem__restart_ints(fsdem__restart *io, int *a, int count, int lo, int hi, const char *what) {
    const unsigned char *p = io->mode == FSDEM__RESTART_CHECK ? fsdem__restart_peek(io, sizeof(int) * (size_t)count) : NULL;
    int k, v;
    for (k = 0; p && k < count; ++k)
        if ((v = fsdem__restart_int_at(p, k)) < lo || v > hi) {
            fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "%s %d is %d, outside [%d, %d] (corrupted data)", what, k, v, lo, hi);
            return;
        }
    fsdem__restart_data(io, a, sizeof(int) * (size_t)count);
}

/* `count` bytes of object data, each at most hi (checked in CHECK): flags and cell types. */
static void fsdem__restart_flags(fsdem__restart *io, unsigned char *a, int count, int hi, const char *what) {
    const unsigned char *p = io->mode == FSDEM__RESTART_CHECK ? fsdem__restart_peek(io, (size_t)count) : NULL;
    int k;
    for (k = 0; p && k < count; ++k)
        if (p[k] > hi) {
            fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "%s %d is %d, more than %d (corrupted data)", what, k, p[k], hi);
            return;
        }
    fsdem__restart_data(io, a, (size_t)count);
}

/* A desc field the object must share with the save: written, or read and compared (bit for bit for
   reals). A difference is refused naming the field and both values: the object was not created
   from the desc of the save. */
static void fsdem__restart_same_int(fsdem__restart *io, int mine, const char *what) {
    int saved = mine;
    fsdem__restart_value(io, &saved, sizeof saved);
    if (io->mode == FSDEM__RESTART_CHECK && io->res == FSDEM_OK && saved != mine)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "desc.%s is %d in the save and %d in the object (create the object from the desc it was saved with)",
                            what, saved, mine);
}

static void fsdem__restart_same_ll(fsdem__restart *io, long long mine, const char *what) {
    long long saved = mine;
    fsdem__restart_value(io, &saved, sizeof saved);
    if (io->mode == FSDEM__RESTART_CHECK && io->res == FSDEM_OK && saved != mine)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "desc.%s is %lld in the save and %lld in the object (create the object from the desc it was saved with)",
                            what, saved, mine);
}

static void fsdem__restart_same_vec3(fsdem__restart *io, fsdem_vec3 mine, const char *what) {
    fsdem_vec3 saved = mine;
    fsdem__restart_value(io, &saved, sizeof saved);
    if (io->mode == FSDEM__RESTART_CHECK && io->res == FSDEM_OK && memcmp(&saved, &mine, sizeof saved) != 0)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "desc.%s is (%.17g, %.17g, %.17g) in the save and (%.17g, %.17g, %.17g) in the object "
                            "(create the object from the desc it was saved with)",
                            what, (double)saved.x, (double)saved.y, (double)saved.z, (double)mine.x, (double)mine.y,
                            (double)mine.z);
}

static void fsdem__restart_same_real(fsdem__restart *io, fsdem_real mine, const char *what) {
    fsdem_real saved = mine;
    fsdem__restart_value(io, &saved, sizeof saved);
    if (io->mode == FSDEM__RESTART_CHECK && io->res == FSDEM_OK && memcmp(&saved, &mine, sizeof saved) != 0)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "desc.%s is %.17g in the save and %.17g in the object (create the object from the desc it was saved with)",
                            what, (double)saved, (double)mine);
}

/* A section tag of four characters: written, or read and checked, so that data out of place are
   caught at the section where they start. */
static void fsdem__restart_tag(fsdem__restart *io, const char *tag) {
    char got[4];
    memcpy(got, tag, 4);
    fsdem__restart_value(io, got, 4);
    if (io->mode != FSDEM__RESTART_WRITE && io->res == FSDEM_OK && memcmp(got, tag, 4) != 0)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "section '%.4s' expected at byte %llu (corrupted data)", tag,
                            (unsigned long long)(io->pos - 4));
}

/* RESERVE: a failed allocation becomes the restore's result. */
static void fsdem__restart_need(fsdem__restart *io, fsdem_result res, const char *what) {
    if (res != FSDEM_OK) fsdem__restart_fail(io, FSDEM_ERR_OUT_OF_MEMORY, "out of memory for %s", what);
}

/* A fresh block of `bytes` for the object: RESERVE allocates it with the object's allocator and keeps
   it, COMMIT hands the blocks over in the order RESERVE made them (the visitor asks for them in the
   same order both times). NULL in the other modes and for 0 bytes. Blocks not handed over are freed
   when the restore fails. */
static void *fsdem__restart_block(fsdem__restart *io, const fsdem_allocator *al, size_t bytes) {
    fsdem__restart_held *b;
    if (io->res != FSDEM_OK || bytes == 0) return NULL;
    if (io->mode == FSDEM__RESTART_COMMIT) {
        FSDEM_ASSERT(io->block_next < io->block_count && io->blocks[io->block_next].bytes == bytes);
        return io->blocks[io->block_next++].ptr;
    }
    if (io->mode != FSDEM__RESTART_RESERVE) return NULL;
    if (fsdem__grow(io->allocator, (void **)&io->blocks, &io->block_capacity, io->block_count, io->block_count + 1,
                    sizeof *io->blocks) != FSDEM_OK) {
        fsdem__restart_need(io, FSDEM_ERR_OUT_OF_MEMORY, "the restore's bookkeeping");
        return NULL;
    }
    b = &io->blocks[io->block_count];
    b->ptr = fsdem__alloc(al, bytes);
    b->bytes = bytes;
    b->allocator = al;
    if (!b->ptr) fsdem__restart_need(io, FSDEM_ERR_OUT_OF_MEMORY, "the restored state");
    else io->block_count++;
    return NULL;
}

/* ---- >>restart_dem : discrete elements ---- */

/* One neighbour list: its rows and entries, the row offsets, the row of each entry, the partner keys
   with their HELD bits and the tangential springs (zero where not HELD: they mean nothing there and
   may be uninitialised), exactly as they are: the entries, their order and their springs decide the
   next steps, and a rebuild forced at the restore would rebuild at other positions than the
   uninterrupted run does. While the lists are current (not `stale`) they have one row per particle.
   *entries gets the saved number of entries; returns the longest saved row. */
static int fsdem__restart_dem_list(fsdem__restart *io, fsdem_dem *d, fsdem__dem_list *l, int pairs, int n, int stale,
                                   int walls, int *entries) {
    const char *name = pairs ? "particle-pair list" : "particle-wall list";
    const unsigned char *start = NULL;
    int rows = l->rows, count = l->count, longest = 0, i, k;
    fsdem__restart_count(io, &rows, FSDEM__DEM_MAX_PARTICLES, sizeof(int), pairs ? "pair-list rows" : "wall-list rows");
    fsdem__restart_count(io, &count, 1 << 30, 2 * sizeof(int) + sizeof(fsdem_vec3),
                         pairs ? "pair-list entries" : "wall-list entries");
    *entries = count;
    if (io->res != FSDEM_OK) return 0;
    if (io->mode == FSDEM__RESTART_CHECK && ((!stale && rows != n) || (rows == 0 && count != 0)))
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "the %s has %d rows and %d entries for %d particles (corrupted data)",
                            name, rows, count, n);
    if (io->mode == FSDEM__RESTART_RESERVE) {
        if (rows > 0)
            fsdem__restart_need(io, fsdem__grow(&d->allocator, (void **)&l->start, &l->start_capacity,
                                                l->rows > 0 ? l->rows + 1 : 0, rows + 1, sizeof(int)), name);
        while (io->res == FSDEM_OK && l->capacity < count) fsdem__restart_need(io, fsdem__dem_list_grow(d, l), name);
    }
    if (rows > 0) {
        start = fsdem__restart_peek(io, sizeof(int) * (size_t)(rows + 1));
        for (i = 0; start && i < rows; ++i) {
            const int a = fsdem__restart_int_at(start, i), b = fsdem__restart_int_at(start, i + 1);
            if (io->mode == FSDEM__RESTART_CHECK && (a > b || (i == 0 && a != 0) || (i == rows - 1 && b != count))) {
                fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "the %s has bad row offsets at row %d (corrupted data)", name, i);
                start = NULL;
            } else if (b - a > longest)
                longest = b - a;
        }
        fsdem__restart_data(io, l->start, sizeof(int) * (size_t)(rows + 1));
    }
    if (io->mode == FSDEM__RESTART_CHECK && start) {
        /* each entry in its row; pairs name a later particle, wall entries a wall and a face */
        const unsigned char *first = fsdem__restart_peek(io, 2 * sizeof(int) * (size_t)count);
        for (i = 0; first && i < rows; ++i)
            for (k = fsdem__restart_int_at(start, i); k < fsdem__restart_int_at(start, i + 1); ++k) {
                const int key = fsdem__restart_int_at(first, (long)count + k), partner = FSDEM__DEM_PARTNER(key);
                const int bad = pairs ? partner <= i || partner >= rows
                                      : partner / 8 >= walls || partner % 8 >= 2 * d->desc.dim;
                if (fsdem__restart_int_at(first, k) != i || key < 0 || bad) {
                    fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "the %s has a bad entry %d (corrupted data)", name, k);
                    first = NULL;
                    break;
                }
            }
    }
    fsdem__restart_data(io, l->first, sizeof(int) * (size_t)count);
    fsdem__restart_data(io, l->key, sizeof(int) * (size_t)count);
    if (io->mode == FSDEM__RESTART_WRITE) /* a spring without its HELD bit means nothing: saved as 0 */
        for (k = 0; k < count; ++k) {
            fsdem_vec3 spring = fsdem__dem_spring(l, k);
            fsdem__restart_data(io, &spring, sizeof spring);
        }
    else
        fsdem__restart_data(io, l->history, sizeof(fsdem_vec3) * (size_t)count);
    if (io->mode == FSDEM__RESTART_COMMIT) {
        l->rows = rows;
        l->count = count;
    }
    return longest;
}

/* Everything of a DEM, in order. State: time, dt, counters, the neighbour-list bookkeeping (x_ref,
   max_disp2, need_rebuild, skin, r_max, walls' `moved`), forces_valid and forces_cleared with the
   forces and torques of the last evaluation (the next Verlet kick uses them), external loads,
   materials with their pair table (the Hertz damping calibration is costly and its result must be
   the same bits), walls, particles, both neighbour lists and the inert pairs. Configuration: the
   desc fields that steps read, compared. Not saved, rebuilt or rewritten before use: the cell grid,
   the pair scratch (found), the wall-hit scratch and the arena (reserved here for the next force
   evaluation), the previous lists pp_old and pw_old (storage the next rebuild fills), the
   predictor-corrector's x0, v0, w0, fa, ta and the walls' force_a (written at the start of each
   such step), capacities, the allocator, log and message. SDF walls keep the object's callbacks. */
static void fsdem__restart_dem(fsdem__restart *io, void *object) {
    fsdem_dem *d = (fsdem_dem *)object;
    const fsdem_dem_desc *dd = &d->desc;
    const int reserve = io->mode == FSDEM__RESTART_RESERVE, commit = io->mode == FSDEM__RESTART_COMMIT;
    int nm = d->material_count, nw = d->wall_count, n = d->n, stale = d->need_rebuild, inert = d->inert_count;
    int k, longest, pairs = 0, wall_entries = 0;
    fsdem__restart_tag(io, "DEM1");
    fsdem__restart_same_int(io, dd->dim, "dim");
    fsdem__restart_same_vec3(io, dd->domain_min, "domain_min");
    fsdem__restart_same_vec3(io, dd->domain_max, "domain_max");
    fsdem__restart_same_vec3(io, dd->gravity, "gravity");
    fsdem__restart_same_int(io, (int)dd->law, "law");
    fsdem__restart_same_int(io, (int)dd->integrator, "integrator");
    fsdem__restart_same_int(io, (int)dd->dt_rule, "dt_rule");
    fsdem__restart_same_real(io, dd->dt_param, "dt_param");
    fsdem__restart_same_real(io, dd->skin, "skin");
    fsdem__restart_same_real(io, dd->contact_offset, "contact_offset");
    fsdem__restart_same_real(io, dd->linear_theta, "linear_theta");
    fsdem__restart_same_real(io, dd->linear_dx, "linear_dx");
    fsdem__restart_same_real(io, dd->linear_accel, "linear_accel");
    fsdem__restart_same_real(io, dd->disc_length, "disc_length");
    fsdem__restart_same_int(io, dd->rotation, "rotation");
    fsdem__restart_same_int(io, dd->tangential_damping, "tangential_damping");
    fsdem__restart_same_int(io, (int)dd->tangential_history, "tangential_history");
    fsdem__restart_same_int(io, (int)dd->coulomb_limit, "coulomb_limit");
    fsdem__restart_same_int(io, (int)dd->linear_stiffness, "linear_stiffness");
    fsdem__restart_same_int(io, dd->periodic[0], "periodic[0]");
    fsdem__restart_same_int(io, dd->periodic[1], "periodic[1]");
    fsdem__restart_same_int(io, dd->periodic[2], "periodic[2]");

    fsdem__restart_data(io, &d->dt, sizeof d->dt);
    fsdem__restart_data(io, &d->time, sizeof d->time);
    fsdem__restart_data(io, &d->steps, sizeof d->steps);
    fsdem__restart_data(io, &d->rebuilds, sizeof d->rebuilds);
    fsdem__restart_data(io, &d->stable_dt, sizeof d->stable_dt);
    fsdem__restart_data(io, &d->dt_warned, sizeof d->dt_warned);
    fsdem__restart_data(io, &d->next_id, sizeof d->next_id);
    fsdem__restart_data(io, &d->skin, sizeof d->skin);
    fsdem__restart_data(io, &d->r_max, sizeof d->r_max);
    fsdem__restart_data(io, &d->max_disp2, sizeof d->max_disp2);
    fsdem__restart_int_in(io, &stale, 0, 1, "need_rebuild");
    fsdem__restart_data(io, &d->forces_valid, sizeof d->forces_valid);
    fsdem__restart_data(io, &d->rolling, sizeof d->rolling);
    fsdem__restart_data(io, &d->external, sizeof d->external);
    fsdem__restart_data(io, &d->forces_cleared, sizeof d->forces_cleared);
    fsdem__restart_data(io, &d->contacts, sizeof d->contacts);
    fsdem__restart_data(io, &d->wall_contacts, sizeof d->wall_contacts);
    fsdem__restart_data(io, &d->max_overlap, sizeof d->max_overlap);
    if (commit) d->need_rebuild = stale;

    /* materials and their pair table */
    fsdem__restart_count(io, &nm, 46340, sizeof(fsdem_dem_material), "material count");
    if (reserve && nm > 0) {
        fsdem__restart_need(io, fsdem__grow(&d->allocator, (void **)&d->materials, &d->material_capacity, d->material_count,
                                            nm, sizeof(fsdem_dem_material)), "the materials");
        fsdem__restart_need(io, fsdem__grow(&d->allocator, (void **)&d->pairs, &d->pair_capacity,
                                            d->material_count * d->material_count, nm * nm, sizeof(fsdem__dem_pair)),
                            "the materials");
    }
    fsdem__restart_data(io, d->materials, sizeof(fsdem_dem_material) * (size_t)nm);
    fsdem__restart_data(io, d->pairs, sizeof(fsdem__dem_pair) * (size_t)nm * (size_t)nm);
    if (commit) {
        d->material_count = nm;
        fsdem__dem_pair_flags(d);
    }

    /* walls: geometry where it has moved to, velocity, forces and impulses */
    fsdem__restart_count(io, &nw, FSDEM__DEM_HELD / 8, 4 * sizeof(int) + 6 * sizeof(fsdem_vec3), "wall count");
    if (reserve && nw > 0)
        fsdem__restart_need(io, fsdem__grow(&d->allocator, (void **)&d->walls, &d->wall_capacity, d->wall_count, nw,
                                            sizeof(fsdem__dem_wall)), "the walls");
    for (k = 0; k < nw && io->res == FSDEM_OK; ++k) {
        fsdem__dem_wall w;
        int type, material;
        if (io->mode == FSDEM__RESTART_WRITE) w = d->walls[k];
        else memset(&w, 0, sizeof w);
        type = (int)w.d.type;
        material = w.d.material;
        fsdem__restart_int_in(io, &type, 0, FSDEM_DEM_WALL_TYPE_SDF, "wall type");
        fsdem__restart_value(io, &w.d.a, sizeof w.d.a);
        fsdem__restart_value(io, &w.d.b, sizeof w.d.b);
        fsdem__restart_value(io, &w.d.c, sizeof w.d.c);
        fsdem__restart_value(io, &w.d.velocity, sizeof w.d.velocity);
        fsdem__restart_int_in(io, &material, 0, nm - 1, "wall material");
        fsdem__restart_int_in(io, &w.active, 0, 1, "wall active flag");
        fsdem__restart_value(io, &w.force, sizeof w.force);
        fsdem__restart_value(io, &w.impulse, sizeof w.impulse);
        fsdem__restart_value(io, &w.moved, sizeof w.moved);
        if (io->mode != FSDEM__RESTART_WRITE && io->res == FSDEM_OK && type == FSDEM_DEM_WALL_TYPE_SDF) {
            if (k >= d->wall_count || d->walls[k].d.type != FSDEM_DEM_WALL_TYPE_SDF)
                fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                                    "wall %d is an SDF wall in the save: add the same SDF walls (fsdem_dem_wall_sdf), in the "
                                    "same order, to the object before restoring",
                                    k);
            else {
                w.d.sdf = d->walls[k].d.sdf; /* wall k of the object is overwritten only below */
                w.d.sdf_user = d->walls[k].d.sdf_user;
            }
        }
        if (commit) {
            w.d.type = (fsdem_dem_wall_type)type;
            w.d.material = material;
            d->walls[k] = w;
        }
    }
    if (commit) d->wall_count = nw;

    /* particles */
    fsdem__restart_count(io, &n, FSDEM__DEM_MAX_PARTICLES, 8 * sizeof(fsdem_vec3) + 4 * sizeof(fsdem_real),
                          "particle count");
    if (reserve) fsdem__restart_need(io, fsdem__dem_reserve_particles(d, n > 0 ? n : 1), "the particles");
    fsdem__restart_data(io, d->id, sizeof(int) * (size_t)n);
    fsdem__restart_ints(io, d->material, n, 0, nm - 1, "material of particle");
    fsdem__restart_ints(io, d->old_of, n, -1, FSDEM__RESTART_INT_MAX, "previous row of particle");
    fsdem__restart_flags(io, d->fixed, n, 1, "fixed flag of particle");
    fsdem__restart_data(io, d->x, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->v, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->w, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->f, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->t, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->fext, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->text, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->x_ref, sizeof(fsdem_vec3) * (size_t)n);
    fsdem__restart_data(io, d->r, sizeof(fsdem_real) * (size_t)n);
    fsdem__restart_data(io, d->m, sizeof(fsdem_real) * (size_t)n);
    fsdem__restart_data(io, d->inv_m, sizeof(fsdem_real) * (size_t)n);
    fsdem__restart_data(io, d->inv_i, sizeof(fsdem_real) * (size_t)n);
    if (commit) d->n = n;

    /* neighbour lists with contact history, and the pairs of fixed particles listed aside */
    fsdem__restart_dem_list(io, d, &d->pp, 1, n, stale, nw, &pairs);
    longest = fsdem__restart_dem_list(io, d, &d->pw, 0, n, stale, nw, &wall_entries);
    fsdem__restart_count(io, &inert, 1 << 29, 2 * sizeof(int), "inert pair count");
    if (reserve && inert > 0)
        fsdem__restart_need(io, fsdem__grow(&d->allocator, (void **)&d->inert, &d->inert_capacity, 2 * d->inert_count,
                                            2 * inert, sizeof(int)), "the inert pairs");
    fsdem__restart_ints(io, d->inert, 2 * inert, 0, stale ? FSDEM__RESTART_INT_MAX : n - 1, "inert pair entry");
    if (commit) d->inert_count = inert;
    /* scratch of a force evaluation before the next rebuild, as fsdem__dem_rebuild reserves it */
    if (reserve && io->res == FSDEM_OK) {
        if (longest > 0)
            fsdem__restart_need(io, fsdem__grow(&d->allocator, (void **)&d->hits, &d->hit_capacity, 0, longest,
                                                sizeof(fsdem__dem_wall_hit)), "the wall contacts");
        fsdem__restart_need(io, fsdem__arena_reserve(&d->allocator, &d->arena,
                                                     fsdem__arena_bytes(sizeof(int) * (size_t)pairs) +
                                                         fsdem__arena_bytes(sizeof(fsdem__dem_batch))),
                            "the force evaluation");
    }
    fsdem__restart_tag(io, "DEM.");
}

/* ---- >>restart_pic : PIC/FLIP ---- */

/* Everything of a PIC solver, in order. State: time, last dt, steps (they pick the sorting steps),
   the random-number state, particles with their capacity (a full capacity refuses inflow seeds) and
   APIC matrices, obstacles (polygons with their vertices) with the static face fractions, solid
   velocities and cell flags derived from them (recomputing them samples SDF callbacks), the
   coupler's arrays, cells_fresh with the fractions and level set it vouches for, the pressure (the
   initial guess of the next solve), the face velocities, effective faces and cell types (views,
   sampling and fsdem_pic_add_force read them between steps), counters and the last step's figures.
   Configuration: the grid and the desc fields that steps read, compared. Not saved, rewritten
   before use: uold, wsum, ftmp, the valid-face marks, the extrapolation queue, rhs, diag, ctmp,
   cstart and the particle scratch (ptmp, pcell, pidx; pflag is zeroed), the viscous face grids, the
   linear solvers (set up at every use), CPU times, the allocator, log and message. SDF obstacles
   keep the object's callbacks; a pressure-extra operator stays as set. */
/* The gauges of a PIC solver (positions, kinds, radii); their file is not part of the state. */
/* Point gauges (fsdem__gauges) into fresh arrays; refused while their file is open (`close` names
   the function that closes it). */
static void fsdem__restart_gauges(fsdem__restart *io, fsdem__gauges *g, const fsdem_allocator *al, const char *close) {
    int ng = g->count;
    fsdem_vec3 *at;
    int *kind;
    fsdem_real *radius;
    if (io->mode == FSDEM__RESTART_CHECK && g->series.file)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "the object has a gauge file open: close it (%s) before restoring and open it again afterwards", close);
    fsdem__restart_count(io, &ng, 1 << 24, sizeof(fsdem_vec3) + sizeof(int) + sizeof(fsdem_real), "gauge count");
    at = (fsdem_vec3 *)fsdem__restart_block(io, al, sizeof(fsdem_vec3) * (size_t)ng);
    kind = (int *)fsdem__restart_block(io, al, sizeof(int) * (size_t)ng);
    radius = (fsdem_real *)fsdem__restart_block(io, al, sizeof(fsdem_real) * (size_t)ng);
    if (io->mode == FSDEM__RESTART_COMMIT) {
        fsdem__gauges_free(g, al);
        g->at = at;
        g->kind = kind;
        g->radius = radius;
        g->count = g->capacity = ng;
    }
    fsdem__restart_data(io, g->at, sizeof(fsdem_vec3) * (size_t)ng);
    fsdem__restart_ints(io, g->kind, ng, FSDEM__GAUGE_LEVEL, FSDEM__GAUGE_PRESSURE, "gauge kind");
    fsdem__restart_data(io, g->radius, sizeof(fsdem_real) * (size_t)ng);
}

static void fsdem__restart_pic(fsdem__restart *io, void *object) {
    fsdem_pic *s = (fsdem_pic *)object;
    const fsdem_pic_desc *pd = &s->desc;
    const fsdem_allocator *al = &s->allocator;
    const int commit = io->mode == FSDEM__RESTART_COMMIT, apic = pd->transfer == FSDEM_PIC_TRANSFER_APIC;
    static const char *bc_names[6] = {"boundary[0]", "boundary[1]", "boundary[2]",
                                      "boundary[3]", "boundary[4]", "boundary[5]"};
    static const char *bv_names[6] = {"boundary_velocity[0]", "boundary_velocity[1]", "boundary_velocity[2]",
                                      "boundary_velocity[3]", "boundary_velocity[4]", "boundary_velocity[5]"};
    int grid[3], no = s->obst_count, np = s->np, pcap = s->pcap, a, k;
    fsdem__pic_obst *obst;
    size_t cells = sizeof(fsdem_real) * (size_t)s->ncell;
    fsdem__restart_tag(io, "PIC2");
    for (a = 0; a < 3; ++a) grid[a] = s->n[a];
    fsdem__restart_value(io, grid, sizeof grid);
    if (io->mode == FSDEM__RESTART_CHECK && io->res == FSDEM_OK &&
        (grid[0] != s->n[0] || grid[1] != s->n[1] || grid[2] != s->n[2]))
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "the grid has %d x %d x %d cells in the save and %d x %d x %d in the object (create the "
                            "object from the desc it was saved with)",
                            grid[0], grid[1], grid[2], s->n[0], s->n[1], s->n[2]);
    fsdem__restart_same_int(io, pd->dim, "dim");
    fsdem__restart_same_vec3(io, pd->domain_min, "domain_min");
    fsdem__restart_same_real(io, pd->cell_size, "cell_size");
    fsdem__restart_same_real(io, pd->density, "density");
    fsdem__restart_same_real(io, pd->viscosity, "viscosity");
    fsdem__restart_same_vec3(io, pd->gravity, "gravity");
    for (k = 0; k < 6; ++k) {
        fsdem__restart_same_int(io, (int)pd->boundary[k], bc_names[k]);
        fsdem__restart_same_vec3(io, pd->boundary_velocity[k], bv_names[k]);
    }
    fsdem__restart_same_int(io, pd->free_surface, "free_surface");
    fsdem__restart_same_int(io, (int)pd->transfer, "transfer");
    fsdem__restart_same_real(io, pd->flip_ratio, "flip_ratio");
    fsdem__restart_same_int(io, (int)pd->kernel, "kernel");
    fsdem__restart_same_int(io, pd->particles_per_cell, "particles_per_cell");
    fsdem__restart_same_real(io, pd->jitter, "jitter");
    fsdem__restart_same_int(io, pd->min_particles_per_cell, "min_particles_per_cell");
    fsdem__restart_same_int(io, pd->max_particles_per_cell, "max_particles_per_cell");
    fsdem__restart_same_int(io, pd->advection_order, "advection_order");
    fsdem__restart_same_real(io, pd->cfl, "cfl");
    fsdem__restart_same_real(io, pd->cfl_max, "cfl_max");
    fsdem__restart_same_real(io, pd->dt_max, "dt_max");
    fsdem__restart_same_int(io, pd->density_projection, "density_projection");
    fsdem__restart_same_real(io, pd->ghost_theta_min, "ghost_theta_min");
    fsdem__restart_same_int(io, pd->extrapolation_layers, "extrapolation_layers");
    fsdem__restart_same_int(io, (int)pd->pressure_precond, "pressure_precond");
    fsdem__restart_same_real(io, pd->pressure_tolerance, "pressure_tolerance");
    fsdem__restart_same_int(io, pd->pressure_max_iterations, "pressure_max_iterations");
    fsdem__restart_same_int(io, (int)pd->viscosity_precond, "viscosity_precond");
    fsdem__restart_same_real(io, pd->viscosity_tolerance, "viscosity_tolerance");

    fsdem__restart_data(io, &s->time, sizeof s->time);
    fsdem__restart_data(io, &s->dt_last, sizeof s->dt_last);
    fsdem__restart_data(io, &s->steps, sizeof s->steps);
    fsdem__restart_data(io, &s->rng, sizeof s->rng);
    fsdem__restart_data(io, &s->cells_fresh, sizeof s->cells_fresh);
    fsdem__restart_data(io, &s->fluid_cells, sizeof s->fluid_cells);
    fsdem__restart_data(io, &s->p_iters, sizeof s->p_iters);
    fsdem__restart_data(io, &s->v_iters, sizeof s->v_iters);
    fsdem__restart_data(io, &s->d_iters, sizeof s->d_iters);
    fsdem__restart_data(io, &s->p_res, sizeof s->p_res);
    fsdem__restart_data(io, &s->max_div, sizeof s->max_div);
    fsdem__restart_data(io, &s->div_before, sizeof s->div_before);
    fsdem__restart_data(io, &s->reseeded, sizeof s->reseeded);
    fsdem__restart_data(io, &s->removed, sizeof s->removed);
    fsdem__restart_data(io, &s->refused, sizeof s->refused);
    fsdem__restart_data(io, &s->moved, sizeof s->moved);

    /* obstacles, into a fresh array (polygons own their vertices) */
    fsdem__restart_count(io, &no, 1 << 20, 2 * sizeof(int) + 5 * sizeof(fsdem_vec3) + sizeof(fsdem_real), "obstacle count");
    obst = (fsdem__pic_obst *)fsdem__restart_block(io, al, sizeof(fsdem__pic_obst) * (size_t)no);
    for (k = 0; k < no && io->res == FSDEM_OK; ++k) {
        fsdem__pic_obst o;
        fsdem_vec3 *verts;
        int type, nv;
        if (io->mode == FSDEM__RESTART_WRITE) o = s->obst[k];
        else memset(&o, 0, sizeof o);
        type = (int)o.d.type;
        nv = o.d.type == FSDEM_PIC_OBSTACLE_TYPE_POLYGON ? o.d.vertex_count : 0;
        fsdem__restart_int_in(io, &type, 0, FSDEM_PIC_OBSTACLE_TYPE_SDF, "obstacle type");
        fsdem__restart_value(io, &o.d.a, sizeof o.d.a);
        fsdem__restart_value(io, &o.d.b, sizeof o.d.b);
        fsdem__restart_value(io, &o.d.radius, sizeof o.d.radius);
        fsdem__restart_value(io, &o.d.velocity, sizeof o.d.velocity);
        fsdem__restart_value(io, &o.box_lo, sizeof o.box_lo);
        fsdem__restart_value(io, &o.box_hi, sizeof o.box_hi);
        fsdem__restart_count(io, &nv, 1 << 24, sizeof(fsdem_vec3), "polygon vertex count");
        if (io->mode == FSDEM__RESTART_CHECK && io->res == FSDEM_OK && (type == FSDEM_PIC_OBSTACLE_TYPE_POLYGON) != (nv >= 3))
            fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "obstacle %d has %d vertices (corrupted data)", k, nv);
        verts = (fsdem_vec3 *)fsdem__restart_block(io, al, sizeof(fsdem_vec3) * (size_t)nv);
        fsdem__restart_data(io, io->mode == FSDEM__RESTART_WRITE ? o.verts : verts, sizeof(fsdem_vec3) * (size_t)nv);
        if (io->mode != FSDEM__RESTART_WRITE && io->res == FSDEM_OK && type == FSDEM_PIC_OBSTACLE_TYPE_SDF) {
            if (k >= s->obst_count || s->obst[k].d.type != FSDEM_PIC_OBSTACLE_TYPE_SDF)
                fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                                    "obstacle %d is an SDF obstacle in the save: add the same SDF obstacles "
                                    "(fsdem_pic_obstacle_sdf), in the same order, to the object before restoring",
                                    k);
            else {
                o.d.sdf = s->obst[k].d.sdf;
                o.d.sdf_user = s->obst[k].d.sdf_user;
            }
        }
        if (commit) {
            o.d.type = (fsdem_pic_obstacle_type)type;
            o.d.vertex_count = nv;
            o.d.vertices = o.verts = verts;
            obst[k] = o;
        }
    }
    if (commit) {
        for (k = 0; k < s->obst_count; ++k)
            if (s->obst[k].verts) fsdem__pic_release(s, s->obst[k].verts, sizeof(fsdem_vec3) * (size_t)s->obst[k].d.vertex_count);
        fsdem__pic_release(s, s->obst, sizeof(fsdem__pic_obst) * (size_t)s->obst_capacity);
        s->obst = obst;
        s->obst_count = s->obst_capacity = no;
        s->bytes += sizeof(fsdem__pic_obst) * (size_t)no;
        for (k = 0; k < no; ++k) s->bytes += sizeof(fsdem_vec3) * (size_t)obst[k].d.vertex_count;
    }

    /* particles, into fresh arrays of the saved capacity */
    fsdem__restart_count(io, &pcap, 1 << 29, 0, "particle capacity");
    fsdem__restart_count(io, &np, pcap, 2 * sizeof(fsdem_vec3), "particle count");
    if (io->res == FSDEM_OK) {
        const size_t vb = sizeof(fsdem_vec3) * (size_t)pcap, ib = sizeof(int) * (size_t)pcap;
        fsdem_vec3 *px = (fsdem_vec3 *)fsdem__restart_block(io, al, vb), *pv = (fsdem_vec3 *)fsdem__restart_block(io, al, vb);
        fsdem_vec3 *pt = (fsdem_vec3 *)fsdem__restart_block(io, al, vb), *pc[3] = {NULL, NULL, NULL};
        int *pcell, *pidx;
        unsigned char *pflag;
        for (a = 0; a < 3 && apic; ++a) pc[a] = (fsdem_vec3 *)fsdem__restart_block(io, al, vb);
        pcell = (int *)fsdem__restart_block(io, al, ib);
        pidx = (int *)fsdem__restart_block(io, al, ib);
        pflag = (unsigned char *)fsdem__restart_block(io, al, (size_t)pcap);
        if (commit) {
            fsdem__pic_free_particles(s);
            s->px = px;
            s->pv = pv;
            s->ptmp = pt;
            for (a = 0; a < 3; ++a) s->pc[a] = pc[a];
            s->pcell = pcell;
            s->pidx = pidx;
            s->pflag = pflag;
            if (pflag) memset(pflag, 0, (size_t)pcap);
            s->pcap = pcap;
            s->np = np;
            s->bytes += (apic ? 6 : 3) * vb + 2 * ib + (size_t)pcap;
        }
    }
    fsdem__restart_data(io, s->px, sizeof(fsdem_vec3) * (size_t)np);
    fsdem__restart_data(io, s->pv, sizeof(fsdem_vec3) * (size_t)np);
    for (a = 0; a < 3 && apic; ++a) fsdem__restart_data(io, s->pc[a], sizeof(fsdem_vec3) * (size_t)np);

    /* grid fields, in place (the grid matches) */
    for (a = 0; a < s->dim; ++a) {
        const size_t fb = sizeof(fsdem_real) * (size_t)s->nface[a];
        fsdem__restart_data(io, s->u[a], fb);
        fsdem__restart_data(io, s->sopen[a], fb);
        fsdem__restart_data(io, s->svel[a], fb);
        fsdem__restart_data(io, s->copen[a], fb);
        fsdem__restart_data(io, s->cvel[a], fb);
        if (s->cvisc[a]) fsdem__restart_data(io, s->cvisc[a], fb); /* viscosity > 0, as the desc */
        fsdem__restart_data(io, s->cacc[a], fb);
        fsdem__restart_data(io, s->E[a], fb);
        fsdem__restart_data(io, s->us[a], fb);
    }
    fsdem__restart_data(io, s->frac, cells);
    fsdem__restart_data(io, s->phi, cells);
    fsdem__restart_data(io, s->pres, cells);
    fsdem__restart_data(io, s->crhs, cells);
    fsdem__restart_data(io, s->cref, cells);
    fsdem__restart_data(io, s->fref, cells);
    fsdem__restart_flags(io, s->ctype, s->ncell, FSDEM_STENCIL_CELL_SOLID, "type of cell");
    fsdem__restart_flags(io, s->cnear, s->ncell, 1, "near-solid flag of cell");
    fsdem__restart_flags(io, s->csolid, s->ncell, 1, "solid flag of cell");
    fsdem__restart_gauges(io, &s->gauges, &s->allocator, "fsdem_pic_gauges_close");
    fsdem__restart_tag(io, "PIC.");
}

/* ---- >>restart_swe : shallow water ---- */

/* The per-cell masks of the SWE: the blocked cells, when there are any (nx*ny flags); `masks`
   counts them, so data with a mask this build does not know are refused. */
static void fsdem__restart_swe_masks(fsdem__restart *io, fsdem_swe *s) {
    int masks = s->blocked ? 1 : 0, k, count = 0;
    unsigned char *blocked;
    fsdem__restart_int_in(io, &masks, 0, 1, "the number of per-cell masks (data of a newer build)");
    blocked = masks ? (unsigned char *)fsdem__restart_block(io, &s->allocator, (size_t)s->n) : NULL;
    if (masks) fsdem__restart_flags(io, io->mode == FSDEM__RESTART_WRITE ? s->blocked : blocked, s->n, 1, "blocked flag of cell");
    if (io->mode != FSDEM__RESTART_COMMIT) return;
    fsdem__free(&s->allocator, s->blocked, (size_t)s->n);
    s->blocked = blocked;
    for (k = 0; blocked && k < s->n; ++k) count += blocked[k];
    s->blocked_count = count;
}

/* A series of n points (times and values): written, or read into fresh arrays that COMMIT hands to
   *t and *v after freeing the old ones. */
static void fsdem__restart_swe_series(fsdem__restart *io, fsdem_swe *s, fsdem_real **t, fsdem_real **v, int *n,
                                      const char *what) {
    int count = *n;
    fsdem_real *ft, *fv;
    fsdem__restart_count(io, &count, 1 << 28, 2 * sizeof(fsdem_real), what);
    ft = (fsdem_real *)fsdem__restart_block(io, &s->allocator, sizeof(fsdem_real) * (size_t)count);
    fv = (fsdem_real *)fsdem__restart_block(io, &s->allocator, sizeof(fsdem_real) * (size_t)count);
    if (io->mode == FSDEM__RESTART_COMMIT) {
        fsdem__swe_free_series(s, t, v, n);
        *t = ft;
        *v = fv;
        *n = count;
    }
    fsdem__restart_data(io, *t, sizeof(fsdem_real) * (size_t)count);
    fsdem__restart_data(io, *v, sizeof(fsdem_real) * (size_t)count);
}

/* Everything of a shallow-water solver, in order. State: time, last dt, counters, the bound of the
   wave speed and of the acceleration (the next adaptive dt reads them) and the other figures of the
   last step, the volume budget, rain, the surface, discharges and bed exactly, the momentum sources
   and whether they are in use, the per-cell masks (merge point above), per-cell Manning, the four
   boundaries with their series, point sources with their series, ids and states, gauge positions.
   Configuration: the grid and the desc fields that steps read, compared. Not saved: the work rows
   (prim, rows, south) and the boundary values of the step in flight (bvalue), rewritten by every
   step; the gauge file, its interval and next output time (restore refuses while a file is open);
   capacities, the allocator, log and message. */
static void fsdem__restart_swe(fsdem__restart *io, void *object) {
    fsdem_swe *s = (fsdem_swe *)object;
    const fsdem_swe_desc *sd = &s->desc;
    const fsdem_allocator *al = &s->allocator;
    const int commit = io->mode == FSDEM__RESTART_COMMIT;
    const size_t cells = sizeof(fsdem_real) * (size_t)s->n;
    int grid[2], has_manning = s->manning != NULL, ns = s->src_count, next_id = s->src_next_id, ng = s->gauge_count;
    int side, k;
    fsdem__swe_src *src;
    fsdem_real *manning, *xy;
    fsdem__restart_tag(io, "SWE1");
    grid[0] = s->nx;
    grid[1] = s->ny;
    fsdem__restart_value(io, grid, sizeof grid);
    if (io->mode == FSDEM__RESTART_CHECK && io->res == FSDEM_OK && (grid[0] != s->nx || grid[1] != s->ny))
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "the grid has %d x %d cells in the save and %d x %d in the object (create the object from "
                            "the desc it was saved with)",
                            grid[0], grid[1], s->nx, s->ny);
    fsdem__restart_same_int(io, sd->dim, "dim");
    fsdem__restart_same_real(io, sd->x_min, "x_min");
    fsdem__restart_same_real(io, sd->x_max, "x_max");
    fsdem__restart_same_real(io, sd->y_min, "y_min");
    fsdem__restart_same_real(io, sd->y_max, "y_max");
    fsdem__restart_same_real(io, sd->width, "width");
    fsdem__restart_same_vec3(io, sd->gravity, "gravity");
    fsdem__restart_same_real(io, sd->density, "density");
    fsdem__restart_same_real(io, sd->cfl, "cfl");
    fsdem__restart_same_real(io, sd->dt_max, "dt_max");
    fsdem__restart_same_int(io, sd->order, "order");
    fsdem__restart_same_int(io, (int)sd->limiter, "limiter");
    fsdem__restart_same_real(io, sd->dry_depth, "dry_depth");
    fsdem__restart_same_real(io, sd->manning, "manning");
    fsdem__restart_same_real(io, sd->eddy_viscosity, "eddy_viscosity");
    if (io->mode == FSDEM__RESTART_CHECK && s->gauges.file)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG,
                            "the object has a gauge file open: close it (fsdem_swe_gauges_close) before restoring and "
                            "open it again afterwards");

    fsdem__restart_data(io, &s->time, sizeof s->time);
    fsdem__restart_data(io, &s->dt_last, sizeof s->dt_last);
    fsdem__restart_data(io, &s->steps, sizeof s->steps);
    fsdem__restart_data(io, &s->fallbacks, sizeof s->fallbacks);
    fsdem__restart_data(io, &s->max_wave, sizeof s->max_wave);
    fsdem__restart_data(io, &s->max_accel, sizeof s->max_accel);
    fsdem__restart_data(io, &s->max_speed, sizeof s->max_speed);
    fsdem__restart_data(io, &s->max_depth, sizeof s->max_depth);
    fsdem__restart_data(io, &s->wet_cells, sizeof s->wet_cells);
    fsdem__restart_data(io, &s->vol_boundary, sizeof s->vol_boundary);
    fsdem__restart_data(io, &s->vol_source, sizeof s->vol_source);
    fsdem__restart_data(io, &s->vol_clipped, sizeof s->vol_clipped);
    fsdem__restart_data(io, &s->rain, sizeof s->rain);
    fsdem__restart_data(io, &s->sources_used, sizeof s->sources_used);

    /* the state, exactly, in place */
    fsdem__restart_data(io, s->eta, cells);
    fsdem__restart_data(io, s->qx, cells);
    fsdem__restart_data(io, s->qy, cells);
    fsdem__restart_data(io, s->bed, cells);
    fsdem__restart_data(io, s->sx, cells);
    fsdem__restart_data(io, s->sy, cells);
    fsdem__restart_swe_masks(io, s);

    /* per-cell Manning: kept in place when the object has the array, else a fresh one */
    fsdem__restart_int_in(io, &has_manning, 0, 1, "per-cell Manning flag");
    manning = has_manning && !s->manning ? (fsdem_real *)fsdem__restart_block(io, al, cells) : NULL;
    if (commit && !has_manning) {
        fsdem__free(al, s->manning, cells);
        s->manning = NULL;
    } else if (commit && manning)
        s->manning = manning;
    if (has_manning) fsdem__restart_data(io, s->manning, cells);

    for (side = 0; side < 4 && io->res == FSDEM_OK; ++side) {
        fsdem__swe_bnd *b = &s->bnd[side];
        int type = (int)b->type;
        fsdem_real value = b->value;
        fsdem__restart_int_in(io, &type, 0, FSDEM_SWE_BC_STAGE, "boundary type");
        fsdem__restart_value(io, &value, sizeof value);
        fsdem__restart_swe_series(io, s, &b->t, &b->v, &b->n, "boundary series length");
        if (commit) {
            b->type = (fsdem_swe_bc)type;
            b->value = value;
        }
    }

    /* point sources, into a fresh array */
    fsdem__restart_count(io, &ns, 1 << 24, sizeof(fsdem_real) + 4 * sizeof(int), "point source count");
    fsdem__restart_value(io, &next_id, sizeof next_id);
    src = (fsdem__swe_src *)fsdem__restart_block(io, al, sizeof(fsdem__swe_src) * (size_t)ns);
    for (k = 0; k < ns && io->res == FSDEM_OK; ++k) {
        fsdem__swe_src q;
        if (io->mode == FSDEM__RESTART_WRITE) q = s->src[k];
        else memset(&q, 0, sizeof q);
        fsdem__restart_value(io, &q.discharge, sizeof q.discharge);
        fsdem__restart_int_in(io, &q.cell, 0, s->n - 1, "point source cell");
        fsdem__restart_value(io, &q.id, sizeof q.id);
        fsdem__restart_int_in(io, &q.active, 0, 1, "point source active flag");
        fsdem__restart_swe_series(io, s, &q.t, &q.v, &q.n, "point source series length");
        if (commit) src[k] = q;
    }
    if (commit) {
        for (k = 0; k < s->src_count; ++k) fsdem__swe_free_series(s, &s->src[k].t, &s->src[k].v, &s->src[k].n);
        fsdem__free(al, s->src, sizeof(fsdem__swe_src) * (size_t)s->src_capacity);
        s->src = src;
        s->src_count = s->src_capacity = ns;
        s->src_next_id = next_id;
    }

    /* gauge positions (the file is not part of the state) */
    fsdem__restart_count(io, &ng, 1 << 24, 2 * sizeof(fsdem_real), "gauge count");
    xy = (fsdem_real *)fsdem__restart_block(io, al, 2 * sizeof(fsdem_real) * (size_t)ng);
    if (commit) {
        fsdem__free(al, s->gauge, 2 * sizeof(fsdem_real) * (size_t)s->gauge_capacity);
        s->gauge = xy;
        s->gauge_count = s->gauge_capacity = ng;
    }
    fsdem__restart_data(io, s->gauge, 2 * sizeof(fsdem_real) * (size_t)ng);
    fsdem__restart_tag(io, "SWE.");
}

/* ---- >>restart_swe_dem : SWE-DEM coupler ---- */

/* A coupler's file holds the coupled run: the SWE, then the DEM (restored into the solvers the
   coupler was created with), then the coupler's own state: counters, the last step, the impulse
   given to the water and the per-particle force records and reactions (fsdem_swe_dem_get_force and
   the next step's impulse read them). Configuration: beta, two_way, heave_damping, max_substeps and
   the water's density, gravity and dry depth taken at creation, compared. Not saved: the solver
   pointers, the allocator, log and message. */
static void fsdem__restart_swe_dem(fsdem__restart *io, void *object) {
    fsdem_swe_dem *c = (fsdem_swe_dem *)object;
    const int commit = io->mode == FSDEM__RESTART_COMMIT;
    int count = c->force_capacity, k;
    fsdem_swe_dem_force *force;
    fsdem_vec3 *reaction;
    fsdem__restart_tag(io, "SWD1");
    io->section = "shallow water";
    fsdem__restart_swe(io, c->desc.swe);
    io->section = "debris (DEM)";
    fsdem__restart_dem(io, c->desc.dem);
    io->section = NULL;
    fsdem__restart_same_real(io, c->desc.beta, "beta");
    fsdem__restart_same_int(io, c->desc.two_way, "two_way");
    fsdem__restart_same_real(io, c->desc.heave_damping, "heave_damping");
    fsdem__restart_same_ll(io, c->desc.max_substeps, "max_substeps");
    fsdem__restart_same_real(io, c->rho, "swe.density");
    fsdem__restart_same_real(io, c->g, "swe.gravity");
    fsdem__restart_same_real(io, c->dry, "swe.dry_depth");
    fsdem__restart_data(io, &c->steps, sizeof c->steps);
    fsdem__restart_data(io, &c->substeps, sizeof c->substeps);
    fsdem__restart_data(io, &c->substeps_total, sizeof c->substeps_total);
    fsdem__restart_data(io, &c->dt_last, sizeof c->dt_last);
    fsdem__restart_data(io, &c->in_water, sizeof c->in_water);
    fsdem__restart_data(io, &c->impulse, sizeof c->impulse);
    fsdem__restart_count(io, &count, 1 << 29, sizeof(int) + 5 * sizeof(fsdem_vec3) + 3 * sizeof(fsdem_real), "force record count");
    {
        int records = c->records;
        fsdem__restart_data(io, &records, sizeof records);
        if (io->res == FSDEM_OK && (records < 0 || records > count)) fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "bad record count");
        if (commit) c->records = records;
    }
    force = (fsdem_swe_dem_force *)fsdem__restart_block(io, &c->allocator, sizeof *force * (size_t)count);
    reaction = (fsdem_vec3 *)fsdem__restart_block(io, &c->allocator, sizeof *reaction * (size_t)count);
    if (commit) {
        fsdem__free(&c->allocator, c->force, sizeof *force * (size_t)c->force_capacity);
        fsdem__free(&c->allocator, c->reaction, sizeof *reaction * (size_t)c->force_capacity);
        c->force = force;
        c->reaction = reaction;
        c->force_capacity = count;
        if (force) memset(force, 0, sizeof *force * (size_t)count);
    }
    for (k = 0; k < count && io->res == FSDEM_OK; ++k) {
        fsdem_swe_dem_force scratch, *f = io->mode == FSDEM__RESTART_WRITE || commit ? &c->force[k] : &scratch;
        fsdem__restart_data(io, &f->id, sizeof f->id);
        fsdem__restart_data(io, &f->buoyancy, sizeof f->buoyancy);
        fsdem__restart_data(io, &f->hydrostatic, sizeof f->hydrostatic);
        fsdem__restart_data(io, &f->dynamic, sizeof f->dynamic);
        fsdem__restart_data(io, &f->heave, sizeof f->heave);
        fsdem__restart_data(io, &f->submerged_volume, sizeof f->submerged_volume);
        fsdem__restart_data(io, &f->frontal_area, sizeof f->frontal_area);
        fsdem__restart_data(io, &f->surface, sizeof f->surface);
        fsdem__restart_data(io, &f->in_water, sizeof f->in_water);
    }
    fsdem__restart_data(io, c->reaction, sizeof(fsdem_vec3) * (size_t)count);
    fsdem__restart_tag(io, "SWD.");
}

/* ---- >>restart_mps : MPS ---- */

/* The particles go into fresh arrays of the saved capacity (all FSDEM__MPS_ARRAYS of them and the
   four row-offset arrays, as fsdem__mps_reserve makes them); of their contents the state that the
   next step reads (positions, velocities, pressures: the pressure solve starts from them, kinds,
   porosities, a coupler's forces, obstacle membership) and the views of the last step (number
   density, surface flags, pressure gradients) are saved. The neighbour rows and the matrix are
   rebuilt by every step; their memory stays. */
static void fsdem__restart_mps(fsdem__restart *io, void *object) {
    fsdem_mps *s = (fsdem_mps *)object;
    const fsdem_mps_desc *d = &s->desc;
    const fsdem_allocator *al = &s->allocator;
    const int commit = io->mode == FSDEM__RESTART_COMMIT;
    int no = s->obst_n, n = s->n, cap = s->cap, i, a;
    fsdem__mps_obst *obst;
    fsdem__restart_tag(io, "MPS2");
    fsdem__restart_same_int(io, d->dim, "dim");
    fsdem__restart_same_real(io, d->r0, "r0");
    fsdem__restart_same_real(io, d->re, "re");
    fsdem__restart_same_real(io, d->density, "density");
    fsdem__restart_same_real(io, d->viscosity, "viscosity");
    fsdem__restart_same_vec3(io, d->gravity, "gravity");
    fsdem__restart_same_real(io, d->gamma, "gamma");
    fsdem__restart_same_int(io, (int)d->model, "model");
    fsdem__restart_same_real(io, d->beta, "beta");
    fsdem__restart_same_real(io, d->alpha, "alpha");
    fsdem__restart_same_real(io, d->cfl, "cfl");
    fsdem__restart_same_real(io, d->dt_max, "dt_max");
    fsdem__restart_same_vec3(io, d->domain_min, "domain_min");
    fsdem__restart_same_vec3(io, d->domain_max, "domain_max");
    fsdem__restart_same_int(io, (int)d->gradient, "gradient");
    fsdem__restart_same_int(io, d->clamp_negative_pressure, "clamp_negative_pressure");
    fsdem__restart_same_real(io, d->collision_distance, "collision_distance");
    fsdem__restart_same_real(io, d->restitution, "restitution");
    fsdem__restart_same_real(io, d->shifting, "shifting");
    fsdem__restart_same_int(io, (int)d->pressure_precond, "pressure_precond");
    fsdem__restart_same_real(io, d->pressure_tolerance, "pressure_tolerance");
    fsdem__restart_same_int(io, d->pressure_max_iterations, "pressure_max_iterations");

    fsdem__restart_data(io, &s->time, sizeof s->time);
    fsdem__restart_data(io, &s->dt_last, sizeof s->dt_last);
    fsdem__restart_data(io, &s->steps, sizeof s->steps);
    fsdem__restart_data(io, &s->iters_total, sizeof s->iters_total);
    fsdem__restart_data(io, &s->iters, sizeof s->iters);
    fsdem__restart_data(io, &s->residual, sizeof s->residual);
    fsdem__restart_data(io, &s->surface_count, sizeof s->surface_count);
    fsdem__restart_data(io, &s->pair_count, sizeof s->pair_count);

    /* obstacles, into a fresh array */
    fsdem__restart_count(io, &no, 1 << 24, sizeof(fsdem__mps_obst), "obstacle count");
    obst = (fsdem__mps_obst *)fsdem__restart_block(io, al, sizeof *obst * (size_t)no);
    if (commit) {
        fsdem__free(al, s->obst, sizeof *s->obst * (size_t)s->obst_cap);
        s->bytes += sizeof *obst * (size_t)no - sizeof *s->obst * (size_t)s->obst_cap;
        s->obst = obst;
        s->obst_n = s->obst_cap = no;
    }
    fsdem__restart_data(io, s->obst, sizeof *s->obst * (size_t)no);

    /* particles, into fresh arrays of the saved capacity */
    fsdem__restart_count(io, &cap, 1 << 29, 0, "particle capacity");
    fsdem__restart_count(io, &n, cap, 2 * sizeof(fsdem_vec3), "particle count");
    if (io->res == FSDEM_OK && (io->mode == FSDEM__RESTART_RESERVE || commit)) {
        void **ptr[FSDEM__MPS_ARRAYS];
        size_t elem[FSDEM__MPS_ARRAYS];
        void *fresh[FSDEM__MPS_ARRAYS + 4];
        const int k = fsdem__mps_arrays(s, ptr, elem);
        for (a = 0; a < k; ++a) fresh[a] = fsdem__restart_block(io, al, elem[a] * (size_t)cap);
        for (a = 0; a < 4; ++a) fresh[k + a] = fsdem__restart_block(io, al, sizeof(int) * (size_t)(cap + 1));
        if (commit) {
            for (a = 0; a < k; ++a) {
                fsdem__free(al, *ptr[a], elem[a] * (size_t)s->cap);
                *ptr[a] = fresh[a];
                s->bytes += elem[a] * (size_t)cap - elem[a] * (size_t)s->cap;
            }
            for (a = 0; a < 4; ++a) {
                int **rows = fsdem__mps_rows(s, a);
                fsdem__free(al, *rows, sizeof(int) * (size_t)(s->cap + 1));
                *rows = (int *)fresh[k + a];
                memset(*rows, 0, sizeof(int) * (size_t)(cap + 1));
            }
            s->bytes += 4 * sizeof(int) * (size_t)cap - 4 * sizeof(int) * (size_t)s->cap;
            s->cap = cap;
            s->n = n;
            s->rows = 0; /* the pressure matrix of the last step is not kept */
        }
    }
    fsdem__restart_data(io, s->x, sizeof *s->x * (size_t)n);
    fsdem__restart_data(io, s->v, sizeof *s->v * (size_t)n);
    fsdem__restart_data(io, s->p, sizeof *s->p * (size_t)n);
    fsdem__restart_data(io, s->eps, sizeof *s->eps * (size_t)n);
    fsdem__restart_data(io, s->nd, sizeof *s->nd * (size_t)n);
    fsdem__restart_data(io, &s->external, sizeof s->external);
    fsdem__restart_data(io, s->fext, sizeof *s->fext * (size_t)n);
    fsdem__restart_data(io, s->gradp, sizeof *s->gradp * (size_t)n);
    fsdem__restart_flags(io, s->kind, n, FSDEM_MPS_KIND_DUMMY, "kind of particle");
    fsdem__restart_flags(io, s->surf, n, 1, "surface flag of particle");
    fsdem__restart_ints(io, s->body, n, -1, no - 1, "obstacle of particle");
    fsdem__restart_gauges(io, &s->gauges, al, "fsdem_mps_gauges_close");
    if (commit) {
        s->counts[0] = s->counts[1] = s->counts[2] = 0;
        for (i = 0; i < n; ++i) {
            s->counts[s->kind[i]]++;
            s->us[i] = s->shift[i] = fsdem__zero3();
            s->unknown[i] = -1;
        }
    }
    fsdem__restart_tag(io, "MPS.");
}

/* ---- >>restart_mps_dem : MPS-DEM coupler ---- */

/* The two solvers, then the coupler's counters and the force records of its last update (a step
   recomputes them first, so they only serve fsdem_mps_dem_get_force until then). The pair lists
   and the grid are rebuilt by every update. */
static void fsdem__restart_mps_dem(fsdem__restart *io, void *object) {
    fsdem_mps_dem *c = (fsdem_mps_dem *)object;
    const int commit = io->mode == FSDEM__RESTART_COMMIT;
    int count = c->forces, k;
    fsdem_mps_dem_force *force;
    fsdem__restart_tag(io, "MPD1");
    io->section = "water (MPS)";
    fsdem__restart_mps(io, c->desc.mps);
    io->section = "sediment (DEM)";
    fsdem__restart_dem(io, c->desc.dem);
    io->section = NULL;
    fsdem__restart_same_int(io, (int)c->desc.drag, "drag");
    fsdem__restart_same_real(io, c->desc.radius, "radius");
    fsdem__restart_same_real(io, c->desc.min_porosity, "min_porosity");
    fsdem__restart_same_real(io, c->desc.drag_dt_fraction, "drag_dt_fraction");
    fsdem__restart_same_ll(io, c->desc.max_substeps, "max_substeps");
    fsdem__restart_data(io, &c->steps, sizeof c->steps);
    fsdem__restart_data(io, &c->substeps, sizeof c->substeps);
    fsdem__restart_data(io, &c->substeps_total, sizeof c->substeps_total);
    fsdem__restart_data(io, &c->pairs, sizeof c->pairs);
    fsdem__restart_data(io, &c->dt_last, sizeof c->dt_last);
    fsdem__restart_data(io, &c->drag_dt, sizeof c->drag_dt);
    fsdem__restart_data(io, &c->wet, sizeof c->wet);
    fsdem__restart_data(io, &c->drag_sum, sizeof c->drag_sum);
    fsdem__restart_data(io, &c->pressure_sum, sizeof c->pressure_sum);
    fsdem__restart_data(io, &c->fluid_sum, sizeof c->fluid_sum);
    fsdem__restart_count(io, &count, 1 << 29, sizeof(int) + 4 * sizeof(fsdem_vec3) + 2 * sizeof(fsdem_real), "force record count");
    force = (fsdem_mps_dem_force *)fsdem__restart_block(io, &c->allocator, sizeof *force * (size_t)count);
    if (commit) {
        fsdem__free(&c->allocator, c->force, sizeof *force * (size_t)c->force_cap);
        c->force = force;
        c->forces = c->force_cap = count;
        if (force) memset(force, 0, sizeof *force * (size_t)count);
    }
    for (k = 0; k < count && io->res == FSDEM_OK; ++k) {
        fsdem_mps_dem_force scratch, *f = io->mode == FSDEM__RESTART_WRITE || commit ? &c->force[k] : &scratch;
        fsdem__restart_data(io, &f->id, sizeof f->id);
        fsdem__restart_data(io, &f->drag, sizeof f->drag);
        fsdem__restart_data(io, &f->pressure, sizeof f->pressure);
        fsdem__restart_data(io, &f->total, sizeof f->total);
        fsdem__restart_data(io, &f->fluid_velocity, sizeof f->fluid_velocity);
        fsdem__restart_data(io, &f->porosity, sizeof f->porosity);
        fsdem__restart_data(io, &f->reynolds, sizeof f->reynolds);
        fsdem__restart_data(io, &f->wet, sizeof f->wet);
    }
    fsdem__restart_tag(io, "MPD.");
}

/* ---- >>restart_pic_dem : PIC-DEM coupler ---- */

/* The two solvers, then the coupler's counters, its viscous limit and the loads of its last step.
   Its cut (faces, J, references) is redone at the start of every step over the PIC's reset coupling
   arrays, so it is not saved; the viscous limit of the saved step is: the run goes on bit for bit. */
static void fsdem__restart_pic_dem(fsdem__restart *io, void *object) {
    fsdem_pic_dem *c = (fsdem_pic_dem *)object;
    const int commit = io->mode == FSDEM__RESTART_COMMIT;
    int count = c->loaded ? c->bodies : 0, b;
    fsdem__restart_tag(io, "PDM1");
    io->section = "water (PIC)";
    fsdem__restart_pic(io, c->desc.pic);
    io->section = "bodies (DEM)";
    fsdem__restart_dem(io, c->desc.dem);
    io->section = NULL;
    fsdem__restart_same_real(io, c->desc.dissipation, "dissipation");
    fsdem__restart_same_real(io, c->desc.contact_length, "contact_length");
    fsdem__restart_same_real(io, c->desc.viscous_dt_fraction, "viscous_dt_fraction");
    fsdem__restart_same_int(io, c->desc.discrete_weight, "discrete_weight");
    fsdem__restart_same_ll(io, c->desc.max_substeps, "max_substeps");
    fsdem__restart_data(io, &c->steps, sizeof c->steps);
    fsdem__restart_data(io, &c->substeps, sizeof c->substeps);
    fsdem__restart_data(io, &c->substeps_total, sizeof c->substeps_total);
    fsdem__restart_data(io, &c->dissipated, sizeof c->dissipated);
    fsdem__restart_data(io, &c->pushed, sizeof c->pushed);
    fsdem__restart_data(io, &c->removed, sizeof c->removed);
    fsdem__restart_data(io, &c->dt_last, sizeof c->dt_last);
    fsdem__restart_data(io, &c->viscous_dt, sizeof c->viscous_dt);
    fsdem__restart_data(io, &c->force_sum, sizeof c->force_sum);
    fsdem__restart_count(io, &count, 1 << 29, sizeof(int) + 4 * sizeof(fsdem_vec3) + sizeof(fsdem_real), "body load count");
    if (io->mode == FSDEM__RESTART_RESERVE && fsdem__pic_dem_reserve_bodies(c, count) != FSDEM_OK) io->res = FSDEM_ERR_OUT_OF_MEMORY;
    if (commit) { /* the next step cuts afresh, as every step does */
        c->face_count = c->jac_count = 0;
        c->bodies = count;
        c->loaded = count > 0;
        for (b = 0; b <= count; ++b) c->face_start[b] = c->jac_start[b] = 0;
    }
    for (b = 0; b < count && io->res == FSDEM_OK; ++b) {
        fsdem_vec3 scratch[4];
        fsdem_real vol;
        const int here = io->mode == FSDEM__RESTART_WRITE || commit;
        int id;
        fsdem__restart_data(io, here ? &c->body_id[b] : &id, sizeof(int));
        fsdem__restart_data(io, here ? &c->fp[b] : &scratch[0], sizeof(fsdem_vec3));
        fsdem__restart_data(io, here ? &c->fv[b] : &scratch[1], sizeof(fsdem_vec3));
        fsdem__restart_data(io, here ? &c->tq[b] : &scratch[2], sizeof(fsdem_vec3));
        fsdem__restart_data(io, here ? &c->wc[b] : &scratch[3], sizeof(fsdem_vec3));
        fsdem__restart_data(io, here ? &c->volume[b] : &vol, sizeof(fsdem_real));
    }
    fsdem__restart_tag(io, "PDM.");
}

/* ---- >>restart_api : memory and files ---- */

/* What the API needs to know of one object. */
typedef struct fsdem__restart_object {
    unsigned int kind;
    int dim, sizes[4];
    void *object;
    fsdem__restart_visit_fn visit;
    const fsdem_allocator *allocator;
    fsdem__status *status; /* the message is the only part of a saved (const) object that changes */
    const char *name;
} fsdem__restart_object;

static const char *fsdem__restart_kind_name(unsigned int kind) {
    switch (kind) {
    case FSDEM__RESTART_DEM: return "fsdem_dem";
    case FSDEM__RESTART_PIC: return "fsdem_pic";
    case FSDEM__RESTART_SWE: return "fsdem_swe";
    case FSDEM__RESTART_SWE_DEM: return "fsdem_swe_dem";
    case FSDEM__RESTART_MPS: return "fsdem_mps";
    case FSDEM__RESTART_MPS_DEM: return "fsdem_mps_dem";
    case FSDEM__RESTART_PIC_DEM: return "fsdem_pic_dem";
    }
    return "unknown object";
}

static fsdem__restart_object fsdem__restart_of_dem(const fsdem_dem *d) {
    fsdem__restart_object o;
    memset(&o, 0, sizeof o);
    if (!d) return o;
    o.kind = FSDEM__RESTART_DEM;
    o.dim = d->desc.dim;
    o.sizes[0] = d->n;
    o.sizes[1] = d->material_count;
    o.sizes[2] = d->wall_count;
    o.sizes[3] = d->pp.count;
    o.object = (void *)d;
    o.visit = fsdem__restart_dem;
    o.allocator = &d->allocator;
    o.status = (fsdem__status *)&d->status;
    o.name = "fsdem_dem";
    return o;
}

static fsdem__restart_object fsdem__restart_of_pic(const fsdem_pic *s) {
    fsdem__restart_object o;
    memset(&o, 0, sizeof o);
    if (!s) return o;
    o.kind = FSDEM__RESTART_PIC;
    o.dim = s->dim;
    o.sizes[0] = s->n[0];
    o.sizes[1] = s->n[1];
    o.sizes[2] = s->n[2];
    o.sizes[3] = s->np;
    o.object = (void *)s;
    o.visit = fsdem__restart_pic;
    o.allocator = &s->allocator;
    o.status = (fsdem__status *)&s->status;
    o.name = "fsdem_pic";
    return o;
}

static fsdem__restart_object fsdem__restart_of_swe(const fsdem_swe *s) {
    fsdem__restart_object o;
    memset(&o, 0, sizeof o);
    if (!s) return o;
    o.kind = FSDEM__RESTART_SWE;
    o.dim = s->dim;
    o.sizes[0] = s->nx;
    o.sizes[1] = s->ny;
    o.sizes[2] = s->src_count;
    o.sizes[3] = s->gauge_count;
    o.object = (void *)s;
    o.visit = fsdem__restart_swe;
    o.allocator = &s->allocator;
    o.status = (fsdem__status *)&s->status;
    o.name = "fsdem_swe";
    return o;
}

static fsdem__restart_object fsdem__restart_of_swe_dem(const fsdem_swe_dem *c) {
    fsdem__restart_object o;
    memset(&o, 0, sizeof o);
    if (!c) return o;
    o.kind = FSDEM__RESTART_SWE_DEM;
    o.dim = c->desc.swe->dim;
    o.sizes[0] = c->desc.swe->nx;
    o.sizes[1] = c->desc.swe->ny;
    o.sizes[2] = c->desc.dem->n;
    o.sizes[3] = c->force_capacity;
    o.object = (void *)c;
    o.visit = fsdem__restart_swe_dem;
    o.allocator = &c->allocator;
    o.status = (fsdem__status *)&c->status;
    o.name = "fsdem_swe_dem";
    return o;
}

static fsdem__restart_object fsdem__restart_of_mps(const fsdem_mps *s) {
    fsdem__restart_object o;
    memset(&o, 0, sizeof o);
    if (!s) return o;
    o.kind = FSDEM__RESTART_MPS;
    o.dim = s->dim;
    o.sizes[0] = s->n;
    o.sizes[1] = s->counts[FSDEM_MPS_KIND_FLUID];
    o.sizes[2] = s->obst_n;
    o.sizes[3] = 0;
    o.object = (void *)s;
    o.visit = fsdem__restart_mps;
    o.allocator = &s->allocator;
    o.status = (fsdem__status *)&s->status;
    o.name = "fsdem_mps";
    return o;
}

static fsdem__restart_object fsdem__restart_of_mps_dem(const fsdem_mps_dem *c) {
    fsdem__restart_object o;
    memset(&o, 0, sizeof o);
    if (!c) return o;
    o.kind = FSDEM__RESTART_MPS_DEM;
    o.dim = c->dim;
    o.sizes[0] = c->desc.mps->n;
    o.sizes[1] = c->desc.dem->n;
    o.sizes[2] = c->forces;
    o.sizes[3] = 0;
    o.object = (void *)c;
    o.visit = fsdem__restart_mps_dem;
    o.allocator = &c->allocator;
    o.status = (fsdem__status *)&c->status;
    o.name = "fsdem_mps_dem";
    return o;
}

static fsdem__restart_object fsdem__restart_of_pic_dem(const fsdem_pic_dem *c) {
    fsdem__restart_object o;
    memset(&o, 0, sizeof o);
    if (!c) return o;
    o.kind = FSDEM__RESTART_PIC_DEM;
    o.dim = c->dim;
    o.sizes[0] = c->desc.pic->np;
    o.sizes[1] = c->desc.dem->n;
    o.sizes[2] = c->loaded ? c->bodies : 0;
    o.sizes[3] = 0;
    o.object = (void *)c;
    o.visit = fsdem__restart_pic_dem;
    o.allocator = &c->allocator;
    o.status = (fsdem__status *)&c->status;
    o.name = "fsdem_pic_dem";
    return o;
}

/* A cursor for `verb` of object o ("save", "restore_memory", ...). */
static void fsdem__restart_begin(fsdem__restart *io, const fsdem__restart_object *o, const char *verb,
                                 fsdem__restart_mode mode) {
    memset(io, 0, sizeof *io);
    io->mode = mode;
    io->res = FSDEM_OK;
    io->allocator = o->allocator;
    snprintf(io->fn, sizeof io->fn, "%s_%s", o->name, verb);
}

/* Hands the cursor's result to the object: its message on failure, an empty one on success. */
static fsdem_result fsdem__restart_end(fsdem__restart *io, const fsdem__restart_object *o) {
    int k;
    for (k = io->block_next; k < io->block_count; ++k)
        fsdem__free(io->blocks[k].allocator, io->blocks[k].ptr, io->blocks[k].bytes);
    fsdem__free(io->allocator, io->blocks, sizeof *io->blocks * (size_t)io->block_capacity);
    io->blocks = NULL;
    io->block_count = io->block_capacity = io->block_next = 0;
    return io->res == FSDEM_OK ? fsdem__ok(o->status) : fsdem__fail(o->status, io->res, "%s", io->message);
}

/* The header of o with a payload of `payload` bytes, and the checksum of its first 56 bytes. */
static unsigned long long fsdem__restart_header(unsigned char h[FSDEM__RESTART_HEADER], const fsdem__restart_object *o,
                                                unsigned long long payload) {
    const unsigned int u[6] = {FSDEM__RESTART_VERSION, FSDEM__RESTART_BOM, (unsigned int)sizeof(fsdem_real), o->kind,
                               (unsigned int)o->dim, 0u};
    memset(h, 0, FSDEM__RESTART_HEADER);
    memcpy(h, "FSDEMRST", 8);
    memcpy(h + 8, u, sizeof u);
    memcpy(h + 32, o->sizes, sizeof o->sizes);
    memcpy(h + 48, &payload, 8);
    return fsdem__restart_fnv(FSDEM__RESTART_FNV_BASIS, h, 56);
}

static unsigned int fsdem__restart_u32(const unsigned char *p) {
    unsigned int v;
    memcpy(&v, p, sizeof v);
    return v;
}

/* Measures the payload of o and fills the header; the cursor is then ready to write the payload. */
static void fsdem__restart_prepare(fsdem__restart *io, const fsdem__restart_object *o,
                                   unsigned char header[FSDEM__RESTART_HEADER]) {
    o->visit(io, o->object);
    io->hash = fsdem__restart_header(header, o, (unsigned long long)io->pos);
    io->size = io->pos;
    io->pos = 0;
}

/* Saves o to `buffer` (`capacity` bytes; NULL: only the size). The payload is measured first, so a
   buffer too small is refused before anything is written. */
static fsdem_result fsdem__restart_save_memory(const fsdem__restart_object *o, void *buffer, size_t capacity,
                                               size_t *size) {
    fsdem__restart io;
    unsigned char header[FSDEM__RESTART_HEADER];
    if (!o->object) return FSDEM_ERR_INVALID_ARG; /* a NULL handle: no object to hold a message */
    fsdem__restart_begin(&io, o, "save_memory", FSDEM__RESTART_WRITE);
    if (!size) {
        fsdem__restart_fail(&io, FSDEM_ERR_INVALID_ARG, "size is NULL");
        return fsdem__restart_end(&io, o);
    }
    fsdem__restart_prepare(&io, o, header);
    *size = FSDEM__RESTART_HEADER + io.size;
    if (buffer && capacity < *size)
        fsdem__restart_fail(&io, FSDEM_ERR_INVALID_ARG, "the buffer of %llu bytes is too small: %llu are needed",
                            (unsigned long long)capacity, (unsigned long long)*size);
    if (buffer && io.res == FSDEM_OK) {
        io.out = (unsigned char *)buffer + FSDEM__RESTART_HEADER;
        o->visit(&io, o->object);
        FSDEM_ASSERT(io.pos == io.size);
        memcpy(header + 56, &io.hash, 8);
        memcpy(buffer, header, FSDEM__RESTART_HEADER);
    }
    return fsdem__restart_end(&io, o);
}

/* Saves o to the file `path` in one pass: header, payload, then the checksum into the header. */
static fsdem_result fsdem__restart_save_file(const fsdem__restart_object *o, const char *path) {
    fsdem__restart io;
    unsigned char header[FSDEM__RESTART_HEADER];
    FILE *fp;
    int bad;
    if (!o->object) return FSDEM_ERR_INVALID_ARG; /* a NULL handle: no object to hold a message */
    fsdem__restart_begin(&io, o, "save", FSDEM__RESTART_WRITE);
    if (!path) {
        fsdem__restart_fail(&io, FSDEM_ERR_INVALID_ARG, "path is NULL");
        return fsdem__restart_end(&io, o);
    }
    fp = fopen(path, "wb");
    if (!fp) {
        fsdem__restart_fail(&io, FSDEM_ERR_IO, "cannot open '%s' for writing", path);
        return fsdem__restart_end(&io, o);
    }
    fsdem__restart_prepare(&io, o, header);
    bad = fwrite(header, 1, FSDEM__RESTART_HEADER, fp) != FSDEM__RESTART_HEADER;
    io.file = fp;
    o->visit(&io, o->object);
    memcpy(header + 56, &io.hash, 8);
    bad |= ferror(fp) || fseek(fp, 56, SEEK_SET) != 0 || fwrite(header + 56, 1, 8, fp) != 8;
    bad |= fclose(fp) != 0;
    if (bad) fsdem__restart_fail(&io, FSDEM_ERR_IO, "cannot write '%s'", path);
    return fsdem__restart_end(&io, o);
}

/* Checks the header of `size` bytes at `data` against o: magic, version, byte order, precision,
   kind, dimension, the announced size, then the checksum. */
static void fsdem__restart_check_header(fsdem__restart *io, const fsdem__restart_object *o, const unsigned char *data,
                                        size_t size) {
    unsigned long long payload, sum;
    unsigned int precision, kind, dim;
    if (!data) {
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "buffer is NULL");
        return;
    }
    if (size < FSDEM__RESTART_HEADER || memcmp(data, "FSDEMRST", 8) != 0) {
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "not a fsdem restart file (%s)",
                            size < FSDEM__RESTART_HEADER ? "shorter than the 64-byte header" : "no FSDEMRST magic");
        return;
    }
    precision = fsdem__restart_u32(data + 16);
    kind = fsdem__restart_u32(data + 20);
    dim = fsdem__restart_u32(data + 24);
    memcpy(&payload, data + 48, 8);
    memcpy(&sum, data + 56, 8);
    if (fsdem__restart_u32(data + 8) != FSDEM__RESTART_VERSION)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "format version %u; this build reads version %u",
                            fsdem__restart_u32(data + 8), FSDEM__RESTART_VERSION);
    else if (fsdem__restart_u32(data + 12) != FSDEM__RESTART_BOM)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "written on a machine of another byte order");
    else if (precision != sizeof(fsdem_real))
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "precision: written with %u-byte reals, this build's fsdem_real has %u (%s)",
                            precision, (unsigned int)sizeof(fsdem_real), sizeof(fsdem_real) == 4 ? "FSDEM_USE_FLOAT" : "double");
    else if (kind != o->kind)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "the data hold the state of a %s, not of a %s",
                            fsdem__restart_kind_name(kind), fsdem__restart_kind_name(o->kind));
    else if (dim != (unsigned int)o->dim)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "dimension: the data hold a %uD state, the object is %dD", dim, o->dim);
    else if (payload != (unsigned long long)(size - FSDEM__RESTART_HEADER))
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "%s: %llu bytes after the header, %llu announced",
                            payload > (unsigned long long)(size - FSDEM__RESTART_HEADER) ? "truncated" : "trailing bytes",
                            (unsigned long long)(size - FSDEM__RESTART_HEADER), payload);
    else if (fsdem__restart_fnv(fsdem__restart_fnv(FSDEM__RESTART_FNV_BASIS, data, 56), data + FSDEM__RESTART_HEADER,
                                (size_t)payload) != sum)
        fsdem__restart_fail(io, FSDEM_ERR_INVALID_ARG, "checksum mismatch: the data are corrupted");
}

/* Restores o from `size` bytes at `data`: the header, then the visitor's CHECK, RESERVE and COMMIT
   passes over the payload. */
static fsdem_result fsdem__restart_load(const fsdem__restart_object *o, const char *verb, const unsigned char *data,
                                        size_t size) {
    fsdem__restart io;
    static const fsdem__restart_mode passes[3] = {FSDEM__RESTART_CHECK, FSDEM__RESTART_RESERVE, FSDEM__RESTART_COMMIT};
    int pass;
    fsdem__restart_begin(&io, o, verb, FSDEM__RESTART_CHECK);
    fsdem__restart_check_header(&io, o, data, size);
    for (pass = 0; pass < 3 && io.res == FSDEM_OK; ++pass) {
        io.mode = passes[pass];
        io.in = data + FSDEM__RESTART_HEADER;
        io.size = size - FSDEM__RESTART_HEADER;
        io.pos = 0;
        o->visit(&io, o->object);
        if (io.res == FSDEM_OK && io.pos != io.size)
            fsdem__restart_fail(&io, FSDEM_ERR_INVALID_ARG, "%llu bytes left unread (corrupted data)",
                                (unsigned long long)(io.size - io.pos));
    }
    FSDEM_ASSERT(io.res != FSDEM_OK || io.block_next == io.block_count);
    return fsdem__restart_end(&io, o);
}

/* Restores o from the file `path`, read whole into memory (FSDEM_ERR_IO when it cannot be). */
static fsdem_result fsdem__restart_load_file(const fsdem__restart_object *o, const char *path) {
    fsdem__restart io;
    FILE *fp;
    unsigned char *data = NULL;
    long length = -1;
    fsdem_result res;
    if (!o->object) return FSDEM_ERR_INVALID_ARG; /* a NULL handle: no object to hold a message */
    fp = path ? fopen(path, "rb") : NULL;
    fsdem__restart_begin(&io, o, "restore", FSDEM__RESTART_CHECK);
    if (!path) fsdem__restart_fail(&io, FSDEM_ERR_INVALID_ARG, "path is NULL");
    else if (!fp) fsdem__restart_fail(&io, FSDEM_ERR_IO, "cannot open '%s'", path);
    /* a directory opens and seeks on some systems (its "length" is then LONG_MAX): read a byte
       before trusting the length */
    else if (fseek(fp, 0, SEEK_END) != 0 || (length = ftell(fp)) < 0 || fseek(fp, 0, SEEK_SET) != 0 ||
             (length > 0 && (getc(fp) == EOF || fseek(fp, 0, SEEK_SET) != 0)))
        fsdem__restart_fail(&io, FSDEM_ERR_IO, "cannot read '%s' (not a readable file)", path);
    else if (!(data = (unsigned char *)fsdem__alloc(o->allocator, (size_t)length)))
        fsdem__restart_fail(&io, FSDEM_ERR_OUT_OF_MEMORY, "out of memory for the %ld bytes of '%s'", length, path);
    else if (fread(data, 1, (size_t)length, fp) != (size_t)length)
        fsdem__restart_fail(&io, FSDEM_ERR_IO, "cannot read '%s'", path);
    if (fp) fclose(fp);
    res = io.res == FSDEM_OK ? fsdem__restart_load(o, "restore", data, (size_t)length) : fsdem__restart_end(&io, o);
    fsdem__free(o->allocator, data, length > 0 ? (size_t)length : 1);
    return res;
}

/* Restores o from the `size` bytes at `buffer` (a save_memory image). */
static fsdem_result fsdem__restart_load_memory(const fsdem__restart_object *o, const void *buffer, size_t size) {
    if (!o->object) return FSDEM_ERR_INVALID_ARG; /* a NULL handle: no object to hold a message */
    return fsdem__restart_load(o, "restore_memory", (const unsigned char *)buffer, size);
}

/* The public functions: save and restore, to files and to memory, for each of the four objects:
   two lines each around the helpers above, which refuse a NULL object with FSDEM_ERR_INVALID_ARG
   without a message: there is no object to hold it. */

/* fsdem_dem (>>restart): the discrete elements. */
fsdem_result fsdem_dem_save(const fsdem_dem *dem, const char *path) {
    fsdem__restart_object o = fsdem__restart_of_dem(dem);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_dem_restore(fsdem_dem *dem, const char *path) {
    fsdem__restart_object o = fsdem__restart_of_dem(dem);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_dem_save_memory(const fsdem_dem *dem, void *buffer, size_t capacity, size_t *size) {
    fsdem__restart_object o = fsdem__restart_of_dem(dem);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_dem_restore_memory(fsdem_dem *dem, const void *buffer, size_t size) {
    fsdem__restart_object o = fsdem__restart_of_dem(dem);
    return fsdem__restart_load_memory(&o, buffer, size);
}

/* fsdem_pic (>>restart): the PIC/FLIP solver. */
fsdem_result fsdem_pic_save(const fsdem_pic *pic, const char *path) {
    fsdem__restart_object o = fsdem__restart_of_pic(pic);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_pic_restore(fsdem_pic *pic, const char *path) {
    fsdem__restart_object o = fsdem__restart_of_pic(pic);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_pic_save_memory(const fsdem_pic *pic, void *buffer, size_t capacity, size_t *size) {
    fsdem__restart_object o = fsdem__restart_of_pic(pic);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_pic_restore_memory(fsdem_pic *pic, const void *buffer, size_t size) {
    fsdem__restart_object o = fsdem__restart_of_pic(pic);
    return fsdem__restart_load_memory(&o, buffer, size);
}

/* fsdem_swe (>>restart): the shallow-water solver. */
fsdem_result fsdem_swe_save(const fsdem_swe *swe, const char *path) {
    fsdem__restart_object o = fsdem__restart_of_swe(swe);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_swe_restore(fsdem_swe *swe, const char *path) {
    fsdem__restart_object o = fsdem__restart_of_swe(swe);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_swe_save_memory(const fsdem_swe *swe, void *buffer, size_t capacity, size_t *size) {
    fsdem__restart_object o = fsdem__restart_of_swe(swe);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_swe_restore_memory(fsdem_swe *swe, const void *buffer, size_t size) {
    fsdem__restart_object o = fsdem__restart_of_swe(swe);
    return fsdem__restart_load_memory(&o, buffer, size);
}

/* fsdem_swe_dem (>>restart): the SWE-DEM coupler with its two solvers. */
fsdem_result fsdem_swe_dem_save(const fsdem_swe_dem *coupler, const char *path) {
    fsdem__restart_object o = fsdem__restart_of_swe_dem(coupler);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_swe_dem_restore(fsdem_swe_dem *coupler, const char *path) {
    fsdem__restart_object o = fsdem__restart_of_swe_dem(coupler);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_swe_dem_save_memory(const fsdem_swe_dem *coupler, void *buffer, size_t capacity, size_t *size) {
    fsdem__restart_object o = fsdem__restart_of_swe_dem(coupler);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_swe_dem_restore_memory(fsdem_swe_dem *coupler, const void *buffer, size_t size) {
    fsdem__restart_object o = fsdem__restart_of_swe_dem(coupler);
    return fsdem__restart_load_memory(&o, buffer, size);
}

/* fsdem_mps (>>restart): the MPS solver. */
fsdem_result fsdem_mps_save(const fsdem_mps *mps, const char *path) {
    fsdem__restart_object o = fsdem__restart_of_mps(mps);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_mps_restore(fsdem_mps *mps, const char *path) {
    fsdem__restart_object o = fsdem__restart_of_mps(mps);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_mps_save_memory(const fsdem_mps *mps, void *buffer, size_t capacity, size_t *size) {
    fsdem__restart_object o = fsdem__restart_of_mps(mps);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_mps_restore_memory(fsdem_mps *mps, const void *buffer, size_t size) {
    fsdem__restart_object o = fsdem__restart_of_mps(mps);
    return fsdem__restart_load_memory(&o, buffer, size);
}

/* fsdem_mps_dem (>>restart): the MPS-DEM coupler with its two solvers. */
fsdem_result fsdem_mps_dem_save(const fsdem_mps_dem *coupler, const char *path) {
    fsdem__restart_object o = fsdem__restart_of_mps_dem(coupler);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_mps_dem_restore(fsdem_mps_dem *coupler, const char *path) {
    fsdem__restart_object o = fsdem__restart_of_mps_dem(coupler);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_mps_dem_save_memory(const fsdem_mps_dem *coupler, void *buffer, size_t capacity, size_t *size) {
    fsdem__restart_object o = fsdem__restart_of_mps_dem(coupler);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_mps_dem_restore_memory(fsdem_mps_dem *coupler, const void *buffer, size_t size) {
    fsdem__restart_object o = fsdem__restart_of_mps_dem(coupler);
    return fsdem__restart_load_memory(&o, buffer, size);
}

/* fsdem_pic_dem (>>restart): the PIC-DEM coupler with its two solvers. */
fsdem_result fsdem_pic_dem_save(const fsdem_pic_dem *coupler, const char *path) {
    fsdem__restart_object o = fsdem__restart_of_pic_dem(coupler);
    return fsdem__restart_save_file(&o, path);
}

fsdem_result fsdem_pic_dem_restore(fsdem_pic_dem *coupler, const char *path) {
    fsdem__restart_object o = fsdem__restart_of_pic_dem(coupler);
    return fsdem__restart_load_file(&o, path);
}

fsdem_result fsdem_pic_dem_save_memory(const fsdem_pic_dem *coupler, void *buffer, size_t capacity, size_t *size) {
    fsdem__restart_object o = fsdem__restart_of_pic_dem(coupler);
    return fsdem__restart_save_memory(&o, buffer, capacity, size);
}

fsdem_result fsdem_pic_dem_restore_memory(fsdem_pic_dem *coupler, const void *buffer, size_t size) {
    fsdem__restart_object o = fsdem__restart_of_pic_dem(coupler);
    return fsdem__restart_load_memory(&o, buffer, size);
}

/* ===== >>impl_io : CSV, ParaView series, VTK XML ====================================================

   Contents: >>io_csv (CSV time series), >>io_vtk (the VTK XML writer core, through which every VTK
   file of the library is written), >>io_pvd (ParaView series), >>io_dem (particles, walls,
   contacts), >>io_pic (particles, grid), >>io_swe (fields). */

/* ---- >>io_csv : CSV time series ---- */


fsdem_result fsdem_csv_open(fsdem_csv *csv, const char *path, const char *header) {
    FILE *fp;
    const char *c;
    if (!csv || !path || !header || !header[0]) return FSDEM_ERR_INVALID_ARG;
    csv->file = NULL;
    csv->columns = 1;
    for (c = header; *c; ++c)
        if (*c == ',') csv->columns++;
    fp = fopen(path, "w");
    if (!fp) return FSDEM_ERR_IO;
    csv->file = fp;
    if (fprintf(fp, "%s\n", header) < 0) {
        fclose(fp);
        csv->file = NULL;
        return FSDEM_ERR_IO;
    }
    return FSDEM_OK;
}

fsdem_result fsdem_csv_row(fsdem_csv *csv, const fsdem_real *values, int count) {
    int k;
    if (!csv || !csv->file || !values || count != csv->columns) return FSDEM_ERR_INVALID_ARG;
    for (k = 0; k < count; ++k)
        if (fprintf((FILE *)csv->file, k ? ",%.10g" : "%.10g", (double)values[k]) < 0) return FSDEM_ERR_IO;
    return fputc('\n', (FILE *)csv->file) == EOF ? FSDEM_ERR_IO : FSDEM_OK;
}

fsdem_result fsdem_csv_close(fsdem_csv *csv) {
    int bad;
    if (!csv || !csv->file) return FSDEM_ERR_INVALID_ARG;
    bad = fclose((FILE *)csv->file) != 0;
    csv->file = NULL;
    return bad ? FSDEM_ERR_IO : FSDEM_OK;
}

/* ---- >>io_vtk : the VTK XML writer core ----

   A writer opens the file (fsdem__vtk_open), starts the dataset (fsdem__vtk_polydata or
   fsdem__vtk_imagedata: the dataset element, FieldData TimeValue, <Piece>), writes sections of
   arrays in VTK's order (fsdem__vtk_section, fsdem__vtk_write, fsdem__vtk_section_end; PolyData:
   PointData, CellData, Points, Verts, Lines, Polys) and closes (fsdem__vtk_close: </Piece>, the
   appended data, </VTKFile>). An array is a description (fsdem__vtk_array), not a copy: its values
   are read through it when they are written, which for FSDEM_VTK_FORMAT_APPENDED is at the close, so the
   data it points to must live until then (the description itself is copied). Each value goes
   through a double, which holds every Float32, Float64, Int32 and UInt8 value exactly. Binary
   numbers are written in the machine's byte order, which the root element names. The rules of the
   three formats are those of fsdem_vtk_format (>>io). */

typedef enum fsdem__vtk_type {
    FSDEM__VTK_FLOAT32 = 0,
    FSDEM__VTK_FLOAT64 = 1,
    FSDEM__VTK_INT32 = 2,
    FSDEM__VTK_UINT8 = 3
} fsdem__vtk_type;

#ifdef FSDEM_USE_FLOAT
#define FSDEM__VTK_REAL FSDEM__VTK_FLOAT32
#else
#define FSDEM__VTK_REAL FSDEM__VTK_FLOAT64
#endif

/* Int32 values are written from an int and byte counts from an unsigned long long. */
typedef char fsdem__vtk_int_is_32_bits[sizeof(int) == 4 ? 1 : -1];
typedef char fsdem__vtk_ull_is_64_bits[sizeof(unsigned long long) == 8 ? 1 : -1];

/* Where an array's values come from. */
typedef enum fsdem__vtk_source {
    FSDEM__VTK_FROM_REALS = 0,  /* const fsdem_real[count] */
    FSDEM__VTK_FROM_VEC3S = 1,  /* const fsdem_vec3[count] (3 components) */
    FSDEM__VTK_FROM_INTS = 2,   /* const int[count] */
    FSDEM__VTK_FROM_BYTES = 3,  /* const unsigned char[count] */
    FSDEM__VTK_FROM_RAMP = 4,   /* first + step * index (Int32) */
    FSDEM__VTK_FROM_DOUBLE = 5, /* one const double, repeated */
    FSDEM__VTK_FROM_FN = 6      /* a callback per tuple */
} fsdem__vtk_source;

/* Tuple `index` of a computed array into out[0 .. components - 1]. */
typedef void (*fsdem__vtk_tuple_fn)(const void *user, long long index, double out[3]);

typedef struct fsdem__vtk_array {
    const char *name;
    fsdem__vtk_type type;
    int components; /* 1 or 3 */
    long long count; /* tuples */
    fsdem__vtk_source source;
    const void *data; /* the values, or the callback's user */
    fsdem__vtk_tuple_fn fn;
    long long first, step; /* FSDEM__VTK_FROM_RAMP */
} fsdem__vtk_array;

#define FSDEM__VTK_MAX_ARRAYS 24 /* arrays of one file (the most any writer has is 14) */

typedef struct fsdem__vtk_writer {
    FILE *fp;
    fsdem_vtk_format format;
    const char *type;      /* "PolyData" or "ImageData" */
    fsdem__status *status; /* the object's, for the message (may be NULL) */
    const char *who, *path;
    double time;           /* s, the TimeValue field */
    unsigned long long appended; /* FSDEM_VTK_FORMAT_APPENDED: bytes of the blocks announced so far */
    fsdem__vtk_array queue[FSDEM__VTK_MAX_ARRAYS]; /* FSDEM_VTK_FORMAT_APPENDED: the blocks to write */
    int queued;
} fsdem__vtk_writer;

static fsdem__vtk_array fsdem__vtk_from(const char *name, fsdem__vtk_type type, int components, long long count,
                                       fsdem__vtk_source source, const void *data) {
    fsdem__vtk_array a;
    memset(&a, 0, sizeof a);
    a.name = name;
    a.type = type;
    a.components = components;
    a.count = count;
    a.source = source;
    a.data = data;
    return a;
}
static fsdem__vtk_array fsdem__vtk_reals(const char *name, const fsdem_real *p, long long n) {
    return fsdem__vtk_from(name, FSDEM__VTK_REAL, 1, n, FSDEM__VTK_FROM_REALS, p);
}
static fsdem__vtk_array fsdem__vtk_vec3s(const char *name, const fsdem_vec3 *p, long long n) {
    return fsdem__vtk_from(name, FSDEM__VTK_REAL, 3, n, FSDEM__VTK_FROM_VEC3S, p);
}
static fsdem__vtk_array fsdem__vtk_ints(const char *name, const int *p, long long n) {
    return fsdem__vtk_from(name, FSDEM__VTK_INT32, 1, n, FSDEM__VTK_FROM_INTS, p);
}
static fsdem__vtk_array fsdem__vtk_bytes(const char *name, const unsigned char *p, long long n) {
    return fsdem__vtk_from(name, FSDEM__VTK_UINT8, 1, n, FSDEM__VTK_FROM_BYTES, p);
}
/* Int32 values first, first + step, ... (connectivity and offsets of regular cells). */
static fsdem__vtk_array fsdem__vtk_ramp(const char *name, long long n, long long first, long long step) {
    fsdem__vtk_array a = fsdem__vtk_from(name, FSDEM__VTK_INT32, 1, n, FSDEM__VTK_FROM_RAMP, NULL);
    a.first = first;
    a.step = step;
    return a;
}
static fsdem__vtk_array fsdem__vtk_computed(const char *name, fsdem__vtk_type type, int components, long long n,
                                           fsdem__vtk_tuple_fn fn, const void *user) {
    fsdem__vtk_array a = fsdem__vtk_from(name, type, components, n, FSDEM__VTK_FROM_FN, user);
    a.fn = fn;
    return a;
}

static const char *fsdem__vtk_type_name(fsdem__vtk_type t) {
    switch (t) {
    case FSDEM__VTK_FLOAT32: return "Float32";
    case FSDEM__VTK_FLOAT64: return "Float64";
    case FSDEM__VTK_INT32: return "Int32";
    default: return "UInt8";
    }
}

static size_t fsdem__vtk_type_size(fsdem__vtk_type t) {
    return t == FSDEM__VTK_FLOAT64 ? 8 : t == FSDEM__VTK_UINT8 ? 1 : 4;
}

static int fsdem__vtk_little_endian(void) {
    const unsigned int one = 1;
    unsigned char first;
    memcpy(&first, &one, 1);
    return first == 1;
}

static void fsdem__vtk_tuple(const fsdem__vtk_array *a, long long i, double v[3]) {
    switch (a->source) {
    case FSDEM__VTK_FROM_REALS: v[0] = (double)((const fsdem_real *)a->data)[i]; break;
    case FSDEM__VTK_FROM_VEC3S: {
        const fsdem_vec3 p = ((const fsdem_vec3 *)a->data)[i];
        v[0] = (double)p.x;
        v[1] = (double)p.y;
        v[2] = (double)p.z;
        break;
    }
    case FSDEM__VTK_FROM_INTS: v[0] = (double)((const int *)a->data)[i]; break;
    case FSDEM__VTK_FROM_BYTES: v[0] = (double)((const unsigned char *)a->data)[i]; break;
    case FSDEM__VTK_FROM_RAMP: v[0] = (double)(a->first + a->step * i); break;
    case FSDEM__VTK_FROM_DOUBLE: v[0] = *(const double *)a->data; break;
    default: a->fn(a->data, i, v); break;
    }
}

/* One value in the array's type, in the machine's byte order, into out; returns its size. */
static size_t fsdem__vtk_pack(fsdem__vtk_type t, double v, unsigned char *out) {
    switch (t) {
    case FSDEM__VTK_FLOAT32: {
        const float f = (float)v;
        memcpy(out, &f, 4);
        return 4;
    }
    case FSDEM__VTK_FLOAT64: memcpy(out, &v, 8); return 8;
    case FSDEM__VTK_INT32: {
        const int k = (int)v;
        memcpy(out, &k, 4);
        return 4;
    }
    default: out[0] = (unsigned char)v; return 1;
    }
}

/* Binary output: raw bytes (appended), or base64 (inline) kept as one stream across calls. */
typedef struct fsdem__vtk_sink {
    fsdem__vtk_writer *w;
    unsigned char pending[3];
    int npending;
    char text[4096];
    int ntext;
} fsdem__vtk_sink;

static void fsdem__vtk_sink_put(fsdem__vtk_sink *s, const unsigned char *p, size_t n) {
    static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    if (s->w->format == FSDEM_VTK_FORMAT_APPENDED) {
        fwrite(p, 1, n, s->w->fp);
        return;
    }
    while (n--) {
        s->pending[s->npending++] = *p++;
        if (s->npending < 3) continue;
        if (s->ntext + 4 > (int)sizeof s->text) {
            fwrite(s->text, 1, (size_t)s->ntext, s->w->fp);
            s->ntext = 0;
        }
        s->text[s->ntext++] = digits[s->pending[0] >> 2];
        s->text[s->ntext++] = digits[((s->pending[0] & 3) << 4) | (s->pending[1] >> 4)];
        s->text[s->ntext++] = digits[((s->pending[1] & 15) << 2) | (s->pending[2] >> 6)];
        s->text[s->ntext++] = digits[s->pending[2] & 63];
        s->npending = 0;
    }
}

/* Ends a base64 stream: the last one or two bytes with '=' padding. */
static void fsdem__vtk_sink_end(fsdem__vtk_sink *s) {
    static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    if (s->w->format == FSDEM_VTK_FORMAT_APPENDED) return;
    if (s->npending) {
        const unsigned char b0 = s->pending[0], b1 = s->npending > 1 ? s->pending[1] : 0;
        char quad[4];
        quad[0] = digits[b0 >> 2];
        quad[1] = digits[((b0 & 3) << 4) | (b1 >> 4)];
        quad[2] = s->npending > 1 ? digits[(b1 & 15) << 2] : '=';
        quad[3] = '=';
        fwrite(s->text, 1, (size_t)s->ntext, s->w->fp);
        s->ntext = 0;
        fwrite(quad, 1, 4, s->w->fp);
        s->npending = 0;
    }
    fwrite(s->text, 1, (size_t)s->ntext, s->w->fp);
    s->ntext = 0;
}

static unsigned long long fsdem__vtk_bytes_of(const fsdem__vtk_array *a) {
    return (unsigned long long)a->count * (unsigned long long)a->components * fsdem__vtk_type_size(a->type);
}

/* The values of an array in the writer's format: text, or the byte count and the data in binary. */
static void fsdem__vtk_values(fsdem__vtk_writer *w, const fsdem__vtk_array *a) {
    long long i;
    int c;
    double v[3];
    if (w->format == FSDEM_VTK_FORMAT_ASCII) {
        for (i = 0; i < a->count; ++i) {
            fsdem__vtk_tuple(a, i, v);
            for (c = 0; c < a->components; ++c) {
                const char sep = c + 1 < a->components ? ' ' : '\n';
                switch (a->type) {
                case FSDEM__VTK_FLOAT32: fprintf(w->fp, "%.9g%c", (double)(float)v[c], sep); break;
                case FSDEM__VTK_FLOAT64: fprintf(w->fp, "%.17g%c", v[c], sep); break;
                case FSDEM__VTK_INT32: fprintf(w->fp, "%d%c", (int)v[c], sep); break;
                default: fprintf(w->fp, "%u%c", (unsigned)(unsigned char)v[c], sep); break;
                }
            }
        }
    } else {
        /* whole tuples of up to 3 x 8 bytes fill the buffer; flushed at 3072 - 24 */
        unsigned char buf[3072];
        const unsigned long long bytes = fsdem__vtk_bytes_of(a);
        fsdem__vtk_sink sink;
        size_t used;
        sink.w = w;
        sink.npending = sink.ntext = 0;
        memcpy(buf, &bytes, 8);
        used = 8;
        for (i = 0; i < a->count; ++i) {
            if (used + 24 > sizeof buf) {
                fsdem__vtk_sink_put(&sink, buf, used);
                used = 0;
            }
            fsdem__vtk_tuple(a, i, v);
            for (c = 0; c < a->components; ++c) used += fsdem__vtk_pack(a->type, v[c], buf + used);
        }
        fsdem__vtk_sink_put(&sink, buf, used);
        fsdem__vtk_sink_end(&sink);
    }
}

/* A <DataArray>: inline with its values (ascii, base64), or announced with its offset and queued for
   the appended data. `field`: a FieldData array, which also names its number of tuples. */
static void fsdem__vtk_write_array(fsdem__vtk_writer *w, fsdem__vtk_array a, int field) {
    static const char *const formats[3] = {"ascii", "binary", "appended"};
    fprintf(w->fp, "<DataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%d\" format=\"%s\"", fsdem__vtk_type_name(a.type),
            a.name, a.components, formats[w->format]);
    if (field) fprintf(w->fp, " NumberOfTuples=\"%lld\"", a.count);
    if (w->format == FSDEM_VTK_FORMAT_APPENDED) {
        FSDEM_ASSERT(w->queued < FSDEM__VTK_MAX_ARRAYS);
        fprintf(w->fp, " offset=\"%llu\"/>\n", w->appended);
        w->queue[w->queued++] = a;
        w->appended += 8 + fsdem__vtk_bytes_of(&a);
        return;
    }
    fputs(">\n", w->fp);
    fsdem__vtk_values(w, &a);
    fputs(w->format == FSDEM_VTK_FORMAT_BASE64 ? "\n</DataArray>\n" : "</DataArray>\n", w->fp);
}

static void fsdem__vtk_write(fsdem__vtk_writer *w, fsdem__vtk_array a) { fsdem__vtk_write_array(w, a, 0); }

/* Checks the arguments every writer shares; the message goes to `status` (may be NULL). */
static fsdem_result fsdem__vtk_check(fsdem__status *status, const char *who, const char *path, fsdem_vtk_format format) {
    fsdem__status scratch;
    fsdem__status *st = status ? status : &scratch;
    if (!status) scratch.log = NULL;
    if (!path) return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: path is NULL", who);
    if ((int)format < (int)FSDEM_VTK_FORMAT_ASCII || (int)format > (int)FSDEM_VTK_FORMAT_APPENDED)
        return fsdem__fail(st, FSDEM_ERR_INVALID_ARG, "%s: format %d is not a fsdem_vtk_format", who, (int)format);
    return FSDEM_OK;
}

/* Checks the arguments, creates the file and writes the root element of a dataset `type`. */
static fsdem_result fsdem__vtk_open(fsdem__vtk_writer *w, fsdem__status *status, const char *who, const char *path,
                                    fsdem_vtk_format format, const char *type) {
    fsdem_result res = fsdem__vtk_check(status, who, path, format);
    memset(w, 0, sizeof *w);
    if (res != FSDEM_OK) return res;
    w->format = format;
    w->type = type;
    w->status = status;
    w->who = who;
    w->path = path;
    w->fp = fopen(path, "wb");
    if (!w->fp) {
        if (status) fsdem__fail(status, FSDEM_ERR_IO, "%s: cannot open '%s' for writing", who, path);
        return FSDEM_ERR_IO;
    }
    fprintf(w->fp, "<?xml version=\"1.0\"?>\n<VTKFile type=\"%s\" version=\"1.0\" byte_order=\"%s\" header_type=\"UInt64\">\n",
            type, fsdem__vtk_little_endian() ? "LittleEndian" : "BigEndian");
    return FSDEM_OK;
}

/* The FieldData of the dataset: TimeValue (s). */
static void fsdem__vtk_time(fsdem__vtk_writer *w, double time) {
    w->time = time;
    fputs("<FieldData>\n", w->fp);
    fsdem__vtk_write_array(w, fsdem__vtk_from("TimeValue", FSDEM__VTK_FLOAT64, 1, 1, FSDEM__VTK_FROM_DOUBLE, &w->time), 1);
    fputs("</FieldData>\n", w->fp);
}

/* <PolyData>, the time, and the piece's counts (strips are never written). */
static void fsdem__vtk_polydata(fsdem__vtk_writer *w, double time, long long points, long long verts, long long lines,
                                long long polys) {
    fputs("<PolyData>\n", w->fp);
    fsdem__vtk_time(w, time);
    fprintf(w->fp,
            "<Piece NumberOfPoints=\"%lld\" NumberOfVerts=\"%lld\" NumberOfLines=\"%lld\" NumberOfStrips=\"0\" "
            "NumberOfPolys=\"%lld\">\n",
            points, verts, lines, polys);
}

/* <ImageData> of cells[0] x cells[1] x cells[2] cells (0 for a flat axis: one layer of points), the
   time, and the piece, which is the whole extent. */
static void fsdem__vtk_imagedata(fsdem__vtk_writer *w, double time, const int cells[3], const double origin[3],
                                 const double spacing[3]) {
    fprintf(w->fp, "<ImageData WholeExtent=\"0 %d 0 %d 0 %d\" Origin=\"%.17g %.17g %.17g\" Spacing=\"%.17g %.17g %.17g\">\n",
            cells[0], cells[1], cells[2], origin[0], origin[1], origin[2], spacing[0], spacing[1], spacing[2]);
    fsdem__vtk_time(w, time);
    fprintf(w->fp, "<Piece Extent=\"0 %d 0 %d 0 %d\">\n", cells[0], cells[1], cells[2]);
}

/* Opens a section (PointData, CellData, Points, Verts, Lines, Polys) with its active scalars and
   vectors (may be NULL). */
static void fsdem__vtk_section(fsdem__vtk_writer *w, const char *tag, const char *scalars, const char *vectors) {
    fprintf(w->fp, "<%s", tag);
    if (scalars) fprintf(w->fp, " Scalars=\"%s\"", scalars);
    if (vectors) fprintf(w->fp, " Vectors=\"%s\"", vectors);
    fputs(">\n", w->fp);
}

static void fsdem__vtk_section_end(fsdem__vtk_writer *w, const char *tag) { fprintf(w->fp, "</%s>\n", tag); }

/* A cell section (Verts, Lines, Polys) from its connectivity and offsets (Int32). */
static void fsdem__vtk_cells(fsdem__vtk_writer *w, const char *tag, fsdem__vtk_array connectivity, fsdem__vtk_array offsets) {
    fsdem__vtk_section(w, tag, NULL, NULL);
    fsdem__vtk_write(w, connectivity);
    fsdem__vtk_write(w, offsets);
    fsdem__vtk_section_end(w, tag);
}

/* Closes the piece and the dataset, writes the appended data and closes the file. The object's
   message names the path on failure, and is cleared on success. */
static fsdem_result fsdem__vtk_close(fsdem__vtk_writer *w) {
    int k, bad;
    fprintf(w->fp, "</Piece>\n</%s>\n", w->type);
    if (w->format == FSDEM_VTK_FORMAT_APPENDED) {
        fputs("<AppendedData encoding=\"raw\">\n_", w->fp);
        for (k = 0; k < w->queued; ++k) fsdem__vtk_values(w, &w->queue[k]);
        fputs("\n</AppendedData>\n", w->fp);
    }
    fputs("</VTKFile>\n", w->fp);
    bad = ferror(w->fp) != 0;
    bad |= fclose(w->fp) != 0;
    w->fp = NULL;
    if (bad) return w->status ? fsdem__fail(w->status, FSDEM_ERR_IO, "%s: write error on '%s'", w->who, w->path) : FSDEM_ERR_IO;
    return w->status ? fsdem__ok(w->status) : FSDEM_OK;
}

/* A particle snapshot (PolyData, one point and one vertex per particle), in two halves around its
   point data: the file, its header and the opening of <PointData> with the active arrays; then
   the closing of <PointData>, the points and the vertices, and the file closed. */
static fsdem_result fsdem__vtk_particles_begin(fsdem__vtk_writer *w, const fsdem__status *status, const char *who, const char *path,
                                               fsdem_vtk_format format, double time, long long n, const char *scalars,
                                               const char *vectors) {
    const fsdem_result res = fsdem__vtk_open(w, (fsdem__status *)status, who, path, format, "PolyData");
    if (res != FSDEM_OK) return res;
    fsdem__vtk_polydata(w, time, n, n, 0, 0);
    fsdem__vtk_section(w, "PointData", scalars, vectors);
    return FSDEM_OK;
}

static fsdem_result fsdem__vtk_particles_end(fsdem__vtk_writer *w, const fsdem_vec3 *points, long long n) {
    fsdem__vtk_section_end(w, "PointData");
    fsdem__vtk_section(w, "Points", NULL, NULL);
    fsdem__vtk_write(w, fsdem__vtk_vec3s("Points", points, n));
    fsdem__vtk_section_end(w, "Points");
    fsdem__vtk_cells(w, "Verts", fsdem__vtk_ramp("connectivity", n, 0, 1), fsdem__vtk_ramp("offsets", n, 1, 1));
    return fsdem__vtk_close(w);
}

/* ---- >>io_pvd : ParaView series ---- */

/* The closing tags, at the current position. */
static fsdem_result fsdem__io_pvd_finish(FILE *fp) {
    fputs("</Collection>\n</VTKFile>\n", fp);
    fflush(fp);
    return ferror(fp) ? FSDEM_ERR_IO : FSDEM_OK;
}

fsdem_result fsdem_pvd_open(fsdem_pvd *pvd, const char *path) {
    FILE *fp;
    long tail;
    if (!pvd || !path) return FSDEM_ERR_INVALID_ARG;
    pvd->file = NULL;
    pvd->tail = 0;
    pvd->count = 0;
    fp = fopen(path, "w");
    if (!fp) return FSDEM_ERR_IO;
    fputs("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n", fp);
    tail = ftell(fp);
    if (tail < 0 || fsdem__io_pvd_finish(fp) != FSDEM_OK) {
        fclose(fp);
        return FSDEM_ERR_IO;
    }
    pvd->file = fp;
    pvd->tail = tail;
    return FSDEM_OK;
}

/* A piece the series reader can take: a serial VTK XML file by its extension, no control character. */
static int fsdem__io_pvd_piece_ok(const char *file) {
    static const char *const ext[5] = {".vtp", ".vtu", ".vti", ".vts", ".vtr"};
    const char *c;
    size_t n = strlen(file);
    int k;
    for (c = file; *c; ++c)
        if ((unsigned char)*c < 0x20 || *c == 0x7f) return 0;
    for (k = 0; k < 5; ++k)
        if (n > 4 && strcmp(file + n - 4, ext[k]) == 0) return 1;
    return 0;
}

fsdem_result fsdem_pvd_add(fsdem_pvd *pvd, double time, const char *file) {
    FILE *fp;
    const char *c;
    long tail;
    if (!pvd || !pvd->file || !file || !(time == time && time - time == 0) || !fsdem__io_pvd_piece_ok(file))
        return FSDEM_ERR_INVALID_ARG;
    fp = (FILE *)pvd->file;
    if (fseek(fp, pvd->tail, SEEK_SET) != 0) return FSDEM_ERR_IO;
    fprintf(fp, "<DataSet timestep=\"%.17g\" part=\"0\" file=\"", time);
    for (c = file; *c; ++c) switch (*c) {
        case '&': fputs("&amp;", fp); break;
        case '<': fputs("&lt;", fp); break;
        case '>': fputs("&gt;", fp); break;
        case '"': fputs("&quot;", fp); break;
        case '\'': fputs("&apos;", fp); break;
        default: fputc(*c, fp); break;
        }
    fputs("\"/>\n", fp);
    tail = ftell(fp);
    if (tail < 0 || fsdem__io_pvd_finish(fp) != FSDEM_OK) return FSDEM_ERR_IO;
    pvd->tail = tail;
    pvd->count++;
    return FSDEM_OK;
}

fsdem_result fsdem_pvd_close(fsdem_pvd *pvd) {
    FILE *fp;
    int bad;
    if (!pvd || !pvd->file) return FSDEM_ERR_INVALID_ARG;
    fp = (FILE *)pvd->file;
    /* the tags are there already; written again in case an add failed part way */
    bad = fseek(fp, pvd->tail, SEEK_SET) != 0 || fsdem__io_pvd_finish(fp) != FSDEM_OK;
    bad |= fclose(fp) != 0;
    pvd->file = NULL;
    return bad ? FSDEM_ERR_IO : FSDEM_OK;
}

/* ---- >>io_dem : particles, walls, contacts ---- */

fsdem_result fsdem_dem_write_csv(const fsdem_dem *d, const char *path) {
    FILE *fp;
    int i, bad;
    if (!d || !path) return FSDEM_ERR_INVALID_ARG;
    if (!(fp = fopen(path, "w"))) return FSDEM_ERR_IO;
    fprintf(fp, "id,x,y,z,vx,vy,vz,wx,wy,wz,radius,material\n");
    for (i = 0; i < d->n; ++i)
        fprintf(fp, "%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%d\n", d->id[i], (double)d->x[i].x,
                (double)d->x[i].y, (double)d->x[i].z, (double)d->v[i].x, (double)d->v[i].y, (double)d->v[i].z,
                (double)d->w[i].x, (double)d->w[i].y, (double)d->w[i].z, (double)d->r[i], d->material[i]);
    bad = ferror(fp);
    return (fclose(fp) != 0 || bad) ? FSDEM_ERR_IO : FSDEM_OK;
}

fsdem_result fsdem_dem_write_vtp(const fsdem_dem *d, const char *path, fsdem_vtk_format format) {
    fsdem__vtk_writer w;
    fsdem_result res;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    res = fsdem__vtk_particles_begin(&w, &d->status, "fsdem_dem_write_vtp", path, format, d->time, d->n, "radius", "velocity");
    if (res != FSDEM_OK) return res;
    fsdem__vtk_write(&w, fsdem__vtk_ints("id", d->id, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_reals("radius", d->r, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_reals("mass", d->m, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_ints("material", d->material, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_bytes("fixed", d->fixed, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_vec3s("velocity", d->v, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_vec3s("angular_velocity", d->w, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_vec3s("force", d->f, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_vec3s("torque", d->t, d->n));
    fsdem__vtk_write(&w, fsdem__vtk_vec3s("external_force", d->fext, d->n));
    return fsdem__vtk_particles_end(&w, d->x, d->n);
}

/* Wall geometry for the writer: points, cells (connectivity, offsets) and per-cell wall data, the
   line cells (two points) first and then the polygons, as VTK orders PolyData cells. Points are not
   shared, so the connectivity of point k is k; offsets count from the start of their section. */
typedef struct fsdem__io_walls {
    fsdem_vec3 *points;
    int *connectivity, *offsets, *wall_id;
    unsigned char *type;
    fsdem_vec3 *force;
    int points_count, cells_count;
    int lines;                     /* the pass: 1 takes line cells, 0 polygons */
    int section_start;             /* points before the current section */
    int line_cells, line_points;   /* the line section, after the build */
} fsdem__io_walls;

#define FSDEM__IO_WALL_POINTS 24 /* the most points of one wall: a 3D box's six faces of four */
#define FSDEM__IO_WALL_CELLS 6

static void fsdem__io_walls_cell(fsdem__io_walls *g, const fsdem_vec3 *v, int n, int id, const fsdem__dem_wall *w) {
    int k;
    if ((n == 2) != g->lines) return; /* the other pass's */
    for (k = 0; k < n; ++k) {
        g->connectivity[g->points_count] = g->points_count;
        g->points[g->points_count++] = v[k];
    }
    g->offsets[g->cells_count] = g->points_count - g->section_start;
    g->wall_id[g->cells_count] = id;
    g->type[g->cells_count] = (unsigned char)w->d.type;
    g->force[g->cells_count++] = w->force;
}

/* Keeps the part of a convex polygon where sign (x_axis - bound) >= 0 (Sutherland-Hodgman). */
static int fsdem__io_clip(const fsdem_vec3 *in, int n, fsdem_vec3 *out, int axis, fsdem_real bound, fsdem_real sign) {
    int k, m = 0;
    for (k = 0; k < n; ++k) {
        const fsdem_vec3 cur = in[k], prev = in[(k + n - 1) % n];
        const fsdem_real dc = sign * (fsdem__comp(cur, axis) - bound), dp = sign * (fsdem__comp(prev, axis) - bound);
        if ((dc >= 0) != (dp >= 0)) {
            fsdem_vec3 q = fsdem__madd(prev, fsdem__sub(cur, prev), dp / (dp - dc));
            if (axis == 0) q.x = bound;
            else if (axis == 1) q.y = bound;
            else q.z = bound;
            out[m++] = q;
        }
        if (dc >= 0) out[m++] = cur;
    }
    return m;
}

/* A plane (through p, unit normal n) drawn inside the box [lo, hi]: in 3D the convex polygon where
   they meet, ordered counter-clockwise about n (up to 10 vertices), in 2D the chord of the line
   through the rectangle (2 vertices, z = 0). Returns the number of vertices; fewer than 3 in 3D or
   2 in 2D: the plane misses the box. */
static int fsdem__io_plane_patch(fsdem_vec3 p, fsdem_vec3 n, fsdem_vec3 lo, fsdem_vec3 hi, int dim, fsdem_vec3 *out) {
    const fsdem_vec3 mid = fsdem__scale(fsdem__add(lo, hi), (fsdem_real)0.5);
    const fsdem_vec3 c = fsdem__madd(mid, n, -fsdem__dot(fsdem__sub(mid, p), n)); /* mid projected on the plane */
    fsdem_vec3 diag = fsdem__sub(hi, lo);
    fsdem_real half;
    int axis, count;
    if (dim == 2) diag.z = 0;
    half = fsdem__norm(diag); /* every point of the box projects within half of c */
    if (dim == 2) {
        const fsdem_vec3 t = fsdem_v3(-n.y, n.x, 0);
        fsdem_real t0 = -half, t1 = half;
        for (axis = 0; axis < 2; ++axis) {
            const fsdem_real ta = fsdem__comp(t, axis), ca = fsdem__comp(c, axis);
            const fsdem_real la = fsdem__comp(lo, axis), ha = fsdem__comp(hi, axis);
            if (ta == 0) {
                if (ca < la || ca > ha) return 0;
            } else {
                fsdem_real a = (la - ca) / ta, b = (ha - ca) / ta;
                if (a > b) {
                    const fsdem_real s = a;
                    a = b;
                    b = s;
                }
                if (a > t0) t0 = a;
                if (b < t1) t1 = b;
            }
        }
        if (!(t0 < t1)) return 0;
        out[0] = fsdem__madd(c, t, t0);
        out[1] = fsdem__madd(c, t, t1);
        out[0].z = out[1].z = 0;
        return 2;
    } else {
        /* u, v = n x u: an orthonormal basis of the plane with u x v = n */
        const fsdem_real ax = n.x < 0 ? -n.x : n.x, ay = n.y < 0 ? -n.y : n.y, az = n.z < 0 ? -n.z : n.z;
        const fsdem_vec3 e = ax <= ay && ax <= az ? fsdem_v3(1, 0, 0) : ay <= az ? fsdem_v3(0, 1, 0) : fsdem_v3(0, 0, 1);
        fsdem_vec3 u = fsdem__cross(e, n), v, a[12], b[12];
        u = fsdem__scale(u, half / fsdem__norm(u));
        v = fsdem__cross(n, u);
        a[0] = fsdem__sub(fsdem__sub(c, u), v);
        a[1] = fsdem__sub(fsdem__add(c, u), v);
        a[2] = fsdem__add(fsdem__add(c, u), v);
        a[3] = fsdem__add(fsdem__sub(c, u), v);
        count = 4;
        for (axis = 0; axis < 3 && count >= 3; ++axis) {
            count = fsdem__io_clip(a, count, b, axis, fsdem__comp(lo, axis), 1);
            count = fsdem__io_clip(b, count, a, axis, fsdem__comp(hi, axis), -1);
        }
        if (count < 3) return 0;
        memcpy(out, a, sizeof *a * (size_t)count);
        return count;
    }
}

/* The cells of the drawable walls of the pass g->lines into g (room for FSDEM__IO_WALL_POINTS points
   and FSDEM__IO_WALL_CELLS cells per wall). */
static void fsdem__io_walls_pass(const fsdem_dem *d, fsdem__io_walls *g) {
    /* a 3D box's faces as corners (bit 0: x at hi, bit 1: y, bit 2: z), counter-clockwise seen from outside */
    static const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    const int dim = d->desc.dim;
    int id, f, k;
    for (id = 0; id < d->wall_count; ++id) {
        const fsdem__dem_wall *w = &d->walls[id];
        const fsdem_dem_wall_desc *gd = &w->d;
        fsdem_vec3 v[12];
        if (!w->active) continue;
        switch (gd->type) {
        case FSDEM_DEM_WALL_TYPE_PLANE:
            k = fsdem__io_plane_patch(gd->a, gd->b, d->desc.domain_min, d->desc.domain_max, dim, v);
            if (k >= (dim == 2 ? 2 : 3)) fsdem__io_walls_cell(g, v, k, id, w);
            break;
        case FSDEM_DEM_WALL_TYPE_BOX_INSIDE:
        case FSDEM_DEM_WALL_TYPE_BOX_OUTSIDE:
            if (dim == 2) {
                const fsdem_vec3 r[4] = {fsdem_v3(gd->a.x, gd->a.y, 0), fsdem_v3(gd->b.x, gd->a.y, 0), fsdem_v3(gd->b.x, gd->b.y, 0),
                                         fsdem_v3(gd->a.x, gd->b.y, 0)};
                for (f = 0; f < 4; ++f) {
                    v[0] = r[f];
                    v[1] = r[(f + 1) % 4];
                    fsdem__io_walls_cell(g, v, 2, id, w);
                }
            } else
                for (f = 0; f < 6; ++f) {
                    for (k = 0; k < 4; ++k) {
                        /* an inside box holds the particles: its faces face inwards */
                        const int corner = faces[f][gd->type == FSDEM_DEM_WALL_TYPE_BOX_INSIDE ? 3 - k : k];
                        v[k] = fsdem_v3(corner & 1 ? gd->b.x : gd->a.x, corner & 2 ? gd->b.y : gd->a.y, corner & 4 ? gd->b.z : gd->a.z);
                    }
                    fsdem__io_walls_cell(g, v, 4, id, w);
                }
            break;
        case FSDEM_DEM_WALL_TYPE_SEGMENT:
            v[0] = gd->a;
            v[1] = gd->b;
            fsdem__io_walls_cell(g, v, 2, id, w);
            break;
        case FSDEM_DEM_WALL_TYPE_TRIANGLE:
            v[0] = gd->a;
            v[1] = gd->b;
            v[2] = gd->c;
            fsdem__io_walls_cell(g, v, 3, id, w);
            break;
        default: break; /* SDF: known only through its callback */
        }
    }
}

/* Every drawable wall: the line cells (2D walls, segments), then the polygons (3D walls). */
static void fsdem__io_walls_build(const fsdem_dem *d, fsdem__io_walls *g) {
    g->points_count = g->cells_count = g->section_start = 0;
    g->lines = 1;
    fsdem__io_walls_pass(d, g);
    g->line_cells = g->cells_count;
    g->line_points = g->section_start = g->points_count;
    g->lines = 0;
    fsdem__io_walls_pass(d, g);
}

fsdem_result fsdem_dem_write_walls_vtp(const fsdem_dem *d, const char *path, fsdem_vtk_format format) {
    static const char *const who = "fsdem_dem_write_walls_vtp";
    const size_t walls = d && d->wall_count > 0 ? (size_t)d->wall_count : 1; /* no allocation of 0 bytes */
    const size_t np = FSDEM__IO_WALL_POINTS * walls, nc = FSDEM__IO_WALL_CELLS * walls;
    fsdem__status *st;
    fsdem__io_walls g;
    fsdem__vtk_writer w;
    fsdem_result res;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    st = (fsdem__status *)&d->status; /* the message is the object's only mutable part here */
    res = fsdem__vtk_check(st, who, path, format);
    if (res != FSDEM_OK) return res;
    g.points = (fsdem_vec3 *)fsdem__alloc(&d->allocator, sizeof(fsdem_vec3) * np);
    g.connectivity = (int *)fsdem__alloc(&d->allocator, sizeof(int) * np);
    g.offsets = (int *)fsdem__alloc(&d->allocator, sizeof(int) * nc);
    g.wall_id = (int *)fsdem__alloc(&d->allocator, sizeof(int) * nc);
    g.type = (unsigned char *)fsdem__alloc(&d->allocator, nc);
    g.force = (fsdem_vec3 *)fsdem__alloc(&d->allocator, sizeof(fsdem_vec3) * nc);
    if (!g.points || !g.connectivity || !g.offsets || !g.wall_id || !g.type || !g.force)
        res = fsdem__fail(st, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory (%d walls)", who, d->wall_count);
    else {
        fsdem__io_walls_build(d, &g);
        res = fsdem__vtk_open(&w, st, who, path, format, "PolyData");
        if (res == FSDEM_OK) {
            const int polys = g.cells_count - g.line_cells;
            fsdem__vtk_polydata(&w, d->time, g.points_count, 0, g.line_cells, polys);
            fsdem__vtk_section(&w, "CellData", "wall_id", "force");
            fsdem__vtk_write(&w, fsdem__vtk_ints("wall_id", g.wall_id, g.cells_count));
            fsdem__vtk_write(&w, fsdem__vtk_bytes("type", g.type, g.cells_count));
            fsdem__vtk_write(&w, fsdem__vtk_vec3s("force", g.force, g.cells_count));
            fsdem__vtk_section_end(&w, "CellData");
            fsdem__vtk_section(&w, "Points", NULL, NULL);
            fsdem__vtk_write(&w, fsdem__vtk_vec3s("Points", g.points, g.points_count));
            fsdem__vtk_section_end(&w, "Points");
            if (g.line_cells)
                fsdem__vtk_cells(&w, "Lines", fsdem__vtk_ints("connectivity", g.connectivity, g.line_points),
                                 fsdem__vtk_ints("offsets", g.offsets, g.line_cells));
            if (polys)
                fsdem__vtk_cells(&w, "Polys", fsdem__vtk_ints("connectivity", g.connectivity + g.line_points, g.points_count - g.line_points),
                                 fsdem__vtk_ints("offsets", g.offsets + g.line_cells, polys));
            res = fsdem__vtk_close(&w);
        }
    }
    fsdem__free(&d->allocator, g.points, sizeof(fsdem_vec3) * np);
    fsdem__free(&d->allocator, g.connectivity, sizeof(int) * np);
    fsdem__free(&d->allocator, g.offsets, sizeof(int) * nc);
    fsdem__free(&d->allocator, g.wall_id, sizeof(int) * nc);
    fsdem__free(&d->allocator, g.type, nc);
    fsdem__free(&d->allocator, g.force, sizeof(fsdem_vec3) * nc);
    return res;
}

/* Contacts for the writer: two points and the cell data of each. */
typedef struct fsdem__io_contacts {
    fsdem_vec3 *points; /* 2 per contact */
    fsdem_vec3 *force;
    fsdem_real *normal_force, *overlap;
    int *particle, *partner;
    int count;
} fsdem__io_contacts;

/* The contact law on a filled batch, as fsdem__dem_drain runs it, with the law chosen at run time
   (one more instantiation of the kernel; the step's are per law). */
static void fsdem__io_dem_batch_law(fsdem__dem_batch *b, fsdem_dem_law law, fsdem_real h, int pairs, fsdem_real off,
                                    const fsdem__dem_pair *uniform, const fsdem__dem_rules *rules) {
    fsdem__dem_batch_law(b, law, h, pairs, off, uniform, rules);
}

/* Runs the law on a batch of particle pairs or (`walls`) wall contacts and appends its contacts to
   c, leaving the object as it is (nothing is scattered, no spring is committed); empties the batch. */
static void fsdem__io_dem_drain(const fsdem_dem *d, fsdem__dem_batch *batch, int walls, fsdem_real h, fsdem__io_contacts *c) {
    const fsdem__dem_pair *uniform = d->material_count == 1 ? d->pairs : NULL;
    const fsdem__dem_batch *b = batch; /* read only after the law */
    const fsdem_real off = d->desc.contact_offset;
    const fsdem__dem_rules rules = fsdem__dem_rules_of(d);
    int k;
    fsdem__dem_batch_pad(batch, !walls, uniform != NULL);
    fsdem__io_dem_batch_law(batch, fsdem__dem_kernel_law(d), h, !walls, walls ? 0 : off, uniform, &rules);
    for (k = 0; k < b->count; ++k) {
        const int i = b->i[k], e = c->count++;
        c->points[2 * e] = d->x[i];
        if (walls) {
            /* the wall's closest point: r_i + offset - overlap from the centre, along -n */
            const fsdem_vec3 n = fsdem__dem_batch_vec(b->n, k);
            c->points[2 * e + 1] = fsdem__madd(d->x[i], n, -(d->r[i] + off - b->delta[k]));
            c->partner[e] = -1 - b->other[k];
        } else {
            c->points[2 * e + 1] = fsdem__dem_image_of(d, i, b->other[k]); /* across a periodic seam: its image */
            c->partner[e] = d->id[b->other[k]];
        }
        c->force[e] = fsdem__dem_batch_vec(b->force, k);
        c->normal_force[e] = b->fn[k];
        c->overlap[e] = b->delta[k];
        c->particle[e] = d->id[i];
    }
    batch->count = 0;
}

/* The contacts of the last force evaluation with their forces (fsdem_dem_write_contacts_vtp), into c
   (NULL: only counted); `hits` has room for the longest row of the particle-wall list. Returns
   their number. */
static int fsdem__io_dem_contacts(const fsdem_dem *d, fsdem__dem_batch *b, fsdem__dem_wall_hit *hits, fsdem__io_contacts *c) {
    const fsdem_real off = d->desc.contact_offset;
    /* springs with history: as committed, not advanced again; seed 000's linear law: its one-step spring */
    const fsdem_real h = fsdem__dem_kernel_law(d) == FSDEM_DEM_LAW_LINEAR ? d->dt : 0;
    const int uniform = d->material_count == 1;
    int i, k, nh, count = 0;
    if (c) {
        c->count = 0;
        b->count = 0;
    }
    /* touching pairs, as fsdem__dem_touching finds them */
    for (k = 0; k < d->pp.count; ++k) {
        const int key = d->pp.key[k];
        const int p = d->pp.first[k], q = FSDEM__DEM_PARTNER(key);
        const fsdem_vec3 e = fsdem__dem_min_image(d, fsdem__sub(d->x[p], d->x[q]));
        const fsdem_real ex = e.x, ey = e.y, ez = e.z;
        const fsdem_real reach = d->r[p] + d->r[q] + off;
        if (!(ex * ex + ey * ey + ez * ez < reach * reach)) continue;
        count++;
        if (!c) continue;
        fsdem__dem_gather_pair(d, b, b->count++, k, fsdem__dem_kernel_law(d), uniform);
        if (b->count == FSDEM__DEM_BATCH) fsdem__io_dem_drain(d, b, 0, h, c);
    }
    if (c && b->count) fsdem__io_dem_drain(d, b, 0, h, c);
    /* wall contacts of the free particles, as fsdem__dem_compute_forces_law finds them */
    for (i = 0; i < d->n; ++i) {
        if (d->inv_m[i] == 0 || d->pw.start[i] == d->pw.start[i + 1]) continue;
        nh = fsdem__dem_wall_hits_into(d, i, hits, NULL);
        count += nh;
        if (!c) continue;
        for (k = 0; k < nh; ++k) {
            fsdem__dem_gather_wall(d, b, b->count++, i, &hits[k], uniform);
            if (b->count == FSDEM__DEM_BATCH) fsdem__io_dem_drain(d, b, 1, h, c);
        }
    }
    if (c && b->count) fsdem__io_dem_drain(d, b, 1, h, c);
    return count;
}

fsdem_result fsdem_dem_write_contacts_vtp(const fsdem_dem *d, const char *path, fsdem_vtk_format format) {
    static const char *const who = "fsdem_dem_write_contacts_vtp";
    fsdem__status *st;
    fsdem__vtk_writer w;
    fsdem__io_contacts c;
    fsdem__dem_batch *b = NULL;
    fsdem__dem_wall_hit *hits = NULL;
    size_t row_max = 1, n = 1; /* room for the longest wall row and the contacts (no allocation of 0 bytes) */
    fsdem_result res;
    int i;
    if (!d) return FSDEM_ERR_INVALID_ARG;
    st = (fsdem__status *)&d->status; /* the message is the object's only mutable part here */
    res = fsdem__vtk_check(st, who, path, format);
    if (res != FSDEM_OK) return res;
    memset(&c, 0, sizeof c);
    /* the lists describe the particles of the last step unless they were edited since */
    if (!d->need_rebuild && d->pp.rows == d->n && d->pw.rows == d->n && d->n > 0) {
        for (i = 0; i < d->n; ++i)
            if ((size_t)(d->pw.start[i + 1] - d->pw.start[i]) > row_max) row_max = (size_t)(d->pw.start[i + 1] - d->pw.start[i]);
        b = (fsdem__dem_batch *)fsdem__alloc(&d->allocator, sizeof *b);
        hits = (fsdem__dem_wall_hit *)fsdem__alloc(&d->allocator, sizeof *hits * row_max);
        if (b && hits) {
            n = (size_t)fsdem__io_dem_contacts(d, b, hits, NULL);
            if (n == 0) n = 1;
            c.points = (fsdem_vec3 *)fsdem__alloc(&d->allocator, sizeof(fsdem_vec3) * 2 * n);
            c.force = (fsdem_vec3 *)fsdem__alloc(&d->allocator, sizeof(fsdem_vec3) * n);
            c.normal_force = (fsdem_real *)fsdem__alloc(&d->allocator, sizeof(fsdem_real) * n);
            c.overlap = (fsdem_real *)fsdem__alloc(&d->allocator, sizeof(fsdem_real) * n);
            c.particle = (int *)fsdem__alloc(&d->allocator, sizeof(int) * n);
            c.partner = (int *)fsdem__alloc(&d->allocator, sizeof(int) * n);
        }
        if (!b || !hits || !c.points || !c.force || !c.normal_force || !c.overlap || !c.particle || !c.partner)
            res = fsdem__fail(st, FSDEM_ERR_OUT_OF_MEMORY, "%s: out of memory (%lu contacts)", who, (unsigned long)n);
        else
            fsdem__io_dem_contacts(d, b, hits, &c);
    }
    if (res == FSDEM_OK) res = fsdem__vtk_open(&w, st, who, path, format, "PolyData");
    if (res == FSDEM_OK) {
        fsdem__vtk_polydata(&w, d->time, 2 * (long long)c.count, 0, c.count, 0);
        fsdem__vtk_section(&w, "CellData", "normal_force", "force");
        fsdem__vtk_write(&w, fsdem__vtk_vec3s("force", c.force, c.count));
        fsdem__vtk_write(&w, fsdem__vtk_reals("normal_force", c.normal_force, c.count));
        fsdem__vtk_write(&w, fsdem__vtk_reals("overlap", c.overlap, c.count));
        fsdem__vtk_write(&w, fsdem__vtk_ints("particle", c.particle, c.count));
        fsdem__vtk_write(&w, fsdem__vtk_ints("partner", c.partner, c.count));
        fsdem__vtk_section_end(&w, "CellData");
        fsdem__vtk_section(&w, "Points", NULL, NULL);
        fsdem__vtk_write(&w, fsdem__vtk_vec3s("Points", c.points, 2 * (long long)c.count));
        fsdem__vtk_section_end(&w, "Points");
        fsdem__vtk_cells(&w, "Lines", fsdem__vtk_ramp("connectivity", 2 * (long long)c.count, 0, 1),
                         fsdem__vtk_ramp("offsets", c.count, 2, 2));
        res = fsdem__vtk_close(&w);
    }
    fsdem__free(&d->allocator, b, sizeof *b);
    fsdem__free(&d->allocator, hits, sizeof *hits * row_max);
    fsdem__free(&d->allocator, c.points, sizeof(fsdem_vec3) * 2 * n);
    fsdem__free(&d->allocator, c.force, sizeof(fsdem_vec3) * n);
    fsdem__free(&d->allocator, c.normal_force, sizeof(fsdem_real) * n);
    fsdem__free(&d->allocator, c.overlap, sizeof(fsdem_real) * n);
    fsdem__free(&d->allocator, c.particle, sizeof(int) * n);
    fsdem__free(&d->allocator, c.partner, sizeof(int) * n);
    return res;
}

/* ---- >>io_pic : particles, grid ---- */

fsdem_result fsdem_pic_write_particles_vtp(const fsdem_pic *s, const char *path, fsdem_vtk_format format) {
    fsdem__vtk_writer w;
    fsdem_result res;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    res = fsdem__vtk_particles_begin(&w, &s->status, "fsdem_pic_write_particles_vtp", path, format, s->time, s->np, NULL, "velocity");
    if (res != FSDEM_OK) return res;
    fsdem__vtk_write(&w, fsdem__vtk_vec3s("velocity", s->pv, s->np));
    return fsdem__vtk_particles_end(&w, s->px, s->np);
}

fsdem_result fsdem_mps_write_vtp(const fsdem_mps *s, const char *path, fsdem_vtk_format format) {
    fsdem__vtk_writer w;
    fsdem_result res;
    if (!s) return FSDEM_ERR_INVALID_ARG;
    res = fsdem__vtk_particles_begin(&w, &s->status, "fsdem_mps_write_vtp", path, format, s->time, s->n, "pressure", "velocity");
    if (res != FSDEM_OK) return res;
    fsdem__vtk_write(&w, fsdem__vtk_bytes("kind", s->kind, s->n));
    fsdem__vtk_write(&w, fsdem__vtk_bytes("surface", s->surf, s->n));
    fsdem__vtk_write(&w, fsdem__vtk_reals("pressure", s->p, s->n));
    fsdem__vtk_write(&w, fsdem__vtk_vec3s("velocity", s->v, s->n));
    fsdem__vtk_write(&w, fsdem__vtk_reals("number_density", s->nd, s->n));
    fsdem__vtk_write(&w, fsdem__vtk_reals("porosity", s->eps, s->n));
    return fsdem__vtk_particles_end(&w, s->x, s->n);
}

/* ---- CSV snapshots of rows of numbers ---- */

/* Fills the values of row `index`; returns 0 when the row is left out. */
typedef int (*fsdem__io_row_fn)(const void *object, int index, double *values);

/* Writes `header` and the rows 0 .. rows-1 that `row` gives (as many values as the header has
   names), with 17 significant digits so that they read back exactly. */
static fsdem_result fsdem__io_write_rows(const fsdem__status *status, const char *who, const char *path, const char *header,
                                         int rows, fsdem__io_row_fn row, const void *object) {
    double values[32];
    int columns = 1, index, k, bad;
    const char *h;
    FILE *fp;
    if (!path) return fsdem__fail((fsdem__status *)status, FSDEM_ERR_INVALID_ARG, "%s: path is NULL", who);
    for (h = header; *h; ++h) columns += *h == ',';
    FSDEM_ASSERT(columns <= (int)(sizeof values / sizeof values[0]));
    if (!(fp = fopen(path, "w"))) return fsdem__fail((fsdem__status *)status, FSDEM_ERR_IO, "%s: cannot open '%s' for writing", who, path);
    fprintf(fp, "%s\n", header);
    for (index = 0; index < rows; ++index) {
        if (!row(object, index, values)) continue;
        for (k = 0; k < columns; ++k) fprintf(fp, k ? ",%.17g" : "%.17g", values[k]);
        fputc('\n', fp);
    }
    bad = ferror(fp);
    if (fclose(fp) != 0 || bad) return fsdem__fail((fsdem__status *)status, FSDEM_ERR_IO, "%s: cannot write '%s'", who, path);
    return fsdem__ok((fsdem__status *)status);
}

static void fsdem__io_put3(double *v, fsdem_vec3 a) {
    v[0] = (double)a.x;
    v[1] = (double)a.y;
    v[2] = (double)a.z;
}

static int fsdem__io_mps_row(const void *object, int i, double *v) {
    const fsdem_mps *s = (const fsdem_mps *)object;
    v[0] = s->kind[i];
    v[1] = s->surf[i];
    fsdem__io_put3(v + 2, s->x[i]);
    fsdem__io_put3(v + 5, s->v[i]);
    v[8] = (double)s->p[i];
    v[9] = (double)s->nd[i];
    v[10] = (double)s->eps[i];
    return 1;
}

fsdem_result fsdem_mps_write_csv(const fsdem_mps *s, const char *path) {
    if (!s) return FSDEM_ERR_INVALID_ARG;
    return fsdem__io_write_rows(&s->status, "fsdem_mps_write_csv", path,
                                "kind,surface,x,y,z,vx,vy,vz,pressure,number_density,porosity", s->n, fsdem__io_mps_row, s);
}

static int fsdem__io_swe_dem_row(const void *object, int i, double *v) {
    const fsdem_swe_dem *c = (const fsdem_swe_dem *)object;
    const int k = fsdem__swe_dem_record(c, i);
    fsdem_swe_dem_force f;
    if (k < 0) return 0;
    f = c->force[k];
    v[0] = f.id;
    v[1] = (double)f.buoyancy.z;
    v[2] = (double)f.hydrostatic.x;
    v[3] = (double)f.hydrostatic.y;
    v[4] = (double)f.dynamic.x;
    v[5] = (double)f.dynamic.y;
    v[6] = (double)f.heave.z;
    v[7] = (double)f.submerged_volume;
    v[8] = (double)f.frontal_area;
    v[9] = (double)f.surface;
    v[10] = f.in_water;
    return 1;
}

fsdem_result fsdem_swe_dem_write_csv(const fsdem_swe_dem *c, const char *path) {
    if (!c) return FSDEM_ERR_INVALID_ARG;
    return fsdem__io_write_rows(&c->status, "fsdem_swe_dem_write_csv", path,
                                "id,buoyancy_z,hydrostatic_x,hydrostatic_y,dynamic_x,dynamic_y,heave_z,submerged_volume,"
                                "frontal_area,surface,in_water",
                                fsdem_dem_get_particles(c->desc.dem).count, fsdem__io_swe_dem_row, c);
}

static int fsdem__io_mps_dem_row(const void *object, int i, double *v) {
    const fsdem_mps_dem *c = (const fsdem_mps_dem *)object;
    const int k = fsdem__mps_dem_record(c, i);
    const fsdem_mps_dem_force *f = &c->force[k < 0 ? 0 : k];
    if (k < 0) return 0;
    v[0] = f->id;
    fsdem__io_put3(v + 1, f->drag);
    fsdem__io_put3(v + 4, f->pressure);
    fsdem__io_put3(v + 7, f->total);
    fsdem__io_put3(v + 10, f->fluid_velocity);
    v[13] = (double)f->porosity;
    v[14] = (double)f->reynolds;
    v[15] = f->wet;
    return 1;
}

fsdem_result fsdem_mps_dem_write_csv(const fsdem_mps_dem *c, const char *path) {
    if (!c) return FSDEM_ERR_INVALID_ARG;
    return fsdem__io_write_rows(&c->status, "fsdem_mps_dem_write_csv", path,
                                "id,drag_x,drag_y,drag_z,pressure_x,pressure_y,pressure_z,total_x,total_y,total_z,fluid_u,"
                                "fluid_v,fluid_w,porosity,reynolds,wet",
                                fsdem_dem_get_particles(c->desc.dem).count, fsdem__io_mps_dem_row, c);
}

static int fsdem__io_pic_dem_row(const void *object, int i, double *v) {
    const fsdem_pic_dem *c = (const fsdem_pic_dem *)object;
    fsdem_pic_dem_force f;
    if (fsdem__pic_dem_record(c, i) < 0 || fsdem_pic_dem_get_force(c, i, &f) != FSDEM_OK) return 0;
    v[0] = f.id;
    fsdem__io_put3(v + 1, f.pressure_force);
    fsdem__io_put3(v + 4, f.viscous_force);
    fsdem__io_put3(v + 7, f.torque);
    fsdem__io_put3(v + 10, f.weight_correction);
    v[13] = (double)f.volume;
    v[14] = f.faces;
    return 1;
}

fsdem_result fsdem_pic_dem_write_csv(const fsdem_pic_dem *c, const char *path) {
    if (!c) return FSDEM_ERR_INVALID_ARG;
    return fsdem__io_write_rows(&c->status, "fsdem_pic_dem_write_csv", path,
                                "id,pressure_x,pressure_y,pressure_z,viscous_x,viscous_y,viscous_z,torque_x,torque_y,torque_z,"
                                "weight_correction_x,weight_correction_y,weight_correction_z,volume,faces",
                                fsdem_dem_get_particles(c->desc.dem).count, fsdem__io_pic_dem_row, c);
}

static void fsdem__io_pic_velocity(const void *user, long long c, double out[3]) {
    const fsdem_pic *s = (const fsdem_pic *)user;
    const int i = (int)(c % s->n[0]), j = (int)(c / s->n[0] % s->n[1]), k = (int)(c / ((long long)s->n[0] * s->n[1]));
    const fsdem_vec3 v = fsdem__pic_cell_velocity(s, i, j, k);
    out[0] = (double)v.x;
    out[1] = (double)v.y;
    out[2] = (double)v.z;
}

fsdem_result fsdem_pic_write_grid_vti(const fsdem_pic *s, const char *path, fsdem_vtk_format format) {
    fsdem__vtk_writer w;
    fsdem_result res;
    int cells[3];
    double origin[3], spacing[3];
    if (!s) return FSDEM_ERR_INVALID_ARG;
    res = fsdem__vtk_open(&w, (fsdem__status *)&s->status, "fsdem_pic_write_grid_vti", path, format, "ImageData");
    if (res != FSDEM_OK) return res;
    cells[0] = s->n[0];
    cells[1] = s->n[1];
    cells[2] = s->dim == 3 ? s->n[2] : 0;
    origin[0] = (double)s->lo.x;
    origin[1] = (double)s->lo.y;
    origin[2] = s->dim == 3 ? (double)s->lo.z : 0;
    spacing[0] = spacing[1] = spacing[2] = (double)s->dx;
    fsdem__vtk_imagedata(&w, s->time, cells, origin, spacing);
    fsdem__vtk_section(&w, "CellData", "pressure", "velocity");
    fsdem__vtk_write(&w, fsdem__vtk_reals("pressure", s->pres, s->ncell));
    fsdem__vtk_write(&w, fsdem__vtk_reals("phi", s->phi, s->ncell));
    fsdem__vtk_write(&w, fsdem__vtk_reals("fraction", s->frac, s->ncell));
    fsdem__vtk_write(&w, fsdem__vtk_bytes("type", s->ctype, s->ncell));
    fsdem__vtk_write(&w, fsdem__vtk_computed("velocity", FSDEM__VTK_REAL, 3, s->ncell, fsdem__io_pic_velocity, s));
    fsdem__vtk_section_end(&w, "CellData");
    return fsdem__vtk_close(&w);
}

/* ---- >>io_swe : fields ---- */

static void fsdem__io_swe_depth(const void *user, long long k, double out[3]) {
    const fsdem_swe *s = (const fsdem_swe *)user;
    const fsdem_real h = s->eta[k] - s->bed[k];
    out[0] = (double)h;
}

static void fsdem__io_swe_velocity(const void *user, long long k, double out[3]) {
    fsdem_real u, v;
    fsdem__swe_velocity((const fsdem_swe *)user, (int)k, &u, &v);
    out[0] = (double)u;
    out[1] = (double)v;
    out[2] = 0;
}

fsdem_result fsdem_swe_write_vti(const fsdem_swe *s, const char *path, fsdem_vtk_format format) {
    fsdem__vtk_writer w;
    fsdem_result res;
    int cells[3];
    double origin[3], spacing[3];
    if (!s) return FSDEM_ERR_INVALID_ARG;
    res = fsdem__vtk_open(&w, (fsdem__status *)&s->status, "fsdem_swe_write_vti", path, format, "ImageData");
    if (res != FSDEM_OK) return res;
    cells[0] = s->nx;
    cells[1] = s->ny; /* 1 in 1D: one cell of the channel's width */
    cells[2] = 0;
    origin[0] = (double)s->desc.x_min;
    origin[1] = s->dim == 2 ? (double)s->desc.y_min : 0;
    origin[2] = 0;
    spacing[0] = (double)s->dx;
    spacing[1] = (double)s->dy;
    spacing[2] = 1;
    fsdem__vtk_imagedata(&w, s->time, cells, origin, spacing);
    fsdem__vtk_section(&w, "CellData", "h", "velocity");
    fsdem__vtk_write(&w, fsdem__vtk_computed("h", FSDEM__VTK_REAL, 1, s->n, fsdem__io_swe_depth, s));
    fsdem__vtk_write(&w, fsdem__vtk_reals("eta", s->eta, s->n));
    fsdem__vtk_write(&w, fsdem__vtk_reals("bed", s->bed, s->n));
    fsdem__vtk_write(&w, fsdem__vtk_computed("velocity", FSDEM__VTK_REAL, 3, s->n, fsdem__io_swe_velocity, s));
    if (s->manning) fsdem__vtk_write(&w, fsdem__vtk_reals("manning", s->manning, s->n));
    fsdem__vtk_section_end(&w, "CellData");
    return fsdem__vtk_close(&w);
}

#endif /* FSDEM_IMPLEMENTATION_DONE */
#endif /* FSDEM_IMPLEMENTATION */

/* ===== >>licence : MIT ================================================================================

   Copyright (c) 2026 the fsdem.h authors

   Permission is hereby granted, free of charge, to any person obtaining a copy of this software and
   associated documentation files (the "Software"), to deal in the Software without restriction,
   including without limitation the rights to use, copy, modify, merge, publish, distribute,
   sublicense, and/or sell copies of the Software, and to permit persons to whom the Software is
   furnished to do so, subject to the following conditions:

   The above copyright notice and this permission notice shall be included in all copies or
   substantial portions of the Software.

   THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR IMPLIED, INCLUDING BUT
   NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY, FITNESS FOR A PARTICULAR PURPOSE AND
   NONINFRINGEMENT. IN NO EVENT SHALL THE AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM,
   DAMAGES OR OTHER LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM, OUT
   OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE SOFTWARE.
*/
