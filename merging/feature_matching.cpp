#include "merging/feature_matching.h"

#include <algorithm>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "merging/grid_level.h"
#include "merging/hamming.h"
#include "merging/rigid_fit.h"

namespace fleetmap::merging {

namespace {

// The map as a picture for a detector: occupied black, free white, unknown mid grey, scaled up by
// `scale` and softened.
cv::Mat map_image(const GridLevel& level, int scale, double blur) {
  cv::Mat img(level.occupied.size(), CV_8U, cv::Scalar(128));
  img.setTo(255, level.free);
  img.setTo(0, level.occupied);
  if (scale > 1) cv::resize(img, img, {}, scale, scale, cv::INTER_LINEAR);
  if (blur > 0.0) cv::GaussianBlur(img, img, cv::Size(0, 0), blur * scale);
  return img;
}

cv::Mat wall_mask(const GridLevel& level, int scale) {
  cv::Mat mask;
  cv::dilate(level.walls, mask, cv::Mat::ones(5, 5, CV_8U));
  if (scale > 1) cv::resize(mask, mask, {}, scale, scale, cv::INTER_NEAREST);
  return mask;
}

cv::Ptr<cv::Feature2D> make_detector(const std::string& name, const FeatureMatchingOptions& options) {
  if (name == "orb") return cv::ORB::create(options.max_features);
  if (name == "akaze") return cv::AKAZE::create();
  throw InputError("unknown feature detector '" + name + "' (valid: orb, akaze)");
}

}  // namespace

std::vector<Hypothesis> feature_hypotheses(const PreparedGrid& a, const PreparedGrid& b,
                                           const FeatureMatchingOptions& options, core::Random& random) {
  const int top = std::min(a.level_count(), b.level_count()) - 1;
  const int level = std::min(top, std::max(a.level_for_size(options.max_image_cells),
                                           b.level_for_size(options.max_image_cells)));
  const GridLevel& la = a.level(level);
  const GridLevel& lb = b.level(level);
  const int longest = std::max({la.width(), la.height(), lb.width(), lb.height()});
  const int scale = std::clamp((options.min_image_cells + longest - 1) / std::max(1, longest), 1, 4);
  const cv::Mat img_a = map_image(la, scale, options.blur), img_b = map_image(lb, scale, options.blur);
  // Keypoints only near walls: corners of the unknown border are artefacts of where a map ends.
  const cv::Mat mask_a = wall_mask(la, scale), mask_b = wall_mask(lb, scale);

  std::vector<Hypothesis> out;
  for (const auto& name : options.detectors) {
    const auto detector = make_detector(name, options);
    std::vector<cv::KeyPoint> kp_a, kp_b;
    cv::Mat desc_a, desc_b;
    detector->detectAndCompute(img_a, mask_a, kp_a, desc_a);
    detector->detectAndCompute(img_b, mask_b, kp_b, desc_b);
    if (kp_a.size() < 2 || kp_b.size() < 2 || desc_a.empty() || desc_b.empty()) continue;
    const auto nearest = nearest_two_hamming(desc_b, desc_a);
    std::vector<PointPair> pairs;
    for (std::size_t i = 0; i < nearest.size(); ++i) {
      const NearestTwo& m = nearest[i];
      // As a DMatch holds them: floats.
      if (float(m.distance) < options.ratio * float(m.second_distance)) {
        const auto& pb = kp_b[i].pt;
        const auto& pa = kp_a[std::size_t(m.index)].pt;
        // Pixel centres of the scaled image back to cells of the level.
        const auto cell = [&](const cv::Point2f& p) {
          return Eigen::Vector2d((p.x + 0.5) / scale - 0.5, (p.y + 0.5) / scale - 0.5);
        };
        pairs.push_back({cell(pb), cell(pa), 1.0});
      }
    }
    RigidRansacOptions ransac;
    ransac.inlier_distance = options.inlier_distance;
    ransac.iterations = options.ransac_iterations;
    ransac.min_inliers = options.min_inliers;
    std::vector<bool> used(pairs.size(), false);
    for (int model = 0; model < options.models; ++model) {
      const auto fit = ransac_rigid(pairs, ransac, random, used);
      if (!fit) break;
      for (int i : fit->inliers) used[std::size_t(i)] = true;
      // RANSAC leaves a few cells of error at the working level: refinement starts one level up.
      out.push_back({from_level(fit->transform, la.factor), double(fit->inliers.size()), level + 1, "features"});
    }
  }
  std::sort(out.begin(), out.end(), [](const Hypothesis& x, const Hypothesis& y) { return x.score > y.score; });
  return out;
}

}  // namespace fleetmap::merging
