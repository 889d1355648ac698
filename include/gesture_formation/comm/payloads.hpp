#pragma once
/// \file
/// \brief Payload codecs for the messages UAVs exchange (docs/security.md §3.2 has the byte
/// tables). Integers big-endian, doubles IEEE-754 binary64 big-endian, no padding.
///
/// Encoders refuse what decoders would refuse (non-finite numbers, oversize arrays, values
/// out of range), so a node never sends what its peers must drop. Decoders are strict: the
/// payload must be consumed exactly, every double finite, every array within its maximum,
/// every enum value known; the output is written only on success.
/// Thread safety: free functions are reentrant; PayloadDecoder has no locking.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "gesture_formation/comm/envelope.hpp"
#include "gesture_formation/common/result.hpp"
#include "gesture_formation/formation/assistance.hpp"
#include "gesture_formation/formation/formation_commands.hpp"
#include "gesture_formation/formation/formation_params.hpp"
#include "gesture_formation/formation/leadership.hpp"
#include "gesture_formation/gesture/view_triangulation.hpp"
#include "gesture_formation/planning/abort_mode.hpp"
#include "gesture_formation/planning/planned_trajectory.hpp"

namespace gesture_formation::comm {

/// Largest number of samples in a planned trajectory (88 bytes each: 52.8 kB < kMaxPayloadBytes).
constexpr std::size_t kMaxTrajectorySamples = 600;
/// Largest UAV index on the wire (leader 0, followers 1..kMaxUavIndex).
constexpr int kMaxUavIndex = 31;
constexpr std::size_t kMaxFollowers = kMaxUavIndex;
/// Largest number of UAVs listed in one command target.
constexpr std::size_t kMaxCommandTargets = kMaxUavIndex + 1;
/// Largest command sender name [bytes]; printable ASCII without spaces (0x21..0x7e).
constexpr std::size_t kMaxSenderNameBytes = 64;
/// Longest operator name: the leader hands an operator's command on (and acknowledges it) as
/// NAME@ID, ID the link sender (≤ 65535), which must fit kMaxSenderNameBytes.
constexpr std::size_t kMaxOperatorNameBytes = kMaxSenderNameBytes - 6;

/// \brief The parameter owner's formation parameters and their version: the commands applied since
/// the mission's start, carried on by a new leader from the version it held (docs/safety.md §1.2),
/// so a follower, the operator's acknowledgements and every UAV's plan name one sequence of versions.
struct FormationParamsMessage {
  formation::FormationParams params;
  std::uint64_t version = 0;
};

/// \brief One UAV's plan as it goes on the link: the trajectory and whether it is a fallback (the
/// last verified plan re-flown or a brake plan, not this replanning's optimised one). Receivers with
/// `avoid_all_plans: false` avoid a lower-priority UAV's plan only when it is a fallback
/// (planning::buildPlanRequest), so the flag travels with the plan itself: a heartbeat naming it
/// can be lost or arrive after it.
struct PlanMessage {
  planning::PlannedTrajectory plan;
  bool fallback = false;
};

/// \brief Liveness of one UAV, sent periodically (e.g. 5 Hz).
struct Heartbeat {
  enum class Status : std::uint8_t { kOk = 0, kDegraded = 1, kFailsafe = 2, kLanding = 3 };
  std::uint16_t uav_index = 0;           ///< 0 = leader, ≤ kMaxUavIndex
  Status status = Status::kOk;
  bool worker_visible = false;           ///< the worker is in this UAV's camera / estimate
  std::uint32_t last_plan_sequence = 0;  ///< PlannedTrajectory::sequence of the last plan sent
};

/// \brief The leader's worker estimate (design.md §3): state at t_s with the covariance diagonal.
struct WorkerStateMessage {
  double t_s = 0.0;
  /// When the estimator last fused a measurement [s], ≤ t_s: the estimate's age for the hold rule
  /// (docs/safety.md §1 rule 2: max_worker_age_s) is t_now − last_fused_t_s.
  double last_fused_t_s = 0.0;
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();  ///< [m] ENU
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();  ///< [m/s] ENU
  /// pxx, pyy, pzz [m²], pvxx, pvyy, pvzz [(m/s)²]; each ≥ 0.
  std::array<double, 6> covariance_diag{{0, 0, 0, 0, 0, 0}};
  bool lost = false;  ///< estimator reports the worker lost (prediction only, timed out)
};

/// \brief A skeleton with its camera as it travels: the orientation as a quaternion, sent as
/// given, so that decode and encode are inverse (the codec is a bijection on valid input).
struct ObservedSkeleton {
  gesture::Skeleton2D skeleton;  ///< keypoints [px] and confidences; the box is not sent
  Eigen::Quaterniond q_world_camera = Eigen::Quaterniond::Identity();  ///< optical frame → world, norm 1 ± 1e-6
  Eigen::Vector3d p_world_camera = Eigen::Vector3d::Zero();            ///< optical centre [m]
  estimation::CameraIntrinsics intrinsics;                              ///< width, height ≤ 65535

