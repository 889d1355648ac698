#include "gesture_formation/gesture/gesture_mapping.hpp"

#include <cmath>
#include <cstdlib>

namespace gesture_formation::gesture {

using common::ConfigReader;

const char* toString(GestureEvent e) { return e == GestureEvent::kAbort ? "abort" : "assist_requested"; }

GestureMapping GestureMapping::paperDefault() {
  GestureMapping m;
  const struct {
    int id;
    const char* path;
    double increment;
  } table[] = {{1, "leader.beta_deg", -30.0}, {2, "leader.beta_deg", 30.0}, {3, "leader.gamma_deg", -5.0},
               {4, "leader.gamma_deg", 5.0}};
  for (const auto& row : table) {
    GestureAction a;
    a.parameter_path = row.path;
    const auto parsed = formation::parseParameterPath(row.path);
    a.target = parsed->first;
    a.parameter = parsed->second;
    a.increment = row.increment;
    m.actions[row.id] = a;
  }
  return m;
}

const GestureAction* GestureMapping::find(int gesture_id) const {
  const auto it = actions.find(gesture_id);
  return it == actions.end() ? nullptr : &it->second;
}

namespace {

bool parseNumber(const YAML::Node& n, double& out) {
  if (!n.IsScalar()) return false;
  const std::string& s = n.Scalar();
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return !s.empty() && end != nullptr && *end == '\0' && std::isfinite(out);
}

}  // namespace

void readGestureMapping(ConfigReader& r, int max_gesture_id, int follower_count, GestureMapping& mapping) {
  if (!r.has("mapping") && r.mode() == ConfigReader::MissingKeys::kUseDefaults) return;
  const YAML::Node root = r.node("mapping");
  if (!root.IsDefined()) return;  // missing: already reported in kError mode
  if (!root.IsMap()) {
    r.addError("mapping", "expected a map {gesture_id: {parameter: ..., increment: ...} | {event: ...}}");
    return;
  }
  const std::size_t errors_before = r.errors().size();
  GestureMapping out;
  for (const auto& kv : root) {
    const std::string id_text = kv.first.IsScalar() ? kv.first.Scalar() : std::string("?");
    const std::string key = "mapping." + id_text;
    double id_value = 0.0;
    if (!parseNumber(kv.first, id_value) || id_value != std::floor(id_value) || id_value < 1 ||
        id_value > max_gesture_id) {
      r.addError(key, "gesture id must be an integer in [1, max_gesture_id=" + std::to_string(max_gesture_id) +
                          "] (0 is 'none' and cannot be mapped)");
      continue;
    }
    const YAML::Node& v = kv.second;
    if (!v.IsMap()) {
      r.addError(key, "expected {parameter: <target>.<name>, increment: <number>} or {event: assist_requested|abort}");
      continue;
    }
    for (const auto& field : v) {
      const std::string f = field.first.Scalar();
      if (f != "parameter" && f != "increment" && f != "event") r.addError(key + "." + f, "unknown key");
    }
    GestureAction a;
    if (v["event"]) {
      const std::string e = v["event"].IsScalar() ? v["event"].Scalar() : std::string();
      if (v["parameter"] || v["increment"]) {
        r.addError(key, "an event mapping takes no parameter or increment");
        continue;
      }
      if (e == "assist_requested") {
        a.event = GestureEvent::kAssistRequested;
      } else if (e == "abort") {
        a.event = GestureEvent::kAbort;
      } else {
        r.addError(key + ".event", "value '" + e + "' is not one of assist_requested|abort");
        continue;
      }
      a.kind = GestureAction::Kind::kEvent;
    } else {
      if (!v["parameter"] || !v["parameter"].IsScalar()) {
        r.addError(key + ".parameter", "missing (or give event: assist_requested|abort)");
        continue;
      }
      a.parameter_path = v["parameter"].Scalar();
      const auto parsed = formation::parseParameterPath(a.parameter_path);
      if (!parsed) {
        r.addError(key + ".parameter", parsed.reason());
        continue;
      }
      a.target = parsed->first;
      a.parameter = parsed->second;
      const auto uavs = a.target.resolve(1 + follower_count);
      if (!uavs) {
        r.addError(key + ".parameter", "'" + a.parameter_path + "': " + uavs.reason());
        continue;
      }
      if (!v["increment"] || !parseNumber(v["increment"], a.increment)) {
        r.addError(key + ".increment", "expected a finite number");
        continue;
      }
    }
    out.actions[static_cast<int>(id_value)] = a;
  }
  if (r.errors().size() == errors_before) mapping = out;  // all or nothing
}

formation::FormationCommand toCommand(const GestureAction& action, std::uint64_t sequence) {
  formation::FormationCommand c;
  c.id = formation::CommandId{"gesture", sequence};
  c.source = formation::CommandSource::kGesture;
  c.target = action.target;
  c.parameter = action.parameter;
  c.kind = formation::CommandKind::kIncrement;
  c.amount = action.increment;
  return c;
}

}  // namespace gesture_formation::gesture
