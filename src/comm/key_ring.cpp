#include "gesture_formation/comm/key_ring.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <sstream>

namespace gesture_formation::comm {

using common::Result;

Result<KeyRing> KeyRing::create(std::vector<KeyEntry> keys, std::uint8_t active_id) {
  if (keys.empty()) return Result<KeyRing>::fail("no keys");
  if (keys.size() > kMaxKeys) {
    return Result<KeyRing>::fail("too many keys: " + std::to_string(keys.size()) + " (at most " +
                                 std::to_string(kMaxKeys) + ")");
  }
  std::set<int> ids;
  bool have_active = false;
  for (const KeyEntry& k : keys) {
    if (!ids.insert(k.id).second) return Result<KeyRing>::fail("duplicate key id " + std::to_string(k.id));
    if (std::isnan(k.accept_until_s)) {
      return Result<KeyRing>::fail("key " + std::to_string(k.id) + ": accept_until_s is NaN");
    }
    if (k.id == active_id) {
      have_active = true;
      if (std::isfinite(k.accept_until_s)) {
        return Result<KeyRing>::fail("active key " + std::to_string(k.id) +
                                     " must not have accept_until_s (it is being retired)");
      }
    }
  }
  if (!have_active) return Result<KeyRing>::fail("active key id " + std::to_string(active_id) + " is not in the ring");
  return Result<KeyRing>::ok(KeyRing(std::move(keys), active_id));
}

const KeyEntry* KeyRing::find(std::uint8_t id) const {
  for (const KeyEntry& k : keys_) {
    if (k.id == id) return &k;
  }
  return nullptr;
}

namespace {

int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::vector<std::string> splitWords(const std::string& line) {
  std::vector<std::string> words;
  std::string w;
  for (char c : line) {
    if (c == ' ' || c == '\t' || c == '\r') {
      if (!w.empty()) words.push_back(std::move(w));
      w.clear();
    } else {
      w.push_back(c);
    }
  }
  if (!w.empty()) words.push_back(std::move(w));
  return words;
}

/// Parses a decimal 0..255 without locale or overflow surprises.
bool parseKeyId(const std::string& s, std::uint8_t& id) {
  if (s.empty() || s.size() > 3) return false;
  int v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  if (v > 255) return false;
  id = static_cast<std::uint8_t>(v);
  return true;
}

}  // namespace

Result<KeyRing> parseKeyFileText(const std::string& text, const std::string& source) {
  std::vector<KeyEntry> keys;
  int active_count = 0;
  std::uint8_t active_id = 0;
  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  auto fail = [&](const std::string& msg) { return Result<KeyRing>::fail(source + ":" + std::to_string(line_number) + ": " + msg); };
  while (std::getline(in, line)) {
    ++line_number;
    const std::size_t hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    const std::vector<std::string> words = splitWords(line);
    if (words.empty()) continue;
    if (keys.size() >= kMaxKeys) return fail("more than " + std::to_string(kMaxKeys) + " keys");
    if (words.size() < 2) return fail("expected '<key_id> <64 hex digits> [active] [accept_until_s=<s>]'");
    KeyEntry entry;
    if (!parseKeyId(words[0], entry.id)) return fail("key id must be a decimal number 0..255");
    const std::string& hex = words[1];
    if (hex.size() != 2 * kKeyBytes) {
      return fail("key " + std::to_string(entry.id) + " has " + std::to_string(hex.size()) +
                  " hex digits, expected " + std::to_string(2 * kKeyBytes) + " (" + std::to_string(kKeyBytes) +
                  " bytes)");
    }
    std::array<std::uint8_t, kKeyBytes> bytes{};
    for (std::size_t i = 0; i < kKeyBytes; ++i) {
      const int hi = hexValue(hex[2 * i]);
      const int lo = hexValue(hex[2 * i + 1]);
      if (hi < 0 || lo < 0) {
        secureZero(bytes.data(), bytes.size());
        return fail("key " + std::to_string(entry.id) + " contains a non-hex character");
      }
      bytes[i] = static_cast<std::uint8_t>(hi * 16 + lo);
    }
    entry.key = SecretKey(bytes);
    secureZero(bytes.data(), bytes.size());
    for (std::size_t w = 2; w < words.size(); ++w) {
      const std::string& opt = words[w];
      static const std::string kUntil = "accept_until_s=";
      if (opt == "active") {
        ++active_count;
        active_id = entry.id;
      } else if (opt.compare(0, kUntil.size(), kUntil) == 0) {
        const std::string value = opt.substr(kUntil.size());
        char* end = nullptr;
        errno = 0;
        const double t = value.empty() ? std::nan("") : std::strtod(value.c_str(), &end);
        if (value.empty() || end != value.c_str() + value.size() || !std::isfinite(t) || errno == ERANGE) {
          return fail("key " + std::to_string(entry.id) + ": accept_until_s must be a finite number of seconds");
        }
        entry.accept_until_s = t;
      } else {
        // Not echoed: a mangled line may hold key material (found by fuzz_key_file).
        return fail("unknown option in word " + std::to_string(w + 1) + " (expected 'active' or 'accept_until_s=<s>')");
      }
    }
    keys.push_back(std::move(entry));
  }
  // Whole-file problems: no line number.
  auto failFile = [&](const std::string& msg) { return Result<KeyRing>::fail(source + ": " + msg); };
  if (keys.empty()) return failFile("no keys");
  if (active_count > 1) return failFile("more than one key marked 'active'");
  if (active_count == 0) {
    if (keys.size() != 1) return failFile("several keys but none marked 'active'");
    active_id = keys.front().id;
  }
  Result<KeyRing> ring = KeyRing::create(std::move(keys), active_id);
  if (!ring) return failFile(ring.reason());
  return ring;
}

namespace {

/// Closes a descriptor on scope exit.
struct FdGuard {
  int fd;
  ~FdGuard() {
    if (fd >= 0) ::close(fd);
  }
};

std::string modeString(mode_t mode) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04o", static_cast<unsigned>(mode & 07777));
  return buf;
}

}  // namespace

