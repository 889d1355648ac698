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

std::optional<std::string> depthAlignmentProblem(int depth_width, int depth_height, const std::string& depth_frame,
                                                 int colour_width, int colour_height, const std::string& colour_frame) {
  const auto bare = [](const std::string& f) { return f.empty() || f[0] != '/' ? f : f.substr(1); };
  const bool same_frame = depth_frame.empty() || colour_frame.empty() || bare(depth_frame) == bare(colour_frame);
  if (depth_width == colour_width && depth_height == colour_height && same_frame) return std::nullopt;
  return "depth image " + std::to_string(depth_width) + "x" + std::to_string(depth_height) + " in '" + depth_frame +
         "', the colour image " + std::to_string(colour_width) + "x" + std::to_string(colour_height) + " in '" +
         colour_frame + "' (depth aligned to the colour image expected)";
}

}  // namespace gesture_formation::onboard
