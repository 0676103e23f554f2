#include "merging/hamming.h"

#include <gtest/gtest.h>

#include <opencv2/features2d.hpp>

#include "core/error.h"

namespace fleetmap::merging {
namespace {

// Descriptors of `bits` random bits (the rest zero) in `bytes`-wide rows: few bits make many ties.
cv::Mat random_descriptors(int rows, int bytes, int bits, cv::RNG& rng) {
  cv::Mat m = cv::Mat::zeros(rows, bytes, CV_8U);
  for (int r = 0; r < rows; ++r) {
    for (int b = 0; b < bits; ++b) {
      if (rng.uniform(0, 2)) m.at<std::uint8_t>(r, b / 8) |= std::uint8_t(1u << (b % 8));
    }
  }
  return m;
}

// The matcher replaces cv::BFMatcher's knnMatch(k = 2) in feature matching: the same neighbours,
// distances and tie order, or the merges would change.
TEST(NearestTwoHamming, FindsWhatOpenCvsBruteForceMatcherFinds) {
  cv::RNG rng(7);
  // ORB's 32 bytes, AKAZE's 61, and 5 bits in 32 bytes (ties nearly everywhere).
  for (const auto& [bytes, bits] : {std::pair{32, 256}, std::pair{61, 486}, std::pair{32, 5}}) {
    const cv::Mat query = random_descriptors(300, bytes, bits, rng), train = random_descriptors(250, bytes, bits, rng);
    std::vector<std::vector<cv::DMatch>> knn;
    cv::BFMatcher(cv::NORM_HAMMING).knnMatch(query, train, knn, 2);
    const auto nearest = nearest_two_hamming(query, train);
    ASSERT_EQ(nearest.size(), knn.size());
    for (std::size_t i = 0; i < knn.size(); ++i) {
      ASSERT_EQ(knn[i].size(), 2u);
      EXPECT_EQ(nearest[i].index, knn[i][0].trainIdx) << bytes << " bytes, " << bits << " bits, query " << i;
      EXPECT_EQ(float(nearest[i].distance), knn[i][0].distance) << i;
      EXPECT_EQ(float(nearest[i].second_distance), knn[i][1].distance) << i;
    }
  }
}

TEST(NearestTwoHamming, RefusesDescriptorsItCannotCompare) {
  const cv::Mat two = cv::Mat::zeros(2, 32, CV_8U);
  EXPECT_THROW(nearest_two_hamming(two, cv::Mat::zeros(1, 32, CV_8U)), InputError);
  EXPECT_THROW(nearest_two_hamming(two, cv::Mat::zeros(2, 61, CV_8U)), InputError);
  EXPECT_THROW(nearest_two_hamming(cv::Mat::zeros(2, 32, CV_32F), cv::Mat::zeros(2, 32, CV_32F)), InputError);
}

}  // namespace
}  // namespace fleetmap::merging
