/* CenterOut-v1's vector env in C: ``LabSession._advance``'s loop (the muscles, the arm's step with the trial's
 * field, the speed guard, the shown hand and the task's hold and reach) for a batch of runs, and the v1
 * observation of each, blocks of runs stepping in the game's vector lanes (_ccenter_lanes.h); and a step's per-run
 * work around it: the actions' muscles (``act``, _creward.h), the dense reward
 * (``progress``, ``edges``: the single env's math.hypot, _pyhypot.h) and each ended trial's reach measures
 * (``measures``, _creach.h). ``armgame.env.center_out_batch`` drives it: it keeps each run's trials (the lab's
 * ``schedule``) and, at a trial's end, the outcome, its row of the lab's table and the next trial's
 * description; this loop stops a run there and is called again for the steps left.
 *
 * Why it equals the single env bit for bit: the step is _cstep.h's ``rk4_exact`` (the game's step; with a field,
 * ``loads``' accel, operation for operation), the shown hand is ``physics.hand.hand_xy`` (the C library's sin and
 * cos, as Python's ``math``), the displays are ``lab.perturbations``' transforms
 * as their ``plan`` numbers write them, and the rules' tests are ``Target.contains`` and ``_task_step``'s, in the
 * same order. The hand's sin and cos come in pairs from glibc's sincos only where this module's start found it
 * equal to sin and cos, bit for bit (_ckernel.c's check). setup.py builds this file with floating-point contraction
 * off. tests/test_env_center_out_batch.py compares every observation, reward, flag and info with Gymnasium's
 * ``SyncVectorEnv`` of single envs. */
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
#include "../game/_lanes.h"
#include "_pyhypot.h"

/* Columns of a run's float state, int state and trial (the Python side names them the same). */
enum { S_X = 0, S_A = 4, S_G = 8, S_R = 12, S_CX = 16, S_CY = 17, S_FW1 = 18, S_FW2 = 19, S_TRIG = 20, S_COUNT = 26 };
enum { I_STEPS, I_TOTAL, I_PHASE, I_COUNTER, I_GO, I_EVENT, I_PATH, I_TODO, I_START, I_FRESH, I_COUNT };
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

/* The step's arm and field code inlined into the run's loop (GCC, Clang): the calls of accel_full, four a step, cost
 * a tenth of the loop's time. */
#if defined(__GNUC__) || defined(__clang__)
#define RUN_FLATTEN __attribute__((flatten))
#else
#define RUN_FLATTEN
#endif

/* The hand's last sin and cos (of q1 and q1 + q2) with their angles, in the run's state from S_TRIG: the
 * observation's are the same where its angles are, bit for bit, and take them from here. */
static inline void keep_trig(double *s, double q1, double q12, double s1, double c1, double s12, double c12)
{
    double *k = s + S_TRIG;
    k[0] = q1;
    k[1] = q12;
    k[2] = s1;
    k[3] = c1;
    k[4] = s12;
    k[5] = c12;
}

/* sin and cos of q1 and q12, from the run's kept ones where their angles have the same bits. */
static inline void trig_of(const double *s, double q1, double q12, double *s1, double *c1, double *s12, double *c12)
{
    const double *k = s + S_TRIG;
    if (memcmp(&k[0], &q1, sizeof q1) == 0 && memcmp(&k[1], &q12, sizeof q12) == 0) {
        *s1 = k[2];
        *c1 = k[3];
        *s12 = k[4];
        *c12 = k[5];
        return;
    }
    sin_cos(q1, s1, c1);
    sin_cos(q12, s12, c12);
}

/* A run's counts while it steps (run's locals, which the lanes keep per lane). */
typedef struct {
    int64_t n, ran, phase, counter, steps, path;
} Walk;

/* A run's steps to run now (it[I_TODO], at most those left): sets up w and clears TODO. */
static inline void begin_walk(int64_t *it, Walk *w)
{
    int64_t n = it[I_TODO];
    if (it[I_TOTAL] - it[I_STEPS] < n)
        n = it[I_TOTAL] - it[I_STEPS];
    it[I_TODO] = 0;
    w->n = n;
    w->ran = 0;
    w->phase = it[I_PHASE];
    w->counter = it[I_COUNTER];
    w->steps = it[I_STEPS];
    w->path = it[I_PATH];
}

/* The run's counts back into its ints. */
static inline void end_walk(int64_t *it, const Walk *w)
{
    it[I_PHASE] = w->phase;
    it[I_COUNTER] = w->counter;
    it[I_STEPS] = w->steps;
    it[I_PATH] = w->path;
}

