#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Checks the layer rules of ARCHITECTURE.md on the source tree:

1. A file includes only from its own layer or the ones below it: the libraries never include from
   tools/, and each layer's tests (tests/LAYER/) include nothing above LAYER.
2. The programs stand on the installed API: no file under tools/, tests/tools/, tests/bench/ or
   fuzz/ includes a header under a library's src/ folder (format/src, codec/*/src).
3. Each tool builds from its own sources: no target of one tool (tools/NAME/) compiles a source
   file of another, whether through its CMake sources or by including a .cc file.

Every quoted #include is resolved the way the compiler would (the including file's folder first,
then the tools' folders, then every layer's include/ and src/ folders); a problem is reported with
the file, the line and what to do instead.

Usage: tools/scripts/check-layers.py [REPO]     exit 0: the tree keeps the rules; 1: it does not
"""
import glob
import os
import re
import sys

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                       os.path.join(os.path.dirname(__file__), "..", ".."))
# Lowest first. A layer may include from itself and every layer before it.
LAYERS = [
    ("format", ["format/include", "format/src"]),
    ("decoder", ["codec/decoder/include", "codec/decoder/src"]),
    ("encoder", ["codec/encoder/include", "codec/encoder/src"]),
    ("extras", ["codec/extras/include", "codec/extras/src"]),
    ("tools", ["tools", "tools/cli"]),
]
RANK = {name: i for i, (name, _) in enumerate(LAYERS)}
# Folders whose files belong to a layer: the libraries' own, and each layer's tests.
MEMBERS = [
    ("format/", "format"), ("codec/decoder/", "decoder"), ("codec/encoder/", "encoder"),
    ("codec/extras/", "extras"), ("tools/", "tools"),
    ("tests/format/", "format"), ("tests/decoder/", "decoder"), ("tests/encoder/", "encoder"),
    ("tests/extras/", "extras"), ("tests/tools/", "tools"),
]
# Programs over the libraries: they include installed headers (include/cbrdf/) only.
PROGRAMS = ["tools/", "tests/tools/", "tests/bench/", "fuzz/"]
INTERNAL = [d for _, dirs in LAYERS[:-1] for d in dirs if d.endswith("/src")]
PUBLIC = [d for _, dirs in LAYERS[:-1] for d in dirs if d.endswith("/include")]
INCLUDE = re.compile(r'^\s*#\s*include\s*(?:"([^"]+)"|<([^>]+)>)')
SOURCE = (".h", ".cc", ".c", ".cpp", ".def")
COMPILED = (".cc", ".c", ".cpp")
SKIP_DIRS = {"node_modules", "__pycache__"}


def layer_of(rel):
    for prefix, name in MEMBERS:
        if rel.startswith(prefix):
            return name
    return None


def resolve(rel_file, target):
    """The repository path the include names, and the layer that owns it (None: not ours). An
    <angle> include (target starting with "<") skips the including file's folder."""
    if target.startswith("<"):
        target = target[1:]
        here = None
    else:
        here = os.path.join(ROOT, os.path.dirname(rel_file), target)
    if here and os.path.isfile(here):
        rel = os.path.relpath(os.path.normpath(here), ROOT)
        return rel, layer_of(rel)
    for name, dirs in LAYERS:
        for d in dirs:
            if os.path.isfile(os.path.join(ROOT, d, target)):
                return os.path.join(d, target), name
    return None, None


def public_instead(internal_path, target):
    """What a program should include instead of an internal header, in words."""
    # An internal header that only forwards to a public one (nothing but comments and the
    # include) names it.
    with open(os.path.join(ROOT, internal_path), encoding="utf-8") as f:
        code = [line.strip() for line in f
                if line.strip() and not line.strip().startswith(("//", "#pragma"))]
    forwards = [m.group(1) for m in map(INCLUDE.match, code) if m and m.group(1)]
    if len(code) == 1 and forwards and any(os.path.isfile(os.path.join(ROOT, d, forwards[0]))
                                           for d in PUBLIC):
        return f'include "{forwards[0]}" instead'
    base = os.path.basename(target)
    same = [os.path.join("cbrdf", base) for d in PUBLIC
            if os.path.isfile(os.path.join(ROOT, d, "cbrdf", base))]
    if same:
        return f'include "{same[0]}" instead'
    return ("use the installed headers (include \"cbrdf/...\"), make what it needs public API "
            "(a documented header under the layer's include/cbrdf/), or move it into the program")


