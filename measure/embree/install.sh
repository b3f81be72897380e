#!/usr/bin/env bash
# Installs what the Embree peer benchmark builds against: Debian's Embree 3
# (libembree-dev) and a C++ compiler. Run as root, or with sudo.
set -euo pipefail
if [[ -f /usr/include/embree3/rtcore.h ]] && command -v g++ >/dev/null; then
    echo "install.sh: Embree 3 and g++ are already installed"
    exit 0
fi
apt-get update -qq
apt-get install -y -qq libembree-dev g++
