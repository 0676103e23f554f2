#include "sweep/sweep.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <cctype>
#include <set>
#include <utility>

#include <fmt/format.h>
#include "core/format.h"
#include "core/error.h"
#include "core/suggest.h"
#include "io/file_io.h"
#include "io/file_kind.h"
#include "io/yaml_reader.h"

namespace fleetmap::sweep {

namespace fs = std::filesystem;

namespace {

using core::join;
using core::split_list;
using core::trim;

template <typename T>
void check_unique(const std::vector<T>& items, const std::string& what) {
  for (std::size_t i = 0; i < items.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (items[i] == items[j]) {
        if constexpr (std::is_same_v<T, std::string>) throw InputError(what + ": '" + items[i] + "' is listed twice");
        else throw InputError(what + ": " + std::to_string(items[i]) + " is listed twice");
      }
    }
  }
}

// A list value of a sweep file: a YAML sequence or a comma-separated scalar, as one string.
std::optional<std::string> list_text(io::YamlMap& m, const std::string& key) {
  const auto node = m.node(key);
  if (!node) return std::nullopt;
  if (node->IsScalar()) return node->Scalar();
  if (!node->IsSequence() || node->size() == 0) {
    throw InputError(m.where(key) + ": expected a list such as [a, b] or 'a,b', got " + io::describe_node(*node));
  }
  std::vector<std::string> items;
  for (const auto& item : *node) {
    if (!item.IsScalar()) throw InputError(m.where(key) + ": expected a list of names or numbers, got " + io::describe_node(item));
    items.push_back(item.Scalar());
  }
  return join(items, ",");
}

bool looks_like_file(const std::string& source) {
  return source.find('/') != std::string::npos || fs::path(source).has_extension();
}


std::string number_text(double v) {
  if (std::isinf(v)) return "inf";
  return fmt::format("{:.17g}", v);
}


// Short names of common axes and the scenario keys they stand for.
const std::vector<std::pair<std::string, std::string>>& axis_aliases() {
  static const std::vector<std::pair<std::string, std::string>> kAliases = {
      {"beams", "sensors.range.beams"},          {"sensor_range", "sensors.range.max_range"},
      {"comm_range", "communication.range"},     {"localization", "localization.method"},
      {"merging", "merging.mode"},               {"path_planner", "exploration.path_planner"},
      {"steps", "steps"},                        {"noise_position", "noise.position"},
  };
  return kAliases;
}

std::vector<std::string> short_names() {
  std::vector<std::string> names;
  for (const auto& [alias, full] : axis_aliases()) names.push_back(alias);
  return names;
}

// The short names, and every key of a scenario file that holds one value, dotted
// ("sensors.range.beams"): the settings an axis can vary.
const std::vector<std::string>& axis_settings() {
  static const std::vector<std::string> kSettings = [] {
    std::vector<std::string> names = short_names();
    const auto walk = [&](const auto& self, const YAML::Node& node, const std::string& prefix) -> void {
      for (const auto& kv : node) {
        const std::string key = prefix + kv.first.Scalar();
        if (kv.second.IsMap()) self(self, kv.second, key + ".");
        else names.push_back(key);
      }
    };
    walk(walk, YAML::Load(sim::scenario_to_yaml(sim::Scenario{})), "");
    return names;
  }();
  return kSettings;
}

// "(valid: beams, sensor_range, ..., or a scenario file's key, dotted, such as sensors.range.noise)".
std::string valid_settings_text() {
  return "(valid: " + join(short_names()) + ", or a scenario file's key, dotted, such as sensors.range.noise)";
}

// "what: unknown strategy 'x' (did you mean 'y'?) (valid: ...)".
InputError unknown_strategy(const std::string& what, const std::string& name) {
  const auto valid = exploration::strategy_names();
  return InputError(what + ": unknown strategy '" + name + "'" + core::did_you_mean(name, valid) + " (valid: " + join(valid) +
                    ", or all on its own)");
}

// Sets the dotted `path` of a YAML mapping to a scalar, making the mappings on the way.
void set_path(YAML::Node node, const std::vector<std::string>& parts, std::size_t at, const std::string& value,
              const std::string& what) {
  if (at + 1 == parts.size()) {
    node[parts[at]] = value;
    return;
  }
  YAML::Node child = node[parts[at]];
  if (child.IsDefined() && !child.IsNull() && !child.IsMap()) {
    throw InputError(what + ": '" + parts[at] + "' is a single setting, not a group of settings");
  }
  set_path(child, parts, at + 1, value, what);
}

// A scenario error about the generated text, without its meaningless line number.
std::string without_place(const std::string& message, const std::string& source) {
  if (message.rfind(source + ":", 0) != 0) return message;
  std::size_t at = source.size() + 1;
  while (at < message.size() && std::isdigit(static_cast<unsigned char>(message[at]))) ++at;
  if (at < message.size() && message[at] == ':') ++at;
  while (at < message.size() && message[at] == ' ') ++at;
  return message.substr(at);
}

// The base for runs of `strategy`: the strategy settings it does not declare dropped.
sim::Scenario for_strategy(const sim::Scenario& base, const std::string& strategy) {
  sim::Scenario s = base;
  s.exploration.strategy = strategy;
  s.exploration.strategy_settings = exploration::declared_settings(strategy, base.exploration.strategy_settings);
  return s;
}

// `s` with each family's settings cut to those its member declares (the others are for members an
// axis chooses).
sim::Scenario declared_only(sim::Scenario s) {
  for (const auto& f : sim::parameter_families()) {
    const core::Params declared = f.params(f.member(s));
    std::erase_if(f.settings(s), [&](const auto& kv) { return !declared.declares(kv.first); });
  }
  return s;
}

// The family parameter an axis sets ("strategy.beta", "exploration.strategy.beta",
// "localization.particles"): its family and key, or no family for a plain scenario key.
struct FamilyParameter {
  const sim::ParameterFamily* family = nullptr;
  std::string key;
};
FamilyParameter family_parameter(const std::string& scenario_key, const std::vector<std::string>& plain_keys) {
  if (std::find(plain_keys.begin(), plain_keys.end(), scenario_key) != plain_keys.end()) return {};
  for (const auto& f : sim::parameter_families()) {
    for (const std::string& prefix : {f.name + ".", f.group + "."}) {
      if (scenario_key.rfind(prefix, 0) == 0 && scenario_key.size() > prefix.size() &&
          scenario_key.find('.', prefix.size()) == std::string::npos) {
        return {&f, scenario_key.substr(prefix.size())};
      }
    }
  }
  return {};
}

// The settings of `family` in `s`: those of `given` that the member declares, then the axes' values
// of parameters it declares.
core::Settings member_settings(const sim::ParameterFamily& family, const sim::Scenario& s, const core::Settings& given,
                               const std::vector<SweepAxis>& axes, const std::vector<std::string>& values,
                               const std::vector<std::string>& plain_keys) {
  const core::Params declared = family.params(family.member(s));
  core::Settings out;
  for (const auto& kv : given) {
    if (declared.declares(kv.first)) out.push_back(kv);
  }
  for (std::size_t i = 0; i < axes.size(); ++i) {
    const auto p = family_parameter(axes[i].scenario_key, plain_keys);
    if (p.family != &family || !declared.declares(p.key)) continue;
    std::erase_if(out, [&](const auto& kv) { return kv.first == p.key; });
    out.emplace_back(p.key, values[i]);
  }
  return out;
}

// The base with one value per axis. An axis over a parameter the run's member of its family (its
// strategy, its localizer) does not declare leaves the run alone: a sweep of several strategies
// varies each one's own parameters.
sim::Scenario with_values(const sim::Scenario& base, const std::vector<SweepAxis>& axes,
                          const std::vector<std::string>& values) {
  if (axes.empty()) return base;
  const std::string what = variant_label(axes, values);
  // The members' settings are applied after the file is read back, since an axis may change the
  // member they belong to.
  sim::Scenario given = base, plain = base;
  for (const auto& f : sim::parameter_families()) f.settings(plain).clear();
  YAML::Node root = YAML::Load(sim::scenario_to_yaml(plain));
  const auto& plain_keys = axis_settings();
  for (std::size_t i = 0; i < axes.size(); ++i) {
    if (family_parameter(axes[i].scenario_key, plain_keys).family) continue;
    std::vector<std::string> parts;
    std::size_t start = 0;
    for (std::size_t dot; (dot = axes[i].scenario_key.find('.', start)) != std::string::npos; start = dot + 1) {
      parts.push_back(axes[i].scenario_key.substr(start, dot - start));
    }
    parts.push_back(axes[i].scenario_key.substr(start));
    set_path(root, parts, 0, values[i], axes[i].name + "=" + values[i]);
  }
  YAML::Emitter out;
  out << root;
  const std::string source = "@sweep-axis@";
  try {
    sim::Scenario s = sim::parse_scenario(out.c_str(), source, base.base_dir);
    s.map = base.map;
    for (const auto& f : sim::parameter_families()) {
      f.settings(s) = member_settings(f, s, f.settings(given), axes, values, plain_keys);
    }
    sim::validate_scenario(s);
    return s;
  } catch (const InputError& e) {
    throw InputError("axis " + what + ": " + without_place(e.what(), source));
  }
}

}  // namespace

