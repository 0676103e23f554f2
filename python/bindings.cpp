// The C++ half of the Python package `fleetmap` (pybind11): maps as numpy arrays, exploration runs,
// map merging, path planning, sweeps, and coordination strategies, planners, map aligners,
// localizers and merge methods written in Python. The Python half (fleetmap/__init__.py) turns
// scenario dicts and files into the YAML text read here and wraps the results;
// fleetmap/__init__.pyi documents both.
#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/angle.h"
#include "core/error.h"
#include "core/memory.h"
#include "exploration/strategy.h"
#include "io/map_io.h"
#include "localization/localizer.h"
#include "maps/builtin_maps.h"
#include "merging/map_aligner.h"
#include "merging/merge.h"
#include "merging/multi_merge.h"
#include "merging/rendezvous.h"
#include "planning/free_space.h"
#include "planning/planner.h"
#include "sim/run_metrics.h"
#include "sim/run_output.h"
#include "sim/scenario.h"
#include "sim/simulation.h"
#include "io/file_io.h"
#include "sweep/sweep.h"
#include "sweep/sweep_report.h"
#include "sweep/sweep_results.h"
#include "sweep/sweep_runner.h"

namespace py = pybind11;
namespace fs = std::filesystem;
using namespace fleetmap;

namespace {

using Array2 = py::array_t<double>;

// Poses as rows (x, y, theta).
py::array_t<double> pose_rows(const std::vector<core::Pose2>& poses) {
  py::array_t<double> out({py::ssize_t(poses.size()), py::ssize_t(3)});
  auto a = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    a(py::ssize_t(i), 0) = poses[i].x, a(py::ssize_t(i), 1) = poses[i].y, a(py::ssize_t(i), 2) = poses[i].theta;
  }
  return out;
}

py::array_t<double> point_rows(const std::vector<Eigen::Vector2d>& points) {
  py::array_t<double> out({py::ssize_t(points.size()), py::ssize_t(2)});
  auto a = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < points.size(); ++i) a(py::ssize_t(i), 0) = points[i].x(), a(py::ssize_t(i), 1) = points[i].y();
  return out;
}

py::tuple pose_tuple(const core::Pose2& p) { return py::make_tuple(p.x, p.y, p.theta); }

// The map_saver image of a grid: uint8 (height, width), top row first, 254 free, 0 occupied, 205 unknown.
py::array_t<std::uint8_t> grid_image(const mapping::OccupancyGrid& grid) {
  io::MapImage image = io::map_image(grid);
  py::array_t<std::uint8_t> out({py::ssize_t(image.height), py::ssize_t(image.width)});
  std::copy(image.pixels.begin(), image.pixels.end(), out.mutable_data());
  return out;
}

mapping::OccupancyGrid grid_from_array(const py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>& array,
                                       double resolution, const core::Pose2& origin) {
  if (array.ndim() != 2 || array.shape(0) == 0 || array.shape(1) == 0) {
    throw InputError("map image: expected a non-empty 2-D array (rows, columns), got " + std::to_string(array.ndim()) +
                     " dimensions");
  }
  if (!(resolution >= io::kResolutionRange.lo && resolution <= io::kResolutionRange.hi)) {
    throw InputError("map resolution: expected " + core::expected_text(io::kResolutionRange) + " metres per cell");
  }
  io::MapImage image;
  image.height = int(array.shape(0));
  image.width = int(array.shape(1));
  image.pixels.assign(array.data(), array.data() + array.size());
  io::MapYaml meta;
  meta.resolution = resolution;
  meta.origin = origin;
  return io::grid_from_map_image(image, meta);
}

// Refuses a resampling of `grid` to `resolution` over the cells a loaded map may have.
void check_resampled_size(const mapping::OccupancyGrid& grid, double resolution, const std::string& what) {
  const double cells = mapping::resampled_cell_count(grid, resolution);
  if (const auto limit = io::MapLoadOptions{}.max_cells; cells > double(limit)) {
    throw InputError(fmt::format("{}: {} m cells would make {:.0f} cells, over the limit of {}", what, resolution, cells,
                                 limit));
  }
}

// Two maps aligned as `fleetmap merge` aligns them; the fused map is made when first asked for (a
// script that merges in a loop for the transforms does not pay for it).
class PairMerge {
 public:
  PairMerge(py::object a, py::object b, const merging::MergeOptions& options)
      : a_(std::move(a)), b_(std::move(b)) {
    const auto grids = this->grids();
    {
      py::gil_scoped_release release;
      merge_ = merging::merge_maps(grids, options);
    }
    const auto& pair = result();
    placement_ = merging::placement(grids[0]->geometry(), grids[1]->geometry(), pair.transform, pair.covariance);
    if (placement_.covariance) {
      const Eigen::Vector2d at = grids[0]->geometry().grid_to_world(pair.quality.overlap_centre + Eigen::Vector2d(0.5, 0.5));
      uncertainty_ = merging::describe_uncertainty(*placement_.covariance, placement_.metres, at);
    }
  }
  const std::optional<merging::Uncertainty>& uncertainty() const { return uncertainty_; }
  const merging::MergeResult& result() const { return merge_.pairs.front().result; }
  const merging::Placement& placement() const { return placement_; }
  std::optional<mapping::OccupancyGrid> map() {
    if (!merge_.to_first[1]) return std::nullopt;
    if (!map_) {
      const auto grids = this->grids();
      py::gil_scoped_release release;
      map_ = merging::fuse_placed(grids, merge_).map;
    }
    return map_;
  }

 private:
  std::vector<const mapping::OccupancyGrid*> grids() const {
    return {&a_.cast<const mapping::OccupancyGrid&>(), &b_.cast<const mapping::OccupancyGrid&>()};
  }
  py::object a_, b_;  // held, so that the maps outlive the result that fuses them
  merging::MultiMergeResult merge_;
  merging::Placement placement_;
  std::optional<merging::Uncertainty> uncertainty_;
  std::optional<mapping::OccupancyGrid> map_;
};

// A getter of a PairMerge's field of its pair's result.
template <typename T>
auto of_result(T merging::MergeResult::*field) {
  return [field](const PairMerge& r) { return r.result().*field; };
}

py::tuple transform_tuple(const core::Transform2& t) {
  return py::make_tuple(t.translation().x(), t.translation().y(), core::rad2deg(t.rotation()));
}

// A finished exploration run and the label its map goes by.
struct Run {
  sim::RunResult result;
  std::string label;
};

Run explore(const std::string& yaml, const std::string& source, const std::string& base_dir) {
  sim::Scenario s = sim::parse_scenario(yaml, source, base_dir);
  s.map = sim::map_source(s);
  io::MapLoadOptions load;
  load.default_resolution = s.map_resolution_m;
  auto truth = maps::load_map_source(s.map, load);
  Run run{{}, sweep::map_label(s.map)};
  sim::Simulation simulation(s, std::move(truth));
  run.result = simulation.run();
  return run;
}

