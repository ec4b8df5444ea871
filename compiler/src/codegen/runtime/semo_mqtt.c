/* semo_mqtt.c: the MQTT transport, through libmosquitto. Compiled only with
 * -DSEMO_MQTT (the Makefile's TRANSPORT=mqtt, which also links -lmosquitto);
 * without it this file is empty.
 *
 * Every topic starts with the run's scope, `semo/<mission>/<run>` (`--run`,
 * else $SEMO_RUN, else `default`): a run never hears another, not even the
 * values an earlier one left retained on the broker. Topics then name the
 * receiver and the sender: a message to a team goes to
 * `<scope>/<team>/<key>/<from team>/<from robot>`, one to a single robot to
 * `<scope>/<team>/<robot>/<key>/<from team>/<from robot>` (seven and eight
 * levels: a team's subscription never matches a robot's topic); every robot
 * subscribes to both levels of its own team and robot.
 * The payload is the runtime's datagram unchanged. Who sent a message is
 * what the broker vouches for, never what the payload says: the broker's
 * ACL (`semo deploy broker-config`) lets each user write only topics whose
 * sender levels are its own robots, and a message whose datagram names
 * another sender or key than its topic is refused here (recv returns
 * SEMO_RECV_REFUSED, which the runtime traces as a `reject`).
 * `compiler/src/deploy/topics.rs` mirrors these topics for the ACL, the
 * operator console and the editor's monitor.
 *
 * `send` messages travel at QoS 1 and the session is persistent
 * (clean_session false, client id `semo-<mission>-<run>-<robot>`: one
 * session per run), so a robot that was away gets what was sent meanwhile;
 * `publish` messages at QoS 0, not retained: as over UDP and in the
 * simulator, a robot that joins (or restarts) hears the publishes made from
 * then on, never an earlier one the broker kept. A session kept over runs (a client id
 * given by the deployment) may bring messages of an earlier run: they are
 * another run's, and dropped unseen.
 * TCP_NODELAY is set: without it a QoS 1 round trip on loopback waits for
 * Nagle's algorithm (tens of ms instead of 0.1 ms).
 */
#ifdef SEMO_MQTT
#define _POSIX_C_SOURCE 200809L

#include "semo_internal.h"

#include <mosquitto.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The runtime's largest datagram (SEMO__DATAGRAM_MAX: 3 fields and a value) and a
 * spare byte: a longer payload arrives truncated and is rejected as
 * malformed by the runtime. */
#define MQTT_PAYLOAD_MAX (SEMO__DATAGRAM_MAX + 1)
/* Room for the longest topic: "semo", the mission (63 bytes), the run (63)
 * and five levels of at most 255 bytes (datagram fields), each after its
 * `/`. */
#define MQTT_TOPIC_MAX 1600
#define MQTT_KEEPALIVE_S 10
/* How long open waits for the broker's CONNACK and SUBACK, and close for
 * the acknowledgements of QoS 1 messages still in flight (wall ms). */
#define MQTT_OPEN_WAIT_MS 5000
#define MQTT_CLOSE_WAIT_MS 2000
/* QoS 1 messages sent and not yet acknowledged, at most (libmosquitto's
 * MOSQ_OPT_SEND_MAXIMUM; more wait, in order, in its queue): the broker's
 * rate times a loaded machine's scheduling delay of a few ms (20k/s × 3 ms),
 * where libmosquitto's default of 20 made the sender wait on loopback. */
#define MQTT_SEND_WINDOW 64
/* Messages handed to libmosquitto and not yet acknowledged, at most, while
 * connected: beyond the window libmosquitto queues each one it is given
 * (allocated), so a robot sending faster than the broker acknowledges
 * would grow without bound; a send waits for acknowledgements instead
 * (back-pressure, as the message channels give). Not while disconnected:
 * a send then waits in the outbox (MQTT_OUTBOX). */
#define MQTT_UNACKED_MAX (4 * MQTT_SEND_WINDOW)

