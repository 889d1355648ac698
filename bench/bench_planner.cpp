// Benchmarks of the planner (docs/design.md §7: one full replanning of one UAV < 20 ms median,
// < 50 ms p99). A program that prints figures (median, p99 over many runs), not a test:
//   gf_bench_planner [--runs N]        (GF_SOURCE_DIR or the source tree as working directory)
// Sections:
//   1. full replanning in power_towers, closed loop (leader + 2 followers in priority order,
//      worker climbing the west tower), per stage, QP size and iterations;
//   2. stage-2 decision: A* on the distance field vs OMPL RRT-Connect (+ path simplification)
//      on blocked segments through the towers and conductors;
//   3. camera: Ceres vs the closed-form rate-limited filter (time and line-of-sight error);
//   4. the power-tower mission (gfctl simulate's closed loop, the same seed and planners): every
//      replanning's stage timings, the slowest 1 % and what they did (the tails: issue 38).
//   gf_bench_planner --mission [--seed N] [--fault-profile NAME] [--slowest K] [--qp-instances]
//   (section 4 only; --qp-instances: the slow replannings' QPs solved again alone, each formulation,
//   median of 3 solves, and the primal-infeasible ones' diagnosis; --qp-repeats R: of R, e.g. to
//   profile them; --qp-dump DIR: those QPs as DIR/qp_NN.json (planning/qp_json.hpp) with ProxQP's
//   answer and CPU time from the same matrices, for tools/bench_qp_osqp.py; --results FILE.md: also
//   a dated page with the output, e.g. docs/results/planning_tails.md)
// Figures and decisions: docs/planning.md §10.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <ompl/base/SpaceInformation.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include "bench_machine.hpp"
#include "gesture_formation/formation/formation_config.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/planning/camera_tracking.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/path_search.hpp"
#include "gesture_formation/planning/qp_diagnosis.hpp"
#include "gesture_formation/planning/qp_json.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/planning/trajectory_verifier.hpp"
#include "gesture_formation/planning/uav_planner.hpp"
#include "gesture_formation/sim/leader_camera.hpp"
#include "gesture_formation/sim/mission_config.hpp"
#include "gesture_formation/sim/mission_runner.hpp"

using namespace gesture_formation;
using namespace gesture_formation::planning;
using Clock = std::chrono::steady_clock;

