#include "gesture_formation/planning/lattice_tower.hpp"

#include <array>
#include <cmath>

#include <Eigen/Geometry>

namespace gesture_formation::planning {

const common::FieldTable<LatticeTowerSpec>& latticeTowerFields() {
  using C = LatticeTowerSpec;
  using common::Range;
  static const common::FieldTable<LatticeTowerSpec> t{{
      {"height_m", Range::positive(), [](C& c) { return &c.height_m; }},
      {"base_width_m", Range::positive(), [](C& c) { return &c.base_width_m; }},
      {"top_width_m", Range::positive(), [](C& c) { return &c.top_width_m; }},
      {"panels", Range::closed(1, 1000), [](C& c) { return &c.panels; }},
      {"leg_radius_m", Range::positive(), [](C& c) { return &c.leg_radius_m; }},
      {"brace_radius_m", Range::positive(), [](C& c) { return &c.brace_radius_m; }},
      {"keep_out_thickness_m", Range::positive(), [](C& c) { return &c.keep_out_thickness_m; }},
  }};
  return t;
}

const common::FieldTable<CrossArmSpec>& crossArmFields() {
  using C = CrossArmSpec;
  using common::Range;
  static const common::FieldTable<CrossArmSpec> t{{
      {"height_m", Range::positive(), [](C& c) { return &c.height_m; }},
      {"half_length_m", Range::positive(), [](C& c) { return &c.half_length_m; }},
      {"section_m", Range::positive(), [](C& c) { return &c.section_m; }},
  }};
  return t;
}

std::vector<common::ConfigError> LatticeTowerSpec::problems() const {
  std::vector<common::ConfigError> e = latticeTowerFields().rangeProblems(*this);
  if (!base_world.allFinite()) e.push_back({"base", "must be finite"});
  common::checkRule(e, std::isfinite(yaw_rad), "yaw_deg", yaw_rad, "must be finite");
  common::checkRule(e, top_width_m <= base_width_m, "top_width_m", top_width_m, "must be <= base_width_m");
  latticeTowerFields().sortByTableOrder(e);
  for (std::size_t i = 0; i < cross_arms.size(); ++i) {
    const std::string q = "cross_arms[" + std::to_string(i) + "].";
    for (const auto& p : crossArmFields().rangeProblems(cross_arms[i])) e.push_back({q + p.key, p.message});
    common::checkRule(e, cross_arms[i].height_m <= height_m, q + "height_m", cross_arms[i].height_m,
                      "must be <= the tower's height_m");
  }
  return e;
}

std::vector<std::string> LatticeTowerSpec::validate() const {
  const std::string p = name.empty() ? std::string("tower") : "tower '" + name + "'";
  std::vector<std::string> lines;
  for (const auto& line : common::problemLines(problems())) lines.push_back(p + ": " + line);
  return lines;
}

Eigen::Vector3d LatticeTowerSpec::armTip(std::size_t arm, int side, double drop_m) const {
  const CrossArmSpec& a = cross_arms.at(arm);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return base_world + R * Eigen::Vector3d(0.0, side >= 0 ? a.half_length_m : -a.half_length_m, a.height_m - drop_m);
}

PrimitiveSet towerPrimitives(const LatticeTowerSpec& spec) {
  PrimitiveSet set;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(spec.yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  auto world = [&](const Eigen::Vector3d& p_tower) -> Eigen::Vector3d { return spec.base_world + R * p_tower; };
  // Leg k at height h: corners (±w/2, ±w/2) in counter-clockwise order.
  const std::array<Eigen::Vector2d, 4> signs = {Eigen::Vector2d(1, 1), Eigen::Vector2d(-1, 1), Eigen::Vector2d(-1, -1),
                                                Eigen::Vector2d(1, -1)};
  auto corner = [&](int k, double h) -> Eigen::Vector3d {
    const double w = spec.base_width_m + (spec.top_width_m - spec.base_width_m) * h / spec.height_m;
    return world(Eigen::Vector3d(0.5 * w * signs[static_cast<std::size_t>(k)].x(),
                                 0.5 * w * signs[static_cast<std::size_t>(k)].y(), h));
  };
  for (int k = 0; k < 4; ++k) set.cylinders.push_back(Cylinder{corner(k, 0.0), corner(k, spec.height_m), spec.leg_radius_m});
  for (int level = 0; level < spec.panels; ++level) {
    const double h0 = spec.height_m * level / spec.panels;
    const double h1 = spec.height_m * (level + 1) / spec.panels;
    for (int k = 0; k < 4; ++k) {
      const int n = (k + 1) % 4;
      set.cylinders.push_back(Cylinder{corner(k, h1), corner(n, h1), spec.brace_radius_m});  // ring
      set.cylinders.push_back(Cylinder{corner(k, h0), corner(n, h1), spec.brace_radius_m});  // X bracing
      set.cylinders.push_back(Cylinder{corner(n, h0), corner(k, h1), spec.brace_radius_m});
    }
  }
  if (spec.keep_out) {
    const double th = spec.keep_out_thickness_m;
    for (int level = 0; level < spec.panels; ++level) {
      const double h0 = spec.height_m * level / spec.panels;
      const double h1 = spec.height_m * (level + 1) / spec.panels;
      for (int k = 0; k < 4; ++k) {
        const int n = (k + 1) % 4;
        const Eigen::Vector3d b0 = corner(k, h0), b1 = corner(n, h0), t0 = corner(k, h1), t1 = corner(n, h1);
        const Eigen::Vector3d along = (b1 - b0).normalized();
        const Eigen::Vector3d up = (0.5 * (t0 + t1) - 0.5 * (b0 + b1));
        const Eigen::Vector3d up_dir = (up - up.dot(along) * along).normalized();
        OrientedBox plate;
        plate.center_world = 0.25 * (b0 + b1 + t0 + t1);
        plate.size_m = Eigen::Vector3d((b1 - b0).norm(), up.norm(), th);
        plate.R_world_box.col(0) = along;
        plate.R_world_box.col(1) = up_dir;
        plate.R_world_box.col(2) = along.cross(up_dir);
        set.boxes.push_back(plate);
      }
    }
    OrientedBox cap;
    cap.center_world = world(Eigen::Vector3d(0.0, 0.0, spec.height_m));
    cap.size_m = Eigen::Vector3d(spec.top_width_m, spec.top_width_m, th);
    cap.R_world_box = R;
    set.boxes.push_back(cap);
  }
  for (const auto& arm : spec.cross_arms) {
    OrientedBox b;
    b.center_world = world(Eigen::Vector3d(0.0, 0.0, arm.height_m));
    b.size_m = Eigen::Vector3d(arm.section_m, 2.0 * arm.half_length_m, arm.section_m);
    b.R_world_box = R;
    set.boxes.push_back(b);
  }
  return set;
}

}  // namespace gesture_formation::planning
