// The one file that speaks OMPL: it adapts OMPL's geometric planners to fleetmap's Planner.
//
// The problem given to OMPL: a point in the plane (the centre of a disc robot), in the grid's own
// frame (metres from the map's lower-left corner, so the map's box is the state-space bounds even
// under a rotated origin); a state is valid when FreeSpace::valid holds (clearance above the robot
// radius), a motion when FreeSpace::segment_valid holds (every crossed cell valid, exact, so no
// motion cuts a corner); the objective is path length. OMPL's log output is switched off: planning
// code never prints.
#include <ompl/base/MotionValidator.h>
#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/objectives/PathLengthOptimizationObjective.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/informedtrees/BITstar.h>
#include <ompl/geometric/planners/prm/PRMstar.h>
#include <ompl/geometric/planners/rrt/InformedRRTstar.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <mutex>

#include "planning/planners.h"

namespace fleetmap::planning {

namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;
using Clock = std::chrono::steady_clock;

// The share of the budget kept for path simplification.
constexpr double kSimplifyShare = 0.1;

Eigen::Vector2d to_world(const GridGeometry& g, const ob::State* s) {
  const auto* v = s->as<ob::RealVectorStateSpace::StateType>();
  return g.grid_to_world(Eigen::Vector2d(v->values[0], v->values[1]) / g.resolution());
}

void set_state(const GridGeometry& g, const Eigen::Vector2d& world, ob::State* s) {
  const Eigen::Vector2d m = g.world_to_grid(world) * g.resolution();
  auto* v = s->as<ob::RealVectorStateSpace::StateType>();
  v->values[0] = m.x();
  v->values[1] = m.y();
}

// Motion validity by exact cell traversal (FreeSpace), instead of OMPL's sampling along the motion.
class GridMotionValidator final : public ob::MotionValidator {
 public:
  GridMotionValidator(const ob::SpaceInformationPtr& si, const FreeSpace& space)
      : ob::MotionValidator(si), space_(space) {}

  bool checkMotion(const ob::State* s1, const ob::State* s2) const override {
    const GridGeometry& g = space_.geometry();
    return space_.segment_valid(to_world(g, s1), to_world(g, s2));
  }

  bool checkMotion(const ob::State* s1, const ob::State* s2, std::pair<ob::State*, double>& last_valid) const override {
    const GridGeometry& g = space_.geometry();
    const Eigen::Vector2d a = to_world(g, s1), b = to_world(g, s2);
    const std::optional<double> hit = space_.first_invalid_distance(a, b);
    if (!hit) return true;
    // Just short of the first invalid cell: still in the valid cell before it.
    const double length = (b - a).norm();
    const double fraction = length > 0.0 ? std::max(0.0, (*hit - 1e-6 * g.resolution()) / length) : 0.0;
    if (last_valid.first != nullptr) si_->getStateSpace()->interpolate(s1, s2, fraction, last_valid.first);
    last_valid.second = fraction;
    return false;
  }

 private:
  const FreeSpace& space_;
};

ob::PlannerPtr allocate(OmplAlgorithm algorithm, const ob::SpaceInformationPtr& si) {
  switch (algorithm) {
    case OmplAlgorithm::RrtStar: return std::make_shared<og::RRTstar>(si);
    case OmplAlgorithm::InformedRrtStar: return std::make_shared<og::InformedRRTstar>(si);
    case OmplAlgorithm::PrmStar: return std::make_shared<og::PRMstar>(si);
    case OmplAlgorithm::RrtConnect: return std::make_shared<og::RRTConnect>(si);
    case OmplAlgorithm::BitStar: return std::make_shared<og::BITstar>(si);
  }
  return nullptr;
}

const char* algorithm_name(OmplAlgorithm algorithm) {
  switch (algorithm) {
    case OmplAlgorithm::RrtStar: return "rrtstar";
    case OmplAlgorithm::InformedRrtStar: return "informedrrtstar";
    case OmplAlgorithm::PrmStar: return "prmstar";
    case OmplAlgorithm::RrtConnect: return "rrtconnect";
    case OmplAlgorithm::BitStar: return "bitstar";
  }
  return "ompl";
}

// The best cost an optimising planner reports (its "best cost" progress property), infinite
// before the first solution or when the planner has no such property.
double reported_best_cost(const ob::Planner& planner) {
  const auto& properties = planner.getPlannerProgressProperties();
  for (const auto& [key, get] : properties) {
    if (key.rfind("best cost", 0) == 0) return std::strtod(get().c_str(), nullptr);
  }
  return INFINITY;
}

class OmplPlanner final : public Planner {
 public:
  explicit OmplPlanner(OmplAlgorithm algorithm) : algorithm_(algorithm) {}
  std::string name() const override { return algorithm_name(algorithm_); }