namespace {
using gf_bench::loadAverage;
using gf_bench::threadCpuMs;

double ms(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }

struct Stats {
  std::vector<double> v;
  void add(double x) { v.push_back(x); }
  double quantile(double q) const {
    if (v.empty()) return std::nan("");
    std::vector<double> s = v;
    std::sort(s.begin(), s.end());
    const std::size_t i = std::min(s.size() - 1, static_cast<std::size_t>(std::ceil(q * static_cast<double>(s.size())) - 1));
    return s[i];
  }
  double median() const { return quantile(0.5); }
  double max() const { return v.empty() ? std::nan("") : *std::max_element(v.begin(), v.end()); }
};

void row(std::FILE* out, const char* name, const Stats& s, const char* unit = "ms") {
  std::fprintf(out, "  %-34s median %9.3f  p99 %9.3f  max %9.3f %s  (n=%zu)\n", name, s.median(), s.quantile(0.99), s.max(),
               unit, s.v.size());
}

void row(const char* name, const Stats& s, const char* unit = "ms") { row(stdout, name, s, unit); }

std::string source(const std::string& rel) {
  const char* src = std::getenv("GF_SOURCE_DIR");
  return std::string(src ? src : ".") + "/" + rel;
}

// ---- 1. full replanning -------------------------------------------------------------------

void benchFullReplanning(const std::shared_ptr<const OccupancyMap>& map, const std::shared_ptr<const DistanceField>& field,
                         int cycles) {
  const auto cfg_r = loadPlannerConfig(source("config/planner.yaml"), common::ConfigReader::MissingKeys::kError);
  const auto form_r = formation::loadFormationConfig(source("config/formation.yaml"), common::ConfigReader::MissingKeys::kUseDefaults);
  if (!cfg_r || !form_r) {
    std::fprintf(stderr, "config: %s%s\n", cfg_r.reason().c_str(), form_r.reason().c_str());
    std::exit(2);
  }
  PlannerConfig cfg = *cfg_r;
  cfg.time_budget_ms = 0.0;  // measure, do not cut
  const int n_uav = form_r->params.uavCount();
  std::vector<std::unique_ptr<UavPlanner>> owned;
  std::vector<UavPlanner*> planners;
  for (int i = 0; i < n_uav; ++i) {
    owned.push_back(std::make_unique<UavPlanner>(cfg, map, field));
    planners.push_back(owned.back().get());
  }
  const int steps = 41;
  const double dt = 0.2, period = 0.25;
  // The worker climbs the west tower's face and walks along the lower cross-arm and back.
  const auto workerAt = [](double t) {
    const double c = std::fmod(t, 60.0);
    if (c < 20.0) return Eigen::Vector3d(-3.2 + 0.02 * c, 0.0, 1.0 + 0.8 * c);
    if (c < 40.0) return Eigen::Vector3d(-2.8, 5.5 * std::sin((c - 20.0) / 20.0 * M_PI), 17.0);
    return Eigen::Vector3d(-2.8, 0.0, 17.0 - 0.8 * (c - 40.0));
  };
  std::vector<UavKinematicState> state(static_cast<std::size_t>(n_uav));
  {
    formation::WorkerHorizon w;
    w.p_world.resize(3, 1);
    w.heading_rad.resize(1, 1);
    w.p_world.col(0) = workerAt(0.0);
    w.heading_rad(0) = 0.0;
    std::vector<formation::ReferenceTrajectory> refs;
    formation::formationHorizon(w, form_r->params, nullptr, refs);
    for (int i = 0; i < n_uav; ++i) {
      const auto p0 = projectToClearance(*field, *map, refs[static_cast<std::size_t>(i)].p_world.col(0), cfg.path_clearance_m, 10.0);
      state[static_cast<std::size_t>(i)].p_world = p0 ? *p0 : Eigen::Vector3d(refs[static_cast<std::size_t>(i)].p_world.col(0));
    }
  }
  Stats path, corridor, qp, heading, verify, total, vars, cons, iters, corridors, min_mutual;
  int status_count[3] = {0, 0, 0};
  std::string last_reason;
  double t = 0.0;
  for (int c = 0; c < cycles; ++c) {
    formation::WorkerHorizon w;
    w.p_world.resize(3, steps);
    w.heading_rad.resize(1, steps);
    for (int k = 0; k < steps; ++k) {
      // Constant-velocity prediction from the current worker state (as the KF would give).
      const Eigen::Vector3d v = (workerAt(t + 0.1) - workerAt(t)) / 0.1;
      w.p_world.col(k) = workerAt(t) + v * (k * dt);
      w.heading_rad(k) = 0.0;
    }
    std::vector<formation::ReferenceTrajectory> refs;
    formation::formationHorizon(w, form_r->params, nullptr, refs);
    std::vector<PlanRequest> req(static_cast<std::size_t>(n_uav));
    for (int i = 0; i < n_uav; ++i) {
      auto& r = req[static_cast<std::size_t>(i)];
      r.uav_index = i;
      r.t_now_s = t;
      r.dt_s = dt;
      r.state = state[static_cast<std::size_t>(i)];
      r.reference = refs[static_cast<std::size_t>(i)];
      r.worker = w;
    }
    const auto res = planInPriorityOrder(planners, req);
    for (int i = 0; i < n_uav; ++i) {
      const auto& r = res[static_cast<std::size_t>(i)];
      status_count[static_cast<int>(r.status)]++;
      if (r.status != PlanStatus::kOptimized) last_reason = r.reason;
      total.add(r.timings.total_ms);
      if (r.status == PlanStatus::kOptimized) {
        path.add(r.timings.path_ms);
        corridor.add(r.timings.corridor_ms);
        qp.add(r.timings.qp_ms);
        heading.add(r.timings.heading_ms);
        verify.add(r.timings.verify_ms);
        vars.add(r.qp_variables);
        cons.add(r.qp_constraints);
        iters.add(r.qp_iterations);
        corridors.add(r.corridor_count);
      }
    }
    for (double tt = t; tt < t + period; tt += 0.05) {
      for (int i = 0; i < n_uav; ++i) {
        for (int j = i + 1; j < n_uav; ++j) {
          min_mutual.add((evaluateTrajectory(res[static_cast<std::size_t>(i)].trajectory, tt).p -
                          evaluateTrajectory(res[static_cast<std::size_t>(j)].trajectory, tt).p).norm());
        }
      }
    }
    t += period;
    for (int i = 0; i < n_uav; ++i) {
      const auto& tr = res[static_cast<std::size_t>(i)].trajectory;
      const TrajectoryPoint x = evaluateTrajectory(tr, t);
      auto& s = state[static_cast<std::size_t>(i)];
      s.t_s = t;
      s.p_world = x.p;
      s.v_world = x.v;
      s.a_world = x.a;
      const TrajectorySample a = tr.sampleAt(t);
      s.heading_rad = a.heading_rad;
      s.pitch_rad = a.pitch_rad;
    }
  }
  std::printf("1. full replanning, power_towers, %d UAVs x %d cycles (period %.2f s, horizon %d x %.1f s):\n", n_uav, cycles,
              period, steps, dt);
  std::printf("  status: optimized %d, fallback_previous %d, fallback_brake %d%s%s\n", status_count[0], status_count[1],
              status_count[2], last_reason.empty() ? "" : "; last fallback reason: ", last_reason.c_str());
  row("stage 2 path (projection, A*)", path);
  row("stage 3 corridors", corridor);
  row("stage 3 QP (assembly + ProxQP)", qp);
  row("camera heading/pitch (configured solver)", heading);
  row("verification", verify);
  row("TOTAL one replanning", total);
  row("QP variables", vars, "");
  row("QP constraints (eq + ineq)", cons, "");
  row("QP iterations", iters, "");
  row("corridors per plan", corridors, "");
  std::printf("  min mutual distance over the run: %.3f m\n", min_mutual.v.empty() ? NAN : *std::min_element(min_mutual.v.begin(), min_mutual.v.end()));
}

// ---- 2. stage-2 decision ------------------------------------------------------------------

struct Query {
  Eigen::Vector3d a, b;
};

std::vector<Query> blockedQueries(const OccupancyMap& map, const DistanceField& field, double clearance, int n) {
  std::mt19937 rng(7);
  // Pairs across the west tower, across the conductor bundle, around the east tower.
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::vector<Query> out;
  int guard = 0;
  while (static_cast<int>(out.size()) < n && ++guard < 100000) {
    const int kind = static_cast<int>(out.size()) % 3;
    Eigen::Vector3d c = kind == 0 ? Eigen::Vector3d(0, 0, 12) : kind == 1 ? Eigen::Vector3d(25, 0, 15) : Eigen::Vector3d(50, 0, 20);
    Eigen::Vector3d d(U(rng), U(rng), 0.4 * U(rng));
    d.normalize();
    const double r = 5.0 + 3.0 * std::abs(U(rng));
    Query q{c + r * d, c - r * d};
    if (field.clearance(q.a) < clearance || field.clearance(q.b) < clearance) continue;
    if (segmentClear(field, map.resolution(), q.a, q.b, clearance)) continue;  // only blocked ones
    out.push_back(q);
  }
  return out;
}

double pathLength(const std::vector<Eigen::Vector3d>& p) {
  double l = 0;
  for (std::size_t i = 1; i < p.size(); ++i) l += (p[i] - p[i - 1]).norm();
  return l;
}

void benchPathSearch(const OccupancyMap& map, const DistanceField& field, int n) {
  const double clearance = 1.0, shortcut = 0.8, margin = 8.0;
  const auto queries = blockedQueries(map, field, clearance, n);
  GridPathSearch astar(map, field);
  Stats a_ms, a_len, o_ms, o_len;
  int a_ok = 0, o_ok = 0;
  for (const auto& q : queries) {
    const auto t0 = Clock::now();
    const auto r = astar.search(q.a, q.b, clearance, shortcut, margin, 200000);
    a_ms.add(ms(t0, Clock::now()));
    if (r) ++a_ok, a_len.add(pathLength(*r) / (q.b - q.a).norm());
  }
  ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
  for (const auto& q : queries) {
    auto space = std::make_shared<ompl::base::RealVectorStateSpace>(3);
    ompl::base::RealVectorBounds bounds(3);
    for (int i = 0; i < 3; ++i) {
      bounds.setLow(i, std::max(map.gridBounds().min_world(i), std::min(q.a(i), q.b(i)) - margin));
      bounds.setHigh(i, std::min(map.gridBounds().max_world(i), std::max(q.a(i), q.b(i)) + margin));
    }
    space->setBounds(bounds);
    ompl::geometric::SimpleSetup ss(space);
    ss.setStateValidityChecker([&field, clearance](const ompl::base::State* s) {
      const auto* v = s->as<ompl::base::RealVectorStateSpace::StateType>();
      return field.clearance(Eigen::Vector3d(v->values[0], v->values[1], v->values[2])) >= clearance;
    });
    ss.getSpaceInformation()->setStateValidityCheckingResolution(0.1 / space->getMaximumExtent());
    ompl::base::ScopedState<> start(space), goal(space);
    for (int i = 0; i < 3; ++i) start[static_cast<unsigned>(i)] = q.a(i), goal[static_cast<unsigned>(i)] = q.b(i);
    ss.setStartAndGoalStates(start, goal);
    ss.setPlanner(std::make_shared<ompl::geometric::RRTConnect>(ss.getSpaceInformation()));
    const auto t0 = Clock::now();
    const auto solved = ss.solve(0.05);  // 50 ms budget
    bool ok = solved == ompl::base::PlannerStatus::EXACT_SOLUTION;
    if (ok) ss.simplifySolution(0.01);
    o_ms.add(ms(t0, Clock::now()));
    if (ok) {
      ++o_ok;
      std::vector<Eigen::Vector3d> pts;
      for (const auto* s : ss.getSolutionPath().getStates()) {
        const auto* v = s->as<ompl::base::RealVectorStateSpace::StateType>();
        pts.emplace_back(v->values[0], v->values[1], v->values[2]);
      }
      o_len.add(pathLength(pts) / (q.b - q.a).norm());
    }
  }
  std::printf("2. stage 2 on %zu blocked segments (clearance %.1f m, box margin %.0f m):\n", queries.size(), clearance, margin);
  std::printf("  A* (26-conn., distance field, shortcut): solved %d/%zu\n", a_ok, queries.size());
  row("A* time", a_ms);
  row("A* length / straight distance", a_len, "");
  std::printf("  OMPL RRT-Connect (50 ms budget) + simplifySolution: solved %d/%zu\n", o_ok, queries.size());
  row("RRT-Connect time", o_ms);
  row("RRT-Connect length / straight distance", o_len, "");
}

// ---- 3. camera --------------------------------------------------------------------------------

void benchCamera(int n) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Stats ceres_ms, filter_ms, ceres_err, filter_err, ceres_it;
  for (int i = 0; i < n; ++i) {
    CameraTrackingProblem pr;
    pr.dt_s = 0.2;
    pr.heading0_rad = M_PI * U(rng);
    pr.pitch0_rad = 0.3 * U(rng);
    const Eigen::Vector3d worker(0, 0, 10);
    const double r = 8.0, a0 = M_PI * U(rng), w = 0.15 * U(rng);
    for (int k = 0; k <= 40; ++k) {
      const double a = a0 + w * k;
      pr.p_world.push_back(worker + Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 2.0 + U(rng) * 0.2));
      pr.target_world.push_back(worker);
    }
    auto t0 = Clock::now();
    const CameraTrack c = solveCameraCeres(pr);
    ceres_ms.add(ms(t0, Clock::now()));
    t0 = Clock::now();
    const CameraTrack f = cameraFilter(pr);
    filter_ms.add(ms(t0, Clock::now()));
    if (c.ok) ceres_err.add(c.rms_error_rad * 180 / M_PI), ceres_it.add(c.iterations);
    if (f.ok) filter_err.add(f.rms_error_rad * 180 / M_PI);
  }
  std::printf("3. camera heading/pitch over 41 samples (%d random orbits, random initial heading):\n", n);
  row("Ceres time", ceres_ms);
  row("Ceres RMS line-of-sight error", ceres_err, "deg");
  row("Ceres iterations", ceres_it, "");
  row("filter time", filter_ms);
  row("filter RMS line-of-sight error", filter_err, "deg");
}


