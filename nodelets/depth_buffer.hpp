#pragma once
// The Perception nodelet's last depth images, to pair each colour image with the depth image
// nearest its stamp. Depth and colour are two topics that ROS 1 does not deliver in order, so a
// colour image processed late must still find its depth, and one processed early may wait for it.
// Thread safety: every method locks; add() from one thread, nearest() from another.
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <mutex>

#include <ros/time.h>
#include <sensor_msgs/Image.h>

namespace gesture_formation::nodelets {

class DepthBuffer {
 public:
  static constexpr std::size_t kSize = 10;  ///< depth images kept (≥ 0.3 s at 30 Hz)
  double max_dt_s = 0.0;                    ///< a depth image further than this from the colour stamp is not used

  void add(const sensor_msgs::Image::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    depths_.push_back(m);
    while (depths_.size() > kSize) depths_.pop_front();
    arrived_.notify_all();
  }

  /// The stored depth image nearest `stamp`, if within max_dt_s (else null). When none is stored
  /// and no depth image newer than `stamp` has arrived yet, its depth image may still be in flight:
  /// wait for it, at most max_dt_s of wall time (not at all without a depth stream).
  sensor_msgs::Image::ConstPtr nearest(const ros::Time& stamp) {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto find = [&]() {
      sensor_msgs::Image::ConstPtr best;
      double best_dt = max_dt_s;
      for (const auto& d : depths_) {
        const double dt = std::abs((d->header.stamp - stamp).toSec());
        if (dt <= best_dt) {
          best_dt = dt;
          best = d;
        }
      }
      return best;
    };
    const auto settled = [&]() { return find() || (!depths_.empty() && depths_.back()->header.stamp > stamp); };
    if (!depths_.empty()) arrived_.wait_for(lock, std::chrono::duration<double>(max_dt_s), settled);
    return find();
  }

 private:
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::deque<sensor_msgs::Image::ConstPtr> depths_;
};

}  // namespace gesture_formation::nodelets
