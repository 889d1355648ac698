// gfctl plan --problem problem.json --out traj.csv [--json timings.json] [--dump-qp qp.json]
// One replanning of one UAV (docs/planning.md §9). The problem file is JSON (read with
// yaml-cpp, a YAML 1.2 superset of JSON, through common::ConfigReader, so that every bad or
// missing field is reported at once as "problem.json: key: message").
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <tuple>

#include "commands.hpp"
#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/formation/formation_config.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/qp_json.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/planning/trajectory_qp.hpp"
#include "gesture_formation/planning/uav_planner.hpp"

namespace gesture_formation::gfctl {

namespace {
int cmdPlan(const Args& args);
const Registrar kRegistrar{
    "plan",
    "--problem problem.json --out traj.csv [--json result.json] [--dump-qp qp.json]   one replanning of one UAV (docs/planning.md 9)",
    cmdPlan};

using common::ConfigReader;
using common::Range;

std::string resolve(const std::string& base_file, const std::string& path) {
  if (path.empty() || path[0] == '/') return path;
  const auto slash = base_file.find_last_of('/');
  return slash == std::string::npos ? path : base_file.substr(0, slash + 1) + path;
}

Eigen::Vector3d readVec3(ConfigReader& r, const std::string& key, bool required) {
  std::vector<double> v{0.0, 0.0, 0.0};
  if (required || r.has(key)) r.readDoubleList(key, v, 3, 3, Range::any());
  return v.size() == 3 ? Eigen::Vector3d(v[0], v[1], v[2]) : Eigen::Vector3d::Zero();
}

std::string num(double v) { return planning::jsonNumber(v); }

/// The request's scalars, state and the worker's constant-velocity prediction over the horizon
/// (docs/design.md §3); false when a key is bad (reported by `r`).
bool readRequest(ConfigReader& r, planning::PlanRequest& req, int& steps) {
  r.readInt("uav_index", req.uav_index, Range::atLeast(0));
  r.readDouble("t_now_s", req.t_now_s, Range::any());
  r.readDouble("dt_s", req.dt_s, Range::positive());
  r.readInt("steps", steps, Range::closed(2, formation::kMaxHorizonSteps));
  req.state.t_s = req.t_now_s;
  req.state.p_world = readVec3(r, "state.p", true);
  req.state.v_world = readVec3(r, "state.v", false);
  req.state.a_world = readVec3(r, "state.a", false);
  if (r.has("state.heading_rad")) r.readDouble("state.heading_rad", req.state.heading_rad, Range::any());
  if (r.has("state.pitch_rad")) r.readDouble("state.pitch_rad", req.state.pitch_rad, Range::any());
  const Eigen::Vector3d worker_p = readVec3(r, "worker.p", true);
  const Eigen::Vector3d worker_v = readVec3(r, "worker.v", false);
  double worker_heading = 0.0;
  if (r.has("worker.heading_rad")) r.readDouble("worker.heading_rad", worker_heading, Range::any());
  if (!r.ok()) return false;
  req.worker.p_world.resize(3, steps);
  req.worker.heading_rad.resize(1, steps);
  for (int k = 0; k < steps; ++k) {
    req.worker.p_world.col(k) = worker_p + worker_v * (k * req.dt_s);
    req.worker.heading_rad(k) = worker_heading;
  }
  return true;
}

/// Reference: explicit rows [x, y, z, heading, pitch], or the formation's (stage 1). Returns
/// kExitBadInput when the formation file is invalid (said on stderr); key errors go to `r`.
int readReference(ConfigReader& r, const std::string& problem_path, int steps, planning::PlanRequest& req) {
  if (r.has("reference")) {
    int rows = 0;
    while (r.has("reference[" + std::to_string(rows) + "]")) ++rows;
    if (rows != steps) {
      r.addError("reference", "has " + std::to_string(rows) + " rows, steps is " + std::to_string(steps));
      return kExitOk;
    }
    req.reference.resize(steps);
    for (int k = 0; k < steps; ++k) {
      std::vector<double> row{0, 0, 0, 0, 0};
      r.readDoubleList("reference[" + std::to_string(k) + "]", row, 5, 5, Range::any());
      if (row.size() == 5) {
        req.reference.p_world.col(k) = Eigen::Vector3d(row[0], row[1], row[2]);
        req.reference.heading_rad(k) = row[3];
        req.reference.pitch_rad(k) = row[4];
      }
    }
    return kExitOk;
  }
  std::string formation_file;
  r.readString("formation", formation_file);  // missing → error naming both options
  if (!r.ok()) return kExitOk;
  const std::string fpath = resolve(problem_path, formation_file);
  const auto fc = formation::loadFormationConfig(fpath, ConfigReader::MissingKeys::kUseDefaults);
  if (!fc) {
    std::cerr << "gfctl plan: invalid formation config " << fpath << ":\n" << fc.reason();
    return kExitBadInput;
  }
  if (!fc->params.hasUav(req.uav_index)) {
    r.addError("uav_index", "is " + std::to_string(req.uav_index) + " but the formation has " +
                                std::to_string(fc->params.uavCount()) + " UAVs");
  } else {
    std::vector<formation::ReferenceTrajectory> refs;
    formation::formationHorizon(req.worker, fc->params, nullptr, refs);
    req.reference = refs[static_cast<std::size_t>(req.uav_index)];
  }
  return kExitOk;
}

/// Other (higher-priority) plans: samples [x, y, z, vx, vy, vz] (velocities optional → 0).
void readOtherPlans(ConfigReader& r, planning::PlanRequest& req) {
  for (int j = 0; r.has("other_plans[" + std::to_string(j) + "]"); ++j) {
    const std::string key = "other_plans[" + std::to_string(j) + "]";
    planning::PlannedTrajectory p;
    r.readInt(key + ".uav_index", p.uav_index, Range::atLeast(0));
    r.readDouble(key + ".t0_s", p.t0_s, Range::any());
    r.readDouble(key + ".dt_s", p.dt_s, Range::positive());
    for (int k = 0; r.has(key + ".samples[" + std::to_string(k) + "]"); ++k) {
      std::vector<double> row;
      r.readDoubleList(key + ".samples[" + std::to_string(k) + "]", row, 3, 6, Range::any());
      if (row.size() != 3 && row.size() != 6) {
        if (!row.empty()) r.addError(key + ".samples[" + std::to_string(k) + "]", "needs 3 or 6 numbers");
        continue;
      }
      planning::TrajectorySample s;
      s.p_world = Eigen::Vector3d(row[0], row[1], row[2]);
      if (row.size() == 6) s.v_world = Eigen::Vector3d(row[3], row[4], row[5]);
      p.samples.push_back(s);
    }
    if (p.samples.empty()) r.addError(key + ".samples", "missing or empty");
    req.higher_priority_plans.push_back(p);
  }
}

/// The planner config named by `planner_config` (defaults without it); kExitBadInput when invalid.
int readPlannerConfigFile(ConfigReader& r, const std::string& problem_path, planning::PlannerConfig& config) {
  if (!r.has("planner_config")) return kExitOk;
  std::string cfg_file;
  r.readString("planner_config", cfg_file);
  const std::string cpath = resolve(problem_path, cfg_file);
  std::vector<std::string> warnings;
  const auto c = planning::loadPlannerConfig(cpath, ConfigReader::MissingKeys::kUseDefaults, &warnings);
  for (const auto& w : warnings) std::cerr << "gfctl plan: warning: " << w << "\n";
  if (!c) {
    std::cerr << "gfctl plan: invalid planner config " << cpath << ":\n" << c.reason();
    return kExitBadInput;
  }
  config = *c;
  return kExitOk;
}

int writeTrajectoryCsv(const Args& args, const planning::PlannedTrajectory& tr) {
  std::ofstream out(args.get("out"));
  if (!out) return badInput(args, args.get("out") + ": cannot open for writing");
  out << "t,x,y,z,vx,vy,vz,ax,ay,az,heading,pitch\n";
  for (std::size_t k = 0; k < tr.samples.size(); ++k) {
    const auto& s = tr.samples[k];
    out << common::formatDouble(tr.t0_s + static_cast<double>(k) * tr.dt_s);
    for (const Eigen::Vector3d* v : {&s.p_world, &s.v_world, &s.a_world}) {
      for (int i = 0; i < 3; ++i) out << ',' << common::formatDouble((*v)(i));
    }
    out << ',' << common::formatDouble(s.heading_rad) << ',' << common::formatDouble(s.pitch_rad) << '\n';
  }
  out.flush();
  if (!out) return badInput(args, args.get("out") + ": write failed");
  return kExitOk;
}

int writeResultJson(const Args& args, const planning::PlanResult& res, double map_ms) {
  const auto& T = res.timings;
  std::ostringstream js;
  js << "{\"status\": \"" << planning::toString(res.status) << "\", \"reason\": \"";
  for (char c : res.reason) js << (c == '"' || c == '\\' ? std::string("\\") + c : std::string(1, c));
  js << "\", \"verified\": " << (res.verified ? "true" : "false") << ", \"timings_ms\": {\"path\": " << num(T.path_ms)
     << ", \"corridor\": " << num(T.corridor_ms) << ", \"qp\": " << num(T.qp_ms) << ", \"heading\": " << num(T.heading_ms)
     << ", \"verify\": " << num(T.verify_ms) << ", \"total\": " << num(T.total_ms) << ", \"map_build\": " << num(map_ms)
     << "}, \"qp\": {\"variables\": " << res.qp_variables << ", \"constraints\": " << res.qp_constraints
     << ", \"iterations\": " << res.qp_iterations << "}, \"corridors\": " << res.corridor_count
     << ", \"projected_references\": " << res.projected_references << ", \"path_searches\": " << res.path_searches
     << ", \"min_obstacle_clearance_m\": " << num(res.min_obstacle_clearance_m)
     << ", \"min_uav_margin_m\": " << num(res.min_uav_margin_m) << ", \"min_worker_distance_m\": " << num(res.min_worker_distance_m)
     << "}\n";
  const std::string json_path = args.has("json") ? args.get("json") : args.get("out") + ".json";
  std::ofstream jout(json_path);
  if (!jout) return badInput(args, json_path + ": cannot open for writing");
  jout << js.str();
  jout.flush();
  if (!jout) return badInput(args, json_path + ": write failed");
  return kExitOk;
}

/// `--dump-qp`: the assembled matrices, ProxQP's solution and objective ("null" without a QP).
int dumpQp(const Args& args, const planning::TrajectoryQpProblem* qp) {
  std::ofstream q(args.get("dump-qp"));
  if (!q) return badInput(args, args.get("dump-qp") + ": cannot open for writing");
  if (qp == nullptr) {
    q << "null\n";
  } else {
    const planning::QpMatrices m = planning::TrajectoryQp::assemble(*qp);
    const planning::TrajectoryQpSolution sol = planning::TrajectoryQp().solve(*qp);
    const Eigen::VectorXd x = planning::TrajectoryQp::variables(qp->intervals, sol.p, sol.v, sol.a);
    planning::writeQpJson(q, m, {{"status", "\"" + (sol.solved() ? std::string("solved") : sol.reason) + "\""},
                                 {"x", planning::jsonVector(x)},
                                 {"objective", num(sol.objective)}});
  }
  q.flush();
  if (!q) return badInput(args, args.get("dump-qp") + ": write failed");
  return kExitOk;
}

int cmdPlan(const Args& args) {
  if (!checkOptions(args, {"problem", "out"}, {"json", "dump-qp"})) return kExitBadInput;
  const std::string problem_path = args.get("problem");
  {
    std::ifstream probe(problem_path);
    if (!probe) return badInput(args, problem_path + ": cannot open");
  }
  ConfigReader r = ConfigReader::fromFile(problem_path, ConfigReader::MissingKeys::kError);
  std::string scenario_file;
  r.readString("scenario", scenario_file);
  planning::PlanRequest req;
  int steps = 41;
  if (!readRequest(r, req, steps)) {
    std::cerr << "gfctl plan: invalid problem:\n" << r.errorReport();
    return kExitBadInput;
  }
  if (readReference(r, problem_path, steps, req) != kExitOk) return kExitBadInput;
  readOtherPlans(r, req);
  planning::PlannerConfig config;
  if (readPlannerConfigFile(r, problem_path, config) != kExitOk) return kExitBadInput;
  for (const auto& k : r.unusedKeys()) std::cerr << "gfctl plan: warning: " << problem_path << ": unknown key '" << k << "' ignored\n";
  if (!r.ok()) {
    std::cerr << "gfctl plan: invalid problem:\n" << r.errorReport();
    return kExitBadInput;
  }
  // Non-finite numbers are accepted by the reader's "any" range only if finite; NaN given as
  // .nan in YAML is rejected there. The planner still checks everything (fallback on bad).

  const std::string scenario_path = resolve(problem_path, scenario_file);
  const auto scenario = planning::loadScenario(scenario_path);
  if (!scenario) {
    std::cerr << "gfctl plan: invalid scenario " << scenario_path << ":\n" << scenario.reason();
    return kExitBadInput;
  }
  const auto t_map = std::chrono::steady_clock::now();
  auto map = planning::OccupancyMap::fromScenario(*scenario);
  if (!map) return badInput(args, scenario_path + ": " + map.reason());
  auto map_ptr = std::make_shared<const planning::OccupancyMap>(std::move(map.value()));
  auto field = std::make_shared<const planning::DistanceField>(*map_ptr);
  const double map_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_map).count();

