#pragma once
/// \file
/// \brief What survives a restart of a node's link (docs/security.md §4): the sender's boot
/// counter, whose value fills the high bits of its sequence numbers, and the receiver's
/// per-sender high-water marks, so that neither a clock set back nor a restart reopens a
/// replay window.
///
/// Sequence numbers of boot b: b · 2^40 + 1, b · 2^40 + 2, … — independent of any clock, and
/// above every number of an earlier boot as long as one boot sends fewer than 2^40 envelopes
/// (35 years at 1000 per second). Files: small text files, created owner-only (0600), written
/// to a temporary file, fsync'd and renamed over the old one (a crash leaves the old or the
/// new content, never half of one); an existing file that grants group or others access, or
/// does not parse, is refused naming the path and the problem.
/// Thread safety: none (one owner per file).

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "gesture_formation/common/result.hpp"

namespace gesture_formation::comm {

constexpr unsigned kBootCounterShift = 40;
constexpr std::uint32_t kMaxBootCounter = (std::uint32_t{1} << 24) - 1;

/// \brief The first sequence number of boot `boot` (1-based): boot · 2^40 + 1.
constexpr std::uint64_t firstSequenceOfBoot(std::uint32_t boot) {
  return (static_cast<std::uint64_t>(boot) << kBootCounterShift) + 1;
}

/// \brief Where a bridge keeps its boot counter and high-water marks by default:
/// $ROS_HOME/gesture_formation, else $HOME/.ros/gesture_formation (else /tmp/.ros/...).
std::string defaultStateDirectory();

/// \brief Creates `dir` (and its parent) with mode 0700 when one of `files` lives in it; errors
/// show when the files are opened.
void ensureStateDirectory(const std::string& dir, const std::vector<std::string>& files);

/// \brief Reads a whole state file (a regular file, mode 0600 or stricter, ≤ 64 KiB); `exists`
/// false (and ok, empty) when there is none. Fails naming the path and the problem.
common::Result<std::string> readStateFile(const std::string& path, bool& exists);
/// \brief Writes `text` durably: to path.tmp.<pid> (0600), fsync, rename over `path`, fsync of the
/// directory; the old file is kept on failure.
common::Result<bool> writeStateFile(const std::string& path, const std::string& text);

/// \brief Reads the boot counter at `path` (0 when the file does not exist), adds one, writes
/// it back durably and returns the new value. Fails (nothing written) on a bad file, a
/// counter at kMaxBootCounter, or an I/O error.
common::Result<std::uint32_t> advanceBootCounter(const std::string& path);

/// \brief Per-sender high-water marks at `path` (lines `<sender id> <sequence>`); an empty map
/// when the file does not exist.
common::Result<std::map<std::uint16_t, std::uint64_t>> loadHighWaterMarks(const std::string& path);

/// \brief Writes the marks durably (temporary file, fsync, rename); the old file is kept on failure.
common::Result<bool> saveHighWaterMarks(const std::string& path, const std::map<std::uint16_t, std::uint64_t>& marks);

}  // namespace gesture_formation::comm
