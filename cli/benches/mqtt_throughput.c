/* Messages per second through an MQTT broker with many robots: ROBOTS
 * processes, each opening the runtime's MQTT transport (semo_mqtt.c,
 * unchanged) as one robot of a team of ROBOTS, publish to their team at
 * RATE Hz for SECONDS (a `publish`: QoS 0, retained, to
 * semo/<mission>/<run>/<team>/<key>/<team>/<robot>, which the broker fans out to every other
 * robot), and count what their transport hands them from the others.
 *
 * usage: mqtt_throughput PORT ROBOTS RATE SECONDS
 * prints "published delivered expected wall_seconds" */
#define _POSIX_C_SOURCE 200809L
#include "semo_runtime.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define MAX_ROBOTS 256

static semo_peer peers[MAX_ROBOTS];
static char names[MAX_ROBOTS][16];

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec / 1e9;
}

static size_t datagram(unsigned char *out, const char *robot, const char *value)
{
    const char *fields[] = {"Bench", robot, "Bench.POSITION", value};
    memcpy(out, "SEMO\x01p", 6);
    size_t n = 6;
    for (int i = 0; i < 4; i++) {
        size_t len = strlen(fields[i]);
        out[n++] = (unsigned char)len;
        memcpy(out + n, fields[i], len);
        n += len;
    }
    return n;
}

/* One robot: opens the transport, says it is ready, waits for the start,
 * publishes `rate` times a second for `seconds` while counting what
 * arrives from the others, keeps counting one more second, and writes its
 * count to `report`. */
static int robot(size_t self, size_t count, int port, int rate, int seconds, int ready, int go, int report)
{
    static semo_program_desc program;
    program = (semo_program_desc){.mission = "throughput.mission", .team = "Bench", .robot = peers[self].robot,
                                  .peers = peers, .peer_count = count, .self = self};
    semo_transport_config config = {.broker_host = "127.0.0.1", .broker_port = port};
    if (semo_mqtt_transport.open(&program, &config) != 0)
        return 1;
    char byte = 'r';
    if (write(ready, &byte, 1) != 1 || read(go, &byte, 1) != 1)
        return 1;
    long published = 0, received = 0;
    double start = now_s(), period = 1.0 / rate, end = start + seconds, drain = end + 1.0;
    double next = start + period * ((double)self / (double)count); /* spread over the period */
    for (;;) {
        double now = now_s();
        if (now >= drain)
            break;
        if (now >= next && now < end) {
            char value[32];
            snprintf(value, sizeof value, "%ld", published);
            unsigned char data[128];
            size_t len = datagram(data, peers[self].robot, value);
            if (semo_mqtt_transport.send_to("Bench", data, len) == 0)
                published++;
            next += period;
            continue;
        }
        double until = now < end && next < drain ? next : drain;
        int wait_ms = (int)((until - now) * 1000.0) + 1;
        unsigned char data[2048];
        int n = semo_mqtt_transport.recv(data, sizeof data, wait_ms);
        /* From another robot: the robot field (the second) is not ours. */
        if (n > 7) {
            size_t team_len = data[6];
            size_t at = 7 + team_len;
            if (at < (size_t)n) {
                size_t len = data[at];
                const char *me = peers[self].robot;
                if (!(len == strlen(me) && at + 1 + len <= (size_t)n && memcmp(data + at + 1, me, len) == 0))
                    received++;
            }
        }
    }
    semo_mqtt_transport.close();
    char line[64];
    int len = snprintf(line, sizeof line, "%ld %ld\n", published, received);
    return write(report, line, (size_t)len) == len ? 0 : 1;
}

int main(int argc, char **argv)
{
    if (argc != 5)
        return 2;
    int port = atoi(argv[1]);
    int count = atoi(argv[2]), rate = atoi(argv[3]), seconds = atoi(argv[4]);
    int ready[2], go[2], report[2];
    if (count < 2 || count > MAX_ROBOTS || rate <= 0 || seconds <= 0 || pipe(ready) || pipe(go) || pipe(report))
        return 2;
    for (int i = 0; i < count; i++) {
        snprintf(names[i], sizeof names[i], "r%d", i);
        peers[i] = (semo_peer){"Bench", names[i]};
    }
    for (int i = 0; i < count; i++) {
        pid_t child = fork();
        if (child < 0)
            return 1;
        if (child == 0)
            _exit(robot((size_t)i, (size_t)count, port, rate, seconds, ready[1], go[0], report[1]));
    }
    /* Every robot is connected and subscribed: start them together. */
    char byte;
    for (int i = 0; i < count; i++)
        if (read(ready[0], &byte, 1) != 1)
            return 1;
    double start = now_s();
    for (int i = 0; i < count; i++)
        if (write(go[1], "g", 1) != 1)
            return 1;
    close(report[1]);
    long published = 0, delivered = 0;
    FILE *lines = fdopen(report[0], "r");
    long p, d;
    int reported = 0;
    while (lines && fscanf(lines, "%ld %ld", &p, &d) == 2) {
        published += p;
        delivered += d;
        reported++;
    }
    int failed = 0;
    for (int i = 0; i < count; i++) {
        int status = 1;
        wait(&status);
        failed += !(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    }
    double wall = now_s() - start - 1.0; /* the publishing part */
    if (failed || reported != count) {
        fprintf(stderr, "%d of %d robots failed\n", failed, count);
        return 1;
    }
    printf("%ld %ld %ld %.3f\n", published, delivered, published * (count - 1), wall);
    return 0;
}
