#pragma once
// Rotation candidates from Hough spectra (Carpin, "Fast and accurate map merging for multi-robot
// systems", Autonomous Robots 2008): the spectrum of a point set is HS(theta) = sum_rho H(rho, theta)^2
// over its Hough transform H; rotating a map shifts its spectrum circularly (period pi), so the
// peaks of the circular cross-correlation of two spectra are the candidate rotations.
#include <Eigen/Core>

#include <vector>

namespace fleetmap::merging {

// HS over `bins` angles theta_j = j * pi / bins, normalised to zero mean and unit norm.
// rho is quantised to cells.
std::vector<double> hough_spectrum(const std::vector<Eigen::Vector2f>& points, int bins);

// CC(k) = sum_j a[(j + k) mod n] * b[j]: CC peaks at k when b's lines, turned by k * pi / n, are a's.
std::vector<double> circular_cross_correlation(const std::vector<double>& a, const std::vector<double>& b);

// The `peaks` highest local maxima of CC (at least `min_separation` bins apart), refined by a
// parabola through the neighbours, as angles in [0, pi), best first. Each stands for two
// rotations, theta and theta + pi.
std::vector<double> correlation_peaks(const std::vector<double>& cc, int peaks, int min_separation);

}  // namespace fleetmap::merging
