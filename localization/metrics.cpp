#include "localization/metrics.h"

#include <Eigen/Dense>
#include <boost/math/distributions/chi_squared.hpp>

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/angle.h"
#include "core/error.h"

namespace fleetmap::localization {

double chi_square_quantile(double dof, double p) {
  if (!(dof > 0.0) || !(p > 0.0 && p < 1.0)) {
    throw std::domain_error("chi_square_quantile: needs dof > 0 and 0 < p < 1, got dof " + std::to_string(dof) +
                            ", p " + std::to_string(p));
  }
  return boost::math::quantile(boost::math::chi_squared_distribution<double>(dof), p);
}

ChiSquareBand average_chi_square_band(int dof, long samples, double confidence) {
  if (dof < 1 || samples < 1 || !(confidence > 0.0 && confidence < 1.0)) {
    throw std::domain_error("average_chi_square_band: needs dof >= 1, samples >= 1 and 0 < confidence < 1");
  }
  const double total_dof = static_cast<double>(dof) * static_cast<double>(samples);
  const double n = static_cast<double>(samples);
  return {chi_square_quantile(total_dof, 0.5 * (1.0 - confidence)) / n,
          chi_square_quantile(total_dof, 0.5 * (1.0 + confidence)) / n};
}

Eigen::Vector3d pose_error(const core::Pose2& truth, const core::Pose2& estimate) {
  return {truth.x - estimate.x, truth.y - estimate.y, core::normalize_angle(truth.theta - estimate.theta)};
}

std::optional<double> nees(const Eigen::Vector3d& error, const Eigen::Matrix3d& covariance) {
  const Eigen::LLT<Eigen::Matrix3d> llt(covariance);
  if (llt.info() != Eigen::Success) return std::nullopt;
  const double v = error.dot(llt.solve(error));
  if (!std::isfinite(v)) return std::nullopt;
  return v;
}

double dalfonso_mu_term(const Eigen::Vector3d& error, const Eigen::Matrix3d& covariance) {
  return error.dot(covariance * error);
}

void LocalizationMetrics::add(const core::Pose2& truth, const core::Pose2& estimate,
                              const Eigen::Matrix3d& covariance) {
  const Eigen::Vector3d e = pose_error(truth, estimate);
  ++steps_;
  position_sq_ += e.head<2>().squaredNorm();
  heading_sq_ += e(2) * e(2);
  if (const auto v = nees(e, covariance)) {
    nees_sum_ += *v;
    ++nees_steps_;
  }
  mu_sum_ += dalfonso_mu_term(e, covariance);
}

LocalizationSummary LocalizationMetrics::summary(double confidence) const {
  if (steps_ == 0) throw Error("LocalizationMetrics::summary: no step was added");
  const double n = static_cast<double>(steps_);
  LocalizationSummary s;
  s.steps = steps_;
  s.position_rmse = std::sqrt(position_sq_ / n);
  s.heading_rmse = std::sqrt(heading_sq_ / n);
  s.nees_steps = nees_steps_;
  if (nees_steps_ > 0) {
    s.nees_band = average_chi_square_band(3, nees_steps_, confidence);
    s.average_nees = nees_sum_ / static_cast<double>(nees_steps_);
    s.nees_inside_band = s.nees_band.contains(*s.average_nees);
  }
  s.dalfonso_mu = mu_sum_ / n;
  return s;
}

}  // namespace fleetmap::localization
