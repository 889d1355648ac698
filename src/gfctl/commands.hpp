#pragma once
// gfctl subcommands (contracts: docs/design.md §8). Each returns the process exit code:
// 0 success, 2 bad arguments or input (one-line message on stderr naming file, line, field).

#include <map>
#include <string>
#include <vector>

namespace gesture_formation::gfctl {

/// Parsed `--key value` options and bare flags (`--flag` → "1").
struct Args {
  std::string command;
  std::map<std::string, std::string> options;

  bool has(const std::string& k) const { return options.count(k) != 0; }
  std::string get(const std::string& k, const std::string& def = "") const {
    const auto it = options.find(k);
    return it == options.end() ? def : it->second;
  }
};

constexpr int kExitOk = 0;
constexpr int kExitBadInput = 2;

/// Prints "gfctl <cmd>: message" to stderr and returns kExitBadInput.
int badInput(const Args& args, const std::string& message);
/// Checks that every required option is present and no unknown option was given.
bool checkOptions(const Args& args, const std::vector<std::string>& required, const std::vector<std::string>& optional);

/// Self-registration: in a cmd_*.cpp, `static const Registrar kReg{"name", "usage", runFn};`
using CommandFn = int (*)(const Args&);
struct CommandInfo {
  const char* name;
  const char* usage;
  CommandFn run;
};
std::vector<CommandInfo>& commandRegistry();
struct Registrar {
  Registrar(const char* name, const char* usage, CommandFn run) { commandRegistry().push_back({name, usage, run}); }
};

/// \brief Where the models are: --models, else $GF_MODELS_DIR, else the install space's
/// share/gesture_formation/third_party_models next to this executable, else the source tree's
/// third_party_models (set by CMake), else ./third_party_models.
std::string modelsRoot(const Args& args);

}  // namespace gesture_formation::gfctl
