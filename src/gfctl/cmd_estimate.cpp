// gfctl estimate --config FILE --in meas.csv --out states.csv   (docs/design.md §8.1)
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>

#include "commands.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/estimation/estimator_config.hpp"
#include "gesture_formation/estimation/human_kalman.hpp"
#include "gesture_formation/estimation/measurement_model.hpp"

namespace gesture_formation::gfctl {

namespace {

using common::formatDouble;
using estimation::DistanceSource;
using estimation::UpdateOutcome;

constexpr int kMaxWarnings = 20;

}  // namespace

namespace {
int cmdEstimate(const Args& args);
const Registrar kRegistrar{"estimate", "--config FILE --in meas.csv --out states.csv   replay the worker estimator (docs/design.md §8.1)",
                           cmdEstimate};

int cmdEstimate(const Args& args) {
  if (!checkOptions(args, {"config", "in", "out"}, {})) return kExitBadInput;
  std::vector<std::string> warnings;
  const auto cfg = estimation::loadEstimatorConfig(args.get("config"), common::ConfigReader::MissingKeys::kUseDefaults,
                                                   &warnings);
  for (const auto& w : warnings) std::cerr << "gfctl estimate: warning: " << w << "\n";
  if (!cfg) {
    std::cerr << "gfctl estimate: invalid configuration:\n" << cfg.reason();
    return kExitBadInput;
  }

  common::CsvReader in(args.get("in"));
  const std::vector<std::string> columns = {"t",  "cam_x", "cam_y", "cam_z", "cam_qw", "cam_qx", "cam_qy",
                                            "cam_qz", "u", "v",     "w",     "h",      "d_uwb",  "d_stereo"};
  if (!in.requireColumns(columns)) return badInput(args, in.error());

  std::ofstream out(args.get("out"));
  if (!out) return badInput(args, args.get("out") + ": cannot open for writing");
  out << "t,x,y,z,vx,vy,vz,source,accepted,pxx,pyy,pzz,pvxx,pvyy,pvzz\n";

  const estimation::CameraModel camera(cfg->camera);
  estimation::HumanKalman filter(cfg->filter);
  std::size_t rows = 0, detections = 0, rejected_rows = 0, warned = 0;
  std::map<std::string, std::size_t> fused_by_source;
  auto warn = [&](const std::string& msg) {
    ++rejected_rows;
    if (warned++ < kMaxWarnings) std::cerr << "gfctl estimate: " << in.path() << ":" << in.lineNumber() << ": " << msg << "\n";
  };

  while (in.next()) {
    ++rows;
    const double t = in.number("t");
    const bool has_detection = !in.field(in.column("u")).empty();
    estimation::CameraPose pose;
    estimation::Box box;
    double d_uwb = std::nan(""), d_stereo = std::nan("");
    if (has_detection) {
      pose.t_world_camera = Eigen::Vector3d(in.number("cam_x"), in.number("cam_y"), in.number("cam_z"));
      pose.q_world_camera =
          Eigen::Quaterniond(in.number("cam_qw"), in.number("cam_qx"), in.number("cam_qy"), in.number("cam_qz"));
      box = estimation::Box{in.number("u"), in.number("v"), in.number("w"), in.number("h")};
      d_uwb = in.number("d_uwb", true);
      d_stereo = in.number("d_stereo", true);
    }
    if (!in.error().empty()) return badInput(args, in.error());

    DistanceSource source = DistanceSource::kNone;
    bool accepted = false;
    if (!std::isfinite(t)) {
      warn("field 't': non-finite time; row ignored");
    } else if (has_detection) {
      ++detections;
      const auto m = estimation::makeMeasurement(camera, pose, box, d_uwb, d_stereo, cfg->human_height_m, cfg->noise,
                                                 cfg->max_apparent_distance_m);
      if (!m) {
        warn("measurement rejected: " + m.reason());
        filter.predict(t);  // the row still advances the filter's time (Q once per row)
      } else {
        source = m->source;
        const UpdateOutcome outcome = filter.step(t, *m);
        accepted = estimation::accepted(outcome);
        if (accepted) ++fused_by_source[toString(source)];
        if (outcome == UpdateOutcome::kOutOfOrder) warn("measurement older than the filter's time; dropped");
        if (outcome == UpdateOutcome::kInvalid) warn("measurement rejected: non-finite update");
      }
    } else if (filter.initialized() && t >= filter.time()) {
      filter.predict(t);
    }

    out << formatDouble(t);
    if (filter.initialized()) {
      const auto& x = filter.state();
      const auto& P = filter.covariance();
      for (int i = 0; i < 6; ++i) out << ',' << formatDouble(x(i));
      out << ',' << toString(source) << ',' << (accepted ? 1 : 0);
      for (int i = 0; i < 6; ++i) out << ',' << formatDouble(P(i, i));
    } else {
      out << ",nan,nan,nan,nan,nan,nan,none,0,nan,nan,nan,nan,nan,nan";
    }
    out << '\n';
  }
  if (!in.error().empty()) return badInput(args, in.error());
  out.flush();
  if (!out) return badInput(args, args.get("out") + ": write failed");
  if (warned > kMaxWarnings) std::cerr << "gfctl estimate: " << (warned - kMaxWarnings) << " more warnings not shown\n";

  const auto& c = filter.counters();
  std::cout << "gfctl estimate: " << rows << " rows, " << detections << " detections; fused " << c.fused
            << " + initialised " << c.initializations << " + re-initialised " << c.reinitializations << " (uwb "
            << fused_by_source["uwb"] << ", stereo " << fused_by_source["stereo"] << ", apparent "
            << fused_by_source["apparent"] << "); gated " << c.gated << ", out-of-order " << c.out_of_order
            << ", rejected rows " << rejected_rows << "\n";
  if (filter.initialized()) {
    const auto& x = filter.state();
    std::cout << "gfctl estimate: final state at t=" << formatDouble(filter.time()) << " s: p=(" << formatDouble(x(0))
              << ", " << formatDouble(x(1)) << ", " << formatDouble(x(2)) << ") m, v=(" << formatDouble(x(3)) << ", "
              << formatDouble(x(4)) << ", " << formatDouble(x(5)) << ") m/s\n";
  }
  return kExitOk;
}
}  // namespace

}  // namespace gesture_formation::gfctl
