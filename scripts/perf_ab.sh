#!/usr/bin/env bash
# Where two texsim builds spend a frame, by perf samples: renders SCENE with OLD and NEW in
# alternation (PAIRS pairs, old then new) under `perf record`, and prints for each run the
# samples of every symbol matching each of SYMS, and all samples, in units of the samples of
# UNIT (a symbol both builds share unchanged), beside the run's median and fastest frame. On a
# shared, noisy machine these ratios hold where wall times do not (docs/PERFORMANCE_LOG.md,
# stops 49 to 55), but a change that slows other symbols as much as UNIT leaves them
# unchanged: check the fastest frames too, in more than one hour (stop 57's LOD batch: `lod`
# -20% in UNIT's samples; fastest W1 frame +8% in one hour, -2% forty minutes later).
# Usage: scripts/perf_ab.sh OLD_TEXSIM NEW_TEXSIM SCENE [PAIRS] [THREADS]
#   e.g. scripts/perf_ab.sh /tmp/texsim-main target/release/texsim w2-mesh 3 1
# Environment: UNIT (regex, default 'texcoord::fixed_span'); SYMS (space-separated regexes,
# default 'trilinear lod::fixed_span interpolator Group::shade|run_spans'); RENDER_ARGS
# (default '--no-reference --no-cycles'); FRAMES (timed frames, default 21, after 2 warm-up);
# PERF_DIR (work files, default target/perf-ab). Needs `perf` (Debian: linux-perf).
set -uo pipefail
[ $# -ge 3 ] || { sed -n 2,13p "$0"; exit 2; }
OLD=$1; NEW=$2; SCENE=$3; PAIRS=${4:-3}; THREADS=${5:-1}
UNIT=${UNIT:-texcoord::fixed_span}
SYMS=${SYMS:-trilinear lod::fixed_span interpolator Group::shade|run_spans}
W=${PERF_DIR:-target/perf-ab}
command -v perf >/dev/null || { echo "perf_ab: perf not found (apt-get install linux-perf)"; exit 2; }
mkdir -p "$W"
# One run's line: median and fastest frames, all samples and each of SYMS over UNIT's.
shares() {
    local frames
    frames=$(grep -o 'median [0-9.]* ms (min [0-9.]*' "$1.log" | head -1 |
        sed 's/ ms (min \(.*\)/ ms, min \1 ms/')
    perf report -i "$1.data" --no-children --sort symbol -F sample,symbol 2>/dev/null |
        grep -v '^#' |
        awk -v unit="$UNIT" -v syms="$SYMS" -v frames="${frames:-median ? ms, min ? ms}" '
        BEGIN { n = split(syms, re, " ") }
        NF > 1 {
            s = $1; $1 = ""; total += s
            if ($0 ~ unit) u += s
            for (i = 1; i <= n; i++) if ($0 ~ re[i]) got[i] += s
        }
        END {
            if (u == 0) { print "no samples of " unit; exit 1 }
            line = sprintf("%s  all %.2f", frames, total / u)
            for (i = 1; i <= n; i++) line = line sprintf("  %s %.2f", re[i], got[i] / u)
            print line
        }'
}
status=0
for i in $(seq 1 "$PAIRS"); do
    for side in old new; do
        bin=$OLD; [ $side = new ] && bin=$NEW
        run="$W/$side.$SCENE.$i"
        perf record -q -F 4000 -o "$run.data" "$bin" --threads "$THREADS" render --scene "$SCENE" \
            ${RENDER_ARGS:---no-reference --no-cycles} --warmup 2 --frames "${FRAMES:-21}" \
            --out "$W/out" >"$run.log" 2>&1 || { echo "FAILED $side run $i (see $run.log)"; status=1; continue; }
        line=$(shares "$run") || status=1
        echo "$side $i: $line"
    done
done
echo "units: samples over those of '$UNIT'"
exit $status
