"""murk.bench and murk.plugins: libmurklab's bench row by row and the plugins' schemas as data
(murk/lab.h). Internal to the murk module; murk/__init__.py exports them."""
import ctypes
import os
import sys
import tempfile

from . import _lib
from . import _interruptible, _sets, _set_value, _scene_error, _whole

_TYPES = {1: "float", 2: "int", 3: "bool", 4: "rgb", 5: "string", 6: "enum"}
_METRICS = ("mse", "relmse_raw", "ref_noise", "relmse", "relmse_se", "mare")


class BenchError(RuntimeError):
    """A bench that failed; .status is `murk bench`'s exit status, the message its last line on stderr."""


def _row(r):
    row = {"variant": r.variant, "label": r.label.decode(errors="replace"), "budget": r.budget, "seed": r.seed,
           "spp": r.spp, "seconds": r.seconds, "rays": int(r.rays)}
    row.update({n: int(getattr(r.counters, n)) for n in _lib.COUNTER_NAMES})
    row.update({n: getattr(r.metrics, n) for n in _METRICS})
    row.update(nonfinite=int(r.nonfinite), max_sample=r.max_sample)
    return row


def _numbers(name, vals, kind):
    vals = [vals] if isinstance(vals, (int, float)) else list(vals)
    if not vals or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and v > 0 for v in vals):
        raise ValueError("murk.bench: %s takes positive %s, got %r" % (name, kind, vals))
    return ",".join(repr(v) for v in vals)


def _bench_argv(scene, vary, set, spp, time, repeat, reference, ref_spp, ref_set, threads, out, charts):
    if not isinstance(scene, (str, os.PathLike)):
        raise TypeError("murk.bench: the scene is a YAML file's path (a bench caches its reference by the "
                        "file's bytes)")
    argv = [os.fspath(scene)]
    for k, vals in (vary or {}).items():
        vals = [vals] if isinstance(vals, (str, int, float)) else list(vals)
        argv += ["--vary", "%s=%s" % (k, ",".join(_set_value(v, k) for v in vals))]
    for s in _sets(set):
        argv += ["--set", s]
    if spp is not None and time is not None:
        raise ValueError("murk.bench: spp= or time=, not both")
    if spp is not None:
        argv += ["--spp", _numbers("spp", spp, "whole numbers")]
    if time is not None:
        argv += ["--time", _numbers("time", time, "seconds")]
    if repeat is not None:
        argv += ["--repeat", str(_whole("repeat", repeat, 1, 1000))]
    if reference is not None:
        argv += ["--reference", os.fspath(reference)]
    if ref_spp is not None:
        argv += ["--ref-spp", str(_whole("ref_spp", ref_spp, 1, 1 << 24))]
    for s in _sets(ref_set):
        argv += ["--ref-set", s]
    if threads is not None:
        argv += ["--threads", str(_whole("threads", threads, 1, 1024))]
    argv += ["-o", os.fspath(out)]
    if not charts:
        argv.append("--no-charts")
    return argv


def _captured_stderr(run):
    """Runs run() with the process's stderr (fd 2: the C library's messages) going to a file, then writes
    that text to sys.stderr. (run's value, the text)."""
    sys.stderr.flush()
    with tempfile.TemporaryFile() as f:
        saved = os.dup(2)
        os.dup2(f.fileno(), 2)
        try:
            value = run()
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        f.seek(0)
        text = f.read().decode(errors="replace")
    sys.stderr.write(text)
    return value, text


