// gfctl: the offline command-line tool of gesture_formation (no ROS master needed).
#include <cstdio>
#include <cstring>
#include <algorithm>
#include <iostream>
#include <string>

#include "commands.hpp"

namespace gesture_formation::gfctl {

std::vector<CommandInfo>& commandRegistry() {
  static std::vector<CommandInfo> registry;
  return registry;
}

int badInput(const Args& args, const std::string& message) {
  std::cerr << "gfctl " << args.command << ": " << message << std::endl;
  return kExitBadInput;
}

bool checkOptions(const Args& args, const std::vector<std::string>& required, const std::vector<std::string>& optional) {
  bool ok = true;
  for (const auto& r : required) {
    if (!args.has(r)) {
      std::cerr << "gfctl " << args.command << ": missing required option --" << r << std::endl;
      ok = false;
    }
  }
  for (const auto& kv : args.options) {
    bool known = false;
    for (const auto& r : required) known = known || r == kv.first;
    for (const auto& o : optional) known = known || o == kv.first;
    if (!known) {
      std::cerr << "gfctl " << args.command << ": unknown option --" << kv.first << std::endl;
      ok = false;
    }
  }
  return ok;
}

namespace {

void usage(std::FILE* out) {
  std::fprintf(out, "usage: gfctl <command> [options]\n\ncommands:\n");
  auto commands = commandRegistry();
  std::sort(commands.begin(), commands.end(),
            [](const CommandInfo& a, const CommandInfo& b) { return std::strcmp(a.name, b.name) < 0; });
  for (const auto& c : commands) std::fprintf(out, "  %-16s %s\n", c.name, c.usage);
  std::fprintf(out, "\nExit codes: 0 success, 2 bad arguments or input.\n");
}

}  // namespace
}  // namespace gesture_formation::gfctl

int main(int argc, char** argv) {
  using namespace gesture_formation::gfctl;
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0 ||
      std::strcmp(argv[1], "help") == 0) {
    usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? kExitBadInput : kExitOk;
  }
  Args args;
  args.command = argv[1];
  for (int i = 2; i < argc; ++i) {
    std::string a = argv[i];
    if (a.rfind("--", 0) != 0 || a.size() < 3) {
      std::cerr << "gfctl " << args.command << ": unexpected argument '" << a << "'" << std::endl;
      return kExitBadInput;
    }
    a = a.substr(2);
    const auto eq = a.find('=');
    if (eq != std::string::npos) {
      args.options[a.substr(0, eq)] = a.substr(eq + 1);
    } else if (i + 1 < argc && std::strncmp(argv[i + 1], "--", 2) != 0) {
      args.options[a] = argv[++i];
    } else {
      args.options[a] = "1";
    }
  }
  for (const auto& c : commandRegistry()) {
    if (args.command == c.name) {
      try {
        return c.run(args);
      } catch (const std::exception& e) {
        std::cerr << "gfctl " << args.command << ": internal error: " << e.what() << std::endl;
        return 1;
      }
    }
  }
  std::cerr << "gfctl: unknown command '" << args.command << "'\n";
  usage(stderr);
  return kExitBadInput;
}
