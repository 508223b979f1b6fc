/* armfault monitor plugin ABI, version 1.1: a health monitor compiled into a shared library
 * (C, C++, Rust, ... behind a C interface) that `armfault run` loads with
 *     "monitor": {"type": "plugin", "library": "path/to/lib.so", "settings": {...}}
 * and scores exactly like its built-in monitor (docs/monitor-api.md, "C plugin").
 *
 * A plugin defines the six functions declared below, with C linkage and these exact names (and
 * may define the optional ones: armfault_monitor_create_v2 in place of armfault_monitor_create,
 * and the two that publish its statistics).
 * Including this header where they are defined lets the compiler check their signatures.
 *
 * Calls, per run (one instance per run):
 *     create (or create_v2) -> step (every controller tick, in time order) ... -> finish -> destroy
 * `verdicts` may be called after any step and after finish. After a step or finish returned an
 * error, armfault calls only destroy. destroy is called for every instance create returned,
 * also after an error. At load, armfault calls abi_version, then create and destroy once with
 * the campaign's settings (to report bad settings before any run starts).
 *
 * Ownership and lifetime: every pointer armfault passes in (the JSON texts, the signals, the
 * error buffer) is valid only for the duration of that call; copy what you keep. The verdict
 * array belongs to the instance and must stay valid, unchanged, until the next call of step,
 * finish or destroy on that instance.
 *
 * Threading: an instance is called from one thread at a time, so it needs no locks. Runs of a
 * campaign run in parallel: different instances are called concurrently from different
 * threads, and one loaded library serves every campaign in the process, so a plugin must keep
 * no mutable global or static state. abi_version may be called from any thread.
 *
 * Determinism: what an instance emits must be a function of robot_json, settings_json and the
 * sequence of steps only (no clocks, no unseeded randomness, no state shared between
 * instances): campaign results are then bit-identical for any thread count or shard split.
 *
 * Errors: a function that fails writes a NUL-terminated message of at most error_size bytes
 * (including the NUL) into `error` and returns NULL (create) or non-zero (step, finish). At
 * load, a failing create is an input error (exit status 2); during a run, a failing step or
 * finish fails that run with the message, and the campaign goes on. A plugin must not crash,
 * abort, exit or let an exception escape these functions.
 */
#ifndef ARMFAULT_MONITOR_PLUGIN_H_
#define ARMFAULT_MONITOR_PLUGIN_H_

#include <stddef.h>

#define ARMFAULT_MONITOR_PLUGIN_ABI_VERSION 1
/* The minor version: what this header added to version 1 without breaking it. A plugin built
 * against an older minor loads unchanged; one that uses a newer minor's optional function needs
 * an armfault of that minor (or must also export what the older one requires). A plugin may test
 * it (#if ARMFAULT_MONITOR_PLUGIN_ABI_MINOR >= 1) to build against either header.
 *   0  the six functions, the two statistics functions
 *   1  armfault_monitor_create_v2 (the control period, the joint count and the unit's
 *      commissioning blob at create); commissioning (armfault_monitor_commission_*);
 *      include/armfault/monitor_settings.h (reading the settings JSON in C) */
#define ARMFAULT_MONITOR_PLUGIN_ABI_MINOR 1

/* Bytes of the name buffers in armfault_verdict, including the terminating NUL. */
#define ARMFAULT_VERDICT_NAME_SIZE 32

/* Verdict states. */
#define ARMFAULT_STATE_HEALTHY 0
#define ARMFAULT_STATE_WORN 1
#define ARMFAULT_STATE_DEFECTIVE 2

#if defined(__GNUC__) || defined(__clang__)
#define ARMFAULT_PLUGIN_EXPORT __attribute__((visibility("default")))
#else
#define ARMFAULT_PLUGIN_EXPORT
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* The signals one joint's controller has at a tick, and nothing else (JointSignals in
 * core/signals/joint_signals.h). Units are in the names: rad, rad/s, N m, A, V, degrees Celsius. */
