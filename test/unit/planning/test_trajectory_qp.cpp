// The trajectory QP (ProxQP; condensed/dense and sparse forms): solutions satisfy every
// constraint (dynamics, polytope rows, inner speed/acceleration sets incl. the Bézier points) and
// are optimal (no feasible point of a random family is cheaper; the assembled matrices reproduce
// the cost; both forms state the same problem and find the same optimum); the inner
// sets really bound the Euclidean norms; the camera angles respect their rate limits.
// (Comparison with an independent solver: test/integration/gfctl_plan_qp_reference.sh.)
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/planning/camera_tracking.hpp"
#include "gesture_formation/planning/trajectory_qp.hpp"

using namespace gesture_formation::planning;

namespace {

/// A random instance: reference along a random line, a slab corridor around it, a random
/// half-space for some samples (another UAV), random initial velocity.
TrajectoryQpProblem randomProblem(std::mt19937& rng, int N) {
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  TrajectoryQpProblem pr;
  pr.dt_s = 0.2;
  pr.intervals = N;
  pr.p0 = Eigen::Vector3d(U(rng), U(rng), 5 + U(rng));
  pr.v0 = Eigen::Vector3d(U(rng), U(rng), 0.5 * U(rng));
  pr.a0 = Eigen::Vector3d(U(rng), U(rng), 0.3 * U(rng));
  const Eigen::Vector3d dir = Eigen::Vector3d(U(rng), U(rng), 0.2 * U(rng)).normalized();
  pr.reference.assign(static_cast<std::size_t>(N) + 1, pr.p0);
  for (int k = 1; k <= N; ++k) pr.reference[static_cast<std::size_t>(k)] = pr.p0 + dir * (3.0 * k * pr.dt_s) + Eigen::Vector3d(0, 0, 0.1 * U(rng));
  pr.velocity = NormPolygon{4.0, 1.5};
  pr.acceleration = NormPolygon{3.0, 2.0};
  // Slab |n·(x − p0)| ≤ 0.6 with n ⟂ dir (the reference lies inside it), and a floor.
  const Eigen::Vector3d n = dir.cross(Eigen::Vector3d::UnitZ()).normalized();
  for (int k = 1; k <= N; ++k) {
    pr.constraints.push_back({k, n, n.dot(pr.p0) + 0.6, PositionConstraint::Kind::kCorridor});
    pr.constraints.push_back({k, -n, -n.dot(pr.p0) + 0.6, PositionConstraint::Kind::kCorridor});
    pr.constraints.push_back({k, -Eigen::Vector3d::UnitZ(), -(pr.p0.z() - 1.0), PositionConstraint::Kind::kCorridor});
    // "Another UAV" ahead on the line for the second half: stay behind a plane.
    if (k > N / 2) pr.constraints.push_back({k, dir, dir.dot(pr.p0) + 2.0 + 0.5 * U(rng), PositionConstraint::Kind::kUav});
  }
  return pr;
}

}  // namespace

TEST(NormPolygonTest, InnerSetBoundsTheNormAndContainsTheInscribedBall) {
  const NormPolygon poly{5.0, 2.0};
  std::mt19937 rng(3);
  std::normal_distribution<double> G(0.0, 1.0);
  const double r = std::sqrt(25.0 - 4.0);
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d d = Eigen::Vector3d(G(rng), G(rng), G(rng)).normalized();
    // Largest multiple of d inside the polygon (support) must not exceed the norm bound …
    const auto D = poly.directions();
    const auto h = poly.halfWidths();
    double s = 1e9;
    for (int r2 = 0; r2 < NormPolygon::kRows; ++r2) {
      const double c = std::abs(D.row(r2).dot(d));
      if (c > 1e-12) s = std::min(s, h(r2) / c);
    }
    ASSERT_LE(s, 5.0 + 1e-9) << d.transpose();
    EXPECT_TRUE(poly.contains(s * d, 1e-9));
    // … and it reaches at least the inscribed ball min(r cos(π/8), v_z,max).
    ASSERT_GE(s, std::min(r * std::cos(M_PI / 8), 2.0) - 1e-9);
  }
}

class TrajectoryQpFormulationTest : public ::testing::TestWithParam<TrajectoryQpProblem::Formulation> {};

