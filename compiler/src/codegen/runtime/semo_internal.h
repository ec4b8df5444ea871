/* semo_internal.h: what the runtime's own files share (not for task code).
 *
 * semo_runtime.c owns the clock, the run state and the message queue;
 * semo_sim.c (built with -DSEMO_SIM) reads the scenario and feeds operator
 * commands into that queue.
 */
#ifndef SEMO_INTERNAL_H
#define SEMO_INTERNAL_H

#include "semo_runtime.h"

/* Waits until mission time `deadline_ms`; false when the program stopped first. */
bool semo__wait_until(int64_t deadline_ms);
/* Queues a message as if it had arrived over the transport. */
void semo__deliver(const semo_message *msg);

/* The time scales accepted (wall ms per mission ms), from the command line or
 * a scenario: a million times faster to a million times slower. Beyond them
 * mission times no longer fit the clock's arithmetic (1e-18 would overflow
 * the conversion to int64_t), and no simulation needs them. */
#define SEMO_TIME_SCALE_MIN 1e-6
#define SEMO_TIME_SCALE_MAX 1e6

#ifdef SEMO_SIM
/* Reads the scenario for `program->robot`; on error prints
 * "scenario FILE:LINE:COL: message" and returns -1. */
int semo__sim_load(const char *path, const semo_program_desc *program);
/* The scenario's settings; false when it gives none. */
bool semo__sim_time_scale(double *out);
bool semo__sim_duration(int64_t *out);
/* Starts and stops the thread that injects the operator's commands. */
int semo__sim_start(void);
void semo__sim_stop(void);
void semo__sim_free(void);
#endif

#endif /* SEMO_INTERNAL_H */
