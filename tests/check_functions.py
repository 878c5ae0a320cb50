#!/usr/bin/python3
"""check_functions.py — no function of core/ or plugins/ is longer than a limit (issue 24: 100 lines).

    check_functions.py [--self-test] [--limit N] [--list K] SOURCE_ROOT

Reads every .c, .h and .cpp file below SOURCE_ROOT/core and SOURCE_ROOT/plugins, finds each top-level
brace block whose head holds a parenthesis and no `=` before it (a function definition, or a macro
that expands to one; an initialised table is not one; the blocks of a C++ namespace or extern "C" are
looked into, a C++ struct's or class's methods are not), and counts its lines from the first line of its
head to its closing brace. Comments, strings and preprocessor lines are blanked first, so a brace in
them does not count. Fails (exit 1) naming each function longer than the limit; --list K also prints
the K longest. --self-test first shows the count on small files made for it: a function of exactly the
limit passes, one line more fails (inside a C++ namespace too), braces in comments and strings and a
table do not count."""
import os
import re
import sys
import tempfile

LIMIT = 100


def blank(src):
    """src with comments, string and character literals and preprocessor lines blanked (newlines kept)."""
    out, i, n = [], 0, len(src)
    while i < n:
        if src.startswith('//', i):
            j = src.find('\n', i)
            j = n if j < 0 else j
        elif src.startswith('/*', i):
            j = src.find('*/', i + 2)
            j = n if j < 0 else j + 2
        elif src[i] in '"\'':
            j = i + 1
            while j < n and src[j] != src[i] and src[j] != '\n':
                j += 2 if src[j] == '\\' else 1
            j = min(j + 1, n)
        else:
            out.append(src[i])
            i += 1
            continue
        out.append(re.sub(r'[^\n]', ' ', src[i:j]))
        i = j
    lines = ''.join(out).split('\n')
    cont = False
    for k, line in enumerate(lines):  # preprocessor lines and their continuations
        if cont or line.lstrip().startswith('#'):
            cont = line.rstrip().endswith('\\')
            lines[k] = ''
    return '\n'.join(lines)


def functions(path):
    """[(lines, first line, name)] of the functions in the file at path."""
    s = blank(open(path, encoding='utf-8', errors='replace').read())
    out, depth, head_start, head, opened = [], 0, 0, '', 0
    for i, c in enumerate(s):
        if c == '{':
            if depth == 0:
                head = s[head_start:i]
                if re.search(r'(\bnamespace\b[\w\s:]*|\bextern\s*"\s*")$', head.strip()):
                    opened += 1  # a C++ namespace or extern "C" block: its functions count as top-level
                    head_start = i + 1
                    continue
            depth += 1
        elif c == '}' and depth == 0 and opened:
            opened -= 1
            head_start = i + 1
        elif c == '}' and depth > 0:
            depth -= 1
            if depth == 0:
                h = head.strip()
                if '(' in h and '=' not in h.split('(')[0] and not re.search(r'\b(struct|enum|union|class)\s*\w*\s*$', h):
                    first = s.count('\n', 0, head_start + len(head) - len(head.lstrip())) + 1
                    last = s.count('\n', 0, i) + 1
                    names = re.findall(r'(\w+)\s*\(', h)
                    out.append((last - first + 1, first, names[0] if names else '?'))
                head_start = i + 1
        elif c == ';' and depth == 0:
            head_start = i + 1
    return out


def scan(root):
    found = []
    for top in ('core', 'plugins'):
        for d, _, names in os.walk(os.path.join(root, top)):
            for name in sorted(names):
                if name.endswith(('.c', '.h', '.cpp')):
                    path = os.path.join(d, name)
                    rel = os.path.relpath(path, root)
                    found += [(n, f'{rel}:{line}', fn) for n, line, fn in functions(path)]
    return sorted(found, reverse=True)


def self_test(limit):
    body = lambda k: ''.join(f'    x += {j};\n' for j in range(k))
    cases = {  # name: (source, the longest function's length, or 0 for none)
        'at the limit': (f'int f(int x)\n{{\n{body(limit - 3)}}}\n', limit),
        'one over': (f'static int g(int x) {{\n{body(limit - 1)}}}\n', limit + 1),
        'inside a C++ namespace': (f'namespace {{\nint n(int x)\n{{\n{body(limit - 2)}}}\n}} // namespace\n', limit + 1),
        'an enum parameter': (f'static int e(int x, enum kind k)\n{{\n{body(limit - 2)}}}\n', limit + 1),
        'braces in comments and strings': ('int h(void)\n{\n    /* { */ const char *s = "}{";\n    // }\n'
                                           "    return s[0] == '{';\n}\n", 6),
        'a table is no function': ('static const int t[] = {\n' + '    1,\n' * (limit + 5) + '};\n', 0),
        'a macro line with a brace': ('#define OPEN {\nint k(void)\n{\n    return 0;\n}\n', 4),
    }
    failures = 0
    for name, (src, want) in cases.items():
        with tempfile.NamedTemporaryFile('w', suffix='.c', delete=False) as f:
            f.write(src)
        got = max((n for n, _, _ in functions(f.name)), default=0)
        os.unlink(f.name)
        ok = got == want
        print(f'self-test {name}: {"ok" if ok else "WRONG"} (longest {got}, expected {want})')
        failures += not ok
    return failures


def main(argv):
    args, limit, nlist, test = argv[1:], LIMIT, 0, False
    while args and args[0].startswith('--'):
        opt = args.pop(0)
        if opt == '--self-test':
            test = True
        elif opt == '--limit':
            limit = int(args.pop(0))
        elif opt == '--list':
            nlist = int(args.pop(0))
        else:
            print(__doc__.split('\n\n')[1], file=sys.stderr)
            return 2
    if test and self_test(limit):
        return 1
    if len(args) != 1:
        print(__doc__.split('\n\n')[1], file=sys.stderr)
        return 2
    found = scan(args[0])
    for n, where, fn in found[:nlist]:
        print(f'{n:5d} {where} {fn}')
    over = [f for f in found if f[0] > limit]
    for n, where, fn in over:
        print(f'{where}: {fn} is {n} lines, over the limit of {limit}: split it')
    print(f'functions: {len(found)} in core/ and plugins/, the longest {found[0][0] if found else 0} lines; '
          f'{len(over)} over {limit}')
    return 1 if over else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
