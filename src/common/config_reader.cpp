#include "gesture_formation/common/config_reader.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "gesture_formation/common/format_number.hpp"

namespace gesture_formation::common {

namespace {

/// Splits "a.b[2].c" into {"a", "b", "[2]", "c"}.
std::vector<std::string> splitPath(const std::string& key) {
  std::vector<std::string> parts;
  std::string cur;
  for (std::size_t i = 0; i < key.size(); ++i) {
    const char c = key[i];
    if (c == '.') {
      if (!cur.empty()) parts.push_back(cur);
      cur.clear();
    } else if (c == '[') {
      if (!cur.empty()) parts.push_back(cur);
      cur = "[";
    } else if (c == ']') {
      cur += ']';
      parts.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) parts.push_back(cur);
  return parts;
}

bool parseStrictDouble(const std::string& s, double& out) {
  if (s.empty()) return false;
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return end != nullptr && *end == '\0';
}

void collectLeaves(const YAML::Node& node, const std::string& prefix, std::vector<std::string>& out) {
  if (node.IsMap()) {
    for (const auto& kv : node) {
      // A key that is not a scalar (YAML allows `{a: 1}: x` or `[1, 2]: x`) has no dotted
      // name: it is reported as unknown under a placeholder instead of throwing.
      const std::string k = kv.first.IsScalar() ? kv.first.Scalar() : std::string("<non-scalar key>");
      collectLeaves(kv.second, prefix.empty() ? k : prefix + "." + k, out);
    }
  } else if (node.IsSequence()) {
    bool scalars = true;
    for (const auto& item : node) scalars = scalars && item.IsScalar();
    if (scalars) {
      out.push_back(prefix);
      return;
    }
    for (std::size_t i = 0; i < node.size(); ++i) collectLeaves(node[i], prefix + "[" + std::to_string(i) + "]", out);
  } else {
    out.push_back(prefix);
  }
}

std::string topSection(const std::string& key) {
  const auto pos = key.find_first_of(".[");
  return pos == std::string::npos ? key : key.substr(0, pos);
}

}  // namespace

bool Range::contains(double v) const {
  if (!std::isfinite(v)) return false;
  if (lo_inclusive ? v < lo : v <= lo) return false;
  if (hi_inclusive ? v > hi : v >= hi) return false;
  return true;
}

std::string Range::describe() const {
  std::string s = lo_inclusive && std::isfinite(lo) ? "[" : "(";
  s += std::isfinite(lo) ? formatNumber(lo) : "-inf";
  s += ", ";
  s += std::isfinite(hi) ? formatNumber(hi) : "inf";
  s += hi_inclusive && std::isfinite(hi) ? "]" : ")";
  return s;
}

ConfigReader::ConfigReader(YAML::Node root, std::string source, MissingKeys mode)
    : root_(std::move(root)), source_(std::move(source)), mode_(mode) {}

ConfigReader ConfigReader::fromFile(const std::string& path, MissingKeys mode) {
  try {
    ConfigReader reader(YAML::LoadFile(path), path, mode);
    if (!reader.root_.IsMap() && !reader.root_.IsNull()) {
      reader.parse_failed_ = true;
      reader.errors_.push_back({"", "the top level must be a mapping of keys"});
    }
    if (reader.root_.IsNull()) reader.root_ = YAML::Node(YAML::NodeType::Map);
    return reader;
  } catch (const YAML::BadFile&) {
    ConfigReader reader(YAML::Node(YAML::NodeType::Map), path, mode);
    reader.parse_failed_ = true;
    reader.errors_.push_back({"", "cannot open file"});
    return reader;
  } catch (const YAML::Exception& e) {
    ConfigReader reader(YAML::Node(YAML::NodeType::Map), path, mode);
    reader.parse_failed_ = true;
    reader.errors_.push_back({"", "line " + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg});
    return reader;
  }
}

ConfigReader ConfigReader::fromString(const std::string& yaml, const std::string& source_name, MissingKeys mode) {
  try {
    ConfigReader reader(YAML::Load(yaml), source_name, mode);
    if (!reader.root_.IsMap() && !reader.root_.IsNull()) {
      reader.parse_failed_ = true;
      reader.errors_.push_back({"", "the top level must be a mapping of keys"});
    }
    if (reader.root_.IsNull()) reader.root_ = YAML::Node(YAML::NodeType::Map);
    return reader;
  } catch (const YAML::Exception& e) {
    ConfigReader reader(YAML::Node(YAML::NodeType::Map), source_name, mode);
    reader.parse_failed_ = true;
    reader.errors_.push_back({"", "line " + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg});
    return reader;
  }
}

YAML::Node ConfigReader::lookup(const std::string& key, bool report_missing) {
  // Walk with const nodes and rebind with reset(): yaml-cpp's non-const operator[] inserts
  // and its operator= assigns through aliases.
  YAML::Node walk;
  walk.reset(root_);
  for (const std::string& part : splitPath(key)) {
    const YAML::Node parent = walk;
    YAML::Node next(YAML::NodeType::Undefined);
    if (part.front() == '[') {
      const std::size_t idx = std::strtoul(part.c_str() + 1, nullptr, 10);
      if (parent.IsSequence() && idx < parent.size()) next.reset(parent[idx]);
    } else if (parent.IsMap()) {
      // A missing key gives an invalid ("zombie") node: test before rebinding to it.
      const YAML::Node child = parent[part];
      if (child.IsDefined()) next.reset(child);
    }
    if (!next.IsDefined()) {
      if (report_missing && mode_ == MissingKeys::kError && !parse_failed_) {
        errors_.push_back({key, "missing (required)"});
      }
      return YAML::Node(YAML::NodeType::Undefined);
    }
    walk.reset(next);
  }
  return walk;
}

void ConfigReader::markUsed(const std::string& key) { used_.insert(key); }

bool ConfigReader::has(const std::string& key) const {
  return const_cast<ConfigReader*>(this)->lookup(key, false).IsDefined();
}

YAML::Node ConfigReader::node(const std::string& key) {
  markUsed(key);
  return lookup(key, true);
}

void ConfigReader::addError(const std::string& key, const std::string& message) {
  errors_.push_back({key, message});
}

void ConfigReader::readDouble(const std::string& key, double& value, const Range& range) {
  markUsed(key);
  const YAML::Node n = lookup(key, true);
  if (!n.IsDefined()) return;
  double v = 0.0;
  if (!n.IsScalar() || !parseStrictDouble(n.Scalar(), v)) {
    addError(key, "expected a number, got '" + (n.IsScalar() ? n.Scalar() : std::string("a non-scalar")) + "'");
    return;
  }
  if (!range.contains(v)) {
    addError(key, "value " + n.Scalar() + " is out of range " + range.describe());
    return;
  }
  value = v;
}

void ConfigReader::readInt(const std::string& key, int& value, const Range& range) {
  markUsed(key);
  const YAML::Node n = lookup(key, true);
  if (!n.IsDefined()) return;
  double v = 0.0;
  if (!n.IsScalar() || !parseStrictDouble(n.Scalar(), v) || !std::isfinite(v) || std::floor(v) != v ||
      std::abs(v) > 2e9) {
    addError(key, "expected an integer, got '" + (n.IsScalar() ? n.Scalar() : std::string("a non-scalar")) + "'");
    return;
  }
  if (!range.contains(v)) {
    addError(key, "value " + n.Scalar() + " is out of range " + range.describe());
    return;
  }
  value = static_cast<int>(v);
}

void ConfigReader::readBool(const std::string& key, bool& value) {
  markUsed(key);
  const YAML::Node n = lookup(key, true);
  if (!n.IsDefined()) return;
  bool v = false;
  if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v)) {
    addError(key, "expected true or false, got '" + (n.IsScalar() ? n.Scalar() : std::string("a non-scalar")) + "'");
    return;
  }
  value = v;
}

