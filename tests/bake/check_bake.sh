#!/usr/bin/env bash
# Tool tests of `ldc bake` (issue 23). Usage: check_bake.sh LDC WORKDIR CASE
#   identity  a one-process bake (0/1) and a 3-shard bake + merge give the
#             same index.json and the same bytes in every product file
#   rerun     a finished shard is skipped on a re-run; a killed (partial) one is redone
#   faults    merge refuses: a corrupted file (naming it), a missing shard,
#             shards of another world; no index is written
#   lods      --lods 2 adds mesh/lod1/ (every 2nd ray): the 2-shard bake equals
#             the one-process one, and level 1 takes under half the bytes;
#             --mesh-format drc writes Draco files
# Exits non-zero, naming what failed.
set -u
LDC=$1; WORK=$2; CASE=$3
WORLD=(--terrain-size 64,64 --cell-size 0.5 --chunk-size 16)
die() { echo "FAIL: $*" >&2; exit 1; }
rm -rf "$WORK"; mkdir -p "$WORK"
bake() { "$LDC" -q bake "${WORLD[@]}" "$@"; }
# Compares two merged bakes: index.json and every file it lists, byte for byte.
same_bake() {
  cmp "$1/index.json" "$2/index.json" || die "index.json differs between $1 and $2"
  local n=0
  while read -r f; do
    cmp "$1/$f" "$2/$f" || die "$f differs between $1 and $2"
    n=$((n + 1))
  done < <(grep -o '"name": *"[^"]*"' "$1/index.json" | sed 's/.*"\([^"]*\)"$/\1/')
  [ "$n" -gt 0 ] || die "index.json of $1 lists no files"
  # no file beside the index that the other bake lacks
  diff -r --exclude=shards "$1" "$2" >/dev/null || die "the merged folders $1 and $2 differ"
  echo "same bake: index.json and $n files byte-identical"
}
case $CASE in
identity)
  bake --out "$WORK/one" --shard 0/1 >/dev/null || die "bake 0/1"
  "$LDC" -q bake --merge "$WORK/one" >/dev/null || die "merge of 0/1"
  for i in 0 1 2; do bake --out "$WORK/three" --shard $i/3 >/dev/null || die "bake $i/3"; done
  "$LDC" -q bake --merge "$WORK/three" || die "merge of 3 shards"
  same_bake "$WORK/one" "$WORK/three"
  grep -q '"mesh/' "$WORK/one/index.json" || die "no mesh files"
  grep -q '"nav/' "$WORK/one/index.json" || die "no nav files"
  grep -q '"voxels/' "$WORK/one/index.json" || die "no voxel files"
  # the check must be able to fail: flip one byte of one merged file
  f=$(ls "$WORK/three/mesh" | head -1)
  cp --remove-destination "$WORK/three/mesh/$f" "$WORK/three/mesh/$f.tmp" && mv "$WORK/three/mesh/$f.tmp" "$WORK/three/mesh/$f"
  printf '\x01' | dd of="$WORK/three/mesh/$f" bs=1 seek=100 conv=notrunc 2>/dev/null
  (same_bake "$WORK/one" "$WORK/three" 2>/dev/null) && die "same_bake did not notice a changed byte"
  echo "identity ok"
  ;;
