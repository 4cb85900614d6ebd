/* ===== >>couple_step : a coupled step that is taken whole or not at all, couplers stepped together */

/* Every coupler's step, step_dt and advance (>>couple), and the coupled calls below, follow one rule:
   all that can refuse the step (the fluid's and the coupler's limits, max_substeps, a DEM particle
   that does not fit or is not finite) is checked before anything moves; a failure that can only be
   seen once something moved (a NaN in a result, a solver's refusal during its step) puts coupler,
   fluid and DEM back as they were before the call, bit for bit, from a copy of their saved state
   taken before the step (>>restart, without its checksum: the copy never leaves the process). The
   copy costs one save of the coupled run per step, in memory the coupler keeps (grown when the run
   grows; FSDEM_ERR_OUT_OF_MEMORY before anything moves when it cannot be). The fluid's gauge rows
   of the step (fsdem_X_gauges_open) wait until the step is taken (fsdem_X_gauges_hold), so a step
   put back leaves the gauge file as it was too; FSDEM_ERR_IO when they cannot be written then (the
   step is taken). */

/* Couplers of one fluid stepped together: every coupler's stages before the fluid step, in the
   order of the list, one step of the fluid, then every coupler's stages after it. The step is the
   smallest stable dt of them all (fsdem_coupled_stable_dt), or dt; each coupler refuses it as its
   own step would, before anything moves. FSDEM_ERR_INVALID_ARG for an empty list, a NULL entry,
   a coupler listed twice or couplers of different fluids. A failure's message goes to every
   coupler of the list (fsdem_X_last_error). A list of one is that coupler's own step. */
FSDEM_API fsdem_result fsdem_coupled_step(fsdem_coupler *const *couplers, int count);
FSDEM_API fsdem_result fsdem_coupled_step_dt(fsdem_coupler *const *couplers, int count, fsdem_real dt);
FSDEM_API fsdem_result fsdem_coupled_advance(fsdem_coupler *const *couplers, int count, fsdem_real duration, long long *steps);
FSDEM_API fsdem_result fsdem_coupled_stable_dt(fsdem_coupler *const *couplers, int count, fsdem_real *dt);
