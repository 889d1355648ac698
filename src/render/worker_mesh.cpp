#include "gesture_formation/render/worker_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <random>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

namespace gesture_formation::render {

namespace {

using Eigen::Matrix3d;
using Eigen::Quaterniond;
using Eigen::Vector3d;
namespace g = gesture;

/// glTF (x the figure's left, y up, z its front) → body frame (x forward, y left, z up).
Vector3d toBody(const aiVector3D& v) { return Vector3d(v.z, v.x, v.y); }

/// The joints the posing drives (SMPL-X names as the asset has them).
enum J : int {
  kPelvis, kLHip, kRHip, kSpine1, kSpine2, kSpine3, kLKnee, kRKnee, kLAnkle, kRAnkle, kLFoot, kRFoot, kNeck,
  kLCollar, kRCollar, kHead, kLShoulder, kRShoulder, kLElbow, kRElbow, kLWrist, kRWrist, kNumNamed
};
const std::array<const char*, kNumNamed> kJointNames{
    "Pelvis", "L_Hip", "R_Hip", "Spine1", "Spine2", "Spine3", "L_Knee", "R_Knee", "L_Ankle", "R_Ankle", "L_Foot",
    "R_Foot", "Neck", "L_Collar", "R_Collar", "Head", "L_Shoulder", "R_Shoulder", "L_Elbow", "R_Elbow", "L_Wrist",
    "R_Wrist"};

/// The right-handed frame of orthonormal x and z.
Matrix3d frameOf(const Vector3d& x, const Vector3d& z) {
  Matrix3d F;
  F.col(0) = x;
  F.col(1) = z.cross(x);
  F.col(2) = z;
  return F;
}

/// Orthonormal frame with x along a and z along the part of b orthogonal to a.
Matrix3d frameXZ(const Vector3d& a, const Vector3d& b) {
  const Vector3d x = a.normalized();
  return frameOf(x, (b - b.dot(x) * x).normalized());
}

/// Orthonormal frame with z along `up` and x along the part of `lateral` orthogonal to it.
Matrix3d frameUp(const Vector3d& up, const Vector3d& lateral) {
  const Vector3d z = up.normalized();
  return frameOf((lateral - lateral.dot(z) * z).normalized(), z);
}

Matrix3d slerp(const Matrix3d& a, const Matrix3d& b, double t) {
  return Quaterniond(a).slerp(t, Quaterniond(b)).toRotationMatrix();
}

Matrix3d swing(const Vector3d& from, const Vector3d& to) {
  return Quaterniond::FromTwoVectors(from, to).toRotationMatrix();
}

/// Vertex regions for dressing.
enum class Region { kSkin, kTorso, kUpperArm, kForearm, kHand, kLegs, kFeet, kHeadTop, kEye, kMouth };

}  // namespace

struct WorkerMesh::Impl {
  std::vector<std::string> joint_names;
  std::vector<int> parent;                  ///< -1 for the root
  std::vector<int> order;                   ///< parents before children
  std::array<int, kNumNamed> named{};       ///< J → joint index
  std::vector<Vector3d> rest_p;             ///< vertices, body frame, unscaled
  std::vector<Vector3d> rest_n;
  std::vector<std::array<int, 4>> vj;       ///< skin joints per vertex
  std::vector<std::array<float, 4>> vw;     ///< skin weights per vertex (sum 1)
  std::vector<int> dominant;                ///< strongest joint per vertex
  std::vector<std::uint32_t> indices;
  std::vector<Region> region;
  int v_nose = 0, v_eye_l = 0, v_eye_r = 0, v_ear_l = 0, v_ear_r = 0, v_head_top = 0;
  std::vector<Vector3d> colours;            ///< per vertex (dress)
  std::vector<Matrix3d> G;                  ///< posed joint rotations (scratch)
  std::vector<Vector3d> P;                  ///< posed joint positions (scratch)
};

WorkerMesh::WorkerMesh() : impl_(std::make_unique<Impl>()) {}
WorkerMesh::~WorkerMesh() = default;

const char* toString(Outfit outfit) {
  switch (outfit) {
    case Outfit::kHiVisHelmet: return "hivis_helmet";
    case Outfit::kWorkClothes: return "work_clothes";
  }
  return "?";
}

const std::array<Rgb, 6>& skinTones() {
  static const std::array<Rgb, 6> t{Rgb(0.96f, 0.80f, 0.69f), Rgb(0.90f, 0.70f, 0.56f), Rgb(0.80f, 0.60f, 0.45f),
                                    Rgb(0.66f, 0.46f, 0.32f), Rgb(0.48f, 0.32f, 0.22f), Rgb(0.33f, 0.22f, 0.15f)};
  return t;
}

std::vector<std::string> Appearance::validate() const {
  std::vector<std::string> e;
  if (skin_tone < 0 || skin_tone >= static_cast<int>(skinTones().size())) {
    e.push_back("appearance.skin_tone must be in [0, 5], got " + std::to_string(skin_tone));
  }
  return e;
}

Appearance Appearance::fromSeed(std::uint64_t seed) {
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 0x52454E44ull);
  Appearance a;
  a.outfit = std::uniform_int_distribution<int>(0, 1)(rng) == 0 ? Outfit::kHiVisHelmet : Outfit::kWorkClothes;
  a.skin_tone = std::uniform_int_distribution<int>(0, 5)(rng);
  a.seed = rng();
  return a;
}

