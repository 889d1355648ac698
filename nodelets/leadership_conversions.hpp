#pragma once
// Leadership message ↔ core conversions (LcmBridge, Leadership nodelet; docs/safety.md §1.2).
#include <ros/time.h>

#include "gesture_formation/LeadershipMessage.h"
#include "gesture_formation/LeadershipState.h"
#include "gesture_formation/comm/payloads.hpp"
#include "gesture_formation/common/result.hpp"
#include "gesture_formation/formation/leadership.hpp"

namespace gesture_formation::nodelets {

inline gesture_formation::LeadershipMessage toMsg(const formation::LeadershipMessage& m) {
  gesture_formation::LeadershipMessage r;
  r.kind = static_cast<std::uint8_t>(m.kind);
  r.term = m.term;
  r.sender = m.from;
  r.addressee = m.to;
  r.sent_s = m.sent_s;
  r.echo_s = m.echo_s;
  r.granted = m.granted;
  r.lease_age_s = m.lease_age_s;
  r.estimate_age_s = m.estimate_age_s;
  return r;
}

/// A leadership message from ROS, checked as the wire checks it (comm::encodePayload); fails naming the field.
inline common::Result<formation::LeadershipMessage> fromMsg(const gesture_formation::LeadershipMessage& r) {
  using R = common::Result<formation::LeadershipMessage>;
  if (r.kind > gesture_formation::LeadershipMessage::KIND_VOTE_REPLY) {
    return R::fail("leadership.kind must be 0..5, got " + std::to_string(r.kind));
  }
  formation::LeadershipMessage m;
  m.kind = static_cast<formation::LeadershipMessageKind>(r.kind);
  m.term = r.term;
  m.from = r.sender;
  m.to = r.addressee;
  m.sent_s = r.sent_s;
  m.echo_s = r.echo_s;
  m.granted = r.granted;
  m.lease_age_s = r.lease_age_s;
  m.estimate_age_s = r.estimate_age_s;
  if (auto e = comm::encodePayload(m); !e) return R::fail(e.reason());  // the wire's rules
  return R::ok(m);
}

/// One UAV's leadership view at `stamp`.
inline gesture_formation::LeadershipState toStateMsg(const formation::Leadership& l, bool acting, const ros::Time& stamp) {
  gesture_formation::LeadershipState s;
  s.header.stamp = stamp;
  s.uav_index = l.self();
  s.term = l.term();
  s.leader = l.leader();
  s.role = static_cast<std::uint8_t>(l.role());
  s.acting = acting;
  if (acting) s.lease_until = ros::Time(l.leaseUntil());
  return s;
}

}  // namespace gesture_formation::nodelets
