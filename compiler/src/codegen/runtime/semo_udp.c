/* semo_udp.c: the loopback transport. The robot at place i of the mission
 * (`semo_peer::index`) owns UDP port `port_base + i` on 127.0.0.1; a message
 * to a robot is one
 * datagram to its port. Only local processes can reach a loopback port, and
 * without a run key every one of them is trusted. With one ($SEMO_UDP_KEY,
 * the same for every robot of a run) each datagram carries its HMAC-SHA256
 * under that key (RFC 2104, its 32 bytes after the runtime's datagram), and
 * recv refuses one whose tag is not right (SEMO_RECV_REFUSED): a process
 * that does not know the key can neither forge nor alter a message. Nor
 * replay one: between the datagram and its tag the sender writes its place
 * in the mission and a counter (both under the tag), the machine's monotonic clock
 * in ns when it sent, raised past the last it sent, and recv refuses
 * (SEMO_RECV_REPLAYED) a counter no later than the last taken from that
 * sender, or older than UDP_FRESH_NS (a capture replayed to a robot
 * restarted since). Loopback peers share one clock (CLOCK_MONOTONIC is
 * system-wide and never steps back). `semo::deploy::datagram::sign` is the
 * same on the Rust side.
 */
#define _POSIX_C_SOURCE 200809L

#include "semo_internal.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

static void udp_close(void);

/* Set by open before any thread uses the transport, cleared by close after
 * they are joined; the kernel serialises concurrent sendto/recv. */
static int g_fd = -1;
/* A pipe whose read end becomes readable when the program stops, so that
 * recv can wait on the socket without a timeout. */
static int g_wake[2] = {-1, -1};
static int g_port_base;
/* The program's peers, whose places give their ports. */
static const semo_peer *g_peers;
static size_t g_peer_count;
static size_t g_self;
/* The run key (none: g_key_len 0). */
static unsigned char g_key[SEMO_UDP_KEY_MAX];
static size_t g_key_len;
/* With a key: the last counter taken from each robot of the peer table, and
 * (the last slot) from senders outside it (the operator's console); the
 * last this robot sent. Only the receive thread reads and writes g_last;
 * g_sent is taken under g_sent_lock (every thread sends). */
static uint64_t *g_last;
static uint64_t g_sent;
static pthread_mutex_t g_sent_lock = PTHREAD_MUTEX_INITIALIZER;

/* ----------------------------------------------------------- HMAC-SHA256 */

#define SHA256_BLOCK 64
#define UDP_TAG 32 /* a SHA-256 digest */
/* The sender's peer index (u32) and counter (u64), little-endian, signed
 * with the datagram. */
#define UDP_STAMP 12
/* How old a counter may be when it arrives: far more than a datagram waits
 * in a loopback socket, far less than a robot takes to restart. */
#define UDP_FRESH_NS (5LL * 1000 * 1000 * 1000)

typedef struct {
    uint32_t h[8];
    unsigned char block[SHA256_BLOCK];
    size_t used;     /* bytes in block */
    uint64_t length; /* bytes hashed */
} sha256;

static const uint32_t sha256_k[64] = {
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5,
    0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174,
    0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
    0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967,
    0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
    0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
    0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
    0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2,
};

static uint32_t rotr(uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }

static void sha256_block(sha256 *s, const unsigned char *p)
{
    uint32_t w[64];
    for (int i = 0; i < 16; i++)
        w[i] = (uint32_t)p[4 * i] << 24 | (uint32_t)p[4 * i + 1] << 16 | (uint32_t)p[4 * i + 2] << 8 | p[4 * i + 3];
    for (int i = 16; i < 64; i++) {
        uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
        uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
        w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    uint32_t a = s->h[0], b = s->h[1], c = s->h[2], d = s->h[3], e = s->h[4], f = s->h[5], g = s->h[6],
             h = s->h[7];
    for (int i = 0; i < 64; i++) {
        uint32_t t1 = h + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25)) + ((e & f) ^ (~e & g)) + sha256_k[i] + w[i];
        uint32_t t2 = (rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22)) + ((a & b) ^ (a & c) ^ (b & c));
        h = g;
        g = f;
        f = e;
        e = d + t1;
        d = c;
        c = b;
        b = a;
        a = t1 + t2;
    }
    s->h[0] += a;
    s->h[1] += b;
    s->h[2] += c;
    s->h[3] += d;
    s->h[4] += e;
    s->h[5] += f;
    s->h[6] += g;
    s->h[7] += h;
}

static void sha256_init(sha256 *s)
{
    static const uint32_t h0[8] = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                                   0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
    memcpy(s->h, h0, sizeof h0);
    s->used = 0;
    s->length = 0;
}

