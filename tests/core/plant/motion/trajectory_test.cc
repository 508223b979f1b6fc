#include "core/plant/motion/trajectory.h"

#include "core/base/json_input.h"
#include "tests/core/test_support.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace armfault {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::HasSubstr;
using testing::Not;

constexpr double kPi = 3.14159265358979323846;
double Rad(double deg) { return deg * (kPi / 180.0); }

InputContext JsonContext() {
  InputContext ctx;
  ctx.source = "experiment.json";
  return ctx;
}

std::unique_ptr<Trajectory> Make(const json& spec, const InputContext& ctx = JsonContext()) {
  return MakeTrajectory(spec, "/joints/3", ctx);
}

// The InputError that building `spec` throws (a test failure if none is thrown).
InputError ErrorOf(const json& spec, const InputContext& ctx = JsonContext()) {
  try {
    Make(spec, ctx);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no InputError for " << spec.dump();
  return InputError("", "", "");
}

// Analytic velocity and acceleration must equal central differences of At(); times
// closer than 10 steps to a point in `skip` (where acceleration may jump) are left out.
void ExpectDerivativesMatchFiniteDifferences(const Trajectory& traj, double t_end,
                                             const std::vector<double>& skip = {}) {
  constexpr double h = 1e-6;
  int checked = 0;
  for (double t = 0.0137; t < t_end; t += 0.0731) {
    bool near_skip = false;
    for (double s : skip) near_skip = near_skip || std::fabs(t - s) < 10 * h;
    if (near_skip) continue;
    const TrajectoryPoint here = traj.At(t), before = traj.At(t - h), after = traj.At(t + h);
    const double fd_qd = (after.q_rad - before.q_rad) / (2 * h);
    const double fd_qdd = (after.qd_rad_s - before.qd_rad_s) / (2 * h);
    EXPECT_NEAR(here.qd_rad_s, fd_qd, 1e-6 * (1 + std::fabs(fd_qd))) << traj.type() << " t=" << t;
    EXPECT_NEAR(here.qdd_rad_s2, fd_qdd, 1e-6 * (1 + std::fabs(fd_qdd)))
        << traj.type() << " t=" << t;
    ++checked;
  }
  EXPECT_GT(checked, 10);
}

// ---------------------------------------------------------------- registry

TEST(TrajectoryRegistry, ListsTypesInTableOrder) {
  EXPECT_THAT(TrajectoryTypeNames(),
              testing::ElementsAre("sine_pair", "cosine_ramp", "min_jerk", "hold", "csv"));
}

TEST(TrajectoryRegistry, EachAnalyticTypeReportsItsOwnName) {
  const json specs[] = {
      {{"type", "sine_pair"}, {"amplitude_deg", 25}, {"omega_rad_s", 1}},
      {{"type", "cosine_ramp"}, {"amplitude_deg", 10}, {"period_s", 2}},
      {{"type", "min_jerk"}, {"waypoints", {{0, 0}}}},
      {{"type", "hold"}},
  };
  for (const json& spec : specs) {
    EXPECT_EQ(Make(spec)->type(), spec["type"].get<std::string>());
  }
}

// ---------------------------------------------------------------- sine_pair

TEST(SinePair, ThesisExperimentOneValues) {
  const double a = 25.0, w = 8.0 / (2.0 * kPi), offset = 5.0;
  auto traj = Make({{"type", "sine_pair"}, {"amplitude_deg", a}, {"omega_rad_s", w},
                    {"offset_deg", offset}});
  // t = 0: at the offset, at rest.
  EXPECT_DOUBLE_EQ(traj->At(0).q_rad, Rad(offset));
  EXPECT_DOUBLE_EQ(traj->At(0).qd_rad_s, 0.0);
  EXPECT_DOUBLE_EQ(traj->At(0).qdd_rad_s2, 0.0);
  // t = pi/(2w): sin = 1, sin(2wt) = sin(pi) = 0.
  const TrajectoryPoint p = traj->At(kPi / (2 * w));
  EXPECT_NEAR(p.q_rad, Rad(offset + a), 1e-12);
  EXPECT_NEAR(p.qd_rad_s, Rad(a) * w, 1e-12);           // cos = 0, cos(pi) = -1
  EXPECT_NEAR(p.qdd_rad_s2, -Rad(a) * w * w, 1e-12);    // -sin = -1, 2 sin(pi) = 0
  // t = pi/w: q back at the offset, velocity -2 A w.
  EXPECT_NEAR(traj->At(kPi / w).q_rad, Rad(offset), 1e-12);
  EXPECT_NEAR(traj->At(kPi / w).qd_rad_s, -2 * Rad(a) * w, 1e-12);
}

TEST(SinePair, OffsetDefaultsToZero) {
  auto traj = Make({{"type", "sine_pair"}, {"amplitude_deg", 25}, {"omega_rad_s", 2}});
  EXPECT_DOUBLE_EQ(traj->At(0).q_rad, 0.0);
  EXPECT_NEAR(traj->At(kPi / 4).q_rad, Rad(25), 1e-12);
}

TEST(SinePair, DerivativesMatchFiniteDifferences) {
  auto traj = Make({{"type", "sine_pair"}, {"amplitude_deg", 25}, {"omega_rad_s", 1.2732},
                    {"offset_deg", -10}});
  ExpectDerivativesMatchFiniteDifferences(*traj, 6.0);
}

// ---------------------------------------------------------------- cosine_ramp

TEST(CosineRamp, ValuesAtQuarterAndHalfPeriod) {
  const double a = 10.0, period = 2.0, offset = -3.0, w = 2 * kPi / period;
  auto traj = Make({{"type", "cosine_ramp"}, {"amplitude_deg", a}, {"period_s", period},
                    {"offset_deg", offset}});
  EXPECT_DOUBLE_EQ(traj->At(0).q_rad, Rad(offset));
  EXPECT_DOUBLE_EQ(traj->At(0).qd_rad_s, 0.0);
  EXPECT_NEAR(traj->At(0).qdd_rad_s2, Rad(a) * w * w, 1e-12);
  EXPECT_NEAR(traj->At(0.5).q_rad, Rad(offset + a), 1e-12);
  EXPECT_NEAR(traj->At(0.5).qd_rad_s, Rad(a) * w, 1e-12);
  EXPECT_NEAR(traj->At(1.0).q_rad, Rad(offset + 2 * a), 1e-12);
  EXPECT_NEAR(traj->At(1.0).qd_rad_s, 0.0, 1e-12);
  EXPECT_NEAR(traj->At(1.0).qdd_rad_s2, -Rad(a) * w * w, 1e-12);
}

TEST(CosineRamp, DerivativesMatchFiniteDifferences) {
  auto traj = Make({{"type", "cosine_ramp"}, {"amplitude_deg", 30}, {"period_s", 1.7}});
  ExpectDerivativesMatchFiniteDifferences(*traj, 4.0);
}

// ---------------------------------------------------------------- min_jerk

TEST(MinJerk, HitsWaypointsAtRestAndHoldsOutside) {
  auto traj = Make({{"type", "min_jerk"}, {"waypoints", {{0.5, 10}, {1.5, 40}, {2.0, -20}}}});
  const double times[] = {0.5, 1.5, 2.0}, angles[] = {10, 40, -20};
  for (int i = 0; i < 3; ++i) {
    const TrajectoryPoint p = traj->At(times[i]);
    EXPECT_DOUBLE_EQ(p.q_rad, Rad(angles[i])) << "waypoint " << i;
    EXPECT_DOUBLE_EQ(p.qd_rad_s, 0.0) << "waypoint " << i;
    EXPECT_DOUBLE_EQ(p.qdd_rad_s2, 0.0) << "waypoint " << i;
  }
  // Before the first waypoint and after the last: held, at rest.
  EXPECT_DOUBLE_EQ(traj->At(0.0).q_rad, Rad(10));
  EXPECT_DOUBLE_EQ(traj->At(0.0).qd_rad_s, 0.0);
  EXPECT_DOUBLE_EQ(traj->At(7.0).q_rad, Rad(-20));
  EXPECT_DOUBLE_EQ(traj->At(7.0).qd_rad_s, 0.0);
  EXPECT_DOUBLE_EQ(traj->At(7.0).qdd_rad_s2, 0.0);
}

TEST(MinJerk, SegmentMidpointIsHalfwayAtPeakVelocity) {
  // s(1/2) = 1/2, ds/dtau(1/2) = 30/16 = 1.875, d2s/dtau2(1/2) = 0.
  auto traj = Make({{"type", "min_jerk"}, {"waypoints", {{0, 0}, {2, 60}}}});
  const TrajectoryPoint p = traj->At(1.0);
  EXPECT_NEAR(p.q_rad, Rad(30), 1e-12);
  EXPECT_NEAR(p.qd_rad_s, Rad(60) * 1.875 / 2.0, 1e-12);
  EXPECT_NEAR(p.qdd_rad_s2, 0.0, 1e-12);
  // Monotonic between waypoints: no overshoot.
  for (double t = 0; t <= 2.0; t += 0.01) EXPECT_GE(traj->At(t).qd_rad_s, 0.0) << t;
}

TEST(MinJerk, SingleWaypointIsConstant) {
  auto traj = Make({{"type", "min_jerk"}, {"waypoints", {{1.0, 12}}}});
  for (double t : {0.0, 1.0, 3.0}) {
    EXPECT_DOUBLE_EQ(traj->At(t).q_rad, Rad(12));
    EXPECT_DOUBLE_EQ(traj->At(t).qd_rad_s, 0.0);
  }
}

TEST(MinJerk, DerivativesMatchFiniteDifferences) {
  // Waypoints included on purpose: velocity and acceleration are continuous across them.
  auto traj = Make({{"type", "min_jerk"}, {"waypoints", {{0.2, 0}, {1.0, 45}, {1.4, -30}, {3, 5}}}});
  ExpectDerivativesMatchFiniteDifferences(*traj, 4.0);
}

// ---------------------------------------------------------------- hold

TEST(Hold, ConstantAtRest) {
  auto traj = Make({{"type", "hold"}, {"angle_deg", -42.5}});
  for (double t : {0.0, 0.3, 100.0}) {
    EXPECT_DOUBLE_EQ(traj->At(t).q_rad, Rad(-42.5));
    EXPECT_DOUBLE_EQ(traj->At(t).qd_rad_s, 0.0);
    EXPECT_DOUBLE_EQ(traj->At(t).qdd_rad_s2, 0.0);
  }
  EXPECT_DOUBLE_EQ(Make({{"type", "hold"}})->At(1.0).q_rad, 0.0);
  ExpectDerivativesMatchFiniteDifferences(*traj, 2.0);
}

// ---------------------------------------------------------------- SampleMotion

TEST(SampleMotion, FindsExtremaOfCosineRamp) {
  auto traj = Make({{"type", "cosine_ramp"}, {"amplitude_deg", 10}, {"period_s", 2},
                    {"offset_deg", 5}});
  const MotionEnvelope r = SampleMotion(*traj, 2.0);
  EXPECT_DOUBLE_EQ(r.min_rad, Rad(5));
  EXPECT_NEAR(r.max_rad, Rad(25), 1e-12);  // t = 1.0 is a 1 ms sample
}

TEST(SampleMotion, IncludesTheEndBetweenSamples) {
  // Rising ramp: the maximum over [0, 0.0015] is at 0.0015, between 1 ms samples.
  auto traj = Make({{"type", "min_jerk"}, {"waypoints", {{0, 0}, {1, 90}}}});
  EXPECT_DOUBLE_EQ(SampleMotion(*traj, 0.0015).max_rad, traj->At(0.0015).q_rad);
  EXPECT_DOUBLE_EQ(SampleMotion(*traj, 0.0015).min_rad, 0.0);
  const MotionEnvelope at_start = SampleMotion(*traj, 0.0);
  EXPECT_DOUBLE_EQ(at_start.min_rad, 0.0);
  EXPECT_DOUBLE_EQ(at_start.max_rad, 0.0);
}

// ---------------------------------------------------------------- csv

class CsvTrajectory : public testing::Test {
 protected:
  // Writes `text` to dir_/name; returns the full path.
  std::string Write(const std::string& name, const std::string& text) { return scratch_.Write(name, text); }
  InputContext Context() const {
    InputContext ctx;
    ctx.source = "experiment.json";
    ctx.base_dir = dir_.string();
    return ctx;
  }
  std::unique_ptr<Trajectory> MakeFrom(const std::string& text) {
    Write("traj.csv", text);
    return Make({{"type", "csv"}, {"path", "traj.csv"}}, Context());
  }
  InputError ErrorFrom(const std::string& text) {
    Write("traj.csv", text);
    return ErrorOf({{"type", "csv"}, {"path", "traj.csv"}}, Context());
  }
  testing_support::ScratchDir scratch_{"armfault_trajectory_test"};
  const fs::path& dir_ = scratch_.path();
};

TEST_F(CsvTrajectory, ReproducesRowsWithHeaderCommentsBlanksAndWhitespace) {
  auto traj = MakeFrom(
      "time_s,angle_deg\r\n"
      "# recorded 2024-01-01\r\n"
      "0.2, 0\r\n"
      "\r\n"
      "  0.5 ,10\r\n"
      "1.0,\t30\r\n"
      "2.0,20\r\n");
  EXPECT_STREQ(traj->type(), "csv");
  const double times[] = {0.2, 0.5, 1.0, 2.0}, angles[] = {0, 10, 30, 20};
  for (int i = 0; i < 4; ++i) EXPECT_DOUBLE_EQ(traj->At(times[i]).q_rad, Rad(angles[i])) << i;
  // Held before the first and after the last row, at rest.
  EXPECT_DOUBLE_EQ(traj->At(0.0).q_rad, 0.0);
  EXPECT_DOUBLE_EQ(traj->At(0.0).qd_rad_s, 0.0);
  EXPECT_DOUBLE_EQ(traj->At(5.0).q_rad, Rad(20));
  EXPECT_DOUBLE_EQ(traj->At(5.0).qd_rad_s, 0.0);
  EXPECT_DOUBLE_EQ(traj->At(5.0).qdd_rad_s2, 0.0);
}

TEST_F(CsvTrajectory, VelocityIsContinuousAndEqualsCatmullRomSlopeAtRows) {
  auto traj = MakeFrom("0,0\n0.5,10\n1.0,30\n2.0,20\n");
  const double eps = 1e-9;
  const double rows[] = {0.5, 1.0};
  for (double t : rows) {
    EXPECT_NEAR(traj->At(t - eps).q_rad, traj->At(t + eps).q_rad, 1e-7) << t;
    EXPECT_NEAR(traj->At(t - eps).qd_rad_s, traj->At(t + eps).qd_rad_s, 1e-6) << t;
  }
  EXPECT_NEAR(traj->At(0.5).qd_rad_s, Rad(30 - 0) / (1.0 - 0.0), 1e-12);
  EXPECT_NEAR(traj->At(1.0).qd_rad_s, Rad(20 - 10) / (2.0 - 0.5), 1e-12);
  // One-sided slopes at the ends.
  EXPECT_NEAR(traj->At(0.0).qd_rad_s, Rad(10) / 0.5, 1e-12);
  EXPECT_NEAR(traj->At(2.0).qd_rad_s, Rad(-10) / 1.0, 1e-12);
}

TEST_F(CsvTrajectory, ReproducesLinesAndInteriorQuadraticsExactly) {
  // Linear data (uneven spacing): the spline is that line everywhere in the span.
  auto line = MakeFrom("0,1\n0.3,4\n1.0,11\n1.1,12\n");
  for (double t = 0.0; t <= 1.1; t += 0.01) {
    EXPECT_NEAR(line->At(t).q_rad, Rad(1 + 10 * t), 1e-12) << t;
    EXPECT_NEAR(line->At(t).qd_rad_s, Rad(10), 1e-11) << t;
  }
  // q = t^2 on an even grid: central differences are exact, so interior segments are too.
  auto parabola = MakeFrom("0,0\n1,1\n2,4\n3,9\n4,16\n");
  for (double t = 1.0; t <= 3.0; t += 0.05) {
    EXPECT_NEAR(parabola->At(t).q_rad, Rad(t * t), 1e-12) << t;
    EXPECT_NEAR(parabola->At(t).qd_rad_s, Rad(2 * t), 1e-12) << t;
    EXPECT_NEAR(parabola->At(t).qdd_rad_s2, Rad(2), 1e-11) << t;
  }
}

TEST_F(CsvTrajectory, DerivativesMatchFiniteDifferences) {
  auto traj = MakeFrom("0,0\n0.5,10\n0.8,-5\n1.6,30\n2.0,20\n");
  // Acceleration jumps at rows; velocity jumps at the end of the span.
  ExpectDerivativesMatchFiniteDifferences(*traj, 3.0, {0.0, 0.5, 0.8, 1.6, 2.0});
}

TEST_F(CsvTrajectory, AbsolutePathIgnoresBaseDir) {
  const std::string path = Write("abs.csv", "0,0\n1,10\n");
  InputContext ctx = Context();
  ctx.base_dir = "/nonexistent";
  EXPECT_DOUBLE_EQ(Make({{"type", "csv"}, {"path", path}}, ctx)->At(1.0).q_rad, Rad(10));
}

TEST_F(CsvTrajectory, MalformedLineNamesFileAndLineNumber) {
  const InputError e = ErrorFrom("time_s,angle_deg\n0,0\n0.5;12\n1,3\n");
  // The campaign (or run) file and the key that names the CSV file, then the CSV file's line.
  EXPECT_EQ(e.source(), "experiment.json");
  EXPECT_EQ(e.pointer(), "/joints/3/path");
  EXPECT_THAT(e.what(), HasSubstr("experiment.json: /joints/3/path: CSV file \"" + (dir_ / "traj.csv").string() +
                                  "\" (resolved from \"traj.csv\"): line 3: expected 2 numbers \"time_s,angle_deg\", got 1 field"));
  // The file's text is never echoed (a path may name any file): line and column instead.
  EXPECT_THAT(e.what(), Not(HasSubstr("0.5;12")));
}

TEST_F(CsvTrajectory, BadFieldsAreNamed) {
  EXPECT_THAT(ErrorFrom("0,0\n1,abc\n").what(), HasSubstr("line 2: expected 2 numbers"));
  EXPECT_THAT(ErrorFrom("0,0\n1,abc\n").what(), HasSubstr("field 2 (column 3) is not a number"));
  EXPECT_THAT(ErrorFrom("0,0\n1,abc\n").what(), Not(HasSubstr("abc")));
  EXPECT_THAT(ErrorFrom("0,0\n1, nan\n").what(), HasSubstr("field 2 (column 4) is not a finite number"));
  EXPECT_THAT(ErrorFrom("0,0\nx1e999,1\n").what(), HasSubstr("field 1 (column 1) is not a number"));
  EXPECT_THAT(ErrorFrom("0,0\n1,1e999\n").what(), HasSubstr("field 2 (column 3) is not a finite number"));
  EXPECT_THAT(ErrorFrom("0,0\n1,2,3\n").what(), HasSubstr("line 2: expected 2 numbers"));
  EXPECT_THAT(ErrorFrom("0,0\n1,1,5\n").what(), HasSubstr("got 3 fields"));  // decimal comma
  // A header is allowed on the first line with content only.
  EXPECT_THAT(ErrorFrom("0,0\ntime_s,angle_deg\n1,1\n").what(),
              HasSubstr("line 2: expected 2 numbers"));
  // A first line with one number is a broken row, not a header.
  EXPECT_THAT(ErrorFrom("0,x\n1,1\n2,2\n").what(), HasSubstr("line 1:"));
}

TEST_F(CsvTrajectory, OnlyARegularFileOfBoundedSizeIsRead) {
  // A device never ends (/dev/zero) and is not a trajectory; neither is a fifo.
  const InputError dev = ErrorOf({{"type", "csv"}, {"path", "/dev/zero"}}, Context());
  EXPECT_EQ(dev.pointer(), "/joints/3/path");
  EXPECT_THAT(dev.message(), HasSubstr("CSV file \"/dev/zero\" is not a regular file"));
  // Larger than 64 MiB: refused after reading that much, whatever the file system says.
  const std::string big = (dir_ / "big.csv").string();
  {
    std::ofstream out(big, std::ios::binary);
    const std::string row = "0,0\n";
    for (size_t n = 0; n <= (size_t{64} << 20) / row.size(); ++n) out << row;
  }
  const InputError e = ErrorOf({{"type", "csv"}, {"path", big}}, Context());
  EXPECT_THAT(e.message(), HasSubstr("is larger than 64 MiB"));
}

TEST_F(CsvTrajectory, TimesMustStrictlyIncrease) {
  const InputError e = ErrorFrom("# t, q\n0,0\n1,10\n1,20\n");
  EXPECT_EQ(e.pointer(), "/joints/3/path");
  EXPECT_THAT(e.message(), HasSubstr("traj.csv\"): line 4: "));
  EXPECT_THAT(e.message(), HasSubstr("time 1 s is not after the previous row's time 1 s (line 3)"));
}

TEST_F(CsvTrajectory, NeedsTwoRows) {
  const InputError e = ErrorFrom("time_s,angle_deg\n0,0\n");
  EXPECT_EQ(e.source(), "experiment.json");
  EXPECT_EQ(e.pointer(), "/joints/3/path");
  EXPECT_THAT(e.message(), HasSubstr("has 1 data row(s); at least 2 are needed"));
}

TEST_F(CsvTrajectory, MissingFileNamesPathAndJsonPointer) {
  const InputError e = ErrorOf({{"type", "csv"}, {"path", "nope.csv"}}, Context());
  EXPECT_EQ(e.source(), "experiment.json");
  EXPECT_EQ(e.pointer(), "/joints/3/path");
  EXPECT_THAT(e.what(), HasSubstr("experiment.json: /joints/3/path: CSV file"));
  EXPECT_THAT(e.message(), HasSubstr((dir_ / "nope.csv").string()));
  EXPECT_THAT(e.message(), HasSubstr("does not exist"));
}

// ---------------------------------------------------------------- JSON errors

TEST(TrajectoryErrors, UnknownTypeListsKnownTypes) {
  const InputError e = ErrorOf({{"type", "sine_par"}, {"amplitude_deg", 25}});
  EXPECT_EQ(e.source(), "experiment.json");
  EXPECT_EQ(e.pointer(), "/joints/3/type");
  EXPECT_THAT(e.message(), HasSubstr("unknown trajectory type \"sine_par\""));
  EXPECT_THAT(e.message(), HasSubstr("sine_pair, cosine_ramp, min_jerk, hold, csv"));
}

TEST(TrajectoryErrors, MissingOrWrongTypedType) {
  EXPECT_EQ(ErrorOf({{"angle_deg", 1}}).pointer(), "/joints/3/type");
  EXPECT_THAT(ErrorOf({{"angle_deg", 1}}).message(), HasSubstr("known types: sine_pair"));
  EXPECT_THAT(ErrorOf({{"type", 3}}).message(), HasSubstr("expected a string"));
  EXPECT_THAT(ErrorOf(json::array()).message(), HasSubstr("expected an object"));
}

TEST(TrajectoryErrors, UnknownKeyReportedAtItsPointerEvenIfARequiredKeyIsMissing) {
  // The misspelt key is the user's actual mistake, not the "missing" amplitude_deg.
  const InputError e =
      ErrorOf({{"type", "sine_pair"}, {"amplitud_deg", 25}, {"omega_rad_s", 1.27}});
  EXPECT_EQ(e.pointer(), "/joints/3/amplitud_deg");
  EXPECT_THAT(e.what(), HasSubstr("experiment.json: /joints/3/amplitud_deg: unknown key"));
  // Every type rejects unknown keys.
  EXPECT_EQ(ErrorOf({{"type", "hold"}, {"angle", 3}}).pointer(), "/joints/3/angle");
  EXPECT_EQ(ErrorOf({{"type", "cosine_ramp"}, {"amplitude_deg", 1}, {"period_s", 1},
                     {"phase", 0}}).pointer(),
            "/joints/3/phase");
  EXPECT_EQ(ErrorOf({{"type", "min_jerk"}, {"waypoints", {{0, 0}}}, {"x", 0}}).pointer(),
            "/joints/3/x");
  EXPECT_EQ(ErrorOf({{"type", "csv"}, {"path", "a.csv"}, {"sep", ";"}}).pointer(),
            "/joints/3/sep");
}

TEST(TrajectoryErrors, MissingWrongTypedAndOutOfRangeValues) {
  EXPECT_EQ(ErrorOf({{"type", "sine_pair"}, {"omega_rad_s", 1}}).pointer(),
            "/joints/3/amplitude_deg");
  EXPECT_THAT(ErrorOf({{"type", "sine_pair"}, {"omega_rad_s", 1}}).message(),
              HasSubstr("missing"));
  EXPECT_THAT(ErrorOf({{"type", "sine_pair"}, {"amplitude_deg", "25"}, {"omega_rad_s", 1}})
                  .message(),
              HasSubstr("expected a number"));
  const InputError omega = ErrorOf({{"type", "sine_pair"}, {"amplitude_deg", 25}, {"omega_rad_s", 0}});
  EXPECT_EQ(omega.pointer(), "/joints/3/omega_rad_s");
  EXPECT_EQ(ErrorOf({{"type", "cosine_ramp"}, {"amplitude_deg", 1}, {"period_s", -1}}).pointer(),
            "/joints/3/period_s");
  EXPECT_EQ(ErrorOf({{"type", "hold"}, {"angle_deg", nullptr}}).pointer(), "/joints/3/angle_deg");
  EXPECT_EQ(ErrorOf({{"type", "csv"}, {"path", ""}}).pointer(), "/joints/3/path");
}

TEST(TrajectoryErrors, WaypointTimesMustStrictlyIncrease) {
  const InputError e =
      ErrorOf({{"type", "min_jerk"}, {"waypoints", {{0, 0}, {1, 10}, {1, 20}}}});
  EXPECT_EQ(e.source(), "experiment.json");
  EXPECT_EQ(e.pointer(), "/joints/3/waypoints/2/0");
  EXPECT_THAT(e.message(), HasSubstr("not after the previous one"));
  EXPECT_EQ(ErrorOf({{"type", "min_jerk"}, {"waypoints", {{0, 0}, {2, 10}, {1, 20}}}}).pointer(),
            "/joints/3/waypoints/2/0");
}

TEST(TrajectoryErrors, MalformedWaypoints) {
  EXPECT_EQ(ErrorOf({{"type", "min_jerk"}, {"waypoints", json::array()}}).pointer(),
            "/joints/3/waypoints");
  EXPECT_EQ(ErrorOf({{"type", "min_jerk"}, {"waypoints", {{0, 0}, {1, 2, 3}}}}).pointer(),
            "/joints/3/waypoints/1");
  EXPECT_EQ(ErrorOf({{"type", "min_jerk"}, {"waypoints", {{0, 0}, {1, "x"}}}}).pointer(),
            "/joints/3/waypoints/1/1");
  const InputError negative = ErrorOf({{"type", "min_jerk"}, {"waypoints", {{-1, 0}}}});
  EXPECT_EQ(negative.pointer(), "/joints/3/waypoints/0/0");
  EXPECT_THAT(negative.message(), HasSubstr("below the minimum 0"));
}

}  // namespace
}  // namespace armfault
