#!/usr/bin/env bash
# The tests under AddressSanitizer + UndefinedBehaviorSanitizer (gcc), built into ./build-asan
# (or $BUILD_DIR: an existing instrumented tree rebuilds incrementally, far cheaper than a cold one).
# Not part of scripts/test.sh: the instrumented build and the slower tests take about as long as
# the normal build and tests again. Any report fails the run (halt_on_error, no UB recovery).
#   bash scripts/sanitize.sh                 # every test
#   bash scripts/sanitize.sh -R 'ScanPcd'    # extra arguments go to ctest
#   TARGETS="sensors_test pitchlab" bash scripts/sanitize.sh -R 'Pcd|BadInput'   # build only these
#   BUILD_DIR=build-asan2 bash scripts/sanitize.sh                                # another tree
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${BUILD_DIR:-build-asan}
bash scripts/setup.sh
# EIGEN_MALLOC_ALREADY_ALIGNED=1: under ASan Eigen stops trusting glibc's 16-byte aligned malloc
# (Eigen/src/Core/util/Memory.h tests __SANITIZE_ADDRESS__) and offsets its blocks by hand, while
# Debian's unsanitized PCL frees the same blocks with plain free (pcl::RangeImage::cropImage from
# createFromPointCloud, our NARF features): a "bad-free" of the build mix, not of the code. glibc's
# malloc on x86-64 is 16-byte aligned, which is all Eigen asks of it without AVX.
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
flags="$flags -DEIGEN_MALLOC_ALREADY_ALIGNED=1"
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_FLAGS="$flags" -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined"
# shellcheck disable=SC2086  # TARGETS is a list of words
cmake --build "$build_dir" -j"$(nproc)" ${TARGETS:+--target $TARGETS}
# Leaks: a third-party library's process-lifetime state would go in scripts/lsan.supp, each entry
# with why; anything else is ours and fails. The full run (issue 18) needed none.
# Many tests run `pitchlab` as a child and expect it to fail (exit 1 or 2 on bad input): a report
# in such a child, exiting 1 as ASan does by default, would pass for the expected failure. So
# ASan's and LSan's reports go to files in $reports, from every process, and any file there fails
# the run; and both sanitizers exit 86, a code no pitchlab command uses (0, 1, 2, 130, 143).
# GCC's libubsan writes its diagnostics to stderr whatever log_path says (measured with gcc 12),
# so a UB report is caught by its exit code alone.
reports=$PWD/$build_dir/sanitizer-reports
rm -rf "$reports"
mkdir -p "$reports"
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:abort_on_error=0:strict_string_checks=1:exitcode=86:log_path=$reports/asan"
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:exitcode=86"
# The fuzz label is clang's own sanitizer build (tests/hw/fuzz): not this one's business.
status=0
ctest --test-dir "$build_dir" --output-on-failure -j"$(nproc)" -LE fuzz --timeout 1800 "$@" ||
  status=$?
if [ -n "$(ls -A "$reports")" ]; then
  for f in "$reports"/*; do
    echo "sanitize: report of process ${f##*.} ($f):"
    cat "$f"
  done
  echo "sanitize: FAIL: $(ls "$reports" | wc -l) sanitizer report(s) in $reports" >&2
  exit 1
fi
exit "$status"
