/* Plans rolled out from one state: the reference controller's search (armgame/env/ceiling.py).
 *
 * A plan is a bang-bang command per joint: one muscle of the pair fully on for n1 decisions, its
 * antagonist for n2, then both off. ``shoot`` rolls many plans out from the same state on the game's
 * own step (GameSession._advance: torque from the activations, the muscles' first-order step, then
 * integrators._rk4 with the field's torque at each stage where one is given: ``rk4_exact``, the step
 * rk4_step_loaded takes), and reports where each first satisfies the game's hit (the hand in the disc,
 * for ``hold`` physics steps in a row: rules.DwellRules' count), so that a plan's predicted hit is the
 * game's, to the physics step, wherever nothing the plan cannot know (motor noise) intervenes.
 *
 * Why C: a search rolls out thousands of plans of up to a hundred decisions for every target; in numpy
 * that is hundreds of calls a physics step, in Python floats minutes a game.
 */
#include "_ckernel.h"

/* The most physics steps one call may run over all its plans: bounds the work of any call before it starts
 * (a search of this module's controller runs about 10^6). */
#define MAX_SHOOT_STEPS 2.0e9
/* A plan's counts of decisions (beyond the horizon they are never reached: a caller may cut a search short). */
#define MAX_PLAN_DECISIONS 1000000

/* The squared distance of the rules' hand (rules.hand_position: the arm's own sine) from (tx, ty). */
static inline double hand_distance2(double l1, double l2, double q1, double q2, double tx, double ty)
{
    double sa, ca, sb, cb;
    arm_sin_cos(q1, &sa, &ca);
    arm_sin_cos(q1 + q2, &sb, &cb);
    const double dx = l1 * ca + l2 * cb - tx, dy = l1 * sa + l2 * sb - ty;
    return dx * dx + dy * dy;
}

const char armgame_shoot_doc[] =
"shoot(params, mode, rates, field, x0, act0, plans, substeps, horizon, target, hold, dwelt, box, out) -> None\n\n"
"Roll each plan out from state x0 (4 float64: q1 q2 w1 w2) and activations act0 (4 float64). plans: (N, 6)\n"
"int64 rows (shoulder sign, n1, n2, elbow sign, n1, n2): a joint's first muscle (sign 1; its second, -1) is\n"
"pressed for n1 decisions of ``substeps`` physics steps, the other for n2, then both released, for at most\n"
"``horizon`` decisions (counts 0 to 1e6: past the horizon they are never reached, so a caller may cut a search\n"
"short). rates: 8 float64, the muscles' rise then decay rates a step; field: 5 float64 (kind 0 none, 1 curl\n"
"b = p0, 2 viscous ((p0, p1), (p2, p3)); then p0-p3); target: 3 float64 (x, y, radius squared); hold: the\n"
"physics steps the hand must stay in the disc (1: entering it), dwelt: steps it has stayed already; box: 4\n"
"float64 (q1 low, high, q2 low, high) a plan may not leave. out: (N, 6) float64, each plan's physics step of\n"
"the hit counted from the start (-1: none within the horizon, -2: it left the box), the state then (or at its\n"
"end) and the hand's distance from the target's centre then. params: the kernel's P_* doubles (the arm, dt,\n"
"lengths, moments). Refused (ValueError): anything not finite, counts out of range, more than 2e9 physics\n"
"steps in all.";

