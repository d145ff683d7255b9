// What the whole-run benchmarks print beside their figures: medians of repeats, and the machine's
// load before and after (this 2-core VM is noisy, so a figure is read with the load it ran under).
#pragma once

#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

namespace fieldrig::bench {

inline double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? 0.0 : values[values.size() / 2];
}

// /proc/loadavg's 1, 5 and 15 minute averages.
inline std::string loadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

}  // namespace fieldrig::bench
