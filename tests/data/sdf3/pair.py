#!/usr/bin/env python3
"""Whole-process CPU time of commands run side by side, paired.

    python3 pair.py N 'REFERENCE COMMAND' 'COMMAND' ['COMMAND' ...]

Runs every command once to warm up, then N rounds, each running all of them
in turn (the order reversed every other round, so neither is always first).
A run's time is its user plus system CPU time, from the kernel's accounting
of finished children (microseconds, where a timer in whole milliseconds
cannot tell 8 ms from 9 on a 10 ms process). Prints each command's median
and, for every command after the first, the median (min-max) of its ratio to
the first within each round. Standard output and error are discarded.
"""

import resource
import shlex
import statistics
import subprocess
import sys


def cpu_seconds(command):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    rounds = int(sys.argv[1])
    commands = [shlex.split(c) for c in sys.argv[2:]]
    for command in commands:
        cpu_seconds(command)
    times = [[] for _ in commands]
    for i in range(rounds):
        order = range(len(commands)) if i % 2 == 0 else reversed(range(len(commands)))
        for k in order:
            times[k].append(cpu_seconds(commands[k]))
    for k, command in enumerate(commands):
        print(f"{k}: median {statistics.median(times[k]) * 1000:.2f} ms  {' '.join(command)}")
    for k in range(1, len(commands)):
        ratios = [a / b for a, b in zip(times[k], times[0]) if b > 0]
        print(
            f"{k}/0: {statistics.median(ratios):.3f} ({min(ratios):.3f}-{max(ratios):.3f})"
        )


if __name__ == "__main__":
    main()
