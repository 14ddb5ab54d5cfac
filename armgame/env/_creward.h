/* A step's actions and dense reward for CenterOut's batch: included by _ccenter.c (after its buffers, ``take`` and
 * ``release``), whose module gives ``act``, ``progress`` and ``edges`` to armgame.env.center_out_batch. Kept apart so
 * that _ccenter.c holds the runs' loop and this file the per-run work around it. */
#ifndef ARMGAME_CENTER_REWARD_H
#define ARMGAME_CENTER_REWARD_H

/* ---------------------------------------------------------------- a step's actions and dense reward
 * The per-run work of a step that the Python side did in numpy and per env: the action's muscles
 * (``CenterOutV1Env._press_keys`` and ``_set_levels``) and the distance the dense reward measures
 * (``CenterOutV1Env._edge``: math.hypot, _pyhypot.h). */

/* A read-only contiguous buffer of count items of itemsize bytes (its format is the caller's to read). */
static int take_items(PyObject *obj, Buffer *buf, const char *name, Py_ssize_t itemsize, Py_ssize_t count,
                      int writable)
{
    if (PyObject_GetBuffer(obj, &buf->view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0)) < 0)
        return -1;
    buf->held = 1;
    if (buf->view.itemsize != itemsize || buf->view.len != count * itemsize) {
        PyErr_Format(PyExc_ValueError, "%s: expected a contiguous array of %zd items of %zd bytes", name, count,
                     itemsize);
        return -1;
    }
    return 0;
}

/* An action's value k of run i as a double, from its buffer's format (float64, float32, int64 or one byte). */
static inline double action_at(const void *a, char kind, Py_ssize_t k)
{
    switch (kind) {
    case 'd':
        return ((const double *)a)[k];
    case 'f':
        return (double)((const float *)a)[k];
    case 'q':
        return (double)((const int64_t *)a)[k];
    default:
        return (double)((const uint8_t *)a)[k];
    }
}

/* new where mask is all ones, else old, bit for bit. */
static inline double blend(double old, double new_value, uint64_t mask)
{
    uint64_t a, b;
    memcpy(&a, &old, sizeof a);
    memcpy(&b, &new_value, sizeof b);
    a = (a & ~mask) | (b & mask);
    memcpy(&old, &a, sizeof old);
    return old;
}

/* ``act``'s work for one kind of action (a constant where inlined): the whole action checked before any run's
 * muscles change, as the Python step raised before them; then each stepping run's goals and rates. */
LANES_INLINE int act_runs(const void *a, const char kind, const int continuous, Py_ssize_t n, const uint8_t *stepping,
                          const uint8_t *finished, const int64_t *ints, uint8_t *held, double *state,
                          const double *rise, const double *decay, const int64_t *task_of)
{
    int ok = 1;
    for (Py_ssize_t i = 0; i < n && ok; i++) {
        if (!stepping[i])
            continue;
        for (int m = 0; m < 4; m++) {
            const double v = action_at(a, kind, 4 * i + m);
            ok &= continuous ? isfinite(v) : ((v == 0.0) | (v == 1.0));
        }
    }
    if (!ok)
        return 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        const int64_t *it = ints + I_COUNT * i;
        if (!stepping[i] || finished[i] || it[I_STEPS] >= it[I_TOTAL])
            continue;
        double *s = state + S_COUNT * i;
        const double *up_rate = rise + 4 * task_of[i], *down_rate = decay + 4 * task_of[i];
        for (int m = 0; m < 4; m++) {
            const double v = action_at(a, kind, 4 * i + m);
            if (continuous) {
                /* np.clip((level + 1) / 2 as * 0.5, 0, 1); the rate rises where the goal is above the activation. */
                double level = (v + 1.0) * 0.5;
                level = level < 0.0 ? 0.0 : level > 1.0 ? 1.0 : level;
                s[S_R + m] = blend(down_rate[m], up_rate[m], (uint64_t)0 - (uint64_t)(level > s[S_A + m]));
                s[S_G + m] = level;
            } else {
                /* A key held, or left up, leaves its muscle going on as it was; a press or a release sets its goal
                 * and rate. Chosen by masks, with no branch: random keys change half the time, and a mispredicted
                 * branch a key made this loop seven times as slow (0.18 ms against 0.025 at 8,192 runs). */
                const uint8_t down = v == 1.0;
                const uint64_t change = (uint64_t)0 - (uint64_t)(down != (held[4 * i + m] != 0));
                const uint64_t pressed = (uint64_t)0 - (uint64_t)down;
                held[4 * i + m] = down;
                s[S_G + m] = blend(s[S_G + m], (double)down, change);
                s[S_R + m] = blend(s[S_R + m], blend(down_rate[m], up_rate[m], pressed), change);
            }
        }
    }
    return 1;
}

