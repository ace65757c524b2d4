# Sourced by .ci/sanitize and fuzz/run.sh: the clang flags of the instrumented tree they share.
#
# AddressSanitizer, and UndefinedBehaviorSanitizer halting on its first report, without three of
# its checks that ASan already covers and that took over a third of the compile time of the
# heaviest source, stability.cpp (Eigen's expression templates are pointer and reference
# accesses throughout): `null` and `alignment`
# (a null or misaligned access faults, and ASan reports the fault with its stack) and
# `object-size` (an access outside its object lands in ASan's redzones). The checks kept are the
# arithmetic ones ASan cannot see: signed overflow, shifts, float-to-int, bounds of arrays,
# bool and enum values, unreachable code, vptr.
# Coverage for the fuzzers (-fsanitize=fuzzer-no-link) is not here: lib/CMakeLists.txt adds it to
# the case-loading sources only, when KIRCHHOFF_FUZZ is on.
SANITIZER_FLAGS="-fsanitize=address,undefined -fno-sanitize=alignment,null,object-size"
SANITIZER_FLAGS+=" -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
# Eigen 3.4.0 takes blocks of empty matrices as a null pointer plus an offset: see the file.
SANITIZER_FLAGS+=" -fsanitize-ignorelist=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/ubsan_ignorelist.txt"
SANITIZER_FLAGS+=" -Wno-unknown-warning-option"  # lib/ passes a GCC-only -Wno-maybe-uninitialized
SANITIZER_LINK_FLAGS="-fsanitize=address,undefined"
