#pragma once
/// \file
/// \brief Sliding anti-replay window over one sender's sequence numbers (the IPsec ESP /
/// DTLS scheme, RFC 4303 §3.4.3, with RFC 6479's ring of bit words).
///
/// Keeps the highest sequence number accepted, h, and one bit per number in (h − W, h].
/// A number s is
/// - new when s > h (the window slides forward on accept), or s is within the window and
///   its bit is clear (a late, reordered packet);
/// - a duplicate when within the window and its bit is set;
/// - too old when s ≤ h − W (cannot be told from a replay, so it is refused).
/// check() never changes state; accept() is called only for authenticated packets.
/// Thread safety: none.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace gesture_formation::comm {

/// \brief Largest window [sequence numbers].
constexpr std::size_t kMaxReplayWindow = 65536;

class ReplayWindow {
 public:
  enum class Check { kNew, kDuplicate, kTooOld };

  /// \brief `window` sequence numbers, rounded up to a multiple of 64, clamped to
  /// [64, kMaxReplayWindow].
  explicit ReplayWindow(std::size_t window = 256);

  Check check(std::uint64_t sequence) const;
  /// \brief Records `sequence` (precondition: check(sequence) == kNew; otherwise no-op).
  void accept(std::uint64_t sequence);

  /// \brief Treats every number ≤ `sequence` as seen (a receiver restoring its persisted
  /// high-water mark): highest = max(highest, sequence), and the window's bits all set when
  /// the mark moves it. A mark below the current highest changes nothing.
  void markSeenUpTo(std::uint64_t sequence);

  bool empty() const { return !any_; }
  std::uint64_t highest() const { return highest_; }
  std::size_t size() const { return bits_.size() * 64; }

 private:
  bool testBit(std::uint64_t sequence) const;
  void setBit(std::uint64_t sequence);
  void clearBit(std::uint64_t sequence);

  std::vector<std::uint64_t> bits_;  ///< bit (s mod size) of word ((s / 64) mod words)
  std::uint64_t highest_ = 0;
  bool any_ = false;
};

}  // namespace gesture_formation::comm
