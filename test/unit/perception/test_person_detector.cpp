// Person detectors on real photographs (Debian opencv-doc, scikit-image astronaut) against
// boxes labelled by hand (test/data/perception/labels/README.md), and bad input.
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "gesture_formation/perception/blazepose_detector.hpp"
#include "gesture_formation/perception/movenet_multipose_detector.hpp"
#include "gesture_formation/perception/perception_pipeline.hpp"
#include "perception_test_util.hpp"

namespace gesture_formation::perception {
namespace {

using test::imagePath;
using test::label;
using test::modelsRoot;

float bestIou(const std::vector<Detection>& dets, const cv::Rect2f& box) {
  float best = 0.0f;
  for (const auto& d : dets) best = std::max(best, iou(d.box_px, box));
  return best;
}

struct LabelledImage {
  const char* image;
  const char* person;
};

class PersonDetectorOnLabelledImages : public ::testing::TestWithParam<LabelledImage> {};

TEST_P(PersonDetectorOnLabelledImages, DetectionOverlapsHandLabel) {
  const std::string path = imagePath(GetParam().image);
  GF_REQUIRE_FILE(path);
  auto det = MoveNetMultiposeDetector::create({}, modelsRoot());
  ASSERT_TRUE(det) << det.reason();
  const cv::Mat img = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  auto r = (*det)->detect(img);
  ASSERT_TRUE(r) << r.reason();
  ASSERT_FALSE(r->empty());
  const cv::Rect2f truth = label(GetParam().image, GetParam().person);
  EXPECT_GE(bestIou(*r, truth), 0.5f) << GetParam().image << " " << GetParam().person;
  // The best-scoring detection is that person (one clearly dominant person per image).
  EXPECT_GE(iou((*r)[0].box_px, truth), 0.5f);
}

INSTANTIATE_TEST_SUITE_P(RealImages, PersonDetectorOnLabelledImages,
                         ::testing::Values(LabelledImage{"messi5.jpg", "messi"},
                                           LabelledImage{"basketball1.png", "left_man"},
                                           LabelledImage{"astronaut.png", "astronaut"}),
                         [](const auto& info) { return std::string(info.param.person); });

TEST(PersonDetectorTest, MultiposeFindsTheCutPersonOfBasketball) {
  const std::string path = imagePath("basketball1.png");
  GF_REQUIRE_FILE(path);
  auto det = MoveNetMultiposeDetector::create({}, modelsRoot());
  ASSERT_TRUE(det) << det.reason();
  auto r = (*det)->detect(cv::imread(path, cv::IMREAD_COLOR));
  ASSERT_TRUE(r) << r.reason();
  EXPECT_EQ(r->size(), 2u);
  // The right man is cut by the border and leans out of the frame: a looser overlap.
  EXPECT_GE(bestIou(*r, label("basketball1.png", "right_man_cut")), 0.4f);
}

TEST(PersonDetectorTest, MultiposeFindsSmallPedestriansOfVtest) {
  // vtest.avi frame 580 (768×576): several pedestrians 70–150 px tall.
  const std::string path = test::debianData() + "/vtest.avi";
  GF_REQUIRE_FILE(path);
  cv::VideoCapture cap(path);
  cv::Mat frame;
  for (int i = 0; i <= 580; ++i) ASSERT_TRUE(cap.read(frame));
  auto det = MoveNetMultiposeDetector::create({}, modelsRoot());
  ASSERT_TRUE(det) << det.reason();
  auto r = (*det)->detect(frame);
  ASSERT_TRUE(r) << r.reason();
  EXPECT_GE(r->size(), 2u);
  EXPECT_GE(bestIou(*r, label("vtest.avi", "blonde_woman", 580)), 0.5f);
}

TEST(PersonDetectorTest, BlazePoseBodyCentreInsideHandLabel) {
  // BlazePose detects the face + body keypoints; its box is the square around the body
  // circle, so only the hip centre and a coarse overlap are checked.
  for (const auto& [image, person] : {std::pair{"astronaut.png", "astronaut"}, std::pair{"messi5.jpg", "messi"}}) {
    const std::string path = imagePath(image);
    GF_REQUIRE_FILE(path);
    auto det = BlazePoseDetector::create({}, modelsRoot());
    ASSERT_TRUE(det) << det.reason();
    auto r = (*det)->detect(cv::imread(path, cv::IMREAD_COLOR));
    ASSERT_TRUE(r) << r.reason();
    ASSERT_FALSE(r->empty()) << image;
    const cv::Rect2f truth = label(image, person);
    // The hip centre lies inside the label, except for the astronaut whose photo ends at
    // the waist: her hip centre is extrapolated below the image, under her body.
    const cv::Point2f hip = (*r)[0].roi.center_px;
    EXPECT_GT(hip.x, truth.x) << image;
    EXPECT_LT(hip.x, truth.x + truth.width) << image;
    EXPECT_GT(hip.y, truth.y + truth.height / 2) << image;
    if (std::string(image) == "messi5.jpg") {
      EXPECT_TRUE(truth.contains(hip)) << hip;
    }
    EXPECT_GE(iou((*r)[0].box_px, truth), 0.3f) << image;
  }
}

TEST(PersonDetectorTest, BadImagesGiveReasons) {
  auto det = MoveNetMultiposeDetector::create({}, modelsRoot());
  ASSERT_TRUE(det) << det.reason();
  auto bp = BlazePoseDetector::create({}, modelsRoot());
  ASSERT_TRUE(bp) << bp.reason();
  for (PersonDetector* d : {static_cast<PersonDetector*>(det->get()), static_cast<PersonDetector*>(bp->get())}) {
    auto empty = d->detect(cv::Mat());
    ASSERT_FALSE(empty);
    EXPECT_NE(empty.reason().find("empty"), std::string::npos) << empty.reason();
    auto gray = d->detect(cv::Mat(64, 64, CV_8UC1, cv::Scalar(0)));
    ASSERT_FALSE(gray);
    EXPECT_NE(gray.reason().find("3 channels"), std::string::npos) << gray.reason();
    auto bgra = d->detect(cv::Mat(64, 64, CV_8UC4, cv::Scalar(0)));
    ASSERT_FALSE(bgra);
    EXPECT_NE(bgra.reason().find("got 4"), std::string::npos) << bgra.reason();
    auto f32 = d->detect(cv::Mat(64, 64, CV_32FC3, cv::Scalar(0)));
    ASSERT_FALSE(f32);
    EXPECT_NE(f32.reason().find("8-bit"), std::string::npos) << f32.reason();
  }
}

TEST(PersonDetectorTest, NobodyInAFlatImage) {
  auto det = MoveNetMultiposeDetector::create({}, modelsRoot());
  ASSERT_TRUE(det) << det.reason();
  auto r = (*det)->detect(cv::Mat(480, 640, CV_8UC3, cv::Scalar(90, 120, 90)));
  ASSERT_TRUE(r) << r.reason();
  EXPECT_TRUE(r->empty());
}

TEST(PersonDetectorTest, MissingCorruptOrWrongModelFileGivesReason) {
  MoveNetMultiposeConfig cfg;
  cfg.model_path = "/nonexistent/movenet.onnx";
  auto missing = MoveNetMultiposeDetector::create(cfg, modelsRoot());
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.reason().find("/nonexistent/movenet.onnx"), std::string::npos) << missing.reason();
  EXPECT_NE(missing.reason().find("missing"), std::string::npos) << missing.reason();

