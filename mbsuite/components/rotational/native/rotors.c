/* The rotor library's stick/slip state machine as a native stepper of the core (an mbs_hook_fn): friction elements with
 * real MuJoCo locks, their lock trials, event times, the energy bookkeeping and the recorded row, per step in C.
 *
 * The semantics are those of Modelica's Rotational PartialFriction (modes -1 backward, 0 stuck, 1 forward, 2 free)
 * on a MuJoCo model whose rotors are hinge joints (mbsuite/components/rotational/mujoco_sim.py describes the MJCF
 * conventions). mbsuite/components/rotational/stepper.py (RotorStepper) is the readable Python twin of this file, statement
 * for statement; a test holds the two equal.
 *
 * Per step k (t = k dt), at MBS_STAGE_POST_FORWARD (the core has just run mj_forward at the state and the control of
 * the previous step, so the lock forces of the stuck elements are current):
 *   levels at t (sliding torque of each part = level x command x max(0, schedule(t)), summed per element);
 *   mode decisions at t: level <= free_tol -> free; free -> sliding in the direction of the slip (or a lock trial at
 *   zero slip); sliding and armed (it has slid in its direction since it started) whose slip reversed -> lock trial;
 *   stuck whose lock force exceeds peak x level -> sliding in the direction of the force (not armed);
 *   lock trials: the velocities of the rigid groups of the stuck elements are set to their momentum-weighted means
 *   (plastic impact; the kinetic energy removed is the lock-impact loss), the lock equalities are switched, the
 *   sliding torques and sources set at t, mj_forward; the most overloaded stuck element (lock force / breakaway > 1)
 *   is released and the trial repeated until every stuck element holds;
 *   events: each mode change with its time interpolated linearly in the event function (slip for a sliding element,
 *   breakaway - |lock force| for a stuck one) between the previous step and this one;
 *   the sliding torques held over the step: levels at mid-step if a schedule varies in time, sources at mid-step;
 *   if that changed the control, the stages of the forward that depend on it are redone (mj_forwardSkip from the
 *   velocity stage: the state and the locks are those of the last forward), so d always leaves with the forward
 *   the integrator needs and the core never repeats a full one.
 * At MBS_STAGE_POST_STEP: the work of the step: sources c0 shape(t + dt/2) dq + c1 (w0^2 + w1^2)/2 dt, viscous
 * B (w0^2 + w1^2)/2 dt, each sliding part mode x level x relative displacement (exact for the held torques).
 *
 * General elements (`general`: a relative speed g . w over the rotors, e.g. behind an ideal planetary; locked by a
 * tendon equality on the fixed tendon g . q, whose force acts as -g tau_e: eqsign -1), one-way clutches (Modelica
 * OneWayClutch: slide forward only, lock at zero slip, hold any torque toward negative slip, release when the lock
 * force exceeds peak x level, or `hold` while disengaged), dampers between rotors (their loss after the parts'
 * terms) and quadratic speed-dependent sources (c2 w^2, held over the step at the speed predicted at mid-step) are
 * no-ops for systems without them.
 *
 * The model's eq_data of a lock is written when the lock engages (each run owns its model). Nothing here is global:
 * two runs in two threads never mix. */
#include <math.h>
#include <string.h>

#include "mbsuite.h"

enum { DRV_FWD = 1, DRV_STUCK = 0, DRV_BWD = -1, DRV_FREE = 2 };

/* error codes returned to the core (negative) */
enum {
  DRV_ERR_NONFINITE = -1, /* a non-finite rotor speed, position or lock force */
  DRV_ERR_CHATTER = -2,   /* an element changed mode chatter_n times within chatter_window steps */
  DRV_ERR_EVENTS = -3,    /* the event buffer is full (the caller drains it too rarely) */
  DRV_ERR_TRIALS = -4,    /* the lock trials did not settle */
  DRV_ERR_LEVEL = -5,     /* a schedule or source shape is not finite */
};

#define DRV_ZERO_SLIP 1e-12 /* rad/s: a free element engaging at a smaller slip is tried for a lock */

/* Layout mirrored by mbsuite.components.rotational.native_stepper._Rotors (ctypes). Arrays are numpy buffers owned by the
 * Python side, which keeps them alive during the run. */
