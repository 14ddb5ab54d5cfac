/* A trial's reach measures in C, with no Python in it: included by _ccenter.c, whose ``measures`` gives them to
 * armgame.env.center_out_batch for every ended trial's row of the lab's table. */
#ifndef ARMGAME_REACH_H
#define ARMGAME_REACH_H
#include <math.h>
#include <stdint.h>

/* ---------------------------------------------------------------- a trial's reach measures
 * lab.metrics.reach_metrics (its defaults: threshold 0.05, the direction 100 ms after onset, moved from 0.01 m/s)
 * on lab.analysis.reach_of's reach, operation for operation in numpy's order, so each number is the single env's
 * bit for bit: np.gradient's differences, the C library's hypot (np.hypot's), np.argmax's first largest (a NaN
 * first), np.interp's search and slope (numpy's compiled_base.c), np.sum's pairwise sum from its identity 0, and
 * Python's math.atan2 and math.degrees. tests/test_env_center_out_batch.py compares it with reach_metrics. */
enum { M_RT, M_MT, M_PEAK, M_DIR, M_PERP, M_RATIO, M_COUNT };

/* numpy's pairwise sum of float64 (loops_utils.h.src), as np.add.reduce runs it on one contiguous array. */
static double pairwise_sum(const double *a, int64_t n)
{
    if (n < 8) {
        double res = -0.0;
        for (int64_t i = 0; i < n; i++)
            res += a[i];
        return res;
    }
    if (n <= 128) {
        double r[8];
        int64_t i;
        for (int k = 0; k < 8; k++)
            r[k] = a[k];
        for (i = 8; i < n - (n % 8); i += 8)
            for (int k = 0; k < 8; k++)
                r[k] += a[i + k];
        double res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
        for (; i < n; i++)
            res += a[i];
        return res;
    }
    int64_t n2 = n / 2;
    n2 -= n2 % 8;
    return pairwise_sum(a, n2) + pairwise_sum(a + n2, n - n2);
}

/* np.interp(x, t, f) at one x, t increasing (n >= 2): numpy's arr_interp without precomputed slopes. */
static double interp(double x, const double *t, const double *f, int64_t n)
{
    if (isnan(x))
        return x;
    if (x > t[n - 1])
        return f[n - 1];
    if (x < t[0])
        return f[0];
    int64_t lo = 0, hi = n; /* the last j with t[j] <= x */
    while (lo < hi) {
        const int64_t mid = lo + ((hi - lo) >> 1);
        if (x >= t[mid])
            lo = mid + 1;
        else
            hi = mid;
    }
    const int64_t j = lo - 1;
    if (j == n - 1 || t[j] == x)
        return f[j];
    const double slope = (f[j + 1] - f[j]) / (t[j + 1] - t[j]);
    double r = slope * (x - t[j]) + f[j];
    if (isnan(r)) {
        r = slope * (x - t[j + 1]) + f[j + 1];
        if (isnan(r) && f[j] == f[j + 1])
            r = f[j];
    }
    return r;
}

/* np.argmax over a[from:to]: the first largest, or the first NaN. */
static int64_t argmax(const double *a, int64_t from, int64_t to)
{
    int64_t best = from;
    for (int64_t k = from; k < to; k++) {
        if (isnan(a[k]))
            return k;
        if (a[k] > a[best])
            best = k;
    }
    return best;
}

/* Python's math.atan2 (its m_atan2: the special values before the C library's). */
static double py_atan2(double y, double x)
{
    const double pi = 3.141592653589793;
    if (isnan(x) || isnan(y))
        return NAN;
    if (isinf(y)) {
        if (isinf(x))
            return copysign(x > 0 ? 0.25 * pi : 0.75 * pi, y);
        return copysign(0.5 * pi, y);
    }
    if (isinf(x) || y == 0.0)
        return copysign(1.0, x) == 1.0 ? 0.0 * y : copysign(pi, y);
    return atan2(y, x);
}

/* One reach: the hand x, y (n samples from the go cue), its first sample's step go, the step dt, the home and
 * target centres; out gets the six measures (NaN where undefined); work holds 6 n doubles. */
