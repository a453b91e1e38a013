/*
 * bt4.c - C reference of the explicit BT4 + J2 step of structure-solver (a measurement tool:
 * `structure-solver bench` compiles nothing from it; build.rs builds it as a separate program
 * and the bench runs it in the same run, on one thread, beside the Rust loop).
 *
 * Per step, the same work as src/bench.rs (Bt4Explicit::step) and src/elements/bt4/:
 *   du = dt v, x += du; for each block of 8 elements: gather, corotated frames at the mid and
 *   end geometry, strain increments with the warping correction, per thickness point the
 *   elastic trial and the Simo-Taylor plane-stress return (Newton from the radial-return
 *   estimate, each lane frozen when |f| <= tol kappa^2, the safeguarded Newton-bisection
 *   fallback for lanes still outside after `newton` updates), resultants, Flanagan-Belytschko
 *   hourglass forces, nodal forces in the global frame, scatter in element order; commit;
 *   v -= dt f / m; dt = 0.9 min over elements of the element stable step.
 * The operations are those of the Rust code in the same order (gcc -O3 -march=native
 * -ffp-contract=off -fno-math-errno: no FMA contraction, IEEE sqrt and division), so the end
 * positions agree with the Rust run to round-off.
 *
 * Usage: bt4 INPUT OUTPUT. INPUT as written by src/bench.rs (c_reference_input); OUTPUT gets
 * the end positions (3 f64 per node). Prints {"seconds": ..., "cpu_seconds": ..., "steps": ...}
 * (the timed steps: wall-clock and processor time).
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define L 8
#define NS 5
#define NH 5
#define MAXP 16
#define FALLBACK_UPDATES 120
#define SQRT_2_3 0.816496580927726

typedef struct {
    double c00, c01, c22, gk, e, c1, c2, h, sy, hg, tol, wave, s12, rho;
    int np, newton, scaled;
    double pts[MAXP], wts[MAXP];
} Params;

static void die(const char *m) {
    fprintf(stderr, "bt4: %s\n", m);
    exit(1);
}

static double clock_s(clockid_t c) {
    struct timespec t;
    clock_gettime(c, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* Frame of one element (scalar): e[3][3], local x, y, z, b1, b2, area. */
typedef struct {
    double e[3][3], x[4], y[4], z[4], b1[4], b2[4], area;
} Frame;

static inline void frame(const double xe[4][3], Frame *f) {
    double a[3], b[3], e3[3], x21[3], e1[3], e2[3], c[3];
    for (int k = 0; k < 3; k++) {
        a[k] = xe[2][k] - xe[0][k];
        b[k] = xe[3][k] - xe[1][k];
    }
    double n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    double inv = 1.0 / sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int k = 0; k < 3; k++) e3[k] = n[k] * inv;
    for (int k = 0; k < 3; k++) x21[k] = xe[1][k] - xe[0][k];
    double d = x21[0] * e3[0] + x21[1] * e3[1] + x21[2] * e3[2];
    double p[3] = {x21[0] - d * e3[0], x21[1] - d * e3[1], x21[2] - d * e3[2]};
    inv = 1.0 / sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int k = 0; k < 3; k++) e1[k] = p[k] * inv;
    e2[0] = e3[1] * e1[2] - e3[2] * e1[1];
    e2[1] = e3[2] * e1[0] - e3[0] * e1[2];
    e2[2] = e3[0] * e1[1] - e3[1] * e1[0];
    for (int k = 0; k < 3; k++) c[k] = (xe[0][k] + xe[1][k] + xe[2][k] + xe[3][k]) * 0.25;
    for (int i = 0; i < 4; i++) {
        double r[3] = {xe[i][0] - c[0], xe[i][1] - c[1], xe[i][2] - c[2]};
        f->x[i] = r[0] * e1[0] + r[1] * e1[1] + r[2] * e1[2];
        f->y[i] = r[0] * e2[0] + r[1] * e2[1] + r[2] * e2[2];
        f->z[i] = r[0] * e3[0] + r[1] * e3[1] + r[2] * e3[2];
    }
    double two_a = (f->x[2] - f->x[0]) * (f->y[3] - f->y[1]) - (f->x[3] - f->x[1]) * (f->y[2] - f->y[0]);
    inv = 1.0 / two_a;
    f->b1[0] = (f->y[1] - f->y[3]) * inv;
    f->b1[1] = (f->y[2] - f->y[0]) * inv;
    f->b1[2] = (f->y[3] - f->y[1]) * inv;
    f->b1[3] = (f->y[0] - f->y[2]) * inv;
    f->b2[0] = (f->x[3] - f->x[1]) * inv;
    f->b2[1] = (f->x[0] - f->x[2]) * inv;
    f->b2[2] = (f->x[1] - f->x[3]) * inv;
    f->b2[3] = (f->x[2] - f->x[0]) * inv;
    for (int k = 0; k < 3; k++) {
        f->e[0][k] = e1[k];
        f->e[1][k] = e2[k];
        f->e[2][k] = e3[k];
    }
    f->area = two_a * 0.5;
}

