#include "gesture_formation/sim/site_mapping.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "gesture_formation/comm/map_update.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/planning/uav_planner.hpp"
#include "gesture_formation/sim/random.hpp"

namespace gesture_formation::sim {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const auto idx = static_cast<std::size_t>(std::max(0.0, std::ceil(q * static_cast<double>(v.size())) - 1.0));
  return v[std::min(idx, v.size() - 1)];
}

std::string num(double v) { return std::isfinite(v) ? common::formatDouble(v) : std::string("null"); }

std::string joinLines(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += (out.empty() ? "" : "; ") + l;
  return out;
}

/// The voxel centres (grid of `grid`) whose voxel meets the obstacle's surface at its listed pose:
/// the centre within half a voxel of the solid, and not every corner of the voxel inside it.
std::vector<Eigen::Vector3d> surfaceOf(const UnmappedObstacle& o, const planning::MapConfig& grid) {
  std::vector<Eigen::Vector3d> out;
  const double res = grid.resolution_m;
  const planning::Aabb b = o.boundsAt(0.0).inflated(res);
  const Eigen::Vector3i lo = (b.min_world / res).array().floor().cast<int>();
  const Eigen::Vector3i hi = (b.max_world / res).array().floor().cast<int>();
  for (int k = lo.z(); k <= hi.z(); ++k) {
    for (int j = lo.y(); j <= hi.y(); ++j) {
      for (int i = lo.x(); i <= hi.x(); ++i) {
        const Eigen::Vector3d c = (Eigen::Vector3d(i, j, k).array() + 0.5).matrix() * res;
        if (!grid.bounds.contains(c) || o.distanceAt(c, 0.0) > 0.5 * res) continue;
        bool all_inside = true;
        for (int corner = 0; corner < 8 && all_inside; ++corner) {
          const Eigen::Vector3d d(corner & 1 ? 0.5 : -0.5, corner & 2 ? 0.5 : -0.5, corner & 4 ? 0.5 : -0.5);
          all_inside = o.distanceAt(c + res * d, 0.0) <= 0.0;
        }
        if (!all_inside) out.push_back(c);
      }
    }
  }
  return out;
}

std::string shareJson(const MapShareSummary& s) {
  std::ostringstream os;
  os << "{\"enabled\": " << (s.enabled ? "true" : "false") << ", \"updates_sent\": " << s.updates_sent
     << ", \"updates_merged\": " << s.updates_merged << ", \"updates_lost\": " << s.updates_lost
     << ", \"updates_refused\": " << s.updates_refused << ", \"voxels_sent\": " << s.voxels_sent
     << ", \"changes_deferred\": " << s.changes_deferred << ", \"changes_dropped\": " << s.changes_dropped
     << ", \"voxels_superseded\": " << s.voxels_superseded << ", \"bytes_per_s_p50\": " << num(s.bytes_per_s_p50)
     << ", \"bytes_per_s_max\": " << num(s.bytes_per_s_max) << ", \"age_s_p50\": " << num(s.age_s_p50)
     << ", \"age_s_max\": " << num(s.age_s_max) << ", \"merge_ms_median\": " << num(s.merge_ms_median)
     << ", \"merge_ms_p99\": " << num(s.merge_ms_p99) << "}";
  return os.str();
}

}  // namespace

