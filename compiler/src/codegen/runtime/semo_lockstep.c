/* semo_lockstep.c: lock-step virtual time for `linux-sim` programs
 * (`--lockstep SOCKET`; `semo simulate --engine c` is the coordinator).
 *
 * The robot's clock is driven, not read: mission time is what the
 * coordinator last granted, and it moves only when every robot of the run
 * is idle. A run is then a function of the programs and the scenario, as
 * fast as the machine allows and the same on a loaded one.
 *
 * Inside a robot the threads take turns: one runs at a time (it holds the
 * turn), the others wait in the runtime (a condition wait, a sleep until a
 * time, a read of an empty channel). Every such wait goes through
 * semo__ls_wait, every wake-up through semo__ls_wake, so this file knows at
 * each moment which threads could run; the turn goes to the lowest-numbered
 * of them (threads are numbered in the order the program starts them), so
 * the order of what happens at one instant is fixed too. When none can run
 * the robot is idle: the link thread tells the coordinator, with the
 * earliest time a waiting thread wants to wake at, and waits for its answer:
 * messages to deliver (`D`), then the time granted (`G`).
 *
 * The coordinator is the network: a robot's messages go to it (`M`, with
 * the peer they are for), on the same stream as its idle reports, so when a
 * robot says it is idle the coordinator has everything it sent. It delivers
 * them in a fixed order before it grants any later time.
 *
 * Frames, both ways: one kind byte, a 32-bit little-endian payload length,
 * the payload. Robot to coordinator: `H` (u32: who it is, its place among
 * the mission's robots, `semo_peer::index`), `I` (i64: the next wake-up, -1
 * none), `M` (u32: the place of the robot it is for, then the datagram),
 * `L` (the same after an i64: the extra delay of a scenario's delay fault,
 * ms: the coordinator holds the message that much longer, and takes it, for
 * its random loss and the receiver it reaches, as sent now).
 * Coordinator to robot: `G` (i64: mission time now), `D` (a datagram).
 */
#define _POSIX_C_SOURCE 200809L

#include "semo_internal.h"

/* Only simulation builds (-DSEMO_SIM) have lock-step. */
#if defined(SEMO_SIM) && !defined(SEMO_STATIC)

#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

typedef enum { LS_READY, LS_RUNNING, LS_BLOCKED, LS_DONE } ls_state;

typedef struct {
    ls_state state;
    const void *key;   /* the condition a blocked thread waits on */
    int64_t deadline;  /* mission ms it wakes at by itself; -1: never */
    pthread_cond_t turn; /* signalled when it is given the turn */
} ls_thread;

typedef struct ls_datagram {
    struct ls_datagram *next;
    size_t len;
    unsigned char data[];
} ls_datagram;

static struct {
    atomic_bool on;    /* mission time is the coordinator's */
    atomic_bool turns; /* the threads take turns (until the coordinator goes) */
    pthread_mutex_t lock; /* everything below but the queue */
    pthread_cond_t idle;  /* the link thread waits for the robot to be idle */
    ls_thread **threads;  /* in the order they were started */
    size_t count, cap;
    ls_thread *running;   /* the thread holding the turn; NULL: idle */
    bool lost;            /* the coordinator went away: nothing waits any more */
    bool stopping;        /* the program stopped: its time no longer moves */
    _Atomic int_least64_t now;
    int fd;
    pthread_mutex_t write_lock;
    pthread_t link;
    bool link_started;
    /* Datagrams the coordinator delivered, for the transport's recv. */
    pthread_mutex_t queue_lock;
    char queued; /* the receiver waits on its address */
    ls_datagram *head, *tail;
    bool interrupted;
} g_ls = {
    .lock = PTHREAD_MUTEX_INITIALIZER,
    .idle = PTHREAD_COND_INITIALIZER,
    .write_lock = PTHREAD_MUTEX_INITIALIZER,
    .queue_lock = PTHREAD_MUTEX_INITIALIZER,
    .fd = -1,
};

/* This thread's record; NULL in threads outside the turns (the signal
 * watcher, the link thread, the main thread once it left). */
static _Thread_local ls_thread *g_self;

bool semo__ls_on(void)
{
    return atomic_load(&g_ls.on);
}

bool semo__ls_turns(void)
{
    return atomic_load(&g_ls.turns);
}

