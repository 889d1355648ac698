#include "gesture_formation/comm/replay_window.hpp"

#include <algorithm>

namespace gesture_formation::comm {

ReplayWindow::ReplayWindow(std::size_t window) {
  const std::size_t clamped = std::min(std::max<std::size_t>(window, 64), kMaxReplayWindow);
  bits_.assign((clamped + 63) / 64, 0);
}

bool ReplayWindow::testBit(std::uint64_t s) const {
  const std::size_t word = static_cast<std::size_t>((s / 64) % bits_.size());
  return (bits_[word] >> (s % 64)) & 1u;
}

void ReplayWindow::setBit(std::uint64_t s) {
  const std::size_t word = static_cast<std::size_t>((s / 64) % bits_.size());
  bits_[word] |= std::uint64_t{1} << (s % 64);
}

void ReplayWindow::clearBit(std::uint64_t s) {
  const std::size_t word = static_cast<std::size_t>((s / 64) % bits_.size());
  bits_[word] &= ~(std::uint64_t{1} << (s % 64));
}

ReplayWindow::Check ReplayWindow::check(std::uint64_t s) const {
  if (!any_ || s > highest_) return Check::kNew;
  if (highest_ - s >= size()) return Check::kTooOld;
  return testBit(s) ? Check::kDuplicate : Check::kNew;
}

void ReplayWindow::accept(std::uint64_t s) {
  if (check(s) != Check::kNew) return;
  if (!any_) {
    std::fill(bits_.begin(), bits_.end(), 0);
    any_ = true;
    highest_ = s;
  } else if (s > highest_) {
    const std::uint64_t advance = s - highest_;
    if (advance >= size()) {
      std::fill(bits_.begin(), bits_.end(), 0);
    } else {
      // The numbers highest_+1 .. s enter the window: their slots held numbers that leave it.
      for (std::uint64_t k = highest_ + 1; k != s + 1; ++k) clearBit(k);
    }
    highest_ = s;
  }
  setBit(s);
}

void ReplayWindow::markSeenUpTo(std::uint64_t sequence) {
  if (any_ && sequence <= highest_) return;
  // Conservative: numbers not actually accepted before the mark are refused too.
  std::fill(bits_.begin(), bits_.end(), ~std::uint64_t{0});
  any_ = true;
  highest_ = sequence;
}

}  // namespace gesture_formation::comm
