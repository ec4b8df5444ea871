/* semo_runtime.c: the POSIX-threads platform layer of the SeMo runtime
 * (targets `linux`, `linux-sim`); values and trace lines are the portable
 * core's (semo_core.c).
 *
 * One thread per task, plus a message receiver, a signal watcher and (in
 * simulation) the operator. Every shared structure has its own mutex; every
 * wait is on a condition variable tied to the monotonic clock, and stopping
 * the program broadcasts all of them so that no thread sleeps through it.
 */
#define _POSIX_C_SOURCE 200809L

#include "semo_internal.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Task code is small: a modest stack keeps the program's footprint low
 * (`make CFLAGS="-O2 -DSEMO_STACK_BYTES=65536"` for less). */
#ifndef SEMO_STACK_BYTES
#define SEMO_STACK_BYTES (512u * 1024u)
#endif
#define RECV_ERROR_PAUSE_MS 50
#define DEFAULT_PORT_BASE 47000
#define DEFAULT_BROKER "mqtt://127.0.0.1:1883"
/* The target's transport (the Makefile's TRANSPORT); MQTT is compiled in
 * only where it is the default, as only then is libmosquitto linked. */
#ifdef SEMO_MQTT
#define DEFAULT_TRANSPORT "mqtt"
#elif defined(SEMO_LINK_DEFAULT)
#define DEFAULT_TRANSPORT "link"
#else
#define DEFAULT_TRANSPORT "udp"
#endif

/* ------------------------------------------------------------ run state */

static const semo_program_desc *g_prog;
static atomic_bool g_running;
static struct timespec g_t0;
static double g_scale = 1.0; /* wall ms per mission ms */
static pthread_mutex_t g_run_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t g_run_cond;

static void init_cond(pthread_cond_t *cond)
{
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    /* Timed waits must not jump when someone sets the wall clock. */
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    pthread_cond_init(cond, &attr);
    pthread_condattr_destroy(&attr);
}

bool semo_running(void)
{
    return atomic_load(&g_running);
}

const semo_program_desc *semo_program(void)
{
    return g_prog;
}

/* ------------------------------------------------------------------ time */

int64_t semo_now_ms(void)
{
#ifdef SEMO_SIM
    if (semo__ls_on())
        return semo__ls_now();
#endif
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    double wall_ns = (double)(now.tv_sec - g_t0.tv_sec) * 1e9 + (double)(now.tv_nsec - g_t0.tv_nsec);
    double mission_ms = wall_ns / (g_scale * 1e6);
    /* The scale is bounded (SEMO_TIME_SCALE_MIN), so this holds for
     * millennia; the check keeps the conversion defined regardless. */
    return mission_ms < 9e18 ? (int64_t)mission_ms : INT64_C(9000000000000000000);
}

/* The monotonic instant at which mission time reaches `mission_ms`. A
 * microsecond of slack makes sure semo_now_ms() has reached it on waking,
 * so rounding never turns a wait into a spin. */
static struct timespec wall_deadline(int64_t mission_ms)
{
    double ns = (double)mission_ms * g_scale * 1e6 + 1e3;
    if (ns > 1e17) /* three years: far enough, and no overflow below */
        ns = 1e17;
    if (ns < 0)
        ns = 0;
    long long total = (long long)g_t0.tv_nsec + (long long)ns;
    struct timespec at = {.tv_sec = g_t0.tv_sec + (time_t)(total / 1000000000LL),
                          .tv_nsec = (long)(total % 1000000000LL)};
    return at;
}

/* Waits on `cond` until woken or mission time `deadline_ms` (< 0: no limit). */
static void wait_until(pthread_cond_t *cond, pthread_mutex_t *lock, int64_t deadline_ms)
{
#ifdef SEMO_SIM
    if (semo__ls_turns()) {
        semo__ls_wait(cond, lock, deadline_ms);
        return;
    }
#endif
    if (deadline_ms < 0) {
        pthread_cond_wait(cond, lock);
    } else {
        struct timespec at = wall_deadline(deadline_ms);
        pthread_cond_timedwait(cond, lock, &at);
    }
}

/* Every signal of a condition the runtime waits on goes through these, so
 * that lock-step knows who may run. */
static void cond_signal(pthread_cond_t *cond)
{
#ifdef SEMO_SIM
    if (semo__ls_turns()) {
        semo__ls_wake(cond, false);
        return;
    }
#endif
    pthread_cond_signal(cond);
}

static void cond_broadcast(pthread_cond_t *cond)
{
#ifdef SEMO_SIM
    if (semo__ls_turns()) {
        semo__ls_wake(cond, true);
        return;
    }
#endif
    pthread_cond_broadcast(cond);
}

#ifdef SEMO_SIM
void semo__cond_signal(pthread_cond_t *cond)
{
    cond_signal(cond);
}

void semo__cond_init(pthread_cond_t *cond)
{
    init_cond(cond);
}

void semo__cond_wait_until(pthread_cond_t *cond, pthread_mutex_t *lock, int64_t deadline_ms)
{
    wait_until(cond, lock, deadline_ms);
}
#endif

bool semo__wait_until(int64_t deadline_ms)
{
    pthread_mutex_lock(&g_run_lock);
    while (semo_running() && semo_now_ms() < deadline_ms)
        wait_until(&g_run_cond, &g_run_lock, deadline_ms);
    bool running = semo_running();
    pthread_mutex_unlock(&g_run_lock);
    return running;
}

void semo_sleep_ms(int64_t ms)
{
    if (ms > 0)
        semo__wait_until(semo_now_ms() + ms);
}

bool semo_sleep_until(int64_t at_ms)
{
    return semo__wait_until(at_ms);
}

/* ----------------------------------------------------------------- traces */

static FILE *g_trace;
static bool g_trace_owned; /* false for "-" (stdout) */
static pthread_mutex_t g_trace_lock = PTHREAD_MUTEX_INITIALIZER;

/* A trace line is written in many small pieces (each field, each escaped
 * run of a string): they are gathered here and given to stdio at once, not
 * one locked fwrite a piece (a sixth of a sending robot's instructions). */
typedef struct {
    FILE *file;
    size_t len;
    char bytes[1024];
} line_buffer;

static void put_line(void *ctx, const char *bytes, size_t n)
{
    line_buffer *line = ctx;
    if (line->len + n > sizeof line->bytes) {
        fwrite(line->bytes, 1, line->len, line->file);
        line->len = 0;
        if (n > sizeof line->bytes) {
            fwrite(bytes, 1, n, line->file);
            return;
        }
    }
    memcpy(line->bytes + line->len, bytes, n);
    line->len += n;
}

static void observe_status(const char *event, va_list args);

void semo__trace_emit(const char *event, const char *value_key, const semo_value *value, va_list args)
{
    va_list seen;
    va_copy(seen, args);
    observe_status(event, seen);
    va_end(seen);
    pthread_mutex_lock(&g_trace_lock);
    if (g_trace) {
        /* The time is read under the lock so that lines are in time order. */
        line_buffer line;
        line.file = g_trace;
        line.len = 0;
        semo__sink sink = {put_line, &line};
        semo__trace_line(&sink, semo_now_ms(), g_prog ? g_prog->robot : "", event, args, value_key, value);
        fwrite(line.bytes, 1, line.len, g_trace);
        fflush(g_trace);
    }
    pthread_mutex_unlock(&g_trace_lock);
}

/* --------------------------------------------------------------- channels */

/* The rings are the core's (semo_core.c); here each has its lock and a
 * condition variable its reader waits on. */
typedef struct {
    semo__ring ring;
    semo_channel_state state;
    pthread_mutex_t lock;
    pthread_cond_t readable; /* a write for the reader; a take or a reader's firing for a writer */
    struct task_s *reader; /* the task reading it, woken by a write */
    struct task_s *writer; /* the task writing it (semo_port_await_sends) */
    atomic_int room_waiters; /* writers waiting for room (semo__queue_wait_room) */
} channel;

static void wake_task(struct task_s *t);
static void wake_group_readers(void);
static void mark_group_reader(void);

static channel *g_channels;

static channel *channel_at(int port)
{
    if (!g_prog || !g_channels || port < 0 || (size_t)port >= g_prog->channel_count)
        return NULL;
    return &g_channels[port];
}

bool semo__channel_ring(int port, semo__ring *out)
{
    channel *c = channel_at(port);
    if (!c)
        return false;
    *out = c->ring;
    return true;
}

static pthread_mutex_t g_inbox_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t g_inbox_cond;

void semo__queue_lock(int queue)
{
    pthread_mutex_lock(queue == SEMO__INBOX ? &g_inbox_lock : &g_channels[queue].lock);
}

void semo__queue_unlock(int queue)
{
    pthread_mutex_unlock(queue == SEMO__INBOX ? &g_inbox_lock : &g_channels[queue].lock);
}

