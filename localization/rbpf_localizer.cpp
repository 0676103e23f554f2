#include "mapping/range_scan.h"
#include "localization/rbpf_localizer.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "core/angle.h"
#include "core/error.h"
#include "localization/likelihood_field.h"
#include "localization/localizers.h"

namespace fleetmap::localization {

namespace {

// The context's parameters, or the member's defaults when it has none.
core::Params params_of(const LocalizerContext& c, RbpfLocalizer::Proposal proposal) {
  if (!c.params.specs().empty()) return c.params;
  return localizer_registry().params(proposal == RbpfLocalizer::Proposal::ScanMatching ? "rbpf" : "fastslam-grid");
}

}  // namespace

RbpfLocalizer::RbpfLocalizer(const LocalizerContext& c, Proposal proposal)
    : options_(c.options), proposal_(proposal), rng_(c.seed) {
  const core::Params params = params_of(c, proposal);
  sample_motion_ = params.declares("sample_motion") ? params.flag("sample_motion") : true;
  if (params.declares("linear_update")) linear_update_ = params.number("linear_update");
  if (params.declares("angular_update")) angular_update_ = params.number("angular_update");
  // The robot knows where it starts: every particle starts there, with equal weights.
  particles_.resize(std::size_t(params.number("particles")));  // declared >= 1
  for (auto& p : particles_) p.pose = p.odometry_pose = c.initial_pose;
  n_eff_ = double(particles_.size());
}

void RbpfLocalizer::predict(const Odometry& u) {
  ++steps_;
  ++pending_steps_;
  moved_ += std::abs(u.v * u.dt);
  turned_ += std::abs(u.omega * u.dt);
  due_ = !(linear_update_ > 0.0 && angular_update_ > 0.0) || moved_ >= linear_update_ || turned_ >= angular_update_;
  // The noise of the pending steps is drawn once, when their scan is due: until then the particles
  // follow the odometry, so that the poses reported in between are the last corrected ones moved by it.
  const double spread = std::sqrt(double(pending_steps_));
  if (due_) {
    draw_spread_ = spread;
    pending_steps_ = 0;
  }
  for (auto& p : particles_) {
    p.odometry_pose = integrate_motion(p.pose, u);
    p.pose = p.odometry_pose;
    if (!due_ || (!sample_motion_ && proposal_ == Proposal::ScanMatching)) continue;
    p.pose = {p.pose.x + rng_.normal(0.0, spread * options_.process_noise_xy),
              p.pose.y + rng_.normal(0.0, spread * options_.process_noise_xy),
              core::normalize_angle(p.pose.theta + rng_.normal(0.0, spread * options_.process_noise_theta))};
  }
}

void RbpfLocalizer::update_scan(const RangeScan& scan, const mapping::OccupancyGrid& own_map) {
  const bool restart = !maps_ready_ || !(particles_.front().map.geometry() == own_map.geometry());
  if (!due_ && !restart) {
    ++skipped_;
    return;
  }
  if (restart) {
    const CowGrid start = CowGrid::from_occupancy_grid(own_map);
    for (auto& p : particles_) p.map = start;  // one set of tiles, shared by all
    maps_ready_ = true;
  }
  ScanMatcherOptions m = scan_matcher_options(options_, scan.max_range, own_map.resolution());
  // The motion prior spans the steps whose noise was drawn as one.
  m.prior_xy_m *= draw_spread_;
  m.prior_theta_rad *= draw_spread_;
  moved_ = turned_ = 0.0;
  due_ = !(linear_update_ > 0.0 && angular_update_ > 0.0);
  if (proposal_ == Proposal::Motion) {
    // The likelihood at the drawn pose alone: no search, no refinement, no prior.
    m.search_xy_m = m.search_theta_rad = 0.0;
    m.prior_xy_m = m.prior_theta_rad = 0.0;
    m.refine_iterations = 0;
  }
  for (auto& p : particles_) {
    // The motion model p(x | x', u) is centred on the odometry step; the drawn pose seeds the search.
    const ScanMatch match = match_scan_to_grid(p.map, scan, p.pose, m, p.odometry_pose);
    if (match.matched) {
      if (proposal_ == Proposal::ScanMatching) p.pose = match.pose;
      p.log_weight += match.log_normalizer;
      ++matched_;
    }
    mapping::insert_scan(p.map, p.pose, scan);
  }
  // Normalise, find the best particle, and resample when the weights have degenerated.
  double top = -1e300;
  for (const auto& p : particles_) top = std::max(top, p.log_weight);
  double sum = 0.0, sum2 = 0.0;
  for (auto& p : particles_) {
    p.log_weight -= top;
    sum += std::exp(p.log_weight);
  }
  for (auto& p : particles_) {
    p.log_weight -= std::log(sum);
    sum2 += std::exp(2.0 * p.log_weight);
  }
  n_eff_ = 1.0 / sum2;
  best_ = int(std::max_element(particles_.begin(), particles_.end(),
                               [](const Particle& a, const Particle& b) { return a.log_weight < b.log_weight; }) -
              particles_.begin());
  if (particles_.size() > 1 && n_eff_ < 0.5 * double(particles_.size())) resample();
}

void RbpfLocalizer::resample() {
  // Low-variance (systematic) resampling; the copies share their parent's map tiles.
  const std::size_t n = particles_.size();
  std::vector<Particle> next;
  next.reserve(n);
  const double step = 1.0 / double(n);
  double u = rng_.uniform(0.0, step), c = std::exp(particles_[0].log_weight);
  std::size_t i = 0;
  int best = 0;
  double best_w = -1.0;
  for (std::size_t k = 0; k < n; ++k) {
    while (u > c && i + 1 < n) c += std::exp(particles_[++i].log_weight);
    next.push_back(particles_[i]);
    next.back().log_weight = -std::log(double(n));
    if (std::exp(particles_[i].log_weight) > best_w) {
      best_w = std::exp(particles_[i].log_weight);
      best = int(k);
    }
    u += step;
  }
  particles_ = std::move(next);
  best_ = best;
  n_eff_ = double(n);
  ++resamplings_;
}

Eigen::Matrix3d RbpfLocalizer::covariance() const {
  // The weighted spread of the particles around the reported one, floored by one map cell.
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  const core::Pose2 ref = pose();
  for (const auto& p : particles_) {
    const Eigen::Vector3d d(p.pose.x - ref.x, p.pose.y - ref.y, core::normalize_angle(p.pose.theta - ref.theta));
    cov += std::exp(p.log_weight) * d * d.transpose();
  }
  const double res = maps_ready_ ? particles_.front().map.geometry().resolution() : 0.05;
  cov += Eigen::Vector3d(res * res / 12.0, res * res / 12.0, 1e-6).asDiagonal().toDenseMatrix();
  return cov;
}

void RbpfLocalizer::change_frame(const core::Transform2& t) {
  for (auto& p : particles_) p.pose = core::Pose2::from_transform(t * p.pose.as_transform());
  maps_ready_ = false;  // the maps restart from the robot's map in the new frame at the next scan
}

std::vector<std::pair<std::string, double>> RbpfLocalizer::counters() const {
  const MemoryStats m = memory();
  return {{"particles", double(particles_.size())},
          {"resamplings", double(resamplings_)},
          {"effective_sample_size", n_eff_},
          {"scan_matches", double(matched_)},
          {"scans_skipped", double(skipped_)},
          {"map_bytes_shared", double(m.shared_bytes)},
          {"map_bytes_unshared", double(m.unshared_bytes)}};
}

std::optional<mapping::OccupancyGrid> RbpfLocalizer::map_estimate() const {
  if (!maps_ready_) return std::nullopt;
  return particles_[std::size_t(best_)].map.to_occupancy_grid();
}

RbpfLocalizer::MemoryStats RbpfLocalizer::memory() const {
  MemoryStats s;
  if (!maps_ready_) return s;
  std::unordered_set<const CowGrid::Tile*> tiles;
  for (const auto& p : particles_) {
    p.map.collect_tiles(tiles);
    s.shared_bytes += p.map.table_bytes();
    s.unshared_bytes += std::size_t(p.map.geometry().cell_count()) * CowGrid::tile_bytes() / (CowGrid::kTile * CowGrid::kTile);
  }
  s.distinct_tiles = int(tiles.size());
  s.shared_bytes += tiles.size() * CowGrid::tile_bytes();
  return s;
}

std::unique_ptr<Localizer> make_rbpf_localizer(const LocalizerContext& c) { return std::make_unique<RbpfLocalizer>(c); }

std::unique_ptr<Localizer> make_grid_fastslam_localizer(const LocalizerContext& c) {
  return std::make_unique<RbpfLocalizer>(c, RbpfLocalizer::Proposal::Motion);
}

}  // namespace fleetmap::localization
