#include "merging/merge.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "core/angle.h"
#include "core/error.h"
#include "core/format.h"
#include "mapping/state_mask.h"
#include "merging/evaluation.h"
#include "merging/grid_level.h"

namespace fleetmap::merging {

namespace {

std::vector<Hypothesis> propose_overlap(const PreparedGrid& a, const PreparedGrid& b, const MergeOptions& options,
                                        core::Random&) {
  return overlap_hypotheses(a, b, options.overlap);
}

std::vector<Hypothesis> propose_overlap_sweep(const PreparedGrid& a, const PreparedGrid& b, const MergeOptions& options,
                                              core::Random&) {
  OverlapSearchOptions sweep = options.overlap;
  sweep.sweep_step_deg = options.sweep_step_deg;
  sweep.search_cells = options.sweep_search_cells;
  return overlap_hypotheses(a, b, sweep);
}

std::vector<Hypothesis> propose_features(const PreparedGrid& a, const PreparedGrid& b, const MergeOptions& options,
                                         core::Random& random) {
  return feature_hypotheses(a, b, options.features, random);
}

// Two placements of b turned from each other by more than 45 degrees: another turn of a symmetric
// place (a room's quarter or half turn), not a variant of one placement.
bool turned_apart(const core::Transform2& x, const core::Transform2& y) {
  return std::abs(core::normalize_angle(x.rotation() - y.rotation())) > std::numbers::pi / 4.0;
}

bool same_answer(const core::Transform2& x, const core::Transform2& y, const Eigen::Vector2d& at_b,
                 const ConfidenceOptions& options) {
  const double dtheta = std::abs(core::rad2deg(core::normalize_angle(x.rotation() - y.rotation())));
  return dtheta <= options.distinct_rotation_deg && (x.apply(at_b) - y.apply(at_b)).norm() <= options.distinct_distance;
}

struct Candidate {
  Hypothesis hypothesis;
  LevelFit fit;
  bool leader = false;  // its method's best proposal at its level (refine_candidates)
};

// Keeps the best-scoring of near-identical candidates, best first, at most `keep`, and also the
// fit with the most walls in common among those whose walls agree as well as a merged answer's
// must (ConfidenceOptions::zero_agreement), when it is not one of them. The score weighs a wall on
// the other map's free space ten times, and at the coarse levels a stretch of wall that one map
// lost (grazing beams see through a thin wall) is a run of such walls: a large right fit then
// ranked below placements that fit almost nothing, and was dropped (seen in the simulator: two
// robots' maps of a house, the right fit 254 walls in and 26 out at the search level, and the pair
// merged with the room they shared turned a half turn). The full resolution judges it.
// One such fit per turn: the largest agreeing fit, then the largest turned by more than 45 degrees
// from it, and so on. A symmetric place has a large agreeing fit at each of its turns, and the
// right one may be the smaller: seen in the simulator, two robots' maps of a rectangular hall, the
// wrong placement turned a half turn 525 walls in and 58 out at full resolution, the right one
// 356 in and 26 out (twice the score), but 216 in and 36 out on cells of two, where it ranked last
// and went, and the pair merged 10 m off (min_confidence 0.4 on the old scale of the confidence);
// the symmetry probes, pruned the same way, did not see it.
void prune(std::vector<Candidate>& c, const PreparedGrid& b, const ConfidenceOptions& options, std::size_t keep,
           bool keep_leaders) {
  std::sort(c.begin(), c.end(), [](const Candidate& x, const Candidate& y) { return x.fit.score > y.fit.score; });
  const Eigen::Vector2d centre_b((b.width() - 1) / 2.0, (b.height() - 1) / 2.0);
  std::vector<std::size_t> agreeing;
  for (std::size_t i = 0; i < c.size(); ++i) {
    const LevelFit& f = c[i].fit;
    if (f.inliers > 0 && f.inliers >= options.zero_agreement * (f.inliers + f.outliers)) agreeing.push_back(i);
  }
  std::stable_sort(agreeing.begin(), agreeing.end(),
                   [&](std::size_t i, std::size_t j) { return c[i].fit.inliers > c[j].fit.inliers; });
  std::vector<std::size_t> largest;  // the largest agreeing fit of each turn
  for (const std::size_t i : agreeing) {
    const bool new_turn = std::all_of(largest.begin(), largest.end(), [&](std::size_t j) {
      return turned_apart(c[i].fit.b_to_a, c[j].fit.b_to_a);
    });
    if (new_turn) largest.push_back(i);
  }
  std::vector<Candidate> kept;
  const auto keep_unless_dup = [&](Candidate& x) {
    for (const auto& k : kept)
      if (same_answer(x.fit.b_to_a, k.fit.b_to_a, centre_b, options)) return;
    kept.push_back(std::move(x));
  };
  std::size_t next = 0;
  for (; next < c.size() && kept.size() < keep; ++next) keep_unless_dup(c[next]);
  // Those below `next` are kept already, or were duplicates of better ones.
  for (const std::size_t i : largest)
    if (i >= next) keep_unless_dup(c[i]);
  if (keep_leaders) {
    for (std::size_t i = next; i < c.size(); ++i)
      if (c[i].leader && std::find(largest.begin(), largest.end(), i) == largest.end()) keep_unless_dup(c[i]);
  }
  c = std::move(kept);
}

double clamp01(double v) { return std::clamp(v, 0.0, 1.0); }

// b's cells that b_to_a lays on known cells of a, grown by `margin` cells, as a mask of b's cells.
cv::Mat common_mask(const PreparedGrid& a, const PreparedGrid& b, const core::Transform2& b_to_a, int margin) {
  const GridLevel& la = a.level(0);
  const GridLevel& lb = b.level(0);
  cv::Mat mask = cv::Mat::zeros(lb.height(), lb.width(), CV_8U);
  const Eigen::Matrix2d r = b_to_a.rotation_matrix();
  const Eigen::Vector2d t = b_to_a.translation();
  for (int y = 0; y < lb.height(); ++y) {
    auto* m = mask.ptr<std::uint8_t>(y);
    const Eigen::Vector2d start = r * Eigen::Vector2d(0.0, y) + t, step = r.col(0);
    for (int x = 0; x < lb.width(); ++x) {
      if (!lb.known(x, y)) continue;
      const Eigen::Vector2d p = start + double(x) * step;
      const int ax = nearest_cell(p.x()), ay = nearest_cell(p.y());
      if (ax >= 0 && ay >= 0 && ax < la.width() && ay < la.height() && la.known(ax, ay)) m[x] = 255;
    }
  }
  if (margin > 0) cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * margin + 1, 2 * margin + 1}));
  return mask;
}

