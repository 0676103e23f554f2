// Every row of the README's bad-input table (section "### Bad input") is run as written: the
// command must exit with the code the table gives, print exactly the table's one line on stderr,
// never crash, and leave nothing behind in the folder it ran in.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "tests/cli_run.h"

namespace fleetmap::cli {
namespace {

using fleetmap::testing::run_fleetmap;
using fleetmap::testing::TempDir;

struct Row {
  std::string what, args, message;
  int exit_code = 0;
};

// Rows of the first Markdown table after the "### Bad input" heading of README.md.
std::vector<Row> readme_rows() {
  std::ifstream in(std::filesystem::path(FLEETMAP_SOURCE_DIR) / "README.md");
  std::vector<Row> rows;
  bool in_section = false;
  const std::regex row_re(R"(^\| ([^|]+) \| `fleetmap ([^`]+)` \| (\d+) \| `([^`]+)` \|$)");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("#", 0) == 0) {
      if (in_section) break;
      in_section = line == "### Bad input";
      continue;
    }
    std::smatch m;
    if (in_section && std::regex_match(line, m, row_re)) rows.push_back({m[1], m[2], m[4], std::stoi(m[3])});
  }
  return rows;
}

class BadInput : public ::testing::TestWithParam<Row> {};

TEST_P(BadInput, OneLineNonZeroExitNothingWritten) {
  const Row& row = GetParam();
  TempDir dir;
  std::filesystem::create_directory_symlink(std::filesystem::path(FLEETMAP_SOURCE_DIR) / "tests/data/bad_input",
                                            dir / "bad");
  const auto r = run_fleetmap(row.args, dir);
  EXPECT_EQ(r.exit_code, row.exit_code) << row.what << "\n" << r.err;
  EXPECT_EQ(r.err, row.message + "\n") << row.what;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    const std::string name = entry.path().filename().string();
    EXPECT_TRUE(name == "bad" || name == "stdout.txt" || name == "stderr.txt") << row.what << " left " << name;
  }
}

std::string row_name(const ::testing::TestParamInfo<Row>& info) {
  std::string name;
  for (char c : info.param.what) name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return std::to_string(info.index) + "_" + name;
}

INSTANTIATE_TEST_SUITE_P(ReadmeTable, BadInput, ::testing::ValuesIn(readme_rows()), row_name);

TEST(BadInputTable, HasARowForEveryKindTheIssueNames) {
  const auto rows = readme_rows();
  std::string all;
  for (const auto& r : rows) all += r.what + "\n";
  for (const char* kind : {"missing file", "directory", "empty file", "truncated PNG", "1x1", "0-sized", "huge",
                           "non-numeric", "unknown key", "NaN", "inf", "robot in a wall", "unreachable goal",
                           "no free cell", "all-unknown"}) {
    EXPECT_NE(all.find(kind), std::string::npos) << "no row for: " << kind;
  }
}

// A scenario, sweep or map file given to a command that reads another kind is named as what it is,
// with the command that reads it, instead of failing on one of its keys; nothing is written.
TEST(WrongKindOfFile, IsNamedWithTheCommandThatReadsIt) {
  TempDir dir;
  const std::string src = std::string(FLEETMAP_SOURCE_DIR) + "/";
  const std::string explore = src + "scenarios/office_rendezvous.yaml", slam = src + "scenarios/dalfonso_3robots.yaml",
                    corridor = src + "scenarios/leon_corridor.yaml", sweep = src + "scenarios/sweeps/burgard.yaml",
                    map = src + "maps/office.yaml";
  const struct {
    std::string args, message;
  } cases[] = {
      {"slam --scenario " + explore, explore + " is an exploration scenario, not a SLAM scenario: use fleetmap explore --scenario " + explore},
      {"slam --scenario " + map, map + " is a map (map_server YAML), not a SLAM scenario: use fleetmap explore --map " + map},
      {"slam --scenario " + sweep, sweep + " is a sweep file, not a SLAM scenario: use fleetmap bench --sweep " + sweep},
      {"explore --scenario " + slam, slam + " is a SLAM scenario, not an exploration scenario: use fleetmap slam --scenario " + slam},
      {"explore --scenario " + corridor, corridor + " is a SLAM scenario, not an exploration scenario: use fleetmap slam"},
      {"explore --scenario " + sweep, sweep + " is a sweep file, not an exploration scenario: use fleetmap bench --sweep " + sweep},
      {"explore --scenario " + map, map + " is a map (map_server YAML), not an exploration scenario"},
      {"bench --sweep " + explore, explore + " is an exploration scenario, not a sweep file: use fleetmap explore --scenario"},
      {"bench --sweep " + slam, slam + " is a SLAM scenario, not a sweep file: use fleetmap slam --scenario " + slam},
      {"bench --scenario " + sweep, sweep + " is a sweep file, not an exploration scenario: use fleetmap bench --sweep " + sweep},
  };
  for (const auto& c : cases) {
    const auto r = run_fleetmap(c.args + " --out out", dir);
    EXPECT_ONE_LINE_ERROR(r, c.message);
    EXPECT_EQ(r.exit_code, 2) << c.args;
    EXPECT_FALSE(std::filesystem::exists(dir / "out")) << c.args;
  }
  // A file of the expected kind with a mistake still gets the message about its key.
  dir.write("typo.yaml", "map: office\nrobots: 2\nmaps: [office]\nstrategies: [market]\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario typo.yaml --out out", dir), "unknown key 'maps'");
}

}  // namespace
}  // namespace fleetmap::cli
