/* ===== >>couple : what every coupler shares ====================================================== */

/* A coupler (fsdem_swe_dem, fsdem_mps_dem, fsdem_pic_dem, fsdem_gic) joins one fluid and one DEM.
   Its step is a list of named stages around one step of the fluid: the fluid first for SWE-DEM,
   MPS-DEM and PIC-DEM (forces from the current state, the fluid step, then the DEM's substeps), the
   granules first for GIC (seed 004 Algorithm 1: sand substeps, volume fractions, then the fluid).
   Every coupler steps alike:
     - step: its stable dt, the fluid's stable dt cut by the coupler's own limits (drag or viscous
       relaxation, bodies' speed); step_dt(dt): that dt, refused with FSDEM_ERR_CFL above the
       coupler's hard limits; either refuses before anything moves when the DEM would need more
       than desc.max_substeps substeps, and a step is taken whole or not at all (>>couple_step);
     - advance(duration): steps of the stable dt until exactly `duration` later, the last two
       shortened to end there (never a sliver: a last step shorter than half a stable one is
       avoided by halving the two);
     - time: the fluid's; get_stats starts with the fsdem_coupling_stats below;
     - update: what the coupler writes into the solvers, from the current state, without stepping;
     - get_force(index): the record of DEM particle `index` from the last update (SWE-DEM, MPS-DEM)
       or step (PIC-DEM, GIC), found by the particle's stable id, so particles removed since do not
       mix the records up (FSDEM_ERR_NOT_FOUND for a bad index, before the first update or step, or
       for a particle added since), and write_csv(path): the records as CSV, one row per DEM
       particle that has one, in index order, the record's fields as columns (a vector as name_x,
       name_y, name_z), the first the particle's stable id; before the first update or step the file
       holds the header alone; a file that cannot be written is FSDEM_ERR_IO;
   A coupler holds pointers to its solvers and does not own them: destroy it before them. It claims
   the solvers' arrays it writes when it is created and releases them when it is destroyed
   (fsdem_claim): the DEM's external loads, and the fluid's arrays of its kind (SWE-DEM the
   SWE's momentum sources; MPS-DEM the MPS's forces and porosities; PIC-DEM the PIC's moving solids;
   GIC the PIC's porosity and accelerations). A second coupler that would write a claimed array is
   refused at creation, naming the first. Couplers that write different arrays of one fluid, each
   with its own DEM, share that fluid and step together with fsdem_coupled_step (>>couple_step): one PIC then
   carries a granular bed (fsdem_gic) and resolved bodies (fsdem_pic_dem) at once. */

/* Figures every coupler keeps (the head of its fsdem_X_stats). */
typedef struct fsdem_coupling_stats {
    long long steps;              /* coupled steps */
    double time;                  /* s; the fluid's time */
    fsdem_real dt;                /* s; the last coupled step */
    long long substeps;           /* DEM substeps of the last step */
    long long substeps_total;     /* DEM substeps of all steps */
    double seconds_fluid;         /* CPU seconds in the fluid's steps */
    double seconds_dem;           /* CPU seconds in the DEM's substeps (the force evaluations */
                                  /*    they call back included) */
    double seconds_coupling;      /* CPU seconds in the coupler's own work (forces, fractions, cuts) */
} fsdem_coupling_stats;

/* Any coupler, as fsdem_swe_dem_coupler, fsdem_mps_dem_coupler, fsdem_pic_dem_coupler and
   fsdem_gic_coupler give it (the same object: destroy it as what it is). */
typedef struct fsdem_coupler fsdem_coupler;
