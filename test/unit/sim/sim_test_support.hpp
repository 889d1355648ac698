#pragma once
// Shared by the sim unit tests: an empty 60 × 60 × 20 m world with ground, the open-field
// mission, and the test-only stand-in planner (the plan is the stage-1 reference itself, safe in
// an empty world; the product uses planning::UavPlanner) that records every request it gets.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/sim/mission_runner.hpp"

namespace gesture_formation::sim::test {

/// Empty 60 × 60 × 20 m world with ground, 0.4 m voxels.
struct EmptyWorld {
  planning::OccupancyMap map;
  planning::DistanceField field;
  EmptyWorld() : map(makeMap()), field(map) {}
  static planning::OccupancyMap makeMap() {
    planning::MapConfig mc;
    mc.resolution_m = 0.4;
    mc.bounds = planning::Aabb{Eigen::Vector3d(-30, -30, 0), Eigen::Vector3d(30, 30, 20)};
    return planning::OccupancyMap::fromPrimitives(mc, planning::PrimitiveSet{}, planning::GroundSpec{true, 0.0});
  }
};

/// config/scenarios/open_field.yaml without its operator requests.
inline MissionConfig openFieldWithoutRequests() {
  const auto m = loadMissionConfig(std::string(GF_SOURCE_DIR) + "/config/scenarios/open_field.yaml");
  EXPECT_TRUE(m) << m.reason();
  MissionConfig c = m ? *m : MissionConfig{};
  c.requests.clear();
  return c;
}

/// The plan "fly the reference": its samples are the request's stage-1 reference, velocities by
/// finite differences.
inline planning::PlanResult referenceAsPlan(const planning::PlanRequest& r) {
  planning::PlanResult res;
  res.status = planning::PlanStatus::kOptimized;
  res.trajectory.uav_index = r.uav_index;
  res.trajectory.t0_s = r.t_now_s;
  res.trajectory.dt_s = r.dt_s;
  for (int k = 0; k < r.reference.steps(); ++k) {
    planning::TrajectorySample s;
    s.p_world = r.reference.p_world.col(k);
    const int k1 = std::min(k + 1, r.reference.steps() - 1), k0 = k1 - 1;
    s.v_world = (r.reference.p_world.col(k1) - r.reference.p_world.col(k0)) / r.dt_s;
    s.heading_rad = r.reference.heading_rad(k);
    s.pitch_rad = r.reference.pitch_rad(k);
    res.trajectory.samples.push_back(s);
  }
  return res;
}

/// One request the recording planner got.
struct PlanCall {
  int uav = 0;
  double t_s = 0.0;
  bool constant_reference = false;  ///< every step at one point (hold)
  Eigen::Vector3d reference0 = Eigen::Vector3d::Zero();
  Eigen::Vector3d state_p = Eigen::Vector3d::Zero();
  std::vector<int> avoided;        ///< uav_index of each plan in higher_priority_plans
  std::vector<double> avoided_t0;  ///< and its t0_s
};

/// Test-only planner that records every request: returns the reference as the plan
/// (referenceAsPlan), or with `inner` that planner's plan (the product's, for the statements that
/// need avoidance: the reference alone dodges nobody).
class RecordingPlanner : public MissionPlanner {
 public:
  explicit RecordingPlanner(std::shared_ptr<std::vector<PlanCall>> calls, std::unique_ptr<MissionPlanner> inner = nullptr)
      : calls_(std::move(calls)), inner_(std::move(inner)) {}
  planning::PlanResult plan(const planning::PlanRequest& r) override {
    PlanCall c;
    c.uav = r.uav_index;
    c.t_s = r.t_now_s;
    c.reference0 = r.reference.p_world.col(0);
    c.state_p = r.state.p_world;
    c.constant_reference = true;
    for (int k = 1; k < r.reference.steps(); ++k) {
      c.constant_reference = c.constant_reference && (r.reference.p_world.col(k) - c.reference0).norm() < 1e-12;
    }
    for (const auto& p : r.higher_priority_plans) {
      c.avoided.push_back(p.uav_index);
      c.avoided_t0.push_back(p.t0_s);
    }
    calls_->push_back(c);
    return inner_ ? inner_->plan(r) : referenceAsPlan(r);
  }

 private:
  std::shared_ptr<std::vector<PlanCall>> calls_;
  std::unique_ptr<MissionPlanner> inner_;
};

}  // namespace gesture_formation::sim::test
