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

static int fsdem__io_gic_row(const void *object, int i, double *v) {
    const fsdem_gic *c = (const fsdem_gic *)object;
    const int k = fsdem__gic_record(c, i);
    if (k < 0) return 0;
    v[0] = c->force[k].id;
    fsdem__io_put3(v + 1, c->force[k].pressure);
    fsdem__io_put3(v + 4, c->force[k].drag);
    fsdem__io_put3(v + 7, c->force[k].virtual_mass);
    fsdem__io_put3(v + 10, c->force[k].fluid_velocity);
    v[13] = (double)c->force[k].porosity;
    v[14] = (double)c->force[k].liquid;
    return 1;
}

fsdem_result fsdem_gic_write_csv(const fsdem_gic *c, const char *path) {
    if (!c) return FSDEM_ERR_INVALID_ARG;
    return fsdem__io_write_rows(&c->status, "fsdem_gic_write_csv", path,
                                "id,pressure_x,pressure_y,pressure_z,drag_x,drag_y,drag_z,virtual_mass_x,virtual_mass_y,virtual_mass_z,"
                                "fluid_u,fluid_v,fluid_w,porosity,liquid",
                                fsdem_dem_get_particles(c->desc.dem).count, fsdem__io_gic_row, c);
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
