/* The game's hot loop, compiled: muscles, RK4 and the hand's slack for many games (``run``), and
 * the single session's loop for one game (``game_steps``), one RK4 step (``rk4_step``, the lab's) and
 * one arm's run of RK4 steps under given torques (``rk4_run``, the benchmark's table).
 *
 * Why C: a batch of a thousand games in numpy pays about 140 calls of call overhead per
 * physics step, and Python floats pay the interpreter per operation; here each game runs its
 * own steps in registers. Why it equals the single session bit for bit: every expression is
 * ``GameSession._advance``'s, ``integrators._rk4``'s and ``TwoJointArm``'s accel, with the same
 * IEEE double operations in the same order (C evaluates a + b + c as (a + b) + c, as Python
 * does), and ``cos``/``sin`` are the C library's, which is what Python's ``math`` calls. The
 * build (setup.py) turns off floating-point contraction, so no multiply-add is fused, and the
 * builtin sin and cos, so the compiler cannot merge them into a ``sincos`` of its own choosing;
 * the file calls glibc's sincos itself only where it has checked it (``sin_cos`` below).
 *
 * With ``fast`` set, the elbow's cos and sin come by angle addition instead (the numpy fast
 * kernel's method, see batch/numpy_kernel.py): round-off, not bit for bit, and the batch says so.
 *
 * The kernel knows nothing of targets' rules: it stops a game whose hand may be on its target
 * (within a relative 1e-6 of the disc) and lets Python decide, with the single session's own
 * test and its ``GameRules``. See ``armgame/game/batch/compiled.py`` for the calling side.
 *
 * Every entry point refuses, before its loop, what no game of armgame's passes: params or values
 * that are not finite, and counts of steps outside a game's (0 to 24 h at its dt), so a bad call is
 * one ValueError, never NaN results or a loop that runs for as long as anyone waits. The checks cost
 * a call of one step about 10 ns (a bot calls once a step; params already found finite are not
 * checked again), a game nothing measurable (benchmarks/game_speed.py).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* Where the C library is glibc, whose sincos runs the very code of its sin and cos (one argument
 * reduction for both: a pair costs 11 ns here against 17), the elbow's and the hand's pairs come from
 * sincos. Nothing promises that elsewhere, so other libraries call sin and cos apart, and even glibc's
 * sincos is used only after the module's start has found it equal to sin and cos, bit for bit, on
 * angles from -1e6 to 1e6 (``SINCOS`` says whether it is used). */
#if defined(__GLIBC__)
extern void sincos(double x, double *s, double *c);
#endif
static int use_sincos = 0;

static inline void sin_cos(double x, double *s, double *c)
{
#if defined(__GLIBC__)
    if (use_sincos) {
        sincos(x, s, c);
        return;
    }
#endif
    *s = sin(x);
    *c = cos(x);
}

/* Whether sincos gives sin's and cos's bits on a spread of angles (small, game-sized and huge). */
static int sincos_agrees(void)
{
#if defined(__GLIBC__)
    uint64_t r = UINT64_C(88172645463325252);
    for (int i = 0; i < 3000; i++) {
        r ^= r << 13;
        r ^= r >> 7;
        r ^= r << 17;
        const double scale = i % 3 == 0 ? 1.0 : (i % 3 == 1 ? 40.0 : 2e6);
        const double x = ((double)(r >> 11) / 9007199254740992.0 - 0.5) * scale;
        double s, c;
        sincos(x, &s, &c);
        if (s != sin(x) || c != cos(x))
            return 0;
    }
    return 1;
#else
    return 0;
#endif
}

/* Layout of the ``params`` buffer (doubles), as compiled.py's ``CompiledKernel`` writes it. */
enum {
    P_DT, P_H, P_K, P_B, P_D, P_DET0, P_AMD, P_G1, P_G2, P_K1, P_K2,
    P_L1, P_L2, P_RADIUS, P_NEAR, P_REACH1, P_REACH2, P_LIMIT2,
    P_S0, P_S1, P_S2, P_S3, P_E0, P_E1, P_E2, P_E3,
    P_COUNT
};

/* The P_* names, for a message naming a parameter that is not finite. */
static const char *const PARAM_NAMES[P_COUNT] = {
    "dt", "h", "k", "b", "d", "det0", "amd", "g1", "g2", "k1", "k2",
    "l1", "l2", "radius", "near", "reach1", "reach2", "limit2",
    "s0", "s1", "s2", "s3", "e0", "e1", "e2", "e3",
};

