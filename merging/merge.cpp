#include "merging/merge.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include "core/angle.h"
#include "core/error.h"

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
  return overlap_hypotheses(a, b, sweep);
}

std::vector<Hypothesis> propose_features(const PreparedGrid& a, const PreparedGrid& b, const MergeOptions& options,
                                         core::Random& random) {
  return feature_hypotheses(a, b, options.features, random);
}

bool same_answer(const core::Transform2& x, const core::Transform2& y, const Eigen::Vector2d& at_b,
                 const ConfidenceOptions& options) {
  const double dtheta = std::abs(core::rad2deg(core::normalize_angle(x.rotation() - y.rotation())));
  return dtheta <= options.distinct_rotation_deg && (x.apply(at_b) - y.apply(at_b)).norm() <= options.distinct_distance;
}

struct Candidate {
  Hypothesis hypothesis;
  LevelFit fit;
};

// Keeps the best-scoring of near-identical candidates, best first, at most `keep`.
void prune(std::vector<Candidate>& c, const PreparedGrid& b, const ConfidenceOptions& options, std::size_t keep) {
  std::sort(c.begin(), c.end(), [](const Candidate& x, const Candidate& y) { return x.fit.score > y.fit.score; });
  const Eigen::Vector2d centre_b((b.width() - 1) / 2.0, (b.height() - 1) / 2.0);
  std::vector<Candidate> kept;
  for (auto& x : c) {
    if (kept.size() >= keep) break;
    bool dup = false;
    for (const auto& k : kept) dup = dup || same_answer(x.fit.b_to_a, k.fit.b_to_a, centre_b, options);
    if (!dup) kept.push_back(std::move(x));
  }
  c = std::move(kept);
}

double clamp01(double v) { return std::clamp(v, 0.0, 1.0); }

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
  for (int k = start; k >= 0; --k) {
    for (const auto& h : candidates) {
      if (std::min(h.level, top) == k) active.push_back({h, LevelFit{h.b_to_a, 0, 0, 0.0}});
    }
    // Many candidates enter at the top level; a few steps there are enough to rank them.
    RefineOptions level_options = options.refinement;
    if (k == start) level_options.iterations = std::min(level_options.iterations, options.first_level_iterations);
    for (auto& c : active) c.fit = refine_at_level(a, b, c.fit.b_to_a, k, level_options);
    prune(active, b, options.confidence, std::size_t(k >= 2 ? options.coarse_candidates : options.fine_candidates));
  }
  return active;
}

}  // namespace

const std::vector<MergeMethod>& merge_methods() {
  static const std::vector<MergeMethod> kMethods = {
      {"overlap",
       "grid overlap search (wave-algorithm paper, Birk & Carpin 2006): Hough-spectrum rotations (Carpin 2008), FFT "
       "correlation of walls for translations, coarse to fine; a rotation sweep when the spectra find nothing",
       {propose_overlap, propose_overlap_sweep}},
      {"features", "ORB and AKAZE keypoints, ratio test, rigid RANSAC (the common ROS merger's approach)",
       {propose_features}},
  };
  return kMethods;
}

namespace {

// auto's order: (method, pass) lists, each ending with a decision.
const std::vector<std::vector<std::pair<std::string, std::size_t>>>& auto_steps() {
  static const std::vector<std::vector<std::pair<std::string, std::size_t>>> kSteps = {
      {{"overlap", 0}},
      {{"features", 0}, {"overlap", 1}},
  };
  return kSteps;
}

}  // namespace

std::vector<std::string> merge_method_names() {
  std::vector<std::string> names = {"auto"};
  for (const auto& m : merge_methods()) names.push_back(m.name);
  return names;
}

std::string merge_method_help() {
  std::string s = "  auto: overlap's spectral pass; if not confident, features and overlap's sweep too; the best wins\n";
  for (const auto& m : merge_methods()) s += "  " + m.name + ": " + m.help + "\n";
  return s;
}

void check_merge_method(const std::string& name) {
  const auto names = merge_method_names();
  if (std::find(names.begin(), names.end(), name) != names.end()) return;
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  throw InputError("unknown merge method '" + name + "' (valid: " + list + ")");
}

