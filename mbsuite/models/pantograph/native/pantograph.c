/* The pantograph's effects as MuJoCo engine plugins (Eppinger 1984, "An experimental and analytical study of
 * pantograph dynamics"; equations as in mbsuite/models/pantograph/equations.py, which stays the readable reference; a test holds the two
 * to 1e-12 on every scene).
 *
 * mbsuite.pantograph.cylinder (actuator plugin, one activation = the cylinder state, declared with actdim="1"):
 *   model "linear"    (3.24-3.26)  P' = (kc/bc)(x_p - P),  force = Pg Ap + kc (P - x_p)          (P in m)
 *   model "nonlinear" (3.15-3.22, corrected)  V = V0 + Ap x_p,  P' = (R T / V) mdot(P) - (P / V) Ap x_p',
 *                     force = (P - Pa) Ap                                                          (P in Pa)
 *   The actuator acts on the base joint (theta_1 = its length): x_p = lb cos(alpha - theta_1) (3.19, erratum 13),
 *   x_p' = lb sin(alpha - theta_1) theta_1', and its actuator force is the torque F lb sin(alpha - theta_1).
 *   mdot (3.17 corrected): choked below the critical ratio (2/(gamma+1))^(gamma/(gamma-1)) (0.528 for gamma = 1.4),
 *   linear in (Ps - P) for Pd/Pu > r_laminar.
 * mbsuite.pantograph.elbow (passive plugin): the elbow spring of Eq 3.13 with the pinion angle theta_e(theta_1) of
 *   App. B (B.3-B.6, or the exact chain wrap), mapped onto the joints q1 = theta_1, q2 = pi - theta_1 - theta_2:
 *   Te = ke (theta_e - theta_2) + be (theta_e' - theta_2'),  qfrc_passive += -(Te (dte/dt1 + 1), Te).
 * Parameters are config attributes of the plugin instance (SI units), so the MJCF file holds the whole model. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mbsuite.h"

#define ELBOW_NO_TANGENT "elbow chain has no tangent line to the pinion at this theta_1 (B^2 - 4AC)"

/* ------------------------------------------------------------------------------------------------ cylinder */
static const char* cyl_attributes[] = {"model", "lb", "alpha", "kc", "bc", "Pg", "Pa", "Ap", "V0", "R_gas", "T", "gamma", "cd",
                                       "Ao", "r_laminar"};

typedef struct {
  mbs_plugin_header h;
  int nonlinear;
  int actuator;
  double lb, alpha, kc, bc, Pg, Pa, Ap, V0, R, T, gamma, cd, Ao, r_lam;
  double Ps, gas, m_lam, dp_lam, r_crit;
} Cylinder;

static int cyl_nstate(const mjModel* m, int instance) { return 0; }

