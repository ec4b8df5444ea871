/* semo_link.h: the serial link between a small robot and `semo gateway`
 * (docs/link.md), the same definition as `semo::link` on the Rust side
 * (`tests/link.rs` holds them to each other).
 *
 * A frame: kind (1 byte), seq (2, big-endian), payload, CRC-16/CCITT-FALSE
 * of those (2, big-endian); COBS-stuffed and closed by a zero byte.
 * The reliable kinds (S, T, M, R) go one at a time, each with the next
 * sequence number, again every SEMO_LINK_RETRY_MS until their `A` comes;
 * the receiver acknowledges every copy and takes a frame only when its
 * number is not the last one it took. A session starts with `H`, answered
 * by `W`: no reliable frame goes before.
 *
 * No heap, no stdio: a `semo_link` holds every buffer, sized here
 * (SEMO_LINK_PAYLOAD_MAX, SEMO_LINK_SEND_MAX and SEMO_LINK_QUEUE may be set
 * smaller for a board: a longer frame is refused by both sides). Not
 * thread-safe: the caller holds its lock around every call. Time is the
 * caller's (ms). */
#ifndef SEMO_LINK_H
#define SEMO_LINK_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* The longest payload this side takes (said in its H and W). */
#ifndef SEMO_LINK_PAYLOAD_MAX
#define SEMO_LINK_PAYLOAD_MAX 1536
#endif
/* The longest payload this side sends: a board's status may be longer than
 * anything it is sent, and the gateway takes up to 1536 bytes; only the
 * frames sent (the queue, link->wire) are sized by it. */
#ifndef SEMO_LINK_SEND_MAX
#define SEMO_LINK_SEND_MAX SEMO_LINK_PAYLOAD_MAX
#endif
/* Reliable frames waiting behind the one in flight. */
#ifndef SEMO_LINK_QUEUE
#define SEMO_LINK_QUEUE 4
#endif
/* H and W say it in two bytes. */
_Static_assert(SEMO_LINK_PAYLOAD_MAX >= 64 && SEMO_LINK_PAYLOAD_MAX <= 0xFFFF,
               "SEMO_LINK_PAYLOAD_MAX must be 64 to 65535");
/* A robot sends what it may be sent (its sends, the gateway's are alike)
 * and the gateway takes no longer. */
_Static_assert(SEMO_LINK_SEND_MAX >= SEMO_LINK_PAYLOAD_MAX && SEMO_LINK_SEND_MAX <= 1536,
               "SEMO_LINK_SEND_MAX must be SEMO_LINK_PAYLOAD_MAX to 1536");
/* A frame's bytes on the line, stuffed and closed, for a payload of `n`. */
#define SEMO_LINK_WIRE_FOR(n) ((3 + (n) + 2) + (3 + (n) + 2) / 254 + 1 + 1)
/* The longest frame received on the line, and sent. */
#define SEMO_LINK_WIRE_MAX SEMO_LINK_WIRE_FOR(SEMO_LINK_PAYLOAD_MAX)
#define SEMO_LINK_SEND_WIRE_MAX SEMO_LINK_WIRE_FOR(SEMO_LINK_SEND_MAX)
#define SEMO_LINK_RETRY_MS 200
#define SEMO_LINK_HELLO_RETRY_MS 500
/* A datagram's kind byte (its sixth) for a send (semo_runtime.h's SEMO_MSG_SEND). */
#define SEMO_LINK_DATAGRAM_SEND 's'
/* What an R says (its one byte): the message's datagram names another
 * sender or key than its topic; the message is longer than this side takes
 * (the payload bound its H or W said). */
#define SEMO_LINK_REFUSED_TOPIC 'T'
#define SEMO_LINK_REFUSED_LENGTH 'L'

enum {
    SEMO_LINK_HELLO = 'H',
    SEMO_LINK_WELCOME = 'W',
    SEMO_LINK_SEND = 'S',
    SEMO_LINK_PUBLISH = 'P',
    SEMO_LINK_STATUS = 'T',
    SEMO_LINK_MESSAGE = 'M',
    SEMO_LINK_REFUSED = 'R',
    SEMO_LINK_ACK = 'A',
};

/* Writes bytes to the line (all of them). */
typedef void (*semo_link_write)(void *ctx, const unsigned char *bytes, size_t n);

/* A frame handed to the caller: its payload lives in the link until the
 * next call. */
typedef struct {
    unsigned char kind;
    uint16_t seq;
    const unsigned char *payload;
    size_t len;
} semo_link_frame;

