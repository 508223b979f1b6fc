/* Example armfault monitor plugin (plain C99, include/armfault/monitor_plugin.h and its
 * settings helper monitor_settings.h only; ABI 1.1, armfault_monitor_create_v2): a
 * current-residual monitor.
 *
 * Each joint's motor must supply, on its shaft, the torque the torque sensor measures (through
 * the harmonic drive: ratio and mesh loss) plus its friction:
 *     K_T i_cmd = a * (tau + m |tau| sgn(qd)) / N  +  c * f(qd)
 * with the datasheet's K_T, ratio N, mesh loss fraction m and friction model
 * f(qd) = b qd + (F_c + F_s exp(-F_t qd^2)) sgn(qd), all read from robot_json. A healthy joint
 * has a = c = 1. K_T degraded to n (kt_degradation) makes a = c = 1/n; friction scaled by k
 * (friction_increase) makes a = 1, c = k. The plugin fits a and c by least squares over an
 * exponentially weighted window of the ticks where the joint moves; 1/a estimates kt_factor and
 * c/a friction_factor. When that fit leaves the healthy range for debounce_s, a fresh fit of
 * the ticks from then on names the fault and keeps refining its size. It sees only the signals
 * and the robot as designed, as any monitor (docs/monitor-api.md).
 *
 * Settings (all optional, numbers; read with include/armfault/monitor_settings.h): window_s 2
 * (the fits' time constant), min_speed_rad_s 0.05 (slower ticks are left out: the friction's
 * sign is unknown), min_moving_s 1 (motion in the window before the watch trusts its fit; at
 * least 10 control periods, which create_v2 is told), judge_moving_s 0.5 (motion after a change before it
 * is named), debounce_s 0.3, kt_worn 0.85, kt_defective 0.65, friction_worn 1.4,
 * friction_defective 2.5, refine_step 0.05 (a new verdict when the size estimate moved by more).
 *
 * Threshold mode (setting threshold_alarm 1): no judge phase; a joint alarms, latched, as soon
 * as its watch fit's K_T deficit (1 - kt_factor) passes kt_deficit_threshold (default 0.15) or
 * its friction excess (friction_factor - 1) passes friction_excess_threshold (0.4), the first
 * naming the family. The plugin then publishes those two statistics (their running maxima, so
 * the latched alarm is exactly "statistic above threshold", docs/monitor-api.md "Statistics for
 * tune") and `armfault tune` can sweep both thresholds. In the default mode it publishes none:
 * the judge phase's alarm is not a threshold test on one statistic.
 *
 * Commissioning (ABI minor 1, armfault_monitor_commission_*): on a unit's healthy commissioning
 * run it fits each joint's own 1/a and c/a over the whole run and its windowed fit's healthy
 * scatter; the unit's runs judge the fits relative to the unit, and leave out a joint whose
 * healthy scatter already reached kt_worn or friction_worn (docs/monitor-api.md, "With
 * commissioning"). Without commissioning it judges against the datasheet, as before.
 *
 * Build: gcc -std=c99 -O2 -Wall -Wextra -fPIC -shared -I include \
 *            examples/plugins/current_residual.c -o libcurrent_residual.so -lm
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "armfault/monitor_plugin.h"
#include "armfault/monitor_settings.h"

/* ------------------------------------------------------------------ settings */

typedef struct {
  double window_s;           /* time constant of the exponential forgetting */
  double min_speed_rad_s;    /* a tick counts when |qd_est| is above: sgn(qd) is known */
  double min_moving_s;       /* moving time in the watch window before it is trusted */
  double judge_moving_s;     /* moving time after a change before it is named */
  double debounce_s;         /* a new state must hold this long before it is emitted */
  double kt_worn, kt_defective;
  double friction_worn, friction_defective;
  double refine_step;
  double threshold_alarm; /* 1: threshold mode (see the top) */
  double kt_deficit_threshold, friction_excess_threshold;
} settings;

