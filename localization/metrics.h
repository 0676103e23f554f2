#pragma once
// Localization metrics, defined once (DESIGN.md §5): position and heading RMSE, the standard
// NEES e^T P^-1 e averaged over steps with its chi-square band, and D'Alfonso et al.'s mu as that paper
// prints it (e^T P e, without the inverse), to be reported side by side.
#include <Eigen/Core>

#include <optional>

#include "core/transform2.h"

namespace fleetmap::localization {

// The p-quantile of the chi-square distribution with `dof` degrees of freedom (Boost.Math).
// Throws std::domain_error for dof <= 0 or p outside (0, 1).
double chi_square_quantile(double dof, double p);

// A two-sided confidence interval.
struct ChiSquareBand {
  double lower = 0.0;
  double upper = 0.0;
  bool contains(double value) const { return value >= lower && value <= upper; }
};

// The two-sided `confidence` band for the mean of `samples` independent chi-square(dof) values:
// samples * mean ~ chi2(dof * samples), so the band is [q((1-c)/2), q((1+c)/2)] / samples. With
// dof = 3 and samples = K it is the band of a run's average NEES over K steps; with samples = N it
// is the band of the N-run Monte-Carlo average at one step (Bar-Shalom et al. 2001, §5.4).
// Throws std::domain_error for dof < 1, samples < 1 or confidence outside (0, 1).
ChiSquareBand average_chi_square_band(int dof, long samples, double confidence = 0.95);

// e = truth - estimate, the heading difference wrapped to (-pi, pi].
Eigen::Vector3d pose_error(const core::Pose2& truth, const core::Pose2& estimate);

// The standard NEES e^T P^-1 e; nullopt when P is not positive definite (e.g. `ideal`'s zero P).
std::optional<double> nees(const Eigen::Vector3d& error, const Eigen::Matrix3d& covariance);

// D'Alfonso et al. §4's summand [x - x~]^T P [x - x~], as printed (P, not P^-1). It is not a consistency
// measure (its scale is that of P times e^2); it is reported so results compare with Table 1.
double dalfonso_mu_term(const Eigen::Vector3d& error, const Eigen::Matrix3d& covariance);

// One run's (or one robot's) localization summary.
struct LocalizationSummary {
  long steps = 0;
  double position_rmse = 0.0;  // m: sqrt(mean(ex^2 + ey^2))
  double heading_rmse = 0.0;   // rad
  // The mean NEES over the nees_steps steps whose covariance is positive definite (a start with
  // P0 = 0, or `ideal`, has none); nullopt when there is no such step.
  std::optional<double> average_nees;
  long nees_steps = 0;
  ChiSquareBand nees_band;  // the band of the mean of `nees_steps` chi2(3) values (0, 0 if none)
  bool nees_inside_band = false;
  // D'Alfonso et al.'s mu: 1/(k_f + 1) sum_{k=0}^{k_f} e^T P e over the same steps (add step 0 to match
  // the paper's sum).
  double dalfonso_mu = 0.0;
};

// Accumulates one estimate per step against the truth.
class LocalizationMetrics {
 public:
  void add(const core::Pose2& truth, const core::Pose2& estimate, const Eigen::Matrix3d& covariance);
  long steps() const { return steps_; }
  // Throws fleetmap::Error when no step was added.
  LocalizationSummary summary(double confidence = 0.95) const;

 private:
  long steps_ = 0;
  long nees_steps_ = 0;
  double position_sq_ = 0.0;
  double heading_sq_ = 0.0;
  double nees_sum_ = 0.0;
  double mu_sum_ = 0.0;
};

}  // namespace fleetmap::localization
