#include "merging/real_dft.h"

#include <algorithm>
#include <cstring>
#include <fftw3.h>
#include <fmt/format.h>
#include <mutex>

#include "core/error.h"

namespace fleetmap::merging {

namespace {

// FFTW's planner is not thread-safe (its execution is): merges may run on several threads.
std::mutex& planner_mutex() {
  static std::mutex m;
  return m;
}

}  // namespace

RealDft::RealDft(cv::Size size) : size_(size) {
  if (size.width < 1 || size.height < 1)
    throw InputError(fmt::format("RealDft: size {} x {} has no cells", size.width, size.height));
  const std::size_t cells = std::size_t(size.width) * std::size_t(size.height);
  const std::size_t half = std::size_t(half_cols()) * std::size_t(size.height);
  std::lock_guard lock(planner_mutex());
  real_ = fftwf_alloc_real(cells);
  complex_ = reinterpret_cast<std::complex<float>*>(fftwf_alloc_complex(half));
  auto* c = reinterpret_cast<fftwf_complex*>(complex_);
  // FFTW_ESTIMATE: plans from the size alone (no timing runs), so every run computes the same sums.
  forward_ = fftwf_plan_dft_r2c_2d(size.height, size.width, real_, c, FFTW_ESTIMATE);
  inverse_ = fftwf_plan_dft_c2r_2d(size.height, size.width, c, real_, FFTW_ESTIMATE);
  if (!real_ || !complex_ || !forward_ || !inverse_) {
    if (forward_) fftwf_destroy_plan(forward_);
    if (inverse_) fftwf_destroy_plan(inverse_);
    fftwf_free(real_);
    fftwf_free(complex_);
    throw Error(fmt::format("RealDft: FFTW could not plan a {} x {} transform", size.width, size.height));
  }
}

RealDft::~RealDft() {
  std::lock_guard lock(planner_mutex());
  fftwf_destroy_plan(forward_);
  fftwf_destroy_plan(inverse_);
  fftwf_free(real_);
  fftwf_free(complex_);
}

void RealDft::forward(const cv::Mat& image, HalfSpectrum& spectrum) {
  if (image.type() != CV_32F || image.cols > size_.width || image.rows > size_.height)
    throw InputError(fmt::format("RealDft: a {} x {} image of type {} does not fit a {} x {} float transform", image.cols,
                                 image.rows, image.type(), size_.width, size_.height));
  const std::size_t width = std::size_t(size_.width), cols = std::size_t(image.cols);
  for (int y = 0; y < image.rows; ++y) {
    float* row = real_ + std::size_t(y) * width;
    std::memcpy(row, image.ptr<float>(y), cols * sizeof(float));
    std::fill(row + cols, row + width, 0.0f);
  }
  std::fill(real_ + std::size_t(image.rows) * width, real_ + std::size_t(size_.height) * width, 0.0f);
  fftwf_execute(forward_);
  spectrum.assign(complex_, complex_ + std::size_t(half_cols()) * std::size_t(size_.height));
}

void RealDft::inverse(const HalfSpectrum& spectrum, cv::Mat& image) {
  const std::size_t half = std::size_t(half_cols()) * std::size_t(size_.height);
  if (spectrum.size() != half)
    throw InputError(fmt::format("RealDft: a spectrum of {} values for a {} x {} transform (needs {})", spectrum.size(),
                                 size_.width, size_.height, half));
  std::copy(spectrum.begin(), spectrum.end(), complex_);  // the transform overwrites its input
  fftwf_execute(inverse_);
  image.create(size_, CV_32F);
  const float scale = 1.0f / float(size_.width * size_.height);
  for (int y = 0; y < size_.height; ++y) {
    const float* from = real_ + std::size_t(y) * std::size_t(size_.width);
    float* to = image.ptr<float>(y);
    for (int x = 0; x < size_.width; ++x) to[x] = from[x] * scale;
  }
}

}  // namespace fleetmap::merging
