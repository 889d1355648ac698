#pragma once
/// \file
/// \brief Pre-shared HMAC keys: a small ring of keys addressed by a one-byte key id, one of
/// them active for sending, and the key-file loader (docs/security.md §5).
///
/// Key file format (text, at most 4096 bytes, owner-only permissions):
/// ```
/// # comments and blank lines are ignored
/// <key_id> <64 hex digits = 32 bytes> [active] [accept_until_s=<seconds>]
/// ```
/// - key_id: decimal 0..255, unique; 1 to kMaxKeys lines.
/// - Exactly one key is `active` (the one this node signs with); a file with a single key
///   may omit the word. The active key may not carry `accept_until_s`.
/// - `accept_until_s`: the key is accepted on receive only while now ≤ that time (same clock
///   as envelope stamps); without it, for as long as it is in the file. This bounds the
///   rotation window without a second edit of every file.
///
/// Rotation (two keys accepted during the window, told apart by key id):
///   1. every node gets `<old> active` + `<new>` (receives both, still sends with old);
///   2. every node switches to `<old> accept_until_s=T` + `<new> active`;
///   3. after T (or by removing the old line) only the new key is accepted.
/// Thread safety: KeyRing is an immutable value after creation; share by const reference.

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "gesture_formation/comm/hmac.hpp"
#include "gesture_formation/common/result.hpp"

namespace gesture_formation::comm {

/// \brief Maximal number of keys in a ring (a rotation needs two).
constexpr std::size_t kMaxKeys = 4;
/// \brief Maximal size of a key file [bytes].
constexpr std::size_t kMaxKeyFileBytes = 4096;

/// \brief A 32-byte secret, wiped from memory when destroyed.
class SecretKey {
 public:
  SecretKey() { bytes_.fill(0); }
  explicit SecretKey(const std::array<std::uint8_t, kKeyBytes>& bytes) : bytes_(bytes) {}
  SecretKey(const SecretKey&) = default;
  SecretKey& operator=(const SecretKey&) = default;
  ~SecretKey() { secureZero(bytes_.data(), bytes_.size()); }

  const std::uint8_t* data() const { return bytes_.data(); }
  static constexpr std::size_t size() { return kKeyBytes; }

 private:
  std::array<std::uint8_t, kKeyBytes> bytes_;
};

/// \brief One key of the ring.
struct KeyEntry {
  std::uint8_t id = 0;
  SecretKey key;
  /// Accepted on receive while now_s ≤ accept_until_s (+inf: no limit).
  double accept_until_s = std::numeric_limits<double>::infinity();
};

/// \brief The keys a node accepts and the one it signs with.
class KeyRing {
 public:
  /// \brief Fails naming the problem: no keys, more than kMaxKeys, duplicate ids, unknown
  /// active id, an active key with a finite accept_until_s, NaN accept_until_s.
  static common::Result<KeyRing> create(std::vector<KeyEntry> keys, std::uint8_t active_id);

  /// \brief The key with this id, or nullptr.
  const KeyEntry* find(std::uint8_t id) const;
  const KeyEntry& active() const { return *find(active_id_); }
  std::uint8_t activeId() const { return active_id_; }
  const std::vector<KeyEntry>& keys() const { return keys_; }

 private:
  KeyRing(std::vector<KeyEntry> keys, std::uint8_t active_id) : keys_(std::move(keys)), active_id_(active_id) {}
  std::vector<KeyEntry> keys_;
  std::uint8_t active_id_ = 0;
};

/// \brief Parses key-file text (format in the file comment). Errors read
/// "<source>:<line>: <problem>" and never echo key material.
common::Result<KeyRing> parseKeyFileText(const std::string& text, const std::string& source);

/// \brief Loads a key file after checking it: it exists and is a regular file, is owned by
/// this user (or root), grants no permission to group or others (mode & 077 == 0; fix with
/// `chmod 600 <path>`), is at most kMaxKeyFileBytes, and parses. The checks run on the open
/// descriptor (fstat), so the file checked is the file read. Errors name the path and the
/// problem.
common::Result<KeyRing> loadKeyFile(const std::string& path);

}  // namespace gesture_formation::comm
