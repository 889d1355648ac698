#include "gesture_formation/onboard/frame_check.hpp"

namespace gesture_formation::onboard {

std::optional<std::string> checkFrame(const std::string& field, const std::string& expected, const std::string& received) {
  if (!expected.empty() && received == expected) return std::nullopt;
  return field + ": expected '" + expected + "', received '" + received + "'";
}

std::optional<std::string> checkOdometryFrames(const std::string& what, const OdometryFrames& expected,
                                               const std::string& frame_id, const std::string& child_frame_id) {
  if (auto e = checkFrame(what + " header.frame_id", expected.frame_id, frame_id)) return e;
  return checkFrame(what + " child_frame_id", expected.child_frame_id, child_frame_id);
}

OdometryFrames plannerOdometryFrames(const std::string& world_frame) { return OdometryFrames{world_frame, world_frame}; }

}  // namespace gesture_formation::onboard
