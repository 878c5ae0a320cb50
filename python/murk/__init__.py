"""murk from Python: render a scene (a file or a dict), bench trackers, compare images, read the plugins'
schemas. A binding over libmurk and libmurklab (murk/murk.h, murk/lab.h) through ctypes:

    import murk
    r = murk.render("scenes/cornell.yaml", spp=4)
    print(r.image.shape, r.seconds, r.counters["rays"])

docs/python.md describes every function."""
import ctypes
import json
import os
import re
import signal
import threading

import numpy as np

from . import _lib
from ._scene import Invalid, locate, path_text, to_yaml, _listish, _scalar, _Writer

__all__ = ["render", "bench", "compare", "plugins", "read_exr", "Result", "SceneError", "RenderError"]

_ERRLEN = 4096
_LOC = re.compile(r"^(?P<file>.*?):(?P<line>\d+):(?P<col>\d+): (?P<what>.*)$", re.S)
_DICT_NAME = "<scene dict>"


class SceneError(ValueError):
    """A scene murk refuses, with the CLI's one-line message. file, line, col: where (the scene file, or
    _DICT_NAME's generated YAML for a dict scene, whose key path is then in .path); set: the --set that
    caused it ("KEY=VALUE"), else None; what: the message without its location."""

    def __init__(self, message, file=None, line=None, col=None, set=None, path=None, what=None):
        super().__init__(message)
        self.file, self.line, self.col, self.set, self.path = file, line, col, set, path
        self.what = what if what is not None else message


class RenderError(RuntimeError):
    """A render that failed after its scene loaded (a checkpoint that could not be written, ...)."""


def _scene_error(msg, name=None, marks=None, sets=()):
    for s in sets:  # an override's error quotes it
        if msg.startswith("--set " + s + ": "):
            return SceneError(msg, set=s, what=msg[len("--set " + s + ": "):])
    m = _LOC.match(msg)
    if not m:
        return SceneError(msg)
    f, line, col, what = m.group("file"), int(m.group("line")), int(m.group("col")), m.group("what")
    if marks is not None and f == name:
        path = locate(marks, line, col)
        return SceneError("%s: %s" % (path_text(path), what), file=_DICT_NAME, line=line, col=col, path=path,
                          what=what)
    return SceneError(msg, file=f, line=line, col=col, what=what)


def _set_value(v, key):
    seq = _listish(v, (key,))
    if seq is not None:
        return _Writer().flow(seq, (key,), 1, 0)
    if isinstance(v, dict):
        text, _ = to_yaml(v)
        return "{" + ", ".join(line.strip() for line in text.splitlines()) + "}" if v else "{}"
    return _scalar(v, (key,))


def _sets(set_, seed=None):
    """--set overrides from a dict {KEY.PATH: value} or a list of "KEY.PATH=VALUE" strings."""
    out = []
    if isinstance(set_, dict):
        for k, v in set_.items():
            if not isinstance(k, str) or not k:
                raise TypeError("murk: a set= key is a KEY.PATH string, got %r" % (k,))
            try:
                out.append("%s=%s" % (k, _set_value(v, k)))
            except Invalid as e:
                raise SceneError("--set %s: %s" % (k, str(e).split(": ", 1)[1]), set=k) from None
    elif set_ is not None:
        if isinstance(set_, str) or not all(isinstance(s, str) for s in set_):
            raise TypeError("murk: set= takes a dict {KEY.PATH: value} or a list of 'KEY.PATH=VALUE' strings")
        out = list(set_)
    if seed is not None:
        out.append("render.seed=%d" % _whole("seed", seed, 0, 2**63 - 1))
    return out


def _whole(name, v, lo, hi):
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not lo <= int(v) <= hi:
        raise ValueError("murk: %s must be a whole number in [%d, %d], got %r" % (name, lo, hi, v))
    return int(v)


class _Scene:
    """A loaded scene (murk_scene *), freed on close."""

    def __init__(self, scene, sets, base):
        err = ctypes.create_string_buffer(_ERRLEN)
        arr = _lib.strings(sets)
        marks = None
        if isinstance(scene, (str, bytes, os.PathLike)):
            self.name = os.fsdecode(scene)
            ptr = _lib.murk.murk_scene_load(os.fsencode(scene), arr, len(sets), err, _ERRLEN)
        elif isinstance(scene, dict):
            try:
                text, marks = to_yaml(scene)
            except Invalid as e:
                raise SceneError(str(e), path=e.path, what=str(e).split(": ", 1)[1]) from None
            self.name = os.path.join(os.path.abspath(base or os.getcwd()), _DICT_NAME)
            ptr = _lib.murk.murk_scene_load_text(text.encode(), self.name.encode(), arr, len(sets), err, _ERRLEN)
        else:
            raise TypeError("murk: a scene is a file's path or a dict, got a %s" % type(scene).__name__)
        if ptr and _lib.murk.murk_scene_check_unused(ptr, err, _ERRLEN) != 0:
            _lib.murk.murk_scene_free(ptr)
            ptr = None
        if not ptr:
            raise _scene_error(err.value.decode(errors="replace"), self.name, marks, sets)
        self.ptr, self.sets, self.is_dict = ptr, sets, marks is not None

    def close(self):
        if self.ptr:
            _lib.murk.murk_scene_free(self.ptr)
            self.ptr = None


