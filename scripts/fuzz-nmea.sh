#!/usr/bin/env bash
# Fuzzes the NMEA parser with libFuzzer for a bounded time.
#
#   scripts/fuzz-nmea.sh [SECONDS]     (default 20)
#
# Builds with clang++ directly from the parser sources (no CMake), seeds the corpus with every
# line of the gpsd regression logs, and exits non-zero when the fuzzer finds a crash, a sanitizer
# report or a broken invariant. Exit 77 (CTest "skipped") when clang++ or its fuzzer runtime is
# missing. Everything is written under FUZZ_WORK_DIR (default: a fresh temporary folder), never
# into the repository.
set -euo pipefail

seconds="${1:-20}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
data_dir="${FIELDRIG_SHARED_DATA_DIR:-$root/../shared/data}/nmea/gpsd"
work="${FUZZ_WORK_DIR:-$(mktemp -d -t fieldrig-fuzz-nmea.XXXXXX)}"
mkdir -p "$work"

clangxx=""
for candidate in clang++ clang++-19 clang++-18 clang++-17 clang++-16 clang++-15 clang++-14; do
  if command -v "$candidate" >/dev/null 2>&1; then
    clangxx="$candidate"
    break
  fi
done
if [[ -z "$clangxx" ]]; then
  echo "fuzz-nmea: no clang++ found; skipping" >&2
  exit 77
fi

# The fuzzer runtime ships separately (libclang-rt-*-dev on Debian): probe for it.
probe="$work/probe.cpp"
printf 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }\n' \
  >"$probe"
if ! "$clangxx" -fsanitize=fuzzer,address,undefined "$probe" -o "$work/probe" 2>"$work/probe.log"; then
  echo "fuzz-nmea: $clangxx cannot link the libFuzzer runtime (see $work/probe.log); skipping" >&2
  exit 77
fi

binary="$work/nmea_parser_fuzzer"
"$clangxx" -std=c++20 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined -O1 -g \
  -I"$root/gps/include" -I"$root/core/include" \
  "$root/tests/fuzz/nmea_parser_fuzzer.cpp" "$root/gps/src/nmea_parser.cpp" \
  "$root/gps/src/fix_assembler.cpp" "$root/core/src/time.cpp" \
  -o "$binary"

# Seed corpus: one file per line of the real receiver logs (garbage lines included).
corpus="$work/corpus"
mkdir -p "$corpus"
if [[ -d "$data_dir" ]]; then
  n=0
  for log in "$data_dir"/*.log; do
    while IFS= read -r line || [[ -n "$line" ]]; do
      n=$((n + 1))
      printf '%s\n' "$line" >"$corpus/seed-$n"
    done <"$log"
  done
  echo "fuzz-nmea: seeded $n lines from $data_dir"
else
  echo "fuzz-nmea: no gpsd logs at $data_dir; starting from an empty corpus" >&2
fi

echo "fuzz-nmea: running $seconds s in $work"
status=0
(cd "$work" && "$binary" -max_total_time="$seconds" -max_len=4096 -timeout=10 \
  -print_final_stats=1 "$corpus") >"$work/fuzz.log" 2>&1 || status=$?
tail -n 25 "$work/fuzz.log"
if [[ $status -ne 0 ]]; then
  echo "fuzz-nmea: FAILED (exit $status); reproducer and log in $work" >&2
  exit 1
fi
echo "fuzz-nmea: no crash in $seconds s"
if [[ -z "${FUZZ_WORK_DIR:-}" ]]; then rm -rf "$work"; fi