bool semo__queue_wait(int queue, int64_t deadline_ms)
{
    if (queue == SEMO__INBOX)
        wait_until(&g_inbox_cond, &g_inbox_lock, deadline_ms);
    else
        wait_until(&g_channels[queue].readable, &g_channels[queue].lock, deadline_ms);
    return true;
}

/* semo_port_await_sends: a send task waiting for the rest of its writer's
 * firing. One condition for all its channels (it waits on several), told
 * only while someone waits (`g_send_waiters`, counted under `g_sends_lock`
 * before the channels are looked at: a write or a firing's end after that
 * look finds the count and takes the lock to broadcast). */
static pthread_mutex_t g_sends_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t g_sends_cond;
static atomic_int g_send_waiters;

static void tell_send_waiters(void)
{
    if (atomic_load(&g_send_waiters) == 0)
        return;
    pthread_mutex_lock(&g_sends_lock);
    cond_broadcast(&g_sends_cond);
    pthread_mutex_unlock(&g_sends_lock);
}

/* A waiter looks at the count under the lock before it waits, so a signal
 * after the lock is released is never missed. */
void semo__queue_written(int queue)
{
    if (queue == SEMO__INBOX) {
        /* Both a poller and a held-back delivery may wait on the inbox. */
        cond_broadcast(&g_inbox_cond);
    } else {
        cond_signal(&g_channels[queue].readable);
        wake_task(g_channels[queue].reader);
        tell_send_waiters();
    }
}

/* A receiver waits for room in the inbox instead (semo__queue_wait). */
void semo__inbox_polled(void) {}

/* Only a writer waits on a channel that has just been taken from. */
void semo__queue_taken(int queue)
{
    channel *c = channel_at(queue);
    if (c && atomic_load(&c->room_waiters) > 0) {
        pthread_mutex_lock(&c->lock);
        cond_broadcast(&c->readable);
        pthread_mutex_unlock(&c->lock);
    }
}

/* -------------------------------------------------------------- multicast */

typedef struct {
    const semo_multicast_desc *desc;
    unsigned char *buf;
    bool written;
    pthread_mutex_t lock;
} group;

static group *g_groups;

static group *find_group(const char *name, size_t size)
{
    if (!g_prog || !name)
        return NULL;
    for (size_t i = 0; i < g_prog->group_count; i++)
        if (strcmp(g_prog->groups[i].name, name) == 0)
            return size == g_prog->groups[i].sample_size ? &g_groups[i] : NULL;
    return NULL;
}

int UFMulticast_Write(const char *name, const void *buf, size_t size)
{
    group *g = find_group(name, size);
    if (!g || !buf)
        return 0;
    pthread_mutex_lock(&g->lock);
    memcpy(g->buf, buf, size);
    g->written = true;
    pthread_mutex_unlock(&g->lock);
    wake_group_readers();
    return (int)size;
}

int UFMulticast_Read(const char *name, void *buf, size_t size)
{
    group *g = find_group(name, size);
    if (!g || !buf)
        return 0;
    mark_group_reader();
    pthread_mutex_lock(&g->lock);
    int read = 0;
    if (g->written) {
        memcpy(buf, g->buf, size);
        read = (int)size;
    }
    pthread_mutex_unlock(&g->lock);
    return read;
}

/* ------------------------------------------------------------------ tasks */

typedef struct param {
    struct param *next;
    long long value;
    char name[]; /* owned copy */
} param;

typedef struct task_s {
    const semo_task_desc *desc;
    pthread_t thread;
    bool started;
    pthread_mutex_t lock;
    pthread_cond_t changed; /* any field below changed */
    semo__task_control control; /* changed by UFControl_* (the core's switch) */
    param *params;
    /* semo_next_firing: a time-driven task that said when its next firing
     * is needed sleeps until then, or until `woken` by what it may wait
     * for: data on one of its channels, a change of state of a task it
     * controls (UFControl_*: `controller` below), a multicast group
     * written when it reads groups. Nothing else wakes it. */
    bool hinted, woken;
    int64_t hint_ms;
    struct task_s *controller; /* the task that last ran, called or stopped it */
    atomic_bool reads_groups;  /* it has called UFMulticast_Read */
    /* Firings begun and ended: a writer that waits for room in one of its
     * channels gives up once a firing begun after it has ended. */
    atomic_ulong firings_begun, firings_ended;
} task;

static task *g_tasks;
/* The task whose thread this is (NULL in other threads). */
static _Thread_local task *g_current;

/* Wakes a task sleeping on its hint; never called with another task's lock held. */
static void wake_task(task *t)
{
    if (!t || t == g_current)
        return;
    pthread_mutex_lock(&t->lock);
    /* Kept even while the task fires: a hint given later in that firing
     * must not sleep through it. */
    t->woken = true;
    if (t->hinted)
        cond_broadcast(&t->changed);
    pthread_mutex_unlock(&t->lock);
}

/* A multicast group was written: wakes the tasks that read groups. */
static void wake_group_readers(void)
{
    for (size_t i = 0; g_tasks && g_prog && i < g_prog->task_count; i++)
        if (atomic_load(&g_tasks[i].reads_groups))
            wake_task(&g_tasks[i]);
}

static void mark_group_reader(void)
{
    if (g_current)
        atomic_store(&g_current->reads_groups, true);
}

/* The writer waits on the channel's condition variable, which a take and
 * the end of a firing of its reader broadcast (the counts are read under
 * the channel's lock, and changed before the lock is taken to broadcast:
 * no wake-up is missed). The first call wakes the reader, so that the
 * firing that decides comes at once: it takes, or the writer gives up. */
bool semo__queue_wait_room(int queue, semo__room_wait *room)
{
    channel *c = channel_at(queue);
    if (!c)
        return false;
    task *reader = c->reader;
    if (!room->patient) {
        if (!reader)
            return false;
        if (!room->marked) {
            room->marked = true;
            room->mark = atomic_load(&reader->firings_begun);
            wake_task(reader);
        }
    }
    atomic_fetch_add(&c->room_waiters, 1);
    bool wait = room->patient || atomic_load(&reader->firings_ended) <= room->mark;
    if (wait)
        wait_until(&c->readable, &c->lock, -1);
    atomic_fetch_sub(&c->room_waiters, 1);
    return wait;
}

/* After a firing of `t`: writers waiting for room in its channels look
 * again, and so does a send task waiting for the rest of the firing. */
static void firing_ended(task *t)
{
    atomic_fetch_add(&t->firings_ended, 1);
    tell_send_waiters();
    for (size_t i = 0; g_prog && i < g_prog->channel_count; i++) {
        channel *c = &g_channels[i];
        if (c->reader == t && atomic_load(&c->room_waiters) > 0) {
            pthread_mutex_lock(&c->lock);
            cond_broadcast(&c->readable);
            pthread_mutex_unlock(&c->lock);
        }
    }
}

/* Whether a channel holds a sample, or its writer (another thread's task)
 * is in a firing that may still write to it. */
static void look_at_channel(int port, bool *holds, bool *writing)
{
    channel *c = channel_at(port);
    if (!c)
        return;
    pthread_mutex_lock(&c->lock);
    *holds = *holds || c->state.count > 0;
    pthread_mutex_unlock(&c->lock);
    task *w = c->writer;
    if (w && w != g_current && atomic_load(&w->firings_begun) > atomic_load(&w->firings_ended))
        *writing = true;
}

bool semo_port_await_sends(const int *ports, size_t count)
{
    pthread_mutex_lock(&g_sends_lock);
    atomic_fetch_add(&g_send_waiters, 1);
    bool holds = false;
    for (;;) {
        bool writing = false;
        for (size_t i = 0; i < count; i++)
            look_at_channel(ports[i], &holds, &writing);
        if (holds || !writing || !semo_running())
            break;
        wait_until(&g_sends_cond, &g_sends_lock, -1);
    }
    atomic_fetch_sub(&g_send_waiters, 1);
    pthread_mutex_unlock(&g_sends_lock);
    return holds;
}

void semo_next_firing(int64_t at_ms)
{
    task *t = g_current;
    if (!t || t->desc->trigger != SEMO_TRIGGER_TIME)
        return;
    pthread_mutex_lock(&t->lock);
    t->hinted = true;
    t->hint_ms = at_ms;
    pthread_mutex_unlock(&t->lock);
}

static task *find_task(const char *name)
{
    if (!g_prog || !name)
        return NULL;
    for (size_t i = 0; i < g_prog->task_count; i++)
        if (strcmp(g_prog->tasks[i].name, name) == 0)
            return &g_tasks[i];
    return NULL;
}

void semo_wake(const char *task_name)
{
    wake_task(find_task(task_name));
}

/* Time- and data-driven tasks start running; control-driven ones wait
 * for the control task. All of them obey UFControl_*. */
