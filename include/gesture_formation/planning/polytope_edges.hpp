#pragma once
/// \file
/// \brief The edges of a bounded polytope `A x ≤ b` as line segments, for display (rviz draws
/// the stage-3 corridors with them; docs/ros.md). Vertex enumeration by plane triples: a vertex
/// is the intersection of three planes that satisfies every other inequality; an edge joins
/// two vertices that share two planes. O(m³) for m planes — display only, and refused (empty)
/// above `max_planes`. Unbounded or empty polytopes give no edges.
/// Thread safety: pure functions.

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "gesture_formation/planning/polytope.hpp"

namespace gesture_formation::planning {

/// \brief The vertices of `p` with, for each, the indices of the planes it lies on.
inline std::vector<std::pair<Eigen::Vector3d, std::vector<int>>> polytopeVertices(const Polytope& p, double tol_m = 1e-7,
                                                                                  int max_planes = 64) {
  std::vector<std::pair<Eigen::Vector3d, std::vector<int>>> out;
  const int m = p.rows();
  if (m < 4 || m > max_planes || !p.A.allFinite() || !p.b.allFinite()) return out;
  for (int i = 0; i < m; ++i) {
    for (int j = i + 1; j < m; ++j) {
      for (int k = j + 1; k < m; ++k) {
        Eigen::Matrix3d M;
        M << p.A.row(i), p.A.row(j), p.A.row(k);
        if (std::abs(M.determinant()) < 1e-9) continue;  // parallel or dependent planes
        const Eigen::Vector3d v = M.partialPivLu().solve(Eigen::Vector3d(p.b(i), p.b(j), p.b(k)));
        if (!v.allFinite() || p.violation(v) > tol_m) continue;
        bool merged = false;
        for (auto& [w, planes] : out) {
          if ((w - v).norm() < 1e-6) {  // a vertex on more than three planes
            merged = true;
            for (const int q : {i, j, k}) {
              if (std::find(planes.begin(), planes.end(), q) == planes.end()) planes.push_back(q);
            }
            break;
          }
        }
        if (!merged) out.push_back({v, {i, j, k}});
      }
    }
  }
  return out;
}

/// \brief The edges of `p`: pairs of vertices that share at least two planes.
inline std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> polytopeEdges(const Polytope& p, double tol_m = 1e-7,
                                                                              int max_planes = 64) {
  const auto vertices = polytopeVertices(p, tol_m, max_planes);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> edges;
  for (std::size_t a = 0; a < vertices.size(); ++a) {
    for (std::size_t b = a + 1; b < vertices.size(); ++b) {
      int shared = 0;
      for (const int q : vertices[a].second) {
        shared += std::find(vertices[b].second.begin(), vertices[b].second.end(), q) != vertices[b].second.end() ? 1 : 0;
      }
      if (shared >= 2) edges.emplace_back(vertices[a].first, vertices[b].first);
    }
  }
  return edges;
}

}  // namespace gesture_formation::planning
