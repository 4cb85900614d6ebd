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

/* Shallow-water fields as ImageData (.vti): extent 0..nx x 0..ny x 0..0 points, origin (x_min,
   y_min, 0), spacing (dx, dy, 1); a 1D channel is one cell high, 0..nx x 0..1, origin (x_min, 0, 0),
   spacing (dx, width, 1). Cell data h (m, eta - bed), eta (m), bed (m), velocity (m/s, (u, v, 0) as
   fsdem_swe_copy_field gives them, 0 in dry cells) and, when per-cell coefficients were set
   (fsdem_swe_set_manning), manning (s/m^(1/3)). Active scalars h, active vectors velocity. */
FSDEM_API fsdem_result fsdem_swe_write_vti(const fsdem_swe *swe, const char *path, fsdem_vtk_format format);
