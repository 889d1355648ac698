#include "gesture_formation/comm/link_settings.hpp"

#include <algorithm>

#include "gesture_formation/comm/payloads.hpp"
#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::comm {

namespace {

bool senderId(int id) { return id >= 0 && id <= 65535; }

/// The ids of `list` other than `own` into `out`; a problem per id out of range.
void senderList(const std::string& key, const std::vector<int>& list, int own, std::vector<std::uint16_t>& out,
                std::vector<common::ConfigError>& problems) {
  for (const int id : list) {
    if (!senderId(id)) problems.push_back({key, std::to_string(id) + " out of range [0, 65535]"});
    else if (id != own) out.push_back(static_cast<std::uint16_t>(id));  // own id: never received
  }
}

}  // namespace

VerifierConfig verifierConfigOf(const LinkSettings& s, std::vector<common::ConfigError>& problems) {
  VerifierConfig c;
  if (!senderId(s.sender_id)) problems.push_back({"sender_id", "must be in [0, 65535], got " + std::to_string(s.sender_id)});
  // Ages: the verifier's own range (one range per setting). A value outside it is reported
  // here and keeps its default in the config, so that the verifier's rules add only what is new.
  const common::Range& age = *verifierFields().rangeOf("max_age_s");
  const LinkSettings defaults;
  if (!age.contains(s.max_age_s)) problems.push_back({"max_age_s", common::rangeProblem(age, s.max_age_s)});
  if (!age.contains(s.command_max_age_s)) {
    problems.push_back({"command_max_age_s", common::rangeProblem(age, s.command_max_age_s)});
  }
  if (s.recv_buf_bytes < 65536) {
    problems.push_back({"recv_buf_bytes", "must be >= 65536, got " + std::to_string(s.recv_buf_bytes)});
  }
  senderList("known_senders", s.known_senders, s.sender_id, c.known_senders, problems);
  for (const auto& [key, list, type] : {std::make_tuple(std::string("command_senders"), &s.command_senders, MessageType::kFormationCommand),
                                        std::make_tuple(std::string("params_senders"), &s.params_senders, MessageType::kFormationParams),
                                        std::make_tuple(std::string("abort_senders"), &s.abort_senders, MessageType::kAbortCommand)}) {
    if (!list->has_value()) continue;
    if ((*list)->empty()) problems.push_back({key, "must list at least one sender id (omit it to allow every known sender)"});
    senderList(key, **list, s.sender_id, c.senders_by_type[type], problems);  // own id only → empty: no one else
  }
  // Command acknowledgements come from the parameter owner: the senders of formation parameters;
  // the assistance state from the parameter owner (the request) and the command senders (the
  // operator's acknowledgement).
  const auto owners = c.senders_by_type.find(MessageType::kFormationParams);
  const auto commanders = c.senders_by_type.find(MessageType::kFormationCommand);
  if (owners != c.senders_by_type.end()) {
    c.senders_by_type[MessageType::kCommandAck] = owners->second;
    if (commanders != c.senders_by_type.end()) {
      auto both = owners->second;
      both.insert(both.end(), commanders->second.begin(), commanders->second.end());
      std::sort(both.begin(), both.end());
      both.erase(std::unique(both.begin(), both.end()), both.end());
      c.senders_by_type[MessageType::kAssistance] = both;
    }
  }
  // Leadership messages (docs/safety.md §1.2) come from the UAVs only — the known senders with a UAV
  // index (0..kMaxUavIndex), never a ground station; so do live-map changes (docs/mapping.md §8).
  auto& members = c.senders_by_type[MessageType::kLeadership];
  for (const std::uint16_t id : c.known_senders) {
    if (id <= kMaxUavIndex) members.push_back(id);
  }
  c.senders_by_type[MessageType::kMapUpdate] = members;
  c.own_sender_id = static_cast<std::uint16_t>(std::clamp(s.sender_id, 0, 65535));
  c.max_age_s = age.contains(s.max_age_s) ? s.max_age_s : defaults.max_age_s;
  c.max_age_s_by_type[MessageType::kHeartbeat] = std::max(c.max_age_s, 2.0);
  c.max_age_s_by_type[MessageType::kFormationCommand] =
      age.contains(s.command_max_age_s) ? s.command_max_age_s : defaults.command_max_age_s;
  c.max_age_s_by_type[MessageType::kAbortCommand] = c.max_age_s_by_type[MessageType::kFormationCommand];
  c.max_age_s_by_type[MessageType::kCommandAck] = c.max_age_s_by_type[MessageType::kFormationCommand];
  c.max_age_s_by_type[MessageType::kAssistance] = c.max_age_s_by_type[MessageType::kFormationCommand];
  c.max_rate_hz = s.max_rate_hz;
  c.burst = s.burst;
  for (const auto& e : c.validate()) problems.push_back({"verifier", e});
  return c;
}

std::optional<common::ConfigError> keyRingOwnerProblem(const KeyRing& keys, int sender_id) {
  if (!keys.perSender() || keys.active().sender_id == sender_id) return std::nullopt;
  return common::ConfigError{"key_file", "its signing key belongs to sender " + std::to_string(keys.active().sender_id) +
                                             ", not to sender_id " + std::to_string(sender_id)};
}

std::string withReceiveBuffer(const std::string& url, int bytes) {
  if (url.rfind("udpm://", 0) != 0 || url.find("recv_buf_size") != std::string::npos || bytes < 65536) return url;
  return url + (url.find('?') == std::string::npos ? "?" : "&") + "recv_buf_size=" + std::to_string(bytes);
}

std::string describeOptional(const LinkSettings& s) {
  const auto ids = [](const std::optional<std::vector<int>>& list) {
    return list ? std::to_string(list->size()) + " id(s)" : std::string("any known sender");
  };
  return "command_max_age_s: " + std::to_string(s.command_max_age_s) + ", recv_buf_bytes: " +
         std::to_string(s.recv_buf_bytes) + ", max_rate_hz: " + std::to_string(s.max_rate_hz) +
         ", burst: " + std::to_string(s.burst) + ", command_senders: " + ids(s.command_senders) +
         ", params_senders: " + ids(s.params_senders) + ", abort_senders: " + ids(s.abort_senders);
}

}  // namespace gesture_formation::comm
