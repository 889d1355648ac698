#pragma once
/// \file
/// \brief What a receiving node does with each authenticated envelope before it hands the content
/// on (the LcmBridge's receive side, docs/security.md §2–3), ROS-free: the payload decoded
/// (comm::PayloadDecoder: strict, every refusal counted), heartbeats decoded (and counted) but not handed on, plans (their
/// fallback flag on the wire with them, comm::PlanMessage) refused unless their
/// UAV is the envelope's sender and their t0 is not after the envelope's stamp, formation commands through
/// comm::CommandIntake (first copy of each id, name bound to the envelope sender), gesture
/// observations refused when the observing UAV is not the envelope's sender or the frame time is
/// not a valid time, abort commands handed on at every copy with sent_s = the envelope's stamp (the
/// UAV's ReplanStep acts on the first it accepts; docs/safety.md §2.8), command acknowledgements
/// handed on once per command id (the leader repeats them like commands; docs/safety.md §2.9),
/// leadership messages handed on at every copy when their `from` is the envelope's sender
/// (formation::Leadership tolerates duplicates; docs/safety.md §1.2), map updates handed on when
/// their uav_index is the envelope's sender (the receiver's live map checks them against its grid:
/// comm::checkMapUpdate; docs/mapping.md §8).
/// Thread safety: none (the caller's lock).

#include <cstdint>
#include <deque>
#include <set>
#include <string>
#include <tuple>
#include <variant>

#include "gesture_formation/comm/command_intake.hpp"
#include "gesture_formation/comm/envelope.hpp"
#include "gesture_formation/comm/map_update.hpp"
#include "gesture_formation/comm/payloads.hpp"

namespace gesture_formation::comm {

/// \brief What one envelope yields to hand on (monostate: nothing — a heartbeat, a command's copy,
/// a refusal).
using InboxItem = std::variant<std::monostate, WorkerStateMessage, PlanMessage, FormationParamsMessage,
                               formation::FormationCommand, GestureObservationMessage, planning::AbortCommand,
                               CommandAckMessage, AssistanceMessage, formation::LeadershipMessage, MapUpdate>;

class LinkInbox {
 public:
  /// \brief The content of an authenticated envelope to hand on (see the file comment).
  InboxItem take(const Envelope& envelope);

  /// \brief Why the last envelope yielded nothing (empty: it did or it was a heartbeat / copy).
  const std::string& lastRefusal() const { return last_refusal_; }
  /// \brief The last refusal was a payload that did not decode (the verifier counts those).
  bool lastWasDecodeFailure() const { return last_decode_failure_; }

  std::uint64_t commandCopiesDropped() const { return intake_.copiesDropped(); }
  std::uint64_t observationsRefused() const { return observations_refused_; }
  /// \brief Plans whose uav_index was not the envelope's sender, or whose t0 was later than the
  /// envelope's stamp + kPlanT0AllowanceS.
  std::uint64_t plansRefused() const { return plans_refused_; }
  /// \brief How far a plan's t0 may lie after its envelope's stamp [s]. Both are the sender's ROS
  /// time — the planner's t0 at its replanning, the bridge's stamp when it sends — but in separate
  /// processes under simulated time each reads /clock on its own, the bridge up to a few clock
  /// ticks behind (standalone nodelets in SITL); a t0 far ahead is still refused.
  static constexpr double kPlanT0AllowanceS = 0.5;
  /// \brief Leadership messages whose `from` was not the envelope's sender.
  std::uint64_t leadershipRefused() const { return leadership_refused_; }
  /// \brief Map updates whose uav_index was not the envelope's sender.
  std::uint64_t mapUpdatesRefused() const { return map_updates_refused_; }
  const PayloadCounters& payloadCounters() const { return decoder_.counters(); }

 private:
  InboxItem decodeOne(const Envelope& e);

  PayloadDecoder decoder_;
  CommandIntake intake_;
  /// The last kAckMemory acknowledgements handed on, by (link sender, command id): later copies
  /// from the same sender are dropped; another sender's ack of the same id is its own (one UAV
  /// cannot silence another's acknowledgement by sending it first).
  static constexpr std::size_t kAckMemory = 256;
  using AckKey = std::tuple<std::uint16_t, std::string, std::uint64_t>;
  std::set<AckKey> acks_seen_;
  std::deque<AckKey> acks_order_;
  std::uint64_t observations_refused_ = 0;
  std::uint64_t plans_refused_ = 0;
  std::uint64_t leadership_refused_ = 0;
  std::uint64_t map_updates_refused_ = 0;
  std::string last_refusal_;
  bool last_decode_failure_ = false;
};

}  // namespace gesture_formation::comm
