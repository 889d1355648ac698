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
      fault_rng_(makeRng(seed, Stream::kFault)) {}

LeaderCameraFrame LeaderCamera::frame(double t, const MultirotorState& leader, const WorkerState& ws,
                                      WorkerModel& worker, MissionClassifier* classifier) {
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
  out.skeleton = worker.skeletonAt(t, true_pose.t_world_camera);
  if (!frame.visible()) return out;
  if (t - last_visible_s_ > kSkeletonGapS) window_.clear();  // a gap breaks the FIFO's temporal consistency
  window_.push(out.skeleton.skeleton);
  last_visible_s_ = t;
  if (classifier != nullptr && window_.full()) {
    auto c = classifier->classify(window_);
    if (c) out.classification = *c;
  }
  return out;
}

}  // namespace gesture_formation::sim