/* The longest game GameConfig allows (time_limit <= 24 h), in seconds: no count of steps past it at the
 * params' dt is a game's, and refusing it bounds the work of a call before its loop (a halt of 2**62 ran
 * for as long as anyone waited). */
#define MAX_GAME_SECONDS 86400.0

/* Refuse, before any loop, params that are not finite (a NaN arm or dt made every result NaN), and a dt
 * that is not positive where ``counted`` (the loops of steps: their counts are bounded by it). */
static int check_params(const char *name, const double *p, int counted)
{
    for (int i = 0; i < P_COUNT; i++) {
        if (!isfinite(p[i])) {
            PyErr_Format(PyExc_ValueError, "%s: params %s is not finite", name, PARAM_NAMES[i]);
            return -1;
        }
    }
    if (counted && !(p[P_DT] > 0.0)) {
        PyErr_Format(PyExc_ValueError, "%s: params dt must be positive", name);
        return -1;
    }
    return 0;
}

/* The most steps a game may have at step dt (MAX_GAME_SECONDS of them, with one for rounding). */
static double max_steps(double dt)
{
    return MAX_GAME_SECONDS / dt + 1.0;
}

/* Which accel the single session uses (TwoJointArm._build_components). */
enum { MODE_UNFORCED = 0, MODE_DAMPING = 1, MODE_GRAVITY = 2 };

typedef struct {
    double b, d, det0, amd, g1, g2, k1, k2;
    int mode;
} Arm;

/* TwoJointArm's accel_unforced, accel_with_damping and accel_with_gravity_and_damping, given
 * bc = b cos q2 and h = b sin q2. */
static inline void accel_trig(const Arm *arm, double q1, double q2, double bc, double h, double w1, double w2,
                              double t1, double t2, double *o1, double *o2)
{
    double gc12 = 0.0, f1, f2;
    if (arm->mode == MODE_GRAVITY)
        gc12 = arm->g2 * cos(q1 + q2);
    double m12 = arm->d + bc;
    if (arm->mode == MODE_UNFORCED) {
        f1 = t1 + h * (w1 + w1 + w2) * w2;
        f2 = t2 - h * w1 * w1;
    } else if (arm->mode == MODE_DAMPING) {
        f1 = t1 + h * (w1 + w1 + w2) * w2 - arm->k1 * w1;
        f2 = t2 - h * w1 * w1 - arm->k2 * w2;
    } else {
        f1 = t1 + h * (w1 + w1 + w2) * w2 - arm->g1 * cos(q1) - gc12 - arm->k1 * w1;
        f2 = t2 - h * w1 * w1 - gc12 - arm->k2 * w2;
    }
    double r = 1.0 / (arm->det0 - bc * bc);
    *o1 = (arm->d * f1 - m12 * f2) * r;
    *o2 = ((m12 + arm->amd + bc) * f2 - m12 * f1) * r;
}

/* The fast kernel's elbow trig (batch.numpy_kernel's, there in numpy): b cos and b sin of q2 + delta
 * from those of q2 by angle addition, with cos and sin of the small delta from Taylor series
 * in delta^2 (the first dropped terms below 3e-17 within SERIES_LIMIT). Returns 0, leaving the
 * outputs alone, if |delta| is beyond the series' range. */
static inline int turned(double bc, double bs, double delta, double limit2, double *oc, double *os)
{
    const double d2 = delta * delta;
    if (!(d2 <= limit2))
        return 0;
    const double c = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * (1.0 / 40320.0))));
    const double s = delta * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (-1.0 / 5040.0
                                                                              + d2 * (1.0 / 362880.0)))));
    *oc = bc * c - bs * s;
    *os = bs * c + bc * s;
    return 1;
}

/* A stage's b cos q2 and b sin q2: in full (the exact kernel), or turned by delta from stage 1's
 * (bc, bs) in the fast kernel, in full there too if delta is beyond the series' range. */
static inline void elbow(const Arm *arm, int fast, double q2, double delta, double bc, double bs, double limit2,
                         double *oc, double *os)
{
    if (!fast || !turned(bc, bs, delta, limit2, oc, os)) {
        double sn, cs;
        sin_cos(q2, &sn, &cs);
        *oc = arm->b * cs;
        *os = arm->b * sn;
    }
}

/* Steps between full cos and sin of the elbow in the fast kernel (turned ones gather round-off). */
#define REANCHOR 32

