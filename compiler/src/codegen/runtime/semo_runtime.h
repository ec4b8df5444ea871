/* semo_runtime.h: the SeMo runtime API (every target).
 *
 * Generated robot programs and the task files users write call only what is
 * declared here. Names of the task-facing calls follow the HOPES/UEM
 * convention (UFPort_*, UFControl_*, UFTimer_*, LIBCALL/LIBFUNC) so existing
 * task code ports over. The generated files provide the descriptor tables
 * (tasks, channels, multicast groups, peers) in one `semo_program_desc`
 * handed to `semo_main`.
 *
 * Platforms: POSIX threads (`linux`, `linux-sim`: one thread per task, every
 * call below is thread-safe) or a static schedule (`-DSEMO_STATIC`, targets
 * `cortex-m`, `cortex-m-sim`: one loop, `Core_1_go`, fires the tasks in the
 * order of the task graph's single-appearance schedule; no threads, no
 * heap, and no call blocks).
 * Time: "mission time" in milliseconds since start. In simulation
 * (`-DSEMO_SIM`) on POSIX it runs `time_scale` times faster than the wall
 * clock.
 */
#ifndef SEMO_RUNTIME_H
#define SEMO_RUNTIME_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* ---------------------------------------------------------------- values */

/* Values are typed as the catalog declares them (`refine::value` is the
 * simulator's side of the same rules): integers (int64), reals (double),
 * truth values, words (an enum's constants and the mission's symbolic
 * constants: an index into the program's word table, compared by identity)
 * and text (catalog string, location "x,y", image) in a bounded buffer:
 * longer text is cut to SEMO_TEXT_MAX - 1 bytes at a character. A value
 * never set has type SEMO_NONE. The static-schedule targets' Makefile sets
 * SEMO_TEXT_MAX from the program (its longest text literal and scenario
 * value, at least 16), and -DSEMO_NO_REALS for a program without reals: no
 * floating point is linked then (reals are neither parsed, compared nor
 * printed: a SEMO_REAL value counts as no number). */
#ifndef SEMO_TEXT_MAX
#define SEMO_TEXT_MAX 64
#endif
typedef enum { SEMO_NONE, SEMO_INT, SEMO_REAL, SEMO_BOOL, SEMO_WORD, SEMO_TEXT } semo_type;
typedef struct {
    unsigned char type; /* semo_type */
    union {
        int64_t i;
        double r;
        bool b;
        unsigned short word; /* index into semo_program()->words */
        char text[SEMO_TEXT_MAX];
    };
} semo_value;

/* Literals, each a `const semo_value *`: SEMO_LIT("5,5") is text. */
#define SEMO_LIT(s) (&(const semo_value){.type = SEMO_TEXT, .text = s})
#define SEMO_LIT_INT(n) (&(const semo_value){.type = SEMO_INT, .i = (n)})
#define SEMO_LIT_REAL(x) (&(const semo_value){.type = SEMO_REAL, .r = (x)})
#define SEMO_LIT_BOOL(x) (&(const semo_value){.type = SEMO_BOOL, .b = (x)})
#define SEMO_LIT_WORD(n) (&(const semo_value){.type = SEMO_WORD, .word = (n)})

void semo_value_set(semo_value *v, const char *text); /* text, cut to fit */
void semo_value_set_int(semo_value *v, int64_t n);
void semo_value_set_real(semo_value *v, double x);
void semo_value_set_bool(semo_value *v, bool b);
/* False (and `v` unchanged) when `word` is not in the program's word table. */
bool semo_value_set_word(semo_value *v, const char *word);
/* `text` read as a value of `type` (scenario values, text received where
 * a type is declared): integers "[+-]digits", reals in the grammar of
 * `parse_number`, "true"/"false", a word of the table, any text. False (and
 * `v` unchanged) when it is not one. */
bool semo_value_parse(semo_value *v, semo_type type, const char *text);
/* A received value where `type` is declared (SEMO_NONE: a team variable,
 * any type): the same type passes, an integer widens to a real, text is
 * parsed as the type, a word becomes text; false for anything else. */
