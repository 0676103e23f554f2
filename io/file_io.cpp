#include "io/file_io.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include "core/error.h"

namespace fleetmap::io {

namespace fs = std::filesystem;

namespace {

std::string quoted_path(const fs::path& p) { return printable(p.string()); }

// What a non-regular file is, for messages.
std::string kind_of(fs::file_type type) {
  switch (type) {
    case fs::file_type::directory: return "a directory";
    case fs::file_type::character: return "a character device";
    case fs::file_type::block: return "a block device";
    case fs::file_type::fifo: return "a FIFO (named pipe)";
    case fs::file_type::socket: return "a socket";
    case fs::file_type::symlink: return "a symbolic link";
    default: return "not a regular file";
  }
}

bool is_link_loop(const std::error_code& ec) { return ec == std::errc::too_many_symbolic_link_levels; }

// Where writing to `path` lands: the path itself, or the end of its chain of symbolic links.
fs::path link_target(const fs::path& path) {
  fs::path p = path;
  for (int hops = 0; hops < 40; ++hops) {
    std::error_code ec;
    if (!fs::is_symlink(fs::symlink_status(p, ec))) return p;
    const fs::path next = fs::read_symlink(p, ec);
    if (ec) return p;
    p = next.is_absolute() ? next : p.parent_path() / next;
  }
  throw InputError(quoted_path(path) + ": too many levels of symbolic links (a link loop)");
}

// Throws unless `path` (a link's target) is absent or a regular file.
void check_replaceable(const fs::path& path, const fs::path& named, const std::string& what) {
  std::error_code ec;
  const auto status = fs::symlink_status(path, ec);
  if (ec && is_link_loop(ec)) throw InputError(what + quoted_path(named) + ": too many levels of symbolic links (a link loop)");
  if (!fs::exists(status) || fs::is_regular_file(status)) return;
  throw InputError(what + quoted_path(named) + ": exists and is " + kind_of(status.type()) +
                   "; fleetmap writes only regular files (use - for the standard output)");
}

// Plain names inside a folder: no separators, not "." or "..".
bool plain_name(const std::string& name) {
  return !name.empty() && name != "." && name != ".." && name.find('/') == std::string::npos &&
         name.find('\0') == std::string::npos;
}

}  // namespace

std::string printable(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) out += fmt::format("\\x{:02X}", u);
    else out += c;
  }
  return out;
}

std::string read_file(const fs::path& path, std::size_t max_bytes) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (ec && is_link_loop(ec)) throw InputError(quoted_path(path) + ": too many levels of symbolic links (a link loop)");
  if (!fs::exists(status)) throw InputError(quoted_path(path) + ": no such file");
  if (fs::is_directory(status)) throw InputError(quoted_path(path) + ": is a directory, expected a file");
  if (!fs::is_regular_file(status)) {
    throw InputError(quoted_path(path) + ": is " + kind_of(status.type()) + ", expected a regular file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(quoted_path(path) + ": cannot open for reading (" + std::strerror(errno) + ")");
  const auto too_large = [&] {
    return InputError(fmt::format("{}: file too large (over the limit of {} bytes)", quoted_path(path), max_bytes));
  };
  const auto size = fs::file_size(path, ec);
  if (!ec && size > max_bytes) throw too_large();
  std::string bytes;
  if (!ec) bytes.reserve(size);
  // Read in pieces up to the limit: the size on disk may change while we read.
  char buffer[1 << 16];
  while (in) {
    in.read(buffer, sizeof buffer);
    const auto got = static_cast<std::size_t>(in.gcount());
    if (bytes.size() + got > max_bytes) throw too_large();
    bytes.append(buffer, got);
  }
  if (in.bad()) throw InputError(quoted_path(path) + ": read error");
  return bytes;
}

void ensure_directory(const fs::path& dir) {
  if (dir.empty()) return;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !is_folder(dir)) {
    throw InputError(quoted_path(dir) + ": cannot create output directory (" + ec.message() + ")");
  }
}

bool path_exists(const fs::path& path) noexcept {
  std::error_code ec;
  return fs::exists(path, ec);
}

bool is_regular_file(const fs::path& path) noexcept {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

bool is_folder(const fs::path& path) noexcept {
  std::error_code ec;
  return fs::is_directory(path, ec);
}

bool is_standard_output(const fs::path& path) { return path == "-" || path == "/dev/stdout"; }

bool same_file(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::equivalent(a, b, ec) && !ec) return true;
  // "missing/../x" names x once the missing folder is made: compare where the paths lead.
  std::error_code ea, eb;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ea), ea), cb = fs::weakly_canonical(fs::absolute(b, eb), eb);
  return !ea && !eb && ca == cb && fs::exists(cb, eb);
}

