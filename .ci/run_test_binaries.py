#!/usr/bin/env python3
"""Runs test executables that `cargo test --no-run --message-format=json` built, as `cargo test`
runs them: one after another, each in its package's folder with CARGO_MANIFEST_DIR set, every
test of each.

    run_test_binaries.py MESSAGES PACKAGE...

MESSAGES is the file of cargo's JSON messages; PACKAGE names the workspace members whose test
executables run (their unit tests, integration tests and binaries' tests). Every executable runs
even when an earlier one failed, so one run reports every failure; the exit status is 1 if any
failed (or if a named package has no executable: a silent empty run cannot pass), else 0.

.ci/run uses it for the OpenGL pass, which runs the very binaries the README's test command built
while that command runs the Vulkan pass: cargo would hold the build folder's lock for the whole
of a second `cargo test`, and the two passes are each bound to one core (shader compiles).
"""

import json
import os
import subprocess
import sys
import time


def main() -> int:
    if len(sys.argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    messages, packages = sys.argv[1], set(sys.argv[2:])
    meta = json.loads(
        subprocess.run(
            ["cargo", "metadata", "--no-deps", "--format-version", "1"],
            check=True,
            capture_output=True,
            text=True,
        ).stdout
    )
    by_manifest = {p["manifest_path"]: p["name"] for p in meta["packages"]}
    runs = []
    with open(messages, encoding="utf-8") as f:
        for line in f:
            if not line.startswith("{"):
                continue
            m = json.loads(line)
            if m.get("reason") != "compiler-artifact" or not m.get("executable"):
                continue
            if not m.get("profile", {}).get("test"):
                continue
            name = by_manifest.get(m.get("manifest_path"))
            if name in packages:
                runs.append((name, m["target"]["src_path"], m["executable"], m["manifest_path"]))
    missing = packages - {r[0] for r in runs}
    if missing:
        print(f"error: no test executables of {', '.join(sorted(missing))} in {messages}", file=sys.stderr)
        return 1
    failed = []
    t0 = time.monotonic()
    for name, src, exe, manifest in runs:
        folder = os.path.dirname(manifest)
        print(f"     Running {os.path.relpath(src, folder)} of {name} ({os.path.relpath(exe)})", flush=True)
        env = dict(os.environ, CARGO_MANIFEST_DIR=folder, CARGO_PKG_NAME=name)
        t = time.monotonic()
        rc = subprocess.run([exe], cwd=folder, env=env).returncode
        print(f"     ({time.monotonic() - t:.1f} s, exit {rc})", flush=True)
        if rc != 0:
            failed.append(f"{name}: {os.path.relpath(src, folder)} (exit {rc})")
    print(f"{len(runs)} test executables in {time.monotonic() - t0:.1f} s", flush=True)
    for f in failed:
        print(f"error: failed: {f}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
