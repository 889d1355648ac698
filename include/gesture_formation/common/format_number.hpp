#pragma once
// One way to print a number in a config error ("... got 0.5"): the stream's default format.
#include <sstream>
#include <string>

namespace gesture_formation::common {

/// \brief `v` as `std::ostream << v` prints it (6 significant digits, "nan", "inf").
inline std::string formatNumber(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

}  // namespace gesture_formation::common
