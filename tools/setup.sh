#!/usr/bin/env bash
# Installs the Debian 12 packages biotcontact needs (as root, idempotent) and
# builds the solver into build/. Usage: tools/setup.sh
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  g++ cmake make pkg-config openmpi-bin
  libdolfinx-dev python3-dolfinx python3-ffcx python3-basix python3-ufl
  libtomlplusplus-dev libmuparser-dev libgtest-dev
  gmsh python3-gmsh libgmsh-dev
  python3-numpy python3-h5py python3-matplotlib python3-meshio python3-scipy
  libopenblas0-serial
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# MUMPS, CHOLMOD and UMFPACK spend their factorisations in dgemm and dtrsm:
# OpenBLAS (serial: the ranks are the parallelism) instead of the reference
# BLAS, chosen here whatever the alternatives held (docs/performance.md).
# FFCx tabulates the forms' basis functions with it too: tables made under
# another BLAS (the build's generated forms, the prototype's JIT cache)
# differ in the last digit, and the two tracks would differ by 1e-12.
arch=$(gcc -print-multiarch)
blas_before=$(readlink -f "/etc/alternatives/libblas.so.3-$arch" || true)
for lib in libblas.so.3 liblapack.so.3; do
  update-alternatives --set "$lib-$arch" "/usr/lib/$arch/openblas-serial/$lib" >/dev/null
done
if [ "$blas_before" != "$(readlink -f "/etc/alternatives/libblas.so.3-$arch")" ]; then
  rm -rf build/biot_*.[ch] "${XDG_CACHE_HOME:-$HOME/.cache}/fenics"
fi

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
if ! cmake --build build -j2 > build/build.log 2>&1; then
  tail -40 build/build.log >&2
  echo "setup: build failed, full log in build/build.log" >&2
  exit 1
fi
echo "setup: built build/biotcontact"
