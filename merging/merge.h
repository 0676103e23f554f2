#pragma once
// Aligning two occupancy grids when their relative pose is unknown, with a confidence and a
// refusal ("no reliable overlap") below a threshold: a wrong merge is worse than none.
//
// Methods propose candidate transforms; one common pipeline then refines every candidate
// (refine.h), scores it by how the two maps' walls fit (acceptance.h) and decides. Methods are
// members of an open registry (core/registry.h): the built-in `overlap` and `features`, and any a
// program adds with register_merge_method; "auto" runs them all in order.
//
// Transforms map b's cell coordinates (x = column, y = row from the bottom, cell centres at
// integers) into a's: a = R(theta) b + t. Both grids are taken to have the same cell size.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/random.h"
#include "core/registry.h"
#include "core/range.h"
#include "core/transform2.h"
#include "mapping/occupancy_grid.h"
#include "merging/acceptance.h"
#include "merging/feature_matching.h"
#include "merging/hypothesis.h"
#include "merging/overlap_search.h"
#include "merging/prepared_grid.h"
#include "merging/refine.h"

namespace fleetmap::merging {

// confidence = agreement factor * acceptance factor * (1 - 2^(-evidence * distinctiveness / half_evidence)):
// - agreement factor: the share of matched walls among matched + contradicting walls, mapped
//   linearly from zero_agreement (0) to full_agreement (1). Two robots' maps of one building
//   disagree on a few percent of their walls (drift, doors, glass); clutter never contradicts;
// - acceptance factor: the wave-algorithm paper's omega over all cells known in both maps, mapped linearly from
//   zero_acceptance (0) to full_acceptance (1): two maps laid edge to edge along a wall fit their
//   walls but not the cells beside them;
// - evidence: how many independent wall pieces pin the answer's weakest direction
//   (AlignmentQuality::constraint), each weighted by how much better than chance it fits:
//   ln(chance_rms / residual_rms), where residual_rms is the RMS distance of the walls that land
//   within the contradiction distance d of the other map's walls and chance_rms the same for walls
//   placed by chance (uniform within d: d / sqrt(3)), and residual_rms at least 0.2 cells (closer
//   is walls inside the other map's thick walls, not precision). Walls of identical maps coincide to a third
//   of a cell (weight ~1.7); two robots' maps with drift to 0.6-1 cell (~1), and then need more
//   walls in common; a chance fit of similar rooms lines walls up only roughly. So the bar rises
//   with the maps' noise instead of being a constant;
// - distinctiveness: 1 - S2 / S1, with S1 the best candidate's score and S2 the best score of a
//   plausible different answer (rotation off by more than distinct_rotation_deg, or displacement at
//   the overlap centre above distinct_distance cells). Repeated or symmetric places give ~0.
//   (Comparing evidence instead of scores raised right answers' confidences but merged two wrong
//   answers on the benchmark: large contradiction-free fits of similar houses.)
//   A different answer is plausible when its contradictions are what the best answer's own rate
//   (at least min_contradiction_rate) predicts: with z = (c - rate n) / sqrt(rate n + 1) over its n
//   tested walls, it counts fully for z <= 2 and not at all for z >= 4; and, as the answer, when
//   its cells agree with a's (its score times the acceptance factor below at its own omega): a
//   placement that lays free cells on occupied ones could not be merged and is no rival.
//   A rival cleaner than the answer's rate predicts (z <= -3) at whose own rate the answer's
//   contradictions are implausible (z >= 4), both over all their walls and over the part of b
//   that the rival lays on a's known cells, makes the distinctiveness 0: the maps cannot disagree
//   as the answer says and agree as the rival says, and a higher score does not tell which of two
//   placements that both fit many walls is right (a corridor slid by a row of door niches). Where
//   the answer is as clean as the rival on the rival's own part of b (drifted maps contradict
//   their right placement elsewhere), the rival says nothing against it, unless the answer lays a
//   wall group in a's open space (ConfidenceOptions::rival_cleaner_where_it_lies); such an answer
//   yields to a rival cleaner than its rate predicts even when its own contradictions are
//   plausible at the rival's rate (ConfidenceOptions::slid_answer_yields).
// - corner factor: the matched walls off the two straight lines that hold most of them
//   (AlignmentQuality::beyond_corner), 0 up to zero_beyond_corner, 1 from full_beyond_corner on
//   (4 x 4 blocks of wall, counted in both maps: a door jamb seen by both is two), plus the
//   matched wall ends (AlignmentQuality::wall_ends: an opening in a wall that both maps see
//   through, at the same place in both), plus a full set for a T or cross junction
//   (AlignmentQuality::junction_arms >= 3: one of the two walls goes on past where the other meets
//   it, in both maps): two maps whose common walls are one corner of a bare room fit any other
//   corner as well, and nothing in either map can tell (seen on a real plan: two corners of a
//   large hall, turned a quarter); an opening in one of the walls pins the corner along them, and
//   a bare room has no T. A T with nothing else is one more corner (ConfidenceOptions::refuse_lone_t).
// - one rectangular room (ConfidenceOptions::min_turned_share): its sides are four lines, and the
//   room turned a half turn fits them too; when the answer's common walls are such four lines and
//   the probes find a turned placement free of contradictions with at least that share of the
//   answer's evidence, the distinctiveness is 0: which of the two lays more of one map on the other
//   says nothing in a symmetric room.
// - one end of a bare hall (AlignmentQuality::beyond_end): when the common walls are two parallel
//   walls and one across them and nothing else (at most zero_beyond_corner blocks off those three
//   lines, no matched wall end), and neither map saw past the two parallel walls, the maps may show
//   the same end or the two ends of a longer hall, each reaching into the other's unknown: the
//   distinctiveness is 0. That second placement lays no wall on a wall, so no probe finds it.
// half_evidence: the evidence (times distinctiveness) at which the last factor is 0.5, set on the
// development benchmark of robot-built maps (bench/merging_real_bench.cpp) so that the default
// min_confidence accepts no wrong answer there; bench/README.md shows the reliability table.
// The symmetry probes run only on answers that could be merged (their confidence before the
// distinctiveness reaches min_confidence), so a confidence below the threshold is an upper bound,
// and a bar set by the best wrong answer below it was set by answers never probed: 13 was, by an
// unrelated pair of bare houses at 0.46 that the probes put at 0.18 (another placement fits
// nearly as well) and one at 0.45 that they refuse as one room. 9.5 is where the development sets
// still merge no wrong answer with the probes run on every answer that could be merged
// (bench/README.md, "The bar set by answers the probes never saw"); it merges right answers of
// small overlaps and corridors that 13 refused.
struct ConfidenceOptions {
  double zero_agreement = 0.85;
  double full_agreement = 0.95;
  double zero_acceptance = 0.93;
  double full_acceptance = 0.98;
  double half_evidence = 9.5;
  double zero_beyond_corner = 1.0;
  double full_beyond_corner = 4.0;
  double distinct_distance = 4.0;
  double distinct_rotation_deg = 2.0;
  double min_contradiction_rate = 0.005;
  // One rectangular room (0: off): when the matched walls lie on four lines (at most
  // zero_beyond_corner blocks off them) and a placement turned by 45 degrees or more fits as well
  // (its contradictions plausible at the answer's rate, or at most twice that rate, or its walls
  // agreeing as a merged answer's must and its evidence at least the answer's) with at least
  // this share of the answer's evidence ("nearly as well", as a distinctiveness below 0.5 reads),
  // the distinctiveness is 0. Seen in the simulator: two robots' maps of a bare rectangular hall
  // merged turned a half turn, 33 m off, at confidence 0.80; and of a small room in a house, 6 m
  // off at 0.52, where the right placement's walls agreed 86% and the answer's 92%; with scan
  // matching, 11.6 m off at 0.84, the drifted maps' right placement pinned more but rougher.
  double min_turned_share = 0.5;
  // Refuse an answer whose common walls are sides of one bare rectangular room
  // (AlignmentQuality::off_room_sides at most zero_beyond_corner, or outside_room at most
  // most_outside_room and room_details at most zero_beyond_corner; parallel_lines at most 2, no
  // wall_ends or common_openings, junction_arms below 3): they fix the room's size and nothing else.
  bool refuse_bare_room = true;
  // A T junction and nothing else (AlignmentQuality::junction_arms 3, fewer than full_beyond_corner
  // blocks off its two lines, no wall_ends or common_openings) counts as one corner: every inner
  // wall meets an outer one in a T, and any such junction fits it as well. Off, a T counts as a full
  // set of blocks beyond the corner, as a cross always does.
  bool refuse_lone_t = true;
  // A rival cleaner than the answer (above) is asked to be cleaner on its own part of b too: the
  // answer judged on the cells of b that the rival lays on a's known cells. Where the answer is as
  // clean there, the rival says nothing against it (two robots' maps that drifted apart contradict
  // their right placement in other places, and one corner of b laid elsewhere is clean). Not for
  // an answer with a wall group in a's open space (AlignmentQuality::open_space_walls at least
  // full_open_space): that is how a slid placement looks (a corridor slid by a row of door niches,
  // the end wall of one map across the other's corridor, 18 cells), and then the rival stands.
  // Off, a rival cleaner over all the walls is enough.
  bool rival_cleaner_where_it_lies = true;
  // An answer with a wall group in a's open space (open_space_walls at least full_open_space)
  // yields to any acceptable rival cleaner than its rate predicts (z <= -3), however plausible its
  // contradictions are at the rival's rate: they stand together where the maps' noise does not put
  // walls (drift lays walls a cell or three beside the other map's), not spread as noise is. Seen
  // in a test: a corridor slid by its row of door niches whose only contradictions are its end
  // wall across the other map's corridor (24 of 2190 walls, as many as min_contradiction_rate
  // expects), merged 18 m off at 0.67 over the clean truth. Off, such an answer is judged as any.
  bool slid_answer_yields = true;
  // One map saw the room alone: at most this share of its free cells lies beyond the room's sides.
  double most_outside_room = 0.02;
  // A wall in the other map's open space (AlignmentQuality::open_space_walls, the largest group): the
  // agreement factor is at most 1 up to full_open_space wall cells and 0 from zero_open_space on,
  // linear between. Right answers on the benchmark of robot-built maps and in the simulator: at
  // most 15 (a thin wall one robot's grazing beams saw through); windows of real laser maps at
  // most 3. Seen on a real laser map: a corridor whose wall has two identical pairs of niches 8 m
  // apart, one pair in each map, merged niche on niche at 0.79-0.96 with the end wall of one map's
  // corridor across the other's (28).
  double full_open_space = 16.0;
  double zero_open_space = 24.0;
};

// The confidences a threshold may be (the scenario's merging.min_confidence, merge --min-confidence).
inline constexpr core::Range kConfidenceRange{0, 1};

// Per merge method by name, the values given to its declared parameters (`--set features.ratio=0.7`).
using MergeMethodSettings = std::vector<std::pair<std::string, core::Settings>>;

struct MergeOptions {
  std::string method = "auto";   // a name of merge_method_names()
  MergeMethodSettings method_settings;  // for `method` and, under `auto`, the methods it runs
  double min_confidence = 0.5;   // below: not merged, "no reliable overlap"
  // A step's merge below this confidence does not end the search: the next step runs too, its
  // candidates join, and the higher confidence wins. A first step that missed the right rotation
  // can merge a wrong placement weakly (seen on a real laser map seen through 0.1 m cells: 29 m
  // off at 0.52, where the rotation sweep of the next step finds the truth at 0.999). The wrong
  // merges of the benchmark were at 0.52-0.62; checking merges up to 0.9 changed no decision
  // between 0.75 and 0.9 and cost a third of the time of a set of bare rooms. (Those were
  // confidences with half_evidence 13; the same evidence reads 0.85 with 9.5.)
  double sure_confidence = 0.85;
  bool refine = true;            // refine candidates to sub-cell accuracy (off: the methods' raw answers)
  // Candidates kept after the level where they enter, when it is level 2 or coarser, and besides them
  // each method's best proposal at that level (its own ranking, Hypothesis::score): a few steps on
  // coarse cells rank candidates roughly (seen on a real laser map: the rotation sweep's first and
  // right candidate ranked 33rd-40th of 73 on 8 x 8 cells). Twelve, not eight: on 4 x 4 cells a
  // large right fit with a few walls on the other map's free space (a ray fan, a door open in one
  // map) ranks below small exact fits of a wall or two (seen on real laser maps: the truth refined
  // from the spectral search's second candidate ranked tenth, 55 walls in and 3 out against 34 in
  // and none; a corridor's right placement ranked ninth among sixteen placements along it).
  int coarse_candidates = 12;
  int fine_candidates = 4;       // candidates kept after every other level (and taken to full resolution)
  int first_level_iterations = 4;  // refinement steps at the level where the candidates enter, when it is level 2 or coarser
  double sweep_step_deg = 4.0;   // `overlap`'s second pass: rotation sweep step
  int sweep_search_cells = 64;   // ... on a level this coarse (OverlapSearchOptions::search_cells)
  // Before merging, search for other placements (b turned by quarter turns from the answer, all
  // translations) so that symmetric or repeated places lower the distinctiveness whatever method
  // proposed the answer.
  bool probe_symmetries = true;
  // Run those probes on every answer with evidence, not only on answers that could be merged, so
  // that MergeResult::features are complete for every answer (the decision model's benchmark). The
  // decision is the same; a refused answer costs the probes' time.
  bool complete_features = false;
  std::uint64_t seed = 1;        // RANSAC sampling
  OverlapSearchOptions overlap;
  FeatureMatchingOptions features;
  RefineOptions refinement;
  QualityOptions quality;
  ConfidenceOptions confidence;
  PrepareOptions prepare;
};

// Why an answer was not merged: the weakest factor of the confidence (ConfidenceOptions), in the
// order `decide` names them; MergeResult::reason says the same in words.
enum class Refusal {
  None,               // merged
  NoCandidate,        // no method proposed a transform, or a map has no walls
  WallsCross,         // the walls of one map cross the other's free space (wall agreement)
  CellsDisagree,      // free in one, occupied in the other (acceptance)
  OneCorner,          // the common walls are one corner of a bare room
  OneRoom,            // the common walls are the sides of one rectangular room
  HallEnd,            // the common walls are one end of a bare hall, which its other end fits as well
  AnotherPlacement,   // another placement fits nearly as well (distinctiveness)
  FreeToSlide,        // the common walls leave the placement free to slide or turn (constraint)
  LittleFit,          // too little of the common walls fits better than chance
};

// What the decision saw, before its shape rules (ConfidenceOptions): quantities that mean the same
// on any map, for fitting and checking a decision model on pairs of known truth
// (bench/merging_model_bench.cpp).
struct DecisionFeatures {
  double distinctiveness = 0.0;  // 1 - S2 / S1 against the best plausible rival the search and probes found
  bool probed = false;           // the symmetry probes ran (the answer could be merged before them, or complete_features)
  // From MergeResult::covariance: the largest standard deviation of where b's points land at the
  // overlap centre (cells), and theta's (degrees).
  double largest_std_cells = 0.0;
  double theta_std_deg = 0.0;
  // The largest share of the answer's evidence that a plausible placement turned a quarter turn or
  // more from it reaches (a symmetric room fits itself turned).
  double turned = 0.0;
};

struct MergeResult {
  bool merged = false;            // confidence >= min_confidence
  core::Transform2 transform;     // b's cells into a's cells; the best candidate even when not merged
  // The covariance of transform's (tx, ty, theta), cells, cells and radians, from the fit of the
  // walls around it (fit_covariance in refine.h): how sure the answer is in which direction, as a
  // pose graph takes a match. nullopt without a candidate or with too few walls in common.
  std::optional<Eigen::Matrix3d> covariance;
  double acceptance = 0.0;        // omega of the wave-algorithm paper, at `transform`
  double confidence = 0.0;        // in [0, 1]
  double distinctiveness = 0.0;
  double evidence = 0.0;          // see ConfidenceOptions
  AlignmentQuality quality;
  // The best plausible different answer (what makes distinctiveness low), when there is one.
  std::optional<core::Transform2> alternative;
  std::string method;             // the method whose candidate won; empty when there was none
  std::string reason;             // why not merged; empty when merged
  Refusal refusal = Refusal::None; // the same, as a value
  int candidates = 0;             // candidates the methods proposed
  DecisionFeatures features;
};

// One pass of a method: proposes candidates for the common pipeline.
using ProposeFn = std::function<std::vector<Hypothesis>(const PreparedGrid& a, const PreparedGrid& b,
                                                        const MergeOptions& options, core::Random& random)>;
// A method runs its passes in order, each adding candidates, until the decision is to merge.
using MergePasses = std::vector<ProposeFn>;
// What a registered method runs: steps, each a list of passes whose candidates are then decided on;
// the search stops at a sure merge. Made when a merge starts, from the method's own parameters'
// values and, for `auto`, which runs the other methods, every method's settings.
using MergeSteps = std::vector<std::vector<ProposeFn>>;
using MergeMethod = std::function<MergeSteps(const core::Params& own, const MergeMethodSettings& all)>;

// Every merge method by name: auto, grid, features, then the registered ones. `auto` is the first
// pass of the first other method (grid's spectral search), then, when that is not confident, every
// other method's passes in the order registered and the first method's remaining passes.
core::Registry<MergeMethod>& merge_method_registry();
// Adds a method that `merge --method`, the `overlap` aligner's `method` and `auto` then use, one
// step per pass. Throws Error for an empty or taken name, or no passes.
void register_merge_method(std::string name, std::string help, MergePasses passes);
// The same for a method with parameters of its own (core/params.h): `make` gets their values
// (`merge --set NAME.KEY=VALUE`, MergeOptions::method_settings) and returns the passes.
void register_merge_method(std::string name, std::string help, std::function<MergePasses(const core::Params&)> make,
                           std::vector<core::ParamSpec> params);
// The registry's names, for --help and errors.
std::vector<std::string> merge_method_names();
// One line per name: "  name: help", and its parameters.
std::string merge_method_help();
// Throws InputError unless `name` is one of merge_method_names() (naming the valid ones) and each
// of `settings` is for a method that `name` runs (itself, or any under `auto`) and declared by it.
void check_merge_method(const std::string& name, const MergeMethodSettings& settings = {});

// A map cut to the box of its known cells (with a margin), so that the search does not pay for
// the unknown around what a robot saw (a robot's map is often allocated far larger). The cut's
// cells lie where they lay in the map's frame (its geometry's origin is moved with the box).
class KnownPart {
 public:
  explicit KnownPart(const mapping::OccupancyGrid& grid, int margin = 2);
  const mapping::OccupancyGrid& grid() const { return cut_ ? *cut_ : *full_; }
  // The cut's cell (0, 0) in the full map's cells.
  const Eigen::Vector2i& origin() const { return origin_; }