std::string siteMappingJson(const SiteMappingSummary& s, int indent) {
  const std::string pad(static_cast<std::size_t>(indent), ' '), in = pad + "  ";
  std::ostringstream os;
  os << "{\n" << in << "\"mapping\": " << (s.mapping ? "true" : "false") << ",\n"
     << in << "\"prior_map\": " << (s.prior_map ? "true" : "false") << ",\n"
     << in << "\"camera\": \"" << s.camera << "\",\n"
     << in << "\"clearance_m\": " << num(s.clearance_m) << ",\n"
     << in << "\"depth_frames\": " << s.depth_frames << ",\n"
     << in << "\"coverage\": " << num(s.coverage) << ",\n"
     << in << "\"min_unmapped_distance_m\": " << num(s.min_unmapped_distance_m) << ",\n"
     << in << "\"depth_ms_median\": " << num(s.depth_ms_median) << ",\n"
     << in << "\"integrate_ms_median\": " << num(s.integrate_ms_median) << ",\n"
     << in << "\"integrate_ms_p99\": " << num(s.integrate_ms_p99) << ",\n"
     << in << "\"share\": " << shareJson(s.share) << ",\n"
     << in << "\"obstacles\": [";
  for (std::size_t i = 0; i < s.obstacles.size(); ++i) {
    const UnmappedObstacleRecord& r = s.obstacles[i];
    os << (i ? "," : "") << "\n" << in << "  {\"name\": \"" << r.name << "\", \"surface_voxels\": " << r.surface_voxels
       << ", \"surface_voxels_seen\": " << r.surface_voxels_seen << ", \"coverage\": " << num(r.coverage)
       << ", \"first_seen_s\": " << num(r.first_seen_s) << ", \"first_seen_uav\": " << r.first_seen_uav
       << ", \"avoided_s\": " << num(r.avoided_s) << ", \"sight_to_avoidance_s\": " << num(r.sight_to_avoidance_s)
       << ", \"min_distance_m\": " << num(r.min_distance_m) << ", \"min_distance_uav\": " << r.min_distance_uav
       << ", \"min_distance_t_s\": " << num(r.min_distance_t_s) << "}";
  }
  os << (s.obstacles.empty() ? "" : "\n" + in) << "]\n" << pad << "}";
  return os.str();
}

SiteMapping::SiteMapping(const MissionConfig& mission, const planning::PrimitiveSet& solids, double ground_height_m,
                         std::vector<UnmappedObstacle> unmapped)
    : config_(mission.mapping),
      intrinsics_(mission.estimator.camera),
      clearance_m_(mission.planner.obstacle_clearance_m),
      n_(static_cast<int>(mission.uavs.size())),
      unmapped_(std::move(unmapped)),
      raycaster_(solids, ground_height_m) {}

common::Result<std::unique_ptr<SiteMapping>> SiteMapping::create(const MissionConfig& mission, const planning::MapConfig& grid,
                                                                 std::shared_ptr<const planning::OccupancyMap> prior,
                                                                 const planning::PrimitiveSet& solids, double ground_height_m,
                                                                 std::vector<UnmappedObstacle> unmapped) {
  using R = common::Result<std::unique_ptr<SiteMapping>>;
  const std::vector<std::string> bad = mission.mapping.validate("mission.mapping.");
  if (!bad.empty()) return R::fail(joinLines(bad));
  std::unique_ptr<SiteMapping> s(new SiteMapping(mission, solids, ground_height_m, std::move(unmapped)));
  const auto n = static_cast<std::size_t>(s->n_);
  if (mission.mapping.enabled) {
    for (std::size_t i = 0; i < n; ++i) {
      auto live = mapping::LiveMap::create(mission.mapping.live, grid, mission.mapping.prior_map ? prior : nullptr);
      if (!live) return R::fail("mission.mapping: " + live.reason());
      s->live_.push_back(std::move(*live));
      // Staggered like the replannings: UAV i's frames at (k + i/n) / rate.
      s->next_frame_s_.push_back(static_cast<double>(i) / (static_cast<double>(n) * mission.mapping.rate_hz));
    }
  }
  s->travel_target_.assign(n, Eigen::Vector3d::Constant(kNaN));
  s->travel_dir_.assign(n, {kNaN, kNaN});
  if (mission.mapping.travel_camera_hfov_deg > 0.0) {
    estimation::CameraIntrinsics& c = s->travel_intrinsics_;
    c = estimation::CameraIntrinsics{};  // 640 × 480, centred, square pixels, no distortion
    c.fx = c.fy = 0.5 * c.width_px / std::tan(0.5 * mission.mapping.travel_camera_hfov_deg * M_PI / 180.0);
  }
  s->surfaceVoxels(grid);
  const std::size_t m = s->unmapped_.size();
  s->seen_s_.assign(n, std::vector<double>(m, kNaN));
  s->avoided_s_.assign(n, std::vector<double>(m, kNaN));
  return R::ok(std::move(s));
}

