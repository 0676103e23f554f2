#include "cli/outputs.h"

#include "core/error.h"
#include "io/file_io.h"
#include "io/map_image.h"
#include "io/map_io.h"

namespace fleetmap::cli {

namespace fs = std::filesystem;

void check_outputs(const std::vector<OutputFile>& outputs, const std::vector<fs::path>& inputs) {
  const OutputFile* to_stdout = nullptr;
  for (const auto& o : outputs) {
    if (o.path.empty()) continue;
    if (io::is_standard_output(o.path)) {
      if (to_stdout) throw InputError(to_stdout->flag + " and " + o.flag + ": only one output can go to the standard output");
      to_stdout = &o;
      continue;
    }
    for (const auto& other : outputs) {
      if (&other == &o || other.path.empty()) continue;
      if (&other < &o && (other.path == o.path || io::same_file(other.path, o.path))) {
        throw InputError(other.flag + " and " + o.flag + ": both name " + io::printable(o.path.string()) +
                         "; give each output its own file");
      }
    }
    io::check_output_file(o.path, inputs, o.flag);
  }
}

std::FILE* report_stream(const std::vector<OutputFile>& outputs) {
  for (const auto& o : outputs) {
    if (!o.path.empty() && io::is_standard_output(o.path)) return stderr;
  }
  return stdout;
}

void write_output(const fs::path& path, std::string_view bytes) {
  if (!io::is_standard_output(path)) return io::write_file_atomic(path, bytes);
  if (std::fwrite(bytes.data(), 1, bytes.size(), stdout) != bytes.size() || std::fflush(stdout) != 0) {
    throw Error("cannot write to the standard output");
  }
}

void write_picture(const fs::path& path, const cv::Mat& image) {
  const std::string ext = io::is_standard_output(path) ? ".png" : path.extension().string();
  write_output(path, io::encode_image(ext, image, path.string()));
}

}  // namespace fleetmap::cli
