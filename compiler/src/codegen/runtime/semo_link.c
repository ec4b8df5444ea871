/* semo_link.c: the serial link's frames and sessions (semo_link.h,
 * docs/link.md). No heap, no stdio: every buffer is the link's. */
#include "semo_link.h"

#include <string.h>

uint16_t semo_link_crc16(const unsigned char *bytes, size_t n)
{
    uint16_t crc = 0xFFFF;
    for (size_t i = 0; i < n; i++) {
        crc ^= (uint16_t)(bytes[i] << 8);
        for (int b = 0; b < 8; b++)
            crc = (crc & 0x8000) ? (uint16_t)((crc << 1) ^ 0x1021) : (uint16_t)(crc << 1);
    }
    return crc;
}

void semo_link_init(semo_link *link, semo_link_write write, void *ctx)
{
    memset(link, 0, sizeof *link);
    link->write = write;
    link->ctx = ctx;
    link->peer_payload_max = SEMO_LINK_PAYLOAD_MAX;
}

/* The payload bound our H and W say, big-endian. */
static const unsigned char g_payload_max[2] = {(unsigned char)(SEMO_LINK_PAYLOAD_MAX >> 8),
                                               (unsigned char)SEMO_LINK_PAYLOAD_MAX};

/* Stuffs the body (kind, seq, the payload's `count` pieces in order, CRC)
 * into link->wire and writes it with its closing zero. */
static void write_pieces(semo_link *link, unsigned char kind, uint16_t seq, const unsigned char *const *pieces,
                         const size_t *lens, int count)
{
    unsigned char head[3] = {kind, (unsigned char)(seq >> 8), (unsigned char)seq};
    uint16_t crc = 0xFFFF;
    /* The CRC over the pieces, as semo_link_crc16 over their concatenation. */
    for (int p = -1; p < count; p++) {
        const unsigned char *bytes = p < 0 ? head : pieces[p];
        size_t n = p < 0 ? 3 : lens[p];
        for (size_t i = 0; i < n; i++) {
            crc ^= (uint16_t)(bytes[i] << 8);
            for (int k = 0; k < 8; k++)
                crc = (crc & 0x8000) ? (uint16_t)((crc << 1) ^ 0x1021) : (uint16_t)(crc << 1);
        }
    }
    unsigned char tail[2] = {(unsigned char)(crc >> 8), (unsigned char)crc};
    size_t out = 0, code_at = out++;
    unsigned char code = 1;
    for (int p = -1; p <= count; p++) {
        const unsigned char *bytes = p < 0 ? head : p == count ? tail : pieces[p];
        size_t n = p < 0 ? 3 : p == count ? 2 : lens[p];
        for (size_t i = 0; i < n; i++) {
            unsigned char byte = bytes[i];
            if (byte == 0) {
                link->wire[code_at] = code;
                code_at = out++;
                code = 1;
            } else {
                link->wire[out++] = byte;
                if (++code == 0xFF) {
                    link->wire[code_at] = code;
                    code_at = out++;
                    code = 1;
                }
            }
        }
    }
    link->wire[code_at] = code;
    link->wire[out++] = 0;
    link->write(link->ctx, link->wire, out);
}

static void write_frame(semo_link *link, unsigned char kind, uint16_t seq, const unsigned char *a, size_t alen,
                        const unsigned char *b, size_t blen)
{
    const unsigned char *pieces[2] = {a, b};
    size_t lens[2] = {alen, blen};
    write_pieces(link, kind, seq, pieces, lens, 2);
}

unsigned char *semo_link_slot(semo_link *link)
{
    if (link->tx_count >= SEMO_LINK_QUEUE + 1)
        return NULL;
    return link->queue[(link->tx_head + link->tx_count) % (SEMO_LINK_QUEUE + 1)].payload;
}

int semo_link_commit(semo_link *link, unsigned char kind, size_t len)
{
    if (len > SEMO_LINK_SEND_MAX || link->tx_count >= SEMO_LINK_QUEUE + 1)
        return -1;
    size_t slot = (link->tx_head + link->tx_count) % (SEMO_LINK_QUEUE + 1);
    link->queue[slot].kind = kind;
    link->queue[slot].len = len;
    link->tx_count++;
    return 0;
}

/* The last frame queued, if it is not on the line yet: -1 when none. */
static int last_waiting(const semo_link *link)
{
    if (link->tx_count == 0 || (link->tx_count == 1 && link->tx_in_flight))
        return -1;
    return (int)((link->tx_head + link->tx_count - 1) % (SEMO_LINK_QUEUE + 1));
}

