// gfctl formation-ref --config FILE --in human.csv --out refs.csv   (docs/design.md §8.2)
#include <cmath>
#include <fstream>
#include <iostream>

#include "commands.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/formation/formation_config.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"

namespace gesture_formation::gfctl {

namespace {

using common::formatDouble;

int cmdFormationRef(const Args& args);
const Registrar kRegistrar{"formation-ref",
                           "--config FILE --in human.csv --out refs.csv   formation reference geometry (docs/design.md §8.2)",
                           cmdFormationRef};

void writeRow(std::ostream& out, const std::string& t, const std::string& label, const formation::UavReference& r) {
  out << t << ',' << label << ',' << formatDouble(r.p_world.x()) << ',' << formatDouble(r.p_world.y()) << ','
      << formatDouble(r.p_world.z()) << ',' << formatDouble(r.heading_rad) << ',' << formatDouble(r.pitch_rad) << '\n';
}

int cmdFormationRef(const Args& args) {
  if (!checkOptions(args, {"config", "in", "out"}, {})) return kExitBadInput;
  std::vector<std::string> warnings;
  const auto cfg = formation::loadFormationConfig(args.get("config"), common::ConfigReader::MissingKeys::kUseDefaults,
                                                  &warnings);
  for (const auto& w : warnings) std::cerr << "gfctl formation-ref: warning: " << w << "\n";
  if (!cfg) {
    std::cerr << "gfctl formation-ref: invalid configuration:\n" << cfg.reason();
    return kExitBadInput;
  }
  const formation::FormationParams& params = cfg->params;

  common::CsvReader in(args.get("in"));
  if (!in.requireColumns({"t", "hx", "hy", "hz", "h_heading"})) return badInput(args, in.error());
  std::ofstream out(args.get("out"));
  if (!out) return badInput(args, args.get("out") + ": cannot open for writing");
  out << "t,uav,x,y,z,heading,pitch\n";

  std::vector<std::string> labels;
  for (formation::UavIndex u = 0; u < params.uavCount(); ++u) labels.push_back(formation::uavLabel(u));
  std::size_t rows = 0;
  while (in.next()) {
    const double t = in.number("t");
    const Eigen::Vector3d p_h(in.number("hx"), in.number("hy"), in.number("hz"));
    const double heading = in.number("h_heading");
    if (!in.error().empty()) return badInput(args, in.error());
    const char* names[] = {"t", "hx", "hy", "hz", "h_heading"};
    const double values[] = {t, p_h.x(), p_h.y(), p_h.z(), heading};
    for (int i = 0; i < 5; ++i) {
      if (!std::isfinite(values[i])) {
        in.fail(names[i], "must be finite, got '" + in.field(in.column(names[i])) + "'");
        return badInput(args, in.error());
      }
    }
    ++rows;
    // Followers use the leader's desired heading and pitch (eq. leader_ref) at this row.
    const formation::UavReference leader = formation::leaderReference(p_h, heading, params.leader);
    const std::string ts = formatDouble(t);
    writeRow(out, ts, labels[0], leader);
    for (std::size_t i = 0; i < params.followers.size(); ++i) {
      writeRow(out, ts, labels[i + 1],
               formation::followerReference(p_h, leader.heading_rad, leader.pitch_rad, params.followers[i]));
    }
  }
  if (!in.error().empty()) return badInput(args, in.error());
  out.flush();
  if (!out) return badInput(args, args.get("out") + ": write failed");
  std::cout << "gfctl formation-ref: " << rows << " rows x " << params.uavCount() << " UAVs (leader + "
            << params.followers.size() << " followers)\n";
  return kExitOk;
}

}  // namespace
}  // namespace gesture_formation::gfctl
