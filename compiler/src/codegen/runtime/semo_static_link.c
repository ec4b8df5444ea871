/* semo_static_link.c: the static schedule's transport to other robots
 * (built with -DSEMO_LINK, which the generator sets for a board robot that
 * messages other robots): the serial link (semo_link.c, docs/link.md) on
 * the board's second serial port to `semo gateway`, which speaks MQTT for
 * the robot. The same frames as a Linux robot's `--transport link`
 * (semo_link_transport.c): semo_link_send_datagram makes both sides' S and
 * P frames from the core's one datagram.
 *
 * No thread: the loop (semo_static.c) pumps the line at every pass (the
 * bytes received fed to the link, what is due written) and sleeps until the
 * link's next deadline (a hello or a frame to repeat, on the board's clock)
 * or a received byte. A `send` goes reliably (repeated until acknowledged);
 * a `publish` goes at once (lost with the line, as at QoS 0). Both are made
 * in the next free slot of the link's queue, where a send's frame is
 * queued (no buffer of their own): while the queue is full the line is
 * pumped in place until a slot frees (never lost). The robot's status (T,
 * semo_static_status.c) is queued the same way. A message (M) goes to the
 * inbox, and while the inbox is full and a task reads it, the rest stays on
 * the line (the gateway and the broker keep what follows, as for a full
 * Linux robot); a refusal (R) is traced. At start the robot says hello
 * until the gateway welcomes it, without a time limit (a robot that
 * messages others has nothing to do without them): mission time 0 is when
 * it joined. At the end it waits at most 2 s for what it sent to be
 * acknowledged and traces what the link lost, then, after its `stop`, at
 * most 2 s more for its last status.
 */
/* In lock-step the port speaks to the coordinator (semo_static_lockstep.c). */
#if defined(SEMO_LINK) && !defined(SEMO_LOCKSTEP)
#include "semo_internal.h"
#include "semo_link.h"

#include <string.h>

#define LINK_CLOSE_WAIT_MS 2000

static semo_link g_link;
/* One message at a time (nothing else runs): the one being sent, until it
 * is encoded, then the one being received. Static, off the stack. */
static semo_message g_message;
/* The line is being fed: a frame taken may be traced with arguments in
 * g_message or in the link, so nothing pumps the line again until it is
 * done (semo__link_slot). */
static bool g_feeding;

static void line_write(void *ctx, const unsigned char *bytes, size_t n)
{
    (void)ctx;
    semo__board_link_put(bytes, n);
}

/* A frame the gateway sent. */
static void taken(const semo_link_frame *f)
{
    if (f->kind == SEMO_LINK_REFUSED) {
        semo_trace("reject", "reason",
                   f->payload[0] == SEMO_LINK_REFUSED_LENGTH ? SEMO_TOO_LONG_REASON : "sender not its topic",
                   NULL);
    } else if (f->kind == SEMO_LINK_MESSAGE) {
        if (semo__decode_message(f->payload, f->len, &g_message))
            semo__deliver(&g_message);
        else
            semo_trace("reject", "reason", "malformed datagram", NULL);
    }
}

/* Feeds the bytes received. `hold`: a frame's last byte stays on the line
 * while the inbox holds back (the frame is then neither taken nor
 * acknowledged). `until_welcomed`: stops at the byte that completes the
 * session (what follows waits for the mission to start). */
static void feed(bool hold, bool until_welcomed)
{
    unsigned char byte;
    g_feeding = true;
    while (semo__board_link_peek(&byte)) {
        if (byte == 0 && hold && semo__inbox_holds_back())
            break;
        semo__board_link_take();
        semo_link_frame f;
        if (semo_link_feed(&g_link, byte, semo__board_now_ms(), &f))
            taken(&f);
        if (until_welcomed && g_link.welcomed)
            break;
    }
    g_feeding = false;
}

/* Sleeps until the link's next deadline, `limit` (board ms) or a byte. */
static void wait_on_line(int64_t limit)
{
    int64_t due = semo_link_deadline(&g_link);
    semo__board_sleep_until(due < limit ? due : limit);
}

void semo__link_open(void)
{
#ifdef SEMO_SIM
    /* The scenario's link faults act on a message per receiver, which only
     * the udp transport of linux-sim has (as an MQTT robot refuses them). */
    if (semo__scenario.link_count > 0) {
        static const char message[] =
            "semo runtime: the scenario's link faults need the udp transport (linux-sim): a board robot on the serial link cannot run them\n";
        semo__board_put(NULL, message, sizeof message - 1);
        semo__board_exit(1);
    }
#endif
    semo_link_init(&g_link, line_write, NULL);
    while (!g_link.welcomed) {
        feed(true, true);
        if (g_link.welcomed)
            break;
        semo_link_tick(&g_link, semo__board_now_ms());
        wait_on_line(INT64_MAX);
    }
}

void semo__link_pump(void)
{
    feed(true, false);
    semo_link_tick(&g_link, semo__board_now_ms());
}

int64_t semo__link_deadline(void)
{
    return semo_link_deadline(&g_link);
}