typedef struct {
    Py_buffer view;
    int held;
} Buf;

static void release(Buf *bufs, int count)
{
    for (int i = 0; i < count; i++)
        if (bufs[i].held)
            PyBuffer_Release(&bufs[i].view);
}

/* Get a C-contiguous buffer of ``count`` items of ``itemsize`` bytes (any whole number of them if
 * ``count`` is -1), writable if asked. */
static int get(PyObject *obj, Buf *buf, Py_ssize_t count, Py_ssize_t itemsize, int writable, const char *name)
{
    int flags = PyBUF_C_CONTIGUOUS | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, &buf->view, flags) < 0)
        return -1;
    buf->held = 1;
    if (count < 0 ? buf->view.len % itemsize != 0 : buf->view.len != count * itemsize) {
        if (count < 0)
            PyErr_Format(PyExc_ValueError, "%s: %zd bytes, not items of %zd", name, buf->view.len, itemsize);
        else
            PyErr_Format(PyExc_ValueError, "%s: %zd bytes, expected %zd", name, buf->view.len, count * itemsize);
        return -1;
    }
    return 0;
}

PyDoc_STRVAR(run_doc,
"run(params, mode, fast, n, x, act, goal, rate, slack, tx, ty, steps, halt, cursor, ev_end, ev_step, ev_muscle,\n"
"    ev_goal, ev_rate, flags) -> int\n\n"
"Step every game i from steps[i] up to halt[i], applying its muscle events on the way, and\n"
"stop it early after a step that leaves its hand near its target (flags[i] = 1). Returns how\n"
"many games were flagged. Arrays: x (4+, n) float64 rows q1 q2 w1 w2; act, goal, rate (4, n);\n"
"slack, tx, ty (n,); steps, halt, cursor, ev_end (n,) int64; game i's events are\n"
"cursor[i]:ev_end[i] of ev_step (int64), ev_muscle (int64, 0-3), ev_goal, ev_rate (float64),\n"
"sorted by step; an event at step s applies before the step from s; flags (n,) uint8.\n"
"With fast true, RK4's elbow trig comes by angle addition (the numpy fast kernel's method):\n"
"round-off, not bit for bit. Refused before any step (ValueError): params not finite or dt not positive,\n"
"steps or halt outside 0 to the steps of a 24 h game at dt, a command's goal or rate not finite.");

