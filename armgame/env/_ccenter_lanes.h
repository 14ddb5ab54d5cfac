/* CenterOut's runs in the game's vector lanes: included by _ccenter.c after a run's rules (``count_step``,
 * ``hand_step``, ``Walk``), whose ``advance`` hands this file's ``run_block`` every block of LANES runs that most of
 * has steps to run. Kept apart so that _ccenter.c holds one run's step and the module, and this file the lanes. */
#ifndef ARMGAME_CENTER_LANES_H
#define ARMGAME_CENTER_LANES_H

/* ---------------------------------------------------------------- the runs in vector lanes
 * LANES consecutive runs step together in _lanes.h's RK4 (the game's batch's, the same operations in the same
 * order as ``rk4_exact``, so each lane's state is the one ``run`` gives, bit for bit); each lane's guard, hand
 * and rules follow one at a time (``after_step``). A step runs in the lanes where every running lane steps
 * without a field, or all with the same field; otherwise (runs of the block in different phases of a loaded
 * trial) that step runs lane by lane in ``rk4_exact``. A lane whose run stops (its steps done, a trial's end,
 * the guard) sits still until the block's other runs are done. */

#define CENTER_FLATTEN RUN_FLATTEN

/* The lanes' plain step and the loaded one (one field for every lane), each built for several instruction sets
 * (``LANES_CLONES``). Their guard and slack are not used: ``after_step`` guards, and the lanes' slack is infinite. */
LANES_CLONES
static void center_lanes_plain(const Step *k, Lanes *L)
{
    (void)step_lanes_as(k, L, 0);
}

LANES_CLONES
static void center_lanes_loaded(const Step *k, Lanes *L)
{
    (void)step_lanes_as(k, L, 1);
}

/* A lane out of use: a still arm with relaxed muscles. */
static void idle_lane(Lanes *L, int l)
{
    L->q1[l] = L->q2[l] = L->w1[l] = L->w2[l] = 0.0;
    for (int m = 0; m < 4; m++)
        L->a[m][l] = L->g[m][l] = L->r[m][l] = 0.0;
    L->game[l] = -1;
}