static const char* const kSettingNames[] = {"window_s",      "min_speed_rad_s",    "min_moving_s",
                                            "judge_moving_s", "debounce_s",         "kt_worn",
                                            "kt_defective",  "friction_worn",      "friction_defective",
                                            "refine_step",   "threshold_alarm",    "kt_deficit_threshold",
                                            "friction_excess_threshold"};

static double* setting_slot(settings* s, int k) {
  double* slots[] = {&s->window_s,     &s->min_speed_rad_s, &s->min_moving_s,  &s->judge_moving_s,
                     &s->debounce_s,   &s->kt_worn,         &s->kt_defective,  &s->friction_worn,
                     &s->friction_defective, &s->refine_step,   &s->threshold_alarm,
                     &s->kt_deficit_threshold, &s->friction_excess_threshold};
  return slots[k];
}

/* Reads the settings with include/armfault/monitor_settings.h: every key must be one of
 * kSettingNames and a number; absent ones keep their defaults. `dt_s` is the control period
 * (create_v2): the fits' window must hold enough ticks to fit two unknowns. Returns 0 or -1 with
 * a message. */
static int parse_settings(const char* json, double dt_s, settings* s, char* error, size_t error_size) {
  const int count = (int)(sizeof kSettingNames / sizeof kSettingNames[0]);
  int k;
  s->window_s = 2.0;
  s->min_speed_rad_s = 0.05;
  s->min_moving_s = 1.0;
  s->judge_moving_s = 0.5;
  s->debounce_s = 0.3;
  s->kt_worn = 0.85;
  s->kt_defective = 0.65;
  s->friction_worn = 1.4;
  s->friction_defective = 2.5;
  s->refine_step = 0.05;
  s->threshold_alarm = 0;
  s->kt_deficit_threshold = 0.15;
  s->friction_excess_threshold = 0.4;
  if (armfault_setting_check_keys(json, kSettingNames, count, error, error_size) < 0) return -1;
  for (k = 0; k < count; k++) {
    if (armfault_setting_number(json, kSettingNames[k], setting_slot(s, k), error, error_size) < 0) return -1;
  }
  if (!(s->window_s > 0 && s->min_speed_rad_s > 0 && s->min_moving_s > 0 && s->judge_moving_s > 0 &&
        s->debounce_s >= 0 && s->refine_step > 0)) {
    snprintf(error, error_size,
             "window_s, min_speed_rad_s, min_moving_s, judge_moving_s and refine_step must be > 0, debounce_s >= 0");
    return -1;
  }
  if (!((s->threshold_alarm == 0 || s->threshold_alarm == 1) && s->kt_deficit_threshold > 0 &&
        s->friction_excess_threshold > 0)) {
    snprintf(error, error_size, "threshold_alarm must be 0 or 1, kt_deficit_threshold and friction_excess_threshold > 0");
    return -1;
  }
  if (!(s->min_moving_s < s->window_s && s->judge_moving_s < s->window_s)) {
    /* a window holds at most window_s of motion */
    snprintf(error, error_size, "min_moving_s (%g) and judge_moving_s (%g) must be below window_s (%g)",
             s->min_moving_s, s->judge_moving_s, s->window_s);
    return -1;
  }
  if (!(0 < s->kt_defective && s->kt_defective < s->kt_worn && s->kt_worn < 1)) {
    snprintf(error, error_size, "expected 0 < kt_defective < kt_worn < 1, got %g and %g", s->kt_defective, s->kt_worn);
    return -1;
  }
  if (!(1 < s->friction_worn && s->friction_worn < s->friction_defective)) {
    snprintf(error, error_size, "expected 1 < friction_worn < friction_defective, got %g and %g", s->friction_worn,
             s->friction_defective);
    return -1;
  }
  if (!(s->min_moving_s >= 10 * dt_s)) {
    snprintf(error, error_size, "min_moving_s (%g) must hold at least 10 control periods (%g s)", s->min_moving_s,
             10 * dt_s);
    return -1;
  }
  return 0;
}

/* ------------------------------------------------------------------ the robot as designed */

typedef struct {
  double kt_Nm_per_A, ratio, mesh_loss_fraction;
  double viscous_Nm_s_per_rad, coulomb_Nm, static_Nm, stribeck_s2_per_rad2;
} joint_model;

