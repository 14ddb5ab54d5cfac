/* A replay's timeline in two passes, as armgame.records' Python ones make them, for the games with many events.
 *
 * ``read_events`` is the fast test of replay._timeline_from_list: each [step, key, action] a list of an exact
 * int, a known key and a known action, steps never going back and at most the last step, made into InputEvent
 * as that loop makes it (object.__new__, then object.__setattr__ of each field). At the first event the test refuses it
 * returns that event's index, and the Python loop reads the timeline again and names what is wrong.
 *
 * ``forms_text`` is identity._both_forms for a game that ran to its end, returning the JSON text
 * (json.dumps with separators (",", ":")) of its three lists: the held runs, the resets and version 1's
 * events. It returns None wherever its C types cannot hold what Python's would (a step past int64, more
 * than 62 muscles, an action neither "down" nor "up", a key that is not a str, steps going back), and the
 * caller runs the Python pass.
 *
 * Why: a bot's game has 15,000 events, and these two loops were half of what a class's server spent on it
 * (benchmarks/class_server.py); the results are the Python ones, which tests/test_timeline_native.py holds
 * equal on random timelines. An install without a C compiler runs the Python passes alone. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* A growing text buffer: ASCII only (every piece written here is digits, brackets and known names). */
typedef struct {
    char *data;
    Py_ssize_t size, capacity;
} Text;

static int text_reserve(Text *t, Py_ssize_t more)
{
    if (t->size + more <= t->capacity)
        return 0;
    Py_ssize_t capacity = t->capacity ? t->capacity : 256;
    while (capacity < t->size + more)
        capacity *= 2;
    char *data = PyMem_Realloc(t->data, (size_t)capacity);
    if (data == NULL) {
        PyErr_NoMemory();
        return -1;
    }
    t->data = data;
    t->capacity = capacity;
    return 0;
}

static int text_add(Text *t, const char *s, Py_ssize_t n)
{
    if (text_reserve(t, n) < 0)
        return -1;
    memcpy(t->data + t->size, s, (size_t)n);
    t->size += n;
    return 0;
}

static int text_int(Text *t, long long v)
{
    char digits[24];
    int n = sizeof digits;
    unsigned long long u = v < 0 ? 0ULL - (unsigned long long)v : (unsigned long long)v;
    do {
        digits[--n] = (char)('0' + u % 10);
        u /= 10;
    } while (u);
    if (v < 0)
        digits[--n] = '-';
    return text_add(t, digits + n, (Py_ssize_t)sizeof digits - n);
}

/* ``[a,b]`` after a comma where it is not the list's first. */
static int text_pair(Text *t, long long a, long long b)
{
    if (text_add(t, t->size > 1 ? ",[" : "[", t->size > 1 ? 2 : 1) < 0 || text_int(t, a) < 0
        || text_add(t, ",", 1) < 0 || text_int(t, b) < 0)
        return -1;
    return text_add(t, "]", 1);
}

/* ``[step,"name","action"]``, likewise. */
static int text_event(Text *t, long long step, const char *name, Py_ssize_t name_size, const char *action,
                      Py_ssize_t action_size)
{
    if (text_add(t, t->size > 1 ? ",[" : "[", t->size > 1 ? 2 : 1) < 0 || text_int(t, step) < 0
        || text_add(t, ",\"", 2) < 0 || text_add(t, name, name_size) < 0 || text_add(t, "\",\"", 3) < 0
        || text_add(t, action, action_size) < 0)
        return -1;
    return text_add(t, "\"]", 2);
}

static PyObject *text_close(Text *t)
{
    PyObject *out = NULL;
    if (text_add(t, "]", 1) == 0)
        out = PyUnicode_DecodeASCII(t->data, t->size, "strict");
    PyMem_Free(t->data);
    t->data = NULL;
    return out;
}

static PyObject *STEP, *KEY, *ACTION;

