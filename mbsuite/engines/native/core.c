/* The step-and-record core: one loop for every MuJoCo path of mbsuite (see mbsuite.h for the contract).
 *
 * Per step k:  input row k -> d->ctrl;  mj_checkPos, mj_checkVel, mj_forward, mj_checkAcc (exactly mj_step's
 * preamble);  native stepper (POST_FORWARD; a dirty return recomputes mj_forward);  record the row if k is a
 * multiple of `every` (every recorded quantity is then consistent with the state at t_k);  integrate with the
 * model's integrator (mj_Euler / mj_RungeKutta / mj_implicit: what mj_step calls, so the trajectory is bitwise the
 * one of mj_step; the `discrete` integrator, which MuJoCo does not export, goes through mj_step after the
 * forward);  native stepper (POST_STEP);  checks: MuJoCo's warnings of a broken state (bad qpos, qvel, qacc or
 * ctrl; full constraint arrays) and mbsuite plugin faults
 * every step, finite qpos/qvel/act every `check_every` steps and at every recorded row, plausibility bounds on
 * every recorded value. The first failure stops the run and is reported in the job. */
#include <math.h>
#include <string.h>

#include "mbsuite.h"

/* ------------------------------------------------------------------------------------------------ plugins */
#define MBS_MAX_PLUGINS 64
static int own_slots[MBS_MAX_PLUGINS];
static int n_own_slots = 0;
static int own_overflow = 0;

int mbs_register_plugin(const mjpPlugin* plugin) {
  int slot = mjp_registerPlugin(plugin);
  if (n_own_slots < MBS_MAX_PLUGINS) {
    own_slots[n_own_slots++] = slot;
  } else {
    own_overflow = 1;
  }
  return slot;
}

int mbs_plugin_overflow(void) { return own_overflow; }

int mbs_is_own_instance(const mjModel* m, int instance) {
  int slot = m->plugin[instance];
  for (int i = 0; i < n_own_slots; i++) {
    if (own_slots[i] == slot) return 1;
  }
  return 0;
}

void mbs_fault(mjData* d, int instance, int code, double value) {
  mbs_plugin_header* h = (mbs_plugin_header*)d->plugin_data[instance];
  if (h && !h->fault) {
    h->fault = code;
    h->fault_time = d->time;
    h->fault_value = value;
  }
}

void mbs_model_fault(mjData* d, int instance, const char* text, double value) {
  mbs_plugin_header* h = (mbs_plugin_header*)d->plugin_data[instance];
  if (h && !h->fault) {
    h->fault = MBS_FAULT_MODEL;
    h->text = text;
    h->fault_time = d->time;
    h->fault_value = value;
  }
}

void mbs_model_config_fault(mbs_plugin_header* h, const char* text, const char* what, double value) {
  if (h && !h->fault) {
    mbs_config_fault(h, what, value);
    h->fault = MBS_FAULT_MODEL;
    h->text = text;
  }
}

void mbs_config_fault(mbs_plugin_header* h, const char* what, double value) {
  if (h && !h->fault) {
    h->fault = MBS_FAULT_CONFIG;
    h->at_load = 1;
    h->fault_time = 0.0;
    h->fault_value = value;
    h->what = what;
  }
}

int mbs_config_require(mbs_plugin_header* h, int ok, const char* what, double value) {
  if (!ok) mbs_config_fault(h, what, value);
  return ok;
}

double mbs_config_number(const mjModel* m, int instance, const char* key, double fallback,
                         mbs_plugin_header* h) {
  const char* s = mj_getPluginConfig(m, instance, key);
  if (!s || !s[0]) {
    if (isnan(fallback)) mbs_config_fault(h, key, NAN); /* required */
    return fallback;
  }
  char* end = NULL;
  double v = strtod(s, &end);
  int bad = end == s || !isfinite(v);
  if (!bad) {
    while (*end == ' ') end++;
    bad = *end != 0;
  }
  if (bad) {
    mbs_config_fault(h, key, NAN);
    return fallback;
  }
  return v;
}

