#!/usr/bin/env bash
# Fuzzes one of fieldrig's parsers with libFuzzer for a bounded time.
#
#   scripts/fuzz.sh TARGET [SECONDS]     (default 20)
#   scripts/fuzz.sh --list               the targets
#
# Each target is tests/fuzz/TARGET_fuzzer.cpp, built with clang++ directly from the sources it
# fuzzes (no CMake: the project builds with GCC, which has no libFuzzer). Where a parser lives in a
# big library its few source files are compiled into the fuzzer rather than linking the library.
# Objects go through ccache when it is installed, so a second run compiles nothing.
#
# The seed corpus comes from the repository's and the shared data's own inputs (by path, never
# copied into the repository) and from seeds the target writes with the project's own writers.
# Exits non-zero when the fuzzer finds a crash, a sanitizer report, a hang or a broken invariant;
# exit 77 (CTest "skipped") when clang++ or its fuzzer runtime is missing. Everything is written
# under FUZZ_WORK_DIR (default: a fresh temporary folder, removed after a clean run), never into
# the repository; a finding leaves its reproducer there (crash-*, timeout-*, leak-*).
set -euo pipefail

# One function, read whole before it runs: editing this file cannot break a run in progress.
main() {
  root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
  data="${FIELDRIG_SHARED_DATA_DIR:-$root/../shared/data}"
  targets=(nmea_parser map_csv session_index_line cloud_file calibration_yaml config_yaml
           traits_options stem_page_request)

  usage() {
    echo "usage: scripts/fuzz.sh TARGET [SECONDS]   (TARGET: ${targets[*]})" >&2
    exit 2
  }

  if [[ "${1:-}" == "--list" ]]; then
    printf '%s\n' "${targets[@]}"
    exit 0
  fi
  [[ $# -ge 1 && $# -le 2 ]] || usage
  target="$1"
  seconds="${2:-20}"
  [[ " ${targets[*]} " == *" $target "* ]] || usage
  [[ "$seconds" =~ ^[0-9]+$ && "$seconds" -gt 0 ]] || usage

  # What each target compiles (besides tests/fuzz/TARGET_fuzzer.cpp), its include folders and
  # libraries, the seed files it starts from, and the largest input it tries.
  sources=()
  includes=(core/include)
  system_includes=()
  libs=()
  seed_files=()
  max_len=4096
  case "$target" in
    nmea_parser)
      sources=(gps/src/nmea_parser.cpp gps/src/fix_assembler.cpp core/src/time.cpp)
      includes+=(gps/include)
      ;;
    map_csv)
      sources=(gps/src/location_map.cpp core/src/durable_file.cpp)
      includes+=(gps/include)
      seed_files=("$root/sim/data/demo_map.csv")
      ;;
    session_index_line)
      sources=(recording/src/session_format.cpp core/src/time.cpp)
      includes+=(recording/include)
      ;;
    cloud_file)
      # Both readers are the project's own: no PCL.
      sources=(pipeline/traits/src/cloud_io.cpp)
      includes+=(pipeline/traits/include)
      system_includes=(/usr/include/eigen3)
      seed_files=("$data"/pointclouds/pcl/*.pcd)
      max_len=16384
      ;;
    calibration_yaml)
      # The stereo calibration (pipeline/stereo) and the rig's rig.yml (pipeline/cloud): their
      # loaders only, not the two libraries.
      sources=(pipeline/stereo/src/calibration.cpp pipeline/cloud/src/rig_calibration.cpp
               core/src/durable_file.cpp)
      includes+=(pipeline/stereo/include pipeline/cloud/include)
      system_includes=(/usr/include/opencv4)
      libs=(-lyaml-cpp -lopencv_calib3d -lopencv_core)
      max_len=16384
      ;;
    config_yaml | traits_options)
      # config.cpp calls the option checks of the cloud, the matcher and the traits and the
      # fsync policy's parser; the file that holds TraitsOptions::validate() also holds the
      # traits, whose steps need PCL: those few files are compiled in, not their libraries.
      sources=(config/src/config.cpp config/src/traits_config.cpp
               pipeline/cloud/src/cloud_options.cpp pipeline/stereo/src/matcher.cpp
               pipeline/traits/src/plot_traits.cpp pipeline/traits/src/depth_map_area.cpp
               pipeline/traits/src/sparse_outliers.cpp pipeline/traits/src/pcl_steps.cpp
               pipeline/traits/src/paper_area.cpp recording/src/session_format.cpp
               core/src/time.cpp)
      includes+=(config/include gps/include drivers/include recording/include
                 pipeline/cloud/include pipeline/stereo/include pipeline/traits/include)
      system_includes=(/usr/include/eigen3 /usr/include/pcl-1.13 /usr/include/opencv4)
      libs=(-lyaml-cpp -lopencv_ximgproc -lopencv_calib3d -lopencv_imgproc -lopencv_core
            -lpcl_surface -lpcl_registration -lpcl_features -lpcl_filters -lpcl_search
            -lpcl_kdtree -lpcl_sample_consensus -lpcl_common -lqhull_r -lspdlog -lfmt)
      if [[ "$target" == config_yaml ]]; then
        seed_files=("$root/config/fieldrigd.yaml" "$root/config/replay.yaml")
      fi
      ;;
    stem_page_request)
      # The page's API end to end (StemPage::handle) on a session the target records at start:
      # the request bodies are parsed inside stem_page.cpp, not callable on their own.
      sources=(tools/stem_page/stem_page.cpp tools/stem_page/route_table.cpp
               daemon/src/head_frames.cpp
               pipeline/stem/src/quadrangle.cpp pipeline/stem/src/stem_measurer.cpp
               pipeline/stem/src/measurement_json.cpp pipeline/stem/src/measurement_log.cpp
               pipeline/stereo/src/calibration.cpp pipeline/stereo/src/preprocess.cpp
               pipeline/stereo/src/disparity_io.cpp
               pipeline/stereo/src/rectifier.cpp pipeline/cloud/src/rig_calibration.cpp
               recording/src/session_format.cpp recording/src/session_writer.cpp
               recording/src/session_reader.cpp recording/src/file_util.cpp
               core/src/time.cpp core/src/durable_file.cpp core/src/frame_pool.cpp)
      includes+=(tools daemon/include pipeline/stem/include pipeline/stereo/include
                 recording/include drivers/include gps/include pipeline/cloud/include
                 pipeline/traits/include pipeline/processor/include)
      system_includes=(/usr/include/eigen3 /usr/include/pcl-1.13 /usr/include/opencv4)
      libs=(-lyaml-cpp -lopencv_imgcodecs -lopencv_calib3d -lopencv_imgproc -lopencv_core
            -lcrypto -lz -lspdlog -lfmt)
      ;;
  esac

  work="${FUZZ_WORK_DIR:-$(mktemp -d -t "fieldrig-fuzz-$target.XXXXXX")}"
  mkdir -p "$work"
  say() { echo "fuzz $target: $*"; }

  clangxx=""
  for candidate in clang++ clang++-19 clang++-18 clang++-17 clang++-16 clang++-15 clang++-14; do
    if command -v "$candidate" >/dev/null 2>&1; then
      clangxx="$candidate"
      break
    fi
  done
  if [[ -z "$clangxx" ]]; then
    say "no clang++ found; skipping" >&2
    exit 77
  fi

  # The fuzzer runtime ships separately (libclang-rt-*-dev on Debian): probe for it.
  probe="$work/probe.cpp"
  printf 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }\n' \
    >"$probe"
  if ! "$clangxx" -fsanitize=fuzzer,address,undefined "$probe" -o "$work/probe" 2>"$work/probe.log"; then
    say "$clangxx cannot link the libFuzzer runtime (see $work/probe.log); skipping" >&2
    exit 77
  fi

  launcher=()
  if command -v ccache >/dev/null 2>&1; then
    launcher=(ccache)
  fi
  flags=(-std=c++20 -O1 -g -fno-omit-frame-pointer -fsanitize=fuzzer-no-link,address,undefined
         -fno-sanitize-recover=undefined -DFIELDRIG_VERSION='"fuzz"' -DFMT_SHARED
         -DSPDLOG_COMPILED_LIB -DSPDLOG_FMT_EXTERNAL -DSPDLOG_SHARED_LIB)
  for dir in "${includes[@]}"; do flags+=(-I"$root/$dir"); done
  flags+=(-I"$root/tests/fuzz")
  for dir in "${system_includes[@]}"; do flags+=(-isystem "$dir"); done

  objects=()
  mkdir -p "$work/obj"
  for source in "tests/fuzz/${target}_fuzzer.cpp" "${sources[@]}"; do
    object="$work/obj/${source//\//_}.o"
    "${launcher[@]}" "$clangxx" "${flags[@]}" -c "$root/$source" -o "$object"
    objects+=("$object")
  done
  binary="$work/${target}_fuzzer"
  "$clangxx" -fsanitize=fuzzer,address,undefined "${objects[@]}" "${libs[@]}" -o "$binary"

  # Seed corpus: the data files above, then the target's own seeds (FIELDRIG_FUZZ_SEEDS).
  corpus="$work/corpus"
  mkdir -p "$corpus" "$work/empty"
  n=0
  if [[ "$target" == nmea_parser ]]; then
    # One file per line of the real receiver logs (garbage lines included).
    if [[ -d "$data/nmea/gpsd" ]]; then
      for log in "$data"/nmea/gpsd/*.log; do
        while IFS= read -r line || [[ -n "$line" ]]; do
          n=$((n + 1))
          printf '%s\n' "$line" >"$corpus/seed-$n"
        done <"$log"
      done
    else
      say "no gpsd logs at $data/nmea/gpsd; starting from an empty corpus" >&2
    fi
  fi
  for file in "${seed_files[@]}"; do
    if [[ -f "$file" ]]; then
      n=$((n + 1))
      cp "$file" "$corpus/seed-$n-$(basename "$file")"
    else
      say "seed $file is missing; going on without it" >&2
    fi
  done
  if ! (cd "$work" && FIELDRIG_FUZZ_SEEDS="$corpus" FIELDRIG_SHARED_DATA_DIR="$data" \
    "$binary" -runs=0 "$work/empty") >"$work/seeds.log" 2>&1; then
    cat "$work/seeds.log" >&2
    say "writing the target's own seeds failed" >&2
    exit 1
  fi
  say "$(ls "$corpus" | wc -l) seeds"

  say "running $seconds s in $work"
  status=0
  (cd "$work" && UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}" "$binary" \
    -max_total_time="$seconds" -max_len="$max_len" -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 "$corpus") >"$work/fuzz.log" 2>&1 || status=$?
  tail -n 25 "$work/fuzz.log"
  if [[ $status -ne 0 ]]; then
    say "FAILED (exit $status); reproducer and log in $work" >&2
    exit 1
  fi
  say "no finding in $seconds s"
  if [[ -z "${FUZZ_WORK_DIR:-}" ]]; then rm -rf "$work"; fi
}

main "$@"
