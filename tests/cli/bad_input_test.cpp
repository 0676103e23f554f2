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

}  // namespace
}  // namespace fleetmap::cli
