#include "gesture_formation/planning/scenario.hpp"

#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "gesture_formation/common/config_reader.hpp"

namespace gesture_formation::planning {

using common::ConfigReader;
using common::Range;

const common::FieldTable<MapConfig>& mapConfigFields() {
  static const common::FieldTable<MapConfig> t{{
      {"map.resolution_m", Range::closed(0.01, 10.0), [](MapConfig& m) { return &m.resolution_m; }},
  }};
  return t;
}

std::vector<common::ConfigError> MapConfig::problems() const {
  std::vector<common::ConfigError> e = mapConfigFields().rangeProblems(*this);
  if (!bounds.min_world.allFinite() || !bounds.max_world.allFinite()) {
    e.push_back({"map.bounds", "must be finite"});
    return e;
  }
  bool extent = true;
  for (int i = 0; i < 3; ++i) {
    if (!(bounds.max_world(i) > bounds.min_world(i))) {
      e.push_back({"map.bounds", "max[" + std::to_string(i) + "] must be > min[" + std::to_string(i) + "]"});
      extent = false;
    }
  }
  // Keep the dense grid (one byte per voxel, plus 4 for the distance field) bounded.
  if (extent && mapConfigFields().rangeProblems(*this).empty()) {
    const Eigen::Vector3d n = (bounds.max_world - bounds.min_world) / resolution_m;
    if (n.prod() > 1.0e8) e.push_back({"map.bounds", "more than 1e8 voxels at this resolution"});
  }
  return e;
}

std::vector<std::string> MapConfig::validate() const { return common::problemLines(problems()); }

PrimitiveSet Scenario::primitives() const {
  PrimitiveSet set;
  set.boxes = boxes;
  set.cylinders = cylinders;
  set.cylinders.insert(set.cylinders.end(), insulators.begin(), insulators.end());
  for (const auto& t : towers) set.append(towerPrimitives(t));
  for (const auto& c : conductors) {
    const auto p = conductorPrimitives(c);
    if (p) set.append(*p);
  }
  return set;
}

namespace {

std::vector<std::string> splitKey(const std::string& key) {
  std::vector<std::string> parts;
  std::string cur;
  for (const char c : key) {
    if (c == '.' || c == '[') {
      if (!cur.empty()) parts.push_back(cur);
      cur.clear();
    } else if (c != ']') {
      cur += c;
    }
  }
  if (!cur.empty()) parts.push_back(cur);
  return parts;
}

/// The deepest node of `raw` on the path of `key` (for line numbers).
YAML::Node deepest(const YAML::Node& raw, const std::string& key) {
  YAML::Node walk;
  walk.reset(raw);
  for (const auto& part : splitKey(key)) {
    const YAML::Node parent = walk;  // const: yaml-cpp's non-const operator[] inserts
    YAML::Node next(YAML::NodeType::Undefined);
    if (parent.IsSequence() && !part.empty() && std::isdigit(static_cast<unsigned char>(part[0]))) {
      const std::size_t i = std::stoul(part);
      if (i < parent.size()) next.reset(parent[i]);
    } else if (parent.IsMap()) {
      const YAML::Node child = parent[part];
      if (child.IsDefined()) next.reset(child);
    }
    if (!next.IsDefined()) break;
    walk.reset(next);
  }
  return walk;
}

class ScenarioReader {
 public:
  ScenarioReader(ConfigReader& r, YAML::Node raw, std::string base_dir)
      : r_(r), raw_(std::move(raw)), base_dir_(std::move(base_dir)) {}

  Scenario read() {
    Scenario s;
    s.source = r_.source();
    readMap(s.map);
    if (r_.has("ground")) {
      s.ground.enabled = true;
      r_.readDouble("ground.height_m", s.ground.height_m, Range::any());
    }
    for (std::size_t i = 0, n = listSize("boxes"); i < n; ++i) s.boxes.push_back(readBox(item("boxes", i)));
    for (std::size_t i = 0, n = listSize("cylinders"); i < n; ++i) s.cylinders.push_back(readCylinder(item("cylinders", i)));
    for (std::size_t i = 0, n = listSize("towers"); i < n; ++i) s.towers.push_back(readTower(item("towers", i)));
    std::map<std::string, std::size_t> tower_index;
    for (std::size_t i = 0; i < s.towers.size(); ++i) {
      const std::string& name = s.towers[i].name;
      if (!tower_index.emplace(name, i).second) r_.addError(item("towers", i) + ".name", "duplicate tower name '" + name + "'");
    }
    for (std::size_t i = 0, n = listSize("conductors"); i < n; ++i) readConductor(item("conductors", i), s, tower_index);
    for (const auto& k : r_.unusedKeys()) r_.addError(k, "unknown key (sections map, ground, boxes, cylinders, towers, conductors are checked)");
    return s;
  }

