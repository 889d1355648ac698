#include "gesture_formation/render/mesh.hpp"

#include <algorithm>
#include <cmath>

#include "gesture_formation/planning/catenary.hpp"
#include "gesture_formation/planning/lattice_tower.hpp"

namespace gesture_formation::render {

namespace {

using Eigen::Vector3d;

Vertex vertex(const Vector3d& p, const Vector3d& n, const Rgb& c) {
  Vertex v{};
  for (int i = 0; i < 3; ++i) {
    v.p[i] = static_cast<float>(p[i]);
    v.n[i] = static_cast<float>(n[i]);
    v.c[i] = c[i];
  }
  return v;
}

void addQuad(TriangleMesh& m, const std::array<Vector3d, 4>& p, const Vector3d& n, const Rgb& c) {
  const auto base = static_cast<std::uint32_t>(m.vertices.size());
  for (const auto& q : p) m.vertices.push_back(vertex(q, n, c));
  for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
}

/// Sides so that the chord error r (1 − cos(π/n)) stays below kMaxChordErrorM.
int cylinderSides(double radius_m) {
  const double c = 1.0 - kMaxChordErrorM / std::max(radius_m, 1e-6);
  const double n = c <= -1.0 ? 8.0 : std::ceil(M_PI / std::acos(std::max(-1.0, c)));
  return std::clamp(static_cast<int>(n), 8, 128);
}

}  // namespace

void TriangleMesh::append(const TriangleMesh& other) {
  const auto base = static_cast<std::uint32_t>(vertices.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  indices.reserve(indices.size() + other.indices.size());
  for (std::uint32_t i : other.indices) indices.push_back(base + i);
}

TriangleMesh boxMesh(const planning::OrientedBox& box, const Rgb& colour) {
  TriangleMesh m;
  const Vector3d h = 0.5 * box.size_m;
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {-1, 1}) {
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      Vector3d n = Vector3d::Zero();
      n[axis] = sign;
      std::array<Vector3d, 4> q;
      const double sa[4] = {-1, 1, 1, -1}, sb[4] = {-1, -1, 1, 1};
      for (int k = 0; k < 4; ++k) {
        Vector3d p = Vector3d::Zero();
        p[axis] = sign * h[axis];
        p[a] = sa[k] * h[a];
        p[b] = sign * sb[k] * h[b];  // counter-clockwise seen from outside
        q[static_cast<std::size_t>(k)] = box.center_world + box.R_world_box * p;
      }
      addQuad(m, q, box.R_world_box * n, colour);
    }
  }
  return m;
}

