// gfctl synth-gestures --seed S --count N --out DIR [--config FILE] [--views D1,D2,…]
// Writes DIR/skeletons.csv (docs/design.md §8.7 + label, sequence) and DIR/sequences.csv (what
// produced each sequence). Config keys: the fields of gesture::SynthConfig (all optional).
// --views: the same performances also seen by further cameras at these azimuth offsets [deg]
// from the primary one (the formation's followers, e.g. 60,-60): DIR/skeletons_view1.csv, …
// and DIR/sequences_view1.csv, … in the same layout; skeletons.csv is unchanged by it.
#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <iostream>

#include "commands.hpp"
#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/gesture/skeleton_synth.hpp"

namespace gesture_formation::gfctl {
namespace {

int cmdSynthGestures(const Args& args);
const Registrar kRegistrar{"synth-gestures",
                           "--seed S --count N --out DIR [--config FILE] [--views D1,D2]   synthetic gesture/work-motion skeletons (docs/design.md §8.7)",
                           cmdSynthGestures};

/// Reads `<name>_min<unit>` and `<name>_max<unit>`, both within `range`.
void readInterval(common::ConfigReader& r, const std::string& name, const std::string& unit, double& min_value,
                  double& max_value, const common::Range& range) {
  r.readDouble(name + "_min" + unit, min_value, range);
  r.readDouble(name + "_max" + unit, max_value, range);
}

bool readSynthConfig(const std::string& path, gesture::SynthConfig& c, std::string& report) {
  using common::ConfigReader;
  using common::Range;
  ConfigReader r = ConfigReader::fromFile(path, ConfigReader::MissingKeys::kUseDefaults);
  r.readDouble("fps", c.fps, Range::openClosed(0, 120));
  readInterval(r, "height", "_m", c.height_min_m, c.height_max_m, Range::closed(1.0, 2.3));
  r.readDouble("proportion_jitter", c.proportion_jitter, Range::closed(0, 0.3));
  readInterval(r, "distance", "_m", c.distance_min_m, c.distance_max_m, Range::closed(1.5, 100));
  readInterval(r, "elevation", "_deg", c.elevation_min_deg, c.elevation_max_deg, Range::closed(-30, 80));
  readInterval(r, "azimuth", "_deg", c.azimuth_min_deg, c.azimuth_max_deg, Range::closed(-360, 360));
  readInterval(r, "tempo", "", c.tempo_min, c.tempo_max, Range::closed(0.1, 5));
  readInterval(r, "hold", "_s", c.hold_min_s, c.hold_max_s, Range::closed(0, 30));
  readInterval(r, "lead", "_s", c.lead_min_s, c.lead_max_s, Range::closed(0, 30));
  readInterval(r, "keypoint_noise", "", c.keypoint_noise_min, c.keypoint_noise_max, Range::closed(0, 0.2));
  r.readDouble("dropout_max", c.dropout_max, Range::closed(0, 0.9));
  r.readDouble("box_jitter", c.box_jitter, Range::closed(0, 0.3));
  r.readDouble("gesture_fraction", c.gesture_fraction, Range::closed(0, 1));
  for (const auto& e : c.validate()) r.addError("(ranges)", e);
  report = r.errorReport();
  return r.ok();
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
    std::ofstream meta(meta_path);
    meta << "sequence,motion,gesture_id,left_arm,height_m,distance_m,elevation_deg,azimuth_deg,frames,motion_start_s,motion_end_s\n";
    for (const auto& s : views[v]) {
      meta << s.id << ',' << gesture::toString(s.motion) << ',' << gesture::gestureIdOf(s.motion) << ',' << (s.left_arm ? 1 : 0)
           << ',' << common::formatDouble(s.height_m) << ',' << common::formatDouble(s.distance_m) << ','
           << common::formatDouble(s.elevation_deg) << ',' << common::formatDouble(s.azimuth_deg) << ',' << s.frames.size()
           << ',' << common::formatDouble(s.motion_start_s) << ',' << common::formatDouble(s.motion_end_s) << '\n';
    }
    meta.flush();
    if (!meta) return badInput(args, meta_path + ": write failed");
  }
  const auto& sequences = views[0];
  std::cout << "gfctl synth-gestures: " << sequences.size() << " sequences, " << frames << " frames → " << dir
            << "/skeletons.csv\n";
  return kExitOk;
}

}  // namespace
}  // namespace gesture_formation::gfctl
