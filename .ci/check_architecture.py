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
4. The "Add a wave shape" walk-through names every source file that lists the closed-form wave
   kinds one by one (a match, table or dispatch over `WaveShape`, `WaveKind`, the GPU's `WAVE_*`
   codes, `KIND_BIT_*` bits or `USE_*` overrides, or hadou-math's per-shape energies): each must
   gain the new kind, so the list is checked against the kinds' uses, not kept by hand.
5. Every name the map gives in backticks as code (`Frame::sample_grid`, `load_frame`,
   `WaveVariant::NAMES`: identifiers, `::` paths, a trailing `()`) exists: each of its segments is
   a word of the workspace's sources, CI scripts, web page or scenes.

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


# Groups of names that a place handling every wave kind lists one by one (the closed-form kinds;
# a curve kind's places are the curve module's and are listed under it).
KIND_GROUPS = [
    [f"WaveShape::{k}" for k in ("Sphere", "Cylinder", "Capsule", "Beam")],
    [f"WaveKind::{k}" for k in ("Sphere", "Cylinder", "Capsule", "Beam")],
    [f"WAVE_{k}" for k in ("SPHERE", "CYLINDER", "CAPSULE", "BEAM")],
    [f"KIND_BIT_{k}" for k in ("SPHERE", "CYLINDER", "CAPSULE", "BEAM")],
    [f"USE_{k}" for k in ("SPHERE", "CYLINDER", "CAPSULE", "BEAM")],
    [f"{k}_energy" for k in ("sphere", "cylinder", "capsule", "beam")],
]


def wave_kind_sites():
    """Every source file (`crates/*/src/`, Rust or WGSL) naming all closed-form kinds of one group."""
    sites = []
    for f in sorted(FILES):
        parts = f.split("/")
        if len(parts) < 4 or parts[0] != "crates" or parts[2] != "src" or not f.endswith((".rs", ".wgsl")):
            continue
        code = open(os.path.join(ROOT, f), encoding="utf-8").read()
        if any(all(re.search(r"(?<![\w])" + re.escape(n) + r"(?![\w])", code) for n in g) for g in KIND_GROUPS):
            sites.append(f)
    return sites


def source_words():
    """Every identifier-like word of the sources (crates, CI scripts, the web page, scenes)."""
    words = set()
    for f in FILES:
        if f.split("/")[0] in ("crates", ".ci", "web", "scenes") and f.endswith(
            (".rs", ".wgsl", ".toml", ".py", ".js", ".html", ".sh")
        ):
            with open(os.path.join(ROOT, f), encoding="utf-8", errors="replace") as fh:
                words |= set(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", fh.read()))
    return words


def missing_names(text):
    """The backticked code names of `text` with a segment no source has."""
    words = source_words()
    out = []
    for token in re.findall(r"`([^`\n]+)`", text):
        name = token.strip()
        if name.endswith("()"):
            name = name[:-2]
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*(::[A-Za-z_][A-Za-z0-9_]*)*", name):
            continue
        if any(seg not in words for seg in name.split("::")) and token not in out:
            out.append(token)
    return out


def walk_through(text):
    """The body of the "Add a wave shape" section, or None."""
    m = re.search(r"^### Add a wave shape$(.*?)(?=^#{1,3} )", text, flags=re.M | re.S)
    return m.group(1) if m else None


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
    walk = walk_through(text)
    sites = wave_kind_sites()
    if walk is None:
        problems.append("ARCHITECTURE.md: no section `### Add a wave shape`")
    else:
        for f in sites:
            if f"`{f}`" not in walk:
                problems.append(f"ARCHITECTURE.md: \"Add a wave shape\" does not name `{f}`, which lists every wave kind")
    names = missing_names(text)
    for token in names:
        problems.append(f"ARCHITECTURE.md: `{token}` names nothing in the sources")
    for n, line in enumerate(text.splitlines(), 1):
        if re.search(r"\(\d[\d,]* lines", line):
            problems.append(f"ARCHITECTURE.md:{n}: a line count (they drift): {line.strip()[:80]}")
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} problem(s)")
        return 1
    print(f"ARCHITECTURE.md: {count} modules named, {paths} paths exist, no line counts, "
          f"every code name found, the {len(sites)} places that list every wave kind in \"Add a wave shape\"")
    return 0


if __name__ == "__main__":
    sys.exit(main())