/* The value after the n-th (0-based) occurrence of "key": in the robot JSON; each module holds
 * each of the keys below exactly once, modules in joint order. Returns 0 or -1. */
static int nth_number(const char* json, const char* key, int n, double* out) {
  char pattern[64];
  const char* p = json;
  snprintf(pattern, sizeof pattern, "\"%s\":", key);
  for (;;) {
    char* end;
    p = strstr(p, pattern);
    if (!p) return -1;
    p += strlen(pattern);
    if (n-- > 0) continue;
    *out = strtod(p, &end);
    return end == p ? -1 : 0;
  }
}

static int count_of(const char* json, const char* key) {
  char pattern[64];
  int n = 0;
  const char* p = json;
  snprintf(pattern, sizeof pattern, "\"%s\":", key);
  while ((p = strstr(p, pattern)) != NULL) {
    n++;
    p += strlen(pattern);
  }
  return n;
}

/* ------------------------------------------------------------------ the fit */

/* Exponentially weighted least squares of y = a x0 + c x1 over the ticks a joint moved: sums of
 * x x^T and x y, each tick weighted by its dt, decaying with the window's time constant. */
typedef struct {
  double sxx00, sxx01, sxx11, sxy0, sxy1;
  double moving_s; /* weighted time moving */
} fit;

static void fit_decay(fit* f, double forget) {
  f->sxx00 *= forget;
  f->sxx01 *= forget;
  f->sxx11 *= forget;
  f->sxy0 *= forget;
  f->sxy1 *= forget;
  f->moving_s *= forget;
}

static void fit_add(fit* f, double dt_s, double x0, double x1, double y) {
  f->sxx00 += dt_s * x0 * x0;
  f->sxx01 += dt_s * x0 * x1;
  f->sxx11 += dt_s * x1 * x1;
  f->sxy0 += dt_s * x0 * y;
  f->sxy1 += dt_s * x1 * y;
  f->moving_s += dt_s;
}

/* The estimates 1/a (kt_factor) and c/a (friction_factor); 0 when the window cannot tell the
 * torque gain from friction: x0 and x1 nearly proportional (1 - correlation^2 below 0.02, where
 * one stroke of the arm is 0.05 to 0.07 and a stroke each way more). */
static int fit_solve(const fit* f, double* kt_factor, double* friction_factor) {
  const double det = f->sxx00 * f->sxx11 - f->sxx01 * f->sxx01;
  double a, c;
  if (!(det > 0.02 * f->sxx00 * f->sxx11)) return 0;
  a = (f->sxx11 * f->sxy0 - f->sxx01 * f->sxy1) / det;
  c = (f->sxx00 * f->sxy1 - f->sxx01 * f->sxy0) / det;
  if (!(a > 0.05)) return 0; /* no sensible torque gain (a dead drive is not this monitor's) */
  *kt_factor = 1 / a;
  *friction_factor = c / a;
  return 1;
}

/* ------------------------------------------------------------------ the monitor */

enum { FAMILY_NONE = 0, FAMILY_KT = 1, FAMILY_FRICTION = 2 };

/* WATCH: the long-running fit looks for a change. JUDGE: a change held for debounce_s; a fresh
 * fit, of the ticks since, names it (the long fit mixes ticks before and after the fault, and a
 * mix of healthy and lower torque gain can look like more friction). ALARM: that fit goes on,
 * refining the size. */
enum { PHASE_WATCH = 0, PHASE_JUDGE = 1, PHASE_ALARM = 2 };

typedef struct {
  joint_model model;
  fit watch, judge;
  int phase;
  double suspect_s;                  /* WATCH: when the watch fit left healthy, or -1 */
  int state, family;                 /* as last emitted */
  double magnitude, emitted_s;       /* as last emitted */
  int pending_state, pending_family; /* JUDGE, ALARM: another view, held since pending_s (or -1) */
  double pending_s;
  double max_deficit, max_excess; /* threshold mode: running maxima of the watch fit's deviations */
  double kt0, friction0;          /* the unit's own healthy 1/a and c/a (commissioning), else 1 */
  int muted; /* commissioning: its healthy windowed fit already reached a worn limit; never judged */
  int has_value;                  /* threshold mode: the watch fit was trusted at least once */
} joint_monitor;