// Coarse to fine: every candidate joins at its level; after each level near-duplicates go and only
// the best few go on.
std::vector<Candidate> refine_candidates(const PreparedGrid& a, const PreparedGrid& b,
                                         const std::vector<Hypothesis>& candidates, const MergeOptions& options) {
  std::vector<Candidate> active;
  if (!options.refine) {
    for (const auto& h : candidates) active.push_back({h, LevelFit{h.b_to_a, 0, 0, 0.0}});
    return active;
  }
  const int top = std::min(a.level_count(), b.level_count()) - 1;
  int start = 0;
  for (const auto& h : candidates) start = std::max(start, std::min(h.level, top));
  // Each method's best proposal at each level (the first of equals): what its own search ranks first.
  std::vector<std::size_t> best;  // one index per (method, level)
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const Hypothesis& h = candidates[i];
    const auto group = std::find_if(best.begin(), best.end(), [&](std::size_t j) {
      return candidates[j].level == h.level && candidates[j].method == h.method;
    });
    if (group == best.end()) best.push_back(i);
    else if (h.score > candidates[*group].score) *group = i;
  }
  std::vector<bool> leader(candidates.size(), false);
  for (std::size_t i : best) leader[i] = true;
  for (int k = start; k >= 0; --k) {
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      const auto& h = candidates[i];
      if (std::min(h.level, top) == k) active.push_back({h, LevelFit{h.b_to_a, 0, 0, 0.0}, leader[i]});
    }
    // Many candidates enter at the top level; on coarse cells a few steps there are enough to rank
    // them roughly, and more go on from there than from the finer levels. On cells of one or two
    // fine cells a candidate is several cells off and takes all the steps (seen on the benchmark: a
    // house pair searched on cells of 2 x 2 merged 2.6 cells off after four steps, right after ten).
    const bool rough = k == start && k >= 2;
    RefineOptions level_options = options.refinement;
    if (rough) level_options.iterations = std::min(level_options.iterations, options.first_level_iterations);
    for (auto& c : active) c.fit = refine_at_level(a, b, c.fit.b_to_a, k, level_options);
    prune(active, b, options.confidence, std::size_t(rough ? options.coarse_candidates : options.fine_candidates), rough);
  }
  return active;
}

}  // namespace