int mbs_plugin_fault(const mjModel* m, const mjData* d, int* code, double* time, double* value, const char** what,
                     const char** text) {
  for (int i = 0; i < m->nplugin; i++) {
    if (!mbs_is_own_instance(m, i)) continue;
    const mbs_plugin_header* h = (const mbs_plugin_header*)d->plugin_data[i];
    if (h && h->fault) {
      *code = h->fault;
      *time = h->at_load ? -1.0 : h->fault_time; /* < 0: found when the data was created */
      *value = h->fault_value;
      *what = h->what;
      *text = (h->fault == MBS_FAULT_MODEL && h->text) ? h->text : mbs_fault_text(h->fault);
      return i;
    }
  }
  return -1;
}

const char* mbs_fault_text(int code) {
  switch (code) {
    case MBS_FAULT_CONFIG: return "a configuration attribute is missing, not a finite number or out of its range";
    case MBS_FAULT_NONFINITE: return "non-finite state (NaN or inf) reached the effect";
    case MBS_FAULT_MODEL: return "a fault of the effect's model";
    default: return "unknown fault";
  }
}

/* ------------------------------------------------------------------------------------------------ signals */
int mbs_signal_size(const double* spec) {
  switch ((int)spec[0]) {
    case 0: return 2;
    case 1: return 4;
    case 2: return 6;
    case 3: return 5;
    case 4: return 7;
    case 5: return 2 + 2 * (int)spec[1];
    default: return -1;
  }
}

double mbs_signal(const double* s, double t) {
  switch ((int)s[0]) {
    case 0:
      return s[1];
    case 1:
      return s[1] + (t >= s[3] ? s[2] : 0.0);
    case 2:
      return s[1] + (t >= s[5] ? s[2] * sin(2.0 * M_PI * s[3] * (t - s[5]) + s[4]) : 0.0);
    case 3: {
      double off = s[1], h = s[2], t0 = s[3], dur = s[4];
      if (t < t0) return off;
      if (dur <= 0.0 || t >= t0 + dur) return off + h;
      return off + h * (t - t0) / dur;
    }
    case 4: {
      double off = s[1], amp = s[2], width = s[3], period = s[4], t0 = s[5];
      int n = (int)s[6];
      if (t < t0) return off;
      double k = floor((t - t0) / period);
      if (n > 0 && k >= n) return off;
      double phase = (t - t0) - k * period;
      return off + (phase < width * period ? amp : 0.0);
    }
    case 5: {
      int n = (int)s[1];
      const double* tt = s + 2;
      const double* yy = s + 2 + n;
      if (t <= tt[0]) return yy[0];
      if (t >= tt[n - 1]) return yy[n - 1];
      int lo = 0, hi = n - 1;
      while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (tt[mid] <= t) lo = mid; else hi = mid;
      }
      double dt = tt[hi] - tt[lo];
      return dt > 0.0 ? yy[lo] + (yy[hi] - yy[lo]) * (t - tt[lo]) / dt : yy[hi];
    }
    default:
      return NAN;
  }
}

/* ------------------------------------------------------------------------------------------------ the core */
int mbs_abi_version(void) { return MBS_ABI_VERSION; }

double mbs_fp_contract_probe(double a, double b, double c) { return a * b + c; }

static int finite_state(const mjModel* m, const mjData* d) {
  for (int i = 0; i < m->nq; i++) if (!isfinite(d->qpos[i])) return 0;
  for (int i = 0; i < m->nv; i++) if (!isfinite(d->qvel[i])) return 0;
  for (int i = 0; i < m->na; i++) if (!isfinite(d->act[i])) return 0;
  return 1;
}

/* rows of the equality constraint `eq` in the current efc arrays: copy up to n values of arr (0 if inactive) */
static void eq_rows(const mjData* d, int eq, const mjtNum* arr, double* out, int n) {
  int j = 0;
  for (int r = 0; r < d->nefc && j < n; r++) {
    if (d->efc_type[r] == mjCNSTR_EQUALITY && d->efc_id[r] == eq) out[j++] = arr[r];
  }
  for (; j < n; j++) out[j] = 0.0;
}

