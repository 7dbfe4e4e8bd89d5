#include "run/run_energy.h"

#include "base/agree.h"
#include "model/cells.h"
#include "run/solver_status.h"

double sp_energy_fields(const sp_energy_parts *p) {
  return p->bulk + p->gradient + p->repulsion + p->buffer + p->adhesion;
}

int sp_run_energy(sp_run *run, sp_energy_parts *parts) {
  SP_CALL(sp_agree(run->agree_comm, SP_OK)); /* a collective follows */
  const int status = sp_solver_energy(run->solver, &run->opt.model, run->state, parts);
  if (status != SP_SOLVER_OK) return sp_solver_failed(run->solver, status, "energy");
  return SP_OK;
}

int sp_run_observe(const sp_run *run, sp_cell_obs *obs) {
  return sp_cells_observe(run->mesh, run->layout, run->state,
                          run->opt.division.observe_threshold, obs);
}
