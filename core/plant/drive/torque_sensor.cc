#include "core/plant/drive/torque_sensor.h"

#include <algorithm>
#include <cmath>

namespace armfault {

namespace {
double HalfRange(const TorqueSensorParams& p) { return 0.5 * p.adc_range_V; }
int MaxCode(const TorqueSensorParams& p) { return (1 << static_cast<int>(p.adc_bits)) - 1; }
}  // namespace

double TorqueSensorVoltage(const TorqueSensorParams& p, double torque_Nm, double noise_std_normal) {
  double tau = torque_Nm + p.noise_Nm * noise_std_normal;
  return HalfRange(p) + (tau - p.offset_Nm) * HalfRange(p) / p.full_scale_Nm;
}

int TorqueSensorAdcCode(const TorqueSensorParams& p, double voltage_V) {
  double v = std::clamp(voltage_V, 0.0, p.adc_range_V);
  return static_cast<int>(std::lround(v / p.adc_range_V * MaxCode(p)));
}

double TorqueFromAdcCode(const TorqueSensorParams& p, int code) {
  double v = static_cast<double>(code) * p.adc_range_V / MaxCode(p);
  return p.full_scale_Nm * (v - HalfRange(p)) / HalfRange(p) + p.offset_Nm;
}

double StuckLeadVoltage(const TorqueSensorParams& /*p*/, SensorLead lead) {
  // The 5 V supply is above the ADC range: the converter reads full scale.
  return lead == SensorLead::kSupply ? 5.0 : 0.0;
}

}  // namespace armfault