int64_t semo__ls_now(void)
{
    return atomic_load(&g_ls.now);
}

/* ------------------------------------------------------------- the turns */

/* Gives the turn to the lowest-numbered thread that can run, or marks the
 * robot idle. Called with the lock held and no thread running. */
static void hand_on_locked(void)
{
    for (size_t i = 0; i < g_ls.count; i++) {
        ls_thread *t = g_ls.threads[i];
        if (t->state == LS_READY) {
            t->state = LS_RUNNING;
            g_ls.running = t;
            pthread_cond_signal(&t->turn);
            return;
        }
    }
    g_ls.running = NULL;
    pthread_cond_signal(&g_ls.idle);
}

static void await_turn_locked(ls_thread *me)
{
    while (g_ls.running != me && !g_ls.lost)
        pthread_cond_wait(&me->turn, &g_ls.lock);
}

/* A new record, ready to run; NULL when memory ran out. */
static ls_thread *add_thread_locked(ls_state state)
{
    if (g_ls.count == g_ls.cap) {
        size_t cap = g_ls.cap ? g_ls.cap * 2 : 16;
        ls_thread **grown = realloc(g_ls.threads, cap * sizeof *grown);
        if (!grown)
            return NULL;
        g_ls.threads = grown;
        g_ls.cap = cap;
    }
    ls_thread *t = calloc(1, sizeof *t);
    if (!t)
        return NULL;
    t->state = state;
    t->deadline = -1;
    pthread_cond_init(&t->turn, NULL);
    g_ls.threads[g_ls.count++] = t;
    return t;
}

/* Marks the threads waiting on `key` ready (the first only unless `all`). */
static void wake_locked(const void *key, bool all)
{
    for (size_t i = 0; i < g_ls.count; i++) {
        ls_thread *t = g_ls.threads[i];
        if (t->state == LS_BLOCKED && t->key == key) {
            t->state = LS_READY;
            if (!all)
                return;
        }
    }
}

void semo__ls_wait(const void *key, pthread_mutex_t *lock, int64_t deadline_ms)
{
    ls_thread *me = g_self;
    pthread_mutex_lock(&g_ls.lock);
    if (!me || g_ls.lost) {
        /* Outside the turns, or the run is over: a spurious wake-up (every
         * caller waits in a loop that looks again). */
        pthread_mutex_unlock(&g_ls.lock);
        return;
    }
    me->key = key;
    me->deadline = deadline_ms;
    /* A time already reached: the thread only lets the others go first. */
    me->state = deadline_ms >= 0 && deadline_ms <= semo__ls_now() ? LS_READY : LS_BLOCKED;
    hand_on_locked();
    /* Unlocking never waits, so holding the turn lock here cannot deadlock;
     * the next thread may wait a moment for `lock`. */
    pthread_mutex_unlock(lock);
    await_turn_locked(me);
    pthread_mutex_unlock(&g_ls.lock);
    pthread_mutex_lock(lock);
}

void semo__ls_wake(const void *key, bool all)
{
    pthread_mutex_lock(&g_ls.lock);
    wake_locked(key, all);
    /* From outside the turns (the signal watcher) while the robot is idle:
     * someone must run. */
    if (!g_ls.running && !g_self)
        hand_on_locked();
    pthread_mutex_unlock(&g_ls.lock);
}

/* The key a paused thread waits on: nothing wakes it but a grant. */
static const char g_paused;

void semo__ls_pause(void)
{
    ls_thread *me = g_self;
    pthread_mutex_lock(&g_ls.lock);
    if (me && !g_ls.lost) {
        /* Blocked until now, unlike semo__ls_wait's "time already
         * reached", so the robot reports itself idle with this instant as
         * its next wake-up. */
        me->key = &g_paused;
        me->deadline = semo__ls_now();
        me->state = LS_BLOCKED;
        hand_on_locked();
        await_turn_locked(me);
    }
    pthread_mutex_unlock(&g_ls.lock);
}

typedef struct {
    ls_thread *me;
    void *(*body)(void *);
    void *arg;
} ls_start;

static void *trampoline(void *p)
{
    ls_start start = *(ls_start *)p;
    free(p);
    g_self = start.me;
    pthread_mutex_lock(&g_ls.lock);
    await_turn_locked(start.me);
    pthread_mutex_unlock(&g_ls.lock);
    void *result = start.body(start.arg);
    semo__ls_leave();
    return result;
}

