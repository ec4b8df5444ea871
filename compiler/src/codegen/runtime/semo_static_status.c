/* semo_static_status.c: a board robot's status for operators (built with
 * -DSEMO_LINK: a board robot that messages other robots; docs/link.md).
 *
 * What a Linux robot publishes (semo_runtime.c's observe_status), kept the
 * same way from the same trace events (start, mode, service_start and
 * service_end, leader and fenced, finish, stop; a new battery level with
 * the next event) and written as the same JSON object, sent as a `T` frame
 * on the link each time it changes; the gateway publishes it retained on
 * <scope>/status/<robot>, where the operator console and the live monitor
 * read it as a Linux robot's:
 *   {"t":..,"robot":..,"event":"status","state":..,"started":"0","mode":..,
 *    "leader":..,"services":"Plan=Service,...","groups":"Room1=4,...",
 *    "battery":".."}
 * `groups` as a Linux robot's: only when it passed a statement of counted
 * groups since its mode started, its group at each (by statement number,
 * told by the control task through semo_status_group) with the members it
 * counted alive when it took it; the Makefile's SEMO_STATUS_GROUPS is how
 * many such statements the robot has (none: no table at all).
 * `started` is 0: a board has no wall clock, and its mission time 0 is the
 * gateway's welcome (semo_static_link.c), whose wall-clock time the gateway
 * puts in its place. `battery` only when the robot
 * knows its level (its BATTERY value, in simulation the scenario's).
 *
 * No heap, no copies: the names come from the generated control task's
 * constant tables (mode_name, service_name, the regions' plans, the peer
 * table), so the status keeps pointers to them. No buffer of its own
 * either: the JSON is written straight into the link queue's next slot,
 * which the Makefile sizes from the mission to hold the longest status
 * (SEMO_LINK_SEND_MAX, board_link.rs), escaped as the trace escapes
 * (semo__json_chars).
 *
 * Each change is queued in order, waiting for a slot as a send does, so
 * every mode and state the robot enters is published; but a status that
 * says the same mode and state as the last one queued, while that one has
 * not left yet, takes its place: a mode change (each plan's service ending,
 * the mode, each plan's service starting: a status each) then costs the
 * robot no wait for the line, and the operator sees the new mode with what
 * it runs. A change that finds the queue full while the line is being fed
 * (traced as a frame is taken), or once the program stops (the gateway
 * gone), goes with the next event instead, if any. Nothing goes before the
 * robot's `start`.
 */
/* In lock-step (-DSEMO_LOCKSTEP) the robot has no operators. */
#if defined(SEMO_LINK) && !defined(SEMO_LOCKSTEP)
#include "semo_internal.h"
#include "semo_link.h"

#include <string.h>

/* The plans the robot runs (the Makefile's, from the mission). */
#ifndef SEMO_STATUS_PLANS
#define SEMO_STATUS_PLANS 8
#endif
_Static_assert(SEMO_STATUS_PLANS >= 1 && SEMO_STATUS_PLANS <= 0xFFFF, "SEMO_STATUS_PLANS must be 1 to 65535");
/* The statements of counted groups the robot has (the Makefile's). */
#ifndef SEMO_STATUS_GROUPS
#define SEMO_STATUS_GROUPS 0
#endif
_Static_assert(SEMO_STATUS_GROUPS >= 0 && SEMO_STATUS_GROUPS <= 0xFFFF, "SEMO_STATUS_GROUPS must be 0 to 65535");

/* A name not known yet is NULL, written "" (semo__json_chars). */
static struct {
    const char *state, *mode, *leader;
    /* The mode and state the last status queued said. */
    const char *queued_mode, *queued_state;
    struct {
        const char *plan, *service;
    } running[SEMO_STATUS_PLANS];
#if SEMO_STATUS_GROUPS > 0
    /* By statement number, in order; the group's name is the control
     * task's constant (a group's name, or "others"). */
    struct {
        const char *group;
        unsigned short statement, alive;
    } groups[SEMO_STATUS_GROUPS];
    unsigned short group_count;
#endif
    /* The battery level the last status said. */
    long long battery;
    unsigned short running_count;
    bool battery_known;
    /* Changed since the last status queued; a status being queued. */
    bool pending, busy;
} g_status;