INSTANTIATE_TEST_SUITE_P(BothForms, TrajectoryQpFormulationTest,
                         ::testing::Values(TrajectoryQpProblem::Formulation::kCondensed,
                                           TrajectoryQpProblem::Formulation::kSparse),
                         [](const auto& info) {
                           return info.param == TrajectoryQpProblem::Formulation::kCondensed ? std::string("Condensed")
                                                                                             : std::string("Sparse");
                         });

TEST_P(TrajectoryQpFormulationTest, SolutionsSatisfyEveryConstraintAndAreOptimal) {
  std::mt19937 rng(20250402);
  const TrajectoryQp solver;
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const bool condensed = GetParam() == TrajectoryQpProblem::Formulation::kCondensed;
  int solved = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const int N = 5 + trial;
    TrajectoryQpProblem pr = randomProblem(rng, N);
    pr.formulation = GetParam();
    const TrajectoryQpSolution s = solver.solve(pr);
    ASSERT_EQ(s.status, TrajectoryQpSolution::Status::kSolved) << "trial " << trial << ": " << s.reason;
    ++solved;
    EXPECT_EQ(s.condensed, condensed);
    EXPECT_EQ(s.variables, condensed ? 3 * N : 9 * N);
    EXPECT_EQ(s.equalities, condensed ? 0 : 6 * N);
    // Every constraint, evaluated independently of the solver's matrices.
    EXPECT_LE(TrajectoryQp::maxViolation(pr, s.p, s.v, s.a), 1e-5) << "trial " << trial;
    // The assembled matrices reproduce the stated cost.
    const QpMatrices m = TrajectoryQp::assemble(pr);
    Eigen::VectorXd x(9 * N);
    for (int k = 1; k <= N; ++k) {
      x.segment<3>(9 * (k - 1)) = s.p[static_cast<std::size_t>(k)];
      x.segment<3>(9 * (k - 1) + 3) = s.v[static_cast<std::size_t>(k)];
      x.segment<3>(9 * (k - 1) + 6) = s.a[static_cast<std::size_t>(k)];
    }
    const double quad = 0.5 * x.dot(m.H * x) + m.g.dot(x) + m.cost_constant;
    EXPECT_NEAR(quad, TrajectoryQp::cost(pr, s.p, s.v, s.a), 1e-7 * (1.0 + std::abs(quad)));
    // Optimality: feasible perturbations (through the dynamics, on the acceleration
    // sequence) are never cheaper. Build them by rolling out perturbed accelerations.
    for (int j = 0; j < 20; ++j) {
      std::vector<Eigen::Vector3d> a = s.a, p = s.p, v = s.v;
      const double eps = 0.02;
      for (int k = 1; k <= N; ++k) a[static_cast<std::size_t>(k)] += eps * Eigen::Vector3d(U(rng), U(rng), U(rng));
      for (int k = 0; k < N; ++k) {
        const auto i = static_cast<std::size_t>(k);
        p[i + 1] = p[i] + v[i] * pr.dt_s + a[i] * (pr.dt_s * pr.dt_s / 3.0) + a[i + 1] * (pr.dt_s * pr.dt_s / 6.0);
        v[i + 1] = v[i] + (a[i] + a[i + 1]) * (pr.dt_s / 2.0);
      }
      if (TrajectoryQp::maxViolation(pr, p, v, a) > 0.0) continue;  // only feasible neighbours
      EXPECT_GE(TrajectoryQp::cost(pr, p, v, a), s.objective - 1e-6) << "trial " << trial;
    }
  }
  EXPECT_EQ(solved, 30);
}