 protected:
  Search search(const FreeSpace& space, const Eigen::Vector2d& start, const Eigen::Vector2d& goal,
                const PlannerOptions& options, Clock::time_point deadline) override {
    static std::once_flag quiet;
    std::call_once(quiet, [] { ompl::msg::noOutputHandler(); });
    // OMPL draws every instance's seed from one process-wide generator; reseeding it here makes a
    // call reproducible. Calls take turns, or one call's draws would change another's.
    static std::mutex one_at_a_time;
    const std::lock_guard<std::mutex> turn(one_at_a_time);
    ompl::RNG::setSeed(static_cast<std::uint_fast32_t>(options.seed % 0xFFFFFFFFull) + 1);

    const GridGeometry& g = space.geometry();
    auto state_space = std::make_shared<ob::RealVectorStateSpace>(2);
    ob::RealVectorBounds bounds(2);
    bounds.setLow(0, 0.0);
    bounds.setHigh(0, g.width_m());
    bounds.setLow(1, 0.0);
    bounds.setHigh(1, g.height_m());
    state_space->setBounds(bounds);

    og::SimpleSetup setup(state_space);
    const ob::SpaceInformationPtr& si = setup.getSpaceInformation();
    setup.setStateValidityChecker([&space, &g](const ob::State* s) { return space.valid(to_world(g, s)); });
    si->setMotionValidator(std::make_shared<GridMotionValidator>(si, space));
    // Used by planners that discretise motions themselves: half a cell.
    si->setStateValidityCheckingResolution(0.5 * g.resolution() / state_space->getMaximumExtent());

    ob::ScopedState<> from(state_space), to(state_space);
    set_state(g, start, from.get());
    set_state(g, goal, to.get());
    setup.setStartAndGoalStates(from, to);
    auto objective = std::make_shared<ob::PathLengthOptimizationObjective>(si);
    setup.setOptimizationObjective(objective);
    const ob::PlannerPtr planner = allocate(algorithm_, si);
    setup.setPlanner(planner);
    setup.setup();

    // The first solution: reported by RRT*, Informed RRT* and BIT* through the intermediate
    // solution callback, seen by polling the "best cost" of PRM* (which publishes its path only at
    // the end); RRT-Connect stops at its first path.
    std::atomic<Clock::rep> first_solution{-1};
    const auto mark_first = [&first_solution] {
      Clock::rep unset = -1;
      first_solution.compare_exchange_strong(unset, Clock::now().time_since_epoch().count());
    };
    const ob::ProblemDefinitionPtr& problem = setup.getProblemDefinition();
    problem->setIntermediateSolutionCallback(
        [&mark_first](const ob::Planner*, const std::vector<const ob::State*>&, const ob::Cost&) { mark_first(); });
    const Clock::time_point solve_deadline =
        options.simplify ? deadline - std::chrono::duration_cast<Clock::duration>(
                                          std::chrono::duration<double>(kSimplifyShare * options.time_budget_s))
                         : deadline;
    // Time, and with an iteration budget also a count of the planner's checks (the same on every machine).
    const auto budget = [&options](Clock::time_point end, long iterations) {
      if (options.iteration_budget <= 0) return ob::PlannerTerminationCondition([end] { return Clock::now() >= end; });
      return ob::PlannerTerminationCondition([end, iterations, checks = 0L]() mutable {
        return ++checks > iterations || Clock::now() >= end;
      });
    };
    ob::PlannerTerminationCondition until = budget(solve_deadline, options.iteration_budget);
    if (algorithm_ == OmplAlgorithm::PrmStar) {
      const ob::PlannerTerminationCondition poll(
          [&] {
            if (first_solution.load() < 0 && std::isfinite(reported_best_cost(*planner))) mark_first();
            return false;
          },
          0.001);
      until = ob::plannerOrTerminationCondition(until, poll);
    }
    const ob::PlannerStatus status = setup.solve(until);
    const Clock::time_point solved_at = Clock::now();

    Search s;
    if (status != ob::PlannerStatus::EXACT_SOLUTION || !setup.haveExactSolutionPath()) {
      if (status == ob::PlannerStatus::INVALID_START || status == ob::PlannerStatus::INVALID_GOAL ||
          status == ob::PlannerStatus::UNRECOGNIZED_GOAL_TYPE || status == ob::PlannerStatus::CRASH) {
        s.detail = name() + ": OMPL reports " + status.asString();
      }
      return s;
    }
    s.found = true;
    s.first_solution = first_solution.load() >= 0 ? Clock::time_point(Clock::duration(first_solution.load())) : solved_at;

    og::PathGeometric path = setup.getSolutionPath();
    if (options.simplify) {
      og::PathGeometric simplified = path;
      og::PathSimplifier simplifier(si, problem->getGoal(), objective);
      const ob::PlannerTerminationCondition simplify_until = budget(deadline, std::max(1L, options.iteration_budget / 10));
      if (simplifier.simplify(simplified, simplify_until) && simplified.check()) path = simplified;
    }
    for (std::size_t i = 0; i < path.getStateCount(); ++i) s.path.push_back(to_world(g, path.getState(i)));
    // The ends are the query's points exactly, not their round trip through the grid frame.
    s.path.front() = start;
    s.path.back() = goal;
    return s;
  }

 private:
  OmplAlgorithm algorithm_;
};

}  // namespace

std::unique_ptr<Planner> make_ompl_planner(OmplAlgorithm algorithm) { return std::make_unique<OmplPlanner>(algorithm); }

}  // namespace fleetmap::planning
