// Fuzzes the two kinds of SLAM scenario `fleetmap slam` reads: the polynomial SLAM experiment
// (parser, validator, and for small rooms the set-up that checks every path against the walls) and
// the corridor experiment's options.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "experiments/corridor_experiment.h"
#include "experiments/slam_experiment.h"
#include "experiments/slam_scenario.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace experiments = fleetmap::experiments;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    if (experiments::is_corridor_scenario(text, "fuzz.yaml")) {
      experiments::parse_corridor_options(text, "fuzz.yaml");
      return 0;
    }
    const experiments::SlamScenario s = experiments::parse_slam_scenario(text, "fuzz.yaml");
    experiments::validate_slam_scenario(s);
    // The set-up rasterizes the room: worth it only for rooms of modest size and paths of few steps.
    double lo_x = 1e300, lo_y = 1e300, hi_x = -1e300, hi_y = -1e300;
    for (const auto& p : s.room.boundary) {
      lo_x = std::min(lo_x, p.x()), lo_y = std::min(lo_y, p.y());
      hi_x = std::max(hi_x, p.x()), hi_y = std::max(hi_y, p.y());
    }
    const double cells = (hi_x - lo_x) * (hi_y - lo_y) / (s.room.resolution_m * s.room.resolution_m);
    if (cells < 1e5 && s.steps <= 2000) experiments::prepare_slam(s);
  } catch (const fleetmap::InputError&) {
  }
  return 0;
}