SweepAxis make_axis(const std::string& key, const std::vector<std::string>& values, const std::string& what) {
  SweepAxis axis;
  axis.name = trim(key);
  axis.scenario_key = axis.name;
  for (const auto& [alias, full] : axis_aliases()) {
    if (alias == axis.name) axis.scenario_key = full;
  }
  const std::string& k = axis.scenario_key;
  if (k.empty() || k.find_first_of(" =,\"'") != std::string::npos || k.front() == '.' || k.back() == '.' ||
      k.find("..") != std::string::npos) {
    throw InputError(what + ": '" + key + "' is not a setting " + valid_settings_text());
  }
  // The team (its size and where it starts) is the robots axis; the robots' radius, speed and the
  // like are settings like any other.
  if (k == "map" || k == "seed" || k == "robots" || k == "robots.count" || k == "robots.random" || k == "robots.starts" ||
      k == "exploration.strategy" || k == "strategy" || k == "exploration.strategy.name") {
    throw InputError(what + ": '" + key + "' is an axis of every sweep already; use maps, robots, strategies or seeds");
  }
  // FAMILY.KEY: a parameter some member of the family declares (the runs of members that do not
  // declare it are left alone).
  if (const auto p = family_parameter(k, axis_settings()); p.family) {
    const auto declared = p.family->parameter_names();
    if (std::find(declared.begin(), declared.end(), p.key) == declared.end()) {
      throw InputError(what + ": no " + p.family->name + " has a parameter '" + p.key + "'" +
                       core::did_you_mean(p.key, declared) + " (the " + p.family->name +
                       " parameters: " + (declared.empty() ? std::string("none") : join(declared)) + ")");
    }
  } else if (const auto& settings = axis_settings(); std::find(settings.begin(), settings.end(), k) == settings.end()) {
    throw InputError(what + ": unknown setting '" + axis.name + "'" + core::did_you_mean(axis.name, settings) + " " +
                     valid_settings_text());
  }
  if (values.empty()) throw InputError(what + ": '" + key + "' needs at least one value");
  for (const auto& v : values) {
    if (v.empty() || v.find_first_of(" \t,\"'=") != std::string::npos) {
      throw InputError(what + ": value '" + v + "' of '" + key + "': values may not be empty or hold spaces, commas, quotes or =");
    }
  }
  check_unique(values, what);
  axis.values = values;
  return axis;
}

