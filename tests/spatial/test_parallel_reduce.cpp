#include <tbb/task_arena.h>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "ulc/core/parallel_reduce.hpp"

namespace {

/// 1e6 doubles whose magnitudes span 1e-8 .. 1e8 with both signs: the order of additions
/// changes the rounded sum, so only a fixed order gives fixed bits.
std::vector<double> wild_values() {
  std::mt19937_64 rng(101);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-8, 8);
  std::vector<double> v(1000000);
  for (auto& x : v) x = mantissa(rng) * std::pow(10.0, exponent(rng));
  return v;
}

double deterministic_sum(const std::vector<double>& v, std::size_t grain) {
  return ulc::deterministic_reduce(
      v.size(), 0.0,
      [&](std::size_t begin, std::size_t end, double acc) {
        for (std::size_t i = begin; i < end; ++i) acc += v[i];
        return acc;
      },
      [](double a, double b) { return a + b; }, grain);
}

std::uint64_t bits(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

}  // namespace

TEST_CASE("deterministic_reduce: same bits for 1 and 2 threads", "[reduce][threads]") {
  const auto v = wild_values();
  for (std::size_t grain : {std::size_t{1024}, std::size_t{4096}, std::size_t{100000}}) {
    INFO("grain = " << grain);
    tbb::task_arena one(1), two(2);
    const double s1 = one.execute([&] { return deterministic_sum(v, grain); });
    const double s2 = two.execute([&] { return deterministic_sum(v, grain); });
    const double s2_again = two.execute([&] { return deterministic_sum(v, grain); });
    CHECK(bits(s1) == bits(s2));
    CHECK(bits(s2) == bits(s2_again));
    // And it is a sum: close to an exactly compensated reference (Kahan-Babuska).
    double sum = 0.0, c = 0.0;
    for (double x : v) {
      const double t = sum + x;
      c += std::abs(sum) >= std::abs(x) ? (sum - t) + x : (x - t) + sum;
      sum = t;
    }
    CHECK(s1 == Approx(sum + c).epsilon(1e-9));
  }
  // (tbb::parallel_reduce with the default partitioner carries no such promise: its result
  // may change between runs and thread counts. bench_core shows it; nothing here relies on it.)
}

TEST_CASE("deterministic_reduce: empty range, tiny grain, non-scalar values", "[reduce]") {
  auto count = [](std::size_t n, std::size_t grain) {
    return ulc::deterministic_reduce(
        n, std::size_t{0},
        [](std::size_t b, std::size_t e, std::size_t acc) { return acc + (e - b); },
        [](std::size_t a, std::size_t b) { return a + b; }, grain);
  };
  CHECK(count(0, 16) == 0);
  CHECK(count(1, 0) == 1);  // grain 0 is treated as 1
  CHECK(count(12345, 7) == 12345);

  // Join order is left-to-right: concatenation rebuilds the sequence.
  tbb::task_arena two(2);
  const auto seq = two.execute([] {
    return ulc::deterministic_reduce(
        1000, std::vector<int>{},
        [](std::size_t b, std::size_t e, std::vector<int> acc) {
          for (std::size_t i = b; i < e; ++i) acc.push_back(static_cast<int>(i));
          return acc;
        },
        [](std::vector<int> a, const std::vector<int>& b) {
          a.insert(a.end(), b.begin(), b.end());
          return a;
        },
        10);
  });
  REQUIRE(seq.size() == 1000);
  for (int i = 0; i < 1000; ++i) CHECK(seq[static_cast<std::size_t>(i)] == i);
}
