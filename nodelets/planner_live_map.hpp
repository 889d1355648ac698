#pragma once
// The FormationPlanner's live map (docs/mapping.md "Through ROS"): with ~mapping_config (a YAML of
// mapping::MappingConfig's keys, config/mapping.yaml) the planner plans on a mapping::LiveMap fed by
// this UAV's aligned depth images (depth_in: sensor_msgs/Image 32FC1 metres or 16UC1 in
// ~mapping_depth_scale_m units, default 0.001 (millimetres), REP 118; depth_info_in: its CameraInfo
// in the same frame_id — the pinhole of the rectified image, P where set, else K; the optical
// frame's pose from tf at the image's stamp, which must be set; when ROS time goes back the live
// map's stamps restart, mapping::LiveMap::restartClock), fused with the scenario's map as the prior (~mapping_prior,
// default true). Frames are integrated at most ~mapping_rate_hz on the depth callback's thread
// (ROS serialises one subscription's callbacks: never two integrate() at once); the planner holds
// readLock() for a whole replanning. Without ~mapping_config nothing is subscribed and the planner
// plans on the scenario's map, as before. With share.enabled in the mapping config (docs/mapping.md
// §8) every share.rate_hz the planner publishes its own changes (mapping::LiveMap::takeChanges, the
// nearest to its camera first, within share.max_bytes_per_s) on map_update_out and merges the other
// UAVs' from map_update_in (the LcmBridge carries both over LCM). Once a second it publishes what its
// live map holds around its camera on live_map_markers_out (latched visualization_msgs/Marker, a cube
// list: voxels the prior map holds grey, those only the camera or another UAV found construction
// yellow, the ground's layer left out; within ~mapping_markers_range_m, default 20 m, 0: none) for rviz. Thread safety: integrate(), merge()
// and takeChanges() serialised by update_mutex_ (one subscription's callbacks are serialised, three
// are not); the counters under their own mutex.
#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <tuple>

