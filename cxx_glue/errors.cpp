#include "errors.hpp"

#include <Epetra_Comm.h>

#include <exception>
#include <new>
#include <vector>

namespace sp {

namespace {

// The classes of c_api.cpp's guarded(), in its order of catching.
enum ErrorClass { OK = 0, INPUT, MEMORY, MPI, INTERNAL, SOLVER };

ErrorClass classify(std::exception_ptr e, std::string &what) {
  try {
    std::rethrow_exception(e);
  } catch (const input_error &x) {
    what = x.what();
    return INPUT;
  } catch (const memory_error &x) {
    what = x.what();
    return MEMORY;
  } catch (const std::bad_alloc &x) {
    what = std::string("out of memory in the Trilinos glue (") + x.what() + ")";
    return MEMORY;
  } catch (const mpi_error &x) {
    what = x.what();
    return MPI;
  } catch (const std::logic_error &x) {
    what = x.what();
    return INTERNAL;
  } catch (const std::exception &x) {
    what = x.what();
  } catch (const char *x) {
    what = std::string("NOX: ") + x;
  } catch (...) {
    what = "unknown exception in the Trilinos glue";
  }
  return SOLVER;
}

[[noreturn]] void throw_as(ErrorClass c, const std::string &what) {
  switch (c) {
    case INPUT: throw input_error(what);
    case MEMORY: throw memory_error(what);
    case MPI: throw mpi_error(what);
    case INTERNAL: throw std::logic_error(what);
    default: throw std::runtime_error(what);
  }
}

}  // namespace

void agree_local(const Epetra_Comm &comm, const std::function<void()> &local) {
  std::exception_ptr failed;
  try {
    local();
  } catch (...) {
    failed = std::current_exception();
  }
  const int size = comm.NumProc(), rank = comm.MyPID();
  if (size == 1) {
    if (failed) std::rethrow_exception(failed);
    return;
  }
  int mine = failed ? rank : size, first = size;
  if (comm.MinAll(&mine, &first, 1) != 0) throw mpi_error("MPI: agreeing on a local failure");
  if (first == size) return;
  // The failing rank tells the others its class and message, then rethrows.
  std::string what;
  int head[2] = {0, 0};  // class, message length
  if (rank == first) {
    head[0] = classify(failed, what);
    head[1] = (int)what.size();
  }
  if (comm.Broadcast(head, 2, first) != 0) throw mpi_error("MPI: broadcasting a local failure");
  std::vector<char> text(head[1] + 1, '\0');
  if (rank == first) what.copy(text.data(), what.size());
  if (head[1] > 0 && comm.Broadcast(text.data(), head[1], first) != 0)
    throw mpi_error("MPI: broadcasting a local failure");
  if (rank == first) std::rethrow_exception(failed);
  throw_as(static_cast<ErrorClass>(head[0]),
           "on rank " + std::to_string(first) + " of " + std::to_string(size) + ": " +
               std::string(text.data(), head[1]));
}

}  // namespace sp
