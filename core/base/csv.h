// CSV cells (RFC 4180): what results.csv, manifest.csv and trace CSVs share.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

namespace armfault {

// A text cell, quoted only when it must be (a comma, a quote or a line break in it). Text that
// a spreadsheet would take for a formula (its first character one of = + - @, a tab or a
// carriage return: a run or trajectory name, a reason) gets a leading apostrophe, as OWASP's
// rule for CSV injection says, so that it opens as the text it is. Numbers are not text cells.
inline std::string CsvText(const std::string& s) {
  const bool formula = !s.empty() && std::string("=+-@\t\r").find(s[0]) != std::string::npos;
  const std::string cell = formula ? "'" + s : s;
  if (cell.find_first_of(",\"\n\r") == std::string::npos) return cell;
  std::string out = "\"";
  for (char c : cell) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

// A number in its shortest form that reads back as the same double; NaN (no value) as "".
// Appends to `out`.
inline void AppendCsvExact(std::string* out, double x) {
  if (std::isnan(x)) return;
  char buf[32];
  const auto end = std::to_chars(buf, buf + sizeof buf, x).ptr;
  out->append(buf, end);
}

// x rounded to `digits` significant digits (1 to 15), written as printf's %.<digits>g writes it:
// the same text as std::to_chars(first, last, x, std::chars_format::general, digits), which is
// what the fast path is tested against (tests/core/base/csv_test.cc). The fast path covers the
// fixed notation (1e-4 <= |x| < 10^digits after rounding), where 10^k is an exact double and
// the product's rounding error is exact by one FMA, so the rounding is the library's (ties to
// even); everything else goes to std::to_chars. On the import's values (|x| < 3) 44-55 ns a
// number here against 62-66 ns for std::to_chars's shortest form (2.5x faster than its
// precision form), and 12 characters against 18 to deflate. `last - first` >= 32.
inline char* FormatGeneral(char* first, char* last, double x, int digits) {
  // 10^-5 ... 10^22 as doubles (exact from 10^0 on); kTen[i] = 10^(i - 5).
  static constexpr double kTen[] = {1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,
                                    1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const auto ten = [](int e) { return kTen[e + 5]; };
  const auto library = [&] { return std::to_chars(first, last, x, std::chars_format::general, digits).ptr; };
  const double a = std::fabs(x);
  if (digits < 1 || digits > 15 || !(a >= 1e-4 && a < ten(digits))) return library();
  // e: the decimal exponent of a, 10^e <= a < 10^(e+1). From the binary exponent it is one of
  // two; a within an ulp of an inexact power (10^-1 ... 10^-4) is corrected by the rounding below.
  uint64_t bits;
  std::memcpy(&bits, &a, sizeof bits);
  const int binary_exponent = static_cast<int>(bits >> 52) - 1023;  // a is normal here
  int e = (binary_exponent * 1233) >> 12;  // floor(log2(a) * log10(2)), one low at most
  if (a >= ten(e + 1)) ++e;
  const uint64_t low = static_cast<uint64_t>(ten(digits - 1)), high = static_cast<uint64_t>(ten(digits));
  uint64_t m = 0;
  for (int pass = 0;; ++pass) {
    if (e < -4 || e >= digits || pass > 2) return library();
    const double scale = ten(digits - 1 - e);  // 10^0 ... 10^18: exact
    const double scaled = a * scale;           // < 10^15: its integer part and fraction exact
    m = static_cast<uint64_t>(scaled);
    const double frac = scaled - static_cast<double>(m);
    // On a tie of the rounded product, the product's own rounding error (exact by one FMA)
    // decides; an exact tie goes to even.
    const auto error = [&] { return std::fma(a, scale, -scaled); };
    if (frac > 0.5 || (frac == 0.5 && (error() > 0 || (error() == 0 && (m & 1))))) ++m;
    if (m < low) {
      --e;  // a was under 10^e (an inexact power of ten)
    } else if (m > high) {
      ++e;
    } else if (m == high) {  // rounded up to 10^(e+1), or a was 10^(e+1): the same digits
      m = low;
      ++e;
      if (e >= digits) return library();
      break;
    } else {
      break;
    }
  }
  char d[16];
  for (int i = digits - 1; i >= 0; --i) {
    d[i] = static_cast<char>('0' + m % 10);
    m /= 10;
  }
  int n = digits;  // digits written: trailing zeros of the fraction dropped
  while (n > e + 1 && n > 1 && d[n - 1] == '0') --n;
  char* p = first;
  *p = '-';
  p += std::signbit(x);
  if (e >= 0) {
    for (int i = 0; i <= e; ++i) *p++ = d[i];
    if (n > e + 1) {
      *p++ = '.';
      for (int i = e + 1; i < n; ++i) *p++ = d[i];
    }
  } else {
    *p++ = '0';
    *p++ = '.';
    for (int i = 0; i < -e - 1; ++i) *p++ = '0';
    for (int i = 0; i < n; ++i) *p++ = d[i];
  }
  return p;
}

// The plain decimal a logger writes ("-12.3456", "86400000.1234": a minus sign, digits, a point,
// digits, no exponent, at most 15 significant digits with at most 22 after the point) at the
// start of [first, last): the digits as an integer, exact in a double, divided by an exact
// power of ten, which is the correctly rounded value (Clinger's fast path, as fast_float's).
// Returns the end of the decimal, or nullptr where the text is not one such (the caller then
// asks std::from_chars).
inline const char* ParsePlainDecimal(const char* first, const char* last, double* x) {
  static constexpr double kTen[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const char* p = first;
  const bool negative = p != last && *p == '-';
  p += negative;
  uint64_t m = 0;
  const char* const integer = p;
  while (p != last && static_cast<unsigned>(*p - '0') < 10) m = m * 10 + static_cast<unsigned>(*p++ - '0');
  const long integer_digits = p - integer;
  long after_point = 0;
  if (p != last && *p == '.') {
    const char* const fraction = ++p;
    while (p != last && static_cast<unsigned>(*p - '0') < 10) m = m * 10 + static_cast<unsigned>(*p++ - '0');
    after_point = p - fraction;
  }
  // Up to 15 digits the integer is below 2^53 (exact); leading zeros count, as a bound only.
  if (integer_digits == 0 || integer_digits + after_point > 15 || after_point > 22) return nullptr;
  if (p != last && (*p == 'e' || *p == 'E')) return nullptr;  // an exponent: not plain
  const double v = static_cast<double>(m) / kTen[after_point];
  *x = negative ? -v : v;
  return p;
}

// std::from_chars for a double, the plain decimals the fast way (ParsePlainDecimal): the same
// value, the same pointer and the same error as std::from_chars, which
// tests/core/base/csv_test.cc holds it to.
inline std::from_chars_result ParseDouble(const char* first, const char* last, double& x) {
  double v = 0;
  if (ParsePlainDecimal(first, last, &v) == last) {
    x = v;
    return {last, std::errc()};
  }
  return std::from_chars(first, last, x);
}

}  // namespace armfault
