// Map merging: success rate, rotation and translation error, and time of every merge method
// against the overlap of the two maps (10% to 90%) and their size (200, 1000 and 4000 cells
// square), and false merges on pairs that do not overlap.
//
// Each pair is two views of a procedural indoor world (merging/evaluation.h, SyntheticWorld):
// rooms from a binary space partition with doors, slanted walls, furniture seen by its outline.
// `a` is an axis-aligned window, `b` a window of the same size turned by a uniform random angle in
// (-180, 180] degrees and shifted until the two share the requested part of their area. One
// iteration aligns one pair; the pairs are the same for every method (seeded by size, overlap and
// index). A success is a merge within 1 degree and 1 cell (at the centre of the common area) of the
// truth; a wrong merge is any other merge.
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "merging/evaluation.h"
#include "merging/merge.h"

namespace {

using namespace fleetmap;

struct Variant {
  std::string name;      // as shown in the benchmark's name
  std::string method;    // merge method
  bool refine = true;
};

const merging::SyntheticWorld& world_for(int size, double noise) {
  static std::map<std::pair<int, double>, std::unique_ptr<merging::SyntheticWorld>> worlds;
  auto& w = worlds[{size, noise}];
  if (!w) {
    core::Random random(1000 + std::uint64_t(size));
    merging::SyntheticWorldOptions o;
    o.width = o.height = 2 * size + 200;  // room for b beside a at 10% overlap
    o.speckle_rate = noise;
    o.wall_gap_rate = 20.0 * noise;
    w = std::make_unique<merging::SyntheticWorld>(o, random);
  }
  return *w;
}

void merge_pairs(benchmark::State& state, const Variant& v, int size, double overlap, double noise) {
  const merging::SyntheticWorld& world = world_for(size, noise);
  merging::CropPairOptions crop;
  crop.width = crop.height = size;
  crop.overlap = overlap;
  crop.min_inside = overlap > 0.0 ? 0.9 : 0.8;
  merging::MergeOptions options;
  options.method = v.method;
  options.refine = v.refine;
  int pairs = 0, merged = 0, success = 0, wrong = 0;
  double rot_sum = 0.0, tr_sum = 0.0, rot_max = 0.0, tr_max = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    core::Random random(std::uint64_t(size) * 7919u + std::uint64_t(std::lround(overlap * 100)) * 104729u +
                        std::uint64_t(pairs) + std::uint64_t(noise * 1e6));
    const merging::CropPair pair = merging::make_world_pair(world, crop, random);
    state.ResumeTiming();
    const merging::MergeResult r = merging::align_maps(pair.a, pair.b, options);
    state.PauseTiming();
    ++pairs;
    if (r.merged) {
      ++merged;
      const merging::TransformError e = merging::transform_error(r.transform, pair.b_to_a, pair.overlap_centre_b);
      const bool right = overlap > 0.0 && e.rotation_deg < 1.0 && e.translation_cells < 1.0;
      success += right;
      wrong += !right;
      if (overlap > 0.0) {
        rot_sum += e.rotation_deg, tr_sum += e.translation_cells;
        rot_max = std::max(rot_max, e.rotation_deg), tr_max = std::max(tr_max, e.translation_cells);
      }
    }
    state.ResumeTiming();
  }
  state.counters["pairs"] = pairs;
  state.counters["success"] = pairs > 0 ? double(success) / pairs : 0.0;
  state.counters["merged"] = pairs > 0 ? double(merged) / pairs : 0.0;
  state.counters["wrong"] = wrong;
  state.counters["rot_mean_deg"] = merged > 0 ? rot_sum / merged : 0.0;
  state.counters["rot_max_deg"] = rot_max;
  state.counters["tr_mean_cells"] = merged > 0 ? tr_sum / merged : 0.0;
  state.counters["tr_max_cells"] = tr_max;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<Variant> variants = {
      {"grid", "grid", true},
      {"features", "features", true},
      // The feature method's own answer, without the common sub-cell refinement (as the ROS merger).
      {"features_unrefined", "features", false},
      {"auto", "auto", true},
  };
  struct Size {
    int cells, pairs, disjoint_pairs;  // pairs per overlap; pairs that do not overlap (false merges)
    std::vector<double> overlaps;
  };
  const std::vector<Size> sizes = {
      {200, 20, 100, {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.0}},
      {1000, 20, 50, {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.0}},
      {4000, 4, 4, {0.1, 0.2, 0.5, 0.9, 0.0}},
  };
  for (const auto& s : sizes) {
    for (const double overlap : s.overlaps) {
      for (const auto& v : variants) {
        const std::string name = "merge/" + v.name + "/size:" + std::to_string(s.cells) + "/overlap:" +
                                 std::to_string(int(std::lround(overlap * 100)));
        benchmark::RegisterBenchmark(name.c_str(), [v, s, overlap](benchmark::State& st) {
          merge_pairs(st, v, s.cells, overlap, 0.0);
        })->Iterations(overlap > 0.0 ? s.pairs : s.disjoint_pairs)->Unit(benchmark::kMillisecond)
            ->MeasureProcessCPUTime()->UseRealTime();
      }
    }
  }
  // Sensor-like noise: specks on free space (0.2% of cells) and gaps in walls (4%).
  for (const double overlap : {0.2, 0.5}) {
    for (const auto& v : variants) {
      const std::string name = "merge_noisy/" + v.name + "/size:1000/overlap:" + std::to_string(int(std::lround(overlap * 100)));
      benchmark::RegisterBenchmark(name.c_str(), [v, overlap](benchmark::State& st) {
        merge_pairs(st, v, 1000, overlap, 0.002);
      })->Iterations(20)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();
    }
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
