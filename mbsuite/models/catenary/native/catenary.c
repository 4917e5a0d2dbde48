/* The per-step core of the FE catenary under N moving contact points (mbsuite.models.catenary.native).
 *
 * The C twin of `sim.Passage.step` (the readable Python path; a test holds the two equal to rounding). One step of
 * the trapezoidal rule in its midpoint form (h = dt/2, S = M + hC + h^2 K, G = h^2 S^-1):
 *   predict:  R = q_n + h/2 g_n,  vb* = S^-1 R  (one banded Cholesky solve, S factorised once here);
 *   contacts: per contact k its element, Hermite shape functions N_k, the wire height a_k without new local forces
 *             (static sag and the contact wire's height irregularity r(x_k) included),
 *             the compliances C_kl = N_k . G N_l, the influence bz_kj of contact k on dropper j, the elongations
 *             dstar_j of the droppers, and the contact spring in series with the contact wire's point-load defect
 *             d_k there, k_c,k = 1 / (1/k_c + d_k) (fe.PointCorrection; the droppers' own defects are in kdj);
 *   local:    the contact forces f_k = k_c,k max(y_head,k - y_wire,k, 0) (unilateral) and the slack droppers' tension-
 *             cancelling corrections s_j >= 0 (the droppers whose law is tension-only, dslack), solved exactly by a
 *             primal-dual active-set iteration on this piecewise-linear problem, with each pantograph's head map
 *             y_head,k = P_k - gp_k f_k;
 *   advance:  vb = vb* + (sum_k f_k G N_k - sum_j s_j G B_j) / (2h), u += 2h vb, and the momentum recursions
 *             q' = 2(M - h^2 K) vb - p, p' = 2(M + h^2 K) vb - q with M vb from S vb = R (g_{n+1} included).
 * `mbs_cat_run` loops these stages over a range of steps, every pantograph coupled through its one-port (mbsuite.h:
 * the 2-mass pantograph below, the linear and MuJoCo ports of engines/native/oneport.c, a model's own such as the
 * Eppinger pantograph's hand-derived ODE), an affine one by its exact head map, a nonlinear one by a secant
 * iteration (`couple`), recording every step; the stages are also exposed one by one for the Python-driven twin. No allocation: every array belongs to the caller (numpy).
 *
 * Several contact wires (a route: tension sections chained into one line, overlapping): a contact point belongs to one
 * contact wire (cwk_k: its DOFs, static state and point-load defect tables, its element range erng_k) and exists only
 * while its position lies in that wire's x-range (xrng_k; onw_k). One pantograph head owns one contact point per
 * contact wire, contiguous, the first its owner (own_k = the owner's index): the owner carries the head's one-port,
 * the head height y_head = P - gp F with F the sum of the head's contact forces, so the local problem couples the
 * contacts of one head through gp (C_kl + gp for k, l of one head). On a single contact wire every head has one
 * contact point, its own owner, on the wire over the whole line: the arithmetic is the single-wire core's. */
#include <math.h>
#include <string.h>

#include "mbsuite.h"

#define CAT_ABI 7
/* G = h^2 S^-1 decays geometrically away from a load (S is dominated by the mass matrix at these steps): the
 * advance adds a column only where it is above this fraction of its largest entry (the rest is below the sums'
 * rounding) */
#define RANGE_EPS 0x1p-60

typedef struct {
  /* sizes and switches */
  int n, bw, nd, nsup, ncon, nnode, nnz;
  int slack, unilateral, max_iter;
  /* scalars of the scheme */
  double h, hh2, c_ab, inv_1ha, c_kd, two_hh, kc, V, dt, max_disp;
  /* matrices (caller's arrays) */
  double *L;     /* n*(bw+1): on entry the lower band of S (L[i*(bw+1)+k] = S[i][i-k]), factorised in place */
  double *invd;  /* n: 1 / diagonal of the Cholesky factor */
  int *Kp, *Ki;  /* CSR of K = K0 + Kd */
  double *Kx;
  int *up, *lo;  /* nd: free index of the w DOF of each dropper's upper / lower wire */
  int *dslack;   /* nd: 1 when the dropper may go slack (its law is tension-only), 0 when it is bilateral */
  double *T0;    /* nd static dropper tensions */
  double *kdj;   /* nd dropper stiffnesses (the wires' point-load defects in series) */
  double *Zg;    /* nd*n: row j = G B_j */
  double *D;     /* nd*nd: B^T G B */
  double *xnode; /* nnode node positions */
  int *cwdof;    /* 2*nnode per contact wire: free index of its (w, theta) at each node, -1 when pinned or absent */
  double *w0cw;  /* 2*nnode per contact wire: its static (w, theta) at each node */
  int *supidx;   /* nsup: free index of the CW w at each uplift point (fe.arms), -1 when pinned */
  int *esig;     /* nnode-1 per contact wire: each element's entry in pq, pref (fe.PointCorrection) */
  double *pq;    /* 16 per entry: the Hermite compliance Q of the element's DOFs on its reference beam */
  double *pref;  /* 3 per entry: a0, L (reference beam; L = 0: no correction), h */
  double *ptk;   /* per entry: the tension of its reference beam */
  /* the contact wire's height irregularity r(x): piecewise linear on x = irr_x0 + i irr_dx, i < nirr; 0 outside */
  int nirr;
  double irr_x0, irr_dx;
  double *irr;   /* nirr heights (m) */
  /* catenary state and work */
  double *u, *q, *p, *R, *vbs, *vb; /* n each */
  int *slk;      /* nd: the slack set (sorted) */
  int nslack;
  double *sS;    /* nd: corrections of the slack set */
  /* contacts */
  int *present;  /* ncon: 1 while the pantograph is on the line */
  int *active;   /* ncon: in contact (unilateral state) */
  int *elem;     /* ncon: current element, -1 = none cached */
  double *xc;    /* ncon: current positions */
  double *xs;    /* ncon: position at t = 0 (x_k = xs_k + V t) */
  double *xend;  /* ncon: end of each run */
  double *Nl;    /* 4*ncon shape functions (0 on pinned DOFs) */
  int *dofs;     /* 4*ncon free DOFs of the element (pinned -> 0) */
  double *w0d;   /* 4*ncon static CW DOFs of the element */
  double *cols;  /* ncon*4*n: G e_d for the element's 4 CW DOFs (0 for a pinned DOF) */
  int *crng;     /* ncon*2: [lo, hi), outside which the 4 columns are below RANGE_EPS of their largest entry */
  int *zrng;     /* nd*2: the same for each dropper's G B_j (row j of Zg) */
  double *f;     /* ncon contact forces at the end of the last step */
  double *kce;   /* ncon contact stiffness in series with the contact wire's point-load defect there */
  double *cbc;   /* ncon the defect d_k (m/N) */
  double *rirr;  /* ncon the irregularity r(x_k) under each contact (m) */
  double *gv;    /* 4*ncon: N_k f_k of the last step (the local force g_n) */
  double *a, *Cm, *bz, *dstar; /* ncon, ncon*ncon, ncon*nd, nd */
  double *P, *gp; /* ncon head maps */
  double *head;  /* ncon */
  double *work;  /* (ncon+nd)*(ncon+nd+1) + (ncon+nd) */
  int *iwork;    /* 2*(ncon+nd) */
  /* the pantographs: per contact its one-port (mbsuite.h; NULL while a contact has none), the secant slope of a
   * nonlinear one's head map kept between steps (gs, NaN = not yet measured), work (cw: 4*ncon, nl: ncon) */
  mbs_port **ports;
  double *gs, *cw;
  int *nl;
  /* records (row = step index), may be NULL; rec_out: per row nout doubles, contact k's port outputs at ooff[k] */
  double *rec_t, *rec_x, *rec_f, *rec_head, *rec_wire, *rec_out, *rec_up; /* nrec, nrec*ncon x4, nrec*nout, nrec*nsup */
  int *rec_ns;
  int *ooff;
  int nout;
  /* block form of the factor (see build_blocks) */
  int blocked;   /* 1 when the block form is in use */
  int *fidx;     /* n: padded index of each free DOF (node I's DOFs are noff[I] .. noff[I+1]-1) */
  int *noff;     /* nnode+1: padded offset of each node's DOFs (node sizes 1..MAXB) */
  int *boff;     /* nnode+1: offset of each node's blocks in blk */
  double *blk;   /* per node of size s (previous p, next q): Di = D^-1 (s*s), F = D^-1 E (s*p), Dt = D^-T (s*s),
                    G = D^-T E_next^T (s*q), row-major */
  double *pw;    /* noff[nnode]: padded work vector */
  int *seg;      /* 6*nnode: the sweeps' stretches, (first, end, size) each (see block_solve) */
  int nseg_f, nseg_b; /* number of stretches of the forward and the backward sweep */
  /* diagnostics */
  long n_local;
  int err;       /* 0 ok; 1 non-finite; 2 displacement too large; 3 lost the wire; 4 active set; 5 not SPD;
                    6 a pantograph's trial failed (its code in err_port); 7 the coupling did not converge;
                    8 bad arguments (too many contacts, a present contact without a port) */
  int err_con;
  int err_port;
  double err_value;
  /* several contact wires (see the file's comment): cwdof, w0cw hold 2*nnode per contact wire, esig nnode-1 */
  int ncw;       /* number of contact wires */
  int *own;      /* ncon: the contact owning the head (its one-port, P, gp, head); own[k] == k for an owner */
  int *cwk;      /* ncon: contact wire of each contact */
  int *erng;     /* 2*ncon: first and last element of its wire */
  int *onw;      /* ncon: 1 while the contact lies on its wire (present, position in xrng) */
  double *xrng;  /* 2*ncon: the x-range of its wire */
  double *cwEI;  /* ncw: bending stiffness of each contact wire (its point-load defect) */
  double *Nf;    /* 4*ncon: the shape functions unmasked (the static height at a pinned end, which need not be 0) */
  /* sections in play (update_live): the factor's blocks, and per mechanical component (wires joined by droppers or
   * clamps: a route's tension section) its blocks, its free DOFs (both contiguous, fe.component_blocks) and the
   * x-range of its contact wires (x0 > x1: none) */
  int nblk;      /* blocks of the factor (nblk + 1 entries in noff, boff; a block per node on one section) */
  int ncomp;     /* components; 0: every DOF is stepped */
  int *cmpb;     /* 2*ncomp: block range [first, end) */
  int *cmpd;     /* 2*ncomp: free-DOF range [first, end) */
  double *cmpx;  /* 2*ncomp: x-range of its contact wires */
  int retire;    /* 1: a component every contact point has passed is no longer stepped */
  double *cmpt;  /* ncomp: the time of the first step it was not stepped after being in play (NaN: none yet) */
  int lb0, lb1, ld0, ld1; /* the blocks and free DOFs stepped: the components in play and any between them */
} cat_job;

