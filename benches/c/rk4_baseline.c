/*
 * The plain-loop RK4 baseline in C: an independent check of the limit that `platen bench`
 * and `cargo bench --bench rk4_throughput` compare the Rust integrator with.
 *
 * Same loop as src/bench/baseline.rs (platen::bench::baseline): classical RK4 on the identified
 * LHPOST model at 13.8 MPa (Eq. 22/23: Me = 144 t, Ke = 1.266 MN/m, Fmu = 0.44 % x 5783 kN,
 * Ce = 44.58 kN/(m/s)^0.5 with alpha = 0.5 as a square root, a = 12.04 kN, b = 78.5 s/m),
 * one exp per stage, copysign friction, force linearly interpolated, no stick logic, no
 * output. Same workload as `platen bench`: a 100 kN, 0.5 Hz sine force sampled at 1024 Hz
 * (a table test within the LHPOST's limits), stepped at 1/1024 s for 600 s from rest. Prints the median ns/step of 5 runs and the final
 * state (which matches baseline_rk4's to the last bits: same operations, same libm).
 *
 *   cc -O2 benches/c/rk4_baseline.c -lm && ./a.out            (optionally: ./a.out SECONDS RUNS)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define RATE_HZ 1024.0

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Model constants, set in main() so that the compiler cannot fold them into the loop. */
static double K, FMU, C, A, B, INV_M;

static inline double acc(double f, double u, double v) {
    double w = fabs(v);
    return (f - K * u - copysign(FMU + C * sqrt(w) + A * exp(-B * w), v)) * INV_M;
}

static void run(const double *force, size_t n, double h, double *u_out, double *v_out) {
    double u = 0.0, v = 0.0;
    for (size_t j = 0; j + 1 < n; j++) {
        double f0 = force[j], f1 = force[j + 1];
        double fm = 0.5 * (f0 + f1);
        double a1 = acc(f0, u, v);
        double v2 = v + 0.5 * h * a1;
        double a2 = acc(fm, u + 0.5 * h * v, v2);
        double v3 = v + 0.5 * h * a2;
        double a3 = acc(fm, u + 0.5 * h * v2, v3);
        double v4 = v + h * a3;
        double a4 = acc(f1, u + h * v3, v4);
        u += h / 6.0 * (v + 2.0 * (v2 + v3) + v4);
        v += h / 6.0 * (a1 + 2.0 * (a2 + a3) + a4);
    }
    *u_out = u;
    *v_out = v;
}

int main(int argc, char **argv) {
    double seconds = argc > 1 ? atof(argv[1]) : 600.0;
    int runs = argc > 2 ? atoi(argv[2]) : 5;
    if (!(seconds > 0.0) || runs < 1) {
        fprintf(stderr, "usage: %s [SECONDS > 0] [RUNS >= 1]\n", argv[0]);
        return 2;
    }
    double pressure_scale = 13.8e6 / 13.8e6;
    K = 1.266e6 * pressure_scale;
    FMU = 0.0044 * (1.613e6 + 2.0 * 2085e3 * pressure_scale);
    C = 44.58e3;
    A = 12.04e3;
    B = 78.5;
    INV_M = 1.0 / 144e3;

    size_t n = (size_t)llround(seconds * RATE_HZ) + 1;
    double *force = malloc(n * sizeof *force);
    double *times = malloc((size_t)runs * sizeof *times);
    if (!force || !times) return 1;
    double w = 2.0 * 3.141592653589793 * 0.5;
    for (size_t j = 0; j < n; j++) force[j] = 100e3 * sin(w * (double)j / RATE_HZ);

    double u = 0.0, v = 0.0;
    for (int r = 0; r < runs; r++) {
        double start = now_s();
        run(force, n, 1.0 / RATE_HZ, &u, &v);
        times[r] = now_s() - start;
    }
    qsort(times, (size_t)runs, sizeof *times, cmp);
    double median = runs % 2 ? times[runs / 2] : 0.5 * (times[runs / 2 - 1] + times[runs / 2]);
    double steps = (double)(n - 1);
    printf("c_baseline_ns_per_step %.2f\n", median * 1e9 / steps);
    printf("steps_per_s %.4e\n", steps / median);
    printf("simulated_s_per_wall_s %.0f\n", seconds / median);
    printf("final u_m %.17g v_m_s %.17g\n", u, v);
    free(force);
    free(times);
    return 0;
}