bool semo_value_coerce(semo_value *v, semo_type type);
/* Whether `v` is one of the `n` words of `domain` (indices into the
 * program's words); true for a value that is not a word or no domain. */
bool semo_value_in(const semo_value *v, const unsigned short *domain, size_t n);
/* The text of a word or a text value, else NULL. */
const char *semo_value_word_text(const semo_value *v);
/* Writes the value as JSON (a number, true/false, a string; null for none)
 * into `out`; returns its length (cut to `cap` - 1). */
size_t semo_value_json(const semo_value *v, char *out, size_t cap);
/* How generated code compares, as the checker typed each comparison (never
 * guessing from the values). As numbers: integers exactly, else as reals;
 * false when either value is not a number. As words: equal when the same
 * word, a word and a text with the same text, the same number or truth
 * value, or both none; words are never ordered (SEMO_LT ... are false). */
typedef enum { SEMO_EQ, SEMO_NE, SEMO_LT, SEMO_LE, SEMO_GT, SEMO_GE } semo_cmp;
bool semo_value_numbers(const semo_value *a, semo_cmp op, const semo_value *b);
bool semo_value_words(const semo_value *a, semo_cmp op, const semo_value *b);
/* `true`, or a number other than zero. */
bool semo_value_truthy(const semo_value *v);

/* ------------------------------------------------------------------ time */

int64_t semo_now_ms(void);         /* mission time since start */
void semo_sleep_ms(int64_t ms);    /* mission ms; returns early when the program stops */
/* Waits until mission time `at_ms` (no earlier; at once when it is past);
 * false when the program stops first. A service task's time-triggered inner
 * task waits for its period with it. POSIX only. */
bool semo_sleep_until(int64_t at_ms);

/* -------------------------------------------------------- program tables */

typedef enum { SEMO_TRIGGER_TIME, SEMO_TRIGGER_DATA, SEMO_TRIGGER_CONTROL } semo_trigger;

typedef struct {
    const char *name;
    semo_trigger trigger;
    int64_t period_ms; /* SEMO_TRIGGER_TIME only */
    void (*init)(void);
    void (*go)(void);  /* one firing */
    void (*wrapup)(void);
} semo_task_desc;

/* Where a channel's samples are on the static schedule (no heap): the
 * generated channels.c gives each channel its buffer and this state. */
typedef struct {
    size_t head, count;
    unsigned long dropped;
    unsigned short reader; /* index of the task reading it (set at start) */
    bool stalled; /* semo_port_offer gave up; until the next take, it waits no more */
} semo_channel_state;

/* A FIFO channel of the task graph: a bounded ring buffer of fixed-size samples. */
typedef struct {
    const char *src_task, *src_port, *dst_task, *dst_port;
    size_t sample_size;
    size_t capacity;          /* samples, from the buffer analysis */
    unsigned initial_samples; /* zero-filled samples present at start */
    /* Static schedule only (NULL on POSIX, which allocates them):
     * `capacity * sample_size` bytes, and the ring's state. */
    unsigned char *storage;
    semo_channel_state *state;
} semo_channel_desc;

/* One term of the static schedule: `count` firings of task `task` (an index
 * into the task table). */
typedef struct {
    unsigned short task;
    unsigned short count;
} semo_firing;

/* A multicast group: a buffer holding the latest sample. */
typedef struct {
    const char *name;
    size_t sample_size;
} semo_multicast_desc;

/* A robot this one sends to or hears from (its team's robots and those its
 * messages go to, not the whole mission): its team, name and place among the
 * mission's robots, `index` (formation order, below `robot_count`). Over UDP
 * the robot at place i listens on port `port_base + i` of 127.0.0.1; in
 * lock-step the place is its id. */
typedef struct {
    const char *team;
    const char *robot;
    size_t index;
} semo_peer;