int mbs_cat_abi(void) { return CAT_ABI; }
int mbs_cat_job_size(void) { return (int)sizeof(cat_job); }

/* ------------------------------------------------------------------------------------- banded Cholesky */
/* The factor L of S (band form) seen node by node: padded with an identity row/column for each pinned DOF, L is
 * block lower bidiagonal (a node couples only to its neighbours, and Cholesky fills nothing outside that profile),
 * L = [D_I on the diagonal, E_I below it], node I's block of size s_I = noff[I+1] - noff[I] (2 DOFs per wire present
 * at the node). The sweeps then run block by block,
 *   forward  y_I = D_I^-1 b_I - (D_I^-1 E_I) y_{I-1},   backward  x_I = D_I^-T y_I - (D_I^-T E_{I+1}^T) x_{I+1},
 * whose dependency chain is one small product per node instead of one multiply-subtract per DOF: the row sweeps of a
 * narrow band are bound by that chain's latency, the block sweeps by arithmetic. A stretch of nodes of one size s in
 * {2, 4, 6, 8} runs in a loop unrolled for that size with the previous node's values in registers; a node whose
 * neighbour has another size takes the general loop (the same sums in the same order). If L has an entry outside the
 * block profile, or a node more than MAXB DOFs, the band sweeps are kept (blocked = 0). */
#define MAXB 8
#define NSIZE(J, I) ((J)->noff[(I) + 1] - (J)->noff[(I)])

static void inv_lower(const double* D, double* X, int s) {
  memset(X, 0, sizeof(double) * s * s);
  for (int c = 0; c < s; c++) {
    for (int r = c; r < s; r++) {
      double v = (r == c) ? 1.0 : 0.0;
      for (int k = c; k < r; k++) v -= D[r * s + k] * X[k * s + c];
      X[r * s + c] = v / D[r * s + r];
    }
  }
}

/* F . a over m terms in a fixed tree: pair sums u_k = F_2k a_2k + F_2k+1 a_2k+1 (a last single term when m is odd),
 * then u_0 | u_0 + u_1 | (u_0 + u_1) + u_2 | (u_0 + u_1) + (u_2 + u_3) */
static inline __attribute__((always_inline)) double tree_dot(const double* F, const double* a, const int m) {
  if (m <= 0) return 0.0;
  double u[4];
  const int np = (m + 1) / 2;
#pragma GCC unroll 4
  for (int k = 0; k < np; k++) u[k] = (2 * k + 1 < m) ? F[2 * k] * a[2 * k] + F[2 * k + 1] * a[2 * k + 1] : F[2 * k] * a[2 * k];
  if (np == 1) return u[0];
  if (np == 2) return u[0] + u[1];
  if (np == 3) return (u[0] + u[1]) + u[2];
  return (u[0] + u[1]) + (u[2] + u[3]);
}

