/* send → receive latency through an MQTT broker, as generated robots see
 * it: two processes, each opening the runtime's MQTT transport
 * (semo_mqtt.c, unchanged: QoS 1, persistent session, TCP_NODELAY); robot
 * `a` sends robot `b` one datagram per millisecond carrying the time it was
 * sent (CLOCK_MONOTONIC is one clock for every process of the machine), and
 * `b` measures when its transport hands it over.
 *
 * usage: mqtt_latency PORT COUNT   (prints "median_us p99_us max_us") */
#define _POSIX_C_SOURCE 200809L
#include "semo_runtime.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static const semo_peer peers[] = {{"Bench", "a"}, {"Bench", "b"}};

static int64_t now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000000 + t.tv_nsec;
}

static int open_as(size_t self, int port)
{
    static semo_program_desc program;
    program = (semo_program_desc){
        .mission = "bench.mission", .team = "Bench", .robot = peers[self].robot, .peers = peers, .peer_count = 2, .self = self};
    semo_transport_config config = {.broker_host = "127.0.0.1", .broker_port = port};
    return semo_mqtt_transport.open(&program, &config);
}

/* The runtime's datagram (semo_internal.h; semo__encode_message is not
 * linked here, the bench has no program around the transport): "SEMO" 0x02
 * `s`, three fields, then the value, typed: SEMO_INT and 8 bytes big-endian. */
static size_t datagram(unsigned char *out, int64_t value)
{
    const char *fields[] = {"Bench", "a", "Bench.t"};
    size_t n = 0;
    memcpy(out, "SEMO\x02s", 6);
    n = 6;
    for (int i = 0; i < 3; i++) {
        size_t len = strlen(fields[i]);
        out[n++] = (unsigned char)len;
        memcpy(out + n, fields[i], len);
        n += len;
    }
    out[n++] = SEMO_INT;
    for (int shift = 56; shift >= 0; shift -= 8)
        out[n++] = (unsigned char)((uint64_t)value >> shift);
    return n;
}

static int compare(const void *x, const void *y)
{
    int64_t a = *(const int64_t *)x, b = *(const int64_t *)y;
    return (a > b) - (a < b);
}

int main(int argc, char **argv)
{
    if (argc != 3)
        return 2;
    int port = atoi(argv[1]);
    long count = atol(argv[2]);
    int ready[2];
    if (count <= 0 || pipe(ready) != 0)
        return 2;
    pid_t sender = fork();
    if (sender == 0) {
        char go;
        if (read(ready[0], &go, 1) != 1 || open_as(0, port) != 0)
            _exit(1);
        for (long i = 0; i < count; i++) {
            unsigned char data[64];
            size_t len = datagram(data, now_ns());
            if (semo_mqtt_transport.send_to("b", data, len) != 0)
                _exit(1);
            struct timespec pause = {0, 1000000};
            nanosleep(&pause, NULL);
        }
        semo_mqtt_transport.close();
        _exit(0);
    }
    /* The receiver subscribes first, then lets the sender start. */
    if (open_as(1, port) != 0 || write(ready[1], "g", 1) != 1)
        return 1;
    int64_t *latency = calloc((size_t)count, sizeof *latency);
    long got = 0;
    while (got < count) {
        unsigned char data[2048];
        int n = semo_mqtt_transport.recv(data, sizeof data, 10000);
        if (n <= 0)
            break;
        int64_t at = now_ns();
        /* The value is last: SEMO_INT and the time in 8 bytes big-endian. */
        if (n < 9 || data[n - 9] != SEMO_INT)
            break;
        uint64_t sent = 0;
        for (int i = n - 8; i < n; i++)
            sent = sent << 8 | data[i];
        latency[got++] = at - (int64_t)sent;
    }
    int status = 1;
    waitpid(sender, &status, 0);
    semo_mqtt_transport.close();
    if (got < count) {
        fprintf(stderr, "received %ld of %ld\n", got, count);
        return 1;
    }
    qsort(latency, (size_t)count, sizeof *latency, compare);
    printf("%.1f %.1f %.1f\n", latency[count / 2] / 1000.0, latency[count * 99 / 100] / 1000.0,
           latency[count - 1] / 1000.0);
    free(latency);
    return status == 0 ? 0 : 1;
}
