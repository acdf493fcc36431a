// Wall-clock and memory measurement shared by every benchmark and stage timer (the path tracer's
// benchmark, pxf bench, the preview's stage times, stats.json).
#pragma once
#include <chrono>
#include <vector>

namespace pxf {

using BenchClock = std::chrono::steady_clock;
inline double elapsed_ms(BenchClock::time_point start) {
  return std::chrono::duration<double, std::milli>(BenchClock::now() - start).count();
}
double median_of(std::vector<double> values);  // the upper median; 0 for none
// Peak resident memory of this process so far (getrusage ru_maxrss), MiB.
double peak_memory_mib();

}  // namespace pxf
