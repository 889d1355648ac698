// Naming the cause of an infeasible trajectory QP (planning::diagnoseInfeasibleQp, docs/planning.md
// §7.1) and the QP's JSON form (planning/qp_json.hpp): each family made contradictory on its own
// is the one named, two at once are "no single family", a stop or an iteration cap is reported as
// such; the JSON holds every matrix entry and the bounds as written.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <utility>

#include "gesture_formation/planning/qp_diagnosis.hpp"
#include "gesture_formation/planning/qp_json.hpp"
#include "gesture_formation/planning/trajectory_qp.hpp"

using namespace gesture_formation::planning;
using Cause = QpDiagnosis::Cause;
using Kind = PositionConstraint::Kind;

namespace {

/// Hover at (0, 0, 5) towards a reference 1 m ahead, inside a 2 m wide corridor, behind another
/// UAV's plane 4 m ahead and the worker's 4 m to the side: feasible.
TrajectoryQpProblem feasibleProblem() {
  TrajectoryQpProblem pr;
  pr.intervals = 10;
  pr.p0 = Eigen::Vector3d(0, 0, 5);
  pr.reference.assign(11, pr.p0 + Eigen::Vector3d::UnitX());
  pr.velocity = NormPolygon{4.0, 1.5};
  pr.acceleration = NormPolygon{3.0, 2.0};
  for (int k = 1; k <= pr.intervals; ++k) {
    pr.constraints.push_back({k, Eigen::Vector3d::UnitY(), 1.0, Kind::kCorridor});
    pr.constraints.push_back({k, -Eigen::Vector3d::UnitY(), 1.0, Kind::kCorridor});
    pr.constraints.push_back({k, Eigen::Vector3d::UnitX(), 4.0, Kind::kUav});
    pr.constraints.push_back({k, Eigen::Vector3d::UnitZ(), 9.0, Kind::kWorker});
  }
  return pr;
}

/// Sample 1 (0.2 s after a hover) asked to be 3 m away along +x: no family can allow it alone.
void addUnreachableRow(TrajectoryQpProblem& pr, Kind kind) {
  pr.constraints.push_back({1, -Eigen::Vector3d::UnitX(), -3.0, kind});
}

}  // namespace

TEST(QpDiagnosisTest, NamesTheOnlyFamilyThatMakesItInfeasible) {
  const TrajectoryQp qp;
  ASSERT_TRUE(qp.solve(feasibleProblem()).solved());
  for (const auto& [kind, cause] : {std::pair{Kind::kCorridor, Cause::kCorridors}, std::pair{Kind::kUav, Cause::kUavSeparation},
                                    std::pair{Kind::kWorker, Cause::kWorkerSeparation}}) {
    TrajectoryQpProblem pr = feasibleProblem();
    addUnreachableRow(pr, kind);
    ASSERT_EQ(qp.solve(pr).status, TrajectoryQpSolution::Status::kInfeasible);
    const QpDiagnosis d = diagnoseInfeasibleQp(qp, pr, nullptr, pr.max_iterations);
    EXPECT_EQ(d.cause, cause) << describe(d.cause);
    EXPECT_GE(d.solves, 1);
    EXPECT_EQ(d.sparse_stops, 0);
  }
}

TEST(QpDiagnosisTest, TwoContradictoryFamiliesAreNoSingleFamilyAndTheWarmStartFindsTheSame) {
  const TrajectoryQp qp;
  TrajectoryQpProblem pr = feasibleProblem();
  addUnreachableRow(pr, Kind::kCorridor);
  addUnreachableRow(pr, Kind::kUav);
  const QpDiagnosis cold = diagnoseInfeasibleQp(qp, pr, nullptr, pr.max_iterations);
  EXPECT_EQ(cold.cause, Cause::kNoSingleFamily);
  EXPECT_EQ(cold.solves, 3);
  EXPECT_NE(describe(cold.cause).find("infeasible even without any single family"), std::string::npos);
  // The warm start of the failed solve (the previous plan re-timed: here a hover) changes nothing.
  TrajectoryQpSolution hover;
  hover.p.assign(11, pr.p0);
  hover.v.assign(11, Eigen::Vector3d::Zero());
  hover.a.assign(11, Eigen::Vector3d::Zero());
  EXPECT_EQ(diagnoseInfeasibleQp(qp, pr, &hover, pr.max_iterations).cause, Cause::kNoSingleFamily);
}