// A sweep's rows as results.csv has them: the header, then one line per run, in the sweep's order.
// With `out`, the folder `fleetmap bench --out` writes too (results.csv, the reports, sweep.yaml and
// scenario.yaml): new, empty, or written before by a sweep, whose files it replaces.
std::vector<std::string> run_sweep(const std::string& yaml, const std::string& source, const std::string& base_dir,
                                   int jobs, const std::string& out) {
  const sweep::Sweep spec = sweep::parse_sweep(yaml, source, base_dir);
  sweep::SweepMaps truths;
  std::vector<std::string> labels;
  std::vector<fs::path> inputs;
  if (io::is_regular_file(source)) inputs.push_back(source);
  for (const auto& m : spec.maps) {
    io::MapLoadOptions load;
    load.default_resolution = spec.base.map_resolution_m;
    labels.push_back(sweep::map_label(m));
    truths.emplace(labels.back(), maps::load_map_source(m, load));
    for (auto& file : maps::map_source_files(m)) inputs.push_back(std::move(file));
  }
  sweep::check_placements(spec, truths);
  const auto runs = sweep::sweep_runs(spec);
  std::optional<io::OutputFolder> folder;
  if (!out.empty()) {
    folder.emplace(out, "bench", sweep::sweep_folder_files(labels, spec.base.html_replay ? runs : std::vector<sweep::SweepRun>{}),
                   inputs, "out " + out);
    folder->claim();
  }
  std::vector<sweep::RunRecord> records;
  std::mutex mutex;
  sweep::SweepRunOptions run_options;
  run_options.jobs = jobs;
  run_options.replay_dir = out;
  sweep::run_sweep(spec, runs, truths, run_options, [&](const sweep::RunRecord& r) {
    const std::lock_guard<std::mutex> lock(mutex);
    records.push_back(r);
  });
  sweep::sort_records(records, runs);
  if (folder) {
    auto written = sweep::write_sweep_definition(out, spec);
    sweep::write_results(fs::path(out) / "results.csv", records);
    written.push_back(fs::path(out) / "results.csv");
    for (auto& p : sweep::write_sweep_reports(out, records)) written.push_back(std::move(p));
    for (const auto& r : runs) {
      const fs::path replay = fs::path(out) / sweep::replay_file_name(sweep::run_key(r));
      if (spec.base.html_replay && io::is_regular_file(replay)) written.push_back(replay);
    }
    folder->finish(io::OutputFolder::names(written));
  }
  std::vector<std::string> lines{sweep::results_header()};
  for (const auto& r : records) lines.push_back(sweep::format_record(r));
  return lines;
}

// Writes rows given as the text of each results.csv column (sweep()'s rows turned back into text)
// as `fleetmap bench` writes results.csv: each row read as bench reads one, so a wrong value is
// refused with the row and the column, then written in bench's own formats.
void write_results(const std::vector<std::string>& lines, const std::string& path) {
  std::vector<sweep::RunRecord> records;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    records.push_back(sweep::parse_record(lines[i], fmt::format("save_results: rows[{}]", i)));
  }
  io::check_output_file(path, {}, "save_results");
  sweep::write_results(path, records);
}

// A member's declared parameters with their values, as every Python plug-in gets them: numbers as
// float, flags as bool, words as str.
py::dict params_dict(const core::Params& params) {
  py::dict out;
  for (const auto& spec : params.specs()) {
    switch (spec.type) {
      case core::ParamSpec::Type::Number: out[py::str(spec.name)] = params.number(spec.name); break;
      case core::ParamSpec::Type::Flag: out[py::str(spec.name)] = params.flag(spec.name); break;
      case core::ParamSpec::Type::Text: out[py::str(spec.name)] = params.text(spec.name); break;
    }
  }
  return out;
}

// What a Python strategy gets besides the arrays (its assign's optional fifth argument): the
// robots' places in the team, the strategy options, and the lazily computed target-to-target wave
// costs and unknown areas, which exist only while assign runs.
class AssignmentContext {
 public:
  AssignmentContext(const exploration::AssignmentInput& input, const exploration::StrategyOptions& options)
      : input_(&input), options_(options) {}
  void close() { input_ = nullptr; }

  py::array_t<int> team_indices() const {
    const auto& robots = live().robots;
    py::array_t<int> out(py::ssize_t(robots.size()));
    for (std::size_t r = 0; r < robots.size(); ++r) out.mutable_at(py::ssize_t(r)) = robots[r].team_index;
    return out;
  }
  int team_size() const { return live().robots.empty() ? 0 : live().robots.front().team_size; }
  double sensor_range() const { return live().sensor_range_m; }
  // The strategy's declared parameters with this run's values: numbers as float, flags as bool.
  py::dict params() const { return params_dict(options_); }
  py::array_t<double> target_costs() const {
    const auto& input = live();
    Eigen::MatrixXd costs;
    {
      py::gil_scoped_release release;  // wave fronts from every goal: let other runs' strategies go on
      costs = exploration::target_costs(input);
    }
    const auto n = py::ssize_t(costs.rows());
    py::array_t<double> out({n, n});
    auto o = out.mutable_unchecked<2>();
    for (py::ssize_t a = 0; a < n; ++a)
      for (py::ssize_t b = 0; b < n; ++b) o(a, b) = costs(a, b);
    return out;
  }
  py::array_t<double> target_gains() const {
    const auto& input = live();
    std::vector<double> gains;
    if (input.target_gains_m2) {
      py::gil_scoped_release release;
      gains = input.target_gains_m2();
    } else {
      gains.assign(input.targets.size(), 1.0);
    }
    return py::array_t<double>(py::ssize_t(gains.size()), gains.data());
  }

 private:
  const exploration::AssignmentInput& live() const {
    if (!input_) throw Error("the assignment context is valid only while assign runs");
    return *input_;
  }
  const exploration::AssignmentInput* input_;
  exploration::StrategyOptions options_;
};

// A Python object a C++ plug-in owns: released with the GIL held, on whichever thread the plug-in
// dies (simulations run with the GIL released).
class PluginObject {
 public:
  explicit PluginObject(py::object object) : object_(std::move(object)) {}
  PluginObject(const PluginObject&) = delete;
  PluginObject& operator=(const PluginObject&) = delete;
  ~PluginObject() {
    py::gil_scoped_acquire gil;
    object_ = py::object();
  }
  operator const py::object&() const { return object_; }
  py::object attr(const char* name) const { return object_.attr(name); }

 private:
  py::object object_;
};

