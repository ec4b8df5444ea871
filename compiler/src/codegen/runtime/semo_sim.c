/* semo_sim.c: the simulated world of the threads platform (built only with
 * -DSEMO_SIM).
 *
 * The robot's world from the scenario is compiled into the program by
 * `semo build --scenario FILE` (the generated scenario.c: semo__scenario,
 * semo_internal.h); nothing here reads a file. Sensor tasks read the latest
 * value (BATTERY, when no entry names it, the battery level at that time);
 * operator commands are delivered into the message queue at their time by
 * one thread. Link faults (drop, delay, partition) act on the send path:
 * semo_comm_send asks semo__sim_link for each robot it sends to, and a
 * delayed datagram is sent by a second thread at its time (in lock-step it
 * goes to the coordinator at once, with its delay). Kill and restart
 * faults happen to the process from outside (a crash is not something a
 * program does to itself): they are not in the tables.
 *
 * The platform (semo_runtime.c) calls none of this by name: the program
 * gives it semo_sim_platform, the table of hooks at the end of this file.
 */
#define _POSIX_C_SOURCE 200809L

#include "semo_internal.h"

#ifdef SEMO_SIM

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DEFAULT_SERVICE_MS 100

/* ------------------------------------------------- the running scenario */

static pthread_t g_operator;
static bool g_operator_started;

/* The commands' `operator_next` is touched only by this thread (and set
 * before it starts). */
static void *operator_thread(void *arg)
{
    (void)arg;
    const semo__sim_tables *w = &semo__scenario;
    for (;;) {
        size_t due = w->operator_count;
        for (size_t i = 0; i < w->operator_count; i++)
            if (w->operator_next[i] >= 0 && (due == w->operator_count || w->operator_next[i] < w->operator_next[due]))
                due = i;
        if (due == w->operator_count || !semo__wait_until(w->operator_next[due]))
            return NULL;
        const semo__sim_command_entry *c = &w->operator_commands[due];
        semo_message m = {.kind = SEMO_MSG_SEND, .from_team = "USER", .from_robot = "USER"};
        snprintf(m.key, sizeof m.key, "%s", c->key);
        semo_value_set(&m.value, c->is);
        semo__deliver(&m);
        int64_t *next = &w->operator_next[due];
        *next = c->every > 0 && (c->until < 0 || *next + c->every <= c->until) ? *next + c->every : -1;
    }
}

static bool sim_link(size_t peer, int64_t *delay_ms)
{
    int64_t now = semo_now_ms();
    *delay_ms = 0;
    for (size_t i = 0; i < semo__scenario.link_count; i++) {
        const semo__sim_link_entry *f = &semo__scenario.links[i];
        if (now < f->from || now >= f->until)
            continue;
        bool touches = false;
        for (size_t k = 0; k < f->peer_count && !touches; k++)
            touches = f->peers[k] == peer;
        if (!touches)
            continue;
        if (f->lost)
            return false;
        *delay_ms += f->by;
    }
    return true;
}

/* Datagrams held back by a delay fault, sent by one thread at their time. */
typedef struct late_datagram {
    struct late_datagram *next;
    int64_t due;
    size_t peer, len;
    unsigned char data[];
} late_datagram;

static struct {
    pthread_mutex_t lock;
    pthread_cond_t changed;
    late_datagram *queue; /* unordered; a delay fault holds few at a time */
    const semo_transport *transport;
    bool stopping, started;
    pthread_t thread;
} g_late = {.lock = PTHREAD_MUTEX_INITIALIZER};

static bool has_delays(void)
{
    for (size_t i = 0; i < semo__scenario.link_count; i++)
        if (!semo__scenario.links[i].lost)
            return true;
    return false;
}

