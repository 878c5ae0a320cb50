#!/bin/sh
# figures.sh — regenerates the gallery (docs/gallery.md, docs/gallery/*.png): the five figures of the
# reference report re-rendered by murk. EXRs, logs and a table of every render's spp, time and relMSE
# go to out/gallery/ (not committed); the strips with their captions go to docs/gallery/, and the numbers
# gallery.md quotes (Figure 2's comparison, Figure 3's and Figure 4's tables) are spliced into
# DOCS/gallery.md between its markers (tools/mdsplice.py, bench/figure4.py).
#
#   scenes/figures.sh [FIGURE ...]      # figures 1..5, lights, media; default: 2 3 4 5
#
#   1  GGX roughness rows, murk's scale and the report's (alpha:), and albedo/specular (docs/ggx_*.png)
#   2  Cornell box + bunny: decomposition at control 0 beside delta tracking (transmittance: ratio on
#      both, so the two make the same decisions), and their difference
#   3  cornell_smoke with decomposition: majorant x1.01, x1.1, x2, x4 and control 0.5, 0.1 (equal spp)
#   4  the three spectral scenes on heterogeneous media: the report's three-pass naive baseline, murk's
#      hero-per-path naive, spectral, spectral_mis, in interleaved timed rounds (bench/figure4.py)
#   5  the final scene, scenes/axe_room.yaml
#   lights  the scenes of the lights: block (envmap_spheres, spot_fog, cloud_sun), docs/gallery/lights_*.png
#   media   issue 27's media: dense_cloud_sun (Mie droplets in sunlight) and explosion (blackbody emission)
#
# Every render but figure 4's (timed) runs under `nice -n 10` with murk's default thread count. Figures 1,
# 5, lights and media splice a table of their renders (size, spp, seconds, load average) into gallery.md.
# Environment: MURK (the murk executable, default ./build/core/murk), SCALE (multiplies every spp,
# default 1; tools/docs.sh passes its --scale), DOCS (the docs folder written, default docs; the strips go
# to DOCS/gallery), OUT (renders, logs, tables; default out/gallery), REUSE=1 (keep renders already in
# OUT and only recompute the comparisons and strips), PYTHON (default /usr/bin/python3, needs
# python3-matplotlib for bench/strip.py). Normally run through tools/docs.sh, which regenerates all of docs/.
set -euf   # -f: no globbing, the [W,H] in --set values stay literal
cd "$(dirname "$0")/.."
MURK=${MURK:-./build/core/murk}
PYTHON=${PYTHON:-/usr/bin/python3}
SCALE=${SCALE:-1}
DOCS=${DOCS:-docs}
OUT=${OUT:-out/gallery}
DOC=$DOCS/gallery
RES=256                       # figures 2-3: 256x256
# n N: N spp times SCALE, at least 1
n() { awk -v n="$1" -v s="$SCALE" 'BEGIN { v = int(n * s + 0.5); print (v < 1 ? 1 : v) }'; }
REF_SPP=$(n 512)              # references for relMSE (figure 3): 8x the spp of a 64-spp variant,
                              # seed 1: independent of the variants' seed-0 samples
mkdir -p "$OUT" "$DOC"
TABLE=$OUT/results.txt
[ -f "$TABLE" ] || printf 'image\tspp\tseconds\trelMSE\n' > "$TABLE"

# render NAME SCENE ARGS... : renders $OUT/NAME.exr; leaves "SPP SECONDS WxH LOAD_BEFORE LOAD_AFTER" in
# $OUT/NAME.stats (the 1-minute load averages)
render() {
  name=$1; scene=$2; shift 2
  if [ "${REUSE:-0}" = 1 ] && [ -s "$OUT/$name.stats" ] && [ -f "$OUT/$name.exr" ]; then
    echo "== $name: reused"; return 0
  fi
  echo "== $name: murk render $scene $*"
  l0=$(cut -d' ' -f1 /proc/loadavg)
  nice -n 10 "$MURK" render "$scene" -o "$OUT/$name.exr" "$@" > "$OUT/$name.log" 2>&1 ||
    { cat "$OUT/$name.log"; exit 1; }
  l1=$(cut -d' ' -f1 /proc/loadavg)
  # murk's summary: "NAME.exr, NAME.png: WxH, N spp, T s, ..."
  sed -n 's/.*: \([0-9]*x[0-9]*\), \([0-9]*\) spp, \([0-9.]*\) s,.*/\2 \3 \1/p' "$OUT/$name.log" | tail -n 1 |
    sed "s/\$/ $l0 $l1/" > "$OUT/$name.stats"
  cat "$OUT/$name.stats"
}