SweepAxis parse_axis(const std::string& text, const std::string& what) {
  const auto eq = text.find('=');
  if (eq == std::string::npos) {
    throw InputError(what + ": expected SETTING=VALUE,VALUE,... such as beams=90,360 or communication.range=5,inf, got '" +
                     text + "'");
  }
  return make_axis(text.substr(0, eq), split_list(text.substr(eq + 1), what), what);
}

std::string variant_label(const std::vector<SweepAxis>& axes, const std::vector<std::string>& values) {
  std::string label;
  for (std::size_t i = 0; i < axes.size() && i < values.size(); ++i) {
    label += (label.empty() ? "" : " ") + axes[i].name + "=" + values[i];
  }
  return label;
}

namespace {

// The "name=value" items of a variant label.
std::vector<std::string> variant_items(const std::string& variant) {
  std::vector<std::string> items;
  std::size_t start = 0;
  while (start < variant.size()) {
    const auto space = variant.find(' ', start);
    items.push_back(variant.substr(start, space == std::string::npos ? std::string::npos : space - start));
    if (space == std::string::npos) break;
    start = space + 1;
  }
  return items;
}

}  // namespace

std::optional<std::string> variant_value(const std::string& variant, const std::string& name) {
  for (const auto& item : variant_items(variant)) {
    if (item.rfind(name + "=", 0) == 0) return item.substr(name.size() + 1);
  }
  return std::nullopt;
}

