#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Fetches Debian's zstd source package (the installed libzstd-dev's version) once into a cache
# folder, where the WebAssembly build's configure finds it (tools/wasm/zstd_source.cmake; the
# configure itself never runs apt or reaches the network). tools/scripts/install-deps.sh wasm runs
# it. Needs a deb-src entry for apt: it adds one for the system's Debian suites when apt has none
# (root or sudo then; --deb-src-only does that alone). apt-get source itself needs no root. zstd's
# sources stay in the cache: they are never committed. Prints the unpacked source folder; prints
# apt's messages only when every candidate failed.
#   usage: tools/wasm/fetch-zstd-source.sh [DIR]   (default: $XDG_CACHE_HOME/cbrdf/zstd-source,
#                                                   i.e. ~/.cache/cbrdf/zstd-source)
#          tools/wasm/fetch-zstd-source.sh --deb-src-only
set -euo pipefail

dir=${1:-${XDG_CACHE_HOME:-$HOME/.cache}/cbrdf/zstd-source}

sudo=""
if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi

# apt-get source needs a deb-src entry; Debian's images ship only deb ones.
add_deb_src() {
  if grep -rqsE '^(deb-src|Types:.*deb-src)' /etc/apt/sources.list /etc/apt/sources.list.d/; then
    return 0
  fi
  local src=/etc/apt/sources.list.d/cbrdf-deb-src.sources
  echo "fetch-zstd-source: adding $src" >&2
  . /etc/os-release
  $sudo tee "$src" >/dev/null <<SRC
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: ${VERSION_CODENAME} ${VERSION_CODENAME}-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb-src
URIs: http://deb.debian.org/debian-security
Suites: ${VERSION_CODENAME}-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
  $sudo apt-get update -qq >&2
}

if [[ $dir == --deb-src-only ]]; then
  add_deb_src
  exit 0
fi

version=$(dpkg-query -W -f='${Version}' libzstd-dev 2>/dev/null || true)
if [[ -z $version ]]; then
  echo "fetch-zstd-source: libzstd-dev is not installed (tools/scripts/install-deps.sh installs it)" >&2
  exit 1
fi
upstream=${version#*:}
upstream=${upstream%%-*}   # 1.5.4+dfsg2
upstream=${upstream%%+*}   # 1.5.4

mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
unpacked() { find "$dir" -maxdepth 1 -type d -name "libzstd-${upstream}*" | head -n 1; }
existing=$(unpacked)
if [[ -n $existing && -f $existing/lib/zstd.h ]]; then
  echo "$existing"
  exit 0
fi

add_deb_src

# The installed version, so that the wasm decoder decodes as the native library does; where the
# mirror lacks that revision's source (security updates), another Debian revision of the same
# upstream release (Debian's revisions patch the CLI and tests, not the decompressor). A failed
# candidate's messages ("E: Failed to fetch ... 404") are kept and shown only if all fail.
candidates=("$version")
while read -r v; do
  [[ $v != "$version" && $v == *"$upstream"* ]] && candidates+=("$v")
done < <(apt-cache showsrc libzstd 2>/dev/null | sed -n 's/^Version: //p')
log=$(mktemp)
trap 'rm -f "$log"' EXIT
for v in "${candidates[@]}"; do
  echo "== apt-get source libzstd=${v}" >>"$log"
  if (cd "$dir" && apt-get source -qq "libzstd=${v}" >>"$log" 2>&1); then
    echo "fetch-zstd-source: unpacked libzstd ${v} into $dir" >&2
    break
  fi
done
existing=$(unpacked)
if [[ -z $existing || ! -f $existing/lib/zstd.h ]]; then
  cat "$log" >&2
  echo "fetch-zstd-source: apt-get source libzstd (${candidates[*]}) left no libzstd-${upstream}* in $dir" >&2
  exit 1
fi
echo "$existing"
