#!/usr/bin/env bash
# check_hostile_overlay.sh LDC WORLD DIR [--no-ulimit]: issue 24 finding 2. An 8,000-vertex
# overlay path zig-zagging +-10 km, drawn at 64 x 64, must render under a 2 GB address-space
# limit (it took 3.7 GB and aborted with bad_alloc when every segment was sampled along its whole
# length). --no-ulimit for AddressSanitizer builds, whose shadow memory needs terabytes of
# address space (the sanitizer still catches any overflow; the bound is checked unsanitized).
set -eu
ldc=$1 world=$2 dir=$3 limit=${4:-}
json=$dir/hostile_overlay.json png=$dir/hostile_overlay.png
rm -f "$png"
awk 'BEGIN { printf "{\"path\": ["; for (i = 0; i < 8000; ++i) { s = (i % 2) ? 10000 : -10000;
  printf "%s[%d, %d, %d]", (i ? ", " : ""), s, -s, (i % 4) * 2500 - 3750 } print "]}" }' > "$json"
if [ "$limit" != "--no-ulimit" ]; then ulimit -v 2000000; fi
"$ldc" -q render "$world" -o "$png" --width 64 --height 64 --overlay "$json" > /dev/null
test -s "$png" && echo ok
