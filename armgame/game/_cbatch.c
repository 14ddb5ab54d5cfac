/* The batch's loop (``_ckernel.run``): many games, each from its step to its halt, with its muscle
 * commands applied at their steps, stopped early when its hand may be on its target.
 *
 * Two loops compute the same thing. ``run_lanes`` steps LANES games side by side, one array per
 * quantity with a game per element (structure of arrays), so that every arithmetic line is one loop
 * over the lanes that the compiler turns into vector instructions (SSE2's two doubles, AVX2's four
 * where the CPU has it: ``LANES_CLONES``); a lane whose game ends takes the next game, so the lanes
 * stay full whatever the games' lengths. ``run_scalar`` runs one game at a time (the loop before
 * the lanes; the arm with gravity, whose cos q1 would need the C library in every stage, runs it).
 *
 * Why the lanes equal the single session bit for bit: vectorising across games changes no game's
 * operations or their order, only how many games one instruction serves. Addition, multiplication,
 * division and sqrt are correctly rounded IEEE operations whether scalar or vector, the build turns
 * off contraction (no fused multiply-add is formed from a * b + c) and fast-math (no reassociation),
 * and the C library's sin and cos (or its sincos, where checked) are called for each lane as the
 * single session calls them: the exact kernel calls them four times a step, and at some 10 ns each
 * (their throughput here) they are its bound. The fast kernel (``fast``) needs them once in 32 steps
 * and at a hand's check, so it is arithmetic only, and the lanes make it several times faster.
 */
#include "_ckernel.h"

/* Games side by side. A step is a chain of four dependent stages, each waiting on a divide (13 cycles)
 * and its series, so the lanes are there to hide latency as much as to fill a register: the fast kernel
 * ran 65 M arm-steps/s with 8 lanes, 78 M with 16 and 77 M with 32 (benchmarks/kernel_speed.py). */
#define LANES 16

/* Where the compiler and platform can build one function for several instruction sets and pick
 * the one the CPU has when the module loads (GCC and Clang on x86-64 Linux: an ifunc), the lanes'
 * step is built for AVX2 and for the baseline (SSE2). Elsewhere (MSVC, macOS, ARM's NEON is
 * baseline) it is built once for the baseline. Either way the same IEEE operations in the same
 * order: the results do not depend on which runs. */
#if defined(__x86_64__) && defined(__linux__) && defined(__has_attribute)
#if __has_attribute(target_clones)
#define LANES_CLONES __attribute__((target_clones("avx2", "default")))
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

/* A call's arrays and constants (the arguments of ``run``, checked). */
typedef struct {
    Arm arm;
    int fast;
    Py_ssize_t n;
    double *x, *act, *goal, *rate, *slack;
    const double *tx, *ty;
    int64_t *steps, *cursor;
    const int64_t *halt, *ev_end, *ev_step, *ev_muscle;
    const double *ev_goal, *ev_rate;
    uint8_t *flags;
    double *trig;   /* (6, n): cos q1, sin q1, cos(q1 + q2), sin(q1 + q2), q1, q2 after a game's last step, or NULL */
    double dt, h, k, l1, l2, radius, near, reach1, reach2, limit2;
    double s[4], e[4];
} Batch;

/* The hand's trig of game i, for the caller's observations (the single session's cos and sin), with the
 * angles it is of: the caller knows it current while they are the game's. */
static inline void write_trig(const Batch *B, Py_ssize_t i, double q1, double q2)
{
    if (B->trig == NULL)
        return;
    const Py_ssize_t n = B->n;
    double sa, ca, sb, cb;
    sin_cos(q1, &sa, &ca);
    sin_cos(q1 + q2, &sb, &cb);
    B->trig[i] = ca;
    B->trig[n + i] = sa;
    B->trig[2 * n + i] = cb;
    B->trig[3 * n + i] = sb;
    B->trig[4 * n + i] = q1;
    B->trig[5 * n + i] = q2;
}

/* One game at a time: the loop the lanes replaced, kept for the arm with gravity and as their reference
 * (``run(..., lanes=False)``). */