void ConfigReader::readString(const std::string& key, std::string& value, const std::vector<std::string>& allowed) {
  markUsed(key);
  const YAML::Node n = lookup(key, true);
  if (!n.IsDefined()) return;
  if (!n.IsScalar()) {
    addError(key, "expected a string");
    return;
  }
  const std::string& s = n.Scalar();
  if (!allowed.empty()) {
    bool found = false;
    std::string list;
    for (const auto& a : allowed) {
      found = found || a == s;
      list += (list.empty() ? "" : "|") + a;
    }
    if (!found) {
      addError(key, "value '" + s + "' is not one of " + list);
      return;
    }
  }
  value = s;
}

void ConfigReader::readDoubleList(const std::string& key, std::vector<double>& value, std::size_t min_size,
                                  std::size_t max_size, const Range& element_range) {
  markUsed(key);
  const YAML::Node n = lookup(key, true);
  if (!n.IsDefined()) return;
  if (!n.IsSequence()) {
    addError(key, "expected a list of numbers");
    return;
  }
  if (n.size() < min_size || n.size() > max_size) {
    addError(key, "expected " +
                      (min_size == max_size ? std::to_string(min_size)
                                            : std::to_string(min_size) + ".." + std::to_string(max_size)) +
                      " numbers, got " + std::to_string(n.size()));
    return;
  }
  std::vector<double> out;
  bool good = true;
  for (std::size_t i = 0; i < n.size(); ++i) {
    double v = 0.0;
    if (!n[i].IsScalar() || !parseStrictDouble(n[i].Scalar(), v)) {
      addError(key + "[" + std::to_string(i) + "]", "expected a number");
      good = false;
    } else if (!element_range.contains(v)) {
      addError(key + "[" + std::to_string(i) + "]",
               "value " + n[i].Scalar() + " is out of range " + element_range.describe());
      good = false;
    }
    out.push_back(v);
  }
  if (good) value = out;
}

