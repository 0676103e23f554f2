#include "io/file_kind.h"

#include <algorithm>
#include <array>
#include <vector>

#include "core/error.h"

namespace fleetmap::io {

namespace {

struct KindInfo {
  YamlFileKind kind;
  const char* name;  // "a sweep file"
  const char* use;   // the command that reads it, FILE standing for the file
  // Top-level keys that no other kind has (sim/scenario.cpp, sweep/sweep.cpp,
  // experiments/*_scenario.cpp and corridor_experiment.cpp, io/map_io.cpp).
  std::vector<std::string> own_keys;
};

const std::array<KindInfo, 4>& kinds() {
  static const std::array<KindInfo, 4> kKinds = {{
      {YamlFileKind::ExploreScenario, "an exploration scenario",
       "fleetmap explore --scenario FILE (or fleetmap bench --scenario FILE as a sweep's base)",
       {"map", "map_resolution", "communication", "exploration", "lookahead", "outputs"}},
      {YamlFileKind::Sweep, "a sweep file", "fleetmap bench --sweep FILE",
       {"maps", "strategies", "first_seed", "scenario", "comm_range", "sensor_range", "vary"}},
      {YamlFileKind::SlamScenario, "a SLAM scenario", "fleetmap slam --scenario FILE",
       {"experiment", "method", "runs", "paper_table", "single_robot", "room", "initial_sigma", "exchange", "polynomial",
        "world", "drive", "odometry", "laser", "methods", "merge_by_detection", "speed", "particles", "alignment", "cases",
        "parts"}},
      {YamlFileKind::MapServerMap, "a map (map_server YAML)",
       "fleetmap explore --map FILE, or name it as a scenario's or sweep's map",
       {"image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh", "mode"}},
  }};
  return kKinds;
}

const KindInfo& info(YamlFileKind kind) {
  return *std::find_if(kinds().begin(), kinds().end(), [&](const KindInfo& k) { return k.kind == kind; });
}

int own_keys_in(const YAML::Node& root, const KindInfo& kind) {
  int n = 0;
  for (const auto& kv : root) {
    if (!kv.first.IsScalar()) continue;
    const std::string key = kv.first.Scalar();
    n += std::find(kind.own_keys.begin(), kind.own_keys.end(), key) != kind.own_keys.end();
  }
  return n;
}

}  // namespace

std::optional<YamlFileKind> recognise_yaml_file(const YAML::Node& root) {
  if (!root || !root.IsMap()) return std::nullopt;
  if (root["experiment"]) return YamlFileKind::SlamScenario;
  std::optional<YamlFileKind> best;
  int most = 1;
  for (const auto& k : kinds()) {
    if (const int n = own_keys_in(root, k); n > most) best = k.kind, most = n;
  }
  return best;
}

void check_yaml_file_kind(const YAML::Node& root, const std::string& source, YamlFileKind expected) {
  const auto kind = recognise_yaml_file(root);
  if (!kind || *kind == expected || own_keys_in(root, info(expected)) > 0) return;
  std::string use = info(*kind).use;
  for (std::size_t at; (at = use.find("FILE")) != std::string::npos;) use.replace(at, 4, source);
  throw InputError(source + " is " + info(*kind).name + ", not " + info(expected).name + ": use " + use);
}

}  // namespace fleetmap::io