static Py_ssize_t run_scalar(const Batch *B)
{
    const Arm arm = B->arm;
    const int fast = B->fast;
    const Py_ssize_t n = B->n;
    double *x = B->x;
    const double dt = B->dt, h = B->h, k = B->k, l1 = B->l1, l2 = B->l2, radius = B->radius, near = B->near;
    const double reach1 = B->reach1, reach2 = B->reach2, limit2 = B->limit2;
    Py_ssize_t flagged = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        int64_t s = B->steps[i], c = B->cursor[i];
        const int64_t stop = B->halt[i], end = B->ev_end[i];
        B->flags[i] = 0;
        if (s >= stop && (c >= end || B->ev_step[c] > s))
            continue;
        double q1 = x[i], q2 = x[n + i], w1 = x[2 * n + i], w2 = x[3 * n + i];
        double bc = 0.0, bs = 0.0;  /* the fast kernel's b cos q2, b sin q2, carried from step to step */
        int anchor = 0;  /* steps left before they are computed in full again; none at a game's start */
        double a[4], g[4], r[4];
        for (int m = 0; m < 4; m++) {
            a[m] = B->act[m * n + i];
            g[m] = B->goal[m * n + i];
            r[m] = B->rate[m * n + i];
        }
        double sl = B->slack[i];
        const double x0 = B->tx[i], y0 = B->ty[i];
        for (;;) {
            while (c < end && B->ev_step[c] <= s) {
                g[B->ev_muscle[c]] = B->ev_goal[c];
                r[B->ev_muscle[c]] = B->ev_rate[c];
                c++;
            }
            if (s >= stop)
                break;
            /* GameSession._advance: torque from the activations, then the muscles step. */
            const double t1 = a[0] * B->s[0] + a[1] * B->s[1] + a[2] * B->s[2] + a[3] * B->s[3];
            const double t2 = a[0] * B->e[0] + a[1] * B->e[1] + a[2] * B->e[2] + a[3] * B->e[3];
            for (int m = 0; m < 4; m++)
                a[m] += (g[m] - a[m]) * r[m];
            /* integrators._rk4 */
            const double p1 = q1, p2 = q2;
            /* Stage 1's elbow trig: in full, or in the fast kernel carried from the last step. */
            if (!fast || anchor <= 0) {
                double sn, cs;
                sin_cos(q2, &sn, &cs);
                bc = arm.b * cs;
                bs = arm.b * sn;
                anchor = REANCHOR;
            }
            anchor--;
            double a1, a2, b1, b2, c1, c2, d1, d2, ec, es;
            accel_trig(&arm, q1, q2, bc, bs, w1, w2, t1, t2, &a1, &a2);
            const double v1 = w1 + h * a1;
            const double v2 = w2 + h * a2;
            const double q2b = q2 + h * w2;
            elbow(&arm, fast, q2b, h * w2, bc, bs, limit2, &ec, &es);
            accel_trig(&arm, q1 + h * w1, q2b, ec, es, v1, v2, t1, t2, &b1, &b2);
            const double u1 = w1 + h * b1;
            const double u2 = w2 + h * b2;
            const double q2c = q2 + h * v2;
            elbow(&arm, fast, q2c, h * v2, bc, bs, limit2, &ec, &es);
            accel_trig(&arm, q1 + h * v1, q2c, ec, es, u1, u2, t1, t2, &c1, &c2);
            const double z1 = w1 + dt * c1;
            const double z2 = w2 + dt * c2;
            const double q2d = q2 + dt * u2;
            elbow(&arm, fast, q2d, dt * u2, bc, bs, limit2, &ec, &es);
            accel_trig(&arm, q1 + dt * u1, q2d, ec, es, z1, z2, t1, t2, &d1, &d2);
            q1 = p1 + k * (w1 + z1 + 2.0 * (v1 + u1));
            q2 = p2 + k * (w2 + z2 + 2.0 * (v2 + u2));
            const double n1 = w1 + k * (a1 + d1 + 2.0 * (b1 + c1));
            const double n2 = w2 + k * (a2 + d2 + 2.0 * (b2 + c2));
            w1 = n1;
            w2 = n2;
            s++;
            /* The next step's elbow trig: this one's turned by the step's change of q2. */
            if (fast && !turned(bc, bs, q2 - p2, limit2, &bc, &bs))
                anchor = 0;
            /* A lower bound on the hand's distance from the disc, lowered by a bound on its move;
             * measured only when it runs out (see NumpyKernel.run). */
            sl -= fabs(q1 - p1) * reach1 + fabs(q2 - p2) * reach2;
            if (sl < 0.0) {
                double sa, ca, sb, cb;
                sin_cos(q1, &sa, &ca);
                sin_cos(q1 + q2, &sb, &cb);
                const double dx = l1 * ca + l2 * cb - x0;
                const double dy = l1 * sa + l2 * sb - y0;
                const double d2h = dx * dx + dy * dy;
                sl = sqrt(d2h) - radius - 1e-9;
                if (d2h <= near) {
                    B->flags[i] = 1;
                    flagged++;
                    break;
                }
            }
        }
        x[i] = q1;
        x[n + i] = q2;
        x[2 * n + i] = w1;
        x[3 * n + i] = w2;
        for (int m = 0; m < 4; m++) {
            B->act[m * n + i] = a[m];
            B->goal[m * n + i] = g[m];
            B->rate[m * n + i] = r[m];
        }
        B->slack[i] = sl;
        B->steps[i] = s;
        B->cursor[i] = c;
        write_trig(B, i, q1, q2);
    }
    return flagged;
}

