#include "gesture_formation/comm/verifier.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::comm {

const char* toString(Verdict v) {
  switch (v) {
    case Verdict::kAccepted: return "accepted";
    case Verdict::kTruncated: return "truncated";
    case Verdict::kOversize: return "oversize";
    case Verdict::kBadVersion: return "bad_version";
    case Verdict::kBadType: return "bad_type";
    case Verdict::kMalformed: return "malformed";
    case Verdict::kOwnMessage: return "own_message";
    case Verdict::kUnknownSender: return "unknown_sender";
    case Verdict::kUnknownKey: return "unknown_key";
    case Verdict::kExpiredKey: return "expired_key";
    case Verdict::kForged: return "forged";
    case Verdict::kTooOld: return "too_old";
    case Verdict::kTooNew: return "too_new";
    case Verdict::kReplayed: return "replayed";
    case Verdict::kStale: return "stale";
    case Verdict::kRateLimited: return "rate_limited";
    case Verdict::kNotPermitted: return "not_permitted";
  }
  return "unknown";
}

std::uint64_t VerifierCounters::total() const {
  std::uint64_t t = 0;
  for (std::uint64_t c : by_verdict) t += c;
  return t;
}

std::uint64_t VerifierCounters::rejected() const {
  return total() - count(Verdict::kAccepted) - count(Verdict::kOwnMessage);
}

const common::FieldTable<VerifierConfig>& verifierFields() {
  using C = VerifierConfig;
  using common::Range;
  static const common::FieldTable<VerifierConfig> t{{
      {"max_age_s", Range::closed(0.01, 60.0), [](C& c) { return &c.max_age_s; }},
      {"max_future_s", Range::nonNegative(), [](C& c) { return &c.max_future_s; }},
      {"max_rate_hz", Range::positive(), [](C& c) { return &c.max_rate_hz; }},
      {"burst", Range::atLeast(1.0), [](C& c) { return &c.burst; }},
  }};
  return t;
}

std::vector<std::string> VerifierConfig::validate() const {
  std::vector<std::string> e;
  if (known_senders.empty()) e.push_back("known_senders must list at least one sender id");
  std::set<std::uint16_t> seen;
  for (std::uint16_t s : known_senders) {
    if (!seen.insert(s).second) e.push_back("known_senders lists sender id " + std::to_string(s) + " twice");
    if (own_sender_id && *own_sender_id == s) {
      e.push_back("known_senders must not contain own_sender_id " + std::to_string(s));
    }
  }
  for (auto& line : common::problemLines(verifierFields().rangeProblems(*this))) e.push_back(line);
  const common::Range& age_range = *verifierFields().rangeOf("max_age_s");
  for (const auto& [type, age] : max_age_s_by_type) {
    if (!isKnownMessageType(static_cast<std::uint8_t>(type))) {
      e.push_back("max_age_s_by_type has an unknown message type");
    } else if (!age_range.contains(age)) {
      e.push_back(std::string("max_age_s_by_type.") + toString(type) + " " + common::rangeProblem(age_range, age));
    }
  }
  for (const auto& [type, senders] : senders_by_type) {
    const std::string field = std::string("senders_by_type.") + (isKnownMessageType(static_cast<std::uint8_t>(type)) ? toString(type) : "?");
    for (std::uint16_t id : senders) {
      if (!seen.count(id)) e.push_back(field + " lists sender id " + std::to_string(id) + ", which is not in known_senders");
    }
  }
  if (replay_window < 64 || replay_window > kMaxReplayWindow) {
    e.push_back("replay_window must be in [64, " + std::to_string(kMaxReplayWindow) + "], got " +
                std::to_string(replay_window));
  }
  return e;
}

double VerifierConfig::maxAgeS(MessageType type) const {
  const auto it = max_age_s_by_type.find(type);
  return it == max_age_s_by_type.end() ? max_age_s : it->second;
}

