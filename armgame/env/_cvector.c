/* The vector env's work around the kernel, a pass over the batch each: the keys held (``hold_keys``, what
 * ``BatchGameSession.set_held`` does; ``armgame.env.vector`` calls it for the discrete envs) and Reach-v1's
 * observation rows with the hands' distances to their targets' edges (``observe_v1``;
 * ``armgame.env.features.observe_v1`` calls it). Where this was not built, numpy's twins run.
 *
 * Why the keys: ``set_held`` finds the changed keys as flat indices and scatters through them, some ten
 * numpy passes, about a tenth of a step at 8,192 games with random keys; here it is a compare per key. It
 * only copies values (a key's state, its goal 0 or 1, its rise or decay rate), so it equals ``set_held``
 * exactly.
 *
 * Why C: at 8,192 games numpy took about a quarter of a vector env's step for these 15 columns and the
 * distances, two dozen passes over the batch with a temporary each; here it is one pass, the hand's trig
 * read once. Why it equals the numpy twin bit for bit: every expression is the twin's (features.py), the
 * same IEEE double operations in the same order, then one rounding to float32 where the observation is
 * float32, as numpy's cast rounds; setup.py builds this file, as ``_ckernel.c``, with floating-point
 * contraction turned off, so no fused multiply-add changes a rounding. ``hypot`` and ``rint`` are the C
 * library's, which numpy's ``hypot`` and ``rint`` call too. tests/test_env_observe.py compares both with ``==``.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

PyDoc_STRVAR(observe_v1_doc,
"observe_v1(x, trig, act, tx, ty, steps, total, obs, edges, l1, l2, radius) -> None\n\n"
"Fill obs (n rows of 15, float32 or float64) with Reach-v1's observations of n games and, unless edges is\n"
"None, edges (n float64) with the hands' distances to their targets' edges. x: rows q1, q2, w1, w2 (at least\n"
"4 rows of n float64); trig: rows cos q1, sin q1, cos(q1 + q2), sin(q1 + q2) (at least 4 rows of n); act: 4\n"
"rows of n activations; tx, ty: targets (n float64); steps, total: the games' steps and lengths (n int64).");

typedef struct {
    Py_buffer view;
    int held;
} Buffer;

/* A C-contiguous buffer of at least ``count`` items of ``itemsize`` bytes whose format is one of ``formats``. */
static int take(PyObject *obj, Buffer *buf, const char *name, const char *formats, Py_ssize_t itemsize,
                Py_ssize_t count, int writable)
{
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, &buf->view, flags) < 0)
        return -1;
    buf->held = 1;
    const char *format = buf->view.format ? buf->view.format : "B";
    if (format[0] == '<' || format[0] == '=' || format[0] == '@')
        format++;
    if (buf->view.itemsize != itemsize || strlen(format) != 1 || strchr(formats, format[0]) == NULL
        || buf->view.len < count * itemsize) {
        PyErr_Format(PyExc_ValueError, "%s: expected a contiguous array of at least %zd items of format %s",
                     name, count, formats);
        return -1;
    }
    return 0;
}

static void release(Buffer *bufs, int count)
{
    for (int i = 0; i < count; i++)
        if (bufs[i].held)
            PyBuffer_Release(&bufs[i].view);
}

/* numpy's twin: ``wrapped = q - tau * rint(q / tau)``, clipped to [-pi, pi], and q itself where |q| <= pi. */
static inline double wrap(double q)
{
    const double pi = 3.141592653589793, tau = 6.283185307179586;
    if (fabs(q) <= pi)
        return q;
    double w = q - tau * rint(q / tau);
    if (w < -pi)
        w = -pi;
    else if (w > pi)
        w = pi;
    return w;
}

#define OBSERVE(T)                                                                                  \
    for (Py_ssize_t i = 0; i < n; i++) {                                                             \
        const double q1 = x[i], q2 = x[n + i], w1 = x[2 * n + i], w2 = x[3 * n + i];                 \
        const double c1 = tr[i], s1 = tr[n + i], c12 = tr[2 * n + i], s12 = tr[3 * n + i];           \
        const double hx = l1 * c1 + l2 * c12, hy = l1 * s1 + l2 * s12, w12 = w1 + w2;               \
        const int64_t s = steps[i], t = total[i];                                                    \
        T *restrict row = (T *)out + 15 * i;                                                         \
        row[0] = (T)wrap(q1);                                                                        \
        row[1] = (T)wrap(q2);                                                                        \
        row[2] = (T)w1;                                                                              \
        row[3] = (T)w2;                                                                              \
        row[4] = (T)act[i];                                                                          \
        row[5] = (T)act[n + i];                                                                      \
        row[6] = (T)act[2 * n + i];                                                                  \
        row[7] = (T)act[3 * n + i];                                                                  \
        row[8] = (T)hx;                                                                              \
        row[9] = (T)hy;                                                                              \
        row[10] = (T)(-l1 * s1 * w1 - l2 * s12 * w12);                                              \
        row[11] = (T)(l1 * c1 * w1 + l2 * c12 * w12);                                               \
        const double dx = tx[i] - hx, dy = ty[i] - hy;                                               \
        row[12] = (T)dx;                                                                             \
        row[13] = (T)dy;                                                                             \
        row[14] = (T)((double)(t - (s < t ? s : t)) / (double)t);                                    \
        if (edges != NULL) {                                                                         \
            const double e = hypot(dx, dy) - radius;                                                 \
            edges[i] = e < 0.0 ? 0.0 : e; /* numpy's maximum: a NaN stays NaN */                     \
        }                                                                                            \
    }

