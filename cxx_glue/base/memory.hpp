// The memory this process may still use on its machine, for a solver that
// checks its estimate before it allocates (an allocation that succeeds and
// is then touched past a cgroup's limit ends the process by the kernel's
// OOM killer, with no message and nothing written).
#pragma once

#include <mpi.h>

#include <string>

namespace sp {

// The megabytes this process may still allocate on its machine: the least
// of the kernel's MemAvailable (/proc/meminfo) and its memory cgroup's
// limit less its usage (cgroup v2 memory.max - memory.current, or v1
// memory.limit_in_bytes - memory.usage_in_bytes), the cgroup's ancestors
// included; -1 when none can be read. @p source names the one that bounds it.
double available_memory_mb(std::string *source);

// A solver's estimate of what it is about to allocate, checked against what
// the machine still offers: need_mb (this rank's) summed over the ranks of
// @p machine (those on one machine: MPI_Comm_split_type SHARED of @p all),
// against the least any of them may still use; and whether it fits on
// every machine of @p all, so that all ranks go on or stop together.
// Collective over all.
struct MachineMemory {
  bool fits = true;       // on every machine (also when no limit can be read)
  bool fits_here = true;  // on this rank's machine
  double need_mb = 0;     // summed over this machine's ranks
  double left_mb = 0;     // the least left on any of them
  std::string source;     // what bounds it (available_memory_mb's source)
};
MachineMemory check_machine_memory(MPI_Comm all, MPI_Comm machine, double need_mb);

}  // namespace sp
