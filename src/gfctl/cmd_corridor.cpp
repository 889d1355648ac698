// gfctl corridor --scenario FILE --path path.csv --out corridor.json [--clearance M] [--box-margin M]
// (docs/design.md §8.6)
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/planning/corridor_builder.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/scenario.hpp"

namespace gesture_formation::gfctl {

namespace {
int cmdCorridor(const Args& args);
const Registrar kRegistrar{
    "corridor",
    "--scenario FILE --path path.csv --out corridor.json [--clearance M] [--box-margin M]   convex corridors (docs/design.md §8.6)",
    cmdCorridor};

/// Parses a finite number option; records the problem and returns false otherwise.
bool numberOption(const Args& args, const std::string& name, double& value, const common::Range& range) {
  if (!args.has(name)) return true;
  const auto v = common::parseDouble(args.get(name));
  if (!v || !range.contains(*v)) {
    badInput(args, "--" + name + ": expected a number " + common::rangeRequirement(range) + ", got '" + args.get(name) + "'");
    return false;
  }
  value = *v;
  return true;
}

void writeNumber(std::ostream& os, double v) { os << (std::isfinite(v) && v != 0.0 ? v : 0.0); }  // no "-0", no nan

int cmdCorridor(const Args& args) {
  if (!checkOptions(args, {"scenario", "path", "out"}, {"clearance", "box-margin"})) return kExitBadInput;
  planning::CorridorConfig config;
  double box_margin = config.local_box_margin_m.x();
  if (!numberOption(args, "clearance", config.clearance_m, *planning::corridorConfigFields().rangeOf("clearance_m"))) {
    return kExitBadInput;
  }
  if (!numberOption(args, "box-margin", box_margin, common::Range::atLeast(0.01))) return kExitBadInput;
  config.local_box_margin_m = Eigen::Vector3d::Constant(box_margin);
  const planning::CorridorBuilder builder(config);
  if (!builder.configError().empty()) return badInput(args, builder.configError());

  const auto scenario = planning::loadScenario(args.get("scenario"));
  if (!scenario) {
    std::cerr << "gfctl corridor: invalid scenario:\n" << scenario.reason();
    return kExitBadInput;
  }

  common::CsvReader in(args.get("path"));
  if (!in.requireColumns({"x", "y", "z"})) return badInput(args, in.error());
  std::vector<Eigen::Vector3d> path;
  std::vector<std::size_t> lines;
  while (in.next()) {
    const Eigen::Vector3d p(in.number("x"), in.number("y"), in.number("z"));
    if (!in.error().empty()) return badInput(args, in.error());
    for (int i = 0; i < 3; ++i) {
      if (!std::isfinite(p(i))) {
        in.fail(std::string(1, "xyz"[i]), "must be finite");
        return badInput(args, in.error());
      }
    }
    path.push_back(p);
    lines.push_back(in.lineNumber());
  }
  if (!in.error().empty()) return badInput(args, in.error());
  if (path.size() < 2) {
    return badInput(args, in.path() + ": needs at least 2 waypoints (rows), got " + std::to_string(path.size()));
  }

  const auto map = planning::OccupancyMap::fromScenario(*scenario);
  if (!map) return badInput(args, args.get("scenario") + ": " + map.reason());

  const auto t0 = std::chrono::steady_clock::now();
  std::vector<planning::SegmentCorridor> corridors;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    auto seg = builder.buildSegment(path[i], path[i + 1], *map);
    if (!seg) {
      return badInput(args, in.path() + ":" + std::to_string(lines[i]) + ": segment to line " + std::to_string(lines[i + 1]) +
                                ": " + seg.reason());
    }
    corridors.push_back(std::move(seg.value()));
  }
  const double time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const double half_diagonal = planning::OccupancyMap::rasterInflation(map->resolution());
  for (std::size_t i = 0; i < corridors.size(); ++i) {
    if (corridors[i].segment_clearance_m < half_diagonal) {
      std::cerr << "gfctl corridor: warning: " << in.path() << ":" << lines[i] << ": the segment passes "
                << corridors[i].segment_clearance_m << " m from an occupied voxel centre (it crosses an occupied voxel)\n";
    }
  }

  std::ostringstream js;
  js << std::setprecision(17) << "{\"polytopes\": [";
  double min_clearance = config.clearance_m;
  std::size_t rows = 0;
  for (std::size_t k = 0; k < corridors.size(); ++k) {
    const auto& c = corridors[k];
    min_clearance = std::min(min_clearance, c.clearance_m);
    rows += static_cast<std::size_t>(c.polytope.rows());
    js << (k ? ",\n  " : "\n  ") << "{\"A\": [";
    for (int r = 0; r < c.polytope.rows(); ++r) {
      js << (r ? ", " : "") << "[";
      for (int j = 0; j < 3; ++j) {
        if (j) js << ", ";
        writeNumber(js, c.polytope.A(r, j));
      }
      js << "]";
    }
    js << "], \"b\": [";
    for (int r = 0; r < c.polytope.rows(); ++r) {
      if (r) js << ", ";
      writeNumber(js, c.polytope.b(r));
    }
    js << "], \"seed\": [";
    for (const Eigen::Vector3d* s : {&c.seed_begin_world, &c.seed_end_world}) {
      js << (s == &c.seed_begin_world ? "[" : ", [");
      for (int j = 0; j < 3; ++j) {
        if (j) js << ", ";
        writeNumber(js, (*s)(j));
      }
      js << "]";
    }
    js << "]}";
  }
  js << "\n], \"time_ms\": ";
  writeNumber(js, time_ms);
  js << "}\n";

  std::ofstream out(args.get("out"));
  if (!out) return badInput(args, args.get("out") + ": cannot open for writing");
  out << js.str();
  out.flush();
  if (!out) return badInput(args, args.get("out") + ": write failed");
  std::cout << "gfctl corridor: " << corridors.size() << " polytopes (" << rows << " planes) in " << time_ms
            << " ms; clearance " << config.clearance_m << " m requested, " << min_clearance << " m achieved\n";
  return kExitOk;
}
}  // namespace

}  // namespace gesture_formation::gfctl
