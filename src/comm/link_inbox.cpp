#include "gesture_formation/comm/link_inbox.hpp"

#include <sstream>
#include <utility>

namespace gesture_formation::comm {

namespace {

// A payload that speaks for another UAV than its envelope's sender: counted, and why.
std::string speaksForAnother(const char* what, std::uint64_t& refused, std::uint16_t sender, const char* field, long claimed) {
  ++refused;
  return std::string(what) + " refused (" + std::to_string(refused) + " so far): sender " + std::to_string(sender) + ", " +
         field + " " + std::to_string(claimed);
}

}  // namespace

InboxItem LinkInbox::take(const Envelope& e) {
  last_refusal_.clear();
  last_decode_failure_ = false;
  InboxItem item = decodeOne(e);
  if (!decoder_.lastReason().empty()) {
    last_decode_failure_ = true;
    last_refusal_ = "payload refused (decode_failure): " + decoder_.lastReason();
  }
  return item;
}

InboxItem LinkInbox::decodeOne(const Envelope& e) {
  switch (e.type) {
    case MessageType::kHeartbeat: {
      Heartbeat h;
      decoder_.decode(e, h);  // liveness is the link's (per-sender counters); nothing to hand on
      return {};
    }
    case MessageType::kWorkerState: {
      WorkerStateMessage w;
      if (decoder_.decode(e, w)) return w;
      return {};
    }
    case MessageType::kPlannedTrajectory: {
      PlanMessage m;
      if (!decoder_.decode(e, m)) return {};
      // A UAV sends its own plans only, made before it sent them: a plan for another UAV (a
      // holder of one key speaking for another UAV) or starting after its envelope's stamp (it
      // would outrank every later plan of that UAV: receivers keep the newest t0) is refused.
      if (m.plan.uav_index != static_cast<int>(e.sender_id) || !(m.plan.t0_s <= e.stamp_s + kPlanT0AllowanceS)) {
        ++plans_refused_;
        std::ostringstream os;
        os.precision(12);
        os << "plan refused (" << plans_refused_ << " so far): sender " << e.sender_id << ", uav_index "
           << m.plan.uav_index << ", t0 " << m.plan.t0_s << " s, envelope stamp " << e.stamp_s << " s";
        last_refusal_ = os.str();
        return {};
      }
      return m;
    }
    case MessageType::kFormationParams: {
      FormationParamsMessage p;
      if (decoder_.decode(e, p)) return p;
      return {};
    }
    case MessageType::kFormationCommand: {
      formation::FormationCommand c;
      if (!decoder_.decode(e, c)) return {};
      auto forwarded = intake_.accept(e.sender_id, std::move(c));
      if (forwarded) return std::move(*forwarded);
      return {};
    }
    case MessageType::kGestureObservation: {
      GestureObservationMessage o;
      if (!decoder_.decode(e, o)) return {};
      // A UAV votes for its own camera only (its time, a wire time, is checked by the decoder).
      if (o.uav_index != e.sender_id) {
        ++observations_refused_;
        std::ostringstream os;
        os << "gesture observation refused (" << observations_refused_ << " so far): sender " << e.sender_id
           << ", uav_index " << o.uav_index << ", t " << o.t_s << " s";
        last_refusal_ = os.str();
        return {};
      }
      return o;
    }
    case MessageType::kAbortCommand: {
      AbortMessage a;
      if (decoder_.decode(e, a)) return a.command(e.stamp_s);
      return {};
    }
    case MessageType::kCommandAck: {
      CommandAckMessage a;
      if (!decoder_.decode(e, a)) return {};
      AckKey key{e.sender_id, a.id.sender, a.id.sequence};
      if (!acks_seen_.insert(key).second) return {};  // a later copy
      acks_order_.push_back(std::move(key));
      if (acks_order_.size() > kAckMemory) {
        acks_seen_.erase(acks_order_.front());
        acks_order_.pop_front();
      }
      return a;
    }
    case MessageType::kAssistance: {
      AssistanceMessage a;
      if (decoder_.decode(e, a)) return a;  // every copy: the state is idempotent
      return {};
    }
    case MessageType::kLeadership: {
      formation::LeadershipMessage m;
      if (!decoder_.decode(e, m)) return {};
      // A UAV speaks for itself only: a captured key cannot vote or beat for another member.
      if (m.from != e.sender_id) {
        last_refusal_ = speaksForAnother("leadership message", leadership_refused_, e.sender_id, "from", m.from);
        return {};
      }
      return m;
    }
    case MessageType::kMapUpdate: {
      MapUpdate m;
      if (!decoder_.decode(e, m)) return {};
      // A UAV shares its own map changes only (a captured key cannot speak for another UAV's map).
      if (m.uav_index != e.sender_id) {
        last_refusal_ = speaksForAnother("map update", map_updates_refused_, e.sender_id, "uav_index", m.uav_index);
        return {};
      }
      return m;
    }
  }
  return {};
}

}  // namespace gesture_formation::comm
