#!/usr/bin/env bash
# Installs what drivegate needs to build, run and test, from Debian 12 packages only. Idempotent:
# packages already present are left alone and apt is not even called then.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config       # toolchain
  clang libclang-rt-dev lld ninja-build  # the test build (scripts/test.sh): clang + sanitizers, lld, Ninja
  libfastrtps-dev libfastcdr-dev fastddsgen  # Fast DDS and its IDL code generator
  libyaml-cpp-dev                        # configuration files
  libtinyxml2-dev                        # EtherCAT ESI files (XML) given for slaves
  libspdlog-dev                          # logging
  googletest libgtest-dev                # unit and integration tests
  libsystemd-dev systemd                 # sd_notify; systemd-analyze verifies the unit in tests
  iproute2                               # network namespaces for tests that need them
  openssl                                # scripts/make-pki.sh (DDS Security certificates)
  python3-can                            # reference peer for the UDP multicast CAN bus (tests)
  cyclonedds-dev cyclonedds-tools        # a second DDS implementation: the interoperability test
  tshark                                 # dissects the EtherCAT frames the codecs write (tests)
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi
if [[ $(id -u) -ne 0 ]]; then
  echo "install-deps: missing packages: ${missing[*]}; run as root (or install them with sudo apt-get install)" >&2
  exit 1
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -q
apt-get install -y -q --no-install-recommends "${missing[@]}"
