#!/usr/bin/env bash
# check_hostile_reads.sh LDC WORLD DIR: issue 24 finding 4, under a 1 GB address-space limit.
# 1. Sparse 2 GiB files of zeros named as every mesh format and as a world are refused from
#    their first block, each with its format's message, in well under a second (they were read
#    whole first: 300 MB took 2 s and 313 MB before "no triangles" or "bad magic").
# 2. `inside` with a million points streams its report under a 400 MB limit (50 MB resident
#    now): the whole JSON document took about 860 bytes a point (4.3 GB for 5 M points).
set -eu
ldc=$1 world=$2 dir=$3
ulimit -v 1000000
expect() {  # expect REGEX COMMAND...: the command fails, its stderr matching REGEX
  local regex=$1 err
  shift
  if err=$("$@" 2>&1 >/dev/null); then echo "unexpected success: $*"; exit 1; fi
  if ! [[ $err =~ $regex ]]; then echo "stderr of '$*': '$err' does not match '$regex'"; exit 1; fi
}
for ext in obj off ply stl glb drc ldc; do
  rm -f "$dir/hostile_zeros.$ext"
  truncate -s 2G "$dir/hostile_zeros.$ext"
done
z=$dir/hostile_zeros
expect "^ldc remesh: parse error: $z\.obj: not a text OBJ file \(a zero byte at offset 0\)$" "$ldc" -q remesh "$z.obj" -o "$dir/hostile_zeros_out.obj"
expect "^ldc build: parse error: $z\.off: not a text OFF file \(a zero byte at offset 0\)$" "$ldc" -q build "$z.off" -o "$dir/hostile_zeros_out.ldc"
expect "^ldc remesh: parse error: $z\.ply:1: not a PLY file \(the first line is not 'ply'\)$" "$ldc" -q remesh "$z.ply" -o "$dir/hostile_zeros_out.obj"
expect "^ldc remesh: parse error: $z\.stl: binary STL header declares 0 triangles, which take 84 bytes, but the file has 2147483648$" "$ldc" -q remesh "$z.stl" -o "$dir/hostile_zeros_out.obj"
expect "^ldc remesh: parse error: $z\.glb: not a binary glTF file \(it does not start with 'glTF'\)$" "$ldc" -q remesh "$z.glb" -o "$dir/hostile_zeros_out.obj"
expect "^ldc remesh: parse error: $z\.drc: not a Draco file \(it does not start with 'DRACO'\)$" "$ldc" -q remesh "$z.drc" -o "$dir/hostile_zeros_out.obj"
expect "^ldc info: corrupt data: $z\.ldc: not an \.ldc file \(bad magic\)$" "$ldc" -q info "$z.ldc"
rm -f "$z".* "$dir/hostile_zeros_out".*
points=$dir/hostile_million_points.txt
awk 'BEGIN { for (i = 0; i < 1000000; ++i) printf "%.3f %.3f %.3f\n", (i % 101) / 50 - 1, (i % 103) / 51 - 1, (i % 107) / 53 - 1 }' > "$points"
tail=$(ulimit -v 400000; "$ldc" -q --threads 1 inside "$world" --points "$points" | tail -c 40)
rm -f "$points"
[[ $tail =~ \],\"total\":1000000\}$ ]] || { echo "inside: the report ends '$tail'"; exit 1; }
echo ok
