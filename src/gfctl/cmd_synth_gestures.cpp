// gfctl synth-gestures --seed S --count N --out DIR [--config FILE] [--views D1,D2,…]
// Writes DIR/skeletons.csv (docs/design.md §8.7 + label, sequence) and DIR/sequences.csv (what
// produced each sequence). Config keys: the fields of gesture::SynthConfig (all optional).
// --views: the same performances also seen by further cameras at these azimuth offsets [deg]
// from the primary one (the formation's followers, e.g. 60,-60): DIR/skeletons_view1.csv, …
// and DIR/sequences_view1.csv, … in the same layout; skeletons.csv is unchanged by it.
// sequences*.csv carry each view's nominal camera pose and intrinsics (cam_* columns, writeSequencesCsv).
#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <iostream>

#include <Eigen/Geometry>

#include "commands.hpp"
#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/gesture/skeleton_synth.hpp"
#include "gesture_formation/gesture/view_triangulation.hpp"

namespace gesture_formation::gfctl {
namespace {

int cmdSynthGestures(const Args& args);
const Registrar kRegistrar{"synth-gestures",
                           "--seed S --count N --out DIR [--config FILE] [--views D1,D2]   synthetic gesture/work-motion skeletons (docs/design.md §8.7)",
                           cmdSynthGestures};

bool readSynthConfig(const std::string& path, gesture::SynthConfig& c, std::string& report) {
  using common::ConfigReader;
  ConfigReader r = ConfigReader::fromFile(path, ConfigReader::MissingKeys::kUseDefaults);
  gesture::synthConfigFields().readFields(r, "", c);
  // The rules between fields (each interval's min <= max), always: a key outside its range was
  // reported while reading and kept its default, so these add only what is new.
  common::addProblems(r, "", gesture::synthConfigProblems(c));
  report = r.errorReport();
  return r.ok();
}

// What produced each sequence, with the camera's nominal pose in the body frame (x forward, y left,
// z up, feet at 0): gesture::cameraAround at the view's distance, elevation and azimuth aimed at
// 0.55 of the height — what the simulator's UAVs know of their cameras (sim::WorkerModel::calibrated);
// the generator's aim jitter (σ 3 % of the height) is the difference, a pose error of a few tenths of
// a degree. Columns cam_*: as `gfctl fuse-views` reads them.
bool writeSequencesCsv(const std::string& path, const std::vector<gesture::SynthSequence>& sequences,
                       const estimation::CameraIntrinsics& camera) {
  std::ofstream meta(path);
  meta << "sequence,motion,gesture_id,left_arm,height_m,distance_m,elevation_deg,azimuth_deg,frames,motion_start_s,"
          "motion_end_s,cam_x,cam_y,cam_z,cam_qw,cam_qx,cam_qy,cam_qz,cam_fx,cam_fy,cam_cx,cam_cy,cam_width,cam_height\n";
  const auto f = [](double v) { return common::formatDouble(v); };
  for (const auto& s : sequences) {
    const gesture::CalibratedSkeleton c =
        gesture::cameraAround(s.distance_m, s.elevation_deg, s.azimuth_deg, 0.55 * s.height_m, camera);
    const Eigen::Quaterniond q(c.R_world_camera);
    meta << s.id << ',' << gesture::toString(s.motion) << ',' << gesture::gestureIdOf(s.motion) << ',' << (s.left_arm ? 1 : 0)
         << ',' << f(s.height_m) << ',' << f(s.distance_m) << ',' << f(s.elevation_deg) << ',' << f(s.azimuth_deg) << ','
         << s.frames.size() << ',' << f(s.motion_start_s) << ',' << f(s.motion_end_s) << ',' << f(c.p_world_camera.x()) << ','
         << f(c.p_world_camera.y()) << ',' << f(c.p_world_camera.z()) << ',' << f(q.w()) << ',' << f(q.x()) << ',' << f(q.y())
         << ',' << f(q.z()) << ',' << f(camera.fx) << ',' << f(camera.fy) << ',' << f(camera.cx) << ',' << f(camera.cy) << ','
         << camera.width_px << ',' << camera.height_px << '\n';
  }
  meta.flush();
  return static_cast<bool>(meta);
}

int cmdSynthGestures(const Args& args) {
  if (!checkOptions(args, {"seed", "count", "out"}, {"config", "views"})) return kExitBadInput;
  const auto seed = common::parseDouble(args.get("seed"));
  const auto count = common::parseDouble(args.get("count"));
  if (!seed || *seed < 0 || *seed != static_cast<double>(static_cast<std::uint64_t>(*seed))) {
    return badInput(args, "--seed: expected a non-negative integer, got '" + args.get("seed") + "'");
  }
  if (!count || *count < 1 || *count > 1e6 || *count != static_cast<double>(static_cast<int>(*count))) {
    return badInput(args, "--count: expected an integer in [1, 1000000], got '" + args.get("count") + "'");
  }
  std::vector<double> offsets;
  if (args.has("views")) {
    const std::string list = args.get("views");
    for (const std::string& item : common::splitCsvLine(list)) {
      const auto v = common::parseDouble(item);
      if (!v || !std::isfinite(*v) || *v < -360.0 || *v > 360.0) {
        return badInput(args, "--views: expected comma-separated azimuth offsets in [-360, 360] deg, got '" + item + "' in '" +
                                  list + "'");
      }
      offsets.push_back(*v);
    }
    if (offsets.size() > 8) return badInput(args, "--views: at most 8 further views, got " + std::to_string(offsets.size()));
  }
  gesture::SynthConfig config;
  if (args.has("config")) {
    std::string report;
    if (!readSynthConfig(args.get("config"), config, report)) {
      std::cerr << "gfctl synth-gestures: invalid configuration:\n" << report;
      return kExitBadInput;
    }
  }
  const std::string dir = args.get("out");
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    return badInput(args, dir + ": cannot create directory: " + (ec ? ec.message() : std::string("not a directory")));
  }
  gesture::SkeletonSynthesizer synth(config, static_cast<std::uint64_t>(*seed));
  const std::size_t n_views = 1 + offsets.size();
  std::vector<std::vector<gesture::SynthSequence>> views(n_views);
  for (auto& v : views) v.reserve(static_cast<std::size_t>(*count));
  std::size_t frames = 0;
  for (int i = 0; i < static_cast<int>(*count); ++i) {
    if (offsets.empty()) {
      views[0].push_back(synth.next());
    } else {
      auto seqs = synth.nextViews(offsets);
      for (std::size_t v = 0; v < n_views; ++v) views[v].push_back(std::move(seqs[v]));
    }
    frames += views[0].back().frames.size();
  }
  for (std::size_t v = 0; v < n_views; ++v) {
    const std::string suffix = v == 0 ? "" : "_view" + std::to_string(v);
    std::string error;
    if (!gesture::writeSkeletonCsv(dir + "/skeletons" + suffix + ".csv", views[v], &error)) return badInput(args, error);
    const std::string meta_path = dir + "/sequences" + suffix + ".csv";
    if (!writeSequencesCsv(meta_path, views[v], config.camera)) return badInput(args, meta_path + ": write failed");
  }
  const auto& sequences = views[0];
  std::cout << "gfctl synth-gestures: " << sequences.size() << " sequences, " << frames << " frames → " << dir
            << "/skeletons.csv\n";
  return kExitOk;
}

}  // namespace
}  // namespace gesture_formation::gfctl
