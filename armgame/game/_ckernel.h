/* What the compiled loops share with Python (_ckernel.c: one game and the module; _cbatch.c: the batch): the
 * arithmetic, with no Python in it, is _cstep.h's; here the params' checks, the buffers, the batch's call and
 * the entry points. See _ckernel.c's opening comment for why each is exactly the Python it replaces. */
#ifndef ARMGAME_CKERNEL_H
#define ARMGAME_CKERNEL_H
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "_cstep.h"

/* The P_* names, for a message naming a parameter that is not finite. */
static const char *const PARAM_NAMES[P_COUNT] = {
    "dt", "h", "k", "b", "d", "det0", "amd", "g1", "g2", "k1", "k2",
    "l1", "l2", "radius", "near", "reach1", "reach2", "limit2",
    "s0", "s1", "s2", "s3", "e0", "e1", "e2", "e3",
};

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
