#!/usr/bin/python3
"""A/B timing in interleaved rounds: runs COMMAND_A and COMMAND_B in turn (A B A B ...), ROUNDS times
each after one warm-up of each, and prints each command's median CPU seconds (user + system, the
kernel's accounting of the finished child) and the median, min and max of the per-round ratio A/B.
Pairing keeps the ratio meaningful when a shared machine's speed drifts; CPU time is steadier than
wall time on a loaded machine. Standard library only.

    /usr/bin/python3 bench/ab.py ROUNDS -- COMMAND_A ... -- COMMAND_B ...
"""
import os
import resource
import statistics
import subprocess
import sys


def cpu_of(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        sys.exit("ab.py: %s exited with %d" % (" ".join(cmd), r.returncode))
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    argv = sys.argv[1:]
    if len(argv) < 5 or argv[1] != "--" or "--" not in argv[2:]:
        sys.exit(__doc__)
    rounds = int(argv[0])
    rest = argv[2:]
    k = rest.index("--")
    a, b = rest[:k], rest[k + 1:]
    cpu_of(a), cpu_of(b)  # warm-up: page cache, plugin files
    ta, tb = [], []
    for i in range(rounds):
        ta.append(cpu_of(a))
        tb.append(cpu_of(b))
        print("round %d: A %.3f s  B %.3f s  A/B %.4f" % (i + 1, ta[-1], tb[-1], ta[-1] / tb[-1]), flush=True)
    r = [x / y for x, y in zip(ta, tb)]
    print("A median %.3f s, B median %.3f s; A/B median %.4f (min %.4f, max %.4f) over %d interleaved rounds"
          % (statistics.median(ta), statistics.median(tb), statistics.median(r), min(r), max(r), rounds))


if __name__ == "__main__":
    main()
