#include "merging/overlap_search.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/angle.h"
#include "merging/grid_level.h"
#include "merging/hough_spectrum.h"

namespace fleetmap::merging {

namespace {

constexpr double kPi = std::numbers::pi;

int common_level(const PreparedGrid& a, const PreparedGrid& b, int cells, double max_cell_m) {
  const int top = std::min(a.level_count(), b.level_count()) - 1;
  int level = std::min(top, std::max(a.level_for_size(cells), b.level_for_size(cells)));
  const double resolution = std::max(a.grid().resolution(), b.grid().resolution());
  while (level > 0 && a.level(level).factor * resolution > max_cell_m + 1e-9) --level;
  return level;
}

cv::Mat as_float(const cv::Mat& mask) {
  cv::Mat f;
  mask.convertTo(f, CV_32F, 1.0 / 255.0);
  return f;
}

// Free cells at least 1.5 cells from any wall: where a wall of the other map contradicts.
cv::Mat clear_free(const GridLevel& level) {
  cv::Mat far = level.wall_distance > 1.5f;
  return as_float(level.free & far);
}

cv::Mat padded_dft(const cv::Mat& img, cv::Size size) {
  cv::Mat padded = cv::Mat::zeros(size, CV_32F);
  img.copyTo(padded(cv::Rect(0, 0, img.cols, img.rows)));
  cv::Mat spectrum;
  // Rows past the image are zero: their row transforms are zero and are skipped.
  cv::dft(padded, spectrum, 0, img.rows);
  return spectrum;
}

struct Peak {
  cv::Point at;
  double value;
};

// The `count` highest maxima of `s` (CV_32F), each suppressing a square of radius `radius` around
// it: the highest positive value (the first in raster order among equals), then the highest
// outside the squares of those taken, and so on. The maximum of every row, kept up to date for the
// rows a square covers, finds each in a few rows instead of a search of the whole surface.
std::vector<Peak> top_peaks(cv::Mat s, int count, int radius) {
  std::vector<Peak> peaks;
  if (s.empty() || count <= 0) return peaks;
  cv::Mat row_max;  // s.rows x 1
  cv::reduce(s, row_max, 1, cv::REDUCE_MAX);
  float* m = row_max.ptr<float>();
  for (int i = 0; i < count; ++i) {
    const int y = int(std::max_element(m, m + s.rows) - m);  // the first of equals
    if (!(m[y] > 0.0f)) break;
    const float* row = s.ptr<float>(y);
    const int x = int(std::find(row, row + s.cols, m[y]) - row);
    peaks.push_back({{x, y}, double(m[y])});
    const cv::Rect r = cv::Rect(x - radius, y - radius, 2 * radius + 1, 2 * radius + 1) & cv::Rect(0, 0, s.cols, s.rows);
    s(r).setTo(-1e30);
    for (int yy = r.y; yy < r.y + r.height; ++yy) {
      const float* w = s.ptr<float>(yy);
      m[yy] = *std::max_element(w, w + s.cols);
    }
  }
  return peaks;
}

}  // namespace

std::vector<double> spectral_rotation_candidates(const PreparedGrid& a, const PreparedGrid& b,
                                                 const OverlapSearchOptions& options) {
  const int bins = std::max(8, options.angle_bins);
  const auto hs_a = hough_spectrum(a.level(0).wall_points, bins);
  const auto hs_b = hough_spectrum(b.level(0).wall_points, bins);
  const auto cc = circular_cross_correlation(hs_a, hs_b);
  // Peaks closer than 3 degrees are one peak.
  const int separation = std::max(1, int(std::lround(3.0 * bins / 180.0)));
  std::vector<double> rotations;
  for (double theta : correlation_peaks(cc, options.spectrum_peaks, separation)) {
    rotations.push_back(core::normalize_angle(theta));
    rotations.push_back(core::normalize_angle(theta + kPi));
  }
  return rotations;
}

std::vector<Hypothesis> overlap_hypotheses(const PreparedGrid& a, const PreparedGrid& b,
                                           const OverlapSearchOptions& options) {
  std::vector<double> rotations = spectral_rotation_candidates(a, b, options);
  if (options.sweep_step_deg > 0.0) {
    const double step = core::deg2rad(options.sweep_step_deg);
    const std::size_t spectral = rotations.size();
    for (double theta = -kPi + step; theta <= kPi + 1e-9; theta += step) {
      bool near = false;
      for (std::size_t i = 0; i < spectral; ++i) {
        if (std::abs(core::normalize_angle(theta - rotations[i])) < 0.75 * step) near = true;
      }
      if (!near) rotations.push_back(core::normalize_angle(theta));
    }
  }
  return overlap_hypotheses_at(a, b, rotations, options);
}

std::vector<Hypothesis> overlap_hypotheses_at(const PreparedGrid& a, const PreparedGrid& b,
                                              const std::vector<double>& rotations,
                                              const OverlapSearchOptions& options) {
  const int level = common_level(a, b, options.search_cells, options.max_search_cell_m);
  const GridLevel& la = a.level(level);
  const GridLevel& lb = b.level(level);
  const double w = options.contradiction_weight;

  // a's side of the score, transformed once: the free side of walls near the free side of walls
  // counts for (walls seen from the same side: two rooms laid edge to edge along a wall do not
  // fit), occupied cells on clear free space against.
  // Clutter never counts against (it may have moved between the two visits).
  const cv::Mat occupied_a = as_float(la.occupied & ~la.clutter);
  cv::Mat band_a_near;
  cv::dilate(as_float(la.free_band), band_a_near, cv::Mat::ones(3, 3, CV_8U));
  const cv::Mat band_b = as_float(lb.free_band), occupied_b = as_float(lb.occupied & ~lb.clutter), clear_b = clear_free(lb);

  // b turned by any angle fits a D x D canvas centred on b's centre.
  const int d = int(std::ceil(std::hypot(double(lb.width()), double(lb.height())))) + 2;
  const cv::Size size(cv::getOptimalDFTSize(la.width() + d), cv::getOptimalDFTSize(la.height() + d));
  const cv::Mat g_band = padded_dft(band_a_near, size);
  const cv::Mat g_clear = padded_dft(clear_free(la), size);
  const cv::Mat g_occupied = padded_dft(occupied_a, size);
  const Eigen::Vector2d centre_b((lb.width() - 1) / 2.0, (lb.height() - 1) / 2.0);
  const Eigen::Vector2d centre_canvas((d - 1) / 2.0, (d - 1) / 2.0);
  const int radius = std::max(1, options.peak_separation);

  // Each rotation's maxima, in the order of `rotations`.
  std::vector<std::vector<Hypothesis>> found(rotations.size());
  const auto add_peaks = [&](std::size_t i, const cv::Mat& s, const Eigen::Vector2d& shift) {
    for (const auto& p : top_peaks(s, options.translation_peaks, radius)) {
      // A shift index beyond a's extent wraps around to a negative shift.
      const int tx = p.at.x >= la.width() ? p.at.x - size.width : p.at.x;
      const int ty = p.at.y >= la.height() ? p.at.y - size.height : p.at.y;
      const core::Transform2 coarse(shift + Eigen::Vector2d(tx, ty), rotations[i]);
      found[i].push_back({from_level(coarse, la.factor), p.value, level, "grid"});
    }
  };
  // b turned by theta + pi is b turned by theta reflected through the canvas centre (D - q for
  // D = d - 1), and a correlation with a reflection is a convolution:
  // S_{theta+pi}(t) = sum_q T(D - q) A(q + t) = (A * T)(t + D). Rotations a half turn apart
  // share b's three transforms (the spectral candidates come in such pairs, and so do the probes'
  // quarter turns).
  std::vector<bool> done(rotations.size(), false);
  // b turned is drawn straight into the top-left d x d corner of one zero canvas of the transform's
  // size (the rest stays zero), and transformed from there.
  cv::Mat canvas = cv::Mat::zeros(size, CV_32F);
  cv::Mat turned = canvas(cv::Rect(0, 0, d, d));
  cv::Mat f_band, f_occupied, f_clear, product, product2, s, shifted;
  const auto combine = [&](bool conjugate) {
    cv::mulSpectrums(g_band, f_band, product, 0, conjugate);
    cv::mulSpectrums(g_clear, f_occupied, product2, 0, conjugate);
    product -= w * product2;
    cv::mulSpectrums(g_occupied, f_clear, product2, 0, conjugate);
    product -= w * product2;
    cv::idft(product, s, cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
  };
  for (std::size_t i = 0; i < rotations.size(); ++i) {
    if (done[i]) continue;
    const double theta = rotations[i];
    const core::Transform2 rot(0.0, 0.0, theta);
    const Eigen::Vector2d shift = centre_canvas - rot.apply(centre_b);
    const Eigen::Matrix2d r = rot.rotation_matrix();
    const cv::Mat m = (cv::Mat_<double>(2, 3) << r(0, 0), r(0, 1), shift.x(), r(1, 0), r(1, 1), shift.y());
    const auto turned_dft = [&](const cv::Mat& image, cv::Mat& spectrum) {
      cv::warpAffine(image, turned, m, turned.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
      assert(turned.data == canvas.data);  // drawn in place (same size and type), not reallocated
      cv::dft(canvas, spectrum, 0, d);  // rows past d are zero
    };
    turned_dft(band_b, f_band);
    turned_dft(occupied_b, f_occupied);
    turned_dft(clear_b, f_clear);
    // S(t) = sum_q band_b(q) band_a_near(q + t)
    //        - w sum_q [occupied_b(q) clear_a(q + t) + clear_b(q) occupied_a(q + t)], all t at once.
    combine(true);
    add_peaks(i, s, shift);
    for (std::size_t j = i + 1; j < rotations.size(); ++j) {
      if (done[j] || std::abs(core::normalize_angle(rotations[j] - theta - kPi)) > 1e-9) continue;
      done[j] = true;
      combine(false);
      // Index t of S is index t + D of the convolution (cyclic).
      const int dx = (d - 1) % size.width, dy = (d - 1) % size.height;
      shifted.create(s.size(), s.type());
      const int w0 = size.width - dx, h0 = size.height - dy;
      s(cv::Rect(dx, dy, w0, h0)).copyTo(shifted(cv::Rect(0, 0, w0, h0)));
      if (dx > 0) s(cv::Rect(0, dy, dx, h0)).copyTo(shifted(cv::Rect(w0, 0, dx, h0)));
      if (dy > 0) s(cv::Rect(dx, 0, w0, dy)).copyTo(shifted(cv::Rect(0, h0, w0, dy)));
      if (dx > 0 && dy > 0) s(cv::Rect(0, 0, dx, dy)).copyTo(shifted(cv::Rect(w0, h0, dx, dy)));
      const core::Transform2 turned(0.0, 0.0, rotations[j]);
      add_peaks(j, shifted, centre_canvas - turned.apply(centre_b));
      break;
    }
  }
  std::vector<Hypothesis> out;
  for (auto& f : found) out.insert(out.end(), f.begin(), f.end());
  std::sort(out.begin(), out.end(), [](const Hypothesis& x, const Hypothesis& y) { return x.score > y.score; });
  if (int(out.size()) > options.max_hypotheses) out.resize(std::size_t(std::max(0, options.max_hypotheses)));
  return out;
}

}  // namespace fleetmap::merging