static int build_blocks(cat_job* J) {
  const int n = J->n, bw = J->bw, w = bw + 1, nn = J->nblk;
  J->blocked = 0;
  if (!J->blk || !J->pw || !J->fidx || !J->noff || !J->boff) return 0;
  for (int I = 0; I < nn; I++) {
    if (NSIZE(J, I) < 1 || NSIZE(J, I) > MAXB) return 0;
  }
  double* blk = J->blk;
  /* D (s*s) and E (s*p) of each node in its Di and F slots; identity on the diagonal for pinned DOFs */
  memset(blk, 0, sizeof(double) * (size_t)J->boff[nn]);
  for (int I = 0; I < nn; I++) {
    const int si = NSIZE(J, I);
    for (int r = 0; r < si; r++) blk[J->boff[I] + r * si + r] = 1.0;
  }
  int I = 0;
  for (int i = 0; i < n; i++) {
    const int pi = J->fidx[i];
    while (J->noff[I + 1] <= pi) I++;
    const int si = NSIZE(J, I), r = pi - J->noff[I], sp = I > 0 ? NSIZE(J, I - 1) : 0;
    double* D = blk + J->boff[I];
    double* E = D + si * si;
    D[r * si + r] = J->L[(long)i * w];
    int Jn = I;
    for (int m = 1; m <= bw && m <= i; m++) {
      const double v = J->L[(long)i * w + m];
      const int pj = J->fidx[i - m];
      while (Jn > 0 && J->noff[Jn] > pj) Jn--;
      const int c = pj - J->noff[Jn];
      if (Jn == I) {
        D[r * si + c] = v;
      } else if (Jn == I - 1) {
        E[r * sp + c] = v;
      } else if (v != 0.0) {
        return 0; /* outside the block profile: keep the band sweeps */
      }
    }
  }
  double Di[MAXB * MAXB], Ei[MAXB * MAXB], X[MAXB * MAXB];
  /* pass 1: Di, F = Di E and Dt = Di^T; E_I (s_I x s_{I-1}) is stashed in the G slot of node I-1 (s_{I-1} x s_I) */
  for (int I = nn - 1; I >= 0; I--) {
    const int si = NSIZE(J, I), sp = I > 0 ? NSIZE(J, I - 1) : 0;
    double* b = blk + J->boff[I];
    memcpy(Ei, b + si * si, sizeof(double) * si * sp);
    inv_lower(b, Di, si);
    if (I > 0) memcpy(blk + J->boff[I] - sp * si, Ei, sizeof(double) * si * sp);
    for (int r = 0; r < si; r++)
      for (int c = 0; c < sp; c++) {
        double v = 0.0;
        for (int k = 0; k < si; k++) v += Di[r * si + k] * Ei[k * sp + c];
        X[r * sp + c] = v;
      }
    memcpy(b, Di, sizeof(double) * si * si);
    memcpy(b + si * si, X, sizeof(double) * si * sp);
    for (int r = 0; r < si; r++)
      for (int c = 0; c < si; c++) b[si * si + si * sp + r * si + c] = Di[c * si + r]; /* Dt = Di^T */
  }
  /* pass 2: G_I = Dt_I E_{I+1}^T (E_{I+1} stashed in the G slot of node I) */
  for (int I = 0; I < nn - 1; I++) {
    const int si = NSIZE(J, I), sq = NSIZE(J, I + 1);
    double* G = blk + J->boff[I + 1] - si * sq;
    const double* Dt = G - si * si;
    memcpy(Ei, G, sizeof(double) * si * sq);
    for (int r = 0; r < si; r++)
      for (int c = 0; c < sq; c++) {
        double v = 0.0;
        for (int k = 0; k < si; k++) v += Dt[r * si + k] * Ei[c * si + k];
        X[r * sq + c] = v;
      }
    memcpy(G, X, sizeof(double) * si * sq);
  }
  /* the stretches: forward, ascending (first, end, size): a node whose previous node has another size (or none)
   * alone with size 0 (the general loop), else the longest run of nodes of its size; backward, descending (first,
   * end) with first > end, likewise with the next node */
  int* sg = J->seg;
  int ns = 0;
  for (int I = 0; I < nn;) {
    const int si = NSIZE(J, I);
    const int run = I > 0 && NSIZE(J, I - 1) == si && (si == 2 || si == 4 || si == 6 || si == 8);
    int E = I + 1;
    if (run) {
      while (E < nn && NSIZE(J, E) == si) E++;
    }
    sg[3 * ns] = I, sg[3 * ns + 1] = E, sg[3 * ns + 2] = run ? si : 0;
    ns++;
    I = E;
  }
  J->nseg_f = ns;
  sg += 3 * ns;
  ns = 0;
  for (int I = nn - 1; I >= 0;) {
    const int si = NSIZE(J, I);
    int B = I - 1;
    const int run = I < nn - 1 && NSIZE(J, I + 1) == si && (si == 2 || si == 4 || si == 6 || si == 8);
    if (run) {
      while (B >= 0 && NSIZE(J, B) == si) B--;
    }
    sg[3 * ns] = I, sg[3 * ns + 1] = B, sg[3 * ns + 2] = run ? si : 0;
    ns++;
    I = B;
  }
  J->nseg_b = ns;
  J->blocked = 1;
  return 0;
}

/* forward sweep of node I (size s, previous node's size p, its values a) */
static inline __attribute__((always_inline)) void fwd_node(const double* D, const double* F, double* v,
                                                           const double* a, const int s, const int p) {
  double yv[MAXB] = {0.0};
#pragma GCC unroll 8
  for (int r = 0; r < s; r++) {
    double t = D[r * s] * v[0];
#pragma GCC unroll 8
    for (int k = 1; k <= r; k++) t += D[r * s + k] * v[k];
    yv[r] = t - tree_dot(F + r * p, a, p);
  }
#pragma GCC unroll 8
  for (int r = 0; r < s; r++) v[r] = yv[r];
}

/* backward sweep of node I (size s, next node's size q, its values a) */
static inline __attribute__((always_inline)) void bwd_node(const double* T, const double* G, double* v,
                                                           const double* a, const int s, const int q) {
  double xv[MAXB] = {0.0};
#pragma GCC unroll 8
  for (int r = 0; r < s; r++) {
    double t = T[r * s + r] * v[r];
#pragma GCC unroll 8
    for (int k = r + 1; k < s; k++) t += T[r * s + k] * v[k];
    xv[r] = t - tree_dot(G + r * q, a, q);
  }
#pragma GCC unroll 8
  for (int r = 0; r < s; r++) v[r] = xv[r];
}

/* nodes I0 .. I1-1, all of size S, the node before I0 of size S too: the previous values stay in registers; each
 * node's blocks take 4 S^2 doubles (its next node's size may differ only after the last one's D and F) */
static inline __attribute__((always_inline)) void fwd_run(const cat_job* J, double* y, int I0, int I1, const int S) {
  double a[MAXB];
  double* v = y + J->noff[I0];
  const double* D = J->blk + J->boff[I0];
#pragma GCC unroll 8
  for (int k = 0; k < S; k++) a[k] = v[k - S];
  for (int I = I0; I < I1; I++, v += S, D += 4 * S * S) {
    fwd_node(D, D + S * S, v, a, S, S);
#pragma GCC unroll 8
    for (int k = 0; k < S; k++) a[k] = v[k];
  }
}

/* nodes I0 down to I1 + 1, all of size S, the node after I0 of size S too (the same 4 S^2 doubles per node) */
static inline __attribute__((always_inline)) void bwd_run(const cat_job* J, double* y, int I0, int I1, const int S) {
  double a[MAXB];
  double* v = y + J->noff[I0];
  const double* G = J->blk + J->boff[I0 + 1] - S * S;
#pragma GCC unroll 8
  for (int k = 0; k < S; k++) a[k] = v[k + S];
  for (int I = I0; I > I1; I--, v -= S, G -= 4 * S * S) {
    bwd_node(G - S * S, G, v, a, S, S);
#pragma GCC unroll 8
    for (int k = 0; k < S; k++) a[k] = v[k];
  }
}

/* one node whose neighbour has another size: the node kernels unrolled for each pair of even sizes, else the loops */
#define PAIRS(X, s, p) \
  switch (s * 16 + p) { \
    X(2, 0) X(2, 2) X(2, 4) X(2, 6) X(2, 8) X(4, 0) X(4, 2) X(4, 4) X(4, 6) X(4, 8) \
    X(6, 0) X(6, 2) X(6, 4) X(6, 6) X(6, 8) X(8, 0) X(8, 2) X(8, 4) X(8, 6) X(8, 8) \
    default: GENERIC; \
  }

static void fwd_any(const cat_job* J, double* y, int I) {
  const int s = NSIZE(J, I), p = I > 0 ? NSIZE(J, I - 1) : 0;
  const double* D = J->blk + J->boff[I];
  double* v = y + J->noff[I];
  const double* a = p ? y + J->noff[I - 1] : y;
#define GENERIC fwd_node(D, D + s * s, v, a, s, p)
#define FWD(S_, P_) \
  case S_ * 16 + P_: fwd_node(D, D + S_ * S_, v, a, S_, P_); break;
  PAIRS(FWD, s, p)
#undef FWD
#undef GENERIC
}

static void bwd_any(const cat_job* J, double* y, int I) {
  const int s = NSIZE(J, I), q = I < J->nblk - 1 ? NSIZE(J, I + 1) : 0;
  const double* G = J->blk + J->boff[I + 1] - s * q;
  double* v = y + J->noff[I];
  const double* a = q ? y + J->noff[I + 1] : y;
#define GENERIC bwd_node(G - s * s, G, v, a, s, q)
#define BWD(S_, Q_) \
  case S_ * 16 + Q_: bwd_node(G - S_ * S_, G, v, a, S_, Q_); break;
  PAIRS(BWD, s, q)
#undef BWD
#undef GENERIC
}

