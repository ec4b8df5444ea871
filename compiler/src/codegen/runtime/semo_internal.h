/* semo_internal.h: what the runtime's own files share (not for task code).
 *
 * semo_core.c is the portable core (values, trace lines, numbers); a
 * platform layer owns the clock, the run state, channels, tasks and the
 * message queue: semo_runtime.c (POSIX threads) or semo_static.c (one loop,
 * with a board file such as semo_lm3s6965.c). In simulation (-DSEMO_SIM) the
 * robot's world from the scenario is compiled in (the generated scenario.c,
 * semo__scenario below): semo_sim.c reads it for the threads platform
 * (sensors, battery, services, link faults, and a thread that feeds the
 * operator's commands into the queue), semo_static.c for the static one.
 * The threads platform reaches semo_sim.c only through the hooks the
 * program gives it (semo_program_desc::sim, semo_sim_hooks below).
 */
#ifndef SEMO_INTERNAL_H
#define SEMO_INTERNAL_H

#include "semo_runtime.h"

#include <stdarg.h>

/* Where the bytes of a trace line go (a file, a UART). */
typedef struct {
    void (*put)(void *ctx, const char *bytes, size_t n);
    void *ctx;
} semo__sink;

/* Writes one trace line (see semo_trace) to `sink`; `value_key` (NULL:
 * none) names a typed value written last (semo_trace_value). */
void semo__trace_line(const semo__sink *sink, int64_t t, const char *robot, const char *event, va_list args,
                      const char *value_key, const semo_value *value);
/* A JSON string's characters, escaped as a trace line's, without quotes. */
void semo__json_chars(const semo__sink *sink, const char *text);
/* The value of `key` among a trace call's pairs (semo_trace's), or NULL. */
const char *semo__trace_pair(va_list args, const char *key);
/* Platform: writes one trace line where the platform's trace goes
 * (semo_trace and semo_trace_value are the core's). */
void semo__trace_emit(const char *event, const char *value_key, const semo_value *value, va_list args);
/* `n` in decimal into `out` (at least 21 bytes); returns its length. No
 * printf: newlib-nano's has no `%lld`. */
size_t semo__format_i64(char *out, int64_t n);
/* The battery level the control task last reported (semo_battery_report),
 * rounded; false before the first report. */
bool semo__battery(long long *level);

/* Waits until mission time `deadline_ms`; false when the program stopped first. */
bool semo__wait_until(int64_t deadline_ms);

/* Channels and the inbox of messages are the core's (semo_core.c): one ring
 * code for every platform. A queue is a channel (its port id) or the inbox
 * (SEMO__INBOX); the platform gives each channel's storage and the hooks. */
#define SEMO__INBOX (-1)
/* Messages received and not yet taken (`drop` beyond). */
#ifndef SEMO_INBOX
#ifdef SEMO_STATIC
#define SEMO_INBOX 8
#else
#define SEMO_INBOX 64
#endif
#endif
typedef struct {
    unsigned char *storage; /* capacity * sample_size bytes */
    semo_channel_state *state;
    size_t capacity, sample_size;
} semo__ring;
/* Platform: channel `port`'s ring; false for a bad id. */
bool semo__channel_ring(int port, semo__ring *out);
/* Platform: the queue's lock (none on the static schedule). */
void semo__queue_lock(int queue);
void semo__queue_unlock(int queue);
/* Platform, with the lock held: waits until the queue is written, mission
 * time `deadline_ms` (< 0: none) or the program stops (the caller looks
 * again); false when the platform cannot wait (the static schedule, where
 * nothing else runs meanwhile). */
bool semo__queue_wait(int queue, int64_t deadline_ms);
/* Platform, after the lock is released: something was added to the queue;
 * wakes its reader (and tasks sleeping on a semo_next_firing hint). */
void semo__queue_written(int queue);
/* Platform: the task running polls the inbox (semo_comm_poll): the static
 * schedule in lock-step fires it when a delivery finds the inbox full. */