static void sha256_add(sha256 *s, const unsigned char *p, size_t n)
{
    s->length += n;
    while (n > 0) {
        size_t take = SHA256_BLOCK - s->used < n ? SHA256_BLOCK - s->used : n;
        memcpy(s->block + s->used, p, take);
        s->used += take;
        p += take;
        n -= take;
        if (s->used == SHA256_BLOCK) {
            sha256_block(s, s->block);
            s->used = 0;
        }
    }
}

static void sha256_end(sha256 *s, unsigned char out[UDP_TAG])
{
    uint64_t bits = s->length * 8;
    unsigned char pad[SHA256_BLOCK + 8] = {0x80};
    size_t zeros = (s->used < 56 ? 56 : 120) - s->used;
    for (int i = 0; i < 8; i++)
        pad[zeros + (size_t)i] = (unsigned char)(bits >> (56 - 8 * i));
    sha256_add(s, pad, zeros + 8);
    for (int i = 0; i < 8; i++)
        for (int j = 0; j < 4; j++)
            out[4 * i + j] = (unsigned char)(s->h[i] >> (24 - 8 * j));
}

/* HMAC-SHA256 of `data` under the run key (shorter than a block). */
static void udp_tag(const unsigned char *data, size_t len, unsigned char tag[UDP_TAG])
{
    unsigned char pad[SHA256_BLOCK];
    sha256 s;
    memset(pad, 0x36, sizeof pad);
    for (size_t i = 0; i < g_key_len; i++)
        pad[i] ^= g_key[i];
    sha256_init(&s);
    sha256_add(&s, pad, sizeof pad);
    sha256_add(&s, data, len);
    unsigned char inner[UDP_TAG];
    sha256_end(&s, inner);
    for (size_t i = 0; i < sizeof pad; i++)
        pad[i] ^= 0x36 ^ 0x5c;
    sha256_init(&s);
    sha256_add(&s, pad, sizeof pad);
    sha256_add(&s, inner, sizeof inner);
    sha256_end(&s, tag);
}

/* Whether the last UDP_TAG bytes of `data` are its tag, compared in time
 * that does not depend on where they differ. */
static bool udp_tag_right(const unsigned char *data, size_t len)
{
    if (len < UDP_TAG)
        return false;
    unsigned char tag[UDP_TAG];
    udp_tag(data, len - UDP_TAG, tag);
    unsigned char differ = 0;
    for (size_t i = 0; i < UDP_TAG; i++)
        differ |= (unsigned char)(tag[i] ^ data[len - UDP_TAG + i]);
    return differ == 0;
}

/* The machine's monotonic clock, ns: what a counter is. */
static uint64_t udp_clock_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

/* The next counter this robot sends: the clock, or one past the last sent
 * when the clock has not moved since. */
static uint64_t udp_next_counter(void)
{
    uint64_t now = udp_clock_ns();
    pthread_mutex_lock(&g_sent_lock);
    g_sent = now > g_sent ? now : g_sent + 1;
    uint64_t counter = g_sent;
    pthread_mutex_unlock(&g_sent_lock);
    return counter;
}

static void put_le(unsigned char *at, uint64_t v, int bytes)
{
    for (int i = 0; i < bytes; i++)
        at[i] = (unsigned char)(v >> (8 * i));
}

static uint64_t get_le(const unsigned char *at, int bytes)
{
    uint64_t v = 0;
    for (int i = 0; i < bytes; i++)
        v |= (uint64_t)at[i] << (8 * i);
    return v;
}

/* Whether a signed datagram's stamp (`stamp`, UDP_STAMP bytes) is newer
 * than the last taken from its sender and fresh; if so it is the last now. */
static bool udp_stamp_fresh(const unsigned char *stamp)
{
    uint64_t sender = get_le(stamp, 4), counter = get_le(stamp + 4, 8);
    /* The sender names its place in the mission (`semo_peer.index`): each
     * robot's table lists only its peers, so positions differ between
     * robots; a place not in the table is an outsider's. The table is in
     * ascending places (`program_is_valid`): a binary search, so a robot of
     * a large team pays log n per datagram, not n. */
    size_t slot = g_peer_count, low = 0, high = g_peer_count;
    while (low < high) {
        size_t middle = low + (high - low) / 2;
        if (g_peers[middle].index < sender) {
            low = middle + 1;
        } else {
            if (g_peers[middle].index == sender)
                slot = middle;
            high = middle;
        }
    }
    uint64_t now = udp_clock_ns();
    if (counter <= g_last[slot] || counter + UDP_FRESH_NS < now)
        return false;
    g_last[slot] = counter;
    return true;
}

static struct sockaddr_in loopback(int port)
{
    struct sockaddr_in addr;
    memset(&addr, 0, sizeof addr);
    addr.sin_family = AF_INET;
    addr.sin_port = htons((uint16_t)port);
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    return addr;
}

