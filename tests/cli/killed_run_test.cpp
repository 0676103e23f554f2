// A run killed at any moment leaves no truncated file: every output is written to a temporary name
// and renamed, so each file in the output folder is either absent or whole.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <thread>
#include <vector>

#include "tests/cli_run.h"

extern char** environ;

namespace fleetmap::cli {
namespace {

namespace fs = std::filesystem;
using fleetmap::testing::slurp;
using fleetmap::testing::TempDir;

pid_t spawn_fleetmap(const std::vector<std::string>& args) {
  std::vector<std::string> all = {FLEETMAP_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, FLEETMAP_BINARY, &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

bool is_temporary(const std::string& name) {
  return name.find(".tmp.") != std::string::npos || name.find(".partial") != std::string::npos;
}

// Every final-named file in `dir` is whole: images decode, JSON parses, YAML and .bt are not empty.
void expect_whole_files(const fs::path& dir, const std::string& when) {
  if (!fs::exists(dir)) return;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (is_temporary(name)) continue;  // never read by anyone; the next run overwrites nothing of it
    const std::string ext = entry.path().extension().string();
    SCOPED_TRACE(when + ": " + name);
    if (ext == ".png" || ext == ".pgm") {
      EXPECT_FALSE(cv::imread(entry.path().string(), cv::IMREAD_UNCHANGED).empty());
    } else if (ext == ".json") {
      EXPECT_TRUE(nlohmann::json::accept(slurp(entry.path())));
    } else {
      EXPECT_GT(fs::file_size(entry.path()), 0u);
    }
  }
}

TEST(KilledRun, LeavesNoTruncatedFile) {
  TempDir dir;
  const fs::path out = dir / "run";
  // Kill at the moment the first output appears, then later each time (0, 10, 20, 40, ... ms), until
  // a run ends on its own: the kills land while the outputs are being written.
  int killed = 0;
  for (int delay_ms = 0; delay_ms <= 2560; delay_ms = delay_ms == 0 ? 10 : 2 * delay_ms) {
    const pid_t pid = spawn_fleetmap({"explore", "--map", "campus", "--robots", "2", "--steps", "3", "--out",
                                      out.string(), "--quiet"});
    ASSERT_GT(pid, 0);
    int status = 0;
    bool ended = false;
    // Wait for the folder to get its first file (or the run to end).
    while (!ended) {
      if (waitpid(pid, &status, WNOHANG) == pid) ended = true;
      else if (fs::exists(out) && !fs::is_empty(out)) break;
      else std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    if (!ended) {
      std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      killed += WIFSIGNALED(status) ? 1 : 0;
    }
    expect_whole_files(out, "kill " + std::to_string(delay_ms) + " ms after the first file");
    if (!WIFSIGNALED(status)) break;  // the run finished before the kill: later kills would too
  }
  EXPECT_GT(killed, 0) << "no run was killed while writing";
  // Whatever a killed run left, the next run takes the folder: it ends well and leaves exactly its
  // own files (listed in outputs.txt), no temporaries.
  const auto last = fleetmap::testing::run_fleetmap("explore --map campus --robots 2 --steps 3 --quiet --out run", dir);
  ASSERT_EQ(last.exit_code, 0) << "a run into a killed run's folder failed: " << last.err;
  const std::string listed = slurp(out / "outputs.txt");
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    EXPECT_FALSE(is_temporary(name)) << name;
    if (name != "outputs.txt") {
      EXPECT_NE(listed.find("\n" + name + "\n"), std::string::npos) << name << " not listed";
    }
  }
}

}  // namespace
}  // namespace fleetmap::cli