namespace {

// The settings given to method `name` (none when it has none).
core::Settings settings_of(const MergeMethodSettings& all, const std::string& name) {
  core::Settings out;
  for (const auto& [method, settings] : all) {
    if (method == name) out.insert(out.end(), settings.begin(), settings.end());
  }
  return out;
}

// Method `name`'s steps, built from its settings among `all`.
MergeSteps method_steps(const core::Registry<MergeMethod>& registry, const std::string& name, const MergeMethodSettings& all) {
  return registry.get(name).make(registry.configure(name, settings_of(all, name)), all);
}

// The steps of `auto`: the first other method's first pass, then every other method's passes, then
// the first method's remaining passes.
MergeSteps auto_steps(const core::Registry<MergeMethod>& registry, const MergeMethodSettings& all) {
  std::vector<MergePasses> methods;  // each other method's passes, in order
  for (const auto& name : registry.names()) {
    if (name == "auto") continue;
    MergePasses passes;
    for (const auto& step : method_steps(registry, name, all)) passes.insert(passes.end(), step.begin(), step.end());
    methods.push_back(std::move(passes));
  }
  MergeSteps steps(2);
  if (methods.empty() || methods.front().empty()) return {};
  steps[0].push_back(methods.front().front());
  for (std::size_t i = 1; i < methods.size(); ++i) steps[1].insert(steps[1].end(), methods[i].begin(), methods[i].end());
  steps[1].insert(steps[1].end(), methods.front().begin() + 1, methods.front().end());
  if (steps[1].empty()) steps.pop_back();
  return steps;
}

// One step per pass.
MergeSteps in_steps(const MergePasses& passes) {
  MergeSteps steps;
  for (const auto& pass : passes) steps.push_back({pass});
  return steps;
}

// `pass` run with the options `apply` sets from a method's own parameters.
ProposeFn with_options(ProposeFn pass, std::function<void(MergeOptions&)> apply) {
  return [pass = std::move(pass), apply = std::move(apply)](const PreparedGrid& a, const PreparedGrid& b,
                                                             const MergeOptions& options, core::Random& random) {
    MergeOptions own = options;
    apply(own);
    return pass(a, b, own, random);
  };
}

// The grid search's parameters; the defaults are MergeOptions' own.
std::vector<core::ParamSpec> grid_params() {
  using core::ParamSpec;
  const MergeOptions d;
  const core::Range cells{16, 4096, true};
  return {
      ParamSpec::number("search_cells", d.overlap.search_cells, cells, "cells",
                        "the translation search runs on the finest level whose larger side is at most this"),
      ParamSpec::number("spectrum_peaks", d.overlap.spectrum_peaks, {1, 64, true}, "",
                        "rotations kept from the Hough spectra's correlation (each also turned by 180 degrees)"),
      ParamSpec::number("translation_peaks", d.overlap.translation_peaks, {1, 256, true}, "",
                        "correlation maxima kept per rotation (repeated places give several)"),
      ParamSpec::number("sweep_step_deg", d.sweep_step_deg, {0.25, 90.0}, "deg",
                        "the second pass's rotation sweep step, run when the spectra find nothing reliable"),
      ParamSpec::number("sweep_search_cells", d.sweep_search_cells, cells, "cells",
                        "the sweep's translation search level, as search_cells"),
  };
}

void apply_grid(const core::Params& p, MergeOptions& o) {
  o.overlap.search_cells = int(p.number("search_cells"));
  o.overlap.spectrum_peaks = int(p.number("spectrum_peaks"));
  o.overlap.translation_peaks = int(p.number("translation_peaks"));
  o.sweep_step_deg = p.number("sweep_step_deg");
  o.sweep_search_cells = int(p.number("sweep_search_cells"));
}

// Feature matching's parameters; the defaults are FeatureMatchingOptions' own.
std::vector<core::ParamSpec> feature_params() {
  using core::ParamSpec;
  const FeatureMatchingOptions d;
  return {
      ParamSpec::text("detectors", d.detectors.size() == 2 ? "both" : d.detectors.front(), {"orb", "akaze", "both"},
                      "keypoint detectors: AKAZE finds a few more matches on large smooth maps at ten times ORB's time"),
      ParamSpec::number("max_features", d.max_features, {10, 100000, true}, "", "ORB's keypoint budget per image"),
      ParamSpec::number("ratio", d.ratio, {0.05, 1.0}, "", "Lowe's ratio test on the two nearest descriptors"),
      ParamSpec::number("inlier_distance", d.inlier_distance, {0.1, 100.0}, "cells", "RANSAC inlier distance"),
      ParamSpec::number("ransac_iterations", d.ransac_iterations, {10, 1e6, true}, "", "RANSAC iterations per model"),
      ParamSpec::number("min_inliers", d.min_inliers, {3, 10000, true}, "", "inliers a model needs to be proposed"),
  };
}

void apply_features(const core::Params& p, MergeOptions& o) {
  const std::string& d = p.text("detectors");
  o.features.detectors = d == "both" ? std::vector<std::string>{"orb", "akaze"} : std::vector<std::string>{d};
  o.features.max_features = int(p.number("max_features"));
  o.features.ratio = p.number("ratio");
  o.features.inlier_distance = p.number("inlier_distance");
  o.features.ransac_iterations = int(p.number("ransac_iterations"));
  o.features.min_inliers = int(p.number("min_inliers"));
}

// A method from passes made of its own parameters.
MergeMethod from_passes(std::function<MergePasses(const core::Params&)> make) {
  return [make = std::move(make)](const core::Params& own, const MergeMethodSettings&) { return in_steps(make(own)); };
}

void add_builtin_methods(core::Registry<MergeMethod>& registry) {
  registry.add("auto",
               "grid's spectral pass; if not confident, the other methods and grid's sweep too; the best wins",
               [](const core::Params&, const MergeMethodSettings& all) { return auto_steps(merge_method_registry(), all); });
  registry.add("grid",
               "grid overlap search (wave-algorithm paper, Birk & Carpin 2006): Hough-spectrum rotations (Carpin "
               "2008), FFT correlation of walls for translations, coarse to fine; a rotation sweep when the spectra "
               "find nothing",
               from_passes([](const core::Params& p) {
                 const auto apply = [p](MergeOptions& o) { apply_grid(p, o); };
                 return MergePasses{with_options(propose_overlap, apply), with_options(propose_overlap_sweep, apply)};
               }),
               grid_params());
  registry.add("features", "ORB keypoints, ratio test, rigid RANSAC (the common ROS merger's approach)",
               from_passes([](const core::Params& p) {
                 return MergePasses{with_options(propose_features, [p](MergeOptions& o) { apply_features(p, o); })};
               }),
               feature_params());
}

}  // namespace

core::Registry<MergeMethod>& merge_method_registry() {
  static core::Registry<MergeMethod> registry("merge method");
  static const bool built_in = (add_builtin_methods(registry), true);
  (void)built_in;
  return registry;
}

void register_merge_method(std::string name, std::string help, std::function<MergePasses(const core::Params&)> make,
                           std::vector<core::ParamSpec> params) {
  if (!make) throw Error("register merge method: '" + name + "' needs a function that makes its passes");
  merge_method_registry().add(
      name, std::move(help),
      from_passes([name, make = std::move(make)](const core::Params& p) {
        MergePasses passes = make(p);
        if (passes.empty() || std::any_of(passes.begin(), passes.end(), [](const ProposeFn& f) { return !f; })) {
          throw Error("merge method '" + name + "' made no passes, or an empty one");
        }
        return passes;
      }),
      std::move(params));
}

void register_merge_method(std::string name, std::string help, MergePasses passes) {
  if (passes.empty() || std::any_of(passes.begin(), passes.end(), [](const ProposeFn& f) { return !f; })) {
    throw Error("register merge method: '" + name + "' needs at least one pass, and no empty one");
  }
  register_merge_method(std::move(name), std::move(help), [passes](const core::Params&) { return passes; }, {});
}

std::vector<std::string> merge_method_names() { return merge_method_registry().names(); }

std::string merge_method_help() { return merge_method_registry().help(); }

