#!/usr/bin/env bash
# Side-by-side timing of texsim and Mesa (softpipe, llvmpipe) on the two anchor workloads
# (shared/anchors/mesa: W1 plane, W2 mesh, 1024x1024, same texture and geometry).
# Needs the anchor built once: (cd ../shared/anchors/mesa && ./build.sh), which needs
#   apt-get install -y gcc pkg-config libosmesa6-dev libpng-dev
# Usage: scripts/compare_mesa.sh [REPEATS]    (prints one line per configuration: the median
# of REPEATS runs, then the issue-12 ratios at equal thread counts: the ratio of the medians and
# the range of the ratios within each repeat, whose runs ran side by side)
# Frames: the Mesa anchor times 5 frames after 1 warm-up frame in one process and takes their
# median; texsim-hw and texsim-ref do the same (`texsim render --warmup 1 --frames 5`), and
# texsim-cold is the bit-accurate path's first frame in a fresh process (`--frames 1`), which also
# faults in the memory of every buffer.
# Thread counts: llvmpipe-t1 rasterises in the calling thread (LP_NUM_THREADS=0), llvmpipe-t2
# on two rasteriser threads (LP_NUM_THREADS=2); texsim-*-tT is `texsim --threads T`. Within a
# repeat the configurations alternate, so a slow spell of a shared machine falls on all of them.
set -euo pipefail
cd "$(dirname "$0")/.."
REPEATS=${1:-5}
ANCHOR=${MESA_ANCHOR:-../shared/anchors/mesa/build/mesa_anchor}
[ -x "$ANCHOR" ] || { echo "build the Mesa anchor first (see the header of this script)"; exit 1; }
cargo build --release -q
median() { sort -n | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
raw=$(mktemp)
trap 'rm -f "$raw"' EXIT
mesa() { # $1 workload, $2 driver, $3 LP_NUM_THREADS (empty: unset)
    if [ -n "$3" ]; then export LP_NUM_THREADS=$3; else unset LP_NUM_THREADS; fi
    GALLIUM_DRIVER=$2 "$ANCHOR" --workload "$1" --frames 5 --warmup 1 | grep -o 'median_ms=[0-9.]*' | cut -d= -f2
    unset LP_NUM_THREADS
}
texsim() { # $1 scene, $2 threads, $3 path (hw: bit-accurate, ref: the float stages, cold: hw's first frame)
    local extra=(--no-reference --no-cycles --warmup 1 --frames 5)
    [ "$3" = ref ] && extra+=(--float bary,texcoord,lod,trilinear,color,modulate)
    [ "$3" = cold ] && extra=(--no-reference --no-cycles)
    ./target/release/texsim --threads "$2" render --scene "$1" "${extra[@]}" --out target/compare-out 2>/dev/null |
        grep -o 'wall time: hardware path [0-9.]*' | awk '{print $5}'
}
for r in $(seq "$REPEATS"); do
    for w in plane:w1-plane mesh:w2-mesh; do
        m=${w%%:*}; s=${w##*:}
        echo "$r $s softpipe $(mesa "$m" softpipe '')" >>"$raw"
        echo "$r $s llvmpipe-t1 $(mesa "$m" llvmpipe 0)" >>"$raw"
        echo "$r $s llvmpipe-t2 $(mesa "$m" llvmpipe 2)" >>"$raw"
        for t in 1 2; do
            for p in hw ref cold; do
                echo "$r $s texsim-$p-t$t $(texsim "$s" "$t" "$p")" >>"$raw"
            done
        done
    done
done
declare -A med
for s in w1-plane w2-mesh; do
    for c in softpipe llvmpipe-t1 llvmpipe-t2 texsim-hw-t1 texsim-ref-t1 texsim-cold-t1 texsim-hw-t2 \
        texsim-ref-t2 texsim-cold-t2; do
        med[$s/$c]=$(awk -v s="$s" -v c="$c" '$2 == s && $3 == c {print $4}' "$raw" | median)
        printf "%-9s %-14s %8.1f ms\n" "$s" "$c" "${med[$s/$c]}"
    done
done
echo "ratios (issue 12 asks bit-accurate <= 3x llvmpipe on W1, <= 1.5x on W2, and <= the float path;"
echo "        in brackets the lowest and highest ratio within one repeat):"
# The lowest and highest ratio `num / den` of configurations `num` and `den` of scene `s` within
# one repeat.
spread() {
    awk -v s="$1" -v num="$2" -v den="$3" '$2 == s && $3 == num {n[$1] = $4} $2 == s && $3 == den {d[$1] = $4}
        END {for (r in n) if ((r in d) && d[r] > 0) {q = n[r] / d[r]; lo = (lo == "" || q < lo) ? q : lo; hi = (q > hi) ? q : hi}
             printf "%.2fx-%.2fx", lo, hi}' "$raw"
}
for s in w1-plane w2-mesh; do
    for t in 1 2; do
        awk -v s="$s" -v t="$t" -v hw="${med[$s/texsim-hw-t$t]}" -v lp="${med[$s/llvmpipe-t$t]}" \
            -v ref="${med[$s/texsim-ref-t$t]}" -v cold="${med[$s/texsim-cold-t$t]}" \
            -v lps="$(spread "$s" "texsim-hw-t$t" "llvmpipe-t$t")" -v refs="$(spread "$s" "texsim-hw-t$t" "texsim-ref-t$t")" \
            'BEGIN {printf "%-9s %d thread(s): bit-accurate / llvmpipe %5.2fx [%s], bit-accurate / float path %5.2fx [%s], first frame / llvmpipe %5.2fx\n", s, t, hw / lp, lps, hw / ref, refs, cold / lp}'
    done
done
