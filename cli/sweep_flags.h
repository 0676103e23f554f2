#pragma once
// The sweep flags of `fleetmap bench`: each replaces the sweep file's value. Lists are as typed.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sweep/sweep.h"

namespace fleetmap::cli {

struct SweepFlags {
  std::optional<std::string> maps, strategies, robots;
  std::optional<int> seeds;
  std::optional<std::uint64_t> first_seed;
  std::optional<std::string> scenario;  // a scenario file: the base
  std::optional<int> steps;
  std::optional<std::string> localization;
  std::optional<std::string> merging;     // known, rendezvous or overlap
  std::optional<std::string> comm_range;  // metres, or "inf"
  std::optional<double> sensor_range;
  std::optional<double> resolution;  // metres per cell of bare image maps
  std::vector<std::string> vary;  // "SETTING=V1,V2", each a further axis (replacing the file's)
  std::vector<std::string> set;   // "FAMILY.KEY=VALUE", a member's parameter in every run

  bool any() const {
    return maps || strategies || robots || seeds || first_seed || scenario || steps || localization || merging ||
           comm_range || sensor_range || resolution || !vary.empty() || !set.empty();
  }
};

// Applies the flags over `sweep` (relative paths are relative to the working directory); errors
// name the flag. Numbers were checked by the flags' validators (the same ranges as the file's).
void apply_sweep_flags(sweep::Sweep& sweep, const SweepFlags& flags);

// "--shard K/N"; throws InputError naming the flag.
sweep::Shard parse_shard(const std::string& text);

}  // namespace fleetmap::cli