void SiteMapping::surfaceVoxels(const planning::MapConfig& grid) {
  for (const UnmappedObstacle& o : unmapped_) {
    surface_.push_back(surfaceOf(o, grid));
    surface_seen_.emplace_back(surface_.back().size(), false);
    UnmappedObstacleRecord r;
    r.name = o.name;
    r.surface_voxels = static_cast<int>(surface_.back().size());
    records_.push_back(r);
  }
}

const planning::DistanceField* SiteMapping::field(int uav) const {
  if (live_.empty() || uav < 0 || uav >= static_cast<int>(live_.size())) return nullptr;
  return live_[static_cast<std::size_t>(uav)]->field().get();
}

PlannerFactory SiteMapping::plannerFactory(const planning::PlannerConfig& config,
                                           std::shared_ptr<const planning::OccupancyMap> prior_map,
                                           std::shared_ptr<const planning::DistanceField> prior_field) const {
  if (live_.empty()) return uavPlannerFactory(config, std::move(prior_map), std::move(prior_field));
  std::vector<std::shared_ptr<const planning::OccupancyMap>> maps;
  std::vector<std::shared_ptr<const planning::DistanceField>> fields;
  std::vector<std::shared_ptr<const planning::SeenSpace>> seen;
  for (const auto& l : live_) {
    maps.push_back(l->map());
    fields.push_back(l->field());
    seen.push_back(l->seen());
  }
  return [config, maps, fields, seen](int i) -> std::unique_ptr<MissionPlanner> {
    const auto u = static_cast<std::size_t>(i);
    return std::make_unique<planning::UavPlannerAdapter>(
        std::make_unique<planning::UavPlanner>(config, maps.at(u), fields.at(u), seen.at(u)));
  };
}

ObstacleDistance SiteMapping::withUnmapped(ObstacleDistance base) const {
  if (!unmapped_.empty()) base.extra = [this](const Eigen::Vector3d& p) { return unmappedDistanceNow(p); };
  return base;
}

void SiteMapping::openShareLinks(const LinkConfig& link, std::uint64_t seed) {
  if (live_.empty() || !config_.live.share.enabled || !share_links_.empty()) return;
  const auto n = static_cast<std::size_t>(n_);
  std::uint64_t index = 0;
  share_links_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    share_links_[i].resize(n);
    for (std::size_t j = 0; j < n; ++j) {
      if (i != j) share_links_[i][j] = std::make_unique<ShareLink>(link, makeRng(seed, Stream::kMapShare, index++));
    }
    // Staggered like the frames, half a frame period after them.
    next_share_s_.push_back((static_cast<double>(i) + 0.5) / (static_cast<double>(n) * config_.live.share.rate_hz));
  }
  share_sequence_.assign(n, 0);
  bytes_by_second_.assign(n, {});
  share_.enabled = true;
}

void SiteMapping::sendUpdate(int uav, double t_s, const Eigen::Vector3d& p_world) {
  const auto u = static_cast<std::size_t>(uav);
  mapping::OutgoingStats stats;
  comm::MapUpdate m;
  m.delta = live_[u]->takeChanges(p_world, t_s, mapping::shareVoxelBudget(config_.live.share), config_.live.share.max_age_s,
                                  &stats);
  share_.changes_deferred += stats.deferred;
  share_.changes_dropped += stats.dropped;
  if (m.delta.size() == 0) return;  // nothing to tell
  m.uav_index = static_cast<std::uint16_t>(uav);
  m.sequence = ++share_sequence_[u];
  const auto bytes = comm::encodePayload(m);
  if (!bytes) {  // cannot happen: the budget keeps the count within the limit, the keys are the grid's
    ++share_.updates_refused;
    return;
  }
  ++share_.updates_sent;
  share_.voxels_sent += static_cast<long>(m.delta.size());
  const auto second = static_cast<std::size_t>(std::max(0.0, std::floor(t_s)));
  if (bytes_by_second_[u].size() <= second) bytes_by_second_[u].resize(second + 1, 0.0);
  bytes_by_second_[u][second] += static_cast<double>(bytes->size() + mapping::kMapUpdateEnvelopeBytes);
  for (std::size_t j = 0; j < share_links_[u].size(); ++j) {
    if (share_links_[u][j]) share_links_[u][j]->send(t_s, *bytes);
  }
}

