/* mbsuite native layer: the shared declarations of the step-and-record core (core.c), the time signals
 * (the signal evaluator) and the models' engine plugins and steppers (each model package's native folder).
 *
 * Everything here is compiled into one shared library against the headers of the installed mujoco wheel
 * (mbsuite.engines.native.build). Nothing here keeps global mutable state: plugins keep theirs per instance in
 * mjData.plugin_data, steppers in the user data the caller passes, so two models in two threads never mix. */
#ifndef MBSUITE_NATIVE_H_
#define MBSUITE_NATIVE_H_

#include <mujoco/mujoco.h>

/* ------------------------------------------------------------------------------------------------ plugins */
/* Every mbsuite plugin instance's data starts with this header. A plugin that meets a non-physical state (a
 * negative chamber volume, a geometry with no solution, a non-finite input) records the first fault here, returns a
 * harmless value, and the core stops the run after the current step with an error naming the instance, the fault
 * and the time. A plugin cannot raise: this is its only way out. */
typedef struct {
  int fault;          /* 0 = none; else an MBS_FAULT_* code */
  int at_load;        /* 1: found when the data was created (a configuration fault): survives mj_resetData */
  double fault_time;  /* d->time of the first fault */
  double fault_value; /* the offending value */
  const char* what;   /* the offending configuration attribute or quantity (a static string), or NULL */
  const char* text;   /* MBS_FAULT_MODEL: the model's own description of the fault (a static string) */
} mbs_plugin_header;

/* Register a plugin and remember its slot, so that the core can find mbsuite's instances in any model. */
int mbs_register_plugin(const mjpPlugin* plugin);
/* 1 if the plugin instance `instance` of m is one of mbsuite's. */
int mbs_is_own_instance(const mjModel* m, int instance);
/* Record a fault of the core's kinds (MBS_FAULT_NONFINITE) on an instance (the first one wins). */
void mbs_fault(mjData* d, int instance, int code, double value);
/* Record a fault the model describes itself (`text`: a static string, e.g. "cylinder chamber volume became <= 0"):
 * the engine layer knows no model, so every model-specific fault carries its own text. */
void mbs_model_fault(mjData* d, int instance, const char* text, double value);
/* Record a configuration fault found at init (names the attribute; survives mj_resetData). */
void mbs_config_fault(mbs_plugin_header* h, const char* what, double value);
/* A configuration fault the model describes itself: `text` says what is wrong, `what` names the attributes. */
void mbs_model_config_fault(mbs_plugin_header* h, const char* text, const char* what, double value);
/* Parse a numeric config attribute; `fallback` if absent (a NaN fallback makes it required). On a missing required,
 * malformed or non-finite value: records a configuration fault naming `key` on h and returns the fallback. */
double mbs_config_number(const mjModel* m, int instance, const char* key, double fallback, mbs_plugin_header* h);
/* Configuration check: if !ok, records a configuration fault naming `what` with `value`. Returns ok. */
int mbs_config_require(mbs_plugin_header* h, int ok, const char* what, double value);
/* Scan the mbsuite plugin instances of (m, d) for a fault: returns the instance id (or -1) and fills the rest; the
 * time is < 0 for a fault found when the data was created (a configuration fault); `text` is the fault's description
 * (the model's own for MBS_FAULT_MODEL, else mbs_fault_text(code)). */
int mbs_plugin_fault(const mjModel* m, const mjData* d, int* code, double* time, double* value, const char** what,
                     const char** text);
/* 1 if more plugins were registered than the core can track (their faults would go unseen). */
int mbs_plugin_overflow(void);

/* Fault codes of the core; texts in core.c. A model's own faults are MBS_FAULT_MODEL with the model's text. */
enum {
  MBS_FAULT_NONE = 0,
  MBS_FAULT_CONFIG = 1,          /* a config attribute is missing or not a number */
  MBS_FAULT_NONFINITE = 2,       /* a non-finite input state */
  MBS_FAULT_MODEL = 3,           /* described by the model (mbs_model_fault, mbs_model_config_fault) */
};
const char* mbs_fault_text(int code);

/* ------------------------------------------------------------------------------------------------ signals */
/* A time signal as a flat array: [kind, p0, p1, ...]. Kinds and parameters (mbsuite.engines.inputs mirrors them):
 *  0 constant   [0, c]
 *  1 step       [1, offset, height, t0]                          offset + height (t >= t0)
 *  2 sine       [2, offset, amplitude, freq_hz, phase, t0]       offset + A sin(2 pi f (t - t0) + phase) (t >= t0)
 *  3 ramp       [3, offset, height, t0, duration]                linear from offset to offset + height
 *  4 pulse      [4, offset, amplitude, width, period, t0, n]     n = 0: unlimited periods; width as a fraction 0..1
 *  5 table      [5, n, t_0..t_{n-1}, y_0..y_{n-1}]               piecewise linear, held outside
 */
