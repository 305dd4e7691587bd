// Helpers every benchmark uses: the common command-line options (CLI11), median-of-repeats timing,
// the machine's description, an aligned text table and the same table as a JSON document
// (nlohmann::json).
//
// Conventions: times are wall-clock seconds from std::chrono::steady_clock; a benchmark reports
// the median over `repeats` runs (the machines are shared and noisy: the median ignores the
// odd slow run) and compares thread counts measured in the same process run.
#pragma once

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace ulc_bench {

struct Options {
  bool json = false;  ///< --json: print a JSON document instead of the table
  int repeats = 5;    ///< --repeats N (at least 1)
};

/// Declares --json and --repeats N on a benchmark's command line; each main then declares its
/// own options and parses with CLI11_PARSE(app, argc, argv) (--help, errors: exit codes of CLI11).
inline void add_options(CLI::App& app, Options& options) {
  app.add_flag("--json", options.json, "print a JSON document instead of the table");
  app.add_option("--repeats", options.repeats,
                 "runs of each measurement; the median is reported (default 5)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
}

/// --threads N: the worker threads of the stages measured (a TBB arena; the default is 2).
inline void add_threads_option(CLI::App& app, int& threads) {
  app.add_option("--threads", threads, "worker threads (default 2)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
}

/// --first-run K: the index of the first seeded run, to extend a measurement or hold seeds out.
inline void add_first_run_option(CLI::App& app, std::size_t& first_run) {
  app.add_option("--first-run", first_run, "first run's index (default 0)")->type_name("K");
}

struct Machine {
  unsigned threads = 0;  ///< std::thread::hardware_concurrency(), what nproc reports
  std::string cpu;       ///< "model name" from /proc/cpuinfo, or "unknown"
  std::string load;      ///< 1, 5 and 15 minute load averages from /proc/loadavg (shared hosts)
};

inline Machine machine() {
  Machine m;
  m.threads = std::thread::hardware_concurrency();
  m.cpu = "unknown";
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) m.cpu = line.substr(line.find_first_not_of(" \t", colon + 1));
      break;
    }
  }
  std::ifstream loadavg("/proc/loadavg");
  std::string one, five, fifteen;
  if (loadavg >> one >> five >> fifteen) m.load = one + " " + five + " " + fifteen;
  return m;
}

/// Wall time of one call of f, in seconds.
template <class F>
double seconds_of(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  const auto stop = std::chrono::steady_clock::now();
  return std::chrono::duration<double>(stop - start).count();
}

/// Runs f `repeats` times; returns the sorted wall times in seconds.
template <class F>
std::vector<double> time_repeats(int repeats, F&& f) {
  std::vector<double> seconds;
  for (int r = 0; r < repeats; ++r) seconds.push_back(seconds_of(f));
  std::sort(seconds.begin(), seconds.end());
  return seconds;
}