static PyObject *run(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *obj[17];
    int mode, fast;
    Py_ssize_t n;
    if (!PyArg_ParseTuple(args, "OipnOOOOOOOOOOOOOOOO", &obj[0], &mode, &fast, &n, &obj[1], &obj[2], &obj[3], &obj[4],
                          &obj[5], &obj[6], &obj[7], &obj[8], &obj[9], &obj[10], &obj[11], &obj[12], &obj[13],
                          &obj[14], &obj[15], &obj[16]))
        return NULL;
    /* n bounded first: every size below is n times at most 4 * 8 bytes, which must not overflow (a wrapped
       n * D of 0 would divide by zero below: SIGFPE, the process gone). */
    if (mode < MODE_UNFORCED || mode > MODE_GRAVITY || n < 1 || n > PY_SSIZE_T_MAX / (4 * (Py_ssize_t)sizeof(double))) {
        PyErr_Format(PyExc_ValueError, "mode %d, %zd games: expected mode 0, 1 or 2 and at least one game, at most %zd", mode,
                     n, PY_SSIZE_T_MAX / (4 * (Py_ssize_t)sizeof(double)));
        return NULL;
    }
    Buf b[17];
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

    const double *p = b[0].view.buf;
    if (check_params("run", p, 1) < 0)
        goto done;
    double *x = b[1].view.buf, *act = b[2].view.buf, *goal = b[3].view.buf, *rate = b[4].view.buf;
    double *slack = b[5].view.buf;
    const double *tx = b[6].view.buf, *ty = b[7].view.buf;
    int64_t *steps = b[8].view.buf, *cursor = b[10].view.buf;
    const int64_t *halt = b[9].view.buf, *ev_end = b[11].view.buf, *ev_step = b[12].view.buf;
    const int64_t *ev_muscle = b[13].view.buf;
    const double *ev_goal = b[14].view.buf, *ev_rate = b[15].view.buf;
    uint8_t *flags = b[16].view.buf;

    /* The work is bounded before it starts: cursors within the events, muscles 0-3, finite commands, and
     * every game's steps and halt from 0 to a game's most steps at this dt. */
    const double most = max_steps(p[P_DT]);
    for (Py_ssize_t i = 0; i < n; i++) {
        if (cursor[i] < 0 || cursor[i] > ev_end[i] || ev_end[i] > events) {
            PyErr_Format(PyExc_ValueError, "game %zd: events %lld:%lld of %zd", i, (long long)cursor[i],
                         (long long)ev_end[i], events);
            goto done;
        }
        if (steps[i] < 0 || halt[i] < 0 || (double)steps[i] > most || (double)halt[i] > most) {
            char message[200];  /* PyErr_Format has no %g */
            snprintf(message, sizeof message,
                     "run: game %zd: steps %lld, halt %lld: expected 0 to %.15g (%g s at dt %g)", i,
                     (long long)steps[i], (long long)halt[i], most, MAX_GAME_SECONDS, p[P_DT]);
            PyErr_SetString(PyExc_ValueError, message);
            goto done;
        }
    }
    for (Py_ssize_t e = 0; e < events; e++) {
        if (ev_muscle[e] < 0 || ev_muscle[e] > 3) {
            PyErr_Format(PyExc_ValueError, "event %zd: muscle %lld", e, (long long)ev_muscle[e]);
            goto done;
        }
        if (!isfinite(ev_goal[e]) || !isfinite(ev_rate[e])) {
            PyErr_Format(PyExc_ValueError, "event %zd: its goal or rate is not finite", e);
            goto done;
        }
    }

    const Arm arm = {p[P_B], p[P_D], p[P_DET0], p[P_AMD], p[P_G1], p[P_G2], p[P_K1], p[P_K2], mode};
    const double dt = p[P_DT], h = p[P_H], k = p[P_K];
    const double l1 = p[P_L1], l2 = p[P_L2], radius = p[P_RADIUS], near = p[P_NEAR];
    const double reach1 = p[P_REACH1], reach2 = p[P_REACH2], limit2 = p[P_LIMIT2];
    const double s0 = p[P_S0], s1 = p[P_S1], s2 = p[P_S2], s3 = p[P_S3];
    const double e0 = p[P_E0], e1 = p[P_E1], e2 = p[P_E2], e3 = p[P_E3];
    Py_ssize_t flagged = 0;

    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t i = 0; i < n; i++) {
        int64_t s = steps[i], c = cursor[i];
        const int64_t stop = halt[i], end = ev_end[i];
        flags[i] = 0;
        if (s >= stop && (c >= end || ev_step[c] > s))
            continue;
        double q1 = x[i], q2 = x[n + i], w1 = x[2 * n + i], w2 = x[3 * n + i];
        double bc = 0.0, bs = 0.0;  /* the fast kernel's b cos q2, b sin q2, carried from step to step */
        int anchor = 0;  /* steps left before they are computed in full again; none at a game's start */
        double a[4], g[4], r[4];
        for (int m = 0; m < 4; m++) {
            a[m] = act[m * n + i];
            g[m] = goal[m * n + i];
            r[m] = rate[m * n + i];
        }
        double sl = slack[i];
        const double x0 = tx[i], y0 = ty[i];
        for (;;) {
            while (c < end && ev_step[c] <= s) {
                g[ev_muscle[c]] = ev_goal[c];
                r[ev_muscle[c]] = ev_rate[c];
                c++;
            }
            if (s >= stop)
                break;
            /* GameSession._advance: torque from the activations, then the muscles step. */
            const double t1 = a[0] * s0 + a[1] * s1 + a[2] * s2 + a[3] * s3;
            const double t2 = a[0] * e0 + a[1] * e1 + a[2] * e2 + a[3] * e3;
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
                    flags[i] = 1;
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
            act[m * n + i] = a[m];
            goal[m * n + i] = g[m];
            rate[m * n + i] = r[m];
        }
        slack[i] = sl;
        steps[i] = s;
        cursor[i] = c;
    }
    Py_END_ALLOW_THREADS
    result = PyLong_FromSsize_t(flagged);
done:
    release(b, 17);
    return result;
}

/* A stage of RK4 in full: GameSession's accel with its own b cos q2 and b sin q2. */
static inline void accel_full(const Arm *arm, double q1, double q2, double w1, double w2, double t1, double t2,
                              double *o1, double *o2)
{
    double sn, cs;
    sin_cos(q2, &sn, &cs);
    accel_trig(arm, q1, q2, arm->b * cs, arm->b * sn, w1, w2, t1, t2, o1, o2);
}

