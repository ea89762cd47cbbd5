#!/usr/bin/env bash
# Side-by-side timing of texsim and Mesa (softpipe, llvmpipe) on the two anchor workloads
# (shared/anchors/mesa: W1 plane, W2 mesh, 1024x1024, same texture and geometry).
# Needs the anchor built once: (cd ../shared/anchors/mesa && ./build.sh), which needs
#   apt-get install -y gcc pkg-config libosmesa6-dev libpng-dev
# Usage: scripts/compare_mesa.sh [REPEATS]    (prints one line per run and the medians)
set -euo pipefail
cd "$(dirname "$0")/.."
REPEATS=${1:-5}
ANCHOR=${MESA_ANCHOR:-../shared/anchors/mesa/build/mesa_anchor}
[ -x "$ANCHOR" ] || { echo "build the Mesa anchor first (see the header of this script)"; exit 1; }
cargo build --release -q
median() { sort -n | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
for w in plane:w1-plane mesh:w2-mesh; do
    mesa=${w%%:*}; scene=${w##*:}
    for drv in softpipe llvmpipe; do
        for _ in $(seq "$REPEATS"); do
            GALLIUM_DRIVER=$drv "$ANCHOR" --workload "$mesa" --frames 5 --warmup 1 | grep -o 'median_ms=[0-9.]*' | cut -d= -f2
        done | median | xargs printf "%-9s %-9s %8.1f ms\n" "$scene" "$drv"
    done
    for threads in 1 2; do
        for path in hw ref; do
            for _ in $(seq "$REPEATS"); do
                if [ $path = hw ]; then extra=(--no-reference --no-cycles); else extra=(--float bary,texcoord,lod,trilinear,color,modulate --no-reference --no-cycles); fi
                ./target/release/texsim --threads $threads render --scene "$scene" "${extra[@]}" --out target/compare-out 2>/dev/null \
                    | grep -o 'hardware path [0-9.]*' | awk '{print $3}'
            done | median | xargs printf "%-9s %-9s %8.1f ms\n" "$scene" "texsim-$path-t$threads"
        done
    done
done
