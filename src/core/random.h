// A small counter-based random source: the same numbers on every platform
// and standard library (std::*_distribution is implementation-defined), and
// independent streams per (seed, stream) so results never depend on the order
// in which agents are visited.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/config.h"

namespace throng {

THRONG_HOST_DEVICE inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

class Rng {
 public:
  THRONG_HOST_DEVICE explicit Rng(std::uint64_t seed, std::uint64_t stream = 0)
      : state_(splitmix64(seed ^ splitmix64(stream + 0x632be59bd9b4e019ull))) {}
  THRONG_HOST_DEVICE std::uint64_t next() {
    state_ += 0x9e3779b97f4a7c15ull;
    return splitmix64(state_);
  }
  // Uniform in [0, 1).
  THRONG_HOST_DEVICE double uniform() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); }
  THRONG_HOST_DEVICE double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Uniform integer in [0, n), n > 0.
  THRONG_HOST_DEVICE std::uint64_t below(std::uint64_t n) {
    return static_cast<std::uint64_t>(uniform() * static_cast<double>(n)) % n;
  }
  // Standard normal (Box-Muller, one value per call).
  THRONG_HOST_DEVICE double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
  }

 private:
  std::uint64_t state_;
};

}  // namespace throng
