"""The Python module as a researcher uses it (pytest, Debian's python3-pytest): murk.render of a scene file
gives the murk command's EXR bit for bit; a scene error raises murk.SceneError with its location (file,
line, column; the --set it came from; a dict scene's key path) and the CLI's "did you mean"; input that is
not a scene or not an image raises a Python exception, never a crash; Ctrl-C (a stop) and a progress
callback end a render after whole passes; compare gives the CLI's figures; plugins lists the schemas;
bench returns its rows; a render leaves the GIL to other threads; the sweep example of docs/ runs; and the
module imports and renders from a `meson install --destdir` prefix.
Run by meson (tests 'python' and 'python_install'), which sets MURK_SOURCE_ROOT, MURK_EXE, MURK_BUILD_ROOT
and the module's paths."""
import copy
import ctypes
import json
import math
import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import murk

SRC = os.environ.get("MURK_SOURCE_ROOT", os.path.join(os.path.dirname(__file__), "..", ".."))
EXE = os.environ.get("MURK_EXE")
CORNELL = os.path.join(SRC, "scenes", "cornell.yaml")
SMOKE = os.path.join(SRC, "scenes", "cornell_smoke.yaml")
SMALL = {"render.resolution": [24, 24]}

BOX = {"murk": 1, "render": {"resolution": [16, 16], "spp": 2, "seed": 3},
       "camera": {"from": [0, 1, 3.4], "at": [0, 1, 0], "up": [0, 1, 0], "fov": 40},
       "integrator": {"type": "path", "max_depth": 8},
       "materials": {"white": {"type": "diffuse", "albedo": [0.73, 0.73, 0.73]}},
       "shapes": [{"type": "quad", "center": [0, 0, 0], "u": [0, 0, 1], "v": [1, 0, 0], "material": "white"},
                  {"type": "quad", "center": [0, 1.998, 0], "u": [0.2, 0, 0], "v": [0, 0, 0.2],
                   "material": "white", "emission": [17, 12, 4]}]}


def box(change=None):
    s = copy.deepcopy(BOX)
    if change:
        change(s)
    return s


@pytest.mark.skipif(not EXE, reason="needs the murk command (MURK_EXE)")
@pytest.mark.parametrize("scene,sets", [(CORNELL, SMALL), (SMOKE, dict(SMALL, **{"media.smoke.type": "decomposition"}))])
def test_render_equals_cli_exr(tmp_path, scene, sets):
    out = tmp_path / "cli.exr"
    args = [EXE, "render", scene, "--spp", "3", "--threads", "2", "-q", "-o", str(out)]
    for k, v in sets.items():
        args += ["--set", "%s=%s" % (k, json.dumps(v).replace(" ", ""))]
    subprocess.run(args, check=True)
    cli = murk.read_exr(out)
    r = murk.render(scene, spp=3, threads=1, set=sets)  # another thread count: the same pixels
    assert r.image.dtype == np.float32 and r.image.shape == (24, 24, 3)
    assert r.image.tobytes() == cli.image.tobytes()
    assert r.counters == json.loads(cli.metadata["counters"])  # the same work, counted the same
    assert r.metadata["spp"] == 3 and r.seconds > 0 and not r.interrupted


def test_dict_scene_equals_its_file(tmp_path):
    import yaml  # python3-yaml: the dict written as a file by another YAML writer
    f = tmp_path / "box.yaml"
    f.write_text(yaml.safe_dump(BOX))
    assert murk.render(BOX).image.tobytes() == murk.render(str(f)).image.tobytes()


def test_seed_and_set():
    a = murk.render(BOX, seed=1).image
    assert a.tobytes() == murk.render(BOX, set={"render.seed": 1}).image.tobytes()
    assert a.tobytes() != murk.render(BOX, seed=2).image.tobytes()


def test_file_error_has_location(tmp_path):
    f = tmp_path / "bad.yaml"
    f.write_text(open(CORNELL).read().replace("albedo: [0.63", "albedoo: [0.63"))
    with pytest.raises(murk.SceneError) as e:
        murk.render(str(f))
    assert (e.value.file, e.value.line) == (str(f), 10) and e.value.col > 1
    assert "did you mean 'albedo'" in str(e.value) and str(e.value).startswith("%s:10:" % f)


