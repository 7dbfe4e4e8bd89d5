// The table of linear solvers (c_api/softpack_linear.h) as factories: the
// one place that turns the scene's solver.linear into a solver.
#include <cstdio>
#include <string>

#include "base/errors.hpp"
#include "linear/linear.hpp"

namespace sp {

namespace {

struct Backend {
  const char *name;
  sp_linear_ranks ranks;
  std::unique_ptr<LinearSolver> (*make)(MPI_Comm, const sp_solver_options &);
  const char *(*version)(bool *);
};

#define SP_LINEAR_ROW_(id, name, ranks) {#name, ranks, make_linear_##name, linear_##name##_version},
const Backend backends[] = {SP_LINEAR_SOLVERS(SP_LINEAR_ROW_)};
#undef SP_LINEAR_ROW_
static_assert(sizeof backends / sizeof backends[0] == SP_LINEAR_COUNT,
              "one row per solver of SP_LINEAR_SOLVERS");

const Backend *find(int kind) {
  return kind >= 0 && kind < SP_LINEAR_COUNT ? &backends[kind] : nullptr;
}

// "superlu_dist, mumps, ..." : the solvers that run on several ranks
std::string several_rank_solvers() {
  std::string list;
  for (const Backend &b : backends)
    if (b.ranks != SP_LINEAR_SERIAL) list += (list.empty() ? "" : ", ") + std::string(b.name);
  return list;
}

}  // namespace

KrylovOptions krylov_options(const sp_solver_options &options) {
  KrylovOptions k;
  k.tolerance = options.krylov_tol;
  if (!(k.tolerance > 0 && k.tolerance < 1)) {
    char got[32];
    std::snprintf(got, sizeof got, "%g", k.tolerance);
    throw input_error(std::string("solver.krylov_tol: expected 0 < tol < 1, got ") + got);
  }
  return k;
}

std::unique_ptr<LinearSolver> make_linear_solver(MPI_Comm comm, const sp_solver_options &options) {
  const Backend *b = find(options.linear);
  if (!b) throw input_error("solver.linear: unknown kind");
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  if (size == 1 || b->ranks == SP_LINEAR_PARALLEL) return b->make(comm, options);
  if (b->ranks == SP_LINEAR_GATHERED)
    return make_gathered(comm, rank == 0 ? b->make(comm, options) : nullptr);
  // Every rank refuses here, at set-up, before anything is written: the
  // solver's own factory first, which may say why, else with the list.
  b->make(comm, options);
  throw input_error(std::string("solver.linear: ") + b->name +
                    " runs on one MPI process only (this run has " + std::to_string(size) +
                    "; docs/parallel.md); with several processes use one of " +
                    several_rank_solvers());
}

int linear_solver_version(int kind, const char **version) {
  const Backend *b = find(kind);
  if (!b) return -1;
  bool available = true;
  const char *what = nullptr;
  try {
    what = b->version(&available);
  } catch (...) {
    available = false;
  }
  if (version) *version = what;
  return available ? 1 : 0;
}

}  // namespace sp
