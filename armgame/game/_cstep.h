/* The arm's step and the single game's loop in C, with no Python in it: what the compiled game (_ckernel.c),
 * the batch (_cbatch.c, _clanes.c), the plans' roll-outs (_cshoot.c) and any build for the browser (wasm)
 * compile from one source. Here: the params' layout, the arm's trig (physics/_trig.h) and accel, RK4
 * (``rk4_exact``), a field at the hand, the fast kernel's trig, the C library's sincos where checked, and
 * GameSession._advance's loop for one game (``game_loop``). Python's glue (argument checks, buffers,
 * errors) is _ckernel.h's. See _ckernel.c's opening comment for why each is exactly the Python it replaces,
 * and docs/development.md's table of the physics' copies for the others and the tests that hold them. Only
 * the C library's math.h: tests/test_golden.py compiles this header without Python's. */
#ifndef ARMGAME_CSTEP_H
#define ARMGAME_CSTEP_H
#include <math.h>
#include <stdint.h>
#include <string.h>

/* The hand's trig (kinematics: where the hand is, the observations) is the C library's, as Python's
 * ``math`` is. Where the C library is glibc, whose sincos runs the very code of its sin and cos (one
 * argument reduction for both: a pair costs 11 ns here against 17), the hand's pairs come from sincos.
 * Nothing promises that elsewhere, so other libraries call sin and cos apart, and even glibc's sincos is
 * used only after the module's start has found it equal to sin and cos, bit for bit, on angles from
 * -1e6 to 1e6 (``SINCOS`` says whether it is used). */
#if defined(__GLIBC__)
extern void sincos(double x, double *s, double *c);
/* Set once at the Python module's start (_ckernel.c), read by every loop; a build without Python on glibc
 * defines it (0: sin and cos apart). */
extern int armgame_use_sincos;
#endif

static inline void sin_cos(double x, double *s, double *c)
{
#if defined(__GLIBC__)
    if (armgame_use_sincos) {
        sincos(x, s, c);
        return;
    }
#endif
    *s = sin(x);
    *c = cos(x);
}

/* Whether sincos gives sin's and cos's bits on a spread of angles (small, game-sized and huge): each module
 * that steps the hand asks it once at its start and sets armgame_use_sincos from the answer. */
static inline int sincos_agrees(void)
{
#if defined(__GLIBC__)
    uint64_t r = UINT64_C(88172645463325252);
    for (int i = 0; i < 3000; i++) {
        r ^= r << 13;
        r ^= r >> 7;
        r ^= r << 17;
        const double scale = i % 3 == 0 ? 1.0 : (i % 3 == 1 ? 40.0 : 2e6);
        const double x = ((double)(r >> 11) / 9007199254740992.0 - 0.5) * scale;
        double s, c;
        sincos(x, &s, &c);
        if (s != sin(x) || c != cos(x))
            return 0;
    }
    return 1;
#else
    return 0;
#endif
}

/* The arm's trig (arm_sin_cos, arm_cos): armgame/physics/_trig.h. */
#include "../physics/_trig.h"

/* Layout of the ``params`` buffer (doubles), as compiled.py's ``CompiledKernel`` writes it. */
enum {
    P_DT, P_H, P_K, P_B, P_D, P_DET0, P_AMD, P_G1, P_G2, P_K1, P_K2,
    P_L1, P_L2, P_RADIUS, P_NEAR, P_REACH1, P_REACH2, P_LIMIT2,
    P_S0, P_S1, P_S2, P_S3, P_E0, P_E1, P_E2, P_E3,
    P_COUNT
};

/* The longest game GameConfig allows (time_limit <= 24 h), in seconds: no count of steps past it at the
 * params' dt is a game's, and refusing it bounds the work of a call before its loop (a halt of 2**62 ran
 * for as long as anyone waited). */
#define MAX_GAME_SECONDS 86400.0

/* The most steps a game may have at step dt (MAX_GAME_SECONDS of them, with one for rounding). */
static inline double max_steps(double dt)
{
    return MAX_GAME_SECONDS / dt + 1.0;
}

/* Which accel the single session uses (TwoJointArm._build_components). */
enum { MODE_UNFORCED = 0, MODE_DAMPING = 1, MODE_GRAVITY = 2 };