// ---- 4. the power-tower mission: every replanning, the slowest 1 % ------------------------------



struct ReplanRecord {
  int uav = 0;
  double t_s = 0.0;
  PlanStatus status = PlanStatus::kOptimized;
  StageTimings timings;
  double cpu_ms = 0.0;  ///< the planner thread's CPU time (survives a loaded machine better than wall time)
  int qp_constraints = 0, qp_iterations = 0, corridors = 0, corridor_planes = 0, path_searches = 0, sparse_stops = 0;
  int searches_failed = 0, expansions = 0;
  std::string reason;
};

/// A slow replanning's QP as the planner handed it to ProxQP (problem and warm start).
struct QpInstance {
  double t_s = 0.0;
  int uav = 0;
  double replanning_cpu_ms = 0.0;
  TrajectoryQpProblem problem;
  TrajectoryQpSolution warm;
};

/// The product's planner of one UAV, recording what each replanning did (and, with `instances`,
/// the QPs of the replannings over kInstanceCpuMs).
class RecordingPlanner final : public Planner {
 public:
  static constexpr double kInstanceCpuMs = 10.0;
  RecordingPlanner(std::unique_ptr<Planner> inner, int uav, std::vector<ReplanRecord>* out, std::vector<QpInstance>* instances)
      : inner_(std::move(inner)), uav_(uav), out_(out), instances_(instances) {
    auto* adapter = dynamic_cast<UavPlannerAdapter*>(inner_.get());
    planner_ = adapter != nullptr ? &adapter->planner() : nullptr;
    if (planner_ != nullptr && instances_ != nullptr) planner_->keepLastQp(true);
  }
  PlanResult plan(const PlanRequest& request) override {
    const double cpu0 = threadCpuMs();
    PlanResult r = inner_->plan(request);
    ReplanRecord rec;
    rec.cpu_ms = threadCpuMs() - cpu0;
    rec.uav = uav_;
    rec.t_s = request.t_now_s;
    rec.status = r.status;
    rec.timings = r.timings;
    rec.qp_constraints = r.qp_constraints;
    rec.qp_iterations = r.qp_iterations;
    rec.corridors = r.corridor_count;
    for (const auto& c : r.corridors) rec.corridor_planes += static_cast<int>(c.polytope.rows());
    rec.path_searches = r.path_searches;
    rec.searches_failed = r.path_searches_failed;
    rec.expansions = r.path_search_expansions;
    rec.sparse_stops = r.qp_sparse_timeouts;
    rec.reason = r.reason;
    if (instances_ != nullptr && planner_ != nullptr && rec.cpu_ms > kInstanceCpuMs && planner_->lastQp() != nullptr &&
        r.qp_constraints > 0) {
      instances_->push_back(QpInstance{request.t_now_s, uav_, rec.cpu_ms, *planner_->lastQp(), *planner_->lastQpWarmStart()});
    }
    out_->push_back(std::move(rec));
    return r;
  }

