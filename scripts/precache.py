#!/usr/bin/env python3
"""Fills in the service worker of a release build: the list of files it caches at install
(every file of the build but the worker script itself and the single-file page) and a version made of their contents,
so a new build replaces the old cache. Usage: scripts/precache.py dist"""
import hashlib
import json
import pathlib
import sys

dist = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "dist")
sw = dist / "sw.js"
# cutroute.html is the same app in one file, a download for file:// use; the hosted app never
# loads it (scripts/single-file.py writes it after this script anyway).
files = sorted(p for p in dist.rglob("*") if p.is_file() and p != sw and p.name != "cutroute.html")
digest = hashlib.sha256()
for p in files:
    digest.update(p.relative_to(dist).as_posix().encode())
    digest.update(p.read_bytes())
urls = ["./"] + [p.relative_to(dist).as_posix() for p in files]
text = sw.read_text(encoding="utf-8")
for placeholder in ("const VERSION = 'development';", "const PRECACHE = [];"):
    if placeholder not in text:
        sys.exit(f"precache: {sw} lacks {placeholder!r}")
text = text.replace("const VERSION = 'development';", f"const VERSION = '{digest.hexdigest()[:16]}';")
text = text.replace("const PRECACHE = [];", f"const PRECACHE = {json.dumps(urls)};")
sw.write_text(text, encoding="utf-8")
print(f"[build] service worker caches {len(urls)} files, version {digest.hexdigest()[:16]}", file=sys.stderr)
