// CPU time of the whole process (all threads, user + system), for whole-run benchmarks: unlike
// wall time it barely moves when other processes load the machine.
#pragma once

#include <ctime>

namespace fieldrig::bench {

inline double processCpuSeconds() {
  timespec t{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace fieldrig::bench
