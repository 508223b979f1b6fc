#include "campaigns/import.h"

#include <unistd.h>
#include <isa-l/igzip_lib.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string_view>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>

#include "campaigns/campaign_spec.h"
#include "campaigns/channels.h"
#include "campaigns/export.h"
#include "campaigns/run_dir.h"
#include "core/base/csv.h"
#include "core/base/json_input.h"
#include "core/base/output_file.h"
#include "core/base/suggest.h"
#include "core/plant/simulation.h"
#include "faults/fault.h"

namespace armfault {

namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

// The JointSignals fields (export column order) and the quantity each is of.
enum class Quantity { kAngle, kAngularVelocity, kTorque, kCurrent, kVoltage, kTemperature };
struct FieldInfo {
  const char* name;
  Quantity quantity;
};
const FieldInfo kFields[kImportFields] = {
    {"q_ref_rad", Quantity::kAngle},          {"qd_ref_rad_s", Quantity::kAngularVelocity},
    {"q_meas_rad", Quantity::kAngle},         {"qd_est_rad_s", Quantity::kAngularVelocity},
    {"tau_sensor_Nm", Quantity::kTorque},     {"i_cmd_A", Quantity::kCurrent},
    {"i_supply_meas_A", Quantity::kCurrent},  {"v_bus_meas_V", Quantity::kVoltage},
    {"winding_temp_C", Quantity::kTemperature},
};

// Units by quantity: value in the field's SI unit = raw * scale + offset.
struct UnitInfo {
  Quantity quantity;
  const char* name;
  double scale, offset;
};
const UnitInfo kUnits[] = {
    {Quantity::kAngle, "rad", 1, 0},
    {Quantity::kAngle, "mrad", 1e-3, 0},
    {Quantity::kAngle, "deg", kPi / 180, 0},
    {Quantity::kAngularVelocity, "rad/s", 1, 0},
    {Quantity::kAngularVelocity, "deg/s", kPi / 180, 0},
    {Quantity::kAngularVelocity, "rpm", 2 * kPi / 60, 0},
    {Quantity::kTorque, "N m", 1, 0},
    {Quantity::kTorque, "Nm", 1, 0},
    {Quantity::kTorque, "mN m", 1e-3, 0},
    {Quantity::kTorque, "mNm", 1e-3, 0},
    {Quantity::kCurrent, "A", 1, 0},
    {Quantity::kCurrent, "mA", 1e-3, 0},
    {Quantity::kVoltage, "V", 1, 0},
    {Quantity::kVoltage, "mV", 1e-3, 0},
    {Quantity::kTemperature, "degC", 1, 0},
    {Quantity::kTemperature, "°C", 1, 0},
    {Quantity::kTemperature, "K", 1, -273.15},
};

// The longest run a campaign holds (campaign_spec.cc's duration_s range): the stand-in
// campaign's duration is the longest run's.
constexpr double kMaxRunSeconds = 3600;

std::string Quoted(const std::string& s) { return "\"" + s + "\""; }

ImportColumn ColumnFromJson(const nlohmann::json& value, const std::string& pointer, int field, ErrorList* errors) {
  ImportColumn c;
  ObjectReader r(value, pointer);
  errors->Try([&] { r.AllowOnly({"column", "unit", "scale", "offset", "resample"}); });
  errors->Try([&] {
    c.column = r.RequireString("column");
    if (c.column.empty()) throw InputError("", r.PointerTo("column"), "expected a column name, got \"\"");
  });
  const bool has_unit = r.Has("unit"), has_scale = r.Has("scale") || r.Has("offset");
  if (has_unit && has_scale) {
    errors->Add(InputError("", r.PointerTo("unit"), "give a \"unit\" or a \"scale\" and \"offset\", not both"));
  } else if (!has_unit && !has_scale) {
    errors->Add(InputError("", pointer,
                           "expected a \"unit\" (or a \"scale\" and \"offset\" to the field's unit) for column " +
                               Quoted(c.column)));
  }
  if (has_unit) {
    errors->Try([&] {
      c.unit = r.RequireString("unit");
      std::string known;
      if (field >= 0 && !UnitToSi(field, c.unit, &c.scale, &c.offset, &known)) {
        std::vector<std::string> all;
        for (const UnitInfo& u : kUnits) all.push_back(u.name);
        const std::string near = NearestWord(c.unit, all);
        throw InputError("", r.PointerTo("unit"),
                         "unknown unit " + Describe(value["unit"]) + " for " + kFields[field].name + " (known: " + known + ")",
                         near.empty() || near == c.unit ? "" : "did you mean \"" + near + "\"?");
      }
    });
  }
  errors->Try([&] {
    r.OptionalNumber("scale", &c.scale);
    if (!std::isfinite(c.scale) || c.scale == 0) {
      throw InputError("", r.PointerTo("scale"), "expected a finite non-zero number, got " + Describe(value["scale"]));
    }
  });
  errors->Try([&] { r.OptionalNumber("offset", &c.offset); });
  errors->Try([&] {
    std::string how = "linear";
    r.OptionalString("resample", &how);
    if (how != "linear" && how != "hold") {
      throw InputError("", r.PointerTo("resample"), "expected \"linear\" or \"hold\", got " + Describe(value["resample"]));
    }
    c.hold = how == "hold";
  });
  return c;
}

ImportLabel LabelFromJson(const nlohmann::json& value, const std::string& pointer) {
  ImportLabel l;
  l.pointer = pointer;
  if (value.is_string()) {
    const std::string s = value.get<std::string>();
    if (s == "healthy") l.kind = ImportLabel::Kind::kHealthy;
    else if (s == "unknown") l.kind = ImportLabel::Kind::kUnknown;
    else throw InputError("", pointer, "expected \"healthy\", \"unknown\" or a fault object, got " + Describe(value));
    return l;
  }
  if (!value.is_object()) {
    throw InputError("", pointer, "expected \"healthy\", \"unknown\" or a fault object, got " + Describe(value));
  }
  ErrorList errors;
  ObjectReader r(value, pointer);
  errors.Try([&] { r.AllowOnly({"family", "joint", "onset_s", "magnitude"}); });
  l.kind = ImportLabel::Kind::kFault;
  errors.Try([&] { l.family = r.RequireString("family"); });
  errors.Try([&] { l.joint = r.RequireInt("joint"); });
  errors.Try([&] {
    l.onset_s = r.RequireNumber("onset_s");
    RequireAtLeast(l.onset_s, 0, r.PointerTo("onset_s"));
  });
  errors.Try([&] {
    if (const nlohmann::json* m = r.Find("magnitude"); m && !m->is_null()) l.magnitude = AsNumber(*m, r.PointerTo("magnitude"));
  });
  errors.ThrowIfAny();
  return l;
}

RobotConfig RobotOfMap(const nlohmann::json& value, const std::string& pointer, const std::string& base_dir) {
  if (value.is_string()) {
    const std::string what = value.get<std::string>();
    for (const std::string& name : RobotPresetNames()) {
      if (what == name) return RobotPreset(name, pointer);
    }
    const fs::path path = fs::path(what).is_absolute() ? fs::path(what) : fs::path(base_dir) / what;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
      std::string presets;
      for (const std::string& name : RobotPresetNames()) presets += (presets.empty() ? "" : ", ") + name;
      throw InputError("", pointer, Describe(value) + " is neither a robot preset (" + presets + ") nor a robot file");
    }
    const nlohmann::json file = ReadJsonFile(path.string());
    const std::string base = path.parent_path().string();
    try {
      const bool wrapper = file.is_object() && file.contains("robot") && !file.contains("modules") && !file.contains("urdf");
      return wrapper ? RobotFromJson(file.at("robot"), "/robot", base) : RobotFromJson(file, "", base);
    } catch (const InputError& e) {
      throw e.WithSource(path.string());
    }
  }
  return RobotFromJson(value, pointer, base_dir);
}

}  // namespace

