#pragma once
/// \file
/// \brief The receiving half of authenticated messaging: accepts an envelope only if it is
/// well formed, from a known sender, tagged with an accepted key, fresh and not a replay;
/// counts every rejection by kind (docs/security.md §4, §6).
///
/// Checks, in this order (the first failing one decides the verdict and its counter):
///   1. structure (parseEnvelope): kTruncated / kOversize / kBadVersion / kBadType / kMalformed
///   2. own sender id (our own multicast echo): kOwnMessage
///   3. sender id in the configured set: kUnknownSender
///   4. key: a group ring takes version 1 only and looks the key id up; a per-sender ring
///      takes version 2 only and looks up (sender id, key id) among the verifying keys —
///      otherwise kUnknownKey; still accepted at now (accept_until_s): kExpiredKey
///   4b. per-sender budget (token buckets, max_rate_hz / burst each) for envelopes that reach
///      the tag check: kRateLimited — a flood claiming a sender costs one cheap refusal, not a
///      signature verification, once the budget is spent. Two lanes per sender: sequence
///      numbers near the window (≤ kNearLane above the highest accepted, or inside the window:
///      where the sender's next envelopes are) and all others, so a flood with numbers that
///      are not the sender's next ones does not spend the budget its real envelopes use
///   5. tag: HMAC-SHA256 with constant-time compare (version 1) or the Ed25519 signature
///      with the claimed sender's public key (version 2): kForged
///   5b. authorisation: an authentic envelope of a type with a senders_by_type list from a
///      sender not on it: kNotPermitted
///   6. stamp age: now − stamp > max age of the type → kTooOld; stamp − now > max_future_s
///      (clock skew allowance) → kTooNew
///   7. replay window of the sender: duplicate → kReplayed; below the window → kStale
/// Only an accepted envelope changes state (the sender's replay window); a rejection
/// changes nothing but its counters (and a spent token of the sender's budget).
/// Counters exist in total and per *claimed* sender (configured senders only: an unknown id
/// or a structurally broken datagram counts in the totals alone). The claimed sender of a
/// refused envelope is unauthenticated: per-sender counts tell whose name is being used. Checks 1–4 run before any cryptography, so garbage costs
/// no HMAC; senders' windows exist from construction, so unauthenticated traffic cannot
/// allocate memory.
/// Thread safety: none; one Verifier per receiving thread.

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "gesture_formation/comm/envelope.hpp"
#include "gesture_formation/comm/key_ring.hpp"
#include "gesture_formation/comm/replay_window.hpp"
#include "gesture_formation/common/result.hpp"

namespace gesture_formation::common {
template <class Config>
struct FieldTable;
}  // namespace gesture_formation::common

namespace gesture_formation::comm {

/// \brief The outcome of Verifier::verify. Values index Counters.
enum class Verdict : std::uint8_t {
  kAccepted = 0,
  kTruncated,       ///< shorter than its header/length says
  kOversize,        ///< larger than the maximal envelope / payload
  kBadVersion,
  kBadType,         ///< unknown message type
  kMalformed,       ///< bad magic, reserved flags, trailing bytes, non-finite stamp
  kOwnMessage,      ///< our own sender id (multicast loopback); ignored
  kUnknownSender,
  kUnknownKey,
  kExpiredKey,      ///< key id known but past its accept_until_s
  kForged,          ///< tag does not verify
  kTooOld,
  kTooNew,
  kReplayed,        ///< sequence already accepted (within the window)
  kStale,           ///< sequence below the replay window
  kRateLimited,     ///< the claimed sender's verification budget is spent (flood)
  kNotPermitted,    ///< authentic, but this sender may not send this type (senders_by_type)
};
constexpr std::size_t kVerdictCount = 17;
/// \brief Sequence numbers up to this far above a sender's highest accepted one use its near lane.
constexpr std::uint64_t kNearLane = 64;
const char* toString(Verdict v);

/// \brief One counter per verdict.
struct VerifierCounters {
  std::array<std::uint64_t, kVerdictCount> by_verdict{};
  std::uint64_t count(Verdict v) const { return by_verdict[static_cast<std::size_t>(v)]; }
  std::uint64_t accepted() const { return count(Verdict::kAccepted); }
  /// Everything but kAccepted and kOwnMessage.
  std::uint64_t rejected() const;
  std::uint64_t total() const;
};

/// \brief Rejections of one claimed sender, by class.
struct SenderCounters {
  std::array<std::uint64_t, kVerdictCount> by_verdict{};
  std::uint64_t decode_failures = 0;  ///< accepted envelopes whose payload did not decode (PayloadDecoder)
  std::uint64_t count(Verdict v) const { return by_verdict[static_cast<std::size_t>(v)]; }
};

/// \brief Receiver policy. Defaults documented per field; validate() names the field.
struct VerifierConfig {
  std::vector<std::uint16_t> known_senders;  ///< sender ids accepted; non-empty, no default
  std::optional<std::uint16_t> own_sender_id;  ///< this node's id (its echoes are ignored)
  double max_age_s = 1.0;       ///< oldest acceptable stamp age [s], > 0
  double max_future_s = 0.25;   ///< clock skew allowance: stamp may lead now by this [s], ≥ 0
  /// Per-type overrides of max_age_s [s], each > 0 (e.g. heartbeat 2 s, command 5 s).
  std::map<MessageType, double> max_age_s_by_type;
  std::size_t replay_window = 1024;  ///< per sender [sequence numbers], 64..kMaxReplayWindow
  /// Who may send a type (e.g. commands: the ground station; parameters: the leader); a type
  /// not listed may come from any known sender; an empty list: from none. Known senders only.
  std::map<MessageType, std::vector<std::uint16_t>> senders_by_type;
  /// Per-sender budget of envelopes that reach the tag check [1/s], > 0. Default 400: ten
  /// times a UAV's normal rate (heartbeat, plan, worker state, observations, command copies).
  double max_rate_hz = 400.0;
  /// Depth of that budget [envelopes], ≥ 1 (a burst of this many passes at once).
  double burst = 200.0;

