#!/usr/bin/env bash
# Builds fieldrig with AddressSanitizer and UndefinedBehaviorSanitizer (GCC, RelWithDebInfo) into
# build-asan/ (or $FIELDRIG_BUILD_DIR) and runs every test there; given test folders
# (`scripts/test-sanitize.sh tests/core tests/gps`), it builds and runs only theirs, and a folder
# without tests is an error. Any sanitizer report fails the test that caused it: ASan aborts on
# the first error, UB stops the program (-fno-sanitize-recover), LeakSanitizer fails a program
# that leaks at exit.
#
# The few tests that cannot run under the sanitizers skip themselves, saying why
# (tests/support/sanitizer.h); the benchmarks and the fuzz smoke runs are not part of this build
# (the fuzzers bring their own sanitizers, and run in the README's build).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${FIELDRIG_BUILD_DIR:-$root/build-asan}
folders=("${@%/}")
targets=all
if ((${#folders[@]} == 0)); then
  folders=(.)
else
  targets=$(printf '%s/all ' "${folders[@]}")
fi
FIELDRIG_SANITIZE=address,undefined FIELDRIG_BUILD_DIR="$build" FIELDRIG_BUILD_TARGETS="$targets" \
  "$root/scripts/build.sh"
# Stack traces for UB reports; leak detection; and an allocation too large for ASan's allocator
# returns null from malloc and a non-throwing new, as glibc does (ASan still aborts a throwing
# new it cannot satisfy), since the frame pool's tests check that such a request is refused with
# an error rather than aborting.
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1}"
# Instrumented code runs 2-3 times slower: the per-test limit is three times the README build's.
for folder in "${folders[@]}"; do
  ctest --test-dir "$build/$folder" --output-on-failure --timeout 900 -j "$(nproc)" \
    --no-tests=error
done
