// gfctl: the offline command-line tool of gesture_formation (no ROS master needed).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

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
  std::fprintf(out, "  %-16s %s\n", "bench",
               "<name> [options]   run a benchmark program built next to gfctl (planning, planner, estimation, formation, perception)");
  std::fprintf(out, "\nExit codes: 0 success, 2 bad arguments or input.\n");
}

}  // namespace
}  // namespace gesture_formation::gfctl

namespace {

/// `gfctl bench <name> [options]`: runs the benchmark programs built next to gfctl
/// (bench/bench_<name>.cpp → gf_bench_<name>); `planning` runs the world-model/corridor
/// benchmark and then the full-replanning one. Options go to the programs unchanged.
int runBench(int argc, char** argv) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path dir = fs::read_symlink("/proc/self/exe", ec).parent_path();
  std::vector<std::string> available;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string();
    if (n.rfind("gf_bench_", 0) == 0) available.push_back(n.substr(9));
  }
  std::sort(available.begin(), available.end());
  std::string list;
  for (const auto& a : available) list += " " + a;
  if (argc < 3 || argv[2][0] == '-') {
    std::cerr << "usage: gfctl bench <name> [options]   names:" << list << " (planning = planning + planner)\n";
    return gesture_formation::gfctl::kExitBadInput;
  }
  const std::string name = argv[2];
  std::vector<std::string> programs = name == "planning" ? std::vector<std::string>{"planning", "planner"}
                                                         : std::vector<std::string>{name};
  for (const auto& p : programs) {
    if (std::find(available.begin(), available.end(), p) == available.end()) {
      std::cerr << "gfctl bench: no benchmark '" << name << "' next to gfctl in " << dir << " (available:" << list << ")\n";
      return gesture_formation::gfctl::kExitBadInput;
    }
  }
  // The benchmarks read config/ and scenarios from the source tree.
  std::string root = GF_DEFAULT_MODELS_DIR;
  root = root.substr(0, root.find_last_of('/'));
  setenv("GF_SOURCE_DIR", root.c_str(), 0);
  int rc = 0;
  for (const auto& p : programs) {
    std::string cmd = (dir / ("gf_bench_" + p)).string();
    for (int i = 3; i < argc; ++i) {
      std::string a = argv[i], q = "'";
      for (char c : a) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
      cmd += " " + q + "'";
    }
    std::cout << "== " << cmd << std::endl;
    const int status = std::system(cmd.c_str());
    if (status != 0) rc = 1;
  }
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace gesture_formation::gfctl;
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0 ||
      (std::strcmp(argv[1], "help") == 0 && argc < 3)) {
    usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? kExitBadInput : kExitOk;
  }
  if (std::strcmp(argv[1], "bench") == 0) return runBench(argc, argv);
  // `gfctl <command> --help` (or -h) and `gfctl help <command>`: that command's usage on stdout.
  const bool help_for = std::strcmp(argv[1], "help") == 0;
  bool asks_help = help_for;
  for (int i = 2; i < argc; ++i) asks_help = asks_help || std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0;
  if (asks_help) {
    const char* name = help_for ? argv[2] : argv[1];
    for (const auto& c : commandRegistry()) {
      if (std::strcmp(name, c.name) == 0) {
        std::printf("usage: gfctl %s %s\n", c.name, c.usage);
        return kExitOk;
      }
    }
    std::cerr << "gfctl: unknown command '" << name << "'\n";
    usage(stderr);
    return kExitBadInput;
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
