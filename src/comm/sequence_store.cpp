#include "gesture_formation/comm/sequence_store.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <sstream>

namespace gesture_formation::comm {

using common::Result;

namespace {

constexpr std::size_t kMaxStateFileBytes = 65536;

struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

bool parseUnsigned(const std::string& s, std::uint64_t max, std::uint64_t& out) {
  if (s.empty() || s.size() > 20) return false;
  std::uint64_t v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    const std::uint64_t d = static_cast<std::uint64_t>(c - '0');
    if (v > (max - d) / 10) return false;
    v = v * 10 + d;
  }
  out = v;
  return true;
}

}  // namespace

Result<std::string> readStateFile(const std::string& path, bool& exists) {
  auto fail = [&](const std::string& m) { return Result<std::string>::fail("state file '" + path + "': " + m); };
  exists = false;
  if (path.empty()) return Result<std::string>::fail("state file: no path given");
  const Fd f{::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK)};
  if (f.fd < 0) {
    if (errno == ENOENT) return Result<std::string>::ok(std::string());
    return fail(std::string("cannot open: ") + std::strerror(errno));
  }
  exists = true;
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) return fail(std::string("cannot stat: ") + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) return fail("is not a regular file");
  if ((st.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    return fail(std::string("permissions ") + mode + " give access to group or others (chmod 600 '" + path + "')");
  }
  if (st.st_size > static_cast<off_t>(kMaxStateFileBytes)) return fail("larger than " + std::to_string(kMaxStateFileBytes) + " bytes");
  std::string text(static_cast<std::size_t>(st.st_size), '\0');
  std::size_t got = 0;
  while (got < text.size()) {
    const ssize_t n = ::read(f.fd, &text[got], text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return fail(std::string("read error: ") + std::strerror(errno));
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  text.resize(got);
  return Result<std::string>::ok(std::move(text));
}

Result<bool> writeStateFile(const std::string& path, const std::string& text) {
  auto fail = [&](const std::string& m) { return Result<bool>::fail("state file '" + path + "': " + m); };
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());  // two writers never share one
  {
    const Fd f{::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0600)};
    if (f.fd < 0) return fail(std::string("cannot create '") + tmp + "': " + std::strerror(errno));
    if (::fchmod(f.fd, 0600) != 0) return fail(std::string("cannot chmod: ") + std::strerror(errno));
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::write(f.fd, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return fail(std::string("write error: ") + std::strerror(errno));
      done += static_cast<std::size_t>(n);
    }
    if (::fsync(f.fd) != 0) return fail(std::string("fsync failed: ") + std::strerror(errno));
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    return fail(std::string("rename failed: ") + std::strerror(err));
  }
  // The rename is durable only once the directory is: without this a power cut soon after a start
  // can bring the old boot counter back, and the next boot reuses the crashed run's sequence numbers.
  const std::size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
  const Fd d{::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC)};
  if (d.fd < 0) return fail(std::string("cannot open its directory '") + dir + "': " + std::strerror(errno));
  if (::fsync(d.fd) != 0) return fail(std::string("fsync of its directory failed: ") + std::strerror(errno));
  return Result<bool>::ok(true);
}

Result<std::uint32_t> advanceBootCounter(const std::string& path) {
  bool exists = false;
  auto text = readStateFile(path, exists);
  if (!text) return Result<std::uint32_t>::fail(text.reason());
  std::uint64_t boot = 0;
  if (exists) {
    std::string t = text.value();
    while (!t.empty() && (t.back() == '\n' || t.back() == ' ')) t.pop_back();
    if (!parseUnsigned(t, kMaxBootCounter, boot)) {
      return Result<std::uint32_t>::fail("state file '" + path + "': expected one boot counter 0.." +
                                         std::to_string(kMaxBootCounter));
    }
  }
  if (boot >= kMaxBootCounter) {
    return Result<std::uint32_t>::fail("state file '" + path + "': boot counter exhausted; rotate this sender's key and reset the file");
  }
  ++boot;
  auto written = writeStateFile(path, std::to_string(boot) + "\n");
  if (!written) return Result<std::uint32_t>::fail(written.reason());
  return Result<std::uint32_t>::ok(static_cast<std::uint32_t>(boot));
}

Result<std::map<std::uint16_t, std::uint64_t>> loadHighWaterMarks(const std::string& path) {
  using R = Result<std::map<std::uint16_t, std::uint64_t>>;
  bool exists = false;
  auto text = readStateFile(path, exists);
  if (!text) return R::fail(text.reason());
  std::map<std::uint16_t, std::uint64_t> marks;
  std::istringstream in(text.value());
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    const std::size_t space = line.find(' ');
    std::uint64_t sender = 0, sequence = 0;
    if (space == std::string::npos || !parseUnsigned(line.substr(0, space), 65535, sender) ||
        !parseUnsigned(line.substr(space + 1), UINT64_MAX, sequence)) {
      return R::fail("state file '" + path + "':" + std::to_string(number) + ": expected '<sender id> <sequence>'");
    }
    marks[static_cast<std::uint16_t>(sender)] = sequence;
  }
  return R::ok(std::move(marks));
}

Result<bool> saveHighWaterMarks(const std::string& path, const std::map<std::uint16_t, std::uint64_t>& marks) {
  std::string text;
  for (const auto& [sender, sequence] : marks) text += std::to_string(sender) + " " + std::to_string(sequence) + "\n";
  return writeStateFile(path, text);
}

std::string defaultStateDirectory() {
  const char* ros_home = std::getenv("ROS_HOME");
  const char* home = std::getenv("HOME");
  const std::string base = ros_home && *ros_home ? ros_home : std::string(home && *home ? home : "/tmp") + "/.ros";
  return base + "/gesture_formation";
}

void ensureStateDirectory(const std::string& dir, const std::vector<std::string>& files) {
  bool inside = false;
  for (const auto& f : files) inside = inside || f.rfind(dir + "/", 0) == 0;
  if (!inside) return;
  const std::string parent = dir.substr(0, dir.rfind('/'));
  ::mkdir(parent.c_str(), 0700);  // $ROS_HOME may not exist yet
  ::mkdir(dir.c_str(), 0700);
}

}  // namespace gesture_formation::comm