bool UnitToSi(int field, const std::string& unit, double* scale, double* offset, std::string* known) {
  if (field < 0 || field >= kImportFields) return false;
  const Quantity q = kFields[field].quantity;
  std::string list;
  for (const UnitInfo& u : kUnits) {
    if (u.quantity != q) continue;
    if (unit == u.name) {
      *scale = u.scale;
      *offset = u.offset;
      return true;
    }
    list += (list.empty() ? "" : ", ") + std::string(u.name);
  }
  if (known) *known = list;
  return false;
}

bool TimeUnitToSeconds(const std::string& unit, double* seconds) {
  if (unit == "s") *seconds = 1;
  else if (unit == "ms") *seconds = 1e-3;
  else if (unit == "us" || unit == "µs") *seconds = 1e-6;
  else return false;
  return true;
}

ImportMap ImportMapFromJson(const nlohmann::json& value, const std::string& source, const std::string& base_dir) {
  ImportMap m;
  m.source = source;
  m.base_dir = base_dir;
  try {
    if (!value.is_object()) throw InputError("", "", "expected a JSON object (an import map), got " + Describe(value));
    ErrorList errors;
    ObjectReader r(value, "");
    errors.Try([&] {
      r.AllowOnly({"$schema", "name", "robot", "time", "run_column", "max_gap_periods", "joints", "labels", "floors"});
    });
    errors.Try([&] {
      std::string schema;
      r.OptionalString("$schema", &schema);
    });
    errors.Try([&] {
      r.OptionalString("name", &m.name);
      if (m.name.empty() || m.name.find('/') != std::string::npos) {
        throw InputError("", "/name", "a name must be non-empty and without '/', got " + Describe(value["name"]));
      }
    });
    errors.Try([&] {
      m.robot_given = r.Require("robot");
      m.robot = RobotOfMap(m.robot_given, "/robot", base_dir);
    });
    errors.Try([&] {
      const nlohmann::json& t = r.Require("time");
      ObjectReader tr(t, "/time");
      errors.Try([&] { tr.AllowOnly({"column", "unit"}); });
      errors.Try([&] { m.time.column = tr.RequireString("column"); });
      errors.Try([&] {
        m.time.unit = tr.RequireString("unit");
        if (!TimeUnitToSeconds(m.time.unit, &m.time.scale)) {
          const std::string near = NearestWord(m.time.unit, {"s", "ms", "us"});
          throw InputError("", "/time/unit", "unknown time unit " + Describe(t["unit"]) + " (known: s, ms, us)",
                           near.empty() ? "" : "did you mean \"" + near + "\"?");
        }
      });
    });
    errors.Try([&] { r.OptionalString("run_column", &m.run_column); });
    errors.Try([&] { r.OptionalNumber("max_gap_periods", &m.max_gap_periods); });
    errors.Try([&] {
      if (const nlohmann::json* f = r.Find("floors")) {
        if (!f->is_object()) throw InputError("", "/floors", "expected an object of floors, got " + Describe(*f));
        m.floors = *f;
      }
    });
    errors.Try([&] {
      const nlohmann::json& joints = r.Require("joints");
      if (!joints.is_object()) throw InputError("", "/joints", "expected an object keyed by joint number, got " + Describe(joints));
      for (auto it = joints.begin(); it != joints.end(); ++it) {
        const std::string jp = PointerJoin("/joints", it.key());
        errors.Try([&] {
          int j = 0;
          const auto [end, ec] = std::from_chars(it.key().data(), it.key().data() + it.key().size(), j);
          if (ec != std::errc() || end != it.key().data() + it.key().size() || j < 1 || j > 64) {
            throw InputError("", jp, "expected a joint number (1 = base), got \"" + it.key() + "\"");
          }
          if (static_cast<int>(m.joints.size()) < j) m.joints.resize(j);
          ObjectReader fr(it.value(), jp);
          std::vector<std::string> names;
          for (const FieldInfo& f : kFields) names.push_back(f.name);
          errors.Try([&] { fr.AllowOnly(names); });
          for (int f = 0; f < kImportFields; ++f) {
            if (const nlohmann::json* c = fr.Find(kFields[f].name)) {
              const std::string cp = fr.PointerTo(kFields[f].name);
              errors.Try([&] {
                if (c->is_string()) throw InputError("", cp, "expected {\"column\": ..., \"unit\": ...}, got " + Describe(*c));
                m.joints[j - 1][f] = ColumnFromJson(*c, cp, f, &errors);
              });
            }
          }
        });
      }
    });
    errors.Try([&] {
      if (const nlohmann::json* labels = r.Find("labels")) {
        if (!labels->is_object()) throw InputError("", "/labels", "expected an object keyed by run_id, got " + Describe(*labels));
        for (auto it = labels->begin(); it != labels->end(); ++it) {
          errors.Try([&] { m.labels[it.key()] = LabelFromJson(it.value(), PointerJoin("/labels", it.key())); });
        }
      }
    });
    errors.ThrowIfAny();
  } catch (const InputError& e) {
    throw e.WithSource(source);
  }
  return m;
}

