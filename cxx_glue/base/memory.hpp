// The memory this process may still use on its machine, for a solver that
// checks its estimate before it allocates (an allocation that succeeds and
// is then touched past a cgroup's limit ends the process by the kernel's
// OOM killer, with no message and nothing written).
#pragma once

#include <string>

namespace sp {

// The megabytes this process may still allocate on its machine: the least
// of the kernel's MemAvailable (/proc/meminfo) and its memory cgroup's
// limit less its usage (cgroup v2 memory.max - memory.current, or v1
// memory.limit_in_bytes - memory.usage_in_bytes), the cgroup's ancestors
// included; -1 when none can be read. @p source names the one that bounds it.
double available_memory_mb(std::string *source);

}  // namespace sp
