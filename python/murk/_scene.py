"""A scene given as a dict (the YAML's structure) written as YAML text for the scene loader, with a map
from each line and column of that text back to the key path it came from, so that the loader's
"LINE:COL: message" can name scene['media']['smoke']['sigma_a'] instead. Internal to the murk module."""
import math
import numbers
import re

MAX_TEXT = 64 << 20  # the loader's limit for a scene file (64 MiB)
MAX_DEPTH = 64
_PLAIN = re.compile(r"^[A-Za-z_][A-Za-z0-9_.\-]*$")
_YAML_WORDS = {"true", "false", "yes", "no", "on", "off", "null", "y", "n", "~"}


def path_text(path):
    return "scene" + "".join("[%r]" % (k,) for k in path)


class Invalid(Exception):
    """A value no scene can hold: .path is its key path, str() says what is wrong."""

    def __init__(self, path, what):
        super().__init__("%s: %s" % (path_text(path), what))
        self.path = path


def _scalar(v, path):
    if isinstance(v, bool) or type(v).__name__ == "bool_":
        return "true" if v else "false"
    if isinstance(v, numbers.Integral):
        return str(int(v))
    if isinstance(v, numbers.Real):
        x = float(v)
        if not math.isfinite(x):
            raise Invalid(path, "%r is not a number a scene can hold (NaN or infinite)" % x)
        return repr(x)
    if isinstance(v, str):
        if "\0" in v:
            raise Invalid(path, "a string with a NUL character")
        if _PLAIN.match(v) and v.lower() not in _YAML_WORDS:
            return v
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n").replace("\t", "\\t") + '"'
    if v is None:
        return "null"
    raise Invalid(path, "a %s is not a scene value (numbers, strings, booleans, lists and dicts are)"
                  % type(v).__name__)


def _key(k, path):
    if not isinstance(k, str):
        raise Invalid(path, "key %r is a %s; a scene's keys are strings" % (k, type(k).__name__))
    return _scalar(k, path + (k,))


class _Writer:
    def __init__(self):
        self.lines, self.marks, self.size = [], [], 0

    def line(self, text):
        self.size += len(text) + 1
        if self.size > MAX_TEXT:
            raise Invalid((), "the scene is larger than the loader reads (64 MiB of YAML)")
        self.lines.append(text)

    def mark(self, col, path):  # what starts at (this line, col): 1-based, as the loader counts
        self.marks.append((len(self.lines) + 1, col, path))

    def flow(self, seq, path, col, depth):
        """A list of scalars or small lists on one line: its text; marks each item's column."""
        parts, c = [], col + 1
        for i, v in enumerate(seq):
            p = path + (i,)
            self.mark(c, p)
            t = self.flow(_listish(v, p), p, c, depth + 1) if _listish(v, p) is not None else _scalar(v, p)
            parts.append(t)
            c += len(t) + 2
        return "[" + ", ".join(parts) + "]"

    def node(self, v, path, indent, depth):
        if depth > MAX_DEPTH:
            raise Invalid(path, "nested deeper than %d levels (a cycle?)" % MAX_DEPTH)
        pad = " " * indent
        if isinstance(v, dict):
            if not v:
                self.mark(indent + 1, path)
                self.line(pad + "{}")
            for k, x in v.items():
                key = _key(k, path)
                p = path + (k,)
                self.block_entry(pad + key + ":", x, p, indent, depth)
            return
        seq = _listish(v, path)
        if seq is not None:
            if not seq:
                self.mark(indent + 1, path)
                self.line(pad + "[]")
            for i, x in enumerate(seq):
                self.block_entry(pad + "-", x, path + (i,), indent, depth)
            return
        self.mark(indent + 1, path)
        self.line(pad + _scalar(v, path))

    def block_entry(self, head, x, p, indent, depth):
        self.mark(indent + 1, p)
        seq = _listish(x, p)
        if isinstance(x, dict) and x:
            self.line(head)
            self.node(x, p, indent + 2, depth + 1)
        elif seq is not None and seq and not _flat(seq, p):
            self.line(head)
            self.node(seq, p, indent + 2, depth + 1)
        elif seq is not None:
            self.line(head + " " + self.flow(seq, p, len(head) + 2, depth + 1))
        elif isinstance(x, dict):
            self.line(head + " {}")
        else:
            self.mark(len(head) + 2, p)
            self.line(head + " " + _scalar(x, p))


def _listish(v, path):
    """v as a list if it is a sequence (list, tuple, numpy array), else None."""
    if isinstance(v, (list, tuple)):
        return list(v)
    if hasattr(v, "tolist") and hasattr(v, "shape") and getattr(v, "shape", ()) != ():
        if getattr(v, "size", 0) > 1 << 24:
            raise Invalid(path, "an array of %d values: larger than a scene holds" % v.size)
        return v.tolist()
    return None


def _flat(seq, path):
    """1 if seq is written on one line: scalars, or lists of at most 16 scalars (a matrix)."""
    if len(seq) > 1 << 16:
        return False
    for x in seq:
        if isinstance(x, dict):
            return False
        s = _listish(x, path)
        if s is not None and (len(s) > 16 or any(isinstance(y, (dict, list, tuple)) for y in s)):
            return False
    return True


def to_yaml(scene):
    """(text, marks): the YAML of a scene dict and [(line, col, path)] in text order."""
    if not isinstance(scene, dict):
        raise Invalid((), "a scene is a dict (or a file's path), got a %s" % type(scene).__name__)
    w = _Writer()
    w.node(scene, (), 0, 0)
    return "\n".join(w.lines) + "\n", sorted(w.marks, key=lambda m: (m[0], m[1]))


def locate(marks, line, col):
    """The key path of the text at (line, col): the last mark at or before it."""
    best = ()
    for ml, mc, p in marks:
        if (ml, mc) <= (line, col):
            best = p
        else:
            break
    return best
