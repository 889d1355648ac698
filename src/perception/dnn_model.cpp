#include "gesture_formation/perception/dnn_model.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <opencv2/imgproc.hpp>

namespace gesture_formation::perception {

std::string resolveModelPath(const std::string& models_root, const std::string& path) {
  if (path.empty() || path.front() == '/' || models_root.empty()) return path;
  return models_root.back() == '/' ? models_root + path : models_root + "/" + path;
}

namespace {

struct DeviceSpec {
  DnnDevice device;
  const char* name;
  cv::dnn::Backend backend;
  cv::dnn::Target target;
};

constexpr DeviceSpec kDevices[] = {
    {DnnDevice::kCpu, "cpu", cv::dnn::DNN_BACKEND_OPENCV, cv::dnn::DNN_TARGET_CPU},
    {DnnDevice::kOpenCl, "opencl", cv::dnn::DNN_BACKEND_OPENCV, cv::dnn::DNN_TARGET_OPENCL},
    {DnnDevice::kOpenClFp16, "opencl_fp16", cv::dnn::DNN_BACKEND_OPENCV, cv::dnn::DNN_TARGET_OPENCL_FP16},
    {DnnDevice::kCuda, "cuda", cv::dnn::DNN_BACKEND_CUDA, cv::dnn::DNN_TARGET_CUDA},
    {DnnDevice::kCudaFp16, "cuda_fp16", cv::dnn::DNN_BACKEND_CUDA, cv::dnn::DNN_TARGET_CUDA_FP16},
};

const DeviceSpec& specOf(DnnDevice device) {
  for (const auto& d : kDevices) {
    if (d.device == device) return d;
  }
  return kDevices[0];
}

bool available(const DeviceSpec& d) {
  try {
    const std::vector<cv::dnn::Target> targets = cv::dnn::getAvailableTargets(d.backend);
    return std::find(targets.begin(), targets.end(), d.target) != targets.end();
  } catch (const cv::Exception&) {
    return false;
  }
}

}  // namespace

const char* toString(DnnDevice device) { return specOf(device).name; }

common::Result<DnnDevice> parseDnnDevice(const std::string& name) {
  std::string names;
  for (const auto& d : kDevices) {
    if (name == d.name) return common::Result<DnnDevice>::ok(d.device);
    names += (names.empty() ? "" : ", ") + std::string(d.name);
  }
  return common::Result<DnnDevice>::fail("dnn_device must be one of " + names + ", got '" + name + "'");
}

std::string dnnDeviceProblem(DnnDevice device) {
  const DeviceSpec& spec = specOf(device);
  if (available(spec)) return {};
  std::string usable;
  for (const auto& d : kDevices) {
    if (available(d)) usable += (usable.empty() ? "" : ", ") + std::string(d.name);
  }
  return std::string("dnn_device '") + spec.name + "': this OpenCV (" + CV_VERSION + ") cannot run networks there" +
         (device == DnnDevice::kCuda || device == DnnDevice::kCudaFp16 ? " (it was built without CUDA)" : "") +
         "; usable here: " + (usable.empty() ? "none" : usable);
}

common::Result<cv::dnn::Net> loadOnnxModel(const std::string& path, const std::vector<std::string>& required_outputs,
                                           DnnDevice device) {
  using R = common::Result<cv::dnn::Net>;
  const std::string device_problem = dnnDeviceProblem(device);
  if (!device_problem.empty()) return R::fail(path + ": " + device_problem);
  std::ifstream probe(path, std::ios::binary);
  if (!probe) return R::fail(path + ": model file missing or unreadable");
  probe.seekg(0, std::ios::end);
  if (probe.tellg() <= 0) return R::fail(path + ": model file is empty");
  probe.close();
  cv::dnn::Net net;
  try {
    net = cv::dnn::readNetFromONNX(path);
  } catch (const cv::Exception& e) {
    return R::fail(path + ": not a loadable ONNX model (corrupt or unsupported): " + e.msg);
  } catch (const std::exception& e) {
    return R::fail(path + ": not a loadable ONNX model: " + e.what());
  }
  if (net.empty()) return R::fail(path + ": ONNX model loaded as an empty network");
  net.setPreferableBackend(specOf(device).backend);
  net.setPreferableTarget(specOf(device).target);
  const std::vector<std::string> outs = net.getUnconnectedOutLayersNames();
  std::string missing;
  for (const auto& name : required_outputs) {
    if (std::find(outs.begin(), outs.end(), name) == outs.end()) missing += (missing.empty() ? "" : ", ") + name;
  }
  if (!missing.empty()) return R::fail(path + ": model lacks the expected output(s) " + missing + " (wrong file?)");
  return R::ok(std::move(net));
}

std::string checkBgrImage(const cv::Mat& image, const std::string& what) {
  if (image.empty()) return what + " is empty";
  if (image.dims != 2) return what + " must be a 2-D image, got " + std::to_string(image.dims) + " dimensions";
  if (image.depth() != CV_8U) {
    return what + " must be 8-bit (CV_8U), got depth " + std::to_string(image.depth()) + " (" +
           cv::typeToString(image.type()) + ")";
  }
  if (image.channels() != 3) {
    return what + " must have 3 channels (BGR), got " + std::to_string(image.channels());
  }
  return {};
}

Letterbox letterboxImage(const cv::Mat& image, int side, cv::Mat& out) {
  Letterbox lb;
  lb.scale = static_cast<float>(side) / static_cast<float>(std::max(image.cols, image.rows));
  const int w = std::max(1, static_cast<int>(std::lround(image.cols * lb.scale)));
  const int h = std::max(1, static_cast<int>(std::lround(image.rows * lb.scale)));
  const int px = (side - w) / 2, py = (side - h) / 2;
  lb.pad_x = static_cast<float>(px);
  lb.pad_y = static_cast<float>(py);
  out.create(side, side, image.type());
  out.setTo(cv::Scalar::all(0));
  cv::Mat roi = out(cv::Rect(px, py, w, h));
  cv::resize(image, roi, cv::Size(w, h), 0, 0, lb.scale < 1.0f ? cv::INTER_AREA : cv::INTER_LINEAR);
  return lb;
}

namespace {
// Affine map from the side×side output to the image: p_img = A · [a, b, 1].
cv::Matx23d squareToImageAffine(const cv::Point2f& c, float roi_side, float rot, int side) {
  const double s = static_cast<double>(roi_side) / side;
  const double cr = std::cos(rot), sr = std::sin(rot);
  // p = c + R · ((a, b) − side/2) · s
  const double h = 0.5 * side;
  return cv::Matx23d(cr * s, -sr * s, c.x - (cr * h - sr * h) * s,  //
                     sr * s, cr * s, c.y - (sr * h + cr * h) * s);
}
}  // namespace

void warpSquare(const cv::Mat& image, const cv::Point2f& center_px, float roi_side_px, float rotation_rad, int side,
                cv::Mat& out) {
  const cv::Matx23d a = squareToImageAffine(center_px, roi_side_px, rotation_rad, side);
  cv::warpAffine(image, out, a, cv::Size(side, side), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT,
                 cv::Scalar::all(0));
}

cv::Point2f squareToImage(const cv::Point2f& p, const cv::Point2f& center_px, float roi_side_px, float rotation_rad,
                          int side) {
  const cv::Matx23d a = squareToImageAffine(center_px, roi_side_px, rotation_rad, side);
  return {static_cast<float>(a(0, 0) * p.x + a(0, 1) * p.y + a(0, 2)),
          static_cast<float>(a(1, 0) * p.x + a(1, 1) * p.y + a(1, 2))};
}

}  // namespace gesture_formation::perception