# relmse NAME REF : relMSE of $OUT/NAME.exr against $OUT/REF.exr, appended to the results table and
# kept in $OUT/NAME.relmse
relmse() {
  r=$("$MURK" compare "$OUT/$1.exr" "$OUT/$2.exr" | awk '/^MSE/ {print $4}')
  printf '%s\n' "$r" > "$OUT/$1.relmse"
  set -- "$1" "$2" "$r" $(cat "$OUT/$1.stats")
  printf '%s\t%s\t%s\t%s\n' "$1" "$4" "$5" "$3" >> "$TABLE"
  printf '%s' "$3"
}

# e2 X : X in the docs' short exponent form, 6.35e-3
e2() { awk -v x="$1" 'BEGIN { s = sprintf("%.2e", x); sub(/e-0/, "e-", s); sub(/e\+0/, "e", s); print s }'; }

# splice NAME : standard input into DOCS/gallery.md's block NAME
splice() { "$PYTHON" tools/mdsplice.py "$DOCS/gallery.md" "$1" scenes/figures.sh; }

# renders_table NAME... : a Markdown table of the renders NAME (scenes/NAME.yaml) from their stats (with
# REUSE=1, stats written before they held the size and load: the size from the log, the load not recorded)
renders_table() {
  echo "| scene | size | spp | seconds | load average before–after |"; echo "|---|---|---|---|---|"
  for name in "$@"; do
    awk -v s="$name" -v lg="$OUT/$name.log" '{ size = $3
      while (size == "" && (getline l < lg) > 0) if (match(l, /: [0-9]+x[0-9]+, /)) size = substr(l, RSTART + 2, RLENGTH - 4)
      printf "| `scenes/%s.yaml` | %s | %s | %s | %s |\n", s, size, $1, $2, ($5 == "" ? "not recorded" : $4 "–" $5) }' \
      "$OUT/$name.stats"
  done
}

# caption NAME LABEL [REF] : "LABEL\nN spp, T s[\nrelMSE X]" for bench/strip.py
caption() {
  set -- "$1" "$2" "${3:-}" $(cat "$OUT/$1.stats")
  c="$2\\n$4 spp, $5 s"
  if [ -n "$3" ]; then c="$c\\nrelMSE $(relmse "$1" "$3")"; fi
  printf '%s' "$c"
}

figure1() {
  for s in ggx_roughness ggx_roughness_alpha ggx_albedo_specular; do
    render "$s" "scenes/$s.yaml" --spp "$(n 256)"
    cp "$OUT/$s.png" "$DOCS/$s.png"
  done
  renders_table ggx_roughness ggx_roughness_alpha ggx_albedo_specular | splice "fig1 renders"
}

figure2() {
  S=scenes/cornell_bunny.yaml
  render bunny_delta $S --spp "$(n 128)" --set render.resolution=[$RES,$RES] --set media.smoke.type=delta \
    --set media.smoke.transmittance=ratio
  render bunny_control0 $S --spp "$(n 128)" --set render.resolution=[$RES,$RES] \
    --set media.smoke.type=decomposition --set media.smoke.control=0 --set media.smoke.transmittance=ratio
  "$MURK" compare "$OUT/bunny_control0.exr" "$OUT/bunny_delta.exr" --diff "$OUT/bunny_diff.png" \
    | tee "$OUT/bunny_diff.txt"
  rel=$(awk '/^MSE/ {print $4}' "$OUT/bunny_diff.txt")
  absrel=$(awk '/^MSE/ {print $6}' "$OUT/bunny_diff.txt")
  white=$(sed -n 's/.*99th percentile (\([^)]*\)).*/\1/p' "$OUT/bunny_diff.txt" | head -n 1)
  "$PYTHON" bench/strip.py --title "Figure 2: decomposition at control 0 vs delta tracking" "$DOC/fig2_bunny.png" \
    "$OUT/bunny_control0.png:$(caption bunny_control0 'decomposition, control 0')" \
    "$OUT/bunny_delta.png:$(caption bunny_delta 'delta tracking')" \
    "$OUT/bunny_diff.png:|control 0 - delta|, relMSE $rel\\nwhite = $white (99th percentile)"
  printf 'The strip: %s, %s spp (control 0) and %s spp (delta); control 0 against delta: relMSE %s, mean abs\nrel %s, the white of the difference image (its 99th percentile of |control 0 − delta|) %s.\n' \
    "${RES}x$RES" "$(cut -d' ' -f1 "$OUT/bunny_control0.stats")" \
    "$(cut -d' ' -f1 "$OUT/bunny_delta.stats")" \
    "$(e2 "$rel")" "$(e2 "$absrel")" "$(e2 "$white")" | splice "fig2 numbers"
}

