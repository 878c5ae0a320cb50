"""Finds and loads libmurk and libmurklab with ctypes, and declares the C types and functions of
murk/murk.h and murk/lab.h that the module calls. Internal to the murk module."""
import ctypes
import ctypes.util
import os

c_int, c_uint32, c_uint64, c_double, c_float, c_char_p, c_size_t, c_void_p = (
    ctypes.c_int, ctypes.c_uint32, ctypes.c_uint64, ctypes.c_double, ctypes.c_float, ctypes.c_char_p,
    ctypes.c_size_t, ctypes.c_void_p)

COUNTER_SLOTS = 64
COUNTER_NAMES = ("lookups", "cells", "collisions", "scatters", "shadow")


class Counters(ctypes.Structure):
    _fields_ = [(n, c_uint64) for n in COUNTER_NAMES]


class RenderOpts(ctypes.Structure):
    _fields_ = [("spp", c_int), ("threads", c_int), ("time_limit", c_double), ("progress", c_int),
                ("stop", ctypes.POINTER(c_int)), ("checkpoint", c_char_p), ("checkpoint_every", c_double),
                ("resume", c_char_p), ("scene_hash", c_uint64), ("overrides", c_char_p),
                ("part", c_int), ("parts", c_int)]


class RenderResult(ctypes.Structure):
    _fields_ = [("width", c_int), ("height", c_int), ("spp", c_int), ("rgb", ctypes.POINTER(c_float)),
                ("seconds", c_double), ("samples", c_uint64), ("rays", c_uint64), ("nonfinite", c_uint64),
                ("interrupted", c_int), ("resumed_spp", c_int), ("nmedia", c_int),
                ("media", Counters * COUNTER_SLOTS), ("max_sample", c_double), ("ranks", c_int),
                ("threads", c_int), ("thread_seconds", c_double)]


class SceneInfo(ctypes.Structure):
    _fields_ = [("width", c_int), ("height", c_int), ("spp", c_int), ("seed", c_uint64), ("exposure", c_float),
                ("integrator", c_char_p), ("nmedia", c_int)]


class Crop(ctypes.Structure):
    _fields_ = [("x", c_int), ("y", c_int), ("w", c_int), ("h", c_int)]


class Metrics(ctypes.Structure):
    _fields_ = [("n", c_size_t), ("nonfinite", c_size_t), ("mse", c_double), ("relmse_raw", c_double),
                ("ref_noise", c_double), ("relmse", c_double), ("relmse_se", c_double), ("mare", c_double),
                ("diff", c_double * 4), ("diff_se", c_double * 4)]


class CompareFigures(ctypes.Structure):
    _fields_ = [("m", Metrics), ("z", c_double), ("seconds", c_double), ("lookups", c_double),
                ("efficiency_time", c_double), ("efficiency_lookups", c_double)]


class BenchRow(ctypes.Structure):
    _fields_ = [("variant", c_int), ("label", c_char_p), ("budget", c_double), ("seed", c_int), ("spp", c_int),
                ("seconds", c_double), ("rays", c_uint64), ("counters", Counters), ("metrics", Metrics),
                ("nonfinite", c_uint64), ("max_sample", c_double)]


class Abi(ctypes.Structure):
    _fields_ = [("major", c_uint32), ("minor", c_uint32)]


class Param(ctypes.Structure):
    _fields_ = [("name", c_char_p), ("type", c_uint32), ("flags", c_uint32), ("default", c_double * 3),
                ("def_str", c_char_p), ("choices", c_char_p), ("min", c_double), ("max", c_double),
                ("doc", c_char_p)]


class PluginInfo(ctypes.Structure):
    _fields_ = [("name", c_char_p), ("description", c_char_p), ("version", c_char_p), ("path", c_char_p),
                ("kind", c_int), ("abi", Abi), ("params", ctypes.POINTER(Param)), ("nparams", c_uint32)]


PROGRESS_FN = ctypes.CFUNCTYPE(None, c_void_p, c_double, c_double, c_int)
BENCH_ROW_FN = ctypes.CFUNCTYPE(None, c_void_p, ctypes.POINTER(BenchRow))


