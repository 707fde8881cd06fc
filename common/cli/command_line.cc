#include "common/cli/command_line.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <new>

#include <fmt/format.h>

#include "common/io/provenance.h"

namespace tiltcal::cli {

bool IsTerminalLog(const std::ostream* log) {
  return (log == &std::cerr || log == &std::clog) && ::isatty(STDERR_FILENO);
}

CommandLine::CommandLine(std::string tool, std::string purpose)
    : tool_(std::move(tool)), purpose_(std::move(purpose)) {}

void CommandLine::AddFlag(const std::string& name, const std::string& help,
                          Requirement requirement, const std::string& default_value) {
  flags_[name] = Flag{help, requirement, /*is_switch=*/false, default_value};
  flag_order_.push_back(name);
}

void CommandLine::AddSwitch(const std::string& name, const std::string& help) {
  flags_[name] = Flag{help, kOptional, /*is_switch=*/true, "false"};
  flag_order_.push_back(name);
}

void CommandLine::SetPositional(const std::string& usage, const std::string& help, int min_count,
                                int max_count) {
  positional_usage_ = usage;
  positional_help_ = help;
  positional_min_ = min_count;
  positional_max_ = max_count;
}

void CommandLine::AddExample(const std::string& example) { examples_.push_back(example); }

int CommandLine::UsageError(const std::string& message) const {
  std::cerr << tool_ << ": " << message << " (see " << tool_ << " --help)\n";
  return kExitUsage;
}

std::optional<int> CommandLine::Parse(int argc, const char* const* argv) {
  command_line_ = JoinCommandLine(argc, argv);
  values_.clear();
  positional_.clear();
  bool only_positional = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (only_positional || arg.size() < 2 || arg.compare(0, 1, "-") != 0) {
      positional_.push_back(arg);
      continue;
    }
    if (arg == "--") {
      only_positional = true;
      continue;
    }
    if (arg == "--help" || arg == "-h" || arg == "-help") {
      std::cout << Help();
      return kExitOk;
    }
    const size_t dashes = arg.compare(0, 2, "--") == 0 ? 2 : 1;
    const size_t equals = arg.find('=');
    const std::string name = arg.substr(dashes, equals == std::string::npos ? std::string::npos
                                                                            : equals - dashes);
    const auto flag = flags_.find(name);
    if (flag == flags_.end()) return UsageError("unknown flag --" + name);
    if (values_.count(name) != 0) return UsageError("--" + name + " is given twice");
    if (flag->second.is_switch) {
      const std::string value = equals == std::string::npos ? "true" : arg.substr(equals + 1);
      if (value != "true" && value != "false") {
        return UsageError("--" + name + " takes no value, or true / false, not '" + value + "'");
      }
      values_[name] = value;
      continue;
    }
    if (equals != std::string::npos) {
      values_[name] = arg.substr(equals + 1);
    } else if (i + 1 < argc) {
      values_[name] = argv[++i];
    } else {
      return UsageError("--" + name + " needs a value");
    }
  }
  for (const std::string& name : flag_order_) {
    const Flag& flag = flags_.at(name);
    if (flag.requirement == kRequired && Get(name).empty()) {
      return UsageError("--" + name + " is required");
    }
  }
  const int count = static_cast<int>(positional_.size());
  if (count < positional_min_) {
    return UsageError(positional_usage_.empty() ? "missing arguments"
                                                : "missing " + positional_usage_);
  }
  if (positional_max_ >= 0 && count > positional_max_) {
    return UsageError("unexpected argument '" + positional_[positional_max_] + "'");
  }
  return std::nullopt;
}

const std::string& CommandLine::Get(const std::string& name) const {
  const auto value = values_.find(name);
  if (value != values_.end()) return value->second;
  return flags_.at(name).default_value;
}

bool CommandLine::Has(const std::string& name) const { return values_.count(name) != 0; }

bool CommandLine::GetSwitch(const std::string& name) const { return Get(name) == "true"; }

Status CommandLine::GetInt(const std::string& name, int64_t* value) const {
  const std::string& text = Get(name);
  char* end = nullptr;
  errno = 0;
  const long long parsed = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE) {
    return Status::Error("--" + name + "=" + text + " is not an integer");
  }
  *value = parsed;
  return Status::Ok();
}

std::string CommandLine::Help() const {
  std::string help = fmt::format("{}: {}\n\nusage: {}", tool_, purpose_, tool_);
  if (!positional_usage_.empty()) help += " " + positional_usage_;
  for (const std::string& name : flag_order_) {
    const Flag& flag = flags_.at(name);
    const std::string form = flag.is_switch ? "--" + name : "--" + name + "=…";
    help += flag.requirement == kRequired ? " " + form : " [" + form + "]";
  }
  help += "\n\n";
  size_t width = 0;
  for (const std::string& name : flag_order_) width = std::max(width, name.size() + 2);
  if (!positional_usage_.empty()) {
    width = std::max(width, positional_usage_.size());
    help += fmt::format("  {:<{}}  {}\n", positional_usage_, width, positional_help_);
  }
  for (const std::string& name : flag_order_) {
    const Flag& flag = flags_.at(name);
    std::string text = flag.help;
    if (flag.requirement == kRequired) text += " (required)";
    if (!flag.is_switch && !flag.default_value.empty()) {
      text += " (default: " + flag.default_value + ")";
    }
    help += fmt::format("  {:<{}}  {}\n", "--" + name, width, text);
  }
  if (!examples_.empty()) {
    help += examples_.size() == 1 ? "\nexample:\n" : "\nexamples:\n";
    for (const std::string& example : examples_) help += "  " + example + "\n";
  }
  help += fmt::format(
      "\nexit codes: {} done, {} the run failed (the reason is on stderr, no output is left), "
      "{} wrong command line",
      kExitOk, kExitFailure, kExitUsage);
  for (const auto& [code, meaning] : exit_codes_) help += fmt::format(", {} {}", code, meaning);
  help += "\n";
  return help;
}

void CommandLine::AddExitCode(int code, const std::string& meaning) {
  exit_codes_.emplace_back(code, meaning);
}

int CommandLine::Finish(const Status& status) const {
  if (status.ok()) return kExitOk;
  std::cerr << tool_ << ": " << status.message() << "\n";
  return kExitFailure;
}

int RunMain(const char* tool, int (*body)(int, char**), int argc, char** argv) {
  try {
    return body(argc, argv);
  } catch (const std::bad_alloc&) {
    std::cerr << tool << ": out of memory (std::bad_alloc); the input needs more memory than "
                         "this machine gave the process\n";
  } catch (const std::exception& e) {
    std::cerr << tool << ": internal error: " << e.what() << "\n";
  }
  return kExitFailure;
}

}  // namespace tiltcal::cli
