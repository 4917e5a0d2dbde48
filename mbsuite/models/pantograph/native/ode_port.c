/* The Eppinger pantograph's hand-derived ODE as a one-port (mbsuite.h, `mbs_port`): the C twin of one catenary step
 * of `EppingerReference` (mbsuite/models/pantograph/under_wire.py), Eppinger 1984, "An experimental and analytical
 * study of pantograph dynamics".
 *
 * A trial is `EppingerReference._rk4`: one classical RK4 step of `PantographODE.rhs_with_force`
 * (mbsuite/models/pantograph/equations.py, the readable reference, followed here statement by statement; the elbow
 * of elbow.py) with the contact force varying linearly f0 -> f1 over the step (f >= 0 presses the head down: the
 * force on the head is f_up = -f). Its answer is y = contact_height(x_new) - y_op. Effects: gravity on/off, viscous
 * joint damping on/off, the smooth Coulomb law c tanh(w / omega_s) or none (the event-exact stick/slip has no place
 * at a fixed step: under_wire.py), the cylinder constant / linear (3.24-3.26) / nonlinear (3.15-3.22 corrected), the
 * elbow compliant (spring ke, be; 3 DOF) or rigid (theta_2 = theta_e(theta_1); 2 DOF), its kinematics B.6 or the
 * exact chain wrap (erratum 22).
 *
 * The only departure from the Python: the small dense solve M q'' = F is a Gaussian elimination with partial pivoting
 * here (LAPACK's dgesv in numpy), and numpy's small matrix products may sum in another order: the two agree to
 * rounding, not bit for bit.
 *
 * Failures (a trial returns the code, the struct keeps what describes it; `ode_port.py` words the message): a
 * non-finite input, committed state or stage rate, the elbow chain without a tangent line (elbow.py's GeometryError),
 * the nonlinear cylinder's volume <= 0 or non-positive upstream pressure (equations.py's SolverErrors), a singular
 * mass matrix (numpy's LinAlgError). A failed trial leaves no pending state: a commit after it changes nothing. */
#include <math.h>
#include <string.h>

#include "mbsuite.h"

#define MBS_PANTO_ODE_ABI 2
#define MBS_PANTO_ODE_NX 7 /* largest state: 3 angles, 3 rates, the cylinder state */

/* failure codes (ode_port.py mirrors them) */
enum {
  PO_OK = 0,
  PO_FAIL_INPUT = 1,     /* non-finite t, dt, f0 or f1 (fail_index 0..3) */
  PO_FAIL_STATE = 2,     /* non-finite committed state entry fail_index */
  PO_FAIL_RATE = 3,      /* non-finite rate entry fail_index at RK4 stage fail_stage */
  PO_FAIL_NEW = 4,       /* non-finite new state entry fail_index (-1: the height) */
  PO_FAIL_ELBOW = 5,     /* no tangent line: fail_value = B^2 - 4AC, fail_aux = A, at fail_theta1 */
  PO_FAIL_VOLUME = 6,    /* nonlinear cylinder volume V = fail_value <= 0 at fail_theta1 */
  PO_FAIL_PRESSURE = 7,  /* orifice: non-positive upstream pressure, P = fail_value */
  PO_FAIL_SINGULAR = 8,  /* mass matrix singular: zero pivot in column fail_index */
};

