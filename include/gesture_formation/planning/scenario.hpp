#pragma once
/// \file
/// \brief The static world of a scenario file (`config/scenarios/*.yaml`, docs/planning.md):
/// map extent and resolution, ground, boxes, vertical cylinders, lattice towers and conductor
/// lines. The loader owns the top-level sections `map`, `ground`, `boxes`, `cylinders`,
/// `towers` and `conductors`; it checks every key in them (unknown keys are errors) and
/// ignores every other top-level section, which belongs to other components (worker route,
/// UAVs, mission). All coordinates are in the world frame (x east, y north, z up), metres.
/// Thread safety: value types; loading has no shared state.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/common/result.hpp"
#include "gesture_formation/planning/catenary.hpp"
#include "gesture_formation/planning/lattice_tower.hpp"
#include "gesture_formation/planning/shapes.hpp"

namespace gesture_formation::planning {

/// \brief Extent and resolution of the occupancy map.
struct MapConfig {
  double resolution_m = 0.2;  ///< voxel edge, [0.01, 10] m
  /// Region the map (and its distance field) covers; obstacles outside it are clipped.
  Aabb bounds{Eigen::Vector3d(-10, -10, 0), Eigen::Vector3d(10, 10, 10)};
  /// Optional OctoMap `.bt` file merged into the map (path resolved against the scenario
  /// file's folder). Its resolution must equal `resolution_m`. Empty: none.
  std::string octomap_file;

  /// Every problem, each naming the field; empty when valid.
  std::vector<std::string> validate() const;
  /// The same problems, typed {key, message}: `map.resolution_m` outside its range
  /// (mapConfigFields()), `map.bounds` not finite, empty or over 1e8 voxels.
  std::vector<common::ConfigError> problems() const;
};

/// \brief MapConfig's numbers (`map.resolution_m`) with their ranges: the only place they are
/// written, used by validate() and by the scenario reader.
const common::FieldTable<MapConfig>& mapConfigFields();

/// \brief The ground: everything at or below `height_m` is solid (within the map bounds).
struct GroundSpec {
  bool enabled = false;
  double height_m = 0.0;
};

/// \brief Radius (m) of the insulator string drawn between a cross-arm tip and a conductor
/// attachment point lowered by `drop_m`.
constexpr double kInsulatorRadiusM = 0.1;

/// \brief A scenario's static world.
struct Scenario {
  std::string source;  ///< the file it was loaded from
  MapConfig map;
  GroundSpec ground;
  std::vector<OrientedBox> boxes;
  std::vector<Cylinder> cylinders;
  std::vector<LatticeTowerSpec> towers;
  std::vector<ConductorSpec> conductors;
  /// Insulator strings (arm tip → attachment), from conductor ends given as tower references.
  std::vector<Cylinder> insulators;

  /// \brief All solids except the ground, towers and conductors expanded. Conductors were
  /// checked at load time, so expansion cannot fail here (a bad one is skipped).
  PrimitiveSet primitives() const;
};

/// \brief Loads a scenario file. On failure the reason holds every problem, one per line,
/// each as "file:line: key: message".
common::Result<Scenario> loadScenario(const std::string& path);

/// \brief As loadScenario, from YAML text (`source_name` is used in messages; a relative
/// `map.octomap_file` resolves against the current directory).
common::Result<Scenario> parseScenario(const std::string& yaml, const std::string& source_name);

}  // namespace gesture_formation::planning
