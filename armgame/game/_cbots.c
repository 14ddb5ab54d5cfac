/* The bots' forward model, compiled: ``InternalModel.predict`` (armgame/game/bots.py) in C.
 *
 * Why C: a bot re-predicts the arm over a reaction time (about 62 steps of 4 ms) before every
 * decision, so a lab run of the adapting bot spends three quarters of its time in that loop, at
 * about 2 us a step in Python. Why it equals the Python loop bit for bit: every expression is
 * ``InternalModel.predict``'s and the lab bot's curl estimate's (armgame/lab/bots.py), the same
 * IEEE double operations in the same order, with the C library's sin and cos (which Python's
 * ``math`` calls); setup.py builds this file, as ``_ckernel.c``, with floating-point contraction
 * and the compiler's builtin sin and cos turned off. The tests compare both loops with ``==``.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>

PyDoc_STRVAR(predict_doc,
"predict(state, rows, period, a, b, d, k1, k2, interaction, curl_b, l1, l2) -> (q1, q2, w1, w2)\n\n"
"Step state (q1, q2, w1, w2) through rows (sequences whose last two items are the torques t1, t2),\n"
"each held period s, by the internal model's accel and semi-implicit Euler; with curl_b not None,\n"
"adding the curl field estimate J^T curl_b (vy, -vx) of arm links l1, l2 to the torques.");

static int as_double(PyObject *item, double *out)
{
    *out = PyFloat_AsDouble(item);
    return (*out == -1.0 && PyErr_Occurred()) ? -1 : 0;
}

static PyObject *predict(PyObject *self, PyObject *args)
{
    PyObject *state, *rows, *curl;
    double period, a, b, d, k1, k2, l1, l2;
    int interaction;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOddddddpOdd", &state, &rows, &period, &a, &b, &d, &k1, &k2, &interaction,
                          &curl, &l1, &l2))
        return NULL;
    double q1, q2, w1, w2, cb = 0.0;
    int load = curl != Py_None;
    if (load && as_double(curl, &cb) < 0)
        return NULL;
    PyObject *s = PySequence_Fast(state, "state must be a sequence of 4 numbers");
    if (s == NULL)
        return NULL;
    if (PySequence_Fast_GET_SIZE(s) != 4) {
        Py_DECREF(s);
        PyErr_SetString(PyExc_ValueError, "state must be a sequence of 4 numbers");
        return NULL;
    }
    PyObject **sv = PySequence_Fast_ITEMS(s);
    int bad = as_double(sv[0], &q1) || as_double(sv[1], &q2) || as_double(sv[2], &w1) || as_double(sv[3], &w2);
    Py_DECREF(s);
    if (bad)
        return NULL;
    PyObject *seq = PySequence_Fast(rows, "rows must be a sequence");
    if (seq == NULL)
        return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    PyObject **items = PySequence_Fast_ITEMS(seq);
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *row = PySequence_Fast(items[i], "each row must be a sequence ending in two torques");
        if (row == NULL)
            goto fail;
        Py_ssize_t m = PySequence_Fast_GET_SIZE(row);
        double t1, t2;
        if (m < 2) {
            Py_DECREF(row);
            PyErr_SetString(PyExc_ValueError, "each row must be a sequence ending in two torques");
            goto fail;
        }
        PyObject **rv = PySequence_Fast_ITEMS(row);
        bad = as_double(rv[m - 2], &t1) || as_double(rv[m - 1], &t2);
        Py_DECREF(row);
        if (bad)
            goto fail;
        if (load) {
            /* lab/bots.py's load(): the hand Jacobian once, the field at the predicted velocity. */
            double s12 = sin(q1 + q2), c12 = cos(q1 + q2);
            double jx1 = -l1 * sin(q1) - l2 * s12, jy1 = l1 * cos(q1) + l2 * c12;
            double jx2 = -l2 * s12, jy2 = l2 * c12;
            double fx = cb * (jy1 * w1 + jy2 * w2);
            double fy = cb * -(jx1 * w1 + jx2 * w2);
            double e1 = jx1 * fx + jy1 * fy, e2 = jx2 * fx + jy2 * fy;
            t1 = t1 + e1;
            t2 = t2 + e2;
        }
        double a1, a2;
        if (interaction) {
            double h = b * sin(q2);
            double f1 = t1 - (-h * (2.0 * w1 * w2 + w2 * w2) + k1 * w1);
            double f2 = t2 - (h * w1 * w1 + k2 * w2);
            double bc = b * cos(q2);
            double m11 = a + 2.0 * bc;
            double m12 = d + bc;
            double r = 1.0 / (m11 * d - m12 * m12);
            a1 = (d * f1 - m12 * f2) * r;
            a2 = (m11 * f2 - m12 * f1) * r;
        } else {
            double f1 = t1 - k1 * w1, f2 = t2 - k2 * w2;
            a1 = f1 / (a + 2.0 * (b * cos(q2)));
            a2 = f2 / d;
        }
        w1 += a1 * period;
        w2 += a2 * period;
        q1 += w1 * period;
        q2 += w2 * period;
    }
    Py_DECREF(seq);
    return Py_BuildValue("(dddd)", q1, q2, w1, w2);
fail:
    Py_DECREF(seq);
    return NULL;
}

static PyMethodDef methods[] = {
    {"predict", predict, METH_VARARGS, predict_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_cbots", "The bots' forward model in C (see armgame/game/bots.py).", -1, methods,
};

PyMODINIT_FUNC PyInit__cbots(void)
{
    PyObject *m = PyModule_Create(&module);
    /* VERSION changes with the calling convention, so a stale build is refused, not misread. */
    if (m != NULL && PyModule_AddIntConstant(m, "VERSION", 1) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
