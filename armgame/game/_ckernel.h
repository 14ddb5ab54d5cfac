/* What the compiled loops share (_ckernel.c: one game and the module; _cbatch.c: the batch): the
 * params' layout, the arm's trig (physics/_trig.h) and accel, the fast kernel's trig, the C library's
 * sincos where checked, and the buffers' checks. See _ckernel.c's opening comment for why each is exactly the Python it replaces. */
#ifndef ARMGAME_CKERNEL_H
#define ARMGAME_CKERNEL_H
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* The hand's trig (kinematics: where the hand is, the observations) is the C library's, as Python's
 * ``math`` is. Where the C library is glibc, whose sincos runs the very code of its sin and cos (one
 * argument reduction for both: a pair costs 11 ns here against 17), the hand's pairs come from sincos.
 * Nothing promises that elsewhere, so other libraries call sin and cos apart, and even glibc's sincos is
 * used only after the module's start has found it equal to sin and cos, bit for bit, on angles from
 * -1e6 to 1e6 (``SINCOS`` says whether it is used). */
#if defined(__GLIBC__)
extern void sincos(double x, double *s, double *c);
#endif
/* Set once at the module's start (_ckernel.c), read by every loop. */
extern int armgame_use_sincos;

static inline void sin_cos(double x, double *s, double *c)
{
#if defined(__GLIBC__)
    if (armgame_use_sincos) {
        sincos(x, s, c);
        return;
    }
#endif
    *s = sin(x);
    *c = cos(x);
}

/* The arm's trig (arm_sin_cos, arm_cos): armgame/physics/_trig.h. */
#include "../physics/_trig.h"

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
static inline int check_params(const char *name, const double *p, int counted)
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
static inline double max_steps(double dt)
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
        gc12 = arm->g2 * arm_cos(q1 + q2);
    double m12 = arm->d + bc;
    if (arm->mode == MODE_UNFORCED) {
        f1 = t1 + h * (w1 + w1 + w2) * w2;
        f2 = t2 - h * w1 * w1;
    } else if (arm->mode == MODE_DAMPING) {
        f1 = t1 + h * (w1 + w1 + w2) * w2 - arm->k1 * w1;
        f2 = t2 - h * w1 * w1 - arm->k2 * w2;
    } else {
        f1 = t1 + h * (w1 + w1 + w2) * w2 - arm->g1 * arm_cos(q1) - gc12 - arm->k1 * w1;
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
        arm_sin_cos(q2, &sn, &cs);
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

static inline void release(Buf *bufs, int count)
{
    for (int i = 0; i < count; i++)
        if (bufs[i].held)
            PyBuffer_Release(&bufs[i].view);
}

/* Get a C-contiguous buffer of ``count`` items of ``itemsize`` bytes (any whole number of them if
 * ``count`` is -1), writable if asked. */
static inline int get(PyObject *obj, Buf *buf, Py_ssize_t count, Py_ssize_t itemsize, int writable, const char *name)
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

/* A field at the hand (loads.CurlField, loads.ViscousField) and the flag of a game the guard stopped. */
enum { FIELD_NONE = 0, FIELD_CURL = 1, FIELD_VISCOUS = 2 };

/* A field at the hand: its kind, parameters (curl b; viscous b11 b12 b21 b22) and the arm's lengths. */
typedef struct {
    int kind;
    double p[4], l1, l2;
} Field;

/* The batch (_cbatch.c: the call, one game at a time; _clanes.c: games side by side). */
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
    /* The harder tasks' physics (game/variant.py), or none: every game's muscle moments, (8, n) rows s0-s3
     * then e0-e3 (motor noise rescales them before each decision), or NULL for s and e above; the field at
     * the hand (kind FIELD_NONE: none); the speed guard (rad/s, infinite: none), past which a game stops
     * (flags 2) with the state of the step that passed it. */
    const double *mom;
    Field field;
    double limit;
} Batch;


/* The field's joint torque ``J(q)^T F(v)`` (loads._with_loads's ``external`` with no joint load, operation
 * for operation) from the hand's trig: sin and cos of q1 (s1, c1) and of q1 + q2 (s12, c12). */