static int cyl_init(const mjModel* m, mjData* d, int instance) {
  Cylinder* c = calloc(1, sizeof(Cylinder));
  if (!c) return -1;
  d->plugin_data[instance] = (uintptr_t)c;
  mbs_plugin_header* h = &c->h;
  const char* model = mj_getPluginConfig(m, instance, "model");
  mbs_config_require(h, model && (!strcmp(model, "linear") || !strcmp(model, "nonlinear")), "model", NAN);
  c->nonlinear = model && !strcmp(model, "nonlinear");
  c->lb = mbs_config_number(m, instance, "lb", NAN, h);
  c->alpha = mbs_config_number(m, instance, "alpha", NAN, h);
  c->kc = mbs_config_number(m, instance, "kc", NAN, h);
  c->bc = mbs_config_number(m, instance, "bc", NAN, h);
  c->Pg = mbs_config_number(m, instance, "Pg", NAN, h);
  c->Pa = mbs_config_number(m, instance, "Pa", NAN, h);
  c->Ap = mbs_config_number(m, instance, "Ap", NAN, h);
  c->V0 = mbs_config_number(m, instance, "V0", NAN, h);
  c->R = mbs_config_number(m, instance, "R_gas", NAN, h);
  c->T = mbs_config_number(m, instance, "T", NAN, h);
  c->gamma = mbs_config_number(m, instance, "gamma", NAN, h);
  c->cd = mbs_config_number(m, instance, "cd", NAN, h);
  c->Ao = mbs_config_number(m, instance, "Ao", NAN, h);
  c->r_lam = mbs_config_number(m, instance, "r_laminar", NAN, h);
  /* the ranges of PantographParams */
  mbs_config_require(h, c->lb > 0, "lb", c->lb);
  mbs_config_require(h, c->kc > 0, "kc", c->kc);
  mbs_config_require(h, c->bc > 0, "bc", c->bc);
  mbs_config_require(h, c->Pg > 0, "Pg", c->Pg);
  mbs_config_require(h, c->Pa > 0, "Pa", c->Pa);
  mbs_config_require(h, c->Ap > 0, "Ap", c->Ap);
  mbs_config_require(h, c->V0 > 0, "V0", c->V0);
  mbs_config_require(h, c->R > 0, "R_gas", c->R);
  mbs_config_require(h, c->T > 0, "T", c->T);
  mbs_config_require(h, c->gamma > 1 && c->gamma < 2, "gamma", c->gamma);
  mbs_config_require(h, c->cd > 0 && c->cd <= 1, "cd", c->cd);
  mbs_config_require(h, c->Ao > 0, "Ao", c->Ao);
  c->r_crit = pow(2.0 / (c->gamma + 1.0), c->gamma / (c->gamma - 1.0));
  mbs_config_require(h, c->r_lam > c->r_crit && c->r_lam < 1, "r_laminar", c->r_lam);
  c->actuator = -1;
  for (int i = 0; i < m->nu; i++) {
    if (m->actuator_plugin[i] == instance) c->actuator = i;
  }
  int a = c->actuator;
  if (mbs_config_require(h, a >= 0, "actuator (none uses this instance)", NAN)) {
    mbs_config_require(h, m->actuator_actnum[a] == 1, "actdim (must be 1)", m->actuator_actnum[a]);
    mbs_config_require(h, m->actuator_trntype[a] == mjTRN_JOINT && m->jnt_type[m->actuator_trnid[2 * a]] == mjJNT_HINGE,
                       "transmission (must be the base hinge joint)", NAN);
    mbs_config_require(h, m->actuator_gear[6 * a] == 1.0, "gear (must be 1)", m->actuator_gear[6 * a]);
  }
  if (h->fault) c->actuator = -1; /* a configured model only */
  if (c->nonlinear && !h->fault) {
    c->Ps = c->Pg + c->Pa;
    c->gas = c->cd * c->Ao * sqrt(2.0 * c->gamma / (c->R * (c->gamma - 1.0))) / sqrt(c->T);
    double rl = c->r_lam;
    c->dp_lam = c->Ps * (1.0 - rl);
    c->m_lam = c->gas * c->Ps * pow(rl, 1.0 / c->gamma) * sqrt(1.0 - pow(rl, (c->gamma - 1.0) / c->gamma));
  }
  return 0;
}

static void plugin_destroy(mjData* d, int instance) {
  free((void*)d->plugin_data[instance]);
  d->plugin_data[instance] = 0;
}

/* mj_copyData: the destination keeps its own block (MuJoCo restores dst's plugin_data pointers before calling copy) */
static void copy_block(mjData* dst, const mjData* src, int instance, size_t size) {
  void* block = (void*)dst->plugin_data[instance];
  if (!block) block = malloc(size);
  if (!block) return;
  memcpy(block, (const void*)src->plugin_data[instance], size);
  dst->plugin_data[instance] = (uintptr_t)block;
}

static void cyl_copy(mjData* dst, const mjModel* m, const mjData* src, int instance) {
  copy_block(dst, src, instance, sizeof(Cylinder));
}

static void plugin_reset(const mjModel* m, mjtNum* plugin_state, void* plugin_data, int instance) {
  mbs_plugin_header* h = (mbs_plugin_header*)plugin_data;
  if (h && !h->at_load) { /* a configuration fault stays */
    h->fault = 0;
    h->fault_time = 0.0;
    h->fault_value = 0.0;
    h->what = NULL;
  }
}

/* mass flow into the cylinder (kg/s); P > 0 */
static double orifice_mass_flow(const Cylinder* c, double P) {
  double Ps = c->Ps;
  double Pu = P <= Ps ? Ps : P, Pd = P <= Ps ? P : Ps;
  double r = Pd / Pu;
  if (r > c->r_lam) return c->m_lam * (Ps - P) / c->dp_lam;
  double sgn = P <= Ps ? 1.0 : -1.0;
  if (r < c->r_crit) r = c->r_crit;
  return sgn * c->gas * Pu * pow(r, 1.0 / c->gamma) * sqrt(1.0 - pow(r, (c->gamma - 1.0) / c->gamma));
}