WorkerJoints WorkerJoints::fromBody(const g::Body3D& body, const Vector3d& feet_world, double heading_rad) {
  const Matrix3d R = Eigen::AngleAxisd(heading_rad, Vector3d::UnitZ()).toRotationMatrix();
  WorkerJoints w;
  for (int k = 0; k < g::kNumKeypoints; ++k) w.p_world[static_cast<std::size_t>(k)] = feet_world + R * body.p[static_cast<std::size_t>(k)];
  w.head_top_world = feet_world + R * body.head_top;
  return w;
}

namespace {

/// Picks the face landmarks and the regions (rest pose, body frame) once at load.
void classifyVertices(WorkerMesh::Impl& m) {
  const std::size_t n = m.rest_p.size();
  const int head = m.named[kHead];
  Vector3d lo = Vector3d::Constant(1e9), hi = Vector3d::Constant(-1e9);
  for (std::size_t i = 0; i < n; ++i) {
    if (m.dominant[i] != head) continue;
    lo = lo.cwiseMin(m.rest_p[i]);
    hi = hi.cwiseMax(m.rest_p[i]);
  }
  const double hz = hi.z() - lo.z();
  auto nearestHead = [&](const Vector3d& target) {
    int best = 0;
    double bd = 1e18;
    for (std::size_t i = 0; i < n; ++i) {
      if (m.dominant[i] != head) continue;
      const double d = (m.rest_p[i] - target).squaredNorm();
      if (d < bd) bd = d, best = static_cast<int>(i);
    }
    return best;
  };
  const double z_nose = lo.z() + 0.40 * hz, z_eye = lo.z() + 0.52 * hz, z_mouth = lo.z() + 0.27 * hz;
  m.v_nose = nearestHead(Vector3d(hi.x() + 0.05, 0.0, z_nose));
  const double eye_dy = 0.30 * (hi.y() - lo.y()) / 2.0;
  m.v_eye_l = nearestHead(Vector3d(hi.x() + 0.05, eye_dy, z_eye));
  m.v_eye_r = nearestHead(Vector3d(hi.x() + 0.05, -eye_dy, z_eye));
  const double x_mid = 0.5 * (lo.x() + hi.x());
  m.v_ear_l = nearestHead(Vector3d(x_mid - 0.01, hi.y() + 0.05, z_eye - 0.03));
  m.v_ear_r = nearestHead(Vector3d(x_mid - 0.01, lo.y() - 0.05, z_eye - 0.03));
  m.v_head_top = nearestHead(Vector3d(x_mid, 0.0, hi.z() + 0.05));

  const std::map<int, Region> by_joint{
      {m.named[kPelvis], Region::kLegs},      {m.named[kLHip], Region::kLegs},       {m.named[kRHip], Region::kLegs},
      {m.named[kLKnee], Region::kLegs},       {m.named[kRKnee], Region::kLegs},      {m.named[kLAnkle], Region::kFeet},
      {m.named[kRAnkle], Region::kFeet},      {m.named[kLFoot], Region::kFeet},      {m.named[kRFoot], Region::kFeet},
      {m.named[kSpine1], Region::kTorso},     {m.named[kSpine2], Region::kTorso},    {m.named[kSpine3], Region::kTorso},
      {m.named[kLCollar], Region::kTorso},    {m.named[kRCollar], Region::kTorso},   {m.named[kNeck], Region::kSkin},
      {m.named[kLShoulder], Region::kUpperArm}, {m.named[kRShoulder], Region::kUpperArm},
      {m.named[kLElbow], Region::kForearm},   {m.named[kRElbow], Region::kForearm}};
  m.region.assign(n, Region::kHand);  // wrists, hands, fingers
  const Vector3d eye_l = m.rest_p[static_cast<std::size_t>(m.v_eye_l)], eye_r = m.rest_p[static_cast<std::size_t>(m.v_eye_r)];
  for (std::size_t i = 0; i < n; ++i) {
    const auto it = by_joint.find(m.dominant[i]);
    if (it != by_joint.end()) m.region[i] = it->second;
    if (m.dominant[i] != head) continue;
    const Vector3d& p = m.rest_p[i];
    const double fz = (p.z() - lo.z()) / hz;
    const bool front = p.x() > x_mid + 0.25 * (hi.x() - lo.x());
    if (fz > 0.70 || (!front && fz > 0.45 && p.x() < x_mid - 0.2 * (hi.x() - lo.x()))) {
      m.region[i] = Region::kHeadTop;
    } else if (front && std::min((p - eye_l).norm(), (p - eye_r).norm()) < 0.011) {
      m.region[i] = Region::kEye;
    } else if (front && std::abs(p.z() - z_mouth) < 0.006 && std::abs(p.y()) < 0.022) {
      m.region[i] = Region::kMouth;
    } else {
      m.region[i] = Region::kSkin;
    }
  }
}

}  // namespace

