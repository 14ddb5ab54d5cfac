/* The batch's games side by side (``_ckernel.run`` with lanes, the default): LANES games at a time, one
 * array per quantity with a game per element (structure of arrays), so that every arithmetic line is one
 * loop over the lanes that the compiler turns into vector instructions. See _cbatch.c's opening comment
 * for why the results are the one-at-a-time loop's, bit for bit. */
#include "_ckernel.h"
/* The lanes' state and RK4 step (shared with CenterOut's batch, env/_ccenter.c). */
#include "_lanes.h"

/* The plain game's step, and the harder tasks' (see ``step_lanes_as``). */
LANES_CLONES
static int step_lanes(const Step *k, Lanes *L)
{
    return step_lanes_as(k, L, 0);
}

LANES_CLONES
static int step_lanes_loaded(const Step *k, Lanes *L)
{
    return step_lanes_as(k, L, 1);
}

/* Game i's muscle moments into lane l: its own (B->mom) or the batch's. */
static void moments_lane(const Batch *B, Lanes *L, int l, Py_ssize_t i)
{
    L->run[l] = 0;
    for (int m = 0; m < 4; m++) {
        L->ms[m][l] = B->mom != NULL ? B->mom[m * B->n + i] : B->s[m];
        L->me[m][l] = B->mom != NULL ? B->mom[(4 + m) * B->n + i] : B->e[m];
    }
}

/* Game i's arrays into lane l; no game (i < 0): a still arm that never needs attention. */
static void load_lane(const Batch *B, Lanes *L, int l, Py_ssize_t i)
{
    const Py_ssize_t n = B->n;
    L->game[l] = i;
    L->anchor[l] = 0;
    L->bc[l] = L->bs[l] = 0.0;
    if (i < 0) {
        L->q1[l] = L->q2[l] = L->w1[l] = L->w2[l] = 0.0;
        for (int m = 0; m < 4; m++)
            L->a[m][l] = L->g[m][l] = L->r[m][l] = 0.0;
        L->sl[l] = INFINITY;
        L->x0[l] = L->y0[l] = 0.0;
        L->s[l] = 0;
        L->stop[l] = L->next[l] = INT64_MAX;
        L->c[l] = L->end[l] = 0;
        L->run[l] = 0;
        for (int m = 0; m < 4; m++)
            L->ms[m][l] = L->me[m][l] = 0.0;
        return;
    }
    moments_lane(B, L, l, i);
    L->q1[l] = B->x[i];
    L->q2[l] = B->x[n + i];
    L->w1[l] = B->x[2 * n + i];
    L->w2[l] = B->x[3 * n + i];
    for (int m = 0; m < 4; m++) {
        L->a[m][l] = B->act[m * n + i];
        L->g[m][l] = B->goal[m * n + i];
        L->r[m][l] = B->rate[m * n + i];
    }
    L->sl[l] = B->slack[i];
    L->x0[l] = B->tx[i];
    L->y0[l] = B->ty[i];
    L->s[l] = B->steps[i];
    L->stop[l] = B->halt[i];
    L->c[l] = B->cursor[i];
    L->end[l] = B->ev_end[i];
}

/* Lane l's game back into the arrays. */
static void store_lane(const Batch *B, const Lanes *L, int l)
{
    const Py_ssize_t n = B->n, i = L->game[l];
    B->x[i] = L->q1[l];
    B->x[n + i] = L->q2[l];
    B->x[2 * n + i] = L->w1[l];
    B->x[3 * n + i] = L->w2[l];
    for (int m = 0; m < 4; m++) {
        B->act[m * n + i] = L->a[m][l];
        B->goal[m * n + i] = L->g[m][l];
        B->rate[m * n + i] = L->r[m][l];
    }
    B->slack[i] = L->sl[l];
    B->steps[i] = L->s[l];
    B->cursor[i] = L->c[l];
    write_trig(B, i, L->q1[l], L->q2[l]);
}

/* The muscle commands due at lane l's step, then whether its game goes on (else the caller stores it);
 * sets the step of its next event or stop. */