void semo__inbox_polled(void);
/* A writer waiting for room in a full message channel (semo_port_send:
 * `patient`; semo_port_offer: not). `marked`/`mark` are the platform's,
 * zero at the first call. */
typedef struct {
    bool patient;
    bool marked;
    unsigned long mark;
} semo__room_wait;
/* Platform, with the lock held, the channel full: waits until something is
 * taken from it, the program stops, or (not patient) the reader ends a
 * firing begun since the first call (the caller looks again); false when
 * the writer must give up: such a firing has ended, or the platform cannot
 * make room. */
bool semo__queue_wait_room(int port, semo__room_wait *room);
/* Platform, after the lock is released: something was taken from the
 * channel; wakes a writer waiting for room. */
void semo__queue_taken(int port);

/* The datagram of a message (the one wire format of every transport): "SEMO"
 * 0x02 <kind>, then from_team, from_robot and key, each a length byte and
 * that many bytes (no NUL), then the value: its type byte and, by type,
 * nothing (none), 8 bytes big-endian (int64; a real's IEEE 754 bits), one
 * byte (bool), or a length byte and the text (word, text). Nothing after. */
#define SEMO__DATAGRAM_MAGIC "SEMO\x02"
#define SEMO__DATAGRAM_MAX (6 + 3 * 256 + 1 + 256)

#ifndef SEMO_STATIC
#include <pthread.h>
#include <string.h>
#include <time.h>

/* What a network transport's thread received and its `recv` has not taken
 * yet (semo_mqtt.c, semo_link_transport.c): the datagrams in order, and the
 * refused messages still to report (SEMO_RECV_REFUSED), under the
 * transport's own lock. One code for both: header-only, so that a program
 * built with one transport alone (the MQTT benchmarks) needs nothing else. */
#define SEMO__RECEIVED_MAX 64
typedef struct {
    struct {
        size_t len;
        unsigned char data[SEMO__DATAGRAM_MAX + 1];
    } slots[SEMO__RECEIVED_MAX];
    size_t head, count;
    unsigned long refused;
    unsigned long too_long; /* SEMO_RECV_TOO_LONG: the link's gateway refused them */
} semo__received;

/* `ms` wall milliseconds from now on CLOCK_MONOTONIC (the clock the
 * transports' conditions wait on). */
static inline struct timespec semo__deadline_after(int ms)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    t.tv_sec += ms / 1000;
    t.tv_nsec += (long)(ms % 1000) * 1000000L;
    if (t.tv_nsec >= 1000000000L) {
        t.tv_sec++;
        t.tv_nsec -= 1000000000L;
    }
    return t;
}

static inline bool semo__received_full(const semo__received *r)
{
    return r->count == SEMO__RECEIVED_MAX;
}

/* Under the lock, with room made first (the network thread waits while
 * full rather than lose a message): keeps `len` bytes of `data` (at most a
 * slot's). */
static inline void semo__received_put(semo__received *r, const void *data, size_t len)
{
    if (semo__received_full(r))
        return;
    size_t at = (r->head + r->count) % SEMO__RECEIVED_MAX;
    r->slots[at].len = len < sizeof r->slots[at].data ? len : sizeof r->slots[at].data;
    memcpy(r->slots[at].data, data, r->slots[at].len);
    r->count++;
}

/* A transport's `recv`: waits on `changed` under `lock` until a datagram or
 * a refusal is there, `*interrupted`, or `timeout_ms` (< 0: no limit); then
 * copies the next datagram into `data` (at most `cap` bytes) and returns
 * its length, or SEMO_RECV_REFUSED or SEMO_RECV_TOO_LONG, or 0. A take is broadcast: the network
 * thread may wait for room. */