typedef struct {
  int n, ne, npart, nsrc, neq, timevar, chatter_n, chatter_window;
  double dt;
  /* rotors: dof and qpos address, inertia, viscous coefficient (n) */
  const int* dof;
  const int* qadr;
  const double* J;
  const double* B;
  /* friction elements (ne): rotors a, b (-1 = ground), breakaway factor, free tolerance, lock equality, actuator and
   * its sign; eq2el (neq): element of each equality or -1 */
  const int* ea;
  const int* eb;
  const double* peak;
  const double* free_tol;
  const int* eq;
  const int* act;
  const double* act_sign;
  const int* eq2el;
  /* parts (npart): owning element, level, command index (-1 none), schedule offset in sig (-1 none) */
  const int* owner;
  const double* level;
  const int* cmd;
  const int* sched;
  /* sources (nsrc): rotor, c0, c1, actuator, shape offset in sig (-1: shape 1) */
  const int* sbody;
  const double* c0;
  const double* c1;
  const int* sact;
  const int* shape;
  const double* sig; /* signal specs, concatenated */
  const double* u;   /* command states, written by the caller between steps */
  /* state */
  int* modes;      /* ne */
  int* armed;      /* ne */
  int* old;        /* ne */
  int* scratch;    /* 2 n + 2 + 2 ne: groups (n + 1), group sizes (n + 1), trials (ne), seen (ne) */
  long* chatter;   /* ne x chatter_n: steps of the last mode changes (ring) */
  long* nchange;   /* ne */
  double* lam;     /* ne: lock forces of the last forward */
  double* gprev;   /* ne: event function after the previous step's decisions */
  double* gnow;    /* ne: event function before this step's decisions */
  double* wr;      /* ne */
  double* lv;      /* npart: levels at t */
  double* el;      /* ne */
  double* lvm;     /* npart: levels held over the step */
  double* elm;     /* ne */
  double* wa;      /* n: speeds and positions at the start of the step (after the decisions) */
  double* qa;
  double* wtmp;    /* 2 n + 2 */
  double* acc;     /* 1 + n + npart: source, viscous per rotor, per part */
  double* ctrl0;   /* nu: control before the held torques are set */
  int first;
  int decided;     /* POST_FORWARD of the current step done (reset at POST_STEP) */
  double reset_energy;
  long lock_trials;
  /* the recorded row: q (n), w (n), modes (ne), u (ncmd), acc (1 + n + npart), lock impact */
  double* rec;
  int ncmd;
  /* events: rows of 5 doubles (t interpolated, t applied, element, from, to) */
  double* ev;
  long ev_cap;
  long ev_n;
  /* error detail */
  int err_index;
  double err_time;
  double err_value;
  /* general relative-speed rows (ne x n; used when general), lock force sign per element (+1 joint equality, -1
   * tendon equality), one-way flags and hold torques (ne) */
  int general;
  const double* grow;
  const double* eqsign;
  const int* oneway;
  const double* hold;
  /* dampers (ndamp): rotors a, b (-1 = ground), coefficient; quadratic sources: c2 (nsrc), held torque (nsrc) */
  int ndamp;
  const int* da;
  const int* db;
  const double* dD;
  const double* c2;
  double* sheld;
  /* work space of the general plastic impact: ne (ne + 1) + ne doubles, 2 ne ints */
  double* gmat;
  int* gidx;
} mbs_rotors;

static int fail(mbs_rotors* S, int code, int index, double t, double value) {
  S->err_index = index;
  S->err_time = t;
  S->err_value = value;
  return code;
}

static inline double w_of(const mjData* d, const mbs_rotors* S, int i) { return d->qvel[S->dof[i]]; }
static inline double q_of(const mjData* d, const mbs_rotors* S, int i) { return d->qpos[S->qadr[i]]; }

static inline int sliding(int mode) { return mode == DRV_FWD || mode == DRV_BWD; }

/* sliding torque of every part and element at time t under the current commands */
static int levels(mbs_rotors* S, double t, double* lv, double* el) {
  for (int e = 0; e < S->ne; e++) el[e] = 0.0;
  for (int p = 0; p < S->npart; p++) {
    double v = S->level[p];
    if (S->cmd[p] >= 0) v *= S->u[S->cmd[p]];
    if (S->sched[p] >= 0) {
      double s = mbs_signal(S->sig + S->sched[p], t);
      if (!isfinite(s)) return fail(S, DRV_ERR_LEVEL, p, t, s);
      v *= s > 0.0 ? s : 0.0;
    }
    lv[p] = v;
    el[S->owner[p]] += v;
  }
  return 0;
}

