// The YAML config loaders on arbitrary text: common::ConfigReader, then the estimator and
// formation readers (the files gfctl and the nodelets load), in both missing-key modes.
// Invariant: a config the reader accepted also validates.
#include <string>

#include "fuzz_common.hpp"
#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/estimation/estimator_config.hpp"
#include "gesture_formation/formation/formation_config.hpp"

using namespace gesture_formation;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const auto mode = (data[0] & 1) ? common::ConfigReader::MissingKeys::kError : common::ConfigReader::MissingKeys::kUseDefaults;
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  {
    common::ConfigReader reader = common::ConfigReader::fromString(text, "fuzz.yaml", mode);
    const estimation::EstimatorConfig c = estimation::readEstimatorConfig(reader);
    if (reader.ok()) GF_FUZZ_ASSERT(c.validate().empty());
    (void)reader.unusedKeys();
    (void)reader.errorReport();
  }
  {
    common::ConfigReader reader = common::ConfigReader::fromString(text, "fuzz.yaml", mode);
    const formation::FormationConfig c = formation::readFormationConfig(reader);
    if (reader.ok()) GF_FUZZ_ASSERT(c.validate().empty());
    (void)reader.unusedKeys();
    (void)reader.errorReport();
  }
  {
    // Generic reads with dotted/indexed keys a caller might use.
    common::ConfigReader reader = common::ConfigReader::fromString(text, "fuzz.yaml", mode);
    double d = 0;
    int i = 0;
    bool b = false;
    std::string s;
    std::vector<double> list;
    reader.readDouble("a.b", d, common::Range::positive());
    reader.readInt("followers[1].x", i, common::Range::closed(-5, 5));
    reader.readBool("flag", b);
    reader.readString("mode", s, {"constant", "motion"});
    reader.readDoubleList("camera.distortion", list, 0, 8, common::Range::any());
    (void)reader.has("leader.beta_deg");
    (void)reader.node("followers[0]");
    (void)reader.unusedKeys();
  }
  return 0;
}
