#!/usr/bin/env bash
# Installs what libblend needs to build and test on Debian 12. Idempotent:
# packages already present are skipped, so a second run does not touch apt.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config clang-format
  clang libclang-rt-14-dev   # libFuzzer and sanitizer runtimes for clang
  libcmocka-dev              # unit-test framework used by tests/
  libcjson-dev               # JSON parser for scene files
  python3-jsonschema         # tests: scene files against docs/libblend-scene.schema.json
  python3-numpy              # tests: independent mesh readers and checks (tests/mesh/)
  python3-skimage            # tests: marching cubes on the same grid, the mesher's reference
  povray                     # tests: the generated POV-Ray include, run by POV-Ray itself
  openimageio-tools          # tests: idiff compares POV-Ray renders with libblend silhouettes
  blender                    # tests: the add-on in headless Blender (blender_addon_c/)
  libopenimageio-dev         # blendtool's image writer (tools/imageio, C++): PNG, EXR, contact sheets
  libxxhash-dev              # content hashes of batch tasks (resume manifests), compiled in from the header
  zlib1g-dev                 # blendtool: the CRCs of PNG chunks when POV-Ray writes the final PNG
  fonts-dejavu-core          # the contact sheets' labels
  slurm-wlm munge            # tests: batch jobs on a single-node Slurm cluster (scripts/slurm-cluster.sh)
  parallel                   # tests: batch task lists through GNU parallel
  time                       # tests: GNU time measures blendtool's peak memory (input limits)
  valgrind                   # bench: instruction counts (callgrind) beside the timings (run_features_bench.sh)
  libmeshoptimizer-dev       # bench: meshoptimizer's collapses, the floor of any collapse simplifier (run_simplify_bench.sh)
  gcc-mingw-w64-x86-64       # the Windows DLL, cross-compiled (cmake/mingw-w64-x86_64.cmake)
  wine64                     # tests: the Windows build's test programs (scripts/wine-run.sh)
  libopenvdb-dev             # blendtool vdb: narrow-band level sets written by OpenVDB (tools/vdb, C++)
  python3-openvdb            # tests: the written .vdb files read back by OpenVDB's own binding
)


missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  SUDO=sudo
fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
