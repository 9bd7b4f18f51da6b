/* A first-order Moreau-type time-stepper for the rotor benchmark, written from BENCHMARK.md
 * alone: a client of the job-file protocol in plain C99.
 *
 *   cc -O2 -o first_order bench/clients/first_order.c -lm
 *   rotor bench --external first_order:h=./first_order
 *
 * Scheme (backward Euler in the velocities, the friction taken at the end of the step, the
 * spring at its start; first order in h):
 *
 *   J_u (w_u' - w_u) = h (k_m u - k a - T_u),   T_u in F_u(w_u')
 *   J_l (w_l' - w_l) = h (k a - T_l),           T_l in F_l(w_l')
 *   a' = a + h (w_u' - w_l')
 *
 * F is the set-valued friction law: T_c(w) sgn(w) for w != 0, the static interval at w = 0.
 * With the spring explicit the two discs decouple, and each step is one scalar inclusion
 * per disc: the disc sticks (w' = 0 exactly) when the applied impulse lies inside the static
 * interval, else it slips in the direction of that impulse and w' solves a scalar equation
 * (safeguarded Newton). Events are the step ends where a disc starts or stops sticking, or
 * reverses: rough (to within h), but honest. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char *job;

/* The number after "key": in the job text, searching from `from` (a crude reader that is
 * enough for the job file's flat layout). */
static double num(const char *from, const char *key, int required) {
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\":", key);
    const char *p = strstr(from, pat);
    if (!p) {
        if (required) {
            fprintf(stderr, "job file: no \"%s\"\n", key);
            exit(2);
        }
        return 0.0;
    }
    p += strlen(pat);
    while (*p == ' ') p++;
    if (strncmp(p, "null", 4) == 0) return NAN;
    return strtod(p, NULL);
}

static void str(const char *from, const char *key, char *out, size_t n) {
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\":", key);
    const char *p = strstr(from, pat);
    if (!p) { fprintf(stderr, "job file: no \"%s\"\n", key); exit(2); }
    p = strchr(p + strlen(pat), '"') + 1;
    size_t k = 0;
    while (*p && *p != '"' && k + 1 < n) out[k++] = *p++;
    out[k] = 0;
}

/* Parameters. */
static double Ju, Jl, km, kt, u;
static double uts, udts, ub, udb;          /* upper: T = ts + dts sgn w + b|w| + db w */
static int stribeck;
static double lts, ltc, lws, ldelta, lb;   /* stribeck lower */
static double t1, t2, w1, w2;              /* exponential lower */

/* Friction magnitude of the lower disc at |w| = v > 0, and its derivative. */
static void lower_level(double v, double *T, double *dT) {
    if (stribeck) {
        double r = pow(v / lws, ldelta), e = exp(-r);
        *T = ltc + (lts - ltc) * e + lb * v;
        *dT = -(lts - ltc) * e * ldelta * r / v + lb;
    } else {
        double e1 = exp(-w1 * v), e2 = exp(-w2 * v);
        /* 1 - 2/(1+e^{wv}) = (1 - e^{-wv}) / (1 + e^{-wv}) */
        *T = lts + t1 * (1 - e1) / (1 + e1) + t2 * (1 - e2) / (1 + e2) + lb * v;
        *dT = t1 * 2 * w1 * e1 / ((1 + e1) * (1 + e1)) + t2 * 2 * w2 * e2 / ((1 + e2) * (1 + e2)) + lb;
    }
}

/* Friction magnitude of the upper disc at |w| = v > 0 slipping in direction s. */
static void upper_level(double v, int s, double *T, double *dT) {
    *T = uts + s * udts + (ub + s * udb) * v;
    *dT = ub + s * udb;
}

/* One disc's step: w' = w + (h/J)(F - T), T in F(w'). `disc` 0 = upper, 1 = lower. */
static double disc_step(int disc, double w, double F, double h, double J) {
    double p = J * w / h + F;              /* the impulse (per h) with w' = 0 */
    double Tp, Tm, d;
    if (disc == 0) { upper_level(0, 1, &Tp, &d); upper_level(0, -1, &Tm, &d); }
    else { lower_level(1e-300, &Tp, &d); Tm = Tp; }
    if (p <= Tp && p >= -Tm) return 0.0;   /* stick */
    int s = p > 0 ? 1 : -1;
    /* slip in direction s: g(v) = J v / h - (s p) + T(v) = 0 for v = |w'| > 0 */
    double lo = 0, hi = h * fabs(p) / J + 1e-300, v = fmin(fabs(w), hi);
    if (v <= 0) v = 0.5 * hi;
    for (int it = 0; it < 100; it++) {
        double T, dT;
        if (disc == 0) upper_level(v, s, &T, &dT); else lower_level(v, &T, &dT);
        double g = J * v / h - s * p + T;
        if (g > 0) hi = v; else lo = v;
        double dg = J / h + dT, vn = v - g / dg;
        if (!(vn > lo && vn < hi)) vn = 0.5 * (lo + hi);
        if (fabs(vn - v) <= 1e-15 * fmax(v, 1e-300) || hi - lo <= 1e-16 * hi) { v = vn; break; }
        v = vn;
    }
    return s * v;
}

