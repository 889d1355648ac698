// The trajectory QP's bounds (trajectory_qp.hpp, docs/safety.md §4.5), without threads: a QP on
// which ProxQP's sparse solver would loop forever (recorded in the fault matrix, dup_reorder seed
// 28, t = 246.94 s, UAV 1; test/data/planning/README.md) stops at ProxQP's own invariant check
// and is answered by the dense backend with the optimum the sparse solver finds from a cold
// start; the cooperative deadline stops a solve between rounds of iterations. No assertion here
// depends on the machine's speed (ctest's timeout catches a solve that never returns).
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "gesture_formation/planning/trajectory_qp.hpp"

using namespace gesture_formation::planning;

namespace {

struct RecordedQp {
  QpMatrices m;
  Eigen::VectorXd x0;
  double eps_abs = 0.0;
  int max_iterations = 0;
};

/// Reads the text dump described in test/data/planning/README.md; fails the test on any mismatch.
RecordedQp readRecordedQp(const std::string& path) {
  RecordedQp q;
  std::ifstream f(path);
  EXPECT_TRUE(f.good()) << path;
  std::string word;
  f >> word >> q.eps_abs >> word >> q.max_iterations;
  const auto sparse = [&f](const char* name, Eigen::SparseMatrix<double>& M) {
    std::string tag;
    long rows = 0, cols = 0, nnz = 0;
    f >> tag >> rows >> cols >> nnz;
    EXPECT_EQ(tag, name);
    std::vector<Eigen::Triplet<double>> t;
    for (long i = 0; i < nnz && f; ++i) {
      long r = 0, c = 0;
      double v = 0.0;
      f >> r >> c >> v;
      t.emplace_back(static_cast<int>(r), static_cast<int>(c), v);
    }
    M.resize(rows, cols);
    M.setFromTriplets(t.begin(), t.end());
  };
  const auto dense = [&f](const char* name, Eigen::VectorXd& v) {
    std::string tag;
    long n = 0;
    f >> tag >> n;
    EXPECT_EQ(tag, name);
    v.resize(n);
    for (long i = 0; i < n; ++i) f >> v(i);
  };
  sparse("H", q.m.H);
  dense("g", q.m.g);
  sparse("A", q.m.A);
  dense("b", q.m.b);
  sparse("C", q.m.C);
  dense("l", q.m.l);
  dense("u", q.m.u);
  dense("x0", q.x0);
  EXPECT_FALSE(f.fail()) << path << ": truncated";
  return q;
}

double objective(const QpMatrices& m, const Eigen::VectorXd& x) { return 0.5 * x.dot(m.H * x) + m.g.dot(x); }

/// Worst violation of Ax = b and l ≤ Cx ≤ u.
double violation(const QpMatrices& m, const Eigen::VectorXd& x) {
  const Eigen::VectorXd ax = m.A * x, cx = m.C * x;
  double w = (ax - m.b).cwiseAbs().maxCoeff();
  for (int i = 0; i < cx.size(); ++i) w = std::max({w, m.l(i) - cx(i), cx(i) - m.u(i)});
  return w;
}

}  // namespace

TEST(QpTimeBound, SparseSolveThatWouldLoopForeverIsAnsweredByTheDenseBackend) {
  const RecordedQp q = readRecordedQp(std::string(GF_SOURCE_DIR) + "/test/data/planning/proxqp_sparse_hang.txt");
  ASSERT_EQ(q.m.H.rows(), 351);
  ASSERT_EQ(q.m.C.rows(), 1180);
  ASSERT_EQ(q.x0.size(), 351);
  QpSolveLimits limits;
  limits.eps_abs = q.eps_abs;
  limits.max_iterations = q.max_iterations;
  limits.timeout_s = 60.0;  // far beyond what either backend needs: only the invariant check may stop it

  // Cold start: the sparse solver returns (the reference optimum).
  const QpMatricesSolution cold = TrajectoryQp::solveMatrices(q.m, nullptr, limits);
  ASSERT_EQ(cold.status, TrajectoryQpSolution::Status::kSolved) << cold.reason;
  EXPECT_FALSE(cold.sparse_invariant_broken);
  EXPECT_FALSE(cold.dense_backend);

  // Warm start from the recorded plan: ProxQP's sparse LDLᵀ row deletion breaks `it_pos == 0`
  // (with the check compiled out it then never returns). The check stops it; the dense backend answers.
  const QpMatricesSolution warm = TrajectoryQp::solveMatrices(q.m, &q.x0, limits);
  EXPECT_TRUE(warm.sparse_invariant_broken)
      << "the sparse solve passed: if ProxQP was upgraded and fixed, record another QP that breaks it "
         "(docs/safety.md 4.5) so that the fallback stays tested";
  EXPECT_NE(warm.reason.find("it_pos == 0"), std::string::npos) << warm.reason;
  EXPECT_TRUE(warm.dense_backend);
  ASSERT_EQ(warm.status, TrajectoryQpSolution::Status::kSolved) << warm.reason;
  ASSERT_EQ(warm.x.size(), 351);
  EXPECT_LT(violation(q.m, warm.x), 1e-5);
  const double f_cold = objective(q.m, cold.x), f_warm = objective(q.m, warm.x);
  EXPECT_NEAR(f_warm, f_cold, 1e-6 * std::abs(f_cold)) << "dense and sparse optima differ";
}

