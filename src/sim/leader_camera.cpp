#include "gesture_formation/sim/leader_camera.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <limits>
#include <mutex>
#include <thread>

#include "gesture_formation/sim/random.hpp"

namespace gesture_formation::sim {

std::vector<std::optional<gesture::Classification>> MissionClassifier::classifyAll(
    const std::vector<const gesture::SkeletonWindow*>& windows) {
  std::vector<std::optional<gesture::Classification>> out(windows.size());
  for (std::size_t i = 0; i < windows.size(); ++i) {
    auto c = classify(*windows[i]);
    if (c) out[i] = *c;
  }
  return out;
}

namespace {

/// The ONNX LSTM; classifyAll spreads a frame's windows over `nets_.size()` threads, each with
/// its own network: the caller and the persistent workers claim the windows one at a time from a
/// shared counter, so the caller never waits for a worker that has not started yet (on a loaded
/// machine it classifies them all itself) and waits only for windows a worker has claimed. The
/// networks are copies of one model and keep no state between windows: which thread classifies a
/// window does not change its result (test_sim ParallelClassifierTest).
class OnnxClassifier : public MissionClassifier {
 public:
  explicit OnnxClassifier(std::vector<gesture::GestureClassifier> nets) : nets_(std::move(nets)) {
    for (std::size_t j = 1; j < nets_.size(); ++j) workers_.emplace_back([this, j] { work(j); });
  }
  ~OnnxClassifier() override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    start_.notify_all();
    for (auto& w : workers_) w.join();
  }
  OnnxClassifier(const OnnxClassifier&) = delete;
  OnnxClassifier& operator=(const OnnxClassifier&) = delete;

  common::Result<gesture::Classification> classify(const gesture::SkeletonWindow& w) override {
    return nets_.front().classify(w);
  }

  std::vector<std::optional<gesture::Classification>> classifyAll(
      const std::vector<const gesture::SkeletonWindow*>& windows) override {
    std::vector<std::optional<gesture::Classification>> out(windows.size());
    if (workers_.empty() || windows.size() < 2) {
      for (std::size_t i = 0; i < windows.size(); ++i) run(0, *windows[i], out[i]);
      return out;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      batch_ = &windows;
      results_ = &out;
      next_.store(0);
      completed_.store(0);
      open_ = true;
      ++generation_;
    }
    start_.notify_all();
    claim(0);
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return completed_.load() == windows.size() && active_ == 0; });
    open_ = false;  // a worker waking from now on finds nothing to join
    batch_ = nullptr;
    results_ = nullptr;
    return out;
  }

 private:
  void run(std::size_t net, const gesture::SkeletonWindow& w, std::optional<gesture::Classification>& slot) {
    auto c = nets_[net].classify(w);
    if (c) slot = *c;
  }
  /// Thread j classifies unclaimed windows of the open batch with its network until none is left
  /// (each slot is written by exactly the thread that claimed it).
  void claim(std::size_t j) {
    for (std::size_t i = next_.fetch_add(1); i < batch_->size(); i = next_.fetch_add(1)) {
      run(j, *(*batch_)[i], (*results_)[i]);
      completed_.fetch_add(1);
    }
  }
  void work(std::size_t j) {
    std::uint64_t seen = 0;
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      start_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      if (!open_) continue;  // the caller already finished that batch alone
      ++active_;             // the caller waits for this thread before it closes the batch
      lock.unlock();
      claim(j);
      lock.lock();
      --active_;
      done_.notify_one();
    }
  }

  std::vector<gesture::GestureClassifier> nets_;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_, done_;
  const std::vector<const gesture::SkeletonWindow*>* batch_ = nullptr;
  std::vector<std::optional<gesture::Classification>>* results_ = nullptr;
  std::atomic<std::size_t> next_{0};       ///< the next unclaimed window of the open batch
  std::atomic<std::size_t> completed_{0};  ///< windows of the open batch classified
  std::uint64_t generation_ = 0;
  int active_ = 0;     ///< workers inside the open batch (guarded by mutex_)
  bool open_ = false;  ///< a batch is published and not yet closed by the caller (guarded by mutex_)
  bool stop_ = false;
};

}  // namespace

common::Result<std::unique_ptr<MissionClassifier>> loadOnnxClassifier(const std::string& onnx_path, int threads) {
  using R = common::Result<std::unique_ptr<MissionClassifier>>;
  if (threads < 1 || threads > kMaxClassifierThreads) {
    return R::fail("classifier threads: expected 1.." + std::to_string(kMaxClassifierThreads) + ", got " +
                   std::to_string(threads));
  }
  std::vector<gesture::GestureClassifier> nets;
  for (int j = 0; j < threads; ++j) {
    auto c = gesture::GestureClassifier::load(onnx_path);  // a separate network per thread
    if (!c) return R::fail(c.reason());
    nets.push_back(std::move(*c));
  }
  return R::ok(std::make_unique<OnnxClassifier>(std::move(nets)));
}

