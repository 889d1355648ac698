#pragma once
/// \file
/// \brief Reads YAML configuration and collects *every* problem at once.
///
/// Keys are dotted paths with optional list indices: `camera.fx`, `followers[1].beta_deg`.
/// Each `read*` call leaves the caller's value untouched unless the key is present and valid,
/// so the caller's initial value is the documented default. Missing keys are an error in
/// `MissingKeys::kError` mode (onboard nodelets: physical limits have no silent defaults) and
/// keep the default in `MissingKeys::kUseDefaults` mode (gfctl: design.md §8 "config files need
/// only the keys a subcommand uses"). Out-of-range or malformed values are always errors.
/// Thread safety: none; one reader per thread.

#include <functional>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace gesture_formation::common {

/// \brief An interval of allowed values for a numeric configuration key.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_inclusive = true;
  bool hi_inclusive = true;

  static Range any() { return Range{}; }
  static Range positive() { return Range{0.0, std::numeric_limits<double>::infinity(), false, true}; }
  static Range nonNegative() { return Range{0.0, std::numeric_limits<double>::infinity(), true, true}; }
  static Range closed(double lo, double hi) { return Range{lo, hi, true, true}; }
  static Range openClosed(double lo, double hi) { return Range{lo, hi, false, true}; }
  static Range atLeast(double lo) { return Range{lo, std::numeric_limits<double>::infinity(), true, true}; }

  /// True for finite values inside the interval.
  bool contains(double v) const;
  /// e.g. "(0, inf)" or "[-90, 90]".
  std::string describe() const;
};

/// \brief One configuration problem: the key it is about (dotted path, e.g.
/// "mission.faults.max_share_age_s"; empty: the document as a whole — unreadable, not YAML) and
/// what is wrong, naming the value.
struct ConfigError {
  std::string key;
  std::string message;
};

class ConfigReader {
 public:
  enum class MissingKeys { kUseDefaults, kError };

  /// Parses a YAML file. A file that cannot be read or parsed yields a reader whose
  /// errors() already names the problem (and whose reads all report "missing" quietly).
  static ConfigReader fromFile(const std::string& path, MissingKeys mode);
  static ConfigReader fromString(const std::string& yaml, const std::string& source_name, MissingKeys mode);

  bool has(const std::string& key) const;
  /// The node at `key` (an undefined node when absent). Marks the key as used.
  YAML::Node node(const std::string& key);

  void readDouble(const std::string& key, double& value, const Range& range);
  void readInt(const std::string& key, int& value, const Range& range);
  void readBool(const std::string& key, bool& value);
  /// `allowed` empty: any string.
  void readString(const std::string& key, std::string& value, const std::vector<std::string>& allowed = {});
  /// A YAML sequence of numbers with a length in [min_size, max_size], each in `element_range`.
  void readDoubleList(const std::string& key, std::vector<double>& value, std::size_t min_size,
                      std::size_t max_size, const Range& element_range);

  /// Records a problem found by the caller (e.g. a cross-field constraint).
  void addError(const std::string& key, const std::string& message);

  /// Every problem, typed (in the order found).
  const std::vector<ConfigError>& problems() const { return errors_; }
  /// Every problem as text: "<source>: <key>: <message>" ("<source>: <message>" without a key).
  std::vector<std::string> errors() const;
  bool ok() const { return errors_.empty(); }
  const std::string& source() const { return source_; }
  MissingKeys mode() const { return mode_; }

  /// Leaf keys present in the document under a top-level section that was read at least
  /// once, but never consumed — most likely typos. Sections never touched are ignored, so
  /// one file can hold the configuration of several components.
  std::vector<std::string> unusedKeys() const;
  /// Every leaf key of the document never consumed, whether or not its section was read (a
  /// document that is one component's configuration: withSubReader).
  std::vector<std::string> unusedKeysOfWholeDocument() const;

  /// All errors joined, one per line, each prefixed with the source name.
  std::string errorReport() const;

 private:
  ConfigReader(YAML::Node root, std::string source, MissingKeys mode);
  /// Looks the key up; reports a missing key according to the mode. Returns an undefined
  /// node if absent.
  YAML::Node lookup(const std::string& key, bool report_missing);
  void markUsed(const std::string& key);
  std::vector<std::string> unusedLeaves(bool whole_document) const;

  YAML::Node root_;
  std::string source_;
  MissingKeys mode_;
  bool parse_failed_ = false;
  std::vector<ConfigError> errors_;
  std::set<std::string> used_;
};

/// \brief Runs `fn` on a sub-reader over the node at `key` of `r` (a reader whose top level is
/// that node, for another module's loader) and copies its problems into `r`, each renamed
/// "<key>.<field>: message"; keys of the node `fn` did not read are reported as unknown.
void withSubReader(ConfigReader& r, const std::string& key, ConfigReader::MissingKeys mode,
                   const std::function<void(ConfigReader&)>& fn);

}  // namespace gesture_formation::common
