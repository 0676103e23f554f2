#include "merging/multi_merge.h"

#include <Eigen/Dense>
#include <cmath>
#include <memory>

#include "core/angle.h"
#include "core/error.h"
#include "merging/rendezvous.h"
#include "merging/resolutions.h"

namespace fleetmap::merging {

MultiMergeResult merge_maps(const std::vector<const mapping::OccupancyGrid*>& grids, const MergeOptions& options,
                            const std::function<void(int, int)>& progress) {
  check_merge_method(options.method);
  const int n = int(grids.size());
  MultiMergeResult out;
  out.to_first.assign(std::size_t(n), std::nullopt);
  out.covariance.assign(std::size_t(n), std::nullopt);
  out.parent.assign(std::size_t(n), -1);
  out.confidence.assign(std::size_t(n), 0.0);
  out.method.assign(std::size_t(n), "");
  out.reason.assign(std::size_t(n), "");
  out.reason_pair.assign(std::size_t(n), -1);
  if (n == 0) return out;
  // Each map cut and prepared once, when a pair of one resolution first needs it (a pair of two
  // resolutions aligns resampled copies instead).
  const auto count = static_cast<std::size_t>(n);
  std::vector<std::unique_ptr<KnownPart>> parts(count);
  std::vector<std::unique_ptr<PreparedGrid>> prepared(count);
  const auto prepare = [&](std::size_t i) {
    if (!prepared[i]) {
      parts[i] = std::make_unique<KnownPart>(*grids[i]);
      prepared[i] = std::make_unique<PreparedGrid>(parts[i]->grid(), prepare_options(options));
    }
  };
  // Every pair's result in the first map's cells (each map seen through them: its own cells when it
  // has the first's resolution).
  const double first = grids[0]->resolution();
  const auto in_first_cells = [&](MergeResult r, double resolution) {
    if (resolution == first) return r;
    if (r.covariance)
      r.covariance = propagate_covariance(*r.covariance, r.transform,
                                          [&](const core::Transform2& t) { return rescale_cells(t, resolution, first); });
    r.transform = rescale_cells(r.transform, resolution, first);
    if (r.alternative) r.alternative = rescale_cells(*r.alternative, resolution, first);
    const Eigen::Vector2d h(0.5, 0.5);
    r.quality.overlap_centre = (r.quality.overlap_centre + h) * (resolution / first) - h;
    return r;
  };
  const int total = n * (n - 1) / 2;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      const auto si = std::size_t(i), sj = std::size_t(j);
      const double ri = grids[si]->resolution(), rj = grids[sj]->resolution();
      MergeResult r;
      if (ri == rj) {
        prepare(si);
        prepare(sj);
        r = uncut(align_prepared(*prepared[si], *prepared[sj], options), *parts[si], *parts[sj]);
      } else {
        r = align_across_resolutions(*grids[si], *grids[sj], options);
      }
      out.pairs.push_back({i, j, in_first_cells(std::move(r), std::max(ri, rj))});
      if (progress) progress(int(out.pairs.size()), total);
    }
  }
  // Prim's algorithm on the reliable pairs, heaviest confidence first, from the first map.
  out.to_first[0] = core::Transform2::identity();
  out.covariance[0] = Eigen::Matrix3d::Zero();
  out.confidence[0] = 1.0;
  std::vector<bool> in_tree(std::size_t(n), false);
  in_tree[0] = true;
  std::vector<bool> tree_pair(out.pairs.size(), false);
  while (true) {
    int best = -1;
    for (int e = 0; e < int(out.pairs.size()); ++e) {
      const auto& p = out.pairs[std::size_t(e)];
      if (!p.result.merged || in_tree[std::size_t(p.a)] == in_tree[std::size_t(p.b)]) continue;
      if (best < 0 || p.result.confidence > out.pairs[std::size_t(best)].result.confidence) best = e;
    }
    if (best < 0) break;
    tree_pair[std::size_t(best)] = true;
    const auto& p = out.pairs[std::size_t(best)];
    // The new map is b (placed through a) or a (placed through b, with the inverse).
    const bool new_is_b = in_tree[std::size_t(p.a)];
    const int from = new_is_b ? p.a : p.b, to = new_is_b ? p.b : p.a;
    const core::Transform2 to_from = new_is_b ? p.result.transform : p.result.transform.inverse();
    const auto& from_covariance = out.covariance[std::size_t(from)];
    if (from_covariance && p.result.covariance) {
      // to_from as a function of the pair's transform (inverted when the new map is a).
      const auto compose = [&](const core::Transform2& from_first, const core::Transform2& pair) {
        return from_first * (new_is_b ? pair : pair.inverse());
      };
      out.covariance[std::size_t(to)] = propagate_covariance(*from_covariance, *out.to_first[std::size_t(from)],
                                                             *p.result.covariance, p.result.transform, compose);
    }
    out.to_first[std::size_t(to)] = *out.to_first[std::size_t(from)] * to_from;
    out.parent[std::size_t(to)] = from;
    out.confidence[std::size_t(to)] = p.result.confidence;
    out.method[std::size_t(to)] = p.result.method;
    in_tree[std::size_t(to)] = true;
  }
  for (int i = 1; i < n; ++i) {
    if (in_tree[std::size_t(i)]) continue;
    // The most confident refusal between this map and a placed one explains it best.
    const PairAlignment* closest = nullptr;
    for (const auto& p : out.pairs) {
      if ((p.a == i && in_tree[std::size_t(p.b)]) || (p.b == i && in_tree[std::size_t(p.a)])) {
        if (closest == nullptr || p.result.confidence > closest->result.confidence) closest = &p;
      }
    }
    if (closest != nullptr) out.reason_pair[std::size_t(i)] = int(closest - out.pairs.data());
    out.reason[std::size_t(i)] = closest != nullptr && !closest->result.reason.empty()
                                     ? closest->result.reason
                                     : "no reliable overlap with any map linked to the first";
  }
  // Loop check: reliable pairs the tree did not use.
  for (std::size_t e = 0; e < out.pairs.size(); ++e) {
    const auto& p = out.pairs[e];
    if (tree_pair[e] || !p.result.merged || !out.to_first[std::size_t(p.a)] || !out.to_first[std::size_t(p.b)]) continue;
    const core::Transform2 implied = out.to_first[std::size_t(p.a)]->inverse() * *out.to_first[std::size_t(p.b)];
    const Eigen::Vector2d at_b = p.result.transform.inverse().apply(p.result.quality.overlap_centre);
    out.max_loop_gap = std::max(out.max_loop_gap, (implied.apply(at_b) - p.result.transform.apply(at_b)).norm());
  }
  return out;
}

