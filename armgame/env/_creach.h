/* A trial's reach measures in C, with no Python in it: included by _ccenter.c, whose ``measures`` gives them to
 * armgame.env.center_out_batch for every ended trial's row of the lab's table. */
#ifndef ARMGAME_REACH_H
#define ARMGAME_REACH_H
#include <math.h>
#include <stdint.h>
#include <string.h>

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

/* reach_metrics's t[k]: (go + k) dt, the same product wherever it is read, so no array of it is kept. */
static double t_at(int64_t go, double dt, int64_t k)
{
    return (double)(go + k) * dt;
}

/* np.interp(x, t, f) at one x, t[k] = t_at(go, dt, k) increasing (n >= 2): numpy's arr_interp without precomputed
 * slopes. */
static double interp(double x, int64_t go, double dt, const double *f, int64_t n)
{
    if (isnan(x))
        return x;
    if (x > t_at(go, dt, n - 1))
        return f[n - 1];
    if (x < t_at(go, dt, 0))
        return f[0];
    int64_t lo = 0, hi = n; /* the last j with t[j] <= x */
    while (lo < hi) {
        const int64_t mid = lo + ((hi - lo) >> 1);
        if (x >= t_at(go, dt, mid))
            lo = mid + 1;
        else
            hi = mid;
    }
    const int64_t j = lo - 1;
    const double tj = t_at(go, dt, j);
    if (j == n - 1 || tj == x)
        return f[j];
    const double tk = t_at(go, dt, j + 1), slope = (f[j + 1] - f[j]) / (tk - tj);
    double r = slope * (x - tj) + f[j];
    if (isnan(r)) {
        r = slope * (x - tk) + f[j + 1];
        if (isnan(r) && f[j] == f[j + 1])
            r = f[j];
    }
    return r;
}

/* The first k in [lo, hi) where t[k] > x (above) or t[k] >= x (not above), else hi: t increasing, a binary search. A
 * NaN x is above no t and below none. */
