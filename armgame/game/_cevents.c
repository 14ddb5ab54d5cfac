/* The events of a batch's timelines as columns, for schedule.py's _event_columns: the one pass over every
 * event that stayed in Python (a bot's 15,000 events, 3 ms; a fifth of a class server's time for a hand-in).
 *
 * event_columns(timelines, codes, down) -> (steps, code, is_down) as bytearrays of int64, int64 and bool
 * (numpy reads them in place), or None where an event's step is not an exact int that fits int64 (the
 * Python pass then clips it, as it always has). ``codes`` maps a key to its code; a key not in it is -1.
 * The same columns as the Python pass (tests/test_schedule.py holds them equal). */
#include "_ckernel.h"

const char armgame_event_columns_doc[] =
    "event_columns(timelines, codes, down): each event's step, code and whether it is a key going down, as "
    "int64, int64 and bool bytes, in order; None where a step is past int64 (the Python pass clips it).";

static PyObject *step_name, *key_name, *action_name;

static int names(void)
{
    if (step_name == NULL) {
        step_name = PyUnicode_InternFromString("step");
        key_name = PyUnicode_InternFromString("key");
        action_name = PyUnicode_InternFromString("action");
    }
    return step_name && key_name && action_name ? 0 : -1;
}

/* One event into the columns at ``at``: 1 done, 0 the caller hands back to Python, -1 an error. */
static int one_event(PyObject *event, PyObject *codes, PyObject *down, int64_t *step_out, int64_t *code_out,
                     char *down_out)
{
    PyObject *step = PyObject_GetAttr(event, step_name);
    if (step == NULL)
        return -1;
    int overflow = 0;
    long long value = PyLong_CheckExact(step) ? PyLong_AsLongLongAndOverflow(step, &overflow) : 0;
    int fits = PyLong_CheckExact(step) && !overflow && !(value == -1 && PyErr_Occurred());
    Py_DECREF(step);
    if (!fits) {
        PyErr_Clear();
        return 0;
    }
    PyObject *key = PyObject_GetAttr(event, key_name);
    if (key == NULL)
        return -1;
    PyObject *code = PyDict_GetItemWithError(codes, key);  /* borrowed */
    Py_DECREF(key);
    long long code_value = -1;
    if (code != NULL) {
        code_value = PyLong_AsLongLong(code);
        if (code_value == -1 && PyErr_Occurred())
            return -1;
    }
    else if (PyErr_Occurred())
        return -1;
    PyObject *action = PyObject_GetAttr(event, action_name);
    if (action == NULL)
        return -1;
    int is_down = PyObject_RichCompareBool(action, down, Py_EQ);
    Py_DECREF(action);
    if (is_down < 0)
        return -1;
    *step_out = (int64_t)value;
    *code_out = (int64_t)code_value;
    *down_out = (char)is_down;
    return 1;
}

PyObject *armgame_event_columns(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *timelines, *codes, *down;
    if (!PyArg_ParseTuple(args, "OO!O", &timelines, &PyDict_Type, &codes, &down) || names() < 0)
        return NULL;
    PyObject *games = PySequence_Fast(timelines, "timelines must be a sequence");
    if (games == NULL)
        return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(games), count = 0;
    PyObject **game = PySequence_Fast_ITEMS(games);
    PyObject *fast = PyList_New(n);  /* each timeline as a fast sequence, kept while the columns are filled */
    PyObject *steps = NULL, *code = NULL, *is_down = NULL, *out = NULL;
    if (fast == NULL)
        goto done;
    for (Py_ssize_t g = 0; g < n; g++) {
        PyObject *events = PySequence_Fast(game[g], "a timeline must be a sequence");
        if (events == NULL)
            goto done;
        PyList_SET_ITEM(fast, g, events);
        count += PySequence_Fast_GET_SIZE(events);
    }
    steps = PyByteArray_FromStringAndSize(NULL, count * (Py_ssize_t)sizeof(int64_t));
    code = PyByteArray_FromStringAndSize(NULL, count * (Py_ssize_t)sizeof(int64_t));
    is_down = PyByteArray_FromStringAndSize(NULL, count);
    if (steps == NULL || code == NULL || is_down == NULL)
        goto done;
    int64_t *step_column = (int64_t *)PyByteArray_AS_STRING(steps);
    int64_t *code_column = (int64_t *)PyByteArray_AS_STRING(code);
    char *down_column = PyByteArray_AS_STRING(is_down);
    Py_ssize_t at = 0;
    for (Py_ssize_t g = 0; g < n; g++) {
        PyObject *events = PyList_GET_ITEM(fast, g);
        Py_ssize_t size = PySequence_Fast_GET_SIZE(events);
        PyObject **items = PySequence_Fast_ITEMS(events);
        for (Py_ssize_t i = 0; i < size; i++, at++) {
            int done = one_event(items[i], codes, down, step_column + at, code_column + at, down_column + at);
            if (done < 0)
                goto done;
            if (done == 0) {
                out = Py_None;
                Py_INCREF(out);
                goto done;
            }
        }
    }
    out = PyTuple_Pack(3, steps, code, is_down);
done:
    Py_XDECREF(steps);
    Py_XDECREF(code);
    Py_XDECREF(is_down);
    Py_XDECREF(fast);
    Py_DECREF(games);
    return out;
}
