// Not a Google Benchmark: reference relations (Kuemmerle et al. 2009) built from a corrected log's own
// poses (the FLASER pose field of GMapping's `-corrected` logs), so that a SLAM method run from the
// log's raw odometry can be scored against GMapping's answer with the relation metric. Writes the
// relations file format fleetmap reads (`t1 t2 x y z roll pitch yaw`) to stdout:
//
//   fleetmap_bench_corrected_relations LOG > LOG.relations.txt
//
// Relations, between scans i < j of the log (indices of the scans kept, see below):
//   - consecutive scans (j = i + 1) and scans kStride apart (j = i + kStride): local consistency;
//   - loop pairs: every kStride-th scan i and every kStride-th scan j at least kLoopGap scans later
//     whose laser positions are within kLoopRadius_m: the revisits a loop closure must get right.
// A scan whose timestamp another scan shares is left out (a relation could not name it).
#include <fmt/format.h>

#include <cmath>
#include <exception>
#include <map>
#include <string>
#include <vector>

#include "core/angle.h"
#include "io/laser_log.h"

namespace fm = fleetmap;

namespace {

constexpr std::size_t kStride = 10;
constexpr std::size_t kLoopGap = 100;
constexpr double kLoopRadius_m = 1.0;

struct Scan {
  std::string timestamp;
  fm::core::Pose2 pose;
};

void print_relation(const Scan& a, const Scan& b) {
  const fm::core::Pose2 m = a.pose.inverse().compose(b.pose);
  fmt::print("{} {} {:.6f} {:.6f} 0 0 0 {:.6f}\n", a.timestamp, b.timestamp, m.x, m.y, fm::core::normalize_angle(m.theta));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    fmt::print(stderr, "usage: {} LOG   (a corrected CARMEN log: FLASER lines with the corrected pose)\n", argv[0]);
    return 2;
  }
  std::vector<Scan> all;
  std::map<std::string, int> uses;
  try {
    fm::io::LaserLogReader log{std::filesystem::path(argv[1])};
    while (const auto s = log.next()) {
      if (!s->logged_pose) {
        fmt::print(stderr, "{}: line {}: the scan has no logged pose: not a corrected log\n", argv[1], s->line);
        return 2;
      }
      all.push_back({s->timestamp, *s->logged_pose});
      ++uses[s->timestamp];
    }
  } catch (const std::exception& e) {
    fmt::print(stderr, "{}\n", e.what());
    return 2;
  }
  std::vector<Scan> scans;
  for (auto& s : all) {
    if (uses[s.timestamp] == 1) scans.push_back(std::move(s));
  }
  const std::size_t n = scans.size();
  std::size_t local = 0, loops = 0;
  for (std::size_t i = 0; i + 1 < n; ++i) print_relation(scans[i], scans[i + 1]), ++local;
  for (std::size_t i = 0; i + kStride < n; ++i) print_relation(scans[i], scans[i + kStride]), ++local;
  for (std::size_t i = 0; i < n; i += kStride) {
    for (std::size_t j = i + kLoopGap; j < n; j += kStride) {
      if ((scans[i].pose.position() - scans[j].pose.position()).norm() <= kLoopRadius_m) print_relation(scans[i], scans[j]), ++loops;
    }
  }
  fmt::print(stderr, "{}: {} scans ({} left out: shared timestamps), {} local relations, {} loop relations\n", argv[1],
             n, all.size() - n, local, loops);
  return 0;
}
