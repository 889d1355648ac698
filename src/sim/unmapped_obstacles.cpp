#include "gesture_formation/sim/unmapped_obstacles.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/format_number.hpp"

namespace gesture_formation::sim {

using common::ConfigReader;
using common::Range;

Eigen::Vector3d ObstacleMotion::offsetAt(double t_s) const {
  if (!moves()) return Eigen::Vector3d::Zero();
  const double moving_s = std::clamp(t_s - from_s, 0.0, to_s - from_s);
  return moving_s * velocity_mps;
}

double UnmappedObstacle::distanceAt(const Eigen::Vector3d& p_world, double t_s) const {
  if (!presentAt(t_s)) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d q = p_world - motion.offsetAt(t_s);
  return shape == Shape::kBox ? box.distance(q) : cylinder.distance(q);
}

planning::PrimitiveSet UnmappedObstacle::primitivesAt(double t_s) const {
  planning::PrimitiveSet set;
  if (!presentAt(t_s)) return set;
  const Eigen::Vector3d d = motion.offsetAt(t_s);
  if (shape == Shape::kBox) {
    planning::OrientedBox b = box;
    b.center_world += d;
    set.boxes.push_back(b);
  } else {
    planning::Cylinder c = cylinder;
    c.p0_world += d;
    c.p1_world += d;
    set.cylinders.push_back(c);
  }
  return set;
}

planning::Aabb UnmappedObstacle::boundsAt(double t_s) const {
  const planning::Aabb b = shape == Shape::kBox ? box.bounds() : cylinder.bounds();
  const Eigen::Vector3d d = motion.offsetAt(t_s);
  return planning::Aabb{b.min_world + d, b.max_world + d};
}

double unmappedDistance(const std::vector<UnmappedObstacle>& obstacles, const Eigen::Vector3d& p_world, double t_s) {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& o : obstacles) d = std::min(d, o.distanceAt(p_world, t_s));
  return d;
}

namespace {

constexpr const char* kSection = "unmapped_obstacles";

class UnmappedReader {
 public:
  /// `list`: the section's node (read without marking it used, so that unknown keys under it
  /// are still found).
  UnmappedReader(ConfigReader& r, YAML::Node list) : r_(r), list_(std::move(list)) {}

  std::vector<UnmappedObstacle> read() {
    std::vector<UnmappedObstacle> out;
    const YAML::Node& list = list_;
    if (!list.IsDefined() || list.IsNull()) return out;
    if (!list.IsSequence()) {
      r_.addError(kSection, "expected a list of obstacles");
      return out;
    }
    std::set<std::string> names;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string k = std::string(kSection) + "[" + std::to_string(i) + "]";
      if (!list[i].IsMap()) {
        r_.addError(k, "expected a mapping with one of box, cylinder");
        r_.node(k);  // consumed: not also reported as unknown
        continue;
      }
      UnmappedObstacle o = readObstacle(k, i);
      if (!names.insert(o.name).second) r_.addError(k + ".name", "duplicate name '" + o.name + "'");
      out.push_back(std::move(o));
    }
    for (const auto& u : r_.unusedKeys()) {
      if (u.rfind(kSection, 0) == 0) r_.addError(u, "unknown key (name, box, cylinder, moves, gone_after_s)");
    }
    return out;
  }

