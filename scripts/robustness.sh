#!/usr/bin/env bash
# The robustness stage of CI: the test suite under AddressSanitizer + UndefinedBehaviorSanitizer
# (g++, build-asan/; every test but those labelled `slow`, which are long runs of code the other
# tests already cover, and which the Quick-start test command has just run in the normal build), then every libFuzzer target of fuzz/ (clang, build-fuzz/) for FUZZ_SECONDS
# seconds each (default 60) from its seed corpus.
# Fails on a test failure, a sanitizer report, a leak, a fuzzer crash or a fuzzer timeout.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${FUZZ_SECONDS:-60}
jobs=${JOBS:-2}

./scripts/install-deps.sh --robustness
# The sanitizer build uses the project's compiler, so that runs follow the same floating-point
# paths as the normal build and the same tests hold.
cmake -S . -B build-asan -G Ninja -DFLEETMAP_SANITIZE=ON -DFLEETMAP_BUILD_BENCH=OFF
cmake --build build-asan
# Sanitizer reports end the process with an error; leaks are reported at exit. GCC 12's leak
# checker misreads glibc 2.36's dynamic TLS blocks of the libraries Ceres brings (a block at
# 0x15ba) and dies scanning them, losing the program's buffered output; intercept_tls_get_addr=0
# leaves those blocks out of the scan, and leaks elsewhere are still found.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:halt_on_error=1:detect_stack_use_after_return=1:intercept_tls_get_addr=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/fuzz/lsan.supp:print_suppressions=0}
ctest --test-dir build-asan -j"$jobs" --output-on-failure -LE slow

# libFuzzer needs clang: a second build with only the fuzz targets and what they link.
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DFLEETMAP_FUZZ=ON -DFLEETMAP_BUILD_BENCH=OFF \
  -DFLEETMAP_BUILD_TESTS=OFF
cmake --build build-fuzz --target fuzz_map_image fuzz_map_yaml fuzz_scenario fuzz_sweep fuzz_slam_scenario fuzz_laser_log

# Fuzz from a copy of the seed corpus, so that the repository's corpus stays as committed.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for target in map_image map_yaml scenario sweep slam_scenario laser_log; do
  mkdir -p "$work/$target" "$work/artifacts"
  cp fuzz/corpus/$target/* "$work/$target/"
  echo "robustness: fuzzing $target for ${seconds} s"
  build-fuzz/fuzz/fuzz_$target "$work/$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -max_len=65536 -print_final_stats=1 -artifact_prefix="$work/artifacts/" 2>"$work/$target.log" || {
    tail -n 60 "$work/$target.log"
    echo "robustness: fuzz_$target found a problem (input saved under $work/artifacts, shown above)" >&2
    trap - EXIT
    exit 1
  }
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$work/$target.log" | sed "s/^/  $target /"
done
echo "robustness: all passed"
