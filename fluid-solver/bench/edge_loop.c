/*
 * edge_loop.c - C reference for the hot loop of fluid-solver (a measurement tool, not part of
 * the product; nothing links it).
 *
 * It does per edge the same work as the solver's edge flux loop
 * (fluid-solver/src/semidiscretization.rs, edge_loop_with) for a perfect gas with the van
 * Albada limiter and Roe's flux:
 *   - gather the primitive states [rho, u, v, w, p], their gradients and the coordinates of
 *     both end nodes;
 *   - MUSCL extrapolation to the edge midpoint, u_ij = u_i + L(2 grad u_i . d - D, D)/2,
 *     u_ji = u_j - L(2 grad u_j . d - D, D)/2, D = u_j - u_i, with the van Albada slope
 *     L(a, b) = ab(a + b)/(a^2 + b^2) if ab > 0 else 0; back to the nodal states if either
 *     extrapolated density or pressure is not positive;
 *   - Roe's flux with Harten's entropy fix (epsilon 0.1 on the acoustic waves), in the same
 *     operation order as src/flux/roe.rs and src/flux/mod.rs;
 *   - R_i += F, R_j -= F.
 * The edges are visited in ascending order on one thread, so the scatter is plain.
 *
 * Input: the raw file written by `fluid-solver bench --dump-edges FILE` (format in
 * fluid-solver/src/bench.rs), which also holds the solver's own edge residual: the program
 * checks that it computes the same residual (to round-off: the solver adds a node's edge
 * contributions in a slightly different order) and prints the time per edge.
 *
 * Build and run: fluid-solver/bench/run-c-reference.sh (gcc -O3 -march=native -fopenmp-simd
 * -ffp-contract=off -fno-math-errno: the same IEEE operations as the Rust code, which never
 * contracts to FMA and has no errno to set on sqrt; the `omp simd` loop of the ten limited
 * slopes runs in AVX-512 registers).
 *
 * Usage: edge_loop FILE [REPETITIONS]
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define ENTROPY_FIX 0.1

static double slope(double a, double b) {
    double ab = a * b;
    double r = ab * (a + b) / (a * a + b * b); /* computed always: no branch */
    return ab <= 0.0 ? 0.0 : r;
}

static double phi(double lambda, int acoustic, double delta) {
    double a = fabs(lambda);
    double d = ENTROPY_FIX * delta;
    return (acoustic && a < d) ? (lambda * lambda + d * d) / (2.0 * d) : a;
}

static void prim_to_cons(double gamma, const double *w, double *q) {
    double rho = w[0], u = w[1], v = w[2], wz = w[3], p = w[4];
    double e = p / ((gamma - 1.0) * rho);
    q[0] = rho;
    q[1] = rho * u;
    q[2] = rho * v;
    q[3] = rho * wz;
    q[4] = rho * e + 0.5 * rho * (u * u + v * v + wz * wz);
}

static void flux_of(const double *w, const double *q, const double *n, double *f) {
    double un = w[1] * n[0] + w[2] * n[1] + w[3] * n[2];
    double p = w[4];
    f[0] = q[0] * un;
    f[1] = q[1] * un + p * n[0];
    f[2] = q[2] * un + p * n[1];
    f[3] = q[3] * un + p * n[2];
    f[4] = (q[4] + p) * un;
}