static int due_lane(const Batch *B, Lanes *L, int l)
{
    int64_t c = L->c[l];
    const int64_t s = L->s[l], end = L->end[l];
    while (c < end && B->ev_step[c] <= s) {
        const int64_t m = B->ev_muscle[c];
        L->g[m][l] = B->ev_goal[c];
        L->r[m][l] = B->ev_rate[c];
        c++;
    }
    L->c[l] = c;
    if (s >= L->stop[l])
        return 0;
    L->next[l] = c < end && B->ev_step[c] < L->stop[l] ? B->ev_step[c] : L->stop[l];
    return 1;
}

/* Lane l takes the next game with steps or commands due (from *queue on), or none. */
static void fill_lane(const Batch *B, Lanes *L, int l, Py_ssize_t *queue)
{
    while (*queue < B->n) {
        const Py_ssize_t i = (*queue)++;
        const int64_t s = B->steps[i], c = B->cursor[i];
        B->flags[i] = 0;
        if (s >= B->halt[i] && (c >= B->ev_end[i] || B->ev_step[c] > s))
            continue;
        load_lane(B, L, l, i);
        if (due_lane(B, L, l))
            return;
        store_lane(B, L, l);
    }
    load_lane(B, L, l, -1);
}

/* The games of the lanes back into the arrays, as ``store_lane`` for each, where they are LANES
 * consecutive games (the lockstep of a vector env: every game stops at the same step): one contiguous
 * copy a quantity, which the compiler vectorises, instead of LANES scattered ones. */
static void store_block(const Batch *B, const Lanes *L)
{
    const Py_ssize_t n = B->n, i = L->game[0];
    for (int l = 0; l < LANES; l++) {
        B->x[i + l] = L->q1[l];
        B->x[n + i + l] = L->q2[l];
        B->x[2 * n + i + l] = L->w1[l];
        B->x[3 * n + i + l] = L->w2[l];
        B->slack[i + l] = L->sl[l];
        B->steps[i + l] = L->s[l];
        B->cursor[i + l] = L->c[l];
    }
    for (int m = 0; m < 4; m++) {
        for (int l = 0; l < LANES; l++) {
            B->act[m * n + i + l] = L->a[m][l];
            B->goal[m * n + i + l] = L->g[m][l];
            B->rate[m * n + i + l] = L->r[m][l];
        }
    }
    for (int l = 0; l < LANES; l++)
        write_trig(B, i + l, L->q1[l], L->q2[l]);
}

/* The next LANES games into the lanes as ``fill_lane`` would take them, where each has steps to run:
 * contiguous copies (see ``store_block``). Returns 0, touching nothing, where they are not so. */
static int fill_block(const Batch *B, Lanes *L, Py_ssize_t *queue)
{
    const Py_ssize_t n = B->n, i = *queue;
    if (n - i < LANES)
        return 0;
    for (int l = 0; l < LANES; l++)
        if (B->steps[i + l] >= B->halt[i + l])
            return 0;
    for (int l = 0; l < LANES; l++) {
        B->flags[i + l] = 0;
        L->game[l] = i + l;
        L->anchor[l] = 0;
        L->bc[l] = L->bs[l] = 0.0;
        L->q1[l] = B->x[i + l];
        L->q2[l] = B->x[n + i + l];
        L->w1[l] = B->x[2 * n + i + l];
        L->w2[l] = B->x[3 * n + i + l];
        L->sl[l] = B->slack[i + l];
        L->x0[l] = B->tx[i + l];
        L->y0[l] = B->ty[i + l];
        L->s[l] = B->steps[i + l];
        L->stop[l] = B->halt[i + l];
        L->c[l] = B->cursor[i + l];
        L->end[l] = B->ev_end[i + l];
    }
    for (int m = 0; m < 4; m++) {
        for (int l = 0; l < LANES; l++) {
            L->a[m][l] = B->act[m * n + i + l];
            L->g[m][l] = B->goal[m * n + i + l];
            L->r[m][l] = B->rate[m * n + i + l];
        }
    }
    *queue = i + LANES;
    for (int l = 0; l < LANES; l++)
        moments_lane(B, L, l, i + l);
    for (int l = 0; l < LANES; l++)
        due_lane(B, L, l);  /* each has steps before its halt: none stops here */
    return 1;
}

/* Steps the other lanes may still run while a freed lane waits for them (see ``armgame_run_lanes``). */
#define WAIT_STEPS 16

