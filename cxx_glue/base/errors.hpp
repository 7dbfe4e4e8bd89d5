// The classes of hard errors the glue reports through the C door
// (sp_solver_status in c_api/softpack_solver.h). c_api.cpp maps each
// exception to its class: input_error -> SP_SOLVER_ERR_INPUT,
// std::bad_alloc -> MEMORY, mpi_error -> MPI, any other std::logic_error
// (an invariant or argument check: a bug) -> INTERNAL, everything else
// (std::runtime_error from a library, NOX's const char*) -> SOLVER.
#pragma once

#include <mpi.h>

#include <exception>
#include <functional>
#include <stdexcept>
#include <string>

#include "base/fault.h"

namespace sp {

// Options or a choice the user made that the glue refuses (the message
// names the scene key): bad input, exit status 2.
struct input_error : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// Out of memory, with a message (std::bad_alloc carries none): what the
// other ranks throw when one rank ran out (agree_local), and the fault
// hook's stand-in for an allocation that failed.
struct memory_error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// An MPI call that returned an error code.
struct mpi_error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throw mpi_error unless an MPI call returned MPI_SUCCESS (codes come back
// only on communicators with MPI_ERRORS_RETURN; by default MPI aborts).
inline void check_mpi(int code, const char *call) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING] = "";
  int len = 0;
  MPI_Error_string(code, text, &len);
  throw mpi_error(std::string("MPI: ") + call + " failed: " + text);
}

// The class of the exception @p e as the C door reports it (an
// sp_solver_status: SP_SOLVER_ERR_INPUT, _MEMORY, _MPI, _INTERNAL or
// _SOLVER) and its message in @p what.
int error_status(std::exception_ptr e, std::string &what);

// Collective on @p comm: the lowest rank whose @p failed is set, or -1 if
// none; then every rank holds that rank's @p status and @p why. One
// integer reduction; two broadcasts when a rank failed.
int lowest_failure(MPI_Comm comm, bool failed, int &status, std::string &why);

// Run @p local, the rank-local part of a step that a collective follows
// (an element loop before an Export or an MPI reduction). If it threw on any
// rank, every rank throws before the collective, so none is left waiting
// in it: the failing rank (the lowest, if several) its own exception, the
// others one of the same class naming that rank and its message. One
// integer reduction when nothing failed; nothing on one process.
void agree_local(MPI_Comm comm, const std::function<void()> &local);

// The fault hook (src/base/fault.h) in the glue: SOFTPACK_FAULT=NAME:RANK fails
// rank @p rank at @p phase (assembly: every residual fill; attach: every
// layout taken) with a memory_error, as if an allocation had failed there.
void fault_in_glue(sp_fault_phase phase, const char *name, int rank);

}  // namespace sp