def bench(scene, vary=None, set=None, spp=None, time=None, repeat=None, reference=None, ref_spp=None,
          ref_set=None, threads=None, out=None, charts=False, frame=False):
    """`murk bench` with the command's arguments as keywords: vary {KEY: [values]} (--vary), set, spp or time
    (budgets), repeat, reference (an EXR), ref_spp, ref_set, threads; out: the folder of its files (bench.csv,
    report.html, ...; default a temporary folder, removed); charts: the PNG charts (--no-charts unless True).
    -> its rows as a list of dicts (bench.csv's columns), or a pandas DataFrame with frame=True. Ctrl-C stops
    the running render and raises KeyboardInterrupt with .rows, the finished renders'."""
    pandas = None
    if frame:
        import pandas  # fails here, before the renders, when pandas is missing
    tmp = tempfile.TemporaryDirectory(prefix="murk-bench-") if out is None else None
    argv = _bench_argv(scene, vary, set, spp, time, repeat, reference, ref_spp, ref_set, threads,
                       tmp.name if tmp else out, charts)
    rows, stop, state = [], ctypes.c_int(0), {}
    cb = _lib.BENCH_ROW_FN(lambda user, r: rows.append(_row(r[0])))
    arr = _lib.strings(argv)

    def run():
        state["rc"] = _lib.lab.murk_lab_bench_run(len(argv), arr, ctypes.byref(stop), cb, None)

    def halt():
        stop.value = 1

    try:
        interrupted, text = _captured_stderr(lambda: _interruptible(run, "murk bench", halt))
    finally:
        if tmp:
            tmp.cleanup()
    if interrupted:
        e = KeyboardInterrupt("murk.bench interrupted after %d renders" % len(rows))
        e.rows = rows
        raise e
    rc = state.get("rc", 1)
    if rc != 0:
        lines = [l for l in text.splitlines() if l.strip()]
        located = [l for l in lines if not l.startswith("murk: ")]
        if rc == 1 and located:  # a scene's (or a --vary's) located message, as murk render gives it
            raise _scene_error(located[0])
        e = BenchError(lines[-1] if lines else "murk bench failed (status %d)" % rc)
        e.status = rc
        raise e
    if frame:
        return pandas.DataFrame(rows)
    return rows


def _param(p):
    t = _TYPES.get(p.type, "type %d" % p.type)
    if t == "rgb":
        default = list(p.default)
    elif t in ("string", "enum"):
        default = p.def_str.decode() if p.def_str else None
    elif t == "bool":
        default = bool(p.default[0])
    elif t == "int":
        default = int(p.default[0])
    else:
        default = p.default[0]
    d = {"name": p.name.decode(), "type": t, "default": default, "doc": (p.doc or b"").decode(),
         "required": bool(p.flags & 2), "texturable": bool(p.flags & 1)}
    if t in ("float", "int", "rgb"):
        d.update(min=p.min, max=p.max)
    if t == "enum":
        d["choices"] = (p.choices or b"").decode().split("|")
    return d


def plugins():
    """Every plugin on the search path ($MURK_PLUGIN_PATH, then murk's own) as `murk plugins NAME` describes
    it: {name: {"name", "kind", "description", "version", "path", "abi", "params": [...]}}; a tracker (kind
    "medium") also has "medium_keys", the keys every medium takes. A plugin murk refuses has "error"."""
    raw = _lib.lab.murk_lab_plugin_names()
    if not raw:
        raise MemoryError("murk.plugins: out of memory")
    names = ctypes.string_at(raw).decode(errors="replace").split()
    _lib.libc.free(raw)
    n = ctypes.c_uint32()
    core = _lib.lab.murk_lab_medium_params(ctypes.byref(n))
    medium_keys = [_param(core[i]) for i in range(n.value)]
    out, err = {}, ctypes.create_string_buffer(2048)
    for name in names:
        info = _lib.PluginInfo()
        h = _lib.lab.murk_lab_plugin_open(name.encode(), ctypes.byref(info), err, len(err))
        if not h:
            out[name] = {"name": name, "error": err.value.decode(errors="replace")}
            continue
        try:
            kind = _lib.murk.murk_kind_name(info.kind)
            d = {"name": info.name.decode(), "kind": kind.decode() if kind else str(info.kind),
                 "description": (info.description or b"").decode(),
                 "version": info.version.decode() if info.version else None, "path": info.path.decode(),
                 "abi": (info.abi.major, info.abi.minor),
                 "params": [_param(info.params[i]) for i in range(info.nparams)]}
            if info.kind == 2:
                d["medium_keys"] = medium_keys
            out[name] = d
        finally:
            _lib.lab.murk_lab_plugin_close(h)
    return out
