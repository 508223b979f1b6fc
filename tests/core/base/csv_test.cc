// FormatGeneral (core/base/csv.h): the import's fast %.<digits>g, held to the library's text.
#include "core/base/csv.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace armfault {
namespace {

std::string Fast(double x, int digits) {
  char buf[64];
  return std::string(buf, FormatGeneral(buf, buf + sizeof buf, x, digits));
}

std::string Library(double x, int digits) {
  char buf[64];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, x, std::chars_format::general, digits).ptr);
}

TEST(FormatGeneral, WritesWhatPrintfWrites) {
  EXPECT_EQ(Fast(0.36950016528121554, 10), "0.3695001653");
  EXPECT_EQ(Fast(-0.219381, 10), "-0.219381");
  EXPECT_EQ(Fast(0.032637700000000006, 10), "0.0326377");
  EXPECT_EQ(Fast(30.0, 10), "30");
  EXPECT_EQ(Fast(9.99999999996, 10), "10");
  EXPECT_EQ(Fast(0.00012345678901, 10), "0.000123456789");
  EXPECT_EQ(Fast(1.25, 2), "1.2");  // an exact tie: to even
  EXPECT_EQ(Fast(1.35, 2), "1.4");  // 1.35 is 1.350000000000000088817...: up
  EXPECT_EQ(Fast(0.0, 10), "0");
  EXPECT_EQ(Fast(-0.0, 10), "-0");
  EXPECT_EQ(Fast(1e-5, 10), "1e-05");
  EXPECT_EQ(Fast(12345678901.0, 10), "1.23456789e+10");
}

// Every value the fast path takes: the same text as std::to_chars (random magnitudes across and
// beyond the fixed range, powers of ten and their neighbours, exact decimal ties, rounding to the
// next power), for every precision the function accepts.
TEST(FormatGeneral, SameTextAsTheLibrary) {
  std::vector<double> values;
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> exponent(-7, 17), mantissa(1, 10);
  for (int i = 0; i < 300000; ++i) {
    const double x = mantissa(rng) * std::pow(10.0, std::floor(exponent(rng)));
    values.push_back(i % 2 ? -x : x);
  }
  for (int e = -6; e <= 17; ++e) {
    const double p = std::pow(10.0, e);
    for (double x : {p, std::nextafter(p, 0.0), std::nextafter(p, 1e300)}) {
      for (int u = 0; u < 3; ++u) values.push_back(x * (1 + u * 1e-16));
    }
    for (int d = 1; d <= 15; ++d) {
      const double q = std::pow(10.0, e - d + 1);
      values.push_back(p * 10 - 0.5 * q);  // rounds up to the next power
      values.push_back(p * 10 - 0.49 * q);
      values.push_back(p * 10 - 0.51 * q);
    }
  }
  // Exact ties at every precision: n + 0.5 in units of the last digit, where representable.
  for (int d = 1; d <= 15; ++d) {
    for (int n = 0; n < 2000; ++n) {
      values.push_back((std::pow(10.0, d - 1) + 37 * n + 0.5) / 64 * 64);
      values.push_back(std::ldexp(static_cast<double>(2 * (n + 1) + 1), -(n % 12 + 1)));
    }
  }
  long compared = 0;
  for (int digits = 1; digits <= 15; ++digits) {
    for (double x : values) {
      ASSERT_EQ(Fast(x, digits), Library(x, digits)) << "x = " << Library(x, 17) << ", digits " << digits;
      ++compared;
    }
  }
  EXPECT_GT(compared, 4000000);
}

// ParseDouble: the same value (to the bit), pointer and error as std::from_chars, on the
// decimals a logger writes and on everything else.
TEST(ParseDouble, SameAsTheLibrary) {
  std::vector<std::string> cells = {"0", "-0", "0.0", "-0.0", "1.", ".5", "-.5", "1e5", "1E-3", "12.5e", "-", ".", "",
                                    "--1", "1..2", "1.2.3", "nan", "inf", "-inf", "0x1p3", "1,5", " 1", "1 ", "12a",
                                    "000000000000000012.5", "123456789012345", "1234567890123456",
                                    "0.0000000000000000000001", "0.00000000000000000000001", "9007199254740993",
                                    "179769313486231570000000000000000000000000000000000000000000000000000000000000"};
  std::mt19937_64 rng(29);
  std::uniform_int_distribution<int> length(1, 18), digit(0, 9), point(0, 19), sign(0, 3);
  for (int i = 0; i < 400000; ++i) {
    std::string s = sign(rng) == 0 ? "-" : "";
    const int n = length(rng), at = point(rng);
    for (int d = 0; d < n; ++d) {
      if (d == at) s += '.';
      s += static_cast<char>('0' + digit(rng));
    }
    cells.push_back(s);
  }
  char buf[64];
  for (double v : {0.1, 1.0 / 3, 2.0 / 3, 86400000.1234, 1e-4, 123.456}) {
    for (int d = 1; d <= 17; ++d) cells.push_back(std::string(buf, std::to_chars(buf, buf + 64, v, std::chars_format::fixed, d).ptr));
  }
  long fast = 0;
  for (const std::string& s : cells) {
    double got = -1, want = -1;
    const auto g = ParseDouble(s.data(), s.data() + s.size(), got);
    const auto w = std::from_chars(s.data(), s.data() + s.size(), want);
    ASSERT_EQ(g.ec, w.ec) << '"' << s << '"';
    ASSERT_EQ(g.ptr, w.ptr) << '"' << s << '"';
    if (w.ec == std::errc()) {
      ASSERT_EQ(std::memcmp(&got, &want, sizeof got), 0) << '"' << s << "\": " << got << " vs " << want;
    }
    fast += s.size() <= 16 && s.find_first_of("eEnix") == std::string::npos;
  }
  EXPECT_GT(fast, 100000);
}

}  // namespace
}  // namespace armfault
