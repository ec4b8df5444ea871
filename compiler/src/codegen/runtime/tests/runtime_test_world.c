/* runtime_test_world.c: the simulated world of runtime_test.c's sim builds,
 * as `semo build --scenario FILE` compiles a robot's world into scenario.c
 * (semo__sim_tables, semo_internal.h): the runtime reads no scenario file.
 *
 * With -DRUNTIME_TEST_WORLD: robot irobot's world of a scenario
 *   {"time_scale": 0.05, "duration": 20000,
 *    "robots": {"irobot": {"sensors": [{"at": 0, "value": "LOCATION", "is": "0,0"},
 *                                      {"at": 1500, "value": "LOCATION", "is": "5,5"},
 *                                      {"at": 0, "value": "BATTERY", "is": 97}],
 *                          "services": {"move": 300}}},
 *    "operator": [{"at": 500, "to": "irobot", "value": "RC_CMD", "is": "AUTO_MODE"},
 *                 {"every": 400, "from": 0, "until": 2000, "to": "RemoteTeam", "value": "RC_CMD", "is": "NONE"},
 *                 {"at": 3000, "to": "irobot", "value": "RC_CMD", "is": "FINISH"}]}
 * (mode `sim`); without it, a scenario with nothing in it.
 */
#include "../semo_internal.h"

#if defined(SEMO_SIM) && defined(RUNTIME_TEST_WORLD)
static const semo__sim_sensor_entry sensors[] = {
    {0, "LOCATION", "0,0"},
    {1500, "LOCATION", "5,5"},
    {0, "BATTERY", "97"},
};
static const semo__sim_service_entry services[] = {
    {"move", 300},
};
static const semo__sim_command_entry operator_commands[] = {
    {500, 0, 500, "USER.RC_CMD", "AUTO_MODE"},
    {0, 400, 2000, "USER.RC_CMD", "NONE"},
    {3000, 0, 3000, "USER.RC_CMD", "FINISH"},
};
static int64_t operator_next[3];

const semo__sim_tables semo__scenario = {
    .duration_ms = 20000,
    .sensors = sensors,
    .sensor_count = 3,
    .services = services,
    .service_count = 1,
    .operator_commands = operator_commands,
    .operator_next = operator_next,
    .operator_count = 3,
    .time_scale = 0.05,
};
#elif defined(SEMO_SIM)
const semo__sim_tables semo__scenario = {.duration_ms = 0};
#else
/* ISO C wants at least one declaration in a translation unit. */
typedef int runtime_test_world_unused;
#endif
