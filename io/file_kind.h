#pragma once
// Which kind of fleetmap YAML file a file is, told by its top-level keys: an exploration scenario
// (`fleetmap explore`), a sweep file (`fleetmap bench --sweep`), a SLAM scenario (`fleetmap slam`)
// or a map_server map. Each reader checks it first, so that a file given to the wrong command is
// named as what it is, with the command that reads it, instead of failing on one of its keys.
#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>

namespace fleetmap::io {

enum class YamlFileKind { ExploreScenario, Sweep, SlamScenario, MapServerMap };

// The kind `root` clearly is: one with `experiment:` or two keys only SLAM scenarios have is a SLAM
// scenario; otherwise the kind with the most keys of its own, when it has two or more. nullopt when
// no kind is clear (a short or mistyped file).
std::optional<YamlFileKind> recognise_yaml_file(const YAML::Node& root);

// Throws InputError "SOURCE is a sweep file, not an exploration scenario: use fleetmap bench --sweep
// SOURCE" when `root` is clearly another kind and has no key of `expected`'s own, so that a file of
// the expected kind with a mistake still gets the reader's message about that key.
void check_yaml_file_kind(const YAML::Node& root, const std::string& source, YamlFileKind expected);

}  // namespace fleetmap::io
