#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The Python package as a user installs it (ctest: python_wheel). `python3 -m build --no-isolation
# --wheel` packages BUILD_DIR's module (CBRDF_CMAKE_BUILD_DIR: nothing is compiled twice); the wheel
# goes into a fresh `python3 -m venv --system-site-packages` with no package index; tests/python
# then runs against the installed package, with no PYTHONPATH and outside the source tree. Fails
# when the wheel lacks a file or the metadata is wrong, when the module needs an installed
# libcbrdf, or when `cbrdf` is imported from anywhere but the venv.
#   Usage: tools/python/test-wheel.sh BUILD_DIR CBRDF_CLI [PYTHON]   (PYTHON: /usr/bin/python3)
set -euo pipefail
usage="usage: test-wheel.sh BUILD_DIR CBRDF_CLI [PYTHON]"
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?$usage}" && pwd)
cli=${2:?$usage}
python=${3:-/usr/bin/python3}
fail() { echo "test-wheel: FAILED: $*" >&2; exit 1; }

# Only the venv may provide cbrdf: no PYTHONPATH (ctest's python_tests sets one to the build tree),
# no user site, no index.
unset PYTHONPATH PYTHONHOME PYTHONSTARTUP PYTHONUSERBASE
export PYTHONNOUSERSITE=1 PIP_NO_INDEX=1 PIP_DISABLE_PIP_VERSION_CHECK=1
# Scratch space in the build tree (a run that ctest kills on timeout leaves nothing elsewhere),
# without `build/` or `cbrdf/`, so that `-m build` and `import cbrdf` find the installed ones.
work=$build/python-wheel-test
rm -rf "$work"
mkdir "$work"
trap 'rm -rf "$work"' EXIT
cd "$work"

for module in build venv ensurepip; do
  "$python" -c "import $module" 2> /dev/null ||
    fail "$python has no '$module' module: install Debian's python3-build and python3-venv" \
      "(tools/scripts/install-deps.sh)"
done
version=$(sed -n 's/^project(cbrdf VERSION \([0-9.]*\).*/\1/p' "$root/CMakeLists.txt")
[[ -n $version ]] || fail "no project(cbrdf VERSION ...) in CMakeLists.txt"
had_scratch=$([[ -e $root/build-python ]] && echo 1 || echo 0)

start=$SECONDS
echo "test-wheel: CBRDF_CMAKE_BUILD_DIR=$build $python -m build --no-isolation --wheel"
CBRDF_CMAKE_BUILD_DIR=$build "$python" -m build --no-isolation --wheel --outdir "$work/dist" \
  "$root" > "$work/build.log" 2>&1 || { cat "$work/build.log"; fail "python3 -m build failed"; }
echo "test-wheel: built in $((SECONDS - start)) s"
wheels=("$work"/dist/*.whl)
[[ ${#wheels[@]} == 1 && -f ${wheels[0]} ]] || fail "dist/ holds ${wheels[*]}, not one wheel"
wheel=${wheels[0]}
echo "test-wheel: $(basename "$wheel")"
# With CBRDF_CMAKE_BUILD_DIR, setuptools' scratch files go into that tree, not the source tree.
if ((!had_scratch)) && [[ -e $root/build-python ]]; then
  fail "the build wrote $root/build-python"
fi
compgen -G "$root/*.egg-info" > /dev/null && fail "the build wrote $(compgen -G "$root/*.egg-info")"

# The wheel's files and metadata.
"$python" - "$wheel" "$version" << 'EOF' || fail "the wheel's contents are wrong (above)"
import sys, sysconfig, zipfile
wheel, version = sys.argv[1], sys.argv[2]
names = set(zipfile.ZipFile(wheel).namelist())
info = f"cbrdf-{version}.dist-info"
want = ["cbrdf/__init__.py", "cbrdf/__init__.pyi", "cbrdf/py.typed",
        "cbrdf/_cbrdf" + sysconfig.get_config_var("EXT_SUFFIX"),
        f"{info}/METADATA", f"{info}/LICENSE", f"{info}/LICENSE-nbrdf.txt"]
missing = [n for n in want if n not in names]
meta = zipfile.ZipFile(wheel).read(f"{info}/METADATA").decode() if f"{info}/METADATA" in names else ""
fields = [line for line in meta.splitlines() if ": " in line]
for line in ["Name: cbrdf", f"Version: {version}", "License: MIT", "Requires-Dist: numpy (>=1.20)"]:
    if line not in fields:
        missing.append(f"METADATA line '{line}'")
if missing:
    sys.exit(f"missing from the wheel: {missing}; it holds {sorted(names)}")
EOF

"$python" -m venv --system-site-packages "$work/venv"
venv_python=$work/venv/bin/python
# Its dependency (numpy) must come from the system site: PIP_NO_INDEX is set.
"$venv_python" -m pip install -q "$wheel" || fail "pip could not install the wheel into a venv"
module=$("$venv_python" -c 'import cbrdf._cbrdf as m; print(m.__file__)') ||
  fail "the installed cbrdf does not import"
if readelf -d "$module" | grep -q 'NEEDED.*libcbrdf'; then
  fail "$module needs a shared libcbrdf: $(readelf -d "$module" | grep NEEDED | tr -s ' ')"
fi

echo "test-wheel: tests/python against $module"
CBRDF_VENV=$work/venv CBRDF_BUILD_DIR=$build CBRDF_CLI=$cli MPLBACKEND=Agg \
  "$venv_python" - "$root/tests/python" << 'EOF' || fail "tests/python failed against the wheel"
import importlib.metadata
import os
import sys

import cbrdf  # before pytest: the conftest's fallback to the build tree can never be taken

venv = os.path.realpath(os.environ["CBRDF_VENV"]) + os.sep
for f in (cbrdf.__file__, cbrdf._cbrdf.__file__):
    if not os.path.realpath(f).startswith(venv):
        sys.exit(f"cbrdf was imported from {f}, not from the venv {venv}")
if importlib.metadata.version("cbrdf") != cbrdf.__version__:
    sys.exit(f"the wheel's version {importlib.metadata.version('cbrdf')} is not the "
             f"library's {cbrdf.__version__}")
import pytest

sys.exit(pytest.main(["-q", "-p", "no:cacheprovider", sys.argv[1]]))
EOF
echo "test-wheel: the wheel installs into a fresh venv and passes tests/python" \
  "($((SECONDS - start)) s)"
