/* semo_static_lockstep.c: lock-step virtual time for a board robot in QEMU
 * (a `-sim` board target made with `make LOCKSTEP=1`, -DSEMO_LOCKSTEP;
 * `semo simulate --engine c --boards` is the coordinator, cli/src/lockstep.rs).
 *
 * The same protocol as a `linux-sim` program's (semo_lockstep.c), on the
 * board's second serial port (the link's) instead of a socket: QEMU connects
 * that port to the coordinator's socket. The robot's clock is driven, not
 * read: mission time is what the coordinator last granted. The static loop
 * (semo_static.c) runs everything due at an instant, then reports itself
 * idle with the earliest time it wants to wake at (`I`) and reads the
 * coordinator's answer: the time of the messages that follow (`N`),
 * the messages to deliver (`D`, each taken at once, into the inbox or, when
 * that is full, through the task that reads it; each acknowledged with `A`:
 * a serial port has no flow control, and the board's receive ring holds two
 * frames, so the coordinator sends the next only after the
 * acknowledgement; or refused for now with `B` while the inbox is full and
 * no task polled it yet, as a POSIX robot's receiver waits, at most
 * SEMO__INBOX_UNPOLLED_WAIT_MS: the coordinator keeps it and what follows
 * and offers them again once the robot ran), then the time granted (`G`),
 * or the end of the run
 * (`E`: a serial port does not close; the robot stops as a program whose
 * coordinator went away). Its messages go out as `M` frames, one per robot
 * they are for, as a `linux-sim` program's do, so the coordinator is the
 * network for both alike and applies the scenario's latency and losses.
 *
 * Frames, both ways: one kind byte, a 32-bit little-endian payload length,
 * the payload. QEMU's serial ports lose nothing and change nothing, so no
 * checksum; a frame too long for the board, or the receive ring overrun,
 * is an internal error: the robot says so on its trace port and exits.
 */
#if defined(SEMO_STATIC) && defined(SEMO_SIM) && defined(SEMO_LOCKSTEP)
#include "semo_internal.h"

#include <string.h>

#ifndef SEMO_LINK
#error "SEMO_LOCKSTEP: a board robot in lock-step speaks on its link's serial port (-DSEMO_LINK)"
#endif

/* The longest frame the coordinator sends: a datagram. */
#define LS_PAYLOAD_MAX SEMO__DATAGRAM_MAX

static int64_t g_now;
static int64_t g_joined;
/* The frame being read and its message; apart from those being sent: a
 * message taken into a full inbox fires the task that reads it, which may
 * send before the message taken is queued. */
static semo_message g_message;
static unsigned char g_payload[LS_PAYLOAD_MAX];
static semo_message g_sent;
static unsigned char g_datagram[LS_PAYLOAD_MAX];
/* A message waits for room in a full inbox no task polled yet, as a POSIX
 * robot's receiver does: the coordinator keeps it (and what follows it)
 * until `g_waits_until`, then the robot drops it. */
static bool g_waiting;
static int64_t g_waits_until;

static void put_le(unsigned char *out, uint64_t v, int bytes)
{
    for (int i = 0; i < bytes; i++)
        out[i] = (unsigned char)(v >> (8 * i));
}

static uint64_t get_le(const unsigned char *in, int bytes)
{
    uint64_t v = 0;
    for (int i = bytes - 1; i >= 0; i--)
        v = (v << 8) | in[i];
    return v;
}

static void fail(const char *why)
{
    static const char head[] = "semo runtime: lock-step: ";
    semo__board_put(NULL, head, sizeof head - 1);
    semo__board_put(NULL, why, strlen(why));
    semo__board_put(NULL, "\n", 1);
    semo__board_exit(1);
}

static void write_frame(char kind, const unsigned char *head, size_t head_len, const unsigned char *body,
                        size_t body_len)
{
    unsigned char header[5];
    header[0] = (unsigned char)kind;
    put_le(header + 1, head_len + body_len, 4);
    semo__board_link_put(header, sizeof header);
    if (head_len > 0)
        semo__board_link_put(head, head_len);
    if (body_len > 0)
        semo__board_link_put(body, body_len);
}

/* The next byte from the coordinator, sleeping until it comes. */
static unsigned char read_byte(void)
{
    unsigned char byte;
    while (!semo__board_link_peek(&byte))
        semo__board_sleep_until(INT64_MAX);
    semo__board_link_take();
    if (semo__board_link_overruns() > 0)
        fail("the receive ring overran (a frame came before the last was read)");
    return byte;
}