void ValidateImportMap(const ImportMap& m) {
  ErrorList errors;
  const int joints = static_cast<int>(m.robot.modules.size());
  if (!(m.max_gap_periods >= 1 && m.max_gap_periods <= 1e6)) {
    errors.Add(InputError(m.source, "/max_gap_periods",
                          "expected a number of control periods from 1 to 1e6, got " + FormatNumber(m.max_gap_periods)));
  }
  if (static_cast<int>(m.joints.size()) > joints) {
    errors.Add(InputError(m.source, "/joints/" + std::to_string(m.joints.size()),
                          "joint " + std::to_string(m.joints.size()) + " does not exist: the robot has " +
                              std::to_string(joints) + " joints"));
  }
  std::map<std::string, std::string> used;  // column -> pointer of its first use
  used[m.time.column] = "/time/column";
  if (!m.run_column.empty()) {
    if (!used.emplace(m.run_column, "/run_column").second) {
      errors.Add(InputError(m.source, "/run_column", Quoted(m.run_column) + " is also the time column"));
    }
  }
  long columns = 0;
  for (size_t j = 0; j < m.joints.size(); ++j) {
    for (int f = 0; f < kImportFields; ++f) {
      if (!m.joints[j][f]) continue;
      ++columns;
      const std::string p = "/joints/" + std::to_string(j + 1) + "/" + kFields[f].name + "/column";
      if (!used.emplace(m.joints[j][f]->column, p).second) {
        errors.Add(InputError(m.source, p, "column " + Quoted(m.joints[j][f]->column) + " is also " + used[m.joints[j][f]->column]));
      }
    }
  }
  if (columns == 0) errors.Add(InputError(m.source, "/joints", "the map names no signal column"));
  const std::vector<std::string> families = FaultFamilyNames();
  for (const auto& [run, l] : m.labels) {
    if (l.kind != ImportLabel::Kind::kFault) continue;
    if (std::find(families.begin(), families.end(), l.family) == families.end()) {
      const std::string near = NearestWord(l.family, families);
      errors.Add(InputError(m.source, l.pointer + "/family", "unknown fault family \"" + l.family + "\"",
                            near.empty() ? "" : "did you mean \"" + near + "\"?"));
      continue;
    }
    if (l.joint < 1 || l.joint > joints) {
      errors.Add(InputError(m.source, l.pointer + "/joint",
                            "expected a joint from 1 to " + std::to_string(joints) + ", got " + std::to_string(l.joint)));
    }
    FaultMagnitudeRange range;
    if (l.magnitude && FaultMagnitudeRangeOf(l.family, &range)) {
      const double x = *l.magnitude;
      const bool low = range.min_exclusive ? !(x > range.min) : !(x >= range.min);
      if (low || !(x <= range.max) || (range.zero_excluded && x == 0)) {
        errors.Add(InputError(m.source, l.pointer + "/magnitude",
                              FormatNumber(x) + " is outside " + l.family + "'s range " + FaultMagnitudeRangeText(l.family)));
      }
    }
  }
  errors.ThrowIfAny();
}