typedef struct {
    double b, d, det0, amd, g1, g2, k1, k2;
    int mode;
} Arm;

/* TwoJointArm's accel_unforced, accel_with_damping and accel_with_gravity_and_damping, given
 * bc = b cos q2 and h = b sin q2. */
static inline void accel_trig(const Arm *arm, double q1, double q2, double bc, double h, double w1, double w2,
                              double t1, double t2, double *o1, double *o2)
{
    double gc12 = 0.0, f1, f2;
    if (arm->mode == MODE_GRAVITY)
        gc12 = arm->g2 * arm_cos(q1 + q2);
    double m12 = arm->d + bc;
    if (arm->mode == MODE_UNFORCED) {
        f1 = t1 + h * (w1 + w1 + w2) * w2;
        f2 = t2 - h * w1 * w1;
    } else if (arm->mode == MODE_DAMPING) {
        f1 = t1 + h * (w1 + w1 + w2) * w2 - arm->k1 * w1;
        f2 = t2 - h * w1 * w1 - arm->k2 * w2;
    } else {
        f1 = t1 + h * (w1 + w1 + w2) * w2 - arm->g1 * arm_cos(q1) - gc12 - arm->k1 * w1;
        f2 = t2 - h * w1 * w1 - gc12 - arm->k2 * w2;
    }
    double r = 1.0 / (arm->det0 - bc * bc);
    *o1 = (arm->d * f1 - m12 * f2) * r;
    *o2 = ((m12 + arm->amd + bc) * f2 - m12 * f1) * r;
}

/* The fast kernel's elbow trig (batch.numpy_kernel's, there in numpy): b cos and b sin of q2 + delta
 * from those of q2 by angle addition, with cos and sin of the small delta from Taylor series
 * in delta^2 (the first dropped terms below 3e-17 within SERIES_LIMIT). Returns 0, leaving the
 * outputs alone, if |delta| is beyond the series' range. */
static inline int turned(double bc, double bs, double delta, double limit2, double *oc, double *os)
{
    const double d2 = delta * delta;
    if (!(d2 <= limit2))
        return 0;
    const double c = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * (1.0 / 40320.0))));
    const double s = delta * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (-1.0 / 5040.0
                                                                              + d2 * (1.0 / 362880.0)))));
    *oc = bc * c - bs * s;
    *os = bs * c + bc * s;
    return 1;
}

/* A stage's b cos q2 and b sin q2: in full (the exact kernel), or turned by delta from stage 1's
 * (bc, bs) in the fast kernel, in full there too if delta is beyond the series' range. */
static inline void elbow(const Arm *arm, int fast, double q2, double delta, double bc, double bs, double limit2,
                         double *oc, double *os)
{
    if (!fast || !turned(bc, bs, delta, limit2, oc, os)) {
        double sn, cs;
        arm_sin_cos(q2, &sn, &cs);
        *oc = arm->b * cs;
        *os = arm->b * sn;
    }
}

/* Steps between full cos and sin of the elbow in the fast kernel (turned ones gather round-off). */
#define REANCHOR 32

/* A field at the hand (loads.CurlField, loads.ViscousField, loads.ConstantForce, loads.SpringField) or at the
 * joints (a loads.JointLoad of viscosity alone, the lab's ``joint_viscous``), and the flag of a game the guard
 * stopped. */
enum { FIELD_NONE = 0, FIELD_CURL = 1, FIELD_VISCOUS = 2, FIELD_CONSTANT = 3, FIELD_SPRING = 4, FIELD_JOINT = 5 };

/* A field: its kind, parameters (curl b; viscous b11 b12 b21 b22; constant fx fy; spring stiffness, anchor x y;
 * joint w11 w12 w21 w22) and the arm's lengths. */
typedef struct {
    int kind;
    double p[4], l1, l2;
} Field;

/* The field's joint torque ``J(q)^T F(v)`` (loads._with_loads's ``external`` with no joint load, operation
 * for operation) from the hand's trig: sin and cos of q1 (s1, c1) and of q1 + q2 (s12, c12). */
