#pragma once
/// \file
/// \brief Leader hand-over (docs/safety.md §1.2): which UAV leads, decided by every UAV on its own
/// from the messages it receives, with at most one UAV *acting* as leader at any instant under
/// message loss, delay, duplication and reordering.
///
/// Scheme — numbered terms, majority votes and leases:
/// - Term 1 begins with UAV 0 as the designated leader. The leader broadcasts a heartbeat every
///   heartbeat_period_s (in the product it rides with the share); every member that accepts it
///   answers with an ack that echoes the heartbeat's send time.
/// - Lease: the leader acts (estimator, gesture vote and filter, parameter ownership, the share)
///   only until its own clock reads s + lease_s, s the latest send time such that a majority of
///   the members (itself included) acknowledged a heartbeat (or granted a vote request) sent at s
///   or later.
/// - Promise: a member that acks a heartbeat or grants a vote will not vote for anyone else for
///   promise_s = lease_s·(1 + ρ)/(1 − ρ) of its own clock from the receipt (ρ = clock_drift, the
///   bound on every clock's rate error). A receipt follows its send, so a promise outlasts the
///   lease it backs in real time. While promised (and while it acts as leader), a member ignores
///   vote requests: a member that lost touch with a working leader cannot depose it. A leader
///   that grants a vote has adopted the newer term and stopped acting.
/// - Election: a follower that has heard no heartbeat of a leader holding (or recently holding) a
///   lease for silence_limit_s, and whose promise has expired, stands after a further
///   candidacy_stagger_s × its rank (its place in index order among the members other than the
///   silent leader): a new term, its own vote, a request to the others. A member grants at most
///   one vote per term, only when not promised, and only to a candidate whose worker estimate is
///   not older than its own by more than estimate_tolerance_s (the freshest estimate wins over
///   rank; the callers pass the fresher of a UAV's worker state and its own camera's last detection). A majority makes the candidate leader, its lease counted from the request's send time.
///   The request is repeated every heartbeat_period_s against loss; no majority within
///   election_timeout_s: it stands again after its stagger in a new term.
///   Before that, a pre-vote: the candidate asks whether a majority *would* vote for it in the next
///   term (no state changes at the receivers) and starts the term only if so; a member that cannot
///   hear the leader but is not heard by a majority either thus never inflates its term, and cannot
///   depose a working leader through the newer term its refusals would carry.
/// - Terms order everything: a message of an older term gets a refusal carrying the newer term;
///   a member that sees a newer term adopts it and follows — a recovered old leader rejoins as a
///   follower that way.
///
/// Why two leaders never act at once: the majority behind the old leader's lease and the majority
/// that elected the new one share a member x. Had x granted the new vote (term T' > T) before
/// acking the old leader's lease-giving heartbeat (term T), it would have been in term T' and
/// refused that heartbeat; so it acked first, and granted the vote only once its promise had
/// expired — after the old lease ended in real time. This holds for any loss, delay, duplication
/// or reordering of messages. It assumes clock rates within 1 ± ρ, and that a member which
/// restarts without its term and vote stays quiet (no ack, no vote) for promise_s (Start::kRestart).
/// Liveness needs a majority able to talk: any 2 of 3 UAVs; a lone UAV never leads a formation of 3.
/// Thread safety: none; one instance per UAV, called from one thread.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::formation {

/// \brief Configuration (mission YAML section `leadership`).
struct LeadershipConfig {
  int uav_count = 3;                  ///< members, indices 0..uav_count−1, in [1, 16]
  double heartbeat_period_s = 0.2;    ///< the leader's heartbeat period [s], in (0, 5]
  double lease_s = 1.0;               ///< how long a majority's ack lets the leader act [s], > heartbeat_period_s
  double silence_limit_s = 2.0;       ///< no heartbeat of a leasing leader this long → stand [s], ≥ promise_s
  double candidacy_stagger_s = 0.5;   ///< extra wait per rank before standing [s], ≥ 0
  double election_timeout_s = 1.0;    ///< no majority this long → stand again in a new term [s], > 0
  double clock_drift = 1e-3;          ///< bound ρ on every clock's rate error, in [0, 0.1]
  double estimate_tolerance_s = 0.5;  ///< a candidate's worker estimate may be this much older than the voter's [s], ≥ 0

