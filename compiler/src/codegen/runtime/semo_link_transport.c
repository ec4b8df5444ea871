/* semo_link_transport.c: the serial link (semo_link.c, docs/link.md) as a
 * POSIX program's transport, `--transport link`: the robot speaks the link
 * to `semo gateway` over a TCP connection, $SEMO_LINK=tcp:HOST:PORT (the
 * gateway's `--link ROBOT=listen:HOST:PORT`), and the gateway speaks MQTT
 * for it. The fastest way to run a robot over the link end to end; a board
 * speaks the same frames over its UART.
 *
 * One I/O thread reads the connection and feeds the link, writes what is
 * due (hellos, the reliable frames and their copies), and reconnects when
 * the connection is lost (a gateway restarted). `send` waits for room in the
 * link's queue (never lost); `publish` goes at once (lost with the line, as
 * at QoS 0, and counted); the status goes reliably. `open` waits (at most
 * 5 s) for the gateway's Welcome, whose flag says whether the broker kept
 * the robot's session (semo_session_resumed). At the end the trace's `link`
 * event says what the link lost or did again: bad frames, duplicates,
 * repeats, publishes lost without a session, reconnections (a gateway
 * restarted), frames never acknowledged. */
#define _POSIX_C_SOURCE 200809L

#include "semo_internal.h"
#include "semo_link.h"

#include <errno.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#define LINK_OPEN_WAIT_MS 5000
#define LINK_CLOSE_WAIT_MS 2000
#define LINK_RECONNECT_MS 100

static semo_link g_link;
static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t g_changed; /* monotonic clock; every change below */
static pthread_t g_thread;
static bool g_thread_started;
static int g_fd = -1;
static int g_wake[2] = {-1, -1};
static char g_host[256], g_port[16];
static bool g_stopping, g_interrupted;
static unsigned long g_connections; /* to the gateway, the first included */
static semo__received g_received; /* what recv has still to take */

static int64_t now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000 + t.tv_nsec / 1000000;
}


/* The link's writes, under g_lock: the whole frame or, the line gone,
 * nothing (the reliable ones go again on the next connection). */
static void write_all(void *ctx, const unsigned char *bytes, size_t n)
{
    (void)ctx;
    while (n > 0 && g_fd >= 0) {
        ssize_t w = send(g_fd, bytes, n, MSG_NOSIGNAL);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return;
        bytes += w;
        n -= (size_t)w;
    }
}

static void wake_thread(void)
{
    if (g_wake[1] >= 0) {
        ssize_t w = write(g_wake[1], "w", 1);
        (void)w;
    }
}

static int connect_gateway(void)
{
    struct addrinfo hints = {.ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM}, *found = NULL;
    if (getaddrinfo(g_host, g_port, &hints, &found) != 0)
        return -1;
    int fd = -1;
    for (struct addrinfo *a = found; a && fd < 0; a = a->ai_next) {
        fd = socket(a->ai_family, a->ai_socktype, a->ai_protocol);
        if (fd >= 0 && connect(fd, a->ai_addr, a->ai_addrlen) != 0) {
            close(fd);
            fd = -1;
        }
    }
    freeaddrinfo(found);
    if (fd >= 0) {
        int one = 1;
        setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    }
    return fd;
}

/* A frame the gateway sent, under g_lock. */
static void taken(const semo_link_frame *f)
{
    if (f->kind == SEMO_LINK_REFUSED) {
        if (!g_interrupted && f->payload[0] == SEMO_LINK_REFUSED_LENGTH)
            g_received.too_long++;
        else if (!g_interrupted)
            g_received.refused++;
    } else if (f->kind == SEMO_LINK_MESSAGE && !g_interrupted) {
        /* Room was made before the frame was taken (io_thread); none only
         * once the program stops, when nothing more is delivered. */
        semo__received_put(&g_received, f->payload, f->len);
    }
    pthread_cond_broadcast(&g_changed);
}

