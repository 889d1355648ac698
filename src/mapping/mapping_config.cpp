#include "gesture_formation/mapping/mapping_config.hpp"

#include <algorithm>
#include <cmath>

#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/mapping/map_delta.hpp"

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
      {"share.rate_hz", Range::openClosed(0.0, 10.0), [](C& c) { return &c.share.rate_hz; }},
      {"share.max_bytes_per_s", Range::closed(1000.0, 1e7), [](C& c) { return &c.share.max_bytes_per_s; }},
      {"share.max_age_s", Range::openClosed(0.0, 60.0), [](C& c) { return &c.share.max_age_s; }},
      {"share.refresh_share", Range::closed(0.0, 1.0), [](C& c) { return &c.share.refresh_share; }},
  }};
  return t;
}

namespace {

std::vector<common::ConfigError> problems(const MappingConfig& c) {
  std::vector<common::ConfigError> e = mappingConfigFields().rangeProblems(c);
  common::checkRule(e, c.max_range_m > c.min_range_m, "depth.max_range_m", c.max_range_m, "must be > depth.min_range_m");
  if (c.share.rate_hz > 0.0 && std::isfinite(c.share.max_bytes_per_s)) {
    common::checkRule(e, shareVoxelBudget(c.share) > 0, "share.max_bytes_per_s", c.share.max_bytes_per_s,
                      "must allow one voxel per update: ≥ share.rate_hz × " + std::to_string(mapUpdateWireBytes(1)) + " bytes");
  }
  return e;
}

}  // namespace

std::vector<std::string> MappingConfig::validate(const std::string& prefix) const {
  return common::problemLines(problems(*this), prefix);
}

std::size_t shareVoxelBudget(const ShareConfig& share) {
  if (!(share.rate_hz > 0.0) || !std::isfinite(share.max_bytes_per_s)) return 0;
  const double bytes = std::floor(share.max_bytes_per_s / share.rate_hz);
  const double fixed = static_cast<double>(mapUpdateWireBytes(0));
  if (bytes < fixed) return 0;
  const double voxels = std::floor((bytes - fixed) / static_cast<double>(kMapUpdateKeyBytes));
  return static_cast<std::size_t>(std::min(voxels, static_cast<double>(kMaxMapUpdateVoxels)));
}

MappingConfig readMappingConfig(common::ConfigReader& reader, const std::string& prefix) {
  MappingConfig c;
  if (reader.has(prefix + "share.enabled")) reader.readBool(prefix + "share.enabled", c.share.enabled);
  mappingConfigFields().readFields(reader, prefix, c);
  common::addProblems(reader, prefix, problems(c));
  return c;
}

}  // namespace gesture_formation::mapping
