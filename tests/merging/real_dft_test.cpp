#include "merging/real_dft.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace fleetmap::merging {
namespace {

cv::Mat random_image(int cols, int rows) {
  cv::Mat img(rows, cols, CV_32F);
  cv::RNG rng(3);
  rng.fill(img, cv::RNG::UNIFORM, -1.0, 1.0);
  return img;
}

// The overlap search reads correlations from these transforms where it read cv::dft's.
TEST(RealDft, ItsSpectrumIsOpenCvsAndTheInverseGivesTheImageBack) {
  // An odd width: the half spectrum's last column is no Nyquist column.
  for (const cv::Size size : {cv::Size(64, 48), cv::Size(45, 30)}) {
    const cv::Mat img = random_image(size.width - 7, size.height - 5);
    cv::Mat padded = cv::Mat::zeros(size, CV_32F);
    img.copyTo(padded(cv::Rect(0, 0, img.cols, img.rows)));
    cv::Mat expected;
    cv::dft(padded, expected, cv::DFT_COMPLEX_OUTPUT);

    RealDft dft(size);
    HalfSpectrum spectrum;
    dft.forward(img, spectrum);
    ASSERT_EQ(spectrum.size(), std::size_t(size.height) * std::size_t(size.width / 2 + 1));
    double worst = 0.0;
    for (int y = 0; y < size.height; ++y) {
      for (int x = 0; x < dft.half_cols(); ++x) {
        const auto e = expected.at<cv::Vec2f>(y, x);
        worst = std::max(worst, double(std::abs(spectrum[std::size_t(y * dft.half_cols() + x)] - std::complex<float>(e[0], e[1]))));
      }
    }
    // Sums of ~3000 values of magnitude 1 in floats.
    EXPECT_LT(worst, 1e-3) << size;

    cv::Mat back;
    dft.inverse(spectrum, back);
    ASSERT_EQ(back.size(), size);
    EXPECT_LT(cv::norm(back, padded, cv::NORM_INF), 1e-5) << size;
  }
}

TEST(RealDft, RefusesWhatDoesNotFit) {
  EXPECT_THROW(RealDft(cv::Size(0, 4)), InputError);
  RealDft dft(cv::Size(8, 8));
  HalfSpectrum spectrum;
  EXPECT_THROW(dft.forward(random_image(9, 8), spectrum), InputError);
  EXPECT_THROW(dft.forward(cv::Mat::zeros(4, 4, CV_8U), spectrum), InputError);
  cv::Mat out;
  EXPECT_THROW(dft.inverse(HalfSpectrum(3), out), InputError);
}

}  // namespace
}  // namespace fleetmap::merging
