#!/usr/bin/python3
"""Checks that every relative link of the docs resolves, so that a moved page or heading is caught.

    doc_links_test.py REPO

Reads README.md, ARCHITECTURE.md, docs/*.md, server/README.md, bench/RESULTS.md and
bench/notes/*.md; each Markdown link or image
`[text](target)` whose target is not a URL must name a file or folder of the repository, and its
`#anchor`, if any, a heading of the Markdown file it names (GitHub's anchors: lower case,
punctuation dropped, spaces as hyphens, a repeated heading numbered -1, -2, ...). Links inside
code are not links and are skipped.
"""
import collections
import pathlib
import re
import sys

LINK = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(([^()\s]+)\)")
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$")
FENCE = re.compile(r"^\s*(```|~~~)")
CODE_SPAN = re.compile(r"(`+)(?:(?!\1).)+?\1")


def pages(repo):
    found = [repo / "README.md", repo / "ARCHITECTURE.md", repo / "server" / "README.md"]
    found.append(repo / "bench" / "RESULTS.md")
    return ([page for page in found if page.exists()] + sorted((repo / "docs").glob("*.md")) +
            sorted((repo / "bench" / "notes").glob("*.md")))


def unfenced(text):
    """The text's lines with fenced code blanked, so that line numbers stay."""
    lines, in_fence = [], False
    for line in text.split("\n"):
        fence = FENCE.match(line)
        lines.append("" if in_fence or fence else line)
        if fence:
            in_fence = not in_fence
    return lines


def prose(text):
    """The text with fenced code and code spans blanked."""
    blank = lambda match: re.sub(r"[^\n]", " ", match.group(0))
    return CODE_SPAN.sub(blank, "\n".join(unfenced(text)))


def anchors(page):
    """GitHub's anchors of a Markdown file's headings."""
    seen = collections.Counter()
    found = set()
    for line in unfenced(page.read_text()):
        match = HEADING.match(line)
        if not match:
            continue
        text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", match.group(1))  # a link: its text
        slug = re.sub(r"[^\w\- ]", "", text.lower()).replace(" ", "-")
        found.add(slug if seen[slug] == 0 else f"{slug}-{seen[slug]}")
        seen[slug] += 1
    return found


def broken_links(repo):
    """(page, line, target, why) for every relative link that does not resolve."""
    broken = []
    for page in pages(repo):
        text = prose(page.read_text())
        for match in LINK.finditer(text):
            target = match.group(1)
            if re.match(r"[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
                continue
            path, _, anchor = target.partition("#")
            resolved = (page.parent / path).resolve() if path else page
            where = (page.relative_to(repo), text.count("\n", 0, match.start()) + 1, target)
            if repo not in resolved.parents and resolved != repo:
                broken.append(where + ("outside the repository",))
            elif not resolved.exists():
                broken.append(where + ("no such file",))
            elif anchor and resolved.suffix == ".md" and anchor not in anchors(resolved):
                broken.append(where + (f"no heading #{anchor} in {resolved.name}",))
    return broken


def main():
    repo = pathlib.Path(sys.argv[1]).resolve()
    broken = broken_links(repo)
    checked = [str(page.relative_to(repo)) for page in pages(repo)]
    print(f"checked the links of {', '.join(checked)}: {len(broken)} broken")
    for page, number, target, why in broken:
        print(f"{page}:{number}: ({target}): {why}")
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