static void copy_field(const mjModel* m, const mjData* d, const mbs_job* J, int f, int start, int size, double* out) {
  const mjtNum* src = NULL;
  switch (f) {
    case MBS_F_TIME: src = &d->time; break;
    case MBS_F_QPOS: src = d->qpos; break;
    case MBS_F_QVEL: src = d->qvel; break;
    case MBS_F_ACT: src = d->act; break;
    case MBS_F_CTRL: src = d->ctrl; break;
    case MBS_F_ACTUATOR_FORCE: src = d->actuator_force; break;
    case MBS_F_ACTUATOR_LENGTH: src = d->actuator_length; break;
    case MBS_F_ACTUATOR_VELOCITY: src = d->actuator_velocity; break;
    case MBS_F_SENSORDATA: src = d->sensordata; break;
    case MBS_F_QFRC_PASSIVE: src = d->qfrc_passive; break;
    case MBS_F_QFRC_ACTUATOR: src = d->qfrc_actuator; break;
    case MBS_F_ENERGY: src = d->energy; break;
    case MBS_F_SITE_XPOS: src = d->site_xpos; break;
    case MBS_F_HOOK: src = J->hook_rec; break;
    case MBS_F_EQ_POS: eq_rows(d, start, d->efc_pos, out, size); return;
    case MBS_F_EQ_FORCE: eq_rows(d, start, d->efc_force, out, size); return;
    default: break;
  }
  if (src) {
    memcpy(out, src + start, sizeof(double) * (size_t)size);
  } else {
    for (int i = 0; i < size; i++) out[i] = NAN;
  }
  (void)m;
}

static void fail(mbs_job* J, int status, long k, double t) {
  J->status = status;
  J->fail_step = k;
  J->fail_time = t;
}

/* record one row; returns 0 or a failure status */
static int record(const mjModel* m, const mjData* d, mbs_job* J, long k) {
  if (J->rec_row >= J->rec_cap) {
    fail(J, MBS_FAIL_ARGS, k, d->time);
    return MBS_FAIL_ARGS;
  }
  double* row = J->rec + J->rec_row * J->rec_ncol;
  row[0] = d->time;
  int col = 1;
  for (int c = 0; c < J->nchan; c++) {
    copy_field(m, d, J, J->chan_field[c], J->chan_start[c], J->chan_size[c], row + col);
    col += J->chan_size[c];
  }
  J->rec_row++;
  if (!finite_state(m, d)) {
    fail(J, MBS_FAIL_NONFINITE, k, d->time);
    return MBS_FAIL_NONFINITE;
  }
  for (int c = 1; c < J->rec_ncol; c++) {
    double v = row[c];
    int ok = isfinite(v) && (!J->lo || v >= J->lo[c]) && (!J->hi || v <= J->hi[c]);
    if (!ok) {
      fail(J, MBS_FAIL_BOUNDS, k, d->time);
      J->fail_col = c;
      J->fail_value = v;
      return MBS_FAIL_BOUNDS;
    }
  }
  return MBS_OK;
}

/* MuJoCo's warnings that mean the state is garbage: bad qpos/qvel/qacc/ctrl, full constraint or contact arrays */
static const int bad_warnings[] = {mjWARN_BADQPOS, mjWARN_BADQVEL, mjWARN_BADQACC, mjWARN_BADCTRL, mjWARN_CNSTRFULL,
                                   mjWARN_CONTACTFULL};
#define N_BAD_WARNINGS ((int)(sizeof(bad_warnings) / sizeof(bad_warnings[0])))

/* the first bad warning counted during this call (the counters were zeroed at entry), or -1 */
static int new_bad_warning(const mjData* d) {
  for (int i = 0; i < N_BAD_WARNINGS; i++) {
    if (d->warning[bad_warnings[i]].number > 0) return bad_warnings[i];
  }
  return -1;
}

static int plugin_faults(const mjModel* m, const mjData* d, mbs_job* J, long k, double tk) {
  if (!m->nplugin) return MBS_OK;
  int code;
  double time, value;
  const char *what, *text;
  int i = mbs_plugin_fault(m, d, &code, &time, &value, &what, &text);
  if (i < 0) return MBS_OK;
  fail(J, MBS_FAIL_PLUGIN, k, time);
  J->fail_plugin = i;
  J->fail_code = code;
  J->fail_value = value;
  J->fail_what = what;
  J->fail_text = text;
  return MBS_FAIL_PLUGIN;
}

int mbs_job_size(void) { return (int)sizeof(mbs_job); }

