#include <gtest/gtest.h>

#include "gesture_formation/planning/polytope_edges.hpp"

using namespace gesture_formation::planning;

namespace {

Polytope box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  Polytope p;
  p.A.resize(6, 3);
  p.b.resize(6);
  for (int a = 0; a < 3; ++a) {
    p.A.row(2 * a) = Eigen::Vector3d::Unit(a).transpose();
    p.b(2 * a) = hi(a);
    p.A.row(2 * a + 1) = -Eigen::Vector3d::Unit(a).transpose();
    p.b(2 * a + 1) = -lo(a);
  }
  return p;
}

}  // namespace

TEST(PolytopeEdgesTest, BoxHasEightVerticesAndTwelveEdgesOfItsSideLengths) {
  const Polytope p = box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(polytopeVertices(p).size(), 8u);
  const auto edges = polytopeEdges(p);
  ASSERT_EQ(edges.size(), 12u);
  int n1 = 0, n2 = 0, n3 = 0;
  for (const auto& [a, b] : edges) {
    const double len = (a - b).norm();
    n1 += std::abs(len - 1.0) < 1e-9;
    n2 += std::abs(len - 2.0) < 1e-9;
    n3 += std::abs(len - 3.0) < 1e-9;
    EXPECT_LE(p.violation(a), 1e-9);
    EXPECT_LE(p.violation(b), 1e-9);
  }
  EXPECT_EQ(n1, 4);
  EXPECT_EQ(n2, 4);
  EXPECT_EQ(n3, 4);
}

TEST(PolytopeEdgesTest, RedundantAndCuttingPlanes) {
  Polytope p = box(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1));
  // A redundant plane (x ≤ 5) changes nothing; a corner cut x + y + z ≤ 2.5 adds a triangle.
  p.A.conservativeResize(8, 3);
  p.b.conservativeResize(8);
  p.A.row(6) = Eigen::Vector3d(1, 0, 0).transpose();
  p.b(6) = 5.0;
  p.A.row(7) = Eigen::Vector3d(1, 1, 1).normalized().transpose();
  p.b(7) = 2.5 / std::sqrt(3.0);
  EXPECT_EQ(polytopeVertices(p).size(), 10u);  // 8 − 1 corner + 3 on the cut
  EXPECT_EQ(polytopeEdges(p).size(), 15u);     // 12 + 3 (the triangle)
}

TEST(PolytopeEdgesTest, UnboundedTooLargeOrNonFiniteGiveNothing) {
  Polytope half;  // one plane: unbounded
  half.A = Eigen::RowVector3d(0, 0, 1);
  half.b = Eigen::VectorXd::Constant(1, 1.0);
  EXPECT_TRUE(polytopeEdges(half).empty());
  Polytope p = box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1));
  EXPECT_TRUE(polytopeEdges(p, 1e-7, 5).empty());  // over max_planes
  p.b(0) = std::nan("");
  EXPECT_TRUE(polytopeEdges(p).empty());
}
