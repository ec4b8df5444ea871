/* semo_static.c: the static-schedule platform layer of the SeMo runtime
 * (targets `cortex-m`, `cortex-m-sim`; built with -DSEMO_STATIC).
 *
 * One loop and no threads: `Core_1_go` fires the due tasks in the order of
 * the single-appearance schedule; then the loop works out when a task is
 * next due (a period, a task's `semo_next_firing`, data waiting, an
 * operator command, the end of the run) and the board sleeps until then:
 * no clock tick, so an idle robot wakes only for its deadlines. No call
 * blocks, nothing is allocated: channels live in the buffers the generated
 * channels.c gives them, everything else in the fixed tables below (sizes
 * overridable with -D). The board file (semo_lm3s6965.c, semo_stm32f405.c)
 * gives the trace's output, the core (semo_cortex_m.c) the clock and the
 * exit.
 */
#include "semo_internal.h"

#include <string.h>

#ifndef SEMO_MAX_TASKS
#define SEMO_MAX_TASKS 32
#endif
#ifndef SEMO_MAX_TIMERS
#define SEMO_MAX_TIMERS 8
#endif
#ifndef SEMO_MAX_PARAMS
#define SEMO_MAX_PARAMS 8
#endif
#ifndef SEMO_MAX_GROUPS
#define SEMO_MAX_GROUPS 4
#endif

/* ------------------------------------------------------------ run state */

static const semo_program_desc *g_prog;
static bool g_running;
static int64_t g_start_ms;
static unsigned long g_passes; /* loop iterations: wake-ups (-DSEMO_COUNT_PASSES prints them) */

bool semo_running(void)
{
    return g_running;
}

const semo_program_desc *semo_program(void)
{
    return g_prog;
}

void semo_stop_program(void)
{
    g_running = false;
}

/* ------------------------------------------------------------------ time */

int64_t semo_now_ms(void)
{
#ifdef SEMO_LOCKSTEP
    return semo__lockstep_now();
#else
    return semo__board_now_ms() - g_start_ms;
#endif
}

/* Blocks the whole loop: only for start-up code, never in a task body. */
void semo_sleep_ms(int64_t ms)
{
    int64_t end = semo_now_ms() + ms;
    while (g_running && semo_now_ms() < end)
#ifdef SEMO_LOCKSTEP
        semo__lockstep_idle(end);
#else
        semo__board_sleep_until(g_start_ms + end);
#endif
}

/* ----------------------------------------------------------------- traces */

void semo__trace_emit(const char *event, const char *value_key, const semo_value *value, va_list args)
{
#if defined(SEMO_LINK) && !defined(SEMO_LOCKSTEP)
    /* The status follows the trace (before its line, as on POSIX). */
    va_list seen;
    va_copy(seen, args);
    semo__status_observe(event, seen);
    va_end(seen);
#endif
    semo__sink sink = {semo__board_put, NULL};
    semo__trace_line(&sink, semo_now_ms(), g_prog ? g_prog->robot : "", event, args, value_key, value);
}

#if !defined(SEMO_LINK) || defined(SEMO_LOCKSTEP)
/* A board robot alone, or in lock-step, has no status (a linked one's is
 * in semo_static_status.c, its groups with it). */
void semo_status_group(unsigned statement, const char *group, size_t alive)
{
    (void)statement;
    (void)group;
    (void)alive;
}
#endif

/* --------------------------------------------------------------- channels */

static void wake_reader(int port);
static void wake_group_readers(void);
static void mark_group_reader(void);

/* The rings are the core's (semo_core.c); here they live in the buffers of
 * the generated channels.c, and nothing locks or waits. */
bool semo__channel_ring(int port, semo__ring *out)
{
    if (!g_prog || port < 0 || (size_t)port >= g_prog->channel_count)
        return false;
    const semo_channel_desc *c = &g_prog->channels[port];
    if (!c->storage || !c->state)
        return false;
    *out = (semo__ring){c->storage, c->state, c->capacity, c->sample_size};
    return true;
}

