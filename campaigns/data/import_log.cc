// The reading of one log (LogImporter): its gzip or plain text in blocks, the header against
// the map, each line's cells and numbers, the split into runs, and the resampling of the
// samples to the robot's control ticks, written by a RunWriter per run.
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string_view>

#include "campaigns/data/export.h"
#include "campaigns/data/gzip_reason.h"
#include "campaigns/data/import_internal.h"
#include "campaigns/data/import_run_writer.h"
#include "core/base/csv.h"
#include "core/base/json_input.h"
#include "core/base/suggest.h"

namespace armfault::import_detail {

namespace fs = std::filesystem;

namespace {

// One mapped column of a log: where its value goes.
struct Target {
  int log_column = -1;
  int out_column = 0;  // index among the output's signal columns (joint-major, field)
  double scale = 1, offset = 0;
  bool hold = false;
  std::string name;    // the log's column name, for errors
};

std::string StemOf(const std::string& path) {
  std::string s = fs::path(path).filename().string();
  for (const char* ext : {".gz", ".csv", ".txt"}) {
    const size_t n = std::strlen(ext);
    if (s.size() > n && s.compare(s.size() - n, n, ext) == 0) s.resize(s.size() - n);
  }
  return s;
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = s.substr(1, s.size() - 2);
  return s;
}

// Reads one log and writes its runs. Lines are numbered from 1 (the header).
class LogImporter {
 public:
  LogImporter(const ImportMap& map, const std::string& path, const fs::path& out_dir, double dt_s, int joints,
              std::vector<RunOut>* runs, std::set<std::string>* run_ids)
      : map_(map), path_(path), out_dir_(out_dir), dt_s_(dt_s), joints_(joints), runs_(runs), run_ids_(run_ids) {
    max_gap_s_ = map.max_gap_periods * dt_s;
  }

  long Run() {
    gzFile in = gzopen(path_.c_str(), "rb");
    if (!in) throw InputError(path_, "", std::string("cannot read the file: ") + std::strerror(errno ? errno : EIO));
    gzbuffer(in, 1 << 18);
    struct Closer {
      gzFile f;
      ~Closer() { gzclose(f); }
    } closer{in};
    std::string buf;
    constexpr size_t kChunk = 4 << 20;
    size_t start = 0;  // first unprocessed byte
    bool eof = false;
    while (!eof) {
      const size_t keep = buf.size() - start;
      buf.erase(0, start);
      start = 0;
      buf.resize(keep + kChunk);
      const int n = gzread(in, buf.data() + keep, static_cast<unsigned>(kChunk));
      if (n < 0) {
        int code = 0;
        throw InputError(path_, "", std::string("cannot read the file: ") + GzipReason(in, path_, &code));
      }
      buf.resize(keep + static_cast<size_t>(n));
      eof = n == 0;
      // zlib returns the data it could decode of a stream cut short and then 0, with
      // Z_BUF_ERROR: a log cut at a line boundary would import with its end missing.
      if (eof) {
        int code = Z_OK;
        const std::string why = GzipReason(in, path_, &code);
        if (code != Z_OK) throw InputError(path_, "", "cannot read the file: " + why);
      }
      if (eof && !buf.empty() && buf.back() != '\n') buf += '\n';  // a last line without its newline
      const char* data = buf.data();
      const size_t size = buf.size();
      while (start < size) {
        const char* nl = static_cast<const char*>(std::memchr(data + start, '\n', size - start));
        if (!nl) break;
        Line(std::string_view(data + start, static_cast<size_t>(nl - (data + start))));
        start = static_cast<size_t>(nl - data) + 1;
      }
    }
    if (line_ == 0) throw InputError(path_, "", "line 1: empty file, no header line");
    if (rows_ == 0) throw InputError(path_, "", "line 2: no data lines after the header");
    FinishRun();
    return rows_;
  }

 private:
  [[noreturn]] void Bad(const std::string& column, const std::string& why) const {
    throw InputError(path_, "", "line " + std::to_string(line_) + ", column " + Quoted(column) + ": " + why);
  }