/* What follows a step's RK4 (x the new state, previous the one before it, loaded: the step had the trial's
 * field) is the guard, the shown hand and the task's hold and reach, in two parts around the hand's sin and cos, so
 * that the lanes take every lane's trig in one loop (``run_block``). ``count_step`` guards and counts the step: it
 * returns STEP_STOPPED where the guard stopped the run (it[I_EVENT] says so; x is put back), STEP_BLIND where the
 * hand is not looked at this step, else STEP_HAND: ``hand_step`` then takes the hand's trig. */
enum { STEP_HAND, STEP_BLIND, STEP_STOPPED };

static inline int count_step(double *s, int64_t *it, const double *t, Walk *w, double x[4], const double previous[4],
                             int loaded)
{
    const double limit = t[T_LIMIT];
    if (loaded && !(-limit <= x[2] && x[2] <= limit && -limit <= x[3] && x[3] <= limit)) {
        /* variant.guarded: the state is refused, the run keeps the last one and ends there. */
        s[S_FW1] = x[2];
        s[S_FW2] = x[3];
        memcpy(x, previous, 4 * sizeof(double));
        it[I_TOTAL] = w->steps;
        it[I_EVENT] = EVENT_STOPPED;
        return STEP_STOPPED;
    }
    w->steps++;
    w->ran++;
    if (w->phase == 0 && t[T_HOLD_AT_HOME] == 0.0 && (double)(w->counter + 1) < t[T_DELAY] && w->ran < w->n) {
        /* The go cue's wait with no hold at home, neither its last step nor the call's: the hand is not looked at
         * (the next step writes the cursor before anything reads it), and a pair of the C library's sincos is
         * a fifth of the loop's time. */
        w->counter++;
        return STEP_BLIND;
    }
    return STEP_HAND;
}

/* The step's shown hand and rules from the hand's trig (s1, c1 of x[0]; s12, c12 of x[0] + x[1]). Returns 1 where
 * the trial ends here (it[I_EVENT] says how), having put x and a where the end leaves them. */
static inline int hand_step(const double *p, double *s, int64_t *it, const double *t, double *xs, double *ys,
                            int64_t cap, Walk *w, double x[4], double a[4], double s1, double c1, double s12,
                            double c12)
{
    const double l1 = p[P_L1], l2 = p[P_L2];
    keep_trig(s, x[0], x[0] + x[1], s1, c1, s12, c12);
    double hx = l1 * c1 + l2 * c12, hy = l1 * s1 + l2 * s12;
    shown(t, w->phase, x[0], x[1], &hx, &hy);
    s[S_CX] = hx;
    s[S_CY] = hy;
    if (w->phase == 0) {
        const double dx = hx - t[T_HX], dy = hy - t[T_HY];
        w->counter = (t[T_HOLD_AT_HOME] == 0.0 || dx * dx + dy * dy <= t[T_HR] * t[T_HR]) ? w->counter + 1 : 0;
        if ((double)w->counter >= t[T_DELAY]) {
            w->phase = 1;
            it[I_GO] = it[I_START] = w->steps;
            w->counter = 0;
            xs[0] = hx;
            ys[0] = hy;
            w->path = 1;
        }
        return 0;
    }
    if (w->path < cap) {
        xs[w->path] = hx;
        ys[w->path] = hy;
    }
    w->path++;
    const double dx = hx - t[T_TX], dy = hy - t[T_TY];
    w->counter = dx * dx + dy * dy <= t[T_TR] * t[T_TR] ? w->counter + 1 : 0;
    const int hit = (double)w->counter >= t[T_HOLD];
    if (!hit && (double)(w->steps - it[I_GO]) < t[T_TIMEOUT])
        return 0;
    /* The trial's end: the arm goes home at rest and the muscles relax; the caller enters the next trial. */
    it[I_EVENT] = hit ? EVENT_HIT : EVENT_MISS;
    x[0] = t[T_HQ1];
    x[1] = t[T_HQ2];
    x[2] = x[3] = 0.0;
    a[0] = a[1] = a[2] = a[3] = 0.0;
    s[S_CX] = t[T_HX];
    s[S_CY] = t[T_HY];
    w->phase = 0;
    w->counter = 0;
    it[I_START] = w->steps;
    it[I_TODO] = w->n - w->ran;
    return 1;
}