typedef struct {
  /* effects (PantographConfig as the ODE reads it) */
  int nq;       /* 3: compliant elbow (theta_1, theta_2, theta_h); 2: rigid (theta_1, theta_h) */
  int n;        /* state size 2 nq + has_P */
  int has_P;    /* the cylinder has a state (linear, nonlinear) */
  int cylinder; /* 0 constant, 1 linear, 2 nonlinear */
  int exact;    /* elbow kinematics: 0 B.6, 1 exact chain wrap */
  int smooth;   /* 1: Coulomb friction c tanh(w / omega_s); 0: none */
  /* parameters (PantographParams) */
  double l1, l2, lh, m1, m2, mh, I1, I2, Ih, d1, d2, dh, kh, ke, be;
  double xf, yf, le, theta_e0, lb, alpha, Ap, V0, Pg, Pa, Ps, R_gas, T, gamma, kc, bc, r_laminar, omega_s, y_op;
  /* what PantographODE and its Elbow derive (copied from them) */
  double g;          /* p.g, or 0 without gravity */
  double b[3], c[3]; /* viscous and Coulomb coefficients (0 when the effect is off) */
  double K12, K13, K23, r_crit, gas, phi1_0, lfb0;
  double h2;         /* step of Elbow.second_derivative */
  double aero_head, aero_frame; /* PantographODE.aero: vertical uplift (N) at the head's / upper arm's mass centre */
  /* derived by mbs_panto_ode_port: the orifice's laminar band */
  double m_lam, dp_lam;
  /* states */
  double x[MBS_PANTO_ODE_NX];       /* committed */
  double pending[MBS_PANTO_ODE_NX]; /* the last successful trial */
  int has_pending;
  /* failure of the last trial */
  int fail_code, fail_stage, fail_index; /* stage: 1..4 the RK4 stage, 5 the new state (its height) */
  double fail_value, fail_aux, fail_theta1, fail_t;
  /* work */
  double k[4][MBS_PANTO_ODE_NX], xs[MBS_PANTO_ODE_NX], xn[MBS_PANTO_ODE_NX];
} mbs_panto_ode;

int mbs_panto_ode_abi(void) { return MBS_PANTO_ODE_ABI; }
int mbs_panto_ode_size(void) { return (int)sizeof(mbs_panto_ode); }

static int po_fail(mbs_panto_ode* s, int code, int index, double value, double aux, double theta1) {
  s->fail_code = code;
  s->fail_index = index;
  s->fail_value = value;
  s->fail_aux = aux;
  s->fail_theta1 = theta1;
  return code;
}

/* ------------------------------------------------------------------------------------------------ elbow (elbow.py) */
/* `_chain`: (phi1, dphi1/dth1, lfb, dlfb/dth1) from B.3-B.5 and their implicit derivatives */
static int po_chain(mbs_panto_ode* s, double theta1, double* phi1, double* dphi1, double* lfb, double* dlfb) {
  const double le = s->le;
  double c1 = cos(theta1), s1 = sin(theta1);
  double X = s->l1 * c1 - s->xf;
  double Y = s->l1 * s1 + s->yf;
  double A = X * X - le * le;
  double B = -2.0 * X * Y;
  double C = Y * Y - le * le;
  double disc = B * B - 4.0 * A * C;
  if (disc <= 0.0 || A == 0.0) return po_fail(s, PO_FAIL_ELBOW, 0, disc, A, theta1);
  double sq = sqrt(disc);
  double p = atan2(-B - sq, 2.0 * A);
  double t = tan(p);
  double dX = -s->l1 * s1, dY = s->l1 * c1;
  double dA = 2 * X * dX, dB = -2.0 * (dX * Y + X * dY), dC = 2 * Y * dY;
  double dt = -(dA * t * t + dB * t + dC) / (2.0 * A * t + B);
  double dp = dt / (1.0 + t * t);
  double gx = X + le * sin(p);
  double gy = Y - le * cos(p);
  double l = hypot(gx, gy);
  double dgx = dX + le * cos(p) * dp;
  double dgy = dY + le * sin(p) * dp;
  *phi1 = p;
  *dphi1 = dp;
  *lfb = l;
  *dlfb = (gx * dgx + gy * dgy) / l;
  return PO_OK;
}

/* `Elbow.__call__`: theta_e and d theta_e / d theta_1 */
static int po_elbow(mbs_panto_ode* s, double theta1, double* te, double* dte) {
  double phi1, dphi1, lfb, dlfb;
  int err = po_chain(s, theta1, &phi1, &dphi1, &lfb, &dlfb);
  if (err) return err;
  if (s->exact) {
    *te = s->theta_e0 + (lfb - s->lfb0) / s->le - (phi1 - s->phi1_0);
    *dte = dlfb / s->le - dphi1;
  } else {
    *te = s->theta_e0 + (lfb - s->lfb0) / s->le - theta1;
    *dte = dlfb / s->le - 1.0;
  }
  return PO_OK;
}