int semo__ls_create(pthread_t *thread, const pthread_attr_t *attr, void *(*body)(void *), void *arg)
{
    ls_start *start = malloc(sizeof *start);
    if (!start)
        return ENOMEM;
    pthread_mutex_lock(&g_ls.lock);
    /* Numbered now, by the thread that starts it: the numbering is the
     * program's order, not the order the threads happen to get going. */
    start->me = add_thread_locked(LS_READY);
    pthread_mutex_unlock(&g_ls.lock);
    if (!start->me) {
        free(start);
        return ENOMEM;
    }
    start->body = body;
    start->arg = arg;
    int err = pthread_create(thread, attr, trampoline, start);
    if (err != 0) {
        pthread_mutex_lock(&g_ls.lock);
        start->me->state = LS_DONE;
        pthread_mutex_unlock(&g_ls.lock);
        free(start);
    }
    return err;
}

void semo__ls_stopping(void)
{
    pthread_mutex_lock(&g_ls.lock);
    g_ls.stopping = true;
    pthread_mutex_unlock(&g_ls.lock);
}

void semo__ls_leave(void)
{
    ls_thread *me = g_self;
    if (!me)
        return;
    pthread_mutex_lock(&g_ls.lock);
    me->state = LS_DONE;
    if (g_ls.running == me)
        hand_on_locked();
    pthread_mutex_unlock(&g_ls.lock);
    g_self = NULL;
}

/* ---------------------------------------------------------------- frames */

/* All `len` bytes sent (`out`) or received; -1 when the stream ended or broke. */
static int transfer(unsigned char *p, size_t len, bool out)
{
    while (len > 0) {
        ssize_t n = out ? send(g_ls.fd, p, len, MSG_NOSIGNAL) : recv(g_ls.fd, p, len, 0);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return -1;
        p += n;
        len -= (size_t)n;
    }
    return 0;
}

/* send() only reads the bytes. */
static int write_all(const void *data, size_t len)
{
    return transfer((unsigned char *)(uintptr_t)data, len, true);
}

static int read_all(void *data, size_t len)
{
    return transfer(data, len, false);
}

/* Little-endian fields of `bytes` bytes (4 or 8). */
static void put_le(unsigned char *out, uint64_t v, int bytes)
{
    for (int i = 0; i < bytes; i++)
        out[i] = (unsigned char)(v >> (8 * i));
}

static uint64_t get_le(const unsigned char *in, int bytes)
{
    uint64_t v = 0;
    for (int i = 0; i < bytes; i++)
        v |= (uint64_t)in[i] << (8 * i);
    return v;
}

/* One frame: `head` (a peer index for `M`) then `body`. */
static int write_frame(char kind, const void *head, size_t head_len, const void *body, size_t body_len)
{
    unsigned char header[5];
    header[0] = (unsigned char)kind;
    put_le(header + 1, (uint32_t)(head_len + body_len), 4);
    pthread_mutex_lock(&g_ls.write_lock);
    int result = write_all(header, sizeof header) == 0 && write_all(head, head_len) == 0 &&
                         (body_len == 0 || write_all(body, body_len) == 0)
                     ? 0
                     : -1;
    pthread_mutex_unlock(&g_ls.write_lock);
    return result;
}

/* The next frame from the coordinator: its kind, its payload in `*out`
 * (malloc'd, the caller frees it); -1 when the stream ended or broke. */
