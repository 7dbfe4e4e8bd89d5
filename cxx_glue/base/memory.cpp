// The memory this process may still use (memory.hpp).
#include "base/memory.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

namespace sp {

namespace {

// The first number in FILE (-1: unreadable or "max", no limit).
double read_number(const std::string &file) {
  std::ifstream in(file);
  std::string word;
  if (!(in >> word) || word == "max") return -1;
  char *end = nullptr;
  const double v = std::strtod(word.c_str(), &end);
  return end && *end == '\0' ? v : -1;
}

// The least (limit - usage) over the cgroup at DIR and its ancestors up to
// ROOT (a limit of 2^62 or more means none), in bytes; -1 if none.
double cgroup_room(const std::string &root, std::string dir, const char *limit_file,
                   const char *usage_file) {
  double least = -1;
  for (;;) {
    const double limit = read_number(root + dir + "/" + limit_file);
    const double usage = read_number(root + dir + "/" + usage_file);
    if (limit >= 0 && limit < 4.6e18 && usage >= 0 && (least < 0 || limit - usage < least))
      least = limit - usage;
    if (dir.empty() || dir == "/") break;
    dir = dir.substr(0, dir.find_last_of('/'));
  }
  return least;
}

}  // namespace

double available_memory_mb(std::string *source) {
  double best = -1;
  std::string what;
  auto take = [&](double bytes, const char *name) {
    if (bytes < 0) return;
    if (best < 0 || bytes < best) {
      best = bytes;
      what = name;
    }
  };
  {  // MemAvailable, in kB
    std::ifstream in("/proc/meminfo");
    std::string line;
    while (std::getline(in, line))
      if (line.rfind("MemAvailable:", 0) == 0) {
        take(1024.0 * std::strtod(line.c_str() + 13, nullptr), "the machine's available memory");
        break;
      }
  }
  std::ifstream cgroups("/proc/self/cgroup");
  std::string line;
  while (std::getline(cgroups, line)) {  // ID:CONTROLLERS:PATH
    const size_t a = line.find(':'), b = line.find(':', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    const std::string controllers = line.substr(a + 1, b - a - 1), path = line.substr(b + 1);
    const std::string dir = path == "/" ? "" : path;
    if (controllers.empty()) {  // v2
      for (const char *root : {"/sys/fs/cgroup", "/sys/fs/cgroup/unified"})
        take(cgroup_room(root, dir, "memory.max", "memory.current"), "the memory cgroup's limit");
    } else if (("," + controllers + ",").find(",memory,") != std::string::npos) {
      take(cgroup_room("/sys/fs/cgroup/memory", dir, "memory.limit_in_bytes",
                       "memory.usage_in_bytes"),
           "the memory cgroup's limit");
    }
  }
  if (source) *source = what;
  return best < 0 ? -1 : best / 1048576.0;
}

MachineMemory check_machine_memory(MPI_Comm all, MPI_Comm machine, double need_mb) {
  constexpr double kUnknown = 1e300;  // no limit known
  MachineMemory m;
  const double available = available_memory_mb(&m.source);
  double left = available < 0 ? kUnknown : available, need = need_mb > 0 ? need_mb : 0.0;
  MPI_Allreduce(&need, &m.need_mb, 1, MPI_DOUBLE, MPI_SUM, machine);
  MPI_Allreduce(MPI_IN_PLACE, &left, 1, MPI_DOUBLE, MPI_MIN, machine);
  m.left_mb = left;
  m.fits_here = left >= kUnknown || m.need_mb <= left;
  int everywhere = m.fits_here;
  MPI_Allreduce(MPI_IN_PLACE, &everywhere, 1, MPI_INT, MPI_MIN, all);
  m.fits = everywhere;
  if (m.source.empty()) m.source = "the least on its ranks";
  return m;
}

}  // namespace sp