void check_merge_method(const std::string& name, const MergeMethodSettings& settings) {
  // The grid search was called "overlap" before the simulator's `overlap` aligner used the name.
  if (name == "overlap") throw InputError("merge method 'overlap' is now called 'grid' (valid: " + core::join(merge_method_names()) + ")");
  const auto& registry = merge_method_registry();
  registry.get(name);  // InputError naming the valid ones
  for (const auto& [method, given] : settings) {
    registry.get(method);
    if (given.empty()) continue;
    if (method != name && name != "auto") {
      throw InputError("merge method '" + name + "' does not run '" + method + "', so its parameters do not apply (only auto runs every method)");
    }
  }
  for (const auto& method : registry.names()) {
    if (method == name || name == "auto") registry.configure(method, settings_of(settings, method));
  }
}

namespace {

using Placements = std::vector<std::pair<AlignmentQuality, core::Transform2>>;

// `known` and the placements of b in a found by the overlap search at the four quarter turns of
// `answer`, each refined and scored.
Placements other_placements(const PreparedGrid& a, const PreparedGrid& b, const core::Transform2& answer,
                            const MergeOptions& options, Placements known) {
  std::vector<double> turns;
  for (int k = 0; k < 4; ++k) turns.push_back(answer.rotation() + k * std::numbers::pi / 2.0);
  OverlapSearchOptions probe = options.overlap;
  probe.translation_peaks = 4;
  QualityOptions fit_only = options.quality;
  fit_only.shape = false;
  // Each turn's best proposal by the search's own ranking goes on from the coarse level where they
  // enter (as a method's best does: refine_candidates): there a wall on the other map's free space
  // weighs ten, and a rival that the full resolution scores higher than the answer may rank last
  // (the hall of prune's comment). The finer levels keep each turn's largest agreeing fit.
  std::vector<Hypothesis> proposals = overlap_hypotheses_at(a, b, turns, probe);
  for (auto& h : proposals) {
    const double from_answer = core::normalize_angle(h.b_to_a.rotation() - answer.rotation());
    h.method = "probe, turn " + std::to_string(int(std::lround(from_answer / (std::numbers::pi / 2.0)) + 4) % 4);
  }
  for (const auto& c : refine_candidates(a, b, proposals, options))
    known.emplace_back(evaluate_alignment(a, b, c.fit.b_to_a, fit_only), c.fit.b_to_a);
  return known;
}

// Options that would leave no candidate to decide on, or search nothing.
void check_search_options(const MergeOptions& options) {
  const auto at_least = [](const char* name, double value, double least) {
    if (!(value >= least)) throw InputError(fmt::format("merge options: {} must be at least {} (got {})", name, least, value));
  };
  at_least("coarse_candidates", options.coarse_candidates, 1);
  at_least("fine_candidates", options.fine_candidates, 1);
  at_least("first_level_iterations", options.first_level_iterations, 0);
  at_least("overlap.search_cells", options.overlap.search_cells, 1);
  at_least("sweep_search_cells", options.sweep_search_cells, 1);
  // A shorter stretch would count the gap between two neighbouring walls as a door.
  if (!(options.quality.min_opening_m > 0.0))
    throw InputError(fmt::format("merge options: quality.min_opening_m must be greater than 0 (got {})",
                                 options.quality.min_opening_m));
  if (!(options.confidence.zero_open_space > options.confidence.full_open_space))
    throw InputError(fmt::format("merge options: confidence.zero_open_space ({}) must be greater than full_open_space ({})",
                                 options.confidence.zero_open_space, options.confidence.full_open_space));
}

}  // namespace

