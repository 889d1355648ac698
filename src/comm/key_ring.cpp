#include "gesture_formation/comm/key_ring.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <set>
#include <sstream>

namespace gesture_formation::comm {

using common::Result;

const char* toString(KeyKind kind) {
  switch (kind) {
    case KeyKind::kGroupHmac: return "group";
    case KeyKind::kSigning: return "signing";
    case KeyKind::kVerifying: return "verifying";
  }
  return "unknown";
}

Result<KeyEntry> signingKey(std::uint8_t id, std::uint16_t sender_id, const std::array<std::uint8_t, kKeyBytes>& seed) {
  KeyEntry e;
  e.id = id;
  e.kind = KeyKind::kSigning;
  e.sender_id = sender_id;
  e.key = SecretKey(seed);
  if (!ed25519PublicFromSeed(e.key.data(), e.public_key)) {
    return Result<KeyEntry>::fail("key " + std::to_string(id) + ": Ed25519 public key derivation failed (OpenSSL)");
  }
  return Result<KeyEntry>::ok(std::move(e));
}

KeyEntry verifyingKeyOf(const KeyEntry& signing, double accept_until_s) {
  KeyEntry e;
  e.id = signing.id;
  e.kind = KeyKind::kVerifying;
  e.sender_id = signing.sender_id;
  e.public_key = signing.public_key;
  e.accept_until_s = accept_until_s;
  return e;
}

namespace {

std::string keyName(const KeyEntry& k) {
  if (k.kind == KeyKind::kGroupHmac) return "key " + std::to_string(k.id);
  return std::string(toString(k.kind)) + " key " + std::to_string(k.id) + " of sender " + std::to_string(k.sender_id);
}

/// Per-sender rules: no group key, signing keys of one sender, verifying ids unique per sender.
std::optional<std::string> perSenderProblem(const std::vector<KeyEntry>& keys) {
  std::set<std::pair<int, int>> verifying;
  std::optional<std::uint16_t> signer;
  std::size_t signing_count = 0;
  for (const KeyEntry& k : keys) {
    if (k.kind == KeyKind::kGroupHmac) {
      return std::string("group key ") + std::to_string(k.id) +
             " mixed with per-sender keys (it would let any holder speak for every sender)";
    }
    if (k.kind == KeyKind::kVerifying) {
      if (!verifying.insert({k.sender_id, k.id}).second) {
        return "duplicate verifying key " + std::to_string(k.id) + " of sender " + std::to_string(k.sender_id);
      }
      continue;
    }
    ++signing_count;
    if (signer && *signer != k.sender_id) {
      return "signing keys of two senders (" + std::to_string(*signer) + " and " + std::to_string(k.sender_id) +
             "): a node holds only its own";
    }
    signer = k.sender_id;
    if (std::isfinite(k.accept_until_s)) return keyName(k) + ": accept_until_s applies to verifying keys only";
  }
  if (signing_count == 0) return std::string("no signing key (a 'signing sender=<id>' line for this node)");
  if (verifying.size() > kMaxVerifyingKeys) {
    return "too many verifying keys: " + std::to_string(verifying.size()) + " (at most " +
           std::to_string(kMaxVerifyingKeys) + ")";
  }
  return std::nullopt;
}

}  // namespace

Result<KeyRing> KeyRing::create(std::vector<KeyEntry> keys, std::uint8_t active_id) {
  if (keys.empty()) return Result<KeyRing>::fail("no keys");
  const bool per_sender = std::any_of(keys.begin(), keys.end(), [](const KeyEntry& k) { return k.kind != KeyKind::kGroupHmac; });
  if (per_sender) {
    if (const auto problem = perSenderProblem(keys)) return Result<KeyRing>::fail(*problem);
  }
  std::set<int> ids;
  bool have_active = false;
  for (const KeyEntry& k : keys) {
    if (std::isnan(k.accept_until_s)) return Result<KeyRing>::fail(keyName(k) + ": accept_until_s is NaN");
    if (k.kind == KeyKind::kVerifying) continue;
    if (ids.size() >= kMaxKeys) {
      return Result<KeyRing>::fail("too many " + std::string(per_sender ? "signing" : "") + (per_sender ? " " : "") +
                                   "keys: more than " + std::to_string(kMaxKeys));
    }
    if (!ids.insert(k.id).second) return Result<KeyRing>::fail("duplicate key id " + std::to_string(k.id));
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
    if (k.id == id && k.kind != KeyKind::kVerifying) return &k;
  }
  return nullptr;
}

const KeyEntry* KeyRing::findVerifying(std::uint16_t sender_id, std::uint8_t id) const {
  for (const KeyEntry& k : keys_) {
    if (k.kind == KeyKind::kVerifying && k.id == id && k.sender_id == sender_id) return &k;
  }
  return nullptr;
}

bool KeyRing::hasVerifyingKeyFor(std::uint16_t sender_id) const {
  return std::any_of(keys_.begin(), keys_.end(),
                     [&](const KeyEntry& k) { return k.kind == KeyKind::kVerifying && k.sender_id == sender_id; });
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
  std::size_t own_count = 0;        // group or signing keys
  std::size_t verifying_count = 0;
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
    if (words.size() < 2) return fail("expected '<key_id> <64 hex digits> [signing|verifying sender=<id>] [active] [accept_until_s=<s>]'");
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
    bool active = false;
    bool have_sender = false;
    for (std::size_t w = 2; w < words.size(); ++w) {
      const std::string& opt = words[w];
      static const std::string kUntil = "accept_until_s=";
      static const std::string kSender = "sender=";
      if (opt == "active") {
        active = true;
      } else if (opt == "signing" || opt == "verifying") {
        if (entry.kind != KeyKind::kGroupHmac) {
          secureZero(bytes.data(), bytes.size());
          return fail("key " + std::to_string(entry.id) + ": 'signing' or 'verifying' given twice");
        }
        entry.kind = opt == "signing" ? KeyKind::kSigning : KeyKind::kVerifying;
      } else if (opt.compare(0, kSender.size(), kSender) == 0) {
        const std::string value = opt.substr(kSender.size());
        char* end = nullptr;
        errno = 0;
        const unsigned long id = value.empty() || value[0] == '-' ? 70000UL : std::strtoul(value.c_str(), &end, 10);
        if (value.empty() || end != value.c_str() + value.size() || id > 65535UL || errno == ERANGE) {
          secureZero(bytes.data(), bytes.size());
          return fail("key " + std::to_string(entry.id) + ": sender must be a decimal id 0..65535");
        }
        entry.sender_id = static_cast<std::uint16_t>(id);
        have_sender = true;
      } else if (opt.compare(0, kUntil.size(), kUntil) == 0) {
        const std::string value = opt.substr(kUntil.size());
        char* end = nullptr;
        errno = 0;
        const double t = value.empty() ? std::nan("") : std::strtod(value.c_str(), &end);
        if (value.empty() || end != value.c_str() + value.size() || !std::isfinite(t) || errno == ERANGE) {
          secureZero(bytes.data(), bytes.size());
          return fail("key " + std::to_string(entry.id) + ": accept_until_s must be a finite number of seconds");
        }
        entry.accept_until_s = t;
      } else {
        // Not echoed: a mangled line may hold key material (found by fuzz_key_file).
        secureZero(bytes.data(), bytes.size());
        return fail("unknown option in word " + std::to_string(w + 1) +
                    " (expected 'active', 'signing', 'verifying', 'sender=<id>' or 'accept_until_s=<s>')");
      }
    }
    const std::string name = "key " + std::to_string(entry.id);
    if ((entry.kind != KeyKind::kGroupHmac) != have_sender) {
      secureZero(bytes.data(), bytes.size());
      return fail(name + ": 'sender=<id>' goes with 'signing' or 'verifying', and they need it");
    }
    if (entry.kind == KeyKind::kVerifying) {
      std::copy(bytes.begin(), bytes.end(), entry.public_key.begin());
      secureZero(bytes.data(), bytes.size());
      if (active) return fail(name + ": a verifying key cannot be 'active' (a node signs with its own signing key)");
      if (++verifying_count > kMaxVerifyingKeys) return fail("more than " + std::to_string(kMaxVerifyingKeys) + " verifying keys");
      keys.push_back(std::move(entry));
      continue;
    }
    if (++own_count > kMaxKeys) {
      secureZero(bytes.data(), bytes.size());
      return fail("more than " + std::to_string(kMaxKeys) + " keys");
    }
    if (entry.kind == KeyKind::kSigning) {
      auto signing = signingKey(entry.id, entry.sender_id, bytes);
      secureZero(bytes.data(), bytes.size());
      if (!signing) return fail(signing.reason());
      signing.value().accept_until_s = entry.accept_until_s;
      entry = std::move(signing.value());
    } else {
      entry.key = SecretKey(bytes);
      secureZero(bytes.data(), bytes.size());
    }
    if (active) {
      ++active_count;
      active_id = entry.id;
    }
    keys.push_back(std::move(entry));
  }
  // Whole-file problems: no line number.
  auto failFile = [&](const std::string& msg) { return Result<KeyRing>::fail(source + ": " + msg); };
  if (keys.empty()) return failFile("no keys");
  if (active_count > 1) return failFile("more than one key marked 'active'");
  if (active_count == 0) {
    if (own_count > 1) return failFile("several keys but none marked 'active'");
    for (const KeyEntry& k : keys) {
      if (k.kind != KeyKind::kVerifying) active_id = k.id;
    }
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
