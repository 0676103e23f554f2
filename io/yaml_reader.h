#pragma once
// Strict reading of YAML mappings into option structs: every key must be read (unknown keys are
// errors that list the valid ones), and every error names the file, the line, the key and what
// was expected.
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/params.h"
#include "core/range.h"

namespace fleetmap::io {

class YamlMap {
 public:
  // `source` names the file in messages; `prefix` is the dotted path of this mapping ("" at top).
  // Throws InputError when `node` is not a mapping, has a key that is not a name (null, a list or
  // a mapping), or holds a key twice (YAML keeps both and readers would silently take one).
  YamlMap(const YAML::Node& node, std::string source, std::string prefix = "");

  bool has(const std::string& key) const;
  // The keys written, in file order.
  std::vector<std::string> keys() const;
  // The raw node (marks the key as known); nullopt when absent.
  std::optional<YAML::Node> node(const std::string& key);
  // A nested mapping; absent keys give an empty mapping.
  YamlMap map(const std::string& key);

  // Numbers: within [lo, hi]; "inf" / ".inf" accepted only when allow_inf.
  double number(const std::string& key, double fallback, double lo = -std::numeric_limits<double>::infinity(),
                double hi = std::numeric_limits<double>::infinity(), bool allow_inf = false);
  long long integer(const std::string& key, long long fallback, long long lo = std::numeric_limits<long long>::min(),
                    long long hi = std::numeric_limits<long long>::max());
  // A number in `range` (a whole one when range.whole).
  double number(const std::string& key, double fallback, const core::Range& range);
  std::uint64_t seed(const std::string& key, std::uint64_t fallback);
  bool boolean(const std::string& key, bool fallback);
  std::string text(const std::string& key, const std::string& fallback);
  std::string choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& valid);
  // A registered member chosen by `key`: its name (`strategy: coordinated`) or a mapping of its name
  // and its own parameters (`strategy: {name: coordinated, beta: 0.5}`). Each parameter is checked
  // against `declared(name)` (the member's parameters at their defaults); errors name the key.
  // An absent key gives `fallback`; a mapping without `name` keeps the fallback's member.
  struct Member {
    std::string name;
    std::vector<std::pair<std::string, std::string>> settings;  // in the order written
  };
  Member member(const std::string& key, const Member& fallback, const std::vector<std::string>& valid,
                const std::function<core::Params(const std::string&)>& declared);
  // A list of numbers; `size` 0 accepts any length.
  std::vector<double> numbers(const std::string& key, std::size_t size = 0);

  // Throws InputError for the first key that was never asked for.
  void finish() const;

  // "file:line: key 'prefix.key'" for messages about a value.
  std::string where(const std::string& key) const;
  std::string where_node(const YAML::Node& node) const;
  const std::string& source() const { return source_; }
  std::string full_key(const std::string& key) const { return prefix_.empty() ? key : prefix_ + "." + key; }

 private:
  YAML::Node node_;
  std::string source_;
  std::string prefix_;
  std::vector<std::string> asked_;
};

// Sets a member's declared parameter and records it among `settings` (replacing an earlier value);
// errors are prefixed with `where`.
void set_declared(core::Params& params, core::Settings& settings, const std::string& key, const std::string& value,
                  const std::string& where);
// Reads the keys of `m` that `params` declares (each a scalar) into params and settings.
void read_declared(YamlMap& m, core::Params& params, core::Settings& settings);

// Parses YAML text; syntax errors become InputError "source:line: not valid YAML (...)".
YAML::Node parse_yaml(const std::string& text, const std::string& source);

// The text of a scalar or a short description of a non-scalar, for messages.
std::string describe_node(const YAML::Node& node);

// `text` as a YAML double-quoted scalar that reads back as the same bytes: quotes and backslashes
// escaped, control characters (line breaks included, which YAML would fold) as \xHH.
std::string yaml_quoted(const std::string& text);

}  // namespace fleetmap::io
