/* CenterOut-v1's vector env in C: ``LabSession._advance``'s loop (the muscles, the arm's step with the trial's
 * field, the speed guard, the shown hand and the task's hold and reach) for a batch of runs, and the v1
 * observation of each. ``armgame.env.center_out_batch`` drives it: it keeps each run's trials (the lab's
 * ``schedule``) and, at a trial's end, the outcome, its row of the lab's table and the next trial's
 * description; this loop stops a run there and is called again for the steps left.
 *
 * Why it equals the single env bit for bit: the step is _cstep.h's ``rk4_exact`` (the game's step; with a field,
 * ``loads``' accel, operation for operation), the shown hand is ``physics.hand.hand_xy`` (the C library's sin and
 * cos, as Python's ``math``), the displays are ``lab.perturbations``' transforms
 * as their ``plan`` numbers write them, and the rules' tests are ``Target.contains`` and ``_task_step``'s, in the
 * same order. The hand's sin and cos come in pairs from glibc's sincos only where this module's start found it
 * equal to sin and cos, bit for bit (_ckernel.c's check). setup.py builds this file with floating-point contraction off. tests/test_env_center_out_batch.py
 * compares every observation, reward, flag and info with Gymnasium's ``SyncVectorEnv`` of single envs. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#if defined(__GLIBC__)
/* _cstep.h's sin_cos reads this: 1 where sincos_agrees found glibc's sincos equal to its sin and cos. */
int armgame_use_sincos = 0;
#endif
#include "../game/_cstep.h"

/* Columns of a run's float state, int state and trial (the Python side names them the same). */
enum { S_X = 0, S_A = 4, S_G = 8, S_R = 12, S_CX = 16, S_CY = 17, S_FW1 = 18, S_FW2 = 19, S_COUNT = 20 };
enum { I_STEPS, I_TOTAL, I_PHASE, I_COUNTER, I_GO, I_EVENT, I_PATH, I_TODO, I_START, I_COUNT };
enum { T_DELAY, T_TX, T_TY, T_TR, T_HX, T_HY, T_HR, T_HQ1, T_HQ2, T_FIELD, T_FP, T_SHOW = T_FP + 4, T_SP,
       T_HOLD_AT_HOME = T_SP + 6, T_HOLD, T_TIMEOUT, T_LIMIT, T_COUNT };
enum { EVENT_NONE = 0, EVENT_HIT = 1, EVENT_MISS = 2, EVENT_STOPPED = 3 };
enum { SHOW_NONE = 0, SHOW_LINEAR = 1, SHOW_JOINT = 2 };

typedef struct {
    Py_buffer view;
    int held;
} Buffer;