/* A threads robot's connection defaults, baked in by `semo build --deploy`
 * (its `semo_deploy.h`, which the robot's generated main.c reads): the
 * broker URL, and who the robot is there. NULL where the deployment gives
 * none; options and environment variables override each. Kept out of the
 * runtime's own sources, which every robot of a build shares. */
typedef struct {
    const char *broker;
    const char *client_id;
    const char *user;
    const char *password_file;
    const char *ca;
    const char *cert;
    const char *key;
} semo_deploy_defaults;

typedef struct {
    const char *mission; /* file name, for traces */
    const char *team;
    const char *robot;
    const char *robot_type;
    const semo_task_desc *tasks;
    size_t task_count;
    const semo_channel_desc *channels;
    size_t channel_count;
    const semo_multicast_desc *groups;
    size_t group_count;
    const semo_peer *peers;
    size_t peer_count;
    size_t self; /* index of this robot in `peers` */
    size_t robot_count; /* robots of the mission (its peers are some of them) */
    /* A task takes messages from the inbox (the communication task): without
     * one, a message that arrives is ignored, as the simulator's robot that
     * takes no message hears none (it would fill the inbox for nothing). */
    bool receives;
    /* Static schedule only: one iteration of the single-appearance schedule. */
    const semo_firing *schedule;
    size_t schedule_count;
    /* The words of the program (SEMO_WORD values are indices into it). */
    const char *const *words;
    size_t word_count;
    /* Threads targets: the connection defaults (NULL: none). */
    const semo_deploy_defaults *deploy;
    /* Threads simulation: the simulated world's hooks the platform calls
     * (&semo_sim_platform; NULL: none, the program runs without a world). */
    const struct semo_sim_hooks *sim;
} semo_program_desc;

#ifdef SEMO_SIM
/* The threads platform's simulated world (semo_sim.c), over the scenario
 * compiled into the program (scenario.c): what a linux-sim program gives
 * the platform in semo_program_desc::sim. */
extern const struct semo_sim_hooks semo_sim_platform;
#endif

/* Runs the program: parses the command line (`--trace FILE`,
 * `--transport udp|mqtt`, `--port-base N`, `--broker URL`, `--duration MS`;
 * simulation also `--time-scale X`, its scenario being compiled in),
 * allocates channels, opens the transport, calls every
 * task's init, starts one thread per task (time-driven tasks fire every
 * period, data-driven tasks fire again as soon as a firing returns,
 * control-driven tasks wait for UFControl_*), and waits until
 * `semo_stop_program` is called or the duration elapses; then stops the
 * threads, calls every wrapup and returns the exit status. */
int semo_main(int argc, char **argv, const semo_program_desc *program);

#ifdef SEMO_STATIC
/* One pass of the static schedule: every task of `schedule` that is due
 * (time-driven: its period elapsed and its semo_next_firing reached;
 * data-driven: always, its body returns when no data waits;
 * control-driven: running or called) fires, in order. semo_main calls it,
 * then sleeps until the earliest time a task is due next (no clock tick). */
void Core_1_go(void);
/* For a task body on the static schedule that must wait (a service taking
 * time): the current firing is not over; the body returns and is called
 * again at the next pass, and the task stays busy (not idle) meanwhile.
 * When the program stops, a firing under way is called once more, with
 * semo_running() false, to end (a call under way ends with the program, as
 * a POSIX task's wait does). */
void semo_firing_continues(void);
#endif

/* Mission time when this program started, after the start barrier: 0, or
 * later for a robot restarted into a mission under way (`--start-at` in the
 * past). Leader elections use it: a restarted robot listens first. */
int64_t semo_joined_ms(void);
/* Whether the transport found this robot's session from an earlier start in
 * its run (the MQTT broker still held it, under the client id that names the
 * run: the robot was restarted); false on UDP. */
bool semo_session_resumed(void);

/* Ends the program (from any task). */
void semo_stop_program(void);
bool semo_running(void);
/* The program being run (valid inside semo_main). */
const semo_program_desc *semo_program(void);