/// Median of sorted values (mean of the middle two for an even count).
inline double median_of_sorted(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

/// Median wall time of f over `repeats` runs, in seconds.
template <class F>
double median_seconds(int repeats, F&& f) {
  return median_of_sorted(time_repeats(repeats, std::forward<F>(f)));
}

/// A table cell: text, or a number shown with a fixed number of decimals (and written to JSON
/// as a number).
struct Cell {
  std::string text;
  std::optional<double> number;

  Cell(const char* s) : text(s) {}             // NOLINT: implicit on purpose, for row literals
  Cell(std::string s) : text(std::move(s)) {}  // NOLINT
  static Cell num(double value, int decimals) {
    std::ostringstream out;
    out << std::fixed << std::setprecision(decimals) << value;
    Cell c(out.str());
    c.number = value;
    return c;
  }
  static Cell integer(long long value) {
    Cell c(std::to_string(value));
    c.number = static_cast<double>(value);
    return c;
  }
};

/// A cell as JSON: its number (a whole one without ".0"), else its text.
inline nlohmann::ordered_json json_value(const Cell& c) {
  if (!c.number) return c.text;
  const double x = *c.number;
  if (x == std::floor(x) && std::fabs(x) < 1e15) return static_cast<long long>(x);
  return x;
}

class Table {
 public:
  explicit Table(std::vector<std::string> columns) : columns_(std::move(columns)) {}

  void add_row(std::vector<Cell> row) {
    row.resize(columns_.size(), Cell(""));
    rows_.push_back(std::move(row));
  }
  const std::vector<std::vector<Cell>>& rows() const { return rows_; }

  /// Markdown-compatible aligned table: numbers right-aligned, text left-aligned.
  void print(std::ostream& out) const {
    std::vector<std::size_t> width(columns_.size());
    for (std::size_t c = 0; c < columns_.size(); ++c) width[c] = columns_[c].size();
    for (const auto& row : rows_)
      for (std::size_t c = 0; c < row.size(); ++c)
        width[c] = std::max(width[c], row[c].text.size());
    auto line = [&](auto cell_text, auto right) {
      out << "|";
      for (std::size_t c = 0; c < columns_.size(); ++c) {
        out << " " << (right(c) ? std::right : std::left) << std::setw(static_cast<int>(width[c]))
            << cell_text(c) << " |";
      }
      out << "\n";
    };
    line([&](std::size_t c) { return columns_[c]; }, [](std::size_t) { return false; });
    out << "|";
    for (std::size_t c = 0; c < columns_.size(); ++c) out << std::string(width[c] + 2, '-') << "|";
    out << "\n";
    for (const auto& row : rows_)
      line([&](std::size_t c) { return row[c].text; },
           [&](std::size_t c) { return row[c].number.has_value(); });
    out << std::left;
  }

  /// {"benchmark": name, "machine": {...}, "repeats": n, "parameters": {...}, "rows": [...],
  ///  "notes": {...}}; parameters and notes are (key, cell) pairs.
  void write_json(std::ostream& out, const std::string& name, const Machine& m, int repeats,
                  const std::vector<std::pair<std::string, Cell>>& parameters,
                  const std::vector<std::pair<std::string, Cell>>& notes = {}) const {
    using Json = nlohmann::ordered_json;
    auto object = [](const std::vector<std::pair<std::string, Cell>>& fields) {
      Json o = Json::object();
      for (const auto& [key, cell] : fields) o[key] = json_value(cell);
      return o;
    };
    Json doc = Json::object();
    doc["benchmark"] = name;
    doc["machine"] = {{"nproc", m.threads}, {"cpu", m.cpu}, {"load_average", m.load}};
    doc["repeats"] = repeats;
    doc["parameters"] = object(parameters);
    Json rows = Json::array();
    for (const auto& row : rows_) {
      std::vector<std::pair<std::string, Cell>> fields;
      for (std::size_t c = 0; c < columns_.size(); ++c) fields.emplace_back(columns_[c], row[c]);
      rows.push_back(object(fields));
    }
    doc["rows"] = std::move(rows);
    doc["notes"] = object(notes);
    out << doc.dump(2, ' ', false, Json::error_handler_t::replace) << "\n";
  }

 private:
  std::vector<std::string> columns_;
  std::vector<std::vector<Cell>> rows_;
};

/// (key, cell) pairs: a benchmark's parameters or the notes printed after its table.
using Fields = std::vector<std::pair<std::string, Cell>>;

/// The notes as "key: value" lines, after a printed table.
inline void print_notes(std::ostream& out, const Fields& notes) {
  for (const auto& n : notes) out << n.first << ": " << n.second.text << "\n";
}

/// A benchmark's output: the table as JSON (--json), else the table and its notes as text.
inline void emit(std::ostream& out, const Table& table, bool json, const std::string& name,
                 int repeats, const Fields& parameters, const Fields& notes) {
  if (json) {
    table.write_json(out, name, machine(), repeats, parameters, notes);
  } else {
    table.print(out);
    print_notes(out, notes);
  }
}

}  // namespace ulc_bench
