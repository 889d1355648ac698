// gfctl detect --image FILE|--video FILE --out annotated.png|.mp4 --csv boxes_keypoints.csv
//              [--models DIR] [--max-frames N] [--detector movenet_multipose|blazepose]
//              [--skeleton movenet_lightning|blazepose_landmark] [--tracker kcf|csrt] [--detect-every K]
//              [--dnn-device cpu|opencl|opencl_fp16|cuda|cuda_fp16]
// Runs the perception pipeline (docs/perception.md) and writes the skeleton CSV of design.md §8.7.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "commands.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/perception/perception_pipeline.hpp"

namespace gesture_formation::gfctl {

namespace {

using namespace perception;

int cmdDetect(const Args& args);
const Registrar kRegistrar{
    "detect",
    "--image FILE|--video FILE --out annotated.png|.mp4 --csv boxes_keypoints.csv [--models DIR] [--max-frames N] "
    "[--detector movenet_multipose|blazepose] [--skeleton movenet_lightning|blazepose_landmark] [--tracker kcf|csrt] "
    "[--detect-every K] [--dnn-device cpu|opencl|opencl_fp16|cuda|cuda_fp16]   worker box + COCO-17 skeleton per frame (docs/design.md §8.7)",
    cmdDetect};

constexpr float kDrawMinConfidence = 0.3f;


cv::Point px(const Keypoint& k) { return {cvRound(k.x), cvRound(k.y)}; }

std::string lower(std::string s) {
  for (auto& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

bool parseInt(const std::string& text, int lo, int& value) {
  try {
    std::size_t pos = 0;
    const long v = std::stol(text, &pos);
    if (pos != text.size() || v < lo || v > 1000000000L) return false;
    value = static_cast<int>(v);
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

std::string fmt(double v, int decimals = 1) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(decimals);
  s << v;
  return s.str();
}

void drawFrame(cv::Mat& img, const PerceptionFrame& f, int frame_index) {
  const auto& t = f.track;
  for (std::size_t i = 0; i < t.detections.size(); ++i) {
    if (static_cast<int>(i) == t.worker_detection) continue;
    cv::rectangle(img, t.detections[i].box_px, cv::Scalar(160, 160, 160), 1);
    cv::putText(img, fmt(t.detections[i].score, 2), t.detections[i].box_px.tl() + cv::Point2f(1, -3),
                cv::FONT_HERSHEY_PLAIN, 0.9, cv::Scalar(160, 160, 160), 1);
  }
  if (t.found) {
    const cv::Scalar colour = t.source == BoxSource::kDetector ? cv::Scalar(0, 220, 0) : cv::Scalar(0, 200, 255);
    cv::rectangle(img, t.box_px, colour, 2);
    cv::putText(img, "worker id " + std::to_string(t.id) + " (" + toString(t.source) + ")",
                cv::Point2f(t.box_px.x, std::max(12.0f, t.box_px.y - 4.0f)), cv::FONT_HERSHEY_SIMPLEX, 0.45, colour, 1,
                cv::LINE_AA);
  }
  if (f.has_skeleton) {
    const auto& s = f.skeleton;
    for (const auto& [a, b] : cocoLimbs()) {
      const Keypoint& p = s[static_cast<std::size_t>(a)];
      const Keypoint& q = s[static_cast<std::size_t>(b)];
      if (p.c < kDrawMinConfidence || q.c < kDrawMinConfidence) continue;
      // person's left side blue-ish, right side red-ish, centre white
      const bool left = (a % 2 == 1) && (b % 2 == 1) && a > 0;
      const bool right = (a % 2 == 0) && (b % 2 == 0) && a > 0 && b > 0;
      const cv::Scalar c = left ? cv::Scalar(255, 120, 0) : right ? cv::Scalar(0, 0, 255) : cv::Scalar(255, 255, 255);
      cv::line(img, px(p), px(q), c, 2, cv::LINE_AA);
    }
    for (int k = 0; k < kNumKeypoints; ++k) {
      const Keypoint& p = s[static_cast<std::size_t>(k)];
      if (p.c < kDrawMinConfidence) continue;
      cv::circle(img, px(p), 3, k == 0 ? cv::Scalar(255, 255, 255) : (k % 2 ? cv::Scalar(255, 120, 0) : cv::Scalar(0, 0, 255)),
                 -1, cv::LINE_AA);
    }
  }
  const std::string line1 = "frame " + std::to_string(frame_index) + "  detect " + fmt(t.detect_ms) + " ms  track " +
                            fmt(t.track_ms) + " ms  skeleton " + fmt(f.skeleton_ms) + " ms  total " + fmt(f.total_ms) + " ms";
  cv::rectangle(img, cv::Rect(0, 0, img.cols, 18), cv::Scalar(0, 0, 0), -1);
  cv::putText(img, line1, {4, 13}, cv::FONT_HERSHEY_SIMPLEX, 0.42, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
}

void writeCsvRow(std::ostream& out, double t, const PerceptionFrame& f) {
  const auto& b = f.track.box_px;
  out << common::formatDouble(t) << ',' << common::formatDouble(b.x) << ',' << common::formatDouble(b.y) << ','
      << common::formatDouble(b.width) << ',' << common::formatDouble(b.height);
  for (const auto& k : f.skeleton) {
    const bool present = f.has_skeleton && k.c > 0.0f;
    out << ',' << common::formatDouble(present ? k.x : 0.0) << ',' << common::formatDouble(present ? k.y : 0.0) << ','
        << common::formatDouble(present ? k.c : 0.0);
  }
  out << '\n';
}

int cmdDetect(const Args& args) {
  if (!checkOptions(args, {"out", "csv"},
                    {"image", "video", "models", "max-frames", "detector", "skeleton", "tracker", "detect-every", "dnn-device"})) {
    return kExitBadInput;
  }
  if (args.has("image") == args.has("video")) return badInput(args, "give exactly one of --image FILE or --video FILE");
  const bool video = args.has("video");
  const std::string in_path = video ? args.get("video") : args.get("image");

  PerceptionConfig cfg;
  cfg.models_root = modelsRoot(args);
  if (args.has("detector")) {
    const auto k = parseDetectorKind(args.get("detector"));
    if (!k) return badInput(args, "--detector: " + k.reason());
    cfg.detector = *k;
  }
  if (args.has("skeleton")) {
    const auto k = parseSkeletonKind(args.get("skeleton"));
    if (!k) return badInput(args, "--skeleton: " + k.reason());
    cfg.skeleton = *k;
  }
  if (args.has("dnn-device")) {
    const auto d = parseDnnDevice(args.get("dnn-device"));
    if (!d) return badInput(args, "--dnn-device: " + d.reason());
    cfg.dnn_device = *d;
    if (const std::string p = dnnDeviceProblem(*d); !p.empty()) return badInput(args, "--dnn-device: " + p);
  }
  if (args.has("tracker")) {
    const auto k = parseTrackerKind(args.get("tracker"));
    if (!k) return badInput(args, "--tracker: " + k.reason());
    cfg.tracker.tracker = *k;
  }
  if (args.has("detect-every") && !parseInt(args.get("detect-every"), 1, cfg.tracker.detect_every_k)) {
    return badInput(args, "--detect-every: expected an integer >= 1, got '" + args.get("detect-every") + "'");
  }
  int max_frames = -1;
  if (args.has("max-frames") && !parseInt(args.get("max-frames"), 1, max_frames)) {
    return badInput(args, "--max-frames: expected an integer >= 1, got '" + args.get("max-frames") + "'");
  }
  const std::string out_path = args.get("out");
  const std::string out_ext = lower(out_path.substr(std::min(out_path.size(), out_path.rfind('.') == std::string::npos ? out_path.size() : out_path.rfind('.'))));
  if (!video && out_ext != ".png" && out_ext != ".jpg" && out_ext != ".jpeg") {
    return badInput(args, "--out " + out_path + ": an image needs a .png or .jpg output");
  }
  if (video && out_ext != ".mp4" && out_ext != ".avi") {
    return badInput(args, "--out " + out_path + ": a video needs a .mp4 or .avi output");
  }

  // Input first: a bad input file is reported before the models are loaded.
  cv::Mat image;
  cv::VideoCapture cap;
  double fps = 0.0;
  if (video) {
    if (!std::ifstream(in_path)) return badInput(args, in_path + ": cannot open video file");
    if (!cap.open(in_path) || !cap.isOpened()) return badInput(args, in_path + ": not a readable video");
    fps = cap.get(cv::CAP_PROP_FPS);
    if (!(fps > 0.0 && std::isfinite(fps))) {
      std::cerr << "gfctl detect: " << in_path << ": no frame rate in the file; assuming 30 frames/s\n";
      fps = 30.0;
    }
  } else {
    if (!std::ifstream(in_path)) return badInput(args, in_path + ": cannot open image file");
    image = cv::imread(in_path, cv::IMREAD_COLOR);
    if (image.empty()) return badInput(args, in_path + ": not a readable image");
  }

  auto pipeline = PerceptionPipeline::create(cfg);
  if (!pipeline) return badInput(args, pipeline.reason() + " (models root: --models " + cfg.models_root + ")");

  std::ofstream csv(args.get("csv"));
  if (!csv) return badInput(args, args.get("csv") + ": cannot open for writing");
  csv << "t,u,v,w,h";
  for (int k = 0; k < kNumKeypoints; ++k) csv << ",x" << k << ",y" << k << ",c" << k;
  csv << '\n';

  int frames = 0, found = 0;
  double sum_ms = 0.0;
  std::vector<double> total_ms;
  if (!video) {
    auto f = (*pipeline)->step(image);
    if (!f) return badInput(args, in_path + ": " + f.reason());
    frames = 1;
    if (f->track.found) {
      ++found;
      writeCsvRow(csv, 0.0, *f);
    }
    total_ms.push_back(f->total_ms);
    drawFrame(image, *f, 0);
    bool written = false;
    try {
      written = cv::imwrite(out_path, image);
    } catch (const cv::Exception&) {
      written = false;
    }
    if (!written) return badInput(args, out_path + ": cannot write image");
  } else {
    cv::VideoWriter writer;
    std::string written_path = out_path;
    cv::Mat frame;
    int index = 0;
    while ((max_frames < 0 || index < max_frames) && cap.read(frame)) {
      if (frame.empty()) break;
      if (!writer.isOpened()) {
        const int fourcc = out_ext == ".mp4" ? cv::VideoWriter::fourcc('m', 'p', '4', 'v') : cv::VideoWriter::fourcc('M', 'J', 'P', 'G');
        writer.open(written_path, fourcc, fps, frame.size());
        if (!writer.isOpened() && out_ext == ".mp4") {
          written_path = out_path.substr(0, out_path.size() - 4) + ".avi";
          std::cerr << "gfctl detect: cannot write " << out_path << " with fourcc mp4v; writing " << written_path
                    << " (MJPG) instead\n";
          writer.open(written_path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps, frame.size());
        }
        if (!writer.isOpened()) return badInput(args, written_path + ": cannot open a video writer");
      }
      auto f = (*pipeline)->step(frame);
      if (!f) return badInput(args, in_path + ": frame " + std::to_string(index) + ": " + f.reason());
      if (f->track.found) {
        ++found;
        writeCsvRow(csv, static_cast<double>(index) / fps, *f);
      }
      total_ms.push_back(f->total_ms);
      drawFrame(frame, *f, index);
      writer.write(frame);
      ++index;
    }
    frames = index;
    if (frames == 0) return badInput(args, in_path + ": no frame could be read");
  }
  csv.flush();
  if (!csv) return badInput(args, args.get("csv") + ": write failed");
  for (double v : total_ms) sum_ms += v;
  std::vector<double> sorted = total_ms;
  std::sort(sorted.begin(), sorted.end());
  const auto& c = (*pipeline)->tracker().counters();
  std::cout << "gfctl detect: " << frames << " frames, worker found in " << found << "; detector runs "
            << c.detections_run << ", tracker failures " << c.tracker_failures << ", drifts " << c.drifts
            << ", identities " << c.identities << ", lost " << c.lost << "; per frame median "
            << fmt(sorted[sorted.size() / 2]) << " ms, mean " << fmt(sum_ms / static_cast<double>(frames)) << " ms ("
            << (*pipeline)->tracker().detector().name() << " + " << toString(cfg.tracker.tracker) << " + "
            << (*pipeline)->skeletonExtractor().name() << "; models " << cfg.models_root << ")\n";
  return kExitOk;
}

}  // namespace

std::string modelsRoot(const Args& args) {
  if (args.has("models")) return args.get("models");
  const char* env = std::getenv("GF_MODELS_DIR");
  if (env != nullptr && *env != '\0') return env;
  // An installed gfctl (<prefix>/lib/gesture_formation/gfctl) uses its package's share directory,
  // whether or not the source tree it was built from still exists.
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const auto share = exe.parent_path().parent_path().parent_path() / "share" / "gesture_formation" / "third_party_models";
    if (std::filesystem::is_directory(share, ec)) return share.string();
  }
#ifdef GF_DEFAULT_MODELS_DIR
  return GF_DEFAULT_MODELS_DIR;
#else
  return "third_party_models";
#endif
}

}  // namespace gesture_formation::gfctl