int mbs_run(const mjModel* m, mjData* d, mbs_job* J) {
  J->status = MBS_OK;
  J->steps_done = 0;
  J->fail_col = -1;
  J->fail_plugin = -1;
  J->fail_code = 0;
  J->fail_what = NULL;
  J->fail_text = NULL;
  if (J->every < 1 || J->check_every < 1 || J->nstep < 0 || (J->ctrl && (!J->ctrl_idx || J->ctrl_ncol < 1))) {
    fail(J, MBS_FAIL_ARGS, J->k0, d->time);
    return J->status;
  }
  const int integrator = m->opt.integrator;
  const int split = integrator == mjINT_EULER || integrator == mjINT_RK4 || integrator == mjINT_IMPLICIT ||
                    integrator == mjINT_IMPLICITFAST;
  /* MuJoCo resets the data when it meets a broken state, which zeroes every warning counter and then counts the new
   * warning: a counter compared with its value at entry could miss it. The counters are zeroed here, any count is a
   * failure, and the caller's counts are added back on the way out. */
  int warn0[N_BAD_WARNINGS];
  for (int i = 0; i < N_BAD_WARNINGS; i++) {
    warn0[i] = d->warning[bad_warnings[i]].number;
    d->warning[bad_warnings[i]].number = 0;
  }
  const long n = J->nstep + (J->final ? 1 : 0);
  for (long i = 0; i < n; i++) {
    const long k = J->k0 + i;
    const int last = i == J->nstep;
    const double tk = d->time; /* the state's time (a reset by MuJoCo would zero d->time) */
    if (!last && J->ctrl && k < J->ctrl_rows) {
      const double* row = J->ctrl + k * J->ctrl_ncol;
      for (int c = 0; c < J->ctrl_ncol; c++) d->ctrl[J->ctrl_idx[c]] = row[c];
    }
    const int rec_now = J->rec != NULL && (last || k % J->every == 0);
    if (last && !rec_now) break;
    if (split || rec_now || J->hook) {
      mj_checkPos(m, d);
      mj_checkVel(m, d);
      mj_forward(m, d);
      mj_checkAcc(m, d);
      if (plugin_faults(m, d, J, k, tk)) goto done;
      int w = new_bad_warning(d);
      if (w >= 0) {
        fail(J, MBS_FAIL_BADQACC, k, tk);
        J->fail_code = w;
        goto done;
      }
      if (J->hook) {
        int r = J->hook(m, d, J->hook_ud, k, MBS_STAGE_POST_FORWARD);
        if (r < 0) {
          fail(J, MBS_FAIL_HOOK, k, tk);
          J->fail_code = r;
          goto done;
        }
        if (r > 0) {
          mj_forward(m, d);
          mj_checkAcc(m, d);
          if (plugin_faults(m, d, J, k, tk)) goto done;
        }
      }
      if (rec_now && record(m, d, J, k)) goto done;
    }
    if (last) break;
    switch (integrator) {
      case mjINT_EULER: mj_Euler(m, d); break;
      case mjINT_RK4: mj_RungeKutta(m, d, 4); break;
      case mjINT_IMPLICIT:
      case mjINT_IMPLICITFAST: mj_implicit(m, d); break;
      default: mj_step(m, d); break; /* the discrete integrator: mj_step repeats the forward */
    }
    J->steps_done++;
    if (J->hook) {
      int r = J->hook(m, d, J->hook_ud, k, MBS_STAGE_POST_STEP);
      if (r < 0) {
        fail(J, MBS_FAIL_HOOK, k, tk);
        J->fail_code = r;
        goto done;
      }
    }
    if (plugin_faults(m, d, J, k, tk)) goto done;
    int w = new_bad_warning(d);
    if (w >= 0) {
      fail(J, MBS_FAIL_BADQACC, k, tk);
      J->fail_code = w;
      goto done;
    }
    if ((k + 1) % J->check_every == 0 && !finite_state(m, d)) {
      fail(J, MBS_FAIL_NONFINITE, k, tk);
      goto done;
    }
  }
done:
  for (int i = 0; i < N_BAD_WARNINGS; i++) d->warning[bad_warnings[i]].number += warn0[i];
  return J->status;
}
