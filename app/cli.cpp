#include "app/cli.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <type_traits>

namespace pxf {

namespace {
std::string join(const std::vector<std::string>& words, const char* sep) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : sep) + w;
  return out;
}

double parse_number(const std::string& option, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(value))
    throw UsageError(option + ": '" + text + "' is not a number");
  return value;
}

// A limit as a person reads it: integers in full (16777216, not 1.67772e+07), others with the
// digits of a float (21.33333).
std::string readable_number(double v) {
  char buffer[64];
  if (v == std::floor(v) && std::abs(v) < 1e15)
    std::snprintf(buffer, sizeof buffer, "%.0f", v);
  else
    std::snprintf(buffer, sizeof buffer, "%.7g", v);
  return buffer;
}

// Whether `value` converts to T without overflow. An integer type's max (2^63 - 1, 2^64 - 1) rounds
// up to 2^63, 2^64 in double, where the conversion is undefined: its bound is that power, exclusive.
template <typename T>
bool representable(double value) {
  if (value < static_cast<double>(std::numeric_limits<T>::lowest())) return false;
  if (std::is_integral<T>::value) return value < std::ldexp(1.0, std::numeric_limits<T>::digits);
  return value <= static_cast<double>(std::numeric_limits<T>::max());
}

template <typename T>
std::function<void(const std::string&)> number_setter(const std::string& name, T* target, double min, double max,
                                                      bool integer) {
  // The bounds in the target's type; a bound that double cannot carry back (UINT64_MAX) is the type's own.
  const T lo = representable<T>(min) ? static_cast<T>(min) : std::numeric_limits<T>::lowest();
  const T hi = representable<T>(max) ? static_cast<T>(max) : std::numeric_limits<T>::max();
  return [=](const std::string& text) {
    const double value = parse_number(name, text);
    if (integer && value != std::floor(value)) throw UsageError(name + ": '" + text + "' is not an integer");
    // Compared in the target's type: a float limit such as 0.1f is not 0.1 in double, so "0.1"
    // would be out of a range that prints as starting at 0.1.
    const bool fits = representable<T>(value);
    const T typed = fits ? static_cast<T>(value) : T{};
    if (!fits || typed < lo || typed > hi)
      throw UsageError(name + ": " + text + " is out of range [" + readable_number(static_cast<double>(lo)) + ", " +
                       readable_number(static_cast<double>(hi)) + "]");
    *target = typed;
  };
}
}  // namespace

CommandLine::CommandLine(std::string command, std::string usage, std::string summary)
    : command_(std::move(command)), usage_(std::move(usage)), summary_(std::move(summary)) {}

void CommandLine::flag(const std::string& name, bool* target, const std::string& help) {
  options_.push_back({name, "", help, true, [target](const std::string&) { *target = true; }});
}

void CommandLine::option(const std::string& name, std::string* target, const std::string& metavar,
                         const std::string& help) {
  options_.push_back({name, metavar, help, false, [target](const std::string& v) { *target = v; }});
}

void CommandLine::option(const std::string& name, int* target, const std::string& help, int min, int max) {
  options_.push_back({name, "N", help + " [" + std::to_string(min) + ".." + std::to_string(max) + "]", false,
                      number_setter(name, target, min, max, true)});
}

void CommandLine::option(const std::string& name, float* target, const std::string& help, float min, float max) {
  options_.push_back({name, "X", help, false, number_setter(name, target, min, max, false)});
}

void CommandLine::option(const std::string& name, double* target, const std::string& help, double min, double max) {
  options_.push_back({name, "X", help, false, number_setter(name, target, min, max, false)});
}

void CommandLine::option(const std::string& name, uint64_t* target, const std::string& help, uint64_t min,
                         uint64_t max) {
  options_.push_back({name, "N", help + " [" + std::to_string(min) + ".." + std::to_string(max) + "]", false,
                      number_setter(name, target, static_cast<double>(min), static_cast<double>(max), true)});
}

void CommandLine::choice(const std::string& name, std::string* target, const std::vector<std::string>& choices,
                         const std::string& help) {
  choice_index(name, [target, choices](size_t i) { *target = choices[i]; }, choices, help);
}

