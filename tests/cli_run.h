#pragma once
// Runs the fleetmap executable as a user would, capturing its exit code, stdout and stderr.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/test_support.h"

namespace fleetmap::testing {

struct CliResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// `args` is appended to the binary path as shell words; stdin is /dev/null.
inline CliResult run_fleetmap(const std::string& args, const TempDir& scratch) {
  const auto out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  const std::string cmd = std::string("cd '") + scratch.path().string() + "' && '" + FLEETMAP_BINARY + "' " + args +
                          " >'" + out.string() + "' 2>'" + err.string() + "' </dev/null";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

inline int line_count(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n + (!s.empty() && s.back() != '\n');
}

// Bad input: a non-zero exit, exactly one line on stderr that contains `part`, nothing on stdout.
#define EXPECT_ONE_LINE_ERROR(result, part)                                          \
  do {                                                                               \
    const auto& r_ = (result);                                                       \
    EXPECT_NE(r_.exit_code, 0);                                                      \
    EXPECT_LT(r_.exit_code, 128) << "crashed: " << r_.err;                           \
    EXPECT_EQ(fleetmap::testing::line_count(r_.err), 1) << r_.err;                   \
    EXPECT_NE(r_.err.find(part), std::string::npos) << "'" << (part) << "' not in: " << r_.err; \
  } while (0)

}  // namespace fleetmap::testing
