#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Every repository path the documentation names exists (ctest: doc_paths).

Reads README.md, ARCHITECTURE.md, docs/*.md and spec/*.md and checks three kinds of names:
  - paths under a top-level folder of the repository (codec/..., tools/scripts/..., tests/...),
    with {a,b} alternatives expanded;
  - relative Markdown link targets, from the document's folder;
  - installed headers (cbrdf/NAME.h), which must be some layer's include/cbrdf/NAME.h or a
    generated one (cmake/NAME.h.in).
Names with placeholders (NAME, MATERIAL, *, <...>, ...) and build outputs (build/..., a
build-* folder) are not paths of the tree and are skipped. Prints each missing path with the
document and line that names it, and exits 1 when there is one.
   Usage: tools/scripts/check-doc-paths.py [REPO_ROOT]
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parents[2])
DOCS = ["README.md", "ARCHITECTURE.md", *sorted(str(p.relative_to(ROOT)) for p in
        [*ROOT.glob("docs/*.md"), *ROOT.glob("spec/*.md")])]

# Top-level entries whose paths are checked; build outputs and the .git folder are not.
TOP = sorted(p.name for p in ROOT.iterdir()
             if p.name not in {".git", "build"} and not p.name.startswith("build-")
             and not p.name.startswith(".pytest"))
PATH = re.compile(r"(?<![\w./-])((?:%s)/[\w.{},/*<>-]*[\w}*>])" %
                  "|".join(re.escape(t) for t in TOP if not t.startswith(".")) +
                  r"|(?<![\w/-])(\.ci/[\w./-]*\w)")
LINK = re.compile(r"\]\(([^)\s#]+)(?:#[^)]*)?\)")
HEADER = re.compile(r"(?<![\w/])cbrdf/([\w]+\.h)\b")
PLACEHOLDER = re.compile(r"[*<>]|\.\.\.|\b[A-Z][A-Z0-9_]{2,}\b")


def expand(path):
    """a/{b,c}/d -> a/b/d, a/c/d."""
    m = re.search(r"\{([^{}]*)\}", path)
    if not m:
        return [path]
    out = []
    for alt in m.group(1).split(","):
        out += expand(path[:m.start()] + alt + path[m.end():])
    return out


def header_exists(name):
    return any(ROOT.glob(f"*/include/cbrdf/{name}")) or \
        any(ROOT.glob(f"*/*/include/cbrdf/{name}")) or (ROOT / "cmake" / f"{name}.in").exists()


def main():
    missing, checked = [], set()
    for doc in DOCS:
        text = (ROOT / doc).read_text(encoding="utf-8")
        base = (ROOT / doc).parent
        for lineno, line in enumerate(text.splitlines(), 1):
            names = []
            for m in PATH.finditer(line):
                names += [(ROOT, p) for p in expand((m.group(1) or m.group(2)).rstrip("./"))]
            for m in LINK.finditer(line):
                target = m.group(1)
                if re.match(r"[a-z]+:", target) or target.startswith("/"):
                    continue  # a URL or an absolute path on the reader's machine
                names.append((base, target))
            for where, name in names:
                checked.add((doc, name))
                # A missing name with a placeholder (README.md exists, NAME.binary is one).
                if (where / name).exists() or PLACEHOLDER.search(name) or "build/" in name:
                    continue
                missing.append(f"{doc}:{lineno}: {name}")
            for m in HEADER.finditer(line):
                checked.add((doc, m.group(0)))
                if not header_exists(m.group(1)) and not PLACEHOLDER.search(m.group(1)):
                    missing.append(f"{doc}:{lineno}: cbrdf/{m.group(1)} (no layer installs it)")
    for m in sorted(set(missing)):
        print(f"check-doc-paths: missing: {m}")
    if missing:
        print(f"check-doc-paths: {len(set(missing))} of the {len(checked)} paths named in "
              f"{len(DOCS)} documents do not exist: fix the document or the path", flush=True)
        return 1
    print(f"check-doc-paths: the {len(checked)} paths named in {len(DOCS)} documents exist")
    return 0


if __name__ == "__main__":
    sys.exit(main())
