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


def stamp(path, meta=None):
    """Adds the text keys to a PNG another program wrote (a browser's screenshot): tEXt chunks right
    after IHDR, the file rewritten through a temporary renamed over it."""
    import struct
    import zlib
    meta = meta or metadata()
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("%s: not a PNG file" % path)
    ihdr_end = 8 + 12 + struct.unpack(">I", data[8:12])[0]
    chunks = b""
    for k, v in meta.items():
        body = k.encode("latin-1") + b"\0" + v.encode("latin-1", "replace")
        chunks += struct.pack(">I", len(body)) + b"tEXt" + body + struct.pack(">I", zlib.crc32(b"tEXt" + body))
    tmp = "%s.tmp-%d" % (path, os.getpid())
    with open(tmp, "wb") as f:
        f.write(data[:ihdr_end] + chunks + data[ihdr_end:])
    os.replace(tmp, path)


if __name__ == "__main__":  # pngmeta.py FILE.png...: stamps each with murk's text keys
    import sys
    for p in sys.argv[1:]:
        stamp(p)
