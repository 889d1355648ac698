#include "gesture_formation/formation/formation_config.hpp"

#include <cmath>
#include <limits>

namespace gesture_formation::formation {

using common::ConfigReader;

std::vector<common::ConfigError> FormationConfig::problems() const {
  std::vector<common::ConfigError> e = limits.problems();
  for (auto& p : paramsProblems(params, limits)) e.push_back(p);
  for (auto& p : worker_heading.problems()) e.push_back(p);
  for (auto& p : duplicates.problems()) e.push_back(p);
  return e;
}

std::vector<std::string> FormationConfig::validate() const { return common::problemLines(problems()); }

namespace {

void readUav(ConfigReader& r, const std::string& key, UavObservation& o) {
  uavObservationFields().readFields(r, key + ".", o);
}

}  // namespace

FormationConfig readFormationConfig(ConfigReader& r) {
  FormationConfig c;
  formationLimitsFields().readFields(r, "", c.limits);

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
  workerHeadingFields().readFields(r, "", c.worker_heading);
  duplicateWindowFields().readFields(r, "", c.duplicates);

  // The rules between fields, always: a key outside its range was reported while reading and
  // kept its default, so these add only what is new (elevations and distances within the limits).
  common::addProblems(r, "", c.problems());
  return c;
}

common::Result<FormationConfig> loadFormationConfig(const std::string& path, ConfigReader::MissingKeys mode,
                                                    std::vector<std::string>* warnings) {
  ConfigReader r = ConfigReader::fromFile(path, mode);
  const FormationConfig c = readFormationConfig(r);
  if (warnings) {
    for (const auto& k : r.unusedKeysOfWholeDocument()) warnings->push_back(path + ": unknown key '" + k + "' ignored");
  }
  if (!r.ok()) return common::Result<FormationConfig>::fail(r.errorReport());
  return common::Result<FormationConfig>::ok(c);
}

}  // namespace gesture_formation::formation
