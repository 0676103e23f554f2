// Fuzzes the laser log reader (CARMEN and DP-SLAM lines, with the maximum-range pass) and the
// relations parser: every input ends in scans or one InputError.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "io/laser_log.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace io = fleetmap::io;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    io::LaserLogReader reader(text, "fuzz.log");
    while (const auto scan = reader.next()) {
      // What every consumer relies on: one angle per range, no negative or NaN range, a finite time.
      if (scan->scan.angles.size() != scan->scan.ranges.size() || !std::isfinite(scan->time_s)) __builtin_trap();
      for (const auto& r : scan->scan.ranges) {
        if (r && (!(*r >= 0.0) || !std::isfinite(*r))) __builtin_trap();
      }
    }
  } catch (const fleetmap::InputError&) {
  }
  try {
    (void)io::parse_relations(text, "fuzz.relations");
  } catch (const fleetmap::InputError&) {
  }
  return 0;
}