/* `Elbow.second_derivative`: central difference of the analytic first derivative */
static int po_elbow_second(mbs_panto_ode* s, double theta1, double* d2) {
  double te_p, dte_p, te_m, dte_m;
  int err = po_elbow(s, theta1 + s->h2, &te_p, &dte_p);
  if (err) return err;
  err = po_elbow(s, theta1 - s->h2, &te_m, &dte_m);
  if (err) return err;
  *d2 = (dte_p - dte_m) / (2.0 * s->h2);
  return PO_OK;
}

/* ------------------------------------------------------------------------------------------------ kinematics */
/* `theta`: absolute angles from q (rigid elbow: theta_2 = theta_e(theta_1)) */
static int po_theta(mbs_panto_ode* s, const double* q, double* t) {
  if (s->nq == 3) {
    t[0] = q[0];
    t[1] = q[1];
    t[2] = q[2];
    return PO_OK;
  }
  double te, dte;
  int err = po_elbow(s, q[0], &te, &dte);
  if (err) return err;
  t[0] = q[0];
  t[1] = te;
  t[2] = q[1];
  return PO_OK;
}

/* `theta_jacobian`: J = d theta / d q (3 x nq, row-major in J[3][3]) and jd = Jdot q' / q'1^2 */
static int po_theta_jacobian(mbs_panto_ode* s, const double* q, double J[3][3], double* jd) {
  memset(J, 0, 9 * sizeof(double));
  jd[0] = jd[1] = jd[2] = 0.0;
  if (s->nq == 3) {
    J[0][0] = J[1][1] = J[2][2] = 1.0;
    return PO_OK;
  }
  double te, dte;
  int err = po_elbow(s, q[0], &te, &dte);
  if (err) return err;
  J[0][0] = 1.0;
  J[1][0] = dte;
  J[2][1] = 1.0;
  return po_elbow_second(s, q[0], &jd[1]);
}

/* `contact_height`: y_d = l1 sin t1 + l2 sin t2 + lh sin th */
static int po_contact_height(mbs_panto_ode* s, const double* x, double* y) {
  double t[3];
  int err = po_theta(s, x, t);
  if (err) return err;
  *y = s->l1 * sin(t[0]) + s->l2 * sin(t[1]) + s->lh * sin(t[2]);
  return PO_OK;
}

/* ------------------------------------------------------------------------------------------------ model pieces */
/* `mass_matrix_theta`: M(theta) of Eqs 3.10-3.12 */
static void po_mass_matrix(const mbs_panto_ode* s, const double* t, double M[3][3]) {
  double m11 = s->I1 + s->m1 * (s->d1 * s->d1) + (s->m2 + s->mh) * (s->l1 * s->l1);
  double m22 = s->I2 + s->m2 * (s->d2 * s->d2) + s->mh * (s->l2 * s->l2);
  double m33 = s->Ih + s->mh * (s->dh * s->dh);
  double m12 = s->K12 * cos(t[0] + t[1]);
  double m13 = s->K13 * cos(t[0] - t[2]);
  double m23 = s->K23 * cos(t[1] + t[2]);
  M[0][0] = m11, M[0][1] = m12, M[0][2] = m13;
  M[1][0] = m12, M[1][1] = m22, M[1][2] = m23;
  M[2][0] = m13, M[2][1] = m23, M[2][2] = m33;
}

/* `cylinder_lever`: x_p = lb cos(alpha - t1), d x_p / d t1 = lb sin(alpha - t1) */
static void po_cylinder_lever(const mbs_panto_ode* s, double t1, double* xp, double* dxp) {
  *xp = s->lb * cos(s->alpha - t1);
  *dxp = s->lb * sin(s->alpha - t1);
}

