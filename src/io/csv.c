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