static void *task_thread(void *arg)
{
    task *t = arg;
    const semo_task_desc *d = t->desc;
    int64_t next_release = 0, first_release = -1, woken_release = -1;
    g_current = t;
    pthread_mutex_lock(&t->lock);
    while (semo_running()) {
        if (t->control.stop_requested && t->control.state != SEMO_TASK_IDLE) {
            t->control.state = SEMO_TASK_IDLE;
            t->control.stop_requested = false;
            t->control.calls = 0;
            cond_broadcast(&t->changed);
            task *controller = t->controller;
            pthread_mutex_unlock(&t->lock);
            wake_task(controller); /* the control task waits for idle tasks */
            pthread_mutex_lock(&t->lock);
            continue;
        }
        if (t->control.state != SEMO_TASK_RUNNING) {
            wait_until(&t->changed, &t->lock, -1);
            continue;
        }
        if (d->trigger == SEMO_TRIGGER_TIME) {
            int64_t now = semo_now_ms();
            if (first_release < 0)
                first_release = now;
            /* The period is the shortest gap; a task that gave a hint sleeps
             * until it unless something it may wait for happens first. */
            int64_t due = next_release;
            if (t->hinted && !t->woken && t->hint_ms > due)
                due = t->hint_ms;
            /* Firings keep to the period's grid from the first one: a task
             * due, or woken by an event, between two grid points fires at
             * the next (as the simulator's control task fires every period
             * from its start, and only then). The instant is kept once
             * chosen: on the wall clock a wait ends a little after it. */
            due = semo__on_grid(due, first_release, d->period_ms);
            if (t->woken && due < now) {
                if (woken_release < 0)
                    woken_release = semo__on_grid(now, first_release, d->period_ms);
                due = woken_release;
            }
            if (now < due) {
                /* Woken early by a state change, an event or the end of the program. */
                wait_until(&t->changed, &t->lock, due == INT64_MAX ? -1 : due);
                continue;
            }
            woken_release = -1;
            next_release = semo__on_grid(now + 1, first_release, d->period_ms);
            t->hinted = t->woken = false;
        }
        pthread_mutex_unlock(&t->lock);
        atomic_fetch_add(&t->firings_begun, 1);
        if (d->go)
            d->go();
        firing_ended(t);
        pthread_mutex_lock(&t->lock);
        bool went_idle = !t->control.repeat && t->control.calls > 0 && --t->control.calls == 0;
        if (went_idle)
            t->control.state = SEMO_TASK_IDLE;
        cond_broadcast(&t->changed);
        if (went_idle) {
            task *controller = t->controller;
            pthread_mutex_unlock(&t->lock);
            wake_task(controller);
            pthread_mutex_lock(&t->lock);
        }
    }
    pthread_mutex_unlock(&t->lock);
    return NULL;
}

/* Task control hooks (the switch is the core's, semo__control): the
 * record is changed under the task's lock, and the task is woken. */
semo__task_control *semo__control_begin(const char *name)
{
    task *t = find_task(name);
    if (!t)
        return NULL;
    pthread_mutex_lock(&t->lock);
    return &t->control;
}

void semo__control_end(semo__task_control *control)
{
    task *t = (task *)((char *)control - offsetof(task, control));
    if (g_current && g_current != t)
        t->controller = g_current;
    t->woken = true; /* its own hint is void: it was told what to do */
    cond_broadcast(&t->changed);
    pthread_mutex_unlock(&t->lock);
}

semo_task_state UFControl_GetTaskState(const char *name)
{
    task *t = find_task(name);
    if (!t)
        return SEMO_TASK_IDLE;
    pthread_mutex_lock(&t->lock);
    semo_task_state state = t->control.state;
    pthread_mutex_unlock(&t->lock);
    return state;
}

bool UFControl_WaitIdle(const char *name, int64_t timeout_ms)
{
    task *t = find_task(name);
    if (!t)
        return false;
    int64_t deadline = timeout_ms < 0 ? -1 : semo_now_ms() + timeout_ms;
    pthread_mutex_lock(&t->lock);
    while (t->control.state != SEMO_TASK_IDLE && semo_running() && (deadline < 0 || semo_now_ms() < deadline))
        wait_until(&t->changed, &t->lock, deadline);
    bool idle = t->control.state == SEMO_TASK_IDLE;
    pthread_mutex_unlock(&t->lock);
    return idle;
}

bool UFControl_WaitStop(const char *name, int64_t until_ms)
{
    task *t = find_task(name);
    if (!t)
        return !semo_running();
    pthread_mutex_lock(&t->lock);
    while (!t->control.stop_requested && semo_running() && semo_now_ms() < until_ms)
        wait_until(&t->changed, &t->lock, until_ms);
    bool stop = t->control.stop_requested || !semo_running();
    pthread_mutex_unlock(&t->lock);
    return stop;
}

bool UFControl_StopRequested(const char *name)
{
    task *t = find_task(name);
    if (!semo_running())
        return true;
    if (!t)
        return false;
    pthread_mutex_lock(&t->lock);
    bool stop = t->control.stop_requested;
    pthread_mutex_unlock(&t->lock);
    return stop;
}

int UFTask_SetIntegerParameter(const char *name, const char *param_name, long long value)
{
    task *t = find_task(name);
    if (!t || !param_name)
        return -1;
    int result = 0;
    pthread_mutex_lock(&t->lock);
    param *p = t->params;
    while (p && strcmp(p->name, param_name) != 0)
        p = p->next;
    if (!p) {
        size_t len = strlen(param_name);
        p = malloc(sizeof *p + len + 1);
        if (p) {
            memcpy(p->name, param_name, len + 1);
            p->next = t->params;
            t->params = p;
        }
    }
    if (p)
        p->value = value;
    else
        result = -1;
    pthread_mutex_unlock(&t->lock);
    return result;
}

long long UFTask_GetIntegerParameter(const char *name, const char *param_name)
{
    task *t = find_task(name);
    if (!t || !param_name)
        return 0;
    long long value = 0;
    pthread_mutex_lock(&t->lock);
    for (param *p = t->params; p; p = p->next)
        if (strcmp(p->name, param_name) == 0)
            value = p->value;
    pthread_mutex_unlock(&t->lock);
    return value;
}

/* ----------------------------------------------------------------- timers */

typedef struct {
    int64_t due_ms;
    bool used;
} timer;

static timer *g_timers;
static size_t g_timer_count;
static pthread_mutex_t g_timer_lock = PTHREAD_MUTEX_INITIALIZER;

int UFTimer_Set(int64_t period, semo_time_unit unit)
{
    static const int64_t unit_ms[] = {[SEMO_MSEC] = 1, [SEMO_SEC] = 1000, [SEMO_MIN] = 60000, [SEMO_HOUR] = 3600000};
    if (period < 0 || unit < SEMO_MSEC || unit > SEMO_HOUR || period > INT64_MAX / 2 / unit_ms[unit])
        return -1;
    int64_t due = semo_now_ms() + period * unit_ms[unit];
    int id = -1;
    pthread_mutex_lock(&g_timer_lock);
    for (size_t i = 0; i < g_timer_count && id < 0; i++)
        if (!g_timers[i].used)
            id = (int)i;
    if (id < 0 && g_timer_count < INT_MAX) {
        size_t count = g_timer_count ? g_timer_count * 2 : 8;
        timer *grown = realloc(g_timers, count * sizeof *grown);
        if (grown) {
            memset(grown + g_timer_count, 0, (count - g_timer_count) * sizeof *grown);
            id = (int)g_timer_count;
            g_timers = grown;
            g_timer_count = count;
        }
    }
    if (id >= 0)
        g_timers[id] = (timer){.due_ms = due, .used = true};
    pthread_mutex_unlock(&g_timer_lock);
    return id;
}

bool UFTimer_GetAlarmed(int id)
{
    bool alarmed = false;
    pthread_mutex_lock(&g_timer_lock);
    if (id >= 0 && (size_t)id < g_timer_count && g_timers[id].used)
        alarmed = semo_now_ms() >= g_timers[id].due_ms;
    pthread_mutex_unlock(&g_timer_lock);
    return alarmed;
}

void UFTimer_Cancel(int id)
{
    pthread_mutex_lock(&g_timer_lock);
    if (id >= 0 && (size_t)id < g_timer_count)
        g_timers[id].used = false;
    pthread_mutex_unlock(&g_timer_lock);
}

/* --------------------------------------------------------------- messages */

/* The datagram is the core's (semo__encode_message, semo_internal.h). */
#define DATAGRAM_MAX SEMO__DATAGRAM_MAX

static const semo_transport *g_transport; /* NULL: no other robots */
/* Mission time when the program started (after the start barrier): written
 * before any task thread starts. */
static int64_t g_joined_at;

int64_t semo_joined_ms(void)
{
    return g_joined_at;
}

bool semo_session_resumed(void)
{
    if (g_transport == &semo_link_transport)
        return semo__link_session_present();
#ifdef SEMO_MQTT
    if (g_transport == &semo_mqtt_transport)
        return semo__mqtt_session_present();
#endif
    return false;
}