void semo__queue_lock(int queue)
{
    (void)queue;
}

void semo__queue_unlock(int queue)
{
    (void)queue;
}

#ifdef SEMO_LOCKSTEP
static bool drain_inbox(void);
#endif

/* Nothing would write while this waited: a read of an empty queue returns.
 * In lock-step a delivery to a full inbox (messages come only between
 * passes) fires the task that reads it first, as a POSIX robot's receiver
 * waits for it; elsewhere the message is dropped (a link holds it back on
 * the line instead: semo__inbox_holds_back). */
bool semo__queue_wait(int queue, int64_t deadline_ms)
{
    (void)deadline_ms;
#ifdef SEMO_LOCKSTEP
    if (queue == SEMO__INBOX)
        return drain_inbox();
#else
    (void)queue;
#endif
    return false;
}

/* One loop: no writer fires while the send task does, so what it has
 * taken is all its writer's firing sent. */
bool semo_port_await_sends(const int *ports, size_t count)
{
    (void)ports;
    (void)count;
    return false;
}

/* A sample voids its reader's hint; a message needs no wake-up (the loop
 * looks at the inbox: semo__inbox_waiting). */
void semo__queue_written(int queue)
{
    if (queue >= 0)
        wake_reader(queue);
}

/* -------------------------------------------------------------- multicast */

static semo_value g_group_value[SEMO_MAX_GROUPS];
static bool g_group_written[SEMO_MAX_GROUPS];

static int find_group(const char *name, size_t size)
{
    for (size_t i = 0; g_prog && name && i < g_prog->group_count && i < SEMO_MAX_GROUPS; i++)
        if (strcmp(g_prog->groups[i].name, name) == 0 && size == g_prog->groups[i].sample_size &&
            size <= sizeof(semo_value))
            return (int)i;
    return -1;
}

int UFMulticast_Write(const char *name, const void *buf, size_t size)
{
    int g = find_group(name, size);
    if (g < 0 || !buf)
        return 0;
    memcpy(&g_group_value[g], buf, size);
    g_group_written[g] = true;
    wake_group_readers();
    return (int)size;
}

int UFMulticast_Read(const char *name, void *buf, size_t size)
{
    int g = find_group(name, size);
    mark_group_reader();
    if (g < 0 || !buf || !g_group_written[g])
        return 0;
    memcpy(buf, &g_group_value[g], size);
    return (int)size;
}

/* ------------------------------------------------------------------ tasks */

typedef struct task_s task;
struct task_s {
    semo__task_control control; /* changed by UFControl_* (the core's switch) */
    bool in_firing; /* a body said semo_firing_continues */
    int64_t next_release;
    /* semo_next_firing, as on POSIX: not needed before `hint_ms` unless
     * `woken` (a sample in one of its channels, a change of state of a task
     * it controls, a group written when it reads groups). */
    bool hinted, woken;
    int64_t hint_ms;
    task *controller; /* the task that last ran, called or stopped it */
    bool reads_groups;
};

static task g_tasks[SEMO_MAX_TASKS];
/* Mission time of the loop's first pass: the start of every time-driven
 * task's period grid (-1: before it). */
static int64_t g_first_pass_ms = -1;
static bool g_continues; /* set by the body being fired */
static task *g_current;  /* the task being fired */

static task *find_task(const char *name)
{
    if (!g_prog || !name)
        return NULL;
    for (size_t i = 0; i < g_prog->task_count; i++)
        if (strcmp(g_prog->tasks[i].name, name) == 0)
            return &g_tasks[i];
    return NULL;
}

#ifdef SEMO_LOCKSTEP
/* The task that reads the inbox: the last one that polled it. */
static task *g_inbox_reader;
#endif

void semo__inbox_polled(void)
{
#ifdef SEMO_LOCKSTEP
    if (g_current)
        g_inbox_reader = g_current;
#endif
}

#ifdef SEMO_LOCKSTEP
static void fire_if_due(size_t i);

/* Outside any firing, the inbox full: fires its reader once; whether it
 * made room. */
