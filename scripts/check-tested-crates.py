#!/usr/bin/env python3
"""Fails when a workspace crate that has tests did not run them.

Reads the log of `cargo test --workspace` (argument 1) and `cargo metadata`: every package of the
workspace whose sources hold a `#[test]` (or that has a `tests/` folder) must show up in the log
as a test binary that ran ("Running ... deps/<crate>-<hash>") or as its doc-tests. A crate left
out of the test command, or a test target that silently stopped building, fails CI here.
"""
import json
import pathlib
import re
import subprocess
import sys

log = pathlib.Path(sys.argv[1]).read_text(errors="replace")
meta = json.loads(subprocess.run(
    ["cargo", "metadata", "--no-deps", "--format-version", "1"],
    check=True, capture_output=True, text=True).stdout)

ran = set(re.findall(r"Running [^\n]*?deps/([A-Za-z0-9_]+)-[0-9a-f]+", log))
ran |= {name.replace("-", "_") for name in re.findall(r"Doc-tests ([A-Za-z0-9_-]+)", log)}

missing = []
for package in meta["packages"]:
    root = pathlib.Path(package["manifest_path"]).parent
    has_tests = (root / "tests").is_dir() or any(
        "#[test]" in path.read_text(errors="replace")
        for path in (root / "src").rglob("*.rs"))
    if not has_tests:
        continue
    # Libraries and binaries only: integration-test names (tests/heat.rs) repeat across crates.
    targets = {t["name"].replace("-", "_") for t in package["targets"]
               if set(t["kind"]) & {"lib", "bin"}}
    if not targets & ran:
        missing.append(package["name"])

if missing:
    print("crates with tests that did not run them:", ", ".join(sorted(missing)))
    sys.exit(1)
print(f"every crate with tests ran them ({len(ran)} test binaries and doc-test sets)")
