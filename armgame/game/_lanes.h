/* The arm's step in vector lanes: LANES runs side by side, one array per quantity with a run per element
 * (structure of arrays), so that every arithmetic line is one loop over the lanes that the compiler turns into
 * vector instructions. RK4's stages here are _cstep.h's ``rk4_exact`` and ``muscle_step``, operation for
 * operation, lane by lane (see _cbatch.c's opening comment for why the results are the one-at-a-time loop's,
 * bit for bit). Two loops step their runs here: the game's batch (_clanes.c) and CenterOut's (env/_ccenter.c).
 * Include it after Python.h (a lane's game is a Py_ssize_t). */
#ifndef ARMGAME_LANES_H
#define ARMGAME_LANES_H
#include "_cstep.h"

/* Games side by side. A step is a chain of four dependent stages, each waiting on a divide (13 cycles)
 * and its series, so the lanes are there to hide latency as much as to fill a register: the fast kernel
 * ran 65 M arm-steps/s with 8 lanes, 78 M with 16 and 77 M with 32 (benchmarks/kernel_speed.py). */
#define LANES 16

/* Where the compiler and platform can build one function for several instruction sets and pick
 * the one the CPU has when the module loads (GCC and Clang on x86-64 Linux: an ifunc), the lanes'
 * step is built for x86-64-v4 (AVX-512: 8 doubles a vector), for AVX2 (4) and for the baseline (SSE2,
 * 2). Elsewhere (MSVC, macOS, ARM's NEON is baseline) it is built once for the baseline. Either way
 * the same IEEE operations in the same order: the results do not depend on which runs. */
#if defined(__x86_64__) && defined(__linux__) && defined(__has_attribute)
#if __has_attribute(target_clones)
/* GCC names x86-64-v4 from 11 on, Clang's target_clones takes it from 14 on; older ones get AVX2. */
#if (defined(__clang__) && __clang_major__ >= 14) || (!defined(__clang__) && __GNUC__ >= 11)
#define LANES_CLONES __attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
#else
#define LANES_CLONES __attribute__((target_clones("avx2", "default")))
#endif
#endif
#endif
#ifndef LANES_CLONES
#define LANES_CLONES
#endif

/* The lanes' helpers go inside each build of the step, so their loops are built for its instructions. */
#if defined(__GNUC__) || defined(__clang__)
#define LANES_INLINE static inline __attribute__((always_inline))
#elif defined(_MSC_VER)
#define LANES_INLINE static __forceinline
#else
#define LANES_INLINE static inline
#endif


/* The lanes' state: one array per quantity, a game per element. */
typedef struct {
    double q1[LANES], q2[LANES], w1[LANES], w2[LANES];
    double a[4][LANES], g[4][LANES], r[4][LANES];
    double sl[LANES], x0[LANES], y0[LANES];
    double bc[LANES], bs[LANES];        /* stage 1's b cos q2, b sin q2 (the fast kernel carries them) */
    double qs[LANES], ds[LANES];        /* a stage's elbow angle and, in the fast kernel, its increment */
    double ec[LANES], es[LANES];        /* that stage's b cos and b sin of it */
    int ok[LANES];                      /* the fast kernel's series held for the lane (else: in full) */
    double ms[4][LANES], me[4][LANES];  /* the loaded step's muscle moments (motor noise: each game's own) */
    int run[LANES];                     /* the loaded step: the lane's joint speed passed the guard */
    int anchor[LANES];
    int64_t s[LANES], stop[LANES], next[LANES], c[LANES], end[LANES];
    Py_ssize_t game[LANES];             /* the lane's game, or -1 */
} Lanes;

/* The step's constants, the same for every lane. */
typedef struct {
    double b, d, det0, amd, k1, k2, dt, h, k, limit2, reach1, reach2;
    double s[4], e[4];
    int damping, fast;
    /* The loaded step's (Batch's field and limit). */
    Field field;
    double limit;
} Step;

