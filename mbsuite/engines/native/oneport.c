/* One-ports (mbsuite.h): the struct's size for the Python mirror; the MuJoCo one-port, a MuJoCo model driven by one
 * force actuator stepped by a host that owns the force, call for call what a Python adapter does with the same model:
 * mj_setState, ctrl, the core's one checked step (mbs_run), mj_kinematics, mj_getState; the linear one-port. */
#include <math.h>

#include "mbsuite.h"

int mbs_port_size(void) { return (int)sizeof(mbs_port); }
int mbs_mj_port_size(void) { return (int)sizeof(mbs_mj_port); }
int mbs_lin_port_size(void) { return (int)sizeof(mbs_lin_port); }

static double mj_height(const mbs_mj_port* s) {
  const mjData* d = s->d;
  return d->site_xpos[3 * s->site + 2] - d->site_xpos[3 * s->origin + 2] - s->offset;
}

static int mj_trial(void* self, double t, double dt, double f0, double f1, double* y) {
  mbs_mj_port* s = (mbs_mj_port*)self;
  const mjModel* m = s->m;
  mjData* d = s->d;
  mj_setState(m, d, s->committed, s->spec);
  d->ctrl[s->actuator] = s->sign * (0.5 * (f0 + f1));
  mbs_job* J = s->job;
  J->nstep = 1;
  J->k0 = 0;
  J->final = 0;
  J->ctrl = NULL;
  J->ctrl_idx = NULL;
  J->ctrl_ncol = 0;
  J->ctrl_rows = 0;
  J->rec = NULL;
  J->rec_cap = 0;
  J->rec_row = 0;
  const int status = mbs_run(m, d, J);
  s->holds = 0;
  if (status) return status;
  mj_kinematics(m, d);
  *y = mj_height(s);
  mj_getState(m, d, s->pending, s->spec);
  s->holds = 1;
  return 0;
}

static void mj_commit(void* self) {
  mbs_mj_port* s = (mbs_mj_port*)self;
  double* c = s->committed;
  s->committed = s->pending;
  s->pending = c;
  /* d holds the committed state with its kinematics when it held the last trial; else restore it */
  if (!s->holds) {
    mj_setState(s->m, s->d, s->committed, s->spec);
    mj_kinematics(s->m, s->d);
  }
  s->holds = 0;
}

static void mj_outputs(const void* self, double* out) {
  const mbs_mj_port* s = (const mbs_mj_port*)self;
  out[0] = mj_height(s);
  for (int i = 0; i < s->nq_out; i++) out[1 + i] = s->d->qpos[i];
}

void mbs_mj_port_init(mbs_port* port, mbs_mj_port* s) {
  port->self = s;
  port->affine = 0;
  port->nout = 1 + s->nq_out;
  port->map = NULL;
  port->trial = mj_trial;
  port->commit = mj_commit;
  port->outputs = mj_outputs;
  s->holds = 0;
}

/* ------------------------------------------------------------------------------------------ the linear one-port */
/* A linear model's trapezoidal step as written by its Python twin: x = Phi x + G0 - Gf (f0 + f1) (sums in index
 * order). */
static double dot(const double* a, const double* b, int n) {
  double s = 0.0;
  for (int i = 0; i < n; i++) s += a[i] * b[i];
  return s;
}

static void lin_map(void* self, double t, double dt, double f0, double* P, double* g) {
  const mbs_lin_port* s = (const mbs_lin_port*)self;
  *P = dot(s->cPhi, s->x, s->n) + s->cG0 - s->cGf * f0;
  *g = s->cGf;
}

static int lin_trial(void* self, double t, double dt, double f0, double f1, double* y) {
  mbs_lin_port* s = (mbs_lin_port*)self;
  const int n = s->n;
  const double f = f0 + f1;
  for (int i = 0; i < n; i++) s->pending[i] = dot(s->Phi + (long)i * n, s->x, n) + s->G0[i] - s->Gf[i] * f;
  *y = dot(s->c, s->pending, n);
  return isfinite(*y) ? 0 : 1;
}

static void lin_commit(void* self) {
  mbs_lin_port* s = (mbs_lin_port*)self;
  double* x = s->x;
  s->x = s->pending;
  s->pending = x;
}

static void lin_outputs(const void* self, double* out) {
  const mbs_lin_port* s = (const mbs_lin_port*)self;
  for (int r = 0; r < s->nout; r++) out[r] = dot(s->Cout + (long)r * s->n, s->x, s->n);
}

void mbs_lin_port_init(mbs_port* port, mbs_lin_port* s) {
  port->self = s;
  port->affine = 1;
  port->nout = s->nout;
  port->map = lin_map;
  port->trial = lin_trial;
  port->commit = lin_commit;
  port->outputs = lin_outputs;
}