/* `cylinder_force`: constant Pg Ap, linear 3.26, nonlinear 3.22 */
static double po_cylinder_force(const mbs_panto_ode* s, double t1, double P) {
  if (s->cylinder == 0) return s->Pg * s->Ap;
  if (s->cylinder == 1) {
    double xp, dxp;
    po_cylinder_lever(s, t1, &xp, &dxp);
    return s->Pg * s->Ap + s->kc * (P - xp);
  }
  return (P - s->Pa) * s->Ap;
}

/* `orifice_mass_flow`: mass flow into the cylinder, 3.17 corrected (errata 10, 12, 14) */
static int po_orifice_mass_flow(mbs_panto_ode* s, double P, double* mdot) {
  double Ps = s->Ps;
  double Pu = P <= Ps ? Ps : P, Pd = P <= Ps ? P : Ps;
  if (Pu <= 0.0) return po_fail(s, PO_FAIL_PRESSURE, 0, P, Pu, NAN);
  double r = Pd / Pu;
  double sgn = P <= Ps ? 1.0 : -1.0;
  if (r > s->r_laminar) {
    *mdot = s->m_lam * (Ps - P) / s->dp_lam; /* the laminar band (m_lam, dp_lam: mbs_panto_ode_port) */
    return PO_OK;
  }
  if (s->r_crit > r) r = s->r_crit; /* max(r, r_crit): Python keeps r when it is NaN */
  *mdot = sgn * s->gas * Pu * pow(r, 1.0 / s->gamma) * sqrt(1.0 - pow(r, (s->gamma - 1.0) / s->gamma));
  return PO_OK;
}

/* `cylinder_rate`: linear 3.25, nonlinear 3.16 with 3.17 */
static int po_cylinder_rate(mbs_panto_ode* s, double t1, double t1d, double P, double* rate) {
  double xp, dxp;
  po_cylinder_lever(s, t1, &xp, &dxp);
  if (s->cylinder == 1) {
    *rate = s->kc / s->bc * (xp - P);
    return PO_OK;
  }
  double V = s->V0 + s->Ap * xp;
  if (V <= 0.0) return po_fail(s, PO_FAIL_VOLUME, 0, V, xp, t1);
  double dV = s->Ap * dxp * t1d;
  double mdot;
  int err = po_orifice_mass_flow(s, P, &mdot);
  if (err) return err;
  *rate = s->R_gas * s->T / V * mdot - P / V * dV;
  return PO_OK;
}

/* `applied_forces_theta`: R without joint friction (centripetal, gravity, catenary, aerodynamic uplift, head spring,
 * cylinder, elbow) */
static int po_applied_forces(mbs_panto_ode* s, const double* t, const double* td, double f_s, double P, double* R) {
  /* velocity_forces_theta */
  double s12 = sin(t[0] + t[1]);
  R[0] = s->K12 * (td[1] * td[1]) * s12 + s->K13 * (td[2] * td[2]) * sin(t[2] - t[0]);
  R[1] = s->K12 * (td[0] * td[0]) * s12 + s->K23 * (td[2] * td[2]) * sin(t[1] + t[2]);
  R[2] = s->K13 * (td[0] * td[0]) * sin(t[0] - t[2]) + s->K23 * (td[1] * td[1]) * sin(t[1] + t[2]);
  /* + gravity_forces_theta */
  const double ng = -s->g;
  R[0] += ng * ((s->m1 * s->d1 + (s->m2 + s->mh) * s->l1) * cos(t[0]));
  R[1] += ng * ((s->m2 * s->d2 + s->mh * s->l2) * cos(t[1]));
  R[2] += ng * (s->mh * s->dh * cos(t[2]));
  /* + f_s contact_jacobian_theta */
  R[0] += f_s * (s->l1 * cos(t[0]));
  R[1] += f_s * (s->l2 * cos(t[1]));
  R[2] += f_s * (s->lh * cos(t[2]));
  /* + aero_forces_theta: F_head at the head's mass centre, F_frame at the upper arm's */
  if (s->aero_head != 0.0 || s->aero_frame != 0.0) {
    R[0] += (s->aero_head + s->aero_frame) * (s->l1 * cos(t[0]));
    R[1] += (s->aero_head * s->l2 + s->aero_frame * s->d2) * cos(t[1]);
    R[2] += s->aero_head * (s->dh * cos(t[2]));
  }
  R[2] -= s->kh * t[2];
  double xp, dxp;
  po_cylinder_lever(s, t[0], &xp, &dxp);
  R[0] += po_cylinder_force(s, t[0], P) * dxp;
  if (s->nq == 3) {
    /* elbow_torque: Te = ke (theta_e - t2) + be (theta_e' t1' - t2') */
    double te, dte;
    int err = po_elbow(s, t[0], &te, &dte);
    if (err) return err;
    double Te = s->ke * (te - t[1]) + s->be * (dte * td[0] - td[1]);
    R[0] -= Te * dte;
    R[1] += Te;
  }
  return PO_OK;
}