ImportMap ReadImportMap(const std::string& path) {
  const nlohmann::json value = ReadJsonFile(path);
  ImportMap m = ImportMapFromJson(value, path, fs::path(path).parent_path().string());
  ValidateImportMap(m);
  return m;
}

namespace {

// Significant digits of a resampled signal value in the runs' CSV (docs/import.md,
// "Resampling"): a relative rounding of at most 5e-10, far below any joint sensor's resolution
// (a 24-bit encoder's count is 6e-8 of a turn), where the exact 17 digits of an interpolated
// double would carry nothing of the log and cost the formatting and the deflate twice as much.
constexpr int kValueDigits = 10;

// A gzip CSV of a run's signals written into the temporary directory. The parse hands over
// ticks as numbers, kBlockTicks at a time; each block is formatted and deflated on its own, as
// one gzip member, by one of kWorkers threads while the next blocks are parsed, and the members
// are written in order (a gzip file of several members is one stream to zlib's gzread,
// Python's gzip and pandas). Formatting and deflate are about two thirds of an import's CPU
// time; so the parse and the workers share the cores. Deflate by ISA-L's igzip at its level 2:
// on these digits 4x zlib's Huffman-only speed and 1.8x libdeflate's level 1, files within
// 2 % of theirs (docs/import.md, "Speed"). Any error of a worker is thrown by the next Submit()
// or by Close().
class RunWriter {
 public:
  // `columns` numbers a tick: t_s (written exact), then the signals (NaN: an empty cell).
  RunWriter(const fs::path& path, std::string header, size_t columns) : path_(path), columns_(columns), header_(std::move(header)) {
    file_ = OpenForWriting(path_, "wb");
    block_.reserve(kBlockTicks * columns_);
    for (int i = 0; i < kWorkers; ++i) threads_.emplace_back([this] { Work(); });
  }
  ~RunWriter() {
    Stop();
    if (file_) std::fclose(file_);
  }
  // Room for one tick's numbers at the end of the block.
  double* AddTick() {
    block_.resize(block_.size() + columns_);
    return block_.data() + block_.size() - columns_;
  }
  void MaybeFlush() {
    if (block_.size() >= kBlockTicks * columns_) Submit();
  }
  void Close() {
    Submit();
    Stop();
    if (error_) std::rethrow_exception(error_);
    std::FILE* f = file_;
    file_ = nullptr;
    CloseChecked(f, path_);
  }