MergeResult decide(const PreparedGrid& a, const PreparedGrid& b, const std::vector<Hypothesis>& candidates,
                   const MergeOptions& options) {
  check_search_options(options);
  MergeResult result;
  result.candidates = int(candidates.size());
  if (candidates.empty()) {
    result.reason = "no reliable overlap: no candidate transform";
    result.refusal = Refusal::NoCandidate;
    return result;
  }
  std::vector<Candidate> active = refine_candidates(a, b, candidates, options);
  // Score the survivors at full resolution; the best one is the answer.
  // The shape of the common walls counts for the answer only (below).
  QualityOptions fit_only = options.quality;
  fit_only.shape = false;
  std::vector<std::pair<AlignmentQuality, const Candidate*>> scored;
  for (const auto& c : active) scored.emplace_back(evaluate_alignment(a, b, c.fit.b_to_a, fit_only), &c);
  std::sort(scored.begin(), scored.end(), [](const auto& x, const auto& y) { return x.first.score > y.first.score; });
  // The answer: the best-scoring survivor whose cells agree with the other map (the wave-algorithm
  // paper's acceptance index, Birk & Carpin 2006, at least ConfidenceOptions::zero_acceptance). The
  // wall score does not see free cells of one map on filled obstacles or thick walls of the other; a
  // placement that lays many of them would be refused anyway, and a smaller placement that agrees
  // is then the better answer.
  std::vector<double> omega(scored.size(), -1.0);
  std::size_t pick = 0;
  for (std::size_t i = 0; i < scored.size(); ++i) {
    omega[i] = acceptance_index(a.grid(), b.grid(), scored[i].second->fit.b_to_a).omega();
    if (omega[i] >= options.confidence.zero_acceptance) {
      pick = i;
      break;
    }
  }
  if (omega[pick] < options.confidence.zero_acceptance) pick = 0;
  std::rotate(scored.begin(), scored.begin() + std::ptrdiff_t(pick), scored.begin() + std::ptrdiff_t(pick) + 1);
  scored.front().first = evaluate_alignment(a, b, scored.front().second->fit.b_to_a, options.quality);
  const auto& [best_q, best] = scored.front();
  result.transform = best->fit.b_to_a;
  result.covariance = fit_covariance(a, b, result.transform, options.refinement);
  result.method = best->hypothesis.method;
  result.quality = best_q;
  result.acceptance = omega[pick];

  const auto& co = options.confidence;
  const double wall_agreement = clamp01((best_q.agreement - co.zero_agreement) / (co.full_agreement - co.zero_agreement));
  const double open_space_factor =
      clamp01((co.zero_open_space - best_q.open_space_walls) / (co.zero_open_space - co.full_open_space));
  const double agree_factor = std::min(wall_agreement, open_space_factor);
  const auto acceptance_factor_of = [&](double omega) {
    return clamp01((omega - co.zero_acceptance) / (co.full_acceptance - co.zero_acceptance));
  };
  const double acceptance_factor = acceptance_factor_of(result.acceptance);
  const double chance_rms = options.quality.contradiction_distance / std::sqrt(3.0);
  // A grid places a wall no closer than about a fifth of a cell: walls that land closer to the
  // other map's walls than that land inside its thick walls (distance 0 within an occupied band,
  // as real laser maps draw walls 2-3 cells thick), which says nothing more about the placement
  // (seen on a real map: a corridor placed 2.6 cells off along its thick walls fitted at RMS
  // 0.001 cells and was merged at confidence 0.54).
  constexpr double kTightestRms = 0.2;
  // How many wall cells' worth pin a placement, each weighted by how much better than chance it
  // fits. A turned placement of one room is compared with the answer by this measure (below), not
  // by wall counts: in a symmetric room the answer may lay more of one map on the other and still
  // be the wrong one of two equally tight fits.
  const auto evidence_of = [&](const AlignmentQuality& q) {
    return q.matched > 0 ? q.constraint * std::max(0.0, std::log(chance_rms / std::max(q.residual_rms, kTightestRms))) : 0.0;
  };
  result.evidence = evidence_of(best_q);
  const auto support = [&](double evidence) { return 1.0 - std::exp2(-evidence / co.half_evidence); };

  // A placement's rate of walls on the other map's free space (at least min_contradiction_rate),
  // and how far `contradicted` of `tested` walls lie from what a rate predicts, in standard deviations.
  const auto contradiction_rate = [&](const AlignmentQuality& q) {
    return std::max(co.min_contradiction_rate, (q.contradicted + 1.0) / (q.matched + q.contradicted + 2.0));
  };
  const auto contradiction_z = [](double contradicted, double tested, double rate) {
    return (contradicted - rate * tested) / std::sqrt(rate * tested + 1.0);
  };
  // The best plausible different answer among `others` (placements of `from` in a), relative to
  // the answer's score `best` there: 1 - S2 / S1.
  const double rate = contradiction_rate(best_q);
  // Also the largest share of the best score that a plausible placement turned by a quarter turn or
  // more from the answer reaches (`turned`).
  double turned = 0.0;
  const auto distinctiveness = [&](const PreparedGrid& from, const Placements& others,
                                   const AlignmentQuality& best, const core::Transform2& answer) {
    const Eigen::Vector2d at = answer.inverse().apply(best.overlap_centre);
    const double own = evidence_of(best);
    double second = 0.0;
    std::optional<core::Transform2> alternative, cleaner;
    for (const auto& [q, t] : others) {
      if (same_answer(t, answer, at, co)) continue;
      const double n = q.matched + q.contradicted;
      const double z = contradiction_z(q.contradicted, n, rate);
      // A rival too clean for the answer's rate whose own rate makes the answer's contradictions
      // implausible: the maps cannot disagree as the answer says and agree as the rival says, so
      // one of two placements that both fit many walls is wrong, and no score tells which (seen
      // on a real laser map: a corridor with regularly spaced door niches placed 8 m off along
      // it, 1304 walls matched and 65 on free space, merged at 0.56 over the truth's 413 matched
      // and none on free space).
      // Cleaner on the same cells: the answer judged on the part of `from` that the rival lays on
      // a's known cells. Where the answer is as clean there, the rival's cleanliness says nothing
      // against it: two robots' maps that drifted apart contradict their right placement here and
      // there, and a placement of one corner of a map, elsewhere, is clean (seen on the benchmark:
      // two maps sharing nine tenths, the answer's 108 contradictions none of them in the corner
      // that a half-turned placement laid on the other map with none; refused at 0). Not for an
      // answer with a wall group in a's open space, the mark of a slid placement (the corridor
      // above lays the end wall of one map's corridor across the other's: 18 cells in open space,
      // and on the rival's part of b it is as clean as the rival, 240 walls and 1 on free space;
      // drifted maps' right placements, 2-7 cells). Such an answer yields to a clean rival even
      // when its contradictions are as few as the least rate expects: they stand together in
      // open space, where noise does not put walls.
      if (!cleaner && z <= -3.0) {
        const double rival_rate = contradiction_rate(q);
        const core::Transform2& rival = t;  // (a structured binding, which clang's lambdas cannot capture)
        const auto implausible = [&](const AlignmentQuality& answer_q) {
          return contradiction_z(answer_q.contradicted, answer_q.matched + answer_q.contradicted, rival_rate) >= 4.0;
        };
        const auto implausible_where_it_lies = [&] {
          Eigen::Vector2i origin;
          const PreparedGrid part = prepared_part(from, common_mask(a, from, rival, 3), options.prepare, origin);
          const core::Transform2 answer_on_part(answer.translation() + answer.rotation_matrix() * origin.cast<double>(),
                                                answer.rotation());
          return implausible(evaluate_alignment(a, part, answer_on_part, fit_only));
        };
        const bool slid_look = best.open_space_walls >= co.full_open_space;
        const bool acceptable = acceptance_factor_of(acceptance_index(a.level(0), from.level(0), t).omega()) >= 0.5;
        if (acceptable && slid_look && co.slid_answer_yields) cleaner = t;
        else if (acceptable && implausible(best) && (!co.rival_cleaner_where_it_lies || slid_look || implausible_where_it_lies()))
          cleaner = t;
      }
      double plausible = q.score * clamp01((4.0 - z) / 2.0);
      // A rival is judged as the answer is: one whose cells disagree with a's (free on occupied)
      // more than the acceptance factor allows could not be merged itself, and says nothing about
      // the answer (seen on the benchmark: a quarter-turned corner of one room laid on a's walls).
      if (plausible > second) plausible *= acceptance_factor_of(acceptance_index(a.level(0), from.level(0), t).omega());
      if (plausible > second) second = plausible, alternative = t;
      // A turned placement fits as well when it is plausible, or when the maps contradict it at
      // most twice as often as the answer: contradictions come in clumps (an obstacle in a doorway
      // in one map, a wall the other saw through), and between two rough fits of one room a clump
      // or two more says little (seen in the simulator: a room merged turned a half turn, its
      // walls agreeing 92%, while the right placement's agreed 86%). Or when its walls agree as a
      // merged answer's must and pin it more than the answer's: two maps that drifted contradict
      // their right placement in many places, one room laid on itself in few (seen in the
      // simulator with scan matching: evidence 55 at 93% against the half-turned room's 35 at 98%).
      const bool as_rough = n > 0.0 && q.contradicted <= 2.0 * rate * n;
      const bool stronger = n > 0.0 && q.matched >= co.zero_agreement * n && evidence_of(q) >= own;
      if ((z <= 2.0 || as_rough || stronger) && turned_apart(t, answer) && own > 0.0) turned = std::max(turned, evidence_of(q) / own);
    }
    if (cleaner) return std::pair(0.0, cleaner);
    return std::pair(best.score > 0.0 ? clamp01(1.0 - second / best.score) : 0.0, alternative);
  };
  Placements others;
  for (std::size_t i = 1; i < scored.size(); ++i) others.emplace_back(scored[i].first, scored[i].second->fit.b_to_a);
  std::tie(result.distinctiveness, result.alternative) = distinctiveness(b, others, best_q, result.transform);

  // Symmetric or repeated places (only when the answer could be merged at all): other placements
  // of b in a, turned by quarter turns from the answer, at every translation. Twice: all of b (a
  // quarter-turned placement elsewhere, on a row of identical rooms), and only the part of b that
  // the answer lays on a's known cells, which is all the evidence there is: rows of identical
  // rooms, or a symmetric room, fit elsewhere nearly as well, and the rest of b, lying on a's
  // unknown, cannot tell them apart.
  // What tells the common walls from any corner of a bare room: matched walls off the corner's two
  // lines, matched openings in its walls, and a T or cross junction (a wall going on past the
  // corner in both maps), which counts as a full set of blocks beyond. But a T and nothing else
  // (fewer than a full set of blocks off its two lines, no wall end, no opening both saw) is one
  // more corner: every inner wall meets an outer one in a T, and any such junction, in this
  // building or another, fits it as well (seen on the benchmark of robot-built maps: windows of
  // two different houses merged at 0.52, an inner wall meeting the outer wall laid on another).
  const bool lone_t = co.refuse_lone_t && best_q.junction_arms == 3 && best_q.beyond_corner < co.full_beyond_corner &&
                      best_q.wall_ends == 0 && best_q.common_openings == 0;
  const double beyond = best_q.beyond_corner + best_q.wall_ends +
                        (best_q.junction_arms >= 3 && !lone_t ? co.full_beyond_corner : 0.0);
  // The probes count for the decision only on answers that could be merged; with
  // complete_features they run on every answer with evidence, for DecisionFeatures alone.
  const bool counts = options.probe_symmetries && beyond > 0 &&
                      agree_factor * acceptance_factor * support(result.evidence) >= options.min_confidence;
  const double turned_unprobed = turned;
  const double distinct_unprobed = result.distinctiveness;
  const auto alternative_unprobed = result.alternative;
  if (counts || (options.complete_features && options.probe_symmetries && result.evidence > 0.0)) {
    result.features.probed = true;
    std::tie(result.distinctiveness, result.alternative) =
        distinctiveness(b, other_placements(a, b, result.transform, options, others), best_q, result.transform);
    // b's prepared data, masked and cut (preparing the common part again cost a third of the time
    // of preparing the maps).
    Eigen::Vector2i origin;
    const PreparedGrid pc = prepared_part(b, common_mask(a, b, result.transform, 3), options.prepare, origin);
    // When the answer lays nearly all of b on a's known cells, the probe of all of b said it all.
    if (!pc.walls().empty() && pc.walls().size() < 0.8 * b.walls().size()) {
      const Eigen::Vector2d o = origin.cast<double>();
      const core::Transform2 answer(result.transform.translation() + result.transform.rotation_matrix() * o,
                                    result.transform.rotation());  // the cut's cells into a's
      const AlignmentQuality own = evaluate_alignment(a, pc, answer, fit_only);
      const auto [d, alternative] = distinctiveness(pc, other_placements(a, pc, answer, options, {}), own, answer);
      if (d < result.distinctiveness) {
        result.distinctiveness = d;
        // Back to b's cells: the cut's cell q is b's cell q + o.
        if (alternative) result.alternative = core::Transform2(alternative->translation() - alternative->rotation_matrix() * o,
                                                                alternative->rotation());
      }
    }
  }
  result.features.distinctiveness = result.distinctiveness;
  result.features.turned = turned;
  if (!counts) {
    turned = turned_unprobed;
    result.distinctiveness = distinct_unprobed;
    result.alternative = alternative_unprobed;
  }
  if (result.covariance) {
    // Where b's points land at the overlap centre: dt + dtheta perp(centre - t).
    const Eigen::Vector2d lever = best_q.overlap_centre - result.transform.translation();
    Eigen::Matrix<double, 2, 3> j;
    j << 1.0, 0.0, -lever.y(), 0.0, 1.0, lever.x();
    const Eigen::Matrix2d at_centre = j * *result.covariance * j.transpose();
    result.features.largest_std_cells =
        std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(at_centre).eigenvalues()(1)));
    result.features.theta_std_deg = core::rad2deg(std::sqrt(std::max(0.0, (*result.covariance)(2, 2))));
  }
  // One rectangular room: the common walls are its sides (four lines), and the room turned a half
  // turn (a quarter for a square) fits them as well without contradiction: a smaller share of the
  // room in common does not make that placement less true (seen in the simulator: two robots in a
  // bare rectangular hall merged turned a half turn, because the wrong placement laid more of one
  // map on the other). In a house the turned placement lays the other rooms of b on a's free
  // space, and the probe does not count it.
  const bool one_room =
      co.min_turned_share > 0.0 && best_q.beyond_room <= co.zero_beyond_corner && turned >= co.min_turned_share;
  if (one_room) result.distinctiveness = 0.0;
  // A bare room: the common walls are sides of one rectangular room (four long straight walls at
  // most, no more than two of them parallel, nothing off them: no jog or niche), with no opening in
  // them that both maps saw and no wall going on past a corner (a T). All they fix is the room's
  // size, and a room of that size elsewhere, in this building or another, fits them as well; the
  // rest of each map lies on the other's unknown.
  // Seen on the benchmark of robot-built maps: windows of two different houses merged at 0.69 and
  // 0.56, three sides of a room laid on a room of the other house as wide.
  // The same when one map saw that room and nothing else (at most 2% of its free cells beyond the
  // sides) and both saw nothing inside it (no matched wall half a metre in from the outline): the
  // blocks off the sides are then the outline's own (a thick wall's far face, ragged corners, a
  // short fourth side), no detail that says where the room is. Seen on the benchmark: a window of
  // one bare room, four blocks off its sides at the corners, laid on a room of another house at 0.72.
  const bool only_sides = best_q.off_room_sides <= co.zero_beyond_corner ||
                          (best_q.outside_room <= co.most_outside_room && best_q.room_details <= co.zero_beyond_corner);
  const bool bare_room = co.refuse_bare_room && only_sides && best_q.parallel_lines <= 2 && best_q.wall_ends == 0 &&
                         best_q.common_openings == 0 && best_q.junction_arms < 3;
  if (bare_room) result.distinctiveness = 0.0;
  // One end of a bare hall: the common walls are two parallel walls and one across them, nothing
  // else (no wall off those lines, no opening in them seen by both), and neither map saw past the
  // two parallel walls. The two maps may show the same end or the two ends of a longer hall, each
  // reaching into the other's unknown: the second placement lays no wall on a wall, so no probe
  // finds it, and nothing in the maps tells which (seen in the simulator with scan matching: two
  // robots' maps of a 25 m wide hall, each a U of its own end, merged turned a half turn, 19 m off,
  // at confidence 0.60). Rooms beside the hall, seen by either map, would lie on the other map's
  // rooms or walls at the other end: the end is determined (seen in the simulator: three sides of
  // a room in common, each map holding the rooms on its own side, merged right at 0.61).
  const bool hall_end = best_q.beyond_end >= 0 && best_q.beyond_end <= co.zero_beyond_corner && best_q.wall_ends == 0;
  if (hall_end) result.distinctiveness = 0.0;
  const double support_factor = support(result.evidence * result.distinctiveness);
  // Matched wall ends count with the blocks off the corner's two lines: an opening in a wall, seen in
  // both maps at one place, tells the corner from the room's other corners as a wall beyond does.
  const double corner_factor = clamp01((beyond - co.zero_beyond_corner) / (co.full_beyond_corner - co.zero_beyond_corner));
  result.confidence = agree_factor * acceptance_factor * support_factor * corner_factor;
  result.merged = result.confidence >= options.min_confidence;
  if (!result.merged) {
    // The weakest factor says why, in words.
    // A named copy: a lambda may not capture a structured binding (clang 14).
    const double constraint = best_q.constraint;
    const auto [refusal, why] = [&]() -> std::pair<Refusal, const char*> {
      if (open_space_factor < 0.5 && open_space_factor <= wall_agreement)
        return {Refusal::WallsCross, "a wall of one map stands in the other's open space, where that one saw a room or "
                                     "corridor (a wall drawn or moved there, or two copies of a repeated place laid on "
                                     "each other)"};
      if (agree_factor < 0.5) return {Refusal::WallsCross, "the walls of one map cross the other's free space"};
      if (acceptance_factor < 0.5)
        return {Refusal::CellsDisagree, "the maps disagree on the cells they share (free in one, occupied in the other)"};
      if (corner_factor < 0.5 && lone_t)
        return {Refusal::OneCorner, "the common walls are one T (a wall meeting another that goes on past it) and nothing "
                                    "else, which any other such junction fits as well"};
      if (corner_factor < 0.5)
        return {Refusal::OneCorner, "the common walls are one corner (two straight walls), which fits any other corner of a bare room as well"};
      if (one_room) return {Refusal::OneRoom, "the common walls are the sides of one rectangular room, which fits itself turned as well"};
      if (hall_end)
        return {Refusal::HallEnd, "the common walls are one end of a bare hall (two parallel walls and one across), which the "
                                  "hall's other end fits as well: the maps may show its two ends"};
      if (bare_room)
        return {Refusal::OneRoom, "the common walls are sides of one bare rectangular room (no opening both maps saw, no wall "
                                  "going on past a corner), which any room of that size fits as well"};
      if (result.distinctiveness < 0.5)
        return {Refusal::AnotherPlacement, "another placement fits nearly as well, or without the answer's contradictions (repeated or symmetric places)"};
      if (constraint < co.half_evidence)
        return {Refusal::FreeToSlide, "the common walls leave the placement free to slide or turn (a bare room, a corridor, one wall)"};
      return {Refusal::LittleFit, "too little of the common walls fits better than chance"};
    }();
    result.refusal = refusal;
    result.reason = fmt::format(
        "no reliable overlap: {}; confidence {:.2f} < {:.2f} (wall agreement {:.2f}, acceptance {:.2f}, evidence {:.1f} "
        "from constraint {:.1f} at {:.2f} cells, distinctiveness {:.2f})",
        why, result.confidence, options.min_confidence, best_q.agreement, result.acceptance, result.evidence,
        best_q.constraint, best_q.residual_rms, result.distinctiveness);
  }
  return result;
}

