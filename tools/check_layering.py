#!/usr/bin/env python3
"""Fails when an #include edge between Follicle modules is not allowed by docs/architecture.md."""
import re
import sys
from pathlib import Path

ALLOWED = {
    "core": set(),
    "geom": {"core"},
    "image": {"core"},
    "anim": {"core", "geom"},
    "sim": {"core", "geom"},
    "skin": {"core", "geom", "image", "anim", "sim"},
    "hair": {"core", "geom", "image", "anim", "sim"},
    "render": {"core", "geom", "image"},
    "scene": {"core", "geom", "image", "anim", "sim", "skin", "hair", "render"},
}
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]follicle/(\w+)/')


def main() -> int:
    root = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    src = root / "src" / "follicle"
    bad = []
    for f in sorted(src.rglob("*")):
        if f.suffix not in {".hpp", ".cpp", ".h", ".inl"}:
            continue
        module = f.relative_to(src).parts[0]
        if module not in ALLOWED:
            bad.append(f"{f}: module '{module}' is not in the architecture table")
            continue
        for n, line in enumerate(f.read_text(errors="replace").splitlines(), 1):
            m = INCLUDE.match(line)
            if m and m.group(1) != module and m.group(1) not in ALLOWED[module]:
                bad.append(f"{f}:{n}: '{module}' may not include '{m.group(1)}'")
    for b in bad:
        print(b)
    print(f"layering: {len(bad)} violation(s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
