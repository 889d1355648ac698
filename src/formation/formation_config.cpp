#include "gesture_formation/formation/formation_config.hpp"

#include <cmath>
#include <limits>

namespace gesture_formation::formation {

using common::ConfigReader;
using common::Range;

std::vector<std::string> FormationConfig::validate() const {
  std::vector<std::string> e = limits.validate();
  for (auto& s : validateParams(params, limits)) e.push_back(s);
  for (auto& s : worker_heading.validate()) e.push_back(s);
  for (auto& s : duplicates.validate()) e.push_back(s);
  return e;
}

namespace {

void readUav(ConfigReader& r, const std::string& key, UavObservation& o) {
  r.readDouble(key + ".beta_deg", o.beta_deg, Range::openClosed(-180.0, 180.0));
  r.readDouble(key + ".gamma_deg", o.gamma_deg, Range::openClosed(-90.0, 90.0));
  r.readDouble(key + ".distance_m", o.distance_m, Range::positive());
}

/// Records "key: message" for a validate() line "key message".
void addValidationError(ConfigReader& r, const std::string& line) {
  const auto sp = line.find(' ');
  r.addError(line.substr(0, sp), sp == std::string::npos ? std::string("invalid") : line.substr(sp + 1));
}

}  // namespace

FormationConfig readFormationConfig(ConfigReader& r) {
  FormationConfig c;
  FormationLimits& l = c.limits;
  r.readDouble("limits.gamma_min_deg", l.gamma_min_deg, Range{-90.0, 90.0, false, false});
  r.readDouble("limits.gamma_max_deg", l.gamma_max_deg, Range{-90.0, 90.0, false, false});
  r.readDouble("limits.distance_min_m", l.distance_min_m, Range::positive());
  r.readDouble("limits.distance_max_m", l.distance_max_m, Range::positive());
  r.readDouble("limits.safety_distance_m", l.safety_distance_m, Range::positive());

  readUav(r, "leader", c.params.leader);
  if (r.has("followers") || r.mode() == ConfigReader::MissingKeys::kError) {
    const FormationParams table2;
    std::vector<UavObservation> followers;
    if (!r.has("followers[0]")) {
      const YAML::Node n = r.node("followers");  // reports a missing key in kError mode
      if (n.IsDefined() && !(n.IsSequence() && n.size() == 0) && !n.IsNull()) {
        r.addError("followers", "expected a list of {beta_deg, gamma_deg, distance_m}");
      }
    }
    for (std::size_t i = 0; r.has("followers[" + std::to_string(i) + "]"); ++i) {
      const std::string key = "followers[" + std::to_string(i) + "]";
      UavObservation f = i < table2.followers.size()
                             ? table2.followers[i]
                             : UavObservation{std::numeric_limits<double>::quiet_NaN(), 0.0, 8.0};
      readUav(r, key, f);
      if (std::isnan(f.beta_deg) && !r.has(key + ".beta_deg")) {
        if (r.mode() != ConfigReader::MissingKeys::kError) {
          r.addError(key + ".beta_deg", "missing (Table II has defaults for the first two followers only)");
        }
        f.beta_deg = 0.0;  // keeps the rest of the checks meaningful
      }
      followers.push_back(f);
    }
    c.params.followers = followers;
  }

  std::string mode = toString(c.worker_heading.mode);
  r.readString("worker_heading.mode", mode, {"constant", "motion", "operator"});
  c.worker_heading.mode = mode == "motion"     ? WorkerHeadingMode::kMotion
                          : mode == "operator" ? WorkerHeadingMode::kOperator
                                               : WorkerHeadingMode::kConstant;
  r.readDouble("worker_heading.constant_heading_deg", c.worker_heading.constant_heading_deg, Range::any());
  r.readDouble("worker_heading.speed_low_mps", c.worker_heading.speed_low_mps, Range::nonNegative());
  r.readDouble("worker_heading.speed_high_mps", c.worker_heading.speed_high_mps, Range::positive());
  r.readInt("duplicates.window_per_sender", c.duplicates.window_per_sender, Range::atLeast(1));
  r.readInt("duplicates.max_senders", c.duplicates.max_senders, Range::atLeast(1));

  // Single-key ranges were checked while reading (a bad value keeps its default); add the
  // cross-field rules: elevations and distances within the limits.
  for (const auto& line : c.validate()) addValidationError(r, line);
  return c;
}

common::Result<FormationConfig> loadFormationConfig(const std::string& path, ConfigReader::MissingKeys mode,
                                                    std::vector<std::string>* warnings) {
  ConfigReader r = ConfigReader::fromFile(path, mode);
  const FormationConfig c = readFormationConfig(r);
  if (warnings) {
    for (const auto& k : r.unusedKeys()) warnings->push_back(path + ": unknown key '" + k + "' ignored");
  }
  if (!r.ok()) return common::Result<FormationConfig>::fail(r.errorReport());
  return common::Result<FormationConfig>::ok(c);
}

}  // namespace gesture_formation::formation