typedef struct {
  settings s;
  int joints;
  joint_monitor* joint;
  double last_t_s;
  int started;
  armfault_verdict* verdicts;
  int count, capacity;
  armfault_statistic statistics[2]; /* threshold mode */
  double* values;                   /* threshold mode: [joint][2] */
} monitor;

static void classify(const settings* s, double kt_factor, double friction_factor, int* state, int* family,
                     double* magnitude) {
  *state = ARMFAULT_STATE_HEALTHY;
  *family = FAMILY_NONE;
  *magnitude = 0;
  if (kt_factor < s->kt_worn) {
    *family = FAMILY_KT;
    *state = kt_factor < s->kt_defective ? ARMFAULT_STATE_DEFECTIVE : ARMFAULT_STATE_WORN;
    *magnitude = kt_factor;
  } else if (friction_factor > s->friction_worn) {
    *family = FAMILY_FRICTION;
    *state = friction_factor > s->friction_defective ? ARMFAULT_STATE_DEFECTIVE : ARMFAULT_STATE_WORN;
    *magnitude = friction_factor;
  }
}

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_abi_version(void) { return ARMFAULT_MONITOR_PLUGIN_ABI_VERSION; }

/* Joint j's (0-based) model from robot_json. 0, or -1 with a message. */
static int read_model(const char* robot_json, int j, joint_model* m, char* error, size_t error_size) {
  static const char* const keys[] = {"kt_Nm_per_A",          "ratio",      "mesh_loss_fraction",
                                     "viscous_Nm_s_per_rad", "coulomb_Nm", "static_Nm",
                                     "stribeck_s2_per_rad2"};
  double* fields[7];
  int k;
  fields[0] = &m->kt_Nm_per_A;
  fields[1] = &m->ratio;
  fields[2] = &m->mesh_loss_fraction;
  fields[3] = &m->viscous_Nm_s_per_rad;
  fields[4] = &m->coulomb_Nm;
  fields[5] = &m->static_Nm;
  fields[6] = &m->stribeck_s2_per_rad2;
  for (k = 0; k < 7; k++) {
    if (nth_number(robot_json, keys[k], j, fields[k]) != 0) {
      snprintf(error, error_size, "robot_json: no number for %s of joint %d", keys[k], j + 1);
      return -1;
    }
  }
  if (!(m->kt_Nm_per_A > 0 && m->ratio > 0)) {
    snprintf(error, error_size, "robot_json: joint %d needs kt_Nm_per_A > 0 and ratio > 0", j + 1);
    return -1;
  }
  return 0;
}

/* ABI minor 1: told the control period and the joint count (no create of minor 0: this example
 * ships with the armfault that loads it). */