/* x <- S^-1 x on the free DOFs [d0, d1) = the blocks [b0, b1) (whole components: S couples nothing outside them,
 * its factor neither, so the entries outside are neither read into nor written; the sweeps' stretches clipped) */
static void block_solve(const cat_job* J, double* x, int d0, int d1, int b0, int b1) {
  double* y = J->pw;
  const int* fi = J->fidx;
  memset(y + J->noff[b0], 0, sizeof(double) * (size_t)(J->noff[b1] - J->noff[b0]));
  for (int i = d0; i < d1; i++) y[fi[i]] = x[i];
  const int* sg = J->seg;
  for (int g = 0; g < J->nseg_f; g++, sg += 3) {
    const int a = sg[0] > b0 ? sg[0] : b0, e = sg[1] < b1 ? sg[1] : b1;
    if (a >= e) continue;
    switch (sg[2]) { /* a run starting inside the range still has a previous block of its size */
      case 2: fwd_run(J, y, a, e, 2); break;
      case 4: fwd_run(J, y, a, e, 4); break;
      case 6: fwd_run(J, y, a, e, 6); break;
      case 8: fwd_run(J, y, a, e, 8); break;
      default: fwd_any(J, y, a);
    }
  }
  for (int g = 0; g < J->nseg_b; g++, sg += 3) {
    const int top = sg[0] < b1 - 1 ? sg[0] : b1 - 1, bot = sg[1] > b0 - 1 ? sg[1] : b0 - 1;
    if (top <= bot) continue;
    switch (sg[2]) {
      case 2: bwd_run(J, y, top, bot, 2); break;
      case 4: bwd_run(J, y, top, bot, 4); break;
      case 6: bwd_run(J, y, top, bot, 6); break;
      case 8: bwd_run(J, y, top, bot, 8); break;
      default: bwd_any(J, y, top);
    }
  }
  for (int i = d0; i < d1; i++) x[i] = y[fi[i]];
}

/* step every DOF */
static void full_range(cat_job* J) {
  J->lb0 = 0, J->lb1 = J->nblk, J->ld0 = 0, J->ld1 = J->n;
}

int mbs_cat_factor(cat_job* J) {
  const int n = J->n, bw = J->bw, w = bw + 1;
  double* L = J->L;
  for (int i = 0; i < n; i++) {
    for (int k = (i < bw ? i : bw); k >= 1; k--) {
      const int j = i - k;
      double s = L[i * w + k];
      for (int m = k + 1; m <= bw && m <= i; m++) s -= L[i * w + m] * L[j * w + (m - k)];
      L[i * w + k] = s * J->invd[j];
    }
    double d = L[i * w];
    for (int m = 1; m <= bw && m <= i; m++) d -= L[i * w + m] * L[i * w + m];
    if (!(d > 0.0)) {
      J->err = 5;
      J->err_value = (double)i;
      return 5;
    }
    L[i * w] = sqrt(d);
    J->invd[i] = 1.0 / L[i * w];
  }
  full_range(J);
  return build_blocks(J);
}

/* x <- S^-1 x on the stepped range [ld0, ld1) (whole components, see block_solve); the forward sweep starts at
 * `first` (entries before it are zero) */
static void band_solve(const cat_job* J, double* x, int first) {
  if (J->blocked) {
    block_solve(J, x, J->ld0, J->ld1, J->lb0, J->lb1);
    return;
  }
  const int n = J->ld1, bw = J->bw, w = bw + 1;
  const double* L = J->L;
  const double* invd = J->invd;
  if (first < J->ld0) first = J->ld0;
  for (int i = first; i < n; i++) {
    double s = x[i];
    const int mmax = (i - first < bw ? i - first : bw);
    const double* Li = L + (long)i * w;
    for (int m = 1; m <= mmax; m++) s -= Li[m] * x[i - m];
    x[i] = s * invd[i];
  }
  for (int i = n - 1; i >= J->ld0; i--) {
    double s = x[i];
    const int mmax = (n - 1 - i < bw ? n - 1 - i : bw);
    for (int m = 1; m <= mmax; m++) s -= L[(long)(i + m) * w + m] * x[i + m];
    x[i] = s * invd[i];
  }
}

void mbs_cat_solve(cat_job* J, double* x) {
  const int b0 = J->lb0, b1 = J->lb1, d0 = J->ld0, d1 = J->ld1;
  full_range(J);
  band_solve(J, x, 0);
  J->lb0 = b0, J->lb1 = b1, J->ld0 = d0, J->ld1 = d1;
}

/* ----------------------------------------------------------------------------------------- contacts */
/* G e_d into col (n), zero for a pinned DOF */
/* G e_d into col on the stepped range [ld0, ld1) (zero there for a pinned DOF; the entries outside are never read:
 * update_live drops every cached column when the range changes) */
static void unit_column(const cat_job* J, int d, double* col) {
  memset(col + J->ld0, 0, sizeof(double) * (J->ld1 - J->ld0));
  if (d < 0) return;
  col[d] = 1.0;
  band_solve(J, col, d);
  const double hh = J->h * J->h;
  for (int i = J->ld0; i < J->ld1; i++) col[i] *= hh;
}

/* [lo, hi) of the m columns of length n at col (contiguous), read on [d0, d1), outside which every entry is below
 * RANGE_EPS of the largest (lo = hi = 0 if all are zero) */
static void col_range(const double* col, int n, int m, int* rng, int d0, int d1) {
  double big = 0.0;
  for (int c = 0; c < m; c++) {
    for (int i = d0; i < d1; i++) big = fmax(big, fabs(col[(long)c * n + i]));
  }
  const double eps = big * RANGE_EPS;
  int lo = n, hi = 0;
  for (int c = 0; c < m; c++) {
    const double* v = col + (long)c * n;
    int a = d0, b = d1;
    while (a < b && !(fabs(v[a]) > eps)) a++;
    while (b > a && !(fabs(v[b - 1]) > eps)) b--;
    if (a < b) {
      lo = a < lo ? a : lo;
      hi = b > hi ? b : hi;
    }
  }
  rng[0] = lo < hi ? lo : 0;
  rng[1] = lo < hi ? hi : 0;
}

/* the ranges of the droppers' G B_j (zrng), once Zg is set */
void mbs_cat_dropper_ranges(cat_job* J) {
  for (int j = 0; j < J->nd; j++) col_range(J->Zg + (long)j * J->n, J->n, 1, J->zrng + 2 * j, 0, J->n);
}

static void set_element(cat_job* J, int k, int e) {
  const int n = J->n;
  double* cols = J->cols + (long)k * 4 * n;
  const int* cwdof = J->cwdof + (long)2 * J->nnode * J->cwk[k];
  const double* w0cw = J->w0cw + (long)2 * J->nnode * J->cwk[k];
  const int old = J->elem[k];
  if (old == e) return;
  if (old >= 0 && e == old + 1) {
    const int d0 = J->ld0, nl = J->ld1 - J->ld0;
    memmove(cols + d0, cols + 2 * (long)n + d0, sizeof(double) * nl);
    memmove(cols + (long)n + d0, cols + 3 * (long)n + d0, sizeof(double) * nl);
  } else {
    unit_column(J, cwdof[2 * e], cols);
    unit_column(J, cwdof[2 * e + 1], cols + n);
  }
  unit_column(J, cwdof[2 * (e + 1)], cols + 2 * (long)n);
  unit_column(J, cwdof[2 * (e + 1) + 1], cols + 3 * (long)n);
  col_range(cols, n, 4, J->crng + 2 * k, J->ld0, J->ld1);
  for (int m = 0; m < 4; m++) {
    const int d = cwdof[2 * e + m];
    J->dofs[4 * k + m] = d >= 0 ? d : 0;
    J->w0d[4 * k + m] = w0cw[2 * e + m];
  }
  J->elem[k] = e;
}