static void *io_thread(void *arg)
{
    (void)arg;
    unsigned char buf[4096];
    pthread_mutex_lock(&g_lock);
    while (!g_stopping) {
        if (g_fd < 0) {
            pthread_mutex_unlock(&g_lock);
            int fd = connect_gateway();
            pthread_mutex_lock(&g_lock);
            if (fd < 0) {
                struct timespec until = semo__deadline_after(LINK_RECONNECT_MS);
                while (!g_stopping && pthread_cond_timedwait(&g_changed, &g_lock, &until) == 0) {
                }
                continue;
            }
            g_fd = fd;
            g_connections++;
            semo_link_restart(&g_link);
        }
        semo_link_tick(&g_link, now_ms());
        int64_t due = semo_link_deadline(&g_link);
        int64_t now = now_ms();
        int timeout = due == INT64_MAX ? -1 : due <= now ? 0 : (int)(due - now > 60000 ? 60000 : due - now);
        struct pollfd fds[2] = {{.fd = g_fd, .events = POLLIN}, {.fd = g_wake[0], .events = POLLIN}};
        pthread_mutex_unlock(&g_lock);
        int ready = poll(fds, 2, timeout);
        ssize_t n = 0;
        if (ready > 0 && (fds[0].revents & (POLLIN | POLLHUP | POLLERR)))
            n = recv(fds[0].fd, buf, sizeof buf, 0);
        if (ready > 0 && (fds[1].revents & POLLIN)) {
            char drain[64];
            ssize_t r = read(g_wake[0], drain, sizeof drain);
            (void)r;
        }
        pthread_mutex_lock(&g_lock);
        if (ready > 0 && (fds[0].revents & (POLLIN | POLLHUP | POLLERR)) && n <= 0 &&
            !(n < 0 && errno == EINTR)) {
            close(g_fd); /* the gateway went away: connect again */
            g_fd = -1;
            /* No session until the next Welcome: a publish meanwhile is
             * lost and counted, not written to a closed line. */
            semo_link_restart(&g_link);
            pthread_cond_broadcast(&g_changed);
            continue;
        }
        for (ssize_t i = 0; i < n; i++) {
            /* A frame's last byte may bring a message, which the link
             * acknowledges as it takes it: with the inbox full, wait for
             * room (link_recv makes it) rather than acknowledge a message
             * and lose it. The gateway keeps the rest meanwhile, as the
             * broker does for a full MQTT robot. */
            while (buf[i] == 0 && semo__received_full(&g_received) && !g_interrupted && !g_stopping)
                pthread_cond_wait(&g_changed, &g_lock);
            semo_link_frame f;
            if (semo_link_feed(&g_link, buf[i], now_ms(), &f))
                taken(&f);
        }
        pthread_cond_broadcast(&g_changed);
    }
    pthread_mutex_unlock(&g_lock);
    return NULL;
}

/* `tcp:HOST:PORT`. */
static bool parse_link(const char *link)
{
    if (!link || strncmp(link, "tcp:", 4) != 0)
        return false;
    const char *rest = link + 4, *colon = strrchr(rest, ':');
    if (!colon || colon == rest || (size_t)(colon - rest) >= sizeof g_host || strlen(colon + 1) == 0 ||
        strlen(colon + 1) >= sizeof g_port)
        return false;
    memcpy(g_host, rest, (size_t)(colon - rest));
    g_host[colon - rest] = '\0';
    snprintf(g_port, sizeof g_port, "%s", colon + 1);
    return true;
}

bool semo__link_session_present(void)
{
    pthread_mutex_lock(&g_lock);
    bool present = (g_link.peer_flags & 1) != 0;
    pthread_mutex_unlock(&g_lock);
    return present;
}

static int link_open(const semo_program_desc *program, const semo_transport_config *config)
{
    (void)program;
    if (g_thread_started)
        return -1;
    if (!parse_link(config->link)) {
        fprintf(stderr, "semo runtime: the link transport needs $SEMO_LINK=tcp:HOST:PORT (the gateway's listen:HOST:PORT), not \"%s\"\n",
                config->link ? config->link : "");
        return -1;
    }
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    pthread_cond_init(&g_changed, &attr);
    pthread_condattr_destroy(&attr);
    if (pipe(g_wake) != 0)
        return -1;
    semo_link_init(&g_link, write_all, NULL);
    g_stopping = g_interrupted = false;
    g_received.head = g_received.count = 0;
    g_received.refused = 0;
    g_received.too_long = 0;
    g_connections = 0;
    if (pthread_create(&g_thread, NULL, io_thread, NULL) != 0)
        return -1;
    g_thread_started = true;
    /* Nothing is sent before the gateway has answered: it holds the robot's
     * subscriptions by then. */
    struct timespec deadline = semo__deadline_after(LINK_OPEN_WAIT_MS);
    pthread_mutex_lock(&g_lock);
    int waited = 0;
    while (!g_link.welcomed && waited == 0)
        waited = pthread_cond_timedwait(&g_changed, &g_lock, &deadline);
    bool ready = g_link.welcomed;
    pthread_mutex_unlock(&g_lock);
    if (!ready) {
        fprintf(stderr, "semo runtime: no gateway answered on %s\n", config->link);
        return -1;
    }
    return 0;
}

