// The extern "C" door: argument checks, try/catch, codes. No exception
// crosses it (NOX also throws const char*, hence catch (...)).
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>

#include <Trilinos_version.h>

#include "base/errors.hpp"
#include "base/fault.h"
#include "linear/linear.hpp"
#include "newton.hpp"
#include "softpack_solver.h"

struct sp_solver_s {
  std::unique_ptr<sp::Solver> impl;
  std::string error;
};

namespace {

// Each exception as its class (sp::error_status); the message stays in the
// handle.
template <class F> int guarded(sp_solver s, F &&body) {
  try {
    body();
    return SP_SOLVER_OK;
  } catch (...) {
    std::string what;
    const int status = sp::error_status(std::current_exception(), what);
    if (s) s->error = what;
    return status;
  }
}

void need(bool ok, const char *what) {
  if (!ok) throw std::invalid_argument(what);
}

bool valid_kind(int kind) {
  return kind >= SP_SOLVER_JAC_AD && kind <= SP_SOLVER_JAC_AD_DFAD;
}

}  // namespace

extern "C" {

const char *sp_solver_trilinos_version(void) { return TRILINOS_VERSION_STRING; }

int sp_solver_linear_backend(int linear, const char **backend) {
  return sp::linear_solver_version(linear, backend);
}

int sp_solver_create(MPI_Comm comm, const sp_solver_options *options, sp_solver *out) {
  if (!options || !out) return SP_SOLVER_ERR_INTERNAL;
  sp_solver s = new (std::nothrow) sp_solver_s;
  if (!s) return SP_SOLVER_ERR_MEMORY;
  *out = s;
  return guarded(s, [&] {
    // The fault hook (src/base/fault.h): SOFTPACK_FAULT=solver:RANK fails one
    // rank as a library would. The ranks agree on it before the solver's
    // collectives begin, so every rank reports the failure.
    int rank = 0, faulty = -1, faulty_rank = -1;
    sp::check_mpi(MPI_Comm_rank(comm, &rank), "MPI_Comm_rank");
    if (sp_fault_due(SP_FAULT_SOLVER, rank)) faulty = rank;
    sp::check_mpi(MPI_Allreduce(&faulty, &faulty_rank, 1, MPI_INT, MPI_MAX, comm),
                  "MPI_Allreduce");
    if (faulty_rank >= 0)
      throw std::runtime_error("solver creation failed on rank " + std::to_string(faulty_rank) +
                               " (fault injected by SOFTPACK_FAULT=solver:" +
                               std::to_string(faulty_rank) + ")");
    s->impl.reset(new sp::Solver(comm, *options));
  });
}

int sp_solver_ranks(sp_solver s) {
  if (!s || !s->impl) return 0;
  return s->impl->ranks();
}

int sp_solver_set_problem(sp_solver s, const sp_mesh_view *mesh, const sp_layout_view *layout) {
  if (!s) return SP_SOLVER_ERR_INTERNAL;
  return guarded(s, [&] {
    need(s->impl != nullptr, "the solver was not created");
    need(mesh && layout, "sp_solver_set_problem: mesh and layout are required");
    s->impl->set_problem(*mesh, *layout);
  });
}

int sp_solver_usage_of(sp_solver s, sp_solver_usage *out) {
  if (!s) return SP_SOLVER_ERR_INTERNAL;
  return guarded(s, [&] {
    need(s->impl != nullptr && out != nullptr, "sp_solver_usage_of: null argument");
    *out = s->impl->usage();
  });
}

int sp_solver_set_linear(sp_solver s, int linear, double krylov_tol) {
  if (!s) return SP_SOLVER_ERR_INTERNAL;
  return guarded(s, [&] {
    need(s->impl != nullptr, "the solver was not created");
    s->impl->set_linear(linear, krylov_tol);
  });
}

int sp_solver_carry_point(sp_solver s, int *carry, double *dt, const double **x,
                          const sp_shape_coef **shape, int *n_shape, int *shape_implicit) {
  if (!s) return SP_SOLVER_ERR_INTERNAL;
  return guarded(s, [&] {
    need(s->impl != nullptr, "the solver was not created");
    need(carry && dt && x && shape && n_shape && shape_implicit,
         "sp_solver_carry_point: null argument");
    const std::vector<double> *xs;
    const std::vector<sp_shape_coef> *coefs;
    *carry = s->impl->carry_point(*dt, xs, coefs, *shape_implicit) ? 1 : 0;
    *x = xs->data();
    *shape = coefs->empty() ? nullptr : coefs->data();
    *n_shape = (int)coefs->size();
  });
}

int sp_solver_carry_restore(sp_solver s, const sp_step_data *data, const double *x) {
  if (!s) return SP_SOLVER_ERR_INTERNAL;
  return guarded(s, [&] {
    need(s->impl != nullptr, "the solver was not created");
    need(data && x && data->dt > 0, "sp_solver_carry_restore: null argument or dt <= 0");
    s->impl->carry_restore(*data, x);
  });
}

int sp_solver_carry_mark(sp_solver s) {
  if (!s) return SP_SOLVER_ERR_INTERNAL;
  return guarded(s, [&] {
    need(s->impl != nullptr, "the solver was not created");
    s->impl->carry_mark();
  });
}

int sp_solver_carry_rewind(sp_solver s) {
  if (!s) return SP_SOLVER_ERR_INTERNAL;
  return guarded(s, [&] {
    need(s->impl != nullptr, "the solver was not created");
    s->impl->carry_rewind();
  });
}

int sp_solver_step(sp_solver s, const sp_step_data *data, double *state, sp_step_report *report) {
  if (!s) return SP_SOLVER_ERR_INTERNAL;
  int newton = 0;
  int rc = guarded(s, [&] {
    need(s->impl != nullptr, "the solver was not created");
    need(data && state && report && data->state_old, "sp_solver_step: null argument");
    need(data->dt > 0, "sp_solver_step: dt must be positive");
    newton = s->impl->step(*data, state, *report);
  });
  if (rc != 0) return rc;
  if (newton != 0) s->error = report->reason;
  return newton;
}

int sp_solver_energy(sp_solver s, const sp_model_params *model, const double *state,
                     sp_energy_parts *parts) {
  if (!s) return SP_SOLVER_ERR_INTERNAL;
  return guarded(s, [&] {
    need(s->impl && model && state && parts, "sp_solver_energy: null argument");
    *parts = s->impl->energy(*model, state);
  });
}

int sp_solver_residual(sp_solver s, const sp_step_data *data, const double *state,
                       double *residual) {
  if (!s) return SP_SOLVER_ERR_INTERNAL;
  return guarded(s, [&] {
    need(s->impl && data && state && residual, "sp_solver_residual: null argument");
    s->impl->residual(*data, state, residual);
  });
}

int sp_solver_apply_jacobian(sp_solver s, const sp_step_data *data, const double *state,
                             int transpose, const double *x, double *y) {
  if (!s) return SP_SOLVER_ERR_INTERNAL;
  return guarded(s, [&] {
    need(s->impl && data && state && x && y, "sp_solver_apply_jacobian: null argument");
    s->impl->jacobian_times(*data, state, transpose != 0, x, y);
  });
}

int sp_solver_check_jacobian(sp_solver s, const sp_step_data *data, const double *state,
                             int jacobian, double *max_rel_err) {
  if (!s) return SP_SOLVER_ERR_INTERNAL;
  return guarded(s, [&] {
    need(s->impl && data && state && max_rel_err, "sp_solver_check_jacobian: null argument");
    need(valid_kind(jacobian), "sp_solver_check_jacobian: unknown kind");
    *max_rel_err = s->impl->check_jacobian(*data, state, jacobian);
  });
}

int sp_solver_compare_jacobians(sp_solver s, const sp_step_data *data, const double *state,
                                int kind_a, int kind_b, double *max_rel_diff) {
  if (!s) return SP_SOLVER_ERR_INTERNAL;
  return guarded(s, [&] {
    need(s->impl && data && state && max_rel_diff, "sp_solver_compare_jacobians: null argument");
    need(valid_kind(kind_a) && valid_kind(kind_b), "sp_solver_compare_jacobians: unknown kind");
    *max_rel_diff = s->impl->compare_jacobians(*data, state, kind_a, kind_b);
  });
}

int sp_solver_time_jacobian(sp_solver s, const sp_step_data *data, const double *state,
                            int kind, int repeats, double *seconds_fill,
                            double *seconds_elements) {
  if (!s) return SP_SOLVER_ERR_INTERNAL;
  return guarded(s, [&] {
    need(s->impl && data && state && seconds_fill, "sp_solver_time_jacobian: null argument");
    need(valid_kind(kind), "sp_solver_time_jacobian: unknown kind");
    need(repeats >= 1, "sp_solver_time_jacobian: repeats must be >= 1");
    *seconds_fill = s->impl->time_jacobian(*data, state, kind, repeats, seconds_elements);
  });
}

const char *sp_solver_last_error(sp_solver s) { return s ? s->error.c_str() : "no solver"; }

void sp_solver_destroy(sp_solver *s) {
  if (!s || !*s) return;
  delete *s;
  *s = nullptr;
}

}  // extern "C"
