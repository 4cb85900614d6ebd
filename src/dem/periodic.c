/* ---- >>dem_periodic : periodic axes ----

   Along a periodic axis (desc.periodic) of period L, a pair interacts through its minimum image:
   the separation e loses the multiple of L nearest e / L. The neighbour lists are built on a cell
   grid whose neighbourhoods wrap round (fsdem_cellgrid_setup_periodic), their entries keep the
   pair and its spring whichever side of the seam the partners are on, and positions are brought
   back into [domain_min, domain_max) after every drift (with the rebuild reference x_ref, so the
   displacement since the last rebuild is unchanged). The minimum image is the only image in
   reach while L exceeds twice the neighbour reach 2 r_max + contact_offset + skin, which
   fsdem_dem_add_particle checks. */

/* Where particle i sees particle j: j's image nearest i; j itself, bit for bit, along the axes no
   period separates them (x_i - (x_i - x_j) is x_j only to rounding). */
static fsdem_vec3 fsdem__dem_image_of(const fsdem_dem *d, int i, int j) {
    const fsdem_vec3 e = fsdem__sub(d->x[i], d->x[j]);
    return fsdem__add(d->x[j], fsdem__sub(e, fsdem__min_image(&d->periods, e)));
}

/* Brings every position into [domain_min, domain_max) along the periodic axes, moving x_ref along. */
static void fsdem__dem_wrap(fsdem_dem *d) {
    int a, i;
    for (a = 0; a < 3; ++a)
        if (d->periods.length[a] > 0)
            for (i = 0; i < d->n; ++i) {
                const fsdem_real shift = fsdem__wrap_axis(&d->periods, a, fsdem__comp(d->desc.domain_min, a),
                                                              fsdem__comp(d->desc.domain_max, a), &d->x[i]);
                if (shift != 0) fsdem__set_comp(&d->x_ref[i], a, fsdem__comp(d->x_ref[i], a) - shift);
            }
}

/* A particle of radius r keeps every minimum image unique: each period exceeds twice the reach of
   the neighbour lists with it. */
static fsdem_result fsdem__dem_period_check(fsdem_dem *d, fsdem_real r) {
    const fsdem_real r_max = r > d->r_max ? r : d->r_max, skin = d->desc.skin >= 0 ? d->desc.skin : (fsdem_real)0.25 * r_max;
    const fsdem_real reach = 2 * r_max + d->desc.contact_offset + skin;
    int a;
    for (a = 0; a < 3; ++a)
        if (d->periods.length[a] > 0 && !(d->periods.length[a] > 2 * reach))
            return fsdem__fail(&d->status, FSDEM_ERR_INVALID_ARG,
                               "fsdem_dem_particle_desc.radius %g m: the period %g m along %c must exceed twice the neighbour reach "
                               "2 r_max + contact_offset + skin = %g m",
                               (double)r, (double)d->periods.length[a], "xyz"[a], (double)reach);
    return FSDEM_OK;
}
