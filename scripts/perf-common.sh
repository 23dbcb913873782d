# shared by scripts/perf-compare.sh and scripts/perf-ablation.sh (sourced, not run): the
# world list and the statistics of their interleaved rounds.

# world_files: the files of the names or paths in $worlds (default: the four bundled worlds);
# exits 2 naming a world without a file.
perf_resolve_worlds() {
  local repo w f
  repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
  [[ ${#worlds[@]} -gt 0 ]] || worlds=(default house warehouse outdoor)
  world_files=()
  for w in "${worlds[@]}"; do
    if [[ $w == */* || $w == *.yaml ]]; then f=$w; else f=$repo/worlds/$w.yaml; fi
    [[ -f $f ]] || { echo "$0: world '$w': no file $f; expected a bundled world name or a world file" >&2; exit 2; }
    world_files+=("$f")
  done
}

# median, min and max of the numbers given
stats() {
  printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2; printf "%s %s %s\n", m, v[1], v[NR] }'
}
