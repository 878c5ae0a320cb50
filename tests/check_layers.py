#!/usr/bin/python3
"""check_layers.py — core/'s folders depend on each other one way only, as core/README.md's layer table says.

    check_layers.py [--self-test] SOURCE_ROOT [LIBRARY.a ...]
        checks the tree (and the libraries' objects); --self-test first shows, on small trees made for
        it, that each check fails on what it exists to catch (an upward include, a cycle, ...)

The table (the rows of core/README.md's table headed `| layer | folder | ...`) gives each folder of
core/ a layer number. A file of folder F may include:
  - a public header, "murk/NAME.h" (core/include/murk/); a public header may include nothing else;
  - a header of its own folder or of a folder of a LOWER layer, written with its folder: "util/util.h".
Anything else fails: an include of a higher layer (upwards), of another folder of the same layer
(sideways), a bare name ("util.h", which hides the direction), a folder the table does not list, a
header that does not exist. A cycle of includes between core's own files fails too, and so does a
folder with sources that the table misses (or a row naming no folder), and, where the table has a column
`files`, a C or C++ source of a folder that its row's files do not name (`policy_*.c` names a family), or a
file named there that does not exist: the table is the map a newcomer reads. The public headers are one ABI
apart from the layers: they may include each other (murk/medium.h and murk/transmittance.h do, on
purpose, so that either brings both).

With libraries (libmurkcore.a, libmurkplugin.a: meson names each member FOLDER_FILE.c.o), the same rule
is checked on what the code calls: every symbol an object uses from another object must be defined
in its own folder or a lower layer's. That catches what an include cannot show: an `extern`
declared by hand, like the counters global media.c once wrote in render/host.c.
Exit 0 when all holds, 1 with one line per violation."""
import fnmatch
import os
import re
import subprocess
import sys
import tempfile

INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"', re.M)


def read_table(readme, files=None):
    """{folder: layer} from the markdown table whose header has the cells 'layer' and 'folder'; with a dict
    files, also {folder: [the `names` of its cell under 'files']} for a table with that column."""
    layers, cols = {}, None
    for line in open(readme, encoding='utf-8'):
        if not line.startswith('|'):
            cols = None
            continue
        cells = [c.strip() for c in line.strip().strip('|').split('|')]
        if cols is None:
            low = [c.lower() for c in cells]
            if 'layer' in low and 'folder' in low:
                cols = (low.index('layer'), low.index('folder'), low.index('files') if 'files' in low else None)
            continue
        if set(''.join(cells)) <= set('-: '):
            continue  # the |---|---| line
        layer, folder = cells[cols[0]], cells[cols[1]].strip('`').rstrip('/')
        if not layer.isdigit() or not folder:
            raise SystemExit(f'{readme}: a layer row needs a number and a folder: {line.strip()}')
        if folder in layers:
            raise SystemExit(f'{readme}: folder {folder}/ listed twice')
        layers[folder] = int(layer)
        if files is not None and cols[2] is not None:
            files[folder] = re.findall(r'`([^`]+)`', cells[cols[2]])
    if not layers:
        raise SystemExit(f'{readme}: no table headed | layer | folder | ...')
    return layers


def sources(core):
    """core/'s C files (the public headers apart) as paths relative to core/."""
    out = []
    for d, _, names in os.walk(core):
        for n in names:
            if n.endswith(('.c', '.h')):
                out.append(os.path.relpath(os.path.join(d, n), core))
    return sorted(out)


def generated(core, target):
    """1 if the folder's meson.build generates the header (a custom_target's `output : 'NAME.h'`)."""
    build = os.path.join(core, os.path.dirname(target), 'meson.build')
    return os.path.isfile(build) and f"output : '{os.path.basename(target)}'" in open(build, encoding='utf-8').read()


