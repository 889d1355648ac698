// gfctl's CSV reader (common::CsvReader) on arbitrary file contents, read the way the
// estimate / formation-ref / gesture-filter / classify commands read their inputs.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "fuzz_common.hpp"
#include "gesture_formation/common/csv.hpp"

using namespace gesture_formation;

namespace {

const std::string& tempPath() {
  static const std::string path = "/tmp/gf_fuzz_csv_" + std::to_string(::getpid()) + ".csv";
  static const bool cleanup = (std::atexit([] { std::remove(tempPath().c_str()); }), true);
  (void)cleanup;
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = tempPath();
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (f == nullptr) return 0;
    if (size > 0) std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  static const std::vector<std::vector<std::string>> kSchemas = {
      {"t", "cam_x", "cam_y", "cam_z", "cam_qw", "cam_qx", "cam_qy", "cam_qz", "u", "v", "w", "h", "d_uwb", "d_stereo"},
      {"t", "hx", "hy", "hz", "h_heading"},
      {"t", "gesture_id"},
      {"x", "y", "z"},
  };
  for (const auto& schema : kSchemas) {
    common::CsvReader reader(path);
    if (!reader.error().empty()) continue;
    const bool have_all = reader.requireColumns(schema);
    int rows = 0;
    while (reader.next() && rows < 1000) {
      ++rows;
      GF_FUZZ_ASSERT(reader.fields().size() == reader.header().size());
      for (const std::string& name : schema) {
        if (reader.column(name) < 0) continue;
        (void)reader.field(reader.column(name));
        (void)reader.number(name, name == "u" || name == "d_uwb" || name == "d_stereo");
      }
    }
    (void)have_all;
    for (const std::string& field : common::splitCsvLine(std::string(reinterpret_cast<const char*>(data), size))) {
      (void)common::parseDouble(field);
    }
  }
  return 0;
}