 private:
  std::unique_ptr<Planner> inner_;
  int uav_;
  std::vector<ReplanRecord>* out_;
  std::vector<QpInstance>* instances_;
  UavPlanner* planner_ = nullptr;
};

/// The slow replannings' QPs solved again, alone: the product's solve (sparse, warm) beside the
/// alternatives, CPU time (median of `repeats`). Returns the product's status of each instance.
std::vector<TrajectoryQpSolution::Status> benchQpVariants(std::FILE* out, const std::vector<QpInstance>& instances, int repeats) {
  struct Variant {
    const char* name;
    TrajectoryQpProblem::Formulation formulation;
    bool warm;
    double eps_primal_inf;
  };
  const double product_inf = TrajectoryQpProblem{}.eps_primal_inf;
  const Variant variants[] = {{"sparse, warm (the product)", TrajectoryQpProblem::Formulation::kSparse, true, product_inf},
                              {"sparse, cold", TrajectoryQpProblem::Formulation::kSparse, false, product_inf},
                              {"condensed dense, warm", TrajectoryQpProblem::Formulation::kCondensed, true, product_inf},
                              {"sparse, warm, eps_primal_inf 1e-3", TrajectoryQpProblem::Formulation::kSparse, true, 1e-3},
                              {"sparse, warm, eps_primal_inf 1e-2", TrajectoryQpProblem::Formulation::kSparse, true, 1e-2}};
  std::fprintf(out, "  the QPs of the %zu replannings over %.0f ms CPU, solved again alone (CPU ms, median of %d; product: "
               "eps_primal_inf %.0e):\n", instances.size(), RecordingPlanner::kInstanceCpuMs, repeats, product_inf);
  const TrajectoryQp qp;
  std::vector<double> product_objective(instances.size(), NAN);
  std::vector<TrajectoryQpSolution::Status> product_status(instances.size(), TrajectoryQpSolution::Status::kBadInput);
  for (const Variant& v : variants) {
    Stats t, it;
    int solved = 0, same_status = 0;
    double worst_rel = 0.0;
    for (std::size_t i = 0; i < instances.size(); ++i) {
      TrajectoryQpProblem pr = instances[i].problem;
      pr.formulation = v.formulation;
      pr.eps_primal_inf = v.eps_primal_inf;
      const bool use_warm = v.warm && !instances[i].warm.p.empty();
      Stats once;
      TrajectoryQpSolution sol;
      for (int r = 0; r < repeats; ++r) {
        const double c0 = threadCpuMs();
        sol = qp.solve(pr, use_warm ? &instances[i].warm : nullptr);
        once.add(threadCpuMs() - c0);
      }
      t.add(once.median());
      it.add(sol.iterations);
      if (&v == &variants[0]) product_status[i] = sol.status;
      same_status += sol.status == product_status[i] ? 1 : 0;
      if (!sol.solved()) continue;
      ++solved;
      if (&v == &variants[0]) product_objective[i] = sol.objective;
      if (std::isfinite(product_objective[i])) {
        worst_rel = std::max(worst_rel, std::abs(sol.objective - product_objective[i]) / std::max(1.0, std::abs(product_objective[i])));
      }
    }
    std::fprintf(out, "    %-28s solved %d/%zu (status as the product's: %d), worst objective difference to the product %.1e "
                 "(relative)\n", v.name, solved, instances.size(), same_status, worst_rel);
    row(out, "      time", t);
    row(out, "      iterations", it, "");
  }
  return product_status;
}

