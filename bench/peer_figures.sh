#!/bin/sh
# peer_figures.sh — every figure of docs/results.md's "Side by side with Tungsten and pbrt-v4", in one run.
#
#   bench/peer_figures.sh OUTDIR TUNGSTEN PBRT SCENES_DIR [ROUNDS]
#
# TUNGSTEN and PBRT are the two renderers' binaries; SCENES_DIR holds the shared scenes as NAME.yaml,
# NAME/scene.json and NAME.pbrt (cbox_sphere and cbox_volume). Run from the source tree after
# ./tools/build.sh, on a quiet machine. Writes OUTDIR/{peers,cloud,layers,long_paths}.txt and prints them:
#   peers       murk, Tungsten and pbrt-v4 on SCENES_DIR's scenes: 256², 64 spp, 2 threads, a 1024-spp
#               Tungsten reference, ROUNDS (default 5) interleaved rounds (bench/side_by_side.py);
#   cloud       murk and pbrt-v4 on cornell_smoke's cloud (bench/pbrt_cloud.py): 256², 64 spp, a
#               1024-spp murk reference, ROUNDS rounds;
#   layers      murk / bare on the Cornell box (build/bench/embree_throughput, 1 s per side, 9 rounds);
#   long_paths  murk / bare lookups per CPU second and the time per scattering event in scenes/dense_cloud.yaml
#               (build/bench/long_paths, 1 s per side, 9 rounds).
# Each prints its check figure (image means, the sum of the densities read) beside murk's.
set -eu
[ $# -ge 4 ] || { sed -n '2,17p' "$0"; exit 2; }
out=$1; tungsten=$2; pbrt=$3; scenes=$4; rounds=${5:-5}
mkdir -p "$out"
py=/usr/bin/python3
$py bench/side_by_side.py "$out/peers" --murk build/core/murk --tungsten "$tungsten" --pbrt "$pbrt" \
    --scenes-dir "$scenes" --rounds "$rounds" --spp 64 --ref-spp 1024 | tee "$out/peers.txt"
$py bench/side_by_side.py "$out/cloud" --murk build/core/murk --pbrt "$pbrt" --cloud --res 256 \
    --rounds "$rounds" --spp 64 --ref-spp 1024 | tee "$out/cloud.txt"
build/bench/embree_throughput scenes/cornell.yaml 1 9 surfaces | tee "$out/layers.txt"
build/bench/long_paths scenes/dense_cloud.yaml 1 9 | tee "$out/long_paths.txt"
