"""pngmeta.py — the PNG text keys every chart under docs/ carries: murk:commit and murk:version, the same
keys murk's own PNG writer writes (core/image/png.c), so `murk info CHART.png` says which build made it.

    import pngmeta; fig.savefig(path, metadata=pngmeta.metadata())

The build is the one MURK_EXE (or MURK, else build/core/murk) names, asked with `murk --version`; when
MURK_COMMIT is set (tools/docs.sh sets it once for a whole run) that wins. Without a murk executable the
commit of the source tree (git describe) is used, marked as such."""
import os
import re
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _murk_version(exe):
    try:
        out = subprocess.run([exe, "--version"], capture_output=True, text=True, timeout=30).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    m = re.match(r"murk (\S+) \(commit (\S+),", out)
    return (m.group(1), m.group(2)) if m else None


def metadata():
    """{'murk:commit': ..., 'murk:version': ...} for matplotlib's savefig(metadata=...)."""
    commit, version = os.environ.get("MURK_COMMIT"), os.environ.get("MURK_VERSION")
    if not commit or not version:
        exe = os.environ.get("MURK_EXE") or os.environ.get("MURK") or os.path.join(ROOT, "build", "core", "murk")
        got = _murk_version(exe)
        if got:
            version, commit = version or got[0], commit or got[1]
    if not commit:
        try:
            commit = subprocess.run(["git", "-C", ROOT, "describe", "--always", "--dirty", "--abbrev=12",
                                     "--exclude=*"], capture_output=True, text=True).stdout.strip()
            commit = (commit or "unknown") + " (source tree; no murk executable)"
        except OSError:
            commit = "unknown"
    return {"murk:commit": commit, "murk:version": version or "unknown"}
