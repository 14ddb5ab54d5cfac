/* Python's math.hypot(x, y) in C, bit for bit: CPython's own algorithm (Modules/mathmodule.c's vector_norm for two
 * coordinates), not the C library's hypot, which differs from it in the last bit now and then. The single env's
 * dense reward measures its distance with math.hypot, so the batch's must be this one. CPython changed the
 * algorithm in 3.12 (exact squares by fma, two compensation terms where 3.11 split them and kept three), and the
 * two can differ in the last bit; the extension is built for one Python, so it takes that Python's. Only +, -, *, /, sqrt, fma, frexp and ldexp,
 * all correctly rounded, so the bits are the platform's Python's wherever the C library's fma is exact (C99
 * requires it; it is on glibc, macOS and Windows' UCRT). tests/test_env_center_out_batch.py compares it with
 * math.hypot on random, huge, tiny, subnormal and special values. The file is built with contraction off. */
#ifndef ARMGAME_PYHYPOT_H
#define ARMGAME_PYHYPOT_H
#include <Python.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

/* frexp's exponent of a positive finite x, and ldexp(1.0, k): from the bits where the numbers are normal, else the C
 * library's (the same values, both exact). Two library calls an env a step were a fifth of the dense reward's time. */
static inline int py_hypot_exponent(double x)
{
    uint64_t bits;
    memcpy(&bits, &x, sizeof bits);
    const int field = (int)((bits >> 52) & 0x7ff);
    if (field == 0) {
        int e;
        frexp(x, &e);
        return e;
    }
    return field - 1022;
}

static inline double py_hypot_pow2(int k)
{
    if (k < -1022 || k > 1023)
        return ldexp(1.0, k);
    const uint64_t bits = (uint64_t)(k + 1023) << 52;
    double x;
    memcpy(&x, &bits, sizeof x);
    return x;
}

#if PY_VERSION_HEX >= 0x030C0000

/* 3.12 on: Ogita, Rump and Oishi's exact sum and product (CPython's dl_fast_sum, dl_mul). */
typedef struct {
    double hi, lo;
} PyHypotPair;

static inline PyHypotPair py_hypot_fast_sum(double a, double b)
{
    const double x = a + b;
    return (PyHypotPair){x, (a - x) + b};
}

static inline PyHypotPair py_hypot_mul(double x, double y)
{
    const double z = x * y;
    return (PyHypotPair){z, fma(x, y, -z)};
}

/* vector_norm of n = 2 values v (each >= 0, finite), max the larger. */
static double py_hypot_norm(double v0, double v1, double max)
{
    if (max == 0.0)
        return max;
    const int max_e = py_hypot_exponent(max);
    if (max_e < -1023)  /* py_hypot_pow2(-max_e) would overflow: subnormals made normal first */
        return DBL_MIN * py_hypot_norm(v0 / DBL_MIN, v1 / DBL_MIN, max / DBL_MIN);
    const double scale = py_hypot_pow2(-max_e);
    double csum = 1.0, frac1 = 0.0, frac2 = 0.0;
    const double v[2] = {v0, v1};
    for (int i = 0; i < 2; i++) {
        const double x = v[i] * scale;
        const PyHypotPair pr = py_hypot_mul(x, x);
        const PyHypotPair sm = py_hypot_fast_sum(csum, pr.hi);
        csum = sm.hi;
        frac1 += pr.lo;
        frac2 += sm.lo;
    }
    double h = sqrt(csum - 1.0 + (frac1 + frac2));
    const PyHypotPair pr = py_hypot_mul(-h, h);
    const PyHypotPair sm = py_hypot_fast_sum(csum, pr.hi);
    csum = sm.hi;
    frac1 += pr.lo;
    frac2 += sm.lo;
    const double x = csum - 1.0 + (frac1 + frac2);
    h += x / (2.0 * h);
    return h / scale;
}

#else

/* 3.11: Dekker's split of each scaled value into halves, three compensation terms. */
static double py_hypot_norm(double v0, double v1, double max)
{
    const double T27 = 134217729.0; /* 2**27 + 1 */
    if (max == 0.0)
        return max;
    const int max_e = py_hypot_exponent(max);
    double x, t, hi, lo, oldcsum, csum = 1.0, frac1 = 0.0, frac2 = 0.0, frac3 = 0.0;
    const double v[2] = {v0, v1};
    if (max_e >= -1023) {
        const double scale = py_hypot_pow2(-max_e);
        for (int i = 0; i < 2; i++) {
            x = v[i] * scale;
            t = x * T27;
            hi = t - (t - x);
            lo = x - hi;
            x = hi * hi;
            oldcsum = csum;
            csum += x;
            frac1 += (oldcsum - csum) + x;
            x = 2.0 * hi * lo;
            oldcsum = csum;
            csum += x;
            frac2 += (oldcsum - csum) + x;
            frac3 += lo * lo;
        }
        const double h = sqrt(csum - 1.0 + (frac1 + frac2 + frac3));
        x = h;
        t = x * T27;
        hi = t - (t - x);
        lo = x - hi;
        x = -hi * hi;
        oldcsum = csum;
        csum += x;
        frac1 += (oldcsum - csum) + x;
        x = -2.0 * hi * lo;
        oldcsum = csum;
        csum += x;
        frac2 += (oldcsum - csum) + x;
        x = -lo * lo;
        oldcsum = csum;
        csum += x;
        frac3 += (oldcsum - csum) + x;
        x = csum - 1.0 + (frac1 + frac2 + frac3);
        return (h + x / (2.0 * h)) / scale;
    }
    /* The largest is subnormal-small: divide by it instead of scaling. */
    for (int i = 0; i < 2; i++) {
        x = v[i] / max;
        x = x * x;
        oldcsum = csum;
        csum += x;
        frac1 += (oldcsum - csum) + x;
    }
    return max * sqrt(csum - 1.0 + frac1);
}

#endif

/* math.hypot(a, b): math_hypot's absolute values, its largest (a NaN is never the largest), then an infinity
 * before a NaN, as vector_norm tests them. */
static inline double py_hypot(double a, double b)
{
    const double x = fabs(a), y = fabs(b);
    double max = 0.0;
    if (x > max)
        max = x;
    if (y > max)
        max = y;
    if (isinf(max))
        return max;
    if (isnan(x) || isnan(y))
        return NAN;
    return py_hypot_norm(x, y, max);
}

#endif