namespace {

// check_output_file with the output already named for messages (`label`: "--json out.json").
void check_output(const fs::path& output, const std::vector<fs::path>& inputs, const std::string& label) {
  if (is_standard_output(output)) return;
  const fs::path target = link_target(output);
  for (const auto& input : inputs) {
    if (same_file(target, input)) {
      throw InputError(label + ": is the input " + quoted_path(input) +
                       "; fleetmap never overwrites an input, choose another output");
    }
  }
  std::error_code ec;
  const auto status = fs::symlink_status(target, ec);
  if (ec && is_link_loop(ec)) throw InputError(label + ": too many levels of symbolic links (a link loop)");
  if (fs::exists(status) && !fs::is_regular_file(status)) {
    throw InputError(label + ": exists and is " + kind_of(status.type()) +
                     "; fleetmap writes only regular files (use - for the standard output)");
  }
  // The folder: an existing one must be a folder we may write in; a missing one must be makeable.
  fs::path folder = target.parent_path();
  while (!folder.empty() && !fs::exists(folder, ec)) {
    folder = folder.has_parent_path() && folder.parent_path() != folder ? folder.parent_path() : fs::path();
  }
  if (folder.empty()) folder = ".";
  if (!fs::is_directory(folder, ec)) throw InputError(label + ": " + quoted_path(folder) + " is not a folder");
  if (::access(folder.c_str(), W_OK | X_OK) != 0) {
    throw InputError(label + ": cannot write in " + quoted_path(folder) + " (" + std::strerror(errno) + ")");
  }
}

}  // namespace

void check_output_file(const fs::path& output, const std::vector<fs::path>& inputs, const std::string& what) {
  check_output(output, inputs, (what.empty() ? std::string() : what + " ") + quoted_path(output));
}

void write_file_atomic(const fs::path& path, std::string_view bytes) {
  if (is_standard_output(path)) throw Error(path.string() + ": the standard output is written by the command line");
  static std::atomic<unsigned> counter{0};
  const fs::path target = link_target(path);
  check_replaceable(target, path, "");
  ensure_directory(target.parent_path());
  fs::path tmp = target;
  tmp += ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error(quoted_path(path) + ": cannot write (" + std::strerror(errno) + ")");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) {
      std::error_code ignored;
      fs::remove(tmp, ignored);
      throw Error(quoted_path(path) + ": write failed (disk full?)");
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw Error(quoted_path(path) + ": cannot replace file (" + ec.message() + ")");
  }
}

