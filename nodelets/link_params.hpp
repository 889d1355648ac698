#pragma once
// The LcmBridge's link parameters (docs/ros.md "LcmBridge"): identity, transport, key, state files
// and the optional limits and sender lists, into lcm_bridge::LinkStartupConfig. Ranges are the
// link's own (checked with its settings by lcm_bridge::checkLinkStartup / startLink).
#include <string>
#include <utility>
#include <type_traits>
#include <vector>

#include <ros/node_handle.h>

#include "gesture_formation/comm/sequence_store.hpp"
#include "gesture_formation/lcm_bridge/link_startup.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

inline void loadLinkParams(ros::NodeHandle& pnh, ParamLoader& params, lcm_bridge::LinkStartupConfig& cfg) {
  comm::LinkSettings& link = cfg.link;
  params.load("sender_id", link.sender_id, 0, 65535);
  params.load("known_senders", link.known_senders);
  params.load("lcm_url", cfg.lcm_url);
  params.load("channel_prefix", cfg.channel_prefix);
  params.load("key_file", cfg.key_file);
  params.load("max_age_s", link.max_age_s);  // range: the verifier's, checked with the link's settings
  cfg.state_dir = comm::defaultStateDirectory();
  const std::string stem = cfg.state_dir + "/lcm_bridge_" + std::to_string(link.sender_id);
  params.loadOptional("sequence_file", cfg.sequence_file, stem + ".boot");
  params.loadOptional("high_water_file", cfg.marks_file, stem + ".marks");
  // Optional (absent: the link's default; ranges: the verifier's, checked with the link's settings);
  // present but not of the type — e.g. a string — is an error, never the default in silence.
  const auto optional = [&pnh, &params](const char* name, auto& value) {
    if (pnh.hasParam(name) && !pnh.getParam(name, value)) {
      params.addError(pnh.resolveName(name) + ": not a " + (std::is_integral_v<std::decay_t<decltype(value)>> ? "whole number" : "number"));
    }
  };
  optional("command_max_age_s", link.command_max_age_s);
  optional("recv_buf_bytes", link.recv_buf_bytes);
  optional("max_rate_hz", link.max_rate_hz);
  optional("burst", link.burst);
  for (auto [name, list] : {std::make_pair("command_senders", &link.command_senders),
                            std::make_pair("params_senders", &link.params_senders),
                            std::make_pair("abort_senders", &link.abort_senders)}) {
    // Absent: any known sender. Present, it must be a list of ids: `100` instead of `[100]` would
    // otherwise let every known sender send commands, parameters or aborts.
    std::vector<int> ids;
    if (pnh.getParam(name, ids)) {
      *list = ids;
    } else if (pnh.hasParam(name)) {
      params.addError(pnh.resolveName(name) + ": not a list of sender ids (e.g. [100])");
    }
  }
}

}  // namespace gesture_formation::nodelets
