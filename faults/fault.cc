// The shared pieces of the fault families (faults/family_support.h): the timing, the common
// JSON fields, the magnitude reader and the effect meters, plus the schedule and the recorder
// of fault.h. Dependencies go one way: the family files and registry.cc (the table of
// families) use these; nothing here calls into registry.cc or a family file.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "faults/family_support.h"

namespace armfault {

namespace {

const char* ProfileName(FaultProfile p) {
  switch (p) {
    case FaultProfile::kAbrupt: return "abrupt";
    case FaultProfile::kIncipient: return "incipient";
    case FaultProfile::kIntermittent: return "intermittent";
  }
  return "abrupt";
}

// Sums of a quantity before onset and after onset + settle.
struct Split {
  double before = 0, after = 0;
  long n_before = 0, n_after = 0;
  void Add(double t, double onset, double x) {
    if (t < onset) {
      before += x;
      ++n_before;
    } else if (t >= onset + kEffectSettle_s) {
      after += x;
      ++n_after;
    }
  }
};

constexpr long kMinSamples = 50;  // 0.1 s of ticks

class RatioMeter : public EffectMeter {
 public:
  RatioMeter(std::string measure, double onset, double nominal, double threshold,
             std::function<RatioTerms(const JointTick&)> terms)
      : measure_(std::move(measure)), onset_(onset), nominal_(nominal), threshold_(threshold), terms_(std::move(terms)) {}
  void Observe(double t, const JointTick& j) override {
    const RatioTerms r = terms_(j);
    if (!r.include) return;
    num_.Add(t, onset_, r.numerator);
    den_.Add(t, onset_, r.denominator);
  }
  FaultEffect Result() const override {
    FaultEffect e;
    e.measure = measure_;
    e.healthy = num_.n_before >= kMinSamples && den_.before != 0 ? num_.before / den_.before : nominal_;
    if (num_.n_after < kMinSamples || den_.after == 0) {
      e.faulty = e.healthy;
      e.measured = false;
      e.note = "too few informative samples after onset to measure " + measure_;
      return e;
    }
    e.faulty = num_.after / den_.after;
    e.took_effect = std::fabs(e.faulty / e.healthy - 1.0) > threshold_;
    if (!e.took_effect) e.note = measure_ + " changed by less than " + FormatNumber(100 * threshold_) + " %";
    return e;
  }

 private:
  std::string measure_;
  double onset_, nominal_, threshold_;
  std::function<RatioTerms(const JointTick&)> terms_;
  Split num_, den_;
};

class RmsMeter : public EffectMeter {
 public:
  RmsMeter(std::string measure, double onset, double factor, double margin, std::function<double(const JointTick&)> value)
      : measure_(std::move(measure)), onset_(onset), factor_(factor), margin_(margin), value_(std::move(value)) {}
  void Observe(double t, const JointTick& j) override {
    const double x = value_(j);
    sq_.Add(t, onset_, x * x);
  }
  FaultEffect Result() const override {
    FaultEffect e;
    e.measure = measure_;
    e.healthy = sq_.n_before > 0 ? std::sqrt(sq_.before / sq_.n_before) : 0.0;
    e.faulty = sq_.n_after > 0 ? std::sqrt(sq_.after / sq_.n_after) : e.healthy;
    e.took_effect = sq_.n_after > 0 && e.faulty > factor_ * e.healthy + margin_;
    e.measured = sq_.n_after > 0;
    if (!e.took_effect) e.note = measure_ + " did not rise above " + FormatNumber(factor_) + " x healthy + " + FormatNumber(margin_);
    return e;
  }