/* the element of contact k's wire holding xp, searched from e */
static int locate(const cat_job* J, int k, double xp, int e) {
  const double* x = J->xnode;
  const int first = J->erng[2 * k], last = J->erng[2 * k + 1];
  if (e < first) e = first;
  if (e > last) e = last;
  while (e < last && xp > x[e + 1]) e++;
  while (e > first && xp < x[e]) e--;
  return e;
}

/* the static deflection at a of a pinned-pinned tensioned beam of length L under a unit force at a (closed form,
 * fe.tensioned_beam_compliance) */
static double beam_compliance(double a, double L, double T, double EI) {
  double s = a * (L - a) / L;
  if (EI > 0.0) {
    const double lam = sqrt(T / EI);
    s -= (-expm1(-2 * lam * a)) * (-expm1(-2 * lam * (L - a))) / (2 * lam * (-expm1(-2 * lam * L)));
  }
  return s / T;
}

/* contact wire c's point-load defect at xi of element e (fe.PointCorrection.defect, same order of operations); an
 * entry with L < 0 is tabulated (a wire stiffened by insulators): its 13 samples at xi = j/12 in its Q slots,
 * Lagrange-interpolated (point_correction.lagrange, SAMPLES = 13) */
static double point_defect(const cat_job* J, int c, int e, double xi) {
  const int k = J->esig[(long)(J->nnode - 1) * c + e];
  const double a0 = J->pref[3 * k], L = J->pref[3 * k + 1], h = J->pref[3 * k + 2];
  if (L == 0.0) return 0.0;
  if (L < 0.0) {
    enum { NS = 13 };
    const double* s = J->pq + 16 * k;
    const double t = xi * (NS - 1);
    double q = 0.0;
    for (int j = 0; j < NS; j++) {
      double p = 1.0, den = 1.0;
      for (int m = 0; m < NS; m++) {
        if (m != j) {
          p *= t - (double)m;
          den *= (double)(j - m);
        }
      }
      q += s[j] * (p / den);
    }
    return q;
  }
  const double x2 = xi * xi, x3 = x2 * xi;
  const double N[4] = {1 - 3 * x2 + 2 * x3, h * (xi - 2 * x2 + x3), 3 * x2 - 2 * x3, h * (x3 - x2)};
  const double* Q = J->pq + 16 * k;
  double q = 0.0;
  for (int r = 0; r < 4; r++) q += N[r] * (((Q[4 * r] * N[0] + Q[4 * r + 1] * N[1]) + Q[4 * r + 2] * N[2]) + Q[4 * r + 3] * N[3]);
  return beam_compliance(a0 + xi * h, L, J->ptk[k], J->cwEI[c]) - q;
}

/* the contact wire's height irregularity at x (m): linear between the table's points, 0 outside the table
 * (fe.irregularity; sim.irregularity_at, the same operations) */
static double irregularity(const cat_job* J, double x) {
  const int m = J->nirr;
  if (m <= 0) return 0.0;
  const double t = (x - J->irr_x0) / J->irr_dx;
  if (!(t >= 0.0) || t > (double)(m - 1)) return 0.0;
  const int i = (int)t;
  if (i >= m - 1) return J->irr[m - 1];
  return J->irr[i] + (t - (double)i) * (J->irr[i + 1] - J->irr[i]);
}

/* element, shape functions and geometry of contact k at position xp; its contact stiffness with the defect */
void mbs_cat_place(cat_job* J, int k, double xp) {
  J->xc[k] = xp;
  J->onw[k] = J->present[k] && xp >= J->xrng[2 * k] && xp <= J->xrng[2 * k + 1];
  if (!J->onw[k]) { /* off its wire: no contact point (a head beyond this wire's section) */
    for (int m = 0; m < 4; m++) J->Nl[4 * k + m] = J->Nf[4 * k + m] = 0.0;
    J->cbc[k] = 0.0;
    J->kce[k] = J->kc;
    J->rirr[k] = 0.0;
    return;
  }
  const int* cwdof = J->cwdof + (long)2 * J->nnode * J->cwk[k];
  const int e = locate(J, k, xp, J->elem[k]);
  set_element(J, k, e);
  const double he = J->xnode[e + 1] - J->xnode[e];
  const double xi = (xp - J->xnode[e]) / he;
  const double x2 = xi * xi, x3 = x2 * xi;
  const double N[4] = {1 - 3 * x2 + 2 * x3, he * (xi - 2 * x2 + x3), 3 * x2 - 2 * x3, he * (x3 - x2)};
  for (int m = 0; m < 4; m++) {
    J->Nl[4 * k + m] = cwdof[2 * e + m] >= 0 ? N[m] : 0.0;
    J->Nf[4 * k + m] = N[m];
  }
  const double d = point_defect(J, J->cwk[k], e, xi);
  J->cbc[k] = d;
  J->kce[k] = d != 0.0 ? J->kc / (1.0 + J->kc * d) : J->kc;
  J->rirr[k] = irregularity(J, xp);
}

/* CW height at contact k from the current u (static sag and the irregularity under it included; at a pinned end
 * its static height alone) */
double mbs_cat_wire(const cat_job* J, int k) {
  double s = 0.0;
  for (int m = 0; m < 4; m++) {
    if (J->Nl[4 * k + m] != 0.0 || J->Nf[4 * k + m] == 0.0) {
      s += J->Nl[4 * k + m] * (J->w0d[4 * k + m] + J->u[J->dofs[4 * k + m]]);
    } else {
      s += J->Nf[4 * k + m] * J->w0d[4 * k + m];
    }
  }
  return s + J->rirr[k];
}

/* ------------------------------------------------------------------------------------------ stages */
/* 1 when dropper j hangs in the stepped range (both its ends are in one component) */
static inline int dropper_live(const cat_job* J, int j) { return J->up[j] >= J->ld0 && J->up[j] < J->ld1; }

/* The components in play at t_new: component c from the step its contact wires' x-range begins under the foremost
 * contact point (before, nothing has touched it: its state is exactly the static one, zero, as stepping it would
 * keep it) until every contact point has passed its end (with `retire`; after, nothing it does reaches a
 * pantograph: only pantographs join sections). The stepped range runs from the first component in play to the
 * last; a slack dropper left outside it leaves the slack set. Without components, or none in play, everything. */
static void update_live(cat_job* J, double t_new) {
  if (J->ncomp <= 0) {
    full_range(J);
    return;
  }
  double xmax = -INFINITY, xmin = INFINITY;
  for (int k = 0; k < J->ncon; k++) {
    double xp = J->xs[k] + J->V * t_new;
    if (xp > J->xend[k]) xp = J->xend[k];
    xmax = xp > xmax ? xp : xmax;
    xmin = xp < xmin ? xp : xmin;
  }
  int lo = -1, hi = -1;
  for (int c = 0; c < J->ncomp; c++) {
    const double x0 = J->cmpx[2 * c], x1 = J->cmpx[2 * c + 1];
    if (!(x0 <= x1) || xmax < x0) continue;
    if (J->retire && xmin > x1) {
      if (isnan(J->cmpt[c])) J->cmpt[c] = t_new;
      continue;
    }
    if (lo < 0) lo = c;
    hi = c;
  }
  const int b0 = J->lb0, b1 = J->lb1;
  if (lo < 0) {
    full_range(J);
  } else {
    J->lb0 = J->cmpb[2 * lo], J->lb1 = J->cmpb[2 * hi + 1];
    J->ld0 = J->cmpd[2 * lo], J->ld1 = J->cmpd[2 * hi + 1];
  }
  if (J->lb0 == b0 && J->lb1 == b1) return;
  for (int k = 0; k < J->ncon; k++) J->elem[k] = -1; /* the cached columns hold the old range only: anew */
  int c = 0;
  for (int b = 0; b < J->nslack; b++) { /* a slack dropper left outside the range leaves the slack set */
    if (!dropper_live(J, J->slk[b])) continue;
    J->slk[c] = J->slk[b];
    J->sS[c++] = J->sS[b];
  }
  J->nslack = c;
}