/* integrators._rk4, exactly: x (q1, q2, w1, w2) one step of dt on, torques t1, t2 held. h and k are
 * taken from dt as the Python step takes them (0.5 dt and dt times _SIXTH, 1/6 rounded once). */
static inline void rk4_exact(const Arm *arm, double t1, double t2, double dt, double x[4])
{
    const double q1 = x[0], q2 = x[1], w1 = x[2], w2 = x[3];
    const double h = 0.5 * dt;
    double ka1, ka2, kb1, kb2, kc1, kc2, kd1, kd2;
    accel_full(arm, q1, q2, w1, w2, t1, t2, &ka1, &ka2);
    const double v1 = w1 + h * ka1;
    const double v2 = w2 + h * ka2;
    accel_full(arm, q1 + h * w1, q2 + h * w2, v1, v2, t1, t2, &kb1, &kb2);
    const double u1 = w1 + h * kb1;
    const double u2 = w2 + h * kb2;
    accel_full(arm, q1 + h * v1, q2 + h * v2, u1, u2, t1, t2, &kc1, &kc2);
    const double z1 = w1 + dt * kc1;
    const double z2 = w2 + dt * kc2;
    accel_full(arm, q1 + dt * u1, q2 + dt * u2, z1, z2, t1, t2, &kd1, &kd2);
    const double k = dt * (1.0 / 6.0);
    x[0] = q1 + k * (w1 + z1 + 2.0 * (v1 + u1));
    x[1] = q2 + k * (w2 + z2 + 2.0 * (v2 + u2));
    x[2] = w1 + k * (ka1 + kd1 + 2.0 * (kb1 + kc1));
    x[3] = w2 + k * (ka2 + kd2 + 2.0 * (kb2 + kc2));
}

/* Nonzero if ``x`` is NaN or infinite: its exponent bits all ones. No branch, so checking a call's
 * arguments as they are read costs next to nothing. */
static inline uint64_t not_finite(double x)
{
    const uint64_t exponent = UINT64_C(0x7ff0000000000000);
    uint64_t bits;
    memcpy(&bits, &x, sizeof bits);
    return (bits & exponent) == exponent;
}

/* The params bytes object last found finite, held so that it cannot be freed and its address reused:
 * a session passes the same object on every call (a bot's, once a step), which is then not checked
 * again (bytes do not change). */
static PyObject *finite_params = NULL;

static int arg_double(PyObject *obj, double *out)
{
    if (PyFloat_CheckExact(obj)) {
        *out = PyFloat_AS_DOUBLE(obj);
        return 0;
    }
    *out = PyFloat_AsDouble(obj);
    return (*out == -1.0 && PyErr_Occurred()) ? -1 : 0;
}

/* The calls of one game (game_steps, rk4_step): ``expected`` arguments, the first two the params bytes
 * (P_* doubles, into p) and the mode, then ``count`` doubles from ``first`` on (into v), named ``names``
 * (space-separated) in a message: every one must be finite (a NaN in gave NaN out, or a loop that never
 * found its target). ``counted``: a loop of steps follows, whose dt must be positive. */
static int one_game_args(const char *name, PyObject *const *args, Py_ssize_t nargs, Py_ssize_t expected,
                         double *p, Arm *arm, Py_ssize_t first, int count, double *v, const char *names,
                         int counted)
{
    if (nargs != expected) {
        PyErr_Format(PyExc_TypeError, "%s takes %zd arguments, got %zd", name, expected, nargs);
        return -1;
    }
    if (!PyBytes_Check(args[0]) || PyBytes_GET_SIZE(args[0]) != P_COUNT * (Py_ssize_t)sizeof(double)) {
        PyErr_SetString(PyExc_ValueError, "params: expected bytes of the P_* doubles");
        return -1;
    }
    memcpy(p, PyBytes_AS_STRING(args[0]), P_COUNT * sizeof(double));
    const long mode = PyLong_AsLong(args[1]);
    if (mode == -1 && PyErr_Occurred())
        return -1;
    if (mode < MODE_UNFORCED || mode > MODE_GRAVITY) {
        PyErr_Format(PyExc_ValueError, "mode %ld: expected mode 0, 1 or 2", mode);
        return -1;
    }
    uint64_t bad = 0;
    for (int i = 0; i < count; i++) {
        if (arg_double(args[first + i], &v[i]) < 0)
            return -1;
        bad |= not_finite(v[i]);
    }
    if (args[0] != finite_params) {
        if (check_params(name, p, 0) < 0)
            return -1;
        Py_INCREF(args[0]);
        Py_XSETREF(finite_params, args[0]);
    }
    if (counted && !(p[P_DT] > 0.0)) {
        PyErr_Format(PyExc_ValueError, "%s: params dt must be positive", name);
        return -1;
    }
    for (int i = 0; bad && i < count; i++) {
        if (!isfinite(v[i])) {
            /* The i-th of the space-separated names. */
            const char *at = names;
            for (int j = 0; j < i && at != NULL; j++) {
                at = strchr(at, ' ');
                if (at != NULL)
                    at++;
            }
            const char *end = at == NULL ? NULL : strchr(at, ' ');
            const int width = at == NULL ? 1 : (end == NULL ? (int)strlen(at) : (int)(end - at));
            char message[120];  /* PyErr_Format has no %.*s before Python 3.12 */
            snprintf(message, sizeof message, "%s: %.*s is not finite", name, width, at == NULL ? "?" : at);
            PyErr_SetString(PyExc_ValueError, message);
            return -1;
        }
    }
    const Arm value = {p[P_B], p[P_D], p[P_DET0], p[P_AMD], p[P_G1], p[P_G2], p[P_K1], p[P_K2], (int)mode};
    *arm = value;
    return 0;
}

