#pragma once
// Factories behind the strategy registry (strategy.cpp). Add a strategy by writing its file,
// declaring its factory here and adding one row to the registry table.
#include <memory>

#include "exploration/strategy.h"

namespace fleetmap::exploration {

std::unique_ptr<CoordinationStrategy> make_uncoordinated_strategy(const StrategyOptions& options);
std::unique_ptr<CoordinationStrategy> make_coordinated_strategy(const StrategyOptions& options);
std::unique_ptr<CoordinationStrategy> make_optimized_strategy(const StrategyOptions& options);
std::unique_ptr<CoordinationStrategy> make_directional_strategy(const StrategyOptions& options);
std::unique_ptr<CoordinationStrategy> make_market_strategy(const StrategyOptions& options);
std::unique_ptr<CoordinationStrategy> make_tour_strategy(const StrategyOptions& options);

}  // namespace fleetmap::exploration
