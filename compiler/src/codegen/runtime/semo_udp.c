/* semo_udp.c: the loopback transport. Robot i of the mission's peer table
 * owns UDP port `port_base + i` on 127.0.0.1; a message to a robot is one
 * datagram to its port. Only local processes can reach a loopback port.
 */
#define _POSIX_C_SOURCE 200809L

#include "semo_runtime.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

/* Set by open before any thread uses the transport, cleared by close after
 * they are joined; the kernel serialises concurrent sendto/recv. */
static int g_fd = -1;
/* A pipe whose read end becomes readable when the program stops, so that
 * recv can wait on the socket without a timeout. */
static int g_wake[2] = {-1, -1};
static int g_port_base;
static size_t g_peer_count;

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
        (long)port_base + (long)program->peer_count > 65536)
        return -1;
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    if (fd < 0)
        return -1;
    /* Child processes (a task running a helper) must not inherit the port. */
    fcntl(fd, F_SETFD, FD_CLOEXEC);
    struct sockaddr_in self = loopback((int)port_base + (int)program->self);
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
    g_peer_count = program->peer_count;
    return 0;
}

static int udp_send(size_t peer, const void *data, size_t len)
{
    if (g_fd < 0 || peer >= g_peer_count)
        return -1;
    struct sockaddr_in to = loopback(g_port_base + (int)peer);
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
    ssize_t n = recv(g_fd, data, cap, 0);
    if (n < 0)
        return errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK || errno == ECONNREFUSED ? 0 : -1;
    return (int)n;
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
    g_peer_count = 0;
}

const semo_transport semo_udp_transport = {
    .name = "udp",
    .open = udp_open,
    .send = udp_send,
    .recv = udp_recv,
    .interrupt = udp_interrupt,
    .close = udp_close,
};
