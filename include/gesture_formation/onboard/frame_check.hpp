#pragma once
/// \file
/// \brief Frame checks for the messages the onboard nodelets consume (docs/ros.md, "Flight
/// stacks"): a message whose `header.frame_id` or `child_frame_id` is not the configured one is
/// refused — nothing from it is used — with a reason that names the field, the expected and the
/// received value. A ROS-free home so that every consumer (the OdometryAdapter, the
/// SetpointRelay, the FormationPlanner's `odometry_in`) refuses in the same words.

#include <optional>
#include <string>

namespace gesture_formation::onboard {

/// \brief The frames a nav_msgs/Odometry must carry: the pose is `child_frame_id` in
/// `frame_id`; the twist is expressed in `child_frame_id` (nav_msgs' definition).
struct OdometryFrames {
  std::string frame_id;        ///< the fixed frame (REP 105 map / odom; `world` in the simulation)
  std::string child_frame_id;  ///< the body (MAVROS base_link, MRS <uav>/fcu) or the fixed frame itself
};

/// \brief nullopt when `received` == `expected`; else "<field>: expected '<expected>', received
/// '<received>'". An empty expected name is never matched (a configuration error is not a wildcard).
std::optional<std::string> checkFrame(const std::string& field, const std::string& expected, const std::string& received);

/// \brief Both frames of an odometry message: the first mismatch (header.frame_id, then
/// child_frame_id), prefixed by `what` (e.g. "odometry_in").
std::optional<std::string> checkOdometryFrames(const std::string& what, const OdometryFrames& expected,
                                               const std::string& frame_id, const std::string& child_frame_id);

/// \brief What the FormationPlanner (and the ViewObserver) expect on `odometry_in` (docs/ros.md,
/// odometry convention): pose and twist in the world frame, `child_frame_id` = the world frame.
OdometryFrames plannerOdometryFrames(const std::string& world_frame);

/// \brief A depth image belongs to its colour image (aligned depth, docs/perception.md): the same
/// size and, where both name one, the same frame (compared without a leading '/'). nullopt when
/// aligned; else the reason naming both sizes and frames.
std::optional<std::string> depthAlignmentProblem(int depth_width, int depth_height, const std::string& depth_frame,
                                                 int colour_width, int colour_height, const std::string& colour_frame);

}  // namespace gesture_formation::onboard