/* R = q + h/2 g_n and vb* = S^-1 R; contact quantities a, Cm, bz and the dropper elongations dstar (the components in
 * play, update_live) */
void mbs_cat_predict(cat_job* J, double t_new) {
  update_live(J, t_new);
  const int d0 = J->ld0, n = J->n, nl = J->ld1 - J->ld0, nc = J->ncon, nd = J->nd;
  const double hh2 = J->hh2, h2 = 2 * J->h;
  double *R = J->R, *vbs = J->vbs, *u = J->u;
  memcpy(R + d0, J->q + d0, sizeof(double) * nl);
  for (int k = 0; k < nc; k++) {
    for (int m = 0; m < 4; m++) {
      const double g = J->gv[4 * k + m];
      if (g != 0.0) R[J->dofs[4 * k + m]] += hh2 * g;
    }
  }
  for (int a = 0; a < J->nslack; a++) {
    const int j = J->slk[a];
    R[J->up[j]] -= hh2 * J->sS[a];
    R[J->lo[j]] += hh2 * J->sS[a];
  }
  memcpy(vbs + d0, R + d0, sizeof(double) * nl);
  band_solve(J, vbs, 0);
  for (int k = 0; k < nc; k++) {
    if (!J->present[k]) continue;
    double xp = J->xs[k] + J->V * t_new;
    if (xp > J->xend[k]) xp = J->xend[k];
    mbs_cat_place(J, k, xp);
    if (!J->onw[k]) continue;
    const double* N = J->Nl + 4 * k;
    const int* dk = J->dofs + 4 * k;
    double s = 0.0, s0 = 0.0;
    for (int m = 0; m < 4; m++) {
      s += N[m] * (u[dk[m]] + h2 * vbs[dk[m]]);
      s0 += J->Nf[4 * k + m] * J->w0d[4 * k + m];
    }
    J->a[k] = (s + s0) + J->rirr[k];
  }
  for (int k = 0; k < nc; k++) {
    if (!J->onw[k]) continue;
    const double* N = J->Nl + 4 * k;
    const int* dk = J->dofs + 4 * k;
    for (int l = 0; l < nc; l++) {
      if (!J->onw[l]) {
        J->Cm[k * nc + l] = 0.0;
        continue;
      }
      const double* cl = J->cols + (long)l * 4 * n;
      const double* Nl = J->Nl + 4 * l;
      double c = 0.0;
      for (int m = 0; m < 4; m++) {
        double z = 0.0;
        for (int r = 0; r < 4; r++) z += cl[(long)r * n + dk[m]] * Nl[r];
        c += N[m] * z;
      }
      J->Cm[k * nc + l] = c;
    }
    if (J->slack) {
      const double* ck = J->cols + (long)k * 4 * n;
      for (int j = 0; j < nd; j++) {
        const int im = J->up[j], ic = J->lo[j];
        double z = 0.0;
        if (dropper_live(J, j)) {
          for (int r = 0; r < 4; r++) z += (ck[(long)r * n + im] - ck[(long)r * n + ic]) * N[r];
        }
        J->bz[k * nd + j] = z;
      }
    }
  }
  if (J->slack) {
    for (int j = 0; j < nd; j++) {
      if (!dropper_live(J, j)) continue;
      const int im = J->up[j], ic = J->lo[j];
      J->dstar[j] = (u[im] - u[ic]) + h2 * (vbs[im] - vbs[ic]);
    }
  }
}

/* dense solve A x = r (m x m, row-major, partial pivoting); A and r are overwritten, x in r */
static int dense_solve(double* A, double* r, int m) {
  for (int c = 0; c < m; c++) {
    int piv = c;
    double best = fabs(A[c * m + c]);
    for (int i = c + 1; i < m; i++) {
      if (fabs(A[i * m + c]) > best) {
        best = fabs(A[i * m + c]);
        piv = i;
      }
    }
    if (best == 0.0) return 1;
    if (piv != c) {
      for (int j = 0; j < m; j++) {
        double tmp = A[c * m + j];
        A[c * m + j] = A[piv * m + j];
        A[piv * m + j] = tmp;
      }
      double tmp = r[c];
      r[c] = r[piv];
      r[piv] = tmp;
    }
    const double inv = 1.0 / A[c * m + c];
    for (int i = c + 1; i < m; i++) {
      const double fct = A[i * m + c] * inv;
      if (fct == 0.0) continue;
      for (int j = c + 1; j < m; j++) A[i * m + j] -= fct * A[c * m + j];
      r[i] -= fct * r[c];
    }
  }
  for (int c = m - 1; c >= 0; c--) {
    double s = r[c];
    for (int j = c + 1; j < m; j++) s -= A[c * m + j] * r[j];
    r[c] = s / A[c * m + c];
  }
  return 0;
}

/* the local problem: contact forces f (present contacts) and the slack set with its corrections, given the head
 * maps P - gp f of the pantographs (active-set iteration, see the file's comment and sim.Passage.solve_local) */
int mbs_cat_local(cat_job* J) {
  const int nc = J->ncon, nd = J->nd;
  int* act_idx = J->iwork;        /* active contacts */
  int* in_s = J->iwork + nc + nd; /* membership of the slack set (nd) */
  double* f = J->f;
  double* s = J->sS;
  int* S = J->slk;
  for (int it = 0; it < J->max_iter; it++) {
    int na = 0;
    for (int k = 0; k < nc; k++) {
      if (J->onw[k] && J->active[k]) act_idx[na++] = k;
    }
    const int ms = J->nslack, m = na + ms;
    double* A = J->work;
    double* r = J->work + (long)m * m;
    for (int i = 0; i < na; i++) {
      const int k = act_idx[i];
      const double kc = J->kce[k];
      for (int j = 0; j < na; j++) A[i * m + j] = kc * J->Cm[k * nc + act_idx[j]];
      A[i * m + i] += 1.0 + kc * J->gp[k];
      for (int j = 0; j < na; j++) { /* another contact of the same head: y_head = P - gp (f_k + f_l + ...) */
        if (j != i && J->own[act_idx[j]] == J->own[k]) A[i * m + j] += kc * J->gp[k];
      }
      for (int b = 0; b < ms; b++) A[i * m + na + b] = -kc * J->bz[k * nd + S[b]];
      r[i] = kc * (J->P[k] - J->a[k]);
    }
    for (int b = 0; b < ms; b++) {
      const int j = S[b], row = na + b;
      const double kd = J->kdj[j];
      for (int i = 0; i < na; i++) A[row * m + i] = kd * J->bz[act_idx[i] * nd + j];
      for (int c = 0; c < ms; c++) A[row * m + na + c] = (b == c ? 1.0 : 0.0) - kd * J->D[j * nd + S[c]];
      r[row] = -J->T0[j] - kd * J->dstar[j];
    }
    if (m > 0 && dense_solve(A, r, m)) {
      J->err = 4;
      return 4;
    }
    for (int k = 0; k < nc; k++) f[k] = 0.0;
    for (int i = 0; i < na; i++) f[act_idx[i]] = r[i];
    for (int b = 0; b < ms; b++) s[b] = r[na + b];
    int changed = 0;
    if (J->unilateral) {
      for (int k = 0; k < nc; k++) {
        if (!J->onw[k]) continue;
        if (J->active[k]) {
          if (f[k] < 0) {
            J->active[k] = 0;
            changed = 1;
          }
        } else {
          double gap = J->P[k] - J->a[k];
          for (int l = 0; l < nc; l++) gap -= J->Cm[k * nc + l] * f[l];
          for (int b = 0; b < ms; b++) gap += J->bz[k * nd + S[b]] * s[b];
          for (int l = 0; l < nc; l++) {
            if (l != k && J->own[l] == J->own[k] && f[l] != 0.0) gap -= J->gp[k] * f[l];
          }
          if (gap > 0) {
            J->active[k] = 1;
            changed = 1;
          }
        }
      }
    }
    if (J->slack) {
      for (int j = 0; j < nd; j++) in_s[j] = 0;
      for (int b = 0; b < ms; b++) in_s[S[b]] = 1;
      int setchange = 0;
      for (int b = 0; b < ms; b++) {
        if (s[b] < 0) {
          in_s[S[b]] = 0;
          setchange = 1;
        }
      }
      for (int j = 0; j < nd; j++) {
        if (!J->dslack[j] || !dropper_live(J, j)) continue; /* bilateral: never slack; outside: not stepped */
        double d = J->dstar[j];
        for (int k = 0; k < nc; k++) d += J->bz[k * nd + j] * f[k];
        for (int b = 0; b < ms; b++) d -= J->D[j * nd + S[b]] * s[b];
        const double tension = J->T0[j] + J->kdj[j] * d;
        int was = 0;
        for (int b = 0; b < ms; b++) was |= (S[b] == j);
        if (tension < 0 && !was) {
          in_s[j] = 1;
          setchange = 1;
        }
      }
      if (setchange) {
        int c = 0;
        for (int j = 0; j < nd; j++) {
          if (in_s[j]) S[c++] = j;
        }
        J->nslack = c;
        changed = 1;
      }
    }
    if (!changed) return 0;
  }
  J->err = 4;
  return 4;
}