static PyObject *observe_v1(PyObject *self, PyObject *args)
{
    PyObject *obj[9];
    double l1, l2, radius;
    Buffer b[9] = {{{0}}};
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOOOOOddd", &obj[0], &obj[1], &obj[2], &obj[3], &obj[4], &obj[5], &obj[6],
                          &obj[7], &obj[8], &l1, &l2, &radius))
        return NULL;
    /* The batch's size is its targets'; every other array is checked against it. */
    if (take(obj[3], &b[3], "tx", "d", 8, 0, 0) < 0)
        goto fail;
    const Py_ssize_t n = b[3].view.len / 8;
    if (take(obj[0], &b[0], "x", "d", 8, 4 * n, 0) < 0 || take(obj[1], &b[1], "trig", "d", 8, 4 * n, 0) < 0
        || take(obj[2], &b[2], "act", "d", 8, 4 * n, 0) < 0 || take(obj[4], &b[4], "ty", "d", 8, n, 0) < 0
        || take(obj[5], &b[5], "steps", "qlL", 8, n, 0) < 0 || take(obj[6], &b[6], "total", "qlL", 8, n, 0) < 0)
        goto fail;
    /* x, trig and act are read as rows of n: a longer buffer (the batch's scratch rows) is fine only if
     * its rows are n long, which the caller's shapes guarantee; act must be exactly 4 rows. */
    if (b[2].view.len != 4 * n * 8 || b[4].view.len != n * 8 || b[5].view.len != n * 8 || b[6].view.len != n * 8
        || b[0].view.len % (n * 8 ? n * 8 : 1) || b[1].view.len % (n * 8 ? n * 8 : 1)) {
        PyErr_SetString(PyExc_ValueError, "x, trig, act, tx, ty, steps and total must be rows of the same n games");
        goto fail;
    }
    if (PyObject_GetBuffer(obj[7], &b[7].view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0)
        goto fail;
    b[7].held = 1;
    const char *format = b[7].view.format ? b[7].view.format : "B";
    if (format[0] == '<' || format[0] == '=' || format[0] == '@')
        format++;
    const int single = strcmp(format, "f") == 0 && b[7].view.itemsize == 4;
    if (!(single || (strcmp(format, "d") == 0 && b[7].view.itemsize == 8))
        || b[7].view.len != 15 * n * b[7].view.itemsize) {
        PyErr_SetString(PyExc_ValueError, "obs must be a contiguous (n, 15) float32 or float64 array");
        goto fail;
    }
    double *edges_out = NULL;
    if (obj[8] != Py_None) {
        if (take(obj[8], &b[8], "edges", "d", 8, n, 1) < 0)
            goto fail;
        if (b[8].view.len != n * 8) {
            PyErr_SetString(PyExc_ValueError, "edges must be n float64");
            goto fail;
        }
        edges_out = (double *)b[8].view.buf;
    }
    for (Py_ssize_t i = 0; i < n; i++)
        if (((const int64_t *)b[6].view.buf)[i] <= 0) {
            PyErr_SetString(PyExc_ValueError, "total: every game's length must be at least one step");
            goto fail;
        }
    {
        /* restrict: the rows written are no array read, so the compiler need not reload after each store. */
        const double *restrict x = b[0].view.buf, *restrict tr = b[1].view.buf, *restrict act = b[2].view.buf;
        const double *restrict tx = b[3].view.buf, *restrict ty = b[4].view.buf;
        const int64_t *restrict steps = b[5].view.buf, *restrict total = b[6].view.buf;
        void *restrict out = b[7].view.buf;
        double *restrict edges = edges_out;
        Py_BEGIN_ALLOW_THREADS
        if (single) {
            OBSERVE(float)
        } else {
            OBSERVE(double)
        }
        Py_END_ALLOW_THREADS
    }
    release(b, 9);
    Py_RETURN_NONE;
fail:
    release(b, 9);
    return NULL;
}