static inline int semo__received_take(semo__received *r, pthread_mutex_t *lock, pthread_cond_t *changed,
                                      const bool *interrupted, void *data, size_t cap, int timeout_ms)
{
    struct timespec deadline = semo__deadline_after(timeout_ms < 0 ? 0 : timeout_ms);
    pthread_mutex_lock(lock);
    int waited = 0;
    while (r->count == 0 && r->refused == 0 && r->too_long == 0 && !*interrupted && waited == 0) {
        if (timeout_ms < 0)
            pthread_cond_wait(changed, lock);
        else
            waited = pthread_cond_timedwait(changed, lock, &deadline);
    }
    int n = 0;
    if (r->refused > 0 && !*interrupted) {
        r->refused--;
        n = SEMO_RECV_REFUSED;
    } else if (r->too_long > 0 && !*interrupted) {
        r->too_long--;
        n = SEMO_RECV_TOO_LONG;
    } else if (r->count > 0 && !*interrupted) {
        n = (int)(r->slots[r->head].len < cap ? r->slots[r->head].len : cap);
        memcpy(data, r->slots[r->head].data, (size_t)n);
        r->head = (r->head + 1) % SEMO__RECEIVED_MAX;
        r->count--;
        pthread_cond_broadcast(changed);
    }
    pthread_mutex_unlock(lock);
    return n;
}
#endif
size_t semo__encode_message(const semo_message *m, unsigned char *out);
/* How many bytes semo__encode_message writes for `m`. */
size_t semo__encoded_size(const semo_message *m);
/* False for anything else (the message is then unspecified). */
bool semo__decode_message(const unsigned char *in, size_t len, semo_message *m);

/* Task control (UFControl_RunTask, CallTask, StopTask, SuspendTask,
 * ResumeTask) is the core's: one switch over the part of a task's record it
 * changes, which every platform's task record holds. */
typedef struct {
    semo_task_state state;
    bool repeat;    /* RunTask; otherwise `calls` firings are owed */
    unsigned calls;
    bool stop_requested;
} semo__task_control;
/* Platform: task `name`'s control record with whatever guards it held
 * (POSIX: the task's lock); NULL for an unknown task. */
semo__task_control *semo__control_begin(const char *name);
/* Platform: after the core changed the record: the task that controls it
 * noted, the task woken (its own semo_next_firing hint is void), the guard
 * released. */
void semo__control_end(semo__task_control *control);

/* The first instant at or after `at` of the grid of `period_ms` that
 * starts at `first` (INT64_MAX stays: no time; `first` < 0: no grid yet):
 * the instants a time-driven task fires at, on either platform. */
int64_t semo__on_grid(int64_t at, int64_t first, int64_t period_ms);
/* Queues a message as if it had arrived over the transport. */
void semo__deliver(const semo_message *msg);
/* Empties the inbox (start-up, shut-down). */
void semo__inbox_reset(void);
/* Whether a message waits for a task that polls the inbox. */
bool semo__inbox_waiting(void);
/* Whether the inbox is full while a task reads it: a transport that can
 * keep a message where it is (on the line, at the gateway) holds it back
 * rather than have semo__deliver drop it on the static schedule. */
bool semo__inbox_holds_back(void);
/* Whether the inbox is full and no task has polled it yet: a delivery then
 * waits at most SEMO__INBOX_UNPOLLED_WAIT_MS (mission ms) for room before
 * the message is dropped (a robot that receives nothing must not hold back
 * its transport for ever). */
bool semo__inbox_unpolled_full(void);
#define SEMO__INBOX_UNPOLLED_WAIT_MS 1000
/* What every send does before the transport: checks the arguments and
 * traces the send; -1 on bad arguments, 1 when it went to the operator
 * console ("USER", whose record is the trace), 0 when the transport must
 * carry it. */
int semo__comm_send_local(const char *to_team, semo_msg_kind kind, const char *key, const semo_value *value);
/* Traces `dropped` for every channel that dropped samples. */
void semo__trace_dropped_samples(void);

