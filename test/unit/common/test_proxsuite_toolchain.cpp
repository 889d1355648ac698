// The planning issue builds on ProxQP from the proxsuite wheel that tools/setup.sh installs:
// this test proves the headers, CMake config and Debian's Eigen work together.
#include <gtest/gtest.h>

// ProxQP as the project includes it (invariant checks on; one definition per binary).
#include "gesture_formation/planning/detail/proxqp_checked.hpp"

TEST(ProxsuiteToolchainTest, SolvesProjectionOntoHalfPlane) {
  // min (x1 − 1)² + (x2 − 2)²  s.t.  x1 + x2 ≤ 1  → x* = (0, 1) (projection onto the line).
  namespace dense = proxsuite::proxqp::dense;
  dense::QP<double> qp(2, 0, 1);
  Eigen::MatrixXd H = 2.0 * Eigen::MatrixXd::Identity(2, 2);
  Eigen::VectorXd g(2);
  g << -2.0, -4.0;
  Eigen::MatrixXd C(1, 2);
  C << 1.0, 1.0;
  Eigen::VectorXd l(1), u(1);
  l << -1e20;
  u << 1.0;
  qp.settings.eps_abs = 1e-9;
  qp.init(H, g, proxsuite::nullopt, proxsuite::nullopt, C, l, u);
  qp.solve();
  EXPECT_EQ(qp.results.info.status, proxsuite::proxqp::QPSolverOutput::PROXQP_SOLVED);
  EXPECT_NEAR(qp.results.x(0), 0.0, 1e-6);
  EXPECT_NEAR(qp.results.x(1), 1.0, 1e-6);
}
