#!/usr/bin/env bash
# Image comparison of texsim and Mesa (softpipe, llvmpipe) on the two anchor workloads
# (shared/anchors/mesa: W1 plane, W2 mesh, 1024x1024): the anchor writes each driver's frame
# (--png), texsim renders the same scene, `texsim compare` reports the covered pixels
# (those that differ from the clear colour 0,0,0,0 in the Mesa image).
# Needs the anchor built once (see scripts/compare_mesa.sh).
# Usage: scripts/compare_mesa_images.sh [HW]    (HW: a preset or hw file, default texram16)
# Writes target/mesa-images/{plane,mesh}_{softpipe,llvmpipe}.png, the renders and the reports.
set -euo pipefail
cd "$(dirname "$0")/.."
HW=${1:-texram16}
ANCHOR=${MESA_ANCHOR:-../shared/anchors/mesa/build/mesa_anchor}
[ -x "$ANCHOR" ] || { echo "build the Mesa anchor first (see scripts/compare_mesa.sh)"; exit 1; }
cargo build --release -q
OUT=target/mesa-images
mkdir -p "$OUT"
for w in plane:w1-plane mesh:w2-mesh; do
    mesa=${w%%:*}; scene=${w##*:}
    ./target/release/texsim render --scene "$scene" --hw "$HW" --no-reference --out "$OUT/$scene" >/dev/null 2>&1
    for drv in softpipe llvmpipe; do
        GALLIUM_DRIVER=$drv "$ANCHOR" --workload "$mesa" --frames 1 --warmup 0 --png "$OUT/${mesa}_$drv.png" >/dev/null
        echo "== $scene ($HW) vs $drv"
        ./target/release/texsim compare "$OUT/$scene/hw.png" "$OUT/${mesa}_$drv.png" \
            --coverage-from b --top 5 --out "$OUT/compare-$scene-$drv"
    done
done