static void roe(double gamma, const double *wl, const double *wr, const double *n, double *f) {
    double area = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    double inv_area = 1.0 / area;
    double nh[3] = {n[0] * inv_area, n[1] * inv_area, n[2] * inv_area};
    double ql[5], qr[5];
    prim_to_cons(gamma, wl, ql);
    prim_to_cons(gamma, wr, qr);
    /* Roe averages. */
    double sl = sqrt(wl[0]), sr = sqrt(wr[0]);
    double inv = 1.0 / (sl + sr);
    double al = sl * inv, ar = sr * inv;
    double u[3] = {al * wl[1] + ar * wr[1], al * wl[2] + ar * wr[2], al * wl[3] + ar * wr[3]};
    double hl = (ql[4] + wl[4]) / wl[0];
    double hr = (qr[4] + wr[4]) / wr[0];
    double h = al * hl + ar * hr;
    double c2 = (gamma - 1.0) * (h - 0.5 * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]));
    double rho = sl * sr;
    double c = sqrt(c2);
    double delta = fabs(u[0] * nh[0] + u[1] * nh[1] + u[2] * nh[2]) + c;
    /* |A| dQ. */
    double un = u[0] * nh[0] + u[1] * nh[1] + u[2] * nh[2];
    double dun = (wr[1] - wl[1]) * nh[0] + (wr[2] - wl[2]) * nh[1] + (wr[3] - wl[3]) * nh[2];
    double dp = wr[4] - wl[4];
    double inv_2c2 = 0.5 / (c * c);
    double a1 = (dp - rho * c * dun) * inv_2c2;
    double a5 = (dp + rho * c * dun) * inv_2c2;
    double phi_u = phi(un, 0, delta);
    double k1 = (phi(un - c, 1, delta) - phi_u) * a1;
    double k5 = (phi(un + c, 1, delta) - phi_u) * a5;
    double diss[5];
    for (int k = 0; k < 5; k++) diss[k] = phi_u * (qr[k] - ql[k]);
    diss[0] += k1 + k5;
    for (int d = 0; d < 3; d++) diss[1 + d] += k1 * (u[d] - c * nh[d]) + k5 * (u[d] + c * nh[d]);
    diss[4] += k1 * (h - un * c) + k5 * (h + un * c);
    double fl[5], fr[5];
    flux_of(wl, ql, nh, fl);
    flux_of(wr, qr, nh, fr);
    for (int k = 0; k < 5; k++) f[k] = 0.5 * area * (fl[k] + fr[k] - diss[k]);
}

static void edge_loop(size_t n_nodes, size_t n_edges, double gamma,
                      const uint32_t *restrict edges, const double *restrict normals,
                      const double *restrict coords, const double *restrict prim,
                      const double *restrict grad, double *restrict res) {
    memset(res, 0, n_nodes * 5 * sizeof(double));
    for (size_t e = 0; e < n_edges; e++) {
        size_t i = edges[2 * e], j = edges[2 * e + 1];
        const double *wi = prim + 5 * i, *wj = prim + 5 * j;
        const double *gi = grad + 15 * i, *gj = grad + 15 * j;
        double d[3] = {coords[3 * j] - coords[3 * i], coords[3 * j + 1] - coords[3 * i + 1],
                       coords[3 * j + 2] - coords[3 * i + 2]};
        /* The ten slopes (five variables, two ends) side by side so that they vectorise. */
        double a[10], b[10], s[10];
        for (int k = 0; k < 5; k++) {
            double gid = gi[3 * k] * d[0] + gi[3 * k + 1] * d[1] + gi[3 * k + 2] * d[2];
            double gjd = gj[3 * k] * d[0] + gj[3 * k + 1] * d[1] + gj[3 * k + 2] * d[2];
            double delta = wj[k] - wi[k];
            a[k] = 2.0 * gid - delta;
            a[5 + k] = 2.0 * gjd - delta;
            b[k] = b[5 + k] = delta;
        }
        _Pragma("omp simd") for (int m = 0; m < 10; m++) s[m] = slope(a[m], b[m]);
        double wl[5], wr[5];
        for (int k = 0; k < 5; k++) {
            wl[k] = wi[k] + 0.5 * s[k];
            wr[k] = wj[k] - 0.5 * s[5 + k];
        }
        if (!(wl[0] > 0.0 && wl[4] + 0.0 > 0.0 && wr[0] > 0.0 && wr[4] + 0.0 > 0.0)) {
            memcpy(wl, wi, sizeof wl);
            memcpy(wr, wj, sizeof wr);
        }
        double f[5];
        roe(gamma, wl, wr, normals + 3 * e, f);
        for (int k = 0; k < 5; k++) {
            res[5 * i + k] += f[k];
            res[5 * j + k] -= f[k];
        }
    }
}