/* A reliable frame, waiting for room in the link's queue. */
static int queue_reliable(unsigned char kind, const void *a, size_t alen, const void *b, size_t blen)
{
    if (alen + blen > SEMO_LINK_PAYLOAD_MAX)
        return -1;
    pthread_mutex_lock(&g_lock);
    int rc;
    while ((rc = semo_link_queue(&g_link, kind, a, alen, b, blen)) != 0 && !g_interrupted)
        pthread_cond_wait(&g_changed, &g_lock);
    pthread_mutex_unlock(&g_lock);
    wake_thread();
    return rc;
}

/* The link's frame for the datagram (semo_link_send_datagram, as a board
 * sends it); a send waits for room in the link's queue. */
static int link_send_to(const char *to, const void *data, size_t len)
{
    pthread_mutex_lock(&g_lock);
    int rc;
    while ((rc = semo_link_send_datagram(&g_link, to, data, len)) == -2 && !g_interrupted)
        pthread_cond_wait(&g_changed, &g_lock);
    pthread_mutex_unlock(&g_lock);
    wake_thread();
    return rc == 0 ? 0 : -1;
}

static int link_status(const char *json, size_t len)
{
    return queue_reliable(SEMO_LINK_STATUS, json, len, NULL, 0);
}

static int link_recv(void *data, size_t cap, int timeout_ms)
{
    return semo__received_take(&g_received, &g_lock, &g_changed, &g_interrupted, data, cap, timeout_ms);
}

static void link_interrupt(void)
{
    pthread_mutex_lock(&g_lock);
    g_interrupted = true;
    pthread_cond_broadcast(&g_changed);
    pthread_mutex_unlock(&g_lock);
    wake_thread();
}

/* With g_lock held: waits (up to LINK_CLOSE_WAIT_MS) until what was sent
 * reliably is acknowledged, or the link is gone. */
static void wait_for_acknowledgements(void)
{
    struct timespec deadline = semo__deadline_after(LINK_CLOSE_WAIT_MS);
    int waited = 0;
    while (semo_link_pending(&g_link) > 0 && g_fd >= 0 && waited == 0)
        waited = pthread_cond_timedwait(&g_changed, &g_lock, &deadline);
}

static void format_count(char *out, unsigned long n)
{
    snprintf(out, 21, "%lu", n);
}

void semo__link_report(void)
{
    if (!g_thread_started)
        return;
    pthread_mutex_lock(&g_lock);
    wait_for_acknowledgements();
    unsigned long counts[6] = {g_link.bad_frames, g_link.duplicates, g_link.retransmissions, g_link.lost,
                               g_connections > 1 ? g_connections - 1 : 0, semo_link_pending(&g_link)};
    pthread_mutex_unlock(&g_lock);
    bool any = false;
    for (int i = 0; i < 6; i++)
        any = any || counts[i] > 0;
    if (!any)
        return;
    char text[6][21];
    for (int i = 0; i < 6; i++)
        format_count(text[i], counts[i]);
    semo_trace("link", "bad_frames", text[0], "duplicates", text[1], "retransmissions", text[2], "lost", text[3],
               "reconnections", text[4], "unacknowledged", text[5], NULL);
}

static void link_close(void)
{
    if (!g_thread_started)
        return;
    /* What was sent reliably reaches the gateway before we go. */
    pthread_mutex_lock(&g_lock);
    wait_for_acknowledgements();
    g_stopping = true;
    pthread_cond_broadcast(&g_changed);
    pthread_mutex_unlock(&g_lock);
    wake_thread();
    pthread_join(g_thread, NULL);
    g_thread_started = false;
    if (g_fd >= 0)
        close(g_fd);
    g_fd = -1;
    close(g_wake[0]);
    close(g_wake[1]);
    g_wake[0] = g_wake[1] = -1;
    pthread_cond_destroy(&g_changed);
}

const semo_transport semo_link_transport = {
    .name = "link",
    .refusal = "sender not its topic",
    .open = link_open,
    .send_to = link_send_to,
    .recv = link_recv,
    .interrupt = link_interrupt,
    .status = link_status,
    .close = link_close,
};