/// Random accelerations in [−3, 3] for k = 1..N (drawn x, y, z per sample), p and v rolled out
/// by the dynamics, and the point in both forms' variables.
struct Rollout {
  std::vector<Eigen::Vector3d> p, v, a;
  Eigen::VectorXd xc, xs;  ///< condensed [a_x a_y a_z], sparse [p_1 v_1 a_1 …]
};
Rollout randomRollout(const TrajectoryQpProblem& pr, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-3.0, 3.0);
  const int N = pr.intervals;
  Rollout o{std::vector<Eigen::Vector3d>(N + 1, pr.p0), std::vector<Eigen::Vector3d>(N + 1, pr.v0),
            std::vector<Eigen::Vector3d>(N + 1, pr.a0), Eigen::VectorXd(3 * N), Eigen::VectorXd(9 * N)};
  for (int k = 1; k <= N; ++k) {
    o.a[static_cast<std::size_t>(k)] = Eigen::Vector3d(U(rng), U(rng), U(rng));
    for (int i = 0; i < 3; ++i) o.xc(i * N + k - 1) = o.a[static_cast<std::size_t>(k)](i);
  }
  for (int k = 0; k < N; ++k) {
    const auto i = static_cast<std::size_t>(k);
    o.p[i + 1] = o.p[i] + o.v[i] * pr.dt_s + o.a[i] * (pr.dt_s * pr.dt_s / 3.0) + o.a[i + 1] * (pr.dt_s * pr.dt_s / 6.0);
    o.v[i + 1] = o.v[i] + (o.a[i] + o.a[i + 1]) * (pr.dt_s / 2.0);
  }
  for (int k = 1; k <= N; ++k) {
    o.xs.segment<3>(9 * (k - 1)) = o.p[static_cast<std::size_t>(k)];
    o.xs.segment<3>(9 * (k - 1) + 3) = o.v[static_cast<std::size_t>(k)];
    o.xs.segment<3>(9 * (k - 1) + 6) = o.a[static_cast<std::size_t>(k)];
  }
  return o;
}

// The condensed matrices state the same problem: for any accelerations (p, v rolled out by the
// dynamics), ½xᵀHx + gᵀx + const equals the cost, and every row's slacks Cx − l, u − Cx are the
// corresponding row's of the 9N-variable form times one positive factor per row (the condensed
// rows are equilibrated to unit ∞-norm).
TEST(TrajectoryQpTest, CondensedMatricesReproduceTheCostAndTheRowsOfTheSparseForm) {
  std::mt19937 rng(77);
  for (int trial = 0; trial < 10; ++trial) {
    const int N = 3 + 4 * trial;
    const TrajectoryQpProblem pr = randomProblem(rng, N);
    const QpMatrices c = TrajectoryQp::assembleCondensed(pr);
    const QpMatrices m = TrajectoryQp::assemble(pr);
    ASSERT_EQ(c.H.rows(), 3 * N);
    ASSERT_EQ(c.A.rows(), 0);
    ASSERT_EQ(c.C.rows(), m.C.rows());
    const Rollout one = randomRollout(pr, rng);
    const Eigen::VectorXd &xc = one.xc, &xs = one.xs;
    const double want = TrajectoryQp::cost(pr, one.p, one.v, one.a);
    const double got = 0.5 * xc.dot(c.H * xc) + c.g.dot(xc) + c.cost_constant;
    EXPECT_NEAR(got, want, 1e-9 * (1.0 + std::abs(want))) << "trial " << trial;
    EXPECT_LT((m.A * xs - m.b).cwiseAbs().maxCoeff(), 1e-9);  // the rollout satisfies the sparse form's dynamics
    const Eigen::VectorXd cc = c.C * xc, cs = m.C * xs;
    // A second point: the per-row factor must be the same at both, and positive.
    const Rollout two = randomRollout(pr, rng);
    const Eigen::VectorXd &xc2 = two.xc, &xs2 = two.xs;
    const Eigen::VectorXd cc2 = c.C * xc2, cs2 = m.C * xs2;
    const Eigen::MatrixXd Cd(c.C);
    for (int r = 0; r < cc.size(); ++r) {
      EXPECT_NEAR(Cd.row(r).cwiseAbs().maxCoeff(), 1.0, 1e-12) << "row " << r << " not equilibrated";
      // factor = Δ(sparse row value) / Δ(condensed row value) between the two points
      const double dc = cc2(r) - cc(r), ds = cs2(r) - cs(r);
      ASSERT_GT(std::abs(dc), 1e-9) << "row " << r;
      const double f = ds / dc;
      EXPECT_GT(f, 0.0) << "row " << r;
      if (m.u(r) < 1e19) {
        EXPECT_NEAR(f * (c.u(r) - cc(r)), m.u(r) - cs(r), 1e-8 * (1.0 + std::abs(m.u(r)))) << "row " << r;
      }
      if (m.l(r) > -1e19) {
        EXPECT_NEAR(f * (cc(r) - c.l(r)), cs(r) - m.l(r), 1e-8 * (1.0 + std::abs(m.l(r)))) << "row " << r;
      }
      EXPECT_EQ(c.u(r) < 1e19, m.u(r) < 1e19) << "row " << r;
      EXPECT_EQ(c.l(r) > -1e19, m.l(r) > -1e19) << "row " << r;
    }
  }
}

