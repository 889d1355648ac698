// gfctl fuse-views --in g0.csv,g1.csv[,…] --out fused.csv [--config FILE]
// The multi-view vote of gesture::ViewFusion (docs/gestures.md §6) over the classifications of
// several cameras: each input is `gfctl classify` output (t,gesture_id,…), optionally with the
// camera's geometry per row (columns distance_m, elevation_deg; without them a view counts as
// unknown geometry, which votes only when view_fusion.gate_envelope is false). The first file
// is the leader's: one output row per row of it, `t,gesture_id,voting_views,agreeing_views`,
// fusing at its t the newest row of every view with t' ≤ t. Rows must be in time order per
// file. Config: `view_fusion.*` and max_gesture_id of config/gestures.yaml (defaults without).
// Calibrated views (view_fusion.require_3d / confirm_3d, docs/gestures.md §6): a file whose header
// has the frame's keypoints (x0..x16, y0..y16, c0..c16, image pixels as in skeletons.csv) and its
// camera (cam_x, cam_y, cam_z: optical centre in a world frame common to all views [m];
// cam_qw, cam_qx, cam_qy, cam_qz: R_world_camera, unit quaternion; cam_fx, cam_fy, cam_cx, cam_cy,
// cam_width, cam_height: intrinsics) gives every row's observation its calibrated skeleton; the
// output then has two more columns, checked_3d and rejected_3d (0/1).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

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
  bool calibrated = false;  ///< rows carry the skeleton and the camera (kCalibratedColumns)
  bool pending = false;  ///< a row read but not yet observed (its t is later than the fusion time)
  gesture::ViewObservation row;
};

const std::vector<std::string>& calibratedColumns() {
  static const std::vector<std::string> columns = [] {
    std::vector<std::string> c;
    for (const char* p : {"x", "y", "c"}) {
      for (int k = 0; k < gesture::kNumKeypoints; ++k) c.push_back(p + std::to_string(k));
    }
    for (const char* n : {"cam_x", "cam_y", "cam_z", "cam_qw", "cam_qx", "cam_qy", "cam_qz", "cam_fx", "cam_fy", "cam_cx",
                          "cam_cy", "cam_width", "cam_height"}) {
      c.emplace_back(n);
    }
    return c;
  }();
  return columns;
}

// The current row's calibrated skeleton into f.row.calibrated (an error naming the field otherwise).
void readCalibrated(ViewFile& f) {
  common::CsvReader& in = *f.in;
  gesture::CalibratedSkeleton c;
  for (int k = 0; k < gesture::kNumKeypoints; ++k) {
    const auto i = static_cast<std::size_t>(k);
    c.skeleton.x[i] = in.number("x" + std::to_string(k));
    c.skeleton.y[i] = in.number("y" + std::to_string(k));
    c.skeleton.c[i] = in.number("c" + std::to_string(k));
  }
  c.p_world_camera = Eigen::Vector3d(in.number("cam_x"), in.number("cam_y"), in.number("cam_z"));
  const Eigen::Quaterniond q(in.number("cam_qw"), in.number("cam_qx"), in.number("cam_qy"), in.number("cam_qz"));
  if (in.error().empty() && !(std::abs(q.norm() - 1.0) <= 1e-6)) {
    in.fail("cam_qw", "the camera quaternion must have norm 1 (within 1e-6), got " + common::formatDouble(q.norm()));
  }
  c.R_world_camera = q.normalized().toRotationMatrix();
  c.intrinsics.fx = in.number("cam_fx");
  c.intrinsics.fy = in.number("cam_fy");
  c.intrinsics.cx = in.number("cam_cx");
  c.intrinsics.cy = in.number("cam_cy");
  const double w = in.number("cam_width"), h = in.number("cam_height");
  if (in.error().empty() && !(w >= 1 && w <= 1e5 && w == std::floor(w) && h >= 1 && h <= 1e5 && h == std::floor(h))) {
    in.fail("cam_width", "image size must be positive integers, got " + common::formatDouble(w) + " x " + common::formatDouble(h));
  }
  if (!in.error().empty()) return;
  c.intrinsics.width_px = static_cast<int>(w);
  c.intrinsics.height_px = static_cast<int>(h);
  const std::vector<std::string> problems = gesture::validate(c);
  if (!problems.empty()) {
    in.fail("cam_x", "calibrated skeleton: " + problems.front());
    return;
  }
  f.row.calibrated = std::move(c);
}

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
  f.row.calibrated.reset();
  if (f.calibrated && f.in->error().empty()) readCalibrated(f);
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
    if (files[i].in->column("cam_x") >= 0) {
      if (!files[i].in->requireColumns(calibratedColumns())) return badInput(args, files[i].in->error());
      files[i].calibrated = true;
    }
  }
  const bool any_calibrated = std::any_of(files.begin(), files.end(), [](const ViewFile& f) { return f.calibrated; });
  std::ofstream out(args.get("out"));
  if (!out) return badInput(args, args.get("out") + ": cannot open for writing");
  out << "t,gesture_id,voting_views,agreeing_views" << (any_calibrated ? ",checked_3d,rejected_3d" : "") << '\n';
  gesture::ViewFusion fusion(config, static_cast<int>(paths.size()), max_gesture_id);
  std::size_t rows = 0, fused_gestures = 0, rejected_3d = 0;
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
    out << common::formatDouble(t) << ',' << g.gesture_id << ',' << g.voting_views << ',' << g.agreeing_views;
    if (any_calibrated) out << ',' << (g.checked_3d ? 1 : 0) << ',' << (g.rejected_3d ? 1 : 0);
    out << '\n';
    ++rows;
    fused_gestures += g.gesture_id != 0 ? 1 : 0;
    rejected_3d += g.rejected_3d ? 1 : 0;
  }
  if (!lead.in->error().empty()) return badInput(args, lead.in->error());
  out.flush();
  if (!out) return badInput(args, args.get("out") + ": write failed");
  std::cout << "gfctl fuse-views: " << paths.size() << " views, " << rows << " rows, " << fused_gestures
            << " fused as a gesture" << (any_calibrated ? ", " + std::to_string(rejected_3d) + " rejected by the 3-D check" : "")
            << '\n';
  return kExitOk;
}

}  // namespace
}  // namespace gesture_formation::gfctl