/* The slot being written (measured first: it holds the status). */
typedef struct {
    unsigned char *out;
    size_t len;
} slot_sink;

static void put_slot(void *ctx, const char *bytes, size_t n)
{
    slot_sink *s = ctx;
    memcpy(s->out + s->len, bytes, n);
    s->len += n;
}

static void count(void *ctx, const char *bytes, size_t n)
{
    (void)bytes;
    *(size_t *)ctx += n;
}

static void put(const semo__sink *sink, const char *text)
{
    sink->put(sink->ctx, text, strlen(text));
}

/* `,"key":"value"`, the value escaped. */
static void field(const semo__sink *sink, const char *key, const char *value)
{
    put(sink, ",\"");
    put(sink, key);
    put(sink, "\":\"");
    semo__json_chars(sink, value);
    put(sink, "\"");
}

/* The status JSON at mission time `t`, as semo__trace_line writes a Linux
 * robot's. */
static void write_status(const semo__sink *sink, int64_t t)
{
    char number[21];
    put(sink, "{\"t\":");
    semo__format_i64(number, t);
    put(sink, number);
    field(sink, "robot", semo_program()->robot);
    field(sink, "event", "status");
    field(sink, "state", g_status.state);
    field(sink, "started", "0");
    field(sink, "mode", g_status.mode);
    field(sink, "leader", g_status.leader);
    put(sink, ",\"services\":\"");
    bool first = true;
    for (size_t i = 0; i < g_status.running_count; i++) {
        if (!g_status.running[i].service[0])
            continue;
        put(sink, first ? "" : ",");
        semo__json_chars(sink, g_status.running[i].plan);
        put(sink, "=");
        semo__json_chars(sink, g_status.running[i].service);
        first = false;
    }
    put(sink, "\"");
#if SEMO_STATUS_GROUPS > 0
    if (g_status.group_count > 0) {
        put(sink, ",\"groups\":\"");
        for (size_t i = 0; i < g_status.group_count; i++) {
            put(sink, i ? "," : "");
            semo__json_chars(sink, g_status.groups[i].group);
            put(sink, "=");
            semo__format_i64(number, g_status.groups[i].alive);
            put(sink, number);
        }
        put(sink, "\"");
    }
#endif
    if (g_status.battery_known) {
        semo__format_i64(number, g_status.battery);
        field(sink, "battery", number);
    }
    put(sink, "}");
}

/* The service plan `plan` runs now: "" when it ended. */
static void plan_runs(const char *plan, const char *service, bool starts)
{
    size_t i = 0;
    while (i < g_status.running_count && strcmp(g_status.running[i].plan, plan) != 0)
        i++;
    if (starts && i == g_status.running_count && i < SEMO_STATUS_PLANS)
        g_status.running[g_status.running_count++].plan = plan;
    if (i < g_status.running_count)
        g_status.running[i].service = starts && service ? service : "";
}

static void queue_status(void);

void semo__status_observe(const char *event, va_list args)
{
    bool changed = true;
    if (strcmp(event, "start") == 0) {
        g_status.state = "running";
    } else if (strcmp(event, "finish") == 0) {
        g_status.state = "finished";
    } else if (strcmp(event, "stop") == 0) {
        g_status.state = "stopped";
    } else if (strcmp(event, "mode") == 0) {
        g_status.mode = semo__trace_pair(args, "mode");
#if SEMO_STATUS_GROUPS > 0
        /* The new mode's statements tell their groups as they are passed. */
        g_status.group_count = 0;
#endif
    } else if (strcmp(event, "leader") == 0) {
        g_status.leader = semo__trace_pair(args, "leader");
    } else if (strcmp(event, "fenced") == 0) {
        g_status.leader = NULL; /* it knows no leader until it hears a majority */
    } else if (strcmp(event, "service_start") == 0 || strcmp(event, "service_end") == 0) {
        const char *plan = semo__trace_pair(args, "plan");
        if (plan)
            plan_runs(plan, semo__trace_pair(args, "service"), strcmp(event, "service_start") == 0);
    } else {
        changed = false;
    }
    g_status.pending = g_status.pending || changed;
    queue_status();
}