def test_set_error_quotes_the_set():
    with pytest.raises(murk.SceneError) as e:
        murk.render(SMOKE, set={"media.smok.type": "delta"})
    assert e.value.set == "media.smok.type=delta" and e.value.line is None
    assert str(e.value) == ("--set media.smok.type=delta: media.smok is not used by any shape or by the camera; "
                            "did you mean media.smoke?")
    with pytest.raises(murk.SceneError, match=r"^--set render.spp=abc: render.spp must be a number"):
        murk.render(SMOKE, set=["render.spp=abc"])


@pytest.mark.parametrize("change,path,text", [
    (lambda s: s["materials"]["white"].update(albedoo=[1, 1, 1]), ("materials", "white", "albedoo"),
     "did you mean 'albedo'?"),
    (lambda s: s["shapes"][1].update(materiall="white"), ("shapes", 1, "materiall"), "did you mean 'material'?"),
    (lambda s: s["materials"]["white"].update(type="difuse"), ("materials", "white", "type"),
     "did you mean 'diffuse'?"),
    (lambda s: s["render"].update(resolution="big"), ("render", "resolution"), "must be a list of 2 numbers"),
    (lambda s: s["shapes"][0]["center"].__setitem__(1, "x"), ("shapes", 0, "center", 1), ""),
])
def test_dict_error_names_the_key(change, path, text):
    with pytest.raises(murk.SceneError) as e:
        murk.render(box(change))
    assert e.value.path == path and text in str(e.value), str(e.value)
    assert str(e.value).startswith("scene" + "".join("[%r]" % (k,) for k in path) + ": ")


@pytest.mark.parametrize("change,text", [
    (lambda s: s["materials"]["white"].update(albedo=[math.nan, 1, 1]), "NaN or infinite"),
    (lambda s: s["shapes"][0].update(center=[0, math.inf, 0]), "NaN or infinite"),
    (lambda s: s["shapes"][0].update(center=[0, object(), 0]), "is not a scene value"),
    (lambda s: s.update({3: 4}), "a scene's keys are strings"),
    (lambda s: s.update(camera=np.zeros(1 << 25)), "larger than a scene holds"),
    (lambda s: s["materials"].update(loop=s), "nested deeper"),
    (lambda s: s.update(render=[[[[[[[[[1]]]]]]]]]), ""),
])
def test_dict_that_is_not_a_scene(change, text):
    with pytest.raises(murk.SceneError, match=None) as e:
        murk.render(box(change))
    assert text in str(e.value)


@pytest.mark.parametrize("scene,kw,exc", [
    ([1, 2], {}, TypeError), (BOX, {"spp": 0}, ValueError), (BOX, {"spp": 2.5}, ValueError),
    (BOX, {"threads": -1}, ValueError), (BOX, {"time": math.nan}, ValueError), (BOX, {"set": "a=b"}, TypeError),
    (BOX, {"progress": 3}, TypeError), ("/nonexistent/scene.yaml", {}, murk.SceneError),
    (BOX, {"set": {"render.seed": math.nan}}, murk.SceneError),
])
def test_bad_arguments_raise(scene, kw, exc):
    with pytest.raises(exc):
        murk.render(scene, **kw)


def test_progress_and_stop():
    seen, tiny = [], {"render.resolution": [12, 12]}
    r = murk.render(SMOKE, spp=16, set=tiny, progress=lambda f, s, last: seen.append((f, last)))
    assert seen[-1] == (1.0, True) and all(b >= a for (a, _), (b, _) in zip(seen, seen[1:]))
    # returning False stops it after whole passes, as Ctrl-C would: the image of the spp reached
    s = murk.render(SMOKE, spp=1 << 20, set=tiny, time=60, progress=lambda f, s, last: s < 0.2)
    assert s.interrupted and 0 < s.spp < 1 << 20
    assert s.image.tobytes() == murk.render(SMOKE, spp=s.spp, set=tiny).image.tobytes()

    def boom(f, s, last):
        raise ZeroDivisionError("from the callback")
    with pytest.raises(ZeroDivisionError):
        murk.render(SMOKE, spp=16, set=tiny, progress=boom)
    assert r.spp == 16


