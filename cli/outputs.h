#pragma once
// Output files named on the command line: checked before the work, written whole at the end, and
// "-" or /dev/stdout written to the standard output.
#include <opencv2/core/mat.hpp>

#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace fleetmap::cli {

// One output named by a flag ("--json" and its value).
struct OutputFile {
  std::string flag;
  std::filesystem::path path;  // empty: not asked for
};

// Checks every output before the work starts: none may be an input, a device or a folder, at
// most one may be the standard output, and each folder must be writable. Throws InputError.
void check_outputs(const std::vector<OutputFile>& outputs, const std::vector<std::filesystem::path>& inputs);

// Where the command's own report goes: stderr when an output is the standard output (so that the
// output stays clean for a pipe), stdout otherwise.
std::FILE* report_stream(const std::vector<OutputFile>& outputs);

// Writes `bytes` to the standard output or atomically to the file.
void write_output(const std::filesystem::path& path, std::string_view bytes);
// A picture as PNG (to the standard output too).
void write_picture(const std::filesystem::path& path, const cv::Mat& image);

}  // namespace fleetmap::cli