  /// As the triangulation takes it (R from the normalised quaternion).
  gesture::CalibratedSkeleton calibrated() const;
  /// Every problem (quaternion norm, image size, and gesture::validate of calibrated()).
  std::vector<std::string> validate() const;
};

/// \brief One UAV's gesture classification of one camera frame with that camera's geometry to
/// the worker estimate (the multi-view vote, gesture::ViewObservation; docs/gestures.md §4.1).
/// The sender's id, sequence and send stamp are the envelope's.
struct GestureObservationMessage {
  std::uint16_t uav_index = 0;      ///< the observing UAV, ≤ kMaxUavIndex (0 = leader)
  double t_s = 0.0;                 ///< the frame's time [s]
  std::uint8_t gesture_id = 0;      ///< the classifier's argmax, ≤ kMaxGestureId
  std::vector<double> probabilities;  ///< class probabilities, each in [0, 1], ≤ kMaxGestureClasses
  bool geometry_known = false;      ///< false: no worker estimate / odometry (the view cannot vote)
  double distance_m = 0.0;          ///< camera → worker estimate [m], [0, kMaxObservationDistanceM]
  double elevation_deg = 0.0;       ///< camera above the worker estimate [deg], [−90, 90]
  /// The frame's skeleton with the camera that saw it, for view_fusion.confirm_3d; absent: the
  /// view takes no part in the 3-D confirmation.
  std::optional<ObservedSkeleton> skeleton;
};

/// \brief An abort command as it travels (docs/safety.md §2.8): the command's id and who issued it.
/// When it was sent is the envelope's stamp (each copy — the sender's repeats, every UAV's relay of
/// the abort it accepted — is a new envelope, stamped when sent: planning::AbortCommand::sent_s); replays are
/// the envelope's to refuse (sequence, age).
struct AbortMessage {
  formation::CommandId id;  ///< sender name (1..kMaxSenderNameBytes printable ASCII, no spaces), sequence
  planning::AbortSource source = planning::AbortSource::kOperator;