void CommandLine::choice_index(const std::string& name, std::function<void(size_t)> set,
                               const std::vector<std::string>& names, const std::string& help) {
  options_.push_back({name, join(names, "|"), help, false, [=](const std::string& v) {
                        for (size_t i = 0; i < names.size(); ++i)
                          if (names[i] == v) {
                            set(i);
                            return;
                          }
                        throw UsageError(name + ": '" + v + "' is not one of " + join(names, ", "));
                      }});
}

void CommandLine::size_option(const std::string& name, int* width, int* height, const std::string& help) {
  options_.push_back({name, "WxH", help, false, [=](const std::string& v) {
                        const size_t x = v.find('x');
                        if (x == std::string::npos) throw UsageError(name + ": '" + v + "' is not of the form WxH");
                        int w = 0, h = 0;
                        number_setter(name, &w, 1, 16384, true)(v.substr(0, x));
                        number_setter(name, &h, 1, 16384, true)(v.substr(x + 1));
                        *width = w;
                        *height = h;
                      }});
}

void CommandLine::positional(const std::string& name, std::string* target, const std::string& help) {
  positionals_.push_back({name, help, target});
}

void CommandLine::positional_list(const std::string& name, std::vector<std::string>* target, const std::string& help) {
  rest_ = {name, help, nullptr};
  rest_target_ = target;
}

bool CommandLine::given(const std::string& name) const {
  for (const auto& g : given_)
    if (g == name) return true;
  return false;
}

bool CommandLine::parse(const std::vector<std::string>& args) {
  size_t next_positional = 0;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--help" || arg == "-h") {
      std::fputs(help().c_str(), stdout);
      return false;
    }
    if (arg.size() > 1 && arg[0] == '-' && !(arg.size() > 1 && (std::isdigit(arg[1]) || arg[1] == '.'))) {
      std::string name = arg, value;
      const size_t eq = arg.find('=');
      const bool inline_value = eq != std::string::npos;
      if (inline_value) name = arg.substr(0, eq), value = arg.substr(eq + 1);
      const Option* found = nullptr;
      for (const auto& o : options_)
        if (o.name == name) found = &o;
      if (!found) throw UsageError("unknown option '" + name + "' (see pxf " + command_ + " --help)");
      if (found->is_flag) {
        if (inline_value) throw UsageError(name + " takes no value");
      } else if (!inline_value) {
        if (i + 1 >= args.size()) throw UsageError(name + " needs a value (" + found->metavar + ")");
        value = args[++i];
      }
      found->set(value);
      given_.push_back(name);
      continue;
    }
    if (next_positional >= positionals_.size() && rest_target_) {
      rest_target_->push_back(arg);
      continue;
    }
    if (next_positional >= positionals_.size()) throw UsageError("unexpected argument '" + arg + "'");
    *positionals_[next_positional++].target = arg;
  }
  if (next_positional < positionals_.size())
    throw UsageError("missing argument " + positionals_[next_positional].name + " (see pxf " + command_ + " --help)");
  if (rest_target_ && rest_target_->empty())
    throw UsageError("missing argument " + rest_.name + " (see pxf " + command_ + " --help)");
  return true;
}

std::string CommandLine::help() const {
  std::ostringstream out;
  out << "usage: pxf " << command_ << " " << usage_ << "\n\n" << summary_ << "\n";
  if (!positionals_.empty()) {
    out << "\narguments:\n";
    for (const auto& p : positionals_) out << "  " << p.name << "\n      " << p.help << "\n";
  }
  if (rest_target_) {
    if (positionals_.empty()) out << "\narguments:\n";
    out << "  " << rest_.name << "\n      " << rest_.help << "\n";
  }
  out << "\noptions:\n";
  for (const auto& o : options_)
    out << "  " << o.name << (o.metavar.empty() ? "" : " " + o.metavar) << "\n      " << o.help << "\n";
  out << "  --help\n      show this help\n";
  return out.str();
}

}  // namespace pxf