def check_includes(core, layers):
    """Violations of the table by core/'s #include lines, and the include graph between files."""
    bad, graph = [], {}
    folders = {f.split('/')[0] for f in sources(core) if '/' in f and not f.startswith('include/')}
    for f in sorted(folders - set(layers)):
        bad.append(f'core/{f}/: a folder with sources that core/README.md\'s layer table does not list')
    for f in sorted(set(layers) - folders):
        bad.append(f'core/README.md: the layer table lists {f}/, which has no sources')
    for path in sources(core):
        text = open(os.path.join(core, path), encoding='utf-8').read()
        public = path.startswith('include/')
        me = path.split('/')[0]
        graph[path] = []
        for m in INCLUDE.finditer(text):
            inc, line = m.group(1), text.count('\n', 0, m.start()) + 1
            where = f'core/{path}:{line}: "{inc}"'
            if inc.startswith('murk/'):
                target = 'include/' + inc
            elif public:
                bad.append(f'{where}: a public header includes only murk/*.h')
                continue
            elif '/' not in inc:
                bad.append(f'{where}: name its folder ("FOLDER/{inc}")')
                continue
            else:
                target, to = inc, inc.split('/')[0]
                if to not in layers:
                    bad.append(f'{where}: {to}/ is not in core/README.md\'s layer table')
                    continue
                if to != me and me in layers and layers[to] >= layers[me]:
                    way = 'upwards' if layers[to] > layers[me] else 'sideways'
                    bad.append(f'{where}: {me}/ (layer {layers[me]}) may not include {to}/ (layer {layers[to]}): {way}')
            if not os.path.isfile(os.path.join(core, target)) and not generated(core, target):
                bad.append(f'{where}: no such header core/{target}')
                continue
            if not public and not target.startswith('include/'):
                graph[path].append(target)
    return bad, graph


def check_files(core, named):
    """The sources of each folder that its row's files cell does not name, and names that are no file."""
    bad = []
    for folder, names in sorted(named.items()):
        have = sorted(os.path.relpath(os.path.join(d, n), os.path.join(core, folder))
                      for d, _, ns in os.walk(os.path.join(core, folder)) for n in ns if n.endswith(('.c', '.cpp')))
        for h in have:
            if not any(fnmatch.fnmatchcase(h, n) for n in names):
                bad.append(f'core/{folder}/{h}: core/README.md\'s layer table does not name it in {folder}/\'s files')
        for n in names:
            if n.endswith(('.c', '.cpp')) and not any(fnmatch.fnmatchcase(h, n) for h in have):
                bad.append(f'core/README.md: {folder}/\'s files name {n}, which is no source of core/{folder}/')
    return bad


def find_cycle(graph):
    """One cycle of the graph as a list of nodes, or None (iterative depth-first search)."""
    state = {}
    for root in sorted(graph):
        if state.get(root):
            continue
        stack, path = [(root, iter(graph.get(root, ())))], [root]
        state[root] = 1
        while stack:
            node, it = stack[-1]
            nxt = next(it, None)
            if nxt is None:
                state[node] = 2
                stack.pop()
                path.pop()
            elif state.get(nxt) == 1:
                return path[path.index(nxt):] + [nxt]
            elif not state.get(nxt):
                state[nxt] = 1
                stack.append((nxt, iter(graph.get(nxt, ()))))
                path.append(nxt)
    return None


def check_symbols(libraries, layers):
    """Violations of the table by the calls between the libraries' objects (nm's defined and undefined)."""
    defined, used, bad = {}, {}, []
    for lib in libraries:
        out = subprocess.run(['nm', '-A', lib], capture_output=True, text=True, check=True).stdout
        for line in out.splitlines():
            head, _, rest = line.rpartition(':')  # LIBRARY:MEMBER:ADDRESS TYPE NAME
            member = os.path.basename(head.split(':')[-1])  # a thin archive's members are paths
            f = rest.split()
            if len(f) == 3 and f[1] in 'TDBRCVW':  # defined with external linkage
                defined[f[2]] = member
            elif len(f) == 2 and f[0] == 'U':
                used.setdefault(member, set()).add(f[1])
    if not defined:
        return [f'no symbols in {" ".join(libraries)} (nm found none)']
    for member, symbols in sorted(used.items()):
        me = member.split('_')[0]
        for s in sorted(symbols):
            d = defined.get(s)
            if not d or me not in layers:
                continue
            to = d.split('_')[0] if '_' in d else '.'
            if to not in layers:
                bad.append(f'{member} uses {s} of {d}, which is in no folder of the layer table')
            elif to != me and layers[to] >= layers[me]:
                way = 'upwards' if layers[to] > layers[me] else 'sideways'
                bad.append(f'{member} uses {s} of {d}: {me}/ (layer {layers[me]}) may not reach '
                           f'{to}/ (layer {layers[to]}): {way}')
    return bad


