// CSV cells (RFC 4180): what results.csv, manifest.csv and trace CSVs share.
#pragma once

#include <charconv>
#include <cmath>
#include <string>

namespace armfault {

// A text cell, quoted only when it must be (a comma, a quote or a line break in it).
inline std::string CsvText(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
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

}  // namespace armfault