#if SEMO_STATUS_GROUPS > 0
void semo_status_group(unsigned statement, const char *group, size_t alive)
{
    unsigned short n = g_status.group_count;
    unsigned short i = 0;
    while (i < n && g_status.groups[i].statement < statement)
        i++;
    bool found = i < n && g_status.groups[i].statement == statement;
    unsigned short counted = alive > 0xFFFF ? 0xFFFF : (unsigned short)alive;
    if (!group && found) {
        memmove(&g_status.groups[i], &g_status.groups[i + 1], (size_t)(n - i - 1) * sizeof g_status.groups[0]);
        g_status.group_count--;
    } else if (group && found && strcmp(g_status.groups[i].group, group) != 0) {
        g_status.groups[i].group = group;
        g_status.groups[i].alive = counted;
    } else if (group && !found && n < SEMO_STATUS_GROUPS) {
        memmove(&g_status.groups[i + 1], &g_status.groups[i], (size_t)(n - i) * sizeof g_status.groups[0]);
        g_status.group_count++;
        g_status.groups[i].statement = (unsigned short)statement;
        g_status.groups[i].group = group;
        g_status.groups[i].alive = counted;
    } else {
        return;
    }
    g_status.pending = true;
    queue_status();
}
#else
/* No statement of counted groups: nothing to tell. */
void semo_status_group(unsigned statement, const char *group, size_t alive)
{
    (void)statement;
    (void)group;
    (void)alive;
}
#endif

/* Queues the status when it changed since the last one queued (or the
 * battery level did). */
static void queue_status(void)
{
    /* The battery: what the control task last read of its BATTERY value; in
     * simulation without one, the scenario's level. */
    long long level = 0;
    bool known = semo__battery(&level);
#ifdef SEMO_SIM
    if (!known)
        known = semo_sim_battery(&level);
#endif
    if (known != g_status.battery_known || (known && level != g_status.battery))
        g_status.pending = true;
    /* Nothing before its start (a refusal traced while it joins). Busy: a
     * trace made while this waits for a slot; the status queued then says
     * what it changed. */
    if (!g_status.state || !g_status.pending || g_status.busy)
        return;
    g_status.busy = true;
    /* The names are the tables' own: the same mode is the same pointer. */
    bool same = g_status.mode == g_status.queued_mode && g_status.state == g_status.queued_state;
    unsigned char *waiting = same ? semo__link_waiting(SEMO_LINK_STATUS) : NULL;
    unsigned char *slot = waiting ? waiting : semo__link_slot(false);
    if (slot) {
        g_status.battery_known = known;
        g_status.battery = level;
        int64_t t = semo_now_ms();
        size_t len = 0;
        semo__sink measure = {count, &len};
        write_status(&measure, t);
        /* Never longer than a slot (the Makefile sizes it from the
         * mission's names); were it, it would be dropped, not sent cut. */
        if (len <= SEMO_LINK_SEND_MAX) {
            slot_sink out = {slot, 0};
            semo__sink sink = {put_slot, &out};
            write_status(&sink, t);
            if (waiting)
                semo__link_rewrite(out.len);
            else
                semo__link_commit(SEMO_LINK_STATUS, out.len);
            g_status.queued_mode = g_status.mode;
            g_status.queued_state = g_status.state;
        }
        g_status.pending = false;
    }
    g_status.busy = false;
}
#else
/* Not a robot that messages others: nothing here (ISO C wants a declaration). */
typedef int semo__static_status_unused;
#endif
