#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "gesture_formation/comm/byte_io.hpp"
#include "gesture_formation/comm/payloads.hpp"

using namespace gesture_formation::comm;
namespace formation = gesture_formation::formation;
namespace planning = gesture_formation::planning;
namespace gesture = gesture_formation::gesture;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

PlanMessage trajectory(std::size_t n, std::uint64_t seed = 3, bool fallback = false) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  PlanMessage msg;
  msg.fallback = fallback;
  planning::PlannedTrajectory& t = msg.plan;
  t.uav_index = 2;
  t.sequence = 77;
  t.t0_s = 12.25;
  t.dt_s = 0.2;
  for (std::size_t k = 0; k < n; ++k) {
    planning::TrajectorySample s;
    s.p_world = {u(rng), u(rng), u(rng)};
    s.v_world = {u(rng), u(rng), u(rng)};
    s.a_world = {u(rng), u(rng), u(rng)};
    s.heading_rad = u(rng);
    s.pitch_rad = u(rng);
    t.samples.push_back(s);
  }
  return msg;
}

formation::FormationCommand command() {
  formation::FormationCommand c;
  c.id = {"operator-gcs1", 123456789012ull};
  c.source = formation::CommandSource::kGesture;
  c.target = formation::CommandTarget::list({2, 0});
  c.parameter = formation::Parameter::kDistance;
  c.kind = formation::CommandKind::kSet;
  c.amount = 12.5;
  return c;
}

template <class T>
std::vector<std::uint8_t> encoded(const T& m) {
  auto r = encodePayload(m);
  EXPECT_TRUE(r) << r.reason();
  return r ? r.value() : std::vector<std::uint8_t>{};
}

template <class T>
PayloadError decode(const std::vector<std::uint8_t>& b, T& out, std::string* reason = nullptr) {
  return decodePayload(b.data(), b.size(), out, reason);
}

/// Overwrites the big-endian double at `offset`.
void putDouble(std::vector<std::uint8_t>& b, std::size_t offset, double v) {
  ByteWriter w;
  w.f64(v);
  std::memcpy(&b[offset], w.buffer().data(), 8);
}

}  // namespace

TEST(CommPayloadsTest, HeartbeatRoundTrip) {
  Heartbeat h;
  h.uav_index = 3;
  h.status = Heartbeat::Status::kFailsafe;
  h.worker_visible = true;
  h.last_plan_sequence = 0xDEADBEEF;
  const auto b = encoded(h);
  ASSERT_EQ(b.size(), 8u);
  Heartbeat d;
  ASSERT_EQ(decode(b, d), PayloadError::kNone);
  EXPECT_EQ(d.uav_index, 3);
  EXPECT_EQ(d.status, Heartbeat::Status::kFailsafe);
  EXPECT_TRUE(d.worker_visible);
  EXPECT_EQ(d.last_plan_sequence, 0xDEADBEEFu);
  auto bad = b;
  bad[2] = 4;
  EXPECT_EQ(decode(bad, d), PayloadError::kOutOfRange);
  bad = b;
  bad[3] = 2;
  EXPECT_EQ(decode(bad, d), PayloadError::kOutOfRange);
  bad = b;
  bad[1] = 32;
  EXPECT_EQ(decode(bad, d), PayloadError::kOutOfRange);
  h.uav_index = 32;
  EXPECT_FALSE(encodePayload(h));
}

TEST(CommPayloadsTest, WorkerStateRoundTripAndNonFinite) {
  WorkerStateMessage m;
  m.t_s = 3.5;
  m.last_fused_t_s = 2.75;
  m.p_world = {1, -2, 3.25};
  m.v_world = {0.1, 0.2, -0.3};
  m.covariance_diag = {0.01, 0.02, 0.03, 0.4, 0.5, 0.6};
  m.lost = true;
  const auto b = encoded(m);
  ASSERT_EQ(b.size(), 14 * 8 + 1u);
  WorkerStateMessage d;
  ASSERT_EQ(decode(b, d), PayloadError::kNone);
  EXPECT_EQ(d.t_s, m.t_s);
  EXPECT_EQ(d.last_fused_t_s, m.last_fused_t_s);
  EXPECT_EQ(d.p_world, m.p_world);
  EXPECT_EQ(d.v_world, m.v_world);
  EXPECT_EQ(d.covariance_diag, m.covariance_diag);
  EXPECT_TRUE(d.lost);
  // Every double replaced by NaN / inf in turn is refused naming the field; d is untouched.
  for (std::size_t f = 0; f < 14; ++f) {
    for (double bad_value : {kNaN, kInf, -kInf}) {
      auto bad = b;
      putDouble(bad, 8 * f, bad_value);
      WorkerStateMessage untouched = d;
      std::string reason;
      const PayloadError e = decode(bad, untouched, &reason);
      ASSERT_EQ(e, PayloadError::kNonFinite) << f << " " << reason;
      EXPECT_NE(reason.find("worker_state."), std::string::npos);
      EXPECT_EQ(untouched.t_s, d.t_s);
      EXPECT_EQ(untouched.last_fused_t_s, d.last_fused_t_s);
    }
  }
  auto neg = b;
  putDouble(neg, 8 * 8, -0.1);
  std::string reason;
  EXPECT_EQ(decode(neg, d, &reason), PayloadError::kOutOfRange);
  EXPECT_EQ(reason, "out_of_range: worker_state.covariance_diag[0]");
  // A fusion after the state's own time is malformed (it would make the estimate look fresher).
  auto future = b;
  putDouble(future, 8, 3.6);
  EXPECT_EQ(decode(future, d, &reason), PayloadError::kOutOfRange);
  EXPECT_EQ(reason, "out_of_range: worker_state.last_fused_t_s");
  EXPECT_EQ(d.last_fused_t_s, 2.75);
  WorkerStateMessage later = m;
  later.last_fused_t_s = 4.0;
  EXPECT_FALSE(encodePayload(later));
  m.p_world.x() = kNaN;
  EXPECT_FALSE(encodePayload(m));
}