common::Result<Verifier> Verifier::create(const VerifierConfig& config, KeyRing keys) {
  std::vector<std::string> problems = config.validate();
  if (keys.perSender()) {
    for (std::uint16_t s : config.known_senders) {
      if (!keys.hasVerifyingKeyFor(s)) {
        problems.push_back("known sender " + std::to_string(s) + " has no verifying key in the key ring");
      }
    }
  }
  if (!problems.empty()) {
    std::string reason;
    for (const std::string& p : problems) reason += (reason.empty() ? "" : "\n") + p;
    return common::Result<Verifier>::fail(reason);
  }
  return common::Result<Verifier>::ok(Verifier(config, std::move(keys)));
}

Verifier::Verifier(const VerifierConfig& config, KeyRing keys) : config_(config), keys_(std::move(keys)) {
  for (std::uint16_t s : config_.known_senders) senders_.emplace(s, SenderState(config_));
}

const ReplayWindow* Verifier::window(std::uint16_t sender_id) const {
  const auto it = senders_.find(sender_id);
  return it == senders_.end() ? nullptr : &it->second.window;
}

std::map<std::uint16_t, SenderCounters> Verifier::senderCounters() const {
  std::map<std::uint16_t, SenderCounters> out;
  for (const auto& [id, state] : senders_) out.emplace(id, state.counters);
  return out;
}

void Verifier::countDecodeFailure(std::uint16_t sender_id) {
  const auto it = senders_.find(sender_id);
  if (it != senders_.end()) ++it->second.counters.decode_failures;
}

std::map<std::uint16_t, std::uint64_t> Verifier::highWaterMarks() const {
  std::map<std::uint16_t, std::uint64_t> out;
  for (const auto& [id, state] : senders_) {
    if (!state.window.empty()) out.emplace(id, state.window.highest());
  }
  return out;
}

void Verifier::restoreHighWaterMarks(const std::map<std::uint16_t, std::uint64_t>& marks) {
  for (const auto& [id, mark] : marks) {
    const auto it = senders_.find(id);
    if (it != senders_.end()) it->second.window.markSeenUpTo(mark);
  }
}

bool Verifier::takeToken(Budget& budget, double now_s) const {
  if (std::isfinite(now_s)) {
    // A clock that jumps back (simulation restart) only restarts the refill.
    if (std::isfinite(budget.refilled_at_s) && now_s > budget.refilled_at_s) {
      budget.tokens = std::min(config_.burst, budget.tokens + (now_s - budget.refilled_at_s) * config_.max_rate_hz);
    }
    budget.refilled_at_s = now_s;
  }
  if (budget.tokens < 1.0) return false;
  budget.tokens -= 1.0;
  return true;
}

VerifyResult Verifier::reject(Verdict v, const char* detail, SenderState* sender) {
  ++counters_.by_verdict[static_cast<std::size_t>(v)];
  if (sender != nullptr) ++sender->counters.by_verdict[static_cast<std::size_t>(v)];
  VerifyResult r;
  r.verdict = v;
  r.detail = detail;
  return r;
}

VerifyResult Verifier::checkTag(const EnvelopeView& view, double now_s, SenderState& sender) {
  const bool per_sender = keys_.perSender();
  if (per_sender != (view.version == kEnvelopeVersionEd25519)) {
    return reject(Verdict::kUnknownKey, per_sender ? "group-key envelope (version 1); this node accepts per-sender signatures only"
                                                   : "per-sender envelope (version 2); this node holds a group key only",
                  &sender);
  }
  const KeyEntry* key = per_sender ? keys_.findVerifying(view.sender_id, view.key_id) : keys_.find(view.key_id);
  if (key == nullptr) return reject(Verdict::kUnknownKey, per_sender ? "no such key id for this sender" : "key id not in the key ring", &sender);
  // (A NaN now_s passes here and fails the age check after the tag.)
  if (now_s > key->accept_until_s) return reject(Verdict::kExpiredKey, "key past its accept_until_s", &sender);
  const ReplayWindow& w = sender.window;
  const bool near = !w.empty() && view.sequence <= w.highest() + kNearLane && view.sequence + w.size() > w.highest();
  if (!takeToken(near ? sender.near : sender.far, now_s)) {
    return reject(Verdict::kRateLimited, "sender's verification budget spent", &sender);
  }
  if (per_sender) {
    if (!ed25519Verify(key->public_key, view.signed_bytes, view.signed_size, view.tag)) {
      return reject(Verdict::kForged, "signature does not verify with the sender's key", &sender);
    }
  } else {
    Tag tag{};
    if (!hmacSha256(key->key.data(), key->key.size(), view.signed_bytes, view.signed_size, tag) ||
        !constantTimeEqual(tag.data(), view.tag, kTagBytes)) {
      return reject(Verdict::kForged, "tag does not verify", &sender);
    }
  }
  VerifyResult ok;
  ok.verdict = Verdict::kAccepted;
  return ok;
}