 private:
  static std::string item(const std::string& list, std::size_t i) { return list + "[" + std::to_string(i) + "]"; }

  /// Size of an optional list section; records an error when it is not a list.
  std::size_t listSize(const std::string& key) {
    if (!r_.has(key)) return 0;
    const YAML::Node n = deepest(raw_, key);
    if (n.IsNull()) return 0;
    if (!n.IsSequence()) {
      r_.addError(key, "expected a list");
      r_.node(key);  // consumed: do not also report its children as unknown
      return 0;
    }
    return n.size();
  }

  bool isMap(const std::string& key) {
    const YAML::Node n = deepest(raw_, key);
    if (n.IsMap()) return true;
    r_.addError(key, "expected a mapping of keys");
    r_.node(key);
    return false;
  }

  Eigen::Vector3d readPoint(const std::string& key, const Range& range = Range::any()) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    readPointInto(key, p, range);
    return p;
  }

  /// Reads `[x, y, z]` into `p`; a missing or malformed point keeps `p`.
  void readPointInto(const std::string& key, Eigen::Vector3d& p, const Range& range = Range::any()) {
    std::vector<double> v;
    r_.readDoubleList(key, v, 3, 3, range);
    if (v.size() == 3) p = Eigen::Vector3d(v[0], v[1], v[2]);
  }

  void readOptional(const std::string& key, double& value, const Range& range) {
    if (r_.has(key)) r_.readDouble(key, value, range);
  }

  void readMap(MapConfig& m) {
    mapConfigFields().readFields(r_, "", m);
    readPointInto("map.bounds.min", m.bounds.min_world);  // a bad point keeps the default
    readPointInto("map.bounds.max", m.bounds.max_world);
    if (r_.has("map.octomap_file")) {
      r_.readString("map.octomap_file", m.octomap_file);
      if (!m.octomap_file.empty() && m.octomap_file.front() != '/' && !base_dir_.empty()) {
        m.octomap_file = base_dir_ + "/" + m.octomap_file;
      }
    }
    // The rules between fields, always (a bad value kept its default while reading).
    common::addProblems(r_, "", m.problems());
  }

  OrientedBox readBox(const std::string& k) {
    OrientedBox b;
    if (!isMap(k)) return b;
    b.center_world = readPoint(k + ".center");
    b.size_m = readPoint(k + ".size", Range::positive());
    if (r_.has(k + ".rpy_deg")) {
      const Eigen::Vector3d rpy = readPoint(k + ".rpy_deg") * (M_PI / 180.0);
      b.R_world_box = rotationFromRpy(rpy.x(), rpy.y(), rpy.z());
    }
    return b;
  }

  Cylinder readCylinder(const std::string& k) {
    Cylinder c;
    if (!isMap(k)) return c;
    c.p0_world = readPoint(k + ".base");
    double height_m = 1.0;
    r_.readDouble(k + ".radius_m", c.radius_m, Range::positive());
    r_.readDouble(k + ".height_m", height_m, Range::positive());
    c.p1_world = c.p0_world + Eigen::Vector3d(0, 0, height_m);
    return c;
  }

  LatticeTowerSpec readTower(const std::string& k) {
    LatticeTowerSpec t;
    if (!isMap(k)) return t;
    r_.readString(k + ".name", t.name);
    t.base_world = readPoint(k + ".base");
    double yaw_deg = 0.0;
    readOptional(k + ".yaw_deg", yaw_deg, Range::closed(-360.0, 360.0));
    t.yaw_rad = yaw_deg * M_PI / 180.0;
    for (const auto& f : latticeTowerFields().fields) {  // height_m required, the rest optional
      if (std::string(f.key) == "height_m" || r_.has(k + "." + f.key)) latticeTowerFields().readField(r_, k + ".", t, f.key);
    }
    if (r_.has(k + ".keep_out")) r_.readBool(k + ".keep_out", t.keep_out);
    for (std::size_t i = 0, n = listSize(k + ".cross_arms"); i < n; ++i) {
      const std::string a = item(k + ".cross_arms", i);
      CrossArmSpec arm;
      if (!isMap(a)) continue;
      for (const auto& f : crossArmFields().fields) {  // section_m optional
        if (std::string(f.key) != "section_m" || r_.has(a + "." + f.key)) crossArmFields().readField(r_, a + ".", arm, f.key);
      }
      t.cross_arms.push_back(arm);
    }
    // The rules between fields, always (a bad value kept its default while reading).
    common::addProblems(r_, k + ".", t.problems());
    return t;
  }

