#!/usr/bin/env bash
# Installs the Debian packages ldc needs to build, test and benchmark.
# Safe to run repeatedly; uses sudo when not root.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  # core
  libtbb-dev libglm-dev libzstd-dev libstb-dev
  # CGAL: exact predicates, mesh repair and test references
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev
  # contour: mesh output and export
  libopenmesh-dev libdraco-dev libtinygltf-dev libmeshoptimizer-dev
  # tool
  libcli11-dev nlohmann-json3-dev
  # tests, fuzzing, benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev
  # OpenVDB: the .vdb export (voxelize_vdb, built with the tool and tests); peers in the
  # benchmarks: Embree (also the ray-cast agreement tests and the GI path tracer), Recast/Detour
  libopenvdb-dev libboost-iostreams-dev libembree-dev librecast-dev
  # gi_bridge (issue 8): Vulkan loader and headers, Mesa's lavapipe (CPU Vulkan), glslc
  libvulkan-dev mesa-vulkan-drivers glslc
  # outside checks of written files: draco_decoder (node and npm below, for gltf-validator)
  draco
)

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ "${#missing[@]}" -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
else
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# node and npm: Debian's, unless the machine has its own (a NodeSource nodejs
# bundles npm and conflicts with Debian's npm package).
if ! command -v npm >/dev/null 2>&1; then
  echo "install-deps: installing nodejs npm"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends nodejs npm
fi

# npm tools the tests check outputs with (versions pinned in tests/js/package-lock.json).
js_dir="$(cd "$(dirname "$0")/.." && pwd)/tests/js"
if [ ! -d "$js_dir/node_modules/gltf-validator" ] || [ ! -d "$js_dir/node_modules/kubernetes-models" ]; then
  echo "install-deps: npm ci in tests/js (gltf-validator, kubernetes-models, js-yaml)"
  (cd "$js_dir" && npm ci --no-audit --no-fund --silent)
fi