int applyRangeFaults(const FaultConfig& faults, double t, SensorFrame& frame, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int outliers = 0;
  if (inWindow(faults.uwb_dropouts, t)) frame.d_uwb_m = std::numeric_limits<double>::quiet_NaN();
  if (inWindow(faults.stereo_dropouts, t)) frame.d_stereo_m = std::numeric_limits<double>::quiet_NaN();
  for (double* d : {&frame.d_uwb_m, &frame.d_stereo_m}) {
    const double u_hit = u01(rng), u_size = u01(rng), u_sign = u01(rng);  // fixed draws per frame
    if (std::isfinite(*d) && u_hit < faults.range_outliers.probability) {
      const RangeOutlierConfig& ro = faults.range_outliers;
      const double err = ro.min_error_m + u_size * (ro.max_error_m - ro.min_error_m);
      *d = std::max(0.1, *d + (u_sign < 0.5 ? -err : err));
      ++outliers;
    }
  }
  return outliers;
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
  out.intrinsics = cfg_.camera.camera;
  const FaultConfig& faults = cfg_.faults;
  const estimation::CameraPose true_pose = cameraPose(leader.p_world, leader.heading_rad, leader.pitch_rad);
  bool blackout = false;
  for (const auto& [a, b] : faults.camera_blackouts) blackout = blackout || (t >= a && t < b);
  SensorFrame& frame = out.sensors;
  frame = sensors_.observe(true_pose, ws.feet_world, ws.p_world, cfg_.worker.height_m, blackout);
  out.range_outliers = applyRangeFaults(faults, t, frame, fault_rng_);
  std::vector<Eigen::Vector3d> cameras{true_pose.t_world_camera};
  std::vector<estimation::CameraPose> follower_poses;
  for (const MultirotorState& f : followers) {
    follower_poses.push_back(cameraPose(f.p_world, f.heading_rad, f.pitch_rad));
    cameras.push_back(follower_poses.back().t_world_camera);
  }
  const std::vector<gesture::SynthFrame> skeletons = worker.skeletonsAt(t, cameras);
  out.skeleton = skeletons.front();
  const bool calibrate = cfg_.view_fusion.usesCalibratedViews();  // the poses serve only the 3-D tests
  if (calibrate) out.calibrated = worker.calibrated(0, out.skeleton.skeleton, ws);
  // A camera's FIFO: a gap breaks its temporal consistency. A full FIFO is classified below,
  // all cameras of the frame together (MissionClassifier::classifyAll).
  std::vector<const gesture::SkeletonWindow*> windows;
  std::vector<std::optional<gesture::Classification>*> slots;
  const auto push = [&](gesture::SkeletonWindow& window, double& last_visible, const gesture::Skeleton2D& sk,
                        std::optional<gesture::Classification>& slot) {
    if (t - last_visible > kSkeletonGapS) window.clear();
    window.push(sk);
    last_visible = t;
    if (classifier == nullptr || !window.full()) return;
    windows.push_back(&window);
    slots.push_back(&slot);
  };
  while (follower_cams_.size() < followers.size()) {
    const auto i = static_cast<std::uint64_t>(follower_cams_.size());
    follower_cams_.push_back(FollowerCamera{SyntheticSensors(cfg_.camera, cfg_.stereo, cfg_.uwb, map_,
                                                             makeRng(seed_, Stream::kFollowerCamera, 3 * i),
                                                             makeRng(seed_, Stream::kFollowerCamera, 3 * i + 1),
                                                             makeRng(seed_, Stream::kFollowerCamera, 3 * i + 2)),
                                            {}, -1e9});
  }
  out.followers.resize(followers.size());  // not resized again: slots point into it
  for (std::size_t i = 0; i < followers.size(); ++i) {
    FollowerView& v = out.followers[i];
    FollowerCamera& fc = follower_cams_[i];
    const SensorFrame seen = fc.sensors.observe(follower_poses[i], ws.feet_world, ws.p_world, cfg_.worker.height_m, false);
    v.visible = (i >= online.size() || online[i]) && seen.visible();
    if (calibrate && v.visible) v.calibrated = worker.calibrated(i + 1, skeletons[i + 1].skeleton, ws);
    if (v.visible) push(fc.window, fc.last_visible_s, skeletons[i + 1].skeleton, v.classification);
  }
  if (frame.visible()) push(window_, last_visible_s_, out.skeleton.skeleton, out.classification);
  if (!windows.empty()) {
    auto results = classifier->classifyAll(windows);
    for (std::size_t i = 0; i < slots.size() && i < results.size(); ++i) *slots[i] = std::move(results[i]);
  }
  return out;
}

}  // namespace gesture_formation::sim