/* ----------------------------------------------------------------- ports */

/* The channel id of a task's port, or -1 when the task has no such port. */
int UFPort_Initialize(const char *task, const char *port);
/* Blocks until one sample is available; returns the bytes read, or 0 when
 * the program is stopping or `size` is not the channel's sample size. */
int UFPort_ReadFromQueue(int port, void *buf, size_t size);
/* Never blocks: returns the bytes written, or 0 when the channel is full
 * (the sample is dropped and counted) or `size` is wrong. */
int UFPort_WriteToQueue(int port, const void *buf, size_t size);
/* Samples waiting in the channel; never blocks. -1 for a bad id. */
int UFPort_GetNumOfAvailableData(int port);
/* The message channels (the control task's sends to CommSend, and what
 * CommReceive hands the control task) never drop a message for want of room
 * where the simulator would deliver it: the writer waits for room instead.
 * semo_port_send waits until there is room (its reader, CommSend, takes
 * every message and never waits on its writer); 0 only when the program is
 * stopping or `size` is wrong. */
int semo_port_send(int port, const void *buf, size_t size);
/* semo_port_offer waits for room too, waking the reader (the control task),
 * until a firing of the reader that began after the wait has ended without
 * taking from the channel: that reader is not taking this message now (it
 * waits for another one), and holding it would hold every message behind
 * it. It is then dropped and counted, and 0 returned; until the reader
 * next takes from the channel, a message that finds it full is dropped at
 * once (the channel is stalled). The simulator does the same. */
int semo_port_offer(int port, const void *buf, size_t size);
/* The send task's wait for the rest of a firing (CommSend, after taking
 * what its channels `ports` held): true when one of them holds a message
 * again; false once they are empty and their writer (the control task) is
 * not in a firing, or the program is stopping. While that firing goes on
 * it waits for its next send: the messages one control firing sends all
 * leave in it, whatever the channel's room (16), instead of 16 or so a
 * period. Never waits on the caller's own firing (the control task runs
 * CommSend's body itself when it finishes), nor on the static schedule. */
bool semo_port_await_sends(const int *ports, size_t count);

/* ------------------------------------------------------------- multicast */

/* Latest-value groups: Write replaces the value, Read copies the latest
 * (returns the bytes read, 0 while nothing was written yet). */
int UFMulticast_Write(const char *group, const void *buf, size_t size);
int UFMulticast_Read(const char *group, void *buf, size_t size);

/* --------------------------------------------------------------- control */

typedef enum { SEMO_TASK_IDLE, SEMO_TASK_RUNNING, SEMO_TASK_SUSPENDED } semo_task_state;

int UFControl_RunTask(const char *task);     /* fire repeatedly until stopped */
int UFControl_CallTask(const char *task);    /* fire once, then back to idle */
int UFControl_StopTask(const char *task);    /* ask to stop; idle after the current firing */
int UFControl_SuspendTask(const char *task); /* no new firing until resumed */
int UFControl_ResumeTask(const char *task);
semo_task_state UFControl_GetTaskState(const char *task);
/* Waits (at most `timeout_ms` mission ms; < 0: no limit) until the task is
 * idle, e.g. after UFControl_CallTask; true when it is. Saves the control
 * task from polling UFControl_GetTaskState. */
bool UFControl_WaitIdle(const char *task, int64_t timeout_ms);
/* For task bodies that take long: true when the control task asked this
 * task to stop (or the program is stopping). */
bool UFControl_StopRequested(const char *task);
/* Waits until mission time `until_ms`, or until the control task asks the
 * task to stop, or the program stops, without polling; true when asked to
 * stop (or stopping). On the static schedule it never waits (it answers
 * UFControl_StopRequested). */
bool UFControl_WaitStop(const char *task, int64_t until_ms);