static void reach_measures(const double *x, const double *y, int64_t n, int64_t go, double dt, const double *home,
                           const double *target, double *out, double *work)
{
    for (int k = 0; k < M_COUNT; k++)
        out[k] = NAN;
    if (n < 2)
        return;
    double *t = work, *speed = work + n, *px = work + 2 * n, *py = work + 3 * n, *seg = work + 4 * n,
           *side = work + 5 * n;
    const double go_time = (double)go * dt;
    int finite = isfinite(go_time) && isfinite(home[0]) && isfinite(home[1]) && isfinite(target[0])
                 && isfinite(target[1]);
    for (int64_t k = 0; k < n; k++) {
        t[k] = (double)(go + k) * dt;
        finite = finite && isfinite(t[k]) && isfinite(x[k]) && isfinite(y[k]);
    }
    if (!finite)
        return;
    for (int64_t k = 0; k + 1 < n; k++)
        if (t[k + 1] - t[k] <= 0.0)
            return;
    int64_t first = n; /* t increases: the samples at or after the go cue are a tail */
    for (int64_t k = 0; k < n; k++)
        if (t[k] >= go_time) {
            first = k;
            break;
        }
    if (n - first < 2)
        return;
    const double step = (t[n - 1] - t[0]) / (double)(n - 1), two = 2.0 * step;
    speed[0] = hypot((x[1] - x[0]) / step, (y[1] - y[0]) / step);
    for (int64_t k = 1; k + 1 < n; k++)
        speed[k] = hypot((x[k + 1] - x[k - 1]) / two, (y[k + 1] - y[k - 1]) / two);
    speed[n - 1] = hypot((x[n - 1] - x[n - 2]) / step, (y[n - 1] - y[n - 2]) / step);
    const int64_t peak = argmax(speed, first, n);
    const double top = speed[peak];
    out[M_PEAK] = top;
    if (!(top >= 0.01) || top == 0.0)
        return;
    const double level = 0.05 * top;
    double t_on = t[0], t_end = t[n - 1];
    for (int64_t i = peak - 1; i >= 0; i--)
        if (speed[i] < level) {
            t_on = t[i] + (level - speed[i]) / (speed[i + 1] - speed[i]) * (t[i + 1] - t[i]);
            break;
        }
    for (int64_t j = peak + 1; j < n; j++)
        if (speed[j] < level) {
            t_end = t[j - 1] + (speed[j - 1] - level) / (speed[j - 1] - speed[j]) * (t[j] - t[j - 1]);
            break;
        }
    const double on_x = interp(t_on, t, x, n), on_y = interp(t_on, t, y, n);
    const double end_x = interp(t_end, t, x, n), end_y = interp(t_end, t, y, n);
    int64_t m = 0;
    px[m] = on_x;
    py[m++] = on_y;
    for (int64_t k = 0; k < n; k++)
        if (t[k] > t_on && t[k] < t_end) {
            px[m] = x[k];
            py[m++] = y[k];
        }
    px[m] = end_x;
    py[m++] = end_y;
    for (int64_t k = 0; k + 1 < m; k++)
        seg[k] = hypot(px[k + 1] - px[k], py[k + 1] - py[k]);
    const double length = 0.0 + pairwise_sum(seg, m - 1);
    const double chord = hypot(end_x - on_x, end_y - on_y);
    out[M_RATIO] = chord > 0.0 ? length / chord : NAN;
    double at = t_on + 0.1;
    if (t[n - 1] < at)
        at = t[n - 1];
    const double moved_x = interp(at, t, x, n) - on_x, moved_y = interp(at, t, y, n) - on_y;
    const double aim_x = target[0] - home[0], aim_y = target[1] - home[1];
    const double distance = hypot(aim_x, aim_y);
    if (distance > 0.0) {
        const double u0 = aim_x / distance, u1 = aim_y / distance;
        for (int64_t k = 0; k < m; k++) {
            const double a = u0 * (py[k] - home[1]), b = u1 * (px[k] - home[0]);
            side[k] = fabs(a - b);
            seg[k] = a - b;
        }
        out[M_PERP] = seg[argmax(side, 0, m)];
        if (moved_x != 0.0 || moved_y != 0.0) {
            const double cross = u0 * moved_y - u1 * moved_x, dot = u0 * moved_x + u1 * moved_y;
            const double direction = py_atan2(cross, dot) * (180.0 / 3.141592653589793);
            out[M_DIR] = direction == -180.0 ? 180.0 : direction;
        }
    }
    out[M_RT] = t_on - go_time;
    out[M_MT] = t_end - t_on;
}

#endif