TriangleMesh cylinderMesh(const planning::Cylinder& cyl, const Rgb& colour) {
  TriangleMesh m;
  const Vector3d axis = cyl.p1_world - cyl.p0_world;
  const double len = axis.norm();
  if (!(len > 0.0)) return m;
  const Vector3d z = axis / len;
  const Vector3d x = (std::abs(z.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY()).cross(z).normalized();
  const Vector3d y = z.cross(x);
  const int n = cylinderSides(cyl.radius_m);
  // side: two rings with radial normals
  const auto base = static_cast<std::uint32_t>(m.vertices.size());
  for (int i = 0; i <= n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    const Vector3d radial = std::cos(a) * x + std::sin(a) * y;
    m.vertices.push_back(vertex(cyl.p0_world + cyl.radius_m * radial, radial, colour));
    m.vertices.push_back(vertex(cyl.p1_world + cyl.radius_m * radial, radial, colour));
  }
  for (int i = 0; i < n; ++i) {
    const std::uint32_t a0 = base + 2 * i, a1 = a0 + 1, b0 = a0 + 2, b1 = a0 + 3;
    for (std::uint32_t k : {a0, b0, b1, a0, b1, a1}) m.indices.push_back(k);
  }
  // caps: fans
  for (int cap = 0; cap < 2; ++cap) {
    const Vector3d c = cap == 0 ? cyl.p0_world : cyl.p1_world;
    const Vector3d nrm = cap == 0 ? Vector3d(-z) : z;
    const auto centre = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.push_back(vertex(c, nrm, colour));
    for (int i = 0; i < n; ++i) {
      const double a = 2.0 * M_PI * i / n;
      m.vertices.push_back(vertex(c + cyl.radius_m * (std::cos(a) * x + std::sin(a) * y), nrm, colour));
    }
    for (int i = 0; i < n; ++i) {
      const std::uint32_t p = centre + 1 + static_cast<std::uint32_t>(i);
      const std::uint32_t q = centre + 1 + static_cast<std::uint32_t>((i + 1) % n);
      if (cap == 0) {
        for (std::uint32_t k : {centre, q, p}) m.indices.push_back(k);
      } else {
        for (std::uint32_t k : {centre, p, q}) m.indices.push_back(k);
      }
    }
  }
  return m;
}

TriangleMesh obstacleMesh(const planning::Scenario& scenario, const WorldColours& colours) {
  TriangleMesh m;
  for (const auto& b : scenario.boxes) m.append(boxMesh(b, colours.box));
  for (const auto& c : scenario.cylinders) m.append(cylinderMesh(c, colours.cylinder));
  for (const auto& c : scenario.insulators) m.append(cylinderMesh(c, colours.insulator));
  for (planning::LatticeTowerSpec spec : scenario.towers) {
    spec.keep_out = false;  // the planning keep-out plates are not physical
    const planning::PrimitiveSet p = planning::towerPrimitives(spec);
    for (const auto& b : p.boxes) m.append(boxMesh(b, colours.steel));
    for (const auto& c : p.cylinders) m.append(cylinderMesh(c, colours.steel));
  }
  for (const auto& conductor : scenario.conductors) {
    const auto p = planning::conductorPrimitives(conductor);
    if (!p) continue;  // checked by the scenario loader
    for (const auto& c : p->cylinders) m.append(cylinderMesh(c, colours.conductor));
  }
  return m;
}

TriangleMesh quadrotorMesh() {
  TriangleMesh m;
  const Rgb body(0.12f, 0.12f, 0.13f), rotor(0.05f, 0.05f, 0.05f), front(0.75f, 0.10f, 0.08f), rear(0.10f, 0.55f, 0.15f);
  planning::OrientedBox core;
  core.size_m = Vector3d(0.22, 0.14, 0.08);
  m.append(boxMesh(core, body));
  for (int i = 0; i < 4; ++i) {
    const double a = M_PI / 4 + i * M_PI / 2;  // 45°: front-left, 135°: rear-left, ...
    const Vector3d tip(0.20 * std::cos(a), 0.20 * std::sin(a), 0.0);
    planning::Cylinder arm;
    arm.p0_world = Vector3d::Zero();
    arm.p1_world = tip;
    arm.radius_m = 0.012;
    m.append(cylinderMesh(arm, std::cos(a) > 0 ? front : rear));
    planning::Cylinder disc;
    disc.p0_world = tip + Vector3d(0, 0, 0.03);
    disc.p1_world = tip + Vector3d(0, 0, 0.04);
    disc.radius_m = 0.075;
    m.append(cylinderMesh(disc, rotor));
  }
  return m;
}

TriangleMesh transformed(const TriangleMesh& mesh, const Eigen::Isometry3d& T) {
  TriangleMesh out = mesh;
  const Eigen::Matrix3d R = T.linear();
  for (auto& v : out.vertices) {
    const Vector3d p = T * Vector3d(v.p[0], v.p[1], v.p[2]);
    const Vector3d n = R * Vector3d(v.n[0], v.n[1], v.n[2]);
    for (int i = 0; i < 3; ++i) {
      v.p[i] = static_cast<float>(p[i]);
      v.n[i] = static_cast<float>(n[i]);
    }
  }
  return out;
}

}  // namespace gesture_formation::render