double mbs_signal(const double* spec, double t);
/* length of a signal spec (number of doubles), or -1 for an unknown kind */
int mbs_signal_size(const double* spec);

/* ------------------------------------------------------------------------------------------------ the core */
/* Recorded MjData quantities (mbsuite.engines.core.FIELDS mirrors them). */
enum {
  MBS_F_TIME = 0, MBS_F_QPOS, MBS_F_QVEL, MBS_F_ACT, MBS_F_CTRL, MBS_F_ACTUATOR_FORCE, MBS_F_ACTUATOR_LENGTH,
  MBS_F_ACTUATOR_VELOCITY, MBS_F_SENSORDATA, MBS_F_QFRC_PASSIVE, MBS_F_QFRC_ACTUATOR, MBS_F_ENERGY,
  MBS_F_EQ_POS, MBS_F_EQ_FORCE, MBS_F_HOOK, MBS_F_SITE_XPOS, MBS_NFIELD
};

/* Stages at which a native stepper (hook) is called. */
enum { MBS_STAGE_POST_FORWARD = 0, MBS_STAGE_POST_STEP = 1 };

/* A native stepper: called at MBS_STAGE_POST_FORWARD after mj_forward at the state of step k (it may change ctrl,
 * qvel, eq_active, ...; return 1 to have the core recompute mj_forward), and at MBS_STAGE_POST_STEP after the
 * integration. A negative return stops the run (status MBS_FAIL_HOOK, code in job.fail_code). */
typedef int (*mbs_hook_fn)(const mjModel* m, mjData* d, void* ud, long k, int stage);

/* Status of mbs_run. */
enum {
  MBS_OK = 0, MBS_FAIL_NONFINITE = 1, MBS_FAIL_BADQACC = 2 /* any MuJoCo warning of a broken state; fail_code */, MBS_FAIL_PLUGIN = 3, MBS_FAIL_BOUNDS = 4,
  MBS_FAIL_HOOK = 5, MBS_FAIL_ARGS = 6
};

/* One call of the core: run `nstep` steps from global step k0 (rows of `ctrl` are global step indices), record a
 * row at every global step that is a multiple of `every` (and the final state when `final` is set), check at a
 * cadence, stop at the first failure. Layout mirrored by mbsuite.engines.core._Job (ctypes). */
typedef struct {
  /* run */
  long nstep;            /* steps in this call */
  long k0;               /* global index of the first step */
  int final;             /* 1: after the last step, forward and record the final state (no integration) */
  /* input: d->ctrl[ctrl_idx[i]] = ctrl[k * ctrl_ncol + i] before step k (k global; rows up to ctrl_rows) */
  const double* ctrl;
  const int* ctrl_idx;
  int ctrl_ncol;
  long ctrl_rows;
  /* recording: rows of rec_ncol doubles; column 0 is time; rec = NULL records nothing */
  int every;
  double* rec;
  long rec_cap;          /* rows allocated */
  long rec_row;          /* next row to write (in/out) */
  int rec_ncol;
  int nchan;
  const int* chan_field;
  const int* chan_start;
  const int* chan_size;
  const double* lo;      /* per column plausibility bounds (column 0 unused); NULL = none */
  const double* hi;
  int check_every;       /* finite check of qpos, qvel, act every this many steps (>= 1) */
  /* native stepper */
  mbs_hook_fn hook;
  void* hook_ud;
  const double* hook_rec; /* MBS_F_HOOK reads here */
  /* out: failure */
  int status;
  long fail_step;
  double fail_time;
  int fail_col;
  double fail_value;
  int fail_plugin;        /* plugin instance id (MBS_FAIL_PLUGIN) */
  int fail_code;          /* plugin fault code, hook error, or the MuJoCo warning (mjtWarning) */
  const char* fail_what;  /* plugin fault: the offending attribute or quantity, or NULL */
  long steps_done;        /* steps integrated in this call */
  const char* fail_text;  /* plugin fault: its description (the model's own text for MBS_FAULT_MODEL) */
} mbs_job;

int mbs_run(const mjModel* m, mjData* d, mbs_job* job);
/* sizeof(mbs_job): the Python side compares it with its ctypes layout */
int mbs_job_size(void);

