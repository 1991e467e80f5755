#!/usr/bin/env bash
# The material stage's cost against the solve's (issue 13): wall time and peak memory of the
# dexel pass (`feedopt check`: read the program, cut the stock, the overload check) and of a
# default `feedopt solve` without the material stage, on the same program, at 0.1 mm dexels.
#
#   bash benches/material.sh            # all rows
#   bash benches/material.sh linuxcnc   # rows whose name contains "linuxcnc"
#   CELL=0.05 bash benches/material.sh  # another cell size, mm (default 0.1)
#   FEEDOPT=/tmp/old/feedopt bash benches/material.sh  # another build (no cargo build), for a
#                                                      # before/after pair in the same hour
#   COMPARE=/tmp/old/feedopt bash benches/material.sh  # also: does this build cut as that one?
#
# Rows (the machine files get a `stock` in a temporary folder; nothing is written into the crate):
# - seed_blade: problems/seed_head_head (the bundled 5-axis problem, a flank pass along one
#   blade of a centrifugal impeller). Its program's TLDATA/MILL,6,3,50 is a 6 mm ball-nose end
#   mill with 50 mm of flutes (feedopt reads CUTTER/, not TLDATA/, so the options give it). Its
#   blank: a cylinder about the impeller axis (x = y = 0), R 100 mm (the blade's outer end),
#   z 0…60 mm (the hub is at z 8…50; the lead-in starts at z 56).
# - linuxcnc_impeller: ../shared/realworld/linuxcnc/impeller-7bl-xyzac.ngc with the cylinder
#   blank its closing comment gives (R 45.44 mm, Z −2.65…39.77, about the C axis at x = y = 0).
#   The program names no tool (no T word, no tool comment; "roughing out in soft non-metal
#   material"), so this assumes a 6 mm ball-nose end mill, flutes 2 D = 12 mm (the default);
#   TOOL="--tool-diameter 8 --tool-corner-radius 0" bash benches/material.sh runs the
#   configuration's tool-table T2 (D 8 "end mill") instead.
# - camotics_bear, nx_roeders (3-axis: a vertical tool, whose cut is exact per dexel):
#   ../shared/realworld/cam's CAMotics bear (15,163 lines, moves that ramp) with a 3.175 mm ball
#   and 25 mm flutes (2 D would leave the shank in the relief), and NX's Röders finish (36,746
#   lines, mostly level moves) with a 6 mm ball assumed (the program names no tool), each on
#   xyz_mill.json with a box blank around its moves (bear X, Y 0…80, Z down to −17.368; Röders
#   X −13.2…12.5, Y ±73.3, Z down to −6), 2 mm (bear) and 5 mm (Röders) wider, 1 mm deeper.
#
# Prints per row and run: samples, dexels, removed volume (check) or stations and cycle time
# (solve), wall time and CPU time (user + system, s) and peak resident memory (MB, GNU time's
# -v). The machine is assumed
# shared: compare the two runs of a row, measured minutes apart, not rows of other days.
# Needs GNU time (/usr/bin/time) and python3; skips a row whose inputs in ../shared are absent.
#
# COMPARE=path: per row, both builds check the program once more with an MRR cap of 1e-9 mm³/s,
# so that every move that cuts is a finding carrying the move's removed volume and its worst
# sample's A; prints the largest differences of those per move, of the totals and of the peaks
# (`check --json` reports no single samples). Untimed.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x /usr/bin/time ] || { echo "needs GNU time at /usr/bin/time (apt-get install time)" >&2; exit 2; }
cell=${CELL:-0.1}
if [ -n "${FEEDOPT:-}" ]; then
  bin=$FEEDOPT
else
  cargo build --release --quiet
  # Where cargo put it (CARGO_TARGET_DIR moves it out of target/).
  bin=${CARGO_TARGET_DIR:-target}/release/feedopt
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# with_stock MACHINE OUT STOCK_JSON: MACHINE plus a `stock` section.
with_stock() {
  python3 -c '
import json, sys
m = json.load(open(sys.argv[1]))
m["stock"] = json.loads(sys.argv[3])
json.dump(m, open(sys.argv[2], "w"), indent=1)
' "$1" "$2" "$3"
}

seed=problems/seed_head_head
with_stock $seed/machine.json "$tmp/seed.json" \
  '{"cylinder": {"center": [0, 0], "radius": 100, "z": [0, 60]}}'
lnx=../shared/realworld/linuxcnc
if [ -d "$lnx" ]; then
  with_stock $lnx/impeller-7bl-xyzac.machine.json "$tmp/impeller.json" \
    '{"cylinder": {"center": [0, 0], "radius": 45.44, "z": [-2.65, 39.77]}}'
fi

cam=../shared/realworld/cam
if [ -d "$cam" ]; then
  with_stock $cam/machines/xyz_mill.json "$tmp/bear.json" \
    '{"box": {"min": [-2, -2, -18.368], "max": [82, 82, 0]}}'
  with_stock $cam/machines/xyz_mill.json "$tmp/roeders.json" \
    '{"box": {"min": [-18.243, -78.312, -7], "max": [17.506, 78.312, 0]}}'