int semo_comm_send(const char *to_team, semo_msg_kind kind, const char *key, const semo_value *value)
{
    int local = semo__comm_send_local(to_team, kind, key, value);
    if (local < 0)
        return local;
    bool to_operator = local == 1;
    if (!g_transport)
        return to_operator ? 1 : -1; /* the operator console: the trace is its record */
    semo_message m = {.kind = (char)kind};
    snprintf(m.from_team, sizeof m.from_team, "%s", g_prog->team);
    snprintf(m.from_robot, sizeof m.from_robot, "%s", g_prog->robot);
    snprintf(m.key, sizeof m.key, "%s", key);
    m.value = *value;
    unsigned char datagram[DATAGRAM_MAX];
    size_t len = semo__encode_message(&m, datagram);
    if (to_operator) {
        /* A transport that reaches operators (MQTT: semo/<mission>/USER/<key>,
         * `semo operator`) tells them too; the trace stays the record. */
        if (g_transport->send_to)
            g_transport->send_to("USER", datagram, len);
        return 1;
    }
    int sent = 0;
    for (size_t i = 0; i < g_prog->peer_count; i++) {
        const semo_peer *p = &g_prog->peers[i];
        if (i == g_prog->self || (strcmp(p->team, to_team) != 0 && strcmp(p->robot, to_team) != 0))
            continue;
        sent++;
        if (g_transport->send_to)
            continue; /* one message for all of them, below */
#ifdef SEMO_SIM
        int64_t delay_ms = 0;
        if (g_prog->sim && !g_prog->sim->link(i, &delay_ms))
            continue; /* a link fault of the scenario loses it */
        if (delay_ms > 0) {
            g_prog->sim->send_later(g_transport, i, datagram, len, delay_ms);
            continue;
        }
#endif
        if (g_transport->send(i, datagram, len) != 0) {
            semo_trace("comm_error", "to", p->robot, "key", key, NULL);
            return -1;
        }
    }
    if (g_transport->send_to && sent > 0 && g_transport->send_to(to_team, datagram, len) != 0) {
        semo_trace("comm_error", "to", to_team, "key", key, NULL);
        return -1;
    }
    return sent;
}

/* -------------------------------------------------------------- status */

/* The robot's status for operators, kept from the trace's own events (the
 * trace is the record of what the robot does, so the status cannot say
 * something else): its state (running, finished, stopped; the broker's last
 * will says lost), mode, leader and the service each plan runs. Published
 * on every change through the transport's `status` (MQTT: retained on
 * semo/<mission>/<run>/status/<robot>) as one JSON line of the trace's form:
 * {"t":..,"robot":..,"event":"status","state":..,"started":"<Unix ms>",
 * "mode":..,"leader":..,"services":"Plan=Service,...","groups":"Room1=4,...",
 * "battery":"87"}
 * (`battery` only when the robot knows its level; `groups` only when it
 * passed a statement of counted groups since its mode started: its group at
 * each, in the statements' order, with the members it counted alive when it
 * took it, told by the control task through semo_status_group). */
#define STATUS_PLANS 16
#define STATUS_GROUPS 16
#define STATUS_NAME 64
/* Mission time 0 on the wall clock (Unix ms): the robot's status says it,
 * so that a console can tell the newest run. */
static int64_t g_started_unix_ms;

static struct {
    pthread_mutex_t lock;
    char state[16];
    char mode[STATUS_NAME];
    char leader[STATUS_NAME];
    struct {
        char plan[STATUS_NAME], service[STATUS_NAME];
    } running[STATUS_PLANS];
    size_t running_count;
    /* By statement number, in order. */
    struct {
        unsigned statement;
        char group[STATUS_NAME];
        size_t alive;
    } groups[STATUS_GROUPS];
    size_t group_count;
    bool battery_known;
    long long battery;
} g_status = {.lock = PTHREAD_MUTEX_INITIALIZER};

typedef struct {
    char text[1024 + 4 * STATUS_PLANS * STATUS_NAME + 2 * STATUS_GROUPS * (STATUS_NAME + 24)];
    size_t len;
} status_buffer;

static void put_status(void *ctx, const char *bytes, size_t n)
{
    status_buffer *b = ctx;
    size_t room = sizeof b->text - 1 - b->len;
    n = n < room ? n : room;
    memcpy(b->text + b->len, bytes, n);
    b->len += n;
    b->text[b->len] = '\0';
}

static void status_line(status_buffer *b, const char *event, ...)
{
    semo__sink sink = {put_status, b};
    va_list args;
    va_start(args, event);
    semo__trace_line(&sink, semo_now_ms(), g_prog ? g_prog->robot : "", event, args, NULL, NULL);
    va_end(args);
}

static void copy_name(char *out, const char *name)
{
    snprintf(out, STATUS_NAME, "%s", name ? name : "");
}

/* Publishes the status kept (g_status.lock held). */
static void publish_status(const semo_transport *transport)
{
    char services[STATUS_PLANS * 2 * STATUS_NAME + STATUS_PLANS * 2] = "";
    size_t at = 0;
    for (size_t i = 0; i < g_status.running_count; i++)
        if (g_status.running[i].service[0] && at < sizeof services)
            at += (size_t)snprintf(services + at, sizeof services - at, "%s%s=%s", at ? "," : "",
                                   g_status.running[i].plan, g_status.running[i].service);
    char groups[STATUS_GROUPS * (STATUS_NAME + 24)] = "";
    at = 0;
    for (size_t i = 0; i < g_status.group_count && at < sizeof groups; i++)
        at += (size_t)snprintf(groups + at, sizeof groups - at, "%s%s=%lu", at ? "," : "", g_status.groups[i].group,
                               (unsigned long)g_status.groups[i].alive);
    status_buffer line = {.len = 0};
    char battery[24], started[24];
    semo__format_i64(battery, g_status.battery);
    semo__format_i64(started, g_started_unix_ms);
    /* A field without a value is absent: the list ends before it, or
     * `battery` takes the place of `groups`. */
    bool with_groups = g_status.group_count > 0;
    const char *after = g_status.battery_known ? "battery" : NULL;
    status_line(&line, "status", "state", g_status.state, "started", started, "mode", g_status.mode, "leader",
                g_status.leader, "services", services, with_groups ? "groups" : after, with_groups ? groups : battery,
                with_groups ? after : NULL, battery, NULL);
    if (line.len > 0 && line.text[line.len - 1] == '\n')
        line.text[--line.len] = '\0'; /* one JSON object, not a line */
    transport->status(line.text, line.len);
}

void semo_status_group(unsigned statement, const char *group, size_t alive)
{
    const semo_transport *transport = g_transport;
    if (!transport || !transport->status)
        return;
    pthread_mutex_lock(&g_status.lock);
    size_t i = 0;
    while (i < g_status.group_count && g_status.groups[i].statement < statement)
        i++;
    bool found = i < g_status.group_count && g_status.groups[i].statement == statement;
    bool changed = false;
    if (!group && found) {
        memmove(&g_status.groups[i], &g_status.groups[i + 1], (g_status.group_count - i - 1) * sizeof g_status.groups[0]);
        g_status.group_count--;
        changed = true;
    } else if (group && found && strcmp(g_status.groups[i].group, group) != 0) {
        copy_name(g_status.groups[i].group, group);
        g_status.groups[i].alive = alive;
        changed = true;
    } else if (group && !found && g_status.group_count < STATUS_GROUPS) {
        memmove(&g_status.groups[i + 1], &g_status.groups[i], (g_status.group_count - i) * sizeof g_status.groups[0]);
        g_status.group_count++;
        g_status.groups[i].statement = statement;
        copy_name(g_status.groups[i].group, group);
        g_status.groups[i].alive = alive;
        changed = true;
    }
    /* Before the robot's `start` there is nothing to say yet. */
    if (changed && g_status.state[0])
        publish_status(transport);
    pthread_mutex_unlock(&g_status.lock);
}