/* Both parts for one run: returns 1 where the run stops here (a trial's end or the guard's stop). */
static inline int after_step(const double *p, double *s, int64_t *it, const double *t, double *xs, double *ys,
                             int64_t cap, Walk *w, double x[4], double a[4], const double previous[4], int loaded)
{
    const int kind = count_step(s, it, t, w, x, previous, loaded);
    if (kind != STEP_HAND)
        return kind == STEP_STOPPED;
    double s1, c1, s12, c12;
    sin_cos(x[0], &s1, &c1);
    sin_cos(x[0] + x[1], &s12, &c12);
    return hand_step(p, s, it, t, xs, ys, cap, w, x, a, s1, c1, s12, c12);
}

/* The trial's field, for ``rk4_exact``. */
static inline Field trial_field(const double *p, const double *t)
{
    const Field field = {(int)t[T_FIELD], {t[T_FP], t[T_FP + 1], t[T_FP + 2], t[T_FP + 3]}, p[P_L1], p[P_L2]};
    return field;
}

/* One run: up to it[I_TODO] steps, stopping after a trial's end or the guard's stop (it[I_EVENT] says which). */
RUN_FLATTEN static void run(const Arm *arm, const double *p, double *s, int64_t *it, const double *t, double *xs, double *ys,
                int64_t cap)
{
    Walk w;
    begin_walk(it, &w);
    if (w.n <= 0)
        return;
    const double dt = p[P_DT];
    double *x = s + S_X;
    double a[4] = {s[S_A], s[S_A + 1], s[S_A + 2], s[S_A + 3]};
    const double *g = s + S_G, *r = s + S_R;
    const Field field = trial_field(p, t);
    while (w.ran < w.n) {
        double t1, t2;
        muscle_step(p, a, g, r, &t1, &t2);
        const int loaded = w.phase == 1 && field.kind != FIELD_NONE;
        double previous[4];
        memcpy(previous, x, sizeof previous);
        if (loaded)
            rk4_exact(arm, &field, t1, t2, dt, x);
        else  /* apart, so that the inlined step without a field has no test of one */
            rk4_exact(arm, NULL, t1, t2, dt, x);
        if (after_step(p, s, it, t, xs, ys, cap, &w, x, a, previous, loaded))
            break;
    }
    memcpy(s + S_A, a, sizeof a);
    end_walk(it, &w);
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

/* center_out_v1.CenterOutV1Env._observation of a run into o, in its order; it clears the run's FRESH. */
static inline void observe(const double *p, const double *s, int64_t *it, const double *t, double *o)
{
    const double l1 = p[P_L1], l2 = p[P_L2];
    it[I_FRESH] = 0;
    const double q1 = s[0], q2 = s[1], w1 = s[2], w2 = s[3];
    const double q12 = q1 + q2, w12 = w1 + w2;
    double c1, s1, c12, s12;
    trig_of(s, q1, q12, &s1, &c1, &s12, &c12);
    const int reach = it[I_PHASE] == 1;
    const double cx = s[S_CX], cy = s[S_CY];
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
    o[15] = (double)(it[I_STEPS] - it[I_START]) * p[P_DT];
}

/* The runs in vector lanes: run_block, and the path lines it prefetches. */
#include "_ccenter_lanes.h"

PyDoc_STRVAR(advance_doc,
"advance(params, mode, state, ints, trials, xs, ys, obs) -> int\n\n"
"Run every run of the batch its ints[:, TODO] steps (stopping at a trial's end or the guard's stop, which\n"
"ints[:, EVENT] says, with the steps left in TODO), then fill obs (n, 16 float64) with the v1 observation\n"
"of each run that ran or has ints[:, FRESH] set (which it clears). Returns how many runs stopped at an event.");

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
        Py_BEGIN_ALLOW_THREADS
        /* The lanes take blocks of runs where most of a block has steps to run (a step's first call); the runs
         * left, and the calls for the few runs a trial's end stopped, run one at a time. */
        const int lanes = mode != MODE_GRAVITY;  /* accel_lanes has no gravity */
        Py_ssize_t blocked = 0;
        for (Py_ssize_t i0 = 0; lanes && i0 + LANES <= n; i0 += LANES) {
            int due = 0;
            for (int l = 0; l < LANES; l++) {
                const int64_t *it = ints + I_COUNT * (i0 + l);
                due += it[I_EVENT] == EVENT_NONE && it[I_TODO] > 0;
            }
            if (2 * due < LANES)
                continue;
            for (int l = 0; l < LANES; l++) {  /* run_block clears TODO: the observation's test reads it first */
                int64_t *it = ints + I_COUNT * (i0 + l);
                it[I_FRESH] |= it[I_TODO] > 0;
            }
            if (i0 + 2 * LANES <= n)
                prefetch_paths(ints, xs, ys, cap, i0 + LANES);
            run_block(&arm, p, mode, state, ints, trials, xs, ys, cap, i0);
            blocked++;
        }
        (void)blocked;
        for (Py_ssize_t i = 0; i < n; i++) {
            double *s = state + S_COUNT * i;
            int64_t *it = ints + I_COUNT * i;
            const double *t = trials + T_COUNT * i;
            /* A run's observation changes only when it runs or the caller changed it (FRESH): called again within a
             * step for the runs a trial's end stopped, the loop leaves the others' as they are. */
            const int touched = it[I_TODO] > 0 || it[I_FRESH] != 0;
            if (it[I_EVENT] == EVENT_NONE && it[I_TODO] > 0)
                run(&arm, p, s, it, t, xs + cap * i, ys + cap * i, cap);
            events += it[I_EVENT] != EVENT_NONE;
            if (!touched)
                continue;
            observe(p, s, it, t, obs + 16 * i);
        }
        Py_END_ALLOW_THREADS
    }
    release(b, 8);
    return PyLong_FromSsize_t(events);