namespace {

/// Joints (every bone of the mesh), their parents and bind positions (node hierarchy, body frame),
/// the named joints the posing drives and a parents-first order. Returns "" or what is wrong.
std::string readSkeleton(const aiScene& scene, const aiMesh& mesh, WorkerMesh::Impl& m, std::vector<Vector3d>& bind_body) {
  std::map<std::string, int> index;
  for (unsigned b = 0; b < mesh.mNumBones; ++b) {
    index[mesh.mBones[b]->mName.C_Str()] = static_cast<int>(b);
    m.joint_names.push_back(mesh.mBones[b]->mName.C_Str());
  }
  const std::size_t nj = m.joint_names.size();
  m.parent.assign(nj, -1);
  bind_body.assign(nj, Vector3d::Zero());
  for (std::size_t j = 0; j < nj; ++j) {
    const aiNode* node = scene.mRootNode->FindNode(m.joint_names[j].c_str());
    if (node == nullptr) return "no node for joint " + m.joint_names[j];
    aiMatrix4x4 global = node->mTransformation;
    for (const aiNode* p = node->mParent; p != nullptr; p = p->mParent) global = p->mTransformation * global;
    bind_body[j] = toBody(aiVector3D(global.a4, global.b4, global.c4));
    if (node->mParent != nullptr) {
      const auto it = index.find(node->mParent->mName.C_Str());
      if (it != index.end()) m.parent[j] = it->second;
    }
  }
  for (std::size_t k = 0; k < kJointNames.size(); ++k) {
    const auto it = index.find(kJointNames[k]);
    if (it == index.end()) return std::string("no joint ") + kJointNames[k];
    m.named[k] = it->second;
  }
  std::vector<bool> done(nj, false);
  while (m.order.size() < nj) {
    const std::size_t before = m.order.size();
    for (std::size_t j = 0; j < nj; ++j) {
      if (done[j] || (m.parent[j] >= 0 && !done[static_cast<std::size_t>(m.parent[j])])) continue;
      done[j] = true;
      m.order.push_back(static_cast<int>(j));
    }
    if (m.order.size() == before) return "the skeleton has a cycle";
  }
  m.G.assign(nj, Matrix3d::Identity());
  m.P.assign(nj, Vector3d::Zero());
  return "";
}

/// Vertices and normals (body frame), the 4 strongest skin weights renormalised, each vertex's
/// strongest joint, triangles. Returns "" or what is wrong.
std::string readSkin(const aiMesh& mesh, WorkerMesh::Impl& m) {
  const std::size_t nv = mesh.mNumVertices;
  m.rest_p.resize(nv);
  m.rest_n.resize(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    m.rest_p[i] = toBody(mesh.mVertices[i]);
    m.rest_n[i] = toBody(mesh.mNormals[i]).normalized();
  }
  std::vector<std::vector<std::pair<float, int>>> influences(nv);
  for (unsigned b = 0; b < mesh.mNumBones; ++b) {
    const aiBone* bone = mesh.mBones[b];
    for (unsigned k = 0; k < bone->mNumWeights; ++k) {
      const auto& vw = bone->mWeights[k];
      if (vw.mVertexId < nv && vw.mWeight > 0.0f) influences[vw.mVertexId].push_back({vw.mWeight, static_cast<int>(b)});
    }
  }
  m.vj.resize(nv);
  m.vw.resize(nv);
  m.dominant.resize(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    auto& list = influences[i];
    if (list.empty()) return "vertex " + std::to_string(i) + " has no skin weight";
    std::sort(list.begin(), list.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    float sum = 0.0f;
    for (std::size_t k = 0; k < 4; ++k) {
      m.vj[i][k] = k < list.size() ? list[k].second : list[0].second;
      m.vw[i][k] = k < list.size() ? list[k].first : 0.0f;
      sum += m.vw[i][k];
    }
    for (auto& x : m.vw[i]) x /= sum;
    m.dominant[i] = list[0].second;
  }
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    if (mesh.mFaces[f].mNumIndices != 3) continue;
    for (int k = 0; k < 3; ++k) m.indices.push_back(mesh.mFaces[f].mIndices[k]);
  }
  return "";
}

}  // namespace