  void Line(std::string_view line) {
    ++line_;
    if (line_ == 1) return Header(line);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty()) return;  // a blank line
    // Cells up to the last one needed.
    size_t pos = 0;
    int col = 0;
    std::string_view run_value;
    size_t next_target = 0;
    double raw_t = 0;
    while (col <= last_needed_) {
      if (pos > line.size()) {
        // The line ended before this column.
        const std::string& name = header_[static_cast<size_t>(col)];
        Bad(name, "missing: the line has only " + std::to_string(col) + " cells");
      }
      const int role = role_[static_cast<size_t>(col)];
      if (role == kTime || role == kValue) {
        // The common cell: a plain decimal up to the comma (ParsePlainDecimal), read in one pass.
        double x;
        const char* const q = ParsePlainDecimal(line.data() + pos, line.data() + line.size(), &x);
        if (q && (q == line.data() + line.size() || *q == ',')) {
          Value(role, col, x, &raw_t, &next_target);
          pos = static_cast<size_t>(q - line.data()) + 1;
          ++col;
          continue;
        }
      }
      size_t end;
      if (pos < line.size() && line[pos] == '"') {
        const size_t close = line.find('"', pos + 1);
        end = close == std::string_view::npos ? line.size() : line.find(',', close);
      } else {
        end = line.find(',', pos);
      }
      if (end == std::string_view::npos) end = line.size();
      if (role != kSkip) {
        const std::string_view cell = Trim(line.substr(pos, end - pos));
        if (role == kRun) {
          if (cell.empty()) Bad(header_[static_cast<size_t>(col)], "empty cell");
          run_value = cell;
        } else {
          Value(role, col, Number(cell, col), &raw_t, &next_target);
        }
      }
      pos = end + 1;
      ++col;
    }
    if (!map_.run_column.empty()) {
      if (runs_open_ == 0 || run_value != current_value_) {
        if (runs_open_ > 0) FinishRun();
        const std::string value(run_value);
        if (const auto [it, fresh] = seen_values_.emplace(value, line_); !fresh) {
          // The value is the log's: named by where it was first, not repeated.
          Bad(map_.run_column, "the run first seen on line " + std::to_string(it->second) +
                                   " starts again after another run: a run's lines must be together");
        }
        StartRun(value);
      }
    } else if (runs_open_ == 0) {
      StartRun("");
    }
    Sample(raw_t);
    ++rows_;
  }

  // A number of log column `col`: the time, or the fields it maps to.
  void Value(int role, int col, double x, double* raw_t, size_t* next_target) {
    if (role == kTime) {
      *raw_t = x;
      return;
    }
    // targets_ are sorted by log column: the next one is this column's.
    while (*next_target < targets_.size() && targets_[*next_target].log_column == col) {
      const Target& t = targets_[*next_target];
      cur_[static_cast<size_t>(t.out_column)] = x * t.scale + t.offset;
      ++*next_target;
    }
  }

  double Number(std::string_view cell, int col) const {
    if (cell.empty()) Bad(header_[static_cast<size_t>(col)], "empty cell");
    const char* b = cell.data();
    const char* e = b + cell.size();
    if (*b == '+') ++b;
    double x = 0;
    const auto [ptr, ec] = ParseDouble(b, e, x);
    if (ec == std::errc::result_out_of_range) Bad(header_[static_cast<size_t>(col)], "number out of range");
    if (ec != std::errc() || ptr != e) Bad(header_[static_cast<size_t>(col)], "not a number");
    if (!std::isfinite(x)) Bad(header_[static_cast<size_t>(col)], "NaN or infinite value");
    return x;
  }