static void observe_status(const char *event, va_list args)
{
    const semo_transport *transport = g_transport;
    if (!transport || !transport->status)
        return;
    pthread_mutex_lock(&g_status.lock);
    bool changed = true;
    if (strcmp(event, "start") == 0) {
        snprintf(g_status.state, sizeof g_status.state, "running");
    } else if (strcmp(event, "finish") == 0) {
        snprintf(g_status.state, sizeof g_status.state, "finished");
    } else if (strcmp(event, "stop") == 0) {
        snprintf(g_status.state, sizeof g_status.state, "stopped");
    } else if (strcmp(event, "mode") == 0) {
        copy_name(g_status.mode, semo__trace_pair(args, "mode"));
        /* The new mode's statements tell their groups as they are passed. */
        g_status.group_count = 0;
    } else if (strcmp(event, "leader") == 0) {
        copy_name(g_status.leader, semo__trace_pair(args, "leader"));
    } else if (strcmp(event, "fenced") == 0) {
        g_status.leader[0] = '\0'; /* it knows no leader until it hears a majority */
    } else if (strcmp(event, "service_start") == 0 || strcmp(event, "service_end") == 0) {
        const char *plan = semo__trace_pair(args, "plan");
        size_t i = 0;
        while (i < g_status.running_count && strcmp(g_status.running[i].plan, plan ? plan : "") != 0)
            i++;
        bool starts = strcmp(event, "service_start") == 0;
        if (starts && i == g_status.running_count && i < STATUS_PLANS) {
            g_status.running_count++;
            copy_name(g_status.running[i].plan, plan);
        }
        if (i < g_status.running_count)
            copy_name(g_status.running[i].service, starts ? semo__trace_pair(args, "service") : "");
    } else {
        changed = false;
    }
    /* The battery: what the control task last read of its BATTERY value;
     * in simulation without one, the scenario's level. A new level is
     * published with the next event traced. */
    long long level = 0;
    bool known = semo__battery(&level);
#ifdef SEMO_SIM
    if (!known && g_prog->sim)
        known = g_prog->sim->battery(&level);
#endif
    if (known != g_status.battery_known || (known && level != g_status.battery)) {
        g_status.battery_known = known;
        g_status.battery = level;
        changed = true;
    }
    if (changed)
        publish_status(transport);
    pthread_mutex_unlock(&g_status.lock);
}

static void *receiver_thread(void *arg)
{
    (void)arg;
    unsigned char buf[DATAGRAM_MAX + 1]; /* one spare byte detects oversized datagrams */
    while (semo_running()) {
        /* No timeout: semo_stop_program interrupts the wait. */
        int n = g_transport->recv(buf, sizeof buf, -1);
        semo_message m;
        if (n == SEMO_RECV_REFUSED) {
            semo_trace("reject", "reason", g_transport->refusal, NULL);
        } else if (n == SEMO_RECV_REPLAYED) {
            semo_trace("reject", "reason", SEMO_REPLAYED_REASON, NULL);
        } else if (n == SEMO_RECV_TOO_LONG) {
            semo_trace("reject", "reason", SEMO_TOO_LONG_REASON, NULL);
        } else if (n < 0) {
            semo_trace("comm_error", "reason", "receive failed", NULL);
            semo_sleep_ms(RECV_ERROR_PAUSE_MS); /* a failing socket must not spin */
        } else if (n > 0 && semo__decode_message(buf, (size_t)n, &m)) {
            semo__deliver(&m);
        } else if (n > 0) {
            semo_trace("reject", "reason", "malformed datagram", NULL);
        }
    }
    return NULL;
}

/* ------------------------------------------------------------- stopping */

void semo_stop_program(void)
{
    if (!atomic_exchange(&g_running, false))
        return;
    /* Every waiter re-checks semo_running() under its own lock, so taking
     * each lock before broadcasting means no one can miss the news. */
    pthread_mutex_lock(&g_run_lock);
    cond_broadcast(&g_run_cond);
    pthread_mutex_unlock(&g_run_lock);
    pthread_mutex_lock(&g_inbox_lock);
    cond_broadcast(&g_inbox_cond);
    pthread_mutex_unlock(&g_inbox_lock);
    for (size_t i = 0; g_channels && i < g_prog->channel_count; i++) {
        pthread_mutex_lock(&g_channels[i].lock);
        cond_broadcast(&g_channels[i].readable);
        pthread_mutex_unlock(&g_channels[i].lock);
    }
    pthread_mutex_lock(&g_sends_lock);
    cond_broadcast(&g_sends_cond);
    pthread_mutex_unlock(&g_sends_lock);
    for (size_t i = 0; g_tasks && i < g_prog->task_count; i++) {
        pthread_mutex_lock(&g_tasks[i].lock);
        cond_broadcast(&g_tasks[i].changed);
        pthread_mutex_unlock(&g_tasks[i].lock);
    }
    /* The receiver waits on the socket without a timeout. */
    const semo_transport *transport = g_transport;
    if (transport && transport->interrupt)
        transport->interrupt();
}

/* SIGINT and SIGTERM end the program cleanly (wrapups run, traces close).
 * They are blocked in every thread and taken here with sigwait. */
static sigset_t g_signals;
static atomic_bool g_signal_thread_done;

static void *signal_thread(void *arg)
{
    (void)arg;
    for (;;) {
        int sig;
        if (sigwait(&g_signals, &sig) != 0 || atomic_load(&g_signal_thread_done))
            return NULL;
        semo_trace("signal", "signal", sig == SIGINT ? "SIGINT" : "SIGTERM", NULL);
        semo_stop_program();
    }
}

/* ---------------------------------------------------------------- options */

typedef struct {
    const char *trace;
    const semo_transport *transport;
    char broker_host[256];
    int broker_port;
    bool broker_tls;
    char run[SEMO_RUN_MAX]; /* --run, $SEMO_RUN: the run the MQTT topics are of */
    semo_transport_config identity; /* mqtt: who the robot is at the broker */
    long port_base;
    int64_t duration_ms;
    bool duration_given;
    double time_scale;
    bool time_scale_given;
    long start_at_ms; /* --start-at: Unix ms of mission time 0; 0: when the program starts */
    const char *lockstep; /* --lockstep: the coordinator's socket; NULL: real time */
    unsigned char udp_key[SEMO_UDP_KEY_MAX]; /* $SEMO_UDP_KEY; udp_key_len 0: none */
    size_t udp_key_len;
} options;

/* The latest --start-at (the year 2096): keeps the clock's arithmetic in 64 bits. */
#define START_AT_MAX 4000000000000L

/* The program's connection defaults (`semo build --deploy`); none when the
 * program has no deployment. */
static const semo_deploy_defaults *deployed(void)
{
    static const semo_deploy_defaults none = {0};
    return g_prog->deploy ? g_prog->deploy : &none;
}

/* The broker used when neither --broker nor $SEMO_BROKER names one. */
static const char *default_broker(void)
{
    const char *broker = deployed()->broker;
    return broker ? broker : DEFAULT_BROKER;
}

static void usage(FILE *f, const char *prog)
{
    fprintf(f,
            "usage: %s [--trace FILE] [--transport udp|mqtt|link] [--port-base N] [--broker URL] [--run ID]"
            " [--duration MS] [--start-at UNIX_MS]"
#ifdef SEMO_SIM
            " [--time-scale X] [--lockstep PATH]"
#endif
            "\n"
            "  --trace FILE      write a JSON-lines trace to FILE (\"-\": standard output)\n"
            "  --transport T     udp (loopback), mqtt, or link: the serial link to `semo gateway`\n"
            "                    at $SEMO_LINK=tcp:HOST:PORT (default %s, or $SEMO_TRANSPORT)\n"
            "  --port-base N     udp: robot i uses UDP port N+i on 127.0.0.1 (default %d, or $SEMO_PORT_BASE);\n"
            "                    $SEMO_UDP_KEY (hex, 16 to 64 bytes, the same for every robot of the run):\n"
            "                    datagrams are signed with it, and one not signed with it is refused\n"
            "  --broker URL      mqtt: the broker, mqtt://HOST[:PORT] or mqtts://HOST[:PORT] (TLS)\n"
            "                    (default %s, or $SEMO_BROKER); who the robot is there:\n"
            "                    $SEMO_MQTT_CLIENT_ID, $SEMO_MQTT_USER, $SEMO_MQTT_PASSWORD_FILE, $SEMO_MQTT_CA,\n"
            "                    $SEMO_MQTT_CERT, $SEMO_MQTT_KEY (defaults from semo build --deploy)\n"
            "  --run ID          mqtt: the run this robot takes part in (default \"" SEMO_RUN_DEFAULT "\", or $SEMO_RUN):\n"
            "                    its topics are semo/<mission>/ID/..., so that a run hears nothing of\n"
            "                    another; every robot of a run is given the same ID\n"
            "  --duration MS     stop after MS mission milliseconds (0: run until stopped)\n"
            "  --start-at T      mission time 0 is the wall-clock instant T (ms since 1970, or $SEMO_START_AT):\n"
            "                    robots given the same T start together; a T passed continues its mission time\n"
#ifdef SEMO_SIM
            "  --time-scale X    wall ms per mission ms (0.1: ten times faster; default: the scenario's\n"
            "                    time_scale, else 1); the scenario is compiled in (semo build --scenario FILE)\n"
            "  --lockstep PATH   virtual time: mission time and messages come from the coordinator on\n"
            "                    the Unix socket PATH (`semo simulate --engine c`); --start-at, --time-scale,\n"
            "                    --transport and --port-base do not apply\n"
#endif
            ,
            prog, DEFAULT_TRANSPORT, DEFAULT_PORT_BASE, default_broker());
}

static bool parse_long(const char *s, long min, long max, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (*s == '\0' || *end != '\0' || errno != 0 || v < min || v > max)
        return false;
    *out = v;
    return true;
}

