# SPDX-License-Identifier: MIT
"""Builds the `cbrdf` Python package with CMake, for pip and `python3 -m build` (pyproject.toml).

    pip install --no-build-isolation .          # Debian's python3 (or a venv made from it)
    python3 -m build --no-isolation --wheel     # dist/cbrdf-<version>-cp3XX-...-linux_x86_64.whl

The extension `cbrdf._cbrdf` is the CMake target `_cbrdf` (tools/python/CMakeLists.txt), built in
Release with the cbrdf libraries linked statically into it; the pure-Python files and type stubs
come from tools/python/cbrdf. A fresh build goes to build-python/cmake and is reused by the next
install. Environment:
  CBRDF_CMAKE_BUILD_DIR       an existing CMake build tree configured with -DCBRDF_PYTHON=ON for
                              this Python (relative: to this folder, where pip runs setup.py):
                              its module is brought up to date and packaged, and nothing else is
                              compiled (ctest python_wheel packages its release build this way)
  CMAKE_BUILD_PARALLEL_LEVEL  parallel compile jobs (CMake's own variable)
  CMAKE_GENERATOR             as for cmake (default: Ninja when `ninja` is on PATH)
  CMAKE_ARGS                  extra arguments for a fresh configure, e.g. "-DCBRDF_WERROR=ON"
"""
import importlib.util
import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
# The package's source folder and the CMake target of its extension: the only paths here.
PACKAGE_DIR = "tools/python/cbrdf"
EXTENSION_TARGET = "_cbrdf"
CMAKE_MINIMUM = (3, 20)  # CMakeLists.txt's cmake_minimum_required


def fail(message: str) -> None:
    """Stops the build with one actionable line (pip shows it under the hook's output)."""
    sys.exit(f"cbrdf: {message}")


def check_wheel_package() -> None:
    # Without it setuptools only says "invalid command 'bdist_wheel'"; it is missing when a Python
    # other than Debian's (pyenv, conda) builds with --no-build-isolation.
    if importlib.util.find_spec("wheel") is None:
        fail(f"{sys.executable} (Python {sys.version.split()[0]}) has no `wheel` package: build "
             "with Debian's /usr/bin/python3 (python3-wheel) or a venv made from it with "
             "--system-site-packages (docs/python.md)")


def project_version() -> str:
    text = (ROOT / "CMakeLists.txt").read_text(encoding="utf-8")
    m = re.search(r"project\(\s*cbrdf\s+VERSION\s+([0-9]+\.[0-9]+\.[0-9]+)", text)
    if not m:
        fail("CMakeLists.txt has no `project(cbrdf VERSION x.y.z ...)`: cannot tell the version")
    return m.group(1)


def reused_build_dir():
    value = os.environ.get("CBRDF_CMAKE_BUILD_DIR")
    return Path(value).resolve() if value else None


def check_cmake() -> str:
    cmake = shutil.which("cmake")
    if cmake is None:
        fail("`cmake` is not on PATH: install CMake >= 3.20 (Debian: apt install cmake ninja-build, "
             "or run tools/scripts/install-deps.sh)")
    out = subprocess.run([cmake, "--version"], capture_output=True, text=True).stdout
    m = re.search(r"version ([0-9]+)\.([0-9]+)", out)
    if not m or (int(m.group(1)), int(m.group(2))) < CMAKE_MINIMUM:
        fail(f"{cmake} is too old ({out.splitlines()[0] if out else 'no version'}); "
             "cbrdf needs CMake >= 3.20")
    return cmake


def check_python_headers() -> None:
    include = Path(sysconfig.get_paths()["include"])
    if not (include / "Python.h").exists():
        fail(f"{sys.executable} (Python {sys.version.split()[0]}) has no C headers "
             f"({include}/Python.h): install its development package (Debian: python3-dev), "
             "or build with Debian's /usr/bin/python3")


def pybind11_cmake_args() -> list:
    """pybind11's CMake package: the Python package's copy when this Python has one, else CMake
    looks for Debian's pybind11-dev itself (tools/python/CMakeLists.txt says what is missing)."""
    try:
        import pybind11
    except ImportError:
        return []
    cmake_dir = Path(pybind11.get_cmake_dir())
    return [f"-Dpybind11_DIR={cmake_dir}"] if cmake_dir.is_dir() else []


def cmake_cache(build_dir: Path) -> dict:
    entries = {}
    for line in (build_dir / "CMakeCache.txt").read_text(encoding="utf-8").splitlines():
        m = re.match(r"([A-Za-z_0-9]+):[A-Z]+=(.*)$", line)
        if m:
            entries[m.group(1)] = m.group(2)
    return entries


def run(cmd: list) -> None:
    print("cbrdf:", " ".join(shlex.quote(str(c)) for c in cmd), flush=True)
    if subprocess.run([str(c) for c in cmd]).returncode != 0:
        fail(f"`{' '.join(str(c) for c in cmd[:2])} ...` failed (its messages are above)")


class CMakeExtension(Extension):
    def __init__(self, name: str, target: str):
        super().__init__(name, sources=[])
        self.target = target