Result<KeyRing> loadKeyFile(const std::string& path) {
  auto fail = [&](const std::string& msg) { return Result<KeyRing>::fail("key file '" + path + "': " + msg); };
  if (path.empty()) return Result<KeyRing>::fail("key file: no path given");
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
  if (fd < 0) {
    const int err = errno;
    if (err == ENOENT) return fail("does not exist");
    if (err == EACCES) return fail("permission denied");
    return fail(std::string("cannot open: ") + std::strerror(err));
  }
  FdGuard guard{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) return fail(std::string("cannot stat: ") + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) return fail("is not a regular file");
  if ((st.st_mode & 077) != 0) {
    return fail("permissions " + modeString(st.st_mode) +
                " give access to group or others; a key file must be owner-only (chmod 600 '" + path + "')");
  }
  if (st.st_uid != ::geteuid() && st.st_uid != 0) {
    return fail("owned by uid " + std::to_string(st.st_uid) + ", expected this user (uid " +
                std::to_string(::geteuid()) + ") or root");
  }
  if (st.st_size > static_cast<off_t>(kMaxKeyFileBytes)) {
    return fail("is " + std::to_string(st.st_size) + " bytes, larger than " + std::to_string(kMaxKeyFileBytes));
  }
  std::string text;
  text.resize(kMaxKeyFileBytes + 1);
  std::size_t got = 0;
  while (got < text.size()) {
    const ssize_t n = ::read(fd, &text[got], text.size() - got);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      secureZero(&text[0], text.size());
      return fail(std::string("read error: ") + std::strerror(err));
    }
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  if (got > kMaxKeyFileBytes) {
    secureZero(&text[0], text.size());
    return fail("larger than " + std::to_string(kMaxKeyFileBytes) + " bytes");
  }
  text.resize(got);
  Result<KeyRing> ring = parseKeyFileText(text, path);
  secureZero(&text[0], text.size());
  return ring;
}

}  // namespace gesture_formation::comm