/* `udp` or `mqtt` (when built in): the transport of that name. */
static bool parse_transport(const char *prog, const char *name, const semo_transport **out)
{
    if (strcmp(name, "udp") == 0) {
        *out = &semo_udp_transport;
        return true;
    }
    if (strcmp(name, "link") == 0) {
        *out = &semo_link_transport;
        return true;
    }
#ifdef SEMO_MQTT
    if (strcmp(name, "mqtt") == 0) {
        *out = &semo_mqtt_transport;
        return true;
    }
#else
    if (strcmp(name, "mqtt") == 0) {
        fprintf(stderr, "%s: this program was built without the mqtt transport (rebuild with `make TRANSPORT=mqtt`)\n",
                prog);
        return false;
    }
#endif
    fprintf(stderr, "%s: the transport must be udp or mqtt or link, not \"%s\"\n", prog, name);
    return false;
}

/* `mqtt://HOST[:PORT]` or `mqtts://HOST[:PORT]` (port 1883 or 8883 when
 * left out) into the options. */
static bool parse_broker(const char *prog, const char *url, options *o)
{
    bool tls = strncmp(url, "mqtts://", 8) == 0;
    const char *rest = tls ? url + 8 : strncmp(url, "mqtt://", 7) == 0 ? url + 7 : NULL;
    if (!rest) {
        fprintf(stderr, "%s: the broker must be mqtt://HOST[:PORT] or mqtts://HOST[:PORT], not \"%s\"\n", prog, url);
        return false;
    }
    const char *colon = strrchr(rest, ':');
    size_t host_len = colon ? (size_t)(colon - rest) : strlen(rest);
    long port = tls ? 8883 : 1883;
    if (host_len == 0 || host_len >= sizeof o->broker_host || (colon && !parse_long(colon + 1, 1, 65535, &port))) {
        fprintf(stderr, "%s: the broker must be %s://HOST[:PORT] with a port from 1 to 65535, not \"%s\"\n", prog,
                tls ? "mqtts" : "mqtt", url);
        return false;
    }
    memcpy(o->broker_host, rest, host_len);
    o->broker_host[host_len] = '\0';
    o->broker_port = (int)port;
    o->broker_tls = tls;
    return true;
}

static bool ascii_alnum(char c)
{
    return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
}

/* A run id, checked as `semo::deploy::topics::RunId::parse` does: 1 to
 * SEMO_RUN_MAX - 1 ASCII letters, digits, `-`, `_` and `.`, starting with a
 * letter or a digit. It becomes a topic level and part of the client id as
 * it is, so nothing MQTT gives a meaning to (`/`, `+`, `#`) gets in, nor a
 * name a file system does (`.`, `..`). Copied into `o->run`. */
static bool parse_run(const char *prog, const char *from, const char *id, options *o)
{
    size_t n = strlen(id);
    bool fits = n > 0 && n < sizeof o->run && ascii_alnum(id[0]);
    for (size_t i = 0; fits && i < n; i++)
        fits = ascii_alnum(id[i]) || id[i] == '-' || id[i] == '_' || id[i] == '.';
    if (!fits) {
        fprintf(stderr,
                "%s: %s must be 1 to %d letters, digits, '-', '_' and '.', starting with a letter or a digit, not "
                "\"%s\"\n",
                prog, from, SEMO_RUN_MAX - 1, id);
        return false;
    }
    memcpy(o->run, id, n + 1);
    return true;
}

/* The deployment's value of a connection setting, under its environment
 * variable; NULL when neither gives one. */
static const char *setting(const char *env_name, const char *deployed)
{
    const char *env = getenv(env_name);
    return env && *env ? env : deployed;
}

/* Who the robot is at the broker, into `o->identity`; with the MQTT
 * transport chosen, false (the problem printed) when the settings do not fit
 * together. */
static bool mqtt_identity(const char *prog, options *o)
{
    semo_transport_config *net = &o->identity;
    net->broker_tls = o->broker_tls;
    const semo_deploy_defaults *d = deployed();
    net->client_id = setting("SEMO_MQTT_CLIENT_ID", d->client_id);
    net->user = setting("SEMO_MQTT_USER", d->user);
    net->password_file = setting("SEMO_MQTT_PASSWORD_FILE", d->password_file);
    net->ca = setting("SEMO_MQTT_CA", d->ca);
    net->cert = setting("SEMO_MQTT_CERT", d->cert);
    net->key = setting("SEMO_MQTT_KEY", d->key);
    const char *problem = NULL;
    if (net->password_file && !net->user)
        problem = "a password file needs a user ($SEMO_MQTT_USER)";
    else if (!net->cert != !net->key)
        problem = "a client certificate needs both $SEMO_MQTT_CERT and $SEMO_MQTT_KEY";
    else if (net->broker_tls && !net->ca)
        problem = "an mqtts:// broker needs the CA that signed its certificate ($SEMO_MQTT_CA)";
    else if (!net->broker_tls && net->cert)
        problem = "a client certificate needs an mqtts:// broker";
    if (o->transport == &semo_udp_transport || o->transport == &semo_link_transport)
        return true;
    if (problem)
        fprintf(stderr, "%s: %s\n", prog, problem);
    return !problem;
}

/* $SEMO_UDP_KEY, hexadecimal, into `o->udp_key`; false when it is not 16
 * to 64 bytes of hexadecimal digits. */
static bool parse_udp_key(const char *hex, options *o)
{
    size_t digits = strlen(hex);
    if (digits % 2 != 0 || digits < 32 || digits > 2 * SEMO_UDP_KEY_MAX)
        return false;
    for (size_t i = 0; i < digits; i++) {
        char c = hex[i];
        int v = -1;
        if (c >= '0' && c <= '9')
            v = c - '0';
        else if (c >= 'a' && c <= 'f')
            v = c - 'a' + 10;
        else if (c >= 'A' && c <= 'F')
            v = c - 'A' + 10;
        if (v < 0)
            return false;
        o->udp_key[i / 2] = (unsigned char)(i % 2 == 0 ? v << 4 : o->udp_key[i / 2] | v);
    }
    o->udp_key_len = digits / 2;
    return true;
}

/* 0: run; 1: help printed; 2: bad command line (message printed). */
static int parse_options(int argc, char **argv, options *o)
{
    const char *prog = argc > 0 && argv[0] ? argv[0] : "robot";
    size_t robots = g_prog->robot_count ? g_prog->robot_count : 1;
    long max_base = 65536 - (long)robots;
    const char *env = getenv("SEMO_PORT_BASE");
    o->port_base = DEFAULT_PORT_BASE;
    if (env && !parse_long(env, 1, max_base, &o->port_base)) {
        fprintf(stderr, "%s: SEMO_PORT_BASE must be a port number from 1 to %ld, not \"%s\"\n", prog, max_base, env);
        return 2;
    }
    env = getenv("SEMO_START_AT");
    if (env && *env && !parse_long(env, 1, START_AT_MAX, &o->start_at_ms)) {
        fprintf(stderr, "%s: SEMO_START_AT must be a time in ms since 1970, not \"%s\"\n", prog, env);
        return 2;
    }
    env = getenv("SEMO_TRANSPORT");
    if (!parse_transport(prog, env && *env ? env : DEFAULT_TRANSPORT, &o->transport))
        return 2;
    env = getenv("SEMO_UDP_KEY");
    if (env && *env && !parse_udp_key(env, o)) {
        fprintf(stderr, "%s: SEMO_UDP_KEY must be 32 to 128 hexadecimal digits (16 to 64 bytes), such as `od -An -N32 -tx1 /dev/urandom | tr -d ' \\n'` writes\n", prog);
        return 2;
    }
    env = getenv("SEMO_BROKER");
    if (!parse_broker(prog, env && *env ? env : default_broker(), o))
        return 2;
    env = getenv("SEMO_RUN");
    if (!parse_run(prog, "SEMO_RUN", env && *env ? env : SEMO_RUN_DEFAULT, o))
        return 2;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0) {
            usage(stdout, prog);
            return 1;
        }
        static const char *const names[] = {"--trace",      "--port-base", "--duration", "--scenario",
                                            "--time-scale", "--transport", "--broker",  "--start-at",
                                            "--lockstep",   "--run"};
        size_t which = sizeof names / sizeof names[0];
        const char *value = NULL;
        for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
            size_t len = strlen(names[k]);
            if (strncmp(arg, names[k], len) == 0 && (arg[len] == '\0' || arg[len] == '=')) {
                which = k;
                value = arg[len] == '=' ? arg + len + 1 : (i + 1 < argc ? argv[++i] : NULL);
            }
        }
        if (which == 3) { /* the scenario is the build's: no program reads one */
            fprintf(stderr,
                    "%s: --scenario is not read at run time: a simulation's scenario is compiled into the program;"
                    " build it with `semo build --sim --scenario FILE`\n",
                    prog);
            return 2;
        }
#ifndef SEMO_SIM
        if (which == 4 || which == 8) {
            fprintf(stderr, "%s: %s needs a simulation build (-DSEMO_SIM)\n", prog, names[which]);
            return 2;
        }