static int source_shape(mbs_rotors* S, int s, double t, double* out) {
  if (S->shape[s] < 0) {
    *out = 1.0;
    return 0;
  }
  double v = mbs_signal(S->sig + S->shape[s], t);
  if (!isfinite(v)) return fail(S, DRV_ERR_LEVEL, S->npart + s, t, v);
  *out = v;
  return 0;
}

static void slips(const mjData* d, mbs_rotors* S) {
  for (int e = 0; e < S->ne; e++) {
    if (S->general) {
      double v = 0.0;
      for (int i = 0; i < S->n; i++) v += S->grow[e * S->n + i] * w_of(d, S, i);
      S->wr[e] = v;
    } else {
      S->wr[e] = (S->eb[e] >= 0 ? w_of(d, S, S->eb[e]) : 0.0) - w_of(d, S, S->ea[e]);
    }
  }
}

/* breakaway torque of element e at levels el (a disengaged one-way clutch: its hold torque) */
static inline double capacity(const mbs_rotors* S, int e, const double* el) {
  if (S->oneway[e] && el[e] <= S->free_tol[e]) return S->hold[e];
  return S->peak[e] * el[e];
}

/* how far a lock force is past the breakaway torque (> 1: it breaks); a one-way clutch holds any negative force */
static inline double overload(const mbs_rotors* S, int e, const double* el) {
  double lam = S->oneway[e] ? (S->lam[e] > 0.0 ? S->lam[e] : 0.0) : fabs(S->lam[e]);
  return lam / capacity(S, e, el);
}

/* lock forces of the friction elements from the last forward (first row of each equality; 0 where inactive) */
static int lock_forces(const mjData* d, mbs_rotors* S, double t) {
  int* seen = S->scratch + 2 * S->n + 2 + S->ne;
  for (int e = 0; e < S->ne; e++) {
    S->lam[e] = 0.0;
    seen[e] = 0;
  }
  for (int r = 0; r < d->nefc; r++) {
    if (d->efc_type[r] != mjCNSTR_EQUALITY) continue;
    int id = d->efc_id[r];
    int e = id >= 0 && id < S->neq ? S->eq2el[id] : -1;
    if (e >= 0 && !seen[e]) {
      S->lam[e] = S->eqsign[e] * d->efc_force[r];
      seen[e] = 1;
      if (!isfinite(S->lam[e])) return fail(S, DRV_ERR_NONFINITE, e, t, S->lam[e]);
    }
  }
  return 0;
}

