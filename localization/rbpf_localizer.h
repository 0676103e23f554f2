#pragma once
// `rbpf`: a Rao-Blackwellized particle filter for grid SLAM (León et al., §II.B-C; Grisetti, Stachniss
// & Burgard 2005). Every particle carries a pose and its own grid (grid FastSLAM). Each step:
//  1. sampling: the particle's odometry step is drawn with the process noise
//     (its sample_motion parameter);
//  2. improved proposal: the scan is matched to the particle's own map, the search starting from
//     that draw, with the motion model centred on the odometry step as prior (match_scan:
//     correlative search, then refinement); the particle takes the proposal's mode, as GMapping
//     does (Grisetti et al. draw from a Gaussian around it);
//  3. weighting: w <- w * eta, eta the proposal's normaliser (the sum over the search window of
//     likelihood x motion prior, Grisetti eq. (11)), with the likelihood scaled to a few independent
//     beams (ScanMatcherOptions::independent_beams), as GMapping's likelihood gain smooths weights;
//  4. the scan is integrated into the particle's map at its pose;
//  5. selective resampling: low-variance resampling when N_eff = 1 / sum(w^2) < N / 2.
// Steps 1-5 run only once the odometry has moved linear_update metres or turned angular_update
// radians since the last processed scan (GMapping's linearUpdate / angularUpdate): scans closer
// together add little to the map and cost a scan match per particle. Until then every particle
// follows its odometry undrawn, and the step's noise is drawn once for the whole motion (sqrt(k)
// times a step's for k steps), the matcher's prior widened alike.
// Maps are CowGrids: resampled copies share every tile until one of them writes to it.
// The reported pose and map are the particle with the largest weight.
//
// `fastslam-grid` is the same filter without the improved proposal (León et al., §II.B: grid-based
// FastSLAM, Montemerlo et al.'s particles with a grid each): a particle keeps its draw from the raw
// motion model (step 1, always sampled), and its weight is the likelihood of the scan at that pose
// on its own map (the likelihood field of step 2 at the one pose, scaled the same way).
#include <memory>
#include <vector>

#include "core/random.h"
#include "localization/cow_grid.h"
#include "localization/localizer.h"
#include "localization/scan_matcher.h"

namespace fleetmap::localization {

class RbpfLocalizer final : public Localizer {
 public:
  enum class Proposal {
    ScanMatching,  // `rbpf`: Grisetti et al.'s improved proposal
    Motion,        // `fastslam-grid`: the raw motion model
  };
  struct Particle {
    core::Pose2 pose;
    core::Pose2 odometry_pose;  // the last odometry step from the previous pose, undrawn
    CowGrid map;
    double log_weight = 0.0;
  };
  struct MemoryStats {
    std::size_t shared_bytes = 0;    // distinct tiles over all particles, plus the pointer tables
    std::size_t unshared_bytes = 0;  // what a dense grid of the same cells per particle would take
    int distinct_tiles = 0;
  };

  // The particles' maps are created at the first scan with the geometry of the robot's own map,
  // and restart from that map (shared by all) when its geometry changes, e.g. after change_frame.
  explicit RbpfLocalizer(const LocalizerContext& context, Proposal proposal = Proposal::ScanMatching);

  std::string name() const override { return proposal_ == Proposal::Motion ? "fastslam-grid" : "rbpf"; }
  bool uses_scans() const override { return true; }
  void predict(const Odometry& u) override;
  void update_scan(const RangeScan& scan, const mapping::OccupancyGrid& own_map) override;
  core::Pose2 pose() const override { return particles_[std::size_t(best_)].pose; }
  Eigen::Matrix3d covariance() const override;
  void change_frame(const core::Transform2& t) override;
  std::vector<std::pair<std::string, double>> counters() const override;
  std::optional<mapping::OccupancyGrid> map_estimate() const override;

  const std::vector<Particle>& particles() const { return particles_; }
  MemoryStats memory() const;
  double effective_sample_size() const { return n_eff_; }
  int resamplings() const { return resamplings_; }

 private:
  void resample();

  LocalizerOptions options_;
  Proposal proposal_;
  bool sample_motion_ = true;  // `rbpf`'s sample_motion parameter (fastslam-grid always samples)
  double linear_update_ = 0.0, angular_update_ = 0.0;  // 0 (fastslam-grid): every scan
  double moved_ = 0.0, turned_ = 0.0;  // odometry since the last processed scan
  int pending_steps_ = 0;              // odometry steps whose noise is not drawn yet
  double draw_spread_ = 1.0;           // sqrt of the steps the last draw stood for
  bool due_ = true;                    // the next scan is processed
  int skipped_ = 0;
  core::Random rng_;
  std::vector<Particle> particles_;
  int best_ = 0;
  double n_eff_ = 0.0;
  int resamplings_ = 0, steps_ = 0, matched_ = 0;
  bool maps_ready_ = false;
};

}  // namespace fleetmap::localization