 private:
  const mapping::OccupancyGrid* full_;
  std::optional<mapping::OccupancyGrid> cut_;
  Eigen::Vector2i origin_ = Eigen::Vector2i::Zero();
};

// A result between two cuts, expressed between the full maps' cells.
MergeResult uncut(MergeResult result, const KnownPart& a, const KnownPart& b);

// Aligns b to a. Never throws for hard inputs (no walls, no overlap): the result says why it did
// not merge. Throws InputError for an unknown method name, and for maps of different resolutions
// (cells are compared one to one: mapping::resample one map to the other's cells first).
MergeResult align_maps(const mapping::OccupancyGrid& a, const mapping::OccupancyGrid& b,
                       const MergeOptions& options = {});
// The same on grids prepared once (N-map merging prepares each map once for all its pairs), with
// prepare_options(options) or a larger max_wall_distance: throws InputError for a smaller one.
MergeResult align_prepared(const PreparedGrid& a, const PreparedGrid& b, const MergeOptions& options = {});

// The PrepareOptions::max_wall_distance that `options` need: the largest wall distance they compare
// (match, contradiction, refinement) and 1.5 cells more, since a distance read between cell
// centres mixes four cells up to 1.42 cells apart in distance; and at least
// QualityOptions::open_space_distance (a wall is that far or more: the capped distance tells).
double needed_wall_distance(const MergeOptions& options);
// options.prepare with max_wall_distance raised to needed_wall_distance(options) where it is less.
PrepareOptions prepare_options(const MergeOptions& options);

// The common pipeline on given candidates: refine, score, decide.
MergeResult decide(const PreparedGrid& a, const PreparedGrid& b, const std::vector<Hypothesis>& candidates,
                   const MergeOptions& options);

}  // namespace fleetmap::merging
