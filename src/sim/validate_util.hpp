#pragma once
// Small helpers for the sim configs' validate() (private to src/sim).
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "gesture_formation/common/format_number.hpp"

namespace gesture_formation::sim::detail {

/// Appends "<prefix><name> must be <rule>, got <v>" when !(ok && finite).
inline void check(std::vector<std::string>& e, bool ok, double v, const std::string& prefix, const char* name,
                  const char* rule) {
  if (!(ok && std::isfinite(v))) e.push_back(prefix + name + " must be " + rule + ", got " + common::formatNumber(v));
}

}  // namespace gesture_formation::sim::detail
