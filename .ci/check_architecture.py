#!/usr/bin/env python3
"""Checks that ARCHITECTURE.md's code map stays true to the tree.

1. Every source module (a `.rs` file under `crates/NAME/src/` other than the crate root, and every
   `.wgsl` shader) is named in the section of its crate (`### \`crates/NAME\``): by its path under
   `src/` (`passes/wave.rs`), by its file name (`wave.rs`), or, for a folder's `mod.rs`, by the
   folder (`passes/`).
2. Every path the map names in backticks (a token with a `/`, or ending in `.rs`, `.wgsl`, `.toml`,
   `.md`, `.py`, `.sh`) exists: from the repository root, from the crate of its section, or from
   that crate's `src/` (a bare file name is looked for anywhere under that crate).
3. No line counts ("(750 lines)"): they drift with every change.

Exit 1 with one line per problem; 0 and a summary otherwise. Run from anywhere.
"""

import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MAP = os.path.join(ROOT, "ARCHITECTURE.md")
EXTENSIONS = (".rs", ".wgsl", ".toml", ".md", ".py", ".sh", ".glb", ".gltf", ".html", ".js", ".json")


def sections(text):
    """(crate name or None, section text) for each `### ` section; the text before the first one and
    every section not about a crate get None."""
    parts = re.split(r"^(### .*)$", text, flags=re.M)
    out = [(None, parts[0])]
    for i in range(1, len(parts), 2):
        m = re.match(r"### `crates/([^`]+)`", parts[i])
        out.append((m.group(1) if m else None, parts[i] + parts[i + 1]))
    return out


def modules(crate):
    """Every module file of a crate, as its path under `src/`."""
    src = os.path.join(ROOT, "crates", crate, "src")
    found = []
    for dirpath, dirnames, filenames in os.walk(src):
        dirnames[:] = [d for d in dirnames if d != "target"]
        for f in filenames:
            if not (f.endswith(".rs") or f.endswith(".wgsl")):
                continue
            rel = os.path.relpath(os.path.join(dirpath, f), src)
            if rel in ("lib.rs", "main.rs"):
                continue
            found.append(rel)
    return sorted(found)


def named(rel, body):
    """Whether the section `body` names module `rel`."""
    candidates = {rel, "src/" + rel, os.path.basename(rel)}
    if os.path.basename(rel) == "mod.rs":
        folder = os.path.dirname(rel)
        candidates |= {folder + "/", os.path.basename(folder) + "/", folder}
    else:
        # A module `a/b.rs` may be named as `a/b` or by its stem in a list of its folder's files.
        candidates.add(rel[: -len(os.path.splitext(rel)[1])])
    return any(re.search(r"(?<![\w/.-])" + re.escape(c) + r"(?![\w-])", body) for c in candidates)


def path_like(token):
    if any(ch in token for ch in "*…<>{}$ ") or token.startswith(("http", "-", "../", ".", "target/")) or "::" in token:
        return False
    return "/" in token and not token.startswith("/") or token.endswith(EXTENSIONS)


def all_files():
    """Every file of the repository (build outputs and dependencies left out), by path."""
    out = set()
    for dirpath, dirnames, filenames in os.walk(ROOT):
        dirnames[:] = [d for d in dirnames if d not in ("target", ".git", "node_modules", "pkg")]
        for f in filenames:
            out.add(os.path.relpath(os.path.join(dirpath, f), ROOT))
    return out


FILES = all_files()
DIRS = {os.path.dirname(f) for f in FILES} | {os.path.dirname(os.path.dirname(f)) for f in FILES}


def exists(token, crate):
    """Whether `token` names a file or folder of the repository: from its root, from `crates/`,
    from the section's crate or its `src/`, from any crate's `src/` (the feature table names
    `passes/wave.rs`), or, for a bare name, anywhere."""
    token = token.rstrip("/").split("#")[0].split(":")[0]
    if not token:
        return True
    prefixes = ["", "crates/", "scenes/"]
    if crate:
        prefixes += [f"crates/{crate}/", f"crates/{crate}/src/"]
    prefixes += [f"crates/{c}/src/" for c in os.listdir(os.path.join(ROOT, "crates"))]
    prefixes += [f"crates/{c}/" for c in os.listdir(os.path.join(ROOT, "crates"))]
    for pre in prefixes:
        cand = os.path.normpath(pre + token)
        if cand in FILES or cand in DIRS:
            return True
    if "/" not in token:
        return any(os.path.basename(f) == token for f in FILES)
    return False


def main():
    text = open(MAP, encoding="utf-8").read()
    problems = []
    crates = sorted(d for d in os.listdir(os.path.join(ROOT, "crates")) if os.path.isdir(os.path.join(ROOT, "crates", d, "src")))
    by_crate = {}
    for crate, body in sections(text):
        if crate:
            by_crate[crate] = by_crate.get(crate, "") + body
    count = 0
    for crate in crates:
        body = by_crate.get(crate)
        if body is None:
            problems.append(f"ARCHITECTURE.md: no section `### \\`crates/{crate}\\``")
            continue
        for rel in modules(crate):
            count += 1
            if not named(rel, body):
                problems.append(f"ARCHITECTURE.md: crates/{crate}/src/{rel} is not named in the crates/{crate} section")
    paths = 0
    for crate, body in sections(text):
        for token in re.findall(r"`([^`\n]+)`", body):
            if path_like(token):
                paths += 1
                if not exists(token, crate):
                    where = f"crates/{crate}" if crate else "the top"
                    problems.append(f"ARCHITECTURE.md: `{token}` (in {where}) does not exist")
    for n, line in enumerate(text.splitlines(), 1):
        if re.search(r"\(\d[\d,]* lines", line):
            problems.append(f"ARCHITECTURE.md:{n}: a line count (they drift): {line.strip()[:80]}")
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} problem(s)")
        return 1
    print(f"ARCHITECTURE.md: {count} modules named, {paths} paths exist, no line counts")
    return 0


if __name__ == "__main__":
    sys.exit(main())