VerifyResult Verifier::verify(const std::uint8_t* data, std::size_t size, double now_s) {
  EnvelopeView view;
  const EnvelopeError error = parseEnvelope(data, size, view);
  switch (error) {
    case EnvelopeError::kNone: break;
    case EnvelopeError::kTruncated: return reject(Verdict::kTruncated, toString(error));
    case EnvelopeError::kOversize: return reject(Verdict::kOversize, toString(error));
    case EnvelopeError::kBadVersion: return reject(Verdict::kBadVersion, toString(error));
    case EnvelopeError::kBadType: return reject(Verdict::kBadType, toString(error));
    case EnvelopeError::kBadMagic:
    case EnvelopeError::kBadFlags:
    case EnvelopeError::kLengthMismatch:
    case EnvelopeError::kBadStamp: return reject(Verdict::kMalformed, toString(error));
  }
  if (config_.own_sender_id && view.sender_id == *config_.own_sender_id) {
    return reject(Verdict::kOwnMessage, "own sender id");
  }
  const auto sender_it = senders_.find(view.sender_id);
  if (sender_it == senders_.end()) return reject(Verdict::kUnknownSender, "sender id not configured");
  SenderState& sender = sender_it->second;
  const VerifyResult keyed = checkTag(view, now_s, sender);
  if (keyed.verdict != Verdict::kAccepted) return keyed;
  const auto allowed = config_.senders_by_type.find(view.type);
  if (allowed != config_.senders_by_type.end() &&
      std::find(allowed->second.begin(), allowed->second.end(), view.sender_id) == allowed->second.end()) {
    return reject(Verdict::kNotPermitted, "this sender may not send this message type", &sender);
  }

  // Written so that a NaN now_s fails the checks (counted too old).
  const double age_s = now_s - view.stamp_s;
  if (!(age_s <= config_.maxAgeS(view.type))) return reject(Verdict::kTooOld, "stamp older than the maximal age", &sender);
  if (!(-age_s <= config_.max_future_s)) return reject(Verdict::kTooNew, "stamp ahead of now by more than max_future_s", &sender);

  ReplayWindow& window = sender.window;
  switch (window.check(view.sequence)) {
    case ReplayWindow::Check::kNew: break;
    case ReplayWindow::Check::kDuplicate: return reject(Verdict::kReplayed, "sequence already accepted", &sender);
    case ReplayWindow::Check::kTooOld: return reject(Verdict::kStale, "sequence below the replay window", &sender);
  }

  VerifyResult r;
  r.verdict = Verdict::kAccepted;
  static_cast<EnvelopeHeader&>(r.envelope) = view;  // the header as parsed and authenticated
  r.envelope.payload.assign(view.payload, view.payload + view.payload_bytes);
  window.accept(view.sequence);
  ++counters_.by_verdict[static_cast<std::size_t>(Verdict::kAccepted)];
  ++sender.counters.by_verdict[static_cast<std::size_t>(Verdict::kAccepted)];
  return r;
}

}  // namespace gesture_formation::comm
