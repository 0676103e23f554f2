#include "sweep/statistics.h"

#include <boost/math/distributions/students_t.hpp>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace fleetmap::sweep {

double student_t_critical(int dof, double confidence) {
  if (dof < 1 || !(confidence > 0.0 && confidence < 1.0)) {
    throw std::invalid_argument("student_t_critical: need dof >= 1 and 0 < confidence < 1");
  }
  const boost::math::students_t t{double(dof)};
  return boost::math::quantile(t, 0.5 + 0.5 * confidence);
}

SampleSummary summarize(std::span<const double> values, double confidence) {
  SampleSummary s;
  double sum = 0.0;
  for (double v : values) {
    if (std::isfinite(v)) sum += v, ++s.n;
  }
  if (s.n == 0) return s;
  s.mean = sum / s.n;
  if (s.n < 2) return s;
  double squares = 0.0;
  for (double v : values) {
    if (std::isfinite(v)) squares += (v - s.mean) * (v - s.mean);
  }
  s.sd = std::sqrt(squares / (s.n - 1));
  const double half = student_t_critical(s.n - 1, confidence) * s.sd / std::sqrt(double(s.n));
  s.ci_low = s.mean - half;
  s.ci_high = s.mean + half;
  return s;
}

PairedComparison compare_paired(std::span<const double> a, std::span<const double> b, double confidence) {
  if (a.size() != b.size()) throw std::invalid_argument("compare_paired: the two samples differ in length");
  PairedComparison c;
  std::vector<double> d;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!std::isfinite(a[i]) || !std::isfinite(b[i])) continue;
    d.push_back(a[i] - b[i]);
    if (a[i] < b[i]) ++c.a_lower;
    else if (b[i] < a[i]) ++c.b_lower;
    else ++c.ties;
  }
  c.difference = summarize(d, confidence);
  if (c.difference.n < 2) return c;
  if (c.difference.sd == 0.0) {
    c.p_value = c.difference.mean == 0.0 ? 1.0 : 0.0;
    return c;
  }
  c.t = c.difference.mean / (c.difference.sd / std::sqrt(double(c.difference.n)));
  const boost::math::students_t dist{double(c.difference.n - 1)};
  c.p_value = 2.0 * boost::math::cdf(boost::math::complement(dist, std::abs(c.t)));
  return c;
}

}  // namespace fleetmap::sweep