static struct mosquitto *g_mosq;
static const semo_program_desc *g_program;
static char g_mission[64];
static char g_run[SEMO_RUN_MAX];
/* `semo/<mission>/<run>/`: where every topic of this run starts. */
static char g_run_prefix[MQTT_TOPIC_MAX];
static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t g_changed; /* monotonic clock; every state change below */
static semo__received g_received; /* what recv has still to take */
static bool g_interrupted;
static bool g_subscribed;
static int g_connect_refused; /* the broker's CONNACK code when it refused */
static bool g_connected_once, g_session_present; /* the first CONNACK's session-present flag */
static int g_subscribe_mid = -1;
static unsigned long g_opened; /* opens so far: a topic named under an earlier open is not reused */
static long g_unacked; /* messages handed to libmosquitto whose on_publish has not come */
/* Acknowledgements (on_publish) and disconnections wake, on g_acked, only
 * those who wait for them: close (g_closing) and sends finding
 * MQTT_UNACKED_MAX unacknowledged (g_ack_waiters). Waking the receiver
 * (which waits on g_changed) at every one cost a thread switch a message. */
static pthread_cond_t g_acked; /* monotonic clock */
static bool g_closing;
static int g_ack_waiters;
static bool g_connected; /* between a CONNACK that accepted and a disconnection */

/* Sends made while the broker was unreachable, oldest first; g_send_lock
 * also keeps sends in order against the flush (never held by a callback
 * while it waits for g_lock, nor taken under g_lock). */
/* At most this many (a robot sending every 10 ms waits about 80 s); each
 * takes only its own size, allocated when the broker is away. */
#define MQTT_OUTBOX 8192
typedef struct {
    size_t len;
    unsigned char *data;
    char topic[]; /* then the payload */
} mqtt_outgoing;
static pthread_mutex_t g_send_lock = PTHREAD_MUTEX_INITIALIZER;
static mqtt_outgoing *g_outbox[MQTT_OUTBOX];
static size_t g_out_head, g_out_count;

/* A topic level made of a name: the characters MQTT gives a meaning to
 * (level separator, wildcards) become `_`. */
static void append_level(char *topic, size_t cap, const char *name)
{
    size_t at = strlen(topic);
    if (at + 1 < cap)
        topic[at++] = '/';
    for (; *name && at + 1 < cap; name++)
        topic[at++] = (*name == '/' || *name == '+' || *name == '#') ? '_' : *name;
    topic[at] = '\0';
}

/* The mission's name for topics: the file name without `.mission`, cut to
 * the buffer never inside a UTF-8 character (a topic must be UTF-8). */
static void mission_name(const char *mission)
{
    const char *name = mission && *mission ? mission : "mission";
    size_t n = strlen(name);
    if (n >= sizeof g_mission) {
        n = sizeof g_mission - 1;
        while (n > 0 && ((unsigned char)name[n] & 0xC0) == 0x80)
            n--;
    }
    memcpy(g_mission, name, n);
    g_mission[n] = '\0';
    char *dot = strstr(g_mission, ".mission");
    if (dot && dot != g_mission && dot[8] == '\0')
        *dot = '\0';
}

/* `semo/<mission>/<run>`: the run's scope, where every topic starts. */
static void scope_of(char *topic, size_t cap)
{
    snprintf(topic, cap, "semo");
    append_level(topic, cap, g_mission);
    append_level(topic, cap, g_run);
}

/* <scope>/<team>[/<robot>]/<key>/<from team>/<from robot>; without a key,
 * our subscription to every key from every sender. False when the topic
 * does not fit (it never is cut short: a cut topic could name another
 * sender). */
static bool topic_of(char *topic, size_t cap, const char *team, const char *robot, const char *key,
                     const char *from_team, const char *from_robot)
{
    scope_of(topic, cap);
    append_level(topic, cap, team);
    if (robot)
        append_level(topic, cap, robot);
    if (!key) {
        snprintf(topic + strlen(topic), cap - strlen(topic), "/+/+/+");
        return true;
    }
    append_level(topic, cap, key);
    append_level(topic, cap, from_team);
    append_level(topic, cap, from_robot);
    return strlen(topic) + 1 < cap;
}

/* The datagram's fields after "SEMO" 0x02 <kind> (semo_internal.h): each a length byte and
 * that many bytes. Copies field `index` (0 team, 1 robot, 2 key) into `out`;
 * false where the runtime's decoder refuses the field too (cut short, or
 * with a NUL byte), so that what is checked here is what it reads. */
