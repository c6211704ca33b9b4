// CPU time of this process and of its busiest thread, for timing a frame on a
// shared machine: wall time doubles when another process takes a core, CPU
// time does not (lavapipe.md, "Timestamps"). Linux only (/proc/self/task).
#pragma once

#include <map>

namespace sky::bench {

struct CpuSnapshot {
  double process_ms = 0;           // CLOCK_PROCESS_CPUTIME_ID, every thread that ever ran
  std::map<int, double> thread_ms; // per thread id: time on a CPU (/proc/self/task/<tid>/schedstat, first field)
};

// Reads the process's and every live thread's CPU time (a few /proc reads, tens of us).
CpuSnapshot sampleCpu();

struct CpuUse {
  double cpu_ms = 0;        // process CPU time between the two snapshots
  double maxThread_ms = 0;  // the largest per-thread CPU time between them (a thread born in
                            // between counts from 0; one that ended in between is missed)
};
CpuUse cpuBetween(const CpuSnapshot& before, const CpuSnapshot& after);

}  // namespace sky::bench
