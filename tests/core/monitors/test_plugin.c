/* A monitor plugin that misbehaves on request, for tests/core/monitors/plugin_monitor_test.cc.
 * settings {"mode": M}:
 *   "quiet"        emits nothing (also the no-op plugin of the overhead benchmark)
 *   "alarm"        friction_increase on the last joint at the first tick at or after 1 s
 *                  where that joint's reference moves
 *   "joint0", "nan", "backwards", "bad_state", "unterminated"
 *                  that alarm, broken in that way (joint 0, NaN magnitude, a second verdict
 *                  earlier than the first, state 7, a family without its NUL)
 *   "step_error"   step returns -3 with a message at that tick
 *   "finish_error" finish returns 1 with a message
 *   "create_error" create returns NULL with a message
 *   "stats_true"   the alarm, publishing the statistic "alarmed" (1 from the alarm on, else 0;
 *                  threshold 0.5, friction_increase): the threshold contract kept
 *   "stats_lie"    the alarm, publishing "alarmed" as 0 throughout: the contract broken
 *   "stats_zero"   declares a statistic with threshold 0 (refused at load)
 *   "context"      at its first tick, a healthy verdict telling what create got: joint = the
 *                  joint count, magnitude = dt_s (magnitude_name "dt_s"); create (ABI minor 0)
 *                  gives joint 0 and dt_s -1, create_v2 what armfault passed
 *   "commissioned" (create_v2 builds, which also commission) at its first tick two healthy
 *                  verdicts from the unit's blob: joint 1's magnitude the commissioning run's
 *                  tick count, joint 2's the mean |i_cmd_A| of the last joint over it (-1 and
 *                  -1 without a blob)
 *   "commission_error" commission_tick returns an error at t >= 1 s
 * Built six times (tests/CMakeLists.txt): as is; with TEST_PLUGIN_ABI_VERSION=2 (another
 * ABI); with TEST_PLUGIN_WITHOUT_FINISH (a missing function); with TEST_PLUGIN_CREATE_V2 (also
 * armfault_monitor_create_v2, which reads its settings with include/armfault/monitor_settings.h);
 * with that and TEST_PLUGIN_WITHOUT_CREATE (create_v2 alone); with TEST_PLUGIN_WITHOUT_CREATE
 * alone (no create of either kind). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "armfault/monitor_plugin.h"
#ifdef TEST_PLUGIN_CREATE_V2
#include "armfault/monitor_settings.h"
#endif

#ifndef TEST_PLUGIN_ABI_VERSION
#define TEST_PLUGIN_ABI_VERSION ARMFAULT_MONITOR_PLUGIN_ABI_VERSION
#endif

typedef struct {
  char mode[32];
  int fired;
  int count;
  armfault_verdict verdicts[2];
  armfault_statistic statistic;
  double values[16]; /* [joint][1] */
  double dt_s;       /* as create_v2 got it; -1 from create */
  int joints;        /* as create_v2 got it; 0 from create */
  double blob_ticks, blob_mean_abs_i_A; /* from the unit's commissioning blob, or -1 */
} test_plugin;

/* What commissioning learns: the blob's layout. */
typedef struct {
  double ticks;
  double sum_abs_i_A; /* |i_cmd_A| of the last joint, summed over the ticks */
} test_blob;

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_abi_version(void) { return TEST_PLUGIN_ABI_VERSION; }

#ifndef TEST_PLUGIN_WITHOUT_CREATE
/* The value of "mode" in the compact JSON armfault passes ({"mode":"nan"}), or "quiet". */
static void read_mode(const char* settings_json, char* mode, size_t size) {
  const char* key = strstr(settings_json, "\"mode\":\"");
  size_t n = 0;
  snprintf(mode, size, "quiet");
  if (!key) return;
  key += strlen("\"mode\":\"");
  while (key[n] && key[n] != '"' && n + 1 < size) n++;
  memcpy(mode, key, n);
  mode[n] = '\0';
}
#endif

