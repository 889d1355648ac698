#pragma once
/// \file
/// \brief The operator's list of UAV indices as text ("[0, 2]": the OperatorInterface's
/// send_command target, tools/gf_command.py): parsed strictly — what it is not is refused, never
/// guessed at ("[-1]", "[1.5]", "[1, 2" were read as [1], [1, 5] and [1]).
/// Thread safety: pure function.

#include <optional>
#include <string>
#include <vector>

namespace gesture_formation::formation {

/// \brief '[' index (',' index)* ']', spaces allowed around each index, each index 1–3 decimal
/// digits; nullopt otherwise (the caller names the text). Whether each index exists is the
/// command's check (CommandTarget::resolve).
inline std::optional<std::vector<int>> parseUavList(const std::string& text) {
  if (text.size() < 2 || text.front() != '[' || text.back() != ']') return std::nullopt;
  std::vector<int> out;
  std::string item;
  const auto take = [&]() {
    const auto a = item.find_first_not_of(' '), b = item.find_last_not_of(' ');
    if (a == std::string::npos) return false;
    const std::string digits = item.substr(a, b - a + 1);
    if (digits.size() > 3 || digits.find_first_not_of("0123456789") != std::string::npos) return false;
    out.push_back(std::stoi(digits));
    item.clear();
    return true;
  };
  for (const char c : text.substr(1, text.size() - 2)) {
    if (c != ',') {
      item += c;
    } else if (!take()) {
      return std::nullopt;
    }
  }
  if (!take()) return std::nullopt;
  return out;
}

}  // namespace gesture_formation::formation
