/* The batch's loop (``_ckernel.run``): many games, each from its step to its halt, with its muscle
 * commands applied at their steps, stopped early when its hand may be on its target.
 *
 * Two loops compute the same thing. ``armgame_run_lanes`` (_clanes.c) steps LANES games side by side, one array per
 * quantity with a game per element (structure of arrays), so that every arithmetic line is one loop
 * over the lanes that the compiler turns into vector instructions (SSE2's two doubles, AVX2's four,
 * AVX-512's eight, where the CPU has them: _clanes.c's ``LANES_CLONES``); a lane whose game ends takes the next game, so the lanes
 * stay full whatever the games' lengths. ``run_scalar`` runs one game at a time (the loop before
 * the lanes; the arm with gravity, whose cos q1 and cos(q1 + q2) the lanes do not compute, runs it).
 *
 * Why the lanes equal the single session bit for bit: vectorising across games changes no game's
 * operations or their order, only how many games one instruction serves. Addition, multiplication,
 * division and sqrt are correctly rounded IEEE operations whether scalar or vector, the build turns
 * off contraction (no fused multiply-add is formed from a * b + c) and fast-math (no reassociation),
 * and the arm's sin and cos (``arm_sin_cos``, physics/_trig.h) are made of those operations alone, so they
 * vectorise too: the exact kernel computes them four times a step for every lane at once. The fast
 * kernel (``fast``) needs them once in 32 steps and carries them by angle addition in between.
 */
#include "_ckernel.h"

/* One game at a time: the loop the lanes replaced, kept for the arm with gravity and as their reference
 * (``run(..., lanes=False)``). */
static Py_ssize_t run_scalar(const Batch *B)
{
    const Arm arm = B->arm;
    const int fast = B->fast;
    const Py_ssize_t n = B->n;
    double *x = B->x;
    const double dt = B->dt, h = B->h, k = B->k, l1 = B->l1, l2 = B->l2, radius = B->radius, near = B->near;
    const double reach1 = B->reach1, reach2 = B->reach2, limit2 = B->limit2;
    Py_ssize_t flagged = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        int64_t s = B->steps[i], c = B->cursor[i];
        const int64_t stop = B->halt[i], end = B->ev_end[i];
        B->flags[i] = 0;
        if (s >= stop && (c >= end || B->ev_step[c] > s))
            continue;
        double q1 = x[i], q2 = x[n + i], w1 = x[2 * n + i], w2 = x[3 * n + i];
        double bc = 0.0, bs = 0.0;  /* the fast kernel's b cos q2, b sin q2, carried from step to step */
        int anchor = 0;  /* steps left before they are computed in full again; none at a game's start */
        double a[4], g[4], r[4];
        for (int m = 0; m < 4; m++) {
            a[m] = B->act[m * n + i];
            g[m] = B->goal[m * n + i];
            r[m] = B->rate[m * n + i];
        }
        double sl = B->slack[i];
        const double x0 = B->tx[i], y0 = B->ty[i];
        for (;;) {
            while (c < end && B->ev_step[c] <= s) {
                g[B->ev_muscle[c]] = B->ev_goal[c];
                r[B->ev_muscle[c]] = B->ev_rate[c];
                c++;
            }
            if (s >= stop)
                break;
            /* GameSession._advance: torque from the activations, then the muscles step. */
            const double t1 = a[0] * B->s[0] + a[1] * B->s[1] + a[2] * B->s[2] + a[3] * B->s[3];
            const double t2 = a[0] * B->e[0] + a[1] * B->e[1] + a[2] * B->e[2] + a[3] * B->e[3];
            for (int m = 0; m < 4; m++)
                a[m] += (g[m] - a[m]) * r[m];
            /* integrators._rk4 */
            const double p1 = q1, p2 = q2;
            /* Stage 1's elbow trig: in full, or in the fast kernel carried from the last step. */
            if (!fast || anchor <= 0) {
                double sn, cs;
                arm_sin_cos(q2, &sn, &cs);
                bc = arm.b * cs;
                bs = arm.b * sn;
                anchor = REANCHOR;
            }
            anchor--;
            double a1, a2, b1, b2, c1, c2, d1, d2, ec, es;
            accel_trig(&arm, q1, q2, bc, bs, w1, w2, t1, t2, &a1, &a2);
            const double v1 = w1 + h * a1;
            const double v2 = w2 + h * a2;
            const double q2b = q2 + h * w2;
            elbow(&arm, fast, q2b, h * w2, bc, bs, limit2, &ec, &es);
            accel_trig(&arm, q1 + h * w1, q2b, ec, es, v1, v2, t1, t2, &b1, &b2);
            const double u1 = w1 + h * b1;
            const double u2 = w2 + h * b2;
            const double q2c = q2 + h * v2;
            elbow(&arm, fast, q2c, h * v2, bc, bs, limit2, &ec, &es);
            accel_trig(&arm, q1 + h * v1, q2c, ec, es, u1, u2, t1, t2, &c1, &c2);
            const double z1 = w1 + dt * c1;
            const double z2 = w2 + dt * c2;
            const double q2d = q2 + dt * u2;
            elbow(&arm, fast, q2d, dt * u2, bc, bs, limit2, &ec, &es);
            accel_trig(&arm, q1 + dt * u1, q2d, ec, es, z1, z2, t1, t2, &d1, &d2);
            q1 = p1 + k * (w1 + z1 + 2.0 * (v1 + u1));
            q2 = p2 + k * (w2 + z2 + 2.0 * (v2 + u2));
            const double n1 = w1 + k * (a1 + d1 + 2.0 * (b1 + c1));
            const double n2 = w2 + k * (a2 + d2 + 2.0 * (b2 + c2));
            w1 = n1;
            w2 = n2;
            s++;
            /* The next step's elbow trig: this one's turned by the step's change of q2. */
            if (fast && !turned(bc, bs, q2 - p2, limit2, &bc, &bs))
                anchor = 0;
            /* A lower bound on the hand's distance from the disc, lowered by a bound on its move;
             * measured only when it runs out (see NumpyKernel.run). */
            sl -= fabs(q1 - p1) * reach1 + fabs(q2 - p2) * reach2;
            if (sl < 0.0) {
                double sa, ca, sb, cb;
                sin_cos(q1, &sa, &ca);
                sin_cos(q1 + q2, &sb, &cb);
                const double dx = l1 * ca + l2 * cb - x0;
                const double dy = l1 * sa + l2 * sb - y0;
                const double d2h = dx * dx + dy * dy;
                sl = sqrt(d2h) - radius - 1e-9;
                if (d2h <= near) {
                    B->flags[i] = 1;
                    flagged++;
                    break;
                }
            }
        }
        x[i] = q1;
        x[n + i] = q2;
        x[2 * n + i] = w1;
        x[3 * n + i] = w2;
        for (int m = 0; m < 4; m++) {
            B->act[m * n + i] = a[m];
            B->goal[m * n + i] = g[m];
            B->rate[m * n + i] = r[m];
        }
        B->slack[i] = sl;
        B->steps[i] = s;
        B->cursor[i] = c;
        write_trig(B, i, q1, q2);
    }
    return flagged;
}