void SiteMapping::receiveUpdates(int uav, double t_s, bool offline) {
  const auto u = static_cast<std::size_t>(uav);
  for (std::size_t from = 0; from < share_links_.size(); ++from) {
    if (!share_links_[from][u]) continue;
    for (const std::vector<std::uint8_t>& bytes : share_links_[from][u]->receive(t_s)) {
      if (offline) {  // the radio is down: what arrives is lost
        ++share_.updates_lost;
        continue;
      }
      comm::MapUpdate m;
      if (comm::decodePayload(bytes.data(), bytes.size(), m) != comm::PayloadError::kNone ||
          comm::checkMapUpdate(m, live_[u]->keyGrid()) != comm::PayloadError::kNone) {
        ++share_.updates_refused;
        continue;
      }
      const auto t0 = std::chrono::steady_clock::now();
      const auto merged = live_[u]->merge(m.delta);
      merge_ms_.push_back(msSince(t0));
      if (!merged) {
        ++share_.updates_refused;
        continue;
      }
      ++share_.updates_merged;
      share_.voxels_superseded += merged->superseded;
      share_age_s_.push_back(t_s - m.delta.stamp_s);
    }
  }
}

void SiteMapping::step(double t_s, const std::vector<MultirotorState>& uavs, const std::vector<bool>& offline) {
  clock_s_ = t_s;
  const auto isOffline = [&](int i) { return static_cast<std::size_t>(i) < offline.size() && offline[static_cast<std::size_t>(i)]; };
  for (int i = 0; i < n_ && !share_links_.empty(); ++i) receiveUpdates(i, t_s, isOffline(i));
  for (int i = 0; i < n_ && i < static_cast<int>(uavs.size()); ++i) {
    const MultirotorState& s = uavs[static_cast<std::size_t>(i)];
    for (std::size_t j = 0; j < unmapped_.size(); ++j) {
      const double d = unmapped_[j].distanceAt(s.p_world, t_s);
      UnmappedObstacleRecord& r = records_[j];
      if (d < r.min_distance_m) {
        r.min_distance_m = d;
        r.min_distance_uav = i;
        r.min_distance_t_s = t_s;
      }
    }
    if (!share_links_.empty() && t_s + 1e-9 >= next_share_s_[static_cast<std::size_t>(i)]) {
      next_share_s_[static_cast<std::size_t>(i)] += 1.0 / config_.live.share.rate_hz;
      if (!isOffline(i)) sendUpdate(i, t_s, s.p_world);
    }
    if (live_.empty() || t_s + 1e-9 < next_frame_s_[static_cast<std::size_t>(i)]) continue;
    next_frame_s_[static_cast<std::size_t>(i)] += 1.0 / config_.rate_hz;
    depthFrame(i, t_s, s);
  }
}

void SiteMapping::useOfferedDepth() {
  offered_depth_ = true;
  held_.assign(static_cast<std::size_t>(n_), std::nullopt);
}

void SiteMapping::offerDepth(int uav, const CameraDepth& depth) {
  if (!offered_depth_ || uav < 0 || uav >= n_) return;
  held_[static_cast<std::size_t>(uav)] = depth;
}

void SiteMapping::depthFrame(int uav, double t_s, const MultirotorState& state) {
  if (!offered_depth_) {
    integrateFrame(uav, t_s, opticalPoseFromHeadingPitch(state.p_world, state.heading_rad, state.pitch_rad), intrinsics_);
  } else if (auto& held = held_[static_cast<std::size_t>(uav)]) {
    integrateDepth(uav, held->t_s, held->T_world_camera, held->intrinsics, held->depth_m);
    held.reset();
  }
  if (config_.travel_camera_hfov_deg > 0.0) {
    const auto [heading, pitch] = travelDirection(uav, state);
    integrateFrame(uav, t_s, opticalPoseFromHeadingPitch(state.p_world, heading, pitch), travel_intrinsics_);
  }
  recordSightings(uav, t_s, state.p_world);
}

