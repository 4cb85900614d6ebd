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
