#include "cli/map_notes.h"

#include <fmt/format.h>

#include <filesystem>

#include "io/file_io.h"

namespace fleetmap::cli {

void print_map_notes(const std::string& source, const io::MapLoadOptions& options, bool resolution_given,
                     const std::string& resolution_source) {
  std::error_code ec;
  // A file of that name is read before a built-in map of that name (maps::load_map_source).
  if (!std::filesystem::is_regular_file(source, ec)) return;
  for (const auto& note : io::map_reading_notes(source, options, resolution_given ? std::string() : resolution_source)) {
    fmt::print(stderr, "fleetmap: note: {}\n", io::printable(note));
  }
}

std::string map_notes_suffix(const std::string& source, const io::MapLoadOptions& options, bool resolution_given) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(source, ec)) return "";
  const auto notes =
      io::map_reading_notes(source, options, resolution_given ? std::string() : "the default; --resolution sets it");
  if (notes.empty()) return "";
  std::string text;
  for (const auto& note : notes) text += (text.empty() ? " (" : "; ") + note;
  return text + ")";
}

}  // namespace fleetmap::cli
