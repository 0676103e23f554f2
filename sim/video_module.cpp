// The video module (sim/video_module.h): OpenCV's VideoWriter behind a C interface.
#include "sim/video_module.h"

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include <memory>
#include <string>
#include <type_traits>

extern "C" {

__attribute__((visibility("default"))) void* fleetmap_video_open(const char* path, const char* fourcc, double fps,
                                                                  int width, int height) {
  try {
    auto writer = std::make_unique<cv::VideoWriter>();
    const int code = cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]);
    if (!writer->open(path, cv::CAP_FFMPEG, code, fps, cv::Size(width, height))) return nullptr;
    return writer.release();
  } catch (const std::exception&) {
    return nullptr;
  }
}

__attribute__((visibility("default"))) int fleetmap_video_write(void* writer, const unsigned char* bgr, std::size_t step,
                                                                 int width, int height) {
  try {
    const cv::Mat frame(height, width, CV_8UC3, const_cast<unsigned char*>(bgr), step);
    static_cast<cv::VideoWriter*>(writer)->write(frame);
    return 0;
  } catch (const std::exception&) {
    return 1;
  }
}

__attribute__((visibility("default"))) void fleetmap_video_close(void* writer) {
  auto* w = static_cast<cv::VideoWriter*>(writer);
  try {
    w->release();
  } catch (const std::exception&) {
  }
  delete w;
}

}

// The loader (sim/run_output.cpp) casts what dlsym finds to these types.
static_assert(std::is_same_v<decltype(&fleetmap_video_open), fleetmap_video_open_fn>);
static_assert(std::is_same_v<decltype(&fleetmap_video_write), fleetmap_video_write_fn>);
static_assert(std::is_same_v<decltype(&fleetmap_video_close), fleetmap_video_close_fn>);