 private:
  UnmappedObstacle readObstacle(const std::string& k, std::size_t i) {
    UnmappedObstacle o;
    o.name = "unmapped_" + std::to_string(i);
    if (r_.has(k + ".name")) r_.readString(k + ".name", o.name);
    if (o.name.empty()) r_.addError(k + ".name", "must not be empty");
    const bool box = r_.has(k + ".box"), cyl = r_.has(k + ".cylinder");
    if (box == cyl) {
      r_.addError(k, box ? "has both box and cylinder: give exactly one shape" : "missing its shape: give box or cylinder");
    }
    if (box) {
      o.shape = UnmappedObstacle::Shape::kBox;
      o.box.center_world = point(k + ".box.center", Range::any(), true);
      o.box.size_m = point(k + ".box.size", Range::positive(), true);
      if (r_.has(k + ".box.rpy_deg")) {
        const Eigen::Vector3d rpy = point(k + ".box.rpy_deg", Range::closed(-360.0, 360.0), true) * (M_PI / 180.0);
        o.box.R_world_box = planning::rotationFromRpy(rpy.x(), rpy.y(), rpy.z());
      }
    } else if (cyl) {
      o.shape = UnmappedObstacle::Shape::kCylinder;
      o.cylinder.p0_world = point(k + ".cylinder.base", Range::any(), true);
      double height_m = 1.0;
      required(k + ".cylinder.radius_m", o.cylinder.radius_m, Range::positive());
      required(k + ".cylinder.height_m", height_m, Range::positive());
      o.cylinder.p1_world = o.cylinder.p0_world + Eigen::Vector3d(0.0, 0.0, height_m);
    }
    readMotion(k, o.motion);
    return o;
  }

  void readMotion(const std::string& k, ObstacleMotion& m) {
    if (r_.has(k + ".moves")) {
      required(k + ".moves.from_s", m.from_s, Range::nonNegative());
      required(k + ".moves.to_s", m.to_s, Range::nonNegative());
      m.velocity_mps = point(k + ".moves.velocity_mps", Range::closed(-100.0, 100.0), true);
      if (r_.has(k + ".moves.from_s") && r_.has(k + ".moves.to_s") && !(m.to_s >= m.from_s)) {
        r_.addError(k + ".moves.to_s", "must be >= from_s (" + common::formatNumber(m.from_s) + "), got " +
                                           common::formatNumber(m.to_s));
        m.to_s = m.from_s;
      }
    }
    if (r_.has(k + ".gone_after_s")) r_.readDouble(k + ".gone_after_s", m.gone_after_s, Range::positive());
  }

  void required(const std::string& key, double& value, const Range& range) {
    if (!r_.has(key)) {
      r_.addError(key, "missing (required)");
      return;
    }
    r_.readDouble(key, value, range);
  }

  Eigen::Vector3d point(const std::string& key, const Range& range, bool is_required) {
    if (!r_.has(key)) {
      if (is_required) r_.addError(key, "missing (required): [x, y, z]");
      return range.contains(1.0) ? Eigen::Vector3d::Ones() : Eigen::Vector3d::Zero();
    }
    std::vector<double> v;
    r_.readDoubleList(key, v, 3, 3, range);
    if (v.size() != 3) return range.contains(1.0) ? Eigen::Vector3d::Ones() : Eigen::Vector3d::Zero();
    return Eigen::Vector3d(v[0], v[1], v[2]);
  }

  ConfigReader& r_;
  YAML::Node list_;
};

}  // namespace

common::Result<std::vector<UnmappedObstacle>> parseUnmappedObstacles(const std::string& yaml,
                                                                     const std::string& source_name) {
  using R = common::Result<std::vector<UnmappedObstacle>>;
  ConfigReader r = ConfigReader::fromString(yaml, source_name, ConfigReader::MissingKeys::kUseDefaults);
  if (!r.ok()) return R::fail(r.errorReport());
  YAML::Node section;
  try {
    const YAML::Node root = YAML::Load(yaml);
    if (root.IsMap() && root[kSection]) section.reset(root[kSection]);
  } catch (const YAML::Exception& e) {
    return R::fail(source_name + ": not YAML: " + e.what() + "\n");
  }
  std::vector<UnmappedObstacle> out = UnmappedReader(r, section).read();
  if (!r.ok()) return R::fail(r.errorReport());
  return R::ok(std::move(out));
}

common::Result<std::vector<UnmappedObstacle>> loadUnmappedObstacles(const std::string& scenario_path) {
  std::ifstream f(scenario_path);
  if (!f) return common::Result<std::vector<UnmappedObstacle>>::fail(scenario_path + ": cannot be read\n");
  std::stringstream ss;
  ss << f.rdbuf();
  return parseUnmappedObstacles(ss.str(), scenario_path);
}

}  // namespace gesture_formation::sim