/* M x = F for n <= 3 by Gaussian elimination with partial pivoting (M, F overwritten); returns the column of a zero
 * pivot + 1, or 0 */
static int po_solve(int n, double M[3][3], double* F, double* x) {
  for (int k = 0; k < n; k++) {
    int p = k;
    for (int i = k + 1; i < n; i++) {
      if (fabs(M[i][k]) > fabs(M[p][k])) p = i;
    }
    if (M[p][k] == 0.0) return k + 1;
    if (p != k) {
      for (int j = 0; j < n; j++) {
        double a = M[k][j];
        M[k][j] = M[p][j];
        M[p][j] = a;
      }
      double b = F[k];
      F[k] = F[p];
      F[p] = b;
    }
    for (int i = k + 1; i < n; i++) {
      double l = M[i][k] / M[k][k];
      for (int j = k + 1; j < n; j++) M[i][j] -= l * M[k][j];
      F[i] -= l * F[k];
    }
  }
  for (int i = n - 1; i >= 0; i--) {
    double r = F[i];
    for (int j = i + 1; j < n; j++) r -= M[i][j] * x[j];
    x[i] = r / M[i][i];
  }
  return 0;
}

/* `_dynamics` without friction modes (the smooth law or none): q'' and theta_1' */
static int po_dynamics(mbs_panto_ode* s, const double* x, double f_s, double* qdd, double* t1d) {
  static const double G[3][3] = {{1.0, 0.0, 0.0}, {1.0, 1.0, 0.0}, {0.0, 1.0, 1.0}}; /* G_JOINTS (A.15) */
  const int nq = s->nq;
  const double* q = x;
  const double* qd = x + nq;
  double P = s->has_P ? x[2 * nq] : 0.0;
  double J[3][3], jd[3], t[3], td[3], Mt[3][3], R[3];
  int err = po_theta_jacobian(s, q, J, jd);
  if (!err) err = po_theta(s, q, t);
  if (err) return err;
  for (int i = 0; i < 3; i++) { /* td = J q' */
    td[i] = 0.0;
    for (int k = 0; k < nq; k++) td[i] += J[i][k] * qd[k];
  }
  po_mass_matrix(s, t, Mt);
  err = po_applied_forces(s, t, td, f_s, P, R);
  if (err) return err;
  double a[3], qd02 = qd[0] * qd[0];
  for (int i = 0; i < 3; i++) a[i] = jd[i] * qd02;
  for (int i = 0; i < 3; i++) { /* R -= Mt (jd q'1^2) */
    double v = 0.0;
    for (int j = 0; j < 3; j++) v += Mt[i][j] * a[j];
    R[i] -= v;
  }
  double Gq[3][3], w[3], tau[3];
  for (int i = 0; i < 3; i++) { /* Gq = G J, w = Gq q' */
    for (int k = 0; k < nq; k++) {
      Gq[i][k] = 0.0;
      for (int j = 0; j < 3; j++) Gq[i][k] += G[i][j] * J[j][k];
    }
  }
  for (int i = 0; i < 3; i++) {
    w[i] = 0.0;
    for (int k = 0; k < nq; k++) w[i] += Gq[i][k] * qd[k];
  }
  for (int i = 0; i < 3; i++) tau[i] = -s->b[i] * w[i];
  if (s->smooth) {
    for (int i = 0; i < 3; i++) tau[i] -= s->c[i] * tanh(w[i] / s->omega_s);
  }
  double A[3][3], M[3][3], F[3];
  for (int k = 0; k < nq; k++) { /* A = J^T Mt */
    for (int j = 0; j < 3; j++) {
      A[k][j] = 0.0;
      for (int i = 0; i < 3; i++) A[k][j] += J[i][k] * Mt[i][j];
    }
  }
  for (int k = 0; k < nq; k++) { /* M = A J */
    for (int l = 0; l < nq; l++) {
      M[k][l] = 0.0;
      for (int j = 0; j < 3; j++) M[k][l] += A[k][j] * J[j][l];
    }
  }
  for (int k = 0; k < nq; k++) { /* F = J^T R + Gq^T tau */
    double u = 0.0, v = 0.0;
    for (int i = 0; i < 3; i++) u += J[i][k] * R[i];
    for (int i = 0; i < 3; i++) v += Gq[i][k] * tau[i];
    F[k] = u + v;
  }
  int z = po_solve(nq, M, F, qdd);
  if (z) return po_fail(s, PO_FAIL_SINGULAR, z - 1, 0.0, 0.0, q[0]);
  *t1d = td[0];
  return PO_OK;
}