static int take(PyObject *obj, Buffer *buf, const char *name, char format, Py_ssize_t count)
{
    if (PyObject_GetBuffer(obj, &buf->view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0)
        return -1;
    buf->held = 1;
    const char *f = buf->view.format ? buf->view.format : "B";
    if (f[0] == '<' || f[0] == '=' || f[0] == '@')
        f++;
    const int ok = format == 'd' ? (strcmp(f, "d") == 0) : (strcmp(f, "q") == 0 || strcmp(f, "l") == 0);
    if (!ok || buf->view.itemsize != 8 || buf->view.len != count * 8) {
        PyErr_Format(PyExc_ValueError, "%s: expected a writable contiguous array of %zd %s", name, count,
                     format == 'd' ? "float64" : "int64");
        return -1;
    }
    return 0;
}

static void release(Buffer *b, int count)
{
    for (int i = 0; i < count; i++)
        if (b[i].held)
            PyBuffer_Release(&b[i].view);
}

/* The shown hand: the trial's display in a reach (``show.plan``), else the hand. */
static inline void shown(const double *t, int64_t phase, double q1, double q2, double *x, double *y)
{
    if (phase == 0 || t[T_SHOW] == SHOW_NONE)
        return;
    const double *sp = t + T_SP;
    if (t[T_SHOW] == SHOW_LINEAR) {
        const double dx = *x - sp[0], dy = *y - sp[1];
        *x = sp[0] + sp[2] * dx + sp[3] * dy;
        *y = sp[1] + sp[4] * dx + sp[5] * dy;
    } else {
        *x = sp[0] + sp[2] * (q1 - sp[3]);
        *y = sp[1] + sp[2] * (q2 - sp[4]);
    }
}

/* One run: up to it[I_TODO] steps, stopping after a trial's end or the guard's stop (it[I_EVENT] says which). */
static void run(const Arm *arm, const double *p, double *s, int64_t *it, const double *t, double *xs, double *ys,
                int64_t cap)
{
    int64_t n = it[I_TODO];
    if (it[I_TOTAL] - it[I_STEPS] < n)
        n = it[I_TOTAL] - it[I_STEPS];
    it[I_TODO] = 0;
    if (n <= 0)
        return;
    const double dt = p[P_DT], l1 = p[P_L1], l2 = p[P_L2];
    const double s0 = p[P_S0], s1 = p[P_S1], s2 = p[P_S2], s3 = p[P_S3];
    const double e0 = p[P_E0], e1 = p[P_E1], e2 = p[P_E2], e3 = p[P_E3];
    double *x = s + S_X;
    double a0 = s[S_A], a1 = s[S_A + 1], a2 = s[S_A + 2], a3 = s[S_A + 3];
    const double g0 = s[S_G], g1 = s[S_G + 1], g2 = s[S_G + 2], g3 = s[S_G + 3];
    const double r0 = s[S_R], r1 = s[S_R + 1], r2 = s[S_R + 2], r3 = s[S_R + 3];
    const double limit = t[T_LIMIT];
    const Field field = {(int)t[T_FIELD], {t[T_FP], t[T_FP + 1], t[T_FP + 2], t[T_FP + 3]}, l1, l2};
    int64_t phase = it[I_PHASE], counter = it[I_COUNTER], steps = it[I_STEPS], path = it[I_PATH];
    int64_t ran = 0;
    while (ran < n) {
        const double t1 = a0 * s0 + a1 * s1 + a2 * s2 + a3 * s3;
        const double t2 = a0 * e0 + a1 * e1 + a2 * e2 + a3 * e3;
        a0 += (g0 - a0) * r0;
        a1 += (g1 - a1) * r1;
        a2 += (g2 - a2) * r2;
        a3 += (g3 - a3) * r3;
        const int loaded = phase == 1 && field.kind != FIELD_NONE;
        double previous[4];
        memcpy(previous, x, sizeof previous);
        rk4_exact(arm, loaded ? &field : NULL, t1, t2, dt, x);
        if (loaded && !(-limit <= x[2] && x[2] <= limit && -limit <= x[3] && x[3] <= limit)) {
            /* variant.guarded: the state is refused, the run keeps the last one and ends there. */
            s[S_FW1] = x[2];
            s[S_FW2] = x[3];
            memcpy(x, previous, sizeof previous);
            it[I_TOTAL] = steps;
            it[I_EVENT] = EVENT_STOPPED;
            break;
        }
        steps++;
        ran++;
        double s1, c1, s12, c12;
        sin_cos(x[0], &s1, &c1);
        sin_cos(x[0] + x[1], &s12, &c12);
        double hx = l1 * c1 + l2 * c12, hy = l1 * s1 + l2 * s12;
        shown(t, phase, x[0], x[1], &hx, &hy);
        s[S_CX] = hx;
        s[S_CY] = hy;
        if (phase == 0) {
            const double dx = hx - t[T_HX], dy = hy - t[T_HY];
            counter = (t[T_HOLD_AT_HOME] == 0.0 || dx * dx + dy * dy <= t[T_HR] * t[T_HR]) ? counter + 1 : 0;
            if ((double)counter >= t[T_DELAY]) {
                phase = 1;
                it[I_GO] = it[I_START] = steps;
                counter = 0;
                xs[0] = hx;
                ys[0] = hy;
                path = 1;
            }
            continue;
        }
        if (path < cap) {
            xs[path] = hx;
            ys[path] = hy;
        }
        path++;
        const double dx = hx - t[T_TX], dy = hy - t[T_TY];
        counter = dx * dx + dy * dy <= t[T_TR] * t[T_TR] ? counter + 1 : 0;
        const int hit = (double)counter >= t[T_HOLD];
        if (!hit && (double)(steps - it[I_GO]) < t[T_TIMEOUT])
            continue;
        /* The trial's end: the arm goes home at rest and the muscles relax; the caller enters the next trial. */
        it[I_EVENT] = hit ? EVENT_HIT : EVENT_MISS;
        x[0] = t[T_HQ1];
        x[1] = t[T_HQ2];
        x[2] = x[3] = 0.0;
        a0 = a1 = a2 = a3 = 0.0;
        s[S_CX] = t[T_HX];
        s[S_CY] = t[T_HY];
        phase = 0;
        counter = 0;
        it[I_START] = steps;
        it[I_TODO] = n - ran;
        break;
    }
    s[S_A] = a0;
    s[S_A + 1] = a1;
    s[S_A + 2] = a2;
    s[S_A + 3] = a3;
    it[I_PHASE] = phase;
    it[I_COUNTER] = counter;
    it[I_STEPS] = steps;
    it[I_PATH] = path;
}

/* features.wrap_angle: q itself within [-pi, pi], else q - tau round(q / tau) clipped (round: half to even). */
static inline double wrap(double q)
{
    const double pi = 3.141592653589793, tau = 6.283185307179586;
    if (-pi <= q && q <= pi)
        return q;
    double w = q - tau * rint(q / tau);
    return w < -pi ? -pi : w > pi ? pi : w;
}

PyDoc_STRVAR(advance_doc,
"advance(params, mode, state, ints, trials, xs, ys, obs) -> int\n\n"
"Run every run of the batch its ints[:, TODO] steps (stopping at a trial's end or the guard's stop, which\n"
"ints[:, EVENT] says, with the steps left in TODO), then fill obs (n, 16 float64) with each run's v1\n"
"observation. Returns how many runs stopped at an event.");

static PyObject *advance(PyObject *self, PyObject *args)
{
    PyObject *obj[8];
    int mode;
    Buffer b[8] = {{{0}}};
    (void)self;
    if (!PyArg_ParseTuple(args, "OiOOOOOO", &obj[0], &mode, &obj[1], &obj[2], &obj[3], &obj[4], &obj[5],
                          &obj[6]))
        return NULL;
    if (take(obj[0], &b[0], "params", 'd', P_COUNT) < 0 || take(obj[1], &b[1], "state", 'd',
                                                                 PyObject_Length(obj[1]) * S_COUNT) < 0)
        goto fail;
    const Py_ssize_t n = b[1].view.len / (8 * S_COUNT);
    if (take(obj[2], &b[2], "ints", 'q', n * I_COUNT) < 0 || take(obj[3], &b[3], "trials", 'd', n * T_COUNT) < 0
        || take(obj[6], &b[6], "obs", 'd', n * 16) < 0)
        goto fail;
    if (PyObject_GetBuffer(obj[4], &b[4].view, PyBUF_C_CONTIGUOUS | PyBUF_WRITABLE) < 0)
        goto fail;
    b[4].held = 1;
    if (PyObject_GetBuffer(obj[5], &b[5].view, PyBUF_C_CONTIGUOUS | PyBUF_WRITABLE) < 0)
        goto fail;
    b[5].held = 1;
    const int64_t cap = n ? b[4].view.len / (8 * n) : 0;
    if (b[4].view.len != cap * 8 * n || b[5].view.len != b[4].view.len || cap < 1) {
        PyErr_SetString(PyExc_ValueError, "xs and ys must be (n, cap) float64 paths");
        goto fail;
    }
    const double *p = b[0].view.buf;
    for (int k = 0; k < P_COUNT; k++)
        if (!isfinite(p[k])) {
            PyErr_SetString(PyExc_ValueError, "params must be finite");
            goto fail;
        }
    if (!(p[P_DT] > 0.0) || mode < MODE_UNFORCED || mode > MODE_GRAVITY) {
        PyErr_SetString(PyExc_ValueError, "params: dt must be positive and mode 0, 1 or 2");
        goto fail;
    }
    Py_ssize_t events = 0;
    {
        const Arm arm = {p[P_B], p[P_D], p[P_DET0], p[P_AMD], p[P_G1], p[P_G2], p[P_K1], p[P_K2], mode};
        double *state = b[1].view.buf, *trials = b[3].view.buf, *obs = b[6].view.buf;
        double *xs = b[4].view.buf, *ys = b[5].view.buf;
        int64_t *ints = b[2].view.buf;
        const double dt = p[P_DT], l1 = p[P_L1], l2 = p[P_L2];
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t i = 0; i < n; i++) {
            double *s = state + S_COUNT * i;
            int64_t *it = ints + I_COUNT * i;
            const double *t = trials + T_COUNT * i;
            if (it[I_EVENT] == EVENT_NONE && it[I_TODO] > 0)
                run(&arm, p, s, it, t, xs + cap * i, ys + cap * i, cap);
            events += it[I_EVENT] != EVENT_NONE;
            /* center_out_v1.CenterOutV1Env._observation, in its order. */
            const double q1 = s[0], q2 = s[1], w1 = s[2], w2 = s[3];
            const double q12 = q1 + q2, w12 = w1 + w2;
            double c1, s1, c12, s12;
            sin_cos(q1, &s1, &c1);
            sin_cos(q12, &s12, &c12);
            const int reach = it[I_PHASE] == 1;
            const double cx = s[S_CX], cy = s[S_CY];
            double *o = obs + 16 * i;
            o[0] = wrap(q1);
            o[1] = wrap(q2);
            o[2] = w1;
            o[3] = w2;
            memcpy(o + 4, s + S_A, 4 * sizeof(double));
            o[8] = cx - t[T_HX];
            o[9] = cy - t[T_HY];
            o[10] = -l1 * s1 * w1 - l2 * s12 * w12;
            o[11] = l1 * c1 * w1 + l2 * c12 * w12;
            o[12] = (reach ? t[T_TX] : t[T_HX]) - cx;
            o[13] = (reach ? t[T_TY] : t[T_HY]) - cy;
            o[14] = reach ? 1.0 : 0.0;
            o[15] = (double)(it[I_STEPS] - it[I_START]) * dt;
        }
        Py_END_ALLOW_THREADS
    }
    release(b, 8);
    return PyLong_FromSsize_t(events);
fail:
    release(b, 8);
    return NULL;
}

static PyMethodDef methods[] = {
    {"advance", advance, METH_VARARGS, advance_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_ccenter", "CenterOut-v1's runs stepped in C (see armgame/env/center_out_batch.py).", -1,
    methods,
};

PyMODINIT_FUNC PyInit__ccenter(void)
{
    armgame_use_sincos = sincos_agrees();
    PyObject *m = PyModule_Create(&module);
    if (m != NULL && (PyModule_AddIntConstant(m, "VERSION", 1) < 0
                      || PyModule_AddIntConstant(m, "SINCOS", armgame_use_sincos) < 0)) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