fi

rows=(
  "seed_blade|$seed/machine.json|$tmp/seed.json|$seed/impeller_blade.cls|--tool-diameter 6 --tool-corner-radius 3 --tool-flute-length 50"
  "linuxcnc_impeller|$lnx/impeller-7bl-xyzac.machine.json|$tmp/impeller.json|$lnx/impeller-7bl-xyzac.ngc|${TOOL:---tool-diameter 6 --tool-corner-radius 3}"
  "camotics_bear|$cam/machines/xyz_mill.json|$tmp/bear.json|$cam/camotics_bear.nc|--tool-diameter 3.175 --tool-corner-radius 1.5875 --tool-flute-length 25"
  "nx_roeders|$cam/machines/xyz_mill.json|$tmp/roeders.json|$cam/nx_roeders_rfm600_finish.nc|--tool-diameter 6 --tool-corner-radius 3"
)

# run NAME ARGS…: runs feedopt under GNU time, prints wall s and peak RSS MB into $wall $rss.
run() {
  if /usr/bin/time -v "$bin" "$@" > "$tmp/out.json" 2> "$tmp/time.txt"; then
    ok=1
  else
    ok=0
  fi
  wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {n = split($2, p, ":"); s = 0; for (i = 1; i <= n; i++) s = s * 60 + p[i]; print s}' "$tmp/time.txt")
  rss=$(awk -F': ' '/Maximum resident set size/ {printf "%.0f", $2 / 1024}' "$tmp/time.txt")
  cpu=$(awk -F': ' '/(User|System) time \(seconds\)/ {s += $2} END {printf "%.2f", s}' "$tmp/time.txt")
}

printf '%-18s %-6s %-50s %8s %8s %8s\n' program run result wall_s cpu_s rss_MB
for row in "${rows[@]}"; do
  IFS='|' read -r name machine stocked program tool <<< "$row"
  [[ -n "${1:-}" && "$name" != *"$1"* ]] && continue
  if [ ! -f "$program" ] || [ ! -f "$stocked" ]; then
    echo "$name: skipped, needs $program (../shared beside the crate)"
    continue
  fi
  # shellcheck disable=SC2086
  run check --json --cell "$cell" $tool --machine "$stocked" "$program"
  if [ "$ok" = 1 ]; then
    result=$(python3 -c '
import json, sys
r = json.load(open(sys.argv[1]))
print("%d samples, %dx%d dexels, removed %.0f mm3" % (r["samples"], r["dexels"][0], r["dexels"][1], r["removed_volume_mm3"]))
' "$tmp/out.json")
  else
    result="error: $(grep -v '^\s' "$tmp/time.txt" | head -1 | cut -c1-60)"
  fi
  printf '%-18s %-6s %-50s %8s %8s %8s\n' "$name" check "$result" "$wall" "$cpu" "$rss"
  if [ -n "${COMPARE:-}" ]; then
    python3 -c '
import json, sys
m = json.load(open(sys.argv[1]))
m["process"] = {"mrr_max": 1e-9}
json.dump(m, open(sys.argv[2], "w"), indent=1)
' "$stocked" "$tmp/capped.json"
    # shellcheck disable=SC2086
    "$bin" check --json --cell "$cell" $tool --machine "$tmp/capped.json" "$program" > "$tmp/new.json"
    # shellcheck disable=SC2086
    "$COMPARE" check --json --cell "$cell" $tool --machine "$tmp/capped.json" "$program" > "$tmp/old.json"
    python3 -c '
import json, sys
new = json.load(open(sys.argv[1] + "/new.json"))
old = json.load(open(sys.argv[1] + "/old.json"))
keys = ["removed_volume_mm3", "peak_area_mm2", "peak_axial_depth_mm", "peak_radial_engagement_mm", "air_share"]
print("  vs COMPARE: " + ", ".join("%s %.2e" % (k, abs(new[k] - old[k])) for k in keys))
f = lambda r: {(x["point"], x["severity"], str(x["limit"])): x for x in r["findings"]}
a, b = f(old), f(new)
both = set(a) & set(b)
dv = max((abs(a[k]["removed"] - b[k]["removed"]) for k in both), default=0.0)
da = max((abs(a[k]["area"] - b[k]["area"]) for k in both), default=0.0)
print("  vs COMPARE: %d moves cut (%d in one build only); largest per-move diff: removed %.2e mm3, A %.2e mm2" % (len(both), len(set(a) ^ set(b)), dv, da))
' "$tmp"
  fi
  run solve --json --machine "$machine" "$program"
  if [ "$ok" = 1 ]; then
    result=$(python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
print("%d stations, cycle %.4f s, verified %s" % (s["stations"], s["cycle_time_s"], s["verified"]))
' "$tmp/out.json")
  else
    result="error: $(grep -v '^\s' "$tmp/time.txt" | head -1 | cut -c1-60)"
  fi
  printf '%-18s %-6s %-50s %8s %8s %8s\n' "$name" solve "$result" "$wall" "$cpu" "$rss"
done
