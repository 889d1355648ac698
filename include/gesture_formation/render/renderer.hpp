#pragma once
/// \file
/// \brief Headless rendering of one pinhole camera's colour and depth images with the truth of
/// the worker (docs/rendering.md; docs/design.md §9): OpenGL 3.3 core through EGL without a window
/// system (Mesa's surfaceless platform: llvmpipe on a CPU, a GPU's driver where there is one),
/// into an off-screen framebuffer that is read back each frame.
///
/// Usage (one Renderer per process or thread; the GL context, its buffers and the uploaded
/// world are reused across frames and cameras):
///   auto r = Renderer::create(config);            // EGL + GL + the worker asset
///   r->setWorld(scenario);                        // once: obstacles (planner's geometry), ground
///   per simulation frame: r->setWorker(joints, height, appearance); r->setUavs(poses);
///     per UAV i: r->render(camera_i, /*skip_uav=*/i)   → colour, depth, truth
///
/// Camera (docs/conventions.md): intrinsics as a sensor_msgs/CameraInfo carries them (fx, fy,
/// cx, cy, width, height; pixel centres at integer coordinates; distortion must be zero — the
/// rendered image is the rectified one), pose `T_world_camera` of the *optical* frame
/// (z forward, x right, y down).
/// Depth: metres along the optical axis (the z of the optical frame, as a RealSense aligned
/// depth image, not the ray length), CV_32FC1; NaN where the pixel sees nothing (sky, and
/// anything beyond `far_m`) as REP 118 asks of float depth images.
/// Thread safety: use a Renderer only from the thread that created it. Each call makes its EGL
/// context current on the calling thread and never releases it, and a context current on one
/// thread cannot be made current on another (the SimCamera nodelet therefore creates
/// and uses its renderer on one rendering thread). Several Renderers may live in one process.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/estimation/camera_model.hpp"
#include "gesture_formation/gesture/skeleton.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/render/mesh.hpp"
#include "gesture_formation/render/worker_mesh.hpp"