/* The lanes: ``run_scalar``'s games, LANES at a time. Returns the games flagged. */
Py_ssize_t armgame_run_lanes(const Batch *B)
{
    Lanes L;
    const Arm *arm = &B->arm;
    const Step k = {arm->b, arm->d, arm->det0, arm->amd, arm->k1, arm->k2, B->dt, B->h, B->k, B->limit2,
                    B->reach1, B->reach2, {B->s[0], B->s[1], B->s[2], B->s[3]},
                    {B->e[0], B->e[1], B->e[2], B->e[3]}, arm->mode == MODE_DAMPING, B->fast,
                    B->field, B->limit};
    /* The loaded step where the games have their own moments, a field or a guard; else the plain one. */
    const int loaded = B->mom != NULL || B->field.kind != FIELD_NONE || B->limit < INFINITY;
    int (*const step)(const Step *, Lanes *) = loaded ? step_lanes_loaded : step_lanes;
    Py_ssize_t queue = 0, flagged = 0;
    int busy = 0;
    for (int l = 0; l < LANES; l++) {
        fill_lane(B, &L, l, &queue);
        busy += L.game[l] >= 0;
    }
    while (busy) {
        /* Steps every lane can run before one needs its commands or its stop. */
        int64_t run = INT64_MAX;
        for (int l = 0; l < LANES; l++)
            if (L.game[l] >= 0 && L.next[l] - L.s[l] < run)
                run = L.next[l] - L.s[l];
        int short_ = 0;
        while (run > 0) {
            run--;
            if (step(&k, &L)) {
                short_ = 1;
                break;
            }
        }
        int done[LANES], finished = 0;
        for (int l = 0; l < LANES; l++) {
            const Py_ssize_t i = L.game[l];
            done[l] = 0;
            if (i < 0)
                continue;
            if (short_ && L.run[l]) {
                /* The guard: the game stops with this step's state, which the caller puts back. */
                B->flags[i] = FLAG_RUNAWAY;
                flagged++;
                done[l] = 1;
                finished++;
                continue;
            }
            if (short_ && L.sl[l] < 0.0) {
                /* The slack ran out: measure the hand (as the single session does, on its floats). */
                double sa, ca, sb, cb;
                sin_cos(L.q1[l], &sa, &ca);
                sin_cos(L.q1[l] + L.q2[l], &sb, &cb);
                const double dx = B->l1 * ca + B->l2 * cb - L.x0[l];
                const double dy = B->l1 * sa + B->l2 * sb - L.y0[l];
                const double d2h = dx * dx + dy * dy;
                L.sl[l] = sqrt(d2h) - B->radius - 1e-9;
                if (d2h <= B->near) {
                    B->flags[i] = FLAG_NEAR;
                    flagged++;
                    done[l] = 1;
                    finished++;
                    continue;
                }
            }
            if (L.s[l] >= L.next[l] && !due_lane(B, &L, l)) {
                done[l] = 1;
                finished++;
            }
        }
        if (!finished)
            continue;
        /* Every lane's game done at once, and consecutive games: the lockstep's block copies. */
        int block = finished == LANES;
        for (int l = 1; block && l < LANES; l++)
            block = L.game[l] == L.game[0] + l;
        if (block)
            store_block(B, &L);
        int64_t longest = 0;  /* the most steps a lane still running has before its stop */
        for (int l = 0; l < LANES; l++) {
            if (done[l]) {
                if (!block)
                    store_lane(B, &L, l);
                load_lane(B, &L, l, -1);
            } else if (L.game[l] >= 0 && L.stop[l] - L.s[l] > longest) {
                longest = L.stop[l] - L.s[l];
            }
        }
        if (longest == 0 && fill_block(B, &L, &queue))
            continue;
        /* A lane freed while the others are about to stop (a hit in a vector env's few steps) waits for
         * them, so that the lanes fill as a block again; otherwise it takes the next game now. */
        busy = 0;
        for (int l = 0; l < LANES; l++) {
            if (L.game[l] < 0 && (longest == 0 || longest > WAIT_STEPS))
                fill_lane(B, &L, l, &queue);
            busy += L.game[l] >= 0;
        }
    }
    return flagged;
}