  /// \brief promise_s = lease_s·(1 + ρ)/(1 − ρ).
  double promiseS() const { return lease_s * (1.0 + clock_drift) / (1.0 - clock_drift); }
  /// \brief Every problem, each naming its key (`leadership.<field>`) and value; empty when valid.
  std::vector<std::string> validate() const;
  std::vector<common::ConfigError> problems() const;
};

/// \brief LeadershipConfig's numbers (keys `leadership.*`) with their ranges.
const common::FieldTable<LeadershipConfig>& leadershipFields();

enum class LeadershipRole : std::uint8_t { kFollower, kCandidate, kLeader };
const char* toString(LeadershipRole role);

enum class LeadershipMessageKind : std::uint8_t {
  kHeartbeat,
  kHeartbeatAck,
  kPreVoteRequest,  ///< "would you vote for me in term `term`?" — changes nothing at the receiver
  kPreVoteReply,
  kVoteRequest,
  kVoteReply,
};
const char* toString(LeadershipMessageKind kind);

/// \brief One message between members (carried authenticated by the links; the core only reads
/// its fields). Times are the *sender's* clock, except echo_s, which is the addressee's own.
struct LeadershipMessage {
  static constexpr int kBroadcast = -1;
  LeadershipMessageKind kind = LeadershipMessageKind::kHeartbeat;
  std::uint32_t term = 0;
  int from = 0;
  int to = kBroadcast;     ///< kBroadcast for heartbeats and vote requests
  double sent_s = 0.0;     ///< heartbeat / vote request: the sender's send time
  double echo_s = 0.0;     ///< ack / reply: the sent_s it answers
  bool granted = false;    ///< ack / reply: accepted (false: refused; term then says why)
  double lease_age_s = 0.0;  ///< heartbeat: 0 while the leader acts, else how long since its lease lapsed
  double estimate_age_s = std::numeric_limits<double>::infinity();  ///< vote request: the candidate's worker estimate age
};

struct LeadershipCounters {
  std::uint64_t heartbeats_sent = 0;
  std::uint64_t acks_sent = 0;
  std::uint64_t pre_votes_started = 0;
  std::uint64_t elections_started = 0;
  std::uint64_t elections_won = 0;
  std::uint64_t votes_granted = 0;
  std::uint64_t votes_refused = 0;
  std::uint64_t stale_term_messages = 0;  ///< messages of an older term (answered with a refusal)
  std::uint64_t terms_adopted = 0;        ///< newer terms learnt from others
  /// heartbeats of its current term from another UAV than the one it follows or voted for in that
  /// term (a second leader of one term: it gets no ack, so its lease lapses)
  std::uint64_t rival_heartbeats_refused = 0;
  std::uint64_t answers_from_the_future = 0;  ///< acks/replies echoing a send time after its own clock (ignored)
  std::uint64_t terms_exhausted = 0;          ///< candidacies refused because the term counter is at its maximum
};

/// \brief One UAV's view of the leadership (see the file comment).
class Leadership {
 public:
  /// kMissionStart: term 1, UAV 0 leads (it acts once a majority acked). kRestart: a member that
  /// lost its state: term 0, follower, quiet (no ack, no vote, no candidacy) for promise_s.
  enum class Start : std::uint8_t { kMissionStart, kRestart };

  /// \brief `config` must be valid (validate() empty) and 0 ≤ self < uav_count; throws
  /// std::invalid_argument naming the problem otherwise.
  Leadership(const LeadershipConfig& config, int self, Start start, double now_s);

