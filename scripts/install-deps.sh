#!/usr/bin/env bash
# Installs every system dependency of ColonFlat from Debian 12 (bookworm) packages.
# The README, .ci/run and docker/Dockerfile all call this one script.
#   scripts/install-deps.sh            build + test + runtime dependencies
#   scripts/install-deps.sh --runtime  only what the installed binary needs (Docker runtime stage)
set -euo pipefail

BUILD_PKGS=(
  build-essential cmake ninja-build pkg-config git ca-certificates
  libvtk9-dev            # reconstruction (flying edges), .vtp/.vtk I/O, off-screen rendering, PNG
  libinsighttoolkit5-dev # volume I/O (DICOM/GDCM, NRRD, NIfTI, MHA), filters
  libeigen3-dev          # sparse linear algebra (flattening)
  libsuitesparse-dev     # CHOLMOD supernodal Cholesky through Eigen (flattening; optional, faster)
  libmetis-dev           # METIS nested dissection order called directly, cheaper options (flattening; optional)
  libopenmesh-dev        # halfedge mesh + OFF/OBJ/PLY/STL I/O
  libgtest-dev libgmock-dev
  libbenchmark-dev
  libboost-graph-dev     # Boykov-Kolmogorov max-flow
  libcli11-dev           # command-line parsing
  nlohmann-json3-dev     # JSON reports
  libcgal-dev            # tests only: independent self-intersection check
  libdcmtk-dev           # DICOM exams and results (modules/dicom); in tests a second reader of the series we write
  dicom3tools            # tests only: dciodvfy checks the DICOM objects we write against their IOD
  orthanc                # tests only: a real PACS (started by the tests on loopback ports they choose)
  python3-pydicom        # tests only: an independent reader of the SEG we write
  python3-numpy          # tests only: pydicom decodes pixel data with NumPy (a Recommends, not installed by --no-install-recommends)
  xvfb xauth             # off-screen rendering where there is no display
  python3                # small test helpers
  snakemake              # cohort processing (workflow/Snakefile) and its ctest test
  chromium               # tests only: headless browser check of report.html
)
# What the installed `colonflat` needs (checked with ldd on the built binary; every other library
# it loads comes with these packages' dependencies). libgl1-mesa-dri: the software OpenGL driver
# that Xvfb-based 3D snapshots use (ldd cannot see it: it is loaded at run time).
RUNTIME_PKGS=(
  libvtk9.1 libinsighttoolkit5.2 libopenmesh1 libcholmod3 libmetis5 libdcmtk17 libgl1-mesa-dri xvfb xauth
)

SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO=sudo; fi
export DEBIAN_FRONTEND=noninteractive

if [ "${1:-}" = "--runtime" ]; then
  PKGS=("${RUNTIME_PKGS[@]}")
else
  PKGS=("${BUILD_PKGS[@]}")
fi

# Skip the network entirely when everything is already installed.
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PKGS[@]} packages already installed"
  exit 0
fi
echo "install-deps: installing ${#missing[@]} packages: ${missing[*]}"
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
