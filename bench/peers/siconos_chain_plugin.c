/* Siconos plugin for bench/peers/siconos_chain.py: the internal forces of a chain of N discs
 * in Lagrangian form (docs/model.md §4a; the rig's form in siconos_rotor_plugin.c is its
 * N = 2 case) and their Jacobians, in Siconos' FPtr6 signature
 *   (time, size of q, q, v, out, size of z, z)
 * with matrices column-major. q = [theta_1 .. theta_N, x_1 .. x_N]: a disc's angle, then the
 * pseudo-DOF its frictional contact presses on.
 *
 * For disc i (0-based), with the spring k_i and coupling c_i to the disc above (none for
 * i = 0) and the friction law's single-valued part:
 *   F_int[i]     = k_i (theta_i - theta_{i-1}) + k_{i+1} (theta_i - theta_{i+1})
 *                + c_i (v_i - v_{i-1}) + c_{i+1} (v_i - v_{i+1}) + smooth_i(v_i)
 *   F_int[N + i] = max(level_i(|v_i|), 0)   (the contact's normal force)
 * smooth_i: upper family b v + dt_s + db |v| (its level t_s constant); exponential and
 * Stribeck families b v, plus min(level, 0) sign(v) (a negative level would open the contact,
 * so it acts as a smooth force there, as in the rig's plugin); viscous b v (no contact).
 *
 * z = [N, then per disc 14 values: family (0 viscous, 1 upper, 2 exponential, 3 stribeck),
 *      k, c, b, t_s, dt_s, db, t_1, t_2, w_1, w_2, t_c, omega_s, delta]
 */
#include <math.h>

enum { FAM, K, C, B, TS, DTS, DB, T1, T2, W1, W2, TC, OMS, DEL, STRIDE };

static const double *disc(const double *z, unsigned int i) { return z + 1 + STRIDE * i; }

/* The level N(x) for x = |v| >= 0 and dN/dx; the upper family's is its constant t_s, a
 * viscous law's 0. */
static void level(const double *d, double x, double *n, double *dn)
{
  if (d[FAM] == 2.0) {
    double a = tanh(0.5 * d[W1] * x), b = tanh(0.5 * d[W2] * x);
    *n = d[TS] + d[T1] * a + d[T2] * b;
    *dn = 0.5 * d[T1] * d[W1] * (1.0 - a * a) + 0.5 * d[T2] * d[W2] * (1.0 - b * b);
  } else if (d[FAM] == 3.0) {
    double r = pow(x / d[OMS], d[DEL]);
    double e = exp(-r);
    *n = d[TC] + (d[TS] - d[TC]) * e;
    *dn = x > 0.0 ? -(d[TS] - d[TC]) * e * d[DEL] * r / x : 0.0;
  } else if (d[FAM] == 1.0) {
    *n = d[TS];
    *dn = 0.0;
  } else {
    *n = 0.0;
    *dn = 0.0;
  }
}

static double sgn(double v) { return v < 0.0 ? -1.0 : 1.0; }

void chain_fint(double time, unsigned int n, double *q, double *v, double *f,
                unsigned int nz, double *z)
{
  (void)time; (void)n; (void)nz;
  unsigned int m = (unsigned int)z[0];
  for (unsigned int i = 0; i < m; i++) {
    const double *d = disc(z, i);
    double nl, dnl;
    level(d, fabs(v[i]), &nl, &dnl);
    double t = d[B] * v[i];
    if (d[FAM] == 1.0) t += d[DTS] + d[DB] * fabs(v[i]);
    if (d[FAM] >= 2.0 && nl < 0.0) t += nl * sgn(v[i]);
    if (i > 0) t += d[K] * (q[i] - q[i - 1]) + d[C] * (v[i] - v[i - 1]);
    if (i + 1 < m) {
      const double *e = disc(z, i + 1);
      t += e[K] * (q[i] - q[i + 1]) + e[C] * (v[i] - v[i + 1]);
    }
    f[i] = t;
    f[m + i] = nl > 0.0 ? nl : 0.0;
  }
}

void chain_jac_q(double time, unsigned int n, double *q, double *v, double *jac,
                 unsigned int nz, double *z)
{
  (void)time; (void)q; (void)v; (void)nz;
  unsigned int m = (unsigned int)z[0];
  for (unsigned int i = 0; i < n * n; i++) jac[i] = 0.0;
  /* column-major: jac[row + n * col] */
  for (unsigned int i = 0; i + 1 < m; i++) {
    double k = disc(z, i + 1)[K];
    jac[i + n * i] += k;
    jac[(i + 1) + n * (i + 1)] += k;
    jac[i + n * (i + 1)] -= k;
    jac[(i + 1) + n * i] -= k;
  }
}

void chain_jac_v(double time, unsigned int n, double *q, double *v, double *jac,
                 unsigned int nz, double *z)
{
  (void)time; (void)q; (void)nz;
  unsigned int m = (unsigned int)z[0];
  for (unsigned int i = 0; i < n * n; i++) jac[i] = 0.0;
  for (unsigned int i = 0; i < m; i++) {
    const double *d = disc(z, i);
    double nl, dnl;
    level(d, fabs(v[i]), &nl, &dnl);
    double s = sgn(v[i]);
    double own = d[B];
    if (d[FAM] == 1.0) own += d[DB] * s;
    /* d/dv [N(|v|) sign v] = N'(|v|) away from 0 */
    if (d[FAM] >= 2.0 && nl < 0.0) own += dnl;
    jac[i + n * i] += own;
    jac[(m + i) + n * i] = nl > 0.0 ? dnl * s : 0.0;
    if (i + 1 < m) {
      double c = disc(z, i + 1)[C];
      jac[i + n * i] += c;
      jac[(i + 1) + n * (i + 1)] += c;
      jac[i + n * (i + 1)] -= c;
      jac[(i + 1) + n * i] -= c;
    }
  }
}