TEST(CommPayloadsTest, PlannedTrajectoryRoundTripIsBitExact) {
  for (bool fallback : {false, true}) {
    for (std::size_t n : {0u, 1u, 40u, static_cast<unsigned>(kMaxTrajectorySamples)}) {
      const auto msg = trajectory(n, 3, fallback);
      const planning::PlannedTrajectory& t = msg.plan;
      const auto b = encoded(msg);
      ASSERT_EQ(b.size(), 25 + 88 * n);
      ASSERT_LE(b.size(), kMaxPayloadBytes);
      PlanMessage got;
      got.fallback = !fallback;
      ASSERT_EQ(decode(b, got), PayloadError::kNone);
      EXPECT_EQ(got.fallback, fallback);  // the flag travels with the plan (a heartbeat naming it may be lost)
      const planning::PlannedTrajectory& d = got.plan;
      EXPECT_EQ(d.uav_index, t.uav_index);
      EXPECT_EQ(d.sequence, t.sequence);
      EXPECT_EQ(d.t0_s, t.t0_s);
      EXPECT_EQ(d.dt_s, t.dt_s);
      ASSERT_EQ(d.samples.size(), n);
      for (std::size_t k = 0; k < n; ++k) {
        EXPECT_EQ(d.samples[k].p_world, t.samples[k].p_world);
        EXPECT_EQ(d.samples[k].v_world, t.samples[k].v_world);
        EXPECT_EQ(d.samples[k].a_world, t.samples[k].a_world);
        EXPECT_EQ(d.samples[k].heading_rad, t.samples[k].heading_rad);
        EXPECT_EQ(d.samples[k].pitch_rad, t.samples[k].pitch_rad);
      }
      EXPECT_EQ(encoded(got), b);
    }
  }
}

TEST(CommPayloadsTest, PlannedTrajectoryRefusals) {
  const auto b = encoded(trajectory(3));
  PlanMessage d;
  std::string reason;
  // Count above the maximum, whatever the bytes: refused before any allocation.
  auto bad = b;
  bad[23] = 0xFF;
  bad[24] = 0xFF;
  EXPECT_EQ(decode(bad, d, &reason), PayloadError::kOversizeArray);
  EXPECT_EQ(reason, "oversize_array: planned_trajectory.count 65535");
  bad = b;
  bad[24] = 4;  // claims 4 samples, holds 3
  EXPECT_EQ(decode(bad, d), PayloadError::kTruncated);
  bad = b;
  bad[24] = 2;  // claims 2, holds 3
  EXPECT_EQ(decode(bad, d), PayloadError::kTrailingBytes);
  bad = b;
  bad[6] = 2;  // a flag bit that means nothing
  EXPECT_EQ(decode(bad, d, &reason), PayloadError::kOutOfRange);
  EXPECT_EQ(reason, "out_of_range: planned_trajectory.flags");
  bad = b;
  putDouble(bad, 15, 0.0);  // dt
  EXPECT_EQ(decode(bad, d), PayloadError::kOutOfRange);
  bad = b;
  putDouble(bad, 25 + 88 + 9 * 8, kNaN);  // samples[1].heading
  EXPECT_EQ(decode(bad, d, &reason), PayloadError::kNonFinite);
  EXPECT_EQ(reason, "non_finite: planned_trajectory.samples[1].heading_rad");
  for (std::size_t cut = 0; cut < b.size(); ++cut) {
    std::vector<std::uint8_t> part(b.begin(), b.begin() + static_cast<long>(cut));
    ASSERT_EQ(decode(part, d), PayloadError::kTruncated) << cut;
  }
  auto t = trajectory(kMaxTrajectorySamples + 1);
  EXPECT_FALSE(encodePayload(t));
  t = trajectory(2);
  t.plan.uav_index = -1;
  EXPECT_FALSE(encodePayload(t));
  t = trajectory(2);
  t.plan.samples[1].a_world.z() = kInf;
  EXPECT_FALSE(encodePayload(t));
}

