#!/usr/bin/env bash
# Hostile-input sweep for the `ldc` command-line tool.
#
# Usage: bash bench/hostile_sweep.sh [path/to/ldc] [workdir]
#   path/to/ldc  default: build/tools/ldc (relative to the repository root)
#   workdir      default: a mktemp -d folder, removed at the end (a given one is kept)
#
# Throws a few hundred hostile inputs at ldc (mutated meshes, mutated .ldc worlds,
# hostile option values, hostile JSON/points files, file-system oddities), one run of
# ldc per case, under `timeout 20`, `ulimit -v 4000000` and stdin from /dev/null, and
# prints one markdown table of counts per family, then every case that was not ok.
# Runs are sequential (one ldc at a time). Always exits 0; the last line is "FAILURES: n".
#
# Classification of one case (first match wins):
#   crash   killed by a signal / exit status >= 128 (other than timeout's 124)
#   hang    timeout's exit status 124
#   unclear exit status != 0 and stderr empty, or not starting with "ldc " / "ldc:",
#           or containing "internal error", "std::", "basic_string", "terminate", "what():"
#   silent  expected "fail" but exit 0; expected "succeed" but exit != 0; a failed run
#           that left its -o/--output file behind; an input that had to stay unchanged
#           and changed (CMP_SAME=file)
#   ok      otherwise
set -u

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
LDC=${1:-$ROOT/build/tools/ldc}
case $LDC in /*) ;; *) LDC=$PWD/$LDC ;; esac
if [[ ! -x $LDC ]]; then echo "hostile_sweep: no executable ldc at $LDC" >&2; echo "FAILURES: 0"; exit 0; fi
if [[ $# -ge 2 ]]; then W=$2; mkdir -p "$W"; KEEP=1; else W=$(mktemp -d); KEEP=0; fi
W=$(cd "$W" && pwd)
DATA=$ROOT/tests/data
cleanup() { [[ $KEEP == 1 ]] || rm -rf "$W"; }
trap cleanup EXIT
cd "$W" || exit 0
mkdir -p o
T0=$SECONDS

# ---------------------------------------------------------------- bookkeeping
FAMILIES=()
declare -A N_IN N_CRASH N_HANG N_UNCLEAR N_SILENT
BAD=()          # one line per non-ok case
NO=0            # output-name counter
SKIPPED=0       # cases where ldc itself could not be started (not counted)

add_family() {
  FAMILIES+=("$1"); N_IN[$1]=0; N_CRASH[$1]=0; N_HANG[$1]=0; N_UNCLEAR[$1]=0; N_SILENT[$1]=0
}
# o EXT: a fresh output path (relative to the work folder) in $OUTP
o() { NO=$((NO + 1)); OUTP=o/$NO.$1; }

# Deterministic PRNG (LCG): rnd N sets R to a number in [0, N).
SEED=12345
rnd() { SEED=$(( (SEED * 1103515245 + 12345) & 0x7fffffff )); R=$(( (SEED >> 4) % $1 )); }

# run_case FAMILY EXPECT CMD...   (EXPECT: fail | succeed | either)
# Optional (as a prefix assignment): CMP_SAME=file  -- that file must be unchanged afterwards.
run_case() {
  local fam=$1 expect=$2; shift 2
  local out="" prev="" a cls="" why="" rc
  for a in "$@"; do
    if [[ $prev == -o || $prev == --output ]]; then out=$a; fi
    prev=$a
  done
  local out_existed=1
  if [[ -n $out && ! -e $out ]]; then out_existed=0; fi
  local same=${CMP_SAME:-}
  if [[ -n $same ]]; then cp -p -- "$same" .cmp_copy 2>/dev/null; fi

  local try
  for try in 1 2 3 4 5; do   # 126/127: ldc could not be started (e.g. being relinked by a build): retry
    ( ulimit -v 4000000; exec timeout -k 5 20 "$@" </dev/null >/dev/null 2>.stderr )
    rc=$?
    (( rc == 126 || rc == 127 )) || break
    sleep 2
  done
  if (( rc == 126 || rc == 127 )); then
    SKIPPED=$((SKIPPED + 1)); [[ -n $out && $out_existed == 0 && -f $out ]] && rm -f -- "$out"; return
  fi

  local first
  first=$(head -n 1 .stderr | cut -c1-200 | tr -d '\r')
  if (( rc == 124 )); then cls=hang; why="timed out after 20 s"
  elif (( rc >= 128 )); then cls=crash; why="exit $rc (signal $((rc - 128)))"
  elif (( rc != 0 )) && { [[ ! -s .stderr ]] || ! head -c 4 .stderr | grep -qE '^ldc[ :]' ||
                          grep -qE 'internal error|std::|basic_string|terminate|what\(\):' .stderr; }; then
    cls=unclear; why="exit $rc, unclear message"
  elif [[ $expect == fail ]] && (( rc == 0 )); then cls=silent; why="exit 0, expected a failure"
  elif [[ $expect == succeed ]] && (( rc != 0 )); then cls=silent; why="exit $rc, expected success"
  elif (( rc != 0 )) && [[ $out_existed == 0 && -e $out ]]; then cls=silent; why="exit $rc but left output $out behind"
  elif [[ -n $same ]] && ! cmp -s -- .cmp_copy "$same"; then cls=silent; why="exit $rc and changed $same"
  fi
  # clean up this case's output (never a path that was there before)
  if [[ -n $out && $out_existed == 0 && -f $out ]]; then rm -f -- "$out"; fi
  rm -f o/*.raw 2>/dev/null

  N_IN[$fam]=$(( ${N_IN[$fam]} + 1 ))
  case $cls in
    crash)   N_CRASH[$fam]=$(( ${N_CRASH[$fam]} + 1 )) ;;
    hang)    N_HANG[$fam]=$(( ${N_HANG[$fam]} + 1 )) ;;
    unclear) N_UNCLEAR[$fam]=$(( ${N_UNCLEAR[$fam]} + 1 )) ;;
    silent)  N_SILENT[$fam]=$(( ${N_SILENT[$fam]} + 1 )) ;;
  esac
  if [[ -n $cls ]]; then
    local cmd="" x
    for x in "$@"; do
      if [[ $x == "$LDC" ]]; then cmd+="ldc "
      elif [[ $x =~ ^[-A-Za-z0-9_./,:=+@%]+$ ]]; then cmd+="$x "
      else cmd+="$(printf '%q' "$x") "; fi
    done
    BAD+=("- **$cls** [$fam] \`${cmd% }\` -- $why; stderr: \`${first:-(empty)}\`")
  fi
}

# ---------------------------------------------------------------- small inputs
make_inputs() {
  cp "$DATA/spot.obj" spot.obj
  cp "$DATA/suzanne.obj" suzanne.obj
  printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n' > cube.obj
  printf 'f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n' >> cube.obj
  # PLY / OFF / STL versions of the cube (0-based indices)
  {
    printf 'ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n'
    printf 'element face 12\nproperty list uchar int vertex_indices\nend_header\n'
    awk '/^v /{print $2, $3, $4}' cube.obj
    awk '/^f /{print 3, $2-1, $3-1, $4-1}' cube.obj
  } > cube.ply
  {
    printf 'OFF\n8 12 0\n'
    awk '/^v /{print $2, $3, $4}' cube.obj
    awk '/^f /{print 3, $2-1, $3-1, $4-1}' cube.obj
  } > cube.off
  awk '/^v /{n++; x[n]=$2; y[n]=$3; z[n]=$4}
       /^f /{f[++m]=$2" "$3" "$4}
       END{print "solid cube";
           for(i=1;i<=m;i++){split(f[i],t," ");
             print "facet normal 0 0 0\n outer loop";
             for(k=1;k<=3;k++) print "  vertex", x[t[k]], y[t[k]], z[t[k]];
             print " endloop\nendfacet"}
           print "endsolid cube"}' cube.obj > cube.stl
}

# ---------------------------------------------------------------- family 1: meshes
mesh_case() {  # mesh_case EXPECT FILE: build and remesh one mesh file
  o ldc; run_case meshes "$1" "$LDC" -q build "$2" -o "$OUTP" --cells 16
  o obj; run_case meshes "$1" "$LDC" -q remesh "$2" -o "$OUTP" --cells 16
}

family_meshes() {
  add_family meshes
  mkdir -p m
  local base ext size i k n off b f
  for base in spot.obj suzanne.obj cube.obj cube.ply cube.off cube.stl; do
    ext=${base##*.}; size=$(stat -c %s "$base")
    for i in 1 2; do                        # truncations at random offsets
      rnd "$size"; f=m/trunc$i-$base; head -c "$R" "$base" > "$f"; mesh_case either "$f"
    done
    for i in 1 2; do                        # random byte flips (1..8 bytes)
      f=m/flip$i-$base; cp "$base" "$f"; rnd 8; n=$((R + 1))
      for ((k = 0; k < n; k++)); do
        rnd "$size"; off=$R; rnd 256; b=$R
        printf "\\$(printf %03o "$b")" | dd of="$f" bs=1 seek="$off" conv=notrunc status=none
      done
      mesh_case either "$f"
    done
    f=m/dup-$base; n=$(wc -l < "$base"); rnd "$n"      # a duplicated line
    awk -v n=$((R + 1)) 'NR==n{print} {print}' "$base" > "$f"; mesh_case either "$f"
  done
  # OBJ specials: NaN / inf / huge coordinates and bad indices must fail
  local v c=0
  for v in 'v nan 0 0' 'v -nan 0 0' 'v inf 0 0' 'v 0 -inf 0' 'v 1e400 0 0' 'v 0 0 NaN' 'v 0 0 1e-400x'; do
    c=$((c + 1)); f=m/coord$c.obj; { echo "$v"; cat cube.obj; } > "$f"
    # the extra vertex is the first one: shift the faces so that they use it too
    awk '/^f /{print "f", $2, $3+1, $4+1; next} {print}' "$f" > "$f.tmp" && mv "$f.tmp" "$f"
    mesh_case fail "$f"
  done
  for v in 'f 1 2 999999999' 'f 1 2 -999999999' 'f 0 1 2' 'f 1 2 99999999999999999999' 'f 1 2 x'; do
    c=$((c + 1)); f=m/index$c.obj; { cat cube.obj; echo "$v"; } > "$f"; mesh_case fail "$f"
  done
  f=m/vtindex.obj; { cat cube.obj; echo 'f 1 2 3/999999'; } > "$f"; mesh_case either "$f"   # vt index: not geometry
  f=m/relneg.obj; { grep '^v ' cube.obj; awk '/^f /{print "f", $2-9, $3-9, $4-9}' cube.obj; } > "$f"
  mesh_case succeed "$f"                    # relative (negative) indices are legal OBJ
  f=m/huge1e308.obj; { echo 'v 1e308 0 0'; echo 'v -1e308 0 0'; cat cube.obj; } > "$f"; mesh_case either "$f"
  # other formats: NaN / bad index / lying counts must fail
  sed '0,/^0 0 0$/s//nan 0 0/' cube.ply > m/nan.ply;            mesh_case fail m/nan.ply
  sed '0,/^0 0 0$/s//inf 0 0/' cube.off > m/inf.off;            mesh_case fail m/inf.off
  sed '0,/vertex 0 0 0/s//vertex nan 0 0/' cube.stl > m/nan.stl; mesh_case fail m/nan.stl
  sed 's/^3 0 2 1$/3 0 2 99/' cube.ply > m/index.ply;          mesh_case fail m/index.ply
  sed 's/^3 0 2 1$/3 0 2 -5/' cube.off > m/index.off;          mesh_case fail m/index.off
  sed 's/element vertex 8/element vertex 2000000000/' cube.ply > m/count.ply;  mesh_case fail m/count.ply
  sed 's/element face 12/element face -3/' cube.ply > m/negcount.ply;          mesh_case fail m/negcount.ply
  sed 's/^8 12 0$/8 4000000000 0/' cube.off > m/count.off;                     mesh_case fail m/count.off
  sed 's/^3 0 2 1$/255 0 2 1/' cube.ply > m/listlen.ply;                       mesh_case fail m/listlen.ply
  { head -c 80 /dev/zero; printf '\xff\xff\xff\xff'; head -c 100 /dev/zero; } > m/bincount.stl
  mesh_case fail m/bincount.stl             # binary STL claiming 4e9 triangles
  # degenerate files
  : > m/empty.obj;                                  mesh_case fail m/empty.obj
  printf '\n  \n\t\n' > m/blank.obj;               mesh_case fail m/blank.obj
  printf '# only\n# comments\n' > m/comments.obj;  mesh_case fail m/comments.obj
  head -c 4096 /dev/zero > m/zeros.obj;            mesh_case fail m/zeros.obj
  head -c 4096 /dev/zero > m/zeros.ply;            mesh_case fail m/zeros.ply
  head -c 4096 /dev/zero > m/zeros.stl;            mesh_case fail m/zeros.stl
  : > m/empty.off;                                  mesh_case fail m/empty.off
  printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\n' > m/novface.obj;   mesh_case fail m/novface.obj
  printf 'v 0 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3\n' > m/degen.obj; mesh_case either m/degen.obj
  printf 'v 0 0 0\xff\xfe\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > m/nonutf.obj; mesh_case either m/nonutf.obj
  cp cube.obj m/noext;                              mesh_case either m/noext
  cp cube.obj m/cube.xyz;                           mesh_case fail m/cube.xyz
  cp cube.obj $'m/bad\xff.obj';                     mesh_case either $'m/bad\xff.obj'
  cp cube.obj 'm/sp ace;$(x).obj';                  mesh_case succeed 'm/sp ace;$(x).obj'
}

# ---------------------------------------------------------------- family 2: .ldc worlds
family_worlds() {
  add_family worlds
  mkdir -p w
  "$LDC" -q build --primitive sphere --cells 16 -o base.ldc >/dev/null 2>&1
  local size i k n off b f
  size=$(stat -c %s base.ldc)
  for ((i = 1; i <= 55; i++)); do           # random byte flips, 1..4 bytes
    f=w/flip$i.ldc; cp base.ldc "$f"; rnd 4; n=$((R + 1))
    for ((k = 0; k < n; k++)); do
      rnd "$size"; off=$R; rnd 255; b=$(( (R + 1) ^ $(od -An -tu1 -j "$off" -N1 base.ldc) ))
      printf "\\$(printf %03o "$b")" | dd of="$f" bs=1 seek="$off" conv=notrunc status=none
    done
  done
  for ((i = 1; i <= 10; i++)); do           # flips in the first 64 bytes (header)
    f=w/head$i.ldc; cp base.ldc "$f"; rnd 64; off=$R; rnd 255
    b=$(( (R + 1) ^ $(od -An -tu1 -j "$off" -N1 base.ldc) ))
    printf "\\$(printf %03o "$b")" | dd of="$f" bs=1 seek="$off" conv=notrunc status=none
  done
  for ((i = 1; i <= 30; i++)); do           # truncations
    rnd "$size"; head -c "$R" base.ldc > w/trunc$i.ldc
  done
  : > w/empty.ldc
  head -c "$size" /dev/zero > w/zeros.ldc
  { cat base.ldc; printf 'trailing garbage'; } > w/trailing.ldc
  cat base.ldc base.ldc > w/doubled.ldc
  cp cube.obj w/mesh_as.ldc
  for f in w/*.ldc; do
    run_case worlds either "$LDC" -q info "$f"
    o png; run_case worlds either "$LDC" -q render "$f" -o "$OUTP" --width 16 --height 16
  done
}

# ---------------------------------------------------------------- family 3: options
# values for scalar and vector options; expectation chosen by param_expect
SCALARS=(-1 0 nan inf 1e308 -1e308 99999999999999999999 '' abc)
VECTORS=('nan,0,0' 'inf,0,0' '1e308,1e308,1e308' '-1,-1,-1' '0,0,0' '1,2' '1,2,3,4' '' 'abc' '99999999999999999999,0,0')

# param_expect KIND VALUE -> EXP; KIND: pos (must be > 0), nonneg (>= 0), any, vec3, vec3pos, vec2pos, light
param_expect() {
  local kind=$1 v=$2
  EXP=either
  case $v in *nan*|abc) EXP=fail; return ;; esac
  if [[ $v == *inf* ]]; then [[ $kind == nonneg_inf ]] && return; EXP=fail; return; fi
  [[ $kind == nonneg_inf ]] && kind=nonneg
  case $kind in
    pos)     [[ $v == -* || $v == 0 ]] && EXP=fail ;;
    nonneg)  [[ $v == -* ]] && EXP=fail ;;
    vec3)    [[ $v == 1,2 || $v == 1,2,3,4 ]] && EXP=fail ;;
    vec3pos) [[ $v == 1,2 || $v == 1,2,3,4 || $v == -* || $v == 0,0,0 ]] && EXP=fail ;;
    vec2pos) [[ $v == -* || $v == 0,0,0 || $v == 1,2,3,4 ]] && EXP=fail ;;
    light)   [[ $v == 1,2 || $v == -* ]] && EXP=fail ;;
    vec3nz)  [[ $v == 1,2 || $v == 1,2,3,4 || $v == 0,0,0 ]] && EXP=fail ;;
    dir)     [[ $v == 1,2 || $v == 1,2,3,4 || $v == 0,0,0 ]] && EXP=fail ;;
  esac
}

# sweep "BASE CMD WITH @OUT@" OPTION KIND
sweep() {
  local base=$1 opt=$2 kind=$3 v ext
  local -a vals
  if [[ $kind == vec* || $kind == light ]]; then vals=("${VECTORS[@]}"); else vals=("${SCALARS[@]}"); fi
  for v in "${vals[@]}"; do
    param_expect "$kind" "$v"
    local -a cmd=()
    read -r -a cmd <<< "$base"
    local i
    for i in "${!cmd[@]}"; do
      if [[ ${cmd[$i]} == @OUT.*@ ]]; then ext=${cmd[$i]#@OUT.}; o "${ext%@}"; cmd[$i]=$OUTP; fi
    done
    run_case options "$EXP" "$LDC" -q "${cmd[@]}" "$opt" "$v"
  done
}

family_options() {
  add_family options
  [[ -f base.ldc ]] || "$LDC" -q build --primitive sphere --cells 16 -o base.ldc >/dev/null 2>&1
  local B='build --primitive sphere -o @OUT.ldc@'
  sweep "$B --cells 16" --cell-size nonneg      # 0 = unset (use --cells)
  sweep "$B" --cells pos
  sweep "$B --cells 16" --chunk-size pos
  sweep "$B --cells 16" --radius pos
  sweep 'build --primitive box --cells 16 -o @OUT.ldc@' --half-extents vec3pos
  sweep "$B --cells 16" --scale vec3nz          # negative = mirror
  sweep 'terrain -o @OUT.ldc@ --cell-size 0.5' --size vec2pos
  sweep 'terrain -o @OUT.ldc@ --size 8,8' --cell-size pos
  sweep 'info base.ldc' --threads nonneg
  sweep 'contour base.ldc -o @OUT.obj@' --max-error nonneg
  sweep 'remesh cube.obj -o @OUT.obj@' --cell-size nonneg
  sweep 'boolean cube.obj cube.obj --op subtract --cells 16 -o @OUT.obj@' --translate-b vec3
  sweep 'boolean cube.obj cube.obj --op union --cells 16 -o @OUT.obj@' --scale-b pos
  sweep 'raycast base.ldc --direction 0,0,-1' --origin vec3
  sweep 'raycast base.ldc --origin 0,0,5' --direction dir
  sweep 'raycast base.ldc --origin 0,0,5 --direction 0,0,-1' --max-distance nonneg_inf
  sweep 'render base.ldc -o @OUT.png@ --width 16 --height 16' --camera vec3
  sweep 'render base.ldc -o @OUT.png@ --width 16 --height 16' --fov pos
  sweep 'render base.ldc -o @OUT.png@ --height 16' --width pos
  local G='gi base.ldc -o @OUT.png@ --engine cpu --width 16 --height 16'
  sweep "$G --levels 2" --resolution pos
  sweep "$G --levels 2 --resolution 8" --voxel-size nonneg   # 0 = default (2 h)
  sweep "$G --levels 2 --resolution 8" --light light
  sweep 'path base.ldc --to 0.5,0.5,2' --from vec3
  sweep 'path base.ldc --from 0,0,2 --to 0.5,0.5,2' --agent-radius nonneg
  sweep 'path base.ldc --from 0,0,2 --to 0.5,0.5,2' --max-nodes pos
  sweep 'voxelize base.ldc -o @OUT.json@' --voxel-size pos
  sweep 'voxelize base.ldc -o @OUT.json@ --voxel-size 0.25 --resolution 8' --cascades nonneg
  sweep 'voxelize base.ldc -o @OUT.json@ --voxel-size 0.25 --cascades 2 --resolution 8' --camera vec3
}

# ---------------------------------------------------------------- family 4: JSON / points files
# json_variants NAME VALID_JSON: writes j/NAME.* variants and lists "EXPECT FILE" lines in $VARIANTS
json_variants() {
  local n=$1 valid=$2 d=j/$1
  mkdir -p "$d"
  VARIANTS=()
  printf '%s\n' "$valid" > "$d/valid.json";                           VARIANTS+=("succeed $d/valid.json")
  : > "$d/empty.json";                                                VARIANTS+=("fail $d/empty.json")
  printf '%s' "${valid:0:$(( ${#valid} / 2 ))}" > "$d/trunc.json";    VARIANTS+=("fail $d/trunc.json")
  printf '%s' "${valid%?}" | sed 's/]$/],/' > "$d/nobrace.json";      VARIANTS+=("fail $d/nobrace.json")
  printf '%s\n' "$valid" | sed 's/\([]}]\)$/,\1/' > "$d/trailcomma.json"; VARIANTS+=("fail $d/trailcomma.json")
  printf '%s\n' "$valid" | sed '0,/[0-9][0-9.]*/s//NaN/' > "$d/nan.json";       VARIANTS+=("fail $d/nan.json")
  printf '%s\n' "$valid" | sed '0,/[0-9][0-9.]*/s//Infinity/' > "$d/infinity.json"; VARIANTS+=("fail $d/infinity.json")
  printf '%s\n' "$valid" | sed '0,/[0-9][0-9.]*/s//1e400/' > "$d/e400.json";    VARIANTS+=("fail $d/e400.json")
  printf '%s\n' "$valid" | sed '0,/[0-9][0-9.]*/s//-1e308/' > "$d/e308.json";   VARIANTS+=("either $d/e308.json")
  printf '%s\n' "$valid" | sed '0,/[0-9][0-9.]*/s//99999999999999999999999999999/' > "$d/bigint.json"; VARIANTS+=("either $d/bigint.json")
  printf '%s\n' "$valid" | sed '0,/[0-9][0-9.]*/s//"1"/' > "$d/wrongtype.json"; VARIANTS+=("fail $d/wrongtype.json")
  printf '%s\n' "$valid" | sed '0,/{/s//{"bogus_field": 1, /' > "$d/unknown.json"; VARIANTS+=("fail $d/unknown.json")
  printf '%s\n' "$valid" | sed '0,/"/s//"\xff\xfe/' > "$d/nonutf8.json";  VARIANTS+=("fail $d/nonutf8.json")
  { printf '%s' "$valid"; printf '\0\0\0'; } > "$d/nul.json";           VARIANTS+=("fail $d/nul.json")
  { printf '%s' "$valid"; printf ' xyz'; } > "$d/garbage.json";         VARIANTS+=("fail $d/garbage.json")
  { printf '\xef\xbb\xbf'; printf '%s' "$valid"; } > "$d/bom.json";      VARIANTS+=("either $d/bom.json")
  printf '%s' "$valid" | sed '0,/{/s//{"z":/;s/$/}/' > "$d/wrapped.json"; VARIANTS+=("fail $d/wrapped.json")
  printf '[%.0s' {1..10000} > "$d/deep_open.json";                      VARIANTS+=("fail $d/deep_open.json")
  { printf '[%.0s' {1..10000}; printf ']%.0s' {1..10000}; } > "$d/deep.json"; VARIANTS+=("fail $d/deep.json")
  { printf '{"a":%.0s' {1..10000}; printf '1'; printf '}%.0s' {1..10000}; } > "$d/deep_obj.json"; VARIANTS+=("fail $d/deep_obj.json")
  printf '"just a string"' > "$d/string.json";                           VARIANTS+=("fail $d/string.json")
  printf 'null' > "$d/null.json";                                        VARIANTS+=("fail $d/null.json")
  head -c 2000 "$DATA/spot.obj" > "$d/notjson.json";                     VARIANTS+=("fail $d/notjson.json")
}