ARMFAULT_PLUGIN_EXPORT void* armfault_monitor_create_v2(const armfault_monitor_create_args* args, char* error,
                                                        size_t error_size) {
  const char* robot_json = args->robot_json;
  monitor* self = calloc(1, sizeof *self);
  int j;
  if (!self) {
    snprintf(error, error_size, "out of memory");
    return NULL;
  }
  if (parse_settings(args->settings_json, args->dt_s, &self->s, error, error_size) != 0) goto fail;
  self->joints = args->joint_count;
  if (count_of(robot_json, "kt_Nm_per_A") != self->joints) {
    snprintf(error, error_size, "robot_json has %d modules with motor/kt_Nm_per_A, expected %d", count_of(robot_json, "kt_Nm_per_A"),
             self->joints);
    goto fail;
  }
  self->joint = calloc((size_t)self->joints, sizeof *self->joint);
  if (!self->joint) {
    snprintf(error, error_size, "out of memory");
    goto fail;
  }
  /* The unit's commissioning: 1/a and c/a per joint (armfault_monitor_commission_end). */
  if (args->commissioning && args->commissioning_size != 4 * (size_t)self->joints * sizeof(double)) {
    snprintf(error, error_size, "a commissioning blob of %lu bytes, expected %lu", (unsigned long)args->commissioning_size,
             (unsigned long)(4 * (size_t)self->joints * sizeof(double)));
    goto fail;
  }
  for (j = 0; j < self->joints; j++) {
    joint_monitor* jm = &self->joint[j];
    if (read_model(robot_json, j, &jm->model, error, error_size) != 0) goto fail;
    jm->suspect_s = -1;
    jm->pending_s = -1;
    jm->kt0 = jm->friction0 = 1;
    if (args->commissioning) {
      const double* learned = (const double*)args->commissioning + 4 * j;
      jm->kt0 = learned[0];
      jm->friction0 = learned[1];
      /* learned[2], [3]: the lowest kt_factor and highest friction_factor its healthy windowed fit
       * gave, relative to kt0 and friction0: within the worn limits, the joint's faults can be
       * told from its scatter; beyond them, not from this monitor's fit. */
      jm->muted = learned[2] < self->s.kt_worn || learned[3] > self->s.friction_worn;
    }
  }
  if (self->s.threshold_alarm == 1) {
    self->values = malloc(2 * (size_t)self->joints * sizeof *self->values);
    if (!self->values) {
      snprintf(error, error_size, "out of memory");
      goto fail;
    }
    for (j = 0; j < 2 * self->joints; j++) self->values[j] = NAN;
    strcpy(self->statistics[0].name, "kt_deficit");
    strcpy(self->statistics[0].family, "kt_degradation");
    self->statistics[0].threshold = self->s.kt_deficit_threshold;
    strcpy(self->statistics[0].setting, "/kt_deficit_threshold");
    strcpy(self->statistics[1].name, "friction_excess");
    strcpy(self->statistics[1].family, "friction_increase");
    self->statistics[1].threshold = self->s.friction_excess_threshold;
    strcpy(self->statistics[1].setting, "/friction_excess_threshold");
  }
  return self;
fail:
  free(self->joint);
  free(self);
  return NULL;
}

/* Appends a verdict of joint j's view (jm->state, jm->family) with `magnitude`. 0 or -1. */
static int emit(monitor* self, double t_s, int j, joint_monitor* jm, double magnitude) {
  armfault_verdict* v;
  if (self->count == self->capacity) {
    const int capacity = self->capacity ? 2 * self->capacity : 16;
    armfault_verdict* grown = realloc(self->verdicts, (size_t)capacity * sizeof *grown);
    if (!grown) return -1;
    self->verdicts = grown;
    self->capacity = capacity;
  }
  v = &self->verdicts[self->count++];
  memset(v, 0, sizeof *v);
  v->t_s = t_s;
  v->joint = j + 1;
  v->state = jm->state;
  v->confidence = 1;
  if (jm->family == FAMILY_KT) {
    strcpy(v->family, "kt_degradation");
    strcpy(v->magnitude_name, "kt_factor");
    v->magnitude = magnitude;
    /* 0.5 at the worn threshold, 1 at the defective one and beyond */
    v->confidence = 0.5 + 0.5 * (self->s.kt_worn - magnitude) / (self->s.kt_worn - self->s.kt_defective);
  } else if (jm->family == FAMILY_FRICTION) {
    strcpy(v->family, "friction_increase");
    strcpy(v->magnitude_name, "friction_factor");
    v->magnitude = magnitude;
    v->confidence =
        0.5 + 0.5 * (magnitude - self->s.friction_worn) / (self->s.friction_defective - self->s.friction_worn);
  }
  if (v->confidence > 1) v->confidence = 1;
  if (v->confidence < 0) v->confidence = 0;
  jm->magnitude = magnitude;
  jm->emitted_s = t_s;
  return 0;
}

/* The fit's regressors at one tick: x0 the link torque through the drive and x1 the modelled
 * friction, both as motor torque [N m], and y the motor torque the command asks for. 0 when the
 * joint is too slow to know the friction's sign (the tick is left out). */
