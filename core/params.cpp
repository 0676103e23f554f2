#include "core/params.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/suggest.h"

namespace fleetmap::core {

namespace {

// A number as a scenario file writes it: the shortest text that reads back to the same double.
std::string canonical_number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt::format("{}", v);
}

bool usable_name(const std::string& name) {
  return !name.empty() && std::islower(static_cast<unsigned char>(name.front())) &&
         name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") == std::string::npos;
}

std::optional<std::string> canonical(const ParamSpec& spec, const std::string& value) {
  switch (spec.type) {
    case ParamSpec::Type::Number: {
      const auto v = parse_in_range(value, spec.range);
      if (!v) return std::nullopt;
      return canonical_number(*v);
    }
    case ParamSpec::Type::Flag:
      if (value == "true" || value == "yes" || value == "on" || value == "1") return std::string("true");
      if (value == "false" || value == "no" || value == "off" || value == "0") return std::string("false");
      return std::nullopt;
    case ParamSpec::Type::Text:
      if (value.empty() || value.find_first_of(" \t\n,=") != std::string::npos) return std::nullopt;
      if (!spec.choices.empty() && std::find(spec.choices.begin(), spec.choices.end(), value) == spec.choices.end()) {
        return std::nullopt;
      }
      return value;
  }
  return std::nullopt;
}

}  // namespace

ParamSpec ParamSpec::number(std::string name, double default_value, Range range, std::string unit, std::string doc) {
  ParamSpec s;
  s.name = std::move(name);
  s.type = Type::Number;
  s.default_value = canonical_number(default_value);
  s.range = range;
  s.unit = std::move(unit);
  s.doc = std::move(doc);
  return s;
}

ParamSpec ParamSpec::flag(std::string name, bool default_value, std::string doc) {
  ParamSpec s;
  s.name = std::move(name);
  s.type = Type::Flag;
  s.default_value = default_value ? "true" : "false";
  s.doc = std::move(doc);
  return s;
}

ParamSpec ParamSpec::text(std::string name, std::string default_value, std::vector<std::string> choices,
                          std::string doc) {
  ParamSpec s;
  s.name = std::move(name);
  s.type = Type::Text;
  s.default_value = std::move(default_value);
  s.choices = std::move(choices);
  s.doc = std::move(doc);
  return s;
}

std::string ParamSpec::expected() const {
  switch (type) {
    case Type::Number:
      return expected_text(range) + (unit.empty() ? "" : " (" + unit + ")");
    case Type::Flag:
      return "true or false";
    case Type::Text: {
      if (choices.empty()) return "a word without spaces or commas";
      std::string list;
      for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
      return "one of " + list;
    }
  }
  return {};
}

std::string ParamSpec::describe() const {
  // The unit follows the default, so the accepted numbers need not repeat it.
  const bool with_unit = type == Type::Number && !unit.empty();
  return name + " = " + default_value + (with_unit ? " " + unit : "") + "  (" +
         (with_unit ? expected_text(range) : expected()) + "): " + doc;
}

Params::Params(std::string owner, std::vector<ParamSpec> specs) : owner_(std::move(owner)), specs_(std::move(specs)) {
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    const auto& s = specs_[i];
    if (!usable_name(s.name)) {
      throw Error(owner_ + ": parameter '" + s.name + "' is not a usable name (lower case letters, digits and '_')");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (specs_[j].name == s.name) throw Error(owner_ + ": parameter '" + s.name + "' is declared twice");
    }
    const auto value = canonical(s, s.default_value);
    if (!value) {
      throw Error(owner_ + ": parameter '" + s.name + "': its default '" + s.default_value + "' is not " + s.expected());
    }
    values_.push_back(*value);
  }
}

void Params::set(const std::string& key, const std::string& value) {
  const auto it = std::find_if(specs_.begin(), specs_.end(), [&](const ParamSpec& s) { return s.name == key; });
  if (it == specs_.end()) {
    std::vector<std::string> names;
    std::string list;
    for (const auto& s : specs_) names.push_back(s.name), list += (list.empty() ? "" : ", ") + s.name;
    throw InputError(owner_ + " has no parameter '" + key + "'" + did_you_mean(key, names) +
                     (list.empty() ? " (it has none)" : " (it has: " + list + ")"));
  }
  const auto v = canonical(*it, value);
  if (!v) throw InputError(owner_ + ": parameter '" + key + "': expected " + it->expected() + ", got '" + value + "'");
  values_[std::size_t(it - specs_.begin())] = *v;
}

bool Params::declares(const std::string& key) const {
  return std::any_of(specs_.begin(), specs_.end(), [&](const ParamSpec& s) { return s.name == key; });
}

std::size_t Params::index(const std::string& key) const {
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    if (specs_[i].name == key) return i;
  }
  throw Error(owner_ + " reads parameter '" + key + "', which it does not declare");
}

double Params::number(const std::string& key) const {
  const auto i = index(key);
  if (specs_[i].type != ParamSpec::Type::Number) throw Error(owner_ + ": parameter '" + key + "' is not a number");
  return *parse_in_range(values_[i], specs_[i].range);
}

bool Params::flag(const std::string& key) const {
  const auto i = index(key);
  if (specs_[i].type != ParamSpec::Type::Flag) throw Error(owner_ + ": parameter '" + key + "' is not a flag");
  return values_[i] == "true";
}

const std::string& Params::text(const std::string& key) const {
  const auto i = index(key);
  if (specs_[i].type != ParamSpec::Type::Text) throw Error(owner_ + ": parameter '" + key + "' is not text");
  return values_[i];
}

const std::string& Params::value_text(const std::string& key) const { return values_[index(key)]; }

std::vector<std::string> Params::changed() const {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    if (values_[i] != *canonical(specs_[i], specs_[i].default_value)) out.push_back(specs_[i].name);
  }
  return out;
}

ParamAssignment parse_param_assignment(const std::string& text, const std::string& what) {
  const auto eq = text.find('=');
  const auto dot = text.find('.');
  if (eq == std::string::npos || dot == std::string::npos || dot > eq || dot == 0 || dot + 1 == eq ||
      eq + 1 == text.size()) {
    throw InputError(what + ": expected FAMILY.KEY=VALUE (e.g. strategy.beta=0.5), got '" + text + "'");
  }
  return {text.substr(0, dot), text.substr(dot + 1, eq - dot - 1), text.substr(eq + 1)};
}

}  // namespace fleetmap::core
