#pragma once
// The parameters a registered member (a strategy, a localizer, a map aligner, a planner) declares,
// and the values it is built with. Built-in members and plug-ins declare them alike; scenario files,
// `--set family.key=value` and sweep axes set them by name, checked against the declaration, and
// `--help` and `fleetmap plugins` list them from it (as OMPL's ParamSet or Nav2's declared
// parameters).
#include <string>
#include <utility>
#include <vector>

#include "core/range.h"

namespace fleetmap::core {

struct ParamSpec {
  enum class Type { Number, Flag, Text };
  std::string name;           // a scenario key: lower case, digits and '_'
  Type type = Type::Number;
  std::string default_value;  // as a scenario file writes it
  std::string unit;           // "m", "deg", "particles"; empty for a pure number
  Range range;                // numbers: what is accepted (whole numbers for counts)
  std::vector<std::string> choices;  // text: the values accepted; empty accepts any word
  std::string doc;                   // one line: what it changes

  static ParamSpec number(std::string name, double default_value, Range range, std::string unit, std::string doc);
  static ParamSpec flag(std::string name, bool default_value, std::string doc);
  static ParamSpec text(std::string name, std::string default_value, std::vector<std::string> choices, std::string doc);

  // "a number >= 0 and <= 10 (m)", "true or false", "one of a, b".
  std::string expected() const;
  // "beta = 1 (a number >= 0 ...): weight of travel cost", one line for --help.
  std::string describe() const;
};

// Values for one member's declared parameters, each holding its default until set.
class Params {
 public:
  Params() = default;
  // `owner` names the member in messages: "strategy 'coordinated'". Throws Error for a declaration
  // that is not usable (a repeated or malformed name, a default its own range refuses).
  Params(std::string owner, std::vector<ParamSpec> specs);

  // Sets `key` from its text. Throws InputError naming the owner, the key and the problem: an
  // undeclared key (with the nearest declared one and the list), a value of the wrong kind or out
  // of range (with what is accepted).
  void set(const std::string& key, const std::string& value);
  bool declares(const std::string& key) const;

  // The value of a declared key; asking for an undeclared one (or of another type) is the
  // member's own bug and throws Error.
  double number(const std::string& key) const;
  bool flag(const std::string& key) const;
  const std::string& text(const std::string& key) const;

  // The value as a scenario file writes it.
  const std::string& value_text(const std::string& key) const;
  // Declared keys whose value differs from the default, in declaration order.
  std::vector<std::string> changed() const;

  const std::string& owner() const { return owner_; }
  const std::vector<ParamSpec>& specs() const { return specs_; }

  bool operator==(const Params& other) const { return specs_.size() == other.specs_.size() && values_ == other.values_; }

 private:
  std::size_t index(const std::string& key) const;  // throws Error for an undeclared key

  std::string owner_;
  std::vector<ParamSpec> specs_;
  std::vector<std::string> values_;  // canonical text, one per spec
};

// Settings for a member as given by the user, key and value text, in the order given (a scenario
// file's `{name: coordinated, beta: 0.5}`, `--set strategy.beta=0.5`); checked when applied.
using Settings = std::vector<std::pair<std::string, std::string>>;

// Splits "family.key=value" (as given to --set) into its three parts; throws InputError naming
// `what` when one is missing.
struct ParamAssignment {
  std::string family;
  std::string key;
  std::string value;
};
ParamAssignment parse_param_assignment(const std::string& text, const std::string& what);

}  // namespace fleetmap::core
