#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Fetches Debian's zstd source package (the version of the installed libzstd-dev) into DIR, for the
# WebAssembly build, which compiles its decompressor with emcc (tools/wasm/CMakeLists.txt). Adds a
# deb-src entry for the system's Debian suites when apt has none (needs root or sudo then). zstd's
# sources stay in DIR (a build tree): they are never committed. Prints the unpacked source folder.
#   usage: tools/wasm/fetch-zstd-source.sh DIR
#          tools/wasm/fetch-zstd-source.sh --deb-src-only   (the apt entry alone: tools/scripts/install-deps.sh)
set -euo pipefail

dir=${1:?usage: fetch-zstd-source.sh DIR | --deb-src-only}

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
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)

version=$(dpkg-query -W -f='${Version}' libzstd-dev 2>/dev/null || true)
if [[ -z $version ]]; then
  echo "fetch-zstd-source: libzstd-dev is not installed (tools/scripts/install-deps.sh installs it)" >&2
  exit 1
fi
upstream=${version#*:}
upstream=${upstream%%-*}   # 1.5.4+dfsg2
upstream=${upstream%%+*}   # 1.5.4

unpacked() { find "$dir" -maxdepth 1 -type d -name "libzstd-${upstream}*" | head -n 1; }
existing=$(unpacked)
if [[ -n $existing && -f $existing/lib/zstd.h ]]; then
  echo "$existing"
  exit 0
fi

add_deb_src

# The installed version, so that the wasm decoder decodes as the native library does; where the
# mirror lacks that revision's source (security updates), another Debian revision of the same
# upstream release (Debian's revisions patch the CLI and tests, not the decompressor).
candidates=("$version")
while read -r v; do
  [[ $v != "$version" && $v == *"$upstream"* ]] && candidates+=("$v")
done < <(apt-cache showsrc libzstd 2>/dev/null | sed -n 's/^Version: //p')
for v in "${candidates[@]}"; do
  if (cd "$dir" && apt-get source -qq "libzstd=${v}" >&2); then
    echo "fetch-zstd-source: unpacked libzstd ${v}" >&2
    break
  fi
done
existing=$(unpacked)
if [[ -z $existing || ! -f $existing/lib/zstd.h ]]; then
  echo "fetch-zstd-source: apt-get source libzstd (${candidates[*]}) left no libzstd-${upstream}* in $dir" >&2
  exit 1
fi
echo "$existing"
