#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The README's usage snippets, run as a user would (ctest: readme_snippets): the five command
# lines in a scratch folder, the C snippet compiled as C99 against the shared decoder, the C++
# snippet against the static decoder, the Python snippet with PYTHONPATH=BUILD/python (when the
# build has the module). The C and C++ snippets evaluate the same file at the same directions and
# must print the same RGB; a snippet that no longer compiles or runs fails the check.
#   Usage: tools/scripts/check-readme.sh BUILD_DIR
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?usage: check-readme.sh BUILD_DIR}" && pwd)
readme=$root/README.md
work=$(mktemp -d /tmp/cbrdf-readme.XXXXXX)
trap 'rm -rf "$work"' EXIT
cd "$work"

# The indented block that follows the first line starting with $1.
block() {
  awk -v start="$1" 'index($0, start) == 1 { f = 1; next }
    f && /^    / { print substr($0, 5); got = 1; next }
    f && got { exit }' "$readme"
}
fail() { echo "check-readme: FAILED: $*" >&2; exit 1; }

block "The command (" | sed 's/ *#.*$//' > cli.txt
block "C, the stable ABI" > snippet.c.txt
block "C++ (static" > snippet.cc.txt
block "Python (" > snippet.py
for f in cli.txt snippet.c.txt snippet.cc.txt snippet.py; do
  [[ $(grep -c . "$f") == 5 ]] || fail "README block $f has $(grep -c . "$f") lines, not 5"
done

export PATH=$build:$PATH
while read -r line; do
  echo "check-readme: $line"
  bash -c "$line" > /dev/null || fail "'$line' exited with $?"
done < cli.txt

includes=(-I"$root/format/include" -I"$root/codec/decoder/include" -I"$build/generated/include")
{
  grep '^#include' snippet.c.txt
  printf '#include <stdio.h>\nint main(void) {\n'
  grep -v '^#include' snippet.c.txt
  printf 'printf("%%.17g %%.17g %%.17g\\n", rgb[0], rgb[1], rgb[2]);\nreturn 0;\n}\n'
} > snippet.c
{
  grep '^#include' snippet.cc.txt
  printf '#include <cstdio>\nint main() {\n'
  grep -v '^#include' snippet.cc.txt
  printf 'std::printf("%%.17g %%.17g %%.17g\\n", rgb[0], rgb[1], rgb[2]);\n'
  printf 'return sampler.sample({0, -0.6, 0.8}, 0.5, 0.5).valid ? 0 : 1;\n}\n'
} > snippet.cc
cc -std=c99 -Wall -Wextra -Werror -pedantic "${includes[@]}" snippet.c -o snippet_c \
  -L"$build" -lcbrdf_decoder -Wl,-rpath,"$build" -lm || fail "the C snippet does not compile"
c++ -std=c++20 -Wall -Wextra -Werror "${includes[@]}" snippet.cc -o snippet_cc \
  "$build/libcbrdf_decoder.a" $(pkg-config --libs libzstd libxxhash) -pthread ||
  fail "the C++ snippet does not compile"
c_rgb=$(./snippet_c) || fail "the C snippet exited with $?"
cc_rgb=$(./snippet_cc) || fail "the C++ snippet exited with $?"
echo "check-readme: C: $c_rgb; C++: $cc_rgb"
[[ $c_rgb == "$cc_rgb" ]] || fail "the C and C++ snippets disagree"
awk '{ exit !($1 > 0 && $2 > 0 && $3 > 0) }' <<< "$c_rgb" || fail "the snippets' RGB is not positive"

if [[ -d $build/python/cbrdf ]]; then
  py=$(PYTHONPATH=$build/python /usr/bin/python3 snippet.py) || fail "the Python snippet failed"
  echo "check-readme: Python: $py"
  awk '{ exit !($1 > 0 && $2 > 0) }' <<< "$py" || fail "the Python snippet printed '$py'"
fi
echo "check-readme: the README's command, C, C++ and Python snippets run"