class BuildWithCMake(build_ext):
    """Builds each CMakeExtension's target with CMake and copies the module where setuptools
    packs it."""

    def build_extension(self, ext):
        if not isinstance(ext, CMakeExtension):
            return super().build_extension(ext)
        cmake = check_cmake()
        build_dir = reused_build_dir()
        if build_dir is not None:
            self.check_reused(build_dir)
        else:
            check_python_headers()
            build_dir = Path(self.build_temp).resolve() / "cmake"
            self.configure(cmake, build_dir)
        if importlib.util.find_spec("numpy") is None:  # needed at run time only: say so now
            print(f"cbrdf: warning: {sys.executable} has no numpy, which `import cbrdf` needs "
                  "(Debian: python3-numpy; a venv: --system-site-packages)", file=sys.stderr)
        run([cmake, "--build", build_dir, "--target", ext.target])
        self.copy_module(cmake, build_dir, ext)

    def configure(self, cmake: str, build_dir: Path) -> None:
        args = [cmake, "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
                "-DCBRDF_PYTHON=ON", "-DCBRDF_TESTS=OFF", "-DCBRDF_BENCH=OFF",
                "-DCBRDF_FUZZ=OFF", "-DCBRDF_SHARED=OFF", f"-DPython3_EXECUTABLE={sys.executable}"]
        if not (build_dir / "CMakeCache.txt").exists() and "CMAKE_GENERATOR" not in os.environ \
                and shutil.which("ninja"):
            args += ["-G", "Ninja"]
        args += pybind11_cmake_args() + shlex.split(os.environ.get("CMAKE_ARGS", ""))
        run(args)

    @staticmethod
    def check_reused(build_dir: Path) -> None:
        if not (build_dir / "CMakeCache.txt").exists():
            fail(f"CBRDF_CMAKE_BUILD_DIR={build_dir} is not a configured CMake build tree "
                 "(no CMakeCache.txt); configure it with -DCBRDF_PYTHON=ON, or unset the variable")
        cache = cmake_cache(build_dir)
        if cache.get("CBRDF_PYTHON", "OFF").upper() not in ("ON", "TRUE", "1", "YES"):
            fail(f"CBRDF_CMAKE_BUILD_DIR={build_dir} was configured without the Python module: "
                 f"run `cmake {build_dir} -DCBRDF_PYTHON=ON`, or unset the variable")
        if cache.get("CMAKE_BUILD_TYPE") != "Release":
            print(f"cbrdf: warning: CBRDF_CMAKE_BUILD_DIR={build_dir} is a "
                  f"'{cache.get('CMAKE_BUILD_TYPE', '')}' build, not Release", file=sys.stderr)

    def copy_module(self, cmake: str, build_dir: Path, ext: CMakeExtension) -> None:
        # `cmake --install` of the python component says where the module is, whatever the tree's
        # layout, and strips it (the C API's objects carry debug information); the staging
        # folder is thrown away.
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        with tempfile.TemporaryDirectory(prefix="cbrdf-stage-") as stage:
            run([cmake, "--install", build_dir, "--component", "python", "--prefix", stage,
                 "--strip"])
            built = sorted(Path(stage).rglob(f"{ext.target}.*so"))
            if not built:
                fail(f"{build_dir}'s python install has no {ext.target} module")
            wanted = [p for p in built if p.name == ext.target + suffix]
            if not wanted:
                fail(f"{build_dir} builds {built[0].name}, a module for another Python than "
                     f"{sys.executable} (which loads {ext.target}{suffix}): reconfigure it with "
                     f"-DPython3_EXECUTABLE={sys.executable}, or build with the Python it was "
                     f"configured for ({cmake_cache(build_dir).get('Python3_EXECUTABLE', '?')})")
            target = Path(self.get_ext_fullpath(ext.name))
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(wanted[0], target)


class BuildPyAfresh(build_py):
    """Copies the package afresh: a file deleted from the package's folder must not live on in
    the reused scratch folder, and from there in the wheel."""

    def run(self):
        shutil.rmtree(Path(self.build_lib) / "cbrdf", ignore_errors=True)
        super().run()


def build_base() -> str:
    """setuptools' scratch folder: inside the reused CMake tree, else build-python/ (ignored by
    git), never the CMake build folder `build/` a developer has."""
    reused = reused_build_dir()
    base = reused / "python-package" if reused else ROOT / "build-python"
    base.mkdir(parents=True, exist_ok=True)
    return str(base)


check_wheel_package()
base = build_base()
setup(
    version=project_version(),
    packages=["cbrdf"],
    package_dir={"cbrdf": PACKAGE_DIR},
    package_data={"cbrdf": ["__init__.pyi", "py.typed"]},
    ext_modules=[CMakeExtension("cbrdf._cbrdf", EXTENSION_TARGET)],
    cmdclass={"build_py": BuildPyAfresh, "build_ext": BuildWithCMake},
    options={"build": {"build_base": base}, "egg_info": {"egg_base": base}},
)