common::Result<std::shared_ptr<WorkerMesh>> WorkerMesh::load(const std::string& glb_path) {
  using R = common::Result<std::shared_ptr<WorkerMesh>>;
  const std::string how = " (regenerate it: tools/setup.sh, then /opt/gesture_formation/venv/bin/python "
                          "tools/models/convert_mannequin.py; docs/rendering.md)";
  auto fail = [&](const std::string& what) { return R::fail("worker asset " + glb_path + ": " + what + how); };
  if (!std::ifstream(glb_path).good()) return fail("no such file");
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(glb_path, aiProcess_Triangulate);
  if (scene == nullptr || scene->mNumMeshes == 0) return fail(std::string("Assimp cannot read it (") + importer.GetErrorString() + ")");
  const aiMesh* mesh = scene->mMeshes[0];
  if (mesh->mNumBones == 0 || !mesh->HasNormals()) return fail("its mesh has no skin or no normals");
  std::shared_ptr<WorkerMesh> w(new WorkerMesh());
  Impl& m = *w->impl_;
  std::string error = readSkeleton(*scene, *mesh, m, w->bind_body_);
  if (error.empty()) error = readSkin(*mesh, m);
  if (!error.empty()) return fail(error);
  double zmin = 1e9, zmax = -1e9;
  for (const auto& p : m.rest_p) zmin = std::min(zmin, p.z()), zmax = std::max(zmax, p.z());
  w->rest_height_m_ = zmax - zmin;
  classifyVertices(m);
  w->dress(Appearance());
  // the rest pose as the initial mesh
  w->posed_.indices = m.indices;
  w->posed_.vertices.resize(m.rest_p.size());
  for (std::size_t i = 0; i < m.rest_p.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      w->posed_.vertices[i].p[k] = static_cast<float>(m.rest_p[i][k]);
      w->posed_.vertices[i].n[k] = static_cast<float>(m.rest_n[i][k]);
      w->posed_.vertices[i].c[k] = static_cast<float>(m.colours[i][k]);
    }
  }
  return R::ok(w);
}