const char armgame_run_doc[] =
"run(params, mode, fast, n, x, act, goal, rate, slack, tx, ty, steps, halt, cursor, ev_end, ev_step, ev_muscle,\n"
"    ev_goal, ev_rate, flags, trig, lanes) -> int\n\n"
"Step every game i from steps[i] up to halt[i], applying its muscle events on the way, and\n"
"stop it early after a step that leaves its hand near its target (flags[i] = 1). Returns how\n"
"many games were flagged. Arrays: x (4+, n) float64 rows q1 q2 w1 w2; act, goal, rate (4, n);\n"
"slack, tx, ty (n,); steps, halt, cursor, ev_end (n,) int64; game i's events are\n"
"cursor[i]:ev_end[i] of ev_step (int64), ev_muscle (int64, 0-3), ev_goal, ev_rate (float64),\n"
"sorted by step; an event at step s applies before the step from s; flags (n,) uint8.\n"
"trig (6, n) float64 or None: for every game stepped, cos q1, sin q1, cos(q1 + q2), sin(q1 + q2)\n"
"after its last step (the C library's) and the q1, q2 they are of.\n"
"With fast true, RK4's elbow trig comes by angle addition (the numpy fast kernel's method):\n"
"round-off, not bit for bit. lanes: step several games side by side (the same results; false: one\n"
"at a time, the reference). Refused before any step (ValueError): params not finite or dt not positive,\n"
"steps or halt outside 0 to the steps of a 24 h game at dt, a command's goal or rate not finite.\n\n"
"moments (8, n) float64 or None: each game's muscle moments, rows shoulder s0-s3 then elbow e0-e3, in\n"
"place of the params' (motor noise). loads (6,) float64 or None: the field at the hand, kind (0 none,\n"
"1 curl: F = b [[0, 1], [-1, 0]] v, 2 viscous: F = B v), its parameters (b, 0, 0, 0 or b11 b12 b21 b22)\n"
"and the speed guard (rad/s, inf: none): a game whose joint speed passes it after a step stops there,\n"
"flags[i] = 2, its state that step's. Both need the lanes and an arm without gravity.";