static bool datagram_field(const unsigned char *data, size_t len, int index, char *out, size_t cap)
{
    size_t at = 6;
    for (int i = 0; at < len; i++) {
        size_t n = data[at++];
        if (at + n > len)
            return false;
        if (i == index) {
            if (n >= cap || memchr(data + at, '\0', n))
                return false;
            memcpy(out, data + at, n);
            out[n] = '\0';
            return true;
        }
        at += n;
    }
    return false;
}


static void outbox_flush(void);

bool semo__mqtt_session_present(void)
{
    pthread_mutex_lock(&g_lock);
    bool present = g_session_present;
    pthread_mutex_unlock(&g_lock);
    return present;
}

/* On every (re)connection: subscribe again (the persistent session keeps the
 * subscriptions, but a broker that lost its state must learn them). */
static void on_connect(struct mosquitto *mosq, void *obj, int rc, int flags)
{
    (void)obj;
    if (rc == 0) {
        pthread_mutex_lock(&g_lock);
        if (!g_connected_once)
            g_session_present = (flags & 1) != 0;
        g_connected_once = true;
        g_connected = true;
        pthread_mutex_unlock(&g_lock);
    }
    if (rc != 0) {
        pthread_mutex_lock(&g_lock);
        g_connect_refused = rc;
        pthread_cond_broadcast(&g_changed);
        pthread_mutex_unlock(&g_lock);
        return;
    }
    const semo_peer *self = &g_program->peers[g_program->self];
    char team[MQTT_TOPIC_MAX], robot[MQTT_TOPIC_MAX];
    topic_of(team, sizeof team, self->team, NULL, NULL, NULL, NULL);
    topic_of(robot, sizeof robot, self->team, self->robot, NULL, NULL, NULL);
    char *topics[] = {team, robot};
    int mid;
    if (mosquitto_subscribe_multiple(mosq, &mid, 2, topics, 1, 0, NULL) == MOSQ_ERR_SUCCESS) {
        pthread_mutex_lock(&g_lock);
        g_subscribe_mid = mid;
        pthread_mutex_unlock(&g_lock);
    }
    outbox_flush();
}

/* A send waiting for acknowledgements gives up waiting: until the next
 * connection, sends go to the outbox. */
static void on_disconnect(struct mosquitto *mosq, void *obj, int rc)
{
    (void)mosq;
    (void)obj;
    (void)rc;
    pthread_mutex_lock(&g_lock);
    g_connected = false;
    pthread_cond_broadcast(&g_acked);
    pthread_mutex_unlock(&g_lock);
}

static void on_subscribe(struct mosquitto *mosq, void *obj, int mid, int count, const int *granted)
{
    (void)mosq;
    (void)obj;
    (void)count;
    (void)granted;
    pthread_mutex_lock(&g_lock);
    if (mid == g_subscribe_mid) {
        g_subscribed = true;
        pthread_cond_broadcast(&g_changed);
    }
    pthread_mutex_unlock(&g_lock);
}

static void on_publish(struct mosquitto *mosq, void *obj, int mid)
{
    (void)mosq;
    (void)obj;
    (void)mid;
    pthread_mutex_lock(&g_lock);
    if (g_unacked > 0)
        g_unacked--;
    if (g_closing || g_ack_waiters > 0)
        pthread_cond_broadcast(&g_acked);
    pthread_mutex_unlock(&g_lock);
}

/* Whether `topic` is where the sender and key that the datagram claims
 * would send it to us (to our team or to us alone): the broker lets only
 * that sender's user write there. */
static bool sent_on_its_topic(const char *topic, const char *team, const char *robot, const char *key)
{
    const semo_peer *self = &g_program->peers[g_program->self];
    char expected[MQTT_TOPIC_MAX];
    if (topic_of(expected, sizeof expected, self->team, NULL, key, team, robot) && strcmp(topic, expected) == 0)
        return true;
    return topic_of(expected, sizeof expected, self->team, self->robot, key, team, robot) &&
           strcmp(topic, expected) == 0;
}