def check(root, libraries=()):
    core = os.path.join(root, 'core')
    named = {}
    layers = read_table(os.path.join(core, 'README.md'), named)
    bad, graph = check_includes(core, layers)
    bad += check_files(core, named)
    cycle = find_cycle(graph)
    if cycle:
        bad.append('a cycle of includes: ' + ' -> '.join('core/' + c for c in cycle))
    if libraries:
        bad += check_symbols(libraries, layers)
    nfiles = len(graph)
    nincl = sum(len(v) for v in graph.values())
    return bad, f'{nfiles} files, {nincl} includes, {len(layers)} folders in {len(set(layers.values()))} layers'


def self_test():
    """A small tree that passes, then one mutation each that must fail."""
    table = '| layer | folder | what | files |\n|---|---|---|---|\n| 0 | `low/` | x | |\n| 1 | `mid/` | x | `b.c` |\n' \
            '| 1 | `side/` | x | |\n| 2 | `top/` | x | `d.c` |\n'
    files = {'core/README.md': table, 'core/low/a.h': '', 'core/mid/b.h': '#include "low/a.h"\n',
             'core/side/c.h': '#include "low/a.h"\n', 'core/top/d.c': '#include "mid/b.h"\n#include "side/c.h"\n',
             'core/include/murk/p.h': '', 'core/mid/b.c': '#include "mid/b.h"\n#include "murk/p.h"\n'}
    mutants = {
        'upwards': ('core/low/a.h', '#include "mid/b.h"\n'),
        'sideways': ('core/side/c.h', '#include "mid/b.h"\n'),
        'bare name': ('core/top/d.c', '#include "b.h"\n'),
        'unlisted folder': ('core/extra/e.c', '#include "low/a.h"\n'),
        'public header leaks': ('core/include/murk/p.h', '#include "low/a.h"\n'),
        'missing header': ('core/top/d.c', '#include "mid/nothere.h"\n'),
        'source the table does not name': ('core/mid/b2.c', '#include "mid/b.h"\n'),
        'cycle': ('core/mid/b.h', '#include "mid/b2.h"\n', 'core/mid/b2.h', '#include "mid/b.h"\n'),
    }
    failures = 0
    for name, edits in [('clean', ())] + list(mutants.items()):
        with tempfile.TemporaryDirectory() as tmp:
            tree = dict(files)
            for i in range(0, len(edits), 2):
                tree[edits[i]] = edits[i + 1]
            for path, text in tree.items():
                os.makedirs(os.path.dirname(os.path.join(tmp, path)), exist_ok=True)
                with open(os.path.join(tmp, path), 'w', encoding='utf-8') as f:
                    f.write(text)
            bad, _ = check(tmp)
        ok = not bad if name == 'clean' else bool(bad)
        print(f'self-test {name}: {"ok" if ok else "WRONG"}' + (f' ({bad[0]})' if bad else ''))
        failures += not ok
    return failures


def main(argv):
    args = argv[1:]
    if args[:1] == ['--self-test']:
        args = args[1:]
        if self_test():
            return 1
    if not args:
        print(__doc__.split('\n\n')[0], file=sys.stderr)
        return 2
    bad, summary = check(args[0], args[1:])
    for b in bad:
        print(b)
    if bad:
        print(f'layers: {len(bad)} violation(s) of core/README.md\'s layer table ({summary})')
        return 1
    print(f'layers: {summary}; every include{" and call" if args[1:] else ""} runs down, no cycle')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