  void Header(std::string_view line) {
    if (line.size() >= 3 && std::memcmp(line.data(), "\xEF\xBB\xBF", 3) == 0) line.remove_prefix(3);  // a BOM
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    size_t pos = 0;
    while (pos <= line.size()) {
      size_t end = line.find(',', pos);
      if (end == std::string_view::npos) end = line.size();
      header_.emplace_back(Trim(line.substr(pos, end - pos)));
      pos = end + 1;
    }
    role_.assign(header_.size(), kSkip);
    ErrorList errors;
    std::set<std::string> named = {map_.time.column, map_.run_column};
    for (const auto& joint : map_.joints) {
      for (const std::optional<ImportColumn>& c : joint) {
        if (c) named.insert(c->column);
      }
    }
    auto find = [&](const std::string& name, const std::string& pointer) -> int {
      int found = -1;
      for (size_t i = 0; i < header_.size(); ++i) {
        if (header_[i] != name) continue;
        if (found >= 0) {
          errors.Add(InputError(path_, "", "line 1: column " + Quoted(name) + " appears twice (the map's " + pointer + ")"));
          return -1;
        }
        found = static_cast<int>(i);
      }
      if (found < 0) {
        // The nearest among the columns the map does not name (a renamed column is one of them).
        std::vector<std::string> free;
        for (const std::string& h : header_) {
          if (!named.count(h)) free.push_back(h);
        }
        const std::string near = NearestWord(name, free);
        errors.Add(InputError(path_, "", "line 1: no column " + Quoted(name) + " (the map's " + map_.source + ": " + pointer + ")",
                              near.empty() ? "" : "did you mean \"" + near + "\"?"));
      }
      return found;
    };
    const int t = find(map_.time.column, "/time/column");
    if (t >= 0) role_[static_cast<size_t>(t)] = kTime;
    if (!map_.run_column.empty()) {
      const int r = find(map_.run_column, "/run_column");
      if (r >= 0) role_[static_cast<size_t>(r)] = kRun;
    }
    for (size_t j = 0; j < map_.joints.size(); ++j) {
      for (int f = 0; f < kImportFields; ++f) {
        const std::optional<ImportColumn>& c = map_.joints[j][f];
        if (!c) continue;
        const int col = find(c->column, "/joints/" + std::to_string(j + 1) + "/" + kFields[f].name + "/column");
        if (col < 0) continue;
        role_[static_cast<size_t>(col)] = kValue;
        Target tg;
        tg.log_column = col;
        tg.out_column = static_cast<int>(j) * kImportFields + f;
        tg.scale = c->scale;
        tg.offset = c->offset;
        tg.hold = c->hold;
        tg.name = c->column;
        targets_.push_back(tg);
      }
    }
    errors.ThrowIfAny();
    std::sort(targets_.begin(), targets_.end(), [](const Target& a, const Target& b) { return a.log_column < b.log_column; });
    for (size_t i = 0; i < role_.size(); ++i) {
      if (role_[i] != kSkip) last_needed_ = static_cast<int>(i);
    }
    const size_t outs = static_cast<size_t>(joints_) * kImportFields;
    cur_.assign(outs, std::nan(""));
    prev_.assign(outs, std::nan(""));
    mapped_.assign(outs, false);
    hold_.assign(outs, false);
    for (const Target& tg : targets_) {
      mapped_[static_cast<size_t>(tg.out_column)] = true;
      hold_[static_cast<size_t>(tg.out_column)] = tg.hold;
    }
  }

  void StartRun(const std::string& value) {
    RunOut r;
    r.file = path_;
    r.value = value;
    r.run_id = value.empty() ? StemOf(path_) : StemOf(path_) + "/" + value;
    if (!run_ids_->insert(r.run_id).second) {
      throw InputError(path_, "", "line " + std::to_string(line_) + ": run_id \"" + r.run_id +
                                      "\" is already a run of an earlier log (two logs of one name?)");
    }
    r.first_line = line_;
    char name[32];
    std::snprintf(name, sizeof name, "runs/%06zu.csv.gz", runs_->size());
    r.signals = name;
    runs_->push_back(r);
    writer_.emplace(out_dir_ / r.signals, SignalsCsvHeader(joints_), 1 + static_cast<size_t>(joints_) * kImportFields);
    ++runs_open_;
    samples_ = 0;
    tick_ = 0;
    current_value_ = value;
  }

  void FinishRun() {
    RunOut& r = runs_->back();
    if (samples_ < 2 || t_prev_ < dt_s_) {
      throw InputError(path_, "", "line " + std::to_string(r.last_line) + ": the run on lines " +
                                      std::to_string(r.first_line) + "-" + std::to_string(r.last_line) +
                                      " spans less than one control period (" + FormatNumber(dt_s_) + " s)");
    }
    writer_->Close();
    writer_.reset();
    r.ticks = tick_;
    r.end_s = RoundToMicroseconds(static_cast<double>(tick_ - 1) * dt_s_);
  }

