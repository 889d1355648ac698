#include "gesture_formation/common/csv.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace gesture_formation::common {

std::optional<double> parseDouble(std::string_view field) {
  if (field.empty()) return std::nullopt;
  const std::string s(field);
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || *end != '\0') return std::nullopt;
  return v;
}

std::string formatDouble(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.15g", v);
  return buf;
}

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  auto push = [&]() {
    std::size_t b = 0;
    std::size_t e = cur.size();
    while (b < e && (cur[b] == ' ' || cur[b] == '\t')) ++b;
    while (e > b && (cur[e - 1] == ' ' || cur[e - 1] == '\t' || cur[e - 1] == '\r')) --e;
    out.push_back(cur.substr(b, e - b));
    cur.clear();
  };
  for (char c : line) {
    if (c == ',') {
      push();
    } else {
      cur += c;
    }
  }
  push();
  return out;
}

CsvReader::CsvReader(const std::string& path) : path_(path), in_(path) {
  if (!in_) {
    error_ = path + ": cannot open file";
    return;
  }
  std::string line;
  while (std::getline(in_, line)) {
    ++line_number_;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    header_ = splitCsvLine(line);
    return;
  }
  error_ = path + ": empty file (expected a header row)";
}

bool CsvReader::requireColumns(const std::vector<std::string>& names) {
  if (!error_.empty()) return false;
  std::string missing;
  for (const auto& n : names) {
    if (column(n) < 0) missing += (missing.empty() ? "" : ", ") + n;
  }
  if (!missing.empty()) {
    error_ = path_ + ":1: header lacks column(s): " + missing;
    return false;
  }
  return true;
}

int CsvReader::column(const std::string& name) const {
  for (std::size_t i = 0; i < header_.size(); ++i) {
    if (header_[i] == name) return static_cast<int>(i);
  }
  return -1;
}

bool CsvReader::next() {
  if (!error_.empty()) return false;
  std::string line;
  while (std::getline(in_, line)) {
    ++line_number_;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    fields_ = splitCsvLine(line);
    if (fields_.size() != header_.size()) {
      error_ = path_ + ":" + std::to_string(line_number_) + ": expected " + std::to_string(header_.size()) +
               " fields, got " + std::to_string(fields_.size());
      return false;
    }
    return true;
  }
  return false;
}

void CsvReader::fail(const std::string& field_name, const std::string& message) {
  if (!error_.empty()) return;  // keep the first error
  error_ = path_ + ":" + std::to_string(line_number_) + ": field '" + field_name + "': " + message;
}

double CsvReader::number(const std::string& name, bool allow_empty, double empty_value) {
  const int c = column(name);
  if (c < 0) {
    fail(name, "no such column");
    return std::numeric_limits<double>::quiet_NaN();
  }
  const std::string& f = field(c);
  if (f.empty()) {
    if (allow_empty) return empty_value;
    fail(name, "empty (a number is required)");
    return std::numeric_limits<double>::quiet_NaN();
  }
  const auto v = parseDouble(f);
  if (!v) {
    fail(name, "cannot parse '" + f + "' as a number");
    return std::numeric_limits<double>::quiet_NaN();
  }
  return *v;
}

}  // namespace gesture_formation::common
