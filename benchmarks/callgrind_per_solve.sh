#!/usr/bin/env bash
# Instructions per timed solve of bench_contacts' cases, by callgrind: steadier than wall time on a
# shared machine (the ratios in BENCHMARKS.md's contacts section were checked this way).
#   benchmarks/callgrind_per_solve.sh [bench_contacts binary] [case masks...]
# A mask is BENCH_CONTACTS_CASE's bit mask of the cases to time (1 plain m = 3, 2 plain m = 6,
# 4 frictionless, 8 sticking, 16 sliding, 32 set-points). The state search runs in every run, so
# a run with mask 0 (nothing timed) is subtracted: (instructions in vereshchagin::solve under the
# mask - under 0) / (its calls under the mask - under 0).
set -euo pipefail
bin=${1:-build/bench/benchmarks/bench_contacts}
shift || true
masks=("${@:-2 8}")
out=$(mktemp -d)
count() {  # "instructions calls" of vereshchagin::solve(Model, Data, SolveInput) under mask $1
  BENCH_CONTACTS_CASE=$1 valgrind --tool=callgrind --callgrind-out-file="$out/cg.$1" "$bin" >/dev/null 2>&1
  callgrind_annotate --tree=calling "$out/cg.$1" 2>/dev/null |
    grep -E ">   \?\?\?:vereshchagin::solve\(vereshchagin::Model const&, vereshchagin::Data&, vereshchagin::SolveInput const&\)" |
    sed 's/,//g' | awk '{ir += $1; c = $(NF - 1); gsub(/[(x)]/, "", c); n += c} END {print ir, n}'
}
read -r ir0 n0 < <(count 0)
for m in ${masks[*]}; do
  read -r ir n < <(count "$m")
  echo "mask $m: $(((ir - ir0) / (n - n0))) instructions per solve over $((n - n0)) solves"
done
rm -rf "$out"