static void on_message(struct mosquitto *mosq, void *obj, const struct mosquitto_message *msg)
{
    (void)mosq;
    (void)obj;
    /* Another run's message (a session kept over runs) is none of ours. */
    if (strncmp(msg->topic, g_run_prefix, strlen(g_run_prefix)) != 0)
        return;
    const semo_peer *self = &g_program->peers[g_program->self];
    const unsigned char *data = msg->payload;
    size_t len = msg->payloadlen > 0 ? (size_t)msg->payloadlen : 0;
    char team[256], robot[256], key[256];
    /* A payload that is no datagram goes on: the runtime rejects it as malformed. */
    bool claims = datagram_field(data, len, 0, team, sizeof team) &&
                  datagram_field(data, len, 1, robot, sizeof robot) && datagram_field(data, len, 2, key, sizeof key);
    /* A message to our team that we sent ourselves: UDP never sends to self. */
    if (claims && strcmp(team, self->team) == 0 && strcmp(robot, self->robot) == 0 &&
        sent_on_its_topic(msg->topic, team, robot, key))
        return;
    bool refused = claims && !sent_on_its_topic(msg->topic, team, robot, key);
    pthread_mutex_lock(&g_lock);
    if (refused) {
        /* Told to recv, which the runtime traces; never delivered. */
        if (!g_interrupted)
            g_received.refused++;
        pthread_cond_broadcast(&g_changed);
        pthread_mutex_unlock(&g_lock);
        return;
    }
    /* A full queue holds back the network thread (and so the broker's
     * acknowledgement) rather than losing a message. */
    while (semo__received_full(&g_received) && !g_interrupted)
        pthread_cond_wait(&g_changed, &g_lock);
    if (!g_interrupted) {
        semo__received_put(&g_received, data, len);
        pthread_cond_broadcast(&g_changed);
    }
    pthread_mutex_unlock(&g_lock);
}

static void status_topic(char *topic, size_t cap);

/* The password: the first line of its file, without the line break. */
static int read_password(const char *path, char *out, size_t cap)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "semo runtime: cannot read the MQTT password file \"%s\"\n", path);
        return -1;
    }
    bool got = fgets(out, (int)cap, f) != NULL;
    fclose(f);
    if (!got) {
        fprintf(stderr, "semo runtime: the MQTT password file \"%s\" is empty\n", path);
        return -1;
    }
    out[strcspn(out, "\r\n")] = '\0';
    return 0;
}

/* Who we are at the broker (user and password) and, for mqtts://, TLS with
 * the CA that signed the broker's certificate and our own certificate. */
static int identify(const semo_transport_config *config)
{
    if (config->user) {
        char password[256] = "";
        if (config->password_file && read_password(config->password_file, password, sizeof password) != 0)
            return -1;
        int rc = mosquitto_username_pw_set(g_mosq, config->user, config->password_file ? password : NULL);
        /* The password stays in libmosquitto only. */
        memset(password, 0, sizeof password);
        if (rc != MOSQ_ERR_SUCCESS) {
            fprintf(stderr, "semo runtime: MQTT user \"%s\": %s\n", config->user, mosquitto_strerror(rc));
            return -1;
        }
    }
    if (config->broker_tls) {
        int rc = mosquitto_tls_set(g_mosq, config->ca, NULL, config->cert, config->key, NULL);
        if (rc != MOSQ_ERR_SUCCESS) {
            fprintf(stderr, "semo runtime: TLS with CA \"%s\"%s%s: %s\n", config->ca ? config->ca : "",
                    config->cert ? " and certificate " : "", config->cert ? config->cert : "", mosquitto_strerror(rc));
            return -1;
        }
    }
    return 0;
}