TEST(CommPayloadsTest, FormationParamsRoundTripAndLimits) {
  FormationParamsMessage p;  // Table II
  p.params.followers.push_back({15.0, -5.0, 9.5});
  p.version = 0x0102030405060708ULL;  // the version travels: a follower and a new leader carry it on
  const auto b = encoded(p);
  ASSERT_EQ(b.size(), 24 + 1 + 3 * 24u + 8);
  FormationParamsMessage d;
  d.params.followers.clear();
  ASSERT_EQ(decode(b, d), PayloadError::kNone);
  ASSERT_EQ(d.params.uavCount(), 4);
  for (int u = 0; u < 4; ++u) {
    EXPECT_EQ(d.params.uav(u).beta_deg, p.params.uav(u).beta_deg);
    EXPECT_EQ(d.params.uav(u).gamma_deg, p.params.uav(u).gamma_deg);
    EXPECT_EQ(d.params.uav(u).distance_m, p.params.uav(u).distance_m);
  }
  EXPECT_EQ(d.version, p.version);
  auto bad = b;
  bad[24] = static_cast<std::uint8_t>(kMaxFollowers + 1);
  EXPECT_EQ(decode(bad, d), PayloadError::kOversizeArray);
  EXPECT_EQ(d.params.uavCount(), 4);  // untouched
  bad = b;
  putDouble(bad, 16, -1.0);  // leader distance
  EXPECT_EQ(decode(bad, d), PayloadError::kOutOfRange);
  bad.assign(b.begin(), b.end() - 8);  // without its version (an older build's payload)
  EXPECT_EQ(decode(bad, d), PayloadError::kTruncated);
  EXPECT_EQ(d.version, p.version);  // untouched
  p.params.followers.assign(kMaxFollowers + 1, formation::UavObservation{});
  EXPECT_FALSE(encodePayload(p));
}

TEST(CommPayloadsTest, FormationCommandRoundTrip) {
  const auto c = command();
  const auto b = encoded(c);
  formation::FormationCommand d;
  ASSERT_EQ(decode(b, d), PayloadError::kNone);
  EXPECT_EQ(d.id.sender, c.id.sender);
  EXPECT_EQ(d.id.sequence, c.id.sequence);
  EXPECT_EQ(d.source, c.source);
  EXPECT_EQ(d.target.group, formation::TargetGroup::kList);
  EXPECT_EQ(d.target.uavs, c.target.uavs);
  EXPECT_EQ(d.parameter, c.parameter);
  EXPECT_EQ(d.kind, c.kind);
  EXPECT_EQ(d.amount, c.amount);
  for (auto group : {formation::CommandTarget::leader(), formation::CommandTarget::followers(), formation::CommandTarget::all()}) {
    formation::FormationCommand g = c;
    g.target = group;
    g.parameter = formation::Parameter::kGamma;
    g.kind = formation::CommandKind::kIncrement;
    g.source = formation::CommandSource::kOperator;
    ASSERT_EQ(decode(encoded(g), d), PayloadError::kNone);
    EXPECT_EQ(d.target.group, group.group);
    EXPECT_TRUE(d.target.uavs.empty());
    EXPECT_EQ(d.parameter, formation::Parameter::kGamma);
    EXPECT_EQ(d.source, formation::CommandSource::kOperator);
  }
}

TEST(CommPayloadsTest, AbortCommandRoundTripAndByteLayout) {
  AbortMessage m;
  m.id = {"operator", 0x0102030405060708ull};
  m.source = planning::AbortSource::kGesture;
  const auto b = encoded(m);
  // u8 length, "operator", u64 sequence big-endian, u8 source (docs/security.md §3.2).
  const std::vector<std::uint8_t> expected{8, 'o', 'p', 'e', 'r', 'a', 't', 'o', 'r', 1, 2, 3, 4, 5, 6, 7, 8, 1};
  EXPECT_EQ(b, expected);
  AbortMessage d;
  ASSERT_EQ(decode(b, d), PayloadError::kNone);
  EXPECT_EQ(d.id.sender, "operator");
  EXPECT_EQ(d.id.sequence, m.id.sequence);
  EXPECT_EQ(d.source, planning::AbortSource::kGesture);
  const planning::AbortCommand c = d.command(12.5);
  EXPECT_EQ(c.sent_s, 12.5);
  EXPECT_EQ(c.id.sender, "operator");
  EXPECT_EQ(c.source, planning::AbortSource::kGesture);
}