unsigned char *semo_link_waiting(semo_link *link, unsigned char kind)
{
    int last = last_waiting(link);
    return last >= 0 && link->queue[last].kind == kind ? link->queue[last].payload : NULL;
}

int semo_link_rewrite(semo_link *link, size_t len)
{
    int last = last_waiting(link);
    if (last < 0 || len > SEMO_LINK_SEND_MAX)
        return -1;
    link->queue[last].len = len;
    return 0;
}

int semo_link_queue(semo_link *link, unsigned char kind, const void *a, size_t alen, const void *b, size_t blen)
{
    unsigned char *slot = semo_link_slot(link);
    if (alen + blen > SEMO_LINK_SEND_MAX || !slot)
        return -1;
    if (alen)
        memcpy(slot, a, alen);
    if (blen)
        memcpy(slot + alen, b, blen);
    return semo_link_commit(link, kind, alen + blen);
}

int semo_link_emit(semo_link *link, unsigned char kind, const void *a, size_t alen, const void *b, size_t blen)
{
    if (alen + blen > SEMO_LINK_SEND_MAX)
        return -1;
    write_frame(link, kind, 0, a, alen, b, blen);
    return 0;
}

int semo_link_send_datagram(semo_link *link, const char *to, const void *datagram, size_t len)
{
    size_t to_len = strlen(to);
    /* The kind is the datagram's sixth byte ("SEMO" 0x02 <kind>). */
    if (len < 6 || to_len == 0 || to_len > 255 || 1 + to_len + len > SEMO_LINK_SEND_MAX)
        return -1;
    unsigned char head[1] = {(unsigned char)to_len};
    if (((const unsigned char *)datagram)[5] != SEMO_LINK_DATAGRAM_SEND) {
        if (!link->welcomed) {
            link->lost++;
            return 0;
        }
        const unsigned char *pieces[3] = {head, (const unsigned char *)to, (const unsigned char *)datagram};
        size_t lens[3] = {1, to_len, len};
        write_pieces(link, SEMO_LINK_PUBLISH, 0, pieces, lens, 3);
        return 0;
    }
    unsigned char *slot = semo_link_slot(link);
    if (!slot)
        return -2;
    /* Straight into the queue's slot: no second copy of the payload. The
     * datagram may be there already (semo_link_slot): memmove. */
    memmove(slot + 1 + to_len, datagram, len);
    slot[0] = head[0];
    memcpy(slot + 1, to, to_len);
    return semo_link_commit(link, SEMO_LINK_SEND, 1 + to_len + len);
}

static void send_in_flight(semo_link *link, int64_t now)
{
    link->tx_sent_at = now;
    write_frame(link, link->queue[link->tx_head].kind, link->tx_seq, link->queue[link->tx_head].payload,
                link->queue[link->tx_head].len, NULL, 0);
}

void semo_link_tick(semo_link *link, int64_t now)
{
    if (!link->welcomed) {
        if (!link->hello_sent || now >= link->hello_at + SEMO_LINK_HELLO_RETRY_MS) {
            link->hello_sent = true;
            link->hello_at = now;
            write_frame(link, SEMO_LINK_HELLO, 0, g_payload_max, 2, NULL, 0);
        }
        return;
    }
    if (link->tx_in_flight) {
        if (now >= link->tx_sent_at + SEMO_LINK_RETRY_MS) {
            link->retransmissions++;
            send_in_flight(link, now);
        }
        return;
    }
    if (link->tx_count > 0) {
        link->tx_in_flight = true;
        send_in_flight(link, now);
    }
}

int64_t semo_link_deadline(const semo_link *link)
{
    if (!link->welcomed)
        return link->hello_sent ? link->hello_at + SEMO_LINK_HELLO_RETRY_MS : 0;
    if (link->tx_in_flight)
        return link->tx_sent_at + SEMO_LINK_RETRY_MS;
    return link->tx_count > 0 ? 0 : INT64_MAX;
}

void semo_link_restart(semo_link *link)
{
    link->welcomed = false;
    link->hello_sent = false;
    link->tx_sent_at = INT64_MIN / 2; /* due at once once welcomed */
    link->rx_len = 0;
    link->rx_overflow = false;
}

size_t semo_link_pending(const semo_link *link)
{
    return link->tx_count;
}

