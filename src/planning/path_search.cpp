#include "gesture_formation/planning/path_search.hpp"

#include <algorithm>
#include <cmath>
#include <queue>
#include <sstream>

namespace gesture_formation::planning {

namespace {
/// Weighted A* (ε = 1.5): at most 1.5× the shortest grid path, far fewer expansions; the
/// shortcut pass straightens the result. Deterministic.
constexpr float kHeuristicWeight = 1.5f;
}  // namespace

std::optional<Eigen::Vector3d> projectToClearance(const DistanceField& field, const OccupancyMap& map,
                                                  const Eigen::Vector3d& p, double clearance_m, double max_move_m) {
  if (!p.allFinite()) return std::nullopt;
  if (field.clearance(p) >= clearance_m) return p;
  const double res = map.resolution();
  // 1. Gradient ascent (the field's gradient points away from the nearest obstacle).
  Eigen::Vector3d x = p;
  const int max_steps = static_cast<int>(std::ceil(2.0 * max_move_m / res)) + 4;
  for (int step = 0; step < max_steps; ++step) {
    Eigen::Vector3d grad;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d e = Eigen::Vector3d::Unit(i) * res;
      grad(i) = field.clearance(x + e) - field.clearance(x - e);
    }
    const double gn = grad.norm();
    if (!(gn > 1e-9)) break;
    x += grad * (0.5 * res / gn);
    if ((x - p).norm() > max_move_m) break;
    if (field.clearance(x) >= clearance_m) {
      // Pull back towards p along the way as far as the clearance still holds (bisection),
      // so that the result is close to the nearest clear point.
      double lo = 0.0, hi = 1.0;
      for (int it = 0; it < 8; ++it) {
        const double mid = 0.5 * (lo + hi);
        if (field.clearance(p + (x - p) * mid) >= clearance_m) hi = mid; else lo = mid;
      }
      return Eigen::Vector3d(p + (x - p) * hi);
    }
  }
  // 2. Exhaustive search in cubic shells of voxel centres around p (rare: pockets).
  const VoxelIndex c = map.voxelOf(p);
  const int rmax = static_cast<int>(std::ceil(max_move_m / res));
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector3d best_p = p;
  for (int r = 1; r <= rmax; ++r) {
    if ((r - 1) * res > best) break;  // every further shell is farther than the best found
    for (int dz = -r; dz <= r; ++dz) {
      for (int dy = -r; dy <= r; ++dy) {
        for (int dx = -r; dx <= r; ++dx) {
          if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != r) continue;
          const Eigen::Vector3d q = map.centerOf(c + VoxelIndex(dx, dy, dz));
          const double d = (q - p).norm();
          if (d >= best || d > max_move_m) continue;
          if (field.clearance(q) >= clearance_m) {
            best = d;
            best_p = q;
          }
        }
      }
    }
  }
  if (std::isfinite(best)) return best_p;
  return std::nullopt;
}

double segmentClearance(const DistanceField& field, double res, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double len = (b - a).norm();
  const int n = std::max(1, static_cast<int>(std::ceil(len / (0.5 * res))));
  double m = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= n; ++i) m = std::min(m, field.clearance(a + (b - a) * (static_cast<double>(i) / n)));
  return m;
}

bool segmentClear(const DistanceField& field, double res, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                  double clearance_m) {
  const double len = (b - a).norm();
  if (!std::isfinite(len)) return false;
  const int n = std::max(1, static_cast<int>(std::ceil(len / (0.5 * res))));
  // Ends first (most likely to fail), then the interior.
  if (field.clearance(b) < clearance_m || field.clearance(a) < clearance_m) return false;
  for (int i = 1; i < n; ++i) {
    if (field.clearance(a + (b - a) * (static_cast<double>(i) / n)) < clearance_m) return false;
  }
  return true;
}

namespace {

std::string noPathReason(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double clearance_m, double margin_m,
                         int expansions, long pocket_voxels) {
  std::ostringstream os;
  os << "A*: no path with clearance " << clearance_m << " m from (" << a.transpose() << ") to (" << b.transpose()
     << ") within " << margin_m << " m (" << expansions << " expansions";
  if (pocket_voxels > 0) os << "; the goal lies in a closed pocket of " << pocket_voxels << " voxels";
  os << ")";
  return os.str();
}

/// Greedy shortcut: from each kept point jump to the farthest point in sight (clear by
/// `clearance_m` and outside the keep-out tube).
std::vector<Eigen::Vector3d> shortcutPath(const std::vector<Eigen::Vector3d>& raw, const DistanceField& field, double res,
                                          double clearance_m, const KeepOutTube& keep_out) {
  std::vector<Eigen::Vector3d> out{raw.front()};
  std::size_t i = 0;
  while (i + 1 < raw.size()) {
    std::size_t j = raw.size() - 1;
    while (j > i + 1 && !(segmentClear(field, res, raw[i], raw[j], clearance_m) && keep_out.segmentOutside(raw[i], raw[j]))) {
      --j;
    }
    out.push_back(raw[j]);
    i = j;
  }
  return out;
}

}  // namespace

