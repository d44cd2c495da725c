#!/usr/bin/env python3
"""Checks that every relative Markdown link resolves: the file exists and, for a #fragment, a
heading of that file has that GitHub anchor. Usage: scripts/check-md-links.py [PATH...]
(default bench/); exits 1 and lists the broken links if any."""
import pathlib
import re
import sys

LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def anchors(path):
    text = re.sub(r"```.*?```", "", path.read_text(), flags=re.S)
    out = set()
    for line in text.splitlines():
        m = re.match(r"#+ +(.*)", line)
        if m:
            slug = re.sub(r"[^\w\- ]", "", m.group(1).strip().lower()).replace(" ", "-")
            out.add(slug)
    return out


def main(args):
    root = pathlib.Path(__file__).resolve().parent.parent
    files = []
    for a in args or ["bench"]:
        p = (root / a) if not pathlib.Path(a).is_absolute() else pathlib.Path(a)
        files += sorted(p.rglob("*.md")) if p.is_dir() else [p]
    broken, count = [], 0
    for f in files:
        name = f.relative_to(root) if f.is_relative_to(root) else f
        text = re.sub(r"```.*?```", "", f.read_text(), flags=re.S)
        for target in LINK.findall(text):
            if re.match(r"[a-z]+:", target):
                continue  # http:, https:, mailto:
            count += 1
            path, _, frag = target.partition("#")
            dest = (f.parent / path).resolve() if path else f
            if not dest.exists():
                broken.append(f"{name}: {target} (no such file)")
            elif frag and dest.is_file() and frag not in anchors(dest):
                broken.append(f"{name}: {target} (no such heading)")
    print(f"{count} relative links in {len(files)} files, {len(broken)} broken")
    for b in broken:
        print("  " + b)
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
