#!/usr/bin/env bash
# Fuzzes the case-file loader and --set parsing for SECONDS seconds in all: configures a clang
# build in build-fuzz/ with libFuzzer, AddressSanitizer and UBSan, replays
# fuzz/corpus/regressions/ (inputs that once crashed, hung or were wrongly accepted), then fuzzes
# override_fuzzer (--set parsing and the nesting scan, microseconds per input) for a quarter of
# the time and case_file_fuzzer (the whole loader, toml11 included) for the rest, from the seed
# corpora (cases/, fuzz/corpus/overrides/ and the regressions). Exit status non-zero on any crash, hang
# (> 10 s for one input), memory blow-up (> 2 GB) or sanitizer report; the input is then saved
# as build-fuzz/crash-*, timeout-* or oom-* (add it to fuzz/corpus/regressions/ once fixed).
#   fuzz/run.sh 60                 # CI
#   JOBS=2 fuzz/run.sh 3600        # longer, two fuzzing processes (libFuzzer -fork)
# BUILD_JOBS (default: all cores) sets the build's parallelism.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:?usage: fuzz/run.sh SECONDS}"
jobs="${JOBS:-1}"
# FUZZ_BUILD names a tree already configured with -DKIRCHHOFF_FUZZ=ON and the same sanitizer
# flags (.ci/sanitize's build-asan, which also holds the fast tests): it is built, not reconfigured.
build="${FUZZ_BUILD:-build-fuzz}"

runtime=$(clang++ -print-file-name=libclang_rt.fuzzer-x86_64.a 2>/dev/null || true)
if ! command -v clang++ >/dev/null || [ ! -f "$runtime" ]; then
  echo "fuzz/run.sh: needs clang++ and libFuzzer (Debian: clang libclang-rt-14-dev)" >&2
  exit 2
fi

# The library with the sanitizers (fuzz/sanitizer_flags.sh); KIRCHHOFF_FUZZ instruments its
# case-loading sources for coverage (lib/CMakeLists.txt) and links libFuzzer into the targets only.
source fuzz/sanitizer_flags.sh
if [ -z "${FUZZ_BUILD:-}" ]; then
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_CXX_FLAGS="$SANITIZER_FLAGS" -DCMAKE_EXE_LINKER_FLAGS="$SANITIZER_LINK_FLAGS" \
    -DKIRCHHOFF_FUZZ=ON -DKIRCHHOFF_BUILD_TESTS=OFF -DKIRCHHOFF_BUILD_BENCH=OFF -DKIRCHHOFF_BUILD_PYTHON=OFF >/dev/null
fi
cmake --build "$build" -j"${BUILD_JOBS:-$(nproc)}" --target case_file_fuzzer override_fuzzer

export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
# Leaks are checked too: the loader allocates per input and a leak would grow over a run.
export ASAN_OPTIONS="detect_leaks=1"
fuzzer="$build/fuzz/case_file_fuzzer"
override_fuzzer="$build/fuzz/override_fuzzer"
# -max_len: the largest shipped case is 2.9 kB; toml11 takes ~1 us per byte (more under ASan),
# so longer inputs would mostly slow the search down.
limits=(-timeout=10 -rss_limit_mb=2048 -max_len=4096)

echo "== replaying fuzz/corpus/regressions"
"$fuzzer" "${limits[@]}" fuzz/corpus/regressions/*
"$override_fuzzer" "${limits[@]}" fuzz/corpus/overrides/* fuzz/corpus/regressions/*

# The seed corpus: every shipped case, the regressions, and what earlier runs found (kept in
# build-fuzz/corpus, outside git; a fresh clone starts from the seeds). The cases are seeded
# without their descriptions and comments: toml11 spends most of an execution on the text, and
# the prose exercises nothing the shorter strings do not.
mkdir -p "$build/corpus" "$build/seeds" "$build/corpus-override"
for case in cases/*.toml; do
  awk '/^description = """/ { skip = 1 } skip { if (/"""$/ && !/^description = """$/) skip = 0; next }
       /^[[:space:]]*#/ { next } { sub(/[[:space:]]+#[^"]*$/, ""); print }' "$case" >"$build/seeds/$(basename "$case")"
done
cd "$build"
fork=()
[ "$jobs" -gt 1 ] && fork=(-fork="$jobs" -ignore_crashes=0)
quarter=$(( seconds / 4 > 5 ? seconds / 4 : 5 ))
echo "== fuzzing override_fuzzer for $quarter s"
../"$override_fuzzer" "${limits[@]}" "${fork[@]}" -max_total_time="$quarter" -print_final_stats=1 \
  -dict=../fuzz/case_file.dict corpus-override ../fuzz/corpus/overrides
echo "== fuzzing case_file_fuzzer for $(( seconds - quarter > 5 ? seconds - quarter : 5 )) s"
../"$fuzzer" "${limits[@]}" "${fork[@]}" -max_total_time="$(( seconds - quarter > 5 ? seconds - quarter : 5 ))" \
  -print_final_stats=1 -dict=../fuzz/case_file.dict corpus seeds ../fuzz/corpus/regressions