 private:
  std::string measure_;
  double onset_, factor_, margin_;
  std::function<double(const JointTick&)> value_;
  Split sq_;
};

class MeanMeter : public EffectMeter {
 public:
  MeanMeter(std::string measure, double onset, double margin, std::function<double(const JointTick&)> value)
      : measure_(std::move(measure)), onset_(onset), margin_(margin), value_(std::move(value)) {}
  void Observe(double t, const JointTick& j) override { sum_.Add(t, onset_, value_(j)); }
  FaultEffect Result() const override {
    FaultEffect e;
    e.measure = measure_;
    e.healthy = sum_.n_before > 0 ? sum_.before / sum_.n_before : 0.0;
    e.faulty = sum_.n_after > 0 ? sum_.after / sum_.n_after : e.healthy;
    e.took_effect = sum_.n_after > 0 && e.faulty > e.healthy + margin_;
    e.measured = sum_.n_after > 0;
    if (!e.took_effect) e.note = measure_ + " did not rise by more than " + FormatNumber(margin_);
    return e;
  }

 private:
  std::string measure_;
  double onset_, margin_;
  std::function<double(const JointTick&)> value_;
  Split sum_;
};

class FlatnessMeter : public EffectMeter {
 public:
  FlatnessMeter(std::string measure, double onset, double fraction, std::function<double(const JointTick&)> value)
      : measure_(std::move(measure)), onset_(onset), fraction_(fraction), value_(std::move(value)) {}
  void Observe(double t, const JointTick& j) override {
    const double x = value_(j);
    sum_.Add(t, onset_, x);
    sq_.Add(t, onset_, x * x);
  }
  FaultEffect Result() const override {
    FaultEffect e;
    e.measure = measure_;
    e.healthy = Std(sum_.before, sq_.before, sum_.n_before);
    e.faulty = Std(sum_.after, sq_.after, sum_.n_after);
    e.took_effect = sum_.n_after >= kMinSamples && e.healthy > 0 && e.faulty < fraction_ * e.healthy;
    e.measured = sum_.n_after >= kMinSamples;
    if (!e.took_effect) e.note = measure_ + " did not fall below " + FormatNumber(fraction_) + " x healthy";
    return e;
  }

 private:
  static double Std(double sum, double sq, long n) {
    if (n < 2) return 0.0;
    const double mean = sum / n;
    return std::sqrt(std::max(0.0, sq / n - mean * mean));
  }
  std::string measure_;
  double onset_, fraction_;
  std::function<double(const JointTick&)> value_;
  Split sum_, sq_;
};

class EitherMeter : public EffectMeter {
 public:
  EitherMeter(std::unique_ptr<EffectMeter> a, std::unique_ptr<EffectMeter> b) : a_(std::move(a)), b_(std::move(b)) {}
  void Observe(double t, const JointTick& j) override {
    a_->Observe(t, j);
    b_->Observe(t, j);
  }
  FaultEffect Result() const override {
    FaultEffect a = a_->Result();
    if (a.took_effect) return a;
    FaultEffect b = b_->Result();
    if (b.took_effect) return b;
    a.note += "; " + b.note;
    a.measured = a.measured || b.measured;
    return a;
  }

