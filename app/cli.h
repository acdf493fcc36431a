// A small declarative command-line parser: each subcommand declares its options into plain
// parameter structs; unknown flags, missing values and out-of-range numbers are a UsageError
// (one line, exit code 2).
#pragma once
#include <cstdint>
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
  void option(const std::string& name, uint64_t* target, const std::string& help, uint64_t min, uint64_t max);
  // A value from a fixed name table (e.g. GL back ends).
  void choice(const std::string& name, std::string* target, const std::vector<std::string>& choices,
              const std::string& help);
  // An enum (or bool) bound to its name table: names[i] names static_cast<E>(i). The same table
  // names the value everywhere else (the explorer's combo boxes, stats.json), so the command line
  // sets the enum itself and no name travels as a string.
  template <typename E>
  void choice(const std::string& name, E* target, const std::vector<std::string>& names, const std::string& help) {
    choice_index(name, [target](size_t i) { *target = static_cast<E>(i); }, names, help);
  }
  // A value from a name table, given to `set` as its index (a field reached through an accessor).
  void choice_setter(const std::string& name, std::function<void(size_t)> set, const std::vector<std::string>& names,
                     const std::string& help) {
    choice_index(name, std::move(set), names, help);
  }
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
  void choice_index(const std::string& name, std::function<void(size_t)> set, const std::vector<std::string>& names,
                    const std::string& help);
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