/* `rhs_with_force`: x' under the vertical force f_up on the contact point (positive up) */
static int po_rhs(mbs_panto_ode* s, const double* x, double f_up, double* dx) {
  const int nq = s->nq;
  double t1d;
  int err = po_dynamics(s, x, f_up, dx + nq, &t1d);
  if (err) return err;
  for (int i = 0; i < nq; i++) dx[i] = x[nq + i];
  if (s->has_P) return po_cylinder_rate(s, x[0], t1d, x[2 * nq], &dx[2 * nq]);
  return PO_OK;
}

/* ------------------------------------------------------------------------------------------------ the one-port */
static int po_stage(mbs_panto_ode* s, int stage, const double* x, double f_up, double* k) {
  s->fail_stage = stage;
  int err = po_rhs(s, x, f_up, k);
  if (err) return err;
  for (int i = 0; i < s->n; i++) {
    if (!isfinite(k[i])) return po_fail(s, PO_FAIL_RATE, i, k[i], 0.0, x[0]);
  }
  return PO_OK;
}

/* `EppingerReference._rk4` and `trial` */
static int po_trial(void* self, double t, double dt, double f0, double f1, double* y) {
  mbs_panto_ode* s = (mbs_panto_ode*)self;
  const int n = s->n;
  const double* x = s->x;
  double* xs = s->xs;
  double* xn = s->xn;
  double (*k)[MBS_PANTO_ODE_NX] = s->k;
  s->has_pending = 0;
  s->fail_code = PO_OK;
  s->fail_stage = 0;
  s->fail_t = t;
  const double in[4] = {t, dt, f0, f1};
  for (int i = 0; i < 4; i++) {
    if (!isfinite(in[i])) return po_fail(s, PO_FAIL_INPUT, i, in[i], 0.0, x[0]);
  }
  for (int i = 0; i < n; i++) {
    if (!isfinite(x[i])) return po_fail(s, PO_FAIL_STATE, i, x[i], 0.0, x[0]);
  }
  double fm = 0.5 * (f0 + f1);
  double h2 = dt / 2, h6 = dt / 6;
  int err = po_stage(s, 1, x, -f0, k[0]);
  if (err) return err;
  for (int i = 0; i < n; i++) xs[i] = x[i] + h2 * k[0][i];
  if ((err = po_stage(s, 2, xs, -fm, k[1]))) return err;
  for (int i = 0; i < n; i++) xs[i] = x[i] + h2 * k[1][i];
  if ((err = po_stage(s, 3, xs, -fm, k[2]))) return err;
  for (int i = 0; i < n; i++) xs[i] = x[i] + dt * k[2][i];
  if ((err = po_stage(s, 4, xs, -f1, k[3]))) return err;
  for (int i = 0; i < n; i++) xn[i] = x[i] + h6 * (k[0][i] + 2 * k[1][i] + 2 * k[2][i] + k[3][i]);
  s->fail_stage = 5;
  for (int i = 0; i < n; i++) {
    if (!isfinite(xn[i])) return po_fail(s, PO_FAIL_NEW, i, xn[i], 0.0, xn[0]);
  }
  double yd;
  if ((err = po_contact_height(s, xn, &yd))) return err;
  double yy = yd - s->y_op;
  if (!isfinite(yy)) return po_fail(s, PO_FAIL_NEW, -1, yy, 0.0, xn[0]);
  memcpy(s->pending, xn, (size_t)n * sizeof(double));
  s->has_pending = 1;
  s->fail_stage = 0;
  *y = yy;
  return PO_OK;
}