 private:
  std::unique_ptr<EffectMeter> a_, b_;
};

}  // namespace

double FaultTiming::Severity(double t) const {
  if (t < onset_s) return 0.0;
  switch (profile) {
    case FaultProfile::kAbrupt:
      return 1.0;
    case FaultProfile::kIncipient:
      return std::min(1.0, (t - onset_s) / ramp_s);
    case FaultProfile::kIntermittent: {
      const double phase = std::fmod(t - onset_s, period_s);
      return phase < duty * period_s ? 1.0 : 0.0;
    }
  }
  return 0.0;
}

nlohmann::json FaultEffect::ToJson() const {
  nlohmann::json j = {{"measure", measure}, {"healthy", healthy}, {"faulty", faulty}, {"took_effect", took_effect}};
  if (!took_effect) j["verdict"] = "no effect: " + note;
  j["joint_travel_rad"] = std::round(joint_travel_rad * 1e6) / 1e6;
  return j;
}

nlohmann::json Fault::ToJson() const {
  nlohmann::json j = {{"family", family_}, {"joint", joint_index_ + 1}};
  const nlohmann::json parameters = Parameters();
  for (auto it = parameters.begin(); it != parameters.end(); ++it) j[it.key()] = it.value();
  if (timing_.condition) {
    j["onset"] = timing_.condition->input;
  } else {
    j["onset_s"] = timing_.onset_s;
  }
  j["profile"] = ProfileName(timing_.profile);
  if (timing_.profile == FaultProfile::kIncipient) j["ramp_s"] = timing_.ramp_s;
  if (timing_.profile == FaultProfile::kIntermittent) {
    j["period_s"] = timing_.period_s;
    j["duty"] = timing_.duty;
  }
  return j;
}

void FaultSchedule::Apply(double t_s, std::vector<HardwareCondition>* conditions) const {
  for (HardwareCondition& c : *conditions) c = HardwareCondition{};
  for (const auto& fault : faults_) {
    const double severity = fault->timing().Severity(t_s);
    if (severity > 0.0) fault->Apply(severity, t_s, &(*conditions)[fault->joint_index()]);
  }
}

EffectRecorder::EffectRecorder(const ArmModel& model, const std::vector<std::shared_ptr<const Fault>>& faults) {
  for (const auto& fault : faults) {
    joints_.push_back(fault->joint_index());
    onsets_s_.push_back(fault->timing().onset_s);
    travel_rad_.push_back(0.0);
    meters_.push_back(fault->MakeEffectMeter(model.joint(fault->joint_index())));
  }
}

void EffectRecorder::Observe(const Tick& tick) {
  const double dt_s = last_t_s_ < 0 ? 0.0 : tick.t_s - last_t_s_;
  last_t_s_ = tick.t_s;
  for (size_t k = 0; k < meters_.size(); ++k) {
    const JointTick& joint = (*tick.joints)[joints_[k]];
    meters_[k]->Observe(tick.t_s, joint);
    if (tick.t_s >= onsets_s_[k]) travel_rad_[k] += std::fabs(joint.signals.qd_ref_rad_s) * dt_s;
  }
}

std::vector<FaultEffect> EffectRecorder::Results() const {
  std::vector<FaultEffect> out;
  for (size_t k = 0; k < meters_.size(); ++k) {
    out.push_back(meters_[k]->Result());
    out.back().joint_travel_rad = travel_rad_[k];
  }
  return out;
}

int ReadJointIndex(ObjectReader& reader, const RobotConfig& robot) {
  const int n = static_cast<int>(robot.modules.size());
  const int joint = reader.RequireInt("joint");
  if (joint < 1 || joint > n) {
    throw InputError("", reader.PointerTo("joint"),
                     "joint " + std::to_string(joint) + " does not exist: robot " + robot.name + " has joints 1.." +
                         std::to_string(n));
  }
  return joint - 1;
}

FaultCommon ReadFaultCommon(ObjectReader& reader, const RobotConfig& robot, std::initializer_list<const char*> own_keys,
                            ErrorList* errors) {
  std::vector<std::string> keys = {"family", "joint", "onset_s", "onset", "profile", "ramp_s", "period_s", "duty"};
  for (const char* k : own_keys) keys.push_back(k);
  errors->Try([&] { reader.AllowOnly(keys); });
  FaultCommon c;
  errors->Try([&] {
    if (reader.ShouldRead("joint")) c.joint_index = ReadJointIndex(reader, robot);
  });
  errors->Try([&] {
    reader.OptionalNumber("onset_s", &c.timing.onset_s);
    RequireAtLeast(c.timing.onset_s, 0.0, reader.PointerTo("onset_s"));
  });
  // A conditional onset: a condition on the plant's truth instead of a time (onset_condition.h).
  if (reader.Has("onset")) {
    errors->Try([&] {
      if (reader.Has("onset_s")) {
        throw InputError("", reader.PointerTo("onset"),
                         "give either onset_s (a time) or onset (a condition), not both (" + reader.PointerTo("onset_s") +
                             " is given too)");
      }
      c.timing.condition =
          std::make_shared<const OnsetCondition>(ReadOnsetCondition(*reader.Find("onset"), reader.PointerTo("onset"), robot));
      c.timing.onset_s = std::numeric_limits<double>::infinity();  // until it fires
    });
  }
  std::string profile = "abrupt";
  const bool profile_ok = errors->Try([&] {
    reader.OptionalString("profile", &profile);
    if (profile == "abrupt") {
      c.timing.profile = FaultProfile::kAbrupt;
    } else if (profile == "incipient") {
      c.timing.profile = FaultProfile::kIncipient;
    } else if (profile == "intermittent") {
      c.timing.profile = FaultProfile::kIntermittent;
    } else {
      throw InputError("", reader.PointerTo("profile"),
                       "unknown profile \"" + profile + "\" (known: abrupt, incipient, intermittent)");
    }
  });
  // Keys of other profiles are refused rather than ignored: they would not do what they say.
  // Which keys apply needs a known profile; with an unknown one their values are still checked.
  const bool incipient = c.timing.profile == FaultProfile::kIncipient;
  const bool intermittent = c.timing.profile == FaultProfile::kIntermittent;
  auto applies = [&](const char* key) {
    const bool allowed = std::string(key) == "ramp_s" ? incipient : intermittent;
    if (!profile_ok || !reader.Has(key) || allowed) return true;
    errors->Add(InputError("", reader.PointerTo(key), std::string(key) + " does not apply to the " + profile + " profile"));
    return false;
  };
  if (applies("ramp_s")) {
    errors->Try([&] {
      reader.OptionalNumber("ramp_s", &c.timing.ramp_s);
      RequireAbove(c.timing.ramp_s, 0.0, reader.PointerTo("ramp_s"));
    });
  }
  if (applies("period_s")) {
    errors->Try([&] {
      reader.OptionalNumber("period_s", &c.timing.period_s);
      RequireAbove(c.timing.period_s, 0.0, reader.PointerTo("period_s"));
    });
  }
  if (applies("duty")) {
    errors->Try([&] {
      reader.OptionalNumber("duty", &c.timing.duty);
      RequireInRange(c.timing.duty, 0.0, 1.0, reader.PointerTo("duty"));
      RequireAbove(c.timing.duty, 0.0, reader.PointerTo("duty"));
    });
  }
  return c;
}

void ReadMagnitude(ObjectReader& reader, const FaultMagnitudeSpec& magnitude, double* value, bool required) {
  if (*magnitude.key == '\0') throw std::logic_error(std::string(magnitude.family) + " has no magnitude");
  const FaultMagnitudeRange& r = magnitude.range;
  const std::string key = magnitude.key;
  if (required ? !reader.ShouldRead(key) : !reader.Has(key)) return;
  const double x = reader.RequireNumber(key);
  if (r.min_exclusive) RequireAbove(x, r.min, reader.PointerTo(key));
  RequireInRange(x, r.min, r.max, reader.PointerTo(key));
  if (r.zero_excluded && x == 0.0) throw InputError("", reader.PointerTo(key), "0 is no change");
  *value = x;
}

std::unique_ptr<EffectMeter> MakeRatioMeter(std::string measure, double onset_s, double nominal, double threshold,
                                            std::function<RatioTerms(const JointTick&)> terms) {
  return std::make_unique<RatioMeter>(std::move(measure), onset_s, nominal, threshold, std::move(terms));
}
std::unique_ptr<EffectMeter> MakeRmsMeter(std::string measure, double onset_s, double factor, double margin,
                                          std::function<double(const JointTick&)> value) {
  return std::make_unique<RmsMeter>(std::move(measure), onset_s, factor, margin, std::move(value));
}
std::unique_ptr<EffectMeter> MakeFlatnessMeter(std::string measure, double onset_s, double fraction,
                                               std::function<double(const JointTick&)> value) {
  return std::make_unique<FlatnessMeter>(std::move(measure), onset_s, fraction, std::move(value));
}
std::unique_ptr<EffectMeter> MakeEitherMeter(std::unique_ptr<EffectMeter> first, std::unique_ptr<EffectMeter> second) {
  return std::make_unique<EitherMeter>(std::move(first), std::move(second));
}
std::unique_ptr<EffectMeter> MakeMeanMeter(std::string measure, double onset_s, double margin,
                                           std::function<double(const JointTick&)> value) {
  return std::make_unique<MeanMeter>(std::move(measure), onset_s, margin, std::move(value));
}

}  // namespace armfault
