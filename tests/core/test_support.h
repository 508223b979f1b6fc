// Shared helpers for the core tests.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/base/json_input.h"
#include "core/plant/simulation.h"

namespace armfault::testing_support {

// The text of each error an InputError holds ("source: /pointer: message"), in order.
inline std::vector<std::string> ErrorTexts(const InputError& e) {
  std::vector<std::string> out;
  for (const InputError& one : e.errors()) out.push_back(one.text());
  return out;
}

// Runs `f`, which must throw an InputError, and returns it (a test failure if it does not).
template <class F>
InputError ErrorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no InputError thrown";
  return InputError("", "", "");
}

// The whole file as bytes ("" if it cannot be read).
inline std::string ReadAll(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The lines of `text`, without their line ends.
inline std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

// A fresh directory for one test, removed with everything in it at the end.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& prefix) {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    path_ = std::filesystem::temp_directory_path() / (prefix + "_" + std::to_string(getpid()) + "_" + test);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  // Writes `text` to <dir>/name; returns the full path.
  std::string Write(const std::string& name, const std::string& text) const {
    const std::filesystem::path path = path_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path.string();
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// A hardware condition applied to one joint (0-based) from t = 0: the simplest fault.
class ConstantCondition : public HardwareSchedule {
 public:
  ConstantCondition(int joint, HardwareCondition condition) : joint_(joint), condition_(condition) {}
  void Apply(double, std::vector<HardwareCondition>* conditions) const override {
    (*conditions)[joint_] = condition_;
  }

 private:
  int joint_;
  HardwareCondition condition_;
};

// All ticks of a run, copied.
struct Recording {
  std::vector<double> t;
  std::vector<std::vector<JointTick>> ticks;
  TickObserver Observer() {
    return [this](const Tick& tick) {
      t.push_back(tick.t_s);
      ticks.push_back(*tick.joints);
    };
  }
};

// A run of the ur-class arm on campaigns/files/ur-class.json's "sweep" motion (every joint moving).
inline nlohmann::json UrClassSweepRun(double duration_s) {
  return {{"robot", "ur-class"},
          {"duration_s", duration_s},
          {"joints",
           {{"1", {{"type", "sine_pair"}, {"amplitude_deg", 30}, {"omega_rad_s", 1.1}}},
            {"2", {{"type", "cosine_ramp"}, {"amplitude_deg", 25}, {"period_s", 4}}},
            {"3", {{"type", "sine_pair"}, {"amplitude_deg", 25}, {"omega_rad_s", 1.2732}}},
            {"4", {{"type", "sine_pair"}, {"amplitude_deg", 35}, {"omega_rad_s", 1.5}}},
            {"5", {{"type", "cosine_ramp"}, {"amplitude_deg", 30}, {"period_s", 3}}},
            {"6", {{"type", "sine_pair"}, {"amplitude_deg", 45}, {"omega_rad_s", 2.0}}}}}};
}

}  // namespace armfault::testing_support