static int udp_open(const semo_program_desc *program, const semo_transport_config *config)
{
    long port_base = config->port_base;
    if (g_fd >= 0 || program->self >= program->peer_count || port_base < 1 ||
        (long)port_base + (long)program->robot_count > 65536)
        return -1;
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    if (fd < 0)
        return -1;
    /* Child processes (a task running a helper) must not inherit the port. */
    fcntl(fd, F_SETFD, FD_CLOEXEC);
    struct sockaddr_in self = loopback((int)port_base + (int)program->peers[program->self].index);
    if (bind(fd, (const struct sockaddr *)&self, sizeof self) != 0 || pipe(g_wake) != 0) {
        close(fd);
        return -1;
    }
    for (int i = 0; i < 2; i++) {
        fcntl(g_wake[i], F_SETFD, FD_CLOEXEC);
        fcntl(g_wake[i], F_SETFL, O_NONBLOCK);
    }
    g_fd = fd;
    g_port_base = (int)port_base;
    g_peers = program->peers;
    g_peer_count = program->peer_count;
    g_self = program->self;
    g_key_len = config->udp_key_len <= sizeof g_key ? config->udp_key_len : 0;
    if (g_key_len > 0) {
        memcpy(g_key, config->udp_key, g_key_len);
        g_last = calloc(g_peer_count + 1, sizeof *g_last);
        if (g_last == NULL) {
            udp_close();
            return -1;
        }
    }
    return 0;
}

static int udp_send(size_t peer, const void *data, size_t len)
{
    if (g_fd < 0 || peer >= g_peer_count)
        return -1;
    unsigned char signed_data[SEMO__DATAGRAM_MAX + UDP_STAMP + UDP_TAG];
    if (g_key_len > 0) {
        if (len > SEMO__DATAGRAM_MAX)
            return -1;
        memcpy(signed_data, data, len);
        put_le(signed_data + len, g_peers[g_self].index, 4);
        put_le(signed_data + len + 4, udp_next_counter(), 8);
        len += UDP_STAMP;
        udp_tag(signed_data, len, signed_data + len);
        data = signed_data;
        len += UDP_TAG;
    }
    struct sockaddr_in to = loopback(g_port_base + (int)g_peers[peer].index);
    ssize_t n;
    do
        n = sendto(g_fd, data, len, 0, (const struct sockaddr *)&to, sizeof to);
    while (n < 0 && errno == EINTR);
    /* A peer that is not running yet refuses nothing over UDP: the datagram
     * is simply lost, as it would be on a real network. */
    return n == (ssize_t)len ? 0 : -1;
}

static int udp_recv(void *data, size_t cap, int timeout_ms)
{
    if (g_fd < 0)
        return -1;
    struct pollfd pfd[2] = {{.fd = g_fd, .events = POLLIN}, {.fd = g_wake[0], .events = POLLIN}};
    int ready = poll(pfd, 2, timeout_ms < 0 ? -1 : timeout_ms);
    if (ready < 0)
        return errno == EINTR ? 0 : -1;
    if (ready == 0 || pfd[1].revents != 0)
        return 0;
    /* With a key, the datagram, its stamp and its tag, and a spare byte (a
     * longer one is cut short, and then its tag is wrong). */
    unsigned char wire[SEMO__DATAGRAM_MAX + UDP_STAMP + UDP_TAG + 1];
    ssize_t n = recv(g_fd, g_key_len > 0 ? wire : data, g_key_len > 0 ? sizeof wire : cap, 0);
    if (n < 0)
        return errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK || errno == ECONNREFUSED ? 0 : -1;
    if (g_key_len == 0)
        return (int)n;
    if ((size_t)n < UDP_STAMP + UDP_TAG || !udp_tag_right(wire, (size_t)n))
        return SEMO_RECV_REFUSED;
    size_t len = (size_t)n - UDP_TAG - UDP_STAMP;
    if (!udp_stamp_fresh(wire + len))
        return SEMO_RECV_REPLAYED;
    memcpy(data, wire, len < cap ? len : cap);
    return (int)(len < cap ? len : cap);
}

static void udp_interrupt(void)
{
    if (g_wake[1] >= 0) {
        ssize_t written = write(g_wake[1], "x", 1); /* a full pipe is awake already */
        (void)written;
    }
}

static void udp_close(void)
{
    if (g_fd >= 0)
        close(g_fd);
    for (int i = 0; i < 2; i++) {
        if (g_wake[i] >= 0)
            close(g_wake[i]);
        g_wake[i] = -1;
    }
    g_fd = -1;
    g_peers = NULL;
    g_peer_count = 0;
    free(g_last);
    g_last = NULL;
}

const semo_transport semo_udp_transport = {
    .name = "udp",
    .refusal = "not signed with the run's key",
    .open = udp_open,
    .send = udp_send,
    .recv = udp_recv,
    .interrupt = udp_interrupt,
    .close = udp_close,
};
