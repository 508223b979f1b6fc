/* The smallest monitor plugin: it watches nothing and emits nothing. The overhead benchmark
 * (bench/plugin_bench.cc) runs it to measure the plugin call path alone; it is also the
 * skeleton of a plugin (docs/monitor-api.md, "C plugin"). */
#include <stdlib.h>

#include "armfault/monitor_plugin.h"

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_abi_version(void) { return ARMFAULT_MONITOR_PLUGIN_ABI_VERSION; }

ARMFAULT_PLUGIN_EXPORT void* armfault_monitor_create(const char* robot_json, const char* settings_json, char* error,
                                                     size_t error_size) {
  (void)robot_json;
  (void)settings_json;
  (void)error;
  (void)error_size;
  return malloc(1); /* any non-NULL pointer of this instance's own */
}

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_step(void* self, double t_s, const armfault_joint_signals* joints,
                                                 int joint_count, char* error, size_t error_size) {
  (void)self;
  (void)t_s;
  (void)joints;
  (void)joint_count;
  (void)error;
  (void)error_size;
  return 0;
}

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_finish(void* self, double t_end_s, char* error, size_t error_size) {
  (void)self;
  (void)t_end_s;
  (void)error;
  (void)error_size;
  return 0;
}

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_verdicts(void* self, const armfault_verdict** verdicts) {
  (void)self;
  *verdicts = NULL;
  return 0;
}

ARMFAULT_PLUGIN_EXPORT void armfault_monitor_destroy(void* self) { free(self); }
