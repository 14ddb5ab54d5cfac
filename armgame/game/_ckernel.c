/* The game's hot loop, compiled: muscles, RK4 and the hand's slack for many games (``run``), and
 * the single session's loop for one game (``game_steps``), one RK4 step (``rk4_step``, the lab's) and
 * one arm's run of RK4 steps under given torques (``rk4_run``, the benchmark's table).
 *
 * Why C: a batch of a thousand games in numpy pays about 140 calls of call overhead per
 * physics step, and Python floats pay the interpreter per operation; here each game runs its
 * own steps in registers. Why it equals the single session bit for bit: every expression is
 * ``GameSession._advance``'s, ``integrators._rk4``'s and ``TwoJointArm``'s accel, with the same
 * IEEE double operations in the same order (C evaluates a + b + c as (a + b) + c, as Python
 * does); the joint angles' cos and sin are the arm's own (``arm_sin_cos``, physics/_trig.h, which is
 * ``physics.trig.sin_cos`` operation for operation), and so, since armgame 0.4, are the hand's where a hit
 * is decided on them (``game_steps``: ``rules.hand_position``). The batch's "near" filters (``run``,
 * _clanes.c) and the observations' trig (``write_trig``) keep the C library's, as Python's ``math`` is:
 * the filters only pick which hands Python tests (with a margin far above the two sines' few-ulp
 * difference), and the observations are not the rules. The build (setup.py) turns off floating-point
 * contraction, so no multiply-add is fused, and the builtin sin and cos, so the compiler cannot merge
 * them into a ``sincos`` of its own choosing; the file calls glibc's sincos itself only where it has
 * checked it (``sin_cos`` below).
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
#include "_ckernel.h"

int armgame_use_sincos = 0;

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
    /* GameSession._advance's loop: _cstep.h's game_loop, which any build of the game compiles. */
    Game game = {{v[0], v[1], v[2], v[3]}, {v[4], v[5], v[6], v[7]}, {v[0], v[1], v[2], v[3]}, 0.0, 0.0};
    int flagged = 0;
    const Py_ssize_t ran = (Py_ssize_t)game_loop(&arm, p, v + 8, v + 12, v[16], v[17], v[18], (int64_t)n, &game,
                                                 &flagged);
    PyObject *out = PyTuple_New(16);
    if (out == NULL)
        return NULL;
    const double *x = game.x, *previous = game.previous, *a = game.a;
    const double values[14] = {x[0], x[1], x[2], x[3], previous[0], previous[1], previous[2], previous[3],
                               a[0], a[1], a[2], a[3], game.hx, game.hy};
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
    rk4_exact(&arm, NULL, v[4], v[5], v[6], x);
    return Py_BuildValue("(dddd)", x[0], x[1], x[2], x[3]);
}

PyDoc_STRVAR(rk4_step_loaded_doc,
"rk4_step_loaded(params, mode, kind, p0, p1, p2, p3, q1, q2, w1, w2, t1, t2, dt) -> (q1, q2, w1, w2)\n\n"
"rk4_step with a field at the hand: loads.loaded_arm's RK4 step, its operations in order (the hand's cos\n"
"and sin the C library's, as Python's math is there). kind 1: the curl field of b = p0; 2: the viscous\n"
"field of the matrix ((p0, p1), (p2, p3)). The arm's lengths are the params'. Refused (ValueError): a value\n"
"or param not finite, another kind.");

static PyObject *rk4_step_loaded(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    double p[P_COUNT], v[12];
    Arm arm;
    if (one_game_args("rk4_step_loaded", args, nargs, 14, p, &arm, 2, 12, v,
                      "kind p0 p1 p2 p3 q1 q2 w1 w2 t1 t2 dt", 0) < 0)
        return NULL;
    if (v[0] != FIELD_CURL && v[0] != FIELD_VISCOUS) {
        PyErr_SetString(PyExc_ValueError, "rk4_step_loaded: kind must be 1 (curl) or 2 (viscous)");
        return NULL;
    }
    const Field field = {(int)v[0], {v[1], v[2], v[3], v[4]}, p[P_L1], p[P_L2]};
    double x[4] = {v[5], v[6], v[7], v[8]};
    rk4_exact(&arm, &field, v[9], v[10], v[11], x);
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
        rk4_exact(&arm, NULL, tq[2 * row], tq[2 * row + 1], dt, x);
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
    {"run", armgame_run, METH_VARARGS, armgame_run_doc},
    {"shoot", armgame_shoot, METH_VARARGS, armgame_shoot_doc},
    {"rk4_step_loaded", (PyCFunction)(void (*)(void))rk4_step_loaded, METH_FASTCALL, rk4_step_loaded_doc},
    {"event_columns", armgame_event_columns, METH_VARARGS, armgame_event_columns_doc},
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
    armgame_use_sincos = sincos_agrees();
    PyObject *m = PyModule_Create(&module);
    /* VERSION changes with the calling convention, so a stale build is refused, not misread. */
    if (m != NULL && (PyModule_AddIntConstant(m, "PARAMS", P_COUNT) < 0
                      || PyModule_AddIntConstant(m, "VERSION", 7) < 0
                      || PyModule_AddIntConstant(m, "SINCOS", armgame_use_sincos) < 0)) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
