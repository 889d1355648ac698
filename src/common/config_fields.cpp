#include "gesture_formation/common/config_fields.hpp"

#include <cmath>

#include "gesture_formation/common/format_number.hpp"

namespace gesture_formation::common {

std::string rangeRequirement(const Range& range) {
  const bool lo = std::isfinite(range.lo);
  const bool hi = std::isfinite(range.hi);
  if (!lo && !hi) return "finite";
  if (!hi) return std::string(range.lo_inclusive ? ">= " : "> ") + formatNumber(range.lo);
  if (!lo) return std::string(range.hi_inclusive ? "<= " : "< ") + formatNumber(range.hi);
  return "in " + range.describe();
}

std::string rangeProblem(const Range& range, double value) {
  return "must be " + rangeRequirement(range) + ", got " + formatNumber(value);
}

std::string rangeProblem(const Range& range, int value) {
  return "must be " + rangeRequirement(range) + ", got " + std::to_string(value);
}

void checkRule(std::vector<ConfigError>& problems, bool ok, const std::string& key, double value,
               const std::string& what) {
  if (!ok) problems.push_back({key, what + ", got " + formatNumber(value)});
}

void addProblems(ConfigReader& r, const std::string& prefix, const std::vector<ConfigError>& problems) {
  for (const auto& p : problems) r.addError(prefix + p.key, p.message);
}

std::vector<std::string> problemLines(const std::vector<ConfigError>& problems, const std::string& prefix) {
  std::vector<std::string> lines;
  lines.reserve(problems.size());
  for (const auto& p : problems) lines.push_back(prefix + p.key + " " + p.message);
  return lines;
}

}  // namespace gesture_formation::common
