#include "common/cli/command_line.h"

#include <vector>

#include <gtest/gtest.h>

namespace tiltcal::cli {
namespace {

// A tool with two required flags, an optional one with a default, a switch
// and up to two positional arguments.
CommandLine MakeTool() {
  CommandLine cli("tiltcal_example", "does one thing");
  cli.AddFlag("imu", "input: imu.binpb", kRequired);
  cli.AddFlag("out", "output: result.txtpb", kRequired);
  cli.AddFlag("params", "params (default: the stage defaults)");
  cli.AddFlag("record", "index of the scan", kOptional, "0");
  cli.AddSwitch("quiet", "no progress lines");
  cli.SetPositional("[FILE...]", "extra inputs", 0, 2);
  cli.AddExample("tiltcal_example --imu=a.binpb --out=b.txtpb");
  return cli;
}

std::optional<int> Parse(CommandLine* cli, std::vector<const char*> args) {
  args.insert(args.begin(), "tiltcal_example");
  return cli->Parse(static_cast<int>(args.size()), args.data());
}

TEST(CommandLine, NamedFlagsSwitchesAndPositionals) {
  CommandLine cli = MakeTool();
  ASSERT_FALSE(Parse(&cli, {"--imu=a.binpb", "--out", "b.txtpb", "--quiet", "x", "y"}));
  EXPECT_EQ(cli.Get("imu"), "a.binpb");
  EXPECT_EQ(cli.Get("out"), "b.txtpb");
  EXPECT_EQ(cli.Get("params"), "");
  EXPECT_FALSE(cli.Has("params"));
  EXPECT_TRUE(cli.Has("imu"));
  EXPECT_TRUE(cli.GetSwitch("quiet"));
  EXPECT_EQ(cli.positional(), (std::vector<std::string>{"x", "y"}));
  EXPECT_EQ(cli.command_line(), "tiltcal_example --imu=a.binpb --out b.txtpb --quiet x y");
  int64_t record = -1;
  ASSERT_TRUE(cli.GetInt("record", &record).ok());
  EXPECT_EQ(record, 0);
}

TEST(CommandLine, SwitchTakesAnExplicitBoolean) {
  CommandLine cli = MakeTool();
  ASSERT_FALSE(Parse(&cli, {"--imu=a", "--out=b", "--quiet=false"}));
  EXPECT_FALSE(cli.GetSwitch("quiet"));
  CommandLine bad = MakeTool();
  EXPECT_EQ(Parse(&bad, {"--imu=a", "--out=b", "--quiet=yes"}), kExitUsage);
}

TEST(CommandLine, UsageErrorsExitWithTheUsageCode) {
  {
    CommandLine cli = MakeTool();
    ::testing::internal::CaptureStderr();
    EXPECT_EQ(Parse(&cli, {"--out=b"}), kExitUsage);
    const std::string error = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(error, "tiltcal_example: --imu is required (see tiltcal_example --help)\n");
  }
  {
    CommandLine cli = MakeTool();
    ::testing::internal::CaptureStderr();
    EXPECT_EQ(Parse(&cli, {"--imu=a", "--out=b", "--bogus=1"}), kExitUsage);
    EXPECT_NE(::testing::internal::GetCapturedStderr().find("unknown flag --bogus"),
              std::string::npos);
  }
  {
    CommandLine cli = MakeTool();
    ::testing::internal::CaptureStderr();
    EXPECT_EQ(Parse(&cli, {"--imu=a", "--out=b", "--imu=c"}), kExitUsage);
    EXPECT_NE(::testing::internal::GetCapturedStderr().find("--imu is given twice"),
              std::string::npos);
  }
  {
    CommandLine cli = MakeTool();
    ::testing::internal::CaptureStderr();
    EXPECT_EQ(Parse(&cli, {"--imu=a", "--out=b", "x", "y", "z"}), kExitUsage);
    EXPECT_NE(::testing::internal::GetCapturedStderr().find("unexpected argument 'z'"),
              std::string::npos);
  }
  {
    CommandLine cli = MakeTool();
    ::testing::internal::CaptureStderr();
    EXPECT_EQ(Parse(&cli, {"--imu=a", "--out"}), kExitUsage);
    EXPECT_NE(::testing::internal::GetCapturedStderr().find("--out needs a value"),
              std::string::npos);
  }
}

TEST(CommandLine, NonIntegerValueNamesTheFlag) {
  CommandLine cli = MakeTool();
  ASSERT_FALSE(Parse(&cli, {"--imu=a", "--out=b", "--record=3x"}));
  int64_t record = 0;
  const Status status = cli.GetInt("record", &record);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(), "--record=3x is not an integer");
}

TEST(CommandLine, HelpShowsTheToolsOwnFlagsAndAnExample) {
  CommandLine cli = MakeTool();
  ::testing::internal::CaptureStdout();
  EXPECT_EQ(Parse(&cli, {"--help"}), kExitOk);
  const std::string help = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(help, cli.Help());
  EXPECT_NE(help.find("tiltcal_example: does one thing"), std::string::npos) << help;
  EXPECT_NE(help.find("--imu"), std::string::npos) << help;
  EXPECT_NE(help.find("input: imu.binpb (required)"), std::string::npos) << help;
  EXPECT_NE(help.find("(default: 0)"), std::string::npos) << help;
  EXPECT_NE(help.find("example:\n  tiltcal_example --imu=a.binpb --out=b.txtpb"),
            std::string::npos)
      << help;
  // Nothing of a flags library's own flags.
  EXPECT_EQ(help.find("flagfile"), std::string::npos) << help;
}

TEST(CommandLine, FinishPrintsTheFailureOnOneLine) {
  CommandLine cli = MakeTool();
  EXPECT_EQ(cli.Finish(Status::Ok()), kExitOk);
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(cli.Finish(Status::Error("run1.bag: record 7: bad header")), kExitFailure);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(),
            "tiltcal_example: run1.bag: record 7: bad header\n");
}

}  // namespace
}  // namespace tiltcal::cli
