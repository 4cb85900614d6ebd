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
    if (s->desc.scheme == FSDEM_MPS_SCHEME_EXPLICIT) fsdem__vtk_write(&w, fsdem__vtk_reals("density", s->rho, s->n));
    return fsdem__vtk_particles_end(&w, s->x, s->n);
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
    return fsdem__write_rows(&s->status, "fsdem_mps_write_csv", path,
                                "kind,surface,x,y,z,vx,vy,vz,pressure,number_density,porosity", s->n, fsdem__io_mps_row, s);
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