family_json() {
  add_family json
  [[ -f base.ldc ]] || "$LDC" -q build --primitive sphere --cells 16 -o base.ldc >/dev/null 2>&1
  local line exp f
  json_variants edit '{"edits": [{"op": "subtract", "brush": "sphere", "centre": [0.5, 0, 0], "radius": 0.5}]}'
  for line in "${VARIANTS[@]}"; do exp=${line%% *}; f=${line#* }
    o ldc; run_case json "$exp" "$LDC" -q edit base.ldc --script "$f" -o "$OUTP"; done
  json_variants rays '[{"origin": [0.1, 0, 5], "direction": [0, 0, -1]}, {"origin": [0, 0, 5], "direction": [0, 0, -1], "max_distance": 2}]'
  for line in "${VARIANTS[@]}"; do exp=${line%% *}; f=${line#* }
    run_case json "$exp" "$LDC" -q raycast base.ldc --rays "$f"; done
  json_variants overlay '{"path": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "points": [[0, 0, 1]]}'
  # An overlay may carry other fields: it is often `ldc path`'s whole report (documented).
  VARIANTS=("${VARIANTS[@]/#fail j\/overlay\/unknown.json/either j/overlay/unknown.json}")
  for line in "${VARIANTS[@]}"; do exp=${line%% *}; f=${line#* }
    o png; run_case json "$exp" "$LDC" -q render base.ldc -o "$OUTP" --width 16 --height 16 --overlay "$f"; done
  json_variants filter '{"include_flags": 65535, "materials": {"0": {"cost": 2}}, "exclude_flags": 0}'
  for line in "${VARIANTS[@]}"; do exp=${line%% *}; f=${line#* }
    run_case json "$exp" "$LDC" -q path base.ldc --from 0,0,2 --to 0.5,0.5,2 --filter "$f"; done
  json_variants links '{"links": [{"a": [0.5, 0, 1], "b": [0, 0.5, 1], "radius": 1}]}'
  for line in "${VARIANTS[@]}"; do exp=${line%% *}; f=${line#* }
    run_case json "$exp" "$LDC" -q path base.ldc --from 0,0,2 --to 0.5,0.5,2 --links "$f"; done

  # edit-script specifics
  mkdir -p j/e
  local s
  local -a specs=(
    'fail|{"edits": [{"op": "subtract", "brush": "sphere", "centre": [0,0,0], "radius": -1}]}'
    'fail|{"edits": [{"op": "subtract", "brush": "sphere", "centre": [0,0,0], "radius": 1e400}]}'
    'either|{"edits": [{"op": "subtract", "brush": "sphere", "centre": [0,0,0], "radius": 1e308}]}'
    'either|{"edits": [{"op": "subtract", "brush": "sphere", "centre": [0,0,0], "radius": 1e-320}]}'
    'fail|{"edits": [{"op": "explode", "brush": "sphere", "centre": [0,0,0], "radius": 1}]}'
    'fail|{"edits": [{"op": "subtract", "brush": "tesseract", "centre": [0,0,0], "radius": 1}]}'
    'fail|{"edits": [{"op": "subtract", "brush": "sphere", "centre": [0,0], "radius": 1}]}'
    'fail|{"edits": [{"op": "subtract", "brush": "sphere", "centre": 0, "radius": 1}]}'
    'fail|{"edits": [{"op": "paint", "brush": "sphere", "centre": [0,0,0], "radius": 1, "material": -1}]}'
    'fail|{"edits": [{"op": "paint", "brush": "sphere", "centre": [0,0,0], "radius": 1, "material": 70000}]}'
    'either|{"edits": [{"op": "paint", "brush": "sphere", "centre": [0,0,0], "radius": 1, "material": 1.5}]}'
    'fail|{"edits": [{"op": "union", "brush": "box", "centre": [0,0,0], "half_extents": [1,-1,1]}]}'
    'fail|{"edits": [{"op": "union", "brush": "box", "centre": [0,0,0], "half_extents": [1,1,1], "rotate_deg": 30, "axis": [0,0,0]}]}'
    'fail|{"edits": [{"op": "union", "brush": "capsule", "a": [0,0,0], "b": [0,0,1], "radius": NaN}]}'
    'either|{"edits": [{"op": "union", "brush": "cylinder", "a": [0,0,0], "b": [0,0,0], "radius": 1}]}'
    'either|{"edits": [{"op": "subtract", "brush": "noise", "centre": [0,0,0], "radius": 1, "frequency": 1e308, "amplitude": 1e308}]}'
    'fail|{"edits": [{"op": "add", "brush": "mesh", "mesh": "missing.obj"}]}'
    'fail|{"edits": [{"op": "add", "brush": "mesh", "mesh": "/dev/zero"}]}'
    'fail|{"edits": [{"op": "add", "brush": "mesh", "mesh": "s.json"}]}'
    'fail|{"edits": [{"op": "add", "brush": "mesh", "mesh": "../../../m/coord1.obj"}]}'
    'either|{"edits": [{"op": "add", "brush": "mesh", "mesh": "../../../cube.obj", "scale": 1e30}]}'
    'fail|{"edits": [{"op": "add", "brush": "mesh", "mesh": "../../../cube.obj", "scale": 0}]}'
    'either|{"edits": []}'
    'fail|{"edits": {}}'
    'fail|{"edits": [1, 2, 3]}'
    'fail|{}'
    'either|{"edits": [{"op": "subtract", "brush": "sphere", "centre": [0,0,0], "radius": 0.5, "radius": 0.7}]}'
    'fail|{"edits": [{"op": "subtract", "brush": "sphere", "centre": [0,0,0], "radius": "0.5"}]}'
  )
  local i=0
  for s in "${specs[@]}"; do
    i=$((i + 1)); mkdir -p "j/e/$i"; printf '%s\n' "${s#*|}" > "j/e/$i/s.json"
    o ldc; run_case json "${s%%|*}" "$LDC" -q edit base.ldc --script "j/e/$i/s.json" -o "$OUTP"
  done

  # inside --points (text, one "x y z" per line)
  mkdir -p j/p
  printf '0 0 0\n5, 5, 5\n' > j/p/valid.txt;      run_case json succeed "$LDC" -q inside base.ldc --points j/p/valid.txt
  : > j/p/empty.txt;                               run_case json either "$LDC" -q inside base.ldc --points j/p/empty.txt
  local p
  for p in 'nan 0 0' '0 inf 0' '1e400 0 0' '1 2' '1 2 3 4' 'abc def ghi' $'0 0 0\xff' $'0 0\x000' '0x10 0 0'; do
    i=$((i + 1)); printf '%s\n' "$p" > "j/p/$i.txt"
    run_case json fail "$LDC" -q inside base.ldc --points "j/p/$i.txt"
  done
  awk 'BEGIN{for(i=0;i<200000;i++) print i%7*0.1, i%5*0.1, i%3*0.1}' > j/p/many.txt
  run_case json succeed "$LDC" -q inside base.ldc --points j/p/many.txt
  head -c 3000000 /dev/zero | tr '\0' '1' > j/p/longline.txt
  run_case json fail "$LDC" -q inside base.ldc --points j/p/longline.txt
}

# ---------------------------------------------------------------- family 5: file system
family_files() {
  add_family files
  [[ -f base.ldc ]] || "$LDC" -q build --primitive sphere --cells 16 -o base.ldc >/dev/null 2>&1
  mkdir -p fs/dir fs/dir.obj fs/dir.ldc
  cp cube.obj fs/F.obj; cp cube.obj fs/A.obj; cp base.ldc fs/W.ldc
  printf '{"edits": [{"op": "subtract", "brush": "sphere", "centre": [0,0,0], "radius": 0.5}]}\n' > fs/s.json
  run_case files fail "$LDC" -q build cube.obj -o fs/missing/sub/out.ldc --cells 16
  run_case files fail "$LDC" -q remesh cube.obj -o fs/missing/out.obj --cells 16
  run_case files fail "$LDC" -q build cube.obj -o fs/dir --cells 16
  run_case files fail "$LDC" -q build cube.obj -o fs/dir.ldc --cells 16
  run_case files fail "$LDC" -q render base.ldc -o fs/dir --width 16 --height 16
  run_case files fail "$LDC" -q build cube.obj -o fs/out.ldc/ --cells 16
  CMP_SAME=fs/F.obj run_case files fail "$LDC" -q build fs/F.obj -o fs/F.obj --cells 16
  CMP_SAME=fs/F.obj run_case files fail "$LDC" -q remesh fs/F.obj -o fs/F.obj --cells 16
  CMP_SAME=fs/F.obj run_case files fail "$LDC" -q remesh fs/F.obj -o fs/../fs/F.obj --cells 16
  CMP_SAME=fs/A.obj run_case files fail "$LDC" -q boolean cube.obj fs/A.obj --op union -o fs/A.obj --cells 16
  ln -sf F.obj fs/link.obj
  CMP_SAME=fs/F.obj run_case files fail "$LDC" -q remesh fs/F.obj -o fs/link.obj --cells 16
  CMP_SAME=fs/s.json run_case files fail "$LDC" -q edit base.ldc --script fs/s.json -o fs/s.json
  run_case files fail "$LDC" -q build fs/dir.obj -o fs/o1.ldc --cells 16
  run_case files fail "$LDC" -q remesh fs/dir.obj -o fs/o2.obj --cells 16
  run_case files fail "$LDC" -q info fs/dir.ldc
  run_case files fail "$LDC" -q edit base.ldc --script fs/dir -o fs/o3.ldc
  mkfifo fs/fifo.obj fs/fifo.ldc fs/fifo.json
  run_case files fail "$LDC" -q build fs/fifo.obj -o fs/o4.ldc --cells 16
  run_case files fail "$LDC" -q info fs/fifo.ldc
  run_case files fail "$LDC" -q render fs/fifo.ldc -o fs/o10.png --width 16 --height 16
  run_case files fail "$LDC" -q edit base.ldc --script fs/fifo.json -o fs/o5.ldc
  run_case files fail "$LDC" -q build /dev/zero -o fs/o6.ldc --cells 16
  run_case files fail "$LDC" -q info /dev/zero
  run_case files fail "$LDC" -q edit base.ldc --script /dev/zero -o fs/o7.ldc
  run_case files fail "$LDC" -q raycast base.ldc --rays /dev/zero
  run_case files fail "$LDC" -q render base.ldc -o fs/o8.png --width 16 --height 16 --overlay /dev/zero
  run_case files fail "$LDC" -q path base.ldc --from 0,0,2 --to 0.5,0.5,2 --filter /dev/zero
  run_case files fail "$LDC" -q inside base.ldc --points /dev/zero
  run_case files fail "$LDC" -q info /dev/null
  run_case files fail "$LDC" -q build fs/nonexistent.obj -o fs/o9.ldc --cells 16
  run_case files fail "$LDC" -q build cube.obj -o /dev/full --cells 16
  run_case files fail "$LDC" -q remesh cube.obj -o /dev/full --cells 16
  run_case files fail "$LDC" -q render base.ldc -o /dev/full --width 16 --height 16
  run_case files fail "$LDC" -q build cube.obj -o '' --cells 16
  run_case files fail "$LDC" -q info ''
}

# ---------------------------------------------------------------- main
make_inputs
family_meshes
family_worlds
family_options
family_json
family_files

ELAPSED=$((SECONDS - T0))
echo "## ldc hostile-input sweep ($(date -u +%Y-%m-%d), $ELAPSED s)"
echo
echo "| family | inputs | crashes | hangs | unclear messages | silent wrong outputs |"
echo "|---|---:|---:|---:|---:|---:|"
t_in=0; t_c=0; t_h=0; t_u=0; t_s=0
for f in "${FAMILIES[@]}"; do
  echo "| $f | ${N_IN[$f]} | ${N_CRASH[$f]} | ${N_HANG[$f]} | ${N_UNCLEAR[$f]} | ${N_SILENT[$f]} |"
  t_in=$((t_in + N_IN[$f])); t_c=$((t_c + N_CRASH[$f])); t_h=$((t_h + N_HANG[$f]))
  t_u=$((t_u + N_UNCLEAR[$f])); t_s=$((t_s + N_SILENT[$f]))
done
echo "| **total** | $t_in | $t_c | $t_h | $t_u | $t_s |"
echo
if (( ${#BAD[@]} > 0 )); then
  echo "### Non-ok cases (commands run in the work folder)"
  echo
  printf '%s\n' "${BAD[@]}"
  echo
fi
(( SKIPPED > 0 )) && echo "(skipped $SKIPPED cases: ldc could not be started, exit 126/127)"
echo "FAILURES: ${#BAD[@]}"
exit 0