/* Called by a time-driven task's body: its next firing is not needed before
 * mission time `at_ms` (INT64_MAX: only on an event) unless data arrives on
 * one of its channels, a task changes state or a multicast group is
 * written; its period stays the shortest gap. A task that never calls it
 * fires every period. So an idle robot's control task sleeps instead of
 * polling. On the static schedule a firing that continues
 * (semo_firing_continues) may say it too: when its next step is needed;
 * no effect in other tasks. */
void semo_next_firing(int64_t at_ms);

/* Something task `task` waits for changed that is none of the above (the
 * communication task recorded a robot's arrival at a group statement): if
 * it sleeps on its semo_next_firing hint, it fires now. */
void semo_wake(const char *task);

/* Task parameters (per task, by name); unknown ones read as 0. */
int UFTask_SetIntegerParameter(const char *task, const char *param, long long value);
long long UFTask_GetIntegerParameter(const char *task, const char *param);

/* ---------------------------------------------------------------- timers */

typedef enum { SEMO_MSEC, SEMO_SEC, SEMO_MIN, SEMO_HOUR } semo_time_unit;
/* A one-shot timer in mission time; returns its id (>= 0) or -1. */
int UFTimer_Set(int64_t period, semo_time_unit unit);
/* True once the timer's period has elapsed (the timer stays alarmed). */
bool UFTimer_GetAlarmed(int id);
void UFTimer_Cancel(int id);

/* -------------------------------------------------------------- libraries */

/* Library tasks live in the program's address space: a library function is
 * a plain C function (which locks its own state), and a call goes straight
 * to it. `LIBFUNC(int, allFound, (void))`, `LIBCALL(colors, allFound, )`:
 * a call without arguments still writes the comma, since C11 wants an
 * argument for `...` (an empty one will do; -Wpedantic checks it). */
#define LIBFUNC(ret, name, params) ret name params
#define LIBCALL(port, func, ...) func(__VA_ARGS__)

/* ---------------------------------------------------- inter-robot messages */

typedef enum { SEMO_MSG_SEND = 's', SEMO_MSG_PUBLISH = 'p' } semo_msg_kind;

typedef struct {
    char kind;            /* semo_msg_kind */
    char from_team[32];
    char from_robot[32];
    char key[64];         /* "SlaveTeam.COLOR", "USER.RC_CMD" */
    semo_value value;
} semo_message;

/* Delivers to every other robot of `to_team` (or to the robot of that name;
 * "USER": the operator console, which only traces it and counts as one).
 * Returns the number of robots it was sent to, -1 on error. */
int semo_comm_send(const char *to_team, semo_msg_kind kind, const char *key, const semo_value *value);
/* The send task's step (CommSend): takes the oldest message of channel
 * `port` and sends it (semo_comm_send) to `to_team` as `key`, both under
 * the channel's lock, so that whoever takes first sends first; false when
 * the channel is empty. Never blocks on an empty channel. */
bool semo_port_forward(int port, const char *to_team, semo_msg_kind kind, const char *key);
/* The next message received (operator commands of the simulation arrive
 * here too, from team "USER"); waits at most `timeout_ms` mission ms
 * (< 0: until a message arrives or the program stops).
 * Returns 1 with `*out` filled, 0 on timeout or stop. */
int semo_comm_poll(semo_message *out, int64_t timeout_ms);

/* Where the transports reach the other robots (`--port-base`, `--broker`)
 * and, for MQTT, who the robot is there: the deployment's defaults
 * (`semo_deploy.h`) under the environment (`SEMO_MQTT_*`). NULL: not given. */
