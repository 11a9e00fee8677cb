// apps/cli_args: the option parsing every subcommand shares (CLI11 underneath), and the words a
// user sees when the command line is wrong.

#include "cli_args.hpp"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace pitchlab::apps {
namespace {

CliArgs Declared() {
  CliArgs args("demo", "A command to test the parser.");
  args.Positionals("CLOUD", "clouds", 1, 2)
      .Option("seed", "N", "random seed", "1")
      .Option("pose", "x,y,yaw", "start pose")
      .Option("out", "FILE", "where to write")
      .Flag("json", "print JSON");
  return args;
}

// Parses `words` (the arguments after the subcommand); CliError propagates.
CliArgs Parsed(std::vector<std::string> words) {
  CliArgs args = Declared();
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  EXPECT_TRUE(args.Parse(static_cast<int>(argv.size()), argv.data()));
  return args;
}

// The CliError's message for `words`, or "" when they parse.
std::string ErrorOf(std::vector<std::string> words) {
  try {
    Parsed(std::move(words));
  } catch (const CliError& e) {
    return e.what();
  }
  return "";
}

TEST(CliArgs, ValuesSpacedOrAfterEqualsDefaultsFlagsAndPositionalsAreRead) {
  const CliArgs a = Parsed({"a.pcd", "--pose", "-8,0.5,90", "--out=m.pcd", "b.pcd", "--json"});
  EXPECT_EQ(a.positionals(), (std::vector<std::string>{"a.pcd", "b.pcd"}));
  EXPECT_EQ(a.GetNumbers("pose", 3), (std::vector<double>{-8, 0.5, 90}));  // a negative value
  EXPECT_EQ(a.Get("out"), "m.pcd");
  EXPECT_EQ(a.GetWholeNumber("seed"), 1u);  // the default
  EXPECT_TRUE(a.Has("seed"));
  EXPECT_FALSE(a.Flagged("seed"));
  EXPECT_TRUE(a.Flagged("json"));
  EXPECT_FALSE(Parsed({"a.pcd"}).Flagged("json"));
  EXPECT_FALSE(Parsed({"a.pcd"}).Has("out"));
}

TEST(CliArgs, AfterADoubleDashAnArgumentStartingWithADashIsAPositional) {
  EXPECT_EQ(Parsed({"--json", "--", "-odd.pcd"}).positionals(),
            std::vector<std::string>{"-odd.pcd"});
}

TEST(CliArgs, MistakesAreNamedAsTheUserWroteThem) {
  EXPECT_EQ(ErrorOf({"a.pcd", "--frobnicate"}), "unknown option '--frobnicate' for 'demo' (see --help)");
  EXPECT_EQ(ErrorOf({"a.pcd", "--frob=3"}), "unknown option '--frob' for 'demo' (see --help)");
  EXPECT_EQ(ErrorOf({"a.pcd", "--seed", "2", "--seed", "3"}), "--seed given 2 times: give it once");
  EXPECT_EQ(ErrorOf({"a.pcd", "--json", "--json"}), "--json given 2 times: give it once");
  EXPECT_EQ(ErrorOf({"a.pcd", "--json=no"}), "--json takes no value");
  EXPECT_EQ(ErrorOf({}), "'demo' needs 1..2 CLOUD argument(s), got 0");
  EXPECT_EQ(ErrorOf({"a", "b", "c"}), "'demo' needs 1..2 CLOUD argument(s), got 3");
  EXPECT_NE(ErrorOf({"a.pcd", "--out"}).find("--out"), std::string::npos);
  EXPECT_EQ(ErrorOf({"a.pcd"}), "");
}

TEST(CliArgs, TypedGettersRefuseWhatIsNotANumberOfTheRightKind) {
  EXPECT_THROW(Parsed({"a", "--pose", "1,2"}).GetNumbers("pose", 3), CliError);
  EXPECT_THROW(Parsed({"a", "--pose", "1,nan,2"}).GetNumbers("pose", 3), CliError);
  EXPECT_THROW(Parsed({"a", "--seed", "-1"}).GetWholeNumber("seed"), CliError);
  EXPECT_THROW(Parsed({"a", "--seed", "1.5"}).GetWholeNumber("seed"), CliError);
  EXPECT_EQ(Parsed({"a", "--seed", "7"}).GetNumber("seed", 0, INFINITY), 7);
  EXPECT_EQ(Parsed({"a", "--seed", "inf"}).GetNumber("seed", 0, INFINITY), INFINITY);
  EXPECT_THROW(Parsed({"a", "--seed", "11"}).GetNumber("seed", 0, 10), CliError);
  EXPECT_THROW(Parsed({"a"}).Get("out"), CliError);  // not given, no default
}

TEST(CliArgs, HelpListsEveryOptionWithItsValueAndDefaultAndParseSaysStop) {
  CliArgs args = Declared();
  std::string help = "--help";
  char* argv[] = {help.data()};
  ::testing::internal::CaptureStdout();
  EXPECT_FALSE(args.Parse(1, argv));
  const std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(out, args.Usage());
  EXPECT_EQ(out.rfind("usage: pitchlab demo CLOUD [options]\n\nA command to test the parser.", 0), 0u)
      << out;
  for (const char* line : {"  CLOUD\n      clouds\n", "  --seed N\n      random seed (default: 1)\n",
                           "  --pose x,y,yaw\n      start pose\n", "  --json\n      print JSON\n",
                           "  -h,--help\n      show this help\n"}) {
    EXPECT_NE(out.find(line), std::string::npos) << line << "\nnot in:\n" << out;
  }
}

}  // namespace
}  // namespace pitchlab::apps