/* The time scales accepted (wall ms per mission ms), from the command line or
 * a scenario: a million times faster to a million times slower. Beyond them
 * mission times no longer fit the clock's arithmetic (1e-18 would overflow
 * the conversion to int64_t), and no simulation needs them. */
#define SEMO_TIME_SCALE_MIN 1e-6
#define SEMO_TIME_SCALE_MAX 1e6

#if defined(SEMO_SIM) && !defined(SEMO_STATIC)
#include <pthread.h>

/* A condition variable on the runtime's clock, a wait on it until woken
 * or mission time `deadline_ms` (< 0: no limit), and its signal. */
void semo__cond_init(pthread_cond_t *cond);
void semo__cond_wait_until(pthread_cond_t *cond, pthread_mutex_t *lock, int64_t deadline_ms);
void semo__cond_signal(pthread_cond_t *cond);
/* Starts a thread of the program (in lock-step, one that takes turns). */
bool semo__start_thread(pthread_t *thread, void *(*body)(void *), void *arg);

/* Lock-step virtual time (semo_lockstep.c, `--lockstep SOCKET`): mission
 * time is granted by a coordinator, and the program's threads take turns.
 * Every wait of the runtime is semo__ls_wait on some key (a condition's
 * address), every signal semo__ls_wake on it. */
bool semo__ls_on(void);
/* Whether the threads take turns (from the connection until the coordinator
 * goes; the clock stays virtual after). */
bool semo__ls_turns(void);
int64_t semo__ls_now(void);
/* Connects as peer `self`, takes the starting time, and starts the link
 * thread; the calling (main) thread holds the first turn. */
int semo__ls_connect(const char *path, size_t self);
/* Called with `lock` held, returns with it held. */
void semo__ls_wait(const void *key, pthread_mutex_t *lock, int64_t deadline_ms);
void semo__ls_wake(const void *key, bool all);
/* Reports the robot idle at this very instant and waits for the
 * coordinator to grant it again: what the coordinator does at this instant
 * (a fault) comes before whatever the robot does next. */
void semo__ls_pause(void);
/* pthread_create for a thread that takes turns (numbered now). */
int semo__ls_create(pthread_t *thread, const pthread_attr_t *attr, void *(*body)(void *), void *arg);
/* The calling thread takes no more turns (it ends, or only joins others). */
void semo__ls_leave(void);
/* The program stopped: it wants no more time (what is left is its threads
 * ending, at the instant it stopped, which its `stop` line shows). */
void semo__ls_stopping(void);
/* Ends the link (the program is over). */
void semo__ls_close(void);
/* Sends a datagram to `peer` through the coordinator, which holds it
 * `delay_ms` longer than the network would (a delay fault): taken as sent
 * now, as the simulator takes it. */
int semo__ls_send_late(size_t peer, const void *data, size_t len, int64_t delay_ms);
extern const semo_transport semo_lockstep_transport;
#endif

#ifdef SEMO_SIM
struct semo__sim_tables_s;
/* What a simulated world adds to the threads platform, given to it by the
 * program (semo_program_desc::sim: semo_sim_platform, semo_sim.c): the
 * platform calls the simulation through this table, never by name. */
typedef struct semo_sim_hooks {
    /* The world compiled in (time scale, duration, ...). */
    const struct semo__sim_tables_s *world;
    /* The link faults on a message from this robot to `peer` sent now:
     * false when it is lost, else the extra delay (ms, 0: none). */
    bool (*link)(size_t peer, int64_t *delay_ms);
    /* Sends `data` to `peer` through `transport` `delay_ms` from now. */
    void (*send_later)(const semo_transport *transport, size_t peer, const void *data, size_t len,
                       int64_t delay_ms);
    /* The battery level now, rounded; false when the world gives none. */
    bool (*battery)(long long *level);
    /* Starts and stops the threads that inject the operator's commands and
     * send delayed datagrams. */
    int (*start)(void);
    void (*stop)(void);
} semo_sim_hooks;
#endif

