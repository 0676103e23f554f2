#include "io/file_kind.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "io/file_io.h"
#include "io/yaml_reader.h"
#include "tests/test_support.h"

namespace fleetmap::io {
namespace {

using fleetmap::testing::expect_input_error;

std::optional<YamlFileKind> kind_of(const std::filesystem::path& file) {
  return recognise_yaml_file(parse_yaml(read_file(file), file.string()));
}

// Every ready file is recognised as the kind of the command that reads it.
TEST(YamlFileKind, EveryReadyFileIsRecognised) {
  namespace fs = std::filesystem;
  const fs::path src = FLEETMAP_SOURCE_DIR;
  int files = 0;
  for (const auto& [folder, kind] : {std::pair{src / "maps", YamlFileKind::MapServerMap}, std::pair{src / "scenarios/sweeps", YamlFileKind::Sweep}}) {
    for (const auto& entry : fs::directory_iterator(folder)) {
      if (entry.path().extension() != ".yaml") continue;
      EXPECT_EQ(kind_of(entry.path()), kind) << entry.path();
      ++files;
    }
  }
  for (const auto& entry : fs::directory_iterator(src / "scenarios")) {
    if (entry.path().extension() != ".yaml") continue;
    const std::string text = read_file(entry.path());
    // The SLAM scenarios say what they are: a method of `fleetmap slam`, or an experiment.
    const bool slam = text.find("\nmethod:") != std::string::npos || text.rfind("method:", 0) == 0 ||
                      text.find("experiment:") != std::string::npos;
    EXPECT_EQ(kind_of(entry.path()), slam ? YamlFileKind::SlamScenario : YamlFileKind::ExploreScenario) << entry.path();
    ++files;
  }
  EXPECT_GE(files, 20);
}

TEST(YamlFileKind, AnotherKindIsNamedOnlyWhenClear) {
  const auto check = [](const std::string& text, YamlFileKind expected) {
    check_yaml_file_kind(parse_yaml(text, "f.yaml"), "f.yaml", expected);
  };
  expect_input_error([&] { check("maps: [office]\nstrategies: all\n", YamlFileKind::ExploreScenario); },
                     {"f.yaml is a sweep file, not an exploration scenario: use fleetmap bench --sweep f.yaml"});
  expect_input_error([&] { check("image: a.png\nresolution: 0.05\n", YamlFileKind::Sweep); },
                     {"f.yaml is a map (map_server YAML), not a sweep file"});
  expect_input_error([&] { check("experiment: leon_corridor\n", YamlFileKind::ExploreScenario); },
                     {"f.yaml is a SLAM scenario, not an exploration scenario: use fleetmap slam --scenario f.yaml"});
  // One key of another kind is a mistake in this kind's file, for its reader to name.
  EXPECT_NO_THROW(check("maps: [office]\nrobots: 2\n", YamlFileKind::ExploreScenario));
  // A key of the expected kind's own: the file is that kind, with mistakes.
  EXPECT_NO_THROW(check("map: office\nmaps: [office]\nstrategies: all\n", YamlFileKind::ExploreScenario));
  EXPECT_NO_THROW(check("steps: 3\n", YamlFileKind::SlamScenario));
  EXPECT_NO_THROW(check("[1, 2]\n", YamlFileKind::Sweep));
}

}  // namespace
}  // namespace fleetmap::io