void WorkerMesh::dress(const Appearance& a) {
  Impl& m = *impl_;
  std::mt19937_64 rng(a.seed);
  auto pick = [&](std::initializer_list<Vector3d> options) {
    const std::vector<Vector3d> v(options);
    return v[std::uniform_int_distribution<std::size_t>(0, v.size() - 1)(rng)];
  };
  const Rgb st = skinTones()[static_cast<std::size_t>(std::clamp(a.skin_tone, 0, 5))];
  const Vector3d skin(st.x(), st.y(), st.z());
  const Vector3d shirt = pick({{0.15, 0.22, 0.45}, {0.55, 0.55, 0.57}, {0.20, 0.35, 0.25}, {0.60, 0.20, 0.15}, {0.85, 0.85, 0.82}});
  const Vector3d trousers = pick({{0.10, 0.12, 0.22}, {0.35, 0.32, 0.25}, {0.22, 0.30, 0.45}, {0.18, 0.18, 0.18}});
  const Vector3d boots = pick({{0.08, 0.07, 0.06}, {0.30, 0.20, 0.12}});
  const Vector3d vest = pick({{0.85, 1.0, 0.10}, {1.0, 0.45, 0.05}});
  const Vector3d helmet = pick({{0.98, 0.98, 0.95}, {1.0, 0.80, 0.05}, {0.95, 0.40, 0.05}});
  const Vector3d hair = pick({{0.08, 0.06, 0.05}, {0.25, 0.16, 0.09}, {0.45, 0.38, 0.30}, {0.60, 0.45, 0.25}});
  const bool short_sleeves = a.outfit == Outfit::kWorkClothes && std::uniform_int_distribution<int>(0, 1)(rng) == 1;
  const bool hivis = a.outfit == Outfit::kHiVisHelmet;
  // reflective bands of the vest: two horizontal stripes on the torso (rest heights, fractions of the height)
  const double h = rest_height_m_;
  double zmin = 1e9;
  for (const auto& p : m.rest_p) zmin = std::min(zmin, p.z());
  m.colours.resize(m.rest_p.size());
  for (std::size_t i = 0; i < m.rest_p.size(); ++i) {
    const double fz = (m.rest_p[i].z() - zmin) / h;
    Vector3d c = skin;
    switch (m.region[i]) {
      case Region::kSkin: c = skin; break;
      case Region::kHand: c = skin; break;
      case Region::kEye: c = Vector3d(0.06, 0.05, 0.05); break;
      case Region::kMouth: c = Vector3d(0.45, 0.15, 0.13); break;
      case Region::kHeadTop: c = hivis ? helmet : hair; break;
      case Region::kTorso:
        c = hivis ? ((std::abs(fz - 0.63) < 0.015 || std::abs(fz - 0.72) < 0.015) ? Vector3d(0.82, 0.84, 0.86) : vest) : shirt;
        break;
      case Region::kUpperArm: c = shirt; break;
      case Region::kForearm: c = short_sleeves ? skin : shirt; break;
      case Region::kLegs: c = (hivis && fz > 0.57) ? vest : trousers; break;  // the vest covers the hips' top
      case Region::kFeet: c = boots; break;
    }
    m.colours[i] = c;
  }
  for (std::size_t i = 0; i < posed_.vertices.size() && i < m.colours.size(); ++i) {
    for (int k = 0; k < 3; ++k) posed_.vertices[i].c[k] = static_cast<float>(m.colours[i][k]);
  }
}

