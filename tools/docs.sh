#!/bin/sh
# docs.sh — regenerates every figure, chart and table under docs/ from the current build, with one command:
#
#   tools/docs.sh [--scale S] [--docs DIR] [--out DIR] [PART ...]
#
# PARTs (default: all, in this order):
#   gallery        the report's figures 1-5 (scenes/figures.sh: docs/ggx_*.png, docs/gallery/fig*.png and
#                  Figure 4's table spliced into docs/gallery.md) and the lights' renders (docs/gallery/lights_*)
#   figures        docs/README.md's images: decomposition_control.png, spectral_trackers.png, cornell_bunny.png
#   glass          docs/glass/*.png (scenes/glass.sh)
#   transmittance  docs/results/transmittance.csv and transmittance_*.png (docs/results/plot.py)
#   stability      docs/stability.md and docs/stability/*.png (bench/stability/atlas.py)
#   bench          docs/results/bench/*: every `murk bench` run results.md quotes (charts, report.md, bench.csv,
#                  bench.json), then results.md's tables of them, spliced in by tools/bench_tables.py
#   page           docs/report_page.png, the comparison page in headless Chromium (skipped without chromium)
#
# --scale S multiplies every sample count and time budget (default 1: the counts the docs state; the long
# test runs --scale 0.01 into a temporary folder to show the command works). --docs DIR writes the docs
# folder there instead of docs/ (the Markdown files the tables are spliced into are copied there first);
# --out DIR holds the renders, logs and intermediate tables (default out/docs). It builds first (ninja), so
# every PNG carries the commit of the tree as built: murk's PNG writer and the chart scripts write the text
# keys murk:commit and murk:version (`murk info FILE.png`). Times are murk's own render times; the timed
# figures (Figure 4, glass, bench) record the load average beside them. A fresh clone at --scale 1 takes
# hours on 2 cores (the stability atlas alone tens of minutes; see docs/README.md for measured times).
set -eu
cd "$(dirname "$0")/.."
ROOT=$(pwd)
SCALE=1 DOCS=docs OUT=out/docs
while [ $# -gt 0 ]; do
  case $1 in
    --scale) SCALE=$2; shift 2 ;;
    --docs) DOCS=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    -h|--help) sed -n '2,25p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "docs.sh: unknown option $1" >&2; exit 2 ;;
    *) break ;;
  esac
done
PARTS=${*:-gallery figures glass transmittance stability bench page}
BUILD=${BUILD:-build}
MURK=${MURK:-$ROOT/$BUILD/core/murk}
PYTHON=${PYTHON:-/usr/bin/python3}
[ -n "${NO_BUILD:-}" ] || ninja -C "$BUILD" > /dev/null
mkdir -p "$DOCS" "$OUT"
DOCS=$(cd "$DOCS" && pwd) OUT=$(cd "$OUT" && pwd)
if [ "$DOCS" != "$ROOT/docs" ]; then   # a docs folder elsewhere: the Markdown the tables go into, copied
  cp "$ROOT"/docs/*.md "$DOCS"/
fi
export MURK PYTHON SCALE DOCS MURK_DOCS_DIR="$DOCS" MURK_EXE="$MURK"
# the commit every chart records, asked once (tools/pngmeta.py)
MURK_COMMIT=$("$MURK" --version | sed -n 's/.*(commit \([^,]*\),.*/\1/p')
MURK_VERSION=$("$MURK" --version | awk '{print $2}')
export MURK_COMMIT MURK_VERSION
touch "$OUT/.start"
echo "docs.sh: murk $MURK_VERSION, commit $MURK_COMMIT; scale $SCALE; docs into $DOCS; renders into $OUT"

n() { awk -v n="$1" -v s="$SCALE" -v m="${2:-1}" 'BEGIN { v = int(n * s + 0.5); print (v < m ? m : v) }'; }
secs() { awk -v n="$1" -v s="$SCALE" 'BEGIN { v = n * s; print (v < 0.05 ? 0.05 : v) }'; }
# list 4,16,64: each scaled, duplicates dropped (murk bench wants distinct budgets)
list() { echo "$1" | tr , '\n' | while read -r x; do n "$x"; done | awk '!seen[$0]++' | paste -sd, -; }
tlist() { echo "$1" | tr , '\n' | while read -r x; do secs "$x"; done | awk '!seen[$0]++' | paste -sd, -; }

