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
