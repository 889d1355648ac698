#include "gesture_formation/onboard/wind_input.hpp"

#include <sstream>

namespace gesture_formation::onboard {

std::string WindInput::receive(const std::string& frame_id, const std::string& world_frame, const Eigen::Vector3d& w,
                               double stamp_s) {
  if (frame_id == world_frame && w.allFinite() && w.norm() <= kMaxWindMps) {
    wind_ = w;
    stamp_s_ = stamp_s;
    return "";
  }
  ++rejected_;
  std::ostringstream why;
  why << "frame_id '" << frame_id << "', expected '" << world_frame << "'; wind " << w.transpose() << " m/s, at most "
      << kMaxWindMps;
  return why.str();
}

std::optional<Eigen::Vector3d> WindInput::at(double t_s) const {
  if (wind_ && t_s - stamp_s_ <= max_age_s_) return wind_;
  return std::nullopt;
}

}  // namespace gesture_formation::onboard
