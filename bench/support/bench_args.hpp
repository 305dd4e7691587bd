// The benchmarks' own command-line options, declared as a table instead of an if/else chain
// repeated in every main (bench code only):
//
//   ulc_bench::Args args;
//   args.value("--seconds", ulc_bench::number(c.seconds))
//       .value("--runs", ulc_bench::at_least(c.runs, std::size_t{1}))
//       .flag("--no-route", [&] { c.route = false; });
//   c.bench = args.parse(argc, argv, "what the bench measures");
//
// Options are applied in the order given on the command line. A value option needs the next
// argument; what no entry takes (and a value option with nothing after it) goes to
// parse_options (bench_util.hpp), which knows --json and --repeats and prints the usage and
// exits on anything else.
#pragma once

#include <algorithm>
#include <cstdlib>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "support/bench_util.hpp"

namespace ulc_bench {

class Args {
 public:
  using Setter = std::function<void(const char*)>;

  Args& value(std::string name, Setter set) {
    values_.emplace_back(std::move(name), std::move(set));
    return *this;
  }
  Args& flag(std::string name, std::function<void()> set) {
    flags_.emplace_back(std::move(name), std::move(set));
    return *this;
  }

  Options parse(int argc, char** argv, const char* description) const {
    std::vector<char*> rest = {argv[0]};
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (take(a, i, argc, argv)) continue;
      rest.push_back(argv[i]);
    }
    return parse_options(static_cast<int>(rest.size()), rest.data(), description);
  }

 private:
  bool take(const std::string& a, int& i, int argc, char** argv) const {
    for (const auto& [name, set] : flags_)
      if (a == name) {
        set();
        return true;
      }
    if (i + 1 >= argc) return false;
    for (const auto& [name, set] : values_)
      if (a == name) {
        set(argv[++i]);
        return true;
      }
    return false;
  }

  std::vector<std::pair<std::string, Setter>> values_;
  std::vector<std::pair<std::string, std::function<void()>>> flags_;
};

inline Args::Setter text(std::string& v) {
  return [&v](const char* s) { v = s; };
}
inline Args::Setter number(double& v, double scale = 1.0) {
  return [&v, scale](const char* s) { v = std::atof(s) * scale; };
}
/// A comma-separated list (split_list).
inline Args::Setter list(std::vector<std::string>& v) {
  return [&v](const char* s) { v = split_list(s); };
}
/// One more item per occurrence (repeatable options).
inline Args::Setter append(std::vector<std::string>& v) {
  return [&v](const char* s) { v.emplace_back(s); };
}
/// An integer, raised to `least` when smaller.
template <class T>
Args::Setter at_least(T& v, T least) {
  return [&v, least](const char* s) {
    v = static_cast<T>(std::max(std::strtoll(s, nullptr, 10), static_cast<long long>(least)));
  };
}

}  // namespace ulc_bench