  planning::UavPlanner planner(config, map_ptr, field);
  if (!planner.configError().empty()) return badInput(args, "planner config: " + planner.configError());
  planner.keepLastQp(args.has("dump-qp"));
  const planning::PlanResult res = planner.plan(req);
  if (const int code = writeTrajectoryCsv(args, res.trajectory); code != kExitOk) return code;
  if (const int code = writeResultJson(args, res, map_ms); code != kExitOk) return code;
  if (args.has("dump-qp")) {
    if (const int code = dumpQp(args, planner.lastQp()); code != kExitOk) return code;
  }

  const auto& T = res.timings;
  std::cout << "gfctl plan: " << planning::toString(res.status) << (res.reason.empty() ? "" : " (" + res.reason + ")") << "; "
            << res.trajectory.samples.size() << " samples; path " << T.path_ms << " ms, corridors " << T.corridor_ms << " ms ("
            << res.corridor_count << "), QP " << T.qp_ms << " ms (" << res.qp_variables << " variables, " << res.qp_constraints
            << " constraints, " << res.qp_iterations << " iterations), camera " << T.heading_ms << " ms, verify "
            << T.verify_ms << " ms, total " << T.total_ms << " ms (map build " << map_ms << " ms)\n";
  return kExitOk;
}
}  // namespace

}  // namespace gesture_formation::gfctl
