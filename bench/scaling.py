#!/usr/bin/python3
"""bench/scaling.py — thread and MPI rank scaling of `murk render`, and a model of 64 nodes.

    /usr/bin/python3 bench/scaling.py [--rounds 5] [--spp 16] [--res 256x192] [--scene scenes/cornell_smoke.yaml]

One command, run from the source tree after ./tools/build.sh (murk built with MPI; mpirun on PATH). It
renders the scene in every configuration below, in interleaved rounds (A B C ... A B C ...), and prints
per configuration the median and the min-max spread over the rounds of: the render time murk reports
(loading and MPI start-up excluded), the speed-up against one thread in the same round, and the CPU
seconds (user + system of every process, mpirun's included) per million samples — the cost of the work
itself, which preemption by other processes does not inflate — and the share of the render threads'
time spent inside tiles (murk:thread_time / (murk:threads x murk:render_time): 1 means no thread ever
waited for work, so the speed-up is the threads' count wherever each gets a core). Configurations
(ranks x threads):

    1x1, 1x2         plain `murk render --threads T` (the thread scaling 1 -> 2)
    mpi 1x2          mpirun -n 1 (MPI initialised, no other rank)
    mpi 2x1, 2x2     mpirun -n 2 --threads T (2x2 oversubscribes 2 cores: 4 render threads)
    mpi 4x1          mpirun -n 4 --oversubscribe

Every MPI run sets MURK_MPI_STATS=1, so rank 0 prints the overheads it measured: tiles handed to other
ranks, messages and bytes, and the CPU time its main thread spent handling them. From those and the
single-thread cost per sample the script states the expected efficiency at 64 nodes (model below).
Every configuration's image is checked against the single-thread one (murk compare: MSE 0; the bitwise
identity itself is what tests/test_mpi.c checks).

Root: Open MPI refuses to run as root without OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;
the script sets both. The machine's load matters: run it on an otherwise idle machine, and read the
CPU-per-sample column when it is not.
"""
import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MURK = os.path.join(ROOT, "build", "core", "murk")
TILE = 16


def children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def exr_attr(path, key):
    """A string attribute of an EXR header (murk writes murk:* as 'string' attributes)."""
    with open(path, "rb") as f:
        head = f.read(1 << 16)
    tag = key.encode() + b"\0string\0"
    i = head.find(tag)
    if i < 0:
        return None
    i += len(tag)
    n = int.from_bytes(head[i:i + 4], "little")
    return head[i + 4:i + 4 + n].decode()


