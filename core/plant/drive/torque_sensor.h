// Joint torque sensor chain: strain gauges on the harmonic-drive output -> amplifier (gain,
// offset, noise) -> 12-bit ADC over [0, adc_range_V] -> the controller's linear mapping back
// to N m (thesis: tau = 28 (V - 1.5)/1.5 + 3.5077).
// Inputs: transmitted torque [N m, link side], a standard-normal noise sample, the lead
// condition. Outputs: amplifier voltage [V], ADC code, reading [N m].
#pragma once

#include "core/plant/parts/hardware_condition.h"
#include "core/plant/robot/robot_config.h"

namespace armfault {

// Amplifier output voltage for a true torque, before the ADC (no clipping).
double TorqueSensorVoltage(const TorqueSensorParams& p, double torque_Nm, double noise_std_normal);
// ADC code of a voltage: clipped to the converter's range, rounded to the nearest step.
int TorqueSensorAdcCode(const TorqueSensorParams& p, double voltage_V);
// The controller's mapping from ADC code to N m.
double TorqueFromAdcCode(const TorqueSensorParams& p, int code);
// Voltage seen by the ADC when a lead is shorted: to the supply (positive rail beyond the ADC
// range -> full scale) or to ground (0 V). Only valid for kSupply and kGround.
double StuckLeadVoltage(const TorqueSensorParams& p, SensorLead lead);

}  // namespace armfault