/* The relative margin of game_steps' "near" test over the exact one (which Python makes): far above
 * the round-off of squaring by multiplication instead of ``**``. */
#define NEAR_MARGIN 1e-9

PyDoc_STRVAR(game_steps_doc,
"game_steps(params, mode, n, q1, q2, w1, w2, a0, a1, a2, a3, g0, g1, g2, g3, r0, r1, r2, r3, tx, ty, rr)\n"
"    -> (ran, near, q1, q2, w1, w2, p1, p2, p3, p4, a0, a1, a2, a3, hx, hy)\n\n"
"GameSession._advance for one game, exactly: up to n steps of the muscles (activations a, goals g,\n"
"rates r) and RK4 from state (q1, q2, w1, w2), stopping early after a step that leaves the hand\n"
"(hx, hy) within a relative 1e-9 of the target disc (tx, ty, radius squared rr): near is then true,\n"
"and the caller decides the hit with the session's own test (hx, hy are the hand after the last step\n"
"only then: the hand is measured only when it may be near). p1-p4 is the state before the last\n"
"step run. params is a bytes object of the P_* doubles (only the arm's, dt's and moments' are read).\n"
"Refused before any step (ValueError): a value or param not finite, dt not positive, n past the steps\n"
"of a 24 h game at dt.");

