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
