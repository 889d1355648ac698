// sim::summarizePerception / perceptionJson / perceptionCsv (docs/simulation.md §8): the
// metrics.json perception section from per-frame records with known values.
#include <gtest/gtest.h>

#include <cmath>

#include "gesture_formation/sim/mission_metrics.hpp"
#include "gesture_formation/sim/perception_truth.hpp"

namespace gf = gesture_formation;
using gf::sim::PerceptionRecord;

namespace {
PerceptionRecord rec(int uav, double d, double el, bool in_view, bool detected, double err_px, int id, bool started) {
  PerceptionRecord r;
  r.uav = uav;
  r.distance_m = d;
  r.elevation_deg = el;
  r.in_view = in_view;
  r.truth_box_height_px = in_view ? 100 : 0;
  r.detected = detected;
  r.iou = detected ? 0.8 : 0.0;
  r.keypoint_error_px = err_px;
  r.keypoint_error_fraction = err_px / 100.0;
  r.track_id = id;
  r.identity_started = started;
  r.render_ms = 10.0;
  r.track_ms = 2.0;
  r.skeleton_ms = detected ? 5.0 : 0.0;
  return r;
}
}  // namespace

TEST(PerceptionTruthTest, RatesBinsSwitchesAndTimes) {
  std::vector<PerceptionRecord> rs = {
      rec(0, 5.0, 10.0, true, true, 2.0, 0, true),     // <6 m, <15 deg
      rec(0, 7.0, 20.0, true, true, 4.0, 0, false),    // 6-9, 15-30
      rec(0, 7.5, 20.0, true, false, NAN, -1, false),  // 6-9 missed
      rec(0, 10.0, 35.0, true, true, 6.0, 1, true),    // 9-12, 30-45: a new id on UAV 0 → one switch
      rec(1, 13.0, 50.0, true, true, 8.0, 0, true),    // >=12, >=45: UAV 1's first id is no switch
      rec(1, 13.0, 50.0, false, false, NAN, -1, false),  // not in view: no figure counts it
      rec(2, 13.0, 50.0, false, true, NAN, 0, true),     // a detection with nothing in view
  };
  rs[0].detector_ran = true;
  rs[0].detect_ms = 30.0;
  const auto s = gf::sim::summarizePerception(rs);
  EXPECT_EQ(s.frames, 7);
  EXPECT_EQ(s.frames_in_view, 5);
  EXPECT_EQ(s.detected_in_view, 4);
  EXPECT_EQ(s.detected_not_in_view, 1);
  EXPECT_DOUBLE_EQ(s.detection_rate, 0.8);
  EXPECT_DOUBLE_EQ(s.keypoint_error_px_median, 5.0);  // of 2, 4, 6, 8
  EXPECT_DOUBLE_EQ(s.keypoint_error_fraction_median, 0.05);
  ASSERT_EQ(s.by_distance.size(), 4u);
  EXPECT_EQ(s.by_distance[0].label, "<6");
  EXPECT_EQ(s.by_distance[1].label, "6-9");
  EXPECT_EQ(s.by_distance[3].label, ">=12");
  EXPECT_EQ(s.by_distance[1].frames, 2);
  EXPECT_EQ(s.by_distance[1].detected, 1);
  EXPECT_DOUBLE_EQ(s.by_distance[1].detection_rate, 0.5);
  EXPECT_DOUBLE_EQ(s.by_distance[1].keypoint_error_px_median, 4.0);
  EXPECT_EQ(s.by_distance[3].frames, 1);
  ASSERT_EQ(s.by_elevation.size(), 4u);
  EXPECT_EQ(s.by_elevation[2].label, "30-45");
  EXPECT_EQ(s.by_elevation[2].frames, 1);
  EXPECT_DOUBLE_EQ(s.by_elevation[2].keypoint_error_px_median, 6.0);
  EXPECT_EQ(s.identities, 4);
  EXPECT_EQ(s.identity_switches, 1);
  EXPECT_DOUBLE_EQ(s.render_ms_median, 10.0);
  EXPECT_DOUBLE_EQ(s.detect_ms_median, 30.0);  // frames where the detector ran
  EXPECT_DOUBLE_EQ(s.skeleton_ms_median, 5.0);  // frames with a detection
}

TEST(PerceptionTruthTest, EmptyBinsAreNullInJsonAndTheSectionOnlyWithARenderedCamera) {
  const auto s = gf::sim::summarizePerception({rec(0, 7.0, 5.0, true, true, 3.0, 0, true)});
  EXPECT_TRUE(std::isnan(s.by_distance[0].detection_rate));
  const std::string js = gf::sim::perceptionJson(s);
  EXPECT_NE(js.find("{\"bin\": \"<6\", \"frames\": 0, \"detected\": 0, \"detection_rate\": null"), std::string::npos) << js;
  EXPECT_NE(js.find("\"identity_switches\": 0"), std::string::npos);
  gf::sim::MissionMetrics m;
  EXPECT_EQ(gf::sim::metricsJson(m).find("perception"), std::string::npos);  // synthetic camera: no section
  m.perception = s;
  const std::string full = gf::sim::metricsJson(m);
  EXPECT_NE(full.find("\"perception\": {"), std::string::npos);
  EXPECT_NE(full.find("\"perception.render_ms_median\""), std::string::npos);  // a wall-clock key
  const std::string csv = gf::sim::perceptionCsv({rec(0, 7.0, 5.0, true, false, NAN, -1, false)});
  EXPECT_EQ(csv.substr(0, 6), "t,uav,");
  EXPECT_NE(csv.find("\n0,0,7,5,100,0,1,0,0,0,0,,,-1,0,10,0,2,0\n"), std::string::npos) << csv;
}