static bool drain_inbox(void)
{
    if (!g_inbox_reader || g_current)
        return false;
    bool held = semo__inbox_holds_back();
    fire_if_due((size_t)(g_inbox_reader - g_tasks));
    return held && !semo__inbox_holds_back();
}
#endif

/* Something task `t` may wait for happened: its hint is void. */
static void wake_task(task *t)
{
    if (t && t != g_current)
        t->woken = true;
}

void semo_wake(const char *task_name)
{
    wake_task(find_task(task_name));
}

static void wake_reader(int port)
{
    unsigned short reader = g_prog->channels[port].state->reader;
    if (reader < g_prog->task_count)
        wake_task(&g_tasks[reader]);
}

/* Nothing else runs while a writer waits: a full message channel makes
 * room by firing its reader at once, as the control task's last firing
 * does (CommSend takes every message and only sends them on); a second
 * call, or a writer that may give up (CommReceive, never here), gives up. */
bool semo__queue_wait_room(int port, semo__room_wait *room)
{
    unsigned short reader = g_prog->channels[port].state->reader;
    if (!room->patient || room->marked || reader >= g_prog->task_count || &g_tasks[reader] == g_current ||
        !g_prog->tasks[reader].go)
        return false;
    room->marked = true;
    task *writer = g_current;
    bool continues = g_continues;
    g_current = &g_tasks[reader];
    g_prog->tasks[reader].go();
    g_current = writer;
    g_continues = continues;
    return true;
}

void semo__queue_taken(int port)
{
    (void)port;
}

static void wake_group_readers(void)
{
    for (size_t i = 0; g_prog && i < g_prog->task_count; i++)
        if (g_tasks[i].reads_groups)
            wake_task(&g_tasks[i]);
}

static void mark_group_reader(void)
{
    if (g_current)
        g_current->reads_groups = true;
}

/* On the static schedule any task may say it: a time-driven one for its
 * next firing, a continuing firing (semo_firing_continues) for its next
 * step. The loop sleeps until the earliest. */
void semo_next_firing(int64_t at_ms)
{
    if (g_current) {
        g_current->hinted = true;
        g_current->hint_ms = at_ms;
    }
}

void semo_firing_continues(void)
{
    g_continues = true;
}

/* When a running time-driven task that is not in a firing fires next: its
 * period, or its hint unless it was woken, on the period's grid from its
 * first firing, the loop's first pass, as every time-driven task runs from
 * the start (a task woken between two grid points fires at the next,a task woken between two grid points fires at the next,
 * as the simulator's control task fires every period from its start, and
 * only then; as on POSIX). */
static int64_t time_due(const task *t, int64_t period_ms, int64_t now)
{
    int64_t due = t->next_release;
    if (t->hinted && !t->woken && t->hint_ms > due)
        due = t->hint_ms;
    due = semo__on_grid(due, g_first_pass_ms, period_ms);
    if (t->woken && due < now)
        due = semo__on_grid(now, g_first_pass_ms, period_ms);
    return due;
}

/* Fires task `i` if it is due; the rules of the POSIX threads, one step at a time. */
static void fire_if_due(size_t i)
{
    task *t = &g_tasks[i];
    const semo_task_desc *d = &g_prog->tasks[i];
    if (t->control.stop_requested && t->control.state != SEMO_TASK_IDLE && !t->in_firing) {
        t->control.state = SEMO_TASK_IDLE;
        t->control.stop_requested = false;
        t->control.calls = 0;
        wake_task(t->controller);
        return;
    }
    if (t->control.state != SEMO_TASK_RUNNING && !t->in_firing)
        return;
    int64_t now = semo_now_ms();
    bool hint_holds = t->hinted && !t->woken;
    if (t->in_firing && hint_holds && now < t->hint_ms)
        return;
    if (d->trigger == SEMO_TRIGGER_TIME && !t->in_firing) {
        if (now < time_due(t, d->period_ms, now))
            return;
        t->next_release = semo__on_grid(now + 1, g_first_pass_ms, d->period_ms);
    }
    t->hinted = t->woken = false;
    g_continues = false;
    g_current = t;
    if (d->go)
        d->go();
    g_current = NULL;
    t->in_firing = g_continues && g_running;
    if (t->in_firing)
        return;
    if (t->control.stop_requested) {
        t->control.state = SEMO_TASK_IDLE;
        t->control.stop_requested = false;
        t->control.calls = 0;
        wake_task(t->controller);
    } else if (!t->control.repeat && t->control.calls > 0 && --t->control.calls == 0) {
        t->control.state = SEMO_TASK_IDLE;
        wake_task(t->controller);
    }
}

