#include "base/errors.hpp"

#include <exception>
#include <new>

#include "softpack_solver.h"

namespace sp {

int error_status(std::exception_ptr e, std::string &what) {
  try {
    std::rethrow_exception(e);
  } catch (const input_error &x) {
    what = x.what();
    return SP_SOLVER_ERR_INPUT;
  } catch (const memory_error &x) {
    what = x.what();
    return SP_SOLVER_ERR_MEMORY;
  } catch (const std::bad_alloc &x) {
    what = std::string("out of memory in the Trilinos glue (") + x.what() + ")";
    return SP_SOLVER_ERR_MEMORY;
  } catch (const mpi_error &x) {
    what = x.what();
    return SP_SOLVER_ERR_MPI;
  } catch (const std::logic_error &x) {
    what = x.what();
    return SP_SOLVER_ERR_INTERNAL;
  } catch (const std::exception &x) {
    what = x.what();
  } catch (const char *x) {  // NOX throws these too
    what = std::string("NOX: ") + x;
  } catch (...) {
    what = "unknown exception in the Trilinos glue";
  }
  return SP_SOLVER_ERR_SOLVER;
}

int lowest_failure(MPI_Comm comm, bool failed, int &status, std::string &why) {
  int rank, size;
  check_mpi(MPI_Comm_rank(comm, &rank), "MPI_Comm_rank");
  check_mpi(MPI_Comm_size(comm, &size), "MPI_Comm_size");
  int mine = failed ? rank : size, first = size;
  check_mpi(MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm), "MPI_Allreduce");
  if (first == size) return -1;
  int head[2] = {status, (int)why.size()};  // the failing rank's
  check_mpi(MPI_Bcast(head, 2, MPI_INT, first, comm), "MPI_Bcast");
  std::string text(head[1], ' ');
  if (rank == first) text = why;
  if (head[1] > 0) check_mpi(MPI_Bcast(&text[0], head[1], MPI_CHAR, first, comm), "MPI_Bcast");
  status = head[0];
  why = text;
  return first;
}

namespace {

[[noreturn]] void throw_as(int status, const std::string &what) {
  switch (status) {
    case SP_SOLVER_ERR_INPUT: throw input_error(what);
    case SP_SOLVER_ERR_MEMORY: throw memory_error(what);
    case SP_SOLVER_ERR_MPI: throw mpi_error(what);
    case SP_SOLVER_ERR_INTERNAL: throw std::logic_error(what);
    default: throw std::runtime_error(what);
  }
}

}  // namespace

void agree_local(MPI_Comm comm, const std::function<void()> &local) {
  std::exception_ptr failed;
  try {
    local();
  } catch (...) {
    failed = std::current_exception();
  }
  int rank, size;
  check_mpi(MPI_Comm_size(comm, &size), "MPI_Comm_size");
  if (size == 1) {
    if (failed) std::rethrow_exception(failed);
    return;
  }
  check_mpi(MPI_Comm_rank(comm, &rank), "MPI_Comm_rank");
  // The failing rank tells the others its class and message, then rethrows.
  std::string what;
  int status = failed ? error_status(failed, what) : SP_SOLVER_OK;
  const int first = lowest_failure(comm, (bool)failed, status, what);
  if (first < 0) return;
  if (first == rank) std::rethrow_exception(failed);
  throw_as(status, "on rank " + std::to_string(first) + " of " + std::to_string(size) + ": " +
                       what);
}

void fault_in_glue(sp_fault_phase phase, const char *name, int rank) {
  if (sp_fault_due(phase, rank))
    throw memory_error(std::string("out of memory at ") + name + " on rank " +
                       std::to_string(rank) + " (fault injected by SOFTPACK_FAULT=" + name +
                       ":" + std::to_string(rank) + ")");
}

}  // namespace sp