namespace gesture_formation::render {

/// \brief What each pixel sees (the class image, CV_8UC1).
/// Bystander i (Renderer::setBystanders) is drawn as kBystander + i.
enum class PixelClass : std::uint8_t { kSky = 0, kGround = 1, kObstacle = 2, kUav = 3, kWorker = 4, kBystander = 5 };
/// At most this many bystanders (their classes 5 .. 5 + kMaxBystanders - 1).
constexpr std::size_t kMaxBystanders = 8;

struct RendererConfig {
  /// The worker mesh (tools/models/convert_mannequin.py). Empty: no worker can be drawn.
  std::string worker_asset_path;
  double near_m = 0.05;    ///< near clipping plane, > 0
  double far_m = 1500.0;   ///< far clipping plane, > near_m; beyond it: sky (depth NaN)
  Eigen::Vector3d sun_direction_world{0.35, 0.25, 0.90};  ///< towards the sun, non-zero
  double ground_half_size_m = 1000.0;  ///< the ground square around the map's centre, > 0
  /// Tolerance of the truth visibility test [m]: a joint inside the body is visible when the
  /// surface seen at its pixel lies at most this much in front of it (0.06 m for the face
  /// points on the surface), > 0.
  double joint_visibility_margin_m = 0.20;
  std::vector<std::string> validate() const;
};

/// \brief A camera to render.
struct CameraView {
  estimation::CameraIntrinsics intrinsics;  ///< distortion must be zero
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();  ///< optical frame
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The optical-frame pose of a camera at `p_world` with heading φ and pitch ξ
/// (docs/conventions.md: φ from +x towards +y, ξ positive up), no roll.
Eigen::Isometry3d cameraPoseFromHeadingPitch(const Eigen::Vector3d& p_world, double heading_rad, double pitch_rad);

/// \brief The truth of one keypoint in one frame.
struct KeypointTruth {
  Eigen::Vector2d uv_px = Eigen::Vector2d::Zero();  ///< projection (pixel centres at integers)
  double depth_m = 0.0;    ///< z in the optical frame
  bool in_image = false;   ///< in front of the camera and inside [0, width) × [0, height)
  bool visible = false;    ///< in_image and not hidden (RendererConfig::joint_visibility_margin_m)
};

/// \brief The worker's truth in one frame.
struct WorkerTruth {
  bool drawn = false;  ///< a worker was set
  std::array<KeypointTruth, gesture::kNumKeypoints> keypoints;  ///< COCO-17 order
  /// Bounding box of the worker's visible pixels (u, v, w, h) [px]; empty when none is seen.
  cv::Rect visible_box_px;
  int visible_pixels = 0;
};

/// \brief Another person in the scene (a second crew member, a passer-by): the same mannequin, its
/// own pose and clothes.
struct Bystander {
  WorkerJoints joints;
  double height_m = 1.75;
  Appearance appearance;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief A bystander's truth in one frame: its visible pixels (class kBystander + i).
struct BystanderTruth {
  cv::Rect visible_box_px;  ///< empty when none is seen
  int visible_pixels = 0;
};

/// \brief One rendered frame.
struct RenderedFrame {
  cv::Mat rgb;       ///< CV_8UC3 in **RGB** order (sensor_msgs "rgb8"; cv::imwrite wants BGR)
  cv::Mat depth_m;   ///< CV_32FC1, metres along the optical axis, NaN where nothing
  cv::Mat classes;   ///< CV_8UC1, PixelClass per pixel
  WorkerTruth worker;
  std::vector<BystanderTruth> bystanders;  ///< one per bystander of setBystanders, in its order
};

class Renderer {
 public:
  /// \brief Creates the EGL context and loads the worker asset. Fails naming what is missing
  /// and how to get it (no EGL display / OpenGL 3.3 context: Mesa packages of
  /// tools/setup.sh; a missing asset: tools/models/convert_mannequin.py).
  static common::Result<std::unique_ptr<Renderer>> create(const RendererConfig& config);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// \brief Uploads the static world: the scenario's obstacles (obstacleMesh) and the ground
  /// plane at the scenario's ground height (z = 0 without a `ground` section).
  common::Result<bool> setWorld(const planning::Scenario& scenario);
  /// \brief Uploads an arbitrary static mesh as obstacles (tests) with the ground at `ground_z_m`.
  common::Result<bool> setWorldMesh(const TriangleMesh& obstacles, double ground_z_m, const Eigen::Vector3d& centre_world);
  /// \brief Obstacles of the site that are not part of the world mesh and may change between frames
  /// (a crane arm, scaffolding, a truck that drives off: sim::UnmappedObstacle): drawn as obstacles
  /// (class kObstacle) from the next render on, replacing the previous set; an empty mesh removes
  /// them. Fails (changing nothing) on a non-finite vertex or an index beyond the vertices.
  common::Result<bool> setSiteObstacles(const TriangleMesh& obstacles);
  /// \brief Poses, dresses and uploads the worker (call once per simulation frame).
  common::Result<bool> setWorker(const WorkerJoints& joints, double height_m, const Appearance& appearance);
  /// \brief No worker in the next frames.
  void clearWorker();
  /// \brief Poses, dresses and uploads the other people of the next frames (at most
  /// kMaxBystanders; empty: none). The worker's truth is unaffected.
  common::Result<bool> setBystanders(const std::vector<Bystander>& people);
  /// \brief Body poses (FLU) of the UAVs drawn in the next frames.
  void setUavs(const std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>>& T_world_body);

  /// \brief Renders one camera. `skip_uav`: index of the UAV carrying this camera (not drawn).
  common::Result<RenderedFrame> render(const CameraView& camera, std::optional<std::size_t> skip_uav = std::nullopt);

  /// \brief The GL renderer string (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)").
  const std::string& glRenderer() const;
  /// \brief The worker's posed truth keypoints (after setWorker; null without a worker), e.g. for
  /// tests — the worker's own, whatever bystanders were posed after it.
  const PosedKeypoints* workerKeypoints() const;

  struct Impl;

 private:
  explicit Renderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace gesture_formation::render