PyDoc_STRVAR(hold_keys_doc,
"hold_keys(pressed, steps, total, held, goal, rate, rise, decay) -> None\n\n"
"BatchGameSession.set_held(pressed) on a batch's arrays: pressed (n, 4) bool, steps and total (n int64: a\n"
"game with steps >= total is over and untouched), held (4, n) bool, goal and rate (4, n) float64, rise and\n"
"decay (4 float64, each muscle's rates). A key whose state changes takes it, its goal (1 or 0) and its rate.");

static PyObject *hold_keys(PyObject *self, PyObject *args)
{
    PyObject *obj[8];
    Buffer b[8] = {{{0}}};
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOOOO", &obj[0], &obj[1], &obj[2], &obj[3], &obj[4], &obj[5], &obj[6], &obj[7]))
        return NULL;
    if (take(obj[1], &b[1], "steps", "qlL", 8, 0, 0) < 0)
        goto fail;
    const Py_ssize_t n = b[1].view.len / 8;
    if (take(obj[0], &b[0], "pressed", "?", 1, 4 * n, 0) < 0 || take(obj[2], &b[2], "total", "qlL", 8, n, 0) < 0
        || take(obj[3], &b[3], "held", "?", 1, 4 * n, 1) < 0 || take(obj[4], &b[4], "goal", "d", 8, 4 * n, 1) < 0
        || take(obj[5], &b[5], "rate", "d", 8, 4 * n, 1) < 0 || take(obj[6], &b[6], "rise", "d", 8, 4, 0) < 0
        || take(obj[7], &b[7], "decay", "d", 8, 4, 0) < 0)
        goto fail;
    if (b[0].view.len != 4 * n || b[2].view.len != 8 * n || b[3].view.len != 4 * n || b[4].view.len != 32 * n
        || b[5].view.len != 32 * n || b[6].view.len != 32 || b[7].view.len != 32) {
        PyErr_SetString(PyExc_ValueError, "pressed, steps, total, held, goal and rate must be of the same n games");
        goto fail;
    }
    {
        const unsigned char *pressed = b[0].view.buf;
        const int64_t *steps = b[1].view.buf, *total = b[2].view.buf;
        unsigned char *held = b[3].view.buf;
        double *goal = b[4].view.buf, *rate = b[5].view.buf;
        const double *rise = b[6].view.buf, *decay = b[7].view.buf;
        Py_BEGIN_ALLOW_THREADS
        /* Muscle by muscle along contiguous rows, in integer masks rather than branches: random keys change
         * half the time, a branch the CPU cannot predict (it made this pass five times slower). A double is
         * only copied, so selecting its bits is selecting it. */
        for (int m = 0; m < 4; m++) {
            unsigned char *hm = held + m * n;
            double *gm = goal + m * n, *rm = rate + m * n;
            uint64_t one, up, relax;
            const double one_d = 1.0;
            memcpy(&one, &one_d, 8);
            memcpy(&up, &rise[m], 8);
            memcpy(&relax, &decay[m], 8);
            for (Py_ssize_t i = 0; i < n; i++) {
                const unsigned char down = pressed[4 * i + m] != 0;
                const unsigned char change = (unsigned char)((down ^ hm[i]) & (steps[i] < total[i]));
                const uint64_t pick = (uint64_t)0 - change, press = (uint64_t)0 - down;
                uint64_t g, r;
                memcpy(&g, &gm[i], 8);
                memcpy(&r, &rm[i], 8);
                g = (g & ~pick) | (one & press & pick);
                r = (r & ~pick) | (((up & press) | (relax & ~press)) & pick);
                memcpy(&gm[i], &g, 8);
                memcpy(&rm[i], &r, 8);
                hm[i] ^= change;
            }
        }
        Py_END_ALLOW_THREADS
    }
    release(b, 8);
    Py_RETURN_NONE;
fail:
    release(b, 8);
    return NULL;
}

static PyMethodDef methods[] = {
    {"observe_v1", observe_v1, METH_VARARGS, observe_v1_doc},
    {"hold_keys", hold_keys, METH_VARARGS, hold_keys_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_cvector", "The vector env's keys and Reach-v1's observations in C (see armgame/env/vector.py).",
    -1, methods,
};

PyMODINIT_FUNC PyInit__cvector(void)
{
    PyObject *m = PyModule_Create(&module);
    /* VERSION changes with the calling convention, so a stale build is refused, not misread. */
    if (m != NULL && PyModule_AddIntConstant(m, "VERSION", 1) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