/* the end-of-step state from f and the slack corrections; the new local forces g_{n+1} */
void mbs_cat_advance(cat_job* J) {
  const int n = J->n, d0 = J->ld0, d1 = J->ld1, nc = J->ncon, nd = J->nd;
  const double inv2h = 1.0 / (2 * J->h), h2 = 2 * J->h, hh2 = J->hh2;
  double *vb = J->vb, *R = J->R, *u = J->u, *q = J->q, *p = J->p;
  memcpy(vb + d0, J->vbs + d0, sizeof(double) * (d1 - d0));
  for (int k = 0; k < nc; k++) {
    if (!J->onw[k] || J->f[k] == 0.0) continue;
    const double* ck = J->cols + (long)k * 4 * n;
    const double* N = J->Nl + 4 * k;
    const double w0 = N[0] * J->f[k] * inv2h, w1 = N[1] * J->f[k] * inv2h, w2 = N[2] * J->f[k] * inv2h,
                 w3 = N[3] * J->f[k] * inv2h;
    const int lo = J->crng[2 * k], hi = J->crng[2 * k + 1];
    for (int i = lo; i < hi; i++) vb[i] += ck[i] * w0 + ck[n + i] * w1 + ck[2 * n + i] * w2 + ck[3 * n + i] * w3;
  }
  for (int b = 0; b < J->nslack; b++) {
    const int j = J->slk[b];
    const double* z = J->Zg + (long)j * n;
    const double c = J->sS[b] * inv2h;
    for (int i = J->zrng[2 * j]; i < J->zrng[2 * j + 1]; i++) vb[i] -= z[i] * c;
  }
  for (int i = d0; i < d1; i++) u[i] += h2 * vb[i];
  for (int k = 0; k < nc; k++) {
    for (int m = 0; m < 4; m++) {
      const double g = J->onw[k] ? J->Nl[4 * k + m] * J->f[k] : 0.0;
      J->gv[4 * k + m] = g;
      if (g != 0.0) R[J->dofs[4 * k + m]] += hh2 * g;
    }
  }
  for (int b = 0; b < J->nslack; b++) {
    const int j = J->slk[b];
    R[J->up[j]] -= hh2 * J->sS[b];
    R[J->lo[j]] += hh2 * J->sS[b];
  }
  const double c_ab = J->c_ab, inv = J->inv_1ha, thh = J->two_hh;
  const int *Kp = J->Kp, *Ki = J->Ki;
  const double* Kx = J->Kx;
  for (int i = d0; i < d1; i++) {
    double kv = 0.0;
    for (int a = Kp[i]; a < Kp[i + 1]; a++) kv += Kx[a] * vb[Ki[a]];
    const double A2 = 2.0 * ((R[i] - c_ab * kv) * inv);
    const double B2 = thh * kv;
    const double qn = A2 - B2 - p[i];
    p[i] = A2 + B2 - q[i];
    q[i] = qn;
  }
  for (int j = 0; j < nd; j++) {
    if (!dropper_live(J, j)) continue;
    const int im = J->up[j], ic = J->lo[j];
    const double dv = 2.0 * J->kdj[j] * J->c_kd * (vb[im] - vb[ic]);
    q[im] += dv;
    p[im] += dv;
    q[ic] -= dv;
    p[ic] -= dv;
  }
}

/* finite state, displacements inside the small-displacement model, a pantograph not flying away */
int mbs_cat_check(cat_job* J) {
  double umax = 0.0;
  for (int i = J->ld0; i < J->ld1; i++) { /* outside: static, or as checked when last stepped */
    const double a = fabs(J->u[i]);
    if (!(a <= umax)) umax = a; /* NaN propagates */
  }
  for (int k = 0; k < J->ncon; k++) {
    if (!J->present[k]) continue;
    const double y = J->head[k], f = J->f[k];
    if (!(isfinite(umax) && isfinite(y) && isfinite(f))) {
      J->err = 1, J->err_con = k, J->err_value = umax;
      return 1;
    }
    if (fabs(y) > J->max_disp && f == 0.0) {
      J->err = 3, J->err_con = k, J->err_value = y;
      return 3;
    }
    if (fabs(y) > J->max_disp) {
      J->err = 2, J->err_con = k, J->err_value = y;
      return 2;
    }
  }
  if (!isfinite(umax)) {
    J->err = 1, J->err_con = -1, J->err_value = umax;
    return 1;
  }
  if (umax > J->max_disp) {
    J->err = 2, J->err_con = -1, J->err_value = umax;
    return 2;
  }
  return 0;
}

/* ---------------------------------------------------------------------------------- 2-mass pantographs */
/* The EN 50318 2-mass pantograph as a one-port (mbsuite.h), the twin of `pantographs.TwoMassPantograph`: its state in
 * TM_SIZE doubles, x1 x2 v1 v2, S^-1 (S00 S01 S10 S11, S = M + hC + h^2 K), m1 m2, k11 k12 k22, the frame's constant
 * uplift F0 + Fa_f, the head's aerodynamic uplift Fa_h, then the pending x1 x2 v1 v2 of the last trial. The
 * trapezoidal rule makes its head height exactly affine in the end force. */
#define TM_SIZE 19

static void twomass_map(void* self, double t, double dt, double f0, double* P, double* g) {
  const double* s = (const double*)self;
  const double h = 0.5 * dt;
  const double r1 = s[8] * s[2] - h * (s[10] * s[0] + s[11] * s[1]) - h * (f0 + 0.0) / 2 + h * s[14];
  const double r2 = s[9] * s[3] - h * (s[11] * s[0] + s[12] * s[1]) + h * s[13];
  *P = s[0] + 2 * h * (s[4] * r1 + s[5] * r2);
  *g = h * h * s[4];
}