// A coordination strategy whose assign() is a Python object's method:
//   assign(poses (R, 3): x, y, heading, targets (T, 4): goal x, goal y, frontier cells, region,
//          costs (R, T) wave metres (inf: unreachable), claimed (K, 2)[, context]) -> R target indices or -1.
// Simulations run with the GIL released (sweeps on several threads); each call takes it.
class PythonStrategy final : public exploration::CoordinationStrategy {
 public:
  PythonStrategy(std::string name, bool joint, bool with_context, py::object instance,
                 const exploration::StrategyOptions& options)
      : name_(std::move(name)), joint_(joint), with_context_(with_context), instance_(std::move(instance)),
        options_(options) {}
  std::string name() const override { return name_; }
  bool joint() const override { return joint_; }

  std::vector<int> assign(const exploration::AssignmentInput& input) const override {
    py::gil_scoped_acquire gil;
    const auto robots = py::ssize_t(input.robots.size()), targets = py::ssize_t(input.targets.size());
    std::vector<core::Pose2> poses;
    for (const auto& r : input.robots) poses.emplace_back(r.position_m.x(), r.position_m.y(), r.heading_rad);
    py::array_t<double> target_rows({targets, py::ssize_t(4)});
    auto t = target_rows.mutable_unchecked<2>();
    for (py::ssize_t k = 0; k < targets; ++k) {
      const auto& target = input.targets[std::size_t(k)];
      t(k, 0) = target.goal_m.x(), t(k, 1) = target.goal_m.y(), t(k, 2) = target.cells, t(k, 3) = target.region;
    }
    py::array_t<double> costs({robots, targets});
    auto c = costs.mutable_unchecked<2>();
    for (py::ssize_t r = 0; r < robots; ++r) {
      for (py::ssize_t k = 0; k < targets; ++k) c(r, k) = input.robots[std::size_t(r)].cost_m[std::size_t(k)];
    }
    std::vector<int> out;
    // The context dies with this call even when Python keeps a reference to it.
    py::object context = py::cast(AssignmentContext(input, options_));
    struct Close {
      py::object& context;
      ~Close() { context.cast<AssignmentContext&>().close(); }
    } close{context};
    try {
      const py::object assign = instance_.attr("assign");
      const py::object answer = with_context_
                                    ? assign(pose_rows(poses), target_rows, costs, point_rows(input.claimed), context)
                                    : assign(pose_rows(poses), target_rows, costs, point_rows(input.claimed));
      for (const auto& item : answer) out.push_back(item.cast<int>());
    } catch (const py::error_already_set& e) {
      throw Error("strategy '" + name_ + "': assign raised " + std::string(e.what()));
    } catch (const py::cast_error& e) {
      throw Error("strategy '" + name_ + "': assign must return a sequence of integers");
    }
    if (out.size() != input.robots.size()) {
      throw Error("strategy '" + name_ + "': assign returned " + std::to_string(out.size()) + " targets for " +
                  std::to_string(input.robots.size()) + " robots");
    }
    for (const int k : out) {
      if (k < -1 || k >= targets) {
        throw Error("strategy '" + name_ + "': target index " + std::to_string(k) + " is not -1 or in 0.." +
                    std::to_string(targets - 1));
      }
    }
    return out;
  }

 private:
  std::string name_;
  bool joint_;
  bool with_context_;
  PluginObject instance_;
  exploration::StrategyOptions options_;
};

// One declared parameter from Python: (name, kind "number" | "flag" | "text", default as text, unit,
// lowest, highest, whole, choices, doc), as fleetmap.register_strategy builds it.
using PythonParam = std::tuple<std::string, std::string, std::string, std::string, double, double, bool,
                               std::vector<std::string>, std::string>;

core::ParamSpec param_spec(const PythonParam& p) {
  const auto& [name, kind, default_value, unit, lo, hi, whole, choices, doc] = p;
  core::ParamSpec spec;
  spec.name = name;
  spec.type = kind == "flag" ? core::ParamSpec::Type::Flag
              : kind == "text" ? core::ParamSpec::Type::Text
                               : core::ParamSpec::Type::Number;
  spec.default_value = default_value;
  spec.unit = unit;
  spec.range = {lo, hi, whole};
  spec.choices = choices;
  spec.doc = doc;
  return spec;
}

// Keeps a registered Python class alive for the life of the process: the registries keep their
// factories beyond the interpreter's, so the reference is never released and no Python object dies
// without it.
PyObject* hold_forever(const py::object& cls) {
  PyObject* held = cls.ptr();
  Py_INCREF(held);
  return held;
}

std::vector<core::ParamSpec> param_specs(const std::vector<PythonParam>& params) {
  std::vector<core::ParamSpec> specs;
  for (const auto& p : params) specs.push_back(param_spec(p));
  return specs;
}

// Makes a plug-in's object from its registered class; an exception raised in Python becomes a
// fleetmap Error naming the plug-in.
template <typename... Args>
py::object make_plugin(const std::string& who, PyObject* cls, Args&&... args) {
  try {
    return py::reinterpret_borrow<py::object>(cls)(std::forward<Args>(args)...);
  } catch (py::error_already_set& e) {
    throw Error(fmt::format("{}: making it raised {}", who, e.what()));
  }
}

void register_python_strategy(const std::string& name, const py::object& cls, const std::string& help, bool joint,
                              bool with_context, const std::vector<PythonParam>& params) {
  if (!py::hasattr(cls, "assign")) throw InputError("register_strategy '" + name + "': the class has no assign method");
  PyObject* held = hold_forever(cls);
  exploration::register_strategy(name, help.empty() ? "written in Python" : help,
                                 [name, held, joint, with_context](const exploration::StrategyOptions& options) {
                                   py::gil_scoped_acquire gil;
                                   py::object instance = make_plugin("strategy '" + name + "'", held);
                                   return std::make_unique<PythonStrategy>(name, joint, with_context,
                                                                           std::move(instance), options);
                                 },
                                 param_specs(params));
}

// Calls a Python plug-in's method; the caller holds the GIL. An exception raised in Python becomes a
// fleetmap Error naming the plug-in (`who`, e.g. "planner 'my-planner'") and the method.
template <typename... Args>
py::object call_plugin(const std::string& who, const py::object& instance, const char* method, Args&&... args) {
  try {
    return instance.attr(method)(std::forward<Args>(args)...);
  } catch (py::error_already_set& e) {
    throw Error(fmt::format("{}: {} raised {}", who, method, e.what()));
  }
}