namespace {

/// The stages of WorkerMesh::pose on one asset, one set of model joints and one scale: joint
/// rotations (trunk, limbs, the joints that follow), forward kinematics with placement, skinning.
class Poser {
 public:
  Poser(WorkerMesh::Impl& m, const std::vector<Vector3d>& bind_body, const WorkerJoints& t, double scale)
      : m_(m), bind_(bind_body), t_(t), s_(scale) {}

  void rotations() {
    trunk();
    for (bool left : {true, false}) {
      leg(left);
      arm(left);
    }
    hands();
  }

  /// Joint positions from the rotations; pelvis over the model's hip centre, lower ankle at its height.
  void forwardKinematics() {
    for (int j : m_.order) {
      const auto ju = static_cast<std::size_t>(j);
      const int p = m_.parent[ju];
      const auto pu = static_cast<std::size_t>(p);
      m_.P[ju] = p < 0 ? Vector3d::Zero() : Vector3d(m_.P[pu] + m_.G[pu] * (s_ * (bind_[ju] - bind_[pu])));
    }
    Vector3d shift = 0.5 * (T(g::kLeftHip) + T(g::kRightHip)) - 0.5 * (P(kLHip) + P(kRHip));
    shift.z() = std::min(T(g::kLeftAnkle).z(), T(g::kRightAnkle).z()) - std::min(P(kLAnkle).z(), P(kRAnkle).z());
    for (auto& p : m_.P) p += shift;
  }

  /// Linear blend skinning of positions and normals into `out`; returns the skinned positions.
  std::vector<Vector3d> skin(TriangleMesh& out) const {
    const std::size_t nv = m_.rest_p.size();
    out.vertices.resize(nv);
    std::vector<Vector3d> skinned(nv);
    for (std::size_t i = 0; i < nv; ++i) {
      Vector3d p = Vector3d::Zero(), n = Vector3d::Zero();
      for (std::size_t k = 0; k < 4; ++k) {
        const float wk = m_.vw[i][k];
        if (wk == 0.0f) continue;
        const auto j = static_cast<std::size_t>(m_.vj[i][k]);
        p += wk * (m_.G[j] * (s_ * (m_.rest_p[i] - bind_[j])) + m_.P[j]);
        n += wk * (m_.G[j] * m_.rest_n[i]);
      }
      n.normalize();
      skinned[i] = p;
      Vertex& v = out.vertices[i];
      for (int c = 0; c < 3; ++c) {
        v.p[c] = static_cast<float>(p[c]);
        v.n[c] = static_cast<float>(n[c]);
        v.c[c] = static_cast<float>(m_.colours[i][c]);
      }
    }
    if (out.indices.size() != m_.indices.size()) out.indices = m_.indices;
    return skinned;
  }

  /// Truth keypoints: the mesh's joints, and skinned face points.
  void keypoints(const std::vector<Vector3d>& skinned, PosedKeypoints& kp) const {
    kp.on_surface.fill(false);
    const std::array<std::pair<int, int>, 12> joints{{{g::kLeftShoulder, kLShoulder}, {g::kRightShoulder, kRShoulder},
                                                      {g::kLeftElbow, kLElbow},       {g::kRightElbow, kRElbow},
                                                      {g::kLeftWrist, kLWrist},       {g::kRightWrist, kRWrist},
                                                      {g::kLeftHip, kLHip},           {g::kRightHip, kRHip},
                                                      {g::kLeftKnee, kLKnee},         {g::kRightKnee, kRKnee},
                                                      {g::kLeftAnkle, kLAnkle},       {g::kRightAnkle, kRAnkle}}};
    for (const auto& [coco, joint] : joints) kp.p_world[static_cast<std::size_t>(coco)] = P(joint);
    const std::array<std::pair<int, int>, 5> face{{{g::kNose, m_.v_nose}, {g::kLeftEye, m_.v_eye_l}, {g::kRightEye, m_.v_eye_r},
                                                   {g::kLeftEar, m_.v_ear_l}, {g::kRightEar, m_.v_ear_r}}};
    for (const auto& [coco, v] : face) {
      kp.p_world[static_cast<std::size_t>(coco)] = skinned[static_cast<std::size_t>(v)];
      kp.on_surface[static_cast<std::size_t>(coco)] = true;
    }
  }

