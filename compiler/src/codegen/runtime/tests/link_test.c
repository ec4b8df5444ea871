/* link_test.c: one side of the serial link (semo_link.c) driven line by line
 * from standard input, for `tests/link.rs`, which is the other side in Rust:
 *   t MS          the time is now MS: write what is due
 *   b HEX         bytes from the line
 *   q KIND HEX    queue a reliable frame;   e KIND HEX   write an unreliable one
 *   w KIND HEX    write the last queued frame again in place, if of KIND and
 *                 not on the line yet (`none` otherwise)
 *   f FLAGS       what our Welcome says
 *   d TO HEX      semo_link_send_datagram of the datagram HEX to TO
 *   r             the line went away (semo_link_restart)
 *   s             print the counters
 * Every byte written to the line is printed `wire HEX`, every frame taken
 * `take KIND SEQ HEX`; each command ends with a line `.`. */
#include "../semo_link.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void hex_out(const unsigned char *b, size_t n)
{
    for (size_t i = 0; i < n; i++)
        printf("%02x", b[i]);
}

static void on_write(void *ctx, const unsigned char *bytes, size_t n)
{
    (void)ctx;
    printf("wire ");
    hex_out(bytes, n);
    printf("\n");
}

static size_t hex_in(const char *text, unsigned char *out, size_t cap)
{
    size_t n = 0;
    while (text[0] && text[1] && n < cap) {
        unsigned v;
        if (sscanf(text, "%2x", &v) != 1)
            break;
        out[n++] = (unsigned char)v;
        text += 2;
    }
    return n;
}

static semo_link g_link;
static unsigned char g_buf[1 << 16];

int main(void)
{
    semo_link_init(&g_link, on_write, NULL);
    static char line[1 << 18];
    long long now = 0;
    printf("payload_max %d\n.\n", SEMO_LINK_PAYLOAD_MAX);
    fflush(stdout);
    while (fgets(line, sizeof line, stdin)) {
        line[strcspn(line, "\n")] = '\0';
        char kind = 0;
        if (line[0] == 't') {
            now = atoll(line + 2);
            semo_link_tick(&g_link, now);
        } else if (line[0] == 'b') {
            size_t n = hex_in(line + 2, g_buf, sizeof g_buf);
            for (size_t i = 0; i < n; i++) {
                semo_link_frame f;
                if (semo_link_feed(&g_link, g_buf[i], now, &f)) {
                    printf("take %c %u ", f.kind, f.seq);
                    hex_out(f.payload, f.len);
                    printf("\n");
                }
            }
        } else if ((line[0] == 'q' || line[0] == 'e') && sscanf(line + 2, "%c", &kind) == 1) {
            size_t n = hex_in(line + 4, g_buf, sizeof g_buf);
            int rc = line[0] == 'q' ? semo_link_queue(&g_link, (unsigned char)kind, g_buf, n, NULL, 0)
                                    : semo_link_emit(&g_link, (unsigned char)kind, g_buf, n, NULL, 0);
            if (rc != 0)
                printf("refused\n");
            if (line[0] == 'q')
                semo_link_tick(&g_link, now);
        } else if (line[0] == 'w' && sscanf(line + 2, "%c", &kind) == 1) {
            size_t n = hex_in(line + 4, g_buf, sizeof g_buf);
            unsigned char *waiting = semo_link_waiting(&g_link, (unsigned char)kind);
            if (!waiting)
                printf("none\n");
            else if (n > SEMO_LINK_SEND_MAX)
                printf("refused\n");
            else {
                memcpy(waiting, g_buf, n);
                semo_link_rewrite(&g_link, n);
            }
        } else if (line[0] == 'd') {
            char to[256];
            int used = 0;
            if (sscanf(line + 2, "%255s %n", to, &used) == 1 && used > 0) {
                size_t n = hex_in(line + 2 + used, g_buf, sizeof g_buf);
                if (semo_link_send_datagram(&g_link, to, g_buf, n) != 0)
                    printf("refused\n");
            }
        } else if (line[0] == 'r') {
            semo_link_restart(&g_link);
        } else if (line[0] == 'f') {
            g_link.welcome_flags = (unsigned char)atoi(line + 2);
        } else if (line[0] == 's') {
            printf("stats bad=%lu dup=%lu retx=%lu pending=%zu welcomed=%d peer_flags=%u peer_payload_max=%zu "
                   "lost=%lu\n",
                   g_link.bad_frames, g_link.duplicates, g_link.retransmissions, semo_link_pending(&g_link),
                   g_link.welcomed, g_link.peer_flags, g_link.peer_payload_max, g_link.lost);
        }
        printf(".\n");
        fflush(stdout);
    }
    return 0;
}
