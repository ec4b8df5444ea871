/* runtime_test.c: robot programs written the way the generator writes them
 * (descriptor tables + task functions), each checking what the runtime
 * promises. Driven by tests/runtime_c.rs, which also reads their traces.
 *
 *   runtime_test MODE [runtime options...]
 *
 * MODE: values | tasks | minimal | wake | reals | udp-a | udp-b | sim (sim: -DSEMO_SIM builds).
 * Exit status: the runtime's, or 1 when a check failed (each failure is
 * printed as "FAIL file:line: condition").
 */
#define _POSIX_C_SOURCE 200809L

#include "../semo_runtime.h"

#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A simulation build's programs give the platform the simulated world
 * (runtime_test_world.c), as a generated linux-sim main.c does. */
#ifdef SEMO_SIM
#define SIM_WORLD .sim = &semo_sim_platform,
#else
#define SIM_WORLD
#endif

static atomic_int failures;

#define CHECK(cond)                                                                                                    \
    do {                                                                                                               \
        if (!(cond)) {                                                                                                 \
            fprintf(stderr, "FAIL %s:%d: %s\n", __FILE__, __LINE__, #cond);                                            \
            atomic_fetch_add(&failures, 1);                                                                            \
        }                                                                                                              \
    } while (0)

/* ---------------------------------------------------------------- values */

static int run_values(void)
{
    semo_value a, b;
    char json[80];
    /* As the checker typed the comparison (what generated code calls). */
    CHECK(semo_value_numbers(SEMO_LIT_INT(5), SEMO_LT, SEMO_LIT_INT(10)));
    CHECK(semo_value_numbers(SEMO_LIT_INT(9007199254740993), SEMO_GT, SEMO_LIT_INT(9007199254740992))); /* exact */
    CHECK(semo_value_numbers(SEMO_LIT_REAL(2.5), SEMO_EQ, SEMO_LIT_REAL(2.50)));
    CHECK(semo_value_numbers(SEMO_LIT_INT(-1000), SEMO_LE, SEMO_LIT_REAL(-999.5))); /* an integer and a real */
    CHECK(!semo_value_numbers(SEMO_LIT("5"), SEMO_EQ, SEMO_LIT_INT(5))); /* text is no number: false */
    CHECK(!semo_value_numbers(SEMO_LIT_BOOL(true), SEMO_GE, SEMO_LIT_INT(1)));
    a.type = SEMO_NONE;
    CHECK(!semo_value_numbers(&a, SEMO_NE, SEMO_LIT_INT(1))); /* none: false */
    CHECK(semo_value_words(SEMO_LIT_INT(10), SEMO_EQ, SEMO_LIT_REAL(10.0))); /* numbers by value */
    CHECK(semo_value_words(SEMO_LIT("LEFT"), SEMO_EQ, SEMO_LIT("LEFT")));
    CHECK(semo_value_words(SEMO_LIT("5"), SEMO_NE, SEMO_LIT_INT(5))); /* other types differ */
    CHECK(semo_value_words(&a, SEMO_EQ, &a) && semo_value_words(&a, SEMO_NE, SEMO_LIT("")));
    CHECK(!semo_value_words(SEMO_LIT("A"), SEMO_LT, SEMO_LIT("B"))); /* never ordered */
    CHECK(semo_value_truthy(SEMO_LIT_BOOL(true)));
    CHECK(semo_value_truthy(SEMO_LIT_INT(2)));
    CHECK(semo_value_truthy(SEMO_LIT_REAL(-0.5)));
    CHECK(!semo_value_truthy(SEMO_LIT_INT(0)));
    CHECK(!semo_value_truthy(SEMO_LIT_BOOL(false)));
    CHECK(!semo_value_truthy(SEMO_LIT("true"))); /* text is not a truth value */
    CHECK(!semo_value_truthy(&a));
    /* Text read as a type (scenario values, operator commands). */
    CHECK(semo_value_parse(&b, SEMO_INT, "-42") && b.type == SEMO_INT && b.i == -42);
    CHECK(semo_value_parse(&b, SEMO_INT, "9223372036854775807") && b.i == INT64_MAX);
    CHECK(!semo_value_parse(&b, SEMO_INT, "9223372036854775808")); /* beyond int64 */
    CHECK(!semo_value_parse(&b, SEMO_INT, "2.5") && !semo_value_parse(&b, SEMO_INT, " 5"));
    CHECK(semo_value_parse(&b, SEMO_REAL, "-1e3") && b.type == SEMO_REAL && b.r == -1000.0);
    CHECK(!semo_value_parse(&b, SEMO_REAL, "5,5"));
    CHECK(semo_value_parse(&b, SEMO_BOOL, "true") && b.type == SEMO_BOOL && b.b);
    CHECK(!semo_value_parse(&b, SEMO_BOOL, "TRUE"));
    CHECK(!semo_value_parse(&b, SEMO_WORD, "LEFT")); /* no program: no words */
    semo_value_set(&b, "7");
    CHECK(semo_value_coerce(&b, SEMO_INT) && b.type == SEMO_INT && b.i == 7);
    CHECK(semo_value_coerce(&b, SEMO_REAL) && b.type == SEMO_REAL && b.r == 7.0); /* widened */
    CHECK(!semo_value_coerce(&b, SEMO_INT) && !semo_value_coerce(&b, SEMO_TEXT));
    CHECK(semo_value_coerce(&b, SEMO_NONE)); /* a team variable takes any type */
    /* JSON keeps the value's type; reals print as refine::value::format_real. */
    semo_value_set_int(&b, INT64_MIN);
    CHECK(semo_value_json(&b, json, sizeof json) == 20 && strcmp(json, "-9223372036854775808") == 0);
    semo_value_set_real(&b, 2.0);
    CHECK(semo_value_json(&b, json, sizeof json) > 0 && strcmp(json, "2.0") == 0);
    semo_value_set_real(&b, 1.0 / 3.0);
    CHECK(semo_value_json(&b, json, sizeof json) > 0 && strcmp(json, "0.333333") == 0);
    semo_value_set_real(&b, 9.3e12); /* scaled by 10^6, beyond int64 */
    CHECK(semo_value_json(&b, json, sizeof json) > 0 && strcmp(json, "9300000000000.0") == 0);
    semo_value_set_real(&b, -1.5e20);
    CHECK(semo_value_json(&b, json, sizeof json) > 0 && strcmp(json, "-150000000000000e6") == 0);
    semo_value_set_real(&b, 1.0 / 0.0);
    CHECK(semo_value_json(&b, json, sizeof json) > 0 && strcmp(json, "null") == 0);
    semo_value_set_bool(&b, false);
    CHECK(semo_value_json(&b, json, sizeof json) > 0 && strcmp(json, "false") == 0);
    CHECK(semo_value_json(SEMO_LIT("a\"b"), json, sizeof json) > 0 && strcmp(json, "\"a\\\"b\"") == 0);
    CHECK(semo_value_json(&a, json, sizeof json) > 0 && strcmp(json, "null") == 0);
    CHECK(semo_value_json(SEMO_LIT("abcdef"), json, 4) == 3 && strcmp(json, "\"ab") == 0); /* cut to fit */
    semo_value_set(&a, NULL);
    CHECK(a.type == SEMO_TEXT && strcmp(a.text, "") == 0);
    /* Truncation keeps whole UTF-8 characters: 62 ASCII bytes + "é" does not fit. */
    char long_text[80];
    memset(long_text, 'x', 62);
    strcpy(long_text + 62, "\xc3\xa9yy");
    semo_value_set(&a, long_text);
    CHECK(strlen(a.text) == 62);
    memset(long_text, 'y', 79);
    long_text[79] = '\0';
    semo_value_set(&a, long_text);
    CHECK(strlen(a.text) == SEMO_TEXT_MAX - 1);
    semo_value_set(&a, a.text + 1); /* overlapping source */
    CHECK(strlen(a.text) == SEMO_TEXT_MAX - 2);
    /* Outside semo_main every call fails softly. */
    CHECK(UFPort_Initialize("A", "B") == -1);
    CHECK(UFControl_RunTask("A") == -1);
    CHECK(semo_program() == NULL);
    return atomic_load(&failures) ? 1 : 0;
}

/* ----------------------------------------------------------------- tasks */

enum { CH_SENSOR_FILTER, CH_FILTER_CONTROL, CH_LOOP, CH_SPILL };

static const semo_channel_desc task_channels[] = {
    [CH_SENSOR_FILTER] = {"Sensor", "OUT", "Filter", "IN", sizeof(int), 4, 0, NULL, NULL},
    [CH_FILTER_CONTROL] = {"Filter", "OUT", "Control", "VALUE", sizeof(int), 64, 0, NULL, NULL},
    [CH_LOOP] = {"Control", "LOOP_OUT", "Control", "LOOP_IN", sizeof(long long), 3, 2, NULL, NULL},
    [CH_SPILL] = {"Control", "SPILL", "Sink", "IN", sizeof(int), 2, 0, NULL, NULL},
};
static const semo_multicast_desc task_groups[] = {{"latest", sizeof(int)}, {"empty", sizeof(int)}};

/* Only the owning task thread writes these; main reads them after semo_main
 * has joined the threads. */
static int sensor_firings;
static long long sensor_starts[512];
static int filter_in, filter_out;
static atomic_int inits, wrapups, worker_firings;
static atomic_llong worker_speed;
static atomic_bool long_worker_began, long_worker_ended;

static void count_init(void) { atomic_fetch_add(&inits, 1); }
static void count_wrapup(void) { atomic_fetch_add(&wrapups, 1); }

static void sensor_go(void)
{
    int n = ++sensor_firings;
    if (n <= 512)
        sensor_starts[n - 1] = (long long)semo_now_ms();
    UFPort_WriteToQueue(UFPort_Initialize("Sensor", "OUT"), &n, sizeof n);
}

static void filter_init(void)
{
    count_init();
    filter_in = UFPort_Initialize("Filter", "IN");
    filter_out = UFPort_Initialize("Filter", "OUT");
}

static void filter_go(void)
{
    int n;
    if (UFPort_ReadFromQueue(filter_in, &n, sizeof n) != (int)sizeof n)
        return; /* the program is stopping */
    UFMulticast_Write("latest", &n, sizeof n);
    n *= 2;
    UFPort_WriteToQueue(filter_out, &n, sizeof n);
}

static void worker_go(void)
{
    atomic_fetch_add(&worker_firings, 1);
    atomic_store(&worker_speed, UFTask_GetIntegerParameter("Worker", "speed"));
    semo_sleep_ms(2);
}

static void long_worker_go(void)
{
    atomic_store(&long_worker_began, true);
    while (!UFControl_StopRequested("LongWorker"))
        semo_sleep_ms(1);
    atomic_store(&long_worker_ended, true);
}

static void check_channels(void)
{
    CHECK(UFPort_Initialize("Filter", "IN") == CH_SENSOR_FILTER);
    CHECK(UFPort_Initialize("Sensor", "OUT") == CH_SENSOR_FILTER);
    CHECK(UFPort_Initialize("Control", "VALUE") == CH_FILTER_CONTROL);
    CHECK(UFPort_Initialize("Control", "NOPE") == -1);
    CHECK(UFPort_Initialize("Nobody", "OUT") == -1);

    /* Initial samples are there, zero-filled, before anyone writes. */
    int loop_in = UFPort_Initialize("Control", "LOOP_IN");
    CHECK(loop_in == CH_LOOP && UFPort_Initialize("Control", "LOOP_OUT") == CH_LOOP);
    CHECK(UFPort_GetNumOfAvailableData(loop_in) == 2);
    long long x = 7;
    CHECK(UFPort_ReadFromQueue(loop_in, &x, 4) == 0); /* wrong sample size */
    CHECK(UFPort_ReadFromQueue(loop_in, &x, sizeof x) == (int)sizeof x && x == 0);
    x = 7;
    CHECK(UFPort_ReadFromQueue(loop_in, &x, sizeof x) == (int)sizeof x && x == 0);
    x = 42;
    CHECK(UFPort_WriteToQueue(loop_in, &x, sizeof x) == (int)sizeof x);
    x = 0;
    CHECK(UFPort_ReadFromQueue(loop_in, &x, sizeof x) == (int)sizeof x && x == 42);
    CHECK(UFPort_GetNumOfAvailableData(loop_in) == 0);

    /* A full channel drops (and counts) instead of blocking the writer. */
    int spill = UFPort_Initialize("Control", "SPILL"), one = 1;
    CHECK(UFPort_WriteToQueue(spill, &one, sizeof one) == (int)sizeof one);
    CHECK(UFPort_WriteToQueue(spill, &one, sizeof one) == (int)sizeof one);
    CHECK(UFPort_WriteToQueue(spill, &one, sizeof one) == 0);
    CHECK(UFPort_GetNumOfAvailableData(spill) == 2);

    CHECK(UFPort_GetNumOfAvailableData(-1) == -1);
    CHECK(UFPort_GetNumOfAvailableData(99) == -1);
    CHECK(UFPort_WriteToQueue(99, &one, sizeof one) == 0);
    CHECK(UFPort_ReadFromQueue(-1, &one, sizeof one) == 0);

    /* Sensor (time) → Filter (data) → here: the doubled counter, in order. */
    int value = UFPort_Initialize("Control", "VALUE"), previous = 0;
    for (int i = 0; i < 5; i++) {
        int v = -1;
        CHECK(UFPort_ReadFromQueue(value, &v, sizeof v) == (int)sizeof v);
        CHECK(v % 2 == 0 && v > previous);
        if (i == 0)
            CHECK(v == 2);
        previous = v;
    }

    int latest = 0;
    CHECK(UFMulticast_Read("latest", &latest, sizeof latest) == (int)sizeof latest && latest >= 5);
    CHECK(UFMulticast_Read("latest", &latest, 2) == 0);
    CHECK(UFMulticast_Read("empty", &latest, sizeof latest) == 0);
    CHECK(UFMulticast_Read("nothing", &latest, sizeof latest) == 0);
    CHECK(UFMulticast_Write("empty", &latest, sizeof latest) == (int)sizeof latest);
    CHECK(UFMulticast_Read("empty", &latest, sizeof latest) == (int)sizeof latest);
}

/* Firings are counted within a generous bound, so that a loaded machine
 * slows the test down instead of failing it. */
static bool worker_fires_past(int count)
{
    for (int i = 0; i < 5000 && atomic_load(&worker_firings) <= count; i++)
        semo_sleep_ms(1);
    return atomic_load(&worker_firings) > count;
}

static void check_control(void)
{
    CHECK(UFControl_GetTaskState("Worker") == SEMO_TASK_IDLE);
    CHECK(UFTask_SetIntegerParameter("Worker", "speed", 7) == 0);
    CHECK(UFTask_GetIntegerParameter("Worker", "speed") == 7);
    CHECK(UFTask_GetIntegerParameter("Worker", "other") == 0);
    CHECK(UFTask_SetIntegerParameter("Nobody", "speed", 7) == -1);

    /* CallTask: exactly one firing, then idle. */
    CHECK(UFControl_CallTask("Worker") == 0);
    CHECK(UFControl_WaitIdle("Worker", 5000));
    CHECK(atomic_load(&worker_firings) == 1);
    CHECK(atomic_load(&worker_speed) == 7);
    semo_sleep_ms(20);
    CHECK(atomic_load(&worker_firings) == 1);

    /* RunTask: firings until suspended; none while suspended. */
    CHECK(UFControl_RunTask("Worker") == 0);
    CHECK(worker_fires_past(3));
    CHECK(UFControl_SuspendTask("Worker") == 0);
    CHECK(UFControl_GetTaskState("Worker") == SEMO_TASK_SUSPENDED);
    /* A firing under way has counted itself already; no new one begins. */
    int frozen = atomic_load(&worker_firings);
    semo_sleep_ms(20);
    CHECK(atomic_load(&worker_firings) == frozen);
    CHECK(UFControl_ResumeTask("Worker") == 0);
    CHECK(UFControl_GetTaskState("Worker") == SEMO_TASK_RUNNING);
    CHECK(worker_fires_past(frozen));

    /* StopTask: idle after the current firing, and it stays idle. */
    CHECK(UFControl_StopTask("Worker") == 0);
    CHECK(UFControl_WaitIdle("Worker", 5000));
    int stopped = atomic_load(&worker_firings);
    semo_sleep_ms(20);
    CHECK(atomic_load(&worker_firings) == stopped);
    CHECK(!UFControl_StopRequested("Worker"));

    /* Stopping a suspended task makes it idle too. */
    UFControl_RunTask("Worker");
    semo_sleep_ms(5);
    UFControl_SuspendTask("Worker");
    UFControl_StopTask("Worker");
    CHECK(UFControl_WaitIdle("Worker", 5000));

    /* A long body polls StopRequested. */
    CHECK(UFControl_CallTask("LongWorker") == 0);
    /* (Stopped before its firing began, it would just go idle.) */
    for (int i = 0; i < 5000 && !atomic_load(&long_worker_began); i++)
        semo_sleep_ms(1);
    CHECK(UFControl_GetTaskState("LongWorker") == SEMO_TASK_RUNNING);
    CHECK(!UFControl_WaitIdle("LongWorker", 5)); /* times out: still running */
    UFControl_StopTask("LongWorker");
    CHECK(UFControl_WaitIdle("LongWorker", 5000));
    CHECK(atomic_load(&long_worker_ended));

    CHECK(UFControl_RunTask("Nobody") == -1);
    CHECK(UFControl_CallTask("Nobody") == -1);
    CHECK(UFControl_StopTask("Nobody") == -1);
    CHECK(UFControl_SuspendTask("Nobody") == -1);
    CHECK(UFControl_ResumeTask("Nobody") == -1);
    CHECK(!UFControl_WaitIdle("Nobody", 1));
}

static void check_timers_and_time(void)
{
    int id = UFTimer_Set(30, SEMO_MSEC);
    CHECK(id >= 0);
    CHECK(!UFTimer_GetAlarmed(id));
    int hour = UFTimer_Set(1, SEMO_HOUR);
    CHECK(hour >= 0 && hour != id);
    int64_t before = semo_now_ms();
    semo_sleep_ms(40);
    CHECK(semo_now_ms() - before >= 40);
    CHECK(UFTimer_GetAlarmed(id));
    CHECK(UFTimer_GetAlarmed(id)); /* stays alarmed */
    CHECK(!UFTimer_GetAlarmed(hour));
    UFTimer_Cancel(id);
    CHECK(!UFTimer_GetAlarmed(id));
    CHECK(UFTimer_Set(-1, SEMO_SEC) == -1);
    CHECK(UFTimer_Set(1, (semo_time_unit)42) == -1);
    CHECK(!UFTimer_GetAlarmed(-3) && !UFTimer_GetAlarmed(1000));
    int ids[20];
    for (int i = 0; i < 20; i++) {
        ids[i] = UFTimer_Set(0, SEMO_MSEC);
        CHECK(ids[i] >= 0 && UFTimer_GetAlarmed(ids[i]));
        for (int j = 0; j < i; j++)
            CHECK(ids[j] != ids[i]);
    }
    for (int i = 0; i < 20; i++)
        UFTimer_Cancel(ids[i]);
    UFTimer_Cancel(hour);
}

static void control_go(void)
{
    CHECK(semo_program() != NULL && strcmp(semo_program()->robot, "r1") == 0);
    check_channels();
    check_control();
    check_timers_and_time();
    semo_trace("note", "text", "quote\" backslash\\ newline\n tab\t ctl\x01 \xc3\xa9 bad\xff\xc3 end", NULL);
    semo_trace("note", "text", NULL);
    /* Group services: no group until the control task sets one; a change is
     * traced once. */
    CHECK(semo_group_rank() == -1 && semo_group_size() == 0);
    semo_group_set(2, 3);
    semo_group_set(2, 3);
    CHECK(semo_group_rank() == 2 && semo_group_size() == 3);
    semo_group_set(1, 2);
    CHECK(semo_group_rank() == 1 && semo_group_size() == 2);
    CHECK(semo_comm_send("USER", SEMO_MSG_SEND, "Team.STATUS", SEMO_LIT("ok")) == 1);
    /* Words: indices into the program's table, compared by identity, a word
     * and a text by their text; traced and sent as their text. */
    semo_value w;
    CHECK(semo_value_parse(&w, SEMO_WORD, "RIGHT") && w.type == SEMO_WORD && w.word == 1);
    CHECK(!semo_value_parse(&w, SEMO_WORD, "UP"));
    CHECK(semo_value_words(&w, SEMO_EQ, SEMO_LIT_WORD(1)) && semo_value_words(&w, SEMO_NE, SEMO_LIT_WORD(0)));
    CHECK(semo_value_words(&w, SEMO_EQ, SEMO_LIT("RIGHT")));
    semo_value_set(&w, "LEFT");
    CHECK(semo_value_coerce(&w, SEMO_WORD) && w.type == SEMO_WORD && w.word == 0);
    CHECK(semo_value_coerce(&w, SEMO_TEXT) && w.type == SEMO_TEXT && strcmp(w.text, "LEFT") == 0);
    /* A received word must be one of its key's enumeration (CommReceive). */
    static const unsigned short only_right[] = {1};
    CHECK(semo_value_in(SEMO_LIT_WORD(1), only_right, 1));
    CHECK(!semo_value_in(SEMO_LIT_WORD(0), only_right, 1));
    CHECK(semo_value_in(SEMO_LIT_WORD(0), NULL, 0) && semo_value_in(SEMO_LIT("LEFT"), only_right, 1));
    CHECK(semo_comm_send("USER", SEMO_MSG_SEND, "Team.TURN", SEMO_LIT_WORD(1)) == 1);
    CHECK(semo_comm_send("USER", SEMO_MSG_SEND, "Team.COUNT", SEMO_LIT_INT(-3)) == 1);
    CHECK(semo_comm_send("Other", SEMO_MSG_SEND, "Team.STATUS", SEMO_LIT("ok")) == -1); /* no transport */
    semo_stop_program();
    CHECK(!semo_running());
}

static const semo_task_desc task_tasks[] = {
    {"Sensor", SEMO_TRIGGER_TIME, 10, count_init, sensor_go, count_wrapup},
    {"Filter", SEMO_TRIGGER_DATA, 0, filter_init, filter_go, count_wrapup},
    {"Worker", SEMO_TRIGGER_CONTROL, 0, count_init, worker_go, count_wrapup},
    {"LongWorker", SEMO_TRIGGER_CONTROL, 0, NULL, long_worker_go, NULL},
    {"Control", SEMO_TRIGGER_TIME, 100000, count_init, control_go, count_wrapup},
};

static const char *const task_words[] = {"LEFT", "RIGHT"};

static int run_tasks(int argc, char **argv)
{
    const semo_program_desc program = {
        .receives = true, /* its tasks may take messages (semo_comm_poll) */
        SIM_WORLD
        .words = task_words,
        .word_count = 2,
        .mission = "test.mission",
        .team = "TestTeam",
        .robot = "r1",
        .robot_type = "TestBot",
        .tasks = task_tasks,
        .task_count = sizeof task_tasks / sizeof task_tasks[0],
        .channels = task_channels,
        .channel_count = sizeof task_channels / sizeof task_channels[0],
        .groups = task_groups,
        .group_count = sizeof task_groups / sizeof task_groups[0],
    };
    int status = semo_main(argc, argv, &program);
    CHECK(status == 0);
    CHECK(atomic_load(&inits) == 4 && atomic_load(&wrapups) == 4);
    CHECK(sensor_firings >= 5);
    /* A time-driven task never fires before its period since the last start:
     * firing n starts at mission time >= 10 (n - 1). (Single intervals can
     * look shorter: the task reads the clock a little after its release.) */
    int n = sensor_firings < 512 ? sensor_firings : 512;
    CHECK(sensor_starts[n - 1] >= 10LL * (n - 1));
    CHECK(UFControl_GetTaskState("Worker") == SEMO_TASK_IDLE); /* program gone */
    return atomic_load(&failures) ? 1 : status;
}

/* --------------------------------------------------------------- minimal */

/* The smallest program: one idle task. For option handling and memory use. */
static void nothing(void) {}
static const semo_task_desc minimal_tasks[] = {{"Idle", SEMO_TRIGGER_CONTROL, 0, NULL, nothing, NULL}};
static const semo_peer minimal_peers[] = {{"SoloTeam", "solo", 0}};

static int run_minimal(int argc, char **argv)
{
    const semo_program_desc program = {
        .receives = true,
        SIM_WORLD
        .mission = "minimal.mission",
        .team = "SoloTeam",
        .robot = "solo",
        .robot_type = "TestBot",
        .tasks = minimal_tasks,
        .task_count = 1,
        .peers = minimal_peers,
        .peer_count = 1,
        .robot_count = 1,
    };
    return semo_main(argc, argv, &program);
}

/* ------------------------------------------------------------------ wake */

/* A time-driven task that asks to fire only on events (semo_next_firing with
 * INT64_MAX) fires once at start and once more when a sample arrives; it
 * does not poll at its 10 ms period in between. */
static atomic_int sleeper_firings, sleeper_samples;
static int sleeper_in = -1, poker_out = -1;

static void sleeper_go(void)
{
    atomic_fetch_add(&sleeper_firings, 1);
    int sample;
    while (UFPort_GetNumOfAvailableData(sleeper_in) > 0 && UFPort_ReadFromQueue(sleeper_in, &sample, sizeof sample) > 0)
        atomic_fetch_add(&sleeper_samples, 1);
    semo_next_firing(INT64_MAX);
}

static void poker_go(void)
{
    static bool poked;
    if (!poked && semo_now_ms() >= 100) {
        int sample = 1;
        poked = UFPort_WriteToQueue(poker_out, &sample, sizeof sample) > 0;
    }
    if (semo_now_ms() >= 300)
        semo_stop_program();
}

static void wake_init(void)
{
    sleeper_in = UFPort_Initialize("Sleeper", "IN");
    poker_out = UFPort_Initialize("Poker", "OUT");
}

static const semo_task_desc wake_tasks[] = {
    {"Sleeper", SEMO_TRIGGER_TIME, 10, wake_init, sleeper_go, NULL},
    {"Poker", SEMO_TRIGGER_TIME, 10, NULL, poker_go, NULL},
};
static const semo_channel_desc wake_channels[] = {{"Poker", "OUT", "Sleeper", "IN", sizeof(int), 4, 0, NULL, NULL}};

static int run_wake(int argc, char **argv)
{
    const semo_program_desc program = {
        .receives = true,
        SIM_WORLD
        .mission = "wake.mission",
        .team = "SoloTeam",
        .robot = "solo",
        .robot_type = "TestBot",
        .tasks = wake_tasks,
        .task_count = 2,
        .channels = wake_channels,
        .channel_count = 1,
        .peers = minimal_peers,
        .peer_count = 1,
        .robot_count = 1,
    };
    int status = semo_main(argc, argv, &program);
    CHECK(atomic_load(&sleeper_samples) == 1);
    CHECK(atomic_load(&sleeper_firings) == 2);
    return atomic_load(&failures) ? 1 : status;
}


/* ------------------------------------------------------------------- udp */

/* Their mission has three robots; the one between them (place 1, port base
 * + 1) is not a peer of either: each robot's table lists only its own, with
 * their places. */
static const semo_peer udp_peers[] = {{"Alpha", "a", 0}, {"Beta", "b", 2}};

static void pinger_go(void)
{
    semo_message m;
    bool answered = false;
    for (int i = 0; i < 500 && !answered && semo_running(); i++) {
        semo_value n;
        semo_value_set_int(&n, i);
        CHECK(semo_comm_send("Beta", SEMO_MSG_SEND, "Alpha.PING", &n) == 1);
        /* Beta may not be listening yet: ask again until it answers. */
        while (!answered && semo_comm_poll(&m, 20) == 1)
            answered = strcmp(m.key, "Beta.PONG") == 0;
    }
    CHECK(answered);
    CHECK(strcmp(m.from_team, "Beta") == 0 && strcmp(m.from_robot, "b") == 0);
    CHECK(strcmp(m.value.text, "pong \"1\"") == 0 && m.kind == SEMO_MSG_SEND);
    CHECK(semo_comm_send("b", SEMO_MSG_PUBLISH, "Alpha.BYE", SEMO_LIT("bye")) == 1); /* by robot name */
    CHECK(semo_comm_send("Alpha", SEMO_MSG_SEND, "Alpha.SELF", SEMO_LIT("me")) == 0); /* not to itself */
    CHECK(semo_comm_send("Nobody", SEMO_MSG_SEND, "Alpha.X", SEMO_LIT("x")) == 0);
    CHECK(semo_comm_send("Beta", (semo_msg_kind)'z', "Alpha.X", SEMO_LIT("x")) == -1);
    CHECK(semo_comm_send("Beta", SEMO_MSG_SEND, "Alpha.THIS_KEY_IS_FAR_TOO_LONG_FOR_A_MESSAGE_KEY_0123456789_0123456789",
                         SEMO_LIT("x")) == -1);
    semo_stop_program();
}

static atomic_bool got_bye;

static void ponger_go(void)
{
    semo_message m;
    if (semo_comm_poll(&m, -1) != 1)
        return; /* stopping */
    if (strcmp(m.key, "Alpha.PING") == 0) {
        CHECK(strcmp(m.from_team, "Alpha") == 0 && strcmp(m.from_robot, "a") == 0);
        CHECK(semo_comm_send("Alpha", SEMO_MSG_SEND, "Beta.PONG", SEMO_LIT("pong \"1\"")) == 1);
    } else if (strcmp(m.key, "Alpha.BYE") == 0) {
        CHECK(m.kind == SEMO_MSG_PUBLISH && strcmp(m.value.text, "bye") == 0);
        atomic_store(&got_bye, true);
        semo_stop_program();
    }
}

static const semo_task_desc pinger_tasks[] = {{"Pinger", SEMO_TRIGGER_TIME, 100000, NULL, pinger_go, NULL}};
static const semo_task_desc ponger_tasks[] = {{"Ponger", SEMO_TRIGGER_DATA, 0, NULL, ponger_go, NULL}};

static int run_udp(int argc, char **argv, bool alpha)
{
    const semo_program_desc program = {
        .receives = true,
        SIM_WORLD
        .mission = "udp.mission",
        .team = alpha ? "Alpha" : "Beta",
        .robot = alpha ? "a" : "b",
        .robot_type = "TestBot",
        .tasks = alpha ? pinger_tasks : ponger_tasks,
        .task_count = 1,
        .peers = udp_peers,
        .peer_count = 2,
        .self = alpha ? 0 : 1,
        .robot_count = 3,
    };
    int status = semo_main(argc, argv, &program);
    if (!alpha)
        CHECK(atomic_load(&got_bye));
    return atomic_load(&failures) ? 1 : status;
}

/* ------------------------------------------------------------------- sim */

#ifdef SEMO_SIM
static bool saw_origin, saw_goal;
static char commands[16][SEMO_TEXT_MAX];
static int command_count;

static void location_go(void)
{
    semo_value v;
    int64_t before = semo_now_ms();
    bool known = semo_sim_sensor("LOCATION", SEMO_TEXT, &v);
    int64_t after = semo_now_ms();
    CHECK(known);
    if (after < 1500)
        CHECK(strcmp(v.text, "0,0") == 0);
    if (before >= 1500)
        CHECK(strcmp(v.text, "5,5") == 0);
    saw_origin |= strcmp(v.text, "0,0") == 0;
    saw_goal |= strcmp(v.text, "5,5") == 0;
    UFPort_WriteToQueue(UFPort_Initialize("Location", "OUT"), &v, sizeof v);
}

static void sim_control_go(void)
{
    semo_message m;
    semo_value location;
    int port = UFPort_Initialize("Control", "LOCATION");
    while (UFPort_GetNumOfAvailableData(port) > 0)
        CHECK(UFPort_ReadFromQueue(port, &location, sizeof location) == (int)sizeof location);
    if (semo_comm_poll(&m, 100) != 1)
        return;
    CHECK(strcmp(m.from_team, "USER") == 0 && strcmp(m.from_robot, "USER") == 0);
    CHECK(strcmp(m.key, "USER.RC_CMD") == 0);
    if (command_count < 16)
        memcpy(commands[command_count++], m.value.text, SEMO_TEXT_MAX);
    CHECK(m.value.type == SEMO_TEXT); /* the operator's commands come as text */
    if (strcmp(m.value.text, "AUTO_MODE") == 0) {
        semo_sim_actuate("Move", SEMO_LIT("5,5"));
        CHECK(semo_sim_service_ms("move") == 300);
        CHECK(semo_sim_service_ms("grab") == 100);
        semo_value v;
        CHECK(!semo_sim_sensor("NOPE", SEMO_TEXT, &v));
        CHECK(semo_sim_sensor("BATTERY", SEMO_INT, &v) && v.type == SEMO_INT && v.i == 97);
        CHECK(!semo_sim_sensor("LOCATION", SEMO_INT, &v)); /* "5,5" is no integer */
    }
    if (strcmp(m.value.text, "FINISH") == 0) {
        CHECK(semo_now_ms() >= 3000);
        semo_stop_program();
    }
}

static const semo_task_desc sim_tasks[] = {
    {"Location", SEMO_TRIGGER_TIME, 100, NULL, location_go, NULL},
    {"Control", SEMO_TRIGGER_DATA, 0, NULL, sim_control_go, NULL},
};
static const semo_channel_desc sim_channels[] = {
    {"Location", "OUT", "Control", "LOCATION", sizeof(semo_value), 8, 0, NULL, NULL},
};

static int run_sim(int argc, char **argv)
{
    const semo_program_desc program = {
        .receives = true,
        SIM_WORLD
        .mission = "remote.mission",
        .team = "RemoteTeam",
        .robot = "irobot",
        .robot_type = "iRobot",
        .tasks = sim_tasks,
        .task_count = 2,
        .channels = sim_channels,
        .channel_count = 1,
    };
    int status = semo_main(argc, argv, &program);
    if (status != 0)
        return status;
    static const char *const expected[] = {"NONE", "NONE", "AUTO_MODE", "NONE", "NONE", "NONE", "NONE", "FINISH"};
    CHECK(command_count == 8);
    for (int i = 0; i < command_count && i < 8; i++)
        if (strcmp(commands[i], expected[i]) != 0) {
            fprintf(stderr, "command %d: %s, expected %s\n", i, commands[i], expected[i]);
            CHECK(!"operator commands in scenario order");
        }
    CHECK(saw_origin && saw_goal);
    return atomic_load(&failures) ? 1 : 0;
}
#endif

/* ----------------------------------------------------------------- reals */

/* Each argument a double's bits in hexadecimal; prints each as a value's
 * JSON, one a line (tests/runtime_c.rs compares them with the simulator's). */
static int run_reals(int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        char *end;
        uint64_t bits = strtoull(argv[i], &end, 16);
        if (*end != '\0') {
            fprintf(stderr, "not hexadecimal bits: %s\n", argv[i]);
            return 64;
        }
        double x;
        memcpy(&x, &bits, sizeof x);
        semo_value v;
        semo_value_set_real(&v, x);
        char json[64];
        semo_value_json(&v, json, sizeof json);
        printf("%s\n", json);
    }
    return 0;
}

int main(int argc, char **argv)
{
    const char *mode = argc > 1 ? argv[1] : "";
    if (strcmp(mode, "values") == 0)
        return run_values();
    if (strcmp(mode, "tasks") == 0)
        return run_tasks(argc - 1, argv + 1);
    if (strcmp(mode, "minimal") == 0)
        return run_minimal(argc - 1, argv + 1);
    if (strcmp(mode, "wake") == 0)
        return run_wake(argc - 1, argv + 1);
    if (strcmp(mode, "reals") == 0)
        return run_reals(argc - 1, argv + 1);
    if (strcmp(mode, "udp-a") == 0 || strcmp(mode, "udp-b") == 0)
        return run_udp(argc - 1, argv + 1, mode[4] == 'a');
#ifdef SEMO_SIM
    if (strcmp(mode, "sim") == 0)
        return run_sim(argc - 1, argv + 1);
#endif
    fprintf(stderr, "usage: runtime_test values|tasks|minimal|wake|reals|udp-a|udp-b|sim [options]\n");
    return 64;
}