#if !defined(TEST_PLUGIN_WITHOUT_CREATE) || defined(TEST_PLUGIN_CREATE_V2)
/* The instance for `mode`; NULL with a message for mode create_error. */
static test_plugin* make(test_plugin* self, char* error, size_t error_size) {
  strcpy(self->statistic.name, "alarmed");
  strcpy(self->statistic.family, "friction_increase");
  self->statistic.threshold = strcmp(self->mode, "stats_zero") == 0 ? 0.0 : 0.5;
  if (strcmp(self->mode, "create_error") == 0) {
    snprintf(error, error_size, "settings rejected: mode create_error");
    free(self);
    return NULL;
  }
  return self;
}
#endif

#ifndef TEST_PLUGIN_WITHOUT_CREATE
ARMFAULT_PLUGIN_EXPORT void* armfault_monitor_create(const char* robot_json, const char* settings_json, char* error,
                                                     size_t error_size) {
  test_plugin* self;
  (void)robot_json;
  self = calloc(1, sizeof *self);
  if (!self) {
    snprintf(error, error_size, "out of memory");
    return NULL;
  }
  read_mode(settings_json, self->mode, sizeof self->mode);
  self->dt_s = -1;
  return make(self, error, error_size);
}
#endif

#ifdef TEST_PLUGIN_CREATE_V2
ARMFAULT_PLUGIN_EXPORT void* armfault_monitor_create_v2(const armfault_monitor_create_args* args, char* error,
                                                        size_t error_size) {
  static const char* const known[] = {"mode"};
  test_plugin* self;
  if (!ARMFAULT_CREATE_ARGS_HAS(args, joint_count)) {
    snprintf(error, error_size, "create_v2 args of %lu bytes: no joint_count", (unsigned long)args->struct_size);
    return NULL;
  }
  self = calloc(1, sizeof *self);
  if (!self) {
    snprintf(error, error_size, "out of memory");
    return NULL;
  }
  strcpy(self->mode, "quiet");
  if (armfault_setting_check_keys(args->settings_json, known, 1, error, error_size) < 0 ||
      armfault_setting_string(args->settings_json, "mode", self->mode, sizeof self->mode, error, error_size) < 0) {
    free(self);
    return NULL;
  }
  self->dt_s = args->dt_s;
  self->joints = args->joint_count;
  self->blob_ticks = self->blob_mean_abs_i_A = -1;
  if (args->commissioning) {
    const test_blob* blob = (const test_blob*)args->commissioning;
    if (args->commissioning_size != sizeof *blob) {
      snprintf(error, error_size, "a commissioning blob of %lu bytes", (unsigned long)args->commissioning_size);
      free(self);
      return NULL;
    }
    self->blob_ticks = blob->ticks;
    self->blob_mean_abs_i_A = blob->ticks > 0 ? blob->sum_abs_i_A / blob->ticks : 0;
  }
  return make(self, error, error_size);
}

typedef struct {
  char mode[32];
  test_blob blob;
} test_commissioning;

ARMFAULT_PLUGIN_EXPORT void* armfault_monitor_commission_begin(const armfault_monitor_create_args* args, char* error,
                                                               size_t error_size) {
  test_commissioning* c = calloc(1, sizeof *c);
  if (!c) {
    snprintf(error, error_size, "out of memory");
    return NULL;
  }
  strcpy(c->mode, "quiet");
  if (args->commissioning != NULL) {
    snprintf(error, error_size, "commission_begin got a blob");
    free(c);
    return NULL;
  }
  if (armfault_setting_string(args->settings_json, "mode", c->mode, sizeof c->mode, error, error_size) < 0) {
    free(c);
    return NULL;
  }
  return c;
}

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_commission_tick(void* handle, double t_s, const armfault_joint_signals* joints,
                                                            int joint_count, char* error, size_t error_size) {
  test_commissioning* c = handle;
  if (strcmp(c->mode, "commission_error") == 0 && t_s >= 1.0) {
    snprintf(error, error_size, "commissioning diverged at t = %g s", t_s);
    return 2;
  }
  c->blob.ticks += 1;
  c->blob.sum_abs_i_A += fabs(joints[joint_count - 1].i_cmd_A);
  return 0;
}

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_commission_end(void* handle, double t_end_s, const void** blob,
                                                           size_t* blob_size, char* error, size_t error_size) {
  test_commissioning* c = handle;
  (void)t_end_s;
  (void)error;
  (void)error_size;
  *blob = &c->blob;
  *blob_size = sizeof c->blob;
  return 0;
}