 private:
  std::size_t idx(int k) const { return static_cast<std::size_t>(m_.named[static_cast<std::size_t>(k)]); }
  Vector3d rj(int k) const { return s_ * bind_[idx(k)]; }  ///< rest joint, scaled
  Vector3d rv(int v) const { return s_ * m_.rest_p[static_cast<std::size_t>(v)]; }  ///< rest vertex, scaled
  const Vector3d& T(int coco) const { return t_.p_world[static_cast<std::size_t>(coco)]; }
  const Vector3d& P(int k) const { return m_.P[idx(k)]; }
  void setG(int k, const Matrix3d& R) { m_.G[idx(k)] = R; }
  const Matrix3d& G(int k) const { return m_.G[idx(k)]; }

  /// Pelvis, spine, collars, neck, head: the trunk axis (hip centre → shoulder centre) and the
  /// head axis (ear centre → head top) exactly, the hip / shoulder / ear lines as near as they allow.
  void trunk() {
    const Vector3d hip_t = 0.5 * (T(g::kLeftHip) + T(g::kRightHip)), sh_t = 0.5 * (T(g::kLeftShoulder) + T(g::kRightShoulder));
    const Vector3d hip_r = 0.5 * (rj(kLHip) + rj(kRHip)), sh_r = 0.5 * (rj(kLShoulder) + rj(kRShoulder));
    pelvis_ = frameUp(sh_t - hip_t, T(g::kLeftHip) - T(g::kRightHip)) * frameUp(sh_r - hip_r, rj(kLHip) - rj(kRHip)).transpose();
    const Matrix3d chest = frameUp(sh_t - hip_t, T(g::kLeftShoulder) - T(g::kRightShoulder)) *
                           frameUp(sh_r - hip_r, rj(kLShoulder) - rj(kRShoulder)).transpose();
    const Vector3d ear_t = 0.5 * (T(g::kLeftEar) + T(g::kRightEar)), ear_r = 0.5 * (rv(m_.v_ear_l) + rv(m_.v_ear_r));
    const Matrix3d head = frameUp(t_.head_top_world - ear_t, T(g::kLeftEar) - T(g::kRightEar)) *
                          frameUp(rv(m_.v_head_top) - ear_r, rv(m_.v_ear_l) - rv(m_.v_ear_r)).transpose();
    for (auto& R : m_.G) R = pelvis_;  // joints not set below follow the pelvis
    setG(kSpine1, slerp(pelvis_, chest, 1.0 / 3.0));
    setG(kSpine2, slerp(pelvis_, chest, 2.0 / 3.0));
    for (int k : {kSpine3, kLCollar, kRCollar}) setG(k, chest);
    setG(kNeck, slerp(chest, head, 0.5));
    setG(kHead, head);
  }

  /// The upper bone turned onto `a_t` in its bend plane (normal `n_rest` at rest; `n_fallback`
  /// when the limb is straight, or a pure swing from the parent when that is zero), the lower
  /// bone by the remaining swing onto `f_t`.
  void limb(int upper, int lower, int end, int parent, const Vector3d& a_t, const Vector3d& f_t, const Vector3d& n_rest,
            const Vector3d& n_fallback) {
    const Vector3d a_r = rj(lower) - rj(upper), f_r = rj(end) - rj(lower);
    const Matrix3d Gp = G(parent);
    const Matrix3d G_swing = swing(Gp * a_r, a_t) * Gp;
    const Vector3d bend = a_t.normalized().cross(f_t.normalized());
    const double sin_bend = bend.norm();
    const bool has_fallback = n_fallback.squaredNorm() > 0.0;
    Matrix3d G_up = G_swing;
    if (sin_bend > 1e-6 || has_fallback) {
      const Vector3d n_t = sin_bend > 1e-6 ? Vector3d(bend / sin_bend) : n_fallback;
      const Matrix3d G_hinge = frameXZ(a_t, n_t) * frameXZ(a_r, n_rest).transpose();
      const double w = has_fallback ? 1.0 : std::clamp((sin_bend - 0.05) / 0.15, 0.0, 1.0);
      G_up = slerp(G_swing, G_hinge, w);
    }
    setG(upper, G_up);
    setG(lower, swing(G_up * f_r, f_t) * G_up);
  }