/// The primal-infeasible instances: the failed solve beside the diagnosis that names its cause
/// (planning::diagnoseInfeasibleQp: as the planner runs it, and cheaper settings), CPU ms.
void benchDiagnosis(std::FILE* out, const std::vector<QpInstance>& instances,
                    const std::vector<TrajectoryQpSolution::Status>& status, int repeats) {
  std::vector<std::size_t> failed;
  for (std::size_t i = 0; i < instances.size(); ++i) {
    if (status[i] == TrajectoryQpSolution::Status::kInfeasible) failed.push_back(i);
  }
  if (failed.empty()) return;
  struct Setting {
    const char* name;
    bool warm;
    int max_iterations;  // 0: the problem's own
  };
  const Setting settings[] = {{"cold, uncapped (the planner)", false, 0},
                              {"warm, uncapped", true, 0},
                              {"warm, 10 outer iterations", true, 10},
                              {"warm, 3 outer iterations", true, 3}};
  std::fprintf(out, "  the %zu primal-infeasible QPs: the failed solve and the diagnosis of its cause (CPU ms, median of %d):\n",
               failed.size(), repeats);
  const TrajectoryQp qp;
  Stats solve_ms;
  for (const std::size_t i : failed) {
    Stats once;
    for (int r = 0; r < repeats; ++r) {
      const double c0 = threadCpuMs();
      (void)qp.solve(instances[i].problem, instances[i].warm.p.empty() ? nullptr : &instances[i].warm);
      once.add(threadCpuMs() - c0);
    }
    solve_ms.add(once.median());
  }
  row(out, "    failed solve (the product's)", solve_ms);
  std::vector<QpDiagnosis::Cause> reference;
  for (const Setting& st : settings) {
    Stats t, solves;
    int agree = 0;
    for (std::size_t j = 0; j < failed.size(); ++j) {
      const QpInstance& in = instances[failed[j]];
      const TrajectoryQpSolution* warm = st.warm && !in.warm.p.empty() ? &in.warm : nullptr;
      Stats once;
      QpDiagnosis d;
      for (int r = 0; r < repeats; ++r) {
        const double c0 = threadCpuMs();
        d = diagnoseInfeasibleQp(qp, in.problem, warm, st.max_iterations > 0 ? st.max_iterations : in.problem.max_iterations);
        once.add(threadCpuMs() - c0);
      }
      if (&st == &settings[0]) reference.push_back(d.cause);
      agree += d.cause == reference[j] ? 1 : 0;
      t.add(once.median());
      solves.add(d.solves);
    }
    std::fprintf(out, "    diagnosis, %-40s same cause as uncapped: %d/%zu\n", st.name, agree, failed.size());
    row(out, "      time", t);
    row(out, "      relaxed solves", solves, "");
  }
}

/// `--qp-dump DIR`: each instance as DIR/qp_NN.json (planning/qp_json.hpp) with ProxQP's answer
/// from the same matrices and primal warm start (TrajectoryQp::solveMatrices, the product's
/// limits) and its CPU time (median of `repeats`): the input of tools/bench_qp_osqp.py.
bool dumpQpInstances(const std::string& dir, const std::vector<QpInstance>& instances, int repeats) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  for (std::size_t i = 0; i < instances.size(); ++i) {
    const QpInstance& in = instances[i];
    const QpMatrices m = TrajectoryQp::assemble(in.problem);
    const Eigen::VectorXd x0 = TrajectoryQp::variables(in.problem.intervals, in.warm.p, in.warm.v, in.warm.a);
    QpSolveLimits limits;
    limits.eps_abs = in.problem.eps_abs;
    limits.eps_primal_inf = in.problem.eps_primal_inf;
    limits.max_iterations = in.problem.max_iterations;
    limits.timeout_s = in.problem.solve_timeout_s;
    Stats once;
    QpMatricesSolution sol;
    for (int r = 0; r < repeats; ++r) {
      const double c0 = threadCpuMs();
      sol = TrajectoryQp::solveMatrices(m, x0.size() == m.H.rows() ? &x0 : nullptr, limits);
      once.add(threadCpuMs() - c0);
    }
    const bool solved = sol.status == TrajectoryQpSolution::Status::kSolved && sol.x.size() == m.H.rows();
    const double objective = solved ? 0.5 * sol.x.dot(m.H * sol.x) + m.g.dot(sol.x) + m.cost_constant : NAN;
    char name[32];
    std::snprintf(name, sizeof name, "/qp_%02zu.json", i);
    std::ofstream f(dir + name);
    writeQpJson(f, m, {{"t_s", jsonNumber(in.t_s)}, {"uav", std::to_string(in.uav)},
                       {"replanning_cpu_ms", jsonNumber(in.replanning_cpu_ms)}, {"eps_abs", jsonNumber(limits.eps_abs)},
                       {"eps_primal_inf", jsonNumber(limits.eps_primal_inf)}, {"x0", jsonVector(x0)},
                       {"status", solved ? "\"solved\"" : (sol.status == TrajectoryQpSolution::Status::kInfeasible ? "\"primal infeasible\"" : "\"failed\"")},
                       {"x", jsonVector(sol.x)}, {"objective", jsonNumber(objective)}, {"iterations", std::to_string(sol.iterations)},
                       {"proxqp_cpu_ms", jsonNumber(once.median())}, {"repeats", std::to_string(repeats)}});
    if (!f) return false;
  }
  return true;
}