def run(cmd, env):
    """Runs cmd; returns (render seconds, samples, cpu seconds, wall seconds, stats dict, output)."""
    c0, w0 = children_cpu(), time.monotonic()
    p = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall, cpu = time.monotonic() - w0, children_cpu() - c0
    if p.returncode != 0:
        sys.exit("failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stdout))
    m = re.search(r": (\d+)x(\d+), (\d+) spp, ([0-9.]+) s,", p.stdout)
    if not m:
        sys.exit("no summary line in:\n" + p.stdout)
    w, h, spp, secs = int(m.group(1)), int(m.group(2)), int(m.group(3)), float(m.group(4))
    stats = {}
    s = re.search(r"murk: mpi: (\d+) ranks, (\d+) passes, (\d+) tiles per pass, (\d+) tiles to other ranks, "
                  r"(\d+) messages, (\d+) bytes, rank 0 handled them in ([0-9.]+) CPU s", p.stdout)
    if s:
        keys = ["ranks", "passes", "ntiles", "tiles", "messages", "bytes", "serve_cpu"]
        stats = {k: float(v) for k, v in zip(keys, s.groups())}
    # the share of the render threads' time spent inside tiles: 1 = no thread ever waited for work
    out = cmd[cmd.index("-o") + 1]
    busy = float(exr_attr(out, "murk:thread_time")) / (int(exr_attr(out, "murk:threads")) * float(
        exr_attr(out, "murk:render_time")))
    stats["busy"] = busy
    return secs, w * h * spp, cpu, wall, stats, p.stdout


def med_spread(xs):
    return "%.3g (%.3g-%.3g)" % (statistics.median(xs), min(xs), max(xs))


def model(t_px, serve_us, bytes_per_tile, nodes=64, threads=32, pass_s=2.0):
    """Expected efficiency of `nodes` x `threads` on images of a few sizes (see the printed statement)."""
    lines = []
    for (w, h) in [(512, 512), (1920, 1080), (3840, 2160)]:
        ntiles = -(-w // TILE) * -(-h // TILE)
        pt = nodes * threads
        # a pass is sized to pass_s seconds of the whole job: n spp of every pixel
        n = max(1.0, pass_s * pt / (w * h * t_px))
        tau = n * TILE * TILE * t_px                    # one tile's render time in a pass
        q = ntiles / pt                                 # tiles per thread per pass
        # dynamic list scheduling of equal tiles: the last round of tiles is partly idle, and a tile
        # started last ends on average half a tile after the ideal end
        if q < 1:
            e_tail = q                                  # fewer tiles than threads: the rest idle
        else:
            e_tail = q / (-(-ntiles // pt) + 0.5)
        e_tail = min(1.0, e_tail)
        pass_wall = max(pass_s, tau)
        master = ntiles * serve_us * 1e-6 / pass_wall   # rank 0's main thread: fraction of one core
        # that core is taken from the job's render threads; beyond one core rank 0 cannot keep up and the
        # job goes at the pace it hands tiles out
        e_master = (1.0 - min(master, 1.0) / (nodes * threads)) * min(1.0, 1.0 / master)
        net_mb_s = ntiles * bytes_per_tile / pass_wall / 1e6
        lines.append("  %4dx%-4d %5d tiles, %5.1f tiles per thread per pass, tile %.3g s: efficiency %.0f%% "
                     "(pass tail %.0f%%, rank 0 busy %.1f%% of a core, %.0f MB/s through rank 0)"
                     % (w, h, ntiles, q, tau, 100 * e_tail * e_master, 100 * e_tail, 100 * master, net_mb_s))
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--res", default="256x192")
    ap.add_argument("--scene", default="scenes/cornell_smoke.yaml")
    a = ap.parse_args()
    w, h = a.res.split("x")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", MURK_MPI_STATS="1")
    tmp = tempfile.mkdtemp(prefix="murk-scaling-")
    scene = os.path.join(ROOT, a.scene)

    def murk(out, threads):
        return [MURK, "render", scene, "-o", os.path.join(tmp, out), "--spp", str(a.spp), "--set",
                "render.resolution=[%s,%s]" % (w, h), "--threads", str(threads)]

    def mpi(n, threads, out):
        return ["mpirun", "--oversubscribe", "--bind-to", "none", "-x", "MURK_MPI_STATS", "-n", str(n)] + murk(out, threads)

    configs = [("1x1", 1, 1, murk("t1.exr", 1)), ("1x2", 1, 2, murk("t2.exr", 2)),
               ("mpi 1x2", 1, 2, mpi(1, 2, "m12.exr")), ("mpi 2x1", 2, 1, mpi(2, 1, "m21.exr")),
               ("mpi 2x2", 2, 2, mpi(2, 2, "m22.exr")), ("mpi 4x1", 4, 1, mpi(4, 1, "m41.exr"))]
    res = {c[0]: [] for c in configs}
    for r in range(a.rounds):
        for name, _, _, cmd in configs:
            res[name].append(run(cmd, env))
            print("round %d %-8s %.2f s" % (r + 1, name, res[name][-1][0]), file=sys.stderr, flush=True)
    for name, _, _, cmd in configs[1:]:  # every configuration makes the same image
        out = cmd[cmd.index("-o") + 1]
        cmp = subprocess.run([MURK, "compare", out, os.path.join(tmp, "t1.exr")], stdout=subprocess.PIPE, text=True)
        if not cmp.stdout.startswith("MSE 0.000000e+00"):
            sys.exit("%s: not the single-thread image: %s" % (name, cmp.stdout))

    print("\n%s at %sx%s, %d spp, %d interleaved rounds on %d cores; median (min-max)\n"
          % (a.scene, w, h, a.spp, a.rounds, os.cpu_count()))
    print("| ranks x threads | render s | speed-up vs 1x1 (per round) | CPU s per Msample | threads busy (in tiles) | MPI: passes, tiles to other ranks, bytes per tile, rank-0 CPU us per tile |")
    print("|---|---|---|---|---|---|")
    base = [x[0] for x in res["1x1"]]
    for name, ranks, threads, _ in configs:
        xs = res[name]
        secs = [x[0] for x in xs]
        speed = [b / s for b, s in zip(base, secs)]
        cpu = [x[2] / (x[1] / 1e6) for x in xs]
        st = [x[4] for x in xs if "tiles" in x[4]]
        busy = [x[4]["busy"] for x in xs]
        mpi_s = "-"
        if st and st[0]["tiles"] > 0:
            mpi_s = "%d, %d, %.0f, %s" % (st[0]["passes"], st[0]["tiles"], st[0]["bytes"] / (2 * st[0]["tiles"]),
                                          med_spread([s["serve_cpu"] / s["tiles"] * 1e6 for s in st]))
        print("| %s | %s | %s | %s | %s | %s |" % (name, med_spread(secs), med_spread(speed), med_spread(cpu),
                                                  med_spread(busy), mpi_s))

    # the model's inputs: one thread's CPU per sample, rank 0's CPU per remote tile, bytes per tile
    t_px = statistics.median([x[2] / x[1] for x in res["1x1"]])
    st = [x[4] for x in res["mpi 2x1"] if x[4].get("tiles", 0) > 0]
    serve_us = statistics.median([s["serve_cpu"] / s["tiles"] * 1e6 for s in st])
    bytes_tile = 16 + 8 + 2 * TILE * TILE * (3 * 8 + 4)
    print("\nModel of 64 nodes x 32 threads (2 s passes, as murk sizes them under MPI):")
    print("  inputs measured here: %.3g CPU us per sample (1x1), %.1f CPU us of rank 0 per tile handed out and "
          "taken back (mpi 2x1, median); %d bytes per tile and pass (state both ways, 2 messages); the "
          "message latency is hidden by the one tile each rank holds in reserve while it is below a tile's "
          "render time" % (t_px * 1e6, serve_us, bytes_tile))
    for line in model(t_px, serve_us, bytes_tile):
        print(line)


if __name__ == "__main__":
    main()
