/* Siconos plugin for bench/peers/siconos_rotor.py: the internal forces of the rotor's
 * Lagrangian form (docs/model.md, "Lagrangian form"; rotor-model's
 * lagrangian.rs) and their Jacobians, in Siconos' FPtr6 signature
 *   (time, size of q, q, v, out, size of z, z)
 * with matrices column-major. q = [theta_u, theta_l, x_u, x_l].
 *
 * F_int(q, v) = [ b_u v_u + k_theta alpha + dT_su + db_u |v_u|,
 *                 b_l v_l - k_theta alpha + min(N_l, 0) sign(v_l),
 *                 T_su,
 *                 max(N_l, 0) ],                       alpha = theta_u - theta_l,
 * N_l = N_l(|v_l|) the lower friction level (exponential or Stribeck family). The contact
 * of x_l carries the non-negative part of the level; a negative level (Table 1 above
 * |omega_l| ~ 18 rad/s) would open it, so its (single-valued, far from omega_l = 0) part is a
 * smooth force on theta_l instead, as rotor-moreau does.
 *
 * z = [k_theta, b_u, b_l, T_su, dT_su, db_u, family (0 exponential, 1 Stribeck),
 *      T_sl, T_1, T_2, w_1, w_2, T_cl, omega_s, delta]
 */
#include <math.h>

enum { KT, BU, BL, TSU, DTSU, DBU, FAM, TSL, T1, T2, W1, W2, TCL, OMS, DEL, NZ };

/* Level N(x) for x = |v| >= 0 and its derivative dN/dx. */
static void level(const double *z, double x, double *n, double *dn)
{
  if (z[FAM] == 0.0) {
    double a = tanh(0.5 * z[W1] * x), b = tanh(0.5 * z[W2] * x);
    *n = z[TSL] + z[T1] * a + z[T2] * b;
    *dn = 0.5 * z[T1] * z[W1] * (1.0 - a * a) + 0.5 * z[T2] * z[W2] * (1.0 - b * b);
  } else {
    double r = pow(x / z[OMS], z[DEL]);
    double e = exp(-r);
    *n = z[TCL] + (z[TSL] - z[TCL]) * e;
    *dn = x > 0.0 ? -(z[TSL] - z[TCL]) * e * z[DEL] * r / x : 0.0;
  }
}

static double sgn(double v) { return v < 0.0 ? -1.0 : 1.0; }

void rotor_fint(double time, unsigned int n, double *q, double *v, double *f,
                unsigned int nz, double *z)
{
  (void)time; (void)n; (void)nz;
  double alpha = q[0] - q[1];
  double nl, dnl;
  level(z, fabs(v[1]), &nl, &dnl);
  f[0] = z[BU] * v[0] + z[KT] * alpha + z[DTSU] + z[DBU] * fabs(v[0]);
  f[1] = z[BL] * v[1] - z[KT] * alpha + (nl < 0.0 ? nl * sgn(v[1]) : 0.0);
  f[2] = z[TSU];
  f[3] = nl > 0.0 ? nl : 0.0;
}

void rotor_jac_q(double time, unsigned int n, double *q, double *v, double *jac,
                 unsigned int nz, double *z)
{
  (void)time; (void)q; (void)v; (void)nz;
  for (unsigned int i = 0; i < n * n; i++) jac[i] = 0.0;
  /* column-major: jac[row + n * col] */
  jac[0 + n * 0] = z[KT];
  jac[0 + n * 1] = -z[KT];
  jac[1 + n * 0] = -z[KT];
  jac[1 + n * 1] = z[KT];
}

void rotor_jac_v(double time, unsigned int n, double *q, double *v, double *jac,
                 unsigned int nz, double *z)
{
  (void)time; (void)q; (void)nz;
  for (unsigned int i = 0; i < n * n; i++) jac[i] = 0.0;
  double nl, dnl;
  level(z, fabs(v[1]), &nl, &dnl);
  double s = sgn(v[1]);
  jac[0 + n * 0] = z[BU] + z[DBU] * sgn(v[0]);
  /* d/dv [N(|v|) sign v] = N'(|v|) away from 0 */
  jac[1 + n * 1] = z[BL] + (nl < 0.0 ? dnl : 0.0);
  jac[3 + n * 1] = nl > 0.0 ? dnl * s : 0.0;
}