/* Task control hooks (the switch is the core's, semo__control): nothing
 * else runs meanwhile, so no lock. */
semo__task_control *semo__control_begin(const char *name)
{
    task *t = find_task(name);
    return t ? &t->control : NULL;
}

void semo__control_end(semo__task_control *control)
{
    task *t = (task *)((char *)control - offsetof(task, control));
    if (g_current && g_current != t)
        t->controller = g_current;
    t->woken = true; /* its own hint is void: it was told what to do */
}

semo_task_state UFControl_GetTaskState(const char *name)
{
    task *t = find_task(name);
    if (!t)
        return SEMO_TASK_IDLE;
    /* A firing still going on keeps the task busy. */
    return t->in_firing && t->control.state == SEMO_TASK_IDLE ? SEMO_TASK_RUNNING : t->control.state;
}

/* Nothing else runs while this waits: only an idle task (or no time) succeeds. */
bool UFControl_WaitIdle(const char *name, int64_t timeout_ms)
{
    (void)timeout_ms;
    return UFControl_GetTaskState(name) == SEMO_TASK_IDLE;
}

/* Nothing else would run while this waited: it only answers. */
bool UFControl_WaitStop(const char *name, int64_t until_ms)
{
    (void)until_ms;
    return UFControl_StopRequested(name);
}

bool UFControl_StopRequested(const char *name)
{
    task *t = find_task(name);
    if (!g_running)
        return true;
    return t && t->control.stop_requested;
}

static struct {
    const char *task, *name; /* names from the program's code: never freed */
    long long value;
} g_params[SEMO_MAX_PARAMS];

int UFTask_SetIntegerParameter(const char *name, const char *param_name, long long value)
{
    if (!find_task(name) || !param_name)
        return -1;
    for (size_t i = 0; i < SEMO_MAX_PARAMS; i++) {
        bool same = g_params[i].task && strcmp(g_params[i].task, name) == 0 &&
                    strcmp(g_params[i].name, param_name) == 0;
        if (same || !g_params[i].task) {
            g_params[i].task = g_prog->tasks[find_task(name) - g_tasks].name;
            g_params[i].name = param_name;
            g_params[i].value = value;
            return 0;
        }
    }
    return -1;
}

long long UFTask_GetIntegerParameter(const char *name, const char *param_name)
{
    for (size_t i = 0; name && param_name && i < SEMO_MAX_PARAMS && g_params[i].task; i++)
        if (strcmp(g_params[i].task, name) == 0 && strcmp(g_params[i].name, param_name) == 0)
            return g_params[i].value;
    return 0;
}

/* ----------------------------------------------------------------- timers */

static struct {
    int64_t due_ms;
    bool used;
} g_timers[SEMO_MAX_TIMERS];

int UFTimer_Set(int64_t period, semo_time_unit unit)
{
    static const int64_t unit_ms[] = {[SEMO_MSEC] = 1, [SEMO_SEC] = 1000, [SEMO_MIN] = 60000, [SEMO_HOUR] = 3600000};
    /* An enum may be unsigned here (AAPCS): one unsigned comparison covers both ends. */
    if (period < 0 || (unsigned)unit > (unsigned)SEMO_HOUR || period > INT64_MAX / 2 / unit_ms[unit])
        return -1;
    for (int i = 0; i < SEMO_MAX_TIMERS; i++)
        if (!g_timers[i].used) {
            g_timers[i].due_ms = semo_now_ms() + period * unit_ms[unit];
            g_timers[i].used = true;
            return i;
        }
    return -1;
}

