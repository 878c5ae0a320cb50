#!/usr/bin/python3
"""ray_budget.py — where murk's instructions per ray go, from a callgrind profile of one render.

    meson setup build-prof --buildtype=release -Dc_args=-g && ninja -C build-prof
    /usr/bin/python3 bench/ray_budget.py [--build build-prof] [--spp 4] [--res 128] [--detail] [scene.yaml] [--set K=V ...]

Runs `valgrind --tool=callgrind` on `murk render --threads 1` of the scene (default scenes/cornell.yaml),
collecting only inside the render threads (`--toggle-collect=worker`: no scene loading, no image
writing), keeps each instruction's own cost, maps it to the innermost function it was inlined from
(`addr2line -i`, so the build needs -g; release optimisation keeps the inlining of a real build) and
adds them up per part of murk: Embree, the integrator (pathtracer.c), the sampler (math.h's inline
hashing), the host (host.c), lights.c, the material, the render loop. Divided by the rays murk counted
(every intersect() and occluded() call). Instruction counts are not time (Embree's SIMD code does more per
instruction than murk's scalar code), but they are deterministic, so two builds compare exactly; confirm a
gain in time with bench/embree_throughput. Needs valgrind and binutils (addr2line).
"""
import argparse, collections, os, re, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SAMPLER = {'murk_hash64', 'murk_lk_hash_', 'murk_reverse_bits32', 'murk_sobol1_reversed', 'murk_u24_',
           'murk_sample_slot_', 'murk_sample_2d', 'murk_sample_1d', 'murk_sampler_start', 'murk_rng_seed',
           'murk_rng_u32', 'murk_rng_float', 'murk_sample_seek'}
# a source file on the inlining chain -> its group (the innermost match wins); the sampler's functions first
FILES = [('pathtracer.c', 'integrator (pathtracer.c and what it inlines)'),
         ('host.c', 'host (host.c: ray checks, Embree call set-up, filling murk_hit)'),
         ('lights.c', 'lights (lights.c)'), ('render.c', 'render loop (render.c: camera ray, film)')]


def profile(args):
    out = tempfile.NamedTemporaryFile(prefix='ray_budget.', suffix='.cg', delete=False).name
    exr = tempfile.NamedTemporaryFile(prefix='ray_budget.', suffix='.exr', delete=False).name
    cmd = ['valgrind', '--tool=callgrind', '--dump-instr=yes', '--compress-pos=no', '--compress-strings=no',
           '--toggle-collect=worker', '--callgrind-out-file=' + out, os.path.join(args.build, 'core', 'murk'),
           'render', args.scene, '--threads', '1', '--spp', str(args.spp),
           '--set', 'render.resolution=[%d,%d]' % (args.res, args.res), '-o', exr]
    for kv in args.set:
        cmd += ['--set', kv]
    r = subprocess.run(cmd, capture_output=True, text=True)
    m = re.search(r'(\d+) rays traced', r.stdout + r.stderr)
    if r.returncode != 0 or not m:
        sys.exit('ray_budget: the render failed:\n' + r.stderr[-2000:])
    for f in (exr, exr[:-4] + '.png'):
        if os.path.exists(f):
            os.unlink(f)
    return out, int(m.group(1))


def read_costs(path):
    """{object: {address: own instructions}} and {(object, address): function name}."""
    cost = collections.defaultdict(collections.Counter)
    fn_at = {}
    ob = fn = None
    after_call = False
    for line in open(path):
        if line.startswith('ob='):
            ob = line[3:].strip()
        elif line.startswith('fn='):
            fn = line[3:].strip()
        elif line.startswith('calls='):
            after_call = True  # the next cost line is the call's inclusive cost: not this function's own
        elif line.startswith('0x'):
            p = line.split()
            if after_call:
                after_call = False
            elif len(p) >= 3:
                a = int(p[0], 16)
                cost[ob][a] += int(p[2])
                fn_at[(ob, a)] = fn
    return cost, fn_at


def inline_chains(obj, addrs):
    """{address: [(function, file), ...] innermost first}, from addr2line -i."""
    chains = {}
    for k in range(0, len(addrs), 4000):
        part = addrs[k:k + 4000]
        res = subprocess.run(['addr2line', '-a', '-f', '-i', '-e', obj] + ['0x%x' % a for a in part],
                             capture_output=True, text=True).stdout.split('\n')
        cur, i = None, 0
        while i < len(res):
            line = res[i]
            if line.startswith('0x'):
                cur = int(line, 16)
                chains[cur] = []
                i += 1
            elif not line:
                i += 1
            else:
                src = res[i + 1].split(' ')[0].split('/')[-1].split(':')[0] if i + 1 < len(res) else '?'
                chains[cur].append((line, src))
                i += 2
    return chains


def group_of(obj, fn, chain):
    if 'embree' in obj:
        return 'Embree'
    if 'libm.so' in obj or 'libm-' in obj:
        return 'libm (the material\'s sincosf)'
    if not chain or chain[0][1] == '??':
        return 'libm' if 'libm' in obj else 'other (%s: %s)' % (os.path.basename(obj), fn)
    if chain[0][0] in SAMPLER:
        return 'sampler (math.h, inlined into the core and the integrator)'
    for name, group in FILES:
        if any(src == name for _, src in chain):
            return group
    if any(src.startswith(('diffuse.c', 'ggx.c', 'dielectric.c')) for _, src in chain):
        return 'material'
    return 'other murk (%s)' % chain[0][1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('scene', nargs='?', default=os.path.join(ROOT, 'scenes', 'cornell.yaml'))
    ap.add_argument('--build', default=os.path.join(ROOT, 'build-prof'))
    ap.add_argument('--spp', type=int, default=4)
    ap.add_argument('--res', type=int, default=128)
    ap.add_argument('--set', action='append', default=[])
    ap.add_argument('--detail', action='store_true', help='also the 40 largest functions')
    args = ap.parse_args()
    path, rays = profile(args)
    cost, fn_at = read_costs(path)
    groups, detail = collections.Counter(), collections.Counter()
    for obj, per_addr in cost.items():
        chains = inline_chains(obj, sorted(per_addr)) if os.path.exists(obj) else {}
        for a, c in per_addr.items():
            chain = chains.get(a, [])
            g = group_of(obj, fn_at[(obj, a)], chain)
            groups[g] += c
            named = chain and chain[0][0] != '??' and g != 'Embree'  # Embree is stripped: callgrind's name
            detail[(g, chain[0][0] if named else fn_at[(obj, a)])] += c
    os.unlink(path)
    total = sum(groups.values())
    print('%s, %d spp at %dx%d, one thread: %d rays, %.1f instructions per ray in the render threads'
          % (os.path.relpath(args.scene, ROOT), args.spp, args.res, args.res, rays, total / rays))
    for g, c in groups.most_common():
        if c / rays >= 0.5:
            print('%8.1f  %s' % (c / rays, g))
    if args.detail:
        for (g, f), c in detail.most_common(40):
            print('   %7.1f  %-32s %s' % (c / rays, f, g))


if __name__ == '__main__':
    main()