void SiteMapping::integrateFrame(int uav, double t_s, const Eigen::Isometry3d& T_world_camera,
                                 const estimation::CameraIntrinsics& intrinsics) {
  planning::PrimitiveSet now;
  for (const UnmappedObstacle& o : unmapped_) now.append(o.primitivesAt(t_s));
  const auto t0 = std::chrono::steady_clock::now();
  cv::Mat depth = raycaster_.render(intrinsics, T_world_camera, config_.live.pixel_stride, config_.camera_range_m, now);
  depth_ms_.push_back(msSince(t0));
  integrateDepth(uav, t_s, T_world_camera, intrinsics, std::move(depth));
}

void SiteMapping::integrateDepth(int uav, double t_s, const Eigen::Isometry3d& T_world_camera,
                                 const estimation::CameraIntrinsics& intrinsics, cv::Mat depth_m) {
  mapping::DepthFrame frame;
  frame.T_world_camera = T_world_camera;
  frame.intrinsics = mapping::PinholeIntrinsics{intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy};
  frame.stamp_s = t_s;
  frame.depth_m = std::move(depth_m);
  const auto t1 = std::chrono::steady_clock::now();
  live_[static_cast<std::size_t>(uav)]->integrate(frame);  // a bad frame (wrong type, non-finite pose) changes nothing
  integrate_ms_.push_back(msSince(t1));
}

std::pair<double, double> SiteMapping::travelDirection(int uav, const MultirotorState& state) {
  const auto u = static_cast<std::size_t>(uav);
  Eigen::Vector3d d = travel_target_[u] - state.p_world;
  if (!d.allFinite() || d.norm() < 0.3) d = state.v_world;
  if (d.allFinite() && d.norm() >= 0.3) {
    const double pitch_limit = 1.2;  // rad (69°): a camera looking straight down sees no route
    travel_dir_[u] = {std::atan2(d.y(), d.x()), std::clamp(std::atan2(d.z(), d.head<2>().norm()), -pitch_limit, pitch_limit)};
  } else if (!std::isfinite(travel_dir_[u].first)) {
    travel_dir_[u] = {state.heading_rad, 0.0};
  }
  return travel_dir_[u];
}

void SiteMapping::recordSightings(int uav, double t_s, const Eigen::Vector3d& p_world) {
  const mapping::LiveMap& live = *live_[static_cast<std::size_t>(uav)];
  const double reach = config_.camera_range_m + 1.0;
  for (std::size_t j = 0; j < unmapped_.size(); ++j) {
    const UnmappedObstacle& o = unmapped_[j];
    if (!o.presentAt(t_s)) continue;
    const planning::Aabb b = o.boundsAt(t_s);
    if ((b.min_world - p_world).cwiseMax(p_world - b.max_world).cwiseMax(0.0).norm() > reach) continue;
    const Eigen::Vector3d offset = o.motion.offsetAt(t_s);
    const bool at_listed_pose = offset.isZero();
    double& seen = seen_s_[static_cast<std::size_t>(uav)][j];
    std::vector<bool>& marks = surface_seen_[j];
    for (std::size_t v = 0; v < surface_[j].size(); ++v) {
      if (!std::isnan(seen) && (!at_listed_pose || marks[v])) continue;  // nothing left to learn from it
      if (live.observed(surface_[j][v] + offset) != mapping::Observed::kOccupied) continue;
      if (std::isnan(seen)) seen = t_s;
      if (at_listed_pose) marks[v] = true;
    }
  }
}

