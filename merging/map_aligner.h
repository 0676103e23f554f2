#pragma once
// How a robot brings a teammate's map into its own map frame before they share maps: the
// simulator's `merging:` modes, one interface for every way of finding the transform.
//   known       every robot knows its start in one shared frame: nothing to align;
//   none        every robot maps alone in its own frame and never takes another's map;
//   rendezvous  both robots detect each other and exchange poses and readings (D'Alfonso et al.
//               2013, §3.2);
//   overlap     the two occupancy grids are searched for their best overlap (merge.h, the
//               methods of `fleetmap merge`), accepted from a confidence on (its parameters:
//               method, min_confidence);
//   landmarks   the two robots' landmark maps are associated by RANSAC (the map-alignment
//               paper, §III.A, eq. (2)-(6)); robots that estimate landmarks (`ekf-slam`);
//               its parameters: min_confidence, support_distance.
// A program that links fleetmap adds its own aligner with register_map_aligner; scenarios and
// `--merging` then reach it by name like the built-in ones.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/registry.h"
#include "core/transform2.h"
#include "localization/localizer.h"
#include "mapping/occupancy_grid.h"
#include "merging/merge.h"
#include "merging/rendezvous.h"

namespace fleetmap::merging {

// What two robots that can talk know when they try to align their frames. Everything is in each
// robot's own map frame (metres).
struct AlignmentRequest {
  const mapping::OccupancyGrid* receiver_map = nullptr;
  const mapping::OccupancyGrid* sender_map = nullptr;
  core::Pose2 receiver_pose, sender_pose;  // the robots' estimates
  // When both detect each other this step: what each measured of the other ("self" = receiver).
  std::optional<MutualObservation> detection;
  std::vector<localization::Landmark> receiver_landmarks, sender_landmarks;  // estimated, may be empty
  std::uint64_t seed = 1;
};

struct FrameAlignment {
  bool attempted = false;  // false: nothing to try yet (e.g. no rendezvous); not recorded
  bool merged = false;
  core::Transform2 sender_to_receiver;  // metres, sender's map frame into the receiver's (merged only)
  std::string method;                   // what found it, e.g. "rendezvous" or a merge method
  double confidence = 0.0;
  std::string reason;                   // why not merged
  std::int64_t bytes_sent = 0;          // what the robots sent each other for the attempt
};

class MapAligner {
 public:
  virtual ~MapAligner() = default;
  // True for robots that share one frame from the start (nothing is ever aligned).
  virtual bool shared_frame() const { return false; }
  // True when attempts need a search worth rate-limiting (the simulator tries a pair at most every
  // `attempt_every` steps).
  virtual bool costly() const { return false; }
  // The sender's whole map goes along with the attempt (the simulator counts the bytes).
  virtual bool sends_map() const { return false; }
  // True when the aligner works on the robots' estimated landmarks (AlignmentRequest's
  // *_landmarks), so that the robots' localizer must estimate some.
  virtual bool needs_landmark_estimates() const { return false; }
  virtual FrameAlignment align(const AlignmentRequest& request) const = 0;
  // The merge methods' own parameters (MergeOptions::method_settings), for an aligner that runs
  // merge methods. Throws InputError for settings it cannot use: by default any, since it runs none.
  virtual void set_merge_methods(const MergeMethodSettings& settings);
};

// Makes an aligner from its declared parameters' values.
using MapAlignerFactory = std::function<std::unique_ptr<MapAligner>(const core::Params&)>;

// The built-in aligners (known, none, rendezvous, overlap, landmarks) and any registered since.
core::Registry<MapAlignerFactory>& map_aligner_registry();
// Adds an aligner under `name` (Error if the name is taken or unusable), with the parameters it
// accepts (core/params.h).
void register_map_aligner(std::string name, std::string help, MapAlignerFactory make,
                          std::vector<core::ParamSpec> params = {});
// The aligner's declared parameters with `settings` applied; throws InputError for an unknown name
// (naming the valid ones), a setting it does not declare or a value it refuses.
core::Params map_aligner_options(const std::string& name, const core::Settings& settings = {});
// Throws as map_aligner_options, and InputError for a merge method the overlap aligner does not know
// or merge-method settings it does not run (MapAligner::set_merge_methods).
std::unique_ptr<MapAligner> make_map_aligner(const std::string& name, const core::Settings& settings = {},
                                             const MergeMethodSettings& merge_methods = {});

}  // namespace fleetmap::merging