static void cyl_act_dot(const mjModel* m, mjData* d, int instance) {
  Cylinder* c = (Cylinder*)d->plugin_data[instance];
  if (c->actuator < 0) return;
  int i = c->actuator;
  int a = m->actuator_actadr[i];
  double P = d->act[a], t1 = d->actuator_length[i];
  double xp = c->lb * cos(c->alpha - t1);
  double rate = 0.0;
  if (!isfinite(P) || !isfinite(xp)) {
    mbs_fault(d, instance, MBS_FAULT_NONFINITE, P);
  } else if (!c->nonlinear) {
    rate = c->kc / c->bc * (xp - P);
  } else {
    double V = c->V0 + c->Ap * xp;
    if (V <= 0.0) {
      mbs_model_fault(d, instance, "cylinder chamber volume V0 + Ap x_p became <= 0 (m^3)", V);
    } else if (P <= 0.0) {
      mbs_model_fault(d, instance, "absolute cylinder pressure became <= 0 (Pa)", P);
    } else {
      double dxp = c->lb * sin(c->alpha - t1) * d->actuator_velocity[i];
      rate = c->R * c->T / V * orifice_mass_flow(c, P) - P / V * c->Ap * dxp;
    }
  }
  d->act_dot[a] = rate;
}

static void cyl_compute(const mjModel* m, mjData* d, int instance, int capability_bit) {
  Cylinder* c = (Cylinder*)d->plugin_data[instance];
  if (c->actuator < 0) return;
  int i = c->actuator;
  double P = d->act[m->actuator_actadr[i]], t1 = d->actuator_length[i];
  double f = c->nonlinear ? (P - c->Pa) * c->Ap : c->Pg * c->Ap + c->kc * (P - c->lb * cos(c->alpha - t1));
  d->actuator_force[m->actuator_outadr[i]] = f * c->lb * sin(c->alpha - t1); /* torque on the base joint */
}

/* ------------------------------------------------------------------------------------------------ elbow */
static const char* elbow_attributes[] = {"l1", "xf", "yf", "le", "theta_e0", "ke", "be", "kinematics", "joint1",
                                         "joint2"};

typedef struct {
  mbs_plugin_header h;
  double l1, xf, yf, le, theta_e0, ke, be;
  int exact;
  int q1, q2, v1, v2;
  double phi1_0, lfb0;
} Elbow;

static int elbow_nstate(const mjModel* m, int instance) { return 0; }

/* B.3-B.5 and their implicit derivatives; returns 0 if the chain has no tangent line */
static int chain(const Elbow* e, double th1, double* phi1, double* dphi1, double* lfb, double* dlfb) {
  double c1 = cos(th1), s1 = sin(th1);
  double X = e->l1 * c1 - e->xf, Y = e->l1 * s1 + e->yf;
  double le = e->le;
  double A = X * X - le * le, B = -2.0 * X * Y, C = Y * Y - le * le;
  double disc = B * B - 4.0 * A * C;
  if (disc <= 0.0 || A == 0.0) return 0;
  double sq = sqrt(disc);
  double p = atan2(-B - sq, 2.0 * A);
  double t = (-B - sq) / (2.0 * A);
  double dX = -e->l1 * s1, dY = e->l1 * c1;
  double dA = 2.0 * X * dX, dB = -2.0 * (dX * Y + X * dY), dC = 2.0 * Y * dY;
  double dt = -(dA * t * t + dB * t + dC) / (2.0 * A * t + B);
  double dp = dt / (1.0 + t * t);
  double sp = sin(p), cp = cos(p);
  double gx = X + le * sp, gy = Y - le * cp;
  double l = sqrt(gx * gx + gy * gy);
  *phi1 = p;
  *dphi1 = dp;
  *lfb = l;
  *dlfb = (gx * (dX + le * cp * dp) + gy * (dY + le * sp * dp)) / l;
  return 1;
}

static int joint_address(const mjModel* m, const char* name, int* qadr, int* vadr) {
  int j = name ? mj_name2id(m, mjOBJ_JOINT, name) : -1;
  if (j < 0 || m->jnt_type[j] != mjJNT_HINGE) return 0;
  *qadr = m->jnt_qposadr[j];
  *vadr = m->jnt_dofadr[j];
  return 1;
}