static void *read_exact(FILE *fp, size_t bytes, const char *what) {
    void *p = malloc(bytes ? bytes : 1);
    if (!p || fread(p, 1, bytes, fp) != bytes) {
        fprintf(stderr, "edge_loop: cannot read %s (%zu bytes)\n", what, bytes);
        exit(1);
    }
    return p;
}

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s FILE [REPETITIONS]\n", argv[0]);
        return 2;
    }
    int reps = argc > 2 ? atoi(argv[2]) : 11;
    if (reps < 1) reps = 1;
    FILE *fp = fopen(argv[1], "rb");
    if (!fp) {
        perror(argv[1]);
        return 1;
    }
    char magic[8];
    uint64_t n, m;
    double gamma;
    if (fread(magic, 1, 8, fp) != 8 || memcmp(magic, "FIVEREDG", 8) != 0 ||
        fread(&n, 8, 1, fp) != 1 || fread(&m, 8, 1, fp) != 1 || fread(&gamma, 8, 1, fp) != 1) {
        fprintf(stderr, "edge_loop: %s is not a `fluid-solver bench --dump-edges` file\n", argv[1]);
        return 1;
    }
    uint32_t *edges = read_exact(fp, m * 2 * sizeof(uint32_t), "edges");
    double *normals = read_exact(fp, m * 3 * sizeof(double), "normals");
    double *coords = read_exact(fp, n * 3 * sizeof(double), "coordinates");
    double *prim = read_exact(fp, n * 5 * sizeof(double), "primitives");
    double *grad = read_exact(fp, n * 15 * sizeof(double), "gradients");
    double *expected = read_exact(fp, n * 5 * sizeof(double), "edge residual");
    fclose(fp);
    for (uint64_t e = 0; e < m; e++) {
        if (edges[2 * e] >= n || edges[2 * e + 1] >= n) {
            fprintf(stderr, "edge_loop: edge %llu refers to a node >= %llu\n",
                    (unsigned long long)e, (unsigned long long)n);
            return 1;
        }
    }
    double *res = malloc(n * 5 * sizeof(double));
    double *t = malloc(reps * sizeof(double));
    edge_loop(n, m, gamma, edges, normals, coords, prim, grad, res); /* warm-up */
    for (int r = 0; r < reps; r++) {
        double t0 = now();
        edge_loop(n, m, gamma, edges, normals, coords, prim, grad, res);
        t[r] = now() - t0;
    }
    qsort(t, reps, sizeof(double), cmp_double);
    /* Largest difference from the solver's residual, relative to the largest |R| of each
       component. */
    double worst = 0.0;
    for (int k = 0; k < 5; k++) {
        double scale = 0.0, diff = 0.0;
        for (uint64_t i = 0; i < n; i++) {
            scale = fmax(scale, fabs(expected[5 * i + k]));
            diff = fmax(diff, fabs(res[5 * i + k] - expected[5 * i + k]));
        }
        worst = fmax(worst, diff / fmax(scale, 1e-300));
    }
    printf("{\"nodes\": %llu, \"edges\": %llu, \"repetitions\": %d, "
           "\"seconds_median\": %.6g, \"seconds_min\": %.6g, \"ns_per_edge_median\": %.4g, "
           "\"ns_per_edge_min\": %.4g, \"max_relative_difference_from_solver\": %.3g}\n",
           (unsigned long long)n, (unsigned long long)m, reps, t[reps / 2], t[0],
           t[reps / 2] / m * 1e9, t[0] / m * 1e9, worst);
    return worst < 1e-10 ? 0 : 3;
}