double needed_wall_distance(const MergeOptions& options) {
  // refine.cpp counts walls 2.5 cells off as outliers, acceptance.cpp cells within 1 of a wall,
  // the overlap search free cells beyond 1.5; and acceptance.cpp tells a wall in open space by a
  // distance of open_space_distance or more, which the capped field must reach.
  return std::max(std::max({options.quality.match_distance, options.quality.contradiction_distance,
                            options.refinement.inlier_distance, 2.5}) + 1.5,
                  options.quality.open_space_distance);
}

PrepareOptions prepare_options(const MergeOptions& options) {
  PrepareOptions p = options.prepare;
  p.max_wall_distance = std::max(p.max_wall_distance, needed_wall_distance(options));
  return p;
}

MergeResult align_prepared(const PreparedGrid& a, const PreparedGrid& b, const MergeOptions& options) {
  check_merge_method(options.method, options.method_settings);
  check_search_options(options);
  const double ra = a.grid().resolution(), rb = b.grid().resolution();
  if (std::abs(ra - rb) > 1e-9 * ra)
    throw InputError(fmt::format("merge: the maps' cells are {} m and {} m; resample one to the other's resolution first",
                                 ra, rb));
  const double needed = needed_wall_distance(options);
  if (a.max_wall_distance() < needed || b.max_wall_distance() < needed)
    throw InputError(fmt::format("merge options: the maps were prepared with max_wall_distance {} cells, the "
                                 "distances compared need {} (prepare them with prepare_options(options))",
                                 std::min(a.max_wall_distance(), b.max_wall_distance()), needed));
  if (a.walls().empty() || b.walls().empty()) {
    MergeResult r;
    r.reason = std::string("no reliable overlap: ") + (a.walls().empty() ? "the first" : "the second") +
               " map has no walls (occupied cells next to free ones) to align";
    r.refusal = Refusal::NoCandidate;
    return r;
  }
  core::Random random(options.seed);
  // Steps: lists of passes. Candidates accumulate; each step ends with a decision, and a merge at
  // sure_confidence or more ends the search.
  const MergeSteps steps = method_steps(merge_method_registry(), options.method, options.method_settings);
  std::vector<Hypothesis> candidates;
  MergeResult best;
  for (const auto& step : steps) {
    for (const ProposeFn& pass : step) {
      auto more = pass(a, b, options, random);
      candidates.insert(candidates.end(), more.begin(), more.end());
    }
    MergeResult r = decide(a, b, candidates, options);
    if (best.candidates == 0 || r.confidence > best.confidence) best = std::move(r);
    if (best.merged && best.confidence >= options.sure_confidence) break;
  }
  best.candidates = int(candidates.size());
  return best;
}