static int mqtt_open(const semo_program_desc *program, const semo_transport_config *config)
{
    if (g_mosq || program->self >= program->peer_count || !config->broker_host)
        return -1;
    g_program = program;
    mission_name(program->mission);
    /* Checked by the options (`parse_run`): a topic level as it is. */
    snprintf(g_run, sizeof g_run, "%s", config->run && *config->run ? config->run : SEMO_RUN_DEFAULT);
    scope_of(g_run_prefix, sizeof g_run_prefix);
    snprintf(g_run_prefix + strlen(g_run_prefix), sizeof g_run_prefix - strlen(g_run_prefix), "/");
    g_received.head = g_received.count = 0;
    g_interrupted = g_subscribed = false;
    g_received.refused = 0;
    g_connect_refused = 0;
    g_subscribe_mid = -1;
    g_unacked = 0;
    g_opened++;
    g_closing = g_connected = false;
    g_ack_waiters = 0;
    g_out_head = g_out_count = 0;
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    pthread_cond_init(&g_changed, &attr);
    pthread_cond_init(&g_acked, &attr);
    pthread_condattr_destroy(&attr);

    mosquitto_lib_init();
    char client_id[MQTT_TOPIC_MAX];
    if (config->client_id)
        snprintf(client_id, sizeof client_id, "%s", config->client_id);
    else
        snprintf(client_id, sizeof client_id, "semo-%s-%s-%s", g_mission, g_run, program->peers[program->self].robot);
    g_mosq = mosquitto_new(client_id, false, NULL);
    if (!g_mosq) {
        mosquitto_lib_cleanup();
        return -1;
    }
    if (identify(config) != 0) {
        mosquitto_destroy(g_mosq);
        g_mosq = NULL;
        mosquitto_lib_cleanup();
        return -1;
    }
    mosquitto_int_option(g_mosq, MOSQ_OPT_TCP_NODELAY, 1);
    mosquitto_int_option(g_mosq, MOSQ_OPT_SEND_MAXIMUM, MQTT_SEND_WINDOW);
    /* If we vanish without disconnecting, the broker says so on our status. */
    char will_topic[MQTT_TOPIC_MAX], will[MQTT_TOPIC_MAX];
    status_topic(will_topic, sizeof will_topic);
    int will_len = snprintf(will, sizeof will,
                            "{\"robot\":\"%s\",\"event\":\"status\",\"state\":\"lost\",\"started\":\"%lld\"}",
                            program->peers[program->self].robot, config->started_unix_ms);
    mosquitto_will_set(g_mosq, will_topic, will_len, will, 1, true);
    mosquitto_connect_with_flags_callback_set(g_mosq, on_connect);
    mosquitto_subscribe_callback_set(g_mosq, on_subscribe);
    mosquitto_disconnect_callback_set(g_mosq, on_disconnect);
    mosquitto_publish_callback_set(g_mosq, on_publish);
    mosquitto_message_callback_set(g_mosq, on_message);
    /* After a lost connection the network thread reconnects by itself. */
    mosquitto_reconnect_delay_set(g_mosq, 1, 8, true);
    int rc = mosquitto_connect(g_mosq, config->broker_host, config->broker_port, MQTT_KEEPALIVE_S);
    if (rc != MOSQ_ERR_SUCCESS || mosquitto_loop_start(g_mosq) != MOSQ_ERR_SUCCESS) {
        fprintf(stderr, "semo runtime: cannot reach the MQTT broker at %s:%d: %s\n", config->broker_host,
                config->broker_port, mosquitto_strerror(rc));
        mosquitto_destroy(g_mosq);
        g_mosq = NULL;
        mosquitto_lib_cleanup();
        return -1;
    }
    /* Sending before our subscriptions stand would lose the answers. */
    struct timespec deadline = semo__deadline_after(MQTT_OPEN_WAIT_MS);
    pthread_mutex_lock(&g_lock);
    int waited = 0;
    while (!g_subscribed && !g_connect_refused && waited == 0)
        waited = pthread_cond_timedwait(&g_changed, &g_lock, &deadline);
    bool ready = g_subscribed;
    int refused = g_connect_refused;
    pthread_mutex_unlock(&g_lock);
    if (!ready) {
        fprintf(stderr, "semo runtime: the MQTT broker at %s:%d %s\n", config->broker_host, config->broker_port,
                refused ? mosquitto_connack_string(refused) : "did not confirm the subscriptions in time");
        mosquitto_disconnect(g_mosq);
        mosquitto_loop_stop(g_mosq, false);
        mosquitto_destroy(g_mosq);
        g_mosq = NULL;
        mosquitto_lib_cleanup();
        return -1;
    }
    return 0;
}

/* Publishes, counting the message until on_publish (QoS 1: the broker's
 * PUBACK; QoS 0: written to the socket), which may come first. */
static int publish(const char *topic, const void *data, size_t len, int qos, bool retain)
{
    pthread_mutex_lock(&g_lock);
    g_unacked++;
    pthread_mutex_unlock(&g_lock);
    int rc = mosquitto_publish(g_mosq, NULL, topic, (int)len, data, qos, retain);
    if (rc != MOSQ_ERR_SUCCESS) {
        pthread_mutex_lock(&g_lock);
        g_unacked--;
        pthread_mutex_unlock(&g_lock);
    }
    return rc;
}