static inline double dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* f, f', kappa of the plane-stress return at dg. */
static inline void ps_eval(const Params *P, double a1, double a2, double kn, double dg, double *f,
                           double *df, double *kappa) {
    double i1 = 1.0 / (1.0 + P->c1 * dg), i2 = 1.0 / (1.0 + P->c2 * dg);
    double q1 = a1 * i1 * i1, q2 = a2 * i2 * i2;
    double xi2 = q1 + q2;
    double xi = sqrt(xi2);
    double dxi2 = -2.0 * (q1 * P->c1 * i1 + q2 * P->c2 * i2);
    double k = kn + P->h * SQRT_2_3 * dg * xi;
    *f = 0.5 * xi2 - (1.0 / 3.0) * k * k;
    double dk = P->h * SQRT_2_3 * (xi + dg * dxi2 * 0.5 / xi);
    *df = 0.5 * dxi2 - (2.0 / 3.0) * k * dk;
    *kappa = k;
}

static inline int ps_active(const Params *P, int yielding, double f, double kappa) {
    double excess = yielding ? fabs(f) - P->tol * kappa * kappa : -1.0;
    return excess > 0.0;
}

/* Plane-stress return of one point; sigma[3] and alpha updated in place. */
static inline void ps_return(const Params *P, double *s0, double *s1, double *s2, double *alpha) {
    double mean = *s0 + *s1;
    double half_diff = (*s1 - *s0) * 0.5;
    double a1 = mean * mean * (1.0 / 6.0);
    double a2 = half_diff * half_diff * 2.0 + *s2 * *s2 * 2.0;
    double kn = P->sy + P->h * *alpha;
    double f_trial = 0.5 * (a1 + a2) - (1.0 / 3.0) * kn * kn;
    double dg = 0.0;
    if (f_trial > 0.0) {
        double xi_tr = sqrt(a1 + a2);
        double k_n = SQRT_2_3 * kn;
        dg = (xi_tr - k_n) / ((2.0 / 3.0) * P->h * xi_tr + P->c2 * k_n);
        double f, df, kappa;
        ps_eval(P, a1, a2, kn, dg, &f, &df, &kappa);
        for (int i = 0; i < P->newton; i++) {
            if (!ps_active(P, 1, f, kappa)) break;
            dg = dg - f / df;
            ps_eval(P, a1, a2, kn, dg, &f, &df, &kappa);
        }
        if (P->tol > 0.0 && ps_active(P, 1, f, kappa)) {
            double lo = 0.0, hi = (xi_tr / k_n - 1.0) / fmin(P->c1, P->c2);
            for (int i = 0; i < FALLBACK_UPDATES; i++) {
                if (!ps_active(P, 1, f, kappa)) break;
                int above = f > 0.0;
                lo = above ? dg : lo;
                hi = above ? hi : dg;
                double mid = (lo + hi) * 0.5;
                double nw = dg - f / df;
                double inside = nw > lo ? nw : mid;
                dg = hi > inside ? inside : mid;
                ps_eval(P, a1, a2, kn, dg, &f, &df, &kappa);
            }
        }
    }
    double m1 = mean / (1.0 + P->c1 * dg);
    double m2 = half_diff / (1.0 + P->c2 * dg);
    double sxy = *s2 / (1.0 + P->c2 * dg);
    *s0 = m1 * 0.5 - m2;
    *s1 = m1 * 0.5 + m2;
    *s2 = sxy;
    double xi = sqrt(m1 * m1 * (1.0 / 6.0) + m2 * m2 * 2.0 + sxy * sxy * 2.0);
    *alpha = *alpha + SQRT_2_3 * dg * xi;
}

