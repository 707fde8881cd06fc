#ifndef TILTCAL_COMMON_CLI_COMMAND_LINE_H_
#define TILTCAL_COMMON_CLI_COMMAND_LINE_H_

#include <cstdint>
#include <iosfwd>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/status.h"

namespace tiltcal::cli {

// True when `log` is the standard error stream and that is a terminal: where
// progress lines rewritten in place belong.
bool IsTerminalLog(const std::ostream* log);

// Exit codes of every tiltcal executable.
inline constexpr int kExitOk = 0;       // done, outputs written
inline constexpr int kExitFailure = 1;  // the run failed (bad input, failed solve); no output left
inline constexpr int kExitUsage = 2;    // the command line is wrong (unknown or missing flag)
// The result was written but is not to be used without reading why (e.g.
// tiltcal_calibrate's verdict SUSPECT; the reasons are in the file and on stderr).
inline constexpr int kExitSuspect = 3;
// The result was written but decides nothing (tiltcal_verify's verdict
// CANNOT_TELL: the recordings are too weak to decide; the reasons say which
// direction).
inline constexpr int kExitCannotTell = 4;

// The command line of one tool: named flags `--name=value` (or `--name value`),
// switches `--name` (or `--name=true|false`), and positional arguments.
//
//   cli::CommandLine cli("tiltcal_gravity", "inclination and flat-ground gravity reference");
//   cli.AddFlag("imu", "input: imu.binpb", cli::kRequired);
//   cli.AddFlag("params", "params (default: the stage defaults)");
//   cli.AddSwitch("quiet", "no progress lines on stderr");
//   cli.AddExample("tiltcal_gravity --imu=out/run1/imu.binpb ...");
//   if (const auto exit_code = cli.Parse(argc, argv)) return *exit_code;
//   paths.imu = cli.Get("imu");
//
// Parse() prints `--help` to stdout (exit 0) and a usage error to stderr as
// one line "<tool>: <what is wrong> (see --help)" (exit kExitUsage).
enum Requirement { kOptional, kRequired };

// The body of every tool's main():
//   int main(int argc, char** argv) { return cli::RunMain("tiltcal_x", Main, argc, argv); }
// returns body(argc, argv). A std::bad_alloc thrown anywhere in it becomes
// one line "<tool>: out of memory (...)" on stderr and kExitFailure, any
// other exception "<tool>: internal error: <what>" and kExitFailure; the
// stack is unwound first, so no temporary output is left behind.
int RunMain(const char* tool, int (*body)(int, char**), int argc, char** argv);

class CommandLine {
 public:
  CommandLine(std::string tool, std::string purpose);

  void AddFlag(const std::string& name, const std::string& help,
               Requirement requirement = kOptional, const std::string& default_value = "");
  void AddSwitch(const std::string& name, const std::string& help);
  // Positional arguments: `usage` names them in --help (e.g. "SEQUENCE_DIR...");
  // at least `min_count` and at most `max_count` (-1: any number).
  void SetPositional(const std::string& usage, const std::string& help, int min_count,
                     int max_count);
  void AddExample(const std::string& example);
  // An exit code of this tool beyond 0, 1 and 2 (e.g. kExitSuspect), listed in --help.
  void AddExitCode(int code, const std::string& meaning);

  // Parses argv. Returns the exit code when the tool must stop now (--help,
  // or a usage error already printed), std::nullopt when it should run.
  std::optional<int> Parse(int argc, const char* const* argv);

  // The value of a flag ("" or its default when absent); a switch's state.
  const std::string& Get(const std::string& name) const;
  bool Has(const std::string& name) const;  // given on the command line
  bool GetSwitch(const std::string& name) const;
  // The value of a flag as an integer; a non-integer value is an error naming the flag.
  Status GetInt(const std::string& name, int64_t* value) const;
  const std::vector<std::string>& positional() const { return positional_; }
  // argv joined into one shell-like line, for the provenance of the outputs.
  const std::string& command_line() const { return command_line_; }
  const std::string& tool() const { return tool_; }

  // The text --help prints.
  std::string Help() const;

  // Prints "<tool>: <message>" on stderr and returns kExitFailure, or returns
  // kExitOk for an ok status: `return cli.Finish(status);` ends a main.
  int Finish(const Status& status) const;

 private:
  struct Flag {
    std::string help;
    Requirement requirement = kOptional;
    bool is_switch = false;
    std::string default_value;
  };
  int UsageError(const std::string& message) const;

  std::string tool_;
  std::string purpose_;
  std::map<std::string, Flag> flags_;
  std::vector<std::string> flag_order_;
  std::string positional_usage_;
  std::string positional_help_;
  int positional_min_ = 0;
  int positional_max_ = 0;
  std::vector<std::string> examples_;
  std::vector<std::pair<int, std::string>> exit_codes_;
  std::map<std::string, std::string> values_;
  std::vector<std::string> positional_;
  std::string command_line_;
};

}  // namespace tiltcal::cli

#endif  // TILTCAL_COMMON_CLI_COMMAND_LINE_H_
