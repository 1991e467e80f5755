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
# children's), so a busy machine stretches the wall time, not the work done.
#
# Writes target/fuzz-long/<target>/: figures.txt (cases, clean errors, failures, kinds of
# error, seeds read cleanly, mean and slowest ms, CPU and wall seconds), log.txt,
# failures/case-<n>/ (each failing input with WHAT.txt) and work/ (the last case, copied from
# the scratch folder on /dev/shm where the cases are written; after an abort, CASE.txt names
# the case that caused it). Prints every target's figures at the end, also to
# target/fuzz-long/summary.txt. Exit status 1 when any target failed or died.
#
# FUZZ_SEED (default 2) chooses the cases; FUZZ_BOUND_S (default 10) bounds one solve. With
# ../shared beside the crate (when built), the corpora include excerpts of its real programs.
set -euo pipefail
cd "$(dirname "$0")/.."
minutes=${1:-60}
shift || true
out=target/fuzz-long
mem_gb=${FUZZ_MEM_GB:-4}

cargo test --release --test fuzz_cli --no-run 2> "$out.build.log" || { cat "$out.build.log" >&2; exit 2; }
bin=$(grep -o 'target/release/deps/fuzz_cli-[0-9a-f]*' "$out.build.log" | tail -1)
rm -f "$out.build.log"
[ -x "$bin" ] || { echo "fuzz_long.sh: cannot find the test binary" >&2; exit 2; }

if [ $# -gt 0 ]; then
  targets=("$@")
else
  mapfile -t targets < <("$bin" --ignored --exact fuzz_list_targets --nocapture 2>/dev/null \
    | sed -n 's/^fuzz-target //p')
fi
[ ${#targets[@]} -gt 0 ] || { echo "fuzz_long.sh: no targets" >&2; exit 2; }

mkdir -p "$out"
shm=/dev/shm
[ -d "$shm" ] && [ -w "$shm" ] || shm=${TMPDIR:-/tmp}
work=$(mktemp -d -p "$shm" feedopt-fuzz.XXXXXX)
trap 'rm -rf "$work"' EXIT
status=0
summary=()
for t in "${targets[@]}"; do
  dir=$out/$t
  rm -rf "$dir"
  mkdir -p "$dir"
  echo "fuzz_long.sh: $t for $minutes CPU minutes ($(date -u +%H:%M:%S) UTC)" >&2
  set +e
  (
    ulimit -v $((mem_gb * 1024 * 1024))
    FEEDOPT_FUZZ_TARGET=$t FEEDOPT_FUZZ_CPU_MINUTES=$minutes FEEDOPT_FUZZ_OUT=$out \
      FEEDOPT_FUZZ_WORK=$work \
      FEEDOPT_FUZZ_SEED=${FUZZ_SEED:-2} FEEDOPT_FUZZ_BOUND_S=${FUZZ_BOUND_S:-10} \
      nice -n 19 "$bin" --ignored --exact fuzz_long --nocapture --test-threads 1
  ) > "$dir/log.txt" 2>&1
  rc=$?
  set -e
  cp -r "$work/$t/work" "$dir/" 2> /dev/null || true
  rm -rf "${work:?}/$t"
  if [ $rc -eq 0 ]; then
    verdict="clean"
  elif [ -d "$dir/failures" ]; then
    verdict="FAILED: $(ls "$dir/failures" | wc -l) failing inputs in $dir/failures"
    status=1
  else
    verdict="DIED (exit $rc): the case that was running is in $dir/work (CASE.txt)"
    status=1
  fi
  summary+=("$t: $verdict")
  [ -f "$dir/figures.txt" ] && cat "$dir/figures.txt" >&2
  echo "fuzz_long.sh: $t: $verdict" >&2
done

header=""
for t in "${targets[@]}"; do
  [ -f "$out/$t/figures.txt" ] && { header=$(sed -n '2p' "$out/$t/figures.txt"); break; }
done
{
  echo "fuzz_long.sh: $minutes CPU minutes per target, seed ${FUZZ_SEED:-2}, $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  [ -n "$header" ] && echo "$header"
  for t in "${targets[@]}"; do
    if [ -f "$out/$t/figures.txt" ]; then
      sed -n '3,$p' "$out/$t/figures.txt" | grep -v '^  (errors:'
    else
      echo "  $t: no figures (the process died; see $out/$t/log.txt)"
    fi
  done
  printf '%s\n' "${summary[@]}"
} > "$out/summary.txt"
cat "$out/summary.txt"
exit $status