#endif
        if (which == sizeof names / sizeof names[0]) {
            fprintf(stderr, "%s: unknown option \"%s\"\n", prog, arg);
            usage(stderr, prog);
            return 2;
        }
        if (!value) {
            fprintf(stderr, "%s: %s needs a value\n", prog, names[which]);
            usage(stderr, prog);
            return 2;
        }
        long n;
        char *end;
        switch (which) {
        case 0:
            o->trace = value;
            break;
        case 1:
            if (!parse_long(value, 1, max_base, &o->port_base)) {
                fprintf(stderr, "%s: --port-base must be a port number from 1 to %ld, not \"%s\"\n", prog, max_base,
                        value);
                return 2;
            }
            break;
        case 2:
            if (!parse_long(value, 0, LONG_MAX, &n)) {
                fprintf(stderr, "%s: --duration must be a whole number of milliseconds, not \"%s\"\n", prog, value);
                return 2;
            }
            o->duration_ms = n;
            o->duration_given = true;
            break;
        case 4:
            o->time_scale = strtod(value, &end);
            if (*value == '\0' || *end != '\0' ||
                !(o->time_scale >= SEMO_TIME_SCALE_MIN && o->time_scale <= SEMO_TIME_SCALE_MAX)) {
                fprintf(stderr, "%s: --time-scale must be a positive number from 0.000001 to 1000000, not \"%s\"\n", prog,
                        value);
                return 2;
            }
            o->time_scale_given = true;
            break;
        case 5:
            if (!parse_transport(prog, value, &o->transport))
                return 2;
            break;
        case 6:
            if (!parse_broker(prog, value, o))
                return 2;
            break;
        case 7:
            if (!parse_long(value, 1, START_AT_MAX, &o->start_at_ms)) {
                fprintf(stderr, "%s: --start-at must be a time in ms since 1970, not \"%s\"\n", prog, value);
                return 2;
            }
            break;
        case 8:
            o->lockstep = value;
            break;
        case 9:
            if (!parse_run(prog, "--run", value, o))
                return 2;
            break;
        }
    }
    return mqtt_identity(prog, o) ? 0 : 2;
}

/* The generator's tables, checked once so that the calls above can trust them. */
static bool program_is_valid(const semo_program_desc *p)
{
    const char *problem = NULL;
    if (!p->team || !p->robot || strlen(p->team) >= 32 || strlen(p->robot) >= 32)
        problem = "team and robot names must be given and shorter than 32 bytes";
    else if ((p->task_count && !p->tasks) || (p->channel_count && !p->channels) || (p->group_count && !p->groups) ||
             (p->peer_count && !p->peers))
        problem = "a table has entries but no array";
    else if (p->peer_count && p->self >= p->peer_count)
        problem = "`self` is not an index of `peers`";
    else if (p->robot_count < p->peer_count || p->robot_count > 65535)
        problem = "the mission has fewer robots than `peers` or more than ports";
    for (size_t i = 0; !problem && i < p->task_count; i++)
        if (!p->tasks[i].name || (p->tasks[i].trigger == SEMO_TRIGGER_TIME && p->tasks[i].period_ms <= 0))
            problem = "every task needs a name, and time-driven tasks a positive period";
    for (size_t i = 0; !problem && i < p->channel_count; i++) {
        const semo_channel_desc *c = &p->channels[i];
        if (!c->src_task || !c->src_port || !c->dst_task || !c->dst_port || c->sample_size == 0 ||
            c->sample_size > INT_MAX || c->capacity > SIZE_MAX / c->sample_size / 2 ||
            c->initial_samples > SIZE_MAX / c->sample_size / 2)
            problem = "a channel lacks a name or has an impossible size";
    }
    for (size_t i = 0; !problem && i < p->group_count; i++)
        if (!p->groups[i].name || p->groups[i].sample_size == 0 || p->groups[i].sample_size > INT_MAX)
            problem = "a multicast group lacks a name or a size";
    for (size_t i = 0; !problem && i < p->peer_count; i++)
        if (!p->peers[i].team || !p->peers[i].robot)
            problem = "a peer lacks a team or robot name";
        else if (p->peers[i].index >= p->robot_count || (i > 0 && p->peers[i].index <= p->peers[i - 1].index))
            problem = "the peers' places must rise and be places of the mission's robots";
    if (problem)
        fprintf(stderr, "semo runtime: invalid program tables: %s\n", problem);
    return !problem;
}

/* ------------------------------------------------------- set-up, tear-down */

static void free_program_state(void)
{
    const semo_program_desc *p = g_prog;
    for (size_t i = 0; g_channels && i < p->channel_count; i++) {
        free(g_channels[i].ring.storage);
        pthread_mutex_destroy(&g_channels[i].lock);
        pthread_cond_destroy(&g_channels[i].readable);
    }
    for (size_t i = 0; g_groups && i < p->group_count; i++) {
        free(g_groups[i].buf);
        pthread_mutex_destroy(&g_groups[i].lock);
    }
    for (size_t i = 0; g_tasks && i < p->task_count; i++) {
        for (param *q = g_tasks[i].params, *next; q; q = next) {
            next = q->next;
            free(q);
        }
        pthread_mutex_destroy(&g_tasks[i].lock);
        pthread_cond_destroy(&g_tasks[i].changed);
    }
    free(g_channels);
    free(g_groups);
    free(g_tasks);
    free(g_timers);
    g_channels = NULL;
    g_groups = NULL;
    g_tasks = NULL;
    g_timers = NULL;
    g_timer_count = 0;
    semo__inbox_reset();
}

static bool allocate_program_state(const semo_program_desc *p)
{
    g_channels = calloc(p->channel_count ? p->channel_count : 1, sizeof *g_channels);
    g_groups = calloc(p->group_count ? p->group_count : 1, sizeof *g_groups);
    g_tasks = calloc(p->task_count ? p->task_count : 1, sizeof *g_tasks);
    if (!g_channels || !g_groups || !g_tasks)
        return false;
    bool ok = true;
    for (size_t i = 0; i < p->channel_count; i++) {
        channel *c = &g_channels[i];
        const semo_channel_desc *d = &p->channels[i];
        size_t capacity = d->capacity;
        if (capacity < d->initial_samples)
            capacity = d->initial_samples;
        if (capacity == 0)
            capacity = 1;
        c->state.count = d->initial_samples;
        c->ring = (semo__ring){calloc(capacity, d->sample_size), &c->state, capacity, d->sample_size};
        ok = ok && c->ring.storage;
        pthread_mutex_init(&c->lock, NULL);
        init_cond(&c->readable);
    }
    for (size_t i = 0; i < p->group_count; i++) {
        g_groups[i].desc = &p->groups[i];
        g_groups[i].buf = calloc(1, p->groups[i].sample_size);
        ok = ok && g_groups[i].buf;
        pthread_mutex_init(&g_groups[i].lock, NULL);
    }
    for (size_t i = 0; i < p->channel_count; i++)
        for (size_t k = 0; k < p->task_count; k++) {
            if (strcmp(p->channels[i].dst_task, p->tasks[k].name) == 0)
                g_channels[i].reader = &g_tasks[k];
            if (strcmp(p->channels[i].src_task, p->tasks[k].name) == 0)
                g_channels[i].writer = &g_tasks[k];
        }
    for (size_t i = 0; i < p->task_count; i++) {
        task *t = &g_tasks[i];
        t->desc = &p->tasks[i];
        bool starts = t->desc->trigger != SEMO_TRIGGER_CONTROL;
        t->control.state = starts ? SEMO_TASK_RUNNING : SEMO_TASK_IDLE;
        t->control.repeat = starts;
        pthread_mutex_init(&t->lock, NULL);
        init_cond(&t->changed);
    }
    return ok;
}

static int open_trace(const char *path)
{
    if (!path)
        return 0;
    if (strcmp(path, "-") == 0) {
        g_trace = stdout;
        return 0;
    }
    g_trace = fopen(path, "w");
    if (!g_trace) {
        fprintf(stderr, "semo runtime: cannot write the trace \"%s\": %s\n", path, strerror(errno));
        return -1;
    }
    g_trace_owned = true;
    return 0;
}

static void close_trace(void)
{
    pthread_mutex_lock(&g_trace_lock);
    if (g_trace_owned)
        fclose(g_trace);
    g_trace = NULL;
    g_trace_owned = false;
    pthread_mutex_unlock(&g_trace_lock);
}

/* `takes_turns`: in lock-step, a thread of the program (not the signal
 * watcher, which only waits for signals). */
static bool start_thread(pthread_t *thread, void *(*body)(void *), void *arg, bool takes_turns)
{
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    pthread_attr_setstacksize(&attr, SEMO_STACK_BYTES);
#ifdef SEMO_SIM
    bool ok = (takes_turns && semo__ls_turns() ? semo__ls_create(thread, &attr, body, arg)
                                              : pthread_create(thread, &attr, body, arg)) == 0;
#else
    (void)takes_turns;
    bool ok = pthread_create(thread, &attr, body, arg) == 0;
#endif
    pthread_attr_destroy(&attr);
    if (!ok)
        fprintf(stderr, "semo runtime: cannot start a thread\n");
    return ok;
}