/* The torque of the field at the hand at every lane's stage (``field_torque``), into e1, e2. The exact kernel
 * takes the hand's cos and sin from the C library, as Python's ``math`` does there; the fast kernel from the
 * arm's own trig, which vectorises (round-off: it is within an ulp of the C library's). */
LANES_INLINE void field_lanes(const Step *k, const double *q1, const double *q2, const double *w1,
                               const double *w2, double *e1, double *e2)
{
    double s1[LANES], c1[LANES], s12[LANES], c12[LANES];
    if (k->fast) {
        for (int l = 0; l < LANES; l++) {
            arm_sin_cos(q1[l], &s1[l], &c1[l]);
            arm_sin_cos(q1[l] + q2[l], &s12[l], &c12[l]);
        }
    } else {
        for (int l = 0; l < LANES; l++) {
            sin_cos(q1[l], &s1[l], &c1[l]);
            sin_cos(q1[l] + q2[l], &s12[l], &c12[l]);
        }
    }
    for (int l = 0; l < LANES; l++)
        field_torque(&k->field, s1[l], c1[l], s12[l], c12[l], w1[l], w2[l], &e1[l], &e2[l]);
}

/* TwoJointArm's accel_unforced or accel_with_damping (``accel_trig``) for every lane, the lanes' stage
 * angles in q1, q2, speeds in w1, w2, elbow trig in L->ec, L->es; ``loaded`` (a constant where inlined):
 * the field's torque added to the muscles', as loads' ``accel`` passes ``t1 + e1`` on. */
LANES_INLINE void accel_lanes(const Step *k, const Lanes *L, const double *q1, const double *q2, const double *w1,
                               const double *w2, const double *t1, const double *t2, double *o1, double *o2,
                               const int loaded)
{
    double e1[LANES], e2[LANES];
    const int pushed = loaded && k->field.kind != FIELD_NONE;
    if (pushed)
        field_lanes(k, q1, q2, w1, w2, e1, e2);
    for (int l = 0; l < LANES; l++) {
        const double bc = L->ec[l], h = L->es[l];
        const double m12 = k->d + bc;
        const double u1 = pushed ? t1[l] + e1[l] : t1[l];
        const double u2 = pushed ? t2[l] + e2[l] : t2[l];
        double f1 = u1 + h * (w1[l] + w1[l] + w2[l]) * w2[l];
        double f2 = u2 - h * w1[l] * w1[l];
        if (k->damping) {
            f1 = f1 - k->k1 * w1[l];
            f2 = f2 - k->k2 * w2[l];
        }
        const double r = 1.0 / (k->det0 - bc * bc);
        o1[l] = (k->d * f1 - m12 * f2) * r;
        o2[l] = ((m12 + k->amd + bc) * f2 - m12 * f1) * r;
    }
}

/* b cos q and b sin q in full (``arm_sin_cos``) into *oc and *os. */
LANES_INLINE void trig_lane(const Step *k, double q, double *oc, double *os)
{
    double sn, cs;
    arm_sin_cos(q, &sn, &cs);
    *oc = k->b * cs;
    *os = k->b * sn;
}

/* The same for every lane's angle q, into oc and os: one vector loop. */
LANES_INLINE void trig_lanes(const Step *k, const double *q, double *oc, double *os)
{
    for (int l = 0; l < LANES; l++)
        trig_lane(k, q[l], &oc[l], &os[l]);
}

/* A stage's elbow trig for every lane: in full (``arm_sin_cos``: the exact kernel, every lane in one
 * vector loop; the fast kernel's lanes whose increment is past the series' range), else turned from
 * stage 1's by the series. */