/* The lanes' state: one array per quantity, a game per element. */
typedef struct {
    double q1[LANES], q2[LANES], w1[LANES], w2[LANES];
    double a[4][LANES], g[4][LANES], r[4][LANES];
    double sl[LANES], x0[LANES], y0[LANES];
    double bc[LANES], bs[LANES];        /* stage 1's b cos q2, b sin q2 (the fast kernel carries them) */
    double qs[LANES], ds[LANES];        /* a stage's elbow angle and, in the fast kernel, its increment */
    double ec[LANES], es[LANES];        /* that stage's b cos and b sin of it */
    int ok[LANES];                      /* the fast kernel's series held for the lane (else: in full) */
    int anchor[LANES];
    int64_t s[LANES], stop[LANES], next[LANES], c[LANES], end[LANES];
    Py_ssize_t game[LANES];             /* the lane's game, or -1 */
} Lanes;

/* The step's constants, the same for every lane. */
typedef struct {
    double b, d, det0, amd, k1, k2, dt, h, k, limit2, reach1, reach2;
    double s[4], e[4];
    int damping, fast;
} Step;

/* TwoJointArm's accel_unforced or accel_with_damping (``accel_trig``) for every lane, the lanes' stage
 * angles in q1, q2, speeds in w1, w2, elbow trig in L->ec, L->es. */
LANES_INLINE void accel_lanes(const Step *k, const Lanes *L, const double *q1, const double *w1,
                               const double *w2, const double *t1, const double *t2, double *o1, double *o2)
{
    (void)q1;
    for (int l = 0; l < LANES; l++) {
        const double bc = L->ec[l], h = L->es[l];
        const double m12 = k->d + bc;
        double f1 = t1[l] + h * (w1[l] + w1[l] + w2[l]) * w2[l];
        double f2 = t2[l] - h * w1[l] * w1[l];
        if (k->damping) {
            f1 = f1 - k->k1 * w1[l];
            f2 = f2 - k->k2 * w2[l];
        }
        const double r = 1.0 / (k->det0 - bc * bc);
        o1[l] = (k->d * f1 - m12 * f2) * r;
        o2[l] = ((m12 + k->amd + bc) * f2 - m12 * f1) * r;
    }
}

/* A stage's elbow trig for every lane: in full from the C library (the exact kernel, and the fast
 * kernel's lanes whose increment is past the series' range), else turned from stage 1's by the series. */
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
    for (int l = 0; l < LANES; l++) {
        if (!k->fast || !L->ok[l]) {
            double sn, cs;
            sin_cos(L->qs[l], &sn, &cs);
            L->ec[l] = k->b * cs;
            L->es[l] = k->b * sn;
        }
    }
}

/* One RK4 step of every lane (``run_scalar``'s step, lane by lane): the muscles, the four stages, the
 * fast kernel's trig carried to the next step, and the slack. Returns whether some lane's slack ran out. */