typedef struct {
    semo_link_write write;
    void *ctx;
    /* Receiving: the bytes since the last zero, decoded in place. */
    unsigned char rx[SEMO_LINK_WIRE_MAX];
    size_t rx_len;
    bool rx_overflow;
    bool rx_seen; /* a reliable frame was taken in this session: rx_last */
    uint16_t rx_last;
    /* Sending. */
    struct {
        unsigned char kind;
        size_t len;
        unsigned char payload[SEMO_LINK_SEND_MAX];
    } queue[SEMO_LINK_QUEUE + 1]; /* [tx_head] is in flight when tx_in_flight */
    size_t tx_head, tx_count;
    uint16_t tx_seq;
    bool tx_in_flight;
    int64_t tx_sent_at;
    bool welcomed;
    bool hello_sent;
    int64_t hello_at;
    unsigned char welcome_flags; /* what our Welcome says; what theirs said */
    unsigned char peer_flags;
    /* The longest payload the other side takes, as its H or W said
     * (SEMO_LINK_PAYLOAD_MAX until it has). Ours, SEMO_LINK_PAYLOAD_MAX, is
     * in each of our H and W: a board's may be smaller than the gateway's. */
    size_t peer_payload_max;
    unsigned char wire[SEMO_LINK_SEND_WIRE_MAX];
    /* Counted for the trace: frames that were no frame (CRC, stuffing,
     * length, kind), copies not taken, frames sent again, publishes lost
     * because no session stood (the line away, the gateway restarting). */
    unsigned long bad_frames, duplicates, retransmissions, lost;
} semo_link;

void semo_link_init(semo_link *link, semo_link_write write, void *ctx);
/* Queues a reliable frame whose payload is `a` then `b` (either may be
 * empty); -1 when it is too long or the queue is full. */
int semo_link_queue(semo_link *link, unsigned char kind, const void *a, size_t alen, const void *b, size_t blen);
/* The payload of the next reliable frame, to be written in place (at most
 * SEMO_LINK_SEND_MAX bytes: no second buffer for it) and queued by
 * semo_link_commit; NULL while the queue is full. A datagram written at
 * its place in the slot (after the length byte and the destination) may be
 * handed to semo_link_send_datagram from there. */
unsigned char *semo_link_slot(semo_link *link);
/* Queues the frame of kind `kind` whose `len` bytes were written in
 * semo_link_slot's slot; -1 when it is too long or the queue is full. */
int semo_link_commit(semo_link *link, unsigned char kind, size_t len);
/* The payload of the last frame queued, when it is of kind `kind` and
 * still waits (not on the line yet), to be written again in place and its
 * new length set by semo_link_rewrite; NULL otherwise. A newer status
 * takes the place of one that has not left. */
unsigned char *semo_link_waiting(semo_link *link, unsigned char kind);
/* The last frame queued (semo_link_waiting's) is now `len` bytes; -1 when
 * it is too long or none waits. */
int semo_link_rewrite(semo_link *link, size_t len);
/* Writes an unreliable frame (P) now; -1 when it is too long. */
int semo_link_emit(semo_link *link, unsigned char kind, const void *a, size_t alen, const void *b, size_t blen);
/* One byte from the line at time `now`: acknowledgements, hellos and
 * welcomes are handled here; returns true when `*out` holds a frame for the
 * caller (a new reliable frame, already acknowledged, or a P). */
bool semo_link_feed(semo_link *link, unsigned char byte, int64_t now, semo_link_frame *out);
/* Writes what is due at `now` (a hello, the next reliable frame, one sent
 * again). */
void semo_link_tick(semo_link *link, int64_t now);
/* When semo_link_tick next has something to do (INT64_MAX: only after a
 * frame is queued or heard). */
int64_t semo_link_deadline(const semo_link *link);
/* The line went away (and may come back): a new session starts with a
 * hello; what was not acknowledged goes again. */
void semo_link_restart(semo_link *link);
/* A datagram for `to` (a team, a robot or "USER"; a length byte then the
 * name lead the payload): reliably (S) when the datagram is a send, at once
 * (P) when it is a publish, which before the session stands is lost as at
 * QoS 0 (and counted, `lost`). What every transport over the link sends (semo_link_transport.c on
 * POSIX, semo_static_link.c on a board). 0 when queued or written, -1 when
 * it can never go (no name, too long), -2 while the queue is full: the
 * caller makes room (waits, or feeds the line) and asks again. */
int semo_link_send_datagram(semo_link *link, const char *to, const void *datagram, size_t len);
/* Reliable frames not yet acknowledged. */
size_t semo_link_pending(const semo_link *link);
uint16_t semo_link_crc16(const unsigned char *bytes, size_t n);

#endif