/* Under g_send_lock: keeps a send for the next connection; false when the
 * outbox is full (the send is then lost, and said so by the caller). */
static bool outbox_put(const char *topic, const void *data, size_t len)
{
    size_t topic_len = strlen(topic) + 1;
    mqtt_outgoing *kept = g_out_count < MQTT_OUTBOX ? malloc(sizeof *kept + topic_len + len) : NULL;
    if (!kept)
        return false;
    memcpy(kept->topic, topic, topic_len);
    kept->data = (unsigned char *)kept->topic + topic_len;
    kept->len = len;
    memcpy(kept->data, data, len);
    g_outbox[(g_out_head + g_out_count) % MQTT_OUTBOX] = kept;
    g_out_count++;
    pthread_mutex_lock(&g_lock); /* close waits for it too */
    g_unacked++;
    pthread_mutex_unlock(&g_lock);
    return true;
}

/* On a (re)connection: the sends kept meanwhile go first, in order. */
static void outbox_flush(void)
{
    pthread_mutex_lock(&g_send_lock);
    while (g_out_count > 0) {
        mqtt_outgoing *kept = g_outbox[g_out_head];
        if (publish(kept->topic, kept->data, kept->len, 1, false) != MOSQ_ERR_SUCCESS)
            break; /* gone again: the next connection retries */
        free(kept);
        g_outbox[g_out_head] = NULL;
        g_out_head = (g_out_head + 1) % MQTT_OUTBOX;
        g_out_count--;
        pthread_mutex_lock(&g_lock); /* now counted by publish */
        g_unacked--;
        pthread_mutex_unlock(&g_lock);
    }
    pthread_mutex_unlock(&g_send_lock);
}

/* The topic of a message to `to` (a team or a robot of the mission, or
 * USER) with `key` from us; false when there is none or it does not fit. */
static bool topic_to(const char *to, const char *key, char *topic, size_t cap)
{
    /* The sender levels are ours, whatever the datagram says: the broker
     * lets our user write only those. */
    const semo_peer *self = &g_program->peers[g_program->self];
    bool team = false;
    const semo_peer *robot = NULL;
    for (size_t i = 0; i < g_program->peer_count; i++) {
        if (strcmp(g_program->peers[i].team, to) == 0)
            team = true;
        else if (strcmp(g_program->peers[i].robot, to) == 0)
            robot = &g_program->peers[i];
    }
    if (team || strcmp(to, "USER") == 0) /* USER: every operator console */
        return topic_of(topic, cap, to, NULL, key, self->team, self->robot);
    if (robot)
        return topic_of(topic, cap, robot->team, robot->robot, key, self->team, self->robot);
    return false;
}

/* `to` is a team (every robot of it hears) or one robot's name. */
static int mqtt_send_to(const char *to, const void *data, size_t len)
{
    if (!g_mosq || len < 6 || len > MQTT_PAYLOAD_MAX)
        return -1;
    char key[256];
    if (!datagram_field(data, len, 2, key, sizeof key))
        return -1;
    /* The topic this thread named last, when it is the same (a robot sends
     * the same key to the same team many times in a row): built only
     * once, not at every message. */
    static _Thread_local struct {
        unsigned long opened; /* g_opened when it was built: another open, another scope */
        char to[256], key[256], topic[MQTT_TOPIC_MAX];
    } last;
    if (last.opened != g_opened || strcmp(last.to, to) != 0 || strcmp(last.key, key) != 0) {
        if (strlen(to) >= sizeof last.to || !topic_to(to, key, last.topic, sizeof last.topic)) {
            last.opened = 0;
            return -1;
        }
        memcpy(last.to, to, strlen(to) + 1);
        memcpy(last.key, key, strlen(key) + 1);
        last.opened = g_opened;
    }
    const char *topic = last.topic;
    bool is_send = ((const unsigned char *)data)[5] == SEMO_MSG_SEND;
    if (!is_send) {
        /* A publish while disconnected is lost, as on UDP: the next one
         * carries the latest value. Not retained: a robot that joins later
         * would otherwise read each publisher's last value at once, which
         * no other engine gives it (one meaning). */
        int rc = publish(topic, data, len, 0, false);
        return rc == MOSQ_ERR_SUCCESS || rc == MOSQ_ERR_NO_CONN ? 0 : -1;
    }
    /* Back-pressure: never more than MQTT_UNACKED_MAX in libmosquitto's
     * hands while connected. Waited for outside g_send_lock, which
     * on_connect (the network thread, the one that reads the
     * acknowledgements) takes to flush the outbox. */
    pthread_mutex_lock(&g_lock);
    while (g_unacked >= MQTT_UNACKED_MAX && g_connected && !g_interrupted) {
        g_ack_waiters++;
        pthread_cond_wait(&g_acked, &g_lock);
        g_ack_waiters--;
    }
    pthread_mutex_unlock(&g_lock);
    /* A send is never lost: while the broker is away (libmosquitto refuses
     * to publish then) it waits in the outbox, in order, until on_connect. */
    pthread_mutex_lock(&g_send_lock);
    int rc = g_out_count == 0 ? publish(topic, data, len, 1, false) : MOSQ_ERR_NO_CONN;
    bool queued = rc == MOSQ_ERR_NO_CONN || rc == MOSQ_ERR_CONN_LOST ? outbox_put(topic, data, len) : false;
    pthread_mutex_unlock(&g_send_lock);
    return rc == MOSQ_ERR_SUCCESS || queued ? 0 : -1;
}