TEST(QpDiagnosisTest, StopAndIterationCapAreReportedAsSuch) {
  const TrajectoryQp qp;
  TrajectoryQpProblem pr = feasibleProblem();
  addUnreachableRow(pr, Kind::kWorker);
  const QpDiagnosis stopped = diagnoseInfeasibleQp(qp, pr, nullptr, pr.max_iterations, [] { return true; });
  EXPECT_EQ(stopped.cause, Cause::kStopped);
  EXPECT_EQ(stopped.solves, 0);
  EXPECT_TRUE(describe(Cause::kStopped).empty());
  // One outer iteration per relaxed solve: either the cause within it, or "not decided" — never a
  // wrong family and never "no single family".
  const QpDiagnosis capped = diagnoseInfeasibleQp(qp, pr, nullptr, 1);
  EXPECT_TRUE(capped.cause == Cause::kWorkerSeparation || capped.cause == Cause::kNotDecided) << describe(capped.cause);
  EXPECT_NE(describe(Cause::kNotDecided).find("not diagnosed"), std::string::npos);
}

TEST(QpJsonTest, WritesEveryEntryTheBoundsAndTheExtraFieldsInOrder) {
  TrajectoryQpProblem pr = feasibleProblem();
  const QpMatrices m = TrajectoryQp::assemble(pr);
  std::ostringstream os;
  writeQpJson(os, m, {{"status", "\"solved\""}, {"objective", jsonNumber(std::nan(""))}});
  const std::string s = os.str();
  for (const char* key : {"{\"H\": {\"rows\": 90, \"cols\": 90", "\"g\": [", "\"A\": {\"rows\": 60", "\"b\": [",
                          "\"C\": {\"rows\": ", "\"l\": [", "\"u\": [", "\"cost_constant\": ", "\"status\": \"solved\"",
                          "\"objective\": null}"}) {
    EXPECT_NE(s.find(key), std::string::npos) << key;
  }
  EXPECT_LT(s.find("\"u\": ["), s.find("\"status\""));
  // The position rows have no lower bound: written as -1e20.
  EXPECT_NE(s.find("-1e20"), std::string::npos);
  EXPECT_EQ(jsonNumber(0.1), "0.10000000000000001");  // 17 digits: an exact round trip
  Eigen::VectorXd v(3);
  v << 1.0, 2e20, -3e20;
  EXPECT_EQ(jsonVector(v), "[1, 1e20, -1e20]");
}

TEST(QpJsonTest, VariablesStackTheSolutionInTheSparseFormsOrder) {
  const TrajectoryQp qp;
  const TrajectoryQpProblem pr = feasibleProblem();
  const TrajectoryQpSolution sol = qp.solve(pr);
  ASSERT_TRUE(sol.solved()) << sol.reason;
  const Eigen::VectorXd x = TrajectoryQp::variables(pr.intervals, sol.p, sol.v, sol.a);
  ASSERT_EQ(x.size(), 9 * pr.intervals);
  const QpMatrices m = TrajectoryQp::assemble(pr);
  EXPECT_NEAR(0.5 * x.dot(m.H * x) + m.g.dot(x) + m.cost_constant, sol.objective, 1e-9 * std::max(1.0, std::abs(sol.objective)));
  EXPECT_LT((m.A * x - m.b).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_EQ((x.segment<3>(9 * 4 + 3) - sol.v[5]).norm(), 0.0);
  EXPECT_EQ(TrajectoryQp::variables(pr.intervals, sol.p, sol.v, {}).size(), 0);
}
