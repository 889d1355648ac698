#pragma once
/// \file
/// \brief The only way the project includes ProxQP: its headers with their own invariant checks
/// (`VEG_ASSERT`) turned on, reporting a broken invariant as a C++ exception instead of carrying
/// on with corrupted state (docs/safety.md §4.5).
///
/// Why: ProxQP's sparse LDLᵀ row deletion (0.7.2–0.8.0, `linalg/sparse/rowmod.hpp`) can break its
/// own precondition (`it_pos == 0`); in a release build the check is compiled out and the solver
/// then walks a corrupted elimination tree forever — `max_iter` does not bound that loop. With the
/// check on, the same QP throws ProxqpInvariantError at the moment the invariant breaks, before
/// any loop, and the caller solves it another way. ProxQP is header-only, so the checks exist only
/// in the translation units that include this header; include it before any other ProxQP header
/// and never include ProxQP directly (every ProxQP template instantiated in one binary must see
/// the same macro, or the One Definition Rule is broken).
///
/// Limits: a check that fails inside a `noexcept` ProxQP function terminates the process (none
/// fired in the missions and fault matrices flown with the checks on); a loop that breaks no
/// checked invariant is bounded only by the iteration limits and the caller's cooperative
/// deadline (TrajectoryQp::solveMatrices).

#include <stdexcept>
#include <string>

#ifdef VEG_ASSERT_HPP_VQDAJ2IBS
#error "proxqp_checked.hpp must be included before any other ProxQP header"
#endif

namespace gesture_formation::planning::detail {

/// \brief A ProxQP invariant (`VEG_ASSERT`) failed: the solver's state is no longer valid.
class ProxqpInvariantError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

[[noreturn]] inline void proxqpInvariantBroken(const char* condition, const char* file, int line) {
  throw ProxqpInvariantError(std::string("ProxQP invariant broken: ") + condition + " (" + file + ":" +
                             std::to_string(line) + ")");
}

}  // namespace gesture_formation::planning::detail

// ProxQP's assertion macros, defined by this header once (its include guard), then replaced.
#include <proxsuite/linalg/veg/internal/assert_impl.hpp>
#undef VEG_ASSERT
#undef VEG_ASSERT_ALL_OF
#define VEG_ASSERT(...)                                                      \
  ((__VA_ARGS__) ? static_cast<void>(0)                                      \
                 : ::gesture_formation::planning::detail::proxqpInvariantBroken(#__VA_ARGS__, __FILE__, __LINE__))
#define VEG_ASSERT_ALL_OF(...)                                                             \
  ((::proxsuite::linalg::veg::_detail::all_of({__VA_ARGS__}))                              \
       ? static_cast<void>(0)                                                              \
       : ::gesture_formation::planning::detail::proxqpInvariantBroken(#__VA_ARGS__, __FILE__, __LINE__))

#include <proxsuite/proxqp/dense/dense.hpp>
#include <proxsuite/proxqp/sparse/sparse.hpp>