/* One element (lane l of a block): state in block layout, forces fe[4][6]. */
static inline void element(const Params *P, int l, const double xe[4][3], const double xm[4][3],
                           const double du[4][6], double h, const double *so, const double *ao,
                           const double *ho, double *sn, double *an, double *hn, double fe[4][6]) {
    Frame fm, fr;
    frame(xm, &fm);
    double ul[4][3], rl[4][3];
    for (int i = 0; i < 4; i++) {
        double th[3] = {du[i][3], du[i][4], du[i][5]};
        double cay = 1.0 + dot3(th, th) * (1.0 / 12.0);
        for (int a = 0; a < 3; a++) {
            ul[i][a] = dot3(fm.e[a], du[i]);
            rl[i][a] = dot3(fm.e[a], th) * cay;
        }
    }
    double em[3] = {0, 0, 0}, kap[3] = {0, 0, 0}, gs[2] = {0, 0}, rxm = 0, rym = 0;
    for (int i = 0; i < 4; i++) {
        double upx = ul[i][0] - fm.z[i] * rl[i][1];
        double upy = ul[i][1] + fm.z[i] * rl[i][0];
        em[0] += fm.b1[i] * upx;
        em[1] += fm.b2[i] * upy;
        em[2] += fm.b2[i] * upx + fm.b1[i] * upy;
        kap[0] += fm.b1[i] * rl[i][1];
        kap[1] -= fm.b2[i] * rl[i][0];
        kap[2] += fm.b2[i] * rl[i][1] - fm.b1[i] * rl[i][0];
        gs[0] += fm.b1[i] * ul[i][2];
        gs[1] += fm.b2[i] * ul[i][2];
        rxm += rl[i][0] * 0.25;
        rym += rl[i][1] * 0.25;
    }
    double gxz = gs[0] + rym, gyz = gs[1] - rxm;
    double half_h = h * 0.5;
    double n[3] = {0, 0, 0}, m[3] = {0, 0, 0}, q[2] = {0, 0};
    for (int p = 0; p < P->np; p++) {
        double z = half_h * P->pts[p];
        double de[3] = {em[0] + z * kap[0], em[1] + z * kap[1], em[2] + z * kap[2]};
        int s = p * NS;
        double t0 = so[(s + 0) * L + l] + P->c00 * de[0] + P->c01 * de[1];
        double t1 = so[(s + 1) * L + l] + P->c01 * de[0] + P->c00 * de[1];
        double t2 = so[(s + 2) * L + l] + P->c22 * de[2];
        double alpha = ao[p * L + l];
        ps_return(P, &t0, &t1, &t2, &alpha);
        double syz = so[(s + 3) * L + l] + P->gk * gyz;
        double szx = so[(s + 4) * L + l] + P->gk * gxz;
        sn[(s + 0) * L + l] = t0;
        sn[(s + 1) * L + l] = t1;
        sn[(s + 2) * L + l] = t2;
        sn[(s + 3) * L + l] = syz;
        sn[(s + 4) * L + l] = szx;
        an[p * L + l] = alpha;
        double wn = half_h * P->wts[p];
        double wm = wn * z;
        double sg[3] = {t0, t1, t2};
        for (int k = 0; k < 3; k++) {
            n[k] += wn * sg[k];
            m[k] += wm * sg[k];
        }
        q[0] += wn * szx;
        q[1] += wn * syz;
    }
    frame(xe, &fr);
    double a = fr.area;
    double fl[4][6];
    for (int i = 0; i < 4; i++) {
        double fx = a * (fr.b1[i] * n[0] + fr.b2[i] * n[2]);
        double fy = a * (fr.b2[i] * n[1] + fr.b1[i] * n[2]);
        fl[i][0] = fx;
        fl[i][1] = fy;
        fl[i][2] = a * (fr.b1[i] * q[0] + fr.b2[i] * q[1]);
        fl[i][3] = -a * (fr.b2[i] * m[1] + fr.b1[i] * m[2]) - a * 0.25 * q[1] + fr.z[i] * fy;
        fl[i][4] = a * (fr.b1[i] * m[0] + fr.b2[i] * m[2]) + a * 0.25 * q[0] - fr.z[i] * fx;
        fl[i][5] = 0.0;
    }
    const double hv[4] = {1.0, -1.0, 1.0, -1.0};
    double hx = hv[0] * fr.x[0] + hv[1] * fr.x[1] + hv[2] * fr.x[2] + hv[3] * fr.x[3];
    double hy = hv[0] * fr.y[0] + hv[1] * fr.y[1] + hv[2] * fr.y[2] + hv[3] * fr.y[3];
    double g[4], bb = 0.0;
    for (int i = 0; i < 4; i++) g[i] = 0.25 * (hv[i] - hx * fr.b1[i] - hy * fr.b2[i]);
    for (int i = 0; i < 4; i++) bb += fr.b1[i] * fr.b1[i] + fr.b2[i] * fr.b2[i];
    double r = P->hg, e = P->e, h3 = h * h * h;
    double k_mem = r * e * h * a * bb * (1.0 / 8.0);
    double k_w = r * P->gk * h3 * bb * (1.0 / 12.0);
    double k_rot = r * e * h3 * a * bb * (1.0 / 192.0);
    double qd[NH] = {0, 0, 0, 0, 0};
    for (int i = 0; i < 4; i++) {
        double ue0 = dot3(fr.e[0], du[i]), ue1 = dot3(fr.e[1], du[i]), ue2 = dot3(fr.e[2], du[i]);
        qd[0] += g[i] * ue0;
        qd[1] += g[i] * ue1;
        qd[2] += g[i] * ue2;
        qd[3] += g[i] * dot3(fr.e[0], du[i] + 3);
        qd[4] += g[i] * dot3(fr.e[1], du[i] + 3);
    }
    double kh[NH] = {k_mem, k_mem, k_w, k_rot, k_rot}, qh[NH];
    for (int k = 0; k < NH; k++) {
        qh[k] = ho[k * L + l] + kh[k] * qd[k];
        hn[k * L + l] = qh[k];
    }
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < NH; k++) fl[i][k] += g[i] * qh[k];
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++) {
            fe[i][k] = fr.e[0][k] * fl[i][0] + fr.e[1][k] * fl[i][1] + fr.e[2][k] * fl[i][2];
            fe[i][3 + k] = fr.e[0][k] * fl[i][3] + fr.e[1][k] * fl[i][4] + fr.e[2][k] * fl[i][5];
        }
}