bool UFTimer_GetAlarmed(int id)
{
    return id >= 0 && id < SEMO_MAX_TIMERS && g_timers[id].used && semo_now_ms() >= g_timers[id].due_ms;
}

void UFTimer_Cancel(int id)
{
    if (id >= 0 && id < SEMO_MAX_TIMERS)
        g_timers[id].used = false;
}

/* --------------------------------------------------------------- messages */

/* Without the link (-DSEMO_LINK, semo_static_link.c) only the operator
 * console ("USER", whose record is the trace) is reachable: the generator
 * builds every robot that messages other robots with the link, so anything
 * else is an error. The inbox
 * (semo_comm_poll, semo__deliver) is the core's. */
#ifndef SEMO_LINK
int semo_comm_send(const char *to_team, semo_msg_kind kind, const char *key, const semo_value *value)
{
    int local = semo__comm_send_local(to_team, kind, key, value);
    if (local != 0)
        return local;
    semo_trace("comm_error", "to", to_team, "key", key, NULL);
    return -1;
}
#endif

/* ------------------------------------------------------------- simulation */

#ifdef SEMO_SIM
#define DEFAULT_SERVICE_MS 100

void semo_sim_actuate(const char *task, const semo_value *command)
{
    semo_trace_value("actuate", "value", command ? command : SEMO_LIT(""), "task", task, NULL);
}

int64_t semo_sim_service_ms(const char *service)
{
    for (size_t i = 0; service && i < semo__scenario.service_count; i++)
        if (strcmp(semo__scenario.services[i].service, service) == 0)
            return semo__scenario.services[i].ms;
    return DEFAULT_SERVICE_MS;
}

int semo_sim_results(const char *service, semo_value *values, int max)
{
    return semo__sim_results(service, values, max);
}

/* Delivers the operator's commands that are due, in time order. */
static void deliver_operator_commands(void)
{
    int64_t now = semo_now_ms();
    for (;;) {
        size_t due = semo__scenario.operator_count;
        for (size_t i = 0; i < semo__scenario.operator_count; i++) {
            int64_t next = semo__scenario.operator_next[i];
            if (next >= 0 && next <= now && (due == semo__scenario.operator_count || next < semo__scenario.operator_next[due]))
                due = i;
        }
        if (due == semo__scenario.operator_count)
            return;
        const semo__sim_command_entry *c = &semo__scenario.operator_commands[due];
        semo_message m = {.kind = SEMO_MSG_SEND, .from_team = "USER", .from_robot = "USER"};
        strncpy(m.key, c->key, sizeof m.key - 1);
        semo_value_set(&m.value, c->is);
        semo__deliver(&m);
        int64_t *next = &semo__scenario.operator_next[due];
        *next = c->every > 0 && (c->until < 0 || *next + c->every <= c->until) ? *next + c->every : -1;
    }
}

/* When the next operator command is due (INT64_MAX: none). */
static int64_t next_operator_command(void)
{
    int64_t next = INT64_MAX;
    for (size_t i = 0; i < semo__scenario.operator_count; i++)
        if (semo__scenario.operator_next[i] >= 0 && semo__scenario.operator_next[i] < next)
            next = semo__scenario.operator_next[i];
    return next;
}

static void start_operator(void)
{
    for (size_t i = 0; i < semo__scenario.operator_count; i++) {
        const semo__sim_command_entry *c = &semo__scenario.operator_commands[i];
        semo__scenario.operator_next[i] = c->until < 0 || c->first <= c->until ? c->first : -1;
    }
}
#endif

/* ---------------------------------------------------------------- the loop */

