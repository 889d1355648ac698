// gfctl map --scenario FILE [--export-points pts.csv] [--out map.bt]   (docs/design.md §8.5)
#include <chrono>
#include <fstream>
#include <iostream>

#include "commands.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/scenario.hpp"

namespace gesture_formation::gfctl {

namespace {
int cmdMap(const Args& args);
const Registrar kRegistrar{"map",
                           "--scenario FILE [--export-points pts.csv] [--out map.bt]   build the scenario's OctoMap (docs/design.md §8.5)",
                           cmdMap};

int cmdMap(const Args& args) {
  if (!checkOptions(args, {"scenario"}, {"export-points", "out"})) return kExitBadInput;
  if (!args.has("export-points") && !args.has("out")) return badInput(args, "give --export-points FILE and/or --out FILE");
  const auto scenario = planning::loadScenario(args.get("scenario"));
  if (!scenario) {
    std::cerr << "gfctl map: invalid scenario:\n" << scenario.reason();
    return kExitBadInput;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const auto map = planning::OccupancyMap::fromScenario(*scenario);
  if (!map) return badInput(args, args.get("scenario") + ": " + map.reason());
  const double build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  if (args.has("export-points")) {
    const std::string path = args.get("export-points");
    std::ofstream out(path);
    if (!out) return badInput(args, path + ": cannot open for writing");
    out << "x,y,z\n";
    for (const auto& p : map->occupiedCenters()) {
      out << common::formatDouble(p.x()) << ',' << common::formatDouble(p.y()) << ',' << common::formatDouble(p.z()) << '\n';
    }
    out.flush();
    if (!out) return badInput(args, path + ": write failed");
  }
  if (args.has("out")) {
    const std::string error = map->writeBinary(args.get("out"));
    if (!error.empty()) return badInput(args, error);
  }
  const auto& g = map->gridBounds();
  std::cout << "gfctl map: " << map->occupiedCount() << " occupied voxels at " << map->resolution() << " m in ["
            << g.min_world.transpose() << "] .. [" << g.max_world.transpose() << "] m, built in " << build_ms << " ms\n";
  if (map->droppedVoxels() > 0) {
    std::cerr << "gfctl map: warning: " << map->droppedVoxels() << " voxels of map.octomap_file lie outside map.bounds\n";
  }
  return kExitOk;
}
}  // namespace

}  // namespace gesture_formation::gfctl