  const std::string corrupt = ::testing::TempDir() + "/gf_corrupt_model.onnx";
  {
    std::ofstream out(corrupt, std::ios::binary);
    out << "this is not a protobuf \x01\x02\x03 at all";
  }
  BlazePoseDetectorConfig bcfg;
  bcfg.model_path = corrupt;
  auto bad = BlazePoseDetector::create(bcfg, modelsRoot());
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.reason().find(corrupt), std::string::npos) << bad.reason();

  // Truncated real model: the first 100 kB of pose_detection.onnx.
  const std::string truncated = ::testing::TempDir() + "/gf_truncated_model.onnx";
  {
    std::ifstream in(modelsRoot() + "/blazepose_detector/pose_detection.onnx", std::ios::binary);
    std::vector<char> head(100000);
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    std::ofstream out(truncated, std::ios::binary);
    out.write(head.data(), in.gcount());
  }
  bcfg.model_path = truncated;
  auto trunc = BlazePoseDetector::create(bcfg, modelsRoot());
  ASSERT_FALSE(trunc);
  EXPECT_NE(trunc.reason().find(truncated), std::string::npos) << trunc.reason();

  // A valid ONNX file of another network: outputs do not match.
  cfg.model_path = "movenet_lightning/movenet_lightning.onnx";
  auto wrong = MoveNetMultiposeDetector::create(cfg, modelsRoot());
  ASSERT_FALSE(wrong);
  EXPECT_NE(wrong.reason().find("expected output"), std::string::npos) << wrong.reason();
}

TEST(PersonDetectorTest, ConfigValidateNamesTheField) {
  MoveNetMultiposeConfig m;
  m.min_person_score = 1.5f;
  ASSERT_EQ(m.validate().size(), 1u);
  EXPECT_NE(m.validate()[0].find("multipose.min_person_score"), std::string::npos);
  BlazePoseDetectorConfig b;
  b.nms_iou = 0.0f;
  b.max_detections = 0;
  EXPECT_EQ(b.validate().size(), 2u);
  auto r = BlazePoseDetector::create(b, modelsRoot());
  ASSERT_FALSE(r);
  EXPECT_NE(r.reason().find("blazepose_detector.nms_iou"), std::string::npos);
  PerceptionConfig p;
  p.fifo_frames = 0;
  p.tracker.detect_every_k = 0;
  EXPECT_EQ(p.validate().size(), 2u);
  EXPECT_TRUE(PerceptionConfig{}.validate().empty());
  EXPECT_FALSE(parseDetectorKind("yolo"));
  EXPECT_EQ(*parseDetectorKind("blazepose"), DetectorKind::kBlazePose);
}

}  // namespace
}  // namespace gesture_formation::perception