  /// A conductor end: `[x, y, z]` or `{tower: NAME, arm: I, side: 1|-1, drop_m: D}`.
  bool readEnd(const std::string& k, const Scenario& s, const std::map<std::string, std::size_t>& towers,
               Eigen::Vector3d& p, std::vector<Cylinder>& insulators) {
    const YAML::Node n = deepest(raw_, k);
    if (!r_.has(k)) {
      r_.addError(k, "missing (required): [x, y, z] or {tower, arm, side, drop_m}");
      return false;
    }
    if (n.IsSequence()) {
      p = readPoint(k);
      return true;
    }
    if (!isMap(k)) return false;
    std::string name;
    int arm = 0, side = 1;
    double drop_m = 0.0;
    r_.readString(k + ".tower", name);
    r_.readInt(k + ".arm", arm, Range::atLeast(0));
    r_.readInt(k + ".side", side, Range::closed(-1, 1));
    readOptional(k + ".drop_m", drop_m, Range::nonNegative());
    if (side == 0) {
      r_.addError(k + ".side", "must be 1 (tower +y) or -1 (tower -y)");
      return false;
    }
    const auto it = towers.find(name);
    if (it == towers.end()) {
      if (!name.empty()) r_.addError(k + ".tower", "no tower named '" + name + "'");
      return false;
    }
    const LatticeTowerSpec& t = s.towers[it->second];
    if (static_cast<std::size_t>(arm) >= t.cross_arms.size()) {
      r_.addError(k + ".arm", "tower '" + name + "' has " + std::to_string(t.cross_arms.size()) + " cross-arms");
      return false;
    }
    p = t.armTip(static_cast<std::size_t>(arm), side, drop_m);
    if (drop_m > 0.0) insulators.push_back(Cylinder{t.armTip(static_cast<std::size_t>(arm), side), p, kInsulatorRadiusM});
    return true;
  }

  void readConductor(const std::string& k, Scenario& s, const std::map<std::string, std::size_t>& towers) {
    if (!isMap(k)) return;
    const std::size_t errors_before = r_.errors().size();
    ConductorSpec c;
    std::vector<Cylinder> insulators;
    const bool ends = readEnd(k + ".from", s, towers, c.from_world, insulators) &
                      readEnd(k + ".to", s, towers, c.to_world, insulators);
    r_.readDouble(k + ".sag_m", c.sag_m, Range::positive());
    readOptional(k + ".radius_m", c.radius_m, Range::positive());
    readOptional(k + ".max_piece_length_m", c.max_piece_length_m, Range::positive());
    if (!ends || r_.errors().size() != errors_before) return;
    const auto cat = Catenary::fit(c.from_world, c.to_world, c.sag_m);
    if (!cat) {
      r_.addError(k, cat.reason());
      return;
    }
    s.conductors.push_back(c);
    s.insulators.insert(s.insulators.end(), insulators.begin(), insulators.end());
  }

  ConfigReader& r_;
  YAML::Node raw_;
  std::string base_dir_;
};

/// Rewrites "source: key: message" into "source:LINE: key: message".
std::string reportWithLines(const ConfigReader& r, const YAML::Node& raw) {
  std::string out;
  const std::string prefix = r.source() + ": ";
  for (const auto& e : r.errors()) {
    if (e.rfind(prefix, 0) == 0 && raw.IsDefined()) {
      const auto end = e.find(": ", prefix.size());
      const std::string key = e.substr(prefix.size(), end == std::string::npos ? std::string::npos : end - prefix.size());
      const YAML::Node n = deepest(raw, key);
      const int line = n.IsDefined() ? n.Mark().line + 1 : 0;
      if (line > 0) {
        out += r.source() + ":" + std::to_string(line) + ": " + e.substr(prefix.size()) + "\n";
        continue;
      }
    }
    out += e + "\n";
  }
  return out;
}

common::Result<Scenario> finish(ConfigReader& r, const YAML::Node& raw, const std::string& base_dir) {
  Scenario s;
  if (r.ok()) {
    ScenarioReader sr(r, raw, base_dir);
    s = sr.read();
  }
  if (!r.ok()) return common::Result<Scenario>::fail(reportWithLines(r, raw));
  return common::Result<Scenario>::ok(s);
}

}  // namespace

common::Result<Scenario> loadScenario(const std::string& path) {
  ConfigReader r = ConfigReader::fromFile(path, ConfigReader::MissingKeys::kError);
  YAML::Node raw;
  if (r.ok()) {
    try {
      raw = YAML::LoadFile(path);
    } catch (const YAML::Exception&) {
      // already reported by the reader
    }
  }
  const auto slash = path.find_last_of('/');
  return finish(r, raw, slash == std::string::npos ? std::string(".") : path.substr(0, slash));
}

common::Result<Scenario> parseScenario(const std::string& yaml, const std::string& source_name) {
  ConfigReader r = ConfigReader::fromString(yaml, source_name, ConfigReader::MissingKeys::kError);
  YAML::Node raw;
  if (r.ok()) {
    try {
      raw = YAML::Load(yaml);
    } catch (const YAML::Exception&) {
    }
  }
  return finish(r, raw, "");
}

}  // namespace gesture_formation::planning