// Reads `count` finite numbers from what a plug-in's `method` returned, or throws Error naming the
// plug-in, the method, what it must return and what it did.
std::vector<double> finite_numbers(const py::handle& answer, std::size_t count, const std::string& who,
                                   const char* method, const char* expected) {
  std::vector<double> out;
  bool read = py::isinstance<py::sequence>(answer) && !py::isinstance<py::str>(answer);
  if (read) {
    try {
      for (const auto& item : py::reinterpret_borrow<py::sequence>(answer)) out.push_back(item.cast<double>());
    } catch (const py::cast_error&) {
      read = false;
    }
  }
  if (!read || out.size() != count || !std::all_of(out.begin(), out.end(), [](double v) { return std::isfinite(v); })) {
    throw Error(fmt::format("{}: {} must return {}, got {}", who, method, expected, std::string(py::repr(answer))));
  }
  return out;
}

// A planner whose search is a Python object's method:
//   search(free, resolution, origin, start, goal, params) -> [(x, y), ...] or None
// `free` is a bool (height, width) array, top row first as Map.image, true where the robot's centre
// may be; origin is the map's lower-left corner (x, y, theta). The path it returns is checked as
// every planner's must be: from the start to the goal (within half a cell's diagonal, then snapped to
// them) and every segment inside the free space.
class PythonPlanner final : public planning::Planner {
 public:
  PythonPlanner(std::string name, py::object instance, const core::Params& params)
      : name_(std::move(name)), instance_(std::move(instance)), params_(params) {}
  std::string name() const override { return name_; }

 protected:
  Search search(const planning::FreeSpace& space, const Eigen::Vector2d& start, const Eigen::Vector2d& goal,
                const planning::PlannerOptions& /*options*/, Clock::time_point /*deadline*/) override {
    const std::string who = "planner '" + name_ + "'";
    const auto& g = space.geometry();
    py::gil_scoped_acquire gil;
    py::array_t<bool> free({py::ssize_t(g.height()), py::ssize_t(g.width())});
    auto f = free.mutable_unchecked<2>();
    for (int y = 0; y < g.height(); ++y)
      for (int x = 0; x < g.width(); ++x) f(py::ssize_t(g.height() - 1 - y), py::ssize_t(x)) = space.valid(planning::Cell{x, y});
    const py::object answer = call_plugin(who, instance_, "search", free, g.resolution(), pose_tuple(g.origin()),
                                          py::make_tuple(start.x(), start.y()), py::make_tuple(goal.x(), goal.y()),
                                          params_dict(params_));
    Search out;
    if (answer.is_none()) {
      out.detail = who + " found no path";
      return out;
    }
    const char* expected = "a list of (x, y) waypoints in metres, or None";
    if (!py::isinstance<py::sequence>(answer) || py::isinstance<py::str>(answer)) {
      throw Error(fmt::format("{}: search must return {}, got {}", who, expected, std::string(py::repr(answer))));
    }
    for (const auto& point : py::reinterpret_borrow<py::sequence>(answer)) {
      const auto xy = finite_numbers(point, 2, who, "search", expected);
      out.path.emplace_back(xy[0], xy[1]);
    }
    // An end within half a cell's diagonal counts as the start or goal itself, so that a planner on
    // cells may answer with the centres of their cells; the segments are checked after snapping.
    const double tolerance = std::sqrt(0.5) * g.resolution() * (1.0 + 1e-9);  // a corner's rounding too
    if (out.path.size() < 2) {
      throw Error(fmt::format("{}: search returned {} waypoint(s); a path needs the start and the goal", who,
                              out.path.size()));
    }
    const auto check_end = [&](const Eigen::Vector2d& got, const Eigen::Vector2d& want, const char* end) {
      if ((got - want).norm() > tolerance) {
        throw Error(fmt::format("{}: the path's {} ({:.3f}, {:.3f}) is {:.3f} m from the {} ({:.3f}, {:.3f}), more "
                                "than half a cell's diagonal ({:.3f} m)",
                                who, end == std::string("start") ? "first waypoint" : "last waypoint", got.x(), got.y(),
                                (got - want).norm(), end, want.x(), want.y(), tolerance));
      }
    };
    check_end(out.path.front(), start, "start");
    check_end(out.path.back(), goal, "goal");
    out.path.front() = start;
    out.path.back() = goal;
    for (std::size_t i = 0; i + 1 < out.path.size(); ++i) {
      if (const auto d = space.first_invalid_distance(out.path[i], out.path[i + 1])) {
        const Eigen::Vector2d at = out.path[i] + *d * (out.path[i + 1] - out.path[i]).normalized();
        throw Error(fmt::format("{}: segment {} of the path, ({:.3f}, {:.3f}) to ({:.3f}, {:.3f}), leaves the free "
                                "space at ({:.3f}, {:.3f}) (an obstacle, unknown space or closer to one than the robot "
                                "radius {:.2f} m)",
                                who, i, out.path[i].x(), out.path[i].y(), out.path[i + 1].x(), out.path[i + 1].y(),
                                at.x(), at.y(), space.robot_radius()));
      }
    }
    out.found = true;
    out.first_solution = Clock::now();
    return out;
  }

 private:
  std::string name_;
  PluginObject instance_;
  core::Params params_;
};

void register_python_planner(const std::string& name, const py::object& cls, const std::string& help, bool complete,
                             const std::vector<PythonParam>& params) {
  if (!py::hasattr(cls, "search")) throw InputError("register_planner '" + name + "': the class has no search method");
  PyObject* held = hold_forever(cls);
  planning::PlannerMaker maker;
  maker.complete = complete;
  maker.make = [name, held](const core::Params& values) -> std::unique_ptr<planning::Planner> {
    py::gil_scoped_acquire gil;
    py::object instance = make_plugin("planner '" + name + "'", held);
    return std::make_unique<PythonPlanner>(name, std::move(instance), values);
  };
  planning::register_planner(name, help.empty() ? "written in Python" : help, std::move(maker), param_specs(params));
}

// A map aligner whose align is a Python object's method:
//   align(receiver_map, sender_map, receiver_pose, sender_pose, params) -> None or (tx, ty, theta, confidence)
// The maps are fleetmap.Map copies, each in its robot's own frame; the answer takes the sender's
// frame into the receiver's (metres, radians). None: tried, not merged.
class PythonMapAligner final : public merging::MapAligner {
 public:
  PythonMapAligner(std::string name, py::object instance, const core::Params& params)
      : name_(std::move(name)), instance_(std::move(instance)), params_(params) {}
  bool costly() const override { return true; }
  bool sends_map() const override { return true; }
  merging::FrameAlignment align(const merging::AlignmentRequest& request) const override {
    const std::string who = "map aligner '" + name_ + "'";
    py::gil_scoped_acquire gil;
    const py::object answer =
        call_plugin(who, instance_, "align", py::cast(*request.receiver_map), py::cast(*request.sender_map),
                    pose_tuple(request.receiver_pose), pose_tuple(request.sender_pose), params_dict(params_));
    merging::FrameAlignment out;
    out.attempted = true;
    out.method = name_;
    if (answer.is_none()) {
      out.reason = name_ + " found no alignment";
      return out;
    }
    const auto t = finite_numbers(answer, 4, who, "align", "None or (tx, ty, theta, confidence)");
    if (!(t[3] >= 0.0 && t[3] <= 1.0)) {
      throw Error(fmt::format("{}: align's confidence must be in [0, 1], got {}", who, t[3]));
    }
    out.merged = true;
    out.sender_to_receiver = core::Transform2(t[0], t[1], t[2]);
    out.confidence = t[3];
    return out;
  }

