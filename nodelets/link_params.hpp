#pragma once
// The LcmBridge's link parameters (docs/ros.md "LcmBridge"): identity, transport, key, state files
// and the optional limits and sender lists, into lcm_bridge::LinkStartupConfig. Ranges are the
// link's own (checked with its settings by lcm_bridge::checkLinkStartup / startLink).
#include <string>
#include <utility>
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
  link.command_max_age_s = pnh.param("command_max_age_s", link.command_max_age_s);
  link.recv_buf_bytes = pnh.param("recv_buf_bytes", link.recv_buf_bytes);
  link.max_rate_hz = pnh.param("max_rate_hz", link.max_rate_hz);
  link.burst = pnh.param("burst", link.burst);
  for (auto [name, list] : {std::make_pair("command_senders", &link.command_senders),
                            std::make_pair("params_senders", &link.params_senders),
                            std::make_pair("abort_senders", &link.abort_senders)}) {
    std::vector<int> ids;
    if (pnh.getParam(name, ids)) *list = ids;
  }
}

}  // namespace gesture_formation::nodelets
