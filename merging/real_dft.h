#pragma once
// Real two-dimensional discrete Fourier transforms of one size, by FFTW (internal: OpenCV and FFTW
// types). The overlap search correlates maps through hundreds of them per merge; FFTW's are three to
// four times faster than cv::dft's on its sizes (128 to 400 cells square: 0.023 against 0.059 ms
// forward at 128, 0.24 against 0.72 at 400, bench/README "FFTW for the overlap search").
#include <complex>
#include <opencv2/core.hpp>
#include <vector>

struct fftwf_plan_s;

namespace fleetmap::merging {

// The non-redundant half of a real image's spectrum: rows x (cols / 2 + 1), row after row.
using HalfSpectrum = std::vector<std::complex<float>>;

class RealDft {
 public:
  // Images of `size` (cols x rows, both at least 1). Throws InputError otherwise.
  explicit RealDft(cv::Size size);
  ~RealDft();
  RealDft(const RealDft&) = delete;
  RealDft& operator=(const RealDft&) = delete;

  cv::Size size() const { return size_; }
  int half_cols() const { return size_.width / 2 + 1; }

  // The spectrum of `image` (CV_32F, at most size(); placed at the top left, zeros elsewhere).
  void forward(const cv::Mat& image, HalfSpectrum& spectrum);
  // The real image whose spectrum is `spectrum`, divided by the cell count (cv::DFT_SCALE), into
  // `image` (CV_32F, size()).
  void inverse(const HalfSpectrum& spectrum, cv::Mat& image);

 private:
  cv::Size size_;
  float* real_ = nullptr;                // size_ cells, FFTW-aligned
  std::complex<float>* complex_ = nullptr;  // rows x half_cols(), FFTW-aligned
  fftwf_plan_s* forward_ = nullptr;
  fftwf_plan_s* inverse_ = nullptr;
};

}  // namespace fleetmap::merging