  // One sample at the log's raw time: emits every control tick up to it.
  void Sample(double raw_t) {
    RunOut& r = runs_->back();
    r.last_line = line_;
    ++r.rows;
    if (samples_ == 0) {
      raw_t0_ = raw_t;
      prev_.swap(cur_);
      t_prev_ = 0;
      Emit(0, 0, 0);  // tick 0 = the first sample
      tick_ = 1;
      samples_ = 1;
      return;
    }
    const double t = (raw_t - raw_t0_) * map_.time.scale;
    if (!(t > t_prev_)) Bad(map_.time.column, "time does not increase (not after line " + std::to_string(line_ - 1) + "'s)");
    if (t - t_prev_ > max_gap_s_ * (1 + 1e-9)) {
      Bad(map_.time.column, "a gap of " + FormatNumber(t - t_prev_) + " s since the line before, longer than the limit of " +
                                FormatNumber(max_gap_s_) + " s (max_gap_periods " + FormatNumber(map_.max_gap_periods) +
                                " x the control period " + FormatNumber(dt_s_) + " s)");
    }
    if (t > kMaxRunSeconds) {
      Bad(map_.time.column, "the run is longer than " + FormatNumber(kMaxRunSeconds) +
                                " s, the longest a campaign holds; split the log into runs (\"run_column\")");
    }
    const double span = t - t_prev_;
    for (;;) {
      const double tk = static_cast<double>(tick_) * dt_s_;
      if (tk > t + 1e-9) break;
      double w = (tk - t_prev_) / span;
      w = w < 0 ? 0 : (w > 1 ? 1 : w);
      Emit(tick_, tk, w);
      ++tick_;
    }
    prev_.swap(cur_);
    t_prev_ = t;
    ++samples_;
  }

  // Writes tick k at time tk, `w` of the way from the previous sample to the current one
  // (k = 0: the first sample, held in prev_).
  void Emit(long k, double tk, double w) {
    double* row = writer_->AddTick();
    row[0] = k == 0 ? 0.0 : tk;
    const size_t outs = prev_.size();
    for (size_t i = 0; i < outs; ++i) {
      double x;
      if (!mapped_[i]) x = std::numeric_limits<double>::quiet_NaN();
      else if (k == 0) x = prev_[i];
      else if (hold_[i]) x = w >= 1 ? cur_[i] : prev_[i];
      else if (w >= 1) x = cur_[i];  // on a sample: its value as it is
      else x = prev_[i] + (cur_[i] - prev_[i]) * w;
      row[1 + i] = x;
    }
    writer_->MaybeFlush();
  }

  static constexpr int kSkip = 0, kTime = 1, kRun = 2, kValue = 3;
  const ImportMap& map_;
  std::string path_;
  fs::path out_dir_;
  double dt_s_;
  int joints_;
  std::vector<RunOut>* runs_;
  std::set<std::string>* run_ids_;
  double max_gap_s_ = 0;

  std::vector<std::string> header_;
  std::vector<int> role_;
  std::vector<Target> targets_;
  int last_needed_ = -1;
  std::vector<double> cur_, prev_;
  std::vector<bool> mapped_, hold_;

  long line_ = 0, rows_ = 0;
  int runs_open_ = 0;
  std::string current_value_;
  std::map<std::string, long> seen_values_;  // a run column value -> its first line
  std::optional<RunWriter> writer_;
  long samples_ = 0, tick_ = 0;
  double raw_t0_ = 0, t_prev_ = 0;
};

}  // namespace

long ReadLogIntoRuns(const ImportMap& map, const std::string& path, const fs::path& out_dir, double dt_s, int joints,
                     std::vector<RunOut>* runs, std::set<std::string>* run_ids) {
  LogImporter importer(map, path, out_dir, dt_s, joints, runs, run_ids);
  return importer.Run();
}

}  // namespace armfault::import_detail