/* Runs i0 to i0 + LANES - 1 (each that has steps to run: no event pending, TODO above 0), as ``run`` would run each. */
CENTER_FLATTEN static void run_block(const Arm *arm, const double *p, int mode, double *state, int64_t *ints,
                                     const double *trials, double *xsall, double *ysall, int64_t cap, Py_ssize_t i0)
{
    Lanes L;
    Walk w[LANES];
    Step k;
    memset(&k, 0, sizeof k);
    k.b = arm->b;
    k.d = arm->d;
    k.det0 = arm->det0;
    k.amd = arm->amd;
    k.k1 = arm->k1;
    k.k2 = arm->k2;
    k.dt = p[P_DT];
    k.h = 0.5 * p[P_DT];             /* rk4_exact's h and k */
    k.k = p[P_DT] * (1.0 / 6.0);
    for (int m = 0; m < 4; m++) {
        k.s[m] = p[P_S0 + m];
        k.e[m] = p[P_E0 + m];
    }
    k.damping = mode == MODE_DAMPING;
    k.fast = 0;
    k.limit = INFINITY;
    int active = 0;
    for (int l = 0; l < LANES; l++) {
        const Py_ssize_t i = i0 + l;
        double *s = state + S_COUNT * i;
        int64_t *it = ints + I_COUNT * i;
        L.sl[l] = INFINITY;
        L.anchor[l] = 0;
        L.bc[l] = L.bs[l] = 0.0;
        L.s[l] = 0;
        L.run[l] = 0;
        for (int m = 0; m < 4; m++) {
            L.ms[m][l] = k.s[m];
            L.me[m][l] = k.e[m];
        }
        idle_lane(&L, l);
        if (it[I_EVENT] != EVENT_NONE || it[I_TODO] <= 0)
            continue;
        begin_walk(it, &w[l]);
        if (w[l].n <= 0)
            continue;
        L.game[l] = i;
        L.q1[l] = s[S_X];
        L.q2[l] = s[S_X + 1];
        L.w1[l] = s[S_X + 2];
        L.w2[l] = s[S_X + 3];
        for (int m = 0; m < 4; m++) {
            L.a[m][l] = s[S_A + m];
            L.g[m][l] = s[S_G + m];
            L.r[m][l] = s[S_R + m];
        }
        active++;
    }
    while (active) {
        /* Whether the running lanes step alike: all without a field, or all with one and the same. */
        int loaded = -1, alike = 1;
        const double *field_of = NULL;
        for (int l = 0; l < LANES && alike; l++) {
            if (L.game[l] < 0)
                continue;
            const double *t = trials + T_COUNT * L.game[l];
            const int on = w[l].phase == 1 && (int)t[T_FIELD] != FIELD_NONE;
            if (loaded < 0)
                loaded = on;
            else if (loaded != on)
                alike = 0;
            if (on) {
                if (field_of == NULL)
                    field_of = t;
                else if (memcmp(field_of + T_FIELD, t + T_FIELD, 5 * sizeof(double)) != 0)
                    alike = 0;
            }
        }
        double previous[LANES][4];
        for (int l = 0; l < LANES; l++) {
            previous[l][0] = L.q1[l];
            previous[l][1] = L.q2[l];
            previous[l][2] = L.w1[l];
            previous[l][3] = L.w2[l];
        }
        if (alike && loaded == 0) {
            center_lanes_plain(&k, &L);
        } else if (alike) {
            k.field = trial_field(p, field_of);
            center_lanes_loaded(&k, &L);
        } else {
            for (int l = 0; l < LANES; l++) {
                if (L.game[l] < 0)
                    continue;
                const double *t = trials + T_COUNT * L.game[l];
                const Field field = trial_field(p, t);
                double a[4], g[4], r[4], x[4] = {L.q1[l], L.q2[l], L.w1[l], L.w2[l]}, t1, t2;
                for (int m = 0; m < 4; m++) {
                    a[m] = L.a[m][l];
                    g[m] = L.g[m][l];
                    r[m] = L.r[m][l];
                }
                muscle_step(p, a, g, r, &t1, &t2);
                if (w[l].phase == 1 && field.kind != FIELD_NONE)
                    rk4_exact(arm, &field, t1, t2, p[P_DT], x);
                else
                    rk4_exact(arm, NULL, t1, t2, p[P_DT], x);
                L.q1[l] = x[0];
                L.q2[l] = x[1];
                L.w1[l] = x[2];
                L.w2[l] = x[3];
                for (int m = 0; m < 4; m++)
                    L.a[m][l] = a[m];
            }
        }
        /* Every lane's guard and count, then the hands' trig in one loop (the C library's sincos is a call, which
         * costs the registers live around it: here few are), then the rules. */
        int kind[LANES];
        double x[LANES][4], a[LANES][4], s1[LANES], c1[LANES], s12[LANES], c12[LANES];
        for (int l = 0; l < LANES; l++) {
            const Py_ssize_t i = L.game[l];
            kind[l] = STEP_BLIND;
            if (i < 0)
                continue;
            const double *t = trials + T_COUNT * i;
            const int on = w[l].phase == 1 && (int)t[T_FIELD] != FIELD_NONE;
            x[l][0] = L.q1[l];
            x[l][1] = L.q2[l];
            x[l][2] = L.w1[l];
            x[l][3] = L.w2[l];
            kind[l] = count_step(state + S_COUNT * i, ints + I_COUNT * i, t, &w[l], x[l], previous[l], on);
        }
        for (int l = 0; l < LANES; l++)
            if (kind[l] == STEP_HAND) {
                sin_cos(x[l][0], &s1[l], &c1[l]);
                sin_cos(x[l][0] + x[l][1], &s12[l], &c12[l]);
            }
        for (int l = 0; l < LANES; l++) {
            const Py_ssize_t i = L.game[l];
            if (i < 0)
                continue;
            double *s = state + S_COUNT * i;
            int64_t *it = ints + I_COUNT * i;
            for (int m = 0; m < 4; m++)
                a[l][m] = L.a[m][l];
            const int stop = kind[l] == STEP_HAND
                                 ? hand_step(p, s, it, trials + T_COUNT * i, xsall + cap * i, ysall + cap * i, cap,
                                             &w[l], x[l], a[l], s1[l], c1[l], s12[l], c12[l])
                                 : kind[l] == STEP_STOPPED;
            if (!stop && w[l].ran < w[l].n)
                continue;
            /* The run is done for now: its state back, its lane idle. */
            memcpy(s + S_X, x[l], sizeof x[l]);
            memcpy(s + S_A, a[l], sizeof a[l]);
            end_walk(it, &w[l]);
            idle_lane(&L, l);
            active--;
        }
    }
}

/* The path lines the block of runs from i0 will write in a call (from each run's I_PATH, five samples at most), asked
 * for a block ahead: the paths (n x cap x 2 doubles, 100 MB at 8,192 runs) are out of every cache, and the stores that
 * wait for their lines cost a sixth of the loop without this (benchmarks/env_speed.py, CenterOut-v1 at 8,192).
 * Inlined always: GCC finds a function of prefetches alone free of effects, and drops its calls. */
LANES_INLINE void prefetch_paths(const int64_t *ints, double *xs, double *ys, int64_t cap, Py_ssize_t i0)
{
#if defined(__GNUC__) || defined(__clang__)
    for (int l = 0; l < LANES; l++) {
        const Py_ssize_t i = i0 + l;
        const int64_t at = ints[I_COUNT * i + I_PATH];
        const int64_t from = at < cap ? at : cap - 1, to = from + 5 < cap ? from + 5 : cap - 1;
        __builtin_prefetch(xs + cap * i + from, 1, 3);
        __builtin_prefetch(ys + cap * i + from, 1, 3);
        __builtin_prefetch(xs + cap * i + to, 1, 3);
        __builtin_prefetch(ys + cap * i + to, 1, 3);
    }
#else
    (void)ints, (void)xs, (void)ys, (void)cap, (void)i0;
#endif
}

#endif
