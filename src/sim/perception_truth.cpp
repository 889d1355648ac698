#include "gesture_formation/sim/perception_truth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "gesture_formation/common/csv.hpp"

namespace gesture_formation::sim {

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

double median(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return kNan;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string num(double v) { return std::isfinite(v) ? common::formatDouble(v) : std::string("null"); }

/// Frames in view within [lo, hi) of `key`, with their detection rate and medians.
PerceptionBin bin(const std::vector<PerceptionRecord>& records, double PerceptionRecord::*key, double lo, double hi,
                  std::string label) {
  PerceptionBin b;
  b.label = std::move(label);
  b.lo = lo;
  b.hi = hi;
  std::vector<double> px, frac, iou;
  for (const PerceptionRecord& r : records) {
    const double k = r.*key;
    if (!r.in_view || !(k >= lo && k < hi)) continue;
    ++b.frames;
    if (!r.detected) continue;
    ++b.detected;
    iou.push_back(r.iou);
    px.push_back(r.keypoint_error_px);
    frac.push_back(r.keypoint_error_fraction);
  }
  b.detection_rate = b.frames > 0 ? static_cast<double>(b.detected) / b.frames : kNan;
  b.keypoint_error_px_median = median(px);
  b.keypoint_error_fraction_median = median(frac);
  b.iou_median = median(iou);
  return b;
}

std::vector<PerceptionBin> bins(const std::vector<PerceptionRecord>& records, double PerceptionRecord::*key,
                                const std::vector<double>& edges) {
  std::vector<PerceptionBin> out;
  const double inf = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i <= edges.size(); ++i) {
    const double lo = i == 0 ? -inf : edges[i - 1];
    const double hi = i == edges.size() ? inf : edges[i];
    std::string label = i == 0 ? "<" + common::formatDouble(hi)
                               : (i == edges.size() ? ">=" + common::formatDouble(lo)
                                                    : common::formatDouble(lo) + "-" + common::formatDouble(hi));
    out.push_back(bin(records, key, lo, hi, std::move(label)));
  }
  return out;
}

}  // namespace

PerceptionSummary summarizePerception(const std::vector<PerceptionRecord>& records) {
  PerceptionSummary s;
  s.frames = static_cast<int>(records.size());
  std::vector<double> px, frac, iou, render, detect, track, skeleton, total;
  std::map<int, int> ids_per_uav;
  for (const PerceptionRecord& r : records) {
    if (r.in_view) ++s.frames_in_view;
    if (r.in_view && r.detected) {
      ++s.detected_in_view;
      px.push_back(r.keypoint_error_px);
      frac.push_back(r.keypoint_error_fraction);
      iou.push_back(r.iou);
    }
    if (!r.in_view && r.detected) ++s.detected_not_in_view;
    if (r.identity_started) ++ids_per_uav[r.uav];
    render.push_back(r.render_ms);
    if (r.detector_ran) detect.push_back(r.detect_ms);
    track.push_back(r.track_ms);
    if (r.detected) skeleton.push_back(r.skeleton_ms);
    total.push_back(r.render_ms + r.detect_ms + r.track_ms + r.skeleton_ms);
  }
  s.detection_rate = s.frames_in_view > 0 ? static_cast<double>(s.detected_in_view) / s.frames_in_view : kNan;
  s.keypoint_error_px_median = median(px);
  s.keypoint_error_fraction_median = median(frac);
  s.iou_median = median(iou);
  s.by_distance = bins(records, &PerceptionRecord::distance_m, {6.0, 9.0, 12.0});
  s.by_elevation = bins(records, &PerceptionRecord::elevation_deg, {15.0, 30.0, 45.0});
  for (const auto& [uav, n] : ids_per_uav) {
    s.identities += n;
    s.identity_switches += n - 1;
  }
  s.render_ms_median = median(render);
  s.detect_ms_median = median(detect);
  s.track_ms_median = median(track);
  s.skeleton_ms_median = median(skeleton);
  s.frame_ms_median = median(total);
  return s;
}

