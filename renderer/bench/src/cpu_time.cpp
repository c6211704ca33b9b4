// Process and per-thread CPU time from the kernel (see cpu_time.hpp).
#include "sky/bench/cpu_time.hpp"

#include <time.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace sky::bench {

CpuSnapshot sampleCpu() {
  CpuSnapshot s;
  timespec ts{};
  if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) == 0) s.process_ms = double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    const int tid = std::atoi(entry.path().filename().c_str());
    std::ifstream in(entry.path() / "schedstat");
    double onCpu_ns = 0;
    if (tid > 0 && (in >> onCpu_ns)) s.thread_ms[tid] = onCpu_ns * 1e-6;
  }
  return s;
}

CpuUse cpuBetween(const CpuSnapshot& before, const CpuSnapshot& after) {
  CpuUse use;
  use.cpu_ms = std::max(0.0, after.process_ms - before.process_ms);
  for (const auto& [tid, ms] : after.thread_ms) {
    const auto it = before.thread_ms.find(tid);
    use.maxThread_ms = std::max(use.maxThread_ms, ms - (it == before.thread_ms.end() ? 0.0 : it->second));
  }
  return use;
}

}  // namespace sky::bench
