#pragma once
// Loads ROS parameters and collects every problem, so that a nodelet can refuse to start with
// one message listing all of them (house style: never ros::shutdown() from a nodelet).
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/common/config_reader.hpp"

namespace gesture_formation::nodelets {

class ParamLoader {
 public:
  explicit ParamLoader(const ros::NodeHandle& nh) : nh_(nh) {}

  void load(const std::string& name, std::string& value) {
    if (!nh_.getParam(name, value)) missing(name);
    loaded_ << "  " << name << " = " << value << "\n";
  }
  void load(const std::string& name, double& value, double lo = -std::numeric_limits<double>::infinity(),
            double hi = std::numeric_limits<double>::infinity()) {
    if (!nh_.getParam(name, value)) {
      missing(name);
      return;
    }
    if (!(value >= lo && value <= hi)) {
      std::ostringstream os;
      os << nh_.resolveName(name) << ": value " << value << " out of range [" << lo << ", " << hi << "]";
      errors_.push_back(os.str());
    }
    loaded_ << "  " << name << " = " << value << "\n";
  }
  void load(const std::string& name, int& value, int lo, int hi) {
    if (!nh_.getParam(name, value)) {
      missing(name);
      return;
    }
    if (value < lo || value > hi) {
      std::ostringstream os;
      os << nh_.resolveName(name) << ": value " << value << " out of range [" << lo << ", " << hi << "]";
      errors_.push_back(os.str());
    }
    loaded_ << "  " << name << " = " << value << "\n";
  }
  /// \brief A number with the range the core declares for it (e.g. onboard::ranges): one range
  /// per setting, whichever source it comes from.
  void load(const std::string& name, double& value, const common::Range& range) {
    if (!nh_.getParam(name, value)) {
      missing(name);
      return;
    }
    if (!range.contains(value)) {
      std::ostringstream os;
      os << nh_.resolveName(name) << ": value " << value << " out of range " << range.describe();
      errors_.push_back(os.str());
    }
    loaded_ << "  " << name << " = " << value << "\n";
  }
  void load(const std::string& name, int& value, const common::Range& range) {
    double v = 0.0;
    load(name, v, range);
    if (v != static_cast<double>(static_cast<int>(v))) {
      errors_.push_back(nh_.resolveName(name) + ": not an integer");
      return;
    }
    value = static_cast<int>(v);
  }
  /// \brief Every number of a core FieldTable, each under the last segment of its key (the table's
  /// "faults.max_plan_age_s" is the parameter max_plan_age_s) with the table's range.
  template <class Config>
  void loadFields(const common::FieldTable<Config>& table, Config& c) {
    for (const auto& f : table.fields) {
      const std::string key = f.key;
      const std::string name = key.substr(key.find_last_of('.') + 1);  // npos + 1 == 0: the whole key
      if (f.ref_double) {
        load(name, *f.ref_double(c), f.range);
      } else if (f.ref_int) {
        load(name, *f.ref_int(c), f.range);
      } else {
        double v = static_cast<double>(*f.ref_float(c));
        load(name, v, f.range);
        *f.ref_float(c) = static_cast<float>(v);
      }
    }
  }
  void load(const std::string& name, bool& value) {
    if (!nh_.getParam(name, value)) missing(name);
    loaded_ << "  " << name << " = " << (value ? "true" : "false") << "\n";
  }
  void load(const std::string& name, std::vector<int>& value) {
    if (!nh_.getParam(name, value)) {
      missing(name);
      return;
    }
    loaded_ << "  " << name << " = [";
    for (std::size_t i = 0; i < value.size(); ++i) loaded_ << (i ? ", " : "") << value[i];
    loaded_ << "]\n";
  }
  /// \brief An optional string: absent → `fallback` (never an error).
  void loadOptional(const std::string& name, std::string& value, const std::string& fallback) {
    if (!nh_.getParam(name, value)) value = fallback;
    loaded_ << "  " << name << " = " << value << "\n";
  }
  /// \brief An optional bool: absent → `fallback` (never an error); not a bool → an error.
  void loadOptional(const std::string& name, bool& value, bool fallback) {
    value = fallback;
    if (nh_.hasParam(name) && !nh_.getParam(name, value)) errors_.push_back(nh_.resolveName(name) + ": not a bool");
    loaded_ << "  " << name << " = " << (value ? "true" : "false") << "\n";
  }
  /// \brief A line for the "loaded" report (e.g. a value taken from a file, not a parameter).
  void note(const std::string& line) { loaded_ << "  " << line << "\n"; }
  void addError(const std::string& error) { errors_.push_back(error); }
  void addErrors(const std::vector<std::string>& errors) { errors_.insert(errors_.end(), errors.begin(), errors.end()); }

  bool ok() const { return errors_.empty(); }
  std::string report() const {
    std::string s;
    for (const auto& e : errors_) s += "  - " + e + "\n";
    return s;
  }
  std::string loaded() const { return loaded_.str(); }

 private:
  void missing(const std::string& name) { errors_.push_back(nh_.resolveName(name) + ": missing (required)"); }
  ros::NodeHandle nh_;
  std::vector<std::string> errors_;
  std::ostringstream loaded_;
};

// A key the reader does not know is refused too, like the missions' (a misplaced or misspelled
// optional key would otherwise be ignored in silence; a misspelled required one reads as missing).
inline void refuseUnknown(const char* what, const std::vector<std::string>& unknown, ParamLoader& params) {
  for (std::string w : unknown) {
    const std::string suffix = " ignored";  // the loaders' warning wording; here it refuses the start
    if (w.size() > suffix.size() && w.compare(w.size() - suffix.size(), suffix.size(), suffix) == 0) w.resize(w.size() - suffix.size());
    params.addError(std::string(what) + ": " + w);
  }
}

}  // namespace gesture_formation::nodelets
