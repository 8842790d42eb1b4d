#!/usr/bin/env bash
# Installs every build and run dependency of flocsim from Debian packages.
# Idempotent: packages already present are left alone; apt is only asked
# when something is missing. Runs as root (CI, containers) or through sudo.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libeigen3-dev libsqlite3-dev sqlite3 libhdf5-dev hdf5-tools
  nlohmann-json3-dev libgtest-dev libgmock-dev libcli11-dev
  gnuplot-nox
  python3-jsonschema
)
# Slurm, the orchestrator's backend for sweeps that outgrow one machine; the
# tests start a private single-node Slurm from these packages. Skip them with
# FLOCSIM_WITH_SLURM=0 (the Slurm tests then skip with a message).
if [[ "${FLOCSIM_WITH_SLURM:-1}" == 1 ]]; then
  packages+=(slurmctld slurmd slurm-client munge)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