static inline void field_torque(const Field *f, double s1, double c1, double s12, double c12, double w1, double w2,
                                double *e1, double *e2)
{
    if (f->kind == FIELD_JOINT) {  /* torque (0, 0) + W w, no hand force: Python's c1 + v11 * w1 + v12 * w2 */
        *e1 = 0.0 + f->p[0] * w1 + f->p[1] * w2;
        *e2 = 0.0 + f->p[2] * w1 + f->p[3] * w2;
        return;
    }
    const double j12 = -f->l2 * s12, j22 = f->l2 * c12;
    const double j11 = -f->l1 * s1 + j12, j21 = f->l1 * c1 + j22;
    const double vx = j11 * w1 + j12 * w2, vy = j21 * w1 + j22 * w2;
    double fx, fy;
    if (f->kind == FIELD_CURL) {
        fx = f->p[0] * vy;
        fy = -f->p[0] * vx;
    } else if (f->kind == FIELD_CONSTANT || f->kind == FIELD_SPRING) {
        /* The hand as _with_loads passes it: l1 cos q1 + l2 cos(q1 + q2), l1 sin q1 + l2 sin(q1 + q2). */
        const double x = f->l1 * c1 + f->l2 * c12, y = f->l1 * s1 + f->l2 * s12;
        if (f->kind == FIELD_CONSTANT) {
            fx = f->p[0] + 0.0 * x;
            fy = f->p[1] + 0.0 * y;
        } else {
            fx = -f->p[0] * (x - f->p[1]);
            fy = -f->p[0] * (y - f->p[2]);
        }
    } else {
        fx = f->p[0] * vx + f->p[1] * vy;
        fy = f->p[2] * vx + f->p[3] * vy;
    }
    /* No joint load: Python's 0.0 + 0.0 * w1 + 0.0 * w2 (+0, or NaN where w is not finite). */
    *e1 = 0.0 + 0.0 * w1 + 0.0 * w2 + j11 * fx + j21 * fy;
    *e2 = 0.0 + 0.0 * w1 + 0.0 * w2 + j12 * fx + j22 * fy;
}
/* A stage of RK4 in full: GameSession's accel with its own b cos q2 and b sin q2; with a field (not NULL),
 * loads' accel: the field's torque at the stage added to the muscles' (the hand's trig the C library's, as
 * Python's ``math`` is there). */
static inline void accel_full(const Arm *arm, const Field *field, double q1, double q2, double w1, double w2,
                              double t1, double t2, double *o1, double *o2)
{
    double sn, cs;
    if (field != NULL) {
        double s1, c1, s12, c12, e1, e2;
        sin_cos(q1, &s1, &c1);
        sin_cos(q1 + q2, &s12, &c12);
        field_torque(field, s1, c1, s12, c12, w1, w2, &e1, &e2);
        t1 = t1 + e1;
        t2 = t2 + e2;
    }
    arm_sin_cos(q2, &sn, &cs);
    accel_trig(arm, q1, q2, arm->b * cs, arm->b * sn, w1, w2, t1, t2, o1, o2);
}

/* integrators._rk4, exactly: x (q1, q2, w1, w2) one step of dt on, torques t1, t2 held, the field's added
 * where one is given. h and k are taken from dt as the Python step takes them (0.5 dt and dt times _SIXTH,
 * 1/6 rounded once). */
static inline void rk4_exact(const Arm *arm, const Field *field, double t1, double t2, double dt, double x[4])
{
    const double q1 = x[0], q2 = x[1], w1 = x[2], w2 = x[3];
    const double h = 0.5 * dt;
    double ka1, ka2, kb1, kb2, kc1, kc2, kd1, kd2;
    accel_full(arm, field, q1, q2, w1, w2, t1, t2, &ka1, &ka2);
    const double v1 = w1 + h * ka1;
    const double v2 = w2 + h * ka2;
    accel_full(arm, field, q1 + h * w1, q2 + h * w2, v1, v2, t1, t2, &kb1, &kb2);
    const double u1 = w1 + h * kb1;
    const double u2 = w2 + h * kb2;
    accel_full(arm, field, q1 + h * v1, q2 + h * v2, u1, u2, t1, t2, &kc1, &kc2);
    const double z1 = w1 + dt * kc1;
    const double z2 = w2 + dt * kc2;
    accel_full(arm, field, q1 + dt * u1, q2 + dt * u2, z1, z2, t1, t2, &kd1, &kd2);
    const double k = dt * (1.0 / 6.0);
    x[0] = q1 + k * (w1 + z1 + 2.0 * (v1 + u1));
    x[1] = q2 + k * (w2 + z2 + 2.0 * (v2 + u2));
    x[2] = w1 + k * (ka1 + kd1 + 2.0 * (kb1 + kc1));
    x[3] = w2 + k * (ka2 + kd2 + 2.0 * (kb2 + kc2));
}