def source_files(prefix):
    for dirpath, dirnames, filenames in os.walk(os.path.join(ROOT, prefix)):
        dirnames[:] = sorted(d for d in dirnames if d not in SKIP_DIRS)
        for fn in sorted(filenames):
            if fn.endswith(SOURCE):
                yield os.path.relpath(os.path.join(dirpath, fn), ROOT)


def includes(rel):
    with open(os.path.join(ROOT, rel), encoding="utf-8") as f:
        for line_no, line in enumerate(f, 1):
            m = INCLUDE.match(line)
            if m:
                yield line_no, m.group(1) if m.group(1) is not None else "<" + m.group(2)


def check_upward(problems):
    checked = 0
    for prefix, owner in MEMBERS:
        for rel in source_files(prefix):
            if layer_of(rel) != owner:
                continue  # a deeper prefix owns it
            checked += 1
            for line_no, target in includes(rel):
                path, layer = resolve(rel, target)
                if layer is not None and RANK[layer] > RANK[owner]:
                    problems.append(f"{rel}:{line_no}: includes {shown(target)} ({path}, layer "
                                    f"{layer}) from layer {owner}: includes run downward only "
                                    "(format < decoder < encoder < extras < tools)")
    return checked


def shown(target):
    """An include's name as written: "x.h" or <x.h>."""
    return f"<{target[1:]}>" if target.startswith("<") else f'"{target}"'


def tool_of(rel):
    """The tool a repository path under tools/ belongs to (its first folder), or None."""
    parts = rel.split("/")
    if len(parts) >= 3 and parts[0] == "tools":
        return parts[1]
    return None


def check_programs(problems):
    checked = 0
    for prefix in PROGRAMS:
        for rel in source_files(prefix):
            checked += 1
            for line_no, target in includes(rel):
                path, _ = resolve(rel, target)
                if path is None:
                    continue
                internal = next((d for d in INTERNAL if path.startswith(d + "/")), None)
                if internal is not None:
                    problems.append(f"{rel}:{line_no}: includes {shown(target)} ({path}), a "
                                    f"library's internal header ({internal}/ is not installed): "
                                    f"{public_instead(path, target)}")
                elif path.endswith(COMPILED):
                    problems.append(f"{rel}:{line_no}: includes the source file {path}: a "
                                    "program compiles only its own sources; move what it needs "
                                    "into a library's public API or into this program")
    return checked


# ---- CMake: the sources of each target under tools/ ----