LANES_CLONES
static int step_lanes(const Step *k, Lanes *L)
{
    double t1[LANES], t2[LANES], p1[LANES], p2[LANES];
    double a1[LANES], a2[LANES], b1[LANES], b2[LANES], c1[LANES], c2[LANES], d1[LANES], d2[LANES];
    double v1[LANES], v2[LANES], u1[LANES], u2[LANES], z1[LANES], z2[LANES], qa[LANES];
    for (int l = 0; l < LANES; l++) {
        double a0 = L->a[0][l], a1_ = L->a[1][l], a2_ = L->a[2][l], a3 = L->a[3][l];
        t1[l] = a0 * k->s[0] + a1_ * k->s[1] + a2_ * k->s[2] + a3 * k->s[3];
        t2[l] = a0 * k->e[0] + a1_ * k->e[1] + a2_ * k->e[2] + a3 * k->e[3];
    }
    for (int m = 0; m < 4; m++)
        for (int l = 0; l < LANES; l++)
            L->a[m][l] += (L->g[m][l] - L->a[m][l]) * L->r[m][l];
    /* Stage 1's elbow trig: in full, or in the fast kernel carried from the last step. */
    for (int l = 0; l < LANES; l++) {
        if (!k->fast || L->anchor[l] <= 0) {
            double sn, cs;
            sin_cos(L->q2[l], &sn, &cs);
            L->bc[l] = k->b * cs;
            L->bs[l] = k->b * sn;
            L->anchor[l] = REANCHOR;
        }
        L->anchor[l]--;
    }
    for (int l = 0; l < LANES; l++) {
        p1[l] = L->q1[l];
        p2[l] = L->q2[l];
        L->ec[l] = L->bc[l];
        L->es[l] = L->bs[l];
    }
    accel_lanes(k, L, L->q1, L->w1, L->w2, t1, t2, a1, a2);
    for (int l = 0; l < LANES; l++) {
        v1[l] = L->w1[l] + k->h * a1[l];
        v2[l] = L->w2[l] + k->h * a2[l];
        L->qs[l] = L->q2[l] + k->h * L->w2[l];
        L->ds[l] = k->h * L->w2[l];
        qa[l] = L->q1[l] + k->h * L->w1[l];
    }
    elbow_lanes(k, L);
    accel_lanes(k, L, qa, v1, v2, t1, t2, b1, b2);
    for (int l = 0; l < LANES; l++) {
        u1[l] = L->w1[l] + k->h * b1[l];
        u2[l] = L->w2[l] + k->h * b2[l];
        L->qs[l] = L->q2[l] + k->h * v2[l];
        L->ds[l] = k->h * v2[l];
        qa[l] = L->q1[l] + k->h * v1[l];
    }
    elbow_lanes(k, L);
    accel_lanes(k, L, qa, u1, u2, t1, t2, c1, c2);
    for (int l = 0; l < LANES; l++) {
        z1[l] = L->w1[l] + k->dt * c1[l];
        z2[l] = L->w2[l] + k->dt * c2[l];
        L->qs[l] = L->q2[l] + k->dt * u2[l];
        L->ds[l] = k->dt * u2[l];
        qa[l] = L->q1[l] + k->dt * u1[l];
    }
    elbow_lanes(k, L);
    accel_lanes(k, L, qa, z1, z2, t1, t2, d1, d2);
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

/* Game i's arrays into lane l; no game (i < 0): a still arm that never needs attention. */
static void load_lane(const Batch *B, Lanes *L, int l, Py_ssize_t i)
{
    const Py_ssize_t n = B->n;
    L->game[l] = i;
    L->anchor[l] = 0;
    L->bc[l] = L->bs[l] = 0.0;
    if (i < 0) {
        L->q1[l] = L->q2[l] = L->w1[l] = L->w2[l] = 0.0;
        for (int m = 0; m < 4; m++)
            L->a[m][l] = L->g[m][l] = L->r[m][l] = 0.0;
        L->sl[l] = INFINITY;
        L->x0[l] = L->y0[l] = 0.0;
        L->s[l] = 0;
        L->stop[l] = L->next[l] = INT64_MAX;
        L->c[l] = L->end[l] = 0;
        return;
    }
    L->q1[l] = B->x[i];
    L->q2[l] = B->x[n + i];
    L->w1[l] = B->x[2 * n + i];
    L->w2[l] = B->x[3 * n + i];
    for (int m = 0; m < 4; m++) {
        L->a[m][l] = B->act[m * n + i];
        L->g[m][l] = B->goal[m * n + i];
        L->r[m][l] = B->rate[m * n + i];
    }
    L->sl[l] = B->slack[i];
    L->x0[l] = B->tx[i];
    L->y0[l] = B->ty[i];
    L->s[l] = B->steps[i];
    L->stop[l] = B->halt[i];
    L->c[l] = B->cursor[i];
    L->end[l] = B->ev_end[i];
}

/* Lane l's game back into the arrays. */
static void store_lane(const Batch *B, const Lanes *L, int l)
{
    const Py_ssize_t n = B->n, i = L->game[l];
    B->x[i] = L->q1[l];
    B->x[n + i] = L->q2[l];
    B->x[2 * n + i] = L->w1[l];
    B->x[3 * n + i] = L->w2[l];
    for (int m = 0; m < 4; m++) {
        B->act[m * n + i] = L->a[m][l];
        B->goal[m * n + i] = L->g[m][l];
        B->rate[m * n + i] = L->r[m][l];
    }
    B->slack[i] = L->sl[l];
    B->steps[i] = L->s[l];
    B->cursor[i] = L->c[l];
    write_trig(B, i, L->q1[l], L->q2[l]);
}

/* The muscle commands due at lane l's step, then whether its game goes on (else the caller stores it);
 * sets the step of its next event or stop. */
static int due_lane(const Batch *B, Lanes *L, int l)
{
    int64_t c = L->c[l];
    const int64_t s = L->s[l], end = L->end[l];
    while (c < end && B->ev_step[c] <= s) {
        const int64_t m = B->ev_muscle[c];
        L->g[m][l] = B->ev_goal[c];
        L->r[m][l] = B->ev_rate[c];
        c++;
    }
    L->c[l] = c;
    if (s >= L->stop[l])
        return 0;
    L->next[l] = c < end && B->ev_step[c] < L->stop[l] ? B->ev_step[c] : L->stop[l];
    return 1;
}

/* Lane l takes the next game with steps or commands due (from *queue on), or none. */
static void fill_lane(const Batch *B, Lanes *L, int l, Py_ssize_t *queue)
{
    while (*queue < B->n) {
        const Py_ssize_t i = (*queue)++;
        const int64_t s = B->steps[i], c = B->cursor[i];
        B->flags[i] = 0;
        if (s >= B->halt[i] && (c >= B->ev_end[i] || B->ev_step[c] > s))
            continue;
        load_lane(B, L, l, i);
        if (due_lane(B, L, l))
            return;
        store_lane(B, L, l);
    }
    load_lane(B, L, l, -1);
}

/* The games of the lanes back into the arrays, as ``store_lane`` for each, where they are LANES
 * consecutive games (the lockstep of a vector env: every game stops at the same step): one contiguous
 * copy a quantity, which the compiler vectorises, instead of LANES scattered ones. */
static void store_block(const Batch *B, const Lanes *L)
{
    const Py_ssize_t n = B->n, i = L->game[0];
    for (int l = 0; l < LANES; l++) {
        B->x[i + l] = L->q1[l];
        B->x[n + i + l] = L->q2[l];
        B->x[2 * n + i + l] = L->w1[l];
        B->x[3 * n + i + l] = L->w2[l];
        B->slack[i + l] = L->sl[l];
        B->steps[i + l] = L->s[l];
        B->cursor[i + l] = L->c[l];
    }
    for (int m = 0; m < 4; m++) {
        for (int l = 0; l < LANES; l++) {
            B->act[m * n + i + l] = L->a[m][l];
            B->goal[m * n + i + l] = L->g[m][l];
            B->rate[m * n + i + l] = L->r[m][l];
        }
    }
    for (int l = 0; l < LANES; l++)
        write_trig(B, i + l, L->q1[l], L->q2[l]);
}

/* The next LANES games into the lanes as ``fill_lane`` would take them, where each has steps to run:
 * contiguous copies (see ``store_block``). Returns 0, touching nothing, where they are not so. */
static int fill_block(const Batch *B, Lanes *L, Py_ssize_t *queue)
{
    const Py_ssize_t n = B->n, i = *queue;
    if (n - i < LANES)
        return 0;
    for (int l = 0; l < LANES; l++)
        if (B->steps[i + l] >= B->halt[i + l])
            return 0;
    for (int l = 0; l < LANES; l++) {
        B->flags[i + l] = 0;
        L->game[l] = i + l;
        L->anchor[l] = 0;
        L->bc[l] = L->bs[l] = 0.0;
        L->q1[l] = B->x[i + l];
        L->q2[l] = B->x[n + i + l];
        L->w1[l] = B->x[2 * n + i + l];
        L->w2[l] = B->x[3 * n + i + l];
        L->sl[l] = B->slack[i + l];
        L->x0[l] = B->tx[i + l];
        L->y0[l] = B->ty[i + l];
        L->s[l] = B->steps[i + l];
        L->stop[l] = B->halt[i + l];
        L->c[l] = B->cursor[i + l];
        L->end[l] = B->ev_end[i + l];
    }
    for (int m = 0; m < 4; m++) {
        for (int l = 0; l < LANES; l++) {
            L->a[m][l] = B->act[m * n + i + l];
            L->g[m][l] = B->goal[m * n + i + l];
            L->r[m][l] = B->rate[m * n + i + l];
        }
    }
    *queue = i + LANES;
    for (int l = 0; l < LANES; l++)
        due_lane(B, L, l);  /* each has steps before its halt: none stops here */
    return 1;
}

/* Steps the other lanes may still run while a freed lane waits for them (see ``run_lanes``). */
#define WAIT_STEPS 16

/* The lanes: ``run_scalar``'s games, LANES at a time. Returns the games flagged. */
static Py_ssize_t run_lanes(const Batch *B)
{
    Lanes L;
    const Arm *arm = &B->arm;
    const Step k = {arm->b, arm->d, arm->det0, arm->amd, arm->k1, arm->k2, B->dt, B->h, B->k, B->limit2,
                    B->reach1, B->reach2, {B->s[0], B->s[1], B->s[2], B->s[3]},
                    {B->e[0], B->e[1], B->e[2], B->e[3]}, arm->mode == MODE_DAMPING, B->fast};
    Py_ssize_t queue = 0, flagged = 0;
    int busy = 0;
    for (int l = 0; l < LANES; l++) {
        fill_lane(B, &L, l, &queue);
        busy += L.game[l] >= 0;
    }
    while (busy) {
        /* Steps every lane can run before one needs its commands or its stop. */
        int64_t run = INT64_MAX;
        for (int l = 0; l < LANES; l++)
            if (L.game[l] >= 0 && L.next[l] - L.s[l] < run)
                run = L.next[l] - L.s[l];
        int short_ = 0;
        while (run > 0) {
            run--;
            if (step_lanes(&k, &L)) {
                short_ = 1;
                break;
            }
        }
        int done[LANES], finished = 0;
        for (int l = 0; l < LANES; l++) {
            const Py_ssize_t i = L.game[l];
            done[l] = 0;
            if (i < 0)
                continue;
            if (short_ && L.sl[l] < 0.0) {
                /* The slack ran out: measure the hand (as the single session does, on its floats). */
                double sa, ca, sb, cb;
                sin_cos(L.q1[l], &sa, &ca);
                sin_cos(L.q1[l] + L.q2[l], &sb, &cb);
                const double dx = B->l1 * ca + B->l2 * cb - L.x0[l];
                const double dy = B->l1 * sa + B->l2 * sb - L.y0[l];
                const double d2h = dx * dx + dy * dy;
                L.sl[l] = sqrt(d2h) - B->radius - 1e-9;
                if (d2h <= B->near) {
                    B->flags[i] = 1;
                    flagged++;
                    done[l] = 1;
                    finished++;
                    continue;
                }
            }
            if (L.s[l] >= L.next[l] && !due_lane(B, &L, l)) {
                done[l] = 1;
                finished++;
            }
        }
        if (!finished)
            continue;
        /* Every lane's game done at once, and consecutive games: the lockstep's block copies. */
        int block = finished == LANES;
        for (int l = 1; block && l < LANES; l++)
            block = L.game[l] == L.game[0] + l;
        if (block)
            store_block(B, &L);
        int64_t longest = 0;  /* the most steps a lane still running has before its stop */
        for (int l = 0; l < LANES; l++) {
            if (done[l]) {
                if (!block)
                    store_lane(B, &L, l);
                load_lane(B, &L, l, -1);
            } else if (L.game[l] >= 0 && L.stop[l] - L.s[l] > longest) {
                longest = L.stop[l] - L.s[l];
            }
        }
        if (longest == 0 && fill_block(B, &L, &queue))
            continue;
        /* A lane freed while the others are about to stop (a hit in a vector env's few steps) waits for
         * them, so that the lanes fill as a block again; otherwise it takes the next game now. */
        busy = 0;
        for (int l = 0; l < LANES; l++) {
            if (L.game[l] < 0 && (longest == 0 || longest > WAIT_STEPS))
                fill_lane(B, &L, l, &queue);
            busy += L.game[l] >= 0;
        }
    }
    return flagged;
}

const char armgame_run_doc[] =
"run(params, mode, fast, n, x, act, goal, rate, slack, tx, ty, steps, halt, cursor, ev_end, ev_step, ev_muscle,\n"
"    ev_goal, ev_rate, flags, trig, lanes) -> int\n\n"
"Step every game i from steps[i] up to halt[i], applying its muscle events on the way, and\n"
"stop it early after a step that leaves its hand near its target (flags[i] = 1). Returns how\n"
"many games were flagged. Arrays: x (4+, n) float64 rows q1 q2 w1 w2; act, goal, rate (4, n);\n"
"slack, tx, ty (n,); steps, halt, cursor, ev_end (n,) int64; game i's events are\n"
"cursor[i]:ev_end[i] of ev_step (int64), ev_muscle (int64, 0-3), ev_goal, ev_rate (float64),\n"
"sorted by step; an event at step s applies before the step from s; flags (n,) uint8.\n"
"trig (6, n) float64 or None: for every game stepped, cos q1, sin q1, cos(q1 + q2), sin(q1 + q2)\n"
"after its last step (the C library's) and the q1, q2 they are of.\n"
"With fast true, RK4's elbow trig comes by angle addition (the numpy fast kernel's method):\n"
"round-off, not bit for bit. lanes: step several games side by side (the same results; false: one\n"
"at a time, the reference). Refused before any step (ValueError): params not finite or dt not positive,\n"
"steps or halt outside 0 to the steps of a 24 h game at dt, a command's goal or rate not finite.";

PyObject *armgame_run(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *obj[18];
    int mode, fast, lanes;
    Py_ssize_t n;
    if (!PyArg_ParseTuple(args, "OipnOOOOOOOOOOOOOOOOOp", &obj[0], &mode, &fast, &n, &obj[1], &obj[2], &obj[3],
                          &obj[4], &obj[5], &obj[6], &obj[7], &obj[8], &obj[9], &obj[10], &obj[11], &obj[12],
                          &obj[13], &obj[14], &obj[15], &obj[16], &obj[17], &lanes))
        return NULL;
    /* n bounded first: every size below is n times at most 4 * 8 bytes, which must not overflow (a wrapped
       n * D of 0 would divide by zero below: SIGFPE, the process gone). */
    if (mode < MODE_UNFORCED || mode > MODE_GRAVITY || n < 1 || n > PY_SSIZE_T_MAX / (4 * (Py_ssize_t)sizeof(double))) {
        PyErr_Format(PyExc_ValueError, "mode %d, %zd games: expected mode 0, 1 or 2 and at least one game, at most %zd", mode,
                     n, PY_SSIZE_T_MAX / (4 * (Py_ssize_t)sizeof(double)));
        return NULL;
    }
    const int with_trig = obj[17] != Py_None;
    Buf b[18];
    memset(b, 0, sizeof b);
    PyObject *result = NULL;
    const Py_ssize_t D = sizeof(double), I = sizeof(int64_t);
    /* x (rows q1 q2 w1 w2) may carry scratch rows after the state's four. */
    if (get(obj[0], &b[0], P_COUNT, D, 0, "params") < 0 || get(obj[1], &b[1], -1, D, 1, "x") < 0)
        goto done;
    if (b[1].view.len % (n * D) || b[1].view.len / (n * D) < 4) {
        PyErr_Format(PyExc_ValueError, "x: %zd bytes, expected (rows >= 4, %zd) float64", b[1].view.len, n);
        goto done;
    }
    if (get(obj[2], &b[2], 4 * n, D, 1, "act") < 0 || get(obj[3], &b[3], 4 * n, D, 1, "goal") < 0
        || get(obj[4], &b[4], 4 * n, D, 1, "rate") < 0 || get(obj[5], &b[5], n, D, 1, "slack") < 0
        || get(obj[6], &b[6], n, D, 0, "tx") < 0 || get(obj[7], &b[7], n, D, 0, "ty") < 0
        || get(obj[8], &b[8], n, I, 1, "steps") < 0 || get(obj[9], &b[9], n, I, 0, "halt") < 0
        || get(obj[10], &b[10], n, I, 1, "cursor") < 0 || get(obj[11], &b[11], n, I, 0, "ev_end") < 0
        || get(obj[12], &b[12], -1, I, 0, "ev_step") < 0)
        goto done;
    const Py_ssize_t events = b[12].view.len / I;
    if (get(obj[13], &b[13], events, I, 0, "ev_muscle") < 0 || get(obj[14], &b[14], events, D, 0, "ev_goal") < 0
        || get(obj[15], &b[15], events, D, 0, "ev_rate") < 0 || get(obj[16], &b[16], n, 1, 1, "flags") < 0)
        goto done;
    if (with_trig && get(obj[17], &b[17], 6 * n, D, 1, "trig") < 0)
        goto done;

    const double *p = b[0].view.buf;
    if (check_params("run", p, 1) < 0)
        goto done;
    Batch B = {
        .arm = {p[P_B], p[P_D], p[P_DET0], p[P_AMD], p[P_G1], p[P_G2], p[P_K1], p[P_K2], mode},
        .fast = fast, .n = n,
        .x = b[1].view.buf, .act = b[2].view.buf, .goal = b[3].view.buf, .rate = b[4].view.buf,
        .slack = b[5].view.buf, .tx = b[6].view.buf, .ty = b[7].view.buf,
        .steps = b[8].view.buf, .halt = b[9].view.buf, .cursor = b[10].view.buf, .ev_end = b[11].view.buf,
        .ev_step = b[12].view.buf, .ev_muscle = b[13].view.buf, .ev_goal = b[14].view.buf,
        .ev_rate = b[15].view.buf, .flags = b[16].view.buf,
        .trig = with_trig ? b[17].view.buf : NULL,
        .dt = p[P_DT], .h = p[P_H], .k = p[P_K], .l1 = p[P_L1], .l2 = p[P_L2], .radius = p[P_RADIUS],
        .near = p[P_NEAR], .reach1 = p[P_REACH1], .reach2 = p[P_REACH2], .limit2 = p[P_LIMIT2],
        .s = {p[P_S0], p[P_S1], p[P_S2], p[P_S3]}, .e = {p[P_E0], p[P_E1], p[P_E2], p[P_E3]},
    };

    /* The work is bounded before it starts: cursors within the events, muscles 0-3, finite commands, and
     * every game's steps and halt from 0 to a game's most steps at this dt. */
    const double most = max_steps(p[P_DT]);
    for (Py_ssize_t i = 0; i < n; i++) {
        if (B.cursor[i] < 0 || B.cursor[i] > B.ev_end[i] || B.ev_end[i] > events) {
            PyErr_Format(PyExc_ValueError, "game %zd: events %lld:%lld of %zd", i, (long long)B.cursor[i],
                         (long long)B.ev_end[i], events);
            goto done;
        }
        if (B.steps[i] < 0 || B.halt[i] < 0 || (double)B.steps[i] > most || (double)B.halt[i] > most) {
            char message[200];  /* PyErr_Format has no %g */
            snprintf(message, sizeof message,
                     "run: game %zd: steps %lld, halt %lld: expected 0 to %.15g (%g s at dt %g)", i,
                     (long long)B.steps[i], (long long)B.halt[i], most, MAX_GAME_SECONDS, p[P_DT]);
            PyErr_SetString(PyExc_ValueError, message);
            goto done;
        }
    }
    for (Py_ssize_t e = 0; e < events; e++) {
        if (B.ev_muscle[e] < 0 || B.ev_muscle[e] > 3) {
            PyErr_Format(PyExc_ValueError, "event %zd: muscle %lld", e, (long long)B.ev_muscle[e]);
            goto done;
        }
        if (!isfinite(B.ev_goal[e]) || !isfinite(B.ev_rate[e])) {
            PyErr_Format(PyExc_ValueError, "event %zd: its goal or rate is not finite", e);
            goto done;
        }
    }
    Py_ssize_t flagged;
    Py_BEGIN_ALLOW_THREADS
    flagged = lanes && mode != MODE_GRAVITY ? run_lanes(&B) : run_scalar(&B);
    Py_END_ALLOW_THREADS
    result = PyLong_FromSsize_t(flagged);
done:
    release(b, 18);
    return result;
}