  /// \brief The command as a UAV's ReplanStep takes it, sent at `sent_s` (the envelope's stamp).
  planning::AbortCommand command(double sent_s) const { return planning::AbortCommand{id, source, sent_s}; }
};

/// Largest outcome text of a command acknowledgement [bytes].
constexpr std::size_t kMaxAckOutcomeBytes = 255;

/// \brief The leader's acknowledgement of a formation command it handled (docs/safety.md §2.9):
/// which command, what became of it and the parameter version it left. Sent by the parameter owner
/// (link setting params_senders) like a command: repeated, acted on once per id.
struct CommandAckMessage {
  formation::CommandId id;  ///< the command's id (sender name as in the command, sequence)
  formation::CommandSource source = formation::CommandSource::kOperator;
  formation::CommandStatus status = formation::CommandStatus::kRejected;
  std::uint64_t params_version = 0;  ///< the leader's parameter version after handling it
  double command_stamp_s = 0.0;      ///< the command's stamp (sent by the operator / fired by the gesture filter)
  /// formation::CommandOutcome::describe() (status, reason, clamps): 0..kMaxAckOutcomeBytes bytes,
  /// UTF-8 text without control characters.
  std::string outcome;
};

/// \brief The worker's request for assistance as it travels (docs/safety.md §2.10): the leader's
/// state (sent on every change and with every worker state while requested) and the operator's
/// acknowledgement (phase kAcknowledged, from the ground station, repeated like a command). From the
/// params_senders and the command_senders only. Names: 0..kMaxSenderNameBytes printable ASCII
/// without spaces.
struct AssistanceMessage {
  formation::AssistanceState state;
};

/// Largest gesture id and number of class probabilities on the wire.
constexpr int kMaxGestureId = 15;
constexpr std::size_t kMaxGestureClasses = 16;
/// Largest camera → worker distance on the wire [m].
constexpr double kMaxObservationDistanceM = 1000.0;

/// \brief Why a payload was refused. Values index PayloadCounters.
enum class PayloadError : std::uint8_t {
  kNone = 0,
  kWrongType,      ///< envelope type is not the one asked for
  kTruncated,      ///< fewer bytes than the fields need
  kTrailingBytes,  ///< bytes left after the last field
  kNonFinite,      ///< a NaN or ±inf double
  kOversizeArray,  ///< an element count above its maximum
  kOutOfRange,     ///< an enum, index, count, string or physical value outside its domain
};
constexpr std::size_t kPayloadErrorCount = 7;
const char* toString(PayloadError e);

// ---- encoders: fail naming the field on what a decoder would refuse ----------------------
common::Result<std::vector<std::uint8_t>> encodePayload(const Heartbeat& m);
common::Result<std::vector<std::uint8_t>> encodePayload(const WorkerStateMessage& m);
common::Result<std::vector<std::uint8_t>> encodePayload(const PlanMessage& m);
common::Result<std::vector<std::uint8_t>> encodePayload(const FormationParamsMessage& m);
common::Result<std::vector<std::uint8_t>> encodePayload(const formation::FormationCommand& m);
common::Result<std::vector<std::uint8_t>> encodePayload(const GestureObservationMessage& m);
common::Result<std::vector<std::uint8_t>> encodePayload(const AbortMessage& m);
common::Result<std::vector<std::uint8_t>> encodePayload(const CommandAckMessage& m);
common::Result<std::vector<std::uint8_t>> encodePayload(const AssistanceMessage& m);
/// A leadership message (docs/safety.md §1.2): `to` −1 (broadcast) or 0..kMaxUavIndex, `from`
/// 0..kMaxUavIndex, times finite, lease_age_s ≥ 0, estimate_age_s ≥ 0 or +inf (none).
common::Result<std::vector<std::uint8_t>> encodePayload(const formation::LeadershipMessage& m);

/// \brief The envelope type of each payload.
inline MessageType messageTypeOf(const Heartbeat&) { return MessageType::kHeartbeat; }
inline MessageType messageTypeOf(const WorkerStateMessage&) { return MessageType::kWorkerState; }
inline MessageType messageTypeOf(const PlanMessage&) { return MessageType::kPlannedTrajectory; }
inline MessageType messageTypeOf(const FormationParamsMessage&) { return MessageType::kFormationParams; }
inline MessageType messageTypeOf(const formation::FormationCommand&) { return MessageType::kFormationCommand; }
inline MessageType messageTypeOf(const GestureObservationMessage&) { return MessageType::kGestureObservation; }
inline MessageType messageTypeOf(const AbortMessage&) { return MessageType::kAbortCommand; }
inline MessageType messageTypeOf(const CommandAckMessage&) { return MessageType::kCommandAck; }
inline MessageType messageTypeOf(const AssistanceMessage&) { return MessageType::kAssistance; }
inline MessageType messageTypeOf(const formation::LeadershipMessage&) { return MessageType::kLeadership; }

// ---- decoders: `out` written only on kNone; `reason` (optional) names the field ---------
PayloadError decodePayload(const std::uint8_t* data, std::size_t size, Heartbeat& out, std::string* reason = nullptr);
PayloadError decodePayload(const std::uint8_t* data, std::size_t size, WorkerStateMessage& out,
                           std::string* reason = nullptr);
PayloadError decodePayload(const std::uint8_t* data, std::size_t size, PlanMessage& out,
                           std::string* reason = nullptr);
PayloadError decodePayload(const std::uint8_t* data, std::size_t size, FormationParamsMessage& out,
                           std::string* reason = nullptr);
PayloadError decodePayload(const std::uint8_t* data, std::size_t size, formation::FormationCommand& out,
                           std::string* reason = nullptr);
PayloadError decodePayload(const std::uint8_t* data, std::size_t size, GestureObservationMessage& out,
                           std::string* reason = nullptr);
PayloadError decodePayload(const std::uint8_t* data, std::size_t size, AbortMessage& out, std::string* reason = nullptr);
PayloadError decodePayload(const std::uint8_t* data, std::size_t size, CommandAckMessage& out,
                           std::string* reason = nullptr);
PayloadError decodePayload(const std::uint8_t* data, std::size_t size, AssistanceMessage& out,
                           std::string* reason = nullptr);
PayloadError decodePayload(const std::uint8_t* data, std::size_t size, formation::LeadershipMessage& out,
                           std::string* reason = nullptr);

/// \brief One counter per PayloadError (kNone counts successful decodes).
struct PayloadCounters {
  std::array<std::uint64_t, kPayloadErrorCount> by_error{};
  std::uint64_t count(PayloadError e) const { return by_error[static_cast<std::size_t>(e)]; }
  std::uint64_t decoded() const { return count(PayloadError::kNone); }
  std::uint64_t rejected() const;
};

/// \brief Decodes the payloads of authenticated envelopes and counts every refusal.
class PayloadDecoder {
 public:
  /// \brief Checks the envelope type, then decodes; false (and a counter) on any error.
  template <class T>
  bool decode(const Envelope& envelope, T& out) {
    T tmp{};
    if (envelope.type != messageTypeOf(tmp)) {
      last_reason_ = std::string("envelope type ") + toString(envelope.type) + ", expected " +
                     toString(messageTypeOf(tmp));
      return record(PayloadError::kWrongType);
    }
    const PayloadError e = decodePayload(envelope.payload.data(), envelope.payload.size(), tmp, &last_reason_);
    if (e == PayloadError::kNone) out = std::move(tmp);
    return record(e);
  }

  const PayloadCounters& counters() const { return counters_; }
  /// \brief Why the last decode failed (names the field).
  const std::string& lastReason() const { return last_reason_; }

 private:
  bool record(PayloadError e) {
    ++counters_.by_error[static_cast<std::size_t>(e)];
    if (e == PayloadError::kNone) last_reason_.clear();
    return e == PayloadError::kNone;
  }
  PayloadCounters counters_;
  std::string last_reason_;
};

}  // namespace gesture_formation::comm