  /// \brief Timers (heartbeats, candidacy, election timeout) at local time now_s; returns the
  /// messages to send. `estimate_age_s`: age of this UAV's worker estimate (+inf: none).
  std::vector<LeadershipMessage> tick(double now_s, double estimate_age_s);
  /// \brief One received message (addressed to this member or broadcast; others are ignored);
  /// returns the replies to send. Non-finite times are ignored.
  std::vector<LeadershipMessage> receive(double now_s, const LeadershipMessage& m, double estimate_age_s);

  /// \brief True while this member is the leader of its term and its lease holds at now_s: only
  /// then may it do the leader's work.
  bool acting(double now_s) const { return role_ == LeadershipRole::kLeader && now_s < lease_until_s_; }
  LeadershipRole role() const { return role_; }
  std::uint32_t term() const { return term_; }
  /// \brief The leader of this member's term as far as it knows (itself when leading), −1 if none.
  int leader() const { return leader_; }
  int self() const { return self_; }
  double leaseUntil() const { return lease_until_s_; }
  const LeadershipCounters& counters() const { return counters_; }
  /// \brief Majority size: uav_count / 2 + 1.
  int majority() const { return config_.uav_count / 2 + 1; }

 private:
  void adoptTerm(std::uint32_t term, double now_s);
  void becomeFollower();
  void standForElection(double now_s, double estimate_age_s, std::vector<LeadershipMessage>& out);
  void updateLease();
  double standAt() const;
  int rank() const;
  LeadershipMessage reply(LeadershipMessageKind kind, const LeadershipMessage& m, bool granted) const;
  void onHeartbeat(double now_s, const LeadershipMessage& m, std::vector<LeadershipMessage>& out);
  void onAnswer(double now_s, const LeadershipMessage& m, std::vector<LeadershipMessage>& out);
  void becomeLeader(double now_s);
  void onVoteRequest(double now_s, const LeadershipMessage& m, double estimate_age_s,
                     std::vector<LeadershipMessage>& out);
  bool wouldVote(double now_s, const LeadershipMessage& m, double estimate_age_s) const;
  LeadershipMessage request() const;  ///< the current (pre-)vote request
  bool mayVoteFor(double now_s, int candidate) const;
  void promise(double now_s, int to);
  void startTerm(double now_s, double estimate_age_s, std::vector<LeadershipMessage>& out);

  LeadershipConfig config_;
  int self_;
  std::uint32_t term_ = 0;
  int voted_for_ = -1;
  int leader_ = -1;
  int silent_leader_ = -1;  ///< the leader whose silence makes this member stand (for its rank)
  LeadershipRole role_ = LeadershipRole::kFollower;
  double quiet_until_s_ = -std::numeric_limits<double>::infinity();
  double promise_until_s_ = -std::numeric_limits<double>::infinity();
  int promised_to_ = -1;
  double last_heard_s_;                 ///< local time of the last heartbeat that reset the silence
  double last_heartbeat_sent_s_ = -std::numeric_limits<double>::infinity();  ///< by the current leader (its clock)
  // Candidate.
  bool pre_vote_ = false;  ///< candidate still in its pre-vote (term not yet started)
  double estimate_age_s_ = std::numeric_limits<double>::infinity();  ///< at the candidacy
  double request_sent_s_ = 0.0;
  double next_request_s_ = 0.0;
  double election_deadline_s_ = 0.0;
  double retry_at_s_ = -std::numeric_limits<double>::infinity();
  std::vector<bool> votes_;
  // Leader.
  double next_heartbeat_s_ = 0.0;
  double lease_until_s_ = -std::numeric_limits<double>::infinity();
  double became_leader_s_ = 0.0;
  std::vector<double> acked_s_;  ///< per member: the latest own send time it acknowledged (this term)
  LeadershipCounters counters_;
};

}  // namespace gesture_formation::formation
