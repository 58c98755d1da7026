#!/usr/bin/env bash
# Installs the system libraries the PySide6 (Qt 6) wheels need, on Debian/Ubuntu, and only those
# that are missing: nothing happens when they are all there. Called by `make install-test`, so
# the editor's tests (Qt's offscreen platform) pass on a bare machine.
#
#   scripts/install-qt-deps.sh            # what Qt needs to run (tests, offscreen)
#   scripts/install-qt-deps.sh --desktop  # also the X11/xcb libraries of a real window
#   scripts/install-qt-deps.sh --check    # only report what is missing (exit 1 if anything)
set -euo pipefail

mode=install
desktop=0
for arg in "$@"; do
  case "$arg" in
    --desktop) desktop=1 ;;
    --check) mode=check ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) echo "install-qt-deps: unknown option $arg" >&2; exit 2 ;;
  esac
done

# shared library -> Debian package (a|b: the first package name the archive knows)
needed=(
  "libGL.so.1 libgl1"
  "libEGL.so.1 libegl1"
  "libxkbcommon.so.0 libxkbcommon0"
  "libfontconfig.so.1 libfontconfig1"
  "libfreetype.so.6 libfreetype6"
  "libdbus-1.so.3 libdbus-1-3"
  "libglib-2.0.so.0 libglib2.0-0t64|libglib2.0-0"
  "libgthread-2.0.so.0 libglib2.0-0t64|libglib2.0-0"
  "libX11.so.6 libx11-6"
  "libX11-xcb.so.1 libx11-xcb1"
  "libxcb.so.1 libxcb1"
)
if [ "$desktop" = 1 ]; then
  needed+=(
    "libxcb-cursor.so.0 libxcb-cursor0"
    "libxcb-icccm.so.4 libxcb-icccm4"
    "libxcb-keysyms.so.1 libxcb-keysyms1"
    "libxcb-image.so.0 libxcb-image0"
    "libxcb-randr.so.0 libxcb-randr0"
    "libxcb-render-util.so.0 libxcb-render-util0"
    "libxcb-shape.so.0 libxcb-shape0"
    "libxcb-xkb.so.1 libxcb-xkb1"
    "libxkbcommon-x11.so.0 libxkbcommon-x11-0"
  )
fi

if [ "$(uname -s)" != Linux ]; then
  exit 0  # macOS and Windows wheels bring what they need
fi

cache=$(ldconfig -p 2>/dev/null || /sbin/ldconfig -p 2>/dev/null || true)
missing=()
for entry in "${needed[@]}"; do
  lib=${entry%% *}
  pkgs=${entry#* }
  if ! grep -q "[[:space:]]$lib " <<<"$cache"; then
    missing+=("$lib:$pkgs")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "install-qt-deps: missing for Qt: $(printf '%s ' "${missing[@]%%:*}")"
if [ "$mode" = check ]; then
  exit 1
fi
if ! command -v apt-get >/dev/null 2>&1; then
  echo "install-qt-deps: not a Debian/Ubuntu system; install those libraries yourself" >&2
  exit 0
fi
sudo=""
if [ "$(id -u)" != 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    sudo="sudo"
  else
    echo "install-qt-deps: run as root to install them" >&2
    exit 1
  fi
fi

export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
packages=()
for item in "${missing[@]}"; do
  IFS='|' read -r -a choices <<<"${item#*:}"
  chosen=""
  for p in "${choices[@]}"; do
    if apt-cache show "$p" >/dev/null 2>&1; then chosen=$p; break; fi
  done
  if [ -z "$chosen" ]; then
    echo "install-qt-deps: no package found for ${item%%:*}" >&2
    exit 1
  fi
  case " ${packages[*]-} " in *" $chosen "*) ;; *) packages+=("$chosen") ;; esac
done
echo "install-qt-deps: apt-get install ${packages[*]}"
$sudo apt-get install -y -qq --no-install-recommends "${packages[@]}"
