#include "gesture_formation/planning/abort_mode.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "gesture_formation/common/format_number.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/plan_request_builder.hpp"

namespace gesture_formation::planning {

using common::Range;

const char* toString(AbortAfter after) {
  switch (after) {
    case AbortAfter::kHover: return "hover";
    case AbortAfter::kReturnHome: return "return_home";
    case AbortAfter::kLand: return "land";
  }
  return "unknown";
}

const char* toString(AbortSource source) {
  switch (source) {
    case AbortSource::kOperator: return "operator";
    case AbortSource::kGesture: return "gesture";
  }
  return "unknown";
}

const char* toString(AbortAcceptance a) {
  switch (a) {
    case AbortAcceptance::kAccepted: return "accepted";
    case AbortAcceptance::kAlreadyAborting: return "already_aborting";
    case AbortAcceptance::kStale: return "stale";
    case AbortAcceptance::kFromTheFuture: return "from_the_future";
  }
  return "unknown";
}

const char* toString(AbortPhase phase) {
  switch (phase) {
    case AbortPhase::kRetreat: return "retreat";
    case AbortPhase::kAtRetreat: return "at_retreat";
    case AbortPhase::kReturnHome: return "return_home";
    case AbortPhase::kAtHome: return "at_home";
    case AbortPhase::kLanding: return "landing";
    case AbortPhase::kLanded: return "landed";
    case AbortPhase::kNoGoal: return "no_goal";
  }
  return "unknown";
}

bool settled(AbortPhase phase) {
  return phase == AbortPhase::kAtRetreat || phase == AbortPhase::kAtHome || phase == AbortPhase::kLanded ||
         phase == AbortPhase::kNoGoal;
}

// ---- configuration -----------------------------------------------------------------------

const common::FieldTable<AbortConfig>& abortConfigFields() {
  using C = AbortConfig;
  static const common::FieldTable<AbortConfig> t{{
      {"retreat_distance_m", Range::positive(), [](C& c) { return &c.retreat_distance_m; }},
      {"retreat_height_m", Range::positive(), [](C& c) { return &c.retreat_height_m; }},
      {"layer_spacing_m", Range::positive(), [](C& c) { return &c.layer_spacing_m; }},
      {"goal_clearance_m", Range::positive(), [](C& c) { return &c.goal_clearance_m; }},
      {"max_distance_m", Range::positive(), [](C& c) { return &c.max_distance_m; }},
      {"bearing_step_deg", Range::openClosed(0.0, 180.0), [](C& c) { return &c.bearing_step_deg; }},
      {"speed_mps", Range::positive(), [](C& c) { return &c.speed_mps; }},
      {"arrival_tolerance_m", Range::positive(), [](C& c) { return &c.arrival_tolerance_m; }},
      {"arrival_speed_mps", Range::positive(), [](C& c) { return &c.arrival_speed_mps; }},
      {"land_height_m", Range::positive(), [](C& c) { return &c.land_height_m; }},
      {"max_command_age_s", Range::positive(), [](C& c) { return &c.max_command_age_s; }},
      {"repeats", Range::closed(1, 100), [](C& c) { return &c.repeats; }},
      {"repeat_period_s", Range::openClosed(0.0, 10.0), [](C& c) { return &c.repeat_period_s; }},
      {"resend_period_s", Range::closed(0.1, 60.0), [](C& c) { return &c.resend_period_s; }},
  }};
  return t;
}

namespace {

/// The rules between AbortConfig's fields.
std::vector<common::ConfigError> ruleProblems(const AbortConfig& c) {
  std::vector<common::ConfigError> e;
  common::checkRule(e, c.max_distance_m >= c.retreat_distance_m, "max_distance_m", c.max_distance_m,
                    "must be >= retreat_distance_m (" + common::formatNumber(c.retreat_distance_m) + ")");
  common::checkRule(e, c.resend_period_s >= c.repeat_period_s, "resend_period_s", c.resend_period_s,
                    "must be >= repeat_period_s (" + common::formatNumber(c.repeat_period_s) + ")");
  return e;
}

}  // namespace

std::vector<common::ConfigError> AbortConfig::problems() const {
  std::vector<common::ConfigError> e = abortConfigFields().rangeProblems(*this);
  for (auto& p : ruleProblems(*this)) e.push_back(std::move(p));
  return e;
}

std::vector<std::string> AbortConfig::validate() const { return common::problemLines(problems()); }

AbortConfig readAbortConfig(common::ConfigReader& r) {
  AbortConfig c;
  abortConfigFields().readFields(r, "", c);
  std::string after = toString(c.after);
  r.readString("after", after, {"hover", "return_home", "land"});
  c.after = after == "land" ? AbortAfter::kLand : after == "return_home" ? AbortAfter::kReturnHome : AbortAfter::kHover;
  // Only the rules between fields are new here (a field out of range kept its default while reading).
  common::addProblems(r, "", ruleProblems(c));
  return c;
}

std::vector<common::ConfigError> abortPlannerProblems(const AbortConfig& abort, double mutual_distance_m,
                                                      double max_speed_mps, const std::string& prefix) {
  std::vector<common::ConfigError> e;
  common::checkRule(e, abort.layer_spacing_m >= mutual_distance_m, prefix + "layer_spacing_m", abort.layer_spacing_m,
                    "must be >= the planner's qp.mutual_distance_m (" + common::formatNumber(mutual_distance_m) +
                        "): the UAVs' retreat goals must keep Gamma_dis");
  common::checkRule(e, abort.speed_mps < max_speed_mps, prefix + "speed_mps", abort.speed_mps,
                    "must be < the planner's limits.max_speed_mps (" + common::formatNumber(max_speed_mps) + ")");
  return e;
}

// ---- goals --------------------------------------------------------------------------------

namespace {

bool insideBy(const Aabb& box, const Eigen::Vector3d& p, double margin) {
  return box.inflated(-margin).contains(p);
}

/// The k-th bearing offset of the search order: 0, +1, −1, +2, −2, … steps.
double bearingOffset(int k, double step_rad) {
  const int n = (k + 1) / 2;
  return (k % 2 == 1 ? 1.0 : -1.0) * n * step_rad;
}

/// Whether the column from `top` down to land_height_m above the ground is clear (see chooseLandingPoint).
bool columnClear(const Eigen::Vector3d& top, const RetreatSpace& space, const AbortConfig& c) {
  const double bottom = space.ground_height_m + c.land_height_m;
  if (!space.bounds.contains(Eigen::Vector3d(top.x(), top.y(), bottom))) return false;
  for (double z = std::max(top.z(), bottom); z >= bottom - 1e-9; z -= 0.5) {
    const double height = z - space.ground_height_m;
    const double need = std::min(c.goal_clearance_m, height - 2.0 * space.resolution_m);
    if (space.field->clearance(Eigen::Vector3d(top.x(), top.y(), z)) < need) return false;
  }
  return true;
}

}  // namespace

common::Result<Eigen::Vector3d> chooseRetreatGoal(int uav_index, int uav_count, const Eigen::Vector3d& p_uav_world,
                                                  const Eigen::Vector3d& p_worker_world, const RetreatSpace& space,
                                                  const AbortConfig& c) {
  using R = common::Result<Eigen::Vector3d>;
  if (space.field == nullptr) return R::fail("no map to choose a retreat goal in");
  // The UAV's layer, kept inside the map by goal_clearance_m: a map lower than the layers (the
  // construction site's 16 m) puts the upper layers at its top. The goals stay apart anyway — each
  // UAV's rings lie layer_spacing_m further out than the previous UAV's, so two goals are at least
  // that far apart horizontally — the layers only add height between their climbs.
  const Aabb& b = space.bounds;
  const double z_low = b.min_world.z() + c.goal_clearance_m, z_high = b.max_world.z() - c.goal_clearance_m;
  if (!(z_low <= z_high)) {
    return R::fail("the map is " + common::formatNumber(b.max_world.z() - b.min_world.z()) +
                   " m high, less than twice abort.goal_clearance_m: no retreat layer fits");
  }
  const double z = std::clamp(space.ground_height_m + c.retreat_height_m + uav_index * c.layer_spacing_m, z_low, z_high);
  const Eigen::Vector2d away = (p_uav_world - p_worker_world).head<2>();
  // Straight above or below the worker: a bearing per UAV index (golden angle), still deterministic.
  const double bearing0 = away.norm() > 1e-6 ? std::atan2(away.y(), away.x()) : uav_index * 2.399963229728653;
  const double step = c.bearing_step_deg * M_PI / 180.0;
  const int bearings = 2 * static_cast<int>(std::floor(M_PI / step + 1e-9)) + 1;
  std::optional<Eigen::Vector3d> best;
  double best_m = std::numeric_limits<double>::infinity();
  for (int k = 0; k < bearings; ++k) {
    const double bearing = bearing0 + bearingOffset(k, step);
    const Eigen::Vector2d dir(std::cos(bearing), std::sin(bearing));
    const double ring_step = std::max(1, uav_count) * c.layer_spacing_m;
    for (double d = c.retreat_distance_m + uav_index * c.layer_spacing_m; d <= c.max_distance_m + 1e-9; d += ring_step) {
      const Eigen::Vector2d xy = p_worker_world.head<2>() + d * dir;
      const Eigen::Vector3d g(xy.x(), xy.y(), z);
      const double flight_m = (g - p_uav_world).norm();
      // Strictly nearer wins: ties go to the earlier candidate of the fixed order.
      if (flight_m < best_m - 1e-9 && insideBy(b, g, c.goal_clearance_m) &&
          space.field->clearance(g) >= c.goal_clearance_m) {
        best = g;
        best_m = flight_m;
      }
    }
  }
  if (best) return R::ok(*best);
  std::ostringstream os;
  os << "no point of UAV " << uav_index << "'s retreat layer (" << common::formatNumber(z) << " m) on its rings from "
     << common::formatNumber(c.retreat_distance_m + uav_index * c.layer_spacing_m) << " to "
     << common::formatNumber(c.max_distance_m) << " m from the worker has goal_clearance_m "
     << common::formatNumber(c.goal_clearance_m) << " m";
  return R::fail(os.str());
}

common::Result<Eigen::Vector3d> chooseLandingPoint(const Eigen::Vector3d& goal_world,
                                                   const std::optional<Eigen::Vector3d>& home_world,
                                                   const RetreatSpace& space, const AbortConfig& c) {
  using R = common::Result<Eigen::Vector3d>;
  if (space.field == nullptr) return R::fail("no map to verify a landing spot in");
  std::vector<Eigen::Vector3d> tops{goal_world};
  if (home_world) tops.push_back(*home_world);
  for (const Eigen::Vector3d& top : tops) {
    if (columnClear(top, space, c)) return R::ok(Eigen::Vector3d(top.x(), top.y(), space.ground_height_m + c.land_height_m));
  }
  return R::fail(home_world ? "neither the column below the retreat goal nor the one below the take-off point is clear"
                            : "the column below the retreat goal is not clear");
}

std::string homeProblem(const Eigen::Vector3d& home_world, const Eigen::Vector3d& worker_world,
                        const RetreatSpace& space, const AbortConfig& c) {
  if (!home_world.allFinite()) return "the take-off point is not known";
  // Horizontally only: a take-off point on the pad lies at the map's floor.
  const Aabb& b = space.bounds;
  const Eigen::Vector2d lo = b.min_world.head<2>().array() + c.goal_clearance_m;
  const Eigen::Vector2d hi = b.max_world.head<2>().array() - c.goal_clearance_m;
  const Eigen::Vector2d xy = home_world.head<2>();
  if (!((xy.array() >= lo.array()).all() && (xy.array() <= hi.array()).all())) {
    return "the take-off point lies less than goal_clearance_m inside the map horizontally";
  }
  const double d = (home_world - worker_world).head<2>().norm();
  if (!(d >= c.retreat_distance_m)) {  // NaN (no worker estimate) refuses too
    return "the take-off point is " + common::formatNumber(d) + " m from the worker estimate, less than retreat_distance_m " +
           common::formatNumber(c.retreat_distance_m);
  }
  return "";
}

formation::ReferenceTrajectory approachReference(const Eigen::Vector3d& p_from_world, const Eigen::Vector3d& goal_world,
                                                 const Eigen::Vector3d& worker_world, double heading_rad,
                                                 double speed_mps, double dt_s, int steps) {
  const Eigen::Vector3d to_goal = goal_world - p_from_world;
  const double length = to_goal.norm();
  const Eigen::Vector3d dir = length > 1e-9 ? Eigen::Vector3d(to_goal / length) : Eigen::Vector3d::Zero();
  formation::ReferenceTrajectory ref;
  ref.resize(steps);
  for (int k = 0; k < steps; ++k) {
    const Eigen::Vector3d p = p_from_world + dir * std::min(length, speed_mps * k * dt_s);
    const formation::ReferenceTrajectory look = holdReference(p, worker_world, heading_rad, 1);
    ref.p_world.col(k) = p;
    ref.heading_rad(k) = look.heading_rad(0);
    ref.pitch_rad(k) = look.pitch_rad(0);
  }
  return ref;
}

// ---- the sequence -------------------------------------------------------------------------

AbortAcceptance AbortPlanner::receive(const AbortCommand& command, double t_s) {
  if (command_) return AbortAcceptance::kAlreadyAborting;
  if (!(t_s - command.sent_s <= config_.max_command_age_s)) return AbortAcceptance::kStale;
  if (!(command.sent_s - t_s <= config_.max_command_age_s)) return AbortAcceptance::kFromTheFuture;
  command_ = command;
  accepted_s_ = t_s;
  return AbortAcceptance::kAccepted;
}

void AbortPlanner::chooseFirstGoal(const Situation& s, Decision& d) {
  started_ = true;
  d.phase_changed = true;
  const auto goal = chooseRetreatGoal(uav_index_, uav_count_, s.p_world, s.worker_world, space_, config_);
  if (goal) {
    retreat_ = *goal;
    goal_ = *goal;
    phase_ = AbortPhase::kRetreat;
    return;
  }
  phase_ = AbortPhase::kNoGoal;
  goal_ = brakingPoint(s.p_world, s.v_world, s.brake_accel_mps2);  // latched: it holds there
  goal_note_ = goal.reason();
}

void AbortPlanner::advance(const Situation& s, Decision& d) {
  const bool arrived = goal_ && (s.p_world - *goal_).norm() <= config_.arrival_tolerance_m &&
                       s.v_world.norm() <= config_.arrival_speed_mps;
  if (!arrived || settled(phase_)) return;
  d.phase_changed = true;
  if (phase_ == AbortPhase::kRetreat) {
    const std::string home_problem = homeProblem(s.home_world, s.worker_world, space_, config_);
    if (config_.after == AbortAfter::kHover) {
      phase_ = AbortPhase::kAtRetreat;
    } else if (config_.after == AbortAfter::kReturnHome && !home_problem.empty()) {
      phase_ = AbortPhase::kAtRetreat;  // the take-off point is not a safe place now: it stays at the retreat goal
      goal_note_ = home_problem + "; staying at the retreat goal";
    } else if (config_.after == AbortAfter::kReturnHome) {
      phase_ = AbortPhase::kReturnHome;
      goal_ = s.home_world;
    } else {
      std::optional<Eigen::Vector3d> home;
      if (home_problem.empty()) home = s.home_world;
      const auto spot = chooseLandingPoint(*goal_, home, space_, config_);
      if (spot) {
        phase_ = AbortPhase::kLanding;
        goal_ = *spot;
      } else {
        phase_ = AbortPhase::kAtRetreat;  // nothing verified to land on: it stays at the retreat goal
        goal_note_ = spot.reason() + (home_problem.empty() ? "" : " (" + home_problem + ")");
      }
    }
  } else if (phase_ == AbortPhase::kReturnHome) {
    phase_ = AbortPhase::kAtHome;
  } else if (phase_ == AbortPhase::kLanding) {
    phase_ = AbortPhase::kLanded;
  }
}

AbortPlanner::Decision AbortPlanner::decide(const Situation& s) {
  Decision d;
  if (!started_) {
    chooseFirstGoal(s, d);
  } else {
    advance(s, d);
  }
  d.phase = phase_;
  const double speed = settled(phase_) ? 0.0 : config_.speed_mps;
  // Settled: every step at the goal (from the goal, not from where it drifted to).
  const Eigen::Vector3d from = settled(phase_) ? *goal_ : s.p_world;
  d.reference = approachReference(from, *goal_, s.worker_world, s.heading_rad, speed, s.dt_s, s.steps);
  std::ostringstream os;
  os << "abort " << toString(phase_) << " (" << common::formatNumber(goal_->x()) << ", "
     << common::formatNumber(goal_->y()) << ", " << common::formatNumber(goal_->z()) << ")";
  if (!goal_note_.empty()) os << ": " << goal_note_;
  d.reason = os.str();
  return d;
}

}  // namespace gesture_formation::planning