/* ------------------------------------------------------------------------------------------------ one-ports */
/* A mechanical one-port stepped by a host that owns the force through it (a compiled loop of a model that couples a
 * body to it through one contact). Over one host step of length dt the port force f (N; f >= 0 presses the port down) varies
 * linearly f0 -> f1, and the port answers its displacement y (m, the host's datum) at the step's end. Per step the
 * host calls `trial` any number of times, each from the committed state, then `commit`, which accepts the last
 * trial. An affine port (y exactly affine in f1) also gives its map y = P - g f1, so the host needs no iteration.
 * Implementations fill the struct with an init function of their own (`void mbs_<name>_port(mbs_port*, state*)`);
 * the state behind `self` belongs to the caller (numpy/ctypes memory). Nothing is global: one port per instance. */
typedef struct {
  void* self;                 /* the implementation's state */
  int affine;                 /* 1: `map` gives y exactly */
  int nout;                   /* outputs per recorded row (`outputs`), <= MBS_PORT_MAXOUT */
  /* affine ports: y(t + dt) = P - g f1 under f0 -> f1 */
  void (*map)(void* self, double t, double dt, double f0, double* P, double* g);
  /* y(t + dt) under f0 -> f1, the committed state unchanged: 0, or a failure code of the implementation (which keeps
     what its caller needs to describe the failure) */
  int (*trial)(void* self, double t, double dt, double f0, double f1, double* y);
  void (*commit)(void* self); /* accept the last trial */
  void (*outputs)(const void* self, double* out); /* the committed state's nout outputs (the host records them) */
} mbs_port;
#define MBS_PORT_MAXOUT 16
/* sizeof(mbs_port): the Python mirror (mbsuite.engines.native.oneport.Port) is checked against it */
int mbs_port_size(void);

/* The MuJoCo one-port: a MuJoCo model driven by one force actuator (gain 1, bias 0: ctrl = force along the actuator)
 * whose displacement is the height of one site above another. A trial restores the committed integration state
 * (mj_setState), sets ctrl = sign (f0 + f1) / 2 (the step's mean force) and advances one step through the core
 * (`mbs_run`, one step, every check: a failure is the job's status), then reads the height after mj_kinematics and
 * saves the pending state (mj_getState). Outputs: the height, then qpos[0 .. nq_out-1]. */
typedef struct {
  const mjModel* m;
  mjData* d;
  mbs_job* job;               /* the core's job for one unrecorded step (status on failure) */
  int actuator, site, origin; /* the force actuator; the site whose height is y, measured from `origin` */
  int spec;                   /* mjtState of the saved states (the integration state) */
  double sign, offset;        /* ctrl = sign * mean force; y = z(site) - z(origin) - offset */
  double* committed;          /* mj_stateSize(m, spec) doubles each */
  double* pending;
  int holds;                  /* 1 when d holds the pending state (the last trial) */
  int nq_out;                 /* qpos entries among the outputs (nout = 1 + nq_out <= MBS_PORT_MAXOUT) */
} mbs_mj_port;
void mbs_mj_port_init(mbs_port* port, mbs_mj_port* s);
int mbs_mj_port_size(void);

/* The linear one-port: a linear model x' = A x + b0 F0 - B f stepped by the trapezoidal rule, which the caller has
 * written as x_{n+1} = Phi x_n + G0 - Gf (f0 + f1); its displacement is y = c . x, its map P = cPhi . x + cG0 - cGf
 * f0, g = cGf (cPhi = c Phi, cG0 = c . G0, cGf = c . Gf); outputs Cout x (nout rows). Affine. */
typedef struct {
  int n, nout;
  const double *Phi, *G0, *Gf, *c, *cPhi, *Cout; /* n*n, n, n, n, n, nout*n */
  double cG0, cGf;
  double *x, *pending;                            /* n each: the committed state and the last trial's */
} mbs_lin_port;
void mbs_lin_port_init(mbs_port* port, mbs_lin_port* s);
int mbs_lin_port_size(void);

/* Version of the job layout; the Python side refuses a library with another. */
int mbs_abi_version(void);
#define MBS_ABI_VERSION 2

/* a * b + c as the source writes it. Compiled with -ffp-contract=off it is rounded twice (the product, then the sum);
 * a build allowed to fuse it into one FMA rounds once. With a = 1 + 2^-30, b = 1 - 2^-30, c = -1 it returns 0 when
 * unfused and -2^-60 when fused: the determinism tests ask the compiled library which it is. */
double mbs_fp_contract_probe(double a, double b, double c);

#endif  /* MBSUITE_NATIVE_H_ */
