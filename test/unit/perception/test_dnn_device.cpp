// The DNN device (dnn_model.hpp): names, the CPU always usable, and a device this OpenCV cannot
// use refused at creation with a reason that names it and what is usable instead.
#include <gtest/gtest.h>

#include <opencv2/dnn.hpp>

#include "gesture_formation/perception/dnn_model.hpp"
#include "gesture_formation/perception/perception_pipeline.hpp"
#include "perception_test_util.hpp"

namespace gesture_formation::perception {
namespace {

TEST(DnnDeviceTest, NamesRoundTripAndBadNamesAreListed) {
  for (const DnnDevice d : {DnnDevice::kCpu, DnnDevice::kOpenCl, DnnDevice::kOpenClFp16, DnnDevice::kCuda, DnnDevice::kCudaFp16}) {
    const auto parsed = parseDnnDevice(toString(d));
    ASSERT_TRUE(parsed) << parsed.reason();
    EXPECT_EQ(*parsed, d);
  }
  const auto bad = parseDnnDevice("gpu");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.reason().find("got 'gpu'"), std::string::npos) << bad.reason();
  EXPECT_NE(bad.reason().find("cuda_fp16"), std::string::npos) << bad.reason();
}

TEST(DnnDeviceTest, TheCpuIsAlwaysUsable) { EXPECT_EQ(dnnDeviceProblem(DnnDevice::kCpu), ""); }

TEST(DnnDeviceTest, AnUnusableDeviceIsRefusedByThePipelineNamingIt) {
  const std::vector<cv::dnn::Target> cuda = cv::dnn::getAvailableTargets(cv::dnn::DNN_BACKEND_CUDA);
  if (!cuda.empty()) GTEST_SKIP() << "this OpenCV runs CUDA: nothing to refuse here";
  PerceptionConfig cfg;
  cfg.models_root = test::modelsRoot();
  cfg.dnn_device = DnnDevice::kCuda;
  const auto problems = cfg.validate();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems.front().find("dnn_device 'cuda'"), std::string::npos) << problems.front();
  EXPECT_NE(problems.front().find("usable here: cpu"), std::string::npos) << problems.front();
  const auto p = PerceptionPipeline::create(cfg);
  ASSERT_FALSE(p);
  EXPECT_NE(p.reason().find("dnn_device 'cuda'"), std::string::npos) << p.reason();
}

// The default device gives the same network as before the setting existed (CPU, OpenCV backend).
TEST(DnnDeviceTest, TheCpuPipelineLoadsTheCommittedModels) {
  PerceptionConfig cfg;
  cfg.models_root = test::modelsRoot();
  cfg.dnn_device = DnnDevice::kCpu;
  const auto p = PerceptionPipeline::create(cfg);
  ASSERT_TRUE(p) << p.reason();
}

}  // namespace
}  // namespace gesture_formation::perception
