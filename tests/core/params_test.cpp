#include "core/params.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/registry.h"
#include "tests/test_support.h"

namespace fleetmap::core {
namespace {

using fleetmap::testing::expect_input_error;

Params sample() {
  return Params("strategy 'sample'",
                {ParamSpec::number("beta", 1.0, {0, 10}, "", "weight of cost"),
                 ParamSpec::number("particles", 30, {1, 1000, true}, "particles", "how many"),
                 ParamSpec::flag("greedy", false, "one at a time"),
                 ParamSpec::text("mode", "fast", {"fast", "exact"}, "how hard to try")});
}

TEST(Params, DefaultsUntilSet) {
  Params p = sample();
  EXPECT_DOUBLE_EQ(p.number("beta"), 1.0);
  EXPECT_DOUBLE_EQ(p.number("particles"), 30.0);
  EXPECT_FALSE(p.flag("greedy"));
  EXPECT_EQ(p.text("mode"), "fast");
  EXPECT_TRUE(p.changed().empty());
  p.set("beta", "0.25");
  p.set("greedy", "yes");
  p.set("mode", "exact");
  EXPECT_DOUBLE_EQ(p.number("beta"), 0.25);
  EXPECT_TRUE(p.flag("greedy"));
  EXPECT_EQ(p.value_text("greedy"), "true");
  EXPECT_EQ(p.changed(), (std::vector<std::string>{"beta", "greedy", "mode"}));
}

TEST(Params, BadValuesSayWhatIsAccepted) {
  Params p = sample();
  expect_input_error([&] { p.set("bta", "1"); }, {"strategy 'sample' has no parameter 'bta'", "did you mean 'beta'",
                                                  "beta, particles, greedy, mode"});
  expect_input_error([&] { p.set("beta", "11"); }, {"'beta'", "<= 10", "got '11'"});
  expect_input_error([&] { p.set("beta", "nan"); }, {"'beta'", "got 'nan'"});
  expect_input_error([&] { p.set("particles", "2.5"); }, {"'particles'", "whole number", "(particles)"});
  expect_input_error([&] { p.set("greedy", "maybe"); }, {"'greedy'", "true or false"});
  expect_input_error([&] { p.set("mode", "slow"); }, {"'mode'", "one of fast, exact"});
  EXPECT_DOUBLE_EQ(p.number("beta"), 1.0) << "a refused value leaves the old one";
}

TEST(Params, AMemberReadingWhatItDidNotDeclareIsItsOwnBug) {
  const Params p = sample();
  EXPECT_THROW(p.number("gamma"), Error);
  EXPECT_THROW(p.flag("beta"), Error);
  try {
    p.number("gamma");
  } catch (const InputError&) {
    ADD_FAILURE() << "not the user's input";
  } catch (const Error&) {
  }
}

TEST(Params, UnusableDeclarationsAreRefusedWhenRegistered) {
  Registry<int> r("strategy");
  EXPECT_THROW(r.add("a", "", 0, {ParamSpec::number("Beta", 1, {}, "", "")}), Error);
  EXPECT_THROW(r.add("b", "", 0, {ParamSpec::number("x", 1, {}, "", ""), ParamSpec::flag("x", true, "")}), Error);
  EXPECT_THROW(r.add("c", "", 0, {ParamSpec::number("x", 5, {0, 1}, "", "")}), Error);
  r.add("d", "", 0, {ParamSpec::number("x", 0.5, {0, 1}, "m", "a length")});
  EXPECT_DOUBLE_EQ(r.params("d").number("x"), 0.5);
  EXPECT_EQ(r.params("d").owner(), "strategy 'd'");
  EXPECT_NE(r.help().find("x = 0.5 m"), std::string::npos) << r.help();
}

TEST(Params, AssignmentsFromTheCommandLine) {
  const auto a = parse_param_assignment("strategy.beta=0.5", "--set");
  EXPECT_EQ(a.family, "strategy");
  EXPECT_EQ(a.key, "beta");
  EXPECT_EQ(a.value, "0.5");
  for (const char* bad : {"beta=0.5", "strategy.beta", ".beta=1", "strategy.=1", "strategy.beta="}) {
    expect_input_error([&] { parse_param_assignment(bad, "--set"); }, {"--set", "FAMILY.KEY=VALUE", bad});
  }
}

}  // namespace
}  // namespace fleetmap::core