#ifdef SEMO_SIM
/* The robot's world from the scenario, compiled in as tables by `semo build
 * --scenario FILE` (the generated scenario.c): both simulation runtimes read
 * these, and no program reads a scenario file. */
typedef struct {
    int64_t at;
    const char *value;
    const char *is; /* read as the sensor's type when it is read */
} semo__sim_sensor_entry;
typedef struct {
    const char *service;
    int64_t ms;
} semo__sim_service_entry;
/* An operator command to this robot: first at `first`, then every `every`
 * ms (0: once) while <= `until` (-1: forever). */
typedef struct {
    int64_t first, every, until;
    const char *key; /* "USER.<value>" */
    const char *is;
} semo__sim_command_entry;
/* The BATTERY value: linear between the points, in time order. */
typedef struct {
    int64_t at;
    double level;
} semo__sim_battery_entry;
/* An SDF/L loop's path and the iteration whose exit task sets the exit flag. */
typedef struct {
    const char *path;
    int64_t iteration;
} semo__sim_loop_entry;
/* A link fault on this robot's messages to `peers` (local indices) sent in
 * [from, until): lost, or `by` ms late. */
typedef struct {
    int64_t from, until, by;
    bool lost;
    const size_t *peers;
    size_t peer_count;
} semo__sim_link_entry;
/* What a service's calls give back (action results), per call done in
 * order: its values' texts (NULL: none) and their count. */
typedef struct {
    const char *service;
    const char *const *const *calls;
    const size_t *counts;
    size_t call_count;
} semo__sim_results_entry;
typedef struct semo__sim_tables_s {
    int64_t duration_ms; /* 0: until the program stops itself */
    const semo__sim_sensor_entry *sensors;
    size_t sensor_count;
    const semo__sim_service_entry *services;
    size_t service_count;
    const semo__sim_command_entry *operator_commands;
    int64_t *operator_next; /* per command: when it is due next, -1 when done */
    size_t operator_count;
    double time_scale; /* wall ms per mission ms; 0: none given (1) */
    const semo__sim_battery_entry *battery;
    size_t battery_count;
    const semo__sim_loop_entry *loops;
    size_t loop_count;
    const semo__sim_link_entry *links;
    size_t link_count;
    const semo__sim_results_entry *results;
    size_t *results_done; /* per entry: the calls done so far */
    size_t results_count;
} semo__sim_tables;
extern const semo__sim_tables semo__scenario;
/* The scenario's battery level at mission time `t` (linear between its
 * points), rounded half away from zero; its table must not be empty. */
double semo__sim_battery_at(int64_t t);

#include <string.h>
/* semo_sim_results on the tables, for both simulation runtimes. */
static inline int semo__sim_results(const char *service, semo_value *values, int max)
{
    const semo__sim_tables *w = &semo__scenario;
    for (size_t i = 0; service && i < w->results_count; i++) {
        const semo__sim_results_entry *e = &w->results[i];
        if (strcmp(e->service, service) != 0 || e->call_count == 0)
            continue;
        size_t call = w->results_done[i] < e->call_count ? w->results_done[i] : e->call_count - 1;
        w->results_done[i]++;
        int n = 0;
        for (size_t k = 0; k < e->counts[call] && n < max; k++, n++) {
            const char *text = e->calls[call][k];
            if (text)
                semo_value_set(&values[n], text);
            else
                values[n] = (semo_value){.type = SEMO_NONE};
        }
        return n;
    }
    return 0;
}
#endif

/* Platform hooks of the static schedule: the board file (semo_lm3s6965.c,
 * semo_stm32f405.c) starts the board and writes the trace's output; the
 * core (semo_cortex_m.c, every Cortex-M) gives a millisecond clock,
 * sleeping until a deadline of that clock (or an interrupt: the caller
 * looks at the time again; INT64_MAX: no deadline) and ending the program. */