  /// \brief Every problem, each naming the field; empty when valid.
  std::vector<std::string> validate() const;
  double maxAgeS(MessageType type) const;
};

/// \brief VerifierConfig's numbers (`max_age_s` — also the range of every max_age_s_by_type
/// entry —, `max_future_s`, `max_rate_hz`, `burst`) with their ranges: the only place they are
/// written, used by validate() and by the LcmBridge nodelet's parameters.
const common::FieldTable<VerifierConfig>& verifierFields();

struct VerifyResult {
  Verdict verdict = Verdict::kMalformed;
  const char* detail = "";   ///< static text with the specific reason (never key material)
  Envelope envelope;         ///< filled only when accepted
  bool accepted() const { return verdict == Verdict::kAccepted; }
};

class Verifier {
 public:
  /// \brief Fails listing every config problem.
  static common::Result<Verifier> create(const VerifierConfig& config, KeyRing keys);

  /// \brief Runs the checks of the file comment on one datagram received at `now_s`
  /// (same clock as the senders' stamps). Never throws, never reads outside the buffer.
  VerifyResult verify(const std::uint8_t* data, std::size_t size, double now_s);

  /// \brief Replaces the accepted keys (rotation). Replay windows are kept.
  void setKeys(KeyRing keys) { keys_ = std::move(keys); }
  const KeyRing& keys() const { return keys_; }
  const VerifierCounters& counters() const { return counters_; }
  /// \brief Rejections per configured (claimed) sender id.
  std::map<std::uint16_t, SenderCounters> senderCounters() const;
  /// \brief Counts an accepted envelope of `sender_id` whose payload did not decode.
  void countDecodeFailure(std::uint16_t sender_id);
  /// \brief Highest accepted sequence number per sender that has sent anything.
  std::map<std::uint16_t, std::uint64_t> highWaterMarks() const;
  /// \brief After a restart: treats every number up to the saved mark of each configured
  /// sender as seen (unconfigured ids ignored; a mark below the current window ignored).
  void restoreHighWaterMarks(const std::map<std::uint16_t, std::uint64_t>& marks);
  const VerifierConfig& config() const { return config_; }
  /// \brief The replay window of a configured sender (nullptr for others).
  const ReplayWindow* window(std::uint16_t sender_id) const;

 private:
  Verifier(const VerifierConfig& config, KeyRing keys);
  /// A token bucket of verification budget.
  struct Budget {
    double tokens = 0.0;  ///< left [envelopes]
    double refilled_at_s = std::numeric_limits<double>::quiet_NaN();
  };
  struct SenderState {
    explicit SenderState(const VerifierConfig& c) : window(c.replay_window) {
      near.tokens = c.burst;
      far.tokens = c.burst;
    }
    ReplayWindow window;
    SenderCounters counters;
    Budget near;  ///< sequence numbers within the window or at most kNearLane above it
    Budget far;   ///< all others (a blind flood; a sender's first envelope after a restart)
  };
  VerifyResult reject(Verdict v, const char* detail, SenderState* sender = nullptr);
  bool takeToken(Budget& budget, double now_s) const;
  /// Checks 4–5: key lookup (group: by key id; per-sender: by (sender, key id)) and tag.
  VerifyResult checkTag(const EnvelopeView& view, double now_s, SenderState& sender);

  VerifierConfig config_;
  KeyRing keys_;
  std::map<std::uint16_t, SenderState> senders_;
  VerifierCounters counters_;
};

}  // namespace gesture_formation::comm
