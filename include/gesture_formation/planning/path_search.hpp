#pragma once
/// \file
/// \brief Stage 2 of the planner (docs/planning.md §5): projection of reference points out of
/// obstacles onto the distance field, straight-segment validity, and A* on the voxel grid
/// (26-connected, free = distance-field value at the voxel centre ≥ the clearance) for the
/// segments that are blocked. The OMPL alternative (RRT-Connect in R³ with the same validity)
/// lives in bench/bench_planner.cpp only; the decision and figures are in docs/planning.md.
///
/// Clearances are distances to occupied voxel centres (the DistanceField's lower bound; true
/// distance ≥ the value read). Thread safety: const methods of GridPathSearch are not
/// thread-safe (reused scratch buffers); the free functions are.

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/shapes.hpp"

namespace gesture_formation::planning {

/// \brief The nearest point to p (world) whose distance-field clearance is ≥ clearance_m,
/// within max_move_m: gradient ascent on the field (central differences, one voxel steps),
/// then, if that stalls in a pocket, an exhaustive search of voxel centres in growing cubic
/// shells. nullopt when nothing within max_move_m qualifies. Returns p itself when it is
/// already clear.
std::optional<Eigen::Vector3d> projectToClearance(const DistanceField& field, const OccupancyMap& map,
                                                  const Eigen::Vector3d& p_world, double clearance_m, double max_move_m);

/// \brief True when every point of the segment a → b sampled every resolution/2 has field
/// clearance ≥ clearance_m (so the true distance to every voxel centre is ≥ clearance_m at
/// those points).
bool segmentClear(const DistanceField& field, double resolution_m, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                  double clearance_m);

/// \brief Smallest field clearance (m) along a → b sampled every resolution/2.
double segmentClearance(const DistanceField& field, double resolution_m, const Eigen::Vector3d& a, const Eigen::Vector3d& b);

/// \brief A tube the path must not enter besides the obstacles: every point within radius_m of
/// the polyline — the worker's keep-out along his predicted positions (`worker_safety_distance_m`
/// + the QP buffer). radius_m ≤ 0 or no points: none.
struct KeepOutTube {
  std::vector<Eigen::Vector3d> polyline_world;
  double radius_m = 0.0;
  bool active() const { return radius_m > 0.0 && !polyline_world.empty(); }
  /// Distance from p to the polyline (infinity without points).
  double distance(const Eigen::Vector3d& p) const { return distanceToPolyline(polyline_world, p); }
  /// Distance from the segment a → b to the polyline (infinity without points).
  double distance(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const { return distanceToPolyline(polyline_world, a, b); }
  bool contains(const Eigen::Vector3d& p) const { return active() && distance(p) < radius_m; }
  /// True when the segment a → b stays outside the tube (inactive: always).
  bool segmentOutside(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
    return !active() || distance(a, b) >= radius_m;
  }
};

/// \brief Weighted A* (ε = 1.5) between two points on the voxel grid inside a box around them.
class GridPathSearch {
 public:
  GridPathSearch(const OccupancyMap& map, const DistanceField& field) : map_(map), field_(field) {}

  struct Stats {
    int expansions = 0;
    int raw_waypoints = 0;
  };

  /// \brief Path a → b (both included, world frame) through voxel centres whose clearance is
  /// ≥ clearance_m, inside the box around a, b grown by margin_m (clipped to the map grid),
  /// shortcut wherever a straight piece stays ≥ shortcut_clearance_m. The start and goal
  /// voxels count as free. Fails when the goal is unreachable within the box or the budget.
  /// After kPocketCheckAfter expansions without reaching the goal, a breadth-first flood from
  /// the goal (at most kPocketMaxVoxels voxels, same connectivity) checks whether the goal lies
  /// in a closed pocket that does not hold the start — e.g. inside a tower's lattice — and
  /// fails at once if so, instead of spending the whole budget on the start's side: the result
  /// is the same (no path exists), only cheaper (docs/planning.md §10). When the previous
  /// search's goal lay in a closed pocket, the flood runs before the first expansion (a goal in a
  /// pocket tends to stay there from one replanning to the next); same result, cheaper again. With `keep_out`, voxel
  /// centres inside the tube are not free either (the goal's voxel still counts as free) and
  /// shortcuts stay outside it; the caller shrinks the tube when a or b lies inside it.
  common::Result<std::vector<Eigen::Vector3d>> search(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double clearance_m,
                                                      double shortcut_clearance_m, double margin_m, int max_expansions,
                                                      Stats* stats = nullptr, const KeepOutTube& keep_out = {}) const;

 private:
  const OccupancyMap& map_;
  const DistanceField& field_;
  mutable std::vector<std::uint32_t> stamp_;
  mutable std::uint32_t generation_ = 0;
  mutable std::vector<float> g_;
  mutable std::vector<std::int32_t> parent_;
  mutable std::vector<std::uint8_t> closed_;
  mutable std::vector<std::uint32_t> flood_stamp_;
  mutable std::uint32_t flood_generation_ = 0;
  mutable std::vector<std::int32_t> flood_queue_;
  mutable bool pocket_hint_ = false;  ///< the last search ended in a closed pocket

 public:
  static constexpr int kPocketCheckAfter = 20'000;
  static constexpr int kPocketMaxVoxels = 60'000;
};

}  // namespace gesture_formation::planning