class Result:
    """A render: image (float32 H x W x 3, linear, row 0 at the top), seconds, spp, counters (as the EXR's
    murk:counters: {"rays", "total", "media": {NAME: {...}}}), metadata (the EXR's murk:* attributes, without
    the prefix) and interrupted (stopped before its spp: the image of the whole passes done)."""

    def __init__(self, image, seconds, spp, counters, metadata, interrupted=False):
        self.image, self.seconds, self.spp = image, seconds, spp
        self.counters, self.metadata, self.interrupted = counters, metadata, interrupted

    def __repr__(self):
        h, w = self.image.shape[:2]
        return "<murk.Result %dx%d, %d spp, %.3f s%s>" % (w, h, self.spp, self.seconds,
                                                        ", interrupted" if self.interrupted else "")


def _counters(scene, res):
    def block(c):
        return {n: int(getattr(c, n)) for n in _lib.COUNTER_NAMES}
    media, total = {}, dict.fromkeys(_lib.COUNTER_NAMES, 0)
    for i in range(min(res.nmedia, _lib.COUNTER_SLOTS)):
        name = _lib.murk.murk_scene_medium_name(scene.ptr, i)
        media[name.decode() if name else "media %d.." % i] = block(res.media[i])
        for k, v in media[list(media)[-1]].items():
            total[k] += v
    return {"rays": int(res.rays), "total": total, "media": media}


def _metadata(scene, res, spp_asked):
    info = _lib.SceneInfo()
    _lib.murk.murk_scene_get_info(scene.ptr, ctypes.byref(info))
    buf = ctypes.create_string_buffer(8192)
    _lib.murk.murk_scene_plugins(scene.ptr, buf, len(buf))
    return {"scene": _DICT_NAME if scene.is_dict else scene.name, "spp": res.spp, "seed": int(info.seed),
            "render_time": res.seconds, "integrator": info.integrator.decode(),
            "nonfinite_samples": int(res.nonfinite), "set": " ".join(scene.sets), "plugins": buf.value.decode(),
            "spp_requested": spp_asked or info.spp, "interrupted": bool(res.interrupted),
            "max_sample": res.max_sample, "threads": res.threads, "thread_time": res.thread_seconds,
            "exposure": info.exposure, "samples": int(res.samples), "rays": int(res.rays)}


def _progress_callback(fn, ss, failure):
    def call(user, fraction, seconds, last):
        if failure:
            return
        try:
            if fn(fraction, seconds, bool(last)) is False:
                _lib.murk.murk_session_stop(ss)
        except BaseException as e:  # raised after the session ends
            failure.append(e)
            _lib.murk.murk_session_stop(ss)
    return _lib.PROGRESS_FN(call)


def _run_passes(ss):
    """Runs the session's passes on a thread of their own (ctypes releases the GIL in each call) while this
    one waits, so Ctrl-C stops the render as SIGINT stops `murk render`: the running pass is abandoned.
    (rc of the last run_pass, its message, interrupted)."""
    state = {}

    def passes():
        err = ctypes.create_string_buffer(_ERRLEN)
        rc = 1
        while rc > 0:
            rc = _lib.murk.murk_session_run_pass(ss, err, _ERRLEN)
        state["rc"], state["err"] = rc, err.value.decode(errors="replace")

    interrupted = _interruptible(passes, "murk render", lambda: _lib.murk.murk_session_stop(ss))
    return state.get("rc", -1), state.get("err", ""), interrupted


def _interruptible(work, name, stop):
    """Runs work() on a thread of its own while this one waits; Ctrl-C meanwhile calls stop() (thread-safe)
    and keeps waiting for work to return, as SIGINT stops `murk render`. Python's SIGINT handler is replaced
    for the wait (on the main thread, when it is Python's own: an ignored SIGINT stays ignored), so no
    KeyboardInterrupt can leave a render running. True if it was interrupted."""
    interrupted = []

    def on_sigint(signum, frame):
        interrupted.append(signum)
        stop()

    old = None
    if threading.current_thread() is threading.main_thread() and \
            signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        old = signal.signal(signal.SIGINT, on_sigint)
    try:
        t = threading.Thread(target=work, name=name, daemon=True)
        t.start()
        while t.is_alive():
            t.join(0.05)
    finally:
        if old is not None:
            signal.signal(signal.SIGINT, old)
    return bool(interrupted)


