#pragma once
/// \file
/// \brief The worker's skinned mesh (docs/rendering.md "The worker"): the wooden mannequin of
/// `third_party_models/mannequin/wooden_mannequin.glb` (54-joint SMPL-X skeleton, 4 skin
/// weights per vertex) loaded with Assimp, dressed by per-joint vertex colours (an outfit and
/// a skin tone), and posed from the worker model's joints — the 17 COCO keypoints and the top
/// of the head that gesture::SkeletonSynthesizer::pose gives (gesture/skeleton_synth.hpp) —
/// by linear blend skinning on the CPU.
///
/// Posing: each bone of the mannequin is turned to point where the worker model's bone points
/// (pelvis and chest from the hips and shoulders, the head from the ears, nose and head top,
/// upper limbs with their bend plane, feet following the pelvis); the mannequin keeps its own
/// bone lengths scaled to the worker's height, its pelvis sits at the model's hip centre and its
/// lower ankle at the model's lower ankle height. The truth keypoints are the *posed mesh's*:
/// its joints for shoulders … ankles and skinned surface points (nose, eyes, ears) for the face,
/// so they match the rendered pixels, not the (slightly differently proportioned) model.
/// Frames: world as docs/conventions.md; the body frame of the worker model is x forward,
/// y left, z up with the feet at z = 0.
/// Thread safety: none (pose() updates internal buffers); const methods are reentrant.

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/gesture/skeleton.hpp"
#include "gesture_formation/gesture/skeleton_synth.hpp"
#include "gesture_formation/render/mesh.hpp"

namespace gesture_formation::render {

/// \brief What the worker wears.
enum class Outfit {
  kHiVisHelmet,   ///< hi-vis vest with reflective bands over a long-sleeved shirt, helmet, work trousers, boots
  kWorkClothes,   ///< plain work shirt and trousers, boots, bare head (hair)
};
const char* toString(Outfit outfit);

/// \brief The worker's appearance. Colours are drawn from the outfit's palette by `seed`.
struct Appearance {
  Outfit outfit = Outfit::kHiVisHelmet;
  int skin_tone = 2;          ///< index into skinTones(), [0, 5]
  std::uint64_t seed = 1;     ///< varies shirt / trousers / helmet colours within the outfit
  std::vector<std::string> validate() const;
  /// \brief An appearance drawn from a seed: outfit, skin tone and colours.
  static Appearance fromSeed(std::uint64_t seed);
};
/// \brief Six skin tones (light to dark), linear RGB.
const std::array<Rgb, 6>& skinTones();

/// \brief The worker model's joints in the world frame [m]: the 17 COCO keypoints (order of
/// gesture/skeleton.hpp, "left" = the person's left) and the top of the head.
struct WorkerJoints {
  std::array<Eigen::Vector3d, gesture::kNumKeypoints> p_world;
  Eigen::Vector3d head_top_world = Eigen::Vector3d::Zero();
  /// \brief The synthesizer's body (body frame) placed with its feet at `feet_world` and its
  /// x axis at `heading_rad` (from world +x towards +y).
  static WorkerJoints fromBody(const gesture::Body3D& body, const Eigen::Vector3d& feet_world, double heading_rad);
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The posed mesh's truth keypoints in the world frame (COCO-17 order).
struct PosedKeypoints {
  std::array<Eigen::Vector3d, gesture::kNumKeypoints> p_world;
  /// True for keypoints on the surface (nose, eyes, ears), false for joints inside the body.
  std::array<bool, gesture::kNumKeypoints> on_surface{};
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The mannequin, dressed; pose() skins it.
class WorkerMesh {
 public:
  /// \brief Loads the .glb (path: a glTF 2.0 binary as tools/models/convert_mannequin.py
  /// writes). Fails naming the file and what is missing (no file, no skinned mesh, a joint
  /// the posing needs).
  static common::Result<std::shared_ptr<WorkerMesh>> load(const std::string& glb_path);

  /// \brief Sets the clothing colours (per dominant joint and region of each vertex).
  void dress(const Appearance& appearance);
  /// \brief Poses the mesh from the worker model's joints scaled to `height_m`; fails for
  /// non-finite joints or a height outside [1.0, 2.3] m.
  common::Result<bool> pose(const WorkerJoints& joints, double height_m);

  /// \brief The posed mesh (world frame) after the last pose(); the rest pose before.
  const TriangleMesh& mesh() const { return posed_; }
  /// \brief The posed truth keypoints after the last pose().
  const PosedKeypoints& keypoints() const { return keypoints_; }
  /// \brief Height of the unposed mannequin [m] (feet to head top).
  double restHeight() const { return rest_height_m_; }
  std::size_t jointCount() const { return bind_body_.size(); }

  struct Impl;  // asset data (public for the .cpp's helpers only)
  ~WorkerMesh();
  WorkerMesh(const WorkerMesh&) = delete;
  WorkerMesh& operator=(const WorkerMesh&) = delete;

 private:
  WorkerMesh();
  std::unique_ptr<Impl> impl_;
  std::vector<Eigen::Vector3d> bind_body_;  ///< joint bind positions, body frame, unscaled [m]
  double rest_height_m_ = 1.7;
  TriangleMesh posed_;
  PosedKeypoints keypoints_;
};

}  // namespace gesture_formation::render