static bool reliable(unsigned char kind)
{
    return kind == SEMO_LINK_SEND || kind == SEMO_LINK_STATUS || kind == SEMO_LINK_MESSAGE ||
           kind == SEMO_LINK_REFUSED;
}

/* Whether the payload has its kind's shape (semo::link's `fits`). */
static bool fits(unsigned char kind, const unsigned char *p, size_t len)
{
    switch (kind) {
    case SEMO_LINK_ACK:
        return len == 0;
    case SEMO_LINK_REFUSED:
        return len == 1;
    case SEMO_LINK_HELLO:
        return len == 2;
    case SEMO_LINK_WELCOME:
        return len == 3;
    case SEMO_LINK_SEND:
    case SEMO_LINK_PUBLISH:
        return len >= 1 && p[0] >= 1 && (size_t)p[0] <= len - 1;
    case SEMO_LINK_STATUS:
    case SEMO_LINK_MESSAGE:
        return len >= 1;
    default:
        return false;
    }
}

/* Unstuffs link->rx in place; the body's length, or 0 when it is no
 * stuffing. */
static size_t unstuff(semo_link *link)
{
    size_t in = 0, out = 0, n = link->rx_len;
    unsigned char *b = link->rx;
    while (in < n) {
        size_t code = b[in];
        if (code == 0 || in + code > n)
            return 0;
        for (size_t i = 1; i < code; i++)
            b[out++] = b[in + i];
        in += code;
        if (code < 0xFF && in < n)
            b[out++] = 0;
    }
    return out;
}

bool semo_link_feed(semo_link *link, unsigned char byte, int64_t now, semo_link_frame *out)
{
    if (byte != 0) {
        if (link->rx_len + 1 < SEMO_LINK_WIRE_MAX)
            link->rx[link->rx_len++] = byte;
        else
            link->rx_overflow = true;
        return false;
    }
    bool overflow = link->rx_overflow;
    size_t stuffed = link->rx_len;
    link->rx_len = 0;
    link->rx_overflow = false;
    if (overflow) {
        link->bad_frames++;
        return false;
    }
    if (stuffed == 0)
        return false;
    link->rx_len = stuffed;
    size_t n = unstuff(link);
    link->rx_len = 0;
    if (n < 5 || semo_link_crc16(link->rx, n - 2) != (uint16_t)((link->rx[n - 2] << 8) | link->rx[n - 1])) {
        link->bad_frames++;
        return false;
    }
    unsigned char kind = link->rx[0];
    uint16_t seq = (uint16_t)((link->rx[1] << 8) | link->rx[2]);
    const unsigned char *payload = link->rx + 3;
    size_t len = n - 5;
    if (!fits(kind, payload, len)) {
        link->bad_frames++;
        return false;
    }
    switch (kind) {
    case SEMO_LINK_ACK:
        if (link->tx_in_flight && seq == link->tx_seq) {
            link->tx_in_flight = false;
            link->tx_head = (link->tx_head + 1) % (SEMO_LINK_QUEUE + 1);
            link->tx_count--;
            link->tx_seq++;
            semo_link_tick(link, now);
        }
        return false;
    case SEMO_LINK_HELLO:
        /* The other side (re)started: its numbers start again, and what we
         * have in flight goes again at once. */
        link->rx_seen = false;
        link->peer_payload_max = (size_t)((payload[0] << 8) | payload[1]);
        write_frame(link, SEMO_LINK_WELCOME, seq, &link->welcome_flags, 1, g_payload_max, 2);
        if (link->tx_in_flight)
            link->tx_sent_at = INT64_MIN / 2;
        semo_link_tick(link, now);
        return false;
    case SEMO_LINK_WELCOME:
        if (!link->welcomed) {
            link->welcomed = true;
            link->peer_flags = payload[0];
            link->peer_payload_max = (size_t)((payload[1] << 8) | payload[2]);
            semo_link_tick(link, now);
        }
        return false;
    default:
        break;
    }
    if (reliable(kind)) {
        write_frame(link, SEMO_LINK_ACK, seq, NULL, 0, NULL, 0);
        if (link->rx_seen && link->rx_last == seq) {
            link->duplicates++;
            return false;
        }
        link->rx_seen = true;
        link->rx_last = seq;
    }
    out->kind = kind;
    out->seq = seq;
    out->payload = payload;
    out->len = len;
    return true;
}
