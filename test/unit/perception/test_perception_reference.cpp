// OpenCV 4.6 DNN on the committed ONNX files vs the SOURCE framework's raw outputs
// (TFLite / TensorFlow, test/data/perception/*/ *.f32), and our C++ decoders vs the source
// graphs' own decoded outputs. Tolerances: test/data/perception/README.md.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "gesture_formation/perception/blazepose_detector.hpp"
#include "gesture_formation/perception/movenet_multipose_detector.hpp"
#include "gesture_formation/perception/skeleton_extractor.hpp"
#include "perception_test_util.hpp"

namespace gesture_formation::perception {
namespace {

using test::dataDir;
using test::modelsRoot;
using test::readF32;
using test::readNumericCsv;

/// max |a − ref| ≤ max(abs_tol, rel_tol · max |ref|) over all elements.
void expectClose(const cv::Mat& out, const std::string& ref_path, double abs_tol, double rel_tol) {
  const std::vector<float> ref = readF32(ref_path);
  ASSERT_FALSE(ref.empty()) << ref_path;
  ASSERT_EQ(out.total(), ref.size()) << ref_path;
  const float* a = out.ptr<float>();
  double max_diff = 0.0, max_ref = 0.0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    max_diff = std::max(max_diff, std::fabs(static_cast<double>(a[i]) - ref[i]));
    max_ref = std::max(max_ref, std::fabs(static_cast<double>(ref[i])));
  }
  const double tol = std::max(abs_tol, rel_tol * max_ref);
  EXPECT_LE(max_diff, tol) << ref_path << ": max |OpenCV − source| = " << max_diff << " (max |ref| " << max_ref << ")";
}

constexpr double kScoreTol = 1e-4;  // heatmaps, sigmoid scores
constexpr double kRegTol = 2e-3;    // regressions, landmarks [px], logits
constexpr double kRelTol = 1e-5;

TEST(PerceptionReferenceTest, BlazePoseAnchorsMatchMediaPipe) {
  const auto anchors = blazePoseAnchors();
  const auto ref = readNumericCsv(dataDir() + "/blazepose_detector/anchors.csv");
  ASSERT_EQ(anchors.size(), 2254u);
  ASSERT_EQ(ref.size(), anchors.size());
  for (std::size_t i = 0; i < ref.size(); ++i) {
    EXPECT_NEAR(anchors[i].x_center, ref[i][0], 1e-6) << i;
    EXPECT_NEAR(anchors[i].y_center, ref[i][1], 1e-6) << i;
    EXPECT_EQ(anchors[i].w, 1.0f);
    EXPECT_EQ(anchors[i].h, 1.0f);
  }
}

TEST(PerceptionReferenceTest, BlazePoseDecoderMatchesReferenceDetections) {
  // Decode the source framework's raw outputs with our C++ decoder: same anchors, same values.
  const auto reg = readF32(dataDir() + "/blazepose_detector/regressors.f32");
  const auto cls = readF32(dataDir() + "/blazepose_detector/classificators.f32");
  const auto ref = readNumericCsv(dataDir() + "/blazepose_detector/detections.csv");
  ASSERT_EQ(reg.size(), 2254u * 12u);
  ASSERT_EQ(cls.size(), 2254u);
  const auto dets = decodeBlazePose(reg.data(), cls.data(), blazePoseAnchors(), 0.5f);
  ASSERT_EQ(dets.size(), ref.size());
  for (std::size_t i = 0; i < ref.size(); ++i) {
    EXPECT_EQ(dets[i].anchor, static_cast<int>(ref[i][0]));
    EXPECT_NEAR(dets[i].score, ref[i][1], 1e-6);
    EXPECT_NEAR(dets[i].face_box.x, ref[i][2], 1e-6);
    EXPECT_NEAR(dets[i].face_box.y, ref[i][3], 1e-6);
    EXPECT_NEAR(dets[i].face_box.x + dets[i].face_box.width, ref[i][4], 1e-6);
    EXPECT_NEAR(dets[i].face_box.y + dets[i].face_box.height, ref[i][5], 1e-6);
    for (std::size_t k = 0; k < 4; ++k) {
      EXPECT_NEAR(dets[i].kp[k].x, ref[i][6 + 2 * k], 1e-6);
      EXPECT_NEAR(dets[i].kp[k].y, ref[i][7 + 2 * k], 1e-6);
    }
  }
  // Weighted NMS merges the overlapping face boxes of the one person into one detection.
  const auto merged = weightedNms(dets, 0.3f);
  ASSERT_GE(merged.size(), 1u);
  EXPECT_EQ(merged[0].anchor, 641);
  EXPECT_NEAR(merged[0].kp[0].x, 0.487, 0.01);
  EXPECT_NEAR(merged[0].kp[0].y, 0.60, 0.01);
}

TEST(PerceptionReferenceTest, BlazePoseDetectorOpenCvMatchesTflite) {
  auto det = BlazePoseDetector::create({}, modelsRoot());
  ASSERT_TRUE(det) << det.reason();
  const cv::Mat img = cv::imread(dataDir() + "/pose_det_224.png", cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  auto r = (*det)->detect(img);
  ASSERT_TRUE(r) << r.reason();
  const auto& out = (*det)->lastOutputs();
  expectClose(out[0], dataDir() + "/blazepose_detector/regressors.f32", kRegTol, kRelTol);
  expectClose(out[1], dataDir() + "/blazepose_detector/classificators.f32", kRegTol, kRelTol);
  // messi5 letterboxed: one person, hip centre at (0.487, 0.602)·224 of the 224 input.
  ASSERT_GE(r->size(), 1u);
  EXPECT_NEAR((*r)[0].roi.center_px.x, 0.487 * 224, 1.5);
  EXPECT_NEAR((*r)[0].roi.center_px.y, 0.602 * 224, 1.5);
}

TEST(PerceptionReferenceTest, BlazePoseLandmarkOpenCvMatchesTflite) {
  auto ext = BlazePoseLandmarkExtractor::create({}, modelsRoot());
  ASSERT_TRUE(ext) << ext.reason();
  const cv::Mat img = cv::imread(dataDir() + "/pose_crop_256.png", cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  auto r = (*ext)->runOnCrop(img);
  ASSERT_TRUE(r) << r.reason();
  const auto& out = (*ext)->lastOutputs();  // heatmap, landmarks, pose_flag, segmentation, world_landmarks
  const std::string d = dataDir() + "/blazepose_landmark_full/";
  expectClose(out[0], d + "heatmap.f32", kRegTol, kRelTol);
  expectClose(out[1], d + "landmarks.f32", kRegTol, kRelTol);
  expectClose(out[2], d + "pose_flag.f32", kScoreTol, 0.0);
  // Segmentation logits saturate in the background (|v| up to 1.7e3): relative 2e-4
  // (observed 0.22 absolute = 1.3e-4 relative; README "use relative for segmentation").
  expectClose(out[3], d + "segmentation.f32", kRegTol, 2e-4);
  expectClose(out[4], d + "world_landmarks.f32", kScoreTol, kRelTol);
}

TEST(PerceptionReferenceTest, MoveNetLightningOpenCvMatchesTensorflow) {
  auto ext = MoveNetLightningExtractor::create({}, modelsRoot());
  ASSERT_TRUE(ext) << ext.reason();
  const cv::Mat img = cv::imread(dataDir() + "/pose_crop_192.png", cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  auto kps = (*ext)->runOnCrop(img);
  ASSERT_TRUE(kps) << kps.reason();
  const auto& out = (*ext)->lastOutputs();  // center_weighted, kpt_heatmap, kpt_offset, kpt_regress
  const std::string d = dataDir() + "/movenet_lightning/";
  expectClose(out[0], d + "center_weighted.f32", kScoreTol, 0.0);
  expectClose(out[1], d + "kpt_heatmap.f32", kScoreTol, 0.0);
  expectClose(out[2], d + "kpt_offset.f32", kRegTol, kRelTol);
  expectClose(out[3], d + "kpt_regress.f32", kRegTol, kRelTol);
  const auto ref = readNumericCsv(d + "final.csv");
  ASSERT_EQ(ref.size(), 17u);
  for (std::size_t k = 0; k < 17; ++k) {
    for (std::size_t j = 0; j < 3; ++j) EXPECT_NEAR((*kps)[k][j], ref[k][j], 1e-4) << "keypoint " << k << " value " << j;
  }
}

TEST(PerceptionReferenceTest, MoveNetLightningDecoderOnSourceOutputsMatchesGraph) {
  const std::string d = dataDir() + "/movenet_lightning/";
  const auto heat = readF32(d + "kpt_heatmap.f32"), centre = readF32(d + "center_weighted.f32");
  const auto reg = readF32(d + "kpt_regress.f32"), off = readF32(d + "kpt_offset.f32");
  ASSERT_EQ(heat.size(), 17u * 48 * 48);
  LightningHeads h{heat.data(), centre.data(), reg.data(), off.data()};
  const auto kps = decodeLightning(h);
  const auto ref = readNumericCsv(d + "final.csv");
  for (std::size_t k = 0; k < 17; ++k) {
    for (std::size_t j = 0; j < 3; ++j) EXPECT_NEAR(kps[k][j], ref[k][j], 1e-5) << "keypoint " << k;
  }
}

void expectMultiposeMatches(const std::vector<MultiposeCandidate>& c, const std::vector<std::vector<double>>& ref,
                            double tol) {
  ASSERT_EQ(c.size(), 6u);
  ASSERT_EQ(ref.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    ASSERT_EQ(ref[i].size(), 56u);
    for (std::size_t k = 0; k < 17; ++k) {
      EXPECT_NEAR(c[i].y[k], ref[i][3 * k], tol) << "candidate " << i << " keypoint " << k;
      EXPECT_NEAR(c[i].x[k], ref[i][3 * k + 1], tol) << "candidate " << i << " keypoint " << k;
      EXPECT_NEAR(c[i].score[k], ref[i][3 * k + 2], tol) << "candidate " << i << " keypoint " << k;
    }
    EXPECT_NEAR(c[i].ymin, ref[i][51], tol);
    EXPECT_NEAR(c[i].xmin, ref[i][52], tol);
    EXPECT_NEAR(c[i].ymax, ref[i][53], tol);
    EXPECT_NEAR(c[i].xmax, ref[i][54], tol);
    EXPECT_NEAR(c[i].person_score, ref[i][55], tol) << "candidate " << i;
  }
}

TEST(PerceptionReferenceTest, MoveNetMultiposeDecoderOnSourceOutputsMatchesGraph) {
  const std::string d = dataDir() + "/movenet_multipose/";
  const auto ch = readF32(d + "center_heatmap.f32"), bs = readF32(d + "box_scale.f32"), bo = readF32(d + "box_offset.f32");
  const auto kh = readF32(d + "kpt_heatmap.f32"), kr = readF32(d + "kpt_regress.f32"), ko = readF32(d + "kpt_offset.f32");
  ASSERT_EQ(ch.size(), 64u * 64u);
  MultiposeHeads h{ch.data(), bs.data(), bo.data(), kh.data(), kr.data(), ko.data(), 64};
  expectMultiposeMatches(decodeMultipose(h), readNumericCsv(d + "final.csv"), 1e-5);
}

TEST(PerceptionReferenceTest, MoveNetMultiposeOpenCvMatchesTensorflow) {
  auto det = MoveNetMultiposeDetector::create({}, modelsRoot());
  ASSERT_TRUE(det) << det.reason();
  const cv::Mat img = cv::imread(dataDir() + "/multipose_256.png", cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  auto r = (*det)->detect(img);
  ASSERT_TRUE(r) << r.reason();
  const auto& out = (*det)->lastOutputs();  // box_offset, box_scale, center_heatmap, kpt_heatmap, kpt_offset, kpt_regress
  const std::string d = dataDir() + "/movenet_multipose/";
  expectClose(out[0], d + "box_offset.f32", kRegTol, kRelTol);
  expectClose(out[1], d + "box_scale.f32", kRegTol, kRelTol);
  expectClose(out[2], d + "center_heatmap.f32", kScoreTol, 0.0);
  expectClose(out[3], d + "kpt_heatmap.f32", kScoreTol, 0.0);
  expectClose(out[4], d + "kpt_offset.f32", kRegTol, kRelTol);
  expectClose(out[5], d + "kpt_regress.f32", kRegTol, kRelTol);
  MultiposeHeads h{out[2].ptr<float>(), out[1].ptr<float>(), out[0].ptr<float>(), out[3].ptr<float>(),
                   out[5].ptr<float>(), out[4].ptr<float>(), 64};
  expectMultiposeMatches(decodeMultipose(h), readNumericCsv(d + "final.csv"), 1e-4);
  // The two people of basketball1 (scores 0.67 and 0.29) are detected.
  ASSERT_EQ(r->size(), 2u);
  EXPECT_NEAR((*r)[0].score, 0.67, 0.01);
  EXPECT_NEAR((*r)[1].score, 0.29, 0.01);
}

}  // namespace
}  // namespace gesture_formation::perception