OutputFolder::OutputFolder(fs::path dir, std::string command, std::vector<std::string> files,
                           const std::vector<fs::path>& inputs, std::string what)
    : dir_(std::move(dir)), command_(std::move(command)), what_(std::move(what)), files_(std::move(files)) {
  if (dir_.empty()) dir_ = ".";
  const std::string where = what_ + ": ";
  for (const auto& name : files_) {
    if (!plain_name(name)) throw Error("OutputFolder: '" + name + "' is not a plain file name");
  }
  std::error_code ec;
  const auto status = fs::status(dir_, ec);
  if (ec && is_link_loop(ec)) throw InputError(where + "too many levels of symbolic links (a link loop)");
  if (fs::exists(status) && !fs::is_directory(status)) {
    throw InputError(where + "is " + (fs::is_regular_file(status) ? std::string("a file") : kind_of(status.type())) +
                     ", expected a folder for the outputs");
  }
  for (const auto& name : files_) check_output(dir_ / name, inputs, where + quoted_path(dir_ / name));
  if (!fs::exists(status)) return;

  // No input inside: an earlier run's output read as this run's input would be replaced or removed.
  for (const auto& input : inputs) {
    std::error_code e1;
    const fs::path folder = fs::weakly_canonical(fs::absolute(input, e1).parent_path(), e1);
    if (!e1 && same_file(folder, dir_)) {
      throw InputError(where + "holds the input " + quoted_path(input) +
                       "; a run writes into a folder of its own: choose another output folder, or move the input");
    }
  }
  const fs::path list = dir_ / kListName;
  if (fs::is_regular_file(list, ec)) {
    const std::string text = read_file(list, 1 << 20);
    const std::string header = text.substr(0, text.find('\n'));
    if (header.rfind("# fleetmap ", 0) != 0) {
      throw InputError(where + quoted_path(list) + " was not written by fleetmap; choose a new or empty folder");
    }
    const std::string other = header.substr(11, header.find(':') == std::string::npos ? std::string::npos : header.find(':') - 11);
    if (other != command_) {
      throw InputError(where + "holds the outputs of 'fleetmap " + printable(other) + "', not of 'fleetmap " + command_ +
                       "'; choose a new or empty folder");
    }
    std::size_t at = header.size() + 1;
    while (at < text.size()) {
      const std::size_t end = std::min(text.find('\n', at), text.size());
      const std::string line = text.substr(at, end - at);
      at = end + 1;
      if (plain_name(line) && line != kListName) earlier_.push_back(line);
    }
  }
  // A listed file, or a temporary of one that a killed run left ("<name>.tmp.<pid>.<n>", a video's
  // "<stem>.partial<ext>"). Without a list, every file is the user's.
  const auto ours = [&](const std::string& name) {
    if (name == kListName || name.rfind(std::string(kListName) + ".tmp.", 0) == 0) return true;
    for (const auto& n : earlier_) {
      if (name == n || name.rfind(n + ".tmp.", 0) == 0) return true;
      const fs::path p = n;
      if (name == p.stem().string() + ".partial" + p.extension().string()) return true;
    }
    return false;
  };
  std::vector<std::string> foreign;
  for (const auto& entry : fs::directory_iterator(dir_, ec)) {
    const std::string name = entry.path().filename().string();
    if (!ours(name)) foreign.push_back(name);
  }
  if (ec) throw InputError(where + "cannot list the folder (" + ec.message() + ")");
  if (!foreign.empty()) {
    std::sort(foreign.begin(), foreign.end());
    throw InputError(where + fmt::format("holds {} that no earlier 'fleetmap {}' run wrote ({}'{}'); fleetmap writes "
                                         "only into a new or empty folder, or one of its own runs: choose another",
                                         foreign.size() == 1 ? "a file" : "files", command_,
                                         foreign.size() == 1 ? "" : "such as ", printable(foreign.front())));
  }
  // The earlier files are replaced or removed: they must be regular files too.
  for (const auto& name : earlier_) check_output(dir_ / name, inputs, where + quoted_path(dir_ / name));
}

void OutputFolder::claim() {
  ensure_directory(dir_);
  std::vector<std::string> claimed = earlier_;
  for (const auto& n : files_) {
    if (std::find(claimed.begin(), claimed.end(), n) == claimed.end()) claimed.push_back(n);
  }
  try {
    write_list(claimed);
  } catch (const Error& e) {
    throw InputError(what_ + ": cannot write in the folder (" + e.what() + ")");
  }
  // Temporaries of a killed run are nobody's outputs.
  std::error_code ec;
  std::vector<fs::path> leftovers;
  for (const auto& entry : fs::directory_iterator(dir_, ec)) {
    const std::string name = entry.path().filename().string();
    const bool listed = std::find(claimed.begin(), claimed.end(), name) != claimed.end();
    if (!listed && name != kListName && entry.is_regular_file(ec)) leftovers.push_back(entry.path());
  }
  for (const auto& p : leftovers) fs::remove(p, ec);
}

std::vector<std::string> OutputFolder::names(const std::vector<fs::path>& paths) {
  std::vector<std::string> out;
  for (const auto& p : paths) out.push_back(p.filename().string());
  return out;
}

void OutputFolder::write_list(const std::vector<std::string>& names) const {
  std::string text = "# fleetmap " + command_ +
                     ": the files of this run; a new run into this folder replaces them and removes those it does "
                     "not write again\n";
  for (const auto& n : names) text += n + "\n";
  write_file_atomic(dir_ / kListName, text);
}

void OutputFolder::finish(const std::vector<std::string>& written) {
  write_list(written);
  std::vector<std::string> candidates = earlier_;
  candidates.insert(candidates.end(), files_.begin(), files_.end());
  for (const auto& name : candidates) {
    if (std::find(written.begin(), written.end(), name) != written.end()) continue;
    std::error_code ec;
    const auto status = fs::symlink_status(dir_ / name, ec);
    if (fs::is_regular_file(status) || fs::is_symlink(status)) fs::remove(dir_ / name, ec);
  }
  earlier_ = written;
}

}  // namespace fleetmap::io