MergeResult decide(const PreparedGrid& a, const PreparedGrid& b, const std::vector<Hypothesis>& candidates,
                   const MergeOptions& options) {
  MergeResult result;
  result.candidates = int(candidates.size());
  if (candidates.empty()) {
    result.reason = "no reliable overlap: no candidate transform";
    return result;
  }
  std::vector<Candidate> active = refine_candidates(a, b, candidates, options);
  // Score the survivors at full resolution; the best one is the answer.
  std::vector<std::pair<AlignmentQuality, const Candidate*>> scored;
  for (const auto& c : active) scored.emplace_back(evaluate_alignment(a, b, c.fit.b_to_a, options.quality), &c);
  std::sort(scored.begin(), scored.end(), [](const auto& x, const auto& y) { return x.first.score > y.first.score; });
  const auto& [best_q, best] = scored.front();
  result.transform = best->fit.b_to_a;
  result.method = best->hypothesis.method;
  result.quality = best_q;
  result.acceptance = acceptance_index(a.grid(), b.grid(), result.transform).omega();

  // Whatever the method, look for other placements where maps with symmetric or repeated
  // structure fit too: b turned a quarter, a half and three quarters from the answer, and every
  // translation at the answer's own rotation (only when the answer could be merged at all).
  const auto& co = options.confidence;
  const double agree_factor = clamp01((best_q.agreement - co.zero_agreement) / (co.full_agreement - co.zero_agreement));
  const double support_factor = clamp01(best_q.constraint / co.full_constraint);
  const double acceptance_factor =
      clamp01((result.acceptance - co.zero_acceptance) / (co.full_acceptance - co.zero_acceptance));
  std::vector<std::pair<AlignmentQuality, core::Transform2>> others;
  for (std::size_t i = 1; i < scored.size(); ++i) others.emplace_back(scored[i].first, scored[i].second->fit.b_to_a);
  if (options.probe_symmetries && agree_factor * acceptance_factor * support_factor >= options.min_confidence) {
    std::vector<double> turns;
    for (int k = 0; k < 4; ++k) turns.push_back(result.transform.rotation() + k * std::numbers::pi / 2.0);
    OverlapSearchOptions probe = options.overlap;
    probe.translation_peaks = 4;
    const auto probes = refine_candidates(a, b, overlap_hypotheses_at(a, b, turns, probe), options);
    for (const auto& c : probes) others.emplace_back(evaluate_alignment(a, b, c.fit.b_to_a, options.quality), c.fit.b_to_a);
  }
  // The best plausible alternative answer, if any.
  const Eigen::Vector2d at_b = result.transform.inverse().apply(best_q.overlap_centre);
  const double rate = std::max(co.min_contradiction_rate,
                               (best_q.contradicted + 1.0) / (best_q.matched + best_q.contradicted + 2.0));
  double second = 0.0;
  for (const auto& [q, t] : others) {
    if (same_answer(t, result.transform, at_b, co)) continue;
    const double n = q.matched + q.contradicted;
    const double z = (q.contradicted - rate * n) / std::sqrt(rate * n + 1.0);
    const double plausible = q.score * clamp01((4.0 - z) / 2.0);
    if (plausible > second) {
      second = plausible;
      result.alternative = t;
    }
  }
  result.distinctiveness = best_q.score > 0.0 ? clamp01(1.0 - second / best_q.score) : 0.0;
  result.confidence = agree_factor * acceptance_factor * support_factor * result.distinctiveness;
  result.merged = result.confidence >= options.min_confidence;
  if (!result.merged) {
    result.reason = fmt::format(
        "no reliable overlap: confidence {:.2f} < {:.2f} (wall agreement {:.2f}, acceptance {:.2f}, constraint {:.1f}, "
        "distinctiveness {:.2f})",
        result.confidence, options.min_confidence, best_q.agreement, result.acceptance, best_q.constraint,
        result.distinctiveness);
  }
  return result;
}

MergeResult align_prepared(const PreparedGrid& a, const PreparedGrid& b, const MergeOptions& options) {
  check_merge_method(options.method);
  if (a.walls().empty() || b.walls().empty()) {
    MergeResult r;
    r.reason = std::string("no reliable overlap: ") + (a.walls().empty() ? "the first" : "the second") +
               " map has no walls (occupied cells next to free ones) to align";
    return r;
  }
  core::Random random(options.seed);
  // Steps: lists of (method, pass). Candidates accumulate; each step ends with a decision.
  const auto method_named = [](const std::string& name) -> const MergeMethod* {
    for (const auto& m : merge_methods()) {
      if (m.name == name) return &m;
    }
    return nullptr;
  };
  std::vector<std::vector<std::pair<const MergeMethod*, std::size_t>>> steps;
  if (options.method == "auto") {
    // overlap's spectral pass is fast and usually enough; then the other passes at once.
    for (const auto& step : auto_steps()) {
      steps.emplace_back();
      for (const auto& [name, pass] : step) steps.back().push_back({method_named(name), pass});
    }
  } else {
    const MergeMethod* m = method_named(options.method);
    for (std::size_t p = 0; p < m->passes.size(); ++p) steps.push_back({{m, p}});
  }
  std::vector<Hypothesis> candidates;
  MergeResult best;
  for (const auto& step : steps) {
    for (const auto& [method, pass] : step) {
      auto more = method->passes[pass](a, b, options, random);
      candidates.insert(candidates.end(), more.begin(), more.end());
    }
    MergeResult r = decide(a, b, candidates, options);
    if (best.candidates == 0 || r.confidence > best.confidence) best = std::move(r);
    if (best.merged) break;
  }
  best.candidates = int(candidates.size());
  return best;
}

MergeResult align_maps(const mapping::OccupancyGrid& a, const mapping::OccupancyGrid& b, const MergeOptions& options) {
  check_merge_method(options.method);
  const PreparedGrid pa(a, options.prepare), pb(b, options.prepare);
  return align_prepared(pa, pb, options);
}

}  // namespace fleetmap::merging
