// gfctl classify --in skeletons.csv --out gestures.csv [--model FILE]   (docs/design.md §8.7)
// Buffers N = 9 frames per sequence (the optional `sequence` column; without it the whole
// file is one sequence) and writes t,gesture_id,p0..p4 for every row once the window is full.
// The optional `segment` column restarts the window within a sequence when it changes (as the
// perception pipeline's FIFO restarts when the worker is lost or another person is chosen:
// `gfctl render-gestures` writes it).
#include <cstdlib>
#include <fstream>
#include <iostream>

#include "commands.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/gesture/gesture_classifier.hpp"

namespace gesture_formation::gfctl {
namespace {

int cmdClassify(const Args& args);
const Registrar kRegistrar{"classify", "--in skeletons.csv --out gestures.csv [--model FILE]   gesture LSTM (docs/design.md §8.7)",
                           cmdClassify};

std::string defaultModel() {
  const char* env = std::getenv("GF_MODELS_DIR");
  return std::string(env ? env : GF_DEFAULT_MODELS_DIR) + "/gesture_lstm/gesture_lstm.onnx";
}

int cmdClassify(const Args& args) {
  if (!checkOptions(args, {"in", "out"}, {"model"})) return kExitBadInput;
  auto classifier = gesture::GestureClassifier::load(args.get("model", defaultModel()));
  if (!classifier) return badInput(args, classifier.reason());
  common::CsvReader in(args.get("in"));
  std::vector<std::string> columns = {"t", "u", "v", "w", "h"};
  for (int k = 0; k < gesture::kNumKeypoints; ++k) {
    for (const char* p : {"x", "y", "c"}) columns.push_back(p + std::to_string(k));
  }
  if (!in.requireColumns(columns)) return badInput(args, in.error());
  const bool has_sequence = in.column("sequence") >= 0;
  const bool has_segment = in.column("segment") >= 0;
  std::ofstream out(args.get("out"));
  if (!out) return badInput(args, args.get("out") + ": cannot open for writing");
  out << "t,gesture_id,p0,p1,p2,p3,p4\n";
  gesture::SkeletonWindow window;
  std::string current_sequence;
  std::size_t rows = 0, written = 0;
  std::array<std::size_t, gesture::kNumGestureClasses> counts{};
  while (in.next()) {
    ++rows;
    gesture::Skeleton2D s;
    const double t = in.number("t");
    s.u = in.number("u");
    s.v = in.number("v");
    s.w = in.number("w");
    s.h = in.number("h");
    for (int k = 0; k < gesture::kNumKeypoints; ++k) {
      const auto i = static_cast<std::size_t>(k);
      s.x[i] = in.number("x" + std::to_string(k));
      s.y[i] = in.number("y" + std::to_string(k));
      s.c[i] = in.number("c" + std::to_string(k));
      if (in.error().empty() && !(s.c[i] >= 0.0 && s.c[i] <= 1.0)) in.fail("c" + std::to_string(k), "confidence must be in [0, 1]");
      if (in.error().empty() && s.c[i] > 0.0 && !(std::isfinite(s.x[i]) && std::isfinite(s.y[i]))) {
        in.fail("x" + std::to_string(k), "a present keypoint needs finite coordinates");
      }
    }
    if (in.error().empty() && !(std::isfinite(t) && std::isfinite(s.u) && std::isfinite(s.v) && s.w > 0 && s.h > 0 &&
                                std::isfinite(s.w) && std::isfinite(s.h))) {
      in.fail("w", "the box must be finite with positive size");
    }
    if (!in.error().empty()) return badInput(args, in.error());
    std::string seq = has_sequence ? in.field(in.column("sequence")) : std::string();
    if (has_segment) seq += "/" + in.field(in.column("segment"));
    if (seq != current_sequence) {
      window.clear();
      current_sequence = seq;
    }
    window.push(s);
    if (!window.full()) continue;
    const auto c = classifier->classify(window);
    if (!c) return badInput(args, in.path() + ":" + std::to_string(in.lineNumber()) + ": " + c.reason());
    out << common::formatDouble(t) << ',' << c->gesture_id;
    for (float p : c->probabilities) out << ',' << common::formatDouble(p);
    out << '\n';
    ++written;
    ++counts[static_cast<std::size_t>(c->gesture_id)];
  }
  if (!in.error().empty()) return badInput(args, in.error());
  std::cout << "gfctl classify: " << rows << " rows, " << written << " classified (none " << counts[0] << ", cross "
            << counts[1] << ", side " << counts[2] << ", palms " << counts[3] << ", up " << counts[4] << ")\n";
  return kExitOk;
}

}  // namespace
}  // namespace gesture_formation::gfctl