TEST(QpTimeBound, TheDeadlineStopsASolveBetweenRounds) {
  const RecordedQp q = readRecordedQp(std::string(GF_SOURCE_DIR) + "/test/data/planning/proxqp_sparse_hang.txt");
  QpSolveLimits limits;
  limits.eps_abs = q.eps_abs;
  limits.max_iterations = q.max_iterations;
  limits.iterations_per_check = 1;  // a deadline check after every outer iteration
  limits.timeout_s = 1e-9;          // passed before the first check
  const QpMatricesSolution r = TrajectoryQp::solveMatrices(q.m, nullptr, limits);
  EXPECT_EQ(r.status, TrajectoryQpSolution::Status::kTimeLimit);
  EXPECT_EQ(r.rounds, 1);
  EXPECT_FALSE(r.dense_backend);
  EXPECT_EQ(r.x.size(), 351);  // the iterate reached, not a solution
}

TEST(QpTimeBound, RoundsContinueTheSameSolve) {
  // The cold solve needs several outer iterations; in rounds of one it reaches the same optimum.
  const RecordedQp q = readRecordedQp(std::string(GF_SOURCE_DIR) + "/test/data/planning/proxqp_sparse_hang.txt");
  QpSolveLimits limits;
  limits.eps_abs = q.eps_abs;
  limits.max_iterations = q.max_iterations;
  limits.timeout_s = 60.0;
  const QpMatricesSolution whole = TrajectoryQp::solveMatrices(q.m, nullptr, limits);
  ASSERT_EQ(whole.status, TrajectoryQpSolution::Status::kSolved) << whole.reason;
  EXPECT_EQ(whole.rounds, 1);
  limits.iterations_per_check = 1;
  const QpMatricesSolution rounds = TrajectoryQp::solveMatrices(q.m, nullptr, limits);
  ASSERT_EQ(rounds.status, TrajectoryQpSolution::Status::kSolved) << rounds.reason;
  EXPECT_GT(rounds.rounds, 1);
  EXPECT_LT(violation(q.m, rounds.x), 1e-5);
  const double f_whole = objective(q.m, whole.x), f_rounds = objective(q.m, rounds.x);
  EXPECT_NEAR(f_rounds, f_whole, 1e-6 * std::abs(f_whole));
}

TEST(QpTimeBound, InvalidLimitsAreRejectedWithEveryFieldNamed) {
  QpMatrices m;
  QpSolveLimits limits;
  limits.eps_abs = 0.0;
  limits.max_iterations = 0;
  limits.timeout_s = -1.0;
  limits.iterations_per_check = 0;
  const QpMatricesSolution r = TrajectoryQp::solveMatrices(m, nullptr, limits);
  EXPECT_EQ(r.status, TrajectoryQpSolution::Status::kBadInput);
  for (const char* field : {"eps_abs", "max_iterations", "solve_timeout_s", "iterations_per_check"}) {
    EXPECT_NE(r.reason.find(field), std::string::npos) << field << " missing in: " << r.reason;
  }
}

TEST(QpTimeBound, ANonPositiveTimeoutIsRejected) {
  TrajectoryQpProblem pr;
  pr.intervals = 2;
  pr.reference.assign(3, Eigen::Vector3d::Zero());
  pr.solve_timeout_s = 0.0;
  const TrajectoryQpSolution s = TrajectoryQp().solve(pr);
  EXPECT_EQ(s.status, TrajectoryQpSolution::Status::kBadInput);
  EXPECT_NE(s.reason.find("solve_timeout_s must be > 0, got 0"), std::string::npos) << s.reason;
}

/// 10 intervals towards (1, 0, 2) with sample 5 held to x ≤ 0.5 (an active row).
static TrajectoryQpProblem tenIntervalProblem(TrajectoryQpProblem::Formulation formulation) {
  TrajectoryQpProblem pr;
  pr.intervals = 10;
  pr.reference.assign(11, Eigen::Vector3d(1.0, 0.0, 2.0));
  pr.constraints.push_back({5, Eigen::Vector3d::UnitX(), 0.5, PositionConstraint::Kind::kCorridor});
  pr.formulation = formulation;
  return pr;
}

TEST(QpTimeBound, AnOrdinarySparseSolveStaysOnTheSparseBackend) {
  const TrajectoryQpProblem pr = tenIntervalProblem(TrajectoryQpProblem::Formulation::kSparse);
  const TrajectoryQpSolution s = TrajectoryQp().solve(pr);
  ASSERT_TRUE(s.solved()) << s.reason;
  EXPECT_FALSE(s.sparse_invariant_broken);
  EXPECT_FALSE(s.dense_backend);
  EXPECT_FALSE(s.condensed);
  EXPECT_LE(s.p[5].x(), 0.5 + 1e-6);
}

// The condensed form is solved by the dense backend, which max_iter bounds: no worker thread and
// no timeout are involved (the sparse time bound is not needed on that path).
TEST(QpTimeBound, TheCondensedSolveUsesTheBoundedDenseBackend) {
  TrajectoryQpProblem pr = tenIntervalProblem(TrajectoryQpProblem::Formulation::kCondensed);
  const TrajectoryQpSolution s = TrajectoryQp().solve(pr);
  ASSERT_TRUE(s.solved()) << s.reason;
  EXPECT_TRUE(s.condensed);
  EXPECT_TRUE(s.dense_backend);
  EXPECT_FALSE(s.sparse_invariant_broken);
  EXPECT_EQ(s.variables, 30);
  EXPECT_LE(s.p[5].x(), 0.5 + 1e-6);
  pr.max_iterations = 1;  // the bound: reports max iterations rather than running on (decided by the sparse form)
  pr.reference.assign(11, Eigen::Vector3d(9.0, 3.0, 2.0));
  const TrajectoryQpSolution bounded = TrajectoryQp().solve(pr);
  EXPECT_EQ(bounded.status, TrajectoryQpSolution::Status::kMaxIterations) << bounded.reason;
}