static FILE *events;
static int stuck[2];
/* The events of one disc over a step that ends at t: it starts or stops sticking, or its
 * velocity changes sign without sticking. */
static void event(double t, int disc, double w0, double w1_) {
    const char *name = disc == 0 ? "upper" : "lower";
    int now = w1_ == 0;
    if (!stuck[disc] && now) fprintf(events, "%.17g,%s,stick_start\n", t, name);
    else if (stuck[disc] && !now) fprintf(events, "%.17g,%s,stick_end\n", t, name);
    else if (w0 * w1_ < 0) fprintf(events, "%.17g,%s,reversal\n", t, name);
    stuck[disc] = now;
}

int main(int argc, char **argv) {
    if (argc != 2) { fprintf(stderr, "usage: first_order JOB.json\n"); return 2; }
    FILE *f = fopen(argv[1], "rb");
    if (!f) { perror(argv[1]); return 2; }
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    job = calloc(n + 1, 1);
    if (fread(job, 1, n, f) != (size_t)n) { fprintf(stderr, "cannot read the job\n"); return 2; }
    fclose(f);

    const char *P = strstr(job, "\"params\"");
    const char *U = strstr(job, "\"upper\""), *L = strstr(job, "\"lower\"");
    if (!P || !U || !L) { fprintf(stderr, "job file: no params\n"); return 2; }
    Ju = num(P, "j_u", 1); Jl = num(P, "j_l", 1); km = num(P, "k_m", 1); kt = num(P, "k_theta", 1);
    uts = num(U, "t_s", 1); udts = num(U, "dt_s", 1); ub = num(U, "b", 1); udb = num(U, "db", 1);
    char fam[32];
    str(L, "family", fam, sizeof fam);
    stribeck = strcmp(fam, "stribeck") == 0;
    lts = num(L, "t_s", 1); lb = num(L, "b", 1);
    if (stribeck) { ltc = num(L, "t_c", 1); lws = num(L, "omega_s", 1); ldelta = num(L, "delta", 1); }
    else { t1 = num(L, "t_1", 1); t2 = num(L, "t_2", 1); w1 = num(L, "w_1", 1); w2 = num(L, "w_2", 1); }
    /* The job's own keys follow its params; search after the params object for them. */
    u = num(job, "u", 1);
    double t_end = num(job, "t_end", 1), dt = num(job, "dt", 1), h = num(job, "h", 0);
    if (!(h > 0)) h = 1e-4;
    const char *x0 = strstr(job, "\"x0\":");
    double x[3];
    if (!x0 || sscanf(strchr(x0, '[') + 1, "%lf , %lf , %lf", &x[0], &x[1], &x[2]) != 3) {
        fprintf(stderr, "job file: no x0\n");
        return 2;
    }
    char trace_path[4096], events_path[4096];
    str(job, "trace", trace_path, sizeof trace_path);
    str(job, "events", events_path, sizeof events_path);
    FILE *out = fopen(trace_path, "w");
    events = fopen(events_path, "w");
    if (!out || !events) { perror("output"); return 2; }
    fprintf(out, "t,alpha,omega_u,omega_l\n");
    fprintf(events, "t,disc,kind\n");

    long rows = lround(t_end / dt), k = 0;
    long steps = (long)ceil(t_end / h - 1e-9);
    double a = x[0], wu = x[1], wl = x[2], t = 0;
    fprintf(out, "%.17g,%.17g,%.17g,%.17g\n", 0.0, a, wu, wl);
    /* A disc at rest sticks if its static interval holds the applied torque. */
    {
        double Tp, Tm, d, Fu = km * u - kt * a, Fl = kt * a;
        upper_level(0, 1, &Tp, &d);
        upper_level(0, -1, &Tm, &d);
        stuck[0] = wu == 0 && Fu <= Tp && Fu >= -Tm && Tp + Tm > 0;
        lower_level(1e-300, &Tp, &d);
        stuck[1] = wl == 0 && fabs(Fl) <= Tp;
    }
    k = 1;
    for (long i = 1; i <= steps; i++) {
        double t1_ = i == steps ? t_end : i * h, hh = t1_ - t;
        double wu1 = disc_step(0, wu, km * u - kt * a, hh, Ju);
        double wl1 = disc_step(1, wl, kt * a, hh, Jl);
        double a1 = a + hh * (wu1 - wl1);
        event(t1_, 0, wu, wu1);
        event(t1_, 1, wl, wl1);
        /* grid rows in (t, t1_]: linear between the step's ends */
        while (k <= rows) {
            double tg = k == rows ? t_end : k * dt;
            if (tg > t1_ + 1e-12) break;
            double s = hh > 0 ? (tg - t) / hh : 1;
            if (s > 1) s = 1;
            fprintf(out, "%.17g,%.17g,%.17g,%.17g\n", tg, a + s * (a1 - a), wu + s * (wu1 - wu),
                    wl + s * (wl1 - wl));
            k++;
        }
        a = a1; wu = wu1; wl = wl1; t = t1_;
    }
    fclose(out);
    fclose(events);
    return 0;
}
