#!/usr/bin/env bash
# The long fuzzing campaign (issue 14): every reader target, and the CLI, for N CPU minutes
# each, one after another, as the issue's acceptance asks ("one hour of fuzzing per reader
# target: 0 panics, 0 aborts, 0 runs past the time bound").
#
#   bash benches/fuzz_long.sh                        # every target, 60 CPU minutes each
#   bash benches/fuzz_long.sh 1                      # every target, 1 CPU minute each
#   bash benches/fuzz_long.sh 60 apt gcode-fanuc     # these targets only
#
# Targets (tests/fuzz_cli.rs): apt, gcode-<dialect> (one per dialect the reader knows),
# machine, joint_csv, solve. Builds the release test binary once (`cargo test --release
# --no-run`), then runs `fuzz_long` once per target, each in its own process (an abort ends
# that target only), under `nice -n 19` and a virtual-memory limit (FUZZ_MEM_GB, default 4: a
# runaway allocation aborts the target instead of the shared machine). The budget is CPU time
# of the process (utime + stime from /proc/self/stat; for `solve`, plus its waited-for feedopt
# children's), so a busy machine stretches the wall time, not the work done. The time bound of
# one case is CPU time too (of the thread that reads it, or of the feedopt child of a solve: 5 s
# a read, FUZZ_BOUND_S a solve), with a wall-clock backstop of 60 times that: under nice 19 a
# case may wait for a core much longer than it runs, and waiting is no hang.
#
# Writes <out>/<target>/ (out: FUZZ_OUT, default target/fuzz-long): figures.txt (cases, clean
# errors, failures, kinds of error, seeds read cleanly, mean ms, slowest CPU ms, CPU and wall
# seconds), log.txt, failures/case-<n>/ (each failing input with WHAT.txt) and work/ (the last
# case, copied from the scratch folder on /dev/shm where the cases are written; after an
# abort, CASE.txt names the case that caused it). Prints every target's figures at the end,
# also to <out>/summary.txt. Exit status 1 when any target failed or died, 2 on a harness
# error (or when the build fails).
#
# FUZZ_SEED (default 2) chooses the cases; FUZZ_BOUND_S (default 10) bounds one solve. With
# ../shared beside the crate (when built), the corpora include excerpts of its real programs.
#
# Two campaigns may run at once (one per core) with different FUZZ_OUT folders and targets.
# FUZZ_WORK names the scratch folder to use (kept at the end); by default one is made on
# /dev/shm and removed at the end.
#
# Stopping it (Ctrl-C, kill) stops the running target's process first and waits for it, keeps
# its last case in <out>/<target>/work, and only then removes the scratch folder. A file the
# harness cannot write is a HARNESS ERROR, never counted as a failure of the target.
set -euo pipefail
cd "$(dirname "$0")/.."
minutes=${1:-60}
shift || true
out=${FUZZ_OUT:-target/fuzz-long}
mem_gb=${FUZZ_MEM_GB:-4}
mkdir -p "$out"

cargo test --release --test fuzz_cli --no-run 2> "$out/build.log" || { cat "$out/build.log" >&2; exit 2; }
bin=$(grep -o '[^ (]*release/deps/fuzz_cli-[0-9a-f]*' "$out/build.log" | tail -1)
rm -f "$out/build.log"
[ -x "$bin" ] || { echo "fuzz_long.sh: cannot find the test binary" >&2; exit 2; }
# A copy of its own: a build in this tree during the campaign (hours) does not change the
# binary that later targets run. (`solve` still runs target/release/feedopt.)
cp "$bin" "$out/fuzz_cli"
bin=$out/fuzz_cli

