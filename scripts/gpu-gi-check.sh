# GI on a GPU: the GI tests, `bench_gi 0 0 timing` and the main job's `ldc gi`
# with both engines, from .gpu/bundle.tgz (scripts/gpu-bundle.sh), on a machine
# with an NVIDIA driver (its Vulkan ICD under /usr/local/nvidia) and the
# libvulkan1/libglvnd .deb files in .gl/. Outputs go to $OUT.
# GPU_GI_IMAGES=PATHS also runs issue 25's whole-image benchmark
# (`bench_gi 0 PATHS images`, both engines against the path tracer) last.
set -u
cd "$(dirname "$0")/.."
OUT=${OUT:-out/gpu}; mkdir -p "$OUT"
[ -d /usr/local/nvidia ] && [ -d .gl ] && { for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; }
# bench_gi reads its meshes from the absolute source path it was built with.
mkdir -p /work; [ -e /work/main ] || ln -s "$PWD" /work/main
B=/tmp/b; mkdir -p $B && tar xzf .gpu/bundle.tgz -C $B
export LD_LIBRARY_PATH=$B/lib
strings $(ldconfig -p | awk '/libstdc\+\+.so.6 /{print $NF; exit}') 2>/dev/null | grep -q GLIBCXX_3.4.30 || export LD_LIBRARY_PATH=$B/lib:$B/fallback
ICD=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
[ -f $ICD ] && export VK_DRIVER_FILES=$ICD VK_ICD_FILENAMES=$ICD __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
nvidia-smi -L; nproc; cat /etc/os-release | head -1; ls /usr/local/nvidia/share/vulkan/icd.d/ /usr/share/vulkan/icd.d 2>&1
echo "== gi tests"; timeout 150 $B/bin/ldc_gi_tests 2>&1 | tee $OUT/gi_tests.txt | grep -E "OK|FAIL|SKIP|PASSED|vulkan|device" | head -40
echo "== bench_gi timing"; timeout 200 $B/bin/bench_gi 0 0 timing 2>&1 | tee $OUT/bench_gi_timing.txt
echo "== main job gi"; mkdir -p out
$B/bin/ldc terrain -o out/default.ldc >/dev/null && $B/bin/ldc edit out/default.ldc --script scripts/default-tunnel.json -o out/tunnel.ldc >/dev/null
for e in vulkan cpu; do timeout 60 $B/bin/ldc gi out/tunnel.ldc -o $OUT/tunnel-gi-$e.png --camera 61,-5,10 --target 45,11,3.4 --fov 55 --width 480 --height 270 --engine $e --passes 8 2>&1 | tee -a $OUT/ldc_gi.txt; done
if [ -n "${GPU_GI_IMAGES:-}" ]; then
  echo "== bench_gi images ($GPU_GI_IMAGES paths per pixel)"
  timeout 300 $B/bin/bench_gi 0 "$GPU_GI_IMAGES" images 2>&1 | tee $OUT/bench_gi_images.txt
fi