FusedMap fuse_merged(const std::vector<const mapping::OccupancyGrid*>& grids, const MultiMergeResult& merged) {
  if (grids.size() != merged.to_first.size()) throw Error("fuse_merged: one merge result per grid expected");
  std::vector<const mapping::OccupancyGrid*> placed;
  std::vector<core::Transform2> transforms;
  std::vector<int> inputs;
  for (std::size_t i = 0; i < grids.size(); ++i) {
    if (!merged.to_first[i]) continue;
    placed.push_back(grids[i]);
    transforms.push_back(*merged.to_first[i]);
    inputs.push_back(int(i));
  }
  FusedMap fused = fuse_grids(placed, transforms);
  fused.inputs = std::move(inputs);
  return fused;
}

Placement placement(const core::GridGeometry& first, const core::GridGeometry& input, const core::Transform2& cells,
                    const std::optional<Eigen::Matrix3d>& covariance) {
  const core::GridGeometry seen = mapping::resampled_geometry(input, first.resolution());
  Placement out;
  out.metres = world_from_cells(first, seen, cells);
  if (covariance)
    out.covariance = propagate_covariance(*covariance, cells,
                                          [&](const core::Transform2& t) { return world_from_cells(first, seen, t); });
  // A pixel (u, v) of the input is its cell (u, H - 1 - v), whose centre lies s (u, H - 1 - v) + c (1, 1)
  // in the seen cells (same origin; c = (s - 1) / 2), which is the seen grid's pixel s (u, v) + o;
  // the rigid placement of the seen grid's pixels then gives s R p + (R o + t).
  const core::Transform2 rigid = flip_rows(cells, first.height(), seen.height());
  const double s = input.resolution() / first.resolution(), c = (s - 1.0) / 2.0;
  const Eigen::Vector2d o(c, seen.height() - 1.0 - s * (input.height() - 1.0) - c);
  out.pixels = core::Transform2(rigid.rotation_matrix() * o + rigid.translation(), rigid.rotation());
  out.scale = s;
  return out;
}