 private:
  static constexpr size_t kBlockTicks = 4096;  // about 1 MB of text for three joints
  static constexpr int kWorkers = 2;
  static constexpr size_t kQueued = 6;  // blocks queued or deflated, not yet written: bounded memory
  struct Job {
    long index = 0;
    std::vector<double> ticks;
  };
  void Submit() {
    if (block_.empty() && submitted_ > 0) return;
    std::unique_lock<std::mutex> lock(mutex_);
    space_.wait(lock, [&] { return in_flight_ < kQueued || error_; });
    if (error_) std::rethrow_exception(error_);
    queue_.push_back(Job{submitted_++, std::move(block_)});
    ++in_flight_;
    if (!spare_.empty()) {
      block_ = std::move(spare_.back());
      spare_.pop_back();
    } else {
      block_ = std::vector<double>();
      block_.reserve(kBlockTicks * columns_);
    }
    ready_.notify_one();
  }
  void Stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    ready_.notify_all();
    for (std::thread& t : threads_) t.join();
    threads_.clear();
  }
  // One block's CSV text (the header first, in the first block) into `text`, grown as needed
  // and never zero-filled; returns its length.
  size_t Format(const Job& job, std::unique_ptr<char[]>* text, size_t* capacity) const {
    const size_t ticks = job.ticks.size() / columns_;
    const size_t bound = header_.size() + ticks * columns_ * 26;  // a number is at most 24 characters and a comma
    if (*capacity < bound) {
      text->reset(new char[bound]);
      *capacity = bound;
    }
    char* p = text->get();
    char* const end = p + bound;
    if (job.index == 0) p = std::copy(header_.begin(), header_.end(), p);
    const double* x = job.ticks.data();
    for (size_t k = 0; k < ticks; ++k) {
      p = std::to_chars(p, end, x[0]).ptr;  // t_s: the control clock, exact
      for (size_t c = 1; c < columns_; ++c) {
        *p++ = ',';
        if (!std::isnan(x[c])) p = FormatGeneral(p, end, x[c], kValueDigits);
      }
      *p++ = '\n';
      x += columns_;
    }
    return static_cast<size_t>(p - text->get());
  }
  // `size` bytes of `text` as one gzip member into `out` (grown as needed); its length, or 0 if
  // ISA-L fails.
  static size_t Deflate(const char* text, size_t size, std::vector<uint8_t>* level_buffer, std::unique_ptr<uint8_t[]>* out,
                        size_t* capacity) {
    isal_zstream z;
    isal_deflate_init(&z);
    z.level = 2;
    z.level_buf = level_buffer->data();
    z.level_buf_size = static_cast<uint32_t>(level_buffer->size());
    z.gzip_flag = IGZIP_GZIP;
    z.end_of_stream = 1;
    z.flush = NO_FLUSH;
    z.next_in = reinterpret_cast<uint8_t*>(const_cast<char*>(text));
    z.avail_in = static_cast<uint32_t>(size);
    const size_t want = size + size / 8 + 1024;
    if (*capacity < want) {
      out->reset(new uint8_t[want]);
      *capacity = want;
    }
    z.next_out = out->get();
    z.avail_out = static_cast<uint32_t>(*capacity);
    // Deflate's worst case (stored blocks) is 5 bytes a 64 kB block over the text: room enough.
    if (isal_deflate(&z) != COMP_OK || z.internal_state.state != ZSTATE_END) return 0;
    return *capacity - z.avail_out;
  }
  void Work() {
    std::vector<uint8_t> level_buffer;
    std::unique_ptr<char[]> text;
    std::unique_ptr<uint8_t[]> out;
    size_t text_capacity = 0, out_capacity = 0;
    for (;;) {
      Job job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        ready_.wait(lock, [&] { return !queue_.empty() || done_; });
        if (queue_.empty()) break;
        job = std::move(queue_.front());
        queue_.pop_front();
      }
      std::exception_ptr error;
      std::string member;
      try {
        level_buffer.resize(ISAL_DEF_LVL2_DEFAULT);
        const size_t size = Format(job, &text, &text_capacity);
        const size_t deflated = Deflate(text.get(), size, &level_buffer, &out, &out_capacity);
        if (deflated == 0) throw std::bad_alloc();
        member.assign(reinterpret_cast<const char*>(out.get()), deflated);
      } catch (...) {
        error = std::make_exception_ptr(InputError(path_.string(), "", "cannot write: deflate failed (out of memory?)"));
      }
      std::lock_guard<std::mutex> lock(mutex_);
      if (error && !error_) error_ = error;
      job.ticks.clear();
      spare_.push_back(std::move(job.ticks));  // for the parse's next block: no fresh pages
      deflated_.emplace(job.index, std::move(member));
      // Whoever holds the next member in order writes it (and any that follow, ready).
      try {
        for (auto it = deflated_.find(written_); it != deflated_.end(); it = deflated_.find(written_)) {
          if (!error_) WriteChecked(file_, it->second, path_);
          deflated_.erase(it);
          ++written_;
          --in_flight_;
        }
      } catch (...) {
        if (!error_) error_ = std::current_exception();
      }
      space_.notify_all();
    }
  }
  fs::path path_;
  size_t columns_;
  std::string header_;
  std::FILE* file_ = nullptr;
  std::vector<double> block_;
  std::mutex mutex_;
  std::condition_variable ready_, space_;
  std::deque<Job> queue_;
  std::vector<std::vector<double>> spare_;  // blocks formatted, their memory kept
  std::map<long, std::string> deflated_;
  long submitted_ = 0, written_ = 0;
  size_t in_flight_ = 0;
  bool done_ = false;
  std::exception_ptr error_;
  std::vector<std::thread> threads_;
};