ARMFAULT_PLUGIN_EXPORT void armfault_monitor_commission_free(void* handle) { free(handle); }
#endif

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_step(void* handle, double t_s, const armfault_joint_signals* joints,
                                                 int joint_count, char* error, size_t error_size) {
  test_plugin* self = handle;
  armfault_verdict* v = &self->verdicts[0];
  if (!self->fired && strcmp(self->mode, "commissioned") == 0) {
    self->fired = 1;
    memset(self->verdicts, 0, sizeof self->verdicts);
    self->verdicts[0].t_s = self->verdicts[1].t_s = t_s;
    self->verdicts[0].joint = 1;
    self->verdicts[1].joint = 2;
    self->verdicts[0].magnitude = self->blob_ticks;
    self->verdicts[1].magnitude = self->blob_mean_abs_i_A;
    self->verdicts[0].confidence = self->verdicts[1].confidence = 1;
    self->count = 2;
    return 0;
  }
  if (!self->fired && strcmp(self->mode, "context") == 0) {
    self->fired = 1;
    memset(v, 0, sizeof *v);
    v->t_s = t_s;
    v->joint = self->joints;
    v->state = ARMFAULT_STATE_HEALTHY;
    strcpy(v->magnitude_name, "dt_s");
    v->magnitude = self->dt_s;
    v->confidence = 1;
    self->count = 1;
    return 0;
  }
  if (self->fired || strcmp(self->mode, "quiet") == 0 || t_s < 1.0) return 0;
  if (joints[joint_count - 1].qd_ref_rad_s == 0) return 0;
  self->fired = 1;
  if (strcmp(self->mode, "step_error") == 0) {
    snprintf(error, error_size, "sensor model diverged at t = %g s", t_s);
    return -3;
  }
  memset(v, 0, sizeof *v);
  v->t_s = t_s;
  v->joint = joint_count;
  v->state = ARMFAULT_STATE_WORN;
  strcpy(v->family, "friction_increase");
  strcpy(v->magnitude_name, "friction_factor");
  v->magnitude = 2.0;
  v->confidence = 0.9;
  self->count = 1;
  if (strcmp(self->mode, "stats_true") == 0 && joint_count <= 16) self->values[joint_count - 1] = 1.0;
  if (strcmp(self->mode, "joint0") == 0) v->joint = 0;
  if (strcmp(self->mode, "nan") == 0) v->magnitude = NAN;
  if (strcmp(self->mode, "bad_state") == 0) v->state = 7;
  if (strcmp(self->mode, "unterminated") == 0) memset(v->family, 'x', sizeof v->family);
  if (strcmp(self->mode, "backwards") == 0) {
    self->verdicts[1] = *v;
    self->verdicts[1].t_s = t_s / 2;
    self->count = 2;
  }
  return 0;
}

#ifndef TEST_PLUGIN_WITHOUT_FINISH
ARMFAULT_PLUGIN_EXPORT int armfault_monitor_finish(void* handle, double t_end_s, char* error, size_t error_size) {
  test_plugin* self = handle;
  if (strcmp(self->mode, "finish_error") == 0) {
    snprintf(error, error_size, "cannot finish at %g s", t_end_s);
    return 1;
  }
  return 0;
}
#endif

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_verdicts(void* handle, const armfault_verdict** verdicts) {
  test_plugin* self = handle;
  *verdicts = self->verdicts;
  return self->count;
}

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_statistics(void* handle, const armfault_statistic** statistics) {
  test_plugin* self = handle;
  *statistics = &self->statistic;
  return strncmp(self->mode, "stats_", 6) == 0 ? 1 : 0;
}

ARMFAULT_PLUGIN_EXPORT const double* armfault_monitor_statistic_values(void* handle) {
  test_plugin* self = handle;
  return self->values; /* calloc'd: 0 until the alarm */
}

ARMFAULT_PLUGIN_EXPORT void armfault_monitor_destroy(void* handle) { free(handle); }
