#!/bin/sh
# Renders the media figures of the reference report into out/figures/: the medium scenes with each
# tracker, and the control-ratio and majorant variants of cornell_smoke — which in murk must look the
# same (only noise and time change). Usage: scenes/figures.sh [SPP]   (default 256)
set -eu
cd "$(dirname "$0")/.."
SPP=${1:-256}
MURK=./build/core/murk
OUT=out/figures
mkdir -p "$OUT"
for s in cornell_smoke cornell_bunny spectral_absorption spectral_scattering spectral_extinction; do
  $MURK render scenes/$s.yaml -o "$OUT/$s.exr" --spp "$SPP"
done
for c in 0 0.1 0.5 1; do   # decomposition control ratio
  $MURK render scenes/cornell_smoke.yaml -o "$OUT/cornell_smoke_control_$c.exr" --spp "$SPP" \
    --set media.smoke.type=decomposition --set media.smoke.control=$c
done
for f in 1 2 4; do         # looser majorants
  $MURK render scenes/cornell_smoke.yaml -o "$OUT/cornell_smoke_majorant_$f.exr" --spp "$SPP" \
    --set media.smoke.majorant_factor=$f
done
for t in naive_spectral spectral spectral_mis; do
  $MURK render scenes/spectral_extinction.yaml -o "$OUT/spectral_extinction_$t.exr" --spp "$SPP" \
    --set media.medium.type=$t
done
