#pragma once
/// \file
/// \brief CSV with a header row (docs/design.md §8): a reader that names file, line and field in
/// every error, and number formatting that round-trips to 1e-10 relative.

#include <cstddef>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gesture_formation::common {

/// \brief Parses a whole field as a double. "nan", "inf" accepted; empty or trailing junk is not.
std::optional<double> parseDouble(std::string_view field);

/// \brief Formats a double with 15 significant digits (enough for 1e-9 m comparisons of coordinates up to 1e5 m); NaN as "nan", ±inf as "inf"/"-inf".
std::string formatDouble(double v);

/// \brief Reads a CSV file with a header row, one record per line (no quoted commas).
/// Thread safety: none.
class CsvReader {
 public:
  /// Opens the file and reads the header. Check `error()` afterwards.
  explicit CsvReader(const std::string& path);

  /// Non-empty when the file could not be opened, has no header, or a required column is
  /// missing (after `requireColumns`).
  const std::string& error() const { return error_; }
  const std::string& path() const { return path_; }
  const std::vector<std::string>& header() const { return header_; }

  /// Records an error listing every required column the header lacks. Returns true if all exist.
  bool requireColumns(const std::vector<std::string>& names);
  /// Index of a column, or -1.
  int column(const std::string& name) const;

  /// Reads the next non-empty line into fields. Returns false at end of file or on a line
  /// with the wrong number of fields (then `error()` names the line).
  bool next();
  std::size_t lineNumber() const { return line_number_; }
  const std::vector<std::string>& fields() const { return fields_; }
  /// Raw text of a column in the current row.
  const std::string& field(int column) const { return fields_.at(static_cast<std::size_t>(column)); }

  /// The current row's value of `name` as a double. Empty fields give `empty_value` when
  /// `allow_empty`, else an error. Errors are recorded (file:line: field 'name': ...) and
  /// NaN is returned.
  double number(const std::string& name, bool allow_empty = false,
                double empty_value = std::numeric_limits<double>::quiet_NaN());
  /// Message "file:line: field 'name': message" (also stored in error()).
  void fail(const std::string& field_name, const std::string& message);

 private:
  std::string path_;
  std::ifstream in_;
  std::vector<std::string> header_;
  std::vector<std::string> fields_;
  std::size_t line_number_ = 0;
  std::string error_;
};

/// \brief Splits a line on commas, trimming spaces and a trailing '\r'.
std::vector<std::string> splitCsvLine(const std::string& line);

}  // namespace gesture_formation::common
