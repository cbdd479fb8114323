#!/usr/bin/env python3
"""Every asset a SOURCES.md lists with a SHA-256 is the file it names, byte for byte.

    tools/check_assets.py ROOT     (exit 0: all match; 1: a file is missing or differs)
"""
import hashlib
import pathlib
import re
import sys

LINE = re.compile(r"^([0-9a-f]{64})  (\S+)$")


def main(root: pathlib.Path) -> int:
    bad, checked = [], 0
    for sources in sorted((root / "assets").rglob("SOURCES.md")):
        for line in sources.read_text().splitlines():
            m = LINE.match(line.strip())
            if not m:
                continue
            path = sources.parent / m.group(2)
            checked += 1
            if not path.is_file():
                bad.append(f"{sources.relative_to(root)}: {m.group(2)}: no such file")
            elif hashlib.sha256(path.read_bytes()).hexdigest() != m.group(1):
                bad.append(f"{sources.relative_to(root)}: {m.group(2)}: SHA-256 differs from the one listed")
    for b in bad:
        print(b)
    print(f"check_assets: {checked} file(s) checked, {len(bad)} wrong")
    return 1 if bad or checked == 0 else 0


if __name__ == "__main__":
    sys.exit(main(pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")))
