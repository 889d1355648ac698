#pragma once
/// \file
/// \brief Deterministic random streams of the simulation: every component draws from its own
/// `std::mt19937_64` seeded from (mission seed, stream id), so that adding draws in one
/// component never changes another's numbers. Distributions are libstdc++'s (deterministic
/// for one build; docs/design.md §8.4 "deterministic for a seed").

#include <cstdint>
#include <random>

namespace gesture_formation::sim {

/// \brief SplitMix64 finaliser: a well-mixed 64-bit hash.
inline std::uint64_t mixSeed(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

/// \brief Stream ids of the simulation's components (one RNG each).
enum class Stream : std::uint64_t {
  kWind = 1,
  kOdometry = 2,     ///< + UAV index
  kWorker = 20,
  kSkeleton = 21,
  kCamera = 22,
  kStereo = 23,
  kUwb = 24,
  kLink = 30,        ///< + link index
  kFault = 40,       ///< injected sensor faults (range outliers)
  kFollowerCamera = 50,  ///< + follower index: the followers' cameras (gesture views)
  kHandover = 60,        ///< + link index: the leadership's links and the links a new leader needs
  kMapShare = 70,        ///< + link index: the map-update links between UAVs (site_mapping.hpp)
};

/// \brief The RNG of stream `stream` (+ `index`) of a mission with seed `seed`.
inline std::mt19937_64 makeRng(std::uint64_t seed, Stream stream, std::uint64_t index = 0) {
  return std::mt19937_64(mixSeed(mixSeed(seed) ^ mixSeed(static_cast<std::uint64_t>(stream) * 1000003ULL + index)));
}

}  // namespace gesture_formation::sim