struct MissionSetup {
  Scenario scenario;
  sim::MissionConfig mission;
  std::shared_ptr<const OccupancyMap> map;
  std::shared_ptr<const DistanceField> field;
  std::unique_ptr<sim::MissionClassifier> classifier;
  PrimitiveSet solids;
};

/// gfctl simulate's set-up of a power-tower mission (scenario, faults, gesture model, map, field).
std::optional<MissionSetup> loadMission(const std::string& fault_profile) {
  const std::string path = source("config/scenarios/power_towers.yaml");
  auto sc = loadScenario(path);
  auto mission = fault_profile.empty() ? sim::loadMissionConfig(path)
                                       : sim::loadMissionConfig(path, source("config/faults/" + fault_profile + ".yaml"));
  if (!sc || !mission) {
    std::fprintf(stderr, "mission: %s%s\n", sc ? "" : sc.reason().c_str(), mission ? "" : mission.reason().c_str());
    return std::nullopt;
  }
  if (mission->mapping.enabled) {
    std::fprintf(stderr, "mission: live mapping is not run by this benchmark (gfctl simulate --mapping)\n");
    return std::nullopt;
  }
  MissionSetup s;
  s.scenario = std::move(*sc);
  s.mission = std::move(*mission);
  s.solids = s.scenario.primitives();
  if (!s.mission.gesture_model.empty()) {
    const int threads = std::clamp(s.mission.formation.params.uavCount(), 1,
                                   std::min(static_cast<int>(std::max(1u, std::thread::hardware_concurrency())), sim::kMaxClassifierThreads));
    auto c = sim::loadOnnxClassifier(s.mission.gesture_model, threads);
    if (!c) {
      std::fprintf(stderr, "mission: %s: %s\n", s.mission.gesture_model.c_str(), c.reason().c_str());
      return std::nullopt;
    }
    s.classifier = std::move(*c);
  }
  auto m = OccupancyMap::fromScenario(s.scenario);
  if (!m) {
    std::fprintf(stderr, "mission: map: %s\n", m.reason().c_str());
    return std::nullopt;
  }
  s.map = std::make_shared<const OccupancyMap>(std::move(*m));
  s.field = std::make_shared<const DistanceField>(*s.map);
  return s;
}

void printSlowest(std::FILE* out, const std::vector<ReplanRecord>& recs, int count) {
  std::vector<const ReplanRecord*> by_time;
  for (const auto& r : recs) by_time.push_back(&r);
  std::sort(by_time.begin(), by_time.end(), [](const auto* a, const auto* b) { return a->cpu_ms > b->cpu_ms; });
  std::fprintf(out, "  the %d slowest by CPU time (ms; planes: corridor planes, cons: QP rows, it: ProxQP iterations):\n", count);
  std::fprintf(out, "    %8s %3s %9s %8s %8s %7s %8s %8s %7s %7s %7s %6s %5s %6s %5s %7s  %s\n", "t_s", "uav", "status", "cpu", "wall",
              "path", "corridor", "qp", "(diag)", "camera", "verify", "cons", "it", "corr", "A*", "expand", "reason");
  for (int i = 0; i < count && i < static_cast<int>(by_time.size()); ++i) {
    const ReplanRecord& r = *by_time[static_cast<std::size_t>(i)];
    const auto& T = r.timings;
    std::fprintf(out, "    %8.2f %3d %9s %8.2f %8.2f %7.2f %8.2f %8.2f %7.2f %7.3f %7.2f %6d %5d %2d/%-3d %d/%-3d %7d  %.70s\n", r.t_s,
                r.uav, r.status == PlanStatus::kOptimized ? "optimized" : (r.status == PlanStatus::kFallbackPrevious ? "previous" : "brake"),
                r.cpu_ms, T.total_ms, T.path_ms, T.corridor_ms, T.qp_ms, T.qp_diagnosis_ms, T.heading_ms, T.verify_ms, r.qp_constraints,
                r.qp_iterations, r.corridors, r.corridor_planes, r.searches_failed, r.path_searches, r.expansions, r.reason.c_str());
  }
}

