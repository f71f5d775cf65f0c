#!/usr/bin/env bash
# Installs the Debian packages Marionette needs: to build bevy (udev, X11, xkbcommon,
# wayland headers), to render without a GPU (Vulkan on Mesa's llvmpipe, Xvfb), and to drive the
# editor with random input in the monkey test (xdotool).
# Run as root or with sudo available.
set -euo pipefail
packages=(gcc pkg-config libudev-dev libx11-dev libxkbcommon-dev libxkbcommon-x11-0 libwayland-dev
          mesa-vulkan-drivers libvulkan1 xvfb xauth xdotool)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all packages present"
  exit 0
fi
sudo=""
[ "$(id -u)" -ne 0 ] && sudo=sudo
$sudo apt-get update
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y --no-install-recommends "${missing[@]}"
