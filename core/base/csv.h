// CSV cells (RFC 4180): what results.csv, manifest.csv and trace CSVs share.
#pragma once

#include <charconv>
#include <cmath>
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

}  // namespace armfault