/* `commit`: take the last (successful) trial; after a failed trial there is none and the state stays */
static void po_commit(void* self) {
  mbs_panto_ode* s = (mbs_panto_ode*)self;
  if (s->has_pending) memcpy(s->x, s->pending, (size_t)s->n * sizeof(double));
}

/* `signals` of the committed state: head (contact height - y_op), theta_1, theta_2, theta_h (NaN if the elbow has
 * no tangent there, which a committed trial has ruled out) */
static void po_outputs(const void* self, double* out) {
  mbs_panto_ode* s = (mbs_panto_ode*)self; /* the elbow's fault record is scratch: restored below */
  const int code = s->fail_code, stage = s->fail_stage, index = s->fail_index;
  const double value = s->fail_value, aux = s->fail_aux, theta1 = s->fail_theta1;
  double t[3], y;
  if (po_theta(s, s->x, t) || po_contact_height(s, s->x, &y)) {
    out[0] = out[1] = out[2] = out[3] = NAN;
  } else {
    out[0] = y - s->y_op;
    out[1] = t[0];
    out[2] = t[1];
    out[3] = t[2];
  }
  s->fail_code = code, s->fail_stage = stage, s->fail_index = index;
  s->fail_value = value, s->fail_aux = aux, s->fail_theta1 = theta1;
}

/* Fill `port` with the ODE one-port of `s` (parameters, effects, derived constants and the committed state set by
 * the caller); derives the orifice's laminar band. */
void mbs_panto_ode_port(mbs_port* port, mbs_panto_ode* s) {
  /* `orifice_mass_flow`'s laminar band: the flow at r_laminar from the supply side, linear in the difference */
  double rl = s->r_laminar, Pu_l = s->Ps;
  s->dp_lam = Pu_l * (1.0 - rl);
  s->m_lam = s->gas * Pu_l * pow(rl, 1.0 / s->gamma) * sqrt(1.0 - pow(rl, (s->gamma - 1.0) / s->gamma));
  s->has_pending = 0;
  s->fail_code = PO_OK;
  s->fail_stage = 0;
  port->self = s;
  port->affine = 0;
  port->nout = 4;
  port->map = NULL;
  port->trial = po_trial;
  port->commit = po_commit;
  port->outputs = po_outputs;
}

/* x' = rhs_with_force(x, f_up) alone (tests); returns 0 or a failure code */
int mbs_panto_ode_rhs(mbs_panto_ode* s, const double* x, double f_up, double* dx) {
  s->fail_code = PO_OK;
  s->fail_stage = 0;
  return po_rhs(s, x, f_up, dx);
}

/* Calls through a port's pointers (tests, from Python) */
int mbs_panto_ode_call_trial(const mbs_port* port, double t, double dt, double f0, double f1, double* y) {
  return port->trial(port->self, t, dt, f0, f1, y);
}
void mbs_panto_ode_call_commit(const mbs_port* port) { port->commit(port->self); }
void mbs_panto_ode_call_outputs(const mbs_port* port, double* out) { port->outputs(port->self, out); }
