#include "gesture_formation/planning/qp_diagnosis.hpp"

#include <algorithm>
#include <utility>

namespace gesture_formation::planning {

namespace {

bool stoppedSparse(const TrajectoryQpSolution& s) {
  return s.status == TrajectoryQpSolution::Status::kTimeLimit || s.sparse_invariant_broken;
}

}  // namespace

std::string describe(QpDiagnosis::Cause cause) {
  switch (cause) {
    case QpDiagnosis::Cause::kCorridors:
      return " (feasible without the corridors constraints)";
    case QpDiagnosis::Cause::kUavSeparation:
      return " (feasible without the UAV separation constraints)";
    case QpDiagnosis::Cause::kWorkerSeparation:
      return " (feasible without the worker separation constraints)";
    case QpDiagnosis::Cause::kNoSingleFamily:
      return " (infeasible even without any single family: dynamics vs the initial state)";
    case QpDiagnosis::Cause::kNotDecided:
      return " (cause not diagnosed: a relaxed problem was not decided within its iterations)";
    case QpDiagnosis::Cause::kStopped:
      break;
  }
  return {};
}

QpDiagnosis diagnoseInfeasibleQp(const TrajectoryQp& qp, const TrajectoryQpProblem& failed, const TrajectoryQpSolution* warm,
                                 int max_iterations, const std::function<bool()>& stop) {
  using Kind = PositionConstraint::Kind;
  using Cause = QpDiagnosis::Cause;
  QpDiagnosis d;
  for (const auto& [kind, cause] : {std::pair{Kind::kCorridor, Cause::kCorridors}, std::pair{Kind::kUav, Cause::kUavSeparation},
                                    std::pair{Kind::kWorker, Cause::kWorkerSeparation}}) {
    if (stop && stop()) {
      d.cause = Cause::kStopped;
      return d;
    }
    TrajectoryQpProblem relaxed = failed;
    const auto before = relaxed.constraints.size();
    relaxed.constraints.erase(std::remove_if(relaxed.constraints.begin(), relaxed.constraints.end(),
                                             [kind = kind](const PositionConstraint& pc) { return pc.kind == kind; }),
                              relaxed.constraints.end());
    if (relaxed.constraints.size() == before) continue;
    relaxed.max_iterations = std::clamp(max_iterations, 1, failed.max_iterations);
    const TrajectoryQpSolution sol = qp.solve(relaxed, warm);
    ++d.solves;
    d.sparse_stops += stoppedSparse(sol) ? 1 : 0;
    if (sol.solved()) {
      d.cause = cause;
      return d;
    }
    // Cut by the diagnosis' own cap: undecided. Any other failure counts as "still infeasible".
    if (sol.status == TrajectoryQpSolution::Status::kMaxIterations && relaxed.max_iterations < failed.max_iterations) {
      d.cause = Cause::kNotDecided;
      return d;
    }
  }
  d.cause = Cause::kNoSingleFamily;
  return d;
}

}  // namespace gesture_formation::planning