static int read_frame(char *kind, unsigned char **out, size_t *len)
{
    unsigned char header[5];
    if (read_all(header, sizeof header) != 0)
        return -1;
    *kind = (char)header[0];
    *len = (uint32_t)get_le(header + 1, 4);
    if (*len > SEMO__DATAGRAM_MAX + 8)
        return -1;
    *out = malloc(*len ? *len : 1);
    if (!*out || read_all(*out, *len) != 0) {
        free(*out);
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------- the link thread */

static bool idle_locked(void)
{
    if (g_ls.running)
        return false;
    for (size_t i = 0; i < g_ls.count; i++)
        if (g_ls.threads[i]->state == LS_READY)
            return false;
    return true;
}

static int64_t next_wake_locked(void)
{
    int64_t next = -1;
    if (g_ls.stopping)
        return next;
    for (size_t i = 0; i < g_ls.count; i++) {
        const ls_thread *t = g_ls.threads[i];
        if (t->state == LS_BLOCKED && t->deadline >= 0 && (next < 0 || t->deadline < next))
            next = t->deadline;
    }
    return next;
}

static void enqueue(unsigned char *data, size_t len)
{
    ls_datagram *d = malloc(sizeof *d + len);
    if (!d) {
        semo_trace("comm_error", "reason", "out of memory for a message", NULL);
        return;
    }
    d->next = NULL;
    d->len = len;
    memcpy(d->data, data, len);
    pthread_mutex_lock(&g_ls.queue_lock);
    if (g_ls.tail)
        g_ls.tail->next = d;
    else
        g_ls.head = d;
    g_ls.tail = d;
    pthread_mutex_lock(&g_ls.lock);
    wake_locked(&g_ls.queued, false); /* it runs when time is granted */
    pthread_mutex_unlock(&g_ls.lock);
    pthread_mutex_unlock(&g_ls.queue_lock);
}

/* Mission time is `now`: the threads whose time it is can run. */
static void grant(int64_t now)
{
    pthread_mutex_lock(&g_ls.lock);
    if (now > semo__ls_now() && !g_ls.stopping)
        atomic_store(&g_ls.now, now);
    for (size_t i = 0; i < g_ls.count; i++) {
        ls_thread *t = g_ls.threads[i];
        if (t->state == LS_BLOCKED && t->deadline >= 0 && t->deadline <= now)
            t->state = LS_READY;
    }
    if (!g_ls.running)
        hand_on_locked();
    pthread_mutex_unlock(&g_ls.lock);
}

/* The coordinator is gone (it ended the run, or died): the threads stop
 * taking turns (the runtime's waits and wake-ups are its plain ones again:
 * a thread that only looked again at once would spin and starve the
 * others of their locks), time stays where it was, and the program stops. */
static void link_lost(void)
{
    pthread_mutex_lock(&g_ls.lock);
    g_ls.lost = true;
    atomic_store(&g_ls.turns, false);
    for (size_t i = 0; i < g_ls.count; i++)
        pthread_cond_signal(&g_ls.threads[i]->turn);
    pthread_mutex_unlock(&g_ls.lock);
    semo_stop_program();
}

static void *link_thread(void *arg)
{
    (void)arg;
    for (;;) {
        pthread_mutex_lock(&g_ls.lock);
        while (!idle_locked() && !g_ls.lost)
            pthread_cond_wait(&g_ls.idle, &g_ls.lock);
        int64_t next = next_wake_locked();
        bool lost = g_ls.lost;
        pthread_mutex_unlock(&g_ls.lock);
        if (lost)
            return NULL;
        unsigned char payload[8];
        put_le(payload, (uint64_t)next, 8);
        if (write_frame('I', payload, sizeof payload, NULL, 0) != 0)
            break;
        for (;;) {
            char kind;
            unsigned char *data;
            size_t len;
            if (read_frame(&kind, &data, &len) != 0)
                goto lost;
            if (kind == 'D') {
                enqueue(data, len);
                free(data);
                continue;
            }
            bool granted = kind == 'G' && len == 8;
            int64_t now = granted ? (int64_t)get_le(data, 8) : 0;
            free(data);
            if (!granted)
                goto lost; /* a frame this robot does not know */
            grant(now);
            break;
        }
    }
lost:
    link_lost();
    return NULL;
}

/* ----------------------------------------------------------- the program */

int semo__ls_connect(const char *path, size_t self)
{
    struct sockaddr_un addr = {.sun_family = AF_UNIX};
    if (strlen(path) >= sizeof addr.sun_path) {
        fprintf(stderr, "semo runtime: the lock-step socket's path is too long: %s\n", path);
        return -1;
    }
    strcpy(addr.sun_path, path);
    g_ls.fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (g_ls.fd < 0 || connect(g_ls.fd, (struct sockaddr *)&addr, sizeof addr) != 0) {
        fprintf(stderr, "semo runtime: cannot reach the lock-step coordinator at %s\n", path);
        return -1;
    }
    unsigned char who[4];
    put_le(who, (uint32_t)self, 4);
    char kind;
    unsigned char *data = NULL;
    size_t len;
    if (write_frame('H', who, sizeof who, NULL, 0) != 0 || read_frame(&kind, &data, &len) != 0 || kind != 'G' ||
        len != 8) {
        free(data);
        fprintf(stderr, "semo runtime: the lock-step coordinator at %s did not start the robot\n", path);
        return -1;
    }
    atomic_store(&g_ls.now, (int64_t)get_le(data, 8));
    free(data);
    /* The main thread is the first to run. */
    pthread_mutex_lock(&g_ls.lock);
    g_self = add_thread_locked(LS_RUNNING);
    g_ls.running = g_self;
    pthread_mutex_unlock(&g_ls.lock);
    if (!g_self)
        return -1;
    atomic_store(&g_ls.on, true);
    atomic_store(&g_ls.turns, true);
    if (pthread_create(&g_ls.link, NULL, link_thread, NULL) != 0) {
        fprintf(stderr, "semo runtime: cannot start the lock-step link\n");
        return -1;
    }
    g_ls.link_started = true;
    return 0;
}

void semo__ls_close(void)
{
    if (g_ls.fd >= 0)
        shutdown(g_ls.fd, SHUT_RDWR);
    if (g_ls.link_started) {
        pthread_mutex_lock(&g_ls.lock);
        g_ls.lost = true;
        atomic_store(&g_ls.turns, false);
        pthread_cond_signal(&g_ls.idle);
        pthread_mutex_unlock(&g_ls.lock);
        pthread_join(g_ls.link, NULL);
        g_ls.link_started = false;
    }
    if (g_ls.fd >= 0)
        close(g_ls.fd);
    g_ls.fd = -1;
}

/* ------------------------------------------------------- the transport */

static int ls_open(const semo_program_desc *program, const semo_transport_config *config)
{
    (void)program;
    (void)config;
    return semo__ls_on() ? 0 : -1;
}

static int ls_send(size_t peer, const void *data, size_t len)
{
    /* The coordinator knows robots by their place in the mission. */
    const semo_program_desc *p = semo_program();
    if (peer >= p->peer_count)
        return -1;
    unsigned char to[4];
    put_le(to, (uint32_t)p->peers[peer].index, 4);
    return write_frame('M', to, sizeof to, data, len);
}

int semo__ls_send_late(size_t peer, const void *data, size_t len, int64_t delay_ms)
{
    const semo_program_desc *p = semo_program();
    if (peer >= p->peer_count)
        return -1;
    unsigned char head[12];
    put_le(head, (uint32_t)p->peers[peer].index, 4);
    put_le(head + 4, (uint64_t)delay_ms, 8);
    return write_frame('L', head, sizeof head, data, len);
}

static int ls_recv(void *data, size_t cap, int timeout_ms)
{
    (void)timeout_ms; /* the receiver waits without one */
    pthread_mutex_lock(&g_ls.queue_lock);
    while (!g_ls.head && !g_ls.interrupted && semo_running() && !g_ls.lost)
        semo__ls_wait(&g_ls.queued, &g_ls.queue_lock, -1);
    ls_datagram *d = g_ls.head;
    if (!d || g_ls.interrupted) {
        pthread_mutex_unlock(&g_ls.queue_lock);
        return 0;
    }
    g_ls.head = d->next;
    if (!g_ls.head)
        g_ls.tail = NULL;
    pthread_mutex_unlock(&g_ls.queue_lock);
    size_t n = d->len < cap ? d->len : cap;
    memcpy(data, d->data, n);
    free(d);
    return (int)n;
}

static void ls_interrupt(void)
{
    pthread_mutex_lock(&g_ls.queue_lock);
    g_ls.interrupted = true;
    semo__ls_wake(&g_ls.queued, true);
    pthread_mutex_unlock(&g_ls.queue_lock);
}

static void ls_transport_close(void)
{
    pthread_mutex_lock(&g_ls.queue_lock);
    while (g_ls.head) {
        ls_datagram *d = g_ls.head;
        g_ls.head = d->next;
        free(d);
    }
    g_ls.tail = NULL;
    pthread_mutex_unlock(&g_ls.queue_lock);
}

const semo_transport semo_lockstep_transport = {
    .name = "lockstep",
    .refusal = "",
    .open = ls_open,
    .send = ls_send,
    .send_to = NULL,
    .recv = ls_recv,
    .interrupt = ls_interrupt,
    .status = NULL,
    .close = ls_transport_close,
};

#else
/* ISO C wants a translation unit to declare something. */
typedef int semo__no_lockstep;
#endif