void Core_1_go(void)
{
    /* At one instant the calls whose service time ends come before the
     * control firing that sees them (docs/language/timing.md, "One instant,
     * step by step"): a continuing firing whose time has come goes first,
     * whatever its place in the schedule. */
    int64_t now = semo_now_ms();
    for (size_t s = 0; s < g_prog->schedule_count && g_running; s++) {
        const task *t = &g_tasks[g_prog->schedule[s].task];
        if (t->in_firing && t->hinted && !t->woken && t->hint_ms <= now)
            fire_if_due(g_prog->schedule[s].task);
    }
#ifdef SEMO_SIM
    deliver_operator_commands();
#endif
    for (size_t s = 0; s < g_prog->schedule_count && g_running; s++) {
        const semo_firing *f = &g_prog->schedule[s];
        for (unsigned n = 0; n < f->count && g_running; n++)
            fire_if_due(f->task);
    }
}

/* The program stopped: each firing under way is called once more, in the
 * schedule's order, to end (a call under way ends with the program:
 * `call_end`, then `stop`, as on POSIX and in the simulator). */
static void end_firings(void)
{
    for (size_t s = 0; s < g_prog->schedule_count; s++) {
        task *t = &g_tasks[g_prog->schedule[s].task];
        if (!t->in_firing)
            continue;
        g_continues = false;
        g_current = t;
        if (g_prog->tasks[g_prog->schedule[s].task].go)
            g_prog->tasks[g_prog->schedule[s].task].go();
        g_current = NULL;
        t->in_firing = false;
    }
}

/* Whether a sample waits in one of task `i`'s input channels. */
static bool input_waiting(size_t i)
{
    for (size_t c = 0; c < g_prog->channel_count; c++)
        if (g_prog->channels[c].state->count > 0 && g_prog->channels[c].state->reader == i)
            return true;
    return false;
}

/* The mission time at which the next pass has something to do: the
 * earliest time a task is due by the rules of fire_if_due. A data-driven
 * (or running control-driven) task is due only when a sample waits for it,
 * a call is owed or a message waits in the inbox: its body returns at once
 * otherwise, and what it waits for is written in a pass, which wakes it. */
static int64_t next_due(int64_t now)
{
    int64_t next = INT64_MAX;
    for (size_t i = 0; i < g_prog->task_count; i++) {
        const task *t = &g_tasks[i];
        bool hint_holds = t->hinted && !t->woken;
        int64_t due = INT64_MAX;
        if (t->in_firing) {
            /* A firing that goes on without naming when: as with a clock tick. */
            due = hint_holds ? t->hint_ms : t->hinted ? now : now + 1;
        } else if (t->control.stop_requested && t->control.state != SEMO_TASK_IDLE) {
            due = now;
        } else if (t->control.state != SEMO_TASK_RUNNING) {
            continue;
        } else if (g_prog->tasks[i].trigger == SEMO_TRIGGER_TIME) {
            due = time_due(t, g_prog->tasks[i].period_ms, now);
        } else if ((!t->control.repeat && t->control.calls > 0) || input_waiting(i) || semo__inbox_waiting()) {
            due = now;
        }
        if (due < next)
            next = due;
    }
    return next;
}

/* A program the static schedule can run: every table within its bounds. */
static bool program_fits(const semo_program_desc *p)
{
    if (p->task_count > SEMO_MAX_TASKS || p->group_count > SEMO_MAX_GROUPS)
        return false;
    for (size_t s = 0; s < p->schedule_count; s++)
        if (p->schedule[s].task >= p->task_count)
            return false;
    for (size_t i = 0; i < p->channel_count; i++) {
        const semo_channel_desc *c = &p->channels[i];
        if (!c->storage || !c->state || c->capacity == 0 || c->initial_samples > c->capacity)
            return false;
    }
    return true;
}

/* No command line on the board: `argc`/`argv` are ignored. The duration is
 * the scenario's in simulation, else the program runs until it stops itself. */
