#pragma once
// Whole-file reads with user-facing errors, and writes that never leave a half-written file.
#include <filesystem>
#include <string>
#include <string_view>

namespace fleetmap::core {

// Reads a whole file. Throws InputError naming the path when it is missing, a directory,
// unreadable, or larger than `max_bytes`.
std::string read_file(const std::filesystem::path& path, std::size_t max_bytes = std::size_t{1} << 31);

// Writes `bytes` to a temporary file next to `path` and renames it over `path`, so readers see
// the old file or the new one, never a truncated one. Creates missing parent directories.
// Throws fleetmap::Error naming the path on failure.
void write_file_atomic(const std::filesystem::path& path, std::string_view bytes);

// Creates a directory (and its parents) for outputs; throws InputError naming it on failure.
void ensure_directory(const std::filesystem::path& dir);

}  // namespace fleetmap::core