#ifdef SEMO_STATIC
void semo__board_init(void);
int64_t semo__board_now_ms(void);
void semo__board_put(void *ctx, const char *bytes, size_t n);
void semo__board_sleep_until(int64_t deadline_ms);
void semo__board_exit(int status);
/* semo_cortex_m.c's: the clock started by the board's init; the reset,
 * SysTick and fault handlers in the board's vector table. */
void semo__systick_start(void);
void semo__reset(void);
void semo__systick(void);
void semo__fault(void);
#ifdef SEMO_LINK
/* The link to `semo gateway` on the board's second serial port (-DSEMO_LINK:
 * a robot that messages other robots; docs/link.md). The board file starts
 * it in semo__board_init, writes bytes (all of them, waiting for room), and
 * hands each byte its interrupt receives to the core's receive ring
 * (semo_cortex_m.c), which gives the next byte received without taking it
 * (false: none yet), takes it, and counts the bytes lost to a full ring. A
 * received byte ends a sleep: it sets semo__board_woken, which
 * semo__board_sleep_until reads with interrupts masked, so a byte that came
 * just before the sleep is not slept through. */
void semo__board_link_put(const unsigned char *bytes, size_t n);
void semo__board_link_received(unsigned char byte);
bool semo__board_link_peek(unsigned char *byte);
void semo__board_link_take(void);
unsigned long semo__board_link_overruns(void);
extern volatile bool semo__board_woken;
/* semo_static_link.c's, for the loop (semo_static.c): waits for the
 * gateway's welcome (mission time starts after it); feeds what the line
 * brought and writes what is due; when that is next needed (board ms,
 * INT64_MAX: only when a byte comes); before the program's `stop`, waits
 * (at most 2 s) for what was sent to be acknowledged and traces what the
 * link lost (semo__link_report, below); after it, waits (at most 2 s) for
 * its last status. */
void semo__link_open(void);
void semo__link_pump(void);
int64_t semo__link_deadline(void);
void semo__link_close(void);
/* The payload of the link queue's next frame, to be written in place
 * (SEMO_LINK_SEND_MAX bytes) and queued by semo__link_commit. While the
 * queue is full it pumps the line until a slot frees, however long when
 * `patient` (a send), else only while the program runs; never from within
 * the line's own feeding (a trace made as a frame is taken): NULL then. */
unsigned char *semo__link_slot(bool patient);
void semo__link_commit(unsigned char kind, size_t len);
/* The last frame queued, if of kind `kind` and not on the line yet, to be
 * written again in place (semo_link_waiting); its new length. */
unsigned char *semo__link_waiting(unsigned char kind);
void semo__link_rewrite(size_t len);
#ifdef SEMO_LOCKSTEP
/* semo_static_lockstep.c's: mission time as the coordinator granted it;
 * reports the robot idle until `wake_ms` (INT64_MAX: until a message) and
 * returns once the coordinator grants a time (after delivering what came)
 * or ends the run (the program is then stopped). */
int64_t semo__lockstep_now(void);
void semo__lockstep_idle(int64_t wake_ms);
#endif
/* semo_static_status.c's: the robot's status, kept from each trace event
 * (semo__trace_emit's) and sent on the link when it changes. */
void semo__status_observe(const char *event, va_list args);
#endif
#endif

#ifdef SEMO_MQTT
/* Whether the broker still held this robot's session at the first
 * connection (CONNACK's session-present flag): the robot was restarted in
 * its run (the default client id names the run). */
bool semo__mqtt_session_present(void);
#endif
/* Whether the gateway's Welcome said the broker kept the robot's session
 * (semo_link_transport.c, POSIX). */
bool semo__link_session_present(void);
/* Before the program's `stop`: waits (at most 2 s) for what was sent
 * reliably to be acknowledged, then traces a `link` event with what the
 * link lost or did again, when anything (semo_link_transport.c on POSIX,
 * semo_static_link.c on a board). */
void semo__link_report(void);

#endif /* SEMO_INTERNAL_H */