static double element_dt(const Params *P, const double xe[4][3], double h) {
    Frame f;
    frame(xe, &f);
    double a = f.area;
#define D(i, j) sqrt(pow(xe[i][0] - xe[j][0], 2) + pow(xe[i][1] - xe[j][1], 2) + pow(xe[i][2] - xe[j][2], 2))
    double d02 = D(0, 2), d13 = D(1, 3);
#undef D
    double l = a / (d02 > d13 ? d02 : d13);
    double a_rot = P->scaled ? a : 0.0;
    double w2 = (P->s12 + 4.0 * P->e * h * h / a) / (P->rho * (h * h + a_rot));
    double t1 = l / P->wave, t2 = 2.0 / sqrt(w2);
    return t1 < t2 ? t1 : t2;
}

static void *read_all(FILE *f, size_t n) {
    void *p = aligned_alloc(64, (n + 63) / 64 * 64 + 64);
    if (!p || fread(p, 1, n, f) != n) die("short input");
    return p;
}

int main(int argc, char **argv) {
    if (argc != 3) die("usage: bt4 INPUT OUTPUT");
    FILE *in = fopen(argv[1], "rb");
    if (!in) die("cannot open the input");
    uint64_t hd[8];
    if (fread(hd, 8, 8, in) != 8 || hd[0] != 0x3146455243344254ULL) die("not a BT4 bench input");
    size_t nn = hd[1], ne = hd[2], np = hd[3];
    Params P;
    P.newton = (int)hd[4];
    size_t warmup = hd[5], steps = hd[6];
    P.scaled = (int)hd[7];
    if (np > MAXP) die("too many thickness points");
    P.np = (int)np;
    double c[15];
    if (fread(c, 8, 15, in) != 15) die("short input");
    P.c00 = c[0]; P.c01 = c[1]; P.c22 = c[2]; P.gk = c[3]; P.e = c[4]; P.c1 = c[5]; P.c2 = c[6];
    P.h = c[7]; P.sy = c[8]; P.hg = c[9]; P.tol = c[10]; P.wave = c[11]; P.s12 = c[12];
    P.rho = c[13];
    double dt = c[14];
    if (fread(P.pts, 8, np, in) != np || fread(P.wts, 8, np, in) != np) die("short input");
    double *x = read_all(in, nn * 3 * 8);
    double *v = read_all(in, nn * 6 * 8);
    double *im = read_all(in, nn * 6 * 8);
    double *th = read_all(in, ne * 8);
    uint32_t *conn = read_all(in, ne * 4 * 4);
    fclose(in);
    size_t nb = (ne + L - 1) / L;
    size_t ss = nb * np * NS * L, sa = nb * np * L, sh = nb * NH * L;
    double *so = calloc(ss, 8), *sn = calloc(ss, 8), *ao = calloc(sa, 8), *an = calloc(sa, 8);
    double *ho = calloc(sh, 8), *hn = calloc(sh, 8);
    double *du = calloc(nn * 6, 8), *f = calloc(nn * 6, 8);
    if (!so || !sn || !ao || !an || !ho || !hn || !du || !f) die("out of memory");
    double t0 = 0.0, c0 = 0.0;
    for (size_t step = 0; step < warmup + steps; step++) {
        if (step == warmup) {
            t0 = clock_s(CLOCK_MONOTONIC);
            c0 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
        }
        for (size_t i = 0; i < nn; i++) {
            for (int k = 0; k < 6; k++) du[6 * i + k] = dt * v[6 * i + k];
            for (int k = 0; k < 3; k++) x[3 * i + k] += du[6 * i + k];
        }
        memset(f, 0, nn * 6 * 8);
        for (size_t b = 0; b < nb; b++) {
            size_t e0 = b * L, valid = ne - e0 < L ? ne - e0 : L;
            double fe[L][4][6];
            for (int l = 0; l < L; l++) {
                size_t el = e0 + ((size_t)l < valid ? (size_t)l : valid - 1);
                double xe[4][3], xm[4][3], dv[4][6];
                for (int i = 0; i < 4; i++) {
                    size_t n = conn[4 * el + i];
                    for (int k = 0; k < 3; k++) {
                        xe[i][k] = x[3 * n + k];
                        xm[i][k] = x[3 * n + k] - 0.5 * du[6 * n + k];
                    }
                    for (int k = 0; k < 6; k++) dv[i][k] = du[6 * n + k];
                }
                element(&P, l, xe, xm, dv, th[el], so + b * np * NS * L, ao + b * np * L,
                        ho + b * NH * L, sn + b * np * NS * L, an + b * np * L, hn + b * NH * L,
                        fe[l]);
            }
            for (size_t l = 0; l < valid; l++)
                for (int i = 0; i < 4; i++) {
                    size_t n = conn[4 * (e0 + l) + i];
                    for (int k = 0; k < 6; k++) f[6 * n + k] += fe[l][i][k];
                }
        }
        double *t;
        t = so; so = sn; sn = t;
        t = ao; ao = an; an = t;
        t = ho; ho = hn; hn = t;
        for (size_t i = 0; i < nn * 6; i++) v[i] -= dt * f[i] * im[i];
        double m = INFINITY;
        for (size_t e = 0; e < ne; e++) {
            double xe[4][3];
            for (int i = 0; i < 4; i++)
                for (int k = 0; k < 3; k++) xe[i][k] = x[3 * conn[4 * e + i] + k];
            double d = element_dt(&P, xe, th[e]);
            m = d < m ? d : m;
        }
        dt = 0.9 * m;
    }
    double secs = clock_s(CLOCK_MONOTONIC) - t0;
    double cpu = clock_s(CLOCK_PROCESS_CPUTIME_ID) - c0;
    FILE *out = fopen(argv[2], "wb");
    if (!out || fwrite(x, 8, nn * 3, out) != nn * 3) die("cannot write the output");
    fclose(out);
    printf("{\"seconds\": %.9g, \"cpu_seconds\": %.9g, \"steps\": %zu}\n", secs, cpu, steps);
    return 0;
}
