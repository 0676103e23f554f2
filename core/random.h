#pragma once
// The one source of randomness. Every random thing in fleetmap takes a Random (or a seed)
// so that the same seed gives the same numbers.
#include <cstdint>
#include <random>

namespace fleetmap::core {

class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed), seed_(seed) {}

  std::uint64_t seed() const { return seed_; }
  // An independent stream derived from this one's seed and `stream` (e.g. a robot index);
  // it does not advance this generator.
  Random fork(std::uint64_t stream) const;

  double uniform() { return std::uniform_real_distribution<double>(0.0, 1.0)(engine_); }
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(engine_); }
  // Inclusive on both ends.
  int uniform_int(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(engine_); }
  // Zero-mean Gaussian; `stddev` 0 gives exactly `mean` without drawing.
  double normal(double mean, double stddev);
  bool bernoulli(double p) { return uniform() < p; }

  std::mt19937_64& engine() { return engine_; }

 private:
  std::mt19937_64 engine_;
  std::uint64_t seed_;
};

}  // namespace fleetmap::core