/* Waits (at most LINK_CLOSE_WAIT_MS) for what was sent to be acknowledged. */
static void wait_for_acknowledgements(void)
{
    int64_t until = semo__board_now_ms() + LINK_CLOSE_WAIT_MS;
    while (semo_link_pending(&g_link) > 0 && semo__board_now_ms() < until) {
        feed(false, false);
        semo_link_tick(&g_link, semo__board_now_ms());
        wait_on_line(until);
    }
}

void semo__link_report(void)
{
    wait_for_acknowledgements();
    unsigned long overruns = semo__board_link_overruns();
    if (g_link.bad_frames || g_link.duplicates || g_link.retransmissions || overruns ||
        semo_link_pending(&g_link)) {
        char counts[5][21];
        semo__format_i64(counts[0], (int64_t)g_link.bad_frames);
        semo__format_i64(counts[1], (int64_t)g_link.duplicates);
        semo__format_i64(counts[2], (int64_t)g_link.retransmissions);
        semo__format_i64(counts[3], (int64_t)overruns);
        semo__format_i64(counts[4], (int64_t)semo_link_pending(&g_link));
        semo_trace("link", "bad_frames", counts[0], "duplicates", counts[1], "retransmissions", counts[2],
                   "overruns", counts[3], "unacknowledged", counts[4], NULL);
    }
}

void semo__link_close(void)
{
    wait_for_acknowledgements();
}

unsigned char *semo__link_slot(bool patient)
{
    unsigned char *slot;
    while ((slot = semo_link_slot(&g_link)) == NULL && !g_feeding && (patient || semo_running())) {
        /* Room comes with the gateway's acknowledgement: read the line for
         * it here (a message behind it goes to the inbox, or is dropped and
         * traced when the inbox is full: nothing else can take it now). */
        feed(false, false);
        semo_link_tick(&g_link, semo__board_now_ms());
        if ((slot = semo_link_slot(&g_link)) == NULL)
            wait_on_line(INT64_MAX);
    }
    return slot;
}

void semo__link_commit(unsigned char kind, size_t len)
{
    semo_link_commit(&g_link, kind, len);
    semo_link_tick(&g_link, semo__board_now_ms());
}

unsigned char *semo__link_waiting(unsigned char kind)
{
    return semo_link_waiting(&g_link, kind);
}

void semo__link_rewrite(size_t len)
{
    semo_link_rewrite(&g_link, len);
}

int64_t semo_joined_ms(void)
{
    return 0; /* mission time starts when the gateway welcomed the robot */
}

bool semo_session_resumed(void)
{
    return (g_link.peer_flags & 1) != 0;
}

/* Every other robot of `to_team` (or the robot of that name) in the
 * program's peer table; the gateway publishes one message for all of them,
 * as the MQTT transport does. */
static int addressed(const char *to_team)
{
    const semo_program_desc *p = semo_program();
    int count = 0;
    for (size_t i = 0; i < p->peer_count; i++)
        if (i != p->self && (strcmp(p->peers[i].team, to_team) == 0 || strcmp(p->peers[i].robot, to_team) == 0))
            count++;
    return count;
}

static void copy_name(char *out, size_t cap, const char *name)
{
    size_t n = strlen(name);
    n = n < cap - 1 ? n : cap - 1;
    memcpy(out, name, n);
    out[n] = '\0';
}

int semo_comm_send(const char *to_team, semo_msg_kind kind, const char *key, const semo_value *value)
{
    int local = semo__comm_send_local(to_team, kind, key, value);
    if (local < 0)
        return local;
    int sent = local == 1 ? 1 : addressed(to_team);
    if (sent == 0)
        return 0;
    /* The slot first: the line is read while waiting for one, and a
     * message read goes through g_message. */
    unsigned char *slot = semo__link_slot(true);
    const semo_program_desc *p = semo_program();
    semo_message *m = &g_message;
    memset(m, 0, sizeof *m);
    m->kind = (char)kind;
    copy_name(m->from_team, sizeof m->from_team, p->team);
    copy_name(m->from_robot, sizeof m->from_robot, p->robot);
    copy_name(m->key, sizeof m->key, key);
    m->value = *value;
    /* The datagram goes where semo_link_send_datagram puts it, after the
     * length byte and the destination: no frame longer than a slot can go. */
    size_t to_len = strlen(to_team);
    int rc = -1;
    if (slot && to_len > 0 && to_len <= 255 && 1 + to_len + semo__encoded_size(m) <= SEMO_LINK_SEND_MAX) {
        unsigned char *datagram = slot + 1 + to_len;
        rc = semo_link_send_datagram(&g_link, to_team, datagram, semo__encode_message(m, datagram));
    }
    if (rc != 0) {
        semo_trace("comm_error", "to", to_team, "key", key, NULL);
        return -1;
    }
    semo_link_tick(&g_link, semo__board_now_ms());
    return sent;
}
#else
/* Not a robot that messages others: nothing here (ISO C wants a declaration). */
typedef int semo__static_link_unused;
#endif