LANES_INLINE void elbow_lanes(const Step *k, Lanes *L)
{
    int all = 1;
    if (k->fast) {
        for (int l = 0; l < LANES; l++) {
            const double delta = L->ds[l], d2 = delta * delta;
            const double c = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * (1.0 / 40320.0))));
            const double s = delta * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (-1.0 / 5040.0
                                                                                      + d2 * (1.0 / 362880.0)))));
            L->ec[l] = L->bc[l] * c - L->bs[l] * s;
            L->es[l] = L->bs[l] * c + L->bc[l] * s;
            L->ok[l] = d2 <= k->limit2;
        }
        for (int l = 0; l < LANES; l++)
            all &= L->ok[l];
        if (all)
            return;
    }
    if (!k->fast) {
        trig_lanes(k, L->qs, L->ec, L->es);
        return;
    }
    for (int l = 0; l < LANES; l++)
        if (!L->ok[l])
            trig_lane(k, L->qs[l], &L->ec[l], &L->es[l]);
}

/* One RK4 step of every lane (``run_scalar``'s step, lane by lane): the muscles, the four stages, the
 * fast kernel's trig carried to the next step, and the slack. Returns whether some lane's slack ran out,
 * or, ``loaded``, its joint speed passed the guard (L->run). ``loaded``: each lane's own muscle moments
 * (L->ms, L->me), the field and the guard (game/variant.py's physics); a constant, so that the plain
 * step (``step_lanes``) carries none of it. */
