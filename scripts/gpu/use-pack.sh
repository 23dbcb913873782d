# sourced by the scripts that run a pack on the GPU machine (ab.sh, speed.sh, overhead.sh,
# run-breakdown.sh):
#
#   use_pack PKG [DIR...]
#   unpack_pack PACK [BASELINE]
#
# makes the unpacked pack PKG usable: its libraries come first on LD_LIBRARY_PATH (the libraries
# its executables' libraries load), and its worlds appear at the source folder its executables
# were built in (PKG/source-dir.txt, where they look for worlds/*.yaml) and in every further DIR
# (e.g. a baseline executable built elsewhere), as links to PKG/src/worlds where none exist.
use_pack() {
  local pkg=$1 d
  shift
  export LD_LIBRARY_PATH=$pkg/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
  for d in "$(cat "$pkg/source-dir.txt")" "$@"; do
    [ -e "$d/worlds" ] || { mkdir -p "$d" && ln -sfn "$pkg/src/worlds" "$d/worlds"; }
  done
}

# unpack_pack PACK [BASELINE]: unpacks scripts/gpu/pack.sh's tarball PACK into a new temporary
# folder and makes it usable (use_pack, with /work/main as a further folder); with BASELINE (an
# xz-compressed render_cuda_bench of another commit) also puts that at $B/base_bench. sets work
# (the temporary folder), pkg (the unpacked pack), B (its bin folder) and W (its worlds).
unpack_pack() {
  work=$(mktemp -d)
  tar -C "$work" -xJf "$1"
  pkg=$work/penumbra-gpu
  B=$pkg/bin
  W=$pkg/src/worlds
  use_pack "$pkg" /work/main
  if [ -n "${2:-}" ]; then xz -dc "$2" > "$B/base_bench" && chmod +x "$B/base_bench"; fi
}

# step NAME LIMIT_S CMD...: runs CMD with its output in $STEP_LOGS/NAME.txt under a time limit
# of LIMIT_S, cut to what is left of STEP_BUDGET_S seconds since STEP_T0 (date +%s); once fewer
# than STEP_MIN_LEFT_S seconds are left it starts nothing. prints "== NAME rc=RC N ms" (or
# "== NAME skipped (time)"). the caller sets the four STEP_ variables.
step() {
  local name=$1 limit=$2
  shift 2
  local left=$((STEP_BUDGET_S - ($(date +%s) - STEP_T0)))
  if [ "$left" -lt "$STEP_MIN_LEFT_S" ]; then echo "== $name skipped (time)"; return; fi
  [ "$limit" -gt "$left" ] && limit=$left
  local t0 rc
  t0=$(date +%s%N)
  timeout "$limit" "$@" > "$STEP_LOGS/$name.txt" 2>&1
  rc=$?
  echo "== $name rc=$rc $((($(date +%s%N) - t0) / 1000000)) ms"
}
