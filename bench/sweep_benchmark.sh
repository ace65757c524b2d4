#!/usr/bin/env bash
# `kirchhoff sweep` serially and under MPI: the speed-up with 2 ranks on a grid of 48 solves, and the
# manager's overhead per job. Prints the measurements; docs/sweeps.md extrapolates from them.
#
#   bench/sweep_benchmark.sh [BUILD_DIR]        (from the repository's top folder; default build)
#
# 1. 48 solves of cases/wall.toml (a = 0.1, 0.125; Delta = 0.005 ... 0.045), each reached by homotopy
#    from the case's values (0.1 to a few seconds: the costs differ, as in real sweeps): serial, then
#    mpirun -n 2 (the manager runs jobs on a thread between messages); the two index.csv must be
#    identical.
# 2. 400 jobs that cost almost nothing (Fig. 3 at the case's own theta0: Newton from its guess, ~3 ms)
#    under mpirun -n 2 --manager-only: one worker runs them all, so the wall time beyond the jobs'
#    own is the scheduling's cost per job; the CLI also prints how long workers waited per job.
set -euo pipefail
build=${1:-build}
kirchhoff=$(realpath "$build/apps/kirchhoff")
cases=$(realpath cases)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mpirun=(mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && mpirun+=(--allow-run-as-root)

seconds() { local t0 t1; t0=$(date +%s.%N); "$@" > /dev/null 2> "$work/last.log"; t1=$(date +%s.%N); echo "$t1 - $t0" | bc -l; }
sum_of_jobs() { awk -F, 'NR > 1 { s += $2 } END { printf "%.3f", s }' "$1/times.csv"; }

cat > "$work/solves.toml" <<TOML
case = "$cases/wall.toml"
solver = { tolerance = 1e-10 }
[[jobs]]
name = "wall"
kind = "solve"
grid = { a = [0.1, 0.125], Delta = { from = 0.005, to = 0.045, count = 24 } }
profiles = false
TOML
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores (other processes slow the ranks down)"
t_serial=$(seconds "$kirchhoff" sweep "$work/solves.toml" --out "$work/serial")
t_mpi=$(seconds "${mpirun[@]}" -n 2 "$kirchhoff" sweep "$work/solves.toml" --out "$work/mpi")
waited=$(grep -o 'waited [0-9.e+-]* ms' "$work/last.log" || echo "waited ? ms")
cmp -s "$work/serial/index.csv" "$work/mpi/index.csv" && same=identical || same=DIFFERENT
printf '48 solves (wall.toml): serial %.1f s (jobs %s s), mpirun -n 2 %.1f s: speed-up %.2f; index.csv %s\n' \
  "$t_serial" "$(sum_of_jobs "$work/serial")" "$t_mpi" "$(echo "$t_serial / $t_mpi" | bc -l)" "$same"
printf '  the worker %s for the manager per job; the jobs took %s s in all under MPI (serially %s s):\n' \
  "$waited" "$(sum_of_jobs "$work/mpi")" "$(sum_of_jobs "$work/serial")"
printf '  parallel efficiency (jobs / (2 x wall)) %.2f, the cores the two ranks had between them %.2f\n' \
  "$(echo "$(sum_of_jobs "$work/serial") / (2 * $t_mpi)" | bc -l)" "$(echo "$(sum_of_jobs "$work/mpi") / $t_mpi" | bc -l)"

cat > "$work/tiny.toml" <<TOML
case = "$cases/simply_supported.toml"
[[jobs]]
name = "tiny"
kind = "solve"
list = [$(for k in $(seq 400); do printf '{ theta0 = 1 }, '; done)]
profiles = false
TOML
t_tiny=$(seconds "${mpirun[@]}" -n 2 "$kirchhoff" sweep "$work/tiny.toml" --out "$work/tiny" --manager-only)
waited=$(grep -o 'waited [0-9.e+-]* ms' "$work/last.log" || echo "waited ? ms")
t_start=$(seconds "${mpirun[@]}" -n 2 "$kirchhoff" sweep "$work/tiny.toml" --out "$work/tiny" --manager-only --resume)
jobs_s=$(sum_of_jobs "$work/tiny")
printf '400 tiny jobs, mpirun -n 2 --manager-only: %.2f s, of which jobs %s s and start-up + index %.2f s (the same run\n' \
  "$t_tiny" "$jobs_s" "$t_start"
printf '  resumed with nothing to do): overhead per job %.2f ms; the worker %s per job\n' \
  "$(echo "($t_tiny - $jobs_s - $t_start) * 1000 / 400" | bc -l)" "$waited"