/// The slowest 1 % by CPU time, beside all replannings: where their time goes.
void printTail(std::FILE* out, const std::vector<ReplanRecord>& recs) {
  std::vector<ReplanRecord> sorted = recs;
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.cpu_ms > b.cpu_ms; });
  const std::size_t n_tail = std::max<std::size_t>(1, sorted.size() / 100);
  const auto share = [](const std::vector<ReplanRecord>& v, std::size_t n, double StageTimings::*f) {
    double part = 0.0, whole = 0.0;
    for (std::size_t i = 0; i < n; ++i) part += v[i].timings.*f, whole += v[i].timings.total_ms;
    return whole > 0.0 ? 100.0 * part / whole : 0.0;
  };
  Stats cons_tail, it_tail, planes_tail;
  int failed_tail = 0;
  for (std::size_t i = 0; i < n_tail; ++i) {
    cons_tail.add(sorted[i].qp_constraints);
    it_tail.add(sorted[i].qp_iterations);
    planes_tail.add(sorted[i].corridor_planes);
    failed_tail += sorted[i].status == PlanStatus::kOptimized ? 0 : 1;
  }
  std::fprintf(out, "  slowest 1 %% (%zu replannings, %d failed): wall-time share path %.1f %%, corridors %.1f %%, QP %.1f %%, "
              "camera %.1f %%, verification+fallback %.1f %%\n",
              n_tail, failed_tail, share(sorted, n_tail, &StageTimings::path_ms), share(sorted, n_tail, &StageTimings::corridor_ms),
              share(sorted, n_tail, &StageTimings::qp_ms), share(sorted, n_tail, &StageTimings::heading_ms),
              share(sorted, n_tail, &StageTimings::verify_ms));
  std::fprintf(out, "    QP rows median %.0f (all: see below), iterations median %.0f max %.0f, corridor planes median %.0f max %.0f\n",
              cons_tail.median(), it_tail.median(), it_tail.max(), planes_tail.median(), planes_tail.max());
}

/// The replannings whose QP was infeasible: the QP stage without and with the diagnosis of the cause.
void printDiagnosisSplit(std::FILE* out, const std::vector<ReplanRecord>& recs) {
  Stats solve, diagnosis, total;
  for (const auto& r : recs) {
    if (r.reason.rfind("QP primal infeasible", 0) != 0) continue;
    solve.add(r.timings.qp_ms - r.timings.qp_diagnosis_ms);
    diagnosis.add(r.timings.qp_diagnosis_ms);
    total.add(r.cpu_ms);
  }
  if (total.v.empty()) return;
  std::fprintf(out, "  the %zu replannings with a primal-infeasible QP (wall ms, but the total):\n", total.v.size());
  row(out, "  QP stage without the diagnosis", solve);
  row(out, "  diagnosis of the cause", diagnosis);
  row(out, "  the replanning, CPU time", total);
}

struct MissionRecord {
  sim::MissionMetrics metrics;
  std::vector<ReplanRecord> replannings;
  std::vector<QpInstance> instances;
  std::string load_before, load_after;
};

void printMission(std::FILE* out, const MissionRecord& M, std::uint64_t seed, const std::string& fault_profile, int slowest,
                  int qp_repeats) {
  const auto& m = M.metrics;
  const auto& recs = M.replannings;
  std::fprintf(out, "4. power-tower mission, seed %llu%s%s (load average %s before, %s after; the lead's quiet anchor, seed 1 "
               "nominal, main before issue 38: planning p99 20.5-21.7 ms, max 130-163 ms; target p99 <= 20, max <= 50 ms):\n",
               static_cast<unsigned long long>(seed), fault_profile.empty() ? "" : ", faults ", fault_profile.c_str(),
               M.load_before.c_str(), M.load_after.c_str());
  std::fprintf(out, "  mission: collisions %d, min obstacle %.3f m, min mutual %.3f m, requests %d/%d, planning median %.2f p99 "
               "%.2f max %.2f ms (wall), fallback previous %d, brake %d of %d\n",
               m.collisions, m.min_obstacle_distance_m, m.min_mutual_distance_m, m.requests_applied, m.requests_total,
               m.planning_ms_median, m.planning_ms_p99, m.planning_ms_max, m.plans_fallback_previous, m.plans_fallback_brake, m.plans);
  Stats cpu, wall, path, corridor, qp, heading, verify, cons, iters, planes;
  int over[3] = {0, 0, 0};
  for (const auto& r : recs) {
    cpu.add(r.cpu_ms);
    wall.add(r.timings.total_ms);
    path.add(r.timings.path_ms);
    corridor.add(r.timings.corridor_ms);
    qp.add(r.timings.qp_ms);
    heading.add(r.timings.heading_ms);
    verify.add(r.timings.verify_ms);
    cons.add(r.qp_constraints);
    iters.add(r.qp_iterations);
    planes.add(r.corridor_planes);
    over[0] += r.cpu_ms > 10.0 ? 1 : 0;
    over[1] += r.cpu_ms > 20.0 ? 1 : 0;
    over[2] += r.cpu_ms > 50.0 ? 1 : 0;
  }
  row(out, "TOTAL one replanning, CPU time", cpu);
  row(out, "TOTAL one replanning, wall", wall);
  row(out, "stage 2 path (projection, A*)", path);
  row(out, "stage 3 corridors", corridor);
  row(out, "stage 3 QP (assembly + ProxQP)", qp);
  row(out, "camera heading/pitch", heading);
  row(out, "verification (+ fallback)", verify);
  row(out, "QP constraints (eq + ineq)", cons, "");
  row(out, "QP iterations", iters, "");
  row(out, "corridor planes per replanning", planes, "");
  std::fprintf(out, "  replannings over 10 / 20 / 50 ms CPU: %d / %d / %d of %zu\n", over[0], over[1], over[2], recs.size());
  printDiagnosisSplit(out, recs);
  printTail(out, recs);
  printSlowest(out, recs, slowest);
  if (qp_repeats > 0 && !M.instances.empty()) {
    const auto status = benchQpVariants(out, M.instances, qp_repeats);
    benchDiagnosis(out, M.instances, status, qp_repeats);
  }
}

std::string utcNow() {
  const std::time_t now = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  return buf;
}

