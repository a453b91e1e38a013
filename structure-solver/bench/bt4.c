/*
 * bt4.c - C reference of the explicit BT4 + J2 step of structure-solver (a measurement tool:
 * `structure-solver bench` compiles nothing from it; build.rs builds it as a separate program
 * and the bench runs it in the same run, on one thread, beside the Rust loop).
 *
 * Per step, the same work as src/bench.rs (Bt4Explicit::step) and src/elements/bt4/, blocked as
 * the Rust kernel is: every temporary holds the 8 elements of a block lane-innermost, so gcc
 * vectorises each lane loop (check with -fopt-info-vec):
 *   du = dt v, x += du; for each block of 8 elements: gather, corotated frames at the mid and
 *   end geometry, strain increments with the warping correction, per thickness point the
 *   elastic trial and the Simo-Taylor plane-stress return (Newton from the radial-return
 *   estimate, each lane frozen when |f| <= tol kappa^2, the safeguarded Newton-bisection
 *   fallback for lanes still outside after `newton` updates), resultants, Flanagan-Belytschko
 *   hourglass forces, nodal forces in the global frame, scatter in element order; commit;
 *   v -= dt f / m; dt = 0.9 min over elements of the element stable step (also by blocks).
 * Lanes that have converged are frozen (selects, not branches), so each lane follows the path
 * of the scalar return exactly.
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

#define LANES for (int l = 0; l < L; l++)

/* Frames of the L elements of a block, lane-innermost: e[a][k][l], local x, y, z, b1, b2, area. */
typedef struct {
    double e[3][3][L], x[4][L], y[4][L], z[4][L], b1[4][L], b2[4][L], area[L];
} Frame;

static inline void frame(const double xe[4][3][L], Frame *restrict f) {
    LANES {
        double p4[4][3], a[3], b[3], e3[3], x21[3], e1[3], e2[3], c[3];
        for (int i = 0; i < 4; i++)
            for (int k = 0; k < 3; k++) p4[i][k] = xe[i][k][l];
        for (int k = 0; k < 3; k++) {
            a[k] = p4[2][k] - p4[0][k];
            b[k] = p4[3][k] - p4[1][k];
        }
        double n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                       a[0] * b[1] - a[1] * b[0]};
        double inv = 1.0 / sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; k++) e3[k] = n[k] * inv;
        for (int k = 0; k < 3; k++) x21[k] = p4[1][k] - p4[0][k];
        double d = x21[0] * e3[0] + x21[1] * e3[1] + x21[2] * e3[2];
        double p[3] = {x21[0] - d * e3[0], x21[1] - d * e3[1], x21[2] - d * e3[2]};
        inv = 1.0 / sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        for (int k = 0; k < 3; k++) e1[k] = p[k] * inv;
        e2[0] = e3[1] * e1[2] - e3[2] * e1[1];
        e2[1] = e3[2] * e1[0] - e3[0] * e1[2];
        e2[2] = e3[0] * e1[1] - e3[1] * e1[0];
        for (int k = 0; k < 3; k++)
            c[k] = (p4[0][k] + p4[1][k] + p4[2][k] + p4[3][k]) * 0.25;
        double x[4], y[4];
        for (int i = 0; i < 4; i++) {
            double r[3] = {p4[i][0] - c[0], p4[i][1] - c[1], p4[i][2] - c[2]};
            x[i] = r[0] * e1[0] + r[1] * e1[1] + r[2] * e1[2];
            y[i] = r[0] * e2[0] + r[1] * e2[1] + r[2] * e2[2];
            f->x[i][l] = x[i];
            f->y[i][l] = y[i];
            f->z[i][l] = r[0] * e3[0] + r[1] * e3[1] + r[2] * e3[2];
        }
        double two_a = (x[2] - x[0]) * (y[3] - y[1]) - (x[3] - x[1]) * (y[2] - y[0]);
        inv = 1.0 / two_a;
        f->b1[0][l] = (y[1] - y[3]) * inv;
        f->b1[1][l] = (y[2] - y[0]) * inv;
        f->b1[2][l] = (y[3] - y[1]) * inv;
        f->b1[3][l] = (y[0] - y[2]) * inv;
        f->b2[0][l] = (x[3] - x[1]) * inv;
        f->b2[1][l] = (x[0] - x[2]) * inv;
        f->b2[2][l] = (x[1] - x[3]) * inv;
        f->b2[3][l] = (x[2] - x[0]) * inv;
        for (int k = 0; k < 3; k++) {
            f->e[0][k][l] = e1[k];
            f->e[1][k][l] = e2[k];
            f->e[2][k][l] = e3[k];
        }
        f->area[l] = two_a * 0.5;
    }
}