typedef struct armfault_joint_signals {
  double q_ref_rad;        /* reference position the controller tracks */
  double qd_ref_rad_s;     /* reference velocity */
  double q_meas_rad;       /* encoder, link side */
  double qd_est_rad_s;     /* the controller's velocity estimate */
  double tau_sensor_Nm;    /* joint torque sensor, after the ADC; NaN on a joint without one */
  double i_cmd_A;          /* commanded current, after the DAC */
  double i_supply_meas_A;  /* driver input current, mean over the control period */
  double v_bus_meas_V;     /* driver input (bus) voltage */
  double winding_temp_C;   /* winding temperature sensor where the robot has one, else NaN */
} armfault_joint_signals;

/* One timestamped verdict about one joint (Verdict in core/monitors/monitor.h). Emit one when
 * the monitor's view of a joint changes (state, family) or a magnitude estimate is refined. */
typedef struct armfault_verdict {
  double t_s;     /* time of the tick it was reached at, in [0, t_end_s], never decreasing */
  int joint;      /* 1-based: 1 .. joint_count */
  int state;      /* ARMFAULT_STATE_HEALTHY, _WORN or _DEFECTIVE; alarm = not healthy */
  /* A fault family of docs/faults.md ("kt_degradation", "friction_increase", ...) or "unknown";
   * "" when healthy. NUL-terminated within the buffer. */
  char family[ARMFAULT_VERDICT_NAME_SIZE];
  /* The family's own size parameter ("kt_factor", "friction_factor", ...) or "" for none. */
  char magnitude_name[ARMFAULT_VERDICT_NAME_SIZE];
  double magnitude;   /* estimate of magnitude_name; finite (0 when there is none) */
  double confidence;  /* in [0, 1] */
} armfault_verdict;

/* Returns ARMFAULT_MONITOR_PLUGIN_ABI_VERSION as the plugin was compiled against; armfault
 * refuses a library whose version differs from its own. */
ARMFAULT_PLUGIN_EXPORT int armfault_monitor_abi_version(void);

/* A new instance for one run (required unless armfault_monitor_create_v2 is exported, which
 * armfault then calls instead). robot_json: the robot as designed (datasheet values, never a
 * unit's draw or the fault), as armfault's robot JSON (docs/robot-format.md; "modules" is the
 * array of joints, base first), complete: every key of every module and link is written out with
 * its value, defaults filled in, so a plugin never needs armfault's defaults. settings_json: the campaign's "settings" object as JSON text
 * ("{}" when absent). Returns NULL on error, with the message in `error`. */
ARMFAULT_PLUGIN_EXPORT void* armfault_monitor_create(const char* robot_json, const char* settings_json, char* error,
                                                     size_t error_size);

/* What armfault_monitor_create_v2 gets (ABI minor 1). A later minor appends fields, never
 * moves or removes one: struct_size says how many this armfault filled in, so a plugin built
 * against a newer header checks ARMFAULT_CREATE_ARGS_HAS(args, field) before reading a newer
 * field. Every pointer is valid only during the call (copy what you keep). */
typedef struct armfault_monitor_create_args {
  size_t struct_size;        /* sizeof(armfault_monitor_create_args) as armfault was built */
  const char* robot_json;    /* as armfault_monitor_create's robot_json */
  const char* settings_json; /* as armfault_monitor_create's settings_json */
  double dt_s;               /* the control period [s] (> 0): step's t_s are k * dt_s, k = 0, 1, ... */
  int joint_count;           /* joints at every step (the robot's modules), >= 1 */
  /* What the plugin learned on this run's robot unit (the bytes its commission_end returned
   * for that unit), as armfault's copy: read-only, valid until this instance's destroy, and
   * shared with the other instances of that unit, which other threads may be running. NULL and
   * 0 when the campaign does not commission its units, the plugin has no commissioning
   * functions, and at load and commission_begin. */
  const void* commissioning;
  size_t commissioning_size;
} armfault_monitor_create_args;

