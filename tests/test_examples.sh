#!/bin/sh
# test_examples.sh — each installed example, copied and built out of tree as an author gets it (sdk_lib.sh:
# `meson install --destdir`, the installed murk-plugin.pc, the examples' own meson.build and its default
# release build), passes `murk check` (the full sample counts, not --quick) and measures, in a short
# `murk bench` against the built-in it mirrors on an installed starter scene, an efficiency
# (1 / (relMSE x seconds), each variant's mean over the seeds) within a stated band of the built-in's:
#   example_delta    vs delta     on cornell_smoke: the same algorithm step for step (the same image for
#                                 the same seed), so the ratio is their speed: band [0.67, 1.5]
#   example_matte    vs diffuse   as cornell's white walls: the same BSDF (tint 1), its own sampling code
#   example_bsdfpath vs volpath   on cornell, both at max_depth 16, rr_depth 4: BSDF sampling only, both
#                                 the last two: band [0.5, 2] (the relMSE of 3 seeds varies by ~20 %)
# The bands catch an example that fell behind its built-in (a debug build measured 0.76x for
# example_delta: the release check in sdk_lib.sh catches that one exactly); they do not rank them.
# Usage: test_examples.sh MESON; MURK_BUILD_ROOT is the build folder. In the suite 'examples'.
set -eu
MESON=${1:-meson}
. "$(dirname "$0")/sdk_lib.sh"
PY=/usr/bin/python3
sdk_install
sdk_build_examples
export MURK_PLUGIN_PATH="$EXB:$BUILTINS" MURK_CACHE_DIR="$TMP/cache"
unset LD_LIBRARY_PATH || true
SCENES="$SHARE/murk/scenes"

step "murk check on each example"
for p in example_matte example_delta example_bsdfpath; do
  "$MURK" check "$p" >"$TMP/check_$p.txt" 2>&1 || { cat "$TMP/check_$p.txt"; fail "murk check $p"; }
  tail -n 1 "$TMP/check_$p.txt"
done

# bench NAME LO HI SCENE ARGS...: the built-in is variant 0 (the reference is rendered with it), the
# example variant 1; the example's efficiency over the built-in's must lie in [LO, HI].
bench() {
  name=$1 lo=$2 hi=$3 scene=$4
  shift 4
  step "murk bench: $name against its built-in, band [$lo, $hi]"
  "$MURK" bench "$scene" "$@" --set 'render.resolution=[48,48]' --spp 8 --repeat 3 --ref-spp 256 --threads 2 \
    --no-charts -o "$TMP/bench_$name" >"$TMP/bench_$name.log" 2>&1 || { cat "$TMP/bench_$name.log"; fail "murk bench $name"; }
  "$PY" - "$TMP/bench_$name/bench.csv" "$lo" "$hi" <<'PYEOF' || fail "$name: efficiency outside its band"
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
eff, label = {}, {}
for v in ("0", "1"):
    r = [x for x in rows if x["variant"] == v]
    relmse = statistics.mean(float(x["relmse"]) for x in r)
    secs = statistics.mean(float(x["seconds"]) for x in r)
    eff[v], label[v] = 1.0 / (relmse * secs), r[0]["label"]
    print(f"  {label[v]}: relMSE {relmse:.4g}, {secs:.3f} s per render, efficiency {eff[v]:.4g}")
ratio = eff["1"] / eff["0"]
lo, hi = float(sys.argv[2]), float(sys.argv[3])
print(f"  efficiency ratio {ratio:.3f} (band [{lo}, {hi}])")
sys.exit(0 if lo <= ratio <= hi else 1)
PYEOF
}

bench example_delta 0.67 1.5 "$SCENES/cornell_smoke.yaml" --vary media.smoke.type=delta,example_delta
bench example_matte 0.5 2 "$SCENES/cornell.yaml" \
  --vary 'materials.white={type: diffuse},{type: example_matte, color: [0.73, 0.73, 0.73]}'
bench example_bsdfpath 0.5 2 "$SCENES/cornell.yaml" \
  --vary 'integrator={type: volpath, max_depth: 16, rr_depth: 4},{type: example_bsdfpath, max_depth: 16, rr_depth: 4}'
echo "examples: all steps passed"