static int twomass_trial(void* self, double t, double dt, double f0, double f1, double* y) {
  double* s = (double*)self;
  const double h = 0.5 * dt;
  const double r1 = s[8] * s[2] - h * (s[10] * s[0] + s[11] * s[1]) - h * (f0 + f1) / 2 + h * s[14];
  const double r2 = s[9] * s[3] - h * (s[11] * s[0] + s[12] * s[1]) + h * s[13];
  const double vb1 = s[4] * r1 + s[5] * r2;
  const double vb2 = s[6] * r1 + s[7] * r2;
  s[15] = s[0] + 2 * h * vb1;
  s[16] = s[1] + 2 * h * vb2;
  s[17] = 2 * vb1 - s[2];
  s[18] = 2 * vb2 - s[3];
  *y = s[15];
  return 0;
}

static void twomass_commit(void* self) {
  double* s = (double*)self;
  memcpy(s, s + 15, 4 * sizeof(double));
}

static void twomass_outputs(const void* self, double* out) {
  const double* s = (const double*)self;
  out[0] = s[0];
  out[1] = s[1];
}

void mbs_cat_twomass_port(mbs_port* port, double* state) {
  port->self = state;
  port->affine = 1;
  port->nout = 2;
  port->map = twomass_map;
  port->trial = twomass_trial;
  port->commit = twomass_commit;
  port->outputs = twomass_outputs;
}
int mbs_cat_twomass_size(void) { return TM_SIZE; }

static void record(cat_job* J, long row, double t) {
  const int nc = J->ncon;
  if (J->rec_t) J->rec_t[row] = t;
  for (int k = 0; k < nc; k++) {
    if (J->rec_x) J->rec_x[row * nc + k] = J->xc[k];
    if (J->rec_f) J->rec_f[row * nc + k] = J->onw[k] ? J->f[k] : 0.0;
    if (J->rec_head) J->rec_head[row * nc + k] = J->head[k];
    if (J->rec_wire) J->rec_wire[row * nc + k] = J->onw[k] ? mbs_cat_wire(J, k) + J->cbc[k] * J->f[k] : 0.0;
    if (J->rec_out && J->present[k] && J->own[k] == k && J->ports[k]) {
      const mbs_port* pt = J->ports[k];
      pt->outputs(pt->self, J->rec_out + row * J->nout + J->ooff[k]);
    }
  }
  if (J->rec_up) {
    for (int j = 0; j < J->nsup; j++) {
      const int d = J->supidx[j];
      J->rec_up[row * J->nsup + j] = d >= 0 ? J->u[d] : 0.0;
    }
  }
  if (J->rec_ns) J->rec_ns[row] = J->nslack;
}

/* ------------------------------------------------------------------------------------------------ coupling */
/* The contact forces of the step ending at t + dt and every present pantograph advanced to it, the twin of
 * `train._Secant.couple`: an affine pantograph gives its exact head map P - g f1; a nonlinear one is iterated by the
 * secant rule on its force (the slope kept between steps in gs), all of them in one local problem per iteration,
 * until every nonlinear head map is consistent to 1e-13 + 1e-11 |y|; then each pantograph's last trial (an affine one
 * steps once with its force) is committed. Returns 0 or the error code (J->err). */
static int port_failed(cat_job* J, int k, int code, double t_end) {
  J->err = 6;
  J->err_con = k;
  J->err_port = code;
  J->err_value = t_end;
  return 6;
}

/* the force on head k (an owner): the sum of its contacts' forces in v, the owner's first */
static inline double head_sum(const cat_job* J, const double* v, int k) {
  double s = v[k];
  for (int l = k + 1; l < J->ncon && J->own[l] == k; l++) s += v[l];
  return s;
}

/* the owner's head map and head height handed to the head's other contacts */
static inline void share_map(cat_job* J, int k) {
  for (int l = k + 1; l < J->ncon && J->own[l] == k; l++) {
    J->P[l] = J->P[k];
    J->gp[l] = J->gp[k];
  }
}

static int couple(cat_job* J, double t) {
  const int nc = J->ncon;
  const double dt = J->dt;
  double *fprev = J->cw, *ya = J->cw + nc, *fa = J->cw + 2 * nc, *yh = J->cw + 3 * nc;
  int* nonlin = J->nl;
  int nn = 0;
  for (int k = 0; k < nc; k++) {
    if (!J->present[k] || J->own[k] != k) continue;
    fprev[k] = head_sum(J, J->f, k);
  }
  for (int k = 0; k < nc; k++) {
    if (!J->present[k] || J->own[k] != k) continue;
    mbs_port* pt = J->ports[k];
    if (pt->affine) {
      pt->map(pt->self, t, dt, fprev[k], J->P + k, J->gp + k);
      share_map(J, k);
      continue;
    }
    double y0, y1;
    int code = pt->trial(pt->self, t, dt, fprev[k], fprev[k], &y0);
    if (!code && isnan(J->gs[k])) {
      code = pt->trial(pt->self, t, dt, fprev[k], fprev[k] + 1.0, &y1);
      J->gs[k] = y0 - y1;
    }
    if (code) return port_failed(J, k, code, t + dt);
    J->gp[k] = J->gs[k];
    J->P[k] = y0 + J->gs[k] * fprev[k];
    share_map(J, k);
    ya[k] = y0;
    fa[k] = fprev[k];
    nonlin[nn++] = k;
  }
  int done = 0;
  for (int it = 0; it < 30 && !done; it++) {
    if (mbs_cat_local(J)) {
      J->err_value = t + dt;
      return J->err;
    }
    done = 1;
    for (int i = 0; i < nn; i++) {
      const int k = nonlin[i];
      mbs_port* pt = J->ports[k];
      const double f = head_sum(J, J->f, k);
      const int code = pt->trial(pt->self, t, dt, fprev[k], f, yh + k);
      if (code) return port_failed(J, k, code, t + dt);
      if (f == fa[k]) continue;
      const double y = yh[k];
      const double err = y - (J->P[k] - J->gp[k] * f);
      if (fabs(err) < 1e-13 + 1e-11 * fabs(y)) continue;
      done = 0;
      if (fabs(f - fa[k]) > 1e-9) {
        const double g_new = (ya[k] - y) / (f - fa[k]);
        if (g_new > 0) {
          J->gs[k] = g_new;
          J->gp[k] = g_new;
        }
      }
      J->P[k] = y + J->gp[k] * f;
      share_map(J, k);
      fa[k] = f;
      ya[k] = y;
    }
  }
  if (!done) {
    J->err = 7;
    J->err_value = t + dt;
    return 7;
  }
  for (int k = 0; k < nc; k++) {
    if (!J->present[k] || J->own[k] != k) continue;
    mbs_port* pt = J->ports[k];
    if (pt->affine) {
      const int code = pt->trial(pt->self, t, dt, fprev[k], head_sum(J, J->f, k), yh + k);
      if (code) return port_failed(J, k, code, t + dt);
    }
    pt->commit(pt->self);
    J->head[k] = yh[k];
    for (int l = k + 1; l < nc && J->own[l] == k; l++) J->head[l] = yh[k];
  }
  J->n_local++;
  return 0;
}

/* steps n0+1 .. n1, every present contact coupled through its port; records row n after step n; checks every
 * `check_every` steps and at n1. Returns 0 or the error code (J->err; the time in J->err_value for codes 4, 6, 7). */
int mbs_cat_run(cat_job* J, long n0, long n1, int check_every) {
  const int nc = J->ncon;
  for (int k = 0; k < nc; k++) {
    if (J->present[k] && J->own[k] == k && !J->ports[k]) {
      J->err = 8;
      J->err_con = k;
      return 8;
    }
  }
  for (long n = n0 + 1; n <= n1; n++) {
    const double t_new = (double)n * J->dt;
    mbs_cat_predict(J, t_new);
    if (couple(J, t_new - J->dt)) return J->err;
    mbs_cat_advance(J);
    record(J, n, t_new);
    if ((check_every > 0 && n % check_every == 0) || n == n1) {
      if (mbs_cat_check(J)) return J->err;
    }
  }
  return 0;
}

void mbs_cat_record(cat_job* J, long row, double t) { record(J, row, t); }
