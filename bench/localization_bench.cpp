// Time per predict and per update of the EKF localizers with 10, 100 and 500 landmarks:
// in the state for `ekf-slam` (state size 3 + 2N), in the known map for `ekf` (state size 3; N
// only matters for nearest-neighbour association). Results: bench/README.md, "## Localization".
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <memory>
#include <numbers>
#include <vector>

#include "localization/localizer.h"

namespace fleetmap::localization {
namespace {

// N landmarks on a spiral around the origin, 2 to 20 m from it.
std::vector<Landmark> spiral(int n) {
  std::vector<Landmark> out;
  for (int i = 0; i < n; ++i) {
    const double r = 2.0 + 18.0 * i / std::max(1, n - 1);
    const double a = 2.399963 * i;  // the golden angle keeps neighbours apart
    out.push_back({i, Eigen::Vector2d(r * std::cos(a), r * std::sin(a))});
  }
  return out;
}

LandmarkObservation reading_of(const Landmark& l, bool with_id) {
  return {with_id ? l.id : -1, l.position.norm(), std::atan2(l.position.y(), l.position.x())};
}

// An `ekf-slam` filter at the origin that has seen all N landmarks once.
std::unique_ptr<Localizer> slam_with(int n, bool known_ids) {
  LocalizerContext c;
  c.options.known_associations = known_ids;
  auto slam = make_localizer("ekf-slam", c);
  std::vector<LandmarkObservation> all;
  for (const Landmark& l : spiral(n)) all.push_back(reading_of(l, true));
  if (!known_ids) {
    // Nearest-neighbour mode learns them one by one, so that none is mistaken for another.
    for (auto& r : all) {
      r.id = -1;
      slam->update_landmarks({r});
    }
  } else {
    slam->update_landmarks(all);
  }
  return slam;
}

double counter(const Localizer& l, const std::string& name) {
  for (const auto& [key, value] : l.counters()) {
    if (key == name) return value;
  }
  return -1.0;
}

void BM_EkfSlamPredict(benchmark::State& state) {
  auto slam = slam_with(static_cast<int>(state.range(0)), true);
  const Odometry u{0.0, 0.0, 1.0};  // standing still: only the covariance moves
  for (auto _ : state) {
    slam->predict(u);
    benchmark::DoNotOptimize(slam->pose());
  }
  state.counters["landmarks_in_state"] = counter(*slam, "landmarks_in_state");
}

// One update_landmarks call with one reading of a landmark already in the state.
void BM_EkfSlamUpdate(benchmark::State& state, bool known_ids) {
  const int n = static_cast<int>(state.range(0));
  auto slam = slam_with(n, known_ids);
  const std::vector<LandmarkObservation> one = {reading_of(spiral(n)[static_cast<std::size_t>(n / 2)], known_ids)};
  for (auto _ : state) {
    slam->update_landmarks(one);
    benchmark::DoNotOptimize(slam->pose());
  }
  state.counters["landmarks_in_state"] = counter(*slam, "landmarks_in_state");
  state.counters["rejected"] = counter(*slam, "rejected_associations");
}

void BM_EkfPredict(benchmark::State& state) {
  LocalizerContext c;
  c.known_landmarks = spiral(static_cast<int>(state.range(0)));
  auto ekf = make_localizer("ekf", c);
  const Odometry u{0.0, 0.0, 1.0};
  for (auto _ : state) {
    ekf->predict(u);
    benchmark::DoNotOptimize(ekf->pose());
  }
}

// One reading of a known-map landmark; without ids it is matched against all N by nearest neighbour.
void BM_EkfUpdate(benchmark::State& state, bool known_ids) {
  const int n = static_cast<int>(state.range(0));
  LocalizerContext c;
  c.known_landmarks = spiral(n);
  c.options.known_associations = known_ids;
  auto ekf = make_localizer("ekf", c);
  const std::vector<LandmarkObservation> one = {reading_of(c.known_landmarks[static_cast<std::size_t>(n / 2)], known_ids)};
  for (auto _ : state) {
    ekf->update_landmarks(one);
    benchmark::DoNotOptimize(ekf->pose());
  }
  state.counters["rejected"] = counter(*ekf, "rejected_associations");
}

BENCHMARK(BM_EkfSlamPredict)->Arg(10)->Arg(100)->Arg(500)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_EkfSlamUpdate, known_ids, true)->Arg(10)->Arg(100)->Arg(500)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_EkfSlamUpdate, nearest_neighbour, false)
    ->Arg(10)
    ->Arg(100)
    ->Arg(500)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_EkfPredict)->Arg(10)->Arg(100)->Arg(500)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_EkfUpdate, known_ids, true)->Arg(10)->Arg(100)->Arg(500)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_EkfUpdate, nearest_neighbour, false)->Arg(10)->Arg(100)->Arg(500)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace fleetmap::localization

BENCHMARK_MAIN();