def test_ctrl_c_stops_after_whole_passes():
    """SIGINT (Ctrl-C) in a render: KeyboardInterrupt with .result, the image of the whole passes done."""
    code = """if 1:
        import os, signal, murk
        tiny, sent = {"render.resolution": [12, 12]}, []
        def ctrl_c(fraction, seconds, last):  # SIGINT to the process 0.2 s into the render
            if seconds > 0.2 and not sent:
                sent.append(os.kill(os.getpid(), signal.SIGINT))
        try:
            murk.render(%r, spp=1 << 22, set=tiny, time=120, progress=ctrl_c)
            print("not interrupted")
        except KeyboardInterrupt as e:
            r = e.result
            same = r.image.tobytes() == murk.render(%r, spp=r.spp, set=tiny).image.tobytes()
            print("interrupted", r.interrupted, r.spp > 0, same)
    """ % (SMOKE, SMOKE)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.strip() == "interrupted True True True", out.stdout + out.stderr


def _main_thread_share(work, bin_seconds=0.5):
    """Runs work() on a thread of its own while this thread counts in which bins of bin_seconds (over
    work's span) it got to run Python: the share of those bins, and the span in seconds."""
    t = threading.Thread(target=work)
    t0 = time.monotonic()
    t.start()
    bins = set()
    while t.is_alive():
        bins.add(int((time.monotonic() - t0) / bin_seconds))
    span = time.monotonic() - t0
    n = max(1, int(span / bin_seconds))
    return len([b for b in bins if b < n]) / n, span


def test_render_releases_the_gil():
    """Another Python thread runs throughout a render of about 2 s (a bin of 0.5 s without it would mean
    the render held the GIL for that long; bins that long keep a loaded machine's scheduling out of it).
    Must fail: the same measure on calls that hold the GIL (libc's usleep through ctypes.PyDLL, two of
    1 s) sees this thread stopped in most bins."""
    r = []
    share, span = _main_thread_share(lambda: r.append(murk.render(SMOKE, spp=1 << 20, time=2, threads=1,
                                                                  set={"render.resolution": [32, 32]}, quiet=True)))
    assert r and r[0].interrupted is False and span > 1.5
    held = ctypes.PyDLL(None).usleep
    held_share, _ = _main_thread_share(lambda: [held(1000000) for _ in range(2)])
    print("main thread ran in %.0f %% of the bins during the render, %.0f %% during GIL-holding calls"
          % (100 * share, 100 * held_share))
    assert share >= 0.75, share
    assert held_share <= 0.5, held_share  # the must-fail case: the measure sees a held GIL