/// A dated results page: the command and its output verbatim (docs/results/, written only by this).
bool writeResultsPage(const std::string& path, const MissionRecord& M, std::uint64_t seed, const std::string& fault_profile,
                      int slowest, int qp_repeats, const std::string& command) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  std::fprintf(f, "# Results: replanning tails in the power-tower mission (issue 38 item 1)\n\n"
                  "Written by `%s` on %s (%u hardware threads; load average %s before, %s after: wall times on a\n"
                  "loaded machine are inflated, the CPU times per replanning much less). The planner is the product's\n"
                  "(`sim::uavPlannerFactory`), run in `gfctl simulate`'s closed loop with the same seed and configs;\n"
                  "CPU time is the planner thread's (`CLOCK_THREAD_CPUTIME_ID`) around each `plan()`. What the\n"
                  "figures mean: [planning.md](../planning.md) §10.\n\n```\n",
               command.c_str(), utcNow().c_str(), std::thread::hardware_concurrency(), M.load_before.c_str(), M.load_after.c_str());
  printMission(f, M, seed, fault_profile, slowest, qp_repeats);
  std::fprintf(f, "```\n");
  return std::fclose(f) == 0;
}

int benchMission(std::uint64_t seed, const std::string& fault_profile, int slowest, int qp_repeats, const std::string& results,
                 const std::string& qp_dump, const std::string& command) {
  MissionRecord M;
  M.load_before = loadAverage();
  auto setup = loadMission(fault_profile);
  if (!setup) return 2;
  MissionSetup& S = *setup;
  sim::MissionWorld world;
  world.map = S.map.get();
  world.field = S.field.get();
  world.ground_height_m = S.scenario.ground.enabled ? S.scenario.ground.height_m : -1e9;
  world.solids = &S.solids;
  const sim::PlannerFactory product = sim::uavPlannerFactory(S.mission.planner, S.map, S.field);
  const sim::PlannerFactory recording = [&](int i) -> std::unique_ptr<sim::MissionPlanner> {
    return std::make_unique<RecordingPlanner>(product(i), i, &M.replannings,
                                              qp_repeats > 0 || !qp_dump.empty() ? &M.instances : nullptr);
  };
  const auto out = sim::runMission(S.mission, world, recording, S.classifier.get(), seed);
  if (!out) {
    std::fprintf(stderr, "mission: %s\n", out.reason().c_str());
    return 2;
  }
  M.metrics = out->metrics;
  M.load_after = loadAverage();
  printMission(stdout, M, seed, fault_profile, slowest, qp_repeats);
  if (!results.empty() && !writeResultsPage(results, M, seed, fault_profile, slowest, qp_repeats, command)) {
    std::fprintf(stderr, "gf_bench_planner: cannot write %s\n", results.c_str());
    return 2;
  }
  if (!qp_dump.empty()) {
    if (!dumpQpInstances(qp_dump, M.instances, std::max(qp_repeats, 5))) {
      std::fprintf(stderr, "gf_bench_planner: cannot write the QPs to %s\n", qp_dump.c_str());
      return 2;
    }
    std::printf("  %zu QPs written to %s (tools/bench_qp_osqp.py %s)\n", M.instances.size(), qp_dump.c_str(), qp_dump.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 200, slowest = 20;
  bool mission = false;
  int qp_repeats = 0;
  std::string results, qp_dump, command = "gf_bench_planner";
  std::uint64_t seed = 1;
  std::string fault_profile;
  for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
  for (int i = 1; i < argc; ++i) {
    const bool has_value = i + 1 < argc;
    if (std::strcmp(argv[i], "--mission") == 0) {
      mission = true;
    } else if (std::strcmp(argv[i], "--qp-instances") == 0) {
      qp_repeats = 3;
    } else if (std::strcmp(argv[i], "--qp-repeats") == 0 && has_value) {
      qp_repeats = std::max(1, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--runs") == 0 && has_value) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--seed") == 0 && has_value) {
      seed = std::strtoull(argv[++i], nullptr, 10);
    } else if (std::strcmp(argv[i], "--slowest") == 0 && has_value) {
      slowest = std::max(0, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--results") == 0 && has_value) {
      results = argv[++i];
    } else if (std::strcmp(argv[i], "--qp-dump") == 0 && has_value) {
      qp_dump = argv[++i];
    } else if (std::strcmp(argv[i], "--fault-profile") == 0 && has_value) {
      fault_profile = argv[++i];
    } else {
      std::fprintf(stderr, "gf_bench_planner: unknown or incomplete option '%s' (--runs N | --mission [--seed N] "
                           "[--fault-profile NAME] [--slowest K] [--qp-instances | --qp-repeats R] [--qp-dump DIR] [--results FILE.md])\n", argv[i]);
      return 2;
    }
  }
  if (mission) return benchMission(seed, fault_profile, slowest, qp_repeats, results, qp_dump, command);
  auto scenario = loadScenario(source("config/scenarios/power_towers.yaml"));
  if (!scenario) {
    std::fprintf(stderr, "cannot load the scenario (run from the source tree or set GF_SOURCE_DIR):\n%s", scenario.reason().c_str());
    return 2;
  }
  auto m = OccupancyMap::fromScenario(*scenario);
  if (!m) {
    std::fprintf(stderr, "%s\n", m.reason().c_str());
    return 2;
  }
  auto map = std::make_shared<const OccupancyMap>(std::move(m.value()));
  auto field = std::make_shared<const DistanceField>(*map);
  benchFullReplanning(map, field, runs);
  benchPathSearch(*map, *field, 60);
  benchCamera(200);
  return 0;
}
