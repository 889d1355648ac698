#include "gesture_formation/comm/payloads.hpp"
#include "gesture_formation/comm/wire_time.hpp"

#include <cmath>
#include <initializer_list>
#include <limits>
#include <set>

#include <Eigen/Geometry>

#include "gesture_formation/comm/byte_io.hpp"

namespace gesture_formation::comm {

using Bytes = std::vector<std::uint8_t>;
using EncodeResult = common::Result<Bytes>;

const char* toString(PayloadError e) {
  switch (e) {
    case PayloadError::kNone: return "none";
    case PayloadError::kWrongType: return "wrong_type";
    case PayloadError::kTruncated: return "truncated";
    case PayloadError::kTrailingBytes: return "trailing_bytes";
    case PayloadError::kNonFinite: return "non_finite";
    case PayloadError::kOversizeArray: return "oversize_array";
    case PayloadError::kOutOfRange: return "out_of_range";
  }
  return "unknown";
}

std::uint64_t PayloadCounters::rejected() const {
  std::uint64_t t = 0;
  for (std::size_t i = 1; i < by_error.size(); ++i) t += by_error[i];
  return t;
}

namespace {

// ---- wire values of enums (explicit: independent of the C++ enums' order) -------------------
std::uint8_t wireSource(formation::CommandSource s) { return s == formation::CommandSource::kGesture ? 1 : 0; }
std::uint8_t wireGroup(formation::TargetGroup g) {
  switch (g) {
    case formation::TargetGroup::kLeader: return 0;
    case formation::TargetGroup::kFollowers: return 1;
    case formation::TargetGroup::kAll: return 2;
    case formation::TargetGroup::kList: return 3;
  }
  return 255;
}
std::uint8_t wireParameter(formation::Parameter p) {
  switch (p) {
    case formation::Parameter::kBeta: return 0;
    case formation::Parameter::kGamma: return 1;
    case formation::Parameter::kDistance: return 2;
  }
  return 255;
}
std::uint8_t wireKind(formation::CommandKind k) { return k == formation::CommandKind::kSet ? 1 : 0; }

bool validSenderName(const std::string& s) {
  if (s.empty() || s.size() > kMaxSenderNameBytes) return false;
  for (char c : s) {
    if (c < 0x21 || c > 0x7e) return false;
  }
  return true;
}

bool allFinite(std::initializer_list<double> values) {
  for (double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

void putVector(ByteWriter& w, const Eigen::Vector3d& v) {
  w.f64(v.x());
  w.f64(v.y());
  w.f64(v.z());
}

/// Decoding context: reads fields, remembers the first error and its field name.
class Decoder {
 public:
  Decoder(const std::uint8_t* data, std::size_t size) : r_(data, size) {}

  bool ok() const { return error_ == PayloadError::kNone; }
  PayloadError error() const { return error_; }

  bool fail(PayloadError e, const std::string& field) {
    if (error_ == PayloadError::kNone) {
      error_ = e;
      field_ = field;
    }
    return false;
  }
  bool u8(std::uint8_t& v, const char* field) { return ok() && (r_.u8(v) || fail(PayloadError::kTruncated, field)); }
  bool u16(std::uint16_t& v, const char* field) { return ok() && (r_.u16(v) || fail(PayloadError::kTruncated, field)); }
  bool u32(std::uint32_t& v, const char* field) { return ok() && (r_.u32(v) || fail(PayloadError::kTruncated, field)); }
  bool u64(std::uint64_t& v, const char* field) { return ok() && (r_.u64(v) || fail(PayloadError::kTruncated, field)); }
  /// A finite double.
  bool f64(double& v, const std::string& field) {
    if (!ok()) return false;
    double x = 0;
    if (!r_.f64(x)) return fail(PayloadError::kTruncated, field);
    if (!std::isfinite(x)) return fail(PayloadError::kNonFinite, field);
    v = x;
    return true;
  }
  /// A wire time (isWireTime).
  bool time(double& v, const std::string& field) {
    if (!f64(v, field)) return false;
    return isWireTime(v) || fail(PayloadError::kOutOfRange, field);
  }
  bool vec3(Eigen::Vector3d& v, const std::string& field) {
    return f64(v.x(), field + ".x") && f64(v.y(), field + ".y") && f64(v.z(), field + ".z");
  }
  bool bytes(std::size_t n, const std::uint8_t*& out, const char* field) {
    return ok() && (r_.bytes(n, out) || fail(PayloadError::kTruncated, field));
  }
  /// Succeeds when every byte was consumed.
  bool finish() {
    if (ok() && r_.remaining() != 0) fail(PayloadError::kTrailingBytes, std::to_string(r_.remaining()) + " bytes after the last field");
    return ok();
  }
  std::size_t remaining() const { return r_.remaining(); }

  PayloadError report(std::string* reason) const {
    if (reason != nullptr) *reason = ok() ? std::string() : std::string(toString(error_)) + ": " + field_;
    return error_;
  }

 private:
  ByteReader r_;
  PayloadError error_ = PayloadError::kNone;
  std::string field_;
};

bool validUavIndex(long v) { return v >= 0 && v <= kMaxUavIndex; }

}  // namespace

// ---- heartbeat: u16 uav_index, u8 status, u8 flags(bit0 worker_visible), u32 last_plan_sequence

EncodeResult encodePayload(const Heartbeat& m) {
  if (m.uav_index > kMaxUavIndex) return EncodeResult::fail("heartbeat.uav_index " + std::to_string(m.uav_index) + " > " + std::to_string(kMaxUavIndex));
  if (static_cast<std::uint8_t>(m.status) > 3) return EncodeResult::fail("heartbeat.status out of range");
  ByteWriter w;
  w.u16(m.uav_index);
  w.u8(static_cast<std::uint8_t>(m.status));
  w.u8(m.worker_visible ? 1 : 0);
  w.u32(m.last_plan_sequence);
  return EncodeResult::ok(w.release());
}

PayloadError decodePayload(const std::uint8_t* data, std::size_t size, Heartbeat& out, std::string* reason) {
  Decoder d(data, size);
  Heartbeat m;
  std::uint8_t status = 0, flags = 0;
  if (d.u16(m.uav_index, "heartbeat.uav_index") && !validUavIndex(m.uav_index)) d.fail(PayloadError::kOutOfRange, "heartbeat.uav_index");
  if (d.u8(status, "heartbeat.status") && status > 3) d.fail(PayloadError::kOutOfRange, "heartbeat.status");
  if (d.u8(flags, "heartbeat.flags") && (flags & ~1u) != 0) d.fail(PayloadError::kOutOfRange, "heartbeat.flags");
  d.u32(m.last_plan_sequence, "heartbeat.last_plan_sequence");
  if (d.finish()) {
    m.status = static_cast<Heartbeat::Status>(status);
    m.worker_visible = (flags & 1u) != 0;
    out = m;
  }
  return d.report(reason);
}

// ---- worker state: f64 t_s, f64 last_fused_t_s (≤ t_s), p[3], v[3], cov_diag[6] (≥ 0),
//      u8 flags(bit0 lost) -------------------------------------------------------------------

EncodeResult encodePayload(const WorkerStateMessage& m) {
  for (const auto& [t, field] : {std::pair{m.t_s, "worker_state.t_s"}, std::pair{m.last_fused_t_s, "worker_state.last_fused_t_s"}}) {
    if (const std::string e = wireTimeProblem(t, field); !e.empty()) return EncodeResult::fail(e);
  }
  if (m.last_fused_t_s > m.t_s) return EncodeResult::fail("worker_state.last_fused_t_s after t_s");
  if (!m.p_world.allFinite()) return EncodeResult::fail("worker_state.p_world not finite");
  if (!m.v_world.allFinite()) return EncodeResult::fail("worker_state.v_world not finite");
  for (double c : m.covariance_diag) {
    if (!(std::isfinite(c) && c >= 0)) return EncodeResult::fail("worker_state.covariance_diag must be finite and >= 0");
  }
  ByteWriter w;
  w.f64(m.t_s);
  w.f64(m.last_fused_t_s);
  putVector(w, m.p_world);
  putVector(w, m.v_world);
  for (double c : m.covariance_diag) w.f64(c);
  w.u8(m.lost ? 1 : 0);
  return EncodeResult::ok(w.release());
}

PayloadError decodePayload(const std::uint8_t* data, std::size_t size, WorkerStateMessage& out, std::string* reason) {
  Decoder d(data, size);
  WorkerStateMessage m;
  std::uint8_t flags = 0;
  d.time(m.t_s, "worker_state.t_s");
  if (d.time(m.last_fused_t_s, "worker_state.last_fused_t_s") && m.last_fused_t_s > m.t_s) {
    d.fail(PayloadError::kOutOfRange, "worker_state.last_fused_t_s");
  }
  d.vec3(m.p_world, "worker_state.p_world");
  d.vec3(m.v_world, "worker_state.v_world");
  for (std::size_t i = 0; i < m.covariance_diag.size(); ++i) {
    const std::string field = "worker_state.covariance_diag[" + std::to_string(i) + "]";
    if (d.f64(m.covariance_diag[i], field) && m.covariance_diag[i] < 0) d.fail(PayloadError::kOutOfRange, field);
  }
  if (d.u8(flags, "worker_state.flags") && (flags & ~1u) != 0) d.fail(PayloadError::kOutOfRange, "worker_state.flags");
  if (d.finish()) {
    m.lost = (flags & 1u) != 0;
    out = m;
  }
  return d.report(reason);
}

// ---- planned trajectory: u16 uav_index, u32 sequence, u8 flags (bit 0 fallback), f64 t0_s,
//      f64 dt_s (> 0), u16 count,
//      count × (p[3] v[3] a[3] heading pitch) ------------------------------------------------

EncodeResult encodePayload(const PlanMessage& msg) {
  const planning::PlannedTrajectory& m = msg.plan;
  if (!validUavIndex(m.uav_index)) return EncodeResult::fail("planned_trajectory.uav_index " + std::to_string(m.uav_index) + " outside [0, " + std::to_string(kMaxUavIndex) + "]");
  if (const std::string e = wireTimeProblem(m.t0_s, "planned_trajectory.t0_s"); !e.empty()) return EncodeResult::fail(e);
  if (!(std::isfinite(m.dt_s) && m.dt_s > 0)) return EncodeResult::fail("planned_trajectory.dt_s must be finite and > 0");
  if (m.samples.size() > kMaxTrajectorySamples) {
    return EncodeResult::fail("planned_trajectory.samples has " + std::to_string(m.samples.size()) + " entries, at most " + std::to_string(kMaxTrajectorySamples));
  }
  for (std::size_t k = 0; k < m.samples.size(); ++k) {
    const planning::TrajectorySample& s = m.samples[k];
    if (!(s.p_world.allFinite() && s.v_world.allFinite() && s.a_world.allFinite() && allFinite({s.heading_rad, s.pitch_rad}))) {
      return EncodeResult::fail("planned_trajectory.samples[" + std::to_string(k) + "] not finite");
    }
  }
  ByteWriter w;
  w.u16(static_cast<std::uint16_t>(m.uav_index));
  w.u32(m.sequence);
  w.u8(msg.fallback ? 1 : 0);
  w.f64(m.t0_s);
  w.f64(m.dt_s);
  w.u16(static_cast<std::uint16_t>(m.samples.size()));
  for (const planning::TrajectorySample& s : m.samples) {
    putVector(w, s.p_world);
    putVector(w, s.v_world);
    putVector(w, s.a_world);
    w.f64(s.heading_rad);
    w.f64(s.pitch_rad);
  }
  return EncodeResult::ok(w.release());
}

PayloadError decodePayload(const std::uint8_t* data, std::size_t size, PlanMessage& out, std::string* reason) {
  constexpr std::size_t kSampleBytes = 11 * 8;
  Decoder d(data, size);
  planning::PlannedTrajectory m;
  std::uint16_t uav = 0, count = 0;
  if (d.u16(uav, "planned_trajectory.uav_index") && !validUavIndex(uav)) d.fail(PayloadError::kOutOfRange, "planned_trajectory.uav_index");
  d.u32(m.sequence, "planned_trajectory.sequence");
  std::uint8_t flags = 0;
  if (d.u8(flags, "planned_trajectory.flags") && (flags & ~1u) != 0) d.fail(PayloadError::kOutOfRange, "planned_trajectory.flags");
  d.time(m.t0_s, "planned_trajectory.t0_s");
  if (d.f64(m.dt_s, "planned_trajectory.dt_s") && !(m.dt_s > 0)) d.fail(PayloadError::kOutOfRange, "planned_trajectory.dt_s");
  if (d.u16(count, "planned_trajectory.count")) {
    if (count > kMaxTrajectorySamples) {
      d.fail(PayloadError::kOversizeArray, "planned_trajectory.count " + std::to_string(count));
    } else if (d.remaining() < count * kSampleBytes) {
      // Checked before allocating: the count cannot make us reserve more than the bytes hold.
      d.fail(PayloadError::kTruncated, "planned_trajectory.samples");
    }
  }
  if (d.ok()) {
    m.uav_index = uav;
    m.samples.resize(count);
    for (std::size_t k = 0; k < count && d.ok(); ++k) {
      planning::TrajectorySample& s = m.samples[k];
      const std::string field = "planned_trajectory.samples[" + std::to_string(k) + "]";
      d.vec3(s.p_world, field + ".p_world");
      d.vec3(s.v_world, field + ".v_world");
      d.vec3(s.a_world, field + ".a_world");
      d.f64(s.heading_rad, field + ".heading_rad");
      d.f64(s.pitch_rad, field + ".pitch_rad");
    }
  }
  if (d.finish()) out = PlanMessage{std::move(m), (flags & 1u) != 0};
  return d.report(reason);
}

// ---- formation params: leader (β, γ, d), u8 follower count, count × (β, γ, d), u64 version ---

EncodeResult encodePayload(const FormationParamsMessage& msg) {
  const formation::FormationParams& m = msg.params;
  if (m.followers.size() > kMaxFollowers) {
    return EncodeResult::fail("formation_params.followers has " + std::to_string(m.followers.size()) + " entries, at most " + std::to_string(kMaxFollowers));
  }
  for (int u = 0; u < m.uavCount(); ++u) {
    const formation::UavObservation& o = m.uav(u);
    if (!allFinite({o.beta_deg, o.gamma_deg, o.distance_m}) || !(o.distance_m > 0)) {
      return EncodeResult::fail("formation_params UAV " + formation::uavLabel(u) + ": values must be finite and distance_m > 0");
    }
  }
  ByteWriter w;
  auto put = [&w](const formation::UavObservation& o) {
    w.f64(o.beta_deg);
    w.f64(o.gamma_deg);
    w.f64(o.distance_m);
  };
  put(m.leader);
  w.u8(static_cast<std::uint8_t>(m.followers.size()));
  for (const formation::UavObservation& o : m.followers) put(o);
  w.u64(msg.version);
  return EncodeResult::ok(w.release());
}

PayloadError decodePayload(const std::uint8_t* data, std::size_t size, FormationParamsMessage& out,
                           std::string* reason) {
  Decoder d(data, size);
  FormationParamsMessage msg;
  formation::FormationParams& m = msg.params;
  auto get = [&d](formation::UavObservation& o, const std::string& name) {
    d.f64(o.beta_deg, name + ".beta_deg");
    d.f64(o.gamma_deg, name + ".gamma_deg");
    if (d.f64(o.distance_m, name + ".distance_m") && !(o.distance_m > 0)) d.fail(PayloadError::kOutOfRange, name + ".distance_m");
  };
  get(m.leader, "formation_params.leader");
  std::uint8_t count = 0;
  if (d.u8(count, "formation_params.follower_count") && count > kMaxFollowers) {
    d.fail(PayloadError::kOversizeArray, "formation_params.follower_count " + std::to_string(count));
  }
  if (d.ok()) {
    m.followers.assign(count, formation::UavObservation{});
    for (std::size_t i = 0; i < count && d.ok(); ++i) get(m.followers[i], "formation_params.followers[" + std::to_string(i) + "]");
  }
  d.u64(msg.version, "formation_params.version");
  if (d.finish()) out = std::move(msg);
  return d.report(reason);
}

// ---- formation command: u8 name length, name, u64 sequence, u8 source, u8 group, u8 uav count,
//      count × u16 uav, u8 parameter, u8 kind, f64 amount -------------------------------------

EncodeResult encodePayload(const formation::FormationCommand& m) {
  if (!validSenderName(m.id.sender)) {
    return EncodeResult::fail("formation_command.id.sender must be 1.." + std::to_string(kMaxSenderNameBytes) + " printable ASCII characters without spaces");
  }
  const std::uint8_t group = wireGroup(m.target.group);
  const std::uint8_t parameter = wireParameter(m.parameter);
  if (group == 255) return EncodeResult::fail("formation_command.target.group out of range");
  if (parameter == 255) return EncodeResult::fail("formation_command.parameter out of range");
  const bool is_list = m.target.group == formation::TargetGroup::kList;
  if (is_list && m.target.uavs.empty()) return EncodeResult::fail("formation_command.target.uavs is empty for a list target");
  if (!is_list && !m.target.uavs.empty()) return EncodeResult::fail("formation_command.target.uavs must be empty unless the group is a list");
  if (m.target.uavs.size() > kMaxCommandTargets) return EncodeResult::fail("formation_command.target.uavs has more than " + std::to_string(kMaxCommandTargets) + " entries");
  for (formation::UavIndex u : m.target.uavs) {
    if (!validUavIndex(u)) return EncodeResult::fail("formation_command.target.uavs holds UAV index " + std::to_string(u));
  }
  if (!std::isfinite(m.amount)) return EncodeResult::fail("formation_command.amount not finite");
  ByteWriter w;
  w.u8(static_cast<std::uint8_t>(m.id.sender.size()));
  w.bytes(reinterpret_cast<const std::uint8_t*>(m.id.sender.data()), m.id.sender.size());
  w.u64(m.id.sequence);
  w.u8(wireSource(m.source));
  w.u8(group);
  w.u8(static_cast<std::uint8_t>(m.target.uavs.size()));
  for (formation::UavIndex u : m.target.uavs) w.u16(static_cast<std::uint16_t>(u));
  w.u8(parameter);
  w.u8(wireKind(m.kind));
  w.f64(m.amount);
  return EncodeResult::ok(w.release());
}

PayloadError decodePayload(const std::uint8_t* data, std::size_t size, formation::FormationCommand& out,
                           std::string* reason) {
  Decoder d(data, size);
  formation::FormationCommand m;
  std::uint8_t name_len = 0, source = 0, group = 0, count = 0, parameter = 0, kind = 0;
  if (d.u8(name_len, "formation_command.id.sender_length") && (name_len == 0 || name_len > kMaxSenderNameBytes)) {
    d.fail(name_len == 0 ? PayloadError::kOutOfRange : PayloadError::kOversizeArray, "formation_command.id.sender_length");
  }
  const std::uint8_t* name = nullptr;
  if (d.bytes(name_len, name, "formation_command.id.sender")) {
    m.id.sender.assign(reinterpret_cast<const char*>(name), name_len);
    if (!validSenderName(m.id.sender)) d.fail(PayloadError::kOutOfRange, "formation_command.id.sender");
  }
  d.u64(m.id.sequence, "formation_command.id.sequence");
  if (d.u8(source, "formation_command.source") && source > 1) d.fail(PayloadError::kOutOfRange, "formation_command.source");
  if (d.u8(group, "formation_command.target.group") && group > 3) d.fail(PayloadError::kOutOfRange, "formation_command.target.group");
  if (d.u8(count, "formation_command.target.count")) {
    if (count > kMaxCommandTargets) {
      d.fail(PayloadError::kOversizeArray, "formation_command.target.count " + std::to_string(count));
    } else if ((group == 3) != (count > 0)) {
      d.fail(PayloadError::kOutOfRange, "formation_command.target.count (a list target needs UAVs, other groups none)");
    }
  }
  for (std::size_t i = 0; i < count && d.ok(); ++i) {
    std::uint16_t u = 0;
    const std::string field = "formation_command.target.uavs[" + std::to_string(i) + "]";
    if (d.u16(u, field.c_str())) {
      if (!validUavIndex(u)) {
        d.fail(PayloadError::kOutOfRange, field);
      } else {
        m.target.uavs.push_back(u);
      }
    }
  }
  if (d.u8(parameter, "formation_command.parameter") && parameter > 2) d.fail(PayloadError::kOutOfRange, "formation_command.parameter");
  if (d.u8(kind, "formation_command.kind") && kind > 1) d.fail(PayloadError::kOutOfRange, "formation_command.kind");
  d.f64(m.amount, "formation_command.amount");
  if (d.finish()) {
    static const formation::TargetGroup kGroups[] = {formation::TargetGroup::kLeader, formation::TargetGroup::kFollowers,
                                                     formation::TargetGroup::kAll, formation::TargetGroup::kList};
    static const formation::Parameter kParameters[] = {formation::Parameter::kBeta, formation::Parameter::kGamma,
                                                       formation::Parameter::kDistance};
    m.source = source == 1 ? formation::CommandSource::kGesture : formation::CommandSource::kOperator;
    m.target.group = kGroups[group];
    m.parameter = kParameters[parameter];
    m.kind = kind == 1 ? formation::CommandKind::kSet : formation::CommandKind::kIncrement;
    out = std::move(m);
  }
  return d.report(reason);
}

// ---- gesture observation: u16 uav_index, f64 t_s, u8 gesture_id, u8 count, count × f64
//      probability, u8 flags (bit0 geometry_known, bit1 skeleton), f64 distance_m, f64 elevation_deg,
//      with bit1: 17 × (f64 x, f64 y, f64 confidence), f64 q_world_camera w x y z (unit within 1e-6),
//      f64 p_world_camera x y z, f64 fx fy cx cy, 5 × f64 distortion, u16 width, u16 height ----------

constexpr double kUnitQuaternionTolerance = 1e-6;

gesture::CalibratedSkeleton ObservedSkeleton::calibrated() const {
  gesture::CalibratedSkeleton c;
  c.skeleton = skeleton;
  c.R_world_camera = q_world_camera.normalized().toRotationMatrix();
  c.p_world_camera = p_world_camera;
  c.intrinsics = intrinsics;
  return c;
}

std::vector<std::string> ObservedSkeleton::validate() const {
  std::vector<std::string> e;
  const double n = q_world_camera.norm();
  if (!(std::abs(n - 1.0) <= kUnitQuaternionTolerance)) {
    e.push_back("q_world_camera: norm " + std::to_string(n) + ", expected 1 +- 1e-6");
    return e;  // calibrated() would be meaningless
  }
  if (intrinsics.width_px > 65535 || intrinsics.height_px > 65535) {
    e.push_back("image size " + std::to_string(intrinsics.width_px) + " x " + std::to_string(intrinsics.height_px) +
                " above 65535");
  }
  for (auto& p : gesture::validate(calibrated())) e.push_back(std::move(p));
  return e;
}

namespace {

void putSkeleton(ByteWriter& w, const ObservedSkeleton& o) {
  for (std::size_t k = 0; k < static_cast<std::size_t>(gesture::kNumKeypoints); ++k) {
    w.f64(o.skeleton.x[k]);
    w.f64(o.skeleton.y[k]);
    w.f64(o.skeleton.c[k]);
  }
  w.f64(o.q_world_camera.w());
  w.f64(o.q_world_camera.x());
  w.f64(o.q_world_camera.y());
  w.f64(o.q_world_camera.z());
  w.f64(o.p_world_camera.x());
  w.f64(o.p_world_camera.y());
  w.f64(o.p_world_camera.z());
  const estimation::CameraIntrinsics& k = o.intrinsics;
  w.f64(k.fx);
  w.f64(k.fy);
  w.f64(k.cx);
  w.f64(k.cy);
  for (double d : k.distortion) w.f64(d);
  w.u16(static_cast<std::uint16_t>(k.width_px));
  w.u16(static_cast<std::uint16_t>(k.height_px));
}

/// Reads what putSkeleton wrote and validates it.
void getSkeleton(Decoder& d, ObservedSkeleton& o) {
  const std::string f = "gesture_observation.skeleton";
  for (std::size_t k = 0; d.ok() && k < static_cast<std::size_t>(gesture::kNumKeypoints); ++k) {
    const std::string kp = f + ".keypoints[" + std::to_string(k) + "]";
    d.f64(o.skeleton.x[k], kp + ".x");
    d.f64(o.skeleton.y[k], kp + ".y");
    d.f64(o.skeleton.c[k], kp + ".confidence");
  }
  d.f64(o.q_world_camera.w(), f + ".q_world_camera");
  d.f64(o.q_world_camera.x(), f + ".q_world_camera");
  d.f64(o.q_world_camera.y(), f + ".q_world_camera");
  d.f64(o.q_world_camera.z(), f + ".q_world_camera");
  d.vec3(o.p_world_camera, f + ".p_world_camera");
  estimation::CameraIntrinsics& k = o.intrinsics;
  d.f64(k.fx, f + ".fx");
  d.f64(k.fy, f + ".fy");
  d.f64(k.cx, f + ".cx");
  d.f64(k.cy, f + ".cy");
  for (double& x : k.distortion) d.f64(x, f + ".distortion");
  std::uint16_t width = 0, height = 0;
  d.u16(width, "gesture_observation.skeleton.width");
  d.u16(height, "gesture_observation.skeleton.height");
  k.width_px = width;
  k.height_px = height;
  if (d.ok()) {
    const std::vector<std::string> problems = o.validate();
    if (!problems.empty()) d.fail(PayloadError::kOutOfRange, f + ": " + problems.front());
  }
}

}  // namespace

EncodeResult encodePayload(const GestureObservationMessage& m) {
  if (!validUavIndex(m.uav_index)) return EncodeResult::fail("gesture_observation.uav_index " + std::to_string(m.uav_index) + " outside [0, " + std::to_string(kMaxUavIndex) + "]");
  if (const std::string e = wireTimeProblem(m.t_s, "gesture_observation.t_s"); !e.empty()) return EncodeResult::fail(e);
  if (m.gesture_id > kMaxGestureId) return EncodeResult::fail("gesture_observation.gesture_id " + std::to_string(m.gesture_id) + " > " + std::to_string(kMaxGestureId));
  if (m.probabilities.size() > kMaxGestureClasses) return EncodeResult::fail("gesture_observation.probabilities has " + std::to_string(m.probabilities.size()) + " entries, at most " + std::to_string(kMaxGestureClasses));
  for (double p : m.probabilities) {
    if (!(p >= 0.0 && p <= 1.0)) return EncodeResult::fail("gesture_observation.probabilities must be in [0, 1]");
  }
  if (!(m.distance_m >= 0.0 && m.distance_m <= kMaxObservationDistanceM)) return EncodeResult::fail("gesture_observation.distance_m outside [0, 1000]");
  if (!(m.elevation_deg >= -90.0 && m.elevation_deg <= 90.0)) return EncodeResult::fail("gesture_observation.elevation_deg outside [-90, 90]");
  if (m.skeleton) {
    const std::vector<std::string> problems = m.skeleton->validate();
    if (!problems.empty()) return EncodeResult::fail("gesture_observation.skeleton: " + problems.front());
  }
  ByteWriter w;
  w.u16(m.uav_index);
  w.f64(m.t_s);
  w.u8(m.gesture_id);
  w.u8(static_cast<std::uint8_t>(m.probabilities.size()));
  for (double p : m.probabilities) w.f64(p);
  w.u8(static_cast<std::uint8_t>((m.geometry_known ? 1u : 0u) | (m.skeleton ? 2u : 0u)));
  w.f64(m.distance_m);
  w.f64(m.elevation_deg);
  if (m.skeleton) putSkeleton(w, *m.skeleton);
  return EncodeResult::ok(w.release());
}

PayloadError decodePayload(const std::uint8_t* data, std::size_t size, GestureObservationMessage& out, std::string* reason) {
  Decoder d(data, size);
  GestureObservationMessage m;
  std::uint8_t count = 0, flags = 0;
  if (d.u16(m.uav_index, "gesture_observation.uav_index") && !validUavIndex(m.uav_index)) {
    d.fail(PayloadError::kOutOfRange, "gesture_observation.uav_index");
  }
  d.time(m.t_s, "gesture_observation.t_s");
  if (d.u8(m.gesture_id, "gesture_observation.gesture_id") && m.gesture_id > kMaxGestureId) {
    d.fail(PayloadError::kOutOfRange, "gesture_observation.gesture_id");
  }
  if (d.u8(count, "gesture_observation.count") && count > kMaxGestureClasses) {
    d.fail(PayloadError::kOversizeArray, "gesture_observation.probabilities");
  }
  for (std::size_t i = 0; d.ok() && i < count; ++i) {
    const std::string field = "gesture_observation.probabilities[" + std::to_string(i) + "]";
    double p = 0.0;
    if (d.f64(p, field) && !(p >= 0.0 && p <= 1.0)) d.fail(PayloadError::kOutOfRange, field);
    m.probabilities.push_back(p);
  }
  if (d.u8(flags, "gesture_observation.flags") && (flags & ~3u) != 0) d.fail(PayloadError::kOutOfRange, "gesture_observation.flags");
  if (d.f64(m.distance_m, "gesture_observation.distance_m") && !(m.distance_m >= 0.0 && m.distance_m <= kMaxObservationDistanceM)) {
    d.fail(PayloadError::kOutOfRange, "gesture_observation.distance_m");
  }
  if (d.f64(m.elevation_deg, "gesture_observation.elevation_deg") && !(m.elevation_deg >= -90.0 && m.elevation_deg <= 90.0)) {
    d.fail(PayloadError::kOutOfRange, "gesture_observation.elevation_deg");
  }
  if (d.ok() && (flags & 2u) != 0) {
    m.skeleton.emplace();
    getSkeleton(d, *m.skeleton);
  }
  if (d.finish()) {
    m.geometry_known = (flags & 1u) != 0;
    out = std::move(m);
  }
  return d.report(reason);
}

// ---- abort command: u8 sender length, sender bytes, u64 sequence, u8 source (0 operator, 1 gesture) --

EncodeResult encodePayload(const AbortMessage& m) {
  if (!validSenderName(m.id.sender)) {
    return EncodeResult::fail("abort_command.id.sender must be 1.." + std::to_string(kMaxSenderNameBytes) +
                              " printable ASCII characters without spaces");
  }
  ByteWriter w;
  w.u8(static_cast<std::uint8_t>(m.id.sender.size()));
  w.bytes(reinterpret_cast<const std::uint8_t*>(m.id.sender.data()), m.id.sender.size());
  w.u64(m.id.sequence);
  w.u8(m.source == planning::AbortSource::kGesture ? 1 : 0);
  return EncodeResult::ok(w.release());
}

PayloadError decodePayload(const std::uint8_t* data, std::size_t size, AbortMessage& out, std::string* reason) {
  Decoder d(data, size);
  AbortMessage m;
  std::uint8_t name_len = 0, source = 0;
  if (d.u8(name_len, "abort_command.id.sender_length") && (name_len == 0 || name_len > kMaxSenderNameBytes)) {
    d.fail(name_len == 0 ? PayloadError::kOutOfRange : PayloadError::kOversizeArray, "abort_command.id.sender_length");
  }
  const std::uint8_t* name = nullptr;
  if (d.bytes(name_len, name, "abort_command.id.sender")) {
    m.id.sender.assign(reinterpret_cast<const char*>(name), name_len);
    if (!validSenderName(m.id.sender)) d.fail(PayloadError::kOutOfRange, "abort_command.id.sender");
  }
  d.u64(m.id.sequence, "abort_command.id.sequence");
  if (d.u8(source, "abort_command.source") && source > 1) d.fail(PayloadError::kOutOfRange, "abort_command.source");
  if (d.finish()) {
    m.source = source == 1 ? planning::AbortSource::kGesture : planning::AbortSource::kOperator;
    out = std::move(m);
  }
  return d.report(reason);
}

// ---- command acknowledgement: u8 sender length, sender bytes, u64 sequence, u8 source (0 operator,
// 1 gesture), u8 status (0 applied, 1 duplicate, 2 rejected), u64 params version, f64 command stamp,
// u8 outcome length, outcome bytes (UTF-8, no control characters) ----------------------------

namespace {

bool validOutcomeText(const std::string& s) {
  if (s.size() > kMaxAckOutcomeBytes) return false;
  for (char c : s) {
    const auto b = static_cast<unsigned char>(c);
    if (b < 0x20 || b == 0x7f) return false;
  }
  return true;
}

std::uint8_t wireStatus(formation::CommandStatus s) {
  switch (s) {
    case formation::CommandStatus::kApplied: return 0;
    case formation::CommandStatus::kDuplicate: return 1;
    case formation::CommandStatus::kRejected: return 2;
  }
  return 2;
}

}  // namespace

EncodeResult encodePayload(const CommandAckMessage& m) {
  if (!validSenderName(m.id.sender)) {
    return EncodeResult::fail("command_ack.id.sender must be 1.." + std::to_string(kMaxSenderNameBytes) +
                              " printable ASCII characters without spaces");
  }
  if (const std::string e = wireTimeProblem(m.command_stamp_s, "command_ack.command_stamp_s"); !e.empty()) return EncodeResult::fail(e);
  if (!validOutcomeText(m.outcome)) {
    return EncodeResult::fail("command_ack.outcome must be at most " + std::to_string(kMaxAckOutcomeBytes) +
                              " bytes without control characters (" + std::to_string(m.outcome.size()) + " bytes)");
  }
  ByteWriter w;
  w.u8(static_cast<std::uint8_t>(m.id.sender.size()));
  w.bytes(reinterpret_cast<const std::uint8_t*>(m.id.sender.data()), m.id.sender.size());
  w.u64(m.id.sequence);
  w.u8(m.source == formation::CommandSource::kGesture ? 1 : 0);
  w.u8(wireStatus(m.status));
  w.u64(m.params_version);
  w.f64(m.command_stamp_s);
  w.u8(static_cast<std::uint8_t>(m.outcome.size()));
  w.bytes(reinterpret_cast<const std::uint8_t*>(m.outcome.data()), m.outcome.size());
  return EncodeResult::ok(w.release());
}

PayloadError decodePayload(const std::uint8_t* data, std::size_t size, CommandAckMessage& out, std::string* reason) {
  Decoder d(data, size);
  CommandAckMessage m;
  std::uint8_t name_len = 0, source = 0, status = 0, outcome_len = 0;
  if (d.u8(name_len, "command_ack.id.sender_length") && (name_len == 0 || name_len > kMaxSenderNameBytes)) {
    d.fail(name_len == 0 ? PayloadError::kOutOfRange : PayloadError::kOversizeArray, "command_ack.id.sender_length");
  }
  const std::uint8_t* bytes = nullptr;
  if (d.bytes(name_len, bytes, "command_ack.id.sender")) {
    m.id.sender.assign(reinterpret_cast<const char*>(bytes), name_len);
    if (!validSenderName(m.id.sender)) d.fail(PayloadError::kOutOfRange, "command_ack.id.sender");
  }
  d.u64(m.id.sequence, "command_ack.id.sequence");
  if (d.u8(source, "command_ack.source") && source > 1) d.fail(PayloadError::kOutOfRange, "command_ack.source");
  if (d.u8(status, "command_ack.status") && status > 2) d.fail(PayloadError::kOutOfRange, "command_ack.status");
  d.u64(m.params_version, "command_ack.params_version");
  d.time(m.command_stamp_s, "command_ack.command_stamp_s");
  if (d.u8(outcome_len, "command_ack.outcome_length") && outcome_len > kMaxAckOutcomeBytes) {
    d.fail(PayloadError::kOversizeArray, "command_ack.outcome_length");
  }
  if (d.bytes(outcome_len, bytes, "command_ack.outcome")) {
    m.outcome.assign(reinterpret_cast<const char*>(bytes), outcome_len);
    if (!validOutcomeText(m.outcome)) d.fail(PayloadError::kOutOfRange, "command_ack.outcome");
  }
  if (d.finish()) {
    m.source = source == 1 ? formation::CommandSource::kGesture : formation::CommandSource::kOperator;
    m.status = status == 0 ? formation::CommandStatus::kApplied
                           : (status == 1 ? formation::CommandStatus::kDuplicate : formation::CommandStatus::kRejected);
    out = std::move(m);
  }
  return d.report(reason);
}

// ---- assistance: u8 phase (0 none, 1 requested, 2 acknowledged), f64 requested_s, u8 L, L bytes
// requested_by, f64 acknowledged_s, u8 M, M bytes acknowledged_by ---------------------------------

namespace {

bool validOptionalName(const std::string& s) { return s.empty() || validSenderName(s); }

}  // namespace

EncodeResult encodePayload(const AssistanceMessage& m) {
  const auto& a = m.state;
  for (const auto& [t, field] : {std::pair{a.requested_s, "assistance.requested_s"}, std::pair{a.acknowledged_s, "assistance.acknowledged_s"}}) {
    if (const std::string e = wireTimeProblem(t, field); !e.empty()) return EncodeResult::fail(e);
  }
  if (!validOptionalName(a.requested_by) || !validOptionalName(a.acknowledged_by)) {
    return EncodeResult::fail("assistance.requested_by / acknowledged_by must be 0.." + std::to_string(kMaxSenderNameBytes) +
                              " printable ASCII characters without spaces");
  }
  ByteWriter w;
  w.u8(static_cast<std::uint8_t>(a.phase));
  w.f64(a.requested_s);
  w.u8(static_cast<std::uint8_t>(a.requested_by.size()));
  w.bytes(reinterpret_cast<const std::uint8_t*>(a.requested_by.data()), a.requested_by.size());
  w.f64(a.acknowledged_s);
  w.u8(static_cast<std::uint8_t>(a.acknowledged_by.size()));
  w.bytes(reinterpret_cast<const std::uint8_t*>(a.acknowledged_by.data()), a.acknowledged_by.size());
  return EncodeResult::ok(w.release());
}

PayloadError decodePayload(const std::uint8_t* data, std::size_t size, AssistanceMessage& out, std::string* reason) {
  Decoder d(data, size);
  AssistanceMessage m;
  auto& a = m.state;
  std::uint8_t phase = 0;
  if (d.u8(phase, "assistance.phase") && phase > 2) d.fail(PayloadError::kOutOfRange, "assistance.phase");
  d.time(a.requested_s, "assistance.requested_s");
  auto name = [&d](std::string& into, const char* length_field, const char* field) {
    std::uint8_t n = 0;
    if (d.u8(n, length_field) && n > kMaxSenderNameBytes) d.fail(PayloadError::kOversizeArray, length_field);
    const std::uint8_t* bytes = nullptr;
    if (d.bytes(n, bytes, field)) {
      into.assign(reinterpret_cast<const char*>(bytes), n);
      if (!validOptionalName(into)) d.fail(PayloadError::kOutOfRange, field);
    }
  };
  name(a.requested_by, "assistance.requested_by_length", "assistance.requested_by");
  d.time(a.acknowledged_s, "assistance.acknowledged_s");
  name(a.acknowledged_by, "assistance.acknowledged_by_length", "assistance.acknowledged_by");
  if (d.finish()) {
    a.phase = static_cast<formation::AssistancePhase>(phase);
    out = std::move(m);
  }
  return d.report(reason);
}

// ---- leadership (42 B): u8 kind, u32 term, u16 from, u16 to (0xffff broadcast), f64 sent_s,
// f64 echo_s, u8 flags (bit 0 granted, bit 1 estimate known), f64 lease_age_s, f64 estimate_age_s
// (0 when not known) -------------------------------------------------------------------------------

namespace {

constexpr std::uint16_t kWireBroadcast = 0xffff;
constexpr std::uint8_t kLeadershipGranted = 0x01, kLeadershipEstimateKnown = 0x02;
constexpr std::uint8_t kMaxLeadershipKind = static_cast<std::uint8_t>(formation::LeadershipMessageKind::kVoteReply);

}  // namespace

EncodeResult encodePayload(const formation::LeadershipMessage& m) {
  if (static_cast<std::uint8_t>(m.kind) > kMaxLeadershipKind) return EncodeResult::fail("leadership.kind out of range");
  if (m.from < 0 || m.from > kMaxUavIndex) {
    return EncodeResult::fail("leadership.from must be 0.." + std::to_string(kMaxUavIndex) + ", got " + std::to_string(m.from));
  }
  if (m.to != formation::LeadershipMessage::kBroadcast && (m.to < 0 || m.to > kMaxUavIndex)) {
    return EncodeResult::fail("leadership.to must be -1 (broadcast) or 0.." + std::to_string(kMaxUavIndex) + ", got " +
                              std::to_string(m.to));
  }
  if (!allFinite({m.sent_s, m.echo_s, m.lease_age_s}) || m.lease_age_s < 0.0) {
    return EncodeResult::fail("leadership.sent_s / echo_s must be finite and lease_age_s finite and >= 0");
  }
  const bool known = std::isfinite(m.estimate_age_s);
  if (std::isnan(m.estimate_age_s) || m.estimate_age_s < 0.0) {
    return EncodeResult::fail("leadership.estimate_age_s must be >= 0 or +inf (none)");
  }
  ByteWriter w;
  w.u8(static_cast<std::uint8_t>(m.kind));
  w.u32(m.term);
  w.u16(static_cast<std::uint16_t>(m.from));
  w.u16(m.to == formation::LeadershipMessage::kBroadcast ? kWireBroadcast : static_cast<std::uint16_t>(m.to));
  w.f64(m.sent_s);
  w.f64(m.echo_s);
  w.u8(static_cast<std::uint8_t>((m.granted ? kLeadershipGranted : 0) | (known ? kLeadershipEstimateKnown : 0)));
  w.f64(m.lease_age_s);
  w.f64(known ? m.estimate_age_s : 0.0);
  return EncodeResult::ok(w.release());
}

PayloadError decodePayload(const std::uint8_t* data, std::size_t size, formation::LeadershipMessage& out,
                           std::string* reason) {
  Decoder d(data, size);
  formation::LeadershipMessage m;
  std::uint8_t kind = 0, flags = 0;
  std::uint16_t from = 0, to = 0;
  double estimate_age_s = 0.0;
  if (d.u8(kind, "leadership.kind") && kind > kMaxLeadershipKind) d.fail(PayloadError::kOutOfRange, "leadership.kind");
  d.u32(m.term, "leadership.term");
  if (d.u16(from, "leadership.from") && from > kMaxUavIndex) d.fail(PayloadError::kOutOfRange, "leadership.from");
  if (d.u16(to, "leadership.to") && to != kWireBroadcast && to > kMaxUavIndex) {
    d.fail(PayloadError::kOutOfRange, "leadership.to");
  }
  d.f64(m.sent_s, "leadership.sent_s");
  d.f64(m.echo_s, "leadership.echo_s");
  if (d.u8(flags, "leadership.flags") && (flags & ~(kLeadershipGranted | kLeadershipEstimateKnown)) != 0) {
    d.fail(PayloadError::kOutOfRange, "leadership.flags");
  }
  if (d.f64(m.lease_age_s, "leadership.lease_age_s") && m.lease_age_s < 0.0) {
    d.fail(PayloadError::kOutOfRange, "leadership.lease_age_s");
  }
  // Without bit 1 the age must be 0 (one encoding per message: what decodes re-encodes the same).
  if (d.f64(estimate_age_s, "leadership.estimate_age_s") &&
      (estimate_age_s < 0.0 || (!(flags & kLeadershipEstimateKnown) && estimate_age_s != 0.0) ||
       (estimate_age_s == 0.0 && std::signbit(estimate_age_s)))) {
    d.fail(PayloadError::kOutOfRange, "leadership.estimate_age_s");
  }
  if (d.finish()) {
    m.kind = static_cast<formation::LeadershipMessageKind>(kind);
    m.from = from;
    m.to = to == kWireBroadcast ? formation::LeadershipMessage::kBroadcast : to;
    m.granted = (flags & kLeadershipGranted) != 0;
    m.estimate_age_s = (flags & kLeadershipEstimateKnown) ? estimate_age_s : std::numeric_limits<double>::infinity();
    out = m;
  }
  return d.report(reason);
}

}  // namespace gesture_formation::comm