static int find(int* parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

/* Switch the locks to the stuck set: plastic impact (the speeds of each rigid group of rotors joined by stuck
 * elements become its momentum-weighted mean, 0 for a group held to the ground), lock offsets of newly engaged
 * locks, equality activation. Returns the kinetic energy removed. */
/* general systems: the plastic impact is the M-orthogonal projection of the speeds onto the stuck elements'
 * constraints, w -= M^-1 G^T (G M^-1 G^T)^-1 G w (M = diag J), by Gaussian elimination with partial pivoting;
 * a dependent constraint (pivot below 1e-12 of the largest diagonal) carries no impulse. */
static double project(mjData* d, mbs_rotors* S) {
  const int n = S->n, ne = S->ne;
  int* rows = S->gidx; /* the stuck elements (ne) */
  int k = 0;
  for (int e = 0; e < ne; e++) {
    if (S->modes[e] == DRV_STUCK) rows[k++] = e;
  }
  double dke = 0.0;
  if (!k) return 0.0;
  double* Sm = S->gmat;      /* k x (k + 1): [G M^-1 G^T | G w] */
  double* lam = S->gmat + (size_t)ne * (ne + 1);
  double dmax = 0.0;
  for (int r = 0; r < k; r++) {
    const double* gr = S->grow + rows[r] * n;
    for (int c = 0; c < k; c++) {
      const double* gc = S->grow + rows[c] * n;
      double v = 0.0;
      for (int i = 0; i < n; i++) v += gr[i] * gc[i] / S->J[i];
      Sm[r * (k + 1) + c] = v;
    }
    double b = 0.0;
    for (int i = 0; i < n; i++) b += gr[i] * w_of(d, S, i);
    Sm[r * (k + 1) + k] = b;
    if (Sm[r * (k + 1) + r] > dmax) dmax = Sm[r * (k + 1) + r];
  }
  int* piv = S->gidx + ne; /* column -> pivot row, or -1 (ne) */
  for (int c = 0; c < k; c++) piv[c] = -1;
  int used = 0;
  for (int c = 0; c < k; c++) {
    int best = -1;
    double bv = 1e-12 * dmax;
    for (int r = used; r < k; r++) {
      if (fabs(Sm[r * (k + 1) + c]) > bv) {
        bv = fabs(Sm[r * (k + 1) + c]);
        best = r;
      }
    }
    if (best < 0) continue;
    if (best != used) {
      for (int j = 0; j <= k; j++) {
        double tmp = Sm[used * (k + 1) + j];
        Sm[used * (k + 1) + j] = Sm[best * (k + 1) + j];
        Sm[best * (k + 1) + j] = tmp;
      }
    }
    for (int r = 0; r < k; r++) {
      if (r == used) continue;
      double f = Sm[r * (k + 1) + c] / Sm[used * (k + 1) + c];
      if (f == 0.0) continue;
      for (int j = c; j <= k; j++) Sm[r * (k + 1) + j] -= f * Sm[used * (k + 1) + j];
    }
    piv[c] = used++;
  }
  for (int c = 0; c < k; c++) lam[c] = piv[c] >= 0 ? Sm[piv[c] * (k + 1) + k] / Sm[piv[c] * (k + 1) + c] : 0.0;
  for (int i = 0; i < n; i++) {
    double w = w_of(d, S, i), dw = 0.0;
    for (int c = 0; c < k; c++) dw += S->grow[rows[c] * n + i] * lam[c];
    double wn = w - dw / S->J[i];
    dke += S->J[i] * (w * w - wn * wn);
    d->qvel[S->dof[i]] = wn;
  }
  return dke;
}

static double engage(const mjModel* mc, mjData* d, mbs_rotors* S) {
  mjModel* m = (mjModel*)mc; /* the lock offsets live in the run's own model */
  const int n = S->n;
  if (S->general) {
    double dke = project(d, S);
    for (int e = 0; e < S->ne; e++) {
      int on = S->modes[e] == DRV_STUCK;
      int k = S->eq[e];
      if (on && !d->eq_active[k]) {
        double off = 0.0;
        if (m->eq_type[k] == mjEQ_TENDON) {
          for (int i = 0; i < n; i++) off += S->grow[e * n + i] * q_of(d, S, i);
          m->eq_data[k * mjNEQDATA + 1] = 0.0;
        } else {
          off = q_of(d, S, S->ea[e]) - (S->eb[e] >= 0 ? q_of(d, S, S->eb[e]) : 0.0);
          m->eq_data[k * mjNEQDATA + 1] = S->eb[e] >= 0 ? 1.0 : 0.0;
        }
        m->eq_data[k * mjNEQDATA + 0] = off;
      }
      d->eq_active[k] = (mjtByte)on;
    }
    return 0.5 * dke;
  }
  int* parent = S->scratch;         /* n + 1 nodes, n = ground */
  int* size = S->scratch + n + 1;   /* rotors per group */
  double* sJ = S->wtmp;             /* n + 1 */
  double* sJw = S->wtmp + n + 1;    /* n + 1 */
  for (int i = 0; i <= n; i++) {
    parent[i] = i;
    size[i] = 0;
    sJ[i] = 0.0;
    sJw[i] = 0.0;
  }
  for (int e = 0; e < S->ne; e++) {
    if (S->modes[e] != DRV_STUCK) continue;
    int a = find(parent, S->ea[e]), b = find(parent, S->eb[e] >= 0 ? S->eb[e] : n);
    if (a == b) continue;
    if (a == n) {  /* keep the ground as the root of its group */
      parent[b] = a;
    } else {
      parent[a] = b;
    }
  }
  int ground = find(parent, n);
  for (int i = 0; i < n; i++) {
    int r = find(parent, i);
    size[r]++;
    sJ[r] += S->J[i];
    sJw[r] += S->J[i] * w_of(d, S, i);
  }
  double dke = 0.0;
  for (int i = 0; i < n; i++) {
    int r = find(parent, i);
    double w = w_of(d, S, i), wn = w;
    if (r == ground) {
      wn = 0.0;
    } else if (size[r] > 1) {
      wn = sJw[r] / sJ[r];
    }
    dke += S->J[i] * (w * w - wn * wn);
    d->qvel[S->dof[i]] = wn;
  }
  for (int e = 0; e < S->ne; e++) {
    int on = S->modes[e] == DRV_STUCK;
    int k = S->eq[e];
    if (on && !d->eq_active[k]) {
      m->eq_data[k * mjNEQDATA + 0] = q_of(d, S, S->ea[e]) - (S->eb[e] >= 0 ? q_of(d, S, S->eb[e]) : 0.0);
      m->eq_data[k * mjNEQDATA + 1] = S->eb[e] >= 0 ? 1.0 : 0.0;
    }
    d->eq_active[k] = (mjtByte)on;
  }
  return 0.5 * dke;
}

/* sliding torques of the elements at levels el, sources at time t; a quadratic source's torque at the speed now
 * (mid = 0) or predicted at mid-step from the last forward's acceleration (mid = 1; held over the step) */
static int set_ctrl(mjData* d, mbs_rotors* S, double t, const double* el, int mid) {
  for (int e = 0; e < S->ne; e++) {
    double tau = sliding(S->modes[e]) ? S->modes[e] * el[e] : 0.0;
    d->ctrl[S->act[e]] = S->act_sign[e] * tau;
  }
  for (int s = 0; s < S->nsrc; s++) {
    double v;
    int r = source_shape(S, s, t, &v);
    if (r) return r;
    if (S->c2[s] != 0.0) {
      int dof = S->dof[S->sbody[s]];
      double w = d->qvel[dof] + (mid ? 0.5 * S->dt * d->qacc[dof] : 0.0);
      v = S->c0[s] * v + S->c2[s] * w * w; /* the actuator's gain is 1 */
      S->sheld[s] = v;
    }
    d->ctrl[S->sact[s]] = v;
  }
  return 0;
}

/* a mode change of element e at step k: time interpolated in the event function, chatter check */
static int note(mbs_rotors* S, long k, double t, int e, int from, int to) {
  double te = t, gp = S->gprev[e], gn = S->gnow[e];
  if (isfinite(gp) && isfinite(gn) && gp != gn) {
    double frac = gn / (gn - gp);
    if (frac >= 0.0 && frac <= 1.0) te = t - frac * S->dt;
  }
  if (S->ev_n >= S->ev_cap) return fail(S, DRV_ERR_EVENTS, e, t, (double)S->ev_cap);
  double* row = S->ev + 5 * S->ev_n++;
  row[0] = te;
  row[1] = t;
  row[2] = e;
  row[3] = from;
  row[4] = to;
  long* ring = S->chatter + (long)e * S->chatter_n;
  long i = S->nchange[e]++ % S->chatter_n;
  if (S->nchange[e] > S->chatter_n && k - ring[i] < S->chatter_window) {
    return fail(S, DRV_ERR_CHATTER, e, t, (double)(k - ring[i]));
  }
  ring[i] = k;
  return 0;
}

/* event function of each element: slip in the sliding direction, or breakaway - |lock force| when stuck */
static void event_function(mbs_rotors* S, double* g, int stuck_too) {
  for (int e = 0; e < S->ne; e++) {
    int md = S->modes[e];
    if (sliding(md)) {
      g[e] = md * S->wr[e];
    } else if (md == DRV_STUCK && stuck_too) {
      g[e] = capacity(S, e, S->el) - (S->oneway[e] ? S->lam[e] : fabs(S->lam[e]));
    } else {
      g[e] = NAN;
    }
  }
}

static void fill_record(const mjData* d, mbs_rotors* S) {
  const int n = S->n, ne = S->ne;
  double* r = S->rec;
  for (int i = 0; i < n; i++) r[i] = q_of(d, S, i);
  for (int i = 0; i < n; i++) r[n + i] = w_of(d, S, i);
  for (int e = 0; e < ne; e++) r[2 * n + e] = S->modes[e];
  for (int c = 0; c < S->ncmd; c++) r[2 * n + ne + c] = S->u[c];
  const int na = 1 + n + S->npart + S->ndamp;
  for (int i = 0; i < na; i++) r[2 * n + ne + S->ncmd + i] = S->acc[i];
  r[2 * n + ne + S->ncmd + na] = S->reset_energy;
}

static int decide(const mjModel* m, mjData* d, mbs_rotors* S, long k) {
  const int n = S->n, ne = S->ne;
  const double dt = S->dt, t = (double)k * dt;
  for (int i = 0; i < n; i++) {
    if (!isfinite(w_of(d, S, i)) || !isfinite(q_of(d, S, i))) return fail(S, DRV_ERR_NONFINITE, -1 - i, t, NAN);
  }
  int r = levels(S, t, S->lv, S->el);
  if (r) return r;
  slips(d, S);
  memcpy(S->old, S->modes, sizeof(int) * (size_t)ne);
  int any_stuck = 0;
  if (!S->first) {
    for (int e = 0; e < ne; e++) any_stuck |= S->modes[e] == DRV_STUCK;
  }
  if (any_stuck && (r = lock_forces(d, S, t))) return r;
  event_function(S, S->gnow, any_stuck);
  int* trial = S->scratch + 2 * S->n + 2;
  int ntrial = 0, changed = 0;
  for (int e = 0; e < ne; e++) {
    int md = S->modes[e];
    double wr = S->wr[e];
    if (S->oneway[e]) { /* Modelica OneWayClutch: stuck = locked or w_rel <= 0; slides forward only */
      if (md == DRV_FREE) {
        if (wr > DRV_ZERO_SLIP) {
          S->modes[e] = DRV_FWD;
          S->armed[e] = 1;
        } else {
          trial[ntrial++] = e;
        }
      } else if (md == DRV_FWD) {
        if (wr > 0.0) {
          S->armed[e] = 1;
        } else if (S->armed[e]) {
          trial[ntrial++] = e;
        }
      } else if (md == DRV_STUCK && !S->first && S->lam[e] > capacity(S, e, S->el)) {
        S->modes[e] = DRV_FWD;
        S->armed[e] = 0;
      }
    } else if (S->el[e] <= S->free_tol[e]) {
      S->modes[e] = DRV_FREE;
    } else if (md == DRV_FREE) {
      if (fabs(wr) < DRV_ZERO_SLIP) {
        trial[ntrial++] = e;
      } else {
        S->modes[e] = wr > 0.0 ? DRV_FWD : DRV_BWD;
        S->armed[e] = 1;
      }
    } else if (sliding(md)) {
      if (md * wr > 0.0) {
        S->armed[e] = 1;
      } else if (S->armed[e]) {
        trial[ntrial++] = e;
      }
    } else if (md == DRV_STUCK && !S->first) {
      double lam = S->lam[e];
      if (fabs(lam) > S->peak[e] * S->el[e]) {
        S->modes[e] = lam > 0.0 ? DRV_FWD : DRV_BWD;
        S->armed[e] = 0;
      }
    }
    changed |= S->modes[e] != S->old[e];
  }
  if (ntrial || changed) {
    for (int i = 0; i < ntrial; i++) S->modes[trial[i]] = DRV_STUCK;
    int settled = 0;
    for (int it = 0; it < 2 * ne + 2 && !settled; it++) {
      S->reset_energy += engage(m, d, S);
      if ((r = set_ctrl(d, S, t, S->el, 0))) return r;
      mj_forward(m, d);
      if ((r = lock_forces(d, S, t))) return r;
      S->lock_trials++;
      int worst = -1;
      double wratio = 0.0;
      for (int e = 0; e < ne; e++) {
        if (S->modes[e] != DRV_STUCK) continue;
        double ratio = overload(S, e, S->el);
        if (worst < 0 || ratio > wratio) {
          worst = e;
          wratio = ratio;
        }
      }
      if (worst < 0 || wratio <= 1.0) {
        settled = 1;
      } else {
        S->modes[worst] = S->lam[worst] > 0.0 ? DRV_FWD : DRV_BWD;
        S->armed[worst] = 0;
      }
    }
    if (!settled) return fail(S, DRV_ERR_TRIALS, -1, t, NAN);
  }
  if (!S->first) {
    for (int e = 0; e < ne; e++) {
      if (S->modes[e] != S->old[e] && (r = note(S, k, t, e, S->old[e], S->modes[e]))) return r;
    }
  }
  S->first = 0;
  slips(d, S);
  event_function(S, S->gprev, 1);
  /* held over the step: time-varying levels and source shapes at mid-step */
  if (S->timevar) {
    if ((r = levels(S, t + 0.5 * dt, S->lvm, S->elm))) return r;
  } else {
    memcpy(S->lvm, S->lv, sizeof(double) * (size_t)S->npart);
    memcpy(S->elm, S->el, sizeof(double) * (size_t)ne);
  }
  memcpy(S->ctrl0, d->ctrl, sizeof(double) * (size_t)m->nu);
  if ((r = set_ctrl(d, S, t + 0.5 * dt, S->elm, 1))) return r;
  int same = 1;
  for (int i = 0; i < m->nu && same; i++) same = d->ctrl[i] == S->ctrl0[i];
  if (!same) {
    /* d holds a forward of this state and these locks: only the stages that depend on the control are redone
     * (actuation, acceleration, constraint forces), which is what a full mj_forward would compute */
    mj_forwardSkip(m, d, mjSTAGE_VEL, 0);
    mj_checkAcc(m, d);
  }
  for (int i = 0; i < n; i++) {
    S->wa[i] = w_of(d, S, i);
    S->qa[i] = q_of(d, S, i);
  }
  fill_record(d, S);
  return 0;
}

static int work(mjData* d, mbs_rotors* S, long k) {
  const int n = S->n;
  const double dt = S->dt, tm = (double)k * dt + 0.5 * dt;
  double* acc = S->acc;
  double src = 0.0;
  for (int s = 0; s < S->nsrc; s++) {
    int i = S->sbody[s];
    double sh;
    int r = source_shape(S, s, tm, &sh);
    if (r) return r;
    double w0 = S->wa[i], w1 = w_of(d, S, i);
    double held = S->c2[s] != 0.0 ? S->sheld[s] : S->c0[s] * sh; /* the torque held over the step (but c1 w) */
    src += held * (q_of(d, S, i) - S->qa[i]) + S->c1[s] * 0.5 * (w0 * w0 + w1 * w1) * dt;
  }
  acc[0] += src;
  for (int i = 0; i < n; i++) {
    double w0 = S->wa[i], w1 = w_of(d, S, i);
    acc[1 + i] += S->B[i] * 0.5 * (w0 * w0 + w1 * w1) * dt;
  }
  for (int p = 0; p < S->npart; p++) {
    int e = S->owner[p];
    int md = S->modes[e];
    if (!sliding(md)) continue;
    double dqr;
    if (S->general) {
      dqr = 0.0;
      for (int i = 0; i < n; i++) dqr += S->grow[e * n + i] * (q_of(d, S, i) - S->qa[i]);
    } else {
      int a = S->ea[e], b = S->eb[e];
      double dqa = q_of(d, S, a) - S->qa[a];
      dqr = (b >= 0 ? q_of(d, S, b) - S->qa[b] : 0.0) - dqa;
    }
    acc[1 + n + p] += md * S->lvm[p] * dqr;
  }
  for (int j = 0; j < S->ndamp; j++) {
    int a = S->da[j], b = S->db[j];
    double r0 = (b >= 0 ? S->wa[b] : 0.0) - S->wa[a];
    double r1 = (b >= 0 ? w_of(d, S, b) : 0.0) - w_of(d, S, a);
    acc[1 + n + S->npart + j] += S->dD[j] * 0.5 * (r0 * r0 + r1 * r1) * dt;
  }
  return 0;
}

int mbs_rotors_hook(const mjModel* m, mjData* d, void* ud, long k, int stage) {
  mbs_rotors* S = (mbs_rotors*)ud;
  if (stage == MBS_STAGE_POST_FORWARD) {
    if (S->decided) return 0; /* the same step again (a repeated final forward): nothing new */
    S->decided = 1;
    return decide(m, d, S, k);
  }
  S->decided = 0;
  return work(d, S, k);
}

/* the size of the struct and the ABI, for the Python side's checks (native_stepper.DECLARATION) */
#define ROT_ABI 1 /* bump with any change of mbs_rotors or of an mbs_rotors_* signature (native_stepper.ABI) */
int mbs_rotors_struct_size(void) { return (int)sizeof(mbs_rotors); }
int mbs_rotors_abi(void) { return ROT_ABI; }
