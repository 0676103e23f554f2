// Fuzzes the sweep-file parser and validator; a sweep that parses must write itself back as a sweep
// file that parses to the same sweep, and list its runs without failing.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "sweep/sweep.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace sweep = fleetmap::sweep;
  try {
    const sweep::Sweep s = sweep::parse_sweep(std::string(reinterpret_cast<const char*>(data), size), "fuzz.yaml", "/nonexistent");
    // Without a scenario file (none exists under /nonexistent) the sweep file holds every setting.
    const std::string yaml = sweep::sweep_to_yaml(s, "");
    const sweep::Sweep back = sweep::parse_sweep(yaml, "round-trip.yaml", "/nonexistent");
    if (sweep::sweep_to_yaml(back, "") != yaml) __builtin_trap();
    if (s.maps.size() * s.strategies.size() * s.robots.size() * std::size_t(s.seeds) <= 100'000 &&
        sweep::sweep_runs(s).size() != s.maps.size() * s.strategies.size() * s.robots.size() * std::size_t(s.seeds)) {
      __builtin_trap();
    }
  } catch (const fleetmap::InputError&) {
  }
  return 0;
}
