#pragma once
// Graph-based 2D SLAM after Hess et al. 2016 ("Real-time loop closure in 2D LIDAR SLAM"): each scan
// is matched against the current submap (Olson's correlative search, refined by least squares)
// and becomes a node; submaps are probability grids of a fixed number of scans; loop closures are
// found by a branch-and-bound correlative search of nodes against finished submaps; a pose graph
// of nodes and submaps, loop closures under a robust (Huber) loss, is optimized with Ceres.
// No I/O: scans in, poses out.
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include "core/transform2.h"
#include "localization/submap_grid.h"
#include "localization/submap_matching.h"
#include "mapping/range_scan.h"

namespace fleetmap::localization {

struct GraphSlamOptions {
  SubmapGridOptions grid;
  // Beams are used between these ranges (a farther return counts as no return).
  double min_range_m = 0.1;
  double max_range_m = 30.0;
  // Points for matching kept one per square of this side: the least-squares refinement; the
  // correlative searches (local and loop closure).
  double match_voxel_m = 0.05;
  double loop_voxel_m = 0.2;
  // A new submap starts every `scans_per_submap` inserted scans and each submap takes twice as
  // many, so that the robot is always matched against a submap already well filled.
  int scans_per_submap = 30;
  // A scan is inserted into the submaps when the robot moved this much since the last inserted
  // (Cartographer's motion filter)
  // (matched, it becomes a node either way): a robot standing still does not swamp the grid.
  double insert_min_distance_m = 0.2;
  double insert_min_angle_rad = 0.0175;
  // The local correlative search scores a scan by the submap's surface field (SubmapGrid), whose
  // sigma is the spread of a return's distance to the centre of the cell that holds its wall:
  // the laser's range noise and two cells' quantization (the point's and the wall's, a cell width
  // over sqrt(12) each). The local refinement fits the same field (local_refine.hit_field); loop
  // closures, the relocalizing search and the comparisons of two matches read the probabilities.
  CorrelativeOptions local_search = [] {
    CorrelativeOptions c;
    c.hit_field = true;
    return c;
  }();
  double range_noise_m = 0.02;
  // The local search's heading window grows by 3 x this x the odometry's turn in the step
  // (LocalizerOptions::turn_noise_per_rad: the heading noise per radian turned), its translation
  // window by 3 x drive_noise_per_m x the step's length. 0: fixed windows.
  double turn_noise_per_rad = 0.0;
  double drive_noise_per_m = 0.0;
  // Consecutive returns are one surface, joined in the field, when they lie closer than a surface
  // seen at this incidence (from the beam's direction) would space them, plus 3 range noises
  // (Borges & Aldon 2004's adaptive breakpoint): a wall's far returns are a line, not dots that a
  // scan taken from the previous pose would align with.
  double surface_min_incidence_rad = 0.1745;  // 10 degrees
  // What the robot can do between two scans (m/s^2, rad/s^2): odometry that departs from the last
  // step's velocity by more (beyond the search window) is an outlier.
  double max_acceleration = 2.0;
  double max_angular_acceleration = 5.0;
  // The search for such a scan prefers poses near the steady prediction (as CorrelativeOptions'
  // weights): along a corridor whose walls do not fix the position, the steady motion does.
  double relocalize_translation_weight = 1.0;
  double relocalize_rotation_weight = 1.0;
  // The local refinement pulls toward the odometry's translation by 10 per metre (Cartographer's)
  // only in the directions the scan leaves free, by 1 in those it fixes: at 10 everywhere a 5 cm
  // odometry error costs as much as the whole scan's misfit and the refinement returns a pose
  // between the odometry's and the scan's.
  RefineOptions local_refine = [] {
    RefineOptions r;
    r.fixed_translation_weight = 1.0;
    r.hit_field = true;
    return r;
  }();
  // Loop closures: searched for a fraction of the (node, finished submap) pairs closer than
  // max_constraint_distance_m, over the branch-and-bound window, refined with loop_refine. A pair's
  // chance to match falls with its distance (on MIT CSAIL a quarter of the searches within 3 m of
  // the submap's origin matched, 3 % of those 12-15 m apart, a third of all searches): 10 m, not
  // Cartographer's 15, keeps most closures for half the searches.
  BranchAndBoundOptions loop_search;
  int branch_and_bound_depth = 7;
  double loop_sampling_ratio = 0.1;
  double max_constraint_distance_m = 10.0;
  // A match is refused when the window holds a rival match farther than loop_rival_radius_m from
  // it that its points prefer by fewer than loop_rival_errors standard errors (score_advantage).
  double loop_rival_radius_m = 1.0;
  double loop_rival_errors = 2.0;
  RefineOptions loop_refine{20.0, 10.0, 1.0, 20};
  // The pose graph. Residuals are the constraint's error divided by its standard deviation
  // (weights in 1/m and 1/rad): local SLAM's motion between consecutive scans is sure to about
  // 5 mm and 0.0025 rad, a scan's match in a submap to 2 cm and 0.01 rad. A loop closure's residual
  // goes through a Huber loss of scale huber_scale (in standard deviations): a false match that
  // passed the rival check pulls with a bounded force, while the many true ones together close
  // loops that drifted metres (Cartographer's 10; on the training logs, MIT CSAIL and Intel, 5-10
  // and a consecutive weight of 200-800 score alike, 30 and 100 bend the local motion to fit
  // imprecise closures).
  double intra_translation_weight = 50.0, intra_rotation_weight = 100.0;
  double loop_translation_weight = 50.0, loop_rotation_weight = 100.0;
  double consecutive_translation_weight = 200.0, consecutive_rotation_weight = 400.0;
  double huber_scale = 10.0;
  int optimize_every_n_nodes = 90;
  int iterations = 10;        // per optimization while running
  int final_iterations = 100;
};

// A relative-pose constraint of the graph: the pose of node `node` in the frame of submap `submap`.
struct GraphConstraint {
  std::size_t submap = 0, node = 0;
  core::Pose2 relative;
  bool loop = false;  // found by the loop-closure search (robust loss), else the node was matched or inserted there
  double score = 0.0;
};

class GraphSlam {
 public:
  explicit GraphSlam(const GraphSlamOptions& options = {}, const core::Pose2& initial_pose = {});
  ~GraphSlam();
  GraphSlam(GraphSlam&&) noexcept;
  GraphSlam& operator=(GraphSlam&&) noexcept;

  // One scan, taken after the robot moved by `odometry` (in the previous scan's frame) since the
  // previous scan, `dt_s` seconds ago (0: unknown). Returns the scan's pose in the map frame as
  // known now.
  core::Pose2 add_scan(const core::Pose2& odometry, const mapping::RangeScan& scan, double dt_s = 0.0);
  // A last optimization with final_iterations; poses() is then the final answer.
  void finish();

  // Every scan's pose in the map frame (revised by every optimization).
  std::vector<core::Pose2> poses() const;
  std::size_t nodes() const;
  std::size_t submaps() const;
  std::size_t loop_closures() const;
  // Matches above the loop search's min_score refused for a rival elsewhere in the window.
  std::size_t rejected_loop_closures() const;
  std::size_t optimizations() const;
  // Scans whose odometry was an outlier: placed by a wider search around the steady motion, whose
  // match the scan preferred to the odometry's.
  std::size_t relocalized() const;
  const std::vector<GraphConstraint>& constraints() const;
  // change_frame: x_new = new_from_old * x_old for every pose held.
  void change_frame(const core::Pose2& new_from_old);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace fleetmap::localization