TEST(TrajectoryQpTest, CondensedAndSparseFormsFindTheSameOptimum) {
  std::mt19937 rng(31);
  const TrajectoryQp solver;
  int active = 0;
  for (int trial = 0; trial < 20; ++trial) {
    TrajectoryQpProblem pr = randomProblem(rng, 10 + 2 * trial);
    pr.formulation = TrajectoryQpProblem::Formulation::kSparse;
    const TrajectoryQpSolution sparse = solver.solve(pr);
    pr.formulation = TrajectoryQpProblem::Formulation::kCondensed;
    const TrajectoryQpSolution cond = solver.solve(pr);
    ASSERT_TRUE(sparse.solved() && cond.solved()) << sparse.reason << " / " << cond.reason;
    EXPECT_TRUE(cond.condensed);
    EXPECT_FALSE(sparse.condensed);
    EXPECT_NEAR(cond.objective, sparse.objective, 1e-5 * (1.0 + std::abs(sparse.objective))) << "trial " << trial;
    double dp = 0.0;
    for (std::size_t k = 0; k < cond.p.size(); ++k) dp = std::max(dp, (cond.p[k] - sparse.p[k]).norm());
    EXPECT_LT(dp, 1e-3) << "trial " << trial;
    // Count problems whose optimum touches a position row (the test must exercise them).
    for (const auto& c : pr.constraints) {
      if (c.a.dot(cond.p[static_cast<std::size_t>(c.sample)]) > c.b - 1e-4) {
        ++active;
        break;
      }
    }
  }
  EXPECT_GE(active, 5) << "too few problems with an active position constraint";
}

// A primal warm start (what the planner has: the previous plan re-timed, no multipliers) gives the
// same solution. The sparse backend also needs no more iterations from it; the dense backend on the
// condensed form does not promise that (zero multipliers: 30 iterations warm vs 29 cold here), so
// the iteration claim is the sparse form's only.
TEST_P(TrajectoryQpFormulationTest, WarmStartGivesTheSameSolution) {
  std::mt19937 rng(5);
  const TrajectoryQp solver;
  TrajectoryQpProblem pr = randomProblem(rng, 40);
  pr.formulation = GetParam();
  const TrajectoryQpSolution cold = solver.solve(pr);
  ASSERT_TRUE(cold.solved()) << cold.reason;
  const TrajectoryQpSolution warm = solver.solve(pr, &cold);
  ASSERT_TRUE(warm.solved()) << warm.reason;
  EXPECT_TRUE(warm.warm_started);
  if (GetParam() == TrajectoryQpProblem::Formulation::kSparse) {
    EXPECT_LE(warm.iterations, cold.iterations);
  }
  for (int k = 0; k <= 40; ++k) EXPECT_LT((warm.p[static_cast<std::size_t>(k)] - cold.p[static_cast<std::size_t>(k)]).norm(), 1e-4);
}

// terminal_rest (UavPlanner's truncated re-solve): the solution ends at rest, v_N = a_N = 0 to the
// solver's accuracy, keeps the dynamics and every row, and costs at least the free-ended optimum;
// asked of the condensed form it is solved in the sparse form (which has the rows).
TEST(TrajectoryQpTest, TerminalRestEndsTheTrajectoryAtRest) {
  std::mt19937 rng(21);
  const TrajectoryQp solver;
  for (int trial = 0; trial < 10; ++trial) {
    TrajectoryQpProblem pr = randomProblem(rng, 12);
    const TrajectoryQpSolution free_end = solver.solve(pr);
    ASSERT_TRUE(free_end.solved()) << free_end.reason;
    EXPECT_GT(free_end.v.back().norm(), 0.1) << "the free end moves (else the test shows nothing)";
    pr.terminal_rest = true;
    pr.formulation = trial % 2 == 0 ? TrajectoryQpProblem::Formulation::kSparse : TrajectoryQpProblem::Formulation::kCondensed;
    const TrajectoryQpSolution s = solver.solve(pr);
    ASSERT_TRUE(s.solved()) << s.reason;
    EXPECT_FALSE(s.condensed);
    EXPECT_EQ(s.equalities, 6 * pr.intervals + 6);
    EXPECT_LT(s.v.back().norm(), 1e-5);
    EXPECT_LT(s.a.back().norm(), 1e-5);
    const double dt = pr.dt_s;
    for (int k = 0; k < pr.intervals; ++k) {
      const auto i = static_cast<std::size_t>(k);
      EXPECT_LT((s.p[i + 1] - (s.p[i] + s.v[i] * dt + s.a[i] * (dt * dt / 3.0) + s.a[i + 1] * (dt * dt / 6.0))).norm(), 1e-5);
      EXPECT_LT((s.v[i + 1] - (s.v[i] + (s.a[i] + s.a[i + 1]) * (dt / 2.0))).norm(), 1e-5);
    }
    for (const auto& c : pr.constraints) EXPECT_LE(c.a.dot(s.p[static_cast<std::size_t>(c.sample)]), c.b + 1e-5);
    EXPECT_GE(TrajectoryQp::cost(pr, s.p, s.v, s.a) + 1e-6, TrajectoryQp::cost(pr, free_end.p, free_end.v, free_end.a));
  }
}

