// Not a Google Benchmark: SLAM methods on a real laser log scored by the relation metric of
// Kuemmerle et al. 2009, with CPU time, the real-time factor (log duration / CPU time) and peak
// memory. One markdown row per method; each method runs in a child process of its own, so that
// its peak memory is its own.
//
//   fleetmap_bench_log_slam LOG RELATIONS [METHOD ...]   (default: every method for logs)
#include <fmt/format.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <numbers>
#include <string>
#include <vector>

#include "experiments/log_slam.h"
#include "io/laser_log.h"
#include "localization/relation_metric.h"

namespace fm = fleetmap;

namespace {

std::string row(const std::string& log, const std::string& relations_path, const std::string& method) {
  const auto relations = fm::io::read_relations(relations_path);
  fm::experiments::LogSlamOptions o;
  o.method = method;
  const double cpu0 = double(std::clock()) / CLOCKS_PER_SEC;
  const auto r = fm::experiments::run_log_slam([&] { return std::make_unique<fm::io::LaserLogReader>(log); }, o);
  const double cpu = double(std::clock()) / CLOCKS_PER_SEC - cpu0;
  std::vector<fm::localization::TimedPose> trajectory;
  for (std::size_t i = 0; i < r.trajectory.size(); ++i) trajectory.push_back({r.times_s[i], r.trajectory[i]});
  // Logs' times need not rise (the Intel lab's go back four times): relation_errors wants them sorted.
  std::stable_sort(trajectory.begin(), trajectory.end(), [](const auto& a, const auto& b) { return a.time_s < b.time_s; });
  std::vector<fm::localization::ReferenceRelation> reference;
  for (const auto& rel : relations) reference.push_back({rel.t1, rel.t2, rel.t1_tolerance, rel.t2_tolerance, rel.motion});
  const auto e = fm::localization::relation_errors(trajectory, reference);
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  constexpr double kDeg = 180.0 / std::numbers::pi;
  std::string counters;
  for (const auto& [name, value] : r.counters) counters += fmt::format("{}{} {:g}", counters.empty() ? "" : ", ", name, value);
  return fmt::format("| {} | {:.4f} ± {:.4f} | {:.3f} ± {:.3f} | {}/{} | {:.2f} | {:.1f} | {:.0f} | {} |\n", method,
                     e.translation_mean_m, e.translation_std_m, e.rotation_mean_rad * kDeg, e.rotation_std_rad * kDeg,
                     e.matched, e.relations, cpu, cpu > 0 ? r.log_duration_s / cpu : 0.0, double(usage.ru_maxrss) / 1024.0,
                     counters);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    fmt::print(stderr, "usage: {} LOG RELATIONS [METHOD ...]\n", argv[0]);
    return 2;
  }
  std::vector<std::string> methods(argv + 3, argv + argc);
  if (methods.empty()) methods = fm::experiments::log_slam_methods();
  fmt::print("| method | translational error (m) | rotational error (deg) | relations | CPU (s) | x real time | peak memory (MB) | counters |\n");
  fmt::print("|---|---|---|---|---|---|---|---|\n");
  std::fflush(stdout);
  for (const auto& method : methods) {
    int fds[2];
    if (pipe(fds) != 0) return 1;
    const pid_t child = fork();
    if (child == 0) {
      close(fds[0]);
      std::string text;
      try {
        text = row(argv[1], argv[2], method);
      } catch (const std::exception& e) {
        text = fmt::format("| {} | failed: {} |\n", method, e.what());
      }
      (void)!write(fds[1], text.data(), text.size());
      _exit(0);
    }
    close(fds[1]);
    std::string text;
    char buffer[4096];
    for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) text.append(buffer, std::size_t(n));
    close(fds[0]);
    int status = 0;
    waitpid(child, &status, 0);
    fmt::print("{}", text.empty() ? fmt::format("| {} | crashed |\n", method) : text);
    std::fflush(stdout);
  }
  return 0;
}