/* f, f', kappa of the plane-stress return at dg, every lane. */
static inline void ps_eval(const Params *P, const double *a1, const double *a2, const double *kn,
                           const double *dg, double *f, double *df, double *kappa) {
    LANES {
        double i1 = 1.0 / (1.0 + P->c1 * dg[l]), i2 = 1.0 / (1.0 + P->c2 * dg[l]);
        double q1 = a1[l] * i1 * i1, q2 = a2[l] * i2 * i2;
        double xi2 = q1 + q2;
        double xi = sqrt(xi2);
        double dxi2 = -2.0 * (q1 * P->c1 * i1 + q2 * P->c2 * i2);
        double k = kn[l] + P->h * SQRT_2_3 * dg[l] * xi;
        f[l] = 0.5 * xi2 - (1.0 / 3.0) * k * k;
        double dk = P->h * SQRT_2_3 * (xi + dg[l] * dxi2 * 0.5 / xi);
        df[l] = 0.5 * dxi2 - (2.0 / 3.0) * k * dk;
        kappa[l] = k;
    }
}

/* Lanes still outside the yield surface; returns how many. */
static inline int ps_active(const Params *P, const int *yielding, const double *f,
                            const double *kappa, int *active) {
    int n = 0;
    LANES {
        double excess = yielding[l] ? fabs(f[l]) - P->tol * kappa[l] * kappa[l] : -1.0;
        active[l] = excess > 0.0;
        n += active[l];
    }
    return n;
}

/* Plane-stress return of one thickness point of every lane; sigma and alpha updated in place.
 * Lanes are frozen where converged, as the Rust lanes are, so each lane takes the scalar path. */
static inline void ps_return(const Params *P, double *s0, double *s1, double *s2, double *alpha) {
    double mean[L], half_diff[L], a1[L], a2[L], kn[L], dg[L], xi_tr[L], k_n[L];
    double f[L], df[L], kappa[L];
    int yielding[L], active[L];
    LANES {
        mean[l] = s0[l] + s1[l];
        half_diff[l] = (s1[l] - s0[l]) * 0.5;
        a1[l] = mean[l] * mean[l] * (1.0 / 6.0);
        a2[l] = half_diff[l] * half_diff[l] * 2.0 + s2[l] * s2[l] * 2.0;
        kn[l] = P->sy + P->h * alpha[l];
        double f_trial = 0.5 * (a1[l] + a2[l]) - (1.0 / 3.0) * kn[l] * kn[l];
        yielding[l] = f_trial > 0.0;
        xi_tr[l] = sqrt(a1[l] + a2[l]);
        k_n[l] = SQRT_2_3 * kn[l];
        double est = (xi_tr[l] - k_n[l]) / ((2.0 / 3.0) * P->h * xi_tr[l] + P->c2 * k_n[l]);
        dg[l] = yielding[l] ? est : 0.0;
    }
    int any = 0;
    LANES any |= yielding[l];
    if (any) {
        ps_eval(P, a1, a2, kn, dg, f, df, kappa);
        for (int i = 0; i < P->newton; i++) {
            if (!ps_active(P, yielding, f, kappa, active)) break;
            LANES dg[l] = active[l] ? dg[l] - f[l] / df[l] : dg[l];
            ps_eval(P, a1, a2, kn, dg, f, df, kappa);
        }
        if (P->tol > 0.0 && ps_active(P, yielding, f, kappa, active)) {
            double lo[L], hi[L];
            LANES {
                lo[l] = 0.0;
                hi[l] = (xi_tr[l] / k_n[l] - 1.0) / fmin(P->c1, P->c2);
            }
            for (int i = 0; i < FALLBACK_UPDATES; i++) {
                if (!ps_active(P, yielding, f, kappa, active)) break;
                LANES {
                    int above = f[l] > 0.0;
                    double lo_n = above ? dg[l] : lo[l];
                    double hi_n = above ? hi[l] : dg[l];
                    double mid = (lo_n + hi_n) * 0.5;
                    double nw = dg[l] - f[l] / df[l];
                    double inside = nw > lo_n ? nw : mid;
                    double dg_n = hi_n > inside ? inside : mid;
                    lo[l] = active[l] ? lo_n : lo[l];
                    hi[l] = active[l] ? hi_n : hi[l];
                    dg[l] = active[l] ? dg_n : dg[l];
                }
                ps_eval(P, a1, a2, kn, dg, f, df, kappa);
            }
        }
    }
    LANES {
        double m1 = mean[l] / (1.0 + P->c1 * dg[l]);
        double m2 = half_diff[l] / (1.0 + P->c2 * dg[l]);
        double sxy = s2[l] / (1.0 + P->c2 * dg[l]);
        s0[l] = m1 * 0.5 - m2;
        s1[l] = m1 * 0.5 + m2;
        s2[l] = sxy;
        double xi = sqrt(m1 * m1 * (1.0 / 6.0) + m2 * m2 * 2.0 + sxy * sxy * 2.0);
        alpha[l] = alpha[l] + SQRT_2_3 * dg[l] * xi;
    }
}