std::string variant_without(const std::string& variant, const std::string& name) {
  std::string out;
  for (const auto& item : variant_items(variant)) {
    if (item.rfind(name + "=", 0) != 0) out += (out.empty() ? "" : " ") + item;
  }
  return out;
}

std::vector<std::string> variant_names(const std::string& variant) {
  std::vector<std::string> names;
  for (const auto& item : variant_items(variant)) names.push_back(item.substr(0, item.find('=')));
  return names;
}

void use_base(Sweep& sweep, sim::Scenario base) {
  if (base.placement == sim::Placement::List) base.placement = sim::Placement::Cluster, base.starts.clear();
  sweep.base = std::move(base);
}

std::string map_label(const std::string& source) {
  return looks_like_file(source) ? fs::path(source).stem().string() : source;
}

std::vector<std::string> parse_map_list(const std::string& text, const std::string& what) {
  auto maps = split_list(text, what);
  check_unique(maps, what);
  return maps;
}

std::vector<std::string> parse_strategy_list(const std::string& text, const std::string& what) {
  const auto valid = exploration::strategy_names();
  if (trim(text) == "all") return valid;
  auto names = split_list(text, what);
  for (const auto& n : names) {
    if (n == "all") throw InputError(what + ": 'all' stands alone (every strategy); give all, or a list of strategies without it");
    if (std::find(valid.begin(), valid.end(), n) == valid.end()) throw unknown_strategy(what, n);
  }
  check_unique(names, what);
  return names;
}

std::vector<int> parse_team_sizes(const std::string& text, const std::string& what) {
  const auto whole = [&](const std::string& item, const std::string& part) {
    const bool digits = !part.empty() && part.size() <= 3 && std::all_of(part.begin(), part.end(), [](char c) {
      return c >= '0' && c <= '9';
    });
    const int v = digits ? std::stoi(part) : 0;
    if (v < 1 || v > 64) {
      throw InputError(what + ": team size '" + item + "': expected whole numbers from 1 to 64, e.g. 1,2,4,9 or 1-9");
    }
    return v;
  };
  std::vector<int> sizes;
  for (const auto& item : split_list(text, what)) {
    const auto dash = item.find('-', 1);
    if (dash == std::string::npos) {
      sizes.push_back(whole(item, item));
      continue;
    }
    const int lo = whole(item, trim(item.substr(0, dash))), hi = whole(item, trim(item.substr(dash + 1)));
    if (hi < lo) throw InputError(what + ": team sizes '" + item + "': the range runs backwards");
    for (int n = lo; n <= hi; ++n) sizes.push_back(n);
  }
  check_unique(sizes, what);
  return sizes;
}

