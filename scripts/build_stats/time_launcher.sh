#!/usr/bin/env bash
# compiler / linker launcher that records the CPU time of each step of a build:
#   cmake -DCMAKE_CXX_COMPILER_LAUNCHER="<this>;<log>" -DCMAKE_CXX_LINKER_LAUNCHER="<this>;<log>"
# appends "<user+sys CPU s> <wall s> <output>" to <log> (the file after -o, or "link" steps by
# their output too); scripts/build_stats/build_cpu.py sums the log per target.
set -u
log=$1
shift
out=?
prev=
for a in "$@"; do
  if [ "$prev" = "-o" ]; then out=$a; fi
  prev=$a
done
tmp=$(mktemp)
/usr/bin/time -f "%U %S %e" -o "$tmp" "$@"
rc=$?
read -r u s e < <(tail -n 1 "$tmp") || true
rm -f "$tmp"
if [ -n "${u:-}" ]; then
  echo "$(echo "$u + $s" | bc) $e $out" >> "$log"
fi
exit $rc