KnownPart::KnownPart(const mapping::OccupancyGrid& grid, int margin) : full_(&grid) {
  if (grid.width() <= 0 || grid.height() <= 0) return;
  // The box of the known cells.
  const cv::Rect box = cv::boundingRect(mapping::state_mask(grid, {mapping::CellState::Occupied, mapping::CellState::Free}));
  if (box.empty()) return;  // nothing known: keep the map as it is
  const int x0 = std::max(0, box.x - margin), y0 = std::max(0, box.y - margin);
  const int x1 = std::min(grid.width() - 1, box.br().x - 1 + margin), y1 = std::min(grid.height() - 1, box.br().y - 1 + margin);
  // Copying costs more than it saves unless the cut is clearly smaller.
  if (double(x1 - x0 + 1) * double(y1 - y0 + 1) > 0.8 * double(grid.width()) * double(grid.height())) return;
  origin_ = Eigen::Vector2i(x0, y0);
  // Where its cells lie in the map's frame: a registered method may read the cut in metres.
  const core::Pose2 corner = grid.geometry().origin().compose(core::Pose2(x0 * grid.resolution(), y0 * grid.resolution(), 0.0));
  cut_ = crop_grid(grid, x0, y0, x1 - x0 + 1, y1 - y0 + 1, corner);
}

MergeResult uncut(MergeResult result, const KnownPart& a, const KnownPart& b) {
  const Eigen::Vector2d oa = a.origin().cast<double>(), ob = b.origin().cast<double>();
  // full_a = cut_a + oa, full_b = cut_b + ob: full_a = T (full_b - ob) + oa.
  const auto move = [&](const core::Transform2& t) {
    return core::Transform2(t.translation() + oa - t.rotation_matrix() * ob, t.rotation());
  };
  if (result.covariance) result.covariance = propagate_covariance(*result.covariance, result.transform, move);
  result.transform = move(result.transform);
  if (result.alternative) result.alternative = move(*result.alternative);
  result.quality.overlap_centre += oa;
  result.quality.open_space_at += oa;
  return result;
}

MergeResult align_maps(const mapping::OccupancyGrid& a, const mapping::OccupancyGrid& b, const MergeOptions& options) {
  check_merge_method(options.method);
  const KnownPart ka(a), kb(b);
  const PrepareOptions prepare = prepare_options(options);
  const PreparedGrid pa(ka.grid(), prepare), pb(kb.grid(), prepare);
  return uncut(align_prepared(pa, pb, options), ka, kb);
}

}  // namespace fleetmap::merging