static void sim_send_later(const semo_transport *transport, size_t peer, const void *data, size_t len,
                           int64_t delay_ms)
{
    if (semo__ls_on()) {
        /* In lock-step the coordinator is the network: it holds the message
         * for the delay, taking it as sent now (its loss drawn in the order
         * of the sends, its receiver the process running now), as the
         * simulator does. Held here, it would reach the coordinator only
         * when due, after later messages, and die with a killed sender. */
        if (semo__ls_send_late(peer, data, len, delay_ms) != 0)
            semo_trace("comm_error", "to", semo_program()->peers[peer].robot, NULL);
        return;
    }
    late_datagram *d = malloc(sizeof *d + len);
    if (!d) {
        semo_trace("comm_error", "reason", "out of memory for a delayed message", NULL);
        return;
    }
    d->due = semo_now_ms() + delay_ms;
    d->peer = peer;
    d->len = len;
    memcpy(d->data, data, len);
    pthread_mutex_lock(&g_late.lock);
    g_late.transport = transport;
    d->next = g_late.queue;
    g_late.queue = d;
    semo__cond_signal(&g_late.changed);
    pthread_mutex_unlock(&g_late.lock);
}

static void *late_thread(void *arg)
{
    (void)arg;
    pthread_mutex_lock(&g_late.lock);
    while (!g_late.stopping) {
        /* The earliest due; of equals the one sent first (the queue is
         * newest first), so that delayed messages keep their order. */
        late_datagram **first = NULL;
        for (late_datagram **d = &g_late.queue; *d; d = &(*d)->next)
            if (!first || (*d)->due <= (*first)->due)
                first = d;
        if (!first) {
            semo__cond_wait_until(&g_late.changed, &g_late.lock, -1);
            continue;
        }
        if (semo_now_ms() < (*first)->due) {
            semo__cond_wait_until(&g_late.changed, &g_late.lock, (*first)->due);
            continue;
        }
        late_datagram *due = *first;
        *first = due->next;
        const semo_transport *transport = g_late.transport;
        pthread_mutex_unlock(&g_late.lock);
        if (transport->send(due->peer, due->data, due->len) != 0)
            semo_trace("comm_error", "to", semo_program()->peers[due->peer].robot, NULL);
        free(due);
        pthread_mutex_lock(&g_late.lock);
    }
    while (g_late.queue) { /* not due before the program stopped */
        late_datagram *d = g_late.queue;
        g_late.queue = d->next;
        free(d);
    }
    pthread_mutex_unlock(&g_late.lock);
    return NULL;
}

static int sim_start(void)
{
    if (has_delays()) {
        semo__cond_init(&g_late.changed);
        g_late.stopping = false;
        if (!semo__start_thread(&g_late.thread, late_thread, NULL)) {
            fprintf(stderr, "semo runtime: cannot start the simulated network\n");
            pthread_cond_destroy(&g_late.changed);
            return -1;
        }
        g_late.started = true;
    }
    const semo__sim_tables *w = &semo__scenario;
    if (w->operator_count == 0)
        return 0;
    for (size_t i = 0; i < w->operator_count; i++) {
        const semo__sim_command_entry *c = &w->operator_commands[i];
        w->operator_next[i] = c->until < 0 || c->first <= c->until ? c->first : -1;
    }
    if (!semo__start_thread(&g_operator, operator_thread, NULL)) {
        fprintf(stderr, "semo runtime: cannot start the simulated operator\n");
        return -1;
    }
    g_operator_started = true;
    return 0;
}

static void sim_stop(void)
{
    if (g_operator_started)
        pthread_join(g_operator, NULL);
    g_operator_started = false;
    if (g_late.started) {
        pthread_mutex_lock(&g_late.lock);
        g_late.stopping = true;
        semo__cond_signal(&g_late.changed);
        pthread_mutex_unlock(&g_late.lock);
        pthread_join(g_late.thread, NULL);
        pthread_cond_destroy(&g_late.changed);
    }
    g_late.started = false;
}

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

int64_t semo_sim_loop_exit(const char *loop)
{
    for (size_t i = 0; loop && i < semo__scenario.loop_count; i++)
        if (strcmp(semo__scenario.loops[i].path, loop) == 0)
            return semo__scenario.loops[i].iteration;
    return 0;
}

const semo_sim_hooks semo_sim_platform = {
    .world = &semo__scenario,
    .link = sim_link,
    .send_later = sim_send_later,
    .battery = semo_sim_battery,
    .start = sim_start,
    .stop = sim_stop,
};

#else
/* ISO C wants at least one declaration in a translation unit. */
typedef int semo_sim_disabled;
#endif /* SEMO_SIM */