TEST(TrajectoryQpTest, InfeasibleAndBadInputAreReported) {
  std::mt19937 rng(9);
  const TrajectoryQp solver;
  TrajectoryQpProblem pr = randomProblem(rng, 10);
  pr.formulation = TrajectoryQpProblem::Formulation::kCondensed;  // a failure goes to the sparse form
  // Sample 1 must be 5 m away from p0: impossible within 0.2 s at 4 m/s.
  pr.constraints.push_back({1, -Eigen::Vector3d::UnitX(), -(pr.p0.x() + 5.0), PositionConstraint::Kind::kUav});
  const TrajectoryQpSolution s = solver.solve(pr);
  EXPECT_FALSE(s.solved());
  EXPECT_FALSE(s.reason.empty());
  EXPECT_FALSE(s.condensed) << "a failure is decided by the sparse form, not by the condensed one";
  TrajectoryQpProblem bad = randomProblem(rng, 10);
  bad.reference[3].x() = std::nan("");
  const TrajectoryQpSolution b = solver.solve(bad);
  EXPECT_EQ(b.status, TrajectoryQpSolution::Status::kBadInput);
  EXPECT_NE(b.reason.find("reference[3]"), std::string::npos) << b.reason;
}

TEST(CameraTrackingTest, BothSolversRespectRateLimitsAndConvergeToLineOfSight) {
  CameraTrackingProblem pr;
  pr.dt_s = 0.2;
  pr.heading0_rad = 3.0;  // far from the line of sight, across the ±π wrap
  pr.pitch0_rad = 0.0;
  const Eigen::Vector3d worker(0, 0, 10);
  for (int k = 0; k <= 40; ++k) {
    const double a = -2.9 + 0.05 * k;
    pr.p_world.push_back(worker + Eigen::Vector3d(8 * std::cos(a), 8 * std::sin(a), 3.0));
    pr.target_world.push_back(worker);
  }
  for (const CameraTrack& c : {cameraFilter(pr), solveCameraCeres(pr)}) {
    ASSERT_TRUE(c.ok) << c.reason;
    ASSERT_EQ(c.heading_rad.size(), 41u);
    EXPECT_DOUBLE_EQ(c.heading_rad[0], 3.0);
    for (std::size_t k = 1; k < c.heading_rad.size(); ++k) {
      EXPECT_LE(std::abs(gesture_formation::common::wrapAngle(c.heading_rad[k] - c.heading_rad[k - 1])),
                pr.max_heading_rate_radps * pr.dt_s + 1e-9);
      EXPECT_LE(std::abs(c.pitch_rad[k] - c.pitch_rad[k - 1]), pr.max_pitch_rate_radps * pr.dt_s + 1e-9);
      EXPECT_GT(c.heading_rad[k], -M_PI);
      EXPECT_LE(c.heading_rad[k], M_PI);
    }
    // At the end the camera looks at the worker.
    const Eigen::Vector2d los = lineOfSight(pr.p_world.back(), worker, Eigen::Vector2d::Zero());
    EXPECT_NEAR(gesture_formation::common::wrapAngle(c.heading_rad.back() - los(0)), 0.0, 0.02);
    EXPECT_NEAR(c.pitch_rad.back(), los(1), 0.02);
  }
}