int semo_main(int argc, char **argv, const semo_program_desc *program)
{
    (void)argc;
    (void)argv;
    semo__board_init();
    if (!program || !program_fits(program)) {
        static const char message[] = "semo runtime: the program does not fit the static tables\n";
        semo__board_put(NULL, message, sizeof message - 1);
        semo__board_exit(1);
        return 1;
    }
    g_prog = program;
    for (size_t i = 0; i < program->channel_count; i++) {
        const semo_channel_desc *c = &program->channels[i];
        memset(c->storage, 0, c->capacity * c->sample_size);
        *c->state = (semo_channel_state){.count = c->initial_samples, .reader = SEMO_MAX_TASKS};
        for (size_t k = 0; k < program->task_count; k++)
            if (strcmp(c->dst_task, program->tasks[k].name) == 0)
                c->state->reader = (unsigned short)k;
    }
    for (size_t i = 0; i < program->task_count; i++)
        g_tasks[i] = (task){.control = {.state = program->tasks[i].trigger == SEMO_TRIGGER_CONTROL
                                                         ? SEMO_TASK_IDLE
                                                         : SEMO_TASK_RUNNING,
                                        .repeat = true}};
#ifdef SEMO_LINK
    /* Mission time starts once the robot has joined the fleet. */
    semo__link_open();
#endif
    semo__inbox_reset();
    g_start_ms = semo__board_now_ms();
    g_running = true;
    int64_t duration = 0;
#ifdef SEMO_SIM
    duration = semo__scenario.duration_ms;
    start_operator();
#endif
    semo_trace("start", "team", program->team, "type", program->robot_type ? program->robot_type : "", "mission",
               program->mission ? program->mission : "", NULL);
#ifdef SEMO_LOCKSTEP
    /* A fault at the instant the robot starts comes after its `start` and
     * before anything else it does, as in the simulator. */
    semo__lockstep_idle(semo_now_ms());
#endif
    for (size_t i = 0; i < program->task_count; i++)
        if (program->tasks[i].init)
            program->tasks[i].init();
    g_first_pass_ms = semo_now_ms();
    while (g_running) {
#ifdef SEMO_LINK
        semo__link_pump();
#endif
        /* At the scenario's duration the robot stops first: nothing of
         * that instant runs. */
        if (duration > 0 && semo_now_ms() >= duration)
            break;
        Core_1_go();
        g_passes++;
        int64_t now = semo_now_ms();
        /* A program that stopped itself (its mission finished) stops at
         * this instant, not at its next deadline. */
        if (!g_running || (duration > 0 && now >= duration))
            break;
        int64_t wake = next_due(now);
#ifdef SEMO_SIM
        int64_t command = next_operator_command();
        if (command < wake)
            wake = command;
#endif
        if (duration > 0 && duration < wake)
            wake = duration;
#ifdef SEMO_LINK
        int64_t link = semo__link_deadline();
        if (link != INT64_MAX && link - g_start_ms < wake)
            wake = link - g_start_ms;
#endif
        if (wake > now)
#ifdef SEMO_LOCKSTEP
            semo__lockstep_idle(wake);
#else
            semo__board_sleep_until(wake == INT64_MAX ? INT64_MAX : g_start_ms + wake);
#endif
    }
    g_running = false;
    end_firings();
    for (size_t i = 0; i < program->task_count; i++)
        if (program->tasks[i].wrapup)
            program->tasks[i].wrapup();
    semo__trace_dropped_samples();
#ifdef SEMO_LINK
    semo__link_report();
#endif
    semo_trace("stop", NULL);
#ifdef SEMO_LINK
    /* The status `stop` queued goes before the board exits. */
    semo__link_close();
#endif
#ifdef SEMO_COUNT_PASSES
    /* For measuring (not a trace line: built only with -DSEMO_COUNT_PASSES). */
    char passes[21], ms[21];
    semo__format_i64(passes, (int64_t)g_passes);
    semo__format_i64(ms, semo_now_ms());
    static const char *const parts[] = {"semo passes ", NULL, " ms ", NULL, "\n"};
    for (size_t p = 0; p < 5; p++) {
        const char *text = p == 1 ? passes : p == 3 ? ms : parts[p];
        semo__board_put(NULL, text, strlen(text));
    }
#endif
    semo__board_exit(0);
    return 0;
}
