# sourced by the scripts that run a pack on the GPU machine (ab.sh, speed.sh, run-breakdown.sh):
#
#   use_pack PKG [DIR...]
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