COMMAND = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)\s*\(")
VARIABLE = re.compile(r"\$\{([A-Za-z0-9_]+)\}")
TARGET_COMMANDS = {"add_library", "add_executable", "target_sources", "pybind11_add_module",
                   "python_add_library"}
KEYWORDS = {"STATIC", "SHARED", "MODULE", "OBJECT", "INTERFACE", "PUBLIC", "PRIVATE", "EXCLUDE_FROM_ALL",
            "NO_EXTRAS", "THIN_LTO", "WITH_SOABI", "GLOB", "GLOB_RECURSE", "CONFIGURE_DEPENDS",
            "FILE_SET", "HEADERS", "BASE_DIRS", "FILES", "WIN32", "MACOSX_BUNDLE", "IMPORTED"}


def cmake_commands(text):
    """(name, argument tokens, line) of each command call, comments removed."""
    text = re.sub(r"#\[\[.*?\]\]", "", text, flags=re.S)
    text = re.sub(r"(?m)#.*$", "", text)
    pos = 0
    while True:
        m = COMMAND.search(text, pos)
        if not m:
            return
        depth, i = 1, m.end()
        while i < len(text) and depth:
            depth += {"(": 1, ")": -1}.get(text[i], 0)
            i += 1
        args = text[m.end():i - 1]
        yield m.group(1), re.findall(r'"[^"]*"|[^\s()]+', args), text.count("\n", 0, m.start()) + 1
        pos = i


def expand(token, variables, cmake_dir, depth=0):
    token = token.strip('"')
    fixed = {"CMAKE_CURRENT_SOURCE_DIR": cmake_dir, "CMAKE_CURRENT_LIST_DIR": cmake_dir,
             "PROJECT_SOURCE_DIR": ROOT, "CMAKE_SOURCE_DIR": ROOT, "cbrdf_SOURCE_DIR": ROOT}
    whole = re.fullmatch(r"\$\{([A-Za-z0-9_]+)\}", token)
    if whole and whole.group(1) in variables and depth < 8:
        out = []
        for t in variables[whole.group(1)]:
            out += expand(t, variables, cmake_dir, depth + 1)
        return out
    token = VARIABLE.sub(lambda v: fixed.get(v.group(1), v.group(0)), token)
    if "${" in token or "$<" in token or token in KEYWORDS:
        return []
    return [os.path.normpath(token if os.path.isabs(token) else os.path.join(cmake_dir, token))]


def glob_files(pattern):
    if not any(c in pattern for c in "*?["):
        return [pattern]
    return [p for p in glob.glob(pattern) if os.path.isfile(p)]


def check_tool_targets(problems):
    """Fails on a target under tools/ whose compiled sources come from more than one tool."""
    for rel in sorted(source_cmakelists()):
        cmake_dir = os.path.join(ROOT, os.path.dirname(rel))
        home = tool_of(rel)  # None for tools/CMakeLists.txt, which builds several tools
        with open(os.path.join(ROOT, rel), encoding="utf-8") as f:
            text = f.read()
        variables = {}
        targets = {}
        for name, args, line in cmake_commands(text):
            lname = name.lower()
            if lname == "set" and args:
                variables[args[0]] = args[1:]
            elif lname == "list" and len(args) >= 3 and args[0] in ("APPEND", "PREPEND"):
                variables.setdefault(args[1], []).extend(args[2:])
            elif lname == "file" and len(args) >= 3 and args[0] in ("GLOB", "GLOB_RECURSE"):
                variables[args[1]] = args[2:]
            elif lname in TARGET_COMMANDS and args:
                targets.setdefault(args[0], []).append((line, args[1:]))
        for target, uses in targets.items():
            tools = {}
            for line, args in uses:
                for token in args:
                    for path in expand(token, variables, cmake_dir):
                        for p in glob_files(path):
                            prel = os.path.relpath(p, ROOT)
                            if prel.endswith(COMPILED) and tool_of(prel):
                                tools.setdefault(tool_of(prel), (line, prel))
            # The target belongs to its CMakeLists' tool, or (tools/CMakeLists.txt) to the tool
            # of its first source.
            owner = home or next(iter(tools), None)
            for tool, (line, prel) in sorted(tools.items()):
                if tool == owner:
                    continue
                problems.append(f"{rel}:{line}: target {target} compiles {prel}, a source of "
                                f"tools/{tool}/ (it builds {', '.join(sorted(tools))}): a tool "
                                "compiles only its own sources; move what they share into a "
                                "library's public API")


def source_cmakelists():
    for dirpath, dirnames, filenames in os.walk(os.path.join(ROOT, "tools")):
        dirnames[:] = sorted(d for d in dirnames if d not in SKIP_DIRS)
        if "CMakeLists.txt" in filenames:
            yield os.path.relpath(os.path.join(dirpath, "CMakeLists.txt"), ROOT)


def main():
    problems = []
    checked = check_upward(problems)
    check_programs(problems)
    check_tool_targets(problems)
    if checked == 0:
        print(f"check-layers: no source files under {ROOT}", file=sys.stderr)
        return 1
    for p in problems:
        print(f"check-layers: {p}", file=sys.stderr)
    if problems:
        print(f"check-layers: FAILED: {len(problems)} problem(s) (ARCHITECTURE.md, Layers)",
              file=sys.stderr)
        return 1
    print(f"check-layers: {checked} files: no include runs upward, the programs include only "
          "installed headers, each tool compiles only its own sources")
    return 0


if __name__ == "__main__":
    sys.exit(main())