  /// Legs: the knee bends about the lateral axis (rest: straight legs); feet follow the pelvis.
  void leg(bool L) {
    const Vector3d lateral = pelvis_ * Vector3d::UnitY();
    const Vector3d a = T(L ? g::kLeftKnee : g::kRightKnee) - T(L ? g::kLeftHip : g::kRightHip);
    const Vector3d f = T(L ? g::kLeftAnkle : g::kRightAnkle) - T(L ? g::kLeftKnee : g::kRightKnee);
    Vector3d n = a.normalized().cross(f.normalized());
    if (n.norm() < 0.05 || n.dot(lateral) < 0.0) n = lateral;
    limb(L ? kLHip : kRHip, L ? kLKnee : kRKnee, L ? kLAnkle : kRAnkle, kPelvis, a, f, Vector3d::UnitY(), n.normalized());
    for (int k : {L ? kLAnkle : kRAnkle, L ? kLFoot : kRFoot}) setG(k, pelvis_);
  }

  /// Arms: rest T-pose, the elbow bends the forearm forward; the hand continues the forearm.
  void arm(bool L) {
    const Vector3d a = T(L ? g::kLeftElbow : g::kRightElbow) - T(L ? g::kLeftShoulder : g::kRightShoulder);
    const Vector3d f = T(L ? g::kLeftWrist : g::kRightWrist) - T(L ? g::kLeftElbow : g::kRightElbow);
    const Vector3d a_rest = rj(L ? kLElbow : kRElbow) - rj(L ? kLShoulder : kRShoulder);
    limb(L ? kLShoulder : kRShoulder, L ? kLElbow : kRElbow, L ? kLWrist : kRWrist, L ? kLCollar : kRCollar, a, f,
         a_rest.normalized().cross(Vector3d::UnitX()).normalized(), Vector3d::Zero());
    setG(L ? kLWrist : kRWrist, G(L ? kLElbow : kRElbow));
  }

  /// Hands and fingers (the joints the posing does not drive) follow their parent.
  void hands() {
    for (int j : m_.order) {
      const auto ju = static_cast<std::size_t>(j);
      if (m_.parent[ju] < 0) continue;
      const std::string& name = m_.joint_names[ju];
      const bool driven = std::find(kJointNames.begin(), kJointNames.end(), name) != kJointNames.end();
      if (!driven && (name.rfind("L_", 0) == 0 || name.rfind("R_", 0) == 0)) m_.G[ju] = m_.G[static_cast<std::size_t>(m_.parent[ju])];
    }
  }

  WorkerMesh::Impl& m_;
  const std::vector<Vector3d>& bind_;
  const WorkerJoints& t_;
  double s_;
  Matrix3d pelvis_ = Matrix3d::Identity();
};

}  // namespace

common::Result<bool> WorkerMesh::pose(const WorkerJoints& t, double height_m) {
  using R = common::Result<bool>;
  if (!(height_m >= 1.0 && height_m <= 2.3)) return R::fail("worker height_m must be in [1.0, 2.3], got " + std::to_string(height_m));
  for (const auto& p : t.p_world) {
    if (!p.allFinite()) return R::fail("worker joints: a keypoint is not finite");
  }
  if (!t.head_top_world.allFinite()) return R::fail("worker joints: head_top is not finite");
  Poser poser(*impl_, bind_body_, t, height_m / rest_height_m_);
  poser.rotations();
  poser.forwardKinematics();
  poser.keypoints(poser.skin(posed_), keypoints_);
  return R::ok(true);
}

}  // namespace gesture_formation::render
