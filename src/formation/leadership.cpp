#include "gesture_formation/formation/leadership.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

namespace gesture_formation::formation {

namespace {
constexpr double kNever = -std::numeric_limits<double>::infinity();
}  // namespace

const char* toString(LeadershipRole role) {
  switch (role) {
    case LeadershipRole::kFollower: return "follower";
    case LeadershipRole::kCandidate: return "candidate";
    case LeadershipRole::kLeader: return "leader";
  }
  return "?";
}

const char* toString(LeadershipMessageKind kind) {
  switch (kind) {
    case LeadershipMessageKind::kHeartbeat: return "heartbeat";
    case LeadershipMessageKind::kHeartbeatAck: return "heartbeat_ack";
    case LeadershipMessageKind::kPreVoteRequest: return "pre_vote_request";
    case LeadershipMessageKind::kPreVoteReply: return "pre_vote_reply";
    case LeadershipMessageKind::kVoteRequest: return "vote_request";
    case LeadershipMessageKind::kVoteReply: return "vote_reply";
  }
  return "?";
}

const common::FieldTable<LeadershipConfig>& leadershipFields() {
  using C = LeadershipConfig;
  using common::Range;
  static const common::FieldTable<LeadershipConfig> t{{
      {"leadership.uav_count", Range::closed(1, 16), [](C& c) { return &c.uav_count; }},
      {"leadership.heartbeat_period_s", Range::openClosed(0.0, 5.0), [](C& c) { return &c.heartbeat_period_s; }},
      {"leadership.lease_s", Range::positive(), [](C& c) { return &c.lease_s; }},
      {"leadership.silence_limit_s", Range::positive(), [](C& c) { return &c.silence_limit_s; }},
      {"leadership.candidacy_stagger_s", Range::nonNegative(), [](C& c) { return &c.candidacy_stagger_s; }},
      {"leadership.election_timeout_s", Range::positive(), [](C& c) { return &c.election_timeout_s; }},
      {"leadership.clock_drift", Range::closed(0.0, 0.1), [](C& c) { return &c.clock_drift; }},
      {"leadership.estimate_tolerance_s", Range::nonNegative(), [](C& c) { return &c.estimate_tolerance_s; }},
  }};
  return t;
}

std::vector<common::ConfigError> LeadershipConfig::problems() const {
  std::vector<common::ConfigError> e = leadershipFields().rangeProblems(*this);
  if (e.empty()) {  // the rules between fields assume each field is in its range
    common::checkRule(e, lease_s > heartbeat_period_s, "leadership.lease_s", lease_s,
                      "must be > leadership.heartbeat_period_s (the lease would lapse between heartbeats)");
    common::checkRule(e, silence_limit_s >= promiseS(), "leadership.silence_limit_s", silence_limit_s,
                      "must be >= lease_s (1 + clock_drift) / (1 - clock_drift) = " + std::to_string(promiseS()) +
                          " (a follower may stand only once its promise to the silent leader has expired)");
  }
  leadershipFields().sortByTableOrder(e);
  return e;
}

std::vector<std::string> LeadershipConfig::validate() const { return common::problemLines(problems()); }

Leadership::Leadership(const LeadershipConfig& config, int self, Start start, double now_s)
    : config_(config), self_(self), last_heard_s_(now_s) {
  const std::vector<std::string> problems = config.validate();
  if (!problems.empty()) throw std::invalid_argument("leadership: " + problems.front());
  if (self < 0 || self >= config.uav_count) {
    throw std::invalid_argument("leadership: self index " + std::to_string(self) + " outside [0, " +
                                std::to_string(config.uav_count - 1) + "]");
  }
  if (!std::isfinite(now_s)) throw std::invalid_argument("leadership: start time is not finite");
  const auto n = static_cast<std::size_t>(config.uav_count);
  votes_.assign(n, false);
  acked_s_.assign(n, kNever);
  if (start == Start::kMissionStart) {
    term_ = 1;
    leader_ = 0;
    voted_for_ = 0;
    silent_leader_ = 0;
    if (self == 0) {
      role_ = LeadershipRole::kLeader;
      became_leader_s_ = now_s;
      next_heartbeat_s_ = now_s;
    }
  } else {
    quiet_until_s_ = now_s + config.promiseS();
  }
}

void Leadership::adoptTerm(std::uint32_t term, double now_s) {
  term_ = term;
  // A newer term is news of a leader or a candidate: the silence before standing starts again
  // (a recovered old leader that learns of its successor waits for its heartbeats instead of
  // standing at once).
  last_heard_s_ = std::max(last_heard_s_, now_s);
  voted_for_ = -1;
  leader_ = -1;
  last_heartbeat_sent_s_ = kNever;
  std::fill(acked_s_.begin(), acked_s_.end(), kNever);
  becomeFollower();
  ++counters_.terms_adopted;
}

void Leadership::becomeFollower() {
  role_ = LeadershipRole::kFollower;
  lease_until_s_ = kNever;
}

void Leadership::promise(double now_s, int to) {
  // The promise runs to the later of both ends and names the newest promisee: a vote for the old
  // one is then refused until the end (conservative); the newest may be voted for again.
  promise_until_s_ = std::max(promise_until_s_, now_s + config_.promiseS());
  promised_to_ = to;
}

int Leadership::rank() const {
  int r = 0;
  for (int j = 0; j < self_; ++j) {
    if (j != silent_leader_) ++r;
  }
  return r;
}

double Leadership::standAt() const {
  const double base = std::max(last_heard_s_ + config_.silence_limit_s, promise_until_s_);
  return std::max({base + config_.candidacy_stagger_s * rank(), quiet_until_s_, retry_at_s_});
}

void Leadership::updateLease() {
  std::vector<double> acked = acked_s_;
  const auto k = static_cast<std::size_t>(majority() - 1);
  std::nth_element(acked.begin(), acked.begin() + static_cast<std::ptrdiff_t>(k), acked.end(), std::greater<double>());
  if (std::isfinite(acked[k])) lease_until_s_ = std::max(lease_until_s_, acked[k] + config_.lease_s);
}

void Leadership::becomeLeader(double now_s) {
  role_ = LeadershipRole::kLeader;
  leader_ = self_;
  became_leader_s_ = now_s;
  next_heartbeat_s_ = now_s;
  ++counters_.elections_won;
  updateLease();
}

void Leadership::standForElection(double now_s, double estimate_age_s, std::vector<LeadershipMessage>& out) {
  ++counters_.pre_votes_started;
  role_ = LeadershipRole::kCandidate;
  pre_vote_ = true;
  estimate_age_s_ = estimate_age_s;
  std::fill(votes_.begin(), votes_.end(), false);
  votes_[static_cast<std::size_t>(self_)] = true;
  request_sent_s_ = now_s;
  election_deadline_s_ = now_s + config_.election_timeout_s;
  if (majority() == 1) {
    startTerm(now_s, estimate_age_s, out);
    return;
  }
  next_request_s_ = now_s + config_.heartbeat_period_s;
  out.push_back(request());
}

void Leadership::startTerm(double now_s, double estimate_age_s, std::vector<LeadershipMessage>& out) {
  if (term_ == std::numeric_limits<std::uint32_t>::max()) {  // a wrap to 0 would make every message of it stale
    ++counters_.terms_exhausted;
    becomeFollower();
    return;
  }
  ++term_;
  ++counters_.elections_started;
  role_ = LeadershipRole::kCandidate;
  pre_vote_ = false;
  voted_for_ = self_;
  leader_ = -1;
  last_heartbeat_sent_s_ = kNever;
  std::fill(votes_.begin(), votes_.end(), false);
  std::fill(acked_s_.begin(), acked_s_.end(), kNever);
  votes_[static_cast<std::size_t>(self_)] = true;
  acked_s_[static_cast<std::size_t>(self_)] = now_s;
  request_sent_s_ = now_s;
  election_deadline_s_ = now_s + config_.election_timeout_s;
  if (majority() == 1) {
    becomeLeader(now_s);
    return;
  }
  estimate_age_s_ = estimate_age_s;
  next_request_s_ = now_s + config_.heartbeat_period_s;
  out.push_back(request());
}

LeadershipMessage Leadership::request() const {
  LeadershipMessage m;
  m.kind = pre_vote_ ? LeadershipMessageKind::kPreVoteRequest : LeadershipMessageKind::kVoteRequest;
  m.term = pre_vote_ ? term_ + 1 : term_;
  m.from = self_;
  m.sent_s = request_sent_s_;
  m.estimate_age_s = estimate_age_s_;
  return m;
}

std::vector<LeadershipMessage> Leadership::tick(double now_s, double estimate_age_s) {
  std::vector<LeadershipMessage> out;
  if (!std::isfinite(now_s)) return out;
  if (role_ == LeadershipRole::kCandidate && now_s >= election_deadline_s_) {
    becomeFollower();  // no majority in time: stand again after the stagger, in a new term
    retry_at_s_ = now_s + config_.candidacy_stagger_s * rank();
  }
  if (role_ == LeadershipRole::kFollower && now_s >= standAt()) {
    standForElection(now_s, estimate_age_s, out);
  } else if (role_ == LeadershipRole::kCandidate && now_s >= next_request_s_) {
    out.push_back(request());  // repeated every heartbeat period against loss (same send time: answers stay matched)
    next_request_s_ = now_s + config_.heartbeat_period_s;
  }
  if (role_ == LeadershipRole::kLeader && now_s >= next_heartbeat_s_) {
    acked_s_[static_cast<std::size_t>(self_)] = now_s;
    updateLease();
    LeadershipMessage m;
    m.kind = LeadershipMessageKind::kHeartbeat;
    m.term = term_;
    m.from = self_;
    m.sent_s = now_s;
    m.lease_age_s = acting(now_s) ? 0.0 : now_s - std::max(lease_until_s_, became_leader_s_);
    out.push_back(m);
    ++counters_.heartbeats_sent;
    next_heartbeat_s_ = now_s + config_.heartbeat_period_s;
  }
  return out;
}

LeadershipMessage Leadership::reply(LeadershipMessageKind kind, const LeadershipMessage& m, bool granted) const {
  LeadershipMessage r;
  r.kind = kind;
  r.term = term_;
  r.from = self_;
  r.to = m.from;
  r.echo_s = m.sent_s;
  r.granted = granted;
  return r;
}

std::vector<LeadershipMessage> Leadership::receive(double now_s, const LeadershipMessage& m, double estimate_age_s) {
  std::vector<LeadershipMessage> out;
  if (!std::isfinite(now_s) || !std::isfinite(m.sent_s) || !std::isfinite(m.echo_s)) return out;
  if (m.from == self_ || m.from < 0 || m.from >= config_.uav_count) return out;
  if (m.to != LeadershipMessage::kBroadcast && m.to != self_) return out;
  if (m.kind == LeadershipMessageKind::kPreVoteRequest) {  // answered from the current state, which it never changes
    const bool would = wouldVote(now_s, m, estimate_age_s);
    LeadershipMessage r = reply(LeadershipMessageKind::kPreVoteReply, m, would);
    if (would) r.term = m.term;  // a grant names the proposed term; a refusal this member's (perhaps newer) one
    out.push_back(r);
    return out;
  }
  if (m.kind == LeadershipMessageKind::kPreVoteReply) {  // a grant carries the proposed term: not adopted
    if (m.granted) {
      onAnswer(now_s, m, out);
    } else if (m.term > term_) {
      adoptTerm(m.term, now_s);
    }
    return out;
  }
  const bool request = m.kind == LeadershipMessageKind::kHeartbeat || m.kind == LeadershipMessageKind::kVoteRequest;
  const LeadershipMessageKind answer =
      m.kind == LeadershipMessageKind::kHeartbeat ? LeadershipMessageKind::kHeartbeatAck : LeadershipMessageKind::kVoteReply;
  if (m.term < term_) {
    ++counters_.stale_term_messages;
    if (request) out.push_back(reply(answer, m, false));  // tells the sender the newer term
    return out;
  }
  if (m.kind == LeadershipMessageKind::kVoteRequest && !mayVoteFor(now_s, m.from)) {
    ++counters_.votes_refused;  // promised (or leading): the request neither deposes nor changes anything
    out.push_back(reply(answer, m, false));
    return out;
  }
  if (m.term > term_) adoptTerm(m.term, now_s);
  switch (m.kind) {
    case LeadershipMessageKind::kHeartbeat: onHeartbeat(now_s, m, out); break;
    case LeadershipMessageKind::kVoteRequest: onVoteRequest(now_s, m, estimate_age_s, out); break;
    case LeadershipMessageKind::kHeartbeatAck:
    case LeadershipMessageKind::kVoteReply: onAnswer(now_s, m, out); break;
    case LeadershipMessageKind::kPreVoteRequest:
    case LeadershipMessageKind::kPreVoteReply: break;  // handled above
  }
  return out;
}

void Leadership::onHeartbeat(double now_s, const LeadershipMessage& m, std::vector<LeadershipMessage>& out) {
  if (role_ == LeadershipRole::kLeader) return;  // another leader of this very term: impossible with one vote per term
  // It backs one leader per term: the one it follows or voted for. A second leader of the same
  // term — possible only after a member that lost its state (restart) voted twice — gets no ack
  // from it, so that leader's lease lapses instead of two acting on the same members' acks.
  if ((leader_ >= 0 && leader_ != m.from) || (voted_for_ >= 0 && voted_for_ != self_ && voted_for_ != m.from)) {
    ++counters_.rival_heartbeats_refused;
    return;
  }
  if (role_ == LeadershipRole::kCandidate) becomeFollower();
  leader_ = m.from;
  silent_leader_ = m.from;
  if (voted_for_ < 0) voted_for_ = m.from;  // no other vote in a term whose leader it follows
  if (now_s < quiet_until_s_) return;      // restarted: no promise until its old ones have expired
  if (m.lease_age_s >= config_.silence_limit_s) return;  // a leader nobody backs counts as silent
  if (m.sent_s > last_heartbeat_sent_s_) {  // a late or duplicated heartbeat does not reset the silence
    last_heartbeat_sent_s_ = m.sent_s;
    last_heard_s_ = now_s;
  }
  promise(now_s, m.from);
  out.push_back(reply(LeadershipMessageKind::kHeartbeatAck, m, true));
  ++counters_.acks_sent;
}

void Leadership::onAnswer(double now_s, const LeadershipMessage& m, std::vector<LeadershipMessage>& out) {
  if (!m.granted || m.to != self_) return;
  if (m.echo_s > now_s) {  // it never sent that: a lease from it would have no end
    ++counters_.answers_from_the_future;
    return;
  }
  const auto j = static_cast<std::size_t>(m.from);
  if (m.kind == LeadershipMessageKind::kPreVoteReply) {
    if (role_ != LeadershipRole::kCandidate || !pre_vote_ || m.echo_s != request_sent_s_ || m.term != term_ + 1) return;
    votes_[j] = true;
    if (std::count(votes_.begin(), votes_.end(), true) >= majority()) startTerm(now_s, estimate_age_s_, out);
  } else if (m.kind == LeadershipMessageKind::kHeartbeatAck && role_ == LeadershipRole::kLeader) {
    acked_s_[j] = std::max(acked_s_[j], m.echo_s);
    updateLease();
  } else if (m.kind == LeadershipMessageKind::kVoteReply && role_ == LeadershipRole::kCandidate && !pre_vote_ &&
             m.echo_s == request_sent_s_) {
    votes_[j] = true;
    acked_s_[j] = std::max(acked_s_[j], m.echo_s);
    if (std::count(votes_.begin(), votes_.end(), true) >= majority()) becomeLeader(now_s);
  }
}

bool Leadership::mayVoteFor(double now_s, int candidate) const {
  const bool promised_elsewhere = now_s < promise_until_s_ && promised_to_ != candidate;
  return !promised_elsewhere && now_s >= quiet_until_s_ && !acting(now_s);
}

bool Leadership::wouldVote(double now_s, const LeadershipMessage& m, double estimate_age_s) const {
  if (!mayVoteFor(now_s, m.from)) return false;
  if (m.term < term_ || (m.term == term_ && (role_ == LeadershipRole::kLeader || (voted_for_ >= 0 && voted_for_ != m.from)))) {
    return false;
  }
  return !std::isfinite(estimate_age_s) || m.estimate_age_s <= estimate_age_s + config_.estimate_tolerance_s;
}

void Leadership::onVoteRequest(double now_s, const LeadershipMessage& m, double estimate_age_s,
                               std::vector<LeadershipMessage>& out) {
  const bool grant = wouldVote(now_s, m, estimate_age_s);
  if (grant) {
    if (role_ == LeadershipRole::kCandidate) becomeFollower();
    voted_for_ = m.from;
    promise(now_s, m.from);
    last_heard_s_ = now_s;  // give the candidate time to win before standing itself
    ++counters_.votes_granted;
  } else {
    ++counters_.votes_refused;
  }
  out.push_back(reply(LeadershipMessageKind::kVoteReply, m, grant));
}

}  // namespace gesture_formation::formation