Uncertainty describe_uncertainty(const Eigen::Matrix3d& covariance, const core::Transform2& transform,
                                 const Eigen::Vector2d& at) {
  Uncertainty u;
  u.std_tx = std::sqrt(std::max(0.0, covariance(0, 0)));
  u.std_ty = std::sqrt(std::max(0.0, covariance(1, 1)));
  u.std_theta_deg = core::rad2deg(std::sqrt(std::max(0.0, covariance(2, 2))));
  u.at = at;
  // The point of b that lands at `at` moves by dt + dtheta perp(at - t).
  const Eigen::Vector2d lever = at - transform.translation();
  Eigen::Matrix<double, 2, 3> j;
  j << 1.0, 0.0, -lever.y(), 0.0, 1.0, lever.x();
  const Eigen::Matrix2d c = j * covariance * j.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(c);
  u.std_minor = std::sqrt(std::max(0.0, eig.eigenvalues()(0)));
  u.std_major = std::sqrt(std::max(0.0, eig.eigenvalues()(1)));
  const Eigen::Vector2d major = eig.eigenvectors().col(1);
  u.major_deg = std::fmod(core::rad2deg(std::atan2(major.y(), major.x())) + 360.0, 180.0);
  return u;
}

MergedMaps merge_and_fuse(const std::vector<const mapping::OccupancyGrid*>& grids, const MergeOptions& options,
                          const std::function<void(int, int)>& progress) {
  return fuse_placed(grids, merge_maps(grids, options, progress));
}

MergedMaps fuse_placed(const std::vector<const mapping::OccupancyGrid*>& grids, MultiMergeResult merge) {
  if (grids.size() != merge.to_first.size()) throw Error("fuse_placed: one merge result per grid expected");
  MergedMaps out;
  out.merge = std::move(merge);
  if (grids.empty()) return out;
  const mapping::OccupancyGrid& first = *grids.front();
  // Maps of other resolutions are fused through the first's cells.
  std::vector<mapping::OccupancyGrid> resampled;
  resampled.reserve(grids.size());
  std::vector<const mapping::OccupancyGrid*> in_first_cells;
  for (std::size_t i = 0; i < grids.size(); ++i) {
    const mapping::OccupancyGrid& g = *grids[i];
    out.placements.push_back(out.merge.to_first[i] ? std::optional(placement(first.geometry(), g.geometry(), *out.merge.to_first[i],
                                                                                  out.merge.covariance[i]))
                                                   : std::nullopt);
    if (g.resolution() == first.resolution() || !out.merge.to_first[i]) {
      in_first_cells.push_back(&g);
      continue;
    }
    resampled.push_back(mapping::resample(g, first.resolution()));
    in_first_cells.push_back(&resampled.back());
  }
  out.fused = fuse_merged(in_first_cells, out.merge);
  out.map = mapping::crop_to_known(out.fused.grid, int(std::ceil(kMergedMarginM / first.resolution())));
  return out;
}

}  // namespace fleetmap::merging
