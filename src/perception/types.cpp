#include "gesture_formation/perception/types.hpp"

#include <algorithm>

namespace gesture_formation::perception {

const std::array<const char*, kNumKeypoints>& cocoKeypointNames() {
  static const std::array<const char*, kNumKeypoints> names = {
      "nose",       "left_eye",    "right_eye", "left_ear",  "right_ear",  "left_shoulder",
      "right_shoulder", "left_elbow", "right_elbow", "left_wrist", "right_wrist", "left_hip",
      "right_hip",  "left_knee",   "right_knee", "left_ankle", "right_ankle"};
  return names;
}

const std::vector<std::pair<int, int>>& cocoLimbs() {
  static const std::vector<std::pair<int, int>> limbs = {
      {kLeftEar, kLeftEye},        {kLeftEye, kNose},           {kNose, kRightEye},        {kRightEye, kRightEar},
      {kLeftShoulder, kRightShoulder}, {kLeftShoulder, kLeftElbow}, {kLeftElbow, kLeftWrist},
      {kRightShoulder, kRightElbow}, {kRightElbow, kRightWrist}, {kLeftShoulder, kLeftHip},
      {kRightShoulder, kRightHip}, {kLeftHip, kRightHip},       {kLeftHip, kLeftKnee},     {kLeftKnee, kLeftAnkle},
      {kRightHip, kRightKnee},     {kRightKnee, kRightAnkle}};
  return limbs;
}

float iou(const cv::Rect2f& a, const cv::Rect2f& b) {
  if (!(a.width > 0 && a.height > 0 && b.width > 0 && b.height > 0)) return 0.0f;
  const float x0 = std::max(a.x, b.x), y0 = std::max(a.y, b.y);
  const float x1 = std::min(a.x + a.width, b.x + b.width), y1 = std::min(a.y + a.height, b.y + b.height);
  const float inter = std::max(0.0f, x1 - x0) * std::max(0.0f, y1 - y0);
  const float uni = a.area() + b.area() - inter;
  return uni > 0.0f ? inter / uni : 0.0f;
}

}  // namespace gesture_formation::perception
