#!/usr/bin/env bash
# Byte-identity check of two texsim builds: renders every built-in scene on each hardware
# configuration with both binaries (2 threads, reference and cycles on) and compares every
# PNG and summary.json (without its provenance: the command line and commit differ). A change
# that must not alter any output (a faster path, a refactor) passes with 0 differences.
# RENDER_ARGS adds arguments to every render (e.g. `--no-reference`: the hardware pass alone,
# which converts only the attributes of the triangles it shades).
# Usage: scripts/compare_renders.sh OLD_TEXSIM NEW_TEXSIM HW...
#   e.g. scripts/compare_renders.sh /tmp/texsim-main target/release/texsim \
#        texram16 d3d11 vulkan-min llvmpipe my_aniso.toml
# Prints a line per differing file and `renders=N fail=K`; exits 1 when any render differs or
# fails. Work files in ${COMPARE_DIR:-target/compare-renders}.
set -uo pipefail
[ $# -ge 3 ] || { sed -n 2,10p "$0"; exit 2; }
OLD=$1; NEW=$2; shift 2
W=${COMPARE_DIR:-target/compare-renders}
rm -rf "$W"; mkdir -p "$W"
summary() {
    [ -f "$1" ] || { echo "missing $1"; return; }
    python3 - "$1" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d.pop("provenance", None)
print(json.dumps(d, sort_keys=True))
PY
}
n=0; fail=0
for hw in "$@"; do
    for s in $("$NEW" scenes | awk 'NR > 1 {print $1}'); do
        n=$((n + 1)); tag=$(basename "$hw" .toml)-$s; ok=1
        for side in old new; do
            bin=$OLD; [ $side = new ] && bin=$NEW
            "$bin" --threads 2 render --scene "$s" --hw "$hw" ${RENDER_ARGS:-} --out "$W/$side-$tag" >/dev/null \
                2>"$W/$side-$tag.err" || { ok=0; echo "FAILED $side $tag (see $W/$side-$tag.err)"; }
        done
        for f in $(cd "$W/old-$tag" 2>/dev/null && ls -- *.png); do
            cmp -s "$W/old-$tag/$f" "$W/new-$tag/$f" || { ok=0; echo "DIFF $tag $f"; }
        done
        [ "$(summary "$W/old-$tag/summary.json")" = "$(summary "$W/new-$tag/summary.json")" ] ||
            { ok=0; echo "DIFF $tag summary.json"; }
        [ $ok = 1 ] || fail=$((fail + 1))
    done
done
echo "renders=$n fail=$fail"
[ $fail = 0 ]
