#pragma once
// The `features` method: OpenCV keypoints (ORB and AKAZE) on both map images, descriptor matching
// with Lowe's ratio test, and a rigid (not similarity) RANSAC fit, as the common ROS map merger
// does (it fits a similarity with estimateAffinePartial2D).
#include <string>
#include <vector>

#include "core/random.h"
#include "merging/hypothesis.h"
#include "merging/prepared_grid.h"

namespace fleetmap::merging {

struct FeatureMatchingOptions {
  // Each "orb" or "akaze". AKAZE finds a few more matches on large smooth maps but costs ten times
  // ORB's time; the rotation sweep covers what ORB misses.
  std::vector<std::string> detectors = {"orb"};
  int max_features = 2000;         // ORB's keypoint budget per image
  double ratio = 0.8;              // Lowe's ratio test on the two nearest descriptors
  double inlier_distance = 3.0;    // RANSAC inlier distance, in cells of the working image
  int ransac_iterations = 3000;
  int min_inliers = 8;
  int models = 2;                  // distinct models kept per detector (sequential RANSAC)
  int max_image_cells = 1600;      // larger maps are matched on the finest pyramid level within this
  int min_image_cells = 600;       // smaller maps are scaled up (by at most 4) toward this: detectors need pixels
  double blur = 0.5;               // Gaussian blur, in working cells: softens the stairs of turned walls
};

// Candidate transforms, best first by inlier count. Throws InputError for an unknown detector name.
std::vector<Hypothesis> feature_hypotheses(const PreparedGrid& a, const PreparedGrid& b,
                                           const FeatureMatchingOptions& options, core::Random& random);

}  // namespace fleetmap::merging