static int regressors(const joint_model* m, const settings* s, const armfault_joint_signals* in, double* x0, double* x1,
                      double* y) {
  const double qd = in->qd_est_rad_s, sign = qd > 0 ? 1.0 : -1.0, tau = in->tau_sensor_Nm;
  if (!(fabs(qd) > s->min_speed_rad_s)) return 0;
  *x0 = (tau + m->mesh_loss_fraction * fabs(tau) * sign) / m->ratio;
  *x1 = m->viscous_Nm_s_per_rad * qd + (m->coulomb_Nm + m->static_Nm * exp(-m->stribeck_s2_per_rad2 * qd * qd)) * sign;
  *y = m->kt_Nm_per_A * in->i_cmd_A;
  return 1;
}

/* fit_solve relative to the unit's commissioning (kt0, friction0: 1 without it). */
static int solve(const joint_monitor* jm, const fit* f, double* kt_factor, double* friction_factor) {
  if (!fit_solve(f, kt_factor, friction_factor)) return 0;
  *kt_factor /= jm->kt0;
  *friction_factor /= jm->friction0;
  return 1;
}

/* One joint at one tick: both fits, then the phase's decision. 0, or -1 out of memory. */
static int watch(monitor* self, double t_s, double dt_s, int j, const armfault_joint_signals* in) {
  joint_monitor* jm = &self->joint[j];
  const joint_model* m = &jm->model;
  const settings* s = &self->s;
  const double forget = exp(-dt_s / s->window_s);
  double kt_factor, friction_factor, magnitude, x0, x1, y;
  int state, family;

  fit_decay(&jm->watch, forget);
  fit_decay(&jm->judge, forget);
  if (regressors(m, s, in, &x0, &x1, &y)) {
    fit_add(&jm->watch, dt_s, x0, x1, y);
    fit_add(&jm->judge, dt_s, x0, x1, y);
  }
  if (jm->muted) return 0;

  if (s->threshold_alarm == 1) {
    double* value = &self->values[2 * j];
    if (jm->watch.moving_s >= s->min_moving_s && solve(jm, &jm->watch, &kt_factor, &friction_factor)) {
      if (!jm->has_value || 1 - kt_factor > jm->max_deficit) jm->max_deficit = 1 - kt_factor;
      if (!jm->has_value || friction_factor - 1 > jm->max_excess) jm->max_excess = friction_factor - 1;
      jm->has_value = 1;
    }
    if (!jm->has_value) return 0;
    value[0] = jm->max_deficit;
    value[1] = jm->max_excess;
    if (jm->state != ARMFAULT_STATE_HEALTHY) return 0; /* latched */
    if (jm->max_deficit > s->kt_deficit_threshold) {
      jm->family = FAMILY_KT;
      magnitude = 1 - jm->max_deficit;
    } else if (jm->max_excess > s->friction_excess_threshold) {
      jm->family = FAMILY_FRICTION;
      magnitude = 1 + jm->max_excess;
    } else {
      return 0;
    }
    jm->state = ARMFAULT_STATE_WORN;
    return emit(self, t_s, j, jm, magnitude);
  }

  if (jm->phase == PHASE_WATCH) {
    int suspect = 0;
    if (jm->watch.moving_s >= s->min_moving_s &&
        solve(jm, &jm->watch, &kt_factor, &friction_factor)) {
      classify(s, kt_factor, friction_factor, &state, &family, &magnitude);
      suspect = family != FAMILY_NONE;
    }
    if (!suspect) {
      jm->suspect_s = -1;
      return 0;
    }
    if (jm->suspect_s < 0) jm->suspect_s = t_s;
    if (t_s - jm->suspect_s < s->debounce_s) return 0;
    /* A change: judge it on what comes from now on. */
    memset(&jm->judge, 0, sizeof jm->judge);
    jm->phase = PHASE_JUDGE;
    jm->suspect_s = -1;
    jm->pending_s = -1;
    return 0;
  }

  /* JUDGE and ALARM: the fresh fit, once it saw enough motion. */
  if (jm->judge.moving_s < s->judge_moving_s || !solve(jm, &jm->judge, &kt_factor, &friction_factor)) {
    return 0;
  }
  classify(s, kt_factor, friction_factor, &state, &family, &magnitude);
  if (state == jm->state && family == jm->family) {
    jm->pending_s = -1;
    if (jm->phase == PHASE_JUDGE) {
      jm->phase = PHASE_WATCH; /* judged healthy: a false start */
      return 0;
    }
    /* The same view: refine its size now and then. */
    if (fabs(magnitude - jm->magnitude) > s->refine_step && t_s - jm->emitted_s >= s->debounce_s) {
      return emit(self, t_s, j, jm, magnitude);
    }
    return 0;
  }
  if (jm->pending_s < 0 || state != jm->pending_state || family != jm->pending_family) {
    jm->pending_state = state;
    jm->pending_family = family;
    jm->pending_s = t_s;
  }
  if (t_s - jm->pending_s < s->debounce_s) return 0;
  jm->state = state;
  jm->family = family;
  jm->pending_s = -1;
  jm->phase = family == FAMILY_NONE ? PHASE_WATCH : PHASE_ALARM;
  return emit(self, t_s, j, jm, magnitude);
}

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_step(void* handle, double t_s, const armfault_joint_signals* joints,
                                                 int joint_count, char* error, size_t error_size) {
  monitor* self = handle;
  double dt_s;
  int j;
  if (joint_count != self->joints) {
    snprintf(error, error_size, "robot_json has %d joints, step got %d", self->joints, joint_count);
    return 1;
  }
  if (!self->started) {
    self->started = 1;
    self->last_t_s = t_s;
  }
  dt_s = t_s - self->last_t_s;
  self->last_t_s = t_s;
  for (j = 0; j < joint_count; j++) {
    if (watch(self, t_s, dt_s, j, &joints[j]) != 0) {
      snprintf(error, error_size, "out of memory for verdicts");
      return 1;
    }
  }
  return 0;
}

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_finish(void* handle, double t_end_s, char* error, size_t error_size) {
  (void)handle;
  (void)t_end_s;
  (void)error;
  (void)error_size;
  return 0; /* every verdict was emitted at its tick */
}

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_verdicts(void* handle, const armfault_verdict** verdicts) {
  const monitor* self = handle;
  *verdicts = self->verdicts;
  return self->count;
}