part_gallery() {
  OUT="$OUT/gallery" sh scenes/figures.sh 1 2 3 4 5
  for s in envmap_spheres spot_fog cloud_sun; do
    "$MURK" render "scenes/$s.yaml" --spp "$(n 64)" -o "$OUT/lights_$s.exr"
    cp "$OUT/lights_$s.png" "$DOCS/gallery/lights_$s.png"
  done
}

part_figures() {
  S=scenes/cornell_smoke.yaml R="render.resolution=[256,256]"
  set --
  for c in 0 0.1 0.5 1; do
    "$MURK" render $S --spp "$(n 256)" --set "$R" --set media.smoke.type=decomposition --set media.smoke.control=$c \
      -o "$OUT/control_$c.exr" --quiet
    set -- "$@" "$OUT/control_$c.png:control $c"
  done
  "$PYTHON" bench/strip.py --title "decomposition tracking, control 0, 0.1, 0.5, 1 ($(n 256) spp)" \
    "$DOCS/decomposition_control.png" "$@"
  set --
  for t in naive_spectral spectral spectral_mis; do
    "$MURK" render scenes/spectral_extinction.yaml --spp "$(n 64)" --set "$R" --set media.medium.type=$t \
      -o "$OUT/trackers_$t.exr" --quiet
    set -- "$@" "$OUT/trackers_$t.png:$t"
  done
  "$PYTHON" bench/strip.py --title "spectral_extinction, $(n 64) spp each" "$DOCS/spectral_trackers.png" "$@"
  "$MURK" render scenes/cornell_bunny.yaml --spp "$(n 256)" --set media.smoke.type=spectral_mis -o "$OUT/cornell_bunny.exr"
  cp "$OUT/cornell_bunny.png" "$DOCS/cornell_bunny.png"
}

part_glass() { OUT="$OUT/glass" T=$(secs 15) REF_T=$(secs 60) sh scenes/glass.sh; }

part_transmittance() { "$PYTHON" docs/results/plot.py "$BUILD" "$(n 200 4)" "$(n 1000 8)" > /dev/null; }

part_stability() {
  if [ "$(awk -v s="$SCALE" 'BEGIN { print (s < 0.5) }')" = 1 ]; then
    "$PYTHON" bench/stability/atlas.py --quick --docs --out "$OUT/stability"   # the sweeps' extreme points
  else
    "$PYTHON" bench/stability/atlas.py --docs --spp "$(n 64)" --out "$OUT/stability"
  fi
}

# bench NAME SCENE ARGS... with --spp LIST / --time LIST / --ref-spp N scaled, into DOCS/results/bench/NAME;
# each argument is passed on as one word (a --set value may hold spaces)
bench() {
  name=$1 scene=$2; shift 2
  left=$#
  while [ "$left" -gt 0 ]; do   # rotate the arguments through "$@", scaling the budgets on the way
    a=$1; shift; left=$((left - 1))
    case $a in
      --spp) set -- "$@" --spp "$(list "$1")"; shift; left=$((left - 1)) ;;
      --time) set -- "$@" --time "$(tlist "$1")"; shift; left=$((left - 1)) ;;
      --ref-spp) set -- "$@" --ref-spp "$(n "$1" 4)"; shift; left=$((left - 1)) ;;
      *) set -- "$@" "$a" ;;
    esac
  done
  "$MURK" bench "$scene" "$@" --threads 2 -o "$DOCS/results/bench/$name"
}