def render(scene, spp=None, seed=None, threads=None, set=None, progress=None, time=None, base=None, quiet=False):
    """Renders scene (a YAML file's path, or a dict of the YAML's structure) as `murk render` does, with
    the same checks and messages (murk.SceneError). spp: samples per pixel (default the scene's); seed:
    render.seed; threads: render threads (default every core; the image does not depend on it); set: --set
    overrides, {KEY.PATH: value} or ["KEY.PATH=VALUE", ...]; time: seconds, renders whole passes that fit
    (spp is then a cap); progress: fn(fraction, seconds, last), called about five times a second from the
    render's thread (return False to stop the render); base: the folder a dict scene's relative paths start
    from (default the current one); quiet: no notes on stderr. Ctrl-C stops the render after its whole
    passes and raises KeyboardInterrupt with .result, the image of those passes. -> murk.Result"""
    spp = None if spp is None else _whole("spp", spp, 1, 1 << 24)
    threads = 0 if threads is None else _whole("threads", threads, 1, 1024)
    if time is not None and not (isinstance(time, (int, float)) and 0 < time < float("inf")):
        raise ValueError("murk: time must be a positive number of seconds, got %r" % (time,))
    if progress is not None and not callable(progress):
        raise TypeError("murk: progress must be a function fn(fraction, seconds, last)")
    sets = _sets(set, seed)
    _lib.murk.murk_set_quiet(1 if quiet else 0)
    sc = _Scene(scene, sets, base)
    try:
        return _render_loaded(sc, spp, threads, time, progress)
    finally:
        sc.close()


def _render_loaded(sc, spp, threads, time, progress):
    err = ctypes.create_string_buffer(_ERRLEN)
    opts = _lib.RenderOpts(spp=spp or 0, threads=threads, time_limit=time or 0.0, checkpoint_every=60.0)
    stop = ctypes.c_int(0)
    opts.stop = ctypes.pointer(stop)  # passes of about half a second: a stop loses at most one
    ss = _lib.murk.murk_session_begin(sc.ptr, ctypes.byref(opts), err, _ERRLEN)
    if not ss:
        raise RenderError(err.value.decode(errors="replace"))
    failure = []
    cb = _progress_callback(progress, ss, failure) if progress else None
    if cb:
        _lib.murk.murk_session_set_progress(ss, cb, None)
    rc, msg, interrupted = _run_passes(ss)
    res = _lib.RenderResult()
    end = _lib.murk.murk_session_end(ss, ctypes.byref(res), err, _ERRLEN)
    try:
        if not res.rgb:
            raise RenderError(msg or err.value.decode(errors="replace") or "murk: nothing was rendered")
        n = res.width * res.height * 3
        image = np.ctypeslib.as_array(res.rgb, shape=(n,)).copy().reshape(res.height, res.width, 3)
    finally:
        _lib.libc.free(ctypes.cast(res.rgb, ctypes.c_void_p))
    result = Result(image, res.seconds, res.spp, _counters(sc, res), _metadata(sc, res, spp),
                    bool(res.interrupted))
    if failure and not isinstance(failure[0], KeyboardInterrupt):
        raise failure[0]
    if interrupted or failure:  # Ctrl-C while the main thread waited, or while the callback ran
        e = KeyboardInterrupt("murk: render interrupted after %d spp" % res.spp)
        e.result = result
        raise e
    if rc < 0 or end != 0:
        raise RenderError(msg or err.value.decode(errors="replace"))
    return result


# ---- images and comparisons --------------------------------------------------------------------------

_EXR_KEYS = ("scene", "spp", "seed", "render_time", "version", "integrator", "nonfinite_samples", "set", "plugins",
             "spp_requested", "interrupted", "resumed_from", "counters", "max_sample", "ranks", "threads",
             "thread_time", "part", "part_split", "part_tiles", "scene_hash", "exposure")