static PyObject *py_read_events(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *items, *keys, *actions, *event_type;
    long long last_step;
    if (!PyArg_ParseTuple(args, "O!O!O!LO!", &PyList_Type, &items, &PyFrozenSet_Type, &keys, &PyFrozenSet_Type,
                          &actions, &last_step, &PyType_Type, &event_type))
        return NULL;
    newfunc make = PyBaseObject_Type.tp_new;
    PyObject *nothing = PyTuple_New(0);
    if (nothing == NULL)
        return NULL;
    Py_ssize_t n = PyList_GET_SIZE(items);
    PyObject *events = PyTuple_New(n);
    if (events == NULL) {
        Py_DECREF(nothing);
        return NULL;
    }
    long long previous = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *item = PyList_GET_ITEM(items, i);
        int plain = 0;
        if (PyList_CheckExact(item) && PyList_GET_SIZE(item) == 3) {
            PyObject *step = PyList_GET_ITEM(item, 0), *key = PyList_GET_ITEM(item, 1);
            PyObject *action = PyList_GET_ITEM(item, 2);
            int overflow = 0;
            long long value = PyLong_CheckExact(step) ? PyLong_AsLongLongAndOverflow(step, &overflow) : 0;
            if (PyLong_CheckExact(step) && !overflow && !(value == -1 && PyErr_Occurred()) && previous <= value
                && value <= last_step && PyUnicode_CheckExact(key) && PySet_Contains(keys, key) == 1
                && PyUnicode_CheckExact(action) && PySet_Contains(actions, action) == 1) {
                /* object.__setattr__'s own path (the frozen class's __setattr__ refuses): the instance's values
                 * kept as Python keeps them, without a dict made for each. */
                PyObject *event = make((PyTypeObject *)event_type, nothing, NULL);
                if (event == NULL || PyObject_GenericSetAttr(event, STEP, step) < 0
                    || PyObject_GenericSetAttr(event, KEY, key) < 0
                    || PyObject_GenericSetAttr(event, ACTION, action) < 0) {
                    Py_XDECREF(event);
                    Py_DECREF(events);
                    Py_DECREF(nothing);
                    return NULL;
                }
                PyTuple_SET_ITEM(events, i, event);
                previous = value;
                plain = 1;
            }
            PyErr_Clear();
        }
        if (!plain) {
            Py_DECREF(events);
            Py_DECREF(nothing);
            return PyLong_FromSsize_t(i);
        }
    }
    Py_DECREF(nothing);
    return events;
}

/* An int field of an event as long long; 0 if it is not an exact int that fits (the caller gives up). */
static int event_step(PyObject *event, long long *step)
{
    PyObject *value = PyObject_GetAttr(event, STEP);
    if (value == NULL)
        return -1;
    int overflow = 0, ok = PyLong_CheckExact(value);
    if (ok) {
        *step = PyLong_AsLongLongAndOverflow(value, &overflow);
        ok = !overflow && !(*step == -1 && PyErr_Occurred());
    }
    Py_DECREF(value);
    PyErr_Clear();
    return ok;
}

/* 1: down, 0: up, 2: something else (the caller gives up), -1: an error. */
static int event_action(PyObject *event, PyObject *down, PyObject *up)
{
    PyObject *action = PyObject_GetAttr(event, ACTION);
    if (action == NULL)
        return -1;
    int which = 2;
    if (PyUnicode_CheckExact(action)) {
        if (PyUnicode_Compare(action, down) == 0)
            which = 1;
        else if (PyUnicode_Compare(action, up) == 0)
            which = 0;
    }
    Py_DECREF(action);
    PyErr_Clear();
    return which;
}

#define MAX_MUSCLES 62