/* Threshold mode publishes its two statistics; the default mode none. */
ARMFAULT_PLUGIN_EXPORT int armfault_monitor_statistics(void* handle, const armfault_statistic** statistics) {
  const monitor* self = handle;
  *statistics = self->statistics;
  return self->s.threshold_alarm == 1 ? 2 : 0;
}

ARMFAULT_PLUGIN_EXPORT const double* armfault_monitor_statistic_values(void* handle) {
  const monitor* self = handle;
  return self->values;
}

ARMFAULT_PLUGIN_EXPORT void armfault_monitor_destroy(void* handle) {
  monitor* self = handle;
  if (!self) return;
  free(self->values);
  free(self->verdicts);
  free(self->joint);
  free(self);
}

/* ------------------------------------------------------------------ commissioning (ABI minor 1) */

/* The unit's healthy commissioning run, fitted whole (no forgetting): each joint's own 1/a and
 * c/a, which its runs then divide by, so a unit whose K_T or friction differs from the datasheet
 * (its tolerances, its temperature) is judged against itself. A joint the fit cannot resolve
 * (too little motion, torque gain and friction not told apart) keeps 1 and 1: the datasheet. */
typedef struct {
  settings s;
  int joints;
  joint_model* model;
  fit* fits;       /* the whole run, per joint */
  fit* windowed;   /* as a run's watch fit (window_s), per joint */
  double* scatter; /* [joint][2]: lowest 1/a and highest c/a of the windowed fit, absolute */
  double last_t_s;
  int started;
  double* learned; /* [joint][4]: kt0, friction0, lowest kt and highest friction relative: the blob */
} commissioning;