def _libdir():
    """The folder of libmurk: $MURK_LIBDIR (set by `meson devenv`), else the installed prefix's libdir
    found from this file's place (_install.py, written by meson install), else the linker's search."""
    d = os.environ.get("MURK_LIBDIR")
    if d:
        return d
    try:
        from . import _install
    except ImportError:
        return None
    here = os.path.dirname(os.path.abspath(__file__))
    prefix = here
    for _ in range(len(_install.PYDIR.strip("/").split("/")) + 1):  # up from PYDIR/murk to the prefix
        prefix = os.path.dirname(prefix)
    return os.path.join(prefix, _install.LIBDIR)


def _open(name, libdir):
    path = os.path.join(libdir, "lib%s.so" % name) if libdir else ctypes.util.find_library(name)
    if libdir and not os.path.exists(path):
        path = os.path.join(libdir, "lib%s.so.0" % name)
    if not path:
        raise ImportError("murk: lib%s.so not found (run from `meson devenv -C build`, or install murk)" % name)
    try:
        return ctypes.CDLL(path)
    except OSError as e:
        raise ImportError("murk: cannot load %s: %s" % (path, e)) from None


def _declare(lib, name, restype, *argtypes):
    f = getattr(lib, name)
    f.restype, f.argtypes = restype, list(argtypes)


_dir = _libdir()
murk = _open("murk", _dir)
lab = _open("murklab", _dir)
libc = ctypes.CDLL(None)
_declare(libc, "free", None, c_void_p)

P = ctypes.POINTER
_declare(murk, "murk_scene_load", c_void_p, c_char_p, P(c_char_p), c_size_t, c_char_p, c_size_t)
_declare(murk, "murk_scene_load_text", c_void_p, c_char_p, c_char_p, P(c_char_p), c_size_t, c_char_p, c_size_t)
_declare(murk, "murk_scene_free", None, c_void_p)
_declare(murk, "murk_scene_check_unused", c_int, c_void_p, c_char_p, c_size_t)
_declare(murk, "murk_scene_get_info", None, c_void_p, P(SceneInfo))
_declare(murk, "murk_scene_medium_name", c_char_p, c_void_p, c_int)
_declare(murk, "murk_scene_plugins", c_size_t, c_void_p, c_char_p, c_size_t)
_declare(murk, "murk_session_begin", c_void_p, c_void_p, P(RenderOpts), c_char_p, c_size_t)
_declare(murk, "murk_session_set_progress", None, c_void_p, PROGRESS_FN, c_void_p)
_declare(murk, "murk_session_run_pass", c_int, c_void_p, c_char_p, c_size_t)
_declare(murk, "murk_session_stop", None, c_void_p)
_declare(murk, "murk_session_end", c_int, c_void_p, P(RenderResult), c_char_p, c_size_t)
_declare(murk, "murk_set_quiet", None, c_int)
_declare(murk, "murk_kind_name", c_char_p, c_int)
_declare(lab, "murk_lab_compare_figures", None, P(c_float), P(c_float), c_int, Crop, c_double, c_double,
         P(CompareFigures))
_declare(lab, "murk_lab_image_read", c_void_p, c_char_p, P(c_int), P(c_int), P(P(c_float)), c_char_p, c_size_t)
_declare(lab, "murk_lab_image_attr", c_char_p, c_void_p, c_char_p)
_declare(lab, "murk_lab_image_free", None, c_void_p)
_declare(lab, "murk_lab_image_seconds", c_double, c_void_p)
_declare(lab, "murk_lab_image_lookups", c_double, c_void_p)
_declare(lab, "murk_lab_bench_run", c_int, c_int, P(c_char_p), P(c_int), BENCH_ROW_FN, c_void_p)
_declare(lab, "murk_lab_plugin_open", c_void_p, c_char_p, P(PluginInfo), c_char_p, c_size_t)
_declare(lab, "murk_lab_plugin_close", None, c_void_p)
_declare(lab, "murk_lab_medium_params", P(Param), P(c_uint32))
_declare(lab, "murk_lab_plugin_names", c_void_p)


def strings(items):
    """A C array of the byte strings of items (kept alive by the array's _keep)."""
    enc = [s.encode() for s in items]
    arr = (c_char_p * max(1, len(enc)))(*enc)
    arr._keep = enc
    return arr