/* True when `args` holds `field` (a member of armfault_monitor_create_args). */
#define ARMFAULT_CREATE_ARGS_HAS(args, field) \
  (offsetof(armfault_monitor_create_args, field) + sizeof((args)->field) <= (args)->struct_size)

/* Optional (ABI minor 1): a new instance for one run, told the control period and the joint
 * count as well. When the library exports it, armfault calls it wherever it would call
 * armfault_monitor_create (at load, once per run), with the same error contract; the plugin may
 * then leave armfault_monitor_create out (it needs it only to load into an armfault older than
 * minor 1, which ignores this function). */
ARMFAULT_PLUGIN_EXPORT void* armfault_monitor_create_v2(const armfault_monitor_create_args* args, char* error,
                                                        size_t error_size);

/* Optional, all four or none (ABI minor 1; needs armfault_monitor_create_v2): commissioning.
 * With "commissioning" on in the campaign, armfault runs each robot unit through a healthy
 * commissioning motion before that unit's runs (docs/campaign-format.md, "Commissioning") and
 * streams it to the plugin, once per unit, on any one thread:
 *     commission_begin -> commission_tick (every controller tick, in time order) ...
 *       -> commission_end -> commission_free
 * commission_end hands out what the plugin learned as bytes (any layout it likes: a struct, a
 * JSON text); armfault copies them, keeps the copy once per unit, and passes it read-only to
 * every run of that unit (armfault_monitor_create_args.commissioning), so runs stay
 * independent and results are the same for any thread count or shard split. The ticks are
 * given one at a time: a commissioning run may be minutes long, keep only what you need.
 * Ownership: the commissioning handle is the plugin's; armfault calls commission_free for every
 * handle commission_begin returned, also after an error. The blob commission_end points to is
 * the plugin's and must stay valid until commission_free; armfault never writes to it. After a
 * failing call only commission_free follows; the unit's runs then fail with the message. */

/* A new commissioning for one unit: args as create_v2 gets them (commissioning NULL). NULL on
 * error, with the message in `error`. */
ARMFAULT_PLUGIN_EXPORT void* armfault_monitor_commission_begin(const armfault_monitor_create_args* args, char* error,
                                                               size_t error_size);
/* One tick of the commissioning run, as step gets it. Returns 0 or non-zero with a message. */
ARMFAULT_PLUGIN_EXPORT int armfault_monitor_commission_tick(void* commissioning, double t_s,
                                                            const armfault_joint_signals* joints, int joint_count,
                                                            char* error, size_t error_size);
/* The end of the commissioning run at t_end_s: sets *blob and *blob_size (bytes, at most
 * 1 GiB; size 0 allowed, then blob may be NULL) to what was learned. Returns 0 or non-zero with
 * a message. */
ARMFAULT_PLUGIN_EXPORT int armfault_monitor_commission_end(void* commissioning, double t_end_s, const void** blob,
                                                           size_t* blob_size, char* error, size_t error_size);
/* Frees the commissioning and its blob. */
ARMFAULT_PLUGIN_EXPORT void armfault_monitor_commission_free(void* commissioning);

/* One controller tick at time t_s [s] (strictly increasing from call to call): joints[k] holds
 * the signals of joint k + 1, k = 0 .. joint_count - 1 (the same count at every tick). Returns
 * 0, or non-zero with a message in `error`. */
ARMFAULT_PLUGIN_EXPORT int armfault_monitor_step(void* self, double t_s, const armfault_joint_signals* joints,
                                                 int joint_count, char* error, size_t error_size);

/* The end of the run at t_end_s [s] (the last tick's time); the last chance to emit verdicts.
 * Returns 0, or non-zero with a message in `error`. */
