#pragma once
// The whole mission of a scenario file for the simulation nodelets (SimUav, SimWorld); the
// nodelets that fly read only its product settings (config_sources.hpp, loadOnboard).
#include <string>

#include "config_sources.hpp"
#include "gesture_formation/sim/mission_config.hpp"

namespace gesture_formation::nodelets {

/// Loads the mission of `mission_file` (every problem into `params`), with the fault profile of
/// the optional ~faults_file merged in (as `gfctl simulate --faults FILE`; every nodelet of a
/// simulation gets the same pair).
inline bool loadMission(const std::string& mission_file, ParamLoader& params, sim::MissionConfig& out) {
  std::string faults_file;
  params.loadOptional("faults_file", faults_file, "");
  auto m = faults_file.empty() ? sim::loadMissionConfig(mission_file) : sim::loadMissionConfig(mission_file, faults_file);
  if (!m) {
    params.addError((faults_file.empty() ? "mission_file: " : "mission_file + faults_file: ") + m.reason());
    return false;
  }
  out = std::move(*m);
  return true;
}

}  // namespace gesture_formation::nodelets
