#!/usr/bin/env bash
# runs the libFuzzer targets of fuzz/ (docs/fuzzing.md): configures a separate clang build with
# AddressSanitizer + UndefinedBehaviorSanitizer (-DPENUMBRA_FUZZ=ON), builds the targets, runs
# each for SECONDS with its seed corpus, and prints a table target / runs / crashes.
#
#   bench/fuzz/run.sh [--seconds S] [--targets "runlog tum ..."] [--build DIR] [--jobs N]
#                     [--parallel]
#
# defaults: 1800 s per target, every target, build folder build-fuzz, 2 build jobs. targets run
# one at a time under `nice -n 19` on one core; --parallel runs them side by side (each gets its
# S seconds of wall time, sharing the cores). new inputs go to DIR/corpus/<target> (the seed
# corpus in fuzz/corpus/ is read, never written); crashes, leaks, timeouts and out-of-memory
# inputs go to DIR/findings/<target>/ and make the script exit 1. each target's libFuzzer log
# is DIR/logs/<target>.log. needs clang and libclang-rt-14-dev (scripts/install-deps.sh).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
seconds=1800
targets="runlog world tum request viewer_messages rollout onnx policy template ros2_sample"
build="$root/build-fuzz"
targets_given=0
jobs=2
parallel=0
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --targets) targets="$2"; targets_given=1; shift 2 ;;
    --build) build="$(realpath -m "$2")"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --parallel) parallel=1; shift ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "run.sh: unknown argument '$1'; expected --seconds, --targets, --build, --jobs or --parallel" >&2
       exit 2 ;;
  esac
done
case "$seconds" in
  ''|*[!0-9]*) echo "run.sh: --seconds '$seconds' is not a whole number of seconds" >&2; exit 2 ;;
esac
for t in $targets; do
  if [ ! -f "$root/fuzz/${t}_fuzz.cc" ]; then
    echo "run.sh: no target '$t' (fuzz/${t}_fuzz.cc); expected one of runlog world tum request viewer_messages rollout onnx policy template ros2_sample" >&2
    exit 2
  fi
done
command -v clang++ >/dev/null || { echo "run.sh: clang++ not found; run scripts/install-deps.sh" >&2; exit 2; }

mkdir -p "$build"
# the clang build: asserts stay on (-O1 -g without -DNDEBUG), no tests or micro-benchmarks
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja \
  -DPENUMBRA_FUZZ=ON -DPENUMBRA_BUILD_TESTS=OFF -DPENUMBRA_BUILD_BENCH=OFF \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g" >"$build/configure.log" 2>&1 \
  || { cat "$build/configure.log" >&2; exit 1; }
# ros2_sample exists only in a build with ROS 2 (cmake/ros2.cmake: Cyclone DDS, idlc, the venv's
# rosbags): left out of the default list without it, an error when asked for by name
if ! ninja -C "$build" -t targets all | grep '^fuzz_ros2_sample:' >/dev/null; then
  if [ "$targets_given" = 1 ] && [[ " $targets " == *" ros2_sample "* ]]; then
    echo "run.sh: ros2_sample needs ROS 2 in the fuzz build; see $build/configure.log" >&2
    exit 2
  fi
  targets="$(echo $targets | sed 's/\bros2_sample\b//')"
fi
bins=()
for t in $targets; do bins+=("fuzz_$t"); done
nice -n 19 cmake --build "$build" -j "$jobs" --target "${bins[@]}"

mkdir -p "$build/logs"
# ASan's leak check stays on; UBSan reports are fatal (-fno-sanitize-recover at compile time)
# malloc_context_size=0: on an out-of-memory input libFuzzer prints ASan's heap profile, which
# took many minutes with allocation stacks kept (and left the finding unwritten meanwhile)
export ASAN_OPTIONS="${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1:malloc_context_size=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
declare -A runs crashes
failed=0
# one target for $seconds: its libFuzzer exit status goes to logs/<target>.rc
fuzz_one() {
  local t="$1" work="$build/corpus/$1" findings="$build/findings/$1"
  mkdir -p "$work" "$findings"
  echo "== $t: ${seconds} s" >&2
  # -rss_limit_mb: an input that makes a parser take 2 GB (or malloc that much at once) is a
  # finding; -timeout: one input running 30 s is a finding (a hang)
  nice -n 19 "$build/fuzz/fuzz_$t" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=30 \
    -print_final_stats=1 -artifact_prefix="$findings/" "$work" "$root/fuzz/corpus/$t" \
    >"$build/logs/$t.log" 2>&1
  echo $? >"$build/logs/$t.rc"
}
set +e
if [ "$parallel" = 1 ]; then
  for t in $targets; do fuzz_one "$t" & done
  wait
else
  for t in $targets; do fuzz_one "$t"; done
fi
set -e
for t in $targets; do
  findings="$build/findings/$t"
  rc=$(cat "$build/logs/$t.rc")
  # (a run killed from outside leaves no final stats: runs "?")
  runs[$t]=$( { grep -o 'stat::number_of_executed_units: *[0-9]*' "$build/logs/$t.log" || true; } |
             grep -o '[0-9]*$' | tail -1 || true)
  crashes[$t]=$(find "$findings" -maxdepth 1 -type f \
                  \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) |
                wc -l)
  if [ "$rc" -ne 0 ] || [ "${crashes[$t]}" -ne 0 ]; then
    failed=1
    echo "   $t: libFuzzer exit $rc; see $build/logs/$t.log and $findings/" >&2
  fi
done

printf '%-16s %14s %8s\n' target runs crashes
for t in $targets; do
  printf '%-16s %14s %8s\n' "$t" "${runs[$t]:-?}" "${crashes[$t]}"
done
exit $failed