void SiteMapping::planned(int uav, double t_s, const planning::PlanResult& result, const formation::ReferenceTrajectory& reference,
                          double reference_dt_s) {
  if (uav < 0 || uav >= n_) return;
  const auto u = static_cast<std::size_t>(uav);
  if (reference.steps() > 0 && reference_dt_s > 0.0) {
    const int k = std::min(reference.steps() - 1, static_cast<int>(std::lround(config_.travel_lookahead_s / reference_dt_s)));
    travel_target_[u] = reference.p_world.col(k);
  }
  if (!result.verified || result.trajectory.empty()) return;
  const planning::PlannedTrajectory& plan = result.trajectory;
  for (std::size_t j = 0; j < unmapped_.size(); ++j) {
    if (std::isnan(seen_s_[u][j]) || !std::isnan(avoided_s_[u][j])) continue;
    double least = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < plan.samples.size(); ++k) {
      const double tk = plan.t0_s + plan.dt_s * static_cast<double>(k);
      least = std::min(least, unmapped_[j].distanceAt(plan.samples[k].p_world, tk));
    }
    if (least >= clearance_m_) avoided_s_[u][j] = t_s;
  }
}

MapShareSummary SiteMapping::shareSummary() const {
  MapShareSummary s = share_;
  std::vector<double> per_second;
  for (const auto& row : bytes_by_second_) {
    // every whole second of the mission so far (silent seconds count as 0 bytes)
    const auto seconds = static_cast<std::size_t>(std::max(1.0, std::floor(clock_s_)));
    for (std::size_t k = 0; k < seconds; ++k) per_second.push_back(k < row.size() ? row[k] : 0.0);
  }
  if (s.enabled) {
    s.bytes_per_s_p50 = quantile(per_second, 0.5);
    s.bytes_per_s_max = quantile(per_second, 1.0);
    for (const auto& row : share_links_) {
      for (const auto& l : row) {
        if (l) s.updates_lost += static_cast<long>(l->counters().lost);
      }
    }
  }
  s.age_s_p50 = quantile(share_age_s_, 0.5);
  s.age_s_max = quantile(share_age_s_, 1.0);
  s.merge_ms_median = quantile(merge_ms_, 0.5);
  s.merge_ms_p99 = quantile(merge_ms_, 0.99);
  return s;
}

SiteMappingSummary SiteMapping::summary() const {
  SiteMappingSummary s;
  s.mapping = mapping();
  s.prior_map = config_.prior_map;
  s.camera = offered_depth_ ? "rendered" : "synthetic";
  s.clearance_m = clearance_m_;
  s.depth_frames = static_cast<int>(integrate_ms_.size());
  s.depth_ms_median = quantile(depth_ms_, 0.5);
  s.integrate_ms_median = quantile(integrate_ms_, 0.5);
  s.integrate_ms_p99 = quantile(integrate_ms_, 0.99);
  int surface = 0, seen = 0;
  for (std::size_t j = 0; j < records_.size(); ++j) {
    UnmappedObstacleRecord r = records_[j];
    r.surface_voxels_seen = static_cast<int>(std::count(surface_seen_[j].begin(), surface_seen_[j].end(), true));
    r.coverage = r.surface_voxels > 0 ? static_cast<double>(r.surface_voxels_seen) / r.surface_voxels : 0.0;
    surface += r.surface_voxels;
    seen += r.surface_voxels_seen;
    for (int i = 0; i < n_; ++i) {  // the first UAV to see it
      const double t = seen_s_[static_cast<std::size_t>(i)][j];
      if (!std::isnan(t) && (std::isnan(r.first_seen_s) || t < r.first_seen_s)) {
        r.first_seen_s = t;
        r.first_seen_uav = i;
      }
    }
    if (r.first_seen_uav >= 0) {
      r.avoided_s = avoided_s_[static_cast<std::size_t>(r.first_seen_uav)][j];
      r.sight_to_avoidance_s = r.avoided_s - r.first_seen_s;
    }
    s.min_unmapped_distance_m = std::min(s.min_unmapped_distance_m, r.min_distance_m);
    s.obstacles.push_back(r);
  }
  s.coverage = surface > 0 ? static_cast<double>(seen) / surface : 0.0;
  s.share = shareSummary();
  return s;
}

}  // namespace gesture_formation::sim
