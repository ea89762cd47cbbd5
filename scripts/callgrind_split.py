#!/usr/bin/env python3
"""Splits each function's instructions by how often they ran: per fragment, per span, ...

Callgrind with `--dump-instr=yes` records every instruction's execution count. An instruction
that ran about as many times as the frame has fragments is work per fragment; one that ran
about as many times as it has spans is work per span. This sums each function's own
instructions (inlined code included, callees not) into those classes and prints, per class,
the instructions per event:

    cargo build --profile profiling
    valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file=cg.out \\
        target/profiling/texsim --threads 1 render --scene w2-mesh --no-reference \\
        --no-cycles --warmup 0 --frames 1
    python3 scripts/callgrind_split.py cg.out fragment=685714 span=165055

The counts are the frame's shaded fragments (`visible` in summary.json) and its shading spans
(e.g. callgrind's call count of `bary::fixed_span`). An instruction goes to the class whose
count is nearest to its own on a log scale, if within a factor of four of it (a fragment's
three samples count as per fragment, three times; a second texture level run by half the
fragments, at half weight); the rest is "other". The profiling build keeps the function names
that inlining would otherwise merge.
"""
import argparse
import collections
import math
import re
import sys


def parse_counts(path):
    """{function name: {instruction address: execution count}} of the functions' own costs
    (the `Ir` event at each instruction address)."""
    names = {}
    ir = None
    own = collections.defaultdict(lambda: collections.defaultdict(int))
    fn = None
    addr = 0
    after_calls = False
    name_line = re.compile(r"(c?fn)=\((\d+)\)(?: (.*))?$")
    positions = ["line"]

    def position(tok, prev):
        if tok == "*":
            return prev
        if tok[0] in "+-":
            step = int(tok[1:], 0)
            return prev + step if tok[0] == "+" else prev - step
        return int(tok, 0)

    with open(path) as f:
        for line in f:
            line = line.rstrip("\n")
            if line.startswith("positions:"):
                positions = line.split()[1:]
                continue
            if line.startswith("events:"):
                if positions[:1] != ["instr"]:
                    sys.exit(f"callgrind_split: '{path}' has no instruction addresses "
                             "(record with --dump-instr=yes)")
                events = line.split()[1:]
                if "Ir" not in events:
                    sys.exit(f"callgrind_split: '{path}' has no Ir event")
                # A cost line is the positions, then the events in this order.
                ir = len(positions) + events.index("Ir")
                continue
            m = name_line.match(line)
            if m:
                kind, ident, name = m.groups()
                if name:
                    names[ident] = name
                if kind == "fn":
                    fn = names.get(ident, ident)
                continue
            if line.startswith("calls="):
                after_calls = True
                continue
            if not line or line[0] not in "+-*0123456789":
                continue
            fields = line.split()
            addr = position(fields[0], addr)
            if after_calls:
                # The cost line of a call: the callee's inclusive cost, not this function's.
                after_calls = False
                continue
            # Trailing zero costs may be left out of a line.
            if fn is not None and ir is not None and len(fields) > ir:
                own[fn][addr] += int(fields[ir])
    return own


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("callgrind_out", help="a callgrind.out file written with --dump-instr=yes")
    ap.add_argument("events", nargs="+", help="NAME=COUNT, e.g. fragment=685714 span=165055")
    ap.add_argument("--top", type=int, default=25, help="functions to print (default 25)")
    args = ap.parse_args()
    classes = []
    for ev in args.events:
        name, _, count = ev.partition("=")
        if not count.isdigit() or int(count) == 0:
            sys.exit(f"callgrind_split: '{ev}' is not NAME=COUNT with a positive COUNT")
        classes.append((name, int(count)))
    own = parse_counts(args.callgrind_out)
    if not own:
        sys.exit(f"callgrind_split: no instruction costs in '{args.callgrind_out}' "
                 "(record with --dump-instr=yes)")

    def class_of(count):
        best = min(classes, key=lambda c: abs(math.log(count / c[1])))
        return best[0] if abs(math.log(count / best[1])) < math.log(4) else None

    rows = []
    for fn, by_addr in own.items():
        sums = collections.defaultdict(int)
        for count in by_addr.values():
            if count:
                sums[class_of(count)] += count
        rows.append((sum(sums.values()), fn, sums))
    rows.sort(reverse=True, key=lambda r: r[0])
    head = "".join(f" {'per ' + n:>13}" for n, _ in classes)
    print(f"{'instructions':>14}{head} {'other':>9}  function")
    for total, fn, sums in rows[: args.top]:
        per = "".join(f" {sums[n] / c:13.1f}" for n, c in classes)
        print(f"{total:14,d}{per} {sums[None]:9,d}  {fn}")


if __name__ == "__main__":
    main()