def read_exr(path):
    """An EXR as murk.Result: image (float32 H x W x 3), seconds and counters from its murk:render_time and
    murk:counters (0 and {} when absent), metadata: its murk:* attributes (without the prefix)."""
    w, h, rgb = ctypes.c_int(), ctypes.c_int(), ctypes.POINTER(ctypes.c_float)()
    err = ctypes.create_string_buffer(_ERRLEN)
    im = _lib.lab.murk_lab_image_read(os.fsencode(path), ctypes.byref(w), ctypes.byref(h), ctypes.byref(rgb),
                                      err, _ERRLEN)
    if not im:
        raise OSError(err.value.decode(errors="replace"))
    try:
        image = np.ctypeslib.as_array(rgb, shape=(h.value * w.value * 3,)).copy().reshape(h.value, w.value, 3)
        meta = {}
        for k in _EXR_KEYS:
            v = _lib.lab.murk_lab_image_attr(im, ("murk:" + k).encode())
            if v is not None:
                meta[k] = v.decode(errors="replace")
        seconds, lookups = _lib.lab.murk_lab_image_seconds(im), _lib.lab.murk_lab_image_lookups(im)
    finally:
        _lib.lab.murk_lab_image_free(im)
    try:
        counters = json.loads(meta.get("counters", "{}"))
    except ValueError:
        counters = {}
    r = Result(image, max(seconds, 0.0), int(meta.get("spp", "0") or 0), counters, meta)
    r._lookups = lookups
    return r


def _comparable(x, what):
    """(float32 C-contiguous H x W x 3 array, seconds, lookups) of an array, a Result or an EXR's path."""
    if isinstance(x, (str, bytes, os.PathLike)):
        x = read_exr(x)
    if isinstance(x, Result):
        lookups = getattr(x, "_lookups", None)
        if lookups is None:
            lookups = x.counters.get("total", {}).get("lookups", -1)
        return x.image, x.seconds or -1.0, float(lookups)
    if not isinstance(x, np.ndarray):
        raise TypeError("murk.compare: %s must be a numpy array (H x W x 3 float32), a murk.Result or an EXR's "
                        "path, got a %s" % (what, type(x).__name__))
    if x.dtype != np.float32:
        raise TypeError("murk.compare: %s has dtype %s; it must be float32 (linear RGB; use .astype(np.float32))"
                        % (what, x.dtype))
    if x.ndim != 3 or x.shape[2] != 3 or x.shape[0] < 1 or x.shape[1] < 1:
        raise ValueError("murk.compare: %s has shape %s; it must be H x W x 3 (linear RGB), H and W above 0"
                         % (what, x.shape))
    return np.ascontiguousarray(x), -1.0, -1.0


def compare(test, reference, crop=None):
    """The figures `murk compare TEST REFERENCE --json` prints, as a dict: mse, relmse (mean (a-r)^2/(r^2+0.01))
    and relmse_se, mare, diff and diff_se (mean a - r per channel and all), z (the bias test), n, nonfinite,
    and when the test's render time and density lookups are known (a murk.Result or a murk EXR),
    seconds/efficiency_time and lookups/efficiency_lookups. test and reference: numpy arrays (H x W x 3
    float32), murk.Result or EXR paths. crop: (x, y, w, h)."""
    a, seconds, lookups = _comparable(test, "test")
    r, _, _ = _comparable(reference, "reference")
    if a.shape != r.shape:
        raise ValueError("murk.compare: test is %dx%d but reference is %dx%d" % (a.shape[1], a.shape[0],
                                                                                r.shape[1], r.shape[0]))
    h, w = a.shape[:2]
    c = (0, 0, w, h) if crop is None else tuple(crop)
    if len(c) != 4 or not all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in c) or \
            c[0] < 0 or c[1] < 0 or c[2] < 1 or c[3] < 1 or c[0] + c[2] > w or c[1] + c[3] > h:
        raise ValueError("murk.compare: crop %r is not (x, y, w, h) inside the %dx%d images" % (crop, w, h))
    f = _lib.CompareFigures()
    fp = ctypes.POINTER(ctypes.c_float)
    _lib.lab.murk_lab_compare_figures(a.ctypes.data_as(fp), r.ctypes.data_as(fp), w, _lib.Crop(*map(int, c)),
                                      seconds, lookups, ctypes.byref(f))
    m = f.m
    out = {"crop": list(map(int, c)), "n": m.n, "nonfinite": m.nonfinite, "mse": m.mse, "relmse": m.relmse,
           "relmse_se": m.relmse_se, "mare": m.mare, "diff": list(m.diff), "diff_se": list(m.diff_se), "z": f.z}
    if f.seconds > 0:
        out.update(seconds=f.seconds, efficiency_time=f.efficiency_time)
    if f.lookups > 0:
        out.update(lookups=f.lookups, efficiency_lookups=f.efficiency_lookups)
    return out


from ._lab import bench, plugins  # noqa: E402  (they use the names above)
