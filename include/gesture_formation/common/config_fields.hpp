#pragma once
/// \file
/// \brief One range per configuration number: a table of {key, Range, place in the struct} that a
/// module's `Config::validate()` (a struct built in code) and its YAML reader both use, so the
/// two can never disagree.
///
/// Use (one table per Config, in the module's .cpp):
/// ```
/// const common::FieldTable<FooConfig>& fields() {
///   static const common::FieldTable<FooConfig> t{{
///       {"max_age_s", Range::positive(), [](FooConfig& c) { return &c.max_age_s; }},
///       {"window_size", Range::closed(1, 100), [](FooConfig& c) { return &c.window_size; }},
///   }};
///   return t;
/// }
/// ```
/// `validate()`: `fields().rangeProblems(*this)` plus the rules between fields; the reader:
/// `fields().readFields(r, prefix, c)`, then *always* the same problems of the result (a key out of
/// range kept its in-range default while reading, so only what is new gets added).
/// Thread safety: tables are immutable after construction; reading shares the reader's (none).

#include <algorithm>
#include <string>
#include <vector>

#include "gesture_formation/common/config_reader.hpp"

namespace gesture_formation::common {

/// \brief One number of `Config` (a double, int or float member): its dotted key (relative to the
/// Config's own section), its range — the only place the range is written — and where it lives
/// in the struct (an accessor, e.g. `[](FooConfig& c) { return &c.limits.max_speed_mps; }`).
template <class Config>
struct Field {
  Field(const char* k, Range r, double* (*ref)(Config&)) : key(k), range(r), ref_double(ref) {}
  Field(const char* k, Range r, int* (*ref)(Config&)) : key(k), range(r), ref_int(ref) {}
  Field(const char* k, Range r, float* (*ref)(Config&)) : key(k), range(r), ref_float(ref) {}

  const char* key;
  Range range;
  double* (*ref_double)(Config&) = nullptr;  ///< exactly one of the three is set
  int* (*ref_int)(Config&) = nullptr;
  float* (*ref_float)(Config&) = nullptr;
};

/// \brief What a value must satisfy, as a sentence fragment: "> 0", ">= 1", "< 90",
/// "in [0, 1]", "in (0, 1)"; "finite" for Range::any().
std::string rangeRequirement(const Range& range);

/// \brief The problem of `value` under `range` ("must be > 0, got -1"), for validate().
std::string rangeProblem(const Range& range, double value);
std::string rangeProblem(const Range& range, int value);

/// \brief Appends {key, "<what>, got <value>"} to `problems` when `ok` is false (a rule between
/// fields, stated on the key that has to change).
void checkRule(std::vector<ConfigError>& problems, bool ok, const std::string& key, double value,
               const std::string& what);

/// \brief Records each problem in `r` under `prefix` + its key.
void addProblems(ConfigReader& r, const std::string& prefix, const std::vector<ConfigError>& problems);

/// \brief Each problem as one validate() line: "<prefix><key> <message>".
std::vector<std::string> problemLines(const std::vector<ConfigError>& problems, const std::string& prefix = "");

/// \brief The numeric fields of `Config`, in the order they are documented (problems are listed
/// in this order).
template <class Config>
struct FieldTable {
  std::vector<Field<Config>> fields;

  /// \brief Each field of `c` outside its range, as {key, "must be ..., got v"}, in table order.
  std::vector<ConfigError> rangeProblems(const Config& c) const {
    std::vector<ConfigError> e;
    Config m = c;  // the accessors take a mutable config; nothing is written
    for (const auto& f : fields) {
      if (f.ref_int) {
        const int v = *f.ref_int(m);
        if (!f.range.contains(v)) e.push_back({f.key, rangeProblem(f.range, v)});
      } else {
        const double v = f.ref_double ? *f.ref_double(m) : static_cast<double>(*f.ref_float(m));
        if (!f.range.contains(v)) e.push_back({f.key, rangeProblem(f.range, v)});
      }
    }
    return e;
  }

  /// \brief Reads every field from `r` at `prefix` + key with its range (a missing, malformed or
  /// out-of-range value keeps the value in `c` and is recorded in `r`).
  void readFields(ConfigReader& r, const std::string& prefix, Config& c) const {
    for (const auto& f : fields) read(r, prefix, c, f);
  }

  /// \brief As readFields, but every field must be present: a missing key is recorded in `r` as
  /// "missing (required: <why>)" (e.g. physical limits, which have no defaults).
  void readRequiredFields(ConfigReader& r, const std::string& prefix, Config& c, const std::string& why) const {
    for (const auto& f : fields) {
      if (!r.has(prefix + f.key)) {
        r.addError(prefix + f.key, "missing (required: " + why + ")");
        continue;
      }
      read(r, prefix, c, f);
    }
  }

  /// \brief Reads only the field `key` (one whose presence depends on other keys); a key the
  /// table does not have is recorded in `r` as a program error.
  void readField(ConfigReader& r, const std::string& prefix, Config& c, const std::string& key) const {
    for (const auto& f : fields) {
      if (key == f.key) return read(r, prefix, c, f);
    }
    r.addError(prefix + key, "not a field of this configuration (program error)");
  }

  /// \brief The range of `key`; nullptr when the table has no such key.
  const Range* rangeOf(const std::string& key) const {
    for (const auto& f : fields) {
      if (key == f.key) return &f.range;
    }
    return nullptr;
  }

  /// \brief Orders `problems` (stable) by the table position of their key; keys the table does
  /// not have (rules about other things) keep their order after those it has.
  void sortByTableOrder(std::vector<ConfigError>& problems) const {
    const auto rank = [this](const std::string& key) {
      for (std::size_t i = 0; i < fields.size(); ++i) {
        if (key == fields[i].key) return i;
      }
      return fields.size();
    };
    std::stable_sort(problems.begin(), problems.end(),
                     [&rank](const ConfigError& a, const ConfigError& b) { return rank(a.key) < rank(b.key); });
  }

 private:
  static void read(ConfigReader& r, const std::string& prefix, Config& c, const Field<Config>& f) {
    if (f.ref_double) {
      r.readDouble(prefix + f.key, *f.ref_double(c), f.range);
    } else if (f.ref_int) {
      r.readInt(prefix + f.key, *f.ref_int(c), f.range);
    } else {
      double v = static_cast<double>(*f.ref_float(c));
      r.readDouble(prefix + f.key, v, f.range);
      *f.ref_float(c) = static_cast<float>(v);
    }
  }
};

}  // namespace gesture_formation::common
