#include <gtest/gtest.h>

#include "app/cli.h"

using namespace pxf;

namespace {
struct Fixture {
  int spp = 4;
  float threshold = 0.01f;
  bool all_hv = false;
  std::string filter = "bilateral-depth", out;
  int width = 0, height = 0;
  CommandLine cli{"render", "[options]", "test"};
  Fixture() {
    cli.option("--spp", &spp, "samples", 1, 1 << 20);
    cli.option("--threshold", &threshold, "t", 0.0f, 1e6f);
    cli.flag("--all-hv", &all_hv, "all HV");
    cli.choice("--filter", &filter, {"bilateral-depth", "bilateral", "none"}, "variant");
    cli.option("--out", &out, "DIR", "output");
    cli.size_option("--size", &width, &height, "size");
  }
};
}  // namespace

TEST(CommandLine, ParsesEveryKindOfOption) {
  Fixture f;
  ASSERT_TRUE(f.cli.parse({"--spp", "64", "--threshold=0.5", "--all-hv", "--filter", "bilateral", "--out", "x",
                           "--size", "320x200"}));
  EXPECT_EQ(f.spp, 64);
  EXPECT_FLOAT_EQ(f.threshold, 0.5f);
  EXPECT_TRUE(f.all_hv);
  EXPECT_EQ(f.filter, "bilateral");
  EXPECT_EQ(f.out, "x");
  EXPECT_EQ(f.width, 320);
  EXPECT_EQ(f.height, 200);
  EXPECT_TRUE(f.cli.given("--spp"));
  EXPECT_FALSE(Fixture().cli.given("--spp"));
}

TEST(CommandLine, RejectsBadInputWithOneLineMessages) {
  const std::vector<std::vector<std::string>> bad = {
      {"--nope"},              {"--spp"},          {"--spp", "abc"},     {"--spp", "0"},
      {"--spp", "1.5"},        {"--spp", "1e30"},  {"--threshold", "-1"}, {"--threshold", "nan"},
      {"--filter", "gauss"},   {"--size", "12"},   {"--size", "0x5"},    {"--all-hv=1"},
      {"stray"},
  };
  for (const auto& args : bad) {
    Fixture f;
    try {
      f.cli.parse(args);
      ADD_FAILURE() << "accepted: " << args[0];
    } catch (const UsageError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
}

TEST(CommandLine, HelpListsEveryOptionAndStopsParsing) {
  Fixture f;
  testing::internal::CaptureStdout();
  EXPECT_FALSE(f.cli.parse({"--help"}));
  const std::string help = testing::internal::GetCapturedStdout();
  for (const char* name : {"--spp", "--threshold", "--all-hv", "--filter", "--out", "--size"})
    EXPECT_NE(help.find(name), std::string::npos) << name;
}

TEST(CommandLine, RequiresPositionals) {
  std::string a, b;
  CommandLine cli("diff", "A B", "test");
  cli.positional("A", &a, "first");
  cli.positional("B", &b, "second");
  EXPECT_THROW(cli.parse({"only-one"}), UsageError);
  CommandLine cli2("diff", "A B", "test");
  cli2.positional("A", &a, "first");
  cli2.positional("B", &b, "second");
  EXPECT_TRUE(cli2.parse({"x.exr", "y.exr"}));
  EXPECT_EQ(a, "x.exr");
  EXPECT_EQ(b, "y.exr");
}

TEST(CommandLine, PositionalListTakesEveryRemainingArgument) {
  std::vector<std::string> states;
  std::string out;
  CommandLine cli{"merge", "STATE...", "test"};
  cli.positional_list("STATE...", &states, "states");
  cli.option("--out", &out, "DIR", "output");
  ASSERT_TRUE(cli.parse({"a.pxfs", "--out", "d", "b.pxfs", "c.pxfs"}));
  EXPECT_EQ(states, (std::vector<std::string>{"a.pxfs", "b.pxfs", "c.pxfs"}));
  EXPECT_EQ(out, "d");
  std::vector<std::string> none;
  CommandLine empty{"merge", "STATE...", "test"};
  empty.positional_list("STATE...", &none, "states");
  EXPECT_THROW(empty.parse({}), UsageError);
}

// A limit given as a float is compared as a float (0.1 is inside [0.1f, ...]), and
// limits print as a person reads them.
TEST(CommandLine, FloatLimitsCompareInTheirTypeAndPrintReadably) {
  float sigma = 0;
  int spp = 0;
  CommandLine cli{"render", "[options]", "test"};
  cli.option("--sigma-s", &sigma, "sigma", 0.1f, 64.0f / 3.0f);
  cli.option("--spp", &spp, "samples", 1, 1 << 24);
  ASSERT_TRUE(cli.parse({"--sigma-s", "0.1"}));
  EXPECT_FLOAT_EQ(sigma, 0.1f);
  try {
    cli.parse({"--sigma-s", "22"});
    FAIL() << "22 accepted";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("[0.1, 21.33333]"), std::string::npos) << e.what();
  }
  try {
    cli.parse({"--spp", "16777217"});
    FAIL() << "16777217 accepted";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("[1, 16777216]"), std::string::npos) << e.what();
  }
  EXPECT_THROW(cli.parse({"--sigma-s", "1e99"}), UsageError);  // beyond float: out of range, not inf
}

TEST(CommandLine, ChoiceBindsAnEnumThroughItsNameTable) {
  enum class Color { Red, Green, Blue };
  Color color = Color::Red;
  bool on = false;
  CommandLine cli{"render", "[options]", "test"};
  cli.choice("--color", &color, {"red", "green", "blue"}, "color");
  cli.choice("--switch", &on, {"off", "on"}, "a bool named by its table");
  ASSERT_TRUE(cli.parse({"--color", "blue", "--switch=on"}));
  EXPECT_EQ(color, Color::Blue);
  EXPECT_TRUE(on);
  EXPECT_NE(cli.help().find("--color red|green|blue"), std::string::npos);
  CommandLine bad{"render", "[options]", "test"};
  bad.choice("--color", &color, {"red", "green", "blue"}, "color");
  EXPECT_THROW(bad.parse({"--color", "Blue"}), UsageError);  // names are exact
  EXPECT_EQ(color, Color::Blue);                              // unchanged by the refused value
}

TEST(CommandLine, Uint64OptionKeepsItsRange) {
  uint64_t seed = 1;
  CommandLine cli{"render", "[options]", "test"};
  cli.option("--seed", &seed, "seed", 0, 2147483647);
  ASSERT_TRUE(cli.parse({"--seed", "2147483647"}));
  EXPECT_EQ(seed, 2147483647u);
  for (const char* bad : {"-1", "2147483648", "1.5"}) {
    CommandLine c{"render", "[options]", "test"};
    c.option("--seed", &seed, "seed", 0, 2147483647);
    EXPECT_THROW(c.parse({"--seed", bad}), UsageError) << bad;
  }
}
