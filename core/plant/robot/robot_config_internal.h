// What robot_config.cc (parsing, validation, output) and robot_presets.cc (the presets and the
// drive catalogue) share beyond the public robot_config.h. Only these two files include it.
#pragma once

#include <string>

namespace armfault {

// Whether drive type `type`'s defaults carry a gearbox group (false for an unknown type).
bool TypeHasGearbox(const std::string& type);

}  // namespace armfault
