#pragma once
// What the benchmark programs print about the machine they ran on, and the CPU-time clock they time
// with (one place for bench_corridors, bench_planner, bench_mapping).
#include <cstdio>
#include <ctime>
#include <string>

namespace gf_bench {

/// The calling thread's CPU time [ms] (CLOCK_THREAD_CPUTIME_ID): on a shared machine what a piece of
/// work costs, where its wall time is what the neighbours left.
inline double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

/// The 1-minute load average ("?" when /proc/loadavg cannot be read).
inline std::string loadAverage() {
  std::FILE* f = std::fopen("/proc/loadavg", "r");
  if (f == nullptr) return "?";
  char buf[64] = {0};
  const bool ok = std::fgets(buf, sizeof buf, f) != nullptr;
  std::fclose(f);
  std::string s = ok ? buf : "?";
  return s.substr(0, s.find(' '));
}

/// The first "model name" of /proc/cpuinfo ("?" when there is none).
inline std::string cpuModel() {
  std::FILE* f = std::fopen("/proc/cpuinfo", "r");
  if (f == nullptr) return "?";
  char line[256];
  std::string model = "?";
  while (std::fgets(line, sizeof line, f) != nullptr) {
    const std::string s(line);
    if (s.rfind("model name", 0) == 0 && s.find(':') != std::string::npos) {
      model = s.substr(s.find(':') + 2);
      model.erase(model.find_last_not_of(" \n") + 1);
      break;
    }
  }
  std::fclose(f);
  return model;
}

}  // namespace gf_bench
