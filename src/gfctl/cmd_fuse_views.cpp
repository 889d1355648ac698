// gfctl fuse-views --in g0.csv,g1.csv[,…] --out fused.csv [--config FILE]
// The multi-view vote of gesture::ViewFusion (docs/gestures.md §6) over the classifications of
// several cameras: each input is `gfctl classify` output (t,gesture_id,…), optionally with the
// camera's geometry per row (columns distance_m, elevation_deg; without them a view counts as
// unknown geometry, which votes only when view_fusion.gate_envelope is false). The first file
// is the leader's: one output row per row of it, `t,gesture_id,voting_views,agreeing_views`,
// fusing at its t the newest row of every view with t' ≤ t. Rows must be in time order per
// file. Config: `view_fusion.*` and max_gesture_id of config/gestures.yaml (defaults without).
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/gesture/gesture_filter.hpp"
#include "gesture_formation/gesture/view_fusion.hpp"

namespace gesture_formation::gfctl {
namespace {

int cmdFuseViews(const Args& args);
const Registrar kRegistrar{"fuse-views",
                           "--in g0.csv,g1.csv,… --out fused.csv [--config FILE]   multi-view gesture vote (docs/gestures.md)",
                           cmdFuseViews};

struct ViewFile {
  std::unique_ptr<common::CsvReader> in;
  bool geometry = false;
  bool pending = false;  ///< a row read but not yet observed (its t is later than the fusion time)
  gesture::ViewObservation row;
};

// Reads the next row of `f` into f.row; false at the end or on error (in->error() says which).
bool readRow(ViewFile& f, int view, int max_gesture_id) {
  if (!f.in->next()) return false;
  f.row.view = view;
  f.row.t_s = f.in->number("t");
  const double id = f.in->number("gesture_id");
  if (f.in->error().empty() && !(id >= 0 && id <= max_gesture_id && id == std::floor(id))) {
    f.in->fail("gesture_id", "expected an integer in [0, " + std::to_string(max_gesture_id) + "], got " +
                                 common::formatDouble(id));
  }
  if (f.in->error().empty() && !std::isfinite(f.row.t_s)) f.in->fail("t", "not finite");
  f.row.gesture_id = static_cast<int>(id);
  if (f.geometry) {
    f.row.distance_m = f.in->number("distance_m");
    f.row.elevation_deg = f.in->number("elevation_deg");
  } else {
    f.row.distance_m = std::nan("");
    f.row.elevation_deg = std::nan("");
  }
  return f.in->error().empty();
}

int cmdFuseViews(const Args& args) {
  if (!checkOptions(args, {"in", "out"}, {"config"})) return kExitBadInput;
  gesture::ViewFusionConfig config;
  int max_gesture_id = gesture::GestureFilterConfig{}.max_gesture_id;
  if (args.has("config")) {
    const std::string path = args.get("config");
    common::ConfigReader r = common::ConfigReader::fromFile(path, common::ConfigReader::MissingKeys::kUseDefaults);
    config = gesture::readViewFusionConfig(r);
    max_gesture_id = gesture::readGestureFilterConfig(r).max_gesture_id;
    if (!r.ok()) {
      std::cerr << "gfctl fuse-views: invalid configuration:\n" << r.errorReport();
      return kExitBadInput;
    }
  }
  const std::vector<std::string> paths = common::splitCsvLine(args.get("in"));
  for (const std::string& path : paths) {
    if (path.empty()) return badInput(args, "--in: empty file name in '" + args.get("in") + "'");
  }
  if (paths.size() > 16) return badInput(args, "--in: at most 16 views, got " + std::to_string(paths.size()));
  std::vector<ViewFile> files(paths.size());
  for (std::size_t i = 0; i < paths.size(); ++i) {
    files[i].in = std::make_unique<common::CsvReader>(paths[i]);
    if (!files[i].in->requireColumns({"t", "gesture_id"})) return badInput(args, files[i].in->error());
    files[i].geometry = files[i].in->column("distance_m") >= 0 && files[i].in->column("elevation_deg") >= 0;
  }
  std::ofstream out(args.get("out"));
  if (!out) return badInput(args, args.get("out") + ": cannot open for writing");
  out << "t,gesture_id,voting_views,agreeing_views\n";
  gesture::ViewFusion fusion(config, static_cast<int>(paths.size()), max_gesture_id);
  std::size_t rows = 0, fused_gestures = 0;
  double last_t = -INFINITY;
  ViewFile& lead = files[0];
  while (readRow(lead, 0, max_gesture_id)) {
    const double t = lead.row.t_s;
    if (t < last_t) lead.in->fail("t", "rows must be in time order: " + common::formatDouble(t) + " after " + common::formatDouble(last_t));
    if (!lead.in->error().empty()) break;
    last_t = t;
    std::string reason;
    if (!fusion.observe(lead.row, &reason)) return badInput(args, paths[0] + ": " + reason);
    for (std::size_t v = 1; v < files.size(); ++v) {
      ViewFile& f = files[v];
      for (;;) {
        if (!f.pending) {
          if (!readRow(f, static_cast<int>(v), max_gesture_id)) break;
          f.pending = true;
        }
        if (f.row.t_s > t) break;
        if (!fusion.observe(f.row, &reason)) return badInput(args, f.in->path() + ":" + std::to_string(f.in->lineNumber()) + ": " + reason);
        f.pending = false;
      }
      if (!f.in->error().empty()) return badInput(args, f.in->error());
    }
    const gesture::FusedGesture g = fusion.fuse(t);
    out << common::formatDouble(t) << ',' << g.gesture_id << ',' << g.voting_views << ',' << g.agreeing_views << '\n';
    ++rows;
    fused_gestures += g.gesture_id != 0 ? 1 : 0;
  }
  if (!lead.in->error().empty()) return badInput(args, lead.in->error());
  out.flush();
  if (!out) return badInput(args, args.get("out") + ": write failed");
  std::cout << "gfctl fuse-views: " << paths.size() << " views, " << rows << " rows, " << fused_gestures
            << " fused as a gesture\n";
  return kExitOk;
}

}  // namespace
}  // namespace gesture_formation::gfctl
