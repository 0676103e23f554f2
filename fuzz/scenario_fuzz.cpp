// Fuzzes the scenario parser and validator; a scenario that parses must write itself back as YAML
// that parses to the same scenario.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "sim/scenario.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace sim = fleetmap::sim;
  try {
    const sim::Scenario s =
        sim::parse_scenario(std::string(reinterpret_cast<const char*>(data), size), "fuzz.yaml", "/nonexistent");
    sim::validate_scenario(s);
    const std::string yaml = sim::scenario_to_yaml(s);
    const sim::Scenario back = sim::parse_scenario(yaml, "round-trip.yaml", "/nonexistent");
    if (sim::scenario_to_yaml(back) != yaml) __builtin_trap();
  } catch (const fleetmap::InputError&) {
  }
  return 0;
}
