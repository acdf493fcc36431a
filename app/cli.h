// A small declarative command-line parser: each subcommand declares its options into plain
// parameter structs; unknown flags, missing values and out-of-range numbers are a UsageError
// (one line, exit code 2).
#pragma once
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace pxf {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class CommandLine {
 public:
  CommandLine(std::string command, std::string usage, std::string summary);

  void flag(const std::string& name, bool* target, const std::string& help);
  void option(const std::string& name, std::string* target, const std::string& metavar, const std::string& help);
  void option(const std::string& name, int* target, const std::string& help, int min, int max);
  void option(const std::string& name, float* target, const std::string& help, float min, float max);
  void option(const std::string& name, double* target, const std::string& help, double min, double max);
  // A value from a fixed name table (e.g. filter variants, GL back ends).
  void choice(const std::string& name, std::string* target, const std::vector<std::string>& choices,
              const std::string& help);
  // "WxH" sizes.
  void size_option(const std::string& name, int* width, int* height, const std::string& help);
  void positional(const std::string& name, std::string* target, const std::string& help);
  // One or more arguments after the single positionals ("STATE...").
  void positional_list(const std::string& name, std::vector<std::string>* target, const std::string& help);

  // Returns false when --help was given (help is printed to stdout); throws UsageError.
  bool parse(const std::vector<std::string>& args);
  std::string help() const;
  const std::string& command() const { return command_; }
  // Whether an option was given explicitly on the command line.
  bool given(const std::string& name) const;

 private:
  struct Option {
    std::string name, metavar, help;
    bool is_flag = false;
    std::function<void(const std::string&)> set;
  };
  struct Positional {
    std::string name, help;
    std::string* target;
  };
  std::string command_, usage_, summary_;
  std::vector<Option> options_;
  std::vector<Positional> positionals_;
  Positional rest_{"", "", nullptr};
  std::vector<std::string>* rest_target_ = nullptr;
  std::vector<std::string> given_;
};

}  // namespace pxf