fail:
    release(b, 8);
    return NULL;
}

/* The reach measures (lab.metrics.reach_metrics, bit for bit): _creach.h. */
#include "_creach.h"

PyDoc_STRVAR(measures_doc,
"measures(xs, ys, runs, samples, go, geometry, out) -> None\n\n"
"For each ended trial k: lab.metrics.reach_metrics of run runs[k]'s path (xs, ys (n, cap) float64, its first\n"
"samples[k] points, the first at step go[k]), geometry[k] = (dt, home x, home y, target x, target y), written\n"
"to out[k] (reaction time, movement time, peak speed, direction error, perpendicular error, path ratio).");

static PyObject *measures(PyObject *self, PyObject *args)
{
    PyObject *obj[7];
    Buffer b[7] = {{{0}}};
    double *work = NULL;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOOO", &obj[0], &obj[1], &obj[2], &obj[3], &obj[4], &obj[5], &obj[6]))
        return NULL;
    const Py_ssize_t k = PyObject_Length(obj[2]);
    if (k < 0 || take(obj[2], &b[2], "runs", 'q', k) < 0 || take(obj[3], &b[3], "samples", 'q', k) < 0
        || take(obj[4], &b[4], "go", 'q', k) < 0 || take(obj[5], &b[5], "geometry", 'd', 5 * k) < 0
        || take(obj[6], &b[6], "out", 'd', M_COUNT * k) < 0)
        goto fail;
    for (int j = 0; j < 2; j++) {
        if (PyObject_GetBuffer(obj[j], &b[j].view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0)
            goto fail;
        b[j].held = 1;
    }
    const Py_ssize_t rows = PyObject_Length(obj[0]);
    const int64_t cap = rows > 0 ? b[0].view.len / (8 * rows) : 0;
    if (rows <= 0 || b[0].view.itemsize != 8 || b[0].view.len != cap * 8 * rows || b[1].view.len != b[0].view.len) {
        PyErr_SetString(PyExc_ValueError, "xs and ys must be (n, cap) float64 paths");
        goto fail;
    }
    const int64_t *runs = b[2].view.buf, *samples = b[3].view.buf, *go = b[4].view.buf;
    for (Py_ssize_t j = 0; j < k; j++)
        if (runs[j] < 0 || runs[j] >= rows || samples[j] < 0 || samples[j] > cap) {
            PyErr_SetString(PyExc_ValueError, "runs and samples must be within the paths");
            goto fail;
        }
    work = PyMem_Malloc((size_t)(6 * cap + 6) * sizeof(double));
    if (work == NULL) {
        PyErr_NoMemory();
        goto fail;
    }
    const double *xs = b[0].view.buf, *ys = b[1].view.buf, *geometry = b[5].view.buf;
    double *out = b[6].view.buf;
    for (Py_ssize_t j = 0; j < k; j++) {
        const double *g = geometry + 5 * j;
        reach_measures(xs + cap * runs[j], ys + cap * runs[j], samples[j], go[j], g[0], g + 1, g + 3,
                       out + M_COUNT * j, work);
    }
    PyMem_Free(work);
    release(b, 7);
    Py_RETURN_NONE;
fail:
    PyMem_Free(work);
    release(b, 7);
    return NULL;
}

#include "_creward.h"

static PyMethodDef methods[] = {
    {"advance", advance, METH_VARARGS, advance_doc},
    {"measures", measures, METH_VARARGS, measures_doc},
    {"act", act, METH_VARARGS, act_doc},
    {"edges", edges, METH_VARARGS, edges_doc},
    {"progress", progress, METH_VARARGS, progress_doc},
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
