#pragma once
/// \file
/// \brief A lattice power-transmission tower built from thin members: four tapered legs,
/// horizontal ring members and X bracing on every face of every panel, and horizontal
/// cross-arms. Tower frame: origin at the footprint centre on the ground, z up, x along the
/// line (the direction `yaw_rad` points to), cross-arms along ±y.
/// Thread safety: value type.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/planning/shapes.hpp"

namespace gesture_formation::planning {

/// \brief A horizontal cross-arm through the tower axis along the tower's y axis.
struct CrossArmSpec {
  double height_m = 25.0;       ///< height of the arm's axis above the base, (0, tower height]
  double half_length_m = 6.0;   ///< from the tower axis to each tip, > 0
  double section_m = 0.4;       ///< square cross-section edge, > 0
};

/// \brief Dimensions of a lattice tower. Defaults: a ~30 m suspension tower.
struct LatticeTowerSpec {
  std::string name;
  Eigen::Vector3d base_world = Eigen::Vector3d::Zero();  ///< footprint centre on the ground
  double yaw_rad = 0.0;          ///< direction of the tower's x axis (along the line)
  double height_m = 30.0;        ///< > 0
  double base_width_m = 6.0;     ///< leg spacing at the base (square footprint), > 0
  double top_width_m = 1.5;      ///< leg spacing at the top, (0, base_width_m]
  int panels = 8;                ///< bracing panels stacked between base and top, ≥ 1
  double leg_radius_m = 0.12;    ///< > 0
  double brace_radius_m = 0.04;  ///< ring and diagonal members, > 0
  std::vector<CrossArmSpec> cross_arms;
  /// Planning keep-out: close the four faces (one thin plate per panel and face, as wide as
  /// the panel's bottom edge) and the top, so that no path leads between the members into
  /// the tower body. Real towers are not flown through: the openings between braces are
  /// about a metre wide, less than a UAV's safe clearance under gusts.
  bool keep_out = false;
  double keep_out_thickness_m = 0.1;  ///< plate thickness, > 0

  /// Every problem, each naming the field; empty when valid.
  std::vector<std::string> validate() const;
  /// The same problems, typed {key, message}, keys relative to the tower (`height_m`,
  /// `cross_arms[0].height_m`): ranges from latticeTowerFields() / crossArmFields() and the rules
  /// between fields (top_width_m ≤ base_width_m, every arm at or below the tower's height).
  std::vector<common::ConfigError> problems() const;

  /// \brief World position of a cross-arm tip (side +1: tower +y, −1: tower −y), lowered
  /// by `drop_m` (an insulator string). Requires a valid arm index.
  Eigen::Vector3d armTip(std::size_t arm, int side, double drop_m = 0.0) const;
};

/// \brief LatticeTowerSpec's numbers (keys relative to the tower) with their ranges: the only
/// place they are written, used by validate() and by the scenario reader.
const common::FieldTable<LatticeTowerSpec>& latticeTowerFields();
/// \brief CrossArmSpec's numbers (keys relative to the arm), likewise.
const common::FieldTable<CrossArmSpec>& crossArmFields();

/// \brief The tower's members as primitives (legs and bracing: cylinders; arms: boxes).
PrimitiveSet towerPrimitives(const LatticeTowerSpec& spec);

}  // namespace gesture_formation::planning