/* The next frame: its kind, its payload in g_payload, its length. */
static char read_frame(size_t *len)
{
    unsigned char header[5];
    for (size_t i = 0; i < sizeof header; i++)
        header[i] = read_byte();
    uint64_t n = get_le(header + 1, 4);
    if (n > LS_PAYLOAD_MAX)
        fail("a frame longer than any datagram");
    for (size_t i = 0; i < n; i++)
        g_payload[i] = read_byte();
    *len = (size_t)n;
    return (char)header[0];
}

/* Reads the coordinator's answer to an idle report or a hello: messages,
 * then the time granted (or the end of the run). */
static void await_grant(void)
{
    for (;;) {
        size_t len;
        char kind = read_frame(&len);
        if (kind == 'G' && len == 8) {
            g_now = (int64_t)get_le(g_payload, 8);
            return;
        }
        if (kind == 'E') {
            semo_stop_program();
            return;
        }
        if (kind == 'N' && len == 8) {
            g_now = (int64_t)get_le(g_payload, 8);
            continue;
        }
        if (kind != 'D')
            fail("a frame the coordinator does not send");
        if (semo__inbox_unpolled_full()) {
            if (!g_waiting) {
                g_waiting = true;
                g_waits_until = g_now + SEMO__INBOX_UNPOLLED_WAIT_MS;
            }
            if (g_now < g_waits_until) {
                write_frame('B', NULL, 0, NULL, 0); /* busy: offer it again later */
                continue;
            }
        }
        g_waiting = false;
        if (semo__decode_message(g_payload, len, &g_message))
            semo__deliver(&g_message); /* dropped, traced, when still full */
        else
            semo_trace("reject", "reason", "malformed datagram", NULL);
        write_frame('A', NULL, 0, NULL, 0);
    }
}

int64_t semo__lockstep_now(void)
{
    return g_now;
}

void semo__lockstep_idle(int64_t wake_ms)
{
    if (g_waiting && g_waits_until < wake_ms)
        wake_ms = g_waits_until;
    unsigned char at[8];
    put_le(at, (uint64_t)(wake_ms == INT64_MAX ? -1 : wake_ms), 8);
    write_frame('I', at, sizeof at, NULL, 0);
    await_grant();
}

/* Says who it is (its place among the mission's robots) and takes the
 * time it starts at. */
void semo__link_open(void)
{
    /* The scenario's link faults act on a message per receiver in the
     * linux-sim runtime (semo_sim.c), which a board does not have. */
    if (semo__scenario.link_count > 0)
        fail("the scenario's link faults need linux-sim robots: a board robot cannot run them");
    const semo_program_desc *p = semo_program();
    unsigned char who[4];
    put_le(who, p->peer_count ? (uint64_t)p->peers[p->self].index : 0, 4);
    write_frame('H', who, sizeof who, NULL, 0);
    await_grant();
    g_joined = g_now;
}

/* Messages come with the grants: nothing to pump, no deadline of its own. */
void semo__link_pump(void) {}

int64_t semo__link_deadline(void)
{
    return INT64_MAX;
}

/* Nothing is sent that could be lost on the way to the coordinator. */
void semo__link_report(void) {}

void semo__link_close(void) {}

int64_t semo_joined_ms(void)
{
    return g_joined;
}

bool semo_session_resumed(void)
{
    return false;
}

/* As the linux-sim runtime's: one datagram per robot it is for. */
int semo_comm_send(const char *to_team, semo_msg_kind kind, const char *key, const semo_value *value)
{
    int local = semo__comm_send_local(to_team, kind, key, value);
    if (local < 0)
        return local;
    if (local == 1)
        return 1; /* the operator console: the trace is its record */
    const semo_program_desc *p = semo_program();
    semo_message *m = &g_sent;
    memset(m, 0, sizeof *m);
    m->kind = (char)kind;
    size_t n;
    n = strlen(p->team);
    memcpy(m->from_team, p->team, n < sizeof m->from_team - 1 ? n : sizeof m->from_team - 1);
    n = strlen(p->robot);
    memcpy(m->from_robot, p->robot, n < sizeof m->from_robot - 1 ? n : sizeof m->from_robot - 1);
    n = strlen(key);
    memcpy(m->key, key, n < sizeof m->key - 1 ? n : sizeof m->key - 1);
    m->value = *value;
    size_t len = semo__encode_message(m, g_datagram);
    int sent = 0;
    for (size_t i = 0; i < p->peer_count; i++) {
        const semo_peer *peer = &p->peers[i];
        if (i == p->self || (strcmp(peer->team, to_team) != 0 && strcmp(peer->robot, to_team) != 0))
            continue;
        unsigned char to[4];
        put_le(to, (uint64_t)peer->index, 4);
        write_frame('M', to, sizeof to, g_datagram, len);
        sent++;
    }
    return sent;
}
#else
/* Not a board robot in lock-step: nothing here (ISO C wants a declaration). */
typedef int semo__static_lockstep_unused;
#endif
