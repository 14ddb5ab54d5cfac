/* The arm's trig in C: ``arm_sin_cos`` is armgame.physics.trig.sin_cos, operation for operation. Included
 * by the game's compiled loops (game/_ckernel.h) and by physics/_ctrig.c, which gives Python the same
 * function. */
#ifndef ARMGAME_TRIG_H
#define ARMGAME_TRIG_H
#include <math.h>
#include <stdint.h>
#include <string.h>

/* The arm's trig (the equations of motion): armgame.physics.trig.sin_cos, the same operations in the
 * same order (see that module for the method, its accuracy and why it is not the C library's). Only
 * correctly rounded +, - and *, and selections: the same bits whether one game or LANES at a time in
 * vector registers, and the same as Python's and numpy's. */
#define TRIG_MAX_ANGLE 1e15
#define TRIG_INV_PIO2 6.36619772367581382433e-01
#define TRIG_SHIFT 6755399441055744.0
#define TRIG_PIO2_1 1.57079632673412561417e+00
#define TRIG_PIO2_2 6.07710050630396597660e-11
#define TRIG_PIO2_3 2.02226624871116645580e-21
#define TRIG_S1 -1.66666666666666324348e-01
#define TRIG_S2 8.33333333332248946124e-03
#define TRIG_S3 -1.98412698298579493134e-04
#define TRIG_S4 2.75573137070700676789e-06
#define TRIG_S5 -2.50507602534068634195e-08
#define TRIG_S6 1.58969099521155010221e-10
#define TRIG_C1 4.16666666666666019037e-02
#define TRIG_C2 -1.38888888888741095749e-03
#define TRIG_C3 2.48015872894767294178e-05
#define TRIG_C4 -2.75573143513906633035e-07
#define TRIG_C5 2.08757232129817482790e-09
#define TRIG_C6 -1.13596475577881948265e-11

#if defined(__GNUC__) || defined(__clang__)
#define TRIG_INLINE static inline __attribute__((always_inline))
#elif defined(_MSC_VER)
#define TRIG_INLINE static __forceinline
#else
#define TRIG_INLINE static inline
#endif

TRIG_INLINE void arm_sin_cos(double x, double *so, double *co)
{
    /* Past TRIG_MAX_ANGLE (or not finite) the arithmetic below runs on anyway, to keep the lanes'
     * loops free of branches, and its result is replaced by NaN. */
    const int inside = fabs(x) <= TRIG_MAX_ANGLE;
    const double y = x * TRIG_INV_PIO2 + TRIG_SHIFT;
    const double k = y - TRIG_SHIFT;
    const double r = ((x - k * TRIG_PIO2_1) - k * TRIG_PIO2_2) - k * TRIG_PIO2_3;
    const double z = r * r, w = z * z;
    const double s = r + z * r * (TRIG_S1 + z * (TRIG_S2 + z * (TRIG_S3 + z * TRIG_S4)
                                                 + z * w * (TRIG_S5 + z * TRIG_S6)));
    const double hz = 0.5 * z, v = 1.0 - hz;
    const double c = v + (((1.0 - v) - hz) + z * (z * (TRIG_C1 + z * (TRIG_C2 + z * TRIG_C3))
                                                  + w * w * (TRIG_C4 + z * (TRIG_C5 + z * TRIG_C6))));
    /* k mod 4 is in y's low bits (|k| < 2^51): odd swaps sin and cos, and the signs follow. */
    uint64_t n, a, b;
    memcpy(&n, &y, sizeof n);
    n &= 3;
    const double first = (n & 1) ? c : s, second = (n & 1) ? s : c;
    memcpy(&a, &first, sizeof a);
    memcpy(&b, &second, sizeof b);
    a ^= (n & 2) << 62;
    b ^= ((n + 1) & 2) << 62;
    double sn, cs;
    memcpy(&sn, &a, sizeof sn);
    memcpy(&cs, &b, sizeof cs);
    *so = inside ? sn : NAN;
    *co = inside ? cs : NAN;
}

TRIG_INLINE double arm_cos(double x)
{
    double s, c;
    arm_sin_cos(x, &s, &c);
    return c;
}

#endif
