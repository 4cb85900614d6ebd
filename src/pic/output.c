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
        int f = fsdem__mac_face(&s->mac, a, i, j, k);
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
                int c = fsdem__mac_cell(&s->mac, i, j, k);
                fsdem_vec3 x = fsdem__mac_cell_pos(&s->mac, i, j, k), v = fsdem__pic_cell_velocity(s, i, j, k);
                fprintf(fp, "%d,%d,%d,%.9g,%.9g,%.9g,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", i, j, k, (double)x.x, (double)x.y,
                        (double)x.z, (int)s->ctype[c], (double)s->pres[c], (double)s->phi[c], (double)s->frac[c], (double)v.x,
                        (double)v.y, (double)v.z);
            }
    bad = ferror(fp);
    return (fclose(fp) != 0 || bad) ? FSDEM_ERR_IO : FSDEM_OK;
}
