#pragma once
/// \file
/// \brief Helpers shared by every network of the perception module: loading an ONNX file
/// into OpenCV DNN with a reason on failure, checking input images, letterboxing and
/// square warps between image pixels and a network input.

#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

#include "gesture_formation/common/result.hpp"

namespace gesture_formation::perception {

/// \brief Resolves a model path: absolute paths are kept, relative ones are taken relative
/// to `models_root` (normally `<source>/third_party_models`).
std::string resolveModelPath(const std::string& models_root, const std::string& path);

/// \brief Where OpenCV DNN runs a network (config key `dnn_device`): OpenCV's own backend on the
/// CPU (default) or through OpenCL (an integrated or discrete GPU), or the CUDA backend (a
/// Jetson's GPU; needs an OpenCV built with CUDA, which Debian's is not). *_fp16: half precision.
enum class DnnDevice { kCpu, kOpenCl, kOpenClFp16, kCuda, kCudaFp16 };
/// "cpu", "opencl", "opencl_fp16", "cuda", "cuda_fp16".
const char* toString(DnnDevice device);
/// \brief The device named `name`; a reason listing the names otherwise.
common::Result<DnnDevice> parseDnnDevice(const std::string& name);
/// \brief Empty when this OpenCV build can run networks on `device`; otherwise why, naming the
/// devices it can use (cv::dnn::getAvailableTargets).
std::string dnnDeviceProblem(DnnDevice device);

/// \brief Loads an ONNX file with `cv::dnn::readNetFromONNX` onto `device` and checks that the
/// network has every output named in `required_outputs`.
/// Fails with a reason naming the file for: missing/unreadable file, parse error (corrupt
/// file), missing outputs, a device this OpenCV cannot use. Never throws.
common::Result<cv::dnn::Net> loadOnnxModel(const std::string& path, const std::vector<std::string>& required_outputs,
                                           DnnDevice device = DnnDevice::kCpu);

/// \brief Empty when `image` is a non-empty 8-bit 3-channel (BGR) image; otherwise a reason
/// naming `what`, the channel count and depth found.
std::string checkBgrImage(const cv::Mat& image, const std::string& what = "image");

/// \brief Uniform scale + centred padding that maps an image into a square network input.
/// input = image · scale + (pad_x, pad_y)   [network-input px]
struct Letterbox {
  float scale = 1.0f;  ///< network px per image px
  float pad_x = 0.0f;  ///< [network-input px]
  float pad_y = 0.0f;  ///< [network-input px]

  cv::Point2f toImage(const cv::Point2f& p_input) const {
    return {(p_input.x - pad_x) / scale, (p_input.y - pad_y) / scale};
  }
};

/// \brief Letterboxes `image` into a `side`×`side` image (zero border, INTER_AREA when
/// shrinking, INTER_LINEAR when enlarging). Returns the mapping used.
Letterbox letterboxImage(const cv::Mat& image, int side, cv::Mat& out);

/// \brief Warps the rotated square `roi` (image px) to an `side`×`side` image (zero border
/// outside the image). A point (a, b) of the output maps back to the image as
/// centre + R(rotation) · ((a, b)/side − 0.5) · roi.side_px.
void warpSquare(const cv::Mat& image, const cv::Point2f& center_px, float roi_side_px, float rotation_rad, int side,
                cv::Mat& out);

/// \brief Maps a point of a `side`×`side` warp made by warpSquare back to image pixels.
cv::Point2f squareToImage(const cv::Point2f& p_input, const cv::Point2f& center_px, float roi_side_px,
                          float rotation_rad, int side);

}  // namespace gesture_formation::perception