PyObject *armgame_shoot(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *obj[10];
    int mode;
    Py_ssize_t substeps, horizon, hold, dwelt;
    if (!PyArg_ParseTuple(args, "OiOOOOOnnOnnOO", &obj[0], &mode, &obj[1], &obj[2], &obj[3], &obj[4], &obj[5],
                          &substeps, &horizon, &obj[6], &hold, &dwelt, &obj[7], &obj[8]))
        return NULL;
    Buf b[9];
    memset(b, 0, sizeof b);
    PyObject *result = NULL;
    const Py_ssize_t D = sizeof(double);
    if (get(obj[0], &b[0], P_COUNT, D, 0, "params") < 0 || get(obj[1], &b[1], 8, D, 0, "rates") < 0
        || get(obj[2], &b[2], 5, D, 0, "field") < 0 || get(obj[3], &b[3], 4, D, 0, "x0") < 0
        || get(obj[4], &b[4], 4, D, 0, "act0") < 0 || get(obj[5], &b[5], -1, 6 * (Py_ssize_t)sizeof(int64_t), 0,
                                                          "plans") < 0
        || get(obj[6], &b[6], 3, D, 0, "target") < 0 || get(obj[7], &b[7], 4, D, 0, "box") < 0)
        goto done;
    const Py_ssize_t n = b[5].view.len / (6 * (Py_ssize_t)sizeof(int64_t));
    if (get(obj[8], &b[8], 6 * n, D, 1, "out") < 0)
        goto done;
    const double *p = b[0].view.buf, *rates = b[1].view.buf, *fv = b[2].view.buf, *x0 = b[3].view.buf;
    const double *act0 = b[4].view.buf, *tv = b[6].view.buf, *box = b[7].view.buf;
    const int64_t *plans = b[5].view.buf;
    double *out = b[8].view.buf;
    if (check_params("shoot", p, 1) < 0)
        goto done;
    if (mode < MODE_UNFORCED || mode > MODE_GRAVITY || substeps < 1 || horizon < 1 || hold < 1 || dwelt < 0
        || (double)n * (double)horizon * (double)substeps > MAX_SHOOT_STEPS) {
        PyErr_SetString(PyExc_ValueError, "shoot: expected mode 0-2, substeps, horizon and hold >= 1, dwelt >= 0 "
                                          "and at most 2e9 physics steps in all");
        goto done;
    }
    const double *checked[6] = {rates, fv, x0, act0, tv, box};
    const int sizes[6] = {8, 5, 4, 4, 3, 4};
    const char *names[6] = {"rates", "field", "x0", "act0", "target", "box"};
    for (int j = 0; j < 6; j++) {
        for (int i = 0; i < sizes[j]; i++) {
            if (!isfinite(checked[j][i])) {
                PyErr_Format(PyExc_ValueError, "shoot: %s is not finite", names[j]);
                goto done;
            }
        }
    }
    if (fv[0] != FIELD_NONE && fv[0] != FIELD_CURL && fv[0] != FIELD_VISCOUS) {
        PyErr_SetString(PyExc_ValueError, "shoot: field kind must be 0 (none), 1 (curl) or 2 (viscous)");
        goto done;
    }
    for (Py_ssize_t i = 0; i < 6 * n; i++) {
        const int64_t v = plans[i];
        if ((i % 3 == 0) ? (v != 1 && v != -1) : (v < 0 || v > MAX_PLAN_DECISIONS)) {
            PyErr_SetString(PyExc_ValueError, "shoot: a plan's signs must be 1 or -1 and its counts 0 to 1e6");
            goto done;
        }
    }
    const Arm arm = {p[P_B], p[P_D], p[P_DET0], p[P_AMD], p[P_G1], p[P_G2], p[P_K1], p[P_K2], mode};
    const Field field_value = {(int)fv[0], {fv[1], fv[2], fv[3], fv[4]}, p[P_L1], p[P_L2]};
    const Field *field = field_value.kind == FIELD_NONE ? NULL : &field_value;
    const double dt = p[P_DT], l1 = p[P_L1], l2 = p[P_L2];
    const double tx = tv[0], ty = tv[1], rr = tv[2];
    const double s[4] = {p[P_S0], p[P_S1], p[P_S2], p[P_S3]}, e[4] = {p[P_E0], p[P_E1], p[P_E2], p[P_E3]};
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t i = 0; i < n; i++) {
        const int64_t *plan = plans + 6 * i;
        double x[4] = {x0[0], x0[1], x0[2], x0[3]};
        double a[4] = {act0[0], act0[1], act0[2], act0[3]};
        Py_ssize_t inside = dwelt, step = 0;
        double hit = -1.0;
        for (Py_ssize_t k = 0; k < horizon && hit == -1.0; k++) {
            /* Each joint's muscle pressed this decision: +1 its first, -1 its second, 0 neither. */
            int pressed[2];
            for (int j = 0; j < 2; j++) {
                const int64_t sign = plan[3 * j], n1 = plan[3 * j + 1], n2 = plan[3 * j + 2];
                pressed[j] = k < n1 ? (int)sign : (k < n1 + n2 ? -(int)sign : 0);
            }
            const int down[4] = {pressed[0] > 0, pressed[0] < 0, pressed[1] > 0, pressed[1] < 0};
            double g[4], r[4];
            for (int m = 0; m < 4; m++) {
                g[m] = down[m] ? 1.0 : 0.0;
                r[m] = down[m] ? rates[m] : rates[4 + m];
            }
            for (Py_ssize_t j = 0; j < substeps; j++) {
                const double t1 = a[0] * s[0] + a[1] * s[1] + a[2] * s[2] + a[3] * s[3];
                const double t2 = a[0] * e[0] + a[1] * e[1] + a[2] * e[2] + a[3] * e[3];
                for (int m = 0; m < 4; m++)
                    a[m] += (g[m] - a[m]) * r[m];
                rk4_exact(&arm, field, t1, t2, dt, x);
                step++;
                if (!(x[0] >= box[0] && x[0] <= box[1] && x[1] >= box[2] && x[1] <= box[3])) {
                    hit = -2.0;  /* out of the box, or not finite */
                    break;
                }
                if (hand_distance2(l1, l2, x[0], x[1], tx, ty) <= rr) {
                    if (++inside >= hold) {
                        hit = (double)step;
                        break;
                    }
                } else {
                    inside = 0;
                }
            }
        }
        double *o = out + 6 * i;
        o[0] = hit;
        o[1] = x[0];
        o[2] = x[1];
        o[3] = x[2];
        o[4] = x[3];
        o[5] = sqrt(hand_distance2(l1, l2, x[0], x[1], tx, ty));
    }
    Py_END_ALLOW_THREADS
    Py_INCREF(Py_None);
    result = Py_None;
done:
    release(b, 9);
    return result;
}
