#include "io/yaml_reader.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "core/format.h"
#include "core/error.h"
#include "core/suggest.h"

namespace fleetmap::io {

std::string describe_node(const YAML::Node& node) {
  if (!node || node.IsNull()) return "nothing";
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  return "something else";
}

YAML::Node parse_yaml(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(source + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML (" + e.msg + ")");
  }
}

YamlMap::YamlMap(const YAML::Node& node, std::string source, std::string prefix)
    : node_(node), source_(std::move(source)), prefix_(std::move(prefix)) {
  if (node_ && !node_.IsNull() && !node_.IsMap()) {
    throw InputError(where_node(node_) + ": " + (prefix_.empty() ? std::string("the file") : "key '" + prefix_ + "'") +
                     ": expected a mapping of keys, got " + describe_node(node_));
  }
  if (!node_ || !node_.IsMap()) return;
  std::vector<std::pair<std::string, YAML::Mark>> seen;
  for (const auto& kv : node_) {
    // A key must be a name: YAML allows null, list and mapping keys, which no reader looks up.
    if (!kv.first.IsScalar()) {
      throw InputError(where_node(kv.first) + ": " + (prefix_.empty() ? std::string("the file") : "key '" + prefix_ + "'") +
                       ": expected a name as key, got " + describe_node(kv.first));
    }
    const std::string key = kv.first.Scalar();
    for (const auto& [other, mark] : seen) {
      if (other != key) continue;
      throw InputError(where_node(kv.first) + ": key '" + full_key(key) + "' is given twice (first on line " +
                       std::to_string(mark.line + 1) + ")");
    }
    seen.emplace_back(key, kv.first.Mark());
  }
}

std::string YamlMap::where_node(const YAML::Node& n) const {
  const auto mark = n.Mark();
  return mark.line >= 0 ? source_ + ":" + std::to_string(mark.line + 1) : source_;
}

std::string YamlMap::where(const std::string& key) const {
  const YAML::Node n = node_ && node_.IsMap() ? node_[key] : YAML::Node();
  return (n ? where_node(n) : source_) + ": key '" + full_key(key) + "'";
}

bool YamlMap::has(const std::string& key) const { return node_ && node_.IsMap() && node_[key]; }

std::vector<std::string> YamlMap::keys() const {
  std::vector<std::string> out;
  if (!node_ || !node_.IsMap()) return out;
  for (const auto& kv : node_) out.push_back(kv.first.Scalar());
  return out;
}

std::optional<YAML::Node> YamlMap::node(const std::string& key) {
  if (std::find(asked_.begin(), asked_.end(), key) == asked_.end()) asked_.push_back(key);
  if (!has(key)) return std::nullopt;
  return node_[key];
}

YamlMap YamlMap::map(const std::string& key) {
  const auto n = node(key);
  return YamlMap(n ? *n : YAML::Node(), source_, full_key(key));
}

double YamlMap::number(const std::string& key, double fallback, double lo, double hi, bool allow_inf) {
  const auto n = node(key);
  if (!n) return fallback;
  double v = 0.0;
  const std::string range = (std::isfinite(lo) ? " >= " + YAML::Node(lo).Scalar() : std::string()) +
                            (std::isfinite(lo) && std::isfinite(hi) ? " and" : "") +
                            (std::isfinite(hi) ? " <= " + YAML::Node(hi).Scalar() : std::string());
  const std::string expected = "expected a number" + range + (allow_inf ? " (or inf)" : "");
  if (allow_inf && n->IsScalar()) {
    std::string t = n->Scalar();
    for (char& ch : t) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    if (t == "inf" || t == "infinity" || t == "+inf") return std::numeric_limits<double>::infinity();
  }
  if (!n->IsScalar() || !YAML::convert<double>::decode(*n, v) || std::isnan(v) || (std::isinf(v) && !allow_inf)) {
    throw InputError(where(key) + ": " + expected + ", got " + describe_node(*n));
  }
  if (v < lo || v > hi) throw InputError(where(key) + ": " + expected + ", got " + describe_node(*n));
  return v;
}

long long YamlMap::integer(const std::string& key, long long fallback, long long lo, long long hi) {
  const auto n = node(key);
  if (!n) return fallback;
  long long v = 0;
  if (!n->IsScalar() || !YAML::convert<long long>::decode(*n, v) || v < lo || v > hi) {
    throw InputError(where(key) + ": expected a whole number from " + std::to_string(lo) + " to " + std::to_string(hi) +
                     ", got " + describe_node(*n));
  }
  return v;
}

double YamlMap::number(const std::string& key, double fallback, const core::Range& range) {
  const auto n = node(key);
  if (!n) return fallback;
  const auto v = n->IsScalar() ? core::parse_in_range(n->Scalar(), range) : std::nullopt;
  if (!v) throw InputError(where(key) + ": expected " + core::expected_text(range) + ", got " + describe_node(*n));
  return *v;
}

std::uint64_t YamlMap::seed(const std::string& key, std::uint64_t fallback) {
  const auto n = node(key);
  if (!n) return fallback;
  const auto v = n->IsScalar() ? core::parse_seed(n->Scalar()) : std::nullopt;
  if (!v) throw InputError(where(key) + ": expected " + std::string(core::kSeedExpected) + ", got " + describe_node(*n));
  return *v;
}

bool YamlMap::boolean(const std::string& key, bool fallback) {
  const auto n = node(key);
  if (!n) return fallback;
  bool v = false;
  if (!n->IsScalar() || !YAML::convert<bool>::decode(*n, v)) {
    throw InputError(where(key) + ": expected true or false, got " + describe_node(*n));
  }
  return v;
}

std::string YamlMap::text(const std::string& key, const std::string& fallback) {
  const auto n = node(key);
  if (!n) return fallback;
  if (!n->IsScalar()) throw InputError(where(key) + ": expected text, got " + describe_node(*n));
  return n->Scalar();
}

std::string YamlMap::choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& valid) {
  const std::string v = text(key, fallback);
  if (std::find(valid.begin(), valid.end(), v) != valid.end()) return v;
  throw InputError(where(key) + ": unknown value '" + v + "'" + core::did_you_mean(v, valid) + " (valid: " +
                   core::join(valid) + ")");
}