TEST(CommPayloadsTest, AbortCommandRefusals) {
  AbortMessage m;
  m.id = {"has space", 1};
  EXPECT_FALSE(encodePayload(m));
  m.id.sender = std::string(kMaxSenderNameBytes + 1, 'a');
  EXPECT_FALSE(encodePayload(m));
  m.id.sender = "gcs";
  const auto b = encoded(m);
  AbortMessage d;
  d.id.sender = "untouched";
  auto bad = b;
  bad[0] = 0;
  EXPECT_EQ(decode(bad, d), PayloadError::kOutOfRange);
  bad[0] = 200;
  EXPECT_EQ(decode(bad, d), PayloadError::kOversizeArray);
  bad = b;
  bad[1] = ' ';
  EXPECT_EQ(decode(bad, d), PayloadError::kOutOfRange);
  bad = b;
  bad.back() = 2;  // source
  std::string reason;
  EXPECT_EQ(decodePayload(bad.data(), bad.size(), d, &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("abort_command.source"), std::string::npos) << reason;
  bad = b;
  bad.push_back(0);
  EXPECT_EQ(decode(bad, d), PayloadError::kTrailingBytes);
  bad = b;
  bad.pop_back();
  EXPECT_EQ(decode(bad, d), PayloadError::kTruncated);
  EXPECT_EQ(d.id.sender, "untouched");  // written only on success
}

TEST(CommPayloadsTest, CommandAckRoundTripAndByteLayout) {
  CommandAckMessage m;
  m.id = {"op@100", 0x0102030405060708ull};
  m.source = formation::CommandSource::kGesture;
  m.status = formation::CommandStatus::kDuplicate;
  m.params_version = 7;
  m.command_stamp_s = 2.0;
  m.outcome = "dup";
  const auto b = encoded(m);
  // u8 length, sender, u64 sequence, u8 source, u8 status, u64 version, f64 stamp, u8 length, outcome
  const std::vector<std::uint8_t> expected{6, 'o', 'p', '@', '1', '0', '0', 1, 2, 3, 4, 5, 6, 7, 8, 1, 1,
                                           0, 0, 0, 0, 0, 0, 0, 7, 0x40, 0, 0, 0, 0, 0, 0, 0, 3, 'd', 'u', 'p'};
  EXPECT_EQ(b, expected);
  CommandAckMessage d;
  ASSERT_EQ(decode(b, d), PayloadError::kNone);
  EXPECT_EQ(d.id.sender, "op@100");
  EXPECT_EQ(d.id.sequence, m.id.sequence);
  EXPECT_EQ(d.source, formation::CommandSource::kGesture);
  EXPECT_EQ(d.status, formation::CommandStatus::kDuplicate);
  EXPECT_EQ(d.params_version, 7u);
  EXPECT_EQ(d.command_stamp_s, 2.0);
  EXPECT_EQ(d.outcome, "dup");
  // Every status and an outcome with UTF-8 (the clamp rules name γ) and no text at all.
  for (const auto status : {formation::CommandStatus::kApplied, formation::CommandStatus::kRejected}) {
    m.status = status;
    m.outcome = status == formation::CommandStatus::kApplied ? "applied (clamped by limits.\xce\xb3_max)" : "";
    ASSERT_EQ(decode(encoded(m), d), PayloadError::kNone);
    EXPECT_EQ(d.status, status);
    EXPECT_EQ(d.outcome, m.outcome);
  }
}

TEST(CommPayloadsTest, CommandAckRefusals) {
  CommandAckMessage m;
  m.id = {"has space", 1};
  EXPECT_FALSE(encodePayload(m));
  m.id.sender = "op";
  m.outcome = "line\nbreak";
  auto e = encodePayload(m);
  ASSERT_FALSE(e);
  EXPECT_NE(e.reason().find("command_ack.outcome"), std::string::npos) << e.reason();
  m.outcome = std::string(kMaxAckOutcomeBytes + 1, 'a');
  EXPECT_FALSE(encodePayload(m));
  m.outcome = "ok";
  m.command_stamp_s = std::nan("");
  EXPECT_FALSE(encodePayload(m));
  m.command_stamp_s = 1.0;
  const auto b = encoded(m);
  CommandAckMessage d;
  d.outcome = "untouched";
  const std::size_t source_at = 1 + 2 + 8, status_at = source_at + 1, stamp_at = status_at + 1 + 8;
  auto bad = b;
  bad[source_at] = 2;
  std::string reason;
  EXPECT_EQ(decodePayload(bad.data(), bad.size(), d, &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("command_ack.source"), std::string::npos) << reason;
  bad = b;
  bad[status_at] = 3;
  EXPECT_EQ(decodePayload(bad.data(), bad.size(), d, &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("command_ack.status"), std::string::npos) << reason;
  bad = b;
  for (std::size_t k = 0; k < 8; ++k) bad[stamp_at + k] = 0xff;  // NaN
  EXPECT_EQ(decode(bad, d), PayloadError::kNonFinite);
  bad = b;
  bad[bad.size() - 2] = 0x07;  // a control character in the outcome
  EXPECT_EQ(decodePayload(bad.data(), bad.size(), d, &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("command_ack.outcome"), std::string::npos) << reason;
  bad = b;
  bad.push_back('x');
  EXPECT_EQ(decode(bad, d), PayloadError::kTrailingBytes);
  bad = b;
  bad.pop_back();
  EXPECT_EQ(decode(bad, d), PayloadError::kTruncated);
  EXPECT_EQ(d.outcome, "untouched");  // written only on success
}

TEST(CommPayloadsTest, AssistanceRoundTripAndRefusals) {
  AssistanceMessage m;
  m.state = formation::AssistanceState{formation::AssistancePhase::kAcknowledged, 2.0, "g", 0.0, "op"};
  const auto b = encoded(m);
  // u8 phase, f64 requested_s, u8 L, requested_by, f64 acknowledged_s, u8 M, acknowledged_by
  const std::vector<std::uint8_t> expected{2, 0x40, 0, 0, 0, 0, 0, 0, 0, 1, 'g', 0, 0, 0, 0, 0, 0, 0, 0, 2, 'o', 'p'};
  EXPECT_EQ(b, expected);
  AssistanceMessage d;
  ASSERT_EQ(decode(b, d), PayloadError::kNone);
  EXPECT_EQ(d.state.phase, formation::AssistancePhase::kAcknowledged);
  EXPECT_EQ(d.state.requested_s, 2.0);
  EXPECT_EQ(d.state.requested_by, "g");
  EXPECT_EQ(d.state.acknowledged_by, "op");
  m.state = formation::AssistanceState{};  // no request yet: empty names
  ASSERT_EQ(decode(encoded(m), d), PayloadError::kNone);
  EXPECT_EQ(d.state.phase, formation::AssistancePhase::kNone);
  m.state.requested_by = "with space";
  EXPECT_FALSE(encodePayload(m));
  m.state.requested_by = "g";
  m.state.acknowledged_s = std::nan("");
  EXPECT_FALSE(encodePayload(m));
  auto bad = b;
  bad[0] = 3;
  std::string reason;
  EXPECT_EQ(decodePayload(bad.data(), bad.size(), d, &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("assistance.phase"), std::string::npos) << reason;
  bad = b;
  bad[10] = ' ';
  EXPECT_EQ(decodePayload(bad.data(), bad.size(), d, &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("assistance.requested_by"), std::string::npos) << reason;
  bad = b;
  bad[9] = kMaxSenderNameBytes + 1;
  EXPECT_EQ(decode(bad, d), PayloadError::kOversizeArray);
  bad = b;
  bad.push_back('x');
  EXPECT_EQ(decode(bad, d), PayloadError::kTrailingBytes);
  bad = b;
  bad.pop_back();
  EXPECT_EQ(decode(bad, d), PayloadError::kTruncated);
}

TEST(CommPayloadsTest, FormationCommandRefusals) {
  auto c = command();
  c.amount = kNaN;
  EXPECT_FALSE(encodePayload(c));
  c = command();
  c.id.sender = "has space";
  EXPECT_FALSE(encodePayload(c));
  c.id.sender = std::string(kMaxSenderNameBytes + 1, 'a');
  EXPECT_FALSE(encodePayload(c));
  c = command();
  c.target.uavs.clear();
  EXPECT_FALSE(encodePayload(c));
  c = command();
  c.target.uavs.push_back(kMaxUavIndex + 1);
  EXPECT_FALSE(encodePayload(c));

  const auto b = encoded(command());
  const std::size_t name = 1 + command().id.sender.size();  // offset after the name
  formation::FormationCommand d;
  auto bad = b;
  bad[0] = 0;
  EXPECT_EQ(decode(bad, d), PayloadError::kOutOfRange);
  bad[0] = 200;
  EXPECT_EQ(decode(bad, d), PayloadError::kOversizeArray);
  bad = b;
  bad[1] = 0x07;  // control character in the name
  EXPECT_EQ(decode(bad, d), PayloadError::kOutOfRange);
  bad = b;
  bad[name + 8] = 2;  // source
  EXPECT_EQ(decode(bad, d), PayloadError::kOutOfRange);
  bad = b;
  bad[name + 9] = 0;  // group leader but a UAV list follows
  EXPECT_EQ(decode(bad, d), PayloadError::kOutOfRange);
  bad = b;
  bad[name + 10] = 200;  // UAV count
  EXPECT_EQ(decode(bad, d), PayloadError::kOversizeArray);
  bad = b;
  bad[name + 12] = 40;  // UAV index 40
  EXPECT_EQ(decode(bad, d), PayloadError::kOutOfRange);
  bad = b;
  putDouble(bad, b.size() - 8, -kInf);
  EXPECT_EQ(decode(bad, d), PayloadError::kNonFinite);
  bad = b;
  bad.push_back(1);
  EXPECT_EQ(decode(bad, d), PayloadError::kTrailingBytes);
}

TEST(CommPayloadsTest, GestureObservationRoundTripAndRefusals) {
  GestureObservationMessage m;
  m.uav_index = 2;
  m.t_s = 41.25;
  m.gesture_id = 3;
  m.probabilities = {0.05, 0.05, 0.1, 0.75, 0.05};
  m.geometry_known = true;
  m.distance_m = 8.5;
  m.elevation_deg = 11.0;
  const auto b = encoded(m);
  // u16 + f64 + u8 + u8 + 5 × f64 + u8 + 2 × f64
  ASSERT_EQ(b.size(), 2 + 8 + 1 + 1 + 5 * 8 + 1 + 2 * 8u);
  GestureObservationMessage d;
  ASSERT_EQ(decode(b, d), PayloadError::kNone);
  EXPECT_EQ(d.uav_index, 2);
  EXPECT_EQ(d.t_s, m.t_s);
  EXPECT_EQ(d.gesture_id, 3);
  EXPECT_EQ(d.probabilities, m.probabilities);
  EXPECT_TRUE(d.geometry_known);
  EXPECT_EQ(d.distance_m, 8.5);
  EXPECT_EQ(d.elevation_deg, 11.0);
  // Bad values on the wire: refused naming the field, the output untouched.
  const std::size_t prob0 = 12, flags = 12 + 5 * 8, distance = flags + 1, elevation = distance + 8;
  struct Case {
    std::size_t offset;
    int byte;       // ≥ 0: replace one byte
    double value;   // else: replace a double
    PayloadError error;
    const char* field;
  };
  const Case cases[] = {
      {1, kMaxUavIndex + 1, 0, PayloadError::kOutOfRange, "gesture_observation.uav_index"},
      {10, kMaxGestureId + 1, 0, PayloadError::kOutOfRange, "gesture_observation.gesture_id"},
      {11, static_cast<int>(kMaxGestureClasses) + 1, 0, PayloadError::kOversizeArray, "gesture_observation.probabilities"},
      {prob0, -1, 1.5, PayloadError::kOutOfRange, "gesture_observation.probabilities[0]"},
      {prob0, -1, -0.1, PayloadError::kOutOfRange, "gesture_observation.probabilities[0]"},
      {prob0, -1, kNaN, PayloadError::kNonFinite, "gesture_observation.probabilities[0]"},
      {flags, 4, 0, PayloadError::kOutOfRange, "gesture_observation.flags"},
      // bit 1 announces a skeleton this payload does not carry
      {flags, 3, 0, PayloadError::kTruncated, "gesture_observation.skeleton.keypoints[0].x"},
      {distance, -1, -1.0, PayloadError::kOutOfRange, "gesture_observation.distance_m"},
      {distance, -1, 1e6, PayloadError::kOutOfRange, "gesture_observation.distance_m"},
      {elevation, -1, 90.5, PayloadError::kOutOfRange, "gesture_observation.elevation_deg"},
      {elevation, -1, kInf, PayloadError::kNonFinite, "gesture_observation.elevation_deg"},
      {2, -1, kNaN, PayloadError::kNonFinite, "gesture_observation.t_s"},
  };
  for (const Case& c : cases) {
    auto bad = b;
    if (c.byte >= 0) bad[c.offset] = static_cast<std::uint8_t>(c.byte);
    else putDouble(bad, c.offset, c.value);
    GestureObservationMessage untouched = d;
    std::string reason;
    EXPECT_EQ(decode(bad, untouched, &reason), c.error) << c.field;
    EXPECT_NE(reason.find(c.field), std::string::npos) << reason;
    EXPECT_EQ(untouched.t_s, d.t_s);
  }
  auto longer = b;
  longer.push_back(0);
  EXPECT_EQ(decode(longer, d), PayloadError::kTrailingBytes);
  // The encoder refuses what a decoder would.
  auto e = m;
  e.gesture_id = kMaxGestureId + 1;
  EXPECT_FALSE(encodePayload(e));
  e = m;
  e.probabilities[1] = 1.2;
  EXPECT_FALSE(encodePayload(e));
  e = m;
  e.elevation_deg = -91.0;
  EXPECT_FALSE(encodePayload(e));
  e = m;
  e.uav_index = kMaxUavIndex + 1;
  EXPECT_FALSE(encodePayload(e));
}

TEST(CommPayloadsTest, GestureObservationWithSkeletonRoundTripAndRefusals) {
  GestureObservationMessage m;
  m.uav_index = 1;
  m.t_s = 12.5;
  m.gesture_id = 2;
  m.probabilities = {0.1, 0.1, 0.6, 0.1, 0.1};
  m.geometry_known = true;
  m.distance_m = 8.0;
  m.elevation_deg = 20.0;
  const gesture::CalibratedSkeleton cam = gesture::cameraAround(8.0, 20.0, 35.0, 1.0);
  ObservedSkeleton c;
  c.q_world_camera = Eigen::Quaterniond(cam.R_world_camera);
  c.p_world_camera = cam.p_world_camera + Eigen::Vector3d(3.0, -4.0, 0.5);
  c.intrinsics.distortion = {0.01, -0.02, 0.001, 0.0, 0.003};
  for (int k = 0; k < gesture::kNumKeypoints; ++k) {
    const auto i = static_cast<std::size_t>(k);
    c.skeleton.x[i] = 300.0 + 3.25 * k;
    c.skeleton.y[i] = 150.0 + 7.5 * k;
    c.skeleton.c[i] = k == 5 ? 0.0 : 0.05 * k;
  }
  m.skeleton = c;
  const auto b = encoded(m);
  // the observation without a skeleton, then 17 × 3 f64, q (4 f64), p (3 f64), fx fy cx cy, 5 distortion, 2 × u16
  const std::size_t base = 2 + 8 + 1 + 1 + 5 * 8 + 1 + 2 * 8u;
  ASSERT_EQ(b.size(), base + 17 * 3 * 8 + 4 * 8 + 3 * 8 + 4 * 8 + 5 * 8 + 2 * 2u);
  EXPECT_EQ(b[base - 17], 3);  // flags: geometry_known | skeleton
  GestureObservationMessage d;
  ASSERT_EQ(decode(b, d), PayloadError::kNone);
  ASSERT_TRUE(d.skeleton.has_value());
  EXPECT_EQ(d.skeleton->skeleton.x, c.skeleton.x);
  EXPECT_EQ(d.skeleton->skeleton.y, c.skeleton.y);
  EXPECT_EQ(d.skeleton->skeleton.c, c.skeleton.c);
  EXPECT_EQ(d.skeleton->q_world_camera.coeffs(), c.q_world_camera.coeffs());  // sent as given: exact
  EXPECT_EQ(d.skeleton->p_world_camera, c.p_world_camera);
  EXPECT_EQ(d.skeleton->intrinsics.fx, c.intrinsics.fx);
  EXPECT_EQ(d.skeleton->intrinsics.cy, c.intrinsics.cy);
  EXPECT_EQ(d.skeleton->intrinsics.distortion, c.intrinsics.distortion);
  EXPECT_EQ(d.skeleton->intrinsics.width_px, 640);
  EXPECT_EQ(d.skeleton->intrinsics.height_px, 480);
  EXPECT_EQ(encoded(d), b);  // decode and encode are inverse
  EXPECT_LT((d.skeleton->calibrated().R_world_camera - cam.R_world_camera).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_TRUE(gesture::validate(d.skeleton->calibrated()).empty());
  // Bad values on the wire: refused naming the field, the output untouched.
  const std::size_t kp0 = base, q = base + 17 * 24, p = q + 32, fx = p + 24, width = fx + 9 * 8;
  struct Case {
    std::size_t offset;
    double value;
    PayloadError error;
    const char* field;
  };
  const Case cases[] = {
      {kp0, kNaN, PayloadError::kNonFinite, "gesture_observation.skeleton.keypoints[0].x"},
      {kp0 + 3 * 24 + 16, 1.5, PayloadError::kOutOfRange, "keypoint 3: confidence expected [0, 1], got 1.5"},
      {kp0 + 16, -0.2, PayloadError::kOutOfRange, "keypoint 0: confidence"},
      {q, 2.0, PayloadError::kOutOfRange, "gesture_observation.skeleton: q_world_camera: norm"},
      {q + 8, kInf, PayloadError::kNonFinite, "gesture_observation.skeleton.q_world_camera"},
      {p + 8, 2e4, PayloadError::kOutOfRange, "p_world_camera: expected finite within 10 km"},
      {fx, -615.0, PayloadError::kOutOfRange, "camera.fx must be > 0"},
      {fx + 4 * 8, kNaN, PayloadError::kNonFinite, "gesture_observation.skeleton.distortion"},
  };
  for (const Case& cs : cases) {
    auto bad = b;
    putDouble(bad, cs.offset, cs.value);
    GestureObservationMessage untouched = d;
    std::string reason;
    EXPECT_EQ(decode(bad, untouched, &reason), cs.error) << cs.field;
    EXPECT_NE(reason.find(cs.field), std::string::npos) << reason;
    EXPECT_EQ(untouched.skeleton->skeleton.x, d.skeleton->skeleton.x);
  }
  auto zero_width = b;
  zero_width[width] = 0;
  zero_width[width + 1] = 0;
  std::string reason;
  EXPECT_EQ(decode(zero_width, d, &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("camera.width must be > 0, got 0"), std::string::npos) << reason;
  auto shorter = b;
  shorter.pop_back();
  EXPECT_EQ(decode(shorter, d, &reason), PayloadError::kTruncated);
  EXPECT_NE(reason.find("gesture_observation.skeleton.height"), std::string::npos) << reason;
  auto longer = b;
  longer.push_back(0);
  EXPECT_EQ(decode(longer, d), PayloadError::kTrailingBytes);
  // The encoder refuses what a decoder would, naming the problem.
  auto e = m;
  e.skeleton->q_world_camera.w() += 0.01;
  const auto not_unit = encodePayload(e);
  ASSERT_FALSE(not_unit);
  EXPECT_NE(not_unit.reason().find("q_world_camera: norm"), std::string::npos) << not_unit.reason();
  e = m;
  e.skeleton->skeleton.c[4] = 1.01;
  EXPECT_FALSE(encodePayload(e));
  e = m;
  e.skeleton->intrinsics.width_px = 70000;
  EXPECT_FALSE(encodePayload(e));
}

TEST(CommPayloadsTest, DecoderChecksTypeAndCountsEveryOutcome) {
  PayloadDecoder decoder;
  Envelope e;
  e.type = MessageType::kHeartbeat;
  e.payload = encoded(Heartbeat{});
  Heartbeat h;
  EXPECT_TRUE(decoder.decode(e, h));
  WorkerStateMessage w;
  EXPECT_FALSE(decoder.decode(e, w));
  EXPECT_EQ(decoder.lastReason(), "envelope type heartbeat, expected worker_state");
  e.payload.pop_back();
  EXPECT_FALSE(decoder.decode(e, h));
  e.type = MessageType::kWorkerState;
  e.payload = encoded(WorkerStateMessage{});
  putDouble(e.payload, 0, kNaN);
  EXPECT_FALSE(decoder.decode(e, w));
  EXPECT_EQ(decoder.counters().decoded(), 1u);
  EXPECT_EQ(decoder.counters().count(PayloadError::kWrongType), 1u);
  EXPECT_EQ(decoder.counters().count(PayloadError::kTruncated), 1u);
  EXPECT_EQ(decoder.counters().count(PayloadError::kNonFinite), 1u);
  EXPECT_EQ(decoder.counters().rejected(), 3u);
}

// Random byte strings: never crash, and whatever decodes re-encodes to the same bytes.
TEST(CommPayloadsTest, RandomBytesDecodeOrRoundTripExactly) {
  std::mt19937_64 rng(99);
  int decoded = 0;
  for (int i = 0; i < 20000; ++i) {
    std::vector<std::uint8_t> b(rng() % 40);
    for (auto& x : b) x = static_cast<std::uint8_t>(rng() % 4 == 0 ? 0 : rng());
    Heartbeat h;
    if (decode(b, h) == PayloadError::kNone) {
      ++decoded;
      EXPECT_EQ(encoded(h), b);
    }
    formation::FormationCommand c;
    if (decode(b, c) == PayloadError::kNone) {
      EXPECT_EQ(encoded(c), b);
    }
  }
  EXPECT_GT(decoded, 0);
}

// The leadership message (docs/security.md §3.2): 42 bytes, broadcast as 0xffff, an unknown
// estimate age as flag bit 1 clear and 0; one encoding per message.
TEST(CommPayloadsTest, LeadershipRoundTripAndRefusals) {
  formation::LeadershipMessage m;
  m.kind = formation::LeadershipMessageKind::kVoteRequest;
  m.term = 3;
  m.from = 2;
  m.sent_s = 2.0;
  m.estimate_age_s = 0.5;
  const auto b = encoded(m);
  ASSERT_EQ(b.size(), 42u);
  const std::vector<std::uint8_t> head{4, 0, 0, 0, 3, 0, 2, 0xff, 0xff, 0x40, 0, 0, 0, 0, 0, 0, 0};
  EXPECT_TRUE(std::equal(head.begin(), head.end(), b.begin()));
  EXPECT_EQ(b[25], 0x02) << "flags: estimate known, not granted";
  formation::LeadershipMessage d;
  ASSERT_EQ(decode(b, d), PayloadError::kNone);
  EXPECT_EQ(d.kind, formation::LeadershipMessageKind::kVoteRequest);
  EXPECT_EQ(d.term, 3u);
  EXPECT_EQ(d.from, 2);
  EXPECT_EQ(d.to, formation::LeadershipMessage::kBroadcast);
  EXPECT_EQ(d.sent_s, 2.0);
  EXPECT_EQ(d.estimate_age_s, 0.5);
  EXPECT_FALSE(d.granted);
  // A reply to UAV 1, granted, no estimate: +inf survives as "not known".
  m.kind = formation::LeadershipMessageKind::kVoteReply;
  m.to = 1;
  m.granted = true;
  m.echo_s = 1.5;
  m.estimate_age_s = std::numeric_limits<double>::infinity();
  const auto r = encoded(m);
  EXPECT_EQ(r[25], 0x01);
  ASSERT_EQ(decode(r, d), PayloadError::kNone);
  EXPECT_EQ(d.to, 1);
  EXPECT_TRUE(d.granted);
  EXPECT_EQ(d.echo_s, 1.5);
  EXPECT_TRUE(std::isinf(d.estimate_age_s));
  // Encoder refusals name the field.
  auto bad_m = m;
  bad_m.from = kMaxUavIndex + 1;
  EXPECT_FALSE(encodePayload(bad_m));
  bad_m = m;
  bad_m.to = -2;
  EXPECT_FALSE(encodePayload(bad_m));
  bad_m = m;
  bad_m.sent_s = std::nan("");
  EXPECT_FALSE(encodePayload(bad_m));
  bad_m = m;
  bad_m.lease_age_s = -1.0;
  EXPECT_FALSE(encodePayload(bad_m));
  bad_m = m;
  bad_m.estimate_age_s = -0.1;
  EXPECT_FALSE(encodePayload(bad_m));
  // Decoder refusals.
  std::string reason;
  auto bad = b;
  bad[0] = 6;
  EXPECT_EQ(decodePayload(bad.data(), bad.size(), d, &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("leadership.kind"), std::string::npos) << reason;
  bad = b;
  bad[6] = kMaxUavIndex + 1;
  EXPECT_EQ(decodePayload(bad.data(), bad.size(), d, &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("leadership.from"), std::string::npos) << reason;
  bad = b;
  bad[7] = 0;
  bad[8] = kMaxUavIndex + 1;
  EXPECT_EQ(decodePayload(bad.data(), bad.size(), d, &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("leadership.to"), std::string::npos) << reason;
  bad = b;
  bad[25] = 0x04;
  EXPECT_EQ(decodePayload(bad.data(), bad.size(), d, &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("leadership.flags"), std::string::npos) << reason;
  bad = b;
  bad[25] = 0x00;  // "not known" with an age of 0.5: two encodings of one message are refused
  EXPECT_EQ(decodePayload(bad.data(), bad.size(), d, &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("leadership.estimate_age_s"), std::string::npos) << reason;
  bad = b;
  bad[26] = 0x80;  // a negative lease age
  bad[27] = 0xf0;
  EXPECT_EQ(decodePayload(bad.data(), bad.size(), d, &reason), PayloadError::kOutOfRange);
  EXPECT_NE(reason.find("leadership.lease_age_s"), std::string::npos) << reason;
  bad = b;
  bad[9] = 0x7f;  // sent_s +inf
  bad[10] = 0xf0;
  EXPECT_EQ(decode(bad, d), PayloadError::kNonFinite);
  bad = b;
  bad.pop_back();
  EXPECT_EQ(decode(bad, d), PayloadError::kTruncated);
  bad = b;
  bad.push_back(0);
  EXPECT_EQ(decode(bad, d), PayloadError::kTrailingBytes);
}