def test_sweep_example_runs(tmp_path):
    """docs/python_sweep.py, the notebook-style example, in its --quick form: it renders, compares and plots."""
    pytest.importorskip("matplotlib")
    out = tmp_path / "sweep.png"
    run = subprocess.run([sys.executable, os.path.join(SRC, "docs", "python_sweep.py"), "--quick", str(out)], cwd=SRC,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert out.stat().st_size > 1000 and run.stdout.count("relMSE") == 8


def test_compare():
    ref = murk.render(BOX, spp=16)
    a = murk.render(BOX, spp=2, seed=9)
    f = murk.compare(a, ref)
    assert f["relmse"] > 0 and "efficiency_time" in f and f["n"] == 16 * 16 * 3
    g = murk.compare(a.image, ref.image)  # arrays: the same figures, without the render's time
    assert g["relmse"] == f["relmse"] and "seconds" not in g
    assert murk.compare(ref.image, ref.image)["mse"] == 0
    assert murk.compare(a.image, ref.image, crop=(0, 0, 4, 4))["n"] == 48
    img = ref.image
    for bad, exc in [(img.astype(np.float64), TypeError), (img[:, :, :2], ValueError), (img[:8], ValueError),
                     (img[None], ValueError), ([[0.0]], TypeError), (np.zeros((0, 4, 3), np.float32), ValueError)]:
        with pytest.raises(exc):
            murk.compare(img, bad)
    with pytest.raises(ValueError):
        murk.compare(img, img, crop=(10, 10, 10, 10))
    with pytest.raises(OSError):
        murk.compare("/nonexistent.exr", img)


@pytest.mark.skipif(not EXE, reason="needs the murk command (MURK_EXE)")
def test_compare_files_as_cli(tmp_path):
    for name, spp in [("a", 2), ("r", 8)]:
        subprocess.run([EXE, "render", CORNELL, "--spp", str(spp), "-q", "--set", "render.resolution=[16,16]",
                        "-o", str(tmp_path / (name + ".exr"))], check=True)
    cli = json.loads(subprocess.run([EXE, "compare", str(tmp_path / "a.exr"), str(tmp_path / "r.exr"), "--json"],
                                    check=True, capture_output=True, text=True).stdout)
    py = murk.compare(tmp_path / "a.exr", str(tmp_path / "r.exr"))
    for k in ("n", "mse", "relmse", "relmse_se", "mare", "z", "seconds", "efficiency_time"):
        assert py[k] == pytest.approx(cli[k], rel=1e-5), k  # the CLI prints 6 to 9 digits


def test_plugins():
    p = murk.plugins()
    assert p["delta"]["kind"] == "medium" and any(k["name"] == "sigma_a" for k in p["delta"]["medium_keys"])
    dec = {q["name"]: q for q in p["decomposition"]["params"]}
    assert dec and all(q["doc"] for q in dec.values())
    assert p["diffuse"]["kind"] == "material" and p["path"]["kind"] == "integrator"


def test_bench_rows(tmp_path):
    rows = murk.bench(CORNELL, vary={"integrator.max_depth": [2, 4]}, set={"render.resolution": [8, 8]},
                      spp=[1, 2], repeat=2, ref_spp=4, threads=1, out=tmp_path / "b")
    assert len(rows) == 8 and {r["label"] for r in rows} == {"max_depth=2", "max_depth=4"}
    assert all(r["relmse"] == r["relmse"] and r["rays"] > 0 for r in rows)
    assert (tmp_path / "b" / "bench.csv").exists() and (tmp_path / "b" / "report.html").exists()
    with pytest.raises(murk.SceneError, match=r"cornell_smoke.yaml:\d+:\d+: --vary media.smok.type: media has no 'smok'"):
        murk.bench(SMOKE, vary={"media.smok.type": ["delta"]}, spp=[1], repeat=2, ref_spp=4)


def test_bench_frame(tmp_path):
    """frame=True: the same rows as a pandas DataFrame (skipped where python3-pandas is not installed)."""
    pandas = pytest.importorskip("pandas")
    df = murk.bench(CORNELL, vary={"integrator.max_depth": [2, 4]}, set={"render.resolution": [8, 8]}, spp=[1],
                    repeat=2, ref_spp=4, threads=1, frame=True)
    assert isinstance(df, pandas.DataFrame) and len(df) == 4 and set(df["label"]) == {"max_depth=2", "max_depth=4"}


@pytest.mark.install
def test_installed_prefix(tmp_path):
    """meson install --destdir, then the installed module alone (no build-tree paths) renders."""
    build, pydir = os.environ.get("MURK_BUILD_ROOT"), os.environ.get("MURK_PYTHON_DIR")
    if not build or not pydir:
        pytest.skip("needs MURK_BUILD_ROOT and MURK_PYTHON_DIR (set by meson test)")
    root = tmp_path / "root"
    subprocess.run(["meson", "install", "-C", build, "--destdir", str(root), "--no-rebuild", "--quiet"], check=True,
                   stdout=subprocess.DEVNULL)
    env = {k: v for k, v in os.environ.items()
           if k not in ("MURK_LIBDIR", "MURK_PLUGIN_PATH", "PYTHONPATH", "LD_LIBRARY_PATH")}
    env["PYTHONPATH"] = str(root) + pydir
    code = ("import murk; print(murk.__file__); "
            "print(murk.render('scenes/cornell.yaml', spp=4, set={'render.resolution': [8, 8]}).image.shape)")
    out = subprocess.run([sys.executable, "-c", code], cwd=SRC, env=env, check=True, capture_output=True,
                         text=True).stdout.split("\n")
    assert out[0].startswith(str(root)) and out[1] == "(8, 8, 3)"