YamlMap::Member YamlMap::member(const std::string& key, const Member& fallback, const std::vector<std::string>& valid,
                                const std::function<core::Params(const std::string&)>& declared) {
  const auto n = node(key);
  if (!n) return fallback;
  if (n->IsScalar()) return {choice(key, fallback.name, valid), {}};
  if (!n->IsMap()) throw InputError(where(key) + ": expected a name or {name: NAME, PARAMETER: VALUE, ...}, got " + describe_node(*n));
  YamlMap m(*n, source_, full_key(key));
  Member out;
  out.name = m.choice("name", fallback.name, valid);
  if (out.name == fallback.name && !m.has("name")) out.settings = fallback.settings;
  core::Params params = declared(out.name);
  for (const auto& kv : *n) {
    const std::string k = kv.first.Scalar();
    if (k == "name") continue;
    m.node(k);
    if (!kv.second.IsScalar()) {
      throw InputError(m.where(k) + ": expected " + (params.declares(k) ? "a value" : "a parameter") + ", got " +
                       describe_node(kv.second));
    }
    set_declared(params, out.settings, k, kv.second.Scalar(), m.where(k));
  }
  return out;
}

void set_declared(core::Params& params, core::Settings& settings, const std::string& key, const std::string& value,
                  const std::string& where) {
  try {
    params.set(key, value);
  } catch (const InputError& e) {
    throw InputError(where + ": " + e.what());
  }
  std::erase_if(settings, [&](const auto& kv) { return kv.first == key; });
  settings.emplace_back(key, params.value_text(key));
}

void read_declared(YamlMap& m, core::Params& params, core::Settings& settings) {
  for (const auto& spec : params.specs()) {
    const auto node = m.node(spec.name);
    if (!node) continue;
    if (!node->IsScalar()) throw InputError(m.where(spec.name) + ": expected a value, got " + describe_node(*node));
    set_declared(params, settings, spec.name, node->Scalar(), m.where(spec.name));
  }
}

std::vector<double> YamlMap::numbers(const std::string& key, std::size_t size) {
  const auto n = node(key);
  if (!n) return {};
  const std::string expected = size ? "a list of " + std::to_string(size) + " numbers" : "a list of numbers";
  if (!n->IsSequence() || (size && n->size() != size)) {
    throw InputError(where(key) + ": expected " + expected + ", got " + describe_node(*n));
  }
  std::vector<double> out;
  for (const auto& item : *n) {
    double v = 0.0;
    if (!item.IsScalar() || !YAML::convert<double>::decode(item, v) || !std::isfinite(v)) {
      throw InputError(where(key) + ": expected " + expected + ", got an item " + describe_node(item));
    }
    out.push_back(v);
  }
  return out;
}

void YamlMap::finish() const {
  if (!node_ || !node_.IsMap()) return;
  for (const auto& kv : node_) {
    const std::string key = kv.first.Scalar();
    if (std::find(asked_.begin(), asked_.end(), key) != asked_.end()) continue;
    std::string names;
    for (const auto& s : asked_) names += (names.empty() ? "" : ", ") + s;
    throw InputError(where_node(kv.first) + ": unknown key '" + full_key(key) + "'" + core::did_you_mean(key, asked_) +
                     (names.empty() ? "" : " (valid" + (prefix_.empty() ? std::string() : " in '" + prefix_ + "'") +
                                               ": " + names + ")"));
  }
}

std::string yaml_quoted(const std::string& text) {
  std::string q = "\"";
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      q += '\\';
      q += c;
    } else if (u < 0x20 || u == 0x7f) {
      static constexpr char kHex[] = "0123456789ABCDEF";
      q += "\\x";
      q += kHex[u >> 4];
      q += kHex[u & 15];
    } else {
      q += c;
    }
  }
  return q + "\"";
}

}  // namespace fleetmap::io