 private:
  std::string name_;
  PluginObject instance_;
  core::Params params_;
};

void register_python_map_aligner(const std::string& name, const py::object& cls, const std::string& help,
                                 const std::vector<PythonParam>& params) {
  if (!py::hasattr(cls, "align")) throw InputError("register_map_aligner '" + name + "': the class has no align method");
  PyObject* held = hold_forever(cls);
  merging::register_map_aligner(
      name, help.empty() ? "written in Python" : help,
      [name, held](const core::Params& values) -> std::unique_ptr<merging::MapAligner> {
        py::gil_scoped_acquire gil;
        py::object instance = make_plugin("map aligner '" + name + "'", held);
        return std::make_unique<PythonMapAligner>(name, std::move(instance), values);
      },
      param_specs(params));
}

// Whether a plug-in's object has `method` (an attribute set to None does not count).
bool has_method(const py::object& object, const char* method) {
  return py::hasattr(object, method) && !object.attr(method).is_none();
}

// A localizer whose methods are a Python object's, made as cls(initial_pose, params, seed):
//   predict(dx, dy, dtheta): the step's odometry as the motion in the robot's frame before it;
//   update_scan(ranges, angles, max_range), when the class has it (uses_scans): inf for no return;
//   pose() -> (x, y, theta); covariance() -> 3 x 3, when it has it (zero otherwise);
//   change_frame(tx, ty, theta), when it has it: the estimate re-expressed after a merge.
class PythonLocalizer final : public localization::Localizer {
 public:
  PythonLocalizer(std::string name, py::object instance)
      : name_(std::move(name)), who_("localizer '" + name_ + "'"), instance_(std::move(instance)),
        uses_scans_(has_method(instance_, "update_scan")), has_covariance_(has_method(instance_, "covariance")),
        moves_(has_method(instance_, "change_frame")) {}
  std::string name() const override { return name_; }
  bool uses_scans() const override { return uses_scans_; }
  bool ignores_own_map() const override { return true; }

  void predict(const localization::Odometry& u) override {
    const core::Pose2 step = localization::integrate_motion(core::Pose2(), u);
    py::gil_scoped_acquire gil;
    call_plugin(who_, instance_, "predict", step.x, step.y, step.theta);
  }
  void update_scan(const localization::RangeScan& scan, const mapping::OccupancyGrid& /*own_map*/) override {
    if (!uses_scans_) return;
    py::gil_scoped_acquire gil;
    py::array_t<double> ranges(py::ssize_t(scan.ranges.size()));
    for (std::size_t b = 0; b < scan.ranges.size(); ++b) {
      ranges.mutable_at(py::ssize_t(b)) = scan.ranges[b].value_or(std::numeric_limits<double>::infinity());
    }
    call_plugin(who_, instance_, "update_scan", ranges,
                py::array_t<double>(py::ssize_t(scan.angles.size()), scan.angles.data()), scan.max_range);
  }
  core::Pose2 pose() const override {
    py::gil_scoped_acquire gil;
    const auto p = finite_numbers(call_plugin(who_, instance_, "pose"), 3, who_, "pose", "(x, y, theta)");
    return {p[0], p[1], p[2]};
  }
  Eigen::Matrix3d covariance() const override {
    if (!has_covariance_) return Eigen::Matrix3d::Zero();
    py::gil_scoped_acquire gil;
    const py::object answer = call_plugin(who_, instance_, "covariance");
    const auto flat = finite_numbers(py::module_::import("numpy").attr("ravel")(answer), 9, who_, "covariance",
                                     "a 3 x 3 matrix of finite numbers");
    Eigen::Matrix3d c;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) c(i, j) = flat[std::size_t(3 * i + j)];
    return c;
  }
  void change_frame(const core::Transform2& t) override {
    if (!moves_) {
      throw Error(who_ + " has no change_frame(tx, ty, theta): its robot cannot take a teammate's map frame");
    }
    py::gil_scoped_acquire gil;
    call_plugin(who_, instance_, "change_frame", t.translation().x(), t.translation().y(), t.rotation());
  }

 private:
  std::string name_, who_;
  PluginObject instance_;
  bool uses_scans_, has_covariance_, moves_;
};

void register_python_localizer(const std::string& name, const py::object& cls, const std::string& help,
                               const std::vector<PythonParam>& params) {
  for (const char* method : {"predict", "pose"}) {
    if (!py::hasattr(cls, method)) {
      throw InputError(fmt::format("register_localizer '{}': the class has no {} method", name, method));
    }
  }
  PyObject* held = hold_forever(cls);
  localization::register_localizer(
      name, help.empty() ? "written in Python" : help,
      [name, held](const localization::LocalizerContext& context) -> std::unique_ptr<localization::Localizer> {
        py::gil_scoped_acquire gil;
        py::object instance = make_plugin("localizer '" + name + "'", held, pose_tuple(context.initial_pose),
                                          params_dict(context.params), context.seed);
        return std::make_unique<PythonLocalizer>(name, std::move(instance));
      },
      param_specs(params));
}

// One pass of a merge method written in Python: the object's propose(a, b) with the two maps as the
// merge sees them (Map copies, perhaps cut to their known cells, their origins where those cells lie),
// answering candidates (tx, ty, theta[, score]) that take b's frame into a's (metres, radians, as
// merge_maps' transform). They enter the common pipeline at full resolution (Hypothesis::level 0);
// without scores, the list's order ranks them.
std::vector<merging::Hypothesis> propose_in_python(const std::string& name, const PluginObject& instance,
                                                   const merging::PreparedGrid& a, const merging::PreparedGrid& b) {
  const std::string who = "merge method '" + name + "'";
  const char* expected = "a list of (tx, ty, theta) or (tx, ty, theta, score)";
  py::gil_scoped_acquire gil;
  const py::object answer = call_plugin(who, instance, "propose", py::cast(a.grid()), py::cast(b.grid()));
  if (!py::isinstance<py::sequence>(answer) || py::isinstance<py::str>(answer)) {
    throw Error(fmt::format("{}: propose must return {}, got {}", who, expected, std::string(py::repr(answer))));
  }
  const auto items = py::reinterpret_borrow<py::sequence>(answer);
  const std::size_t count = items.size();
  std::vector<merging::Hypothesis> out;
  for (std::size_t i = 0; i < count; ++i) {
    const py::object item = items[i];
    const bool scored = py::isinstance<py::sequence>(item) && !py::isinstance<py::str>(item) && py::len(item) == 4;
    const auto t = finite_numbers(item, scored ? 4 : 3, who, "propose", expected);
    const core::Transform2 cells =
        merging::cells_from_world(a.grid().geometry(), b.grid().geometry(), core::Transform2(t[0], t[1], t[2]));
    out.push_back({cells, scored ? t[3] : double(count - i), 0, name});
  }
  return out;
}