std::string perceptionJson(const PerceptionSummary& s, int indent) {
  const std::string in(static_cast<std::size_t>(indent), ' '), in2 = in + "  ", in3 = in2 + "  ";
  std::ostringstream os;
  const auto binList = [&](const std::vector<PerceptionBin>& bs) {
    os << "[";
    for (std::size_t i = 0; i < bs.size(); ++i) {
      const PerceptionBin& b = bs[i];
      os << (i ? ",\n" : "\n") << in3 << "{\"bin\": \"" << b.label << "\", \"frames\": " << b.frames
         << ", \"detected\": " << b.detected << ", \"detection_rate\": " << num(b.detection_rate)
         << ", \"keypoint_error_px_median\": " << num(b.keypoint_error_px_median)
         << ", \"keypoint_error_fraction_median\": " << num(b.keypoint_error_fraction_median)
         << ", \"iou_median\": " << num(b.iou_median) << "}";
    }
    os << "\n" << in2 << "]";
  };
  os << "{\n"
     << in2 << "\"frames\": " << s.frames << ",\n"
     << in2 << "\"frames_in_view\": " << s.frames_in_view << ",\n"
     << in2 << "\"detected_in_view\": " << s.detected_in_view << ",\n"
     << in2 << "\"detected_not_in_view\": " << s.detected_not_in_view << ",\n"
     << in2 << "\"detection_rate\": " << num(s.detection_rate) << ",\n"
     << in2 << "\"keypoint_error_px_median\": " << num(s.keypoint_error_px_median) << ",\n"
     << in2 << "\"keypoint_error_fraction_median\": " << num(s.keypoint_error_fraction_median) << ",\n"
     << in2 << "\"iou_median\": " << num(s.iou_median) << ",\n"
     << in2 << "\"by_distance_m\": ";
  binList(s.by_distance);
  os << ",\n" << in2 << "\"by_elevation_deg\": ";
  binList(s.by_elevation);
  os << ",\n"
     << in2 << "\"identities\": " << s.identities << ",\n"
     << in2 << "\"identity_switches\": " << s.identity_switches << ",\n"
     << in2 << "\"render_ms_median\": " << num(s.render_ms_median) << ",\n"
     << in2 << "\"detect_ms_median\": " << num(s.detect_ms_median) << ",\n"
     << in2 << "\"track_ms_median\": " << num(s.track_ms_median) << ",\n"
     << in2 << "\"skeleton_ms_median\": " << num(s.skeleton_ms_median) << ",\n"
     << in2 << "\"frame_ms_median\": " << num(s.frame_ms_median) << "\n"
     << in << "}";
  return os.str();
}

std::string perceptionCsv(const std::vector<PerceptionRecord>& records) {
  std::ostringstream os;
  os << "t,uav,distance_m,elevation_deg,truth_box_height_px,visible_pixels,in_view,detected,detector_ran,iou,"
        "keypoints_compared,keypoint_error_px,keypoint_error_fraction,track_id,identity_started,render_ms,detect_ms,"
        "track_ms,skeleton_ms\n";
  const auto f = [](double v) { return std::isfinite(v) ? common::formatDouble(v) : std::string(); };
  for (const PerceptionRecord& r : records) {
    os << f(r.t_s) << ',' << r.uav << ',' << f(r.distance_m) << ',' << f(r.elevation_deg) << ',' << r.truth_box_height_px
       << ',' << r.visible_pixels << ',' << (r.in_view ? 1 : 0) << ',' << (r.detected ? 1 : 0) << ','
       << (r.detector_ran ? 1 : 0) << ',' << f(r.iou) << ',' << r.keypoints_compared << ',' << f(r.keypoint_error_px)
       << ',' << f(r.keypoint_error_fraction) << ',' << r.track_id << ',' << (r.identity_started ? 1 : 0) << ','
       << f(r.render_ms) << ',' << f(r.detect_ms) << ',' << f(r.track_ms) << ',' << f(r.skeleton_ms) << '\n';
  }
  return os.str();
}

}  // namespace gesture_formation::sim