static PyObject *game_steps(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    double p[P_COUNT], v[19];
    Arm arm;
    if (one_game_args("game_steps", args, nargs, 22, p, &arm, 3, 19, v,
                      "q1 q2 w1 w2 a0 a1 a2 a3 g0 g1 g2 g3 r0 r1 r2 r3 tx ty rr", 1) < 0)
        return NULL;
    const Py_ssize_t n = PyLong_AsSsize_t(args[2]);
    if (n == -1 && PyErr_Occurred())
        return NULL;
    if (n < 0 || ((double)n - 1.0) * p[P_DT] > MAX_GAME_SECONDS) {  /* n <= max_steps(dt), without a division */
        char message[160];  /* PyErr_Format has no %g */
        snprintf(message, sizeof message,
                 "game_steps: %zd steps: expected steps >= 0 and at most %.15g (%g s at dt %g)", n,
                 max_steps(p[P_DT]), MAX_GAME_SECONDS, p[P_DT]);
        PyErr_SetString(PyExc_ValueError, message);
        return NULL;
    }
    double x[4] = {v[0], v[1], v[2], v[3]};
    double a0 = v[4], a1 = v[5], a2 = v[6], a3 = v[7];
    const double g0 = v[8], g1 = v[9], g2 = v[10], g3 = v[11];
    const double r0 = v[12], r1 = v[13], r2 = v[14], r3 = v[15];
    const double x0 = v[16], y0 = v[17], rr = v[18];
    const double dt = p[P_DT], l1 = p[P_L1], l2 = p[P_L2];
    const double s0 = p[P_S0], s1 = p[P_S1], s2 = p[P_S2], s3 = p[P_S3];
    const double e0 = p[P_E0], e1 = p[P_E1], e2 = p[P_E2], e3 = p[P_E3];
    const double near = rr * (1.0 + NEAR_MARGIN);
    double previous[4] = {x[0], x[1], x[2], x[3]}, hx = 0.0, hy = 0.0;
    /* |the hand's move| <= reach1 |dq1| + reach2 |dq2| (numpy_kernel.hand_move_bounds, a hair over). */
    const double reach1 = (l1 + l2) * (1.0 + 1e-9), reach2 = l2 * (1.0 + 1e-9);
    const double radius = rr > 0.0 ? sqrt(rr) : 0.0;
    double slack = -1.0;  /* measured after the first step */
    Py_ssize_t ran = 0;
    int flagged = 0;
    while (ran < n) {
        /* GameSession._advance: torque from the activations, then the muscles step, then RK4. */
        const double t1 = a0 * s0 + a1 * s1 + a2 * s2 + a3 * s3;
        const double t2 = a0 * e0 + a1 * e1 + a2 * e2 + a3 * e3;
        a0 += (g0 - a0) * r0;
        a1 += (g1 - a1) * r1;
        a2 += (g2 - a2) * r2;
        a3 += (g3 - a3) * r3;
        memcpy(previous, x, sizeof previous);
        rk4_exact(&arm, t1, t2, dt, x);
        ran++;
        /* The hand's four cos and sin cost a third of a step: it is measured only when a lower bound on its
         * distance from the disc, lowered by a bound on each step's move, runs out (the batch's slack, see
         * ``run``), which no hand outside the disc by 1e-9 m can skip past. */
        slack -= fabs(x[0] - previous[0]) * reach1 + fabs(x[1] - previous[1]) * reach2;
        if (slack < 0.0) {
            double sa, ca, sb, cb;
            sin_cos(x[0], &sa, &ca);
            sin_cos(x[0] + x[1], &sb, &cb);
            hx = l1 * ca + l2 * cb;
            hy = l1 * sa + l2 * sb;
            const double dx = hx - x0, dy = hy - y0;
            const double d2h = dx * dx + dy * dy;
            if (d2h <= near) {
                flagged = 1;
                break;
            }
            slack = sqrt(d2h) - radius - 1e-9;
        }
    }
    PyObject *out = PyTuple_New(16);
    if (out == NULL)
        return NULL;
    const double values[14] = {x[0], x[1], x[2], x[3], previous[0], previous[1], previous[2], previous[3],
                               a0, a1, a2, a3, hx, hy};
    PyObject *item = PyLong_FromSsize_t(ran);
    if (item == NULL)
        goto fail;
    PyTuple_SET_ITEM(out, 0, item);
    PyTuple_SET_ITEM(out, 1, PyBool_FromLong(flagged));
    for (int i = 0; i < 14; i++) {
        item = PyFloat_FromDouble(values[i]);
        if (item == NULL)
            goto fail;
        PyTuple_SET_ITEM(out, 2 + i, item);
    }
    return out;
fail:
    Py_DECREF(out);
    return NULL;
}

PyDoc_STRVAR(rk4_step_doc,
"rk4_step(params, mode, q1, q2, w1, w2, t1, t2, dt) -> (q1, q2, w1, w2)\n\n"
"One step of integrators._rk4 on TwoJointArm's accel (mode 0, 1 or 2, as game_steps), torques t1, t2\n"
"held over dt: the Python step's operations in order. params as game_steps' (only the arm's read).\n"
"A value or param not finite is refused (ValueError).");

static PyObject *rk4_step(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    double p[P_COUNT], v[7];
    Arm arm;
    if (one_game_args("rk4_step", args, nargs, 9, p, &arm, 2, 7, v, "q1 q2 w1 w2 t1 t2 dt", 0) < 0)
        return NULL;
    double x[4] = {v[0], v[1], v[2], v[3]};
    rk4_exact(&arm, v[4], v[5], v[6], x);
    return Py_BuildValue("(dddd)", x[0], x[1], x[2], x[3]);
}


PyDoc_STRVAR(rk4_run_doc,
"rk4_run(params, mode, dt, x, torques, steps, states, every, limit) -> int\n\n"
"Steps of integrators._rk4 (rk4_step's operations) from x (4 float64: q1 q2 w1 w2), in place: step i holds\n"
"torques row min(i, rows - 1) (float64 rows t1 t2), so one row holds a torque throughout. The state\n"
"after every ``every``-th step goes to the next row of states (float64, 4 a row; row 0 is the start),\n"
"while rows remain. Stops early after a step that leaves a value not finite or a joint speed at or past\n"
"limit (a blow-up). Returns the steps run. For the benchmark's table: one arm in the compiled loop,\n"
"without the game's muscles and hit tests. Refused (ValueError): params or x not finite, dt not\n"
"positive, steps past a 24 h game at dt, every < 1, no torque row.");

