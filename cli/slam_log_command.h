#pragma once
// `fleetmap slam --log FILE`: one SLAM method over a real robot's laser log, the map, the
// trajectory and the metrics written to a folder, scored against reference relations when given.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace fleetmap::cli {

struct SlamLogFlags {
  std::string log;
  std::string method = "graph-slam";
  std::string relations;  // empty: none
  std::optional<std::uint64_t> seed;
  std::string out;        // empty: out/slam_<log name>
  bool quiet = false;
  std::vector<std::string> set;  // --set localization.KEY=VALUE: the method's own parameters
};

// The --help text of the log mode (methods, outputs).
std::string slam_log_help();
// The methods --method accepts.
std::string slam_log_method_names();
int run_slam_log(const SlamLogFlags& flags);

}  // namespace fleetmap::cli
