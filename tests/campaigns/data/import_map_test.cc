// campaigns/data/import.h: the map's parsing and checks, units, and the resampling rules on logs
// whose answer is known (a ramp is interpolated exactly, a held step stays a step), split
// files, and the awkward text a logger writes (BOM, CRLF, quotes, spaces, gzip).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "campaigns/data/import.h"
#include "core/base/json_input.h"

namespace armfault {
namespace {

namespace fs = std::filesystem;

struct Scratch {
  fs::path dir = fs::temp_directory_path() / ("armfault_import_map_test." + std::to_string(::getpid()) + "." +
                                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
  Scratch() {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~Scratch() { fs::remove_all(dir); }
  std::string Write(const std::string& name, const std::string& text) const {
    std::ofstream(dir / name, std::ios::binary) << text;
    return (dir / name).string();
  }
};

ImportMap MapOf(const nlohmann::json& j) {
  ImportMap m = ImportMapFromJson(j, "map.json", ".");
  ValidateImportMap(m);
  return m;
}

nlohmann::json BaseMap() {
  return {{"robot", "mrr-config1"},
          {"time", {{"column", "t"}, {"unit", "s"}}},
          {"joints",
           {{"3",
             {{"q_meas_rad", {{"column", "q"}, {"unit", "deg"}}},
              {"i_cmd_A", {{"column", "i"}, {"unit", "mA"}, {"resample", "hold"}}}}}}}};
}

// A run's rows of runs/<case>.csv.gz as cells.
std::vector<std::vector<std::string>> ReadRun(const fs::path& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  std::string text;
  char buf[65536];
  for (int n; (n = gzread(f, buf, sizeof buf)) > 0;) text.append(buf, static_cast<size_t>(n));
  gzclose(f);
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    size_t pos = 0;
    for (;;) {
      const size_t end = line.find(',', pos);
      cells.push_back(line.substr(pos, end == std::string::npos ? std::string::npos : end - pos));
      if (end == std::string::npos) break;
      pos = end + 1;
    }
    rows.push_back(cells);
  }
  return rows;
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    std::string all;
    for (const InputError& x : e.errors()) all += x.text() + "\n";
    return all;
  }
  return "";
}

TEST(ImportUnits, ConvertToTheFieldsUnit) {
  double scale = 0, offset = 0;
  std::string known;
  ASSERT_TRUE(UnitToSi(2, "deg", &scale, &offset, &known));  // q_meas_rad
  EXPECT_DOUBLE_EQ(scale, M_PI / 180);
  ASSERT_TRUE(UnitToSi(4, "mN m", &scale, &offset, &known));  // tau_sensor_Nm
  EXPECT_DOUBLE_EQ(scale, 1e-3);
  ASSERT_TRUE(UnitToSi(8, "K", &scale, &offset, &known));  // winding_temp_C
  EXPECT_DOUBLE_EQ(offset, -273.15);
  EXPECT_FALSE(UnitToSi(5, "deg", &scale, &offset, &known));  // i_cmd_A in degrees
  EXPECT_EQ(known, "A, mA");
  double s = 0;
  EXPECT_TRUE(TimeUnitToSeconds("us", &s));
  EXPECT_DOUBLE_EQ(s, 1e-6);
  EXPECT_FALSE(TimeUnitToSeconds("min", &s));
}

TEST(ImportMapTest, EveryErrorNamesTheMapPointerAndValue) {
  nlohmann::json j = BaseMap();
  j["joints"]["3"]["q_meas_rad"]["unit"] = "grad";
  j["joints"]["3"]["tau_sensor"] = {{"column", "x"}, {"unit", "Nm"}};
  j["time"]["unit"] = "hours";
  j["extra"] = 1;
  j["labels"] = {{"a", {{"family", "kt_degradation"}, {"joint", 9}, {"onset_s", -1}}}, {"b", "sick"}};
  const std::string e = ErrorOf([&] { MapOf(j); });
  EXPECT_THAT(e, ::testing::HasSubstr("map.json: /extra"));
  EXPECT_THAT(e, ::testing::HasSubstr("map.json: /joints/3/q_meas_rad/unit: unknown unit \"grad\""));
  EXPECT_THAT(e, ::testing::HasSubstr("map.json: /joints/3/tau_sensor"));
  EXPECT_THAT(e, ::testing::HasSubstr("did you mean \"tau_sensor_Nm\"?"));
  EXPECT_THAT(e, ::testing::HasSubstr("map.json: /time/unit: unknown time unit \"hours\""));
  EXPECT_THAT(e, ::testing::HasSubstr("map.json: /labels/a/onset_s"));
  EXPECT_THAT(e, ::testing::HasSubstr("map.json: /labels/b: expected \"healthy\", \"unknown\" or a fault object, got \"sick\""));
  // The checks that need the robot and the family table.
  nlohmann::json k = BaseMap();
  k["labels"] = {{"a", {{"family", "kt_degradation"}, {"joint", 9}, {"onset_s", 1}}}};
  k["max_gap_periods"] = 0.5;
  k["joints"]["2"] = {{"i_cmd_A", {{"column", "q"}, {"unit", "A"}}}};  // q is joint 3's angle too
  const std::string v = ErrorOf([&] { MapOf(k); });
  EXPECT_THAT(v, ::testing::HasSubstr("map.json: /labels/a/joint: expected a joint from 1 to 3, got 9"));
  EXPECT_THAT(v, ::testing::HasSubstr("map.json: /max_gap_periods"));
  EXPECT_THAT(v, ::testing::HasSubstr("column \"q\" is also"));
}

TEST(ImportResample, LinearIsExactOnARampAndHoldKeepsAStep) {
  Scratch s;
  // 1 kHz, time in s offset by 1000 s: q a ramp of 1 deg/ms (exact under linear interpolation),
  // i a step at 5.5 ms (held: the 500 Hz ticks before it keep the old value).
  // Even samples (but the first and last) 0.3 ms late, so a tick falls between two samples.
  std::string log = "\xEF\xBB\xBF" "junk, t ,\"q\",i\r\n";
  std::vector<std::pair<double, double>> samples;  // (time from the first, mA)
  for (int k = 0; k <= 20; ++k) {
    const double t = 1000 + k * 0.001 + (k % 2 == 0 && k > 0 && k < 20 ? 0.0003 : 0.0);
    const double q = (t - 1000) * 1000;                          // deg
    const double i = t - 1000 < 0.0055 ? 100 : 300;               // mA
    char line[128];
    std::snprintf(line, sizeof line, "x, %.6f ,\"%.9g\",%g\r\n", t, q, i);
    samples.emplace_back(t - 1000, i);
    log += line;
  }
  const std::string path = s.Write("ramp.csv", log);
  const ImportMap map = MapOf(BaseMap());
  const ImportResult r = ImportLogs({path}, map, {(s.dir / "out").string(), nullptr});
  EXPECT_EQ(r.runs, 1);
  EXPECT_EQ(r.rows, 21);
  const auto rows = ReadRun(s.dir / "out" / "runs" / "000000.csv.gz");
  ASSERT_EQ(rows.size(), 12u);  // header + ticks 0, 2, ..., 20 ms
  const size_t q_col = 1 + 2 * 9 + 2, i_col = 1 + 2 * 9 + 5;  // joint 3's q_meas_rad, i_cmd_A
  for (size_t k = 1; k < rows.size(); ++k) {
    const double t = (k - 1) * 0.002;
    EXPECT_NEAR(std::stod(rows[k][0]), t, 1e-12);
    EXPECT_NEAR(std::stod(rows[k][q_col]), t * 1000 * M_PI / 180, 1e-9) << "tick " << k - 1;
    double held = 0;  // the last sample at or before the tick
    for (const auto& [ts, mA] : samples) {
      if (ts <= t + 1e-9) held = mA / 1000;
    }
    EXPECT_DOUBLE_EQ(std::stod(rows[k][i_col]), held) << "tick " << k - 1;
    EXPECT_EQ(rows[k][1], "") << "joint 1 is not in the map: NaN";
  }
  // Labels absent: unknown.
  const std::string manifest = [&] {
    std::ifstream in(s.dir / "out" / "manifest.jsonl");
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  EXPECT_THAT(manifest, ::testing::HasSubstr("\"label\":\"unknown\""));
  EXPECT_THAT(manifest, ::testing::HasSubstr("\"run_id\":\"ramp\""));
}

TEST(ImportSplit, ALongGzipFileIntoRunsByAColumn) {
  Scratch s;
  std::string text = "run,t,q,i\n";
  for (const char* run : {"A", "B"}) {
    for (int k = 0; k <= 10; ++k) text += std::string(run) + "," + std::to_string(k) + ",1,2\n";  // t in ms
  }
  gzFile f = gzopen((s.dir / "shift.csv.gz").c_str(), "wb");
  gzwrite(f, text.data(), static_cast<unsigned>(text.size()));
  gzclose(f);
  nlohmann::json j = BaseMap();
  j["time"]["unit"] = "ms";
  j["run_column"] = "run";
  j["labels"] = {{"shift/A", "healthy"}, {"shift/B", {{"family", "kt_degradation"}, {"joint", 3}, {"onset_s", 0.004}, {"magnitude", 0.7}}}};
  const ImportResult r = ImportLogs({(s.dir / "shift.csv.gz").string()}, MapOf(j), {(s.dir / "out").string(), nullptr});
  EXPECT_EQ(r.runs, 2);
  EXPECT_EQ(r.ticks, 12);
  std::ifstream in(s.dir / "out" / "manifest.jsonl");
  std::string a, b;
  std::getline(in, a);
  std::getline(in, b);
  EXPECT_THAT(a, ::testing::HasSubstr("\"run_id\":\"shift/A\""));
  EXPECT_THAT(a, ::testing::HasSubstr("\"label\":\"healthy\""));
  EXPECT_THAT(b, ::testing::HasSubstr("\"family\":\"kt_degradation\""));
  EXPECT_THAT(b, ::testing::HasSubstr("\"kt_factor\":0.7"));
  EXPECT_THAT(b, ::testing::HasSubstr("\"source\":{\"file\":"));
  EXPECT_TRUE(fs::exists(s.dir / "out" / "campaign.json"));
  // An onset after the run's end is refused, naming the label; nothing is written.
  j["labels"]["shift/B"]["onset_s"] = 1.0;
  const std::string e = ErrorOf([&] { ImportLogs({(s.dir / "shift.csv.gz").string()}, MapOf(j), {(s.dir / "out2").string(), nullptr}); });
  EXPECT_THAT(e, ::testing::HasSubstr("map.json: /labels/shift~1B/onset_s: 1 is after the run's end (0.01 s)"));
  EXPECT_FALSE(fs::exists(s.dir / "out2"));
  for (const auto& entry : fs::directory_iterator(s.dir)) {
    EXPECT_EQ(entry.path().string().find("import-tmp"), std::string::npos) << entry.path();
  }
}

TEST(ImportErrors, ShortRowsAndTooShortRuns) {
  Scratch s;
  const ImportMap map = MapOf(BaseMap());
  const std::string short_row = s.Write("short.csv", "t,q,i\n0,1,2\n0.001,1\n");
  EXPECT_THAT(ErrorOf([&] { ImportLogs({short_row}, map, {(s.dir / "o1").string(), nullptr}); }),
              ::testing::HasSubstr("short.csv: line 3, column \"i\": missing: the line has only 2 cells"));
  const std::string one = s.Write("one.csv", "t,q,i\n0,1,2\n0.001,1,2\n");
  EXPECT_THAT(ErrorOf([&] { ImportLogs({one}, map, {(s.dir / "o2").string(), nullptr}); }),
              ::testing::HasSubstr("spans less than one control period"));
  const std::string inf = s.Write("inf.csv", "t,q,i\n0,1,2\n0.001,inf,2\n");
  EXPECT_THAT(ErrorOf([&] { ImportLogs({inf}, map, {(s.dir / "o3").string(), nullptr}); }),
              ::testing::HasSubstr("inf.csv: line 3, column \"q\": NaN or infinite value"));
  EXPECT_FALSE(fs::exists(s.dir / "o1"));
}

}  // namespace
}  // namespace armfault
