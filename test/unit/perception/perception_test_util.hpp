#pragma once
// Shared helpers of the perception unit tests: paths, raw float32 reference files, hand
// labels (test/data/perception/labels/person_boxes.csv) and Debian opencv-doc images.
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "gesture_formation/perception/types.hpp"

namespace gesture_formation::perception::test {

inline std::string sourceDir() { return GF_SOURCE_DIR; }
inline std::string modelsRoot() { return sourceDir() + "/third_party_models"; }
inline std::string dataDir() { return sourceDir() + "/test/data/perception"; }
/// Debian `opencv-doc` sample data (installed by tools/setup.sh).
inline std::string debianData() { return "/usr/share/doc/opencv-doc/examples/data"; }

inline bool fileExists(const std::string& path) { return static_cast<bool>(std::ifstream(path)); }

/// Raw little-endian float32 file → vector (empty if missing).
inline std::vector<float> readF32(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<float> v;
  if (!in) return v;
  in.seekg(0, std::ios::end);
  const auto n = static_cast<std::size_t>(in.tellg()) / sizeof(float);
  in.seekg(0);
  v.resize(n);
  in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(float)));
  return v;
}

/// Numeric CSV with a header row → rows of doubles (the first `skip_cols` text columns dropped).
inline std::vector<std::vector<double>> readNumericCsv(const std::string& path, std::size_t skip_cols = 0) {
  std::ifstream in(path);
  std::vector<std::vector<double>> rows;
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::stringstream ss(line);
    std::string f;
    std::vector<double> row;
    std::size_t col = 0;
    while (std::getline(ss, f, ',')) {
      if (col++ >= skip_cols) row.push_back(std::stod(f));
    }
    rows.push_back(row);
  }
  return rows;
}

struct LabelledBox {
  std::string source, person;
  int frame = 0;
  cv::Rect2f box;
};

/// Hand-labelled person boxes (test/data/perception/labels/README.md says how they were made).
inline std::vector<LabelledBox> labels() {
  std::ifstream in(dataDir() + "/labels/person_boxes.csv");
  std::vector<LabelledBox> out;
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::stringstream ss(line);
    std::string f[7];
    for (auto& x : f) std::getline(ss, x, ',');
    out.push_back({f[0], f[2], std::stoi(f[1]),
                   cv::Rect2f(std::stof(f[3]), std::stof(f[4]), std::stof(f[5]), std::stof(f[6]))});
  }
  return out;
}

inline cv::Rect2f label(const std::string& source, const std::string& person, int frame = 0) {
  for (const auto& l : labels()) {
    if (l.source == source && l.person == person && l.frame == frame) return l.box;
  }
  ADD_FAILURE() << "no label " << source << " " << person << " " << frame;
  return {};
}

/// Path of a real test image: astronaut.png is committed; the others come from opencv-doc.
inline std::string imagePath(const std::string& name) {
  return name == "astronaut.png" ? dataDir() + "/astronaut.png" : debianData() + "/" + name;
}

}  // namespace gesture_formation::perception::test

/// Skips the test when a Debian data file is absent (tools/setup.sh installs opencv-doc).
#define GF_REQUIRE_FILE(path)                                                                          \
  do {                                                                                                 \
    if (!::gesture_formation::perception::test::fileExists(path)) {                                    \
      GTEST_SKIP() << "missing " << (path) << " (Debian package opencv-doc; run tools/setup.sh)";      \
    }                                                                                                  \
  } while (0)
