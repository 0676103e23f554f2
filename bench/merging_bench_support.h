#pragma once
// Shared by the merging benchmarks: the thread's CPU time, and the feature-based peer of the ROS
// `multirobot_map_merge` package (Horner 2016), as the merging benchmarks run it on the same pairs
// as fleetmap (bench/merging_real_bench.cpp describes it).
#include <Eigen/Core>
#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>

#include <ctime>
#include <algorithm>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "mapping/occupancy_grid.h"

namespace fleetmap::bench {

// The calling thread's CPU time, seconds.
inline double thread_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// --- the peer --------------------------------------------------------------------------------

struct PeerResult {
  bool merged = false;
  std::optional<Eigen::Matrix<double, 2, 3>> b_to_a;
  double confidence = 0.0;
  int matches = 0, inliers = 0;
};

inline cv::Mat ros_image(const mapping::OccupancyGrid& g) {
  // nav_msgs/OccupancyGrid data as the ROS merger reads it: -1 unknown (255 as bytes), 0 free, 100 occupied.
  cv::Mat img(g.height(), g.width(), CV_8U);
  for (int y = 0; y < g.height(); ++y) {
    auto* row = img.ptr<std::uint8_t>(y);
    for (int x = 0; x < g.width(); ++x) {
      const auto s = g.state_at(y * g.width() + x);
      row[x] = s == mapping::CellState::Unknown ? 255 : s == mapping::CellState::Free ? 0 : 100;
    }
  }
  return img;
}

inline PeerResult orb_peer(const mapping::OccupancyGrid& a, const mapping::OccupancyGrid& b) {
  PeerResult out;
  const auto orb = cv::ORB::create(1500, 1.3f, 5);
  std::vector<cv::KeyPoint> ka, kb;
  cv::Mat da, db;
  orb->detectAndCompute(ros_image(a), cv::noArray(), ka, da);
  orb->detectAndCompute(ros_image(b), cv::noArray(), kb, db);
  if (da.empty() || db.empty()) return out;
  cv::BFMatcher matcher(cv::NORM_HAMMING);
  std::vector<std::pair<int, int>> pairs;  // (b, a)
  constexpr float kRatio = 0.7f;           // 1 - match_conf
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(db, da, knn, 2);
  for (const auto& m : knn)
    if (m.size() == 2 && m[0].distance < kRatio * m[1].distance) pairs.emplace_back(m[0].queryIdx, m[0].trainIdx);
  knn.clear();
  matcher.knnMatch(da, db, knn, 2);
  for (const auto& m : knn) {
    if (m.size() < 2 || !(m[0].distance < kRatio * m[1].distance)) continue;
    const std::pair<int, int> p(m[0].trainIdx, m[0].queryIdx);
    if (std::find(pairs.begin(), pairs.end(), p) == pairs.end()) pairs.push_back(p);
  }
  out.matches = int(pairs.size());
  if (out.matches < 6) return out;
  std::vector<cv::Point2f> src, dst;
  for (const auto& [ib, ia] : pairs) {
    src.push_back(kb[std::size_t(ib)].pt);
    dst.push_back(ka[std::size_t(ia)].pt);
  }
  std::vector<std::uint8_t> inliers;
  const cv::Mat h = cv::estimateAffinePartial2D(src, dst, inliers, cv::RANSAC, 3.0);
  if (h.empty()) return out;
  out.inliers = int(std::count(inliers.begin(), inliers.end(), std::uint8_t(1)));
  out.confidence = out.inliers / (8.0 + 0.3 * out.matches);
  Eigen::Matrix<double, 2, 3> m;
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = h.at<double>(r, c);
  out.b_to_a = m;
  out.merged = out.confidence >= 1.0;
  return out;
}


}  // namespace fleetmap::bench