/* The L elements of one block: geometry lane-innermost, state in block layout, forces
 * fe[4][6][L]. */
static inline void element(const Params *P, const double xe[4][3][L], const double xm[4][3][L],
                           const double du[4][6][L], const double *h, const double *so,
                           const double *ao, const double *ho, double *sn, double *an, double *hn,
                           double fe[4][6][L]) {
    Frame fm, fr;
    frame(xm, &fm);
    double em[3][L], kap[3][L], gxz[L], gyz[L];
    LANES {
        double ul[4][3], rl[4][3];
        for (int i = 0; i < 4; i++) {
            double th[3] = {du[i][3][l], du[i][4][l], du[i][5][l]};
            double cay = 1.0 + (th[0] * th[0] + th[1] * th[1] + th[2] * th[2]) * (1.0 / 12.0);
            for (int a = 0; a < 3; a++) {
                const double *ea[3] = {&fm.e[a][0][l], &fm.e[a][1][l], &fm.e[a][2][l]};
                ul[i][a] = *ea[0] * du[i][0][l] + *ea[1] * du[i][1][l] + *ea[2] * du[i][2][l];
                rl[i][a] = (*ea[0] * th[0] + *ea[1] * th[1] + *ea[2] * th[2]) * cay;
            }
        }
        double e0 = 0, e1 = 0, e2 = 0, k0 = 0, k1 = 0, k2 = 0, g0 = 0, g1 = 0, rxm = 0, rym = 0;
        for (int i = 0; i < 4; i++) {
            double b1 = fm.b1[i][l], b2 = fm.b2[i][l], z = fm.z[i][l];
            double upx = ul[i][0] - z * rl[i][1];
            double upy = ul[i][1] + z * rl[i][0];
            e0 += b1 * upx;
            e1 += b2 * upy;
            e2 += b2 * upx + b1 * upy;
            k0 += b1 * rl[i][1];
            k1 -= b2 * rl[i][0];
            k2 += b2 * rl[i][1] - b1 * rl[i][0];
            g0 += b1 * ul[i][2];
            g1 += b2 * ul[i][2];
            rxm += rl[i][0] * 0.25;
            rym += rl[i][1] * 0.25;
        }
        em[0][l] = e0;
        em[1][l] = e1;
        em[2][l] = e2;
        kap[0][l] = k0;
        kap[1][l] = k1;
        kap[2][l] = k2;
        gxz[l] = g0 + rym;
        gyz[l] = g1 - rxm;
    }
    double n[3][L] = {{0}}, m[3][L] = {{0}}, q[2][L] = {{0}};
    for (int p = 0; p < P->np; p++) {
        int s = p * NS;
        double t0[L], t1[L], t2[L], z[L];
        LANES {
            z[l] = h[l] * 0.5 * P->pts[p];
            double de0 = em[0][l] + z[l] * kap[0][l];
            double de1 = em[1][l] + z[l] * kap[1][l];
            double de2 = em[2][l] + z[l] * kap[2][l];
            t0[l] = so[(s + 0) * L + l] + P->c00 * de0 + P->c01 * de1;
            t1[l] = so[(s + 1) * L + l] + P->c01 * de0 + P->c00 * de1;
            t2[l] = so[(s + 2) * L + l] + P->c22 * de2;
            an[p * L + l] = ao[p * L + l];
        }
        ps_return(P, t0, t1, t2, an + p * L);
        LANES {
            double syz = so[(s + 3) * L + l] + P->gk * gyz[l];
            double szx = so[(s + 4) * L + l] + P->gk * gxz[l];
            sn[(s + 0) * L + l] = t0[l];
            sn[(s + 1) * L + l] = t1[l];
            sn[(s + 2) * L + l] = t2[l];
            sn[(s + 3) * L + l] = syz;
            sn[(s + 4) * L + l] = szx;
            double wn = h[l] * 0.5 * P->wts[p];
            double wm = wn * z[l];
            n[0][l] += wn * t0[l];
            n[1][l] += wn * t1[l];
            n[2][l] += wn * t2[l];
            m[0][l] += wm * t0[l];
            m[1][l] += wm * t1[l];
            m[2][l] += wm * t2[l];
            q[0][l] += wn * szx;
            q[1][l] += wn * syz;
        }
    }
    frame(xe, &fr);
    LANES {
        double a = fr.area[l];
        double fl[4][6];
        for (int i = 0; i < 4; i++) {
            double b1 = fr.b1[i][l], b2 = fr.b2[i][l];
            double fx = a * (b1 * n[0][l] + b2 * n[2][l]);
            double fy = a * (b2 * n[1][l] + b1 * n[2][l]);
            fl[i][0] = fx;
            fl[i][1] = fy;
            fl[i][2] = a * (b1 * q[0][l] + b2 * q[1][l]);
            fl[i][3] = -a * (b2 * m[1][l] + b1 * m[2][l]) - a * 0.25 * q[1][l] + fr.z[i][l] * fy;
            fl[i][4] = a * (b1 * m[0][l] + b2 * m[2][l]) + a * 0.25 * q[0][l] - fr.z[i][l] * fx;
            fl[i][5] = 0.0;
        }
        const double hv[4] = {1.0, -1.0, 1.0, -1.0};
        double hx = hv[0] * fr.x[0][l] + hv[1] * fr.x[1][l] + hv[2] * fr.x[2][l] + hv[3] * fr.x[3][l];
        double hy = hv[0] * fr.y[0][l] + hv[1] * fr.y[1][l] + hv[2] * fr.y[2][l] + hv[3] * fr.y[3][l];
        double g[4], bb = 0.0;
        for (int i = 0; i < 4; i++) g[i] = 0.25 * (hv[i] - hx * fr.b1[i][l] - hy * fr.b2[i][l]);
        for (int i = 0; i < 4; i++) bb += fr.b1[i][l] * fr.b1[i][l] + fr.b2[i][l] * fr.b2[i][l];
        double r = P->hg, e = P->e, hl = h[l], h3 = hl * hl * hl;
        double k_mem = r * e * hl * a * bb * (1.0 / 8.0);
        double k_w = r * P->gk * h3 * bb * (1.0 / 12.0);
        double k_rot = r * e * h3 * a * bb * (1.0 / 192.0);
        double qd[NH] = {0, 0, 0, 0, 0};
        for (int i = 0; i < 4; i++) {
            double d[6];
            for (int k = 0; k < 6; k++) d[k] = du[i][k][l];
            for (int a3 = 0; a3 < 3; a3++) {
                double ue = fr.e[a3][0][l] * d[0] + fr.e[a3][1][l] * d[1] + fr.e[a3][2][l] * d[2];
                qd[a3] += g[i] * ue;
            }
            for (int a3 = 0; a3 < 2; a3++) {
                double ur = fr.e[a3][0][l] * d[3] + fr.e[a3][1][l] * d[4] + fr.e[a3][2][l] * d[5];
                qd[3 + a3] += g[i] * ur;
            }
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
                fe[i][k][l] = fr.e[0][k][l] * fl[i][0] + fr.e[1][k][l] * fl[i][1] +
                              fr.e[2][k][l] * fl[i][2];
                fe[i][3 + k][l] = fr.e[0][k][l] * fl[i][3] + fr.e[1][k][l] * fl[i][4] +
                                  fr.e[2][k][l] * fl[i][5];
            }
    }
}