/* GameSession._advance's muscles for one step: the torques (t1 shoulder, t2 elbow) from the activations a as
 * they are, then each activation a step toward its goal g at its rate r. The game's loop and the lab's batch
 * (env/_ccenter.c) both step their muscles here. */
static inline void muscle_step(const double *p, double a[4], const double g[4], const double r[4], double *t1,
                               double *t2)
{
    *t1 = a[0] * p[P_S0] + a[1] * p[P_S1] + a[2] * p[P_S2] + a[3] * p[P_S3];
    *t2 = a[0] * p[P_E0] + a[1] * p[P_E1] + a[2] * p[P_E2] + a[3] * p[P_E3];
    for (int m = 0; m < 4; m++)
        a[m] += (g[m] - a[m]) * r[m];
}

/* The relative margin of game_loop's "near" test over the exact one (which Python makes): far above
 * the round-off of squaring by multiplication instead of ``**``. */
#define NEAR_MARGIN 1e-9

/* One game's state between calls of game_loop: the arm (q1 q2 w1 w2), the muscles' activations, the state
 * before the last step run, and the rules' hand after the last step (only where it was measured). */
typedef struct {
    double x[4], a[4], previous[4], hx, hy;
} Game;

/* GameSession._advance for one game, exactly: up to n steps of the muscles (goals g, rates r: the
 * activations step toward their goals) and RK4 on the arm of params p, stopping early after a step that
 * leaves the hand (rules.hand_position: the arm's own sine) within a relative 1e-9 of the target disc
 * (tx, ty, radius squared rr); the caller then decides the hit with the session's own test. Returns the
 * steps run; *near says whether it stopped for the disc. The caller has checked p (finite, dt > 0) and n. */
static inline int64_t game_loop(const Arm *arm, const double *p, const double g[4], const double r[4], double tx,
                                double ty, double rr, int64_t n, Game *game, int *near)
{
    double *x = game->x;
    double a[4] = {game->a[0], game->a[1], game->a[2], game->a[3]};
    const double dt = p[P_DT], l1 = p[P_L1], l2 = p[P_L2];
    const double close = rr * (1.0 + NEAR_MARGIN);
    /* |the hand's move| <= reach1 |dq1| + reach2 |dq2| (numpy_kernel.hand_move_bounds, a hair over). */
    const double reach1 = (l1 + l2) * (1.0 + 1e-9), reach2 = l2 * (1.0 + 1e-9);
    const double radius = rr > 0.0 ? sqrt(rr) : 0.0;
    double slack = -1.0;  /* measured after the first step */
    int64_t ran = 0;
    *near = 0;
    while (ran < n) {
        /* GameSession._advance: torque from the activations, then the muscles step, then RK4. */
        double t1, t2;
        muscle_step(p, a, g, r, &t1, &t2);
        memcpy(game->previous, x, sizeof game->previous);
        rk4_exact(arm, NULL, t1, t2, dt, x);
        ran++;
        /* The hand's four cos and sin cost a third of a step: it is measured only when a lower bound on its
         * distance from the disc, lowered by a bound on each step's move, runs out (the batch's slack, see
         * ``run``), which no hand outside the disc by 1e-9 m can skip past. */
        slack -= fabs(x[0] - game->previous[0]) * reach1 + fabs(x[1] - game->previous[1]) * reach2;
        if (slack < 0.0) {
            double sa, ca, sb, cb;
            arm_sin_cos(x[0], &sa, &ca);  /* the rules' hand (rules.hand_position): the caller decides on it */
            arm_sin_cos(x[0] + x[1], &sb, &cb);
            game->hx = l1 * ca + l2 * cb;
            game->hy = l1 * sa + l2 * sb;
            const double dx = game->hx - tx, dy = game->hy - ty;
            const double d2h = dx * dx + dy * dy;
            if (d2h <= close) {
                *near = 1;
                break;
            }
            slack = sqrt(d2h) - radius - 1e-9;
        }
    }
    memcpy(game->a, a, sizeof a);
    return ran;
}

#endif