common::Result<std::vector<Eigen::Vector3d>> GridPathSearch::search(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                                    double clearance_m, double shortcut_clearance_m,
                                                                    double margin_m, int max_expansions, Stats* stats,
                                                                    const KeepOutTube& keep_out) const {
  using R = common::Result<std::vector<Eigen::Vector3d>>;
  if (!a.allFinite() || !b.allFinite()) return R::fail("A*: non-finite start or goal");
  const double res = map_.resolution();
  const VoxelIndex origin = map_.gridOrigin();
  const VoxelIndex size = map_.gridSize();
  const VoxelIndex va = map_.voxelOf(a) - origin;
  const VoxelIndex vb = map_.voxelOf(b) - origin;
  const int m = static_cast<int>(std::ceil(margin_m / res));
  VoxelIndex lo = va.cwiseMin(vb) - VoxelIndex::Constant(m);
  VoxelIndex hi = va.cwiseMax(vb) + VoxelIndex::Constant(m);
  lo = lo.cwiseMax(VoxelIndex::Zero());
  hi = hi.cwiseMin(size - VoxelIndex::Ones());
  const int lx = lo.x(), ly = lo.y(), lz = lo.z(), hx = hi.x(), hy = hi.y(), hz = hi.z();
  const auto inBox = [&](int x, int y, int z) { return x >= lx && y >= ly && z >= lz && x <= hx && y <= hy && z <= hz; };
  if (!inBox(va.x(), va.y(), va.z()) || !inBox(vb.x(), vb.y(), vb.z())) return R::fail("A*: start or goal outside the map grid");
  const int nx = hx - lx + 1, ny = hy - ly + 1, nz = hz - lz + 1;
  // A voxel the search may enter: clear of obstacles and outside the keep-out tube.
  const auto enterable = [&](int x, int y, int z) {
    if (field_.atLocal(x, y, z) < clearance_m) return false;
    return !keep_out.active() || !keep_out.contains(map_.centerOf(VoxelIndex(x, y, z) + origin));
  };
  const std::size_t total = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) * static_cast<std::size_t>(nz);
  if (total > 20'000'000) return R::fail("A*: search box too large (" + std::to_string(total) + " voxels)");
  const auto lin = [&](int x, int y, int z) { return static_cast<std::int32_t>((x - lx) + nx * ((y - ly) + ny * (z - lz))); };
  // Scratch arrays are allocated once (grown when needed) and invalidated by a generation
  // stamp instead of being cleared: a search costs its expansions, not its box volume.
  if (stamp_.size() < total) {
    stamp_.assign(total, 0);
    g_.resize(total);
    parent_.resize(total);
    closed_.resize(total);
  }
  if (++generation_ == 0) {  // wrapped: clear once
    std::fill(stamp_.begin(), stamp_.end(), 0u);
    generation_ = 1;
  }
  const std::uint32_t gen = generation_;
  const auto touch = [&](std::int32_t i) {
    const auto u = static_cast<std::size_t>(i);
    if (stamp_[u] != gen) {
      stamp_[u] = gen;
      g_[u] = std::numeric_limits<float>::infinity();
      parent_[u] = -1;
      closed_[u] = 0;
    }
  };
  const std::int32_t start = lin(va.x(), va.y(), va.z()), goal = lin(vb.x(), vb.y(), vb.z());
  using Entry = std::pair<float, std::int32_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  const int gx = vb.x(), gy = vb.y(), gz = vb.z();
  const auto h = [&](int x, int y, int z) {
    return static_cast<float>(std::sqrt(static_cast<double>((x - gx) * (x - gx) + (y - gy) * (y - gy) + (z - gz) * (z - gz))));
  };
  touch(start);
  touch(goal);
  g_[static_cast<std::size_t>(start)] = 0.0f;
  open.emplace(kHeuristicWeight * h(va.x(), va.y(), va.z()), start);
  int expansions = 0;
  bool found = false;
  long pocket_voxels = 0;  // > 0: the goal's closed pocket (no path), found by the flood below
  // Breadth-first flood from the goal through the voxels the search may enter (clear, or the
  // start): the number of voxels of the goal's pocket when it closes without reaching the
  // start within kPocketMaxVoxels, else 0 (unknown: the search goes on).
  const auto goalPocket = [&]() -> long {
    if (flood_stamp_.size() < total) flood_stamp_.assign(total, 0u);
    if (++flood_generation_ == 0) {
      std::fill(flood_stamp_.begin(), flood_stamp_.end(), 0u);
      flood_generation_ = 1;
    }
    const std::uint32_t fg = flood_generation_;
    flood_queue_.clear();
    flood_queue_.push_back(goal);
    flood_stamp_[static_cast<std::size_t>(goal)] = fg;
    for (std::size_t head = 0; head < flood_queue_.size(); ++head) {
      const std::int32_t c = flood_queue_[head];
      const int fx = lx + c % nx, fy = ly + (c / nx) % ny, fz = lz + c / (nx * ny);
      for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const int x = fx + dx, y = fy + dy, z = fz + dz;
            if (!inBox(x, y, z)) continue;
            const std::int32_t ni = lin(x, y, z);
            if (flood_stamp_[static_cast<std::size_t>(ni)] == fg) continue;
            if (ni == start) return 0;  // connected
            if (!enterable(x, y, z)) continue;
            flood_stamp_[static_cast<std::size_t>(ni)] = fg;
            flood_queue_.push_back(ni);
            if (flood_queue_.size() > static_cast<std::size_t>(kPocketMaxVoxels)) return 0;  // too large to tell
          }
        }
      }
    }
    return static_cast<long>(flood_queue_.size());
  };
  // The last goal lay in a closed pocket (a reference in a lattice stays there): flood first; the
  // answer does not depend on when the flood runs, only the cost does.
  const bool pocket_checked = pocket_hint_;
  if (pocket_checked && (pocket_voxels = goalPocket()) > 0) open = decltype(open)();  // no path
  while (!open.empty()) {
    const std::int32_t cur = open.top().second;
    open.pop();
    if (closed_[static_cast<std::size_t>(cur)]) continue;
    closed_[static_cast<std::size_t>(cur)] = 1;
    if (cur == goal) {
      found = true;
      break;
    }
    if (++expansions > max_expansions) break;
    if (expansions == kPocketCheckAfter && !pocket_checked && (pocket_voxels = goalPocket()) > 0) break;
    const int cx = lx + cur % nx, cy = ly + (cur / nx) % ny, cz = lz + cur / (nx * ny);
    const float gc = g_[static_cast<std::size_t>(cur)];
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const int x = cx + dx, y = cy + dy, z = cz + dz;
          if (!inBox(x, y, z)) continue;
          const std::int32_t ni = lin(x, y, z);
          touch(ni);
          if (closed_[static_cast<std::size_t>(ni)]) continue;
          if (ni != goal && !enterable(x, y, z)) continue;
          const float ng = gc + static_cast<float>(std::sqrt(static_cast<double>(dx * dx + dy * dy + dz * dz)));
          if (ng < g_[static_cast<std::size_t>(ni)]) {
            g_[static_cast<std::size_t>(ni)] = ng;
            parent_[static_cast<std::size_t>(ni)] = cur;
            open.emplace(ng + kHeuristicWeight * h(x, y, z), ni);
          }
        }
      }
    }
  }
  if (stats) stats->expansions = expansions;
  pocket_hint_ = pocket_voxels > 0;
  if (!found) return R::fail(noPathReason(a, b, clearance_m, margin_m, expansions, pocket_voxels));
  std::vector<Eigen::Vector3d> raw;
  for (std::int32_t i = goal; i != -1; i = parent_[static_cast<std::size_t>(i)]) {
    const VoxelIndex v(lx + i % nx + origin.x(), ly + (i / nx) % ny + origin.y(), lz + i / (nx * ny) + origin.z());
    raw.push_back(map_.centerOf(v));
  }
  std::reverse(raw.begin(), raw.end());
  raw.front() = a;
  raw.back() = b;
  if (stats) stats->raw_waypoints = static_cast<int>(raw.size());
  return R::ok(shortcutPath(raw, field_, res, shortcut_clearance_m, keep_out));
}

}  // namespace gesture_formation::planning