// One mapped column of a log: where its value goes.
struct Target {
  int log_column = -1;
  int out_column = 0;  // index among the output's signal columns (joint-major, field)
  double scale = 1, offset = 0;
  bool hold = false;
  std::string name;    // the log's column name, for errors
};

struct RunOut {
  std::string run_id;
  std::string file;  // the log
  std::string value;  // the run column's value, "" for a whole file
  long first_line = 0, last_line = 0, rows = 0, ticks = 0;
  double end_s = 0;
  std::string signals;  // runs/<case>.csv.gz
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
        throw InputError(path_, "", std::string("cannot read the file: ") + gzerror(in, &code));
      }
      buf.resize(keep + static_cast<size_t>(n));
      eof = n == 0;
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

// The manifest line of an imported run: the export's keys (campaigns/export.cc), with the
// label as its fault, plus "label" and "source".
nlohmann::json ManifestLine(const RunOut& r, long index, const ImportLabel* label) {
  nlohmann::json m;
  m["case"] = index;
  m["run_id"] = r.run_id;
  m["split"] = nullptr;
  m["signals"] = r.signals;
  m["ticks"] = r.ticks;
  m["end_s"] = r.end_s;
  m["trajectory"] = "import";
  m["seed"] = 0;
  m["repetition"] = 0;
  m["variation"] = nullptr;
  m["effect"] = nullptr;
  m["excited"] = nullptr;
  m["not_excited_reason"] = nullptr;
  m["status"] = "ok";
  m["reason"] = nullptr;
  m["fault"] = nullptr;
  m["family"] = nullptr;
  m["joint"] = nullptr;
  m["onset_s"] = nullptr;
  m["magnitude_key"] = nullptr;
  m["magnitude"] = nullptr;
  m["profile"] = nullptr;
  m["group"] = "";
  m["label"] = "unknown";
  if (label && label->kind == ImportLabel::Kind::kHealthy) m["label"] = "healthy";
  if (label && label->kind == ImportLabel::Kind::kFault) {
    const std::string key = FaultMagnitudeKey(label->family);
    nlohmann::json fault = {{"family", label->family}, {"joint", label->joint}, {"onset_s", label->onset_s}};
    std::string group = label->family;
    if (label->magnitude && !key.empty()) {
      fault[key] = *label->magnitude;
      group += " " + key + "=" + FormatNumber(*label->magnitude);
    }
    group += " joint=" + std::to_string(label->joint);
    m["label"] = "fault";
    m["fault"] = fault;
    m["family"] = label->family;
    m["joint"] = label->joint;
    m["onset_s"] = label->onset_s;
    m["magnitude_key"] = key.empty() ? nlohmann::json(nullptr) : nlohmann::json(key);
    m["magnitude"] = label->magnitude ? nlohmann::json(*label->magnitude) : nlohmann::json(nullptr);
    m["profile"] = "abrupt";
    m["group"] = group;
  }
  nlohmann::json source = {{"file", r.file}, {"lines", {r.first_line, r.last_line}}, {"rows", r.rows}};
  if (!r.value.empty()) source["run_value"] = r.value;
  m["source"] = source;
  return m;
}