void register_python_merge_method(const std::string& name, const py::object& cls, const std::string& help,
                                  const std::vector<PythonParam>& params) {
  if (!py::hasattr(cls, "propose")) {
    throw InputError("register_merge_method '" + name + "': the class has no propose method");
  }
  PyObject* held = hold_forever(cls);
  merging::register_merge_method(
      name, help.empty() ? "written in Python" : help,
      [name, held](const core::Params& values) {
        std::shared_ptr<const PluginObject> instance;
        {
          py::gil_scoped_acquire gil;
          instance = std::make_shared<const PluginObject>(
              make_plugin("merge method '" + name + "'", held, params_dict(values)));
        }
        return merging::MergePasses{[name, instance](const merging::PreparedGrid& a, const merging::PreparedGrid& b,
                                                     const merging::MergeOptions&, core::Random&) {
          return propose_in_python(name, *instance, a, b);
        }};
      },
      param_specs(params));
}

}  // namespace

// A family's members as Python lists them: {name, help, params}, each parameter {name, kind,
// default, unit, accepts, doc}.
template <typename Factory>
py::list registry_members(const core::Registry<Factory>& registry) {
  py::list out;
  for (const auto& name : registry.names()) {
    py::list params;
    for (const auto& spec : registry.get(name).params) {
      py::dict p;
      p["name"] = spec.name;
      p["kind"] = spec.type == core::ParamSpec::Type::Number ? "number" : spec.type == core::ParamSpec::Type::Flag ? "flag" : "text";
      p["default"] = spec.default_value;
      p["unit"] = spec.unit;
      p["accepts"] = spec.expected();
      p["doc"] = spec.doc;
      params.append(p);
    }
    py::dict member;
    member["name"] = name;
    member["help"] = registry.get(name).help;
    member["params"] = params;
    out.append(member);
  }
  return out;
}