typedef struct {
    long port_base;          /* udp: robot i owns port port_base + i of 127.0.0.1 */
    const char *broker_host; /* mqtt */
    int broker_port;
    bool broker_tls;         /* mqtts:// */
    const char *run;         /* mqtt: the run's id (`--run`), a checked topic level */
    long long started_unix_ms; /* mqtt: mission time 0 on the wall clock, for the last will */
    const char *link;        /* link: tcp:HOST:PORT of the gateway ($SEMO_LINK) */
    const char *client_id;   /* default semo-<mission>-<run>-<robot> */
    const char *user;
    const char *password_file; /* its first line is the password */
    const char *ca;            /* TLS: the CA that signed the broker's certificate */
    const char *cert, *key;    /* TLS: the client's certificate and key */
    /* udp: the run's key ($SEMO_UDP_KEY): every datagram carries its
     * HMAC-SHA256 under it, and one without the right one is refused;
     * udp_key_len 0: none, every local process is trusted. */
    const unsigned char *udp_key;
    size_t udp_key_len;
} semo_transport_config;

/* The longest run key (bytes; a longer HMAC key would be hashed first). */
#define SEMO_UDP_KEY_MAX 64

/* Room for a run id (`--run`, `$SEMO_RUN`) and its NUL: 1 to 63 ASCII
 * letters, digits, `-`, `_` and `.`, starting with a letter or a digit
 * (`semo::deploy::topics::RunId`). */
#define SEMO_RUN_MAX 64
/* The run of a program given none. */
#define SEMO_RUN_DEFAULT "default"

/* What recv returns for a message whose sender the transport does not
 * vouch for (MQTT: not its topic's; UDP with a run key: not signed with
 * it): counted and traced (`reject`), never delivered. */
#define SEMO_RECV_REFUSED (-2)
/* What recv returns for a message the transport vouches for but has taken
 * already, or one as old (UDP with a run key: its counter is no later than
 * the last from its sender, or stale): a replay, traced (`reject`, reason
 * SEMO_REPLAYED_REASON), never delivered. */
#define SEMO_RECV_REPLAYED (-3)
#define SEMO_REPLAYED_REASON "replayed: not newer than the last from its sender"
/* What recv returns for a message the serial link's gateway did not pass
 * on because it is longer than the robot's link takes (docs/link.md):
 * traced (`reject`, reason SEMO_TOO_LONG_REASON). */
#define SEMO_RECV_TOO_LONG (-4)
#define SEMO_TOO_LONG_REASON "longer than the link takes"

/* The transport interface: loopback UDP (`semo_udp.c`) and MQTT
 * (`semo_mqtt.c`, with -DSEMO_MQTT). */
typedef struct {
    const char *name;
    /* Why recv refuses a message (SEMO_RECV_REFUSED), as the trace says it. */
    const char *refusal;
    int (*open)(const semo_program_desc *program, const semo_transport_config *config);
    /* To one robot of the peer table; NULL when the transport has send_to. */
    int (*send)(size_t peer, const void *data, size_t len);
    /* To every other robot of a team, or to the robot of that name, at once
     * (a broker fans out); NULL when the transport has send. */
    int (*send_to)(const char *to, const void *data, size_t len);
    /* Bytes received, 0 on timeout or interrupt, -1 on error,
     * SEMO_RECV_REFUSED for a message the transport refused (MQTT: its
     * datagram names another sender or key than the topic it came on; UDP
     * with a run key: not signed with it), SEMO_RECV_REPLAYED for a
     * replay;
     * timeout_ms < 0 waits until a datagram arrives or `interrupt` is
     * called. */
    int (*recv)(void *data, size_t cap, int timeout_ms);
    /* Makes a recv under way, and every later one, return 0 at once (the
     * program is stopping); safe from any thread. */
    void (*interrupt)(void);
    /* Publishes the robot's status (a JSON object, see semo_runtime.c) for
     * operators, replacing the last one; NULL: the transport has none. */
    int (*status)(const char *json, size_t len);
    void (*close)(void);
} semo_transport;
extern const semo_transport semo_udp_transport;
/* The serial link to `semo gateway` over TCP ($SEMO_LINK, semo_link_transport.c). */
extern const semo_transport semo_link_transport;
#ifdef SEMO_MQTT
extern const semo_transport semo_mqtt_transport;
#endif

/* ---------------------------------------------------------- group services */

