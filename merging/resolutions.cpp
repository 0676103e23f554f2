#include "merging/resolutions.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "mapping/state_mask.h"

namespace fleetmap::merging {

namespace {

bool same_resolution(double x, double y) { return std::abs(x - y) <= 1e-9 * std::max(x, y); }

// `fine` pooled through the cells of the coarser map (resolution r) where `place` puts them:
// `place` takes resample(fine, r)'s cells into the coarser map's cells. The new grid covers fine's
// known cells with a margin; `offset` is its cell (0, 0) in the coarser map's cells.
mapping::OccupancyGrid pooled_where_placed(const mapping::OccupancyGrid& fine, double r, const core::Transform2& place,
                                           Eigen::Vector2i& offset) {
  const cv::Rect box =
      cv::boundingRect(mapping::state_mask(fine, {mapping::CellState::Occupied, mapping::CellState::Free}));
  const double s = fine.resolution() / r, c = (s - 1.0) / 2.0;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const int x : {box.x, box.br().x - 1}) {
    for (const int y : {box.y, box.br().y - 1}) {
      const Eigen::Vector2d q = place.apply(s * Eigen::Vector2d(x, y) + Eigen::Vector2d(c, c));
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
  }
  constexpr int kMargin = 2;
  offset = Eigen::Vector2i(int(std::floor(lo.x())) - kMargin, int(std::floor(lo.y())) - kMargin);
  const int width = int(std::ceil(hi.x())) + kMargin + 1 - offset.x();
  const int height = int(std::ceil(hi.y())) + kMargin + 1 - offset.y();
  const core::Transform2 shifted(place.translation() - offset.cast<double>(), place.rotation());
  return mapping::pool(fine, r, shifted, width, height);
}

}  // namespace

core::Transform2 rescale_cells(const core::Transform2& t, double from, double to) {
  // c_a = R c_b + t is m_a = R m_b + from (t + h - R h) in metres from the origin corners, h = (1/2, 1/2).
  const Eigen::Vector2d h(0.5, 0.5);
  const Eigen::Matrix2d r = t.rotation_matrix();
  const Eigen::Vector2d metres = from * (t.translation() + h - r * h);
  return {metres / to - h + r * h, t.rotation()};
}

MergeResult align_across_resolutions(const mapping::OccupancyGrid& a, const mapping::OccupancyGrid& b,
                                     const MergeOptions& options) {
  if (same_resolution(a.resolution(), b.resolution())) return align_maps(a, b, options);
  const double r = std::max(a.resolution(), b.resolution());
  const bool a_finer = a.resolution() < r;
  const mapping::OccupancyGrid coarse_a = a_finer ? mapping::resample(a, r) : a;
  const mapping::OccupancyGrid coarse_b = a_finer ? b : mapping::resample(b, r);
  const MergeResult first = align_maps(coarse_a, coarse_b, options);
  // Lattices half a cell apart lower every measure of a right answer a little: a wall drawn half a
  // cell off still lies on the other map's wall, but the cells beside it read free in one map and
  // occupied in the other (acceptance), and the walls fit less tightly (residual, so evidence). What
  // they do not do is lay walls on the other map's free space. So the second pooling runs for every
  // refused answer whose walls agree fully (agreement factor 1), and for one refused because its
  // cells disagree. An answer refused for its walls stays refused: pooled where that answer puts
  // it, a wrong answer's walls fit better too (real windows of two resolutions: a wrong placement,
  // its walls agreeing 92%, went from 0.44 to 0.64 that way).
  const bool walls_agree = first.quality.agreement >= options.confidence.full_agreement;
  const bool cells_refuse = first.refusal == Refusal::CellsDisagree || (!first.merged && walls_agree);
  if (first.candidates == 0 || !cells_refuse) return first;
  Eigen::Vector2i offset;
  if (!a_finer) {
    // b pooled through a's cells: its cell k is a's cell k + offset; b's coarse cells go there by
    // first.transform, so the answer between coarse_b and a is T2 shift(-offset) T1.
    const mapping::OccupancyGrid pooled_b = pooled_where_placed(b, r, first.transform, offset);
    MergeResult second = align_maps(a, pooled_b, options);
    const core::Transform2 into_pooled(-offset.cast<double>(), 0.0);
    if (second.covariance)
      second.covariance = propagate_covariance(*second.covariance, second.transform, [&](const core::Transform2& t) {
        return t * into_pooled * first.transform;
      });
    second.transform = second.transform * into_pooled * first.transform;
    if (second.alternative) second.alternative = *second.alternative * into_pooled * first.transform;
    return second;
  }
  // a pooled through b's cells: its cell k is b's cell k + offset, which first.transform takes into
  // coarse_a; the answer between b and coarse_a is T1 shift(offset) T2.
  const mapping::OccupancyGrid pooled_a = pooled_where_placed(a, r, first.transform.inverse(), offset);
  MergeResult second = align_maps(pooled_a, b, options);
  const core::Transform2 from_pooled = first.transform * core::Transform2(offset.cast<double>(), 0.0);
  if (second.covariance)
    second.covariance = propagate_covariance(*second.covariance, second.transform,
                                             [&](const core::Transform2& t) { return from_pooled * t; });
  second.transform = from_pooled * second.transform;
  if (second.alternative) second.alternative = from_pooled * *second.alternative;
  second.quality.overlap_centre = from_pooled.apply(second.quality.overlap_centre);
  return second;
}

}  // namespace fleetmap::merging
