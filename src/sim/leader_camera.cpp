#include "gesture_formation/sim/leader_camera.hpp"

#include <algorithm>
#include <limits>

#include "gesture_formation/sim/random.hpp"

namespace gesture_formation::sim {

namespace {

class OnnxClassifier : public MissionClassifier {
 public:
  explicit OnnxClassifier(gesture::GestureClassifier c) : c_(std::move(c)) {}
  common::Result<gesture::Classification> classify(const gesture::SkeletonWindow& w) override { return c_.classify(w); }

 private:
  gesture::GestureClassifier c_;
};

}  // namespace

common::Result<std::unique_ptr<MissionClassifier>> loadOnnxClassifier(const std::string& onnx_path) {
  using R = common::Result<std::unique_ptr<MissionClassifier>>;
  auto c = gesture::GestureClassifier::load(onnx_path);
  if (!c) return R::fail(c.reason());
  return R::ok(std::make_unique<OnnxClassifier>(std::move(*c)));
}

LeaderCamera::LeaderCamera(const MissionConfig& config, const planning::OccupancyMap* map, std::uint64_t seed)
    : cfg_(config),
      sensors_(config.camera, config.stereo, config.uwb, map, makeRng(seed, Stream::kCamera),
               makeRng(seed, Stream::kStereo), makeRng(seed, Stream::kUwb)),
      fault_rng_(makeRng(seed, Stream::kFault)),
      map_(map),
      seed_(seed) {}

LeaderCameraFrame LeaderCamera::frame(double t, const MultirotorState& leader, const WorkerState& ws,
                                      WorkerModel& worker, MissionClassifier* classifier) {
  return frame(t, leader, {}, {}, ws, worker, classifier);
}

LeaderCameraFrame LeaderCamera::frame(double t, const MultirotorState& leader, const std::vector<MultirotorState>& followers,
                                      const std::vector<bool>& online, const WorkerState& ws, WorkerModel& worker,
                                      MissionClassifier* classifier) {
  LeaderCameraFrame out;
  const FaultConfig& faults = cfg_.faults;
  const estimation::CameraPose true_pose = cameraPose(leader.p_world, leader.heading_rad, leader.pitch_rad);
  bool blackout = false;
  for (const auto& [a, b] : faults.camera_blackouts) blackout = blackout || (t >= a && t < b);
  SensorFrame& frame = out.sensors;
  frame = sensors_.observe(true_pose, ws.feet_world, ws.p_world, cfg_.worker.height_m, blackout);
  if (inWindow(faults.uwb_dropouts, t)) frame.d_uwb_m = std::numeric_limits<double>::quiet_NaN();
  if (inWindow(faults.stereo_dropouts, t)) frame.d_stereo_m = std::numeric_limits<double>::quiet_NaN();
  for (double* d : {&frame.d_uwb_m, &frame.d_stereo_m}) {
    const double u_hit = u01_(fault_rng_), u_size = u01_(fault_rng_), u_sign = u01_(fault_rng_);  // fixed draws per frame
    if (std::isfinite(*d) && u_hit < faults.range_outliers.probability) {
      const RangeOutlierConfig& ro = faults.range_outliers;
      const double err = ro.min_error_m + u_size * (ro.max_error_m - ro.min_error_m);
      *d = std::max(0.1, *d + (u_sign < 0.5 ? -err : err));
      ++out.range_outliers;
    }
  }
  std::vector<Eigen::Vector3d> cameras{true_pose.t_world_camera};
  std::vector<estimation::CameraPose> follower_poses;
  for (const MultirotorState& f : followers) {
    follower_poses.push_back(cameraPose(f.p_world, f.heading_rad, f.pitch_rad));
    cameras.push_back(follower_poses.back().t_world_camera);
  }
  const std::vector<gesture::SynthFrame> skeletons = worker.skeletonsAt(t, cameras);
  out.skeleton = skeletons.front();
  // A camera's FIFO and classifier: a gap breaks the FIFO's temporal consistency.
  const auto classify = [&](gesture::SkeletonWindow& window, double& last_visible, const gesture::Skeleton2D& sk)
      -> std::optional<gesture::Classification> {
    if (t - last_visible > kSkeletonGapS) window.clear();
    window.push(sk);
    last_visible = t;
    if (classifier == nullptr || !window.full()) return std::nullopt;
    auto c = classifier->classify(window);
    if (!c) return std::nullopt;
    return *c;
  };
  while (follower_cams_.size() < followers.size()) {
    const auto i = static_cast<std::uint64_t>(follower_cams_.size());
    follower_cams_.push_back(FollowerCamera{SyntheticSensors(cfg_.camera, cfg_.stereo, cfg_.uwb, map_,
                                                             makeRng(seed_, Stream::kFollowerCamera, 3 * i),
                                                             makeRng(seed_, Stream::kFollowerCamera, 3 * i + 1),
                                                             makeRng(seed_, Stream::kFollowerCamera, 3 * i + 2)),
                                            {}, -1e9});
  }
  for (std::size_t i = 0; i < followers.size(); ++i) {
    FollowerView v;
    FollowerCamera& fc = follower_cams_[i];
    const SensorFrame seen = fc.sensors.observe(follower_poses[i], ws.feet_world, ws.p_world, cfg_.worker.height_m, false);
    v.visible = (i >= online.size() || online[i]) && seen.visible();
    if (v.visible) v.classification = classify(fc.window, fc.last_visible_s, skeletons[i + 1].skeleton);
    out.followers.push_back(std::move(v));
  }
  if (!frame.visible()) return out;
  out.classification = classify(window_, last_visible_s_, out.skeleton.skeleton);
  return out;
}

}  // namespace gesture_formation::sim
