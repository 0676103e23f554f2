#pragma once
// Statistics for benchmark tables: the mean, the sample standard deviation and a two-sided
// confidence interval of the mean (Student t), and the paired comparison of two methods run on the
// same problems (the mean difference with its interval and the paired t test).
#include <limits>
#include <span>

namespace fleetmap::sweep {

struct SampleSummary {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  int n = 0;
  double mean = kNaN;    // NaN when n = 0
  double sd = kNaN;      // sample standard deviation (n - 1 in the denominator); NaN when n < 2
  double ci_low = kNaN;  // mean -/+ t(1 - (1 - confidence) / 2, n - 1) * sd / sqrt(n); NaN when n < 2
  double ci_high = kNaN;
  double half_width() const { return 0.5 * (ci_high - ci_low); }
};

// The two-sided critical value t such that P(|T| <= t) = confidence for T ~ Student t with `dof`
// degrees of freedom (dof >= 1, 0 < confidence < 1), e.g. 12.706 for dof 1 and 0.95.
double student_t_critical(int dof, double confidence = 0.95);

// Non-finite values are ignored.
SampleSummary summarize(std::span<const double> values, double confidence = 0.95);

struct PairedComparison {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  SampleSummary difference;  // of a[i] - b[i] over the pairs
  double t = kNaN;           // the paired t statistic, mean / (sd / sqrt(n)); NaN when n < 2 or sd = 0
  double p_value = kNaN;     // two-sided; 0 or 1 when sd = 0 and the mean differs from 0 or not
  int a_lower = 0, b_lower = 0, ties = 0;
};

// a[i] and b[i] are one problem solved by two methods; pairs with a non-finite value are left out.
// Throws std::invalid_argument when the spans differ in length.
PairedComparison compare_paired(std::span<const double> a, std::span<const double> b, double confidence = 0.95);

}  // namespace fleetmap::sweep