static PyObject *py_forms_text(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *timeline, *muscle_keys, *reset_key, *toggle_key, *down, *up;
    long long steps;
    if (!PyArg_ParseTuple(args, "O!O!LUUUU", &PyTuple_Type, &timeline, &PyTuple_Type, &muscle_keys, &steps,
                          &reset_key, &toggle_key, &down, &up))
        return NULL;
    Py_ssize_t muscles = PyTuple_GET_SIZE(muscle_keys);
    if (muscles > MAX_MUSCLES)
        Py_RETURN_NONE;
    Text held_text = {0}, resets_text = {0}, events_text = {0};
    PyObject *out = NULL;
    int given_up = 0;
    if (text_add(&held_text, "[", 1) < 0 || text_add(&resets_text, "[", 1) < 0
        || text_add(&events_text, "[", 1) < 0)
        goto done;
    uint64_t held = 0, mask = 0;
    int has_pending = 0;
    long long pending = 0, reset_step = 0, reset_count = 0, last_step_seen = 0;
    int first = 1;
    Py_ssize_t n = PyTuple_GET_SIZE(timeline);
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *event = PyTuple_GET_ITEM(timeline, i);
        long long step;
        int ok = event_step(event, &step);
        if (ok < 0)
            goto done;
        if (!ok || (!first && step < last_step_seen)) {
            given_up = 1;
            goto done;
        }
        first = 0;
        last_step_seen = step;
        if (!has_pending || step != pending) {
            if (has_pending && held != mask && pending < steps) {
                if (text_pair(&held_text, pending, (long long)held) < 0)
                    goto done;
                mask = held;
            }
            pending = step;
            has_pending = 1;
        }
        if (step >= steps) {
            has_pending = 0;
            break;
        }
        PyObject *key = PyObject_GetAttr(event, KEY);
        if (key == NULL)
            goto done;
        if (!PyUnicode_CheckExact(key)) {
            Py_DECREF(key);
            given_up = 1;
            goto done;
        }
        Py_ssize_t m = -1;
        for (Py_ssize_t j = 0; j < muscles; j++)  /* the last muscle of a key, as a dict of them keeps it */
            if (PyUnicode_Compare(key, PyTuple_GET_ITEM(muscle_keys, j)) == 0)
                m = j;
        int is_reset = m < 0 && PyUnicode_Compare(key, reset_key) == 0;
        int is_toggle = m < 0 && !is_reset && PyUnicode_Compare(key, toggle_key) == 0;
        Py_DECREF(key);
        if (m < 0 && !is_reset && !is_toggle)
            continue;
        int action = event_action(event, down, up);
        if (action < 0)
            goto done;
        if (action == 2) {
            given_up = 1;
            goto done;
        }
        const char *action_name = action ? "down" : "up";
        Py_ssize_t action_size = action ? 4 : 2;
        if (m >= 0) {
            uint64_t bit = (uint64_t)1 << m;
            if (((held & bit) != 0) != action) {
                char name[24];
                int size = snprintf(name, sizeof name, "m%zd", m);
                if (text_event(&events_text, step, name, size, action_name, action_size) < 0)
                    goto done;
            }
            held = action ? held | bit : held & ~bit;
        }
        else if (action) {
            PyObject *which = is_reset ? reset_key : toggle_key;
            Py_ssize_t size;
            const char *name = PyUnicode_AsUTF8AndSize(which, &size);
            if (name == NULL)
                goto done;
            if (text_event(&events_text, step, name, size, action_name, action_size) < 0)
                goto done;
            if (is_reset) {
                if (reset_count > 0 && step != reset_step) {
                    if (text_pair(&resets_text, reset_step, reset_count) < 0)
                        goto done;
                    reset_count = 0;
                }
                reset_step = step;
                reset_count++;
            }
        }
    }
    if (has_pending && held != mask && pending < steps && text_pair(&held_text, pending, (long long)held) < 0)
        goto done;
    if (reset_count > 0 && text_pair(&resets_text, reset_step, reset_count) < 0)
        goto done;
    {
        PyObject *a = text_close(&held_text), *b = a ? text_close(&resets_text) : NULL;
        PyObject *c = b ? text_close(&events_text) : NULL;
        if (c != NULL)
            out = PyTuple_Pack(3, a, b, c);
        Py_XDECREF(a);
        Py_XDECREF(b);
        Py_XDECREF(c);
    }
done:
    PyMem_Free(held_text.data);
    PyMem_Free(resets_text.data);
    PyMem_Free(events_text.data);
    if (given_up && !PyErr_Occurred())
        Py_RETURN_NONE;
    return out;
}

static PyMethodDef methods[] = {
    {"read_events", py_read_events, METH_VARARGS,
     "read_events(items, keys, actions, last_step, event_type): the events as a tuple, or the index of the first "
     "one the fast test refuses."},
    {"forms_text", py_forms_text, METH_VARARGS,
     "forms_text(timeline, muscle_keys, steps, reset_key, toggle_key, down, up): the JSON text of the held runs, "
     "the resets and version 1's events, or None where the Python pass must run."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_ctimeline", "A replay's timeline read and its identity's forms in C (see the file).",
    -1, methods,
};

PyMODINIT_FUNC PyInit__ctimeline(void)
{
    STEP = PyUnicode_InternFromString("step");
    KEY = PyUnicode_InternFromString("key");
    ACTION = PyUnicode_InternFromString("action");
    if (STEP == NULL || KEY == NULL || ACTION == NULL)
        return NULL;
    PyObject *m = PyModule_Create(&module);
    /* VERSION changes with the calling convention, so a stale build is refused, not misread. */
    if (m != NULL && PyModule_AddIntConstant(m, "VERSION", 1) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