PyObject *armgame_run(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *obj[20];
    int mode, fast, lanes;
    Py_ssize_t n;
    obj[18] = obj[19] = Py_None;
    if (!PyArg_ParseTuple(args, "OipnOOOOOOOOOOOOOOOOOp|OO", &obj[0], &mode, &fast, &n, &obj[1], &obj[2], &obj[3],
                          &obj[4], &obj[5], &obj[6], &obj[7], &obj[8], &obj[9], &obj[10], &obj[11], &obj[12],
                          &obj[13], &obj[14], &obj[15], &obj[16], &obj[17], &lanes, &obj[18], &obj[19]))
        return NULL;
    /* n bounded first: every size below is n times at most 4 * 8 bytes, which must not overflow (a wrapped
       n * D of 0 would divide by zero below: SIGFPE, the process gone). */
    if (mode < MODE_UNFORCED || mode > MODE_GRAVITY || n < 1 || n > PY_SSIZE_T_MAX / (4 * (Py_ssize_t)sizeof(double))) {
        PyErr_Format(PyExc_ValueError, "mode %d, %zd games: expected mode 0, 1 or 2 and at least one game, at most %zd", mode,
                     n, PY_SSIZE_T_MAX / (4 * (Py_ssize_t)sizeof(double)));
        return NULL;
    }
    const int with_trig = obj[17] != Py_None, with_moments = obj[18] != Py_None, with_loads = obj[19] != Py_None;
    Buf b[20];
    memset(b, 0, sizeof b);
    PyObject *result = NULL;
    const Py_ssize_t D = sizeof(double), I = sizeof(int64_t);
    /* x (rows q1 q2 w1 w2) may carry scratch rows after the state's four. */
    if (get(obj[0], &b[0], P_COUNT, D, 0, "params") < 0 || get(obj[1], &b[1], -1, D, 1, "x") < 0)
        goto done;
    if (b[1].view.len % (n * D) || b[1].view.len / (n * D) < 4) {
        PyErr_Format(PyExc_ValueError, "x: %zd bytes, expected (rows >= 4, %zd) float64", b[1].view.len, n);
        goto done;
    }
    if (get(obj[2], &b[2], 4 * n, D, 1, "act") < 0 || get(obj[3], &b[3], 4 * n, D, 1, "goal") < 0
        || get(obj[4], &b[4], 4 * n, D, 1, "rate") < 0 || get(obj[5], &b[5], n, D, 1, "slack") < 0
        || get(obj[6], &b[6], n, D, 0, "tx") < 0 || get(obj[7], &b[7], n, D, 0, "ty") < 0
        || get(obj[8], &b[8], n, I, 1, "steps") < 0 || get(obj[9], &b[9], n, I, 0, "halt") < 0
        || get(obj[10], &b[10], n, I, 1, "cursor") < 0 || get(obj[11], &b[11], n, I, 0, "ev_end") < 0
        || get(obj[12], &b[12], -1, I, 0, "ev_step") < 0)
        goto done;
    const Py_ssize_t events = b[12].view.len / I;
    if (get(obj[13], &b[13], events, I, 0, "ev_muscle") < 0 || get(obj[14], &b[14], events, D, 0, "ev_goal") < 0
        || get(obj[15], &b[15], events, D, 0, "ev_rate") < 0 || get(obj[16], &b[16], n, 1, 1, "flags") < 0)
        goto done;
    if (with_trig && get(obj[17], &b[17], 6 * n, D, 1, "trig") < 0)
        goto done;
    if ((with_moments && get(obj[18], &b[18], 8 * n, D, 0, "moments") < 0)
        || (with_loads && get(obj[19], &b[19], 6, D, 0, "loads") < 0))
        goto done;
    const double *loads = with_loads ? b[19].view.buf : NULL;
    if ((with_moments || with_loads) && (!lanes || mode == MODE_GRAVITY)) {
        PyErr_SetString(PyExc_ValueError, "run: moments and loads need the lanes and an arm without gravity");
        goto done;
    }
    if (loads != NULL && !((loads[0] == FIELD_NONE || loads[0] == FIELD_CURL || loads[0] == FIELD_VISCOUS)
                           && isfinite(loads[1]) && isfinite(loads[2]) && isfinite(loads[3]) && isfinite(loads[4])
                           && loads[5] > 0.0)) {
        PyErr_SetString(PyExc_ValueError, "run: loads: expected kind 0, 1 or 2, finite parameters and a guard "
                                          "above 0 (inf: none)");
        goto done;
    }
    if (with_moments) {
        const double *m = b[18].view.buf;
        for (Py_ssize_t j = 0; j < 8 * n; j++) {
            if (!isfinite(m[j])) {
                PyErr_Format(PyExc_ValueError, "run: moments: game %zd's are not finite", j % n);
                goto done;
            }
        }
    }

    const double *p = b[0].view.buf;
    if (check_params("run", p, 1) < 0)
        goto done;
    Batch B = {
        .arm = {p[P_B], p[P_D], p[P_DET0], p[P_AMD], p[P_G1], p[P_G2], p[P_K1], p[P_K2], mode},
        .fast = fast, .n = n,
        .x = b[1].view.buf, .act = b[2].view.buf, .goal = b[3].view.buf, .rate = b[4].view.buf,
        .slack = b[5].view.buf, .tx = b[6].view.buf, .ty = b[7].view.buf,
        .steps = b[8].view.buf, .halt = b[9].view.buf, .cursor = b[10].view.buf, .ev_end = b[11].view.buf,
        .ev_step = b[12].view.buf, .ev_muscle = b[13].view.buf, .ev_goal = b[14].view.buf,
        .ev_rate = b[15].view.buf, .flags = b[16].view.buf,
        .trig = with_trig ? b[17].view.buf : NULL,
        .dt = p[P_DT], .h = p[P_H], .k = p[P_K], .l1 = p[P_L1], .l2 = p[P_L2], .radius = p[P_RADIUS],
        .near = p[P_NEAR], .reach1 = p[P_REACH1], .reach2 = p[P_REACH2], .limit2 = p[P_LIMIT2],
        .s = {p[P_S0], p[P_S1], p[P_S2], p[P_S3]}, .e = {p[P_E0], p[P_E1], p[P_E2], p[P_E3]},
        .mom = with_moments ? b[18].view.buf : NULL,
        .field = {FIELD_NONE, {0.0, 0.0, 0.0, 0.0}, p[P_L1], p[P_L2]},
        .limit = loads != NULL ? loads[5] : INFINITY,
    };
    if (loads != NULL) {
        B.field.kind = (int)loads[0];
        for (int j = 0; j < 4; j++)
            B.field.p[j] = loads[1 + j];
    }

    /* The work is bounded before it starts: cursors within the events, muscles 0-3, finite commands, and
     * every game's steps and halt from 0 to a game's most steps at this dt. */
    const double most = max_steps(p[P_DT]);
    for (Py_ssize_t i = 0; i < n; i++) {
        if (B.cursor[i] < 0 || B.cursor[i] > B.ev_end[i] || B.ev_end[i] > events) {
            PyErr_Format(PyExc_ValueError, "game %zd: events %lld:%lld of %zd", i, (long long)B.cursor[i],
                         (long long)B.ev_end[i], events);
            goto done;
        }
        if (B.steps[i] < 0 || B.halt[i] < 0 || (double)B.steps[i] > most || (double)B.halt[i] > most) {
            char message[200];  /* PyErr_Format has no %g */
            snprintf(message, sizeof message,
                     "run: game %zd: steps %lld, halt %lld: expected 0 to %.15g (%g s at dt %g)", i,
                     (long long)B.steps[i], (long long)B.halt[i], most, MAX_GAME_SECONDS, p[P_DT]);
            PyErr_SetString(PyExc_ValueError, message);
            goto done;
        }
    }
    for (Py_ssize_t e = 0; e < events; e++) {
        if (B.ev_muscle[e] < 0 || B.ev_muscle[e] > 3) {
            PyErr_Format(PyExc_ValueError, "event %zd: muscle %lld", e, (long long)B.ev_muscle[e]);
            goto done;
        }
        if (!isfinite(B.ev_goal[e]) || !isfinite(B.ev_rate[e])) {
            PyErr_Format(PyExc_ValueError, "event %zd: its goal or rate is not finite", e);
            goto done;
        }
    }
    Py_ssize_t flagged;
    Py_BEGIN_ALLOW_THREADS
    flagged = lanes && mode != MODE_GRAVITY ? armgame_run_lanes(&B) : run_scalar(&B);
    Py_END_ALLOW_THREADS
    result = PyLong_FromSsize_t(flagged);
done:
    release(b, 20);
    return result;
}
