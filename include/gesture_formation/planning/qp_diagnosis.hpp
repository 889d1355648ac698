#pragma once
/// \file
/// \brief Why a trajectory QP is infeasible: the constraint family that, left out alone, makes it
/// feasible (docs/planning.md §7.1). Only names a cause; it never changes what the planner flies.
/// Thread safety: a free function; the solver is const and each solve has its own ProxQP object.

#include <functional>
#include <string>

#include "gesture_formation/planning/trajectory_qp.hpp"

namespace gesture_formation::planning {

/// \brief What diagnoseInfeasibleQp found.
struct QpDiagnosis {
  enum class Cause {
    kCorridors,        ///< feasible without the corridor rows
    kUavSeparation,    ///< … without the other UAVs' half-spaces
    kWorkerSeparation, ///< … without the worker's half-spaces
    kNoSingleFamily,   ///< infeasible without each family in turn (dynamics vs the initial state, or several)
    kStopped,          ///< `stop` said so before a cause was found (e.g. the time budget is spent)
    kNotDecided,       ///< a relaxed problem neither solved nor was proven infeasible within its iterations
  } cause = Cause::kNoSingleFamily;
  int solves = 0;        ///< relaxed problems solved (or tried)
  int sparse_stops = 0;  ///< of them, sparse solves stopped by a deadline or a broken ProxQP invariant
};

/// \brief The planner's text for a cause, appended to "QP primal infeasible": e.g.
/// " (feasible without the corridors constraints)". kStopped has no text of its own (the caller
/// says why it stopped).
std::string describe(QpDiagnosis::Cause cause);

/// \brief Solves `failed` again without the corridor, UAV and worker rows in turn (that order: the
/// causes' frequency in the missions) and names the first family whose removal makes it feasible.
/// Families without rows are skipped. `warm` (optional): the primal warm start of the failed solve,
/// used for the relaxed ones too. `max_iterations` (≥ 1): ProxQP outer iterations per relaxed solve
/// (TrajectoryQpProblem::max_iterations; more than the problem's own is not used); a relaxed solve
/// cut by this cap (below the problem's own) ends the diagnosis with kNotDecided; a relaxed solve
/// that fails otherwise counts as still infeasible. `stop` (optional) is asked before each
/// relaxed solve.
QpDiagnosis diagnoseInfeasibleQp(const TrajectoryQp& qp, const TrajectoryQpProblem& failed, const TrajectoryQpSolution* warm,
                                 int max_iterations, const std::function<bool()>& stop = {});

}  // namespace gesture_formation::planning