part_bench() {
  R64='render.resolution=[64,64]'
  bench a_cornell_smoke scenes/cornell_smoke.yaml --vary media.smoke.type=delta,decomposition --set "$R64" --spp 4,16,64
  bench a_cornell_bunny scenes/cornell_bunny.yaml --vary media.smoke.type=delta,decomposition --set "$R64" --spp 4,16,64
  for s in absorption scattering extinction; do
    bench "b_spectral_$s" "scenes/spectral_$s.yaml" --vary media.medium.type=naive_spectral,spectral --set "$R64" \
      --spp 4,16,64
  done
  bench c_spectral_extinction scenes/spectral_extinction.yaml --vary integrator.type=volpath,volpath_nee \
    --vary media.medium.type=naive_spectral,spectral,spectral_mis --set "$R64" --time 2,6 --ref-spp 2048 \
    --ref-set media.medium.type=spectral_mis
  bench g2_spectral_fog_large_light scenes/spectral_fog_large_light.yaml \
    --vary media.fog.type=naive_spectral,spectral,spectral_mis --set "$R64" --spp 16,64 --ref-spp 2048 \
    --ref-set media.fog.type=spectral_mis
  bench g2b_spectral_fog_large_light_nee_mis scenes/spectral_fog_large_light.yaml \
    --vary integrator.nee_mis=solid_angle,null_scattering --vary media.fog.transmittance=residual_ratio,ratio \
    --set "$R64" --spp 16,64 --ref-spp 2048 --ref-set media.fog.type=spectral_mis
  bench g2c_spectral_fog_sky_nee_mis scenes/spectral_fog_sky.yaml --vary integrator.nee_mis=solid_angle,null_scattering \
    --set media.fog.transmittance=ratio --set "$R64" --spp 16,64 --ref-spp 1024 --ref-set media.fog.type=spectral_mis
  bench g2d_spectral_fog_sky scenes/spectral_fog_sky.yaml --vary media.fog.type=naive_spectral,spectral,spectral_mis \
    --set media.fog.transmittance=ratio --set "$R64" --spp 16,64 --ref-spp 1024 --ref-set media.fog.type=spectral_mis
  bench d_dense_cloud scenes/dense_cloud.yaml --vary media.cloud.type=delta,spectral,decomposition --set "$R64" \
    --time 2,6 --ref-spp 1024
  bench d2_dense_cloud_resolution scenes/dense_cloud.yaml --vary media.cloud.type=delta,decomposition \
    --vary media.cloud.majorant_resolution=16,64 --set "$R64" --time 6 --ref-spp 1024 --ref-set media.cloud.type=delta
  bench lights_cloud_sun scenes/cloud_sun.yaml --vary media.cloud.type=delta,decomposition,spectral,spectral_mis \
    --set 'render.resolution=[64,48]' --spp 4,16 --ref-spp 256
  bench lights_spot_fog scenes/spot_fog.yaml \
    --vary media.fog.type=delta,decomposition,spectral,spectral_mis,naive_spectral --set "$R64" --spp 4,16 --ref-spp 256
  # f.: Kutz 2017 on the cloud in sunlight, under the sky (k*_sky*) and in the scene's first version (sun sphere)
  HG='media.cloud.phase={type: hg, g: 0.6}' KUTZ='media.cloud.type=delta,spectral,decomposition'
  KREF='media.cloud.type=delta'
  bench k_dense_cloud_sun_sky scenes/dense_cloud_sun.yaml --vary "$KUTZ" --set "$R64" --time 2,6 --ref-spp 1024 \
    --ref-set "$KREF"
  bench k2_dense_cloud_sun_sky_hg scenes/dense_cloud_sun.yaml --vary "$KUTZ" --set "$HG" --set "$R64" --time 2,6 \
    --ref-spp 1024 --ref-set "$KREF"
  bench k3_dense_cloud_sun_sky_hg_spp scenes/dense_cloud_sun.yaml --vary "$KUTZ" --set "$HG" --set "$R64" --spp 16,64 \
    --ref-spp 1024 --ref-set "$KREF"
  bench k_dense_cloud_sun scenes/dense_cloud_sun_first.yaml --vary "$KUTZ" --set "$R64" --time 2,6 --ref-spp 1024 \
    --ref-set "$KREF"
  bench k2_dense_cloud_sun_hg scenes/dense_cloud_sun_first.yaml --vary "$KUTZ" --set "$HG" --set "$R64" --time 2,6 \
    --ref-spp 1024 --ref-set "$KREF"
  bench k3_dense_cloud_sun_smooth scenes/dense_cloud_sun_first.yaml --vary media.cloud.type=delta,decomposition \
    --set "$HG" --set media.cloud.density.cloud.octaves=2 --set media.cloud.majorant_resolution=32 --set "$R64" \
    --time 2,6 --ref-spp 1024 --ref-set "$KREF"
  # g.: Miller 2019's four steps on spectral_extinction
  MREF='media.medium.type=spectral_mis'
  bench m_spectral_extinction scenes/spectral_extinction.yaml --vary media.medium.type=naive_spectral,spectral,spectral_mis \
    --set "$R64" --time 2,6 --ref-spp 2048 --ref-set "$MREF"
  bench m2_spectral_extinction_nee_mis scenes/spectral_extinction.yaml --vary integrator.nee_mis=solid_angle,null_scattering \
    --set "$MREF" --set "$R64" --time 2,6 --ref-spp 2048 --ref-set "$MREF"
  bench m3_spectral_extinction_nee_mis_ratio scenes/spectral_extinction.yaml \
    --vary integrator.nee_mis=solid_angle,null_scattering --set "$MREF" --set media.medium.transmittance=ratio \
    --set "$R64" --time 2,6 --ref-spp 2048 --ref-set "$MREF"
  bench m4_spectral_extinction_nee_mis_spp scenes/spectral_extinction.yaml \
    --vary integrator.nee_mis=solid_angle,null_scattering --set "$MREF" --set media.medium.transmittance=ratio \
    --set "$R64" --spp 16,64 --ref-spp 2048 --ref-set "$MREF"
  # h.: every tracker, shadow-ray estimator and NEE weighting on the explosion
  EREF='media.fire.type=spectral_mis'
  bench e_explosion_trackers scenes/explosion.yaml \
    --vary media.fire.type=delta,decomposition,spectral,spectral_mis,naive_spectral --set "$R64" --time 2,6 \
    --ref-spp 1024 --ref-set "$EREF"
  bench e2_explosion_estimators scenes/explosion.yaml \
    --vary media.fire.transmittance=residual_ratio,ratio,track_length,unbiased_raymarch,power_series --set "$R64" \
    --time 2,6 --ref-spp 1024 --ref-set "$EREF"
  bench e3_explosion_nee_mis scenes/explosion.yaml --vary integrator.nee_mis=solid_angle,null_scattering --set "$R64" \
    --time 2,6 --ref-spp 1024 --ref-set "$EREF"
  # results.md's tables of these runs (sections a.-h.), written from the runs just made
  "$PYTHON" tools/bench_tables.py --results "$DOCS/results.md" --bench "$DOCS/results/bench"
}