figure3() {
  S=scenes/cornell_smoke.yaml
  R="--set render.resolution=[$RES,$RES]"
  render smoke_reference $S --spp $REF_SPP $R --set media.smoke.type=delta --set render.seed=1
  D="--spp $(n 64) $R --set media.smoke.type=decomposition"
  render smoke_m1 $S $D
  for f in 1.01 1.1 2 4; do render "smoke_m$f" $S $D --set media.smoke.majorant_factor=$f; done
  for c in 0.5 0.1; do render "smoke_c$c" $S $D --set media.smoke.control=$c; done
  "$PYTHON" bench/strip.py --title "Figure 3: decomposition tracking, looser majorants and lower control ($(n 64) spp each)" \
    "$DOC/fig3_majorant_control.png" \
    "$OUT/smoke_m1.png:$(caption smoke_m1 'majorant x1, control 1' smoke_reference)" \
    "$OUT/smoke_m1.01.png:$(caption smoke_m1.01 'majorant x1.01' smoke_reference)" \
    "$OUT/smoke_m1.1.png:$(caption smoke_m1.1 'majorant x1.1' smoke_reference)" \
    "$OUT/smoke_m2.png:$(caption smoke_m2 'majorant x2' smoke_reference)" \
    "$OUT/smoke_m4.png:$(caption smoke_m4 'majorant x4' smoke_reference)" \
    "$OUT/smoke_c0.5.png:$(caption smoke_c0.5 'control 0.5' smoke_reference)" \
    "$OUT/smoke_c0.1.png:$(caption smoke_c0.1 'control 0.1' smoke_reference)"
  { echo "| variant | spp | time | relMSE |"; echo "|---|---|---|---|"
    for v in 'm1:majorant x1, control 1' 'm1.01:majorant x1.01 (report: null 1 %)' \
      'm1.1:majorant x1.1 (report: null 10 %)' 'm2:majorant x2' 'm4:majorant x4' 'c0.5:control 0.5' \
      'c0.1:control 0.1' 'reference:reference: delta, seed 1'; do
      name=smoke_${v%%:*}
      r=—; [ ! -f "$OUT/$name.relmse" ] || [ "$name" = smoke_reference ] || r=$(e2 "$(cat "$OUT/$name.relmse")")
      awk -v l="${v#*:}" -v r="$r" '{ printf "| %s | %s | %.1f s | %s |\n", l, $1, $2, r }' "$OUT/$name.stats"
    done
  } | splice "fig3 table"
}

figure4() {   # timed: not niced; the table is spliced into DOCS/gallery.md
  "$PYTHON" bench/figure4.py --scale "$SCALE" --rounds "${ROUNDS:-5}" --out "$OUT/fig4" --docs "$DOC" --md "$DOCS/gallery.md"
}

figure5() {
  render axe_room scenes/axe_room.yaml --spp "$(n 256)"
  cp "$OUT/axe_room.png" "$DOC/axe_room.png"
  renders_table axe_room | splice "fig5 render"
}

lights() {   # each at its own size, 64 spp at scale 1
  for s in envmap_spheres spot_fog cloud_sun; do
    render "$s" "scenes/$s.yaml" --spp "$(n 64)"
    cp "$OUT/$s.png" "$DOC/lights_$s.png"
  done
  renders_table envmap_spheres spot_fog cloud_sun | splice "lights renders"
}

media() {   # issue 27: 256x256
  render dense_cloud_sun scenes/dense_cloud_sun.yaml --spp "$(n 128)"
  render explosion scenes/explosion.yaml --spp "$(n 256)"
  for s in dense_cloud_sun explosion; do cp "$OUT/$s.png" "$DOC/$s.png"; done
  renders_table dense_cloud_sun explosion | splice "media renders"
}

for fig in ${*:-2 3 4 5}; do   # (not $f: the figure functions use f as their own loop variable)
  case $fig in
    1|2|3|4|5|lights|media)
      start=$(date +%s)
      case $fig in [1-5]) "figure$fig" ;; *) "$fig" ;; esac
      echo "figure $fig: $(( $(date +%s) - start )) s wall" | tee -a "$OUT/walltime.txt" ;;
    *) echo "usage: scenes/figures.sh [FIGURE ...]   (figures 1..5, lights, media)" >&2; exit 2 ;;
  esac
done
echo "results: $TABLE"