/* For task code (docs/groups.md, "Group services"): this robot's rank among
 * the live members of its team's group (0, 1, ...: the live members in
 * ascending robot id, formation order) and the number of live members. A
 * robot in no group (its strategy declares no group service it calls) has
 * rank -1 and size 0. Both change when a member fails (no heartbeat for
 * two periods) or returns; read them each time work is divided. */
int semo_group_rank(void);
int semo_group_size(void);
/* For the generated control task: the rank and size it computed at a
 * heartbeat; a change is traced as {"event":"group","rank":..,"size":..}. */
void semo_group_set(int rank, int size);

/* ---------------------------------------------------------------- battery */

/* For the generated control task: the robot's `BATTERY` sensor value as it
 * read it (a number; anything else is ignored). The robot's status carries
 * the latest one (`battery`, docs/deployment.md). */
void semo_battery_report(const semo_value *level);

/* ----------------------------------------------------------------- groups */

/* For the generated control task, at each pass through statement number
 * `statement` of counted groups (numbered in the machine's order from 0):
 * the group it gave this robot (`others` for a spare) and how many members
 * it counted alive; `group` NULL when the statement forgets it (its
 * enclosing group changed). The robot's status carries the groups of the
 * statements passed since its mode started (`groups`, docs/deployment.md);
 * the trace's `allocated` says each change. A board keeps none. */
void semo_status_group(unsigned statement, const char *group, size_t alive);

/* ----------------------------------------------------------------- traces */

/* Appends one JSON line `{"t":<mission ms>,"robot":"<robot>","event":"<event>",
 * "<k1>":"<v1>",...}` to the trace (`--trace FILE`, `-` for standard output;
 * none without it). The arguments after `event` are key/value string pairs
 * ending with NULL; values are JSON-escaped (a NULL value is written as null
 * and ends the list). */
void semo_trace(const char *event, ...);
/* The same with a value as the last field, `"<value_key>":<its JSON>`
 * (semo_value_json: the JSON type follows the value's type). */
void semo_trace_value(const char *event, const char *value_key, const semo_value *value, ...);

/* --------------------------------------------------------- action results */

/* A service task gives back what its call found, before the firing that
 * ends the call: `count` values in the order of the service's results (its
 * catalog entry's <Result>s, docs/catalog.md), each of its result's type
 * (text is read as the type). The control task reads them into the names
 * the mission binds (`FOUND, WHERE = search(red)`) when the call is done;
 * a call stopped gives nothing back. The generated control task defines it
 * when its mission binds results. */
void semo_reply(const char *task, int count, const semo_value *values);

/* ------------------------------------------------------------- simulation */

#ifdef SEMO_SIM
/* The scenario's latest value of `value` (e.g. "LOCATION") for this robot
 * at the current mission time, read as `type` (the catalog's); false when
 * the scenario gives none yet, or none of that type. */
bool semo_sim_sensor(const char *value, semo_type type, semo_value *out);
/* An actuator command: traced as {"event":"actuate","task":..,"value":..}. */
void semo_sim_actuate(const char *task, const semo_value *command);
/* How long (mission ms) a built-in service takes in the scenario (default 100). */
int64_t semo_sim_service_ms(const char *service);
/* What the scenario says the next done call of `service` gives back, as
 * text values (none for its null): at most `max` into `values`; their
 * count, 0 when the scenario gives the service none. Each call takes the
 * next entry, the last one again past the list. */
int semo_sim_results(const char *service, semo_value *values, int max);
/* The scenario's battery level now, rounded (its "battery" points); false
 * when the scenario gives none. Heartbeats carry it (highest_battery). */
bool semo_sim_battery(long long *level);
/* The iteration (1, 2, ...) in which the exit task of the convergent SDF/L
 * loop `loop` (the graph's name and the loop's path, "kmeans/Converge") sets the exit flag,
 * from the scenario's "loops"; 0 when it never does. */
int64_t semo_sim_loop_exit(const char *loop);
#endif

#endif /* SEMO_RUNTIME_H */