part_page() {
  command -v chromium > /dev/null || { echo "docs.sh: no chromium: docs/report_page.png kept as it is"; return 0; }
  "$MURK" bench scenes/cornell_smoke.yaml --vary media.smoke.type=delta,decomposition,spectral_mis \
    --set 'render.resolution=[192,192]' --spp "$(list 4,16)" --repeat 2 -o "$OUT/smoke"
  printf 'open %s/smoke/report.html\nkey s\nhover 80 104\nscreenshot %s/report_page.png\n' "$OUT" "$DOCS" \
    > "$OUT/page_script.txt"
  "$PYTHON" tests/page_driver.py --size 1280x1000 "$OUT/page_script.txt" > /dev/null
  "$PYTHON" tools/pngmeta.py "$DOCS/report_page.png"
}

for p in $PARTS; do
  case $p in
    gallery|figures|glass|transmittance|stability|bench|page)
      t0=$(date +%s); echo "== docs.sh: $p"; "part_$p"
      echo "docs.sh: $p took $(( $(date +%s) - t0 )) s" | tee -a "$OUT/walltime.txt" ;;
    *) echo "docs.sh: unknown part '$p' (gallery figures glass transmittance stability bench page)" >&2; exit 2 ;;
  esac
done
# every PNG written must say which build made it
missing=$(find "$DOCS" -name '*.png' -newer "$OUT/.start" -exec sh -c '"$1" info "$2" | grep -q "^murk:commit: " || echo "$2"' _ "$MURK" {} \;)
[ -z "$missing" ] || { echo "docs.sh: PNGs without murk:commit:"; echo "$missing"; exit 1; }
echo "docs.sh: done (murk $MURK_VERSION, commit $MURK_COMMIT)"
