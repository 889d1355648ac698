#include "gesture_formation/sim/worker_approach.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/sim/mission_config.hpp"
#include "gesture_formation/sim/worker_model.hpp"

namespace gesture_formation::sim {

using common::Range;

const common::FieldTable<WorkerApproach>& workerApproachFields() {
  using A = WorkerApproach;
  static const common::FieldTable<A> t{{
      {"t_s", Range::nonNegative(), [](A& a) { return &a.t_s; }},
      {"uav", Range::closed(0, 63), [](A& a) { return &a.uav; }},
      {"speed_mps", Range::openClosed(0.0, 3.0), [](A& a) { return &a.speed_mps; }},
      {"stop_m", Range::closed(0.0, 20.0), [](A& a) { return &a.stop_m; }},
  }};
  return t;
}

void readWorkerApproach(common::ConfigReader& r, const std::string& key, std::optional<WorkerApproach>& out) {
  if (!r.has(key)) return;
  const std::string k = key + ".";
  WorkerApproach a;
  for (const char* required : {"t_s", "uav"}) {
    if (!r.has(k + required)) r.addError(k + required, "missing (required: when and towards which UAV he walks)");
  }
  workerApproachFields().readFields(r, k, a);
  out = a;
}

double ApproachSummary::minDistance() const {
  double m = std::numeric_limits<double>::infinity();
  for (const auto& u : uavs) m = std::min(m, u.min_distance_m);
  return m;
}

int ApproachSummary::violations() const {
  int n = 0;
  for (const auto& u : uavs) n += u.gamma_dis_violations;
  return n;
}

void divertTowards(WorkerModel& worker, double t_s, const WorkerApproach& a, const Eigen::Vector3d& uav_p_world) {
  const Eigen::Vector3d feet = worker.stateAt(t_s).feet_world;
  const Eigen::Vector2d way = uav_p_world.head<2>() - feet.head<2>();
  const double len = way.norm();
  const Eigen::Vector2d stop = len > a.stop_m ? Eigen::Vector2d(feet.head<2>() + way * ((len - a.stop_m) / len))
                                              : Eigen::Vector2d(feet.head<2>());
  worker.divert(t_s, Eigen::Vector3d(stop.x(), stop.y(), feet.z()), a.speed_mps);
}

ApproachRecorder::ApproachRecorder(const WorkerApproach& approach, int uav_count, double gamma_dis_m,
                                   std::vector<std::pair<double, double>> camera_blackouts)
    : blackouts_(std::move(camera_blackouts)), inside_(static_cast<std::size_t>(uav_count), false) {
  summary_.t_s = approach.t_s;
  summary_.uav = approach.uav;
  summary_.gamma_dis_m = gamma_dis_m;
  summary_.uavs.resize(static_cast<std::size_t>(uav_count));
}

void ApproachRecorder::sample(double t_s, const std::vector<Eigen::Vector3d>& p_world, const Eigen::Vector3d& worker_world) {
  if (t_s < summary_.t_s || !inWindow(blackouts_, t_s)) return;  // the unseen phase only
  if (!std::isfinite(summary_.unseen_from_s)) summary_.unseen_from_s = t_s;
  summary_.unseen_to_s = t_s;
  for (std::size_t i = 0; i < p_world.size() && i < summary_.uavs.size(); ++i) {
    const double d = (p_world[i] - worker_world).norm();
    UavApproachRecord& u = summary_.uavs[i];
    u.min_distance_m = std::min(u.min_distance_m, d);
    const bool inside = d < summary_.gamma_dis_m;
    if (inside && !inside_[i]) ++u.gamma_dis_violations;
    inside_[i] = inside;
  }
}

std::string approachJson(const ApproachSummary& s, int indent) {
  const std::string in(static_cast<std::size_t>(indent), ' '), in2 = in + "  ", in3 = in2 + "  ";
  const auto num = [](double v) { return std::isfinite(v) ? common::formatDouble(v) : std::string("null"); };
  std::ostringstream os;
  os << "{\n" << in2 << "\"t_s\": " << num(s.t_s) << ",\n";
  os << in2 << "\"uav\": " << s.uav << ",\n";
  os << in2 << "\"gamma_dis_m\": " << num(s.gamma_dis_m) << ",\n";
  os << in2 << "\"unseen_from_s\": " << num(s.unseen_from_s) << ",\n";
  os << in2 << "\"unseen_to_s\": " << num(s.unseen_to_s) << ",\n";
  os << in2 << "\"min_distance_m\": " << num(s.minDistance()) << ",\n";
  os << in2 << "\"gamma_dis_violations\": " << s.violations() << ",\n";
  os << in2 << "\"uavs\": [";
  for (std::size_t i = 0; i < s.uavs.size(); ++i) {
    os << (i ? ",\n" : "\n") << in3 << "{\"uav\": " << i << ", \"min_distance_m\": " << num(s.uavs[i].min_distance_m)
       << ", \"gamma_dis_violations\": " << s.uavs[i].gamma_dis_violations << "}";
  }
  os << "\n" << in2 << "]\n" << in << "}";
  return os.str();
}

}  // namespace gesture_formation::sim
