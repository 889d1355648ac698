#pragma once
// Small helpers for the sim configs' validate() (private to src/sim).
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace gesture_formation::sim::detail {

inline std::string num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

/// Appends "<prefix><name> must be <rule>, got <v>" when !(ok && finite).
inline void check(std::vector<std::string>& e, bool ok, double v, const std::string& prefix, const char* name,
                  const char* rule) {
  if (!(ok && std::isfinite(v))) e.push_back(prefix + name + " must be " + rule + ", got " + num(v));
}

}  // namespace gesture_formation::sim::detail
