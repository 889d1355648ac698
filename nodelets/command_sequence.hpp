#pragma once
// Where a command sender's sequence numbers start (the OperatorInterface, the GestureCommander):
// boot b of the node's counter file (~sequence_file, optional; default
// $ROS_HOME/gesture_formation/command_sequence<node name, '/' → '_'>: one file per node — the
// GestureCommanders of a simulation share a ROS_HOME and a sender name) numbers its commands
// b·2^40 + 1, …
// (comm::firstSequenceOfBoot) — above every number of an earlier start whatever the clock did. The
// wall clock used before went back with the clock: a station restarted after a clock step back
// numbered below the leader's remembered window and every command it sent was refused as stale
// (formation::DuplicateWindow). A counter file that cannot be read or written is a problem of the
// nodelet's start (listed with the others).
#include <cctype>
#include <cstdint>
#include <string>

#include <ros/node_handle.h>

#include "gesture_formation/comm/sequence_store.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

/// \brief The number before this start's first command (the caller pre-increments); 0 with a
/// problem added to `params`.
inline std::uint64_t commandSequenceStart(ParamLoader& params, const std::string& node_name) {
  std::string safe = node_name;
  for (char& c : safe) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  }
  std::string file;
  params.loadOptional("sequence_file", file, comm::defaultStateDirectory() + "/command_sequence_" + safe);
  comm::ensureStateDirectory(comm::defaultStateDirectory(), {file});
  const auto boot = comm::advanceBootCounter(file);
  if (!boot) {
    params.addError("sequence_file: " + boot.reason());
    return 0;
  }
  return comm::firstSequenceOfBoot(*boot) - 1;
}

}  // namespace gesture_formation::nodelets
