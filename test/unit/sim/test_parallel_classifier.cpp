// The mission's classifier on several threads (gfctl simulate --threads): classifyAll returns
// exactly what one network classifying the windows one by one returns, for any batch size and
// any thread count; bad thread counts are refused with the value named.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "gesture_formation/gesture/gesture_classifier.hpp"
#include "gesture_formation/gesture/skeleton_synth.hpp"
#include "gesture_formation/sim/leader_camera.hpp"

namespace gf = gesture_formation;

namespace {

const std::string kModel = std::string(GF_SOURCE_DIR) + "/third_party_models/gesture_lstm/gesture_lstm.onnx";

/// Full windows of synthetic sequences (gestures and work motions, random viewpoints): every
/// window position of `sequences` sequences.
std::vector<gf::gesture::SkeletonWindow> syntheticWindows(int sequences) {
  gf::gesture::SynthConfig cfg;
  gf::gesture::SkeletonSynthesizer synth(cfg, 20261202);
  std::vector<gf::gesture::SkeletonWindow> out;
  for (int s = 0; s < sequences; ++s) {
    gf::gesture::SkeletonWindow w;
    for (const auto& f : synth.next().frames) {
      w.push(f.skeleton);
      if (w.full()) out.push_back(w);
    }
  }
  return out;
}

}  // namespace

TEST(ParallelClassifierTest, ClassifyAllEqualsOneNetworkInOrderForAnyThreadCount) {
  const auto windows = syntheticWindows(12);
  ASSERT_GT(windows.size(), 200u);
  auto serial = gf::gesture::GestureClassifier::load(kModel);
  ASSERT_TRUE(serial) << serial.reason();
  std::vector<gf::gesture::Classification> expected;
  std::vector<int> per_class(gf::gesture::kNumGestureClasses, 0);
  for (const auto& w : windows) {
    auto c = serial->classify(w);
    ASSERT_TRUE(c) << c.reason();
    expected.push_back(*c);
    ++per_class[static_cast<std::size_t>(c->gesture_id)];
  }
  int classes_seen = 0;
  for (int n : per_class) classes_seen += n > 0 ? 1 : 0;
  EXPECT_GE(classes_seen, 3) << "the windows should exercise several classes";

  for (int threads : {1, 2, 3, 5}) {
    auto mc = gf::sim::loadOnnxClassifier(kModel, threads);
    ASSERT_TRUE(mc) << mc.reason();
    // Batches of 1..7 windows (a frame has one per UAV that sees the worker), consecutive.
    std::size_t next = 0;
    int batch = 1, compared = 0;
    while (next < windows.size()) {
      std::vector<const gf::gesture::SkeletonWindow*> ptrs;
      for (int i = 0; i < batch && next < windows.size(); ++i) ptrs.push_back(&windows[next++]);
      const auto got = (*mc)->classifyAll(ptrs);
      ASSERT_EQ(got.size(), ptrs.size());
      for (std::size_t i = 0; i < got.size(); ++i) {
        const std::size_t k = next - ptrs.size() + i;
        ASSERT_TRUE(got[i].has_value()) << "threads " << threads << " window " << k;
        EXPECT_EQ(got[i]->gesture_id, expected[k].gesture_id) << "threads " << threads << " window " << k;
        for (int c = 0; c < gf::gesture::kNumGestureClasses; ++c) {
          // Bitwise: the same network on the same input in the same order of operations.
          EXPECT_EQ(got[i]->probabilities[static_cast<std::size_t>(c)], expected[k].probabilities[static_cast<std::size_t>(c)])
              << "threads " << threads << " window " << k << " class " << c;
        }
        ++compared;
      }
      batch = batch % 7 + 1;
    }
    EXPECT_EQ(compared, static_cast<int>(windows.size()));
  }
}

TEST(ParallelClassifierTest, AWindowThatIsNotFullGivesNoClassificationAndLeavesTheOthers) {
  const auto windows = syntheticWindows(1);
  ASSERT_FALSE(windows.empty());
  gf::gesture::SkeletonWindow partial;
  partial.push(gf::gesture::Skeleton2D{});
  auto mc = gf::sim::loadOnnxClassifier(kModel, 3);
  ASSERT_TRUE(mc) << mc.reason();
  const auto got = (*mc)->classifyAll({&windows[0], &partial, &windows[0]});
  ASSERT_EQ(got.size(), 3u);
  EXPECT_TRUE(got[0].has_value());
  EXPECT_FALSE(got[1].has_value());
  ASSERT_TRUE(got[2].has_value());
  EXPECT_EQ(got[0]->probabilities, got[2]->probabilities);
}

TEST(ParallelClassifierTest, BadThreadCountsAreRefusedWithTheValue) {
  for (int threads : {0, -1, gf::sim::kMaxClassifierThreads + 1}) {
    auto mc = gf::sim::loadOnnxClassifier(kModel, threads);
    ASSERT_FALSE(mc) << threads;
    EXPECT_NE(mc.reason().find("threads"), std::string::npos) << mc.reason();
    EXPECT_NE(mc.reason().find(std::to_string(threads)), std::string::npos) << mc.reason();
  }
  auto missing = gf::sim::loadOnnxClassifier("/nonexistent/model.onnx", 2);
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.reason().find("/nonexistent/model.onnx"), std::string::npos) << missing.reason();
}

TEST(ParallelClassifierTest, ManyBatchesInARowGiveTheSameResultsWhoeverClaimsEachWindow) {
  // The mission's pattern: thousands of frames of up to three windows, one after another. The
  // threads claim windows as they come (a late worker finds its batch already done); every
  // result must still be the one network's, whichever thread classified it.
  const auto windows = syntheticWindows(3);
  ASSERT_GE(windows.size(), 30u);
  auto serial = gf::gesture::GestureClassifier::load(kModel);
  ASSERT_TRUE(serial) << serial.reason();
  std::vector<gf::gesture::Classification> expected;
  for (const auto& w : windows) {
    auto c = serial->classify(w);
    ASSERT_TRUE(c) << c.reason();
    expected.push_back(*c);
  }
  for (int threads : {2, 3}) {
    auto mc = gf::sim::loadOnnxClassifier(kModel, threads);
    ASSERT_TRUE(mc) << mc.reason();
    int mismatches = 0;
    for (int frame = 0; frame < 1500; ++frame) {
      const std::size_t n = 2 + static_cast<std::size_t>(frame % 2);  // 2 or 3 views
      std::vector<const gf::gesture::SkeletonWindow*> ptrs;
      std::vector<std::size_t> index;
      for (std::size_t v = 0; v < n; ++v) {
        index.push_back((static_cast<std::size_t>(frame) * 7 + v * 11) % windows.size());
        ptrs.push_back(&windows[index.back()]);
      }
      const auto got = (*mc)->classifyAll(ptrs);
      ASSERT_EQ(got.size(), n);
      for (std::size_t v = 0; v < n; ++v) {
        const auto& e = expected[index[v]];
        if (!got[v] || got[v]->gesture_id != e.gesture_id || got[v]->probabilities != e.probabilities) ++mismatches;
      }
    }
    EXPECT_EQ(mismatches, 0) << "threads " << threads;
  }
}