#ifdef SEMO_SIM
bool semo__start_thread(pthread_t *thread, void *(*body)(void *), void *arg)
{
    return start_thread(thread, body, arg, true);
}
#endif

/* Mission time 0: now, or the wall-clock instant `start_at_ms` (Unix ms),
 * as a monotonic instant (in the future: the start barrier; in the past: a
 * restarted robot continues its mission's time). */
static void start_clock(long start_at_ms)
{
    clock_gettime(CLOCK_MONOTONIC, &g_t0);
    struct timespec real;
    clock_gettime(CLOCK_REALTIME, &real);
    g_started_unix_ms = start_at_ms > 0 ? start_at_ms : (int64_t)real.tv_sec * 1000 + real.tv_nsec / 1000000;
    if (start_at_ms <= 0)
        return;
    long long ahead_ns = ((long long)start_at_ms - (long long)real.tv_sec * 1000LL) * 1000000LL - real.tv_nsec;
    long long t0_ns = (long long)g_t0.tv_nsec + ahead_ns % 1000000000LL;
    g_t0.tv_sec += (time_t)(ahead_ns / 1000000000LL) + (time_t)(t0_ns / 1000000000LL);
    g_t0.tv_nsec = (long)(t0_ns % 1000000000LL);
    if (g_t0.tv_nsec < 0) {
        g_t0.tv_nsec += 1000000000L;
        g_t0.tv_sec -= 1;
    }
}

/* Starts everything, waits for the end, stops everything; 0 or 1. */
/* The first trace line. A simulated robot on the wall clock also says the
 * speed it runs at (wall ms per mission ms), so a test or an operator reads
 * the scale it applied instead of timing the run; in lock-step there is no
 * wall clock to scale. */
static void trace_start(const semo_program_desc *p, const options *o)
{
    const char *type = p->robot_type ? p->robot_type : "", *mission = p->mission ? p->mission : "";
#ifdef SEMO_SIM
    if (!o->lockstep) {
        char scale[40];
        semo_value_json(SEMO_LIT_REAL(g_scale), scale, sizeof scale);
        semo_trace("start", "team", p->team, "type", type, "mission", mission, "time_scale", scale, NULL);
        return;
    }
#else
    (void)o;
#endif
    semo_trace("start", "team", p->team, "type", type, "mission", mission, NULL);
}

static int run(const options *o)
{
    const semo_program_desc *p = g_prog;
    int status = 0;
    pthread_t receiver, signals;
    bool receiver_started = false, signals_started = false;
    size_t initialized = 0; /* tasks whose init ran get their wrapup */
#ifdef SEMO_SIM
    bool sim_started = false;
#endif
    sigset_t old_mask;
    sigemptyset(&g_signals);
    sigaddset(&g_signals, SIGINT);
    sigaddset(&g_signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &g_signals, &old_mask);
    atomic_store(&g_signal_thread_done, false);

    start_clock(o->start_at_ms);
    atomic_store(&g_running, true);
#ifdef SEMO_SIM
    /* Lock-step: the coordinator is the clock and the network. */
    if (o->lockstep) {
        if (semo__ls_connect(o->lockstep, p->peer_count ? p->peers[p->self].index : 0) != 0) {
            status = 1;
            goto stop;
        }
        if (p->robot_count > 1)
            g_transport = &semo_lockstep_transport;
    }
#endif
    /* A robot alone in its mission has no one to hear from: no port, no receiver. */
    if (p->robot_count > 1 && !g_transport) {
        semo_transport_config net = o->identity;
        net.port_base = o->port_base;
        net.broker_host = o->broker_host;
        net.broker_port = o->broker_port;
        net.run = o->run;
        net.started_unix_ms = g_started_unix_ms;
        net.udp_key = o->udp_key;
        net.udp_key_len = o->udp_key_len;
        net.link = getenv("SEMO_LINK");
        if (o->transport->open(p, &net) != 0) {
            if (o->transport == &semo_udp_transport)
                fprintf(stderr, "semo runtime: cannot open the udp transport on port %ld\n", o->port_base + (long)p->peers[p->self].index);
            else
                fprintf(stderr, "semo runtime: cannot open the %s transport\n", o->transport->name);
            status = 1;
            goto stop;
        }
        g_transport = o->transport;
#ifdef SEMO_SIM
        if (o->transport->send_to && p->sim && p->sim->world->link_count > 0) {
            fprintf(stderr, "semo runtime: the scenario's link faults need a transport that sends to each robot (udp)\n");
            status = 1;
            goto stop;
        }
#endif
    }
    signals_started = start_thread(&signals, signal_thread, NULL, false);
    /* The start barrier: the transport is open (a robot's messages reach the
     * others from the first), the clock starts at the agreed instant. */
    if (!semo__wait_until(0))
        goto stop;
    g_joined_at = semo_now_ms();
    trace_start(p, o);
#ifdef SEMO_SIM
    /* A fault at the instant the robot starts (a kill at 0 ms) comes after
     * its `start` and before anything else it does, as in the simulator. */
    if (o->lockstep)
        semo__ls_pause();
#endif
    for (; initialized < p->task_count; initialized++)
        if (p->tasks[initialized].init)
            p->tasks[initialized].init();
    if (g_transport)
        receiver_started = start_thread(&receiver, receiver_thread, NULL, true);
#ifdef SEMO_SIM
    sim_started = !p->sim || p->sim->start() == 0;
    if (!sim_started)
        status = 1;
#endif
    for (size_t i = 0; i < p->task_count && status == 0; i++) {
        g_tasks[i].started = start_thread(&g_tasks[i].thread, task_thread, &g_tasks[i], true);
        if (!g_tasks[i].started)
            status = 1;
    }
    if (!signals_started || (g_transport && !receiver_started))
        status = 1;

    if (status == 0)
        semo__wait_until(o->duration_ms > 0 ? o->duration_ms : INT64_MAX);
stop:
    semo_stop_program();
#ifdef SEMO_SIM
    /* The main thread only joins from here: the others take the turns, at
     * the instant the program stopped. */
    semo__ls_stopping();
    semo__ls_leave();
#endif
    for (size_t i = 0; i < p->task_count; i++)
        if (g_tasks[i].started)
            pthread_join(g_tasks[i].thread, NULL);
    if (receiver_started)
        pthread_join(receiver, NULL);
#ifdef SEMO_SIM
    if (sim_started && p->sim)
        p->sim->stop();
#endif
    if (signals_started) {
        atomic_store(&g_signal_thread_done, true);
        pthread_kill(signals, SIGTERM); /* taken by its sigwait, never delivered */
        pthread_join(signals, NULL);
    }
    for (size_t i = 0; i < initialized; i++)
        if (p->tasks[i].wrapup)
            p->tasks[i].wrapup();
    semo__trace_dropped_samples();
    if (g_transport == &semo_link_transport)
        semo__link_report();
    semo_trace("stop", NULL);
    if (g_transport)
        g_transport->close();
    g_transport = NULL;
#ifdef SEMO_SIM
    semo__ls_close();
#endif
    pthread_sigmask(SIG_SETMASK, &old_mask, NULL);
    return status;
}

int semo_main(int argc, char **argv, const semo_program_desc *program)
{
    if (!program || g_prog) {
        fprintf(stderr, "semo runtime: semo_main needs a program and runs one at a time\n");
        return 1;
    }
    if (!program_is_valid(program))
        return 1;
    g_prog = program;
    options o = {0};
    int status = parse_options(argc, argv, &o);
    if (status == 1) { /* --help */
        g_prog = NULL;
        return 0;
    }
#ifdef SEMO_SIM
    /* The world's settings, compiled in; the command line's win. */
    const semo__sim_tables *world = program->sim ? program->sim->world : NULL;
    if (!o.time_scale_given)
        o.time_scale = world && world->time_scale > 0 ? world->time_scale : 1.0;
    if (!o.duration_given)
        o.duration_ms = world ? world->duration_ms : 0;
#endif
    if (status == 0) {
        g_scale = o.time_scale > 0 ? o.time_scale : 1.0;
        init_cond(&g_run_cond);
        init_cond(&g_inbox_cond);
        init_cond(&g_sends_cond);
        if (open_trace(o.trace) != 0) {
            status = 1;
        } else if (!allocate_program_state(program)) {
            fprintf(stderr, "semo runtime: out of memory\n");
            status = 1;
        } else {
            status = run(&o);
        }
        free_program_state();
        close_trace();
        pthread_cond_destroy(&g_run_cond);
        pthread_cond_destroy(&g_inbox_cond);
    }
    g_prog = NULL;
    return status;
}
