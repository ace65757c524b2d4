#!/usr/bin/env bash
# Developer tool (not run by CI): kills the README's continuation commands with SIGKILL at random
# moments, resumes each with --resume, and compares the resumed CSV with the uninterrupted run's.
#
#   tests/resume_soak.sh N [euler|wall|twisted|arch|wrap ...]     (default: euler wall)
#   tests/resume_soak.sh --rows STRIDE [euler|wall|twisted|arch|wrap ...]
#
# With --rows, the kills are deterministic instead: after rows -1, 0, STRIDE, 2 STRIDE, ... and
# the last row (KIRCHHOFF_TEST_KILL_AFTER_ROW, which the CLI honours for tests), each resumed and
# compared; it prints "K of M kills matched".
#
# For each command: one uninterrupted run (run twice, to check it is itself reproducible), then N
# trials that start the run, kill it after a uniformly random time in [0, its duration], resume it
# to the end and compare byte for byte. Prints "K of N trials matched" per command (trials whose
# run ended before the kill count too, and are reported). Exit status 1 when a trial differs.
# KIRCHHOFF (default build/apps/kirchhoff) and CASES (default cases) locate the binary and cases.
set -u
STRIDE=""
if [ "${1:-}" = "--rows" ]; then
  STRIDE=${2:?usage: resume_soak.sh --rows STRIDE [euler|wall|twisted|arch|wrap ...]}
  shift 2
  N=0
else
  N=${1:?usage: resume_soak.sh N [euler|wall|twisted|arch|wrap ...]}
  shift
fi
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${KIRCHHOFF:-$ROOT/build/apps/kirchhoff}
CASES=${CASES:-$ROOT/cases}
WORK=$(mktemp -d /tmp/resume_soak.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
[ $# -gt 0 ] || set -- euler wall

command_of() {
  case $1 in
    euler) echo "$CASES/euler_column.toml --param P --to 12 --set P=1 --set theta_guess=0 --switch-at-bp 1 --event theta0=3 --max-step 1" ;;
    wall) echo "$CASES/wall.toml --param Delta --to 0.07 --set Delta=0.005 --set m_guess=0.9 --max-step 2 --max-points 6000" ;;
    twisted) echo "$CASES/twisted_clamped.toml --param phi --to 15 --switch-at-bp 1 --event end_to_end=0.5 --max-step 0.2" ;;
    arch) echo "$CASES/shallow_arch.toml --param w --to 120 --max-step 2" ;;
    wrap) echo "$CASES/wrapped_indenter.toml --set radius=0.5 --set half_span=0.5 --set rise=0.18 --param rise --to -0.01 --step 0.01 --max-step 1" ;;
    *) echo "unknown command '$1' (euler, wall, twisted, arch, wrap)" >&2; exit 2 ;;
  esac
}

now() { date +%s.%N; }
status=0
for name in "$@"; do
  # The state after every point (--checkpoint 0): a kill then resumes from the point before it,
  # not from the last timed checkpoint, which in a run of a few seconds is its start.
  args="$(command_of "$name") --checkpoint 0" || exit 2
  # shellcheck disable=SC2086
  start=$(now); "$BIN" continue $args --out "$WORK/full.csv" 2>/dev/null; end=$(now)
  duration=$(awk -v a="$start" -v b="$end" 'BEGIN { print b - a }')
  # shellcheck disable=SC2086
  "$BIN" continue $args --out "$WORK/again.csv" 2>/dev/null
  if ! cmp -s "$WORK/full.csv" "$WORK/again.csv"; then
    echo "$name: the uninterrupted run is not reproducible itself; no comparison possible"
    status=1
    continue
  fi
  rows=$(($(wc -l < "$WORK/full.csv") - 1))
  if [ -n "$STRIDE" ]; then
    matched=0 kills=0 bad=""
    for row in -1 $(seq 0 "$STRIDE" $((rows - 1))) $((rows - 1)); do
      rm -f "$WORK/run.csv" "$WORK/run.csv.state.json"
      # (Braced, so that the shell's "Killed" notice goes to /dev/null with the run's stderr.)
      # shellcheck disable=SC2086
      { KIRCHHOFF_TEST_KILL_AFTER_ROW=$row "$BIN" continue $args --out "$WORK/run.csv"; } 2>/dev/null
      # shellcheck disable=SC2086
      "$BIN" continue $args --out "$WORK/run.csv" --resume 2>/dev/null
      rc=$?
      kills=$((kills + 1))
      if [ $rc -eq 0 ] && cmp -s "$WORK/run.csv" "$WORK/full.csv"; then
        matched=$((matched + 1))
      else
        bad="$bad [after row $row: resume exit $rc]"
        status=1
      fi
    done
    printf '%s: %d of %d kills matched (after rows -1, 0, every %d-th and the last of %d rows)%s\n' \
      "$name" "$matched" "$kills" "$STRIDE" "$rows" "$bad"
    continue
  fi
  matched=0 finished=0 bad=""
  for trial in $(seq 1 "$N"); do
    rm -f "$WORK/run.csv" "$WORK/run.csv.state.json"
    delay=$(awk -v d="$duration" -v r="$RANDOM" 'BEGIN { printf "%.4f", d * r / 32767 }')
    # shellcheck disable=SC2086
    "$BIN" continue $args --out "$WORK/run.csv" 2>/dev/null &
    pid=$!
    sleep "$delay"
    kill -KILL "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
    [ $? -eq 137 ] || finished=$((finished + 1))  # 128 + SIGKILL: it was killed, else it had ended
    killed_rows=none  # killed before it created its CSV
    [ -f "$WORK/run.csv" ] && killed_rows=$(($(wc -l < "$WORK/run.csv") - 1))
    # shellcheck disable=SC2086
    "$BIN" continue $args --out "$WORK/run.csv" --resume 2>"$WORK/resume.log"
    rc=$?
    if [ $rc -eq 0 ] && cmp -s "$WORK/run.csv" "$WORK/full.csv"; then
      matched=$((matched + 1))
    else
      bad="$bad [trial $trial: killed at $delay s after $killed_rows rows, resume exit $rc: $(cmp "$WORK/run.csv" "$WORK/full.csv" 2>&1 | head -1)]"
      status=1
    fi
  done
  printf '%s: %d of %d trials matched (uninterrupted: %d rows in %.2f s; %d runs had finished before the kill)%s\n' \
    "$name" "$matched" "$N" "$rows" "$duration" "$finished" "$bad"
done
exit $status