ARMFAULT_PLUGIN_EXPORT void* armfault_monitor_commission_begin(const armfault_monitor_create_args* args, char* error,
                                                               size_t error_size) {
  commissioning* c = calloc(1, sizeof *c);
  int j;
  if (!c) {
    snprintf(error, error_size, "out of memory");
    return NULL;
  }
  if (parse_settings(args->settings_json, args->dt_s, &c->s, error, error_size) != 0) goto fail;
  c->joints = args->joint_count;
  c->model = calloc((size_t)c->joints, sizeof *c->model);
  c->fits = calloc((size_t)c->joints, sizeof *c->fits);
  c->windowed = calloc((size_t)c->joints, sizeof *c->windowed);
  c->scatter = calloc(2 * (size_t)c->joints, sizeof *c->scatter);
  c->learned = calloc(4 * (size_t)c->joints, sizeof *c->learned);
  if (!c->model || !c->fits || !c->windowed || !c->scatter || !c->learned) {
    snprintf(error, error_size, "out of memory");
    goto fail;
  }
  for (j = 0; j < c->joints; j++) {
    if (read_model(args->robot_json, j, &c->model[j], error, error_size) != 0) goto fail;
    c->scatter[2 * j] = INFINITY;
    c->scatter[2 * j + 1] = -INFINITY;
  }
  return c;
fail:
  armfault_monitor_commission_free(c);
  return NULL;
}

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_commission_tick(void* handle, double t_s, const armfault_joint_signals* joints,
                                                            int joint_count, char* error, size_t error_size) {
  commissioning* c = handle;
  double dt_s, x0, x1, y;
  int j;
  if (joint_count != c->joints) {
    snprintf(error, error_size, "commissioning: %d joints expected, got %d", c->joints, joint_count);
    return 1;
  }
  if (!c->started) {
    c->started = 1;
    c->last_t_s = t_s;
  }
  dt_s = t_s - c->last_t_s;
  c->last_t_s = t_s;
  for (j = 0; j < joint_count; j++) {
    double kt, friction;
    fit_decay(&c->windowed[j], exp(-dt_s / c->s.window_s));
    if (regressors(&c->model[j], &c->s, &joints[j], &x0, &x1, &y)) {
      fit_add(&c->fits[j], dt_s, x0, x1, y);
      fit_add(&c->windowed[j], dt_s, x0, x1, y);
    }
    if (c->windowed[j].moving_s >= c->s.min_moving_s && fit_solve(&c->windowed[j], &kt, &friction)) {
      if (kt < c->scatter[2 * j]) c->scatter[2 * j] = kt;
      if (friction > c->scatter[2 * j + 1]) c->scatter[2 * j + 1] = friction;
    }
  }
  return 0;
}

ARMFAULT_PLUGIN_EXPORT int armfault_monitor_commission_end(void* handle, double t_end_s, const void** blob,
                                                           size_t* blob_size, char* error, size_t error_size) {
  commissioning* c = handle;
  int j;
  (void)t_end_s;
  (void)error;
  (void)error_size;
  for (j = 0; j < c->joints; j++) {
    double kt0 = 1, friction0 = 1;
    if (!(c->fits[j].moving_s >= c->s.min_moving_s && fit_solve(&c->fits[j], &kt0, &friction0) && kt0 > 0 &&
          friction0 > 0)) {
      kt0 = friction0 = 1;
    }
    c->learned[4 * j] = kt0;
    c->learned[4 * j + 1] = friction0;
    /* no windowed fit at all: no scatter seen (the joint is judged, as without commissioning) */
    c->learned[4 * j + 2] = isfinite(c->scatter[2 * j]) ? c->scatter[2 * j] / kt0 : 1;
    c->learned[4 * j + 3] = isfinite(c->scatter[2 * j + 1]) ? c->scatter[2 * j + 1] / friction0 : 1;
  }
  *blob = c->learned;
  *blob_size = 4 * (size_t)c->joints * sizeof *c->learned;
  return 0;
}

ARMFAULT_PLUGIN_EXPORT void armfault_monitor_commission_free(void* handle) {
  commissioning* c = handle;
  if (!c) return;
  free(c->model);
  free(c->fits);
  free(c->windowed);
  free(c->scatter);
  free(c->learned);
  free(c);
}