lods)
  bake --out "$WORK/one" --shard 0/1 --lods 2 >/dev/null || die "bake 0/1 --lods 2"
  "$LDC" -q bake --merge "$WORK/one" >/dev/null || die "merge of 0/1"
  for i in 0 1; do bake --out "$WORK/two" --shard $i/2 --lods 2 >/dev/null || die "bake $i/2 --lods 2"; done
  "$LDC" -q bake --merge "$WORK/two" >/dev/null || die "merge of 2 shards"
  same_bake "$WORK/one" "$WORK/two"
  n1=$(ls "$WORK/one/mesh/lod1" | wc -l)
  [ "$n1" -gt 0 ] || die "no level-1 meshes"
  s0=$(cat "$WORK"/one/mesh/*.glb | wc -c); s1=$(cat "$WORK"/one/mesh/lod1/*.glb | wc -c)
  [ $((2 * s1)) -lt "$s0" ] || die "level-1 meshes take $s1 bytes, level 0 $s0"
  # a bake of other levels in the same folder is refused
  err=$(bake --out "$WORK/one" --shard 0/1 2>&1 >/dev/null) && die "a 1-level bake over a 2-level one was accepted"
  [[ $err == *"holds a bake of 2 mesh levels, not 1"* ]] || die "unexpected refusal: $err"
  # --mesh-format drc: Draco files at both levels; a .glb bake over them is refused
  bake --out "$WORK/drc" --shard 0/1 --lods 2 --mesh-format drc >/dev/null || die "bake --mesh-format drc"
  nd=$(ls "$WORK"/drc/shards/0/mesh/*.drc "$WORK"/drc/shards/0/mesh/lod1/*.drc | wc -l)
  [ "$nd" -gt 0 ] && [ -z "$(ls "$WORK"/drc/shards/0/mesh/*.glb 2>/dev/null)" ] || die "no .drc meshes (or .glb ones)"
  err=$(bake --out "$WORK/drc" --shard 0/1 --lods 2 2>&1 >/dev/null) && die "a .glb bake over a .drc one was accepted"
  [[ $err == *"holds a bake of .drc meshes, not .glb"* ]] || die "unexpected refusal: $err"
  echo "lods ok: $n1 level-1 meshes, $s1 of $s0 bytes; $nd .drc meshes"
  ;;
rerun)
  bake --out "$WORK/b" --shard 1/2 >/dev/null || die "bake 1/2"
  out=$(bake --out "$WORK/b" --shard 1/2) || die "re-run of 1/2"
  echo "$out"
  [[ $out == "shard 1/2 already baked ("*"files checked"*"); skipped" ]] || die "re-run not skipped: $out"
  # a killed shard: files written, no manifest; and one file truncated
  bake --out "$WORK/b" --shard 0/2 >/dev/null || die "bake 0/2"
  cp -r "$WORK/b/shards/0" "$WORK/good0"
  rm "$WORK/b/shards/0/manifest.json"
  f=$(ls "$WORK/b/shards/0/mesh" | head -1); : > "$WORK/b/shards/0/mesh/$f"
  out=$(bake --out "$WORK/b" --shard 0/2) || die "re-run of the partial shard 0/2"
  [[ $out == "baked shard 0/2:"* ]] || die "partial shard not redone: $out"
  diff -r "$WORK/good0" "$WORK/b/shards/0" || die "redone shard differs"
  # a manifest that no longer checks out is redone too (with a warning)
  printf 'x' >> "$WORK/b/shards/0/mesh/$f"
  err=$(bake --out "$WORK/b" --shard 0/2 2>&1 >/dev/null) || die "re-run after corruption"
  [[ $err == *"re-baking shard 0: "*"checksum mismatch"* ]] || die "no re-bake warning: $err"
  diff -r "$WORK/good0" "$WORK/b/shards/0" || die "re-baked shard differs"
  "$LDC" -q bake --merge "$WORK/b" >/dev/null || die "merge after re-runs"
  echo "rerun ok"
  ;;
faults)
  for i in 0 1 2; do bake --out "$WORK/c" --shard $i/3 >/dev/null || die "bake $i/3"; done
  # corrupted file
  f=$(ls "$WORK/c/shards/1/voxels" | head -1)
  printf '\x07' | dd of="$WORK/c/shards/1/voxels/$f" bs=1 seek=3 conv=notrunc 2>/dev/null
  err=$("$LDC" -q bake --merge "$WORK/c" 2>&1) && die "merge accepted a corrupted file"
  [[ $err == *"shards/1/voxels/$f: checksum mismatch"* ]] || die "corruption message: $err"
  [ -e "$WORK/c/index.json" ] && die "index written despite a corrupted file"
  echo "corrupted: $err"
  # missing shard
  rm -rf "$WORK/c/shards/1"
  err=$("$LDC" -q bake --merge "$WORK/c" 2>&1) && die "merge accepted a missing shard"
  [[ $err == *"shard 1/3 is missing"* ]] || die "missing-shard message: $err"
  [ -e "$WORK/c/index.json" ] && die "index written despite a missing shard"
  echo "missing: $err"
  # unfinished shard (no manifest)
  bake --out "$WORK/c" --shard 1/3 >/dev/null || die "bake 1/3"
  rm "$WORK/c/shards/2/manifest.json"
  err=$("$LDC" -q bake --merge "$WORK/c" 2>&1) && die "merge accepted an unfinished shard"
  [[ $err == *"shard 2 is not finished"* ]] || die "unfinished message: $err"
  echo "unfinished: $err"
  bake --out "$WORK/c" --shard 2/3 >/dev/null || die "bake 2/3"
  # a shard folder out of range
  mkdir -p "$WORK/c/shards/5" && cp "$WORK/c/shards/2/manifest.json" "$WORK/c/shards/5/"
  err=$("$LDC" -q bake --merge "$WORK/c" 2>&1) && die "merge accepted shard 5 of 3"
  [[ $err == *"says shard 2, but lies in folder 5"* || $err == *"out of range"* ]] || die "out-of-range message: $err"
  echo "out of range: $err"
  rm -rf "$WORK/c/shards/5"
  # another world's shards in the output folder
  err=$("$LDC" -q bake --terrain-size 64,72 --cell-size 0.5 --chunk-size 16 --out "$WORK/c" --shard 0/3 2>&1) && die "bake into another world's folder accepted"
  [[ $err == *"holds another world's bake"* ]] || die "other-world message: $err"
  echo "other world: $err"
  # another world's shard mixed in at merge
  "$LDC" -q bake --terrain-size 64,72 --cell-size 0.5 --chunk-size 16 --out "$WORK/d" --shard 1/3 >/dev/null || die "bake of world 2"
  rm -rf "$WORK/c/shards/1" && cp -r "$WORK/d/shards/1" "$WORK/c/shards/1"
  err=$("$LDC" -q bake --merge "$WORK/c" 2>&1) && die "merge accepted a shard of another world"
  [[ $err == *"shard of another world"* ]] || die "merge other-world message: $err"
  [ -e "$WORK/c/index.json" ] && die "index written despite another world's shard"
  echo "merge other world: $err"
  echo "faults ok"
  ;;
*) die "unknown case $CASE" ;;
esac
