#!/usr/bin/env python3
"""Checks the crates that `cargo package --no-verify` packed, as crates.io would hand them out.

Usage: check_packages.py MANIFEST [CARGO ARGS...]

For every package of the workspace of MANIFEST (a workspace's or a package's Cargo.toml) that has a
`.crate` file in the target folder's `package/`, this unpacks it into one new workspace under
`package/checked/` and runs `cargo check --workspace --all-targets` there: each package compiles
from its own files alone (a source, a shader or a build script's input left out of its `include`
list fails here), its dependencies on the other hadou crates taken from their packages
(`[patch.crates-io]`, as cargo's own verification takes them from its local registry). The
workspace's lock file and its profile tables are copied in, so the third-party crates resolve to
the same versions and compile as the workspace's own `cargo check`/`cargo clippy` compiled them:
those are reused, and only the packaged crates are compiled. CARGO ARGS are passed on to cargo
(`--config` patches for crates that are not in this workspace, say).

Prints each package's size and file count; exits with cargo's status.
"""

import json
import os
import re
import shutil
import subprocess
import sys
import tarfile


def main():
    if len(sys.argv) < 2:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    manifest = os.path.abspath(sys.argv[1])
    extra = sys.argv[2:]
    meta = json.loads(
        subprocess.run(
            ["cargo", "metadata", "--no-deps", "--format-version", "1", "--manifest-path", manifest],
            check=True,
            capture_output=True,
            text=True,
        ).stdout
    )
    root = meta["workspace_root"]
    packages = os.path.join(meta["target_directory"], "package")
    checked = os.path.join(packages, "checked")
    shutil.rmtree(checked, ignore_errors=True)
    os.makedirs(checked)
    members = []
    for pkg in meta["packages"]:
        name, version = pkg["name"], pkg["version"]
        crate = os.path.join(packages, f"{name}-{version}.crate")
        if not os.path.exists(crate):
            print(f"error: {crate} is missing: run `cargo package --no-verify` first", file=sys.stderr)
            return 1
        with tarfile.open(crate) as tar:
            files = [m for m in tar.getmembers() if m.isfile()]
            try:
                tar.extractall(checked, filter="data")
            except TypeError:  # a Python without extraction filters (before 3.11.4)
                tar.extractall(checked)
        # A package's files carry one fixed date; dated now (as cargo's own verification dates
        # them), an edited file is compiled again rather than taken for the last run's.
        for m in files:
            os.utime(os.path.join(checked, m.name))
        size = os.path.getsize(crate)
        print(f"{name}-{version}.crate: {size / 1024:.1f} KiB, {len(files)} files")
        members.append((name, f"{name}-{version}"))
    # The packages another package depends on come from their packages, not from crates.io.
    used = {d["name"] for p in meta["packages"] for d in p["dependencies"]}
    # The workspace's profile tables, as its Cargo.toml spells them (comments included).
    with open(os.path.join(root, "Cargo.toml"), encoding="utf-8") as f:
        text = f.read()
    start = re.search(r"^\[profile\.", text, flags=re.M)
    profiles = text[start.start() :] if start else ""
    with open(os.path.join(checked, "Cargo.toml"), "w", encoding="utf-8") as f:
        f.write("# The packages as packed, checked together (.ci/check_packages.py).\n[workspace]\n")
        f.write('resolver = "2"\nmembers = [' + ", ".join(f'"{d}"' for _, d in members) + "]\n\n")
        f.write("[patch.crates-io]\n")
        for name, d in members:
            if name in used:
                f.write(f'{name} = {{ path = "{d}" }}\n')
        f.write("\n" + profiles)
    lock = os.path.join(root, "Cargo.lock")
    if os.path.exists(lock):
        shutil.copy(lock, os.path.join(checked, "Cargo.lock"))
    cmd = ["cargo", "check", "--manifest-path", os.path.join(checked, "Cargo.toml"), "--workspace", "--all-targets"]
    cmd += extra
    print("+ " + " ".join(cmd), flush=True)
    env = dict(os.environ, CARGO_TARGET_DIR=meta["target_directory"])
    return subprocess.run(cmd, env=env).returncode


if __name__ == "__main__":
    sys.exit(main())
