#!/usr/bin/env python3
"""Every relative link of README.md and docs/*.md leads to a file of the project, and to a heading
of it where it names one (GitHub's anchors); none leaves the project. Usage: docs_links_test.py SOURCE_DIR"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1]).resolve()
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^```.*?^```", re.M | re.S)


def anchors(path):
    """The anchors GitHub gives a Markdown file's headings."""
    found, seen = set(), {}
    for heading in re.findall(r"^#+ +(.+?)\s*$", FENCE.sub("", path.read_text()), re.M):
        slug = re.sub(r"[^\w\- ]", "", heading.strip().lower().replace("`", "")).replace(" ", "-")
        count = seen.get(slug, 0)
        seen[slug] = count + 1
        found.add(slug if count == 0 else f"{slug}-{count}")
    return found


failures, checked = [], 0
for page in [root / "README.md", *sorted((root / "docs").glob("*.md"))]:
    for target in LINK.findall(FENCE.sub("", page.read_text())):
        if re.match(r"^[a-z]+:", target):
            continue  # http:, https:, mailto:
        checked += 1
        file_part, _, anchor = target.partition("#")
        where = (page.parent / file_part).resolve() if file_part else page
        name = f"{page.relative_to(root)}: {target}"
        if root not in where.parents and where != root:
            failures.append(f"{name} leaves the project")
        elif not where.exists():
            failures.append(f"{name}: no such file")
        elif anchor and where.suffix == ".md" and anchor not in anchors(where):
            failures.append(f"{name}: no heading #{anchor} in {where.relative_to(root)}")
for failure in failures:
    print("FAIL:", failure)
print(f"{checked} relative links checked, {len(failures)} broken")
sys.exit(1 if failures else 0)
