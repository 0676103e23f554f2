#pragma once
// The C interface of the video module (sim/video_module.cpp, built as its own shared object and
// loaded when a RunVideo is made): OpenCV's video writer and the FFmpeg it links are
// hundreds of shared libraries that would otherwise load, and cost 0.1 s, at every start of
// every program that links fleetmap. Internal: not installed.
#include <cstddef>

extern "C" {

// Opens a writer of `fourcc` (4 characters) at `fps`, frames width x height, through OpenCV's
// FFmpeg backend; nullptr when it cannot write that codec.
typedef void* (*fleetmap_video_open_fn)(const char* path, const char* fourcc, double fps, int width, int height);
// Appends a frame of 8-bit BGR pixels, rows `step` bytes apart, of the size the writer was opened
// with. Returns 0 on success.
typedef int (*fleetmap_video_write_fn)(void* writer, const unsigned char* bgr, std::size_t step, int width, int height);
// Finishes the file and frees the writer.
typedef void (*fleetmap_video_close_fn)(void* writer);

}