ARMFAULT_PLUGIN_EXPORT int armfault_monitor_finish(void* self, double t_end_s, char* error, size_t error_size);

/* Every verdict the instance emitted so far, in time order: sets *verdicts to the first of
 * them (may be NULL when there are none) and returns their count. The list only grows: a
 * verdict once returned must not change. armfault copies the ones it has not seen yet. */
ARMFAULT_PLUGIN_EXPORT int armfault_monitor_verdicts(void* self, const armfault_verdict** verdicts);

/* Frees the instance; `self` is not used again. */
ARMFAULT_PLUGIN_EXPORT void armfault_monitor_destroy(void* self);

/* Optional, both or neither: the statistics behind the alarms, so that `armfault tune` can
 * re-score other thresholds from a campaign's stored runs without simulating again
 * (docs/monitor-api.md, "Statistics for tune"). A plugin without them is scored at its own
 * operating point, and tune says it cannot sweep it.
 *
 * The contract: at every tick, joint j alarms exactly while some statistic s has
 *     value(j, s) > threshold(s),
 * and its verdict names the family of the first such s in declaration order (a monitor whose
 * alarm latches publishes the running maximum of its statistic). tune checks this on every run
 * (the stored statistics must give the run's scored outcome at the declared thresholds) and
 * refuses a campaign whose runs break it. */
typedef struct armfault_statistic {
  char name[ARMFAULT_VERDICT_NAME_SIZE];    /* unique, e.g. "kt_deficit" */
  char family[ARMFAULT_VERDICT_NAME_SIZE];  /* the family its alarm names, or "unknown" */
  double threshold;                         /* > 0: alarms while the value is above it */
  /* The JSON pointer of the threshold in the plugin's settings ("/kt_worn"), so tune can write
   * the tuned settings; "" when the settings do not hold it. */
  char setting[2 * ARMFAULT_VERDICT_NAME_SIZE];
} armfault_statistic;

/* The instance's statistics: sets *statistics to the first and returns their count (0 .. 64).
 * Called once, right after create; the array must stay valid and unchanged until destroy. */
ARMFAULT_PLUGIN_EXPORT int armfault_monitor_statistics(void* self, const armfault_statistic** statistics);

/* After each step: the values at that tick, joint_count x count doubles, joint-major
 * (values[(joint - 1) * count + s]); NaN: no value at this tick. Valid until the next call of
 * step, finish or destroy. */
ARMFAULT_PLUGIN_EXPORT const double* armfault_monitor_statistic_values(void* self);

/* The same functions as pointer types, for a host resolving them with dlsym. */
typedef int (*armfault_monitor_abi_version_fn)(void);
typedef void* (*armfault_monitor_create_fn)(const char*, const char*, char*, size_t);
typedef void* (*armfault_monitor_create_v2_fn)(const armfault_monitor_create_args*, char*, size_t);
typedef void* (*armfault_monitor_commission_begin_fn)(const armfault_monitor_create_args*, char*, size_t);
typedef int (*armfault_monitor_commission_tick_fn)(void*, double, const armfault_joint_signals*, int, char*, size_t);
typedef int (*armfault_monitor_commission_end_fn)(void*, double, const void**, size_t*, char*, size_t);
typedef void (*armfault_monitor_commission_free_fn)(void*);
typedef int (*armfault_monitor_step_fn)(void*, double, const armfault_joint_signals*, int, char*, size_t);
typedef int (*armfault_monitor_finish_fn)(void*, double, char*, size_t);
typedef int (*armfault_monitor_verdicts_fn)(void*, const armfault_verdict**);
typedef void (*armfault_monitor_destroy_fn)(void*);
typedef int (*armfault_monitor_statistics_fn)(void*, const armfault_statistic**);
typedef const double* (*armfault_monitor_statistic_values_fn)(void*);

#ifdef __cplusplus
}
#endif

#endif /* ARMFAULT_MONITOR_PLUGIN_H_ */