double parse_comm_range(const std::string& text, const std::string& what) {
  if (const auto v = core::parse_in_range(trim(text), sim::limits::kCommRange)) return *v;
  throw InputError(what + ": expected " + core::expected_text(sim::limits::kCommRange) + ", got '" + text + "'");
}

Sweep parse_sweep(const std::string& text, const std::string& source, const fs::path& base_dir) {
  const YAML::Node root = io::parse_yaml(text, source);
  if (!root || root.IsNull()) throw InputError(source + ": empty sweep file");
  io::check_yaml_file_kind(root, source, io::YamlFileKind::Sweep);
  io::YamlMap top(root, source);
  Sweep sweep;
  if (const auto scenario = top.node("scenario")) {
    if (!scenario->IsScalar() || scenario->Scalar().empty()) {
      throw InputError(top.where("scenario") + ": expected the path of a scenario file, got " + io::describe_node(*scenario));
    }
    fs::path p = scenario->Scalar();
    if (p.is_relative()) p = base_dir / p;
    if (!io::is_regular_file(p)) throw InputError(top.where("scenario") + ": no scenario file '" + p.string() + "'");
    use_base(sweep, sim::load_scenario(p));
  }
  if (const auto maps = list_text(top, "maps")) {
    sweep.maps = parse_map_list(*maps, top.where("maps"));
    for (auto& m : sweep.maps) {
      // A file is relative to the sweep file; a built-in name stays a name unless such a file is there.
      if (fs::path(m).is_relative() && (looks_like_file(m) || io::is_regular_file(base_dir / m))) m = (base_dir / m).string();
    }
  }
  if (const auto s = list_text(top, "strategies")) sweep.strategies = parse_strategy_list(*s, top.where("strategies"));
  if (const auto r = list_text(top, "robots")) sweep.robots = parse_team_sizes(*r, top.where("robots"));
  sweep.seeds = int(top.number("seeds", sweep.seeds, kSeedCountRange));
  sweep.first_seed = top.seed("first_seed", sweep.first_seed);
  sweep.base.steps = int(top.number("steps", sweep.base.steps, sim::limits::kSteps));
  sweep.base.localization = top.text("localization", sweep.base.localization);
  sweep.base.merging = top.choice("merging", sweep.base.merging, sim::merging_names());
  if (const auto c = top.node("comm_range")) {
    if (!c->IsScalar()) throw InputError(top.where("comm_range") + ": expected metres >= 0 or 'inf'");
    sweep.base.communication.range_m = parse_comm_range(c->Scalar(), top.where("comm_range"));
  }
  sweep.base.range.max_range_m = top.number("sensor_range", sweep.base.range.max_range_m, sim::limits::kSensorRange);
  if (const auto vary = top.node("vary")) {
    if (!vary->IsMap() || vary->size() == 0) {
      throw InputError(top.where("vary") + ": expected settings with their values, such as {beams: [90, 360]}, got " +
                       io::describe_node(*vary));
    }
    io::YamlMap axes(*vary, source, "vary");
    for (const auto& item : *vary) {
      const std::string key = item.first.Scalar();
      const auto values = list_text(axes, key);
      sweep.axes.push_back(make_axis(key, split_list(*values, axes.where(key)), axes.where(key)));
    }
    axes.finish();
  }
  top.finish();
  try {
    validate_sweep(sweep);
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
  return sweep;
}

Sweep load_sweep(const fs::path& path) {
  return parse_sweep(io::read_file(path, std::size_t{1} << 20), path.string(), path.parent_path());
}

void validate_sweep(const Sweep& sweep) {
  if (sweep.maps.empty()) throw InputError("maps: the sweep needs at least one map");
  if (sweep.strategies.empty()) throw InputError("strategies: the sweep needs at least one strategy");
  if (sweep.robots.empty()) throw InputError("robots: the sweep needs at least one team size");
  if (!core::parse_in_range(std::to_string(sweep.seeds), kSeedCountRange)) {
    throw InputError("seeds: expected " + core::expected_text(kSeedCountRange) + ", got " + std::to_string(sweep.seeds));
  }
  if (sweep.first_seed > std::numeric_limits<std::uint64_t>::max() - std::uint64_t(sweep.seeds - 1)) {
    throw InputError("first_seed: " + std::to_string(sweep.first_seed) + " with " + std::to_string(sweep.seeds) +
                     " seeds runs past the largest seed, 18446744073709551615");
  }
  check_unique(sweep.maps, "maps");
  check_unique(sweep.strategies, "strategies");
  check_unique(sweep.robots, "robots");
  std::set<std::string> labels;
  for (const auto& m : sweep.maps) {
    if (!labels.insert(map_label(m)).second) throw InputError("maps: two maps are named '" + map_label(m) + "' (" + join(sweep.maps) + ")");
    if (map_label(m).find_first_of(",\"\n") != std::string::npos) throw InputError("maps: '" + m + "': map names may not hold , or \"");
  }
  const auto valid = exploration::strategy_names();
  for (const auto& s : sweep.strategies) {
    if (std::find(valid.begin(), valid.end(), s) == valid.end()) throw unknown_strategy("strategies", s);
  }
  for (int n : sweep.robots) {
    if (n < 1 || n > 64) throw InputError("robots: team size " + std::to_string(n) + ": expected 1 to 64");
  }
  std::vector<std::string> keys;
  for (const auto& axis : sweep.axes) keys.push_back(axis.scenario_key);
  check_unique(keys, "vary");
  // A member's parameter, set or varied, belongs to at least one member of the sweep in its family:
  // one of its strategies, its localizer or one its axes choose.
  for (const auto& family : sim::parameter_families()) {
    std::vector<std::string> members;
    if (family.name == "strategy") {
      members = sweep.strategies;
    } else {
      members.push_back(family.member(sweep.base));
      for (const auto& axis : sweep.axes) {
        if (axis.scenario_key == family.group || axis.scenario_key == family.group + ".method" ||
            axis.scenario_key == family.group + ".name" || axis.scenario_key == family.group + ".mode") {
          members.insert(members.end(), axis.values.begin(), axis.values.end());
        }
      }
    }
    std::vector<std::pair<std::string, std::string>> parameters;  // (key, where it was given)
    sim::Scenario base = sweep.base;
    for (const auto& kv : family.settings(base)) {
      parameters.emplace_back(kv.first, family.name + "." + kv.first);
    }
    for (const auto& axis : sweep.axes) {
      if (const auto p = family_parameter(axis.scenario_key, axis_settings()); p.family == &family) {
        parameters.emplace_back(p.key, "vary " + axis.name);
      }
    }
    for (const auto& parameter : parameters) {
      const std::string& key = parameter.first;  // not a structured binding: clang 14 cannot capture one
      const std::string& where = parameter.second;
      const auto declares = [&](const std::string& m) {
        try {
          return family.params(m).declares(key);
        } catch (const InputError&) {
          return false;  // an unknown member: its axis says so below
        }
      };
      if (std::none_of(members.begin(), members.end(), declares)) {
        throw InputError(where + ": no " + family.name + " of this sweep (" + join(members) + ") has a parameter '" + key + "'");
      }
    }
  }
  // Every value of every axis makes a valid scenario for every strategy (checked one axis at a
  // time, the others at their first value), before any run starts.
  std::vector<std::string> values;
  for (const auto& axis : sweep.axes) values.push_back(axis.values.front());
  for (const auto& strategy : sweep.strategies) {
    sim::Scenario probe = for_strategy(sweep.base, strategy);
    probe.robot_count = sweep.robots.front();
    sim::validate_scenario(declared_only(probe));
    for (std::size_t i = 0; i < sweep.axes.size(); ++i) {
      std::vector<std::string> v = values;
      for (const auto& value : sweep.axes[i].values) {
        v[i] = value;
        with_values(probe, sweep.axes, v);
      }
    }
  }
}

std::string sweep_to_yaml(const Sweep& sweep, const std::string& scenario_file) {
  std::string y = "# fleetmap bench sweep: run it again with `fleetmap bench --sweep FILE`\n";
  std::vector<std::string> maps;
  for (const auto& m : sweep.maps) maps.push_back(io::yaml_quoted(looks_like_file(m) && io::path_exists(m) ? fs::absolute(m).lexically_normal().string() : m));
  y += "maps: [" + join(maps) + "]\n";
  y += "strategies: [" + join(sweep.strategies) + "]\n";
  std::vector<std::string> robots;
  for (int n : sweep.robots) robots.push_back(std::to_string(n));
  y += "robots: [" + join(robots) + "]\n";
  y += "seeds: " + std::to_string(sweep.seeds) + "\nfirst_seed: " + std::to_string(sweep.first_seed) + "\n";
  if (!scenario_file.empty()) y += "scenario: " + io::yaml_quoted(scenario_file) + "\n";
  y += "steps: " + std::to_string(sweep.base.steps) + "\n";
  y += "localization: " + sweep.base.localization + "\n";
  y += "merging: " + sweep.base.merging + "\n";
  y += "comm_range: " + number_text(sweep.base.communication.range_m) + "\n";
  y += "sensor_range: " + number_text(sweep.base.range.max_range_m) + "\n";
  if (!sweep.axes.empty()) {
    y += "vary:\n";
    for (const auto& axis : sweep.axes) y += "  " + axis.name + ": [" + join(axis.values) + "]\n";
  }
  return y;
}

std::vector<SweepRun> sweep_runs(const Sweep& sweep) {
  // Every combination of the axes' values, the first axis slowest.
  std::vector<std::vector<std::string>> variants = {{}};
  for (const auto& axis : sweep.axes) {
    std::vector<std::vector<std::string>> next;
    for (const auto& v : variants) {
      for (const auto& value : axis.values) {
        next.push_back(v);
        next.back().push_back(value);
      }
    }
    variants = std::move(next);
  }
  std::vector<SweepRun> runs;
  for (const auto& map : sweep.maps) {
    for (const auto& strategy : sweep.strategies) {
      for (int robots : sweep.robots) {
        for (const auto& values : variants) {
          for (int k = 0; k < sweep.seeds; ++k) {
            runs.push_back({runs.size(), map_label(map), map, strategy, robots, sweep.first_seed + std::uint64_t(k),
                            values, variant_label(sweep.axes, values)});
          }
        }
      }
    }
  }
  return runs;
}

sim::Scenario run_scenario(const Sweep& sweep, const SweepRun& run) {
  if (run.values.size() != sweep.axes.size()) throw Error("sweep: a run without a value for every axis");
  sim::Scenario s = with_values(for_strategy(sweep.base, run.strategy), sweep.axes, run.values);
  s.map = run.map_source;
  s.base_dir.clear();
  s.robot_count = run.robots;
  s.seed = run.seed;
  return s;
}

std::vector<SweepRun> shard_runs(const std::vector<SweepRun>& runs, const Shard& shard) {
  std::vector<SweepRun> out;
  for (const auto& r : runs) {
    if (int(r.index % std::size_t(shard.count)) == shard.index - 1) out.push_back(r);
  }
  return out;
}

std::string settings_id(const sim::Scenario& base) {
  sim::Scenario s = base;
  s.map.clear();
  s.base_dir.clear();
  s.seed = 0;
  s.robot_count = 1;
  s.exploration.strategy.clear();
  if (s.placement == sim::Placement::List) s.placement = sim::Placement::Cluster, s.starts.clear();
  const std::string text = sim::scenario_to_yaml(s);
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a, 64 bits
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return fmt::format("{:016x}", h);
}

}  // namespace fleetmap::sweep
