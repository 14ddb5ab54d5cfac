/* The arm's sine for Python: ``sin_cos(x)``, ``sin(x)`` and ``cos(x)`` as armgame.physics.trig's pure
 * Python ones, from the C the compiled loops use (_trig.h), so the same bits (tests/test_trig.py holds
 * them equal). Why: the Python step of the arm takes four of them a step, and the Python ones cost
 * some 0.5 us each against 0.05 us here (benchmarks/trig_change.py); an install without a C compiler runs the Python ones, with the
 * same results. Built as the other extensions are, without contraction (setup.py). */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include "_trig.h"

static int as_double(PyObject *arg, double *x)
{
    if (PyFloat_CheckExact(arg)) {
        *x = PyFloat_AS_DOUBLE(arg);
        return 0;
    }
    *x = PyFloat_AsDouble(arg);
    return (*x == -1.0 && PyErr_Occurred()) ? -1 : 0;
}

static PyObject *py_sin_cos(PyObject *self, PyObject *arg)
{
    (void)self;
    double x, s, c;
    if (as_double(arg, &x) < 0)
        return NULL;
    arm_sin_cos(x, &s, &c);
    PyObject *so = PyFloat_FromDouble(s);
    if (so == NULL)
        return NULL;
    PyObject *co = PyFloat_FromDouble(c);
    if (co == NULL) {
        Py_DECREF(so);
        return NULL;
    }
    PyObject *pair = PyTuple_New(2);
    if (pair == NULL) {
        Py_DECREF(so);
        Py_DECREF(co);
        return NULL;
    }
    PyTuple_SET_ITEM(pair, 0, so);
    PyTuple_SET_ITEM(pair, 1, co);
    return pair;
}

/* sin x (which = 0) or cos x (1) of the argument. */
static PyObject *one(PyObject *arg, int which)
{
    double x, sc[2];
    if (as_double(arg, &x) < 0)
        return NULL;
    arm_sin_cos(x, &sc[0], &sc[1]);
    return PyFloat_FromDouble(sc[which]);
}

static PyObject *py_sin(PyObject *self, PyObject *arg)
{
    (void)self;
    return one(arg, 0);
}

static PyObject *py_cos(PyObject *self, PyObject *arg)
{
    (void)self;
    return one(arg, 1);
}

static PyMethodDef methods[] = {
    {"sin_cos", py_sin_cos, METH_O, "sin_cos(x) -> (sin x, cos x): armgame.physics.trig.sin_cos in C."},
    {"sin", py_sin, METH_O, "sin(x): armgame.physics.trig.sin in C."},
    {"cos", py_cos, METH_O, "cos(x): armgame.physics.trig.cos in C."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_ctrig", "The arm's sine in C (armgame.physics.trig).", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__ctrig(void)
{
    return PyModule_Create(&module);
}