static PyObject *rk4_run(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *obj[4];
    int mode;
    double dt, limit;
    Py_ssize_t steps, every;
    if (!PyArg_ParseTuple(args, "OidOOnOnd", &obj[0], &mode, &dt, &obj[1], &obj[2], &steps, &obj[3], &every, &limit))
        return NULL;
    Buf b[4];
    memset(b, 0, sizeof b);
    PyObject *result = NULL;
    const Py_ssize_t D = sizeof(double);
    if (get(obj[0], &b[0], P_COUNT, D, 0, "params") < 0 || get(obj[1], &b[1], 4, D, 1, "x") < 0
        || get(obj[2], &b[2], -1, 2 * D, 0, "torques") < 0 || get(obj[3], &b[3], -1, 4 * D, 1, "states") < 0)
        goto done;
    const double *p = b[0].view.buf;
    double *x = b[1].view.buf, *out = b[3].view.buf;
    const double *tq = b[2].view.buf;
    const Py_ssize_t rows = b[2].view.len / (2 * D), slots = b[3].view.len / (4 * D);
    if (check_params("rk4_run", p, 0) < 0)
        goto done;
    if (mode < MODE_UNFORCED || mode > MODE_GRAVITY || !(dt > 0.0) || !isfinite(dt) || rows < 1 || every < 1
        || steps < 0 || ((double)steps - 1.0) * dt > MAX_GAME_SECONDS) {
        PyErr_SetString(PyExc_ValueError, "rk4_run: expected mode 0-2, a finite dt > 0, a torque row, every >= 1 "
                                          "and 0 to a 24 h game's steps");
        goto done;
    }
    for (int i = 0; i < 4; i++) {
        if (!isfinite(x[i])) {
            PyErr_SetString(PyExc_ValueError, "rk4_run: x is not finite");
            goto done;
        }
    }
    for (Py_ssize_t i = 0; i < 2 * rows; i++) {
        if (!isfinite(tq[i])) {
            PyErr_SetString(PyExc_ValueError, "rk4_run: a torque is not finite");
            goto done;
        }
    }
    const Arm arm = {p[P_B], p[P_D], p[P_DET0], p[P_AMD], p[P_G1], p[P_G2], p[P_K1], p[P_K2], mode};
    Py_ssize_t ran = 0, slot = 1;
    if (slots > 0)
        memcpy(out, x, 4 * sizeof(double));
    Py_BEGIN_ALLOW_THREADS
    while (ran < steps) {
        const Py_ssize_t row = ran < rows ? ran : rows - 1;
        rk4_exact(&arm, tq[2 * row], tq[2 * row + 1], dt, x);
        ran++;
        if (ran % every == 0 && slot < slots) {
            memcpy(out + 4 * slot, x, 4 * sizeof(double));
            slot++;
        }
        /* A blow-up: the benchmark's test (measure._finite_and_sane), so the run stops where Python's does. */
        if (!(isfinite(x[0]) && isfinite(x[1]) && fabs(x[2]) < limit && fabs(x[3]) < limit))
            break;
    }
    Py_END_ALLOW_THREADS
    result = PyLong_FromSsize_t(ran);
done:
    release(b, 4);
    return result;
}

static PyMethodDef methods[] = {
    {"run", run, METH_VARARGS, run_doc},
    {"game_steps", (PyCFunction)(void (*)(void))game_steps, METH_FASTCALL, game_steps_doc},
    {"rk4_step", (PyCFunction)(void (*)(void))rk4_step, METH_FASTCALL, rk4_step_doc},
    {"rk4_run", rk4_run, METH_VARARGS, rk4_run_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_ckernel",
    "The batched game's hot loop, compiled (optional: armgame.game.batch.compiled falls back to numpy).",
    -1, methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__ckernel(void)
{
    use_sincos = sincos_agrees();
    PyObject *m = PyModule_Create(&module);
    /* VERSION changes with the calling convention, so a stale build is refused, not misread. */
    if (m != NULL && (PyModule_AddIntConstant(m, "PARAMS", P_COUNT) < 0
                      || PyModule_AddIntConstant(m, "VERSION", 4) < 0
                      || PyModule_AddIntConstant(m, "SINCOS", use_sincos) < 0)) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