PYBIND11_MODULE(_fleetmap, m) {
  m.doc() = "fleetmap's C++ core; use the package `fleetmap`, which wraps it.";
  // Importing the module changes no process-wide setting: a script that merges in a loop asks for
  // the allocator setting itself (core/memory.h).
  m.def(
      "keep_freed_memory", [] { return core::keep_freed_memory(); },
      "Asks the C library to keep freed memory for reuse, for the whole process (glibc's M_MMAP_THRESHOLD "
      "32 MiB and M_TRIM_THRESHOLD 128 MiB). Call it once in a script that merges or explores large maps over "
      "and over: without it every merge of two 1000 x 1000 maps faults its pages in again. Returns False "
      "where the C library has no such settings.");
  // pybind11 tries the most recently registered translator first: InputError (an Error) goes last.
  py::register_exception<Error>(m, "Error", PyExc_RuntimeError).doc() =
      "A failure inside fleetmap other than bad input (a RuntimeError).";
  py::register_exception<InputError>(m, "InputError", PyExc_ValueError).doc() =
      "Bad input (a ValueError): a scenario key, a map file, a name; the message names it.";

  py::class_<mapping::OccupancyGrid>(m, "Map", "An occupancy grid map.")
      .def_static(
          "from_image",
          [](const py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>& image, double resolution,
             std::tuple<double, double, double> origin) {
            return grid_from_array(image, resolution, {std::get<0>(origin), std::get<1>(origin), std::get<2>(origin)});
          },
          py::arg("image"), py::arg("resolution") = 0.05, py::arg("origin") = std::make_tuple(0.0, 0.0, 0.0),
          "A map from a uint8 (rows, columns) image, top row first, read with map_server's rules: dark (0) "
          "occupied, light (254) free, mid-grey (205) unknown. `origin`: the pose (x, y, theta) of the lower-left "
          "corner in metres.")
      .def_property_readonly("image", &grid_image,
                             "The map_saver image: uint8 (height, width), top row first, 254 free, 0 occupied, "
                             "205 unknown.")
      .def_property_readonly("width", &mapping::OccupancyGrid::width, "Cells along x.")
      .def_property_readonly("height", &mapping::OccupancyGrid::height, "Cells along y.")
      .def_property_readonly("resolution", &mapping::OccupancyGrid::resolution, "Metres per cell.")
      .def_property_readonly(
          "origin", [](const mapping::OccupancyGrid& g) { return pose_tuple(g.geometry().origin()); },
          "The pose (x, y, theta) of the lower-left corner, metres and radians.")
      .def_property_readonly(
          "free_cells", [](const mapping::OccupancyGrid& g) { return g.count(mapping::CellState::Free); },
          "How many cells are free.")
      .def_property_readonly(
          "occupied_cells", [](const mapping::OccupancyGrid& g) { return g.count(mapping::CellState::Occupied); },
          "How many cells are occupied.")
      .def(
          "save",
          [](const mapping::OccupancyGrid& g, const std::string& file) {
            const fs::path path(file);
            const auto ext = path.extension().string();
            if (ext == ".yaml" || ext == ".yml") io::save_map_yaml(g, path);
            else io::save_map_image(g, path);
          },
          py::arg("path"), ".yaml / .yml: map_server YAML and a .pgm beside it; .png / .pgm: the image alone.")
      .def(
          "resampled", [](const mapping::OccupancyGrid& g, double resolution) {
            if (!(resolution >= io::kResolutionRange.lo && resolution <= io::kResolutionRange.hi)) {
              throw InputError("resampled: resolution: expected " + core::expected_text(io::kResolutionRange) +
                               " metres per cell");
            }
            check_resampled_size(g, resolution, "resampled");
            return mapping::resample(g, resolution);
          },
          py::arg("resolution"),
          "The map seen through cells of `resolution` metres (same origin and extent): a cell is occupied when "
          "any cell of the old map inside it is, free when half of them are (fleetmap merge fuses maps of other "
          "resolutions so in the first map's cells).")
      .def("__repr__", [](const mapping::OccupancyGrid& g) {
        return "<fleetmap.Map " + std::to_string(g.width()) + " x " + std::to_string(g.height()) + " cells of " +
               std::to_string(g.resolution()) + " m>";
      });

  m.def(
      "load_map",
      [](const std::string& source, double resolution) {
        io::MapLoadOptions load;
        load.default_resolution = resolution;
        return maps::load_map_source(source, load);
      },
      py::arg("source"), py::arg("resolution") = 0.05,
      "A built-in map by name (map_names()) or a PNG / PGM / map_server YAML file; `resolution` (metres per "
      "cell) is for a bare image, a YAML has its own. Raises InputError naming the file or name.");
  m.def("map_names", [] {
    std::vector<std::string> names;
    for (const auto& info : maps::builtin_maps()) names.push_back(info.name);
    return names;
  }, "The built-in maps' names (load_map, scenario key `map`).");
  m.def("strategy_names", &exploration::strategy_names,
        "Every coordination strategy's name, the built-in ones and those registered (scenario exploration.strategy).");
  m.def(
      "strategies", [] { return registry_members(exploration::strategy_registry()); },
      "Every coordination strategy, built-in and registered: a list of {name, help, params}, each parameter a "
      "{name, kind, default, unit, accepts, doc} (scenario exploration.strategy: {name: ..., KEY: VALUE}, "
      "--set strategy.KEY=VALUE).");
  m.def(
      "localizers", [] { return registry_members(localization::localizer_registry()); },
      "Every localizer, built-in and registered: a list of {name, help, params} as strategies() gives them "
      "(scenario localization: {name: ..., KEY: VALUE}, --set localization.KEY=VALUE).");
  m.def(
      "map_aligners", [] { return registry_members(merging::map_aligner_registry()); },
      "Every way robots bring a teammate's map into their frame (scenario merging), built-in and registered: a "
      "list of {name, help, params} as strategies() gives them (merging: {mode: ..., KEY: VALUE}, --set "
      "merging.KEY=VALUE).");
  m.def(
      "planners", [] { return registry_members(planning::planner_registry()); },
      "Every path planner, built-in and registered: a list of {name, help, params} as strategies() gives them "
      "(plan_path's `planner` and `params`, fleetmap plan --set planner.KEY=VALUE).");
  m.def("planner_names", &planning::planner_names, "Every path planner's name (plan_path's `planner`).");
  m.def("merge_method_names", &merging::merge_method_names, "Every merge method's name (merge_maps's `method`).");
  m.def(
      "merge_methods", [] { return registry_members(merging::merge_method_registry()); },
      "Every merge method, built-in and registered: a list of {name, help, params} as strategies() gives them "
      "(merge_maps's `method` and `params`, fleetmap merge --set METHOD.KEY=VALUE).");

  py::class_<Run>(m, "Run")
      .def_property_readonly("label", [](const Run& r) { return r.label; })
      .def_property_readonly("steps", [](const Run& r) { return r.result.steps; })
      .def_property_readonly("finished", [](const Run& r) { return r.result.finished; })
      .def("metrics_json", [](const Run& r) { return sim::metrics_json_text(r.result, r.label); })
      .def_property_readonly("coverage", [](const Run& r) { return py::array_t<double>(py::ssize_t(r.result.coverage.size()), r.result.coverage.data()); })
      .def_property_readonly("trajectories", [](const Run& r) {
        std::vector<py::array_t<double>> out;
        for (const auto& t : r.result.robots) out.push_back(pose_rows(t.truth));
        return out;
      })
      .def_property_readonly("estimates", [](const Run& r) {
        std::vector<py::array_t<double>> out;
        for (const auto& t : r.result.robots) out.push_back(pose_rows(t.estimate));
        return out;
      })
      .def_property_readonly("merged_map", [](const Run& r) { return r.result.merged; })
      .def_property_readonly("robot_maps", [](const Run& r) { return r.result.robot_maps; })
      .def(
          "write_outputs",
          [](const Run& r, const std::string& dir) {
            std::vector<std::string> files;
            for (const auto& p : sim::write_run_outputs(r.result, r.label, dir)) files.push_back(p.string());
            return files;
          },
          py::arg("folder"));
  m.def("_explore", &explore, py::arg("yaml"), py::arg("source"), py::arg("base_dir"),
        py::call_guard<py::gil_scoped_release>());
  m.def("_sweep", &run_sweep, py::arg("yaml"), py::arg("source"), py::arg("base_dir"), py::arg("jobs"), py::arg("out"),
        py::call_guard<py::gil_scoped_release>());
  m.def("_results_header", &sweep::results_header);
  m.def("_write_results", &write_results, py::arg("lines"), py::arg("path"));

  py::class_<PairMerge>(m, "MergeResult", "Map b aligned to map a, as `fleetmap merge a b` aligns them.")
      .def_property_readonly("merged", of_result(&merging::MergeResult::merged),
                             "Whether the confidence reached min_confidence.")
      .def_property_readonly("confidence", of_result(&merging::MergeResult::confidence), "In [0, 1].")
      .def_property_readonly("acceptance", of_result(&merging::MergeResult::acceptance),
                             "The share of cells known in both maps that agree at `transform` (Birk & Carpin "
                             "2006's omega).")
      .def_property_readonly("method", of_result(&merging::MergeResult::method),
                             "The method whose candidate won; empty when none.")
      .def_property_readonly("reason", of_result(&merging::MergeResult::reason), "Why not merged; empty when merged.")
      .def_property_readonly(
          "transform", [](const PairMerge& r) { return transform_tuple(r.placement().metres); },
          "(tx, ty, theta): b's map frame into a's, metres and degrees: a point p of b (metres, in the frame b's "
          "origin defines; a bare image's lower-left corner is (0, 0)) lies at R(theta) p + (tx, ty) in a's, as "
          "`fleetmap merge` reports tx_m, ty_m, theta_deg. The best candidate even when not merged.")
      .def_property_readonly(
          "pixel_transform", [](const PairMerge& r) { return transform_tuple(r.placement().pixels); },
          "(tx, ty, theta): pixel (u, v) of b (u = column, v = row from the top) lies at scale R(theta) (u, v) + "
          "(tx, ty) in a's pixel grid, theta in degrees (`fleetmap merge`'s tx_px, ty_px, theta_px_deg).")
      .def_property_readonly(
          "scale", [](const PairMerge& r) { return r.placement().scale; },
          "b's metres per cell / a's: the scale of pixel_transform.")
      .def_property_readonly(
          "covariance",
          [](const PairMerge& r) -> py::object {
            if (!r.placement().covariance) return py::none();
            py::array_t<double> out({3, 3});
            auto m = out.mutable_unchecked<2>();
            for (py::ssize_t i = 0; i < 3; ++i)
              for (py::ssize_t j = 0; j < 3; ++j) m(i, j) = (*r.placement().covariance)(i, j);
            return out;
          },
          "The 3 x 3 covariance of `transform`'s (tx, ty, theta) in metres, metres and radians, from the fit of the "
          "walls around the answer (a lower bound: wall cells taken as independent); None without one.")
      .def_property_readonly(
          "std",
          [](const PairMerge& r) -> py::object {
            if (!r.uncertainty()) return py::none();
            const auto& u = *r.uncertainty();
            return py::make_tuple(u.std_tx, u.std_ty, u.std_theta_deg);
          },
          "(std_tx_m, std_ty_m, std_theta_deg): the standard deviations of `transform` (`fleetmap merge`'s std_tx_m, "
          "std_ty_m, std_theta_deg); None without a covariance.")
      .def_property_readonly(
          "uncertain_direction",
          [](const PairMerge& r) -> py::object {
            if (!r.uncertainty()) return py::none();
            const auto& u = *r.uncertainty();
            return py::make_tuple(u.std_major, u.std_minor, u.major_deg);
          },
          "(std_major_m, std_minor_m, major_direction_deg): where the maps overlap, the largest and smallest standard "
          "deviation (metres) of where a point of b lands in a, and the direction of the largest (degrees from a's x "
          "axis, in [0, 180)); a corridor leaves its own axis the uncertain one. None without a covariance.")
      .def_property_readonly("map", &PairMerge::map,
                             "The fused map (a Map in a's frame and resolution, cut to the known cells and half a "
                             "metre around them: what `fleetmap merge a b --out merged.yaml` writes); None when not "
                             "merged.")
      .def("__repr__", [](const PairMerge& r) {
        return std::string("<fleetmap.MergeResult ") + (r.result().merged ? "merged" : "not merged") +
               ", confidence " + std::to_string(r.result().confidence) + ">";
      });
  m.def(
      "_merge_maps",
      [](const py::object& a, const py::object& b, const std::string& method, double min_confidence,
         std::uint64_t seed, const merging::MergeMethodSettings& method_settings) {
        const auto& ga = a.cast<const mapping::OccupancyGrid&>();
        const auto& gb = b.cast<const mapping::OccupancyGrid&>();
        if (ga.resolution() != gb.resolution()) check_resampled_size(gb, ga.resolution(), "merge_maps: b seen through a's cells");
        merging::MergeOptions options;
        options.method = method;
        options.method_settings = method_settings;
        options.min_confidence = min_confidence;
        options.seed = seed;
        merging::check_merge_method(method, method_settings);  // a bad parameter is refused before any work
        return PairMerge(a, b, options);
      },
      py::arg("a"), py::arg("b"), py::arg("method"), py::arg("min_confidence"), py::arg("seed"), py::arg("method_settings"));

  py::class_<planning::PlanResult>(m, "PlanResult", "A planned path.")
      .def_property_readonly("success", &planning::PlanResult::success, "Whether there is a path.")
      .def_property_readonly(
          "status", [](const planning::PlanResult& r) { return std::string(planning::to_string(r.status)); },
          "Why there is a path or none (e.g. 'success', 'goal in obstacle', 'no path within budget').")
      .def_readonly("planner", &planning::PlanResult::planner, "The planner that made it.")
      .def_readonly("length_m", &planning::PlanResult::length_m, "The path's length in metres (0 without a path).")
      .def_readonly("detail", &planning::PlanResult::detail, "More about the status, or empty.")
      .def_property_readonly(
          "path", [](const planning::PlanResult& r) { return point_rows(r.path); },
          "(N, 2) waypoints in metres from the start to the goal; empty unless success.")
      .def("__repr__", [](const planning::PlanResult& r) {
        return "<fleetmap.PlanResult " + std::string(planning::to_string(r.status)) + ", " + std::to_string(r.length_m) + " m>";
      });
  m.def(
      "_plan_path",
      [](const mapping::OccupancyGrid& map, std::pair<double, double> start, std::pair<double, double> goal,
         const std::string& planner, double robot_radius, double time_budget, std::uint64_t seed,
         const core::Settings& params) {
        auto made = planning::make_planner(planner, params);  // a bad parameter is refused before any work
        planning::FreeSpaceOptions space_options;
        space_options.robot_radius_m = robot_radius;
        const planning::FreeSpace space(map, space_options);
        planning::PlannerOptions options;
        options.time_budget_s = time_budget;
        options.seed = seed;
        return made->plan(space, {start.first, start.second}, {goal.first, goal.second}, options);
      },
      py::arg("map"), py::arg("start"), py::arg("goal"), py::arg("planner"), py::arg("robot_radius"),
      py::arg("time_budget"), py::arg("seed"), py::arg("params"), py::call_guard<py::gil_scoped_release>());

  m.def("_register_strategy", &register_python_strategy, py::arg("name"), py::arg("cls"), py::arg("help"),
        py::arg("joint"), py::arg("with_context"), py::arg("params"));
  m.def("_register_planner", &register_python_planner, py::arg("name"), py::arg("cls"), py::arg("help"),
        py::arg("complete"), py::arg("params"));
  m.def("_register_map_aligner", &register_python_map_aligner, py::arg("name"), py::arg("cls"), py::arg("help"),
        py::arg("params"));
  m.def("_register_localizer", &register_python_localizer, py::arg("name"), py::arg("cls"), py::arg("help"),
        py::arg("params"));
  m.def("_register_merge_method", &register_python_merge_method, py::arg("name"), py::arg("cls"), py::arg("help"),
        py::arg("params"));

  py::class_<AssignmentContext>(m, "AssignmentContext",
                                "What a Python strategy's assign gets as its optional fifth argument; valid only "
                                "while assign runs.")
      .def_property_readonly("team_indices", &AssignmentContext::team_indices,
                             "(R,) each robot's place in the team, 0..team_size-1 (the rows of poses and costs)")
      .def_property_readonly("team_size", &AssignmentContext::team_size, "robots in the team")
      .def_property_readonly("sensor_range", &AssignmentContext::sensor_range,
                             "the range sensor's reach, metres (targets this close to a claimed goal see less new)")
      .def_property_readonly("params", &AssignmentContext::params,
                             "the strategy's declared parameters with this run's values (register_strategy's params, "
                             "set by scenario exploration.strategy: {name: ..., KEY: VALUE} or --set strategy.KEY=VALUE)")
      .def("target_costs", &AssignmentContext::target_costs,
           "(T, T) wave costs between the targets' goals, metres (inf: not connected); computed when called")
      .def("target_gains", &AssignmentContext::target_gains,
           "(T,) never-observed area each target would reveal, square metres; computed when called");
}