static int64_t t_past(double x, int64_t go, double dt, int64_t lo, int64_t hi, int above)
{
    while (lo < hi) {
        const int64_t mid = lo + ((hi - lo) >> 1);
        const double t = t_at(go, dt, mid);
        if (above ? t > x : !(t < x))
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* The largest of a[from:to], none NaN: four running maxima, no one chain of comparisons. */
static double largest(const double *a, int64_t from, int64_t to)
{
    double m[4] = {a[from], a[from], a[from], a[from]};
    int64_t k = from;
    for (; k + 4 <= to; k += 4)
        for (int j = 0; j < 4; j++)
            m[j] = a[k + j] > m[j] ? a[k + j] : m[j];
    for (; k < to; k++)
        m[0] = a[k] > m[0] ? a[k] : m[0];
    for (int j = 1; j < 4; j++)
        m[0] = m[j] > m[0] ? m[j] : m[0];
    return m[0];
}

/* np.argmax over a[from:to]: the first NaN, else the first place of ``largest``'s maximum. (One best index carried
 * from element to element, its value loaded again on each, was a chain of dependent steps that cost more than the
 * rest of the trial's measures.) */
static int64_t argmax(const double *a, int64_t from, int64_t to)
{
    int nan = 0;
    for (int64_t k = from; k < to; k++)
        nan |= isnan(a[k]);
    const double top = nan ? NAN : largest(a, from, to);
    for (int64_t k = from; k < to; k++)
        if (nan ? isnan(a[k]) : a[k] == top)
            return k;
    return from;
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

/* The speed at sample k, as np.hypot(*np.gradient(hand, step, axis=0).T) has it: one side's difference at the ends,
 * the central one between, each divided before hypot. */
static double speed_at(const double *x, const double *y, int64_t n, int64_t k, double step)
{
    if (k == 0)
        return hypot((x[1] - x[0]) / step, (y[1] - y[0]) / step);
    if (k == n - 1)
        return hypot((x[n - 1] - x[n - 2]) / step, (y[n - 1] - y[n - 2]) / step);
    const double two = 2.0 * step;
    return hypot((x[k + 1] - x[k - 1]) / two, (y[k + 1] - y[k - 1]) / two);
}

/* Whether every coordinate is 0 or within [1e-100, 1e100] in size (none NaN or infinite). On the bits of |v|, whose
 * order as integers is the order of the values, and with no comparison, so that the compiler runs it on vectors: the
 * top bit of HI - u is set when u > HI, that of (u - LO) & -u when 0 < u < LO. */
static int coordinates_fit(const double *x, const double *y, int64_t n)
{
    const double least = 1e-100, most = 1e100;
    uint64_t lo, hi, bad = 0;
    memcpy(&lo, &least, 8);
    memcpy(&hi, &most, 8);
    for (int64_t k = 0; k < n; k++) {
        uint64_t u, v;
        memcpy(&u, x + k, 8);
        memcpy(&v, y + k, 8);
        u &= 0x7fffffffffffffffULL;
        v &= 0x7fffffffffffffffULL;
        bad |= (hi - u) | ((u - lo) & (0 - u)) | (hi - v) | ((v - lo) & (0 - v));
    }
    return (bad >> 63) == 0;
}

/* The speeds are needed exactly at a handful of samples only (the peak, the two samples around each level
 * crossing): the others are settled by r[k], the squared difference (dx dx + dy dy; 4 times it at the ends, for
 * their single step), which is the exact speed's square times (2 step)^2 within a relative NEAR. Why: with every
 * coordinate 0 or within [1e-100, 1e100] and the step within [1e-100, 1e100], each nonzero difference lies within
 * [1e-116, 2e100] (a multiple of the smaller coordinate's ulp), so no difference, quotient, square, sum or hypot
 * overflows or underflows: each errs by half an ulp, hypot by one (glibc's; any within 2,000 ulp would do), and
 * r[k] is within 10 ulp, far inside NEAR; r[k] == 0 means both differences are 0, a speed of exactly 0. Otherwise
 * (``exact``) r holds the speeds themselves, by hypot, and each margin is 0. */
#define NEAR 1e-12

typedef struct {
    const double *x, *y, *r;
    int64_t n;
    double step;
    int exact;
} Speeds;

static double speed(const Speeds *s, int64_t k)
{
    return s->exact || s->r[k] == 0.0 ? s->r[k] : speed_at(s->x, s->y, s->n, k, s->step);
}

/* Whether the speed at k is below the level, lo and hi the level's own r (less and more its margins): only a speed
 * within the margins costs its hypot. */
static int below(const Speeds *s, int64_t k, double lo, double hi, double level)
{
    return s->r[k] < lo || (s->r[k] <= hi && speed(s, k) < level);
}

/* One reach: the hand x, y (n samples from the go cue), its first sample's step go, the step dt, the home and
 * target centres; out gets the six measures (NaN where undefined); work holds 5 n doubles. */
static void reach_measures(const double *x, const double *y, int64_t n, int64_t go, double dt, const double *home,
                           const double *target, double *out, double *work)
{
    for (int k = 0; k < M_COUNT; k++)
        out[k] = NAN;
    if (n < 2)
        return;
    double *r = work, *px = work + n, *py = work + 2 * n, *seg = work + 3 * n, *side = work + 4 * n;
    const double go_time = t_at(go, dt, 0);
    if (!(isfinite(go_time) && isfinite(home[0]) && isfinite(home[1]) && isfinite(target[0])
          && isfinite(target[1]) && isfinite(t_at(go, dt, n - 1))))
        return;
    /* reach_metrics wants t finite and rising (np.diff(t) <= 0 nowhere: for finite a and b, a - b <= 0 is a <= b).
     * It is, with no look, when dt is normal and positive and 0 <= go, go + n < 2^52: each go + k is exact, and dt
     * is more than an ulp of (go + k + 1) dt, so the rounded products rise; the last finite, all are. */
    if (!(dt >= 2.2250738585072014e-308 && go >= 0 && go < ((int64_t)1 << 52) - n))
        for (int64_t k = 1; k < n; k++)
            if (!(isfinite(t_at(go, dt, k)) && t_at(go, dt, k) > t_at(go, dt, k - 1)))
                return;
    const int sure = coordinates_fit(x, y, n);
    if (!sure)
        for (int64_t k = 0; k < n; k++)
            if (!(isfinite(x[k]) && isfinite(y[k])))
                return;
    /* reach_metrics's samples at or after the go cue are all n: t[0] is go_time, the same product */
    const double step = (t_at(go, dt, n - 1) - t_at(go, dt, 0)) / (double)(n - 1), two = 2.0 * step;
    Speeds s = {x, y, r, n, step, !(sure && step >= 1e-100 && step <= 1e100)};
    if (s.exact)
        for (int64_t k = 0; k < n; k++)
            r[k] = speed_at(x, y, n, k, step);
    else {
        double dx = x[1] - x[0], dy = y[1] - y[0];
        r[0] = 4.0 * (dx * dx + dy * dy);
        for (int64_t k = 1; k + 1 < n; k++) {
            dx = x[k + 1] - x[k - 1];
            dy = y[k + 1] - y[k - 1];
            r[k] = dx * dx + dy * dy;
        }
        dx = x[n - 1] - x[n - 2];
        dy = y[n - 1] - y[n - 2];
        r[n - 1] = 4.0 * (dx * dx + dy * dy);
    }
    /* np.argmax over the speeds. Inside the margins none is NaN, so it is the first largest, found among the samples
     * whose r comes within the margins of the largest r */
    int64_t peak = 0;
    double top = -1.0;
    if (s.exact) {
        peak = argmax(r, 0, n);
        top = r[peak];
    }
    else {
        const double most = largest(r, 0, n), least = most * (1.0 - 4 * NEAR);
        for (int64_t k = 0; k < n; k++)
            if (r[k] >= least) {
                const double v = speed(&s, k);
                if (v > top) {
                    top = v;
                    peak = k;
                }
            }
    }
    out[M_PEAK] = top;
    if (!(top >= 0.01) || top == 0.0)
        return;
    const double level = 0.05 * top, scaled = level * two;
    const double lo = s.exact ? level : scaled * scaled * (1.0 - 4 * NEAR);
    const double hi = s.exact ? level : scaled * scaled * (1.0 + 4 * NEAR);
    double t_on = t_at(go, dt, 0), t_end = t_at(go, dt, n - 1);
    for (int64_t i = peak - 1; i >= 0; i--)
        if (below(&s, i, lo, hi, level)) {
            const double v = speed(&s, i), w = speed(&s, i + 1), ti = t_at(go, dt, i);
            t_on = ti + (level - v) / (w - v) * (t_at(go, dt, i + 1) - ti);
            break;
        }
    for (int64_t j = peak + 1; j < n; j++)
        if (below(&s, j, lo, hi, level)) {
            const double v = speed(&s, j - 1), w = speed(&s, j), ti = t_at(go, dt, j - 1);
            t_end = ti + (v - level) / (v - w) * (t_at(go, dt, j) - ti);
            break;
        }
    const double on_x = interp(t_on, go, dt, x, n), on_y = interp(t_on, go, dt, y, n);
    const double end_x = interp(t_end, go, dt, x, n), end_y = interp(t_end, go, dt, y, n);
    /* the path: onset, the samples with t_on < t < t_end (a run of them, t rising), the end */
    const int64_t from = t_past(t_on, go, dt, 0, n, 1), to = t_past(t_end, go, dt, from, n, 0);
    int64_t m = 0;
    px[m] = on_x;
    py[m++] = on_y;
    memcpy(px + m, x + from, (size_t)(to - from) * sizeof(double));
    memcpy(py + m, y + from, (size_t)(to - from) * sizeof(double));
    m += to - from;
    px[m] = end_x;
    py[m++] = end_y;
    for (int64_t k = 0; k + 1 < m; k++)
        seg[k] = hypot(px[k + 1] - px[k], py[k + 1] - py[k]);
    const double length = 0.0 + pairwise_sum(seg, m - 1);
    const double chord = hypot(end_x - on_x, end_y - on_y);
    out[M_RATIO] = chord > 0.0 ? length / chord : NAN;
    double at = t_on + 0.1;
    if (t_at(go, dt, n - 1) < at)
        at = t_at(go, dt, n - 1);
    const double moved_x = interp(at, go, dt, x, n) - on_x, moved_y = interp(at, go, dt, y, n) - on_y;
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