/* Smallest stable step of the first `valid` elements of a block (the element bound of
 * time/critical.rs with the shape-scaled rotary inertia). */
static double block_dt(const Params *P, const double xe[4][3][L], const double *h, size_t valid) {
    Frame f;
    frame(xe, &f);
    double dt[L];
    LANES {
        double d[2];
        for (int j = 0; j < 2; j++) {
            double s = 0.0;
            for (int k = 0; k < 3; k++) s += pow(xe[j][k][l] - xe[j + 2][k][l], 2);
            d[j] = sqrt(s);
        }
        double area = f.area[l];
        double len = area / (d[0] > d[1] ? d[0] : d[1]);
        double a_rot = P->scaled ? area : 0.0;
        double w2 = (P->s12 + 4.0 * P->e * h[l] * h[l] / area) / (P->rho * (h[l] * h[l] + a_rot));
        double t1 = len / P->wave, t2 = 2.0 / sqrt(w2);
        dt[l] = t1 < t2 ? t1 : t2;
    }
    double m = INFINITY;
    for (size_t l = 0; l < valid; l++) m = dt[l] < m ? dt[l] : m;
    return m;
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
            double fe[4][6][L], xe[4][3][L], xm[4][3][L], dv[4][6][L], hb[L];
            for (int l = 0; l < L; l++) {
                size_t el = e0 + ((size_t)l < valid ? (size_t)l : valid - 1);
                hb[l] = th[el];
                for (int i = 0; i < 4; i++) {
                    size_t n = conn[4 * el + i];
                    for (int k = 0; k < 3; k++) {
                        xe[i][k][l] = x[3 * n + k];
                        xm[i][k][l] = x[3 * n + k] - 0.5 * du[6 * n + k];
                    }
                    for (int k = 0; k < 6; k++) dv[i][k][l] = du[6 * n + k];
                }
            }
            element(&P, xe, xm, dv, hb, so + b * np * NS * L, ao + b * np * L, ho + b * NH * L,
                    sn + b * np * NS * L, an + b * np * L, hn + b * NH * L, fe);
            for (size_t l = 0; l < valid; l++)
                for (int i = 0; i < 4; i++) {
                    size_t n = conn[4 * (e0 + l) + i];
                    for (int k = 0; k < 6; k++) f[6 * n + k] += fe[i][k][l];
                }
        }
        double *t;
        t = so; so = sn; sn = t;
        t = ao; ao = an; an = t;
        t = ho; ho = hn; hn = t;
        for (size_t i = 0; i < nn * 6; i++) v[i] -= dt * f[i] * im[i];
        double m = INFINITY;
        for (size_t b = 0; b < nb; b++) {
            size_t e0 = b * L, valid = ne - e0 < L ? ne - e0 : L;
            double xe[4][3][L], hb[L];
            for (int l = 0; l < L; l++) {
                size_t el = e0 + ((size_t)l < valid ? (size_t)l : valid - 1);
                hb[l] = th[el];
                for (int i = 0; i < 4; i++)
                    for (int k = 0; k < 3; k++) xe[i][k][l] = x[3 * conn[4 * el + i] + k];
            }
            double d = block_dt(&P, xe, hb, valid);
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