static int mqtt_recv(void *data, size_t cap, int timeout_ms)
{
    return semo__received_take(&g_received, &g_lock, &g_changed, &g_interrupted, data, cap, timeout_ms);
}

/* <scope>/status/<robot>. */
static void status_topic(char *topic, size_t cap)
{
    scope_of(topic, cap);
    append_level(topic, cap, "status");
    append_level(topic, cap, g_program->peers[g_program->self].robot);
}

/* Retained, so that an operator who connects later sees it; QoS 1, so that
 * the last one (stopped) reaches the broker before we disconnect. */
static int mqtt_status(const char *json, size_t len)
{
    if (!g_mosq)
        return -1;
    char topic[MQTT_TOPIC_MAX];
    status_topic(topic, sizeof topic);
    int rc = publish(topic, json, len, 1, true);
    return rc == MOSQ_ERR_SUCCESS || rc == MOSQ_ERR_NO_CONN ? 0 : -1;
}

static void mqtt_interrupt(void)
{
    pthread_mutex_lock(&g_lock);
    g_interrupted = true;
    pthread_cond_broadcast(&g_changed);
    pthread_cond_broadcast(&g_acked);
    pthread_mutex_unlock(&g_lock);
}

static void mqtt_close(void)
{
    if (!g_mosq)
        return;
    /* What we sent at QoS 1 must reach the broker before we go: after a
     * disconnection libmosquitto forgets its queue. */
    struct timespec deadline = semo__deadline_after(MQTT_CLOSE_WAIT_MS);
    pthread_mutex_lock(&g_lock);
    g_closing = true;
    int waited = 0;
    while (g_unacked > 0 && waited == 0)
        waited = pthread_cond_timedwait(&g_acked, &g_lock, &deadline);
    pthread_mutex_unlock(&g_lock);
    mosquitto_disconnect(g_mosq);
    mosquitto_loop_stop(g_mosq, false);
    mosquitto_destroy(g_mosq);
    g_mosq = NULL;
    mosquitto_lib_cleanup();
    pthread_cond_destroy(&g_changed);
    pthread_cond_destroy(&g_acked);
    /* Sends the broker never came back for are lost with the program. */
    for (; g_out_count > 0; g_out_count--) {
        free(g_outbox[g_out_head]);
        g_outbox[g_out_head] = NULL;
        g_out_head = (g_out_head + 1) % MQTT_OUTBOX;
    }
}

const semo_transport semo_mqtt_transport = {
    .name = "mqtt",
    .refusal = "sender not its topic",
    .open = mqtt_open,
    .send_to = mqtt_send_to,
    .recv = mqtt_recv,
    .interrupt = mqtt_interrupt,
    .status = mqtt_status,
    .close = mqtt_close,
};
#else
/* ISO C wants at least one declaration in a translation unit. */
typedef int semo_mqtt_not_built;
#endif