PyDoc_STRVAR(act_doc,
"act(actions, continuous, stepping, finished, ints, held, state, rise, decay, task_of) -> bool\n\n"
"The single env's _set_levels (continuous) or _press_keys on every run that steps (stepping) and is not over:\n"
"actions (n, 4) float64, float32, int64 or one-byte; held (n, 4) bool, the keys down; rise and decay (tasks, 4)\n"
"float64, each run's task's rates by task_of. Returns False, changing nothing, where a stepping run's action\n"
"is not finite (continuous) or not 0 or 1 (keys).");

static PyObject *act(PyObject *self, PyObject *args)
{
    PyObject *obj[10];
    int continuous;
    Buffer b[10] = {{{0}}};
    (void)self;
    if (!PyArg_ParseTuple(args, "OpOOOOOOOO", &obj[0], &continuous, &obj[1], &obj[2], &obj[3], &obj[4], &obj[5],
                          &obj[6], &obj[7], &obj[8]))
        return NULL;
    const Py_ssize_t n = PyObject_Length(obj[1]);
    const Py_ssize_t tasks = PyObject_Length(obj[6]);
    if (n < 0 || tasks < 0)
        goto fail;
    if (PyObject_GetBuffer(obj[0], &b[0].view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0)
        goto fail;
    b[0].held = 1;
    const char *f = b[0].view.format ? b[0].view.format : "B";
    if (f[0] == '<' || f[0] == '=' || f[0] == '@')
        f++;
    char kind = 0;
    if (strcmp(f, "d") == 0 || strcmp(f, "f") == 0 || strcmp(f, "q") == 0)
        kind = f[0];
    else if (strcmp(f, "l") == 0 && b[0].view.itemsize == 8)
        kind = 'q';
    else if ((strcmp(f, "B") == 0 || strcmp(f, "?") == 0) && !continuous)
        kind = 'B';
    if (kind == 0 || b[0].view.len != n * 4 * b[0].view.itemsize) {
        PyErr_SetString(PyExc_ValueError, "actions: expected (n, 4) float64, float32, int64 or one-byte values");
        goto fail;
    }
    if (take_items(obj[1], &b[1], "stepping", 1, n, 0) < 0 || take_items(obj[2], &b[2], "finished", 1, n, 0) < 0
        || take(obj[3], &b[3], "ints", 'q', n * I_COUNT) < 0 || take_items(obj[4], &b[4], "held", 1, n * 4, 1) < 0
        || take(obj[5], &b[5], "state", 'd', n * S_COUNT) < 0 || take(obj[6], &b[6], "rise", 'd', tasks * 4) < 0
        || take(obj[7], &b[7], "decay", 'd', tasks * 4) < 0 || take(obj[8], &b[8], "task_of", 'q', n) < 0)
        goto fail;
    const uint8_t *stepping = b[1].view.buf, *finished = b[2].view.buf;
    const int64_t *ints = b[3].view.buf, *task_of = b[8].view.buf;
    uint8_t *held = b[4].view.buf;
    double *state = b[5].view.buf;
    const double *rise = b[6].view.buf, *decay = b[7].view.buf;
    const void *a = b[0].view.buf;
    for (Py_ssize_t i = 0; i < n; i++)
        if (task_of[i] < 0 || task_of[i] >= tasks) {
            PyErr_SetString(PyExc_ValueError, "task_of: a run's task is not in rise and decay");
            goto fail;
        }
    int ok;
    /* One loop for each kind of action, so that the element's type is known inside it. */
    if (kind == 'd')
        ok = continuous ? act_runs(a, 'd', 1, n, stepping, finished, ints, held, state, rise, decay, task_of)
                        : act_runs(a, 'd', 0, n, stepping, finished, ints, held, state, rise, decay, task_of);
    else if (kind == 'f')
        ok = continuous ? act_runs(a, 'f', 1, n, stepping, finished, ints, held, state, rise, decay, task_of)
                        : act_runs(a, 'f', 0, n, stepping, finished, ints, held, state, rise, decay, task_of);
    else if (kind == 'q')
        ok = continuous ? act_runs(a, 'q', 1, n, stepping, finished, ints, held, state, rise, decay, task_of)
                        : act_runs(a, 'q', 0, n, stepping, finished, ints, held, state, rise, decay, task_of);
    else
        ok = act_runs(a, 'B', 0, n, stepping, finished, ints, held, state, rise, decay, task_of);
    release(b, 10);
    return PyBool_FromLong(ok);
fail:
    release(b, 10);
    return NULL;
}

/* A run's cursor distance to its shown target's edge: the single env's max(0.0, math.hypot(dx, dy) - radius). */
static inline double edge_of(const double *o, const int64_t *it, const double *t)
{
    const double radius = it[I_PHASE] == 1 ? t[T_TR] : t[T_HR];
    const double e = py_hypot(o[12], o[13]) - radius;
    return e > 0.0 ? e : 0.0;  /* Python's max(0.0, e): 0.0 unless e is above it */
}

PyDoc_STRVAR(progress_doc,
"progress(obs, ints, trials, trial, shown, edge, stepping, out) -> None\n\n"
"The dense reward's progress of every run (CenterOutV1Env._dense_reward's): its last edge (edge) less its edge now\n"
"where it shows the same target as then (shown (n, 2) int64: the trial and phase it showed; trial: the trial under\n"
"way), else 0.0, into out; and, for the runs that stepped, edge and shown set to now's.");

static PyObject *progress(PyObject *self, PyObject *args)
{
    PyObject *obj[8];
    Buffer b[8] = {{{0}}};
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOOOO", &obj[0], &obj[1], &obj[2], &obj[3], &obj[4], &obj[5], &obj[6], &obj[7]))
        return NULL;
    const Py_ssize_t n = PyObject_Length(obj[1]);
    if (n < 0 || take(obj[0], &b[0], "obs", 'd', n * 16) < 0 || take(obj[1], &b[1], "ints", 'q', n * I_COUNT) < 0
        || take(obj[2], &b[2], "trials", 'd', n * T_COUNT) < 0 || take(obj[3], &b[3], "trial", 'q', n) < 0
        || take(obj[4], &b[4], "shown", 'q', 2 * n) < 0 || take(obj[5], &b[5], "edge", 'd', n) < 0
        || take_items(obj[6], &b[6], "stepping", 1, n, 0) < 0 || take(obj[7], &b[7], "out", 'd', n) < 0)
        goto fail;
    const double *obs = b[0].view.buf, *trials = b[2].view.buf;
    const int64_t *ints = b[1].view.buf, *trial = b[3].view.buf;
    int64_t *shown = b[4].view.buf;
    double *edge = b[5].view.buf, *out = b[7].view.buf;
    const uint8_t *stepping = b[6].view.buf;
    for (Py_ssize_t i = 0; i < n; i++) {
        const int64_t *it = ints + I_COUNT * i;
        const double now = edge_of(obs + 16 * i, it, trials + T_COUNT * i);
        const int same = shown[2 * i] == trial[i] && shown[2 * i + 1] == it[I_PHASE];
        out[i] = same ? edge[i] - now : 0.0;
        if (stepping[i]) {
            edge[i] = now;
            shown[2 * i] = trial[i];
            shown[2 * i + 1] = it[I_PHASE];
        }
    }
    release(b, 8);
    Py_RETURN_NONE;
fail:
    release(b, 8);
    return NULL;
}

PyDoc_STRVAR(edges_doc,
"edges(obs, ints, trials, runs, out) -> None\n\n"
"Each run's cursor distance to its shown target's edge, max(0.0, math.hypot(obs[:, 12], obs[:, 13]) - radius)\n"
"(the target's radius in a reach, else home's), bit for bit: of runs (int64) into out, or of every run where\n"
"runs is None.");

static PyObject *edges(PyObject *self, PyObject *args)
{
    PyObject *obj[5];
    Buffer b[5] = {{{0}}};
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOO", &obj[0], &obj[1], &obj[2], &obj[3], &obj[4]))
        return NULL;
    const Py_ssize_t n = PyObject_Length(obj[1]);
    if (n < 0 || take(obj[0], &b[0], "obs", 'd', n * 16) < 0 || take(obj[1], &b[1], "ints", 'q', n * I_COUNT) < 0
        || take(obj[2], &b[2], "trials", 'd', n * T_COUNT) < 0)
        goto fail;
    Py_ssize_t k = n;
    const int64_t *runs = NULL;
    if (obj[3] != Py_None) {
        k = PyObject_Length(obj[3]);
        if (k < 0 || take(obj[3], &b[3], "runs", 'q', k) < 0)
            goto fail;
        runs = b[3].view.buf;
        for (Py_ssize_t j = 0; j < k; j++)
            if (runs[j] < 0 || runs[j] >= n) {
                PyErr_SetString(PyExc_ValueError, "runs must be within the batch");
                goto fail;
            }
    }
    if (take(obj[4], &b[4], "out", 'd', k) < 0)
        goto fail;
    const double *obs = b[0].view.buf, *trials = b[2].view.buf;
    const int64_t *ints = b[1].view.buf;
    double *out = b[4].view.buf;
    for (Py_ssize_t j = 0; j < k; j++) {
        const Py_ssize_t i = runs ? runs[j] : j;
        out[j] = edge_of(obs + 16 * i, ints + I_COUNT * i, trials + T_COUNT * i);
    }
    release(b, 5);
    Py_RETURN_NONE;
fail:
    release(b, 5);
    return NULL;
}

#endif