if [ $# -gt 0 ]; then
  targets=("$@")
else
  mapfile -t targets < <("$bin" --ignored --exact fuzz_list_targets --nocapture 2>/dev/null \
    | sed -n 's/^fuzz-target //p')
fi
[ ${#targets[@]} -gt 0 ] || { echo "fuzz_long.sh: no targets" >&2; exit 2; }

if [ -n "${FUZZ_WORK:-}" ]; then
  work=$FUZZ_WORK
  mkdir -p "$work"
  own_work=0
else
  shm=/dev/shm
  [ -d "$shm" ] && [ -w "$shm" ] || shm=${TMPDIR:-/tmp}
  work=$(mktemp -d -p "$shm" feedopt-fuzz.XXXXXX)
  own_work=1
fi
child=""
t=""
# In this order: the target's process (it writes in $work until it ends), its last case, then
# the scratch folder.
cleanup() {
  if [ -n "$child" ] && kill -0 "$child" 2> /dev/null; then
    kill -TERM "$child" 2> /dev/null || true
    wait "$child" 2> /dev/null || true
  fi
  child=""
  if [ -n "$t" ] && [ -d "$work/$t/work" ]; then
    cp -r "$work/$t/work" "$out/$t/" 2> /dev/null || true
  fi
  if [ "$own_work" = 1 ]; then rm -rf "$work"; fi
}
trap cleanup EXIT
trap 'echo "fuzz_long.sh: stopped during ${t:-the start}; its last case is in $out/${t:-?}/work" >&2; exit 130' INT TERM HUP
status=0
summary=()
for t in "${targets[@]}"; do
  dir=$out/$t
  rm -rf "$dir"
  mkdir -p "$dir"
  echo "fuzz_long.sh: $t for $minutes CPU minutes ($(date -u +%H:%M:%S) UTC)" >&2
  set +e
  # In the background, so that a signal reaches the trap at once (`wait` returns) and the trap
  # can stop this process before the scratch folder goes; `exec` keeps its pid.
  (
    ulimit -v $((mem_gb * 1024 * 1024))
    exec env FEEDOPT_FUZZ_TARGET="$t" FEEDOPT_FUZZ_CPU_MINUTES="$minutes" \
      FEEDOPT_FUZZ_OUT="$out" FEEDOPT_FUZZ_WORK="$work" \
      FEEDOPT_FUZZ_SEED="${FUZZ_SEED:-2}" FEEDOPT_FUZZ_BOUND_S="${FUZZ_BOUND_S:-10}" \
      nice -n 19 "$bin" --ignored --exact fuzz_long --nocapture --test-threads 1
  ) > "$dir/log.txt" 2>&1 &
  child=$!
  wait "$child"
  rc=$?
  child=""
  set -e
  cp -r "$work/$t/work" "$dir/" 2> /dev/null || true
  rm -rf "${work:?}/$t"
  if [ $rc -eq 0 ]; then
    verdict="clean"
  elif grep -q 'HARNESS ERROR' "$dir/log.txt"; then
    verdict="HARNESS ERROR (the harness failed, not $t): $(grep -m1 'HARNESS ERROR' "$dir/log.txt")"
    status=2
  elif [ -d "$dir/failures" ]; then
    verdict="FAILED: $(ls "$dir/failures" | wc -l) failing inputs in $dir/failures"
    [ $status -eq 2 ] || status=1
  else
    verdict="DIED (exit $rc): the case that was running is in $dir/work (CASE.txt)"
    [ $status -eq 2 ] || status=1
  fi
  summary+=("$t: $verdict")
  [ -f "$dir/figures.txt" ] && cat "$dir/figures.txt" >&2
  echo "fuzz_long.sh: $t: $verdict" >&2
done
t=""

header=""
for t2 in "${targets[@]}"; do
  [ -f "$out/$t2/figures.txt" ] && { header=$(sed -n '2p' "$out/$t2/figures.txt"); break; }
done
{
  echo "fuzz_long.sh: $minutes CPU minutes per target, seed ${FUZZ_SEED:-2}, $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  [ -n "$header" ] && echo "$header"
  for t2 in "${targets[@]}"; do
    if [ -f "$out/$t2/figures.txt" ]; then
      sed -n '3,$p' "$out/$t2/figures.txt" | grep -v '^  (errors:'
    else
      echo "  $t2: no figures (the process died; see $out/$t2/log.txt)"
    fi
  done
  printf '%s\n' "${summary[@]}"
} > "$out/summary.txt"
cat "$out/summary.txt"
exit $status