// Removes the temporary directory unless released (an error: nothing is left behind).
struct TempDir {
  fs::path path;
  bool keep = false;
  ~TempDir() {
    if (keep) return;
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

}  // namespace

ImportResult ImportLogs(const std::vector<std::string>& logs, const ImportMap& map, const ImportOptions& o) {
  if (logs.empty()) throw InputError("LOG", "", "give at least one log file");
  fs::path dir = fs::path(o.output_dir).lexically_normal();
  if (dir.filename().empty()) dir = dir.parent_path();  // "out/" is "out"
  if (dir.empty() || dir == "." || dir == "..") throw InputError("-o", "", "expected a new directory's name, got \"" + o.output_dir + "\"");
  std::error_code ec;
  if (fs::exists(fs::symlink_status(dir, ec)) && !(fs::is_directory(fs::symlink_status(dir, ec)) && fs::is_empty(dir, ec))) {
    throw InputError(dir.string(), "", "already exists and is not an empty directory: choose another output directory");
  }
  const ArmModel arm(map.robot);
  const double dt_s = arm.control_dt_s();
  const int joints = arm.joint_count();

  fs::path parent = dir.parent_path();
  if (parent.empty()) parent = ".";
  fs::create_directories(parent);
  TempDir tmp{parent / (dir.filename().string() + ".import-tmp." + std::to_string(::getpid()))};
  fs::remove_all(tmp.path, ec);
  fs::create_directories(tmp.path / "runs");

  ImportResult result;
  std::vector<RunOut> runs;
  std::set<std::string> run_ids;
  nlohmann::json log_list = nlohmann::json::array();
  for (const std::string& log : logs) {
    const size_t before = runs.size();
    LogImporter importer(map, log, tmp.path, dt_s, joints, &runs, &run_ids);
    const long rows = importer.Run();
    result.rows += rows;
    nlohmann::json ids = nlohmann::json::array();
    for (size_t i = before; i < runs.size(); ++i) ids.push_back(runs[i].run_id);
    log_list.push_back({{"file", log}, {"rows", rows}, {"runs", ids}});
    if (o.progress) o.progress(result.rows);
  }

  // The labels against the runs found.
  ErrorList errors;
  std::vector<std::string> ids;
  for (const RunOut& r : runs) ids.push_back(r.run_id);
  std::map<std::string, const RunOut*> by_id;
  for (const RunOut& r : runs) by_id[r.run_id] = &r;
  for (const auto& [id, label] : map.labels) {
    const auto it = by_id.find(id);
    if (it == by_id.end()) {
      const std::string near = NearestId(id, ids);
      errors.Add(InputError(map.source, label.pointer, "no run \"" + id + "\" in the logs",
                            near.empty() ? "" : "did you mean \"" + near + "\"?"));
    } else if (label.kind == ImportLabel::Kind::kFault && label.onset_s > it->second->end_s) {
      errors.Add(InputError(map.source, label.pointer + "/onset_s",
                            FormatNumber(label.onset_s) + " is after the run's end (" + FormatNumber(it->second->end_s) + " s)"));
    }
  }
  errors.ThrowIfAny();

  AtomicOutputFile manifest(tmp.path / "manifest.jsonl");
  AtomicOutputFile manifest_csv(tmp.path / "manifest.csv");
  manifest_csv.Write(ManifestCsvHeader());
  for (size_t i = 0; i < runs.size(); ++i) {
    const auto it = map.labels.find(runs[i].run_id);
    const nlohmann::json m = ManifestLine(runs[i], static_cast<long>(i), it == map.labels.end() ? nullptr : &it->second);
    manifest.Write(m.dump() + "\n");
    manifest_csv.Write(ManifestCsvRow(m));
    result.ticks += runs[i].ticks;
    result.max_end_s = std::max(result.max_end_s, runs[i].end_s);
  }
  manifest.Commit();
  manifest_csv.Commit();
  result.runs = static_cast<long>(runs.size());

  // The stand-in campaign: the robot, the longest run, the floors; its cases are not the runs
  // (the manifest is the truth), only as many.
  const nlohmann::json campaign_json = {
      {"name", map.name},
      {"robot", RobotToJson(map.robot)},
      {"duration_s", std::max(result.max_end_s, dt_s)},
      {"trajectories", {{{"name", "import"}, {"joints", nlohmann::json::object()}}}},
      {"healthy", result.runs},
      {"monitor", nlohmann::json::object()},
      {"floors", map.floors}};
  // Only the floors come from the map unchecked: an error in them names the map and /floors/...
  const CampaignSpec campaign = CampaignSpecFromJson(campaign_json, map.source, map.base_dir);
  WriteAtomically(tmp.path / run_dir::kCampaign, CampaignFileJson(campaign, ShardSpec{}).dump(2) + "\n");
  WriteAtomically(tmp.path / "channels.json", ChannelsJson(MonitorSignalChannels(joints), "runs/*.csv.gz"));
  nlohmann::json import_record = {{"map", map.source}, {"logs", log_list}, {"control_period_s", dt_s},
                                  {"max_gap_s", map.max_gap_periods * dt_s}};
  WriteAtomically(tmp.path / "import.json", import_record.dump(2) + "\n");

  if (fs::exists(dir, ec)) fs::remove(dir, ec);  // empty (checked above)
  RenameChecked(tmp.path, dir);
  tmp.keep = true;
  return result;
}

}  // namespace armfault