static int elbow_init(const mjModel* m, mjData* d, int instance) {
  Elbow* e = calloc(1, sizeof(Elbow));
  if (!e) return -1;
  d->plugin_data[instance] = (uintptr_t)e;
  mbs_plugin_header* h = &e->h;
  e->l1 = mbs_config_number(m, instance, "l1", NAN, h);
  e->xf = mbs_config_number(m, instance, "xf", NAN, h);
  e->yf = mbs_config_number(m, instance, "yf", NAN, h);
  e->le = mbs_config_number(m, instance, "le", NAN, h);
  e->theta_e0 = mbs_config_number(m, instance, "theta_e0", NAN, h);
  e->ke = mbs_config_number(m, instance, "ke", NAN, h);
  e->be = mbs_config_number(m, instance, "be", 0.0, h);
  mbs_config_require(h, e->l1 > 0, "l1", e->l1);
  mbs_config_require(h, e->le > 0, "le", e->le);
  mbs_config_require(h, e->ke >= 0, "ke", e->ke);
  mbs_config_require(h, e->be >= 0, "be", e->be);
  const char* kin = mj_getPluginConfig(m, instance, "kinematics");
  mbs_config_require(h, !kin || !kin[0] || !strcmp(kin, "B6") || !strcmp(kin, "exact"), "kinematics", NAN);
  e->exact = kin && !strcmp(kin, "exact");
  mbs_config_require(h, joint_address(m, mj_getPluginConfig(m, instance, "joint1"), &e->q1, &e->v1), "joint1", NAN);
  mbs_config_require(h, joint_address(m, mj_getPluginConfig(m, instance, "joint2"), &e->q2, &e->v2), "joint2", NAN);
  double dphi, dl;
  if (!h->fault && !chain(e, 0.0, &e->phi1_0, &dphi, &e->lfb0, &dl)) {
    mbs_model_config_fault(h, ELBOW_NO_TANGENT, "le, xf, yf (the chain base lies inside the pinion circle)", 0.0);
  }
  return 0;
}

static void elbow_copy(mjData* dst, const mjModel* m, const mjData* src, int instance) {
  copy_block(dst, src, instance, sizeof(Elbow));
}

static void elbow_compute(const mjModel* m, mjData* d, int instance, int capability_bit) {
  Elbow* e = (Elbow*)d->plugin_data[instance];
  if (e->h.at_load) return; /* not configured: the core reports it before this force is ever used */
  double q1 = d->qpos[e->q1], q2 = d->qpos[e->q2];
  if (!isfinite(q1) || !isfinite(q2)) {
    mbs_fault(d, instance, MBS_FAULT_NONFINITE, q1);
    return;
  }
  double phi1, dphi1, lfb, dlfb;
  if (!chain(e, q1, &phi1, &dphi1, &lfb, &dlfb)) {
    mbs_model_fault(d, instance, ELBOW_NO_TANGENT, q1);
    return;
  }
  double te, dte;
  if (e->exact) {
    te = e->theta_e0 + (lfb - e->lfb0) / e->le - (phi1 - e->phi1_0);
    dte = dlfb / e->le - dphi1;
  } else {
    te = e->theta_e0 + (lfb - e->lfb0) / e->le - q1;
    dte = dlfb / e->le - 1.0;
  }
  /* theta_2 = pi - q1 - q2 */
  double Te = e->ke * (te - M_PI + q1 + q2);
  if (e->be != 0.0) {
    double w1 = d->qvel[e->v1], w2 = d->qvel[e->v2];
    Te += e->be * (dte * w1 + w1 + w2);
  }
  d->qfrc_passive[e->v1] -= Te * (dte + 1.0);
  d->qfrc_passive[e->v2] -= Te;
}

/* ------------------------------------------------------------------------------------------------ registration */
mjPLUGIN_LIB_INIT(mbsuite_pantograph) {
  mjpPlugin cyl;
  mjp_defaultPlugin(&cyl);
  cyl.name = "mbsuite.pantograph.cylinder";
  cyl.capabilityflags = mjPLUGIN_ACTUATOR;
  cyl.nattribute = sizeof(cyl_attributes) / sizeof(cyl_attributes[0]);
  cyl.attributes = cyl_attributes;
  cyl.nstate = cyl_nstate;
  cyl.init = cyl_init;
  cyl.destroy = plugin_destroy;
  cyl.copy = cyl_copy;
  cyl.reset = plugin_reset;
  cyl.compute = cyl_compute;
  cyl.actuator_act_dot = cyl_act_dot;
  mbs_register_plugin(&cyl);

  mjpPlugin el;
  mjp_defaultPlugin(&el);
  el.name = "mbsuite.pantograph.elbow";
  el.capabilityflags = mjPLUGIN_PASSIVE;
  el.nattribute = sizeof(elbow_attributes) / sizeof(elbow_attributes[0]);
  el.attributes = elbow_attributes;
  el.nstate = elbow_nstate;
  el.init = elbow_init;
  el.destroy = plugin_destroy;
  el.copy = elbow_copy;
  el.reset = plugin_reset;
  el.compute = elbow_compute;
  mbs_register_plugin(&el);
}
