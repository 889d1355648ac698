// gfctl gesture-filter --config FILE --in gestures.csv --out commands.csv   (docs/design.md §8.3)
#include <cmath>
#include <fstream>
#include <iostream>

#include "commands.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/formation/formation_config.hpp"
#include "gesture_formation/gesture/gesture_filter.hpp"
#include "gesture_formation/gesture/gesture_mapping.hpp"
#include "gesture_formation/gesture/view_fusion.hpp"

namespace gesture_formation::gfctl {

namespace {

using common::formatDouble;

constexpr int kMaxWarnings = 20;

int cmdGestureFilter(const Args& args);
const Registrar kRegistrar{"gesture-filter",
                           "--config FILE --in gestures.csv --out commands.csv   gesture filter + mapping (docs/design.md §8.3)",
                           cmdGestureFilter};

int cmdGestureFilter(const Args& args) {
  if (!checkOptions(args, {"config", "in", "out"}, {})) return kExitBadInput;
  const std::string path = args.get("config");
  common::ConfigReader r = common::ConfigReader::fromFile(path, common::ConfigReader::MissingKeys::kUseDefaults);
  const formation::FormationConfig fcfg = formation::readFormationConfig(r);
  const gesture::GestureFilterConfig gcfg = gesture::readGestureFilterConfig(r);
  gesture::GestureMapping mapping = gesture::GestureMapping::paperDefault();
  gesture::readGestureMapping(r, gcfg.max_gesture_id, static_cast<int>(fcfg.params.followers.size()), mapping);
  (void)gesture::readViewFusionConfig(r);  // validated here too (used by fuse-views and the simulator)
  for (const auto& k : r.unusedKeys()) std::cerr << "gfctl gesture-filter: warning: " << path << ": unknown key '" << k << "' ignored\n";
  if (!r.ok()) {
    std::cerr << "gfctl gesture-filter: invalid configuration:\n" << r.errorReport();
    return kExitBadInput;
  }
  auto state = formation::FormationState::create(fcfg.params, fcfg.limits, fcfg.duplicates);
  auto filter = gesture::GestureFilter::create(gcfg);
  if (!state || !filter) {
    std::cerr << "gfctl gesture-filter: invalid configuration:\n" << state.reason() << filter.reason();
    return kExitBadInput;
  }
  formation::FormationState& formation_state = state.value();
  gesture::GestureFilter& gesture_filter = filter.value();

  common::CsvReader in(args.get("in"));
  if (!in.requireColumns({"t", "gesture_id"})) return badInput(args, in.error());
  std::ofstream out(args.get("out"));
  if (!out) return badInput(args, args.get("out") + ": cannot open for writing");
  out << "t,gesture_id,parameter,increment,value\n";

  std::size_t rows = 0, rejected = 0, fired = 0, clamped = 0, warned = 0, refused = 0;
  std::uint64_t sequence = 0;
  while (in.next()) {
    ++rows;
    const double t = in.number("t");
    const double id = in.number("gesture_id");
    if (!in.error().empty()) return badInput(args, in.error());
    const gesture::GestureFilterOutput o = gesture_filter.update(t, id);
    if (!o.accepted) {
      ++rejected;
      if (warned++ < kMaxWarnings) {
        std::cerr << "gfctl gesture-filter: " << in.path() << ":" << in.lineNumber() << ": measurement rejected: " << o.reason
                  << "\n";
      }
      continue;
    }
    if (!o.fired) continue;
    ++fired;
    out << formatDouble(t) << ',' << o.dominant_id << ',';
    const gesture::GestureAction* action = mapping.find(o.dominant_id);
    if (action == nullptr) {
      out << "none,0,nan\n";
    } else if (action->kind == gesture::GestureAction::Kind::kEvent) {
      out << gesture::toString(action->event) << ",0,nan\n";
    } else {
      const formation::CommandOutcome c = formation_state.apply(gesture::toCommand(*action, ++sequence));
      out << action->parameter_path << ',' << formatDouble(action->increment) << ',';
      if (c.status != formation::CommandStatus::kApplied) {  // e.g. two slots closer than Γ_dis: nothing changed
        ++refused;
        out << "nan\n";
        std::cerr << "gfctl gesture-filter: t=" << formatDouble(t) << " s: command refused: " << c.reason << "\n";
        continue;
      }
      for (std::size_t i = 0; i < c.changes.size(); ++i) out << (i ? ";" : "") << formatDouble(c.changes[i].applied);
      out << '\n';
      for (const auto& ch : c.changes) {
        if (!ch.clamped) continue;
        ++clamped;
        std::cerr << "gfctl gesture-filter: t=" << formatDouble(t) << " s: UAV " << formation::uavLabel(ch.uav) << " "
                  << formation::parameterName(ch.parameter) << " requested " << formatDouble(ch.requested)
                  << ", applied " << formatDouble(ch.applied) << " (" << ch.clamp_rule << ")\n";
      }
    }
  }
  if (!in.error().empty()) return badInput(args, in.error());
  out.flush();
  if (!out) return badInput(args, args.get("out") + ": write failed");
  if (warned > kMaxWarnings) std::cerr << "gfctl gesture-filter: " << (warned - kMaxWarnings) << " more warnings not shown\n";
  std::cout << "gfctl gesture-filter: " << rows << " rows, " << rejected << " rejected, " << fired << " commands fired, "
            << refused << " refused by the formation, " << clamped << " values clamped\n";
  return kExitOk;
}

}  // namespace
}  // namespace gesture_formation::gfctl