static inline void field_torque(const Field *f, double s1, double c1, double s12, double c12, double w1, double w2,
                                double *e1, double *e2)
{
    const double j12 = -f->l2 * s12, j22 = f->l2 * c12;
    const double j11 = -f->l1 * s1 + j12, j21 = f->l1 * c1 + j22;
    const double vx = j11 * w1 + j12 * w2, vy = j21 * w1 + j22 * w2;
    double fx, fy;
    if (f->kind == FIELD_CURL) {
        fx = f->p[0] * vy;
        fy = -f->p[0] * vx;
    } else {
        fx = f->p[0] * vx + f->p[1] * vy;
        fy = f->p[2] * vx + f->p[3] * vy;
    }
    /* No joint load: Python's 0.0 + 0.0 * w1 + 0.0 * w2 (+0, or NaN where w is not finite). */
    *e1 = 0.0 + 0.0 * w1 + 0.0 * w2 + j11 * fx + j21 * fy;
    *e2 = 0.0 + 0.0 * w1 + 0.0 * w2 + j12 * fx + j22 * fy;
}
/* A stage of RK4 in full: GameSession's accel with its own b cos q2 and b sin q2; with a field (not NULL),
 * loads' accel: the field's torque at the stage added to the muscles' (the hand's trig the C library's, as
 * Python's ``math`` is there). */
static inline void accel_full(const Arm *arm, const Field *field, double q1, double q2, double w1, double w2,
                              double t1, double t2, double *o1, double *o2)
{
    double sn, cs;
    if (field != NULL) {
        double s1, c1, s12, c12, e1, e2;
        sin_cos(q1, &s1, &c1);
        sin_cos(q1 + q2, &s12, &c12);
        field_torque(field, s1, c1, s12, c12, w1, w2, &e1, &e2);
        t1 = t1 + e1;
        t2 = t2 + e2;
    }
    arm_sin_cos(q2, &sn, &cs);
    accel_trig(arm, q1, q2, arm->b * cs, arm->b * sn, w1, w2, t1, t2, o1, o2);
}

/* integrators._rk4, exactly: x (q1, q2, w1, w2) one step of dt on, torques t1, t2 held, the field's added
 * where one is given. h and k are taken from dt as the Python step takes them (0.5 dt and dt times _SIXTH,
 * 1/6 rounded once). */
static inline void rk4_exact(const Arm *arm, const Field *field, double t1, double t2, double dt, double x[4])
{
    const double q1 = x[0], q2 = x[1], w1 = x[2], w2 = x[3];
    const double h = 0.5 * dt;
    double ka1, ka2, kb1, kb2, kc1, kc2, kd1, kd2;
    accel_full(arm, field, q1, q2, w1, w2, t1, t2, &ka1, &ka2);
    const double v1 = w1 + h * ka1;
    const double v2 = w2 + h * ka2;
    accel_full(arm, field, q1 + h * w1, q2 + h * w2, v1, v2, t1, t2, &kb1, &kb2);
    const double u1 = w1 + h * kb1;
    const double u2 = w2 + h * kb2;
    accel_full(arm, field, q1 + h * v1, q2 + h * v2, u1, u2, t1, t2, &kc1, &kc2);
    const double z1 = w1 + dt * kc1;
    const double z2 = w2 + dt * kc2;
    accel_full(arm, field, q1 + dt * u1, q2 + dt * u2, z1, z2, t1, t2, &kd1, &kd2);
    const double k = dt * (1.0 / 6.0);
    x[0] = q1 + k * (w1 + z1 + 2.0 * (v1 + u1));
    x[1] = q2 + k * (w2 + z2 + 2.0 * (v2 + u2));
    x[2] = w1 + k * (ka1 + kd1 + 2.0 * (kb1 + kc1));
    x[3] = w2 + k * (ka2 + kd2 + 2.0 * (kb2 + kc2));
}

#define FLAG_NEAR 1
#define FLAG_RUNAWAY 2

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

PyObject *armgame_run(PyObject *self, PyObject *args);
extern const char armgame_run_doc[];
/* Plans rolled out from one state (_cshoot.c: benchmarks' reference controller). */
PyObject *armgame_shoot(PyObject *self, PyObject *args);
extern const char armgame_shoot_doc[];
/* The events of a batch's timelines as columns (_cevents.c). */
PyObject *armgame_event_columns(PyObject *self, PyObject *args);
extern const char armgame_event_columns_doc[];
/* The games of a checked call, LANES at a time: returns the games flagged (_clanes.c). */
Py_ssize_t armgame_run_lanes(const Batch *B);

#endif