#include <diagnostic_msgs/DiagnosticStatus.h>
#include <visualization_msgs/Marker.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "config_sources.hpp"
#include "conversions.hpp"
#include "map_update_conversions.hpp"
#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/format_number.hpp"
#include "gesture_formation/mapping/live_map.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class PlannerLiveMap {
 public:
  /// load(), then (when configured and every parameter so far is fine) start(); problems into `params`.
  void setUp(ros::NodeHandle& nh, ros::NodeHandle& pnh, ParamLoader& params, WorldMap& world, const std::string& world_frame,
             int uav_index) {
    uav_index_ = static_cast<std::uint16_t>(uav_index);
    if (!load(pnh, params) || !params.ok()) return;
    if (const auto why = start(nh, world, world_frame); !why.empty()) params.addError(why);
  }

  /// Reads ~mapping_config (optional), ~mapping_rate_hz, ~mapping_prior, ~mapping_tf_timeout_s,
  /// ~mapping_depth_scale_m; every
  /// problem into `params`. True when a live map is configured.
  bool load(ros::NodeHandle& pnh, ParamLoader& params) {
    params.loadOptional("mapping_config", file_, "");
    if (file_.empty()) return false;
    params.load("mapping_rate_hz", rate_hz_, 0.1, 30.0);
    params.loadOptional("mapping_prior", prior_, true);
    // Optional, with their defaults; present, a number in range (a mistyped value — e.g. the string
    // PyYAML makes of 1e-4 — is refused, never replaced by the default in silence).
    for (auto [name, value, lo, hi, unit, lo_in] :
         {std::make_tuple("mapping_tf_timeout_s", &tf_timeout_s_, 0.0, 1.0, "s", true),
          std::make_tuple("mapping_depth_scale_m", &depth_scale_m_, 0.0, 0.01, "m per 16UC1 unit", false)}) {
      if (pnh.hasParam(name) && !pnh.getParam(name, *value)) {
        params.addError(pnh.resolveName(name) + ": not a number");
      } else if (!((lo_in ? *value >= lo : *value > lo) && *value <= hi)) {
        params.addError(pnh.resolveName(name) + ": must be in " + (lo_in ? "[" : "(") + common::formatNumber(lo) + ", " +
                        common::formatNumber(hi) + "] " + unit + ", got " + std::to_string(*value));
      }
    }
    pnh.param("mapping_markers_range_m", markers_range_m_, 20.0);
    if (!(markers_range_m_ >= 0.0 && markers_range_m_ <= 200.0)) {
      params.addError("mapping_markers_range_m: must be in [0, 200] m, got " + std::to_string(markers_range_m_));
    }
    common::ConfigReader r = common::ConfigReader::fromFile(file_, common::ConfigReader::MissingKeys::kError);
    config_ = mapping::readMappingConfig(r);
    for (const auto& e : r.errors()) params.addError("mapping_config: " + file_ + ": " + e);
    for (const auto& k : r.unusedKeys()) params.addError("mapping_config: " + file_ + ": unknown key " + k);
    return true;
  }

  /// Creates the live map over `world`'s grid (its map as the prior unless ~mapping_prior false)
  /// and points `world`'s map and field at the live ones. Empty on success, else the problem.
  std::string start(ros::NodeHandle& nh, WorldMap& world, const std::string& world_frame) {
    auto live = mapping::LiveMap::create(config_, world.grid, prior_ ? world.map : nullptr);
    if (!live) return "mapping_config: " + live.reason();
    live_ = std::move(*live);
    prior_map_ = prior_ ? world.map : nullptr;
    ground_z_m_ = world.ground_height_m;
    world.map = live_->map();
    world.field = live_->field();
    world_frame_ = world_frame;
    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(tf_buffer_);
    info_sub_ = nh.subscribe<sensor_msgs::CameraInfo>("depth_info_in", 2, [this](const sensor_msgs::CameraInfo::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      info_ = *m;
    });
    depth_sub_ = nh.subscribe("depth_in", 2, &PlannerLiveMap::onDepth, this);
    if (markers_range_m_ > 0.0) {
      markers_pub_ = nh.advertise<visualization_msgs::Marker>("live_map_markers_out", 1, true);
      markers_timer_ = nh.createTimer(ros::Duration(1.0), [this](const ros::TimerEvent&) { publishMarkers(); });
    }
    if (!config_.share.enabled) return "";
    share_pub_ = nh.advertise<gesture_formation::MapUpdate>("map_update_out", 10);
    share_sub_ = nh.subscribe("map_update_in", 20, &PlannerLiveMap::onUpdate, this);
    share_timer_ = nh.createTimer(ros::Duration(1.0 / config_.share.rate_hz), [this](const ros::TimerEvent&) { share(); });
    return "";
  }

  bool enabled() const { return live_ != nullptr; }
  const mapping::LiveMap& live() const { return *live_; }
  std::shared_ptr<const planning::SeenSpace> seen() const { return live_ ? live_->seen() : nullptr; }
  /// For a whole replanning (no lock without a live map).
  std::shared_lock<std::shared_mutex> readLock() const {
    return live_ ? live_->readLock() : std::shared_lock<std::shared_mutex>();
  }

  /// Adds the live map's counts since the last report to the planner's /diagnostics status (WARN
  /// when frames were refused); nothing without a live map.
  void report(diagnostic_msgs::DiagnosticStatus& st, double since_s) {
    if (!live_) return;
    Counts c;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      std::swap(c, counts_);
    }
    const auto kv = [&st](const std::string& k, const std::string& v) {
      diagnostic_msgs::KeyValue x;
      x.key = k;
      x.value = v;
      st.values.push_back(x);
    };
    kv("live_map_frames_per_s", std::to_string(since_s > 0.0 ? c.frames / since_s : 0.0));
    kv("live_map_changes", std::to_string(c.map_changes));
    kv("live_map_frame_ms_mean", std::to_string(c.frames > 0 ? c.total_ms / c.frames : 0.0));
    kv("live_map_refused", std::to_string(c.refused));
    if (config_.share.enabled) {
      kv("live_map_updates_sent", std::to_string(c.updates_sent));
      kv("live_map_voxels_sent", std::to_string(c.voxels_sent));
      kv("live_map_changes_dropped", std::to_string(c.changes_dropped));
      kv("live_map_updates_merged", std::to_string(c.updates_merged));
      kv("live_map_voxels_merged", std::to_string(c.voxels_merged));
      kv("live_map_updates_refused", std::to_string(c.updates_refused));
    }
    if (c.refused == 0) return;
    st.level = std::max<std::uint8_t>(st.level, diagnostic_msgs::DiagnosticStatus::WARN);
    st.message += (st.message.empty() ? "" : "; ") + std::to_string(c.refused) + " depth frame(s) refused: " + c.last_refusal;
  }

 private:
  void refuse(const std::string& why) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counts_.refused;
    counts_.last_refusal = why;
  }

  void onDepth(const sensor_msgs::Image::ConstPtr& m) {
    const double t = m->header.stamp.toSec();
    // No stamp: the camera's pose cannot be looked up at it (tf would answer its latest, maybe stale).
    if (!(t > 0.0)) return refuse("depth_in header.stamp is 0: the camera pose at the frame's time is unknown");
    // ROS time went back (a simulation restarted, a bag looped): the rate limit and the live map's
    // stamps restart from this frame — else every frame is dropped until the clock caught up.
    if (next_frame_s_ > t + 2.0 / rate_hz_ + 1.0) {
      ROS_WARN_STREAM("FormationPlanner live map: depth frame stamped " << t << " s, " << next_frame_s_ - t
                                                                        << " s before the previous one: ROS time went back, the map's stamps restart");
      std::lock_guard<std::mutex> serial(update_mutex_);
      live_->restartClock(t);
      next_frame_s_ = -1.0;
    }
    // At most mapping_rate_hz; 1 ms of slack, or a camera at exactly that rate loses frames to
    // rounding (0.4 + 0.2 > 0.6 in binary: every third frame at 5 Hz).
    if (t + 1e-3 < next_frame_s_) return;
    next_frame_s_ = t + 1.0 / rate_hz_;
    mapping::DepthFrame frame;
    frame.stamp_s = t;
    std::optional<sensor_msgs::CameraInfo> info;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      info = info_;
    }
    if (!info) return refuse("no CameraInfo on depth_info_in yet");
    // The depth must be the camera the CameraInfo describes (an unaligned depth stream of the same
    // size would be placed with the colour camera's intrinsics).
    if (info->header.frame_id != m->header.frame_id) {
      return refuse("depth_in frame_id '" + m->header.frame_id + "' is not its CameraInfo's '" + info->header.frame_id +
                    "' (depth aligned to that camera expected)");
    }
    // The image's own pinhole: the calibration with the binning and region applied (REP 104); the
    // aligned depth is taken as rectified, whatever distortion model the driver names: the
    // projection P where the driver sets it (the rectified image's), else K.
    sensor_msgs::CameraInfo pinhole = *info;
    pinhole.D.clear();
    if (pinhole.P[0] > 0.0 && pinhole.P[5] > 0.0) {
      pinhole.K = {pinhole.P[0], pinhole.P[1], pinhole.P[2], pinhole.P[4], pinhole.P[5], pinhole.P[6], 0.0, 0.0, 1.0};
    }
    const auto k = toIntrinsics(pinhole);
    if (!k) return refuse("depth_info_in: " + k.reason());
    if (static_cast<std::uint32_t>(k->width_px) != m->width || static_cast<std::uint32_t>(k->height_px) != m->height) {
      return refuse("depth image size differs from its CameraInfo");
    }
    frame.intrinsics = {k->fx, k->fy, k->cx, k->cy};
    auto depth = toDepth(*m);
    if (!depth) return refuse("depth_in: " + depth.reason());
    if (depth->type() == CV_16UC1) {  // depth_scale_m units (millimetres by default); 0: no return (REP 118) -> NaN
      depth->convertTo(frame.depth_m, CV_32FC1, depth_scale_m_);
      frame.depth_m.setTo(std::nanf(""), *depth == 0);
    } else {
      frame.depth_m = *depth;
    }
    try {
      const auto T = tf_buffer_.lookupTransform(world_frame_, m->header.frame_id, m->header.stamp, ros::Duration(tf_timeout_s_));
      const auto& q = T.transform.rotation;
      const auto& p = T.transform.translation;
      frame.T_world_camera = Eigen::Translation3d(p.x, p.y, p.z) * Eigen::Quaterniond(q.w, q.x, q.y, q.z);
    } catch (const tf2::TransformException& e) {
      return refuse(std::string("depth frame not used: ") + e.what());
    }
    common::Result<mapping::FrameUpdate> u = common::Result<mapping::FrameUpdate>::fail("");
    {
      std::lock_guard<std::mutex> serial(update_mutex_);
      u = live_->integrate(frame);
      if (u) camera_world_ = frame.T_world_camera.translation();
    }
    if (!u) return refuse("depth frame refused: " + u.reason());
    std::lock_guard<std::mutex> lock(mutex_);
    ++counts_.frames;
    counts_.map_changes += u->map_changes;
    counts_.total_ms += u->total_ms;
  }

  // Every share.rate_hz: this UAV's changes since its last update, if any, on map_update_out.
  void share() {
    mapping::OutgoingStats stats;
    comm::MapUpdate m;
    {
      std::lock_guard<std::mutex> serial(update_mutex_);
      if (!camera_world_) return;  // no frame integrated yet: nothing of its own to tell
      m.delta = live_->takeChanges(*camera_world_, ros::Time::now().toSec(), mapping::shareVoxelBudget(config_.share),
                                   config_.share.max_age_s, &stats);
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      counts_.changes_dropped += stats.dropped;
      if (m.delta.size() == 0) return;
      ++counts_.updates_sent;
      counts_.voxels_sent += static_cast<int>(m.delta.size());
    }
    m.uav_index = uav_index_;
    m.sequence = ++sequence_;
    share_pub_.publish(toMsg(m));
  }

  // The live map's occupied voxels within markers_range_m_ of the camera, as one cube list.
  void publishMarkers() {
    std::optional<Eigen::Vector3d> camera;
    {
      std::lock_guard<std::mutex> serial(update_mutex_);
      camera = camera_world_;
    }
    if (!camera || markers_pub_.getNumSubscribers() == 0) return;
    std::vector<Eigen::Vector3d> points;
    {
      const auto lock = live_->readLock();  // not while a frame's changes are applied
      live_->map()->pointsInBox(planning::Aabb{*camera - Eigen::Vector3d::Constant(markers_range_m_),
                                               *camera + Eigen::Vector3d::Constant(markers_range_m_)}, points);
    }
    visualization_msgs::Marker m;
    m.header.frame_id = world_frame_;
    m.header.stamp = ros::Time::now();
    m.ns = "live_map";
    m.type = visualization_msgs::Marker::CUBE_LIST;
    m.pose.orientation.w = 1.0;
    m.scale.x = m.scale.y = m.scale.z = live_->map()->resolution();
    m.color.a = 1.0f;
    const double floor_z = ground_z_m_ + live_->map()->resolution();  // the ground's voxels are left out
    for (const Eigen::Vector3d& p : points) {
      if (p.z() < floor_z) continue;
      geometry_msgs::Point q;
      q.x = p.x(), q.y = p.y(), q.z = p.z();
      m.points.push_back(q);
      std_msgs::ColorRGBA c;
      const bool known = prior_map_ && prior_map_->isOccupied(p);
      c.r = known ? 0.55f : 0.86f, c.g = known ? 0.55f : 0.66f, c.b = known ? 0.58f : 0.12f, c.a = 1.0f;
      m.colors.push_back(c);
    }
    markers_pub_.publish(m);
  }

  // Another UAV's changes (from the LcmBridge): checked against this map's grid, then merged.
  void onUpdate(const gesture_formation::MapUpdate::ConstPtr& msg) {
    if (msg->uav_index == uav_index_) return;  // its own, looped back
    const auto m = fromMsg(*msg);
    common::Result<mapping::MergeResult> merged = common::Result<mapping::MergeResult>::fail(m ? "" : m.reason());
    if (m) {  // merge() refuses, changing nothing, what does not fit this map's grid
      std::lock_guard<std::mutex> serial(update_mutex_);
      merged = live_->merge(m->delta);
    }
    if (!merged) return refuseUpdate("map update from UAV " + std::to_string(msg->uav_index) + " refused: " + merged.reason());
    std::lock_guard<std::mutex> lock(mutex_);
    ++counts_.updates_merged;
    counts_.voxels_merged += merged->voxels - merged->superseded;
    counts_.map_changes += merged->map_changes;
  }
  void refuseUpdate(const std::string& why) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counts_.updates_refused;
    ROS_WARN_STREAM_THROTTLE(1.0, "FormationPlanner: " << why);
  }

  std::string file_, world_frame_;
  std::uint16_t uav_index_ = 0;
  std::uint32_t sequence_ = 0;  ///< map updates sent
  std::mutex update_mutex_;     ///< one of integrate(), merge(), takeChanges() at a time
  std::optional<Eigen::Vector3d> camera_world_;  ///< the camera at the last integrated frame (under update_mutex_)
  double rate_hz_ = 5.0, tf_timeout_s_ = 0.1, next_frame_s_ = -1e18, markers_range_m_ = 20.0;
  double depth_scale_m_ = 0.001;  ///< 16UC1 depth units [m] (~mapping_depth_scale_m)
  std::shared_ptr<const planning::OccupancyMap> prior_map_;  ///< the scenario's map (null: no prior)
  double ground_z_m_ = -1e9;  ///< the scenario's ground (its voxels are not drawn)
  bool prior_ = true;
  mapping::MappingConfig config_;
  std::unique_ptr<mapping::LiveMap> live_;
  std::mutex mutex_;
  std::optional<sensor_msgs::CameraInfo> info_;
  struct Counts {
    int frames = 0, refused = 0, map_changes = 0;
    int updates_sent = 0, voxels_sent = 0, changes_dropped = 0, updates_merged = 0, voxels_merged = 0, updates_refused = 0;
    double total_ms = 0.0;
    std::string last_refusal;
  };
  Counts counts_;
  tf2_ros::Buffer tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  ros::Subscriber info_sub_, depth_sub_, share_sub_;
  ros::Publisher share_pub_, markers_pub_;
  ros::Timer share_timer_, markers_timer_;
};

}  // namespace gesture_formation::nodelets
