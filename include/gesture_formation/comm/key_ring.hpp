#pragma once
/// \file
/// \brief The keys a node signs and verifies with, addressed by a one-byte key id, one of
/// them active for sending, and the key-file loader (docs/security.md §5).
///
/// Two kinds of ring, never mixed:
/// - **group** (envelope version 1): pre-shared HMAC keys, the same for every node; any
///   holder can claim any sender id;
/// - **per-sender** (envelope version 2): this node's Ed25519 signing key(s) and the
///   verifying (public) keys of every sender it accepts, each bound to a sender id; a
///   message verifies only with its claimed sender's key.
///
/// Key file format (text, at most kMaxKeyFileBytes, owner-only permissions):
/// ```
/// # comments and blank lines are ignored
/// <key_id> <64 hex digits = 32 bytes> [active] [accept_until_s=<seconds>]          group HMAC key
/// <key_id> <64 hex digits = Ed25519 secret seed> signing sender=<id> [active]       this node's key
/// <key_id> <64 hex digits = Ed25519 public key> verifying sender=<id> [accept_until_s=<seconds>]
/// ```
/// - key_id: decimal 0..255; unique among group / signing keys, unique per sender among
///   verifying keys; 1 to kMaxKeys group or signing lines, at most kMaxVerifyingKeys verifying.
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
/// A per-sender rotation is the same three steps with `verifying sender=<id>` lines for the
/// sender whose key changes and its own `signing` lines.
/// Thread safety: KeyRing is an immutable value after creation; share by const reference.

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "gesture_formation/comm/ed25519.hpp"
#include "gesture_formation/comm/hmac.hpp"
#include "gesture_formation/common/result.hpp"

namespace gesture_formation::comm {

/// \brief Maximal number of group or signing keys in a ring (a rotation needs two).
constexpr std::size_t kMaxKeys = 4;
/// \brief Maximal number of verifying keys (33 senders × 2 during a rotation, with room).
constexpr std::size_t kMaxVerifyingKeys = 128;
/// \brief Maximal size of a key file [bytes].
constexpr std::size_t kMaxKeyFileBytes = 32768;

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

/// \brief What a key is for.
enum class KeyKind : std::uint8_t {
  kGroupHmac,   ///< pre-shared HMAC-SHA256 key, signs and verifies every sender (version 1)
  kSigning,     ///< this node's Ed25519 secret seed (version 2); `public_key` derived from it
  kVerifying,   ///< a sender's Ed25519 public key (version 2); `key` unused (zero)
};
const char* toString(KeyKind kind);

/// \brief One key of the ring.
struct KeyEntry {
  std::uint8_t id = 0;
  KeyKind kind = KeyKind::kGroupHmac;
  SecretKey key;            ///< group HMAC key or Ed25519 seed
  PublicKey public_key{};   ///< kSigning / kVerifying
  std::uint16_t sender_id = 0;  ///< kSigning / kVerifying: the sender the key belongs to
  /// Accepted on receive while now_s ≤ accept_until_s (+inf: no limit). Not for kSigning.
  double accept_until_s = std::numeric_limits<double>::infinity();
};

/// \brief A signing key for `sender_id` from an Ed25519 seed (its public key derived), or the
/// OpenSSL failure.
common::Result<KeyEntry> signingKey(std::uint8_t id, std::uint16_t sender_id,
                                    const std::array<std::uint8_t, kKeyBytes>& seed);
/// \brief The verifying key that matches a signing key (for distributing to the receivers).
KeyEntry verifyingKeyOf(const KeyEntry& signing, double accept_until_s = std::numeric_limits<double>::infinity());

/// \brief The keys a node accepts and the one it signs with.
class KeyRing {
 public:
  /// \brief Fails naming the problem: no keys, more than kMaxKeys, duplicate ids, unknown
  /// active id, an active key with a finite accept_until_s, NaN accept_until_s; group keys
  /// mixed with per-sender keys; no signing key, signing keys of two senders, an active
  /// verifying key, a signing key with accept_until_s, more than kMaxVerifyingKeys.
  static common::Result<KeyRing> create(std::vector<KeyEntry> keys, std::uint8_t active_id);

  /// \brief The group or signing key with this id, or nullptr.
  const KeyEntry* find(std::uint8_t id) const;
  /// \brief Per-sender ring: the verifying key (sender_id, id), or nullptr.
  const KeyEntry* findVerifying(std::uint16_t sender_id, std::uint8_t id) const;
  /// \brief True for a per-sender (Ed25519) ring, false for a group (HMAC) ring.
  bool perSender() const { return keys_.front().kind != KeyKind::kGroupHmac; }
  /// \brief Whether some verifying key belongs to `sender_id` (per-sender ring).
  bool hasVerifyingKeyFor(std::uint16_t sender_id) const;
  const KeyEntry& active() const { return *find(active_id_); }
  std::uint8_t activeId() const { return active_id_; }
  const std::vector<KeyEntry>& keys() const { return keys_; }

 private:
  KeyRing(std::vector<KeyEntry> keys, std::uint8_t active_id) : keys_(std::move(keys)), active_id_(active_id) {}
  std::vector<KeyEntry> keys_;
  std::uint8_t active_id_ = 0;
};

/// \brief Parses key-file text (format in the file comment). Errors read
/// "<source>:<line>: <problem>" and never echo key material. A `signing` line's public key is
/// derived from its seed.
common::Result<KeyRing> parseKeyFileText(const std::string& text, const std::string& source);

/// \brief Loads a key file after checking it: it exists and is a regular file, is owned by
/// this user (or root), grants no permission to group or others (mode & 077 == 0; fix with
/// `chmod 600 <path>`), is at most kMaxKeyFileBytes, and parses. The checks run on the open
/// descriptor (fstat), so the file checked is the file read. Errors name the path and the
/// problem.
common::Result<KeyRing> loadKeyFile(const std::string& path);

}  // namespace gesture_formation::comm
