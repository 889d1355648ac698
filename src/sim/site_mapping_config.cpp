#include "gesture_formation/sim/site_mapping_config.hpp"

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::sim {

using common::Range;

const common::FieldTable<SiteMappingConfig>& siteMappingConfigFields() {
  using C = SiteMappingConfig;
  static const common::FieldTable<C> t{{
      {"rate_hz", Range::openClosed(0.0, 30.0), [](C& c) { return &c.rate_hz; }},
      {"camera_range_m", Range::closed(1.0, 100.0), [](C& c) { return &c.camera_range_m; }},
      {"travel_camera_hfov_deg", Range::closed(0.0, 120.0), [](C& c) { return &c.travel_camera_hfov_deg; }},
      {"travel_lookahead_s", Range::openClosed(0.0, 10.0), [](C& c) { return &c.travel_lookahead_s; }},
  }};
  return t;
}

std::vector<std::string> SiteMappingConfig::validate(const std::string& prefix) const {
  std::vector<std::string> e = common::problemLines(siteMappingConfigFields().rangeProblems(*this), prefix);
  for (auto& line : live.validate(prefix)) e.push_back(std::move(line));
  return e;
}

SiteMappingConfig readSiteMappingConfig(common::ConfigReader& reader, const std::string& prefix) {
  SiteMappingConfig c;
  if (reader.has(prefix + "enabled")) reader.readBool(prefix + "enabled", c.enabled);
  if (reader.has(prefix + "prior_map")) reader.readBool(prefix + "prior_map", c.prior_map);
  siteMappingConfigFields().readFields(reader, prefix, c);
  c.live = mapping::readMappingConfig(reader, prefix);
  return c;
}

}  // namespace gesture_formation::sim
