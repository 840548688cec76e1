"""Every relative link and image of README.md and docs/**/*.md resolves to a
file committed to the repository (git ls-files), and a link to a section of
a Markdown page ("page.md#section") names a heading of that page. Web links
(http, https, mailto) are not followed; links inside code (fenced blocks,
`inline code`) are not links."""
import glob
import os
import re
import subprocess
import sys
import unicodedata
from urllib.parse import unquote

from support import ROOT, check

LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\[\]]*\])*\]\(\s*<?([^)\s>]*)>?(?:\s+\"[^\"]*\")?\s*\)")
IMAGE_TAG = re.compile(r"<img\b[^>]*\bsrc=\"([^\"]+)\"", re.I)
FENCE = re.compile(r"^\s*(```|~~~)")
WEB = ("http://", "https://", "mailto:", "ftp://")

git = subprocess.run(["git", "-C", ROOT, "ls-files", "-z"], capture_output=True, text=True)
if git.returncode != 0:
    sys.exit(f"FAIL: git ls-files in {ROOT}: {git.stderr.strip()} (the test needs the git checkout)")
tracked = set(git.stdout.split("\0")) - {""}
tracked_dirs = {os.path.dirname(f) for f in tracked}
for d in list(tracked_dirs):
    while d:
        d = os.path.dirname(d)
        tracked_dirs.add(d)


def prose(text, code="drop"):
    """The lines of a Markdown page outside fenced code, with the inline
    code dropped (code="drop") or only its backticks (code="text")."""
    inside = False
    for number, line in enumerate(text.splitlines(), 1):
        if FENCE.match(line):
            inside = not inside
            continue
        if not inside:
            yield number, re.sub(r"(`+)(.*?)\1", "" if code == "drop" else r"\2", line)


def slug(heading):
    """GitHub's anchor of a heading: lower case, formatting and punctuation
    dropped (letters, digits, '-' and '_' kept), spaces made '-'."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading.strip()).lower()
    kept = "".join(c for c in text if c in " -_" or unicodedata.category(c)[0] in "LN")
    return kept.replace(" ", "-")


def anchors(path):
    found, seen = set(), {}
    with open(path, encoding="utf-8") as f:
        for _, line in prose(f.read(), code="text"):
            m = re.match(r"^\s{0,3}(#{1,6})\s+(.*?)\s*#*\s*$", line)
            if m:
                base = slug(m.group(2))
                n = seen.get(base, 0)
                seen[base] = n + 1
                found.add(base if n == 0 else f"{base}-{n}")
            for name in re.findall(r"<a\s+(?:name|id)=\"([^\"]+)\"", line):
                found.add(name)
    return found


pages = [os.path.join(ROOT, "README.md")] + sorted(
    glob.glob(os.path.join(ROOT, "docs", "**", "*.md"), recursive=True))
problems, count = [], 0
for page in pages:
    name = os.path.relpath(page, ROOT)
    with open(page, encoding="utf-8") as f:
        text = f.read()
    for number, line in prose(text):
        for target in LINK.findall(line) + IMAGE_TAG.findall(line):
            if not target or target.lower().startswith(WEB):
                continue
            count += 1
            path, _, anchor = unquote(target).partition("#")
            resolved = page if not path else os.path.normpath(os.path.join(os.path.dirname(page), path))
            relative = os.path.relpath(resolved, ROOT)
            where = f"{name}:{number}: {target}"
            if not path:  # a section of this page
                if anchor not in anchors(page):
                    problems.append(f"{where} (no section #{anchor} on this page)")
            elif relative.startswith(".."):
                problems.append(f"{where} points outside the repository")
            elif relative not in tracked and relative.rstrip("/") not in tracked_dirs:
                state = "not committed" if os.path.exists(resolved) else "missing"
                problems.append(f"{where} ({relative} {state})")
            elif anchor and relative.endswith(".md") and os.path.isfile(resolved) \
                    and anchor not in anchors(resolved):
                problems.append(f"{where} (no section #{anchor} in {relative})")

check(len(pages) > 1 and count > 0, f"{count} relative links and images in {len(pages)} pages")
check(not problems, "every link and image resolves to a committed file"
      + "".join("\n  " + p for p in problems))
