// A small declarative option parser for the `ulc` subcommands.
// Each subcommand declares its options once; parsing reports the first problem as one clear
// line (UsageError), which main() prints and turns into exit code 2.
#pragma once

#include <cerrno>
#include <cstdlib>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace ulc::cli {

/// Bad usage: unknown option, missing or malformed value. Exit code 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct OptionSpec {
  std::string name;        ///< without the leading "--"
  std::string value_name;  ///< empty: a flag without value
  std::string help;
  bool repeatable = false;
  bool required = false;
};

class Args {
 public:
  explicit Args(std::string command) : command_(std::move(command)) {}

  Args& flag(std::string name, std::string help) {
    specs_.push_back({std::move(name), "", std::move(help), false, false});
    return *this;
  }
  Args& option(std::string name, std::string value_name, std::string help, bool required = false,
               bool repeatable = false) {
    specs_.push_back(
        {std::move(name), std::move(value_name), std::move(help), repeatable, required});
    return *this;
  }

  /// Parses argv[first..argc). Accepts "--name value" and "--name=value".
  void parse(int argc, char** argv, int first) {
    for (int i = first; i < argc; ++i) {
      std::string arg = argv[i];
      if (arg.rfind("--", 0) != 0)
        throw UsageError(command_ + ": unexpected argument '" + arg + "' (options start with --)");
      std::string name = arg.substr(2);
      std::optional<std::string> inline_value;
      if (auto eq = name.find('='); eq != std::string::npos) {
        inline_value = name.substr(eq + 1);
        name = name.substr(0, eq);
      }
      const OptionSpec* spec = find(name);
      if (!spec) throw UsageError(command_ + ": unknown option '--" + name + "' (see --help)");
      if (spec->value_name.empty()) {
        if (inline_value) throw UsageError(command_ + ": option '--" + name + "' takes no value");
        values_[name].push_back("");
        continue;
      }
      std::string value;
      if (inline_value) {
        value = *inline_value;
      } else {
        if (i + 1 >= argc)
          throw UsageError(command_ + ": option '--" + name + "' needs a value <" +
                           spec->value_name + ">");
        value = argv[++i];
      }
      auto& list = values_[name];
      if (!list.empty() && !spec->repeatable)
        throw UsageError(command_ + ": option '--" + name + "' given more than once");
      list.push_back(value);
    }
    if (has("help")) return;
    for (const auto& s : specs_)
      if (s.required && !has(s.name))
        throw UsageError(command_ + ": missing required option '--" + s.name + " <" + s.value_name +
                         ">'");
  }

  bool has(const std::string& name) const { return values_.count(name) > 0; }

  std::string get(const std::string& name, const std::string& fallback = "") const {
    auto it = values_.find(name);
    return it == values_.end() ? fallback : it->second.back();
  }
  std::vector<std::string> get_all(const std::string& name) const {
    auto it = values_.find(name);
    return it == values_.end() ? std::vector<std::string>{} : it->second;
  }

  double get_double(const std::string& name, double fallback) const {
    if (!has(name)) return fallback;
    const std::string text = get(name);
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || errno == ERANGE || !(v == v))
      throw UsageError(command_ + ": option '--" + name + "' expects a number, got '" + text + "'");
    return v;
  }

  long long get_int(const std::string& name, long long fallback, long long min_value,
                    long long max_value) const {
    if (!has(name)) return fallback;
    const std::string text = get(name);
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || errno == ERANGE)
      throw UsageError(command_ + ": option '--" + name + "' expects an integer, got '" + text +
                       "'");
    if (v < min_value || v > max_value)
      throw UsageError(command_ + ": option '--" + name + "' must be within [" +
                       std::to_string(min_value) + ", " + std::to_string(max_value) + "], got " +
                       text);
    return v;
  }

  std::string help_text(const std::string& summary) const {
    std::string out = "usage: ulc " + command_ + " [options]\n" + summary + "\n\noptions:\n";
    for (const auto& s : specs_) {
      std::string left = "  --" + s.name + (s.value_name.empty() ? "" : " <" + s.value_name + ">");
      if (left.size() < 28)
        left.resize(28, ' ');
      else
        left += "\n" + std::string(28, ' ');
      out += left + s.help + (s.required ? " (required)" : "") +
             (s.repeatable ? " (repeatable)" : "") + "\n";
    }
    return out;
  }

 private:
  const OptionSpec* find(const std::string& name) const {
    for (const auto& s : specs_)
      if (s.name == name) return &s;
    return nullptr;
  }

  std::string command_;
  std::vector<OptionSpec> specs_;
  std::map<std::string, std::vector<std::string>> values_;
};

}  // namespace ulc::cli
