#pragma once
// Files a user gives and files fleetmap writes. Inputs are read whole, only from regular files and
// up to a size limit; outputs are written to a temporary name and renamed, never over anything but
// a regular file, and never over an input. Folders of outputs belong to the run that writes them.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace fleetmap::io {

// Reads a whole file. Throws InputError naming the path when it is missing, a directory or any
// other non-regular file (a device, a FIFO, a socket: they may never end or block), behind a
// symbolic-link loop, unreadable, or larger than `max_bytes` (checked while reading too).
std::string read_file(const std::filesystem::path& path, std::size_t max_bytes = std::size_t{1} << 31);

// Writes `bytes` to a temporary file next to `path` and renames it over `path`, so readers see
// the old file or the new one, never a truncated one. Creates missing parent directories. A
// symbolic link is followed: its target is replaced, the link stays. Throws InputError when the
// path (or the link's target) exists and is not a regular file, fleetmap::Error on a failed write.
void write_file_atomic(const std::filesystem::path& path, std::string_view bytes);

// Creates a directory (and its parents) for outputs; throws InputError naming it on failure.
void ensure_directory(const std::filesystem::path& dir);

// Questions about a user's path that never throw: a name too long, a link loop or a missing
// permission is simply "no".
bool path_exists(const std::filesystem::path& path) noexcept;
bool is_regular_file(const std::filesystem::path& path) noexcept;
bool is_folder(const std::filesystem::path& path) noexcept;

// "-" and "/dev/stdout" name the standard output; the command line writes those itself.
bool is_standard_output(const std::filesystem::path& path);

// The same file on disk (one inode), whatever the paths and links that lead to it; false when
// either does not exist.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

// Checks, before any work, that an output file can be written without harm: it is not one of
// `inputs` (through any path, link or hard link), it is a regular file or does not exist yet (a
// link is judged by its target), and its folder is a folder or can be made. `what` names the
// output in messages ("--json"). Throws InputError. The standard output always passes.
void check_output_file(const std::filesystem::path& output, const std::vector<std::filesystem::path>& inputs,
                       const std::string& what);

// A folder that holds the outputs of one run, and nothing of the user's. When it exists it must
// be empty, or hold only the files an earlier run of the same command listed in its `outputs.txt`
// (and that run's temporary files): those are replaced, and the ones this run does not write
// again are removed, so no stale file of an earlier, larger run stays. No input may lie in it.
// Construction only checks (nothing is written, so bad input leaves no trace); claim() then makes
// the folder and lists the planned files in outputs.txt, so that a run killed at any moment
// leaves a folder the next run can take.
class OutputFolder {
 public:
  // `command` names the writer in outputs.txt ("explore"); `files` are the names the run will
  // write (plain names inside the folder); `inputs` are the files the run reads, which no output
  // may replace. `what` names the folder in messages ("--out out/office"). Throws InputError.
  OutputFolder(std::filesystem::path dir, std::string command, std::vector<std::string> files,
               const std::vector<std::filesystem::path>& inputs, std::string what);

  const std::filesystem::path& dir() const { return dir_; }
  // Creates the folder, lists the planned files, removes temporaries a killed run left.
  void claim();
  // Lists exactly `written` (names in the folder) in outputs.txt and removes the earlier run's
  // and the planned files that were not written.
  void finish(const std::vector<std::string>& written);
  // The names of `paths`, for finish().
  static std::vector<std::string> names(const std::vector<std::filesystem::path>& paths);

  static constexpr const char* kListName = "outputs.txt";

 private:
  void write_list(const std::vector<std::string>& names) const;

  std::filesystem::path dir_;
  std::string command_;
  std::string what_;
  std::vector<std::string> files_;
  std::vector<std::string> earlier_;  // files of the earlier run, from its outputs.txt
};

// `text` with control characters (line breaks among them) shown as \xHH, so that a name from a
// user cannot break a one-line message or drive the terminal.
std::string printable(std::string_view text);

}  // namespace fleetmap::io