LANES_INLINE int step_lanes_as(const Step *k, Lanes *L, const int loaded)
{
    double t1[LANES], t2[LANES], p1[LANES], p2[LANES];
    double a1[LANES], a2[LANES], b1[LANES], b2[LANES], c1[LANES], c2[LANES], d1[LANES], d2[LANES];
    double v1[LANES], v2[LANES], u1[LANES], u2[LANES], z1[LANES], z2[LANES], qa[LANES];
    if (loaded) {
        for (int l = 0; l < LANES; l++) {
            double a0 = L->a[0][l], a1_ = L->a[1][l], a2_ = L->a[2][l], a3 = L->a[3][l];
            t1[l] = a0 * L->ms[0][l] + a1_ * L->ms[1][l] + a2_ * L->ms[2][l] + a3 * L->ms[3][l];
            t2[l] = a0 * L->me[0][l] + a1_ * L->me[1][l] + a2_ * L->me[2][l] + a3 * L->me[3][l];
        }
    } else {
        for (int l = 0; l < LANES; l++) {
            double a0 = L->a[0][l], a1_ = L->a[1][l], a2_ = L->a[2][l], a3 = L->a[3][l];
            t1[l] = a0 * k->s[0] + a1_ * k->s[1] + a2_ * k->s[2] + a3 * k->s[3];
            t2[l] = a0 * k->e[0] + a1_ * k->e[1] + a2_ * k->e[2] + a3 * k->e[3];
        }
    }
    for (int m = 0; m < 4; m++)
        for (int l = 0; l < LANES; l++)
            L->a[m][l] += (L->g[m][l] - L->a[m][l]) * L->r[m][l];
    /* Stage 1's elbow trig: in full, or in the fast kernel carried from the last step. */
    if (!k->fast) {
        trig_lanes(k, L->q2, L->bc, L->bs);
    } else {
        for (int l = 0; l < LANES; l++) {
            if (L->anchor[l] <= 0) {
                trig_lane(k, L->q2[l], &L->bc[l], &L->bs[l]);
                L->anchor[l] = REANCHOR;
            }
            L->anchor[l]--;
        }
    }
    for (int l = 0; l < LANES; l++) {
        p1[l] = L->q1[l];
        p2[l] = L->q2[l];
        L->ec[l] = L->bc[l];
        L->es[l] = L->bs[l];
    }
    accel_lanes(k, L, L->q1, L->q2, L->w1, L->w2, t1, t2, a1, a2, loaded);
    for (int l = 0; l < LANES; l++) {
        v1[l] = L->w1[l] + k->h * a1[l];
        v2[l] = L->w2[l] + k->h * a2[l];
        L->qs[l] = L->q2[l] + k->h * L->w2[l];
        L->ds[l] = k->h * L->w2[l];
        qa[l] = L->q1[l] + k->h * L->w1[l];
    }
    elbow_lanes(k, L);
    accel_lanes(k, L, qa, L->qs, v1, v2, t1, t2, b1, b2, loaded);
    for (int l = 0; l < LANES; l++) {
        u1[l] = L->w1[l] + k->h * b1[l];
        u2[l] = L->w2[l] + k->h * b2[l];
        L->qs[l] = L->q2[l] + k->h * v2[l];
        L->ds[l] = k->h * v2[l];
        qa[l] = L->q1[l] + k->h * v1[l];
    }
    elbow_lanes(k, L);
    accel_lanes(k, L, qa, L->qs, u1, u2, t1, t2, c1, c2, loaded);
    for (int l = 0; l < LANES; l++) {
        z1[l] = L->w1[l] + k->dt * c1[l];
        z2[l] = L->w2[l] + k->dt * c2[l];
        L->qs[l] = L->q2[l] + k->dt * u2[l];
        L->ds[l] = k->dt * u2[l];
        qa[l] = L->q1[l] + k->dt * u1[l];
    }
    elbow_lanes(k, L);
    accel_lanes(k, L, qa, L->qs, z1, z2, t1, t2, d1, d2, loaded);
    int out = 0;
    for (int l = 0; l < LANES; l++) {
        const double w1 = L->w1[l], w2 = L->w2[l];
        const double q1 = p1[l] + k->k * (w1 + z1[l] + 2.0 * (v1[l] + u1[l]));
        const double q2 = p2[l] + k->k * (w2 + z2[l] + 2.0 * (v2[l] + u2[l]));
        L->w1[l] = w1 + k->k * (a1[l] + d1[l] + 2.0 * (b1[l] + c1[l]));
        L->w2[l] = w2 + k->k * (a2[l] + d2[l] + 2.0 * (b2[l] + c2[l]));
        L->q1[l] = q1;
        L->q2[l] = q2;
        L->s[l]++;
        /* A lower bound on the hand's distance from the disc, lowered by a bound on its move. */
        L->sl[l] -= fabs(q1 - p1[l]) * k->reach1 + fabs(q2 - p2[l]) * k->reach2;
        out |= L->sl[l] < 0.0;
    }
    if (loaded && k->limit < INFINITY) {
        /* variant.guarded's test (NaN fails it too). No guard (noise alone): a state gone non-finite runs on, as
         * the plain step's, to the batch's NonFiniteStateError, as the single game's. */
        const double lim = k->limit;
        for (int l = 0; l < LANES; l++) {
            const double w1 = L->w1[l], w2 = L->w2[l];
            L->run[l] = !(-lim <= w1 && w1 <= lim && -lim <= w2 && w2 <= lim);
            out |= L->run[l];
        }
    }
    if (k->fast) {
        /* The next step's elbow trig: this one's turned by the step's change of q2 (``turned``); where the
         * series does not hold, the next step computes it in full. */
        for (int l = 0; l < LANES; l++)
            L->ds[l] = L->q2[l] - p2[l];
        for (int l = 0; l < LANES; l++) {
            const double delta = L->ds[l], d2_ = delta * delta;
            const double c = 1.0 + d2_ * (-0.5 + d2_ * (1.0 / 24.0 + d2_ * (-1.0 / 720.0 + d2_ * (1.0 / 40320.0))));
            const double s = delta * (1.0 + d2_ * (-1.0 / 6.0 + d2_ * (1.0 / 120.0 + d2_ * (-1.0 / 5040.0
                                                                                         + d2_ * (1.0 / 362880.0)))));
            const int ok = d2_ <= k->limit2;
            const double nc = L->bc[l] * c - L->bs[l] * s, ns = L->bs[l] * c + L->bc[l] * s;
            L->bc[l] = ok ? nc : L->bc[l];
            L->bs[l] = ok ? ns : L->bs[l];
            L->ok[l] = ok;
        }
        for (int l = 0; l < LANES; l++)
            if (!L->ok[l])
                L->anchor[l] = 0;
    }
    return out;
}

#endif
