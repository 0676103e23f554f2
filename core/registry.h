#pragma once
// One open registry per family of variants: coordination strategies, localizers, map aligners,
// merge methods, planners, built-in maps. Each member has a name, a line of help, the parameters
// it declares (core/params.h) and a factory.
// The built-in members are added when the family is first used; a program that links fleetmap
// adds its own through the family's public register_* call, and the command line, scenario files
// and test harnesses then reach it by name like the built-in ones (as Nav2's plugins or OMPL's
// planner allocators).
#include <algorithm>
#include <deque>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "core/params.h"
#include "core/suggest.h"

namespace fleetmap::core {

template <typename Factory>
class Registry {
 public:
  struct Entry {
    std::string name;
    std::string help;  // one line: what the member does and its source
    Factory make;
    std::vector<ParamSpec> params;  // what the member can be given, with defaults
  };

  // `family` names the members in messages ("strategy", "localization", "planner").
  explicit Registry(std::string family) : family_(std::move(family)) {}

  // Throws Error for an empty name, a name with spaces or commas, or a name already taken.
  // Throws Error as Params does for an unusable declaration.
  void add(std::string name, std::string help, Factory make, std::vector<ParamSpec> params = {}) {
    if (name.empty() || name.find_first_of(" ,\t\n") != std::string::npos) {
      throw Error("register " + family_ + ": '" + name + "' is not a usable name (no spaces or commas)");
    }
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& e : entries_) {
      if (e.name == name) throw Error("register " + family_ + ": '" + name + "' is already registered");
    }
    Params check(family_ + " '" + name + "'", params);
    entries_.push_back({std::move(name), std::move(help), std::move(make), std::move(params)});
  }

  // Throws InputError naming the valid names (and the nearest one) for an unknown one.
  const Entry& get(std::string_view name) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& e : entries_) {
      if (e.name == name) return e;  // a deque keeps references valid while others are added
    }
    std::vector<std::string> names;
    std::string list;
    for (const auto& e : entries_) names.push_back(e.name), list += (list.empty() ? "" : ", ") + e.name;
    throw InputError("unknown " + family_ + " '" + std::string(name) + "'" + did_you_mean(name, names) + " (valid: " + list + ")");
  }

  // The member's parameters at their defaults (throws as get() for an unknown name).
  Params params(std::string_view name) const {
    const auto& e = get(name);
    return Params(family_ + " '" + e.name + "'", e.params);
  }

  // The member's parameters with `settings` applied in order. Throws InputError as get() for an
  // unknown name, and as Params::set for a setting it does not declare or a value it refuses.
  Params configure(std::string_view name, const Settings& settings) const {
    auto p = params(name);
    for (const auto& [key, value] : settings) p.set(key, value);
    return p;
  }

  // The settings among `settings` that member `name` declares: a sweep over several members gives
  // each its own parameters and runs the others unchanged.
  Settings declared(std::string_view name, const Settings& settings) const {
    const auto p = params(name);
    Settings out;
    for (const auto& s : settings) {
      if (p.declares(s.first)) out.push_back(s);
    }
    return out;
  }

  // Every parameter name some member declares, each once, in registration order.
  std::vector<std::string> parameter_names() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> out;
    for (const auto& e : entries_) {
      for (const auto& p : e.params) {
        if (std::find(out.begin(), out.end(), p.name) == out.end()) out.push_back(p.name);
      }
    }
    return out;
  }

  bool contains(std::string_view name) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& e : entries_) {
      if (e.name == name) return true;
    }
    return false;
  }

  // In the order they were registered: the built-in ones first.
  std::vector<std::string> names() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> out;
    for (const auto& e : entries_) out.push_back(e.name);
    return out;
  }

  // "  name: help" per member, then "      key = default (accepted): doc" per parameter, for --help.
  std::string help() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::string out;
    for (const auto& e : entries_) {
      out += "  " + e.name + ": " + e.help + "\n";
      for (const auto& p : e.params) out += "      " + p.describe() + "\n";
    }
    return out;
  }

  const std::string& family() const { return family_; }

 private:
  std::string family_;
  mutable std::mutex mutex_;
  std::deque<Entry> entries_;
};

}  // namespace fleetmap::core
