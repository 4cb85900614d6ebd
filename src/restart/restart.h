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
                    created with, and its own counters and per-body load records;
     fsdem_gic      the states of its fsdem_pic (whose porosity holds the sand's fractions) and
                    fsdem_dem, its fractions, counters and the drag limit of its last step (the
                    per-granule force records are not kept: fsdem_gic_get_force finds none until
                    the next step).
   A restore writes into the object's own arrays wherever they hold what the save has (the PIC's
   and the MPS's particle arrays when their capacity is the saved one), so restoring into an object
   of the sizes saved allocates nothing: a coupled step that fails puts its state back so
   (>>couple_step).
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
                    6 fsdem_mps_dem, 7 fsdem_pic_dem, 8 fsdem_gic
         24      4  dimension of the object (the SWE's for fsdem_swe_dem)
         28      4  reserved (0)
         32     16  four sizes (int) for tools: DEM particles, materials, walls, pair-list entries;
                    PIC cells along x, y, z and particles; SWE nx, ny, point sources, gauges;
                    SWE-DEM nx, ny, DEM particles, force records; MPS particles, FLUID
                    particles, obstacles, 0; MPS-DEM MPS particles, DEM particles, force records, 0;
                    PIC-DEM PIC particles, DEM particles, body load records, 0; GIC PIC
                    particles, DEM particles, PIC cells, 0
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

/* The same four for the Granule-In-Cell coupler: its solvers' states are saved and restored with it. */
FSDEM_API fsdem_result fsdem_gic_save(const fsdem_gic *coupler, const char *path);
FSDEM_API fsdem_result fsdem_gic_restore(fsdem_gic *coupler, const char *path);
FSDEM_API fsdem_result fsdem_gic_save_memory(const fsdem_gic *coupler, void *buffer, size_t capacity, size_t *size);
FSDEM_API fsdem_result fsdem_gic_restore_memory(fsdem_gic *coupler, const void *buffer, size_t size);
