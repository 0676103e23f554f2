#include "merging/hough_spectrum.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace fleetmap::merging {

std::vector<double> hough_spectrum(const std::vector<Eigen::Vector2f>& points, int bins) {
  std::vector<double> hs(std::size_t(std::max(bins, 1)), 0.0);
  if (points.empty()) return hs;
  float max_r = 0.0f;
  Eigen::Vector2f c = Eigen::Vector2f::Zero();
  for (const auto& p : points) c += p;
  c /= float(points.size());
  for (const auto& p : points) max_r = std::max(max_r, (p - c).norm());
  const int offset = int(std::ceil(max_r)) + 1, rho_bins = 2 * offset + 1;
  std::vector<int> h(static_cast<std::size_t>(rho_bins));
  // The points relative to their centre, once (not once per angle).
  std::vector<float> dx(points.size()), dy(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) dx[i] = points[i].x() - c.x(), dy[i] = points[i].y() - c.y();
  std::vector<int> bin(points.size());
  for (int j = 0; j < bins; ++j) {
    const double theta = j * std::numbers::pi / bins;
    const float cs = float(std::cos(theta)), sn = float(std::sin(theta));
    // The bins first, then the votes: the first loop is vectorized, the second cannot be.
    for (std::size_t i = 0; i < points.size(); ++i) {
      const float rho = dx[i] * cs + dy[i] * sn;
      bin[i] = int(rho + float(offset) + 0.5f);
    }
    std::fill(h.begin(), h.end(), 0);
    for (int k : bin) ++h[std::size_t(k)];
    double s = 0.0;
    for (int v : h) s += double(v) * double(v);
    hs[std::size_t(j)] = s;
  }
  double mean = 0.0;
  for (double v : hs) mean += v;
  mean /= double(bins);
  double norm = 0.0;
  for (double& v : hs) {
    v -= mean;
    norm += v * v;
  }
  norm = std::sqrt(norm);
  if (norm > 0.0) for (double& v : hs) v /= norm;
  return hs;
}

std::vector<double> circular_cross_correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t n = a.size();
  std::vector<double> cc(n, 0.0);
  if (b.size() != n) return cc;
  for (std::size_t k = 0; k < n; ++k) {
    double s = 0.0;
    for (std::size_t j = 0; j < n; ++j) s += a[(j + k) % n] * b[j];
    cc[k] = s;
  }
  return cc;
}

std::vector<double> correlation_peaks(const std::vector<double>& cc, int peaks, int min_separation) {
  const int n = int(cc.size());
  if (n == 0) return {};
  std::vector<int> maxima;
  for (int k = 0; k < n; ++k) {
    const double v = cc[std::size_t(k)];
    if (v >= cc[std::size_t((k + n - 1) % n)] && v > cc[std::size_t((k + 1) % n)]) maxima.push_back(k);
  }
  if (maxima.empty()) maxima.push_back(0);  // a flat correlation: no preferred angle
  std::sort(maxima.begin(), maxima.end(), [&](int x, int y) { return cc[std::size_t(x)] > cc[std::size_t(y)]; });
  std::vector<int> kept;
  for (int k : maxima) {
    if (int(kept.size()) >= peaks) break;
    bool far = true;
    for (int q : kept) {
      const int d = std::abs(k - q);
      if (std::min(d, n - d) < min_separation) far = false;
    }
    if (far) kept.push_back(k);
  }
  std::vector<double> out;
  for (int k : kept) {
    const double l = cc[std::size_t((k + n - 1) % n)], m = cc[std::size_t(k)], r = cc[std::size_t((k + 1) % n)];
    const double den = l - 2.0 * m + r;
    const double off = std::abs(den) > 1e-12 ? std::clamp(0.5 * (l - r) / den, -0.5, 0.5) : 0.0;
    double theta = (k + off) * std::numbers::pi / n;
    if (theta < 0.0) theta += std::numbers::pi;
    out.push_back(theta);
  }
  return out;
}

}  // namespace fleetmap::merging
