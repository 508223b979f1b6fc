// "csv": a reference read from a file of "time_s,angle_deg" rows, interpolated with a cubic
// Hermite spline whose slopes are Catmull-Rom central differences
// (p[k+1] - p[k-1]) / (t[k+1] - t[k-1]), one-sided differences at the two ends. Angle and
// velocity are continuous; acceleration (the Hermite second derivative) jumps at rows.
// Outside the time span the end angle is held with zero velocity and acceleration.
#include "core/plant/motion/trajectories.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

namespace armfault {

namespace {

namespace fs = std::filesystem;

class CsvSpline final : public Trajectory {
 public:
  // Requires at least 2 rows with strictly increasing times.
  CsvSpline(std::vector<double> times_s, std::vector<double> angles_rad)
      : t_(std::move(times_s)), q_(std::move(angles_rad)), m_(Slopes(t_, q_)) {}

  TrajectoryPoint At(double t_s) const override {
    TrajectoryPoint p;
    // `!(t >= first)` also catches NaN, which then holds the first angle.
    if (!(t_s >= t_.front())) {
      p.q_rad = q_.front();
      return p;
    }
    if (t_s > t_.back()) {
      p.q_rad = q_.back();
      return p;
    }
    // Segment k with t_[k] <= t <= t_[k + 1]; a row's own time starts its segment at u = 0
    // (the last row ends the last segment at u = 1), so rows are reproduced exactly.
    size_t k = static_cast<size_t>(std::upper_bound(t_.begin(), t_.end(), t_s) - t_.begin() - 1);
    k = std::min(k, t_.size() - 2);
    const double h = t_[k + 1] - t_[k];
    const double u = (t_s - t_[k]) / h;
    const double p0 = q_[k], p1 = q_[k + 1];
    const double m0 = m_[k] * h, m1 = m_[k + 1] * h;  // slopes per unit u
    const double u2 = u * u, u3 = u2 * u;
    p.q_rad = (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0 + (-2 * u3 + 3 * u2) * p1 +
              (u3 - u2) * m1;
    p.qd_rad_s = ((6 * u2 - 6 * u) * p0 + (3 * u2 - 4 * u + 1) * m0 + (-6 * u2 + 6 * u) * p1 +
                  (3 * u2 - 2 * u) * m1) / h;
    p.qdd_rad_s2 = ((12 * u - 6) * p0 + (6 * u - 4) * m0 + (-12 * u + 6) * p1 + (6 * u - 2) * m1) /
                   (h * h);
    return p;
  }
  const char* type() const override { return "csv"; }

 private:
  const std::vector<double> t_;  // row times [s], strictly increasing, at least 2
  const std::vector<double> q_;  // row angles [rad]
  const std::vector<double> m_;  // slopes dq/dt at the rows [rad/s]

  static std::vector<double> Slopes(const std::vector<double>& t, const std::vector<double>& q) {
    const size_t n = t.size();
    std::vector<double> m(n);
    m[0] = (q[1] - q[0]) / (t[1] - t[0]);
    m[n - 1] = (q[n - 1] - q[n - 2]) / (t[n - 1] - t[n - 2]);
    for (size_t k = 1; k + 1 < n; ++k) m[k] = (q[k + 1] - q[k - 1]) / (t[k + 1] - t[k - 1]);
    return m;
  }
};

constexpr const char* kWhitespace = " \t\r\v\f";

std::string_view Trim(std::string_view s) {
  const size_t begin = s.find_first_not_of(kWhitespace);
  if (begin == std::string_view::npos) return {};
  return s.substr(begin, s.find_last_not_of(kWhitespace) - begin + 1);
}

// Text quoted for an error message; text longer than `max_chars` is cut (file contents, not
// paths), and bytes that are not valid UTF-8 are replaced so the message stays printable.
std::string Quote(std::string_view text, size_t max_chars = 60) {
  std::string cut(text.substr(0, max_chars));
  if (text.size() > max_chars) cut += "...";
  return nlohmann::json(cut).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

enum class NumberParse { kOk, kNotANumber, kNotFinite };

// Whole field as a decimal number; locale-independent (std::from_chars, so "1,5" never
// means 1.5 and a decimal point is always '.'). Accepts a leading '+'.
NumberParse ParseNumber(std::string_view field, double* out) {
  if (!field.empty() && field[0] == '+') {
    field.remove_prefix(1);
    if (!field.empty() && field[0] == '-') return NumberParse::kNotANumber;
  }
  if (field.empty()) return NumberParse::kNotANumber;
  const char* end = field.data() + field.size();
  const auto [ptr, ec] = std::from_chars(field.data(), end, *out, std::chars_format::general);
  if (ptr != end) return NumberParse::kNotANumber;
  if (ec == std::errc::result_out_of_range) return NumberParse::kNotFinite;
  if (ec != std::errc()) return NumberParse::kNotANumber;
  return std::isfinite(*out) ? NumberParse::kOk : NumberParse::kNotFinite;
}

std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  for (;;) {
    const size_t comma = line.find(',');
    fields.push_back(Trim(line.substr(0, comma)));
    if (comma == std::string_view::npos) return fields;
    line.remove_prefix(comma + 1);
  }
}

// The column (from 1) where `field`, a view into `raw`, starts.
size_t ColumnOf(std::string_view field, const std::string& raw) {
  return static_cast<size_t>(field.data() - raw.data()) + 1;
}

// The largest trajectory file read (a million rows take about 20 MB).
constexpr size_t kMaxCsvBytes = size_t{64} << 20;

struct Row {
  double time_s;
  double angle_deg;
  size_t line;
};

// Parses the whole file text. Errors: InputError(csv_path, "line N", ...).
std::vector<Row> ParseRows(const std::string& text, const std::string& csv_path) {
  std::vector<Row> rows;
  std::istringstream in(text);
  std::string raw;
  size_t line_number = 0;
  bool first_content_line = true;
  while (std::getline(in, raw)) {
    ++line_number;
    std::string_view line = raw;
    // Spreadsheet exports often start with a UTF-8 byte order mark.
    if (line_number == 1 && line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);
    line = Trim(line);
    if (line.empty() || line[0] == '#') continue;
    // Errors name the line and the column, never the file's text (the path may name any file).
    const std::string where = "line " + std::to_string(line_number);
    const std::string expected = "expected 2 numbers \"time_s,angle_deg\"";

    const std::vector<std::string_view> fields = SplitFields(line);
    if (fields.size() != 2) {
      throw InputError(csv_path, where,
                       expected + ", got " + std::to_string(fields.size()) + (fields.size() == 1 ? " field" : " fields"));
    }
    double values[2];
    NumberParse parsed[2];
    for (int i = 0; i < 2; ++i) parsed[i] = ParseNumber(fields[i], &values[i]);
    // Header: only the first line with content, and only if neither field is a number
    // (so a first data row with one bad field is still reported, not skipped).
    const bool is_header = first_content_line && !fields[0].empty() && !fields[1].empty() &&
                           parsed[0] == NumberParse::kNotANumber &&
                           parsed[1] == NumberParse::kNotANumber;
    first_content_line = false;
    if (is_header) continue;
    for (int i = 0; i < 2; ++i) {
      const std::string field = expected + ": field " + std::to_string(i + 1) + " (column " +
                                std::to_string(ColumnOf(fields[i], raw)) + ")";
      if (parsed[i] == NumberParse::kNotANumber) throw InputError(csv_path, where, field + " is not a number");
      if (parsed[i] == NumberParse::kNotFinite) throw InputError(csv_path, where, field + " is not a finite number");
    }
    if (!rows.empty() && !(values[0] > rows.back().time_s)) {
      throw InputError(csv_path, where,
                       "time " + FormatNumber(values[0]) +
                           " s is not after the previous row's time " +
                           FormatNumber(rows.back().time_s) + " s (line " +
                           std::to_string(rows.back().line) + "); times must strictly increase");
    }
    rows.push_back({values[0], values[1], line_number});
  }
  return rows;
}

}  // namespace

std::unique_ptr<Trajectory> MakeCsv(ObjectReader& reader, const InputContext& ctx) {
  using namespace trajectory_detail;
  ErrorList errors;  // the unknown keys and the file
  errors.Try([&] { reader.AllowOnly({"path"}); });
  std::unique_ptr<Trajectory> out;
  errors.Try([&] {
    if (!reader.ShouldRead("path")) return;
    const std::string pointer = reader.PointerTo("path");
    const std::string path = reader.RequireString("path");
    if (path.empty()) throw InputError("", pointer, "expected a file name, got an empty string");

    // Relative paths are relative to the file that names them (ctx.base_dir), not to the
    // working directory, so an experiment directory can be moved as a whole.
    std::string resolved = path;
    if (fs::path(path).is_relative() && !ctx.base_dir.empty() && ctx.base_dir != ".") {
      resolved = (fs::path(ctx.base_dir) / path).string();
    }
    constexpr size_t kWholePath = std::string_view::npos;
    const std::string named =
        "CSV file " + Quote(resolved, kWholePath) +
        (resolved == path ? "" : " (resolved from " + Quote(path, kWholePath) + ")");

    std::error_code ec;
    const fs::file_status status = fs::status(resolved, ec);
    if (!fs::exists(status)) throw InputError("", pointer, named + " does not exist");
    if (fs::is_directory(status)) throw InputError("", pointer, named + " is a directory");
    // A regular file, read up to a bound: not a device (/dev/zero never ends) or a fifo.
    if (!fs::is_regular_file(status)) throw InputError("", pointer, named + " is not a regular file");
    std::ifstream file(resolved, std::ios::binary);
    std::string text(kMaxCsvBytes + 1, '\0');
    if (file) file.read(text.data(), static_cast<std::streamsize>(text.size()));
    if (!file && !file.eof()) throw InputError("", pointer, named + " cannot be read");
    text.resize(static_cast<size_t>(file.gcount()));
    if (text.size() > kMaxCsvBytes) {
      throw InputError("", pointer, named + " is larger than " + std::to_string(kMaxCsvBytes >> 20) + " MiB");
    }

    // The file's errors name the campaign (or run) file and the key that names the CSV file,
    // then the CSV file and its line.
    std::vector<Row> rows;
    try {
      rows = ParseRows(text, resolved);
    } catch (const InputError& e) {
      throw InputError("", pointer, named + ": " + e.pointer() + ": " + e.message());
    }
    if (rows.size() < 2) {
      throw InputError("", pointer,
                       named + " has " + std::to_string(rows.size()) +
                           " data row(s); at least 2 are needed");
    }
    std::vector<double> times_s, angles_rad;
    for (const Row& row : rows) {
      times_s.push_back(row.time_s);
      angles_rad.push_back(DegToRad(row.angle_deg));
    }
    out = std::make_unique<CsvSpline>(std::move(times_s), std::move(angles_rad));
  });
  errors.ThrowIfAny();
  return out;
}

}  // namespace armfault
