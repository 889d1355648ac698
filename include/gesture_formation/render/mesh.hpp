#pragma once
/// \file
/// \brief Triangle meshes of the rendered world (docs/rendering.md): a vertex is position,
/// normal and colour (linear RGB in [0, 1]); world frame (docs/conventions.md: x east,
/// y north, z up, metres). Builders tessellate the planner's solids (planning/shapes.hpp) so
/// that the rendered obstacles are the very geometry the occupancy map is rasterised from.
/// Thread safety: value types and pure functions.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/planning/shapes.hpp"

namespace gesture_formation::render {

/// \brief One vertex as the GPU reads it (interleaved, 9 floats).
struct Vertex {
  float p[3];  ///< position [m]
  float n[3];  ///< unit normal
  float c[3];  ///< colour, linear RGB in [0, 1]
};

/// \brief An indexed triangle list.
struct TriangleMesh {
  std::vector<Vertex> vertices;
  std::vector<std::uint32_t> indices;  ///< 3 per triangle, counter-clockwise seen from outside
  /// \brief Appends `other` (indices shifted).
  void append(const TriangleMesh& other);
  std::size_t triangleCount() const { return indices.size() / 3; }
};

using Rgb = Eigen::Vector3f;

/// \brief Largest distance [m] between a tessellated cylinder's side and the true surface
/// (the number of sides is chosen per radius to stay below it; 8 to 128 sides).
constexpr double kMaxChordErrorM = 0.0005;

/// \brief A solid box (24 vertices, flat faces).
TriangleMesh boxMesh(const planning::OrientedBox& box, const Rgb& colour);
/// \brief A solid cylinder with flat end caps, sides smooth-shaded; the polygon's vertices
/// lie on the true surface, its chords within kMaxChordErrorM of it.
TriangleMesh cylinderMesh(const planning::Cylinder& cylinder, const Rgb& colour);

/// \brief Colours of the world's obstacle kinds.
struct WorldColours {
  Rgb steel{0.46f, 0.48f, 0.50f};      ///< tower members and cross-arms
  Rgb conductor{0.18f, 0.18f, 0.19f};  ///< conductor lines
  Rgb insulator{0.35f, 0.45f, 0.55f};  ///< insulator strings
  Rgb box{0.62f, 0.55f, 0.45f};        ///< sheds, containers (scenario boxes)
  Rgb cylinder{0.55f, 0.55f, 0.52f};   ///< pillars (scenario cylinders)
};

/// \brief The colour of the site's obstacles that no map holds (Renderer::setSiteObstacles: crane
/// arms, scaffolding, trucks): construction yellow, apart from the world's greys.
inline const Rgb kSiteObstacleColour{0.86f, 0.66f, 0.12f};

/// \brief The scenario's obstacles as one mesh, from the planner's own expansion: scenario
/// boxes and cylinders, insulators, every tower through planning::towerPrimitives (its
/// planning keep-out plates left out: they are not physical) and every conductor through
/// planning::conductorPrimitives. The ground is not included (Renderer draws it).
TriangleMesh obstacleMesh(const planning::Scenario& scenario, const WorldColours& colours = WorldColours());

/// \brief A simple quadrotor (body FLU frame, origin at its centre): a central body, four
/// arms on the diagonals, four rotor discs, red front arms and green rear arms; 0.55 m
/// across the rotor tips.
TriangleMesh quadrotorMesh();

/// \brief Applies a rigid transform to a mesh (positions and normals).
TriangleMesh transformed(const TriangleMesh& mesh, const Eigen::Isometry3d& T);

}  // namespace gesture_formation::render
