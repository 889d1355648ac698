#include "gesture_formation/mapping/mapping_config.hpp"

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::mapping {

using common::Range;

const common::FieldTable<MappingConfig>& mappingConfigFields() {
  using C = MappingConfig;
  static const common::FieldTable<MappingConfig> t{{
      {"depth.pixel_stride", Range::closed(1, 64), [](C& c) { return &c.pixel_stride; }},
      {"depth.min_range_m", Range::positive(), [](C& c) { return &c.min_range_m; }},
      {"depth.max_range_m", Range::positive(), [](C& c) { return &c.max_range_m; }},
      {"octomap.prob_hit", Range{0.5, 1.0, false, false}, [](C& c) { return &c.prob_hit; }},
      {"octomap.prob_miss", Range{0.0, 0.5, false, false}, [](C& c) { return &c.prob_miss; }},
      {"octomap.clamping_min", Range{0.0, 0.5, false, false}, [](C& c) { return &c.clamping_min; }},
      {"octomap.clamping_max", Range{0.5, 1.0, false, false}, [](C& c) { return &c.clamping_max; }},
      {"field.range_m", Range::positive(), [](C& c) { return &c.field_range_m; }},
      {"seen.margin_m", Range::positive(), [](C& c) { return &c.seen.margin_m; }},
      {"seen.horizon_s", Range::positive(), [](C& c) { return &c.seen.horizon_s; }},
  }};
  return t;
}

namespace {

std::vector<common::ConfigError> problems(const MappingConfig& c) {
  std::vector<common::ConfigError> e = mappingConfigFields().rangeProblems(c);
  common::checkRule(e, c.max_range_m > c.min_range_m, "depth.max_range_m", c.max_range_m, "must be > depth.min_range_m");
  return e;
}

}  // namespace

std::vector<std::string> MappingConfig::validate(const std::string& prefix) const {
  return common::problemLines(problems(*this), prefix);
}

MappingConfig readMappingConfig(common::ConfigReader& reader, const std::string& prefix) {
  MappingConfig c;
  mappingConfigFields().readFields(reader, prefix, c);
  common::addProblems(reader, prefix, problems(c));
  return c;
}

}  // namespace gesture_formation::mapping
