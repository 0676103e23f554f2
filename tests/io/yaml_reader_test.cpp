#include "io/yaml_reader.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/test_support.h"

namespace fleetmap::io {
namespace {

using core::Range;

using fleetmap::testing::expect_input_error;

TEST(YamlMap, AKeyGivenTwiceIsAnErrorAtEveryLevel) {
  const auto top = [](const std::string& text) { YamlMap(parse_yaml(text, "s.yaml"), "s.yaml"); };
  expect_input_error([&] { top("steps: 10\nseed: 1\nsteps: 20\n"); }, {"s.yaml:3: key 'steps' is given twice (first on line 1)"});
  expect_input_error(
      [&] {
        YamlMap m(parse_yaml("robots:\n  count: 2\n  radius: 0.2\n  count: 3\n", "s.yaml"), "s.yaml");
        m.map("robots");
      },
      {"s.yaml:4: key 'robots.count' is given twice (first on line 2)"});
  EXPECT_NO_THROW(top("a: 1\nb: {a: 2}\n"));
}

TEST(YamlMap, AKeyMustBeAName) {
  const auto read = [](const std::string& text) {
    YamlMap top(parse_yaml(text, "s.yaml"), "s.yaml");
    top.map("methods");
  };
  expect_input_error([&] { read("methods:\n  ~: 3\n"); }, {"s.yaml:2: key 'methods': expected a name as key, got nothing"});
  expect_input_error([&] { read("null: 1\n"); }, {"s.yaml:1: the file: expected a name as key, got nothing"});
  expect_input_error([&] { read("methods:\n  [a]: 3\n"); }, {"s.yaml:2: key 'methods': expected a name as key, got a list"});
  EXPECT_NO_THROW(read("methods:\n  particles: 3\n"));
}

TEST(YamlMap, NumbersAndSeedsFollowTheirRange) {
  YamlMap m(parse_yaml("beams: 10000000\nseed: 18446744073709551615\nbad_seed: -1\nrange: .inf\n", "f.yaml"), "f.yaml");
  expect_input_error([&] { m.number("beams", 360, Range{1, 100000, true}); },
                     {"f.yaml:1: key 'beams': expected a whole number from 1 to 100000, got '10000000'"});
  EXPECT_EQ(m.seed("seed", 1), 18446744073709551615ull);
  expect_input_error([&] { m.seed("bad_seed", 1); },
                     {"f.yaml:3: key 'bad_seed': expected a whole number from 0 to 18446744073709551615, got '-1'"});
  EXPECT_TRUE(std::isinf(m.number("range", 1, Range{0, std::numeric_limits<double>::infinity(), false, true})));
  expect_input_error([&] { m.number("range", 1, Range{0, 10}); }, {"key 'range': expected a number >= 0 and <= 10, got '.inf'"});
}

}  // namespace
}  // namespace fleetmap::io
