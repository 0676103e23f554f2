#include "core/random.h"

namespace fleetmap::core {

namespace {
// splitmix64: a good mixer to derive stream seeds from (seed, stream).
std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
}  // namespace

Random Random::fork(std::uint64_t stream) const { return Random(mix(mix(seed_) ^ mix(stream + 1))); }

double Random::normal(double mean, double stddev) {
  if (stddev == 0.0) return mean;
  return std::normal_distribution<double>(mean, stddev)(engine_);
}

}  // namespace fleetmap::core
