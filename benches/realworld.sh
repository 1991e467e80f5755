#!/usr/bin/env bash
# Real programs at real size (issue 11): wall time and peak memory of a default `feedopt solve`
# on the programs of ../shared/realworld, one at a time, as a user runs them.
#
#   bash benches/realworld.sh            # all rows
#   bash benches/realworld.sh impeller   # rows whose name contains "impeller"
#
# Builds the release binary, then for each program prints: lines, stations, cycle time, the
# estimated relative error of the cycle time, whether the 1 ms re-simulation verified it, wall
# time, user CPU time (the steadier figure on a busy machine) and peak resident memory (GNU
# time -v). The impeller's body (program lines 7-4502) is
# repeated 8 and 32 times between its header and footer, in a temporary folder; the jerk-limited
# impeller uses its machine file with jerk = 10 x acceleration on every axis. Nothing from
# ../shared is written into the crate. Needs GNU time (/usr/bin/time) and python3 (reads --json).
set -euo pipefail
cd "$(dirname "$0")/.."
shared=../shared/realworld
[ -d "$shared" ] || { echo "needs $shared beside the crate" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "needs GNU time at /usr/bin/time (apt-get install time)" >&2; exit 2; }
cargo build --release --quiet
# Where cargo put it (CARGO_TARGET_DIR moves it out of target/).
bin=${CARGO_TARGET_DIR:-target}/release/feedopt
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

lnx=$shared/linuxcnc
cam=$shared/cam
imp=$lnx/impeller-7bl-xyzac.ngc
imp_m=$lnx/impeller-7bl-xyzac.machine.json
for k in 8 32; do
  { sed -n '1,6p' "$imp"; for _ in $(seq "$k"); do sed -n '7,4502p' "$imp"; done; sed -n '4503,$p' "$imp"; } \
    > "$tmp/impeller_x$k.ngc"
done
# jerk = 10 x acceleration: the machine file's "acceleration": a lines, each followed by a jerk.
sed -E 's/^( *)"acceleration": ([0-9.]+),/\1"acceleration": \2, "jerk": \2e1,/' "$imp_m" > "$tmp/impeller_jerk.json"

rows=(
  "impeller|$imp_m|$imp|"
  "impeller_x8|$imp_m|$tmp/impeller_x8.ngc|"
  "impeller_x32|$imp_m|$tmp/impeller_x32.ngc|"
  "impeller_jerk|$tmp/impeller_jerk.json|$imp|"
  "boat_xyzac|$lnx/boat-xyzac.machine.json|$lnx/boat-xyzac.ngc|"
  "boat_xyzbc|$lnx/boat-xyzbc.machine.json|$lnx/boat-xyzbc.ngc|"
  "camotics_bear|$cam/machines/xyz_mill.json|$cam/camotics_bear.nc|"
  "camotics_flower_mold|$cam/machines/xyz_mill.json|$cam/camotics_flower_mold.nc|"
  "nx_roeders_rfm600|$cam/machines/xyz_mill.json|$cam/nx_roeders_rfm600_finish.nc|"
  # boss's side operations tilt the tool to +X (CSYS, line 5551 on): a three-axis mill
  # refuses it (54c345c), the shared B/C trunnion takes it.
  "aamorim_boss|$cam/machines/trt_bc_spinner_u5.json|$cam/aamorim_boss.apt|"
  "aamorim_basemach|$cam/machines/xyz_mill.json|$cam/aamorim_basemach.apt|"
  "nx_mori_nmv5000|$cam/machines/trt_bc_mori_nmv5000.json|$cam/nx_mori_nmv5000_mm.nc|"
  "nx_dmu70evo_840d|$cam/machines/headtable_dmu70.json|$cam/nx_dmu70evo_840d.mpf|"
  "elmoe_keychain|$cam/machines/trt_bc_spinner_u5.json|$cam/elmoe_keychain.mpf|"
)

printf '%-22s %8s %9s %14s %9s %8s %8s %8s %8s\n' program lines stations cycle_time_s estimate verified wall_s user_s rss_MB
for row in "${rows[@]}"; do
  IFS='|' read -r name machine program extra <<< "$row"
  [[ -n "${1:-}" && "$name" != *"$1"* ]] && continue
  lines=$(wc -l < "$program")
  # shellcheck disable=SC2086
  if /usr/bin/time -v "$bin" solve --json $extra --machine "$machine" "$program" \
      > "$tmp/out.json" 2> "$tmp/time.txt"; then
    read -r stations cycle estimate verified < <(python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
e = s.get("error_estimate")
print(s["stations"], "%.4f" % s["cycle_time_s"], "-" if e is None else "%.1e" % e, s["verified"])
' "$tmp/out.json")
  else
    stations=- cycle=- estimate=- verified="error: $(grep -v '^\s' "$tmp/time.txt" | head -1 | cut -c1-60)"
  fi
  wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {n = split($2, p, ":"); s = 0; for (i = 1; i <= n; i++) s = s * 60 + p[i]; print s}' "$tmp/time.txt")
  user=$(awk -F': ' '/User time \(seconds\)/ {print $2}' "$tmp/time.txt")
  rss=$(awk -F': ' '/Maximum resident set size/ {printf "%.0f", $2 / 1024}' "$tmp/time.txt")
  printf '%-22s %8s %9s %14s %9s %8s %8s %8s %8s\n' "$name" "$lines" "$stations" "$cycle" "$estimate" "$verified" "$wall" "$user" "$rss"
done