std::vector<std::string> ConfigReader::unusedKeys() const { return unusedLeaves(false); }

std::vector<std::string> ConfigReader::unusedKeysOfWholeDocument() const { return unusedLeaves(true); }

std::vector<std::string> ConfigReader::unusedLeaves(bool whole_document) const {
  std::set<std::string> sections;
  for (const auto& k : used_) sections.insert(topSection(k));
  std::vector<std::string> leaves;
  collectLeaves(root_, "", leaves);
  std::vector<std::string> unused;
  for (const auto& leaf : leaves) {
    if (!whole_document && sections.count(topSection(leaf)) == 0) continue;
    bool consumed = false;
    for (const auto& u : used_) {
      // A key is consumed when it was read itself or lies under a node read as a whole.
      if (leaf == u || (leaf.size() > u.size() && leaf.compare(0, u.size(), u) == 0 &&
                        (leaf[u.size()] == '.' || leaf[u.size()] == '['))) {
        consumed = true;
        break;
      }
    }
    if (!consumed) unused.push_back(leaf);
  }
  return unused;
}

std::vector<std::string> ConfigReader::errors() const {
  std::vector<std::string> out;
  out.reserve(errors_.size());
  for (const ConfigError& e : errors_) out.push_back(source_ + ": " + (e.key.empty() ? "" : e.key + ": ") + e.message);
  return out;
}

std::string ConfigReader::errorReport() const {
  std::string s;
  for (const auto& e : errors()) s += e + "\n";
  return s;
}

void withSubReader(ConfigReader& r, const std::string& key, ConfigReader::MissingKeys mode,
                   const std::function<void(ConfigReader&)>& fn) {
  const YAML::Node n = r.node(key);
  std::string text = "{}";
  if (n.IsDefined() && !n.IsNull()) {
    if (!n.IsMap()) {
      r.addError(key, "must be a mapping");
      return;
    }
    YAML::Emitter em;
    em << n;
    text = em.c_str();
  }
  ConfigReader sub = ConfigReader::fromString(text, r.source() + " " + key, mode);
  fn(sub);
  for (const ConfigError& e : sub.problems()) r.addError(e.key.empty() ? key : key + "." + e.key, e.message);
  for (const auto& u : sub.unusedKeysOfWholeDocument()) r.addError(key + "." + u, "unknown key");
}

}  // namespace gesture_formation::common
