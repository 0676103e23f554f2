#include "merging/map_aligner.h"

#include <algorithm>

#include <fmt/format.h>

#include "core/random.h"
#include "merging/landmark_alignment.h"
#include "merging/merge.h"

namespace fleetmap::merging {

namespace {

class KnownFramesAligner final : public MapAligner {
 public:
  bool shared_frame() const override { return true; }
  FrameAlignment align(const AlignmentRequest&) const override { return {}; }
};

// Robots that never bring another's map into their own: each explores and maps alone.
class NoAligner final : public MapAligner {
 public:
  FrameAlignment align(const AlignmentRequest&) const override { return {}; }
};

// D'Alfonso et al., §3.2: both robots see each other and send each other their pose and
// their reading of the other (5 numbers each).
class RendezvousAligner final : public MapAligner {
 public:
  FrameAlignment align(const AlignmentRequest& q) const override {
    FrameAlignment out;
    if (!q.detection) return out;  // no rendezvous yet
    const MutualObservation& d = *q.detection;
    out.attempted = out.merged = true;
    out.bytes_sent = 2 * 5 * 8;
    out.sender_to_receiver = rendezvous_transform_matrices(q.receiver_pose, q.sender_pose,
                                                           0.5 * (d.range_self_to_other + d.range_other_to_self),
                                                           d.bearing_self_to_other, d.bearing_other_to_self);
    out.method = "rendezvous";
    out.confidence = 1.0;
    return out;
  }
};

// The best overlap of the two grids (merge.h), merged from its min_confidence on.
class OverlapAligner final : public MapAligner {
 public:
  explicit OverlapAligner(const core::Params& p) : method_(p.text("method")), min_confidence_(p.number("min_confidence")) {
    check_merge_method(method_);
  }
  void set_merge_methods(const MergeMethodSettings& settings) override {
    check_merge_method(method_, settings);
    merge_methods_ = settings;
  }
  bool costly() const override { return true; }
  bool sends_map() const override { return true; }
  FrameAlignment align(const AlignmentRequest& q) const override {
    MergeOptions o;
    o.method = method_;
    o.method_settings = merge_methods_;
    o.min_confidence = min_confidence_;
    o.seed = q.seed;
    const MergeResult m = align_maps(*q.receiver_map, *q.sender_map, o);
    FrameAlignment out;
    out.attempted = true;
    out.method = m.method.empty() ? method_ : m.method;
    out.confidence = m.confidence;
    out.merged = m.merged;
    out.reason = m.reason;
    if (m.merged) out.sender_to_receiver = world_from_cells(q.receiver_map->geometry(), q.sender_map->geometry(), m.transform);
    return out;
  }

 private:
  std::string method_;
  double min_confidence_;
  MergeMethodSettings merge_methods_;
};

// The map-alignment paper, §III.A: the two landmark maps associated by RANSAC (eq. (2)-(6)), the
// hypothesis with most supports. The paper trusts data association from 10 overlapping landmarks on
// (Fig. 3): the confidence is the share of the smaller map that supports the answer, scaled down
// below that many supports (a few landmarks fit many placements).
class LandmarkAligner final : public MapAligner {
 public:
  explicit LandmarkAligner(const core::Params& p)
      : min_confidence_(p.number("min_confidence")), support_distance_(p.number("support_distance")) {}
  bool costly() const override { return true; }
  bool needs_landmark_estimates() const override { return true; }
  FrameAlignment align(const AlignmentRequest& q) const override {
    FrameAlignment out;
    const auto to_map = [](const std::vector<localization::Landmark>& landmarks) {
      LandmarkMap m;
      for (const auto& l : landmarks) m.landmarks.push_back({l.position, l.covariance, {}});
      return m;
    };
    const LandmarkMap self = to_map(q.receiver_landmarks), other = to_map(q.sender_landmarks);
    LandmarkAlignmentOptions options;
    options.support_threshold = support_distance_;
    if (int(std::min(self.landmarks.size(), other.landmarks.size())) < options.min_supports) return out;  // too few yet
    out.attempted = true;
    out.method = "landmarks";
    out.bytes_sent = std::int64_t(other.landmarks.size()) * 5 * 8;  // position and covariance of each
    core::Random random(q.seed);
    const LandmarkAlignment a = align_landmarks(self, other, options, random);
    const double smaller = double(std::min(self.landmarks.size(), other.landmarks.size()));
    const double supports = double(a.supports.size());
    out.confidence = a.found ? supports / smaller * std::min(1.0, supports / double(options.overlap_threshold)) : 0.0;
    if (!a.found || out.confidence < min_confidence_) {
      out.reason = a.found ? fmt::format("{} of {} landmarks agree (trusted from {}): confidence {:.2f} < {:.2f}",
                                         a.supports.size(), int(smaller), options.overlap_threshold, out.confidence,
                                         min_confidence_)
                           : fmt::format("no placement has {} landmarks agreeing", options.min_supports);
      return out;
    }
    out.merged = true;
    out.sender_to_receiver = a.transform;
    return out;
  }

