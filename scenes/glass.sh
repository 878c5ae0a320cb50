#!/bin/sh
# glass.sh — regenerates docs/glass.md's strips (docs/glass/*.png): glass_juice and glass_cloud with the
# medium's tracker swapped (delta, spectral, spectral_mis) AT EQUAL TIME, relMSE against a longer
# reference of another seed. EXRs, logs and the table of spp, time and relMSE go to out/glass/; the table
# is also spliced into DOCS/glass.md between its markers (tools/mdsplice.py).
#
#   scenes/glass.sh            # about 4 minutes on 2 busy cores
#
# Environment: MURK (default ./build/core/murk), DOCS (the docs folder, default docs; strips to DOCS/glass), OUT
# (renders, default out/glass), T (seconds per variant, default 15), REF_T (seconds of
# each reference, default 60; seed 1), REUSE=1 (keep finished renders), PYTHON (default /usr/bin/python3,
# with python3-matplotlib for bench/strip.py). Every render runs under `nice -n 10`, 256x256.
set -euf   # -f: no globbing, the [W,H] in --set values stay literal
cd "$(dirname "$0")/.."
MURK=${MURK:-./build/core/murk}
PYTHON=${PYTHON:-/usr/bin/python3}
T=${T:-15}
REF_T=${REF_T:-60}
OUT=${OUT:-out/glass}
DOC=${DOCS:-docs}/glass
mkdir -p "$OUT" "$DOC"
TABLE=$OUT/results.txt
printf 'image\tspp\tseconds\trelMSE\n' > "$TABLE"

render() {   # render NAME SCENE ARGS... -> $OUT/NAME.exr, "SPP SECONDS" in $OUT/NAME.stats
  name=$1; file=$2; shift 2
  if [ "${REUSE:-0}" = 1 ] && [ -s "$OUT/$name.stats" ] && [ -f "$OUT/$name.exr" ]; then
    echo "== $name: reused"; return 0
  fi
  echo "== $name: murk render $file $*"
  nice -n 10 "$MURK" render "$file" -o "$OUT/$name.exr" --set render.resolution=[256,256] "$@" \
    > "$OUT/$name.log" 2>&1 || { cat "$OUT/$name.log"; exit 1; }
  sed -n 's/.*: [0-9]*x[0-9]*, \([0-9]*\) spp, \([0-9.]*\) s,.*/\1 \2/p' "$OUT/$name.log" | tail -n 1 \
    > "$OUT/$name.stats"
  cat "$OUT/$name.stats"
}

NL='
'
for scene in juice cloud; do
  medium=$scene
  render "${scene}_ref" "scenes/glass_$scene.yaml" --time "$REF_T" --spp 100000 --set render.seed=1 \
    --set "media.$medium.type=spectral_mis"
  list=$OUT/${scene}_strip.txt   # one bench/strip.py argument per line
  : > "$list"
  for tr in delta spectral spectral_mis; do
    render "${scene}_$tr" "scenes/glass_$scene.yaml" --time "$T" --spp 100000 --set "media.$medium.type=$tr"
    r=$("$MURK" compare "$OUT/${scene}_$tr.exr" "$OUT/${scene}_ref.exr" | awk '/^MSE/ {print $4}')
    set -- $(cat "$OUT/${scene}_$tr.stats")
    printf '%s\t%s\t%s\t%s\n' "${scene}_$tr" "$1" "$2" "$r" >> "$TABLE"
    printf '%s\n' "$OUT/${scene}_$tr.png:$tr\\n$1 spp, $2 s\\nrelMSE $r" >> "$list"
  done
  set -- $(cat "$OUT/${scene}_ref.stats")
  printf '%s\t%s\t%s\t-\n' "${scene}_ref" "$1" "$2" >> "$TABLE"
  printf '%s\n' "$OUT/${scene}_ref.png:reference (spectral_mis, seed 1)\\n$1 spp, $2 s" >> "$list"
  title="glass_$scene: the medium's tracker at equal time ($T s each), 256x256"
  IFS=$NL
  set -- $(cat "$list")
  unset IFS
  "$PYTHON" bench/strip.py --title "$title" "$DOC/$scene.png" "$@"
done
cat "$TABLE"
# glass.md's table: "juice_spectral_mis" is scene glass_juice, tracker spectral_mis
awk -F '\t' 'NR == 1 { print "| scene | tracker | spp | seconds | relMSE |"; print "|---|---|---|---|---|"; next }
  { i = index($1, "_"); t = substr($1, i + 1); if (t == "ref") t = "reference (spectral_mis, seed 1)"
    printf "| glass_%s | %s | %s | %s | %s |\n", substr($1, 1, i - 1), t, $2, $3, ($4 == "-" ? "—" : sprintf("%.3g", $4)) }' \
  "$TABLE" | "$PYTHON" tools/mdsplice.py "${DOCS:-docs}/glass.md" "glass table" scenes/glass.sh
