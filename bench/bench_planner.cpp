// Benchmarks of the planner (docs/design.md §7: one full replanning of one UAV < 20 ms median,
// < 50 ms p99). A program that prints figures (median, p99 over many runs), not a test:
//   gf_bench_planner [--runs N]        (GF_SOURCE_DIR or the source tree as working directory)
// Sections:
//   1. full replanning in power_towers, closed loop (leader + 2 followers in priority order,
//      worker climbing the west tower), per stage, QP size and iterations;
//   2. stage-2 decision: A* on the distance field vs OMPL RRT-Connect (+ path simplification)
//      on blocked segments through the towers and conductors;
//   3. camera: Ceres vs the closed-form rate-limited filter (time and line-of-sight error).
// Figures and decisions: docs/planning.md §10.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <ompl/base/SpaceInformation.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include "gesture_formation/formation/formation_config.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/planning/camera_tracking.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/path_search.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/planning/trajectory_verifier.hpp"
#include "gesture_formation/planning/uav_planner.hpp"

using namespace gesture_formation;
using namespace gesture_formation::planning;
using Clock = std::chrono::steady_clock;

namespace {

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

void row(const char* name, const Stats& s, const char* unit = "ms") {
  std::printf("  %-34s median %9.3f  p99 %9.3f  max %9.3f %s  (n=%zu)\n", name, s.median(), s.quantile(0.99), s.max(), unit,
              s.v.size());
}

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

}  // namespace

int main(int argc, char** argv) {
  int runs = 200;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--runs") == 0) runs = std::max(1, std::atoi(argv[i + 1]));
  }
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