 private:
  double min_confidence_;
  double support_distance_;
};

template <typename T>
MapAlignerFactory make() {
  return [](const core::Params&) { return std::make_unique<T>(); };
}

template <typename T>
MapAlignerFactory make_with_params() {
  return [](const core::Params& p) { return std::make_unique<T>(p); };
}

}  // namespace

core::Registry<MapAlignerFactory>& map_aligner_registry() {
  static core::Registry<MapAlignerFactory> registry("merging");
  static const bool built_in = [] {
    auto& r = registry;
    r.add("known", "every robot knows its start in one shared frame; maps simply add up", make<KnownFramesAligner>());
    r.add("none",
          "every robot maps alone in its own frame and never takes another's map (its map is written as robot_<k>.yaml: "
          "merge them afterwards with fleetmap merge)",
          make<NoAligner>());
    r.add("rendezvous",
          "robots that detect each other compute each other's frame from the detection (D'Alfonso et al., §3.2)",
          make<RendezvousAligner>());
    using core::ParamSpec;
    const auto min_confidence = [](const char* doc) {
      return ParamSpec::number("min_confidence", 0.5, {0, 1}, "", doc);
    };
    r.add("overlap", "robots that can talk search their maps for the best overlap (as fleetmap merge) and merge from a confidence on",
          make_with_params<OverlapAligner>(),
          {ParamSpec::text("method", "auto", {}, "the merge method searched with (fleetmap plugins --family merge-method)"),
           min_confidence("a search's answer below this confidence is not merged")});
    r.add("landmarks",
          "robots that can talk associate their estimated landmark maps by RANSAC (map-alignment paper, eq. (2)-(6)) "
          "and merge once enough agree; needs a localizer that estimates landmarks (ekf-slam, fastslam2)",
          make_with_params<LandmarkAligner>(),
          // Supports within 0.3 m, not the paper's 1 m: landmarks placed along every wall are dense
          // enough that a wrong placement finds one within 1 m of most of them (EKF-SLAM estimates are
          // good to a few centimetres).
          {min_confidence("an association below this confidence is not merged"),
           ParamSpec::number("support_distance", 0.3, {1e-3, 100}, "m",
                             "a landmark supports a placement when one of the other map lies this close to it")});
    return true;
  }();
  (void)built_in;
  return registry;
}

void register_map_aligner(std::string name, std::string help, MapAlignerFactory make, std::vector<core::ParamSpec> params) {
  map_aligner_registry().add(std::move(name), std::move(help), std::move(make), std::move(params));
}

core::Params map_aligner_options(const std::string& name, const core::Settings& settings) {
  return map_aligner_registry().configure(name, settings);
}

void MapAligner::set_merge_methods(const MergeMethodSettings& settings) {
  for (const auto& [method, given] : settings) {
    if (!given.empty()) {
      throw InputError("parameters of merge method '" + method + "' given, but this merging runs no merge method (overlap does)");
    }
  }
}

std::unique_ptr<MapAligner> make_map_aligner(const std::string& name, const core::Settings& settings,
                                             const MergeMethodSettings& merge_methods) {
  auto aligner = map_aligner_registry().get(name).make(map_aligner_options(name, settings));
  aligner->set_merge_methods(merge_methods);
  return aligner;
}

}  // namespace fleetmap::merging
